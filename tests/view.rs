//! `skycast view` in a real window: an X server of its own (Xvfb, which `make test` installs),
//! lavapipe presenting to the window's surface. One scripted run checks that 60 frames are
//! presented, that the time-of-day key changes the sky and that a still pose matches
//! `skycast render` of the same pose; one that `--watch` applies a replaced weather file while
//! the window flies; another that no display is a clear message and exit status 2. Small (320x180) because the software rasteriser shares two cores with other tests.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The pose both commands draw: fair-weather cumulus over Orlando at 2 pm local.
const POSE: [&str; 12] = [
    "--weather",
    "weather/themes/fair_weather_cumulus.toml",
    "--at",
    "28.5,-81.45",
    "--alt-ft",
    "2500",
    "--heading",
    "90",
    "--pitch",
    "6",
    "--time",
    "2025-01-27T19:00:00Z",
];

/// An Xvfb server on a free display, stopped on drop.
struct VirtualDisplay {
    server: Child,
    display: String,
}

impl VirtualDisplay {
    /// Starts Xvfb on a display it picks itself (`-displayfd`: it takes the first free one
    /// under its own lock and writes the number when it is ready, so tests running side by side
    /// never share a server); `None` where it cannot be started.
    fn start() -> Option<Self> {
        let mut server = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1024x768x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .ok()?;
        let mut line = String::new();
        let read = BufReader::new(server.stdout.take()?).read_line(&mut line);
        match read {
            Ok(n) if n > 0 && line.trim().parse::<u32>().is_ok() => Some(Self {
                server,
                display: format!(":{}", line.trim()),
            }),
            _ => {
                let _ = server.kill();
                let _ = server.wait();
                None
            }
        }
    }
}

impl Drop for VirtualDisplay {
    fn drop(&mut self) {
        // SIGTERM, so the server removes its lock file and socket (SIGKILL would leave them).
        let _ = Command::new("kill")
            .arg(self.server.id().to_string())
            .status();
        let _ = self.server.wait();
    }
}

fn skycast(args: &[&str], display: Option<&str>) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_skycast"));
    command.args(args).env_remove("WAYLAND_DISPLAY");
    match display {
        Some(d) => command.env("DISPLAY", d),
        None => command.env_remove("DISPLAY"),
    };
    command.output().expect("skycast runs")
}

fn rgb(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

/// Mean absolute difference per channel, 0..=1, of two same-sized images (rows `rows` only).
fn mean_difference(a: &image::RgbImage, b: &image::RgbImage, rows: std::ops::Range<u32>) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut sum = 0.0;
    let mut count = 0.0;
    for y in rows {
        for x in 0..a.width() {
            for c in 0..3 {
                sum += (a.get_pixel(x, y)[c] as f64 - b.get_pixel(x, y)[c] as f64).abs() / 255.0;
                count += 1.0;
            }
        }
    }
    sum / count
}

#[test]
fn the_viewer_presents_a_scripted_flight_in_a_window() {
    let Some(x) = VirtualDisplay::start() else {
        eprintln!(
            "SKIPPED: Xvfb cannot be started here (make test installs it: apt-get install xvfb xauth)"
        );
        return;
    };
    let dir = std::env::temp_dir().join(format!("skycast-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Twelve presses of + from frame 30: six hours later, evening.
    let script = dir.join("evening.toml");
    let presses: String = (30..42)
        .map(|f| format!("[[press]]\nframe = {f}\nkey = \"Plus\"\n"))
        .collect();
    std::fs::write(&script, presses).unwrap();
    let (still, evening, rendered) = (
        dir.join("still.png"),
        dir.join("evening.png"),
        dir.join("render.png"),
    );
    let mut args = POSE.to_vec();
    let still_at = format!("0,{}", still.display());
    let evening_at = format!("59,{}", evening.display());
    let script_arg = script.display().to_string();
    args.extend([
        "view",
        "--size",
        "320x180",
        "--no-vsync",
        "--frames",
        "60",
        "--script",
        &script_arg,
        "--screenshot-at",
        &still_at,
        "--screenshot-at",
        &evening_at,
    ]);
    args.rotate_left(POSE.len()); // `view` first, then the pose.
    let out = skycast(&args, Some(&x.display));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{:?}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("60 frames presented at 320x180"),
        "{stdout}"
    );

    let render_out = format!("{}", rendered.display());
    let mut args = vec!["render", "--size", "320x180", "--out", &render_out];
    args.extend(POSE);
    let out = skycast(&args, None);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let (still, evening, rendered) = (rgb(&still), rgb(&evening), rgb(&rendered));
    let whole = 0..still.height();
    let difference = mean_difference(&still, &rendered, whole);
    eprintln!("window frame vs skycast render, mean absolute difference: {difference:.5}");
    assert!(
        difference <= 0.01,
        "window frame vs render: {difference:.4}"
    );
    // The sky (the top third) after six hours of + is another colour.
    let sky_change = mean_difference(&still, &evening, 0..still.height() / 3);
    eprintln!("the sky's change after twelve presses of + (six hours): {sky_change:.4}");
    assert!(sky_change > 0.05, "sky change after +6 h: {sky_change:.4}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_replaced_weather_file_reaches_the_window() {
    let Some(x) = VirtualDisplay::start() else {
        eprintln!(
            "SKIPPED: Xvfb cannot be started here (make test installs it: apt-get install xvfb xauth)"
        );
        return;
    };
    let dir = std::env::temp_dir().join(format!("skycast-view-watch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let weather = dir.join("weather.toml");
    std::fs::copy("weather/themes/high_cirrus.toml", &weather).unwrap();
    let mut viewer = Command::new(env!("CARGO_BIN_EXE_skycast"))
        .args(["view", "--weather"])
        .arg(&weather)
        .args([
            "--at",
            "28.5,-81.45",
            "--size",
            "96x54",
            "--no-vsync",
            "--watch",
        ])
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("skycast runs");
    let (lines_tx, lines) = mpsc::channel();
    let stderr = BufReader::new(viewer.stderr.take().unwrap());
    std::thread::spawn(move || {
        for line in stderr.lines().map_while(Result::ok) {
            if lines_tx.send(line).is_err() {
                break;
            }
        }
    });
    let wait_for = |needle: &str, seen: &mut Vec<String>| -> bool {
        let deadline = Instant::now() + Duration::from_secs(60);
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match lines.recv_timeout(left) {
                Ok(line) => {
                    let found = line.contains(needle);
                    seen.push(line);
                    if found {
                        return true;
                    }
                }
                Err(_) => return false,
            }
        }
        false
    };
    let mut seen = Vec::new();
    let watching = wait_for("watching", &mut seen);
    if watching {
        std::fs::copy("weather/themes/fair_weather_cumulus.toml", &weather).unwrap();
    }
    let applied = watching && wait_for("weather applied", &mut seen);
    let _ = viewer.kill();
    let _ = viewer.wait();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(applied, "stderr: {seen:#?}");
}

#[test]
fn no_display_is_one_message_and_status_2() {
    let mut args = vec!["view"];
    args.extend(POSE);
    let out = skycast(&args, None);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("needs a display") && stderr.contains("skycast render"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn help_lists_the_keys() {
    let out = skycast(&["view", "--help"], None);
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for key in ["W / S", "PageUp", "Shift", "+ / -", "F12", "Escape"] {
        assert!(help.contains(key), "{key} missing from:\n{help}");
    }
}

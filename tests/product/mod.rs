//! skycast as a product: the command line runs from any directory (every default built in,
//! `--config-dir` replacing them), and on a device short of what the sky needs (Mesa's OpenGL
//! backend) it gives a frame or one clear error, never a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh directory outside the checkout.
fn elsewhere(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("skycast-product-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn skycast_in(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_skycast"));
    command
        .args(args)
        .current_dir(dir)
        .env_remove("SKYCAST_CONFIG_DIR");
    for (key, value) in env {
        command.env(key, value);
    }
    command.output().expect("the skycast binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn bulk_file() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("weather/awc-metars-2025-01-27T22Z.cache.csv")
        .display()
        .to_string()
}

#[test]
fn the_command_line_runs_from_any_directory() {
    let dir = elsewhere("anywhere");
    // A bulk file placed through the built-in station table.
    let o = skycast_in(&dir, &["weather", &bulk_file(), "--at", "51.47,-0.46"], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("reports 4909, located 4877"), "{text}");
    // A frame of the bulk file, and one of a shipped theme named by its repository path.
    for weather in [
        bulk_file(),
        "weather/themes/fair_weather_cumulus.toml".to_string(),
    ] {
        let out = dir.join("frame.png");
        let o = skycast_in(
            &dir,
            &[
                "render",
                "--weather",
                &weather,
                "--at",
                "33.90,-118.36",
                "--alt-ft",
                "3000",
                "--size",
                "64x36",
                "--out",
                out.to_str().expect("utf-8 temp path"),
            ],
            &[],
        );
        assert!(o.status.success(), "{weather}: {}", stderr(&o));
        let image = image::open(&out).expect("a PNG");
        assert_eq!((image.width(), image.height()), (64, 36));
        std::fs::remove_file(&out).expect("remove the frame");
    }
}

#[test]
fn a_config_dir_replaces_the_built_in_files_by_name() {
    let dir = elsewhere("config-dir");
    // Its field settings are read (the mistake in them is reported, with the file's name).
    std::fs::write(dir.join("weather_field.toml"), "this is = = not toml\n").expect("write");
    let args = [
        "weather",
        "weather/themes/high_cirrus.toml",
        "--at",
        "28.5,-81.45",
    ];
    let dir_arg = dir.to_str().expect("utf-8 temp path");
    let with_flag = skycast_in(&dir, &[&["--config-dir", dir_arg], &args[..]].concat(), &[]);
    let with_env = skycast_in(&dir, &args, &[("SKYCAST_CONFIG_DIR", dir_arg)]);
    for o in [with_flag, with_env] {
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("weather_field.toml"), "{}", stderr(&o));
    }
    // The ceilometer reads the folder's clouds settings, as `fly` does.
    std::fs::remove_file(dir.join("weather_field.toml")).expect("remove");
    std::fs::write(dir.join("clouds.toml"), "[lifecycle]\nformation_s = -1\n").expect("write");
    let o = skycast_in(
        &dir,
        &[
            "--config-dir",
            dir_arg,
            "ceilometer",
            &bulk_file(),
            "--at",
            "51.47,-0.46",
            "--minutes",
            "1",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("clouds.toml"), "{}", stderr(&o));
    std::fs::remove_file(dir.join("clouds.toml")).expect("remove");
    // A file the folder lacks stays built in; a folder that is not there is refused.
    let o = skycast_in(&dir, &args, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = skycast_in(&dir, &["--config-dir", "no/such/folder", "types"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a folder"), "{}", stderr(&o));
}

/// A report file none of whose reports can be placed (a station the table lacks) is one error
/// naming the file and why, with exit 2, for every command that draws from it: an empty sky
/// read like a clear report (the ceilometer read `SKC`).
#[test]
fn a_report_file_that_places_no_report_is_one_clear_error() {
    let dir = elsewhere("unplaced");
    let file = dir.join("unknown.txt");
    std::fs::write(
        &file,
        "XXQQ 272215Z AUTO 23023KT 10SM OVC095 01/M13 A2935\n",
    )
    .expect("write");
    let file = file.to_str().expect("utf-8 temp path");
    for args in [
        &["ceilometer", file, "--at", "44.67,-74.94", "--minutes", "1"][..],
        &["block", "--weather", file, "--at", "44.67,-74.94"][..],
    ] {
        let o = skycast_in(&dir, args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains("unknown.txt: no usable report") && err.contains("without a position"),
            "{args:?}: {err}"
        );
    }
    // `skycast weather` lists such a file rather than refusing it.
    let o = skycast_in(&dir, &["weather", file], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `--at` takes a station's ICAO identifier as well as LAT,LON: the ceilometer stands where the
/// file places the station's report, and an identifier no one knows is one clear error.
#[test]
fn at_takes_a_station_identifier() {
    let dir = elsewhere("at-station");
    let read = |at: &str| {
        let o = skycast_in(
            &dir,
            &[
                "ceilometer",
                &bulk_file(),
                "--at",
                at,
                "--minutes",
                "2",
                "--json",
            ],
            &[],
        );
        assert!(o.status.success(), "{at}: {}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    // KPTD's line of the bulk file: 44.6757,-74.9469.
    assert_eq!(read("kptd"), read("44.6757,-74.9469"));
    let o = skycast_in(&dir, &["ceilometer", &bulk_file(), "--at", "ZZZZ"], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--at ZZZZ: no such station"),
        "{}",
        stderr(&o)
    );
}

/// Mesa's OpenGL driver (llvmpipe through EGL) cannot keep the host's depth as a read-only
/// attachment while sampling it: the sky says so in one line and exits 2. Where a backend can
/// draw the sky, the frame is written.
#[test]
fn the_opengl_backend_gives_a_frame_or_one_clear_error() {
    let dir = elsewhere("gl");
    let out = dir.join("gl.png");
    let o = skycast_in(
        &dir,
        &[
            "render",
            "--weather",
            "weather/themes/fair_weather_cumulus.toml",
            "--at",
            "28.5,-81.45",
            "--alt-ft",
            "2500",
            "--size",
            "64x36",
            "--out",
            out.to_str().expect("utf-8 temp path"),
        ],
        &[("WGPU_BACKEND", "gl")],
    );
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    if o.status.success() {
        assert!(image::open(&out).is_ok(), "a frame: {err}");
    } else {
        assert_eq!(o.status.code(), Some(2), "{err}");
        let lines: Vec<&str> = err
            .lines()
            .filter(|l| l.starts_with("skycast: error:"))
            .collect();
        assert_eq!(lines.len(), 1, "{err}");
        assert!(
            lines[0].contains("graphics") || lines[0].contains("adapter"),
            "{err}"
        );
    }
}

//! `skycast bench` at a tiny size and frame count, so the frame-budget benchmark cannot rot: the
//! table headed by the adapter, `bench.csv` with the three scenarios with impostors on and off,
//! each at the cloud scale asked for and at full resolution, and the plot, a PNG that decodes;
//! `--scenario` and `--impostors` run only part of it, and `--passes` times the sky's passes.

use std::path::PathBuf;

/// Runs `skycast bench` at 64 x 36 with `args`, its output into a fresh directory `name` of
/// the test's temporary directory; returns the directory and what it printed (it must succeed).
fn bench(name: &str, args: &[&str]) -> (PathBuf, String) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_skycast"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", "/tmp")
        .args(["bench", "--size", "64x36"])
        .args(args)
        .args(["--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (dir, stdout)
}

/// A CSV the bench wrote: its header and rows, a cell found by its column's name.
struct Table {
    header: csv::StringRecord,
    rows: Vec<csv::StringRecord>,
}

impl Table {
    fn read(path: &std::path::Path) -> Self {
        let mut reader = csv::Reader::from_path(path).unwrap();
        let header = reader.headers().unwrap().clone();
        let rows = reader.records().map(Result::unwrap).collect();
        Self { header, rows }
    }

    /// The index of column `name` (it must be there).
    fn column(&self, name: &str) -> usize {
        self.header.iter().position(|c| c == name).expect(name)
    }
}

#[test]
fn bench_command_writes_table_csv_and_plot() {
    let (dir, stdout) = bench(
        "bench-command",
        &["--frames", "3", "--view-km", "30", "--cloud-scale", "1/2"],
    );
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines[0].starts_with("skycast bench on "), "{stdout}");
    assert!(lines[0].contains("64x36, 3 frames"), "{stdout}");
    assert!(
        lines[1].split_whitespace().next() == Some("scenario"),
        "{stdout}"
    );
    // Twelve table rows: each scenario with impostors on, then off, at 1/2, then at 1.
    let table: Vec<Vec<&str>> = lines[2..14]
        .iter()
        .map(|l| l.split_whitespace().collect())
        .collect();
    let runs = ["sparse", "scattered", "overcast"]
        .into_iter()
        .flat_map(|s| {
            [("on", "1/2"), ("off", "1/2"), ("on", "1"), ("off", "1")]
                .map(|(impostors, scale)| (s, impostors, scale))
        });
    for (row, (scenario, impostors, scale)) in table.iter().zip(runs) {
        assert_eq!(
            (row[0], row[2], row[3]),
            (scenario, impostors, scale),
            "{stdout}"
        );
    }

    let table = Table::read(&dir.join("bench.csv"));
    let column = |name: &str| table.column(name);
    let rows = &table.rows;
    assert_eq!(rows.len(), 12);
    let number = |r: &csv::StringRecord, name: &str| r[column(name)].parse::<f64>().unwrap();
    for pair in rows.chunks(2) {
        let (on, off) = (&pair[0], &pair[1]);
        assert_eq!(on[column("scenario")], off[column("scenario")]);
        assert_eq!(
            (&on[column("impostors")], &off[column("impostors")]),
            ("on", "off")
        );
        // At 30 km everything fits: both runs drawn, with frame times, and the ratio is theirs.
        assert_eq!(
            (&on[column("drawn")], &off[column("drawn")]),
            ("yes", "yes")
        );
        let (m_on, m_off) = (number(on, "median_ms"), number(off, "median_ms"));
        assert!(m_on > 0.0 && m_off > 0.0, "{on:?} {off:?}");
        assert!(number(on, "p95_ms") >= m_on && number(off, "p95_ms") >= m_off);
        let ratio = number(on, "off_on_ratio");
        assert!(
            (ratio - m_off / m_on).abs() < 0.01 * ratio + 0.002,
            "{on:?} {off:?}"
        );
        // The ring takes the far blocks: fewer sprites with it than without.
        assert!(
            number(on, "sprites_drawn") < number(off, "sprites_drawn"),
            "{on:?} {off:?}"
        );
        assert!(
            on[column("adapter")] == off[column("adapter")] && !on[column("adapter")].is_empty()
        );
        assert_eq!(on[column("cloud_scale")], off[column("cloud_scale")]);
    }
    // Each scenario at 1/2 and at 1; the scale ratios compare a row with its full-resolution
    // twin (1 at full resolution).
    for quad in rows.chunks(4) {
        let scales: Vec<&str> = quad.iter().map(|r| &r[column("cloud_scale")]).collect();
        assert_eq!(scales, ["0.5", "0.5", "1", "1"]);
        for (half, full) in [(&quad[0], &quad[2]), (&quad[1], &quad[3])] {
            let ratio = number(half, "full_scale_ratio");
            let expected = number(full, "median_ms") / number(half, "median_ms");
            assert!((ratio - expected).abs() < 0.01 * ratio + 0.002, "{half:?}");
            assert_eq!(number(full, "full_scale_ratio"), 1.0);
            assert!(number(half, "sky_full_scale_ratio") > 0.0, "{half:?}");
        }
    }
    // The overdraw column: the scenarios' block overdraw, rising sparse -> overcast.
    let overdraw: Vec<f64> = rows.iter().map(|r| number(r, "overdraw_pct")).collect();
    assert!(
        overdraw[0] > 120.0 && overdraw[8] > 2.0 * overdraw[0],
        "{overdraw:?}"
    );

    // One steady frame a sample; before it, with impostors, the frames that rebuild the ring
    // (the 6 km steps are past 15% of the 20 km ring radius), timed as the rebuild column, and
    // the frames that bring the shadow map up to date.
    let frame_table = Table::read(&dir.join("frames.csv"));
    let frames = &frame_table.rows;
    let at =
        |f: &csv::StringRecord, name: &str| -> String { f[frame_table.column(name)].to_string() };
    let steady = |run: &str, scale: &str| {
        frames
            .iter()
            .filter(|f| at(f, "impostors") == run && at(f, "cloud_scale") == scale)
            .filter(|f| at(f, "steady") == "yes")
            .count()
    };
    assert_eq!((steady("on", "0.5"), steady("off", "0.5")), (9, 9));
    assert_eq!((steady("on", "1"), steady("off", "1")), (9, 9));
    let rebuilt = frames
        .iter()
        .filter(|f| at(f, "impostors") == "on" && at(f, "steady") == "no")
        .filter(|f| at(f, "impostors_rebuilt").parse::<u32>().unwrap() > 0)
        .count();
    assert!(rebuilt >= 2 * 3 * 8, "{rebuilt} rebuild frames");
    // A steady frame draws nothing into the cloud shadow map; without the ring, only the frames
    // that draw into it (strips, arriving blocks) come before the steady one.
    let draws_map =
        |f: &csv::StringRecord| at(f, "shadow_sprites") != "0" || at(f, "shadow_texels") != "0";
    assert!(
        frames
            .iter()
            .filter(|f| at(f, "steady") == "yes")
            .all(|f| !draws_map(f))
    );
    assert!(
        frames
            .iter()
            .filter(|f| at(f, "impostors") == "off" && at(f, "steady") == "no")
            .all(draws_map)
    );
    // The cloud target's memory is in the frames: 32 x 18 texels of 8 + 2 + 4 bytes at 1/2,
    // none at 1.
    for f in frames {
        let bytes: u64 = at(f, "cloud_target_bytes").parse().unwrap();
        let expected = if at(f, "cloud_scale") == "1" {
            0
        } else {
            32 * 18 * 14
        };
        assert_eq!(bytes, expected, "{f:?}");
    }
    for pair in rows.chunks(2) {
        assert!(number(&pair[0], "rebuild_ms") > 0.0, "{:?}", pair[0]);
        assert!(pair[1][column("rebuild_ms")].is_empty(), "{:?}", pair[1]);
    }
    let plot = image::open(dir.join("frame_time.png")).unwrap();
    assert!(plot.width() >= 400 && plot.height() >= 200);
    // Lines were drawn: the overcast colour is in it.
    let rgb = plot.to_rgb8();
    assert!(rgb.pixels().any(|p| p.0 == [210, 50, 40]));
}

#[test]
fn bench_runs_only_the_scenario_and_ring_asked_for() {
    let (dir, stdout) = bench(
        "bench-one-scenario",
        &[
            "--frames",
            "2",
            "--view-km",
            "30",
            "--scenario",
            "overcast",
            "--impostors",
            "on",
            "--cloud-scale",
            "1/2",
            "--passes",
        ],
    );
    passes_add_up_to_the_sky(&dir, &stdout);
    let table = Table::read(&dir.join("bench.csv"));
    let column = |name: &str| table.column(name);
    let rows: Vec<(String, String, String)> = table
        .rows
        .iter()
        .map(|r| {
            (
                r[column("scenario")].to_string(),
                r[column("impostors")].to_string(),
                r[column("cloud_scale")].to_string(),
            )
        })
        .collect();
    let row = |scale: &str| ("overcast".to_string(), "on".to_string(), scale.to_string());
    assert_eq!(rows, [row("0.5"), row("1")], "{stdout}");
}

/// `--passes`: the table of where the time goes, and per frame the sky's groups of passes, each
/// timed, together no more than the sky's time around them; below full resolution the
/// downsample and the composite take time, and every frame draws the ring and the sprites.
fn passes_add_up_to_the_sky(dir: &std::path::Path, stdout: &str) {
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("where the sky's GPU time goes")),
        "{stdout}"
    );
    let table = Table::read(&dir.join("frames.csv"));
    let frames = &table.rows;
    let at = |f: &csv::StringRecord, name: &str| -> f64 {
        f[table.column(name)]
            .parse()
            .unwrap_or_else(|_| panic!("{name} in {f:?}"))
    };
    assert!(!frames.is_empty());
    for f in frames {
        let parts = [
            "build_ms",
            "background_ms",
            "far_field_ms",
            "ring_ms",
            "sprites_ms",
            "composite_ms",
        ]
        .map(|name| at(f, name));
        assert!(parts.iter().all(|&ms| ms >= 0.0), "{f:?}");
        let sum: f64 = parts.iter().sum();
        assert!(sum <= at(f, "sky_ms") + 0.5, "{sum} ms of passes in {f:?}");
        assert!(parts[3] > 0.0 && parts[4] > 0.0, "{f:?}");
        if at(f, "cloud_scale") < 1.0 {
            assert!(parts[1] > 0.0 && parts[5] > 0.0, "{f:?}");
        }
    }
}

//! `skycast weather` on a weather model's GRIB2 file: the shipped GFS file alone at a point (its
//! layers and, with `--alt-ft`, the air data, as for report files), under the bulk report file
//! with `--model`, and broken model files (truncated, a field missing): exit status 2 and one
//! message naming the file and what is wrong.

use std::path::PathBuf;
use std::process::{Command, Output};

const GFS: &str = "weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2";
const BULK: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";

fn skycast(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skycast"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the skycast binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("one JSON object")
}

/// The shipped GFS file cut: its first `messages` whole messages, then `extra` bytes of the next.
fn cut_model(name: &str, messages: usize, extra: usize) -> PathBuf {
    let bytes = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2"
    ))
    .unwrap();
    let mut end = 0;
    for _ in 0..messages {
        // Section 0: "GRIB", 2 reserved, discipline, edition, then the total length (8 bytes).
        let length = u64::from_be_bytes(bytes[end + 8..end + 16].try_into().unwrap());
        end += length as usize;
    }
    let dir = std::env::temp_dir().join(format!("skycast-model-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, &bytes[..end + extra]).unwrap();
    path
}

#[test]
fn a_model_file_alone_gives_its_layers_and_air_at_a_point() {
    // Mid-Atlantic, 45N 35W: a grid point of the 2.5 degree grid.
    let out = json(&skycast(&[
        "weather", GFS, "--at", "45,-35", "--alt-ft", "34000", "--json",
    ]));
    assert_eq!(out["format"], "grib2");
    assert_eq!(out["model"]["valid"], "2011-01-15T12Z");
    assert_eq!(out["model"]["levels_hpa"].as_array().unwrap().len(), 26);
    let layers = out["at"]["weather"]["layers"].as_array().unwrap();
    assert!(!layers.is_empty(), "{out}");
    assert!(layers.iter().all(|l| l["type_source"] == "model"), "{out}");
    // The model's own middle layer there: altocumulus about 2 oktas at some 15,000 ft.
    assert!(
        layers.iter().any(|l| l["cloud_type"] == "altocumulus"
            && (l["base_ft_agl"].as_f64().unwrap() - 15_000.0).abs() < 1_500.0),
        "{out}"
    );
    // The wind aloft is the model's, not the settings' profile: some 67 kt from the WSW.
    let air = &out["air"];
    let (from, speed) = (
        air["wind_from_deg"].as_f64().unwrap(),
        air["wind_kt"].as_f64().unwrap(),
    );
    assert!(
        (240.0..275.0).contains(&from) && (55.0..80.0).contains(&speed),
        "{air}"
    );
}

#[test]
fn a_model_goes_under_a_report_file_and_far_in_time_is_a_warning() {
    let o = skycast(&["weather", BULK, "--model", GFS, "--at", "45,-35", "--json"]);
    let out = json(&o);
    assert_eq!(out["reports"], 4909);
    assert_eq!(out["model"]["valid"], "2011-01-15T12Z");
    // 45N 35W is over 1,000 km from any station: the model's layers.
    let layers = out["at"]["weather"]["layers"].as_array().unwrap();
    assert!(layers.iter().all(|l| l["type_source"] == "model"), "{out}");
    let err = stderr(&o);
    assert!(
        err.contains("warning:") && err.contains("the model is valid 2011-01-15 12Z"),
        "{err}"
    );
    // A theme takes no model.
    let o = skycast(&["weather", "weather/themes/high_cirrus.toml", "--model", GFS]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is a weather theme"), "{}", stderr(&o));
}

#[test]
fn a_truncated_or_incomplete_model_file_is_one_clear_error() {
    let truncated = cut_model("truncated.grib2", 200, 1_000);
    let o = skycast(&["weather", truncated.to_str().unwrap(), "--at", "45,-35"]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("truncated.grib2: not a whole GRIB2 file"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");

    // The first 200 messages: isobaric levels but no cloud layers.
    let partial = cut_model("partial.grib2", 200, 0);
    let o = skycast(&["weather", partial.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains(
            "partial.grib2: no low cloud layer cover (parameter 0.6.1 on surface type 214)"
        ),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");

    // The same under a report file.
    let o = skycast(&["weather", BULK, "--model", partial.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("partial.grib2: no low cloud layer cover"),
        "{}",
        stderr(&o)
    );
}

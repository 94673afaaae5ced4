//! `skycast sheet`, `preview` and `block` run as a user runs them, and their errors: exit status
//! 2 with one message naming the file, line and field.

use std::path::PathBuf;
use std::process::{Command, Output};

fn skycast(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skycast"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the skycast binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("skycast-clouds-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn sheet_writes_the_512_pixel_sheet() {
    let path = temp_dir().join("sheet.png");
    let o = skycast(&["sheet", "--out", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&path).expect("a PNG").to_rgba8();
    assert_eq!(img.dimensions(), (512, 512));
    // Cell borders are transparent, cell middles are not.
    assert_eq!(img.get_pixel(128, 64)[3], 0);
    assert!(img.get_pixel(64 + 128 * 2, 64 + 128 * 3)[3] > 100);
}

#[test]
fn block_reports_the_overcast_scenario() {
    let o = skycast(&[
        "block",
        "--weather",
        "weather/scenarios/overcast.metar",
        "--at",
        "60.0167,-111.95",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.starts_with("block (0, 0) at 60.0167,-111.9500: 1 layers, 16 clouds"),
        "{text}"
    );
    assert!(
        text.contains("stratus            8.0 oktas (covered 100%)"),
        "{text}"
    );
    let o = skycast(&[
        "block",
        "--weather",
        "weather/scenarios/overcast.metar",
        "--at",
        "60.0167,-111.95",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    assert_eq!(json["block"]["layers"][0]["cloud_type"], "stratus");
    let sprites = json["sprites"].as_u64().unwrap();
    assert_eq!(
        sprites as usize,
        json["block"]["clouds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["sprites"].as_array().unwrap().len())
            .sum::<usize>()
    );
    assert!((json["overdraw"].as_f64().unwrap() - 4.6).abs() < 0.3);
}

#[test]
fn preview_draws_a_type_and_its_life() {
    let dir = temp_dir();
    let path = dir.join("fog.png");
    let o = skycast(&[
        "preview",
        "--type",
        "fog",
        "--out",
        path.to_str().unwrap(),
        "--width",
        "96",
        "--height",
        "54",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        image::open(&path).unwrap().to_rgba8().dimensions(),
        (96, 54)
    );
    let strip = dir.join("life.png");
    let o = skycast(&[
        "preview",
        "--type",
        "cumulus_humilis",
        "--lifecycle",
        "--out",
        strip.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "40",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        image::open(&strip).unwrap().to_rgba8().dimensions(),
        (64 * 7, 40)
    );
}

#[test]
fn bad_input_exits_2_with_one_clear_message() {
    let o = skycast(&["preview", "--type", "cumulus_giganticus", "--out", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--type cumulus_giganticus: unknown cloud type"),
        "{}",
        stderr(&o)
    );
    // A cloud-types file with a bad field: file, line and field named.
    let text =
        skycast::clouds::config::BUILTIN_CLOUD_TYPES.replacen("taper = 0.3", "taper = 4.5", 1);
    let line = text[..text.find("taper = 4.5").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let path = temp_dir().join("cloud_types.toml");
    std::fs::write(&path, text).unwrap();
    let o = skycast(&[
        "preview",
        "--type",
        "fog",
        "--out",
        "x.png",
        "--types",
        path.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let expected = format!("{}:{line}: field `cumulus_humilis.taper`", path.display());
    assert!(stderr(&o).contains(&expected), "{}", stderr(&o));
    let o = skycast(&[
        "block",
        "--weather",
        "weather/scenarios/sparse.metar",
        "--at",
        "91,0",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not on Earth"), "{}", stderr(&o));
}

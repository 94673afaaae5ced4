//! `skycast weather` run as a user runs it: the summary of the real bulk file, the block at a
//! place (text and JSON), plain and NOAA cycle files placed by the station table, and the errors:
//! exit status 2 with one message naming the file.

use std::path::PathBuf;
use std::process::{Command, Output};

const BULK: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";

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

/// A file in a fresh directory under the system temp dir.
fn temp_file(name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("skycast-weather-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, contents).expect("temp file");
    path
}

#[test]
fn summarises_the_real_bulk_file() {
    let o = skycast(&["weather", BULK]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("aviation weather service metars.cache.csv"),
        "{text}"
    );
    assert!(text.contains("reports 4909, located 4877"), "{text}");
    assert!(text.contains("VV 33"), "{text}");
    // Reports the table cannot place are warnings with their line.
    assert!(
        text.contains("warning: line 72: KQFX: station not in the station table"),
        "{text}"
    );
}

#[test]
fn the_block_at_cork_lists_every_reported_layer() {
    let o = skycast(&["weather", BULK, "--at", "51.848,-8.479", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
    assert_eq!(v["format"], "awc_csv");
    assert_eq!(v["reports"], 4909);
    assert_eq!(v["located"], 4877);
    assert_eq!(v["layers_by_cover"]["VV"], 33);
    let warnings = v["warnings"].as_array().expect("warnings");
    assert!(warnings.iter().all(|w| w["line"].as_u64().unwrap_or(0) > 6));
    let at = &v["at"];
    assert_eq!(at["block"]["i"], 0);
    let layers = at["weather"]["layers"].as_array().expect("layers");
    // EICK: FEW006 SCT018CB BKN035, 6/5 C: three layers, the CB reported, its own type.
    let got: Vec<(String, String, f64)> = layers
        .iter()
        .map(|l| {
            (
                l["cloud_type"].as_str().unwrap_or("").to_string(),
                l["type_source"].as_str().unwrap_or("").to_string(),
                l["base_ft_agl"].as_f64().unwrap_or(-1.0),
            )
        })
        .collect();
    let want = [
        ("cumulus_humilis", "height_rule", 600.0),
        ("cumulonimbus", "reported", 1800.0),
        ("stratocumulus", "height_rule", 3500.0),
    ];
    assert_eq!(got.len(), want.len(), "{at}");
    for ((t, s, b), (wt, ws, wb)) in got.iter().zip(want) {
        assert_eq!((t.as_str(), s.as_str(), *b), (wt, ws, wb), "{at}");
    }
    for l in layers {
        assert!(l["coverage_oktas"].as_f64().is_some_and(|c| c > 0.0), "{l}");
        assert!(l["thickness_ft"].as_f64().is_some_and(|t| t > 0.0), "{l}");
    }
    // The CB grows to its type's height, not a cover's default thickness.
    assert!(
        layers[1]["thickness_ft"].as_f64().unwrap_or(0.0) > 20_000.0,
        "{at}"
    );
    assert_eq!(at["weather"]["visibility_m"], 10000.0);
    let t = at["weather"]["temperature_c"]
        .as_f64()
        .expect("temperature");
    assert!((t - 6.0).abs() < 1.0, "{t}");
}

#[test]
fn text_at_a_place_lists_layers_with_their_type_source() {
    // San Antonio (KSAT) reports OVC020.
    let o = skycast(&["weather", BULK, "--at", "29.533,-98.47"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let block = text
        .lines()
        .skip_while(|l| !l.starts_with("block (0, 0) at 29.5330,-98.4700"))
        .collect::<Vec<_>>();
    assert!(!block.is_empty(), "{text}");
    assert!(
        block
            .iter()
            .any(|l| l.contains("stratus") && l.contains("height_rule")),
        "{text}"
    );
}

#[test]
fn plain_and_cycle_files_are_placed_by_the_station_table() {
    let plain = temp_file(
        "plain.txt",
        "EGLL 272220Z AUTO 19015KT 9999 BKN027 BKN046 08/04 Q0981 NOSIG\n\
         not a report\n\
         LFPG 272200Z 20020KT 9999 BKN025 09/04 Q0993 NOSIG\n",
    );
    let o = skycast(&[
        "weather",
        plain.to_str().unwrap(),
        "--at",
        "51.4775,-0.4614",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("plain METAR lines"), "{text}");
    assert!(text.contains("reports 2, located 2, warnings 1"), "{text}");
    assert!(
        text.contains("warning: line 2: not a METAR report"),
        "{text}"
    );
    assert!(text.contains("stratocumulus"), "{text}");
    let cycle = temp_file(
        "22Z.TXT",
        "2025/01/27 22:20\nEGLL 272220Z AUTO 19015KT 9999 BKN027\n  BKN046 08/04 Q0981 NOSIG\n\n",
    );
    let o = skycast(&["weather", cycle.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("JSON");
    assert_eq!(v["format"], "noaa_cycle");
    assert_eq!(v["located"], 1);
    assert_eq!(v["layers_by_cover"]["BKN"], 2);
}

#[test]
fn a_file_that_is_not_weather_exits_2_with_one_message_naming_it() {
    let o = skycast(&["weather", "Cargo.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("Cargo.toml: not a weather file"), "{err}");
    assert!(stdout(&o).is_empty());
}

#[test]
fn missing_files_and_bad_config_exit_2_naming_them() {
    let o = skycast(&["weather", "weather/no-such-file.csv"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("weather/no-such-file.csv: cannot read"),
        "{}",
        stderr(&o)
    );

    let o = skycast(&["weather", BULK, "--stations", "Cargo.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("Cargo.toml: not a station table"),
        "{}",
        stderr(&o)
    );

    let rule = temp_file(
        "rule.toml",
        "[reported]\ncb = \"cumulonimbus\"\ntcu = \"towering\"\n",
    );
    let o = skycast(&["weather", BULK, "--rule", rule.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("rule.toml:3: field `tcu`"), "{err}");

    let o = skycast(&["weather", BULK, "--at", "95,10"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not on Earth"), "{}", stderr(&o));
}

#[test]
fn themes_and_remarks_show_where_each_type_came_from() {
    let o = skycast(&[
        "weather",
        "weather/themes/building_cumulus_cb_line.toml",
        "--at",
        "28.5,-81.3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("weather theme \"Building cumulus with a Cb line\", pinned to 9 points"),
        "{text}"
    );
    assert!(text.contains("cumulonimbus       theme"), "{text}");
    // CYHY reports BKN098 BKN110 BKN240 RMK AC5AC1CI1: the remark types its layers.
    let o = skycast(&["weather", BULK, "--at", "60.84,-115.78"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("altocumulus        remark"), "{text}");
    let o = skycast(&["weather", "config/flights/cumulonimbus_circle.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a weather theme"), "{}", stderr(&o));
}

/// `--at` with `--alt-ft`: the air data under `"air"` with every field the issue names; at Vigo's
/// elevation (830 ft in the field) the wind and temperature are LEVX's report (33016G27KT 07/05
/// Q1011); 2,000 ft above it, with the regional wind switched off (`--config-dir` with
/// `regional_radius_m = 0`), LEVX's own gradient wind.
#[test]
fn the_air_at_vigo_is_its_report_at_the_ground_and_veered_above() {
    let shipped = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/air.toml"),
    )
    .expect("the shipped air settings");
    assert!(shipped.contains("regional_radius_m = 150000.0"));
    let own_wind = temp_file("regional-off", "")
        .with_extension("d")
        .join("air.toml");
    std::fs::create_dir_all(own_wind.parent().expect("its folder")).expect("a config folder");
    std::fs::write(
        &own_wind,
        shipped.replace("regional_radius_m = 150000.0", "regional_radius_m = 0.0"),
    )
    .expect("air.toml");
    let config_dir = own_wind.parent().expect("its folder").to_string_lossy();
    let air = |ft: &str| {
        let o = skycast(&[
            "weather",
            BULK,
            "--at",
            "42.239,-8.624",
            "--alt-ft",
            ft,
            "--json",
            "--config-dir",
            &config_dir,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("JSON");
        v["air"].clone()
    };
    let ground = air("830");
    for key in [
        "wind_from_deg",
        "wind_kt",
        "gust_kt",
        "temperature_c",
        "dewpoint_c",
        "pressure_hpa",
        "pressure_altitude_ft",
        "visibility_m",
        "in_cloud",
        "turbulence",
        "icing",
        "precipitation_mm_h",
    ] {
        assert!(!ground[key].is_null(), "no {key}: {ground}");
    }
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    assert_eq!(
        (f(&ground, "wind_from_deg"), f(&ground, "wind_kt")),
        (330.0, 16.0)
    );
    assert_eq!(
        (f(&ground, "gust_kt"), f(&ground, "temperature_c")),
        (27.0, 7.0)
    );
    assert!((f(&ground, "qnh_hpa") - 1011.0).abs() < 0.5, "{ground}");
    // 2,000 ft above it: the gradient wind, 30 degrees veered (northern hemisphere).
    let above = air("2830");
    let off = (f(&above, "wind_from_deg") - 360.0 + 540.0).rem_euclid(360.0) - 180.0;
    assert!(off.abs() < 1.0, "{above}");
    assert!(f(&above, "temperature_c") < 7.0);
}

/// `skycast ceilometer` under Atlanta's OVC004 (drizzle and mist): every reading finds the deck's
/// base at 400 ft, and the readings sum up to `OVC004`, the report's own group and ceiling.
#[test]
fn a_ceilometer_under_atlantas_overcast_reads_ovc004() {
    let o = skycast(&[
        "ceilometer",
        BULK,
        "--at",
        "33.6297,-84.4422",
        "--minutes",
        "5",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
    let readings = v["readings"].as_array().expect("readings");
    assert_eq!(readings.len(), 10);
    for r in readings {
        let first = r["bases_ft"][0].as_f64().expect("a base every reading");
        assert!((first - 400.0).abs() <= 50.0, "{r}");
    }
    assert_eq!(v["layers"][0]["group"], "OVC004", "{v}");
    assert_eq!(v["ceiling_ft"], 400.0);
    // A wrong flag value is one line and exit 2.
    let o = skycast(&["ceilometer", BULK, "--at", "33.6,-84.4", "--every-s", "0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--every-s"), "{}", stderr(&o));
}

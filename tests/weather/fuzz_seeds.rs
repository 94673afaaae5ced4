//! Every seed of every fuzz target (`fuzz/seeds/<target>/`) through that target's checks
//! (`fuzz/fuzz_targets/common`), so the corpus the fuzzer starts from is checked on each
//! `cargo test`, with no fuzzer and no nightly compiler.

use std::path::{Path, PathBuf};

#[path = "../../fuzz/fuzz_targets/common/mod.rs"]
mod common;

/// The seeds of one target, sorted; a target without seeds fails (a renamed folder would
/// otherwise check nothing).
fn seeds(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/seeds")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no seeds in {}", dir.display());
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect()
}

/// Runs `check` on every seed, naming the seed that fails.
fn replay(target: &str, check: impl Fn(&[u8]) + std::panic::RefUnwindSafe) -> usize {
    let seeds = seeds(target);
    for (path, bytes) in &seeds {
        if let Err(e) = std::panic::catch_unwind(|| check(bytes)) {
            let why = e
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| e.downcast_ref::<&str>().copied())
                .unwrap_or("");
            panic!("{target} seed {} fails: {why}", path.display());
        }
    }
    seeds.len()
}

fn prefixed(prefix: &str, data: &[u8]) -> Vec<u8> {
    let mut file = prefix.as_bytes().to_vec();
    file.extend_from_slice(data);
    file
}

#[test]
fn every_fuzz_seed_passes_its_targets_checks() {
    let counts = [
        replay("metar_decode", common::check_metar),
        replay("station_table", common::check_station_table),
        replay("weather_file", common::check_weather_file),
        replay("weather_csv", |d| {
            common::check_weather_file(&prefixed(common::CSV_HEADER, d))
        }),
        replay("weather_cycle", |d| {
            common::check_weather_file(&prefixed(common::CYCLE_DATE, d))
        }),
        replay("config_files", common::check_config_files),
        replay("flight_path", common::check_flight_path),
    ];
    assert_eq!(counts, [47, 2, 3, 1, 1, 3, 4]);
}

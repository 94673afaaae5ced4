//! What the command line uses where it is not told: everything is built into the binary (the
//! settings of `config/`, NOAA's station table, the sprite sheet, the fonts, the bench's
//! scenarios, the demo's weather and flight), so an installed `skycast` runs from any directory.
//! `--config-dir DIR` (or `SKYCAST_CONFIG_DIR`) names a folder whose files replace the built-in
//! ones by name: `render.toml`, `time_of_day.toml`, `clouds.toml`, `cloud_types.toml`,
//! `air.toml`, `cloud_type_rule.toml`, `weather_field.toml` and `nsd_cccc.txt` (the station
//! table). A file the folder lacks stays built in; a flag naming a file wins over both.
//!
//! The files the repository ships for users to name (the bulk weather file, the themes, the
//! bench's scenarios, the example views and front, the flights) are built in under their
//! repository paths: `--weather weather/themes/high_cirrus.toml` or `skycast fly
//! config/flights/approach_overcast.toml` read the file where one is there, else the copy in the
//! binary (about 1 MB, most of it the bulk weather file).

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use anyhow::{Context, bail};
use skycast::config::{ConfigError, TomlSettings};
use skycast::weather::StationTable;

/// The environment variable `--config-dir` falls back to.
pub const CONFIG_DIR_ENV: &str = "SKYCAST_CONFIG_DIR";

/// The station table's file name in a config folder.
const STATIONS_FILE: &str = "nsd_cccc.txt";

/// The shipped files built in, by their repository paths.
macro_rules! shipped_files {
    ($($path:literal),* $(,)?) => {
        &[$(($path, include_bytes!(concat!("../../", $path)).as_slice())),*]
    };
}
const SHIPPED: &[(&str, &[u8])] = shipped_files![
    "weather/awc-metars-2025-01-27T22Z.cache.csv",
    "weather/fd1us1-2026-01-31T06Z.txt",
    "weather/themes/building_cumulus_cb_line.toml",
    "weather/themes/fair_weather_cumulus.toml",
    "weather/themes/frontal_nimbostratus.toml",
    "weather/themes/high_cirrus.toml",
    "weather/themes/low_stratus_and_fog.toml",
    "weather/themes/thunderstorm_cells.toml",
    "weather/scenarios/overcast.metar",
    "weather/scenarios/scattered.metar",
    "weather/scenarios/sparse.metar",
    "weather/scenarios/storm.metar",
    "weather/views/high_broken_heathrow.metar",
    "weather/views/low_overcast_heathrow.metar",
    "weather/front/1_clear.txt",
    "weather/front/2_broken.txt",
    "weather/front/3_overcast_rain.txt",
    "config/flights/approach_overcast.toml",
    "config/flights/cruise_fl350_los_angeles_east.toml",
    "config/flights/cruise_scattered_cumulus.toml",
    "config/flights/cumulonimbus_circle.toml",
    "config/flights/demo_coast_under_cumulus.toml",
    "config/flights/front_passing.toml",
    "config/flights/storm_approach.toml",
];

/// The bytes of `path`: the file there, else the built-in copy of a shipped file of that
/// repository path (`None` when neither: the caller reads the path and reports why it cannot).
pub fn shipped(path: &Path) -> Option<&'static [u8]> {
    if path.exists() {
        return None;
    }
    let wanted = path.to_str()?.trim_start_matches("./");
    SHIPPED
        .iter()
        .find(|(name, _)| *name == wanted)
        .map(|(_, bytes)| *bytes)
}

static CONFIG_DIR: OnceLock<Option<PathBuf>> = OnceLock::new();

/// Sets the config folder for the run (once, from `main`); it must be a folder.
pub fn set_config_dir(dir: Option<PathBuf>) -> anyhow::Result<()> {
    if let Some(dir) = &dir
        && !dir.is_dir()
    {
        bail!(
            "--config-dir (or {CONFIG_DIR_ENV}): {}: not a folder",
            dir.display()
        );
    }
    // Set once by `main`; a second call (tests) keeps the first.
    let _ = CONFIG_DIR.set(dir);
    Ok(())
}

/// The config folder's file `name`, if a folder is set and holds it.
fn in_config_dir(name: &str) -> Option<PathBuf> {
    let path = CONFIG_DIR.get()?.as_ref()?.join(name);
    path.is_file().then_some(path)
}

/// The settings file to read: the one a flag names, else the config folder's `name`, else
/// `None` (the built-in settings).
pub fn settings_file(flag: Option<&Path>, name: &str) -> Option<PathBuf> {
    flag.map(Path::to_path_buf).or_else(|| in_config_dir(name))
}

/// Settings of type `T`: the file the flag names, else the config folder's `name`, else the
/// shipped defaults.
pub fn settings<T: TomlSettings>(flag: Option<&Path>, name: &str) -> Result<T, ConfigError> {
    T::load_or_default(settings_file(flag, name).as_deref())
}

/// The station table: the file `--stations` names, else the config folder's `nsd_cccc.txt`,
/// else NOAA's table built into the library.
pub fn station_table(flag: Option<&Path>) -> anyhow::Result<Arc<StationTable>> {
    match settings_file(flag, STATIONS_FILE) {
        Some(path) => Ok(Arc::new(
            StationTable::load(&path).context("station table (choose one with --stations)")?,
        )),
        None => Ok(StationTable::builtin()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flag_wins_and_nothing_set_is_built_in() {
        // No folder is set in unit tests: only a flag names a file.
        assert_eq!(settings_file(None, "render.toml"), None);
        assert_eq!(
            settings_file(Some(Path::new("mine.toml")), "render.toml"),
            Some(PathBuf::from("mine.toml"))
        );
        let table = station_table(None).expect("built in");
        assert!(table.get("EGLL").is_some());
    }

    #[test]
    fn shipped_files_are_built_in_under_their_repository_paths() {
        // Relative to a directory without them, the built-in copy answers.
        let elsewhere = Path::new("/nonexistent/weather/themes/high_cirrus.toml");
        assert_eq!(shipped(elsewhere), None);
        for (name, bytes) in SHIPPED {
            assert!(!bytes.is_empty(), "{name}");
            let on_disk = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(name))
                .expect("shipped file");
            assert_eq!(&on_disk, bytes, "{name}");
        }
    }

    #[test]
    fn a_config_dir_that_is_not_a_folder_is_refused() {
        let err = set_config_dir(Some(PathBuf::from("/nonexistent/skycast-config")))
            .expect_err("no such folder");
        assert!(err.to_string().contains("not a folder"), "{err}");
    }
}

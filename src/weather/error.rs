//! The weather stage's error type and the per-line warnings its readers collect.
//!
//! Errors stop a whole file (it is not weather, a config file does not parse); warnings keep the
//! file going (one report that cannot be placed or decoded) and carry the line they came from.

use std::path::PathBuf;

use serde::Serialize;

/// What went wrong reading weather files, station tables or the weather configuration.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WeatherError {
    /// The file could not be read from disk.
    #[error("{path}: cannot read: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file holds no weather reports in any format skycast reads.
    #[error("{path}: not a weather file: {reason}")]
    NotWeather {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        reason: String,
    },
    /// A bulk file of a known format is broken at one line (for example the CSV header).
    #[error("{path}:{line}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong there.
        message: String,
    },
    /// The station table holds no station at all.
    #[error("{path}: not a station table in NOAA nsd_cccc.txt format: {reason}")]
    NotStationTable {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        reason: String,
    },
    /// A TOML configuration file (the cloud-type rule, the field settings) is wrong; the error
    /// names file, line and field.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
}

/// A problem with one line of an input file that did not stop the file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct LineWarning {
    /// 1-based line of the file.
    pub line: usize,
    /// What is wrong and what was done about it.
    pub message: String,
}

impl std::fmt::Display for LineWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

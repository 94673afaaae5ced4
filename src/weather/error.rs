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
    /// The input was read, but not one of its reports could be used (none placed, none
    /// decoded): an empty sky would hide it, so it is an error. `skipped` says what was left
    /// out and why, counted.
    #[error("{path}: no usable report ({skipped})")]
    NoUsableReport {
        /// The file (or the name given to the bytes).
        path: PathBuf,
        /// What was skipped, counted by reason.
        skipped: Skipped,
    },
    /// A TOML configuration file (the cloud-type rule, the field settings) is wrong; the error
    /// names file, line and field.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// A numerical weather model's file (GRIB2) is broken or lacks a field the reader needs;
    /// the error names file, message and field.
    #[error(transparent)]
    Model(#[from] super::model::ModelError),
}

/// A problem with one line of an input file that did not stop the file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct LineWarning {
    /// 1-based line of the file.
    pub line: usize,
    /// What kind of problem, for counting.
    pub kind: WarningKind,
    /// What is wrong and what was done about it.
    pub message: String,
}

/// What kind of problem a [`LineWarning`] is: reports left out for one reason are counted
/// together ([`Skipped`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum WarningKind {
    /// A report whose station the file does not place and the station table does not hold:
    /// left out.
    NoPosition,
    /// A report the METAR decoder cannot read: left out.
    Undecodable,
    /// A line that is not a report at all (plain text files): skipped.
    NotAReport,
    /// A row of a table (a CSV report file, the station table) that cannot be read: skipped.
    BadRow,
    /// A group of a report that was not understood: the report was kept without it.
    GroupIgnored,
}

impl WarningKind {
    /// Whether a warning of this kind left a whole report or line out.
    pub fn skips(self) -> bool {
        self != Self::GroupIgnored
    }

    /// How `count` of them read in a sentence: "31 reports without a position".
    fn counted(self, count: usize) -> String {
        let s = if count == 1 { "" } else { "s" };
        match self {
            Self::NoPosition => format!("{count} report{s} without a position"),
            Self::Undecodable => format!("{count} undecodable"),
            Self::NotAReport => format!("{count} line{s} not a report"),
            Self::BadRow => format!("{count} unreadable row{s}"),
            Self::GroupIgnored => format!("{count} group{s} not understood"),
        }
    }
}

impl std::fmt::Display for LineWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// What a weather input left out and why, counted by reason: what a host shows or logs after
/// [`crate::SkySystem::set_weather`]. Displays as one line, e.g. "31 reports without a
/// position, lines 2, 7, 9 and 28 more; 2 undecodable, lines 4 and 9".
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Skipped {
    /// Reports the input held.
    pub reports_found: usize,
    /// Reports that were decoded and placed: what the weather is built from.
    pub reports_used: usize,
    /// Each reason with its count and lines, most common first.
    pub counts: Vec<SkipCount>,
    /// Every warning, by line.
    pub warnings: Vec<LineWarning>,
}

/// The warnings of one [`WarningKind`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SkipCount {
    /// The reason.
    pub kind: WarningKind,
    /// How many.
    pub count: usize,
    /// Their lines, in order.
    pub lines: Vec<usize>,
}

/// Lines a [`SkipCount`] names before "and N more".
const LINES_SHOWN: usize = 3;

impl std::fmt::Display for SkipCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shown: Vec<String> = self
            .lines
            .iter()
            .take(LINES_SHOWN)
            .map(usize::to_string)
            .collect();
        let more = self.lines.len().saturating_sub(LINES_SHOWN);
        let lines = match (shown.as_slice(), more) {
            ([one], 0) => format!("line {one}"),
            ([init @ .., last], 0) => format!("lines {} and {last}", init.join(", ")),
            (all, more) => format!("lines {} and {more} more", all.join(", ")),
        };
        write!(f, "{}, {lines}", self.kind.counted(self.count))
    }
}

impl Skipped {
    /// The summary of `warnings` from an input that held `reports_found` reports, of which
    /// `reports_used` were used.
    pub fn new(reports_found: usize, reports_used: usize, warnings: &[LineWarning]) -> Self {
        let mut counts: Vec<SkipCount> = Vec::new();
        for w in warnings {
            match counts.iter_mut().find(|c| c.kind == w.kind) {
                Some(c) => {
                    c.count += 1;
                    c.lines.push(w.line);
                }
                None => counts.push(SkipCount {
                    kind: w.kind,
                    count: 1,
                    lines: vec![w.line],
                }),
            }
        }
        counts.sort_by(|a, b| b.count.cmp(&a.count).then(a.kind.cmp(&b.kind)));
        Self {
            reports_found,
            reports_used,
            counts,
            warnings: warnings.to_vec(),
        }
    }

    /// How many of `kind` there were.
    pub fn count(&self, kind: WarningKind) -> usize {
        self.counts
            .iter()
            .find(|c| c.kind == kind)
            .map_or(0, |c| c.count)
    }

    /// Whether nothing was left out or ignored.
    pub fn is_empty(&self) -> bool {
        self.warnings.is_empty()
    }
}

impl std::fmt::Display for Skipped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.counts.is_empty() {
            return write!(f, "nothing skipped");
        }
        let parts: Vec<String> = self.counts.iter().map(ToString::to_string).collect();
        write!(f, "{}", parts.join("; "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn warning(line: usize, kind: WarningKind) -> LineWarning {
        LineWarning {
            line,
            kind,
            message: String::new(),
        }
    }

    #[test]
    fn warnings_are_counted_by_reason_with_their_lines() {
        let mut warnings: Vec<LineWarning> = (0..31)
            .map(|k| warning(10 + k, WarningKind::NoPosition))
            .collect();
        warnings.push(warning(4, WarningKind::Undecodable));
        warnings.push(warning(9, WarningKind::Undecodable));
        let skipped = Skipped::new(40, 7, &warnings);
        assert_eq!(skipped.count(WarningKind::NoPosition), 31);
        assert_eq!(
            skipped.to_string(),
            "31 reports without a position, lines 10, 11, 12 and 28 more; \
             2 undecodable, lines 4 and 9"
        );
        let one = Skipped::new(2, 1, &[warning(3, WarningKind::NoPosition)]);
        assert_eq!(one.to_string(), "1 report without a position, line 3");
    }
}

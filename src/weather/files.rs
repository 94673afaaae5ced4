//! Bulk weather files in, placed reports out.
//!
//! Three formats, told apart by their content (not their name):
//! - [`FileFormat::AwcCsv`]: the aviation weather service's `metars.cache.csv` export: preamble
//!   lines (`No errors`, ..., `<n> results`), a CSV header starting `raw_text,`, one row a report.
//!   Columns `latitude`, `longitude`, `elevation_m` place the station itself; a row without them
//!   (or with the service's unknown-position sentinel -99.99, -99.99) is placed with the station
//!   table.
//! - [`FileFormat::NoaaCycle`]: NOAA cycle or station files: a date line `2025/01/27 22:00`, then
//!   the report, possibly continued over several lines; blocks separated by blank lines.
//! - [`FileFormat::PlainMetar`]: one report a line (a leading `METAR`/`SPECI` and a trailing `=`
//!   are dropped), placed with the station table.
//!
//! Reading is two steps so each can be tested alone: [`read_raw`] finds the report texts and their
//! lines, [`place`] decodes and locates them. A report that cannot be decoded or placed becomes a
//! [`LineWarning`]; only a file that holds no weather at all (or a broken CSV header) is an error.

use std::fmt::Display;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::error::{LineWarning, WarningKind, WeatherError};
use super::metar::Report;
use super::stations::StationTable;

/// The bulk-file formats skycast reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FileFormat {
    /// The aviation weather service's `metars.cache.csv`.
    AwcCsv,
    /// NOAA cycle/station files: date line, report, blank line.
    NoaaCycle,
    /// One METAR a line.
    PlainMetar,
}

impl FileFormat {
    /// A short human name.
    pub fn describe(self) -> &'static str {
        match self {
            FileFormat::AwcCsv => "aviation weather service metars.cache.csv",
            FileFormat::NoaaCycle => "NOAA cycle file",
            FileFormat::PlainMetar => "plain METAR lines",
        }
    }
}

/// Where a station is, as a file gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Position {
    /// Latitude, degrees north.
    pub latitude_deg: f64,
    /// Longitude, degrees east.
    pub longitude_deg: f64,
    /// Station elevation, metres above mean sea level, when known.
    pub elevation_m: Option<f64>,
}

/// One report's text as found in a file, before decoding.
#[derive(Debug, Clone, PartialEq)]
pub struct RawReport {
    /// 1-based line the report starts on.
    pub line: usize,
    /// The report text (continuation lines joined with single spaces).
    pub text: String,
    /// The position the file itself gives, if any (CSV only).
    pub position: Option<Position>,
}

/// What [`read_raw`] finds in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct RawFile {
    /// The detected format.
    pub format: FileFormat,
    /// Report texts in file order.
    pub reports: Vec<RawReport>,
    /// Lines that were skipped while reading.
    pub warnings: Vec<LineWarning>,
}

/// A decoded report with the place it was observed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacedReport {
    /// The decoded report.
    pub report: Report,
    /// Where the station is.
    pub position: Position,
    /// 1-based line of the file the report starts on.
    pub line: usize,
}

/// A whole weather file, read, decoded and placed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WeatherFile {
    /// The file.
    pub path: PathBuf,
    /// The detected format.
    pub format: FileFormat,
    /// Reports found in the file (decoded or not).
    pub reports_found: usize,
    /// The reports that decoded and could be placed, in file order.
    pub reports: Vec<PlacedReport>,
    /// Reports or lines that were skipped, and group-level decode warnings, by line.
    pub warnings: Vec<LineWarning>,
}

/// Lines searched for the CSV header.
pub(crate) const CSV_HEADER_SEARCH_LINES: usize = 10;

/// Reads a weather file from disk, decodes its reports with the METAR decoder and places them
/// (with `stations` where the file gives no position).
pub fn load(path: &Path, stations: Option<&StationTable>) -> Result<WeatherFile, WeatherError> {
    let bytes = std::fs::read(path).map_err(|source| WeatherError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(path, &bytes, stations)
}

/// [`load`] on bytes already in memory; `path` names the file in errors and the result.
pub fn parse(
    path: &Path,
    bytes: &[u8],
    stations: Option<&StationTable>,
) -> Result<WeatherFile, WeatherError> {
    let raw = read_raw(path, bytes)?;
    let (reports, warnings) = place(&raw, stations, super::metar::decode);
    Ok(WeatherFile {
        path: path.to_path_buf(),
        format: raw.format,
        reports_found: raw.reports.len(),
        reports,
        warnings,
    })
}

/// Finds the report texts of a file. `path` only names the file in errors.
pub fn read_raw(path: &Path, bytes: &[u8]) -> Result<RawFile, WeatherError> {
    let not_weather = |reason: &str| WeatherError::NotWeather {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    if bytes.contains(&0) {
        return Err(not_weather("binary data (NUL bytes)"));
    }
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.lines().map(|l| l.trim_end_matches('\r')).collect();
    if lines.iter().all(|l| l.trim().is_empty()) {
        return Err(not_weather("the file is empty"));
    }
    let header = lines
        .iter()
        .take(CSV_HEADER_SEARCH_LINES)
        .position(|l| l.starts_with("raw_text,") || *l == "raw_text");
    let raw = if let Some(header_index) = header {
        read_awc_csv(path, &lines, header_index)?
    } else if lines
        .iter()
        .find(|l| !l.trim().is_empty())
        .is_some_and(|l| is_date_line(l))
    {
        read_noaa_cycle(&lines)
    } else {
        read_plain(&lines)
    };
    if !raw.reports.iter().any(|r| looks_like_metar(&r.text)) {
        let first = lines.iter().find(|l| !l.trim().is_empty()).unwrap_or(&"");
        let shown: String = first.chars().take(40).collect();
        return Err(not_weather(&format!(
            "no METAR report found (read as {}; first line `{shown}`)",
            raw.format.describe()
        )));
    }
    Ok(raw)
}

/// Decodes and places raw reports. Reports with a position of their own keep it; the others are
/// placed by station id with `stations`. Failures become warnings with the report's line.
pub fn place<E: Display>(
    raw: &RawFile,
    stations: Option<&StationTable>,
    decode: impl Fn(&str) -> Result<Report, E>,
) -> (Vec<PlacedReport>, Vec<LineWarning>) {
    let mut placed = Vec::with_capacity(raw.reports.len());
    let mut warnings = raw.warnings.clone();
    for r in &raw.reports {
        let report = match decode(&r.text) {
            Ok(report) => report,
            Err(err) => {
                warnings.push(LineWarning {
                    line: r.line,
                    kind: WarningKind::Undecodable,
                    message: format!("cannot decode `{}`: {err}", shorten(&r.text)),
                });
                continue;
            }
        };
        for w in &report.warnings {
            warnings.push(LineWarning {
                line: r.line,
                kind: WarningKind::GroupIgnored,
                message: format!("{}: {w}", report.station),
            });
        }
        let position = r.position.or_else(|| {
            stations
                .and_then(|s| s.get(&report.station))
                .map(|s| Position {
                    latitude_deg: s.latitude_deg,
                    longitude_deg: s.longitude_deg,
                    elevation_m: s.elevation_m,
                })
        });
        match position {
            Some(position) => placed.push(PlacedReport {
                report,
                position,
                line: r.line,
            }),
            None => warnings.push(LineWarning {
                line: r.line,
                kind: WarningKind::NoPosition,
                message: match stations {
                    Some(_) => format!(
                        "{}: station not in the station table, report left out",
                        report.station
                    ),
                    None => format!("{}: no position and no station table", report.station),
                },
            }),
        }
    }
    warnings.sort_by_key(|w| w.line);
    (placed, warnings)
}

fn read_awc_csv(path: &Path, lines: &[&str], header_index: usize) -> Result<RawFile, WeatherError> {
    let body = lines[header_index..].join("\n");
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(body.as_bytes());
    let header_line = header_index + 1;
    let headers = reader
        .headers()
        .map_err(|e| WeatherError::Malformed {
            path: path.to_path_buf(),
            line: header_line,
            message: format!("CSV header: {e}"),
        })?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h.trim() == name);
    let raw_text = column("raw_text").ok_or_else(|| WeatherError::Malformed {
        path: path.to_path_buf(),
        line: header_line,
        message: "CSV header has no `raw_text` column".to_string(),
    })?;
    let (lat, lon, elev) = (
        column("latitude"),
        column("longitude"),
        column("elevation_m"),
    );
    let mut reports = Vec::new();
    let mut warnings = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let line = header_index + reader.position().line() as usize;
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                warnings.push(LineWarning {
                    line,
                    kind: WarningKind::BadRow,
                    message: format!("CSV row skipped: {e}"),
                });
                continue;
            }
        }
        let line = header_index + record.position().map_or(line as u64, |p| p.line()) as usize;
        let text = record.get(raw_text).unwrap_or("").trim();
        if text.is_empty() {
            warnings.push(LineWarning {
                line,
                kind: WarningKind::BadRow,
                message: "row has no raw_text, skipped".to_string(),
            });
            continue;
        }
        let number = |i: Option<usize>| {
            i.and_then(|i| record.get(i))
                .and_then(|f| f.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
        };
        let position = match (number(lat), number(lon)) {
            (Some(la), Some(lo)) if la.abs() <= 90.0 && lo.abs() <= 180.0 => Some(Position {
                latitude_deg: la,
                longitude_deg: lo,
                elevation_m: number(elev),
            }),
            _ => None,
        };
        reports.push(RawReport {
            line,
            text: clean_report(text),
            position,
        });
    }
    Ok(RawFile {
        format: FileFormat::AwcCsv,
        reports,
        warnings,
    })
}

fn read_noaa_cycle(lines: &[&str]) -> RawFile {
    let mut reports = Vec::new();
    let mut current: Option<RawReport> = None;
    let mut flush = |current: &mut Option<RawReport>| {
        if let Some(r) = current.take() {
            reports.push(RawReport {
                text: clean_report(&r.text),
                ..r
            });
        }
    };
    for (index, l) in lines.iter().enumerate() {
        let t = l.trim();
        if t.is_empty() || is_date_line(t) {
            flush(&mut current);
            continue;
        }
        match current.as_mut() {
            Some(r) => {
                r.text.push(' ');
                r.text.push_str(t);
            }
            None => {
                current = Some(RawReport {
                    line: index + 1,
                    text: t.to_string(),
                    position: None,
                })
            }
        }
    }
    flush(&mut current);
    RawFile {
        format: FileFormat::NoaaCycle,
        reports,
        warnings: Vec::new(),
    }
}

fn read_plain(lines: &[&str]) -> RawFile {
    let mut reports = Vec::new();
    let mut warnings = Vec::new();
    for (index, l) in lines.iter().enumerate() {
        let t = l.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        if looks_like_metar(t) {
            reports.push(RawReport {
                line: index + 1,
                text: clean_report(t),
                position: None,
            });
        } else {
            warnings.push(LineWarning {
                line: index + 1,
                kind: WarningKind::NotAReport,
                message: format!("not a METAR report, skipped: `{}`", shorten(t)),
            });
        }
    }
    RawFile {
        format: FileFormat::PlainMetar,
        reports,
        warnings,
    }
}

/// `YYYY/MM/DD HH:MM`, NOAA's date line.
fn is_date_line(line: &str) -> bool {
    let b = line.trim().as_bytes();
    b.len() == 16
        && b.iter().enumerate().all(|(i, &c)| match i {
            4 | 7 => c == b'/',
            10 => c == b' ',
            13 => c == b':',
            _ => c.is_ascii_digit(),
        })
}

/// A station id (4 letters/digits, at least one letter) then a `DDHHMMZ` time, after an optional
/// `METAR`/`SPECI` (and `COR`).
pub fn looks_like_metar(text: &str) -> bool {
    let mut tokens = text
        .split_whitespace()
        .skip_while(|t| matches!(*t, "METAR" | "SPECI" | "COR"));
    let station = tokens.next().unwrap_or("");
    let time = tokens.next().unwrap_or("");
    station.len() == 4
        && station
            .bytes()
            .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit())
        && station.bytes().any(|b| b.is_ascii_uppercase())
        && time.len() == 7
        && time.ends_with('Z')
        && time.bytes().take(6).all(|b| b.is_ascii_digit())
}

/// Drops a leading `METAR`/`SPECI` and a trailing `=`, and squeezes whitespace.
fn clean_report(text: &str) -> String {
    let mut tokens: Vec<&str> = text.split_whitespace().collect();
    if matches!(tokens.first(), Some(&"METAR") | Some(&"SPECI")) {
        tokens.remove(0);
    }
    let mut out = tokens.join(" ");
    while out.ends_with('=') {
        out.pop();
    }
    out.truncate(out.trim_end().len());
    out
}

/// The first 60 characters of a text, for messages.
fn shorten(text: &str) -> String {
    let mut s: String = text.chars().take(60).collect();
    if s.len() < text.len() {
        s.push_str("...");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::stations::StationTable;

    /// A stand-in decoder for these tests: takes the station id, fails on `GARBAGE`.
    fn decode(text: &str) -> Result<Report, String> {
        if text.contains("GARBAGE") {
            return Err("garbage".to_string());
        }
        Ok(Report {
            station: text.split_whitespace().next().unwrap_or("").to_string(),
            ..Report::default()
        })
    }

    const CSV: &str = "No errors\nNo warnings\n102 ms\ndata source=metars\n3 results\n\
raw_text,station_id,observation_time,latitude,longitude,temp_c,elevation_m\n\
EGLL 272220Z AUTO 19015KT 9999 BKN027 BKN046 08/04 Q0981 NOSIG,EGLL,2025-01-27T22:20:00Z,51.477,-0.461,8,24\n\
LFBT 272200Z AUTO 29017KT 9999 FEW070 OVC200 10/04 Q1004 NOSIG,LFBT,2025-01-27T22:00:00Z,43.189,,10,359\n\
KJFK 272151Z 25013KT 10SM FEW250 04/M11 A2983 RMK AO2 SLP100 T00441106,KJFK,2025-01-27T21:51:00Z,40.6392,-73.7639,4.4,\n";

    const STATIONS: &str = "EGLL;03;772;London / Heathrow Airport;;United Kingdom;6;51-28N;000-27W;51-29N;000-27W;24;24;P\r\n\
LFBT;07;621;Tarbes / Ossun;;France;6;43-11N;000-00W;;;360;;\r\n";

    fn stations() -> StationTable {
        StationTable::parse(Path::new("nsd_cccc.txt"), STATIONS).unwrap()
    }

    #[test]
    fn csv_rows_place_themselves_with_their_line() {
        let raw = read_raw(Path::new("m.csv"), CSV.as_bytes()).unwrap();
        assert_eq!(raw.format, FileFormat::AwcCsv);
        assert_eq!(raw.reports.len(), 3);
        assert_eq!(raw.reports[0].line, 7);
        assert!(raw.reports[0].text.starts_with("EGLL 272220Z AUTO"));
        assert!(raw.reports[0].text.ends_with("NOSIG"));
        let p = raw.reports[0].position.unwrap();
        assert_eq!(
            (p.latitude_deg, p.longitude_deg, p.elevation_m),
            (51.477, -0.461, Some(24.0))
        );
        // No longitude in the row: placed later by the station table.
        assert_eq!(raw.reports[1].position, None);
        assert_eq!(raw.reports[2].position.unwrap().elevation_m, None);
        assert_eq!(raw.reports[2].line, 9);
    }

    #[test]
    fn csv_rows_without_position_fall_back_to_the_table() {
        let raw = read_raw(Path::new("m.csv"), CSV.as_bytes()).unwrap();
        let (placed, warnings) = place(&raw, Some(&stations()), decode);
        assert_eq!(placed.len(), 3, "{warnings:?}");
        let lfbt = &placed[1];
        assert_eq!(lfbt.report.station, "LFBT");
        assert!((lfbt.position.latitude_deg - (43.0 + 11.0 / 60.0)).abs() < 1e-9);
        assert_eq!(lfbt.position.elevation_m, Some(360.0));
        // Without a table the row is a warning, not a failure.
        let (placed, warnings) = place(&raw, None, decode);
        assert_eq!(placed.len(), 2);
        assert_eq!(warnings.len(), 1);
        assert_eq!(warnings[0].line, 8);
        assert!(warnings[0].message.starts_with("LFBT"), "{}", warnings[0]);
    }

    #[test]
    fn csv_without_raw_text_column_names_the_header_line() {
        let text = "No errors\nstation_id,latitude\nEGLL,51\n";
        // No `raw_text` header at all: read as plain lines, which hold no METAR.
        let err = read_raw(Path::new("x.csv"), text.as_bytes()).unwrap_err();
        assert!(
            err.to_string().starts_with("x.csv: not a weather file"),
            "{err}"
        );
        let text = "raw_text\n\"EGLL 272220Z AUTO 19015KT\"\n";
        let raw = read_raw(Path::new("y.csv"), text.as_bytes()).unwrap();
        assert_eq!(raw.reports[0].line, 2);
    }

    /// Two real reports as NOAA's cycle files carry them (the second continued over a line).
    const CYCLE: &str = "2025/01/27 22:00\n\
EGLL 272220Z AUTO 19015KT 9999 BKN027 BKN046 08/04 Q0981 NOSIG\n\
\n\
2025/01/27 22:00\n\
LFBT 272200Z AUTO 29017KT 9999 FEW070\n     OVC200 10/04 Q1004 NOSIG=\n\
\n\
2025/01/27 22:00\n\
KXXX 272200Z GARBAGE\n";

    #[test]
    fn noaa_cycle_reports_join_continuations() {
        let raw = read_raw(Path::new("22Z.TXT"), CYCLE.as_bytes()).unwrap();
        assert_eq!(raw.format, FileFormat::NoaaCycle);
        assert_eq!(raw.reports.len(), 3);
        assert_eq!(raw.reports[1].line, 5);
        assert_eq!(
            raw.reports[1].text,
            "LFBT 272200Z AUTO 29017KT 9999 FEW070 OVC200 10/04 Q1004 NOSIG"
        );
        let (placed, warnings) = place(&raw, Some(&stations()), decode);
        assert_eq!(placed.len(), 2);
        assert_eq!(placed[0].position.elevation_m, Some(24.0));
        assert_eq!(warnings.len(), 1);
        assert_eq!(warnings[0].line, 9);
        assert!(
            warnings[0].message.contains("cannot decode"),
            "{}",
            warnings[0]
        );
    }

    #[test]
    fn plain_lines_skip_non_reports_and_unknown_stations() {
        let text = "METAR EGLL 272220Z AUTO 19015KT 9999 BKN027 BKN046 08/04 Q0981 NOSIG=\r\n\
# a comment\r\n\
hello world\r\n\
ZZZZ 272200Z 00000KT CAVOK 10/04 Q1004\r\n";
        let raw = read_raw(Path::new("plain.txt"), text.as_bytes()).unwrap();
        assert_eq!(raw.format, FileFormat::PlainMetar);
        assert_eq!(raw.reports.len(), 2);
        assert!(raw.reports[0].text.starts_with("EGLL 272220Z"));
        assert!(raw.reports[0].text.ends_with("NOSIG"));
        let (placed, warnings) = place(&raw, Some(&stations()), decode);
        assert_eq!(placed.len(), 1);
        let lines: Vec<usize> = warnings.iter().map(|w| w.line).collect();
        assert_eq!(lines, vec![3, 4]);
        assert!(
            warnings[1]
                .message
                .contains("ZZZZ: station not in the station table")
        );
    }

    #[test]
    fn files_that_are_not_weather_are_errors_naming_them() {
        for (bytes, why) in [
            (&b""[..], "empty"),
            (&b"\n \n"[..], "empty"),
            (&b"\x7fELF\x02\x01\x01\0\0"[..], "binary"),
            (&b"[package]\nname = \"skycast\"\n"[..], "no METAR report"),
            (&b"2025/01/27 22:00\nhello\n"[..], "no METAR report"),
        ] {
            let err = read_raw(Path::new("Cargo.toml"), bytes).unwrap_err();
            let text = err.to_string();
            assert!(text.starts_with("Cargo.toml: not a weather file"), "{text}");
            assert!(text.contains(why), "{text}");
        }
    }

    #[test]
    fn metar_shape() {
        assert!(looks_like_metar("KJFK 272151Z 25013KT"));
        assert!(looks_like_metar("SPECI K1A5 272151Z"));
        assert!(!looks_like_metar("1234 272151Z"));
        assert!(!looks_like_metar("KJFK 2721Z"));
        assert!(!looks_like_metar("kjfk 272151Z"));
    }

    #[test]
    fn the_real_bulk_file_reads_every_row() {
        let path = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/weather/awc-metars-2025-01-27T22Z.cache.csv"
        ));
        let raw = read_raw(path, &std::fs::read(path).unwrap()).unwrap();
        assert_eq!(raw.format, FileFormat::AwcCsv);
        assert_eq!(raw.reports.len(), 4909);
        assert!(raw.warnings.is_empty(), "{:?}", raw.warnings);
        // 32 rows carry the service's unknown-position sentinel -99.99/-99.99, one (LFBT) no
        // longitude: they are placed by the station table when it knows them.
        assert_eq!(
            raw.reports.iter().filter(|r| r.position.is_none()).count(),
            33
        );
        assert_eq!(raw.reports.last().unwrap().line, 4915);
    }

    #[test]
    fn the_real_bulk_file_places_nearly_every_report() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/weather"));
        let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
        let path = dir.join("awc-metars-2025-01-27T22Z.cache.csv");
        let file = load(&path, Some(&stations)).unwrap();
        assert_eq!(file.reports_found, 4909);
        let unplaced: Vec<&LineWarning> = file
            .warnings
            .iter()
            .filter(|w| w.message.contains("station not in the station table"))
            .collect();
        // Of the 33 rows without a position the table knows only LFBT; the 32 others (US
        // military KQ.. sites and a few more) are warnings, not failures.
        assert_eq!(
            file.reports.len() + unplaced.len(),
            4909,
            "{:?}",
            file.warnings
        );
        assert_eq!(file.reports.len(), 4877);
        assert!(file.reports.iter().any(|r| r.report.station == "LFBT"));
        let egll = file
            .reports
            .iter()
            .find(|r| r.report.station == "EGLL")
            .unwrap();
        assert_eq!(egll.line, 192);
        assert_eq!(egll.report.clouds.len(), 2);
        // The file's own elevation (the station table says 24 m).
        assert_eq!(egll.position.elevation_m, Some(26.0));
    }
}

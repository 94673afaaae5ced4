//! NOAA's station table (`nsd_cccc.txt`): where each ICAO station is, to place reports from files
//! that carry no coordinates (plain METAR lines, NOAA cycle files).
//!
//! Format: one station a line, `;`-separated, CRLF or LF line ends. Field 1 is the ICAO id,
//! fields 8 and 9 latitude and longitude as degrees-minutes[-seconds] with a hemisphere letter
//! (`51-28N`, `000-27W`, `37-03-52N`), field 12 the elevation in metres (may be empty). A few rows
//! of the real table lack a field before the coordinates; the reader takes the first adjacent
//! latitude/longitude pair from field 7 on, and the elevation four fields after the latitude.
//! Rows that still cannot be read are skipped with a [`LineWarning`]; a file with no station at
//! all is an error.
//!
//! The library carries the table itself ([`StationTable::builtin`]): `weather/nsd_cccc.txt`
//! gzipped into `assets/stations/nsd_cccc.txt.gz` (179 KB in the binary instead of 526 KB; the
//! `png` decoder already links `flate2`), decompressed and parsed once, on first use. A host
//! passes its own table where it has a newer one.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;
use std::sync::{Arc, OnceLock};

use super::error::{LineWarning, WarningKind, WeatherError};

/// One station of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// ICAO identifier, upper case.
    pub id: String,
    /// Place name as the table gives it.
    pub name: String,
    /// Latitude, degrees north (negative south).
    pub latitude_deg: f64,
    /// Longitude, degrees east (negative west).
    pub longitude_deg: f64,
    /// Elevation above mean sea level, metres; `None` where the table leaves it empty.
    pub elevation_m: Option<f64>,
}

/// The station table: stations by ICAO id, plus the rows that were skipped.
#[derive(Debug, Clone, Default)]
pub struct StationTable {
    stations: HashMap<String, Station>,
    /// Rows that could not be read, with their line numbers.
    pub skipped: Vec<LineWarning>,
}

/// NOAA's table as the library ships it: `gzip -9 -n -c weather/nsd_cccc.txt`
/// (a test checks it holds the same bytes as the file).
const BUILTIN_GZ: &[u8] = include_bytes!("../../assets/stations/nsd_cccc.txt.gz");

impl StationTable {
    /// NOAA's station table as shipped inside the library (6,510 stations from its 6,519
    /// rows): decompressed and parsed on the first call, shared after.
    pub fn builtin() -> Arc<StationTable> {
        static TABLE: OnceLock<Arc<StationTable>> = OnceLock::new();
        Arc::clone(TABLE.get_or_init(|| {
            // The bytes are the library's own and checked by its tests: a failure here is a
            // broken build, and an empty table (every report then unplaced, each warned about)
            // is the safe answer.
            let text = builtin_text().unwrap_or_default();
            Arc::new(Self::parse(Path::new("nsd_cccc.txt (built in)"), &text).unwrap_or_default())
        }))
    }
    /// Reads a station table from disk.
    pub fn load(path: &Path) -> Result<Self, WeatherError> {
        let bytes = std::fs::read(path).map_err(|source| WeatherError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, &String::from_utf8_lossy(&bytes))
    }

    /// Parses the text of a station table; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Self, WeatherError> {
        let mut table = StationTable::default();
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            let row = raw.trim_end_matches('\r');
            if row.trim().is_empty() {
                continue;
            }
            match parse_row(row) {
                Ok(station) => {
                    // The first row of an id wins; the real table has no duplicates.
                    table.stations.entry(station.id.clone()).or_insert(station);
                }
                Err(message) => table.skipped.push(LineWarning {
                    line,
                    kind: WarningKind::BadRow,
                    message,
                }),
            }
        }
        if table.stations.is_empty() {
            let reason = match table.skipped.first() {
                Some(w) => format!("no station could be read (line {}: {})", w.line, w.message),
                None => "the file is empty".to_string(),
            };
            return Err(WeatherError::NotStationTable {
                path: path.to_path_buf(),
                reason,
            });
        }
        Ok(table)
    }

    /// The station with this ICAO id (case-insensitive).
    pub fn get(&self, id: &str) -> Option<&Station> {
        self.stations
            .get(id)
            .or_else(|| self.stations.get(&id.to_ascii_uppercase()))
    }

    /// Number of stations.
    pub fn len(&self) -> usize {
        self.stations.len()
    }

    /// True when the table holds no station.
    pub fn is_empty(&self) -> bool {
        self.stations.is_empty()
    }
}

/// The shipped table's text.
fn builtin_text() -> std::io::Result<String> {
    let mut text = String::new();
    flate2::read::GzDecoder::new(BUILTIN_GZ).read_to_string(&mut text)?;
    Ok(text)
}

/// One row, or why it cannot be read.
fn parse_row(row: &str) -> Result<Station, String> {
    let fields: Vec<&str> = row.split(';').map(str::trim).collect();
    let id = fields[0];
    if id.len() != 4 || !id.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return Err(format!("field 1: `{id}` is not a 4-character ICAO id"));
    }
    // Field 8 (index 7) normally; index 6 in rows missing the state field.
    let lat_index = (6..fields.len().saturating_sub(1))
        .find(|&i| parse_angle(fields[i], 'N', 'S').is_some() && parse_angle(fields[i + 1], 'E', 'W').is_some())
        .ok_or_else(|| {
            format!(
                "fields 8-9: no latitude/longitude pair like `51-28N;000-27W` (found `{}` and `{}`)",
                fields.get(7).unwrap_or(&""),
                fields.get(8).unwrap_or(&"")
            )
        })?;
    let latitude_deg = parse_angle(fields[lat_index], 'N', 'S').unwrap_or_default();
    let longitude_deg = parse_angle(fields[lat_index + 1], 'E', 'W').unwrap_or_default();
    if latitude_deg.abs() > 90.0 || longitude_deg.abs() > 180.0 {
        return Err(format!(
            "fields 8-9: {latitude_deg} {longitude_deg} is not on Earth"
        ));
    }
    let elevation_m = fields
        .get(lat_index + 4)
        .and_then(|f| f.parse::<f64>().ok())
        .filter(|e| e.is_finite());
    Ok(Station {
        id: id.to_ascii_uppercase(),
        name: fields.get(3).unwrap_or(&"").to_string(),
        latitude_deg,
        longitude_deg,
        elevation_m,
    })
}

/// `DD-MM[-SS]H` or `DDD-MM[-SS]H` to signed degrees; `positive`/`negative` are the hemisphere
/// letters. `None` when the text is not such an angle.
fn parse_angle(text: &str, positive: char, negative: char) -> Option<f64> {
    let (sign, body) = match text.chars().last()? {
        c if c == positive => (1.0, &text[..text.len() - 1]),
        c if c == negative => (-1.0, &text[..text.len() - 1]),
        // A zero angle needs no hemisphere (`000-00` in a few rows of the real table).
        c if c.is_ascii_digit() && text.bytes().all(|b| b == b'0' || b == b'-') => (1.0, text),
        _ => return None,
    };
    let mut parts = body.split('-');
    let mut value = 0.0;
    let mut scale = 1.0;
    let mut count = 0;
    for part in parts.by_ref() {
        if part.is_empty() || part.len() > 3 || !part.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let n: f64 = part.parse().ok()?;
        if count > 0 && n >= 60.0 {
            return None;
        }
        value += n / scale;
        scale *= 60.0;
        count += 1;
        if count > 3 {
            return None;
        }
    }
    (count >= 2).then_some(sign * value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Real rows of weather/nsd_cccc.txt, CRLF as shipped, with the odd ones.
    const EXCERPT: &str = "EGLL;03;772;London / Heathrow Airport;;United Kingdom;6;51-28N;000-27W;51-29N;000-27W;24;24;P\r\n\
AGGH;91;520;Honiara / Henderson;;Solomon Islands;5;09-25S;160-03E;;;8;9;P\r\n\
KCIR;--;---;Cairo, Cairo Regional Airport,IL;United States;4;37-03-52N;089-13-10W;;;98;;\r\n\
KORS;--;---;Eastsound, Orcas Island Airport;WA;United States;4;48-42-29;122-54-37W;;;9;;\r\n\
CXBK;71;569;Bratts Lake, Sask.;;Canada;4;50-12N;104-42W;;580;;\r\n";

    #[test]
    fn the_builtin_table_is_the_shipped_file() {
        let file =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/weather/nsd_cccc.txt"))
                .unwrap();
        assert!(
            builtin_text().unwrap() == file,
            "assets/stations/nsd_cccc.txt.gz is stale"
        );
        let table = StationTable::builtin();
        assert_eq!(table.len(), 6_510, "{:?}", table.skipped);
        let egll = table.get("EGLL").unwrap();
        assert!((egll.latitude_deg - 51.47).abs() < 0.02, "{egll:?}");
    }

    fn table() -> StationTable {
        StationTable::parse(Path::new("nsd_cccc.txt"), EXCERPT).unwrap()
    }

    #[test]
    fn reads_degrees_minutes_and_hemispheres() {
        let t = table();
        let egll = t.get("EGLL").unwrap();
        assert!((egll.latitude_deg - (51.0 + 28.0 / 60.0)).abs() < 1e-12);
        assert!((egll.longitude_deg + 27.0 / 60.0).abs() < 1e-12);
        assert_eq!(egll.elevation_m, Some(24.0));
        assert_eq!(egll.name, "London / Heathrow Airport");
        let aggh = t.get("aggh").unwrap();
        assert!((aggh.latitude_deg + (9.0 + 25.0 / 60.0)).abs() < 1e-12);
        assert!((aggh.longitude_deg - (160.0 + 3.0 / 60.0)).abs() < 1e-12);
    }

    #[test]
    fn reads_seconds_and_rows_missing_a_field() {
        let t = table();
        let kcir = t.get("KCIR").unwrap();
        assert!((kcir.latitude_deg - (37.0 + 3.0 / 60.0 + 52.0 / 3600.0)).abs() < 1e-12);
        assert!((kcir.longitude_deg + (89.0 + 13.0 / 60.0 + 10.0 / 3600.0)).abs() < 1e-12);
        assert_eq!(kcir.elevation_m, Some(98.0));
        // Elevation only in field 11: field 12 is empty, so unknown.
        assert_eq!(t.get("CXBK").unwrap().elevation_m, None);
    }

    #[test]
    fn skips_rows_without_hemisphere_with_their_line() {
        let t = table();
        assert_eq!(t.len(), 4);
        assert!(t.get("KORS").is_none());
        assert_eq!(t.skipped.len(), 1);
        assert_eq!(t.skipped[0].line, 4);
        assert!(
            t.skipped[0].message.contains("48-42-29"),
            "{}",
            t.skipped[0].message
        );
    }

    #[test]
    fn a_file_with_no_station_is_an_error_naming_it() {
        let err = StationTable::parse(Path::new("notes.txt"), "hello;world\n").unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("notes.txt: not a station table"), "{text}");
        assert!(text.contains("line 1"), "{text}");
        assert!(StationTable::parse(Path::new("e.txt"), "").is_err());
    }

    #[test]
    fn the_real_table_reads_almost_every_row() {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/weather/nsd_cccc.txt"));
        let t = StationTable::load(path).unwrap();
        // 6,519 rows; nine carry an angle without its hemisphere letter (or with the wrong one, or
        // 87 minutes) and cannot be placed.
        assert_eq!(t.len() + t.skipped.len(), 6519);
        assert_eq!(t.skipped.len(), 9, "{:?}", t.skipped);
        let lfbt = t.get("LFBT").unwrap();
        assert_eq!(lfbt.longitude_deg, 0.0);
        let lgav = t.get("LGAV").unwrap();
        assert!((lgav.latitude_deg - (37.0 + 56.0 / 60.0)).abs() < 1e-12);
        assert_eq!(lgav.elevation_m, Some(94.0));
    }

    #[test]
    fn angles_reject_garbage() {
        assert_eq!(parse_angle("51-28N", 'N', 'S'), Some(51.0 + 28.0 / 60.0));
        assert_eq!(parse_angle("51N", 'N', 'S'), None);
        assert_eq!(parse_angle("51-75N", 'N', 'S'), None);
        assert_eq!(parse_angle("51-28E", 'N', 'S'), None);
        assert_eq!(parse_angle("N", 'N', 'S'), None);
        assert_eq!(parse_angle("000-00", 'E', 'W'), Some(0.0));
        assert_eq!(parse_angle("069-35", 'E', 'W'), None);
        assert_eq!(parse_angle("", 'N', 'S'), None);
        assert_eq!(parse_angle("5é-1N", 'N', 'S'), None);
    }
}

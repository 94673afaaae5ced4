//! NOAA's winds and temperatures aloft forecast, the FB text product (FD1US1 and its kin: wind
//! and temperature at 3,000 to 39,000 ft over more than 170 US sites), read and blended between
//! sites as the METARs are.
//!
//! The product (NWS Directive 10-812 and the Aviation Weather Handbook, FAA-H-8083-28, ch. 25):
//! a header (`DATA BASED ON ddhhmmZ`, `VALID ddhhmmZ FOR USE hhmm-hhmmZ. TEMPS NEG ABV 24000`),
//! an `FT` line of levels in feet MSL, then one line a site: a three-character id (mostly VOR or
//! airport ids) and one field a level, right-aligned under its level, in the forms
//! - `DDSS`: wind from DD tens of degrees at SS knots, no temperature (3,000 ft, and levels
//!   within 2,500 ft of the site's elevation);
//! - `DDSS±TT`: with the temperature, C;
//! - `DDSSTT`: above the `TEMPS NEG ABV` level, where the temperature is negative without a sign;
//! - `99` for the direction with `00` speed: light and variable (under 5 kt, taken as calm);
//! - DD plus 50 for 100 kt and more: `7510` is 250 degrees at 110 kt;
//! - blank: no forecast (levels within 1,500 ft of the site's elevation).
//!
//! Sites are placed through a station table: the US ones are the airport's ICAO id (`K` and
//! the FB id); VOR and offshore points with no entry are left out and counted. The placed sites
//! are triangulated and blended with Sibson's natural-neighbour weights as the METARs
//! (`super::field`): a level's wind as a vector and its temperature, over the sites that give
//! them (weights renormalised); outside the hull the nearest site. [`super::air`] uses the
//! blended column above the boundary layer.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::error::WeatherError;
use super::frame::LocalFrame;
use super::stations::StationTable;

/// Metres in a foot.
const M_PER_FT: f64 = 0.3048;

/// One level of one site: the wind, and the temperature where the product gives one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FbLevel {
    /// Direction the wind blows from, degrees true (0 for light and variable).
    pub from_deg: f64,
    /// Speed, knots (0 for light and variable).
    pub speed_kt: f64,
    /// Light and variable (`9900`).
    pub light_and_variable: bool,
    /// Temperature, C.
    pub temperature_c: Option<f64>,
}

/// One site of the product.
#[derive(Debug, Clone, PartialEq)]
pub struct FbSite {
    /// The product's id (three characters).
    pub id: String,
    /// 1-based line of the file.
    pub line: usize,
    /// One entry a level of [`WindsAloft::levels_ft`]; `None` where blank.
    pub levels: Vec<Option<FbLevel>>,
}

/// A winds and temperatures aloft product, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct WindsAloft {
    /// The file it came from.
    pub path: PathBuf,
    /// `DATA BASED ON` time, `ddhhmmZ` as written.
    pub based_on: Option<String>,
    /// `VALID` time, `ddhhmmZ` as written.
    pub valid: Option<String>,
    /// Levels, feet MSL.
    pub levels_ft: Vec<f64>,
    /// The sites, in file order.
    pub sites: Vec<FbSite>,
}

impl WindsAloft {
    /// Reads an FB file.
    pub fn load(path: &Path) -> Result<Self, WeatherError> {
        let text = std::fs::read_to_string(path).map_err(|source| WeatherError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Decodes an FB product; `path` names it in errors. A field that is none of the forms
    /// gives one error naming the file, the line and the field (site and level).
    pub fn parse(text: &str, path: &Path) -> Result<Self, WeatherError> {
        let malformed = |line: usize, message: String| WeatherError::Malformed {
            path: path.to_path_buf(),
            line,
            message,
        };
        let mut based_on = None;
        let mut valid = None;
        let mut negative_above_ft = 24_000.0;
        // Each level's field ends in the column its level number ends in.
        let mut header: Option<(Vec<f64>, Vec<usize>)> = None;
        let mut sites = Vec::new();
        for (k, raw) in text.lines().enumerate() {
            let n = k + 1;
            let line = raw.trim_end();
            if line.trim().is_empty() {
                continue;
            }
            let Some((levels_ft, ends)) = &header else {
                let words: Vec<&str> = line.split_whitespace().collect();
                if let Some(i) = words.iter().position(|w| *w == "ON")
                    && line.starts_with("DATA BASED ON")
                {
                    based_on = words.get(i + 1).map(|s| s.to_string());
                } else if words.first() == Some(&"VALID") {
                    valid = words.get(1).map(|s| s.to_string());
                    if let Some(i) = words.iter().position(|w| *w == "ABV") {
                        let level = words.get(i + 1).and_then(|w| w.parse::<f64>().ok());
                        negative_above_ft = level.ok_or_else(|| {
                            malformed(n, "the TEMPS NEG ABV level is not a number".into())
                        })?;
                    }
                } else if words.first() == Some(&"FT") {
                    let mut levels = Vec::new();
                    let mut ends = Vec::new();
                    let mut at = 0;
                    for w in &words[1..] {
                        let start = at + line[at..].find(w).unwrap_or(0);
                        at = start + w.len();
                        let ft = w.parse::<f64>().map_err(|_| {
                            malformed(n, format!("level `{w}` of the FT line is not feet"))
                        })?;
                        levels.push(ft);
                        ends.push(at - 1);
                    }
                    if levels.is_empty() || levels.windows(2).any(|p| p[1] <= p[0]) {
                        return Err(malformed(n, "the FT line's levels must grow".into()));
                    }
                    header = Some((levels, ends));
                }
                continue;
            };
            if line.starts_with("$$") || line.starts_with("&&") {
                continue;
            }
            let id = line.get(..3).unwrap_or(line);
            if id.len() != 3
                || !id.chars().all(|c| c.is_ascii_alphanumeric())
                || line.get(3..4).is_some_and(|c| c != " ")
            {
                return Err(malformed(
                    n,
                    format!("field `site`: `{id}` is not a three-character site id"),
                ));
            }
            let mut levels = Vec::with_capacity(levels_ft.len());
            let mut from = 3;
            for (&ft, &end) in levels_ft.iter().zip(ends) {
                let field = line.get(from..=end.min(line.len().saturating_sub(1)));
                from = end + 1;
                let field = field.unwrap_or("").trim();
                if field.is_empty() {
                    levels.push(None);
                    continue;
                }
                let level = decode(field, ft > negative_above_ft).map_err(|why| {
                    malformed(n, format!("field {id} {ft:.0} ft: `{field}` {why}"))
                })?;
                levels.push(Some(level));
            }
            if line.len() > from {
                return Err(malformed(
                    n,
                    format!("field {id}: `{}` past the last level", line[from..].trim()),
                ));
            }
            sites.push(FbSite {
                id: id.to_string(),
                line: n,
                levels,
            });
        }
        let Some((levels_ft, _)) = header else {
            return Err(WeatherError::NotWeather {
                path: path.to_path_buf(),
                reason: "no FT line of levels: not a winds aloft (FB) product".into(),
            });
        };
        if sites.is_empty() {
            return Err(WeatherError::NotWeather {
                path: path.to_path_buf(),
                reason: "an FB product without a site".into(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            based_on,
            valid,
            levels_ft,
            sites,
        })
    }

    /// Reads an FB file as a watch does ([`super::watch::WeatherWatch::start_loading`]): once,
    /// and only if it is whole (not empty, not still growing, ending with a complete line);
    /// else why not, one line naming the file (and the line and field of a malformed one).
    pub fn load_whole(path: &Path) -> Result<Self, String> {
        let shown = path.display();
        let before =
            std::fs::metadata(path).map_err(|err| format!("{shown}: cannot read: {err}"))?;
        let text =
            std::fs::read_to_string(path).map_err(|err| format!("{shown}: cannot read: {err}"))?;
        if before.len() != text.len() as u64 {
            return Err(format!(
                "{shown}: still being written (its size changed while reading)"
            ));
        }
        if text.trim().is_empty() {
            return Err(format!("{shown}: the file is empty"));
        }
        if !text.ends_with('\n') {
            let line = text.lines().count();
            return Err(format!(
                "{shown}:{line}: ends in the middle of a line: cut short"
            ));
        }
        Self::parse(&text, path).map_err(|err| err.to_string())
    }

    /// Where each site is: the station table's `K` + id (US airports), else the id itself;
    /// `None` for a site with no entry (VOR and offshore points).
    pub fn positions(&self, table: &StationTable) -> Vec<Option<(f64, f64)>> {
        self.sites
            .iter()
            .map(|s| {
                table
                    .get(&format!("K{}", s.id))
                    .or_else(|| table.get(&s.id))
                    .map(|st| (st.latitude_deg, st.longitude_deg))
            })
            .collect()
    }
}

/// One field: `DDSS`, `DDSS±TT` or `DDSSTT` (negative when `negative`).
fn decode(field: &str, negative: bool) -> Result<FbLevel, &'static str> {
    const FORMS: &str = "is not DDSS, DDSS+TT, DDSS-TT or DDSSTT";
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    let (wind, temperature) = match field.len() {
        4 => (field, None),
        6 if digits(field) => (&field[..4], Some(&field[4..])),
        7 => (&field[..4], Some(&field[4..])),
        _ => return Err(FORMS),
    };
    if !digits(wind) {
        return Err(FORMS);
    }
    let dd: u32 = wind[..2].parse().map_err(|_| FORMS)?;
    let ss: u32 = wind[2..].parse().map_err(|_| FORMS)?;
    let (from_deg, speed_kt, light_and_variable) = match dd {
        99 if ss == 0 => (0.0, 0.0, true),
        0..=36 => (f64::from(dd * 10), f64::from(ss), false),
        51..=86 => (f64::from((dd - 50) * 10), f64::from(ss + 100), false),
        _ => return Err("has a direction that is neither 00-36, 51-86 (+100 kt) nor 9900"),
    };
    let temperature_c = match temperature {
        None => None,
        Some(t) => {
            let (sign, value) = match t.as_bytes()[0] {
                b'+' => (1.0, &t[1..]),
                b'-' => (-1.0, &t[1..]),
                _ if negative => (-1.0, t),
                _ => return Err("has a temperature without its sign below TEMPS NEG ABV"),
            };
            if value.len() != 2 || !digits(value) {
                return Err(FORMS);
            }
            Some(sign * value.parse::<f64>().map_err(|_| FORMS)?)
        }
    };
    Ok(FbLevel {
        from_deg: if from_deg == 0.0 && speed_kt > 0.0 {
            360.0
        } else {
            from_deg
        },
        speed_kt,
        light_and_variable,
        temperature_c,
    })
}

/// A level of the blended column over a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AloftLevel {
    /// Altitude, metres MSL.
    pub alt_m_msl: f64,
    /// Wind velocity, knots east and north; `None` where no site near gives it.
    pub velocity_kt: Option<DVec2>,
    /// Temperature, C; `None` where no site near gives it.
    pub temperature_c: Option<f64>,
}

/// The winds and temperatures aloft over a point, lowest level first.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AloftColumn {
    /// The levels.
    pub levels: Vec<AloftLevel>,
}

/// One level of a placed site: (velocity east/north kt, temperature C).
type SiteLevel = (DVec2, Option<f64>);

#[derive(Debug, Clone, Copy)]
struct Vertex {
    position: Point2<f64>,
    site: usize,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// An FB product placed in a frame, to blend between its sites.
#[derive(Debug)]
pub struct WindsAloftField {
    levels_ft: Vec<f64>,
    /// Per placed site, per level.
    values: Vec<Vec<Option<SiteLevel>>>,
    tri: DelaunayTriangulation<Vertex>,
    /// Sites the table placed, of all.
    pub placed: usize,
    /// Ids of the sites with no entry in the table.
    pub unplaced: Vec<String>,
}

impl WindsAloftField {
    /// Places `fb`'s sites through `table` in `frame`.
    pub fn build(frame: &LocalFrame, fb: &WindsAloft, table: &StationTable) -> Self {
        let mut tri = DelaunayTriangulation::<Vertex>::new();
        let mut values = Vec::new();
        let mut unplaced = Vec::new();
        for (site, position) in fb.sites.iter().zip(fb.positions(table)) {
            let Some((lat, lon)) = position else {
                unplaced.push(site.id.clone());
                continue;
            };
            let p = frame.to_local_m(lat, lon);
            let vertex = Vertex {
                position: Point2::new(p.x, p.y),
                site: values.len(),
            };
            if tri.insert(vertex).is_err() {
                unplaced.push(site.id.clone());
                continue;
            }
            values.push(
                site.levels
                    .iter()
                    .map(|l| l.map(|l| (velocity_kt(l.from_deg, l.speed_kt), l.temperature_c)))
                    .collect(),
            );
        }
        Self {
            levels_ft: fb.levels_ft.clone(),
            placed: values.len(),
            values,
            tri,
            unplaced,
        }
    }

    /// The blended column over `point_m` (local metres): natural-neighbour weights of the
    /// sites, each level over the sites that give it.
    pub fn column_at(&self, point_m: DVec2) -> AloftColumn {
        let p = Point2::new(point_m.x, point_m.y);
        let mut weights: Vec<(usize, f64)> = Vec::new();
        if self.tri.num_inner_faces() > 0 {
            let mut raw = Vec::new();
            self.tri.natural_neighbor().get_weights(p, &mut raw);
            weights.extend(
                raw.into_iter()
                    .map(|(h, w)| (self.tri.vertex(h).data().site, w)),
            );
        }
        if weights.is_empty()
            && let Some(v) = self.tri.nearest_neighbor(p)
        {
            weights.push((v.data().site, 1.0));
        }
        let levels = self
            .levels_ft
            .iter()
            .enumerate()
            .map(|(k, &ft)| {
                // (sum, total weight) of the wind, then of the temperature.
                let mut acc = (DVec3::ZERO, DVec2::ZERO);
                for &(site, w) in &weights {
                    if let Some((v, t)) = self.values[site][k] {
                        acc.0 += v.extend(1.0) * w;
                        if let Some(t) = t {
                            acc.1 += DVec2::new(t, 1.0) * w;
                        }
                    }
                }
                AloftLevel {
                    alt_m_msl: ft * M_PER_FT,
                    velocity_kt: (acc.0.z > 0.0).then(|| acc.0.truncate() / acc.0.z),
                    temperature_c: (acc.1.y > 0.0).then(|| acc.1.x / acc.1.y),
                }
            })
            .collect();
        AloftColumn { levels }
    }
}

/// The velocity (knots east, north) of a wind from `from_deg`.
fn velocity_kt(from_deg: f64, speed_kt: f64) -> DVec2 {
    let to = (from_deg + 180.0).to_radians();
    DVec2::new(to.sin(), to.cos()) * speed_kt
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "weather/fd1us1-2026-01-31T06Z.txt";

    fn sample() -> WindsAloft {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE);
        WindsAloft::load(&path).unwrap()
    }

    #[test]
    fn every_encoding_decodes() {
        let l = |f: &str, neg: bool| decode(f, neg).unwrap();
        // DDSS: no temperature.
        assert_eq!(
            l("3114", false),
            FbLevel {
                from_deg: 310.0,
                speed_kt: 14.0,
                light_and_variable: false,
                temperature_c: None
            }
        );
        // DDSS+TT and DDSS-TT.
        assert_eq!(l("3222-06", false).temperature_c, Some(-6.0));
        assert_eq!(l("0710+13", false).temperature_c, Some(13.0));
        // DDSSTT above 24,000 ft: negative without a sign.
        let high = l("359045", true);
        assert_eq!((high.from_deg, high.speed_kt), (350.0, 90.0));
        assert_eq!(high.temperature_c, Some(-45.0));
        // Direction + 50: 100 kt and more.
        let fast = l("850053", true);
        assert_eq!((fast.from_deg, fast.speed_kt), (350.0, 100.0));
        assert_eq!(fast.temperature_c, Some(-53.0));
        let fast = l("7701-25", false);
        assert_eq!((fast.from_deg, fast.speed_kt), (270.0, 101.0));
        // 99: light and variable.
        let lv = l("9900-18", false);
        assert!(lv.light_and_variable && lv.speed_kt == 0.0);
        assert_eq!(lv.temperature_c, Some(-18.0));
        assert!(l("990055", true).light_and_variable);
        // Not a field.
        for bad in ["31X4", "3114+0", "4014", "3114*02", "31140", "311402"] {
            assert!(decode(bad, false).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_shipped_sample_reads_whole() {
        let fb = sample();
        assert_eq!(fb.based_on.as_deref(), Some("310000Z"));
        assert_eq!(fb.valid.as_deref(), Some("310600Z"));
        assert_eq!(
            fb.levels_ft,
            [3e3, 6e3, 9e3, 12e3, 18e3, 24e3, 30e3, 34e3, 39e3]
        );
        assert_eq!(fb.sites.len(), 176);
        // ABQ (ground 5,355 ft): blanks near the ground, then 3513+00.
        let abq = fb.sites.iter().find(|s| s.id == "ABQ").unwrap();
        assert_eq!(abq.levels[..2], [None, None]);
        let l = abq.levels[2].unwrap();
        assert_eq!(
            (l.from_deg, l.speed_kt, l.temperature_c),
            (350.0, 13.0, Some(0.0))
        );
        // ABI's 39,000 ft: 329558 -> 320 at 95 kt, -58 C; its 34,000 ft 850053 -> 350/100.
        let abi = &fb.sites[0];
        assert_eq!(abi.id, "ABI");
        let top = abi.levels[8].unwrap();
        assert_eq!(
            (top.from_deg, top.speed_kt, top.temperature_c),
            (320.0, 95.0, Some(-58.0))
        );
        let l = abi.levels[7].unwrap();
        assert_eq!((l.from_deg, l.speed_kt), (350.0, 100.0));
        // 3,000 ft never has a temperature.
        assert!(
            fb.sites
                .iter()
                .all(|s| s.levels[0].is_none_or(|l| l.temperature_c.is_none()))
        );
        // The shipped station table places most sites: US airports as K + id.
        let table = StationTable::builtin();
        let placed = fb.positions(&table).iter().filter(|p| p.is_some()).count();
        assert_eq!(placed, 157);
    }

    #[test]
    fn a_malformed_field_names_file_line_and_field() {
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE))
            .unwrap()
            .replace("ABQ              3513+00", "ABQ              35X3+00");
        let err = WindsAloft::parse(&text, Path::new("fb.txt"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "fb.txt:10: field ABQ 9000 ft: `35X3+00` is not DDSS, DDSS+TT, DDSS-TT or DDSSTT"
        );
        let err = WindsAloft::parse("DATA BASED ON 1\nABC 3114", Path::new("x.txt"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("x.txt") && err.contains("FT line"), "{err}");
    }

    /// What a watch reads: the whole sample; a file cut mid-line, an empty one and a malformed
    /// field each refused with one line naming the file (and line and field).
    #[test]
    fn a_whole_file_loads_and_a_broken_one_says_why() {
        let dir = std::env::temp_dir().join(format!("skycast-fb-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fb.txt");
        let text =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE)).unwrap();
        std::fs::write(&path, &text).unwrap();
        assert_eq!(WindsAloft::load_whole(&path).unwrap().sites.len(), 176);
        let cut = text.find("ABQ              3513+00").unwrap() + 20;
        std::fs::write(&path, &text[..cut]).unwrap();
        let err = WindsAloft::load_whole(&path).unwrap_err();
        assert!(
            err.ends_with("fb.txt:10: ends in the middle of a line: cut short"),
            "{err}"
        );
        std::fs::write(&path, "\n \n").unwrap();
        let err = WindsAloft::load_whole(&path).unwrap_err();
        assert!(err.ends_with("fb.txt: the file is empty"), "{err}");
        std::fs::write(
            &path,
            text.replace("ABQ              3513+00", "ABQ              35X3+00"),
        )
        .unwrap();
        let err = WindsAloft::load_whole(&path).unwrap_err();
        assert!(
            err.ends_with(
                "fb.txt:10: field ABQ 9000 ft: `35X3+00` is not DDSS, DDSS+TT, DDSS-TT or DDSSTT"
            ),
            "{err}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn at_a_site_the_blend_is_its_forecast() {
        let fb = sample();
        let table = StationTable::builtin();
        let frame = LocalFrame::new(39.0, -98.0);
        let field = WindsAloftField::build(&frame, &fb, &table);
        assert_eq!(field.placed + field.unplaced.len(), 176);
        let mut checked = 0;
        for (site, pos) in fb.sites.iter().zip(fb.positions(&table)) {
            let Some((lat, lon)) = pos else { continue };
            let column = field.column_at(frame.to_local_m(lat, lon));
            for (level, blended) in site.levels.iter().zip(&column.levels) {
                let Some(level) = level else { continue };
                let v = blended.velocity_kt.unwrap();
                let want = velocity_kt(level.from_deg, level.speed_kt);
                assert!((v - want).length() < 1e-6, "{} {v} {want}", site.id);
                if let Some(t) = level.temperature_c {
                    assert!((blended.temperature_c.unwrap() - t).abs() < 1e-9);
                }
                checked += 1;
            }
        }
        assert!(checked > 1_300, "{checked}");
    }
}

//! METAR/SPECI decoding of the main body (WMO FM 15, ICAO Annex 3, and US practice):
//! station, time, AUTO/COR/NIL, wind, visibility, present weather, cloud groups, temperature,
//! dewpoint and altimeter. The body ends at RMK, TEMPO, BECMG, NOSIG, PROB or INTER; the remarks
//! are kept raw for the stages that read them. A malformed group becomes a warning on the
//! report, never a failure of the whole report: [`decode`] fails only when there is no station.
//!
//! Groups are recognised by their shape, not their position, so a report with a group missing or
//! out of order still decodes. Runway visual range, runway state, recent weather, wind shear, sea
//! state and colour codes are recognised and skipped quietly. Units are in the field names of
//! [`Report`]: knots, metres, feet, degrees Celsius, hectopascals.

mod air;
mod report;
mod sky;
mod visibility;
mod weather_group;
mod wind;

pub use report::{
    CloudGroup, ConvectiveKind, Cover, Intensity, PresentWeather, Report, ReportTime, SkyCode,
    WindGroup,
};

use air::AltimeterToken;
use sky::SkyToken;
use visibility::VisibilityToken;
use wind::WindToken;

/// Why a text is not a METAR at all.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MetarError {
    /// The text holds no groups (empty or only blanks).
    #[error("empty report")]
    Empty,
    /// The first group (after METAR/SPECI/COR) is not a four-character ICAO station identifier.
    #[error("no station identifier: `{0}` is not four letters or digits")]
    NoStation(String),
}

/// Groups that end the main body and start a trend forecast.
fn is_trend_start(token: &str) -> bool {
    matches!(token, "TEMPO" | "BECMG" | "NOSIG" | "INTER")
        || token
            .strip_prefix("PROB")
            .is_some_and(|p| p.len() == 2 && p.bytes().all(|b| b.is_ascii_digit()))
}

/// Groups recognised and skipped quietly: military colour states, no significant weather,
/// the words of a wind shear group, US `M` (a missing field), missing groups written with
/// slashes (`////SM`, `///V///`, `RE//`).
const QUIET: [&str; 18] = [
    "BLU", "BLU+", "WHT", "GRN", "YLO", "YLO1", "YLO2", "AMB", "RED", "BLACK", "NSW", "WS", "ALL",
    "RWY", "M", "////SM", "///V///", "RE//",
];

/// Decodes one METAR or SPECI. Fails only when the text has no station; every other problem is a
/// warning on the report.
pub fn decode(text: &str) -> Result<Report, MetarError> {
    let tokens: Vec<&str> = text
        .split_ascii_whitespace()
        .map(|t| t.trim_end_matches('='))
        .filter(|t| !t.is_empty())
        .collect();
    let mut i = 0;
    while i < tokens.len() && matches!(tokens[i], "METAR" | "SPECI" | "COR") {
        i += 1;
    }
    let mut report = Report {
        corrected: tokens[..i].contains(&"COR"),
        ..Report::default()
    };
    let station = *tokens.get(i).ok_or(MetarError::Empty)?;
    if !is_station(station) {
        return Err(MetarError::NoStation(station.chars().take(16).collect()));
    }
    report.station = station.to_string();
    i += 1;

    let mut body = Body::default();
    while i < tokens.len() {
        let token = tokens[i];
        i += 1;
        if token == "RMK" {
            report.remarks = remarks_after(text, token);
            break;
        }
        if body.ended {
            continue;
        }
        if is_trend_start(token) {
            body.ended = true;
            continue;
        }
        if !token.is_ascii() {
            report.warnings.push(format!("`{token}`: not ASCII"));
            continue;
        }
        match body.group(&mut report, token, tokens.get(i).copied()) {
            Ok(used) => i += used - 1,
            Err(why) => report.warnings.push(format!("`{token}`: {why}")),
        }
    }
    Ok(report)
}

/// An ICAO identifier: four ASCII capitals or digits, the first a letter.
fn is_station(token: &str) -> bool {
    let b = token.as_bytes();
    b.len() == 4
        && b[0].is_ascii_uppercase()
        && b.iter()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
}

/// The raw text after the `RMK` token, `=` and blanks trimmed.
fn remarks_after(text: &str, rmk: &str) -> String {
    // `rmk` is a slice of `text`; its offset tells where the remarks start.
    let start = rmk.as_ptr() as usize - text.as_ptr() as usize + rmk.len();
    text.get(start..)
        .unwrap_or("")
        .trim()
        .trim_end_matches('=')
        .trim_end()
        .to_string()
}

/// Decoding state of the main body.
#[derive(Debug, Default)]
struct Body {
    /// A wind group was seen (it may have decoded to nothing, `/////KT`).
    wind_seen: bool,
    /// A trend or NIL ended the body.
    ended: bool,
}

impl Body {
    /// Decodes one group into the report: how many tokens it used, or why it is not a group.
    fn group(&mut self, r: &mut Report, token: &str, next: Option<&str>) -> Result<usize, String> {
        match token {
            "NIL" => {
                r.sky = Some(SkyCode::Nil);
                self.ended = true;
                return Ok(1);
            }
            "AUTO" => r.auto = true,
            "COR" | "CCA" | "CCB" | "CCC" => r.corrected = true,
            "METAR" | "SPECI" => {}
            "CAVOK" => {
                r.cavok = true;
                r.visibility_m = Some(10_000.0);
            }
            _ if QUIET.contains(&token) => {}
            _ if token.bytes().all(|b| b == b'/') => {}
            _ if is_runway_group(token) => {}
            _ if weather_group::is_recent_weather(token) => {}
            _ if is_sea_state(token) => {}
            _ => return self.shaped_group(r, token, next),
        }
        Ok(1)
    }

    /// Groups recognised by their shape.
    fn shaped_group(
        &mut self,
        r: &mut Report,
        token: &str,
        next: Option<&str>,
    ) -> Result<usize, String> {
        if r.time.is_none() && looks_like_time(token) {
            return match parse_time(token) {
                Some(time) => {
                    r.time = Some(time);
                    Ok(1)
                }
                None => Err("time is not DDHHMMZ".into()),
            };
        }
        match wind::parse_wind(token) {
            WindToken::Wind(_) if self.wind_seen => return Err("second wind group".into()),
            WindToken::Wind(wind) => {
                self.wind_seen = true;
                let range = r.wind.and_then(|w| w.var_from.zip(w.var_to));
                r.wind = wind;
                if let Some((from, to)) = range {
                    set_range(r, from, to);
                }
                return Ok(1);
            }
            WindToken::Malformed(why) => return Err(why.into()),
            WindToken::No => {}
        }
        if let Some((from, to)) = wind::parse_variable_range(token) {
            set_range(r, from, to);
            return Ok(1);
        }
        match visibility::parse_visibility(token, next) {
            VisibilityToken::Metres(m, used) => {
                // A second one is a minimum or directional visibility: tolerated, not kept.
                r.visibility_m.get_or_insert(m);
                return Ok(used);
            }
            VisibilityToken::Malformed(why) => return Err(why.into()),
            VisibilityToken::No => {}
        }
        match sky::parse_sky(token) {
            SkyToken::Cloud(cloud) => {
                r.clouds.push(cloud);
                return Ok(1);
            }
            SkyToken::Code(code) => {
                r.sky.get_or_insert(code);
                return Ok(1);
            }
            SkyToken::Malformed(why) => return Err(why.into()),
            SkyToken::No => {}
        }
        if let Some(weather) = weather_group::parse_weather(token) {
            r.weather.push(weather);
            return Ok(1);
        }
        if let Some((t, d)) = air::parse_temperatures(token) {
            if r.temperature_c.is_some() || r.dewpoint_c.is_some() {
                return Err("second temperature group".into());
            }
            r.temperature_c = t;
            r.dewpoint_c = d;
            return Ok(1);
        }
        if let AltimeterToken::Hpa(hpa) = air::parse_altimeter(token) {
            // Some stations give both Q and A; the first is kept.
            if r.altimeter_hpa.is_none() {
                r.altimeter_hpa = hpa;
            }
            return Ok(1);
        }
        Err("not a METAR group".into())
    }
}

/// Records a variable wind direction range on the report's wind (made when there is none yet).
fn set_range(r: &mut Report, from: u16, to: u16) {
    let wind = r.wind.get_or_insert_with(WindGroup::default);
    wind.variable = true;
    wind.var_from = Some(from);
    wind.var_to = Some(to);
}

/// Digits then `Z`: a time group, maybe malformed (`2210Z`).
fn looks_like_time(token: &str) -> bool {
    token.len() <= 8
        && token
            .strip_suffix('Z')
            .is_some_and(|t| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()))
}

/// `DDHHMMZ` with day 1-31, hour 0-24, minute 0-59.
fn parse_time(token: &str) -> Option<ReportTime> {
    let t = token.strip_suffix('Z')?;
    if t.len() != 6 || !t.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let n = |k: usize| (t.as_bytes()[k] - b'0') * 10 + (t.as_bytes()[k + 1] - b'0');
    let time = ReportTime {
        day: n(0),
        hour: n(2),
        minute: n(4),
    };
    ((1..=31).contains(&time.day) && time.hour <= 24 && time.minute <= 59).then_some(time)
}

/// Runway visual range (`R26/0550N`, `R16/P2000N`), runway state (`R24///////`,
/// `R05/CLRD70`, old eight-digit `88290195`), the runway of a wind shear group (`WS R35`).
fn is_runway_group(token: &str) -> bool {
    let b = token.as_bytes();
    let runway = b.len() >= 3 && b[0] == b'R' && b[1].is_ascii_digit() && b[2].is_ascii_digit();
    (runway && (token.contains('/') || matches!(&b[3..], [] | [b'L' | b'C' | b'R'])))
        || (b.len() == 8 && b.iter().all(u8::is_ascii_digit))
}

/// Sea surface temperature and state: `W12/S2`, `W15/H7`, `WM01/S3`, `W/////`.
fn is_sea_state(token: &str) -> bool {
    let b = token.as_bytes();
    b.len() >= 4
        && b[0] == b'W'
        && token.contains('/')
        && b[1..]
            .iter()
            .all(|c| c.is_ascii_digit() || matches!(c, b'/' | b'S' | b'H' | b'M'))
}

#[cfg(test)]
mod tests;

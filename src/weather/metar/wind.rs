//! Wind groups: `dddff[Gfff]KT|MPS|KMH`, `VRBffKT`, calm `00000KT`, and the variable range
//! `dddVddd`. Speeds come out in knots (1 m/s = 1.943844 kt, 1 km/h = 0.539957 kt).

use super::report::WindGroup;

/// Knots per metre per second.
const KT_PER_MPS: f32 = 1.943_844;
/// Knots per kilometre per hour.
const KT_PER_KMH: f32 = 0.539_957;

/// What a token is, seen as a wind group.
#[derive(Debug, PartialEq)]
pub(super) enum WindToken {
    /// A wind group; `None` when every part is missing (`/////KT`).
    Wind(Option<WindGroup>),
    /// Looks like a wind group (ends in a speed unit) but does not decode.
    Malformed(&'static str),
    /// Not a wind group.
    No,
}

/// Decodes a wind group token.
pub(super) fn parse_wind(token: &str) -> WindToken {
    let (body, kt_per_unit) = if let Some(body) = token.strip_suffix("KT") {
        (body, 1.0)
    } else if let Some(body) = token.strip_suffix("MPS") {
        (body, KT_PER_MPS)
    } else if let Some(body) = token.strip_suffix("KMH") {
        (body, KT_PER_KMH)
    } else {
        return WindToken::No;
    };
    if body.len() < 5 {
        return WindToken::Malformed("a wind group needs a direction and a speed");
    }
    let (dir, rest) = body.split_at(3);
    let mut wind = WindGroup::default();
    match dir {
        "VRB" => wind.variable = true,
        "///" => {}
        _ => match digits(dir) {
            Some(deg) if deg <= 360 => wind.dir_deg = Some(deg as u16),
            Some(_) => return WindToken::Malformed("wind direction above 360 degrees"),
            None => return WindToken::Malformed("wind direction is not three digits"),
        },
    }
    let (speed, gust) = match rest.split_once('G') {
        Some((speed, gust)) => (speed, Some(gust)),
        None => (rest, None),
    };
    wind.speed_kt = match speed_value(speed) {
        Ok(v) => v.map(|v| v * kt_per_unit),
        Err(why) => return WindToken::Malformed(why),
    };
    if let Some(gust) = gust {
        wind.gust_kt = match speed_value(gust) {
            Ok(v) => v.map(|v| v * kt_per_unit),
            Err(why) => return WindToken::Malformed(why),
        };
    }
    if wind == WindGroup::default() {
        WindToken::Wind(None)
    } else {
        WindToken::Wind(Some(wind))
    }
}

/// A speed of two or three digits (`P` for "more than" tolerated), or `//` for missing.
fn speed_value(text: &str) -> Result<Option<f32>, &'static str> {
    let text = text.strip_prefix('P').unwrap_or(text);
    if !text.is_empty() && text.bytes().all(|b| b == b'/') {
        return Ok(None);
    }
    if !(2..=3).contains(&text.len()) {
        return Err("wind speed is not two or three digits");
    }
    digits(text)
        .map(|v| Some(v as f32))
        .ok_or("wind speed is not two or three digits")
}

/// Decodes a variable wind direction range `dddVddd` into (from, to) degrees.
pub(super) fn parse_variable_range(token: &str) -> Option<(u16, u16)> {
    let b = token.as_bytes();
    if b.len() != 7 || b[3] != b'V' {
        return None;
    }
    let from = digits(&token[..3])?;
    let to = digits(&token[4..])?;
    (from <= 360 && to <= 360).then_some((from as u16, to as u16))
}

/// The value of an all-ASCII-digit string (at most 9 digits), else `None`.
pub(super) fn digits(text: &str) -> Option<u32> {
    if text.is_empty() || text.len() > 9 || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some(
        text.bytes()
            .fold(0u32, |acc, b| acc * 10 + u32::from(b - b'0')),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wind(token: &str) -> WindGroup {
        match parse_wind(token) {
            WindToken::Wind(Some(w)) => w,
            other => panic!("{token}: {other:?}"),
        }
    }

    #[test]
    fn direction_speed_and_gust_in_knots() {
        let w = wind("33006KT");
        assert_eq!(w.dir_deg, Some(330));
        assert_eq!(w.speed_kt, Some(6.0));
        assert_eq!(w.gust_kt, None);
        assert!(!w.variable);
        let w = wind("25019G31KT");
        assert_eq!(
            (w.dir_deg, w.speed_kt, w.gust_kt),
            (Some(250), Some(19.0), Some(31.0))
        );
        let w = wind("270120G150KT");
        assert_eq!((w.speed_kt, w.gust_kt), (Some(120.0), Some(150.0)));
    }

    #[test]
    fn calm_and_variable() {
        let w = wind("00000KT");
        assert_eq!((w.dir_deg, w.speed_kt), (Some(0), Some(0.0)));
        let w = wind("VRB04KT");
        assert_eq!((w.dir_deg, w.variable, w.speed_kt), (None, true, Some(4.0)));
    }

    #[test]
    fn metres_per_second_and_kilometres_per_hour_become_knots() {
        let w = wind("15002MPS");
        assert!((w.speed_kt.unwrap_or(0.0) - 3.887_688).abs() < 1e-4);
        let w = wind("18010G20KMH");
        assert!((w.speed_kt.unwrap_or(0.0) - 5.39957).abs() < 1e-4);
        assert!((w.gust_kt.unwrap_or(0.0) - 10.79914).abs() < 1e-4);
    }

    #[test]
    fn missing_parts() {
        assert_eq!(parse_wind("/////KT"), WindToken::Wind(None));
        let w = wind("270//KT");
        assert_eq!((w.dir_deg, w.speed_kt), (Some(270), None));
    }

    #[test]
    fn malformed_and_foreign_tokens() {
        assert!(matches!(parse_wind("KT"), WindToken::Malformed(_)));
        assert!(matches!(parse_wind("99010KT"), WindToken::Malformed(_)));
        assert!(matches!(parse_wind("27010GKT"), WindToken::Malformed(_)));
        assert!(matches!(parse_wind("2701234KT"), WindToken::Malformed(_)));
        assert_eq!(parse_wind("9999"), WindToken::No);
        assert_eq!(parse_wind("OVC005"), WindToken::No);
    }

    #[test]
    fn variable_range() {
        assert_eq!(parse_variable_range("140V220"), Some((140, 220)));
        assert_eq!(parse_variable_range("350V030"), Some((350, 30)));
        assert_eq!(parse_variable_range("140V20"), None);
        assert_eq!(parse_variable_range("400V020"), None);
        assert_eq!(parse_variable_range("VRB04KT"), None);
    }

    #[test]
    fn digits_only() {
        assert_eq!(digits("007"), Some(7));
        assert_eq!(digits(""), None);
        assert_eq!(digits("1a"), None);
        assert_eq!(digits("9999999999"), None);
    }
}

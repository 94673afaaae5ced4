//! Temperature/dewpoint (`11/06`, `M03/M03`, `M02/`, `//` halves) in degrees Celsius, and the
//! altimeter setting (`Q1011` hectopascals, `A3011` hundredths of an inch of mercury; out in
//! hectopascals, 1 inHg = 33.8639 hPa).

use super::wind::digits;

/// Hectopascals per inch of mercury.
const HPA_PER_INHG: f64 = 33.863_9;

/// A temperature/dewpoint group: (temperature, dewpoint), each `None` when missing; `None` when
/// the token is not such a group.
pub(super) fn parse_temperatures(token: &str) -> Option<(Option<f32>, Option<f32>)> {
    let (t, d) = match token.strip_prefix("///") {
        Some(d) => ("", d),
        None => token.split_once('/')?,
    };
    let t = half(t)?;
    let d = half(d)?;
    (t.is_some() || d.is_some()).then_some((t, d))
}

/// One half: `M`-signed one or two digits; empty or `//` for missing (`Some(None)`).
fn half(text: &str) -> Option<Option<f32>> {
    if text.is_empty() || text == "//" || text == "/" {
        return Some(None);
    }
    let (sign, digits_text) = match text.strip_prefix('M') {
        Some(rest) => (-1.0, rest),
        None => (1.0, text),
    };
    if digits_text.len() > 2 {
        return None;
    }
    digits(digits_text).map(|v| Some(sign * v as f32))
}

/// What a token is, seen as an altimeter group.
#[derive(Debug, PartialEq)]
pub(super) enum AltimeterToken {
    /// The setting in hectopascals; `None` for `Q////`/`A////`.
    Hpa(Option<f32>),
    /// Not an altimeter group.
    No,
}

/// Decodes `Qdddd` (hPa) or `Adddd` (hundredths of inHg) into hectopascals.
pub(super) fn parse_altimeter(token: &str) -> AltimeterToken {
    let (to_hpa, value): (fn(u32) -> f32, &str) = if let Some(v) = token.strip_prefix('Q') {
        (|hpa| hpa as f32, v)
    } else if let Some(v) = token.strip_prefix('A') {
        (
            |hundredths| (f64::from(hundredths) / 100.0 * HPA_PER_INHG) as f32,
            v,
        )
    } else {
        return AltimeterToken::No;
    };
    if value == "////" {
        return AltimeterToken::Hpa(None);
    }
    if value.len() != 4 {
        return AltimeterToken::No;
    }
    match digits(value) {
        Some(v) => AltimeterToken::Hpa(Some(to_hpa(v))),
        None => AltimeterToken::No,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temperatures_with_signs_and_missing_halves() {
        assert_eq!(parse_temperatures("11/06"), Some((Some(11.0), Some(6.0))));
        assert_eq!(
            parse_temperatures("M03/M03"),
            Some((Some(-3.0), Some(-3.0)))
        );
        assert_eq!(parse_temperatures("00/M00"), Some((Some(0.0), Some(-0.0))));
        assert_eq!(parse_temperatures("M02/"), Some((Some(-2.0), None)));
        assert_eq!(parse_temperatures("05///"), Some((Some(5.0), None)));
        assert_eq!(parse_temperatures("///M01"), Some((None, Some(-1.0))));
        assert_eq!(parse_temperatures("/"), None);
        assert_eq!(parse_temperatures("1/2SM"), None);
        assert_eq!(parse_temperatures("R26/0550N"), None);
        assert_eq!(parse_temperatures("W12/S2"), None);
        assert_eq!(parse_temperatures("123/45"), None);
    }

    #[test]
    fn altimeter_in_hectopascals() {
        assert_eq!(parse_altimeter("Q1011"), AltimeterToken::Hpa(Some(1011.0)));
        assert_eq!(parse_altimeter("Q0989"), AltimeterToken::Hpa(Some(989.0)));
        let AltimeterToken::Hpa(Some(hpa)) = parse_altimeter("A3011") else {
            panic!("A3011 should decode");
        };
        assert!((hpa - 1_019.642).abs() < 0.01, "{hpa}");
        assert_eq!(parse_altimeter("Q////"), AltimeterToken::Hpa(None));
        assert_eq!(parse_altimeter("AUTO"), AltimeterToken::No);
        assert_eq!(parse_altimeter("A01"), AltimeterToken::No);
        assert_eq!(parse_altimeter("Q10111"), AltimeterToken::No);
    }
}

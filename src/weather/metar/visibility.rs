//! Prevailing visibility: metres (`4000`, `9999` = 10 km or more, with an optional direction such
//! as `9999NDV`), kilometres (`10KM`), statute miles (`10SM`, `1/2SM`, `1 1/2SM` over two tokens,
//! `P6SM` = more than 6, `M1/4SM` = less than 1/4). Out: metres (1 SM = 1,609.344 m).

use super::wind::digits;

/// Metres per statute mile.
const M_PER_SM: f64 = 1_609.344;

/// Direction suffixes a metre visibility may carry (`0150E`, `9999NDV`, `0600//`).
const DIRECTIONS: [&str; 10] = ["N", "NE", "E", "SE", "S", "SW", "W", "NW", "NDV", "//"];

/// What a token (with the one after it) is, seen as a visibility group.
#[derive(Debug, PartialEq)]
pub(super) enum VisibilityToken {
    /// A visibility in metres, and how many tokens it used (1, or 2 for `1 1/2SM`).
    Metres(f32, usize),
    /// Looks like a visibility group (ends in `SM`) but does not decode.
    Malformed(&'static str),
    /// Not a visibility group.
    No,
}

/// Decodes a visibility group starting at `token`; `next` is the token after it, used for the
/// whole-number part of `1 1/2SM`.
pub(super) fn parse_visibility(token: &str, next: Option<&str>) -> VisibilityToken {
    if let Some(metres) = metres_group(token) {
        return VisibilityToken::Metres(metres, 1);
    }
    if let Some(km) = token
        .strip_suffix("KM")
        .and_then(|t| (t.len() <= 2).then(|| digits(t)))
    {
        return match km {
            Some(km) => VisibilityToken::Metres(km as f32 * 1000.0, 1),
            None => VisibilityToken::No,
        };
    }
    // `1 1/2SM`: a whole number of one digit, then a fraction in statute miles.
    if token.len() == 1
        && let Some(whole) = digits(token)
        && let Some(next) = next
        && let Some(frac) = next.strip_suffix("SM")
        && frac.contains('/')
    {
        return match fraction(frac) {
            Some(f) => VisibilityToken::Metres(((f64::from(whole) + f) * M_PER_SM) as f32, 2),
            None => VisibilityToken::Malformed("visibility fraction does not decode"),
        };
    }
    let Some(miles) = token.strip_suffix("SM") else {
        return VisibilityToken::No;
    };
    let miles = miles
        .strip_prefix('P')
        .or_else(|| miles.strip_prefix('M'))
        .unwrap_or(miles);
    let value = if miles.contains('/') {
        fraction(miles)
    } else if miles.len() <= 2 {
        digits(miles).map(f64::from)
    } else {
        None
    };
    match value {
        Some(v) => VisibilityToken::Metres((v * M_PER_SM) as f32, 1),
        None => VisibilityToken::Malformed("statute-mile visibility does not decode"),
    }
}

/// `dddd` metres with an optional direction; `9999` means 10 km or more.
fn metres_group(token: &str) -> Option<f32> {
    if token.len() < 4 || !token.is_char_boundary(4) {
        return None;
    }
    let (value, direction) = token.split_at(4);
    let metres = digits(value)?;
    if !direction.is_empty() && !DIRECTIONS.contains(&direction) {
        return None;
    }
    Some(if metres == 9999 {
        10_000.0
    } else {
        metres as f32
    })
}

/// `a/b` with small positive whole numbers and `b` not zero.
fn fraction(text: &str) -> Option<f64> {
    let (a, b) = text.split_once('/')?;
    if a.len() > 2 || b.len() > 2 {
        return None;
    }
    let (a, b) = (digits(a)?, digits(b)?);
    (b != 0).then(|| f64::from(a) / f64::from(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metres(token: &str, next: Option<&str>) -> (f32, usize) {
        match parse_visibility(token, next) {
            VisibilityToken::Metres(m, n) => (m, n),
            other => panic!("{token}: {other:?}"),
        }
    }

    #[test]
    fn metres_and_directions() {
        assert_eq!(metres("4000", None), (4000.0, 1));
        assert_eq!(metres("0200", None), (200.0, 1));
        assert_eq!(metres("9999", None), (10_000.0, 1));
        assert_eq!(metres("9999NDV", None), (10_000.0, 1));
        assert_eq!(metres("0150E", None), (150.0, 1));
        assert_eq!(metres("0600//", None), (600.0, 1));
        assert_eq!(parse_visibility("0150X", None), VisibilityToken::No);
        assert_eq!(parse_visibility("272225Z", None), VisibilityToken::No);
    }

    #[test]
    fn kilometres() {
        assert_eq!(metres("10KM", None), (10_000.0, 1));
    }

    #[test]
    fn statute_miles() {
        assert_eq!(metres("10SM", None), (16_093.44, 1));
        assert_eq!(metres("P6SM", None), (9_656.064, 1));
        assert_eq!(metres("3/4SM", None), (1_207.008, 1));
        assert_eq!(metres("M1/4SM", None), (402.336, 1));
        assert_eq!(metres("1", Some("1/2SM")), (2_414.016, 2));
        assert_eq!(metres("2", Some("3/4SM")), (4_425.696, 2));
    }

    #[test]
    fn malformed_miles() {
        assert!(matches!(
            parse_visibility("1/0SM", None),
            VisibilityToken::Malformed(_)
        ));
        assert!(matches!(
            parse_visibility("SM", None),
            VisibilityToken::Malformed(_)
        ));
        assert!(matches!(
            parse_visibility("1", Some("1/0SM")),
            VisibilityToken::Malformed(_)
        ));
        assert_eq!(parse_visibility("1", Some("OVC005")), VisibilityToken::No);
    }
}

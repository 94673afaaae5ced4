//! Present weather groups (WMO code table 4678): intensity or proximity (`-`, `+`, `VC`), at
//! most one descriptor (MI BC PR DR BL SH TS FZ), then phenomena two letters each (`-SHRA`,
//! `+TSRAGR`, `FZFG`, `VCSH`). Recent weather (`RERA`) is recognised so the caller can skip it.

use super::report::{Intensity, PresentWeather};

/// Descriptors.
const DESCRIPTORS: [&str; 8] = ["MI", "BC", "PR", "DR", "BL", "SH", "TS", "FZ"];

/// Phenomena: precipitation, obscuration, other.
const PHENOMENA: [&str; 22] = [
    "DZ", "RA", "SN", "SG", "IC", "PL", "GR", "GS", "UP", "BR", "FG", "FU", "VA", "DU", "SA", "HZ",
    "PY", "PO", "SQ", "FC", "SS", "DS",
];

/// Decodes a present weather group; `None` when the token is not one.
pub(super) fn parse_weather(token: &str) -> Option<PresentWeather> {
    let (intensity, rest) = if let Some(rest) = token.strip_prefix('-') {
        (Intensity::Light, rest)
    } else if let Some(rest) = token.strip_prefix('+') {
        (Intensity::Heavy, rest)
    } else if let Some(rest) = token.strip_prefix("VC") {
        (Intensity::Vicinity, rest)
    } else {
        (Intensity::Moderate, token)
    };
    if rest.is_empty() || rest.len() % 2 != 0 || !rest.is_ascii() {
        return None;
    }
    let mut pairs = (0..rest.len())
        .step_by(2)
        .map(|i| &rest[i..i + 2])
        .peekable();
    let descriptor = pairs
        .next_if(|pair| DESCRIPTORS.contains(pair))
        .map(str::to_string);
    let mut phenomena = Vec::new();
    for pair in pairs {
        if !PHENOMENA.contains(&pair) {
            return None;
        }
        phenomena.push(pair.to_string());
    }
    // A descriptor stands alone only as thunderstorm (TS) or showers in the vicinity (VCSH).
    let alone_ok = match descriptor.as_deref() {
        Some("TS") => true,
        Some("SH") => intensity == Intensity::Vicinity,
        _ => false,
    };
    if phenomena.is_empty() && !alone_ok {
        return None;
    }
    Some(PresentWeather {
        intensity,
        descriptor,
        phenomena,
    })
}

/// Recent weather (`RERA`, `RETSRA`, `RESN`, `RESH`): `RE` and a present-weather group or a
/// lone descriptor.
pub(super) fn is_recent_weather(token: &str) -> bool {
    token.strip_prefix("RE").is_some_and(|rest| {
        DESCRIPTORS.contains(&rest)
            || parse_weather(rest).is_some_and(|w| w.intensity == Intensity::Moderate)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wx(token: &str) -> PresentWeather {
        parse_weather(token).unwrap_or_else(|| panic!("{token} should decode"))
    }

    #[test]
    fn intensity_descriptor_phenomena() {
        let w = wx("-SHRA");
        assert_eq!(w.intensity, Intensity::Light);
        assert_eq!(w.descriptor.as_deref(), Some("SH"));
        assert_eq!(w.phenomena, ["RA"]);
        let w = wx("+TSRAGR");
        assert_eq!(w.intensity, Intensity::Heavy);
        assert_eq!(w.descriptor.as_deref(), Some("TS"));
        assert_eq!(w.phenomena, ["RA", "GR"]);
        let w = wx("FZFG");
        assert_eq!(w.intensity, Intensity::Moderate);
        assert_eq!(w.descriptor.as_deref(), Some("FZ"));
        assert_eq!(w.phenomena, ["FG"]);
        let w = wx("BR");
        assert_eq!((w.descriptor, w.phenomena), (None, vec!["BR".to_string()]));
        let w = wx("-RASN");
        assert_eq!(w.phenomena, ["RA", "SN"]);
        for token in [
            "FU", "HZ", "DZ", "+FC", "BLSN", "DRSN", "MIFG", "BCFG", "PRFG", "SQ",
        ] {
            wx(token);
        }
    }

    #[test]
    fn vicinity_and_lone_descriptors() {
        let w = wx("VCSH");
        assert_eq!(w.intensity, Intensity::Vicinity);
        assert_eq!(w.descriptor.as_deref(), Some("SH"));
        assert!(w.phenomena.is_empty());
        assert_eq!(wx("TS").descriptor.as_deref(), Some("TS"));
        assert_eq!(wx("VCTS").intensity, Intensity::Vicinity);
        assert_eq!(wx("VCFG").phenomena, ["FG"]);
        assert!(parse_weather("SH").is_none());
        assert!(parse_weather("FZ").is_none());
    }

    #[test]
    fn not_weather() {
        for token in [
            "", "-", "+", "VC", "CB", "RAX", "NSC", "SCT020", "TO", "N", "//", "RMK",
        ] {
            assert!(parse_weather(token).is_none(), "{token}");
        }
    }

    #[test]
    fn recent_weather() {
        assert!(is_recent_weather("RERA"));
        assert!(is_recent_weather("RETSRA"));
        assert!(is_recent_weather("RESH"));
        assert!(!is_recent_weather("RE"));
        assert!(!is_recent_weather("RE-RA"));
        assert!(!is_recent_weather("RMK"));
    }
}

//! Cloud groups: `FEW|SCT|BKN|OVC` + base in hundreds of feet (`///` when not measured) +
//! optional `CB`/`TCU`/`///`; a cover of `///` when not observed (`///015`, `//////CB`,
//! `///CB`); vertical visibility `VV002`/`VV///`; and the no-cloud codes CLR, SKC, NSC, NCD.

use super::report::{CloudGroup, ConvectiveKind, Cover, SkyCode};
use super::wind::digits;

/// What a token is, seen as a sky group.
#[derive(Debug, PartialEq)]
pub(super) enum SkyToken {
    /// A cloud layer or vertical visibility.
    Cloud(CloudGroup),
    /// A no-cloud code.
    Code(SkyCode),
    /// Starts like a cloud group but does not decode (`FEW040TCUBKN070`).
    Malformed(&'static str),
    /// Not a sky group.
    No,
}

/// Decodes a sky group token.
pub(super) fn parse_sky(token: &str) -> SkyToken {
    match token {
        "CLR" => return SkyToken::Code(SkyCode::Clr),
        "SKC" => return SkyToken::Code(SkyCode::Skc),
        "NSC" => return SkyToken::Code(SkyCode::Nsc),
        "NCD" => return SkyToken::Code(SkyCode::Ncd),
        _ => {}
    }
    if let Some(vv) = token.strip_prefix("VV") {
        return match height_ft(vv) {
            Some(base_ft) => SkyToken::Cloud(CloudGroup {
                cover: Some(Cover::Vv),
                base_ft,
                kind: None,
            }),
            None => SkyToken::Malformed("vertical visibility is not three digits or ///"),
        };
    }
    if token.len() < 3 || !token.is_char_boundary(3) {
        return SkyToken::No;
    }
    let (cover, rest) = token.split_at(3);
    let cover = match cover {
        "FEW" => Some(Cover::Few),
        "SCT" => Some(Cover::Sct),
        "BKN" => Some(Cover::Bkn),
        "OVC" => Some(Cover::Ovc),
        "///" => None,
        _ => return SkyToken::No,
    };
    // `///CB`, `///TCU`: a convective cloud with neither cover nor base.
    if cover.is_none()
        && let Some(kind) = kind(rest)
    {
        return SkyToken::Cloud(CloudGroup {
            cover: None,
            base_ft: None,
            kind,
        });
    }
    if rest.len() < 3 || !rest.is_char_boundary(3) {
        return SkyToken::Malformed("cloud base is not three digits or ///");
    }
    let (base, suffix) = rest.split_at(3);
    let Some(base_ft) = height_ft(base) else {
        return SkyToken::Malformed("cloud base is not three digits or ///");
    };
    let Some(kind) = kind(suffix) else {
        return SkyToken::Malformed("cloud type is not CB, TCU or ///");
    };
    SkyToken::Cloud(CloudGroup {
        cover,
        base_ft,
        kind,
    })
}

/// Three digits of hundreds of feet, or `///` (`Some(None)`); `None` when neither.
fn height_ft(text: &str) -> Option<Option<u32>> {
    match text {
        "///" => Some(None),
        _ if text.len() == 3 => digits(text).map(|h| Some(h * 100)),
        _ => None,
    }
}

/// The convective-cloud suffix: empty or `///` (`Some(None)`), CB, TCU; `None` when neither.
fn kind(text: &str) -> Option<Option<ConvectiveKind>> {
    match text {
        "" | "///" => Some(None),
        "CB" => Some(Some(ConvectiveKind::Cb)),
        "TCU" => Some(Some(ConvectiveKind::Tcu)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(token: &str) -> CloudGroup {
        match parse_sky(token) {
            SkyToken::Cloud(c) => c,
            other => panic!("{token}: {other:?}"),
        }
    }

    fn group(
        cover: Option<Cover>,
        base_ft: Option<u32>,
        kind: Option<ConvectiveKind>,
    ) -> CloudGroup {
        CloudGroup {
            cover,
            base_ft,
            kind,
        }
    }

    #[test]
    fn covers_and_bases() {
        assert_eq!(cloud("FEW020"), group(Some(Cover::Few), Some(2_000), None));
        assert_eq!(cloud("SCT028"), group(Some(Cover::Sct), Some(2_800), None));
        assert_eq!(cloud("BKN300"), group(Some(Cover::Bkn), Some(30_000), None));
        assert_eq!(cloud("OVC000"), group(Some(Cover::Ovc), Some(0), None));
    }

    #[test]
    fn convective_suffixes() {
        let cb = Some(ConvectiveKind::Cb);
        let tcu = Some(ConvectiveKind::Tcu);
        assert_eq!(cloud("FEW012CB"), group(Some(Cover::Few), Some(1_200), cb));
        assert_eq!(
            cloud("SCT040TCU"),
            group(Some(Cover::Sct), Some(4_000), tcu)
        );
        assert_eq!(
            cloud("BKN015///"),
            group(Some(Cover::Bkn), Some(1_500), None)
        );
    }

    #[test]
    fn missing_cover_base_or_type() {
        let cb = Some(ConvectiveKind::Cb);
        let tcu = Some(ConvectiveKind::Tcu);
        assert_eq!(cloud("BKN///"), group(Some(Cover::Bkn), None, None));
        assert_eq!(cloud("FEW///CB"), group(Some(Cover::Few), None, cb));
        assert_eq!(cloud("///015"), group(None, Some(1_500), None));
        assert_eq!(cloud("//////CB"), group(None, None, cb));
        assert_eq!(cloud("//////TCU"), group(None, None, tcu));
        assert_eq!(cloud("///TCU"), group(None, None, tcu));
        assert_eq!(cloud("///CB"), group(None, None, cb));
    }

    #[test]
    fn vertical_visibility() {
        assert_eq!(cloud("VV001"), group(Some(Cover::Vv), Some(100), None));
        assert_eq!(cloud("VV///"), group(Some(Cover::Vv), None, None));
        assert!(matches!(parse_sky("VV1"), SkyToken::Malformed(_)));
    }

    #[test]
    fn no_cloud_codes() {
        assert_eq!(parse_sky("CLR"), SkyToken::Code(SkyCode::Clr));
        assert_eq!(parse_sky("SKC"), SkyToken::Code(SkyCode::Skc));
        assert_eq!(parse_sky("NSC"), SkyToken::Code(SkyCode::Nsc));
        assert_eq!(parse_sky("NCD"), SkyToken::Code(SkyCode::Ncd));
    }

    #[test]
    fn malformed_groups() {
        assert!(matches!(
            parse_sky("FEW040TCUBKN070"),
            SkyToken::Malformed(_)
        ));
        assert!(matches!(parse_sky("BKN02"), SkyToken::Malformed(_)));
        assert!(matches!(parse_sky("OVC0100"), SkyToken::Malformed(_)));
        assert!(matches!(parse_sky("SCT"), SkyToken::Malformed(_)));
        assert_eq!(parse_sky("RA"), SkyToken::No);
        assert_eq!(parse_sky("FG"), SkyToken::No);
    }
}

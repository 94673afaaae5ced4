//! Cloud types from remarks. Canadian stations (and a few others) report the type and oktas of
//! each layer after `RMK`, lowest first, with obscuring phenomena ahead of them:
//! `BKN098 BKN110 BKN240 ... RMK AC5AC1CI1` says the three layers are altocumulus (5 oktas),
//! altocumulus (1) and cirrus (1); `FEW007 SCT014 OVC022 ... RMK SN2SF1SC2NS4` has 2 oktas hidden
//! by snow, then stratus fractus, stratocumulus and nimbostratus. The oktas are each layer's own;
//! the body's covers are the running sums (MANOBS, Manual of Surface Weather Observations, ch. 10).

use super::cloud_type::CloudType;
use super::metar::{CloudGroup, Cover};

/// One entry of a cloud-type remark.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RemarkLayer {
    /// The cloud type named, or `None` for an obscuring phenomenon (FG, BR, SN, BLSN, ...).
    pub cloud_type: Option<CloudType>,
    /// Oktas of sky this layer or phenomenon covers on its own, 0..=8.
    pub oktas: u8,
}

/// Cloud-type codes of the remark and the skycast type each becomes.
const CLOUD_CODES: [(&str, CloudType); 15] = [
    ("TCU", CloudType::CumulusCongestus),
    ("ACC", CloudType::Altocumulus),
    ("CB", CloudType::Cumulonimbus),
    ("CU", CloudType::CumulusMediocris),
    ("CF", CloudType::CumulusHumilis),
    ("SC", CloudType::Stratocumulus),
    ("ST", CloudType::Stratus),
    ("SF", CloudType::Stratus),
    ("NS", CloudType::Nimbostratus),
    ("AC", CloudType::Altocumulus),
    ("AS", CloudType::Altostratus),
    ("CC", CloudType::Cirrocumulus),
    ("CS", CloudType::Cirrostratus),
    ("CI", CloudType::Cirrus),
    ("FG", CloudType::Fog),
];

/// Obscuring phenomena that may lead a cloud-type remark (they hide sky but are no cloud layer).
const OBSCURATION_CODES: [&str; 14] = [
    "BLSN", "BLDU", "BLSA", "BR", "SN", "RA", "DZ", "HZ", "FU", "SG", "IC", "PL", "DU", "SA",
];

/// Parses the first cloud-type group of a remark text (`SC1AC1CI2`), if there is one.
/// Entries are matched greedily against the known codes; a group with any unknown code, or
/// oktas outside 1..=8, is not a cloud-type remark and yields nothing.
pub fn remark_layers(remarks: &str) -> Vec<RemarkLayer> {
    remarks
        .split_whitespace()
        .find_map(parse_group)
        .unwrap_or_default()
}

fn parse_group(group: &str) -> Option<Vec<RemarkLayer>> {
    let mut rest = group;
    let mut layers = Vec::new();
    while !rest.is_empty() {
        let (code_len, cloud_type) = code_at(rest)?;
        let digit = rest[code_len..].chars().next()?.to_digit(10)?;
        if !(1..=8).contains(&digit) {
            return None;
        }
        layers.push(RemarkLayer {
            cloud_type,
            oktas: digit as u8,
        });
        rest = &rest[code_len + 1..];
    }
    // A lone obscuration such as `SN8` still counts: it tells what a VV layer is made of.
    (!layers.is_empty()).then_some(layers)
}

/// The longest known code at the start of `text`: its length and the cloud type it names.
fn code_at(text: &str) -> Option<(usize, Option<CloudType>)> {
    let cloud = CLOUD_CODES
        .iter()
        .filter(|(code, _)| text.starts_with(code))
        .map(|(code, t)| (code.len(), Some(*t)));
    let obscuration = OBSCURATION_CODES
        .iter()
        .filter(|code| text.starts_with(*code))
        .map(|code| (code.len(), None));
    // FG is listed as a cloud (fog) so a VV layer over fog becomes fog; longest match wins.
    cloud.chain(obscuration).max_by_key(|(len, _)| *len)
}

/// The remark's type for each of the report's cloud groups, in order, or `None` where the remark
/// says nothing about that group.
///
/// Cloud entries are paired with the cloud groups in order. A vertical-visibility group takes the
/// obscuring phenomenon (fog). When the number of cloud entries and cloud groups differ the pairing
/// is unsafe and nothing is returned: better the height rule than a wrong type.
pub fn remark_types(clouds: &[CloudGroup], remarks: &str) -> Vec<Option<CloudType>> {
    let entries = remark_layers(remarks);
    let mut types = vec![None; clouds.len()];
    let layer_entries: Vec<CloudType> = entries
        .iter()
        .filter_map(|e| e.cloud_type)
        .filter(|t| *t != CloudType::Fog)
        .collect();
    let has_obscuration = entries
        .iter()
        .any(|e| matches!(e.cloud_type, None | Some(CloudType::Fog)));
    let layer_slots: Vec<usize> = (0..clouds.len())
        .filter(|&k| clouds[k].cover != Some(Cover::Vv))
        .collect();
    if layer_entries.len() == layer_slots.len() {
        for (slot, t) in layer_slots.into_iter().zip(layer_entries) {
            types[slot] = Some(t);
        }
    }
    if has_obscuration {
        for (k, group) in clouds.iter().enumerate() {
            if group.cover == Some(Cover::Vv) {
                types[k] = Some(CloudType::Fog);
            }
        }
    }
    types
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(cover: Cover, base_ft: u32) -> CloudGroup {
        CloudGroup {
            cover: Some(cover),
            base_ft: Some(base_ft),
            kind: None,
        }
    }

    #[test]
    fn parses_types_and_oktas_in_order() {
        let layers = remark_layers("AC5AC1CI1 SLP947");
        let types: Vec<_> = layers.iter().map(|l| (l.cloud_type, l.oktas)).collect();
        assert_eq!(
            types,
            [
                (Some(CloudType::Altocumulus), 5),
                (Some(CloudType::Altocumulus), 1),
                (Some(CloudType::Cirrus), 1)
            ]
        );
    }

    #[test]
    fn obscuration_then_layers() {
        let layers = remark_layers("SN2SF1SC2NS4 SF TR VIS CHGG RPDLY PRESRR SLP927");
        assert_eq!(layers.len(), 4);
        assert_eq!(
            layers[0],
            RemarkLayer {
                cloud_type: None,
                oktas: 2
            }
        );
        assert_eq!(
            layers[3],
            RemarkLayer {
                cloud_type: Some(CloudType::Nimbostratus),
                oktas: 4
            }
        );
    }

    #[test]
    fn other_remarks_are_not_cloud_types() {
        for text in [
            "AO2 SLP123 T00560028",
            "SLP914",
            "PRESRR",
            "VIS VRB 1 1/2-3",
            "CIG RAG",
            "SC0",
            "",
        ] {
            assert!(remark_layers(text).is_empty(), "{text}");
        }
    }

    #[test]
    fn pairs_entries_with_groups_and_skips_obscuration() {
        let clouds = [
            layer(Cover::Few, 7),
            layer(Cover::Sct, 14),
            layer(Cover::Ovc, 22),
        ];
        let types = remark_types(&clouds, "SN2SF1SC2NS4 SF TR");
        assert_eq!(
            types,
            [
                Some(CloudType::Stratus),
                Some(CloudType::Stratocumulus),
                Some(CloudType::Nimbostratus)
            ]
        );
    }

    #[test]
    fn vertical_visibility_takes_the_obscuration() {
        let types = remark_types(&[layer(Cover::Vv, 10)], "SN8 SLP852");
        assert_eq!(types, [Some(CloudType::Fog)]);
    }

    #[test]
    fn a_count_mismatch_pairs_nothing() {
        let clouds = [layer(Cover::Few, 20), layer(Cover::Bkn, 140)];
        assert_eq!(remark_types(&clouds, "SC2AS5CS1"), [None, None]);
    }
}

#[cfg(test)]
mod bulk_file_tests {
    use std::path::Path;

    use super::*;
    use crate::weather::field::{CloudTypeRule, FieldSettings, WeatherField};
    use crate::weather::files::{self, PlacedReport};
    use crate::weather::{LocalFrame, TypeSource};

    fn bulk_file() -> Vec<PlacedReport> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("weather/awc-metars-2025-01-27T22Z.cache.csv");
        files::load(&path, None).unwrap().reports
    }

    fn types_of(reports: &[PlacedReport], station: &str) -> Vec<Option<CloudType>> {
        let r = &reports
            .iter()
            .find(|p| p.report.station == station)
            .unwrap()
            .report;
        remark_types(&r.clouds, &r.remarks)
    }

    #[test]
    fn real_reports_get_their_remark_types() {
        use CloudType::*;
        let reports = bulk_file();
        // CYHY: BKN098 BKN110 BKN240 RMK AC5AC1CI1
        assert_eq!(
            types_of(&reports, "CYHY"),
            [Some(Altocumulus), Some(Altocumulus), Some(Cirrus)]
        );
        // CYAM: FEW007 SCT014 OVC022 RMK SN2SF1SC2NS4
        assert_eq!(
            types_of(&reports, "CYAM"),
            [Some(Stratus), Some(Stratocumulus), Some(Nimbostratus)]
        );
        // CYCO: FEW020 BKN140 OVC260 RMK SC2AS5CS1
        assert_eq!(
            types_of(&reports, "CYCO"),
            [Some(Stratocumulus), Some(Altostratus), Some(Cirrostratus)]
        );
        // CYVO: VV010 RMK SN8 (snow hides the sky: drawn as fog)
        assert_eq!(types_of(&reports, "CYVO"), [Some(Fog)]);
        // KLAX has no cloud-type remark.
        assert!(types_of(&reports, "KLAX").iter().all(Option::is_none));
        // The figures quoted in the book (docs/src/weather.md). The one remark that types no
        // layer is CYRT's `BLSN2`: blowing snow over a sky with no cloud group.
        let typed = reports
            .iter()
            .filter(|p| {
                remark_types(&p.report.clouds, &p.report.remarks)
                    .iter()
                    .any(Option::is_some)
            })
            .count();
        let with_remark = reports
            .iter()
            .filter(|p| !remark_layers(&p.report.remarks).is_empty())
            .count();
        assert_eq!(
            (with_remark, typed),
            (141, 140),
            "reports with a cloud-type remark, and typed by it"
        );
    }

    #[test]
    fn the_field_draws_remark_types_at_their_station() {
        let reports = bulk_file();
        let cyhy = reports.iter().find(|p| p.report.station == "CYHY").unwrap();
        let frame = LocalFrame::new(cyhy.position.latitude_deg, cyhy.position.longitude_deg);
        let field = WeatherField::build(
            frame,
            &reports,
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        );
        let layers = field.weather_at(glam::DVec2::ZERO).layers;
        let types: Vec<_> = layers
            .iter()
            .map(|l| (l.cloud_type, l.type_source))
            .collect();
        // Every layer of its own, each with the type its remark gives.
        assert_eq!(
            types,
            [
                (CloudType::Altocumulus, TypeSource::Remark),
                (CloudType::Altocumulus, TypeSource::Remark),
                (CloudType::Cirrus, TypeSource::Remark)
            ]
        );
    }
}

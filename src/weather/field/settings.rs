//! The field's settings, `config/weather_field.toml`: the bands of the type rule, METAR cover to
//! oktas, default thickness per cover, vertical extent by cloud type, fog, CB/TCU survival, how
//! layers of neighbouring stations blend, precipitation and fall-back values.

use std::path::Path;

use serde::Deserialize;

use crate::config::{ConfigError, ShippedFile, TomlSettings};
use crate::weather::metar::Cover;

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../../config/weather_field.toml");

/// Settings of the weather field (units in the names; heights feet AGL).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    /// Altitude band limits (they choose the type rule; layers are never merged by band).
    pub bands: Bands,
    /// Oktas per METAR cover.
    pub oktas: PerCover,
    /// Thickness per cover, feet.
    pub thickness_ft: PerCover,
    /// Vertical extent by cloud type.
    pub extent: Extent,
    /// Fog layers.
    pub fog: Fog,
    /// CB/TCU survival through interpolation.
    pub convective: Convective,
    /// Which interpolated layers are kept.
    pub layers: Layers,
    /// How far around a station its own report holds before the interpolation takes over
    /// (absent from an older file: the shipped values).
    #[serde(default)]
    pub stations: StationHold,
    /// Precipitation intensity by present-weather intensity.
    pub precipitation: Precipitation,
    /// Fall-back values.
    pub defaults: Defaults,
}

/// Band limits, feet AGL.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bands {
    /// Bases below this are low.
    pub low_top_ft: f64,
    /// Bases above this are high.
    pub high_base_ft: f64,
}

/// One value per METAR cover.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerCover {
    /// FEW.
    pub few: f64,
    /// SCT.
    pub sct: f64,
    /// BKN.
    pub bkn: f64,
    /// OVC.
    pub ovc: f64,
}

impl PerCover {
    /// The value for a cover (VV counts as OVC).
    pub fn get(&self, cover: Cover) -> f64 {
        match cover {
            Cover::Few => self.few,
            Cover::Sct => self.sct,
            Cover::Bkn => self.bkn,
            Cover::Ovc | Cover::Vv => self.ovc,
        }
    }
}

/// Vertical extent by cloud type: where the type, not the cover, decides how tall a layer is.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extent {
    /// Cumulonimbus tops (anvil included), feet AGL: the first at or below the cold end of
    /// `convective_top_by_temperature_c`, the second at or above its warm end.
    pub cumulonimbus_top_ft: [f64; 2],
    /// Towering cumulus (cumulus congestus) tops, feet AGL, as for the cumulonimbus.
    pub congestus_top_ft: [f64; 2],
    /// Surface temperatures, degrees C, between which convective tops rise from the first to the
    /// second of their range (a warmer surface, a higher tropopause).
    pub convective_top_by_temperature_c: [f64; 2],
    /// Fair-weather cumulus (humilis, mediocris) thickness, feet: the first at or below the first
    /// temperature-dewpoint spread of `fair_weather_cumulus_by_spread_c`, the second at or above
    /// the second.
    pub fair_weather_cumulus_thickness_ft: [f64; 2],
    /// Spreads, degrees C, between which fair-weather cumulus thickens.
    pub fair_weather_cumulus_by_spread_c: [f64; 2],
    /// Stratus thickness, feet.
    pub stratus_thickness_ft: f64,
}

impl Extent {
    /// Top of a cumulonimbus over a surface at `temperature_c`, feet AGL.
    pub fn cumulonimbus_top_ft(&self, temperature_c: f64) -> f64 {
        lerp_by(
            self.cumulonimbus_top_ft,
            self.convective_top_by_temperature_c,
            temperature_c,
        )
    }

    /// Top of a towering cumulus over a surface at `temperature_c`, feet AGL.
    pub fn congestus_top_ft(&self, temperature_c: f64) -> f64 {
        lerp_by(
            self.congestus_top_ft,
            self.convective_top_by_temperature_c,
            temperature_c,
        )
    }

    /// Thickness of fair-weather cumulus at a temperature-dewpoint spread, feet.
    pub fn fair_weather_cumulus_thickness_ft(&self, spread_c: f64) -> f64 {
        lerp_by(
            self.fair_weather_cumulus_thickness_ft,
            self.fair_weather_cumulus_by_spread_c,
            spread_c,
        )
    }
}

/// `values[0]` at or below `by[0]`, `values[1]` at or above `by[1]`, linear between.
fn lerp_by(values: [f64; 2], by: [f64; 2], x: f64) -> f64 {
    let t = if by[1] > by[0] {
        ((x - by[0]) / (by[1] - by[0])).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let t = if t.is_finite() { t } else { 0.0 };
    values[0] + (values[1] - values[0]) * t
}

/// Fog layers.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fog {
    /// Fog top above ground when no VV height says otherwise, feet.
    pub thickness_ft: f64,
}

/// CB/TCU through interpolation.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Convective {
    /// Share of natural-neighbour weight the reporting stations need, 0..=1.
    pub weight_min: f64,
    /// Base for a CB/TCU group without one, feet AGL.
    pub unknown_base_ft: f64,
}

/// How the layers of neighbouring stations blend, and which are kept.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layers {
    /// Least interpolated coverage of a kept layer, oktas.
    pub min_coverage_oktas: f64,
    /// Layers of different stations whose bases lie within the larger of this, feet ...
    pub blend_within_ft: f64,
    /// ... and this fraction of the base are one layer between the stations.
    pub blend_within_fraction: f64,
    /// Least own coverage of a reported layer that adds no cover seen from below (`BKN010
    /// BKN020`), oktas: it is still drawn, seen through the gaps of the one below.
    pub min_added_oktas: f64,
    /// Least cover a reported layer adds to the sky seen from below, oktas (times its
    /// presence), as far as the class reported at its base allows (`BKN033 BKN041` over 6
    /// oktas: 0.75 of the 1 okta left to BKN's 7), so that a ceilometer meets its base through
    /// the gaps below, as its station's did when it reported it.
    #[serde(default = "default_min_seen_added_oktas")]
    pub min_seen_added_oktas: f64,
    /// Least thickness of a layer squeezed under the next base, feet.
    pub min_thickness_ft: f64,
}

/// [`Layers::min_seen_added_oktas`] where a settings file does not set it.
fn default_min_seen_added_oktas() -> f64 {
    0.75
}

/// How far around a station its own report holds. A METAR describes the sky over its station
/// and its vicinity (the 5-10 statute miles an observer's "VC" means; an automatic station's
/// ceilometer sees the clouds the wind carries over it in 30 minutes), not a point: within
/// `hold_m` the station's natural-neighbour weight is raised `hold_weight` times, and from there
/// to `hold_m + fade_m` the raise fades out. Two stations inside each other's hold blend as
/// before (both are raised alike), so the field stays continuous.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationHold {
    /// Distance from a station within which its report holds, metres.
    pub hold_m: f64,
    /// Distance over which the hold fades to plain interpolation, metres.
    pub fade_m: f64,
    /// How many times a station's weight is raised within the hold (1: no hold).
    pub hold_weight: f64,
}

impl Default for StationHold {
    /// The shipped values (`[stations]` of `config/weather_field.toml`).
    fn default() -> Self {
        FieldSettings::default().stations
    }
}

impl StationHold {
    /// The factor a station's weight is raised by at `distance_m` from it: `hold_weight`
    /// within `hold_m`, falling to 1 over `fade_m` evenly in its logarithm (a weight raised
    /// 50 times hardly moves until the raise is a few times; a linear fall left the whole
    /// change to the fade's last kilometre).
    pub fn raise_at(&self, distance_m: f64) -> f64 {
        let t = ((self.hold_m + self.fade_m - distance_m) / self.fade_m.max(1e-9)).clamp(0.0, 1.0);
        // Smoothstep: the weights' slope does not step where the fade starts or ends.
        self.hold_weight.powf(t * t * (3.0 - 2.0 * t))
    }
}

/// Precipitation intensity 0..=1 per present-weather intensity.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Precipitation {
    /// `-RA`.
    pub light: f64,
    /// `RA`.
    pub moderate: f64,
    /// `+RA`.
    pub heavy: f64,
}

/// Values used where no station reports one.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Defaults {
    /// Visibility, metres.
    pub visibility_m: f64,
    /// Temperature, degrees C.
    pub temperature_c: f64,
    /// Dewpoint, degrees C.
    pub dewpoint_c: f64,
    /// Ground elevation, metres above mean sea level.
    pub ground_elevation_m: f64,
    /// Visibility of a CAVOK report, metres.
    pub cavok_visibility_m: f64,
}

impl TomlSettings for FieldSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/weather_field.toml", BUILTIN);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        if !(self.bands.low_top_ft > 0.0 && self.bands.low_top_ft <= self.bands.high_base_ft) {
            return Err(bad(
                "bands.low_top_ft",
                "must be above 0 and at most bands.high_base_ft",
            ));
        }
        let e = &self.extent;
        for (field, range) in [
            ("extent.cumulonimbus_top_ft", e.cumulonimbus_top_ft),
            ("extent.congestus_top_ft", e.congestus_top_ft),
            (
                "extent.fair_weather_cumulus_thickness_ft",
                e.fair_weather_cumulus_thickness_ft,
            ),
            (
                "extent.convective_top_by_temperature_c",
                e.convective_top_by_temperature_c,
            ),
            (
                "extent.fair_weather_cumulus_by_spread_c",
                e.fair_weather_cumulus_by_spread_c,
            ),
        ] {
            if !(range[0].is_finite() && range[1].is_finite() && range[0] <= range[1]) {
                return Err(bad(
                    field,
                    "must be two finite numbers, the first at most the second",
                ));
            }
        }
        let l = &self.layers;
        if !(l.blend_within_ft >= 0.0 && (0.0..1.0).contains(&l.blend_within_fraction)) {
            return Err(bad(
                "layers.blend_within_fraction",
                "must be within 0..1 (and layers.blend_within_ft at least 0)",
            ));
        }
        if !(0.0..=8.0).contains(&l.min_added_oktas) {
            return Err(bad("layers.min_added_oktas", "must be within 0..=8"));
        }
        if !(0.0..=8.0).contains(&l.min_seen_added_oktas) {
            return Err(bad("layers.min_seen_added_oktas", "must be within 0..=8"));
        }
        let h = &self.stations;
        for (field, ok, message) in [
            (
                "stations.hold_m",
                h.hold_m >= 0.0,
                "must be at least 0 metres",
            ),
            ("stations.fade_m", h.fade_m > 0.0, "must be above 0 metres"),
            (
                "stations.hold_weight",
                h.hold_weight >= 1.0 && h.hold_weight.is_finite(),
                "must be at least 1 (1: no hold)",
            ),
        ] {
            if !ok {
                return Err(bad(field, message));
            }
        }
        if !(0.0..=1.0).contains(&self.convective.weight_min) {
            return Err(bad("convective.weight_min", "must be within 0..=1"));
        }
        Ok(())
    }
}

impl Default for FieldSettings {
    /// The shipped `config/weather_field.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_settings_parse() {
        let s = FieldSettings::default();
        assert_eq!(s.oktas.get(Cover::Bkn), 6.0);
        assert_eq!(s.bands.low_top_ft, 6500.0);
        assert_eq!(s.bands.high_base_ft, 20000.0);
        let e = s.extent;
        assert_eq!(e.cumulonimbus_top_ft(-10.0), 25_000.0);
        assert_eq!(e.cumulonimbus_top_ft(40.0), 40_000.0);
        assert!((e.congestus_top_ft(15.0) - 16_000.0).abs() < 1e-9);
        let (thin, thick) = (
            e.fair_weather_cumulus_thickness_ft(1.0),
            e.fair_weather_cumulus_thickness_ft(20.0),
        );
        assert!(thin < thick, "{thin} {thick}");
    }

    #[test]
    fn a_reversed_extent_range_names_its_line() {
        let text = BUILTIN.replace(
            "cumulonimbus_top_ft = [25000.0, 40000.0]",
            "cumulonimbus_top_ft = [40000.0, 25000.0]",
        );
        let err = FieldSettings::parse(&text, Path::new("f.toml")).unwrap_err();
        let line = BUILTIN
            .lines()
            .position(|l| l.starts_with("cumulonimbus_top_ft"))
            .unwrap()
            + 1;
        assert!(
            err.to_string().starts_with(&format!(
                "f.toml:{line}: field `extent.cumulonimbus_top_ft`"
            )),
            "{err}"
        );
    }

    #[test]
    fn a_bad_station_hold_names_its_own_field() {
        for (line, field) in [
            ("fade_m = 5000.0", "stations.fade_m"),
            ("hold_m = 5000.0", "stations.hold_m"),
            ("hold_weight = 50.0", "stations.hold_weight"),
        ] {
            let key = line.split(' ').next().unwrap();
            let text = BUILTIN.replace(line, &format!("{key} = -1.0"));
            let err = FieldSettings::parse(&text, Path::new("f.toml")).unwrap_err();
            let at = BUILTIN.lines().position(|l| l == line).unwrap() + 1;
            assert!(
                err.to_string()
                    .starts_with(&format!("f.toml:{at}: field `{field}`")),
                "{err}"
            );
        }
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let text = BUILTIN.replace("few = 2.0", "few = \"two\"");
        let err = FieldSettings::parse(&text, Path::new("f.toml")).unwrap_err();
        assert_eq!(err.field.as_deref(), Some("few"), "{err}");
        let line = BUILTIN.lines().position(|l| l == "few = 2.0").unwrap() + 1;
        assert_eq!(err.line, Some(line), "{err}");
        let text = BUILTIN.replace("weight_min = 0.5", "weight_min = 5.0");
        let err = FieldSettings::parse(&text, Path::new("f.toml")).unwrap_err();
        let line = BUILTIN
            .lines()
            .position(|l| l.starts_with("weight_min"))
            .unwrap()
            + 1;
        assert!(
            err.to_string()
                .starts_with(&format!("f.toml:{line}: field `convective.weight_min`")),
            "{err}"
        );
    }
}

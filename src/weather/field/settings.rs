//! The field's settings, `config/weather_field.toml`: altitude bands, METAR cover to oktas,
//! default thickness per cover, fog, CB/TCU survival, precipitation and fall-back values.

use std::path::Path;

use serde::Deserialize;

use crate::config::{ConfigError, parse_toml};
use crate::weather::metar::Cover;

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../../config/weather_field.toml");

/// Settings of the weather field (units in the names; heights feet AGL).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    /// Altitude band limits.
    pub bands: Bands,
    /// Oktas per METAR cover.
    pub oktas: PerCover,
    /// Thickness per cover, feet.
    pub thickness_ft: PerCover,
    /// Fog layers.
    pub fog: Fog,
    /// CB/TCU survival through interpolation.
    pub convective: Convective,
    /// Which interpolated layers are kept.
    pub layers: Layers,
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

/// Which layers are kept.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layers {
    /// Least interpolated coverage of a kept layer, oktas.
    pub min_coverage_oktas: f64,
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

impl FieldSettings {
    /// Reads settings from a TOML file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|err| ConfigError::whole_file(path, format!("cannot read: {err}")))?;
        Self::parse(&text, path)
    }

    /// Parses settings text that came from `path`.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let settings: Self = parse_toml(text, path)?;
        settings.validate(text, path)
    }

    fn validate(self, text: &str, path: &Path) -> Result<Self, ConfigError> {
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        if !(self.bands.low_top_ft > 0.0 && self.bands.low_top_ft <= self.bands.high_base_ft) {
            return Err(bad(
                "bands.low_top_ft",
                "must be above 0 and at most bands.high_base_ft",
            ));
        }
        if !(0.0..=1.0).contains(&self.convective.weight_min) {
            return Err(bad("convective.weight_min", "must be within 0..=1"));
        }
        Ok(self)
    }
}

impl Default for FieldSettings {
    /// The shipped `config/weather_field.toml` (a test proves it parses).
    fn default() -> Self {
        match Self::parse(BUILTIN, Path::new("config/weather_field.toml")) {
            Ok(settings) => settings,
            Err(err) => panic!("built-in config/weather_field.toml: {err}"),
        }
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

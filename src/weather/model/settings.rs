//! The model's settings, `config/weather_model.toml`: how its layers become skycast's layers and
//! how the model blends with the reports.

use std::path::Path;

use serde::Deserialize;

use crate::config::{ConfigError, ShippedFile, TomlSettings};

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../../config/weather_model.toml");

/// Settings of a weather model source (units in the names).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSettings {
    /// How the reports and the model blend.
    pub blend: BlendSettings,
    /// How the model's layers become layers.
    pub layers: ModelLayerSettings,
    /// The weather at the ground.
    pub surface: ModelSurfaceSettings,
    /// How far from the simulated time a model may be valid.
    pub time: ModelTimeSettings,
}

/// `[blend]`: the reports' weight by distance from the nearest station reporting the sky.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendSettings {
    /// Out to this distance, km, the report alone.
    pub station_full_km: f64,
    /// From this distance, km, the model alone.
    pub station_fade_km: f64,
    /// A report this many hours older than the newest, or less, weighs fully.
    pub report_age_full_h: f64,
    /// A report this many hours older than the newest, or more, gives way to the model.
    pub report_age_fade_h: f64,
}

impl BlendSettings {
    /// The reports' weight 0..=1 at `distance_km` from the nearest station: 1 out to
    /// `station_full_km`, 0 from `station_fade_km`, smoothstep between (continuous, with a
    /// continuous slope, so nothing pops where the weight changes).
    pub fn report_weight(&self, distance_km: f64) -> f64 {
        let span = self.station_fade_km - self.station_full_km;
        let t = ((distance_km - self.station_full_km) / span).clamp(0.0, 1.0);
        1.0 - t * t * (3.0 - 2.0 * t)
    }

    /// A report's weight 0..=1 by its age, hours behind the newest report: 1 up to
    /// `report_age_full_h`, 0 from `report_age_fade_h`, smoothstep between.
    pub fn age_weight(&self, age_h: f64) -> f64 {
        let span = self.report_age_fade_h - self.report_age_full_h;
        let t = ((age_h - self.report_age_full_h) / span).clamp(0.0, 1.0);
        1.0 - t * t * (3.0 - 2.0 * t)
    }
}

/// `[layers]`: which model layers are drawn and as what type.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelLayerSettings {
    /// Layers with less cover, oktas, are left out.
    pub cover_min_oktas: f64,
    /// The thinnest layer, feet.
    pub thickness_min_ft: f64,
    /// A low layer with this cover, oktas, or more (and thin) is stratus.
    pub stratus_cover_oktas: f64,
    /// The thickest stratus, feet.
    pub stratus_thickness_max_ft: f64,
    /// A raining low layer with this cover, oktas, or more is nimbostratus.
    pub nimbostratus_cover_oktas: f64,
    /// The rain, mm/h, that makes a low layer nimbostratus.
    pub nimbostratus_rain_mm_h: f64,
    /// A low layer with this cover, oktas, or less (and CAPE) is cumulus.
    pub cumulus_cover_oktas: f64,
    /// The CAPE, J/kg, that makes a thin low layer cumulus.
    pub cumulus_cape_j_kg: f64,
    /// A middle or high layer with this cover, oktas, or more is a sheet (altostratus,
    /// cirrostratus).
    pub sheet_cover_oktas: f64,
    /// The CAPE, J/kg, that makes the convective layer cumulonimbus (else towering cumulus).
    pub cumulonimbus_cape_j_kg: f64,
}

/// `[surface]`: precipitation and visibility.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSurfaceSettings {
    /// No precipitation under this rate, mm/h.
    pub light_mm_h: f64,
    /// Heavy precipitation (intensity 1) from this rate, mm/h.
    pub heavy_mm_h: f64,
    /// Visibility where the model gives none, metres.
    pub visibility_m: f64,
}

impl ModelSurfaceSettings {
    /// Precipitation intensity 0..=1 at `rate_mm_h`.
    pub fn precipitation(&self, rate_mm_h: f64) -> f64 {
        if rate_mm_h < self.light_mm_h {
            return 0.0;
        }
        (rate_mm_h / self.heavy_mm_h).clamp(0.0, 1.0)
    }
}

/// `[time]`: when a model's valid time earns a warning.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelTimeSettings {
    /// Hours between the model's valid time and the simulated time past which a warning is
    /// given (the model is used all the same).
    pub warn_after_h: f64,
}

impl TomlSettings for ModelSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/weather_model.toml", BUILTIN);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, message: &str| Err(ConfigError::at_key(path, text, field, message));
        let b = self.blend;
        if !(b.station_full_km >= 0.0 && b.station_fade_km > b.station_full_km) {
            return bad(
                "blend.station_fade_km",
                "must be greater than blend.station_full_km (which is 0 or more)",
            );
        }
        if !(b.report_age_full_h >= 0.0 && b.report_age_fade_h > b.report_age_full_h) {
            return bad(
                "blend.report_age_fade_h",
                "must be greater than blend.report_age_full_h (which is 0 or more)",
            );
        }
        if self.surface.heavy_mm_h.is_nan() || self.surface.heavy_mm_h <= 0.0 {
            return bad("surface.heavy_mm_h", "must be greater than 0");
        }
        if !(self.layers.cover_min_oktas >= 0.0 && self.layers.cover_min_oktas <= 8.0) {
            return bad("layers.cover_min_oktas", "must be within 0..=8");
        }
        if self.time.warn_after_h.is_nan() || self.time.warn_after_h < 0.0 {
            return bad("time.warn_after_h", "must be 0 or more");
        }
        Ok(())
    }
}

impl Default for ModelSettings {
    /// The shipped `config/weather_model.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_settings_parse_and_a_wrong_fade_is_named() {
        let s = ModelSettings::default();
        assert_eq!(s.blend.report_weight(0.0), 1.0);
        assert_eq!(s.blend.report_weight(s.blend.station_fade_km + 1.0), 0.0);
        let text = BUILTIN.replace("station_fade_km = 80.0", "station_fade_km = 10.0");
        let err = ModelSettings::parse(&text, Path::new("m.toml")).unwrap_err();
        assert!(err.to_string().contains("blend.station_fade_km"), "{err}");
    }
}

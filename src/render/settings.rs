//! Renderer settings, read from `config/render.toml` (built in as the default).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::config::{ConfigError, ShippedFile, TomlSettings};

// The near sprites' own tables stand in a leaf their stages read without the whole tree;
// their paths here stay.
pub use super::sprites::settings::{CloudSettings, VertexCacheSettings};

/// The built-in settings, `config/render.toml`.
pub const DEFAULT_RENDER_TOML: &str = include_str!("../../config/render.toml");

/// Camera projection settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSettings {
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Near clip plane, metres.
    pub near_m: f32,
    /// Far clip plane, metres.
    pub far_m: f32,
}

/// In-cloud fog settings (Wang 7.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InCloudSettings {
    /// Visibility inside a cloud, metres.
    pub visibility_m: f32,
    /// Fog ramps in over this fraction of the cloud half-extent inside its boundary.
    pub ramp_fraction: f32,
}

/// Sun disc settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunSettings {
    /// Apparent radius of the disc, degrees.
    pub disc_radius_deg: f32,
    /// Radius of the glow around it, degrees.
    pub glow_radius_deg: f32,
}

/// All renderer settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSettings {
    /// Projection.
    pub camera: CameraSettings,
    /// Cloud sprites.
    pub clouds: CloudSettings,
    /// In-cloud fog.
    pub in_cloud: InCloudSettings,
    /// Sun disc.
    pub sun: SunSettings,
    /// Vertex cache.
    pub vertex_cache: VertexCacheSettings,
    /// The far-cloud impostor ring (Wang 6.2); built-in defaults when the table is absent.
    #[serde(default)]
    pub impostors: super::impostor::layout::ImpostorSettings,
    /// The round Earth (`[earth]`); curved with the mean radius when the table is absent.
    #[serde(default)]
    pub earth: super::earth::EarthSettings,
    /// The far field (`[far_field]`); the built-in defaults when the table is absent.
    #[serde(default)]
    pub far_field: super::far_field::FarFieldSettings,
    /// The clouds' shadows on the host's ground; built-in defaults when the table is absent.
    #[serde(default)]
    pub cloud_shadows: super::shadow::layout::ShadowSettings,
}

impl Default for RenderSettings {
    /// The shipped `config/render.toml` (built in; a test checks that it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

impl TomlSettings for RenderSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/render.toml", DEFAULT_RENDER_TOML);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let s = self;
        let positive = [
            ("camera.near_m", s.camera.near_m),
            ("camera.fov_y_deg", s.camera.fov_y_deg),
            ("clouds.soft_depth_fade_m", s.clouds.soft_depth_fade_m),
            ("clouds.haze_distance_m", s.clouds.haze_distance_m),
            ("in_cloud.visibility_m", s.in_cloud.visibility_m),
            (
                "vertex_cache.time_distance_m",
                s.vertex_cache.time_distance_m,
            ),
            // Not set is valid (fading clouds age as steady ones).
            (
                "vertex_cache.fading_max_age_s",
                s.vertex_cache.fading_max_age_s.unwrap_or(1.0),
            ),
        ];
        for (field, value) in positive {
            if value.is_nan() || value <= 0.0 {
                return Err(ConfigError::at_key(
                    path,
                    text,
                    field,
                    format!("must be greater than 0, is {value}"),
                ));
            }
        }
        let budgets = [
            (
                "vertex_cache.max_sorted_sprites_per_frame",
                s.vertex_cache.max_sorted_sprites_per_frame,
            ),
            (
                "vertex_cache.max_uploaded_sprites_per_frame",
                s.vertex_cache.max_uploaded_sprites_per_frame,
            ),
        ];
        for (field, value) in budgets {
            if value == 0 {
                return Err(ConfigError::at_key(path, text, field, "must be at least 1"));
            }
        }
        if super::cloud_target::divisor_of(s.clouds.resolution_scale).is_none() {
            return Err(ConfigError::at_key(
                path,
                text,
                "clouds.resolution_scale",
                format!("must be 1, 0.5 or 0.25, is {}", s.clouds.resolution_scale),
            ));
        }
        if !(s.earth.radius_m >= 1000.0 && s.earth.radius_m.is_finite()) {
            return Err(ConfigError::at_key(
                path,
                text,
                "earth.radius_m",
                format!("must be at least 1000 metres, is {}", s.earth.radius_m),
            ));
        }
        if let Some((field, message)) = s.far_field.invalid_field() {
            return Err(ConfigError::at_key(path, text, field, message));
        }
        if let Some((field, message)) = s.impostors.invalid_field() {
            return Err(ConfigError::at_key(path, text, field, message));
        }
        if let Some((field, message)) = s.cloud_shadows.invalid_field() {
            return Err(ConfigError::at_key(path, text, field, message));
        }
        let c = &s.clouds;
        if !(0.0..=1.0).contains(&c.far_fade_fraction) {
            return Err(ConfigError::at_key(
                path,
                text,
                "clouds.far_fade_fraction",
                format!("must be 0..=1, is {}", c.far_fade_fraction),
            ));
        }
        // Angle ranges above or below a sprite's level: 0 <= start < end <= 90 degrees.
        let angle_ranges = [
            (
                "upright_fade",
                c.upright_fade_start_deg,
                c.upright_fade_end_deg,
            ),
            ("layer_turn", c.layer_turn_start_deg, c.layer_turn_end_deg),
        ];
        for (name, start, end) in angle_ranges {
            if !(0.0 <= start && start < end && end <= 90.0) {
                return Err(ConfigError::at_key(
                    path,
                    text,
                    &format!("clouds.{name}_end_deg"),
                    format!("needs 0 <= {name}_start_deg < {name}_end_deg <= 90"),
                ));
            }
        }
        if s.camera.far_m <= s.camera.near_m {
            return Err(ConfigError::at_key(
                path,
                text,
                "camera.far_m",
                "must be greater than camera.near_m",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::line_of_key;

    #[test]
    fn built_in_settings_parse() {
        let s = RenderSettings::parse(DEFAULT_RENDER_TOML, Path::new("render.toml")).unwrap();
        assert_eq!(s, RenderSettings::default());
        assert_eq!(s.clouds.lock_radius_fraction, 0.5);
    }

    #[test]
    fn bad_values_name_the_field() {
        // The error of the shipped file with `from` replaced by `to`.
        let error_with = |from: &str, to: &str| {
            assert!(DEFAULT_RENDER_TOML.contains(from), "{from}");
            RenderSettings::parse(&DEFAULT_RENDER_TOML.replace(from, to), Path::new("r.toml"))
                .unwrap_err()
                .to_string()
        };
        // The error names the file, the key's line in it and the key.
        let names = |err: &str, key: &str| {
            let line = line_of_key(DEFAULT_RENDER_TOML, key).unwrap();
            assert!(
                err.starts_with(&format!("r.toml:{line}: field `{key}`")),
                "{err}"
            );
        };
        let err = error_with("soft_depth_fade_m = 120.0", "soft_depth_fade_m = -1.0");
        names(&err, "clouds.soft_depth_fade_m");
        let err = error_with("near_m = 2.0", "near_m = \"near\"");
        assert!(err.starts_with("r.toml:7: field `near_m`"), "{err}");
        let err = error_with("upright_fade_end_deg = 35.0", "upright_fade_end_deg = 10.0");
        assert!(err.contains("clouds.upright_fade_end_deg"), "{err}");
        let err = error_with(
            "max_sorted_sprites_per_frame = 8192",
            "max_sorted_sprites_per_frame = 0",
        );
        names(&err, "vertex_cache.max_sorted_sprites_per_frame");
        let err = error_with("layer_turn_end_deg = 72.0", "layer_turn_end_deg = 95.0");
        names(&err, "clouds.layer_turn_end_deg");
        assert!(err.contains("<= 90"), "{err}");
        let err = error_with("layer_turn_start_deg = 30.0", "layer_turn_start_deg = 80.0");
        names(&err, "clouds.layer_turn_end_deg");
        let err = error_with("far_fade_fraction = 0.3", "far_fade_fraction = 1.5");
        names(&err, "clouds.far_fade_fraction");
        let err = error_with("resolution_scale = 0.5", "resolution_scale = 0.3");
        names(&err, "clouds.resolution_scale");
        assert!(err.contains("must be 1, 0.5 or 0.25"), "{err}");
        let err = error_with("order_move_fraction = 0.06", "order_move_fraction = 0.0");
        names(&err, "impostors.order_move_fraction");
        assert!(err.contains("greater than 0"), "{err}");
        let err = error_with("size_px = 1024", "size_px = 2048");
        names(&err, "cloud_shadows.size_px");
        assert!(err.contains("4 MiB"), "{err}");
        let err = error_with("update_interval_s = 1.0", "update_interval_s = -2.0");
        names(&err, "cloud_shadows.update_interval_s");
        // Files written before the upright fade (and the later keys left out here) existed still
        // load, with their defaults.
        let old = DEFAULT_RENDER_TOML
            .lines()
            .filter(|l| {
                !l.starts_with("upright_fade")
                    && !l.starts_with("resolution_scale")
                    && !l.starts_with("far_fade_fraction")
                    && !l.starts_with("cull_out_of_view")
                    && !l.starts_with("layer_turn")
                    && !l.starts_with("max_sorted")
                    && !l.starts_with("max_uploaded")
            })
            .collect::<Vec<_>>()
            .join("\n");
        let s = RenderSettings::parse(&old, Path::new("old.toml")).unwrap();
        assert_eq!(s, RenderSettings::default());
    }
}

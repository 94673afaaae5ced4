//! Renderer settings, read from `config/render.toml` (built in as the default).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::config::{ConfigError, parse_toml};

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

fn default_upright_fade_start_deg() -> f32 {
    15.0
}

fn default_upright_fade_end_deg() -> f32 {
    35.0
}

/// Cloud sprite settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudSettings {
    /// Depth difference over which a sprite fades out against the scene (Bahnassi), metres.
    pub soft_depth_fade_m: f32,
    /// Facing locks within this fraction of the sprite radius (Wang 3.3).
    pub lock_radius_fraction: f32,
    /// Locked sprites stay opaque up to this angle to the camera, degrees.
    pub lock_fade_start_deg: f32,
    /// Locked sprites are fully transparent beyond this angle, degrees.
    pub lock_fade_end_deg: f32,
    /// Upright sprites (a heaped cloud's flat-bottomed rim) stay opaque seen from up to this
    /// angle above or below their level, degrees.
    #[serde(default = "default_upright_fade_start_deg")]
    pub upright_fade_start_deg: f32,
    /// Upright sprites are fully transparent seen from beyond this angle, degrees.
    #[serde(default = "default_upright_fade_end_deg")]
    pub upright_fade_end_deg: f32,
    /// Layer sprites (the wide, short puffs of stratus, nimbostratus, altostratus, stratocumulus
    /// and fog) are pancakes: seen from steeply above or below, their outline rounds to their
    /// width, and from this angle above or below their level they start to take a turn of their
    /// own about the view ray instead of the camera's (a deck seen from above otherwise lays
    /// every puff across the line to the nadir, in rings around it), degrees.
    #[serde(default = "default_layer_turn_start_deg")]
    pub layer_turn_start_deg: f32,
    /// Layer sprites have all of their own turn seen from beyond this angle, degrees.
    #[serde(default = "default_layer_turn_end_deg")]
    pub layer_turn_end_deg: f32,
    /// Sprites farther than this from the camera are not drawn, metres.
    pub draw_distance_m: f32,
    /// Distant sprites fade into the horizon haze: 63% at this distance, metres.
    pub haze_distance_m: f32,
    /// Resolution of the off-screen target the clouds (sprites, impostor ring, in-cloud fog) are
    /// drawn into, as a fraction of the host's: 1, 0.5 or 0.25 (1: straight into the host's
    /// colour). See [`super::cloud_target`].
    #[serde(default = "default_resolution_scale")]
    pub resolution_scale: f32,
    /// Clouds seen above the horizon fade out over this last fraction of the farthest distance a
    /// view draws them at (`draw_distance_m` for the camera's sprites, which hold the high and
    /// low layers the ring leaves out; the impostors' `view_radius_m` in the ring), 0..1: a high
    /// layer dissolves there instead of ending in a line across the sky. 0: no fade.
    #[serde(default = "default_far_fade_fraction")]
    pub far_fade_fraction: f32,
}

fn default_layer_turn_start_deg() -> f32 {
    30.0
}

fn default_layer_turn_end_deg() -> f32 {
    72.0
}

fn default_resolution_scale() -> f32 {
    0.5
}

fn default_far_fade_fraction() -> f32 {
    0.3
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

/// Vertex cache thresholds (Wang 6.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VertexCacheSettings {
    /// When false every cloud is recomputed every frame (for comparisons).
    pub enabled: bool,
    /// Recompute after the camera moves this fraction of its distance to the cloud.
    pub move_fraction: f32,
    /// ... plus this many metres.
    pub min_move_m: f32,
    /// Recompute after `max_age_s * (1 + distance / time_distance_m)` seconds.
    pub max_age_s: f32,
    /// Distance scale of the age threshold, metres.
    pub time_distance_m: f32,
    /// Age threshold while a cloud forms or dissipates, seconds. Absent (the shipped setting):
    /// the steady threshold, since a cloud's order is geometric and its fade is applied on the
    /// GPU every frame (Wang re-sorted fading clouds sooner because his CPU wrote their faded
    /// vertex colours with the order).
    #[serde(default)]
    pub fading_max_age_s: Option<f32>,
    /// Most sprites re-sorted in one frame; past it stale clouds keep their order until a later
    /// frame (nearest clouds first), so a frame where many clouds come near at once (the ring
    /// handing blocks back) does not stall.
    #[serde(default = "default_sorted_sprites")]
    pub max_sorted_sprites_per_frame: u32,
    /// Most sprites of newly arrived blocks uploaded in one frame (nearest blocks first; the
    /// others are drawn from a later frame on).
    #[serde(default = "default_uploaded_sprites")]
    pub max_uploaded_sprites_per_frame: u32,
}

fn default_sorted_sprites() -> u32 {
    8192
}

fn default_uploaded_sprites() -> u32 {
    32768
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
    pub impostors: super::impostor::ImpostorSettings,
    /// The round Earth (`[earth]`); curved with the mean radius when the table is absent.
    #[serde(default)]
    pub earth: super::earth::EarthSettings,
    /// The far field (`[far_field]`); the built-in defaults when the table is absent.
    #[serde(default)]
    pub far_field: super::far_field::FarFieldSettings,
    /// The clouds' shadows on the host's ground; built-in defaults when the table is absent.
    #[serde(default)]
    pub cloud_shadows: super::shadow::ShadowSettings,
}

impl Default for RenderSettings {
    /// The shipped `config/render.toml` (built in; a test checks that it parses).
    fn default() -> Self {
        Self::parse(DEFAULT_RENDER_TOML, Path::new("config/render.toml"))
            .expect("the shipped config/render.toml is valid (tested)")
    }
}

impl RenderSettings {
    /// Parses and checks settings; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let s: Self = parse_toml(text, path)?;
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
        Ok(s)
    }

    /// Reads and checks a settings file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|err| ConfigError::whole_file(path, format!("cannot read: {err}")))?;
        Self::parse(&text, path)
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

//! The near sprites' settings: the `[clouds]` and `[vertex_cache]` tables of
//! `config/render.toml`, read by the sprite stages (the draw list, the sprite views, the
//! impostor ring's orders). A leaf of the settings tree:
//! [`RenderSettings`](crate::render::RenderSettings) holds them, and nothing here reads it.

use serde::{Deserialize, Serialize};

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
    /// colour). See [`crate::render::cloud_target`].
    #[serde(default = "default_resolution_scale")]
    pub resolution_scale: f32,
    /// Clouds seen above the horizon fade out over this last fraction of the farthest distance a
    /// view draws them at (`draw_distance_m` for the camera's sprites, which hold the high and
    /// low layers the ring leaves out; the impostors' `view_radius_m` in the ring), 0..1: a high
    /// layer dissolves there instead of ending in a line across the sky. 0: no fade.
    #[serde(default = "default_far_fade_fraction")]
    pub far_fade_fraction: f32,
    /// Leave the clouds wholly out of view out of the view's draw list (a block across the
    /// view's edge drawn without them): the frame is the same, their sprites are not built
    /// nor drawn. False builds and draws every cloud of a block in view (tests that read every
    /// sprite's corners back).
    #[serde(default = "default_cull_out_of_view")]
    pub cull_out_of_view: bool,
}

fn default_cull_out_of_view() -> bool {
    true
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

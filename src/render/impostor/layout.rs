//! The geometry and rules of the impostor ring (Wang 2003 6.2), no GPU: the `[impostors]`
//! settings, which blocks are far, when to rebuild, the impostor cameras and sectors. Where the
//! quads are and their texture coordinates are the shader's (`impostor_at` in
//! `shaders/impostor_quad.wgsl`), checked by the ring tests in `tests/render.rs` (a flipped u or
//! v there moves or loses the far cloud). Units: metres, degrees, feet where named.

use glam::{DVec3, Mat4, Vec3};
use serde::{Deserialize, Serialize};

use crate::render::camera::Camera;
use crate::weather::METRES_PER_FOOT;

/// Number of impostors in a ring.
pub const IMPOSTORS: usize = 8;
/// Horizontal field of view of one impostor (its share of the ring's bearings), degrees.
pub const IMPOSTOR_FOV_DEG: f64 = 45.0;
/// Vertical field of view of one impostor, degrees: 35 up and down, so a storm cell's anvil
/// 25-30 degrees above a ring block near the ring radius is held whole (at 45 the impostor cut
/// anvils along its top edge: a straight line and a staircase across the sky). Keep
/// `IMPOSTOR_TALL` in `shaders/impostor_quad.wgsl` in sync (its half height over half width).
pub const IMPOSTOR_FOV_Y_DEG: f64 = 70.0;

/// The `[impostors]` table of `config/render.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpostorSettings {
    /// Draw far blocks into the ring (false: every block is a sprite).
    pub enabled: bool,
    /// Side of one impostor texture, pixels (RGBA8).
    pub size_px: u32,
    /// Blocks farther than this from the ring centre (horizontally) go into impostors, metres.
    pub ring_radius_m: f64,
    /// Blocks farther than this are not drawn at all, metres.
    pub view_radius_m: f64,
    /// Rebuild after the camera moved this fraction of the ring radius horizontally.
    pub rebuild_move_fraction: f64,
    /// Rebuild after the camera moved this fraction of the ring radius vertically.
    pub rebuild_climb_fraction: f64,
    /// Rebuild after the sun direction turned by more than this, degrees.
    pub rebuild_sun_deg: f64,
    /// A change of the far blocks that shows little (generations that begin to form or are
    /// gone, blocks that arrive whole where the far field's hand-over band has faded the ring
    /// more than halfway) rebuilds only once the ring shown was begun this long ago, seconds
    /// (0: at once); a block that arrives whole nearer rebuilds at once. Meanwhile a new far
    /// block is drawn as sprites and a gone one stays in the ring. Absent: 20.
    #[serde(default = "far_change_after_s")]
    pub rebuild_far_change_after_s: f64,
    /// Crossfade from the old ring to the new one over this time, seconds (0: switch at once).
    pub crossfade_s: f64,
    /// Blocks more than this above or below the camera are never put in impostors, feet.
    pub max_height_difference_ft: f64,
    /// Wang 6.1's `move_fraction` for the far clouds' orders seen from the ring centre: an
    /// order is kept until the centre moved this fraction of the cloud's distance (the other
    /// thresholds are `[vertex_cache]`'s). Absent: `[vertex_cache] move_fraction`.
    #[serde(default)]
    pub order_move_fraction: Option<f64>,
}

/// [`ImpostorSettings::rebuild_far_change_after_s`] when a table leaves it out.
fn far_change_after_s() -> f64 {
    20.0
}

impl Default for ImpostorSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            size_px: 256,
            ring_radius_m: 20_000.0,
            view_radius_m: 100_000.0,
            rebuild_move_fraction: 0.15,
            rebuild_climb_fraction: 0.02,
            rebuild_sun_deg: 2.0,
            rebuild_far_change_after_s: far_change_after_s(),
            crossfade_s: 1.0,
            max_height_difference_ft: 10_000.0,
            order_move_fraction: None,
        }
    }
}

impl ImpostorSettings {
    /// The first field that is out of range, with why.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        let positive = [
            ("impostors.ring_radius_m", self.ring_radius_m),
            (
                "impostors.rebuild_move_fraction",
                self.rebuild_move_fraction,
            ),
            (
                "impostors.rebuild_climb_fraction",
                self.rebuild_climb_fraction,
            ),
            ("impostors.rebuild_sun_deg", self.rebuild_sun_deg),
        ];
        for (field, v) in positive {
            if v.is_nan() || v <= 0.0 {
                return Some((field, format!("must be greater than 0, is {v}")));
            }
        }
        if !(16..=4096).contains(&self.size_px) {
            let v = self.size_px;
            return Some(("impostors.size_px", format!("must be 16..=4096, is {v}")));
        }
        if self.view_radius_m.is_nan() || self.view_radius_m <= self.ring_radius_m {
            return Some((
                "impostors.view_radius_m",
                "must be greater than impostors.ring_radius_m".into(),
            ));
        }
        if self.rebuild_far_change_after_s.is_nan() || self.rebuild_far_change_after_s < 0.0 {
            let field = "impostors.rebuild_far_change_after_s";
            return Some((field, "must be 0 or more".into()));
        }
        if self.crossfade_s.is_nan() || self.crossfade_s < 0.0 {
            return Some(("impostors.crossfade_s", "must be 0 or more".into()));
        }
        if let Some(f) = self.order_move_fraction
            && !(f > 0.0 && f <= 1.0)
        {
            let field = "impostors.order_move_fraction";
            return Some((
                field,
                format!("must be greater than 0 and at most 1, is {f}"),
            ));
        }
        if self.max_height_difference_ft.is_nan() || self.max_height_difference_ft < 0.0 {
            return Some((
                "impostors.max_height_difference_ft",
                "must be 0 or more".into(),
            ));
        }
        None
    }
}

/// Whether a block centred at `block_m` belongs in the impostors of a ring centred at
/// `centre_m` built with the camera at `camera_m`: beyond the ring radius horizontally, within
/// the view radius, and within the height limit of the camera.
pub fn is_far(block_m: DVec3, centre_m: DVec3, camera_m: DVec3, s: &ImpostorSettings) -> bool {
    let d = (block_m - centre_m).truncate().length();
    let dz = (block_m.z - camera_m.z).abs();
    d > s.ring_radius_m
        && d <= s.view_radius_m
        && dz <= s.max_height_difference_ft * METRES_PER_FOOT
}

/// Whether the camera (or sun) left a ring built at `built_m` with sun `built_sun`.
pub fn needs_rebuild(
    built_m: DVec3,
    built_sun: Vec3,
    camera_m: DVec3,
    sun: Vec3,
    s: &ImpostorSettings,
) -> bool {
    let d = camera_m - built_m;
    d.truncate().length() > s.rebuild_move_fraction * s.ring_radius_m
        || d.z.abs() > s.rebuild_climb_fraction * s.ring_radius_m
        || (built_sun.dot(sun).clamp(-1.0, 1.0) as f64)
            .acos()
            .to_degrees()
            > s.rebuild_sun_deg
}

/// Heading of impostor `i`, degrees clockwise from north.
pub(super) fn heading_deg(i: usize) -> f64 {
    i as f64 * IMPOSTOR_FOV_DEG
}

/// The camera that renders impostor `i` from `centre_m`.
pub(super) fn impostor_camera(i: usize, centre_m: DVec3, s: &ImpostorSettings) -> Camera {
    Camera {
        position_m: centre_m,
        heading_deg: heading_deg(i),
        pitch_deg: 0.0,
        fov_y_deg: IMPOSTOR_FOV_Y_DEG as f32,
        // The width of IMPOSTOR_FOV_DEG.
        aspect: ((0.5 * IMPOSTOR_FOV_DEG).to_radians().tan()
            / (0.5 * IMPOSTOR_FOV_Y_DEG).to_radians().tan()) as f32,
        near_m: 50.0,
        far_m: (s.view_radius_m * 1.5) as f32,
    }
}

/// Whether a block at `block_m` can show in impostor `i` seen from `centre_m` (its sector plus
/// the block's angular size).
#[cfg(test)]
pub(super) fn in_sector(i: usize, centre_m: DVec3, block_m: DVec3) -> bool {
    sectors_of(centre_m, block_m) & (1 << i) != 0
}

/// The sectors a block is in ([`in_sector`] for every impostor at once, bit `i` for impostor
/// `i`): its bearing and margin worked out once, for the pass over the far blocks that starts a
/// ring build.
pub(super) fn sectors_of(centre_m: DVec3, block_m: DVec3) -> u8 {
    let rel = (block_m - centre_m).truncate();
    let d = rel.length().max(1.0);
    let bearing = rel.x.atan2(rel.y).to_degrees();
    // A 4 km block reaches about 2.9 km from its centre, plus cloud overhang.
    let margin = (4000.0 / d).min(1.0).asin().to_degrees();
    (0..IMPOSTORS).fold(0, |bits, i| {
        let off = (bearing - heading_deg(i) + 540.0).rem_euclid(360.0) - 180.0;
        bits | (((off.abs() <= IMPOSTOR_FOV_DEG * 0.5 + margin) as u8) << i)
    })
}

/// The projection of impostor `i`'s camera (for tests: a far point projects where its quad is).
pub fn impostor_view_proj(i: usize, s: &ImpostorSettings) -> Mat4 {
    impostor_camera(i, DVec3::ZERO, s).view_proj_relative()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block(_id: u64, x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn far_means_beyond_the_radius_within_view_and_height() {
        let s = ImpostorSettings::default();
        let cam = DVec3::new(0.0, 0.0, 1000.0);
        assert!(!is_far(block(1, 10_000.0, 0.0, 1000.0), cam, cam, &s));
        assert!(is_far(block(2, 0.0, 30_000.0, 1000.0), cam, cam, &s));
        assert!(!is_far(block(3, 0.0, 130_000.0, 1000.0), cam, cam, &s));
        // 10,000 ft is 3,048 m.
        assert!(is_far(block(4, 0.0, 30_000.0, 4000.0), cam, cam, &s));
        assert!(!is_far(block(5, 0.0, 30_000.0, 4100.0), cam, cam, &s));
    }

    #[test]
    fn rebuild_thresholds() {
        let s = ImpostorSettings::default();
        let at = DVec3::new(0.0, 0.0, 1000.0);
        let sun = Vec3::Z;
        assert!(!needs_rebuild(at, sun, at + DVec3::X * 2900.0, sun, &s));
        assert!(needs_rebuild(at, sun, at + DVec3::X * 3100.0, sun, &s));
        assert!(!needs_rebuild(at, sun, at + DVec3::Z * 390.0, sun, &s));
        assert!(needs_rebuild(at, sun, at + DVec3::Z * 410.0, sun, &s));
        let turned = Vec3::new(0.1, 0.0, 1.0).normalize();
        assert!(needs_rebuild(at, sun, at, turned, &s));
    }

    #[test]
    fn every_bearing_is_in_some_sector() {
        for deg in 0..360 {
            let a = (deg as f64).to_radians();
            let p = DVec3::new(a.sin(), a.cos(), 0.0) * 50_000.0;
            assert!(
                (0..IMPOSTORS).any(|i| in_sector(i, DVec3::ZERO, p)),
                "{deg}"
            );
        }
    }
}

//! The geometry and rules of the cloud shadow map, no GPU: the `[cloud_shadows]` settings, the
//! map's axes across the sun's rays, where it is centred (snapped to its texels on a grid fixed
//! to the world, so a camera moving within a texel changes nothing), the orthographic projection
//! its sprites are drawn with and the matrix a host looks it up with, and when it is drawn again.
//!
//! The map is a square of `2 half_extent_m` across the sun's rays (its `right` and `up` axes)
//! centred on the camera, snapped. A point `p` of the world (ENU metres) is at texture
//! coordinates `u = 1/2 + right.(p - centre) / (2 half_extent)`, `v = 1/2 - up.(p - centre) /
//! (2 half_extent)` (v down the texture), wherever along the ray it is: the ground under a cloud
//! and the cloud's sprites land on the same texel. Units: metres, degrees.

use glam::{DMat4, DVec3, DVec4, Mat4};
use serde::{Deserialize, Serialize};

/// The largest map side: R16Float at this side is 4 MiB (the GPU memory the shadows may take).
pub const MAX_SIZE_PX: u32 = 1448;

/// How far the eye of the orthographic draw stands from the map centre along the sun's rays,
/// metres: far enough that every sprite faces the sun within a few degrees (the build pass
/// turns a sprite towards its view's eye), near enough that positions relative to it keep
/// centimetres in f32.
pub const EYE_DISTANCE_M: f64 = 500_000.0;

/// The grid the map's centre is snapped to along the sun's rays, metres.
const ALONG_STEP_M: f64 = 10_000.0;

/// The depth range of the orthographic draw around the map centre, metres either way (nothing
/// is depth-tested; it only keeps every cloud inside the clip volume).
const DEPTH_RANGE_M: f64 = 200_000.0;

/// The `[cloud_shadows]` table of `config/render.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowSettings {
    /// Draw the shadow map. False means the clouds cast no shadows: a host's lookups find open
    /// sun everywhere, so its ground has the clear sun everywhere (`Sky::light` gives the clear
    /// sun either way; the cover's mean dimming is `Sky::sun_cover_transmittance`, applied by
    /// no skycast ground), and the map takes no memory.
    pub enabled: bool,
    /// Side of the map, texels (R16Float: 1024 is 2 MiB; at most [`MAX_SIZE_PX`], 4 MiB).
    pub size_px: u32,
    /// Half the side of the square the map covers across the sun's rays, metres (at least the
    /// sprites' draw distance, so every cloud drawn casts its shadow).
    pub half_extent_m: f64,
    /// While a cloud it covers forms or dissipates, draw the map again after this much sky
    /// time, seconds (between draws the map moves with the clouds' drift; steady clouds need no
    /// new drawing).
    pub update_interval_s: f64,
    /// Draw it again, centred anew, after the camera moved this fraction of the half extent
    /// across the sun's rays.
    pub recentre_fraction: f64,
    /// Draw it again after the sun turned more than this, degrees.
    pub rebuild_sun_deg: f64,
    /// The map's optical depth per the probes' (3 per `[in_cloud] visibility_m` of the sprites'
    /// dense cores along the sun's ray): 1 casts the shadows `World::sun_occlusion` reports.
    pub opacity_scale: f32,
    /// Blocks within this distance of the camera across the sun's rays cast the shadows of all
    /// their sprites, metres.
    #[serde(default = "default_full_detail_m")]
    pub full_detail_m: f64,
    /// Beyond it, every this many sprites of a cloud one is drawn, standing for them all (its
    /// optical depth times this): the far field holds most of the sprites and lies under the
    /// haze. 1: every sprite everywhere.
    #[serde(default = "default_far_sprite_stride")]
    pub far_sprite_stride: u32,
}

fn default_full_detail_m() -> f64 {
    15_000.0
}

fn default_far_sprite_stride() -> u32 {
    8
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            size_px: 1024,
            half_extent_m: 60_000.0,
            update_interval_s: 1.0,
            recentre_fraction: 0.1,
            rebuild_sun_deg: 0.5,
            opacity_scale: 1.0,
            full_detail_m: default_full_detail_m(),
            far_sprite_stride: default_far_sprite_stride(),
        }
    }
}

impl ShadowSettings {
    /// The first field that is out of range, with why.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        if !(16..=MAX_SIZE_PX).contains(&self.size_px) {
            let v = self.size_px;
            return Some((
                "cloud_shadows.size_px",
                format!("must be 16..={MAX_SIZE_PX} (4 MiB of R16Float at most), is {v}"),
            ));
        }
        let positive = [
            ("cloud_shadows.half_extent_m", self.half_extent_m),
            ("cloud_shadows.recentre_fraction", self.recentre_fraction),
            ("cloud_shadows.rebuild_sun_deg", self.rebuild_sun_deg),
        ];
        for (field, v) in positive {
            if v.is_nan() || v <= 0.0 {
                return Some((field, format!("must be greater than 0, is {v}")));
            }
        }
        if self.recentre_fraction > 1.0 {
            let v = self.recentre_fraction;
            return Some((
                "cloud_shadows.recentre_fraction",
                format!("must be at most 1, is {v}"),
            ));
        }
        if self.update_interval_s.is_nan() || self.update_interval_s < 0.0 {
            return Some((
                "cloud_shadows.update_interval_s",
                "must be 0 or more".into(),
            ));
        }
        if self.opacity_scale.is_nan() || self.opacity_scale < 0.0 {
            return Some(("cloud_shadows.opacity_scale", "must be 0 or more".into()));
        }
        if self.full_detail_m.is_nan() || self.full_detail_m < 0.0 {
            return Some(("cloud_shadows.full_detail_m", "must be 0 or more".into()));
        }
        if !(1..=64).contains(&self.far_sprite_stride) {
            let v = self.far_sprite_stride;
            return Some((
                "cloud_shadows.far_sprite_stride",
                format!("must be 1..=64, is {v}"),
            ));
        }
        None
    }

    /// Metres one texel covers across the sun's rays.
    pub fn texel_m(&self) -> f64 {
        2.0 * self.half_extent_m / self.size_px.max(1) as f64
    }
}

/// Where one drawing of the map stands: its axes, its snapped centre and the eye of the draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowFrame {
    /// Unit vector towards the sun (east, north, up).
    pub sun: DVec3,
    /// The map's axes across the sun's rays: u grows along `right`, v against `up`.
    pub right: DVec3,
    /// See `right`.
    pub up: DVec3,
    /// The map's centre, world metres (the camera's point snapped to texels across the rays
    /// and to 10 km along them).
    pub centre_m: DVec3,
    /// Half the side of the map, metres.
    pub half_extent_m: f64,
    /// Where the draw's eye stands, world metres: the sprites are built relative to it.
    pub eye_m: DVec3,
}

impl ShadowFrame {
    /// The map around `camera_m` for the sun along `sun` (a unit vector): its axes across the
    /// rays (`right` level, `up` towards the zenith's side; east and north with the sun
    /// overhead), its centre on the texel grid of those axes through the world origin nearest
    /// the camera.
    pub fn new(camera_m: DVec3, sun: DVec3, settings: &ShadowSettings) -> Self {
        let sun = sun.normalize_or(DVec3::Z);
        let right = DVec3::Z.cross(sun);
        let right = if right.length_squared() > 1e-12 {
            right.normalize()
        } else {
            DVec3::X
        };
        let up = sun.cross(right).normalize();
        let texel = settings.texel_m();
        let snap = |x: f64| (x / texel).round() * texel;
        // Along the rays too, on a coarse grid: the eye then stays where it was as the camera
        // moves, and so does every sprite's position relative to it to the last bit (a moved
        // eye rounds them anew, and a quad's edge crossing a texel's centre adds or drops it).
        let along = (sun.dot(camera_m) / ALONG_STEP_M).round() * ALONG_STEP_M;
        let centre_m =
            right * snap(right.dot(camera_m)) + up * snap(up.dot(camera_m)) + sun * along;
        Self {
            sun,
            right,
            up,
            centre_m,
            half_extent_m: settings.half_extent_m,
            eye_m: centre_m + sun * EYE_DISTANCE_M,
        }
    }

    /// Where `point_m` (world) lands across the rays, metres from the centre along `right` and
    /// `up`.
    pub fn across(&self, point_m: DVec3) -> (f64, f64) {
        let d = point_m - self.centre_m;
        (self.right.dot(d), self.up.dot(d))
    }

    /// Clip space of the draw from positions relative to the eye: x along `right`, y along
    /// `up` (both -1..1 over the map), z the distance from the eye over the depth range
    /// (0..1). Orthographic: w is 1.
    pub fn clip_from_eye_relative(&self) -> Mat4 {
        let h = self.half_extent_m;
        let near = EYE_DISTANCE_M - DEPTH_RANGE_M;
        let depth = 2.0 * DEPTH_RANGE_M;
        let away = -self.sun;
        // Rows of the matrix, as glam builds it from columns.
        let rows = [
            (self.right / h).extend(0.0),
            (self.up / h).extend(0.0),
            (away / depth).extend(-near / depth),
            DVec4::new(0.0, 0.0, 0.0, 1.0),
        ];
        DMat4::from_cols(rows[0], rows[1], rows[2], rows[3])
            .transpose()
            .as_mat4()
    }

    /// The map's texture coordinates (u, v; z 0, w 1) of a position relative to the camera at
    /// `camera_m`, the clouds having drifted `drift_m` since the map was drawn (the shadows go
    /// with them). Worked out in f64, so a camera far from the origin loses nothing.
    pub fn uv_from_camera_relative(&self, camera_m: DVec3, drift_m: DVec3) -> Mat4 {
        let s = 0.5 / self.half_extent_m;
        // A ground point p = camera + q sees the map where p - drift is.
        let offset = camera_m - drift_m - self.centre_m;
        let u = (self.right * s).extend(0.5 + s * self.right.dot(offset));
        let v = (-self.up * s).extend(0.5 - s * self.up.dot(offset));
        let rows = [u, v, DVec4::ZERO, DVec4::new(0.0, 0.0, 0.0, 1.0)];
        DMat4::from_cols(rows[0], rows[1], rows[2], rows[3])
            .transpose()
            .as_mat4()
    }
}

/// Whether the map drawn at `drawn` (with the sky time then, `drawn_s`) must be drawn again for
/// the camera at `camera_m`, the sun along `sun` and sky time `now_s`; `changing`: some cloud it
/// covers forms or dissipates (only then does time alone make it stale: the drift is the
/// lookup's).
pub fn needs_redraw(
    drawn: &ShadowFrame,
    (drawn_s, now_s): (f64, f64),
    camera_m: DVec3,
    sun: DVec3,
    changing: bool,
    settings: &ShadowSettings,
) -> bool {
    let (x, y) = drawn.across(camera_m);
    let moved = x.abs().max(y.abs()) > settings.recentre_fraction * settings.half_extent_m;
    let turned = drawn
        .sun
        .angle_between(sun.normalize_or(DVec3::Z))
        .to_degrees()
        > settings.rebuild_sun_deg;
    let aged = changing && (now_s - drawn_s >= settings.update_interval_s || now_s < drawn_s);
    moved || turned || aged
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun(elevation_deg: f64, azimuth_deg: f64) -> DVec3 {
        let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
        DVec3::new(e.cos() * a.sin(), e.cos() * a.cos(), e.sin())
    }

    #[test]
    fn a_point_and_its_shadow_share_texture_coordinates() {
        let s = ShadowSettings::default();
        let camera = DVec3::new(12_345.6, -7_890.1, 900.0);
        let sun = sun(35.0, 200.0);
        let frame = ShadowFrame::new(camera, sun, &s);
        let uv = frame.uv_from_camera_relative(camera, DVec3::ZERO);
        let cloud = DVec3::new(14_000.0, -6_000.0, 2_000.0);
        // Its shadow on the ground (z = 0): along the ray away from the sun.
        let ground = cloud - sun * (cloud.z / sun.z);
        let at = |p: DVec3| uv * (p - camera).as_vec3().extend(1.0);
        let (a, b) = (at(cloud), at(ground));
        assert!((a - b).truncate().length() < 1e-5, "{a} {b}");
        // Inside the map, and where the draw puts the cloud in clip space.
        let clip = frame.clip_from_eye_relative() * (cloud - frame.eye_m).as_vec3().extend(1.0);
        assert!((clip.x - (2.0 * a.x - 1.0)).abs() < 1e-4, "{clip} {a}");
        assert!((clip.y - (1.0 - 2.0 * a.y)).abs() < 1e-4, "{clip} {a}");
        assert!((0.0..=1.0).contains(&clip.z), "{clip}");
        // The camera's own point is within a texel of the centre.
        let c = at(camera);
        let texel = 1.0 / s.size_px as f32;
        assert!(
            (c.x - 0.5).abs() <= texel && (c.y - 0.5).abs() <= texel,
            "{c}"
        );
    }

    #[test]
    fn the_centre_is_snapped_to_texels_of_a_grid_fixed_to_the_world() {
        let s = ShadowSettings::default();
        let sun = sun(50.0, 120.0);
        let camera = DVec3::new(30_000.0, 40_000.0, 1_000.0);
        let a = ShadowFrame::new(camera, sun, &s);
        // A move of a third of a texel (the texel grid goes through the origin, so the camera
        // is placed mid-texel first) keeps the centre where it was.
        let (x, y) = a.across(camera);
        let mid = camera - a.right * x - a.up * y;
        let a = ShadowFrame::new(mid, sun, &s);
        let b = ShadowFrame::new(mid + a.right * (s.texel_m() / 3.0), sun, &s);
        assert_eq!(a.centre_m, b.centre_m);
        // A whole texel moves it by one.
        let c = ShadowFrame::new(mid + a.right * s.texel_m(), sun, &s);
        let (dx, dy) = c.across(a.centre_m);
        assert!(
            (dx.abs() - s.texel_m()).abs() < 1e-6 && dy.abs() < 1e-6,
            "{dx} {dy}"
        );
        // A point of the world keeps its texture coordinates up to whole texels.
        let p = DVec3::new(31_000.0, 39_000.0, 0.0);
        let u = |f: &ShadowFrame, cam: DVec3| {
            (f.uv_from_camera_relative(cam, DVec3::ZERO) * (p - cam).as_vec3().extend(1.0)).x
        };
        let shift = (u(&a, mid) - u(&c, mid + a.right * s.texel_m())) * s.size_px as f32;
        assert!((shift.abs() - 1.0).abs() < 1e-3, "{shift}");
    }

    #[test]
    fn drift_moves_the_lookup_with_the_clouds() {
        let s = ShadowSettings::default();
        let camera = DVec3::new(0.0, 0.0, 1_000.0);
        let frame = ShadowFrame::new(camera, sun(60.0, 180.0), &s);
        let drift = DVec3::new(600.0, 0.0, 0.0);
        let p = DVec3::new(2_000.0, 500.0, 0.0);
        let before = frame.uv_from_camera_relative(camera, DVec3::ZERO);
        let after = frame.uv_from_camera_relative(camera, drift);
        let a = before * (p - drift - camera).as_vec3().extend(1.0);
        let b = after * (p - camera).as_vec3().extend(1.0);
        assert!((a - b).length() < 1e-6, "{a} {b}");
    }

    #[test]
    fn redraws_on_moves_turns_and_time() {
        let s = ShadowSettings::default();
        let sun0 = sun(40.0, 180.0);
        let frame = ShadowFrame::new(DVec3::ZERO, sun0, &s);
        let step = s.recentre_fraction * s.half_extent_m;
        let at = |t: f64| (0.0, t);
        assert!(!needs_redraw(&frame, at(0.5), DVec3::ZERO, sun0, true, &s));
        assert!(needs_redraw(&frame, at(1.0), DVec3::ZERO, sun0, true, &s));
        // Steady clouds: time alone changes nothing (the lookup follows the drift).
        assert!(!needs_redraw(
            &frame,
            at(100.0),
            DVec3::ZERO,
            sun0,
            false,
            &s
        ));
        let moved = |f: f64| frame.right * step * f;
        assert!(!needs_redraw(&frame, at(0.1), moved(0.9), sun0, false, &s));
        assert!(needs_redraw(&frame, at(0.1), moved(1.1), sun0, false, &s));
        // Along the rays (a climb towards the sun) changes nothing.
        assert!(!needs_redraw(
            &frame,
            at(0.1),
            sun0 * 5_000.0,
            sun0,
            false,
            &s
        ));
        let turned = sun(41.0, 180.0);
        assert!(needs_redraw(
            &frame,
            at(0.1),
            DVec3::ZERO,
            turned,
            false,
            &s
        ));
    }

    #[test]
    fn settings_name_the_bad_field() {
        let bad = |f: fn(&mut ShadowSettings)| {
            let mut s = ShadowSettings::default();
            f(&mut s);
            s.invalid_field().map(|(field, _)| field)
        };
        assert_eq!(ShadowSettings::default().invalid_field(), None);
        assert_eq!(bad(|s| s.size_px = 4096), Some("cloud_shadows.size_px"));
        assert_eq!(
            bad(|s| s.half_extent_m = 0.0),
            Some("cloud_shadows.half_extent_m")
        );
        assert_eq!(
            bad(|s| s.recentre_fraction = 2.0),
            Some("cloud_shadows.recentre_fraction")
        );
        assert_eq!(
            bad(|s| s.update_interval_s = -1.0),
            Some("cloud_shadows.update_interval_s")
        );
        assert_eq!(
            bad(|s| s.opacity_scale = f32::NAN),
            Some("cloud_shadows.opacity_scale")
        );
        // R16Float at the largest side fits 4 MiB.
        assert!(MAX_SIZE_PX as u64 * MAX_SIZE_PX as u64 * 2 <= 4 << 20);
    }
}

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

/// How far the eye of the orthographic draw stands up the sun's rays from its foot (the map's
/// centre snapped to a grid of `half_extent_m`), metres: far enough that every sprite faces the
/// sun within some ten degrees (the build pass turns a sprite towards its view's eye), near
/// enough that positions relative to it keep centimetres in f32.
pub const EYE_DISTANCE_M: f64 = 500_000.0;

/// The grid the map's centre is snapped to along the sun's rays, metres.
const ALONG_STEP_M: f64 = 10_000.0;

/// The depth range of the orthographic draw around the eye's foot, metres either way (nothing
/// is depth-tested; it only keeps every cloud inside the clip volume: the map's corners lie
/// within 1.5 half extents of the foot).
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
    /// While a cloud it covers forms or dissipates, draw the map again whole after this much sky
    /// time, seconds (between draws the map moves with the clouds' drift; steady clouds need no
    /// new drawing).
    pub update_interval_s: f64,
    /// Scroll it (centre it anew by whole texels, drawing only the strips that came into range),
    /// after the camera moved this fraction of the half extent across the sun's rays.
    pub recentre_fraction: f64,
    /// Draw it again whole after the sun turned more than this, degrees.
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
    /// Texels a frame draws again for blocks gone or written again (their footprints, queued;
    /// one at least a frame), beyond the strips a scroll draws: spreads the cost of a changing
    /// sky over frames.
    #[serde(default = "default_redraw_texels_per_frame")]
    pub redraw_texels_per_frame: u32,
    /// Sprites a frame adds to the map of the blocks that arrived (nearest first; one block at
    /// least a frame): the map drawn in when a sky first fills spreads over frames.
    #[serde(default = "default_add_sprites_per_frame")]
    pub add_sprites_per_frame: u32,
}

fn default_full_detail_m() -> f64 {
    15_000.0
}

fn default_far_sprite_stride() -> u32 {
    1
}

fn default_redraw_texels_per_frame() -> u32 {
    65_536
}

fn default_add_sprites_per_frame() -> u32 {
    2_048
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
            redraw_texels_per_frame: default_redraw_texels_per_frame(),
            add_sprites_per_frame: default_add_sprites_per_frame(),
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
    /// Where the draw's eye stands, world metres: the sprites are built relative to it, and
    /// turned towards it. It stays put while the map's centre moves within a cell of a grid of
    /// `half_extent_m` (across and along the rays, through the origin): a map scrolled there is
    /// drawn from the same eye as a fresh one, to the bit.
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
        Self {
            sun,
            right,
            up,
            centre_m: DVec3::ZERO,
            half_extent_m: settings.half_extent_m,
            eye_m: DVec3::ZERO,
        }
        .moved_to(camera_m, settings)
    }

    /// The map with the same axes (to the bit: a frame made anew from its sun could differ in
    /// the last one, and a scroll needs the same axes) centred around `camera_m`.
    pub fn moved_to(&self, camera_m: DVec3, settings: &ShadowSettings) -> Self {
        let (sun, right, up) = (self.sun, self.right, self.up);
        let texel = settings.texel_m();
        let snap = |x: f64| (x / texel).round() * texel;
        // Along the rays too, on a coarse grid: the eye then stays where it was as the camera
        // moves, and so does every sprite's position relative to it to the last bit (a moved
        // eye rounds them anew, and a quad's edge crossing a texel's centre adds or drops it).
        let along = (sun.dot(camera_m) / ALONG_STEP_M).round() * ALONG_STEP_M;
        let centre_m =
            right * snap(right.dot(camera_m)) + up * snap(up.dot(camera_m)) + sun * along;
        let cell = |x: f64| (x / settings.half_extent_m).round() * settings.half_extent_m;
        let foot = right * cell(right.dot(centre_m))
            + up * cell(up.dot(centre_m))
            + sun * cell(sun.dot(centre_m));
        Self {
            centre_m,
            half_extent_m: settings.half_extent_m,
            eye_m: foot + sun * EYE_DISTANCE_M,
            ..*self
        }
    }

    /// Where `point_m` (world) lands across the rays, metres from the centre along `right` and
    /// `up`.
    pub fn across(&self, point_m: DVec3) -> (f64, f64) {
        let d = point_m - self.centre_m;
        (self.right.dot(d), self.up.dot(d))
    }

    /// Clip space of the draw from positions relative to the eye: x along `right`, y along
    /// `up` (both -1..1 over the map, around its centre), z the distance from the eye over the
    /// depth range (0..1). Orthographic: w is 1.
    pub fn clip_from_eye_relative(&self) -> Mat4 {
        let h = self.half_extent_m;
        let (x, y) = self.across(self.eye_m);
        let near = EYE_DISTANCE_M - DEPTH_RANGE_M;
        let depth = 2.0 * DEPTH_RANGE_M;
        let away = -self.sun;
        // Rows of the matrix, as glam builds it from columns.
        let rows = [
            (self.right / h).extend(x / h),
            (self.up / h).extend(y / h),
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

/// Why the map drawn at `drawn` (with the sky time then, `drawn_s`) is due for more drawing,
/// for the camera at `camera_m` (in the map's own coordinates: less the drift since it was
/// drawn), the sun along `sun` and sky time `now_s`; `changing`: some cloud it covers forms or
/// dissipates (only then does time alone make it stale: the drift is the lookup's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RedrawDue {
    /// The camera went `recentre_fraction` of the half extent across the rays: the map is
    /// scrolled to it (its strips drawn), not drawn whole.
    pub recentre: bool,
    /// The sun turned more than `rebuild_sun_deg`: drawn again whole.
    pub turned: bool,
    /// `update_interval_s` went by while clouds it covers form or dissipate: drawn again whole.
    pub aged: bool,
}

/// What is due for the map drawn at `drawn` ([`RedrawDue`]).
pub fn redraw_due(
    drawn: &ShadowFrame,
    (drawn_s, now_s): (f64, f64),
    camera_m: DVec3,
    sun: DVec3,
    changing: bool,
    settings: &ShadowSettings,
) -> RedrawDue {
    let (x, y) = drawn.across(camera_m);
    RedrawDue {
        recentre: x.abs().max(y.abs()) > settings.recentre_fraction * settings.half_extent_m,
        turned: drawn
            .sun
            .angle_between(sun.normalize_or(DVec3::Z))
            .to_degrees()
            > settings.rebuild_sun_deg,
        aged: changing && (now_s - drawn_s >= settings.update_interval_s || now_s < drawn_s),
    }
}

/// The fraction of the map's side across which its edge fades out at each end (the draw's
/// fade, `params.y` of `shaders/cloud_shadow.wgsl`, in clip units of the half side).
pub const EDGE_FADE: f32 = 0.05;

/// Texels from the map's edge that the edge fade touches (with one texel to spare): a
/// scrolled map draws these again on every side it moved across, so its fade is where a
/// whole drawing puts it.
pub fn fade_texels(size_px: u32) -> u32 {
    (EDGE_FADE as f64 * size_px as f64 / 2.0).ceil() as u32 + 1
}

/// A rectangle of the map's texels: columns `x0..x1` (u), rows `y0..y1` (v, down the texture).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl TexelRect {
    /// The whole map of side `size_px`.
    pub fn whole(size_px: u32) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: size_px,
            y1: size_px,
        }
    }

    /// Texels it holds.
    pub fn area(&self) -> u64 {
        (self.x1 - self.x0) as u64 * (self.y1 - self.y0) as u64
    }

    /// Whether the two share a texel.
    pub fn overlaps(&self, other: &Self) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }

    /// The rectangle of columns `x0..x1` and rows `y0..y1` (in texels, any sign) cut to the
    /// map of side `size_px`; `None` if nothing of it is on the map.
    fn clipped(x: (i64, i64), y: (i64, i64), size_px: u32) -> Option<Self> {
        let n = size_px as i64;
        let (x0, x1) = (x.0.clamp(0, n), x.1.clamp(0, n));
        let (y0, y1) = (y.0.clamp(0, n), y.1.clamp(0, n));
        (x0 < x1 && y0 < y1).then_some(Self {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32,
            y1: y1 as u32,
        })
    }
}

/// The texels the shadow of a sphere at `centre_m` of `radius_m` (a block, placed) may fall
/// on in the map drawn at `frame` of side `size_px`, with a texel to spare on every side (a
/// quad's edge rounds to the texel centres it crosses); `None` if it is off the map.
pub fn footprint(
    frame: &ShadowFrame,
    centre_m: DVec3,
    radius_m: f64,
    size_px: u32,
) -> Option<TexelRect> {
    let texel = 2.0 * frame.half_extent_m / size_px.max(1) as f64;
    let (x, y) = frame.across(centre_m);
    let h = frame.half_extent_m;
    let column = |m: f64| m / texel;
    let x = (
        column(x - radius_m + h).floor() as i64 - 1,
        column(x + radius_m + h).ceil() as i64 + 1,
    );
    let y = (
        column(h - y - radius_m).floor() as i64 - 1,
        column(h - y + radius_m).ceil() as i64 + 1,
    );
    TexelRect::clipped(x, y, size_px)
}

/// How many whole texels the map moves from `from` to `to` (two drawings for the same sun):
/// columns along `right` and rows down the texture (against `up`); a world point at texel
/// `(i, j)` of `from` is at `(i - x, j - y)` of `to`. `None` when their suns differ or the move
/// leaves less than half the map in common (drawing it whole costs about the same then), or
/// when the eye moved to another cell (a fresh drawing turns every sprite anew).
pub fn scroll_shift(from: &ShadowFrame, to: &ShadowFrame, size_px: u32) -> Option<(i32, i32)> {
    if from.sun != to.sun || from.half_extent_m != to.half_extent_m || from.eye_m != to.eye_m {
        return None;
    }
    let texel = 2.0 * from.half_extent_m / size_px.max(1) as f64;
    let (x, y) = from.across(to.centre_m);
    let (x, y) = ((x / texel).round(), (-y / texel).round());
    let limit = size_px as f64 / 4.0;
    (x.abs() <= limit && y.abs() <= limit).then_some((x as i32, y as i32))
}

/// The texels a map scrolled by `shift` ([`scroll_shift`]) must draw again: on each side it
/// moved towards, the strip that came into range and the fade band that was the old map's
/// edge; on each side it moved away from, the new fade band. Disjoint: the column strips
/// whole, the row strips between them (four at most).
pub fn scroll_rects((x, y): (i32, i32), size_px: u32) -> Vec<TexelRect> {
    let n = size_px as i64;
    let fade = fade_texels(size_px) as i64;
    let mut rects = Vec::new();
    // Columns: from the left edge and from the right edge.
    let (mut left, mut right) = (0, n);
    if x != 0 {
        left = fade + (-x as i64).max(0);
        right = n - fade - (x as i64).max(0);
        rects.extend(TexelRect::clipped((0, left), (0, n), size_px));
        rects.extend(TexelRect::clipped((right.max(left), n), (0, n), size_px));
    }
    if y != 0 && left < right {
        let top = fade + (-y as i64).max(0);
        let bottom = n - fade - (y as i64).max(0);
        rects.extend(TexelRect::clipped((left, right), (0, top), size_px));
        rects.extend(TexelRect::clipped(
            (left, right),
            (bottom.max(top), n),
            size_px,
        ));
    }
    rects
}

/// Rows of the map a scroll moves at a time through its scratch texture (whose side across is
/// the map's): a scroll copies the map onto itself, and a copy may not read and write one
/// texture, so it goes a band at a time through a small one (128 KiB at 1024 texels, not a
/// second map).
pub const SCROLL_BAND_ROWS: u32 = 64;

/// One band of a scroll: the map's texels from `src` (`size` columns and rows) copied to the
/// scratch texture's corner, then from there to `dst` of the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BandCopy {
    /// First texel read (column, row).
    pub src: [u32; 2],
    /// First texel written.
    pub dst: [u32; 2],
    /// Columns and rows, at most `SCROLL_BAND_ROWS` rows.
    pub size: [u32; 2],
}

/// The bands a scroll by `shift` ([`scroll_shift`]) moves the texels the old and new map have
/// in common with, in order: a texel `(i, j)` goes to `(i - x, j - y)`. Bands are taken from the
/// side the texels move towards, so none is read after it was written over (a memmove's order).
pub fn scroll_copies((x, y): (i32, i32), size_px: u32) -> Vec<BandCopy> {
    let n = size_px as i64;
    let (x, y) = (x as i64, y as i64);
    let (w, h) = (n - x.abs(), n - y.abs());
    if w <= 0 || h <= 0 {
        return Vec::new();
    }
    let (src, dst) = ([x.max(0), y.max(0)], [(-x).max(0), (-y).max(0)]);
    let band = SCROLL_BAND_ROWS as i64;
    let mut bands: Vec<BandCopy> = (0..(h + band - 1) / band)
        .map(|k| {
            let row = k * band;
            BandCopy {
                src: [src[0] as u32, (src[1] + row) as u32],
                dst: [dst[0] as u32, (dst[1] + row) as u32],
                size: [w as u32, band.min(h - row) as u32],
            }
        })
        .collect();
    // Moving down the texture (rows written below those read): the bottom band first.
    if y < 0 {
        bands.reverse();
    }
    bands
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
        let due = |t: f64, camera: DVec3, sun: DVec3, changing: bool| {
            redraw_due(&frame, at(t), camera, sun, changing, &s)
        };
        assert_eq!(due(0.5, DVec3::ZERO, sun0, true), RedrawDue::default());
        assert!(due(1.0, DVec3::ZERO, sun0, true).aged);
        // Steady clouds: time alone changes nothing (the lookup follows the drift).
        assert_eq!(due(100.0, DVec3::ZERO, sun0, false), RedrawDue::default());
        let moved = |f: f64| frame.right * step * f;
        assert!(!due(0.1, moved(0.9), sun0, false).recentre);
        assert!(due(0.1, moved(1.1), sun0, false).recentre);
        // Along the rays (a climb towards the sun) changes nothing.
        assert_eq!(due(0.1, sun0 * 5_000.0, sun0, false), RedrawDue::default());
        let turned = due(0.1, DVec3::ZERO, sun(41.0, 180.0), false);
        assert!(turned.turned && !turned.recentre, "{turned:?}");
    }

    /// The fade a drawing gives texel `(i, j)` of a map of side `n` (the shader's, at the
    /// texel's centre).
    fn fade_at(i: i64, j: i64, n: i64) -> f64 {
        let clip = |k: i64| ((k as f64 + 0.5) / n as f64 * 2.0 - 1.0).abs();
        let edge = clip(i).max(clip(j));
        let f = EDGE_FADE as f64;
        let t = ((edge - (1.0 - f)) / (0.75 * f)).clamp(0.0, 1.0);
        1.0 - t * t * (3.0 - 2.0 * t)
    }

    #[test]
    fn a_scroll_draws_again_every_texel_a_fresh_drawing_would_hold_otherwise() {
        let s = ShadowSettings {
            size_px: 128,
            ..Default::default()
        };
        let n = s.size_px as i64;
        let sun = sun(35.0, 200.0);
        let from = ShadowFrame::new(DVec3::new(1_000.0, 2_000.0, 900.0), sun, &s);
        for (dx, dy) in [(3, 0), (0, -5), (7, 4), (-2, 9), (-11, -1), (1, 1)] {
            let to_centre = from.centre_m + from.right * (dx as f64 * s.texel_m())
                - from.up * (dy as f64 * s.texel_m());
            let to = from.moved_to(to_centre, &s);
            let shift = scroll_shift(&from, &to, s.size_px);
            assert_eq!(shift, Some((dx, dy)));
            // A world point keeps its place: texel (i, j) of the old map is (i - x, j - y).
            let p = from.centre_m + from.right * 1_234.0 + from.up * 567.0;
            let texel = |f: &ShadowFrame| {
                let (x, y) = f.across(p);
                (
                    ((x + f.half_extent_m) / s.texel_m()).floor() as i64,
                    ((f.half_extent_m - y) / s.texel_m()).floor() as i64,
                )
            };
            let (a, b) = (texel(&from), texel(&to));
            assert_eq!((a.0 - b.0, a.1 - b.1), (dx as i64, dy as i64));
            let rects = scroll_rects((dx, dy), s.size_px);
            // The copies, done in order on the map itself through the scratch band.
            let copies = scroll_copies((dx, dy), s.size_px);
            let mut map: Vec<i64> = (0..n * n).collect();
            for c in &copies {
                assert!(c.size[1] <= SCROLL_BAND_ROWS, "{c:?}");
                let (w, h) = (c.size[0] as i64, c.size[1] as i64);
                let scratch: Vec<i64> = (0..h)
                    .flat_map(|r| (0..w).map(move |q| (r, q)))
                    .map(|(r, q)| map[((c.src[1] as i64 + r) * n + c.src[0] as i64 + q) as usize])
                    .collect();
                for r in 0..h {
                    for q in 0..w {
                        map[((c.dst[1] as i64 + r) * n + c.dst[0] as i64 + q) as usize] =
                            scratch[(r * w + q) as usize];
                    }
                }
            }
            for j in 0..n {
                for i in 0..n {
                    let (oi, oj) = (i + dx as i64, j + dy as i64);
                    let inside = (0..n).contains(&oi) && (0..n).contains(&oj);
                    let same = inside && fade_at(oi, oj, n) == fade_at(i, j, n);
                    let drawn = rects
                        .iter()
                        .filter(|r| {
                            (r.x0 as i64..r.x1 as i64).contains(&i)
                                && (r.y0 as i64..r.y1 as i64).contains(&j)
                        })
                        .count();
                    assert!(drawn <= 1, "({i}, {j}) drawn {drawn} times for {dx} {dy}");
                    assert!(same || drawn == 1, "({i}, {j}) not drawn for {dx} {dy}");
                    // What is not drawn again holds the old map's texel there.
                    if drawn == 0 {
                        assert_eq!(map[(j * n + i) as usize], oj * n + oi, "({i}, {j})");
                    }
                }
            }
            // Most of the map is copied, not drawn.
            let area: u64 = rects.iter().map(TexelRect::area).sum();
            assert!(area < (n * n / 2) as u64, "{area} for {dx} {dy}");
        }
        // Another sun, or a jump of more than a quarter of the map: drawn whole.
        let turned = ShadowFrame::new(from.centre_m, self::sun(36.0, 200.0), &s);
        assert_eq!(scroll_shift(&from, &turned, s.size_px), None);
        let far = from.moved_to(from.centre_m + from.right * 40.0 * s.texel_m(), &s);
        assert_eq!(scroll_shift(&from, &far, s.size_px), None);
        // Into another cell of the eye's grid (a half extent): drawn whole.
        let cells = ShadowSettings::default();
        let a = ShadowFrame::new(DVec3::new(0.0, 0.0, 1_000.0), sun, &cells);
        let near = a.moved_to(a.centre_m + a.right * 20_000.0, &cells);
        assert_eq!(near.eye_m, a.eye_m);
        assert!(scroll_shift(&a, &near, cells.size_px).is_some());
        let over = a.moved_to(a.centre_m + a.right * 31_000.0, &cells);
        assert_ne!(over.eye_m, a.eye_m);
        assert_eq!(scroll_shift(&a, &over, cells.size_px), None);
    }

    #[test]
    fn a_footprint_holds_the_shadow_of_its_sphere() {
        let s = ShadowSettings::default();
        let sun = sun(50.0, 120.0);
        let frame = ShadowFrame::new(DVec3::new(5_000.0, -3_000.0, 1_000.0), sun, &s);
        let centre = frame.centre_m + frame.right * 10_000.0 - frame.up * 4_000.0;
        let r = footprint(&frame, centre, 1_000.0, s.size_px).unwrap();
        // 2 km across: 17 texels and a spare one each side, around the centre's texel.
        let (x, y) = frame.across(centre);
        let i = ((x + s.half_extent_m) / s.texel_m()) as u32;
        let j = ((s.half_extent_m - y) / s.texel_m()) as u32;
        assert!(
            (r.x0..r.x1).contains(&i) && (r.y0..r.y1).contains(&j),
            "{r:?}"
        );
        assert!((19..=21).contains(&(r.x1 - r.x0)), "{r:?}");
        // Its shadow on the ground (down the ray) has the same footprint.
        assert_eq!(
            footprint(&frame, centre - sun * 3_000.0, 1_000.0, s.size_px),
            Some(r)
        );
        // Off the map: none; at its edge: cut to it.
        let off = frame.centre_m + frame.right * 70_000.0;
        assert_eq!(footprint(&frame, off, 1_000.0, s.size_px), None);
        let edge = footprint(
            &frame,
            frame.centre_m + frame.up * 60_000.0,
            1_000.0,
            s.size_px,
        );
        assert_eq!(edge.map(|r| r.y0), Some(0));
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

//! Asking the clouds about a point or a segment, on the CPU, cheap enough for every frame: how
//! far inside a cloud a point is (the measure the renderer fogs the camera with, at any point,
//! formation and dissipation fades included), the nearest cloud, the nearest of a type, whether
//! a point is in a rain shaft, and the first cloud a line of sight meets with the optical depth
//! through it.
//!
//! A cloud is its core box: the box of its sprite centres plus a quarter of each sprite's size
//! (rain shafts left out), the same box the renderer's in-cloud fog uses
//! (`render::scene::SkyCloud::core_box_m`). Inside it the in-cloud measure rises from 0 at the
//! boundary to 1 at `ramp_fraction` of the half-extent in, times the cloud's fade where the point
//! is ([`super::lifecycle::alpha_at`] at the point's radius fraction). A line of sight meets a
//! cloud where it enters its box; its optical depth is the extinction inside a cloud
//! (`3 / visibility_m`, Koschmieder) times the length inside, times the fade.
//!
//! The boxes of a generation are worked out once, the first time it is asked about
//! ([`BoxCache`]); a query looks only at the blocks within reach of the point, and skips a
//! block whose clouds' bounds are out of reach. Positions are ground metres (east, north, up
//! MSL); the field's drift is taken off to find the clouds.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use glam::{DVec2, DVec3};

use super::block::Cloud;
use super::field::{CloudField, FieldBlock};
use super::lifecycle::{Phase, alpha_at};
use crate::weather::air::InCloudAirSettings;
use crate::weather::{BLOCK_SIZE_M, BlockIndex, CloudType};

/// A cloud's core box, in the field's (air) frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudBox {
    /// Centre of the box, metres.
    pub centre_m: DVec3,
    /// Half extents, metres.
    pub half_m: DVec3,
    /// The cloud's own centre (its fades go by the distance from it), metres.
    pub cloud_centre_m: DVec3,
    /// The cloud's radius (`Cloud::radius_m`), metres.
    pub radius_m: f64,
    /// The radius of a sphere around the cloud centre holding every sprite, rain included.
    pub sphere_m: f64,
    /// Its type.
    pub cloud_type: CloudType,
    /// Which cloud of the block.
    pub cloud: usize,
}

impl CloudBox {
    /// The box of a cloud (`None` for one without cloud sprites).
    pub fn of(cloud: &Cloud, index: usize) -> Option<Self> {
        let mut lo = DVec3::splat(f64::MAX);
        let mut hi = DVec3::splat(f64::MIN);
        let mut any = false;
        let mut sphere = 0.0f64;
        for s in &cloud.sprites {
            let o = DVec3::from_array(s.offset_m.map(f64::from));
            sphere = sphere.max(o.length() + 0.5 * f64::from(s.width_m.max(s.height_m)));
            if s.precipitation {
                continue;
            }
            let r = DVec3::new(
                f64::from(s.width_m),
                f64::from(s.width_m),
                f64::from(s.height_m),
            ) * 0.25;
            lo = lo.min(o - r);
            hi = hi.max(o + r);
            any = true;
        }
        any.then(|| Self {
            centre_m: cloud.centre_m + (hi + lo) * 0.5,
            half_m: (hi - lo) * 0.5,
            cloud_centre_m: cloud.centre_m,
            radius_m: f64::from(cloud.radius_m).max(1.0),
            sphere_m: sphere,
            cloud_type: cloud.cloud_type,
            cloud: index,
        })
    }

    /// How far inside the box `p` is: 0 outside, rising to 1 over `ramp` of the half-extent.
    pub fn inside(&self, p: DVec3, ramp: f32) -> f32 {
        if self.half_m.min_element() <= 0.0 {
            return 0.0;
        }
        let rel = (p - self.centre_m).abs() / self.half_m;
        let inside = (1.0 - rel.max_element()) as f32;
        (inside / ramp.max(1e-3)).clamp(0.0, 1.0)
    }

    /// Distance from `p` to the box, metres (0 inside).
    pub fn distance_m(&self, p: DVec3) -> f64 {
        ((p - self.centre_m).abs() - self.half_m)
            .max(DVec3::ZERO)
            .length()
    }

    /// Where the segment `a + t (b - a)`, t in 0..=1, is inside the box: (t in, t out).
    pub fn segment(&self, a: DVec3, b: DVec3) -> Option<(f64, f64)> {
        slab(
            a,
            b,
            self.centre_m - self.half_m,
            self.centre_m + self.half_m,
        )
    }
}

/// The t range of the segment `a..b` inside the box `lo..hi` (the slab method).
fn slab(a: DVec3, b: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, f64)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if d[k].abs() < 1e-12 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (u, v) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
        if t0 > t1 {
            return None;
        }
    }
    Some((t0, t1))
}

/// The boxes of one generation and the bounds of them all.
#[derive(Debug)]
pub struct GenerationBoxes {
    /// One per cloud with cloud sprites.
    pub boxes: Vec<CloudBox>,
    /// Bounds of every box (and sphere) of the generation, air frame.
    pub lo_m: DVec3,
    /// See `lo_m`.
    pub hi_m: DVec3,
}

impl GenerationBoxes {
    /// The boxes of a generation's clouds.
    pub fn of(clouds: &[Cloud]) -> Self {
        let boxes: Vec<CloudBox> = clouds
            .iter()
            .enumerate()
            .filter_map(|(i, c)| CloudBox::of(c, i))
            .collect();
        let mut lo = DVec3::splat(f64::MAX);
        let mut hi = DVec3::splat(f64::MIN);
        for b in &boxes {
            let r = DVec3::splat(b.sphere_m);
            lo = lo.min((b.centre_m - b.half_m).min(b.cloud_centre_m - r));
            hi = hi.max((b.centre_m + b.half_m).max(b.cloud_centre_m + r));
        }
        Self {
            boxes,
            lo_m: lo,
            hi_m: hi,
        }
    }

    fn distance_m(&self, p: DVec3) -> f64 {
        if self.boxes.is_empty() {
            return f64::INFINITY;
        }
        let c = (self.lo_m + self.hi_m) * 0.5;
        let h = (self.hi_m - self.lo_m) * 0.5;
        ((p - c).abs() - h).max(DVec3::ZERO).length()
    }
}

/// The boxes of the generations asked about, by serial; shared by the queries of a frame.
#[derive(Debug, Default)]
pub struct BoxCache {
    map: Mutex<HashMap<u64, Arc<GenerationBoxes>>>,
}

impl BoxCache {
    /// Forgets the generations the field no longer holds, once it holds many more than it has.
    fn prune(&self, field: &CloudField) {
        let Ok(mut map) = self.map.lock() else {
            return;
        };
        if map.len() > 2 * field.block_count() + 64 {
            let live: std::collections::HashSet<u64> =
                field.blocks().map(|(_, g)| g.serial).collect();
            map.retain(|serial, _| live.contains(serial));
        }
    }
}

/// What [`CloudProbe::at`] finds at a point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CloudsAtPoint {
    /// In-cloud measure, 0..=1 (the largest of the clouds the point is in, faded).
    pub in_cloud: f32,
    /// The type of that cloud.
    pub cloud_type: Option<CloudType>,
    /// In-cloud measure of the cumulonimbus the point is in, 0..=1 (0 outside every one).
    pub in_cb: f32,
    /// How opaque the rain or snow shafts are where the point is, 0..=1 (as the renderer's).
    pub in_rain: f32,
    /// Distance to the nearest cloud's box (0 inside), metres; `None` beyond the search radius.
    pub nearest_cloud_m: Option<f64>,
    /// Distance to the nearest cumulonimbus, metres; `None` beyond the search radius.
    pub nearest_cb_m: Option<f64>,
}

/// The first cloud a line of sight meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SightHit {
    /// Distance from the start to where it enters the cloud, metres.
    pub distance_m: f64,
    /// Where it enters, ground metres.
    pub point_m: DVec3,
    /// Optical depth through that cloud.
    pub optical_depth: f64,
    /// Optical depth through every cloud along the segment.
    pub total_optical_depth: f64,
    /// The cloud's type.
    pub cloud_type: CloudType,
}

/// Queries on a living [`CloudField`]. See the module docs.
#[derive(Debug, Clone, Copy)]
pub struct CloudProbe<'a> {
    field: &'a CloudField,
    cache: &'a BoxCache,
    settings: &'a InCloudAirSettings,
}

impl<'a> CloudProbe<'a> {
    /// Queries on `field` with `cache` (keep one cache with the field).
    pub fn new(
        field: &'a CloudField,
        cache: &'a BoxCache,
        settings: &'a InCloudAirSettings,
    ) -> Self {
        cache.prune(field);
        Self {
            field,
            cache,
            settings,
        }
    }

    /// Every generation of the blocks whose square reaches within `reach_m` of the air-frame
    /// box `lo..hi` (horizontally) and passes `wanted` (its square padded by a block, for the
    /// clouds that overhang it), with its boxes. The cache is locked once for the query.
    fn generations(
        &self,
        lo: DVec2,
        hi: DVec2,
        reach_m: f64,
        wanted: impl Fn(DVec2, DVec2) -> bool,
    ) -> Vec<(&'a FieldBlock, Arc<GenerationBoxes>)> {
        // Clouds overhang their block by up to a block.
        let pad = reach_m + BLOCK_SIZE_M;
        let a = BlockIndex::containing(lo - DVec2::splat(pad));
        let b = BlockIndex::containing(hi + DVec2::splat(pad));
        let mut map = self.cache.map.lock().ok();
        let mut out = Vec::new();
        let field: &'a CloudField = self.field;
        for j in a.j..=b.j {
            for i in a.i..=b.i {
                let index = BlockIndex::new(i, j);
                let corner = index.min_corner_m();
                let square = (
                    corner - DVec2::splat(BLOCK_SIZE_M),
                    corner + DVec2::splat(2.0 * BLOCK_SIZE_M),
                );
                if !wanted(square.0, square.1) {
                    continue;
                }
                for g in field.generations(index) {
                    if g.phase == Phase::Gone || g.block.clouds.is_empty() {
                        continue;
                    }
                    let boxes = match map.as_mut() {
                        Some(map) => Arc::clone(
                            map.entry(g.serial)
                                .or_insert_with(|| Arc::new(GenerationBoxes::of(&g.block.clouds))),
                        ),
                        None => Arc::new(GenerationBoxes::of(&g.block.clouds)),
                    };
                    out.push((g, boxes));
                }
            }
        }
        out
    }

    fn fade(&self, g: &FieldBlock, b: &CloudBox, p_air: DVec3) -> f32 {
        let fraction = ((p_air - b.cloud_centre_m).length() / b.radius_m).min(1.0) as f32;
        alpha_at(
            g.phase,
            self.field.time_s(),
            fraction,
            self.field.lifecycle(),
        )
    }

    fn air_point(&self, p: DVec3) -> DVec3 {
        let d = self.field.drift_m();
        p - DVec3::new(d.x, d.y, 0.0)
    }

    /// The clouds at ground point `p`.
    pub fn at(&self, p: DVec3) -> CloudsAtPoint {
        let q = self.air_point(p);
        let reach = self.settings.search_radius_m;
        let mut out = CloudsAtPoint::default();
        let mut nearest = f64::INFINITY;
        let mut nearest_cb = f64::INFINITY;
        let all = |_: DVec2, _: DVec2| true;
        for (g, boxes) in self.generations(q.truncate(), q.truncate(), reach, all) {
            if boxes.distance_m(q) > reach.min(nearest.max(nearest_cb)) {
                continue;
            }
            for b in &boxes.boxes {
                let d = b.distance_m(q);
                let in_sphere = (q - b.cloud_centre_m).length_squared() < b.sphere_m * b.sphere_m;
                let cb = b.cloud_type == CloudType::Cumulonimbus;
                // Only what can change an answer needs its fade.
                if d > 0.0 && d >= nearest && !(cb && d < nearest_cb) && !in_sphere {
                    continue;
                }
                let fade = self.fade(g, b, q);
                if fade <= 0.0 {
                    continue;
                }
                nearest = nearest.min(d);
                if cb && fade >= 0.5 {
                    nearest_cb = nearest_cb.min(d);
                }
                if d == 0.0 {
                    let inside = b.inside(q, self.settings.ramp_fraction) * fade;
                    if b.cloud_type == CloudType::Cumulonimbus {
                        out.in_cb = out.in_cb.max(inside);
                    }
                    if inside > out.in_cloud {
                        out.in_cloud = inside;
                        out.cloud_type = Some(b.cloud_type);
                    }
                }
                if in_sphere {
                    out.in_rain = out.in_rain.max(in_rain(&g.block.clouds[b.cloud], q) * fade);
                }
            }
        }
        out.nearest_cloud_m = (nearest <= reach).then_some(nearest);
        out.nearest_cb_m = (nearest_cb <= reach).then_some(nearest_cb);
        out
    }

    /// The first cloud met along the segment from ground point `a` to `b`, with the optical
    /// depth through it and through every cloud along it; `None` in clear air.
    pub fn line_of_sight(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        self.sight(a, b, true)
    }

    /// The first cloud met along the segment and the optical depth through it; its
    /// `total_optical_depth` counts only the clouds looked at before the first was certain (the
    /// cheap query a host casts many of).
    pub fn first_cloud(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        self.sight(a, b, false)
    }

    fn sight(&self, a: DVec3, b: DVec3, whole: bool) -> Option<SightHit> {
        let (qa, qb) = (self.air_point(a), self.air_point(b));
        let length = (qb - qa).length();
        let sigma = 3.0 / f64::from(self.settings.visibility_m);
        let (lo, hi) = (qa.min(qb), qa.max(qb));
        let mut first: Option<(f64, f64, CloudType)> = None;
        let mut total = 0.0;
        // Only the blocks whose padded square the segment crosses, nearest along it first.
        let crosses = |lo: DVec2, hi: DVec2| {
            slab(
                qa.with_z(0.0),
                qb.with_z(0.0),
                lo.extend(-1.0),
                hi.extend(1.0),
            )
            .is_some()
        };
        let mut near: Vec<(f64, &FieldBlock, Arc<GenerationBoxes>)> = self
            .generations(lo.truncate(), hi.truncate(), 0.0, crosses)
            .into_iter()
            .filter_map(|(g, boxes)| {
                slab(qa, qb, boxes.lo_m, boxes.hi_m).map(|(t0, _)| (t0, g, boxes))
            })
            .collect();
        near.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (enter, g, boxes) in near {
            if !whole && first.is_some_and(|f| enter > f.0) {
                break;
            }
            for bx in &boxes.boxes {
                let Some((t0, t1)) = bx.segment(qa, qb) else {
                    continue;
                };
                let mid = qa.lerp(qb, 0.5 * (t0 + t1));
                let fade = f64::from(self.fade(g, bx, mid));
                if fade <= 0.0 {
                    continue;
                }
                let depth = sigma * (t1 - t0) * length * fade;
                total += depth;
                if first.is_none_or(|f| t0 < f.0) {
                    first = Some((t0, depth, bx.cloud_type));
                }
            }
        }
        first.map(|(t, depth, cloud_type)| SightHit {
            distance_m: t * length,
            point_m: a.lerp(b, t),
            optical_depth: depth,
            total_optical_depth: total,
            cloud_type,
        })
    }
}

/// How opaque the rain shafts of `cloud` are at air point `q` (the renderer's rule,
/// `render::draw_list::inside_clouds`): an upright column as opaque as its shaft, less towards
/// its side.
fn in_rain(cloud: &Cloud, q: DVec3) -> f32 {
    if cloud.flat {
        return 0.0;
    }
    let local = (q - cloud.centre_m).as_vec3();
    let mut most = 0.0f32;
    for s in cloud.sprites.iter().filter(|s| s.precipitation) {
        let to = local - glam::Vec3::from_array(s.offset_m);
        if to.z.abs() < 0.5 * s.height_m {
            let aside = to.truncate().length() / (0.5 * s.width_m).max(1.0);
            most = most.max(s.alpha_morph * (1.0 - aside).max(0.0));
        }
    }
    most
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::block::{ColourLevel, Sprite};

    /// A cloud of known geometry: sprites filling the box `centre ± half` (core boxes of
    /// sprites `4 half` wide at the corners of a box of half extent 0: one sprite at the centre
    /// whose core is exactly `half`).
    pub(crate) fn cube_cloud(centre_m: DVec3, half_m: f32, cloud_type: CloudType) -> Cloud {
        let sprite = Sprite {
            offset_m: [0.0; 3],
            width_m: 4.0 * half_m,
            height_m: 4.0 * half_m,
            rotation_deg: 0.0,
            texture: 0,
            shading_group: 0,
            radius_fraction: 0.0,
            alpha_morph: 1.0,
            upright: false,
            precipitation: false,
        };
        Cloud {
            centre_m,
            cloud_type,
            layer: 0,
            radius_m: half_m,
            flat: false,
            sunlit_depth_m: 0.0,
            shaded_base_m: 0.0,
            colour_levels: [ColourLevel {
                height_m: 0.0,
                rgba: [1.0; 4],
            }; 5],
            shading_groups: Vec::new(),
            sprites: vec![sprite],
        }
    }

    #[test]
    fn a_segment_through_a_cloud_hits_its_near_boundary_and_clear_air_none() {
        let c = cube_cloud(DVec3::new(1000.0, 0.0, 2000.0), 500.0, CloudType::Stratus);
        let b = CloudBox::of(&c, 0).unwrap();
        // From 2 km west to 2 km east of it, level through its middle: enters at x = 500.
        let a = DVec3::new(-1000.0, 0.0, 2000.0);
        let (t0, t1) = b.segment(a, DVec3::new(3000.0, 0.0, 2000.0)).unwrap();
        let (enter, exit) = (t0 * 4000.0, t1 * 4000.0);
        assert!((enter - 1500.0).abs() <= 0.1 * 1500.0, "{enter}");
        assert!((exit - 2500.0).abs() < 1.0, "{exit}");
        // Above it, and short of it: nothing.
        assert!(
            b.segment(
                DVec3::new(-1000.0, 0.0, 2600.0),
                DVec3::new(3000.0, 0.0, 2600.0)
            )
            .is_none()
        );
        assert!(b.segment(a, DVec3::new(400.0, 0.0, 2000.0)).is_none());
        // In-cloud: 0 at the boundary, 1 in the core, and the distance outside.
        assert_eq!(b.inside(DVec3::new(500.0, 0.0, 2000.0), 0.35), 0.0);
        assert_eq!(b.inside(DVec3::new(1000.0, 0.0, 2000.0), 0.35), 1.0);
        assert!((b.distance_m(DVec3::new(0.0, 0.0, 2000.0)) - 500.0).abs() < 1e-9);
    }
}

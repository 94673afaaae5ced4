//! The box around a cloud's cores ([`super::core`]: its sprites' dense cores above its base,
//! rain shafts left out), which the probe's queries look through before they ask the cores
//! themselves, and the boxes of a whole generation, worked out once on the generation worker
//! ([`super::field::Generated::boxes`]).

use glam::DVec3;

use super::block::Cloud;
use super::core::SpriteCore;
use crate::weather::CloudType;

/// The box around a cloud's cores, in the field's (air) frame: a line of sight or a point
/// outside it is outside the cloud; inside it, the cores say.
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
            let Some(core) = SpriteCore::of(s, cloud.flat) else {
                continue;
            };
            let r = core.box_half_m();
            lo = lo.min(o - r);
            hi = hi.max(o + r);
            any = true;
        }
        if let Some((slab_lo, slab_hi)) =
            super::core::floor_slab(f64::from(cloud.floor_m), cloud.floor_slab_m)
        {
            lo = lo.min(slab_lo);
            hi = hi.max(slab_hi);
        }
        // Nothing below the base is cloud.
        lo.z = lo.z.max(f64::from(cloud.floor_m)).min(hi.z);
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

/// A segment's reciprocal direction, for a cheap test of bounds it may enter (a tile's of lines
/// of sight, a run's of a cloud's cores): the slab test with no division ([`slab`]'s six were
/// most of the cost of a tile passed over), passing over only bounds the slab test says it
/// misses, or enters at or after a horizon.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cull {
    a: DVec3,
    /// Per axis: 1 over the segment's extent, or none where the slab test takes it as level.
    inverse: [Option<f64>; 3],
}

impl Cull {
    /// How far the t of the entry and exit may lie from the slab test's (a few ulps of numbers
    /// at most 1; far more than that).
    const SLACK: f64 = 1e-9;

    /// The test for the segment `a..b`.
    pub(crate) fn new(a: DVec3, b: DVec3) -> Self {
        let d = b - a;
        // Level as `slab` takes it.
        let inverse = [0, 1, 2].map(|k| (d[k].abs() >= 1e-12).then(|| 1.0 / d[k]));
        Self { a, inverse }
    }

    /// Whether the segment may enter the box `lo..hi` before t = `horizon`: false only where
    /// [`slab`] finds it misses the box, or enters it at or after `horizon`.
    pub(crate) fn may_enter(&self, lo: DVec3, hi: DVec3, horizon: f64) -> bool {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let Some(inverse) = self.inverse[k] else {
                if self.a[k] < lo[k] || self.a[k] > hi[k] {
                    return false;
                }
                continue;
            };
            let (u, v) = ((lo[k] - self.a[k]) * inverse, (hi[k] - self.a[k]) * inverse);
            let (near, far) = if u < v { (u, v) } else { (v, u) };
            // Plain comparisons (a NaN leaves the bounds as they were, as `f64::max` does).
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        t0 <= t1 + Self::SLACK && t0 - Self::SLACK < horizon
    }
}

/// The t range of the segment `a..b` inside the box `lo..hi` (the slab method).
pub(crate) fn slab(a: DVec3, b: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, f64)> {
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
#[derive(Debug, PartialEq)]
pub struct GenerationBoxes {
    /// One per cloud with cloud sprites.
    pub boxes: Vec<CloudBox>,
    /// Bounds of every box (and sphere) of the generation, air frame.
    pub lo_m: DVec3,
    /// See `lo_m`.
    pub hi_m: DVec3,
    /// Whether any box is a cumulonimbus's (the air data looks farther for those).
    pub has_cumulonimbus: bool,
    /// Per cloud of the generation (by its index), its cores in runs where it has many
    /// ([`super::core::CoreRuns`]; `None` for few).
    pub runs: Vec<Option<Box<super::core::CoreRuns>>>,
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
        let runs = (clouds.iter())
            .map(|c| {
                let runs = super::core::CoreRuns::of(c);
                (runs != super::core::CoreRuns::default()).then(|| Box::new(runs))
            })
            .collect();
        Self {
            has_cumulonimbus: boxes
                .iter()
                .any(|b| b.cloud_type == CloudType::Cumulonimbus),
            boxes,
            lo_m: lo,
            hi_m: hi,
            runs,
        }
    }

    /// Distance from `p` to the bounds, metres (0 inside; infinite with no boxes).
    pub fn distance_m(&self, p: DVec3) -> f64 {
        bounds_distance_m(self.lo_m, self.hi_m, p)
    }
}

/// Distance from `p` to the box `lo..hi`, metres: 0 inside, infinite for an empty box (its
/// lowest corner above its highest, as the bounds of a generation without boxes are).
pub fn bounds_distance_m(lo: DVec3, hi: DVec3, p: DVec3) -> f64 {
    if lo.x > hi.x {
        return f64::INFINITY;
    }
    ((p - (lo + hi) * 0.5).abs() - (hi - lo) * 0.5)
        .max(DVec3::ZERO)
        .length()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::clouds::block::{ColourLevel, Sprite};

    /// A cloud of known geometry: one sprite at the centre whose core is a sphere of radius
    /// `half` (and whose box is exactly `centre ± half`), with no base below it.
    pub(crate) fn cube_cloud(centre_m: DVec3, half_m: f32, cloud_type: CloudType) -> Cloud {
        let size = half_m / crate::clouds::core::CORE_HALF_EXTENT as f32;
        let sprite = Sprite {
            offset_m: [0.0; 3],
            width_m: size,
            height_m: size,
            rotation_deg: 0.0,
            texture: 0,
            shading_group: 0,
            radius_fraction: 0.0,
            alpha_morph: 1.0,
            upright: false,
            precipitation: false,
            base: false,
        };
        Cloud {
            centre_m,
            cloud_type,
            layer: 0,
            radius_m: half_m,
            flat: false,
            sunlit_depth_m: 0.0,
            shaded_base_m: 0.0,
            floor_m: f32::MIN,
            floor_slab_m: [0.0; 2],
            optical_density: 1.0,
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
        // The distance outside.
        assert!((b.distance_m(DVec3::new(0.0, 0.0, 2000.0)) - 500.0).abs() < 1e-3);
    }
}

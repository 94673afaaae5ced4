//! A cloud as everything that asks "is there cloud here?" sees it: the union of its sprites'
//! dense cores, none of it below the cloud's flat base.
//!
//! A sprite's core is the part of its quad where the texture is dense: within 0.7 of its half
//! extents ([`CORE_HALF_EXTENT`] of its full size) from its centre, an ellipsoid (a flat sprite's
//! turned with it, as thick as it is narrow). A sprite standing on the base
//! ([`super::block::Sprite::base`]) is dense across its whole width ([`BASE_HALF_EXTENT`]) and
//! down to the base (a flat underside: the column under its core's middle section reaches the
//! cloud's floor): the flat undersides of a heap's base row or a deck's floor overlap into one
//! closed, level underside, as a ceilometer under a cumulus or a pilot breaking out of an
//! overcast sees it, where their round cores alone left the base open and undulating. It is what a person looking up counts as covered,
//! the measure the generator places clouds by ([`super::generate`] covers a layer's oktas with
//! it), and what the probes ([`super::probe`]: `in_cloud`, lines of sight, the sun's occlusion),
//! so a gap the sprites show is a gap to every probe. The cloud's base
//! ([`super::block::Cloud::floor_m`]) cuts the cores: a flat-bottomed cumulus, a deck or a storm
//! cell is first met from below at its base, the relief of its sprites above it.
//!
//! Positions here are relative to the cloud's centre, metres (f64: the probes work in the air
//! frame's metres and subtract the centre first).

use glam::{DVec2, DVec3};

use super::block::{Cloud, Sprite};

#[path = "core_table.rs"]
mod table;
pub(crate) use table::{CoreTable, segment_in_table};

/// A sprite's dense core reaches this fraction of its full width (and height) from its centre.
pub const CORE_HALF_EXTENT: f64 = 0.35;
/// A base sprite's core reaches this fraction of its full width from its centre: its edge.
pub const BASE_HALF_EXTENT: f64 = 0.5;

/// One sprite's core, relative to its cloud's centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpriteCore {
    /// Centre, metres from the cloud's centre.
    pub centre_m: DVec3,
    /// The horizontal axis the first semi-axis lies along (unit).
    along: DVec2,
    /// Semi-axes, metres: along, across, up.
    pub semi_axes_m: DVec3,
    /// A base sprite's floor, metres from the cloud's centre: the core also holds the column
    /// under its middle section down to it (its flat underside).
    floor_m: Option<f64>,
}

impl SpriteCore {
    /// The core of `sprite` of a cloud that is `flat` (`None` for rain or snow, which is not
    /// cloud).
    pub fn of(sprite: &Sprite, flat: bool) -> Option<Self> {
        (!sprite.precipitation).then(|| {
            let mut core = Self::new(
                sprite.offset_m,
                sprite.width_m,
                sprite.height_m,
                sprite.rotation_deg,
                flat,
            );
            if sprite.base {
                core.widen_to_base();
            }
            core
        })
    }

    /// A base sprite's core: dense across its whole width.
    pub fn widen_to_base(&mut self) {
        let k = BASE_HALF_EXTENT / CORE_HALF_EXTENT;
        self.semi_axes_m.x *= k;
        self.semi_axes_m.y *= k;
    }

    /// A base sprite's core standing on its cloud's floor (`floor_m` from the cloud's centre):
    /// it also holds the column under its middle section down to the floor.
    pub fn stand_on(&mut self, floor_m: f64) {
        if floor_m < self.centre_m.z {
            self.floor_m = Some(floor_m);
        }
    }

    /// The core of a sprite `width_m` x `height_m` at `offset_m` from its cloud's centre,
    /// turned `rotation_deg` (what matters of it for a `flat` one, a horizontal rectangle
    /// whose height is its extent across; as thick as it is narrow).
    pub fn new(
        offset_m: [f32; 3],
        width_m: f32,
        height_m: f32,
        rotation_deg: f32,
        flat: bool,
    ) -> Self {
        let mut core = Self::unturned(offset_m, width_m, height_m, flat);
        // A camera-facing sprite's core is round across: its turn is nothing to it (and a sine
        // and cosine a sprite were most of a line of sight's time).
        if flat {
            core.turn(rotation_deg);
        }
        core
    }

    /// [`Self::new`] with its first axis along east whatever the sprite's turn: a camera-facing
    /// sprite's core, or a flat one's before [`Self::turn`] (its centre and reach are the
    /// same either way).
    fn unturned(offset_m: [f32; 3], width_m: f32, height_m: f32, flat: bool) -> Self {
        let (w, h) = (f64::from(width_m), f64::from(height_m));
        let (across, up) = if flat { (h, w.min(h)) } else { (w, h) };
        Self {
            centre_m: DVec3::from_array(offset_m.map(f64::from)),
            along: DVec2::X,
            semi_axes_m: DVec3::new(w, across, up) * CORE_HALF_EXTENT,
            floor_m: None,
        }
    }

    /// Turns a flat sprite's core `rotation_deg` (its first axis along that bearing from east).
    fn turn(&mut self, rotation_deg: f32) {
        self.along = DVec2::from_angle(f64::from(rotation_deg).to_radians());
    }

    /// How far from its centre any of the core (its column included) reaches, metres: a
    /// column's bottom rim lies its depth down and its horizontal radius out.
    pub(super) fn reach_m(&self) -> f64 {
        let r = self.semi_axes_m.max_element();
        match self.floor_m {
            Some(floor) => {
                let across = self.semi_axes_m.x.max(self.semi_axes_m.y);
                r.max(across.hypot(self.centre_m.z - floor))
            }
            None => r,
        }
    }

    /// At least [`Self::reach_m`], without its square root: a column's depth and radius added
    /// (never less than their hypotenuse; widened by a millionth of a millionth against the
    /// hypotenuse's rounding). A line farther from the centre than this is farther than the
    /// reach too.
    fn reach_bound_m(&self) -> f64 {
        let r = self.semi_axes_m.max_element();
        match self.floor_m {
            Some(floor) => {
                let across = self.semi_axes_m.x.max(self.semi_axes_m.y);
                r.max((across + (self.centre_m.z - floor).abs()) * (1.0 + 1e-12))
            }
            None => r,
        }
    }

    /// Half the sides of the box around the core (a turned one's by its longer horizontal
    /// axis), metres.
    pub fn box_half_m(&self) -> DVec3 {
        let a = &self.semi_axes_m;
        DVec3::new(a.x.max(a.y), a.x.max(a.y), a.z)
    }

    /// `p` (from the cloud's centre) in the core's unit sphere.
    fn unit(&self, p: DVec3) -> DVec3 {
        let d = p - self.centre_m;
        let flat = d.truncate();
        DVec3::new(flat.dot(self.along), self.along.perp_dot(flat), d.z) / self.semi_axes_m
    }

    /// The core's normalised radius at `p` (below 1 inside): in its column, the horizontal one.
    pub fn radius(&self, p: DVec3) -> f64 {
        let u = self.unit(p);
        match self.floor_m {
            Some(floor) if p.z >= floor && p.z <= self.centre_m.z => u.truncate().length(),
            _ => u.length(),
        }
    }

    /// Where the segment `a + t (b - a)`, t in 0..=1, is inside the core (its column included),
    /// pushed onto `out` as (t in, t out): none, one or two stretches.
    pub fn segment_into(&self, a: DVec3, b: DVec3, out: &mut Vec<(f64, f64)>) {
        if let Some(span) = self.segment(a, b) {
            out.push(span);
        }
        if let Some(span) = self.column_segment(a, b) {
            out.push(span);
        }
    }

    /// [`Self::segment`] and [`Self::column_segment`] of the same segment, each end put in the
    /// core's unit sphere once (the same numbers: a line of sight near a base sprite's core
    /// asked for its six divisions twice).
    pub(super) fn segments(&self, a: DVec3, b: DVec3) -> [Option<(f64, f64)>; 2] {
        let (o, e) = (self.unit(a), self.unit(b));
        [
            Self::sphere_segment(o, e),
            self.column_segment_in_unit(a, b, o.truncate(), e.truncate()),
        ]
    }

    /// Where the segment is inside the column under a base sprite's core.
    fn column_segment(&self, a: DVec3, b: DVec3) -> Option<(f64, f64)> {
        self.floor_m?;
        let (o, e) = (self.unit(a).truncate(), self.unit(b).truncate());
        self.column_segment_in_unit(a, b, o, e)
    }

    /// [`Self::column_segment`] with the ends' horizontal places in the unit circle, `o` and
    /// `e` (of [`Self::unit`]).
    fn column_segment_in_unit(&self, a: DVec3, b: DVec3, o: DVec2, e: DVec2) -> Option<(f64, f64)> {
        let floor = self.floor_m?;
        // Between the floor and the core's middle.
        let dz = b.z - a.z;
        let (mut t0, mut t1) = if dz.abs() < 1e-12 {
            if a.z < floor || a.z > self.centre_m.z {
                return None;
            }
            (0.0, 1.0)
        } else {
            let (u, v) = ((floor - a.z) / dz, (self.centre_m.z - a.z) / dz);
            (u.min(v).max(0.0), u.max(v).min(1.0))
        };
        // Inside the unit circle horizontally.
        let d = e - o;
        let dd = d.length_squared();
        if dd < 1e-18 {
            if o.length_squared() >= 1.0 {
                return None;
            }
        } else {
            let half_b = o.dot(d);
            let disc = half_b * half_b - dd * (o.length_squared() - 1.0);
            if disc <= 0.0 {
                return None;
            }
            let root = disc.sqrt();
            t0 = t0.max((-half_b - root) / dd);
            t1 = t1.min((-half_b + root) / dd);
        }
        (t0 < t1).then_some((t0, t1))
    }

    /// Where the segment `a + t (b - a)`, t in 0..=1, is inside the core's ellipsoid: (t in,
    /// t out).
    pub fn segment(&self, a: DVec3, b: DVec3) -> Option<(f64, f64)> {
        Self::sphere_segment(self.unit(a), self.unit(b))
    }

    /// Where the segment from `o` to `e` (in the core's unit sphere) is inside the sphere.
    fn sphere_segment(o: DVec3, e: DVec3) -> Option<(f64, f64)> {
        let d = e - o;
        let dd = d.length_squared();
        if dd < 1e-18 {
            return (o.length_squared() < 1.0).then_some((0.0, 1.0));
        }
        // |o + t d|^2 = 1.
        let half_b = o.dot(d);
        let c = o.length_squared() - 1.0;
        let disc = half_b * half_b - dd * c;
        if disc <= 0.0 {
            return None;
        }
        let root = disc.sqrt();
        let (t0, t1) = ((-half_b - root) / dd, (-half_b + root) / dd);
        let (t0, t1) = (t0.max(0.0), t1.min(1.0));
        (t0 < t1).then_some((t0, t1))
    }
}

/// The cores of `cloud`'s sprites (its base sprites' standing on its floor).
pub fn cores(cloud: &Cloud) -> impl Iterator<Item = SpriteCore> + '_ {
    cloud.sprites.iter().filter_map(|s| {
        let mut core = SpriteCore::of(s, cloud.flat)?;
        if s.base {
            core.stand_on(f64::from(cloud.floor_m));
        }
        Some(core)
    })
}

/// [`cores`] with a flat cloud's cores not turned yet, each with its sprite's turn: a line of
/// sight passes most of a cloud's cores by on their centre and reach, which the turn does not
/// change, and turns (a sine and a cosine) only those it comes near. Turned, each is the core
/// [`cores`] gives.
fn unturned_cores(cloud: &Cloud) -> impl Iterator<Item = (SpriteCore, f32)> + '_ {
    cloud.sprites.iter().filter_map(|s| unturned_core(cloud, s))
}

/// One sprite's core of [`unturned_cores`] (`None` for rain or snow).
fn unturned_core(cloud: &Cloud, s: &Sprite) -> Option<(SpriteCore, f32)> {
    (!s.precipitation).then(|| {
        let mut core = SpriteCore::unturned(s.offset_m, s.width_m, s.height_m, cloud.flat);
        if s.base {
            core.widen_to_base();
            core.stand_on(f64::from(cloud.floor_m));
        }
        (core, s.rotation_deg)
    })
}

/// Cores a run of [`CoreRuns`] holds at most.
const RUN_CORES: usize = 8;

/// A cloud with more cores than this has them in runs ([`CoreRuns`]); fewer are looked at one
/// by one.
const RUNS_FROM: usize = 24;

/// A cloud's cores in runs of neighbours, each with the bounds of its cores' reach: a line of
/// sight that passes a run's bounds by enters none of its cores and looks at none of them (a
/// deck's cloud has hundreds of sprites, a line crosses a few). Made once for a generation, with
/// its boxes, off the frame thread; none for a cloud of few cores.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CoreRuns {
    /// The cores' sprites (indices into the cloud's), run after run.
    sprites: Vec<u32>,
    /// Per run: the lowest and highest corner of the spheres its cores reach (and a metre),
    /// from the cloud's centre, and where its sprites end in `sprites`.
    runs: Vec<(DVec3, DVec3, u32)>,
}

impl CoreRuns {
    /// The runs of `cloud`'s cores: in strips west to east, each south to north, cut every
    /// `RUN_CORES` (8); empty for `RUNS_FROM` (24) cores or fewer.
    pub fn of(cloud: &Cloud) -> Self {
        let mut cores: Vec<(u32, DVec3, f64)> = (cloud.sprites.iter().enumerate())
            .filter_map(|(k, s)| {
                unturned_core(cloud, s).map(|(c, _)| (k as u32, c.centre_m, c.reach_m()))
            })
            .collect();
        if cores.len() <= RUNS_FROM {
            return Self::default();
        }
        cores.sort_by(|x, y| x.1.x.total_cmp(&y.1.x));
        // Strips of about as many runs as there are strips.
        let runs = cores.len().div_ceil(RUN_CORES);
        let strip = (runs as f64).sqrt().ceil() as usize * RUN_CORES;
        let mut out = Self::default();
        for strip in cores.chunks_mut(strip) {
            strip.sort_by(|x, y| x.1.y.total_cmp(&y.1.y));
            for run in strip.chunks(RUN_CORES) {
                let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
                for &(k, centre, reach) in run {
                    let r = DVec3::splat(reach + 1.0);
                    (lo, hi) = (lo.min(centre - r), hi.max(centre + r));
                    out.sprites.push(k);
                }
                out.runs.push((lo, hi, out.sprites.len() as u32));
            }
        }
        out
    }
}

/// An overcast's closed floor ([`Cloud::floor_slab_m`]) as a box from the cloud's centre
/// (lowest corner, highest corner), over a floor at `floor_m`; `None` for none.
pub fn floor_slab(floor_m: f64, slab_m: [f32; 2]) -> Option<(DVec3, DVec3)> {
    let [half, depth] = slab_m.map(f64::from);
    (half > 0.0 && depth > 0.0).then(|| {
        (
            DVec3::new(-half, -half, floor_m),
            DVec3::new(half, half, floor_m + depth),
        )
    })
}

/// How far inside `cloud` the point `p` (from the cloud's centre) is: 0 outside every core and
/// below the base, rising to 1 over `ramp` of a core's radius in (the deepest core's).
pub fn inside(cloud: &Cloud, p: DVec3, ramp: f32) -> f32 {
    inside_cores(
        cores(cloud),
        f64::from(cloud.floor_m),
        cloud.floor_slab_m,
        p,
        ramp,
    )
}

/// [`inside`] for any cores (the renderer's own clouds' among them) over a base at `floor_m`,
/// with an overcast's floor slab `slab_m` ([`Cloud::floor_slab_m`]).
pub fn inside_cores(
    cores: impl Iterator<Item = SpriteCore>,
    floor_m: f64,
    slab_m: [f32; 2],
    p: DVec3,
    ramp: f32,
) -> f32 {
    if p.z < floor_m {
        return 0.0;
    }
    let ramp = f64::from(ramp).max(1e-3);
    let mut deepest = 0.0f64;
    if let Some((lo, hi)) = floor_slab(floor_m, slab_m) {
        let (mid, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let r = ((p - mid).abs() / half).max_element();
        if r < 1.0 {
            deepest = (1.0 - r) / ramp;
        }
    }
    for core in cores {
        if deepest >= 1.0 {
            return 1.0;
        }
        let r = core.radius(p);
        if r < 1.0 {
            deepest = deepest.max((1.0 - r) / ramp);
        }
    }
    deepest.min(1.0) as f32
}

/// The distance from `p` (from the cloud's centre) to the nearest core, metres: 0 inside one,
/// otherwise the normalised radius beyond 1 times the core's smallest semi-axis (a lower bound
/// on the true distance, exact for a sphere).
pub fn distance_m(cloud: &Cloud, p: DVec3) -> f64 {
    let floor = f64::from(cloud.floor_m);
    let below = (floor - p.z).max(0.0);
    let mut nearest = floor_slab(floor, cloud.floor_slab_m).map_or(f64::INFINITY, |(lo, hi)| {
        super::boxes::bounds_distance_m(lo, hi, p)
    });
    for core in cores(cloud) {
        if nearest <= 0.0 {
            return 0.0;
        }
        let r = core.radius(p);
        let d = ((r - 1.0).max(0.0) * core.semi_axes_m.min_element()).max(below);
        nearest = nearest.min(d);
    }
    nearest
}

/// The stretches of the segment `a + t (b - a)` (from the cloud's centre), t in 0..=1, that are
/// inside `cloud`: the union of its cores (and floor slab) above its base, sorted and merged,
/// into `out` (cleared first).
pub fn segment(cloud: &Cloud, a: DVec3, b: DVec3, out: &mut Vec<(f64, f64)>) {
    segment_in_runs(cloud, None, a, b, out);
}

/// The part of the segment `a`..`b` (as fractions of it) above a cloud's base at `floor` m;
/// `None` where none of it is.
fn above_floor(a: DVec3, b: DVec3, floor: f64) -> Option<(f64, f64)> {
    let dz = b.z - a.z;
    let (from, to) = if dz.abs() < 1e-12 {
        if a.z < floor {
            return None;
        }
        (0.0, 1.0)
    } else {
        let t = (floor - a.z) / dz;
        if dz > 0.0 {
            (t.max(0.0), 1.0)
        } else {
            (0.0, t.min(1.0))
        }
    };
    (from < to).then_some((from, to))
}

/// [`segment`], the cloud's cores looked at run by run where it has `runs` ([`CoreRuns`]):
/// a run whose bounds the segment misses is passed over whole. The same stretches.
pub fn segment_in_runs(
    cloud: &Cloud,
    runs: Option<&CoreRuns>,
    a: DVec3,
    b: DVec3,
    out: &mut Vec<(f64, f64)>,
) {
    out.clear();
    let floor = f64::from(cloud.floor_m);
    let Some((above_from, above_to)) = above_floor(a, b, floor) else {
        return;
    };
    let mut spans = Vec::with_capacity(2);
    if let Some((lo, hi)) = floor_slab(floor, cloud.floor_slab_m)
        && let Some(span) = super::boxes::slab(a, b, lo, hi)
    {
        spans.push(span);
    }
    let d = b - a;
    let dd = d.length_squared().max(1e-12);
    let mut visit = |(mut core, rotation_deg): (SpriteCore, f32)| {
        // Most of a cloud's cores lie off a line that crosses it: passed over on their
        // distance from the line, before the ellipsoid is asked.
        // (On a bound of its reach first: the reach's hypotenuse is asked only of the cores
        // the bound leaves near; a core the bound passes over the reach passes over too.)
        let off = (core.centre_m - a).cross(d).length_squared();
        let bound = core.reach_bound_m();
        if off > bound * bound * dd {
            return;
        }
        let reach = core.reach_m();
        if off > reach * reach * dd {
            return;
        }
        if cloud.flat {
            core.turn(rotation_deg);
        }
        core.segment_into(a, b, &mut spans);
        out.extend(
            spans
                .drain(..)
                .map(|(t0, t1)| (t0.max(above_from), t1.min(above_to))),
        );
    };
    match runs {
        // A run the segment passes by holds no core it enters (each lies within its reach of
        // its centre, and the run's bounds hold those spheres and a metre): the stretches are
        // the same, found in another order, and merged the same.
        Some(runs) if !runs.runs.is_empty() => {
            let mut from = 0;
            for &(lo, hi, to) in &runs.runs {
                let run = &runs.sprites[from as usize..to as usize];
                from = to;
                if super::boxes::slab(a, b, lo, hi).is_none() {
                    continue;
                }
                for &k in run {
                    if let Some(core) = unturned_core(cloud, &cloud.sprites[k as usize]) {
                        visit(core);
                    }
                }
            }
        }
        _ => unturned_cores(cloud).for_each(visit),
    }
    out.extend(
        spans
            .drain(..)
            .map(|(t0, t1)| (t0.max(above_from), t1.min(above_to))),
    );
    out.retain(|(t0, t1)| t0 < t1);
    merge(out);
}

/// Sorts the intervals and merges those that overlap.
fn merge(spans: &mut Vec<(f64, f64)>) {
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged = 0;
    for k in 0..spans.len() {
        let (t0, t1) = spans[k];
        if merged > 0 && t0 <= spans[merged - 1].1 {
            spans[merged - 1].1 = spans[merged - 1].1.max(t1);
        } else {
            spans[merged] = (t0, t1);
            merged += 1;
        }
    }
    spans.truncate(merged);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::boxes::tests::cube_cloud;
    use crate::weather::CloudType;

    #[test]
    fn a_line_up_through_a_cloud_meets_its_base_not_the_core_below_it() {
        // One sprite 1000 m across, its centre 100 m above the cloud's base: its core reaches
        // 350 m down, the base cuts it at 100 m below the centre.
        let mut c = cube_cloud(
            DVec3::ZERO,
            1000.0 * CORE_HALF_EXTENT as f32,
            CloudType::Stratus,
        );
        c.floor_m = -100.0;
        let mut spans = Vec::new();
        segment(
            &c,
            DVec3::new(0.0, 0.0, -1000.0),
            DVec3::new(0.0, 0.0, 1000.0),
            &mut spans,
        );
        assert_eq!(spans.len(), 1);
        let (enter, exit) = (spans[0].0 * 2000.0 - 1000.0, spans[0].1 * 2000.0 - 1000.0);
        assert!((enter + 100.0).abs() < 1e-6, "{enter}");
        assert!((exit - 350.0).abs() < 1e-6, "{exit}");
        assert_eq!(inside(&c, DVec3::new(0.0, 0.0, -150.0), 0.35), 0.0);
        assert_eq!(inside(&c, DVec3::ZERO, 0.35), 1.0);
        assert!((distance_m(&c, DVec3::new(0.0, 0.0, -300.0)) - 200.0).abs() < 1e-6);
        // Beside the core (its corner box would hold this point): clear.
        assert_eq!(inside(&c, DVec3::new(300.0, 300.0, 0.0), 0.35), 0.0);
    }

    /// A line past a base sprite's column near its bottom rim, farther from the core's centre
    /// than its depth or its radius alone, is inside it (the walk's reach once left it out).
    #[test]
    fn a_line_by_a_columns_bottom_rim_is_in_it() {
        let mut c = cube_cloud(DVec3::ZERO, 100.0, CloudType::CumulusCongestus);
        c.sprites[0].base = true;
        c.floor_m = -300.0;
        let across = 100.0 * BASE_HALF_EXTENT / CORE_HALF_EXTENT;
        let (a, b) = (
            DVec3::new(-500.0, 130.0, -290.0),
            DVec3::new(500.0, 130.0, -290.0),
        );
        let mut spans = Vec::new();
        segment(&c, a, b, &mut spans);
        let half = (across * across - 130.0 * 130.0).sqrt();
        assert_eq!(spans.len(), 1, "{spans:?}");
        let (enter, exit) = (spans[0].0 * 1000.0 - 500.0, spans[0].1 * 1000.0 - 500.0);
        assert!(
            (enter + half).abs() < 1e-3 && (exit - half).abs() < 1e-3,
            "{spans:?}"
        );
    }

    #[test]
    fn two_cores_with_a_gap_between_are_two_stretches() {
        let mut c = cube_cloud(DVec3::ZERO, 100.0, CloudType::Stratus);
        let mut far = c.sprites[0];
        far.offset_m = [1000.0, 0.0, 0.0];
        c.sprites.push(far);
        let mut spans = Vec::new();
        segment(
            &c,
            DVec3::new(-500.0, 0.0, 0.0),
            DVec3::new(1500.0, 0.0, 0.0),
            &mut spans,
        );
        let metres: Vec<(f64, f64)> = spans
            .iter()
            .map(|&(a, b)| (a * 2000.0 - 500.0, b * 2000.0 - 500.0))
            .collect();
        assert_eq!(metres.len(), 2, "{metres:?}");
        // (The sprite's size is an f32: the core's radius is 100 m to a few micrometres.)
        assert!((metres[0].0 + 100.0).abs() < 1e-3 && (metres[0].1 - 100.0).abs() < 1e-3);
        assert!((metres[1].0 - 900.0).abs() < 1e-3 && (metres[1].1 - 1100.0).abs() < 1e-3);
        // Overlapping cores merge into one stretch.
        c.sprites[1].offset_m = [150.0, 0.0, 0.0];
        segment(
            &c,
            DVec3::new(-500.0, 0.0, 0.0),
            DVec3::new(1500.0, 0.0, 0.0),
            &mut spans,
        );
        assert_eq!(spans.len(), 1);
    }

    /// A line of sight turns a flat cloud's cores only once it is near them: turned, they
    /// are the cores every other probe asks, base sprites and rain among the sprites too.
    #[test]
    fn the_cores_turned_late_are_the_cores() {
        for flat in [false, true] {
            let mut c = cube_cloud(DVec3::ZERO, 100.0, CloudType::Stratus);
            c.flat = flat;
            c.floor_m = -400.0;
            let first = c.sprites[0];
            c.sprites = (0..9)
                .map(|k| {
                    let mut s = first;
                    s.offset_m = [40.0 * k as f32, -25.0 * k as f32, 10.0 * (k % 3) as f32];
                    s.width_m = 200.0 + 30.0 * k as f32;
                    s.height_m = 150.0 + 10.0 * k as f32;
                    s.rotation_deg = 37.0 * k as f32;
                    s.base = k % 2 == 0;
                    s.precipitation = k == 4;
                    s
                })
                .collect();
            let late: Vec<SpriteCore> = unturned_cores(&c)
                .map(|(mut core, rotation_deg)| {
                    if flat {
                        core.turn(rotation_deg);
                    }
                    core
                })
                .collect();
            assert_eq!(late, cores(&c).collect::<Vec<_>>());
            assert_eq!(late.len(), 8);
        }
    }
}

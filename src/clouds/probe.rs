//! Asking the clouds about a point or a segment, on the CPU, cheap enough for every frame: how
//! far inside a cloud a point is (the measure the renderer fogs the camera with, at any point,
//! formation and dissipation fades included), the nearest cloud, the nearest of a type, whether
//! a point is in a rain shaft, and the first cloud a line of sight meets with the optical depth
//! through it.
//!
//! A cloud is the union of its sprites' dense cores above its base ([`super::core`]), what the
//! sprites show: a gap between them is clear air here too. Inside a core the in-cloud measure
//! rises from 0 at its boundary to 1 at `ramp_fraction` of its radius in, times the cloud's fade
//! where the point is ([`super::lifecycle::alpha_at`] at the point's radius fraction). A line of
//! sight meets a cloud where it enters a core; its optical depth is the extinction inside a
//! cloud (`3 / visibility_m`, Koschmieder) times its type's `optical_density` (1 for water
//! cloud, far less for thin ice cloud: cirrus), times the length inside the cores, times the
//! fade. The in-cloud measure stays geometric: inside a cirrus is still inside cloud.
//!
//! The walks go through the box around each cloud's cores ([`super::boxes`]) first, and ask the
//! cores only of a cloud whose box they enter. The boxes of a generation are worked out once, on
//! the generation worker
//! ([`super::field::FieldBlock::boxes`]). A point query looks only at the blocks within reach of
//! the point, and skips a block whose clouds' bounds are out of reach; a line of sight walks the
//! field's boxes in tiles (`clouds::sight`), a tile built again when a generation joins it.
//! Inside a box a line reads the cloud's cores from a table laid out for it (centres and
//! bounds of reach side by side, each core's reach and turn worked out once), made the first
//! time a line enters the box and kept with the tile: the same stretches, to the bit, as
//! asking the sprites.
//! Positions are ground metres (east, north, up MSL); the field's drift is taken off to find the
//! clouds.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use glam::{DVec2, DVec3};

use super::block::Cloud;
use super::boxes::{CloudBox, GenerationBoxes, bounds_distance_m};
use super::core;
use super::field::{CloudField, FieldBlock};
use super::lifecycle::{Phase, alpha_at};
use super::sight::{FieldSight, Met};
use crate::weather::air::InCloudAirSettings;
use crate::weather::{BLOCK_SIZE_M, BlockIndex, CloudType};

/// Per block the generations with the bounds of them all, and the field's boxes in tiles for
/// lines of sight: shared by the queries of a frame. The per-block lists hold while the field's
/// membership ([`CloudField::membership`]) does: a point query then looks a block up once and
/// passes over it on its bounds, without the field's own look-ups. The tiles are brought up to a
/// new membership by the first line of sight after it, building only the tiles that changed.
#[derive(Debug, Default)]
pub struct BoxCache {
    state: Mutex<CacheState>,
}

#[derive(Debug, Default)]
struct CacheState {
    /// The field (its address) and membership the block lists and the tiles are of.
    key: Option<(usize, u64)>,
    /// Per block: the generations' serials and boxes, and the bounds of them all.
    blocks: HashMap<BlockIndex, BlockBoxes, BuildFast>,
    /// The field's boxes in tiles, made the first time a line of sight asks (`None` for another
    /// field), and whether the membership changed since they were brought up to it.
    sight: Option<FieldSight>,
    sight_behind: bool,
    /// A line of sight's stretches inside a cloud's cores, kept for the next line (an
    /// allocation a line saved).
    inside: Vec<(f64, f64)>,
}

#[derive(Debug)]
struct BlockBoxes {
    lo_m: DVec3,
    hi_m: DVec3,
    generations: Vec<ListedGeneration>,
}

/// A generation in a block's list: its serial, its boxes and, copied out of them, their
/// bounds (empty: the lowest corner above the highest) and whether one is a cumulonimbus.
#[derive(Debug)]
struct ListedGeneration {
    serial: u64,
    boxes: Arc<GenerationBoxes>,
    lo_m: DVec3,
    hi_m: DVec3,
    has_cumulonimbus: bool,
}

impl BlockBoxes {
    /// The living generations of block `index` that have clouds, and their bounds.
    fn of(field: &CloudField, index: BlockIndex) -> Self {
        let mut lo = DVec3::splat(f64::MAX);
        let mut hi = DVec3::splat(f64::MIN);
        let generations = field
            .generations(index)
            .iter()
            .filter(|g| g.phase != Phase::Gone && !g.block.clouds.is_empty())
            .map(|g| {
                let boxes = Arc::clone(&g.boxes);
                // Without boxes the bounds are empty (lowest corner above the highest).
                lo = lo.min(boxes.lo_m);
                hi = hi.max(boxes.hi_m);
                ListedGeneration {
                    serial: g.serial,
                    has_cumulonimbus: boxes.has_cumulonimbus,
                    lo_m: boxes.lo_m,
                    hi_m: boxes.hi_m,
                    boxes,
                }
            })
            .collect();
        Self {
            lo_m: lo,
            hi_m: hi,
            generations,
        }
    }
}

impl BoxCache {
    /// The cache's state for a query on `field`, locked: the block lists forgotten when the
    /// field's membership changed, and the tiles too when it is another field. (Pruned by the
    /// query that reads it, under the one lock: a line of sight per band took two.)
    fn lock(&self, field: &CloudField) -> Option<std::sync::MutexGuard<'_, CacheState>> {
        let mut state = self.state.lock().ok()?;
        let key = (std::ptr::from_ref(field) as usize, field.membership());
        if state.key != Some(key) {
            if state.key.is_none_or(|k| k.0 != key.0) {
                state.sight = None;
            }
            state.key = Some(key);
            state.blocks.clear();
            state.sight_behind = true;
        }
        Some(state)
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

/// One stretch of cloud along a line of sight: where it enters and leaves cloud (the cores of
/// one cloud or of several that overlap), and the optical depth through it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudCrossing {
    /// Distance from the start to where it enters cloud, metres.
    pub entry_m: f64,
    /// Distance from the start to where it leaves cloud, metres.
    pub exit_m: f64,
    /// Optical depth through the stretch.
    pub optical_depth: f64,
    /// The type of the cloud that makes most of that depth.
    pub cloud_type: CloudType,
}

/// The first cloud a line of sight meets.
#[derive(Debug, Clone, PartialEq)]
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
    /// Every stretch of cloud along the segment, nearest first ([`CloudProbe::line_of_sight`];
    /// empty from [`CloudProbe::first_cloud`] and [`CloudProbe::optical_depth_until`]).
    pub crossings: Vec<CloudCrossing>,
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
        Self {
            field,
            cache,
            settings,
        }
    }

    /// The generations of the blocks within `reach_m` (and a block, for the clouds that
    /// overhang theirs) of air point `q` whose bounds lie within `reach_m` of it: the distance
    /// to their bounds, their block and their place in its list, nearest first. The block
    /// lists are made for the blocks not listed yet. Stable: the generations around the point
    /// (at 0) keep their order, which decides between equally deep clouds.
    fn near_generations(
        state: &mut CacheState,
        field: &CloudField,
        q: DVec3,
        reach_m: f64,
    ) -> Vec<(f64, BlockIndex, usize)> {
        let pad = reach_m + BLOCK_SIZE_M;
        let a = BlockIndex::containing(q.truncate() - DVec2::splat(pad));
        let b = BlockIndex::containing(q.truncate() + DVec2::splat(pad));
        let mut out = Vec::new();
        for j in a.j..=b.j {
            for i in a.i..=b.i {
                let index = BlockIndex::new(i, j);
                let entry = state
                    .blocks
                    .entry(index)
                    .or_insert_with(|| BlockBoxes::of(field, index));
                if entry.generations.is_empty()
                    || bounds_distance_m(entry.lo_m, entry.hi_m, q) > reach_m
                {
                    continue;
                }
                // The bounds are read from the list, not from each generation's boxes (a
                // cache miss each, for the many that lie out of reach).
                for (k, g) in entry.generations.iter().enumerate() {
                    let d = bounds_distance_m(g.lo_m, g.hi_m, q);
                    if d <= reach_m {
                        out.push((d, index, k));
                    }
                }
            }
        }
        out.sort_by(|x, y| x.0.total_cmp(&y.0));
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
        let Some(mut guard) = self.cache.lock(self.field) else {
            return out;
        };
        let state = &mut *guard;
        // Nearest first, so that the nearest cloud found soon passes over the rest.
        let near = Self::near_generations(state, self.field, q, reach);
        for (bounds_m, index, k) in near {
            let Some(listed) = state.blocks.get(&index).and_then(|e| e.generations.get(k)) else {
                continue;
            };
            // Its bounds hold every box and rain sphere: one beyond them all is out of the
            // point's clouds and rain, and has no cloud nearer than the nearest, nor (without a
            // cumulonimbus, or beyond the nearest one) a nearer cumulonimbus.
            let farther =
                bounds_m > nearest && (!listed.has_cumulonimbus || bounds_m >= nearest_cb);
            if bounds_m > 0.0 && farther {
                continue;
            }
            let Some(g) = self
                .field
                .generations(index)
                .iter()
                .find(|g| g.serial == listed.serial)
            else {
                continue;
            };
            let boxes = &listed.boxes;
            for b in &boxes.boxes {
                let box_m = b.distance_m(q);
                let cloud = &g.block.clouds[b.cloud];
                // Inside the box the cores say how near the cloud is; outside it the box's
                // distance is the nearest the cores can be.
                let d = if box_m > 0.0 {
                    box_m
                } else {
                    core::distance_m(cloud, q - cloud.centre_m)
                };
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
                    let inside =
                        core::inside(cloud, q - cloud.centre_m, self.settings.ramp_fraction) * fade;
                    if b.cloud_type == CloudType::Cumulonimbus {
                        out.in_cb = out.in_cb.max(inside);
                    }
                    if inside > out.in_cloud {
                        out.in_cloud = inside;
                        out.cloud_type = Some(b.cloud_type);
                    }
                }
                if in_sphere {
                    out.in_rain = out.in_rain.max(in_rain(cloud, q) * fade);
                }
            }
        }
        out.nearest_cloud_m = (nearest <= reach).then_some(nearest);
        out.nearest_cb_m = (nearest_cb <= reach).then_some(nearest_cb);
        out
    }

    /// Every cloud along the segment from ground point `a` to `b`: the first one met, with the
    /// optical depth through it and through all of them, and each stretch of cloud
    /// (`crossings`: entry, exit, optical depth); `None` in clear air.
    pub fn line_of_sight(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        let mut spans = Vec::new();
        let length = (b - a).length();
        let mut hit = self.sight(a, b, true, f64::INFINITY, Some(&mut spans))?;
        hit.crossings = crossings(spans, length);
        Some(hit)
    }

    /// The optical depth through the clouds along the segment from ground point `a` to `b`,
    /// walked only until it reaches `enough`: then at least that (the sun's occlusion, which
    /// `1 - exp(-depth)` makes 1 to within `exp(-enough)`, needs no more, and a ray up through
    /// a storm would cross hundreds of boxes beyond). 0 in clear air.
    pub fn optical_depth_until(&self, a: DVec3, b: DVec3, enough: f64) -> f64 {
        self.sight(a, b, true, enough, None)
            .map_or(0.0, |hit| hit.total_optical_depth)
    }

    /// The first cloud met along the segment and the optical depth through it; its
    /// `total_optical_depth` counts only the clouds looked at before the first was certain (the
    /// cheap query a host casts many of).
    pub fn first_cloud(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        self.sight(a, b, false, f64::INFINITY, None)
    }

    /// The walk of [`Self::line_of_sight`] (`whole`) or [`Self::first_cloud`], stopped once the
    /// optical depth counted reaches `enough`; each stretch inside a cloud's cores goes into
    /// `spans` (t in, t out, optical depth, type) where given.
    pub(super) fn sight(
        &self,
        a: DVec3,
        b: DVec3,
        whole: bool,
        enough: f64,
        spans: Option<&mut Vec<Span>>,
    ) -> Option<SightHit> {
        self.sight_before(a, b, (whole, f64::INFINITY), enough, spans)
    }

    /// [`Self::first_cloud`] told that a cloud was met at t = `before` along the segment
    /// already (another drift band's): the clouds entered at or after it are passed over. The
    /// first cloud it returns, when it is met before `before`, is [`Self::first_cloud`]'s but
    /// for its `total_optical_depth` (fewer clouds looked at); else it is met at or after
    /// `before`, or `None`.
    pub(super) fn first_cloud_before(&self, a: DVec3, b: DVec3, before: f64) -> Option<SightHit> {
        self.sight_before(a, b, (false, before), f64::INFINITY, None)
    }

    /// [`Self::sight`] with the walk's `(whole, before)` ([`FieldSight::crossed_before`]).
    fn sight_before(
        &self,
        a: DVec3,
        b: DVec3,
        (whole, before): (bool, f64),
        enough: f64,
        mut spans: Option<&mut Vec<Span>>,
    ) -> Option<SightHit> {
        let (qa, qb) = (self.air_point(a), self.air_point(b));
        let length = (qb - qa).length();
        let sigma = 3.0 / f64::from(self.settings.visibility_m);
        let cell_m = self.settings.grid_cell_m;
        let field = self.field;
        let mut guard = self.cache.lock(self.field)?;
        let state = &mut *guard;
        if state.sight.as_ref().is_none_or(|s| s.cell_m() != cell_m) {
            state.sight = Some(FieldSight::new(cell_m));
            state.sight_behind = true;
        }
        let sight = state.sight.as_mut()?;
        if std::mem::take(&mut state.sight_behind) {
            sight.update(
                field
                    .blocks()
                    .filter(|(_, g)| g.phase != Phase::Gone)
                    .map(|(index, g)| (index, g.serial, &g.boxes)),
            );
        }
        let mut first: Option<(f64, f64, CloudType)> = None;
        let mut total = 0.0;
        // The generation of the last box met and its phase now (a box's neighbours along the
        // line are mostly of the same generation).
        let mut last: Option<(u64, Option<&FieldBlock>)> = None;
        let mut inside = std::mem::take(&mut state.inside);
        sight.crossed_before(qa, qb, whole, before, |(index, serial), bx, table, _, _| {
            let block = match last {
                Some((at, block)) if at == serial => block,
                _ => {
                    let block = field.generations(index).iter().find(|b| b.serial == serial);
                    last = Some((serial, block));
                    block
                }
            };
            let Some(block) = block else {
                return Met::Passed;
            };
            // The box is entered: the cloud's cores say where the line is in cloud.
            let cloud = &block.block.clouds[bx.cloud];
            // Its cores as the table lays them out, made the first time a line enters the box.
            let table = table.get_or_insert_with(|| {
                let runs = block.boxes.runs.get(bx.cloud).and_then(|r| r.as_deref());
                Box::new(core::CoreTable::of(cloud, runs))
            });
            let (a, b) = (qa - cloud.centre_m, qb - cloud.centre_m);
            #[cfg(test)]
            if STRAIGHT.get() {
                core::segment(cloud, a, b, &mut inside);
            } else {
                core::segment_in_table(cloud, table, a, b, &mut inside);
            }
            #[cfg(not(test))]
            core::segment_in_table(cloud, table, a, b, &mut inside);
            let mut entry: Option<f64> = None;
            let mut depth_here = 0.0;
            for &(t0, t1) in &inside {
                let mid = qa.lerp(qb, 0.5 * (t0 + t1));
                let fade = f64::from(self.fade(block, bx, mid));
                if fade <= 0.0 {
                    continue;
                }
                let depth = sigma * f64::from(cloud.optical_density) * (t1 - t0) * length * fade;
                depth_here += depth;
                entry.get_or_insert(t0);
                if let Some(spans) = spans.as_deref_mut() {
                    spans.push((t0, t1, depth, bx.cloud_type));
                }
            }
            let Some(t0) = entry else {
                return Met::Passed;
            };
            total += depth_here;
            if first.is_none_or(|f| t0 < f.0) {
                first = Some((t0, depth_here, bx.cloud_type));
            }
            if total >= enough {
                Met::Enough
            } else {
                Met::Counted(t0)
            }
        });
        state.inside = inside;
        first.map(|(t, depth, cloud_type)| SightHit {
            distance_m: t * length,
            point_m: a.lerp(b, t),
            optical_depth: depth,
            total_optical_depth: total,
            cloud_type,
            crossings: Vec::new(),
        })
    }
}

#[cfg(test)]
thread_local! {
    /// Whether this thread's lines of sight ask each cloud's sprites for its cores one by one
    /// (`core::segment`, the straightforward path) instead of its core table: the tests that
    /// the table gives every answer to the bit.
    pub(crate) static STRAIGHT: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// A stretch of one cloud's cores along a line of sight: t in, t out, optical depth, type.
pub(super) type Span = (f64, f64, f64, CloudType);

/// The stretches of cloud along a segment `length_m` long: the clouds' spans, those that
/// overlap joined (each typed by the cloud that gives it most depth).
pub(super) fn crossings(mut spans: Vec<Span>, length_m: f64) -> Vec<CloudCrossing> {
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<(CloudCrossing, f64)> = Vec::new();
    for (t0, t1, depth, cloud_type) in spans {
        let (entry_m, exit_m) = (t0 * length_m, t1 * length_m);
        match out.last_mut() {
            Some((c, most)) if entry_m <= c.exit_m => {
                c.exit_m = c.exit_m.max(exit_m);
                c.optical_depth += depth;
                if depth > *most {
                    *most = depth;
                    c.cloud_type = cloud_type;
                }
            }
            _ => out.push((
                CloudCrossing {
                    entry_m,
                    exit_m,
                    optical_depth: depth,
                    cloud_type,
                },
                depth,
            )),
        }
    }
    out.into_iter().map(|(c, _)| c).collect()
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

/// A multiplicative hash (the Fx hash of rustc) for the cache's small integer keys: the default
/// SipHash was a tenth of a line of sight's time.
#[derive(Debug, Default, Clone, Copy)]
struct BuildFast;

#[derive(Debug, Default)]
struct FastHasher(u64);

impl std::hash::BuildHasher for BuildFast {
    type Hasher = FastHasher;
    fn build_hasher(&self) -> FastHasher {
        FastHasher(0)
    }
}

impl std::hash::Hasher for FastHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
    fn write_i32(&mut self, x: i32) {
        self.write_u64(u64::from(x as u32));
    }
}

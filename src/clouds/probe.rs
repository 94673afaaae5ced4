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
//! ([`BoxCache`]). A point query looks only at the blocks within reach of the point, and skips
//! a block whose clouds' bounds are out of reach; a line of sight walks one grid over every box
//! of the field ([`SightBoxes`]), built again when the field's membership changes. Positions
//! are ground metres (east, north, up MSL); the field's drift is taken off to find the clouds.

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

/// The most cells a side of a [`BoxGrid`] has: 128 km at the shipped 500 m, more than a field
/// holds (`clouds.toml`'s radius plus a block each side); a coarser grid beyond that.
const GRID_MAX_SIDE: usize = 256;

/// Every cloud box of the field, the boxes of all its generations in one list, and one grid
/// over them all for lines of sight: a segment walks one grid, not one per generation.
#[derive(Debug)]
pub struct SightBoxes {
    /// Per box: its corners (the slab test reads only these, packed for the walk).
    corners: Vec<[DVec3; 2]>,
    /// Per box: the generation (an index into `generations`) and its box there.
    owners: Vec<(u32, u32)>,
    /// The generations' boxes, in the order `owners` counts them.
    generations: Vec<Arc<GenerationBoxes>>,
    /// Bounds of every box, air frame.
    lo_m: DVec3,
    /// See `lo_m`.
    hi_m: DVec3,
    /// The footprints of the boxes up to [`BIG_BOX_CELLS`] cells wide on a grid of the cells
    /// asked for, and of the bigger ones (a cumulonimbus, an anvil, a stratus deck) on one
    /// of cells [`BIG_BOX_CELLS`] times as wide: a big box listed in the fine cells filled
    /// them (a storm's 1,800 boxes were 140,000 entries, each rebuilt with the membership).
    grids: [BoxGrid; 2],
}

/// How many cells of the fine grid a box's footprint may span on a side before it goes to the
/// coarse grid of [`SightBoxes`] (whose cells are this many times as wide).
const BIG_BOX_CELLS: f64 = 8.0;

impl SightBoxes {
    /// One list and grid (cells of `cell_m`) over the boxes of `generations`.
    pub fn of(generations: Vec<Arc<GenerationBoxes>>, cell_m: f64) -> Self {
        let mut corners = Vec::new();
        let mut owners = Vec::new();
        for (g, boxes) in generations.iter().enumerate() {
            for (k, b) in boxes.boxes.iter().enumerate() {
                corners.push([b.centre_m - b.half_m, b.centre_m + b.half_m]);
                owners.push((g as u32, k as u32));
            }
        }
        let (lo_m, hi_m) = corners.iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(lo, hi), [a, z]| (lo.min(*a), hi.max(*z)),
        );
        let (big, small): (Vec<u32>, Vec<u32>) = (0..corners.len() as u32).partition(|&i| {
            let [a, z] = corners[i as usize];
            (z - a).truncate().max_element() > BIG_BOX_CELLS * cell_m
        });
        let grids = [
            BoxGrid::of(&corners, &big, cell_m * BIG_BOX_CELLS),
            BoxGrid::of(&corners, &small, cell_m),
        ];
        Self {
            corners,
            owners,
            generations,
            lo_m,
            hi_m,
            grids,
        }
    }

    /// How many boxes.
    pub fn len(&self) -> usize {
        self.corners.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.corners.is_empty()
    }

    /// The boxes the segment `a..b` enters, each once, nearest cells first:
    /// `hit(generation, box, t in, t out)` says whether it counts (a faded-out cloud does not)
    /// and whether the walk has met enough. With `whole` false it also stops once no box left
    /// can be entered before the nearest counted one. `seen` is scratch, one entry per box, and `stamp` a number it does not hold yet (a
    /// box is tested the first time a cell lists it, and marked with the stamp: a big box is
    /// listed in many cells).
    fn crossed(
        &self,
        a: DVec3,
        b: DVec3,
        whole: bool,
        seen: &mut [u32],
        stamp: u32,
        mut hit: impl FnMut(usize, &CloudBox, f64, f64) -> Met,
    ) {
        let Some((from, to)) = slab(a, b, self.lo_m, self.hi_m) else {
            return;
        };
        let mut best = f64::INFINITY;
        let mut enough = false;
        // The big boxes first, then the small ones with the nearest big one's entry to beat.
        // In each grid, once the nearest entry is before the cell is left, no box not yet met
        // can be entered earlier (its entry point lies in a later cell, which lists it).
        for grid in &self.grids {
            if enough {
                return;
            }
            grid.walk(a, b, from, to, |list, _, cell_out| {
                for &index in list {
                    let index = index as usize;
                    if seen[index] == stamp {
                        continue;
                    }
                    seen[index] = stamp;
                    let [lo, hi] = self.corners[index];
                    let Some((t0, t1)) = slab(a, b, lo, hi) else {
                        continue;
                    };
                    if !whole && t0 >= best {
                        continue;
                    }
                    let (g, k) = self.owners[index];
                    let bx = &self.generations[g as usize].boxes[k as usize];
                    match hit(g as usize, bx, t0, t1) {
                        Met::Passed => {}
                        Met::Counted => best = best.min(t0),
                        Met::Enough => {
                            enough = true;
                            return false;
                        }
                    }
                }
                whole || best >= cell_out
            });
        }
    }
}

/// What a box a line of sight enters is to the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Met {
    /// It does not count (a faded-out cloud).
    Passed,
    /// It counts.
    Counted,
    /// It counts, and the walk has what it wants: it stops.
    Enough,
}

/// A uniform horizontal grid over boxes: each cell lists the boxes whose footprint (padded by a
/// metre against rounding) overlaps it, with the lowest bottom and highest top of them, so a
/// segment walked through the cells it crosses (Amanatides and Woo 1987, "A fast voxel
/// traversal algorithm for ray tracing") tests only the boxes near it, nearest cells first, and
/// passes over a cell it crosses above or below all of them.
#[derive(Debug)]
struct BoxGrid {
    /// South-west corner, air frame metres.
    origin_m: DVec2,
    /// Cell side, metres.
    cell_m: f64,
    /// Cells east and north.
    nx: usize,
    ny: usize,
    /// Where each cell's list starts in `items` (`nx * ny + 1` entries).
    starts: Vec<u32>,
    /// Box indices, cell after cell.
    items: Vec<u32>,
    /// Per cell: the lowest bottom and highest top of its boxes, metres (none: +inf, -inf).
    heights_m: Vec<[f64; 2]>,
}

impl BoxGrid {
    /// The grid over the boxes `indices` of `corners`.
    fn of(corners: &[[DVec3; 2]], indices: &[u32], cell_m: f64) -> Self {
        let pad = DVec2::splat(1.0);
        let mut lo = DVec2::splat(f64::MAX);
        let mut hi = DVec2::splat(f64::MIN);
        for [a, z] in indices.iter().map(|&i| &corners[i as usize]) {
            lo = lo.min(a.truncate() - pad);
            hi = hi.max(z.truncate() + pad);
        }
        if indices.is_empty() {
            (lo, hi) = (DVec2::ZERO, DVec2::ONE);
        }
        let size = hi - lo;
        let cell_m = cell_m
            .max(size.max_element() / GRID_MAX_SIDE as f64)
            .max(1.0);
        let nx = ((size.x / cell_m).ceil() as usize).clamp(1, GRID_MAX_SIDE);
        let ny = ((size.y / cell_m).ceil() as usize).clamp(1, GRID_MAX_SIDE);
        let cells = |[a, z]: &[DVec3; 2]| {
            let a = (a.truncate() - pad - lo) / cell_m;
            let z = (z.truncate() + pad - lo) / cell_m;
            let clamp = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n - 1);
            (
                clamp(a.x, nx)..=clamp(z.x, nx),
                clamp(a.y, ny)..=clamp(z.y, ny),
            )
        };
        // Counted, then filled: one allocation for every list.
        let mut counts = vec![0u32; nx * ny + 1];
        let mut heights_m = vec![[f64::INFINITY, f64::NEG_INFINITY]; nx * ny];
        for c in indices.iter().map(|&i| &corners[i as usize]) {
            let (xs, ys) = cells(c);
            for y in ys {
                for x in xs.clone() {
                    counts[y * nx + x + 1] += 1;
                    let h = &mut heights_m[y * nx + x];
                    *h = [h[0].min(c[0].z), h[1].max(c[1].z)];
                }
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let starts = counts.clone();
        let mut items = vec![0u32; counts[nx * ny] as usize];
        for &index in indices {
            let (xs, ys) = cells(&corners[index as usize]);
            for y in ys {
                for x in xs.clone() {
                    let at = &mut counts[y * nx + x];
                    items[*at as usize] = index;
                    *at += 1;
                }
            }
        }
        Self {
            origin_m: lo,
            cell_m,
            nx,
            ny,
            starts,
            items,
            heights_m,
        }
    }

    /// Walks the cells the segment `a + t (b - a)` crosses for t in `t_from..=t_to`, in order:
    /// `visit(boxes of the cell, t entering it, t leaving it)`, the first cell entered at
    /// minus infinity and the last left at plus infinity (so every t belongs to one cell), no
    /// boxes where the segment passes above or below them all; stops when `visit` says false.
    fn walk(
        &self,
        a: DVec3,
        b: DVec3,
        t_from: f64,
        t_to: f64,
        mut visit: impl FnMut(&[u32], f64, f64) -> bool,
    ) {
        let (a2, d) = (a.truncate(), (b - a).truncate());
        let dz = b.z - a.z;
        let hi = self.origin_m + DVec2::new(self.nx as f64, self.ny as f64) * self.cell_m;
        // The part of the segment over the grid.
        let Some((t0, t1)) = slab(
            a2.extend(0.0),
            (a2 + d).extend(0.0),
            self.origin_m.extend(-1.0),
            hi.extend(1.0),
        ) else {
            return;
        };
        let (t0, t1) = (t0.max(t_from), t1.min(t_to));
        if t0 > t1 {
            return;
        }
        let start = (a2 + d * t0 - self.origin_m) / self.cell_m;
        let mut cell = [
            (start.x.floor().max(0.0) as usize).min(self.nx - 1) as i64,
            (start.y.floor().max(0.0) as usize).min(self.ny - 1) as i64,
        ];
        let n = [self.nx as i64, self.ny as i64];
        let mut step = [0i64; 2];
        let mut next = [f64::INFINITY; 2];
        let mut delta = [f64::INFINITY; 2];
        for k in 0..2 {
            if d[k].abs() > 1e-12 {
                step[k] = if d[k] > 0.0 { 1 } else { -1 };
                let edge =
                    self.origin_m[k] + (cell[k] + i64::from(d[k] > 0.0)) as f64 * self.cell_m;
                next[k] = (edge - a2[k]) / d[k];
                delta[k] = self.cell_m / d[k].abs();
            }
        }
        let mut enter = f64::NEG_INFINITY;
        loop {
            let k = usize::from(next[1] < next[0]);
            let last = next[k] >= t1 || !(0..n[k]).contains(&(cell[k] + step[k]));
            let leave = if last { f64::INFINITY } else { next[k] };
            let c = cell[1] as usize * self.nx + cell[0] as usize;
            // The heights the segment has over the cell (a metre's margin, as the footprints).
            let (z0, z1) = (a.z + dz * enter.max(t0), a.z + dz * leave.min(t1));
            let [bottom, top] = self.heights_m[c];
            let list = if z0.max(z1) + 1.0 < bottom || z0.min(z1) - 1.0 > top {
                &[][..]
            } else {
                &self.items[self.starts[c] as usize..self.starts[c + 1] as usize]
            };
            if !visit(list, enter, leave) || last {
                return;
            }
            enter = leave;
            cell[k] += step[k];
            next[k] += delta[k];
        }
    }
}

/// The boxes of the generations asked about, by serial; per block the generations with the
/// bounds of them all; and every box of the field in one grid for lines of sight: shared by the
/// queries of a frame. The per-block lists and the grid hold while the field's membership
/// ([`CloudField::membership`]) does: a point query then looks a block up once and passes over
/// it on its bounds, without the field's own look-ups, and a line of sight walks one grid.
#[derive(Debug, Default)]
pub struct BoxCache {
    state: Mutex<CacheState>,
}

#[derive(Debug, Default)]
struct CacheState {
    /// Boxes by generation serial.
    boxes: HashMap<u64, Arc<GenerationBoxes>, BuildFast>,
    /// The field (its address) and membership the block lists and the grid are of.
    key: Option<(usize, u64)>,
    /// Per block: the generations' serials and boxes, and the bounds of them all.
    blocks: HashMap<BlockIndex, BlockBoxes, BuildFast>,
    /// Every box of the field with its grid, built the first time a line of sight asks
    /// (`None` after the membership changed), and the cell size asked for.
    sight: Option<(f64, SightOf)>,
    /// Scratch for [`SightBoxes::crossed`]: the stamp of the last line of sight that met each
    /// box, and the stamp of the last line.
    seen: Vec<u32>,
    stamp: u32,
}

/// The field's boxes in one grid, with the generations they are of (block and serial, to find
/// their phase now).
#[derive(Debug)]
struct SightOf {
    boxes: SightBoxes,
    generations: Vec<(BlockIndex, u64)>,
}

#[derive(Debug)]
struct BlockBoxes {
    lo_m: DVec3,
    hi_m: DVec3,
    generations: Vec<(u64, Arc<GenerationBoxes>)>,
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

impl BoxCache {
    /// Forgets the generations the field no longer holds, once it holds many more than it has,
    /// and the block lists when its membership changed.
    fn prune(&self, field: &CloudField) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        let key = (std::ptr::from_ref(field) as usize, field.membership());
        if state.key != Some(key) {
            state.key = Some(key);
            state.blocks.clear();
            state.sight = None;
        }
        if state.boxes.len() > 2 * field.block_count() + 64 {
            let live: std::collections::HashSet<u64> =
                field.blocks().map(|(_, g)| g.serial).collect();
            state.boxes.retain(|serial, _| live.contains(serial));
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
    /// clouds that overhang it) and whose clouds' bounds pass `near`, as `keep` makes of it
    /// and its boxes (`None`: left out). The cache is locked once for the query.
    fn generations<T>(
        &self,
        lo: DVec2,
        hi: DVec2,
        reach_m: f64,
        wanted: impl Fn(DVec2, DVec2) -> bool,
        near: impl Fn(DVec3, DVec3) -> bool,
        mut keep: impl FnMut(&'a FieldBlock, &Arc<GenerationBoxes>) -> Option<T>,
    ) -> Vec<T> {
        // Clouds overhang their block by up to a block.
        let pad = reach_m + BLOCK_SIZE_M;
        let a = BlockIndex::containing(lo - DVec2::splat(pad));
        let b = BlockIndex::containing(hi + DVec2::splat(pad));
        let field: &'a CloudField = self.field;
        let mut out = Vec::new();
        let Ok(mut guard) = self.cache.state.lock() else {
            return out;
        };
        let state = &mut *guard;
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
                let entry = state.blocks.entry(index).or_insert_with(|| {
                    let mut lo = DVec3::splat(f64::MAX);
                    let mut hi = DVec3::splat(f64::MIN);
                    let generations = field
                        .generations(index)
                        .iter()
                        .filter(|g| g.phase != Phase::Gone && !g.block.clouds.is_empty())
                        .map(|g| {
                            let boxes =
                                Arc::clone(state.boxes.entry(g.serial).or_insert_with(|| {
                                    Arc::new(GenerationBoxes::of(&g.block.clouds))
                                }));
                            if !boxes.boxes.is_empty() {
                                lo = lo.min(boxes.lo_m);
                                hi = hi.max(boxes.hi_m);
                            }
                            (g.serial, boxes)
                        })
                        .collect();
                    BlockBoxes {
                        lo_m: lo,
                        hi_m: hi,
                        generations,
                    }
                });
                if entry.generations.is_empty() || !near(entry.lo_m, entry.hi_m) {
                    continue;
                }
                let live = field.generations(index);
                for (serial, boxes) in &entry.generations {
                    if let Some(g) = live.iter().find(|g| g.serial == *serial)
                        && let Some(kept) = keep(g, boxes)
                    {
                        out.push(kept);
                    }
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
        let near = |lo: DVec3, hi: DVec3| {
            let (c, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
            ((q - c).abs() - h).max(DVec3::ZERO).length() <= reach
        };
        let keep = |g, b: &Arc<GenerationBoxes>| Some((g, Arc::clone(b)));
        for (g, boxes) in self.generations(q.truncate(), q.truncate(), reach, all, near, keep) {
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
        self.sight(a, b, true, f64::INFINITY)
    }

    /// The optical depth through the clouds along the segment from ground point `a` to `b`,
    /// walked only until it reaches `enough`: then at least that (the sun's occlusion, which
    /// `1 - exp(-depth)` makes 1 to within `exp(-enough)`, needs no more, and a ray up through
    /// a storm would cross hundreds of boxes beyond). 0 in clear air.
    pub fn optical_depth_until(&self, a: DVec3, b: DVec3, enough: f64) -> f64 {
        self.sight(a, b, true, enough)
            .map_or(0.0, |hit| hit.total_optical_depth)
    }

    /// The first cloud met along the segment and the optical depth through it; its
    /// `total_optical_depth` counts only the clouds looked at before the first was certain (the
    /// cheap query a host casts many of).
    pub fn first_cloud(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        self.sight(a, b, false, f64::INFINITY)
    }

    /// The walk of [`Self::line_of_sight`] (`whole`) or [`Self::first_cloud`], stopped once the
    /// optical depth counted reaches `enough`.
    fn sight(&self, a: DVec3, b: DVec3, whole: bool, enough: f64) -> Option<SightHit> {
        let (qa, qb) = (self.air_point(a), self.air_point(b));
        let length = (qb - qa).length();
        let sigma = 3.0 / f64::from(self.settings.visibility_m);
        let cell_m = self.settings.grid_cell_m;
        let field = self.field;
        let Ok(mut guard) = self.cache.state.lock() else {
            return None;
        };
        let state = &mut *guard;
        if state.sight.as_ref().is_none_or(|s| s.0 != cell_m) {
            let sight = sight_of(field, &mut state.boxes, cell_m);
            state.seen = vec![0; sight.boxes.len()];
            state.stamp = 0;
            state.sight = Some((cell_m, sight));
        }
        let Some((_, sight)) = &state.sight else {
            return None;
        };
        state.stamp = state.stamp.wrapping_add(1);
        if state.stamp == 0 {
            state.seen.fill(0);
            state.stamp = 1;
        }
        let mut first: Option<(f64, f64, CloudType)> = None;
        let mut total = 0.0;
        // The generation of the last box met and its phase now (a box's neighbours along the
        // line are mostly of the same generation).
        let mut last: Option<(usize, Option<&FieldBlock>)> = None;
        sight.boxes.crossed(
            qa,
            qb,
            whole,
            &mut state.seen,
            state.stamp,
            |g, bx, t0, t1| {
                let block = match last {
                    Some((at, block)) if at == g => block,
                    _ => {
                        let (index, serial) = sight.generations[g];
                        let block = field.generations(index).iter().find(|b| b.serial == serial);
                        last = Some((g, block));
                        block
                    }
                };
                let Some(block) = block else {
                    return Met::Passed;
                };
                let mid = qa.lerp(qb, 0.5 * (t0 + t1));
                let fade = f64::from(self.fade(block, bx, mid));
                if fade <= 0.0 {
                    return Met::Passed;
                }
                let depth = sigma * (t1 - t0) * length * fade;
                total += depth;
                if first.is_none_or(|f| t0 < f.0) {
                    first = Some((t0, depth, bx.cloud_type));
                }
                if total >= enough {
                    Met::Enough
                } else {
                    Met::Counted
                }
            },
        );
        first.map(|(t, depth, cloud_type)| SightHit {
            distance_m: t * length,
            point_m: a.lerp(b, t),
            optical_depth: depth,
            total_optical_depth: total,
            cloud_type,
        })
    }
}

/// Every box of the living generations of `field` (their boxes from `boxes`, worked out there
/// the first time) in one grid of cells of `cell_m`.
fn sight_of(
    field: &CloudField,
    boxes: &mut HashMap<u64, Arc<GenerationBoxes>, BuildFast>,
    cell_m: f64,
) -> SightOf {
    let mut generations = Vec::new();
    let mut all = Vec::new();
    for (index, g) in field.blocks() {
        if g.phase == Phase::Gone || g.block.clouds.is_empty() {
            continue;
        }
        let b = boxes
            .entry(g.serial)
            .or_insert_with(|| Arc::new(GenerationBoxes::of(&g.block.clouds)));
        if b.boxes.is_empty() {
            continue;
        }
        generations.push((index, g.serial));
        all.push(Arc::clone(b));
    }
    SightOf {
        boxes: SightBoxes::of(all, cell_m),
        generations,
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

    /// The grid a line of sight walks finds what testing every box finds: on 300 clouds of
    /// random size and place in three generations (overlapping) and 3,000 segments (level,
    /// upright, axis-aligned, starting inside and outside the clouds, grazing a box's top),
    /// every box entered is met exactly once, and the nearest entry (the first cloud) is the
    /// same, for a fine, the shipped and a coarse grid.
    #[test]
    fn the_grid_meets_every_box_a_segment_enters_once_and_the_nearest_first() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let generations: Vec<Arc<GenerationBoxes>> = (0..3)
            .map(|_| {
                let clouds: Vec<Cloud> = (0..100)
                    .map(|_| {
                        let c = DVec3::new(
                            rand() * 12_000.0 - 2_000.0,
                            rand() * 8_000.0,
                            500.0 + rand() * 2_500.0,
                        );
                        let half = (30.0 + rand() * 1_500.0 * rand()) as f32;
                        cube_cloud(c, half, CloudType::CumulusMediocris)
                    })
                    .collect();
                Arc::new(GenerationBoxes::of(&clouds))
            })
            .collect();
        let every: Vec<(usize, &CloudBox)> = generations
            .iter()
            .enumerate()
            .flat_map(|(g, b)| b.boxes.iter().map(move |bx| (g, bx)))
            .collect();
        let mut met_first = 0;
        let mut stamp = 0;
        for cell_m in [120.0, 500.0, 4_000.0] {
            let sight = SightBoxes::of(generations.clone(), cell_m);
            assert_eq!(sight.len(), 300);
            let mut seen = vec![0; sight.len()];
            for k in 0..3_000 {
                let mut a = DVec3::new(
                    rand() * 16_000.0 - 4_000.0,
                    rand() * 12_000.0 - 2_000.0,
                    rand() * 3_500.0,
                );
                let mut b = a + DVec3::new(
                    (rand() - 0.5) * 20_000.0,
                    (rand() - 0.5) * 20_000.0,
                    (rand() - 0.5) * 3_000.0,
                );
                match k % 7 {
                    0 => b.z = a.z,
                    1 => b = a.with_z(a.z + 3_000.0),
                    2 => b.x = a.x,
                    3 => a = every[k % every.len()].1.centre_m,
                    // Level, grazing a box's top: the cells' heights must hold it.
                    4 => {
                        let bx = every[k % every.len()].1;
                        a.z = bx.centre_m.z + bx.half_m.z - 0.5;
                        b.z = a.z;
                    }
                    _ => {}
                }
                let mut all: Vec<(f64, usize, usize)> = every
                    .iter()
                    .filter_map(|(g, bx)| bx.segment(a, b).map(|(t0, _)| (t0, *g, bx.cloud)))
                    .collect();
                all.sort_by_key(|x| (x.1, x.2));
                let mut met = Vec::new();
                stamp += 1;
                sight.crossed(a, b, true, &mut seen, stamp, |g, bx, t0, _| {
                    met.push((t0, g, bx.cloud));
                    Met::Counted
                });
                met.sort_by_key(|x| (x.1, x.2));
                assert_eq!(met, all, "cell {cell_m} m, segment {k}: {a} to {b}");
                // A walk that has enough after its first box meets no other, in any grid.
                let mut walked = 0;
                stamp += 1;
                sight.crossed(a, b, true, &mut seen, stamp, |_, _, _, _| {
                    walked += 1;
                    Met::Enough
                });
                assert_eq!(walked, all.len().min(1), "cell {cell_m} m, segment {k}");
                let nearest = all.iter().map(|h| h.0).fold(f64::INFINITY, f64::min);
                let mut first = f64::INFINITY;
                stamp += 1;
                sight.crossed(a, b, false, &mut seen, stamp, |_, _, t0, _| {
                    first = first.min(t0);
                    Met::Counted
                });
                assert_eq!(first, nearest, "cell {cell_m} m, segment {k}");
                met_first += nearest.is_finite() as usize;
            }
        }
        // Both kinds of segment were asked about.
        assert!((1_000..8_000).contains(&met_first), "{met_first}");
    }
}

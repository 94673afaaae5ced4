//! Lines of sight through the field's cloud boxes, on the CPU, for every frame.
//!
//! The field's blocks are cut into square tiles of [`TILE_BLOCKS`] blocks a side. Each tile
//! holds the boxes of its blocks' generations in grids ([`SightBoxes`]), built the first time a
//! line of sight enters the tile's bounds; a grid of the tiles' bounds above them says which
//! tiles a segment crosses, nearest first. When the field's membership changes, a generation
//! that joins a tile gets a grid of its own beside the tile's when a line first comes near (a
//! part; at [`MAX_PARTS`] the tile is built whole again), and blocks join at the field's rim,
//! tens of kilometres from where a host looks. A generation that went is passed over where it
//! lies (the walk asks the field for its phase and finds none) until half a tile's boxes are of
//! gone generations: then the tile is made anew. Building the whole field's grid again on every
//! change was 2 to 3 ms on the frame after each arrival (the cruise).
//!
//! Every box entered is met once, whatever tile or cell lists it; a walk that wants only the
//! first cloud stops once no tile, cell or box left can be entered before the nearest one met
//! (Amanatides and Woo 1987, "A fast voxel traversal algorithm for ray tracing", at both levels).

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::boxes::{CloudBox, Cull, GenerationBoxes, slab};
use super::core::CoreTable;
use crate::weather::{BLOCK_SIZE_M, BlockIndex};

/// Blocks a side of a tile of [`FieldSight`]: 16 km, so a 10 km line crosses a tile or two and
/// a tile made anew holds 16 blocks, not the field's hundreds.
const TILE_BLOCKS: i32 = 4;

/// A generation a line of sight may meet: its block, its serial, and its boxes.
pub(super) type SightMember = (BlockIndex, u64, Arc<GenerationBoxes>);

/// A [`SightMember`] as the field holds it: its boxes borrowed, shared only by a tile that
/// takes it in (a membership change of the Cb circle's thousands of generations cloned every
/// one's boxes, a cache miss each).
pub(super) type LivingMember<'a> = (BlockIndex, u64, &'a Arc<GenerationBoxes>);

/// `member` with its boxes shared.
fn shared((index, serial, boxes): LivingMember<'_>) -> SightMember {
    (index, serial, Arc::clone(boxes))
}

/// The boxes of a field's generations in tiles, for lines of sight. See the module docs.
#[derive(Debug)]
pub(super) struct FieldSight {
    /// The cell of the tiles' grids, metres.
    cell_m: f64,
    /// The tiles, west to east and south to north (the order the walk meets a cell's tiles in
    /// does not depend on how the field was built).
    tiles: Vec<Tile>,
    /// Per tile, in the order of `tiles`: what a line of sight reads of every tile the grid
    /// cells it crosses list (bounds, and whether it walked the tile already), packed apart
    /// from the tiles (a walk read three or four tiles' bounds to enter one).
    heads: Vec<TileHead>,
    /// A grid over the tiles' bounds, cells a tile wide.
    top: BoxGrid,
    /// The last line of sight's stamp (see [`SightBoxes::crossed`]).
    stamp: u32,
}

/// The generations of one tile, with their boxes in grids once a line of sight comes near.
#[derive(Debug)]
struct Tile {
    /// Which tile: its south-west block's index divided by [`TILE_BLOCKS`].
    key: (i32, i32),
    /// Bounds of its generations' boxes, air frame.
    lo_m: DVec3,
    hi_m: DVec3,
    /// The generations: block, serial and boxes, in the order the parts count them.
    members: Vec<SightMember>,
    /// Its boxes in grids, built the first time a line of sight enters its bounds (the field's
    /// rim, where blocks come and go as the camera flies on, is seldom looked along): one part
    /// over the members it had then, and one over each batch that joined after (a tile around
    /// the aircraft in a changing sky is not built again whole for every generation that
    /// forms in it), until there are [`MAX_PARTS`].
    parts: Vec<Part>,
    /// How many of `members` the parts hold (the first ones).
    in_parts: usize,
    /// The serials of `members`, sorted, with how many boxes each has.
    serials: Vec<(u64, usize)>,
    /// How many boxes it holds, living or not.
    box_count: usize,
}

/// A tile's bounds (its [`Tile::lo_m`] and [`Tile::hi_m`]) and the stamp of the last line of
/// sight that walked it.
#[derive(Debug, Clone, Copy)]
struct TileHead {
    lo_m: DVec3,
    hi_m: DVec3,
    walked: u32,
}

/// Some of a tile's members' boxes in one grid.
#[derive(Debug)]
struct Part {
    boxes: SightBoxes,
    /// Which member its first generation is (its generations are the members from there).
    first: usize,
    /// Per box: the stamp of the last line of sight that tested it.
    seen: Vec<u32>,
    /// Per box: its cloud's cores laid out for lines of sight, made the first time a line
    /// enters the box (and dropped with the part).
    tables: Vec<Option<Box<CoreTable>>>,
}

/// The most parts a tile has: one more is built with all the others, whole.
const MAX_PARTS: usize = 4;

/// The bounds of the boxes of `members` (a generation's own bounds hold its sprites' spheres,
/// kilometres wider for a heap's, so that a line of sight near a tile's edge walks the tile
/// beside it only where a box reaches over).
fn box_bounds(members: &[SightMember]) -> (DVec3, DVec3) {
    members.iter().flat_map(|m| m.2.boxes.iter()).fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), b| (lo.min(b.centre_m - b.half_m), hi.max(b.centre_m + b.half_m)),
    )
}

impl Tile {
    fn of(key: (i32, i32), members: Vec<SightMember>) -> Self {
        let mut serials: Vec<(u64, usize)> =
            members.iter().map(|m| (m.1, m.2.boxes.len())).collect();
        serials.sort_unstable();
        let (lo_m, hi_m) = box_bounds(&members);
        Self {
            key,
            lo_m,
            hi_m,
            box_count: serials.iter().map(|s| s.1).sum(),
            members,
            parts: Vec::new(),
            in_parts: 0,
            serials,
        }
    }

    /// Takes in `members`, the tile's generations now, if it can: the ones it does not hold
    /// join it (a part of their own once a line comes near), the ones gone are passed over
    /// where they lie; not when more of its boxes would be gone than living. Returns whether
    /// it did, and whether any joined.
    fn take<'a>(&mut self, members: Vec<LivingMember<'a>>) -> Result<bool, Vec<LivingMember<'a>>> {
        let mut living_boxes = 0;
        let mut joined = 0;
        for m in &members {
            match self.serials.binary_search_by_key(&m.1, |s| s.0) {
                Ok(k) => living_boxes += self.serials[k].1,
                // A generation without boxes is never met (only a joining one is looked at).
                Err(_) => joined += usize::from(!m.2.boxes.is_empty()),
            }
        }
        if 2 * living_boxes < self.box_count {
            return Err(members);
        }
        if joined == 0 {
            return Ok(false);
        }
        let known = self.serials.clone();
        for m in members {
            if known.binary_search_by_key(&m.1, |s| s.0).is_err() && !m.2.boxes.is_empty() {
                let m = shared(m);
                self.serials.push((m.1, m.2.boxes.len()));
                self.box_count += m.2.boxes.len();
                let (lo, hi) = box_bounds(std::slice::from_ref(&m));
                self.lo_m = self.lo_m.min(lo);
                self.hi_m = self.hi_m.max(hi);
                self.members.push(m);
            }
        }
        self.serials.sort_unstable();
        Ok(true)
    }

    /// Builds the parts a line of sight needs: the members not in one yet.
    fn build(&mut self, cell_m: f64) {
        if self.in_parts == self.members.len() {
            return;
        }
        if self.parts.len() >= MAX_PARTS {
            self.parts.clear();
            self.in_parts = 0;
        }
        let first = self.in_parts;
        let boxes = SightBoxes::of(
            self.members[first..]
                .iter()
                .map(|m| Arc::clone(&m.2))
                .collect(),
            cell_m,
        );
        self.parts.push(Part {
            seen: vec![0; boxes.len()],
            tables: vec![None; boxes.len()],
            boxes,
            first,
        });
        self.in_parts = self.members.len();
    }
}

impl FieldSight {
    /// No tiles yet, with grids of cells of `cell_m`.
    pub(super) fn new(cell_m: f64) -> Self {
        Self {
            cell_m,
            tiles: Vec::new(),
            heads: Vec::new(),
            top: BoxGrid::of(&[], &[], 1.0),
            stamp: 0,
        }
    }

    /// The cell of the tiles' grids, metres.
    pub(super) fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// Brings the tiles up to the generations that can be met now (their boxes not empty): a
    /// generation that joins a tile is added to it (a grid of its own, when a line of sight first
    /// comes near), one that went is passed over where it lies, and a tile that would hold more
    /// gone boxes than living ones is made anew; returns how many tiles changed.
    pub(super) fn update<'a>(
        &mut self,
        living: impl IntoIterator<Item = LivingMember<'a>>,
    ) -> usize {
        let mut by_tile: BTreeMap<(i32, i32), Vec<LivingMember<'a>>> = BTreeMap::new();
        for member in living {
            let key = (
                member.0.i.div_euclid(TILE_BLOCKS),
                member.0.j.div_euclid(TILE_BLOCKS),
            );
            by_tile.entry(key).or_default().push(member);
        }
        let mut old: HashMap<(i32, i32), Tile> =
            self.tiles.drain(..).map(|tile| (tile.key, tile)).collect();
        let mut changed = 0;
        for (key, members) in by_tile {
            let kept = match old.remove(&key) {
                Some(mut tile) => tile.take(members).map(|joined| (joined, tile)),
                None => Err(members),
            };
            let tile = match kept {
                Ok((joined, tile)) => {
                    changed += usize::from(joined);
                    tile
                }
                Err(members) => {
                    let members: Vec<SightMember> = (members.into_iter())
                        .filter(|m| !m.2.boxes.is_empty())
                        .map(shared)
                        .collect();
                    if members.is_empty() {
                        continue;
                    }
                    changed += 1;
                    Tile::of(key, members)
                }
            };
            self.tiles.push(tile);
        }
        let corners: Vec<[DVec3; 2]> = self.tiles.iter().map(|t| [t.lo_m, t.hi_m]).collect();
        self.heads = (self.tiles.iter())
            .map(|t| TileHead {
                lo_m: t.lo_m,
                hi_m: t.hi_m,
                walked: 0,
            })
            .collect();
        let all: Vec<u32> = (0..corners.len() as u32).collect();
        let tile_m = f64::from(TILE_BLOCKS) * BLOCK_SIZE_M;
        self.top = BoxGrid::of(&corners, &all, tile_m);
        changed
    }

    /// How many tiles have grids built (a line of sight came near them), and how many parts.
    #[cfg(test)]
    fn tiles_built(&self) -> (usize, usize) {
        let built = self.tiles.iter().filter(|t| !t.parts.is_empty());
        (built.clone().count(), built.map(|t| t.parts.len()).sum())
    }

    /// The boxes the segment `a..b` (air frame) enters, each once, nearest tiles and cells
    /// first: `hit((block, serial), box, t in, t out)` says whether it counts and whether the
    /// walk has met enough. With `whole` false the walk stops once no box left can be entered
    /// before the nearest counted one.
    #[cfg(test)]
    pub(super) fn crossed(
        &mut self,
        a: DVec3,
        b: DVec3,
        whole: bool,
        mut hit: impl FnMut((BlockIndex, u64), &CloudBox, f64, f64) -> Met,
    ) {
        self.crossed_before(a, b, whole, f64::INFINITY, |m, bx, _, t0, t1| {
            hit(m, bx, t0, t1)
        });
    }

    /// [`Self::crossed`], the walk that wants only the first cloud (`whole` false) told that
    /// one was met at t = `before` already (another drift band's): a box entered at or after it
    /// is passed over, as one entered after a counted box is. A box entered before it is met as
    /// without it, so the first cloud met before `before` is the same. `hit` is also handed the
    /// box's slot for its cloud's core table, empty until it fills it.
    pub(super) fn crossed_before(
        &mut self,
        a: DVec3,
        b: DVec3,
        whole: bool,
        before: f64,
        mut hit: impl FnMut((BlockIndex, u64), &CloudBox, &mut Option<Box<CoreTable>>, f64, f64) -> Met,
    ) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            for tile in &mut self.tiles {
                for part in &mut tile.parts {
                    part.seen.fill(0);
                }
            }
            for head in &mut self.heads {
                head.walked = 0;
            }
            self.stamp = 1;
        }
        let stamp = self.stamp;
        let mut walk = Walk::new(whole);
        if !whole {
            walk.best = before;
        }
        let cell_m = self.cell_m;
        let cull = Cull::new(a, b);
        let (tiles, heads) = (&mut self.tiles, &mut self.heads);
        self.top
            .walk(a, b, (0.0, 1.0), walk.horizon(), |list, _, _| {
                for &t in list {
                    let head = &mut heads[t as usize];
                    if head.walked == stamp {
                        continue;
                    }
                    head.walked = stamp;
                    // The grid cell lists every tile its square overlaps: only one whose bounds
                    // the segment may enter (soon enough) is built and walked (its parts test
                    // their own bounds, which it holds, exactly).
                    if !cull.may_enter(head.lo_m, head.hi_m, walk.horizon()) {
                        continue;
                    }
                    let tile = &mut tiles[t as usize];
                    tile.build(cell_m);
                    let members = &tile.members;
                    for part in &mut tile.parts {
                        let first = part.first;
                        let scratch = (&mut part.seen[..], &mut part.tables[..], stamp);
                        part.boxes
                            .crossed(a, b, &mut walk, scratch, |g, bx, table, t0, t1| {
                                let m = &members[first + g];
                                hit((m.0, m.1), bx, table, t0, t1)
                            });
                        if walk.enough {
                            return f64::NEG_INFINITY;
                        }
                    }
                }
                // A tile not walked yet is entered in a later cell, which lists it.
                walk.horizon()
            });
    }
}

/// The most cells a side of a [`BoxGrid`] has: 128 km at the shipped 500 m, more than a tile
/// of the field holds; a coarser grid beyond that.
const GRID_MAX_SIDE: usize = 256;

/// The cloud boxes of some generations (a tile of the field's blocks) in one list, with one
/// grid over them all for lines of sight: a segment walks one grid, not one per generation.
#[derive(Debug)]
struct SightBoxes {
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
    fn of(generations: Vec<Arc<GenerationBoxes>>, cell_m: f64) -> Self {
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
    fn len(&self) -> usize {
        self.corners.len()
    }

    /// The boxes the segment `a..b` enters, each once, nearest cells first:
    /// `hit(generation, box, t in, t out)` says whether it counts (a faded-out cloud does not)
    /// and whether the walk has met enough. A walk that is not `whole` also stops once no box
    /// left can be entered before the nearest counted one (`walk` carries that entry from the
    /// grids walked before). `seen` is scratch, one entry per box, and `stamp` a number it does
    /// not hold yet (a box is tested the first time a cell lists it, and marked with the stamp:
    /// a big box is listed in many cells); `tables` holds a slot per box that `hit` is handed.
    fn crossed(
        &self,
        a: DVec3,
        b: DVec3,
        walk: &mut Walk,
        (seen, tables, stamp): (&mut [u32], &mut [Option<Box<CoreTable>>], u32),
        mut hit: impl FnMut(usize, &CloudBox, &mut Option<Box<CoreTable>>, f64, f64) -> Met,
    ) {
        let Some((from, to)) = slab(a, b, self.lo_m, self.hi_m) else {
            return;
        };
        if !walk.whole && from >= walk.best {
            return;
        }
        // The big boxes first, then the small ones with the nearest big one's entry to beat.
        // In each grid, once the nearest entry is before the cell is left, no box not yet met
        // can be entered earlier (its entry point lies in a later cell, which lists it).
        for grid in &self.grids {
            if walk.enough {
                return;
            }
            grid.walk(a, b, (from, to), walk.horizon(), |list, _, _| {
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
                    if !walk.whole && t0 >= walk.best {
                        continue;
                    }
                    let (g, k) = self.owners[index];
                    let bx = &self.generations[g as usize].boxes[k as usize];
                    match hit(g as usize, bx, &mut tables[index], t0, t1) {
                        Met::Passed => {}
                        Met::Counted(entry) => walk.best = walk.best.min(entry),
                        Met::Enough => {
                            walk.enough = true;
                            return f64::NEG_INFINITY;
                        }
                    }
                }
                walk.horizon()
            });
        }
    }
}

/// One line of sight's walk over several grids: whether it wants every box, the nearest entry
/// counted so far (t along the segment) and whether it has met enough.
#[derive(Debug, Clone, Copy)]
struct Walk {
    whole: bool,
    best: f64,
    enough: bool,
}

impl Walk {
    fn new(whole: bool) -> Self {
        Self {
            whole,
            best: f64::INFINITY,
            enough: false,
        }
    }

    /// How far along the segment a box not met yet can still count ([`BoxGrid::walk`]'s
    /// horizon): anywhere for a whole walk, else before the nearest entry counted.
    fn horizon(&self) -> f64 {
        if self.whole { f64::INFINITY } else { self.best }
    }
}

/// What a box a line of sight enters is to the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Met {
    /// It does not count (a faded-out cloud).
    Passed,
    /// It counts, entered at this t along the segment (at or after the box's entry).
    Counted(f64),
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
    /// Per cell: where its list starts and ends in `items`, and the lowest bottom and highest
    /// top of its boxes, metres (none: +inf, -inf); side by side, so that a cell the walk
    /// crosses is one cache line, not three (the walk's cells were most of its misses).
    cells: Vec<GridCell>,
    /// Per cell: the lowest bottom and highest top of its boxes as `f32`, rounded outward (none:
    /// +inf, -inf), eight bytes beside `cells`' 24: the walk passes over a cell it crosses
    /// above or below them without reading its [`GridCell`] (most cells a line crosses are
    /// empty, or hold only boxes above or below it: on the cruise 9 of its 10 a walk).
    spans_m: Vec<[f32; 2]>,
    /// Box indices, cell after cell.
    items: Vec<u32>,
    /// The lowest bottom and highest top of all its boxes, metres: a segment is walked only
    /// over the part of it between them (a line of sight above or below a drift band's
    /// layers crosses none of its cells).
    heights_m: [f64; 2],
}

/// One cell of a [`BoxGrid`].
#[derive(Debug, Clone, Copy)]
struct GridCell {
    bottom_m: f64,
    top_m: f64,
    start: u32,
    end: u32,
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
        let grid_cells = (0..nx * ny)
            .map(|c| GridCell {
                bottom_m: heights_m[c][0],
                top_m: heights_m[c][1],
                start: counts[c],
                end: counts[c + 1],
            })
            .collect();
        let spans_m = heights_m
            .iter()
            .map(|&[b, t]| [down_f32(b), up_f32(t)])
            .collect();
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
        let heights_m = heights_m
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[b, t], h| {
                [b.min(h[0]), t.max(h[1])]
            });
        Self {
            origin_m: lo,
            cell_m,
            nx,
            ny,
            cells: grid_cells,
            spans_m,
            items,
            heights_m,
        }
    }

    /// Walks the cells the segment `a + t (b - a)` crosses for t in `t_from..=t_to`, in order:
    /// `visit(boxes of the cell, t entering it, t leaving it)` for each cell with boxes the
    /// segment does not pass above or below, the first cell entered at minus infinity and the
    /// last left at plus infinity (so every t belongs to one cell). `visit` returns the horizon:
    /// the walk goes on past a cell only if the horizon is at or beyond the t leaving it
    /// (minus infinity stops it at once); `horizon` is the one before the first visit. A grid
    /// of no boxes visits nothing.
    fn walk(
        &self,
        a: DVec3,
        b: DVec3,
        (t_from, t_to): (f64, f64),
        mut horizon: f64,
        mut visit: impl FnMut(&[u32], f64, f64) -> f64,
    ) {
        // Most tiles have no big box: their coarse grid costs a line of sight nothing.
        if self.items.is_empty() {
            return;
        }
        let (a2, d) = (a.truncate(), (b - a).truncate());
        let dz = b.z - a.z;
        let hi = self.origin_m + DVec2::new(self.nx as f64, self.ny as f64) * self.cell_m;
        // The part of the segment over the grid and between its boxes' lowest bottom and
        // highest top (with the cells' margin of a metre): over the rest every cell's list
        // would be passed over as above or below its boxes.
        let Some((t0, t1)) = slab(
            a,
            b,
            self.origin_m.extend(self.heights_m[0] - 1.0),
            hi.extend(self.heights_m[1] + 1.0),
        ) else {
            return;
        };
        let (t0, t1) = (t0.max(t_from), t1.min(t_to));
        if t0 > t1 {
            return;
        }
        let start = (a2 + d * t0 - self.origin_m) / self.cell_m;
        let mut cell = [
            (start.x.max(0.0) as usize).min(self.nx - 1) as i64,
            (start.y.max(0.0) as usize).min(self.ny - 1) as i64,
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
            // The heights the segment has over the cell (a metre's margin, as the footprints),
            // on plain comparisons: `f64::max` and `min` (NaN-aware) were a tenth of the walk,
            // and none of these is NaN (a NaN height is passed over by neither).
            let z0 = a.z + dz * if enter > t0 { enter } else { t0 };
            let z1 = a.z + dz * if leave < t1 { leave } else { t1 };
            let (low, high) = if z0 < z1 { (z0, z1) } else { (z1, z0) };
            let (below, above) = (high + 1.0, low - 1.0);
            // Passed over on the rounded heights first: what they pass over, the cell's own do.
            let [bottom, top] = self.spans_m[c];
            if !(below < f64::from(bottom) || above > f64::from(top)) {
                let cell_here = &self.cells[c];
                if !(below < cell_here.bottom_m || above > cell_here.top_m) {
                    let list = &self.items[cell_here.start as usize..cell_here.end as usize];
                    horizon = visit(list, enter, leave);
                }
            }
            if horizon < leave || last {
                return;
            }
            enter = leave;
            cell[k] += step[k];
            next[k] += delta[k];
        }
    }
}

/// The largest `f32` at or below `x` (infinities kept).
pub(super) fn down_f32(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// The smallest `f32` at or above `x` (infinities kept).
pub(super) fn up_f32(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

#[cfg(test)]
#[path = "sight_tests.rs"]
mod tests;

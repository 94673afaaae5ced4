//! The CPU's share of a frame of sprites (Wang 2003 sections 3.3 and 6.1), now that the sprites
//! live on the GPU. Per frame: sort the near blocks back to front (hundreds) and write the draw
//! list the vertex shader reads (one entry per block: its centre relative to the camera, worked
//! out in f64, and its fade). A cloud's back-to-front sprite order is recomputed only when the
//! camera has moved relative to it, or time has passed, beyond thresholds that grow with its
//! distance (the vertex cache's rule, applied to the order); a block's list of clouds, back to
//! front, is looked at again only when the camera has used up the smallest slack of its
//! clouds, so most frames touch no cloud at all. The locked facings of the sprites the camera is
//! inside of are kept. Facing, shading and fades are the vertex shader's
//! (`shaders/sprites.wgsl`).
//!
//! In: the resident blocks, the camera (f64), the time. Out: [`GpuDrawBlock`]s, changed orders
//! and cloud lists, locks, [`FrameStats`]. No wgpu calls.

use std::collections::HashMap;

use bytemuck::Zeroable;
use glam::{DVec3, Vec3};

use super::resident::{BlockCheck, CloudState, Resident};
use super::settings::VertexCacheSettings;
use crate::render::camera::Frustum;
use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud, GpuLock, MAX_LOCKS};
use crate::render::id_hash::IdMap;
use crate::render::scene::{Fade, SkyCloud};
use crate::render::settings::RenderSettings;
use crate::render::stats::FrameStats;

/// A facing: the sprite's right and up axes and its normal towards the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facing {
    /// Right axis.
    pub right: Vec3,
    /// Up axis.
    pub up: Vec3,
    /// Normal towards the viewer.
    pub normal: Vec3,
}

/// Right/up axes of a sprite facing a viewer along `normal` (towards the viewer), with world up
/// kept up on screen; falls back to east when the viewer is straight above or below. The vertex
/// shader's `facing_towards` is the same.
pub fn facing_towards(normal: Vec3) -> Facing {
    let right = Vec3::Z.cross(normal);
    let right = if right.length_squared() > 1e-6 {
        right.normalize()
    } else {
        Vec3::X
    };
    let up = normal.cross(right).normalize_or_zero();
    Facing { right, up, normal }
}

/// The facing of an upright sprite seen along `to_cam` (sprite to camera): turned only about the
/// vertical, so its bottom edge stays level. The vertex shader's `upright_facing` is the same.
pub fn upright_facing(to_cam: Vec3) -> Facing {
    let normal = Vec3::new(to_cam.x, to_cam.y, 0.0).normalize_or(Vec3::Y);
    Facing {
        right: Vec3::Z.cross(normal).normalize_or(Vec3::X),
        up: Vec3::Z,
        normal,
    }
}

/// The facings locked now (Wang 3.3), by sprite slot: a sprite's facing locks when the camera
/// comes within `lock_radius_fraction` of its radius and is released when it leaves. Only the
/// clouds the camera is inside of are looked at.
#[derive(Debug, Default)]
pub(in crate::render) struct Locks {
    map: HashMap<u32, (Facing, bool)>,
    changed: bool,
}

impl Locks {
    fn begin(&mut self) {
        self.map.values_mut().for_each(|v| v.1 = false);
    }

    fn keep_or_lock(&mut self, slot: u32, facing: Facing) {
        if let Some(v) = self.map.get_mut(&slot) {
            v.1 = true;
        } else if self.map.len() < MAX_LOCKS {
            self.map.insert(slot, (facing, true));
            self.changed = true;
        }
    }

    fn end(&mut self) {
        let before = self.map.len();
        self.map.retain(|_, v| v.1);
        self.changed |= self.map.len() != before;
    }

    /// Forgets every lock in `slots` (a block that went; its slots may be reused).
    pub fn release(&mut self, slots: std::ops::Range<u32>) {
        let before = self.map.len();
        self.map.retain(|s, _| !slots.contains(s));
        self.changed |= self.map.len() != before;
    }

    /// Moves every lock to the slot `moved` says its sprite has now (the resident buffers were
    /// packed), forgetting those it gives none.
    pub fn follow(&mut self, moved: impl Fn(u32) -> Option<u32>) {
        let before = std::mem::take(&mut self.map);
        for (slot, lock) in before {
            match moved(slot) {
                Some(now) => {
                    self.changed |= now != slot;
                    self.map.insert(now, lock);
                }
                None => self.changed = true,
            }
        }
    }

    /// Whether the locks changed since the last [`Self::take_changed`].
    pub fn take_changed(&mut self) -> bool {
        std::mem::take(&mut self.changed)
    }

    /// The locks as the shader reads them.
    pub fn gpu(&self) -> Vec<GpuLock> {
        let mut locks: Vec<(u32, Facing)> = self.map.iter().map(|(&s, v)| (s, v.0)).collect();
        locks.sort_by_key(|l| l.0);
        locks
            .into_iter()
            .map(|(slot, f)| GpuLock {
                right: f.right.extend(0.0).to_array(),
                up: f.up.extend(0.0).to_array(),
                normal: f.normal.to_array(),
                sprite: slot,
            })
            .collect()
    }
}

/// Wang 6.1's thresholds for a cloud `near_edge_m` away: how far the camera may move relative
/// to it and how long it may wait, metres and seconds; they grow with the distance, and fading
/// clouds age out sooner only with `fading_max_age_s` set.
fn thresholds(fading: bool, near_edge_m: f64, cache: &VertexCacheSettings) -> (f64, f64) {
    let move_limit_m = cache.min_move_m as f64 + cache.move_fraction as f64 * near_edge_m;
    let max_age_s = match cache.fading_max_age_s {
        Some(age_s) if fading => age_s as f64,
        _ => cache.max_age_s as f64 * (1.0 + near_edge_m / cache.time_distance_m as f64),
    };
    (move_limit_m, max_age_s)
}

/// Whether more than `share` of a cloud's movement or age threshold is used up since its order
/// was computed (or time ran backwards): with `share` 1 Wang's rule that the order is stale.
pub(in crate::render) fn used_up(
    (ordered_at, fading): ((DVec3, f64), bool),
    camera_rel_m: DVec3,
    time_s: f64,
    near_edge_m: f64,
    cache: &VertexCacheSettings,
    share: f64,
) -> bool {
    let (move_limit_m, max_age_s) = thresholds(fading, near_edge_m, cache);
    let moved_m = (camera_rel_m - ordered_at.0).length();
    moved_m > share * move_limit_m
        || time_s - ordered_at.1 > share * max_age_s
        || time_s < ordered_at.1
}

/// How far inside the cloud the camera is (`clouds::core::inside`, the air data's own measure):
/// 0 outside its sprites' dense cores and below its base, rising to 1 over `ramp` of a core's
/// radius in. The box around the cores is asked first, the cores only when the camera is in it.
fn in_cloud_factor(state: &CloudState, cloud: &SkyCloud, camera_rel_m: Vec3, ramp: f32) -> f32 {
    if state.core_half_m.min_element() <= 0.0 {
        return 0.0;
    }
    let rel = camera_rel_m - state.core_centre_m;
    if (rel.abs() - state.core_half_m).max_element() > 0.0 {
        return 0.0;
    }
    crate::clouds::core::inside_cores(
        cloud.cores(),
        f64::from(cloud.floor_m),
        cloud.floor_slab_m,
        camera_rel_m.as_dvec3(),
        ramp,
    )
}

/// The cloud's sprite indices, farthest from the camera first, with their squared distances
/// (`cam_local_m` is the camera relative to the cloud centre): the last level of the
/// back-to-front sort, run when a cloud's order is recomputed.
pub fn sprites_back_to_front(cloud: &SkyCloud, cam_local_m: Vec3) -> Vec<(usize, f32)> {
    let mut order: Vec<(usize, f32)> = cloud
        .sprites
        .iter()
        .enumerate()
        .map(|(i, s)| (i, s.offset_m.distance_squared(cam_local_m)))
        .collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1));
    order
}

/// Sort keys of a cloud's sprites (the complement of the squared distance's bits above the
/// sprite's index, so that one ascending sort of plain integers puts the farthest first and
/// equally far sprites by index), and scratch to check a previous order with.
#[derive(Debug, Default)]
pub(in crate::render) struct SortKeys {
    keys: Vec<u64>,
    /// One bit a sprite: seen in the previous order.
    seen: Vec<u64>,
}

impl SortKeys {
    /// Empty buffers.
    pub(in crate::render) fn new() -> Self {
        Self::default()
    }
}

/// Writes the slots (`base` + index) of a cloud's sprites at `offsets` (from its centre,
/// [`super::resident::Resident::offsets_of`]), farthest from the camera first, into `slots`
/// (`cam_local_m`: the camera relative to the cloud centre). The same order as
/// [`sprites_back_to_front`], on integer keys (squared distances are positive floats, whose bits
/// sort as integers; packed with the index into one `u64`, which sorts about twice as fast as a
/// pair with a comparator) and a reused buffer: this runs for a hundred clouds a frame.
///
/// Where `slots` already hold an order of the cloud's sprites (the one Wang's cache is
/// replacing: the camera has moved a little since), the keys start in that order and an
/// insertion sort puts right the few sprites that changed places: a handful of moves a sprite
/// instead of a sort from scratch. Anything else in `slots` (a new cloud, another block's
/// leftovers) is sorted from scratch; the result is the same either way.
pub(in crate::render) fn order_into(
    offsets: &[Vec3],
    cam_local_m: Vec3,
    base: u32,
    slots: &mut [u32],
    keys: &mut SortKeys,
) {
    let key = |i: usize| {
        let far = !offsets[i].distance_squared(cam_local_m).to_bits();
        (u64::from(far) << 32) | i as u64
    };
    let n = offsets.len().min(slots.len());
    let SortKeys { keys, seen } = keys;
    keys.clear();
    keys.reserve(n);
    // The keys in the slots' order, as long as the slots hold each of the cloud's sprites once
    // (checked on the same pass: the slots' first read is a cache miss, the second was not).
    seen.clear();
    seen.resize(n.div_ceil(64), 0);
    let held = slots[..n].iter().all(|&s| {
        let i = s.wrapping_sub(base) as usize;
        if i >= n || seen[i / 64] & (1 << (i % 64)) != 0 {
            return false;
        }
        seen[i / 64] |= 1 << (i % 64);
        keys.push(key(i));
        true
    });
    if held {
        // Past a few moves a sprite the camera has turned the cloud over: sorted afresh.
        if !insertion_sort_within(keys, 4 * n) {
            keys.sort_unstable();
        }
    } else {
        keys.clear();
        keys.extend((0..n).map(key));
        keys.sort_unstable();
    }
    for (slot, &key) in slots.iter_mut().zip(keys.iter()) {
        *slot = base + key as u32;
    }
}

/// Sorts `v` by insertion while that takes at most `max_moves` moves; false (`v` part
/// sorted, still holding every value) once it would take more.
fn insertion_sort_within(v: &mut [u64], max_moves: usize) -> bool {
    let mut moves = 0;
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
        moves += i - j;
        if moves > max_moves {
            return false;
        }
    }
    true
}

/// How much of a block a fade shows, 0..=1: its progress forming, what is left dissipating.
fn fade_opacity(fade: Fade) -> f32 {
    match fade {
        Fade::Steady => 1.0,
        Fade::Forming(p) => p.clamp(0.0, 1.0),
        Fade::Dissipating(q) => 1.0 - q.clamp(0.0, 1.0),
    }
}

/// Or'ed into a draw block's `fade_kind` for a distant block: its sprites keep their opacity
/// beyond the draw distance (`far_fade` in `shaders/sprite_build.wgsl`, keep in sync).
const DISTANT_BLOCK: u32 = 4;

pub(in crate::render) fn fade_code(fade: Fade) -> (u32, f32) {
    match fade {
        Fade::Steady => (0, 1.0),
        Fade::Forming(p) => (1, p.clamp(0.0, 1.0)),
        Fade::Dissipating(q) => (2, q.clamp(0.0, 1.0)),
    }
}

/// The blocks the sky holds, by id.
pub(in crate::render) type Blocks = IdMap<Resident>;

/// Blocks' ids, farthest centre (with its drift) from `from_m` first (the impostor views; the
/// sky camera's sorts the near blocks themselves).
pub(in crate::render) fn blocks_back_to_front(
    blocks: &Blocks,
    ids: &[u64],
    from_m: DVec3,
) -> Vec<(f64, u64)> {
    let mut order: Vec<(f64, &Resident)> = ids
        .iter()
        .filter_map(|id| blocks.get(id))
        .filter(|r| r.place.is_some())
        .map(|r| ((r.centre_m() - from_m).length_squared(), r))
        .collect();
    order.sort_by(|a, b| farthest_first((a.0, a.1), (b.0, b.1)));
    order.into_iter().map(|(d, r)| (d, r.block.id)).collect()
}

/// Back to front by squared distance, equally far blocks in [`Resident::tie_order`].
fn farthest_first(a: (f64, &Resident), b: (f64, &Resident)) -> std::cmp::Ordering {
    b.0.total_cmp(&a.0).then_with(|| a.1.tie_order(b.1))
}

/// The sprites of a frame's distant blocks, which its draw list puts first: they are drawn
/// behind the impostor ring, which holds nearer clouds.
pub(in crate::render) fn distant_sprites(draws: &[GpuDrawBlock], total: u32) -> u32 {
    draws
        .iter()
        .find(|d| d.fade_kind & DISTANT_BLOCK == 0)
        .map_or(total, |d| d.first)
}

/// Where the sky camera's sprite orders and cloud lists go: CPU copies of the order and list
/// buffers and the spans of them changed this frame.
pub(in crate::render) struct Copies<'a> {
    pub orders: &'a mut [u32],
    pub dirty_orders: &'a mut Vec<std::ops::Range<u32>>,
    pub lists: &'a mut [GpuListCloud],
    pub dirty_lists: &'a mut Vec<std::ops::Range<u32>>,
}

/// The sky camera's frame: fills `out` with the draw list of the view's `near` blocks (the ids
/// its impostor ring leaves to the sprites) that are placed and in view (`frustum`: nothing of
/// a block wholly outside it is built or drawn), looks again at the blocks whose slack is used
/// up (re-sorting their clouds, recomputing the orders the cache says are stale, into `copies`,
/// marked dirty, at most `budget` sprites), updates `locks` and `seams`, and counts into
/// `stats`. Returns how far inside a cloud, and how deep in rain, the camera is.
#[allow(clippy::too_many_arguments)]
pub(in crate::render) fn main_view(
    (blocks, near): (&mut Blocks, &[u64]),
    copies: Copies,
    (camera_m, frustum): (DVec3, &Frustum),
    time_s: f64,
    (settings, budget): (&RenderSettings, u32),
    (locks, seams): (&mut Locks, &mut Seams),
    out: &mut Vec<GpuDrawBlock>,
    stats: &mut FrameStats,
) -> Inside {
    // A block out of view is not looked at again either: its slack check catches up with the
    // camera the frame it comes into view. Only the view's near blocks are looked up, not the
    // thousands held (most of them in the ring).
    let mut order: Vec<(bool, f64, &Resident)> = near
        .iter()
        .filter_map(|id| blocks.get(id))
        .filter(|r| r.uploaded)
        .filter(|r| frustum.sees_sphere((r.centre_m() - camera_m).as_vec3(), r.radius_m as f32))
        .map(|r| (r.distant, (r.centre_m() - camera_m).length_squared(), r))
        .collect();
    // Distant blocks (storm cells beyond the field) first: drawn behind the ring. The keys are
    // copied out of the blocks: a comparison that reads a block costs a cache miss, and this
    // sorts a few hundred blocks a frame.
    order.sort_by(|a, b| {
        b.0.cmp(&a.0)
            .then_with(|| farthest_first((a.1, a.2), (b.1, b.2)))
    });
    let order: Vec<(f64, u64)> = (order.into_iter())
        .map(|(_, d2, r)| (d2, r.block.id))
        .collect();
    let Copies {
        orders,
        dirty_orders,
        lists,
        dirty_lists,
    } = copies;
    let (mut scratch, mut keys) = (Vec::new(), SortKeys::new());
    // Looked at again nearest first, so that the frame's sorting budget goes to what is near.
    let mut budget = budget;
    for (_, id) in order.iter().rev() {
        let Some(r) = blocks.get_mut(id) else {
            continue;
        };
        let rel = camera_m - r.centre_m();
        let fresh = settings.vertex_cache.enabled
            && r.check.is_some_and(|c| {
                (rel - c.camera_rel_m).length() <= c.move_budget_m
                    && time_s <= c.deadline_s
                    && time_s >= c.checked_s
            });
        if !fresh {
            recheck(
                r,
                (camera_m, time_s),
                settings,
                (orders, dirty_orders),
                &mut budget,
                stats,
                (&mut scratch, &mut keys),
            );
            if let Some((_, clouds)) = &r.place {
                let n = r.list.len() as u32;
                lists[clouds.start as usize..(clouds.start + n) as usize].copy_from_slice(&r.list);
                dirty_lists.push(clouds.start..clouds.start + n);
            }
        }
    }
    let order: Vec<Listed> = order
        .iter()
        .filter_map(|&(d2, id)| Some(Listed::resident(d2, blocks.get(&id)?)))
        .collect();
    let mut inside = Inside::default();
    out.clear();
    locks.begin();
    for &Listed { d2, r, .. } in &order {
        if d2.sqrt() < r.radius_m {
            let here = inside_clouds(r, camera_m, settings, locks);
            // A forming or dissipating block's inside is as thick as it has formed: a new
            // report's deck around the camera thickens with its clouds, not in one frame.
            let shown = fade_opacity(r.motion.fade);
            inside.cloud = inside.cloud.max(here.cloud * shown);
            inside.rain = inside.rain.max(here.rain * shown);
        }
        stats.clouds_drawn += r.list.len() as u32;
    }
    locks.end();
    let total = draw_entries(&order, camera_m, seams, out);
    stats.sprites_drawn = total;
    stats.cache_hit_rate = if stats.clouds_drawn == 0 {
        1.0
    } else {
        1.0 - stats.clouds_recomputed as f32 / stats.clouds_drawn as f32
    };
    inside
}

/// At most this many blocks have their clouds interleaved together: a camera on the corner of
/// four blocks, each in two generations during a weather change. A block that would make a
/// group larger stays whole (a host's own layout of blocks could chain them without end).
const MAX_INTERLEAVED: usize = 8;

/// A view's groups of blocks drawn with their clouds interleaved ([`draw_entries`]), kept from
/// frame to frame: a group's merge is worked out again only when one of its blocks' lists has
/// been sorted again since, or the group has changed. A block's own list is kept as long as
/// the camera has not used up its clouds' slack (Wang's thresholds); a merge of lists kept
/// that long is as good, and a frame whose groups' lists all stand touches none of their
/// clouds.
#[derive(Debug, Default)]
pub(in crate::render) struct Seams {
    kept: Vec<Merged>,
    /// Scratch: the squared distances of the clouds of the group being merged.
    d2: Vec<f64>,
}

/// The next [`Resident::list_serial`]: unique among all the lists written, so that a block
/// that went and came back with the same id does not find the merges of its old list.
static LIST_SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// A group's merge: its blocks, farthest first (id and [`Resident::list_serial`]), and its
/// runs in drawing order.
#[derive(Debug)]
struct Merged {
    blocks: Vec<(u64, u64)>,
    runs: Vec<Run>,
    /// Whether the frame drew it (one that is not is forgotten).
    drawn: bool,
}

/// A run of one block's clouds in a group's merge: which block of the group, the part of its
/// list (from `start`, `len` clouds) and their sprites. A frame that keeps the merge reads
/// only these, none of the block's list.
#[derive(Debug, Clone, Copy)]
struct Run {
    member: u8,
    start: u32,
    len: u32,
    sprites: u32,
}

/// A block of a draw list: its squared distance from the view's eye, the block, and its drawn
/// clouds' list back to front (`list`, at `list_base` of the bound list buffer) with their
/// sprites.
#[derive(Clone, Copy)]
struct Listed<'a> {
    d2: f64,
    r: &'a Resident,
    list: &'a [GpuListCloud],
    list_base: u32,
    sprites: u32,
}

impl<'a> Listed<'a> {
    /// The sky camera's view of a block: its list as last sorted.
    fn resident(d2: f64, r: &'a Resident) -> Self {
        Self {
            d2,
            r,
            list: &r.list,
            list_base: r.place.as_ref().map_or(0, |p| p.1.start),
            sprites: r.list_sprites,
        }
    }

    /// The squared distances from `eye_m` of the clouds of its list, in its order, onto `d2`
    /// (one pass over the list; a cloud not found is infinitely near, drawn last).
    fn clouds_d2(&self, eye_m: DVec3, d2: &mut Vec<f64>) {
        let start = self.r.place.as_ref().map_or(0, |p| p.1.start);
        let at = self.r.motion.offset_m - eye_m;
        let clouds = &self.r.clouds;
        d2.extend(self.list.iter().map(|e| {
            clouds
                .get(e.cloud.wrapping_sub(start) as usize)
                .map_or(f64::NEG_INFINITY, |c| (c.centre_m + at).length_squared())
        }));
    }

    /// Sprites before the `k`th cloud of its list.
    fn sprites_before(&self, k: usize) -> u32 {
        self.list.get(k).map_or(self.sprites, |e| e.first)
    }

    /// The entry of clouds `part` of its list, its first sprite `first`.
    fn entry(&self, part: std::ops::Range<usize>, eye_m: DVec3, first: u32) -> GpuDrawBlock {
        let (fade_kind, fade_progress) = fade_code(self.r.motion.fade);
        GpuDrawBlock {
            origin_rel: (self.r.centre_m() - eye_m).as_vec3().to_array(),
            fade_kind: fade_kind | if self.r.distant { DISTANT_BLOCK } else { 0 },
            first,
            list_base: self.list_base + part.start as u32,
            list_len: part.len() as u32,
            fade_progress,
        }
    }
}

/// The draw list of `order` (back to front, distant blocks first, seen from `eye_m`): one
/// entry for each block, except where the eye is close to the plane that decides the order of
/// two neighbouring deck blocks. Drawn whole, one after the other, their overlapping sprites along
/// that plane blend out of their distance order: with the eye on a block boundary every sprite
/// of one side is drawn over the other's, and a straight seam runs along the boundary from the
/// eye to the horizon. So their clouds are drawn interleaved, farthest first, as the clouds of
/// one block are: each run of one block's clouds is an entry of its own (a part of its cloud
/// list). `seams` keeps the merges from frame to frame. Returns the sprites.
fn draw_entries(
    order: &[Listed],
    eye_m: DVec3,
    seams: &mut Seams,
    out: &mut Vec<GpuDrawBlock>,
) -> u32 {
    let mut total = 0u32;
    let Some(groups) = seam_groups(order) else {
        // The eye is near no plane between two neighbours.
        seams.kept.clear();
        for b in order {
            out.push(b.entry(0..b.list.len(), eye_m, total));
            total += b.sprites;
        }
        return total;
    };
    let mut sizes = vec![0u8; order.len()];
    for &g in &groups {
        sizes[g as usize] += 1;
    }
    seams.kept.iter_mut().for_each(|m| m.drawn = false);
    let mut members: Vec<Listed> = Vec::with_capacity(MAX_INTERLEAVED);
    let mut key: Vec<(u64, u64)> = Vec::with_capacity(MAX_INTERLEAVED);
    for (i, b) in order.iter().enumerate() {
        let group = groups[i] as usize;
        if sizes[group] == 1 {
            out.push(b.entry(0..b.list.len(), eye_m, total));
            total += b.sprites;
            continue;
        } else if group != i {
            // A group is drawn where its farthest block (its first) is, and skipped after.
            continue;
        }
        members.clear();
        let mut left = sizes[group] as usize;
        for (j, &g) in groups.iter().enumerate().skip(i) {
            if g as usize == group {
                members.push(order[j]);
                left -= 1;
                if left == 0 {
                    break;
                }
            }
        }
        key.clear();
        key.extend(members.iter().map(|b| (b.r.block.id, b.r.list_serial)));
        let at = match seams.kept.iter().position(|m| m.blocks == key) {
            Some(at) => at,
            None => {
                let runs = interleave(&members, eye_m, &mut seams.d2);
                seams.kept.push(Merged {
                    blocks: key.clone(),
                    runs,
                    drawn: false,
                });
                seams.kept.len() - 1
            }
        };
        let merged = &mut seams.kept[at];
        merged.drawn = true;
        // Each block's entry once; each run is it with its part of the list.
        let mut whole = [GpuDrawBlock::zeroed(); MAX_INTERLEAVED];
        for (w, b) in whole.iter_mut().zip(&members) {
            *w = b.entry(0..0, eye_m, 0);
        }
        out.extend(merged.runs.iter().map(|run| {
            let first = total;
            total += run.sprites;
            GpuDrawBlock {
                first,
                list_base: whole[run.member as usize].list_base + run.start,
                list_len: run.len,
                ..whole[run.member as usize]
            }
        }));
    }
    seams.kept.retain(|m| m.drawn);
    total
}

/// For each block of `order` (back to front) the index of the first block of its group, its
/// own where it has none; `None` where no block has one. Two neighbouring deck blocks (their
/// spheres overlap) are grouped when the eye is within their largest cloud's radius of the
/// plane half way between their centres: nearer, some of the farther block's sprites that
/// overlap the nearer one's on screen are nearer the eye than they are. Squared distances
/// differ by `2 |c_a - c_b|` times the eye's distance from that plane, so only blocks a few
/// places apart in `order` are looked at (about three on a grid of equal blocks, however far
/// out).
fn seam_groups(order: &[Listed]) -> Option<Vec<u32>> {
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let n = order.len();
    // Made when the first pair is found.
    let mut parent: Vec<u32> = Vec::new();
    let mut size: Vec<u8> = Vec::new();
    // Only decks: their cells stand side by side up to the blocks' sides, so two decks'
    // sprites overlap all along the boundary and the blend out of order is a line. Heaped
    // clouds have gaps between them; where two overlap across a boundary the error is one
    // cloud's, and grouping them made the cumulus cruise's update dearer by a third.
    let interleaved = |b: &Listed| b.r.deck && !b.r.distant;
    let (mut radius, mut reach) = (0.0f64, 0.0f64);
    for b in order.iter().filter(|b| interleaved(b)) {
        radius = radius.max(b.r.radius_m);
        reach = reach.max(b.r.largest_cloud_m);
    }
    let window = 4.0 * reach * radius;
    for (i, a) in order.iter().enumerate() {
        if !interleaved(a) {
            continue;
        }
        for (j, b) in order.iter().enumerate().skip(i + 1) {
            let dd2 = a.d2 - b.d2;
            if dd2 > window {
                break;
            }
            let apart = (a.r.centre_m() - b.r.centre_m()).length();
            let reach = a.r.largest_cloud_m.max(b.r.largest_cloud_m);
            if !interleaved(b) || apart >= a.r.radius_m + b.r.radius_m || dd2 > 2.0 * reach * apart
            {
                continue;
            }
            if parent.is_empty() {
                parent = (0..n as u32).collect();
                size = vec![1u8; n];
            }
            let (ri, rj) = (root(&mut parent, i as u32), root(&mut parent, j as u32));
            let joined = size[ri as usize] as usize + size[rj as usize] as usize;
            if ri != rj && joined <= MAX_INTERLEAVED {
                // The root is the group's farthest block (its lowest index).
                let (lo, hi) = (ri.min(rj), ri.max(rj));
                parent[hi as usize] = lo;
                size[lo as usize] = joined as u8;
            }
        }
    }
    if parent.is_empty() {
        return None;
    }
    Some((0..n as u32).map(|i| root(&mut parent, i)).collect())
}

/// The runs of the clouds of `members` (a group of [`seam_groups`], farthest block first)
/// merged farthest first by their distance from `eye_m` now, in drawing order. Each block's
/// list keeps its own order, so each run of one block's clouds is a part of its list. `d2` is
/// scratch for the clouds' squared distances.
fn interleave(members: &[Listed], eye_m: DVec3, d2: &mut Vec<f64>) -> Vec<Run> {
    // Each member's distances, worked out once: member `m`'s are `d2[from[m]..from[m + 1]]`.
    let mut from = [0usize; MAX_INTERLEAVED + 1];
    d2.clear();
    for (m, b) in members.iter().enumerate() {
        from[m] = d2.len();
        b.clouds_d2(eye_m, d2);
        from[m + 1] = d2.len();
    }
    let mut heads = from;
    // Whether member `a`'s cloud at `da` goes before member `b`'s at `db`: the farther first;
    // equally far, the farther block's (the lower index).
    let before = |(a, da): (usize, f64), (b, db): (usize, f64)| {
        da.total_cmp(&db).then(b.cmp(&a)) == std::cmp::Ordering::Greater
    };
    let mut runs = Vec::new();
    loop {
        // The member whose next cloud is farthest, and the farthest of the others'.
        let mut next: Option<(usize, f64)> = None;
        let mut other: Option<(usize, f64)> = None;
        for m in 0..members.len() {
            if heads[m] < from[m + 1] {
                let here = (m, d2[heads[m]]);
                if next.is_none_or(|x| before(here, x)) {
                    other = next;
                    next = Some(here);
                } else if other.is_none_or(|x| before(here, x)) {
                    other = Some(here);
                }
            }
        }
        let Some((m, _)) = next else {
            return runs;
        };
        // Its run: its clouds that go before the others' next.
        let start = heads[m];
        let mut end = start + 1;
        while end < from[m + 1] && other.is_none_or(|o| before((m, d2[end]), o)) {
            end += 1;
        }
        heads[m] = end;
        let (b, part) = (&members[m], start - from[m]..end - from[m]);
        runs.push(Run {
            member: m as u8,
            start: part.start as u32,
            len: part.len() as u32,
            sprites: b.sprites_before(part.end) - b.sprites_before(part.start),
        });
    }
}

/// Where the camera is among the clouds of a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(in crate::render) struct Inside {
    /// How far inside a cloud, 0 (outside) ..= 1 (deep in its core).
    pub cloud: f32,
    /// How opaque the rain or snow shaft the camera is in is there: the shaft's opacity, less
    /// towards its edge; 0 out of any.
    pub rain: f32,
}

/// Looks at every cloud of a block again: its clouds within the draw distance sorted back to
/// front into its list, each stale order recomputed (Wang 6.1's thresholds), and how far and
/// how long the camera may go before any of them needs it again.
/// Clouds past the frame's sorting `budget` (sprites) keep their order; their block comes back
/// the next frame.
fn recheck(
    r: &mut Resident,
    (camera_m, time_s): (DVec3, f64),
    settings: &RenderSettings,
    (orders, dirty_orders): (&mut [u32], &mut Vec<std::ops::Range<u32>>),
    budget_sprites: &mut u32,
    stats: &mut FrameStats,
    (scratch, keys): (&mut Vec<(usize, f64, f64)>, &mut SortKeys),
) {
    let cache = &settings.vertex_cache;
    // A distant block (a storm cell beyond the field) is drawn however far it is.
    let draw_m = if r.distant {
        f64::INFINITY
    } else {
        settings.clouds.draw_distance_m as f64
    };
    let offset = r.motion.offset_m;
    let fading = r.motion.fade != Fade::Steady;
    let slope = cache.move_fraction as f64;
    scratch.clear();
    // Slack before a cloud crosses the draw distance.
    let mut budget = f64::INFINITY;
    for (ci, state) in r.clouds.iter().enumerate() {
        let d = (state.centre_m + offset - camera_m).length();
        let near_edge = (d - state.radius_m as f64).max(0.0);
        if state.sprites > 0 {
            budget = budget.min((near_edge - draw_m).abs());
            if near_edge <= draw_m {
                scratch.push((ci, d, near_edge));
            }
        }
    }
    scratch.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    r.list.clear();
    r.list_serial = LIST_SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut first = 0u32;
    let mut nearest_edge = f64::INFINITY;
    let mut oldest = f64::INFINITY;
    for &(ci, _, near_edge) in scratch.iter() {
        let state = &mut r.clouds[ci];
        let rel = camera_m - (state.centre_m + offset);
        // Stale by Wang's thresholds, or nearly (less than a third of its slack left): sorted
        // now with the block's others, so that the block keeps a slack worth waiting for
        // instead of coming back for one cloud every frame.
        let stale = !cache.enabled
            || state
                .ordered_at
                .is_none_or(|at| used_up((at, fading), rel, time_s, near_edge, cache, 2.0 / 3.0));
        let afford = state.sprites <= *budget_sprites;
        if stale && !afford {
            // Over the frame's budget: drawn in its last order, looked at again next frame.
            budget = 0.0;
        } else if stale {
            *budget_sprites = budget_sprites.saturating_sub(state.sprites);
            let base = state.sprite_base as usize;
            let slots = &mut orders[base..base + state.sprites as usize];
            order_into(
                &r.offsets[state.first_offset as usize..][..state.sprites as usize],
                rel.as_vec3(),
                state.sprite_base,
                slots,
                keys,
            );
            dirty_orders.push(state.sprite_base..state.sprite_base + state.sprites);
            state.ordered_at = Some((rel, time_s));
            stats.clouds_recomputed += 1;
            stats.sprites_recomputed += state.sprites;
        }
        // What is left of its movement threshold, knowing that its distance (and with it the
        // threshold) shrinks by at most what the camera moves.
        let (at_rel, at_s) = state.ordered_at.unwrap_or((rel, time_s));
        let (limit, _) = thresholds(fading, near_edge, cache);
        budget = budget.min((limit - (rel - at_rel).length()).max(0.0) / (1.0 + slope));
        nearest_edge = nearest_edge.min(near_edge);
        oldest = oldest.min(at_s);
        r.list.push(GpuListCloud {
            cloud: state.cloud_slot,
            first,
            order_base: state.sprite_base,
            stride: 0,
        });
        first += state.sprites;
    }
    r.list_sprites = first;
    // The age threshold of the nearest cloud once the camera has used up the movement slack
    // (the smallest any of them can have), from the oldest order.
    let (_, max_age_s) = thresholds(fading, (nearest_edge - budget).max(0.0), cache);
    r.check = Some(BlockCheck {
        camera_rel_m: camera_m - r.centre_m(),
        move_budget_m: budget,
        checked_s: time_s,
        deadline_s: oldest + max_age_s,
    });
}

/// The camera is within a block's radius: how far inside its clouds and their rain it is, and
/// the facing locks of the sprites it is within half the radius of.
fn inside_clouds(
    r: &Resident,
    camera_m: DVec3,
    settings: &RenderSettings,
    locks: &mut Locks,
) -> Inside {
    let mut in_cloud = 0.0f32;
    let mut in_rain = 0.0f32;
    let lock_fraction = settings.clouds.lock_radius_fraction;
    for (state, cloud) in r.clouds.iter().zip(&r.block.clouds) {
        let cam_local = (camera_m - (state.centre_m + r.motion.offset_m)).as_vec3();
        if cam_local.length() >= state.radius_m {
            continue;
        }
        in_cloud = in_cloud.max(in_cloud_factor(
            state,
            cloud,
            cam_local,
            settings.in_cloud.ramp_fraction,
        ));
        // Most clouds whose sphere holds the camera (under a cumulus base) are not near
        // enough any of their sprites for a lock or a shaft: their sprites are not read.
        let reach = state.largest_half_side_m * lock_fraction.max(1.0);
        let beyond = (cam_local - state.centres_centre_m).abs() - state.centres_half_m;
        if beyond.max_element() > reach {
            continue;
        }
        if cloud.flat {
            continue;
        }
        for (k, s) in cloud.sprites.iter().enumerate() {
            let to_cam = cam_local - s.offset_m;
            if s.precipitation && to_cam.z.abs() < 0.5 * s.height_m {
                // An upright column: as opaque as the shaft, less towards its side.
                let aside = to_cam.truncate().length() / (0.5 * s.width_m).max(1.0);
                in_rain = in_rain.max(s.alpha_morph * (1.0 - aside).max(0.0));
            }
            let radius = 0.5 * s.width_m.max(s.height_m);
            if to_cam.length() < lock_fraction * radius {
                let face = if s.upright {
                    upright_facing(to_cam)
                } else {
                    facing_towards(to_cam.normalize_or(Vec3::Y))
                };
                locks.keep_or_lock(state.sprite_base + k as u32, face);
            }
        }
    }
    Inside {
        cloud: in_cloud,
        rain: in_rain,
    }
}

#[cfg(test)]
#[path = "draw_list_tests.rs"]
pub(in crate::render) mod tests;

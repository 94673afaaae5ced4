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

use glam::{DVec3, Vec3};

use super::draw_entries::{LIST_SERIAL, Listed, Sight, draw_entries};
pub(in crate::render) use super::draw_entries::{Seams, distant_sprites, fade_code};
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

/// Where the sky camera's sprite orders and cloud lists go: CPU copies of the order and list
/// buffers and the spans of them changed this frame.
pub(in crate::render) struct Copies<'a> {
    pub orders: &'a mut [u32],
    pub dirty_orders: &'a mut Vec<std::ops::Range<u32>>,
    pub lists: &'a mut [GpuListCloud],
    pub dirty_lists: &'a mut Vec<std::ops::Range<u32>>,
}

/// Whether any of a block's quads can reach into the view `sight` looks through from
/// `camera_m`: its clouds' sphere grown by its largest quad's corner reach and the shader's
/// bending onto the round Earth.
pub(super) fn block_in_view(r: &Resident, camera_m: DVec3, sight: &Sight) -> bool {
    sight.sees_cloud(
        (r.centre_m() - camera_m).as_vec3(),
        r.radius_m as f32,
        r.largest_half_side_m,
    )
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
    // thousands held (most of them in the ring). A block is out of view only when its quads'
    // corners and the shader's bending onto the round Earth keep out of it too, as a cloud's
    // are (`Sight::sees_cloud`): a block showing a corner at the view's edge is drawn.
    let seen_by = Sight {
        frustum,
        earth_radius_m: settings.earth.camera_radius_m(camera_m.z),
    };
    let mut order: Vec<(bool, f64, &Resident)> = near
        .iter()
        .filter_map(|id| blocks.get(id))
        .filter(|r| r.uploaded)
        .filter(|r| block_in_view(r, camera_m, &seen_by))
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
            let shown = fade_opacity(r.fade());
            inside.cloud = inside.cloud.max(here.cloud * shown);
            inside.rain = inside.rain.max(here.rain * shown);
        }
        stats.clouds_drawn += r.list.len() as u32;
    }
    locks.end();
    let sight = settings.clouds.cull_out_of_view.then_some(&seen_by);
    let total = draw_entries(&order, (camera_m, sight), seams, out);
    stats.sprites_drawn = total;
    stats.cache_hit_rate = if stats.clouds_drawn == 0 {
        1.0
    } else {
        1.0 - stats.clouds_recomputed as f32 / stats.clouds_drawn as f32
    };
    inside
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
    let offset = r.offset_m();
    let fading = r.fade() != Fade::Steady;
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
        let cam_local = (camera_m - (state.centre_m + r.offset_m())).as_vec3();
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

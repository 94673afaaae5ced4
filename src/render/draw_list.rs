//! The CPU's share of a frame of sprites (Wang 2003 sections 3.3 and 6.1), now that the sprites
//! live on the GPU: sort blocks and clouds back to front (thousands, not 100,000s), recompute a
//! cloud's back-to-front sprite order only when the camera has moved relative to it, or time
//! has passed, beyond thresholds that grow with its distance (the vertex cache's rule, applied
//! to the order), keep the locked facings of the sprites the camera is inside of, and write the
//! draw list the vertex shader reads (one entry per cloud). Facing, shading and fades are the
//! vertex shader's (`shaders/sprites.wgsl`).
//!
//! In: the resident blocks, the camera (f64), the time. Out: [`GpuDrawCloud`]s, changed orders,
//! locks, [`FrameStats`]. No wgpu calls.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use super::gpu_types::{GpuDrawCloud, GpuLock, MAX_LOCKS};
use super::resident::{CloudState, Resident};
use super::scene::{Fade, SkyCloud};
use super::settings::{RenderSettings, VertexCacheSettings};
use super::stats::FrameStats;

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
pub(super) struct Locks {
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

/// Wang 6.1's thresholds: they grow with the cloud's distance; fading clouds age out sooner.
fn needs_recompute(
    ordered_at: (DVec3, f64),
    fading: bool,
    camera_rel_m: DVec3,
    time_s: f64,
    near_edge_m: f64,
    cache: &VertexCacheSettings,
) -> bool {
    let moved_m = (camera_rel_m - ordered_at.0).length();
    let move_limit_m = cache.min_move_m as f64 + cache.move_fraction as f64 * near_edge_m;
    let max_age_s = if fading {
        cache.fading_max_age_s as f64
    } else {
        cache.max_age_s as f64 * (1.0 + near_edge_m / cache.time_distance_m as f64)
    };
    moved_m > move_limit_m || time_s - ordered_at.1 > max_age_s || time_s < ordered_at.1
}

/// How far inside the cloud's core box the camera is: 0 outside, rising to 1 over `ramp` of the
/// half-extent inside the boundary.
fn in_cloud_factor(state: &CloudState, camera_rel_m: Vec3, ramp: f32) -> f32 {
    if state.core_half_m.min_element() <= 0.0 {
        return 0.0;
    }
    let rel = camera_rel_m - state.core_centre_m;
    let inside = (Vec3::ONE - rel.abs() / state.core_half_m).min_element();
    (inside / ramp.max(1e-3)).clamp(0.0, 1.0)
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

fn fade_code(fade: Fade) -> (u32, f32) {
    match fade {
        Fade::Steady => (0, 1.0),
        Fade::Forming(p) => (1, p.clamp(0.0, 1.0)),
        Fade::Dissipating(q) => (2, q.clamp(0.0, 1.0)),
    }
}

/// The blocks the sky holds, by id.
pub(super) type Blocks = HashMap<u64, Resident>;

/// Blocks' ids, farthest centre (with its drift) from `from_m` first; equal distances by id (the
/// impostor views; the sky camera's sorts the near blocks themselves).
fn blocks_back_to_front(blocks: &Blocks, ids: &[u64], from_m: DVec3) -> Vec<(f64, u64)> {
    let mut order: Vec<(f64, u64)> = ids
        .iter()
        .filter_map(|id| blocks.get(id))
        .filter(|r| r.place.is_some())
        .map(|r| ((r.centre_m() - from_m).length_squared(), r.block.id))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    order
}

/// Where the sky camera's sprite orders go: a CPU copy of the order buffer and the spans of it
/// changed this frame.
pub(super) struct OrderCopy<'a> {
    pub slots: &'a mut [u32],
    pub dirty: &'a mut Vec<std::ops::Range<u32>>,
}

/// The sky camera's frame: fills `out` with the draw list of the blocks marked near and placed,
/// recomputes the orders the cache says are stale (into `orders`, marked dirty), updates
/// `locks`, and counts into `stats`. Returns how far inside a cloud the camera is, 0..=1.
///
/// Per frame this reads every near cloud's centre, radius and cache state (`CloudState`, kept
/// together per block) and touches a cloud's sprites only to re-sort them or when the camera
/// is inside it.
pub(super) fn main_view(
    blocks: &mut Blocks,
    orders: OrderCopy,
    camera_m: DVec3,
    time_s: f64,
    settings: &RenderSettings,
    locks: &mut Locks,
    out: &mut Vec<GpuDrawCloud>,
    stats: &mut FrameStats,
) -> f32 {
    let (clouds_cfg, cache) = (&settings.clouds, &settings.vertex_cache);
    let draw_m = clouds_cfg.draw_distance_m as f64;
    let lock_fraction = clouds_cfg.lock_radius_fraction;
    let mut order: Vec<(f64, &mut Resident)> = blocks
        .values_mut()
        .filter(|r| r.near && r.place.is_some())
        .map(|r| ((r.centre_m() - camera_m).length_squared(), r))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.block.id.cmp(&b.1.block.id)));
    let OrderCopy {
        slots: orders_cpu,
        dirty: dirty_orders,
    } = orders;
    let mut in_cloud = 0.0f32;
    let mut cloud_order: Vec<(usize, f64, f64)> = Vec::new();
    let mut total = 0u32;
    out.clear();
    locks.begin();
    for (_, r) in order {
        let offset = r.motion.offset_m;
        let fading = r.motion.fade != Fade::Steady;
        let (fade_kind, fade_progress) = fade_code(r.motion.fade);
        cloud_order.clear();
        for (ci, state) in r.clouds.iter().enumerate() {
            let d = (state.centre_m + offset - camera_m).length();
            let near_edge = (d - state.radius_m as f64).max(0.0);
            if near_edge <= draw_m && state.sprites > 0 {
                cloud_order.push((ci, d, near_edge));
            }
        }
        cloud_order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        for &(ci, d, near_edge) in &cloud_order {
            let state = &mut r.clouds[ci];
            let rel = camera_m - (state.centre_m + offset);
            let cam_local = rel.as_vec3();
            let n = state.sprites;
            if d < state.radius_m as f64 {
                let cloud = &r.block.clouds[ci];
                let inside = in_cloud_factor(state, cam_local, settings.in_cloud.ramp_fraction);
                in_cloud = in_cloud.max(inside);
                if !cloud.flat {
                    for (k, s) in cloud.sprites.iter().enumerate() {
                        let to_cam = cam_local - s.offset_m;
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
            }
            let stale = !cache.enabled
                || state.ordered_at.is_none_or(|at| {
                    needs_recompute(at, fading, rel, time_s, near_edge, cache)
                });
            if stale {
                let base = state.sprite_base as usize;
                let slots = &mut orders_cpu[base..base + n as usize];
                let sorted = sprites_back_to_front(&r.block.clouds[ci], cam_local);
                for (slot, (i, _)) in slots.iter_mut().zip(sorted) {
                    *slot = state.sprite_base + i as u32;
                }
                dirty_orders.push(state.sprite_base..state.sprite_base + n);
                state.ordered_at = Some((rel, time_s));
                stats.clouds_recomputed += 1;
                stats.sprites_recomputed += n;
            }
            out.push(GpuDrawCloud {
                centre_rel: (-rel).as_vec3().to_array(),
                first: total,
                cloud: state.cloud_slot,
                order_base: state.sprite_base,
                fade_kind,
                fade_progress,
            });
            total += n;
            stats.clouds_drawn += 1;
        }
    }
    locks.end();
    stats.sprites_drawn = total;
    stats.cache_hit_rate = if stats.clouds_drawn == 0 {
        1.0
    } else {
        1.0 - stats.clouds_recomputed as f32 / stats.clouds_drawn as f32
    };
    in_cloud
}

/// An impostor's view from `from_m` (no cache, no locks): the draw list of the blocks `ids`
/// within `draw_m`, back to front, with every cloud's order computed afresh into `orders`.
/// Returns the sprites.
pub(super) fn fresh_view(
    blocks: &Blocks,
    ids: &[u64],
    from_m: DVec3,
    draw_m: f64,
    out: &mut Vec<GpuDrawCloud>,
    orders: &mut Vec<u32>,
) -> u32 {
    out.clear();
    orders.clear();
    let mut cloud_order: Vec<(usize, f64)> = Vec::new();
    for (_, id) in blocks_back_to_front(blocks, ids, from_m) {
        let Some(r) = blocks.get(&id) else {
            continue;
        };
        let offset = r.motion.offset_m;
        let (fade_kind, fade_progress) = fade_code(r.motion.fade);
        cloud_order.clear();
        for (ci, (cloud, state)) in r.block.clouds.iter().zip(&r.clouds).enumerate() {
            let d = (cloud.centre_m + offset - from_m).length();
            if (d - state.radius_m as f64).max(0.0) <= draw_m && !cloud.sprites.is_empty() {
                cloud_order.push((ci, d));
            }
        }
        cloud_order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        for &(ci, _) in &cloud_order {
            let (cloud, state) = (&r.block.clouds[ci], &r.clouds[ci]);
            let rel = from_m - (cloud.centre_m + offset);
            out.push(GpuDrawCloud {
                centre_rel: (-rel).as_vec3().to_array(),
                first: orders.len() as u32,
                cloud: state.cloud_slot,
                order_base: orders.len() as u32,
                fade_kind,
                fade_progress,
            });
            orders.extend(
                sprites_back_to_front(cloud, rel.as_vec3())
                    .into_iter()
                    .map(|(i, _)| state.sprite_base + i as u32),
            );
        }
    }
    orders.len() as u32
}

#[cfg(test)]
#[path = "draw_list_tests.rs"]
mod tests;

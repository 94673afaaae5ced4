//! The CPU side of the cloud sprites (Wang 2003 sections 3.3, 5 and 6.1): each frame, sort blocks,
//! clouds and sprites back to front, face each sprite to the camera (locking its facing when the
//! camera comes within half its radius), shade its four corners, and cache a cloud's corners
//! until the camera has moved or time has passed beyond thresholds that grow with its distance.
//!
//! In: [`SkyBlock`]s, the camera position (f64), the sun direction and the time-of-day light.
//! Out: camera-relative [`GpuSpriteVertex`]es in drawing order and [`FrameStats`]. No wgpu calls.

use std::collections::HashMap;
use std::time::Instant;

use glam::{DVec3, Vec3, Vec4};

use super::gpu_types::GpuSpriteVertex;
use super::scene::{SkyBlock, SkyCloud, SkySprite};
use super::settings::{CloudSettings, RenderSettings, VertexCacheSettings};
use crate::shading::{DirectionalMapping, ForwardScattering, TimeOfDay, vertex_colour};

/// What one frame's update did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameStats {
    /// Sprites sent to the GPU.
    pub sprites_drawn: u32,
    /// Clouds within the draw distance.
    pub clouds_drawn: u32,
    /// Clouds whose vertices were recomputed this frame.
    pub clouds_recomputed: u32,
    /// Sprites of those clouds (the vertex work of the frame).
    pub sprites_recomputed: u32,
    /// Fraction of drawn clouds served from the cache, 0..=1 (1 when nothing was drawn).
    pub cache_hit_rate: f32,
    /// CPU time of the update, microseconds.
    pub cpu_update_us: u64,
    /// How far inside a cloud the camera is, 0..=1.
    pub in_cloud: f32,
    /// Impostors of the far-cloud ring rendered this frame (Wang 6.2), 0..=8.
    pub impostors_rebuilt: u32,
    /// Blocks drawn as sprites (inside the ring, or beyond the 10,000 ft rule).
    pub blocks_near: u32,
    /// Blocks drawn into the impostors of the displayed ring.
    pub blocks_far: u32,
    /// Weight of the new ring while crossfading from the old one, 0..=1 (0 when not fading).
    pub crossfade_weight: f32,
    /// Bytes of the ring's GPU textures and buffers.
    pub ring_gpu_bytes: u64,
}

/// The light a frame is shaded with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Unit vector towards the sun (east, north, up).
    pub sun_dir: Vec3,
    /// Time-of-day light.
    pub time_of_day: TimeOfDay,
    /// Wang's Cmin / Cmedian / Cmax.
    pub mapping: DirectionalMapping,
    /// Light scattered forward towards the eye (the silver lining).
    pub forward: ForwardScattering,
}

/// A sprite corner relative to its cloud centre, as cached.
#[derive(Debug, Clone, Copy)]
struct LocalVertex {
    position_m: Vec3,
    uv: [f32; 2],
    colour: Vec4,
}

/// A locked facing (Wang 3.3): the sprite's right and up axes and its normal towards the camera.
#[derive(Debug, Clone, Copy)]
struct Facing {
    right: Vec3,
    up: Vec3,
    normal: Vec3,
}

#[derive(Debug, Clone, Default)]
struct CacheEntry {
    vertices: Vec<LocalVertex>,
    /// Camera position relative to the cloud centre when computed: a cloud drifting with the
    /// wind and a camera moving are the same to the cache.
    camera_rel_m: DVec3,
    time_s: f64,
    sun_dir: Vec3,
    /// Which cloud this was computed for: its sprite count (a regenerated cloud recomputes).
    fingerprint: usize,
    info: Option<CloudInfo>,
    valid: bool,
}

/// Builds sprite vertices and keeps the per-cloud cache and locked facings.
#[derive(Debug, Default)]
pub struct SpriteVertexBuilder {
    entries: HashMap<(u64, u32), CacheEntry>,
    locks: HashMap<(u64, u32, u32), Facing>,
    vertices: Vec<GpuSpriteVertex>,
    in_cloud_rgb: Vec3,
}

/// Sheet layout: 4 x 4 cells. A small inset keeps mip levels from bleeding across cells.
const SHEET_CELLS: u32 = 4;
const CELL_INSET: f32 = 1.0 / 64.0;

fn cell_uv(cell: u8, corner: [f32; 2]) -> [f32; 2] {
    let c = (cell as u32).min(SHEET_CELLS * SHEET_CELLS - 1);
    let (cx, cy) = ((c % SHEET_CELLS) as f32, (c / SHEET_CELLS) as f32);
    let size = 1.0 / SHEET_CELLS as f32;
    let u = CELL_INSET + corner[0] * (1.0 - 2.0 * CELL_INSET);
    let v = CELL_INSET + corner[1] * (1.0 - 2.0 * CELL_INSET);
    [(cx + u) * size, (cy + v) * size]
}

/// Right/up axes of a sprite facing a viewer along `normal` (towards the viewer), with world up
/// kept up on screen; falls back to east when the viewer is straight above or below.
fn facing_towards(normal: Vec3) -> Facing {
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
/// vertical, so its bottom edge stays level; and its alpha, fading from 1 to 0 as the sine of
/// the view's elevation goes from `fade.0` to `fade.1`.
fn upright_facing(to_cam: Vec3, fade: (f32, f32)) -> (Facing, f32) {
    let level = Vec3::new(to_cam.x, to_cam.y, 0.0);
    let normal = level.normalize_or(Vec3::Y);
    let facing = Facing {
        right: Vec3::Z.cross(normal).normalize_or(Vec3::X),
        up: Vec3::Z,
        normal,
    };
    let sin_elevation = (to_cam.z / to_cam.length().max(1e-3)).abs();
    let alpha = 1.0 - ((sin_elevation - fade.0) / (fade.1 - fade.0).max(1e-4)).clamp(0.0, 1.0);
    (facing, alpha)
}

impl SpriteVertexBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the cached clouds of blocks that are no longer in `blocks` (call when the set
    /// of blocks changes; clouds whose sprite count changed recompute by themselves, and a
    /// drifting cloud is judged by the camera's movement relative to it).
    pub fn retain(&mut self, blocks: &[SkyBlock]) {
        let ids: std::collections::HashSet<u64> = blocks.iter().map(|b| b.id).collect();
        self.entries.retain(|k, _| ids.contains(&k.0));
        self.locks.retain(|k, _| ids.contains(&k.0));
    }

    /// The vertices of the last [`Self::update`], four per sprite, back to front.
    pub fn vertices(&self) -> &[GpuSpriteVertex] {
        &self.vertices
    }

    /// The in-cloud fog colour of the last update (the ambient of the cloud the camera is in).
    pub fn in_cloud_rgb(&self) -> Vec3 {
        self.in_cloud_rgb
    }

    /// Builds this frame's vertices for `camera_m` at `time_s`.
    pub fn update<B: std::borrow::Borrow<SkyBlock>>(
        &mut self,
        blocks: &[B],
        camera_m: DVec3,
        time_s: f64,
        lighting: &Lighting,
        settings: &RenderSettings,
    ) -> FrameStats {
        let start = Instant::now();
        let (clouds, cache) = (&settings.clouds, &settings.vertex_cache);
        let mut stats = FrameStats::default();
        let draw_m = clouds.draw_distance_m as f64;

        // Back to front: blocks, then clouds within a block.
        let block_order = blocks_back_to_front(blocks, camera_m);

        self.vertices.clear();
        for (bi, _) in block_order {
            let block = blocks[bi].borrow();
            // Per-cloud bounds are computed once per cloud (and on each recompute), not per frame.
            let mut cloud_order: Vec<(usize, f64, f64)> = Vec::with_capacity(block.clouds.len());
            for (ci, cloud) in block.clouds.iter().enumerate() {
                let fingerprint = cloud.sprites.len();
                let entry = self.entries.entry((block.id, ci as u32)).or_default();
                if entry.fingerprint != fingerprint || entry.info.is_none() {
                    entry.info = Some(CloudInfo::of(cloud));
                    entry.fingerprint = fingerprint;
                    entry.valid = false;
                }
                let info = entry.info.unwrap_or_default();
                let d = (cloud.centre_m - camera_m).length();
                let near_edge = (d - info.radius_m as f64).max(0.0);
                if near_edge <= draw_m {
                    cloud_order.push((ci, d, near_edge));
                }
            }
            cloud_order.sort_by(|a, b| b.1.total_cmp(&a.1));
            for (ci, _, near_edge_m) in cloud_order {
                let cloud = &block.clouds[ci];
                let Some(entry) = self.entries.get_mut(&(block.id, ci as u32)) else {
                    continue;
                };
                let info = entry.info.unwrap_or_default();
                let inside = info.in_cloud_factor(cloud, camera_m, settings.in_cloud.ramp_fraction);
                if inside > stats.in_cloud {
                    stats.in_cloud = inside;
                    // Fog colour: the cloud's ambient at the camera's height plus the median sun.
                    let tod = &lighting.time_of_day;
                    self.in_cloud_rgb = cloud.colour_levels.at(camera_m.z as f32).truncate()
                        * tod.ambient_percent
                        + tod.directional_rgb * lighting.mapping.c_median;
                }
                let stale = !cache.enabled
                    || !entry.valid
                    || needs_recompute(
                        entry,
                        info.fading,
                        camera_m - cloud.centre_m,
                        time_s,
                        lighting.sun_dir,
                        near_edge_m,
                        cache,
                    );
                if stale {
                    let locks = &mut self.locks;
                    entry.vertices.clear();
                    build_cloud(
                        cloud,
                        (block.id, ci as u32),
                        camera_m,
                        lighting,
                        clouds,
                        locks,
                        &mut entry.vertices,
                    );
                    entry.camera_rel_m = camera_m - cloud.centre_m;
                    entry.time_s = time_s;
                    entry.sun_dir = lighting.sun_dir;
                    entry.info = Some(CloudInfo::of(cloud));
                    entry.valid = true;
                    stats.clouds_recomputed += 1;
                    stats.sprites_recomputed += cloud.sprites.len() as u32;
                }
                stats.clouds_drawn += 1;
                let offset = (cloud.centre_m - camera_m).as_vec3();
                self.vertices
                    .extend(entry.vertices.iter().map(|v| GpuSpriteVertex {
                        position_m: (v.position_m + offset).to_array(),
                        _pad0: 0.0,
                        uv: v.uv,
                        _pad1: [0.0; 2],
                        colour: v.colour.to_array(),
                    }));
            }
        }
        stats.sprites_drawn = (self.vertices.len() / 4) as u32;
        stats.cache_hit_rate = if stats.clouds_drawn == 0 {
            1.0
        } else {
            1.0 - stats.clouds_recomputed as f32 / stats.clouds_drawn as f32
        };
        stats.cpu_update_us = start.elapsed().as_micros() as u64;
        stats
    }
}

/// Wang 6.1: thresholds grow with the cloud's distance; fading clouds age out sooner.
fn needs_recompute(
    entry: &CacheEntry,
    fading: bool,
    camera_rel_m: DVec3,
    time_s: f64,
    sun_dir: Vec3,
    near_edge_m: f64,
    cache: &VertexCacheSettings,
) -> bool {
    let moved_m = (camera_rel_m - entry.camera_rel_m).length();
    let move_limit_m = cache.min_move_m as f64 + cache.move_fraction as f64 * near_edge_m;
    let max_age_s = if fading {
        cache.fading_max_age_s as f64
    } else {
        cache.max_age_s as f64 * (1.0 + near_edge_m / cache.time_distance_m as f64)
    };
    moved_m > move_limit_m
        || time_s - entry.time_s > max_age_s
        || time_s < entry.time_s
        || sun_dir.dot(entry.sun_dir) < 0.999_96 // about half a degree
}

/// A cloud's bounds and state, computed when its vertices are.
#[derive(Debug, Clone, Copy, Default)]
struct CloudInfo {
    radius_m: f32,
    core_half_m: Vec3,
    core_centre_m: Vec3,
    fading: bool,
}

impl CloudInfo {
    fn of(cloud: &SkyCloud) -> Self {
        let (core_half_m, core_centre_m) = cloud.core_box_m();
        Self {
            radius_m: cloud.radius_m(),
            core_half_m,
            core_centre_m,
            fading: cloud.is_fading(),
        }
    }

    /// How far inside the cloud's core box the camera is: 0 outside, rising to 1 over `ramp`
    /// of the half-extent inside the boundary.
    fn in_cloud_factor(&self, cloud: &SkyCloud, camera_m: DVec3, ramp: f32) -> f32 {
        if self.core_half_m.min_element() <= 0.0 {
            return 0.0;
        }
        let rel = (camera_m - cloud.centre_m).as_vec3() - self.core_centre_m;
        // Depth inside the box as a fraction of the half extent, along the tightest axis.
        let inside = (Vec3::ONE - rel.abs() / self.core_half_m).min_element();
        (inside / ramp.max(1e-3)).clamp(0.0, 1.0)
    }
}

/// The blocks' indices, farthest centre from `camera_m` first, with their squared distances
/// (square metres): the first level of the frame's back-to-front sort.
pub fn blocks_back_to_front<B: std::borrow::Borrow<SkyBlock>>(
    blocks: &[B],
    camera_m: DVec3,
) -> Vec<(usize, f64)> {
    let mut order: Vec<(usize, f64)> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| (i, (b.borrow().centre_m - camera_m).length_squared()))
        .collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1));
    order
}

/// The cloud's sprite indices, farthest from the camera first, with their squared distances
/// (square metres; `cam_local_m` is the camera relative to the cloud centre): the last level of
/// the back-to-front sort, run whenever a cloud's vertices are recomputed.
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

/// Faces, shades and sorts one cloud's sprites into `out` (positions relative to the centre).
fn build_cloud(
    cloud: &SkyCloud,
    key: (u64, u32),
    camera_m: DVec3,
    lighting: &Lighting,
    settings: &CloudSettings,
    locks: &mut HashMap<(u64, u32, u32), Facing>,
    out: &mut Vec<LocalVertex>,
) {
    let cam_local = (camera_m - cloud.centre_m).as_vec3();
    let order = sprites_back_to_front(cloud, cam_local);
    let tod = &lighting.time_of_day;
    let lock_start = settings.lock_fade_start_deg.to_radians().cos();
    let lock_end = settings.lock_fade_end_deg.to_radians().cos();
    let upright_fade = (
        settings.upright_fade_start_deg.to_radians().sin(),
        settings.upright_fade_end_deg.to_radians().sin(),
    );
    let cloud_radius = cloud.radius_m().max(1.0);
    for (i, dist2) in order {
        let s = &cloud.sprites[i];
        let to_cam = cam_local - s.offset_m;
        let radius = 0.5 * s.width_m.max(s.height_m);
        let lock_key = (key.0, key.1, i as u32);
        // Upright sprites turn only about the vertical and fade seen from steeply above or below.
        let (face, upright_alpha) = if s.upright {
            upright_facing(to_cam, upright_fade)
        } else {
            (facing_towards(to_cam.normalize_or(Vec3::Y)), 1.0)
        };
        // Wang 3.3: lock the facing inside half the radius; fade with the angle to the camera.
        let (facing, lock_alpha) = if cloud.flat {
            (
                Facing {
                    right: Vec3::X,
                    up: Vec3::Y,
                    normal: Vec3::Z,
                },
                1.0,
            )
        } else if dist2.sqrt() < settings.lock_radius_fraction * radius {
            let f = *locks.entry(lock_key).or_insert(face);
            let cos = f.normal.dot(to_cam.normalize_or(f.normal)).abs();
            let alpha = ((cos - lock_end) / (lock_start - lock_end).max(1e-4)).clamp(0.0, 1.0);
            (f, alpha)
        } else {
            locks.remove(&lock_key);
            (face, 1.0)
        };
        let lock_alpha = lock_alpha * upright_alpha;
        if lock_alpha <= 0.0 || s.alpha_morph <= 0.0 {
            continue;
        }
        let (sin, cos) = s.rotation_deg.to_radians().sin_cos();
        let right = facing.right * cos + facing.up * sin;
        let up = facing.up * cos - facing.right * sin;
        let group = cloud
            .group_centres_m
            .get(s.group as usize)
            .copied()
            .unwrap_or(Vec3::ZERO);
        for corner in [[0.0f32, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]] {
            let p = s.offset_m
                + right * ((corner[0] - 0.5) * s.width_m)
                + up * ((corner[1] - 0.5) * s.height_m);
            let height_msl = cloud.centre_m.z as f32 + p.z;
            let ambient = cloud.colour_levels.at(height_msl);
            let ambient = (ambient.truncate() * tod.ambient_percent).extend(ambient.w);
            let view = (p - cam_local).normalize_or_zero();
            let forward =
                lighting
                    .forward
                    .percent(view, lighting.sun_dir, p.length() / cloud_radius);
            let dir = (crate::shading::directional_percent(
                &lighting.mapping,
                p,
                group,
                lighting.sun_dir,
            ) + forward)
                * tod.directional_rgb;
            let colour = vertex_colour(ambient, dir, s.alpha_morph * lock_alpha);
            // Texture v runs down the sheet: the top of the sprite is v = 0.
            out.push(LocalVertex {
                position_m: p,
                uv: cell_uv(s.cell, [corner[0], 1.0 - corner[1]]),
                colour,
            });
        }
    }
}

/// Index list for `sprites` quads of four vertices (two triangles each).
pub fn quad_indices(sprites: u32) -> Vec<u32> {
    (0..sprites)
        .flat_map(|q| {
            let b = q * 4;
            [b, b + 2, b + 1, b + 1, b + 2, b + 3]
        })
        .collect()
}

/// A sprite convenience for tests and hosts: a square sprite.
pub fn square_sprite(offset_m: Vec3, size_m: f32, cell: u8, group: u16) -> SkySprite {
    SkySprite {
        offset_m,
        width_m: size_m,
        height_m: size_m,
        rotation_deg: 0.0,
        cell,
        group,
        alpha_morph: 1.0,
        upright: false,
    }
}

#[cfg(test)]
#[path = "vertices_tests.rs"]
mod tests;

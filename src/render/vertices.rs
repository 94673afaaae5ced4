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
mod tests {
    use super::*;
    use crate::shading::{ColourLevels, TimeOfDayTable};

    fn blocks() -> Vec<SkyBlock> {
        let cloud = |x: f64| SkyCloud {
            centre_m: DVec3::new(x, 5000.0, 1500.0),
            sprites: (0..20)
                .map(|k| {
                    square_sprite(
                        Vec3::new(k as f32 * 20.0, 0.0, (k % 5) as f32 * 40.0),
                        200.0,
                        k as u8,
                        0,
                    )
                })
                .collect(),
            group_centres_m: vec![Vec3::new(200.0, 0.0, 100.0)],
            colour_levels: ColourLevels::even(1500.0, 1800.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
            flat: false,
        };
        vec![SkyBlock {
            id: 1,
            centre_m: DVec3::new(0.0, 5000.0, 1500.0),
            clouds: (0..10).map(|i| cloud(i as f64 * 1500.0)).collect(),
        }]
    }

    fn lighting() -> Lighting {
        let table = TimeOfDayTable::default();
        Lighting {
            sun_dir: Vec3::new(0.0, -0.6, 0.8),
            time_of_day: table.at(40.0),
            mapping: table.directional_mapping,
            forward: table.forward_scattering,
        }
    }

    #[test]
    fn still_camera_recomputes_nothing_after_the_first_frame_and_a_moved_one_does() {
        let (b, l, s) = (blocks(), lighting(), RenderSettings::default());
        let mut builder = SpriteVertexBuilder::new();
        let cam = DVec3::new(0.0, 0.0, 1000.0);
        let first = builder.update(&b, cam, 0.0, &l, &s);
        assert_eq!(
            (
                first.clouds_drawn,
                first.clouds_recomputed,
                first.sprites_drawn
            ),
            (10, 10, 200)
        );
        let first_vertices = builder.vertices().to_vec();
        for frame in 1..30 {
            let still = builder.update(&b, cam, frame as f64 / 30.0, &l, &s);
            assert_eq!(still.clouds_recomputed, 0, "frame {frame}");
            assert_eq!(still.cache_hit_rate, 1.0);
        }
        assert_eq!(builder.vertices(), &first_vertices[..]);
        // Handing the same blocks again (as a host does when the block set changes) keeps them.
        builder.retain(&b);
        assert_eq!(builder.update(&b, cam, 1.0, &l, &s).clouds_recomputed, 0);
        // Clouds drifting with the wind and a camera flying along with them: nothing moved
        // relative to each other, nothing recomputes.
        let drift = DVec3::new(400.0, -250.0, 0.0);
        let mut drifted = b.clone();
        for c in drifted.iter_mut().flat_map(|b| b.clouds.iter_mut()) {
            c.centre_m += drift;
        }
        assert_eq!(
            builder
                .update(&drifted, cam + drift, 1.0, &l, &s)
                .clouds_recomputed,
            0
        );
        // 300 m is past the threshold of every cloud (at most 5 m + 2% of ~19 km).
        let moved = builder.update(&b, cam + DVec3::new(0.0, 300.0, 0.0), 1.0, &l, &s);
        assert_eq!(moved.clouds_recomputed, 10);
        // 150 m more: past the threshold of the near clouds (about 90 m at 4 km) only, not of
        // the far ones (about 280 m at 14 km).
        let nudged = builder.update(&b, cam + DVec3::new(0.0, 450.0, 0.0), 1.1, &l, &s);
        assert!(
            nudged.clouds_recomputed > 0 && nudged.clouds_recomputed < 10,
            "{nudged:?}"
        );
        // Uncached, every frame recomputes everything.
        let mut off = s;
        off.vertex_cache.enabled = false;
        let again = builder.update(&b, cam + DVec3::new(0.0, 450.0, 0.0), 1.1, &l, &off);
        assert_eq!(again.clouds_recomputed, 10);
    }

    /// Seen with the sun behind it, a cloud's rim is brighter than with the sun behind the
    /// camera by the forward-scattering lobe; its core hardly changes (Wang's shading stays).
    #[test]
    fn the_rim_of_a_cloud_against_the_sun_glows() {
        let b = blocks();
        let s = RenderSettings::default();
        let cam = DVec3::new(0.0, 0.0, 1500.0);
        // The first cloud is 5 km north: the sun low in the north, then low in the south.
        let brightest = |sun_dir: Vec3, forward: ForwardScattering| {
            let l = Lighting {
                sun_dir: sun_dir.normalize(),
                forward,
                ..lighting()
            };
            let mut builder = SpriteVertexBuilder::new();
            builder.update(&b[..], cam, 0.0, &l, &s);
            builder
                .vertices()
                .iter()
                .map(|v| v.colour[0])
                .fold(0.0, f32::max)
        };
        let none = ForwardScattering {
            strength: 0.0,
            ..ForwardScattering::default()
        };
        let on = ForwardScattering::default();
        let against = Vec3::new(0.0, 1.0, 0.05);
        let behind = Vec3::new(0.0, -1.0, 0.05);
        let glow = brightest(against, on) - brightest(against, none);
        let other_way = brightest(behind, on) - brightest(behind, none);
        assert!(glow > 0.1, "against the sun: +{glow}");
        assert!(other_way < 0.01, "sun behind the camera: +{other_way}");
    }

    /// An upright sprite keeps its bottom edge level and turns only about the vertical: seen
    /// from the side it is whole, from 25 degrees below it is fading, from 40 degrees below it is
    /// gone (fade 15..35 degrees); a camera-facing sprite beside it is whole from everywhere.
    #[test]
    fn upright_sprites_stay_level_and_fade_seen_from_below() {
        let mut upright = square_sprite(Vec3::ZERO, 200.0, 3, 0);
        upright.upright = true;
        let cloud = SkyCloud {
            centre_m: DVec3::new(0.0, 3000.0, 1500.0),
            sprites: vec![upright, square_sprite(Vec3::X * 600.0, 200.0, 3, 0)],
            group_centres_m: vec![Vec3::ZERO],
            colour_levels: ColourLevels::even(1400.0, 1700.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
            flat: false,
        };
        let b = vec![SkyBlock {
            id: 1,
            centre_m: cloud.centre_m,
            clouds: vec![cloud],
        }];
        let (l, s) = (lighting(), RenderSettings::default());
        let alphas = |elevation_deg: f64| {
            let cam = DVec3::new(0.0, 3000.0, 1500.0)
                + DVec3::new(0.0, -1.0, 0.0) * 2000.0 * elevation_deg.to_radians().cos()
                - DVec3::Z * 2000.0 * elevation_deg.to_radians().sin();
            let mut builder = SpriteVertexBuilder::new();
            builder.update(&b, cam, 0.0, &l, &s);
            let v = builder.vertices().to_vec();
            // The upright sprite's corners are those nearest x = 0.
            let quads: Vec<&[GpuSpriteVertex]> = v.chunks(4).collect();
            let up = quads
                .iter()
                .find(|q| q[0].position_m[0].abs() < 150.0)
                .copied();
            (up.map(|q| q.to_vec()), quads.len())
        };
        let (side, n) = alphas(0.0);
        let side = side.expect("the upright sprite is drawn from the side");
        assert_eq!(n, 2);
        // Corners: top left, top right, bottom left, bottom right; the bottom edge is level and
        // the quad stands vertical.
        assert!((side[2].position_m[2] - side[3].position_m[2]).abs() < 1e-3);
        assert!((side[0].position_m[1] - side[2].position_m[1]).abs() < 1e-3);
        assert!((side[0].colour[3] - 1.0).abs() < 1e-3);
        let (fading, _) = alphas(25.0);
        let fading = fading.expect("still drawn at 25 degrees");
        assert!(
            fading[0].colour[3] > 0.2 && fading[0].colour[3] < 0.8,
            "{fading:?}"
        );
        assert!((fading[0].position_m[1] - fading[2].position_m[1]).abs() < 1e-3);
        let (gone, n) = alphas(40.0);
        assert!(
            gone.is_none() && n == 1,
            "from 40 degrees below only the other sprite"
        );
    }

    #[test]
    fn sprites_are_sorted_back_to_front_and_face_the_camera() {
        let (b, l, s) = (blocks(), lighting(), RenderSettings::default());
        let mut builder = SpriteVertexBuilder::new();
        builder.update(&b, DVec3::new(0.0, 0.0, 1000.0), 0.0, &l, &s);
        let centres: Vec<Vec3> = builder
            .vertices()
            .chunks_exact(4)
            .map(|q| {
                q.iter()
                    .map(|v| Vec3::from_array(v.position_m))
                    .sum::<Vec3>()
                    / 4.0
            })
            .collect();
        let dists: Vec<f32> = centres.iter().map(|c| c.length()).collect();
        // Clouds are far apart, so the whole list is back to front within a cloud's radius.
        assert!(dists.windows(2).all(|w| w[1] <= w[0] + 400.0), "{dists:?}");
        assert!(dists[0] > dists[dists.len() - 1] + 5000.0);
        for (q, c) in builder.vertices().chunks_exact(4).zip(&centres) {
            let a = Vec3::from_array(q[1].position_m) - Vec3::from_array(q[0].position_m);
            let b = Vec3::from_array(q[2].position_m) - Vec3::from_array(q[0].position_m);
            let normal = a.cross(b).normalize();
            assert!(
                normal.dot(c.normalize()).abs() > 0.999,
                "sprite does not face the camera"
            );
        }
    }

    #[test]
    fn facing_locks_inside_half_the_radius_and_fades_with_the_angle() {
        let (l, s) = (lighting(), RenderSettings::default());
        let cloud = SkyCloud {
            centre_m: DVec3::new(0.0, 0.0, 1000.0),
            sprites: vec![square_sprite(Vec3::ZERO, 200.0, 0, 0)],
            group_centres_m: vec![Vec3::ZERO],
            colour_levels: ColourLevels::even(900.0, 1100.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
            flat: false,
        };
        let b = vec![SkyBlock {
            id: 1,
            centre_m: cloud.centre_m,
            clouds: vec![cloud],
        }];
        let mut builder = SpriteVertexBuilder::new();
        let mut off = s;
        off.vertex_cache.enabled = false;
        // 40 m south of the centre (inside 50 m = half the 100 m radius): locks facing north.
        builder.update(&b, DVec3::new(0.0, -40.0, 1000.0), 0.0, &l, &off);
        let locked: Vec<GpuSpriteVertex> = builder.vertices().to_vec();
        assert_eq!(locked.len(), 4);
        assert!(
            locked.iter().all(|v| (v.position_m[1] - 40.0).abs() < 1e-3),
            "plane faces the camera"
        );
        // Step to 30 m east of the centre, still inside: the facing stays, seen at ~53 degrees.
        builder.update(
            &b,
            DVec3::new(30.0, -40.0 + 40.0 * 0.5, 1000.0),
            0.1,
            &l,
            &off,
        );
        let v = builder.vertices();
        assert_eq!(v.len(), 4);
        let ys: Vec<f32> = v.iter().map(|v| v.position_m[1]).collect();
        assert!(
            ys.windows(2).all(|w| (w[0] - w[1]).abs() < 1e-3),
            "facing stayed locked: {ys:?}"
        );
        assert!(
            v[0].colour[3] < locked[0].colour[3] && v[0].colour[3] > 0.0,
            "faded with the angle"
        );
        // Beside it edge-on: gone.
        builder.update(&b, DVec3::new(45.0, -0.5, 1000.0), 0.2, &l, &off);
        assert!(builder.vertices().is_empty());
        // Out of the lock radius: faces the camera again, opaque.
        builder.update(&b, DVec3::new(300.0, 0.0, 1000.0), 0.3, &l, &off);
        assert_eq!(builder.vertices().len(), 4);
        assert!(
            builder
                .vertices()
                .iter()
                .all(|v| (v.position_m[0] + 300.0).abs() < 1e-3)
        );
    }

    #[test]
    fn far_from_the_origin_the_vertices_are_as_precise_as_near_it() {
        let (l, s) = (lighting(), RenderSettings::default());
        let shifted = |offset: DVec3| -> Vec<GpuSpriteVertex> {
            let mut b = blocks();
            for block in &mut b {
                block.centre_m += offset;
                for c in &mut block.clouds {
                    c.centre_m += offset;
                }
            }
            let mut builder = SpriteVertexBuilder::new();
            builder.update(&b, DVec3::new(0.0, 0.0, 1000.0) + offset, 0.0, &l, &s);
            builder.vertices().to_vec()
        };
        let near = shifted(DVec3::ZERO);
        let far = shifted(DVec3::new(250_000.0, -180_000.0, 0.0));
        assert_eq!(near.len(), far.len());
        for (a, b) in near.iter().zip(&far) {
            let d = Vec3::from_array(a.position_m) - Vec3::from_array(b.position_m);
            assert!(d.length() < 1e-3, "jitter of {} m 300 km out", d.length());
        }
    }
}

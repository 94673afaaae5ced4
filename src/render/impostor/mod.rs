//! The far-cloud impostor ring (Wang 2003 section 6.2). Eight square impostors, each a 45 degree
//! field of view, stand at fixed world positions on a circle of `ring_radius_m` around the ring
//! centre (the camera position when the ring was built), facing it. Blocks beyond the ring radius
//! (up to `view_radius_m`) are drawn into them with the same sprite shader, from the ring centre;
//! blocks inside, and blocks more than `max_height_difference_ft` above or below the camera, are
//! drawn as sprites by the sky.
//!
//! A rebuild starts when the camera has moved `rebuild_move_fraction` of the radius horizontally
//! or `rebuild_climb_fraction` of it vertically, when the sun has turned more than
//! `rebuild_sun_deg`, or when a far block arrived whole, or when the set of far blocks changed
//! otherwise and the ring shown was begun `rebuild_far_change_after_s` ago (until then new far
//! blocks are sprites). It renders one impostor per frame over 8 frames into the second ring,
//! then crossfades old -> new over `crossfade_s`. The very first ring is built in one frame
//! (there is nothing to fade from).
//!
//! In: the sky's blocks, camera, light and frame uniform. Out: which blocks are near (sprites),
//! the impostor render passes, and one full-screen ring pass into the host frame
//! (`shaders/impostor_quad.wgsl`): per pixel it finds where the ray leaves each ring's octagon and
//! mixes the shown ring with the one fading in (`mix(old, new, w)` of premultiplied colour, one
//! pass, so the crossfade never dips towards the background as two blended draws do). Beyond
//! Wang, each impostor also stores the alpha-weighted depth of its clouds: the ring pass
//! reprojects each ray with it (the clouds sit at their depth, not on the quad, so they move with
//! the right parallax as the camera leaves the ring centre and a new ring shows nearly the same
//! picture; this is also Wang's vertical translation of the impostors with the angle between
//! clouds and camera, done per pixel at each cloud's own distance), and the host's depth hides
//! them where its scene is nearer (a mountain beyond the ring radius among far clouds). Rules
//! and geometry: `layout`. Units: metres, degrees.

mod band;
// The ring's settings live here, so the settings tree reads them without the ring.
pub(super) mod layout;
mod order_buffer;
mod orders;
mod ring_pass;
// Which blocks the ring draws and when it rebuilds: the CPU's decision, apart from the GPU work.
mod split;

use split::RingPlan;

use std::cell::Cell;

use glam::{DVec3, Vec3};
use wgpu::util::DeviceExt;

use layout::impostor_camera;
pub use layout::{
    IMPOSTOR_FOV_DEG, IMPOSTORS, ImpostorSettings, impostor_view_proj, is_far, needs_rebuild,
};

use super::gpu_types::{GpuDrawBlock, GpuFrame, GpuListCloud, GpuRing, GpuSpriteVertex};
use super::id_hash::IdSet;
use super::pipeline::{PassDesc, SceneDepth, frame_group, pipeline, premultiplied_over};
use super::sprites::build::{SpriteBuild, chunks};
use super::sprites::resident::ResidentSet;
use super::sprites::settings::VertexCacheSettings;
use super::sprites::sprite_view::{self, ViewBuffers, ViewData, ViewLight};
use super::stats::FrameStats;
use order_buffer::OrderBuffer;
use orders::{RingOrders, RingSort};
use ring_pass::RingPassPipelines;

const IMPOSTOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Alpha-weighted cloud depth, kilometres times alpha (half floats: about 30 m at 60 km).
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

#[derive(Debug, Clone, Default)]
struct RingState {
    centre_m: DVec3,
    sun: Vec3,
    /// Ids of the blocks drawn into this ring (looked up for every block every frame).
    far_ids: IdSet,
    /// Mean distance of those blocks from the centre (the ring radius if none), metres: the
    /// first guess of the ring pass's depth reprojection.
    far_mean_m: f64,
    /// The elevations of those blocks' clouds seen from the centre, radians, lowest first
    /// ([`band::cloud_elevations_rad`]): where the ring pass is drawn.
    content_rad: (f64, f64),
    /// Which build made it (the ring's count of builds then).
    build: u64,
    /// The ring's clock when that build started (orders sorted since are good for it; a change
    /// of the far blocks alone rebuilds `rebuild_far_change_after_s` after it).
    begun_s: f64,
}

struct Build {
    ring: usize,
    next: usize,
    state: RingState,
    /// Each impostor's blocks (of `state.far_ids`, in its sector), found in one pass when the
    /// build starts: the frames that gather its orders look at no other block.
    sectors: [Vec<u64>; IMPOSTORS],
}

/// The ring: two sets of 8 textures (displayed and building), their passes and quads.
pub struct ImpostorRing {
    settings: ImpostorSettings,
    device: wgpu::Device,
    sprite_pipeline: wgpu::RenderPipeline,
    /// The ring pass, into the host's colour or the sky's off-screen cloud target.
    quad_pipelines: RingPassPipelines,
    /// `[ring][impostor]` colour and depth views the impostor passes render into.
    views: Vec<Vec<wgpu::TextureView>>,
    depth_views: Vec<Vec<wgpu::TextureView>>,
    /// `[old ring][new ring]` bind groups of the ring pass (both rings' texture arrays).
    quad_groups: Vec<Vec<wgpu::BindGroup>>,
    /// Per impostor of each ring (`[ring * IMPOSTORS + impostor]`): frame uniform, its bind
    /// group, and its view of the resident sprites (draw list and cloud lists from the ring
    /// centre; the sprite orders are the ring's `order_buffer`).
    slot_frames: Vec<wgpu::Buffer>,
    slot_groups: Vec<wgpu::BindGroup>,
    slot_views: Vec<ViewBuffers>,
    view_layout: wgpu::BindGroupLayout,
    draws: Vec<GpuDrawBlock>,
    lists: Vec<GpuListCloud>,
    /// The ring pass's uniform (`GpuRing`).
    ring_uniform: wgpu::Buffer,
    /// Which blocks the ring holds, the rings shown, built and fading, the renders pending:
    /// the CPU's decisions, plain data ([`RingPlan::split`]).
    plan: RingPlan,
    /// This frame's ring pass: (old ring, new ring, whether the new one fades in, the rows of
    /// the screen where it can show a cloud as normalised device y, lowest first), if any ring
    /// is shown and crosses the screen.
    quads: Option<(usize, usize, bool, (f32, f32))>,
    /// The screen's grid of rays that finds those rows, kept while the camera does not turn.
    screen: band::ScreenGrid,
    /// Whether the plan's pending renders went into a recorded frame (then the next plan
    /// starts afresh).
    recorded: Cell<bool>,
    /// How far the ring reaches at most, metres, below its view radius (`None`: the view
    /// radius): while the far field is drawn, the end of its hand-over band, beyond which the
    /// ring's blocks would be built faded out to nothing.
    reach_limit_m: Option<f64>,
    bytes: u64,
    /// The far clouds' orders from the ring centre, kept between builds, and their GPU copy.
    sorts: RingOrders,
    /// `None` for a ring made without impostors.
    order_buffer: Option<OrderBuffer>,
}

const SPRITES_WGSL: &str = include_str!("../../../shaders/sprites.wgsl");
const IMPOSTOR_SPRITES_WGSL: &str = include_str!("../../../shaders/impostor_sprites.wgsl");

/// What a frame's impostor builds need from the sky.
#[derive(Clone, Copy)]
pub(super) struct RingFrame<'a> {
    /// The sky's blocks on the GPU.
    pub resident: &'a ResidentSet,
    /// The sky's frame uniform (light, haze); the view is replaced per impostor.
    pub template: &'a GpuFrame,
    /// The light of the frame's sprites (the camera height is replaced per ring).
    pub view: &'a ViewLight<'a>,
    /// Camera position, metres.
    pub camera_m: DVec3,
    /// The order cache's settings, whose `max_sorted_sprites_per_frame` the ring's sorting
    /// shares with the sky camera's.
    pub cache: &'a VertexCacheSettings,
}

/// The layouts and resources of the sky the ring shares.
pub struct RingShared<'a> {
    /// The host's colour and depth targets (the ring's quads are drawn into them).
    pub targets: super::targets::HostTargets,
    /// Group 0 of the impostor renders (frame uniform, a single-sample scene depth).
    pub frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 0 of the passes into the host's targets (its depth, multisampled or not).
    pub host_frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 1 of the sprite pass (sheet and sampler).
    pub sheet_layout: &'a wgpu::BindGroupLayout,
    /// The targets of the sky's off-screen cloud pass (colour, distance), where the clouds are
    /// drawn below full resolution; the ring then draws there.
    pub cloud_targets: Option<&'a [(wgpu::TextureFormat, Option<wgpu::BlendState>)]>,
    /// The build pass's group of a view (uniform, draw list, cloud lists, orders).
    pub view_layout: &'a wgpu::BindGroupLayout,
}

impl ImpostorRing {
    /// Creates the textures, pipelines and buffers (nothing when the ring is disabled).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        settings: ImpostorSettings,
        shared: &RingShared,
    ) -> Self {
        let array_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        };
        let tex_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ring.texture_layout"),
            entries: &[
                array_entry(0),
                array_entry(1),
                array_entry(2),
                array_entry(3),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                // The ring uniform: the vertex stage hands the rings' centres on to the
                // fragment stage (`impostor_quad.wgsl`, `RingOut`).
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let over = Some(premultiplied_over());
        let sprite_pipeline = pipeline(
            device,
            &PassDesc {
                label: "ring.sprites",
                wgsl: &format!("{SPRITES_WGSL}\n{IMPOSTOR_SPRITES_WGSL}"),
                vs: "vs_sprite",
                fs: "fs_sprite_impostor",
                bind_groups: &[Some(shared.frame_layout), Some(shared.sheet_layout)],
                buffers: &[Some(GpuSpriteVertex::layout())],
                targets: &[(IMPOSTOR_FORMAT, over), (DEPTH_FORMAT, over)],
                samples: 1,
                scene: SceneDepth::Host,
            },
        );
        let quad_pipelines = RingPassPipelines::new(device, shared, &tex_layout);
        let rings = if settings.enabled { 2 } else { 0 };
        let side = settings.size_px;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("ring.sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let mut bytes = 0u64;
        let mut views = Vec::new();
        let mut depth_views = Vec::new();
        let mut arrays = Vec::new();
        for r in 0..rings {
            // One texture array per ring and kind: layer `i` is impostor `i`.
            let make = |what: &str, format| {
                let texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(&format!("ring.{r}.{what}")),
                    size: wgpu::Extent3d {
                        width: side,
                        height: side,
                        depth_or_array_layers: IMPOSTORS as u32,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                });
                let layers: Vec<wgpu::TextureView> = (0..IMPOSTORS as u32)
                    .map(|i| {
                        texture.create_view(&wgpu::TextureViewDescriptor {
                            dimension: Some(wgpu::TextureViewDimension::D2),
                            base_array_layer: i,
                            array_layer_count: Some(1),
                            ..Default::default()
                        })
                    })
                    .collect();
                let array = texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                });
                (layers, array)
            };
            let (colour_layers, colour) = make("colour", IMPOSTOR_FORMAT);
            let (depth_layers, depth) = make("depth", DEPTH_FORMAT);
            bytes += side as u64 * side as u64 * (4 + 2) * IMPOSTORS as u64;
            views.push(colour_layers);
            depth_views.push(depth_layers);
            arrays.push((colour, depth));
        }
        let ring_uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ring.uniform"),
            size: std::mem::size_of::<GpuRing>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // `[old][new]`: the shown ring and the one fading in (the same one when not fading).
        let quad_groups = arrays
            .iter()
            .map(|old| {
                arrays
                    .iter()
                    .map(|new| {
                        let view = |binding, view| wgpu::BindGroupEntry {
                            binding,
                            resource: wgpu::BindingResource::TextureView(view),
                        };
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("ring.quad_group"),
                            layout: &tex_layout,
                            entries: &[
                                view(0, &old.0),
                                view(1, &old.1),
                                view(2, &new.0),
                                view(3, &new.1),
                                wgpu::BindGroupEntry {
                                    binding: 4,
                                    resource: wgpu::BindingResource::Sampler(&sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 5,
                                    resource: ring_uniform.as_entire_binding(),
                                },
                            ],
                        })
                    })
                    .collect()
            })
            .collect();
        // The impostor passes have no scene: a depth of 1 (the far plane) everywhere. One slot
        // per impostor of each ring, so that a build into one ring never rewrites what a render
        // of the other, still to be recorded, reads.
        let slots = rings * IMPOSTORS;
        let no_scene = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("ring.no_scene_depth"),
                size: wgpu::Extent3d {
                    width: side,
                    height: side,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&vec![1.0f32; (side * side) as usize]),
        );
        if settings.enabled {
            bytes += side as u64 * side as u64 * 4;
        }
        let no_scene_view = no_scene.create_view(&wgpu::TextureViewDescriptor::default());
        let mut slot_frames = Vec::new();
        let mut slot_groups = Vec::new();
        for _ in 0..slots {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("ring.frame"),
                size: std::mem::size_of::<GpuFrame>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            slot_groups.push(frame_group(
                device,
                "ring.frame_group",
                shared.frame_layout,
                &buffer,
                &no_scene_view,
            ));
            bytes += buffer.size();
            slot_frames.push(buffer);
        }
        Self {
            settings,
            device: device.clone(),
            sprite_pipeline,
            quad_pipelines,
            views,
            depth_views,
            quad_groups,
            slot_views: (0..slots).map(|_| ViewBuffers::new(device, true)).collect(),
            slot_frames,
            slot_groups,
            view_layout: shared.view_layout.clone(),
            draws: Vec::new(),
            lists: Vec::new(),
            ring_uniform,
            plan: RingPlan::default(),
            quads: None,
            screen: band::ScreenGrid::default(),
            recorded: Cell::new(false),
            reach_limit_m: None,
            bytes,
            sorts: RingOrders::default(),
            order_buffer: (slots > 0).then(|| OrderBuffer::new(device)),
        }
    }

    /// Switches the ring off (every block drawn as sprites) or back on (built afresh from the
    /// next frame, as at the start). Returns false and changes nothing when turning on a ring
    /// made without impostors: their textures are made at start-up only.
    pub fn set_enabled(&mut self, enabled: bool) -> bool {
        if enabled && self.views.is_empty() {
            return false;
        }
        self.settings.enabled = enabled;
        self.plan.shown = None;
        self.plan.fade = None;
        self.plan.build = None;
        self.plan.pending.clear();
        true
    }

    /// Bytes of the ring's textures and buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.bytes
            + self
                .slot_views
                .iter()
                .map(ViewBuffers::gpu_bytes)
                .sum::<u64>()
            + self.order_buffer.as_ref().map_or(0, OrderBuffer::gpu_bytes)
            + if self.settings.enabled {
                self.ring_uniform.size()
            } else {
                0
            }
    }

    /// Limits how far the ring reaches (`None`: its view radius) to the hand-over band
    /// `(start, end)`. While the far field is drawn, the sprites, and the impostors built from
    /// them, fade out by the end of the band: the ring's blocks beyond it would be sorted and
    /// drawn into the impostors to show nothing. A change of the limit changes the far set, so
    /// the ring is rebuilt.
    pub(super) fn set_reach_limit(&mut self, band_m: Option<(f64, f64)>) {
        self.reach_limit_m = band_m.map(|(_, end)| end);
        self.plan.half_faded_m = band_m.map(|(start, end)| 0.5 * (start + end));
    }

    /// The settings with the view radius cut to the reach limit (kept beyond the ring radius).
    fn reach_settings(&self) -> ImpostorSettings {
        let mut s = self.settings;
        if let Some(limit) = self.reach_limit_m {
            s.view_radius_m = s.view_radius_m.min(limit.max(s.ring_radius_m * 1.01));
        }
        s
    }

    /// The ids of the blocks this view draws as sprites this frame (decided by [`Self::split`]).
    pub(super) fn near(&self) -> &[u64] {
        &self.plan.near
    }

    /// Writes this frame's impostor builds (all 8 for a first ring, else the next one whose
    /// sprite orders are all sorted): each sector's draw list and sprite orders from the ring
    /// centre, with its uniforms; lays out the quads and fills the ring's frame stats. The
    /// orders are sorted within what `stats.sprites_recomputed` left of the frame's sorting
    /// budget (a first ring, with nothing to show meanwhile, is sorted whole). Returns the bytes
    /// written.
    pub(super) fn prepare_builds(
        &mut self,
        queue: &wgpu::Queue,
        frame_in: &RingFrame,
        stats: &mut FrameStats,
    ) -> u64 {
        let RingFrame {
            resident,
            template,
            view,
            camera_m,
            cache,
        } = *frame_in;
        let blocks = &resident.blocks;
        self.quads = None;
        stats.ring_gpu_bytes = self.gpu_bytes();
        if !self.settings.enabled {
            stats.blocks_near = blocks.len() as u32;
            return 0;
        }
        let mut bytes = 0;
        let first = self.plan.shown.is_none() && self.plan.fade.is_none();
        let view_radius_m = self.reach_settings().view_radius_m;
        // (A ring with a build has impostors, and so an order buffer.)
        if let Some(order_buffer) = self.order_buffer.as_mut()
            && let Some(mut build) = self.plan.build.take()
        {
            let slots = resident.orders_cpu.len() as u32;
            bytes += order_buffer.fit(&self.device, queue, &mut self.sorts, slots);
            let (count, mut budget, largest) = if first {
                (IMPOSTORS, u32::MAX, u32::MAX)
            } else {
                let whole = cache.max_sorted_sprites_per_frame;
                (1, whole.saturating_sub(stats.sprites_recomputed), whole)
            };
            // The far clouds' own move threshold (`order_move_fraction`).
            let ring_cache = VertexCacheSettings {
                move_fraction: self
                    .settings
                    .order_move_fraction
                    .map_or(cache.move_fraction, |f| f as f32),
                ..*cache
            };
            let mut when = RingSort {
                gather: 0,
                since_s: build.state.begun_s,
                time_s: self.plan.clock_s,
                cache: &ring_cache,
                largest,
            };
            let reach = (build.state.centre_m, view_radius_m);
            let mut rendered = 0;
            for _ in 0..count {
                let i = build.next;
                let centre = build.state.centre_m;
                let sector = &build.sectors[i];
                when.gather = self.plan.builds * IMPOSTORS as u64 + i as u64;
                let (sorted_all, sorted) =
                    self.sorts.sort(blocks, sector, reach, &when, &mut budget);
                stats.ring_sprites_sorted += sorted;
                if !sorted_all {
                    // The rest next frame; the shown ring stays meanwhile.
                    break;
                }
                let sprites =
                    (self.sorts).view(blocks, sector, reach, &mut self.draws, &mut self.lists);
                let light = ViewLight {
                    camera_z_m: centre.z as f32,
                    farthest_m: view_radius_m as f32,
                    ..*view
                };
                let header = sprite_view::header(&light);
                let slot = build.ring * IMPOSTORS + i;
                bytes += self.slot_views[slot].write(
                    &self.device,
                    queue,
                    &self.view_layout,
                    &header,
                    None,
                    ViewData::Own {
                        counts: [self.draws.len() as u32, 0, sprites, 0],
                        draws: &self.draws,
                        lists: &self.lists,
                        orders: order_buffer.buffer(),
                    },
                );
                let cam = impostor_camera(i, centre, &self.settings);
                let vp = cam.view_proj_relative();
                let frame = GpuFrame {
                    view_proj: vp.to_cols_array_2d(),
                    inv_view_proj: vp.inverse().to_cols_array_2d(),
                    in_cloud_rgba: [0.0; 4],
                    // Its own standard-Z view over a scene of nothing (a depth of 1 everywhere).
                    params: [
                        1.0,
                        template.params[1],
                        template.params[2],
                        template.params[3],
                    ],
                    depth_to_view: cam.sky_view().depth_to_view(),
                    ..*template
                };
                queue.write_buffer(&self.slot_frames[slot], 0, bytemuck::bytes_of(&frame));
                bytes += std::mem::size_of::<GpuFrame>() as u64;
                self.plan.pending.push((build.ring, i, sprites));
                build.next += 1;
                rendered += 1;
            }
            stats.impostors_rebuilt = rendered;
            if build.next >= IMPOSTORS {
                if first {
                    self.plan.shown = Some((build.ring, build.state));
                } else {
                    self.plan.fade = Some((build.ring, build.state, 0.0));
                }
            } else {
                self.plan.build = Some(build);
            }
        }
        // The orders this frame's sorts and views wrote, as a patch; sent on frames with none
        // too, so that a patch already applied is not recorded again.
        if let Some(order_buffer) = self.order_buffer.as_mut() {
            let (sent, rewritten) = order_buffer.send(&self.device, queue, &mut self.sorts);
            bytes += sent;
            stats.ring_orders_rewritten = rewritten;
        }
        // The ring pass: the shown ring, mixed with the one fading in by the crossfade weight.
        let w = self.plan.fade.as_ref().map_or(0.0, |f| f.2);
        stats.crossfade_weight = w as f32;
        if let Some((old, old_state)) = &self.plan.shown {
            let (new, new_state) =
                (self.plan.fade.as_ref()).map_or((*old, old_state), |(r, st, _)| (*r, st));
            let half = self.settings.ring_radius_m * (IMPOSTOR_FOV_DEG * 0.5).to_radians().tan();
            let band_of = |state: &RingState| {
                let (radius_m, size_px) = (self.settings.ring_radius_m, self.settings.size_px);
                band::ring_band_rad(
                    state.content_rad,
                    camera_m - state.centre_m,
                    radius_m,
                    size_px,
                )
            };
            let band = if w > 0.0 {
                band::union(band_of(old_state), band_of(new_state))
            } else {
                band_of(old_state)
            };
            let inv_view_proj = glam::Mat4::from_cols_array_2d(&template.inv_view_proj);
            self.screen.aim(inv_view_proj);
            let rows = self.screen.rows_ndc(band);
            let uniform = GpuRing {
                old_centre_weight: (old_state.centre_m - camera_m)
                    .as_vec3()
                    .extend(w as f32)
                    .to_array(),
                new_centre: (new_state.centre_m - camera_m)
                    .as_vec3()
                    .extend(0.0)
                    .to_array(),
                size: [
                    self.settings.ring_radius_m as f32,
                    half as f32,
                    old_state.far_mean_m as f32,
                    new_state.far_mean_m as f32,
                ],
            };
            queue.write_buffer(&self.ring_uniform, 0, bytemuck::bytes_of(&uniform));
            bytes += std::mem::size_of::<GpuRing>() as u64;
            self.quads = rows.map(|rows| (*old, new, w > 0.0, rows));
        }
        stats.blocks_far = self.plan.blocks_far;
        stats.blocks_near = blocks.len() as u32 - self.plan.blocks_far;
        bytes
    }

    /// What of a frame's sorting budget (`whole` sprites) the ring keeps from the sky camera:
    /// half while it rebuilds a ring with one shown, so that a sky camera whose clouds want more
    /// than the budget for a long while (blocks forming all around) cannot hold the rebuild up;
    /// else nothing. The ring also sorts whatever the camera leaves of its share.
    pub(super) fn sort_reserve(&self, whole: u32) -> u32 {
        let shown = self.plan.shown.is_some() || self.plan.fade.is_some();
        if self.settings.enabled && shown && self.plan.build.is_some() {
            whole / 2
        } else {
            0
        }
    }

    /// The most sprites one of the impostor renders to record draws.
    pub(super) fn most_sprites_pending(&self) -> u32 {
        self.plan.pending.iter().map(|p| p.2).max().unwrap_or(0)
    }

    /// Records the impostor renders prepared since the last recorded frame (their own passes,
    /// before the sky pass, in the host's encoder): each sector's corners built from the
    /// resident sprites (`resident`) by `build`, then drawn (`indices`: the quad index buffer).
    /// A frame that is prepared and never recorded leaves its renders to the next recorded one,
    /// ahead of any ring pass that shows them.
    pub(super) fn record_builds(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        sheet: &wgpu::BindGroup,
        build: &SpriteBuild,
        resident: &wgpu::BindGroup,
        indices: &wgpu::Buffer,
    ) {
        self.recorded.set(true);
        if let Some(order_buffer) = &self.order_buffer {
            order_buffer.record(encoder);
        }
        for &(r, i, sprites) in &self.plan.pending {
            let slot = r * IMPOSTORS + i;
            let view = self.slot_views[slot].group().filter(|_| sprites > 0);
            let parts: Vec<(u32, u32, u32)> = chunks(sprites).collect();
            // The impostor is cleared, then its sprites drawn a chunk at a time.
            for k in 0..parts.len().max(1) {
                let part = parts.get(k).copied();
                if let (Some(view), Some((c, _, n))) = (view, part) {
                    build.record(encoder, view, resident, (c, n));
                }
                let load = if k == 0 {
                    wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
                } else {
                    wgpu::LoadOp::Load
                };
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("ring.impostor"),
                    color_attachments: &[&self.views[r][i], &self.depth_views[r][i]].map(|view| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load,
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    }),
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if let (Some(_), Some((_, _, n))) = (view, part) {
                    pass.set_pipeline(&self.sprite_pipeline);
                    pass.set_bind_group(0, &self.slot_groups[slot], &[]);
                    pass.set_bind_group(1, sheet, &[]);
                    pass.set_vertex_buffer(0, build.vertices().slice(..));
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..n * 6, 0, 0..1);
                }
            }
        }
    }

    /// Draws the ring into the sky pass (group 0, the sky's frame, must be bound): one
    /// full-screen pass that mixes the shown ring with the one fading in, scissored to the rows
    /// where it can show a cloud. `offscreen`: the pass is the sky's cloud target (colour and
    /// distance), not the host's colour; `size`: that target's, pixels (the scissor is put back
    /// to all of it).
    pub fn draw(&self, pass: &mut wgpu::RenderPass, offscreen: bool, (width, height): (u32, u32)) {
        let Some((old, new, fading, (low, high))) = self.quads else {
            return;
        };
        // Normalised device y up, rows down; whole rows, rounded outwards.
        let row = |y: f32| (1.0 - y) * 0.5 * height as f32;
        let top = (row(high).floor().max(0.0) as u32).min(height);
        let bottom = (row(low).ceil().max(0.0) as u32).min(height);
        if bottom <= top {
            return;
        }
        pass.set_scissor_rect(0, top, width, bottom - top);
        pass.set_pipeline(self.quad_pipelines.get(offscreen, fading));
        pass.set_bind_group(1, &self.quad_groups[old][new], &[]);
        pass.draw(0..3, 0..1);
        pass.set_scissor_rect(0, 0, width, height);
    }
}

//! The far-cloud impostor ring (Wang 2003 section 6.2). Eight square impostors, each a 45 degree
//! field of view, stand at fixed world positions on a circle of `ring_radius_m` around the ring
//! centre (the camera position when the ring was built), facing it. Blocks beyond the ring radius
//! (up to `view_radius_m`) are drawn into them with the same sprite shader, from the ring centre;
//! blocks inside, and blocks more than `max_height_difference_ft` above or below the camera, are
//! drawn as sprites by the sky.
//!
//! A rebuild starts when the camera has moved `rebuild_move_fraction` of the radius horizontally
//! or `rebuild_climb_fraction` of it vertically, when the sun has turned more than
//! `rebuild_sun_deg`, or when the set of far blocks changed. It renders one impostor per frame
//! over 8 frames into the second ring, then crossfades old -> new over `crossfade_s`. The very
//! first ring is built in one frame (there is nothing to fade from).
//!
//! In: the sky's blocks, camera, light and frame uniform. Out: which blocks are near (sprites),
//! the impostor render passes, and the quads drawn into the host frame. Beyond Wang, each
//! impostor also stores the alpha-weighted depth of its clouds, so the quads put their clouds
//! back at that depth and the host's depth hides them where its scene is nearer (a mountain
//! beyond the ring radius among far clouds). Rules and geometry: `layout`. Units: metres, degrees.

mod layout;

use std::collections::BTreeSet;

use glam::{DVec3, Vec3};
use wgpu::util::DeviceExt;

pub use layout::{
    IMPOSTOR_FOV_DEG, IMPOSTORS, ImpostorSettings, impostor_view_proj, is_far, needs_rebuild,
};
use layout::{QuadVertex, impostor_camera, in_sector, quad_corners};

use super::gpu_types::{GpuFrame, GpuSpriteVertex};
use super::scene::SkyBlock;
use super::settings::RenderSettings;
use super::vertices::{FrameStats, Lighting, SpriteVertexBuilder, quad_indices};

const IMPOSTOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Alpha-weighted cloud depth, kilometres times alpha (half floats: about 30 m at 60 km).
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

#[derive(Debug, Clone, Default)]
struct RingState {
    centre_m: DVec3,
    sun: Vec3,
    /// Ids of the blocks drawn into this ring.
    far_ids: BTreeSet<u64>,
}

struct Build {
    ring: usize,
    next: usize,
    state: RingState,
}

/// The ring: two sets of 8 textures (displayed and building), their passes and quads.
pub struct ImpostorRing {
    settings: ImpostorSettings,
    device: wgpu::Device,
    sprite_pipeline: wgpu::RenderPipeline,
    quad_pipeline: wgpu::RenderPipeline,
    /// `[ring][impostor]` colour views and their bind groups for the quad pass.
    views: Vec<Vec<wgpu::TextureView>>,
    depth_views: Vec<Vec<wgpu::TextureView>>,
    quad_groups: Vec<Vec<wgpu::BindGroup>>,
    /// Per impostor slot: frame uniform, its bind group, vertices and sprite count.
    slot_frames: Vec<wgpu::Buffer>,
    slot_groups: Vec<wgpu::BindGroup>,
    slot_vertices: Vec<wgpu::Buffer>,
    index_buffer: wgpu::Buffer,
    capacity_sprites: u32,
    quad_buffer: wgpu::Buffer,
    builder: SpriteVertexBuilder,
    shown: Option<(usize, RingState)>,
    build: Option<Build>,
    /// The ring fading in and the fade so far, 0..=1.
    fade: Option<(usize, RingState, f64)>,
    /// This frame's impostor renders: (ring, impostor, sprites).
    pending: Vec<(usize, usize, u32)>,
    /// This frame's quads: (ring, impostor, first vertex).
    quads: Vec<(usize, usize, u32)>,
    bytes: u64,
}

const SHARED_WGSL: &str = include_str!("../../../shaders/shared/frame.wgsl");
const SPRITES_WGSL: &str = include_str!("../../../shaders/sprites.wgsl");
const IMPOSTOR_SPRITES_WGSL: &str = include_str!("../../../shaders/impostor_sprites.wgsl");
const QUAD_WGSL: &str = include_str!("../../../shaders/impostor_quad.wgsl");

/// What a frame's impostor builds need from the sky.
#[derive(Clone, Copy)]
pub struct RingFrame<'a> {
    /// All blocks of the sky.
    pub blocks: &'a [SkyBlock],
    /// The sky's frame uniform (light, haze); the view is replaced per impostor.
    pub template: &'a GpuFrame,
    /// The light of the frame.
    pub lighting: &'a Lighting,
    /// Sky time, seconds.
    pub time_s: f64,
    /// Renderer settings.
    pub render: &'a RenderSettings,
    /// Camera position, metres.
    pub camera_m: DVec3,
}

/// The layouts and resources of the sky the ring shares.
pub struct RingShared<'a> {
    /// Format of the host colour target.
    pub colour_format: wgpu::TextureFormat,
    /// Group 0 of the sky passes (frame uniform and scene depth).
    pub frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 1 of the sprite pass (sheet and sampler).
    pub sheet_layout: &'a wgpu::BindGroupLayout,
    /// Premultiplied-over blending.
    pub blend: wgpu::BlendState,
}

impl ImpostorRing {
    /// Creates the textures, pipelines and buffers (nothing when the ring is disabled).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        settings: ImpostorSettings,
        shared: &RingShared,
    ) -> Self {
        let module = |label: &str, wgsl: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(format!("{SHARED_WGSL}\n{wgsl}").into()),
            })
        };
        let tex_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ring.texture_layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline = |label: &str,
                        wgsl: &str,
                        vs: &str,
                        fs: &str,
                        layouts: &[Option<&wgpu::BindGroupLayout>],
                        buffer: wgpu::VertexBufferLayout,
                        formats: &[wgpu::TextureFormat]| {
            let m = module(label, wgsl);
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: layouts,
                immediate_size: 0,
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &m,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[Some(buffer)],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &m,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &formats
                        .iter()
                        .map(|&format| {
                            Some(wgpu::ColorTargetState {
                                format,
                                blend: Some(shared.blend),
                                write_mask: wgpu::ColorWrites::ALL,
                            })
                        })
                        .collect::<Vec<_>>(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let sprite_pipeline = pipeline(
            "ring.sprites",
            &format!("{SPRITES_WGSL}\n{IMPOSTOR_SPRITES_WGSL}"),
            "vs_sprite",
            "fs_sprite_impostor",
            &[Some(shared.frame_layout), Some(shared.sheet_layout)],
            GpuSpriteVertex::layout(),
            &[IMPOSTOR_FORMAT, DEPTH_FORMAT],
        );
        const QUAD_ATTRS: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x2, 2 => Float32, 3 => Float32x3, 4 => Float32
        ];
        let quad_pipeline = pipeline(
            "ring.quads",
            QUAD_WGSL,
            "vs_impostor",
            "fs_impostor",
            &[Some(shared.frame_layout), Some(&tex_layout)],
            wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<QuadVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &QUAD_ATTRS,
            },
            &[shared.colour_format],
        );
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
        let mut quad_groups = Vec::new();
        for r in 0..rings {
            let mut vs = Vec::new();
            let mut ds = Vec::new();
            let mut gs = Vec::new();
            for i in 0..IMPOSTORS {
                let make = |what: &str, format| {
                    device
                        .create_texture(&wgpu::TextureDescriptor {
                            label: Some(&format!("ring.{r}.impostor.{i}.{what}")),
                            size: wgpu::Extent3d {
                                width: side,
                                height: side,
                                depth_or_array_layers: 1,
                            },
                            mip_level_count: 1,
                            sample_count: 1,
                            dimension: wgpu::TextureDimension::D2,
                            format,
                            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                                | wgpu::TextureUsages::TEXTURE_BINDING,
                            view_formats: &[],
                        })
                        .create_view(&wgpu::TextureViewDescriptor::default())
                };
                let view = make("colour", IMPOSTOR_FORMAT);
                let depth = make("depth", DEPTH_FORMAT);
                bytes += side as u64 * side as u64 * (4 + 2);
                gs.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("ring.quad_group"),
                    layout: &tex_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::Sampler(&sampler),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(&depth),
                        },
                    ],
                }));
                ds.push(depth);
                vs.push(view);
            }
            views.push(vs);
            depth_views.push(ds);
            quad_groups.push(gs);
        }
        // The impostor passes have no scene: a depth of 1 (the far plane) everywhere.
        let slots = if settings.enabled { IMPOSTORS } else { 0 };
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
            slot_groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("ring.frame_group"),
                layout: shared.frame_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&no_scene_view),
                    },
                ],
            }));
            bytes += buffer.size();
            slot_frames.push(buffer);
        }
        let quad_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ring.quads"),
            size: (2 * IMPOSTORS * 6 * std::mem::size_of::<QuadVertex>()) as u64,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut ring = Self {
            settings,
            device: device.clone(),
            sprite_pipeline,
            quad_pipeline,
            views,
            depth_views,
            quad_groups,
            slot_frames,
            slot_groups,
            slot_vertices: Vec::new(),
            index_buffer: quad_buffer.clone(),
            capacity_sprites: 0,
            quad_buffer,
            builder: SpriteVertexBuilder::new(),
            shown: None,
            build: None,
            fade: None,
            pending: Vec::new(),
            quads: Vec::new(),
            bytes,
        };
        ring.grow(if settings.enabled { 1024 } else { 0 });
        ring
    }

    fn grow(&mut self, sprites: u32) {
        let bytes = |b: &wgpu::Buffer| b.size();
        let old: u64 = self.slot_vertices.iter().map(bytes).sum::<u64>()
            + if self.capacity_sprites > 0 {
                self.index_buffer.size()
            } else {
                0
            };
        self.capacity_sprites = sprites;
        let slots = self.slot_frames.len();
        self.slot_vertices = (0..slots)
            .map(|_| {
                self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("ring.sprite_vertices"),
                    size: sprites as u64 * 4 * std::mem::size_of::<GpuSpriteVertex>() as u64,
                    usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })
            .collect();
        if sprites > 0 {
            self.index_buffer = self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("ring.sprite_indices"),
                    contents: bytemuck::cast_slice(&quad_indices(sprites)),
                    usage: wgpu::BufferUsages::INDEX,
                });
        }
        let new: u64 = self.slot_vertices.iter().map(bytes).sum::<u64>()
            + if sprites > 0 {
                self.index_buffer.size()
            } else {
                0
            };
        self.bytes = self.bytes + new - old;
    }

    /// Bytes of the ring's textures and buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.bytes
            + if self.settings.enabled {
                self.quad_buffer.size()
            } else {
                0
            }
    }

    /// Decides this frame's near blocks (indices into `blocks`, drawn as sprites) and starts or
    /// advances a rebuild. Call [`Self::prepare_builds`] after, with the frame's uniform.
    pub fn split(
        &mut self,
        blocks: &[SkyBlock],
        camera_m: DVec3,
        sun: Vec3,
        dt_s: f64,
    ) -> Vec<usize> {
        let s = self.settings;
        if !s.enabled {
            return (0..blocks.len()).collect();
        }
        // Advance the crossfade; a finished fade makes the new ring the shown one.
        if let Some((ring, state, w)) = self.fade.take() {
            let w = if s.crossfade_s > 0.0 {
                w + dt_s.max(0.0) / s.crossfade_s
            } else {
                1.0
            };
            if w >= 1.0 {
                self.shown = Some((ring, state));
            } else {
                self.fade = Some((ring, state, w));
            }
        }
        let newest = self
            .fade
            .as_ref()
            .map(|(_, st, _)| st)
            .or(self.shown.as_ref().map(|(_, st)| st));
        if self.build.is_none() {
            let start = match newest {
                None => true,
                Some(st) if self.fade.is_none() => {
                    let far_now: BTreeSet<u64> = blocks
                        .iter()
                        .filter(|b| is_far(b, st.centre_m, camera_m, &s))
                        .map(|b| b.id)
                        .collect();
                    needs_rebuild(st.centre_m, st.sun, camera_m, sun, &s) || far_now != st.far_ids
                }
                Some(_) => false,
            };
            if start {
                let ring = self.shown.as_ref().map_or(0, |(r, _)| 1 - r);
                let far_ids = blocks
                    .iter()
                    .filter(|b| is_far(b, camera_m, camera_m, &s))
                    .map(|b| b.id)
                    .collect();
                self.build = Some(Build {
                    ring,
                    next: 0,
                    state: RingState {
                        centre_m: camera_m,
                        sun,
                        far_ids,
                    },
                });
            }
        }
        let far = self
            .fade
            .as_ref()
            .map(|(_, st, _)| &st.far_ids)
            .or(self.shown.as_ref().map(|(_, st)| &st.far_ids));
        // Before the first ring exists it is built this frame, so its blocks are far already.
        let far = far.or(self.build.as_ref().map(|b| &b.state.far_ids));
        (0..blocks.len())
            .filter(|&i| far.is_none_or(|f| !f.contains(&blocks[i].id)))
            .collect()
    }

    /// Builds this frame's impostor vertices (all 8 for a first ring, else the next one),
    /// uploads them with their uniforms, lays out the quads, and fills the ring's frame stats.
    pub fn prepare_builds(
        &mut self,
        queue: &wgpu::Queue,
        frame_in: &RingFrame,
        stats: &mut FrameStats,
    ) {
        let RingFrame {
            blocks,
            template,
            lighting,
            time_s,
            render,
            camera_m,
        } = *frame_in;
        self.pending.clear();
        self.quads.clear();
        stats.ring_gpu_bytes = self.gpu_bytes();
        if !self.settings.enabled {
            stats.blocks_near = blocks.len() as u32;
            return;
        }
        let first = self.shown.is_none() && self.fade.is_none();
        if let Some(mut build) = self.build.take() {
            let count = if first { IMPOSTORS } else { 1 };
            let mut settings = *render;
            settings.clouds.draw_distance_m = self.settings.view_radius_m as f32;
            settings.vertex_cache.enabled = false;
            for _ in 0..count {
                let i = build.next;
                let centre = build.state.centre_m;
                let sector: Vec<&SkyBlock> = blocks
                    .iter()
                    .filter(|b| build.state.far_ids.contains(&b.id))
                    .filter(|b| in_sector(i, centre, b.centre_m))
                    .collect();
                self.builder
                    .update(&sector, centre, time_s, lighting, &settings);
                let sprites = (self.builder.vertices().len() / 4) as u32;
                if sprites > self.capacity_sprites {
                    self.grow(sprites.next_power_of_two());
                }
                if sprites > 0 {
                    let vertices = bytemuck::cast_slice(self.builder.vertices());
                    queue.write_buffer(&self.slot_vertices[i], 0, vertices);
                }
                let cam = impostor_camera(i, centre, &self.settings);
                let vp = cam.view_proj_relative();
                let frame = GpuFrame {
                    view_proj: vp.to_cols_array_2d(),
                    inv_view_proj: vp.inverse().to_cols_array_2d(),
                    in_cloud_rgba: [0.0; 4],
                    params: [
                        cam.near_m,
                        cam.far_m,
                        template.params[2],
                        template.params[3],
                    ],
                    ..*template
                };
                queue.write_buffer(&self.slot_frames[i], 0, bytemuck::bytes_of(&frame));
                self.pending.push((build.ring, i, sprites));
                build.next += 1;
            }
            stats.impostors_rebuilt = count as u32;
            if build.next >= IMPOSTORS {
                if first {
                    self.shown = Some((build.ring, build.state));
                } else {
                    self.fade = Some((build.ring, build.state, 0.0));
                }
            } else {
                self.build = Some(build);
            }
        }
        // Quads: the shown ring (fading out while a new one fades in), then the new one.
        let mut corners = Vec::with_capacity(2 * IMPOSTORS * 6);
        let w = self.fade.as_ref().map_or(0.0, |f| f.2);
        stats.crossfade_weight = w as f32;
        let mut rings: Vec<(usize, DVec3, f32)> = Vec::new();
        if let Some((r, st)) = &self.shown {
            rings.push((*r, st.centre_m, (1.0 - w) as f32));
        }
        if let Some((r, st, _)) = &self.fade {
            rings.push((*r, st.centre_m, w as f32));
        }
        for (r, centre, weight) in rings {
            for i in 0..IMPOSTORS {
                let first_vertex = corners.len() as u32;
                corners.extend(quad_corners(i, centre - camera_m, &self.settings, weight));
                self.quads.push((r, i, first_vertex));
            }
        }
        if !corners.is_empty() {
            queue.write_buffer(&self.quad_buffer, 0, bytemuck::cast_slice(&corners));
        }
        let far = self
            .fade
            .as_ref()
            .map(|(_, st, _)| &st.far_ids)
            .or(self.shown.as_ref().map(|(_, st)| &st.far_ids));
        let far_count = far.map_or(0, |f| blocks.iter().filter(|b| f.contains(&b.id)).count());
        stats.blocks_far = far_count as u32;
        stats.blocks_near = (blocks.len() - far_count) as u32;
    }

    /// Records this frame's impostor renders (their own passes, before the sky pass).
    pub fn record_builds(&self, encoder: &mut wgpu::CommandEncoder, sheet: &wgpu::BindGroup) {
        for &(r, i, sprites) in &self.pending {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ring.impostor"),
                color_attachments: &[&self.views[r][i], &self.depth_views[r][i]].map(|view| {
                    Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })
                }),
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if sprites > 0 {
                pass.set_pipeline(&self.sprite_pipeline);
                pass.set_bind_group(0, &self.slot_groups[i], &[]);
                pass.set_bind_group(1, sheet, &[]);
                pass.set_vertex_buffer(0, self.slot_vertices[i].slice(..));
                pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..sprites * 6, 0, 0..1);
            }
        }
    }

    /// Draws the ring's quads into the sky pass (group 0, the sky's frame, must be bound).
    pub fn draw(&self, pass: &mut wgpu::RenderPass) {
        if self.quads.is_empty() {
            return;
        }
        pass.set_pipeline(&self.quad_pipeline);
        pass.set_vertex_buffer(0, self.quad_buffer.slice(..));
        for &(r, i, first) in &self.quads {
            pass.set_bind_group(1, &self.quad_groups[r][i], &[]);
            pass.draw(first..first + 6, 0..1);
        }
    }
}

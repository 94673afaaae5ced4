//! Cloud shadows on the host's ground: the clouds drawn from the sun into a shadow map, which a
//! host looks up with a matrix and multiplies into its direct sunlight (`exp(-tau)`).
//!
//! In: the GPU-resident sprites (`resident`), the sun, the camera and the clouds' drift. Out: an
//! R16Float texture of the optical depth `tau` of the clouds along the sun's ray through each
//! texel, and the matrix from a camera-relative position to its texture coordinates
//! ([`CloudShadowMap`]). The draw (`shaders/cloud_shadow.wgsl`, pass `sky.cloud_shadow`) is
//! orthographic along the sun's rays: the build pass (`cs_build_cores` in
//! `shaders/sprite_build.wgsl`) makes a quad facing the sun around each sprite's dense core
//! (`clouds::core`, what every probe asks), with its formation and dissipation fade (so the
//! shadows fade with the clouds), and each fragment adds the optical depth of its ray inside
//! the core, the probes' extinction times the length (Beer's law; additive, so no sort is
//! needed): `World::sun_occlusion` reads what the map holds.
//! Its own draw list and cloud lists (every cloud of the blocks it covers, a few tens of KB)
//! take each cloud's sprites in their slots' order (not the camera's sort, which would change
//! the half-float sums as the camera moves), so it holds nothing per sprite.
//!
//! The map covers a square across the sun's rays around the camera (`half_extent_m`, at least
//! the sprites' draw distance), centred on a texel of a grid fixed to the world, so a camera
//! moving within a texel leaves every shadow as it was (no shimmer). It is drawn again after
//! `update_interval_s` of sky time while a cloud it covers forms or dissipates, when the camera has gone
//! `recentre_fraction` of the half extent, the sun has turned `rebuild_sun_deg`, or a block
//! that may shadow the ground within `full_detail_m` of the camera went; a block that arrives
//! is added to the map (its own sprites drawn over it, the sums being additive), and one that
//! goes farther off keeps its shadow until the next drawing. With the sun below 1 degree the
//! map is drawn empty. Between draws the lookup matrix moves the map with the clouds' drift
//! (SilverLining reuses its map across frames the same way). Its last texels are faded out, so
//! the shadows end softly at the map's edge. Geometry and rules: `layout`. Units: metres.

// The map's settings live here, so the settings tree reads them without the map.
pub(super) mod layout;
// The map's own view of the resident sprites (its draw list and cloud lists), written when a
// drawing is decided.
mod view;

use std::cell::Cell;

use glam::{DVec3, Mat4, Vec3};

pub use layout::{EYE_DISTANCE_M, MAX_SIZE_PX, ShadowFrame, ShadowSettings, needs_redraw};

use super::RenderError;
use super::gpu_types::{GpuDrawBlock, GpuListCloud, GpuSpriteVertex};
use super::id_hash::{IdMap, IdSet};
use super::sprites::build::{SpriteBuild, chunks};
use super::sprites::draw_list::Blocks;
use super::sprites::resident::{ResidentSet, storage_buffer};
use super::sprites::sprite_view::{ViewBuffers, ViewLight};
use super::stats::FrameStats;

const WGSL: &str = include_str!("../../../shaders/cloud_shadow.wgsl");
/// Optical depth along the sun's ray, summed (half floats: a thousandth at tau 1).
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// A far fade beyond any sprite (finite: the fade's smoothstep divides by its length).
const NO_FAR_FADE_M: f32 = 1.0e9;

/// The shadow pass's uniform. Keep in sync with `ShadowFrame` in `shaders/cloud_shadow.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuCloudShadow {
    /// Positions relative to the draw's eye to clip space (orthographic along the rays).
    clip_from_eye: [[f32; 4]; 4],
    /// x: optical depth per metre of cloud core along the ray (the probes' extinction times
    /// the settings' `opacity_scale`, less as the sun nears the horizon); y: the fraction of
    /// the map across which its edge fades out; zw unused.
    params: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuCloudShadow>() == 80);

/// What a host needs to put the clouds' shadows on its ground (from [`super::Sky::cloud_shadows`]).
///
/// Per fragment of ground at `q` metres from the camera (the camera of the last prepared
/// frame): `uv = (uv_from_camera_relative * vec4(q, 1)).xy`, `tau` the texture sampled there
/// (linear filtering, clamped to its edge: its border texels hold 0), and the direct sun
/// multiplied by `exp(-tau)`; the ambient light stays. Switched off, the texture is a single
/// texel of 0: the same lookup finds open sun everywhere, and the ground has the clear sun
/// ([`super::Sky::light`]) everywhere, as open ground does with the map on.
#[derive(Debug, Clone, Copy)]
pub struct CloudShadowMap<'a> {
    /// The optical depth of the clouds along the sun's ray ([`SHADOW_FORMAT`], filterable).
    /// It can be replaced when the shadows are switched on or off: take it every frame.
    pub view: &'a wgpu::TextureView,
    /// From a position relative to the camera (east, north, up metres; w 1) to the map's
    /// texture coordinates in x and y (v down the texture); z 0, w 1.
    pub uv_from_camera_relative: Mat4,
    /// Side of the map, texels.
    pub size_px: u32,
    /// Metres a texel covers across the sun's rays.
    pub texel_m: f32,
    /// Whether the map is drawn (false: open sun everywhere).
    pub enabled: bool,
}

/// The shadow map's optical depth read back (tests and tools).
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowImage {
    /// Side, texels.
    pub size_px: u32,
    /// Optical depth along the sun's ray, row-major from the top left (v = 0).
    pub tau: Vec<f32>,
}

impl ShadowImage {
    /// The optical depth at texture coordinates `uv`, filtered as a host's linear sampler
    /// clamped to the edge does.
    pub fn sample(&self, uv: glam::Vec2) -> f32 {
        let n = self.size_px as i64;
        let at = |x: i64, y: i64| self.tau[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
        let p = uv * self.size_px as f32 - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
        let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// The map: its texture, pipeline, view of the resident sprites and when it was drawn.
pub struct CloudShadows {
    settings: ShadowSettings,
    /// Optical depth per metre inside a cloud's cores: the probes' (3 / the in-cloud
    /// visibility), so the map and `World::sun_occlusion` answer from the same clouds.
    extinction_per_m: f32,
    device: wgpu::Device,
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    view_layout: wgpu::BindGroupLayout,
    sprites_view: ViewBuffers,
    draws: Vec<GpuDrawBlock>,
    lists: Vec<GpuListCloud>,
    /// Per block drawn: its clouds' lists as last built, with the placing and stride they were
    /// built for and their sprites. A drawing copies a block's lists when both stand (a whole
    /// drawing, every second while clouds form, read every cloud of every block it covers).
    kept_lists: IdMap<KeptLists>,
    /// The cloud lists on the GPU (grown in powers of two) and how many times it was replaced
    /// (the view's group is made anew then).
    list_buffer: wgpu::Buffer,
    list_buffers_made: u64,
    /// The last drawing: where it stood, the sky time and the clouds' drift then.
    drawn: Option<(ShadowFrame, f64, DVec3)>,
    /// The blocks whose shadows the map holds (by id): their centre and radius when drawn.
    /// Blocks that arrive later are added to the map; one that leaves is kept there until the
    /// next whole drawing unless its shadow lies within `full_detail_m`.
    in_map: IdMap<(DVec3, f64)>,
    /// Whether this frame's draw adds to the map (blocks that arrived) rather than clearing it.
    adding: bool,
    /// Counts whole drawings.
    drawings: u64,
    /// The last look over every block the sky holds, while it still holds.
    cover: Option<CoverCheck>,
    /// Draw the map at the next prepare whatever changed ([`Self::redraw`]).
    force: bool,
    /// The clouds' drift now ([`super::Sky::set_drift`]).
    drift_m: DVec3,
    /// This frame's draw: its sprites, if the map is drawn this frame.
    pending: Option<u32>,
    lookup: Mat4,
    /// GPU time of the draw (two timestamps around it), while the sky's passes are timed, and
    /// whether the last prepared frame drew it.
    timer: Option<super::Timestamps>,
    timed: Cell<bool>,
}

/// What a look over every block the sky holds found for the map's drawing: the blocks the map
/// holds that are no longer covered, and whether a covered block forms or dissipates. Looked
/// at again only when a block came, went, was written, moved or changed its fade, or the drift
/// moved a texel, or the map was drawn anew: a frame of a steady sky walks none of its
/// thousands of blocks for the map.
#[derive(Debug)]
struct CoverCheck {
    /// `ResidentSet::changes` and `fades`, the whole drawing, and the drift it was made at.
    changes: u64,
    fades: u64,
    drawing: u64,
    drift_m: DVec3,
    /// The blocks of `in_map` left out of the cover then: their centre and radius when drawn.
    gone: Vec<(DVec3, f64)>,
    changing: bool,
}

/// The built corners as the shadow pass reads them: `GpuSpriteVertex`'s position, uv, how many
/// sprites it stands for, and colour (its alpha).
fn shadow_vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRS: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
        0 => Float32x4, 1 => Float32x2, 2 => Float32x4, 3 => Float32x2
    ];
    // Offsets: position 0, uv 16, stands_for 24, colour 32 (`GpuSpriteVertex`).
    const PLACED: [wgpu::VertexAttribute; 4] = [
        ATTRS[0],
        wgpu::VertexAttribute {
            offset: 16,
            ..ATTRS[1]
        },
        wgpu::VertexAttribute {
            offset: 32,
            ..ATTRS[2]
        },
        wgpu::VertexAttribute {
            offset: 24,
            ..ATTRS[3]
        },
    ];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuSpriteVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &PLACED,
    }
}

/// A texture of `side` x `side` texels of optical depth.
fn shadow_texture(device: &wgpu::Device, side: u32) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("sky.cloud_shadow"),
        size: wgpu::Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SHADOW_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    (texture, view)
}

impl CloudShadows {
    /// The pipeline (groups: its uniform, the sprite sheet of `sheet_layout`) and the texture
    /// (a cleared texel while switched off). `view_layout`: the build pass's view group;
    /// `in_cloud_visibility_m`: the visibility inside a cloud (`[in_cloud]`).
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (settings, in_cloud_visibility_m): (ShadowSettings, f32),
        sheet_layout: &wgpu::BindGroupLayout,
        view_layout: &wgpu::BindGroupLayout,
    ) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.cloud_shadow"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.cloud_shadow"),
            size: std::mem::size_of::<GpuCloudShadow>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.cloud_shadow"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sky.cloud_shadow"),
            bind_group_layouts: &[Some(&layout), Some(sheet_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sky.cloud_shadow"),
            source: wgpu::ShaderSource::Wgsl(WGSL.into()),
        });
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sky.cloud_shadow"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &[Some(shadow_vertex_layout())],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_shadow"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: SHADOW_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: add,
                        alpha: add,
                    }),
                    write_mask: wgpu::ColorWrites::RED,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let (texture, view) = shadow_texture(device, 1);
        let mut shadows = Self {
            settings,
            extinction_per_m: 3.0 / in_cloud_visibility_m.max(1e-3),
            device: device.clone(),
            pipeline,
            uniform,
            group,
            texture,
            view,
            view_layout: view_layout.clone(),
            sprites_view: ViewBuffers::new(device, false),
            draws: Vec::new(),
            lists: Vec::new(),
            kept_lists: IdMap::default(),
            list_buffer: storage_buffer(device, "sky.cloud_shadow_lists", 4096 * 16),
            list_buffers_made: 0,
            drawn: None,
            in_map: IdMap::default(),
            adding: false,
            drawings: 0,
            cover: None,
            force: false,
            drift_m: DVec3::ZERO,
            pending: None,
            lookup: Mat4::ZERO,
            timer: None,
            timed: Cell::new(false),
        };
        shadows.set_enabled(queue, settings.enabled);
        shadows
    }

    /// Switches the map on (drawn from the next prepared frame) or off (a single texel of 0:
    /// open sun everywhere, no memory taken).
    pub fn set_enabled(&mut self, queue: &wgpu::Queue, enabled: bool) {
        self.settings.enabled = enabled;
        let side = if enabled { self.settings.size_px } else { 1 };
        (self.texture, self.view) = shadow_texture(&self.device, side);
        self.drawn = None;
        if !enabled {
            // Cleared: a texel of tau 0.
            queue.write_texture(
                self.texture.as_image_copy(),
                &[0u8; 2],
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(2),
                    rows_per_image: None,
                },
                wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
            );
        }
    }

    /// Draws the map at the next prepare whatever changed (a host that moved its clouds by
    /// other means than the drift, tests).
    pub fn redraw(&mut self) {
        self.force = true;
    }

    /// The settings in use.
    pub fn settings(&self) -> &ShadowSettings {
        &self.settings
    }

    /// The clouds' drift now (one offset for every block, as [`super::Sky::set_drift`] sets
    /// it): between draws the map moves with it.
    pub fn set_drift(&mut self, offset_m: DVec3) {
        self.drift_m = offset_m;
    }

    /// Bytes of its texture and buffers.
    pub fn gpu_bytes(&self) -> u64 {
        let side = self.texture.width() as u64;
        let view = if self.settings.enabled {
            self.sprites_view.gpu_bytes()
        } else {
            0
        };
        side * side * 2 + self.uniform.size() + view + self.list_buffer.size()
    }

    /// The map and its lookup for the last prepared frame.
    pub fn map(&self) -> CloudShadowMap<'_> {
        CloudShadowMap {
            view: &self.view,
            uv_from_camera_relative: self.lookup,
            size_px: self.texture.width(),
            texel_m: self.settings.texel_m() as f32,
            enabled: self.settings.enabled,
        }
    }

    /// Decides whether the map is drawn this frame and, if so, writes its view of the resident
    /// sprites (`resident`, lit as `light` says) and its uniform; sets the lookup for the camera
    /// at `camera_m`. Returns the bytes written. Call [`Self::record`] after, in the frame's
    /// own submission, after the patch of the resident orders.
    pub(super) fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        (camera_m, sun, now_s): (DVec3, Vec3, f64),
        stats: &mut FrameStats,
    ) -> u64 {
        self.pending = None;
        self.timed.set(false);
        stats.shadow_gpu_bytes = self.gpu_bytes();
        if !self.settings.enabled {
            self.lookup = Mat4::ZERO;
            return 0;
        }
        let sun = sun.as_dvec3();
        let s = self.settings;
        let blocks = &resident.blocks;
        // A whole drawing when the map is due (moved, turned, aged, forced) or a block whose
        // shadow lies near was taken away; else only the blocks that arrived since are drawn,
        // added to the map (the sums are additive): a block arriving at the edge of the sprites'
        // reach no longer costs a drawing of every cloud (most frames of the storm bench did).
        let mut added: Option<IdSet> = None;
        // The shadows fade out as the sun nears the horizon (they would reach for ever); with
        // it below 1 degree nothing shows, and the map is drawn with no sprite.
        let sun_up = smoothstep(1.0f64.to_radians().sin(), 5.0f64.to_radians().sin(), sun.z);
        let dark = sun_up <= 0.0;
        let stale = match &self.drawn {
            None => true,
            Some((frame, at_s, _)) => {
                let same = self.cover.as_ref().is_some_and(|c| {
                    c.changes == resident.changes
                        && c.fades == resident.fades
                        && c.drawing == self.drawings
                        && (c.drift_m - self.drift_m).length() <= s.texel_m()
                });
                let mut arrived = IdSet::default();
                if !same {
                    let (now, changing) = covered(blocks, frame);
                    let gone = self
                        .in_map
                        .iter()
                        .filter(|(id, _)| !now.contains(id))
                        .map(|(_, &place)| place)
                        .collect();
                    arrived = now
                        .iter()
                        .filter(|id| !self.in_map.contains_key(id))
                        .copied()
                        .collect();
                    self.cover = Some(CoverCheck {
                        changes: resident.changes,
                        fades: resident.fades,
                        drawing: self.drawings,
                        drift_m: self.drift_m,
                        gone,
                        changing,
                    });
                }
                let (gone, changing) = self
                    .cover
                    .as_ref()
                    .map_or((&[][..], false), |c| (&c.gone[..], c.changing));
                let times = (*at_s, now_s);
                let due = std::mem::take(&mut self.force)
                    || needs_redraw(frame, times, camera_m, sun, changing, &s);
                let near_gone = gone
                    .iter()
                    .any(|&(centre, radius)| shadow_is_near(frame, centre, radius, camera_m, &s));
                // Nothing to add or take away while the sun is too low for shadows (the map
                // is drawn empty then).
                let near_gone = near_gone && !dark;
                if !(due || near_gone || dark || arrived.is_empty()) {
                    added = Some(arrived);
                } else if !arrived.is_empty() {
                    // Not added now: looked for again next frame.
                    self.cover = None;
                }
                due || near_gone
            }
        };
        let mut bytes = 0;
        if let (false, Some(arrived), Some((frame, _, drift_then))) = (stale, &added, self.drawn) {
            // The new blocks where they stood when the map was drawn (the lookup moves the map
            // with the drift since).
            let back = self.drift_m - drift_then;
            let sprites = self.shadow_view(blocks, &frame, Some(arrived), back, false);
            bytes += self.write_view(queue, resident, light, &frame, sprites);
            for r in blocks.values().filter(|r| arrived.contains(&r.block.id)) {
                self.in_map
                    .insert(r.block.id, (r.centre_m() - back, r.radius_m));
            }
            self.adding = true;
            self.pending = Some(sprites);
            self.timed.set(self.timer.is_some());
            stats.shadow_sprites = sprites;
        }
        if stale {
            // The sun of the last drawing until it has turned `rebuild_sun_deg` (a shadow 2 km
            // under its cloud moves 17 m at 0.5 degrees): the sun a host gives follows the
            // camera's place and time, and a map turned by a millionth of a radian puts its
            // sprites' edges across other texels' centres.
            let sun = match &self.drawn {
                Some((f, _, _)) if f.sun.angle_between(sun).to_degrees() <= s.rebuild_sun_deg => {
                    f.sun
                }
                _ => sun,
            };
            let frame = ShadowFrame::new(camera_m, sun, &s);
            let sprites = self.shadow_view(blocks, &frame, None, DVec3::ZERO, dark);
            self.in_map = blocks
                .values()
                .filter(|r| is_covered(r, &frame) && !dark)
                .map(|r| (r.block.id, (r.centre_m(), r.radius_m)))
                .collect();
            bytes += self.write_view(queue, resident, light, &frame, sprites);
            // The fade of the drawing's own sun (the last one's, within `rebuild_sun_deg`).
            let sun_up = smoothstep(1.0f64.to_radians().sin(), 5.0f64.to_radians().sin(), sun.z);
            let uniform = GpuCloudShadow {
                clip_from_eye: frame.clip_from_eye_relative().to_cols_array_2d(),
                params: [
                    self.extinction_per_m * s.opacity_scale * sun_up as f32,
                    0.05,
                    0.0,
                    0.0,
                ],
            };
            queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
            bytes += std::mem::size_of::<GpuCloudShadow>() as u64;
            self.drawn = Some((frame, now_s, self.drift_m));
            self.drawings += 1;
            self.adding = false;
            self.pending = Some(sprites);
            self.timed.set(self.timer.is_some());
            stats.shadow_sprites = sprites;
        }
        if let Some((frame, _, drift_then)) = &self.drawn {
            self.lookup = frame.uv_from_camera_relative(camera_m, self.drift_m - *drift_then);
        }
        stats.shadow_redrawn = stale || added.is_some();
        stats.shadow_gpu_bytes = self.gpu_bytes();
        bytes
    }

    /// The sprites of this frame's draw (0 if the map is not drawn this frame).
    pub(super) fn pending_sprites(&self) -> u32 {
        self.pending.unwrap_or(0)
    }

    /// Whether the map is drawn this frame.
    pub(super) fn has_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Records this frame's draw, if any (its own passes, in the sky's submission before the
    /// host's frame): the map cleared, then the sprites' corners built from the resident
    /// sprites (`resident`) by `build` and drawn a chunk at a time (`indices`: the quad index
    /// buffer; `sheet`: the sprite sheet's group).
    pub(super) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        sheet: &wgpu::BindGroup,
        build: &SpriteBuild,
        resident: &wgpu::BindGroup,
        indices: &wgpu::Buffer,
    ) {
        let Some(sprites) = self.pending else {
            return;
        };
        let timer = self.timer.as_ref().filter(|_| self.timed.get());
        if let Some(t) = timer {
            t.write(encoder, 0);
        }
        let view = self.sprites_view.group().filter(|_| sprites > 0);
        let parts: Vec<(u32, u32, u32)> = chunks(sprites).collect();
        for k in 0..parts.len().max(1) {
            let part = parts.get(k).copied();
            if let (Some(view), Some((c, _, n))) = (view, part) {
                build.record_cores(encoder, view, resident, (c, n));
            }
            let load = if k == 0 && !self.adding {
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
            } else {
                wgpu::LoadOp::Load
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sky.cloud_shadow"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if let (Some(_), Some((_, _, n))) = (view, part) {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &self.group, &[]);
                pass.set_bind_group(1, sheet, &[]);
                pass.set_vertex_buffer(0, build.vertices().slice(..));
                pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..n * 6, 0, 0..1);
            }
        }
        if let Some(t) = timer {
            t.write(encoder, 1);
            t.resolve(encoder);
        }
    }

    /// Times the draw on the GPU (two timestamps around it) from the next frame on, or stops.
    pub(super) fn set_timing(&mut self, queue: &wgpu::Queue, on: bool) {
        self.timer = if on {
            super::Timestamps::new(&self.device, queue, "sky.cloud_shadow_time", 2)
        } else {
            None
        };
    }

    /// GPU milliseconds of the last prepared frame's draw (0 if it drew none), once submitted;
    /// `None` while not timing. Waits for the device.
    pub(super) fn last_ms(&self) -> Option<f64> {
        let timer = self.timer.as_ref()?;
        if !self.timed.get() {
            return Some(0.0);
        }
        timer.read_ms(&self.device)?.get(1).copied()
    }

    /// Reads the map back (tests and tools): waits for the device.
    pub fn read_back(&self, queue: &wgpu::Queue) -> Result<ShadowImage, RenderError> {
        let side = self.texture.width();
        let row = (side * 2).div_ceil(256) * 256;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.cloud_shadow_read"),
            size: row as u64 * side as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            self.texture.size(),
        );
        queue.submit([encoder.finish()]);
        buffer.map_async(wgpu::MapMode::Read, .., |_| {});
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let data = buffer
            .get_mapped_range(..)
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let tau = data
            .chunks_exact(row as usize)
            .flat_map(|r| {
                r[..side as usize * 2]
                    .chunks_exact(2)
                    .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
            })
            .collect();
        Ok(ShadowImage { size_px: side, tau })
    }
}

/// Whether a block (placed on the GPU) may cast a shadow into the map: its sphere's shadow
/// reaches the square across the rays.
fn is_covered(r: &super::sprites::resident::Resident, frame: &ShadowFrame) -> bool {
    if r.place.is_none() || !r.uploaded {
        return false;
    }
    let (x, y) = frame.across(r.centre_m());
    let reach = frame.half_extent_m + r.radius_m;
    x.abs() <= reach && y.abs() <= reach
}

/// Whether a block's shadow (centre and radius, placed) lies within `full_detail_m` of the
/// map's centre across the rays.
fn is_near(frame: &ShadowFrame, centre_m: DVec3, radius_m: f64, s: &ShadowSettings) -> bool {
    let (x, y) = frame.across(centre_m);
    x.abs().max(y.abs()) - radius_m <= s.full_detail_m
}

/// Whether a block (its centre and radius, placed) may shadow the ground within
/// `full_detail_m` of the camera: its centre that close to the camera's sun ray across the
/// rays, and not down-sun of the camera (its shadow then falls farther from the sun).
fn shadow_is_near(
    frame: &ShadowFrame,
    centre_m: DVec3,
    radius_m: f64,
    camera_m: DVec3,
    s: &ShadowSettings,
) -> bool {
    let to = centre_m - camera_m;
    let sunward = to.dot(frame.sun);
    let across = (to - frame.sun * sunward).length();
    sunward >= -radius_m && across - radius_m <= s.full_detail_m
}

/// The blocks a drawing at `frame` covers (their ids), and whether any of them forms or
/// dissipates.
fn covered(blocks: &Blocks, frame: &ShadowFrame) -> (IdSet, bool) {
    let mut changing = false;
    let ids = blocks
        .values()
        .filter(|r| is_covered(r, frame))
        .map(|r| {
            changing |= r.motion.fade != super::Fade::Steady;
            r.block.id
        })
        .collect();
    (ids, changing)
}

/// A block's cloud lists for the shadow map, kept between drawings.
#[derive(Debug, Default)]
struct KeptLists {
    /// The block's placing and the stride the lists were built for.
    built_for: Option<(u64, u32)>,
    lists: Vec<GpuListCloud>,
    /// The sprites they draw.
    sprites: u32,
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

//! [`Sky`]: the sky's GPU side (the whole frame step around it is
//! [`SkySystem`](crate::SkySystem)'s). Created once with the host's device,
//! given clouds (uploaded to the GPU once per block), and each frame `prepare`d (CPU: sort blocks
//! and clouds, the cached sprite orders, the draw list; uniforms) and `record`ed into the host's
//! encoder. It draws into the host's colour target and reads the host's depth texture (never
//! writes it): the sky gradient and sun where the host drew nothing, the cloud sprites with soft
//! depth fades (Bahnassi), and in-cloud fog (Wang 7.1).
//!
//! The device needs 7 storage buffers per shader stage (WebGPU's default limit is 8) and compute
//! shaders. The host's depth texture needs `TEXTURE_BINDING` usage; it is read through the
//! host's own projection ([`SkyView`]) in the convention its [`HostTargets`] name (standard or
//! reversed Z, one sample or four). Where it also has `RENDER_ATTACHMENT` usage (a depth buffer
//! the host draws into) and no stencil, the full-screen passes that draw only where the host drew
//! nothing (the sky background, the cloud composite's sky) are also depth-tested against it as a
//! read-only attachment: a software rasteriser then shades only those pixels, while a shader's
//! own test runs the whole shader on every pixel.

use std::collections::HashSet;

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::RenderError;
use super::cloud_target::can_test_against;
use super::gpu_types::{GpuFrame, GpuSpriteVertex};
use super::impostor::RingFrame;
use super::overhead_ease::OverheadEase;
use super::pass_timing::{STAMPS, Stamp};
use super::pipeline::{
    PassDesc, SceneDepth, background_test, frame_group, pipeline, pipeline_with_depth,
    premultiplied_over,
};
use super::scene::{BlockMotion, SkyBlock};
use super::settings::RenderSettings;
use super::sprites::build::{CHUNK, SpriteBuild, chunks};
use super::sprites::draw_list::{Copies, Locks, main_view};
use super::sprites::resident::{ResidentSet, quad_index_buffer};
use super::sprites::scatter::Scatter;
use super::sprites::sprite_view::{self, ViewData, ViewLight};
use super::stats::{FrameStats, Lighting, SkyMemory, Spent, Stopwatch};
use super::targets::{self, HostTargets, SkyView};
use super::view::{View, ViewId, ViewShared};
use crate::clouds::{CloudsConfig, LifecycleConfig};
use crate::shading::{SunPosition, TimeOfDay, TimeOfDayTable, hidden_above};
use crate::weather::{BlockLayer, BlockWeather};

/// The sheet lives in its own leaf module; its path under `sky` stays for hosts that name it.
pub use super::sprites::sheet::SpriteSheet;

/// What the sky is created with.
#[derive(Debug, Clone)]
pub struct SkyConfig {
    /// The host's colour and depth targets: formats, standard or reversed Z, samples.
    pub targets: HostTargets,
    /// Renderer settings (`config/render.toml`).
    pub settings: RenderSettings,
    /// Time-of-day table (`config/time_of_day.toml`).
    pub time_of_day: TimeOfDayTable,
    /// The sprite texture sheet.
    pub sheet: SpriteSheet,
}

impl SkyConfig {
    /// The shipped settings, time-of-day table and sprite sheet for `targets`: nothing read
    /// from files.
    pub fn new(targets: HostTargets) -> Self {
        Self {
            targets,
            settings: RenderSettings::default(),
            time_of_day: TimeOfDayTable::default(),
            sheet: SpriteSheet::generated(),
        }
    }
}

/// The sky subsystem: pipelines, the GPU-resident clouds, their sprite orders and the ring.
/// A host drives it directly only when it has its own weather and cloud handling (it hands the
/// sky blocks of clouds, the sun and its view); otherwise [`crate::SkySystem`] does all of that
/// around it.
pub struct Sky {
    device: wgpu::Device,
    settings: RenderSettings,
    time_of_day: TimeOfDayTable,
    lifecycle: LifecycleConfig,
    frame_layout: wgpu::BindGroupLayout,
    /// The layouts a view is made with (the impostor renders' group 0, the sheet's group).
    ring_frame_layout: wgpu::BindGroupLayout,
    sheet_layout: wgpu::BindGroupLayout,
    targets: HostTargets,
    sheet_group: wgpu::BindGroup,
    /// Bytes of the sheet texture (every mip level), for [`Self::memory`].
    sheet_bytes: u64,
    sky_pipeline: wgpu::RenderPipeline,
    /// The sky background kept by a depth test against the host's depth as a read-only
    /// attachment (in a pass of its own); `None` where the host's depth format has a stencil
    /// aspect.
    sky_tested_pipeline: Option<wgpu::RenderPipeline>,
    sprite_pipeline: wgpu::RenderPipeline,
    in_cloud_pipeline: wgpu::RenderPipeline,
    resident: ResidentSet,
    /// Quad indices for this many sprites (the most one draw needs so far).
    quads: (wgpu::Buffer, u32),
    scatter: Scatter,
    build: SpriteBuild,
    view_layout: wgpu::BindGroupLayout,
    /// Each camera's own state, [`ViewId::MAIN`] first: the blocks, weather and resident
    /// sprites above are shared by all.
    views: Vec<View>,
    /// The clouds beyond the ring, out to the horizon (one for all views: its map and uniform
    /// follow the camera of the last prepared view).
    far_field: super::far_field::FarField,
    elapsed_s: f64,
    /// CPU time of block changes since the last prepare, and the host's field time.
    pending: Spent,
    field: Spent,
    /// The far field's CPU time since the last prepare, wall clock ([`FrameStats::far_field_us`]).
    far_field_us: u64,
    /// Timestamps between the passes, while pass timing is on.
    pass_timer: Option<super::Timestamps>,
    /// Kept to make the pass timer.
    queue: wgpu::Queue,
    /// The time-of-day light of the last frame, clear sky: what the clouds are lit with.
    clear_light: TimeOfDay,
    /// The host's light: the clear sun (the shadow map dims it where clouds stop it, or
    /// nothing does with the shadows off) and the sky colours under the cover over the camera.
    seen_light: TimeOfDay,
    /// The mean share of the direct sun the cover over the camera lets through (1 - the share
    /// of the sky it hides): the sky's own sun glow, and for a host without the map.
    cover_transmittance: f32,
    /// The weather over the camera: its cloud layers and ground elevation, metres.
    overhead: (Vec<BlockLayer>, f32),
    /// The fog settings and the weather over the camera they read (visibility, obscuration).
    fog: (crate::shading::FogSettings, BlockWeather),
    /// The cover and visibility frames show, eased through a change of the weather in time.
    overhead_ease: OverheadEase,
    /// The clouds' shadow map for the host's ground (`shadow`): one for every view, as the
    /// sun is; the main view's prepare draws it.
    shadows: super::shadow::CloudShadows,
    /// The lightning flash lighting a cell now, if any.
    flash: Option<SkyFlash>,
}

/// A lightning flash lighting its cell from inside, as the sprites draw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyFlash {
    /// Its centre, metres east/north/up in the local frame.
    pub position_m: glam::DVec3,
    /// How far its light reaches (the Gaussian's 1/e distance), metres.
    pub reach_m: f32,
    /// The light it adds at its centre now, 0..=4 (fraction of white).
    pub light: f32,
}

const SKY_WGSL: &str = include_str!("../../shaders/sky.wgsl");
const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
const IN_CLOUD_WGSL: &str = include_str!("../../shaders/in_cloud.wgsl");

impl Sky {
    /// Creates pipelines, the sheet texture and buffers on the host's device. The device is
    /// checked first ([`super::capabilities`]): one short of what the sky needs gets
    /// [`RenderError::Unsupported`] naming it, and anything the device still refuses while the
    /// sky is built is returned the same way, never wgpu's panic. Where the device cannot draw
    /// into R32Float textures the clouds draw at full resolution (a warning is logged).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut config: SkyConfig,
    ) -> Result<Self, RenderError> {
        config.targets.validate()?;
        let capabilities = super::capabilities::check(device, &config.targets)?;
        let scale = &mut config.settings.clouds.resolution_scale;
        if !capabilities.r32float_renderable && *scale < 1.0 {
            log::warn!(
                "this device cannot draw into R32Float textures (the off-screen cloud target's farthest distance): the clouds are drawn at full resolution instead of {scale}"
            );
            *scale = 1.0;
        }
        let (sky, refused) =
            super::capabilities::refused(device, || Self::build(device, queue, config));
        match refused {
            Some(why) => Err(RenderError::Unsupported(why)),
            None => sky,
        }
    }

    /// [`Self::new`] once the device is checked.
    fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: SkyConfig,
    ) -> Result<Self, RenderError> {
        let sheet = &config.sheet;
        if sheet.mips.is_empty() || sheet.size_px == 0 {
            return Err(RenderError::Sheet("the sprite sheet has no pixels".into()));
        }
        for (level, data) in sheet.mips.iter().enumerate() {
            let side = (sheet.size_px >> level).max(1) as usize;
            if data.len() != side * side * 4 {
                return Err(RenderError::Sheet(format!(
                    "mip level {level} has {} bytes, expected {} for {side} x {side} RGBA8",
                    data.len(),
                    side * side * 4
                )));
            }
        }
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("sky.sheet"),
                size: wgpu::Extent3d {
                    width: sheet.size_px,
                    height: sheet.size_px,
                    depth_or_array_layers: 1,
                },
                mip_level_count: sheet.mips.len() as u32,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &sheet.mips.concat(),
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("sky.sheet_sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // The nearest level, not a blend of two: the soft puffs show no seam, and on a
            // fill-bound frame it saved an eighth of the sprites' time (lavapipe, overcast).
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        let samples = config.targets.sample_count;
        let frame_layout = targets::frame_layout(device, samples > 1);
        // The impostor renders draw into the ring's own single-sample textures.
        let ring_frame_layout = targets::frame_layout(device, false);
        let sheet_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.sheet_layout"),
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
            ],
        });
        let sheet_view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let sheet_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.sheet_group"),
            layout: &sheet_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&sheet_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        let format = config.targets.colour_format;
        let resident = ResidentSet::new(device, 0);
        let view_layout = sprite_view::layout(device);
        let crops = super::sprites::sheet_crop::cell_crops(sheet);
        let build = SpriteBuild::new(device, &view_layout, resident.layout(), &crops);
        let frame_only = [Some(&frame_layout)];
        let sprite_groups = [Some(&frame_layout), Some(&sheet_layout)];
        let over = Some(premultiplied_over());
        let sky_pipeline_for = |fs, depth| {
            pipeline_with_depth(
                device,
                &PassDesc {
                    label: "sky.background",
                    wgsl: SKY_WGSL,
                    vs: "vs_sky",
                    fs,
                    bind_groups: &frame_only,
                    buffers: &[],
                    targets: &[(format, None)],
                    samples,
                    scene: SceneDepth::host(samples),
                },
                depth,
            )
        };
        let sky_pipeline = sky_pipeline_for("fs_sky", None);
        let depth_format = config.targets.depth_format;
        let sky_tested_pipeline = (!depth_format.has_stencil_aspect()).then(|| {
            sky_pipeline_for(
                "fs_sky_tested",
                Some(background_test(depth_format, wgpu::CompareFunction::Equal)),
            )
        });
        let sprite_pipeline = pipeline(
            device,
            &PassDesc {
                label: "sky.sprites",
                wgsl: SPRITES_WGSL,
                vs: "vs_sprite",
                fs: "fs_sprite",
                bind_groups: &sprite_groups,
                buffers: &[Some(GpuSpriteVertex::layout())],
                targets: &[(format, over)],
                samples,
                scene: SceneDepth::host(samples),
            },
        );
        let in_cloud_pipeline = pipeline(
            device,
            &PassDesc {
                label: "sky.in_cloud",
                wgsl: IN_CLOUD_WGSL,
                vs: "vs_in_cloud",
                fs: "fs_in_cloud",
                bind_groups: &frame_only,
                buffers: &[],
                targets: &[(format, over)],
                samples,
                scene: SceneDepth::host(samples),
            },
        );
        let light = config.time_of_day.at(45.0);
        let offscreen_targets = super::cloud_target::cloud_targets();
        let far_field = super::far_field::FarField::new(
            device,
            config.settings.far_field,
            &super::far_field::FarFieldShared {
                host_frame_layout: &frame_layout,
                offscreen_frame_layout: &ring_frame_layout,
                targets: config.targets,
                cloud_targets: Some(&offscreen_targets[..]),
                sheet_rgb: config
                    .sheet
                    .mean_rgb(crate::clouds::TextureCategory::Foggy.cells()),
            },
        );
        let main = View::new(
            device,
            queue,
            &ViewShared {
                targets: config.targets,
                settings: &config.settings,
                host_frame_layout: &frame_layout,
                ring_frame_layout: &ring_frame_layout,
                sheet_layout: &sheet_layout,
                view_layout: &view_layout,
            },
        );
        let shadows = super::shadow::CloudShadows::new(
            device,
            queue,
            config.settings.cloud_shadows,
            &sheet_layout,
            &view_layout,
        );
        Ok(Self {
            device: device.clone(),
            settings: config.settings,
            time_of_day: config.time_of_day,
            frame_layout,
            ring_frame_layout,
            sheet_layout,
            targets: config.targets,
            sheet_group,
            sheet_bytes: sheet.mips.iter().map(|m| m.len() as u64).sum(),
            sky_pipeline,
            sky_tested_pipeline,
            sprite_pipeline,
            in_cloud_pipeline,
            resident,
            quads: (quad_index_buffer(device, 4096), 4096),
            scatter: Scatter::new(device),
            build,
            view_layout,
            views: vec![main],
            far_field,
            lifecycle: CloudsConfig::builtin().lifecycle,
            elapsed_s: 0.0,
            pending: Spent::default(),
            field: Spent::default(),
            far_field_us: 0,
            pass_timer: None,
            queue: queue.clone(),
            clear_light: light,
            seen_light: light,
            cover_transmittance: 1.0,
            overhead: (Vec::new(), 0.0),
            fog: (
                Default::default(),
                BlockWeather {
                    visibility_m: f32::INFINITY,
                    ..Default::default()
                },
            ),
            overhead_ease: OverheadEase::default(),
            shadows,
            flash: None,
        })
    }

    /// Adds a view: another camera with its own targets (of the same formats and samples), its
    /// own draw list, impostor ring and off-screen cloud target; the blocks, the weather and
    /// the resident sprites stay shared. Prepare it with [`Self::prepare_view`] and record it
    /// with [`Self::record_view`]; several views record into one encoder. It costs
    /// [`Self::view_gpu_bytes`] of GPU memory.
    pub fn add_view(&mut self) -> ViewId {
        let view = View::new(
            &self.device,
            &self.queue,
            &ViewShared {
                targets: self.targets,
                settings: &self.settings,
                host_frame_layout: &self.frame_layout,
                ring_frame_layout: &self.ring_frame_layout,
                sheet_layout: &self.sheet_layout,
                view_layout: &self.view_layout,
            },
        );
        self.views.push(view);
        ViewId(self.views.len() - 1)
    }

    /// Whether the sky has this view.
    pub fn has_view(&self, id: ViewId) -> bool {
        id.0 < self.views.len()
    }

    /// The views the sky has, [`ViewId::MAIN`] included.
    pub fn view_count(&self) -> usize {
        self.views.len()
    }

    /// Bytes of one view's own GPU buffers and textures (frame uniform, draw list and locks,
    /// impostor ring, off-screen cloud target as last sized): what a view adds. 0 for an
    /// unknown view.
    pub fn view_gpu_bytes(&self, id: ViewId) -> u64 {
        self.views.get(id.0).map_or(0, View::gpu_bytes)
    }

    /// Replaces the clouds with `blocks` (none drifting, all steady). A block the sky already
    /// holds with the same id and content stays on the GPU as it is, with its cached orders;
    /// the others are uploaded by the next [`Self::prepare`]. For a whole new scene; a living
    /// field hands over its changes with [`Self::insert_block`], [`Self::remove_block`] and
    /// [`Self::set_block_motion`] instead.
    pub fn set_clouds(&mut self, blocks: Vec<SkyBlock>) {
        let start = Stopwatch::start();
        let ids: HashSet<u64> = blocks.iter().map(|b| b.id).collect();
        let gone: Vec<u64> = self
            .resident
            .blocks
            .keys()
            .filter(|id| !ids.contains(id))
            .copied()
            .collect();
        for id in gone {
            self.retire(id);
        }
        for block in blocks {
            match self.resident.blocks.get_mut(&block.id) {
                Some(r) if r.block == block => {
                    if r.motion != BlockMotion::default() {
                        let steady = BlockMotion::default();
                        self.resident.fades += r.motion.fade.kind_changes(steady.fade) as u64;
                        r.motion = steady;
                        self.resident.changes += 1;
                    }
                }
                _ => self.resident.insert(block, BlockMotion::default()),
            }
        }
        self.pending += start.spent();
    }

    /// Adds a block (or replaces the one with its id); it is uploaded to the GPU once, by the
    /// next [`Self::prepare`]. Many at once: [`Self::insert_blocks`].
    pub fn insert_block(&mut self, block: SkyBlock, motion: BlockMotion) {
        self.insert_blocks([(block, motion)]);
    }

    /// [`Self::insert_block`] for each of `blocks`, timed once (reading the thread's CPU clock
    /// costs about a microsecond, more than inserting a block).
    pub fn insert_blocks(&mut self, blocks: impl IntoIterator<Item = (SkyBlock, BlockMotion)>) {
        let start = Stopwatch::start();
        for (block, motion) in blocks {
            self.retire(block.id);
            self.resident.insert(block, motion);
        }
        self.pending += start.spent();
    }

    /// Says that blocks of `sprites` sprites and `clouds` clouds in all will be inserted in
    /// the next frames (a weather change handed over a part a frame): when the buffers next
    /// grow, they grow for those as well, once. Each call replaces the last; 0, 0 when none
    /// wait.
    pub fn expect_blocks(&mut self, sprites: u64, clouds: u64) {
        self.resident.expected = (sprites, clouds);
    }

    /// Adds a block drawn as sprites however far it is, never into the impostor ring nor cut at
    /// the draw distance: what the ring and the far field cannot draw beyond the cloud field,
    /// a storm cell's tower seen from 100-450 km (`flight::far_cells`). While the far field is
    /// drawn, its sprites fade in over the hand-over band as the near sprites and the ring fade
    /// out there ([`Self::far_field_hand_over_m`]). Replaces the block with
    /// its id; uploaded once, by the next [`Self::prepare`].
    pub fn insert_distant_block(&mut self, block: SkyBlock, motion: BlockMotion) {
        let start = Stopwatch::start();
        let id = block.id;
        self.retire(id);
        self.resident.insert(block, motion);
        if let Some(r) = self.resident.blocks.get_mut(&id) {
            r.distant = true;
        }
        self.pending += start.spent();
    }

    /// Retires a block; false if the sky did not hold it. Many at once:
    /// [`Self::remove_blocks`].
    pub fn remove_block(&mut self, id: u64) -> bool {
        self.remove_blocks([id]) == 1
    }

    /// [`Self::remove_block`] for each of `ids`, timed once; returns how many the sky held.
    pub fn remove_blocks(&mut self, ids: impl IntoIterator<Item = u64>) -> usize {
        let start = Stopwatch::start();
        let held = ids.into_iter().filter(|&id| self.retire(id)).count();
        self.pending += start.spent();
        held
    }

    fn retire(&mut self, id: u64) -> bool {
        match self.resident.remove(id) {
            Some(slots) => {
                for view in &mut self.views {
                    view.locks.release(slots.clone());
                }
                true
            }
            None => false,
        }
    }

    /// Moves a block (its drift) and sets where it is in its life; nothing is uploaded but the
    /// frame's draw list. False if the sky does not hold it.
    pub fn set_block_motion(&mut self, id: u64, motion: BlockMotion) -> bool {
        match self.resident.blocks.get_mut(&id) {
            Some(r) => {
                // What the shadow map watches for (a block moved by other means than the drift).
                self.resident.changes += (r.motion.offset_m != motion.offset_m) as u64;
                self.resident.fades += r.motion.fade.kind_changes(motion.fade) as u64;
                r.motion = motion;
                true
            }
            None => false,
        }
    }

    /// Moves every block the sky holds to the same drift offset (a field drifting with the air as
    /// one): one write a block, no lookups, nothing uploaded.
    pub fn set_drift(&mut self, offset_m: glam::DVec3) {
        for r in self.resident.blocks.values_mut() {
            r.motion.offset_m = offset_m;
        }
        self.resident.drift_m = offset_m;
        self.shadows.set_drift(offset_m);
    }

    /// Sets where a block is in its life, keeping its drift; false if the sky does not hold it.
    pub fn set_block_fade(&mut self, id: u64, fade: super::Fade) -> bool {
        match self.resident.blocks.get_mut(&id) {
            Some(r) => {
                self.resident.fades += r.motion.fade.kind_changes(fade) as u64;
                r.motion.fade = fade;
                true
            }
            None => false,
        }
    }

    /// The ids of the blocks the sky holds.
    pub fn block_ids(&self) -> impl Iterator<Item = u64> + '_ {
        self.resident.blocks.keys().copied()
    }

    /// A block the sky holds.
    pub fn block(&self, id: u64) -> Option<&SkyBlock> {
        self.resident.blocks.get(&id).map(|r| &r.block)
    }

    /// Switches the cloud shading model (`[shading] model` of the time-of-day table). Switched
    /// to Harris and Lastra's, the clouds held get a provisional light at the next
    /// [`Self::prepare`] and their own within the model's budget of sprites a frame.
    pub fn set_shading_model(&mut self, model: crate::shading::ShadingModel) {
        self.time_of_day.shading.model = model;
    }

    /// The cloud shading model in use.
    pub fn shading_model(&self) -> crate::shading::ShadingModel {
        self.time_of_day.shading.model
    }

    /// How clouds form and dissipate (the clouds stage's `[lifecycle]`): which sprites of a
    /// forming or dissipating block show at a given progress.
    pub fn set_lifecycle(&mut self, lifecycle: LifecycleConfig) {
        self.lifecycle = lifecycle;
    }

    /// Caps the GPU memory of the sprites (records, orders, quad indices) at `bytes` (0: only
    /// the device's limits). Past it the farthest blocks are left out and counted in
    /// [`FrameStats::blocks_left_out`]. Every block is uploaded again.
    pub fn set_sprite_budget_bytes(&mut self, bytes: u64) {
        let mut old = ResidentSet::new(&self.device, bytes);
        std::mem::swap(&mut old, &mut self.resident);
        for (_, r) in old.blocks {
            self.resident.insert(r.block, r.motion);
        }
        for view in &mut self.views {
            view.locks = Locks::default();
        }
    }

    /// Counts what the host's cloud field work for this frame `spent` (time it with a
    /// [`Stopwatch`]) into the next prepared frame's [`FrameStats::field_us`] and its thread
    /// figure.
    pub fn add_field_cpu(&mut self, spent: Spent) {
        self.field += spent;
    }

    /// Counts the wall-clock microseconds the host's work on the far field's map took this frame
    /// (sampling the weather into its rows, [`Self::set_far_map`]) into the next prepared
    /// frame's [`FrameStats::far_field_us`]. They are part of the field's time too: count that
    /// span with [`Self::add_field_cpu`] as well.
    pub fn add_far_field_us(&mut self, us: u64) {
        self.far_field_us += us;
    }

    /// Time spent on the block changes handed over since the last [`Self::prepare`] (inserts,
    /// removals, [`Self::set_clouds`]): part of the next frame's
    /// [`FrameStats::cpu_update_us`] and its thread figure.
    pub fn pending_cpu(&self) -> Spent {
        self.pending
    }

    /// The corners of the last prepared frame's sprites, four per sprite in drawing order, as
    /// the build pass makes them for the draw (position relative to the camera, colour, drawn or
    /// not): for tests and tools. Runs the frame's patch and build passes and waits.
    pub fn read_back_corners(
        &self,
        queue: &wgpu::Queue,
    ) -> Result<Vec<super::SpriteCorner>, RenderError> {
        let main = &self.views[0];
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.scatter.record(&mut encoder);
        let read = super::readback::read_buffer(&self.device, main.sprites_to_draw);
        let corner_bytes = 4 * std::mem::size_of::<GpuSpriteVertex>() as u64;
        if let Some(view_group) = main.view.group() {
            for (chunk, first, sprites) in chunks(main.sprites_to_draw) {
                let group = &self.resident.group;
                self.build
                    .record(&mut encoder, view_group, group, (chunk, sprites));
                encoder.copy_buffer_to_buffer(
                    self.build.vertices(),
                    0,
                    &read,
                    first as u64 * corner_bytes,
                    sprites as u64 * corner_bytes,
                );
            }
        }
        super::readback::read_corners(&self.device, queue, encoder, &read, main.sprites_to_draw)
    }

    /// Times each group of the sky's passes on the GPU from the next [`Self::record`] on (a
    /// profiling aid: the far field, the ring and the sprites then go in passes of their own),
    /// or stops.
    /// Returns whether timing is on: the device needs timestamp queries inside encoders
    /// (`wgpu::Features::TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`).
    pub fn set_pass_timing(&mut self, on: bool) -> bool {
        self.pass_timer = if on {
            super::Timestamps::new(&self.device, &self.queue, "sky.pass_times", STAMPS)
        } else {
            None
        };
        self.shadows
            .set_timing(&self.queue, self.pass_timer.is_some());
        self.pass_timer.is_some()
    }

    /// GPU time of each group of passes of the last recorded frame, once it was submitted:
    /// waits for the device. `None` while pass timing is off or if the times cannot be read.
    pub fn pass_times(&self) -> Option<super::PassTimes> {
        let times =
            super::pass_timing::pass_times(&self.pass_timer.as_ref()?.read_ms(&self.device)?);
        let shadow_ms = self.shadows.last_ms().unwrap_or(0.0);
        times.map(|t| super::PassTimes { shadow_ms, ..t })
    }

    /// The clouds' shadow map of the last prepared frame and the matrix a host looks it up with
    /// ([`super::CloudShadowMap`]): the host multiplies its ground's direct sunlight by
    /// `exp(-tau)`. Take it every frame (after [`Self::prepare`]): the lookup follows the camera
    /// and the clouds' drift, and the texture is replaced when the shadows are switched.
    pub fn cloud_shadows(&self) -> super::CloudShadowMap<'_> {
        self.shadows.map()
    }

    /// Switches the cloud shadows on (drawn from the next [`Self::prepare`]) or off (the map a
    /// single texel of open sun).
    pub fn set_cloud_shadows(&mut self, on: bool) {
        self.shadows.set_enabled(&self.queue, on);
        self.settings.cloud_shadows.enabled = on;
    }

    /// Draws the cloud shadow map at the next [`Self::prepare`] whatever changed (it is drawn
    /// again by itself when the camera has gone far, the sun turned, a block near went (one
    /// that arrives is added to it), or, while clouds form or dissipate, after
    /// `update_interval_s`).
    pub fn redraw_cloud_shadows(&mut self) {
        self.shadows.redraw();
    }

    /// The shadow map's optical depth read back (tests and tools); waits for the device.
    pub fn read_back_cloud_shadows(
        &self,
        queue: &wgpu::Queue,
    ) -> Result<super::ShadowImage, RenderError> {
        self.shadows.read_back(queue)
    }

    /// Time the last [`Self::record`] spent.
    pub fn last_record(&self) -> Spent {
        self.views[0].record.get()
    }

    /// Time the last [`Self::record_view`] of `id` spent (0 for an unknown view).
    pub fn view_record(&self, id: ViewId) -> Spent {
        self.views
            .get(id.0)
            .map_or_else(Spent::default, |v| v.record.get())
    }

    /// The host's targets the sky was made for.
    pub fn targets(&self) -> &HostTargets {
        &self.targets
    }

    /// The settings the sky was made with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Turns the far-cloud impostor ring off (every block drawn as sprites) or back on (built
    /// afresh). Returns false and changes nothing when turning it on in a sky made with
    /// `impostors.enabled = false`: the ring's textures are made at start-up only.
    pub fn set_impostors(&mut self, enabled: bool) -> bool {
        let mut switched = true;
        for view in &mut self.views {
            switched &= view.ring.set_enabled(enabled);
        }
        if switched {
            self.settings.impostors.enabled = enabled;
        }
        switched
    }

    /// Turns the vertex cache on or off (off: every cloud recomputed every frame).
    pub fn set_vertex_cache(&mut self, enabled: bool) {
        self.settings.vertex_cache.enabled = enabled;
    }

    /// Hands the far field a new cloud map ([`crate::clouds::far_map::FarMapFeed`] makes them
    /// from the weather field as the camera moves); uploaded now. The first map fades in over
    /// `fade_in_s` when given (as arriving clouds do); a map of another weather
    /// ([`crate::clouds::far_map::FarMap::weather_epoch`]) crossfades from the one shown over
    /// the lifecycle's formation time, as the blocks' clouds form and dissipate; a map moved
    /// with the camera shows at once (its cells keep their weather).
    pub fn set_far_map(
        &mut self,
        queue: &wgpu::Queue,
        map: &crate::clouds::far_map::FarMap,
        fade_in_s: Option<f64>,
    ) {
        let crossfade_s = f64::from(self.lifecycle.formation_s);
        self.far_field.set_map(
            &self.device,
            queue,
            map,
            (self.elapsed_s, fade_in_s, crossfade_s),
        );
    }

    /// Where the far field takes over from the sprites and the ring while it is drawn: the band
    /// over which they fade out and it fades in (metres from the camera), and the distant
    /// blocks fade in ([`Self::insert_distant_block`]). `None` while it is not drawn.
    pub fn far_field_hand_over_m(&self) -> Option<(f32, f32)> {
        self.far_field.hand_over_m()
    }

    /// Switches the far field on or off at run time (for comparisons; the sprites and the ring
    /// fade out as before without it).
    pub fn set_far_field_enabled(&mut self, enabled: bool) {
        self.far_field.set_enabled(enabled);
    }

    /// The far field's settings (the map's size, the hand-over band).
    pub fn far_field_settings(&self) -> super::far_field::FarFieldSettings {
        *self.far_field.settings()
    }

    /// The clouds' distance in the main view's last recorded frame (metres from the camera
    /// plane, weighted by what each cloud shows; 0 where none shows) at the cloud target's
    /// resolution: width, height and the texels row by row. `None` with the clouds drawn at full
    /// resolution (no cloud target). Waits for the GPU: for tools and tests.
    pub fn read_cloud_distance_m(&self, queue: &wgpu::Queue) -> Option<(u32, u32, Vec<f32>)> {
        self.views[0].clouds.read_distance_m(&self.device, queue)
    }

    /// Replaces the fog and haze settings (the shipped `config/fog.toml` until called).
    pub fn set_fog_settings(&mut self, fog: crate::shading::FogSettings) {
        self.fog.0 = fog;
    }

    /// The weather over the camera (the layers and ground of its point of the weather field).
    /// Each frame works out how much of the sky the layers above the camera hide
    /// ([`crate::shading::hidden_above`]): below a thick deck the sky turns grey and dim and
    /// [`Self::light`] loses its sun; above it nothing changes. The clouds keep their own light.
    /// Until it is called the sky is taken as clear overhead.
    pub fn set_weather_overhead(&mut self, weather: &BlockWeather) {
        self.overhead = (weather.layers.clone(), weather.ground_elevation_m);
        self.fog.1 = weather.clone();
    }

    /// The weather overhead changes in time from now (a new report, not the camera moving
    /// through the weather): the cover's light and the fog's visibility go over to the next
    /// [`Self::set_weather_overhead`]'s across the clouds' formation time, as its clouds form,
    /// instead of at once. Called by [`crate::flight::SkySystem`] when it applies a new weather
    /// field; a host handing the weather itself calls it when the weather it hands is new.
    pub fn ease_weather_overhead(&mut self) {
        self.overhead_ease
            .begin(self.elapsed_s, f64::from(self.lifecycle.formation_s));
    }

    /// The fog a host draws over its scene: the visibility and obscuration of the weather over
    /// the camera ([`crate::shading::fog`]) under the last frame's horizon sky, the visibility
    /// the last frame showed ([`Self::ease_weather_overhead`]), thicker where the last frame
    /// found the camera in a rain or snow shaft.
    pub fn fog(&self) -> crate::shading::Fog {
        self.fog_for(self.views[0].in_rain)
    }

    /// The haze a host fogs its ground with along a view ray ([`crate::shading::AltitudeHaze`]:
    /// thinning with height), for [`Self::fog`] with its visibility at most `visibility_m`; the
    /// clouds fade into the same haze.
    pub fn ground_haze(&self, visibility_m: f32) -> crate::shading::AltitudeHaze {
        let mut fog = self.fog();
        fog.distance_m = fog.distance_m.min(visibility_m);
        self.fog.0.ground_haze(&fog, self.fog.1.ground_elevation_m)
    }

    /// The round Earth the sky draws on (`[earth]` of the renderer settings); a host draws its
    /// far ground on the same ([`crate::render::earth::curved_rel`]).
    pub fn earth(&self) -> crate::render::earth::EarthSettings {
        self.settings.earth
    }

    /// Lights the sprites near a lightning flash from inside this frame on (`None`: no flash).
    pub fn set_flash(&mut self, flash: Option<SkyFlash>) {
        self.flash = flash;
    }

    /// [`Self::fog`] with a view's rain.
    fn fog_for(&self, in_rain: f32) -> crate::shading::Fog {
        let mut air = self.fog.0.fog(&self.fog.1, self.seen_light.sky_horizon_rgb);
        if let Some(shown) = self.overhead_ease.visibility_m() {
            air.distance_m = shown;
        }
        self.fog.0.in_rain(air, in_rain)
    }

    /// The fraction of the sky hidden above `altitude_m` by the weather overhead, 0..=1.
    pub fn sky_hidden_at(&self, altitude_m: f64) -> f32 {
        let (layers, ground_m) = &self.overhead;
        hidden_above(
            layers,
            *ground_m,
            altitude_m as f32,
            &self.time_of_day.overcast,
        )
    }

    /// Colour a host should fog its distant ground towards (the horizon sky colour now).
    pub fn horizon_rgb(&self) -> Vec3 {
        self.seen_light.sky_horizon_rgb
    }

    /// The light of the last prepared frame (see [`Self::set_weather_overhead`]): what a host
    /// lights its own scene with. Its sun (`directional_rgb`) is the clear direct sun, with the
    /// cloud shadows on or off: the host dims it by the shadow map ([`Self::cloud_shadows`])
    /// where the clouds stop it. With the shadows off the clouds cast none (the map lets all
    /// the sun through), so the ground is in the clear sun everywhere, as open ground is with
    /// them on. The sky colours are those under the cover over the camera. A host that draws
    /// without the map and wants the cover to dim its ground evenly multiplies the sun by
    /// [`Self::sun_cover_transmittance`]; skycast's own ground does not.
    pub fn light(&self) -> TimeOfDay {
        self.seen_light
    }

    /// The mean share (0..=1) of the direct sun the cloud cover over the camera lets through,
    /// of the last prepared frame: 1 minus the share of the sky it hides, eased through a
    /// change of the weather. Not applied to [`Self::light`]'s sun: it is for a host that does
    /// not look up the shadow map and wants its ground dimmed evenly under a cover instead
    /// (skycast's ground before the shadow map). The sky's own sun glow is dimmed by it.
    pub fn sun_cover_transmittance(&self) -> f32 {
        self.cover_transmittance
    }

    /// The time-of-day light for a sun position (for hosts lighting their own scene).
    pub fn light_for(&self, sun: &SunPosition) -> TimeOfDay {
        self.time_of_day.at(sun.elevation_deg as f32)
    }

    /// Bytes of the GPU buffers the sky holds now (frame uniforms, the resident sprites, the
    /// draw list, the ring); [`Self::memory`] counts the textures too.
    pub fn gpu_buffer_bytes(&self) -> u64 {
        self.views.iter().map(View::gpu_buffer_bytes).sum::<u64>()
            + self.resident.gpu_bytes()
            + self.quads.0.size()
            + self.build.gpu_bytes()
            + self.scatter.gpu_bytes()
            + self.shadows.gpu_bytes()
    }

    /// Every buffer and texture the sky holds now (the ring and the off-screen cloud target
    /// included), and the blocks and slots behind the resident buffers: what a long flight
    /// watches for growth.
    pub fn memory(&self) -> SkyMemory {
        let (blocks, sprites, sprite_slots, cloud_slots) = self.resident.occupancy();
        SkyMemory {
            resident_bytes: self.resident.gpu_bytes(),
            draw_bytes: self
                .views
                .iter()
                .map(|v| v.frame_buffer.size() + v.view.gpu_bytes())
                .sum::<u64>()
                + self.quads.0.size()
                + self.build.gpu_bytes()
                + self.scatter.gpu_bytes(),
            ring_bytes: self.views.iter().map(|v| v.ring.gpu_bytes()).sum(),
            cloud_target_bytes: self.views.iter().map(|v| v.clouds.gpu_bytes()).sum(),
            shadow_bytes: self.shadows.gpu_bytes(),
            sheet_bytes: self.sheet_bytes,
            far_field_bytes: self.far_field.gpu_bytes(),
            blocks,
            sprites,
            sprite_slots: sprite_slots.0,
            sprite_slots_used: sprite_slots.1,
            cloud_slots: cloud_slots.0,
            cloud_slots_used: cloud_slots.1,
        }
    }

    /// CPU work of a frame: advances time by `dt_s`, uploads blocks that arrived, sorts blocks
    /// and clouds, recomputes the sprite orders Wang's cache says are stale, and writes the draw
    /// list and this frame's uniforms (only what changed goes to the GPU). It submits nothing of
    /// its own to the device (the impostor renders of a ring rebuild go into the next
    /// [`Self::record`]), except that a frame prepared and never recorded is flushed by the next
    /// prepare, so nothing piles up however the host drives it; the time that flush holds the
    /// frame thread is `gpu_wait_us`, not in `cpu_update_us`.
    pub fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        view: impl Into<SkyView>,
        sun: &SunPosition,
        dt_s: f64,
    ) -> FrameStats {
        self.prepare_view(ViewId::MAIN, queue, view, sun, dt_s)
    }

    /// [`Self::prepare`] for one view (see [`Self::add_view`]): its draw list, ring and
    /// uniforms from its camera. Every view of a frame is given the frame's `dt_s`: the main
    /// view's advances the sky's clock, the others' only their ring's crossfade. An unknown
    /// view prepares the main one (see [`Self::has_view`]).
    pub fn prepare_view(
        &mut self,
        id: ViewId,
        queue: &wgpu::Queue,
        view: impl Into<SkyView>,
        sun: &SunPosition,
        dt_s: f64,
    ) -> FrameStats {
        let start = Stopwatch::start();
        let i = if id.0 < self.views.len() { id.0 } else { 0 };
        let camera: SkyView = view.into();
        self.views[i].projection = Some(camera.projection);
        let mut gpu_wait = Spent::default();
        if !self.views[i].recorded.replace(false) {
            // The last frame's writes never reached a submit: send them, so they are freed. A
            // device still busy with earlier work can hold the submit (lavapipe waits in it for
            // the submission before): timed apart, as a wait.
            let wait = Stopwatch::start();
            queue.submit([]);
            gpu_wait = wait.spent();
        }
        // The frame's clock is the main view's; the others use `dt_s` for their ring's
        // crossfade only.
        if i == ViewId::MAIN.0 {
            self.elapsed_s += dt_s.max(0.0);
        }
        self.clear_light = self.time_of_day.at(sun.elevation_deg as f32);
        let (hidden, _) = self.overhead_ease.show(
            self.sky_hidden_at(camera.position_m.z),
            self.fog.0.visibility_m(&self.fog.1),
            self.elapsed_s,
        );
        self.seen_light = self
            .clear_light
            .under_cover(hidden, &self.time_of_day.overcast);
        // The host's sun is the clear sun, on or off: the shadow map dims it where the clouds
        // stop it, and with the shadows off nothing does (off casts no shadows; it does not
        // dim the ground evenly). The cover's mean dimming is kept apart for a host without
        // the map.
        self.cover_transmittance = 1.0 - hidden.clamp(0.0, 1.0);
        self.seen_light.directional_rgb = self.clear_light.directional_rgb;
        let sun_dir = sun.direction_enu().as_vec3();
        let lighting = Lighting {
            sun_dir,
            time_of_day: self.clear_light,
            mapping: self.time_of_day.directional_mapping,
            forward: self.time_of_day.forward_scattering,
            model: self.time_of_day.shading.model,
            harris_lastra: self.time_of_day.harris_lastra,
        };
        let mut stats = FrameStats::default();
        (self.resident.lit_sprites, self.resident.light_us) = (0, 0);
        let switched_on = self.resident.light.set(
            self.time_of_day.shading.model,
            &self.time_of_day.harris_lastra,
            sun_dir,
        );
        let mut upload_bytes = 0;
        if switched_on {
            upload_bytes += self.resident.provisional_all(queue);
        }
        let (placed_bytes, left_out) = self.resident.place_and_upload(
            queue,
            camera.position_m,
            self.settings.vertex_cache.max_uploaded_sprites_per_frame,
        );
        stats.blocks_left_out = left_out;
        gpu_wait += self.resident.grow_wait;
        if self.resident.packed() {
            // Blocks moved to other slots: what holds sprite slots from frame to frame follows
            // them, and a patch of orders kept for the old slots goes (the new buffers were
            // written whole from the CPU's copies, which hold its values).
            self.scatter.forget_kept();
            let resident = &self.resident;
            for view in &mut self.views {
                view.locks.follow(|slot| resident.moved_slot(slot));
            }
        }
        upload_bytes += placed_bytes;
        upload_bytes += self.resident.relight(queue, camera.position_m);
        (stats.sprites_lit, stats.light_us) = (self.resident.lit_sprites, self.resident.light_us);
        // While the far field is drawn every sprite has faded out by the end of its hand-over
        // band (a twentieth more: the band is horizontal, the draw distance along the ray):
        // neither the ring nor the sprites go farther.
        let band_m = (self.far_field.hand_over_m()).map(|(start, end)| (start, 1.05 * end));
        let mut drawn = self.settings;
        if let Some((_, end)) = band_m {
            drawn.clouds.draw_distance_m = drawn.clouds.draw_distance_m.min(end);
        }
        (self.views[i].ring)
            .set_reach_limit(band_m.map(|(start, end)| (f64::from(start), f64::from(end))));
        self.views[i]
            .ring
            .split(&mut self.resident, camera.position_m, sun_dir, dt_s);
        // The frame's sorting budget, shared with a ring that is being rebuilt.
        let sort_budget = self.settings.vertex_cache.max_sorted_sprites_per_frame;
        let sort_budget = sort_budget - self.views[i].ring.sort_reserve(sort_budget);
        let resident = &mut self.resident;
        let v = &mut self.views[i];
        let inside = main_view(
            (&mut resident.blocks, v.ring.near()),
            Copies {
                orders: &mut resident.orders_cpu,
                dirty_orders: &mut resident.dirty_orders,
                lists: &mut resident.lists_cpu,
                dirty_lists: &mut resident.dirty_lists,
            },
            (camera.position_m, &camera.frustum()),
            self.elapsed_s,
            (&drawn, sort_budget),
            (&mut v.locks, &mut v.seams),
            &mut v.draws,
            &mut stats,
        );
        let resident = &mut self.resident;
        upload_bytes += self.scatter.prepare(
            &self.device,
            queue,
            (&resident.orders_cpu, &resident.order_buffer),
            &mut resident.dirty_orders,
            (&resident.lists_cpu, &resident.list_buffer),
            &mut resident.dirty_lists,
        );
        let locks = self.views[i].locks.gpu();
        let light = ViewLight {
            lighting: &lighting,
            clouds: &self.settings.clouds,
            lifecycle: &self.lifecycle,
            camera_z_m: camera.position_m.z as f32,
            farthest_m: self.settings.clouds.draw_distance_m,
            hand_over_m: self.far_field.hand_over_m(),
        };
        let header = sprite_view::header(&light);
        let v = &mut self.views[i];
        let changed_locks = v.locks.take_changed().then_some(&locks[..]);
        upload_bytes += v.view.write(
            &self.device,
            queue,
            &self.view_layout,
            &header,
            changed_locks,
            ViewData::Resident {
                counts: [
                    v.draws.len() as u32,
                    locks.len() as u32,
                    stats.sprites_drawn,
                    0,
                ],
                draws: &v.draws,
                lists: &self.resident.list_buffer,
                orders: &self.resident.order_buffer,
                generation: self.resident.generation,
            },
        );
        self.views[i].sprites_to_draw = stats.sprites_drawn;
        self.views[i].distant_sprites =
            super::sprites::draw_list::distant_sprites(&self.views[i].draws, stats.sprites_drawn);
        let in_cloud = inside.cloud;
        self.views[i].in_cloud = in_cloud;
        self.views[i].in_rain = inside.rain;
        stats.in_cloud = in_cloud;

        let view_proj = camera.view_proj();
        let sun_cfg = &self.settings.sun;
        // In-cloud fog: the ambient of a mid-grey cloud at this time of day plus some sun.
        let fog_rgb = Vec3::splat(0.8) * self.clear_light.ambient_percent
            + self.clear_light.directional_rgb * 0.25;
        let cloud_haze = self.fog.0.cloud_haze(
            &self.fog_for(self.views[i].in_rain),
            self.settings.clouds.haze_distance_m,
            self.fog.1.ground_elevation_m,
        );
        let frame = GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            sun_dir: sun_dir
                .extend(sun_cfg.disc_radius_deg.to_radians().cos())
                .to_array(),
            // The sky's own sun glow and disc behind the clouds: dimmed by the cover as a
            // whole, the same with the shadows on or off.
            sun_rgb: (self.seen_light.directional_rgb * self.cover_transmittance)
                .extend(sun_cfg.glow_radius_deg.to_radians().cos())
                .to_array(),
            // w: the camera's height above the haze's base; its distance from the Earth's
            // centre (0: flat).
            sky_zenith_rgb: self
                .seen_light
                .sky_zenith_rgb
                .extend(camera.position_m.z as f32 - cloud_haze.base_msl_m)
                .to_array(),
            sky_horizon_rgb: self
                .seen_light
                .sky_horizon_rgb
                .extend(self.settings.earth.camera_radius_m(camera.position_m.z))
                .to_array(),
            in_cloud_rgba: fog_rgb.extend(in_cloud).to_array(),
            params: [
                self.targets.background_depth(),
                self.settings.clouds.soft_depth_fade_m.recip(),
                self.settings.clouds.soft_depth_fade_m,
                self.settings.in_cloud.visibility_m,
            ],
            haze: cloud_haze.to_gpu(),
            flash_reach: [self.flash.map_or(0.0, |f| f.reach_m), 0.0, 0.0, 0.0],
            depth_to_view: camera.depth_to_view(),
            flash: self.flash.map_or([0.0; 4], |f| {
                (f.position_m - camera.position_m)
                    .as_vec3()
                    .extend(f.light)
                    .to_array()
            }),
        };
        queue.write_buffer(&self.views[i].frame_buffer, 0, bytemuck::bytes_of(&frame));
        let far_field = std::time::Instant::now();
        self.far_field.prepare(
            queue,
            (camera.position_m, frame.sky_horizon_rgb[3]),
            &self.clear_light,
            self.elapsed_s,
        );
        self.far_field_us += far_field.elapsed().as_micros() as u64;
        upload_bytes += std::mem::size_of::<GpuFrame>() as u64;
        let ring_frame = RingFrame {
            resident: &self.resident,
            template: &frame,
            view: &light,
            camera_m: camera.position_m,
            cache: &self.settings.vertex_cache,
        };
        upload_bytes += self.views[i]
            .ring
            .prepare_builds(queue, &ring_frame, &mut stats);
        if i == ViewId::MAIN.0 {
            // One map for all views (the sun is shared), around the main view's camera.
            let at = (camera.position_m, sun_dir, self.elapsed_s);
            upload_bytes += (self.shadows).prepare(queue, &self.resident, &light, at, &mut stats);
        }
        // Quad indices and built corners for the largest draw of the frame (the sprites, an
        // impostor's sector, the shadow map's chunk).
        let most = stats
            .sprites_drawn
            .max(self.views[i].ring.most_sprites_pending())
            .max(self.shadows.pending_sprites())
            .min(CHUNK);
        if most > self.quads.1 {
            let sprites = most.next_power_of_two();
            self.quads = (quad_index_buffer(&self.device, sprites), sprites);
        }
        self.build.reserve(&self.device, most);
        stats.upload_bytes = upload_bytes;
        // The shadow map, when due (rarely: see `shadow`), goes in a submission of its own with
        // the patch of changed orders it reads, applied but kept for the host's frame. The
        // ring's impostor renders go in the host's encoder (`record_view`).
        if self.shadows.has_pending() {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("sky.cloud_shadows"),
                });
            self.scatter.record_kept(&mut encoder);
            let resident = &self.resident.group;
            (self.shadows).record(
                &mut encoder,
                &self.sheet_group,
                &self.build,
                resident,
                &self.quads.0,
            );
            // lavapipe runs the submission on the frame thread: counted as a wait, as the
            // flush above is.
            let wait = Stopwatch::start();
            queue.submit([encoder.finish()]);
            gpu_wait += wait.spent();
        }
        stats.cloud_scale = self.views[i].clouds.scale();
        stats.cloud_target_bytes = self.views[i].clouds.gpu_bytes();
        stats.sprite_gpu_bytes = self.resident.gpu_bytes()
            + self.quads.0.size()
            + self.build.gpu_bytes()
            + self.views[i].view.gpu_bytes();
        let field = std::mem::take(&mut self.field);
        let update = start.spent().saturating_sub(gpu_wait) + std::mem::take(&mut self.pending);
        stats.far_field_us = std::mem::take(&mut self.far_field_us);
        stats.far_field_gpu_bytes = self.far_field.gpu_bytes();
        stats.field_us = field.wall_us;
        stats.thread.field_us = field.thread_us;
        stats.gpu_wait_us = gpu_wait.wall_us;
        stats.cpu_update_us = update.wall_us;
        stats.thread.update_us = update.thread_us;
        stats
    }

    /// Records the sky's passes into the host's encoder: sky background, then the ring, sprites
    /// and in-cloud fog, straight into the host's colour or, below full resolution, into the
    /// sky's cloud target composited over it (`cloud_target`; it follows the host's frame size).
    /// `depth_view` is the host's depth (the format of [`HostTargets::depth_format`], with
    /// `TEXTURE_BINDING`), only read.
    ///
    /// Before anything is recorded the host's textures are checked against the targets the sky
    /// was made for, and the last prepared projection against their depth convention
    /// ([`HostTargets::check_textures`], [`HostTargets::check_projection`]): a mismatch is
    /// [`RenderError::Targets`] naming both sides, and nothing is recorded.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.record_view(ViewId::MAIN, encoder, colour_view, depth_view)
    }

    /// [`Self::record`] for one view, with that view's targets (the same formats and samples;
    /// any size). Several views record into one encoder, each drawing its own prepared frame.
    /// An unknown view is an error.
    pub fn record_view(
        &self,
        id: ViewId,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        let v = self.views.get(id.0).ok_or_else(|| {
            RenderError::Targets(format!(
                "view {} does not exist (the sky has {})",
                id.0,
                self.views.len()
            ))
        })?;
        let start = Stopwatch::start();
        self.targets
            .check_textures(colour_view.texture(), depth_view.texture())?;
        if let Some(projection) = v.projection {
            self.targets.check_projection(projection)?;
        }
        let frame_group = {
            let mut kept = v.frame_group.borrow_mut();
            match kept.as_ref().filter(|(depth, _)| depth == depth_view) {
                Some((_, group)) => group.clone(),
                None => {
                    let group = frame_group(
                        &self.device,
                        "sky.frame_group",
                        &self.frame_layout,
                        &v.frame_buffer,
                        depth_view,
                    );
                    *kept = Some((depth_view.clone(), group.clone()));
                    group
                }
            }
        };
        // The patch of changed orders, then the sky, the ring, the sprites a chunk at a time
        // (each built just before it is drawn; one pass when they fit one chunk), the in-cloud
        // fog.
        let timer = self.pass_timer.as_ref();
        let stamp = |encoder: &mut wgpu::CommandEncoder, at: Stamp| {
            if let Some(timer) = timer {
                timer.write(encoder, at as u32);
            }
        };
        stamp(encoder, Stamp::Start);
        self.scatter.record(encoder);
        // The impostors this view's frame (and any frames prepared since its last recorded
        // one) rebuilt: in the host's submission, never in one of the sky's own, which could
        // hold the host's frame thread while the device is busy.
        v.ring.record_builds(
            encoder,
            &self.sheet_group,
            &self.build,
            &self.resident.group,
            &self.quads.0,
        );
        let view_group = v.view.group().filter(|_| v.sprites_to_draw > 0);
        let parts: Vec<(u32, u32, u32)> = view_group
            .map(|_| chunks(v.sprites_to_draw).collect())
            .unwrap_or_default();
        if parts.len() == 1
            && let Some(group) = view_group
        {
            let (c, _, n) = parts[0];
            self.build
                .record(encoder, group, &self.resident.group, (c, n));
        }
        // Below full resolution the clouds go to the cloud target, composited at the end with
        // the sky background; at full resolution they are drawn over the sky in the host's colour.
        stamp(encoder, Stamp::Build);
        let offscreen = v.clouds.frame(&self.device, &v.frame_buffer, depth_view);
        let mut pass = match &offscreen {
            Some(target) => {
                target.downsample(encoder, &frame_group);
                stamp(encoder, Stamp::Background);
                target.pass(encoder, true)
            }
            None => {
                let tested = self
                    .sky_tested_pipeline
                    .as_ref()
                    .filter(|_| can_test_against(depth_view));
                if let Some(tested) = tested {
                    // The background in a pass of its own, the host's depth attached.
                    let mut pass =
                        self.sky_pass(encoder, colour_view, &frame_group, Some(depth_view));
                    pass.set_pipeline(tested);
                    pass.draw(0..3, 0..1);
                }
                let mut pass = self.sky_pass(encoder, colour_view, &frame_group, None);
                if tested.is_none() {
                    pass.set_pipeline(&self.sky_pipeline);
                    pass.draw(0..3, 0..1);
                }
                if timer.is_some() {
                    drop(pass);
                    stamp(encoder, Stamp::Background);
                    pass = self.sky_pass(encoder, colour_view, &frame_group, None);
                }
                pass
            }
        };
        let (sprite_pipeline, in_cloud_pipeline) = match &offscreen {
            Some(target) => (target.sprite_pipeline(), target.in_cloud_pipeline()),
            None => (&self.sprite_pipeline, &self.in_cloud_pipeline),
        };
        // The far field behind the distant cells, they behind the ring, it behind the sprites
        // (blended over, back to front). The distant cells' sprites come first in the draw
        // list; split off when the frame's sprites are built in one part (with more, they are
        // drawn with the others, over the ring).
        self.far_field.draw(&mut pass, offscreen.is_some());
        if timer.is_some() {
            drop(pass);
            stamp(encoder, Stamp::FarField);
            pass = self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
        }
        let distant = if parts.len() == 1 {
            v.distant_sprites.min(v.sprites_to_draw)
        } else {
            0
        };
        if distant > 0 {
            self.draw_sprites(&mut pass, sprite_pipeline, 0..distant);
        }
        v.ring.draw(&mut pass, offscreen.is_some());
        if timer.is_some() {
            drop(pass);
            stamp(encoder, Stamp::Ring);
            pass = self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
        }
        for &(c, _, n) in &parts {
            if parts.len() > 1 {
                drop(pass);
                if let Some(group) = view_group {
                    self.build
                        .record(encoder, group, &self.resident.group, (c, n));
                }
                pass =
                    self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
            }
            self.draw_sprites(&mut pass, sprite_pipeline, distant.min(n)..n);
        }
        if v.in_cloud > 0.0 {
            pass.set_pipeline(in_cloud_pipeline);
            pass.draw(0..3, 0..1);
        }
        drop(pass);
        stamp(encoder, Stamp::Sprites);
        if let Some(target) = &offscreen {
            target.composite(encoder, colour_view, depth_view, &frame_group);
        }
        stamp(encoder, Stamp::Composite);
        if let Some(timer) = timer {
            timer.resolve(encoder);
        }
        v.recorded.set(true);
        v.record.set(start.spent());
        Ok(())
    }

    /// Draws `sprites` of the quads the build pass made this frame with `pipeline` (the host's
    /// colour or the cloud target's).
    fn draw_sprites(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        sprites: std::ops::Range<u32>,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, &self.sheet_group, &[]);
        pass.set_vertex_buffer(0, self.build.vertices().slice(..));
        pass.set_index_buffer(self.quads.0.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(sprites.start * 6..sprites.end * 6, 0, 0..1);
    }

    /// The clouds' pass taken up again after a break between passes (a timestamp while timing,
    /// a chunk's corner build): into the cloud target below full resolution, else over the
    /// host's colour, nothing cleared.
    fn clouds_pass_again<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        offscreen: Option<&super::cloud_target::CloudFrame<'_>>,
        colour_view: &wgpu::TextureView,
        frame_group: &wgpu::BindGroup,
    ) -> wgpu::RenderPass<'e> {
        match offscreen {
            Some(target) => target.pass(encoder, false),
            None => self.sky_pass(encoder, colour_view, frame_group, None),
        }
    }

    /// A pass over the host's colour (kept), with the frame's group 0 bound, and the host's
    /// depth as a read-only attachment when `depth` is given.
    fn sky_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        frame_group: &wgpu::BindGroup,
        depth: Option<&wgpu::TextureView>,
    ) -> wgpu::RenderPass<'e> {
        let mut pass = super::cloud_target::begin_with_depth(
            encoder,
            "sky",
            &[colour_view],
            wgpu::LoadOp::Load,
            depth,
        );
        pass.set_bind_group(0, frame_group, &[]);
        pass
    }
}

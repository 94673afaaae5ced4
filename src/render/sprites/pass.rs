//! The near sprites as one pass of the sky, in the shape every pass has: `new` builds its
//! pipelines once; `place` brings the resident sprites up to date (the store the ring and the
//! shadow map draw from too); `plan` makes a view's draw list on the CPU (`draw_list::main_view`:
//! plain data, tested without a device in `draw_list_tests`); `upload` writes it; `record`
//! builds the corners and draws them.
//!
//! The far storm cells are blocks of the same draw list: planned with it (they come first in
//! it, [`SpritePlan::distant`]) and drawn apart, behind the ring ([`SpritePass::draw`] over
//! `0..distant`).

use glam::{DVec3, Vec3};

use super::build::{CHUNK, SpriteBuild};
use super::draw_list::{Copies, Inside, Locks, Seams, distant_sprites, main_view};
use super::resident::{ResidentSet, quad_index_buffer};
use super::scatter::Scatter;
use super::sprite_view::{ViewBuffers, ViewData};
use crate::render::camera::Frustum;
use crate::render::gpu_types::{GpuDrawBlock, GpuSpriteVertex, GpuSpriteView};
use crate::render::pipeline::{PassDesc, SceneDepth, pipeline, premultiplied_over};
use crate::render::settings::RenderSettings;
use crate::render::stats::{FrameStats, Spent};
use crate::shading::{HarrisLastra, ShadingModel};

const SPRITES_WGSL: &str = include_str!("../../../shaders/sprites.wgsl");
const IN_CLOUD_WGSL: &str = include_str!("../../../shaders/in_cloud.wgsl");

/// What the sprite pass is made from: the host's colour target and the sky's layouts.
pub(in crate::render) struct SpriteShared<'a> {
    pub format: wgpu::TextureFormat,
    pub samples: u32,
    /// Group 0 of the passes into the host's targets (frame uniform, host depth).
    pub frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 1 of the sprite draw (sheet and sampler).
    pub sheet_layout: &'a wgpu::BindGroupLayout,
    /// The build pass's group of a view.
    pub view_layout: &'a wgpu::BindGroupLayout,
    /// The part of each sheet cell its texture covers.
    pub crops: &'a [[f32; 4]; 16],
}

/// The sprites on the GPU and how they are drawn: the resident set, the patch of changed
/// orders and lists, the corner build, the quad indices and the pipelines of the draw and the
/// in-cloud fog into the host's colour.
pub(in crate::render) struct SpritePass {
    pub resident: ResidentSet,
    pub scatter: Scatter,
    pub build: SpriteBuild,
    /// Quad indices for this many sprites (the most one draw needs so far).
    pub quads: (wgpu::Buffer, u32),
    pipeline: wgpu::RenderPipeline,
    in_cloud_pipeline: wgpu::RenderPipeline,
}

/// A view's frame of sprites as planned: plain numbers for its upload and its record.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(in crate::render) struct SpritePlan {
    /// Where the camera is among the clouds.
    pub inside: Inside,
    /// Sprites in the draw list.
    pub sprites: u32,
    /// The first of them: the far storm cells' (drawn behind the impostor ring).
    pub distant: u32,
}

/// What a view's draw list is planned from.
pub(in crate::render) struct SpriteFrame<'a> {
    pub camera_m: DVec3,
    pub frustum: &'a Frustum,
    /// The sky's clock, seconds.
    pub time_s: f64,
    /// The settings the sprites are drawn with this frame (their draw distance cut to the far
    /// field's hand-over band).
    pub drawn: &'a RenderSettings,
    /// Sprites whose orders may be sorted this frame.
    pub sort_budget: u32,
}

/// The state of one view the sprite pass plans into and reads back.
pub(in crate::render) struct SpriteViewState<'a> {
    pub near: &'a [u64],
    pub locks: &'a mut Locks,
    pub seams: &'a mut Seams,
    pub draws: &'a mut Vec<GpuDrawBlock>,
}

impl SpritePass {
    /// The resident set, the build and the pipelines, once.
    pub fn new(device: &wgpu::Device, shared: &SpriteShared) -> Self {
        let resident = ResidentSet::new(device, 0);
        let build = SpriteBuild::new(device, shared.view_layout, resident.layout(), shared.crops);
        let frame_only = [Some(shared.frame_layout)];
        let sprite_groups = [Some(shared.frame_layout), Some(shared.sheet_layout)];
        let over = Some(premultiplied_over());
        let (format, samples) = (shared.format, shared.samples);
        let pipeline = pipeline(
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
        let in_cloud_pipeline = pipeline_in_cloud(device, &frame_only, format, samples);
        Self {
            resident,
            scatter: Scatter::new(device),
            build,
            quads: (quad_index_buffer(device, 4096), 4096),
            pipeline,
            in_cloud_pipeline,
        }
    }

    /// Brings the resident sprites up to date before any pass plans: the light switched on
    /// (a provisional light for every sprite), the blocks that arrived placed (growing or
    /// packing the buffers; what holds slots across frames, `locks`, follows a packing) and
    /// written nearest first within `budget_sprites`, and their light within its budget. Counts
    /// into `stats`; returns the bytes written and the time the device held the frame thread
    /// while the buffers grew.
    pub fn place<'l>(
        &mut self,
        queue: &wgpu::Queue,
        (camera_m, budget_sprites): (DVec3, u32),
        (model, harris_lastra, sun_dir): (ShadingModel, &HarrisLastra, Vec3),
        locks: impl Iterator<Item = &'l mut Locks>,
        stats: &mut FrameStats,
    ) -> (u64, Spent) {
        let resident = &mut self.resident;
        (resident.lit_sprites, resident.light_us) = (0, 0);
        let mut bytes = 0;
        if resident.light.set(model, harris_lastra, sun_dir) {
            bytes += resident.provisional_all(queue);
        }
        stats.blocks_left_out = resident.place(queue, camera_m);
        if resident.packed() {
            // Blocks moved to other slots: what holds sprite slots from frame to frame follows
            // them, and a patch of orders kept for the old slots goes (the new buffers were
            // written whole from the CPU's copies, which hold its values).
            self.scatter.forget_kept();
            for l in locks {
                l.follow(|slot| resident.moved_slot(slot));
            }
        }
        bytes += resident.write_placed(queue, camera_m, budget_sprites);
        bytes += resident.relight(queue, camera_m);
        (stats.sprites_lit, stats.light_us) = (resident.lit_sprites, resident.light_us);
        (bytes, resident.grow_wait)
    }

    /// A view's draw list, on the CPU: its near blocks in view back to front, the orders and
    /// lists the cache says are stale recomputed into the resident set's CPU copies (within
    /// `frame.sort_budget`), its locks and seams. Counts into `stats`.
    pub fn plan(
        &mut self,
        view: SpriteViewState,
        frame: &SpriteFrame,
        stats: &mut FrameStats,
    ) -> SpritePlan {
        let resident = &mut self.resident;
        let inside = main_view(
            (&mut resident.blocks, view.near),
            Copies {
                orders: &mut resident.orders_cpu,
                dirty_orders: &mut resident.dirty_orders,
                lists: &mut resident.lists_cpu,
                dirty_lists: &mut resident.dirty_lists,
            },
            (frame.camera_m, frame.frustum),
            frame.time_s,
            (frame.drawn, frame.sort_budget),
            (view.locks, view.seams),
            view.draws,
            stats,
        );
        SpritePlan {
            inside,
            sprites: stats.sprites_drawn,
            distant: distant_sprites(view.draws, stats.sprites_drawn),
        }
    }

    /// Writes a planned frame: the patch of changed orders and lists (shared by every view),
    /// then the view's uniform `header`, its draw list and, when they changed, its locks.
    /// Returns the bytes written.
    #[allow(clippy::too_many_arguments)]
    pub fn upload(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        layout: &wgpu::BindGroupLayout,
        plan: &SpritePlan,
        header: &GpuSpriteView,
        (locks, draws): (&mut Locks, &[GpuDrawBlock]),
        buffers: &mut ViewBuffers,
    ) -> u64 {
        let resident = &mut self.resident;
        let mut bytes = self.scatter.prepare(
            device,
            queue,
            (&resident.orders_cpu, &resident.order_buffer),
            &mut resident.dirty_orders,
            (&resident.lists_cpu, &resident.list_buffer),
            &mut resident.dirty_lists,
        );
        let gpu_locks = locks.gpu();
        let changed_locks = locks.take_changed().then_some(&gpu_locks[..]);
        bytes += buffers.write(
            device,
            queue,
            layout,
            header,
            changed_locks,
            ViewData::Resident {
                counts: [draws.len() as u32, gpu_locks.len() as u32, plan.sprites, 0],
                draws,
                lists: &resident.list_buffer,
                orders: &resident.order_buffer,
                generation: resident.generation,
            },
        );
        bytes
    }

    /// Quad indices and built corners for the largest draw of the frame (`most` sprites: the
    /// view's, an impostor's sector, the shadow map's chunk), at most a chunk.
    pub fn reserve(&mut self, device: &wgpu::Device, most: u32) {
        let most = most.min(CHUNK);
        if most > self.quads.1 {
            let sprites = most.next_power_of_two();
            self.quads = (quad_index_buffer(device, sprites), sprites);
        }
        self.build.reserve(device, most);
    }

    /// The pipelines of the sprite draw and the in-cloud fog into the host's colour.
    pub fn pipelines(&self) -> (&wgpu::RenderPipeline, &wgpu::RenderPipeline) {
        (&self.pipeline, &self.in_cloud_pipeline)
    }

    /// Records the build of `sprites` sprites of chunk `chunk` of a view's draw list: their
    /// corners, for the draws after it.
    pub fn record_build(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view_group: &wgpu::BindGroup,
        (chunk, sprites): (u32, u32),
    ) {
        (self.build).record(encoder, view_group, &self.resident.group, (chunk, sprites));
    }

    /// Draws `sprites` of the quads the build made with `pipeline` (the host's colour or the
    /// cloud target's).
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (pipeline, sheet_group): (&wgpu::RenderPipeline, &wgpu::BindGroup),
        sprites: std::ops::Range<u32>,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, sheet_group, &[]);
        pass.set_vertex_buffer(0, self.build.vertices().slice(..));
        pass.set_index_buffer(self.quads.0.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(sprites.start * 6..sprites.end * 6, 0, 0..1);
    }

    /// Bytes of the resident set, the quad indices and the built corners.
    pub fn gpu_bytes(&self) -> u64 {
        self.resident.gpu_bytes() + self.quads.0.size() + self.build.gpu_bytes()
    }
}

/// The in-cloud fog's full-screen pipeline into the host's colour.
fn pipeline_in_cloud(
    device: &wgpu::Device,
    frame_only: &[Option<&wgpu::BindGroupLayout>],
    format: wgpu::TextureFormat,
    samples: u32,
) -> wgpu::RenderPipeline {
    pipeline(
        device,
        &PassDesc {
            label: "sky.in_cloud",
            wgsl: IN_CLOUD_WGSL,
            vs: "vs_in_cloud",
            fs: "fs_in_cloud",
            bind_groups: frame_only,
            buffers: &[],
            targets: &[(format, Some(premultiplied_over()))],
            samples,
            scene: SceneDepth::host(samples),
        },
    )
}

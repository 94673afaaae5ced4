//! One view of the sky: a camera with its targets. What a [`Sky`](super::Sky) prepares and
//! records per camera lives here (its frame uniform, its draw list and in-cloud locks, its
//! impostor ring, its off-screen cloud target); the blocks, the weather and the resident sprites
//! stay the sky's, shared by every view. Several views are prepared and recorded into one
//! encoder without overwriting each other's buffers: each writes only its own.

use std::cell::{Cell, RefCell};

use glam::Mat4;

use super::cloud_target::{CloudShared, CloudTarget, cloud_targets, divisor_of};
use super::gpu_types::{GpuDrawBlock, GpuFrame};
use super::impostor::{ImpostorRing, RingShared};
use super::settings::RenderSettings;
use super::sprites::draw_list::{Locks, Seams};
use super::sprites::sprite_view::ViewBuffers;
use super::stats::Spent;
use super::targets::HostTargets;

/// Which view of a [`Sky`](super::Sky): [`ViewId::MAIN`], made with it, or one of
/// [`Sky::add_view`](super::Sky::add_view).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ViewId(pub(super) usize);

impl ViewId {
    /// The view every sky has: the one [`Sky::prepare`](super::Sky::prepare) and
    /// [`Sky::record`](super::Sky::record) draw.
    pub const MAIN: ViewId = ViewId(0);
}

/// What a view is made from: the sky's layouts and settings.
pub(super) struct ViewShared<'a> {
    pub targets: HostTargets,
    pub settings: &'a RenderSettings,
    pub host_frame_layout: &'a wgpu::BindGroupLayout,
    pub ring_frame_layout: &'a wgpu::BindGroupLayout,
    pub sheet_layout: &'a wgpu::BindGroupLayout,
    pub view_layout: &'a wgpu::BindGroupLayout,
}

/// One camera's per-frame state. See the module docs.
pub(super) struct View {
    pub frame_buffer: wgpu::Buffer,
    pub view: ViewBuffers,
    pub draws: Vec<GpuDrawBlock>,
    pub locks: Locks,
    pub seams: Seams,
    pub sprites_to_draw: u32,
    /// The first of them: the distant blocks' (drawn behind the impostor ring).
    pub distant_sprites: u32,
    pub in_cloud: f32,
    /// How opaque the rain or snow shaft the camera is in is there (0: none): the fog thickens.
    pub in_rain: f32,
    /// What the last recording of this view spent.
    pub record: Cell<Spent>,
    /// Whether the last prepared frame was recorded (if not, its writes are flushed).
    pub recorded: Cell<bool>,
    /// The projection of the last prepared frame: checked against the targets' depth
    /// convention when it is recorded.
    pub projection: Option<Mat4>,
    pub ring: ImpostorRing,
    /// Where the clouds are drawn: the host's colour (scale 1) or the off-screen cloud target.
    pub clouds: CloudTarget,
    /// The frame bind group (the frame uniform and the host's depth) of the last recording,
    /// with the depth view it was made for: a host that keeps its depth view from frame to
    /// frame gets it again instead of a new one each frame.
    pub frame_group: RefCell<Option<(wgpu::TextureView, wgpu::BindGroup)>>,
}

impl View {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, shared: &ViewShared) -> Self {
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.frame"),
            size: std::mem::size_of::<GpuFrame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // Validated settings hold one of the three scales; a hand-built one falls back to 1.
        let divisor = divisor_of(shared.settings.clouds.resolution_scale).unwrap_or(1);
        let clouds = CloudTarget::new(
            device,
            &CloudShared {
                host_frame_layout: shared.host_frame_layout,
                frame_layout: shared.ring_frame_layout,
                sheet_layout: shared.sheet_layout,
                targets: shared.targets,
            },
            divisor,
        );
        let offscreen_targets = cloud_targets();
        let ring = ImpostorRing::new(
            device,
            queue,
            shared.settings.impostors,
            &RingShared {
                targets: shared.targets,
                frame_layout: shared.ring_frame_layout,
                host_frame_layout: shared.host_frame_layout,
                sheet_layout: shared.sheet_layout,
                view_layout: shared.view_layout,
                cloud_targets: (divisor > 1).then_some(&offscreen_targets[..]),
            },
        );
        Self {
            frame_buffer,
            view: ViewBuffers::new(device, false),
            draws: Vec::new(),
            locks: Locks::default(),
            seams: Seams::default(),
            sprites_to_draw: 0,
            distant_sprites: 0,
            in_cloud: 0.0,
            in_rain: 0.0,
            record: Cell::new(Spent::default()),
            frame_group: RefCell::new(None),
            recorded: Cell::new(true),
            projection: None,
            ring,
            clouds,
        }
    }

    /// Bytes of this view's own GPU buffers and textures: what one more view costs (its frame
    /// uniform, draw list and locks, ring, cloud target as last sized).
    pub fn gpu_bytes(&self) -> u64 {
        self.gpu_buffer_bytes() + self.clouds.gpu_bytes()
    }

    /// [`Self::gpu_bytes`] without the cloud target (which follows the host's frame size).
    pub fn gpu_buffer_bytes(&self) -> u64 {
        self.frame_buffer.size() + self.view.gpu_bytes() + self.ring.gpu_bytes()
    }
}

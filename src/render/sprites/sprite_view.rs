//! One view of the GPU-resident sprites (the sky's camera, or one impostor of the ring): its
//! uniform (light, thresholds, locks), its draw list of blocks and, for an impostor, its own
//! cloud lists and sprite orders (the sky's camera uses the resident ones); group 3 of the
//! sprite passes. Buffers grow in powers of two and are rewritten only
//! in the parts that changed.

use glam::Vec3;

use super::resident::storage_buffer;
use super::settings::CloudSettings;
use crate::clouds::LifecycleConfig;
use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud, GpuLock, GpuSpriteView, MAX_LOCKS};
use crate::render::stats::Lighting;
use crate::shading::ShadingModel;

/// Bytes of the view uniform before its lock table.
const HEADER_BYTES: usize = std::mem::size_of::<GpuSpriteView>() - MAX_LOCKS * 48;

/// The layout of group 3: view uniform, draw list, cloud lists, orders.
pub(in crate::render) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let storage = wgpu::BufferBindingType::Storage { read_only: true };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("sky.view_layout"),
        entries: &[
            entry(0, wgpu::BufferBindingType::Uniform),
            entry(1, storage),
            entry(2, storage),
            entry(3, storage),
        ],
    })
}

/// What a view's uniform says besides the locks.
pub(in crate::render) struct ViewLight<'a> {
    pub lighting: &'a Lighting,
    pub clouds: &'a CloudSettings,
    pub lifecycle: &'a LifecycleConfig,
    pub camera_z_m: f32,
    /// The farthest distance the view draws clouds at, metres: the sprites' draw distance for
    /// the camera, the view radius for an impostor.
    pub farthest_m: f32,
    /// While the far field is drawn, the band (start, end metres) over which every cloud fades
    /// out, below the horizon too, as the far field fades in (`far_fade` in
    /// `shaders/sprite_build.wgsl`).
    pub hand_over_m: Option<(f32, f32)>,
}

/// The uniform of a view (its lock table written apart).
pub(in crate::render) fn header(light: &ViewLight) -> GpuSpriteView {
    let ViewLight {
        lighting,
        clouds,
        lifecycle,
        camera_z_m,
        farthest_m,
        hand_over_m,
    } = *light;
    let (fade_start_m, fade_end_m) =
        hand_over_m.unwrap_or((farthest_m * (1.0 - clouds.far_fade_fraction), farthest_m));
    let tod = &lighting.time_of_day;
    let m = &lighting.mapping;
    let hl = &lighting.harris_lastra;
    let cos = |deg: f32| deg.to_radians().cos();
    let sin = |deg: f32| deg.to_radians().sin();
    GpuSpriteView {
        sun_dir_camera_z: lighting.sun_dir.extend(camera_z_m).to_array(),
        directional_ambient: tod.directional_rgb.extend(tod.ambient_percent).to_array(),
        mapping_g: [m.c_min, m.c_median, m.c_max, lighting.forward.g],
        forward_lock: [
            lighting.forward.strength,
            clouds.lock_radius_fraction,
            cos(clouds.lock_fade_start_deg),
            cos(clouds.lock_fade_end_deg),
        ],
        upright_lifecycle: [
            sin(clouds.upright_fade_start_deg),
            sin(clouds.upright_fade_end_deg),
            lifecycle.inner_radius_fraction.max(1e-4),
            lifecycle.outer_start_opacity,
        ],
        hl_phase: [
            (lighting.model == ShadingModel::HarrisLastra) as u32 as f32,
            hl.g,
            hl.lobe_weight,
            hl.sun_strength,
        ],
        hl_sky: (0.5 * (tod.sky_zenith_rgb + tod.sky_horizon_rgb) * hl.sky_strength)
            .extend(hl.ambient * tod.ambient_percent)
            .to_array(),
        hl_deck: [
            1.0 - hl.forward_fraction(),
            // y is the shadow map's (its own sprite order), set there.
            0.0,
            f32::from(u8::from(hand_over_m.is_some())),
            0.0,
        ],
        far_fade_layer_turn: [
            fade_start_m,
            fade_end_m,
            sin(clouds.layer_turn_start_deg),
            sin(clouds.layer_turn_end_deg),
        ],
        locks: [GpuLock {
            right: [0.0; 4],
            up: [0.0; 4],
            normal: Vec3::ZERO.to_array(),
            sprite: u32::MAX,
        }; MAX_LOCKS],
    }
}

/// A view's buffers and bind group.
pub(in crate::render) struct ViewBuffers {
    uniform: wgpu::Buffer,
    draws: Grown,
    /// An impostor view's own cloud lists (the sky's camera uses the resident ones).
    own: Option<Grown>,
    group: Option<wgpu::BindGroup>,
    /// Which order (and, for the sky's camera, list) buffers the group was made with.
    external_generation: u64,
    /// Scratch for the bytes of a write put together from two parts (the draw list after its
    /// counts, the lock table after the header): one queue write instead of two, each a
    /// staging buffer of its own in wgpu (a few microseconds apiece).
    joined: Vec<u8>,
    /// What the uniform buffer holds from its start (the header, then as much of the lock
    /// table as was last written).
    last_uniform: Vec<u8>,
}

/// A storage buffer that grows in powers of two.
struct Grown {
    buffer: wgpu::Buffer,
    capacity_bytes: u64,
    label: &'static str,
}

impl Grown {
    fn new(device: &wgpu::Device, label: &'static str, bytes: u64) -> Self {
        Self {
            buffer: storage_buffer(device, label, bytes),
            capacity_bytes: bytes,
            label,
        }
    }

    /// Makes room for `bytes`; true if the buffer was replaced.
    fn reserve(&mut self, device: &wgpu::Device, bytes: u64) -> bool {
        if bytes <= self.capacity_bytes {
            return false;
        }
        self.capacity_bytes = bytes.next_power_of_two();
        self.buffer = storage_buffer(device, self.label, self.capacity_bytes);
        true
    }

    /// Writes `data` at the start; returns the bytes.
    fn write<T: bytemuck::Pod>(&self, queue: &wgpu::Queue, data: &[T]) -> u64 {
        if data.is_empty() {
            return 0;
        }
        let bytes = bytemuck::cast_slice(data);
        queue.write_buffer(&self.buffer, 0, bytes);
        bytes.len() as u64
    }
}

/// What a view writes besides its uniform: its draw list (after a header of its counts: blocks,
/// locks, sprites), and an impostor's own cloud lists with the ring's order buffer or, for the
/// sky's camera, the resident list and order buffers (with their generation).
pub(in crate::render) enum ViewData<'a> {
    Own {
        counts: [u32; 4],
        draws: &'a [GpuDrawBlock],
        lists: &'a [GpuListCloud],
        orders: (&'a wgpu::Buffer, u64),
    },
    Resident {
        counts: [u32; 4],
        draws: &'a [GpuDrawBlock],
        lists: &'a wgpu::Buffer,
        orders: &'a wgpu::Buffer,
        generation: u64,
    },
}

impl ViewBuffers {
    /// Buffers for a view; `own` for an impostor view (its own cloud lists).
    pub fn new(device: &wgpu::Device, own: bool) -> Self {
        Self {
            uniform: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sky.view"),
                size: std::mem::size_of::<GpuSpriteView>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            draws: Grown::new(device, "sky.draws", 256 * 32),
            own: own.then(|| Grown::new(device, "sky.view_lists", 1024 * 16)),
            group: None,
            external_generation: u64::MAX,
            joined: Vec::new(),
            last_uniform: Vec::new(),
        }
    }

    /// Bytes of its buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.uniform.size()
            + self.draws.buffer.size()
            + self.own.as_ref().map_or(0, |l| l.buffer.size())
    }

    /// Writes the uniform (`locks`: the whole lock table too, else only the header) and `data`;
    /// returns the bytes written.
    pub fn write(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        view: &GpuSpriteView,
        locks: Option<&[GpuLock]>,
        data: ViewData,
    ) -> u64 {
        let mut regroup = self.group.is_none();
        let (counts, draws) = match &data {
            ViewData::Own { counts, draws, .. } | ViewData::Resident { counts, draws, .. } => {
                (*counts, *draws)
            }
        };
        regroup |= self.draws.reserve(device, 16 + draws.len() as u64 * 32);
        self.joined.clear();
        self.joined.extend_from_slice(bytemuck::bytes_of(&counts));
        self.joined.extend_from_slice(bytemuck::cast_slice(draws));
        queue.write_buffer(&self.draws.buffer, 0, &self.joined);
        let mut bytes = self.joined.len() as u64;
        let generation = match (&data, &mut self.own) {
            (ViewData::Own { lists, orders, .. }, Some(own_lists)) => {
                regroup |= own_lists.reserve(device, lists.len() as u64 * 16);
                bytes += own_lists.write(queue, lists);
                orders.1
            }
            (ViewData::Resident { generation, .. }, _) => *generation,
            (ViewData::Own { .. }, None) => return bytes,
        };
        regroup |= generation != self.external_generation;
        self.external_generation = generation;
        let (lists, orders) = match (&data, &self.own) {
            (ViewData::Resident { lists, orders, .. }, _) => (*lists, *orders),
            (ViewData::Own { orders, .. }, Some(l)) => (&l.buffer, orders.0),
            (ViewData::Own { .. }, None) => return bytes,
        };
        if regroup {
            fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
                wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                }
            }
            self.group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sky.view_group"),
                layout,
                entries: &[
                    entry(0, &self.uniform),
                    entry(1, &self.draws.buffer),
                    entry(2, lists),
                    entry(3, orders),
                ],
            }));
        }
        self.joined.clear();
        self.joined
            .extend_from_slice(&bytemuck::bytes_of(view)[..HEADER_BYTES]);
        if let Some(locks) = locks.filter(|l| !l.is_empty()) {
            let table = bytemuck::cast_slice(&locks[..locks.len().min(MAX_LOCKS)]);
            self.joined.extend_from_slice(table);
        }
        // The header stays the same over most frames (the light and the fades' settings): a
        // queue write is a staging buffer of its own, so what the buffer holds is not sent
        // again.
        let held = self.last_uniform.len() >= self.joined.len()
            && self.last_uniform[..self.joined.len()] == self.joined[..];
        if held {
            return bytes;
        }
        queue.write_buffer(&self.uniform, 0, &self.joined);
        let n = self.joined.len().max(self.last_uniform.len());
        self.last_uniform.resize(n, 0);
        self.last_uniform[..self.joined.len()].copy_from_slice(&self.joined);
        bytes + self.joined.len() as u64
    }

    /// The view's group of the build pass (after the first [`Self::write`]).
    pub fn group(&self) -> Option<&wgpu::BindGroup> {
        self.group.as_ref()
    }
}

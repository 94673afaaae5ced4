//! One view of the GPU-resident sprites (the sky's camera, or one impostor of the ring): its
//! uniform (light, thresholds, locks), its draw list and, for an impostor, its own sprite
//! orders; group 3 of the sprite passes. Buffers grow in powers of two and are rewritten only
//! in the parts that changed.

use glam::Vec3;

use super::gpu_types::{GpuDrawCloud, GpuLock, GpuSpriteView, MAX_LOCKS};
use super::settings::CloudSettings;
use super::stats::Lighting;
use crate::clouds::LifecycleConfig;

/// Bytes of the view uniform before its lock table.
const HEADER_BYTES: usize = std::mem::size_of::<GpuSpriteView>() - MAX_LOCKS * 48;

/// The layout of group 3: view uniform, draw list, orders.
pub(super) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX,
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
        ],
    })
}

/// What a view's uniform says besides the locks.
pub(super) struct ViewLight<'a> {
    pub lighting: &'a Lighting,
    pub clouds: &'a CloudSettings,
    pub lifecycle: &'a LifecycleConfig,
    pub camera_z_m: f32,
}

/// The uniform of a view with `draws` clouds and `locks` locks (the table written apart).
pub(super) fn header(light: &ViewLight, draws: u32, locks: u32) -> GpuSpriteView {
    let ViewLight {
        lighting,
        clouds,
        lifecycle,
        camera_z_m,
    } = *light;
    let tod = &lighting.time_of_day;
    let m = &lighting.mapping;
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
        counts: [draws, locks, 0, 0],
        locks: [GpuLock {
            right: [0.0; 4],
            up: [0.0; 4],
            normal: Vec3::ZERO.to_array(),
            sprite: u32::MAX,
        }; MAX_LOCKS],
    }
}

/// A view's buffers and bind group.
pub(super) struct ViewBuffers {
    uniform: wgpu::Buffer,
    draws: wgpu::Buffer,
    draw_capacity: u64,
    /// An impostor view's own orders (the sky's camera uses the resident order buffer).
    orders: Option<wgpu::Buffer>,
    order_capacity: u64,
    group: Option<wgpu::BindGroup>,
    /// Which external order buffer the group was made with.
    orders_generation: u64,
}

fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl ViewBuffers {
    /// Buffers for a view; `own_orders` for an impostor view.
    pub fn new(device: &wgpu::Device, own_orders: bool) -> Self {
        let draw_capacity = 256;
        Self {
            uniform: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sky.view"),
                size: std::mem::size_of::<GpuSpriteView>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            draws: storage(device, "sky.draws", draw_capacity * 32),
            draw_capacity,
            orders: own_orders.then(|| storage(device, "sky.view_orders", 1024 * 4)),
            order_capacity: if own_orders { 1024 } else { 0 },
            group: None,
            orders_generation: u64::MAX,
        }
    }

    /// Bytes of its buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.uniform.size() + self.draws.size() + self.orders.as_ref().map_or(0, |b| b.size())
    }

    /// Writes the uniform (`locks`: the whole lock table too, else only the header), the draw
    /// list and an impostor's own `orders`; `external` is the resident order buffer and its
    /// generation for the sky's camera. Returns the bytes written.
    #[allow(clippy::too_many_arguments)]
    pub fn write(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        view: &GpuSpriteView,
        locks: Option<&[GpuLock]>,
        draws: &[GpuDrawCloud],
        orders: Option<&[u32]>,
        external: Option<(&wgpu::Buffer, u64)>,
    ) -> u64 {
        let mut regroup = self.group.is_none();
        if draws.len() as u64 > self.draw_capacity {
            self.draw_capacity = (draws.len() as u64).next_power_of_two();
            self.draws = storage(device, "sky.draws", self.draw_capacity * 32);
            regroup = true;
        }
        if let Some(orders) = orders
            && orders.len() as u64 > self.order_capacity
        {
            self.order_capacity = (orders.len() as u64).next_power_of_two();
            self.orders = Some(storage(device, "sky.view_orders", self.order_capacity * 4));
            regroup = true;
        }
        if let Some((_, generation)) = external
            && generation != self.orders_generation
        {
            self.orders_generation = generation;
            regroup = true;
        }
        let order_buffer = external.map(|e| e.0).or(self.orders.as_ref());
        if regroup && let Some(order_buffer) = order_buffer {
            self.group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sky.view_group"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: self.draws.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: order_buffer.as_entire_binding(),
                    },
                ],
            }));
        }
        let mut bytes = 0;
        let header = &bytemuck::bytes_of(view)[..HEADER_BYTES];
        queue.write_buffer(&self.uniform, 0, header);
        bytes += header.len() as u64;
        if let Some(locks) = locks.filter(|l| !l.is_empty()) {
            let table = bytemuck::cast_slice(&locks[..locks.len().min(MAX_LOCKS)]);
            queue.write_buffer(&self.uniform, HEADER_BYTES as u64, table);
            bytes += table.len() as u64;
        }
        if !draws.is_empty() {
            queue.write_buffer(&self.draws, 0, bytemuck::cast_slice(draws));
            bytes += draws.len() as u64 * 32;
        }
        if let (Some(orders), Some(buffer)) = (orders.filter(|o| !o.is_empty()), &self.orders) {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(orders));
            bytes += orders.len() as u64 * 4;
        }
        bytes
    }

    /// The uniform and the draw list (for the corner read-back).
    pub fn buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.uniform, &self.draws)
    }

    /// Group 3 of the sprite passes (after the first [`Self::write`]).
    pub fn group(&self) -> Option<&wgpu::BindGroup> {
        self.group.as_ref()
    }
}

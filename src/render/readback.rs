//! The corners of a frame's sprites as the vertex shader builds them, read back for tests and
//! tools: the same WGSL function (`sprite_corner` in `shaders/sprites.wgsl`) run in a compute
//! pass over the sky's buffers (`shaders/sprite_corners.wgsl`). Slow (it waits for the device);
//! never part of a frame.

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};

use super::RenderError;

const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
const CORNERS_WGSL: &str = include_str!("../../shaders/sprite_corners.wgsl");

/// One corner as read back. Keep in sync with `CornerOut` in `shaders/sprite_corners.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuCorner {
    rel_m_visible: [f32; 4],
    colour: [f32; 4],
}

/// One sprite corner of a prepared frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpriteCorner {
    /// Position relative to the camera, metres (east, north, up).
    pub rel_m: Vec3,
    /// Whether it is drawn (false: faded out by the lock angle, the upright fade or its fade).
    pub visible: bool,
    /// Wang's vertex colour (ambient + directional) and alpha, before the texture.
    pub colour: Vec4,
}

/// The buffers of the sky's camera view the corners are built from.
pub(super) struct CornerSources<'a> {
    pub sprites: &'a wgpu::Buffer,
    pub clouds: &'a wgpu::Buffer,
    pub view: &'a wgpu::Buffer,
    pub draws: &'a wgpu::Buffer,
    pub lists: &'a wgpu::Buffer,
    pub orders: &'a wgpu::Buffer,
}

/// Runs the vertex shader's corner code for `sprites` sprites and reads the corners back, four
/// per sprite in drawing order.
pub(super) fn read_corners(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    src: &CornerSources,
    sprites: u32,
) -> Result<Vec<SpriteCorner>, RenderError> {
    let count = sprites as u64 * 4;
    if count == 0 {
        return Ok(Vec::new());
    }
    let stage_buffers = device.limits().max_storage_buffers_per_shader_stage;
    if stage_buffers < 6 {
        return Err(RenderError::Device(format!(
            "reading sprite corners back needs 6 storage buffers per shader stage, the device has {stage_buffers}"
        )));
    }
    let module = super::pipeline::shader(
        device,
        "sky.sprite_corners",
        &format!("{SPRITES_WGSL}\n{CORNERS_WGSL}"),
    );
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("sky.sprite_corners"),
        layout: None,
        module: &module,
        entry_point: Some("cs_sprite_corners"),
        compilation_options: Default::default(),
        cache: None,
    });
    let bytes = count * std::mem::size_of::<GpuCorner>() as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_corners"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_corners_read"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let group = |index: u32, entries: &[(u32, &wgpu::Buffer)]| {
        let entries: Vec<wgpu::BindGroupEntry> = entries
            .iter()
            .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.sprite_corners"),
            layout: &pipeline.get_bind_group_layout(index),
            entries: &entries,
        })
    };
    let groups = [
        group(0, &[]),
        group(1, &[(2, &out)]),
        group(2, &[(0, src.sprites), (1, src.clouds)]),
        group(
            3,
            &[
                (0, src.view),
                (1, src.draws),
                (2, src.lists),
                (3, src.orders),
            ],
        ),
    ];
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sky.sprite_corners"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&pipeline);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, g, &[]);
        }
        pass.dispatch_workgroups(count.div_ceil(64) as u32, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &read, 0, bytes);
    queue.submit([encoder.finish()]);
    read.map_async(wgpu::MapMode::Read, .., |_| {});
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let view = read
        .get_mapped_range(..)
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let corners: &[GpuCorner] = bytemuck::cast_slice(&view);
    Ok(corners
        .iter()
        .map(|c| SpriteCorner {
            rel_m: Vec3::new(c.rel_m_visible[0], c.rel_m_visible[1], c.rel_m_visible[2]),
            visible: c.rel_m_visible[3] > 0.5,
            colour: Vec4::from_array(c.colour),
        })
        .collect())
}

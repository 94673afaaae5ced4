//! The corners of a frame's sprites as the build pass makes them for the draw, read back for
//! tests and tools (`Sky::read_back_corners`). Slow (it waits for the device); never part of a
//! frame.

use glam::{Vec3, Vec4};

use super::RenderError;
use super::gpu_types::GpuSpriteVertex;

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

/// A buffer for `sprites` sprites' corners to be copied into and read back.
pub(super) fn read_buffer(device: &wgpu::Device, sprites: u32) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_corners_read"),
        size: (sprites as u64 * 4 * std::mem::size_of::<GpuSpriteVertex>() as u64).max(16),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    })
}

/// Runs `encoder` (which copies `sprites` sprites' corners into `read`) and reads them back,
/// four per sprite in drawing order.
pub(super) fn read_corners(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    read: &wgpu::Buffer,
    sprites: u32,
) -> Result<Vec<SpriteCorner>, RenderError> {
    queue.submit([encoder.finish()]);
    if sprites == 0 {
        return Ok(Vec::new());
    }
    read.map_async(wgpu::MapMode::Read, .., |_| {});
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let view = read
        .get_mapped_range(..)
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let corners: &[GpuSpriteVertex] = bytemuck::cast_slice(&view);
    Ok(corners[..sprites as usize * 4]
        .iter()
        .map(|c| {
            let p = c.position_visible;
            SpriteCorner {
                rel_m: Vec3::new(p[0], p[1], p[2]),
                visible: p[3] > 0.5,
                colour: Vec4::from_array(c.colour),
            }
        })
        .collect())
}

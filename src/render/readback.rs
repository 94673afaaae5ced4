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

/// Finishes `encoder` (which builds the corners into `vertices`) with a copy of the first
/// `sprites` sprites' corners, runs it and reads them back, four per sprite in drawing order.
pub(super) fn read_corners(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mut encoder: wgpu::CommandEncoder,
    vertices: &wgpu::Buffer,
    sprites: u32,
) -> Result<Vec<SpriteCorner>, RenderError> {
    let bytes = sprites as u64 * 4 * std::mem::size_of::<GpuSpriteVertex>() as u64;
    if bytes == 0 {
        queue.submit([encoder.finish()]);
        return Ok(Vec::new());
    }
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_corners_read"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(vertices, 0, &read, 0, bytes);
    queue.submit([encoder.finish()]);
    read.map_async(wgpu::MapMode::Read, .., |_| {});
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let view = read
        .get_mapped_range(..)
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let corners: &[GpuSpriteVertex] = bytemuck::cast_slice(&view);
    Ok(corners
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

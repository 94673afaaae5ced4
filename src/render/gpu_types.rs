//! The structs the GPU reads, each with a WGSL twin of the same field names. Keep in sync with
//! `shaders/shared/frame.wgsl` (`Frame`), `shaders/sprites.wgsl` (`SpriteVertex`) and
//! `shaders/terrain.wgsl` (`TerrainFrame`, `TerrainVertex`).

use bytemuck::{Pod, Zeroable};

/// Per-frame uniform of the sky passes. Keep in sync with `shaders/shared/frame.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuFrame {
    /// Camera-relative world (east, north, up metres) to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// Inverse of `view_proj`, for sky rays.
    pub inv_view_proj: [[f32; 4]; 4],
    /// xyz: unit vector towards the sun; w: cosine of the disc radius.
    pub sun_dir: [f32; 4],
    /// rgb: sun colour; w: cosine of the glow radius.
    pub sun_rgb: [f32; 4],
    /// rgb: sky colour straight up.
    pub sky_zenith_rgb: [f32; 4],
    /// rgb: sky colour at the horizon.
    pub sky_horizon_rgb: [f32; 4],
    /// rgb: in-cloud fog colour; a: how far inside a cloud the camera is, 0..=1.
    pub in_cloud_rgba: [f32; 4],
    /// near_m, far_m, soft_depth_fade_m, in_cloud_visibility_m.
    pub params: [f32; 4],
    /// x: distance at which sprites have faded 63% into the horizon haze, metres; yzw unused.
    pub haze: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuFrame>() == 240);

/// One corner of a cloud sprite, camera-relative. Keep in sync with `VertexIn` in
/// `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuSpriteVertex {
    /// Position relative to the camera, metres (east, north, up).
    pub position_m: [f32; 3],
    /// Padding to 16 bytes.
    pub _pad0: f32,
    /// Texture coordinate on the sheet.
    pub uv: [f32; 2],
    /// Padding to 16 bytes.
    pub _pad1: [f32; 2],
    /// Wang 5.3 vertex colour `(C_amb + C_dir)` and alpha (ambient alpha times alpha_morph).
    pub colour: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuSpriteVertex>() == 48);

impl GpuSpriteVertex {
    /// The buffer layout (offsets of uv and colour match the struct).
    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        const ATTRS: [wgpu::VertexAttribute; 3] = [
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 0,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x2,
                offset: 16,
                shader_location: 1,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x4,
                offset: 32,
                shader_location: 2,
            },
        ];
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<GpuSpriteVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ATTRS,
        }
    }
}

/// Per-frame uniform of the demo terrain. Keep in sync with `shaders/terrain.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuTerrainFrame {
    /// Camera-relative world to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// xyz: mesh origin minus camera position, metres; w unused.
    pub origin_rel: [f32; 4],
    /// xyz: unit vector towards the sun; w: ambient light factor.
    pub sun_dir: [f32; 4],
    /// rgb: sun colour.
    pub sun_rgb: [f32; 4],
    /// rgb: fog colour; w: fog visibility, metres.
    pub fog_rgb: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuTerrainFrame>() == 128);

/// One terrain vertex, relative to the mesh origin. Keep in sync with `shaders/terrain.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTerrainVertex {
    /// Position from the mesh origin, metres (z above mean sea level minus origin z).
    pub position_m: [f32; 3],
    /// Height above mean sea level, metres (colours the ground).
    pub height_m: f32,
    /// Unit surface normal; w unused.
    pub normal: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuTerrainVertex>() == 32);

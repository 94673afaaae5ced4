//! A headless host: a wgpu device on any adapter (Mesa's lavapipe on machines without a GPU)
//! and an offscreen colour + depth target that can be read back. The CLI and the render tests
//! use it; a real simulator brings its own device and targets instead.

use crate::render::{HostTargets, RenderError};

/// The colour format of the offscreen target: linear half floats (EXR-ready).
pub const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The depth format of the offscreen target.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The off-screen targets as the sky sees them: standard Z, one sample.
pub const TARGETS: HostTargets = HostTargets {
    colour_format: COLOUR_FORMAT,
    depth_format: DEPTH_FORMAT,
    reversed_z: false,
    sample_count: 1,
};

/// The apt line that installs the software Vulkan driver.
pub use crate::render::INSTALL_HINT;

/// A device and queue with no window.
pub struct HeadlessGpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's name, backend and type.
    pub adapter_info: wgpu::AdapterInfo,
    depth_copies: bool,
}

impl HeadlessGpu {
    /// Creates a device on the best adapter there is (`WGPU_BACKEND` picks a backend).
    /// No adapter at all is [`RenderError::NoAdapter`], whose message has the apt line.
    pub fn new() -> Result<Self, RenderError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env().unwrap_or_default(),
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let adapter_info = adapter.get_info();
        // GPU frame times where the adapter can measure them.
        let timing =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let required_features = if adapter.features().contains(timing) {
            timing
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("skycast.headless"),
            required_features,
            // WebGPU's 8 storage buffers per stage where the adapter has them (the sprite corner
            // read-back uses 5); the rest as any downlevel device.
            required_limits: wgpu::Limits {
                max_storage_buffers_per_shader_stage:
                    adapter.limits().max_storage_buffers_per_shader_stage.min(8),
                ..wgpu::Limits::downlevel_defaults()
            },
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| RenderError::Device(e.to_string()))?;
        let depth_copies = adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES);
        Ok(Self {
            device,
            queue,
            adapter_info,
            depth_copies,
        })
    }
}

/// One read-back frame: linear RGBA and depth.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Linear RGBA, row-major from the top left.
    pub rgba: Vec<[f32; 4]>,
    /// Depth buffer values `[0, 1]` (1 = nothing drawn), row-major.
    pub depth: Vec<f32>,
}

/// An offscreen colour + depth target.
pub struct OffscreenTarget {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    /// View of the colour texture.
    pub colour_view: wgpu::TextureView,
    /// View of the depth texture.
    pub depth_view: wgpu::TextureView,
}

fn padded_row(bytes: u32) -> u32 {
    bytes.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

impl OffscreenTarget {
    /// A `width` x `height` target ([`COLOUR_FORMAT`], [`DEPTH_FORMAT`]).
    pub fn new(gpu: &HeadlessGpu, width: u32, height: u32) -> Result<Self, RenderError> {
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::Size { width, height, max });
        }
        let make = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let colour = make("host.colour", COLOUR_FORMAT, usage);
        let depth = make("host.depth", DEPTH_FORMAT, usage);
        let colour_view = colour.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        Ok(Self {
            width,
            height,
            colour,
            depth,
            colour_view,
            depth_view,
        })
    }

    /// Copies colour and depth back to the CPU (waits for the GPU).
    pub fn read_back(&self, gpu: &HeadlessGpu) -> Result<Frame, RenderError> {
        if !gpu.depth_copies {
            return Err(RenderError::Device(
                "this adapter cannot copy depth textures to buffers; use the Vulkan backend".into(),
            ));
        }
        let (w, h) = (self.width, self.height);
        let colour_row = padded_row(w * 8);
        let depth_row = padded_row(w * 4);
        let buffer = |label, size| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            })
        };
        let colour_buf = buffer("host.colour_readback", (colour_row * h) as u64);
        let depth_buf = buffer("host.depth_readback", (depth_row * h) as u64);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let extent = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        for (texture, aspect, buf, row) in [
            (
                &self.colour,
                wgpu::TextureAspect::All,
                &colour_buf,
                colour_row,
            ),
            (
                &self.depth,
                wgpu::TextureAspect::DepthOnly,
                &depth_buf,
                depth_row,
            ),
        ] {
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: buf,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(h),
                    },
                },
                extent,
            );
        }
        gpu.queue.submit([enc.finish()]);
        colour_buf.map_async(wgpu::MapMode::Read, .., |_| {});
        depth_buf.map_async(wgpu::MapMode::Read, .., |_| {});
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let unpad = |buf: &wgpu::Buffer, row: u32, bytes: u32| -> Result<Vec<u8>, RenderError> {
            let view = buf
                .get_mapped_range(..)
                .map_err(|e| RenderError::Device(e.to_string()))?;
            let mut out = Vec::with_capacity((bytes * h) as usize);
            for y in 0..h as usize {
                let s = y * row as usize;
                out.extend_from_slice(&view[s..s + bytes as usize]);
            }
            Ok(out)
        };
        let colour_bytes = unpad(&colour_buf, colour_row, w * 8)?;
        let depth_bytes = unpad(&depth_buf, depth_row, w * 4)?;
        let half_at =
            |p: &[u8], i: usize| half::f16::from_le_bytes([p[2 * i], p[2 * i + 1]]).to_f32();
        let rgba = colour_bytes
            .chunks_exact(8)
            .map(|p| [half_at(p, 0), half_at(p, 1), half_at(p, 2), half_at(p, 3)])
            .collect();
        let depth = depth_bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok(Frame {
            width: w,
            height: h,
            rgba,
            depth,
        })
    }
}

//! The shadow map's GPU side: its textures and pipelines, and the recording of a frame's
//! drawing ([`CloudShadows::record`]): a whole map cleared and drawn, or the map scrolled in
//! place and the rectangles [`CloudShadows::prepare`] chose cleared and drawn again (the draw
//! masked to them in the shader), with the blocks that arrived added over the whole map.

use super::{CloudShadows, RenderError, SHADOW_FORMAT, ShadowImage, WGSL};
use crate::render::gpu_types::GpuSpriteVertex;
use crate::render::sprites::build::{SpriteBuild, chunks};

/// The built corners as the shadow pass reads them: `GpuSpriteVertex`'s position, uv, how many
/// sprites it stands for, and colour (its alpha).
fn shadow_vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRS: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
        0 => Float32x4, 1 => Float32x2, 2 => Float32x4, 3 => Float32x2
    ];
    // Offsets: position 0, uv 16, stands_for 24, colour 32 (`GpuSpriteVertex`).
    const PLACED: [wgpu::VertexAttribute; 4] = [
        ATTRS[0],
        wgpu::VertexAttribute {
            offset: 16,
            ..ATTRS[1]
        },
        wgpu::VertexAttribute {
            offset: 32,
            ..ATTRS[2]
        },
        wgpu::VertexAttribute {
            offset: 24,
            ..ATTRS[3]
        },
    ];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuSpriteVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &PLACED,
    }
}

/// A texture of `width` x `height` texels of optical depth.
pub(super) fn shadow_texture(
    device: &wgpu::Device,
    [width, height]: [u32; 2],
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("sky.cloud_shadow"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SHADOW_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    (texture, view)
}

/// The pipelines over `layout` (the uniform; the cores are analytic, so no sprite sheet is
/// read): the sprites adding their optical depth, and the clear of a rectangle (a triangle over
/// the map writing 0, cut by the scissor), which reads no group.
pub(super) fn pipelines(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
) -> [wgpu::RenderPipeline; 2] {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("sky.cloud_shadow"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("sky.cloud_shadow"),
        source: wgpu::ShaderSource::Wgsl(WGSL.into()),
    });
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let shadow = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("sky.cloud_shadow"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_shadow"),
            compilation_options: Default::default(),
            buffers: &[Some(shadow_vertex_layout())],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_shadow"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: SHADOW_FORMAT,
                blend: Some(wgpu::BlendState {
                    color: add,
                    alpha: add,
                }),
                write_mask: wgpu::ColorWrites::RED,
            })],
        }),
        multiview_mask: None,
        cache: None,
    });
    let clear = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("sky.cloud_shadow_clear"),
        layout: Some(
            &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sky.cloud_shadow_clear"),
                bind_group_layouts: &[],
                immediate_size: 0,
            }),
        ),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_clear"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_clear"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: SHADOW_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::RED,
            })],
        }),
        multiview_mask: None,
        cache: None,
    });
    [shadow, clear]
}

impl CloudShadows {
    /// Records this frame's drawing, if any (its own passes, in the sky's submission before the
    /// host's frame): a scroll moves the map's texels first; the rectangles drawn again are
    /// cleared (a triangle under each one's scissor); then, chunk by chunk, the sprites' corners
    /// are built from the resident sprites (`resident`) by `build` and drawn (`indices`: the
    /// quad index buffer), the map's blocks kept to the rectangles, the blocks that arrived over
    /// all of it.
    pub(in crate::render) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        build: &SpriteBuild,
        resident: &wgpu::BindGroup,
        indices: &wgpu::Buffer,
    ) {
        let Some(sprites) = self.pending else {
            return;
        };
        let timer = self.timer.as_ref().filter(|_| self.timed.get());
        if let Some(t) = timer {
            t.write(encoder, 0);
        }
        // A scroll moves the texels the old map shares with the new one in place, a band at a
        // time through the scratch texture.
        fn at(texture: &wgpu::Texture, [x, y]: [u32; 2]) -> wgpu::TexelCopyTextureInfo<'_> {
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            }
        }
        for copy in &self.copies {
            let size = wgpu::Extent3d {
                width: copy.size[0],
                height: copy.size[1],
                depth_or_array_layers: 1,
            };
            let (map, scratch) = (&self.texture, &self.scratch);
            encoder.copy_texture_to_texture(at(map, copy.src), at(scratch, [0, 0]), size);
            encoder.copy_texture_to_texture(at(scratch, [0, 0]), at(map, copy.dst), size);
        }
        let view = self.sprites_view.group().filter(|_| sprites > 0);
        let parts: Vec<(u32, u32, u32)> = chunks(sprites).collect();
        for k in 0..parts.len().max(1) {
            let part = parts.get(k).copied();
            if let (Some(view), Some((c, _, n))) = (view, part) {
                build.record_cores(encoder, view, resident, (c, n));
            }
            let load = if k == 0 && self.whole {
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
            } else {
                wgpu::LoadOp::Load
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sky.cloud_shadow"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if k == 0 && !self.clears.is_empty() {
                // The rectangles drawn again hold 0 before their sprites add to them.
                pass.set_pipeline(&self.clear_pipeline);
                for r in &self.clears {
                    pass.set_scissor_rect(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0);
                    pass.draw(0..3, 0..1);
                }
                let side = self.texture.width();
                pass.set_scissor_rect(0, 0, side, side);
            }
            if let (Some(_), Some((_, first, n))) = (view, part) {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &self.group, &[]);
                pass.set_vertex_buffer(0, build.vertices().slice(..));
                pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                for segment in &self.segments {
                    let lo = segment.first.max(first);
                    let hi = (segment.first + segment.sprites).min(first + n);
                    // Instance 1: the fragments kept to the rectangles drawn again.
                    let instance = u32::from(segment.masked);
                    if lo < hi {
                        let indices = (lo - first) * 6..(hi - first) * 6;
                        pass.draw_indexed(indices, 0, instance..instance + 1);
                    }
                }
            }
        }
        if let Some(t) = timer {
            t.write(encoder, 1);
            t.resolve(encoder);
        }
    }

    /// Times the draw on the GPU (two timestamps around it) from the next frame on, or stops.
    pub(in crate::render) fn set_timing(&mut self, queue: &wgpu::Queue, on: bool) {
        self.timer = if on {
            crate::render::Timestamps::new(&self.device, queue, "sky.cloud_shadow_time", 2)
        } else {
            None
        };
    }

    /// GPU milliseconds of the last prepared frame's draw (0 if it drew none), once submitted;
    /// `None` while not timing. Waits for the device.
    pub(in crate::render) fn last_ms(&self) -> Option<f64> {
        let timer = self.timer.as_ref()?;
        if !self.timed.get() {
            return Some(0.0);
        }
        timer.read_ms(&self.device)?.get(1).copied()
    }

    /// Reads the map back (tests and tools): waits for the device.
    pub fn read_back(&self, queue: &wgpu::Queue) -> Result<ShadowImage, RenderError> {
        let texture = &self.texture;
        let side = texture.width();
        let row = (side * 2).div_ceil(256) * 256;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.cloud_shadow_read"),
            size: row as u64 * side as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            texture.size(),
        );
        queue.submit([encoder.finish()]);
        buffer.map_async(wgpu::MapMode::Read, .., |_| {});
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let data = buffer
            .get_mapped_range(..)
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let tau = data
            .chunks_exact(row as usize)
            .flat_map(|r| {
                r[..side as usize * 2]
                    .chunks_exact(2)
                    .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
            })
            .collect();
        Ok(ShadowImage { size_px: side, tau })
    }
}

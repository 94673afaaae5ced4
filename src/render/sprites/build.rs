//! The build pass (`shaders/sprite_build.wgsl`): a compute pass that makes the corners of a
//! view's sprites (facing, lock, Wang's shading, fades) from the GPU-resident sprites, the view's
//! draw list, cloud lists and orders, into a vertex buffer the sprite draw reads. The buffer
//! holds at most [`CHUNK`] sprites: a larger view is built and drawn a chunk at a time, in
//! drawing order, so its memory stays bounded whatever is in view. One buffer serves every view
//! of a frame: each build is followed by its draw before the next. The shadow map's view is
//! built by its own entry point (`cs_build_cores`): each sprite as its dense core, what the
//! probes ask, not as its textured quad.

use crate::render::gpu_types::GpuSpriteVertex;

const WGSL: &str = include_str!("../../../shaders/sprite_build.wgsl");
/// Most sprites built and drawn at once (6.3 MB of corners). Keep in sync with `CHUNK` in
/// `shaders/sprite_build.wgsl`.
pub(in crate::render) const CHUNK: u32 = 32_768;
/// Most chunks of one view (8.4 million sprites).
const MAX_CHUNKS: u32 = 256;
/// Bytes between the chunks' uniforms (the dynamic offset alignment every device accepts).
const CHUNK_STRIDE: u64 = 256;
/// Invocations per workgroup and workgroups per dispatch row (WGSL's `cs_build`).
const GROUP: u32 = 64;
const ROW: u32 = 65_535;

/// The pipeline, and the vertex buffer with its bind group.
pub(in crate::render) struct SpriteBuild {
    pipeline: wgpu::ComputePipeline,
    /// The shadow map's build: the sprites' cores (`cs_build_cores`).
    cores_pipeline: wgpu::ComputePipeline,
    out_layout: wgpu::BindGroupLayout,
    vertices: wgpu::Buffer,
    /// Per chunk its first sprite, at [`CHUNK_STRIDE`] bytes apart (written once).
    chunk_starts: wgpu::Buffer,
    out_group: wgpu::BindGroup,
    /// Sprites the vertex buffer holds.
    capacity: u32,
}

/// The chunks of `sprites` sprites: (index, first sprite, sprites).
pub(in crate::render) fn chunks(sprites: u32) -> impl Iterator<Item = (u32, u32, u32)> {
    (0..sprites.div_ceil(CHUNK).min(MAX_CHUNKS))
        .map(move |c| (c, c * CHUNK, (sprites - c * CHUNK).min(CHUNK)))
}

impl SpriteBuild {
    /// The pipeline over the view's group (`view_layout`) and the resident sprites' group; each
    /// sheet cell's quad cut to `cell_crops` (`sheet_crop::cell_crops`).
    pub fn new(
        device: &wgpu::Device,
        view_layout: &wgpu::BindGroupLayout,
        resident_layout: &wgpu::BindGroupLayout,
        cell_crops: &[[f32; 4]; 16],
    ) -> Self {
        let out_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.sprite_build_out"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: std::num::NonZeroU64::new(16),
                    },
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sky.sprite_build"),
            bind_group_layouts: &[Some(view_layout), Some(resident_layout), Some(&out_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sky.sprite_build"),
            source: wgpu::ShaderSource::Wgsl(
                format!("{}\n{WGSL}", super::sheet_crop::crops_wgsl(cell_crops)).into(),
            ),
        });
        let pipeline_of = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("sky.sprite_build"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let (pipeline, cores_pipeline) = (pipeline_of("cs_build"), pipeline_of("cs_build_cores"));
        let mut starts = vec![0u8; (MAX_CHUNKS as u64 * CHUNK_STRIDE) as usize];
        for c in 0..MAX_CHUNKS {
            let at = (c as u64 * CHUNK_STRIDE) as usize;
            starts[at..at + 4].copy_from_slice(&(c * CHUNK).to_le_bytes());
        }
        let chunk_starts = {
            use wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sky.sprite_build_chunks"),
                contents: &starts,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let capacity = 4096;
        let (vertices, out_group) = vertex_buffer(device, &out_layout, &chunk_starts, capacity);
        Self {
            pipeline,
            cores_pipeline,
            out_layout,
            vertices,
            chunk_starts,
            out_group,
            capacity,
        }
    }

    /// Makes room for `sprites` (the largest build of the frame; at most a chunk).
    pub fn reserve(&mut self, device: &wgpu::Device, sprites: u32) {
        let sprites = sprites.min(CHUNK);
        if sprites <= self.capacity {
            return;
        }
        self.capacity = sprites.next_power_of_two();
        (self.vertices, self.out_group) =
            vertex_buffer(device, &self.out_layout, &self.chunk_starts, self.capacity);
    }

    /// The vertex buffer the draws read.
    pub fn vertices(&self) -> &wgpu::Buffer {
        &self.vertices
    }

    /// Bytes of the vertex buffer and the chunks' uniforms.
    pub fn gpu_bytes(&self) -> u64 {
        self.vertices.size() + self.chunk_starts.size()
    }

    /// Records the build of chunk `chunk` (of [`chunks`]: `sprites` sprites) of the view `view`
    /// (group 0) from the resident sprites (`resident`, group 1).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::BindGroup,
        resident: &wgpu::BindGroup,
        chunk: (u32, u32),
    ) {
        self.record_with(&self.pipeline, encoder, (view, resident), chunk);
    }

    /// [`Self::record`] for the shadow map: each sprite built as its dense core
    /// (`build_core` in `shaders/sprite_build.wgsl`).
    pub fn record_cores(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::BindGroup,
        resident: &wgpu::BindGroup,
        chunk: (u32, u32),
    ) {
        self.record_with(&self.cores_pipeline, encoder, (view, resident), chunk);
    }

    fn record_with(
        &self,
        pipeline: &wgpu::ComputePipeline,
        encoder: &mut wgpu::CommandEncoder,
        (view, resident): (&wgpu::BindGroup, &wgpu::BindGroup),
        (chunk, sprites): (u32, u32),
    ) {
        if sprites == 0 {
            return;
        }
        let groups = sprites.div_ceil(GROUP);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sky.sprite_build"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, view, &[]);
        pass.set_bind_group(1, resident, &[]);
        let offset = chunk as u64 * CHUNK_STRIDE;
        pass.set_bind_group(2, &self.out_group, &[offset as u32]);
        pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
    }
}

fn vertex_buffer(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    chunk_starts: &wgpu::Buffer,
    sprites: u32,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_vertices"),
        size: sprites as u64 * 4 * std::mem::size_of::<GpuSpriteVertex>() as u64,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::VERTEX
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sky.sprite_build_out"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: chunk_starts,
                    offset: 0,
                    size: std::num::NonZeroU64::new(16),
                }),
            },
        ],
    });
    (buffer, group)
}

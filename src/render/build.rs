//! The build pass (`shaders/sprite_build.wgsl`): a compute pass that makes the corners of a
//! view's sprites (facing, lock, Wang's shading, fades) from the GPU-resident sprites, the view's
//! draw list, cloud lists and orders, into a vertex buffer the sprite draw reads. One buffer
//! serves every view of a frame: each impostor's build is followed by its draw before the next
//! build, and the sky camera's comes last, before the sky pass.

use super::gpu_types::GpuSpriteVertex;

const WGSL: &str = include_str!("../../shaders/sprite_build.wgsl");
/// Invocations per workgroup and workgroups per dispatch row (WGSL's `cs_build`).
const GROUP: u32 = 64;
const ROW: u32 = 65_535;

/// The pipeline, and the vertex buffer with its bind group.
pub(super) struct SpriteBuild {
    pipeline: wgpu::ComputePipeline,
    out_layout: wgpu::BindGroupLayout,
    vertices: wgpu::Buffer,
    out_group: wgpu::BindGroup,
    /// Sprites the vertex buffer holds.
    capacity: u32,
}

impl SpriteBuild {
    /// The pipeline over the view's group (`view_layout`) and the resident sprites' group.
    pub fn new(
        device: &wgpu::Device,
        view_layout: &wgpu::BindGroupLayout,
        resident_layout: &wgpu::BindGroupLayout,
    ) -> Self {
        let out_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.sprite_build_out"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sky.sprite_build"),
            bind_group_layouts: &[Some(view_layout), Some(resident_layout), Some(&out_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sky.sprite_build"),
            source: wgpu::ShaderSource::Wgsl(WGSL.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("sky.sprite_build"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_build"),
            compilation_options: Default::default(),
            cache: None,
        });
        let capacity = 4096;
        let (vertices, out_group) = vertex_buffer(device, &out_layout, capacity);
        Self {
            pipeline,
            out_layout,
            vertices,
            out_group,
            capacity,
        }
    }

    /// Makes room for `sprites` (the largest build of the frame).
    pub fn reserve(&mut self, device: &wgpu::Device, sprites: u32) {
        if sprites <= self.capacity {
            return;
        }
        self.capacity = sprites.next_power_of_two();
        (self.vertices, self.out_group) = vertex_buffer(device, &self.out_layout, self.capacity);
    }

    /// The vertex buffer the draws read.
    pub fn vertices(&self) -> &wgpu::Buffer {
        &self.vertices
    }

    /// Bytes of the vertex buffer.
    pub fn gpu_bytes(&self) -> u64 {
        self.vertices.size()
    }

    /// Records the build of `sprites` sprites of the view `view` (group 0) from the resident
    /// sprites (`resident`, group 1).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::BindGroup,
        resident: &wgpu::BindGroup,
        sprites: u32,
    ) {
        if sprites == 0 {
            return;
        }
        let groups = (sprites * 4).div_ceil(GROUP);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sky.sprite_build"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, view, &[]);
        pass.set_bind_group(1, resident, &[]);
        pass.set_bind_group(2, &self.out_group, &[]);
        pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
    }
}

fn vertex_buffer(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
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
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    (buffer, group)
}

//! What every sky pipeline shares: the WGSL of `shaders/shared/frame.wgsl` put in front of each
//! pass's shader, premultiplied-alpha blending, and one way to build a pipeline. None of them
//! culls (sprites and full-screen triangles face the camera either way), and they read the
//! host's depth as a texture; only the full-screen passes split by the host's background also
//! test it as a read-only depth attachment ([`background_test`]).

/// The structs and helpers every sky pass shares.
const SHARED_WGSL: &str = include_str!("../../shaders/shared/frame.wgsl");

/// The shared WGSL's binding of the host's depth, single-sampled.
const SINGLE_DEPTH: &str = "var scene_depth: texture_2d<f32>;";

/// Group 0 of `shaders/shared/frame.wgsl` under `layout`: the frame uniform `frame_buffer` and
/// the scene depth `depth_view` (the host's, the cloud target's farthest distance, or an
/// impostor's empty scene).
pub(super) fn frame_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    frame_buffer: &wgpu::Buffer,
    depth_view: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(depth_view),
            },
        ],
    })
}

/// What a pass's `scene_depth` (group 0 of `shaders/shared/frame.wgsl`) holds, and so how its
/// shader reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SceneDepth {
    /// The host's depth, single-sampled (also the blank depth of the impostor renders).
    Host,
    /// The host's depth, multisampled.
    HostMultisampled,
    /// The cloud target's farthest distance of each block of host pixels, metres
    /// (`shaders/cloud_downsample.wgsl`): the shader skips the depth-to-metres conversion.
    FarthestMetres,
}

impl SceneDepth {
    /// The host's depth at `samples` a pixel.
    pub(super) fn host(samples: u32) -> Self {
        if samples > 1 {
            Self::HostMultisampled
        } else {
            Self::Host
        }
    }

    /// The values of the shared WGSL's pipeline-overridable constants.
    fn constants(self) -> &'static [(&'static str, f64)] {
        match self {
            Self::FarthestMetres => &[("SCENE_IN_METRES", 1.0)],
            Self::Host | Self::HostMultisampled => &[],
        }
    }
}

/// A shader module of `shaders/shared/frame.wgsl` followed by `pass_wgsl`, its `scene_depth`
/// declared multisampled where `scene` is the host's multisampled depth (the override that
/// `scene` may set is given when the pipeline is built).
fn shader(
    device: &wgpu::Device,
    label: &str,
    pass_wgsl: &str,
    scene: SceneDepth,
) -> wgpu::ShaderModule {
    let shared = if scene == SceneDepth::HostMultisampled {
        SHARED_WGSL.replace(
            SINGLE_DEPTH,
            "var scene_depth: texture_multisampled_2d<f32>;",
        )
    } else {
        SHARED_WGSL.to_string()
    };
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(format!("{shared}\n{pass_wgsl}").into()),
    })
}

/// Premultiplied "over": what every cloud pass blends with.
pub(super) fn premultiplied_over() -> wgpu::BlendState {
    let over = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::BlendState {
        color: over,
        alpha: over,
    }
}

/// One sky pipeline: its shader (after the shared WGSL), entry points, bind group layouts,
/// vertex buffers and colour targets with their blending.
pub(super) struct PassDesc<'a> {
    /// Label of the module, layout and pipeline.
    pub label: &'a str,
    /// The pass's WGSL.
    pub wgsl: &'a str,
    /// Vertex entry point.
    pub vs: &'a str,
    /// Fragment entry point.
    pub fs: &'a str,
    /// Bind group layouts, group 0 first.
    pub bind_groups: &'a [Option<&'a wgpu::BindGroupLayout>],
    /// Vertex buffers (none for full-screen passes).
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    /// Colour targets: format and blending.
    pub targets: &'a [(wgpu::TextureFormat, Option<wgpu::BlendState>)],
    /// Samples a pixel of the targets (the host's MSAA count, or 1).
    pub samples: u32,
    /// What the depth the pass reads (group 0) holds.
    pub scene: SceneDepth,
}

/// Builds the pipeline `desc` describes.
pub(super) fn pipeline(device: &wgpu::Device, desc: &PassDesc) -> wgpu::RenderPipeline {
    pipeline_with_depth(device, desc, None)
}

/// A full-screen pass's depth test against the host's depth as a read-only attachment of
/// `format`: the triangle is drawn at the host's background depth, and `compare` keeps the
/// pixels where the host drew nothing (`Equal`) or drew its scene (`NotEqual`). Nothing is
/// written.
pub(super) fn background_test(
    format: wgpu::TextureFormat,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(false),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// [`pipeline`] with a depth test (`None`: no depth attachment, as every sky pass but the
/// split full-screen ones).
pub(super) fn pipeline_with_depth(
    device: &wgpu::Device,
    desc: &PassDesc,
    depth: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    let module = shader(device, desc.label, desc.wgsl, desc.scene);
    let compilation_options = wgpu::PipelineCompilationOptions {
        constants: desc.scene.constants(),
        ..Default::default()
    };
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(desc.label),
        bind_group_layouts: desc.bind_groups,
        immediate_size: 0,
    });
    let targets: Vec<Option<wgpu::ColorTargetState>> = desc
        .targets
        .iter()
        .map(|&(format, blend)| {
            Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(desc.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some(desc.vs),
            compilation_options: compilation_options.clone(),
            buffers: desc.buffers,
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: depth,
        multisample: wgpu::MultisampleState {
            count: desc.samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(desc.fs),
            compilation_options: compilation_options.clone(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shared_wgsl_declares_the_depth_the_multisampled_variant_replaces() {
        assert_eq!(SHARED_WGSL.matches(SINGLE_DEPTH).count(), 1);
    }

    #[test]
    fn the_shared_wgsl_declares_every_constant_a_pass_overrides() {
        let all = [
            SceneDepth::Host,
            SceneDepth::HostMultisampled,
            SceneDepth::FarthestMetres,
        ];
        let overridden: Vec<&str> = all
            .iter()
            .flat_map(|scene| scene.constants().iter().map(|(name, _)| *name))
            .collect();
        assert!(!overridden.is_empty());
        for name in overridden {
            let declaration = format!("override {name}: bool = false;");
            assert_eq!(SHARED_WGSL.matches(&declaration).count(), 1, "{name}");
        }
    }
}

//! What the host's device can do, checked before the sky builds anything on it, so that a device
//! short of something (an OpenGL or browser backend, an older GPU) gets a [`RenderError`] that
//! names what is missing instead of wgpu's validation panic, and a fallback where one exists.
//!
//! The host hands the sky a device, not its adapter, so the checks ask the device itself: its
//! limits, and small probes (a 1 x 1 texture, an empty pass) made inside a validation error
//! scope, whose error says whether the device takes them. The probes cost well under a
//! millisecond, once, in [`super::Sky::new`].

use super::RenderError;
use super::targets::HostTargets;

/// Storage buffers the sprite build's compute pass reads in one stage.
pub const STORAGE_BUFFERS_PER_STAGE: u32 = 7;

/// What the sky may use on a device that passed [`check`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// Whether a one-channel 32-bit float texture can be drawn into: the off-screen cloud
    /// target's farthest-distance texture needs it. Without it the clouds draw at full
    /// resolution (`[clouds] resolution_scale` 1), which needs none.
    pub r32float_renderable: bool,
}

/// Checks the device against what the sky needs for `targets`.
pub fn check(device: &wgpu::Device, targets: &HostTargets) -> Result<Capabilities, RenderError> {
    let limits = device.limits();
    let stage_buffers = limits.max_storage_buffers_per_shader_stage;
    if stage_buffers < STORAGE_BUFFERS_PER_STAGE {
        return Err(RenderError::Unsupported(format!(
            "the sky builds its sprites in a compute pass reading {STORAGE_BUFFERS_PER_STAGE} storage buffers per stage (WebGPU's default limit is 8); this device was created with {stage_buffers}"
        )));
    }
    for (format, usage, what) in [
        (
            super::cloud_target::CLOUD_COLOUR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            "the clouds' colour (drawn into, then sampled)",
        ),
        (
            super::cloud_target::CLOUD_DISTANCE_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            "the clouds' distance (drawn into, then sampled)",
        ),
        (
            super::shadow::SHADOW_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            "the cloud shadow map (drawn into, then sampled)",
        ),
    ] {
        if let Some(why) = texture_refused(device, format, usage) {
            return Err(RenderError::Unsupported(format!(
                "{format:?} textures for {what}: {why}"
            )));
        }
    }
    if let Some(why) = read_only_depth_refused(device, targets) {
        return Err(RenderError::Unsupported(format!(
            "the host's depth ({:?}) read by the clouds' shaders while it is their read-only depth attachment (wgpu's DownlevelFlags::READ_ONLY_DEPTH_STENCIL, which OpenGL backends lack): {why}",
            targets.depth_format
        )));
    }
    let r32float_renderable = texture_refused(
        device,
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
    .is_none();
    Ok(Capabilities {
        r32float_renderable,
    })
}

/// Runs `make` inside a validation error scope: the error's text if the device refused it.
pub fn refused<T>(device: &wgpu::Device, make: impl FnOnce() -> T) -> (T, Option<String>) {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let made = make();
    let error = pollster::block_on(scope.pop());
    (made, error.map(|e| first_cause(&e)))
}

/// The innermost line of a wgpu error (its own text repeats the call chain over lines).
fn first_cause(error: &wgpu::Error) -> String {
    let text = error.to_string();
    let mut cause: Option<&dyn std::error::Error> = Some(error);
    let mut last = text.lines().last().unwrap_or("").trim().to_string();
    while let Some(e) = cause {
        let line = e.to_string();
        if let Some(l) = line.lines().rev().find(|l| !l.trim().is_empty()) {
            last = l.trim().to_string();
        }
        cause = e.source();
    }
    last
}

/// Why a 1 x 1 texture of `format` for `usage` is refused, if it is.
fn texture_refused(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Option<String> {
    refused(device, || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("sky.capability_probe"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    })
    .1
}

/// Why a pass with a depth texture as its read-only attachment that also binds the same
/// texture for sampling is refused, if it is: what every cloud pass does with the host's depth.
fn read_only_depth_refused(device: &wgpu::Device, targets: &HostTargets) -> Option<String> {
    let (_, why) = refused(device, || {
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("sky.capability_probe.depth"),
            size: wgpu::Extent3d {
                width: 4,
                height: 4,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: targets.depth_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let attachment = depth.create_view(&wgpu::TextureViewDescriptor::default());
        let sampled = depth.create_view(&wgpu::TextureViewDescriptor {
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.capability_probe.layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.capability_probe.group"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&sampled),
            }],
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("sky.capability_probe"),
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sky.capability_probe"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &attachment,
                    depth_ops: None,
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &group, &[]);
        }
        // Never submitted: finishing is where the pass's usages are checked.
        encoder.finish()
    });
    why
}

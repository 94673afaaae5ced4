//! The ring pass's pipelines (`shaders/impostor_quad.wgsl`): into the host's colour or the sky's
//! cloud target, each in two kinds, one that mixes the shown ring with the one fading in and one
//! that looks up the shown ring alone. A software rasteriser (lavapipe) runs both sides of a
//! branch for every pixel, so a single shader that skipped the second lookup on a crossfade
//! weight of 0 still paid for it on every steady frame; the choice is made on the CPU instead.

use crate::render::pipeline::{PassDesc, SceneDepth, pipeline, premultiplied_over};

use super::RingShared;

const QUAD_WGSL: &str = include_str!("../../../shaders/impostor_quad.wgsl");

/// One target's ring pass: while crossfading, and steady.
struct ByFade {
    fading: wgpu::RenderPipeline,
    shown: wgpu::RenderPipeline,
}

impl ByFade {
    fn get(&self, fading: bool) -> &wgpu::RenderPipeline {
        if fading { &self.fading } else { &self.shown }
    }
}

/// The ring pass's pipelines for every target it may draw into.
pub(super) struct RingPassPipelines {
    host: ByFade,
    /// Into the sky's off-screen cloud target (where the clouds are drawn below full
    /// resolution).
    offscreen: Option<ByFade>,
}

impl RingPassPipelines {
    /// Builds them; `textures` is group 1 (both rings' texture arrays and the ring uniform).
    pub(super) fn new(
        device: &wgpu::Device,
        shared: &RingShared,
        textures: &wgpu::BindGroupLayout,
    ) -> Self {
        let over = Some(premultiplied_over());
        let host_targets = [(shared.targets.colour_format, over)];
        let host = |label, fs| {
            pipeline(
                device,
                &PassDesc {
                    label,
                    wgsl: QUAD_WGSL,
                    vs: "vs_impostor",
                    fs,
                    bind_groups: &[Some(shared.host_frame_layout), Some(textures)],
                    buffers: &[],
                    targets: &host_targets,
                    samples: shared.targets.sample_count,
                    scene: SceneDepth::host(shared.targets.sample_count),
                },
            )
        };
        let offscreen = |targets, label, fs| {
            pipeline(
                device,
                &PassDesc {
                    label,
                    wgsl: QUAD_WGSL,
                    vs: "vs_impostor",
                    fs,
                    bind_groups: &[Some(shared.frame_layout), Some(textures)],
                    buffers: &[],
                    targets,
                    samples: 1,
                    scene: SceneDepth::FarthestMetres,
                },
            )
        };
        Self {
            host: ByFade {
                fading: host("ring.quads", "fs_impostor"),
                shown: host("ring.quads_shown", "fs_impostor_shown"),
            },
            offscreen: shared.cloud_targets.map(|targets| ByFade {
                fading: offscreen(targets, "ring.quads_offscreen", "fs_impostor_offscreen"),
                shown: offscreen(
                    targets,
                    "ring.quads_shown_offscreen",
                    "fs_impostor_shown_offscreen",
                ),
            }),
        }
    }

    /// The pipeline of a ring pass into the cloud target (`offscreen`, where there is one) or
    /// the host's colour, mixing in the ring fading in or (`fading` false) showing one ring.
    pub(super) fn get(&self, offscreen: bool, fading: bool) -> &wgpu::RenderPipeline {
        match (offscreen, &self.offscreen) {
            (true, Some(p)) => p.get(fading),
            _ => self.host.get(fading),
        }
    }
}

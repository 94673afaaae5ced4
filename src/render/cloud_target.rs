//! The off-screen cloud target: the sky's cloud passes (the impostor ring, the sprites, the
//! in-cloud fog) drawn at a fraction of the host's resolution and composited over the host's
//! colour (Cantlay, "High-Speed, Off-Screen Particles", GPU Gems 3 chapter 23). Clouds are soft
//! and low-frequency, and the steady frame is fill-bound by the near deck's overdraw (465% in
//! the overcast scenario): at half resolution the sprites fill a quarter of the pixels.
//!
//! Each frame, when `[clouds] resolution_scale` is below 1:
//! 1. `clouds.downsample` (`shaders/cloud_downsample.wgsl`): the host's depth, the farthest of
//!    each block of pixels, as metres from the camera plane into an R32Float texture of the
//!    target's size;
//! 2. the cloud passes draw into the target against that distance (their soft depth fade reads
//!    it through the frame group's scene depth, `SceneDepth::FarthestMetres`: converted once a
//!    texel, not once a fragment): premultiplied colour in [`CLOUD_COLOUR_FORMAT`],
//!    and the clouds' distance times alpha in [`CLOUD_DISTANCE_FORMAT`], both blended "over";
//! 3. `clouds.composite` (`shaders/cloud_composite.wgsl`): bilinear upsample over the host's
//!    colour, the soft depth fade redone per full-resolution pixel so a silhouette in front of a
//!    cloud (a ridge) keeps its full-resolution edge and no halo; where the host drew nothing, the
//!    sky background under the clouds. Two draws split by the host's depth as a read-only depth
//!    attachment where it can be one (the sky's pixels, then the scene's): on lavapipe a shader
//!    runs both sides of a branch for every pixel, so one draw paid for the sky gradient and the
//!    fix-up everywhere (the composite took half the time it takes now).
//!
//! As every pass of the sky: `new` builds the pipelines, `plan` sizes the target from the
//! host's (plain data), `frame` makes its textures when that size changed, and `downsample`,
//! `pass` and `composite` record.
//!
//! At scale 1 nothing here runs: the cloud passes draw straight into the host's colour as
//! before, and cost nothing more. The target follows the host's frame size (checked each
//! record, rebuilt when it changed); the host's API does not change.

use std::cell::RefCell;

use super::gpu_types::GpuSpriteVertex;
use super::pipeline::{
    PassDesc, SceneDepth, background_test, frame_group, pipeline, pipeline_with_depth,
    premultiplied_over,
};

/// The cloud target's colour: premultiplied linear RGBA in half floats. Eight-bit channels band
/// under 465% overdraw of faint sprites (a sprite's alpha of 0.02 is 5/255, so each blend rounds
/// by up to a tenth of its own contribution) and cannot hold colours over 1 (the sun's forward
/// scattering); half floats keep 11 significant bits at any level, are blendable and filterable
/// on every WebGPU device, and at half resolution cost half the bytes of a full-resolution RGBA8
/// frame. (RGB10A2 would keep only 4 alpha levels; RG11B10 has no alpha.)
pub const CLOUD_COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The clouds' distance from the camera plane, kilometres times alpha (half floats: about 4 m at
/// 6 km, well inside the soft fade's 120 m).
pub const CLOUD_DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;
/// The farthest host depth of each block of pixels, as metres from the camera plane (full
/// floats: the host's far plane may be 1e9, the stand-in for infinity).
const FARTHEST_DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
const IN_CLOUD_WGSL: &str = include_str!("../../shaders/in_cloud.wgsl");
const DOWNSAMPLE_WGSL: &str = include_str!("../../shaders/cloud_downsample.wgsl");
const COMPOSITE_WGSL: &str = include_str!("../../shaders/cloud_composite.wgsl");

/// The colour targets of every pass into the cloud target: colour and distance, both "over".
pub fn cloud_targets() -> [(wgpu::TextureFormat, Option<wgpu::BlendState>); 2] {
    let over = Some(premultiplied_over());
    [(CLOUD_COLOUR_FORMAT, over), (CLOUD_DISTANCE_FORMAT, over)]
}

/// How many host pixels a side of one cloud texel covers at `resolution_scale` (1, 0.5 or
/// 0.25: 1, 2 or 4); `None` for other scales.
pub fn divisor_of(resolution_scale: f32) -> Option<u32> {
    [1, 2, 4]
        .into_iter()
        .find(|&d| (resolution_scale - 1.0 / d as f32).abs() < 1e-6)
}

/// The layouts and formats of the sky the cloud target draws with.
pub(super) struct CloudShared<'a> {
    /// Group 0 of the passes that read the host's depth (the downsample, the composite):
    /// multisampled when the host's targets are.
    pub host_frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 0 of the passes into the cloud target: the frame uniform and the single-sample
    /// farthest distance.
    pub frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 1 of the sprite pass: the sheet and its sampler.
    pub sheet_layout: &'a wgpu::BindGroupLayout,
    /// The host's targets (the composite draws into its colour).
    pub targets: super::targets::HostTargets,
}

/// The cloud target of one resolution scale: nothing at scale 1.
pub(super) struct CloudTarget {
    divisor: u32,
    offscreen: Option<Offscreen>,
}

/// Pipelines of the off-screen path, and the size-dependent textures.
struct Offscreen {
    downsample: wgpu::RenderPipeline,
    composite: wgpu::RenderPipeline,
    /// The composite split by the host's depth as a read-only attachment: the sky's pixels,
    /// then the scene's; `None` where the host's depth format has a stencil aspect.
    split_composite: Option<[wgpu::RenderPipeline; 2]>,
    sprites: wgpu::RenderPipeline,
    in_cloud: wgpu::RenderPipeline,
    frame_layout: wgpu::BindGroupLayout,
    composite_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// Made at the first record and whenever the host's frame size changes (record takes `&`).
    textures: RefCell<Option<SizedTextures>>,
}

/// The textures of one host frame size, and the bind groups that read them.
struct SizedTextures {
    host_size: (u32, u32),
    colour: wgpu::TextureView,
    distance: wgpu::TextureView,
    farthest: wgpu::TextureView,
    /// Group 0 of the cloud passes: the frame uniform and the farthest distance.
    frame_group: wgpu::BindGroup,
    /// Group 1 of the composite.
    composite_group: wgpu::BindGroup,
    bytes: u64,
}

/// The cloud target for one frame: what [`super::Sky::record`] draws the clouds with.
pub(super) struct CloudFrame<'a> {
    offscreen: &'a Offscreen,
    textures: std::cell::Ref<'a, SizedTextures>,
}

impl CloudTarget {
    /// The pipelines for `divisor` (1: none, the host's colour is drawn into directly).
    pub fn new(device: &wgpu::Device, shared: &CloudShared, divisor: u32) -> Self {
        let offscreen = (divisor > 1).then(|| Offscreen::new(device, shared, divisor));
        Self { divisor, offscreen }
    }

    /// The resolution scale, 1 / divisor.
    pub fn scale(&self) -> f32 {
        1.0 / self.divisor as f32
    }

    /// Bytes of the target's textures at the last recorded frame size (0 at scale 1).
    pub fn gpu_bytes(&self) -> u64 {
        self.offscreen
            .as_ref()
            .and_then(|o| o.textures.borrow().as_ref().map(|t| t.bytes))
            .unwrap_or(0)
    }

    /// The clouds' distance of the last recorded frame, metres from the camera plane per texel
    /// of the target (its colour's alpha weighs it; 0 where no cloud shows): width, height and
    /// the texels row by row; `None` at scale 1 or before a frame. Waits for the GPU.
    pub fn read_distance_m(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Option<(u32, u32, Vec<f32>)> {
        let offscreen = self.offscreen.as_ref()?;
        let textures = offscreen.textures.borrow();
        let t = textures.as_ref()?;
        let colour = t.colour.texture();
        let distance = t.distance.texture();
        let (w, h) = (colour.width(), colour.height());
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let rows = [
            (w * 8).div_ceil(align) * align,
            (w * 2).div_ceil(align) * align,
        ];
        let bufs: Vec<wgpu::Buffer> = rows
            .iter()
            .map(|row| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("clouds.distance_readback"),
                    size: u64::from(row * h),
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                })
            })
            .collect();
        let mut enc = device.create_command_encoder(&Default::default());
        for ((texture, buf), row) in [colour, distance].into_iter().zip(&bufs).zip(rows) {
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: buf,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(h),
                    },
                },
                texture.size(),
            );
        }
        queue.submit([enc.finish()]);
        for b in &bufs {
            b.map_async(wgpu::MapMode::Read, .., |_| {});
        }
        device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
        let c = bufs[0].get_mapped_range(..).ok()?;
        let d = bufs[1].get_mapped_range(..).ok()?;
        let half = |p: &[u8], i: usize| half::f16::from_le_bytes([p[i], p[i + 1]]).to_f32();
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            for x in 0..w as usize {
                let alpha = half(&c, y * rows[0] as usize + x * 8 + 6);
                let km_alpha = half(&d, y * rows[1] as usize + x * 2);
                out.push(if alpha > 0.01 {
                    km_alpha / alpha * 1000.0
                } else {
                    0.0
                });
            }
        }
        Some((w, h, out))
    }

    /// The plan of a frame whose host targets are `host_size` pixels: the target's size,
    /// `None` at scale 1 (the clouds go straight into the host's colour). CPU only.
    pub fn plan(&self, host_size: (u32, u32)) -> Option<(u32, u32)> {
        (self.offscreen.is_some()).then(|| target_size(host_size, self.divisor))
    }

    /// The target for a frame of the host's `depth_view`'s size (made or remade if the size
    /// changed: the pass's upload); `None` at scale 1. Its `downsample`, `pass` and
    /// `composite` record.
    pub fn frame(
        &self,
        device: &wgpu::Device,
        frame_buffer: &wgpu::Buffer,
        depth_view: &wgpu::TextureView,
    ) -> Option<CloudFrame<'_>> {
        let offscreen = self.offscreen.as_ref()?;
        let size = depth_view.texture().size();
        let host_size = (size.width, size.height);
        let current = offscreen.textures.borrow().as_ref().map(|t| t.host_size);
        if current != Some(host_size) {
            let size = self.plan(host_size)?;
            let textures = offscreen.textures_for(device, frame_buffer, (host_size, size));
            *offscreen.textures.borrow_mut() = Some(textures);
        }
        let textures =
            std::cell::Ref::filter_map(offscreen.textures.borrow(), Option::as_ref).ok()?;
        Some(CloudFrame {
            offscreen,
            textures,
        })
    }
}

impl Offscreen {
    fn new(device: &wgpu::Device, shared: &CloudShared, divisor: u32) -> Self {
        let with_divisor = |wgsl: &str| format!("const DIVISOR: i32 = {divisor};\n{wgsl}");
        let frame_only = [Some(shared.frame_layout)];
        let host_frame_only = [Some(shared.host_frame_layout)];
        let host_samples = shared.targets.sample_count;
        let targets = cloud_targets();
        let downsample = pipeline(
            device,
            &PassDesc {
                label: "clouds.downsample",
                wgsl: &with_divisor(DOWNSAMPLE_WGSL),
                vs: "vs_downsample",
                fs: "fs_downsample",
                bind_groups: &host_frame_only,
                buffers: &[],
                targets: &[(FARTHEST_DISTANCE_FORMAT, None)],
                samples: 1,
                scene: SceneDepth::host(host_samples),
            },
        );
        let texture_entry = |binding, filterable| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clouds.composite_layout"),
            entries: &[
                texture_entry(0, true),
                texture_entry(1, true),
                texture_entry(2, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let composite_wgsl = with_divisor(COMPOSITE_WGSL);
        let composite_groups = [Some(shared.host_frame_layout), Some(&composite_layout)];
        let colour_format = shared.targets.colour_format;
        let composite_pipeline = |fs, blend, depth| {
            pipeline_with_depth(
                device,
                &PassDesc {
                    label: "clouds.composite",
                    wgsl: &composite_wgsl,
                    vs: "vs_composite",
                    fs,
                    bind_groups: &composite_groups,
                    buffers: &[],
                    targets: &[(colour_format, blend)],
                    samples: host_samples,
                    scene: SceneDepth::host(host_samples),
                },
                depth,
            )
        };
        let over = Some(premultiplied_over());
        let composite = composite_pipeline("fs_composite", over, None);
        let depth_format = shared.targets.depth_format;
        let split_composite = (!depth_format.has_stencil_aspect()).then(|| {
            let split = |fs, blend, compare| {
                composite_pipeline(fs, blend, Some(background_test(depth_format, compare)))
            };
            [
                // Over the sky the output is opaque: written, not blended.
                split("fs_composite_sky", None, wgpu::CompareFunction::Equal),
                split("fs_composite_scene", over, wgpu::CompareFunction::NotEqual),
            ]
        });
        let sprites = pipeline(
            device,
            &PassDesc {
                label: "clouds.sprites",
                wgsl: SPRITES_WGSL,
                vs: "vs_sprite",
                fs: "fs_sprite_offscreen",
                bind_groups: &[Some(shared.frame_layout), Some(shared.sheet_layout)],
                buffers: &[Some(GpuSpriteVertex::layout())],
                targets: &targets,
                samples: 1,
                scene: SceneDepth::FarthestMetres,
            },
        );
        let in_cloud = pipeline(
            device,
            &PassDesc {
                label: "clouds.in_cloud",
                wgsl: IN_CLOUD_WGSL,
                vs: "vs_in_cloud",
                fs: "fs_in_cloud_offscreen",
                bind_groups: &frame_only,
                buffers: &[],
                targets: &targets,
                samples: 1,
                scene: SceneDepth::FarthestMetres,
            },
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clouds.sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Self {
            downsample,
            composite,
            split_composite,
            sprites,
            in_cloud,
            frame_layout: shared.frame_layout.clone(),
            composite_layout,
            sampler,
            textures: RefCell::new(None),
        }
    }

    /// The target's textures for a host frame of `host_size` (each side divided, rounded up).
    fn textures_for(
        &self,
        device: &wgpu::Device,
        frame_buffer: &wgpu::Buffer,
        (host_size, (width, height)): ((u32, u32), (u32, u32)),
    ) -> SizedTextures {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let mut bytes = 0;
        let mut make = |label, format: wgpu::TextureFormat| {
            bytes += size.width as u64
                * size.height as u64
                * format.block_copy_size(None).unwrap_or(4) as u64;
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size,
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    // COPY_SRC: the clouds' distance read back for `--exr`'s `cloud_distance`.
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        let colour = make("clouds.colour", CLOUD_COLOUR_FORMAT);
        let distance = make("clouds.distance", CLOUD_DISTANCE_FORMAT);
        let farthest = make("clouds.farthest_distance", FARTHEST_DISTANCE_FORMAT);
        let frame_group = frame_group(
            device,
            "clouds.frame_group",
            &self.frame_layout,
            frame_buffer,
            &farthest,
        );
        let composite_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clouds.composite_group"),
            layout: &self.composite_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&colour),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&distance),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&farthest),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        SizedTextures {
            host_size,
            colour,
            distance,
            farthest,
            frame_group,
            composite_group,
            bytes,
        }
    }
}

impl CloudFrame<'_> {
    /// Records `clouds.downsample`: the host's depth (in `host_frame_group`) to the farthest
    /// distance of each block, metres.
    pub fn downsample(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        host_frame_group: &wgpu::BindGroup,
    ) {
        let mut pass = begin(
            encoder,
            "clouds.downsample",
            &[&self.textures.farthest],
            wgpu::LoadOp::Clear(wgpu::Color::WHITE),
        );
        pass.set_pipeline(&self.offscreen.downsample);
        pass.set_bind_group(0, host_frame_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// A pass over the cloud target (cleared to transparent when `clear`, else kept), with the
    /// frame uniform and the farthest distance bound as group 0.
    pub fn pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        clear: bool,
    ) -> wgpu::RenderPass<'e> {
        let load = if clear {
            wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
        } else {
            wgpu::LoadOp::Load
        };
        let t = &self.textures;
        let mut pass = begin(encoder, "clouds", &[&t.colour, &t.distance], load);
        pass.set_bind_group(0, &t.frame_group, &[]);
        pass
    }

    /// The target's size, pixels.
    pub fn size(&self) -> (u32, u32) {
        let t = self.textures.colour.texture();
        (t.width(), t.height())
    }

    /// The sprite pipeline that draws into the target.
    pub fn sprite_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.offscreen.sprites
    }

    /// The in-cloud fog pipeline that draws into the target.
    pub fn in_cloud_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.offscreen.in_cloud
    }

    /// Records `clouds.composite`: the target over the host's colour. Where the host's depth
    /// can also be the pass's read-only depth attachment (a depth format without stencil, made
    /// with `RENDER_ATTACHMENT` as a host's depth buffer is), two draws split by it: the sky's
    /// pixels, then the scene's, each shading only its own; else one draw over every pixel.
    pub fn composite(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
        host_frame_group: &wgpu::BindGroup,
    ) {
        let split = self
            .offscreen
            .split_composite
            .as_ref()
            .filter(|_| can_test_against(depth_view));
        let mut pass = begin_with_depth(
            encoder,
            "clouds.composite",
            &[colour_view],
            wgpu::LoadOp::Load,
            split.map(|_| depth_view),
        );
        pass.set_bind_group(0, host_frame_group, &[]);
        pass.set_bind_group(1, &self.textures.composite_group, &[]);
        match split {
            Some(pipelines) => {
                for p in pipelines {
                    pass.set_pipeline(p);
                    pass.draw(0..3, 0..1);
                }
            }
            None => {
                pass.set_pipeline(&self.offscreen.composite);
                pass.draw(0..3, 0..1);
            }
        }
    }
}

/// Whether the host's depth can be a read-only depth attachment of the sky's passes (the
/// split full-screen passes test it): a depth buffer the host renders into, without stencil,
/// of one level and one layer (so the view the host hands is the whole texture).
pub(super) fn can_test_against(depth_view: &wgpu::TextureView) -> bool {
    let texture = depth_view.texture();
    texture
        .usage()
        .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        && !texture.format().has_stencil_aspect()
        && texture.mip_level_count() == 1
        && texture.depth_or_array_layers() == 1
}

/// A render pass over `views`, each loaded with `load` and stored.
fn begin<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    views: &[&wgpu::TextureView],
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPass<'e> {
    begin_with_depth(encoder, label, views, load, None)
}

/// [`begin`] with `depth` (the host's) as a read-only depth attachment (the sky's own passes
/// over the host's colour begin this way too).
pub(super) fn begin_with_depth<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    views: &[&wgpu::TextureView],
    load: wgpu::LoadOp<wgpu::Color>,
    depth: Option<&wgpu::TextureView>,
) -> wgpu::RenderPass<'e> {
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
        .iter()
        .map(|view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &attachments,
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: None,
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// The cloud target's size for host targets of `host_size` pixels drawn at 1 / `divisor`:
/// rounded up, so the last block of host pixels has a texel.
fn target_size(host_size: (u32, u32), divisor: u32) -> (u32, u32) {
    (
        host_size.0.div_ceil(divisor).max(1),
        host_size.1.div_ceil(divisor).max(1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_covers_every_block_of_host_pixels() {
        assert_eq!(target_size((160, 90), 2), (80, 45));
        assert_eq!(target_size((161, 91), 2), (81, 46));
        assert_eq!(target_size((321, 180), 4), (81, 45));
        assert_eq!(target_size((0, 0), 4), (1, 1));
    }

    #[test]
    fn scales_map_to_divisors() {
        assert_eq!(divisor_of(1.0), Some(1));
        assert_eq!(divisor_of(0.5), Some(2));
        assert_eq!(divisor_of(0.25), Some(4));
        assert_eq!(divisor_of(0.3), None);
        assert_eq!(divisor_of(0.0), None);
    }
}

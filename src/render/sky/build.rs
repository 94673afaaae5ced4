//! The sky's construction ([`Sky::new`] once the device is checked): the sprite sheet's
//! texture and group, the pipelines of the sky, the sprites and the in-cloud fog, the resident
//! set, the first view, the far field and the shadow map. Made once; a frame only uses them.

use crate::clouds::CloudsConfig;
use crate::render::RenderError;
use crate::render::overhead_ease::OverheadEase;
use crate::render::pipeline::PassDesc;
use crate::render::pipeline::SceneDepth;
use crate::render::pipeline::background_test;
use crate::render::pipeline::pipeline_with_depth;
use crate::render::sprites::pass::{SpritePass, SpriteShared};
use crate::render::sprites::sprite_view;
use crate::render::stats::Spent;
use crate::render::targets;
use crate::render::view::View;
use crate::render::view::ViewShared;
use crate::weather::BlockWeather;
use wgpu::util::DeviceExt;

use super::SKY_WGSL;
use super::Sky;
use super::SkyConfig;

impl Sky {
    /// [`Self::new`] once the device is checked.
    pub(super) fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: SkyConfig,
    ) -> Result<Self, RenderError> {
        let sheet = &config.sheet;
        if sheet.mips.is_empty() || sheet.size_px == 0 {
            return Err(RenderError::Sheet("the sprite sheet has no pixels".into()));
        }
        for (level, data) in sheet.mips.iter().enumerate() {
            let side = (sheet.size_px >> level).max(1) as usize;
            if data.len() != side * side * 4 {
                return Err(RenderError::Sheet(format!(
                    "mip level {level} has {} bytes, expected {} for {side} x {side} RGBA8",
                    data.len(),
                    side * side * 4
                )));
            }
        }
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("sky.sheet"),
                size: wgpu::Extent3d {
                    width: sheet.size_px,
                    height: sheet.size_px,
                    depth_or_array_layers: 1,
                },
                mip_level_count: sheet.mips.len() as u32,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &sheet.mips.concat(),
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("sky.sheet_sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // The nearest level, not a blend of two: the soft puffs show no seam, and on a
            // fill-bound frame it saved an eighth of the sprites' time (lavapipe, overcast).
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        let samples = config.targets.sample_count;
        let frame_layout = targets::frame_layout(device, samples > 1);
        // The impostor renders draw into the ring's own single-sample textures.
        let ring_frame_layout = targets::frame_layout(device, false);
        let sheet_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.sheet_layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let sheet_view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let sheet_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.sheet_group"),
            layout: &sheet_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&sheet_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        let view_layout = sprite_view::layout(device);
        let crops = crate::render::sprites::sheet_crop::cell_crops(sheet);
        let sprites = SpritePass::new(
            device,
            &SpriteShared {
                format: config.targets.colour_format,
                samples,
                frame_layout: &frame_layout,
                sheet_layout: &sheet_layout,
                view_layout: &view_layout,
                crops: &crops,
            },
        );
        let format = config.targets.colour_format;
        let frame_only = [Some(&frame_layout)];
        let sky_pipeline_for = |fs, depth| {
            pipeline_with_depth(
                device,
                &PassDesc {
                    label: "sky.background",
                    wgsl: SKY_WGSL,
                    vs: "vs_sky",
                    fs,
                    bind_groups: &frame_only,
                    buffers: &[],
                    targets: &[(format, None)],
                    samples,
                    scene: SceneDepth::host(samples),
                },
                depth,
            )
        };
        let sky_pipeline = sky_pipeline_for("fs_sky", None);
        let depth_format = config.targets.depth_format;
        let sky_tested_pipeline = (!depth_format.has_stencil_aspect()).then(|| {
            sky_pipeline_for(
                "fs_sky_tested",
                Some(background_test(depth_format, wgpu::CompareFunction::Equal)),
            )
        });
        let light = config.time_of_day.at(45.0);
        let offscreen_targets = crate::render::cloud_target::cloud_targets();
        let far_field = crate::render::far_field::FarField::new(
            device,
            config.settings.far_field,
            &crate::render::far_field::FarFieldShared {
                host_frame_layout: &frame_layout,
                offscreen_frame_layout: &ring_frame_layout,
                targets: config.targets,
                cloud_targets: Some(&offscreen_targets[..]),
                sheet_rgb: config
                    .sheet
                    .mean_rgb(crate::clouds::TextureCategory::Foggy.cells()),
            },
        );
        let main = View::new(
            device,
            queue,
            &ViewShared {
                targets: config.targets,
                settings: &config.settings,
                host_frame_layout: &frame_layout,
                ring_frame_layout: &ring_frame_layout,
                sheet_layout: &sheet_layout,
                view_layout: &view_layout,
            },
        );
        let shadows = crate::render::shadow::CloudShadows::new(
            device,
            queue,
            (
                config.settings.cloud_shadows,
                config.settings.in_cloud.visibility_m,
            ),
            &view_layout,
        );
        Ok(Self {
            device: device.clone(),
            settings: config.settings,
            time_of_day: config.time_of_day,
            frame_layout,
            ring_frame_layout,
            sheet_layout,
            targets: config.targets,
            sheet_group,
            sheet_bytes: sheet.mips.iter().map(|m| m.len() as u64).sum(),
            sky_pipeline,
            sky_tested_pipeline,
            sprites,
            view_layout,
            views: vec![main],
            far_field,
            lifecycle: CloudsConfig::builtin().lifecycle,
            elapsed_s: 0.0,
            pending: Spent::default(),
            field: Spent::default(),
            far_field_us: 0,
            pass_timer: None,
            prepare_timer: None,
            prepare_submitted: false,
            queue: queue.clone(),
            clear_light: light,
            seen_light: light,
            cover_transmittance: 1.0,
            overhead: (Vec::new(), 0.0),
            fog: (
                Default::default(),
                BlockWeather {
                    visibility_m: f32::INFINITY,
                    ..Default::default()
                },
            ),
            overhead_ease: OverheadEase::default(),
            shadows,
            flash: None,
        })
    }
}

//! [`Sky`]: the library object a host simulator embeds. Created once with the host's device,
//! given clouds, and each frame `prepare`d (CPU: sort, face, shade, cache; uniforms) and
//! `record`ed into the host's encoder. It draws into the host's colour target and reads the
//! host's depth texture (never writes it): the sky gradient and sun where the host drew nothing,
//! the cloud sprites with soft depth fades (Bahnassi), and in-cloud fog (Wang 7.1).
//!
//! The host's depth texture needs `TEXTURE_BINDING` usage and must be drawn with the projection
//! of [`Camera::projection`] (standard `[0, 1]` depth, near and far from the camera).

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::RenderError;
use super::camera::Camera;
use super::gpu_types::{GpuFrame, GpuSpriteVertex};
use super::impostor::{ImpostorRing, RingFrame, RingShared};
use super::pipeline::{PassDesc, pipeline, premultiplied_over};
use super::scene::SkyBlock;
use super::settings::RenderSettings;
use super::vertices::{FrameStats, Lighting, SpriteVertexBuilder, quad_indices};
use crate::shading::{SunPosition, TimeOfDay, TimeOfDayTable, hidden_above};
use crate::weather::{BlockLayer, BlockWeather};

/// The 4 x 4 sprite texture sheet, RGBA8 (linear), level 0 first, each level half the last.
#[derive(Debug, Clone, PartialEq)]
pub struct SpriteSheet {
    /// Side of level 0, pixels.
    pub size_px: u32,
    /// Pixel data of each mip level, RGBA8 row-major.
    pub mips: Vec<Vec<u8>>,
}

/// What the sky is created with.
#[derive(Debug, Clone)]
pub struct SkyConfig {
    /// Format of the host's colour target (linear formats get linear colours).
    pub colour_format: wgpu::TextureFormat,
    /// Renderer settings (`config/render.toml`).
    pub settings: RenderSettings,
    /// Time-of-day table (`config/time_of_day.toml`).
    pub time_of_day: TimeOfDayTable,
    /// The sprite texture sheet.
    pub sheet: SpriteSheet,
}

/// The sky subsystem: pipelines, buffers, the clouds and their vertex cache.
pub struct Sky {
    device: wgpu::Device,
    settings: RenderSettings,
    time_of_day: TimeOfDayTable,
    frame_buffer: wgpu::Buffer,
    frame_layout: wgpu::BindGroupLayout,
    sheet_group: wgpu::BindGroup,
    sky_pipeline: wgpu::RenderPipeline,
    sprite_pipeline: wgpu::RenderPipeline,
    in_cloud_pipeline: wgpu::RenderPipeline,
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    capacity_sprites: u32,
    blocks: Vec<SkyBlock>,
    builder: SpriteVertexBuilder,
    elapsed_s: f64,
    sprites_to_draw: u32,
    in_cloud: f32,
    /// The time-of-day light of the last frame, clear sky: what the clouds are lit with.
    clear_light: TimeOfDay,
    /// `clear_light` under the cloud cover over the camera: the sky colours and the host's light.
    seen_light: TimeOfDay,
    /// The weather over the camera: its cloud layers and ground elevation, metres.
    overhead: (Vec<BlockLayer>, f32),
    /// The fog settings and the weather over the camera they read (visibility, obscuration).
    fog: (crate::shading::FogSettings, BlockWeather),
    ring: ImpostorRing,
}

const SKY_WGSL: &str = include_str!("../../shaders/sky.wgsl");
const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
const IN_CLOUD_WGSL: &str = include_str!("../../shaders/in_cloud.wgsl");

impl Sky {
    /// Creates pipelines, the sheet texture and buffers on the host's device.
    pub fn new(
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
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.frame"),
            size: std::mem::size_of::<GpuFrame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.frame_layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
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
        let format = config.colour_format;
        let frame_only = [Some(&frame_layout)];
        let with_sheet = [Some(&frame_layout), Some(&sheet_layout)];
        let over = Some(premultiplied_over());
        let sky_pipeline = pipeline(
            device,
            &PassDesc {
                label: "sky.background",
                wgsl: SKY_WGSL,
                vs: "vs_sky",
                fs: "fs_sky",
                bind_groups: &frame_only,
                buffers: &[],
                targets: &[(format, None)],
            },
        );
        let sprite_pipeline = pipeline(
            device,
            &PassDesc {
                label: "sky.sprites",
                wgsl: SPRITES_WGSL,
                vs: "vs_sprite",
                fs: "fs_sprite",
                bind_groups: &with_sheet,
                buffers: &[Some(GpuSpriteVertex::layout())],
                targets: &[(format, over)],
            },
        );
        let in_cloud_pipeline = pipeline(
            device,
            &PassDesc {
                label: "sky.in_cloud",
                wgsl: IN_CLOUD_WGSL,
                vs: "vs_in_cloud",
                fs: "fs_in_cloud",
                bind_groups: &frame_only,
                buffers: &[],
                targets: &[(format, over)],
            },
        );
        let capacity_sprites = 1024;
        let (vertex_buffer, index_buffer) = sprite_buffers(device, capacity_sprites);
        let light = config.time_of_day.at(45.0);
        let ring = ImpostorRing::new(
            device,
            queue,
            config.settings.impostors,
            &RingShared {
                colour_format: format,
                frame_layout: &frame_layout,
                sheet_layout: &sheet_layout,
            },
        );
        Ok(Self {
            device: device.clone(),
            settings: config.settings,
            time_of_day: config.time_of_day,
            frame_buffer,
            frame_layout,
            sheet_group,
            sky_pipeline,
            sprite_pipeline,
            in_cloud_pipeline,
            vertex_buffer,
            index_buffer,
            capacity_sprites,
            blocks: Vec::new(),
            builder: SpriteVertexBuilder::new(),
            elapsed_s: 0.0,
            sprites_to_draw: 0,
            in_cloud: 0.0,
            clear_light: light,
            seen_light: light,
            overhead: (Vec::new(), 0.0),
            fog: (
                Default::default(),
                BlockWeather {
                    visibility_m: f32::INFINITY,
                    ..Default::default()
                },
            ),
            ring,
        })
    }

    /// Replaces the clouds. Cached vertices of blocks that stay (same id) are kept.
    pub fn set_clouds(&mut self, blocks: Vec<SkyBlock>) {
        self.builder.retain(&blocks);
        self.blocks = blocks;
    }

    /// The clouds being drawn.
    pub fn clouds(&self) -> &[SkyBlock] {
        &self.blocks
    }

    /// The settings the sky was made with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Turns the vertex cache on or off (off: every cloud recomputed every frame).
    pub fn set_vertex_cache(&mut self, enabled: bool) {
        self.settings.vertex_cache.enabled = enabled;
    }

    /// The weather over the camera (the layers and ground of its point of the weather field).
    /// Each frame works out how much of the sky the layers above the camera hide
    /// ([`crate::shading::hidden_above`]): below a thick deck the sky turns grey and dim and
    /// [`Self::light`] loses its sun; above it nothing changes. The clouds keep their own light.
    /// Until it is called the sky is taken as clear overhead.
    pub fn set_weather_overhead(&mut self, weather: &BlockWeather) {
        self.overhead = (weather.layers.clone(), weather.ground_elevation_m);
        self.fog.1 = weather.clone();
    }

    /// The fog a host draws over its scene: the visibility and obscuration of the weather over
    /// the camera ([`crate::shading::fog`]) under the last frame's horizon sky.
    pub fn fog(&self) -> crate::shading::Fog {
        self.fog.0.fog(&self.fog.1, self.seen_light.sky_horizon_rgb)
    }

    /// The fraction of the sky hidden above `altitude_m` by the weather overhead, 0..=1.
    pub fn sky_hidden_at(&self, altitude_m: f64) -> f32 {
        let (layers, ground_m) = &self.overhead;
        hidden_above(
            layers,
            *ground_m,
            altitude_m as f32,
            &self.time_of_day.overcast,
        )
    }

    /// Colour a host should fog its distant ground towards (the horizon sky colour now).
    pub fn horizon_rgb(&self) -> Vec3 {
        self.seen_light.sky_horizon_rgb
    }

    /// The light of the last prepared frame under the cloud cover (see [`Self::set_weather_overhead`]):
    /// what a host lights its own scene with.
    pub fn light(&self) -> TimeOfDay {
        self.seen_light
    }

    /// The time-of-day light for a sun position (for hosts lighting their own scene).
    pub fn light_for(&self, sun: &SunPosition) -> TimeOfDay {
        self.time_of_day.at(sun.elevation_deg as f32)
    }

    /// Bytes of the GPU buffers the sky holds now (frame uniforms, sprite vertices and indices):
    /// what a long flight watches for growth.
    pub fn gpu_buffer_bytes(&self) -> u64 {
        self.frame_buffer.size()
            + self.vertex_buffer.size()
            + self.index_buffer.size()
            + self.ring.gpu_bytes()
    }

    /// CPU work of a frame: advances time by `dt_s`, sorts, faces, shades and caches sprites,
    /// uploads vertices and this frame's uniforms.
    pub fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        camera: &Camera,
        sun: &SunPosition,
        dt_s: f64,
    ) -> FrameStats {
        self.elapsed_s += dt_s.max(0.0);
        self.clear_light = self.time_of_day.at(sun.elevation_deg as f32);
        self.seen_light = self.clear_light.under_cover(
            self.sky_hidden_at(camera.position_m.z),
            &self.time_of_day.overcast,
        );
        let sun_dir = sun.direction_enu().as_vec3();
        let lighting = Lighting {
            sun_dir,
            time_of_day: self.clear_light,
            mapping: self.time_of_day.directional_mapping,
            forward: self.time_of_day.forward_scattering,
        };
        let near = self
            .ring
            .split(&self.blocks, camera.position_m, sun_dir, dt_s);
        let near: Vec<&SkyBlock> = near.iter().map(|&i| &self.blocks[i]).collect();
        let mut stats = self.builder.update(
            &near,
            camera.position_m,
            self.elapsed_s,
            &lighting,
            &self.settings,
        );
        let upload_start = std::time::Instant::now();
        let vertices = self.builder.vertices();
        let sprites = (vertices.len() / 4) as u32;
        if sprites > self.capacity_sprites {
            self.capacity_sprites = sprites.next_power_of_two();
            let (v, i) = sprite_buffers(&self.device, self.capacity_sprites);
            self.vertex_buffer = v;
            self.index_buffer = i;
        }
        if sprites > 0 {
            queue.write_buffer(&self.vertex_buffer, 0, bytemuck::cast_slice(vertices));
        }
        self.sprites_to_draw = sprites;
        self.in_cloud = stats.in_cloud;

        let view_proj = camera.view_proj_relative();
        let sun_cfg = &self.settings.sun;
        // In-cloud fog: the ambient of a mid-grey cloud at this time of day plus some sun.
        let fog_rgb = Vec3::splat(0.8) * self.clear_light.ambient_percent
            + self.clear_light.directional_rgb * 0.25;
        let frame = GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            sun_dir: sun_dir
                .extend(sun_cfg.disc_radius_deg.to_radians().cos())
                .to_array(),
            sun_rgb: self
                .seen_light
                .directional_rgb
                .extend(sun_cfg.glow_radius_deg.to_radians().cos())
                .to_array(),
            sky_zenith_rgb: self.seen_light.sky_zenith_rgb.extend(1.0).to_array(),
            sky_horizon_rgb: self.seen_light.sky_horizon_rgb.extend(1.0).to_array(),
            in_cloud_rgba: fog_rgb.extend(stats.in_cloud).to_array(),
            params: [
                camera.near_m,
                camera.far_m,
                self.settings.clouds.soft_depth_fade_m,
                self.settings.in_cloud.visibility_m,
            ],
            haze: [
                self.fog
                    .0
                    .haze_distance_m(&self.fog(), self.settings.clouds.haze_distance_m),
                0.0,
                0.0,
                0.0,
            ],
        };
        queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&frame));
        let ring_frame = RingFrame {
            blocks: &self.blocks,
            template: &frame,
            lighting: &lighting,
            time_s: self.elapsed_s,
            render: &self.settings,
            camera_m: camera.position_m,
        };
        self.ring.prepare_builds(queue, &ring_frame, &mut stats);
        stats.cpu_update_us += upload_start.elapsed().as_micros() as u64;
        stats
    }

    /// Records the sky's passes into the host's encoder: sky background, sprites, in-cloud fog.
    /// `depth_view` is the host's depth (Depth32Float with `TEXTURE_BINDING`), only read.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) {
        let frame_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.frame_group"),
            layout: &self.frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.frame_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(depth_view),
                },
            ],
        });
        self.ring.record_builds(encoder, &self.sheet_group);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sky"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &frame_group, &[]);
        pass.set_pipeline(&self.sky_pipeline);
        pass.draw(0..3, 0..1);
        self.ring.draw(&mut pass);
        if self.sprites_to_draw > 0 {
            pass.set_pipeline(&self.sprite_pipeline);
            pass.set_bind_group(1, &self.sheet_group, &[]);
            pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
            pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.sprites_to_draw * 6, 0, 0..1);
        }
        if self.in_cloud > 0.0 {
            pass.set_pipeline(&self.in_cloud_pipeline);
            pass.draw(0..3, 0..1);
        }
    }
}

fn sprite_buffers(device: &wgpu::Device, sprites: u32) -> (wgpu::Buffer, wgpu::Buffer) {
    let vertex = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.sprite_vertices"),
        size: sprites as u64 * 4 * std::mem::size_of::<GpuSpriteVertex>() as u64,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let index = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("sky.sprite_indices"),
        contents: bytemuck::cast_slice(&quad_indices(sprites)),
        usage: wgpu::BufferUsages::INDEX,
    });
    (vertex, index)
}

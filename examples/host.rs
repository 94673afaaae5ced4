//! A complete host: its own device, colour and depth, its own ground, and skycast's sky in one
//! object. `cargo run --example host -- [standard|reversed|msaa] [out.png]`
use glam::camera::rh::{proj::directx as proj, view::look_at_mat4};
use glam::{Mat4, Vec3};
use skycast::{HostCamera, HostPosition, HostTargets, SkySystem, ViewId, Weather};
use wgpu::{TextureFormat, TextureUsages as Usage};
type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// Under the fair-weather cumulus theme near Los Angeles, looking up a little; 320 x 180. (The
/// theme by its path in the repository, so that the example runs from any directory.)
pub const THEME: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/themes/fair_weather_cumulus.toml"
);
pub const AT: (f64, f64) = (34.0, -118.4);
pub const ALT_M: f64 = 800.0;
pub const HEADING_DEG: f64 = 30.0;
pub const PITCH_DEG: f64 = 12.0;
pub const W: u32 = 320;
pub const H: u32 = 180;
pub const UNIX_S: f64 = 1_738_015_200.0; // 2025-01-27T22:00:00Z

/// The host's ground: a 120 km square at sea level, one colour, its sunlit share dimmed by the
/// clouds' shadows: the sky's shadow map holds their optical depth tau along the sun's ray.
const GROUND: &str = "struct Ground { view_proj: mat4x4<f32>, shadow_uv: mat4x4<f32> };
@group(0) @binding(0) var<uniform> g: Ground;
@group(0) @binding(1) var shadow_map: texture_2d<f32>;
@group(0) @binding(2) var shadow_sampler: sampler;
struct Out { @builtin(position) position: vec4<f32>, @location(0) rel: vec3<f32> };
@vertex fn vs(@builtin(vertex_index) i: u32) -> Out {
  let rel = vec3((vec2(f32(i & 1u), f32(i >> 1u)) * 2.0 - 1.0) * 60000.0, -ALT);
  return Out(g.view_proj * vec4(rel, 1.0), rel); }
@fragment fn fs(i: Out) -> @location(0) vec4<f32> {
  let tau = textureSample(shadow_map, shadow_sampler, (g.shadow_uv * vec4(i.rel, 1.0)).xy).r;
  return vec4(vec3(0.18, 0.24, 0.12) * (0.35 + 0.65 * exp(-tau)), 1.0); }";

/// A simulator's renderer in miniature: device, targets, ground pipeline, and the sky.
pub struct Host {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub sky: SkySystem,
    pub targets: HostTargets,
    pub colour: wgpu::Texture,
    pub depth: wgpu::Texture,
    /// The single-sample copy of `colour` (itself when not multisampled).
    pub resolved: wgpu::Texture,
    ground: (wgpu::RenderPipeline, wgpu::Buffer, wgpu::Sampler),
    pub camera: HostCamera,
    /// The air where the camera is, read every frame after the sky's update (what a flight
    /// model and its systems take: wind, temperature, pressure, in-cloud, turbulence, icing).
    pub air: Option<skycast::flight::AirData>,
}

impl Host {
    /// `mode`: "standard" Z, "reversed" Z with an infinite far plane, or "msaa" (4 samples).
    pub fn new(mode: &str, weather: Option<&std::path::Path>) -> Result<Self> {
        let (reversed, samples) = (mode == "reversed", if mode == "msaa" { 4 } else { 1 });
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
        let limits = wgpu::Limits {
            max_storage_buffers_per_shader_stage: 8,
            ..wgpu::Limits::downlevel_defaults()
        };
        let descriptor = wgpu::DeviceDescriptor {
            required_limits: limits,
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
        let targets = HostTargets {
            reversed_z: reversed,
            sample_count: samples,
            ..Default::default()
        };
        let texture = |format, sample_count, usage| texture(&device, format, sample_count, usage);
        let colour = texture(
            targets.colour_format,
            samples,
            Usage::RENDER_ATTACHMENT | Usage::COPY_SRC,
        );
        let resolved = texture(
            targets.colour_format,
            1,
            Usage::RENDER_ATTACHMENT | Usage::COPY_SRC,
        );
        // The sky reads the host's depth as a texture (never writes it).
        let depth = texture(
            targets.depth_format,
            samples,
            Usage::RENDER_ATTACHMENT | Usage::TEXTURE_BINDING | Usage::COPY_SRC,
        );

        // The sky: one object on the host's device, for the host's targets.
        let mut sky = SkySystem::new(&device, &queue, targets, AT)?;
        // The warm-up, for the tests: the first frame waits for every cloud around, the same
        // frame every run. A simulator leaves it off (`main` does): no frame waits.
        sky.world_mut().set_synchronous_clouds(true);
        if let Some(path) = weather {
            sky.set_weather(Weather::File(path))?;
        }
        let (fov, aspect) = (50f32.to_radians(), W as f32 / H as f32);
        let projection = match reversed {
            true => proj::perspective_infinite_reverse(fov, aspect, 1.0),
            false => proj::perspective(fov, aspect, 1.0, 300_000.0),
        };
        let position = HostPosition::LatLonAlt {
            lat_deg: AT.0,
            lon_deg: AT.1,
            alt_m: ALT_M,
        };
        let camera = HostCamera {
            position,
            view: look(HEADING_DEG, PITCH_DEG),
            projection,
        };
        let ground = ground(&device, &targets);
        Ok(Self {
            device,
            queue,
            sky,
            targets,
            colour,
            depth,
            resolved,
            ground,
            camera,
            air: None,
        })
    }

    /// The sky's frame step: weather, clouds, sun, its CPU share and its own GPU work (the
    /// shadow map among it), before the host draws its frame.
    /// The air where the camera is is read after it.
    pub fn update(&mut self) -> Result<skycast::FrameStats> {
        let (stats, _) = self.sky.update(&self.queue, &self.camera, UNIX_S, 0.0)?;
        self.air = Some(self.sky.air_at(self.camera.position));
        Ok(stats)
    }

    /// The ground into colour and depth (cleared to the host's far value), in the clouds'
    /// shadows of the last update.
    pub fn draw_ground(&self, encoder: &mut wgpu::CommandEncoder) {
        let (pipeline, uniform, sampler) = &self.ground;
        let shadows = self.sky.cloud_shadows();
        let view_proj = self.camera.projection * self.camera.view;
        let matrices = [view_proj, shadows.uv_from_camera_relative];
        self.queue
            .write_buffer(uniform, 0, bytemuck::cast_slice(&matrices));
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(shadows.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
            ],
        });
        let (colour, depth) = (
            self.colour.create_view(&Default::default()),
            self.depth.create_view(&Default::default()),
        );
        let store = wgpu::StoreOp::Store;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &colour,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(self.targets.background_depth()),
                    store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..4, 0..1);
    }

    /// The sky's passes over the host's colour, reading its depth (after [`Self::update`]).
    pub fn draw_sky(&mut self, encoder: &mut wgpu::CommandEncoder) -> Result<()> {
        let (colour, depth) = (
            self.colour.create_view(&Default::default()),
            self.depth.create_view(&Default::default()),
        );
        self.sky.record(encoder, &colour, &depth)?;
        if self.targets.sample_count > 1 {
            resolve(encoder, &colour, &self.resolved);
        }
        Ok(())
    }

    /// The frame: the sky's step, then the ground, then the sky; RGBA8 sRGB bytes read back.
    pub fn frame(&mut self) -> Result<Vec<u8>> {
        let stats = self.update()?;
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.draw_ground(&mut encoder);
        self.draw_sky(&mut encoder)?;
        println!(
            "{} sprites, sky CPU {} us",
            stats.sprites_drawn,
            stats.sky_cpu_us()
        );
        let single = if self.targets.sample_count > 1 {
            &self.resolved
        } else {
            &self.colour
        };
        read_back(&self.device, &self.queue, encoder, single)
    }
}

/// A second view of the same sky (a monitor looking back over the tail, a mirror): its own
/// camera and targets, no ground of its own (its depth cleared to the far value).
pub struct SecondView {
    pub id: ViewId,
    pub camera: HostCamera,
    pub colour: wgpu::Texture,
    pub depth: wgpu::Texture,
    /// The single-sample copy of `colour` (unused when not multisampled).
    pub resolved: wgpu::Texture,
}

impl Host {
    /// Adds a view from the same place looking `heading_deg`, `pitch_deg`, with targets of its
    /// own (the sky's formats and samples).
    pub fn add_view(&mut self, heading_deg: f64, pitch_deg: f64) -> SecondView {
        let (d, t) = (&self.device, &self.targets);
        let attachment = Usage::RENDER_ATTACHMENT | Usage::COPY_SRC;
        SecondView {
            id: self.sky.add_view(),
            camera: HostCamera {
                view: look(heading_deg, pitch_deg),
                ..self.camera
            },
            colour: texture(d, t.colour_format, t.sample_count, attachment),
            depth: texture(
                d,
                t.depth_format,
                t.sample_count,
                attachment | Usage::TEXTURE_BINDING,
            ),
            resolved: texture(d, t.colour_format, 1, attachment),
        }
    }

    /// The view's share of the frame step, then its passes into `encoder` (after
    /// [`Self::update`], and [`Self::draw_sky`]'s passes in the same encoder or another).
    pub fn draw_view(
        &mut self,
        view: &SecondView,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<skycast::FrameStats> {
        let stats = self.sky.update_view(view.id, &self.queue, &view.camera)?;
        let colour = view.colour.create_view(&Default::default());
        let depth = view.depth.create_view(&Default::default());
        let store = wgpu::StoreOp::Store;
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &colour,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(self.targets.background_depth()),
                    store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        self.sky.record_view(view.id, encoder, &colour, &depth)?;
        if self.targets.sample_count > 1 {
            resolve(encoder, &colour, &view.resolved);
        }
        Ok(stats)
    }
}

/// The view matrix for east-north-up axes looking `heading_deg` (clockwise from north) and
/// `pitch_deg` up.
fn look(heading_deg: f64, pitch_deg: f64) -> Mat4 {
    let (h, p) = (
        heading_deg.to_radians() as f32,
        pitch_deg.to_radians() as f32,
    );
    let forward = Vec3::new(h.sin() * p.cos(), h.cos() * p.cos(), p.sin());
    look_at_mat4(Vec3::ZERO, forward, Vec3::Z)
}

/// A texture of the frame's size.
fn texture(
    device: &wgpu::Device,
    format: TextureFormat,
    sample_count: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    let size = wgpu::Extent3d {
        width: W,
        height: H,
        depth_or_array_layers: 1,
    };
    device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size,
        mip_level_count: 1,
        sample_count,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The host resolves its multisampled colour itself, after the sky recorded: an empty pass
/// with a resolve target.
fn resolve(
    encoder: &mut wgpu::CommandEncoder,
    colour: &wgpu::TextureView,
    resolved: &wgpu::Texture,
) {
    let resolve_target = Some(resolved.create_view(&Default::default()));
    let ops = wgpu::Operations {
        load: wgpu::LoadOp::Load,
        store: wgpu::StoreOp::Store,
    };
    let attachment = wgpu::RenderPassColorAttachment {
        view: colour,
        depth_slice: None,
        resolve_target: resolve_target.as_ref(),
        ops,
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        color_attachments: &[Some(attachment)],
        ..Default::default()
    });
}

/// The ground pipeline (depth tested the host's way), its uniform (view-projection, shadow
/// lookup) and the shadow map's sampler (linear, clamped to its edge).
fn ground(
    device: &wgpu::Device,
    targets: &HostTargets,
) -> (wgpu::RenderPipeline, wgpu::Buffer, wgpu::Sampler) {
    let source = wgpu::ShaderSource::Wgsl(GROUND.replace("ALT", &format!("{ALT_M:.1}")).into());
    let module = &device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source,
    });
    let depth_compare = Some(if targets.reversed_z {
        wgpu::CompareFunction::Greater
    } else {
        wgpu::CompareFunction::Less
    });
    let depth = wgpu::DepthStencilState {
        format: targets.depth_format,
        depth_write_enabled: Some(true),
        depth_compare,
        stencil: Default::default(),
        bias: Default::default(),
    };
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        multiview_mask: None,
        cache: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleStrip,
            ..Default::default()
        },
        depth_stencil: Some(depth),
        multisample: wgpu::MultisampleState {
            count: targets.sample_count,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(targets.colour_format.into())],
        }),
    });
    let uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 2 * std::mem::size_of::<Mat4>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    (pipeline, uniform, sampler)
}

/// Submits `encoder` with a copy of a 4-byte-texel texture and reads it back (rows unpadded).
pub fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mut encoder: wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> Result<Vec<u8>> {
    let row = (W * 4).div_ceil(256) * 256;
    let usage = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row * H) as u64,
        usage,
        mapped_at_creation: false,
    });
    let layout = wgpu::TexelCopyBufferLayout {
        offset: 0,
        bytes_per_row: Some(row),
        rows_per_image: Some(H),
    };
    let size = wgpu::Extent3d {
        width: W,
        height: H,
        depth_or_array_layers: 1,
    };
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout,
        },
        size,
    );
    queue.submit([encoder.finish()]);
    buffer.map_async(wgpu::MapMode::Read, .., |_| {});
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let bytes = buffer
        .get_mapped_range(..)?
        .chunks(row as usize)
        .flat_map(|r| r[..W as usize * 4].to_vec())
        .collect();
    Ok(bytes)
}

#[allow(dead_code)]
fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("standard", String::as_str);
    let mut host = Host::new(mode, Some(std::path::Path::new(THEME)))?;
    // As a simulator runs it: the first update queues the clouds around and returns, and they
    // arrive over the next frames, fading in.
    host.sky.world_mut().set_synchronous_clouds(false);
    let dt_s = 1.0 / 60.0;
    let start = std::time::Instant::now();
    let (first, _) = host.sky.update(&host.queue, &host.camera, UNIX_S, dt_s)?;
    let first_ms = start.elapsed().as_secs_f64() * 1e3;
    // Four seconds of 60 Hz frame steps (drawn or not, it is the same step), by which the
    // clouds have arrived and faded in: the blocks the sky holds after some of them.
    let mut arrived = vec![(1, host.sky.sky().block_ids().count())];
    for frame in 2..=240 {
        std::thread::sleep(std::time::Duration::from_secs_f64(dt_s));
        host.sky.update(&host.queue, &host.camera, UNIX_S, dt_s)?;
        if [2, 5, 10, 30, 60, 240].contains(&frame) {
            arrived.push((frame, host.sky.sky().block_ids().count()));
        }
    }
    println!(
        "first update {first_ms:.1} ms (cloud field {} us, sky {} us); blocks held after (frames, blocks): {arrived:?}",
        first.field_us, first.cpu_update_us
    );
    let out = args.get(2).map_or("host.png", String::as_str);
    image::save_buffer(out, &host.frame()?, W, H, image::ExtendedColorType::Rgba8)?;
    // A second view of the same sky, looking back over the tail, recorded into the same
    // encoder as the main one: its own draw list, ring and cloud target.
    let back = host.add_view(HEADING_DEG + 180.0, 8.0);
    host.update()?;
    let mut encoder = host.device.create_command_encoder(&Default::default());
    host.draw_ground(&mut encoder);
    host.draw_sky(&mut encoder)?;
    host.draw_view(&back, &mut encoder)?;
    let single = |v: &SecondView| {
        if host.targets.sample_count > 1 {
            v.resolved.clone()
        } else {
            v.colour.clone()
        }
    };
    let back_pixels = read_back(&host.device, &host.queue, encoder, &single(&back))?;
    let back_out = out.replace(".png", "_back.png");
    image::save_buffer(
        &back_out,
        &back_pixels,
        W,
        H,
        image::ExtendedColorType::Rgba8,
    )?;
    println!(
        "second view: {back_out}; it adds {:.1} MB of GPU memory",
        host.sky.sky().view_gpu_bytes(back.id) as f64 / 1e6
    );
    println!(
        "{mode}: {out}; light for the host's own scene: {:?}",
        host.sky.lighting()
    );
    if let Some(air) = &host.air {
        println!(
            "air: wind {:03.0}/{:.0} kt, {:.1} C, {:.1} hPa, in cloud {:.2}, turbulence {:?}",
            air.wind_from_deg,
            air.wind_kt,
            air.temperature_c,
            air.pressure_hpa,
            air.in_cloud,
            air.turbulence_category
        );
    }
    Ok(())
}

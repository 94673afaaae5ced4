//! A complete host: its own device, colour and depth, its own ground, and skycast's sky in one
//! object. `cargo run --example host -- [standard|reversed|msaa] [out.png]`.
use glam::Vec3;
use glam::camera::rh::{proj::directx as proj, view::look_at_mat4};
use skycast::flight::{HostCamera, HostPosition, SkySystem, Weather};
use skycast::render::HostTargets;
type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The pose both this host and `skycast render` draw: under the fair-weather cumulus theme.
pub const THEME: &str = "weather/themes/fair_weather_cumulus.toml";
pub const AT: (f64, f64) = (34.0, -118.4);
pub const ALT_M: f64 = 800.0;
pub const W: u32 = 320;
pub const H: u32 = 180;
pub const HEADING_DEG: f64 = 30.0;
pub const PITCH_DEG: f64 = 12.0;
pub const UNIX_S: f64 = 1_738_015_200.0; // 2025-01-27T22:00:00Z

/// A drawn frame: sRGB bytes, and whether the host's depth was the same after the sky.
pub struct HostFrame {
    pub rgba8: Vec<u8>,
    pub depth_unchanged: Option<bool>,
}

const GROUND_WGSL: &str = "@group(0) @binding(0) var<uniform> u: mat4x4<f32>;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
  let c = array(vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
  return u * vec4<f32>(c[i] * 60000.0, -ALT, 1.0); }
@fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(0.18, 0.24, 0.12, 1.0); }";

/// Draws one frame with the host's depth `mode`: standard, reversed (infinite far), or msaa.
pub fn run(mode: &str, weather: Option<&std::path::Path>) -> Result<HostFrame> {
    let (reversed, samples) = (mode == "reversed", if mode == "msaa" { 4 } else { 1 });
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: wgpu::Limits {
            max_storage_buffers_per_shader_stage: 8,
            ..wgpu::Limits::downlevel_defaults()
        },
        ..Default::default()
    }))?;
    let targets = HostTargets {
        reversed_z: reversed,
        sample_count: samples,
        ..Default::default()
    };
    let texture = |format, samples, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: W,
                height: H,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    use wgpu::TextureUsages as U;
    let colour = texture(
        targets.colour_format,
        samples,
        U::RENDER_ATTACHMENT | U::COPY_SRC,
    );
    let resolved = texture(targets.colour_format, 1, U::RENDER_ATTACHMENT | U::COPY_SRC);
    let depth = texture(
        targets.depth_format,
        samples,
        U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
    );
    let (colour_view, depth_view) = (
        colour.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );

    // The sky: one object, built on this host's device for its targets.
    let mut sky = SkySystem::new(&device, &queue, targets, AT)?;
    sky.world_mut().set_synchronous_clouds(true); // the same frame every run, for the test
    if let Some(path) = weather {
        sky.set_weather(Weather::File(path))?;
    }
    let h = HEADING_DEG.to_radians();
    let p = PITCH_DEG.to_radians();
    let forward = Vec3::new(
        (h.sin() * p.cos()) as f32,
        (h.cos() * p.cos()) as f32,
        p.sin() as f32,
    );
    let view = look_at_mat4(Vec3::ZERO, forward, Vec3::Z);
    let (fov, aspect) = (50f32.to_radians(), W as f32 / H as f32);
    let projection = if reversed {
        proj::perspective_infinite_reverse(fov, aspect, 1.0)
    } else {
        proj::perspective(fov, aspect, 1.0, 300_000.0)
    };
    let camera = HostCamera {
        position: HostPosition::LatLonAlt {
            lat_deg: AT.0,
            lon_deg: AT.1,
            alt_m: ALT_M,
        },
        view,
        projection,
    };
    let (stats, _) = sky.update(&queue, &camera, UNIX_S, 0.0)?;
    println!(
        "{mode}: {} sprites, sky CPU {} us, fog {:.0} m",
        stats.sprites_drawn,
        stats.sky_cpu_us(),
        sky.lighting().fog_distance_m
    );

    // The host's own ground: a plane at sea level under the camera.
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(GROUND_WGSL.replace("ALT", &format!("{ALT_M:.1}")).into()),
    });
    let compare = if reversed {
        wgpu::CompareFunction::Greater
    } else {
        wgpu::CompareFunction::Less
    };
    let ground = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        multiview_mask: None,
        cache: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleStrip,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: targets.depth_format,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(targets.colour_format.into())],
        }),
    });
    use wgpu::util::DeviceExt;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of(&(projection * view)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &ground.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    // The ground pass (clear, draw), or with `resolve` a pass that only resolves the samples.
    let pass = |e: &mut wgpu::CommandEncoder, clear: bool, resolve: Option<&wgpu::TextureView>| {
        let load = if clear {
            wgpu::LoadOp::Clear(wgpu::Color::BLACK)
        } else {
            wgpu::LoadOp::Load
        };
        let mut p = e.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &colour_view,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: clear.then(|| wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(targets.background_depth()),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        if clear {
            p.set_pipeline(&ground);
            p.set_bind_group(0, &group, &[]);
            p.draw(0..4, 0..1);
        }
    };
    let mut e = device.create_command_encoder(&Default::default());
    pass(&mut e, true, None);
    let before = (samples == 1).then(|| copy(&device, &mut e, &depth, 4));
    sky.record(&mut e, &colour_view, &depth_view);
    let after = (samples == 1).then(|| copy(&device, &mut e, &depth, 4));
    if samples > 1 {
        pass(
            &mut e,
            false,
            Some(&resolved.create_view(&Default::default())),
        );
    }
    let pixels = copy(
        &device,
        &mut e,
        if samples > 1 { &resolved } else { &colour },
        4,
    );
    queue.submit([e.finish()]);
    let read = |b: wgpu::Buffer| -> Result<Vec<u8>> {
        b.map_async(wgpu::MapMode::Read, .., |_| {});
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let data = b
            .get_mapped_range(..)?
            .chunks(row(4) as usize)
            .flat_map(|r| r[..W as usize * 4].to_vec())
            .collect();
        Ok(data)
    };
    let depth_unchanged = match (before, after) {
        (Some(b), Some(a)) => Some(read(b)? == read(a)?),
        _ => None,
    };
    Ok(HostFrame {
        rgba8: read(pixels)?,
        depth_unchanged,
    })
}

fn row(texel: u32) -> u32 {
    (W * texel).div_ceil(256) * 256
}

/// Copies a texture into a new mappable buffer (rows padded to 256 bytes).
fn copy(
    device: &wgpu::Device,
    e: &mut wgpu::CommandEncoder,
    t: &wgpu::Texture,
    texel: u32,
) -> wgpu::Buffer {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row(texel) * H) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    e.copy_texture_to_buffer(
        t.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row(texel)),
                rows_per_image: Some(H),
            },
        },
        wgpu::Extent3d {
            width: W,
            height: H,
            depth_or_array_layers: 1,
        },
    );
    buffer
}

#[allow(dead_code)]
fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("standard", String::as_str);
    let frame = run(mode, Some(std::path::Path::new(THEME)))?;
    let out = args.get(2).map_or("host.png", String::as_str);
    image::save_buffer(out, &frame.rgba8, W, H, image::ExtendedColorType::Rgba8)?;
    println!(
        "{out}: depth unchanged by the sky: {:?}",
        frame.depth_unchanged
    );
    Ok(())
}

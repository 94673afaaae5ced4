//! `examples/host.rs`, a host of our own written from the public API, run three times (standard
//! Z, reversed Z, 4x MSAA colour and depth): each frame has its clouds where `skycast render`'s
//! path (the demo host, the same weather and pose) has them, and the host's depth is the same
//! after the sky recorded as before.

#[path = "../examples/host.rs"]
#[allow(dead_code)]
mod host;

use std::path::Path;

use glam::DVec3;
use skycast::demo::{DemoHost, GroundSettings, demo_ground, headless};
use skycast::flight::world::{World, WorldSettings};
use skycast::render::{Camera, SkyConfig};
use skycast::shading::sun_position;
use skycast::weather::{CloudTypeRule, FieldSettings, LocalFrame, WeatherInput};

/// The frames `skycast render` draws of the example's pose (its own ground, the same sky):
/// with the clouds, and with the same weather's sky but no clouds.
fn reference_frames() -> [Vec<u8>; 2] {
    let input = WeatherInput::load(Path::new(host::THEME), None).expect("theme");
    let field = input.field(
        LocalFrame::new(host::AT.0, host::AT.1),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let mut world = World::new(field, &WorldSettings::default());
    let ground = demo_ground(world.field(), &GroundSettings::default());
    let mut demo = DemoHost::new(host::W, host::H, &ground, SkyConfig::new(headless::TARGETS))
        .expect("demo host");
    let position = DVec3::new(0.0, 0.0, host::ALT_M);
    let camera = Camera {
        position_m: position,
        heading_deg: host::HEADING_DEG,
        pitch_deg: host::PITCH_DEG,
        fov_y_deg: 50.0,
        aspect: host::W as f32 / host::H as f32,
        near_m: 1.0,
        far_m: 300_000.0,
    };
    demo.sky.set_weather_overhead(&world.weather_over(position));
    let sun = sun_position(host::UNIX_S, host::AT.0, host::AT.1);
    let (clear, _) = demo.frame(&camera, &sun, 0.0, 40_000.0).expect("frame");
    demo.sky.set_clouds(world.sky_blocks_around(position));
    let (clouds, _) = demo.frame(&camera, &sun, 0.0, 40_000.0).expect("frame");
    [clouds.to_srgb8(), clear.to_srgb8()]
}

/// Which pixels above the horizon are cloud: they differ from the clear sky's.
fn cloud_mask(frame: &[u8], clear: &[u8]) -> Vec<bool> {
    let above_horizon = (host::W * host::H * 6 / 10) as usize;
    (0..above_horizon)
        .map(|i| {
            let d: i32 = (0..3)
                .map(|c| (frame[i * 4 + c] as i32 - clear[i * 4 + c] as i32).abs())
                .sum();
            d > 24
        })
        .collect()
}

fn agreement(a: &[bool], b: &[bool]) -> f64 {
    a.iter().zip(b).filter(|(x, y)| x == y).count() as f64 / a.len() as f64
}

/// Every sample of a 4x multisampled depth texture (which cannot be copied), read by drawing it
/// into a single-sample RGBA32Float target, a sample a channel.
fn depth_samples(h: &host::Host) -> Vec<u8> {
    const WGSL: &str = "@group(0) @binding(0) var depth: texture_multisampled_2d<f32>;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
  return vec4<f32>(f32((i << 1u) & 2u) * 2.0 - 1.0, f32(i & 2u) * 2.0 - 1.0, 0.0, 1.0); }
@fragment fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
  let at = vec2<i32>(p.xy);
  return vec4<f32>(textureLoad(depth, at, 0).r, textureLoad(depth, at, 1).r,
    textureLoad(depth, at, 2).r, textureLoad(depth, at, 3).r); }";
    let device = &h.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(WGSL.into()),
    });
    let format = wgpu::TextureFormat::Rgba32Float;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let view = h.depth.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&view),
        }],
    });
    let size = wgpu::Extent3d {
        width: host::W,
        height: host::H,
        depth_or_array_layers: 1,
    };
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let target_view = target.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
    let row = (host::W * 16).div_ceil(256) * 256;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row * host::H) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(host::H),
            },
        },
        size,
    );
    h.queue.submit([encoder.finish()]);
    buffer.map_async(wgpu::MapMode::Read, .., |_| {});
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    buffer.get_mapped_range(..).unwrap().to_vec()
}

/// The example's frame in `mode`, and whether the host's depth was the same after the sky
/// recorded (copied, or every sample read, when multisampled).
fn host_frame(mode: &str) -> (Vec<u8>, bool) {
    let mut h = host::Host::new(mode, Some(Path::new(host::THEME))).expect(mode);
    let copyable = h.targets.sample_count == 1;
    let encoder = |h: &host::Host| h.device.create_command_encoder(&Default::default());
    h.update().expect("update");
    let mut ground = encoder(&h);
    h.draw_ground(&mut ground);
    let before = if copyable {
        host::read_back(&h.device, &h.queue, ground, &h.depth).expect("depth")
    } else {
        h.queue.submit([ground.finish()]);
        depth_samples(&h)
    };
    let mut sky = encoder(&h);
    h.draw_sky(&mut sky);
    let after = if copyable {
        host::read_back(&h.device, &h.queue, sky, &h.depth).expect("depth")
    } else {
        h.queue.submit([sky.finish()]);
        depth_samples(&h)
    };
    let colour = if copyable { &h.colour } else { &h.resolved };
    let pixels = host::read_back(&h.device, &h.queue, encoder(&h), colour).expect("colour");
    // The ground covers the lower part of the frame: the depth holds something to change.
    assert!(
        before.iter().any(|&b| b != before[0]),
        "{mode}: a uniform depth"
    );
    (pixels, before == after)
}

#[test]
fn the_example_host_draws_the_clouds_render_draws_in_every_depth_convention() {
    let [clouds, clear] = reference_frames();
    let reference = cloud_mask(&clouds, &clear);
    let cover = reference.iter().filter(|&&c| c).count() as f64 / reference.len() as f64;
    assert!(
        (0.2..0.97).contains(&cover),
        "the pose must show clouds and sky: {cover}"
    );
    // Negative control: a frame without the clouds agrees with the reference only where the
    // reference has none.
    let none = vec![false; reference.len()];
    assert!(agreement(&none, &reference) < 0.85);
    for mode in ["standard", "reversed", "msaa"] {
        let (pixels, depth_unchanged) = host_frame(mode);
        let agree = agreement(&cloud_mask(&pixels, &clear), &reference);
        eprintln!("{mode}: clouds agree on {agree:.4} of the pixels");
        assert!(
            agree >= 0.95,
            "{mode}: clouds agree on {agree:.3} of the pixels"
        );
        // The sky never writes the host's depth: byte for byte the same after it recorded, every
        // sample of a multisampled one.
        assert!(depth_unchanged, "{mode}: the sky changed the host's depth");
    }
}

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
    demo.sky
        .sky_mut()
        .set_weather_overhead(&world.weather_over(position));
    let sun = sun_position(host::UNIX_S, host::AT.0, host::AT.1);
    let (clear, _) = demo.frame(&camera, &sun, 0.0, 40_000.0).expect("frame");
    demo.sky
        .sky_mut()
        .set_clouds(world.sky_blocks_around(position));
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
    h.draw_sky(&mut sky).expect("sky");
    // The host read the air where it is (250/8 kt at the surface, 24 C): above the boundary
    // layer, veered 30 degrees and cooler.
    let air = h
        .air
        .as_ref()
        .expect("the host reads the air data each frame");
    assert!(
        (air.wind_from_deg - 280.0).abs() < 1.0 && air.temperature_c < 24.0,
        "{mode}: {air:?}"
    );
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

/// Real reports of 2025-01-27 around 22Z, one a line, as a host would have them: Los Angeles
/// stations (in NOAA's table) and three that are not in it (placed only by a file that gives
/// positions).
const LOS_ANGELES: &str =
    "KLAX 272153Z 26008KT 10SM FEW025 FEW060 SCT160 SCT250 14/07 A3008 RMK AO2 SLP187 T01390067
KBUR 272153Z 17004KT 10SM BKN085 13/03 A3006 RMK AO2 SLP174 T01330028
KVNY 272151Z VRB05KT 10SM SCT055 BKN085 15/01 A3005 RMK AO2 SLP174 T01500006
KLGB 272153Z VRB03KT 10SM SCT040 14/05 A3007 RMK AO2 SLP180 T01440050
KSMO 272151Z 24006KT 10SM FEW025 14/05 A3008 RMK AO2 SLP186 T01440050
";
const THREE_OF_FIVE_UNPLACED: &str =
    "KLAX 272153Z 26008KT 10SM FEW025 FEW060 SCT160 SCT250 14/07 A3008 RMK AO2 SLP187 T01390067
KIKT 272225Z AUTO VRB04KT 10SM SCT028 BKN033 OVC050 22/12 A3011 RMK A01
KBUR 272153Z 17004KT 10SM BKN085 13/03 A3006 RMK AO2 SLP174 T01330028
PFNO 272223Z AUTO 21005KT 1SM -SN BR SCT017 BKN023 OVC046 M18/M20 A2955 RMK AO2 P0000 FZRANO
PAMK 272222Z AUTO 27010KT 9SM FEW010 BKN038 OVC049 M18/M20 A2972 RMK AO2 SNE17 P00
";

/// The example's frame after `setup` gave its sky weather.
fn frame_with(setup: impl FnOnce(&mut skycast::SkySystem)) -> Vec<u8> {
    let mut h = host::Host::new("standard", None).expect("host");
    setup(&mut h.sky);
    h.frame().expect("frame")
}

#[test]
fn plain_metar_text_needs_no_station_file_and_says_what_it_skipped() {
    use skycast::Weather;
    use skycast::weather::WarningKind;
    let name = Path::new("metars.txt");
    let clear = frame_with(|_| {});
    let clouds = frame_with(|sky| {
        let skipped = sky
            .set_weather(Weather::Bytes {
                name,
                bytes: LOS_ANGELES.as_bytes(),
            })
            .expect("plain METAR text");
        assert_eq!((skipped.reports_found, skipped.reports_used), (5, 5));
        assert!(skipped.is_empty(), "{skipped}");
    });
    // The reports placed by the built-in table give clouds: a good part of the sky above the
    // horizon differs from the same frame without weather.
    let cloud = cloud_mask(&clouds, &clear);
    let cover = cloud.iter().filter(|&&c| c).count() as f64 / cloud.len() as f64;
    assert!(cover > 0.05, "clouds on {cover:.3} of the sky");

    // Three reports the table cannot place: three warnings, by line and station, counted.
    let mut h = host::Host::new("standard", None).expect("host");
    let skipped = h
        .sky
        .set_weather(Weather::Bytes {
            name,
            bytes: THREE_OF_FIVE_UNPLACED.as_bytes(),
        })
        .expect("two usable reports");
    assert_eq!(skipped.reports_used, 2);
    assert_eq!(skipped.count(WarningKind::NoPosition), 3, "{skipped}");
    let lines: Vec<usize> = skipped.warnings.iter().map(|w| w.line).collect();
    assert_eq!(lines, [2, 4, 5]);
    for (w, station) in skipped.warnings.iter().zip(["KIKT", "PFNO", "PAMK"]) {
        assert!(w.message.starts_with(station), "{w}");
    }
    assert_eq!(
        skipped.to_string(),
        "3 reports without a position, lines 2, 4 and 5"
    );
    assert_eq!(h.sky.weather_skipped(), &skipped);

    // No usable report is an error, not an empty sky; garbage bytes too.
    let unplaced: String = THREE_OF_FIVE_UNPLACED
        .lines()
        .filter(|l| !l.starts_with("KLAX") && !l.starts_with("KBUR"))
        .map(|l| format!("{l}\n"))
        .collect();
    let err = h
        .sky
        .set_weather(Weather::Bytes {
            name,
            bytes: unplaced.as_bytes(),
        })
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no usable report") && err.contains("3 reports without a position"),
        "{err}"
    );
    let garbage: Vec<u8> = (0..600u32).map(|k| (k * 7919 % 251) as u8 + 1).collect();
    let err = h
        .sky
        .set_weather(Weather::Bytes {
            name,
            bytes: &garbage,
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("not a weather file"), "{err}");
    // The last good weather stays.
    assert_eq!(h.sky.weather_skipped(), &skipped);
}

/// A texture of the example's size on its device.
fn texture(
    h: &host::Host,
    format: wgpu::TextureFormat,
    samples: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    h.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: host::W,
            height: host::H,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

const COLOUR: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT;
const DEPTH: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::TEXTURE_BINDING);

/// The example host in `mode` updated, then recording into `colour` and `depth`, which do not
/// match its targets: the sky's error, after the encoder was finished and submitted (nothing
/// in it for wgpu's validation to panic on).
fn refused(h: &mut host::Host, colour: &wgpu::Texture, depth: &wgpu::Texture) -> String {
    h.sky
        .update(&h.queue, &h.camera, host::UNIX_S, 0.0)
        .expect("the example's own camera");
    let mut encoder = h.device.create_command_encoder(&Default::default());
    let (colour, depth) = (
        colour.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let err = h.sky.record(&mut encoder, &colour, &depth).unwrap_err();
    h.queue.submit([encoder.finish()]);
    h.device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    err.to_string()
}

#[test]
fn a_projection_against_the_reversed_flag_is_refused_naming_both() {
    let fov = 50f32.to_radians();
    let aspect = host::W as f32 / host::H as f32;
    let standard = glam::camera::rh::proj::directx::perspective(fov, aspect, 1.0, 300_000.0);
    let reversed = glam::camera::rh::proj::directx::perspective_infinite_reverse(fov, aspect, 1.0);
    for (mode, wrong) in [("standard", reversed), ("reversed", standard)] {
        let mut h = host::Host::new(mode, None).expect(mode);
        let camera = skycast::HostCamera {
            projection: wrong,
            ..h.camera
        };
        let err = h
            .sky
            .update(&h.queue, &camera, host::UNIX_S, 0.0)
            .unwrap_err()
            .to_string();
        let flag = format!("reversed_z is {}", mode == "reversed");
        assert!(
            err.contains(&flag) && err.contains("but the projection is"),
            "{mode}: {err}"
        );
        // The host's own projection still draws.
        h.frame().expect("the right projection");
    }
}

#[test]
fn a_depth_without_texture_binding_is_refused() {
    let mut h = host::Host::new("standard", None).expect("host");
    let depth = texture(
        &h,
        h.targets.depth_format,
        1,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let colour = texture(&h, h.targets.colour_format, 1, COLOUR);
    let err = refused(&mut h, &colour, &depth);
    assert!(err.contains("without TEXTURE_BINDING"), "{err}");
}

#[test]
fn textures_of_another_sample_count_are_refused() {
    // Targets of 4 samples, textures of 1.
    let mut h = host::Host::new("msaa", None).expect("host");
    let colour = texture(&h, h.targets.colour_format, 1, COLOUR);
    let depth = texture(&h, h.targets.depth_format, 1, DEPTH);
    let err = refused(&mut h, &colour, &depth);
    assert!(
        err.contains("1 sample(s) a pixel but HostTargets::sample_count is 4"),
        "{err}"
    );
}

#[test]
fn a_colour_target_of_another_format_is_refused() {
    let mut h = host::Host::new("standard", None).expect("host");
    let colour = texture(&h, wgpu::TextureFormat::Bgra8UnormSrgb, 1, COLOUR);
    let depth = texture(&h, h.targets.depth_format, 1, DEPTH);
    let err = refused(&mut h, &colour, &depth);
    assert!(
        err.contains("Bgra8UnormSrgb") && err.contains("Rgba8UnormSrgb"),
        "{err}"
    );
}

#[test]
fn the_sky_system_counts_its_recording_in_the_frame_cpu() {
    let mut h = host::Host::new("standard", Some(Path::new(host::THEME))).expect("host");
    let mut records = Vec::new();
    let mut stats = Vec::new();
    for _ in 0..2 {
        stats.push(h.update().expect("update"));
        let mut encoder = h.device.create_command_encoder(&Default::default());
        h.draw_ground(&mut encoder);
        h.draw_sky(&mut encoder).expect("sky");
        records.push(h.sky.last_record());
        h.queue.submit([encoder.finish()]);
    }
    // Through `update` the recording counted is the previous frame's, on both clocks.
    assert!(records[0].wall_us > 0);
    assert_eq!(stats[1].record_us, records[0].wall_us);
    assert_eq!(stats[1].thread.record_us, records[0].thread_us);
    let s = &stats[1];
    assert_eq!(s.sky_cpu_us(), s.field_us + s.cpu_update_us + s.record_us);
    let t = &s.thread;
    assert_eq!(s.sky_thread_us(), t.field_us + t.update_us + t.record_us);
    // The thread's own clock is read (Linux has one): the update computes for well over a
    // microsecond, and the computing fits in the wall time (a microsecond of rounding a span).
    // The recording is one span; the field is a span less the sky's work inside it, which the
    // update counts, so only the two together are one span's worth (less any GPU wait: a core
    // taken during the wait or the sky's part moves wall time between them, not thread time).
    if cfg!(target_os = "linux") {
        assert!(t.update_us > 0 && records[0].thread_us > 0, "{s:?}");
    }
    assert!(t.record_us <= s.record_us + 1, "{s:?}");
    if s.gpu_wait_us == 0 {
        assert!(
            t.field_us + t.update_us <= s.field_us + s.cpu_update_us + 2,
            "{s:?}"
        );
    }
}

/// Cloud pixels above the horizon, as a fraction.
fn cover(frame: &[u8], clear: &[u8]) -> f64 {
    let mask = cloud_mask(frame, clear);
    mask.iter().filter(|&&c| c).count() as f64 / mask.len() as f64
}

#[test]
fn the_first_frames_do_not_wait_and_clouds_fade_in_as_they_arrive() {
    // Every block drawn as sprites (no ring), so each one's own fade shows.
    let host_without_ring = |theme: bool| {
        let weather = theme.then(|| Path::new(host::THEME));
        let mut h = host::Host::new("standard", weather).expect("host");
        h.sky.sky_mut().set_impostors(false);
        h
    };
    let clear = host_without_ring(false).frame().expect("clear");
    // The warm-up (synchronous clouds): every block there in the first frame, whole.
    let mut warm = host_without_ring(true);
    let whole = warm.frame().expect("warm frame");
    let blocks = warm.sky.sky().block_ids().count();
    assert!(cover(&whole, &clear) > 0.2);

    // The default: the first update queues the blocks and returns; they come in over the next
    // updates (the frames' time standing still while they do, so none has faded in yet).
    let mut h = host_without_ring(true);
    h.sky.world_mut().set_synchronous_clouds(false);
    let mut updates = 0;
    while h.sky.sky().block_ids().count() < blocks {
        h.sky
            .update(&h.queue, &h.camera, host::UNIX_S, 0.0)
            .expect("update");
        updates += 1;
        assert!(
            updates < 3_000,
            "{} of {blocks} blocks came",
            h.sky.sky().block_ids().count()
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(updates > 1, "the first update waited for the clouds");
    let step = |h: &mut host::Host, dt_s: f64| {
        h.sky
            .update(&h.queue, &h.camera, host::UNIX_S, dt_s)
            .expect("update");
    };
    let arrived = h.frame().expect("frame");
    // A third of the way through their fade in, then past it.
    step(&mut h, 1.0);
    let fading = h.frame().expect("frame");
    step(&mut h, 3.0);
    let settled = h.frame().expect("frame");
    let covers = [&arrived, &fading, &settled].map(|f| cover(f, &clear));
    assert!(
        covers[0] < 0.02 && covers[1] > covers[0] + 0.05 && covers[2] > covers[1] + 0.05,
        "cloud cover as they arrive, fading in, settled: {covers:?}"
    );
    // Settled, the sky is the warm-up's, the warm-up's clouds drifted as far (the same four
    // seconds of the wind at their height: some 40 m, a few pixels of each cloud's edge).
    step(&mut warm, 1.0);
    step(&mut warm, 3.0);
    let whole = warm.frame().expect("warm frame");
    let agree = agreement(&cloud_mask(&settled, &clear), &cloud_mask(&whole, &clear));
    assert!(
        agree >= 0.97,
        "settled clouds agree with the warm-up's on {agree:.3}"
    );
}

/// Mean absolute difference of two RGBA8 frames' colour, 0..1.
fn mean_difference(a: &[u8], b: &[u8]) -> f64 {
    let sum: u64 = a
        .chunks(4)
        .zip(b.chunks(4))
        .map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c]) as u64).sum::<u64>())
        .sum();
    sum as f64 / (a.len() / 4 * 3) as f64 / 255.0
}

#[test]
fn two_views_recorded_into_one_encoder_each_show_their_own_clouds() {
    let mut h = host::Host::new("standard", Some(Path::new(host::THEME))).expect("host");
    let front_alone = h.frame().expect("front");
    let sky_bytes = h.sky.sky().gpu_buffer_bytes();
    // A second monitor from the same seat, looking back over the tail.
    let back = h.add_view(host::HEADING_DEG + 180.0, 8.0);
    let read = |h: &host::Host, encoder, texture: &wgpu::Texture| {
        host::read_back(&h.device, &h.queue, encoder, texture).expect("read back")
    };
    let encoder = |h: &host::Host| h.device.create_command_encoder(&Default::default());
    // Each view drawn alone, in a submission of its own.
    let mut e = encoder(&h);
    h.draw_view(&back, &mut e).expect("back");
    let back_alone = read(&h, e, &back.colour);
    // Both updated, then both recorded into one encoder, one submit.
    h.update().expect("update");
    let mut e = encoder(&h);
    h.draw_ground(&mut e);
    h.draw_sky(&mut e).expect("front");
    h.draw_view(&back, &mut e).expect("back");
    let front_both = read(&h, e, &h.colour);
    let back_both = read(&h, encoder(&h), &back.colour);
    // The two views show different skies: the comparison can tell them apart.
    let apart = mean_difference(&front_alone, &back_alone);
    assert!(apart > 0.05, "the views look alike: {apart:.4}");
    for (name, both, alone) in [
        ("front", &front_both, &front_alone),
        ("back", &back_both, &back_alone),
    ] {
        let d = mean_difference(both, alone);
        eprintln!("{name}: one encoder against alone, mean absolute difference {d:.5}");
        assert!(d < 0.01, "{name}: {d:.4}");
    }
    // What a view adds: its frame uniform, draw list, ring and cloud target, no more (the
    // resident sprites are the sky's: its buffers grew by the view's own at most).
    let bytes = h.sky.sky().view_gpu_bytes(back.id);
    let grown = h.sky.sky().gpu_buffer_bytes() - sky_bytes;
    eprintln!("a view adds {bytes} bytes of GPU memory; the sky's buffers grew by {grown}");
    assert!(bytes > 0 && grown <= bytes, "{grown} > {bytes}");
}

#[test]
fn the_host_drains_flashes_of_a_ts_theme_and_none_without_ts() {
    use skycast::Weather;
    use skycast::weather::storms::FlashKind;
    let theme = Path::new("weather/themes/thunderstorm_cells.toml");
    let mut h = host::Host::new("standard", Some(theme)).expect("host");
    let mut flashes = Vec::new();
    // Two minutes in 10 s frames, drained each frame as a host does.
    for _ in 0..12 {
        h.sky
            .update(&h.queue, &h.camera, host::UNIX_S, 10.0)
            .expect("update");
        flashes.extend(h.sky.drain_flashes());
    }
    let cells = h
        .sky
        .world()
        .living_field()
        .map_or(0, |f| f.cells().iter().filter(|c| c.thunder > 0).count());
    assert!(cells > 0, "the theme's TS cells");
    // At least one flash a minute per cell (the theme's TS: 4 a minute on average).
    assert!(
        flashes.len() >= 2 * cells,
        "{} flashes of {cells} cells in 2 minutes",
        flashes.len()
    );
    assert!(flashes.windows(2).all(|w| w[0].time_s <= w[1].time_s));
    assert!(flashes.iter().any(|f| f.kind == FlashKind::InCloud));
    assert!(h.sky.drain_flashes().is_empty(), "drained");
    // Weather without TS: the cells and their flashes go.
    h.sky
        .set_weather(Weather::File(Path::new(
            "weather/themes/fair_weather_cumulus.toml",
        )))
        .expect("weather");
    for _ in 0..12 {
        h.sky
            .update(&h.queue, &h.camera, host::UNIX_S, 10.0)
            .expect("update");
    }
    assert!(h.sky.drain_flashes().is_empty(), "no TS, no flash");
}

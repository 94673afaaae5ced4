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

/// The example's frame in `mode`, and whether the host's depth was the same after the sky
/// recorded (`None` for a multisampled depth, which cannot be copied).
fn host_frame(mode: &str) -> (Vec<u8>, Option<bool>) {
    let mut h = host::Host::new(mode, Some(Path::new(host::THEME))).expect(mode);
    let copyable = h.targets.sample_count == 1;
    let encoder = |h: &host::Host| h.device.create_command_encoder(&Default::default());
    let mut ground = encoder(&h);
    h.draw_ground(&mut ground);
    let before = if copyable {
        Some(host::read_back(&h.device, &h.queue, ground, &h.depth).expect("depth"))
    } else {
        h.queue.submit([ground.finish()]);
        None
    };
    let mut sky = encoder(&h);
    h.draw_sky(&mut sky).expect("sky");
    let after = if copyable {
        Some(host::read_back(&h.device, &h.queue, sky, &h.depth).expect("depth"))
    } else {
        h.queue.submit([sky.finish()]);
        None
    };
    let colour = if copyable { &h.colour } else { &h.resolved };
    let pixels = host::read_back(&h.device, &h.queue, encoder(&h), colour).expect("colour");
    (pixels, before.zip(after).map(|(b, a)| b == a))
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
        assert!(
            agree >= 0.95,
            "{mode}: clouds agree on {agree:.3} of the pixels"
        );
        // The sky never writes the host's depth: byte for byte the same after it recorded (a
        // multisampled depth cannot be copied; the same pipelines have no depth attachment).
        let expected = (mode != "msaa").then_some(true);
        assert_eq!(depth_unchanged, expected, "{mode}");
    }
}

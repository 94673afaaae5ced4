//! Memory stays flat however many frames are drawn: the demo host draws the fair-weather cumulus
//! theme frame after frame, and the process's resident memory after the warm-up frames is where
//! it is after many more. Its own test binary, so that no other test's allocations move the
//! process's memory while it measures.
//!
//! It catches a shader branch on a uniform: lavapipe (Mesa 22) specialises a shader on the values
//! of the uniforms that decide a branch as it runs a dispatch or draw, and here kept every copy;
//! the sprite build's `if` on the shading model grew the process by about 0.9 MB a frame, and
//! the far field's `if` on the camera's distance from the Earth's centre about 3.4 MB a frame
//! of a climb or descent (so the camera climbs here). A uniform can do it without a branch of
//! its own in the WGSL: the steady ring pass, reading the shown ring's camera-relative centre
//! from its uniform, was compiled afresh at every draw (about 0.55 MB a frame; its centre now
//! comes through the vertex stage, `impostor_quad.wgsl`).

#[path = "support/rss.rs"]
mod rss;

use rss::live_rss_bytes;

use std::path::Path;

use glam::{DVec2, DVec3};
use skycast::clouds::far_map::FarMapFeed;
use skycast::demo::{DemoHost, GroundSettings, demo_ground, headless};
use skycast::flight::world::{World, WorldSettings};
use skycast::render::{Camera, SkyConfig};
use skycast::shading::{ShadingModel, sun_position};
use skycast::weather::{CloudTypeRule, FieldSettings, LocalFrame, WeatherInput};

const THEME: &str = "weather/themes/fair_weather_cumulus.toml";
const AT: (f64, f64) = (28.5, -81.45);
/// 2025-01-27 19:00 UTC: early afternoon in Orlando.
const UNIX_S: f64 = 1_738_004_400.0;
const W: u32 = 96;
const H: u32 = 54;
/// Frames whose memory is sampled at the end of the warm-up and at the end.
const SAMPLES: u32 = 9;
/// The radius of the camera's circle, metres.
const RADIUS_M: f64 = 1_500.0;

/// Draws `warm_up` frames, then `frames` more, circling at 60 m a frame and climbing 5 m a
/// frame (a level flight hides a branch on the camera's height); returns the resident memory
/// over the last `SAMPLES` frames of the warm-up and over the last `SAMPLES` frames, bytes, each
/// the median of its frames. The warm-up holds the sky's one-time growth (about 22 MB between
/// frames 30 and 40: the ring's and the far field's first builds); the medians pass over the
/// frames that happen to hold a block's generation or a ring rebuild in flight (10-17 MB for a
/// frame or two, at times that vary from run to run), which a leak does not.
fn fly(model: ShadingModel, warm_up: u32, frames: u32) -> (u64, u64) {
    let input = WeatherInput::load(Path::new(THEME), None).expect("theme");
    let field = input.field(
        LocalFrame::new(AT.0, AT.1),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let mut world = World::new(field, &WorldSettings::default());
    let ground = demo_ground(world.field(), &GroundSettings::default());
    let mut config = SkyConfig::new(headless::TARGETS);
    config.time_of_day.shading.model = model;
    let far = config.settings.far_field;
    let mut demo = DemoHost::new(W, H, &ground, config).expect("demo host");
    // The far field's map, made once (the circle stays within one map's reach), so that its
    // pass is drawn every frame.
    let far_map = FarMapFeed::new(far.texels, far.texel_m, far.move_texels, 1)
        .update(DVec2::ZERO, true, world.far_map_cell())
        .expect("a first far map");
    demo.sky
        .sky_mut()
        .set_far_map(&demo.gpu.queue, &far_map, None);
    let sun = sun_position(UNIX_S, AT.0, AT.1);
    let (mut settled, mut late) = (Vec::new(), Vec::new());
    for k in 0..warm_up + frames {
        // A circle of 1.5 km at 60 m a frame: the camera moves and turns every frame, but over
        // the same blocks, so that nothing the sky rightly keeps (new blocks' clouds) grows.
        let turned = 60.0 * k as f64 / RADIUS_M;
        let position = DVec3::new(
            RADIUS_M * turned.sin(),
            RADIUS_M * (turned.cos() - 1.0),
            900.0 + 5.0 * k as f64,
        );
        let camera = Camera {
            position_m: position,
            heading_deg: 90.0 + turned.to_degrees(),
            pitch_deg: 6.0,
            fov_y_deg: 60.0,
            aspect: W as f32 / H as f32,
            near_m: 1.0,
            far_m: 160_000.0,
        };
        demo.sky
            .sky_mut()
            .set_weather_overhead(&world.weather_over(position));
        demo.sky
            .sky_mut()
            .set_clouds(world.sky_blocks_around(position));
        let (_, stats) = demo.frame(&camera, &sun, 0.1, 40_000.0).expect("frame");
        assert!(stats.sprites_drawn > 0, "frame {k} drew no cloud");
        assert!(
            demo.sky.sky().memory().far_field_bytes > 100_000,
            "frame {k} drew no far field"
        );
        if (warm_up - SAMPLES..warm_up).contains(&k) {
            settled.push(live_rss_bytes());
        } else if k + SAMPLES >= warm_up + frames {
            late.push(live_rss_bytes());
        }
    }
    (median(settled), median(late))
}

/// The median of `values` (at least one).
fn median(mut values: Vec<u64>) -> u64 {
    values.sort_unstable();
    values[values.len() / 2]
}

#[test]
fn drawing_frame_after_frame_does_not_grow_memory() {
    for model in [ShadingModel::Wang, ShadingModel::HarrisLastra] {
        let (settled, late) = fly(model, 60, 60);
        eprintln!(
            "{model:?}: RSS {:.1} MB at 60 frames, {:.1} MB 60 frames later (medians of {SAMPLES})",
            settled as f64 / 1e6,
            late as f64 / 1e6
        );
        // With the sprite build's branch on the uniform, 60 frames added 55 MB; with the far
        // field's, 214 MB.
        assert!(
            late <= settled + (16 << 20),
            "{model:?}: memory grew from {settled} to {late} bytes in 60 frames"
        );
    }
}

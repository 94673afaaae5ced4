//! The sky's CPU share of a frame along the shipped cruise flight through the real bulk weather
//! (Wang 2003 6.1 on GPU-resident sprites): `Sky::prepare` (sort blocks and clouds, the cached
//! per-cloud sprite orders, the draw list, the uploads of what changed) and `Sky::record` (the
//! passes into an encoder, not submitted), with and without the order cache. The sprites whose
//! order was recomputed and the bytes uploaded per frame are printed too (independent of the
//! machine). `sort_back_to_front/cruise_frame`: every cloud's sprites sorted from one camera
//! (what a frame without the cache sorts).
//!
//! Needs a graphics adapter (lavapipe is enough): the sprites live in GPU buffers.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use skycast::demo::{DemoHost, headless};
use skycast::flight::FlightPlan;
use skycast::flight::world::{World, WorldSettings};
use skycast::render::draw_list::sprites_back_to_front;
use skycast::render::{Camera, SkyBlock, SkyConfig};
use skycast::shading::{SunPosition, TimeOfDayTable, sun_position};
use skycast::weather::field::{CloudTypeRule, FieldSettings, WeatherField};
use skycast::weather::{LocalFrame, StationTable, files};

const FPS: f64 = 30.0;
const FRAMES: usize = 90;
/// Under `cargo test --all-targets` (no `--bench` flag) the bench runs once as a smoke test on a
/// few frames; the full stretch is for `cargo bench`.
const SMOKE_FRAMES: usize = 3;

fn frames() -> usize {
    if std::env::args().any(|a| a == "--bench") {
        FRAMES
    } else {
        SMOKE_FRAMES
    }
}

struct Cruise {
    host: DemoHost,
    blocks: Vec<SkyBlock>,
    cameras: Vec<Camera>,
    sun: SunPosition,
}

fn cruise() -> Cruise {
    let plan = FlightPlan::load(Path::new("config/flights/cruise_scattered_cumulus.toml"))
        .expect("flight");
    let (lat, lon) = plan.origin_lat_lon_deg;
    let flight = plan.place(&LocalFrame::new(lat, lon));
    let table = StationTable::load(Path::new("weather/nsd_cccc.txt")).expect("stations");
    let file = files::load(
        Path::new("weather/awc-metars-2025-01-27T22Z.cache.csv"),
        Some(&table),
    )
    .expect("weather");
    let field = WeatherField::build(
        LocalFrame::new(lat, lon),
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let mut world = World::new(field, &WorldSettings::default());
    let mut host = DemoHost::new(
        32,
        18,
        &skycast::demo::demo_ground(world.field(), &Default::default()),
        SkyConfig {
            targets: headless::TARGETS,
            settings: Default::default(),
            time_of_day: TimeOfDayTable::default(),
            sheet: world.sheet(),
        },
    )
    .expect("the frame update bench needs a graphics adapter (lavapipe is enough)");
    // A stretch of the cruise 60 s in, at 30 frames a second.
    let cameras: Vec<Camera> = (0..frames())
        .map(|k| {
            let pose = flight.pose_at(60.0 + k as f64 / FPS);
            host.camera(pose.position_m, pose.heading_deg, pose.pitch_deg)
        })
        .collect();
    let blocks = world.sky_blocks_around(cameras[0].position_m);
    host.sky.sky_mut().set_clouds(blocks.clone());
    Cruise {
        host,
        blocks,
        cameras,
        sun: sun_position(1_738_015_200.0 + 60.0, lat, lon),
    }
}

/// Prepares and records every frame of the stretch (nothing submitted; the writes are flushed
/// at the end); returns the sprites recomputed, the sprites drawn and the bytes uploaded.
fn run(c: &mut Cruise, cache: bool) -> (u64, u64, u64) {
    c.host.sky.sky_mut().set_vertex_cache(cache);
    let (mut recomputed, mut drawn, mut uploaded) = (0u64, 0u64, 0u64);
    for camera in &c.cameras {
        let stats = c
            .host
            .sky
            .sky_mut()
            .prepare(&c.host.gpu.queue, camera, &c.sun, 1.0 / FPS);
        let mut encoder = c
            .host
            .gpu
            .device
            .create_command_encoder(&Default::default());
        // The demo host's own targets: they match the sky's.
        c.host
            .sky
            .record(
                &mut encoder,
                &c.host.target.colour_view,
                &c.host.target.depth_view,
            )
            .expect("the demo host's targets");
        recomputed += stats.sprites_recomputed as u64;
        drawn += stats.sprites_drawn as u64;
        uploaded += stats.upload_bytes;
    }
    c.host.gpu.queue.submit([]);
    (recomputed, drawn, uploaded)
}

/// Every cloud's sprites sorted back to front from `camera_m`; returns the sprites sorted.
fn sort_frame(blocks: &[SkyBlock], camera_m: glam::DVec3) -> usize {
    blocks
        .iter()
        .flat_map(|b| &b.clouds)
        .map(|cloud| sprites_back_to_front(cloud, (camera_m - cloud.centre_m).as_vec3()).len())
        .sum()
}

fn bench(crit: &mut Criterion) {
    let mut c = cruise();
    // The first frame uploads every block and builds the whole impostor ring: not a steady one.
    run(&mut c, true);
    let (with, drawn, uploaded) = run(&mut c, true);
    let (without, _, _) = run(&mut c, false);
    let n = c.cameras.len() as u64;
    eprintln!(
        "cruise, {n} frames at {FPS} fps: {} clouds, {} sprites drawn a frame; sprites re-sorted {with} cached vs {without} uncached ({:.1}x less sorting); {} bytes uploaded a frame",
        c.blocks.iter().map(|b| b.clouds.len()).sum::<usize>(),
        drawn / n,
        without as f64 / with.max(1) as f64,
        uploaded / n,
    );
    let mut group = crit.benchmark_group("sky_cpu_frame_cruise");
    group.sample_size(10);
    group.bench_function("cached", |b| b.iter(|| run(&mut c, true)));
    group.bench_function("uncached", |b| b.iter(|| run(&mut c, false)));
    group.finish();
    let camera = c.cameras[0].position_m;
    let sprites = sort_frame(&c.blocks, camera);
    eprintln!(
        "sort: {sprites} sprites of {} blocks a frame",
        c.blocks.len()
    );
    let mut group = crit.benchmark_group("sort_back_to_front");
    group.sample_size(10);
    group.bench_function("cruise_frame", |b| {
        b.iter(|| sort_frame(std::hint::black_box(&c.blocks), camera))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! The CPU frame update of the sky (sort, face, shade the sprites; Wang 2003 6.1) along the
//! shipped cruise flight through the real bulk weather, with and without the vertex cache.
//! The ratio of the two is the README's cache figure; the sprites recomputed per frame are
//! printed too (vertex work, independent of the machine). `sort_back_to_front/cruise_frame`: the
//! back-to-front sort alone, for one frame of the same stretch: blocks by distance, then every
//! cloud's sprites (what an uncached frame sorts; the cache skips the sprite level for clouds it
//! keeps).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use skycast::flight::FlightPlan;
use skycast::render::vertices::{
    Lighting, SpriteVertexBuilder, blocks_back_to_front, sprites_back_to_front,
};
use skycast::render::world::{World, WorldSettings};
use skycast::render::{RenderSettings, SkyBlock};
use skycast::shading::{TimeOfDayTable, sun_position};
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
    blocks: Vec<SkyBlock>,
    cameras: Vec<glam::DVec3>,
    lighting: Lighting,
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
    // A stretch of the cruise 60 s in, at 30 frames a second.
    let cameras: Vec<glam::DVec3> = (0..frames())
        .map(|k| flight.pose_at(60.0 + k as f64 / FPS).position_m)
        .collect();
    let blocks = world.sky_blocks_around(cameras[0]);
    let table = TimeOfDayTable::default();
    let sun = sun_position(1_738_015_200.0 + 60.0, lat, lon);
    let lighting = Lighting {
        sun_dir: sun.direction_enu().as_vec3(),
        time_of_day: table.at(sun.elevation_deg as f32),
        mapping: table.directional_mapping,
        forward: table.forward_scattering,
    };
    Cruise {
        blocks,
        cameras,
        lighting,
    }
}

fn run(c: &Cruise, settings: &RenderSettings) -> (u64, u64) {
    let mut builder = SpriteVertexBuilder::new();
    let (mut sprites_recomputed, mut sprites_drawn) = (0u64, 0u64);
    for (k, cam) in c.cameras.iter().enumerate() {
        let stats = builder.update(&c.blocks, *cam, k as f64 / FPS, &c.lighting, settings);
        sprites_recomputed += stats.sprites_recomputed as u64;
        sprites_drawn += stats.sprites_drawn as u64;
    }
    (sprites_recomputed, sprites_drawn)
}

/// The frame's back-to-front sort from `camera_m`: blocks, then each cloud's sprites; returns
/// the sprites sorted.
fn sort_frame(blocks: &[SkyBlock], camera_m: glam::DVec3) -> usize {
    let mut sorted = 0;
    for (bi, _) in blocks_back_to_front(blocks, camera_m) {
        for cloud in &blocks[bi].clouds {
            let cam_local = (camera_m - cloud.centre_m).as_vec3();
            sorted += sprites_back_to_front(cloud, cam_local).len();
        }
    }
    sorted
}

fn bench(crit: &mut Criterion) {
    let c = cruise();
    let cached = RenderSettings::default();
    let mut uncached = cached;
    uncached.vertex_cache.enabled = false;
    let (with, drawn) = run(&c, &cached);
    let (without, _) = run(&c, &uncached);
    eprintln!(
        "cruise, {} frames at {FPS} fps: {} clouds, {drawn} sprites drawn; sprites recomputed {with} cached vs {without} uncached ({:.1}x less vertex work)",
        c.cameras.len(),
        c.blocks.iter().map(|b| b.clouds.len()).sum::<usize>(),
        without as f64 / with.max(1) as f64
    );
    let mut group = crit.benchmark_group("sky_cpu_update_cruise");
    group.sample_size(10);
    group.bench_function("cached", |b| b.iter(|| run(&c, &cached)));
    group.bench_function("uncached", |b| b.iter(|| run(&c, &uncached)));
    group.finish();
    let sprites = sort_frame(&c.blocks, c.cameras[0]);
    eprintln!(
        "sort: {sprites} sprites of {} blocks a frame",
        c.blocks.len()
    );
    let mut group = crit.benchmark_group("sort_back_to_front");
    group.sample_size(10);
    group.bench_function("cruise_frame", |b| {
        b.iter(|| sort_frame(std::hint::black_box(&c.blocks), c.cameras[0]))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

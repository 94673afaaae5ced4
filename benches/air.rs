//! What a simulator asks the sky every frame (issue 33, Done means 5): the air data at the
//! aircraft (`World::air_at`) and 64 lines of sight of 10 km (16 headings, 4 pitches from -10 to
//! +20 degrees, as `skycast fly` casts them), on three shipped flights' weather with the living
//! clouds generated around the aircraft:
//! - `air/cruise_scattered_cumulus`: the real bulk METARs off Los Angeles, 5,500 ft in
//!   FEW025-SCT040 cumulus;
//! - `air/approach_overcast`: the real bulk METARs at San Antonio, in and above the OVC020 deck;
//! - `air/cumulonimbus_circle`: the `thunderstorm_cells` theme, 2,000 ft around a storm.
//!
//! Each is timed at a few points along its flight (one sample = every point once). The
//! `sight_fan_64_cold` figures time the same fans after each point's caches were flushed
//! ([`EVICT_BYTES`] written first, untimed), as a frame finds them after the renderer's work:
//! the flights' `air_thread_us` follow these more than the warm ones.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use skycast::flight::FlightPlan;
use skycast::flight::world::{World, WorldSettings};
use skycast::weather::field::{CloudTypeRule, FieldSettings};
use skycast::weather::{LocalFrame, StationTable, WeatherInput};

/// Times along each flight the aircraft is asked about, seconds from its start.
const TIMES_S: [f64; 4] = [20.0, 60.0, 100.0, 140.0];

/// A flight's weather with its clouds generated around the points asked about.
struct Scene {
    name: &'static str,
    world: World,
    /// Aircraft positions and headings, local metres and degrees.
    poses: Vec<(DVec3, f64)>,
}

fn scene(name: &'static str, weather: &str) -> Scene {
    let plan = FlightPlan::load(Path::new(&format!("config/flights/{name}.toml"))).expect("flight");
    let (lat, lon) = plan.origin_lat_lon_deg;
    let frame = LocalFrame::new(lat, lon);
    let flight = plan.place(&frame);
    let table = StationTable::load(Path::new("weather/nsd_cccc.txt")).expect("stations");
    let input = WeatherInput::load(Path::new(weather), Some(&table)).expect("weather");
    let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
    let mut world = World::new(
        field,
        &WorldSettings {
            cloud_radius_m: 16_000.0,
            ..WorldSettings::default()
        },
    );
    let poses: Vec<(DVec3, f64)> = TIMES_S
        .iter()
        .map(|&t| {
            let p = flight.pose_at(flight.start_s() + t);
            (p.position_m, p.heading_deg)
        })
        .collect();
    world
        .settle_clouds_around(poses[1].0)
        .expect("the living clouds");
    Scene { name, world, poses }
}

/// 64 lines of sight of 10 km from `at_m`; how many met a cloud.
fn sight_fan(world: &World, at_m: DVec3, heading_deg: f64) -> usize {
    (0..64)
        .filter(|k| {
            let heading = (heading_deg + (k % 16) as f64 * 22.5).to_radians();
            let pitch = (-10.0 + (k / 16) as f64 * 10.0_f64).to_radians();
            let dir = DVec3::new(
                heading.sin() * pitch.cos(),
                heading.cos() * pitch.cos(),
                pitch.sin(),
            );
            world.first_cloud(at_m, at_m + dir * 10_000.0).is_some()
        })
        .count()
}

/// Bytes written between two cold fans: more than a core's L2 cache (2 MiB on the build
/// machine), about what a frame's rendering leaves of the air data's lines.
const EVICT_BYTES: usize = 8 << 20;

/// Writes every cache line of `buffer` (the previous fan's lines leave the core's caches).
fn evict(buffer: &mut [u8], round: u8) {
    for line in buffer.chunks_mut(64) {
        line[0] = line[0].wrapping_add(round);
    }
    black_box(&buffer[..]);
}

fn bench(c: &mut Criterion) {
    const REAL: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";
    let sun = DVec3::new(0.3, -0.5, 0.8).normalize();
    let scenes = [
        scene("cruise_scattered_cumulus", REAL),
        scene("approach_overcast", REAL),
        scene(
            "cumulonimbus_circle",
            "weather/themes/thunderstorm_cells.toml",
        ),
    ];
    let mut group = c.benchmark_group("air");
    group.sample_size(20);
    for s in &scenes {
        let hits: usize = s
            .poses
            .iter()
            .map(|&(p, h)| sight_fan(&s.world, p, h))
            .sum();
        eprintln!(
            "{}: {hits} of {} lines of sight meet a cloud",
            s.name,
            64 * s.poses.len()
        );
        group.bench_function(format!("{}/air_at", s.name), |b| {
            b.iter(|| {
                for &(p, _) in &s.poses {
                    black_box(s.world.air_at(black_box(p), sun));
                }
            })
        });
        group.bench_function(format!("{}/sight_fan_64", s.name), |b| {
            b.iter(|| {
                for &(p, h) in &s.poses {
                    black_box(sight_fan(&s.world, black_box(p), h));
                }
            })
        });
        let mut buffer = vec![0u8; EVICT_BYTES];
        group.bench_function(format!("{}/sight_fan_64_cold", s.name), |b| {
            b.iter_custom(|iters| {
                let mut spent = Duration::ZERO;
                for round in 0..iters {
                    for &(p, h) in &s.poses {
                        evict(&mut buffer, round as u8 | 1);
                        let start = Instant::now();
                        black_box(sight_fan(&s.world, black_box(p), h));
                        spent += start.elapsed();
                    }
                }
                spent
            })
        });
    }
    group.finish();
}

criterion_group!(air, bench);
criterion_main!(air);

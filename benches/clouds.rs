//! The clouds stage's speed (goals from the issue, measured on whatever machine runs it):
//! - `clouds/overcast_block`: one overcast stratus block (the paper's 475 % scenario), goal < 1 ms;
//! - `clouds/radius_100km_parallel`: the ~2,000 blocks within 100 km, mixed weather, on every
//!   core with rayon, goal < 2 s; `clouds/radius_100km_one_thread` for the ratio;
//! - `clouds/field_background_fill`: the same 2,000 blocks through `BlockGenerator` (a pool of
//!   its own) while the caller polls without waiting, counting the polls it made meanwhile.

use std::hint::black_box;
use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;
use skycast::clouds::field::{BlockGenerator, blocks_within, generate_blocks};
use skycast::clouds::{CloudTypes, generate_block};
use skycast::weather::{BlockIndex, BlockLayer, BlockWeather, CloudType, TypeSource};

fn layer(cloud_type: CloudType, oktas: f32, base_ft: f32, thickness_ft: f32) -> BlockLayer {
    BlockLayer {
        cloud_type,
        type_source: TypeSource::HeightRule,
        coverage_oktas: oktas,
        base_ft_agl: base_ft,
        thickness_ft,
    }
}

fn weather(layers: Vec<BlockLayer>) -> BlockWeather {
    BlockWeather {
        layers,
        visibility_m: 9999.0,
        ..Default::default()
    }
}

/// A mixed sky that changes across the 100 km disc: sparse cumulus, scattered cumulus under
/// altocumulus, and an overcast stratus deck under cirrus.
fn mixed(index: BlockIndex) -> BlockWeather {
    match (index.i + index.j).rem_euclid(3) {
        0 => weather(vec![layer(CloudType::CumulusHumilis, 2.0, 3600.0, 1000.0)]),
        1 => weather(vec![
            layer(CloudType::CumulusMediocris, 4.0, 3800.0, 3000.0),
            layer(CloudType::Altocumulus, 3.0, 12000.0, 1500.0),
        ]),
        _ => weather(vec![
            layer(CloudType::Stratus, 8.0, 800.0, 1500.0),
            layer(CloudType::Cirrus, 3.0, 28000.0, 800.0),
        ]),
    }
}

fn benches(c: &mut Criterion) {
    let types = Arc::new(CloudTypes::builtin());
    let overcast = weather(vec![layer(CloudType::Stratus, 8.0, 800.0, 1500.0)]);
    c.bench_function("clouds/overcast_block", |b| {
        b.iter(|| generate_block(black_box(BlockIndex::new(7, -3)), &overcast, 2003, &types))
    });

    let jobs: Vec<(BlockIndex, BlockWeather)> = blocks_within(DVec2::ZERO, 100_000.0)
        .into_iter()
        .map(|i| (i, mixed(i)))
        .collect();
    eprintln!("{} blocks within 100 km", jobs.len());
    let mut group = c.benchmark_group("clouds");
    group.sample_size(10);
    group.bench_function("radius_100km_parallel", |b| {
        b.iter(|| generate_blocks(black_box(&jobs), 2003, &types))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    group.bench_function("radius_100km_one_thread", |b| {
        b.iter(|| one.install(|| generate_blocks(black_box(&jobs), 2003, &types)))
    });
    let mut generator = BlockGenerator::new(Arc::clone(&types), 0).unwrap();
    let mut polls_per_fill = Vec::new();
    group.bench_function("field_background_fill", |b| {
        b.iter(|| {
            for (index, w) in &jobs {
                generator.submit(*index, w.clone(), 2003);
            }
            // The caller's "frames": poll without waiting until everything has arrived.
            let (mut got, mut polls) = (0, 0u64);
            while got < jobs.len() {
                got += generator.poll().len();
                polls += 1;
                std::thread::yield_now();
            }
            polls_per_fill.push(polls);
        })
    });
    group.finish();
    if let Some(min) = polls_per_fill.iter().min() {
        eprintln!("the caller polled at least {min} times while a fill ran (never blocked)");
    }
}

criterion_group!(clouds, benches);
criterion_main!(clouds);

//! What an instrument measures agrees with what is drawn, on the real bulk file: the cover that
//! vertical lines of sight see from below a layer is the cover of its sprites' dense cores.

use std::path::Path;

use glam::{DVec2, DVec3};

use crate::clouds::block::LayerSummary;
use crate::clouds::core::SpriteCore;
use crate::flight::{World, WorldSettings};
use crate::weather::field::{CloudTypeRule, FieldSettings};
use crate::weather::{BLOCK_SIZE_M, BlockIndex, CloudType, LocalFrame, WeatherInput};

const REAL: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";

/// Cells a side of the grid the cover is measured on over a block (100 m).
const CELLS: usize = 40;

/// The cell centres of block (0, 0), ground metres.
fn cell_centres() -> impl Iterator<Item = DVec2> {
    let step = BLOCK_SIZE_M / CELLS as f64;
    (0..CELLS * CELLS)
        .map(move |k| DVec2::new((k % CELLS) as f64 + 0.5, (k / CELLS) as f64 + 0.5) * step)
}

/// The share of block (0, 0) under the dense cores of the sprites of the layer `layer` of the
/// generation there (its clouds and those of the neighbours' same layer, which overhang): the
/// cover the drawn sprites show a person looking up.
fn drawn_cover(world: &World, layer: &LayerSummary) -> f64 {
    let field = world.living_field().expect("living clouds");
    let drift = field.drift_m();
    let mut cores: Vec<(DVec3, SpriteCore)> = Vec::new();
    for (_, g) in field.blocks() {
        // The same layer in a neighbour (its base a little off where the weather varies).
        let same = |l: &LayerSummary| {
            l.cloud_type == layer.cloud_type && l.base_m < layer.top_m && l.top_m > layer.base_m
        };
        for c in &g.block.clouds {
            if g.block.layers.get(usize::from(c.layer)).is_some_and(same) {
                let centre = c.centre_m + drift.extend(0.0);
                cores.extend(crate::clouds::core::cores(c).map(|k| (centre, k)));
            }
        }
    }
    let covered = cell_centres()
        .filter(|p| {
            cores.iter().any(|(centre, k)| {
                // The core's horizontal section through its centre.
                let at = (*p - centre.truncate()).extend(k.centre_m.z);
                k.radius(at) < 1.0
            })
        })
        .count();
    covered as f64 / (CELLS * CELLS) as f64
}

/// The share of block (0, 0) where a vertical line of sight from under the layer to over it
/// meets cloud: the cover the probes (`line_of_sight`, `in_cloud`) report.
fn probed_cover(world: &World, layer: &LayerSummary) -> f64 {
    let (lo, hi) = (
        f64::from(layer.base_m) - 30.0,
        f64::from(layer.top_m) + 30.0,
    );
    let hits = cell_centres()
        .filter(|p| world.first_cloud(p.extend(lo), p.extend(hi)).is_some())
        .count();
    hits as f64 / (CELLS * CELLS) as f64
}

/// Probes equal drawing: at 50 station blocks each of about 2, 4 and 6 oktas (several types)
/// on the real bulk file, the lowest layer's cover seen by vertical lines of sight is the cover
/// of its sprites' cores within 0.03 (the cores' union is what the probes ask; one box a
/// cloud read 0.33, 0.70 and 0.88 where the sprites covered 0.25, 0.51 and 0.76).
#[test]
fn the_cover_probes_see_from_below_is_the_cover_drawn() {
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    let settings = WorldSettings {
        cloud_radius_m: 5_000.0,
        ..WorldSettings::default()
    };
    // Per class (2, 4, 6 oktas): blocks measured, the worst difference, the sums, the types.
    let mut classes: [(usize, f64, f64, f64, Vec<CloudType>); 3] = Default::default();
    let mut seen = std::collections::HashSet::new();
    for report in file.reports.iter().step_by(3) {
        if classes.iter().all(|c| c.0 >= 50) {
            break;
        }
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        if !seen.insert(((lat * 10.0) as i64, (lon * 10.0) as i64)) {
            continue;
        }
        let frame = LocalFrame::new(lat, lon);
        let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
        let weather = field.block_weather(BlockIndex::new(0, 0));
        let Some(lowest) = weather.layers.first() else {
            continue;
        };
        let class = ((lowest.coverage_oktas - 2.0) / 2.0).round();
        if (lowest.coverage_oktas - (2.0 + 2.0 * class)).abs() > 0.5
            || !(0.0..=2.0).contains(&class)
        {
            continue;
        }
        let class = class as usize;
        if classes[class].0 >= 50 || lowest.cloud_type == CloudType::Cumulonimbus {
            continue;
        }
        let mut world = World::new(field, &settings);
        world
            .settle_clouds_around(DVec3::new(2_000.0, 2_000.0, 0.0))
            .expect("clouds");
        let g = world
            .living_field()
            .and_then(|f| f.generations(BlockIndex::new(0, 0)).first())
            .expect("the station's block");
        let Some(layer) = g.block.layers.first().copied() else {
            continue;
        };
        // Another layer reaching into this one's heights would be seen by the same lines.
        let apart = g.block.layers[1..]
            .iter()
            .all(|l| l.base_m > layer.top_m + 60.0 || l.top_m < layer.base_m - 60.0);
        if !apart {
            continue;
        }
        let (drawn, probed) = (drawn_cover(&world, &layer), probed_cover(&world, &layer));
        let c = &mut classes[class];
        c.0 += 1;
        c.1 = c.1.max((probed - drawn).abs());
        c.2 += drawn;
        c.3 += probed;
        if !c.4.contains(&layer.cloud_type) {
            c.4.push(layer.cloud_type);
        }
    }
    for (k, (n, worst, drawn, probed, types)) in classes.iter().enumerate() {
        let oktas = 2 * k + 2;
        let (drawn, probed) = (drawn / *n as f64, probed / *n as f64);
        eprintln!(
            "{oktas} oktas: {n} blocks ({types:?}), drawn {drawn:.3}, probed {probed:.3}, worst block {worst:.3}"
        );
        assert!(*n >= 50, "{oktas} oktas: only {n} blocks");
        assert!(types.len() >= 2, "{oktas} oktas: {types:?}");
        assert!(
            (probed - drawn).abs() <= 0.03,
            "{oktas} oktas: {drawn} {probed}"
        );
        assert!(*worst <= 0.03, "{oktas} oktas: a block {worst} apart");
    }
}

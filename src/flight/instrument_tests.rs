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

/// Cells a side of the grid the cover is measured on over a block (133 m).
const CELLS: usize = 30;

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
    let everywhere = input.field(
        LocalFrame::new(0.0, 0.0),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let class_of = |oktas: f32| {
        let class = ((oktas - 2.0) / 2.0).round();
        ((oktas - (2.0 + 2.0 * class)).abs() <= 0.5 && (0.0..=2.0).contains(&class))
            .then_some(class as usize)
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
        // The station's weather read off one field first: a field of its own, around it, only
        // for the stations kept.
        let Some(lowest) = everywhere
            .weather_at_lat_lon(lat, lon)
            .layers
            .first()
            .copied()
        else {
            continue;
        };
        if class_of(lowest.coverage_oktas).is_none_or(|k| classes[k].0 >= 50) {
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

/// The first cloud a vertical line of sight meets from the ground at each cell of block (0, 0)
/// where it is of the lowest layer's type, metres above mean sea level (a column whose first
/// cloud is of a layer above, where the lowest has a gap, is that layer's).
fn first_hits(world: &World, layer: &LayerSummary, ground_m: f64) -> Vec<f64> {
    let top = f64::from(layer.top_m) + 30.0;
    cell_centres()
        .filter_map(|p| {
            world
                .first_cloud(p.extend(ground_m + 1.0), p.extend(top))
                .filter(|hit| hit.cloud_type == layer.cloud_type)
                .map(|hit| hit.point_m.z)
        })
        .collect()
}

/// The value at `q` (0..=1) of sorted `values`.
fn quantile(values: &[f64], q: f64) -> f64 {
    values[((values.len() - 1) as f64 * q).round() as usize]
}

/// The first cloud met going up from the ground under the base sprites of the storm cells within
/// 12 km of the station (their towers' flat undersides), where it is a cumulonimbus, metres above
/// mean sea level: under a storm's anvil the first cloud is the anvil, kilometres up, and the
/// base the report gives is the tower's.
fn first_hits_under_towers(world: &World, ground_m: f64) -> Vec<f64> {
    let field = world.living_field().expect("living clouds");
    let drift = field.drift_m().extend(0.0);
    let station = DVec2::splat(BLOCK_SIZE_M / 2.0);
    let mut hits = Vec::new();
    for (_, g) in field.blocks() {
        for c in &g.block.clouds {
            if c.cloud_type != CloudType::Cumulonimbus {
                continue;
            }
            for s in c.sprites.iter().filter(|s| s.base).step_by(3) {
                let p = (c.centre_m + drift).truncate()
                    + DVec2::new(f64::from(s.offset_m[0]), f64::from(s.offset_m[1]));
                if p.distance(station) > 12_000.0 {
                    continue;
                }
                let top = c.centre_m.z + 2_000.0;
                if let Some(hit) = world
                    .first_cloud(p.extend(ground_m + 1.0), p.extend(top))
                    .filter(|h| h.cloud_type == CloudType::Cumulonimbus)
                {
                    hits.push(hit.point_m.z);
                }
            }
        }
    }
    hits
}

/// Bases true by type: over the cloud-covered columns of station blocks whose lowest layer is of
/// each type (real reports of the bulk file, up to 6 stations a type), the first cloud of that
/// type met from the ground lies at the reported base: the median of its height over the base
/// within max(50 ft, 5% of the base), its 10th percentile within max(100 ft, 10%). Under a
/// cumulonimbus the columns are those under its towers' bases. The printed table is the book's
/// (clouds.md, "Where a cloud begins").
#[test]
fn the_first_cloud_above_the_ground_is_at_the_reported_base_for_every_type() {
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    let settings = WorldSettings {
        cloud_radius_m: 5_000.0,
        ..WorldSettings::default()
    };
    // Per type: stations, the errors of every covered column (ft), the bases (ft above ground).
    let mut by_type: std::collections::BTreeMap<String, (usize, Vec<f64>, Vec<f64>)> =
        Default::default();
    let mut seen = std::collections::HashSet::new();
    let feet = |m: f64| m / crate::weather::METRES_PER_FOOT;
    let everywhere = input.field(
        LocalFrame::new(0.0, 0.0),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    for report in file.reports.iter().step_by(2) {
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        if !seen.insert(((lat * 10.0) as i64, (lon * 10.0) as i64)) {
            continue;
        }
        // The station's weather read off one field first (a field of its own only for the
        // stations kept).
        let Some(first) = everywhere
            .weather_at_lat_lon(lat, lon)
            .layers
            .first()
            .copied()
        else {
            continue;
        };
        let full = by_type
            .get(&format!("{:?}", first.cloud_type))
            .is_some_and(|t| t.0 >= 6);
        if full || first.coverage_oktas < 2.0 {
            continue;
        }
        let frame = LocalFrame::new(lat, lon);
        let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
        let weather = field.block_weather(BlockIndex::new(0, 0));
        let Some(lowest) = weather.layers.first() else {
            continue;
        };
        let name = format!("{:?}", lowest.cloud_type);
        if by_type.get(&name).is_some_and(|t| t.0 >= 6) || lowest.coverage_oktas < 2.0 {
            continue;
        }
        let ground_m = f64::from(weather.ground_elevation_m);
        // Storm cells stand kilometres apart: a wider field finds the station's.
        let storms = lowest.cloud_type == CloudType::Cumulonimbus;
        let radius_m = if storms {
            16_000.0
        } else {
            settings.cloud_radius_m
        };
        let mut world = World::new(
            field,
            &WorldSettings {
                cloud_radius_m: radius_m,
                ..settings
            },
        );
        world
            .settle_clouds_around(DVec3::new(2_000.0, 2_000.0, ground_m))
            .expect("clouds");
        let Some(layer) = world
            .living_field()
            .and_then(|f| f.generations(BlockIndex::new(0, 0)).first())
            .and_then(|g| g.block.layers.first().copied())
        else {
            continue;
        };
        let hits = if layer.cloud_type == CloudType::Cumulonimbus {
            first_hits_under_towers(&world, ground_m)
        } else {
            first_hits(&world, &layer, ground_m)
        };
        if hits.len() < 10 {
            continue;
        }
        let base = f64::from(layer.base_m);
        let entry = by_type.entry(name).or_default();
        entry.0 += 1;
        entry.1.extend(hits.iter().map(|z| feet(z - base)));
        entry.2.push(feet(base - ground_m));
    }
    eprintln!("| type | stations | columns | median, ft over the base | 10th percentile, ft |");
    let mut wrong = Vec::new();
    for (name, (n, errors, bases)) in &mut by_type {
        errors.sort_by(f64::total_cmp);
        bases.sort_by(f64::total_cmp);
        let (median, p10) = (quantile(errors, 0.5), quantile(errors, 0.1));
        eprintln!(
            "| {name} | {n} | {} | {median:+.0} | {p10:+.0} |",
            errors.len()
        );
        let base_ft = quantile(bases, 0.5);
        if median.abs() > (0.05 * base_ft).max(50.0) || p10.abs() > (0.1 * base_ft).max(100.0) {
            wrong.push(format!(
                "{name}: median {median:+.0} ft, p10 {p10:+.0} ft at {base_ft:.0} ft"
            ));
        }
    }
    assert!(by_type.len() >= 10, "{:?}", by_type.keys());
    assert!(wrong.is_empty(), "{wrong:?}");
}

/// A pilot breaking out of a low overcast: descending through the real reports' decks of 600 ft
/// or lower (Atlanta's OVC004 in drizzle and mist among them), at 25 places over each airport,
/// the ground is first seen straight down within 50 ft of the reported base (the deck's
/// underside is closed: no hole shows the ground from inside it).
#[test]
fn breaking_out_of_a_low_overcast_the_ground_shows_at_the_reported_base() {
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    let feet = |m: f64| m / crate::weather::METRES_PER_FOOT;
    let mut checked = 0;
    for station in ["KAHN", "KFBG", "KWRB", "UATT", "KATL"] {
        let report = file
            .reports
            .iter()
            .find(|r| r.report.station == station)
            .expect("the station's report");
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        let field = input.field(
            LocalFrame::new(lat, lon),
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        );
        let weather = field.block_weather(BlockIndex::new(0, 0));
        let deck = weather.layers[0];
        assert!(
            deck.coverage_oktas >= 8.0 && deck.base_ft_agl <= 600.0,
            "{station}: {deck:?}"
        );
        let ground_m = f64::from(weather.ground_elevation_m);
        let mut world = World::new(
            field,
            &WorldSettings {
                cloud_radius_m: 5_000.0,
                ..WorldSettings::default()
            },
        );
        world
            .settle_clouds_around(DVec3::new(0.0, 0.0, ground_m))
            .expect("clouds");
        let base_ft = f64::from(deck.base_ft_agl);
        let step_ft = 10.0;
        // Over the airport: 25 places within a kilometre of the station, in its block (whose
        // weather is its report; the cover further out is the field's towards the next).
        for k in 0..25 {
            let at = DVec2::new((k % 5) as f64, (k / 5) as f64) * 200.0 + DVec2::splat(100.0);
            let ground = at.extend(ground_m + 1.0);
            // Down from 300 ft above the base: the first height with nothing between it and the
            // ground.
            let mut height_ft = base_ft + 300.0;
            while height_ft > 0.0 {
                let eye = at.extend(ground_m + height_ft * crate::weather::METRES_PER_FOOT);
                if world.first_cloud(eye, ground).is_none() {
                    break;
                }
                height_ft -= step_ft;
            }
            assert!(
                (height_ft - base_ft).abs() <= 50.0,
                "{station} {deck:?} at {at}: the ground first seen from {height_ft:.0} ft ({:.0} ft AGL reported)",
                feet(f64::from(deck.base_ft_agl) * crate::weather::METRES_PER_FOOT)
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 125);
}

/// The share of block (0, 0) where a vertical line from `from_m` to `to_m` meets cloud.
fn covered_between(world: &World, from_m: f64, to_m: f64) -> f64 {
    let hits = cell_centres()
        .filter(|p| {
            world
                .first_cloud(p.extend(from_m), p.extend(to_m))
                .is_some()
        })
        .count();
    hits as f64 / (CELLS * CELLS) as f64
}

/// A reported upper layer a pilot sees: on real reports of two broken layers (`BKN029 BKN033`
/// at KPKD, `BKN025 BKN046` at PAHX, `BKN022 BKN027` at LSZG, `BKN015 BKN020` at SBSJ; the
/// shipped file has no `BKN033 BKN041`), the upper layer has at least 2 oktas of its own, its
/// clouds cover at least a quarter of the station's block seen from between the layers, and the
/// sky seen from the ground stays broken (5 to 7 oktas). (Where the neighbours do not report the
/// upper layer its cover falls across the block: London's `BKN046` is 2 oktas at the station and
/// 0.5 at the block's far side, 0.15 of the block.)
#[test]
fn between_two_broken_layers_the_upper_one_covers_two_oktas() {
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    for station in ["KPKD", "PAHX", "LSZG", "SBSJ"] {
        let report = file
            .reports
            .iter()
            .find(|r| r.report.station == station)
            .expect("the station's report");
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        let field = input.field(
            LocalFrame::new(lat, lon),
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        );
        let weather = field.block_weather(BlockIndex::new(0, 0));
        let [lower, upper] = [weather.layers[0], weather.layers[1]];
        assert!(upper.coverage_oktas >= 2.0, "{station}: {upper:?}");
        let seen =
            crate::weather::block::cover_seen_from_below_oktas(&weather.layers, upper.base_ft_agl);
        assert!(
            (5.0..8.0).contains(&seen),
            "{station}: {seen} oktas seen from below"
        );
        let ground_m = f64::from(weather.ground_elevation_m);
        let mut world = World::new(
            field,
            &WorldSettings {
                cloud_radius_m: 5_000.0,
                ..WorldSettings::default()
            },
        );
        world
            .settle_clouds_around(DVec3::new(2_000.0, 2_000.0, ground_m))
            .expect("clouds");
        let g = world
            .living_field()
            .and_then(|f| f.generations(BlockIndex::new(0, 0)).first())
            .expect("the station's block");
        let (low, high) = (g.block.layers[0], g.block.layers[1]);
        let between = 0.5 * (f64::from(low.top_m) + f64::from(high.base_m));
        let top = f64::from(high.top_m) + 30.0;
        let upper_seen = covered_between(&world, between, top);
        let from_ground = covered_between(&world, ground_m + 1.0, top);
        eprintln!(
            "{station}: {lower:?} / {upper:?}: the upper layer covers {upper_seen:.3} seen from between, both {from_ground:.3} from the ground"
        );
        assert!(upper_seen >= 0.25 - 0.03, "{station}: {upper_seen}");
        assert!(
            (5.0 / 8.0 - 0.05..=7.0 / 8.0 + 0.05).contains(&from_ground),
            "{station}: {from_ground} seen from the ground"
        );
    }
}

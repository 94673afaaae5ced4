//! What an instrument measures agrees with what is drawn, on the real bulk file: the cover that
//! vertical lines of sight see from below a layer is the cover of its sprites' dense cores.

use std::path::Path;

use glam::{DVec2, DVec3};

use crate::clouds::DriftBand;
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
    let mut cores: Vec<(DVec3, SpriteCore)> = Vec::new();
    for (field, (_, g)) in world
        .living_fields()
        .flat_map(|f| f.blocks().map(move |b| (f, b)))
    {
        let drift = field.drift_m();
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

/// The layers of the station's block (0, 0), lowest first: the first generation's of every
/// drift band's field there (asked before the clouds drifted, each band's block (0, 0) is over
/// the station).
fn station_layers(world: &World) -> Vec<LayerSummary> {
    let mut layers: Vec<LayerSummary> = world
        .living_fields()
        .filter_map(|f| f.generations(BlockIndex::new(0, 0)).first())
        .flat_map(|g| g.block.layers.iter().copied())
        .collect();
    layers.sort_by(|a, b| a.base_m.total_cmp(&b.base_m));
    layers
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
        let layers = station_layers(&world);
        let Some(layer) = layers.first().copied() else {
            continue;
        };
        // Another layer reaching into this one's heights would be seen by the same lines.
        let apart = layers[1..]
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
    // The cells are the lowest band's.
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
        let layers = station_layers(&world);
        let (low, high) = (layers[0], layers[1]);
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

/// A METAR cover's class, 1 (FEW) to 4 (OVC).
fn class(cover: crate::weather::metar::Cover) -> i32 {
    use crate::weather::metar::Cover;
    match cover {
        Cover::Few => 1,
        Cover::Sct => 2,
        Cover::Bkn => 3,
        Cover::Ovc | Cover::Vv => 4,
    }
}

/// The ceilometer's round trip over `stations` cloudy stations of the real bulk file (reports
/// with cloud groups and no vertical visibility; an automatic station's layers and ceiling
/// compared below 12,000 ft or its highest reported layer, where its own ceilometer reads; the
/// layers reported over an overcast, which no ceilometer sees, left out): the reported layers
/// it gives back
/// (base within max(100 ft, 10%), cover class within one) and the ceilings (both none, or within
/// the same), as shares.
fn ceilometer_round_trip(stations: usize, seed: u64, set: StationSet) -> RoundTrip {
    use crate::flight::ceilometer;
    use crate::weather::metar::Cover;
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    let near = |a: f64, b: f64| (a - b).abs() <= (0.1 * b).max(100.0);
    let (mut layers, mut layers_met, mut ceilings_met, mut done) = (0, 0, 0, 0);
    let mut calm = (0, 0);
    let mut seen = std::collections::HashSet::new();
    for report in file.reports.iter().skip(set as usize).step_by(3) {
        if done >= stations {
            break;
        }
        let r = &report.report;
        let groups: Vec<(Cover, f64)> = r
            .clouds
            .iter()
            .filter_map(|g| Some((g.cover?, f64::from(g.base_ft?))))
            .collect();
        if groups.is_empty() || groups.iter().any(|g| g.0 == Cover::Vv) {
            continue;
        }
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        if !seen.insert(((lat * 10.0) as i64, (lon * 10.0) as i64)) {
            continue;
        }
        let (frame, at) = ceilometer::frame_centred_on(lat, lon);
        let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
        let ground_m = f64::from(
            field
                .block_weather(BlockIndex::new(0, 0))
                .ground_elevation_m,
        );
        let mut world = World::new(
            field,
            &WorldSettings {
                cloud_radius_m: 5_000.0,
                seed,
                ..WorldSettings::default()
            },
        );
        let readings = ceilometer::read(&mut world, at, ground_m, 20.0, 30.0).expect("the clouds");
        // An automatic station's ceilometer reads to 12,000 ft (or as high as it reported).
        let reach_ft = groups
            .iter()
            .map(|g| g.1 * 1.1 + 100.0)
            .fold(12_000.0, f64::max);
        let below = |ft: f64| !r.auto || ft < reach_ft;
        let found: Vec<ceilometer::Layer> =
            ceilometer::summarize(&readings, &ceilometer::CoverBins::default())
                .into_iter()
                .filter(|l| below(l.base_ft))
                .collect();
        // Nothing above an overcast reaches a ceilometer: the layers reported over one are
        // the observer's, not an instrument's.
        let first_ovc = groups
            .iter()
            .find(|g| g.0 == Cover::Ovc)
            .map_or(f64::INFINITY, |g| g.1);
        // A calm or variable wind (up to 3 kt, or no direction) drifts the clouds over the
        // station hardly at all: its readings are of one spot.
        let is_calm = r
            .wind
            .is_none_or(|w| w.speed_kt.unwrap_or(0.0) <= 3.0 || w.dir_deg.is_none());
        let mut missed = Vec::new();
        for (cover, base) in groups.iter().filter(|g| g.1 <= first_ovc) {
            let met = found
                .iter()
                .any(|l| near(l.base_ft, *base) && (class(l.cover) - class(*cover)).abs() <= 1);
            if !met {
                missed.push((*cover, *base));
            }
            layers += 1;
            layers_met += usize::from(met);
            if is_calm {
                calm.0 += 1;
                calm.1 += usize::from(met);
            }
        }
        let reported = groups
            .iter()
            .find(|g| matches!(g.0, Cover::Bkn | Cover::Ovc))
            .map(|g| g.1);
        let ours = ceilometer::ceiling_ft(&found);
        let ceiling_met = match (reported, ours) {
            (None, None) => true,
            (Some(a), Some(b)) => near(b, a),
            _ => false,
        };
        if std::env::var_os("SKYCAST_DEBUG_CEILOMETER").is_some() {
            eprintln!(
                "{} wind {:?} {:?} -> {:?} missed {missed:?}{}",
                r.station,
                r.wind.map(|w| (w.dir_deg, w.speed_kt)),
                groups,
                found
                    .iter()
                    .map(|l| format!("{} {:.2}", l.group(), l.seen_share))
                    .collect::<Vec<_>>(),
                if ceiling_met { "" } else { " CEILING" }
            );
        }
        ceilings_met += usize::from(ceiling_met);
        done += 1;
    }
    RoundTrip {
        layers: layers_met as f64 / layers.max(1) as f64,
        ceilings: ceilings_met as f64 / done.max(1) as f64,
        stations: done,
        calm_layers: calm,
        windy_layers: (layers - calm.0, layers_met - calm.1),
    }
}

/// Which of the bulk file's reports a round trip reads: every third, from the first or the
/// second (two sets of stations, one to check what was measured on the other).
#[derive(Clone, Copy)]
enum StationSet {
    /// The first report and every third after it.
    First = 0,
    /// The second and every third after it.
    Second = 1,
}

/// What [`ceilometer_round_trip`] gives back.
struct RoundTrip {
    /// The share of the reported layers given back.
    layers: f64,
    /// The share of the ceilings given back.
    ceilings: f64,
    /// Stations read.
    stations: usize,
    /// Reported layers and those given back at stations with a calm or variable wind.
    calm_layers: (usize, usize),
    /// The same at the other stations.
    windy_layers: (usize, usize),
}

impl RoundTrip {
    fn print(&self) {
        eprintln!(
            "{} stations: layers {:.3}, ceilings {:.3}; calm or variable wind: {} of {} layers, \
             the others: {} of {}",
            self.stations,
            self.layers,
            self.ceilings,
            self.calm_layers.1,
            self.calm_layers.0,
            self.windy_layers.1,
            self.windy_layers.0
        );
    }
}

/// The ceilometer's round trip at 40 cloudy stations of the real bulk file: measured 0.953 of
/// the reported layers and 0.950 of the ceilings (the 200-station figures in the book:
/// `cargo test --lib ceilometer_round_trip_at_200 -- --ignored --nocapture`). Held to 0.85 and
/// 0.85 against a fall; what is missing is in the book's "What is still not right": 40 readings
/// along a few kilometres of clouds a kilometre or two wide still toss a layer's cover a class
/// either way now and then.
#[test]
fn a_ceilometer_under_the_drifting_clouds_reads_the_reports_back() {
    let trip = ceilometer_round_trip(40, WorldSettings::default().seed, StationSet::First);
    trip.print();
    assert_eq!(trip.stations, 40);
    assert!(trip.layers >= 0.85 && trip.ceilings >= 0.85);
}

/// The round trip at 200 stations of `set` with the clouds of four seeds: the mean shares of
/// the layers and the ceilings given back.
fn round_trip_over_four_seeds(set: StationSet) -> (f64, f64) {
    let trips: Vec<RoundTrip> = [WorldSettings::default().seed, 1, 2, 3]
        .into_iter()
        .map(|seed| {
            let trip = ceilometer_round_trip(200, seed, set);
            eprint!("seed {seed}: ");
            trip.print();
            assert_eq!(trip.stations, 200);
            trip
        })
        .collect();
    let mean = |f: fn(&RoundTrip) -> f64| trips.iter().map(f).sum::<f64>() / trips.len() as f64;
    let (layers, ceilings) = (mean(|t| t.layers), mean(|t| t.ceilings));
    eprintln!("mean over the seeds: layers {layers:.3}, ceilings {ceilings:.3}");
    (layers, ceilings)
}

/// [`a_ceilometer_under_the_drifting_clouds_reads_the_reports_back`] at 200 stations, with the
/// clouds of four seeds (a few minutes): the seeds' clouds give back 0.946-0.958 of the layers
/// and 0.950-0.975 of the ceilings (0.954 and 0.962 on average; the shipped seed's 0.955 and
/// 0.970); at the stations with a calm or variable wind 60-65 of 69 layers, at the others
/// 233-236 of 243 (`cargo test --lib ceilometer_round_trip_at_200 -- --ignored --nocapture`;
/// `SKYCAST_DEBUG_CEILOMETER=1` prints each station's read and what it missed). Since a run of
/// three BKN layers steps down from 6.75 oktas seen from below (5.25, 6, 6.75, where it was 6,
/// 6.75 and 7), its third layer comes back more often (0.948 before).
#[test]
#[ignore]
fn ceilometer_round_trip_at_200() {
    let (layers, ceilings) = round_trip_over_four_seeds(StationSet::First);
    assert!(layers >= 0.95 && ceilings >= 0.95);
}

/// [`ceilometer_round_trip_at_200`] over 200 other stations (the file's second report and
/// every third after it), to check what was tuned on the first: 0.935-0.947 of the layers and
/// 0.915-0.955 of the ceilings (0.941 and 0.938 on average, 0.938 and 0.940 before BKN runs
/// stepped down; the shipped seed's 0.935 and 0.935); at the stations with a calm or variable
/// wind 63-66 of 72 layers, at the others 236-243 of 251
/// (`cargo test --lib ceilometer_round_trip_at_200_other_stations -- --ignored --nocapture`).
#[test]
#[ignore]
fn ceilometer_round_trip_at_200_other_stations() {
    let (layers, ceilings) = round_trip_over_four_seeds(StationSet::Second);
    assert!(layers >= 0.93 && ceilings >= 0.93);
}

/// The clouds drift with the wind the air data reports at their height: over real reports (and
/// with NOAA's winds aloft over the US), each reported layer's drift band moves in a minute what
/// `air_at`'s wind at that layer's middle carries it, within 1 kt and 5 degrees, upper layers
/// included (one drift for every layer moved them with the lowest one's wind).
#[test]
fn the_clouds_drift_with_the_air_datas_wind_at_their_height() {
    use crate::weather::winds_aloft::WindsAloft;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let input = WeatherInput::load(&root.join(REAL), None).expect("the bulk file");
    let aloft = WindsAloft::load(&root.join("weather/fd1us1-2026-01-31T06Z.txt")).expect("FB");
    let table = crate::weather::StationTable::builtin();
    let (mut checked, mut upper) = (0, 0);
    for (station, lat, lon) in [
        ("KDEN", 39.85, -104.66),
        ("EGLL", 51.4775, -0.4614),
        ("KORD", 41.98, -87.90),
        ("LEVX", 42.239, -8.624),
        ("KSAT", 29.53, -98.47),
    ] {
        for with_aloft in [false, true] {
            let field = input.field(
                LocalFrame::new(lat, lon),
                &FieldSettings::default(),
                &CloudTypeRule::default(),
            );
            let mut world = World::new(field, &WorldSettings::default());
            if with_aloft {
                world.set_winds_aloft(Some(&aloft), &table);
            }
            let layers = world.field().weather_at(DVec2::ZERO).layers.len();
            if layers == 0 {
                continue;
            }
            world.settle_clouds_around(DVec3::ZERO).expect("clouds");
            let before: Vec<DVec2> = world.living_fields().map(|f| f.drift_m()).collect();
            world
                .advance_clouds_around(DVec3::ZERO, 60.0)
                .expect("clouds");
            let bands: Vec<(DriftBand, DVec2)> = (world.living_fields())
                .zip(&before)
                .map(|(f, b)| (f.band(), (f.drift_m() - *b) / 60.0))
                .collect();
            // Each band whose own layer is over the station: the lowest, the second, ...
            for (band, moved) in bands.into_iter().take(layers) {
                let Some(height) = world.band_drift_height_m(DVec2::ZERO, band) else {
                    continue;
                };
                let air = world.air_at(DVec3::new(0.0, 0.0, height), DVec3::Z);
                let to = (air.wind_from_deg + 180.0).to_radians();
                let wind =
                    DVec2::new(to.sin(), to.cos()) * air.wind_kt * crate::weather::METRES_PER_KNOT;
                let knots = |v: DVec2| v.length() / crate::weather::METRES_PER_KNOT;
                let off_deg = if wind.length() > 0.5 && moved.length() > 0.5 {
                    moved.angle_to(wind).to_degrees().abs()
                } else {
                    0.0
                };
                eprintln!(
                    "{station} (aloft {with_aloft}) band {} at {height:.0} m: drift {:.1} kt, air data {:.1} kt from {:.0}, {off_deg:.1} degrees apart",
                    band.index,
                    knots(moved),
                    air.wind_kt,
                    air.wind_from_deg
                );
                assert!((knots(moved) - air.wind_kt).abs() <= 1.0, "{station}");
                assert!(off_deg <= 5.0, "{station}: {off_deg} degrees");
                checked += 1;
                upper += usize::from(band.index > 0);
            }
        }
    }
    assert!(
        checked >= 8 && upper >= 4,
        "{checked} layers, {upper} above the lowest"
    );
}

/// The cover drawn is the cover asked, type by type, at real station blocks: over 700 stations
/// of the bulk file, each layer of the station's block that no other layer reaches into, its
/// sprites' dense cores cover the block's share the weather asked for, within 0.09 on average
/// for every type and okta count met at least 8 times (measured: within 0.05 but altostratus
/// at 2 and 4 oktas, +0.05 and +0.08). About three minutes in a debug build:
/// `cargo test --lib drawn_cover_is_the_cover_asked -- --ignored --nocapture` prints the table.
#[test]
#[ignore]
fn drawn_cover_is_the_cover_asked_at_real_station_blocks() {
    let input = WeatherInput::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL), None)
        .expect("the bulk file");
    let WeatherInput::Reports(file) = &input else {
        panic!("a report file");
    };
    let settings = WorldSettings {
        cloud_radius_m: 5_000.0,
        ..WorldSettings::default()
    };
    // Per (type, oktas asked rounded): layers, the sum of the cover drawn, of the cover asked.
    let mut table: std::collections::BTreeMap<(String, i32), (usize, f64, f64)> =
        Default::default();
    let mut seen = std::collections::HashSet::new();
    let mut stations = 0;
    for report in file.reports.iter().step_by(2) {
        if stations >= 700 {
            break;
        }
        let (lat, lon) = (report.position.latitude_deg, report.position.longitude_deg);
        if report.report.clouds.is_empty()
            || !seen.insert(((lat * 10.0) as i64, (lon * 10.0) as i64))
        {
            continue;
        }
        let field = input.field(
            LocalFrame::new(lat, lon),
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        );
        let mut world = World::new(field, &settings);
        world
            .settle_clouds_around(DVec3::new(2_000.0, 2_000.0, 0.0))
            .expect("clouds");
        let layers = station_layers(&world);
        if world.living_field().is_none() {
            continue;
        }
        stations += 1;
        for (k, layer) in layers.iter().enumerate() {
            // A storm's cover is its cells', not the block's; a layer another reaches into is
            // not told apart by looking up.
            let apart = layers.iter().enumerate().all(|(m, l)| {
                m == k || l.base_m > layer.top_m + 60.0 || l.top_m < layer.base_m - 60.0
            });
            if layer.cloud_type == CloudType::Cumulonimbus || !apart {
                continue;
            }
            let key = (
                format!("{:?}", layer.cloud_type),
                layer.coverage_oktas.round() as i32,
            );
            let e = table.entry(key).or_default();
            e.0 += 1;
            e.1 += drawn_cover(&world, layer);
            e.2 += f64::from(layer.coverage_oktas) / 8.0;
        }
    }
    let mut bins = 0;
    for ((t, oktas), (n, drawn, asked)) in &table {
        let (drawn, asked) = (drawn / *n as f64, asked / *n as f64);
        eprintln!("{t:>18} {oktas} oktas: {n:>3} layers, drawn {drawn:.3}, asked {asked:.3}");
        if *n >= 8 {
            bins += 1;
            assert!(
                (drawn - asked).abs() <= 0.09,
                "{t} {oktas} oktas: drawn {drawn}, asked {asked}"
            );
        }
    }
    assert!(bins >= 10, "only {bins} types and covers met 8 times");
}

//! Tests of `field`: the living field's generations, phases, drift and bands.

use super::*;
use crate::weather::{BlockLayer, CloudType, TypeSource, Wind};

fn weather(oktas: f32) -> BlockWeather {
    BlockWeather {
        layers: vec![BlockLayer {
            cloud_type: CloudType::CumulusMediocris,
            type_source: TypeSource::HeightRule,
            coverage_oktas: oktas,
            base_ft_agl: 3000.0,
            thickness_ft: 2000.0,
        }],
        visibility_m: 9999.0,
        wind: Wind {
            from_deg: 270.0,
            speed_kt: 20.0,
        },
        ..Default::default()
    }
}

fn types() -> Arc<CloudTypes> {
    static TYPES: std::sync::OnceLock<Arc<CloudTypes>> = std::sync::OnceLock::new();
    Arc::clone(TYPES.get_or_init(|| Arc::new(CloudTypes::builtin())))
}

/// `weather(oktas)` without wind: the blocks stay where they are.
fn calm(oktas: f32) -> BlockWeather {
    BlockWeather {
        wind: Wind::default(),
        ..weather(oktas)
    }
}

/// The summed opacity of a generation's sprites at field time `now`.
fn opacity(g: &FieldBlock, now: f64) -> f32 {
    let config = CloudsConfig::builtin().lifecycle;
    g.block
        .clouds
        .iter()
        .flat_map(|c| &c.sprites)
        .map(|s| crate::clouds::lifecycle::alpha_at(g.phase, now, s.radius_fraction, &config))
        .sum::<f32>()
}

/// A calm field at 2 oktas whose weather goes to 6 oktas `after_s` in, taken in.
fn changed_field(after_s: f64) -> CloudField {
    let mut field = small_field();
    field.update(DVec2::ZERO, &|_| calm(2.0));
    field.wait_for_pending();
    field.advance(after_s);
    field.update(DVec2::ZERO, &|_| calm(6.0));
    field.wait_for_pending();
    field
}

fn small_field() -> CloudField {
    let mut config = CloudsConfig::builtin();
    config.field.radius_m = 9_000.0;
    CloudField::new(config, types(), 2).unwrap()
}

#[test]
fn polling_never_waits_for_a_busy_pool() {
    // A one-thread pool held busy by a gate the test owns: generation cannot run.
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap(),
    );
    let (open_gate, gate) = channel::<()>();
    pool.spawn(move || {
        let _ = gate.recv();
    });
    let mut generator = BlockGenerator::with_pool(types(), Arc::clone(&pool));
    for i in 0..3 {
        generator.submit(BlockIndex::new(i, 0), weather(4.0), 9);
    }
    // The caller gets control back at once with nothing finished, three times over.
    for _ in 0..3 {
        assert!(generator.poll().is_empty());
        assert_eq!(generator.pending(), 3);
    }
    open_gate.send(()).unwrap();
    let mut done = generator.wait_all();
    done.sort_by_key(|g| g.index);
    assert_eq!(done.len(), 3);
    assert_eq!(generator.pending(), 0);
    let direct = generate_block(BlockIndex::new(1, 0), &weather(4.0), 9, &types());
    assert_eq!(done[1].block, direct);
}

#[test]
fn batch_generation_matches_one_by_one() {
    let jobs: Vec<_> = (0..6)
        .map(|i| (BlockIndex::new(i, -i), weather(3.0)))
        .collect();
    let batch = generate_blocks(&jobs, 4, &types());
    for ((index, w), block) in jobs.iter().zip(&batch) {
        assert_eq!(block, &generate_block(*index, w, 4, &types()));
    }
}

#[test]
fn the_field_fills_its_circle_and_drifts_without_jumps() {
    let mut field = small_field();
    field.update(DVec2::ZERO, &|_| weather(4.0));
    field.wait_for_pending();
    let expected = blocks_within(DVec2::ZERO, 9_000.0).len();
    assert_eq!(field.block_count(), expected);
    assert_eq!(field.blocks().count(), expected);
    assert!(field.blocks().all(|(_, g)| g.phase == Phase::Steady));
    let before: BTreeMap<BlockIndex, u64> = field
        .blocks()
        .map(|(i, g)| (i, g.block.content_hash()))
        .collect();
    // Ten minutes of a 20 kt westerly x 1.5: about 9.3 km east, in one-second steps.
    let mut last = field.drift_m();
    for _ in 0..600 {
        field.advance(1.0);
        field.update(DVec2::ZERO, &|_| weather(4.0));
        let step = field.drift_m() - last;
        assert!(
            step.x > 0.0 && step.x < 16.0 && step.y.abs() < 1e-9,
            "step {step}"
        );
        last = field.drift_m();
    }
    field.wait_for_pending();
    assert!((field.drift_m().x - 600.0 * 20.0 * 0.514_444 * 1.5).abs() < 1.0);
    // Blocks that stayed in the field kept their identity and content while they moved.
    let mut kept = 0;
    for (i, g) in field.blocks() {
        if let Some(hash) = before.get(&i) {
            assert_eq!(
                *hash,
                g.block.content_hash(),
                "block {i:?} changed while drifting"
            );
            kept += 1;
        }
    }
    assert!(kept > expected / 2, "only {kept} of {expected} blocks kept");
    // The field still covers the circle around the (unmoved) centre.
    for (i, _) in field.blocks() {
        let ground = i.centre_m() + field.drift_m();
        assert!(ground.length() <= 9_000.0 + BLOCK_SIZE_M * 1.5);
    }
}

/// Asked again at the same weather version, a field asks only the blocks it does not hold
/// (the one under the camera for the wind aside); a new version asks every block again and
/// a changed weather forms new generations.
#[test]
fn blocks_kept_at_one_weather_version_are_not_asked_again() {
    let mut field = small_field();
    let asked = std::cell::Cell::new(0);
    let weather = |oktas: f32| {
        let asked = &asked;
        move |_: BlockIndex| {
            asked.set(asked.get() + 1);
            calm(oktas)
        }
    };
    field.update_for(DVec2::ZERO, &weather(4.0), 1);
    field.wait_for_pending();
    let held = field.slots.len();
    assert_eq!(
        asked.get(),
        held + 1,
        "every block, and the one under the camera"
    );
    asked.set(0);
    // A block east, at the same version: the new column only.
    let east = DVec2::new(BLOCK_SIZE_M, 0.0);
    field.update_for(east, &weather(4.0), 1);
    field.wait_for_pending();
    let new = asked.get() - 1;
    assert!(new > 0 && new < held / 3, "{new} of {held} asked");
    // A new version: every block again, and the changed cover forms new generations.
    asked.set(0);
    field.update_for(east, &weather(6.0), 2);
    field.wait_for_pending();
    let wanted = blocks_within(east, field.config.field.radius_m);
    assert_eq!(asked.get(), wanted.len() + 1);
    assert!(wanted.iter().all(|i| field.generations(*i).len() == 2));
}

#[test]
fn generations_without_clouds_also_go() {
    let mut field = small_field();
    let clear = BlockWeather::default();
    field.update(DVec2::ZERO, &|_| clear.clone());
    field.wait_for_pending();
    let index = BlockIndex::new(0, 0);
    // Clear, cloudy, clear again, cloudy: each change leaves a generation to dissipate.
    for w in [calm(4.0), clear.clone(), calm(6.0)] {
        field.update(DVec2::ZERO, &|_| w.clone());
        field.wait_for_pending();
        field.advance(2_000.0);
    }
    assert_eq!(field.generations(index).len(), 1, "old generations stay");
    assert_eq!(field.generations(index)[0].phase, Phase::Steady);
}

#[test]
fn blocks_joining_during_a_weather_change_form_with_their_neighbours() {
    let mut field = changed_field(100.0);
    let forming = Phase::forming(100.0, &CloudsConfig::builtin().lifecycle);
    assert_eq!(field.generations(BlockIndex::new(0, 0))[1].phase, forming);
    // Half-way through the formation the camera has flown a block east: the blocks that
    // join at the rim form from the same moment as those beside them, not whole among them.
    field.advance(60.0);
    let before: Vec<BlockIndex> = field.blocks().map(|(i, _)| i).collect();
    let east = DVec2::new(BLOCK_SIZE_M, 0.0);
    field.update(east, &|_| calm(6.0));
    field.wait_for_pending();
    let joined: Vec<BlockIndex> = field
        .blocks()
        .map(|(i, _)| i)
        .filter(|i| !before.contains(i))
        .collect();
    assert!(joined.len() >= 3, "{joined:?}");
    for index in &joined {
        let gens = field.generations(*index);
        assert_eq!(gens.len(), 1, "{index:?}");
        assert_eq!(gens[0].phase, forming, "{index:?}");
    }
    // Once the change has settled, blocks join formed again.
    field.advance(2_000.0);
    let before: Vec<BlockIndex> = field.blocks().map(|(i, _)| i).collect();
    field.update(east * 2.0, &|_| calm(6.0));
    field.wait_for_pending();
    let joined: Vec<&FieldBlock> = field
        .blocks()
        .filter(|(i, _)| !before.contains(i))
        .map(|(_, g)| g)
        .collect();
    assert!(joined.len() >= 3);
    assert!(joined.iter().all(|g| g.phase == Phase::Steady));
}

/// Air that drifts onto ground of other weather (the same weather version) forms its new
/// clouds, and lets the old go, while it drifts `drift_change_m`; a new version of the weather
/// takes the lifecycle's times.
#[test]
fn a_change_the_drift_brings_forms_while_the_air_crosses_into_it() {
    let mut field = small_field();
    let speed_m_s = 10.0;
    field.set_drift_velocity(Some(DVec2::new(speed_m_s, 0.0)));
    // Ground west of the origin at 2 oktas, east of it at 6.
    let ground = |i: BlockIndex| calm(if i.i < 0 { 2.0 } else { 6.0 });
    field.update_for(DVec2::ZERO, &ground, 1);
    field.wait_for_pending();
    // A block's drift later the air over ground block (-1, 0) is over (0, 0).
    field.advance(BLOCK_SIZE_M / speed_m_s);
    field.update_for(DVec2::ZERO, &ground, 1);
    field.wait_for_pending();
    let lifecycle = *field.lifecycle();
    let crossing_s = lifecycle.drift_change_m / speed_m_s as f32;
    assert!(crossing_s < lifecycle.formation_s.min(lifecycle.dissipation_s));
    let now = field.time_s();
    let changed: Vec<&[FieldBlock]> = field
        .blocks()
        .map(|(i, _)| field.generations(i))
        .filter(|g| g.len() == 2)
        .collect();
    assert!(changed.len() >= 3, "{} blocks changed", changed.len());
    for gens in &changed {
        let (old, new) = (gens[0].phase, gens[1].phase);
        assert_eq!(
            (old, new),
            (
                Phase::Dissipating {
                    since_s: now,
                    over_s: crossing_s
                },
                Phase::Forming {
                    since_s: now,
                    over_s: crossing_s
                }
            )
        );
    }
    // Formed by the time the air is `drift_change_m` into the new ground.
    field.advance(f64::from(crossing_s) + 0.1);
    assert!(field.blocks().all(|(i, _)| {
        field
            .generations(i)
            .iter()
            .all(|g| g.phase == Phase::Steady)
    }));
    // Another weather everywhere: a change in time forms over the lifecycle's time.
    field.update_for(DVec2::ZERO, &|_| calm(4.0), 2);
    field.wait_for_pending();
    let now = field.time_s();
    let mut changed = 0;
    // (Blocks that joined at the rim just now hold one generation.)
    for gens in field.blocks().map(|(i, _)| field.generations(i)) {
        if let [old, new] = gens {
            assert_eq!(new.phase, Phase::forming(now, &lifecycle));
            assert_eq!(old.phase, Phase::dissipating(now, &lifecycle));
            changed += 1;
        }
    }
    assert!(changed > 10, "{changed}");
}

#[test]
fn a_generation_superseded_while_forming_goes_back_without_a_jump() {
    let mut field = changed_field(10.0);
    let config = CloudsConfig::builtin().lifecycle;
    let index = BlockIndex::new(0, 0);
    // 30% formed when the weather changes again.
    field.advance(0.3 * f64::from(config.formation_s));
    let forming = field.generations(index)[1].clone();
    let before = opacity(&forming, field.time_s());
    assert!(before > 0.0);
    field.update(DVec2::ZERO, &|_| calm(4.0));
    field.wait_for_pending();
    let gens = field.generations(index);
    assert_eq!(gens.len(), 3);
    // The same clouds show as the moment before, then less and less, gone after 30% of
    // the formation time (dissipating from whole, they had shown whole at once).
    let after = opacity(&gens[1], field.time_s());
    let superseded = gens[1].serial;
    assert!(
        (after - before).abs() < 1e-3 * before.max(1.0),
        "{before} then {after}"
    );
    assert!(
        matches!(gens[1].phase, Phase::Unforming { from, .. } if (from - 0.3).abs() < 1e-3),
        "{:?}",
        gens[1].phase
    );
    let mut last = after;
    for _ in 0..10 {
        field.advance(0.031 * f64::from(config.formation_s));
        match field.generations(index).get(1) {
            Some(g) if g.serial == superseded => {
                let now = opacity(g, field.time_s());
                assert!(now <= last, "{last} then {now}");
                last = now;
            }
            _ => break,
        }
    }
    assert!(
        field
            .generations(index)
            .iter()
            .all(|g| g.serial != forming.serial),
        "the superseded generation is gone"
    );
}

#[test]
fn a_weather_change_dissipates_the_old_while_the_new_forms() {
    let mut field = small_field();
    field.update(DVec2::ZERO, &|_| weather(2.0));
    field.wait_for_pending();
    let index = BlockIndex::new(0, 0);
    assert_eq!(field.generations(index).len(), 1);
    // A small change (half an okta) re-forms nothing.
    field.update(DVec2::ZERO, &|_| weather(2.5));
    assert_eq!(field.pending(), 0);
    // Some way into the flight: the change's own times start at this field time, not at 0.
    field.advance(100.0);
    field.update(DVec2::ZERO, &|_| weather(6.0));
    field.wait_for_pending();
    let config = CloudsConfig::builtin().lifecycle;
    let gens = field.generations(index);
    assert_eq!(gens.len(), 2);
    assert!(matches!(gens[0].phase, Phase::Dissipating { .. }));
    assert!(matches!(gens[1].phase, Phase::Forming { .. }));
    let (mut old_last, mut new_last) = (f32::MAX, -1.0);
    let total = config.formation_s.max(config.dissipation_s) as f64;
    let mut t = 0.0;
    let (mut overlapping, mut forming) = (0, 0);
    while t < total {
        field.advance(10.0);
        t += 10.0;
        let gens = field.generations(index);
        // Never nothing, never a swap: the new clouds are there from the start.
        assert!(!gens.is_empty());
        overlapping += (gens.len() == 2) as usize;
        let new = gens.last().unwrap();
        forming += matches!(new.phase, Phase::Forming { .. }) as usize;
        let now = field.time_s();
        assert!(opacity(new, now) >= new_last);
        new_last = opacity(new, now);
        if gens.len() == 2 {
            assert!(opacity(&gens[0], now) <= old_last);
            old_last = opacity(&gens[0], now);
        }
    }
    // And it takes its time (10 s steps): the old clouds stay while they dissipate, the new
    // ones form over `formation_s`; settling or going at once is a pop.
    assert!(
        overlapping + 1 >= (config.dissipation_s / 10.0) as usize,
        "the old clouds went after {overlapping} steps of {}",
        config.dissipation_s
    );
    assert!(
        forming + 1 >= (config.formation_s / 10.0) as usize,
        "the new clouds formed in {forming} steps of {}",
        config.formation_s
    );
    let gens = field.generations(index);
    assert_eq!(gens.len(), 1, "the old clouds are gone");
    assert_eq!(gens[0].phase, Phase::Steady);
    assert_eq!(opacity(&gens[0], field.time_s()), new_last);
    assert!(
        gens[0]
            .block
            .clouds
            .iter()
            .flat_map(|c| &c.sprites)
            .all(|s| s.alpha_morph == 1.0),
        "the field never rewrites the sprites"
    );
}

/// An upper drift band holds no clouds over ground without a layer of its rank, and asks
/// nothing again while the weather stays; when the weather brings a second layer, its
/// clouds form there (they do not appear at once).
#[test]
fn an_upper_band_forms_the_layer_the_weather_brings() {
    let mut field = small_field().in_band(DriftBand::new(1, 2));
    let one = weather(4.0);
    let mut two = weather(4.0);
    two.layers.push(BlockLayer {
        base_ft_agl: 9000.0,
        ..two.layers[0]
    });
    field.update_for(DVec2::ZERO, &|_| one.clone(), 1);
    field.wait_for_pending();
    let held = field.block_count();
    assert!(held > 0);
    assert_eq!(field.blocks().count(), 0, "no clouds of band 1");
    assert!(!field.has_clouds());
    field.advance(30.0);
    field.update_for(DVec2::ZERO, &|_| two.clone(), 2);
    field.wait_for_pending();
    assert_eq!(field.blocks().count(), held);
    assert!(field.has_clouds());
    // Its clouds (their boxes and the rain spheres under them) reach over the upper
    // layer's base, 9,000 ft (2,743 m) over the 0 m ground.
    let (lo, hi) = field.heights_m();
    assert!(hi > 2_743.0 && lo < hi, "{lo} {hi}");
    for (_, g) in field.blocks() {
        assert!(matches!(g.phase, Phase::Forming { .. }), "{:?}", g.phase);
        assert_eq!(g.serial % 2, 1, "band 1's serials");
        assert!(g.block.layers.iter().all(|l| l.base_m > 2_000.0));
    }
}

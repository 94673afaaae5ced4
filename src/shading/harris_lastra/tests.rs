//! Unit tests of the Harris and Lastra light (no GPU).

use super::*;

fn particle(x: f32, y: f32, z: f32) -> Particle {
    Particle {
        centre_m: Vec3::new(x, y, z),
        radius_m: 100.0,
        density: 1.0,
    }
}

fn lit(particles: &[Particle], to_light: Vec3) -> Vec<ParticleLight> {
    let mut scratch = LightScratch::default();
    let mut out = Vec::new();
    HarrisLastra::default().light(particles, to_light, &mut scratch, &mut out);
    out
}

#[test]
fn a_particle_behind_others_gets_less_light_and_more_of_them_less_still() {
    // The sun along +x; particles in a row along x, the first nearest the sun.
    let row: Vec<Particle> = (0..6)
        .map(|i| particle(-120.0 * i as f32, 0.0, 0.0))
        .collect();
    let l = lit(&row, Vec3::X);
    assert_eq!(l[0].direct, 1.0);
    assert_eq!(l[0].total, 1.0);
    for pair in l.windows(2) {
        assert!(pair[1].total < pair[0].total, "{l:?}");
        assert!(pair[1].direct <= pair[0].direct, "{l:?}");
        assert!(pair[1].direct <= pair[1].total);
    }
    // Forward scattering keeps much more light than Beer's law alone, but it still falls.
    assert!(l[5].total > 3.0 * l[5].direct, "{l:?}");
    assert!(l[5].total < 0.2, "{l:?}");
    // The order of the input does not matter.
    let mut rev = row.clone();
    rev.reverse();
    let r = lit(&rev, Vec3::X);
    assert!((r[0].total - l[5].total).abs() < 1e-6);
}

#[test]
fn the_grid_finds_what_trying_every_pair_finds() {
    let mut rng = 7u32;
    let mut next = || {
        rng = rng.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (rng >> 8) as f32 / (1u32 << 24) as f32
    };
    // A wide deck of 600 particles, some small, some large.
    let deck: Vec<Particle> = (0..600)
        .map(|_| Particle {
            centre_m: Vec3::new(next() * 6000.0, next() * 6000.0, next() * 300.0),
            radius_m: 80.0 + next() * 220.0,
            density: next(),
        })
        .collect();
    let h = HarrisLastra::default();
    let sun = Vec3::new(0.3, -0.5, 0.4).normalize();
    let got = lit(&deck, sun);
    // Every pair, in order along the light.
    let mut order: Vec<usize> = (0..deck.len()).collect();
    order.sort_by(|&a, &b| {
        (-deck[a].centre_m.dot(sun))
            .total_cmp(&-deck[b].centre_m.dot(sun))
            .then(a.cmp(&b))
    });
    let mut want = vec![ParticleLight::default(); deck.len()];
    for (rank, &k) in order.iter().enumerate() {
        let (mut direct, mut total) = (1.0f32, 1.0f32);
        for &j in &order[..rank] {
            let d = deck[j].centre_m - deck[k].centre_m;
            let along = d.dot(sun);
            let r2 = deck[j].radius_m * deck[j].radius_m;
            let b2 = (d - sun * along).length_squared();
            if along <= 0.0 || b2 >= r2 {
                continue;
            }
            let alpha = h.opacity() * deck[j].density * splat(b2 / r2);
            direct *= 1.0 - alpha;
            total = h.forward_fraction() * alpha * want[j].total + (1.0 - alpha) * total;
        }
        want[k] = ParticleLight {
            direct,
            total: total.max(direct),
        };
    }
    let shaded = want.iter().filter(|l| l.total < 0.99).count();
    assert!(shaded > 100, "{shaded}");
    for (g, w) in got.iter().zip(&want) {
        assert!((g.total - w.total).abs() < 1e-5 && (g.direct - w.direct).abs() < 1e-5);
    }
}

#[test]
fn only_particles_between_a_particle_and_the_light_shade_it() {
    // One beside the ray (farther than its radius), one behind: no shadow.
    let l = lit(
        &[
            particle(0.0, 0.0, 0.0),
            particle(300.0, 150.0, 0.0),
            particle(-200.0, 0.0, 0.0),
        ],
        Vec3::X,
    );
    assert_eq!(l[0].total, 1.0);
    assert!(l[2].total < 1.0);
    // Half a radius off the ray it shades, less than straight on.
    let off = lit(
        &[particle(0.0, 0.0, 0.0), particle(150.0, 50.0, 0.0)],
        Vec3::X,
    );
    let on = lit(
        &[particle(0.0, 0.0, 0.0), particle(150.0, 0.0, 0.0)],
        Vec3::X,
    );
    assert!(
        off[0].total < 1.0 && off[0].total > on[0].total,
        "{off:?} {on:?}"
    );
    // Rain (density 0) casts no shadow.
    let rain = Particle {
        density: 0.0,
        ..particle(150.0, 0.0, 0.0)
    };
    assert_eq!(lit(&[particle(0.0, 0.0, 0.0), rain], Vec3::X)[0].total, 1.0);
}

#[test]
fn forward_fraction_is_the_papers() {
    let h = HarrisLastra {
        optical_depth: 8.0,
        ..HarrisLastra::default()
    };
    // tau 8, albedo 0.9, Rayleigh 3/2: 0.9 * 8 * 1.5 / 4 pi = 0.859.
    assert!(
        (h.forward_fraction() - 0.859).abs() < 0.002,
        "{}",
        h.forward_fraction()
    );
    let thin = HarrisLastra {
        optical_depth: 0.0,
        ..h
    };
    assert_eq!(thin.forward_fraction(), 0.0);
}

#[test]
fn phase_peaks_towards_the_sun() {
    let h = HarrisLastra::default();
    let into = h.phase(1.0);
    let side = h.phase(0.0);
    let away = h.phase(-1.0);
    assert!(into > 2.0 * side && side > away, "{into} {side} {away}");
    // Monotonic from the back to the front.
    let mut last = 0.0;
    for i in 0..=20 {
        let p = h.phase(-1.0 + i as f32 * 0.1);
        assert!(p >= last);
        last = p;
    }
    // On average over the sphere it is 1 (no light made or lost): mean over cos in -1..1.
    let n = 20_000;
    let mean: f32 = (0..n)
        .map(|i| h.phase(-1.0 + (i as f32 + 0.5) * 2.0 / n as f32))
        .sum::<f32>()
        / n as f32;
    assert!((mean - 1.0).abs() < 0.01, "{mean}");
}

#[test]
fn relight_only_after_the_sun_turned_past_the_threshold() {
    let mut t = RelightTrigger::new(1.0);
    let at = |deg: f32| {
        let r = deg.to_radians();
        Vec3::new(r.cos(), 0.0, r.sin())
    };
    assert!(t.update(at(10.0)), "first light");
    assert!(!t.update(at(10.0)));
    assert!(!t.update(at(10.5)));
    assert!(!t.update(at(10.95)));
    assert!(t.update(at(11.1)));
    // Measured from the last light, not the last call.
    assert!(!t.update(at(11.9)));
    assert!(t.update(at(12.2)));
}

#[test]
fn light_packs_into_bytes() {
    let sun = ParticleLight {
        direct: 0.25,
        total: 1.0,
    };
    let sky = ParticleLight {
        direct: 0.0,
        total: 0.5,
    };
    let p = pack_light(sun, sky);
    assert_eq!(p & 0xff, 64);
    assert_eq!((p >> 8) & 0xff, 255);
    assert_eq!((p >> 16) & 0xff, 128);
}

#[test]
fn models_are_named_and_settings_checked() {
    assert_eq!(ShadingModel::from_name("wang"), Some(ShadingModel::Wang));
    assert_eq!(
        ShadingModel::from_name("harris-lastra"),
        Some(ShadingModel::HarrisLastra)
    );
    assert_eq!(ShadingModel::from_name("phong"), None);
    assert!(HarrisLastra::default().invalid_field().is_none());
    let bad = HarrisLastra {
        albedo: 1.5,
        ..HarrisLastra::default()
    };
    assert_eq!(bad.invalid_field().unwrap().0, "harris_lastra.albedo");
}

/// Cost of one cloud's light (run by hand: `cargo test --release --lib light_cost --
/// --ignored --nocapture`).
#[test]
#[ignore]
fn light_cost() {
    let mut rng = 12345u32;
    let mut next = || {
        rng = rng.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (rng >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    let cloud: Vec<Particle> = (0..43)
        .map(|_| Particle {
            centre_m: Vec3::new(next() * 800.0, next() * 800.0, next() * 400.0),
            radius_m: 150.0 + next() * 100.0,
            density: 1.0,
        })
        .collect();
    let h = HarrisLastra::default();
    let (mut scratch, mut out) = (LightScratch::default(), Vec::new());
    let sun = Vec3::new(0.8, 0.1, 0.2).normalize();
    let n = 20_000;
    let start = std::time::Instant::now();
    let mut sum = 0.0;
    for _ in 0..n {
        h.light(&cloud, sun, &mut scratch, &mut out);
        sum += out[7].total;
    }
    let us = start.elapsed().as_secs_f64() * 1e6 / n as f64;
    println!("43 particles: {us:.2} us a light ({sum})");
    let deck: Vec<Particle> = (0..3000)
        .map(|_| Particle {
            centre_m: Vec3::new(next() * 20_000.0, next() * 20_000.0, next() * 300.0),
            radius_m: 300.0 + next() * 200.0,
            density: 1.0,
        })
        .collect();
    let start = std::time::Instant::now();
    for _ in 0..100 {
        h.light(&deck, sun, &mut scratch, &mut out);
    }
    let us = start.elapsed().as_secs_f64() * 1e6 / 100.0;
    println!(
        "3000 particles: {us:.0} us a light, {:.2} us a particle",
        us / 3000.0
    );
}

//! Tests of `generate`.

use super::*;
use crate::weather::{TypeSource, Wind};

fn weather(cloud_type: CloudType, oktas: f32, base_ft: f32, thickness_ft: f32) -> BlockWeather {
    BlockWeather {
        layers: vec![BlockLayer {
            cloud_type,
            type_source: TypeSource::HeightRule,
            coverage_oktas: oktas,
            base_ft_agl: base_ft,
            thickness_ft,
        }],
        visibility_m: 9999.0,
        obscuration: None,
        wind: Wind::default(),
        temperature_c: 10.0,
        dewpoint_c: 5.0,
        precipitation: 0.0,
        thunder: 0.0,
        ground_elevation_m: 250.0,
        cover: None,
    }
}

fn types() -> &'static CloudTypes {
    static TYPES: std::sync::OnceLock<CloudTypes> = std::sync::OnceLock::new();
    TYPES.get_or_init(CloudTypes::builtin)
}

/// The cells of a 50 m grid over the block (row by row, [`COVER_CELLS`] a side) under a
/// sprite's dense core (`clouds::core`, what every probe asks): what a person looking up would
/// see covered, from the sprites.
fn covered_cells(blocks: &[&CloudBlock], index: BlockIndex) -> Vec<bool> {
    let step = BLOCK_SIZE_M / COVER_CELLS as f64;
    let n = COVER_CELLS;
    let corner = index.min_corner_m();
    let mut grid = vec![false; n * n];
    for block in blocks {
        for c in &block.clouds {
            for core in crate::clouds::core::cores(c) {
                let p = (c.centre_m + core.centre_m).truncate() - corner;
                let r = core.box_half_m().x;
                let (x0, x1) = (
                    ((p.x - r) / step).floor().max(0.0) as usize,
                    (((p.x + r) / step).ceil().max(0.0) as usize).min(n),
                );
                let (y0, y1) = (
                    ((p.y - r) / step).floor().max(0.0) as usize,
                    (((p.y + r) / step).ceil().max(0.0) as usize).min(n),
                );
                for y in y0..y1 {
                    for x in x0..x1 {
                        let q = DVec2::new((x as f64 + 0.5) * step, (y as f64 + 0.5) * step);
                        // The core's horizontal section through its centre.
                        if core.radius(core.centre_m + (q - p).extend(0.0)) <= 1.0 {
                            grid[y * n + x] = true;
                        }
                    }
                }
            }
        }
    }
    grid
}

/// Cells a side of [`covered_cells`]' grid (50 m).
const COVER_CELLS: usize = 80;

/// Fraction of [`covered_cells`]' grid covered: the coverage a person looking up would see,
/// measured from the sprites.
fn sprite_coverage(blocks: &[&CloudBlock], index: BlockIndex) -> f64 {
    let grid = covered_cells(blocks, index);
    grid.iter().filter(|&&g| g).count() as f64 / grid.len() as f64
}

#[test]
fn generation_is_pure_and_seeded() {
    let w = weather(CloudType::CumulusMediocris, 4.0, 3000.0, 2000.0);
    let a = generate_block(BlockIndex::new(3, -2), &w, 7, types());
    let b = generate_block(BlockIndex::new(3, -2), &w, 7, types());
    assert_eq!(a, b);
    assert_eq!(a.content_hash(), b.content_hash());
    assert_ne!(
        a.content_hash(),
        generate_block(BlockIndex::new(3, -2), &w, 8, types()).content_hash()
    );
    assert_ne!(
        a.content_hash(),
        generate_block(BlockIndex::new(4, -2), &w, 7, types()).content_hash()
    );
    assert!(a.sprite_count() > 50);
}

/// Cirrus clouds are streaks along the wind: each cloud's sprites spread at least 2.5 times
/// further along the wind's axis than across it, whatever the wind's direction.
#[test]
fn cirrus_are_streaks_along_the_wind() {
    for from_deg in [270.0f32, 225.0, 0.0] {
        let mut w = weather(CloudType::Cirrus, 4.0, 28_000.0, 800.0);
        w.wind = Wind {
            from_deg,
            speed_kt: 40.0,
        };
        // Streaks bigger than a block fall in some blocks and not others: four blocks.
        let blocks: Vec<CloudBlock> = [(2, 1), (3, 1), (2, 2), (3, 2)]
            .map(|(i, j)| generate_block(BlockIndex::new(i, j), &w, 5, types()))
            .into();
        let along = DVec2::from_angle((90.0 - from_deg as f64).to_radians());
        let mut checked = 0;
        let clouds = blocks.iter().flat_map(|b| &b.clouds);
        for c in clouds.filter(|c| c.sprites.len() >= 3) {
            // The sky the streak spans: its sprites, each lying along the wind (its width
            // along, its height across).
            let extent = |axis: DVec2, half: &dyn Fn(&Sprite) -> f64| {
                let (lo, hi) = c.sprites.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
                    let d = DVec2::new(s.offset_m[0] as f64, s.offset_m[1] as f64).dot(axis);
                    (lo.min(d - half(s)), hi.max(d + half(s)))
                });
                hi - lo
            };
            let l = extent(along, &|s| s.width_m as f64 / 2.0);
            let a = extent(along.perp(), &|s| s.height_m as f64 / 2.0);
            assert!(
                l > 2.5 * a,
                "from {from_deg}: {l:.0} m along, {a:.0} m across"
            );
            checked += 1;
        }
        assert!(checked >= 2, "from {from_deg}: {checked} streaks");
    }
}

/// Cirrus follows the oktas, in irregular streaks: over 8 x 8 blocks the sky their sprites'
/// cores cover grows with the cover reported (and stays near it), the streaks per block vary
/// (some blocks have none at a few oktas) and so do their lengths; not one dash of the same
/// length in every block.
#[test]
fn cirrus_amount_follows_the_oktas_in_irregular_streaks() {
    let mut covers = Vec::new();
    for oktas in [1.0f32, 2.0, 4.0] {
        let w = weather(CloudType::Cirrus, oktas, 28_000.0, 800.0);
        let blocks: Vec<CloudBlock> = (0..8)
            .flat_map(|j| (0..8).map(move |i| BlockIndex::new(i, j)))
            .map(|index| generate_block(index, &w, 2003, types()))
            .collect();
        // The sky covered over the middle 4 x 4 blocks, by every streak of the 8 x 8 (those
        // of the outer blocks reach in), cell by cell as the generator counts it.
        let mut covered = 0usize;
        for index in (2..6).flat_map(|j| (2..6).map(move |i| BlockIndex::new(i, j))) {
            let corner = index.min_corner_m();
            let mut cells: Vec<usize> = blocks
                .iter()
                .flat_map(|b| &b.clouds)
                .flat_map(|c| super::cloud_cells(c, corner))
                .collect();
            cells.sort_unstable();
            cells.dedup();
            covered += cells.len();
        }
        let cover = covered as f64 / (16 * GRID * GRID) as f64;
        let per_block: Vec<usize> = blocks.iter().map(|b| b.clouds.len()).collect();
        let lengths: Vec<f64> = blocks
            .iter()
            .flat_map(|b| &b.clouds)
            .map(|c| 2.0 * c.radius_m as f64)
            .collect();
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let spread =
            (lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lengths.len() as f64).sqrt()
                / mean;
        let (fewest, most) = (per_block.iter().min(), per_block.iter().max());
        eprintln!(
            "{oktas} oktas: cover {cover:.3} (asked {:.3}), streaks a block {fewest:?}..={most:?}, length spread {spread:.2}",
            oktas / 8.0
        );
        assert!(
            cover > 0.75 * oktas as f64 / 8.0 && cover < 1.25 * oktas as f64 / 8.0,
            "{oktas} oktas: streaks cover {cover}"
        );
        assert!(
            spread > 0.2,
            "{oktas} oktas: streak lengths alike ({spread})"
        );
        assert!(fewest < most, "{oktas} oktas: every block alike");
        covers.push(cover);
    }
    assert!(covers[0] < covers[1] && covers[1] < covers[2], "{covers:?}");
    let w = weather(CloudType::Cirrus, 1.0, 28_000.0, 800.0);
    let empty = (0..16)
        .filter(|&i| {
            generate_block(BlockIndex::new(i, 0), &w, 2003, types())
                .clouds
                .is_empty()
        })
        .count();
    assert!(empty > 0, "one okta of cirrus puts a streak in every block");
}

#[test]
fn sprites_follow_the_paper_and_the_config() {
    for t in CloudType::ALL {
        let w = weather(t, 5.0, 3000.0, 1500.0);
        let block = generate_block(BlockIndex::new(0, 0), &w, 1, types());
        let config = types().get(t);
        assert!(!block.clouds.is_empty(), "{t}: no clouds");
        let l = block.layers[0];
        assert!(
            (l.base_m - (250.0 + 3000.0 * 0.3048)).abs() < 0.01,
            "{t}: base {}",
            l.base_m
        );
        for c in &block.clouds {
            assert_eq!(c.flat, config.flat);
            assert!(
                c.sprites.len() <= 800,
                "{t}: {} sprites in a cloud",
                c.sprites.len()
            );
            for s in &c.sprites {
                assert!(s.texture < 16);
                assert!((s.shading_group as usize) < c.shading_groups.len());
                let z = c.centre_m.z + s.offset_m[2] as f64;
                assert!(
                    z >= l.base_m as f64 - 0.5 && z <= l.top_m as f64 + 0.5,
                    "{t}: z {z}"
                );
                let fraction = ((z - l.base_m as f64) / (l.top_m - l.base_m) as f64) as f32;
                // A sprite standing on the base (its flat underside on it) takes the first
                // band, the others the band of their centre's height.
                let on_base = (z
                    - super::super::heap::BASE_CENTRE_FRACTION * s.height_m as f64
                    - l.base_m as f64)
                    .abs()
                    < 0.05;
                let band = if on_base {
                    config.texture_bands.first().unwrap()
                } else {
                    config.band_at(fraction.clamp(0.0, 1.0)).unwrap()
                };
                let cat = crate::clouds::TextureCategory::of_cell(s.texture);
                assert!(band.textures.contains(&cat), "{t}: {cat:?} at {fraction}");
                // Only the flat-bottomed sprites standing on a heaped cloud's base are
                // upright (continuous decks have no base rows).
                let heaped = !config.continuous && !config.flat && c.sprites.len() > 1;
                assert_eq!(
                    s.upright,
                    heaped && on_base && cat == crate::clouds::TextureCategory::FlatBottom,
                    "{t}: upright {} on base {on_base} {cat:?}",
                    s.upright
                );
                if config.streak_length_over_width.is_some() {
                    // Streak sprites lie along the wind's axis.
                    let axis = (90.0 - w.wind.from_deg).rem_euclid(360.0);
                    assert!((s.rotation_deg - axis).abs() < 1e-3, "{t}: streak off axis");
                } else if s.width_m != s.height_m {
                    assert_eq!(s.rotation_deg, 0.0, "{t}: non-square sprite rotated");
                } else {
                    assert!(
                        s.rotation_deg >= band.rotation_deg[0]
                            && s.rotation_deg <= band.rotation_deg[1]
                    );
                }
            }
            // The cull pass: no two sprites closer than the cull radius of the later one (of
            // the smaller one: a deck's sprites are shuffled after the cull); those standing on
            // the base are all kept.
            for (k, s) in c.sprites.iter().enumerate() {
                for o in c.sprites[..k].iter().filter(|o| !(s.base || o.base)) {
                    let d2: f32 = (0..3)
                        .map(|a| (s.offset_m[a] - o.offset_m[a]).powi(2))
                        .sum();
                    let r = config.cull_radius_fraction * s.height_m.min(o.height_m);
                    assert!(d2 >= r * r * 0.999, "{t}: sprites {d2} apart");
                }
            }
        }
    }
}

#[test]
fn cumulus_stand_on_a_flat_base_and_narrow_upwards() {
    let bc = crate::clouds::heap::BASE_CENTRE_FRACTION;
    for t in [
        CloudType::CumulusHumilis,
        CloudType::CumulusMediocris,
        CloudType::CumulusCongestus,
    ] {
        let block = generate_block(
            BlockIndex::new(2, 2),
            &weather(t, 3.0, 4000.0, 8000.0),
            9,
            types(),
        );
        let base = block.layers[0].base_m as f64;
        let shaped = block
            .clouds
            .iter()
            .filter(|c| c.sprites.len() >= 30)
            .count();
        assert!(shaped >= 2, "{t}: {shaped} clouds with a shape");
        for c in &block.clouds {
            let z = |s: &Sprite| c.centre_m.z + s.offset_m[2] as f64;
            // Nothing hangs below the base; a row stands exactly on it, flat-bottomed on
            // its rim.
            let on_base: Vec<&Sprite> = c
                .sprites
                .iter()
                .filter(|s| (z(s) - bc * s.height_m as f64 - base).abs() < 0.05)
                .collect();
            for s in &c.sprites {
                assert!(
                    z(s) - bc * s.height_m as f64 >= base - 0.05,
                    "{t}: below base"
                );
            }
            assert!(
                !on_base.is_empty(),
                "{t}: {} sprites on the base",
                on_base.len()
            );
            assert!(
                on_base
                    .iter()
                    .any(|s| crate::clouds::TextureCategory::of_cell(s.texture)
                        == crate::clouds::TextureCategory::FlatBottom),
                "{t}: no flat-bottomed sprite on the base"
            );
            // Rounded: the top third is narrower than the bottom third (for clouds big
            // enough to have a shape; the shrunk last clouds of a layer are a few sprites).
            if c.sprites.len() < 30 {
                continue;
            }
            let (lo, hi) = c
                .sprites
                .iter()
                .map(z)
                .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
            let extent = |from: f64, to: f64| {
                c.sprites
                    .iter()
                    .filter(|s| (from..=to).contains(&((z(s) - lo) / (hi - lo).max(1.0))))
                    .map(|s| s.offset_m[0].hypot(s.offset_m[1]))
                    .fold(0.0f32, f32::max)
            };
            assert!(
                extent(0.67, 1.0) < extent(0.0, 0.33),
                "{t}: top {} bottom {}",
                extent(0.67, 1.0),
                extent(0.0, 0.33)
            );
        }
    }
}

#[test]
fn coverage_is_honoured_for_every_cover_code() {
    // FEW 1-2, SCT 3-4, BKN 5-7, OVC 8 oktas, for heaped and layered types.
    for t in [
        CloudType::CumulusHumilis,
        CloudType::CumulusMediocris,
        CloudType::Stratocumulus,
        CloudType::Altocumulus,
        CloudType::Stratus,
    ] {
        for oktas in [1.5f32, 3.5, 6.0, 8.0] {
            let mut sum = 0.0;
            let blocks = 6;
            for i in 0..blocks {
                let index = BlockIndex::new(i, 1);
                let block = generate_block(index, &weather(t, oktas, 3000.0, 1500.0), 11, types());
                sum += sprite_coverage(&[&block], index);
            }
            let got = sum / blocks as f64;
            let want = oktas as f64 / 8.0;
            // Nearer its own cover code than either neighbour: the codes tried are 2 to 2.5
            // oktas apart, so 1 okta (0.125) is the most that still tells FEW from SCT; measured
            // at most 0.10 (stratus at SCT, 0.54), 0.02 for the heaped types below OVC.
            assert!(
                (got - want).abs() < 0.12,
                "{t} {oktas} oktas: covered {got:.3}, want {want:.3}"
            );
        }
    }
}

#[test]
fn overcast_neighbours_meet_without_a_gap() {
    for t in [
        CloudType::Stratus,
        CloudType::Nimbostratus,
        CloudType::Stratocumulus,
        CloudType::Fog,
    ] {
        let w = weather(
            t,
            8.0,
            if t == CloudType::Fog { 0.0 } else { 1200.0 },
            800.0,
        );
        let a = generate_block(BlockIndex::new(0, 0), &w, 5, types());
        let b = generate_block(BlockIndex::new(1, 0), &w, 5, types());
        // Points along the shared border x = 4000 m, every 20 m: each lies under some sprite's
        // disc (half its width), from one block or the other.
        for k in 0..200 {
            let p = DVec2::new(BLOCK_SIZE_M, 10.0 + 20.0 * k as f64);
            let covered = [&a, &b].iter().any(|blk| {
                blk.clouds.iter().any(|c| {
                    c.sprites.iter().any(|s| {
                        let q = DVec2::new(
                            c.centre_m.x + s.offset_m[0] as f64,
                            c.centre_m.y + s.offset_m[1] as f64,
                        );
                        q.distance(p) < s.width_m as f64 * 0.5
                    })
                })
            });
            assert!(covered, "{t}: gap at the border, y = {} m", p.y);
        }
    }
}

#[test]
fn a_block_with_no_cloud_is_empty_and_cb_has_an_anvil() {
    let block = generate_block(
        BlockIndex::new(0, 0),
        &weather(CloudType::Stratus, 0.0, 1000.0, 500.0),
        1,
        types(),
    );
    assert_eq!(block.sprite_count(), 0);
    assert_eq!(block.overdraw(), 0.0);
    let cb = generate_block(
        BlockIndex::new(0, 0),
        &weather(CloudType::Cumulonimbus, 3.0, 2500.0, 3000.0),
        1,
        types(),
    );
    let c = &cb.clouds[0];
    let half_h = (cb.layers[0].top_m - cb.layers[0].base_m) / 2.0;
    let spread = |lo: f32, hi: f32| {
        c.sprites
            .iter()
            .filter(|s| s.offset_m[2] / half_h >= lo && s.offset_m[2] / half_h < hi)
            .map(|s| s.offset_m[0].abs().max(s.offset_m[1].abs()))
            .fold(0.0f32, f32::max)
    };
    // The anvil (top tenth) spreads wider than the tower's middle.
    assert!(
        spread(0.7, 1.01) > 1.5 * spread(-0.2, 0.2),
        "anvil {} tower {}",
        spread(0.7, 1.01),
        spread(-0.2, 0.2)
    );
}

#[test]
fn few_cb_is_one_or_two_isolated_cells_as_tall_as_the_weather_says() {
    // FEW012CB at Timika: 2 oktas, tops at 35,000 ft over a 25 degree C surface.
    let w = weather(CloudType::Cumulonimbus, 2.0, 1200.0, 33_800.0);
    for i in 0..8 {
        let index = BlockIndex::new(i, -2);
        let block = generate_block(index, &w, 2003, types());
        let cells = block.layers[0].clouds;
        assert!((1..=2).contains(&cells), "block {i}: {cells} cells");
        // Isolated cells: each tower's base (its lowest fifth) is at most 4 km across, the
        // size of the block, while a layer would run on over the block's borders.
        for c in &block.clouds {
            let half_h = (block.layers[0].top_m - block.layers[0].base_m) / 2.0;
            let base_radius = c
                .sprites
                .iter()
                .filter(|s| s.offset_m[2] < -0.6 * half_h)
                .map(|s| s.offset_m[0].hypot(s.offset_m[1]) + s.width_m / 2.0)
                .fold(0.0f32, f32::max);
            assert!(
                base_radius < 2_000.0,
                "block {i}: base radius {base_radius} m"
            );
        }
        // The tops reach the weather's: the layer is not clamped under 25,000 ft, and the
        // tallest sprite stands above 25,000 ft.
        let ground = w.ground_elevation_m;
        let top_ft = (block.layers[0].top_m - ground) as f64 / METRES_PER_FOOT;
        assert!(top_ft > 34_000.0, "block {i}: top {top_ft} ft");
        let highest = block
            .clouds
            .iter()
            .flat_map(|c| {
                c.sprites
                    .iter()
                    .map(move |s| c.centre_m.z + s.offset_m[2] as f64)
            })
            .fold(f64::MIN, f64::max);
        assert!(
            (highest - ground as f64) / METRES_PER_FOOT > 25_000.0,
            "block {i}: highest sprite {highest} m"
        );
    }
}

#[test]
fn a_broken_high_layer_covers_its_oktas_at_a_real_time_cost() {
    // Cirrocumulus is what a METAR's BKN250-BKN300 becomes (the height rule). Drawn as heaps of
    // 70-150 m sprites it cost 5,901 sprites a block at 6 oktas and over a million in the view
    // radius; as a flat layer of grains twice that size it costs a fifth and covers about as
    // much (0.68 of the sky at 6 oktas against 0.75).
    for (oktas, most_sprites) in [(1.5f32, 400), (3.5, 800), (6.0, 1500)] {
        let blocks = 6;
        let (mut covered, mut sprites) = (0.0, 0);
        for i in 0..blocks {
            let index = BlockIndex::new(i, 1);
            let w = weather(CloudType::Cirrocumulus, oktas, 25000.0, 800.0);
            let block = generate_block(index, &w, 11, types());
            assert!(
                block.clouds.iter().all(|c| c.flat),
                "a thin high layer lies flat"
            );
            covered += sprite_coverage(&[&block], index);
            sprites += block.sprite_count();
        }
        let (covered, per_block) = (covered / blocks as f64, sprites / blocks as usize);
        let want = oktas as f64 / 8.0;
        // The bound of `coverage_is_honoured_for_every_cover_code`; measured 0.19, 0.43, 0.68.
        assert!(
            (covered - want).abs() < 0.12,
            "{oktas} oktas: covered {covered:.3}, want {want:.3}"
        );
        // Measured 230, 523 and 1,180 sprites a block.
        assert!(
            per_block <= most_sprites,
            "{oktas} oktas: {per_block} sprites a block, at most {most_sprites}"
        );
    }
}

/// The strongest periodicity of an overcast deck's sprite centres over 3 x 3 blocks: the
/// largest `|sum exp(2 pi i k.x)|^2 / N` over the wave vectors `k` with a whole number of cycles
/// across the 12 km (periods down to 150 m, along and across the lattice and every angle
/// between), against 1 for points strewn at random; and the wave vector's period, metres.
fn strongest_period(t: CloudType) -> (f64, f64) {
    let w = weather(t, 8.0, 1200.0, 800.0);
    let mut points = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let block = generate_block(BlockIndex::new(i, j), &w, 7, types());
            for c in &block.clouds {
                for s in &c.sprites {
                    points.push(DVec2::new(
                        c.centre_m.x + s.offset_m[0] as f64,
                        c.centre_m.y + s.offset_m[1] as f64,
                    ));
                }
            }
        }
    }
    let side = 3.0 * BLOCK_SIZE_M;
    let most = (side / 150.0) as i32;
    let mut strongest = (0.0, 0.0);
    for ny in 0..=most {
        for nx in -most..=most {
            // Half the plane (k and -k give the same power), and not the two longest waves
            // (the window's own shape).
            if (ny == 0 && nx <= 0) || nx * nx + ny * ny <= 4 || (nx * nx + ny * ny) > most * most {
                continue;
            }
            let k = DVec2::new(nx as f64, ny as f64) * (std::f64::consts::TAU / side);
            let (mut re, mut im) = (0.0, 0.0);
            for p in &points {
                let phase = k.dot(*p);
                re += phase.cos();
                im += phase.sin();
            }
            let power = (re * re + im * im) / points.len() as f64;
            if power > strongest.0 {
                strongest = (power, std::f64::consts::TAU / k.length());
            }
        }
    }
    strongest
}

#[test]
fn an_overcast_deck_has_no_lattice() {
    // Seen from above, a deck whose sprites stood on a regular grid read as a grid of squares.
    // Points strewn at random have a power of about 1 at each wave vector, the largest of the
    // ~3,600 looked at about ln(3,600) = 8; the old layout (a fifth of a grid square of jitter,
    // cells overlapping by a tenth) had 67 at the stratus grid's period (226 m); the sprites
    // spread over their whole squares, 9.1 and 9.3 (measured).
    for t in [CloudType::Stratus, CloudType::Stratocumulus] {
        let (power, period) = strongest_period(t);
        eprintln!("{t:?}: strongest period {period:.0} m, power {power:.1}");
        assert!(
            power < 20.0,
            "{t:?}: the sprites stand on a lattice of period {period:.0} m (power {power:.1})"
        );
    }
}

#[test]
fn a_deck_cell_does_not_list_its_sprites_row_by_row() {
    // Until its first sort a cloud is drawn in its sprites' own order: row by row, every
    // lattice cell was lit alike (squares from above). The correlation of a sprite's place in
    // the list with its position across the cell.
    let w = weather(CloudType::Stratus, 8.0, 1200.0, 800.0);
    let block = generate_block(BlockIndex::new(0, 0), &w, 3, types());
    let mut worst = 0.0f64;
    for c in &block.clouds {
        let n = c.sprites.len() as f64;
        for axis in 0..2 {
            let (mut si, mut sp, mut sii, mut spp, mut sip) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for (i, s) in c.sprites.iter().enumerate() {
                let (i, p) = (i as f64, s.offset_m[axis] as f64);
                (si, sp, sii, spp, sip) = (si + i, sp + p, sii + i * i, spp + p * p, sip + i * p);
            }
            let cov = sip / n - si * sp / (n * n);
            let var = (sii / n - (si / n).powi(2)) * (spp / n - (sp / n).powi(2));
            worst = worst.max((cov / var.sqrt()).abs());
        }
    }
    eprintln!("largest correlation of a cell's list with its sprites' positions: {worst:.2}");
    // A cell's 25 sprites shuffled: the largest of 32 correlations measured 0.42 (row by
    // row: 0.98).
    assert!(
        worst < 0.8,
        "a deck cell lists its sprites in rows: correlation {worst:.2}"
    );
}

/// The sky a layer of `config` at `oktas` covers when placed on the lattice (as a continuous
/// type is, and any type's overcast cells), over the middle block of 3 x 3 so that the
/// neighbours' overhang counts, the mean of 12 blocks.
fn lattice_cover(t: CloudType, config: &CloudTypeConfig, oktas: f32) -> f64 {
    with_layer_ctx(t, config, oktas, |ctx| {
        let mut sum = 0.0;
        let (seeds, rows) = (6u64, 2);
        for seed in 0..seeds {
            for row in 0..rows {
                let centre = BlockIndex::new(3 * row, 1);
                let mut block = CloudBlock {
                    index: centre,
                    seed,
                    layers: Vec::new(),
                    clouds: Vec::new(),
                };
                for dj in -1..=1 {
                    for di in -1..=1 {
                        let b = BlockIndex::new(centre.i + di, centre.j + dj);
                        lattice_layer(b, ctx, seed, &mut block.clouds);
                    }
                }
                sum += sprite_coverage(&[&block], centre);
            }
        }
        sum / (seeds as usize * rows as usize) as f64
    })
}

/// Runs `f` with the generation context of one even layer of `t` at `oktas` (base 3,000 ft,
/// 1,500 ft thick) drawn by `config`, alone in its block.
fn with_layer_ctx<R>(
    t: CloudType,
    config: &CloudTypeConfig,
    oktas: f32,
    f: impl FnOnce(&LayerCtx) -> R,
) -> R {
    let w = weather(t, oktas, 3000.0, 1500.0);
    let layer = &w.layers[0];
    let frame = LayerFrame::new(layer, config, w.ground_elevation_m as f64);
    let cover = LayerCover::uniform(oktas);
    f(&LayerCtx {
        config,
        layer,
        li: 0,
        frame: &frame,
        wind_axis_deg: 0.0,
        cover,
        share: Share::alone(&cover),
    })
}

/// A layer on the lattice covers what the weather asks: each kept cell's clouds reach past it
/// (a stratus at 4 oktas covered 4.8, an altostratus 5.1), or leave gaps inside it (an
/// altocumulus' small sprites, 3.6), and `lattice_overhang` keeps fewer or more cells for it.
/// Where an overcast block of stratocumulus (on the lattice) met a broken one (scattered) the
/// cover stepped at the border. Prints the overhang each type's sprites make, fitted with none
/// allowed for, to set `config/cloud_types.toml` by.
#[test]
fn a_layer_on_the_lattice_covers_what_the_weather_asks() {
    let oktas = [2.0f32, 4.0, 6.0];
    let mut worst: Vec<String> = Vec::new();
    for t in CloudType::ALL {
        if t == CloudType::Cumulonimbus {
            // Drawn as the field's storm cells, never on the lattice.
            continue;
        }
        let config = types().get(t);
        let mut raw = config.clone();
        raw.lattice_overhang = 0.0;
        let (mut fit, mut line) = (0.0, String::new());
        for &o in &oktas {
            let p = o as f64 / 8.0;
            // Whole cells of a block: the share kept, as the lattice rounds it.
            let cells = (BLOCK_SIZE_M / config.lattice_spacing_m as f64)
                .powi(2)
                .round();
            let kept = (p * cells).round() / cells;
            fit += (lattice_cover(t, &raw, o) - kept) / (kept * (1.0 - kept)) / oktas.len() as f64;
            let got = 8.0 * lattice_cover(t, config, o);
            line += &format!(" {o}: {got:.2}");
            // A lattice of 2 km cells (cirrus, cirrostratus) keeps a quarter of a block at a
            // time: only the fit is printed for them.
            if cells >= 16.0 && (got - o as f64).abs() > 0.35 {
                worst.push(format!("{t} at {o} oktas covers {got:.2}"));
            }
        }
        eprintln!(
            "{t}: covers{line} oktas (lattice_overhang {:.2}, fitted {fit:.2})",
            config.lattice_overhang
        );
    }
    assert!(worst.is_empty(), "{worst:?}");
}

/// How much the borders between cloud and clear of a layer of `t` at `oktas` run along the
/// world axes: the coverage of 50 m cells over the middle block of 3 x 3 (within 0.7 sprite
/// half-widths of a sprite centre, as `sprite_coverage` counts) smoothed over 450 m, and where
/// it crosses a half the mean of `cos 4 theta` of its gradient's direction, weighted by the
/// gradient: 1 where every border lies along an axis (square gaps), 0 for borders of every
/// direction alike (round ones).
fn border_axis_alignment(t: CloudType, oktas: f32) -> f64 {
    let n = COVER_CELLS;
    let w = weather(t, oktas, 3000.0, 1500.0);
    let (mut aligned, mut weight) = (0.0, 0.0);
    for seed in 0..4u64 {
        let blocks: Vec<CloudBlock> = (-1..=1)
            .flat_map(|dj| (-1..=1).map(move |di| BlockIndex::new(di, dj)))
            .map(|b| generate_block(b, &w, seed, types()))
            .collect();
        let refs: Vec<&CloudBlock> = blocks.iter().collect();
        let grid: Vec<f64> = covered_cells(&refs, BlockIndex::new(0, 0))
            .into_iter()
            .map(f64::from)
            .collect();
        // A box of 9 x 9 cells (450 m): the cells' own bumps smoothed away, the gaps' shapes
        // kept.
        let k = 4usize;
        let mut smooth = vec![0.0f64; n * n];
        for y in k..n - k {
            for x in k..n - k {
                let mut sum = 0.0;
                for v in y - k..=y + k {
                    for u in x - k..=x + k {
                        sum += grid[v * n + u];
                    }
                }
                smooth[y * n + x] = sum / ((2 * k + 1) * (2 * k + 1)) as f64;
            }
        }
        for y in k + 1..n - k - 1 {
            for x in k + 1..n - k - 1 {
                let v = smooth[y * n + x];
                if (v - 0.5).abs() > 0.15 {
                    continue;
                }
                let gx = smooth[y * n + x + 1] - smooth[y * n + x - 1];
                let gy = smooth[(y + 1) * n + x] - smooth[(y - 1) * n + x];
                let g2 = gx * gx + gy * gy;
                if g2 <= 0.0 {
                    continue;
                }
                // cos 4 theta from the gradient without trigonometry.
                let (c2, s2) = ((gx * gx - gy * gy) / g2, 2.0 * gx * gy / g2);
                let g = g2.sqrt();
                aligned += g * (c2 * c2 - s2 * s2);
                weight += g;
            }
        }
    }
    aligned / weight.max(1e-9)
}

/// A broken deck's gaps are clearings, not squares: a continuous layer's cells of a broken
/// layer are round clouds. Square cells left gaps with straight sides along the world axes (a
/// grid of square holes from FL350 over Chicago's broken altostratus on the 2025 bulk file).
#[test]
fn a_broken_deck_has_no_square_gaps() {
    // Square cells: 0.51, 0.48 and 0.42 (stratus at 3, 5 and 6 oktas), 0.46, 0.28 and 0.30
    // (altostratus); round ones 0.20, 0.24, 0.27, 0.19, 0.07 and 0.16 (kept cells side by side
    // on the lattice still run along it a little).
    let mut all = Vec::new();
    for t in [CloudType::Stratus, CloudType::Altostratus] {
        for oktas in [3.0f32, 5.0, 6.0] {
            let alignment = border_axis_alignment(t, oktas);
            eprintln!("{t} at {oktas} oktas: its gaps' borders along the axes {alignment:.2}");
            all.push(alignment);
        }
    }
    let mean = all.iter().sum::<f64>() / all.len() as f64;
    assert!(
        mean < 0.25 && all.iter().all(|&a| a < 0.35),
        "gaps along the axes: {all:.2?}, mean {mean:.2}"
    );
}

/// The clouds of a scattered layer placed at the best of several candidate centres
/// (`placement_candidates`) lie farther from their nearest neighbour than chance would put them
/// (Clark and Evans' ratio of the mean nearest-neighbour distance to a random pattern's), as
/// cumulus fields do, where a single random centre left them about as clumped as chance.
#[test]
fn scattered_clouds_lie_more_evenly_than_chance() {
    let t = CloudType::CumulusHumilis;
    let shipped = types().get(t);
    assert!(shipped.placement_candidates > 1, "{shipped:?}");
    let mut random = shipped.clone();
    random.placement_candidates = 1;
    let ratio = |config: &CloudTypeConfig| {
        with_layer_ctx(t, config, 3.0, |ctx| {
            let (mut sum, mut n) = (0.0, 0usize);
            for seed in 0..24u64 {
                let mut clouds = Vec::new();
                scattered_layer(BlockIndex::new(0, 0), ctx, seed, &mut clouds);
                let centres: Vec<DVec2> = clouds.iter().map(|c| c.centre_m.truncate()).collect();
                if centres.len() < 4 {
                    continue;
                }
                // Clouds within 600 m of the block's sides left out of the mean (their nearest
                // neighbour may be in the next block); every cloud is a neighbour.
                let density = centres.len() as f64 / (BLOCK_SIZE_M * BLOCK_SIZE_M);
                let expected = 0.5 / density.sqrt();
                for (k, p) in centres.iter().enumerate() {
                    if p.min_element() < 600.0 || p.max_element() > BLOCK_SIZE_M - 600.0 {
                        continue;
                    }
                    let nearest = centres
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != k)
                        .map(|(_, q)| p.distance(*q))
                        .fold(f64::INFINITY, f64::min);
                    sum += nearest / expected;
                    n += 1;
                }
            }
            assert!(n >= 20, "{n} clouds measured");
            sum / n as f64
        })
    };
    let (even, chance) = (ratio(shipped), ratio(&random));
    eprintln!(
        "Clark-Evans ratio: {even:.2} at the best of {}, {chance:.2} at one",
        shipped.placement_candidates
    );
    assert!(even > chance + 0.1, "{even} {chance}");
}

/// The drift bands' fields together are the whole block: each band generates its layers of a
/// block exactly as the whole block has them (the same clouds, keyed alike), every cloud naming
/// its layer among its band's summaries.
#[test]
fn the_drift_bands_together_are_the_whole_block() {
    let mut w = weather(CloudType::CumulusMediocris, 3.0, 2500.0, 2000.0);
    let mut add = |cloud_type, oktas, base_ft_agl, thickness_ft| {
        w.layers.push(BlockLayer {
            cloud_type,
            type_source: TypeSource::HeightRule,
            coverage_oktas: oktas,
            base_ft_agl,
            thickness_ft,
        });
    };
    add(CloudType::Altocumulus, 4.0, 9000.0, 1500.0);
    add(CloudType::Cirrus, 3.0, 25000.0, 1000.0);
    let index = BlockIndex::new(3, -2);
    let cache = CellCache::default();
    let whole = generate_block_in_field(index, &w, (&[], DriftBand::WHOLE), &cache, 7, types());
    let mut banded: Vec<Cloud> = Vec::new();
    for band in DriftBand::all(4) {
        let b = generate_block_in_field(index, &w, (&[], band), &cache, 7, types());
        // Three layers in four bands: the last band holds none.
        assert_eq!(b.layers.len(), usize::from(band.index < 3), "{band:?}");
        for c in &b.clouds {
            let summary = b.layers[usize::from(c.layer)];
            assert_eq!(summary.cloud_type, c.cloud_type);
        }
        banded.extend(b.clouds);
    }
    assert!(whole.clouds.len() > 10);
    assert_eq!(banded.len(), whole.clouds.len());
    for (a, b) in banded.iter().zip(&whole.clouds) {
        assert_eq!((a.centre_m, a.sprites.len()), (b.centre_m, b.sprites.len()));
    }
}

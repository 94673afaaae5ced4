//! Tests of the lines of sight's grids and tiles: against testing every box, and what a change
//! of the field builds.

use super::*;
use crate::clouds::block::Cloud;
use crate::clouds::boxes::tests::cube_cloud;
use crate::weather::CloudType;

/// Uniform numbers in 0..1 from a xorshift of `seed`: the same cases on every run.
fn xorshift(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The grid a line of sight walks finds what testing every box finds: on 300 clouds of
/// random size and place in three generations (overlapping) and 3,000 segments (level,
/// upright, axis-aligned, starting inside and outside the clouds, grazing a box's top),
/// every box entered is met exactly once, and the nearest entry (the first cloud) is the
/// same, for a fine, the shipped and a coarse grid.
#[test]
fn the_grid_meets_every_box_a_segment_enters_once_and_the_nearest_first() {
    let mut rand = xorshift(0x2545_f491_4f6c_dd1du64);
    let generations: Vec<Arc<GenerationBoxes>> = (0..3)
        .map(|_| {
            let clouds: Vec<Cloud> = (0..100)
                .map(|_| {
                    let c = DVec3::new(
                        rand() * 12_000.0 - 2_000.0,
                        rand() * 8_000.0,
                        500.0 + rand() * 2_500.0,
                    );
                    let half = (30.0 + rand() * 1_500.0 * rand()) as f32;
                    cube_cloud(c, half, CloudType::CumulusMediocris)
                })
                .collect();
            Arc::new(GenerationBoxes::of(&clouds))
        })
        .collect();
    let every: Vec<(usize, &CloudBox)> = generations
        .iter()
        .enumerate()
        .flat_map(|(g, b)| b.boxes.iter().map(move |bx| (g, bx)))
        .collect();
    let mut met_first = 0;
    let mut stamp = 0;
    for cell_m in [120.0, 500.0, 4_000.0] {
        let sight = SightBoxes::of(generations.clone(), cell_m);
        assert_eq!(sight.len(), 300);
        let mut seen = vec![0; sight.len()];
        let mut tables = vec![None; sight.len()];
        for k in 0..3_000 {
            let mut a = DVec3::new(
                rand() * 16_000.0 - 4_000.0,
                rand() * 12_000.0 - 2_000.0,
                rand() * 3_500.0,
            );
            let mut b = a + DVec3::new(
                (rand() - 0.5) * 20_000.0,
                (rand() - 0.5) * 20_000.0,
                (rand() - 0.5) * 3_000.0,
            );
            match k % 7 {
                0 => b.z = a.z,
                1 => b = a.with_z(a.z + 3_000.0),
                2 => b.x = a.x,
                3 => a = every[k % every.len()].1.centre_m,
                // Level, grazing a box's top: the cells' heights must hold it.
                4 => {
                    let bx = every[k % every.len()].1;
                    a.z = bx.centre_m.z + bx.half_m.z - 0.5;
                    b.z = a.z;
                }
                _ => {}
            }
            let mut all: Vec<(f64, usize, usize)> = every
                .iter()
                .filter_map(|(g, bx)| bx.segment(a, b).map(|(t0, _)| (t0, *g, bx.cloud)))
                .collect();
            all.sort_by_key(|x| (x.1, x.2));
            let mut met = Vec::new();
            stamp += 1;
            sight.crossed(
                a,
                b,
                &mut Walk::new(true),
                (&mut seen, &mut tables, stamp),
                |g, bx, _, t0, _| {
                    met.push((t0, g, bx.cloud));
                    Met::Counted(t0)
                },
            );
            met.sort_by_key(|x| (x.1, x.2));
            assert_eq!(met, all, "cell {cell_m} m, segment {k}: {a} to {b}");
            // A walk that has enough after its first box meets no other, in any grid.
            let mut walked = 0;
            stamp += 1;
            sight.crossed(
                a,
                b,
                &mut Walk::new(true),
                (&mut seen, &mut tables, stamp),
                |_, _, _, _, _| {
                    walked += 1;
                    Met::Enough
                },
            );
            assert_eq!(walked, all.len().min(1), "cell {cell_m} m, segment {k}");
            let nearest = all.iter().map(|h| h.0).fold(f64::INFINITY, f64::min);
            let mut first = f64::INFINITY;
            stamp += 1;
            sight.crossed(
                a,
                b,
                &mut Walk::new(false),
                (&mut seen, &mut tables, stamp),
                |_, _, _, t0, _| {
                    first = first.min(t0);
                    Met::Counted(t0)
                },
            );
            assert_eq!(first, nearest, "cell {cell_m} m, segment {k}");
            met_first += nearest.is_finite() as usize;
        }
    }
    // Both kinds of segment were asked about.
    assert!((1_000..8_000).contains(&met_first), "{met_first}");
}

/// A random segment of up to 30 km at cloud heights over the area `0..size_m` (levels and
/// upright ones among them).
fn segment(rand: &mut dyn FnMut() -> f64, size_m: f64, k: usize) -> (DVec3, DVec3) {
    let a = DVec3::new(rand() * size_m, rand() * size_m, rand() * 4_000.0);
    let mut b = a + DVec3::new(
        (rand() - 0.5) * 30_000.0,
        (rand() - 0.5) * 30_000.0,
        (rand() - 0.5) * 3_000.0,
    );
    match k % 5 {
        0 => b.z = a.z,
        1 => b = a.with_z(a.z + 3_000.0),
        _ => {}
    }
    (a, b)
}

/// Asserts that `sight` meets what testing every box of `members` meets on 1,500 random
/// segments, the `gone` generations passed over.
fn check(
    sight: &mut FieldSight,
    members: &[SightMember],
    gone: &[u64],
    rand: &mut dyn FnMut() -> f64,
    k0: usize,
) {
    let size_m = 12.0 * BLOCK_SIZE_M;
    for k in k0..k0 + 1_500 {
        let (a, b) = segment(&mut *rand, size_m, k);
        let mut every: Vec<(u64, usize, u64)> = members
            .iter()
            .flat_map(|(_, serial, boxes)| {
                boxes.boxes.iter().filter_map(move |bx| {
                    bx.segment(a, b)
                        .map(|(t0, _)| (*serial, bx.cloud, t0.to_bits()))
                })
            })
            .collect();
        every.sort_unstable();
        let mut met = Vec::new();
        sight.crossed(a, b, true, |(_, serial), bx, t0, _| {
            if gone.contains(&serial) {
                return Met::Passed;
            }
            met.push((serial, bx.cloud, t0.to_bits()));
            Met::Counted(t0)
        });
        met.sort_unstable();
        assert_eq!(met, every, "segment {k}: {a} to {b}");
        let nearest = every
            .iter()
            .map(|h| f64::from_bits(h.2))
            .fold(f64::INFINITY, f64::min);
        let mut first = f64::INFINITY;
        sight.crossed(a, b, false, |(_, serial), _, t0, _| {
            if gone.contains(&serial) {
                return Met::Passed;
            }
            first = first.min(t0);
            Met::Counted(t0)
        });
        assert_eq!(first, nearest, "segment {k}: {a} to {b}");
    }
}

/// The tiles find what testing every living box finds, before and after the membership
/// changes: on generations of random clouds (overhanging their blocks) over 12 x 12 blocks,
/// every living box a segment enters is counted once and the first cloud is the nearest;
/// once generations went and others joined, only the tile they joined changes (a part of
/// their own), and the gone ones are passed over where they lie.
#[test]
fn tiles_meet_what_every_box_meets_and_a_change_builds_only_its_tiles() {
    let mut rand = xorshift(0x9e37_79b9_7f4a_7c15u64);
    let generation = |index: BlockIndex, serial: u64, rand: &mut dyn FnMut() -> f64| {
        let corner = index.min_corner_m();
        let clouds: Vec<Cloud> = (0..12)
            .map(|_| {
                let c = DVec3::new(
                    corner.x + rand() * BLOCK_SIZE_M,
                    corner.y + rand() * BLOCK_SIZE_M,
                    500.0 + rand() * 2_500.0,
                );
                let half = (30.0 + rand() * 1_500.0 * rand()) as f32;
                cube_cloud(c, half, CloudType::CumulusMediocris)
            })
            .collect();
        (index, serial, Arc::new(GenerationBoxes::of(&clouds)))
    };
    let mut members: Vec<SightMember> = Vec::new();
    for j in 0..12 {
        for i in 0..12 {
            let serial = members.len() as u64 + 1;
            members.push(generation(BlockIndex::new(i, j), serial, &mut rand));
        }
    }
    let mut sight = FieldSight::new(500.0);
    assert_eq!(sight.update(members.iter().map(|m| (m.0, m.1, &m.2))), 9);
    // A tile's grid is built when a line of sight first enters its bounds: a short one in
    // the middle of tile (1, 1) builds that tile's alone.
    assert_eq!(sight.tiles_built(), (0, 0));
    let middle = DVec3::new(6.0 * BLOCK_SIZE_M, 6.0 * BLOCK_SIZE_M, 1_000.0);
    sight.crossed(middle, middle + DVec3::X * 100.0, true, |_, _, _, _| {
        Met::Counted(0.0)
    });
    assert_eq!(sight.tiles_built(), (1, 1));
    check(&mut sight, &members, &[], &mut rand, 0);
    assert_eq!(sight.tiles_built(), (9, 9));
    // Five generations go, in four tiles; two join the block (5, 6), tile (1, 1), beside
    // its old generation (which then goes too, as a weather change dissipates it).
    let gone: Vec<u64> = [0, 13, 50, 77, 143, 66].map(|k| members[k].1).to_vec();
    let mut living: Vec<SightMember> = members
        .iter()
        .filter(|m| !gone.contains(&m.1))
        .cloned()
        .collect();
    for serial in [1_000, 1_001] {
        living.push(generation(BlockIndex::new(5, 6), serial, &mut rand));
    }
    assert_eq!(sight.update(living.iter().map(|m| (m.0, m.1, &m.2))), 1);
    check(&mut sight, &living, &gone, &mut rand, 10_000);
    // The two that joined have a part of their own: the tile was not built again whole.
    assert_eq!(sight.tiles_built(), (9, 10));
    // A tile that lost more than half its boxes' generations is built again.
    let tile_00: Vec<u64> = living
        .iter()
        .filter(|m| m.0.i < 4 && m.0.j < 4)
        .map(|m| m.1)
        .collect();
    let left: Vec<SightMember> = living
        .iter()
        .filter(|m| !tile_00[..12].contains(&m.1))
        .cloned()
        .collect();
    assert_eq!(sight.update(left.iter().map(|m| (m.0, m.1, &m.2))), 1);
    check(&mut sight, &left, &gone, &mut rand, 20_000);
    assert_eq!(sight.tiles_built(), (9, 10));
    // Generations joining tile (2, 2) one by one, a line through it after each: a part
    // each, until one more than `MAX_PARTS` builds the tile whole again.
    let mut left = left;
    let corner = DVec3::new(10.0 * BLOCK_SIZE_M, 10.0 * BLOCK_SIZE_M, 1_000.0);
    let mut parts = Vec::new();
    for serial in 2_000..2_000 + MAX_PARTS as u64 {
        left.push(generation(BlockIndex::new(9, 9), serial, &mut rand));
        assert_eq!(sight.update(left.iter().map(|m| (m.0, m.1, &m.2))), 1);
        sight.crossed(corner, corner + DVec3::Y * 100.0, true, |_, _, _, _| {
            Met::Counted(0.0)
        });
        parts.push(sight.tiles_built().1);
    }
    assert_eq!(parts, [11, 12, 13, 10]);
    check(&mut sight, &left, &gone, &mut rand, 30_000);
}

/// The cells' heights rounded to `f32` hold the heights they round: the bottom at or below,
/// the top at or above, one `f32` step at most away (so a cell the walk passes over on them is
/// one it passes over on its own heights), the infinities of an empty cell kept.
#[test]
fn a_cells_rounded_heights_hold_its_own() {
    let mut rand = xorshift(0x1234_5678_9abc_def1u64);
    for k in 0..20_000 {
        let x = match k % 4 {
            0 => (rand() - 0.3) * 20_000.0,
            1 => (rand() * 20_000.0).round(),
            2 => f64::from((rand() * 15_000.0) as f32),
            _ => (rand() - 0.5) * 1e-3,
        };
        let (down, up) = (down_f32(x), up_f32(x));
        assert!(f64::from(down) <= x && x <= f64::from(up), "{x}");
        assert!(f64::from(down.next_up()) > x && f64::from(up.next_down()) < x || down == up);
    }
    assert_eq!(down_f32(f64::INFINITY), f32::INFINITY);
    assert_eq!(up_f32(f64::NEG_INFINITY), f32::NEG_INFINITY);
}

/// The cheap test of a tile's bounds passes over only what the slab test does: on 200,000
/// random boxes and segments (level, upright and axis-aligned ones among them, some ending on
/// a box's face), every box the slab test finds entered before the horizon may be entered,
/// and most it finds missed are passed over.
#[test]
fn the_cheap_bounds_test_passes_over_only_what_the_slab_test_does() {
    let mut rand = xorshift(0x5851_f42d_4c95_7f2du64);
    let (mut missed, mut passed_over) = (0, 0);
    for k in 0..200_000 {
        let lo = DVec3::new(rand() * 20_000.0, rand() * 20_000.0, rand() * 5_000.0);
        let hi = lo + DVec3::new(rand() * 8_000.0, rand() * 8_000.0, rand() * 3_000.0);
        let a = DVec3::new(rand() * 30_000.0, rand() * 30_000.0, rand() * 8_000.0) - 5_000.0;
        let mut b = a + DVec3::new(
            (rand() - 0.5) * 30_000.0,
            (rand() - 0.5) * 30_000.0,
            (rand() - 0.5) * 8_000.0,
        );
        match k % 6 {
            0 => b.z = a.z,
            1 => b = a.with_z(a.z + 5_000.0),
            2 => b.y = a.y,
            // Ending on the box's face: entered at t = 1 to the bit, or nearly.
            3 => b.x = lo.x,
            _ => {}
        }
        let horizon = if k % 3 == 0 { f64::INFINITY } else { rand() };
        let cull = Cull::new(a, b);
        let may = cull.may_enter(lo, hi, horizon);
        match slab(a, b, lo, hi) {
            Some((t0, _)) if t0 < horizon => assert!(may, "{k}: {a} to {b}, {lo}..{hi}"),
            _ => {
                missed += 1;
                passed_over += usize::from(!may);
            }
        }
    }
    assert!(passed_over * 100 > missed * 99, "{passed_over} of {missed}");
}

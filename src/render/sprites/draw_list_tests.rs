//! Tests of `draw_list`'s CPU rules (the GPU side is in `tests/sprites.rs`).

use super::*;
use crate::render::scene::SkySprite;
use crate::shading::ColourLevels;

pub(in crate::render) fn cache() -> VertexCacheSettings {
    RenderSettings::default().vertex_cache
}

#[test]
fn the_order_ages_and_moves_out_by_distance_and_sooner_while_fading_if_set() {
    let c = cache();
    let at = (DVec3::new(0.0, -1000.0, 0.0), 10.0);
    // 1 km from its edge: 5 m + 2% = 25 m of movement, 2 s x 1.5 = 3 s of age.
    let moved = |m: f64| DVec3::new(m, -1000.0, 0.0);
    assert!(!used_up((at, false), moved(24.0), 10.0, 1000.0, &c, 1.0));
    assert!(used_up((at, false), moved(26.0), 10.0, 1000.0, &c, 1.0));
    assert!(!used_up((at, false), moved(0.0), 12.9, 1000.0, &c, 1.0));
    assert!(used_up((at, false), moved(0.0), 13.1, 1000.0, &c, 1.0));
    // 10 km out the same 26 m keeps the order (limit 205 m).
    assert!(!used_up((at, false), moved(26.0), 10.0, 10_000.0, &c, 1.0));
    // Fading, as shipped: as a steady cloud (the fade is the GPU's), 2 s x 6 = 12 s at 10 km.
    assert!(!used_up((at, true), moved(0.0), 21.9, 10_000.0, &c, 1.0));
    assert!(used_up((at, true), moved(0.0), 22.1, 10_000.0, &c, 1.0));
    // With `fading_max_age_s` 0.25: every 0.25 s whatever the distance.
    let c = VertexCacheSettings {
        fading_max_age_s: Some(0.25),
        ..c
    };
    assert!(used_up((at, true), moved(0.0), 10.3, 10_000.0, &c, 1.0));
    assert!(!used_up((at, true), moved(0.0), 10.2, 10_000.0, &c, 1.0));
    // Time running backwards (a new flight in the same sky) recomputes.
    assert!(used_up((at, false), moved(0.0), 9.0, 1000.0, &c, 1.0));
}

#[test]
fn locks_start_once_stay_and_go_when_the_camera_leaves() {
    let mut locks = Locks::default();
    let north = facing_towards(Vec3::Y);
    locks.begin();
    locks.keep_or_lock(7, north);
    locks.end();
    assert!(locks.take_changed());
    assert_eq!(locks.gpu().len(), 1);
    // Still inside: the facing it locked with stays, whatever is offered now.
    locks.begin();
    locks.keep_or_lock(7, facing_towards(Vec3::X));
    locks.end();
    assert!(!locks.take_changed());
    let gpu = locks.gpu();
    assert_eq!((gpu[0].sprite, gpu[0].normal), (7, Vec3::Y.to_array()));
    // Not seen this frame: released.
    locks.begin();
    locks.end();
    assert!(locks.take_changed());
    assert!(locks.gpu().is_empty());
    // A block that goes takes its locks with it.
    locks.begin();
    locks.keep_or_lock(3, north);
    locks.keep_or_lock(40, north);
    locks.end();
    locks.release(0..10);
    assert_eq!(locks.gpu().len(), 1);
    assert_eq!(locks.gpu()[0].sprite, 40);
}

#[test]
fn facings_keep_up_up_and_upright_ones_level() {
    let f = facing_towards(Vec3::new(1.0, 1.0, 0.5).normalize());
    assert!(f.right.z.abs() < 1e-6, "right stays horizontal");
    assert!(f.up.z > 0.0 && f.right.dot(f.normal).abs() < 1e-6);
    // Straight below: falls back to east.
    assert_eq!(facing_towards(-Vec3::Z).right, Vec3::X);
    let u = upright_facing(Vec3::new(0.0, -300.0, -800.0));
    assert_eq!(u.up, Vec3::Z);
    assert!((u.normal - -Vec3::Y).length() < 1e-6);
}

/// A cloud of 40 sprites on a 12 m spiral (smaller than any tolerance of a whole-cloud order).
pub(in crate::render) fn small_cloud() -> SkyCloud {
    let sprites = (0..40)
        .map(|k| {
            let a = k as f32 * 2.4;
            SkySprite {
                offset_m: Vec3::new(a.cos(), a.sin(), 0.3 * (k % 7) as f32)
                    * (2.0 + 0.25 * k as f32),
                width_m: 20.0,
                height_m: 20.0,
                rotation_deg: 0.0,
                cell: 4,
                group: 0,
                alpha_morph: 1.0,
                radius_fraction: k as f32 / 40.0,
                upright: false,
                precipitation: false,
                base: false,
            }
        })
        .collect();
    SkyCloud {
        centre_m: DVec3::ZERO,
        sprites,
        group_centres_m: vec![Vec3::ZERO],
        colour_levels: ColourLevels::even(0.0, 100.0, [[1.0; 4]; 5]),
        flat: false,
        sunlit_depth_m: 0.0,
        shaded_base_m: 0.0,
        floor_m: f32::MIN,
        floor_slab_m: [0.0; 2],
        optical_density: 1.0,
    }
}

/// The renderer's integer-key order (`order_into`) is the CPU reference's
/// (`sprites_back_to_front`), and both put every sprite no nearer than the next: deleting either
/// sort fails here, inside one cloud, without a GPU.
#[test]
fn sprites_of_one_cloud_are_ordered_back_to_front_by_both_sorts() {
    let cloud = small_cloud();
    for cam in [
        Vec3::new(30.0, -5.0, 2.0),
        Vec3::new(-3.0, 1.0, 0.5),
        Vec3::ZERO,
    ] {
        let reference = sprites_back_to_front(&cloud, cam);
        assert_eq!(reference.len(), cloud.sprites.len());
        for w in reference.windows(2) {
            assert!(w[0].1 >= w[1].1, "camera {cam}: {reference:?}");
        }
        let mut slots = vec![0u32; cloud.sprites.len()];
        let offsets: Vec<Vec3> = cloud.sprites.iter().map(|s| s.offset_m).collect();
        order_into(&offsets, cam, 100, &mut slots, &mut SortKeys::new());
        let from_slots: Vec<usize> = slots.iter().map(|s| (s - 100) as usize).collect();
        let from_reference: Vec<usize> = reference.iter().map(|r| r.0).collect();
        assert_eq!(from_slots, from_reference, "camera {cam}");
        // Not the identity: the spiral's order depends on where the camera is.
        assert_ne!(from_reference, (0..40).collect::<Vec<_>>(), "camera {cam}");
    }
}

/// Sorting again from a cloud's previous order (the insertion sort of a camera that moved a
/// little), from a far-off camera's (a full sort after too many moves) or from slots that hold
/// no order of the cloud (duplicates, another block's slots) gives the order a fresh sort does.
#[test]
fn an_order_sorted_again_from_any_slots_is_the_fresh_order() {
    let cloud = small_cloud();
    let offsets: Vec<Vec3> = cloud.sprites.iter().map(|s| s.offset_m).collect();
    let n = offsets.len();
    let fresh = |cam: Vec3| {
        let mut slots = vec![u32::MAX; n];
        order_into(&offsets, cam, 100, &mut slots, &mut SortKeys::new());
        slots
    };
    let mut keys = SortKeys::new();
    let near = Vec3::new(30.0, -5.0, 2.0);
    let moved = near + Vec3::new(0.7, 0.4, -0.2);
    let opposite = -near;
    let mut duplicates = vec![100u32; n];
    duplicates[n - 1] = 101;
    let elsewhere: Vec<u32> = (0..n as u32).map(|i| 5_000 + i).collect();
    for (from, cam) in [
        (fresh(near), moved),
        (fresh(near), opposite),
        (duplicates, moved),
        (elsewhere, moved),
    ] {
        let mut slots = from;
        order_into(&offsets, cam, 100, &mut slots, &mut keys);
        assert_eq!(slots, fresh(cam), "camera {cam}");
    }
    // The moved camera's order differs from the first (the insertion sort had work to do).
    assert_ne!(fresh(near), fresh(moved));
}

/// Blocks as far from the camera as each other (a camera on the corner of four blocks) come in
/// the same order whatever ids they were given: the clouds stage hands ids out as its background
/// generation finishes, in an order that differs from run to run, and the overlapping sprites of
/// two such blocks blend differently in either order (a patch of a low deck seen from above
/// changed by up to 17/255 between runs of the same `skycast render`).
#[test]
fn equally_far_blocks_are_ordered_by_place_not_by_id() {
    let corners = [
        (2000.0, 2000.0),
        (-2000.0, 2000.0),
        (-2000.0, -2000.0),
        (2000.0, -2000.0),
    ];
    let order_with = |ids: [u64; 4]| {
        let blocks: Blocks = corners
            .iter()
            .zip(ids)
            .map(|(&(x, y), id)| {
                let block = crate::render::scene::SkyBlock {
                    id,
                    centre_m: DVec3::new(x, y, 1000.0),
                    clouds: vec![small_cloud()],
                };
                let mut resident = Resident::new(block, Default::default());
                resident.place = Some((0..1, 0..1));
                (id, resident)
            })
            .collect();
        let order = blocks_back_to_front(&blocks, &ids, DVec3::ZERO);
        assert!(order.iter().all(|o| o.0 == order[0].0), "{order:?}");
        order
            .iter()
            .map(|&(_, id)| blocks[&id].block.centre_m.truncate())
            .collect::<Vec<_>>()
    };
    assert_eq!(order_with([1, 2, 3, 4]), order_with([4, 3, 2, 1]));
    assert_eq!(order_with([1, 2, 3, 4]), order_with([3, 1, 4, 2]));
}

/// Two blocks of a row of 4 km blocks, west and east of x = 0, 6 km north, each of 4 x 4
/// clouds (500 m in radius) on a 1 km lattice, placed, with their lists back to front from
/// `eye_m` as [`recheck`] writes them; a deck's cells (`sunlit_depth_m` set) when `deck`.
fn two_blocks(eye_m: DVec3, deck: bool) -> Blocks {
    let mut base = 0u32;
    let mut slot = 0u32;
    [(1u64, -2000.0), (2, 2000.0)]
        .into_iter()
        .map(|(id, x)| {
            let centre = DVec3::new(x, 6000.0, 1000.0);
            let clouds = (0..16)
                .map(|k| SkyCloud {
                    // A deck's cell: sprites 400 m wide up to 300 m from its centre.
                    sprites: small_cloud()
                        .sprites
                        .into_iter()
                        .map(|s| SkySprite {
                            offset_m: s.offset_m * 25.0,
                            width_m: 400.0,
                            height_m: 400.0,
                            ..s
                        })
                        .collect(),
                    centre_m: centre
                        + DVec3::new(
                            (k % 4) as f64 * 1000.0 - 1500.0,
                            (k / 4) as f64 * 1000.0 - 1500.0,
                            0.0,
                        ),
                    sunlit_depth_m: if deck { 60.0 } else { 0.0 },
                    ..small_cloud()
                })
                .collect();
            let block = crate::render::scene::SkyBlock {
                id,
                centre_m: centre,
                clouds,
            };
            let mut r = Resident::new(block, Default::default());
            let (sprites, clouds) = (base, slot);
            for state in r.clouds.iter_mut() {
                state.sprite_base = base;
                state.cloud_slot = slot;
                base += state.sprites;
                slot += 1;
            }
            r.place = Some((sprites..base, clouds..slot));
            let mut order: Vec<(usize, f64)> = r
                .clouds
                .iter()
                .enumerate()
                .map(|(ci, c)| (ci, (c.centre_m - eye_m).length()))
                .collect();
            order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            let mut first = 0;
            for (ci, _) in order {
                let c = &r.clouds[ci];
                r.list.push(GpuListCloud {
                    cloud: c.cloud_slot,
                    first,
                    order_base: c.sprite_base,
                    stride: 0,
                });
                first += c.sprites;
            }
            r.list_sprites = first;
            (id, r)
        })
        .collect()
}

/// The clouds of the frame's draw list in drawing order, with their squared distances from
/// `eye_m`, read back as the shader reads it (an entry's sprites run on from its first
/// cloud's `first`).
fn drawn_clouds(blocks: &Blocks, out: &[GpuDrawBlock], eye_m: DVec3) -> Vec<(u32, f64)> {
    let lists: HashMap<u32, (GpuListCloud, DVec3)> = blocks
        .values()
        .flat_map(|r| {
            let start = r.place.as_ref().unwrap().1.start;
            r.list.iter().enumerate().map(move |(k, e)| {
                let c = &r.clouds[(e.cloud - start) as usize];
                (start + k as u32, (*e, c.centre_m))
            })
        })
        .collect();
    out.iter()
        .flat_map(|d| (d.list_base..d.list_base + d.list_len).map(|at| lists[&at]))
        .map(|(e, c)| (e.cloud, (c - eye_m).length_squared()))
        .collect()
}

/// The draw list of every block of `blocks` seen from `eye_m`, back to front as the sky camera
/// orders them: its sprites and entries.
fn entries_of(blocks: &Blocks, eye_m: DVec3, seams: &mut Seams) -> (u32, Vec<GpuDrawBlock>) {
    entries_seen(blocks, (eye_m, None), seams)
}

/// [`entries_of`] keeping to what `sight` sees.
fn entries_seen(
    blocks: &Blocks,
    (eye_m, sight): (DVec3, Option<&Sight>),
    seams: &mut Seams,
) -> (u32, Vec<GpuDrawBlock>) {
    let mut order: Vec<(f64, &Resident)> = blocks
        .values()
        .map(|r| ((r.centre_m() - eye_m).length_squared(), r))
        .collect();
    order.sort_by(|a, b| farthest_first(*a, *b));
    let listed: Vec<Listed> = order
        .iter()
        .map(|&(d2, r)| Listed::resident(d2, r))
        .collect();
    let mut out = Vec::new();
    let total = draw_entries(&listed, (eye_m, sight), seams, &mut out);
    (total, out)
}

/// With the camera on the boundary between two blocks (equally far), their clouds are drawn
/// interleaved farthest first, not one block's all over the other's (the seam along the
/// boundary, `a_deck_shows_no_seam_along_the_block_boundary_through_the_camera` in
/// tests/render.rs); each cloud once, the entries' sprites following on. From the middle of a
/// block (farther from the boundary than their clouds' radius) the blocks are drawn whole, one
/// entry each; and so are two blocks of heaped clouds (not decks) wherever the camera is.
#[test]
fn the_clouds_of_two_blocks_the_camera_stands_between_are_drawn_interleaved() {
    for (eye, deck, whole) in [
        (DVec3::new(0.0, 0.0, 3000.0), true, false),
        (DVec3::new(300.0, 0.0, 3000.0), true, false),
        (DVec3::new(-2000.0, 0.0, 3000.0), true, true),
        (DVec3::new(0.0, 0.0, 3000.0), false, true),
    ] {
        let blocks = two_blocks(eye, deck);
        let (total, out) = entries_of(&blocks, eye, &mut Seams::default());
        assert_eq!(total, 32 * 40, "camera {eye}");
        assert_eq!(out.len() == 2, whole, "camera {eye}: {} entries", out.len());
        // Each entry's sprites follow the last's.
        for w in out.windows(2) {
            let lists = |d: &GpuDrawBlock| {
                let r = blocks
                    .values()
                    .find(|r| r.place.as_ref().unwrap().1.contains(&d.list_base))
                    .unwrap();
                let k = (d.list_base - r.place.as_ref().unwrap().1.start) as usize;
                let end = r
                    .list
                    .get(k + d.list_len as usize)
                    .map_or(r.list_sprites, |e| e.first);
                end - r.list[k].first
            };
            assert_eq!(w[1].first, w[0].first + lists(&w[0]), "camera {eye}");
        }
        let clouds = drawn_clouds(&blocks, &out, eye);
        let mut seen: Vec<u32> = clouds.iter().map(|c| c.0).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..32).collect::<Vec<_>>(), "camera {eye}");
        if !whole {
            for w in clouds.windows(2) {
                assert!(w[0].1 >= w[1].1, "camera {eye}: {clouds:?}");
            }
        }
    }
}

/// A group's merge is kept while its blocks' lists are: from a camera 300 m east of where the
/// lists were sorted, a frame that keeps them draws the merge it made there (the draw list a
/// block's kept list would give, not one merged anew); once one of the lists is sorted again
/// (its serial changes), the merge is made anew, from where the camera is now.
#[test]
fn a_merge_is_kept_while_the_blocks_lists_are_and_made_anew_when_one_is_sorted_again() {
    let (here, there) = (DVec3::new(0.0, 0.0, 3000.0), DVec3::new(300.0, 0.0, 3000.0));
    let mut blocks = two_blocks(here, true);
    let entries = |blocks: &Blocks, eye: DVec3, seams: &mut Seams| {
        let (total, out) = entries_of(blocks, eye, seams);
        assert_eq!(total, 32 * 40, "camera {eye}");
        // What the shader reads: which clouds, in which order, from which sprite.
        out.iter()
            .map(|d| (d.list_base, d.list_len, d.first))
            .collect::<Vec<_>>()
    };
    let made_here = entries(&blocks, here, &mut Seams::default());
    let made_there = entries(&blocks, there, &mut Seams::default());
    assert_ne!(made_here, made_there, "the camera's move changes the merge");
    let mut seams = Seams::default();
    assert_eq!(entries(&blocks, here, &mut seams), made_here);
    assert_eq!(entries(&blocks, there, &mut seams), made_here);
    blocks.values_mut().next().unwrap().list_serial = 7;
    assert_eq!(entries(&blocks, there, &mut seams), made_there);
}

/// Clouds out of view are left out of the draw list, the others kept in their order: a
/// camera looking north-east over the two blocks sees some of their 32 clouds. Every cloud
/// left out has each of its sprites' quads (any facing, a corner at most `sqrt(2)` half sides
/// from the sprite's centre) wholly outside the view; every one kept reaches into it (the
/// bound is not far from the quads); the entries' sprites follow on; and the clouds drawn are
/// drawn in the order they are drawn without the culling, interleaved along the seam or not.
#[test]
fn clouds_wholly_out_of_view_are_left_out_and_the_rest_keep_their_order() {
    use crate::render::camera::Camera;
    for (eye, deck) in [
        (DVec3::new(0.0, 0.0, 3000.0), true),
        (DVec3::new(-2000.0, 0.0, 3000.0), true),
        (DVec3::new(0.0, 0.0, 3000.0), false),
    ] {
        let camera = Camera {
            position_m: eye,
            heading_deg: 30.0,
            pitch_deg: -25.0,
            fov_y_deg: 30.0,
            aspect: 1.0,
            near_m: 1.0,
            far_m: 100_000.0,
        };
        let frustum = camera.frustum_relative();
        let blocks = two_blocks(eye, deck);
        let (all, whole) = entries_of(&blocks, eye, &mut Seams::default());
        for earth_radius_m in [0.0, 6.371e6] {
            let sight = Sight {
                frustum: &frustum,
                earth_radius_m,
            };
            let (total, out) = entries_seen(&blocks, (eye, Some(&sight)), &mut Seams::default());
            let drawn = drawn_clouds(&blocks, &out, eye);
            let kept: Vec<u32> = drawn.iter().map(|c| c.0).collect();
            let in_order: Vec<u32> = drawn_clouds(&blocks, &whole, eye)
                .iter()
                .map(|c| c.0)
                .filter(|c| kept.contains(c))
                .collect();
            assert_eq!(kept, in_order, "camera {eye}");
            assert!(total < all && total > 0, "camera {eye}: {total} of {all}");
            assert_eq!(total, kept.len() as u32 * 40, "camera {eye}");
            for w in out.windows(2) {
                assert!(w[1].first > w[0].first, "camera {eye}");
            }
            for r in blocks.values() {
                for (state, cloud) in r.clouds.iter().zip(&r.block.clouds) {
                    let quads_seen = cloud.sprites.iter().any(|s| {
                        let centre = (cloud.centre_m - eye).as_vec3() + s.offset_m;
                        let reach = 0.5 * std::f32::consts::SQRT_2 * s.width_m.max(s.height_m);
                        frustum.sees_sphere(centre, reach)
                    });
                    let sphere = (cloud.centre_m - eye).as_vec3();
                    let near_view = frustum.sees_sphere(sphere, 1.5 * state.radius_m);
                    let drawn = kept.contains(&state.cloud_slot);
                    assert!(
                        drawn || !quads_seen,
                        "camera {eye}: cloud {} left out",
                        state.cloud_slot
                    );
                    assert!(
                        !drawn || near_view,
                        "camera {eye}: cloud {} drawn",
                        state.cloud_slot
                    );
                }
            }
        }
    }
}

/// A block whose clouds' sphere lies just outside the view but whose quads' corners (up to
/// `sqrt(2)` half sides from a sprite's centre, the sphere counting one) reach into it is in
/// view: culled, its corner would pop in at the view's edge. One farther out than the corners
/// reach is not.
#[test]
fn a_block_showing_only_its_quads_corners_at_the_views_edge_is_in_view() {
    use crate::render::camera::Camera;
    let eye = DVec3::new(0.0, 0.0, 3000.0);
    // Looking east: the block north-west of the eye is out of view.
    let camera = Camera {
        position_m: eye,
        heading_deg: 90.0,
        pitch_deg: 0.0,
        fov_y_deg: 30.0,
        aspect: 1.0,
        near_m: 1.0,
        far_m: 100_000.0,
    };
    let frustum = camera.frustum_relative();
    let mut blocks = two_blocks(eye, false);
    let r = blocks.get_mut(&1).expect("block 1");
    let centre = (r.centre_m() - eye).as_vec3();
    // How far its centre lies outside the view: the least sphere the frustum sees.
    let (mut lo, mut hi) = (0.0f32, 20_000.0f32);
    assert!(!frustum.sees_sphere(centre, lo) && frustum.sees_sphere(centre, hi));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if frustum.sees_sphere(centre, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let outside_m = hi;
    let half_side = r.largest_half_side_m;
    assert_eq!(half_side, 200.0);
    let corner_reach = (std::f32::consts::SQRT_2 - 1.0) * half_side;
    for earth_radius_m in [0.0, 6.371e6] {
        let sight = Sight {
            frustum: &frustum,
            earth_radius_m,
        };
        // The sphere 50 m short of the view, the corners 33 m into it.
        r.radius_m = f64::from(outside_m - 50.0);
        assert!(!frustum.sees_sphere(centre, r.radius_m as f32));
        assert!(
            block_in_view(r, eye, &sight),
            "earth radius {earth_radius_m}"
        );
        // The corners, and the bend, short of it too.
        r.radius_m = f64::from(outside_m - corner_reach - 100.0);
        assert!(
            !block_in_view(r, eye, &sight),
            "earth radius {earth_radius_m}"
        );
    }
}

//! Tests of `vertices`.

use super::*;
use crate::shading::{ColourLevels, TimeOfDayTable};

fn blocks() -> Vec<SkyBlock> {
    let cloud = |x: f64| SkyCloud {
        centre_m: DVec3::new(x, 5000.0, 1500.0),
        sprites: (0..20)
            .map(|k| {
                square_sprite(
                    Vec3::new(k as f32 * 20.0, 0.0, (k % 5) as f32 * 40.0),
                    200.0,
                    k as u8,
                    0,
                )
            })
            .collect(),
        group_centres_m: vec![Vec3::new(200.0, 0.0, 100.0)],
        colour_levels: ColourLevels::even(1500.0, 1800.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
        flat: false,
    };
    vec![SkyBlock {
        id: 1,
        centre_m: DVec3::new(0.0, 5000.0, 1500.0),
        clouds: (0..10).map(|i| cloud(i as f64 * 1500.0)).collect(),
    }]
}

fn lighting() -> Lighting {
    let table = TimeOfDayTable::default();
    Lighting {
        sun_dir: Vec3::new(0.0, -0.6, 0.8),
        time_of_day: table.at(40.0),
        mapping: table.directional_mapping,
        forward: table.forward_scattering,
    }
}

#[test]
fn still_camera_recomputes_nothing_after_the_first_frame_and_a_moved_one_does() {
    let (b, l, s) = (blocks(), lighting(), RenderSettings::default());
    let mut builder = SpriteVertexBuilder::new();
    let cam = DVec3::new(0.0, 0.0, 1000.0);
    let first = builder.update(&b, cam, 0.0, &l, &s);
    assert_eq!(
        (
            first.clouds_drawn,
            first.clouds_recomputed,
            first.sprites_drawn
        ),
        (10, 10, 200)
    );
    let first_vertices = builder.vertices().to_vec();
    for frame in 1..30 {
        let still = builder.update(&b, cam, frame as f64 / 30.0, &l, &s);
        assert_eq!(still.clouds_recomputed, 0, "frame {frame}");
        assert_eq!(still.cache_hit_rate, 1.0);
    }
    assert_eq!(builder.vertices(), &first_vertices[..]);
    // Handing the same blocks again (as a host does when the block set changes) keeps them.
    builder.retain(&b);
    assert_eq!(builder.update(&b, cam, 1.0, &l, &s).clouds_recomputed, 0);
    // Clouds drifting with the wind and a camera flying along with them: nothing moved
    // relative to each other, nothing recomputes.
    let drift = DVec3::new(400.0, -250.0, 0.0);
    let mut drifted = b.clone();
    for c in drifted.iter_mut().flat_map(|b| b.clouds.iter_mut()) {
        c.centre_m += drift;
    }
    assert_eq!(
        builder
            .update(&drifted, cam + drift, 1.0, &l, &s)
            .clouds_recomputed,
        0
    );
    // 300 m is past the threshold of every cloud (at most 5 m + 2% of ~19 km).
    let moved = builder.update(&b, cam + DVec3::new(0.0, 300.0, 0.0), 1.0, &l, &s);
    assert_eq!(moved.clouds_recomputed, 10);
    // 150 m more: past the threshold of the near clouds (about 90 m at 4 km) only, not of
    // the far ones (about 280 m at 14 km).
    let nudged = builder.update(&b, cam + DVec3::new(0.0, 450.0, 0.0), 1.1, &l, &s);
    assert!(
        nudged.clouds_recomputed > 0 && nudged.clouds_recomputed < 10,
        "{nudged:?}"
    );
    // Uncached, every frame recomputes everything.
    let mut off = s;
    off.vertex_cache.enabled = false;
    let again = builder.update(&b, cam + DVec3::new(0.0, 450.0, 0.0), 1.1, &l, &off);
    assert_eq!(again.clouds_recomputed, 10);
}

/// Seen with the sun behind it, a cloud's rim is brighter than with the sun behind the
/// camera by the forward-scattering lobe; its core hardly changes (Wang's shading stays).
#[test]
fn the_rim_of_a_cloud_against_the_sun_glows() {
    let b = blocks();
    let s = RenderSettings::default();
    let cam = DVec3::new(0.0, 0.0, 1500.0);
    // The first cloud is 5 km north: the sun low in the north, then low in the south.
    let brightest = |sun_dir: Vec3, forward: ForwardScattering| {
        let l = Lighting {
            sun_dir: sun_dir.normalize(),
            forward,
            ..lighting()
        };
        let mut builder = SpriteVertexBuilder::new();
        builder.update(&b[..], cam, 0.0, &l, &s);
        builder
            .vertices()
            .iter()
            .map(|v| v.colour[0])
            .fold(0.0, f32::max)
    };
    let none = ForwardScattering {
        strength: 0.0,
        ..ForwardScattering::default()
    };
    let on = ForwardScattering::default();
    let against = Vec3::new(0.0, 1.0, 0.05);
    let behind = Vec3::new(0.0, -1.0, 0.05);
    let glow = brightest(against, on) - brightest(against, none);
    let other_way = brightest(behind, on) - brightest(behind, none);
    assert!(glow > 0.1, "against the sun: +{glow}");
    assert!(other_way < 0.01, "sun behind the camera: +{other_way}");
}

/// An upright sprite keeps its bottom edge level and turns only about the vertical: seen
/// from the side it is whole, from 25 degrees below it is fading, from 40 degrees below it is
/// gone (fade 15..35 degrees); a camera-facing sprite beside it is whole from everywhere.
#[test]
fn upright_sprites_stay_level_and_fade_seen_from_below() {
    let mut upright = square_sprite(Vec3::ZERO, 200.0, 3, 0);
    upright.upright = true;
    let cloud = SkyCloud {
        centre_m: DVec3::new(0.0, 3000.0, 1500.0),
        sprites: vec![upright, square_sprite(Vec3::X * 600.0, 200.0, 3, 0)],
        group_centres_m: vec![Vec3::ZERO],
        colour_levels: ColourLevels::even(1400.0, 1700.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
        flat: false,
    };
    let b = vec![SkyBlock {
        id: 1,
        centre_m: cloud.centre_m,
        clouds: vec![cloud],
    }];
    let (l, s) = (lighting(), RenderSettings::default());
    let alphas = |elevation_deg: f64| {
        let cam = DVec3::new(0.0, 3000.0, 1500.0)
            + DVec3::new(0.0, -1.0, 0.0) * 2000.0 * elevation_deg.to_radians().cos()
            - DVec3::Z * 2000.0 * elevation_deg.to_radians().sin();
        let mut builder = SpriteVertexBuilder::new();
        builder.update(&b, cam, 0.0, &l, &s);
        let v = builder.vertices().to_vec();
        // The upright sprite's corners are those nearest x = 0.
        let quads: Vec<&[GpuSpriteVertex]> = v.chunks(4).collect();
        let up = quads
            .iter()
            .find(|q| q[0].position_m[0].abs() < 150.0)
            .copied();
        (up.map(|q| q.to_vec()), quads.len())
    };
    let (side, n) = alphas(0.0);
    let side = side.expect("the upright sprite is drawn from the side");
    assert_eq!(n, 2);
    // Corners: top left, top right, bottom left, bottom right; the bottom edge is level and
    // the quad stands vertical.
    assert!((side[2].position_m[2] - side[3].position_m[2]).abs() < 1e-3);
    assert!((side[0].position_m[1] - side[2].position_m[1]).abs() < 1e-3);
    assert!((side[0].colour[3] - 1.0).abs() < 1e-3);
    let (fading, _) = alphas(25.0);
    let fading = fading.expect("still drawn at 25 degrees");
    assert!(
        fading[0].colour[3] > 0.2 && fading[0].colour[3] < 0.8,
        "{fading:?}"
    );
    assert!((fading[0].position_m[1] - fading[2].position_m[1]).abs() < 1e-3);
    let (gone, n) = alphas(40.0);
    assert!(
        gone.is_none() && n == 1,
        "from 40 degrees below only the other sprite"
    );
}

#[test]
fn sprites_are_sorted_back_to_front_and_face_the_camera() {
    let (b, l, s) = (blocks(), lighting(), RenderSettings::default());
    let mut builder = SpriteVertexBuilder::new();
    builder.update(&b, DVec3::new(0.0, 0.0, 1000.0), 0.0, &l, &s);
    let centres: Vec<Vec3> = builder
        .vertices()
        .chunks_exact(4)
        .map(|q| {
            q.iter()
                .map(|v| Vec3::from_array(v.position_m))
                .sum::<Vec3>()
                / 4.0
        })
        .collect();
    let dists: Vec<f32> = centres.iter().map(|c| c.length()).collect();
    // Clouds are far apart, so the whole list is back to front within a cloud's radius.
    assert!(dists.windows(2).all(|w| w[1] <= w[0] + 400.0), "{dists:?}");
    assert!(dists[0] > dists[dists.len() - 1] + 5000.0);
    for (q, c) in builder.vertices().chunks_exact(4).zip(&centres) {
        let a = Vec3::from_array(q[1].position_m) - Vec3::from_array(q[0].position_m);
        let b = Vec3::from_array(q[2].position_m) - Vec3::from_array(q[0].position_m);
        let normal = a.cross(b).normalize();
        assert!(
            normal.dot(c.normalize()).abs() > 0.999,
            "sprite does not face the camera"
        );
    }
}

#[test]
fn facing_locks_inside_half_the_radius_and_fades_with_the_angle() {
    let (l, s) = (lighting(), RenderSettings::default());
    let cloud = SkyCloud {
        centre_m: DVec3::new(0.0, 0.0, 1000.0),
        sprites: vec![square_sprite(Vec3::ZERO, 200.0, 0, 0)],
        group_centres_m: vec![Vec3::ZERO],
        colour_levels: ColourLevels::even(900.0, 1100.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
        flat: false,
    };
    let b = vec![SkyBlock {
        id: 1,
        centre_m: cloud.centre_m,
        clouds: vec![cloud],
    }];
    let mut builder = SpriteVertexBuilder::new();
    let mut off = s;
    off.vertex_cache.enabled = false;
    // 40 m south of the centre (inside 50 m = half the 100 m radius): locks facing north.
    builder.update(&b, DVec3::new(0.0, -40.0, 1000.0), 0.0, &l, &off);
    let locked: Vec<GpuSpriteVertex> = builder.vertices().to_vec();
    assert_eq!(locked.len(), 4);
    assert!(
        locked.iter().all(|v| (v.position_m[1] - 40.0).abs() < 1e-3),
        "plane faces the camera"
    );
    // Step to 30 m east of the centre, still inside: the facing stays, seen at ~53 degrees.
    builder.update(
        &b,
        DVec3::new(30.0, -40.0 + 40.0 * 0.5, 1000.0),
        0.1,
        &l,
        &off,
    );
    let v = builder.vertices();
    assert_eq!(v.len(), 4);
    let ys: Vec<f32> = v.iter().map(|v| v.position_m[1]).collect();
    assert!(
        ys.windows(2).all(|w| (w[0] - w[1]).abs() < 1e-3),
        "facing stayed locked: {ys:?}"
    );
    assert!(
        v[0].colour[3] < locked[0].colour[3] && v[0].colour[3] > 0.0,
        "faded with the angle"
    );
    // Beside it edge-on: gone.
    builder.update(&b, DVec3::new(45.0, -0.5, 1000.0), 0.2, &l, &off);
    assert!(builder.vertices().is_empty());
    // Out of the lock radius: faces the camera again, opaque.
    builder.update(&b, DVec3::new(300.0, 0.0, 1000.0), 0.3, &l, &off);
    assert_eq!(builder.vertices().len(), 4);
    assert!(
        builder
            .vertices()
            .iter()
            .all(|v| (v.position_m[0] + 300.0).abs() < 1e-3)
    );
}

#[test]
fn far_from_the_origin_the_vertices_are_as_precise_as_near_it() {
    let (l, s) = (lighting(), RenderSettings::default());
    let shifted = |offset: DVec3| -> Vec<GpuSpriteVertex> {
        let mut b = blocks();
        for block in &mut b {
            block.centre_m += offset;
            for c in &mut block.clouds {
                c.centre_m += offset;
            }
        }
        let mut builder = SpriteVertexBuilder::new();
        builder.update(&b, DVec3::new(0.0, 0.0, 1000.0) + offset, 0.0, &l, &s);
        builder.vertices().to_vec()
    };
    let near = shifted(DVec3::ZERO);
    let far = shifted(DVec3::new(250_000.0, -180_000.0, 0.0));
    assert_eq!(near.len(), far.len());
    for (a, b) in near.iter().zip(&far) {
        let d = Vec3::from_array(a.position_m) - Vec3::from_array(b.position_m);
        assert!(d.length() < 1e-3, "jitter of {} m 300 km out", d.length());
    }
}

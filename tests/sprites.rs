//! The sprites as the vertex shader builds them (Wang 2003 3.3, 5 and 6.1 on GPU-resident
//! sprites), read back from the GPU (`Sky::read_back_corners` runs the shader's own corner code):
//! the order cache, the back-to-front order, facing the camera, the facing lock and its fade,
//! upright base sprites, layer sprites seen from above, the forward-scattering rim, precision far
//! from the origin, each quad cut to the visible part of its sheet cell, and (in drawn frames) the
//! horizon haze. Small scenes on whatever adapter there is (lavapipe here).

use glam::{DVec2, DVec3, Vec3};
use skycast::demo::terrain::HeightField;
use skycast::demo::{DemoHost, Frame, headless};
use skycast::render::{
    BlockMotion, Camera, RenderSettings, SkyBlock, SkyCloud, SkyConfig, SkySprite, SpriteCorner,
    SpriteSheet, square_sprite,
};
use skycast::shading::{ColourLevels, ForwardScattering, SunPosition, TimeOfDayTable};
use skycast::weather::BlockWeather;

/// A rig: a tiny headless target (the corners do not depend on it) and the sky, with an opaque
/// sheet (no quad is cut).
fn host(table: TimeOfDayTable) -> DemoHost {
    let sheet = SpriteSheet {
        size_px: 4,
        mips: vec![vec![255; 64], vec![255; 16], vec![255; 4]],
    };
    host_with_sheet(table, sheet)
}

/// [`host`] with the sprite sheet `sheet`. Every cloud of a block in view is built, those out
/// of view too (`cull_out_of_view` off): these tests read every sprite's corners back, and the
/// lines of clouds they draw reach past the narrow view's sides.
fn host_with_sheet(table: TimeOfDayTable, sheet: SpriteSheet) -> DemoHost {
    let ground = HeightField::from_fn(DVec2::ZERO, 20_000.0, 9, |_| 0.0);
    let mut settings = RenderSettings::default();
    settings.clouds.cull_out_of_view = false;
    DemoHost::new(
        64,
        36,
        &ground,
        SkyConfig {
            targets: headless::TARGETS,
            settings,
            time_of_day: table,
            sheet,
        },
    )
    .unwrap_or_else(|e| panic!("sprite tests need an adapter: {e}"))
}

/// The sun 53 degrees up in the south (towards (0, -0.6, 0.8)).
const SUN: SunPosition = SunPosition {
    elevation_deg: 53.13,
    azimuth_deg: 180.0,
    declination_deg: 0.0,
};

/// Ten clouds of 20 sprites, 1.5 km apart along a line 5 km north, at 1,500 m.
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
        sunlit_depth_m: 0.0,
        shaded_base_m: 0.0,
        floor_m: f32::MIN,
        floor_slab_m: [0.0; 2],
        optical_density: 1.0,
    };
    vec![SkyBlock {
        id: 1,
        centre_m: DVec3::new(0.0, 5000.0, 1500.0),
        clouds: (0..10).map(|i| cloud(i as f64 * 1500.0)).collect(),
    }]
}

/// A cloud of `sprites` around `centre_m` with one shading group at its centre, lit from every
/// side (no deck, no shaded base), in the colour levels `colour_levels`.
fn plain_cloud(centre_m: DVec3, sprites: Vec<SkySprite>, colour_levels: ColourLevels) -> SkyCloud {
    SkyCloud {
        centre_m,
        sprites,
        group_centres_m: vec![Vec3::ZERO],
        colour_levels,
        flat: false,
        sunlit_depth_m: 0.0,
        shaded_base_m: 0.0,
        floor_m: f32::MIN,
        floor_slab_m: [0.0; 2],
        optical_density: 1.0,
    }
}

fn one_cloud(cloud: SkyCloud) -> Vec<SkyBlock> {
    vec![SkyBlock {
        id: 1,
        centre_m: cloud.centre_m,
        clouds: vec![cloud],
    }]
}

fn camera(host: &DemoHost, at: DVec3) -> Camera {
    host.camera(at, 0.0, 0.0)
}

/// Prepares a frame from `at` at sky time step `dt_s` and reads its corners back.
fn corners(host: &mut DemoHost, at: DVec3, dt_s: f64) -> Vec<SpriteCorner> {
    corners_looking(host, at, 0.0, dt_s)
}

/// [`corners`] with the camera looking north `pitch_deg` above the horizon.
fn corners_looking(host: &mut DemoHost, at: DVec3, pitch_deg: f64, dt_s: f64) -> Vec<SpriteCorner> {
    let cam = host.camera(at, 0.0, pitch_deg);
    host.sky.sky_mut().prepare(&host.gpu.queue, cam, &SUN, dt_s);
    host.sky
        .sky()
        .read_back_corners(&host.gpu.queue)
        .expect("corners read back")
}

/// How many sprites (quads of four corners, in drawing order) differ between two read-backs.
fn quads_differing(a: &[SpriteCorner], b: &[SpriteCorner]) -> usize {
    a.chunks(4).zip(b.chunks(4)).filter(|(a, b)| a != b).count()
}

fn centre(quad: &[SpriteCorner]) -> Vec3 {
    quad.iter().map(|c| c.rel_m).sum::<Vec3>() / 4.0
}

/// Wang 6.1 on the orders: a still camera re-sorts nothing after the first frame and draws the
/// same corners; handing the same blocks again or drifting them with the camera keeps the
/// cache; moving past the threshold (5 m + 2% of the distance) re-sorts, near clouds first.
#[test]
fn still_camera_resorts_nothing_after_the_first_frame_and_a_moved_one_does() {
    let mut host = host(TimeOfDayTable::default());
    host.sky.sky_mut().set_clouds(blocks());
    let cam = DVec3::new(0.0, 0.0, 1000.0);
    let at = |host: &DemoHost, p: DVec3| camera(host, p);
    let c0 = at(&host, cam);
    let first = host.sky.sky_mut().prepare(&host.gpu.queue, c0, &SUN, 0.0);
    assert_eq!(
        (
            first.clouds_drawn,
            first.clouds_recomputed,
            first.sprites_drawn
        ),
        (10, 10, 200)
    );
    let first_corners = host.sky.sky().read_back_corners(&host.gpu.queue).unwrap();
    for frame in 1..30 {
        let still = host
            .sky
            .sky_mut()
            .prepare(&host.gpu.queue, c0, &SUN, 1.0 / 30.0);
        assert_eq!(still.clouds_recomputed, 0, "frame {frame}");
        assert_eq!(still.cache_hit_rate, 1.0);
    }
    assert_eq!(
        host.sky.sky().read_back_corners(&host.gpu.queue).unwrap(),
        first_corners
    );
    // Handing the same blocks again (as a host does when the block set changes) keeps them.
    host.sky.sky_mut().set_clouds(blocks());
    let again = host.sky.sky_mut().prepare(&host.gpu.queue, c0, &SUN, 0.0);
    assert_eq!(again.clouds_recomputed, 0);
    // Clouds drifting with the wind and a camera flying along with them: nothing moved
    // relative to each other, nothing re-sorts.
    let drift = DVec3::new(400.0, -250.0, 0.0);
    host.sky.sky_mut().set_block_motion(
        1,
        BlockMotion {
            offset_m: drift,
            ..BlockMotion::default()
        },
    );
    let along = at(&host, cam + drift);
    assert_eq!(
        host.sky
            .sky_mut()
            .prepare(&host.gpu.queue, along, &SUN, 0.0)
            .clouds_recomputed,
        0
    );
    host.sky
        .sky_mut()
        .set_block_motion(1, BlockMotion::default());
    // 300 m is past the threshold of every cloud (at most 5 m + 2% of ~19 km).
    let moved = at(&host, cam + DVec3::new(0.0, 300.0, 0.0));
    assert_eq!(
        host.sky
            .sky_mut()
            .prepare(&host.gpu.queue, moved, &SUN, 0.0)
            .clouds_recomputed,
        10
    );
    // 150 m more: past the threshold of the near clouds (about 90 m at 4 km) only, not of
    // the far ones (about 280 m at 14 km).
    let nudged = at(&host, cam + DVec3::new(0.0, 450.0, 0.0));
    let stats = host
        .sky
        .sky_mut()
        .prepare(&host.gpu.queue, nudged, &SUN, 0.0);
    assert!(
        stats.clouds_recomputed > 0 && stats.clouds_recomputed < 10,
        "{stats:?}"
    );
    // Uncached, every frame re-sorts everything.
    host.sky.sky_mut().set_vertex_cache(false);
    let stats = host
        .sky
        .sky_mut()
        .prepare(&host.gpu.queue, nudged, &SUN, 0.0);
    assert_eq!(stats.clouds_recomputed, 10);
}

/// Every cloud's sprites are drawn farthest first (strictly by distance within each cloud, the
/// clouds farthest first), and every quad faces the camera.
#[test]
fn sprites_are_sorted_back_to_front_and_face_the_camera() {
    let mut host = host(TimeOfDayTable::default());
    host.sky.sky_mut().set_clouds(blocks());
    let quads = corners(&mut host, DVec3::new(0.0, 0.0, 1000.0), 0.0);
    assert_eq!(quads.len(), 200 * 4);
    let dists: Vec<f32> = quads.chunks(4).map(|q| centre(q).length()).collect();
    // Each cloud's 20 sprites in a row, each no nearer than the next.
    for (c, cloud) in dists.chunks(20).enumerate() {
        for w in cloud.windows(2) {
            assert!(
                w[0] >= w[1] - 1e-3,
                "cloud {c} not back to front: {cloud:?}"
            );
        }
        assert!(cloud[0] > cloud[19] + 20.0, "cloud {c}: {cloud:?}");
    }
    let cloud_first: Vec<f32> = dists.chunks(20).map(|c| c[0]).collect();
    assert!(
        cloud_first.windows(2).all(|w| w[0] > w[1]),
        "{cloud_first:?}"
    );
    for q in quads.chunks(4) {
        let a = q[1].rel_m - q[0].rel_m;
        let b = q[2].rel_m - q[0].rel_m;
        let normal = a.cross(b).normalize();
        assert!(
            normal.dot(centre(q).normalize()).abs() > 0.999,
            "sprite does not face the camera"
        );
        assert!(q.iter().all(|c| c.visible));
    }
}

/// Frames prepared and never drawn pile up their re-sorted orders in one patch (sent to the GPU
/// and scattered into place there by the next drawn frame); once it outgrows the patch buffer
/// the first drawn frame bound, the drawn frame still gets every order: the scatter pass reads
/// the grown buffer.
#[test]
fn orders_outgrowing_the_patch_buffer_still_reach_the_gpu() {
    let start = DVec3::new(0.0, 0.0, 1000.0);
    let mut piled = host(TimeOfDayTable::default());
    piled.sky.sky_mut().set_clouds(blocks());
    corners(&mut piled, start, 0.0);
    // Every frame moves 300 m, past every cloud's threshold: its 200 orders sorted again. Twenty
    // frames make 4,000 orders and their lists: more than the 16 kB the patch starts with, less
    // than the buffers themselves (past those the whole buffers would be written instead).
    let mut at = start;
    for _ in 0..20 {
        at.x += 300.0;
        let cam = camera(&piled, at);
        let stats = piled
            .sky
            .sky_mut()
            .prepare(&piled.gpu.queue, cam, &SUN, 1.0 / 30.0);
        assert_eq!(stats.sprites_recomputed, 200);
    }
    let after_pile = piled
        .sky
        .sky()
        .read_back_corners(&piled.gpu.queue)
        .expect("corners read back");
    let mut fresh = host(TimeOfDayTable::default());
    fresh.sky.sky_mut().set_clouds(blocks());
    let from_the_start = corners(&mut fresh, at, 0.0);
    assert_eq!(after_pile.len(), 200 * 4);
    let differing = quads_differing(&after_pile, &from_the_start);
    assert_eq!(differing, 0, "{differing} of 200 sprites differ");
}

/// Each quad is cut to the part of its sheet cell the texture covers: on a sheet whose cell 0 is
/// transparent in its left half, a sprite of cell 0 is as tall as before and spans only the
/// right of its square (from the first visible texel, less the half texel a bilinear lookup
/// reaches, to the right edge); a sprite of an opaque cell keeps its whole square.
#[test]
fn a_quad_is_cut_to_the_visible_part_of_its_cell() {
    // 16 x 16 texels, cells of 4 x 4, all opaque but the two left columns of cell 0.
    let mut pixels = vec![255u8; 16 * 16 * 4];
    for y in 0..4 {
        for x in 0..2 {
            pixels[(y * 16 + x) * 4 + 3] = 0;
        }
    }
    let sheet = SpriteSheet {
        size_px: 16,
        mips: vec![pixels],
    };
    let mut host = host_with_sheet(TimeOfDayTable::default(), sheet);
    host.sky.sky_mut().set_clouds(one_cloud(plain_cloud(
        DVec3::new(0.0, 3000.0, 1000.0),
        vec![
            square_sprite(Vec3::ZERO, 200.0, 0, 0),
            square_sprite(Vec3::new(500.0, 0.0, 0.0), 200.0, 1, 0),
        ],
        ColourLevels::even(900.0, 1100.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
    )));
    // From the south the quads face south: right is east, up is up.
    let quads = corners(&mut host, DVec3::new(0.0, 0.0, 1000.0), 0.0);
    assert_eq!(quads.len(), 8);
    let extent = |quad: &[SpriteCorner], axis: usize| {
        let values = quad.iter().map(|c| c.rel_m.to_array()[axis]);
        let lo = values.clone().fold(f32::MAX, f32::min);
        (lo, values.fold(f32::MIN, f32::max))
    };
    let (cut, whole) = if quads[0].rel_m.x < 250.0 {
        (&quads[..4], &quads[4..])
    } else {
        (&quads[4..], &quads[..4])
    };
    // Visible from texel 2 of 4: u from (2 - 0.5) / 4, mapped past the cell's 1/64 inset.
    let left = ((1.5 / 4.0 - 1.0 / 64.0) / (1.0 - 2.0 / 64.0) - 0.5) * 200.0;
    let (x0, x1) = extent(cut, 0);
    assert!(
        (x0 - left).abs() < 0.1 && (x1 - 100.0).abs() < 0.1,
        "{x0}..{x1}"
    );
    let (z0, z1) = extent(cut, 2);
    assert!(
        (z0 + 100.0).abs() < 0.1 && (z1 - 100.0).abs() < 0.1,
        "{z0}..{z1}"
    );
    // The opaque cell's quad (turned a little towards the camera): its whole 200 m square.
    let (width, height) = (
        whole[1].rel_m.distance(whole[0].rel_m),
        whole[2].rel_m.distance(whole[0].rel_m),
    );
    assert!(
        (width - 200.0).abs() < 0.1 && (height - 200.0).abs() < 0.1,
        "{width} x {height}"
    );
}

/// Wang 3.3: inside half its radius a sprite's facing locks; it fades with the angle between
/// the locked facing and the camera, is gone edge-on, and faces the camera again outside.
#[test]
fn facing_locks_inside_half_the_radius_and_fades_with_the_angle() {
    let mut host = host(TimeOfDayTable::default());
    host.sky.sky_mut().set_vertex_cache(false);
    host.sky.sky_mut().set_clouds(one_cloud(plain_cloud(
        DVec3::new(0.0, 0.0, 1000.0),
        vec![square_sprite(Vec3::ZERO, 200.0, 0, 0)],
        ColourLevels::even(900.0, 1100.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
    )));
    // 40 m south of the centre (inside 50 m = half the 100 m radius): locks facing north.
    let locked = corners(&mut host, DVec3::new(0.0, -40.0, 1000.0), 0.0);
    assert_eq!(locked.len(), 4);
    assert!(
        locked
            .iter()
            .all(|c| (c.rel_m.y - 40.0).abs() < 1e-3 && c.visible),
        "plane faces the camera: {locked:?}"
    );
    // Step to 30 m east and 20 m south, still inside: the facing stays, seen at ~56 degrees.
    let turned = corners(&mut host, DVec3::new(30.0, -20.0, 1000.0), 0.1);
    let ys: Vec<f32> = turned.iter().map(|c| c.rel_m.y).collect();
    assert!(
        ys.windows(2).all(|w| (w[0] - w[1]).abs() < 1e-3),
        "facing stayed locked: {ys:?}"
    );
    assert!(
        turned[0].colour.w < locked[0].colour.w && turned[0].colour.w > 0.0,
        "faded with the angle: {} then {}",
        locked[0].colour.w,
        turned[0].colour.w
    );
    // Beside it edge-on: gone.
    let edge_on = corners(&mut host, DVec3::new(45.0, -0.5, 1000.0), 0.2);
    assert!(edge_on.iter().all(|c| !c.visible), "{edge_on:?}");
    // Out of the lock radius: faces the camera again, opaque.
    let outside = corners(&mut host, DVec3::new(300.0, 0.0, 1000.0), 0.3);
    assert!(
        outside
            .iter()
            .all(|c| (c.rel_m.x + 300.0).abs() < 1e-3 && c.visible && c.colour.w > 0.99),
        "{outside:?}"
    );
}

/// An upright sprite keeps its bottom edge level and turns only about the vertical: seen
/// from the side it is whole, from 25 degrees below it is fading, from 40 degrees below it is
/// gone (fade 15..35 degrees); a camera-facing sprite beside it is whole from everywhere.
#[test]
fn upright_sprites_stay_level_and_fade_seen_from_below() {
    let mut host = host(TimeOfDayTable::default());
    let mut upright = square_sprite(Vec3::ZERO, 200.0, 3, 0);
    upright.upright = true;
    host.sky.sky_mut().set_clouds(one_cloud(plain_cloud(
        DVec3::new(0.0, 3000.0, 1500.0),
        vec![upright, square_sprite(Vec3::X * 600.0, 200.0, 3, 0)],
        ColourLevels::even(1400.0, 1700.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
    )));
    let mut quads = |elevation_deg: f64| {
        let cam = DVec3::new(0.0, 3000.0, 1500.0)
            + DVec3::new(0.0, -1.0, 0.0) * 2000.0 * elevation_deg.to_radians().cos()
            - DVec3::Z * 2000.0 * elevation_deg.to_radians().sin();
        let all = corners(&mut host, cam, 0.0);
        assert_eq!(all.len(), 8);
        let at = cam - DVec3::new(0.0, 3000.0, 1500.0);
        // The upright sprite's corners are those nearest the cloud centre's x.
        let (up, other): (Vec<&[SpriteCorner]>, Vec<&[SpriteCorner]>) = all
            .chunks(4)
            .partition(|q| (centre(q).x + at.x as f32).abs() < 150.0);
        assert!(
            other[0].iter().all(|c| c.visible),
            "the other sprite is drawn"
        );
        up[0].to_vec()
    };
    let side = quads(0.0);
    // Corners: top left, top right, bottom left, bottom right; the bottom edge is level and
    // the quad stands vertical.
    assert!(side.iter().all(|c| c.visible));
    assert!((side[2].rel_m.z - side[3].rel_m.z).abs() < 1e-3);
    assert!((side[0].rel_m.y - side[2].rel_m.y).abs() < 1e-3);
    assert!((side[0].colour.w - 1.0).abs() < 1e-3);
    let fading = quads(25.0);
    assert!(
        fading[0].visible && fading[0].colour.w > 0.2 && fading[0].colour.w < 0.8,
        "{fading:?}"
    );
    assert!((fading[0].rel_m.y - fading[2].rel_m.y).abs() < 1e-3);
    let gone = quads(40.0);
    assert!(
        gone.iter().all(|c| !c.visible),
        "from 40 degrees below: {gone:?}"
    );
}

/// A layer's wide, short sprite (a stratus deck's puff) is a pancake: seen from the side it is
/// the level strip it was made as; seen from straight above its outline is round and each one
/// lies its own way. Turned by the camera alone, every puff of a deck seen from above lay across
/// the line to the nadir, and the deck showed rings around it.
#[test]
fn layer_sprites_seen_from_above_are_round_and_lie_their_own_way() {
    let mut host = host(TimeOfDayTable::default());
    let centre_m = DVec3::new(0.0, 3000.0, 1500.0);
    // Nine puffs 400 m wide and 200 m tall, none straight under the camera above.
    let puffs = (0..9)
        .map(|k| SkySprite {
            height_m: 200.0,
            ..square_sprite(
                Vec3::new(
                    k as f32 * 150.0 - 525.0,
                    (k % 3) as f32 * 170.0 - 170.0,
                    0.0,
                ),
                400.0,
                3,
                0,
            )
        })
        .collect();
    host.sky.sky_mut().set_clouds(one_cloud(plain_cloud(
        centre_m,
        puffs,
        ColourLevels::even(1400.0, 1600.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
    )));
    let width = |q: &[SpriteCorner]| (q[1].rel_m - q[0].rel_m).length();
    let height = |q: &[SpriteCorner]| (q[0].rel_m - q[2].rel_m).length();
    // From 20 km south at the layer's height: 400 x 200, the bottom edge level.
    let side = corners(&mut host, centre_m - DVec3::Y * 20_000.0, 0.0);
    assert_eq!(side.len(), 36);
    for q in side.chunks(4) {
        assert!(q.iter().all(|c| c.visible), "{q:?}");
        assert!((width(q) - 400.0).abs() < 0.5, "{q:?}");
        assert!((height(q) - 200.0).abs() < 0.5, "{q:?}");
        assert!((q[2].rel_m.z - q[3].rel_m.z).abs() < 1e-2, "level: {q:?}");
    }
    // From 3 km straight above (every puff 76 to 89 degrees down): round within 2%, and the
    // angle of each one's width off the line across the nadir its own.
    let top = corners_looking(&mut host, centre_m + DVec3::Z * 3000.0, -89.0, 0.1);
    assert_eq!(top.len(), 36);
    let mut off_the_tangent_deg = Vec::new();
    for q in top.chunks(4) {
        assert!(q.iter().all(|c| c.visible), "{q:?}");
        assert!((width(q) - 400.0).abs() < 0.5, "{q:?}");
        assert!(
            height(q) > 392.0 && height(q) <= 400.5,
            "{}: {q:?}",
            height(q)
        );
        let at = centre(q);
        let tangent = Vec3::new(-at.y, at.x, 0.0).normalize();
        let across = (q[1].rel_m - q[0].rel_m).normalize();
        off_the_tangent_deg.push(across.dot(tangent).abs().min(1.0).acos().to_degrees());
    }
    let turned = off_the_tangent_deg.iter().filter(|&&a| a > 10.0).count();
    assert!(turned >= 5, "{off_the_tangent_deg:?}");
    // Seen from 45 degrees, in between.
    let slant_m = centre_m + DVec3::new(0.0, -3000.0, 3000.0);
    let between = corners_looking(&mut host, slant_m, -45.0, 0.2);
    assert_eq!(between.len(), 36);
    for q in between.chunks(4) {
        assert!(
            height(q) > 250.0 && height(q) < 350.0,
            "{}: {q:?}",
            height(q)
        );
    }
}

/// Seen with the sun behind it, a cloud's rim is brighter than with the sun behind the camera
/// by the forward-scattering lobe (Harris and Lastra's eye scattering); switched off, no glow.
#[test]
fn the_rim_of_a_cloud_against_the_sun_glows() {
    let cam = DVec3::new(0.0, 0.0, 1500.0);
    // The first cloud is 5 km north: the sun low in the north, then low in the south.
    let brightest = |azimuth_deg: f64, forward: ForwardScattering| {
        let mut host = host(TimeOfDayTable {
            forward_scattering: forward,
            ..TimeOfDayTable::default()
        });
        host.sky.sky_mut().set_clouds(blocks());
        let sun = SunPosition {
            elevation_deg: 2.86,
            azimuth_deg,
            declination_deg: 0.0,
        };
        let c = camera(&host, cam);
        host.sky.sky_mut().prepare(&host.gpu.queue, c, &sun, 0.0);
        host.sky
            .sky()
            .read_back_corners(&host.gpu.queue)
            .unwrap()
            .iter()
            .map(|c| c.colour.x)
            .fold(0.0, f32::max)
    };
    let none = ForwardScattering {
        strength: 0.0,
        ..ForwardScattering::default()
    };
    let on = ForwardScattering::default();
    let glow = brightest(0.0, on) - brightest(0.0, none);
    let other_way = brightest(180.0, on) - brightest(180.0, none);
    assert!(glow > 0.1, "against the sun: +{glow}");
    assert!(other_way < 0.01, "sun behind the camera: +{other_way}");
}

/// Positions go to the GPU relative to the camera, worked out in f64: 300 km from the origin the
/// corners are where they are at the origin.
#[test]
fn far_from_the_origin_the_corners_are_as_precise_as_near_it() {
    let shifted = |offset: DVec3| -> Vec<SpriteCorner> {
        let mut host = host(TimeOfDayTable::default());
        let mut b = blocks();
        for block in &mut b {
            block.centre_m += offset;
            for c in &mut block.clouds {
                c.centre_m += offset;
            }
        }
        host.sky.sky_mut().set_clouds(b);
        corners(&mut host, DVec3::new(0.0, 0.0, 1000.0) + offset, 0.0)
    };
    let near = shifted(DVec3::ZERO);
    let far = shifted(DVec3::new(250_000.0, -180_000.0, 0.0));
    assert_eq!(near.len(), far.len());
    for (a, b) in near.iter().zip(&far) {
        let d = a.rel_m - b.rel_m;
        assert!(d.length() < 1e-3, "jitter of {} m 300 km out", d.length());
    }
}

/// Past the sprite budget (or the device's buffer limits) the farthest blocks are left out and
/// counted, never a validation error; flying towards one brings it in and leaves out another.
#[test]
fn past_the_sprite_budget_the_farthest_blocks_are_left_out() {
    let mut host = host(TimeOfDayTable::default());
    let block = |id: u64, north_m: f64| {
        let mut b = blocks().remove(0);
        b.id = id;
        b.centre_m.y = north_m;
        for c in &mut b.clouds {
            c.centre_m.y = north_m;
        }
        b
    };
    // Room for two of the three 200-sprite blocks.
    host.sky
        .sky_mut()
        .set_sprite_budget_bytes(500 * skycast::render::BYTES_PER_SPRITE);
    host.sky.sky_mut().set_clouds(vec![
        block(1, 3_000.0),
        block(2, 6_000.0),
        block(3, -12_000.0),
    ]);
    let drawn_from = |host: &mut DemoHost, at: DVec3| {
        let c = camera(host, at);
        let stats = host.sky.sky_mut().prepare(&host.gpu.queue, c, &SUN, 0.1);
        let norths: Vec<f32> = host
            .sky
            .sky()
            .read_back_corners(&host.gpu.queue)
            .unwrap()
            .chunks(4)
            .map(|q| centre(q).y + at.y as f32)
            .collect();
        (stats, norths)
    };
    let (stats, norths) = drawn_from(&mut host, DVec3::new(5_000.0, 0.0, 1000.0));
    assert_eq!(
        (stats.blocks_left_out, stats.sprites_drawn),
        (1, 400),
        "{stats:?}"
    );
    assert!(
        norths.iter().all(|&y| y > 0.0),
        "the block 12 km south is left out"
    );
    assert!(stats.sprite_gpu_bytes > 0);
    // 10 km south: the southern block is nearest now and the northern one farthest.
    let (stats, norths) = drawn_from(&mut host, DVec3::new(5_000.0, -10_000.0, 1000.0));
    assert_eq!(
        (stats.blocks_left_out, stats.sprites_drawn),
        (1, 400),
        "{stats:?}"
    );
    assert!(
        norths.iter().any(|&y| y < -10_000.0),
        "the southern block came in"
    );
    assert!(norths.iter().all(|&y| y < 5_000.0), "the northern one went");
}

/// Where the clouds end, a layer seen above the horizon dissolves instead of ending in a line
/// across the sky: with the shipped settings (sprites drawn to 60 km, the last 30% fading), a
/// sprite 8 km above the camera and 55 km out is mostly faded, one 30 km out is whole, and one
/// 55 km out but below the horizon (a deck seen from above runs on to the haze) is whole too.
#[test]
fn a_layer_seen_above_the_horizon_fades_out_where_the_clouds_end() {
    let mut host = host(TimeOfDayTable::default());
    let block = |id: u64, at: DVec3| SkyBlock {
        id,
        centre_m: at,
        clouds: vec![plain_cloud(
            at,
            vec![square_sprite(Vec3::ZERO, 300.0, 0, 0)],
            ColourLevels::even(0.0, 12_000.0, [[0.9, 0.9, 0.9, 1.0]; 5]),
        )],
    };
    let camera_z = 9000.0;
    host.sky.sky_mut().set_clouds(vec![
        block(1, DVec3::new(0.0, 55_000.0, camera_z + 8000.0)),
        block(2, DVec3::new(4000.0, 30_000.0, camera_z + 8000.0)),
        block(3, DVec3::new(-4000.0, 55_000.0, camera_z - 8000.0)),
    ]);
    let quads = corners(&mut host, DVec3::new(0.0, 0.0, camera_z), 0.0);
    assert_eq!(quads.len(), 12);
    let alpha_near = |x: f32, y: f32, z: f32| -> f32 {
        let quad = quads
            .chunks(4)
            .find(|q| (centre(q) - Vec3::new(x, y, z)).length() < 1000.0)
            .unwrap_or_else(|| panic!("no sprite near ({x}, {y}, {z}): {quads:?}"));
        quad[0].colour.w
    };
    // 55.6 km from the camera: smoothstep over 42-60 km leaves about 0.1.
    let high_far = alpha_near(0.0, 55_000.0, 8000.0);
    let high_near = alpha_near(4000.0, 30_000.0, 8000.0);
    let low_far = alpha_near(-4000.0, 55_000.0, -8000.0);
    assert!(high_far < 0.25, "the far high sprite: alpha {high_far}");
    assert!(
        (high_near - 1.0).abs() < 1e-3,
        "the nearer one: {high_near}"
    );
    assert!((low_far - 1.0).abs() < 1e-3, "below the horizon: {low_far}");
}

/// Aerial perspective (`sprites.wgsl`): a dark cloud 8 km out fades into the horizon haze. In
/// clear air (visibility past the fog's cap: the clear-air haze, 13.3 km), against the same cloud
/// wholly hazed (a 1 m haze distance: the horizon's colour), the cloud at a 2 km haze distance
/// differs by under a tenth of what it does with the clouds' own haze distance out of the way
/// (then 13.3 km). Without the haze term (`o.haze = 0.0;`) nothing is hazed and this fails. The
/// clouds' haze distance is the uniform haze's (`altitude_haze = false` in `config/fog.toml`);
/// the altitude haze has its own test in `tests/render.rs`.
#[test]
fn a_far_cloud_fades_into_the_horizon_haze() {
    let contrast = |haze_distance_m: f32| {
        let mut settings = RenderSettings::default();
        settings.clouds.haze_distance_m = haze_distance_m;
        let ground = HeightField::from_fn(DVec2::ZERO, 20_000.0, 9, |_| 0.0);
        let sheet = SpriteSheet {
            size_px: 4,
            mips: vec![vec![255; 64], vec![255; 16], vec![255; 4]],
        };
        let mut host = DemoHost::new(
            64,
            36,
            &ground,
            SkyConfig {
                targets: headless::TARGETS,
                settings,
                time_of_day: TimeOfDayTable::default(),
                sheet,
            },
        )
        .unwrap_or_else(|e| panic!("sprite tests need an adapter: {e}"));
        host.sky
            .sky_mut()
            .set_fog_settings(skycast::shading::FogSettings {
                altitude_haze: false,
                ..Default::default()
            });
        host.sky.sky_mut().set_weather_overhead(&BlockWeather {
            visibility_m: 1e9,
            ..BlockWeather::default()
        });
        let camera = host.camera(DVec3::new(0.0, 0.0, 1500.0), 0.0, 2.0);
        let (bare, _) = host.frame(&camera, &SUN, 0.0, 1e9).unwrap();
        host.sky.sky_mut().set_clouds(one_cloud(plain_cloud(
            DVec3::new(0.0, 8000.0, 1800.0),
            vec![square_sprite(Vec3::ZERO, 1500.0, 0, 0)],
            ColourLevels::even(0.0, 4000.0, [[0.05, 0.05, 0.05, 1.0]; 5]),
        )));
        let (cloud, _) = host.frame(&camera, &SUN, 0.0, 1e9).unwrap();
        (bare, cloud)
    };
    let lum = |p: &[f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let summed_difference = |a: &Frame, b: &Frame| -> f32 {
        a.rgba
            .iter()
            .zip(&b.rgba)
            .map(|(p, q)| (lum(p) - lum(q)).abs())
            .sum()
    };
    let (bare, clear) = contrast(1e10);
    let (_, hazed) = contrast(2000.0);
    let (_, horizon) = contrast(1.0);
    let shown = bare
        .rgba
        .iter()
        .zip(&clear.rgba)
        .filter(|(p, q)| (lum(p) - lum(q)).abs() > 0.004)
        .count();
    let (from_clear, from_hazed) = (
        summed_difference(&clear, &horizon),
        summed_difference(&hazed, &horizon),
    );
    eprintln!(
        "against the wholly hazed cloud: {from_hazed} at 2 km, {from_clear} at 13.3 km ({shown} px)"
    );
    assert!(shown > 20, "the cloud shows: {shown} px");
    assert!(from_clear > 0.5, "the haze changes the cloud: {from_clear}");
    assert!(
        from_hazed < 0.1 * from_clear,
        "{from_hazed} vs {from_clear}"
    );
}

/// A block of `clouds` clouds of 20 sprites (those of [`blocks`], ten to a row 1.5 km apart,
/// rows 100 m apart) centred `north_m` north. Each block's are its own: moved `id` x 70 m east
/// and `id` x 3 m wider, so that a block drawn from another's slots shows.
fn row_block(id: u64, north_m: f64, clouds: usize) -> SkyBlock {
    let template = blocks().remove(0).clouds.remove(0);
    let own = template
        .sprites
        .iter()
        .map(|s| SkySprite {
            width_m: s.width_m + 3.0 * id as f32,
            height_m: s.height_m + 3.0 * id as f32,
            ..*s
        })
        .collect::<Vec<_>>();
    SkyBlock {
        id,
        centre_m: DVec3::new(0.0, north_m, 1500.0),
        clouds: (0..clouds)
            .map(|i| SkyCloud {
                centre_m: DVec3::new(
                    (i % 10) as f64 * 1500.0 + 70.0 * id as f64,
                    north_m + (i / 10) as f64 * 100.0,
                    1500.0,
                ),
                sprites: own.clone(),
                ..template.clone()
            })
            .collect(),
    }
}

/// Blocks 1 to `n` of 200 sprites (10 clouds) 4 km north and on, placed and written from `at`
/// in the resident buffers' first 4,096 sprite slots, nearer first: block `k` holds slots
/// `200 (k - 1)` on. Returns them.
fn fill_slots(host: &mut DemoHost, n: u64, at: DVec3) -> Vec<SkyBlock> {
    let all: Vec<SkyBlock> = (1..=n)
        .map(|id| row_block(id, 3750.0 + 250.0 * id as f64, 10))
        .collect();
    host.sky.sky_mut().set_clouds(all.clone());
    let c = camera(host, at);
    let first = host.sky.sky_mut().prepare(&host.gpu.queue, c, &SUN, 0.0);
    assert_eq!(first.sprites_drawn, 200 * n as u32, "{first:?}");
    all
}

/// The blocks [`fill_slots`] placed, less blocks 3, 7, 11 and 15, which are taken away: their
/// 800 slots are free in holes of 200.
fn cut_up_slots(host: &mut DemoHost, all: Vec<SkyBlock>) -> Vec<SkyBlock> {
    let taken = [3, 7, 11, 15];
    assert_eq!(host.sky.sky_mut().remove_blocks(taken), 4);
    all.into_iter().filter(|b| !taken.contains(&b.id)).collect()
}

/// A block that finds no range of free sprite slots long enough, where the slots free are
/// enough in all (the blocks that went cut them up), packs the resident buffers at their size:
/// the device moves the blocks held, and the frame writes the new block, the whole orders and
/// lists (4 and 16 bytes a slot) and its usual few kB, not every sprite again. Placing and
/// writing every block again instead, this frame wrote 156 kB here and re-sorted every cloud
/// (and 21 to 27 MB on the FL350 cruise, every 30 s). The packed sky draws exactly what a fresh
/// sky given the same blocks draws from the same camera, though a frame before it, prepared and
/// never drawn, left a patch of orders for the slots of before.
#[test]
fn a_packing_moves_the_blocks_on_the_device_and_draws_the_same_sprites() {
    let at = DVec3::new(0.0, 0.0, 1000.0);
    let mut packed = host(TimeOfDayTable::default());
    let all = fill_slots(&mut packed, 20, at - DVec3::Y * 600.0);
    let mut kept = cut_up_slots(&mut packed, all);
    // 600 m on, past every cloud's threshold: all 160 clouds sorted again, their orders in a
    // patch that no frame applies before the packing.
    let c = camera(&packed, at);
    let undrawn = packed
        .sky
        .sky_mut()
        .prepare(&packed.gpu.queue, c, &SUN, 0.0);
    assert_eq!(undrawn.clouds_recomputed, 160, "{undrawn:?}");
    let memory = packed.sky.sky().memory();
    assert_eq!(
        (memory.sprite_slots, memory.sprite_slots_used),
        (4096, 3200)
    );
    // 300 sprites in 15 clouds: no hole holds them (the last is 96), the 896 free in all do.
    let new = row_block(21, 6100.0, 15);
    packed
        .sky
        .sky_mut()
        .insert_block(new.clone(), BlockMotion::default());
    kept.push(new);
    let c = camera(&packed, at);
    let stats = packed
        .sky
        .sky_mut()
        .prepare(&packed.gpu.queue, c, &SUN, 0.0);
    let memory = packed.sky.sky().memory();
    // Packed at the same size (not grown), and the new block placed.
    assert_eq!(
        (memory.sprite_slots, memory.sprite_slots_used),
        (4096, 3500)
    );
    assert_eq!((stats.blocks_left_out, stats.sprites_drawn), (0, 3500));
    let sprite_bytes = std::mem::size_of::<skycast::render::gpu_types::GpuSprite>() as u64;
    let held_bytes = 3500 * sprite_bytes;
    assert!(
        stats.upload_bytes < held_bytes / 2,
        "{} bytes written, the sprites held are {held_bytes}",
        stats.upload_bytes
    );
    // The blocks moved keep their orders: only the new block's clouds are sorted.
    assert_eq!(stats.clouds_recomputed, 15, "{stats:?}");
    let after = packed
        .sky
        .sky()
        .read_back_corners(&packed.gpu.queue)
        .expect("corners read back");
    let mut fresh = host(TimeOfDayTable::default());
    fresh.sky.sky_mut().set_clouds(kept);
    let expected = corners(&mut fresh, at, 0.0);
    assert_eq!((after.len(), expected.len()), (3500 * 4, 3500 * 4));
    let differing = quads_differing(&after, &expected);
    assert_eq!(differing, 0, "{differing} of 3,500 sprites differ");
}

/// Wang 3.3's facing lock is kept by sprite slot: when a packing moves the block of the sprite
/// the camera is inside of, its lock moves with it. The camera locks the sprite facing north
/// from 40 m south of it, then steps to 30 m east and 20 m south as the buffers pack: the sprite
/// still faces north (forgotten at its old slot, it turned to face the camera).
#[test]
fn a_locked_facing_follows_its_sprite_when_the_buffers_pack() {
    let mut host = host(TimeOfDayTable::default());
    let locked_at = DVec3::new(0.0, -40.0, 1000.0);
    // 19 blocks in slots 0..3,800, then the sprite's block after them.
    let all = fill_slots(&mut host, 19, locked_at);
    let sprite_m = DVec3::new(0.0, 0.0, 1000.0);
    host.sky.sky_mut().insert_block(
        SkyBlock {
            id: 40,
            centre_m: sprite_m,
            clouds: vec![plain_cloud(
                sprite_m,
                vec![square_sprite(Vec3::ZERO, 200.0, 0, 0)],
                ColourLevels::even(900.0, 1100.0, [[0.5, 0.5, 0.5, 1.0]; 5]),
            )],
        },
        BlockMotion::default(),
    );
    let sprite_near = |quads: &[SpriteCorner], at: DVec3| -> Vec<SpriteCorner> {
        let rel = (sprite_m - at).as_vec3();
        quads
            .chunks(4)
            .find(|q| (centre(q) - rel).length() < 1.0)
            .unwrap_or_else(|| panic!("no sprite at {rel}"))
            .to_vec()
    };
    let locked = sprite_near(&corners(&mut host, locked_at, 0.0), locked_at);
    assert!(locked.iter().all(|c| (c.rel_m.y - 40.0).abs() < 1e-3));
    // The holes of 200 and the 295 at the end hold no 300 sprites: the buffers pack, and the
    // sprite moves from slot 3,800 to 3,000.
    cut_up_slots(&mut host, all);
    assert_eq!(host.sky.sky().memory().sprite_slots_used, 3001);
    host.sky
        .sky_mut()
        .insert_block(row_block(41, 6100.0, 15), BlockMotion::default());
    let stepped_to = DVec3::new(30.0, -20.0, 1000.0);
    let quads = corners(&mut host, stepped_to, 0.1);
    let memory = host.sky.sky().memory();
    assert_eq!(
        (memory.sprite_slots, memory.sprite_slots_used),
        (4096, 3301)
    );
    let turned = sprite_near(&quads, stepped_to);
    let ys: Vec<f32> = turned.iter().map(|c| c.rel_m.y).collect();
    assert!(
        ys.iter().all(|y| (y - 20.0).abs() < 1e-3),
        "still facing north: {ys:?}"
    );
}

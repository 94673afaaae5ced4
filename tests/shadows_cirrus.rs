//! The shadow of thin ice cloud (`src/render/shadow/`, `optical_density` in
//! config/cloud_types.toml): under a real cirrus report the map and the air data's
//! `sun_occlusion` find the ground lightly shaded, and agree. On whatever adapter there is
//! (lavapipe here; a missing adapter fails it). Apart from tests/shadows.rs, which is near the
//! 800 lines a file may have.

use glam::{DVec3, Vec4Swizzles};
use skycast::demo::headless;
use skycast::flight::SkySystemConfig;

#[path = "support/shadow_host.rs"]
mod shadow_host;
use shadow_host::{UNIX_S, host_over, quantile, sun_down_to};
/// Providence, Rhode Island (`KPVD 272151Z 20012KT 10SM SCT250 01/M08 A2976`): cirrus
/// scattered at 25,000 ft, nothing under it.
const KPVD: (f64, f64) = (41.7225, -71.4325);

/// Under Providence's scattered cirrus, the winter sun at 25 degrees, at ground points every
/// 100 m within 4 km of the station: some ground is shaded at all, and the map's occlusion
/// `1 - exp(-tau)` is nowhere above 0.6 (a cirrus layer's whole depth is an optical depth of
/// about 0.03-3, Sassen and Cho 1992: its shadow a light veil, not a cumulus's full shade); the
/// probe (`World::sun_occlusion`) agrees within 0.05 at the 90th percentile of the points, and
/// of the points moved onto the ray through a texel's centre. There the map holds that very
/// ray's optical depth, but where two of a streak's flat cores overlap it adds both (additive
/// blending, as the sprites are drawn) and the probe counts the overlap once (a cloud is the
/// union of its cores): the map darker by up to about 0.2 at a few per cent of the points
/// (docs/src/not-right.md).
#[test]
fn cirrus_shadows_are_light_and_the_probe_agrees() {
    let unix_s = sun_down_to(KPVD, UNIX_S - 5.0 * 3600.0, 25.0);
    let mut config = SkySystemConfig::new(headless::TARGETS, KPVD);
    // The sun's rays from the ground within 4 km climb through the layer at 7.6 km some 16 km
    // up-sun: clouds 22 km around.
    config.world.cloud_radius_m = 22_000.0;
    let mut host = host_over(config);
    let sun_az = skycast::shading::sun_position(unix_s, KPVD.0, KPVD.1).azimuth_deg;
    let camera = host.camera(
        DVec3::new(0.0, 0.0, 300.0),
        (sun_az + 180.0).rem_euclid(360.0),
        -25.0,
    );
    let (stats, _) = host.step(&camera, unix_s, 0.0, true).unwrap();
    assert!(
        stats.shadow_redrawn && stats.shadow_sprites > 0,
        "{stats:?}"
    );
    let map = host
        .sky
        .sky()
        .read_back_cloud_shadows(&host.gpu.queue)
        .unwrap();
    let lookup = host.sky.cloud_shadows().uv_from_camera_relative;
    let sun = host.sky.lighting().sun_direction.as_dvec3();
    let world = host.sky.world();
    let settings = *host.sky.settings();
    let frame =
        skycast::render::shadow::ShadowFrame::new(camera.position_m, sun, &settings.cloud_shadows);
    let side_m = 2.0 * settings.cloud_shadows.half_extent_m;
    let n = map.size_px as f64;
    let occlusion = |p: DVec3| {
        let uv = (lookup * (p - camera.position_m).as_vec3().extend(1.0)).xy();
        (1.0 - (-map.sample(uv)).exp(), uv.as_dvec2())
    };
    let (mut map_most, mut shaded, mut free, mut centred) = (0.0f32, 0, Vec::new(), Vec::new());
    for i in -40..=40 {
        for j in -40..=40 {
            let p = DVec3::new(i as f64 * 100.0 + 7.0, j as f64 * 100.0 + 3.0, 0.0);
            let (on_map, uv) = occlusion(p);
            let probe = world.sun_occlusion(p, sun);
            map_most = map_most.max(on_map);
            shaded += usize::from(probe > 0.02);
            free.push((on_map - probe).abs());
            // The (flat) ground on the ray through the texel's centre.
            let to = ((uv * n).floor() + 0.5) / n - uv;
            let c = p + frame.right * (to.x * side_m) - frame.up * (to.y * side_m);
            let c = c - sun * (c.z / sun.z);
            centred.push((occlusion(c).0 - world.sun_occlusion(c, sun)).abs());
        }
    }
    let (free_p90, free_most) = (quantile(&mut free, 0.9), quantile(&mut free, 1.0));
    let (centred_p90, centred_most) = (quantile(&mut centred, 0.9), quantile(&mut centred, 1.0));
    let overlaps = centred.iter().filter(|d| **d > 0.05).count();
    eprintln!(
        "KPVD SCT250, sun {:.1} deg: {} ground points, {shaded} shaded by the probe (over 0.02); \
         map occlusion at most {map_most:.3}; |map - probe| p90 {free_p90:.4}, max \
         {free_most:.4}; on texel centres' rays p90 {centred_p90:.4}, max {centred_most:.4}, \
         {overlaps} over 0.05",
        sun.z.asin().to_degrees(),
        free.len(),
    );
    assert!(shaded > 100, "no cirrus shadow over the ground: {shaded}");
    assert!(map_most <= 0.6, "a cirrus shadow as dark as {map_most}");
    assert!(free_p90 <= 0.05, "map and probe: p90 {free_p90}");
    assert!(
        centred_p90 <= 0.05,
        "map and probe on texel centres: p90 {centred_p90}"
    );
}

/// The optical depth straight up through a whole layer (every 150 m within 3 km of the
/// station, where a line meets cloud) under real reports of each kind of high and middle cloud,
/// against what is measured of them: cirrus (KPVD SCT250) about 0.03-3 (Sassen and Cho 1992),
/// a cirrostratus veil (CYZR OVC210) a few tenths to a few (the sun shows through it, with its
/// halo), altostratus (KPRO OVC140) a few to tens (the sun a pale disc as through ground glass,
/// or hidden). The medians lie within those ranges and each is printed.
#[test]
fn thin_and_thick_high_clouds_have_their_optical_depths() {
    for (name, at, top_m, lo, hi) in [
        ("KPVD SCT250 cirrus", KPVD, 12_000.0, 0.03, 1.0),
        (
            "CYZR OVC210 cirrostratus",
            (42.995, -82.307),
            12_000.0,
            0.3,
            3.0,
        ),
        (
            "KPRO OVC140 altostratus",
            (41.8278, -94.1637),
            10_000.0,
            2.0,
            20.0,
        ),
    ] {
        let mut config = SkySystemConfig::new(headless::TARGETS, at);
        config.world.cloud_radius_m = 6_000.0;
        let mut host = host_over(config);
        let camera = host.camera(DVec3::new(0.0, 0.0, 300.0), 0.0, 0.0);
        host.step(&camera, UNIX_S - 5.0 * 3600.0, 0.0, false)
            .unwrap();
        let world = host.sky.world();
        let mut up = Vec::new();
        for i in -20..=20 {
            for j in -20..=20 {
                let p = DVec3::new(i as f64 * 150.0, j as f64 * 150.0, 0.0);
                if let Some(hit) = world.line_of_sight(p, p + DVec3::Z * top_m) {
                    up.push(hit.total_optical_depth as f32);
                }
            }
        }
        let met = up.len();
        let (p10, median) = (quantile(&mut up, 0.1), quantile(&mut up, 0.5));
        let (p90, most) = (quantile(&mut up, 0.9), quantile(&mut up, 1.0));
        eprintln!(
            "{name}: {met} of 1681 lines up meet cloud; optical depth median {median:.3} \
             (10th-90th percentile {p10:.3}-{p90:.3}), max {most:.3}"
        );
        assert!(met > 100, "{name}: {met} lines meet cloud");
        assert!((lo..=hi).contains(&median), "{name}: median {median}");
    }
}

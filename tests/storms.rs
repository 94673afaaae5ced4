//! A storm cell of the weather field rendered headless (lavapipe, 320 x 180): how big it looks
//! from 20 km, how dark its base is against the sky beside it, and an in-cloud lightning flash
//! lighting it from inside. Frames are written to `target/tmp/storm-tests/` to look at.

use std::path::PathBuf;

use glam::{DVec2, DVec3};
use skycast::clouds::CloudTypes;
use skycast::clouds::storm::{cell_cloud, part_in_block};
use skycast::demo::terrain::HeightField;
use skycast::demo::{DemoHost, Frame, headless};
use skycast::render::scene::BlockMotion;
use skycast::render::{Camera, SkyBlock, SkyCloud, SkyConfig, SkyFlash};
use skycast::shading::{FogSettings, SunPosition};
use skycast::weather::storms::{StormCell, StormSettings};
use skycast::weather::{BlockIndex, BlockWeather, CloudType, Wind};

const W: u32 = 320;
const H: u32 = 180;
/// The camera's height, metres: 1,000 ft, under the cell's 3,000 ft base.
const EYE_M: f64 = 305.0;

/// A 10 km cell 20 km north of the camera, its 30 km anvil 10.5 km downwind (east).
fn cell() -> StormCell {
    StormCell {
        key: 7,
        centre_m: [0.0, 20_000.0],
        base_width_m: 10_000.0,
        base_ft_agl: 3_000.0,
        top_ft_msl: 38_000.0,
        ground_m_msl: 0.0,
        anvil_width_m: 30_000.0,
        anvil_offset_m: [10_500.0, 0.0],
        anvil_thickness_m: 2_500.0,
        turrets: 5,
        wind_aloft_m_s: [20.0, 0.0],
        thunder: 2,
        precipitation: 0.0,
        cloud_type: CloudType::Cumulonimbus,
    }
}

fn sun() -> SunPosition {
    SunPosition {
        elevation_deg: 35.0,
        azimuth_deg: 200.0,
        declination_deg: 0.0,
    }
}

fn host() -> DemoHost {
    host_at(None)
}

/// A host drawing the clouds at `scale` of the frame's resolution (the shipped one: `None`).
fn host_at(scale: Option<f32>) -> DemoHost {
    let ground = HeightField::from_fn(DVec2::ZERO, 120_000.0, 64, |_| 0.0);
    let mut config = SkyConfig::new(headless::TARGETS);
    if let Some(scale) = scale {
        config.settings.clouds.resolution_scale = scale;
    }
    DemoHost::new(W, H, &ground, config)
        .unwrap_or_else(|e| panic!("render tests need an adapter: {e}"))
}

fn frame(host: &mut DemoHost, name: &str, camera: &Camera) -> Frame {
    let (frame, _) = host.frame(camera, &sun(), 0.0, 60_000.0).unwrap();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("storm-tests");
    std::fs::create_dir_all(&dir).unwrap();
    frame.write_png(&dir.join(format!("{name}.png"))).unwrap();
    frame
}

fn luminance(p: [f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// Pixels the cell changed: against the same view without it.
fn cell_mask(with: &Frame, without: &Frame) -> Vec<bool> {
    with.rgba
        .iter()
        .zip(&without.rgba)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).sum::<f32>() > 0.06)
        .collect()
}

#[test]
fn a_10_km_cell_from_20_km_spans_25_degrees_on_a_dark_base_and_a_flash_lights_it() {
    let types = CloudTypes::builtin();
    let c = cell();
    let weather = BlockWeather {
        wind: Wind {
            from_deg: 270.0,
            speed_kt: 15.0,
        },
        ..BlockWeather::default()
    };
    let cloud = cell_cloud(&c, types.get(CloudType::Cumulonimbus), &weather);
    let block = SkyBlock {
        id: 1,
        centre_m: DVec3::new(c.centre_m[0], c.centre_m[1], cloud.centre_m.z),
        clouds: vec![SkyCloud::from(&cloud)],
    };
    let mut host = host();
    // The cell's shadow darkens the ground below it between the frame without it and the one
    // with it, which the mask would take for the cell: the cell is measured without it.
    host.sky.sky_mut().set_cloud_shadows(false);
    // A report's 9999 (10 km or more) under the cell, drawn in clear air of 100 km visual
    // range: storms are seen 50-80 km off (../shared/DESIGN.md), which the shipped 40 km of
    // `clear_visibility_m` (config/fog.toml) hides; the figure under it is printed below.
    host.sky.sky_mut().set_weather_overhead(&BlockWeather {
        visibility_m: 9_999.0,
        ..weather.clone()
    });
    let shipped = FogSettings::default();
    host.sky.sky_mut().set_fog_settings(FogSettings {
        clear_visibility_m: 100_000.0,
        ..shipped
    });
    // Looking north at it, the view tilted up to hold base and top.
    let camera = host.camera(DVec3::new(0.0, 0.0, EYE_M), 0.0, 15.0);
    let clear = frame(&mut host, "clear", &camera);
    host.sky.sky_mut().set_clouds(vec![block]);
    let storm = frame(&mut host, "cell_from_20_km", &camera);
    let mask = cell_mask(&storm, &clear);
    let at = |x: u32, y: u32| (y * W + x) as usize;

    // Its extent: the rows and columns it covers, as angles of the view.
    let fov_y = camera.fov_y_deg as f64;
    let fov_x = 2.0
        * ((fov_y.to_radians() / 2.0).tan() * camera.aspect as f64)
            .atan()
            .to_degrees();
    let rows: Vec<u32> = (0..H).filter(|&y| (0..W).any(|x| mask[at(x, y)])).collect();
    let cols: Vec<u32> = (0..W).filter(|&x| (0..H).any(|y| mask[at(x, y)])).collect();
    let (top, bottom) = (rows[0], *rows.last().unwrap());
    let tall_deg = (bottom - top + 1) as f64 / H as f64 * fov_y;
    // The body's width, at the rows of its lowest third (under the anvil).
    let body_rows = bottom - (bottom - top) / 6..=bottom - (bottom - top) / 12;
    let body_cols: Vec<u32> = (0..W)
        .filter(|&x| body_rows.clone().any(|y| mask[at(x, y)]))
        .collect();
    let wide_deg = (body_cols.last().unwrap() - body_cols[0] + 1) as f64 / W as f64 * fov_x;
    eprintln!(
        "cell: {tall_deg:.1} deg tall, body {wide_deg:.1} deg wide, {} columns in all",
        cols.len()
    );

    // The base: the cell's lowest rows in its middle half, against the sky beside it in the
    // same rows (left of the cell, where the anvil downwind to the east does not reach).
    let (lo, hi) = (body_cols[0], *body_cols.last().unwrap());
    let middle = lo + (hi - lo) / 4..=hi - (hi - lo) / 4;
    // The flat base seen nearly edge-on from under it and the lowest body: the cell's lowest
    // rows but the last two (its soft lower edge, blended with the sky below).
    let base_rows = bottom.saturating_sub(6)..=bottom.saturating_sub(2);
    let mean = |px: Vec<[f32; 4]>| px.iter().map(|&p| luminance(p)).sum::<f32>() / px.len() as f32;
    let base: Vec<usize> = base_rows
        .clone()
        .flat_map(|y| middle.clone().map(move |x| at(x, y)))
        .filter(|&i| mask[i])
        .collect();
    let beside: Vec<usize> = base_rows
        .flat_map(|y| (0..lo.saturating_sub(4)).map(move |x| at(x, y)))
        .filter(|&i| !mask[i] && storm.depth[i] >= 1.0)
        .collect();
    assert!(
        base.len() > 20 && beside.len() > 20,
        "{} {}",
        base.len(),
        beside.len()
    );
    let ratio_in = |f: &Frame| {
        mean(base.iter().map(|&i| f.rgba[i]).collect())
            / mean(beside.iter().map(|&i| f.rgba[i]).collect())
    };
    let ratio = ratio_in(&storm);
    eprintln!("base / sky beside: {ratio:.2}");
    // The cell spans 25 degrees and more; its body, 10 km across, near the 28 degrees 10 km
    // make at 20 km (its flanks fade into the sky).
    assert!(
        tall_deg >= 25.0 && wide_deg >= 22.5,
        "a 10 km cell from 20 km: {tall_deg:.1} deg tall, body {wide_deg:.1} deg wide"
    );
    assert!(ratio <= 0.65, "the base is {ratio:.2} of the sky beside it");

    // The same view in the shipped clear air (40 km): printed, for the book.
    host.sky.sky_mut().set_fog_settings(shipped);
    let hazed = frame(&mut host, "cell_from_20_km_shipped_fog", &camera);
    eprintln!(
        "base / sky beside in the shipped 40 km clear air: {:.2}",
        ratio_in(&hazed)
    );
    // What the haze lifts the base to: the sprites fade into the horizon's colour, brighter
    // than the sky a few degrees up beside the base (the lowest sky row against those rows).
    let horizon_row = (0..H)
        .rev()
        .find(|&y| clear.depth[at(2, y)] >= 1.0)
        .unwrap_or(0);
    let horizon = mean((0..W).map(|x| clear.rgba[at(x, horizon_row)]).collect());
    let sky_beside = mean(beside.iter().map(|&i| clear.rgba[i]).collect());
    eprintln!(
        "horizon sky / sky beside the base: {:.2}",
        horizon / sky_beside
    );
    host.sky.sky_mut().set_fog_settings(FogSettings {
        clear_visibility_m: 100_000.0,
        ..shipped
    });

    // An in-cloud flash in the middle of the tower: the cell brighter from inside, the sky
    // around the same.
    let lightning = StormSettings::default().lightning;
    host.sky.sky_mut().set_flash(Some(SkyFlash {
        position_m: DVec3::new(c.centre_m[0], c.centre_m[1], 4_500.0),
        reach_m: lightning.reach_m as f32,
        light: lightning.brightness as f32,
    }));
    let lit = frame(&mut host, "cell_flash", &camera);
    host.sky.sky_mut().set_flash(None);
    // The tower: the cell's pixels over the body's columns, base to mid-height.
    let tower: Vec<usize> = ((top + bottom) / 2..=bottom)
        .flat_map(|y| (lo..=hi).map(move |x| at(x, y)))
        .filter(|&i| mask[i])
        .collect();
    let inside = |f: &Frame| mean(tower.iter().map(|&i| f.rgba[i]).collect());
    let outside = |f: &Frame| {
        mean(
            (0..f.rgba.len())
                .filter(|&i| !mask[i] && f.depth[i] >= 1.0)
                .map(|i| f.rgba[i])
                .collect(),
        )
    };
    let (dark, bright) = (inside(&storm), inside(&lit));
    eprintln!("cell luminance {dark:.3} without the flash, {bright:.3} with it");
    assert!(bright > 1.1 * dark, "flash {bright:.3} vs {dark:.3}");
    assert!((outside(&lit) - outside(&storm)).abs() < 0.01);
    let after = frame(&mut host, "cell_after_flash", &camera);
    assert!((inside(&after) - dark).abs() < 0.005, "the flash is over");
}

/// A storm cell beyond the cloud field, 200 km off (past the host's 160 km far plane): drawn as
/// a distant block ([`skycast::render::Sky::insert_distant_block`], what `flight::far_cells`
/// hands the sky) it stands over the horizon from 10,000 ft; the same block inserted as a near
/// block is left out at the draw distance (60 km), as every cell beyond the field was before.
#[test]
fn a_cell_200_km_off_stands_over_the_horizon_as_a_distant_block() {
    let types = CloudTypes::builtin();
    let far = StormSettings::default().far;
    let c = StormCell {
        centre_m: [0.0, 200_000.0],
        anvil_offset_m: [0.0, 0.0],
        ..cell()
    };
    let weather = BlockWeather::default();
    let cloud = skycast::clouds::storm::far_cell_cloud(
        &c,
        types.get(CloudType::Cumulonimbus),
        &weather,
        (far.sprites, far.sprite_over_base),
    );
    let block = SkyBlock {
        id: 9,
        centre_m: cloud.centre_m,
        clouds: vec![SkyCloud::from(&cloud)],
    };
    // At the shipped cloud scale (1/2: the cloud target's depth is in metres) and at full
    // resolution (the host's own depth, whose background is its far plane).
    for scale in [None, Some(1.0)] {
        far_cell_frames(scale, &block);
    }
}

fn far_cell_frames(scale: Option<f32>, block: &SkyBlock) {
    let weather = BlockWeather::default();
    let mut host = host_at(scale);
    host.sky.sky_mut().set_cloud_shadows(false);
    host.sky.sky_mut().set_weather_overhead(&BlockWeather {
        visibility_m: 9_999.0,
        ..weather.clone()
    });
    // In clear air of 100 km (the other test's): in the shipped 40 km only its top shows.
    host.sky.sky_mut().set_fog_settings(FogSettings {
        clear_visibility_m: 100_000.0,
        ..FogSettings::default()
    });
    // From 10,000 ft through a 20 degree lens: the cell spans a few degrees.
    let camera = Camera {
        fov_y_deg: 20.0,
        ..host.camera(DVec3::new(0.0, 0.0, 3_048.0), 0.0, 0.0)
    };
    let clear = frame(&mut host, "far_clear", &camera);
    host.sky
        .sky_mut()
        .insert_block(block.clone(), BlockMotion::default());
    let near = frame(&mut host, "far_cell_as_near_block", &camera);
    host.sky.sky_mut().remove_block(block.id);
    host.sky
        .sky_mut()
        .insert_distant_block(block.clone(), BlockMotion::default());
    let distant = frame(&mut host, "far_cell_200_km", &camera);
    let changed = |f: &Frame| cell_mask(f, &clear).iter().filter(|&&m| m).count();
    let (near_px, distant_px) = (changed(&near), changed(&distant));
    eprintln!(
        "cloud scale {scale:?}: pixels changed: {near_px} as a near block, {distant_px} as a \
         distant one"
    );
    assert_eq!(
        near_px, 0,
        "a near block 200 km off is past the draw distance"
    );
    // A 10 km cell with its 12 km top 200 km off, 3.1 km below the camera's tangent plane
    // there, its lowest 0.1 km under the horizon: 2.9 degrees wide, 3.3 tall from 1.8 below
    // the horizon (about 26 x 30 pixels at 9 a degree), its 30 km anvil 8.6 degrees wide.
    assert!(distant_px >= 400, "{distant_px} pixels");
    // Over the horizon: its pixels show the sky behind them, and it stands in it.
    let mask = cell_mask(&distant, &clear);
    let above = (0..W * H)
        .filter(|&i| mask[i as usize] && clear.depth[i as usize] >= 1.0)
        .count();
    assert!(
        above * 2 >= distant_px,
        "{above} of {distant_px} over the sky"
    );
}

/// A cell 25 km off, cut into its blocks' parts as the field draws it: the parts past the ring
/// radius (20 km) that span the camera's height go into the impostor ring, anvil and all, and
/// the anvil reaches 24-40 degrees up. The impostors hold it (35 degrees up and down): its
/// pixels more than 24 degrees up are those the sprites draw. At 45 degrees of impostor height
/// (22.5 up) the ring cut the anvil along the impostors' top edge.
#[test]
fn the_impostor_ring_holds_a_cells_anvil_high_above_the_horizon() {
    let types = CloudTypes::builtin();
    let c = StormCell {
        centre_m: [0.0, 25_000.0],
        ..cell()
    };
    let cloud = cell_cloud(
        &c,
        types.get(CloudType::Cumulonimbus),
        &BlockWeather::default(),
    );
    // Cut into its 4 km blocks' parts, as the field draws it.
    let mut blocks = Vec::new();
    let reach = c.radius_m() + 4_000.0;
    let (lo, hi) = (
        BlockIndex::containing(c.centre() - DVec2::splat(reach)),
        BlockIndex::containing(c.centre() + DVec2::splat(reach)),
    );
    for j in lo.j..=hi.j {
        for i in lo.i..=hi.i {
            let index = BlockIndex::new(i, j);
            if let Some(part) = part_in_block(&cloud, index, 0) {
                let centre = index.centre_m();
                blocks.push(SkyBlock {
                    id: blocks.len() as u64 + 100,
                    centre_m: DVec3::new(centre.x, centre.y, part.centre_m.z),
                    clouds: vec![SkyCloud::from(&part)],
                });
            }
        }
    }
    let mut host = host();
    host.sky.sky_mut().set_cloud_shadows(false);
    // Looking up at 30 degrees: the rows of the frame from 0 (60 degrees up) down.
    let camera = host.camera(DVec3::new(0.0, 0.0, EYE_M), 0.0, 30.0);
    // The first ring is built at once, with the cell in it.
    let parts = blocks.len() as u32;
    host.sky.sky_mut().set_clouds(blocks);
    let (ring, stats) = host.frame(&camera, &sun(), 0.0, 60_000.0).unwrap();
    eprintln!(
        "{parts} parts: {} near, {} in the ring",
        stats.blocks_near, stats.blocks_far
    );
    assert!(stats.blocks_far > 0, "{stats:?}");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("storm-tests");
    ring.write_png(&dir.join("anvil_in_the_ring.png")).unwrap();
    host.sky.sky_mut().set_impostors(false);
    let sprites = frame(&mut host, "anvil_as_sprites", &camera);
    host.sky.sky_mut().set_clouds(Vec::new());
    let clear = frame(&mut host, "anvil_clear", &camera);
    // The rows more than 24 degrees up: the top 36 of the frame's 60 degrees (rows 0..108).
    let high = |f: &Frame| {
        let mask = cell_mask(f, &clear);
        (0..W * 108).filter(|&i| mask[i as usize]).count()
    };
    let (in_ring, as_sprites) = (high(&ring), high(&sprites));
    eprintln!(
        "anvil pixels more than 24 degrees up: {in_ring} in the ring, {as_sprites} as sprites"
    );
    assert!(as_sprites > 2_000, "{as_sprites}");
    // At 45 degrees of impostor height the ring held 6,824 of the sprites' 7,308 (0.93): the
    // cut along the impostors' top edge; at 70, 7,293.
    assert!(
        in_ring as f64 > 0.97 * as_sprites as f64,
        "the ring holds {in_ring} of the anvil's {as_sprites} pixels"
    );
}

//! The far field's plan of a frame: its uniform ([`GpuFarField`], `shaders/far_field.wgsl`)
//! from where the map lies, its fades, the camera and the light, as plain data (tested without
//! a device); [`FarField::upload`](super::FarField::upload) writes it.

use glam::{DVec2, DVec3, Vec3};

use super::{FarFieldSettings, GpuFarField, band_elevations};
use crate::shading::TimeOfDay;

/// Where the far field's map lies (its texture apart).
pub(super) struct MapPlace {
    pub centre_m: DVec2,
    pub side_m: f64,
    pub texels: u32,
    /// Mean middle heights of the low and high layers, metres above sea level.
    pub heights: [f32; 2],
    /// The lowest base and highest top of the cells with cloud of each layer that has any,
    /// metres above sea level.
    pub extents: Vec<(f32, f32)>,
}

/// What a frame's uniform is planned from besides the camera and the light.
pub(super) struct FarFrame<'a> {
    pub settings: &'a FarFieldSettings,
    pub map: &'a MapPlace,
    /// When the shown map began to fade in (the sky's clock, seconds) and over how long.
    pub fade: Option<(f64, f64)>,
    /// When the crossfade from the weather before began, and over how long.
    pub crossfade: Option<(f64, f64)>,
    /// The hue of the near decks' textures.
    pub sheet_hue: Vec3,
}

/// How far a crossfade begun at `start_s` over `over_s` has come at `now_s`, 0..=1.
pub(super) fn crossfade_progress(now_s: f64, start_s: f64, over_s: f64) -> f32 {
    if over_s <= 0.0 {
        return 1.0;
    }
    ((now_s - start_s) / over_s).clamp(0.0, 1.0) as f32
}

/// The uniform of a frame for a camera at `camera_m` (`camera_radius_m` from the Earth's
/// centre, 0 for the flat frame) under the light `light`, at `now_s` of the sky's clock.
pub(super) fn plan(
    f: &FarFrame,
    (camera_m, camera_radius_m): (DVec3, f32),
    light: &TimeOfDay,
    now_s: f64,
) -> GpuFarField {
    let s = f.settings;
    let map = f.map;
    let period = s.noise_period_m();
    let centre_rel = (map.centre_m - camera_m.truncate()).as_vec2();
    let noise = DVec2::new(
        map.centre_m.x.rem_euclid(period),
        map.centre_m.y.rem_euclid(period),
    )
    .as_vec2();
    // A far cloud's colours: Wang's mid-grey-to-white levels in the ambient light, with the
    // sun's share of its median directional shading on the top.
    let ambient = light.ambient_percent;
    let lit: Vec3 = Vec3::splat(0.9) * ambient + light.directional_rgb * 0.6;
    // A sheet's, in the hue of the textures the near decks are drawn with (the foggy ones are
    // blue-grey); the shader multiplies its type's top level into the ambient part.
    let sheet_ambient = Vec3::splat(ambient) * f.sheet_hue;
    let sheet_sun = light.directional_rgb * 0.6 * f.sheet_hue;
    let shade: Vec3 = Vec3::splat(0.62) * ambient + light.directional_rgb * 0.12;
    // The shader leaves out rays that meet a layer nearer than sqrt(0.8) of the band's
    // start, or off the map.
    let reach = (
        0.8f32.sqrt() * s.fade_start_m,
        centre_rel.length() + (map.side_m * std::f64::consts::FRAC_1_SQRT_2) as f32,
    );
    let band = band_elevations(camera_m.z as f32, camera_radius_m, &map.extents, reach)
        .unwrap_or((0.0, 0.0));
    GpuFarField {
        centre_rel_size: [
            centre_rel.x,
            centre_rel.y,
            map.side_m as f32,
            map.texels as f32,
        ],
        noise_fade: [noise.x, noise.y, s.fade_start_m, s.fade_end_m],
        lit_rgb: lit.extend(camera_m.z as f32).to_array(),
        shade_rgb: shade.extend(s.heaped_scale_m).to_array(),
        heights: [
            map.heights[0],
            map.heights[1],
            s.heaped_scale_m * 8.0,
            period as f32,
        ],
        fade: [
            f.fade.map_or(1.0, |(start, over)| {
                ((now_s - start) / over.max(1e-3)).clamp(0.0, 1.0) as f32
            }),
            band.0,
            band.1,
            (f.crossfade).map_or(1.0, |(start, over)| crossfade_progress(now_s, start, over)),
        ],
        puffs: [
            s.heaped_cloud_size_m[0],
            s.heaped_cloud_size_m[1],
            s.heaped_height_over_size,
            s.puff_share(),
        ],
        sheet_ambient_rgb: sheet_ambient.extend(0.0).to_array(),
        sheet_sun_rgb: sheet_sun.extend(0.0).to_array(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The map's place is given relative to the camera, and the fades run on the sky's clock:
    /// half-way through the fade-in and the crossfade, a half; before any map, whole.
    #[test]
    fn the_plan_places_the_map_around_the_camera_and_runs_its_fades() {
        let settings = FarFieldSettings::default();
        let map = MapPlace {
            centre_m: DVec2::new(10_000.0, -5_000.0),
            side_m: 960_000.0,
            texels: 96,
            heights: [1500.0, 9000.0],
            extents: vec![(800.0, 2500.0)],
        };
        let frame = FarFrame {
            settings: &settings,
            map: &map,
            fade: Some((10.0, 4.0)),
            crossfade: Some((11.0, 2.0)),
            sheet_hue: Vec3::ONE,
        };
        let light = crate::shading::TimeOfDayTable::default().at(30.0);
        let camera = DVec3::new(4_000.0, 1_000.0, 3_000.0);
        let gpu = plan(&frame, (camera, 0.0), &light, 12.0);
        assert_eq!(gpu.centre_rel_size, [6_000.0, -6_000.0, 960_000.0, 96.0]);
        assert_eq!(gpu.lit_rgb[3], 3_000.0);
        assert_eq!(gpu.fade[0], 0.5);
        assert_eq!(gpu.fade[3], 0.5);
        // The band of elevations the layers show in lies below the horizon's up to above it.
        assert!(gpu.fade[1] < gpu.fade[2]);
        let steady = FarFrame {
            fade: None,
            crossfade: None,
            ..frame
        };
        let gpu = plan(&steady, (camera, 0.0), &light, 12.0);
        assert_eq!((gpu.fade[0], gpu.fade[3]), (1.0, 1.0));
    }
}

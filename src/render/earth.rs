//! The round Earth under everything drawn far: a camera-relative point of the flat local frame
//! (east, north, up metres, heights above mean sea level) placed on the sphere of radius
//! `radius_m` the camera flies over. The flat frame's horizontal offset is taken as the arc
//! length along the Earth at the camera's distance from its centre, the offset's height as the
//! height above that sphere; the point then lies `(r_c + z) sin(s / r_c)` out and
//! `z cos(s / r_c) - r_c (1 - cos(s / r_c))` up from the camera (`r_c` the camera's distance from
//! the Earth's centre, `s` the horizontal offset, `z` the height offset). For small `s` the drop is
//! the familiar `s^2 / 2R`: 0.8 km at 100 km, 7.1 km at 300 km (DESIGN.md, "Weather at every
//! scale"). The shaders run the same function (`earth_curved` in `shaders/shared/frame.wgsl` and
//! `shaders/terrain.wgsl`): sprites, the impostors built from them, the far field and the demo
//! ground all go through it, so this is the renderer's projection path (tested below against
//! the sphere's own geometry). Settings: `[earth]` of `config/render.toml`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Settings of the round Earth (`[earth]` of `config/render.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EarthSettings {
    /// Draw the clouds and the demo ground on the curved Earth (false: the flat frame, as
    /// skycast did before; for comparison and tests).
    pub curvature: bool,
    /// The Earth's radius, metres (the mean radius, 6,371 km).
    pub radius_m: f64,
}

impl Default for EarthSettings {
    fn default() -> Self {
        Self {
            curvature: true,
            radius_m: 6_371_000.0,
        }
    }
}

impl EarthSettings {
    /// The camera's distance from the Earth's centre, metres, for a camera `camera_msl_m` above
    /// mean sea level; 0 with the curvature off (the shaders' flag for the flat frame).
    pub fn camera_radius_m(&self, camera_msl_m: f64) -> f32 {
        if self.curvature {
            (self.radius_m + camera_msl_m.max(-self.radius_m * 0.5)) as f32
        } else {
            0.0
        }
    }
}

/// How far below the camera's level plane the geometric horizon lies, radians: the dip, for a
/// camera `height_m` above the ground under it and `camera_radius_m` from the Earth's centre (0:
/// the flat frame, no dip). The sky's gradient starts there (`above_horizon` in
/// `shaders/shared/frame.wgsl`, the same operations in f32): from FL350 it is 3.3 degrees, and a
/// sky that started at the level plane showed a flat band of the horizon's haze above the Earth's
/// rim.
pub fn horizon_dip_rad(height_m: f32, camera_radius_m: f32) -> f32 {
    if camera_radius_m <= 0.0 {
        return 0.0;
    }
    let h = height_m.clamp(0.0, camera_radius_m);
    ((h * (2.0 * camera_radius_m - h)).sqrt() / camera_radius_m)
        .min(1.0)
        .asin()
}

/// A camera-relative point of the flat frame placed on the round Earth, camera-relative; the
/// point itself when `camera_radius_m` is 0 (no curvature). Keep in sync with `earth_curved`
/// in `shaders/shared/frame.wgsl` and `shaders/terrain.wgsl` (the same operations in f32).
pub fn curved_rel(rel: Vec3, camera_radius_m: f32) -> Vec3 {
    let s = (rel.x * rel.x + rel.y * rel.y).sqrt();
    if camera_radius_m <= 0.0 || s <= 0.0 {
        return rel;
    }
    let theta = s / camera_radius_m;
    let sin_half = (0.5 * theta).sin();
    // 1 - cos(theta), written so that it keeps its precision near the camera.
    let drop = 2.0 * sin_half * sin_half;
    let along = (camera_radius_m + rel.z) * theta.sin() / s;
    Vec3::new(
        rel.x * along,
        rel.y * along,
        rel.z * (1.0 - drop) - camera_radius_m * drop,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Camera;
    use glam::{DVec3, Vec4Swizzles};

    /// FL350 looking north 3 degrees down, 1280 x 720, the shipped field of view.
    fn camera() -> Camera {
        let settings = crate::render::RenderSettings::default();
        Camera {
            position_m: DVec3::new(0.0, 0.0, 35_000.0 * 0.3048),
            heading_deg: 0.0,
            pitch_deg: -3.0,
            fov_y_deg: settings.camera.fov_y_deg,
            aspect: 1280.0 / 720.0,
            near_m: settings.camera.near_m,
            far_m: 600_000.0,
        }
    }

    /// The pixel row (0 at the top of a 720-row image) at which the camera-relative point shows.
    fn row_of(camera: &Camera, rel: Vec3) -> f32 {
        let clip = camera.view_proj_relative() * rel.extend(1.0);
        let ndc = clip.xyz() / clip.w;
        (1.0 - ndc.y) * 0.5 * 720.0
    }

    /// The row of the true sphere: a point `height_m` above sea level `distance_m` along the
    /// surface (arc at sea level) north of the camera, from Earth-centred positions in f64.
    fn sphere_row(camera: &Camera, radius_m: f64, distance_m: f64, height_m: f64) -> f32 {
        let cam = DVec3::new(0.0, 0.0, radius_m + camera.position_m.z);
        let a = distance_m / radius_m;
        let point = DVec3::new(0.0, a.sin(), a.cos()) * (radius_m + height_m);
        let elevation = ((point - cam).normalize().z).asin();
        // The image row of that elevation straight ahead (north), through the same projection.
        let dir = DVec3::new(0.0, elevation.cos(), elevation.sin()) * 1000.0;
        row_of(camera, dir.as_vec3())
    }

    /// A flat layer 2,000 m above sea level, seen at 100, 200 and 300 km: where the renderer
    /// draws it (the flat frame's point through `curved_rel` and the camera's projection), at
    /// most `tolerance_px` from where the sphere puts it. Returns the worst miss, pixels.
    fn worst_miss_px(earth: EarthSettings) -> f32 {
        let camera = camera();
        let rc = earth.camera_radius_m(camera.position_m.z);
        let mut worst = 0.0f32;
        for km in [100.0, 200.0, 300.0] {
            // The flat frame's offset of a point `km` north, 2 km above sea level.
            let rel = Vec3::new(
                0.0,
                (km * 1000.0) as f32,
                (2000.0 - camera.position_m.z) as f32,
            );
            let drawn = row_of(&camera, curved_rel(rel, rc));
            let truth = sphere_row(&camera, 6_371_000.0, km * 1000.0, 2000.0);
            worst = worst.max((drawn - truth).abs());
        }
        worst
    }

    #[test]
    fn a_flat_layer_shows_where_the_sphere_puts_it_at_100_200_and_300_km() {
        let miss = worst_miss_px(EarthSettings::default());
        assert!(miss < 2.0, "{miss} px from the sphere's geometry");
    }

    #[test]
    fn with_the_curvature_off_the_layer_misses_by_more_than_2_px() {
        // The negative control: the flat frame puts the layer 7 km too high at 300 km.
        let miss = worst_miss_px(EarthSettings {
            curvature: false,
            ..EarthSettings::default()
        });
        assert!(miss > 2.0, "only {miss} px from the sphere's geometry");
    }

    #[test]
    fn the_drop_is_d_squared_over_2r_and_nothing_moves_near_the_camera() {
        let rc = 6_371_000.0;
        let at = |d: f32| curved_rel(Vec3::new(d, 0.0, 0.0), rc);
        // 7.1 km at 300 km (DESIGN.md), 0.78 km at 100 km.
        assert!(
            (at(300_000.0).z + 7_063.0).abs() < 20.0,
            "{}",
            at(300_000.0)
        );
        assert!((at(100_000.0).z + 785.0).abs() < 3.0, "{}", at(100_000.0));
        // Within a kilometre, only the drop: 7 cm at 922 m.
        let near = Vec3::new(600.0, -700.0, 35.0);
        let moved = curved_rel(near, rc) - near;
        assert!((moved.z + 0.0667).abs() < 0.002, "{moved}");
        assert!(moved.truncate().length() < 0.01, "{moved}");
        assert_eq!(curved_rel(near, 0.0), near);
    }

    #[test]
    fn the_sky_starts_at_the_rim_of_the_ground_the_renderer_draws() {
        // FL350 over sea-level ground: the dip is the sphere's tangent, 3.3 degrees.
        let h = 35_000.0 * 0.3048;
        let earth = EarthSettings::default();
        let rc = earth.camera_radius_m(h);
        let dip = horizon_dip_rad(h as f32, rc);
        let truth = (6_371_000.0 / (6_371_000.0 + h)).acos();
        assert!(
            (f64::from(dip) - truth).abs() < 2e-5,
            "{dip} against {truth}"
        );
        assert!(
            (dip.to_degrees() - 3.31).abs() < 0.01,
            "{}",
            dip.to_degrees()
        );
        // The highest the renderer's ground (sea level through `curved_rel`) shows, out to 600
        // km, is the dip below the level plane: there the sky's gradient begins.
        let rim = (1..=600)
            .map(|km| curved_rel(Vec3::new(0.0, km as f32 * 1000.0, -h as f32), rc))
            .map(|p| (p.z / p.length()).asin())
            .fold(f32::MIN, f32::max);
        assert!((rim + dip).abs() < 2e-4, "rim {rim}, dip {dip}");
        // The flat frame has no dip, nor has a camera on the ground.
        assert_eq!(horizon_dip_rad(h as f32, 0.0), 0.0);
        assert_eq!(horizon_dip_rad(0.0, rc), 0.0);
    }
}

//! The sky pass's plan: a view's frame uniform ([`GpuFrame`], `shaders/shared/frame.wgsl`)
//! from the camera, the sun and the light of the frame, as plain data. Every pass into the
//! host's targets reads it (the sky background and sun, the sprites, the ring, the far field,
//! the in-cloud fog, the composite); the sky writes it once per view and frame.

use glam::Vec3;

use super::SkyFlash;
use crate::render::gpu_types::GpuFrame;
use crate::render::settings::RenderSettings;
use crate::render::targets::SkyView;
use crate::shading::{AltitudeHaze, TimeOfDay};

/// What a view's frame uniform is planned from.
pub(super) struct FrameParts<'a> {
    pub camera: &'a SkyView,
    /// Towards the sun, east-north-up.
    pub sun_dir: Vec3,
    pub settings: &'a RenderSettings,
    /// The clear-sky light the clouds are lit with.
    pub clear_light: &'a TimeOfDay,
    /// The host's light under the cover over the camera.
    pub seen_light: &'a TimeOfDay,
    /// The mean share of the direct sun the cover over the camera lets through.
    pub cover_transmittance: f32,
    /// The haze the clouds fade into.
    pub haze: &'a AltitudeHaze,
    /// How far inside a cloud the camera is, 0..=1 (the in-cloud fog).
    pub in_cloud: f32,
    /// The host's depth where it drew nothing (1, or 0 with reversed Z).
    pub background_depth: f32,
    pub flash: Option<SkyFlash>,
}

/// The frame uniform of [`FrameParts`].
pub(super) fn plan(p: &FrameParts) -> GpuFrame {
    let camera = p.camera;
    let view_proj = camera.view_proj();
    let sun_cfg = &p.settings.sun;
    // In-cloud fog: the ambient of a mid-grey cloud at this time of day plus some sun.
    let fog_rgb =
        Vec3::splat(0.8) * p.clear_light.ambient_percent + p.clear_light.directional_rgb * 0.25;
    GpuFrame {
        view_proj: view_proj.to_cols_array_2d(),
        inv_view_proj: view_proj.inverse().to_cols_array_2d(),
        sun_dir: p
            .sun_dir
            .extend(sun_cfg.disc_radius_deg.to_radians().cos())
            .to_array(),
        // The sky's own sun glow and disc behind the clouds: dimmed by the cover as a whole,
        // the same with the shadows on or off.
        sun_rgb: (p.seen_light.directional_rgb * p.cover_transmittance)
            .extend(sun_cfg.glow_radius_deg.to_radians().cos())
            .to_array(),
        // w: the camera's height above the haze's base; its distance from the Earth's centre
        // (0: flat).
        sky_zenith_rgb: p
            .seen_light
            .sky_zenith_rgb
            .extend(camera.position_m.z as f32 - p.haze.base_msl_m)
            .to_array(),
        sky_horizon_rgb: p
            .seen_light
            .sky_horizon_rgb
            .extend(p.settings.earth.camera_radius_m(camera.position_m.z))
            .to_array(),
        in_cloud_rgba: fog_rgb.extend(p.in_cloud).to_array(),
        params: [
            p.background_depth,
            p.settings.clouds.soft_depth_fade_m.recip(),
            p.settings.clouds.soft_depth_fade_m,
            p.settings.in_cloud.visibility_m,
        ],
        haze: p.haze.to_gpu(),
        flash_reach: [p.flash.map_or(0.0, |f| f.reach_m), 0.0, 0.0, 0.0],
        depth_to_view: camera.depth_to_view(),
        flash: p.flash.map_or([0.0; 4], |f| {
            (f.position_m - camera.position_m)
                .as_vec3()
                .extend(f.light)
                .to_array()
        }),
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Mat4};

    use super::*;
    use crate::shading::TimeOfDayTable;

    fn parts_with<'a>(
        camera: &'a SkyView,
        (settings, light, haze): (&'a RenderSettings, &'a TimeOfDay, &'a AltitudeHaze),
        flash: Option<SkyFlash>,
    ) -> FrameParts<'a> {
        FrameParts {
            camera,
            sun_dir: Vec3::Z,
            settings,
            clear_light: light,
            seen_light: light,
            cover_transmittance: 0.5,
            haze,
            in_cloud: 0.25,
            background_depth: 1.0,
            flash,
        }
    }

    #[test]
    fn the_frame_carries_the_camera_the_cover_and_the_flash_as_the_shaders_read_them() {
        let camera = SkyView {
            position_m: DVec3::new(100.0, -50.0, 3000.0),
            view: Mat4::IDENTITY,
            projection: glam::camera::rh::proj::directx::perspective(
                1.0,
                16.0 / 9.0,
                1.0,
                100_000.0,
            ),
        };
        let settings = RenderSettings::default();
        let light = TimeOfDayTable::default().at(30.0);
        let haze = AltitudeHaze::uniform(1e-4);
        let flash = SkyFlash {
            position_m: DVec3::new(1100.0, -50.0, 3000.0),
            reach_m: 800.0,
            light: 2.0,
        };
        let frame = plan(&parts_with(
            &camera,
            (&settings, &light, &haze),
            Some(flash),
        ));
        // The sun glow is the seen sun dimmed by the cover's mean transmittance.
        let glow = light.directional_rgb * 0.5;
        assert!((Vec3::from_slice(&frame.sun_rgb[..3]) - glow).length() < 1e-6);
        // The in-cloud fog's strength, and the flash relative to the camera.
        assert_eq!(frame.in_cloud_rgba[3], 0.25);
        assert_eq!(frame.flash, [1000.0, 0.0, 0.0, 2.0]);
        assert_eq!(frame.flash_reach[0], 800.0);
        // The inverse is the inverse of the view-projection.
        let vp = Mat4::from_cols_array_2d(&frame.view_proj);
        let inv = Mat4::from_cols_array_2d(&frame.inv_view_proj);
        assert!((vp * inv).abs_diff_eq(Mat4::IDENTITY, 1e-4));
        // No flash: nothing lit.
        let dark = plan(&parts_with(&camera, (&settings, &light, &haze), None));
        assert_eq!(dark.flash, [0.0; 4]);
        assert_eq!(dark.flash_reach[0], 0.0);
    }
}

//! The sky's light and fog: the weather over the camera (its cover eased in time), the fog it
//! makes, the light of the time of day under that cover, and what a host reads of them (the
//! ground's haze, the horizon's colour, the share of the sun the cover lets through).

use glam::Vec3;

use super::Sky;
use super::SkyFlash;
use crate::render::stats::Lighting;
use crate::shading::SunPosition;
use crate::shading::TimeOfDay;
use crate::shading::hidden_above;
use crate::weather::BlockWeather;

impl Sky {
    /// The frame's light, planned before any pass (CPU only): the clear light of the sun's
    /// elevation that the clouds are lit with, the host's light under the cover over a camera
    /// at `altitude_m` (eased through a change of the weather) and the share of the sun that
    /// cover lets through.
    pub(super) fn light_frame(&mut self, sun: &SunPosition, altitude_m: f64) -> Lighting {
        self.clear_light = self.time_of_day.at(sun.elevation_deg as f32);
        let (hidden, _) = self.overhead_ease.show(
            self.sky_hidden_at(altitude_m),
            self.fog.0.visibility_m(&self.fog.1),
            self.elapsed_s,
        );
        self.seen_light = self
            .clear_light
            .under_cover(hidden, &self.time_of_day.overcast);
        // The host's sun is the clear sun, on or off: the shadow map dims it where the clouds
        // stop it, and with the shadows off nothing does (off casts no shadows; it does not
        // dim the ground evenly). The cover's mean dimming is kept apart for a host without
        // the map.
        self.cover_transmittance = 1.0 - hidden.clamp(0.0, 1.0);
        self.seen_light.directional_rgb = self.clear_light.directional_rgb;
        Lighting {
            sun_dir: sun.direction_enu().as_vec3(),
            time_of_day: self.clear_light,
            mapping: self.time_of_day.directional_mapping,
            forward: self.time_of_day.forward_scattering,
            model: self.time_of_day.shading.model,
            harris_lastra: self.time_of_day.harris_lastra,
        }
    }

    /// Replaces the fog and haze settings (the shipped `config/fog.toml` until called).
    pub fn set_fog_settings(&mut self, fog: crate::shading::FogSettings) {
        self.fog.0 = fog;
    }

    /// The weather over the camera (the layers and ground of its point of the weather field).
    /// Each frame works out how much of the sky the layers above the camera hide
    /// ([`crate::shading::hidden_above`]): below a thick deck the sky turns grey and dim and
    /// [`Self::light`] loses its sun; above it nothing changes. The clouds keep their own light.
    /// Until it is called the sky is taken as clear overhead.
    pub fn set_weather_overhead(&mut self, weather: &BlockWeather) {
        self.overhead = (weather.layers.clone(), weather.ground_elevation_m);
        self.fog.1 = weather.clone();
    }

    /// The weather overhead changes in time from now (a new report, not the camera moving
    /// through the weather): the cover's light and the fog's visibility go over to the next
    /// [`Self::set_weather_overhead`]'s across the clouds' formation time, as its clouds form,
    /// instead of at once. Called by [`crate::flight::SkySystem`] when it applies a new weather
    /// field; a host handing the weather itself calls it when the weather it hands is new.
    pub fn ease_weather_overhead(&mut self) {
        self.overhead_ease
            .begin(self.elapsed_s, f64::from(self.lifecycle.formation_s));
    }

    /// The fog a host draws over its scene: the visibility and obscuration of the weather over
    /// the camera ([`crate::shading::fog`]) under the last frame's horizon sky, the visibility
    /// the last frame showed ([`Self::ease_weather_overhead`]), thicker where the last frame
    /// found the camera in a rain or snow shaft.
    pub fn fog(&self) -> crate::shading::Fog {
        self.fog_for(self.views[0].in_rain)
    }

    /// The haze a host fogs its ground with along a view ray ([`crate::shading::AltitudeHaze`]:
    /// thinning with height), for [`Self::fog`] with its visibility at most `visibility_m`; the
    /// clouds fade into the same haze.
    pub fn ground_haze(&self, visibility_m: f32) -> crate::shading::AltitudeHaze {
        let mut fog = self.fog();
        fog.distance_m = fog.distance_m.min(visibility_m);
        self.fog.0.ground_haze(&fog, self.fog.1.ground_elevation_m)
    }

    /// The round Earth the sky draws on (`[earth]` of the renderer settings); a host draws its
    /// far ground on the same ([`crate::render::earth::curved_rel`]).
    pub fn earth(&self) -> crate::render::earth::EarthSettings {
        self.settings.earth
    }

    /// Lights the sprites near a lightning flash from inside this frame on (`None`: no flash).
    pub fn set_flash(&mut self, flash: Option<SkyFlash>) {
        self.flash = flash;
    }

    /// [`Self::fog`] with a view's rain.
    pub(super) fn fog_for(&self, in_rain: f32) -> crate::shading::Fog {
        let mut air = self.fog.0.fog(&self.fog.1, self.seen_light.sky_horizon_rgb);
        if let Some(shown) = self.overhead_ease.visibility_m() {
            air.distance_m = shown;
        }
        self.fog.0.in_rain(air, in_rain)
    }

    /// The fraction of the sky hidden above `altitude_m` by the weather overhead, 0..=1.
    pub fn sky_hidden_at(&self, altitude_m: f64) -> f32 {
        let (layers, ground_m) = &self.overhead;
        hidden_above(
            layers,
            *ground_m,
            altitude_m as f32,
            &self.time_of_day.overcast,
        )
    }

    /// Colour a host should fog its distant ground towards (the horizon sky colour now).
    pub fn horizon_rgb(&self) -> Vec3 {
        self.seen_light.sky_horizon_rgb
    }

    /// The light of the last prepared frame (see [`Self::set_weather_overhead`]): what a host
    /// lights its own scene with. Its sun (`directional_rgb`) is the clear direct sun, with the
    /// cloud shadows on or off: the host dims it by the shadow map ([`Self::cloud_shadows`])
    /// where the clouds stop it. With the shadows off the clouds cast none (the map lets all
    /// the sun through), so the ground is in the clear sun everywhere, as open ground is with
    /// them on. The sky colours are those under the cover over the camera. A host that draws
    /// without the map and wants the cover to dim its ground evenly multiplies the sun by
    /// [`Self::sun_cover_transmittance`]; skycast's own ground does not.
    pub fn light(&self) -> TimeOfDay {
        self.seen_light
    }

    /// The mean share (0..=1) of the direct sun the cloud cover over the camera lets through,
    /// of the last prepared frame: 1 minus the share of the sky it hides, eased through a
    /// change of the weather. Not applied to [`Self::light`]'s sun: it is for a host that does
    /// not look up the shadow map and wants its ground dimmed evenly under a cover instead
    /// (skycast's ground before the shadow map). The sky's own sun glow is dimmed by it.
    pub fn sun_cover_transmittance(&self) -> f32 {
        self.cover_transmittance
    }

    /// The time-of-day light for a sun position (for hosts lighting their own scene).
    pub fn light_for(&self, sun: &SunPosition) -> TimeOfDay {
        self.time_of_day.at(sun.elevation_deg as f32)
    }
}

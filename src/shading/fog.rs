//! Fog and haze from the weather: a [`BlockWeather`]'s visibility and obscuration in, the fog a
//! host draws over its ground ([`Fog`]: distance and colour) and the haze distance of the clouds
//! out. Settings: `config/fog.toml`.
//!
//! Visibility is the meteorological optical range: the distance at which a dark object's contrast
//! falls to 5% (WMO-No. 8, vol. I ch. 9). By Koschmieder's law the extinction coefficient is
//! `ln(20) / V`, about `3 / V`: a host fogging `1 - exp(-3 d / V)` hides 95% of what lies at the
//! visibility. The clouds' haze (`1 - exp(-d / haze_distance)`, 63% at the haze distance) gets
//! the same extinction: `haze_distance = V / 3`, never more than the renderer's clear-air haze.
//! The colour: the obscuration's own (fog grey-white, haze yellowish, smoke brown, dust tan) at
//! the brightness of the horizon sky, mixed with the horizon sky's colour; with no obscuration
//! the horizon sky's colour alone.
//!
//! Altitude haze ([`AltitudeHaze`]): the reported visibility is the surface's. Its haze lies in
//! the boundary layer: an extinction falling off exponentially with the height above the ground
//! (`boundary_layer_scale_height_m`, aerosol scale heights are 1-2 km), over clear air whose own
//! extinction (Rayleigh and background aerosol, `clear_air_visibility_m` at the surface) falls
//! off with the air's density (`clear_air_scale_height_m`, about 8 km). Along a straight ray from
//! height `h0` to `h1` over a distance `d`, an extinction `s exp(-h / H)` integrates to
//! `s d exp(-h_min / H) (1 - exp(-dh / H)) / (dh / H)` (`dh = |h1 - h0|`), so a ray down from
//! cruise altitude crosses the boundary layer's haze only near its end and the ground below the
//! clouds stays dark, while a ray along the ground keeps the surface visibility. With
//! `altitude_haze = false` the old uniform haze comes back (the same extinction everywhere).

use std::path::Path;

use glam::Vec3;
use serde::Deserialize;

use super::luminance;
use crate::config::{ConfigError, ShippedFile, TomlSettings};
use crate::weather::block::{BlockWeather, Obscuration};

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../config/fog.toml");

/// Settings of the fog (`config/fog.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FogSettings {
    /// Extinction coefficient times visibility (3: 5% contrast at the visibility).
    pub extinction_times_visibility: f32,
    /// A reported visibility at or above this, metres, is a capped report of clear air.
    pub capped_visibility_m: f32,
    /// The visibility clear air is drawn with, metres.
    pub clear_visibility_m: f32,
    /// Share of the obscuration's own colour in the fog, 0..=1.
    pub tint: f32,
    /// Visibility inside a rain or snow shaft, metres, divided by the shaft's opacity where the
    /// camera is.
    pub rain_visibility_m: f32,
    /// Haze that thins with height (true) or the same haze along the whole ray (false).
    pub altitude_haze: bool,
    /// Scale height of the boundary layer's haze (the part of the reported visibility above
    /// clear air's), metres.
    pub boundary_layer_scale_height_m: f32,
    /// Visibility of clear air at the surface (Rayleigh and background aerosol), metres.
    pub clear_air_visibility_m: f32,
    /// Scale height of clear air's extinction, metres.
    pub clear_air_scale_height_m: f32,
    /// Linear RGB of each obscuration in daylight.
    pub colours: ObscurationColours,
}

/// The haze along view rays: two extinctions, each falling off exponentially above the ground
/// (module docs). What a shader reads as `[boundary_layer_per_m, boundary_layer_scale_height_m,
/// clear_air_per_m, clear_air_scale_height_m]` (`haze_optical_depth` in
/// `shaders/shared/frame.wgsl` and `shaders/terrain.wgsl`: keep in sync).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AltitudeHaze {
    /// The boundary layer's extinction at the ground, per metre.
    pub boundary_layer_per_m: f32,
    /// Its scale height, metres (1e9: the same at every height).
    pub boundary_layer_scale_height_m: f32,
    /// Clear air's extinction at the ground, per metre.
    pub clear_air_per_m: f32,
    /// Its scale height, metres.
    pub clear_air_scale_height_m: f32,
    /// The height the two fall off from (the ground under the camera), metres above sea level.
    pub base_msl_m: f32,
}

impl AltitudeHaze {
    /// The same extinction `per_m` at every height (the haze before altitude haze).
    pub fn uniform(per_m: f32) -> Self {
        Self {
            boundary_layer_per_m: per_m,
            boundary_layer_scale_height_m: 1.0e9,
            clear_air_per_m: 0.0,
            clear_air_scale_height_m: 1.0,
            base_msl_m: 0.0,
        }
    }

    /// The optical depth of a straight ray `distance_m` long from `from_msl_m` to `to_msl_m`
    /// (heights above mean sea level). Same as `haze_optical_depth` in the shaders.
    pub fn optical_depth(&self, distance_m: f32, from_msl_m: f32, to_msl_m: f32) -> f32 {
        let h0 = from_msl_m - self.base_msl_m;
        let h1 = to_msl_m - self.base_msl_m;
        distance_m
            * (mean_extinction(
                self.boundary_layer_per_m,
                self.boundary_layer_scale_height_m,
                h0,
                h1,
            ) + mean_extinction(self.clear_air_per_m, self.clear_air_scale_height_m, h0, h1))
    }

    /// The fraction of what lies at the ray's end that shows through the haze, 0..=1.
    pub fn transmittance(&self, distance_m: f32, from_msl_m: f32, to_msl_m: f32) -> f32 {
        (-self.optical_depth(distance_m, from_msl_m, to_msl_m)).exp()
    }

    /// The four numbers the shaders read (the base goes with the camera's height).
    pub fn to_gpu(&self) -> [f32; 4] {
        [
            self.boundary_layer_per_m,
            self.boundary_layer_scale_height_m,
            self.clear_air_per_m,
            self.clear_air_scale_height_m,
        ]
    }
}

/// The mean of `per_m exp(-h / scale_m)` along a straight ray from height `h0` to `h1` (above
/// the base; below it counts as at it). Same as `haze_mean` in the shaders.
fn mean_extinction(per_m: f32, scale_m: f32, h0: f32, h1: f32) -> f32 {
    let low = h0.min(h1).max(0.0);
    let x = (h1 - h0).abs() / scale_m;
    let spread = if x < 1.0e-3 {
        1.0 - 0.5 * x
    } else {
        (1.0 - (-x).exp()) / x
    };
    per_m * (-low / scale_m).exp() * spread
}

/// Linear RGB per obscuration.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObscurationColours {
    /// BR.
    pub mist: [f32; 3],
    /// FG.
    pub fog: [f32; 3],
    /// HZ.
    pub haze: [f32; 3],
    /// FU.
    pub smoke: [f32; 3],
    /// DU, SA, DS, SS.
    pub dust: [f32; 3],
}

impl ObscurationColours {
    /// The colour of an obscuration.
    pub fn get(&self, o: Obscuration) -> Vec3 {
        Vec3::from_array(match o {
            Obscuration::Mist => self.mist,
            Obscuration::Fog => self.fog,
            Obscuration::Haze => self.haze,
            Obscuration::Smoke => self.smoke,
            Obscuration::Dust => self.dust,
        })
    }
}

/// The fog over a place: what a host draws its distant ground into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fog {
    /// The visibility, metres: 95% fog at this distance (`1 - exp(-3 d / distance_m)`).
    pub distance_m: f32,
    /// Fog colour, linear RGB.
    pub rgb: Vec3,
}

impl TomlSettings for FogSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/fog.toml", BUILTIN);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        if !(self.extinction_times_visibility > 0.0 && self.extinction_times_visibility.is_finite())
        {
            return Err(bad("extinction_times_visibility", "must be above 0"));
        }
        if !(self.capped_visibility_m > 0.0 && self.clear_visibility_m >= self.capped_visibility_m)
        {
            return Err(bad(
                "clear_visibility_m",
                "must be at least capped_visibility_m, which must be above 0",
            ));
        }
        if !(0.0..=1.0).contains(&self.tint) {
            return Err(bad("tint", "must be within 0..=1"));
        }
        if !(self.rain_visibility_m >= 1.0 && self.rain_visibility_m.is_finite()) {
            return Err(bad("rain_visibility_m", "must be at least 1 metre"));
        }
        let at_least_1 = [
            (
                "boundary_layer_scale_height_m",
                self.boundary_layer_scale_height_m,
            ),
            ("clear_air_visibility_m", self.clear_air_visibility_m),
            ("clear_air_scale_height_m", self.clear_air_scale_height_m),
        ];
        for (field, value) in at_least_1 {
            if !(value >= 1.0 && value.is_finite()) {
                return Err(bad(field, "must be at least 1 metre"));
            }
        }
        Ok(())
    }
}

impl FogSettings {
    /// The visibility a weather is drawn with, metres: the reported one, clear air for a capped
    /// report, never under 1 m.
    pub fn visibility_m(&self, weather: &BlockWeather) -> f32 {
        let v = weather.visibility_m;
        if !v.is_finite() || v >= self.capped_visibility_m {
            self.clear_visibility_m
        } else {
            v.max(1.0)
        }
    }

    /// The fog of a weather under a horizon sky of colour `horizon_rgb` (linear).
    pub fn fog(&self, weather: &BlockWeather, horizon_rgb: Vec3) -> Fog {
        let rgb = match weather.obscuration {
            None => horizon_rgb,
            Some(o) => {
                let own = self.colours.get(o);
                let scaled = own * (luminance(horizon_rgb) / luminance(own).max(1e-4));
                horizon_rgb.lerp(scaled, self.tint)
            }
        };
        Fog {
            distance_m: self.visibility_m(weather),
            rgb,
        }
    }

    /// `fog` with the camera in a rain or snow shaft `in_rain` (0..=1) opaque where it is: the
    /// visibility `rain_visibility_m / in_rain`, if less than the air's.
    pub fn in_rain(&self, fog: Fog, in_rain: f32) -> Fog {
        if in_rain <= 0.0 {
            return fog;
        }
        Fog {
            distance_m: fog
                .distance_m
                .min(self.rain_visibility_m / in_rain.min(1.0)),
            ..fog
        }
    }

    /// The clouds' haze distance (63% faded) in a fog, metres: the same extinction as the fog,
    /// never more than `clear_haze_m`, the renderer's clear-air haze distance.
    pub fn haze_distance_m(&self, fog: &Fog, clear_haze_m: f32) -> f32 {
        (fog.distance_m / self.extinction_times_visibility).min(clear_haze_m)
    }

    /// The haze the clouds fade into under a fog whose ground lies `ground_msl_m` above sea
    /// level: with `altitude_haze`, the fog's visibility at the surface (the boundary layer's
    /// share above clear air's) thinning with height; without, the old uniform haze of
    /// [`Self::haze_distance_m`].
    pub fn cloud_haze(&self, fog: &Fog, clear_haze_m: f32, ground_msl_m: f32) -> AltitudeHaze {
        if !self.altitude_haze {
            return AltitudeHaze::uniform(1.0 / self.haze_distance_m(fog, clear_haze_m).max(1.0));
        }
        self.ground_haze(fog, ground_msl_m)
    }

    /// The haze a host fogs its ground with (the same as the clouds' with `altitude_haze`;
    /// without, the fog's uniform `extinction_times_visibility / distance_m`).
    pub fn ground_haze(&self, fog: &Fog, ground_msl_m: f32) -> AltitudeHaze {
        let surface = self.extinction_times_visibility / fog.distance_m.max(1.0);
        if !self.altitude_haze {
            return AltitudeHaze::uniform(surface);
        }
        let clear = self.extinction_times_visibility / self.clear_air_visibility_m;
        AltitudeHaze {
            boundary_layer_per_m: (surface - clear).max(0.0),
            boundary_layer_scale_height_m: self.boundary_layer_scale_height_m,
            clear_air_per_m: clear,
            clear_air_scale_height_m: self.clear_air_scale_height_m,
            base_msl_m: if ground_msl_m.is_finite() {
                ground_msl_m
            } else {
                0.0
            },
        }
    }
}

impl Default for FogSettings {
    /// The shipped `config/fog.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn weather(visibility_m: f32, obscuration: Option<Obscuration>) -> BlockWeather {
        BlockWeather {
            visibility_m,
            obscuration,
            ..BlockWeather::default()
        }
    }

    #[test]
    fn an_800_m_fog_hides_95_percent_at_800_m_and_greys_the_horizon() {
        let s = FogSettings::default();
        let horizon = Vec3::new(0.45, 0.60, 0.85);
        let fog = s.fog(&weather(800.0, Some(Obscuration::Fog)), horizon);
        assert_eq!(fog.distance_m, 800.0);
        let hidden = |d: f32| 1.0 - (-s.extinction_times_visibility * d / fog.distance_m).exp();
        assert!(hidden(800.0) > 0.94 && hidden(800.0) < 0.96);
        assert!(hidden(200.0) < 0.6);
        // Greyer than the blue horizon, about as bright.
        let spread = |c: Vec3| c.max_element() - c.min_element();
        assert!(spread(fog.rgb) < 0.5 * spread(horizon), "{}", fog.rgb);
        assert!((luminance(fog.rgb) - luminance(horizon)).abs() < 0.02);
        // The clouds fade by the same law: 63% at a third of the visibility.
        assert!((s.haze_distance_m(&fog, 50_000.0) - 800.0 / 3.0).abs() < 1e-3);
    }

    #[test]
    fn rain_thickens_the_fog_by_its_opacity_and_never_clears_it() {
        let s = FogSettings::default();
        let clear = s.fog(&weather(9999.0, None), Vec3::ONE);
        assert_eq!(s.in_rain(clear, 0.0), clear);
        // Heavy rain at a storm's core (0.8 opaque): 1,500 m / 0.8; light (0.35): over 4 km.
        assert_eq!(s.in_rain(clear, 0.8).distance_m, 1875.0);
        assert!((s.in_rain(clear, 0.35).distance_m - 4285.7).abs() < 1.0);
        assert_eq!(s.in_rain(clear, 0.8).rgb, clear.rgb);
        // A fog thicker than the rain's stays as it is.
        let fog = s.fog(&weather(600.0, Some(Obscuration::Fog)), Vec3::ONE);
        assert_eq!(s.in_rain(fog, 0.8).distance_m, 600.0);
    }

    #[test]
    fn capped_reports_are_clear_air_and_clear_air_keeps_the_horizon_colour() {
        let s = FogSettings::default();
        let horizon = Vec3::new(0.45, 0.60, 0.85);
        let clear = s.fog(&weather(9999.0, None), horizon);
        assert_eq!(clear.distance_m, 40_000.0);
        assert_eq!(clear.rgb, horizon);
        assert_eq!(s.haze_distance_m(&clear, 5_000.0), 5_000.0);
        // Smoke and dust keep their hue: redder than blue.
        for o in [Obscuration::Smoke, Obscuration::Dust] {
            let f = s.fog(&weather(3000.0, Some(o)), horizon);
            assert!(f.rgb.x > f.rgb.z, "{o:?} {}", f.rgb);
        }
    }

    #[test]
    fn from_fl350_the_ground_below_shows_through_and_the_surface_keeps_its_visibility() {
        let s = FogSettings::default();
        // 10 km taken as it is (a report of 9999 is clear air's 40 km: thinner still).
        let fog = Fog {
            distance_m: 10_000.0,
            rgb: Vec3::ONE,
        };
        let haze = s.ground_haze(&fog, 200.0);
        // Along the ground: the surface visibility (5% contrast at 10 km).
        let along = haze.transmittance(10_000.0, 210.0, 210.0);
        assert!((along - 0.05).abs() < 0.005, "{along}");
        // From FL350, 30 degrees down to the ground (21 km): the ground shows through (the
        // boundary layer's optical depth 0.34 straight down, clear air's 0.12, twice that).
        let down = haze.transmittance(21_000.0, 10_668.0, 200.0);
        assert!(down > 0.35, "{down}");
        // The old haze hid it almost all (a third of the visibility, 63%).
        let old = s.cloud_haze(&fog, 50_000.0, 200.0);
        let before = FogSettings {
            altitude_haze: false,
            ..s
        }
        .cloud_haze(&fog, 50_000.0, 200.0);
        assert_eq!(old, haze);
        assert!(before.transmittance(21_000.0, 10_668.0, 200.0) < 0.01);
        // The optical depth is the integral of the extinction: a midpoint sum agrees.
        let n = 10_000;
        let sum: f32 = (0..n)
            .map(|k| {
                let h = 10_668.0 + (200.0 - 10_668.0) * (k as f32 + 0.5) / n as f32;
                haze.optical_depth(1.0, h, h) * 21_000.0 / n as f32
            })
            .sum();
        let exact = haze.optical_depth(21_000.0, 10_668.0, 200.0);
        assert!((sum - exact).abs() < 0.01 * exact, "{sum} {exact}");
    }

    #[test]
    fn bad_settings_name_their_line() {
        let text = BUILTIN.replace("tint = 0.85", "tint = 1.5");
        let err = FogSettings::parse(&text, Path::new("fog.toml")).unwrap_err();
        let line = BUILTIN.lines().position(|l| l == "tint = 0.85").unwrap() + 1;
        assert!(
            err.to_string()
                .starts_with(&format!("fog.toml:{line}: field `tint`")),
            "{err}"
        );
    }
}

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

use std::path::Path;

use glam::Vec3;
use serde::Deserialize;

use crate::config::{ConfigError, parse_toml};
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
    /// Linear RGB of each obscuration in daylight.
    pub colours: ObscurationColours,
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

impl FogSettings {
    /// Reads settings from a TOML file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|err| ConfigError::whole_file(path, format!("cannot read: {err}")))?;
        Self::parse(&text, path)
    }

    /// Parses settings text that came from `path`.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let s: Self = parse_toml(text, path)?;
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        if !(s.extinction_times_visibility > 0.0 && s.extinction_times_visibility.is_finite()) {
            return Err(bad("extinction_times_visibility", "must be above 0"));
        }
        if !(s.capped_visibility_m > 0.0 && s.clear_visibility_m >= s.capped_visibility_m) {
            return Err(bad(
                "clear_visibility_m",
                "must be at least capped_visibility_m, which must be above 0",
            ));
        }
        if !(0.0..=1.0).contains(&s.tint) {
            return Err(bad("tint", "must be within 0..=1"));
        }
        if !(s.rain_visibility_m >= 1.0 && s.rain_visibility_m.is_finite()) {
            return Err(bad("rain_visibility_m", "must be at least 1 metre"));
        }
        Ok(s)
    }

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
                let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
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
}

impl Default for FogSettings {
    /// The shipped `config/fog.toml` (a test proves it parses).
    fn default() -> Self {
        match Self::parse(BUILTIN, Path::new("config/fog.toml")) {
            Ok(s) => s,
            Err(err) => panic!("built-in config/fog.toml: {err}"),
        }
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
        let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        assert!((lum(fog.rgb) - lum(horizon)).abs() < 0.02);
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

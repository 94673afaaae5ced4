//! Daylight under the clouds: how much of the sky above a point the cloud layers hide, and what
//! that does to the light below them. Wang's tables light the clouds themselves; under a thick
//! deck the sky seen below its base (the horizon band, the haze the terrain and far clouds fade
//! into) must turn grey and dim and the ground loses its sun, or a nimbostratus day shows a bright
//! blue horizon. The cloud sprites keep their own lighting.
//!
//! In: a block's weather layers, its ground elevation and the camera altitude (metres above sea
//! level). Out: the hidden fraction 0 (clear) ..= 1 (nothing of the sky shows through), and the
//! time-of-day light seen under it. Settings: the `[overcast]` table of `config/time_of_day.toml`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{TimeOfDay, luminance};
use crate::weather::{BlockLayer, CloudType, METRES_PER_FOOT};

const M_PER_FT: f32 = METRES_PER_FOOT as f32;

/// The `[overcast]` table of `config/time_of_day.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OvercastLight {
    /// Thickness of water cloud (every type but the cirrus family) that lets through 1/e of the
    /// light, metres: a layer of thickness `t` hides `1 - exp(-t / this)` of what is behind it.
    pub water_e_folding_m: f32,
    /// How much of the light a whole layer of cirrus, cirrocumulus or cirrostratus hides
    /// (thin ice cloud: the sky stays blue behind it).
    pub ice_layer_opacity: f32,
    /// The hidden fraction where the sky starts to turn grey: below it the sky between the clouds
    /// is still the clear sky.
    pub grey_from: f32,
    /// Brightness of the sky colours under a wholly hidden sky, as a fraction of their luminance.
    pub covered_sky_brightness: f32,
}

impl Default for OvercastLight {
    fn default() -> Self {
        Self {
            water_e_folding_m: 50.0,
            ice_layer_opacity: 0.3,
            grey_from: 0.6,
            covered_sky_brightness: 0.6,
        }
    }
}

impl OvercastLight {
    /// The first field out of range, with why (for the table's error message).
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        let checks = [
            (
                "overcast.water_e_folding_m",
                self.water_e_folding_m,
                f32::MIN_POSITIVE,
                f32::MAX,
            ),
            (
                "overcast.ice_layer_opacity",
                self.ice_layer_opacity,
                0.0,
                1.0,
            ),
            ("overcast.grey_from", self.grey_from, 0.0, 0.999),
            (
                "overcast.covered_sky_brightness",
                self.covered_sky_brightness,
                0.0,
                1.0,
            ),
        ];
        checks
            .into_iter()
            .find(|&(_, v, lo, hi)| !(lo..=hi).contains(&v))
            .map(|(field, v, lo, hi)| {
                let range = if hi == f32::MAX {
                    "greater than 0".to_owned()
                } else {
                    format!("{lo}..={hi}")
                };
                (field, format!("must be {range}, is {v}"))
            })
    }
}

/// Whether a type is thin ice cloud (the cirrus family).
fn is_ice(t: CloudType) -> bool {
    matches!(
        t,
        CloudType::Cirrus | CloudType::Cirrocumulus | CloudType::Cirrostratus
    )
}

/// The fraction of the sky above `altitude_m` that `layers` hide (0 clear ..= 1 nothing shows):
/// each layer hides its coverage times its opacity, the part of it above the camera counted, and
/// layers combine as independent filters, `1 - prod(1 - cover * opacity)`.
pub fn hidden_above(
    layers: &[BlockLayer],
    ground_m: f32,
    altitude_m: f32,
    s: &OvercastLight,
) -> f32 {
    let clear = layers.iter().fold(1.0, |clear, layer| {
        let base = ground_m + layer.base_ft_agl.max(0.0) * M_PER_FT;
        let thickness = layer.thickness_ft.max(0.0) * M_PER_FT;
        let above = (base + thickness - altitude_m.max(base)).clamp(0.0, thickness);
        if above <= 0.0 {
            return clear;
        }
        let opacity = if is_ice(layer.cloud_type) {
            s.ice_layer_opacity * above / thickness
        } else {
            1.0 - (-above / s.water_e_folding_m).exp()
        };
        let cover = (layer.coverage_oktas / 8.0).clamp(0.0, 1.0);
        clear * (1.0 - cover * opacity)
    });
    (1.0 - clear).clamp(0.0, 1.0)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl TimeOfDay {
    /// The light under a sky `hidden` (0..=1, see [`hidden_above`]) by cloud: the direct sun
    /// dimmed by what hides it, and past `grey_from` the sky colours turned towards a dimmer grey
    /// of their own luminance. Ambient is left alone: the clouds scatter it down.
    pub fn under_cover(self, hidden: f32, s: &OvercastLight) -> TimeOfDay {
        let hidden = hidden.clamp(0.0, 1.0);
        let grey = smoothstep(s.grey_from, 1.0, hidden);
        let covered = |c: Vec3| c.lerp(Vec3::splat(luminance(c) * s.covered_sky_brightness), grey);
        TimeOfDay {
            ambient_percent: self.ambient_percent,
            directional_rgb: self.directional_rgb * (1.0 - hidden),
            sky_zenith_rgb: covered(self.sky_zenith_rgb),
            sky_horizon_rgb: covered(self.sky_horizon_rgb),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::TypeSource;

    fn layer(cloud_type: CloudType, oktas: f32, base_ft: f32, thickness_ft: f32) -> BlockLayer {
        BlockLayer {
            cloud_type,
            type_source: TypeSource::HeightRule,
            coverage_oktas: oktas,
            base_ft_agl: base_ft,
            thickness_ft,
        }
    }

    fn saturation(c: Vec3) -> f32 {
        (c.max_element() - c.min_element()) / c.max_element().max(1e-6)
    }

    #[test]
    fn thick_overcast_hides_the_sky_below_it_and_nothing_above_it() {
        let s = OvercastLight::default();
        let ns = [layer(CloudType::Nimbostratus, 8.0, 1500.0, 8000.0)];
        assert!(hidden_above(&ns, 100.0, 300.0, &s) > 0.99);
        // Above the top (100 m + 9,500 ft = 2,995.6 m): nothing hides the sky.
        assert_eq!(hidden_above(&ns, 100.0, 3100.0, &s), 0.0);
        // Any real stratus deck (here 800 ft) is all but opaque.
        let st = [layer(CloudType::Stratus, 8.0, 1000.0, 800.0)];
        assert!(hidden_above(&st, 0.0, 0.0, &s) > 0.99);
        // Inside the deck, 25 m below its top: the part above counts.
        let inside = hidden_above(&ns, 100.0, 2970.6, &s);
        assert!((inside - (1.0 - (-0.5f32).exp())).abs() < 0.01, "{inside}");
        assert_eq!(hidden_above(&[], 0.0, 0.0, &s), 0.0);
    }

    #[test]
    fn cover_and_thin_ice_hide_part_of_the_sky() {
        let s = OvercastLight::default();
        let cu = [layer(CloudType::CumulusMediocris, 3.0, 3000.0, 3000.0)];
        let hidden = hidden_above(&cu, 0.0, 0.0, &s);
        assert!((0.3..0.38).contains(&hidden), "{hidden}");
        let ci = [layer(CloudType::Cirrostratus, 8.0, 25_000.0, 3000.0)];
        assert!((hidden_above(&ci, 0.0, 0.0, &s) - 0.3).abs() < 1e-6);
        // Independent filters: cumulus under a cirrostratus sheet.
        let both = [cu[0], ci[0]];
        let expected = 1.0 - (1.0 - hidden) * 0.7;
        assert!((hidden_above(&both, 0.0, 0.0, &s) - expected).abs() < 1e-6);
    }

    #[test]
    fn under_a_hidden_sky_the_light_is_grey_and_dim_and_the_sun_gone() {
        let s = OvercastLight::default();
        let noon = crate::shading::TimeOfDayTable::default().at(50.0);
        assert_eq!(noon.under_cover(0.0, &s), noon);
        // Scattered cloud: the gaps still show the blue sky.
        let scattered = noon.under_cover(0.4, &s);
        assert_eq!(scattered.sky_horizon_rgb, noon.sky_horizon_rgb);
        assert!((scattered.directional_rgb - noon.directional_rgb * 0.6).length() < 1e-5);
        let overcast = noon.under_cover(1.0, &s);
        assert!(saturation(noon.sky_horizon_rgb) > 0.2);
        assert!(saturation(overcast.sky_horizon_rgb) < 1e-4);
        assert!(overcast.sky_horizon_rgb.x < noon.sky_horizon_rgb.z);
        assert_eq!(overcast.directional_rgb, Vec3::ZERO);
        assert_eq!(overcast.ambient_percent, noon.ambient_percent);
    }

    #[test]
    fn out_of_range_settings_are_named() {
        let s = OvercastLight {
            grey_from: 1.0,
            ..OvercastLight::default()
        };
        let (field, why) = s.invalid_field().unwrap();
        assert_eq!(field, "overcast.grey_from");
        assert!(why.contains("0..=0.999"), "{why}");
        assert!(OvercastLight::default().invalid_field().is_none());
    }
}

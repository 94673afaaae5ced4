//! How the reports' weather and a weather model's blend at a point, given the reports' weight
//! there (`WeatherField::with_model`): layers by cover, surface values linearly.

use glam::DVec2;

use super::wind_from_velocity_kt;
use crate::weather::block::{BlockLayer, BlockWeather, Wind};

/// The reported layers (their covers times the reports' weight `s`) and the model's (times
/// `1 - s`), lowest base first: each fades in and out in cover, so nothing pops where `s`
/// changes.
pub(super) fn layers(
    reported: Vec<BlockLayer>,
    s: f64,
    modelled: Vec<BlockLayer>,
) -> Vec<BlockLayer> {
    let scaled = |layers: Vec<BlockLayer>, w: f64| {
        layers.into_iter().filter_map(move |mut l| {
            l.coverage_oktas *= w as f32;
            (w > 0.0).then_some(l)
        })
    };
    if s >= 1.0 {
        return reported;
    }
    let mut out: Vec<BlockLayer> = scaled(reported, s)
        .chain(scaled(modelled, 1.0 - s))
        .collect();
    out.sort_by(|a, b| a.base_ft_agl.total_cmp(&b.base_ft_agl));
    out
}

/// The surface values of the reports' weather (weight `s`) and the model's (weight `1 - s`):
/// numbers linear, the wind as a vector; the obscuration the reports' while their weight
/// leads. The layers are the reports' weather's own (already blended).
pub(super) fn surface(reported: BlockWeather, s: f64, model: &BlockWeather) -> BlockWeather {
    let mix = |a: f32, b: f32| (f64::from(a) * s + f64::from(b) * (1.0 - s)) as f32;
    let velocity = |w: Wind| -> DVec2 {
        let to = (f64::from(w.from_deg) + 180.0).to_radians();
        DVec2::new(to.sin(), to.cos()) * f64::from(w.speed_kt)
    };
    let v = velocity(reported.wind) * s + velocity(model.wind) * (1.0 - s);
    BlockWeather {
        visibility_m: mix(reported.visibility_m, model.visibility_m),
        obscuration: reported.obscuration.filter(|_| s >= 0.5),
        wind: wind_from_velocity_kt(v.x, v.y),
        temperature_c: mix(reported.temperature_c, model.temperature_c),
        dewpoint_c: mix(reported.dewpoint_c, model.dewpoint_c),
        precipitation: mix(reported.precipitation, model.precipitation),
        thunder: mix(reported.thunder, model.thunder),
        ground_elevation_m: mix(reported.ground_elevation_m, model.ground_elevation_m),
        ..reported
    }
}

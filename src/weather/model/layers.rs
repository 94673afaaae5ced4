//! The model's cloud layers and surface weather at a point, as the reports' field gives them.
//!
//! Each of the model's low, middle and high layers (and its convective layer) with at least
//! `cover_min_oktas` becomes one [`BlockLayer`]: its cover, % to oktas (the layer's own cover,
//! as [`BlockLayer::coverage_oktas`] is; faded in from the least cover to twice it); its base and top, the heights of its bottom and top
//! pressures in the model's column ([`super::column`]) above the model's ground; its type by
//! level, cover, rain and CAPE ([`ModelLayerSettings`]).

use glam::DVec2;

use super::GridPoint;
use super::column::{self, HeightLevel};
use super::fields::{self, LayerFields, ModelLayer};
use super::{ModelField, ModelLayerSettings, ModelSettings};
use crate::weather::block::{
    BlockLayer, BlockWeather, METRES_PER_FOOT, METRES_PER_KNOT, TypeSource, Wind,
};
use crate::weather::cloud_type::CloudType;

/// The model's cloud layers at a point, lowest base first.
pub fn layers_at(
    model: &ModelField,
    lat_deg: f64,
    lon_deg: f64,
    settings: &ModelLayerSettings,
) -> Vec<BlockLayer> {
    let point = model.point(lat_deg, lon_deg);
    let levels = column::heights_at(model, &point);
    let at = |key| model.value_with(key, &point);
    let ground_m = at(&fields::OROGRAPHY).unwrap_or(0.0);
    let cape = at(&fields::CAPE).unwrap_or(0.0);
    let rain_mm_h = at(&fields::PRECIPITATION_RATE).unwrap_or(0.0) * 3600.0;
    let mut out: Vec<BlockLayer> = [
        fields::LOW,
        fields::MIDDLE,
        fields::HIGH,
        fields::CONVECTIVE,
    ]
    .iter()
    .filter_map(|layer| {
        let oktas = at(&layer.cover)? * 0.08;
        let min = settings.cover_min_oktas.max(1e-6);
        if oktas < min {
            return None;
        }
        let (base_ft, thickness_ft) = extent_ft(model, &levels, layer, &point)?;
        let base_ft_agl = (base_ft - ground_m / METRES_PER_FOOT).max(0.0);
        let thickness_ft = thickness_ft.max(settings.thickness_min_ft);
        let facts = Facts {
            oktas,
            thickness_ft,
            cape,
            rain_mm_h,
        };
        Some(BlockLayer {
            cloud_type: cloud_type(layer, &facts, settings),
            type_source: TypeSource::Model,
            // From the least cover to twice it the layer fades in, so that it does not pop
            // where the model's cover crosses the least.
            coverage_oktas: (oktas.min(8.0) * ((oktas - min) / min).min(1.0)) as f32,
            base_ft_agl: base_ft_agl as f32,
            thickness_ft: thickness_ft as f32,
        })
    })
    .collect();
    out.sort_by(|a, b| a.base_ft_agl.total_cmp(&b.base_ft_agl));
    out
}

/// A layer's base, feet MSL, and thickness, feet, from its bottom and top pressures.
fn extent_ft(
    model: &ModelField,
    levels: &[HeightLevel],
    layer: &LayerFields,
    point: &GridPoint,
) -> Option<(f64, f64)> {
    let bottom_pa = model.value_with(&layer.bottom, point)?;
    let top_pa = model.value_with(&layer.top, point)?;
    let base_m = column::height_of_pressure(levels, bottom_pa)?;
    let top_m = column::height_of_pressure(levels, top_pa)?;
    Some((
        base_m / METRES_PER_FOOT,
        (top_m - base_m).max(0.0) / METRES_PER_FOOT,
    ))
}

/// What types a model layer.
struct Facts {
    oktas: f64,
    thickness_ft: f64,
    cape: f64,
    rain_mm_h: f64,
}

/// The type of a model layer.
fn cloud_type(layer: &LayerFields, f: &Facts, s: &ModelLayerSettings) -> CloudType {
    let sheet = f.oktas >= s.sheet_cover_oktas;
    match layer.layer {
        ModelLayer::Convective if f.cape >= s.cumulonimbus_cape_j_kg => CloudType::Cumulonimbus,
        ModelLayer::Convective => CloudType::CumulusCongestus,
        ModelLayer::High if sheet => CloudType::Cirrostratus,
        ModelLayer::High => CloudType::Cirrus,
        ModelLayer::Middle if sheet => CloudType::Altostratus,
        ModelLayer::Middle => CloudType::Altocumulus,
        ModelLayer::Low
            if f.oktas >= s.nimbostratus_cover_oktas && f.rain_mm_h >= s.nimbostratus_rain_mm_h =>
        {
            CloudType::Nimbostratus
        }
        ModelLayer::Low
            if f.oktas >= s.stratus_cover_oktas && f.thickness_ft <= s.stratus_thickness_max_ft =>
        {
            CloudType::Stratus
        }
        ModelLayer::Low if f.oktas <= s.cumulus_cover_oktas && f.cape >= s.cumulus_cape_j_kg => {
            CloudType::CumulusMediocris
        }
        ModelLayer::Low => CloudType::Stratocumulus,
    }
}

/// The model's weather at a point: its layers and its surface values.
pub fn weather_at(
    model: &ModelField,
    lat_deg: f64,
    lon_deg: f64,
    settings: &ModelSettings,
) -> BlockWeather {
    let layers = layers_at(model, lat_deg, lon_deg, &settings.layers);
    let point = model.point(lat_deg, lon_deg);
    let at = |key| model.value_with(key, &point);
    let levels = column::levels_at(model, &point);
    let lowest = levels.first();
    let temperature_c = at(&fields::TEMPERATURE_2M)
        .map(|k| k - 273.15)
        .or(lowest.map(|l| l.temperature_c))
        .unwrap_or(15.0);
    let humidity = at(&fields::HUMIDITY_2M)
        .or(lowest.and_then(|l| l.humidity_pct))
        .unwrap_or(70.0);
    let wind_kt = match (at(&fields::WIND_U_10M), at(&fields::WIND_V_10M)) {
        (Some(u), Some(v)) => DVec2::new(u, v) / METRES_PER_KNOT,
        _ => lowest.map_or(DVec2::ZERO, |l| l.velocity_kt),
    };
    let rain_mm_h = at(&fields::PRECIPITATION_RATE).unwrap_or(0.0) * 3600.0;
    let thunder = layers
        .iter()
        .any(|l| l.cloud_type == CloudType::Cumulonimbus);
    BlockWeather {
        layers,
        visibility_m: at(&fields::VISIBILITY).unwrap_or(settings.surface.visibility_m) as f32,
        obscuration: None,
        wind: wind_of(wind_kt),
        temperature_c: temperature_c as f32,
        dewpoint_c: dewpoint_c(temperature_c, humidity) as f32,
        precipitation: settings.surface.precipitation(rain_mm_h) as f32,
        thunder: if thunder { 2.0 } else { 0.0 },
        ground_elevation_m: at(&fields::OROGRAPHY).unwrap_or(0.0) as f32,
        cover: None,
    }
}

/// The wind of a velocity, knots east/north.
fn wind_of(v: DVec2) -> Wind {
    if v.length() < 1e-9 {
        return Wind::default();
    }
    Wind {
        from_deg: ((v.x.atan2(v.y).to_degrees() + 180.0).rem_euclid(360.0)) as f32,
        speed_kt: v.length() as f32,
    }
}

/// The dewpoint, C, of air at `temperature_c` and relative humidity `humidity_pct` (Magnus
/// formula, Alduchov and Eskridge 1996: b = 17.625, c = 243.04 C).
fn dewpoint_c(temperature_c: f64, humidity_pct: f64) -> f64 {
    let (b, c) = (17.625, 243.04);
    let gamma =
        (humidity_pct.clamp(1.0, 100.0) / 100.0).ln() + b * temperature_c / (c + temperature_c);
    c * gamma / (b - gamma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::model::ModelSettings;

    fn facts(oktas: f64, thickness_ft: f64, cape: f64, rain_mm_h: f64) -> Facts {
        Facts {
            oktas,
            thickness_ft,
            cape,
            rain_mm_h,
        }
    }

    #[test]
    fn a_layer_is_typed_by_its_level_cover_rain_and_cape() {
        let s = ModelSettings::default().layers;
        let t = |layer: &LayerFields, f: Facts| cloud_type(layer, &f, &s);
        use fields::{CONVECTIVE, HIGH, LOW, MIDDLE};
        assert_eq!(
            t(&CONVECTIVE, facts(3.0, 9000.0, 1500.0, 0.0)),
            CloudType::Cumulonimbus
        );
        assert_eq!(
            t(&CONVECTIVE, facts(3.0, 9000.0, 300.0, 0.0)),
            CloudType::CumulusCongestus
        );
        assert_eq!(
            t(&HIGH, facts(7.0, 5000.0, 0.0, 0.0)),
            CloudType::Cirrostratus
        );
        assert_eq!(t(&HIGH, facts(3.0, 5000.0, 0.0, 0.0)), CloudType::Cirrus);
        assert_eq!(
            t(&MIDDLE, facts(6.5, 5000.0, 0.0, 0.0)),
            CloudType::Altostratus
        );
        assert_eq!(
            t(&MIDDLE, facts(2.0, 5000.0, 0.0, 0.0)),
            CloudType::Altocumulus
        );
        assert_eq!(
            t(&LOW, facts(7.0, 4000.0, 0.0, 2.0)),
            CloudType::Nimbostratus
        );
        assert_eq!(t(&LOW, facts(7.5, 1000.0, 0.0, 0.0)), CloudType::Stratus);
        assert_eq!(
            t(&LOW, facts(2.0, 3000.0, 400.0, 0.0)),
            CloudType::CumulusMediocris
        );
        assert_eq!(
            t(&LOW, facts(5.0, 3000.0, 0.0, 0.0)),
            CloudType::Stratocumulus
        );
    }

    #[test]
    fn the_dewpoint_of_saturated_air_is_its_temperature() {
        assert!((dewpoint_c(12.0, 100.0) - 12.0).abs() < 1e-9);
        // 50 % at 20 C: 9.3 C (Magnus).
        assert!(
            (dewpoint_c(20.0, 50.0) - 9.26).abs() < 0.05,
            "{}",
            dewpoint_c(20.0, 50.0)
        );
    }
}

//! The model's air column at a point: its isobaric levels with their geopotential heights, and
//! pressure to height through them.
//!
//! Between two levels the height is linear in ln(p): the hypsometric equation,
//! z2 - z1 = (R T / g) ln(p1 / p2), for the layer's mean temperature. Below the lowest level and
//! above the highest the same holds with that level's temperature. Geopotential metres are taken
//! as metres (they differ by under 0.3 % below 20 km).

use glam::DVec2;

use super::fields::{self, FieldKey};
use super::{GridPoint, ModelField};
use crate::weather::block::METRES_PER_KNOT;
use crate::weather::winds_aloft::{AloftColumn, AloftLevel};

/// Specific gas constant of dry air over standard gravity, metres per kelvin (287.05 / 9.80665).
const R_OVER_G_M_PER_K: f64 = 29.27;

/// One isobaric level of the model's column over a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelLevel {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Geopotential height, metres above mean sea level.
    pub height_m_msl: f64,
    /// Wind velocity, knots east and north.
    pub velocity_kt: DVec2,
    /// Temperature, degrees C.
    pub temperature_c: f64,
    /// Relative humidity, %, where the model gives it.
    pub humidity_pct: Option<f64>,
}

/// The levels of the model's column at a point, lowest (highest pressure) first; a level with a
/// value missing at the point is left out.
pub fn levels_at(model: &ModelField, point: &GridPoint) -> Vec<ModelLevel> {
    let at = |q: [u8; 3], p: i64| model.value_with(&FieldKey::isobaric(q, p), point);
    model
        .levels_pa()
        .iter()
        .filter_map(|&p| {
            Some(ModelLevel {
                pressure_pa: p as f64,
                height_m_msl: at(fields::HEIGHT, p)?,
                velocity_kt: DVec2::new(at(fields::WIND_U, p)?, at(fields::WIND_V, p)?)
                    / METRES_PER_KNOT,
                temperature_c: at(fields::TEMPERATURE, p)? - 273.15,
                humidity_pct: at(fields::HUMIDITY, p),
            })
        })
        .collect()
}

/// One isobaric level's height and temperature: what pressure to height needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightLevel {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Geopotential height, metres above mean sea level.
    pub height_m_msl: f64,
    /// Temperature, degrees C.
    pub temperature_c: f64,
}

impl From<&ModelLevel> for HeightLevel {
    fn from(l: &ModelLevel) -> Self {
        Self {
            pressure_pa: l.pressure_pa,
            height_m_msl: l.height_m_msl,
            temperature_c: l.temperature_c,
        }
    }
}

/// The heights and temperatures of the model's levels at a point, lowest first (the column
/// without its winds and humidity, for pressure to height).
pub fn heights_at(model: &ModelField, point: &GridPoint) -> Vec<HeightLevel> {
    let at = |q: [u8; 3], p: i64| model.value_with(&FieldKey::isobaric(q, p), point);
    model
        .levels_pa()
        .iter()
        .filter_map(|&p| {
            Some(HeightLevel {
                pressure_pa: p as f64,
                height_m_msl: at(fields::HEIGHT, p)?,
                temperature_c: at(fields::TEMPERATURE, p)? - 273.15,
            })
        })
        .collect()
}

/// The height, metres MSL, of pressure `pressure_pa` in the column (`None` for an empty column
/// or a pressure that is not positive).
pub fn height_of_pressure(levels: &[HeightLevel], pressure_pa: f64) -> Option<f64> {
    if pressure_pa.is_nan() || pressure_pa <= 0.0 || levels.is_empty() {
        return None;
    }
    let ln_p = pressure_pa.ln();
    // The two levels around the pressure, or the end level and its neighbour.
    let k = levels
        .windows(2)
        .position(|w| pressure_pa <= w[0].pressure_pa && pressure_pa >= w[1].pressure_pa);
    if let Some(k) = k {
        let (a, b) = (&levels[k], &levels[k + 1]);
        let f = (a.pressure_pa.ln() - ln_p) / (a.pressure_pa.ln() - b.pressure_pa.ln());
        return Some(a.height_m_msl + f * (b.height_m_msl - a.height_m_msl));
    }
    let end = if pressure_pa > levels[0].pressure_pa {
        levels[0]
    } else {
        levels[levels.len() - 1]
    };
    let kelvin = end.temperature_c + 273.15;
    Some(end.height_m_msl + R_OVER_G_M_PER_K * kelvin * (end.pressure_pa.ln() - ln_p))
}

/// The column as winds and temperatures aloft (what the air data follows above the boundary
/// layer).
pub fn aloft(levels: &[ModelLevel]) -> AloftColumn {
    AloftColumn {
        levels: levels
            .iter()
            .map(|l| AloftLevel {
                alt_m_msl: l.height_m_msl,
                velocity_kt: Some(l.velocity_kt),
                temperature_c: Some(l.temperature_c),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn level(p: f64, z: f64) -> HeightLevel {
        HeightLevel {
            pressure_pa: p,
            height_m_msl: z,
            temperature_c: -20.0,
        }
    }

    #[test]
    fn a_pressure_between_levels_is_linear_in_its_logarithm() {
        let levels = [level(100_000.0, 100.0), level(50_000.0, 5_500.0)];
        assert_eq!(height_of_pressure(&levels, 100_000.0), Some(100.0));
        let mid = (100_000.0f64 * 50_000.0).sqrt();
        let z = height_of_pressure(&levels, mid).unwrap();
        assert!((z - 2_800.0).abs() < 1e-6, "{z}");
        // Above the top: the hypsometric equation with the top's temperature.
        let z = height_of_pressure(&levels, 25_000.0).unwrap();
        let want = 5_500.0 + R_OVER_G_M_PER_K * 253.15 * 2f64.ln();
        assert!((z - want).abs() < 1e-6, "{z} {want}");
        assert_eq!(height_of_pressure(&levels, 0.0), None);
    }
}

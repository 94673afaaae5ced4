//! The fields the model reader takes from a GRIB2 file, named by WMO code (GFS layout).
//!
//! Another model's file maps onto these by giving the same fields the same codes: discipline,
//! parameter category and number (code tables 0.0 and 4.2, with NCEP's local entries 192 and up)
//! on the fixed surface of code table 4.5 with its value.
//!
//! | what | discipline, category, number | surface (value) | needed |
//! |---|---|---|---|
//! | geopotential height, gpm | 0, 3, 5 | 100 isobaric (Pa) | yes |
//! | temperature, K | 0, 0, 0 | 100 isobaric (Pa) | yes |
//! | u and v wind, m/s | 0, 2, 2 and 0, 2, 3 | 100 isobaric (Pa) | yes |
//! | relative humidity, % | 0, 1, 1 | 100 isobaric (Pa) | no |
//! | cloud cover, % | 0, 6, 1 | 214 low, 224 middle, 234 high, 244 convective layer | low, middle, high |
//! | layer bottom pressure, Pa | 0, 3, 0 | 212 low, 222 middle, 232 high, 242 convective | with its cover |
//! | layer top pressure, Pa | 0, 3, 0 | 213 low, 223 middle, 233 high, 243 convective | with its cover |
//! | orography, m | 0, 3, 5 | 1 ground | yes |
//! | CAPE, J/kg | 0, 7, 6 | 1 ground | no |
//! | precipitation rate, kg m-2 s-1 | 0, 1, 7 | 1 ground | no |
//! | categorical rain, freezing rain, ice pellets, snow (0/1) | 0, 1, 192/193/194/195 | 1 ground | no |
//! | 2 m temperature, K; 2 m relative humidity, % | 0, 0, 0; 0, 1, 1 | 103 above ground (2 m) | no |
//! | 10 m u and v wind, m/s | 0, 2, 2 and 0, 2, 3 | 103 above ground (10 m) | no |
//! | mean sea-level pressure, Pa | 0, 3, 1 | 101 mean sea level | no |
//! | visibility, m | 0, 19, 0 | 1 ground | no |

use std::fmt;

/// One field of a GRIB2 file: its parameter and the surface it lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FieldKey {
    /// Discipline (code table 0.0; 0 is meteorological products).
    pub discipline: u8,
    /// Parameter category (code table 4.1).
    pub category: u8,
    /// Parameter number (code table 4.2).
    pub number: u8,
    /// Type of the first fixed surface (code table 4.5).
    pub surface_type: u8,
    /// The surface's value, rounded to a whole number in its unit (Pa, m); 0 where none.
    pub surface_value: i64,
}

impl FieldKey {
    /// The key of a field; `surface_value` is rounded (a missing value, NaN, counts as 0).
    pub fn new(discipline: u8, category: u8, number: u8, surface_type: u8, value: f64) -> Self {
        let surface_value = if value.is_finite() && value.abs() < 1e12 {
            value.round() as i64
        } else {
            0
        };
        Self {
            discipline,
            category,
            number,
            surface_type,
            surface_value,
        }
    }

    /// A field on a surface without a value (ground, a cloud layer's bottom).
    const fn on(parameter: [u8; 3], surface_type: u8) -> Self {
        Self::at(parameter, surface_type, 0)
    }

    /// A field on a surface with a value.
    const fn at(parameter: [u8; 3], surface_type: u8, surface_value: i64) -> Self {
        Self {
            discipline: parameter[0],
            category: parameter[1],
            number: parameter[2],
            surface_type,
            surface_value,
        }
    }

    /// This parameter on isobaric surface `pressure_pa`.
    pub const fn isobaric(parameter: [u8; 3], pressure_pa: i64) -> Self {
        Self::at(parameter, ISOBARIC, pressure_pa)
    }
}

impl fmt::Display for FieldKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "parameter {}.{}.{} on surface type {}",
            self.discipline, self.category, self.number, self.surface_type
        )?;
        if self.surface_value != 0 {
            write!(f, " at {}", self.surface_value)?;
        }
        Ok(())
    }
}

/// Code table 4.5: an isobaric surface (value in Pa).
pub const ISOBARIC: u8 = 100;
/// Code table 4.5: the ground.
const GROUND: u8 = 1;
/// Code table 4.5: a height above the ground (value in m).
const ABOVE_GROUND: u8 = 103;

/// Geopotential height, gpm.
pub const HEIGHT: [u8; 3] = [0, 3, 5];
/// Temperature, K.
pub const TEMPERATURE: [u8; 3] = [0, 0, 0];
/// Relative humidity, %.
pub const HUMIDITY: [u8; 3] = [0, 1, 1];
/// Eastward wind, m/s.
pub const WIND_U: [u8; 3] = [0, 2, 2];
/// Northward wind, m/s.
pub const WIND_V: [u8; 3] = [0, 2, 3];
/// Cloud cover, %.
const CLOUD_COVER: [u8; 3] = [0, 6, 1];
/// Pressure, Pa.
const PRESSURE: [u8; 3] = [0, 3, 0];

/// The ground's height, m.
pub const OROGRAPHY: FieldKey = FieldKey::on(HEIGHT, GROUND);
/// Convective available potential energy at the ground, J/kg.
pub const CAPE: FieldKey = FieldKey::on([0, 7, 6], GROUND);
/// Precipitation rate, kg m-2 s-1 (mm/s).
pub const PRECIPITATION_RATE: FieldKey = FieldKey::on([0, 1, 7], GROUND);
/// Categorical rain (1 where it rains).
pub const RAIN: FieldKey = FieldKey::on([0, 1, 192], GROUND);
/// Categorical freezing rain.
pub const FREEZING_RAIN: FieldKey = FieldKey::on([0, 1, 193], GROUND);
/// Categorical ice pellets.
pub const ICE_PELLETS: FieldKey = FieldKey::on([0, 1, 194], GROUND);
/// Categorical snow.
pub const SNOW: FieldKey = FieldKey::on([0, 1, 195], GROUND);
/// Visibility at the ground, m.
pub const VISIBILITY: FieldKey = FieldKey::on([0, 19, 0], GROUND);
/// Temperature 2 m above the ground, K.
pub const TEMPERATURE_2M: FieldKey = FieldKey::at(TEMPERATURE, ABOVE_GROUND, 2);
/// Relative humidity 2 m above the ground, %.
pub const HUMIDITY_2M: FieldKey = FieldKey::at(HUMIDITY, ABOVE_GROUND, 2);
/// Eastward wind 10 m above the ground, m/s.
pub const WIND_U_10M: FieldKey = FieldKey::at(WIND_U, ABOVE_GROUND, 10);
/// Northward wind 10 m above the ground, m/s.
pub const WIND_V_10M: FieldKey = FieldKey::at(WIND_V, ABOVE_GROUND, 10);
/// Pressure reduced to mean sea level, Pa.
pub const SEA_LEVEL_PRESSURE: FieldKey = FieldKey::on([0, 3, 1], 101);

/// Which of the model's cloud layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelLayer {
    /// The low cloud layer.
    Low,
    /// The middle cloud layer.
    Middle,
    /// The high cloud layer.
    High,
    /// The convective cloud layer.
    Convective,
}

/// One of the model's cloud layers and the fields that give it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LayerFields {
    /// Which layer.
    pub layer: ModelLayer,
    /// The layer's name in messages ("low", "middle", "high", "convective").
    pub name: &'static str,
    /// Its cover, %.
    pub cover: FieldKey,
    /// The pressure at its bottom, Pa.
    pub bottom: FieldKey,
    /// The pressure at its top, Pa.
    pub top: FieldKey,
    /// Whether a model file must give it.
    pub needed: bool,
}

impl LayerFields {
    const fn of(layer: ModelLayer, name: &'static str, cover: u8, needed: bool) -> Self {
        Self {
            layer,
            name,
            cover: FieldKey::on(CLOUD_COVER, cover),
            bottom: FieldKey::on(PRESSURE, cover - 2),
            top: FieldKey::on(PRESSURE, cover - 1),
            needed,
        }
    }
}

/// The model's low cloud layer.
pub const LOW: LayerFields = LayerFields::of(ModelLayer::Low, "low", 214, true);
/// The model's middle cloud layer.
pub const MIDDLE: LayerFields = LayerFields::of(ModelLayer::Middle, "middle", 224, true);
/// The model's high cloud layer.
pub const HIGH: LayerFields = LayerFields::of(ModelLayer::High, "high", 234, true);
/// The model's convective cloud layer.
pub const CONVECTIVE: LayerFields =
    LayerFields::of(ModelLayer::Convective, "convective", 244, false);

/// The single fields the reader decodes (the isobaric ones are found by parameter).
pub const SINGLE: [FieldKey; 13] = [
    OROGRAPHY,
    CAPE,
    PRECIPITATION_RATE,
    RAIN,
    FREEZING_RAIN,
    ICE_PELLETS,
    SNOW,
    VISIBILITY,
    TEMPERATURE_2M,
    HUMIDITY_2M,
    WIND_U_10M,
    WIND_V_10M,
    SEA_LEVEL_PRESSURE,
];

/// Whether the reader decodes this field.
pub fn wanted(key: &FieldKey) -> bool {
    let isobaric = key.surface_type == ISOBARIC
        && [HEIGHT, TEMPERATURE, HUMIDITY, WIND_U, WIND_V].contains(&[
            key.discipline,
            key.category,
            key.number,
        ]);
    let layer = [LOW, MIDDLE, HIGH, CONVECTIVE]
        .iter()
        .any(|l| [l.cover, l.bottom, l.top].contains(key));
    isobaric || layer || SINGLE.contains(key)
}

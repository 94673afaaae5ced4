//! A numerical weather model's fields (GRIB2, GFS layout first) in; the same weather the reports'
//! field gives, at any point of the globe, out: cloud layers (cover, base, top, type), the wind
//! and temperature at every height, precipitation.
//!
//! - `decode` reads the GRIB2 file into grids (every field of every message: NCEP sends a level's
//!   u and v wind as two fields of one message); `fields` names the fields by WMO code, so
//!   another model's file can be mapped onto them.
//! - A value at a point is bilinear between the four grid points around it, over those that have
//!   one (a cloud layer's bottom pressure exists only where the layer does).
//! - `column` turns pressures into heights through the model's own geopotential heights at the
//!   point (linear in the logarithm of pressure between its isobaric levels, the hypsometric
//!   equation's form for a layer of constant temperature), and gives the winds and temperatures
//!   aloft as an [`AloftColumn`], which the air data follows above the boundary layer.
//! - `layers` turns the model's low, middle, high and convective cloud layers into
//!   [`BlockLayer`]s: cover in % to oktas, bottom and top pressure to feet above the model's
//!   ground, a type by level, cover, CAPE and rain (`config/weather_model.toml`).
//!
//! The weather field ([`super::WeatherField::with_model`]) blends the model with the reports:
//! near a station the report, fading with distance, the model beyond.

mod column;
mod decode;
pub mod fields;
mod layers;
mod settings;

pub use column::ModelLevel;
pub use decode::{Grids, LatLonGrid, is_grib};
pub use fields::FieldKey;
pub use settings::{
    BlendSettings, ModelLayerSettings, ModelSettings, ModelSurfaceSettings, ModelTimeSettings,
};

use std::path::{Path, PathBuf};

use super::block::BlockLayer;
use super::winds_aloft::AloftColumn;

/// What is wrong with a model file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The file cannot be read as GRIB2, or a message in it cannot be decoded.
    #[error("{path}: {reason}")]
    Grib {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the message and field.
        reason: String,
    },
    /// A field the model reader needs is not in the file.
    #[error("{path}: no {what} ({key}) in the model file")]
    MissingField {
        /// The file.
        path: PathBuf,
        /// The field, in words.
        what: String,
        /// The field's codes.
        key: FieldKey,
    },
}

/// The four grid points around a point and their bilinear weights: (index, weight).
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridPoint {
    corners: [(usize, f64); 4],
}

/// A weather model's fields, decoded: the weather at any latitude/longitude.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelField {
    /// The file it came from.
    pub path: PathBuf,
    grids: Grids,
    /// The isobaric levels that give height, temperature and wind, Pa, highest pressure first.
    levels_pa: Vec<i64>,
}

impl ModelField {
    /// Reads a GRIB2 model file.
    pub fn load(path: &Path) -> Result<Self, super::WeatherError> {
        let bytes = std::fs::read(path).map_err(|source| super::WeatherError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self::parse(path, &bytes)?)
    }

    /// Decodes GRIB2 bytes; `path` names the file in errors.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, ModelError> {
        let grids = decode::decode(path, bytes, fields::wanted)?;
        let missing = |what: String, key: FieldKey| ModelError::MissingField {
            path: path.to_path_buf(),
            what,
            key,
        };
        let needed = [
            fields::LOW,
            fields::MIDDLE,
            fields::HIGH,
            fields::CONVECTIVE,
        ];
        for layer in needed.iter().filter(|l| l.needed) {
            for (key, what) in [
                (layer.cover, "cover"),
                (layer.bottom, "bottom pressure"),
                (layer.top, "top pressure"),
            ] {
                if !grids.fields.contains_key(&key) {
                    return Err(missing(format!("{} cloud layer {what}", layer.name), key));
                }
            }
        }
        if !grids.fields.contains_key(&fields::OROGRAPHY) {
            return Err(missing("ground height".to_string(), fields::OROGRAPHY));
        }
        let profile = [
            fields::HEIGHT,
            fields::TEMPERATURE,
            fields::WIND_U,
            fields::WIND_V,
        ];
        let mut levels_pa: Vec<i64> = grids
            .fields
            .keys()
            .filter(|k| k.surface_type == fields::ISOBARIC)
            .map(|k| k.surface_value)
            .filter(|&p| {
                profile
                    .iter()
                    .all(|&q| grids.fields.contains_key(&FieldKey::isobaric(q, p)))
            })
            .collect();
        levels_pa.sort_unstable_by(|a, b| b.cmp(a));
        levels_pa.dedup();
        if levels_pa.len() < 2 {
            return Err(missing(
                "isobaric levels with height, temperature and u and v wind (two at least)"
                    .to_string(),
                FieldKey::isobaric(fields::HEIGHT, 50_000),
            ));
        }
        Ok(Self {
            path: path.to_path_buf(),
            grids,
            levels_pa,
        })
    }

    /// The decoded grids.
    pub fn grids(&self) -> &Grids {
        &self.grids
    }

    /// The isobaric levels of the air column, Pa, highest pressure (lowest level) first.
    pub fn levels_pa(&self) -> &[i64] {
        &self.levels_pa
    }

    /// The time the model is valid for, UTC: (year, month, day, hour), the run plus its
    /// forecast hours.
    pub fn valid_time(&self) -> (i32, u32, u32, u32) {
        let [year, month, day, hour] = self.grids.run;
        let days_from_civil = days_from_civil(year as i32, month, day);
        let total_h = days_from_civil * 24 + i64::from(hour) + i64::from(self.grids.forecast_hours);
        let (y, m, d) = civil_from_days(total_h.div_euclid(24));
        (y, m, d, total_h.rem_euclid(24) as u32)
    }

    /// Hours since 1970-01-01 00Z of the valid time (to compare with a simulated time).
    pub fn valid_hours_since_epoch(&self) -> i64 {
        let (y, m, d, h) = self.valid_time();
        days_from_civil(y, m, d) * 24 + i64::from(h)
    }

    /// Hours from `unix_s` (seconds since 1970-01-01 00Z) to the model's valid time (negative:
    /// valid before).
    pub fn hours_from(&self, unix_s: f64) -> f64 {
        self.valid_hours_since_epoch() as f64 - unix_s / 3600.0
    }

    /// A warning when the model is valid further than `settings.warn_after_h` from the
    /// simulated time `unix_s` (the model is used all the same): the file, its valid time and
    /// how far off it is.
    pub fn time_warning(&self, unix_s: f64, settings: &ModelTimeSettings) -> Option<String> {
        let hours = self.hours_from(unix_s);
        if hours.abs() <= settings.warn_after_h {
            return None;
        }
        let (y, m, d, h) = self.valid_time();
        let (amount, unit) = if hours.abs() >= 48.0 {
            (hours.abs() / 24.0, "days")
        } else {
            (hours.abs(), "hours")
        };
        let side = if hours < 0.0 { "before" } else { "after" };
        Some(format!(
            "{}: the model is valid {y:04}-{m:02}-{d:02} {h:02}Z, {amount:.0} {unit} {side} the \
             simulated time; used all the same",
            self.path.display()
        ))
    }

    /// Bytes the model's decoded fields take.
    pub fn memory_bytes(&self) -> usize {
        self.grids.memory_bytes()
    }

    /// A field's value at a point, bilinear between the grid points around it over those that
    /// have one; `None` where the file lacks the field or none of the four has a value.
    pub fn value_at(&self, key: &FieldKey, lat_deg: f64, lon_deg: f64) -> Option<f64> {
        self.value_with(key, &self.point(lat_deg, lon_deg))
    }

    /// The four grid points around a latitude/longitude and their bilinear weights (worked out
    /// once for every field asked there).
    pub(crate) fn point(&self, lat_deg: f64, lon_deg: f64) -> GridPoint {
        let g = &self.grids.grid;
        let (i, j) = g.position(lat_deg, lon_deg);
        let j = j.clamp(0.0, (g.nj - 1) as f64);
        let i = if g.wraps() {
            i
        } else {
            i.clamp(0.0, (g.ni - 1) as f64)
        };
        let (i0, j0) = (i.floor() as usize, j.floor() as usize);
        let (fi, fj) = (i - i0 as f64, j - j0 as f64);
        let i0 = i0.min(g.ni - 1);
        let i1 = if g.wraps() {
            (i0 + 1) % g.ni
        } else {
            (i0 + 1).min(g.ni - 1)
        };
        let j1 = (j0 + 1).min(g.nj - 1);
        GridPoint {
            corners: [
                (i0 + j0 * g.ni, (1.0 - fi) * (1.0 - fj)),
                (i1 + j0 * g.ni, fi * (1.0 - fj)),
                (i0 + j1 * g.ni, (1.0 - fi) * fj),
                (i1 + j1 * g.ni, fi * fj),
            ],
        }
    }

    /// A field's value at a [`GridPoint`] (as [`Self::value_at`]).
    pub(crate) fn value_with(&self, key: &FieldKey, point: &GridPoint) -> Option<f64> {
        let values = self.grids.fields.get(key)?;
        let (mut sum, mut total) = (0.0, 0.0);
        for &(index, w) in &point.corners {
            let v = values.get(index).map_or(f64::NAN, |&v| f64::from(v));
            if w > 0.0 && v.is_finite() {
                sum += w * v;
                total += w;
            }
        }
        (total > 1e-12).then(|| sum / total)
    }

    /// The model's air column at a point: its isobaric levels, lowest first.
    pub fn column_at(&self, lat_deg: f64, lon_deg: f64) -> Vec<ModelLevel> {
        column::levels_at(self, &self.point(lat_deg, lon_deg))
    }

    /// The winds and temperatures aloft at a point, for the air data.
    pub fn aloft_column_at(&self, lat_deg: f64, lon_deg: f64) -> AloftColumn {
        column::aloft(&self.column_at(lat_deg, lon_deg))
    }

    /// The model's ground height at a point, metres above mean sea level.
    pub fn ground_m_msl(&self, lat_deg: f64, lon_deg: f64) -> f64 {
        self.value_at(&fields::OROGRAPHY, lat_deg, lon_deg)
            .unwrap_or(0.0)
    }

    /// The model's pressure reduced to mean sea level at a point, hPa (the QNH it gives), if the
    /// file has it.
    pub fn qnh_hpa_at(&self, lat_deg: f64, lon_deg: f64) -> Option<f64> {
        self.value_at(&fields::SEA_LEVEL_PRESSURE, lat_deg, lon_deg)
            .map(|pa| pa / 100.0)
    }

    /// The model's cloud layers at a point, lowest base first (bases feet above the model's
    /// ground).
    pub fn layers_at(
        &self,
        lat_deg: f64,
        lon_deg: f64,
        settings: &ModelLayerSettings,
    ) -> Vec<BlockLayer> {
        layers::layers_at(self, lat_deg, lon_deg, settings)
    }

    /// The model's weather at a point, as the reports' field gives it.
    pub fn weather_at(
        &self,
        lat_deg: f64,
        lon_deg: f64,
        settings: &ModelSettings,
    ) -> super::BlockWeather {
        layers::weather_at(self, lat_deg, lon_deg, settings)
    }
}

/// Days from 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's `days_from_civil`).
fn days_from_civil(year: i32, month: u32, day: u32) -> i64 {
    let y = i64::from(year) - i64::from(month <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(month);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(day) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// The date of a day count from 1970-01-01 (Howard Hinnant's `civil_from_days`).
fn civil_from_days(days: i64) -> (i32, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y as i32, m, d)
}

#[cfg(test)]
mod tests;

//! GRIB2 in, the model's fields on its latitude/longitude grid out.
//!
//! A GRIB2 file is a run of messages; a message holds one or more fields ("submessages": NCEP
//! sends the u and v wind of a level as two fields of one message, so every field of every message
//! is read). A field is named by its discipline, parameter category and number (WMO code tables
//! 0.0 and 4.2) and by the fixed surface it lies on (code table 4.5 and its value, e.g. isobaric
//! surface 100 at 50,000 Pa). Only the fields [`super::fields`] names are decoded; the others are
//! passed over unread. The `grib` crate does the unpacking (simple, complex and complex with
//! spatial differencing, templates 5.0, 5.2 and 5.3); bit-mapped points (no value) decode as
//! NaN. Every field must lie on one regular latitude/longitude grid (template 3.0) that covers the
//! globe in longitude.

use std::path::Path;

use grib::LatLons;
use rustc_hash::FxHashMap;

use super::ModelError;
use super::fields::FieldKey;

/// The model's regular latitude/longitude grid: point (i, j) is at latitude `first_lat_deg +
/// j * step_lat_deg` and longitude `first_lon_deg + i * step_lon_deg`, stored at `i + j * ni`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatLonGrid {
    /// Points along a parallel.
    pub ni: usize,
    /// Points along a meridian.
    pub nj: usize,
    /// Latitude of the first point, degrees.
    pub first_lat_deg: f64,
    /// Longitude of the first point, degrees east.
    pub first_lon_deg: f64,
    /// Latitude step, degrees (negative when the grid runs north to south).
    pub step_lat_deg: f64,
    /// Longitude step, degrees.
    pub step_lon_deg: f64,
}

impl LatLonGrid {
    /// Whether the grid's longitudes close around the globe (the last column is one step short
    /// of the first).
    pub fn wraps(&self) -> bool {
        (self.ni as f64 * self.step_lon_deg.abs() - 360.0).abs() < 1e-6
    }

    /// The fractional grid position (i, j) of a latitude/longitude.
    pub fn position(&self, lat_deg: f64, lon_deg: f64) -> (f64, f64) {
        let i = (lon_deg - self.first_lon_deg) / self.step_lon_deg;
        let i = if self.wraps() {
            i.rem_euclid(self.ni as f64)
        } else {
            i
        };
        (i, (lat_deg - self.first_lat_deg) / self.step_lat_deg)
    }

    /// The latitude/longitude of grid point (i, j), degrees.
    pub fn lat_lon_deg(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.first_lat_deg + j as f64 * self.step_lat_deg,
            self.first_lon_deg + i as f64 * self.step_lon_deg,
        )
    }
}

/// The decoded fields of one GRIB2 file.
#[derive(Debug, Clone, PartialEq)]
pub struct Grids {
    /// The grid every field lies on.
    pub grid: LatLonGrid,
    /// Values by field, `grid.ni * grid.nj` each, in the field's own units; NaN where the field
    /// has no value (bit-mapped out).
    pub fields: FxHashMap<FieldKey, Vec<f32>>,
    /// The model's run (reference time): year, month, day, hour (UTC).
    pub run: [u32; 4],
    /// Hours from the run to the time the fields are valid for (the instantaneous fields';
    /// averages end there).
    pub forecast_hours: u32,
    /// Fields in the file, decoded or not.
    pub field_count: usize,
}

impl Grids {
    /// Bytes the decoded values take.
    pub fn memory_bytes(&self) -> usize {
        self.fields
            .values()
            .map(|v| v.capacity() * std::mem::size_of::<f32>())
            .sum()
    }
}

/// Whether bytes are a GRIB file (edition 1 or 2): they start with `GRIB`.
pub fn is_grib(bytes: &[u8]) -> bool {
    bytes.starts_with(b"GRIB")
}

/// Decodes the fields `wanted` says yes to from the GRIB2 bytes of `path` (named in errors).
pub fn decode(
    path: &Path,
    bytes: &[u8],
    wanted: impl Fn(&FieldKey) -> bool,
) -> Result<Grids, ModelError> {
    let bad = |reason: String| ModelError::Grib {
        path: path.to_path_buf(),
        reason,
    };
    // Section 0's octet 8 is the edition.
    if let Some(&edition) = bytes.get(7)
        && edition != 2
    {
        return Err(bad(format!(
            "GRIB edition {edition}; the model reader reads GRIB edition 2"
        )));
    }
    let file = grib::from_bytes(bytes).map_err(|e| {
        bad(format!(
            "not a whole GRIB2 file (cut short, or a message is broken): {e}"
        ))
    })?;
    let mut grid: Option<(LatLonGrid, Vec<u8>)> = None;
    let mut fields = FxHashMap::default();
    let (mut run, mut forecast_hours, mut field_count) = ([0; 4], 0, 0);
    for (index, sub) in file.iter() {
        field_count += 1;
        let at = format!("message {}, field {}", index.0 + 1, index.1 + 1);
        let prod = sub.prod_def();
        let (Some(category), Some(number), Some((surface, _))) = (
            prod.parameter_category(),
            prod.parameter_number(),
            prod.fixed_surfaces(),
        ) else {
            continue;
        };
        let key = FieldKey::new(
            sub.indicator().discipline,
            category,
            number,
            surface.surface_type,
            surface.value(),
        );
        if !wanted(&key) || fields.contains_key(&key) {
            continue;
        }
        let definition: Vec<u8> = sub.grid_def().iter().copied().collect();
        match &grid {
            Some((_, first)) if *first != definition => {
                return Err(bad(format!(
                    "{at} ({key}) lies on another grid than the fields before it"
                )));
            }
            Some(_) => {}
            None => {
                let g = lat_lon_grid(&sub).map_err(|e| bad(format!("{at}: {e}")))?;
                let t = sub.temporal_raw_info().ref_time_unchecked;
                run = [t.year.into(), t.month.into(), t.day.into(), t.hour.into()];
                grid = Some((g, definition));
            }
        }
        // An average over a period gives the period's start: the latest time is the valid one.
        let hours = forecast_hours_of(&sub.temporal_raw_info().forecast_time_diff);
        forecast_hours = forecast_hours.max(hours);
        let decoder = grib::Grib2SubmessageDecoder::from(sub)
            .map_err(|e| bad(format!("{at} ({key}): cannot decode: {e}")))?;
        let values: Vec<f32> = decoder
            .dispatch()
            .map_err(|e| bad(format!("{at} ({key}): cannot decode: {e}")))?
            .collect();
        let expected = grid.as_ref().map_or(0, |(g, _)| g.ni * g.nj);
        if values.len() != expected {
            return Err(bad(format!(
                "{at} ({key}): {} values for a grid of {expected} points",
                values.len()
            )));
        }
        fields.insert(key, values);
    }
    let Some((grid, _)) = grid else {
        return Err(bad(format!(
            "none of its {field_count} fields is one the model reader knows"
        )));
    };
    Ok(Grids {
        grid,
        fields,
        run,
        forecast_hours,
        field_count,
    })
}

/// The forecast hours of a field's temporal information (hours, minutes or days; 0 when the
/// field gives none).
fn forecast_hours_of(time: &Option<grib::ForecastTime>) -> u32 {
    let Some(t) = time else { return 0 };
    match t.unit {
        grib::Code::Name(grib::codetables::grib2::Table4_4::Minute) => t.value / 60,
        grib::Code::Name(grib::codetables::grib2::Table4_4::Day) => t.value * 24,
        _ => t.value,
    }
}

/// The regular latitude/longitude grid of a field, checked point by point against the
/// coordinates the grid definition gives.
fn lat_lon_grid<R: grib::Grib2Read>(sub: &grib::SubMessage<'_, R>) -> Result<LatLonGrid, String> {
    let template = sub.grid_def().grid_tmpl_num();
    if template != 0 {
        return Err(format!(
            "grid definition template 3.{template}; the model reader reads the regular \
             latitude/longitude grid (3.0) only"
        ));
    }
    let (ni, nj) = sub.grid_shape().map_err(|e| e.to_string())?;
    let points: Vec<(f64, f64)> = sub
        .latlons_unchecked()
        .map_err(|e| e.to_string())?
        .collect();
    if ni < 2 || nj < 2 || points.len() != ni * nj {
        return Err(format!("a {ni} x {nj} grid with {} points", points.len()));
    }
    let grid = LatLonGrid {
        ni,
        nj,
        first_lat_deg: points[0].0,
        first_lon_deg: points[0].1,
        step_lat_deg: points[ni].0 - points[0].0,
        step_lon_deg: points[1].1 - points[0].1,
    };
    let regular = points.iter().enumerate().all(|(k, &(lat, lon))| {
        let (want_lat, want_lon) = grid.lat_lon_deg(k % ni, k / ni);
        (lat - want_lat).abs() < 1e-3 && (lon - want_lon).abs() < 1e-3
    });
    if !regular || grid.step_lon_deg == 0.0 || grid.step_lat_deg == 0.0 {
        return Err("the grid's points are not in rows of one latitude, west to east".to_string());
    }
    Ok(grid)
}

//! A precipitation map around a point for a host's weather-radar display: a top-down grid of
//! precipitation rates (mm/h) out to a range, north up, from the weather field's precipitation
//! (the reports' intensity as a rate, `config/air.toml` `[precipitation]`, the same mapping as
//! the air data).

use glam::{DVec2, DVec3};
use serde::Serialize;

use super::world::World;

/// A top-down grid of precipitation rates around a point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PrecipitationMap {
    /// The middle of the grid, local metres east/north.
    pub centre_m: DVec2,
    /// Side of a cell, metres.
    pub cell_m: f64,
    /// Cells a side (odd: the centre cell holds the point).
    pub side: usize,
    /// Rates, mm/h, row by row from the northern row, each west to east.
    pub rate_mm_h: Vec<f32>,
}

impl PrecipitationMap {
    /// The rate of the cell holding local point `p`, if the map covers it.
    pub fn at(&self, p: DVec2) -> Option<f32> {
        let half = (self.side / 2) as f64;
        let col = ((p.x - self.centre_m.x) / self.cell_m + 0.5 + half).floor();
        let row = (half - (p.y - self.centre_m.y) / self.cell_m + 0.5).floor();
        let n = self.side as f64;
        if !(0.0..n).contains(&col) || !(0.0..n).contains(&row) {
            return None;
        }
        self.rate_mm_h
            .get(row as usize * self.side + col as usize)
            .copied()
    }
}

impl World {
    /// The precipitation map around `point_m` out to `range_m` (at least one cell), cells of
    /// `cell_m` (at least 100 m): for a radar display, not every frame (one field lookup a cell).
    pub fn precipitation_map(&self, point_m: DVec3, range_m: f64, cell_m: f64) -> PrecipitationMap {
        let cell_m = cell_m.max(100.0);
        let half = (range_m.max(cell_m) / cell_m).ceil() as usize;
        let side = 2 * half + 1;
        let centre = point_m.truncate();
        let s = &self.air_settings().precipitation;
        let p = &self.field().settings().precipitation;
        let mut rate_mm_h = Vec::with_capacity(side * side);
        for row in 0..side {
            for col in 0..side {
                let at = centre
                    + DVec2::new(
                        (col as f64 - half as f64) * cell_m,
                        (half as f64 - row as f64) * cell_m,
                    );
                let intensity = f64::from(self.field().weather_at(at).precipitation);
                rate_mm_h.push(if intensity > 0.0 {
                    super::air::rate_mm_h(
                        intensity,
                        [p.light, p.moderate, p.heavy],
                        [s.light_mm_h, s.moderate_mm_h, s.heavy_mm_h],
                    )
                } else {
                    0.0
                });
            }
        }
        PrecipitationMap {
            centre_m: centre,
            cell_m,
            side,
            rate_mm_h,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::flight::WorldSettings;
    use crate::weather::field::{CloudTypeRule, FieldSettings};
    use crate::weather::{LocalFrame, WeatherInput};

    #[test]
    fn the_map_shows_the_rain_where_the_reports_have_it_out_to_150_km() {
        // LEVX (Vigo) reports TSRA.
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("weather/awc-metars-2025-01-27T22Z.cache.csv");
        let input = WeatherInput::load(&path, None).unwrap();
        let frame = LocalFrame::new(42.239, -8.624);
        let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
        let w = World::new(field, &WorldSettings::default());
        let map = w.precipitation_map(DVec3::ZERO, 150_000.0, 5_000.0);
        assert_eq!(map.side, 61);
        assert_eq!(map.rate_mm_h.len(), 61 * 61);
        // At Vigo: the moderate rain's rate.
        let here = map.at(DVec2::ZERO).unwrap();
        assert!((here - 5.0).abs() < 0.5, "{here}");
        // The corners lie 150 km out; outside the map nothing.
        assert!(map.at(DVec2::new(150_000.0, 150_000.0)).is_some());
        assert!(map.at(DVec2::new(160_000.0, 0.0)).is_none());
        // Away from the storm it is much drier (the field blends the reports smoothly, so only
        // a station's own point is dry to the last drop).
        let least = map.rate_mm_h.iter().copied().fold(f32::MAX, f32::min);
        assert!(least < 0.2 * here, "{least} {here}");
    }
}

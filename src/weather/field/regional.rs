//! The regional surface wind: the reported surface winds within a radius of a point, averaged as
//! vectors with weights falling smoothly to nothing at the radius.
//!
//! A surface report's wind is local: a calm at a sheltered airfield at night, a sea breeze, a
//! valley's channelling. The wind above the boundary layer is the large-scale (gradient) flow,
//! which varies over hundreds of kilometres, not over the few between stations. The air's
//! profile (`weather::air::wind_at`) goes over from a point's own surface wind at the anemometer
//! to this regional wind's gradient wind at the top of the boundary layer, so a calm station
//! under a moving sky has its clouds move over it, as they do over a real one.

use std::collections::HashMap;

use glam::DVec2;

/// Side of the cells the stations are binned into, metres (a query visits the cells its radius
/// reaches).
const CELL_M: f64 = 50_000.0;

/// The stations that report a wind, binned by position.
#[derive(Debug, Clone, Default)]
pub(super) struct RegionalWinds {
    /// Per cell: (station position, wind velocity knots east/north).
    cells: HashMap<(i64, i64), Vec<(DVec2, DVec2)>>,
}

impl RegionalWinds {
    /// Bins the stations that report a wind: (position local metres, wind knots east/north).
    pub(super) fn new(stations: impl IntoIterator<Item = (DVec2, Option<[f64; 2]>)>) -> Self {
        let mut cells: HashMap<(i64, i64), Vec<(DVec2, DVec2)>> = HashMap::new();
        for (position, wind) in stations {
            if let Some([east, north]) = wind {
                cells
                    .entry(cell_of(position))
                    .or_default()
                    .push((position, DVec2::new(east, north)));
            }
        }
        Self { cells }
    }

    /// The surface winds within `radius_m` of `point_m`, averaged as vectors (knots east,
    /// north) with weights `(1 - (d / radius)^2)^2`; `None` where no station within the radius
    /// reports a wind.
    pub(super) fn at(&self, point_m: DVec2, radius_m: f64) -> Option<DVec2> {
        if radius_m.is_nan() || radius_m <= 0.0 || !point_m.is_finite() {
            return None;
        }
        let reach = (radius_m / CELL_M).ceil() as i64;
        let (cx, cy) = cell_of(point_m);
        let (mut sum, mut total) = (DVec2::ZERO, 0.0);
        for x in cx - reach..=cx + reach {
            for y in cy - reach..=cy + reach {
                for &(position, wind) in self.cells.get(&(x, y)).into_iter().flatten() {
                    let d2 = position.distance_squared(point_m) / (radius_m * radius_m);
                    if d2 < 1.0 {
                        let w = (1.0 - d2) * (1.0 - d2);
                        sum += wind * w;
                        total += w;
                    }
                }
            }
        }
        (total > 0.0).then(|| sum / total)
    }
}

fn cell_of(p: DVec2) -> (i64, i64) {
    ((p.x / CELL_M).floor() as i64, (p.y / CELL_M).floor() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_winds_within_the_radius_average_as_vectors() {
        let (east, west, calm) = (Some([10.0, 0.0]), Some([-10.0, 0.0]), Some([0.0, 0.0]));
        let winds = RegionalWinds::new([
            (DVec2::new(-40_000.0, 0.0), east),
            (DVec2::new(40_000.0, 0.0), west),
            (DVec2::new(0.0, 60_000.0), calm),
            (DVec2::new(0.0, -10_000.0), None),
            (DVec2::new(300_000.0, 0.0), east),
        ]);
        // Two opposite winds the same distance off and a calm: no wind.
        let middle = winds.at(DVec2::ZERO, 150_000.0).expect("stations near");
        assert!(middle.length() < 1e-9, "{middle:?}");
        // Nearer the east wind, more of it; a station that reports no wind counts for nothing.
        let near_east = winds
            .at(DVec2::new(-30_000.0, 0.0), 150_000.0)
            .expect("near");
        assert!(near_east.x > 1.0 && near_east.x < 10.0, "{near_east:?}");
        // Beyond the radius nothing counts; the lone far station alone there.
        assert_eq!(
            winds.at(DVec2::new(300_000.0, 0.0), 150_000.0),
            Some(DVec2::new(10.0, 0.0))
        );
        assert_eq!(winds.at(DVec2::new(1.0e7, 0.0), 150_000.0), None);
        assert_eq!(winds.at(DVec2::ZERO, 0.0), None);
    }
}

//! The regional surface wind: the reported surface winds within a radius of a point, averaged as
//! vectors with weights falling smoothly to nothing at the radius.
//!
//! A surface report's wind is local: a calm at a sheltered airfield at night, a sea breeze, a
//! valley's channelling. The wind above the boundary layer is the large-scale (gradient) flow,
//! which varies over hundreds of kilometres, not over the few between stations. The air's
//! profile (`weather::air::wind_at`) goes over from a point's own surface wind at the anemometer
//! to this regional wind's gradient wind at the top of the boundary layer, so a calm station
//! under a moving sky has its clouds move over it, as they do over a real one.

use glam::DVec2;

/// Side of the cells the stations are binned into, metres (a query visits the cells its radius
/// reaches).
const CELL_M: f64 = 50_000.0;

/// The stations that report a wind, binned by position: sorted by cell, column then row, so
/// that the cells of one column a query reaches lie side by side (one binary search a column,
/// where a hash map was looked up once a cell: 49 lookups a query, half its time).
#[derive(Debug, Clone, Default)]
pub(super) struct RegionalWinds {
    /// (station position, wind velocity knots east/north), cell after cell, each cell's in
    /// the order they were given.
    stations: Vec<(DVec2, DVec2)>,
    /// Each cell that holds a station, sorted, with its first station in `stations`; then one
    /// past the last cell, whose start is `stations.len()`.
    cells: Vec<((i64, i64), usize)>,
}

impl RegionalWinds {
    /// Bins the stations that report a wind: (position local metres, wind knots east/north).
    pub(super) fn new(stations: impl IntoIterator<Item = (DVec2, Option<[f64; 2]>)>) -> Self {
        let mut binned: Vec<((i64, i64), DVec2, DVec2)> = (stations.into_iter())
            .filter_map(|(position, wind)| {
                let [east, north] = wind?;
                Some((cell_of(position), position, DVec2::new(east, north)))
            })
            .collect();
        // Stable: a cell's stations keep their order, and so does the sum of a query.
        binned.sort_by_key(|b| b.0);
        let mut cells: Vec<((i64, i64), usize)> = Vec::new();
        for (k, b) in binned.iter().enumerate() {
            if cells.last().is_none_or(|c| c.0 != b.0) {
                cells.push((b.0, k));
            }
        }
        cells.push(((i64::MAX, i64::MAX), binned.len()));
        Self {
            stations: binned.into_iter().map(|(_, p, w)| (p, w)).collect(),
            cells,
        }
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
        let occupied = self.cells.len().checked_sub(1)?;
        for x in cx.saturating_sub(reach)..=cx.saturating_add(reach) {
            let (lo, hi) = ((x, cy.saturating_sub(reach)), (x, cy.saturating_add(reach)));
            let first = self.cells[..occupied].partition_point(|c| c.0 < lo);
            for k in first..occupied {
                if self.cells[k].0 > hi {
                    break;
                }
                let stations = &self.stations[self.cells[k].1..self.cells[k + 1].1];
                for &(position, wind) in stations {
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

    #[test]
    fn a_query_sums_the_stations_of_its_cells_column_by_column_as_given() {
        // Stations scattered over a few hundred kilometres, some without a wind, and the sum
        // as every cell the radius reaches is visited in turn (column, row, then the stations
        // as given): the same to the bit.
        let mut seed = 7u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let stations: Vec<(DVec2, Option<[f64; 2]>)> = (0..400)
            .map(|k| {
                let p = DVec2::new(next() * 600e3 - 300e3, next() * 600e3 - 300e3);
                let wind = (k % 7 != 0).then(|| [next() * 40.0 - 20.0, next() * 40.0 - 20.0]);
                (p, wind)
            })
            .collect();
        let winds = RegionalWinds::new(stations.clone());
        let radius = 150_000.0;
        for k in 0..50 {
            let point = DVec2::new(next() * 700e3 - 350e3, next() * 700e3 - 350e3);
            let (cx, cy) = cell_of(point);
            let (mut sum, mut total) = (DVec2::ZERO, 0.0);
            for x in cx - 3..=cx + 3 {
                for y in cy - 3..=cy + 3 {
                    for &(position, wind) in &stations {
                        let Some([e, n]) = wind.filter(|_| cell_of(position) == (x, y)) else {
                            continue;
                        };
                        let d2 = position.distance_squared(point) / (radius * radius);
                        if d2 < 1.0 {
                            let w = (1.0 - d2) * (1.0 - d2);
                            sum += DVec2::new(e, n) * w;
                            total += w;
                        }
                    }
                }
            }
            let expected = (total > 0.0).then(|| sum / total);
            assert_eq!(winds.at(point, radius), expected, "query {k} at {point:?}");
        }
        assert_eq!(RegionalWinds::default().at(DVec2::ZERO, radius), None);
    }
}

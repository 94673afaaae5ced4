//! The far field's cloud map: the weather field out to the horizon of cruise altitude, as plain
//! data the renderer draws far clouds from (`render/far_field`, docs/src/horizon.md).
//!
//! In: the weather at a point (the same field the blocks are made from: Sibson between the
//! stations, the nearest station outside their hull). Out: a square grid of `texels` x `texels`
//! cells of `texel_m`, centred on a point snapped to the grid (so a cell keeps its weather
//! wherever the camera is, and a map moved by whole cells shows the same clouds), each holding
//! two layers: the low and middle clouds (everything but the cirrus family) and the high ones
//! (cirrus, cirrocumulus, cirrostratus). A layer is its cover (0..1, the layers of its kind
//! overlapping at random, `1 - prod(1 - c)`), the base and top of its most covering member
//! (metres above sea level) and whether that member is heaped (cumuliform: the far field's
//! texture is then small and lumpy) or a sheet, and that member's type's look from above: the
//! grey and the alpha of its top colour level (`config/cloud_types.toml`), which its near
//! sprites are drawn with (an altostratus deck translucent, a nimbostratus one grey). Built a few
//! rows a frame ([`FarMapFeed`]) and
//! rebuilt after the camera moved `move_texels` cells or the weather changed (at once for offline
//! frames).

use glam::DVec2;

use super::CloudTypes;
use crate::weather::{BlockWeather, CloudType, METRES_PER_FOOT};

/// One cell of the map: `[cover, base_msl_m, top_msl_m, heaped]` of the low / middle layer,
/// then of the high layer, then `[grey, alpha]` of the low layer's top colour level and of the
/// high layer's (1, 1 where a layer has no cloud).
pub type FarCell = [f32; 12];

/// The far field's cloud map (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FarMap {
    /// Cells per side.
    pub texels: u32,
    /// Side of a cell, metres.
    pub texel_m: f64,
    /// The map's centre in the local frame, metres (a multiple of `texel_m`).
    pub centre_m: DVec2,
    /// `texels * texels` cells, row by row from the south-west corner eastwards, then north.
    pub cells: Vec<FarCell>,
    /// Which weather it was built from: [`FarMapFeed`] counts the weather changes, so a map
    /// of another weather crossfades from the one shown where a map only moved with the camera
    /// shows at once.
    pub weather_epoch: u64,
}

impl FarMap {
    /// The centre of cell `(col, row)`, local metres.
    pub fn cell_centre_m(&self, col: u32, row: u32) -> DVec2 {
        cell_centre(self.centre_m, self.texels, self.texel_m, col, row)
    }

    /// The cell holding a local point, if the map covers it.
    pub fn cell_at(&self, point_m: DVec2) -> Option<&FarCell> {
        let half = f64::from(self.texels) * self.texel_m * 0.5;
        let rel = point_m - self.centre_m + DVec2::splat(half);
        let (col, row) = (rel.x / self.texel_m, rel.y / self.texel_m);
        let n = f64::from(self.texels);
        if !(0.0..n).contains(&col) || !(0.0..n).contains(&row) {
            return None;
        }
        self.cells
            .get(row as usize * self.texels as usize + col as usize)
    }

    /// Bytes of the map on the GPU (three RGBA half-float layers a cell).
    pub fn gpu_bytes(&self) -> u64 {
        u64::from(self.texels) * u64::from(self.texels) * 24
    }

    /// This map's cells where `like` has its cells (a map of the same size whose centre is
    /// whole cells away, as every map's centre is snapped to the grid): each cell keeps its
    /// weather, and a cell this map does not cover takes `like`'s.
    pub fn moved_to(&self, like: &FarMap) -> FarMap {
        let n = i64::from(like.texels);
        let shift = ((like.centre_m - self.centre_m) / self.texel_m).round();
        let (dc, dr) = (shift.x as i64, shift.y as i64);
        let own = i64::from(self.texels);
        let cells = (0..n * n)
            .map(|k| {
                let (col, row) = (k % n + dc, k / n + dr);
                let mine = (0..own).contains(&col) && (0..own).contains(&row);
                mine.then(|| (row * own + col) as usize)
                    .and_then(|at| self.cells.get(at))
                    .or_else(|| like.cells.get(k as usize))
                    .copied()
                    .unwrap_or_default()
            })
            .collect();
        FarMap {
            cells,
            ..like.clone()
        }
    }

    /// The cells `t` (0..=1) of the way from this map's to `to`'s (same centre and size), every
    /// value linearly, as the far field's shader mixes them while it crossfades.
    pub fn blended_towards(&self, to: &FarMap, t: f32) -> FarMap {
        let cells = self
            .cells
            .iter()
            .zip(&to.cells)
            .map(|(a, b)| std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t))
            .collect();
        FarMap {
            cells,
            ..to.clone()
        }
    }
}

fn cell_centre(centre_m: DVec2, texels: u32, texel_m: f64, col: u32, row: u32) -> DVec2 {
    let half = f64::from(texels) * 0.5;
    centre_m
        + DVec2::new(
            (f64::from(col) + 0.5 - half) * texel_m,
            (f64::from(row) + 0.5 - half) * texel_m,
        )
}

/// Whether a type is drawn in the high layer.
fn is_high(t: CloudType) -> bool {
    matches!(
        t,
        CloudType::Cirrus | CloudType::Cirrocumulus | CloudType::Cirrostratus
    )
}

/// Whether a layer's far texture is heaped (separate clouds) rather than a sheet: the
/// cumuliform types, and stratocumulus short of overcast (the clouds stage draws it as separate
/// flat clouds then, config/cloud_types.toml; an overcast one as a deck on the lattice).
fn is_heaped(t: CloudType, oktas: f32) -> bool {
    matches!(
        t,
        CloudType::CumulusHumilis
            | CloudType::CumulusMediocris
            | CloudType::CumulusCongestus
            | CloudType::Cumulonimbus
            | CloudType::Altocumulus
            | CloudType::Cirrocumulus
    ) || (t == CloudType::Stratocumulus && oktas < 8.0)
}

/// The cell of a weather (module docs), with the looks of `types`.
pub fn far_cell(weather: &BlockWeather, types: &CloudTypes) -> FarCell {
    let mut cell = [0.0f32; 12];
    cell[8..].fill(1.0);
    let ground = if weather.ground_elevation_m.is_finite() {
        weather.ground_elevation_m
    } else {
        0.0
    };
    for high in [false, true] {
        let mut clear = 1.0f32;
        let mut best: Option<(f32, f32, f32, CloudType, f32)> = None;
        for l in weather
            .layers
            .iter()
            .filter(|l| is_high(l.cloud_type) == high)
        {
            let cover = (l.coverage_oktas / 8.0).clamp(0.0, 1.0);
            if cover <= 0.0 {
                continue;
            }
            clear *= 1.0 - cover;
            let base = ground + l.base_ft_agl * METRES_PER_FOOT as f32;
            let top = base + l.thickness_ft.max(0.0) * METRES_PER_FOOT as f32;
            if best.is_none_or(|b| cover > b.0) {
                best = Some((cover, base, top, l.cloud_type, l.coverage_oktas));
            }
        }
        if let Some((_, base, top, cloud_type, oktas)) = best {
            let at = if high { 4 } else { 0 };
            cell[at] = 1.0 - clear;
            cell[at + 1] = base;
            cell[at + 2] = top.max(base + 1.0);
            cell[at + 3] = f32::from(u8::from(is_heaped(cloud_type, oktas)));
            let top_level = types.get(cloud_type).colour_levels.last().map(|l| l.rgba);
            if let Some([r, g, b, a]) = top_level {
                let look = if high { 10 } else { 8 };
                cell[look] = 0.2126 * r + 0.7152 * g + 0.0722 * b;
                cell[look + 1] = a;
            }
        }
    }
    cell
}

/// A map being built, row by row.
#[derive(Debug, Clone)]
struct Building {
    map: FarMap,
    next_row: u32,
}

/// Keeps a far map around a moving camera: starts a new one when the camera has moved
/// `move_texels` cells from the shown map's centre or the weather changed, and builds it
/// `rows_per_frame` rows a frame (at once when asked: offline frames), so no frame stalls on it.
#[derive(Debug, Clone)]
pub struct FarMapFeed {
    texels: u32,
    texel_m: f64,
    move_texels: f64,
    rows_per_frame: u32,
    shown_centre: Option<DVec2>,
    building: Option<Building>,
    stale: bool,
    /// Weather changes so far: the epoch of the maps started since.
    weather_epoch: u64,
}

impl FarMapFeed {
    /// A feed of maps of `texels` x `texels` cells of `texel_m`.
    pub fn new(texels: u32, texel_m: f64, move_texels: f64, rows_per_frame: u32) -> Self {
        Self {
            texels: texels.max(2),
            texel_m: texel_m.max(1.0),
            move_texels: move_texels.max(0.0),
            rows_per_frame: rows_per_frame.max(1),
            shown_centre: None,
            building: None,
            stale: true,
            weather_epoch: 0,
        }
    }

    /// The weather changed: the next frames build a new map (of a new epoch). A map half built
    /// is started again: its rows before the change are of the old weather.
    pub fn weather_changed(&mut self) {
        self.stale = true;
        self.weather_epoch += 1;
        self.building = None;
    }

    /// One frame's share of the work around the camera at `camera_m` (local metres): a
    /// finished map when there is one to show. `whole`: build the first map at once (offline
    /// frames, the warm-up); otherwise, and for every later map, `rows_per_frame` rows a frame.
    /// `cell`: the cell at a point ([`far_cell`] of the weather there).
    pub fn update(
        &mut self,
        camera_m: DVec2,
        whole: bool,
        cell: impl Fn(DVec2) -> FarCell,
    ) -> Option<FarMap> {
        let snapped = (camera_m / self.texel_m).round() * self.texel_m;
        let moved = self
            .shown_centre
            .is_none_or(|c| (c - camera_m).abs().max_element() > self.move_texels * self.texel_m);
        if self.building.is_none() && (self.stale || moved) {
            self.stale = false;
            self.building = Some(Building {
                map: FarMap {
                    texels: self.texels,
                    texel_m: self.texel_m,
                    centre_m: snapped,
                    cells: Vec::with_capacity((self.texels * self.texels) as usize),
                    weather_epoch: self.weather_epoch,
                },
                next_row: 0,
            });
        }
        let rows = if whole && self.shown_centre.is_none() {
            self.texels
        } else {
            self.rows_per_frame
        };
        let b = self.building.as_mut()?;
        let end = (b.next_row + rows).min(b.map.texels);
        for row in b.next_row..end {
            for col in 0..b.map.texels {
                let at = b.map.cell_centre_m(col, row);
                b.map.cells.push(cell(at));
            }
        }
        b.next_row = end;
        if end < b.map.texels {
            return None;
        }
        let done = self.building.take()?;
        self.shown_centre = Some(done.map.centre_m);
        Some(done.map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::{BlockLayer, TypeSource};

    fn layer(cloud_type: CloudType, oktas: f32, base_ft: f32, thick_ft: f32) -> BlockLayer {
        BlockLayer {
            cloud_type,
            type_source: TypeSource::HeightRule,
            coverage_oktas: oktas,
            base_ft_agl: base_ft,
            thickness_ft: thick_ft,
        }
    }

    #[test]
    fn a_cell_keeps_the_low_and_the_high_layers_apart() {
        let w = BlockWeather {
            layers: vec![
                layer(CloudType::CumulusMediocris, 4.0, 3000.0, 3000.0),
                layer(CloudType::Stratocumulus, 2.0, 8000.0, 1000.0),
                layer(CloudType::Cirrus, 6.0, 25000.0, 1500.0),
            ],
            ground_elevation_m: 200.0,
            ..BlockWeather::default()
        };
        let types = CloudTypes::builtin();
        let c = far_cell(&w, &types);
        // Half and a quarter, overlapping at random: 1 - 0.5 x 0.75.
        assert!((c[0] - 0.625).abs() < 1e-6, "{c:?}");
        // The most covering low layer's base and top, above sea level; heaped.
        assert!((c[1] - (200.0 + 914.4)).abs() < 0.1, "{c:?}");
        assert!((c[2] - (200.0 + 1828.8)).abs() < 0.1, "{c:?}");
        assert_eq!(c[3], 1.0);
        assert!((c[4] - 0.75).abs() < 1e-6 && c[7] == 0.0, "{c:?}");
        // The looks of cumulus mediocris' and cirrus' top levels.
        assert!((c[8] - 1.0).abs() < 1e-6 && c[9] == 1.0, "{c:?}");
        assert!(
            (c[10] - 1.0).abs() < 1e-6 && (c[11] - 0.55).abs() < 1e-6,
            "{c:?}"
        );
        let clear = far_cell(&BlockWeather::default(), &types);
        assert_eq!(clear[0], 0.0);
        assert_eq!(clear[8..], [1.0; 4]);
        // A deck's look is its type's top level's (an altostratus deck is translucent).
        let deck = |t| BlockWeather {
            layers: vec![layer(t, 8.0, 8000.0, 1000.0)],
            ..BlockWeather::default()
        };
        assert!((far_cell(&deck(CloudType::Altostratus), &types)[9] - 0.8).abs() < 1e-6);
        let grey = |t| far_cell(&deck(t), &types)[8];
        assert!(grey(CloudType::Altostratus) < grey(CloudType::Stratocumulus));
        // Broken stratocumulus is separate clouds, an overcast one a sheet.
        let sc = |oktas| BlockWeather {
            layers: vec![layer(CloudType::Stratocumulus, oktas, 4000.0, 1000.0)],
            ..BlockWeather::default()
        };
        assert_eq!(far_cell(&sc(6.0), &types)[3], 1.0);
        assert_eq!(far_cell(&sc(8.0), &types)[3], 0.0);
    }

    #[test]
    fn the_feed_builds_a_whole_map_at_once_or_a_few_rows_a_frame() {
        // Cloud only north of y = 70 km.
        let types = CloudTypes::builtin();
        let weather = |p: DVec2| {
            let w = BlockWeather {
                layers: if p.y > 70_000.0 {
                    vec![layer(CloudType::Stratus, 8.0, 1000.0, 1000.0)]
                } else {
                    Vec::new()
                },
                ..BlockWeather::default()
            };
            far_cell(&w, &types)
        };
        let mut feed = FarMapFeed::new(16, 10_000.0, 2.0, 4);
        let map = feed
            .update(DVec2::new(3_000.0, -4_000.0), true, weather)
            .unwrap();
        assert_eq!(map.centre_m, DVec2::ZERO);
        assert_eq!(map.cells.len(), 256);
        assert_eq!(map.cell_at(DVec2::new(0.0, 75_000.0)).unwrap()[0], 1.0);
        assert_eq!(map.cell_at(DVec2::new(0.0, 65_000.0)).unwrap()[0], 0.0);
        assert!(map.cell_at(DVec2::new(0.0, 81_000.0)).is_none());
        assert_eq!(map.gpu_bytes(), 16 * 16 * 24);
        // Within two cells nothing is built; past them, four frames of four rows.
        assert!(
            feed.update(DVec2::new(15_000.0, 0.0), false, weather)
                .is_none()
        );
        let mut frames = 0;
        let next = loop {
            frames += 1;
            if let Some(m) = feed.update(DVec2::new(25_000.0, 0.0), false, weather) {
                break m;
            }
        };
        assert_eq!(frames, 4);
        assert_eq!(next.centre_m, DVec2::new(30_000.0, 0.0));
        // A cell keeps its weather when the map moves.
        let p = DVec2::new(45_000.0, 75_000.0);
        assert_eq!(map.cell_at(p), next.cell_at(p));
        // A weather change rebuilds where the camera is.
        feed.weather_changed();
        assert!(
            feed.update(DVec2::new(25_000.0, 0.0), false, weather)
                .is_none()
        );
    }

    /// A map moved by whole cells keeps each cell's weather where it is on the ground, and
    /// takes the other map's cells where it has none; a blend goes linearly between two.
    #[test]
    fn a_map_moves_by_whole_cells_and_blends_linearly() {
        let cell = |v: f32| {
            [
                v,
                1000.0 + v,
                2000.0 + v,
                1.0,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0,
                1.0,
                1.0,
                1.0,
            ]
        };
        let map = |centre_cells: f64, value: &dyn Fn(u32, u32) -> f32| {
            let cells = (0..16).map(|k| cell(value(k % 4, k / 4))).collect();
            FarMap {
                texels: 4,
                texel_m: 100.0,
                centre_m: DVec2::new(centre_cells * 100.0, 0.0),
                cells,
                weather_epoch: 0,
            }
        };
        // Each cell's value is its column on the ground (the map at the origin: column - 2).
        let old = map(0.0, &|col, _| col as f32);
        let fill = map(1.0, &|_, _| 9.0);
        let moved = old.moved_to(&fill);
        assert_eq!(moved.centre_m, fill.centre_m);
        for row in 0..4 {
            // The moved map's column c is the old map's column c + 1; its last, none.
            let values: Vec<f32> = (0..4).map(|col| moved.cells[row * 4 + col][0]).collect();
            assert_eq!(values, [1.0, 2.0, 3.0, 9.0], "row {row}");
        }
        let half = old.blended_towards(&map(0.0, &|_, _| 4.0), 0.25);
        assert_eq!(half.cells[1], cell(1.75));
    }

    /// A weather change starts a map of a new epoch, and a map half built when it came is
    /// built again (its first rows were of the weather before).
    #[test]
    fn a_weather_change_starts_a_map_of_a_new_epoch() {
        let mut feed = FarMapFeed::new(4, 100.0, 1.0, 2);
        let types = CloudTypes::builtin();
        let clear = |_: DVec2| far_cell(&BlockWeather::default(), &types);
        let first = feed
            .update(DVec2::ZERO, true, clear)
            .expect("built at once");
        assert_eq!(first.weather_epoch, 0);
        feed.weather_changed();
        assert!(feed.update(DVec2::ZERO, false, clear).is_none());
        feed.weather_changed();
        // Two rows a frame: the map begun before the second change is started again.
        assert!(feed.update(DVec2::ZERO, false, clear).is_none());
        let next = feed
            .update(DVec2::ZERO, false, clear)
            .expect("two frames of rows");
        assert_eq!(next.weather_epoch, 2);
    }
}

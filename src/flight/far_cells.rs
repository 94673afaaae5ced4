//! Storm cells beyond the cloud field: the cells of the weather field between the field's rim
//! (`config/clouds.toml` `radius_m`) and `[far] reach_m` of `config/storms.toml`, each drawn
//! whole as one cloud of few large sprites ([`crate::clouds::storm::far_cell_cloud`]) that the
//! sky draws however far it is ([`crate::render::Sky::insert_distant_block`]), handed over as
//! [`DistantChange`]s of the frame's [`crate::render::SkyUpdate`]. The ring and the far field stop
//! a storm at the field's rim: the far field would draw its area as a grey layer from base to
//! top (it leaves cumulonimbus out for this), and pilots see storms 50-160 km off.
//!
//! The cells are placed as the near ones are ([`cell_of_square`], the same grid, seed and block
//! weather, in the moving air's frame), looked for a few grid rows a frame around where the
//! camera was, again after it moved `move_m` or the weather changed. Each frame the nearest
//! `most` found beyond the rim are shown: one that joins forms, one that leaves (the camera came
//! near: its blocks draw it now) dissipates, over `fade_s`.

use std::collections::HashMap;

use rustc_hash::FxHashMap;

use glam::{DVec2, DVec3};

use crate::clouds::CloudTypes;
use crate::clouds::storm::far_cell_cloud;
use crate::render::scene::{BlockMotion, Fade, SkyBlock, SkyCloud};
use crate::render::update::DistantChange;
use crate::weather::field::WeatherField;
use crate::weather::storms::{FarCellSettings, StormCell, StormContext, cell_of_square};
use crate::weather::{BlockIndex, BlockWeather, CloudType};

/// Sky ids of far cells: apart from the field's generation serials, which count up from 0.
const FAR_CELL_IDS: u64 = 1 << 62;

/// What a frame's far cells are decided from.
#[derive(Clone, Copy)]
pub(super) struct FarCellFrame<'a> {
    /// The weather field (its block weather places the cells, as the near blocks').
    pub weather: &'a WeatherField,
    /// The weather's version: a new one looks for the cells again.
    pub version: u64,
    /// The storm settings, wind profile and latitude, and the field's seed.
    pub storms: (&'a StormContext, u64),
    /// The cloud types (the cumulonimbus' drawing).
    pub types: &'a CloudTypes,
    /// The camera in the moving air's frame (ground position less the drift), metres.
    pub camera_air_m: DVec2,
    /// The drift: added to every cell's position, as to the field's blocks.
    pub drift_m: DVec2,
    /// The cloud field's radius: cells whose centre is nearer are the field's ...
    pub field_radius_m: f64,
    /// ... unless the far field is drawn: from where its hand-over band starts, the near
    /// sprites fade out and the far cells' sprites fade in (every cell that reaches past it is
    /// a far cell too).
    pub band_start_m: Option<f64>,
    /// The clouds' clock, seconds.
    pub now_s: f64,
    /// Offline frames (synchronous clouds): the first set is found and shown in this call,
    /// steady at once; later ones come a few rows and cells a frame, fading, as in a live
    /// flight (a whole search is 80 x 80 grid squares of block weather).
    pub whole: bool,
}

/// A search of the placement grid around a point, a few rows a frame.
struct Search {
    centre_m: DVec2,
    version: u64,
    rows: std::ops::Range<i64>,
    cols: std::ops::Range<i64>,
    next_row: i64,
    cells: Vec<StormCell>,
}

/// A far cell the sky holds.
struct Shown {
    id: u64,
    cell: StormCell,
    /// When it started forming (`Some(false)`) or dissipating (`Some(true)`); `None`: steady.
    fade: Option<(bool, f64)>,
}

/// The far cells of a living world (module docs).
pub(super) struct FarCells {
    settings: FarCellSettings,
    search: Option<Search>,
    /// The last finished search: where, with which weather, and what it found.
    found: Option<(DVec2, u64, Vec<StormCell>)>,
    shown: HashMap<u64, Shown>,
    next_id: u64,
    /// Searches finished so far, and the search, camera place and hand-over the shown set was
    /// last decided for: it is decided again only when one changed.
    searches: u64,
    decided: Option<(u64, DVec2, Option<f64>)>,
    /// Shown cells forming or dissipating.
    fading: usize,
    /// The block weather searches looked up, with the count of the last search that met it
    /// (a finished search drops what it did not meet): a search 8 km on meets the same
    /// squares, and a look-up in the weather field was most of a search frame's 0.9 ms (the
    /// cruise). Hashed with Fx: moving each entry from the last search's map to this one's
    /// with std's SipHash was over half of a search frame's time (the Cb circle).
    weather: FxHashMap<BlockIndex, (u64, BlockWeather)>,
    /// How many block weathers the search under way looked up in the weather field.
    looked_up: usize,
}

/// The camera moves this far, metres, before the shown set is decided again (cells join and
/// leave at the field's rim, where a kilometre is a fraction of a degree).
const DECIDE_MOVE_M: f64 = 1000.0;

impl FarCells {
    /// No cells yet; `settings` from `config/storms.toml` `[far]`.
    pub(super) fn new(settings: FarCellSettings) -> Self {
        Self {
            settings,
            search: None,
            found: None,
            shown: HashMap::new(),
            next_id: FAR_CELL_IDS,
            searches: 0,
            decided: None,
            fading: 0,
            weather: FxHashMap::default(),
            looked_up: 0,
        }
    }

    /// Whether far cells are drawn.
    pub(super) fn enabled(&self) -> bool {
        self.settings.enabled
    }

    /// One frame: looks further for cells, and adds to `changes` the ones that join or leave
    /// and the fades that moved on, in order, for the sky.
    pub(super) fn update(&mut self, changes: &mut Vec<DistantChange>, f: &FarCellFrame) {
        if !self.settings.enabled {
            for (_, s) in self.shown.drain() {
                changes.push(DistantChange::Went(s.id));
            }
            return;
        }
        self.search_on(f);
        let decide = self.decided.is_none_or(|(searches, at, band)| {
            searches != self.searches
                || at.distance(f.camera_air_m) > DECIDE_MOVE_M
                || band != f.band_start_m
        });
        if decide {
            self.decided = Some((self.searches, f.camera_air_m, f.band_start_m));
            self.decide(changes, f);
        }
        if self.fading > 0 {
            self.fade_on(changes, f);
        }
    }

    /// Hands over the cells that join the shown set (forming) and marks those that leave it.
    fn decide(&mut self, changes: &mut Vec<DistantChange>, f: &FarCellFrame) {
        let wanted = self.wanted(f);
        let by_key: HashMap<u64, &StormCell> = wanted.iter().map(|c| (c.key, c)).collect();
        let offset_m = DVec3::new(f.drift_m.x, f.drift_m.y, 0.0);
        // Leaving: dissipate. Wanted again while dissipating: form back from as far as it
        // had gone. (A cell whose weather changed is replaced by its new self below.)
        let fade_s = self.settings.fade_s;
        for s in self.shown.values_mut() {
            let keep = by_key.get(&s.cell.key).is_some_and(|c| **c == s.cell);
            match s.fade {
                Some((true, since)) if keep => {
                    let gone = ((f.now_s - since) / fade_s.max(1e-9)).clamp(0.0, 1.0);
                    s.fade = Some((false, f.now_s - (1.0 - gone) * fade_s));
                }
                _ if keep => {}
                Some((true, _)) => {}
                _ => s.fade = Some((true, f.now_s)),
            }
        }
        // Joining: drawn now, forming; a few a frame (the first set of offline frames all at
        // once, steady), the rest decided again the next frames.
        let at_once = f.whole && self.shown.is_empty();
        let mut joins = if at_once {
            u32::MAX
        } else {
            self.settings.joins_per_frame
        };
        for cell in &wanted {
            let key = &cell.key;
            if self.shown.get(key).is_some_and(|s| s.cell == *cell) {
                continue;
            }
            if joins == 0 {
                self.decided = None;
                break;
            }
            joins -= 1;
            if let Some(old) = self.shown.remove(key) {
                changes.push(DistantChange::Went(old.id));
            }
            let id = self.next_id;
            self.next_id += 1;
            changes.push(DistantChange::Came(
                far_block(id, cell, f, &self.settings),
                BlockMotion {
                    offset_m,
                    fade: if at_once {
                        Fade::Steady
                    } else {
                        Fade::Forming(0.0)
                    },
                    drift_band: 0,
                },
            ));
            self.shown.insert(
                *key,
                Shown {
                    id,
                    cell: *cell,
                    fade: (!at_once).then_some((false, f.now_s)),
                },
            );
        }
        self.fading = self.shown.values().filter(|s| s.fade.is_some()).count();
    }

    /// The fades go on; those done are steady, or gone.
    fn fade_on(&mut self, changes: &mut Vec<DistantChange>, f: &FarCellFrame) {
        let fade_s = self.settings.fade_s;
        self.shown.retain(|_, s| {
            let Some((leaving, since)) = s.fade else {
                return true;
            };
            let p = if fade_s > 0.0 {
                ((f.now_s - since) / fade_s) as f32
            } else {
                1.0
            };
            match (leaving, p >= 1.0) {
                (true, true) => {
                    changes.push(DistantChange::Went(s.id));
                    return false;
                }
                (false, true) => {
                    s.fade = None;
                    changes.push(DistantChange::Fade(s.id, Fade::Steady));
                }
                (true, false) => {
                    changes.push(DistantChange::Fade(s.id, Fade::Dissipating(p)));
                }
                (false, false) => {
                    changes.push(DistantChange::Fade(s.id, Fade::Forming(p)));
                }
            }
            true
        });
        self.fading = self.shown.values().filter(|s| s.fade.is_some()).count();
    }

    /// The blocks of the far cells around `f`'s camera, found at once (a still world: the bench,
    /// tests), ids from [`FAR_CELL_IDS`] up, nearest first.
    pub(super) fn blocks_now(settings: FarCellSettings, f: &FarCellFrame) -> Vec<SkyBlock> {
        let mut far = Self::new(settings);
        far.search_on(&FarCellFrame { whole: true, ..*f });
        far.wanted(f)
            .iter()
            .enumerate()
            .map(|(i, cell)| far_block(FAR_CELL_IDS + i as u64, cell, f, &settings))
            .collect()
    }

    /// Starts a search where the camera left the last one or the weather changed, and looks
    /// through this frame's rows (all of them for an offline flight's first search).
    fn search_on(&mut self, f: &FarCellFrame) {
        let s = &self.settings;
        let grid = f.storms.0.settings.cells.grid_m;
        let stale = self.found.as_ref().is_none_or(|(at, version, _)| {
            *version != f.version || at.distance(f.camera_air_m) > s.move_m
        });
        let searching_stale = self
            .search
            .as_ref()
            .is_some_and(|search| search.version != f.version);
        if (self.search.is_none() && stale) || searching_stale {
            let reach = s.reach_m + f.storms.0.settings.reach_m();
            let lo = ((f.camera_air_m - DVec2::splat(reach)) / grid).floor();
            let hi = ((f.camera_air_m + DVec2::splat(reach)) / grid).ceil();
            // The last search's block weather is good for this one while the weather is the
            // same.
            if self.found.as_ref().is_none_or(|found| found.1 != f.version) {
                self.weather.clear();
            }
            self.looked_up = 0;
            self.search = Some(Search {
                centre_m: f.camera_air_m,
                version: f.version,
                rows: lo.y as i64..hi.y as i64,
                cols: lo.x as i64..hi.x as i64,
                next_row: lo.y as i64,
                cells: Vec::new(),
            });
        }
        // An offline flight's first search goes through at once.
        let Some(search) = self.search.as_mut() else {
            return;
        };
        let rows = if f.whole && self.found.is_none() {
            search.rows.end - search.next_row
        } else {
            i64::from(s.rows_per_frame)
        };
        let end = (search.next_row + rows).min(search.rows.end);
        let drift = f.drift_m;
        let (known, looked_up) = (&mut self.weather, &mut self.looked_up);
        let stamp = self.searches + 1;
        let mut weather = |p: DVec2| {
            let block = BlockIndex::containing(p + drift);
            let entry = known.entry(block).or_insert_with(|| {
                *looked_up += 1;
                (stamp, f.weather.block_layers_weather(block))
            });
            entry.0 = stamp;
            entry.1.clone()
        };
        let reach = s.reach_m + f.storms.0.settings.reach_m();
        for cj in search.next_row..end {
            for ci in search.cols.clone() {
                let square = DVec2::new(ci as f64 + 0.5, cj as f64 + 0.5) * grid;
                if square.distance(search.centre_m) > reach {
                    continue;
                }
                if let Some(cell) = cell_of_square(ci, cj, &mut weather, f.storms.0, f.storms.1) {
                    search.cells.push(cell);
                }
            }
        }
        search.next_row = end;
        if end >= search.rows.end
            && let Some(done) = self.search.take()
        {
            self.found = Some((done.centre_m, done.version, done.cells));
            self.searches += 1;
            let met = self.searches;
            self.weather.retain(|_, (stamp, _)| *stamp == met);
        }
    }

    /// The nearest `most` cells found that the field's blocks do not draw whole (beyond its
    /// radius, or reaching past the hand-over band's start), their centre within the reach,
    /// nearest first.
    fn wanted(&self, f: &FarCellFrame) -> Vec<StormCell> {
        let Some((_, _, cells)) = &self.found else {
            return Vec::new();
        };
        let mut by_distance: Vec<(f64, &StormCell)> = cells
            .iter()
            .map(|c| (c.centre().distance(f.camera_air_m), c))
            .filter(|(d, c)| {
                let far = match f.band_start_m {
                    Some(start) => d + c.radius_m() > start,
                    None => *d > f.field_radius_m,
                };
                far && *d <= self.settings.reach_m
            })
            .collect();
        by_distance.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.key.cmp(&b.1.key)));
        by_distance
            .into_iter()
            .take(self.settings.most)
            .map(|(_, c)| *c)
            .collect()
    }
}

/// A far cell as the sky's block: one cloud, the whole cell, where the field places it (the
/// drift is its motion).
fn far_block(id: u64, cell: &StormCell, f: &FarCellFrame, s: &FarCellSettings) -> SkyBlock {
    let weather = f
        .weather
        .block_layers_weather(BlockIndex::containing(cell.centre() + f.drift_m));
    let cloud = far_cell_cloud(
        cell,
        f.types.get(CloudType::Cumulonimbus),
        &weather,
        (s.sprites, s.sprite_over_base),
    );
    let sky_cloud = SkyCloud::from(&cloud);
    SkyBlock {
        id,
        centre_m: sky_cloud.centre_m,
        clouds: vec![sky_cloud],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::storms::{StormSettings, cells_over};

    const SEED: u64 = 2003;

    /// The 2025 file around a point 125 km east-north-east of Belo Horizonte (SBBH, TSRA
    /// BKN045CB; SBCF FEW045CB), which reports CAVOK itself.
    fn field() -> WeatherField {
        crate::weather::storms::tests::real_field(-19.55, -42.80)
    }

    fn frame<'a>(
        weather: &'a WeatherField,
        ctx: &'a StormContext,
        types: &'a CloudTypes,
        whole: bool,
    ) -> FarCellFrame<'a> {
        FarCellFrame {
            weather,
            version: 1,
            storms: (ctx, SEED),
            types,
            camera_air_m: DVec2::ZERO,
            drift_m: DVec2::ZERO,
            field_radius_m: 100_000.0,
            band_start_m: None,
            now_s: 0.0,
            whole,
        }
    }

    #[test]
    fn far_cells_are_the_fields_own_cells_beyond_its_rim() {
        let weather = field();
        let ctx = StormContext {
            lat_deg: -19.55,
            ..StormContext::default()
        };
        let types = CloudTypes::builtin();
        let settings = StormSettings::default().far;
        let mut far = FarCells::new(settings);
        let f = frame(&weather, &ctx, &types, true);
        far.search_on(&f);
        let wanted = far.wanted(&f);
        let near_sbbh = wanted
            .iter()
            .filter(|c| c.centre().distance(DVec2::new(-120_000.0, -34_000.0)) < 60_000.0)
            .count();
        eprintln!(
            "{} far cells, {near_sbbh} within 60 km of SBBH",
            wanted.len()
        );
        assert!(near_sbbh >= 5, "{near_sbbh} cells by SBBH");
        assert!(wanted.len() <= settings.most);
        for c in &wanted {
            let d = c.centre().length();
            assert!(d > 100_000.0 && d <= settings.reach_m, "a cell {d} m off");
            // The very cell the field's blocks draw once the camera is near.
            let square = DVec2::splat(1.0);
            let near = cells_over(
                c.centre() - square,
                c.centre() + square,
                // The near field's blocks carry their rim cover: the same cells.
                &mut |p| weather.block_weather(BlockIndex::containing(p)),
                &ctx,
                SEED,
            );
            assert!(near.contains(c), "{c:?}");
        }
        // A few rows a frame find the same.
        let mut slow = FarCells::new(settings);
        let f = frame(&weather, &ctx, &types, false);
        let mut frames = 0;
        while slow.found.is_none() {
            slow.search_on(&f);
            frames += 1;
            assert!(frames < 1000);
        }
        let rows = (2.0 * (settings.reach_m + ctx.settings.reach_m()) / ctx.settings.cells.grid_m)
            .ceil() as u32;
        assert!(
            frames + 2 >= rows / settings.rows_per_frame,
            "{frames} frames"
        );
        assert_eq!(slow.wanted(&f), wanted);
        // A search 9 km on, a few rows a frame, finds what a fresh one finds there, with the
        // last search's block weather taken over where it meets the same blocks.
        let moved = FarCellFrame {
            camera_air_m: DVec2::new(9_000.0, 0.0),
            ..frame(&weather, &ctx, &types, false)
        };
        let searches = slow.searches;
        while slow.searches == searches {
            slow.search_on(&moved);
        }
        let mut fresh = FarCells::new(settings);
        fresh.search_on(&FarCellFrame {
            whole: true,
            ..moved
        });
        assert_eq!(
            slow.found.as_ref().map(|found| &found.2),
            fresh.found.as_ref().map(|found| &found.2)
        );
        let (met, looked_up) = (slow.weather.len(), slow.looked_up);
        assert!(
            met > 1_000 && looked_up * 20 < met,
            "{looked_up} looked up, {met} met"
        );
        // With the far field drawn, every cell reaching past its hand-over band's start is
        // drawn whole too (the near sprites fade out there): cells centred within the field.
        let band = FarCellFrame {
            band_start_m: Some(42_000.0),
            ..frame(&weather, &ctx, &types, true)
        };
        let banded = far.wanted(&band);
        assert!(
            banded.iter().any(|c| c.centre().length() < 100_000.0),
            "none within the field"
        );
        assert!(
            banded
                .iter()
                .all(|c| c.centre().length() + c.radius_m() > 42_000.0)
        );
    }
}

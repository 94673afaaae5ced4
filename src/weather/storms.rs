//! Thunderstorm cells and their lightning: objects of the weather field, not of a block.
//!
//! In: the weather at any point of the local frame (a closure over the field's block weather),
//! the wind profile of `config/air.toml` and the settings of `config/storms.toml`
//! ([`StormSettings`]). Out: plain [`StormCell`]s (where each cumulonimbus stands, how wide its
//! base and its anvil are, which way the anvil spreads) and [`Flash`] events.
//!
//! Placement: a world-aligned grid of `cells.grid_m` squares; each square holds at most one cell,
//! decided by a hash of (seed, square) and the CB layer's own amount reported at the square's
//! centre, with the chance that makes the bases cover that amount (expected base area / square
//! area = oktas / 8). A cell is decided by its square alone, so every block it spans computes the
//! same cell, and the blocks each draw their part of it (`clouds::storm`). Sizes follow
//! `../shared/DESIGN.md` "Weather at every scale": single cells 5-15 km across, the anvil
//! spreading downwind along the upper wind; the wind at the anvil's height is
//! [`super::air::wind_at`]'s, the same profile the air data gives the host.
//!
//! Lightning: a cell under a report with TS flashes `lightning.flashes_per_minute` times a minute
//! (-TS, TS, +TS), each minute's flashes hashed from (cell, minute), so a run is the same every
//! time and any span of time can be asked for in pieces.
//!
//! Units: metres east/north in the local (air) frame, feet for the report's heights as
//! [`super::BlockLayer`] gives them, seconds of field time.

use std::path::Path;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::air::{SurfaceAir, WindSettings, wind_at};
use super::block::{BlockWeather, METRES_PER_FOOT};
use super::cloud_type::CloudType;
use crate::config::{ConfigError, ShippedFile, TomlSettings};

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../config/storms.toml");

/// Settings of the storms (`config/storms.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StormSettings {
    /// Where cells stand and how big they are.
    pub cells: CellSettings,
    /// How often they flash.
    pub lightning: LightningSettings,
    /// Cells beyond the cloud field, out to the horizon.
    pub far: FarCellSettings,
}

/// Cells drawn beyond the cloud field's blocks (`[far]`): each whole, with few large sprites,
/// so a storm reads from 100 km and more (docs/src/storms.md, "Far cells").
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FarCellSettings {
    /// Whether cells beyond the cloud field are drawn.
    pub enabled: bool,
    /// How far from the camera they are looked for, metres.
    pub reach_m: f64,
    /// At most this many, the nearest.
    pub most: usize,
    /// Sprites of one far cell (the near cells' `[cumulonimbus.cell] sprites` budget).
    pub sprites: u32,
    /// Sprite width over the cell's base width, range (wider than a near cell's: fewer sprites
    /// cover the same cell).
    pub sprite_over_base: [f32; 2],
    /// Grid rows of the placement grid looked at a frame while a new set is found.
    pub rows_per_frame: u32,
    /// Cells that join the shown set in one frame at most (each is drawn then).
    pub joins_per_frame: u32,
    /// A new set is found after the camera moved this far from where the last was, metres.
    pub move_m: f64,
    /// A far cell forms or dissipates over this long as it comes into or leaves the set,
    /// seconds.
    pub fade_s: f64,
}

/// Placement and size of the cells (`[cells]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellSettings {
    /// Spacing of the placement grid, metres: at most one cell per square.
    pub grid_m: f64,
    /// Base diameter range, metres.
    pub base_width_m: [f64; 2],
    /// Widest base a dense amount may grow a cell to, metres.
    pub widest_base_m: f64,
    /// Anvil diameter over base diameter, range.
    pub anvil_over_base: [f64; 2],
    /// Downwind offset of the anvil's centre over the anvil's diameter, range.
    pub anvil_offset_over_width: [f64; 2],
    /// Anvil thickness range, metres.
    pub anvil_thickness_m: [f64; 2],
    /// Turrets the body is built of, range.
    pub turrets: [u32; 2],
}

/// Lightning (`[lightning]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightningSettings {
    /// Flashes a minute per cell under -TS, TS and +TS.
    pub flashes_per_minute: [f64; 3],
    /// Share of flashes that strike the ground, 0..=1.
    pub cloud_to_ground_share: f64,
    /// How long a flash lights its cell, seconds.
    pub duration_s: f64,
    /// Light an in-cloud flash adds to its cell at its peak, fraction of white, 0..=4.
    pub brightness: f64,
    /// How far an in-cloud flash's light reaches (its 1/e distance), metres.
    pub reach_m: f64,
}

impl Default for StormSettings {
    /// The shipped `config/storms.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

impl TomlSettings for StormSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/storms.toml", BUILTIN);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        let range = |r: [f64; 2], lo: f64| r[0] >= lo && r[0] <= r[1] && r[1].is_finite();
        let c = &self.cells;
        if !(c.grid_m >= 1000.0 && c.grid_m.is_finite()) {
            return Err(bad("cells.grid_m", "must be at least 1000"));
        }
        if !range(c.base_width_m, 100.0) {
            return Err(bad(
                "cells.base_width_m",
                "must be [low, high] with 100 <= low <= high",
            ));
        }
        if !(c.widest_base_m >= c.base_width_m[1] && c.widest_base_m.is_finite()) {
            return Err(bad(
                "cells.widest_base_m",
                "must be at least the top of cells.base_width_m",
            ));
        }
        if !range(c.anvil_over_base, 1.0) {
            return Err(bad(
                "cells.anvil_over_base",
                "must be [low, high] with 1 <= low <= high",
            ));
        }
        if !range(c.anvil_offset_over_width, 0.0) || c.anvil_offset_over_width[1] > 2.0 {
            return Err(bad(
                "cells.anvil_offset_over_width",
                "must be [low, high] with 0 <= low <= high <= 2",
            ));
        }
        if !range(c.anvil_thickness_m, 100.0) {
            return Err(bad(
                "cells.anvil_thickness_m",
                "must be [low, high] with 100 <= low <= high",
            ));
        }
        if !(c.turrets[0] >= 1 && c.turrets[0] <= c.turrets[1] && c.turrets[1] <= 12) {
            return Err(bad(
                "cells.turrets",
                "must be [low, high] with 1 <= low <= high <= 12",
            ));
        }
        let l = &self.lightning;
        if !l
            .flashes_per_minute
            .iter()
            .all(|r| (0.0..=600.0).contains(r))
        {
            return Err(bad(
                "lightning.flashes_per_minute",
                "must be three rates within 0..=600",
            ));
        }
        if !(0.0..=1.0).contains(&l.cloud_to_ground_share) {
            return Err(bad(
                "lightning.cloud_to_ground_share",
                "must be within 0..=1",
            ));
        }
        if !(l.duration_s > 0.0 && l.duration_s <= 5.0) {
            return Err(bad("lightning.duration_s", "must be within (0, 5]"));
        }
        if !(0.0..=4.0).contains(&l.brightness) {
            return Err(bad("lightning.brightness", "must be within 0..=4"));
        }
        if !(l.reach_m >= 10.0 && l.reach_m <= 50_000.0) {
            return Err(bad("lightning.reach_m", "must be within 10..=50000"));
        }
        let f = &self.far;
        if !(f.reach_m >= 0.0 && f.reach_m <= 2_000_000.0) {
            return Err(bad("far.reach_m", "must be within 0..=2000000"));
        }
        if f.most > 4096 {
            return Err(bad("far.most", "must be at most 4096"));
        }
        if !(8..=4000).contains(&f.sprites) {
            return Err(bad("far.sprites", "must be within 8..=4000"));
        }
        let widths = f.sprite_over_base;
        if !(widths[0] > 0.0 && widths[0] <= widths[1] && widths[1] <= 2.0) {
            return Err(bad(
                "far.sprite_over_base",
                "must be [low, high] with 0 < low <= high <= 2",
            ));
        }
        if f.rows_per_frame == 0 {
            return Err(bad("far.rows_per_frame", "must be at least 1"));
        }
        if f.joins_per_frame == 0 {
            return Err(bad("far.joins_per_frame", "must be at least 1"));
        }
        if !(f.move_m >= 0.0 && f.move_m.is_finite()) {
            return Err(bad("far.move_m", "must be at least 0"));
        }
        if !(0.0..=600.0).contains(&f.fade_s) {
            return Err(bad("far.fade_s", "must be within 0..=600"));
        }
        Ok(())
    }
}

impl StormSettings {
    /// How far from its grid square's centre a cell reaches at most (jitter, base, anvil and
    /// its offset), metres: the margin around an area whose cells are asked for.
    pub fn reach_m(&self) -> f64 {
        let c = &self.cells;
        let anvil = c.widest_base_m * c.anvil_over_base[1];
        0.5 * c.grid_m + anvil * (0.5 + c.anvil_offset_over_width[1])
    }
}

/// What the cells are decided with besides the weather: the settings, the wind profile that
/// turns the surface wind into the wind aloft, and the latitude (its sign turns that wind).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StormContext {
    /// `config/storms.toml`.
    pub settings: StormSettings,
    /// The wind profile of `config/air.toml` (the one the air data uses).
    pub wind: WindSettings,
    /// Latitude of the local frame, degrees.
    pub lat_deg: f64,
}

impl Default for StormContext {
    fn default() -> Self {
        Self {
            settings: StormSettings::default(),
            wind: super::air::AirSettings::default().wind,
            lat_deg: 45.0,
        }
    }
}

/// One cumulonimbus cell of the weather field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StormCell {
    /// The cell's own random key (its grid square hashed with the seed): what draws it.
    pub key: u64,
    /// Centre of the base, metres east/north in the local (air) frame.
    pub centre_m: [f64; 2],
    /// Diameter of the base, metres.
    pub base_width_m: f64,
    /// Base, feet above ground.
    pub base_ft_agl: f32,
    /// Top, feet above mean sea level.
    pub top_ft_msl: f32,
    /// Ground elevation under the cell, metres MSL.
    pub ground_m_msl: f32,
    /// Diameter of the anvil, metres.
    pub anvil_width_m: f64,
    /// From the base's centre to the anvil's, metres east/north (downwind aloft).
    pub anvil_offset_m: [f64; 2],
    /// Anvil thickness, metres.
    pub anvil_thickness_m: f64,
    /// Turrets the body is built of.
    pub turrets: u32,
    /// The wind at the anvil's height, the velocity it moves with, m/s east/north.
    pub wind_aloft_m_s: [f64; 2],
    /// The reports' thunder there: 0 none, 1 `-TS`, 2 `TS`, 3 `+TS`.
    pub thunder: u8,
    /// The precipitation intensity under it, 0..=1.
    pub precipitation: f32,
    /// Always [`CloudType::Cumulonimbus`] today.
    pub cloud_type: CloudType,
}

impl StormCell {
    /// Centre of the base, metres east/north.
    pub fn centre(&self) -> DVec2 {
        DVec2::from_array(self.centre_m)
    }

    /// The anvil's offset from the base's centre, metres east/north.
    pub fn anvil_offset(&self) -> DVec2 {
        DVec2::from_array(self.anvil_offset_m)
    }

    /// Base height, metres MSL.
    pub fn base_m_msl(&self) -> f64 {
        self.ground_m_msl as f64 + self.base_ft_agl as f64 * METRES_PER_FOOT
    }

    /// Top height, metres MSL.
    pub fn top_m_msl(&self) -> f64 {
        self.top_ft_msl as f64 * METRES_PER_FOOT
    }

    /// Farthest any part of it lies from the base's centre, horizontally, metres.
    pub fn radius_m(&self) -> f64 {
        (0.5 * self.base_width_m).max(self.anvil_offset().length() + 0.5 * self.anvil_width_m)
    }

    /// Whether any part of it may lie over the rectangle `min_m`..`max_m`.
    pub fn reaches(&self, min_m: DVec2, max_m: DVec2) -> bool {
        let c = self.centre();
        let nearest = c.clamp(min_m, max_m);
        nearest.distance(c) <= self.radius_m()
    }
}

/// Keys the placement hash apart from other uses of the seed.
const CELL_KEY: u64 = 0x6365_6c6c;
/// Keys the lightning hash.
const FLASH_KEY: u64 = 0x666c_6173;

/// SplitMix64 (Steele et al. 2014): a small, portable hash for deterministic placement.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn hash(keys: &[u64]) -> u64 {
    keys.iter().fold(0x5eed_u64, |h, &k| mix(h ^ mix(k)))
}

/// A stream of uniform numbers from a key.
struct Draws(u64);

impl Draws {
    fn next(&mut self) -> f64 {
        self.0 = mix(self.0);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, r: [f64; 2]) -> f64 {
        r[0] + (r[1] - r[0]) * self.next()
    }
}

/// The CB layer of a weather: its own amount (oktas), base (ft AGL) and thickness (ft).
fn cb_layer(w: &BlockWeather) -> Option<(f32, f32, f32)> {
    w.layers
        .iter()
        .filter(|l| l.cloud_type == CloudType::Cumulonimbus && l.coverage_oktas > 0.0)
        .max_by(|a, b| a.coverage_oktas.total_cmp(&b.coverage_oktas))
        .map(|l| (l.coverage_oktas, l.base_ft_agl, l.thickness_ft))
}

/// The cell of grid square (`ci`, `cj`), if it holds one; `weather_at` gives the weather at a
/// point of the local frame.
pub fn cell_of_square(
    ci: i64,
    cj: i64,
    weather_at: &mut dyn FnMut(DVec2) -> BlockWeather,
    ctx: &StormContext,
    seed: u64,
) -> Option<StormCell> {
    let c = &ctx.settings.cells;
    let g = c.grid_m;
    let square_centre = DVec2::new((ci as f64 + 0.5) * g, (cj as f64 + 0.5) * g);
    let w = weather_at(square_centre);
    let (oktas, base_ft_agl, thickness_ft) = cb_layer(&w)?;
    let key = hash(&[seed, CELL_KEY, ci as u64, cj as u64]);
    let mut d = Draws(key);
    // The chance that makes the expected base area of a square its share of the amount:
    // E[pi/4 w^2] p = (oktas / 8) g^2, with E[w^2] = (a^2 + ab + b^2) / 3 for w even in [a, b].
    let [a, b] = c.base_width_m;
    let mean_area = std::f64::consts::FRAC_PI_4 * (a * a + a * b + b * b) / 3.0;
    let chance = (oktas as f64 / 8.0).clamp(0.0, 1.0) * g * g / mean_area;
    if d.next() >= chance.min(1.0) {
        return None;
    }
    // More than a cell's worth in a square (BKN, OVC CB): the cell grows instead.
    let base_width_m = (d.range(c.base_width_m) * chance.max(1.0).sqrt()).min(c.widest_base_m);
    let jitter = 0.5 * (g - 0.5 * base_width_m).max(0.0);
    let centre = square_centre + DVec2::new(d.next() * 2.0 - 1.0, d.next() * 2.0 - 1.0) * jitter;
    let anvil_width_m = base_width_m * d.range(c.anvil_over_base);
    let ground_m_msl = w.ground_elevation_m as f64;
    let base_m = ground_m_msl + base_ft_agl.max(0.0) as f64 * METRES_PER_FOOT;
    let top_m = base_m + (thickness_ft.max(0.0) as f64 * METRES_PER_FOOT).max(3000.0);
    let anvil_thickness_m = d.range(c.anvil_thickness_m).min(0.4 * (top_m - base_m));
    // Downwind: the wind at the anvil's middle, from the profile the air data gives.
    let surface = SurfaceAir::of(&w, 0.0, 1013.25);
    let anvil_m = top_m - 0.5 * anvil_thickness_m;
    let wind = wind_at(
        &surface,
        anvil_m - ground_m_msl,
        anvil_m,
        ctx.lat_deg,
        &ctx.wind,
    );
    let to = (wind.from_deg + 180.0).to_radians();
    let calm = wind.speed_kt < 1.0;
    // In calm air the anvil spreads some way the hash picks (a cell always has one side).
    let towards = if calm {
        DVec2::from_angle(d.next() * std::f64::consts::TAU)
    } else {
        DVec2::new(to.sin(), to.cos())
    };
    let offset = towards * anvil_width_m * d.range(c.anvil_offset_over_width);
    let turrets = c.turrets[0] + (d.next() * (c.turrets[1] - c.turrets[0] + 1) as f64) as u32;
    let speed_m_s = if calm { 0.0 } else { wind.speed_kt * 0.514_444 };
    Some(StormCell {
        key,
        centre_m: centre.to_array(),
        base_width_m,
        base_ft_agl,
        top_ft_msl: (top_m / METRES_PER_FOOT) as f32,
        ground_m_msl: ground_m_msl as f32,
        anvil_width_m,
        anvil_offset_m: offset.to_array(),
        anvil_thickness_m,
        turrets: turrets.min(c.turrets[1]),
        wind_aloft_m_s: (towards * speed_m_s).to_array(),
        thunder: w.thunder.round().clamp(0.0, 3.0) as u8,
        precipitation: w.precipitation,
        cloud_type: CloudType::Cumulonimbus,
    })
}

/// The cells that may reach over the rectangle `min_m`..`max_m` of the local frame, in a fixed
/// order (by grid square); `weather_at` gives the weather at a point.
pub fn cells_over(
    min_m: DVec2,
    max_m: DVec2,
    weather_at: &mut dyn FnMut(DVec2) -> BlockWeather,
    ctx: &StormContext,
    seed: u64,
) -> Vec<StormCell> {
    let g = ctx.settings.cells.grid_m;
    let reach = ctx.settings.reach_m();
    let (lo, hi) = (
        (min_m - DVec2::splat(reach)) / g,
        (max_m + DVec2::splat(reach)) / g,
    );
    let mut out = Vec::new();
    for cj in lo.y.floor() as i64..hi.y.ceil() as i64 {
        for ci in lo.x.floor() as i64..hi.x.ceil() as i64 {
            if let Some(cell) = cell_of_square(ci, cj, weather_at, ctx, seed)
                && cell.reaches(min_m, max_m)
            {
                out.push(cell);
            }
        }
    }
    out
}

/// The share of the rectangle `min_m`..`max_m` under the cells' bases, oktas (sampled every
/// `step_m` metres).
pub fn base_cover_oktas(cells: &[StormCell], min_m: DVec2, max_m: DVec2, step_m: f64) -> f64 {
    let (nx, ny) = (
        ((max_m.x - min_m.x) / step_m).ceil().max(1.0) as usize,
        ((max_m.y - min_m.y) / step_m).ceil().max(1.0) as usize,
    );
    let mut under = 0usize;
    for y in 0..ny {
        for x in 0..nx {
            let p = min_m + DVec2::new(x as f64 + 0.5, y as f64 + 0.5) * step_m;
            if cells
                .iter()
                .any(|c| p.distance(c.centre()) <= 0.5 * c.base_width_m)
            {
                under += 1;
            }
        }
    }
    8.0 * under as f64 / (nx * ny) as f64
}

/// What a flash is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlashKind {
    /// Inside the cloud: the cell brightens from within.
    InCloud,
    /// A stroke from the base to the ground.
    CloudToGround,
}

/// One lightning flash: an event the host drains, for thunder and for lighting its own scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Flash {
    /// When it starts, seconds of field time.
    pub time_s: f64,
    /// Where, metres east/north/up (MSL) in the local (air) frame: inside the cell for an
    /// in-cloud flash, at the base for a stroke to the ground.
    pub position_m: [f64; 3],
    /// In-cloud or cloud-to-ground.
    pub kind: FlashKind,
    /// The key of the cell it belongs to.
    pub cell_key: u64,
}

/// The flashes of `cells` that start in [`from_s`, `to_s`), oldest first. Each minute of each
/// cell has its own hash, so asking for a span in pieces gives the same flashes as at once.
pub fn flashes_between(
    cells: &[StormCell],
    from_s: f64,
    to_s: f64,
    settings: &LightningSettings,
    seed: u64,
) -> Vec<Flash> {
    let mut out = Vec::new();
    if to_s <= from_s {
        return out;
    }
    for cell in cells {
        if cell.thunder == 0 {
            continue;
        }
        let rate = settings.flashes_per_minute[(cell.thunder as usize - 1).min(2)];
        for minute in (from_s / 60.0).floor() as i64..(to_s / 60.0).ceil() as i64 {
            let mut d = Draws(hash(&[seed, FLASH_KEY, cell.key, minute as u64]));
            // floor(rate + u): the rate on average, never under floor(rate) a minute.
            let n = (rate + d.next()).floor() as u32;
            for _ in 0..n {
                let t = (minute as f64 + d.next()) * 60.0;
                let ground = d.next() < settings.cloud_to_ground_share;
                let r = 0.35 * cell.base_width_m * d.next().sqrt();
                let a = d.next() * std::f64::consts::TAU;
                let (base, top) = (cell.base_m_msl(), cell.top_m_msl());
                let z = if ground {
                    base
                } else {
                    base + (top - base) * d.range([0.25, 0.7])
                };
                if t >= from_s && t < to_s {
                    let p = cell.centre() + DVec2::from_angle(a) * r;
                    out.push(Flash {
                        time_s: t,
                        position_m: DVec3::new(p.x, p.y, z).to_array(),
                        kind: if ground {
                            FlashKind::CloudToGround
                        } else {
                            FlashKind::InCloud
                        },
                        cell_key: cell.key,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    out
}

#[cfg(test)]
#[path = "storms_tests.rs"]
pub(crate) mod tests;

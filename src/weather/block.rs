//! Blocks: the 4 km x 4 km squares of the local frame that clouds are generated in, and the
//! weather of one block (what the clouds stage consumes).
//!
//! Units: block coordinates are metres east/north in the local frame; layer heights are feet above
//! ground, as METAR gives them.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::block_cover::BlockCover;
use super::cloud_type::CloudType;

/// Side of a block, metres (Wang 2003: 16 km2 blocks).
pub const BLOCK_SIZE_M: f64 = 4_000.0;

/// Metres in a foot: METAR heights (bases, thicknesses) and flight altitudes are in feet.
pub const METRES_PER_FOOT: f64 = 0.3048;

/// Metres a second in a knot.
pub const METRES_PER_KNOT: f64 = 0.514_444;

/// Integer index of a block: `i` counts blocks east, `j` blocks north of the frame origin.
/// Block (0, 0) spans [0, 4000) m east and [0, 4000) m north.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BlockIndex {
    /// Blocks east of the origin.
    pub i: i32,
    /// Blocks north of the origin.
    pub j: i32,
}

impl BlockIndex {
    /// The block index (i, j).
    pub const fn new(i: i32, j: i32) -> Self {
        Self { i, j }
    }

    /// The block containing a local point (metres east, north).
    pub fn containing(point_m: DVec2) -> Self {
        Self {
            i: (point_m.x / BLOCK_SIZE_M).floor() as i32,
            j: (point_m.y / BLOCK_SIZE_M).floor() as i32,
        }
    }

    /// South-west corner of the block, metres east/north.
    pub fn min_corner_m(self) -> DVec2 {
        DVec2::new(self.i as f64, self.j as f64) * BLOCK_SIZE_M
    }

    /// Centre of the block, metres east/north.
    pub fn centre_m(self) -> DVec2 {
        self.min_corner_m() + DVec2::splat(BLOCK_SIZE_M / 2.0)
    }
}

/// Where a layer's cloud type came from, so a user can see why a sky looks the way it does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TypeSource {
    /// The report's own CB/TCU suffix.
    Reported,
    /// A cloud-type remark (`RMK SC1AC1CI2`, Canadian practice).
    Remark,
    /// A weather theme that names the type.
    Theme,
    /// The height/cover rule of `config/cloud_type_rule.toml`.
    HeightRule,
    /// A numerical weather model's layer, typed by `config/weather_model.toml`.
    Model,
}

/// One cloud layer of a block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BlockLayer {
    /// The cloud type drawn for this layer.
    pub cloud_type: CloudType,
    /// Where the type came from.
    pub type_source: TypeSource,
    /// The layer's own sky coverage, oktas 0..=8 (fractional after interpolation): the share
    /// of the sky its clouds fill. A METAR cover counts all cloud at and below its base (the
    /// summation principle); the own coverages are such that the layers at and below a base,
    /// overlapping at random, cover what the report gives there (see
    /// [`cover_seen_from_below_oktas`]).
    pub coverage_oktas: f32,
    /// Cloud base, feet above ground.
    pub base_ft_agl: f32,
    /// Layer thickness base to top, feet.
    pub thickness_ft: f32,
}

impl BlockLayer {
    /// Whether this is a reported CB or TCU layer: one with its own amount (ICAO Annex 3),
    /// outside the summation principle that the other layers' covers follow.
    pub fn has_own_amount(&self) -> bool {
        self.type_source == TypeSource::Reported
    }
}

/// What the report says obscures the view near the ground (present weather BR, FG, HZ, FU,
/// DU/SA/DS/SS): with the visibility it sets the fog a host draws and the haze of the clouds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Obscuration {
    /// `BR`: mist, water droplets, visibility 1,000 m and more.
    Mist,
    /// `FG` (also `FZFG`, `BCFG`, `PRFG`, `MIFG`): fog, visibility under 1,000 m where it lies.
    Fog,
    /// `HZ`: haze, dry particles.
    Haze,
    /// `FU`: smoke.
    Smoke,
    /// `DU`, `SA`, `DS`, `SS`: dust or sand, raised or in a storm.
    Dust,
}

impl Obscuration {
    /// The obscuration a present-weather phenomenon code names (`FG`, `BR`, ...), if any.
    pub fn of_code(code: &str) -> Option<Self> {
        match code {
            "BR" => Some(Self::Mist),
            "FG" => Some(Self::Fog),
            "HZ" => Some(Self::Haze),
            "FU" => Some(Self::Smoke),
            "DU" | "SA" | "DS" | "SS" => Some(Self::Dust),
            _ => None,
        }
    }

    /// Which of two reported obscurations a report is drawn with: fog, then smoke, dust, haze,
    /// mist (the one that hides most).
    pub fn rank(self) -> u8 {
        match self {
            Self::Fog => 4,
            Self::Smoke => 3,
            Self::Dust => 2,
            Self::Haze => 1,
            Self::Mist => 0,
        }
    }
}

/// Surface wind; interpolated as a vector so opposite winds cancel instead of averaging direction.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Wind {
    /// Direction the wind blows from, degrees true (0 when calm or variable).
    pub from_deg: f32,
    /// Speed, knots.
    pub speed_kt: f32,
}

impl Wind {
    /// Velocity the air moves with, metres per second east/north (where clouds drift to).
    pub fn drift_m_s(self) -> DVec2 {
        let to_rad = (self.from_deg as f64 + 180.0).to_radians();
        DVec2::new(to_rad.sin(), to_rad.cos()) * self.speed_kt as f64 * METRES_PER_KNOT
    }
}

/// The weather of one block: what the clouds stage turns into clouds.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BlockWeather {
    /// Cloud layers, lowest base first.
    pub layers: Vec<BlockLayer>,
    /// Horizontal visibility, metres.
    pub visibility_m: f32,
    /// What obscures the view near the ground, if the reports say (fog, mist, haze, ...).
    #[serde(default)]
    pub obscuration: Option<Obscuration>,
    /// Surface wind.
    pub wind: Wind,
    /// Air temperature, degrees Celsius.
    pub temperature_c: f32,
    /// Dewpoint, degrees Celsius.
    pub dewpoint_c: f32,
    /// Precipitation intensity 0 (none) ..= 1 (heavy), from the reports' present weather.
    pub precipitation: f32,
    /// Thunder, 0 (none) ..= 3 (`+TS`): 1 `-TS`, 2 `TS`, interpolated between the reports.
    #[serde(default)]
    pub thunder: f32,
    /// Ground elevation under the block, metres above mean sea level (from station elevations).
    pub ground_elevation_m: f32,
    /// How the layers' cover varies across the block ([`BlockCover`]): what the field gives at
    /// the block's rim. `None` (the weather at a point, a theme's block): the same everywhere.
    #[serde(default)]
    pub cover: Option<BlockCover>,
}

/// The sky covered seen from below at `height_ft` AGL, oktas: the layers with their base at or
/// under it, each covering its own coverage of the sky independently of the others (clouds of
/// different layers overlap at random), so `8 (1 - prod(1 - own / 8))`. This is what a METAR
/// cover reports at that layer's base (the summation principle).
pub fn cover_seen_from_below_oktas(layers: &[BlockLayer], height_ft: f32) -> f32 {
    let clear: f32 = layers
        .iter()
        .filter(|l| l.base_ft_agl <= height_ft)
        .map(|l| 1.0 - (l.coverage_oktas / 8.0).clamp(0.0, 1.0))
        .product();
    8.0 * (1.0 - clear)
}

/// The own coverage, oktas, a layer needs so that the sky seen from below goes from
/// `below_oktas` (the cover of the layers under it) to `total_oktas` at its base: the inverse of
/// [`cover_seen_from_below_oktas`]. `None` when the sky below is already overcast (nothing
/// more can be seen) or the total does not grow.
pub fn own_coverage_oktas(below_oktas: f64, total_oktas: f64) -> Option<f64> {
    let clear_below = 1.0 - below_oktas / 8.0;
    if clear_below <= 1e-9 || total_oktas <= below_oktas {
        return None;
    }
    Some(8.0 * (1.0 - (1.0 - total_oktas.min(8.0) / 8.0) / clear_below))
}

/// The ceiling, feet AGL, as a report gives it: the lowest base where the sky seen from below is
/// broken or overcast (at least `broken_oktas`, 5 for the 5/8 that BKN starts at), counting the
/// layers of the summation principle; a reported CB or TCU layer ([`TypeSource::Reported`]) has
/// its own amount (ICAO Annex 3) and makes a ceiling only when that amount is broken itself.
/// `None` when there is none.
pub fn ceiling_ft(layers: &[BlockLayer], broken_oktas: f32) -> Option<f32> {
    let summed: Vec<BlockLayer> = layers
        .iter()
        .filter(|l| !l.has_own_amount())
        .copied()
        .collect();
    let mut bases: Vec<f32> = layers.iter().map(|l| l.base_ft_agl).collect();
    bases.sort_by(f32::total_cmp);
    bases.into_iter().find(|&b| {
        cover_seen_from_below_oktas(&summed, b) >= broken_oktas - 1e-4
            || layers.iter().any(|l| {
                l.has_own_amount() && l.base_ft_agl <= b && l.coverage_oktas >= broken_oktas - 1e-4
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(coverage_oktas: f32, base_ft_agl: f32) -> BlockLayer {
        BlockLayer {
            cloud_type: CloudType::Stratocumulus,
            type_source: TypeSource::HeightRule,
            coverage_oktas,
            base_ft_agl,
            thickness_ft: 500.0,
        }
    }

    #[test]
    fn own_coverages_add_up_to_the_reported_covers_seen_from_below() {
        // FEW008 SCT026 BKN045: 2, 4 and 6 oktas seen from below.
        let few = own_coverage_oktas(0.0, 2.0).unwrap();
        let sct = own_coverage_oktas(2.0, 4.0).unwrap();
        let bkn = own_coverage_oktas(4.0, 6.0).unwrap();
        assert!((few - 2.0).abs() < 1e-9 && (sct - 8.0 / 3.0).abs() < 1e-9 && bkn == 4.0);
        let layers = [
            layer(few as f32, 800.0),
            layer(sct as f32, 2600.0),
            layer(bkn as f32, 4500.0),
        ];
        for (base, cover) in [(800.0, 2.0), (2600.0, 4.0), (4500.0, 6.0)] {
            let seen = cover_seen_from_below_oktas(&layers, base);
            assert!((seen - cover).abs() < 1e-5, "{base}: {seen}");
        }
        assert_eq!(cover_seen_from_below_oktas(&layers, 700.0), 0.0);
        assert_eq!(ceiling_ft(&layers, 5.0), Some(4500.0));
        assert_eq!(ceiling_ft(&layers[..2], 5.0), None);
        // FEW011 SCT017CB BKN023 (LEVX): the Cb's 4 oktas are its own, so the ceiling is the
        // BKN023, not the 5 oktas the Cb and the FEW011 would make together at 1,700 ft; a
        // broken Cb alone (BKN045CB) is a ceiling.
        let cb = |coverage_oktas: f32, base_ft_agl: f32| BlockLayer {
            cloud_type: CloudType::Cumulonimbus,
            type_source: TypeSource::Reported,
            ..layer(coverage_oktas, base_ft_agl)
        };
        let levx = [layer(2.0, 1100.0), cb(4.0, 1700.0), layer(4.0, 2300.0)];
        assert_eq!(ceiling_ft(&levx, 5.0), Some(2300.0));
        assert_eq!(ceiling_ft(&[cb(6.0, 4500.0)], 5.0), Some(4500.0));
        // Nothing more is seen above an overcast, and a cover that does not grow adds nothing.
        assert_eq!(own_coverage_oktas(8.0, 8.0), None);
        assert_eq!(own_coverage_oktas(6.0, 6.0), None);
        assert_eq!(own_coverage_oktas(6.0, 8.0), Some(8.0));
    }

    #[test]
    fn block_index_of_points_on_both_sides_of_the_origin() {
        assert_eq!(
            BlockIndex::containing(DVec2::new(0.0, 0.0)),
            BlockIndex::new(0, 0)
        );
        assert_eq!(
            BlockIndex::containing(DVec2::new(3999.9, 4000.0)),
            BlockIndex::new(0, 1)
        );
        assert_eq!(
            BlockIndex::containing(DVec2::new(-0.1, -4000.1)),
            BlockIndex::new(-1, -2)
        );
        assert_eq!(
            BlockIndex::new(-1, 2).centre_m(),
            DVec2::new(-2000.0, 10_000.0)
        );
    }

    #[test]
    fn westerly_wind_drifts_east() {
        let d = Wind {
            from_deg: 270.0,
            speed_kt: 10.0,
        }
        .drift_m_s();
        assert!((d.x - 5.144).abs() < 0.01 && d.y.abs() < 1e-9);
    }
}

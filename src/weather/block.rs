//! Blocks: the 4 km x 4 km squares of the local frame that clouds are generated in, and the
//! weather of one block (what the clouds stage consumes).
//!
//! Units: block coordinates are metres east/north in the local frame; layer heights are feet above
//! ground, as METAR gives them.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::cloud_type::CloudType;

/// Side of a block, metres (Wang 2003: 16 km2 blocks).
pub const BLOCK_SIZE_M: f64 = 4_000.0;

/// Metres in a foot: METAR heights (bases, thicknesses) and flight altitudes are in feet.
pub const METRES_PER_FOOT: f64 = 0.3048;

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
}

/// One cloud layer of a block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BlockLayer {
    /// The cloud type drawn for this layer.
    pub cloud_type: CloudType,
    /// Where the type came from.
    pub type_source: TypeSource,
    /// Sky coverage, oktas 0..=8 (fractional after interpolation).
    pub coverage_oktas: f32,
    /// Cloud base, feet above ground.
    pub base_ft_agl: f32,
    /// Layer thickness base to top, feet.
    pub thickness_ft: f32,
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
        DVec2::new(to_rad.sin(), to_rad.cos()) * self.speed_kt as f64 * 0.514_444
    }
}

/// The weather of one block: what the clouds stage turns into clouds.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BlockWeather {
    /// Cloud layers, lowest base first.
    pub layers: Vec<BlockLayer>,
    /// Horizontal visibility, metres.
    pub visibility_m: f32,
    /// Surface wind.
    pub wind: Wind,
    /// Air temperature, degrees Celsius.
    pub temperature_c: f32,
    /// Dewpoint, degrees Celsius.
    pub dewpoint_c: f32,
    /// Precipitation intensity 0 (none) ..= 1 (heavy), from the reports' present weather.
    pub precipitation: f32,
    /// Ground elevation under the block, metres above mean sea level (from station elevations).
    pub ground_elevation_m: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

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

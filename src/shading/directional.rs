//! Directional sunlight, Wang 2003 section 5.2, equation (2): a vertex's light depends on the
//! angle between (vertex - shading group centre) and the sun direction, mapped with a bias so the
//! terminator down the middle of a cloud is soft.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The artist's mapping of the dot product `[-1, 1]` to a fraction of the maximum directional
/// colour: `[-1, 0] -> [c_min, c_median]`, `[0, 1] -> [c_median, c_max]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalMapping {
    /// Fraction on the side facing away from the sun (dot = -1).
    pub c_min: f32,
    /// Fraction at right angles to the sun (dot = 0).
    pub c_median: f32,
    /// Fraction on the side facing the sun (dot = 1).
    pub c_max: f32,
}

impl Default for DirectionalMapping {
    fn default() -> Self {
        Self {
            c_min: 0.15,
            c_median: 0.6,
            c_max: 1.0,
        }
    }
}

impl DirectionalMapping {
    /// Maps a dot product in `[-1, 1]` (clamped) with the bias.
    pub fn map(&self, dot: f32) -> f32 {
        let d = dot.clamp(-1.0, 1.0);
        if d < 0.0 {
            self.c_median + (self.c_median - self.c_min) * d
        } else {
            self.c_median + (self.c_max - self.c_median) * d
        }
    }
}

/// The fraction of the maximum directional colour a vertex gets: `map(normalize(vertex -
/// group_centre) . sun_dir)`. `sun_dir` points towards the sun (unit). A vertex at the group
/// centre gets `c_median`.
pub fn directional_percent(
    mapping: &DirectionalMapping,
    vertex: Vec3,
    group_centre: Vec3,
    sun_dir: Vec3,
) -> f32 {
    let v = (vertex - group_centre).normalize_or_zero();
    mapping.map(v.dot(sun_dir.normalize_or_zero()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn biased_mapping_hits_the_three_artist_values() {
        let m = DirectionalMapping {
            c_min: 0.2,
            c_median: 0.7,
            c_max: 1.0,
        };
        assert!((m.map(-1.0) - 0.2).abs() < 1e-6);
        assert!((m.map(0.0) - 0.7).abs() < 1e-6);
        assert!((m.map(1.0) - 1.0).abs() < 1e-6);
        assert!((m.map(-0.5) - 0.45).abs() < 1e-6);
        assert!((m.map(0.5) - 0.85).abs() < 1e-6);
        assert!((m.map(7.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sunward_side_of_a_group_is_brighter() {
        let m = DirectionalMapping::default();
        let sun = Vec3::new(0.0, 0.0, 1.0);
        let c = Vec3::new(10.0, 10.0, 1000.0);
        let top = directional_percent(&m, c + Vec3::Z * 50.0, c, sun);
        let side = directional_percent(&m, c + Vec3::X * 50.0, c, sun);
        let bottom = directional_percent(&m, c - Vec3::Z * 50.0, c, sun);
        assert_eq!((top, side, bottom), (m.c_max, m.c_median, m.c_min));
        assert_eq!(directional_percent(&m, c, c, sun), m.c_median);
    }
}

//! Beyond Wang: light scattered forward towards the eye. Harris and Lastra 2001 shade each
//! particle with a phase function of the angle between the light and the view; Wang's model has
//! none, so a cloud between the camera and the sun is as dull as one beside it. Here a
//! Henyey-Greenstein lobe adds directional light to the thin rim of such a cloud (the silver
//! lining); its thick core keeps Wang's shading. Settings: `[forward_scattering]` of
//! `config/time_of_day.toml`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The `[forward_scattering]` table of `config/time_of_day.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForwardScattering {
    /// Henyey-Greenstein asymmetry, 0 (no preference) ..= 0.95 (a narrow lobe around the sun).
    pub g: f32,
    /// Extra fraction of the directional colour at a cloud's rim looking straight at the sun.
    pub strength: f32,
}

impl Default for ForwardScattering {
    fn default() -> Self {
        Self {
            g: 0.7,
            strength: 1.2,
        }
    }
}

impl ForwardScattering {
    /// The extra fraction of the directional colour at a vertex seen along `view` (unit, camera
    /// to vertex), the sun along `sun_dir` (unit, towards the sun), `rim` the vertex's distance
    /// from the cloud centre over the cloud's radius (0 centre ..= 1 edge): the lobe, 1 looking
    /// straight at the sun, times the rim to the fourth (the outermost sprites only).
    pub fn percent(&self, view: Vec3, sun_dir: Vec3, rim: f32) -> f32 {
        let cos = view.dot(sun_dir).clamp(-1.0, 1.0);
        let g = self.g;
        let lobe = ((1.0 - g) * (1.0 - g) / (1.0 + g * g - 2.0 * g * cos)).powf(1.5);
        let rim = rim.clamp(0.0, 1.0).powi(4);
        self.strength * lobe * rim
    }

    /// The first field out of range, with why.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        if !(0.0..=0.95).contains(&self.g) {
            return Some((
                "forward_scattering.g",
                format!("must be 0..=0.95, is {}", self.g),
            ));
        }
        if !(0.0..=4.0).contains(&self.strength) {
            return Some((
                "forward_scattering.strength",
                format!("must be 0..=4, is {}", self.strength),
            ));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rim_glows_towards_the_sun_and_nowhere_else() {
        let f = ForwardScattering::default();
        let sun = Vec3::new(0.0, 1.0, 0.2).normalize();
        // Looking straight at the sun through a cloud's edge: the whole strength.
        assert!((f.percent(sun, sun, 1.0) - f.strength).abs() < 1e-5);
        // The core gets nothing; halfway out a sixteenth.
        assert_eq!(f.percent(sun, sun, 0.0), 0.0);
        assert!((f.percent(sun, sun, 0.5) - f.strength / 16.0).abs() < 1e-5);
        // 30 degrees off the sun: a small part; at right angles or with the sun behind: ~none.
        let off = Vec3::new(0.5, 0.866, 0.0).normalize();
        let p30 = f.percent(off, Vec3::Y, 1.0);
        assert!(p30 < 0.2 * f.strength && p30 > 0.0, "{p30}");
        assert!(f.percent(Vec3::X, Vec3::Y, 1.0) < 0.02 * f.strength);
        assert!(f.percent(-Vec3::Y, Vec3::Y, 1.0) < 0.01 * f.strength);
        let off = ForwardScattering { strength: 0.0, ..f };
        assert_eq!(off.percent(sun, sun, 1.0), 0.0);
    }

    #[test]
    fn out_of_range_settings_are_named() {
        let f = ForwardScattering {
            g: 1.0,
            ..ForwardScattering::default()
        };
        assert_eq!(f.invalid_field().unwrap().0, "forward_scattering.g");
        assert!(ForwardScattering::default().invalid_field().is_none());
    }
}

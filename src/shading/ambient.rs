//! Ambient sky light, Wang 2003 section 5.1: five RGBA colour levels at heights in a cloud,
//! interpolated by vertex height (equation (1), the `A_V` part). The time-of-day percentage is
//! applied by the caller ([`crate::shading::TimeOfDay::ambient_percent`]).

use glam::Vec4;
use serde::{Deserialize, Serialize};

/// One colour level: a height and the RGBA ambient colour there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColourLevel {
    /// Height, metres (any datum, the same as the vertex heights passed to [`ColourLevels::at`]).
    pub height_m: f32,
    /// Linear RGBA, 0..=1; alpha makes some types (stratus) more transparent.
    pub rgba: [f32; 4],
}

/// The five colour levels of a cloud, lowest first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColourLevels(pub [ColourLevel; 5]);

impl ColourLevels {
    /// Five levels evenly spaced from `base_m` to `top_m`, colours given bottom to top.
    pub fn even(base_m: f32, top_m: f32, rgba: [[f32; 4]; 5]) -> Self {
        let step = (top_m - base_m) / 4.0;
        Self(std::array::from_fn(|i| ColourLevel {
            height_m: base_m + step * i as f32,
            rgba: rgba[i],
        }))
    }

    /// The ambient colour at `height_m`: linear between the two enclosing levels, the end
    /// colours outside them.
    pub fn at(&self, height_m: f32) -> Vec4 {
        let levels = &self.0;
        if height_m <= levels[0].height_m {
            return Vec4::from_array(levels[0].rgba);
        }
        for pair in levels.windows(2) {
            let (lo, hi) = (pair[0], pair[1]);
            if height_m <= hi.height_m {
                let span = hi.height_m - lo.height_m;
                let a_v = if span > 0.0 {
                    (hi.height_m - height_m) / span
                } else {
                    0.0
                };
                return Vec4::from_array(lo.rgba) * a_v + Vec4::from_array(hi.rgba) * (1.0 - a_v);
            }
        }
        Vec4::from_array(levels[4].rgba)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn levels() -> ColourLevels {
        ColourLevels::even(
            1000.0,
            1400.0,
            [
                [0.4, 0.4, 0.5, 1.0],
                [0.5, 0.5, 0.6, 1.0],
                [0.6, 0.6, 0.7, 1.0],
                [0.8, 0.8, 0.85, 1.0],
                [1.0, 1.0, 1.0, 0.5],
            ],
        )
    }

    #[test]
    fn interpolates_between_levels_and_clamps_outside() {
        let l = levels();
        assert_eq!(l.at(500.0), Vec4::new(0.4, 0.4, 0.5, 1.0));
        assert_eq!(l.at(2000.0), Vec4::new(1.0, 1.0, 1.0, 0.5));
        let mid = l.at(1050.0); // halfway between levels 0 (1000 m) and 1 (1100 m)
        assert!((mid - Vec4::new(0.45, 0.45, 0.55, 1.0)).abs().max_element() < 1e-6);
        let top = l.at(1350.0);
        assert!((top - Vec4::new(0.9, 0.9, 0.925, 0.75)).abs().max_element() < 1e-6);
    }

    #[test]
    fn bottoms_are_darker_than_tops() {
        let l = levels();
        assert!(l.at(1000.0).x < l.at(1300.0).x);
    }
}

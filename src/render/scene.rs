//! What the renderer draws: blocks of clouds of sprites, in the plain form the vertex builder
//! reads. The clouds stage's `CloudBlock` converts into these; tests and hosts can also build
//! them directly.
//!
//! Units: positions metres in the local east-north-up frame (z above mean sea level), cloud
//! centres in f64, sprite offsets from the cloud centre in f32.

use glam::{DVec3, Vec3};

use crate::shading::ColourLevels;

/// One camera-facing sprite of a cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkySprite {
    /// Centre, metres from the cloud centre (east, north, up).
    pub offset_m: Vec3,
    /// Width, metres.
    pub width_m: f32,
    /// Height, metres.
    pub height_m: f32,
    /// Rotation in the sprite plane, degrees (0 for non-square sprites).
    pub rotation_deg: f32,
    /// Cell of the 4 x 4 texture sheet, 0..16 (row-major from the top left).
    pub cell: u8,
    /// Index into the cloud's shading group centres.
    pub group: u16,
    /// Formation / dissipation factor multiplied into alpha, 0..=1 (Wang 4).
    pub alpha_morph: f32,
    /// Turns only about the vertical (a cylindrical billboard: its bottom edge stays level) and
    /// fades out as the camera looks at it from steeply below or above.
    pub upright: bool,
}

/// One cloud: sprites around a centre, with its Wang 5 shading inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyCloud {
    /// Centre, metres (east, north, above mean sea level).
    pub centre_m: DVec3,
    /// The sprites.
    pub sprites: Vec<SkySprite>,
    /// Shading group centres, metres from the cloud centre (Wang 5.2).
    pub group_centres_m: Vec<Vec3>,
    /// The five ambient colour levels; heights in metres above mean sea level (Wang 5.1).
    pub colour_levels: ColourLevels,
    /// Drawn as flat horizontal rectangles instead of camera-facing sprites (cirrus, Wang 7.1);
    /// a flat sprite's height is its north-south extent.
    pub flat: bool,
}

/// A 4 km x 4 km block of clouds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkyBlock {
    /// Identifies the block across frames for the vertex cache (e.g. a hash of its index).
    pub id: u64,
    /// Centre of the block, metres (the sort key of the block pass).
    pub centre_m: DVec3,
    /// The clouds.
    pub clouds: Vec<SkyCloud>,
}

impl SkyCloud {
    /// Half extents of the box holding the sprite centres plus half of each sprite's size,
    /// metres, and the box centre offset from `centre_m`.
    pub fn core_box_m(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::MAX);
        let mut hi = Vec3::splat(f32::MIN);
        for s in &self.sprites {
            let r = Vec3::new(s.width_m, s.width_m, s.height_m) * 0.25;
            lo = lo.min(s.offset_m - r);
            hi = hi.max(s.offset_m + r);
        }
        if self.sprites.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        ((hi - lo) * 0.5, (hi + lo) * 0.5)
    }

    /// Radius of a sphere around `centre_m` holding every sprite, metres.
    pub fn radius_m(&self) -> f32 {
        self.sprites
            .iter()
            .map(|s| s.offset_m.length() + 0.5 * s.width_m.max(s.height_m))
            .fold(0.0, f32::max)
    }

    /// Whether any sprite is forming or dissipating.
    pub fn is_fading(&self) -> bool {
        self.sprites.iter().any(|s| s.alpha_morph < 0.999)
    }
}

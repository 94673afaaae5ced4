//! What the renderer draws: blocks of clouds of sprites, in plain form. A block is uploaded to
//! the GPU once when the sky gets it (`Sky::insert_block`, `Sky::set_clouds`); after that only
//! its [`BlockMotion`] (drift offset and [`Fade`]) changes per frame. The clouds stage's
//! `CloudBlock` converts into these; tests and hosts can also build them directly.
//!
//! Units: positions metres in the local east-north-up frame (z above mean sea level), cloud
//! centres in f64, sprite offsets from the cloud centre in f32.

use glam::{DVec3, Vec3};

use crate::clouds::core::SpriteCore;
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
    /// Rotation in the sprite plane, degrees (0 for non-square sprites). A sprite wider than
    /// tall, not upright, in a cloud that is not flat is a layer's puff (a pancake): seen from
    /// steeply above or below its quad rounds to its width and turns its own way on top of this
    /// (`[clouds] layer_turn_start_deg` and `layer_turn_end_deg`).
    pub rotation_deg: f32,
    /// Cell of the 4 x 4 texture sheet, 0..16 (row-major from the top left).
    pub cell: u8,
    /// Index into the cloud's shading group centres.
    pub group: u16,
    /// A fixed transparency factor multiplied into alpha, 0..=1 (1 for a generated cloud: its
    /// formation and dissipation come from the block's [`Fade`]).
    pub alpha_morph: f32,
    /// Distance of the centre from the cloud centre over the cloud radius, 0..=1: which sprites
    /// form first and dissipate last (Wang 4).
    pub radius_fraction: f32,
    /// Turns only about the vertical (a cylindrical billboard: its bottom edge stays level) and
    /// fades out as the camera looks at it from steeply below or above.
    pub upright: bool,
    /// Falling rain or snow (a shaft under the cloud), not cloud: drawn darker and greyer.
    pub precipitation: bool,
    /// Stands on the cloud's base: its dense core spans its width (`clouds::core`), for the
    /// camera's in-cloud measure.
    pub base: bool,
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
    /// A deck's sunlit depth, metres: the depth below its top at which direct sunlight, along
    /// its slanted path, falls to 1/e. Seen from below, the deck is lit evenly by the sun
    /// diffused through it (an even grey ceiling, no sunlit heaps); elsewhere each sprite corner
    /// by its depth below the top, the same at every place, under either shading model (a deck
    /// is one cloud per lattice cell, and lit cloud by cloud each cell had a sunlit side: a grid
    /// seen from above). 0: lit from every side, as Wang lights clouds.
    pub sunlit_depth_m: f32,
    /// A heap's shaded base, metres above its base: below it the body above hides the sun (one
    /// dark, evenly lit base), the sun coming in over it. 0: lit down to the base.
    pub shaded_base_m: f32,
    /// Its flat base, metres from `centre_m` (negative: below it): the camera is in cloud
    /// only above it, inside a sprite's dense core (`clouds::core`, as every probe of the
    /// air data). `f32::MIN`: no base.
    pub floor_m: f32,
    /// An overcast deck's closed underside (`clouds::Cloud::floor_slab_m`): a slab on its
    /// floor, half as wide as the first value and as deep as the second; zeros for none.
    pub floor_slab_m: [f32; 2],
    /// Factor on the in-cloud extinction through its cores (`clouds::Cloud::optical_density`):
    /// how dark its shadow is, as the probes' optical depth.
    pub optical_density: f32,
}

/// A 4 km x 4 km block of clouds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkyBlock {
    /// Identifies the block while the sky holds it. A different content must come with a
    /// different id (the clouds stage gives every generation of a block its own).
    pub id: u64,
    /// Centre of the block, metres (the sort key of the block pass).
    pub centre_m: DVec3,
    /// The clouds.
    pub clouds: Vec<SkyCloud>,
}

impl SkyCloud {
    /// The dense cores of its sprites (rain and snow are not cloud), as every probe sees them.
    pub fn cores(&self) -> impl Iterator<Item = SpriteCore> + '_ {
        self.sprites.iter().filter(|s| !s.precipitation).map(|s| {
            let mut core = SpriteCore::new(
                s.offset_m.to_array(),
                s.width_m,
                s.height_m,
                s.rotation_deg,
                self.flat,
            );
            if s.base {
                core.widen_to_base();
                core.stand_on(f64::from(self.floor_m));
            }
            core
        })
    }

    /// Half extents of the box around its cores above its base, metres, and the box centre
    /// offset from `centre_m`: outside it the camera is out of the cloud.
    pub fn core_box_m(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::MAX);
        let mut hi = Vec3::splat(f32::MIN);
        let mut any = false;
        for core in self.cores() {
            let r = core.box_half_m().as_vec3();
            lo = lo.min(core.centre_m.as_vec3() - r);
            hi = hi.max(core.centre_m.as_vec3() + r);
            any = true;
        }
        if !any {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        if let Some((slab_lo, slab_hi)) =
            crate::clouds::core::floor_slab(f64::from(self.floor_m), self.floor_slab_m)
        {
            lo = lo.min(slab_lo.as_vec3());
            hi = hi.max(slab_hi.as_vec3());
        }
        lo.z = lo.z.max(self.floor_m).min(hi.z);
        ((hi - lo) * 0.5, (hi + lo) * 0.5)
    }

    /// Radius of a sphere around `centre_m` holding every sprite, metres.
    pub fn radius_m(&self) -> f32 {
        self.sprites
            .iter()
            .map(|s| s.offset_m.length() + 0.5 * s.width_m.max(s.height_m))
            .fold(0.0, f32::max)
    }
}

/// Where a block is in its life (Wang 4). The sprites' fades are worked out from it on the GPU:
/// forming, the inner sprites come first; dissipating, the outer ones go first.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Fade {
    /// Fully formed.
    #[default]
    Steady,
    /// Forming; progress 0 (nothing shows) ..= 1 (formed).
    Forming(f32),
    /// Dissipating; progress 0 (whole) ..= 1 (gone).
    Dissipating(f32),
}

impl Fade {
    /// Whether going to `to` changes the kind of fade (steady, forming, dissipating), not
    /// only its progress.
    pub fn kind_changes(self, to: Fade) -> bool {
        std::mem::discriminant(&self) != std::mem::discriminant(&to)
    }
}

/// What changes of a block from frame to frame without a new upload.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BlockMotion {
    /// Added to every cloud centre (the drift with the wind), metres.
    pub offset_m: DVec3,
    /// Formation or dissipation.
    pub fade: Fade,
    /// Which of the drifts a [`crate::render::SkyUpdate`] gives moves it
    /// ([`BandOffsets`]: the clouds stage's drift bands, [`crate::clouds::bands`]); 0 for a
    /// block of the host's own.
    pub drift_band: u8,
}

/// The drift offset of each drift band, metres ([`crate::clouds::bands`]: each of a block's
/// layers drifts with the wind at its own height), lowest band first.
pub type BandOffsets = [DVec3; crate::clouds::config::MAX_DRIFT_BANDS as usize];

/// A sprite convenience for tests and hosts: a square sprite, fully opaque.
pub fn square_sprite(offset_m: Vec3, size_m: f32, cell: u8, group: u16) -> SkySprite {
    SkySprite {
        offset_m,
        width_m: size_m,
        height_m: size_m,
        rotation_deg: 0.0,
        cell,
        group,
        alpha_morph: 1.0,
        radius_fraction: 0.0,
        upright: false,
        precipitation: false,
        base: false,
    }
}

#[cfg(test)]
mod tests {
    use super::Fade;

    /// The shadow map's cover check watches the kind of a block's fade, never its progress: a
    /// sky of forming clouds would trip it every frame.
    #[test]
    fn a_fade_changes_kind_only_between_steady_forming_and_dissipating() {
        assert!(!Fade::Forming(0.2).kind_changes(Fade::Forming(0.3)));
        assert!(!Fade::Dissipating(0.9).kind_changes(Fade::Dissipating(0.1)));
        assert!(!Fade::Steady.kind_changes(Fade::Steady));
        assert!(Fade::Forming(1.0).kind_changes(Fade::Steady));
        assert!(Fade::Steady.kind_changes(Fade::Dissipating(0.0)));
        assert!(Fade::Forming(0.5).kind_changes(Fade::Dissipating(0.5)));
    }
}

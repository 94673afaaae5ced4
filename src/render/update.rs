//! What a living cloud field hands the sky each frame, as plain data: a [`SkyUpdate`] (the
//! blocks that came, with their clouds, the ones that went, their fades, the drift, the
//! lifecycle when it changed, the far storm cells' changes), made by the flight side
//! (`flight::World::advance_sky`) without touching the renderer and applied by
//! [`crate::render::Sky::apply`]. The other way, [`SkyReach`] is what the world needs to know of
//! the sky's settings: where the impostor ring and the far field take over.
//!
//! No wgpu here: a test builds and reads both without a device.
//!
//! Units: metres in the local east-north-up frame; CPU time in microseconds ([`Spent`]).

use glam::DVec3;

use crate::clouds::config::{LifecycleConfig, MAX_DRIFT_BANDS};
use crate::render::scene::{BandOffsets, BlockMotion, Fade, SkyBlock};
use crate::render::stats::Spent;

/// One frame's changes of the blocks a living field hands the sky, applied in this order by
/// [`crate::render::Sky::apply`]: the lifecycle, the distant blocks' changes, the expected
/// blocks, the blocks that came, the fades, the drift, the blocks that went. Consumed when
/// applied: the sprites of the blocks that came are moved into the sky, never copied.
///
/// A frame in which nothing came, went or faded is the drift alone (empty vectors allocate
/// nothing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SkyUpdate {
    /// How clouds form and dissipate, when it changed (the living clouds' first frame).
    pub lifecycle: Option<LifecycleConfig>,
    /// The far storm cells' changes, in the order they happened (a cell replaced is taken out
    /// before its new self comes in).
    pub distant: Vec<DistantChange>,
    /// Sprites and clouds of the blocks that still wait to be handed over (the frames' budget),
    /// when the field's blocks changed: the buffers grow for them too, once
    /// ([`crate::render::Sky::expect_blocks`]). `None`: as the sky last heard.
    pub expected: Option<(u64, u64)>,
    /// New generations, uploaded once, each with its drift and fade.
    pub came: Vec<(SkyBlock, BlockMotion)>,
    /// Blocks the sky holds whose fade moved on (by id), or that finished fading
    /// ([`Fade::Steady`]).
    pub fades: Vec<(u64, Fade)>,
    /// Each drift band's offset with the wind, metres: a block moves with its
    /// [`BlockMotion::drift_band`]'s. `None`: left as it is.
    pub drift_m: Option<BandOffsets>,
    /// Ids of the generations that went.
    pub went: Vec<u64>,
    /// The CPU time the field spent making this update on the frame thread (the clouds
    /// advanced, the blocks looked through), without the sky's applying it: the host adds it
    /// to the frame's [`crate::render::FrameStats::field_us`] (`SkySystem::update` does).
    pub field_cpu: Spent,
}

impl SkyUpdate {
    /// An update that only moves every block to the drift `offset_m` (every band alike).
    pub fn drift(offset_m: DVec3) -> Self {
        Self {
            drift_m: Some([offset_m; MAX_DRIFT_BANDS as usize]),
            ..Self::default()
        }
    }

    /// Whether blocks come or go (distant ones included): what the sky times applying.
    pub fn moves_blocks(&self) -> bool {
        !self.came.is_empty()
            || !self.went.is_empty()
            || self
                .distant
                .iter()
                .any(|c| !matches!(c, DistantChange::Fade(..)))
    }
}

/// A change of the blocks drawn however far they are (the far storm cells,
/// [`crate::render::Sky::insert_distant_block`]).
#[derive(Debug, Clone, PartialEq)]
pub enum DistantChange {
    /// A distant block comes (or replaces the block with its id), with its drift and fade.
    Came(SkyBlock, BlockMotion),
    /// The block with this id goes.
    Went(u64),
    /// The block with this id is now at this point of its life.
    Fade(u64, Fade),
}

/// Where the sky hands the clouds over from one way of drawing them to the next, as a living
/// field needs to know it to decide what it hands the sky: plain values read from the sky
/// ([`crate::render::Sky::reach`]) and given to the world (`flight::World::set_sky_reach`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SkyReach {
    /// The impostor ring's radius, metres, while the ring is drawn: blocks that arrive in a
    /// sky that had none fade in within it (beyond it, the ring's crossfade brings them in).
    pub ring_radius_m: Option<f64>,
    /// Where the far field takes over from the sprites and the ring while it is drawn: the
    /// band (start, end), metres from the camera. The far storm cells reaching past its
    /// start are drawn whole.
    pub hand_over_m: Option<(f32, f32)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drift_alone_moves_no_blocks() {
        let u = SkyUpdate::drift(DVec3::new(1.0, 2.0, 0.0));
        assert_eq!(
            u.drift_m,
            Some([DVec3::new(1.0, 2.0, 0.0); MAX_DRIFT_BANDS as usize])
        );
        assert!(!u.moves_blocks());
        let faded = SkyUpdate {
            distant: vec![DistantChange::Fade(7, Fade::Forming(0.5))],
            ..u.clone()
        };
        assert!(!faded.moves_blocks());
        let went = SkyUpdate {
            distant: vec![DistantChange::Went(7)],
            ..u
        };
        assert!(went.moves_blocks());
    }
}

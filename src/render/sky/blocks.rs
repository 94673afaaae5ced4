//! The blocks a host hands the sky ([`Sky::set_clouds`], [`Sky::insert_block`] and their
//! kin, or a living field's [`SkyUpdate`] through [`Sky::apply`]): into the resident set, out
//! of it, their motion, drift and fade. What a frame uploads of them is the resident set's; here
//! they are only taken in and let go.

use std::collections::HashSet;

use super::Sky;
use crate::render::scene::BlockMotion;
use crate::render::scene::SkyBlock;
use crate::render::stats::Stopwatch;
use crate::render::update::{DistantChange, SkyReach, SkyUpdate};

impl Sky {
    /// Replaces the clouds with `blocks` (none drifting, all steady). A block the sky already
    /// holds with the same id and content stays on the GPU as it is, with its cached orders;
    /// the others are uploaded by the next [`Self::prepare`]. For a whole new scene; a living
    /// field hands over its changes with [`Self::insert_block`], [`Self::remove_block`] and
    /// [`Self::set_block_motion`] instead.
    pub fn set_clouds(&mut self, blocks: Vec<SkyBlock>) {
        let start = Stopwatch::start();
        let ids: HashSet<u64> = blocks.iter().map(|b| b.id).collect();
        let gone: Vec<u64> = self
            .sprites
            .resident
            .blocks
            .keys()
            .filter(|id| !ids.contains(id))
            .copied()
            .collect();
        for id in gone {
            self.retire(id);
        }
        for block in blocks {
            match self.sprites.resident.blocks.get_mut(&block.id) {
                Some(r) if r.block == block => {
                    if r.motion() != BlockMotion::default() {
                        let steady = BlockMotion::default();
                        self.sprites.resident.fades += r.fade().kind_changes(steady.fade) as u64;
                        r.set_motion(steady);
                        self.sprites.resident.changes += 1;
                    }
                }
                _ => self.sprites.resident.insert(block, BlockMotion::default()),
            }
        }
        self.pending += start.spent();
    }

    /// Applies what a living field changed this frame (`flight::World::advance_sky` makes it),
    /// in the order [`SkyUpdate`] gives: the blocks that came are moved in (uploaded once, by
    /// the next [`Self::prepare`]), those that went are retired, the fades and the drift set.
    /// Applying is counted in the next frame's [`crate::render::FrameStats::cpu_update_us`]
    /// when blocks come or go (timed once); a drift (one write for every block) and fades (one
    /// a fading block) alone go untimed, as a clock read would cost more. `update.field_cpu` is
    /// the host's to count ([`Self::add_field_cpu`], or the frame's stats).
    pub fn apply(&mut self, update: SkyUpdate) {
        let start = update.moves_blocks().then(Stopwatch::start);
        let SkyUpdate {
            lifecycle,
            distant,
            expected,
            came,
            fades,
            drift_m,
            went,
            field_cpu: _,
        } = update;
        if let Some(lifecycle) = lifecycle {
            self.set_lifecycle(lifecycle);
        }
        for change in distant {
            match change {
                DistantChange::Came(block, motion) => self.insert_distant(block, motion),
                DistantChange::Went(id) => {
                    self.retire(id);
                }
                DistantChange::Fade(id, fade) => {
                    self.set_block_fade(id, fade);
                }
            }
        }
        if let Some((sprites, clouds)) = expected {
            self.expect_blocks(sprites, clouds);
        }
        for (block, motion) in came {
            self.retire(block.id);
            self.sprites.resident.insert(block, motion);
        }
        for (id, fade) in fades {
            self.set_block_fade(id, fade);
        }
        if let Some(offsets_m) = drift_m {
            self.set_band_drifts(&offsets_m);
        }
        for id in went {
            self.retire(id);
        }
        if let Some(start) = start {
            self.pending += start.spent();
        }
    }

    /// Where this sky hands its clouds over from one way of drawing them to the next (the
    /// impostor ring, the far field's band), as a living field needs to know it: read again
    /// after the ring or the far field is switched, or the far field's first map arrived.
    pub fn reach(&self) -> SkyReach {
        let impostors = &self.settings.impostors;
        SkyReach {
            ring_radius_m: impostors.enabled.then_some(impostors.ring_radius_m),
            hand_over_m: self.far_field_hand_over_m(),
        }
    }

    /// Adds a block (or replaces the one with its id); it is uploaded to the GPU once, by the
    /// next [`Self::prepare`]. Many at once: [`Self::insert_blocks`].
    pub fn insert_block(&mut self, block: SkyBlock, motion: BlockMotion) {
        self.insert_blocks([(block, motion)]);
    }

    /// [`Self::insert_block`] for each of `blocks`, timed once (reading the thread's CPU clock
    /// costs about a microsecond, more than inserting a block).
    pub fn insert_blocks(&mut self, blocks: impl IntoIterator<Item = (SkyBlock, BlockMotion)>) {
        let start = Stopwatch::start();
        for (block, motion) in blocks {
            self.retire(block.id);
            self.sprites.resident.insert(block, motion);
        }
        self.pending += start.spent();
    }

    /// Says that blocks of `sprites` sprites and `clouds` clouds in all will be inserted in
    /// the next frames (a weather change handed over a part a frame): when the buffers next
    /// grow, they grow for those as well, once. Each call replaces the last; 0, 0 when none
    /// wait.
    pub fn expect_blocks(&mut self, sprites: u64, clouds: u64) {
        self.sprites.resident.expected = (sprites, clouds);
    }

    /// Adds a block drawn as sprites however far it is, never into the impostor ring nor cut at
    /// the draw distance: what the ring and the far field cannot draw beyond the cloud field,
    /// a storm cell's tower seen from 100-450 km (`flight::far_cells`). While the far field is
    /// drawn, its sprites fade in over the hand-over band as the near sprites and the ring fade
    /// out there ([`Self::far_field_hand_over_m`]). Replaces the block with
    /// its id; uploaded once, by the next [`Self::prepare`].
    pub fn insert_distant_block(&mut self, block: SkyBlock, motion: BlockMotion) {
        let start = Stopwatch::start();
        self.insert_distant(block, motion);
        self.pending += start.spent();
    }

    /// [`Self::insert_distant_block`], untimed.
    fn insert_distant(&mut self, block: SkyBlock, motion: BlockMotion) {
        let id = block.id;
        self.retire(id);
        self.sprites.resident.insert(block, motion);
        if let Some(r) = self.sprites.resident.blocks.get_mut(&id) {
            r.distant = true;
        }
    }

    /// Retires a block; false if the sky did not hold it. Many at once:
    /// [`Self::remove_blocks`].
    pub fn remove_block(&mut self, id: u64) -> bool {
        self.remove_blocks([id]) == 1
    }

    /// [`Self::remove_block`] for each of `ids`, timed once; returns how many the sky held.
    pub fn remove_blocks(&mut self, ids: impl IntoIterator<Item = u64>) -> usize {
        let start = Stopwatch::start();
        let held = ids.into_iter().filter(|&id| self.retire(id)).count();
        self.pending += start.spent();
        held
    }

    fn retire(&mut self, id: u64) -> bool {
        match self.sprites.resident.remove(id) {
            Some(slots) => {
                for view in &mut self.views {
                    view.locks.release(slots.clone());
                }
                true
            }
            None => false,
        }
    }

    /// Moves a block (its drift) and sets where it is in its life; nothing is uploaded but the
    /// frame's draw list. False if the sky does not hold it.
    pub fn set_block_motion(&mut self, id: u64, motion: BlockMotion) -> bool {
        match self.sprites.resident.blocks.get_mut(&id) {
            Some(r) => {
                // What the shadow map watches for (a block moved by other means than the drift).
                self.sprites.resident.changes += (r.offset_m() != motion.offset_m) as u64;
                self.sprites.resident.fades += r.fade().kind_changes(motion.fade) as u64;
                r.set_motion(motion);
                true
            }
            None => false,
        }
    }

    /// Moves every block the sky holds to the same drift offset (a field drifting with the air as
    /// one, every drift band alike): one write a block, no lookups, nothing uploaded.
    pub fn set_drift(&mut self, offset_m: glam::DVec3) {
        self.set_band_drifts(&[offset_m; crate::clouds::config::MAX_DRIFT_BANDS as usize]);
    }

    /// Moves every block the sky holds to its drift band's offset (each band of layers drifts
    /// with the wind at its own height, [`crate::clouds::bands`]): the bands are written once,
    /// and each block reads its band's offset where it is used; nothing is uploaded.
    pub fn set_band_drifts(&mut self, offsets_m: &crate::render::scene::BandOffsets) {
        self.sprites.resident.set_drift(offsets_m);
        self.shadows.set_drift(offsets_m);
    }

    /// Sets where a block is in its life, keeping its drift; false if the sky does not hold it.
    pub fn set_block_fade(&mut self, id: u64, fade: crate::render::Fade) -> bool {
        match self.sprites.resident.blocks.get_mut(&id) {
            Some(r) => {
                self.sprites.resident.fades += r.fade().kind_changes(fade) as u64;
                r.set_fade(fade);
                true
            }
            None => false,
        }
    }

    /// The ids of the blocks the sky holds.
    pub fn block_ids(&self) -> impl Iterator<Item = u64> + '_ {
        self.sprites.resident.blocks.keys().copied()
    }

    /// A block the sky holds.
    pub fn block(&self, id: u64) -> Option<&SkyBlock> {
        self.sprites.resident.blocks.get(&id).map(|r| &r.block)
    }
}

//! The ring's split of each frame ([`ImpostorRing::split`]): which blocks the camera draws as
//! sprites and which the ring holds, from the camera's height and the blocks' distances from
//! the ring centre (`layout::is_far`), and when the ring starts or advances a rebuild
//! (`layout::needs_rebuild`). Plain data over the resident blocks; the GPU work of a rebuild is
//! [`ImpostorRing::prepare_builds`]'s and [`ImpostorRing::record_builds`]'s.

use glam::{DVec3, Vec3};

use super::layout::{IMPOSTORS, is_far, needs_rebuild, sectors_of};
use super::{Build, ImpostorRing, RingState, SplitCheck};
use crate::render::id_hash::IdSet;
use crate::render::scene::Fade;
use crate::render::sprites::resident::ResidentSet;

impl ImpostorRing {
    /// Decides this frame's near blocks ([`Self::near`]: drawn as sprites) and
    /// starts or advances a rebuild. Call [`Self::prepare_builds`] after, with the frame's
    /// uniform. One pass over the blocks.
    pub(in crate::render) fn split(
        &mut self,
        resident: &mut ResidentSet,
        camera_m: DVec3,
        sun: Vec3,
        dt_s: f64,
    ) {
        let s = self.reach_settings();
        self.clock_s += dt_s.max(0.0);
        if self.recorded.replace(false) {
            self.pending.clear();
        }
        let (changes, drift_m) = (resident.changes, resident.drift_m);
        let blocks = &mut resident.blocks;
        self.blocks_far = 0;
        if !s.enabled {
            self.near_of = None;
            self.near.clear();
            self.near.extend(blocks.keys());
            return;
        }
        // Advance the crossfade; a finished fade makes the new ring the shown one.
        if let Some((ring, state, w)) = self.fade.take() {
            let w = if s.crossfade_s > 0.0 {
                w + dt_s.max(0.0) / s.crossfade_s
            } else {
                1.0
            };
            if w >= 1.0 {
                self.shown = Some((ring, state));
            } else {
                self.fade = Some((ring, state, w));
            }
        }
        // The far set shown (or fading in), and whether the blocks far from the shown ring's
        // centre are still the ones in it (else a rebuild starts).
        let steady_shown = self.fade.is_none() && self.build.is_none();
        let shown = self.shown.as_ref().map(|(_, st)| st);
        let mut far_now = 0;
        let mut same = true;
        let mut whole_new = false;
        // Which blocks are far depends on the camera's height alone (`is_far`), not on where
        // it is across the ground: a level flight walks the blocks again only when they or
        // the drift changed.
        let slack_m = 0.1 * s.rebuild_move_fraction.min(s.rebuild_climb_fraction) * s.ring_radius_m;
        let kept = self.last_split.filter(|c| {
            steady_shown
                && c.changes == changes
                && c.builds == self.builds
                && c.view_radius_m == s.view_radius_m
                && (c.camera_z_m - camera_m.z).abs() + (c.drift_m - drift_m).length() <= slack_m
        });
        let far = (self.fade.as_ref().map(|(_, st, _)| st))
            .or(shown)
            .or(self.build.as_ref().map(|b| &b.state));
        // The blocks drawn as sprites are the ones not in the ring shown (or fading in): they
        // change with the blocks held and the ring, not with the camera.
        let near_of = (changes, far.map(|st| st.build));
        let far_ids = far.map(|st| &st.far_ids);
        if self.near_of != Some(near_of) {
            self.near.clear();
            self.near.extend(
                (blocks.keys())
                    .filter(|id| far_ids.is_none_or(|f| !f.contains(id)))
                    .copied(),
            );
            self.near_of = Some(near_of);
        }
        let far_count = (blocks.len() - self.near.len()) as u32;
        if let Some(c) = kept {
            (far_now, same, whole_new) = (c.far_now, c.same, c.whole_new);
        } else if steady_shown && let Some(st) = shown {
            // Whether the blocks far from the shown ring's centre now are still the ones in it,
            // and whether one not in it is drawn whole (not forming) short of where the band
            // has faded the ring halfway.
            for r in blocks.values() {
                if !r.distant && is_far(r.nearest_height_m(camera_m.z), st.centre_m, camera_m, &s) {
                    far_now += 1;
                    if !st.far_ids.contains(&r.block.id) {
                        same = false;
                        let shown = self.half_faded_m.is_none_or(|half| {
                            (r.centre_m() - st.centre_m).truncate().length() - r.radius_m < half
                        });
                        whole_new |= shown && r.motion.fade == Fade::Steady;
                    }
                }
            }
            self.last_split = Some(SplitCheck {
                changes,
                builds: self.builds,
                view_radius_m: s.view_radius_m,
                camera_z_m: camera_m.z,
                drift_m,
                far_now,
                same,
                whole_new,
            });
        } else {
            self.last_split = None;
        }
        self.blocks_far = far_count;
        if self.build.is_some() {
            return;
        }
        let start = match (&self.shown, &self.fade) {
            (None, None) => true,
            (Some((_, st)), None) => {
                // A block that arrives whole goes into the ring at once (it would stand as
                // sprites until the next rebuild, then swap into the ring); generations that
                // begin to form (at no opacity) or are gone (dissipated) wait their turn.
                let far_change_due = self.clock_s - st.begun_s >= s.rebuild_far_change_after_s;
                needs_rebuild(st.centre_m, st.sun, camera_m, sun, &s)
                    || whole_new
                    || (far_change_due && (!same || far_now != st.far_ids.len()))
            }
            _ => false,
        };
        if !start {
            return;
        }
        let ring = self.shown.as_ref().map_or(0, |(r, _)| 1 - r);
        // Renders into that ring not recorded yet (frames prepared and never recorded) are of a
        // ring no longer shown: this build replaces them.
        self.pending.retain(|p| p.0 != ring);
        let far: Vec<(u64, f64)> = blocks
            .values()
            .filter(|r| {
                !r.distant && is_far(r.nearest_height_m(camera_m.z), camera_m, camera_m, &s)
            })
            .map(|r| (r.block.id, (r.centre_m() - camera_m).length()))
            .collect();
        let far_mean_m = if far.is_empty() {
            s.ring_radius_m
        } else {
            far.iter().map(|f| f.1).sum::<f64>() / far.len() as f64
        };
        let far_ids: IdSet = far.iter().map(|f| f.0).collect();
        let mut sectors: [Vec<u64>; IMPOSTORS] = Default::default();
        for r in blocks.values().filter(|r| far_ids.contains(&r.block.id)) {
            let bits = sectors_of(camera_m, r.centre_m());
            for (i, sector) in sectors.iter_mut().enumerate() {
                if bits & (1 << i) != 0 {
                    sector.push(r.block.id);
                }
            }
        }
        let first = self.shown.is_none();
        if first {
            // Before the first ring exists it is built this frame, so its blocks are far
            // already.
            self.near.retain(|id| !far_ids.contains(id));
            self.blocks_far = far_ids.len() as u32;
        }
        self.sorts.retain(blocks);
        self.builds += 1;
        self.build = Some(Build {
            ring,
            next: 0,
            sectors,
            state: RingState {
                centre_m: camera_m,
                sun,
                far_ids,
                far_mean_m,
                build: self.builds,
                begun_s: self.clock_s,
            },
        });
    }
}

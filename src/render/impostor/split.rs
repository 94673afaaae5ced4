//! The ring's plan of each frame ([`RingPlan::split`]): which blocks the camera draws as
//! sprites and which the ring holds, from the camera's height and the blocks' distances from
//! the ring centre (`layout::is_far`), and when the ring starts or advances a rebuild
//! (`layout::needs_rebuild`). Plain data over the resident blocks, tested without a device; the
//! GPU work of a rebuild is [`ImpostorRing::prepare_builds`]'s and
//! [`ImpostorRing::record_builds`]'s.

use glam::{DVec3, Vec3};

use super::band::{box_elevations_rad, cloud_elevations_rad, widened_m};
use super::layout::{IMPOSTORS, ImpostorSettings, is_far, needs_rebuild, sectors_of};
use super::{Build, ImpostorRing, RingState};
use crate::render::id_hash::IdSet;
use crate::render::scene::{BandOffsets, Fade};
use crate::render::sprites::draw_list::Blocks;
use crate::render::sprites::resident::{Resident, ResidentSet};

/// The ring's CPU state from frame to frame: the rings shown, built and fading in, the renders
/// planned and not recorded yet, and which blocks the view draws as sprites.
#[derive(Default)]
pub(super) struct RingPlan {
    pub shown: Option<(usize, RingState)>,
    pub build: Option<Build>,
    /// The ring fading in and the fade so far, 0..=1.
    pub fade: Option<(usize, RingState, f64)>,
    /// The impostor renders prepared since the last recorded frame: (ring, impostor, sprites).
    pub pending: Vec<(usize, usize, u32)>,
    /// Blocks drawn into the ring this frame.
    pub blocks_far: u32,
    /// Where the hand-over band has faded the ring halfway, metres (`None`: no band): a far
    /// block that arrives whole beyond it (joining the field at its rim) is no reason to
    /// rebuild at once.
    pub half_faded_m: Option<f64>,
    /// Time the ring has seen pass (the sum of the frames' steps), seconds.
    pub clock_s: f64,
    /// Builds started.
    pub builds: u64,
    /// The last pass over every block while the ring was steady.
    last_split: Option<SplitCheck>,
    /// The ids of the blocks this view draws as sprites (held, not in the ring), as of the last
    /// pass over every block: what the view's draw list looks at, not the thousands held.
    pub near: Vec<u64>,
    /// What `near` was found with: the blocks' changes and the build of the ring whose blocks
    /// it leaves out. While both stand it stands, through builds and crossfades.
    near_of: Option<(u64, Option<u64>)>,
}

/// What a pass over every block found while the ring was steady (shown, no build, no fade),
/// and what with: while no block came, went or was written, the same ring is shown and the
/// camera's height and the drift moved less than a tenth of the ring's own rebuild distances
/// (which blocks are far from the ring centre does not depend on where the camera is across
/// the ground), the blocks' near marks and the crossings stand, and the thousands of blocks
/// are not walked again (a block that drifted across the ring radius starts a rebuild that
/// little later).
#[derive(Debug, Clone, Copy)]
struct SplitCheck {
    changes: u64,
    builds: u64,
    view_radius_m: f64,
    camera_z_m: f64,
    drift_m: BandOffsets,
    far_now: usize,
    same: bool,
    /// Whether a far block not in the shown ring is drawn whole
    /// ([`Fade::Steady`](crate::render::Fade::Steady)).
    whole_new: bool,
}

impl ImpostorRing {
    /// This frame's plan ([`RingPlan::split`] over the resident blocks, with the ring's
    /// settings cut to its reach): its near blocks ([`Self::near`]: drawn as sprites), a
    /// rebuild started or advanced. Call [`Self::prepare_builds`] after, with the frame's
    /// uniform.
    pub(in crate::render) fn plan(
        &mut self,
        resident: &ResidentSet,
        camera_m: DVec3,
        sun: Vec3,
        dt_s: f64,
    ) {
        let s = self.reach_settings();
        let recorded = self.recorded.replace(false);
        let blocks = (&resident.blocks, resident.changes, resident.drift_m());
        if (self.plan).split(&s, blocks, (camera_m, sun, dt_s), recorded) {
            // The orders kept for blocks gone go with the build that starts.
            self.sorts.retain(&resident.blocks);
        }
    }
}

impl RingPlan {
    /// Decides this frame's near blocks and starts or advances a rebuild, for a camera at
    /// `camera_m` under the sun `sun`, `dt_s` after the last frame, over `blocks` (with the
    /// resident set's count of changes and its drift). `recorded`: the renders planned before
    /// went into a recorded frame. One pass over the blocks. Returns whether a rebuild started.
    pub fn split(
        &mut self,
        s: &ImpostorSettings,
        (blocks, changes, drift_m): (&Blocks, u64, BandOffsets),
        (camera_m, sun, dt_s): (DVec3, Vec3, f64),
        recorded: bool,
    ) -> bool {
        let s = *s;
        self.clock_s += dt_s.max(0.0);
        if recorded {
            self.pending.clear();
        }
        self.blocks_far = 0;
        if !s.enabled {
            self.near_of = None;
            self.near.clear();
            self.near.extend(blocks.keys());
            return false;
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
                && (c.camera_z_m - camera_m.z).abs() + drift_moved_m(&c.drift_m, &drift_m)
                    <= slack_m
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
                        whole_new |= shown && r.fade() == Fade::Steady;
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
            return false;
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
            return false;
        }
        let ring = self.shown.as_ref().map_or(0, |(r, _)| 1 - r);
        // Renders into that ring not recorded yet (frames prepared and never recorded) are of a
        // ring no longer shown: this build replaces them.
        self.pending.retain(|p| p.0 != ring);
        let far: Vec<(u64, f64, &Resident)> = blocks
            .values()
            .filter(|r| {
                !r.distant && is_far(r.nearest_height_m(camera_m.z), camera_m, camera_m, &s)
            })
            .map(|r| (r.block.id, (r.centre_m() - camera_m).length(), r))
            .collect();
        let far_mean_m = if far.is_empty() {
            s.ring_radius_m
        } else {
            far.iter().map(|f| f.1).sum::<f64>() / far.len() as f64
        };
        let far_ids: IdSet = far.iter().map(|f| f.0).collect();
        let far_blocks: Vec<&Resident> = far.iter().map(|f| f.2).collect();
        let content_rad = content_rad(&far_blocks, camera_m);
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
                content_rad,
                build: self.builds,
                begun_s: self.clock_s,
            },
        });
        true
    }
}

/// Radians a block's bound is taken as wider than it is: far more than the rounding of its
/// elevations (about 1e-16 of a radian), far less than any elevation two clouds differ by.
const BOUND_SLACK_RAD: f64 = 1e-9;

/// The elevations from `from_m` of every cloud of the `far` blocks: the lowest bottom and the
/// highest top of [`cloud_elevations_rad`] over them, `(0, 0)` for none (the ring's content,
/// where its pass is drawn). A block's box of cloud centres widened by its largest cloud
/// ([`box_elevations_rad`]) bounds its clouds' elevations, so the blocks are read highest bound
/// first for the top and lowest first for the bottom, and each walk stops at the first block
/// that cannot reach past what it found: the same numbers as a walk over every cloud, which
/// read the ring's tens of thousands of clouds once a rebuild started (the approach's slowest
/// frames).
fn content_rad(far: &[&Resident], from_m: DVec3) -> (f64, f64) {
    let mut bounds: Vec<(f64, f64, usize)> = (far.iter().enumerate())
        .map(|(k, r)| {
            let (low, high) = block_bound_rad(r, from_m);
            (low, high, k)
        })
        .collect();
    let mut read = vec![false; far.len()];
    let mut found: Option<(f64, f64)> = None;
    let mut read_block = |k: usize, found: &mut Option<(f64, f64)>| {
        if std::mem::replace(&mut read[k], true) {
            return;
        }
        let r = far[k];
        let offset_m = r.offset_m();
        for c in &r.seen {
            let (a, b) =
                cloud_elevations_rad(c.centre_m + offset_m - from_m, f64::from(c.radius_m));
            *found = Some(found.map_or((a, b), |f| (f.0.min(a), f.1.max(b))));
        }
    };
    bounds.sort_by(|a, b| b.1.total_cmp(&a.1));
    for &(_, high, k) in &bounds {
        if found.is_some_and(|f| high < f.1 - BOUND_SLACK_RAD) {
            break;
        }
        read_block(k, &mut found);
    }
    bounds.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(low, _, k) in &bounds {
        if found.is_some_and(|f| low > f.0 + BOUND_SLACK_RAD) {
            break;
        }
        read_block(k, &mut found);
    }
    found.unwrap_or((0.0, 0.0))
}

/// Elevations from `from_m` that no cloud of block `r` reaches beyond (lowest first): its box
/// of cloud centres widened by its largest cloud, read without its clouds.
fn block_bound_rad(r: &Resident, from_m: DVec3) -> (f64, f64) {
    let (lo, hi) = r.centres_box_m;
    let (at, reach) = (r.centre_m() - from_m, widened_m(r.largest_cloud_m));
    box_elevations_rad(at + lo - reach, at + hi + reach)
}

/// How far the farthest-moved drift band has moved from `then` to `now`, metres.
fn drift_moved_m(then: &BandOffsets, now: &BandOffsets) -> f64 {
    then.iter()
        .zip(now)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::rng::SplitMix64;
    use crate::render::scene::BlockMotion;
    use crate::render::scene::{SkyBlock, SkyCloud};
    use crate::render::sprites::draw_list::tests::small_cloud;

    /// Blocks of one small cloud each at `centres`, ids 0, 1, ...
    fn blocks_at(centres: &[DVec3]) -> Blocks {
        (centres.iter().enumerate())
            .map(|(id, &centre_m)| {
                let block = SkyBlock {
                    id: id as u64,
                    centre_m,
                    clouds: vec![SkyCloud {
                        centre_m,
                        ..small_cloud()
                    }],
                };
                (id as u64, Resident::new(block, Default::default()))
            })
            .collect()
    }

    /// The first plan builds a ring of the blocks beyond its radius at once and leaves the near
    /// one to the sprites; the frames of its build start no other; switched off, every block
    /// is near and nothing is built. No device: the plan is plain data.
    #[test]
    fn the_first_plan_puts_the_far_blocks_in_the_ring_and_leaves_the_near_to_the_sprites() {
        let s = ImpostorSettings::default();
        let camera = DVec3::new(0.0, 0.0, 1000.0);
        let blocks = blocks_at(&[
            DVec3::new(0.0, 5_000.0, 1500.0),
            DVec3::new(0.0, 30_000.0, 1500.0),
            DVec3::new(-40_000.0, 0.0, 1500.0),
            // Beyond the view radius: neither in the ring nor near.
            DVec3::new(0.0, -150_000.0, 1500.0),
        ]);
        let frame = (&blocks, 4, BandOffsets::default());
        let mut plan = RingPlan::default();
        assert!(plan.split(&s, frame, (camera, Vec3::Z, 0.016), false));
        let build = plan.build.as_ref().map(|b| &b.state);
        let far: IdSet = [1, 2].into_iter().collect();
        assert_eq!(build.map(|st| &st.far_ids), Some(&far));
        assert_eq!(plan.blocks_far, 2);
        let mut near = plan.near.clone();
        near.sort_unstable();
        assert_eq!(near, vec![0, 3]);
        // The build goes on over the next frames: no new one starts.
        assert!(!plan.split(&s, frame, (camera, Vec3::Z, 0.016), false));
        assert_eq!(plan.builds, 1);
        let off = ImpostorSettings {
            enabled: false,
            ..s
        };
        let mut plan = RingPlan::default();
        assert!(!plan.split(&off, frame, (camera, Vec3::Z, 0.016), false));
        assert!(plan.build.is_none());
        assert_eq!(plan.near.len(), 4);
    }

    /// The ring's content band read block by block, from the highest and the lowest bound, is
    /// the band of every cloud to the bit: blocks of clouds of many sizes spread around their
    /// centres, near and far, above and below the ring centre, each with its own drift.
    #[test]
    fn the_content_band_read_by_block_bounds_is_the_band_of_every_cloud() {
        let mut rng = SplitMix64::new(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.next_f64();
        let from = DVec3::new(1_000.0, -2_000.0, 3_000.0);
        for _ in 0..200 {
            let blocks: Vec<Resident> = (0..30)
                .map(|id| {
                    let centre_m = DVec3::new(
                        (next() - 0.5) * 100_000.0,
                        (next() - 0.5) * 100_000.0,
                        next() * 12_000.0,
                    );
                    let clouds = (0..1 + (next() * 8.0) as usize)
                        .map(|_| {
                            let scale = 0.2 + 10.0 * next() as f32;
                            let mut cloud = small_cloud();
                            for s in &mut cloud.sprites {
                                s.offset_m *= scale;
                                (s.width_m, s.height_m) = (s.width_m * scale, s.height_m * scale);
                            }
                            let spread = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                            cloud.centre_m = centre_m + spread * DVec3::new(3e3, 3e3, 8e3);
                            cloud
                        })
                        .collect();
                    let motion = BlockMotion {
                        offset_m: DVec3::new(next(), next(), 0.0) * 800.0,
                        ..BlockMotion::default()
                    };
                    Resident::new(
                        SkyBlock {
                            id,
                            centre_m,
                            clouds,
                        },
                        motion,
                    )
                })
                .collect();
            let far: Vec<&Resident> = blocks.iter().collect();
            let every = (far.iter())
                .flat_map(|r| {
                    let offset_m = r.offset_m();
                    r.seen.iter().map(move |c| {
                        let rel_m = c.centre_m + offset_m - from;
                        cloud_elevations_rad(rel_m, f64::from(c.radius_m))
                    })
                })
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                .map(|(a, b)| (a.to_bits(), b.to_bits()));
            let (low, high) = content_rad(&far, from);
            assert_eq!(Some((low.to_bits(), high.to_bits())), every);
        }
        assert_eq!(content_rad(&[], from), (0.0, 0.0));
    }

    /// A block whose highest (lowest) cloud lies at the edge of its sphere is still read when a
    /// block with a tighter bound was read first and came close: one small cloud swept past the
    /// top cloud of a block reaching up (past the bottom cloud of one reaching down), beside a
    /// block far below (above) that the other walk reads first.
    #[test]
    fn a_tall_block_is_read_past_a_near_miss() {
        let block = |id: u64, heights: &[f64]| {
            let at = |z: f64| DVec3::new(300.0 * id as f64, 40_000.0, z);
            let clouds = (heights.iter())
                .map(|&z| SkyCloud {
                    centre_m: at(z),
                    ..small_cloud()
                })
                .collect();
            let block = SkyBlock {
                id,
                centre_m: at(heights[0]),
                clouds,
            };
            Resident::new(block, BlockMotion::default())
        };
        let (up, down) = (block(0, &[2_000.0, 4_500.0]), block(0, &[2_000.0, -500.0]));
        let (low, high) = (block(2, &[-6_000.0]), block(2, &[10_000.0]));
        for k in 0..400 {
            let rise = 1_500.0 + 2.5 * f64::from(k);
            for (tall, far) in [(&up, &low), (&down, &high)] {
                let z = if std::ptr::eq(tall, &up) {
                    2_000.0 + rise
                } else {
                    2_000.0 - rise
                };
                let small = block(1, &[z]);
                let blocks = [&small, tall, far];
                let every = (blocks.iter())
                    .flat_map(|r| r.seen.iter())
                    .map(|c| cloud_elevations_rad(c.centre_m, f64::from(c.radius_m)))
                    .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
                assert_eq!(Some(content_rad(&blocks, DVec3::ZERO)), every, "at {z} m");
            }
        }
    }

    /// Every cloud's elevations lie within its block's bound, to a picoradian: clouds alone
    /// straight ahead, behind and beside (where the bound is their own), above and below the
    /// eye, near and far, and blocks of several clouds, each drifted.
    #[test]
    fn every_cloud_lies_within_its_blocks_bound() {
        let mut rng = SplitMix64::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.next_f64();
        let from = DVec3::new(-3_000.0, 500.0, 2_500.0);
        let mut checked = 0;
        for k in 0..400 {
            let distance = 5_000.0 + 150_000.0 * next();
            let height = (next() - 0.4) * 20_000.0;
            let (sin, cos) = ((k % 4) as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
            let centre_m = from + DVec3::new(distance * sin, distance * cos, height);
            let clouds = (0..if k % 2 == 0 {
                1
            } else {
                1 + (next() * 6.0) as usize
            })
                .map(|_| {
                    let scale = 0.2 + 20.0 * next() as f32;
                    let mut cloud = small_cloud();
                    for s in &mut cloud.sprites {
                        s.offset_m *= scale;
                        (s.width_m, s.height_m) = (s.width_m * scale, s.height_m * scale);
                    }
                    let spread = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                    cloud.centre_m = centre_m + spread * DVec3::new(4e3, 4e3, 6e3) * (k % 2) as f64;
                    cloud
                })
                .collect();
            let motion = BlockMotion {
                offset_m: DVec3::new(next() - 0.5, next() - 0.5, 0.0) * 3_000.0,
                ..BlockMotion::default()
            };
            let r = Resident::new(
                SkyBlock {
                    id: k,
                    centre_m,
                    clouds,
                },
                motion,
            );
            let (low, high) = block_bound_rad(&r, from);
            for c in &r.seen {
                let rel_m = c.centre_m + r.offset_m() - from;
                let (a, b) = cloud_elevations_rad(rel_m, f64::from(c.radius_m));
                assert!(
                    low <= a + 1e-12 && b <= high + 1e-12,
                    "{a} {b} in {low} {high}"
                );
                checked += 1;
            }
        }
        assert!(checked > 800);
    }
}

//! The living clouds of a [`super::World`]: one field of blocks per drift band
//! ([`crate::clouds::bands`]: each band of layers drifts with the wind at its own height), and
//! for each which of its generations the sky holds, what it was last told of their fades, and
//! what a frame's budget left waiting. Each frame the bands hand the sky what changed of their
//! fields ([`hand_over`]: nearest first across the bands); the block weathers and the far storm
//! cells are the world's once.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3};

use crate::clouds::CloudField;
use crate::clouds::field::FieldBlock;
use crate::clouds::lifecycle::{Phase, phase_at, progress};
use crate::render::scene::{BandOffsets, BlockMotion, Fade, SkyBlock, SkyCloud};
use crate::render::update::SkyUpdate;
use crate::weather::BlockIndex;

use super::block_weathers::BlockWeathers;
use super::far_cells::FarCells;

/// The clouds stage's living fields (background generation, drift, formation and dissipation)
/// as a [`super::World`] flies through them.
pub struct LivingClouds {
    /// One per drift band, the lowest first (it decides the storm cells).
    pub(super) bands: Vec<BandClouds>,
    /// The block weathers, shared by the bands' fields (each asks for the ground under it).
    pub(super) weather: BlockWeathers,
    /// Storm cells beyond the field, drawn whole.
    pub(super) far_cells: FarCells,
}

impl LivingClouds {
    /// The lowest band's field: the one that decides the storm cells.
    pub(super) fn lowest(&self) -> &CloudField {
        &self.bands[0].field
    }
}

/// One drift band's field and which of its generations the sky holds.
pub(super) struct BandClouds {
    pub(super) field: CloudField,
    /// The camera's air block, the drift's block and the field version when the blocks around
    /// were last asked for: asked again only when one changes.
    pub(super) asked: Option<(BlockIndex, BlockIndex, u64)>,
    in_sky: HashSet<u64>,
    seen: HashSet<u64>,
    /// The newest generation met, and the field's membership count then.
    newest_serial: u64,
    /// Generations met that the frames' budget of sprites has not handed to the sky yet
    /// ([`super::WorldSettings::joined_sprites_per_frame`]).
    waiting: HashSet<u64>,
    membership: Option<u64>,
    /// Generations fading in as they arrive (see [`super::WorldSettings::arrival_fade_s`]),
    /// with the field time they arrived at.
    arriving: HashMap<u64, f64>,
    /// Generations forming or dissipating this frame and the last (serial, phase and the step
    /// of the fade the sky was last given, see [`fade_step`]), by serial.
    fading: Vec<(u64, Phase, FadeStep)>,
    was_fading: Vec<(u64, Phase, FadeStep)>,
}

/// A generation new to the sky, found by a band's walk.
struct Candidate {
    /// Its squared distance from the camera's ground point, metres squared.
    d2: f64,
    serial: u64,
    index: BlockIndex,
    /// Its sprites and clouds.
    sprites: u64,
    clouds: u64,
    /// Whether the frame's budget lets it join.
    joins: bool,
}

/// What a band's walk found: the generations its field holds, and those new to the sky,
/// nearest first.
struct Walk {
    count: usize,
    new: Vec<Candidate>,
}

/// Hands the sky what changed of every band's field since the last frame ([`SkyUpdate`]): the
/// generations that came, nearest the camera first across the bands, as many as the frame's
/// budget of sprites (at least one), at each band's drift `offsets_m`; the fades that moved on;
/// the generations that went. Sets `update.expected` when a band's generations changed.
pub(super) fn hand_over(
    bands: &mut [BandClouds],
    offsets_m: &BandOffsets,
    h: &mut HandOver,
    update: &mut SkyUpdate,
) {
    let last = offsets_m.len() - 1;
    let mut walks: Vec<Option<Walk>> = (bands.iter_mut().enumerate())
        .map(|(k, band)| band.walk(offsets_m[k.min(last)], h, update))
        .collect();
    // Nearest first across the bands: an upper layer's block beside the camera does not wait
    // for the lowest one's at the field's rim.
    let mut order: Vec<(f64, u64, usize, usize)> = Vec::new();
    for (k, walk) in walks.iter().enumerate() {
        for (i, c) in walk.iter().flat_map(|w| w.new.iter().enumerate()) {
            order.push((c.d2, c.serial, k, i));
        }
    }
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut any = false;
    for (_, _, k, i) in order {
        let Some(c) = walks[k].as_mut().map(|w| &mut w.new[i]) else {
            continue;
        };
        if any && h.spent + c.sprites > h.budget {
            continue;
        }
        h.spent += c.sprites;
        (c.joins, any) = (true, true);
    }
    for (k, (band, walk)) in bands.iter_mut().zip(walks).enumerate() {
        if let Some(walk) = walk {
            h.walked = true;
            band.join(walk, (offsets_m[k.min(last)], k as u8), h, update);
        }
    }
    // What still waits, so that the sky grows its buffers once for all of it.
    if h.walked {
        update.expected = Some(h.waiting);
    }
}

/// What the bands' hand-overs of a frame share: the world's settings for arrivals and the
/// frame's budget of sprites, and what they left waiting.
pub(super) struct HandOver {
    /// Arrivals fade in over this long (`fade_in`: they do at all).
    pub(super) fade_in_s: f64,
    pub(super) fade_in: bool,
    /// The impostor ring's radius (arrivals beyond it come in with the ring's crossfade).
    pub(super) ring_m: Option<f64>,
    /// The camera's ground point.
    pub(super) ground_m: DVec2,
    /// Sprites handed over a frame at most, and spent so far.
    pub(super) budget: u64,
    pub(super) spent: u64,
    /// Sprites and clouds left waiting by the budget.
    pub(super) waiting: (u64, u64),
    /// Whether any band walked its generations (then `waiting` is the sky's to expect).
    pub(super) walked: bool,
}

impl BandClouds {
    /// A band's field with nothing handed to the sky yet.
    pub(super) fn new(field: CloudField) -> Self {
        Self {
            field,
            asked: None,
            in_sky: HashSet::new(),
            seen: HashSet::new(),
            newest_serial: 0,
            waiting: HashSet::new(),
            membership: None,
            arriving: HashMap::new(),
            fading: Vec::new(),
            was_fading: Vec::new(),
        }
    }

    /// Walks this band's field for what changed since the last frame: adds the fades that moved
    /// on to `update` and returns the generations new to the sky (nearest first) and how many
    /// the field holds; `None` when nothing came or went (then the fades are all there is).
    fn walk(&mut self, offset_m: DVec3, h: &HandOver, update: &mut SkyUpdate) -> Option<Walk> {
        let living = self;
        let now = living.field.time_s();
        // (Generations still waiting to be handed over are looked for every frame.)
        let same_members =
            living.membership == Some(living.field.membership()) && living.waiting.is_empty();
        // Nothing came, went, forms, dissipates or arrives: only the drift changed.
        if same_members && living.was_fading.is_empty() && living.arriving.is_empty() {
            return None;
        }
        // Nothing came or went: only the generations that were fading can be fading now (a
        // steady one starts to dissipate only beside a new one), so only they are looked at,
        // from their phases kept here, not the field's thousands of generations (the Cb
        // circle's building cumulus fade for minutes).
        if same_members && living.arriving.is_empty() {
            living.fading.clear();
            for &(serial, phase, shown) in &living.was_fading {
                // The phase moves on with time alone (as `CloudField::advance` moves it); one
                // that ended (gone) would have changed the membership.
                let phase = phase_at(phase, now);
                let fade = fade_of(phase, None, now);
                // Told only when it has moved on a step: a weather change's thousand forming
                // generations were a thousand look-ups of the sky's blocks every frame.
                let step = fade_step(serial, fade);
                if step != shown {
                    update.fades.push((serial, fade));
                }
                if fade != Fade::Steady {
                    living.fading.push((serial, phase, step));
                }
            }
            std::mem::swap(&mut living.was_fading, &mut living.fading);
            return None;
        }
        living.membership = Some(living.field.membership());
        // Generations are handed over when they appear (serials only grow; those a frame's
        // budget left waiting are in `waiting`) and when they go; per frame only the drift (one
        // value) and the fades of the blocks forming or dissipating change.
        let mut count = 0;
        let newest = living.newest_serial;
        living.fading.clear();
        // Which new generations fade in as they arrive: steady ones (a weather change's form
        // instead) within the impostor ring (beyond it the ring's crossfade brings them in).
        // Flying on, blocks join at the field's rim, beyond the ring: only a sky that had no
        // clouds around (the first frames, a jump) has arrivals to fade.
        let fade_in_s = h.fade_in_s;
        let (ground_m, drift) = (h.ground_m, offset_m.truncate());
        // The new generations, nearest first after the walk.
        let mut new: Vec<Candidate> = Vec::new();
        for (index, fb) in living.field.blocks() {
            count += 1;
            let is_new = fb.serial > newest
                || (!living.waiting.is_empty() && living.waiting.contains(&fb.serial));
            if is_new {
                let d2 = (index.centre_m() + drift).distance_squared(ground_m);
                new.push(Candidate {
                    d2,
                    serial: fb.serial,
                    index,
                    sprites: fb.block.clouds.iter().map(|c| c.sprites.len() as u64).sum(),
                    clouds: fb.block.clouds.len() as u64,
                    joins: false,
                });
                living.newest_serial = living.newest_serial.max(fb.serial);
            }
            // Arrivals are few and brief (the first frames, a jump): with none, the field's
            // thousands of blocks cost no lookup each a frame.
            let arrival = (!living.arriving.is_empty())
                .then(|| living.arriving.get(&fb.serial))
                .flatten()
                .map(|&since| ((now - since) / fade_in_s) as f32)
                .filter(|&p| p < 1.0);
            if arrival.is_none() && !living.arriving.is_empty() {
                living.arriving.remove(&fb.serial);
            }
            let fade = fade_of(fb.phase, arrival, now);
            if fade != Fade::Steady {
                let step = fade_step(fb.serial, fade);
                // Told only when it has moved on a step since the last frame, as when nothing
                // came or went (`was_fading` is sorted by serial): a block crossing hands over a
                // few generations, not the thousand that form after a weather change.
                let shown = (living.was_fading)
                    .binary_search_by_key(&fb.serial, |f| f.0)
                    .ok()
                    .map(|k| living.was_fading[k].2);
                if !is_new && shown != Some(step) {
                    update.fades.push((fb.serial, fade));
                }
                living.fading.push((fb.serial, fb.phase, step));
            }
        }
        new.sort_unstable_by(|a, b| a.d2.total_cmp(&b.d2).then(a.serial.cmp(&b.serial)));
        Some(Walk { count, new })
    }

    /// Hands the sky the generations of `walk` that the frame's budget let join (at the band's
    /// drift `offset_m` as band `drift_band`), keeps the rest waiting, and adds the fades that
    /// ended and the generations that went to `update`.
    fn join(
        &mut self,
        walk: Walk,
        (offset_m, drift_band): (DVec3, u8),
        h: &mut HandOver,
        update: &mut SkyUpdate,
    ) {
        let living = self;
        let now = living.field.time_s();
        let (fade_in, ring_m) = (h.fade_in, h.ring_m);
        let count = walk.count;
        let joined = &mut update.came;
        for c in &walk.new {
            let serial = c.serial;
            let Some(fb) = living
                .field
                .generations(c.index)
                .iter()
                .find(|g| g.serial == serial)
            else {
                continue;
            };
            if !c.joins {
                living.waiting.insert(serial);
                h.waiting.0 += c.sprites;
                h.waiting.1 += c.clouds;
                continue;
            }
            living.waiting.remove(&serial);
            let arrives =
                fade_in && fb.phase == Phase::Steady && ring_m.is_none_or(|r| c.d2 <= r * r);
            let arrival = arrives.then(|| {
                living.arriving.insert(serial, now);
                0.0
            });
            let fade = fade_of(fb.phase, arrival, now);
            if arrives {
                // Its fade, kept with the others' (it was steady in the walk).
                let step = fade_step(serial, fade);
                living.fading.push((serial, fb.phase, step));
            }
            living.in_sky.insert(serial);
            joined.push((
                living_block(c.index, fb),
                BlockMotion {
                    offset_m,
                    fade,
                    drift_band,
                },
            ));
        }
        // The ones that finished forming since the last frame (told after the new ones come,
        // which they may be).
        living.fading.sort_unstable_by_key(|f| f.0);
        for &(id, _, _) in &living.was_fading {
            if living.fading.binary_search_by_key(&id, |f| f.0).is_err() {
                update.fades.push((id, Fade::Steady));
            }
        }
        std::mem::swap(&mut living.was_fading, &mut living.fading);
        // Every block of the field is in the sky or waits; more there means some went.
        if living.in_sky.len() + living.waiting.len() != count {
            living.seen.clear();
            living
                .seen
                .extend(living.field.blocks().map(|(_, fb)| fb.serial));
            let gone: Vec<u64> = living.in_sky.difference(&living.seen).copied().collect();
            for id in &gone {
                living.in_sky.remove(id);
                living.arriving.remove(id);
            }
            let seen = &living.seen;
            living.waiting.retain(|id| seen.contains(id));
            update.went.extend(gone);
        }
    }
}

/// A living generation as the sky's block: its id is the generation's serial, its clouds where
/// they were generated (the drift is the block's motion).
fn living_block(index: BlockIndex, fb: &FieldBlock) -> SkyBlock {
    let clouds: Vec<SkyCloud> = fb.block.clouds.iter().map(SkyCloud::from).collect();
    let c = index.centre_m();
    let mean_z = clouds.iter().map(|c| c.centre_m.z).sum::<f64>() / clouds.len().max(1) as f64;
    SkyBlock {
        id: fb.serial,
        centre_m: DVec3::new(c.x, c.y, mean_z),
        clouds,
    }
}

/// Steps of a fade's progress (0 to 1) that the sky is told of. A step is 1/1024 of a
/// formation (0.6 s of the shipped 10 minutes): its change of opacity is a quarter of what an
/// 8-bit colour can show.
pub(super) const FADE_STEPS: f64 = 1024.0;

/// A fade's kind (0 steady, 1 forming, 2 dissipating) and which of its [`FADE_STEPS`] its
/// progress is at.
pub(super) type FadeStep = (u8, i64);

/// The step of `fade` for generation `serial`. The steps of each generation are shifted by a
/// fraction of a step of its own (from its serial), so that generations that began to fade
/// together (every block around after a weather change) do not all step in the same frame.
pub(super) fn fade_step(serial: u64, fade: Fade) -> FadeStep {
    let shift = (serial.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11) as f64 / (1u64 << 53) as f64;
    let at = |p: f32| (f64::from(p) * FADE_STEPS + shift).floor() as i64;
    match fade {
        Fade::Steady => (0, 0),
        Fade::Forming(p) => (1, at(p)),
        Fade::Dissipating(p) => (2, at(p)),
    }
}

/// How a generation in `phase` is drawn at field time `now_s`: forming, dissipating or steady,
/// or fading in by `arrival` (0..1) as it arrives.
pub(super) fn fade_of(phase: Phase, arrival: Option<f32>, now_s: f64) -> Fade {
    match phase {
        Phase::Steady => arrival.map_or(Fade::Steady, Fade::Forming),
        Phase::Forming { .. } | Phase::Unforming { .. } => Fade::Forming(progress(phase, now_s)),
        Phase::Dissipating { .. } => Fade::Dissipating(progress(phase, now_s)),
        Phase::Gone => Fade::Dissipating(1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How opaque a block with `fade` is drawn as a whole (the renderer's own measure).
    fn opacity(fade: Fade) -> f32 {
        match fade {
            Fade::Steady => 1.0,
            Fade::Forming(p) => p,
            Fade::Dissipating(q) => 1.0 - q,
        }
    }

    /// A formation of 10 minutes seen at 60 frames a second: the fade the sky holds is never
    /// more than a step behind the field's, and it is told about once a step, not every frame.
    #[test]
    fn a_fade_is_handed_over_a_step_at_a_time_and_never_lags_a_step() {
        let lifecycle = crate::clouds::config::CloudsConfig::builtin().lifecycle;
        let phase = Phase::forming(0.0, &lifecycle);
        let frames = (f64::from(lifecycle.formation_s) * 60.0) as usize;
        let (mut told, mut shown, mut shown_step) = (0, Fade::Forming(0.0), (9, 0));
        for k in 0..=frames {
            let now = k as f64 / 60.0;
            let fade = fade_of(phase_at(phase, now), None, now);
            let step = fade_step(7, fade);
            if step != shown_step {
                (told, shown, shown_step) = (told + 1, fade, step);
            }
            let behind = opacity(fade) - opacity(shown);
            assert!(
                (0.0..=1.0 / FADE_STEPS as f32 + 1e-6).contains(&behind),
                "frame {k}: {behind}"
            );
        }
        assert_eq!(shown, Fade::Steady);
        assert!((1024..=1026).contains(&told), "{told} of {frames} frames");
    }

    /// A thousand generations that begin to form in the same frame (a weather change) step in
    /// different frames: no frame tells the sky of much more than its share.
    #[test]
    fn generations_that_fade_together_step_in_different_frames() {
        let lifecycle = crate::clouds::config::CloudsConfig::builtin().lifecycle;
        let phase = Phase::forming(0.0, &lifecycle);
        let serials: Vec<u64> = (1000..2000).collect();
        let mut last: Vec<FadeStep> = serials
            .iter()
            .map(|&s| fade_step(s, Fade::Forming(0.0)))
            .collect();
        // 10 frames a second: about 10 steps of 1,024 per 6 s, 0.17 a frame for each generation.
        let (mut most, mut all) = (0, 0);
        for k in 1..=600 {
            let now = k as f64 / 10.0;
            let fade = fade_of(phase_at(phase, now), None, now);
            let mut told = 0;
            for (s, l) in serials.iter().zip(&mut last) {
                let step = fade_step(*s, fade);
                told += (step != *l) as usize;
                *l = step;
            }
            (most, all) = (most.max(told), all + told);
        }
        let share = all as f64 / 600.0;
        assert!((100.0..250.0).contains(&share), "{share} a frame");
        assert!(
            (most as f64) < 2.0 * share,
            "{most} in one frame, {share} a frame on average"
        );
    }
}

//! The far clouds' sprite orders from the ring centre (Wang 2003 section 6.1's cache, applied to
//! the impostors), kept by cloud between builds and written, at the clouds' sprite slots, into
//! one order buffer of the ring's own: as the sky camera's orders are kept in the resident order
//! buffer. A cloud's order is written when it is sorted (within the frame's sorting budget), so
//! an impostor's view is its draw list and cloud lists only: no frame copies the tens of
//! thousands of far sprites' orders, whatever the ring holds.
//!
//! The buffer is mirrored on the CPU (`slots`), for the whole writes a grown buffer and a pile
//! of unrecorded patches need. Each cloud's order remembers which placing of its block it was
//! written at ([`Resident::place_serial`]): a block placed again since (the resident buffers
//! packed, or taken off the GPU and put back) has its clouds' orders written again by the next
//! view, once. Nothing else writes the ring's slots, and the resident set never gives two placed
//! blocks the same slots, so an order written at its block's present placing is still there.
//!
//! In: the resident blocks, the ring centre, the sky time. Out: the orders (as the slots' CPU
//! copy and the spans changed), draw lists and cloud lists. No wgpu calls.

use std::ops::Range;

use glam::DVec3;

use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud};
use crate::render::id_hash::IdMap;
use crate::render::scene::Fade;
use crate::render::sprites::draw_list::{
    Blocks, SortKeys, blocks_back_to_front, fade_code, order_into, used_up,
};
#[cfg(doc)]
use crate::render::sprites::resident::Resident;
use crate::render::sprites::settings::VertexCacheSettings;

/// The far clouds' sprite orders as the impostor ring sees them (from its centre), kept from
/// one ring build to the next and sorted a budget at a time: Wang's vertex cache for the ring's
/// views. An impostor is rendered only once every cloud of its sector has an order that is good
/// for its centre; until then each frame sorts what the frame's sorting budget has left after
/// the sky camera's clouds (`[vertex_cache] max_sorted_sprites_per_frame` holds on the frames
/// that rebuild the ring too). A rebuild that finds the camera near where the last one was (the
/// far blocks changed at the rim, the sun turned) takes most orders from here.
#[derive(Debug, Default)]
pub(crate) struct RingOrders {
    /// By block id, then cloud index: one lookup a block, its clouds' orders side by side
    /// (a lookup by block and cloud, with tens of thousands of far clouds, was most of a
    /// gathering frame's time).
    kept: IdMap<Vec<Option<RingOrder>>>,
    keys: SortKeys,
    /// The gather under way ([`RingSort::gather`]) and its clouds still to sort (block id,
    /// cloud index): found once, when it starts, so that its later frames look at nothing else.
    gather: Option<u64>,
    todo: Vec<(u64, usize)>,
    /// Scratch for the clouds a frame leaves to the next.
    left: Vec<(u64, usize)>,
    /// The CPU copy of the ring's order buffer: at each cloud's sprite slots, its sprites' slots
    /// back to front from the ring centre.
    slots: Vec<u32>,
    /// The spans of `slots` written since the last [`Self::take_dirty`].
    dirty: Vec<Range<u32>>,
    /// Sprite orders written by views (blocks placed again since, clouds too large to sort)
    /// since the last [`Self::take_dirty`].
    rewritten: u32,
}

/// One cloud's order seen from a ring centre.
#[derive(Debug)]
struct RingOrder {
    /// The centre relative to the cloud, and the sky time, when it was computed.
    from_rel_m: DVec3,
    at_s: f64,
    /// Its sprites' indices within the cloud, farthest from the centre first (empty for a cloud
    /// never sorted: too large, in its sprites' own order).
    order: Vec<u32>,
    /// The placing of its block ([`Resident::place_serial`]) it was last written at.
    written: Option<u64>,
}

/// When a ring build started and what it may sort this frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RingSort<'a> {
    /// Which impostor of which build is being gathered (a new value starts a new gather).
    pub gather: u64,
    /// Sky time when the build started: orders computed since are good for it, older ones as
    /// long as Wang's thresholds (judged then) hold.
    pub since_s: f64,
    /// Sky time now.
    pub time_s: f64,
    pub cache: &'a VertexCacheSettings,
    /// A cloud with more sprites than this is never sorted for the ring (no frame could afford
    /// it): it goes in in its sprites' own order, as the sky camera draws it until its first sort.
    pub largest: u32,
}

impl RingOrders {
    /// Forgets the orders of blocks the sky no longer holds.
    pub fn retain(&mut self, blocks: &Blocks) {
        self.kept.retain(|id, _| blocks.contains_key(id));
    }

    /// Makes the slots' copy as long as the resident sprite slots (`slots`), keeping what it
    /// holds; true if it grew (the GPU buffer is then made again and written whole).
    pub fn fit(&mut self, slots: u32) -> bool {
        if self.slots.len() >= slots as usize {
            return false;
        }
        self.slots.resize(slots as usize, 0);
        true
    }

    /// The CPU copy of the order buffer.
    pub fn slots(&self) -> &[u32] {
        &self.slots
    }

    /// The spans of [`Self::slots`] written since the last call, and the sprite orders views
    /// wrote again since (blocks placed again, clouds too large to sort).
    pub fn take_dirty(&mut self, into: &mut Vec<Range<u32>>) -> u32 {
        into.append(&mut self.dirty);
        std::mem::take(&mut self.rewritten)
    }

    /// Sorts, from `from_m`, the clouds of blocks `ids` within `draw_m` whose order is missing
    /// or stale, while `budget` (sprites) lasts, taking what it sorts from it, and writes each
    /// at its cloud's slots. Which clouds those are is found on the first call of a gather;
    /// later calls of it sort what is left. Returns whether every such cloud now has a good
    /// order, and the sprites sorted.
    pub fn sort(
        &mut self,
        blocks: &Blocks,
        ids: &[u64],
        (from_m, draw_m): (DVec3, f64),
        when: &RingSort,
        budget: &mut u32,
    ) -> (bool, u32) {
        if self.gather != Some(when.gather) {
            self.gather = Some(when.gather);
            self.find_todo(blocks, ids, (from_m, draw_m), when);
        }
        let mut sorted = 0u32;
        let mut left = std::mem::take(&mut self.left);
        left.clear();
        let mut todo = std::mem::take(&mut self.todo);
        for (id, ci) in todo.drain(..) {
            if *budget == 0 {
                left.push((id, ci));
                continue;
            }
            // A block gone since (or off the GPU) is not in the view either.
            let Some(r) = blocks.get(&id).filter(|r| r.place.is_some()) else {
                continue;
            };
            let (Some(state), Some(cloud)) = (r.clouds.get(ci), r.block.clouds.get(ci)) else {
                continue;
            };
            if state.sprites > *budget {
                left.push((id, ci));
                continue;
            }
            *budget -= state.sprites;
            sorted += state.sprites;
            let rel = from_m - (state.centre_m + r.offset_m());
            // A kept order's buffer is sorted into again.
            let block = self.kept.entry(id).or_default();
            if block.len() < r.clouds.len() {
                block.resize_with(r.clouds.len(), || None);
            }
            let kept = block[ci].get_or_insert_with(|| RingOrder {
                from_rel_m: rel,
                at_s: when.time_s,
                order: Vec::new(),
                written: None,
            });
            kept.order.resize(cloud.sprites.len(), 0);
            order_into(
                r.offsets_of(ci),
                rel.as_vec3(),
                0,
                &mut kept.order,
                &mut self.keys,
            );
            (kept.from_rel_m, kept.at_s) = (rel, when.time_s);
            let at = (state.sprite_base, state.sprites, r.place_serial);
            self.write((id, ci, r.clouds.len()), at);
        }
        // What is left, kept in `left`'s place for the next frame (no allocation a frame).
        self.left = std::mem::replace(&mut todo, left);
        self.todo = todo;
        (self.todo.is_empty(), sorted)
    }

    /// The clouds of blocks `ids` within `draw_m` of `from_m` that a gather must sort: no order
    /// kept, or one neither sorted since the build started nor within Wang's thresholds.
    fn find_todo(
        &mut self,
        blocks: &Blocks,
        ids: &[u64],
        (from_m, draw_m): (DVec3, f64),
        when: &RingSort,
    ) {
        self.todo.clear();
        for id in ids {
            let Some(r) = blocks.get(id).filter(|r| r.place.is_some()) else {
                continue;
            };
            let fading = r.fade() != Fade::Steady;
            let kept = self.kept.get(id).map_or(&[][..], Vec::as_slice);
            for (ci, (state, cloud)) in r.clouds.iter().zip(&r.block.clouds).enumerate() {
                let rel = from_m - (state.centre_m + r.offset_m());
                let near_edge = (rel.length() - state.radius_m as f64).max(0.0);
                if near_edge > draw_m || state.sprites == 0 || state.sprites > when.largest {
                    continue;
                }
                let good = kept.get(ci).and_then(Option::as_ref).is_some_and(|o| {
                    o.order.len() == cloud.sprites.len()
                        && (o.at_s >= when.since_s
                            || (when.cache.enabled
                                && !used_up(
                                    ((o.from_rel_m, o.at_s), fading),
                                    rel,
                                    when.since_s,
                                    near_edge,
                                    when.cache,
                                    1.0,
                                )))
                });
                if !good {
                    self.todo.push((*id, ci));
                }
            }
        }
    }

    /// Writes cloud `cloud` of block `block` (of `clouds`)'s kept order (its sprites' own
    /// order if none fits) at slots `base..base + sprites`, and remembers that it did at
    /// placing `place`.
    fn write(&mut self, (block, cloud, clouds): (u64, usize, usize), at: (u32, u32, u64)) {
        let (base, sprites, place) = at;
        let end = base + sprites;
        let Some(span) = self.slots.get_mut(base as usize..end as usize) else {
            // Slots beyond the copy: `fit` was not called for the resident buffers' size.
            return;
        };
        let kept = self.kept.entry(block).or_default();
        if kept.len() < clouds {
            kept.resize_with(clouds, || None);
        }
        let kept = kept[cloud].get_or_insert_with(|| RingOrder {
            from_rel_m: DVec3::ZERO,
            at_s: f64::NEG_INFINITY,
            order: Vec::new(),
            written: None,
        });
        if kept.order.len() == sprites as usize {
            span.iter_mut()
                .zip(&kept.order)
                .for_each(|(slot, &i)| *slot = base + i);
        } else {
            span.iter_mut().zip(base..).for_each(|(slot, i)| *slot = i);
        }
        kept.written = Some(place);
        // Clouds are written in slot order by a sort and, back to front, in reverse by a view.
        match self.dirty.last_mut() {
            Some(last) if last.end == base => last.end = end,
            Some(last) if last.start == end => last.start = base,
            _ => self.dirty.push(base..end),
        }
    }

    /// An impostor's view from `from_m` (no locks), once [`Self::sort`] is done for it: the
    /// draw list of the blocks `ids` within `draw_m`, back to front, and each block's cloud
    /// list into `lists`, pointing at the clouds' orders in the order buffer. A cloud whose
    /// order is not at its slots (moved, or too large to sort) is written there first. Returns
    /// the sprites.
    pub fn view(
        &mut self,
        blocks: &Blocks,
        ids: &[u64],
        (from_m, draw_m): (DVec3, f64),
        out: &mut Vec<GpuDrawBlock>,
        lists: &mut Vec<GpuListCloud>,
    ) -> u32 {
        out.clear();
        lists.clear();
        let mut total = 0u32;
        let mut cloud_order: Vec<(usize, f64)> = Vec::new();
        let mut stale: Vec<usize> = Vec::new();
        for (_, id) in blocks_back_to_front(blocks, ids, from_m) {
            let Some(r) = blocks.get(&id) else {
                continue;
            };
            let offset = r.offset_m();
            cloud_order.clear();
            for (ci, state) in r.clouds.iter().enumerate() {
                let d = (state.centre_m + offset - from_m).length();
                if (d - state.radius_m as f64).max(0.0) <= draw_m && state.sprites > 0 {
                    cloud_order.push((ci, d));
                }
            }
            cloud_order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            let list_base = lists.len() as u32;
            // The clouds whose orders are not at their slots (one look-up a block).
            let kept = self.kept.get(&id).map_or(&[][..], Vec::as_slice);
            let written = |ci: usize| kept.get(ci)?.as_ref()?.written;
            stale.clear();
            stale.extend(
                (cloud_order.iter())
                    .map(|c| c.0)
                    .filter(|&ci| written(ci) != Some(r.place_serial)),
            );
            for &ci in &stale {
                let state = &r.clouds[ci];
                let at = (state.sprite_base, state.sprites, r.place_serial);
                self.write((id, ci, r.clouds.len()), at);
                self.rewritten += state.sprites;
            }
            let mut first = 0u32;
            for &(ci, _) in &cloud_order {
                let state = &r.clouds[ci];
                let (base, sprites) = (state.sprite_base, state.sprites);
                lists.push(GpuListCloud {
                    cloud: state.cloud_slot,
                    first,
                    order_base: base,
                    stride: 0,
                });
                first += sprites;
            }
            let (fade_kind, fade_progress) = fade_code(r.fade());
            out.push(GpuDrawBlock {
                origin_rel: (r.centre_m() - from_m).as_vec3().to_array(),
                first: total,
                list_base,
                list_len: cloud_order.len() as u32,
                fade_kind,
                fade_progress,
            });
            total += first;
        }
        total
    }
}

#[cfg(test)]
#[path = "orders_tests.rs"]
mod tests;

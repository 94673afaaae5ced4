//! Ranges of slots in a GPU buffer: blocks of sprites (and of clouds) take a contiguous range
//! when they arrive and give it back when they go, so a block is written once by the CPU.
//! First fit over a sorted free list, with neighbours merged on release: the field brings and
//! retires a few blocks at a time, so the list stays short. When a block finds no range long
//! enough, the blocks held are packed at the same capacity when the slots free are enough in
//! all ([`pack`]: the device moves them, see `resident`), and kept where they are in a larger
//! buffer only when they are not ([`SlotRanges::capacity_for`]), so the capacity follows the
//! most slots ever held at once and never how the free ones happen to be cut up.

use std::ops::Range;

/// A first-fit allocator of `u32` slot ranges within a capacity.
#[derive(Debug, Clone, Default)]
pub struct SlotRanges {
    capacity: u32,
    /// Free ranges, sorted by start, never touching each other.
    free: Vec<Range<u32>>,
}

impl SlotRanges {
    /// All of `capacity` free.
    pub fn new(capacity: u32) -> Self {
        Self {
            capacity,
            free: (capacity > 0).then_some(0..capacity).into_iter().collect(),
        }
    }

    /// Slots in all.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Slots in use.
    pub fn used(&self) -> u32 {
        self.capacity - self.free.iter().map(|r| r.end - r.start).sum::<u32>()
    }

    /// Whether a range of `len` slots is free.
    pub fn fits(&self, len: u32) -> bool {
        len == 0 || self.free.iter().any(|r| r.end - r.start >= len)
    }

    /// The capacity to place every block again in when `len` more slots find no free range:
    /// the same one when the free slots are enough in all (packing them makes one range), else
    /// the slots held and a sixteenth more (room for the next few blocks without another
    /// move), rounded up to a multiple of `step`.
    pub fn capacity_for(&self, len: u32, step: u32) -> u32 {
        let need = self.used() as u64 + len as u64;
        if need <= self.capacity as u64 {
            return self.capacity;
        }
        let step = step.max(1) as u64;
        let want = (need * 17 / 16).div_ceil(step) * step;
        want.min(u32::MAX as u64) as u32
    }

    /// Adds the slots from today's capacity up to `capacity` (no less than today's) as free,
    /// every range in use staying where it is.
    pub fn extend_to(&mut self, capacity: u32) {
        if capacity <= self.capacity {
            return;
        }
        match self.free.last_mut() {
            Some(last) if last.end == self.capacity => last.end = capacity,
            _ => self.free.push(self.capacity..capacity),
        }
        self.capacity = capacity;
    }

    /// A range of `len` slots, if one is free (`len` 0 gives an empty range).
    pub fn allocate(&mut self, len: u32) -> Option<Range<u32>> {
        if len == 0 {
            return Some(0..0);
        }
        let i = self.free.iter().position(|r| r.end - r.start >= len)?;
        let start = self.free[i].start;
        self.free[i].start += len;
        if self.free[i].is_empty() {
            self.free.remove(i);
        }
        Some(start..start + len)
    }

    /// Gives `range` back (it must have come from [`Self::allocate`]).
    pub fn release(&mut self, range: Range<u32>) {
        if range.is_empty() {
            return;
        }
        let i = self.free.partition_point(|r| r.start < range.start);
        self.free.insert(i, range);
        // Merge with the next, then with the previous.
        if i + 1 < self.free.len() && self.free[i].end == self.free[i + 1].start {
            let next = self.free.remove(i + 1);
            self.free[i].end = next.end;
        }
        if i > 0 && self.free[i - 1].end == self.free[i].start {
            let this = self.free.remove(i);
            self.free[i - 1].end = this.end;
        }
    }
}

/// The ranges `held` (disjoint, within `capacity`) packed at the start of the slots, one after
/// the other in the order they lie in: their new ranges (in the order of `held`) and the slots
/// with them in use, the rest in one free range. Ranges keep their order, so those before the
/// first gap stay where they are and neighbours stay neighbours ([`copy_runs`]).
pub fn pack(capacity: u32, held: &[Range<u32>]) -> (SlotRanges, Vec<Range<u32>>) {
    let mut by_start: Vec<usize> = (0..held.len()).collect();
    by_start.sort_by_key(|&i| held[i].start);
    let mut packed = vec![0..0; held.len()];
    let mut next = 0u32;
    for i in by_start {
        let len = held[i].end - held[i].start;
        // An empty range is where `allocate` puts one (nothing is moved for it).
        if len > 0 {
            packed[i] = next..next + len;
            next += len;
        }
    }
    debug_assert!(next <= capacity, "{next} slots held in {capacity}");
    let slots = SlotRanges {
        capacity,
        free: (next < capacity)
            .then_some(next..capacity)
            .into_iter()
            .collect(),
    };
    (slots, packed)
}

/// The copies that move each range `from` to start at `to` (as [`pack`] gives them), as
/// `(source, destination, length)` in slots: ranges next to each other before and after are
/// one copy, empty ones none.
pub fn copy_runs(moves: impl IntoIterator<Item = (Range<u32>, u32)>) -> Vec<(u32, u32, u32)> {
    let mut moves: Vec<(Range<u32>, u32)> = moves.into_iter().filter(|m| !m.0.is_empty()).collect();
    moves.sort_by_key(|m| m.0.start);
    let mut runs: Vec<(u32, u32, u32)> = Vec::new();
    for (from, to) in moves {
        let len = from.end - from.start;
        match runs.last_mut() {
            Some(run) if run.0 + run.2 == from.start && run.1 + run.2 == to => run.2 += len,
            _ => runs.push((from.start, to, len)),
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packing moves the ranges held to the start in the order they lay in (the first stays,
    /// the others close the gaps), leaves the rest as one free range, and the copies that do it
    /// join neighbours: a range held between two gaps is a copy of its own.
    #[test]
    fn packing_closes_the_gaps_in_order_with_one_copy_a_run() {
        let mut s = SlotRanges::new(100);
        let held: Vec<_> = [10, 20, 5, 15, 30]
            .iter()
            .map(|&n| s.allocate(n).unwrap())
            .collect();
        // Gaps at 10..30 and 35..50; 0..10 and 30..35 stay, 50..80 moves as it is.
        s.release(held[1].clone());
        s.release(held[3].clone());
        assert!(!s.fits(40));
        let kept = [held[4].clone(), held[0].clone(), 0..0, held[2].clone()];
        let (packed, to) = pack(s.capacity(), &kept);
        assert_eq!(to, vec![15..45, 0..10, 0..0, 10..15]);
        assert_eq!((packed.capacity(), packed.used()), (100, 45));
        assert!(packed.fits(55) && !packed.fits(56));
        let moves = kept.iter().cloned().zip(to.iter().map(|r| r.start));
        assert_eq!(
            copy_runs(moves),
            vec![(0, 0, 10), (30, 10, 5), (50, 15, 30)]
        );
        // Nothing cut up: one copy of everything, to where it was.
        let whole = [0..10, 10..40];
        let (_, to) = pack(50, &whole);
        assert_eq!(to, whole.to_vec());
        let moves = whole.iter().cloned().zip(to.iter().map(|r| r.start));
        assert_eq!(copy_runs(moves), vec![(0, 0, 40)]);
        // Full: no free range left.
        let (full, _) = pack(40, &whole);
        assert!(!full.fits(1) && full.fits(0));
    }

    #[test]
    fn extending_keeps_the_ranges_in_use_and_frees_the_new_slots() {
        let mut s = SlotRanges::new(10);
        let a = s.allocate(6).unwrap();
        let b = s.allocate(4).unwrap();
        assert!(!s.fits(1));
        s.extend_to(16);
        assert_eq!((s.capacity(), s.used()), (16, 10));
        assert_eq!(s.allocate(6), Some(10..16));
        // A free range at the old end merges with the new slots.
        s.release(b.clone());
        s.release(10..16);
        s.extend_to(20);
        assert_eq!(s.allocate(10), Some(6..16));
        s.extend_to(5); // never shrinks
        assert_eq!(s.capacity(), 20);
        assert_eq!(a, 0..6);
    }

    #[test]
    fn ranges_are_disjoint_reused_and_merged() {
        let mut s = SlotRanges::new(100);
        let a = s.allocate(30).unwrap();
        let b = s.allocate(30).unwrap();
        let c = s.allocate(30).unwrap();
        assert_eq!((a.clone(), b.clone(), c.clone()), (0..30, 30..60, 60..90));
        assert_eq!(s.allocate(11), None, "only 10 left");
        assert!(s.fits(10) && !s.fits(11));
        assert_eq!(s.used(), 90);
        s.release(b);
        // A 30-slot hole: a 20 fits in it, first fit.
        assert_eq!(s.allocate(20), Some(30..50));
        s.release(a);
        s.release(30..50);
        // 0..60 merged back into one range: 60 fit at the start.
        assert_eq!(s.allocate(60), Some(0..60));
        s.release(c);
        s.release(0..60);
        assert_eq!(s.used(), 0);
        assert_eq!(s.allocate(100), Some(0..100));
        // Full, then the last range back: it goes after every free range (there are none).
        s.release(0..100);
        let (x, y) = (s.allocate(60).unwrap(), s.allocate(40).unwrap());
        s.release(y);
        assert_eq!((s.used(), s.allocate(40)), (60, Some(60..100)));
        s.release(60..100);
        s.release(x);
        assert_eq!(s.allocate(100), Some(0..100));
        // Growing keeps at least the old size (`resident`): the capacity is the slots in all,
        // used or not.
        assert_eq!((s.capacity(), SlotRanges::new(0).capacity()), (100, 0));
    }

    #[test]
    fn slots_free_in_pieces_are_packed_at_the_same_capacity() {
        // 256 cloud slots cut into pieces of 16: 128 free in all, no range of 20.
        let mut s = SlotRanges::new(256);
        let held: Vec<_> = (0..16).map(|_| s.allocate(16).unwrap()).collect();
        for r in held.into_iter().step_by(2) {
            s.release(r);
        }
        assert_eq!((s.used(), s.fits(20)), (128, false));
        // Packed, 20 more fit in the same 256 (the cloud buffers jumped to 4,096 slots here,
        // 553 KB, two hours into the soak).
        assert_eq!(s.capacity_for(20, 256), 256);
        assert_eq!(s.capacity_for(128, 256), 256);
        // One more than the capacity: what is held and a sixteenth, rounded up to the step.
        assert_eq!(s.capacity_for(129, 256), 512);
        assert_eq!(s.capacity_for(129, 1), 273);
        assert_eq!(SlotRanges::new(12_288).capacity_for(12_522, 4096), 16_384);
        assert_eq!(SlotRanges::new(0).capacity_for(0, 4096), 0);
    }
}

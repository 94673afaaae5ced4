//! Ranges of slots in a GPU buffer: blocks of sprites (and of clouds) take a contiguous range
//! when they arrive and give it back when they go, so a block is written once and never moved.
//! First fit over a sorted free list, with neighbours merged on release: the field brings and
//! retires a few blocks at a time, so the list stays short. A full buffer is replaced by one
//! twice the size and every block placed again (see `resident`).

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

#[cfg(test)]
mod tests {
    use super::*;

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
}

//! Maps and sets keyed by block ids, which the sky looks up for every block (and the ring for
//! every far cloud) every frame: one multiply (Fibonacci hashing) instead of SipHash, whose
//! protection against chosen keys the sky's own ids do not need.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A map keyed by block id.
pub(crate) type IdMap<V> = HashMap<u64, V, BuildHasherDefault<IdHasher>>;

/// A set of block ids.
pub(crate) type IdSet = HashSet<u64, BuildHasherDefault<IdHasher>>;

/// The hasher of [`IdMap`] and [`IdSet`].
#[derive(Default)]
pub(crate) struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        }
    }

    fn write_u64(&mut self, id: u64) {
        self.0 = (self.0 ^ id).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_keep_their_entries() {
        // Neighbouring and far-apart ids (blocks are keyed by packed grid coordinates).
        let ids: Vec<u64> = (0..2_000u64).map(|i| i * 0x1_0000_0001 + 7).collect();
        let map: IdMap<u64> = ids.iter().map(|&id| (id, id ^ 5)).collect();
        assert_eq!(map.len(), ids.len());
        assert!(ids.iter().all(|id| map[id] == id ^ 5));
        assert!(!map.contains_key(&3));
    }
}

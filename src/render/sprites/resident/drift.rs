//! The drift bands' offsets, shared by a [`super::ResidentSet`] and every block it holds: a
//! block reads its band's offset where it is used, so the sky moves every band with one write a
//! frame. Writing each resident block's offset every frame (thousands of blocks, the ring's
//! included, a cache miss each) was a tenth of the sky's update on the shipped flights.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use crate::render::scene::BandOffsets;

/// Each band's offset as the bits of its three `f64`s, and how many times they were set.
/// Atomics only so that the sky stays `Send` and `Sync`: one thread writes and reads them.
#[derive(Debug, Default)]
struct Bands {
    offsets: [[AtomicU64; 3]; crate::clouds::config::MAX_DRIFT_BANDS as usize],
    settings: AtomicU64,
}

/// A handle on the set's drift bands ([`Self::clone`] shares them).
#[derive(Debug, Clone, Default)]
pub(in crate::render) struct SharedDrift(Arc<Bands>);

impl SharedDrift {
    /// Moves every band to `offsets_m`: every block that follows its band is moved.
    pub fn set(&self, offsets_m: &BandOffsets) {
        for (band, offset) in self.0.offsets.iter().zip(offsets_m) {
            for (bits, v) in band.iter().zip(offset.to_array()) {
                bits.store(v.to_bits(), Ordering::Relaxed);
            }
        }
        self.0.settings.fetch_add(1, Ordering::Relaxed);
    }

    /// How many times the bands were set: a block given an offset of its own after the last
    /// setting keeps it until the next.
    pub fn settings(&self) -> u64 {
        self.0.settings.load(Ordering::Relaxed)
    }

    /// Band `band`'s offset (the last band's for a band past the last).
    pub fn offset_m(&self, band: u8) -> DVec3 {
        let bands = &self.0.offsets;
        read(&bands[usize::from(band).min(bands.len() - 1)])
    }

    /// Every band's offset.
    pub fn offsets_m(&self) -> BandOffsets {
        self.0.offsets.each_ref().map(read)
    }
}

/// An offset from the bits of its three `f64`s.
fn read(bits: &[AtomicU64; 3]) -> DVec3 {
    let [x, y, z] = bits
        .each_ref()
        .map(|b| f64::from_bits(b.load(Ordering::Relaxed)));
    DVec3::new(x, y, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_band_reads_what_was_set_last_and_a_band_past_the_last_reads_the_last() {
        let drift = SharedDrift::default();
        let held = drift.clone();
        assert_eq!((held.settings(), held.offset_m(1)), (0, DVec3::ZERO));
        let mut offsets = BandOffsets::default();
        for (k, o) in offsets.iter_mut().enumerate() {
            *o = DVec3::new(k as f64 + 0.5, -(k as f64), 1e-300);
        }
        drift.set(&offsets);
        assert_eq!(held.settings(), 1);
        assert_eq!(held.offset_m(2), offsets[2]);
        assert_eq!(held.offset_m(200), offsets[offsets.len() - 1]);
        assert_eq!(held.offsets_m(), offsets);
    }
}

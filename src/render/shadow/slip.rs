//! How far the upper drift bands' clouds have slipped against the lowest band's since the map
//! was drawn whole ([`crate::clouds::bands`]: each band of layers drifts with its own wind). The
//! map moves with the lowest band between drawings; an upper band's shadows stay where they
//! were drawn, so the map is drawn whole again once one has slipped [`BAND_SLIP_TEXELS`].

use glam::DVec3;

use crate::render::scene::BandOffsets;

/// Texels an upper drift band's shadows may lag where its clouds are before the map is drawn
/// whole again: two 117 m texels are a shadow's soft edge, and with 20 kt of shear between the
/// layers a band slips that far in about 25 s.
pub(super) const BAND_SLIP_TEXELS: f64 = 2.0;

/// Each band's offset against the lowest band's, now and at the last whole drawing.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct BandSlip {
    now: BandOffsets,
    drawn: BandOffsets,
}

impl BandSlip {
    /// Takes the bands' drift offsets now.
    pub(super) fn set(&mut self, offsets_m: &BandOffsets) {
        self.now = offsets_m.map(|o| o - offsets_m[0]);
    }

    /// The map was drawn whole now.
    pub(super) fn drawn(&mut self) {
        self.drawn = self.now;
    }

    /// Whether a band has slipped more than [`BAND_SLIP_TEXELS`] of `texel_m` since.
    pub(super) fn slipped(&self, texel_m: f64) -> bool {
        let limit = BAND_SLIP_TEXELS * texel_m;
        let moved = |(a, b): (&DVec3, &DVec3)| (*a - *b).length();
        self.now
            .iter()
            .zip(&self.drawn)
            .map(moved)
            .any(|m| m > limit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_upper_band_slips_against_the_lowest_not_with_it() {
        let mut slip = BandSlip::default();
        let all = |x: f64| [DVec3::new(x, 0.0, 0.0); 4];
        slip.set(&all(0.0));
        slip.drawn();
        // Every band moved alike: the map moves with them, nothing slipped.
        slip.set(&all(5_000.0));
        assert!(!slip.slipped(117.0));
        let mut offsets = all(5_000.0);
        offsets[2].x += 200.0;
        slip.set(&offsets);
        assert!(!slip.slipped(117.0));
        offsets[2].x += 40.0;
        slip.set(&offsets);
        assert!(slip.slipped(117.0));
        slip.drawn();
        assert!(!slip.slipped(117.0));
    }
}

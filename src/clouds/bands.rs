//! Drift bands: which of a block's layers drift together.
//!
//! Each layer drifts with the wind at its own height (the air data's, `flight::air`), and the
//! winds of two layers differ in speed and direction: an `SCT020 BKN080` under a westerly jet
//! moves its upper deck twice as fast as the cumulus below it. A field of blocks moves as one
//! (a block keeps its content while it drifts), so the layers are split into bands by rank: a
//! block's lowest layer is band 0, the next band 1, and so on, the last band taking every layer
//! above. Each band is a field of blocks of its own ([`super::field::CloudField`]) drifting with
//! its wind, so an upper layer glides over the lower one and every band keeps its blocks around
//! the camera. Ranked by the block's own layers: a layer only at the block's rim (a neighbour's,
//! [`crate::weather::BlockCover::rim_only`]) takes the rank it would have among them.
//!
//! A storm cell belongs to band 0 (the field that decides the cells draws them).

use crate::weather::{BlockLayer, BlockWeather};

use super::config::MAX_DRIFT_BANDS;

/// One band of a field split into `count` ([`super::config::FieldConfig::drift_bands`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DriftBand {
    /// Which band, 0 (the lowest layer) ..`count`.
    pub index: u8,
    /// How many bands the field is split into, 1..=[`MAX_DRIFT_BANDS`].
    pub count: u8,
}

impl DriftBand {
    /// The one band of a field that drifts as one: every layer.
    pub const WHOLE: Self = Self { index: 0, count: 1 };

    /// Band `index` of `count` (both brought into range).
    pub fn new(index: u8, count: u8) -> Self {
        let count = count.clamp(1, MAX_DRIFT_BANDS);
        Self {
            index: index.min(count - 1),
            count,
        }
    }

    /// The bands of a field split into `count`, lowest first.
    pub fn all(count: u8) -> impl Iterator<Item = Self> {
        let count = count.clamp(1, MAX_DRIFT_BANDS);
        (0..count).map(move |index| Self { index, count })
    }

    /// The band a layer based at `base_ft_agl` is in among a block's own `layers`: how many of
    /// them lie below it, the last band taking the rest.
    pub fn rank_of(layers: &[BlockLayer], base_ft_agl: f32, count: u8) -> u8 {
        let below = layers
            .iter()
            .filter(|l| l.base_ft_agl < base_ft_agl)
            .count();
        below.min(usize::from(count.max(1)) - 1) as u8
    }

    /// Whether this band holds the layer based at `base_ft_agl` of a block whose own layers are
    /// `layers`.
    pub fn holds(self, layers: &[BlockLayer], base_ft_agl: f32) -> bool {
        self.count <= 1 || Self::rank_of(layers, base_ft_agl, self.count) == self.index
    }

    /// Whether any layer of `weather` (its own, or one only at its rim) is in this band.
    pub fn holds_any(self, weather: &BlockWeather) -> bool {
        let rim = weather.cover.as_ref().map_or(&[][..], |c| &c.rim_only[..]);
        weather
            .layers
            .iter()
            .chain(rim.iter().map(|(l, _)| l))
            .any(|l| self.holds(&weather.layers, l.base_ft_agl))
    }

    /// The layer of `layers` (a column's) whose wind this band drifts with: the lowest of its
    /// rank; the highest there is where the column has fewer layers than the band's rank.
    /// `None` for no layers.
    pub fn steering_layer(self, layers: &[BlockLayer]) -> Option<&BlockLayer> {
        let mut by_base: Vec<&BlockLayer> = layers.iter().collect();
        by_base.sort_by(|a, b| a.base_ft_agl.total_cmp(&b.base_ft_agl));
        by_base
            .get(usize::from(self.index))
            .or(by_base.last())
            .copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::{CloudType, TypeSource};

    fn layer(base_ft: f32) -> BlockLayer {
        BlockLayer {
            cloud_type: CloudType::Stratocumulus,
            type_source: TypeSource::HeightRule,
            coverage_oktas: 3.0,
            base_ft_agl: base_ft,
            thickness_ft: 1000.0,
        }
    }

    #[test]
    fn layers_are_banded_by_rank_and_the_last_band_takes_the_rest() {
        let layers = [layer(1500.0), layer(4000.0), layer(9000.0), layer(25000.0)];
        let ranks: Vec<u8> = layers
            .iter()
            .map(|l| DriftBand::rank_of(&layers, l.base_ft_agl, 3))
            .collect();
        assert_eq!(ranks, [0, 1, 2, 2]);
        // A rim layer between the first two takes band 1, one under them all band 0.
        assert_eq!(DriftBand::rank_of(&layers, 2500.0, 3), 1);
        assert_eq!(DriftBand::rank_of(&layers, 800.0, 3), 0);
        // One band holds everything.
        assert!(DriftBand::WHOLE.holds(&layers, 25000.0));
        assert!(!DriftBand::new(0, 3).holds(&layers, 4000.0));
        assert!(DriftBand::new(1, 3).holds(&layers, 4000.0));
    }

    #[test]
    fn a_band_steers_by_its_own_layer_or_the_highest_there_is() {
        // A report lists a cumulonimbus or towering cumulus layer out of its height's order.
        let layers = [layer(4000.0), layer(1500.0)];
        let base = |b: DriftBand| b.steering_layer(&layers).map(|l| l.base_ft_agl);
        assert_eq!(base(DriftBand::new(0, 4)), Some(1500.0));
        assert_eq!(base(DriftBand::new(1, 4)), Some(4000.0));
        assert_eq!(base(DriftBand::new(3, 4)), Some(4000.0));
        assert_eq!(DriftBand::new(1, 4).steering_layer(&[]), None);
    }

    #[test]
    fn an_upper_band_holds_a_block_only_with_a_layer_of_its_rank() {
        let mut w = BlockWeather {
            layers: vec![layer(1500.0)],
            ..Default::default()
        };
        assert!(DriftBand::new(0, 3).holds_any(&w));
        assert!(!DriftBand::new(1, 3).holds_any(&w));
        w.layers.push(layer(6000.0));
        assert!(DriftBand::new(1, 3).holds_any(&w));
        assert!(!DriftBand::new(2, 3).holds_any(&w));
    }
}

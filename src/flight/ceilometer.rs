//! A ceilometer on the ground: what one would read under the clouds skycast makes as they drift
//! over it, and the METAR cloud groups its readings sum up to, so that the sky can be checked as
//! an instrument checks it (`skycast ceilometer`).
//!
//! Each reading is a vertical line of sight from the ground up ([`World::line_of_sight`], the
//! clouds every probe and the drawing share): the bases of the first three stretches of cloud it
//! meets while the beam still gets through ([`BEAM_DEPTH`]), feet above the ground. Between
//! readings the clouds advance as a flight's do.
//!
//! The summary ([`summarize`]), an algorithm of skycast's own after NOAA's ASOS (ASOS User's
//! Guide, 1998, section 3.9.2), with its cover bins ([`CoverBins`]) parted between the covers
//! skycast draws a report with (`[oktas]` of `config/weather_field.toml`: FEW 2, SCT 3.5,
//! BKN 6, OVC 8), where ASOS's end at fixed eighths (a layer drawn on a bin's edge reads one
//! class or the next by the toss of 40 readings):
//! 1. Every base of every reading, sorted, is cut into layers where one base lies more than
//!    max(100 ft, 10%) above the one before; a layer so found is cut again where a few bases
//!    chained two layers into one (`split_chained`: both sides more than a stray reading's
//!    share, their medians more than max(100 ft, 10%) apart).
//! 2. A layer's base is the median of its bases, rounded as a METAR writes it (to 100 ft up to
//!    5,000 ft, 500 ft to 10,000 ft, 1,000 ft above).
//! 3. Its cover is what is seen from below up to it (the summation principle): the share of the
//!    readings with a base at or under the layer's highest. Up to 5% is no layer (a stray
//!    reading); then FEW, SCT and BKN each up to where a share is as likely a toss of the next
//!    class's drawn cover as of its own (2.70, 4.83 and 7 oktas with the shipped ones: a
//!    scattered layer's share tosses wider than a broken one's; the last is ASOS's 87.5%),
//!    more OVC.
//! 4. A layer that adds no cover over the one below it (the same share) is still reported when
//!    its own readings are over 5%: a pilot between the two sees it.

use glam::{DVec2, DVec3};
use serde::Serialize;

use super::World;
use crate::render::RenderError;
use crate::weather::field::{FieldSettings, PerCover};
use crate::weather::metar::Cover;
use crate::weather::{BLOCK_SIZE_M, LocalFrame, METRES_PER_FOOT};

/// How high a reading looks, feet above the ground (the highest cirrus).
pub const TOP_FT: f64 = 45_000.0;

/// Bases a reading gives, at most.
pub const BASES_PER_READING: usize = 3;

/// One reading: its time from the start and the bases it found, lowest first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reading {
    /// Seconds from the first reading.
    pub time_s: f64,
    /// The bases of the first stretches of cloud above, feet above the ground (up to
    /// [`BASES_PER_READING`]); empty under a clear sky.
    pub bases_ft: Vec<f64>,
}

/// One METAR cloud group the readings sum up to.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Layer {
    /// Cover seen from below up to this layer.
    pub cover: Cover,
    /// Base, feet above the ground, rounded as a METAR writes it.
    pub base_ft: f64,
    /// The share of readings with a base at or under it.
    pub seen_share: f64,
}

impl Layer {
    /// The group as a METAR writes it (`BKN033`).
    pub fn group(&self) -> String {
        let cover = match self.cover {
            Cover::Few => "FEW",
            Cover::Sct => "SCT",
            Cover::Bkn => "BKN",
            Cover::Ovc => "OVC",
            Cover::Vv => "VV",
        };
        format!("{cover}{:03.0}", self.base_ft / 100.0)
    }
}

/// A local frame in which the point at `lat_deg`, `lon_deg` is the middle of block (0, 0), and
/// that point in it: a station there has the block to itself (its weather is the station's
/// report), and the air drifting over it is always that block's (at a block's corner, the
/// frame's origin, four blocks' weathers took turns overhead).
pub fn frame_centred_on(lat_deg: f64, lon_deg: f64) -> (LocalFrame, DVec2) {
    let half = DVec2::splat(0.5 * BLOCK_SIZE_M);
    let (lat, lon) = LocalFrame::new(lat_deg, lon_deg).to_lat_lon_deg(-half);
    let frame = LocalFrame::new(lat, lon);
    let at = frame.to_local_m(lat_deg, lon_deg);
    (frame, at)
}

/// Reads the sky over ground point `at_m` (local metres; `ground_m` its elevation) every
/// `every_s` seconds for `minutes`, the clouds advancing in between.
pub fn read(
    world: &mut World,
    at_m: DVec2,
    ground_m: f64,
    minutes: f64,
    every_s: f64,
) -> Result<Vec<Reading>, RenderError> {
    let count = ((minutes * 60.0 / every_s).floor() as usize).max(1);
    let mut readings = Vec::with_capacity(count);
    let foot = at_m.extend(ground_m + 1.0);
    let top = at_m.extend(ground_m + TOP_FT * METRES_PER_FOOT);
    world.settle_clouds_around(foot)?;
    for k in 0..count {
        if k > 0 {
            world.advance_clouds_around(foot, every_s)?;
        }
        readings.push(Reading {
            time_s: k as f64 * every_s,
            bases_ft: bases_over(world, foot, top, ground_m),
        });
    }
    Ok(readings)
}

/// The bases of the first stretches of cloud on the line from `foot` up to `top`, feet above
/// `ground_m`: those the beam reaches, with less than [`BEAM_DEPTH`] of cloud below them (a
/// ceilometer sees no base above a thick deck; a line of sight that came out of a deck's gap
/// and went in again met no second layer).
fn bases_over(world: &World, foot: DVec3, top: DVec3, ground_m: f64) -> Vec<f64> {
    let Some(hit) = world.line_of_sight(foot, top) else {
        return Vec::new();
    };
    let mut depth = 0.0;
    let mut bases = Vec::new();
    for c in &hit.crossings {
        if depth >= BEAM_DEPTH || bases.len() == BASES_PER_READING {
            break;
        }
        // To a tenth of a foot: the metres' rounding is no finer.
        let feet = (foot.z + c.entry_m - ground_m) / METRES_PER_FOOT;
        bases.push((feet * 10.0).round() / 10.0);
        depth += c.optical_depth;
    }
    bases
}

/// The optical depth of cloud a ceilometer's beam goes through and still finds the base of
/// another layer above.
pub const BEAM_DEPTH: f64 = 3.0;

/// Where the summary's METAR covers part, as shares of the readings (the module's step 3): a
/// layer seen over `few_max` of them is SCT, over `sct_max` BKN, over `bkn_max` OVC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoverBins {
    /// The most a FEW layer is seen, share of the readings.
    pub few_max: f64,
    /// The most a SCT layer is seen.
    pub sct_max: f64,
    /// The most a BKN layer is seen.
    pub bkn_max: f64,
}

impl CoverBins {
    /// Bins for the covers a report is drawn with (`oktas`, the field's `[oktas]`). A reading
    /// is a yes-or-no look, so the share of readings that meets a layer drawn at cover `p`
    /// tosses about `p` with a spread that goes as `sqrt(p (1 - p))`: a scattered layer's share
    /// tosses wider than a broken one's. Two neighbouring classes therefore part where a share
    /// lies as many spreads from the one drawn cover as from the other (the shipped FEW 2 and
    /// SCT 3.5 oktas at 2.70/8, SCT and BKN 6 at 4.83/8), so that a toss one way is as likely
    /// as the other. BKN and OVC part halfway (7/8): an overcast is closed from below, its
    /// readings do not toss, and what it loses is the deck's edge, not a toss.
    pub fn for_covers(oktas: &PerCover) -> Self {
        let share = |o: f64| (o / 8.0).clamp(0.0, 1.0);
        let spread = |p: f64| (p * (1.0 - p)).sqrt();
        let equal_odds = |a: f64, b: f64| {
            let (a, b) = (share(a), share(b));
            let (sa, sb) = (spread(a), spread(b));
            if sa + sb > 1e-9 {
                (a * sb + b * sa) / (sa + sb)
            } else {
                (a + b) / 2.0
            }
        };
        Self {
            few_max: equal_odds(oktas.few, oktas.sct),
            sct_max: equal_odds(oktas.sct, oktas.bkn),
            bkn_max: (share(oktas.bkn) + share(oktas.ovc)) / 2.0,
        }
    }

    /// The METAR cover of a layer seen over `share` of the readings; `None` for a stray
    /// reading's share.
    fn cover_of(&self, share: f64) -> Option<Cover> {
        match share {
            s if s <= STRAY_SHARE => None,
            s if s <= self.few_max => Some(Cover::Few),
            s if s <= self.sct_max => Some(Cover::Sct),
            s if s <= self.bkn_max => Some(Cover::Bkn),
            _ => Some(Cover::Ovc),
        }
    }
}

impl Default for CoverBins {
    /// For the shipped `config/weather_field.toml`'s covers.
    fn default() -> Self {
        Self::for_covers(&FieldSettings::default().oktas)
    }
}

/// The METAR cloud groups `readings` sum up to, lowest first (the module's algorithm), their
/// covers by `bins`.
pub fn summarize(readings: &[Reading], bins: &CoverBins) -> Vec<Layer> {
    let n = readings.len().max(1) as f64;
    let mut bases: Vec<f64> = readings.iter().flat_map(|r| r.bases_ft.clone()).collect();
    bases.sort_by(f64::total_cmp);
    // 1. Layers where the bases part.
    let mut clusters: Vec<Vec<f64>> = Vec::new();
    for b in bases {
        match clusters.last_mut() {
            Some(c) if b - c[c.len() - 1] <= gap_ft(c[c.len() - 1]) => c.push(b),
            _ => clusters.push(vec![b]),
        }
    }
    let own_share = |low: f64, high: f64| {
        readings
            .iter()
            .filter(|r| r.bases_ft.iter().any(|&b| b >= low && b <= high))
            .count() as f64
            / n
    };
    let clusters: Vec<Vec<f64>> = clusters
        .into_iter()
        .flat_map(|c| split_chained(c, &own_share))
        .collect();
    let mut layers = Vec::new();
    for c in &clusters {
        let highest = c[c.len() - 1];
        // 3. Seen from below up to it, and its own share.
        let seen = readings
            .iter()
            .filter(|r| r.bases_ft.first().is_some_and(|&b| b <= highest))
            .count() as f64
            / n;
        let own = own_share(c[0], highest);
        if own <= STRAY_SHARE {
            continue;
        }
        let Some(cover) = bins.cover_of(seen.max(own)) else {
            continue;
        };
        layers.push(Layer {
            cover,
            base_ft: metar_rounded_ft(c[c.len() / 2]),
            seen_share: seen,
        });
    }
    layers
}

/// Step 1b of the module's algorithm: `cluster` (sorted bases) cut in two where a few bases
/// between two layers chained them into one (the upper puffs of a cumulus, met again above a
/// gap, lie between its base and the deck above). Of its gaps, widest first, the first that
/// leaves more than a stray reading's share on both sides and their medians more than
/// max(100 ft, 10%) apart; each side then again. `own_share(low, high)` is the share of the
/// readings with a base in `low..=high`.
fn split_chained(cluster: Vec<f64>, own_share: &impl Fn(f64, f64) -> f64) -> Vec<Vec<f64>> {
    let median = |c: &[f64]| c[c.len() / 2];
    let mut gaps: Vec<usize> = (1..cluster.len()).collect();
    gaps.sort_by(|&a, &b| {
        let width = |k: usize| cluster[k] - cluster[k - 1];
        width(b).total_cmp(&width(a))
    });
    for k in gaps {
        let (low, high) = cluster.split_at(k);
        let apart = median(high) - median(low) > gap_ft(median(low));
        if apart
            && own_share(low[0], low[low.len() - 1]) > STRAY_SHARE
            && own_share(high[0], high[high.len() - 1]) > STRAY_SHARE
        {
            let (low, high) = (low.to_vec(), high.to_vec());
            let mut parts = split_chained(low, own_share);
            parts.extend(split_chained(high, own_share));
            return parts;
        }
    }
    vec![cluster]
}

/// The share of readings up to which a layer is a stray reading, not a layer.
const STRAY_SHARE: f64 = 0.05;

/// How far above the last base of a layer the next may lie and still be the same layer, feet.
fn gap_ft(base_ft: f64) -> f64 {
    (0.1 * base_ft).max(100.0)
}

/// A base as a METAR writes it: to 100 ft up to 5,000 ft, 500 ft to 10,000 ft, 1,000 ft above.
pub fn metar_rounded_ft(base_ft: f64) -> f64 {
    let step = if base_ft <= 5_000.0 {
        100.0
    } else if base_ft <= 10_000.0 {
        500.0
    } else {
        1_000.0
    };
    (base_ft / step).round() * step
}

/// The ceiling of `layers`, feet: the lowest base seen broken or overcast.
pub fn ceiling_ft(layers: &[Layer]) -> Option<f64> {
    layers
        .iter()
        .find(|l| matches!(l.cover, Cover::Bkn | Cover::Ovc))
        .map(|l| l.base_ft)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn readings(bases: &[&[f64]]) -> Vec<Reading> {
        bases
            .iter()
            .enumerate()
            .map(|(k, b)| Reading {
                time_s: 30.0 * k as f64,
                bases_ft: b.to_vec(),
            })
            .collect()
    }

    #[test]
    fn two_broken_layers_and_a_stray_reading() {
        // 40 readings: 28 see a base near 3,300 ft, 24 one near 4,100 ft (32 of the 40 one or
        // both); one reading meets a wisp at 8,000 ft.
        let mut all: Vec<Vec<f64>> = Vec::new();
        for k in 0..40 {
            let mut b = Vec::new();
            if k < 28 {
                b.push(3_280.0 + (k % 3) as f64 * 20.0);
            }
            if k % 4 != 0 && k < 36 {
                b.push(4_100.0);
            }
            if k == 39 {
                b.push(8_000.0);
            }
            all.push(b);
        }
        let refs: Vec<&[f64]> = all.iter().map(Vec::as_slice).collect();
        let layers = summarize(&readings(&refs), &CoverBins::default());
        let groups: Vec<String> = layers.iter().map(Layer::group).collect();
        assert_eq!(groups, ["BKN033", "BKN041"], "{layers:?}");
        assert_eq!(ceiling_ft(&layers), Some(3_300.0));
        // A clear sky is no layer and no ceiling.
        let clear = summarize(&readings(&[&[], &[], &[]]), &CoverBins::default());
        assert!(clear.is_empty() && ceiling_ft(&clear).is_none());
        // Every reading under one base: overcast.
        let ovc = summarize(
            &readings(&[&[600.0], &[590.0], &[610.0], &[600.0]]),
            &CoverBins::default(),
        );
        assert_eq!(ovc.iter().map(Layer::group).collect::<Vec<_>>(), ["OVC006"]);
    }

    #[test]
    fn a_base_between_two_layers_does_not_chain_them_into_one() {
        // KVTI's SCT080 OVC090 as read under skycast's clouds: the scattered layer over 18 of
        // 40 readings, the deck over the rest, and one reading meeting a cumulus's upper puff
        // at 8,564 ft, which bridges the 1,000 ft between the two.
        let mut all: Vec<Vec<f64>> = Vec::new();
        for k in 0..40 {
            all.push(match k {
                3 => vec![8_000.0, 8_564.0],
                _ if k % 20 < 9 => vec![8_000.0],
                _ => vec![9_000.0],
            });
        }
        let refs: Vec<&[f64]> = all.iter().map(Vec::as_slice).collect();
        let groups: Vec<String> = summarize(&readings(&refs), &CoverBins::default())
            .iter()
            .map(Layer::group)
            .collect();
        assert_eq!(groups, ["SCT080", "OVC090"]);
        // One layer whose bases spread evenly over 10% is not cut.
        let spread: Vec<Vec<f64>> = (0..40).map(|k| vec![3_000.0 + 10.0 * k as f64]).collect();
        let refs: Vec<&[f64]> = spread.iter().map(Vec::as_slice).collect();
        assert_eq!(summarize(&readings(&refs), &CoverBins::default()).len(), 1);
    }

    #[test]
    fn the_covers_part_where_a_toss_either_way_is_as_likely() {
        let bins = |few, sct, bkn, ovc| CoverBins::for_covers(&PerCover { few, sct, bkn, ovc });
        let near =
            |got: [f64; 3], want: [f64; 3]| got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-4);
        // FlightGear's 2, 4, 6 and 8 oktas: a scattered half of the sky tosses wider than a
        // quarter or three quarters, so its edges lie out from halfway (3/8 and 5/8) towards
        // FEW's and BKN's covers, a share of the one as many spreads as of the other off.
        let flightgear = bins(2.0, 4.0, 6.0, 8.0);
        let spread = |p: f64| (p * (1.0 - p)).sqrt();
        let (quarter, half) = (spread(0.25), spread(0.5));
        assert!(
            ((flightgear.few_max - 0.25) / quarter - (0.5 - flightgear.few_max) / half).abs()
                < 1e-9
        );
        assert!(near(
            [flightgear.few_max, flightgear.sct_max, flightgear.bkn_max],
            [0.3660, 0.6340, 0.875]
        ));
        let shipped = CoverBins::default();
        assert_eq!(shipped, bins(2.0, 3.5, 6.0, 8.0));
        assert!(near(
            [shipped.few_max, shipped.sct_max, shipped.bkn_max],
            [2.6991 / 8.0, 4.8348 / 8.0, 0.875]
        ));
        // 24 of 40 readings: 0.33 of SCT's spread over its 0.44 (3.5 oktas), 0.35 of BKN's
        // under its 0.75 (6 oktas): SCT (halfway, 0.59, made it BKN).
        assert_eq!(shipped.cover_of(0.6), Some(Cover::Sct));
        assert_eq!(shipped.cover_of(0.625), Some(Cover::Bkn));
        assert_eq!(shipped.cover_of(0.05), None);
        assert_eq!(shipped.cover_of(0.3), Some(Cover::Few));
        assert_eq!(shipped.cover_of(0.9), Some(Cover::Ovc));
        // A sky drawn clear against one drawn closed: neither tosses, halfway.
        assert_eq!(bins(0.0, 8.0, 8.0, 8.0).few_max, 0.5);
    }

    #[test]
    fn bases_round_as_a_metar_writes_them() {
        assert_eq!(metar_rounded_ft(3_349.0), 3_300.0);
        assert_eq!(metar_rounded_ft(7_200.0), 7_000.0);
        assert_eq!(metar_rounded_ft(23_600.0), 24_000.0);
    }
}

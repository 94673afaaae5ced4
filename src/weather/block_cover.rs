//! How a block's cloud cover varies across it: plain data the weather stage adds to a block's
//! weather, so that the clouds stage fills each part of the block to the cover there and two
//! blocks sharing a border agree along it (issue 31: a block that took all its weather from one
//! point was a square step of an okta or more beside its neighbours).
//!
//! The field is asked at eight points of the block's rim ([`RIM_POINTS_M`]: the corners and the
//! middles of the sides), which neighbouring blocks share, besides the block's own sample point
//! (its station, else its centre). Each layer's own coverage is known at those nine points; in
//! between it is linear on the eight triangles that fan from the sample point to the rim
//! ([`LayerCover::oktas_at`]). So along a side it is linear between two shared rim points (the
//! neighbour has the same figures there), and at the sample point it is the block's own figure:
//! at a station, its report. Units: metres east/north of the block's south-west corner; oktas.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::block::{BLOCK_SIZE_M, BlockLayer};
use super::cloud_type::CloudType;

/// The points of a block's rim the field is sampled at, metres east/north of its south-west
/// corner, anticlockwise from that corner: the corners and the middles of the sides.
pub const RIM_POINTS_M: [DVec2; 8] = {
    let (h, s) = (BLOCK_SIZE_M / 2.0, BLOCK_SIZE_M);
    [
        DVec2::new(0.0, 0.0),
        DVec2::new(h, 0.0),
        DVec2::new(s, 0.0),
        DVec2::new(s, h),
        DVec2::new(s, s),
        DVec2::new(h, s),
        DVec2::new(0.0, s),
        DVec2::new(0.0, h),
    ]
};

/// The cover over a block beyond its sample point (see the module's doc).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BlockCover {
    /// Where the block's weather was sampled, metres east/north of its south-west corner: its
    /// layers' own coverages hold there.
    pub sample_m: [f32; 2],
    /// For each layer of the block (same order), the layer the field has at each rim point that
    /// matches it (same kind, nearest base within the field's blending distance).
    pub rim: Vec<RimLayer>,
    /// Layers the field has at some rim points and not at the sample point; their
    /// `coverage_oktas` is the greatest on the rim (at the sample point they have none), their
    /// type and heights those of the rim point where they cover most.
    pub rim_only: Vec<(BlockLayer, RimLayer)>,
}

/// One layer at the rim points of a block ([`RIM_POINTS_M`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RimLayer {
    /// Its own coverage at each rim point, oktas (0 where the field has no such layer).
    pub oktas: [f32; 8],
    /// Its type at each rim point (where it has none, the block's type of it).
    pub types: [CloudType; 8],
}

impl RimLayer {
    /// No cover of type `cloud_type` anywhere on the rim.
    pub fn none(cloud_type: CloudType) -> Self {
        Self {
            oktas: [0.0; 8],
            types: [cloud_type; 8],
        }
    }
}

/// One layer's own coverage over its block: at the sample point and the rim points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerCover {
    /// The sample point, metres from the block's south-west corner (kept off the rim).
    sample_m: DVec2,
    /// Own coverage at the sample point, oktas.
    at_sample_oktas: f32,
    /// Own coverage at [`RIM_POINTS_M`], oktas.
    rim_oktas: [f32; 8],
}

/// How far inside the rim the fan's centre is kept, metres (a station on a block's side would
/// leave triangles of no area).
const SAMPLE_INSET_M: f64 = 100.0;

impl LayerCover {
    /// The same coverage everywhere in the block.
    pub fn uniform(oktas: f32) -> Self {
        Self {
            sample_m: DVec2::splat(BLOCK_SIZE_M / 2.0),
            at_sample_oktas: oktas,
            rim_oktas: [oktas; 8],
        }
    }

    /// Coverage `at_sample_oktas` at `sample_m` and `rim_oktas` on the rim.
    pub fn new(sample_m: [f32; 2], at_sample_oktas: f32, rim_oktas: [f32; 8]) -> Self {
        let inset = |v: f32| (v as f64).clamp(SAMPLE_INSET_M, BLOCK_SIZE_M - SAMPLE_INSET_M);
        Self {
            sample_m: DVec2::new(inset(sample_m[0]), inset(sample_m[1])),
            at_sample_oktas,
            rim_oktas,
        }
    }

    /// Whether the coverage is the same at all nine points (then everywhere).
    pub fn is_uniform(&self) -> bool {
        self.rim_oktas.iter().all(|&o| o == self.at_sample_oktas)
    }

    /// The greatest coverage anywhere in the block, oktas.
    pub fn max_oktas(&self) -> f32 {
        self.rim_oktas
            .iter()
            .fold(self.at_sample_oktas, |m, &o| m.max(o))
    }

    /// The own coverage at `p_m` (metres from the block's south-west corner, clamped into the
    /// block), oktas: linear on the triangle of the fan from the sample point that holds it.
    /// No trigonometry, so the same bits on every machine.
    pub fn oktas_at(&self, p_m: DVec2) -> f32 {
        if self.is_uniform() {
            return self.at_sample_oktas;
        }
        let p = p_m.clamp(DVec2::ZERO, DVec2::splat(BLOCK_SIZE_M)) - self.sample_m;
        for k in 0..8 {
            let a = RIM_POINTS_M[k] - self.sample_m;
            let b = RIM_POINTS_M[(k + 1) % 8] - self.sample_m;
            if a.perp_dot(p) >= 0.0 && p.perp_dot(b) >= 0.0 {
                let det = a.perp_dot(b);
                let (u, v) = (p.perp_dot(b) / det, a.perp_dot(p) / det);
                let (ra, rb) = (self.rim_oktas[k] as f64, self.rim_oktas[(k + 1) % 8] as f64);
                let c = self.at_sample_oktas as f64;
                return ((1.0 - u - v) * c + u * ra + v * rb) as f32;
            }
        }
        self.at_sample_oktas
    }
}

impl BlockCover {
    /// Each layer to generate with its cover over the block. A layer whose type is not the same
    /// at all its nine points is one layer per type, each with the cover of the points of its
    /// type (0 at the others), so a type gives way to the next across the block, mixed, and not
    /// at its border: the block's `layers` at their type at the sample point first (in order;
    /// uniform where this cover has no rim for one), then the layers only the rim has, then the
    /// other types.
    pub fn layers_over_block(
        cover: Option<&Self>,
        layers: &[BlockLayer],
    ) -> Vec<(BlockLayer, LayerCover)> {
        Self::layers_over_block_grouped(cover, layers)
            .into_iter()
            .map(|(layer, cover, _)| (layer, cover))
            .collect()
    }

    /// [`Self::layers_over_block`] with, for each, the layer of the block's (or rim's) it was cut
    /// from by type (an index in the order they are listed there): the layers of one group are
    /// one layer of cloud whose types share it out, an overcast among them wherever their covers
    /// add up to one.
    pub fn layers_over_block_grouped(
        cover: Option<&Self>,
        layers: &[BlockLayer],
    ) -> Vec<(BlockLayer, LayerCover, usize)> {
        let Some(c) = cover else {
            return layers
                .iter()
                .enumerate()
                .map(|(i, l)| (*l, LayerCover::uniform(l.coverage_oktas), i))
                .collect();
        };
        let own = layers.iter().enumerate().map(|(i, l)| {
            let rim = c.rim.get(i).copied();
            (
                *l,
                l.coverage_oktas,
                rim.unwrap_or(RimLayer::none(l.cloud_type)),
                rim.is_some(),
            )
        });
        let only = c.rim_only.iter().map(|(l, rim)| (*l, 0.0, *rim, true));
        let all: Vec<(BlockLayer, f32, RimLayer, bool)> = own.chain(only).collect();
        let mut out = Vec::with_capacity(all.len());
        let mut others = Vec::new();
        for (group, &(layer, at_sample, rim, has_rim)) in all.iter().enumerate() {
            if !has_rim {
                out.push((layer, LayerCover::uniform(at_sample), group));
                continue;
            }
            let of_type = |t: CloudType| {
                let at = if t == layer.cloud_type {
                    at_sample
                } else {
                    0.0
                };
                let oktas =
                    std::array::from_fn(|k| if rim.types[k] == t { rim.oktas[k] } else { 0.0 });
                LayerCover::new(c.sample_m, at, oktas)
            };
            out.push((layer, of_type(layer.cloud_type), group));
            let mut seen = vec![layer.cloud_type];
            for (k, &t) in rim.types.iter().enumerate() {
                if !seen.contains(&t) && rim.oktas[k] > 0.0 {
                    seen.push(t);
                    let typed = BlockLayer {
                        cloud_type: t,
                        coverage_oktas: 0.0,
                        ..layer
                    };
                    others.push((typed, of_type(t), group));
                }
            }
        }
        out.extend(others);
        out
    }

    /// Whether two covers differ enough to re-form a block's clouds: a rim-only layer added or
    /// removed, a type on the rim changed, or a coverage on the rim by `oktas` or more.
    pub fn differs(a: Option<&Self>, b: Option<&Self>, oktas: f32) -> bool {
        let rims = |c: &Self| -> Vec<RimLayer> {
            let mut all = c.rim.clone();
            all.extend(c.rim_only.iter().map(|r| r.1));
            all
        };
        match (a, b) {
            (None, None) => false,
            (Some(a), Some(b)) => {
                let (x, y) = (rims(a), rims(b));
                a.rim_only.len() != b.rim_only.len()
                    || x.len() != y.len()
                    || x.iter().zip(&y).any(|(p, q)| {
                        p.types != q.types
                            || p.oktas
                                .iter()
                                .zip(&q.oktas)
                                .any(|(u, v)| (u - v).abs() >= oktas)
                    })
            }
            _ => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fan_is_the_sample_at_the_sample_point_and_linear_along_the_rim() {
        let rim = [0.0, 2.0, 4.0, 6.0, 8.0, 6.0, 4.0, 2.0];
        let c = LayerCover::new([1000.0, 3000.0], 5.0, rim);
        assert_eq!(c.oktas_at(DVec2::new(1000.0, 3000.0)), 5.0);
        for (k, p) in RIM_POINTS_M.iter().enumerate() {
            assert!((c.oktas_at(*p) - rim[k]).abs() < 1e-5, "{k}");
        }
        // A quarter along the south side: a quarter of the way from 0 to 2 oktas; the same
        // figure whatever the sample point and its own coverage (the neighbour's view of it).
        let q = DVec2::new(500.0, 0.0);
        let other = LayerCover::new([3500.0, 200.0], 0.0, rim);
        assert!((c.oktas_at(q) - 0.5).abs() < 1e-5);
        assert!((other.oktas_at(q) - 0.5).abs() < 1e-5);
        // Between, within the range of the nine figures; outside the block, clamped into it.
        let mid = c.oktas_at(DVec2::new(2500.0, 2000.0));
        assert!(mid > 2.0 && mid < 6.0, "{mid}");
        assert_eq!(c.oktas_at(DVec2::new(-50.0, -50.0)), 0.0);
        assert!(!c.is_uniform() && LayerCover::uniform(3.0).is_uniform());
        assert_eq!(c.max_oktas(), 8.0);
    }

    #[test]
    fn a_station_on_the_rim_leaves_no_degenerate_triangle() {
        let c = LayerCover::new([0.0, 4000.0], 8.0, [0.0; 8]);
        for p in [DVec2::new(0.0, 4000.0), DVec2::new(1.0, 3999.0)] {
            let o = c.oktas_at(p);
            assert!(o.is_finite() && (0.0..=8.0).contains(&o), "{p}: {o}");
        }
        assert!(c.oktas_at(DVec2::new(100.0, 3900.0)) == 8.0);
    }
}

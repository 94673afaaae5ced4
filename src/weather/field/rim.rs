//! A block's cover at its rim ([`BlockCover`]): the layers the field gives at each rim point,
//! matched to the block's own layers.
//!
//! A rim layer matches a block layer of the same kind (fog, a reported CB/TCU with its own
//! amount, or a plain layer) whose base is within the field's blending distance
//! (`max(blend_within_ft, blend_within_fraction x base)`, as the field matches the stations'
//! layers); pairs are taken nearest bases first, each layer in one pair at most. A rim layer no
//! block layer matches joins a rim-only layer it matches (from another rim point), else starts
//! one. The type does not take part: an altostratus deck at the sample point and altocumulus
//! at the rim are one layer whose cover runs on; each rim point keeps its type, and the clouds
//! stage gives each type its share ([`BlockCover::layers_over_block`]).

use crate::weather::block::{BlockLayer, TypeSource};
use crate::weather::block_cover::{BlockCover, RimLayer};
use crate::weather::cloud_type::CloudType;

use super::settings::FieldSettings;

/// Whether two layers are of one kind and near enough in base to be one layer.
fn same_layer(a: &BlockLayer, b: &BlockLayer, settings: &FieldSettings) -> Option<f32> {
    let kind = |l: &BlockLayer| {
        (
            l.type_source == TypeSource::Reported,
            l.cloud_type == CloudType::Fog,
        )
    };
    let l = &settings.layers;
    let base = a.base_ft_agl.max(b.base_ft_agl) as f64;
    let within = l.blend_within_ft.max(l.blend_within_fraction * base) as f32;
    let gap = (a.base_ft_agl - b.base_ft_agl).abs();
    (kind(a) == kind(b) && gap <= within).then_some(gap)
}

/// For each of `here`'s layers, the index of the layer of `layers` it matches, if any: pairs
/// nearest in base first, each layer in one pair at most.
fn match_to(
    layers: &[BlockLayer],
    here: &[BlockLayer],
    settings: &FieldSettings,
) -> Vec<Option<usize>> {
    let mut pairs: Vec<(f32, usize, usize)> = Vec::new();
    for (h, rim) in here.iter().enumerate() {
        for (i, own) in layers.iter().enumerate() {
            if let Some(gap) = same_layer(own, rim, settings) {
                pairs.push((gap, h, i));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let mut out = vec![None; here.len()];
    let mut taken = vec![false; layers.len()];
    for (_, h, i) in pairs {
        if out[h].is_none() && !taken[i] {
            out[h] = Some(i);
            taken[i] = true;
        }
    }
    out
}

/// The cover of a block whose own `layers` were sampled at `sample_m` (metres from its
/// south-west corner), from the layers the field gives at its rim points (`rim`, in
/// [`crate::weather::block_cover::RIM_POINTS_M`] order).
pub(super) fn block_cover(
    layers: &[BlockLayer],
    rim: &[Vec<BlockLayer>; 8],
    sample_m: [f32; 2],
    settings: &FieldSettings,
) -> BlockCover {
    let mut own: Vec<RimLayer> = layers
        .iter()
        .map(|l| RimLayer::none(l.cloud_type))
        .collect();
    let mut rim_only: Vec<(BlockLayer, RimLayer)> = Vec::new();
    for (k, here) in rim.iter().enumerate() {
        for (layer, matched) in here.iter().zip(match_to(layers, here, settings)) {
            if let Some(i) = matched {
                own[i].oktas[k] = layer.coverage_oktas;
                own[i].types[k] = layer.cloud_type;
                continue;
            }
            let joins = rim_only
                .iter()
                .position(|(l, r)| r.oktas[k] == 0.0 && same_layer(l, layer, settings).is_some());
            let (l, r) = match joins {
                Some(j) => &mut rim_only[j],
                None => {
                    rim_only.push((*layer, RimLayer::none(layer.cloud_type)));
                    let last = rim_only.len() - 1;
                    &mut rim_only[last]
                }
            };
            r.oktas[k] = layer.coverage_oktas;
            r.types[k] = layer.cloud_type;
            if layer.coverage_oktas >= l.coverage_oktas {
                *l = *layer;
            }
        }
    }
    // Where a rim-only layer has none, its type is its own (so it is not split for nothing).
    for (l, r) in &mut rim_only {
        for k in 0..8 {
            if r.oktas[k] == 0.0 {
                r.types[k] = l.cloud_type;
            }
        }
    }
    BlockCover {
        sample_m,
        rim: own,
        rim_only,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(cloud_type: CloudType, coverage_oktas: f32, base_ft_agl: f32) -> BlockLayer {
        BlockLayer {
            cloud_type,
            type_source: TypeSource::HeightRule,
            coverage_oktas,
            base_ft_agl,
            thickness_ft: 700.0,
        }
    }

    #[test]
    fn rim_layers_match_by_base_whatever_their_type_and_the_rest_are_rim_only() {
        let settings = FieldSettings::default();
        // Chino: BKN080 as altostratus at the station; around it altocumulus at 8,500 ft over
        // cumulus at 3,500 ft on the east side only.
        let own = [layer(CloudType::Altostratus, 6.0, 8000.0)];
        let west = vec![layer(CloudType::Altocumulus, 3.0, 8400.0)];
        let east = vec![
            layer(CloudType::CumulusHumilis, 2.0, 3500.0),
            layer(CloudType::Altocumulus, 2.5, 8600.0),
        ];
        let rim: [Vec<BlockLayer>; 8] = std::array::from_fn(|k| match k {
            2..=4 => east.clone(),
            0 | 6 | 7 => west.clone(),
            _ => Vec::new(),
        });
        let c = block_cover(&own, &rim, [2000.0, 2000.0], &settings);
        assert_eq!(c.rim.len(), 1);
        assert_eq!(c.rim[0].oktas, [3.0, 0.0, 2.5, 2.5, 2.5, 0.0, 3.0, 3.0]);
        let (ac, st) = (CloudType::Altocumulus, CloudType::Altostratus);
        assert_eq!(c.rim[0].types, [ac, st, ac, ac, ac, st, ac, ac]);
        assert_eq!(c.rim_only.len(), 1, "{:?}", c.rim_only);
        let (l, r) = c.rim_only[0];
        assert_eq!(l.cloud_type, CloudType::CumulusHumilis);
        assert_eq!(r.oktas, [0.0, 0.0, 2.0, 2.0, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(r.types, [CloudType::CumulusHumilis; 8]);
        // A deck 3,000 ft above is another layer; two rim layers do not both take one.
        let far = vec![
            layer(CloudType::Altocumulus, 3.0, 8100.0),
            layer(CloudType::Altocumulus, 1.0, 8300.0),
            layer(CloudType::Cirrostratus, 1.0, 11_000.0),
        ];
        let rim: [Vec<BlockLayer>; 8] = std::array::from_fn(|_| far.clone());
        let c = block_cover(&own, &rim, [2000.0, 2000.0], &settings);
        assert_eq!(c.rim[0].oktas, [3.0; 8]);
        assert_eq!(c.rim_only.len(), 2, "{:?}", c.rim_only);
    }
}

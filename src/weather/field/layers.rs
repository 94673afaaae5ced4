//! The cloud layers at a point: the reported layers of the natural neighbours, matched by height
//! and blended by their weights. No fixed bands: every reported layer is kept apart.
//!
//! 1. Match: the neighbours' layers of one kind (fog, plain, CB, TCU), sorted by base, are one
//!    layer while each base lies within `max(blend_within_ft, blend_within_fraction x base)` of
//!    the one below and no station gives two of them. A layer only some neighbours report is
//!    one too; its weight (its *presence*) is their share of the natural-neighbour weight.
//! 2. Base: the presence-weighted mean of its stations' bases.
//! 3. Cover seen from below at that base: every neighbour's report read there (the cover of the
//!    layer itself where the neighbour has it, else the neighbour's cover at that height, the
//!    summation principle), weighted; never less than at the layer below. A layer only one
//!    station has fades out with that station's weight. Only fog and plain layers take part:
//!    ICAO Annex 3 reports CB and TCU with their own amount, outside the summation principle.
//! 4. Own coverage: what the layer must add to the sky seen from below, clouds of different layers
//!    overlapping at random ([`own_coverage_oktas`]); a layer that adds little or none
//!    (`BKN033 BKN041`) adds at least `min_seen_added_oktas` to the sky seen from below (what
//!    a ceilometer meets through the gaps of the one below) and has at least `min_added_oktas`
//!    of its own (2 oktas a pilot between them sees), times its presence, as far as the sky
//!    seen from below stays in the class reported at its base (BKN: at most 7 oktas;
//!    over a SCT at the class's top, `min_coverage_oktas`); above an overcast its
//!    stations' own covers.
//!    A CB/TCU layer keeps its stations' own amounts, weighted (`FEW025CB` over a broken deck is
//!    2 oktas of Cb at the station), and needs `convective.weight_min` of presence.
//! 5. Type: CB/TCU as reported; else a type a remark or theme names (with `weight_min` of the
//!    presence); else the height rule on the cover seen from below.
//! 6. Extent by type ([`Extent`](super::settings::Extent)): CB and TCU tops, fair-weather cumulus
//!    by the spread, stratus and fog; else by cover. A layer's top stays under the next base,
//!    but a CB's or TCU's grows through the decks around it.
//!
//! At a station its weight is 1 and every other 0: the layers are its report, exactly.

use crate::weather::block::{BlockLayer, TypeSource, own_coverage_oktas};
use crate::weather::cloud_type::CloudType;

use super::rule::{Band, CloudTypeRule, LayerFacts};
use super::sample::{LayerKind, StationLayer, StationSample};
use super::settings::FieldSettings;

/// The most cover, oktas, of the METAR class that `oktas` seen from below falls in: FEW up to
/// 2, SCT up to 4, BKN up to 7 (an overcast is 8).
fn class_top_oktas(oktas: f64) -> f64 {
    match oktas {
        x if x <= 2.0 => 2.0,
        x if x <= 4.0 => 4.0,
        x if x < 8.0 => 7.0,
        _ => 8.0,
    }
}

/// How near an overcast (oktas short of 8) the sky seen from below is taken as one.
const NEAR_OVERCAST_OKTAS: f64 = 0.5;

/// The surface facts the layers' types and extents depend on.
#[derive(Debug, Clone, Copy)]
pub(super) struct Surface {
    /// Precipitation intensity 0..=1.
    pub precipitation: f64,
    /// Temperature, degrees C.
    pub temperature_c: f64,
    /// Temperature minus dewpoint, degrees C.
    pub spread_c: f64,
}

/// One matched layer: the neighbours' layers that are one.
struct Matched<'a> {
    kind: LayerKind,
    /// (sample index, weight, layer).
    members: Vec<(usize, f64, &'a StationLayer)>,
}

impl Matched<'_> {
    fn presence(&self) -> f64 {
        self.members.iter().map(|m| m.1).sum()
    }

    fn base_ft(&self) -> f64 {
        let p = self.presence();
        self.members.iter().map(|m| m.1 * m.2.base_ft).sum::<f64>() / p
    }
}

/// The layers at a point whose cloud-field weights are `w`, lowest base first.
pub(super) fn blend(
    w: &[(usize, f64)],
    samples: &[StationSample],
    settings: &FieldSettings,
    rule: &CloudTypeRule,
    surface: Surface,
) -> Vec<BlockLayer> {
    let matched = match_layers(w, samples, settings);
    let total_weight: f64 = w.iter().map(|m| m.1).sum();
    if total_weight <= 0.0 {
        return Vec::new();
    }
    let l = &settings.layers;
    // (layer, reported kind) of the kept layers; the running cover of fog and plain layers seen
    // from below (convective layers stand outside it).
    let mut kept: Vec<(BlockLayer, LayerKind, bool)> = Vec::new();
    let mut below = 0.0f64;
    for m in &matched {
        let presence = m.presence();
        let convective = matches!(m.kind, LayerKind::Cb | LayerKind::Tcu);
        if convective && presence < settings.convective.weight_min {
            continue;
        }
        let base = m.base_ft();
        if convective {
            let layer = convective_layer(m, base, total_weight, settings, rule, surface);
            if layer.coverage_oktas >= l.min_coverage_oktas as f32 && layer.coverage_oktas > 0.0 {
                kept.push((layer, m.kind, false));
            }
            continue;
        }
        let reported: f64 = w
            .iter()
            .map(|&(index, weight)| {
                let own = m.members.iter().find(|x| x.0 == index);
                let cover = match own {
                    Some(x) => x.2.cover_below_oktas,
                    None => samples[index].cover_below_oktas(base),
                };
                weight * cover
            })
            .sum::<f64>()
            / total_weight;
        // Within half an okta of an overcast the summation principle cannot tell what a layer
        // adds (it turned the last hundredth of an okta a neighbour 30 km off gave into
        // several oktas of its own): above it, the layer's stations' own covers.
        let own = if below >= 8.0 - NEAR_OVERCAST_OKTAS {
            m.members
                .iter()
                .map(|x| x.1 * x.2.cover_below_oktas)
                .sum::<f64>()
        } else {
            // A layer the summation principle leaves little of its own (`BKN033 BKN041`) keeps
            // what a pilot between the layers sees of it, as far as the sky seen from below
            // stays in the class reported there.
            let top = class_top_oktas(reported);
            let in_class = own_coverage_oktas(below, top)
                .unwrap_or(0.0)
                .max(l.min_coverage_oktas);
            let seen =
                own_coverage_oktas(below, below + l.min_seen_added_oktas * presence).unwrap_or(0.0);
            own_coverage_oktas(below, reported.max(below))
                .unwrap_or(0.0)
                .max((l.min_added_oktas * presence).max(seen).min(in_class))
        }
        .min(8.0);
        if own < l.min_coverage_oktas || own <= 0.0 {
            continue;
        }
        below = 8.0 * (1.0 - (1.0 - below / 8.0) * (1.0 - own / 8.0));
        let (cloud_type, type_source) =
            layer_type(m, base, reported.max(below), settings, rule, surface);
        let explicit = weighted_thickness(m);
        let thickness_ft =
            explicit.unwrap_or_else(|| thickness_ft(cloud_type, base, reported, settings, surface));
        kept.push((
            BlockLayer {
                cloud_type,
                type_source,
                coverage_oktas: own as f32,
                base_ft_agl: base as f32,
                thickness_ft: thickness_ft as f32,
            },
            m.kind,
            explicit.is_some(),
        ));
    }
    // Tops stay under the next base of a deck (towers and a theme's own thicknesses excepted).
    let bases: Vec<(f32, LayerKind)> = kept.iter().map(|k| (k.0.base_ft_agl, k.1)).collect();
    for (layer, kind, explicit) in &mut kept {
        if *explicit || matches!(kind, LayerKind::Cb | LayerKind::Tcu) {
            continue;
        }
        let next = bases
            .iter()
            .filter(|(b, k)| {
                *b > layer.base_ft_agl && matches!(k, LayerKind::Plain | LayerKind::Fog)
            })
            .map(|(b, _)| *b)
            .fold(f32::INFINITY, f32::min);
        let room = next - layer.base_ft_agl;
        if layer.thickness_ft > room {
            layer.thickness_ft = room.max(l.min_thickness_ft as f32);
        }
    }
    kept.into_iter().map(|k| k.0).collect()
}

/// A CB or TCU layer: its stations' own amounts weighted by their share of the natural-neighbour
/// weight (a station's report exactly at the station), with a tower's extent.
fn convective_layer(
    m: &Matched,
    base_ft: f64,
    total_weight: f64,
    settings: &FieldSettings,
    rule: &CloudTypeRule,
    surface: Surface,
) -> BlockLayer {
    let own = (m
        .members
        .iter()
        .map(|x| x.1 * x.2.cover_below_oktas)
        .sum::<f64>()
        / total_weight)
        .min(8.0);
    let (cloud_type, type_source) = layer_type(m, base_ft, own, settings, rule, surface);
    let thickness_ft = weighted_thickness(m)
        .unwrap_or_else(|| thickness_ft(cloud_type, base_ft, own, settings, surface));
    BlockLayer {
        cloud_type,
        type_source,
        coverage_oktas: own as f32,
        base_ft_agl: base_ft as f32,
        thickness_ft: thickness_ft as f32,
    }
}

/// The band of the type rule a base is in (low, middle, high).
fn band_of(base_ft: f64, settings: &FieldSettings) -> Band {
    if base_ft < settings.bands.low_top_ft {
        Band::Low
    } else if base_ft > settings.bands.high_base_ft {
        Band::High
    } else {
        Band::Middle
    }
}

/// The neighbours' layers matched into layers, lowest base first.
fn match_layers<'a>(
    w: &[(usize, f64)],
    samples: &'a [StationSample],
    settings: &FieldSettings,
) -> Vec<Matched<'a>> {
    let mut all: Vec<(usize, f64, &StationLayer)> = Vec::new();
    for &(index, weight) in w {
        if weight <= 1e-12 {
            continue;
        }
        for layer in samples[index].sky.iter().flatten() {
            all.push((index, weight, layer));
        }
    }
    all.sort_by(|a, b| {
        (a.2.kind, a.2.base_ft, a.0)
            .partial_cmp(&(b.2.kind, b.2.base_ft, b.0))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let l = &settings.layers;
    let mut out: Vec<Matched> = Vec::new();
    for member in all {
        let joins = out.last().is_some_and(|m| {
            let (_, _, top) = m.members[m.members.len() - 1];
            let within = l.blend_within_ft.max(l.blend_within_fraction * top.base_ft);
            m.kind == member.2.kind
                && member.2.base_ft - top.base_ft <= within
                && m.members.iter().all(|x| x.0 != member.0)
        });
        match out.last_mut() {
            Some(m) if joins => m.members.push(member),
            _ => out.push(Matched {
                kind: member.2.kind,
                members: vec![member],
            }),
        }
    }
    // At one base a reported CB/TCU comes before the deck beside it (`FEW033CB BKN033`), so the
    // order of the layers is the report's whatever the blending.
    let rank = |k: LayerKind| match k {
        LayerKind::Fog => 0,
        LayerKind::Cb => 1,
        LayerKind::Tcu => 2,
        LayerKind::Plain => 3,
    };
    out.sort_by(|a, b| {
        (a.base_ft(), rank(a.kind))
            .partial_cmp(&(b.base_ft(), rank(b.kind)))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

/// The type of a matched layer and where it came from.
fn layer_type(
    m: &Matched,
    base_ft: f64,
    cover_below_oktas: f64,
    settings: &FieldSettings,
    rule: &CloudTypeRule,
    surface: Surface,
) -> (CloudType, TypeSource) {
    match m.kind {
        LayerKind::Cb => return (rule.reported.cb, TypeSource::Reported),
        LayerKind::Tcu => return (rule.reported.tcu, TypeSource::Reported),
        LayerKind::Fog | LayerKind::Plain => {}
    }
    // The named type carrying the most weight (the first named on ties); where some members
    // name none it needs `weight_min` of the presence.
    let mut named: Vec<((CloudType, TypeSource), f64)> = Vec::new();
    for &(_, weight, layer) in &m.members {
        if let Some(t) = layer.named {
            match named.iter_mut().find(|(n, _)| *n == t) {
                Some((_, total)) => *total += weight,
                None => named.push((t, weight)),
            }
        }
    }
    let unnamed = m.members.iter().any(|x| x.2.named.is_none());
    let min = if unnamed {
        settings.convective.weight_min * m.presence()
    } else {
        0.0
    };
    if let Some((t, _)) = named
        .into_iter()
        .rev()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|(_, weight)| *weight > 0.0 && *weight >= min)
    {
        return t;
    }
    let band = if m.kind == LayerKind::Fog {
        Band::Fog
    } else {
        band_of(base_ft, settings)
    };
    let facts = LayerFacts {
        band,
        coverage_oktas: cover_below_oktas,
        precipitation: surface.precipitation,
        spread_c: surface.spread_c,
    };
    (rule.height_rule_type(&facts), TypeSource::HeightRule)
}

/// The weighted thickness its members give (themes, VV depths); `None` when none gives one.
fn weighted_thickness(m: &Matched) -> Option<f64> {
    let (mut sum, mut total) = (0.0, 0.0);
    for &(_, weight, layer) in &m.members {
        if let Some(t) = layer.thickness_ft {
            sum += weight * t;
            total += weight;
        }
    }
    (total > 0.0).then(|| sum / total)
}

/// Base to top of a layer of `cloud_type`, feet: by type where [`Extent`](super::settings::Extent)
/// says, else by the cover seen from below.
fn thickness_ft(
    cloud_type: CloudType,
    base_ft: f64,
    cover_below_oktas: f64,
    settings: &FieldSettings,
    surface: Surface,
) -> f64 {
    let e = &settings.extent;
    let tower = |top_ft: f64| (top_ft - base_ft).max(settings.thickness_ft.few);
    let per_cover = &settings.thickness_ft;
    let o = &settings.oktas;
    match cloud_type {
        CloudType::Cumulonimbus => tower(e.cumulonimbus_top_ft(surface.temperature_c)),
        CloudType::CumulusCongestus => tower(e.congestus_top_ft(surface.temperature_c)),
        CloudType::CumulusHumilis | CloudType::CumulusMediocris => {
            e.fair_weather_cumulus_thickness_ft(surface.spread_c)
        }
        CloudType::Stratus => e.stratus_thickness_ft,
        CloudType::Fog => settings.fog.thickness_ft,
        _ if cover_below_oktas < (o.few + o.sct) / 2.0 => per_cover.few,
        _ if cover_below_oktas < (o.sct + o.bkn) / 2.0 => per_cover.sct,
        _ if cover_below_oktas < (o.bkn + o.ovc) / 2.0 => per_cover.bkn,
        _ => per_cover.ovc,
    }
}

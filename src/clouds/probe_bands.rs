//! Asking the clouds of every drift band at once ([`super::bands`]: each band is a field of
//! its own, drifting with its own wind): a point is as deep in cloud as the deepest band's
//! cloud makes it, a line of sight meets the nearest band's cloud first and crosses the stretches
//! of them all (those that overlap joined), and the optical depth along a segment adds up over
//! the bands. With one band every answer is that band's [`CloudProbe`]'s.

use glam::DVec3;

use super::config::MAX_DRIFT_BANDS;
use super::field::CloudField;
use super::probe::{BoxCache, CloudProbe, CloudsAtPoint, SightHit, Span, crossings};
use crate::weather::air::InCloudAirSettings;

/// Queries over the fields of every drift band. See the module docs.
#[derive(Debug, Clone, Copy)]
pub struct BandedProbe<'a> {
    /// Each band's probe with the heights its clouds reach ([`CloudField::heights_m`]).
    probes: [Option<(CloudProbe<'a>, (f64, f64))>; MAX_DRIFT_BANDS as usize],
    /// How far the nearest cloud is looked for, metres.
    reach_m: f64,
}

impl<'a> BandedProbe<'a> {
    /// Queries on each band's field with its own cache (at most [`MAX_DRIFT_BANDS`], lowest
    /// band first; more are left out), passing the fields without clouds.
    pub fn new(
        bands: impl IntoIterator<Item = (&'a CloudField, &'a BoxCache)>,
        settings: &'a InCloudAirSettings,
    ) -> Self {
        let mut probes = [None; MAX_DRIFT_BANDS as usize];
        for (slot, (field, cache)) in probes.iter_mut().zip(bands) {
            // A band without clouds (a sky of fewer layers) costs no query.
            *slot = field
                .has_clouds()
                .then(|| (CloudProbe::new(field, cache, settings), field.heights_m()));
        }
        Self {
            probes,
            reach_m: settings.search_radius_m,
        }
    }

    /// The probes of the bands whose clouds reach the heights `lo_m..=hi_m` (a line of sight
    /// under or over a band's clouds meets none of them).
    fn each(&self, lo_m: f64, hi_m: f64) -> impl Iterator<Item = &CloudProbe<'a>> {
        (self.probes.iter().flatten())
            .filter(move |(_, (lo, hi))| hi_m >= *lo && lo_m <= *hi)
            .map(|(probe, _)| probe)
    }

    /// [`Self::each`] for the segment `a`..`b`.
    fn along(&self, a: DVec3, b: DVec3) -> impl Iterator<Item = &CloudProbe<'a>> {
        self.each(a.z.min(b.z), a.z.max(b.z))
    }

    /// The clouds at ground point `p`: the deepest in-cloud measure (with its type), the
    /// deepest cumulonimbus and rain, the nearest cloud and cumulonimbus of any band.
    pub fn at(&self, p: DVec3) -> CloudsAtPoint {
        let mut out = CloudsAtPoint::default();
        // The nearest cloud is looked for within the reach: a band beyond it has nothing to say.
        for probe in self.each(p.z - self.reach_m, p.z + self.reach_m) {
            let here = probe.at(p);
            if here.in_cloud > out.in_cloud {
                out.in_cloud = here.in_cloud;
                out.cloud_type = here.cloud_type;
            }
            out.in_cb = out.in_cb.max(here.in_cb);
            out.in_rain = out.in_rain.max(here.in_rain);
            out.nearest_cloud_m = nearer(out.nearest_cloud_m, here.nearest_cloud_m);
            out.nearest_cb_m = nearer(out.nearest_cb_m, here.nearest_cb_m);
        }
        out
    }

    /// [`CloudProbe::line_of_sight`] over every band: the nearest band's first cloud, the
    /// optical depth through all of them, and the stretches of cloud of all bands joined.
    pub fn line_of_sight(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        let mut spans: Vec<Span> = Vec::new();
        let mut first: Option<SightHit> = None;
        let mut total = 0.0;
        for probe in self.along(a, b) {
            if let Some(hit) = probe.sight(a, b, true, f64::INFINITY, Some(&mut spans)) {
                total += hit.total_optical_depth;
                first = Some(nearest_hit(first, hit));
            }
        }
        let mut hit = first?;
        hit.total_optical_depth = total;
        hit.crossings = crossings(spans, (b - a).length());
        Some(hit)
    }

    /// [`CloudProbe::optical_depth_until`] added up over the bands, walked until the sum
    /// reaches `enough`.
    pub fn optical_depth_until(&self, a: DVec3, b: DVec3, enough: f64) -> f64 {
        let mut depth = 0.0;
        for probe in self.along(a, b) {
            if depth >= enough {
                break;
            }
            depth += probe.optical_depth_until(a, b, enough - depth);
        }
        depth
    }

    /// [`CloudProbe::first_cloud`] of the band whose first cloud is nearest (the earlier
    /// band's on a tie). A band after one that met a cloud walks only the part of the segment
    /// before it (`CloudProbe::first_cloud_before`); where it meets a nearer cloud there, it
    /// walks again as [`CloudProbe::first_cloud`] does, so the hit (its `total_optical_depth`
    /// included) is the one each band's own walk gives.
    pub fn first_cloud(&self, a: DVec3, b: DVec3) -> Option<SightHit> {
        let length = (b - a).length();
        let mut first: Option<SightHit> = None;
        for probe in self.along(a, b) {
            let hit = match &first {
                Some(so_far) if length > 0.0 => {
                    // A little past it: each band's t comes from its own drifted segment, whose
                    // length can differ from this one's in the last bit.
                    let before = so_far.distance_m / length * (1.0 + 1e-9) + 1e-12;
                    match probe.first_cloud_before(a, b, before) {
                        Some(h) if h.distance_m < so_far.distance_m => probe.first_cloud(a, b),
                        _ => None,
                    }
                }
                _ => probe.first_cloud(a, b),
            };
            if let Some(hit) = hit {
                first = Some(nearest_hit(first, hit));
            }
        }
        first
    }
}

/// The nearer of two optional distances.
fn nearer(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Of a first hit so far and another band's, the one met first (the earlier band's on a tie).
fn nearest_hit(so_far: Option<SightHit>, hit: SightHit) -> SightHit {
    match so_far {
        Some(h) if h.distance_m <= hit.distance_m => h,
        _ => hit,
    }
}

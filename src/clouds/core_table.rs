//! A cloud's cores laid out for lines of sight ([`CoreTable`]): what [`super::segment_in_runs`]
//! works out from the cloud's sprites at every line (each core's centre, the bound of its reach,
//! its reach, a flat core's turn), worked out once, in the order the walk reads them.
//!
//! A line of sight reads the centre and bound of every core of a cloud whose box it enters (a
//! cumulus's dozen or two, a deck cloud's runs near the line), and the rest of a core only when
//! it comes near. Read from the sprites, each core was a cache miss of its own on the frame
//! thread (the sprites lie far apart in a cloud's list, and the renderer's work between two
//! frames leaves none of them in cache) and a sine and cosine for a flat one: perf put
//! `segment_in_runs` at about half of the host's sight lines on the approach through the deck.
//! Here the centres and bounds of a run of cores lie side by side, two to a cache line.

use glam::DVec3;

use super::{CoreRuns, SpriteCore, above_floor, floor_slab, merge, unturned_core};
use crate::clouds::block::Cloud;
use crate::clouds::boxes::{Cull, slab};

/// What a line of sight asks of every core it may pass: its centre and the bound of its reach
/// ([`SpriteCore::reach_bound_m`]), metres from the cloud's centre.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Near {
    centre_m: DVec3,
    bound_m: f64,
}

/// A cloud's cores for lines of sight, in groups: the runs of [`CoreRuns`] (each with its
/// bounds) where the cloud has them, else one group of every core, looked at whole. See the
/// module docs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CoreTable {
    /// Per core: centre and bound of reach.
    near: Vec<Near>,
    /// Per core, in the order of `near`: the core, turned, and its reach
    /// ([`SpriteCore::reach_m`]).
    cores: Vec<(SpriteCore, f64)>,
    /// Per group: the lowest and highest corner of its cores' reach (from the cloud's centre)
    /// and where its cores end in `near`.
    groups: Vec<(DVec3, DVec3, u32)>,
    /// Whether a group is passed over where the segment misses its bounds (the runs'), or looked
    /// at whole (the one group of a cloud without runs, whose box the line entered).
    bounded: bool,
}

impl CoreTable {
    /// The table of `cloud`'s cores, grouped as `runs` (the cloud's [`CoreRuns`]) where given.
    pub(crate) fn of(cloud: &Cloud, runs: Option<&CoreRuns>) -> Self {
        // The cores in the order the walk reads them, with the groups' ends.
        let (order, groups, bounded): (Vec<usize>, Vec<(DVec3, DVec3, u32)>, bool) = match runs {
            Some(runs) if !runs.runs.is_empty() => (
                runs.sprites.iter().map(|&k| k as usize).collect(),
                runs.runs.clone(),
                true,
            ),
            _ => {
                let order: Vec<usize> = (0..cloud.sprites.len()).collect();
                (order, Vec::new(), false)
            }
        };
        let mut near = Vec::with_capacity(order.len());
        let mut cores = Vec::with_capacity(order.len());
        for k in order {
            let Some((mut core, rotation_deg)) = unturned_core(cloud, &cloud.sprites[k]) else {
                continue;
            };
            near.push(Near {
                centre_m: core.centre_m,
                bound_m: core.reach_bound_m(),
            });
            let reach = core.reach_m();
            if cloud.flat {
                core.turn(rotation_deg);
            }
            cores.push((core, reach));
        }
        // The runs hold only the cores (rain and snow left out), so their ends count the
        // table's entries; without runs, one group of them all.
        let groups = if bounded {
            groups
        } else {
            vec![(DVec3::ZERO, DVec3::ZERO, near.len() as u32)]
        };
        Self {
            near,
            cores,
            groups,
            bounded,
        }
    }
}

/// [`super::segment`] of `cloud` with its cores read from `table` (its [`CoreTable`]): the same
/// stretches, to the bit (each core's numbers are those the segment works out, and the
/// stretches are merged the same whatever order they are found in).
pub(crate) fn segment_in_table(
    cloud: &Cloud,
    table: &CoreTable,
    a: DVec3,
    b: DVec3,
    out: &mut Vec<(f64, f64)>,
) {
    out.clear();
    let floor = f64::from(cloud.floor_m);
    let Some((above_from, above_to)) = above_floor(a, b, floor) else {
        return;
    };
    let clamp = |(t0, t1): (f64, f64)| (t0.max(above_from), t1.min(above_to));
    if let Some((lo, hi)) = floor_slab(floor, cloud.floor_slab_m)
        && let Some(span) = slab(a, b, lo, hi)
    {
        out.push(clamp(span));
    }
    let d = b - a;
    let dd = d.length_squared().max(1e-12);
    let mut from = 0;
    let cull = Cull::new(a, b);
    for &(lo, hi, to) in &table.groups {
        let group = from as usize..to as usize;
        from = to;
        // A run the segment passes by holds no core it enters (each lies within its reach of
        // its centre, and the run's bounds hold those spheres and a metre); passed over only
        // where the slab test would (a run it nearly grazes is looked at, and its cores are
        // passed over on their own distances).
        if table.bounded && !cull.may_enter(lo, hi, f64::INFINITY) {
            continue;
        }
        for (near, (core, reach)) in table.near[group.clone()].iter().zip(&table.cores[group]) {
            // Passed over on the line's distance from the centre: on the bound first, then on
            // the reach (as `segment_in_runs`, the same numbers).
            let off = (near.centre_m - a).cross(d).length_squared();
            let bound = near.bound_m;
            if off > bound * bound * dd {
                continue;
            }
            if off > reach * reach * dd {
                continue;
            }
            if let Some(span) = core.segment(a, b) {
                out.push(clamp(span));
            }
            if let Some(span) = core.column_segment(a, b) {
                out.push(clamp(span));
            }
        }
    }
    out.retain(|(t0, t1)| t0 < t1);
    merge(out);
}

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
use crate::clouds::sight::{down_f32, up_f32};

/// What a line of sight asks of every core it may pass: its centre and the bound of its reach
/// ([`SpriteCore::reach_bound_m`]), then its reach ([`SpriteCore::reach_m`]), metres from the
/// cloud's centre. The centre is kept as the `f32` it was made from (a sprite's offset), so
/// that one core is 32 bytes, two to a cache line, the reach among them: read from the core
/// beside the turn and axes, it was the table's costliest miss on a frame's cold caches.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Near {
    centre_m: [f32; 3],
    bound_m: f64,
    reach_m: f64,
}

/// A group of a [`CoreTable`]: the lowest and highest corner of its cores' reach (from the
/// cloud's centre), rounded outward to `f32` (a group a line nearly grazes is looked at, and
/// its cores passed over on their own distances: the same stretches), and where its cores end
/// in the table. 28 bytes where three `f64` corners took 56.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Group {
    lo_m: [f32; 3],
    hi_m: [f32; 3],
    end: u32,
}

/// A cloud's cores for lines of sight, in groups: the runs of [`CoreRuns`] (each with its
/// bounds) where the cloud has them, else one group of every core, looked at whole. See the
/// module docs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CoreTable {
    /// Per core: centre, bound of reach and reach.
    near: Vec<Near>,
    /// Per core, in the order of `near`: the core, turned.
    cores: Vec<SpriteCore>,
    /// The groups, in the order of `near`.
    groups: Vec<Group>,
    /// Whether a group is passed over where the segment misses its bounds (the runs'), or looked
    /// at whole (the one group of a cloud without runs, whose box the line entered).
    bounded: bool,
}

impl CoreTable {
    /// The table of `cloud`'s cores, grouped as `runs` (the cloud's [`CoreRuns`]) where given.
    pub(crate) fn of(cloud: &Cloud, runs: Option<&CoreRuns>) -> Self {
        // The cores in the order the walk reads them, with the groups' ends.
        let (order, runs): (Vec<usize>, Option<&CoreRuns>) = match runs {
            Some(runs) if !runs.runs.is_empty() => (
                runs.sprites.iter().map(|&k| k as usize).collect(),
                Some(runs),
            ),
            _ => ((0..cloud.sprites.len()).collect(), None),
        };
        let mut near = Vec::with_capacity(order.len());
        let mut cores = Vec::with_capacity(order.len());
        for k in order {
            let Some((mut core, rotation_deg)) = unturned_core(cloud, &cloud.sprites[k]) else {
                continue;
            };
            let centre_m = core.centre_m.as_vec3().to_array();
            debug_assert_eq!(DVec3::from_array(centre_m.map(f64::from)), core.centre_m);
            near.push(Near {
                centre_m,
                bound_m: core.reach_bound_m(),
                reach_m: core.reach_m(),
            });
            if cloud.flat {
                core.turn(rotation_deg);
            }
            cores.push(core);
        }
        // The runs hold only the cores (rain and snow left out), so their ends count the
        // table's entries; without runs, one group of them all.
        let bounded = runs.is_some();
        let groups = if let Some(runs) = runs {
            (runs.runs.iter())
                .map(|&(lo, hi, end)| Group {
                    lo_m: lo.to_array().map(down_f32),
                    hi_m: hi.to_array().map(up_f32),
                    end,
                })
                .collect()
        } else {
            vec![Group {
                lo_m: [0.0; 3],
                hi_m: [0.0; 3],
                end: near.len() as u32,
            }]
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
    for group in &table.groups {
        let cores = from as usize..group.end as usize;
        from = group.end;
        // A run the segment passes by holds no core it enters (each lies within its reach of
        // its centre, and the run's bounds hold those spheres and a metre); passed over only
        // where the slab test would (a run it nearly grazes is looked at, and its cores are
        // passed over on their own distances).
        if table.bounded && !cull.may_enter(widened(group.lo_m), widened(group.hi_m), f64::INFINITY)
        {
            continue;
        }
        for (near, core) in table.near[cores.clone()].iter().zip(&table.cores[cores]) {
            // Passed over on the line's distance from the centre: on the bound first, then on
            // the reach (as `segment_in_runs`, the same numbers).
            let off = (widened(near.centre_m) - a).cross(d).length_squared();
            let bound = near.bound_m;
            if off > bound * bound * dd {
                continue;
            }
            if off > near.reach_m * near.reach_m * dd {
                continue;
            }
            for span in core.segments(a, b).into_iter().flatten() {
                out.push(clamp(span));
            }
        }
    }
    out.retain(|(t0, t1)| t0 < t1);
    merge(out);
}

/// A corner or centre kept as `f32`, in the `f64` the walk works in (exactly).
fn widened(v: [f32; 3]) -> DVec3 {
    DVec3::from_array(v.map(f64::from))
}

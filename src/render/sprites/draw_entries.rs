//! The entries of a view's draw list ([`GpuDrawBlock`]): one a block, back to front, with its
//! centre relative to the eye and its fade; where the eye is close to the plane between two
//! neighbouring deck blocks, their clouds interleaved farthest first, a run of one block's
//! clouds an entry (kept from frame to frame in [`Seams`]). What
//! [`draw_list`](super::draw_list) hands over once it has sorted the blocks and their lists.
//!
//! No wgpu calls.

use glam::DVec3;

use super::resident::Resident;
use crate::render::camera::Frustum;
use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud};
use crate::render::scene::Fade;

/// Or'ed into a draw block's `fade_kind` for a distant block: its sprites keep their opacity
/// beyond the draw distance (`far_fade` in `shaders/sprite_build.wgsl`, keep in sync).
const DISTANT_BLOCK: u32 = 4;

/// A fade as a draw block's `fade_kind` (0 steady, 1 forming, 2 dissipating) and its progress.
pub(in crate::render) fn fade_code(fade: Fade) -> (u32, f32) {
    match fade {
        Fade::Steady => (0, 1.0),
        Fade::Forming(p) => (1, p.clamp(0.0, 1.0)),
        Fade::Dissipating(q) => (2, q.clamp(0.0, 1.0)),
    }
}

/// The sprites of a frame's distant blocks, which its draw list puts first: they are drawn
/// behind the impostor ring, which holds nearer clouds.
pub(in crate::render) fn distant_sprites(draws: &[GpuDrawBlock], total: u32) -> u32 {
    draws
        .iter()
        .find(|d| d.fade_kind & DISTANT_BLOCK == 0)
        .map_or(total, |d| d.first)
}

/// At most this many blocks have their clouds interleaved together: a camera on the corner of
/// four blocks, each in two generations during a weather change. A block that would make a
/// group larger stays whole (a host's own layout of blocks could chain them without end).
const MAX_INTERLEAVED: usize = 8;

/// A view's groups of blocks drawn with their clouds interleaved ([`draw_entries`]), kept from
/// frame to frame: a group's merge is worked out again only when one of its blocks' lists has
/// been sorted again since, or the group has changed. A block's own list is kept as long as
/// the camera has not used up its clouds' slack (Wang's thresholds); a merge of lists kept
/// that long is as good, and a frame whose groups' lists all stand touches none of their
/// clouds.
#[derive(Debug, Default)]
pub(in crate::render) struct Seams {
    kept: Vec<Merged>,
    /// Scratch: the squared distances of the clouds of the group being merged.
    d2: Vec<f64>,
}

/// The next [`Resident::list_serial`]: unique among all the lists written, so that a block
/// that went and came back with the same id does not find the merges of its old list.
pub(super) static LIST_SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// A group's merge: its blocks, farthest first (id and [`Resident::list_serial`]), and its
/// runs in drawing order.
#[derive(Debug)]
struct Merged {
    blocks: Vec<(u64, u64)>,
    runs: Vec<Run>,
    /// Whether the frame drew it (one that is not is forgotten).
    drawn: bool,
}

/// A run of one block's clouds in a group's merge: which block of the group and the part of
/// its list (from `start`, `len` clouds). A frame that keeps the merge reads only these and
/// the sprite counts at their ends, none of the block's clouds (but across the view's edge).
#[derive(Debug, Clone, Copy)]
struct Run {
    member: u8,
    start: u32,
    len: u32,
}

/// A block of a draw list: its squared distance from the view's eye, the block, and its drawn
/// clouds' list back to front (`list`, at `list_base` of the bound list buffer) with their
/// sprites.
#[derive(Clone, Copy)]
pub(super) struct Listed<'a> {
    pub(super) d2: f64,
    pub(super) r: &'a Resident,
    list: &'a [GpuListCloud],
    list_base: u32,
    sprites: u32,
}

impl<'a> Listed<'a> {
    /// The sky camera's view of a block: its list as last sorted.
    pub(super) fn resident(d2: f64, r: &'a Resident) -> Self {
        Self {
            d2,
            r,
            list: &r.list,
            list_base: r.place.as_ref().map_or(0, |p| p.1.start),
            sprites: r.list_sprites,
        }
    }

    /// The squared distances from `eye_m` of the clouds of its list, in its order, onto `d2`
    /// (one pass over the list; a cloud not found is infinitely near, drawn last).
    fn clouds_d2(&self, eye_m: DVec3, d2: &mut Vec<f64>) {
        let start = self.r.place.as_ref().map_or(0, |p| p.1.start);
        let at = self.r.offset_m() - eye_m;
        let clouds = &self.r.seen;
        d2.extend(self.list.iter().map(|e| {
            clouds
                .get(e.cloud.wrapping_sub(start) as usize)
                .map_or(f64::NEG_INFINITY, |c| (c.centre_m + at).length_squared())
        }));
    }

    /// Sprites before the `k`th cloud of its list.
    fn sprites_before(&self, k: usize) -> u32 {
        self.list.get(k).map_or(self.sprites, |e| e.first)
    }

    /// The entry of clouds `part` of its list, its first sprite `first`.
    fn entry(&self, part: std::ops::Range<usize>, eye_m: DVec3, first: u32) -> GpuDrawBlock {
        let (fade_kind, fade_progress) = fade_code(self.r.fade());
        GpuDrawBlock {
            origin_rel: (self.r.centre_m() - eye_m).as_vec3().to_array(),
            fade_kind: fade_kind | if self.r.distant { DISTANT_BLOCK } else { 0 },
            first,
            list_base: self.list_base + part.start as u32,
            list_len: part.len() as u32,
            fade_progress,
        }
    }
}

/// What of a view a draw list keeps to: its frustum (relative to the eye), and the Earth's
/// radius at the eye (0: the flat frame) the sprite shader bends the clouds by. A cloud whose
/// every quad lies wholly outside the frustum gives the frame no fragment, but its sprites
/// would still be built and their corners shaded and clipped, a cost per sprite that on the
/// software rasteriser is most of a sprite's; a block across the frustum's edge (the ones
/// under and beside the eye) is drawn without its clouds out of view.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sight<'a> {
    pub frustum: &'a Frustum,
    pub earth_radius_m: f32,
}

/// `sqrt(2) - 1`: a quad of half sides `a` and `b` (at most `h`, its sprite's half side: a
/// pancake's height grows at most to its width) reaches `sqrt(a^2 + b^2) <= sqrt(2) h` from its
/// centre, where a cloud's radius counts `h`.
const CORNER_REACH: f32 = std::f32::consts::SQRT_2 - 1.0;

impl Sight<'_> {
    /// How far the shader's bending of the flat frame onto the round Earth (`earth_curved` in
    /// `shaders/shared/frame.wgsl`) moves a point within `reach_m` of the eye and `height_m`
    /// above or below it, at most, metres (the drop `s^2 / 2R` and the stretch `s |z| / R`,
    /// rounded up, plus a metre for f32).
    fn bend_m(&self, reach_m: f32, height_m: f32) -> f32 {
        if self.earth_radius_m <= 0.0 {
            return 1.0;
        }
        let r = self.earth_radius_m;
        reach_m * (reach_m + height_m.abs()) / r + 1.0
    }

    /// Whether a sphere (relative to the eye) lies wholly inside the frustum.
    fn holds(&self, centre: glam::Vec3, radius_m: f32) -> bool {
        let r = radius_m + self.bend_m(centre.length() + radius_m, centre.z.abs() + radius_m);
        self.frustum.holds_sphere(centre, r)
    }

    /// Whether any of a cloud's quads (its centre relative to the eye, its radius and its
    /// largest sprite's half side) can reach into the frustum; or a block's, its radius over
    /// all its clouds.
    pub(super) fn sees_cloud(&self, centre: glam::Vec3, radius_m: f32, half_side_m: f32) -> bool {
        // Widths and heights reach the shader as half floats (a part in 2,048).
        let reach = (radius_m + CORNER_REACH * half_side_m) * 1.001 + 1.0;
        let r = reach + self.bend_m(centre.length() + reach, centre.z.abs() + reach);
        self.frustum.sees_sphere(centre, r)
    }
}

impl Listed<'_> {
    /// The entries of the clouds `part` of its list that `sight` can see (all of them for a
    /// distant block, or one wholly in view): a run of clouds in view an entry, from sprite
    /// `total` on, which it advances.
    fn push_seen(
        &self,
        part: std::ops::Range<usize>,
        (eye_m, sight): (DVec3, Option<&Sight>),
        total: &mut u32,
        out: &mut Vec<GpuDrawBlock>,
    ) {
        let sprites =
            |p: &std::ops::Range<usize>| self.sprites_before(p.end) - self.sprites_before(p.start);
        let whole = |out: &mut Vec<GpuDrawBlock>, total: &mut u32, p: std::ops::Range<usize>| {
            if p.is_empty() {
                return;
            }
            let n = sprites(&p);
            out.push(self.entry(p, eye_m, *total));
            *total += n;
        };
        let centre = (self.r.centre_m() - eye_m).as_vec3();
        let Some(sight) = sight.filter(|s| {
            !self.r.distant && !s.holds(centre, self.r.radius_m as f32 * (1.0 + CORNER_REACH))
        }) else {
            whole(out, total, part);
            return;
        };
        let start = self.r.place.as_ref().map_or(0, |p| p.1.start);
        let at = self.r.offset_m() - eye_m;
        let mut run = part.start..part.start;
        for k in part.clone() {
            let seen = self
                .r
                .seen
                .get(self.list[k].cloud.wrapping_sub(start) as usize)
                .is_none_or(|c| {
                    sight.sees_cloud(
                        (c.centre_m + at).as_vec3(),
                        c.radius_m,
                        c.largest_half_side_m,
                    )
                });
            if seen {
                run.end = k + 1;
            } else {
                whole(out, total, run);
                run = k + 1..k + 1;
            }
        }
        whole(out, total, run);
    }
}

/// The draw list of `order` (back to front, distant blocks first, seen from `eye_m`): one
/// entry for each block, except where the eye is close to the plane that decides the order of
/// two neighbouring deck blocks. Drawn whole, one after the other, their overlapping sprites along
/// that plane blend out of their distance order: with the eye on a block boundary every sprite
/// of one side is drawn over the other's, and a straight seam runs along the boundary from the
/// eye to the horizon. So their clouds are drawn interleaved, farthest first, as the clouds of
/// one block are: each run of one block's clouds is an entry of its own (a part of its cloud
/// list). `seams` keeps the merges from frame to frame. Returns the sprites.
pub(super) fn draw_entries(
    order: &[Listed],
    (eye_m, sight): (DVec3, Option<&Sight>),
    seams: &mut Seams,
    out: &mut Vec<GpuDrawBlock>,
) -> u32 {
    let mut total = 0u32;
    let Some(groups) = seam_groups(order) else {
        // The eye is near no plane between two neighbours.
        seams.kept.clear();
        for b in order {
            b.push_seen(0..b.list.len(), (eye_m, sight), &mut total, out);
        }
        return total;
    };
    let mut sizes = vec![0u8; order.len()];
    for &g in &groups {
        sizes[g as usize] += 1;
    }
    seams.kept.iter_mut().for_each(|m| m.drawn = false);
    let mut members: Vec<Listed> = Vec::with_capacity(MAX_INTERLEAVED);
    let mut key: Vec<(u64, u64)> = Vec::with_capacity(MAX_INTERLEAVED);
    for (i, b) in order.iter().enumerate() {
        let group = groups[i] as usize;
        if sizes[group] == 1 {
            b.push_seen(0..b.list.len(), (eye_m, sight), &mut total, out);
            continue;
        } else if group != i {
            // A group is drawn where its farthest block (its first) is, and skipped after.
            continue;
        }
        members.clear();
        let mut left = sizes[group] as usize;
        for (j, &g) in groups.iter().enumerate().skip(i) {
            if g as usize == group {
                members.push(order[j]);
                left -= 1;
                if left == 0 {
                    break;
                }
            }
        }
        key.clear();
        key.extend(members.iter().map(|b| (b.r.block.id, b.r.list_serial)));
        let at = match seams.kept.iter().position(|m| m.blocks == key) {
            Some(at) => at,
            None => {
                let runs = interleave(&members, eye_m, &mut seams.d2);
                seams.kept.push(Merged {
                    blocks: key.clone(),
                    runs,
                    drawn: false,
                });
                seams.kept.len() - 1
            }
        };
        let merged = &mut seams.kept[at];
        merged.drawn = true;
        // Each run is its block's entry with its part of the list.
        for run in &merged.runs {
            let part = run.start as usize..(run.start + run.len) as usize;
            members[run.member as usize].push_seen(part, (eye_m, sight), &mut total, out);
        }
    }
    seams.kept.retain(|m| m.drawn);
    total
}

/// For each block of `order` (back to front) the index of the first block of its group, its
/// own where it has none; `None` where no block has one. Two neighbouring deck blocks (their
/// spheres overlap) are grouped when the eye is within their largest cloud's radius of the
/// plane half way between their centres: nearer, some of the farther block's sprites that
/// overlap the nearer one's on screen are nearer the eye than they are. Squared distances
/// differ by `2 |c_a - c_b|` times the eye's distance from that plane, so only blocks a few
/// places apart in `order` are looked at (about three on a grid of equal blocks, however far
/// out).
fn seam_groups(order: &[Listed]) -> Option<Vec<u32>> {
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let n = order.len();
    // Made when the first pair is found.
    let mut parent: Vec<u32> = Vec::new();
    let mut size: Vec<u8> = Vec::new();
    // Only decks: their cells stand side by side up to the blocks' sides, so two decks'
    // sprites overlap all along the boundary and the blend out of order is a line. Heaped
    // clouds have gaps between them; where two overlap across a boundary the error is one
    // cloud's, and grouping them made the cumulus cruise's update dearer by a third.
    let interleaved = |b: &Listed| b.r.deck && !b.r.distant;
    let (mut radius, mut reach) = (0.0f64, 0.0f64);
    for b in order.iter().filter(|b| interleaved(b)) {
        radius = radius.max(b.r.radius_m);
        reach = reach.max(b.r.largest_cloud_m);
    }
    let window = 4.0 * reach * radius;
    for (i, a) in order.iter().enumerate() {
        if !interleaved(a) {
            continue;
        }
        for (j, b) in order.iter().enumerate().skip(i + 1) {
            let dd2 = a.d2 - b.d2;
            if dd2 > window {
                break;
            }
            let apart = (a.r.centre_m() - b.r.centre_m()).length();
            let reach = a.r.largest_cloud_m.max(b.r.largest_cloud_m);
            if !interleaved(b) || apart >= a.r.radius_m + b.r.radius_m || dd2 > 2.0 * reach * apart
            {
                continue;
            }
            if parent.is_empty() {
                parent = (0..n as u32).collect();
                size = vec![1u8; n];
            }
            let (ri, rj) = (root(&mut parent, i as u32), root(&mut parent, j as u32));
            let joined = size[ri as usize] as usize + size[rj as usize] as usize;
            if ri != rj && joined <= MAX_INTERLEAVED {
                // The root is the group's farthest block (its lowest index).
                let (lo, hi) = (ri.min(rj), ri.max(rj));
                parent[hi as usize] = lo;
                size[lo as usize] = joined as u8;
            }
        }
    }
    if parent.is_empty() {
        return None;
    }
    Some((0..n as u32).map(|i| root(&mut parent, i)).collect())
}

/// The runs of the clouds of `members` (a group of [`seam_groups`], farthest block first)
/// merged farthest first by their distance from `eye_m` now, in drawing order. Each block's
/// list keeps its own order, so each run of one block's clouds is a part of its list. `d2` is
/// scratch for the clouds' squared distances.
fn interleave(members: &[Listed], eye_m: DVec3, d2: &mut Vec<f64>) -> Vec<Run> {
    // Each member's distances, worked out once: member `m`'s are `d2[from[m]..from[m + 1]]`.
    let mut from = [0usize; MAX_INTERLEAVED + 1];
    d2.clear();
    for (m, b) in members.iter().enumerate() {
        from[m] = d2.len();
        b.clouds_d2(eye_m, d2);
        from[m + 1] = d2.len();
    }
    let mut heads = from;
    // Whether member `a`'s cloud at `da` goes before member `b`'s at `db`: the farther first;
    // equally far, the farther block's (the lower index).
    let before = |(a, da): (usize, f64), (b, db): (usize, f64)| {
        da.total_cmp(&db).then(b.cmp(&a)) == std::cmp::Ordering::Greater
    };
    let mut runs = Vec::new();
    loop {
        // The member whose next cloud is farthest, and the farthest of the others'.
        let mut next: Option<(usize, f64)> = None;
        let mut other: Option<(usize, f64)> = None;
        for m in 0..members.len() {
            if heads[m] < from[m + 1] {
                let here = (m, d2[heads[m]]);
                if next.is_none_or(|x| before(here, x)) {
                    other = next;
                    next = Some(here);
                } else if other.is_none_or(|x| before(here, x)) {
                    other = Some(here);
                }
            }
        }
        let Some((m, _)) = next else {
            return runs;
        };
        // Its run: its clouds that go before the others' next.
        let start = heads[m];
        let mut end = start + 1;
        while end < from[m + 1] && other.is_none_or(|o| before((m, d2[end]), o)) {
            end += 1;
        }
        heads[m] = end;
        let part = start - from[m]..end - from[m];
        runs.push(Run {
            member: m as u8,
            start: part.start as u32,
            len: part.len() as u32,
        });
    }
}

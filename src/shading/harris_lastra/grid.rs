//! The occluder search of the light pass: a grid across the light, so that a particle's
//! occluders (the particles nearer the light whose discs cover its centre) are looked for among
//! its neighbours across the light, not among all of its cloud's particles.

use glam::Vec3;

use super::Particle;

/// Scratch space of [`super::HarrisLastra::light`], kept between calls so that it allocates nothing.
#[derive(Debug, Clone, Default)]
pub struct LightScratch {
    /// Particle indices by rank along the light.
    pub(super) order: Vec<u32>,
    /// By rank, the grid cell.
    pub(super) cell_of: Vec<u32>,
    /// Per cell where its ranks start in `in_cell` (the entry after the last cell: the end).
    pub(super) cell_start: Vec<u32>,
    /// Ranks grouped by cell, ascending within a cell.
    pub(super) in_cell: Vec<u32>,
    /// The occluder candidates of one particle, ranks ascending.
    pub(super) candidates: Vec<u32>,
}

/// A grid across the light: the particles' centres projected on the plane normal to it, in
/// square cells at least as wide as the largest particle's radius, so that every particle
/// whose disc covers a point lies in that point's cell or one of its eight neighbours.
pub(super) struct Grid {
    nx: u32,
    ny: u32,
}

/// Most cells along a side of the grid.
const MAX_CELLS: f32 = 128.0;

impl Grid {
    pub(super) fn new(
        particles: &[Particle],
        order: &[u32],
        to_light: Vec3,
        cell_of: &mut Vec<u32>,
        cell_start: &mut Vec<u32>,
        in_cell: &mut Vec<u32>,
    ) -> Self {
        let (u, v) = to_light.any_orthonormal_pair();
        let across = |p: &Particle| glam::Vec2::new(p.centre_m.dot(u), p.centre_m.dot(v));
        let mut lo = glam::Vec2::splat(f32::MAX);
        let mut hi = glam::Vec2::splat(f32::MIN);
        let mut r_max = 1e-3f32;
        for p in particles {
            let q = across(p);
            lo = lo.min(q);
            hi = hi.max(q);
            r_max = r_max.max(p.radius_m);
        }
        let extent = (hi - lo).max_element().max(0.0);
        let cell = r_max.max(extent / MAX_CELLS);
        let nx = ((hi.x - lo.x).max(0.0) / cell) as u32 + 1;
        let ny = ((hi.y - lo.y).max(0.0) / cell) as u32 + 1;
        cell_of.clear();
        cell_of.extend(order.iter().map(|&i| {
            let c = (across(&particles[i as usize]) - lo) / cell;
            let (x, y) = ((c.x as u32).min(nx - 1), (c.y as u32).min(ny - 1));
            y * nx + x
        }));
        // Counting sort of the ranks by cell (stable: ascending ranks within a cell): counts
        // two ahead, summed, then each cell's cursor one ahead, which leaves every entry at
        // its cell's start.
        let cells = (nx * ny) as usize;
        cell_start.clear();
        cell_start.resize(cells + 2, 0);
        for &c in cell_of.iter() {
            cell_start[c as usize + 2] += 1;
        }
        for i in 1..cell_start.len() {
            cell_start[i] += cell_start[i - 1];
        }
        in_cell.clear();
        in_cell.resize(order.len(), 0);
        for (rank, &c) in cell_of.iter().enumerate() {
            let at = &mut cell_start[c as usize + 1];
            in_cell[*at as usize] = rank as u32;
            *at += 1;
        }
        Self { nx, ny }
    }

    /// The ranks before `rank` in its cell and the eight around it, ascending.
    pub(super) fn candidates(
        &self,
        rank: u32,
        cell_of: &[u32],
        cell_start: &[u32],
        in_cell: &[u32],
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let c = cell_of[rank as usize];
        let (cx, cy) = ((c % self.nx) as i64, (c / self.nx) as i64);
        for y in (cy - 1).max(0)..=(cy + 1).min(self.ny as i64 - 1) {
            for x in (cx - 1).max(0)..=(cx + 1).min(self.nx as i64 - 1) {
                let cell = (y * self.nx as i64 + x) as usize;
                let span = cell_start[cell] as usize..cell_start[cell + 1] as usize;
                out.extend(in_cell[span].iter().take_while(|&&r| r < rank));
            }
        }
        out.sort_unstable();
    }
}

//! Filling a layer whose cover is uneven over its block ([`LayerCover`]), for `generate`:
//! a scattered layer stops adding clouds where its coverage grid is already as covered as the
//! cover there asks ([`window_full`]); a lattice keeps its cells by key against the cover at each
//! ([`choose_by_cover`]). A block of even cover uses neither (it is generated as before issue 31).

use glam::DVec2;

use super::generate::{GRID, OVERCAST_OKTAS};
use crate::weather::BLOCK_SIZE_M;
#[cfg(doc)]
use crate::weather::LayerCover;

/// Cells either side of a candidate's cell in the window whose cover [`window_full`] weighs
/// (1.2 km square: a few clouds wide).
const WINDOW: usize = 6;

/// Whether the coverage grid around `p` (block metres) is already covered as much as the
/// `shares` of its cells ask: then a cloud there would overfill it (where the cover is high,
/// clouds overlap and the covered share lags the cover; without this the block's mean was met
/// with its cloudier side short).
pub(super) fn window_full(grid: &[bool], shares: &[f64], p: DVec2) -> bool {
    let cell = BLOCK_SIZE_M / GRID as f64;
    let at = |v: f64| ((v / cell).floor().max(0.0) as usize).min(GRID - 1);
    let (x, y) = (at(p.x), at(p.y));
    let (mut covered, mut wanted) = (0.0, 0.0);
    for row in y.saturating_sub(WINDOW)..(y + WINDOW).min(GRID) {
        for c in row * GRID + x.saturating_sub(WINDOW)..row * GRID + (x + WINDOW).min(GRID) {
            covered += grid[c] as u8 as f64;
            wanted += shares[c];
        }
    }
    covered >= wanted
}

/// Orders a block's lattice `cells` (key, column, row) by their key against the cover at each
/// (`oktas_at` the cell): where it is overcast (at least [`OVERCAST_OKTAS`]) first, then the
/// lowest key / cover first, so that a cell is kept about as often as the cover is there;
/// returns how many to keep (the cells' covers added up, the overcast ones whole).
pub(super) fn choose_by_cover(
    cells: &mut [(u64, i64, i64)],
    oktas_at: impl Fn(i64, i64) -> f32,
) -> usize {
    let mut wanted = 0.0;
    let mut ranked: Vec<(bool, f64, (u64, i64, i64))> = Vec::with_capacity(cells.len());
    for &c in cells.iter() {
        let oktas = oktas_at(c.1, c.2);
        let share = (oktas as f64 / 8.0).clamp(0.0, 1.0);
        let overcast = oktas >= OVERCAST_OKTAS;
        wanted += if overcast { 1.0 } else { share };
        let key = c.0 as f64 / u64::MAX as f64;
        let rank = if share > 0.0 {
            key / share
        } else {
            f64::INFINITY
        };
        ranked.push((!overcast, rank, c));
    }
    ranked.sort_by(|a, b| {
        (a.0.cmp(&b.0))
            .then(a.1.total_cmp(&b.1))
            .then(a.2.cmp(&b.2))
    });
    for (slot, r) in cells.iter_mut().zip(&ranked) {
        *slot = r.2;
    }
    wanted.round() as usize
}

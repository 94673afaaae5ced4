//! The part of each cell of the sprite sheet its texture covers, to cut the sprites' quads to
//! (particle trimming): a puff fills a third to a half of its square, and the transparent rest
//! of the quad still costs its fragments (blended, depth-faded, into both cloud targets) at
//! every scale on every device. The cells' alpha is read from the sheet the sky is given, so a
//! host's own sheet is cut to its own shapes.
//!
//! The cut keeps every texel whose alpha is above zero at the levels near sprites sample
//! ([`EXACT_LEVELS`]), with the half texel a bilinear lookup reaches beyond it: there the quad
//! draws what the whole square drew. A sprite small enough on screen to sample a coarser level
//! (under about 30 pixels across) loses the faintest rim of its coarsest texels.

use super::sheet::SpriteSheet;

/// Cells along a side of the sheet (4 x 4 textures, Wang 2003 figure 6).
const CELLS_PER_ROW: u32 = 4;

/// Mip levels 0 to this one are drawn exactly as the uncut quad draws them (level 2: a cell of
/// 32 texels, sampled by sprites down to about 32 pixels across).
const EXACT_LEVELS: usize = 2;

/// Per cell (row-major, as the shader's `cell` numbers them) the part of the cell its texture
/// covers: `[u_min, v_min, u_max, v_max]`, fractions of the cell, v down. The whole cell where
/// a cell's pixels are missing or all transparent.
pub(in crate::render) fn cell_crops(sheet: &SpriteSheet) -> [[f32; 4]; 16] {
    std::array::from_fn(|cell| {
        let mut crop: Option<[f32; 4]> = None;
        for (level, data) in sheet.mips.iter().enumerate().take(EXACT_LEVELS + 1) {
            let side = (sheet.size_px >> level).max(1);
            let Some(level_crop) = level_crop(data, side, cell as u32) else {
                continue;
            };
            crop = Some(match crop {
                None => level_crop,
                Some(c) => [
                    c[0].min(level_crop[0]),
                    c[1].min(level_crop[1]),
                    c[2].max(level_crop[2]),
                    c[3].max(level_crop[3]),
                ],
            });
        }
        crop.unwrap_or([0.0, 0.0, 1.0, 1.0])
    })
}

/// The crop of `cell` at one level of side `side` pixels: the box of its texels with alpha
/// above zero, half a texel wider on every side, as fractions of the cell; `None` where the
/// cell is transparent or the level is too small to hold it.
fn level_crop(data: &[u8], side: u32, cell: u32) -> Option<[f32; 4]> {
    let cell_px = side / CELLS_PER_ROW;
    if cell_px == 0 || data.len() < (side * side * 4) as usize {
        return None;
    }
    let (x0, y0) = (
        (cell % CELLS_PER_ROW) * cell_px,
        (cell / CELLS_PER_ROW) * cell_px,
    );
    let (mut lo, mut hi) = ([u32::MAX; 2], [0u32; 2]);
    for y in 0..cell_px {
        for x in 0..cell_px {
            let alpha = data[(((y0 + y) * side + x0 + x) * 4 + 3) as usize];
            if alpha > 0 {
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
            }
        }
    }
    if lo[0] > hi[0] {
        return None;
    }
    let n = cell_px as f32;
    let fraction = |texel: f32| (texel / n).clamp(0.0, 1.0);
    Some([
        fraction(lo[0] as f32 - 0.5),
        fraction(lo[1] as f32 - 0.5),
        fraction(hi[0] as f32 + 1.5),
        fraction(hi[1] as f32 + 1.5),
    ])
}

/// The crops as WGSL (`CELL_CROP` in `shaders/sprite_build.wgsl`), put in front of the shader
/// when its pipeline is built: constants for the sky's life, no uniform to write each frame.
pub(in crate::render) fn crops_wgsl(crops: &[[f32; 4]; 16]) -> String {
    let cells: Vec<String> = crops
        .iter()
        .map(|c| format!("vec4<f32>({:?}, {:?}, {:?}, {:?})", c[0], c[1], c[2], c[3]))
        .collect();
    format!(
        "const CELL_CROP = array<vec4<f32>, 16>(\n    {},\n);\n",
        cells.join(",\n    ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crops_keep_every_visible_texel_and_cut_the_transparent_margins() {
        let sheet = SpriteSheet::generated();
        let crops = cell_crops(&sheet);
        let side = sheet.size_px;
        let cell_px = side / CELLS_PER_ROW;
        let mut kept_area = 0.0;
        for (cell, crop) in crops.iter().enumerate() {
            let (x0, y0) = (
                (cell as u32 % CELLS_PER_ROW) * cell_px,
                (cell as u32 / CELLS_PER_ROW) * cell_px,
            );
            for y in 0..cell_px {
                for x in 0..cell_px {
                    let alpha = sheet.mips[0][(((y0 + y) * side + x0 + x) * 4 + 3) as usize];
                    let (u, v) = (
                        (x as f32 + 0.5) / cell_px as f32,
                        (y as f32 + 0.5) / cell_px as f32,
                    );
                    let inside = u > crop[0] && u < crop[2] && v > crop[1] && v < crop[3];
                    assert!(
                        alpha == 0 || inside,
                        "cell {cell}: texel ({x}, {y}) of alpha {alpha} outside {crop:?}"
                    );
                }
            }
            kept_area += (crop[2] - crop[0]) * (crop[3] - crop[1]) / 16.0;
        }
        // The shipped puffs leave a quarter or more of the sheet's area to cut.
        assert!(kept_area < 0.8, "{kept_area}: {crops:?}");
    }

    #[test]
    fn an_opaque_or_empty_cell_is_kept_whole() {
        // Every texel opaque, then every texel transparent.
        for fill in [255u8, 0] {
            let sheet = SpriteSheet {
                size_px: 8,
                mips: vec![vec![fill; 8 * 8 * 4]],
            };
            let crops = cell_crops(&sheet);
            assert!(
                crops.iter().all(|c| *c == [0.0, 0.0, 1.0, 1.0]),
                "texels of {fill}: {crops:?}"
            );
        }
    }

    #[test]
    fn the_wgsl_holds_sixteen_cells() {
        let wgsl = crops_wgsl(&[[0.25, 0.0, 1.0, 0.5]; 16]);
        assert_eq!(wgsl.matches("vec4<f32>(0.25, 0.0, 1.0, 0.5)").count(), 16);
        assert!(wgsl.starts_with("const CELL_CROP = array<vec4<f32>, 16>("));
    }
}

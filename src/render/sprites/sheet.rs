//! The sprite texture sheet the sky draws its cloud sprites with: what a host hands
//! [`Sky::new`](crate::render::Sky::new) in its [`SkyConfig`](crate::render::SkyConfig) (the
//! clouds stage's procedural sheet by default). A leaf: the sky, the sprite build's crops and
//! the far field read it, and it reads none of them.

use glam::Vec3;

/// The 4 x 4 sprite texture sheet, RGBA8 (linear), level 0 first, each level half the last.
#[derive(Debug, Clone, PartialEq)]
pub struct SpriteSheet {
    /// Side of level 0, pixels.
    pub size_px: u32,
    /// Pixel data of each mip level, RGBA8 row-major.
    pub mips: Vec<Vec<u8>>,
}

impl SpriteSheet {
    /// The clouds stage's procedural 16-texture sheet (Wang 2003 figure 6), with its mips.
    pub fn generated() -> Self {
        let sheet = crate::clouds::TextureSheet::generate();
        Self {
            size_px: sheet.level_size_px(0),
            mips: (0..sheet.level_count())
                .map(|l| sheet.level(l).to_vec())
                .collect(),
        }
    }

    /// The alpha-weighted mean colour of the textures in `cells` (row-major cells of the
    /// clouds stage's layout, [`crate::clouds::CELLS_PER_ROW`] a row), from the smallest mip
    /// level; black where they have no alpha.
    pub fn mean_rgb(&self, cells: std::ops::Range<u8>) -> Vec3 {
        let Some((level, bytes)) = self.mips.iter().enumerate().next_back() else {
            return Vec3::ZERO;
        };
        let per_row = crate::clouds::CELLS_PER_ROW as usize;
        let side = ((self.size_px >> level) as usize).max(per_row);
        let cell_px = side / per_row;
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
        for cell in cells
            .filter(|&c| c < crate::clouds::TEXTURE_COUNT)
            .map(usize::from)
        {
            let (cx, cy) = (cell % per_row * cell_px, cell / per_row * cell_px);
            for y in cy..cy + cell_px {
                for x in cx..cx + cell_px {
                    let Some(p) = bytes.get((y * side + x) * 4..(y * side + x) * 4 + 4) else {
                        continue;
                    };
                    let a = f32::from(p[3]) / 255.0;
                    sum += Vec3::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2])) * a;
                    weight += a;
                }
            }
        }
        if weight > 0.0 {
            sum / (255.0 * weight)
        } else {
            Vec3::ZERO
        }
    }
}

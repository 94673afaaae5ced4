//! The output of the clouds stage: plain data a renderer reads (no wgpu).
//!
//! A [`CloudBlock`] holds the clouds generated for one 4 km x 4 km block; a [`Cloud`] holds its
//! sprites (Wang 2003 §3: 5 to 400 camera-facing, alpha-blended textured quads). Cloud centres are
//! f64 world metres (east, north, up above mean sea level); everything inside a cloud is f32
//! metres relative to the centre, so a renderer can send it to the GPU relative to the camera.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::rng::{FNV_OFFSET, fnv1a};
use crate::weather::{BLOCK_SIZE_M, BlockIndex, CloudType};

/// One camera-facing sprite (or, for a flat cloud, one horizontal rectangle).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sprite {
    /// Centre relative to the cloud centre, metres east, north, up.
    pub offset_m: [f32; 3],
    /// Width of the quad, metres.
    pub width_m: f32,
    /// Height of the quad (for a flat cloud: its north-south extent), metres.
    pub height_m: f32,
    /// Rotation of the texture in the quad's plane, degrees (0 for non-square sprites).
    pub rotation_deg: f32,
    /// Texture cell on the sheet, 0..16 (row-major, see [`super::sheet`]).
    pub texture: u8,
    /// Index into [`Cloud::shading_groups`].
    pub shading_group: u16,
    /// Distance of the centre from the cloud centre over the cloud radius, 0..=1 (§4 uses it).
    pub radius_fraction: f32,
    /// Formation/dissipation transparency factor, 0 (invisible) ..= 1 (Wang 2003 eq. 3).
    pub alpha_morph: f32,
    /// Turns only about the vertical, so its flat bottom stays level: the flat-bottomed sprites
    /// on a heaped cloud's rim, a level base from the side that fades out seen from below
    /// (where the foggy ones under the inside make the smooth grey underside).
    #[serde(default)]
    pub upright: bool,
    /// Falling rain or snow under the cloud (a shaft), not cloud: drawn darker and greyer.
    #[serde(default)]
    pub precipitation: bool,
    /// Stands on the cloud's base (a heap's or a storm cell's flat underside, a deck's floor):
    /// its dense core spans its whole width ([`super::core`]), as the overlapping undersides
    /// close a base seen from below.
    #[serde(default)]
    pub base: bool,
}

/// A shading group: sprites shaded as one clump (Wang 2003 §5.2, 1 to 30 sprites).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShadingGroup {
    /// Group centre relative to the cloud centre, metres east, north, up.
    pub centre_m: [f32; 3],
}

/// One of the five ambient colour levels of a cloud (Wang 2003 §5.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColourLevel {
    /// Height of the level relative to the cloud centre, metres.
    pub height_m: f32,
    /// Colour and alpha, linear 0..=1.
    pub rgba: [f32; 4],
}

/// One cloud: a cluster of sprites around a centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cloud {
    /// Centre, world metres east, north and up (above mean sea level).
    pub centre_m: DVec3,
    /// The type it was made as.
    pub cloud_type: CloudType,
    /// Index of the weather layer it belongs to (0 = lowest).
    pub layer: u8,
    /// Largest distance of a sprite centre from the cloud centre, metres.
    pub radius_m: f32,
    /// Drawn as flat horizontal rectangles instead of camera-facing sprites (cirrus, §7.1).
    pub flat: bool,
    /// A deck's sunlit depth, metres (the type's `sunlit_depth_m` for a layer on the lattice;
    /// 0 for a cloud lit from every side).
    #[serde(default)]
    pub sunlit_depth_m: f32,
    /// A heap's shaded base, metres above its base (the type's `shaded_base_m`; 0 for none).
    #[serde(default)]
    pub shaded_base_m: f32,
    /// The cloud's flat base, metres from its centre (negative: below it): nothing under it is
    /// cloud to a probe ([`super::core`]), so every cloud is first met from below at its base.
    #[serde(default = "no_floor")]
    pub floor_m: f32,
    /// An overcast deck's closed underside: a slab on its floor, half as wide as the first
    /// value (metres, a square around the centre) and as deep as the second; zeros for none
    /// ([`super::core`]).
    #[serde(default)]
    pub floor_slab_m: [f32; 2],
    /// Factor on the in-cloud extinction through its cores (the type's `optical_density`): 1
    /// for water cloud, less for thin ice cloud (cirrus), for the probes' optical depth and the
    /// shadow map alike.
    #[serde(default = "full_density")]
    pub optical_density: f32,
    /// Five ambient colour levels, lowest first.
    pub colour_levels: [ColourLevel; 5],
    /// The cloud's shading groups.
    pub shading_groups: Vec<ShadingGroup>,
    /// The sprites.
    pub sprites: Vec<Sprite>,
}

/// A cloud read without its optical density: as dense as a water cloud.
fn full_density() -> f32 {
    1.0
}

/// A cloud read without a base: its cores reach as low as they do.
fn no_floor() -> f32 {
    f32::MIN
}

impl Cloud {
    /// Sum of the sprite areas, square metres.
    pub fn sprite_area_m2(&self) -> f64 {
        self.sprites
            .iter()
            .map(|s| s.width_m as f64 * s.height_m as f64)
            .sum()
    }
}

/// What one weather layer became in a block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LayerSummary {
    /// The cloud type.
    pub cloud_type: CloudType,
    /// Coverage the weather asked for, oktas.
    pub coverage_oktas: f32,
    /// Fraction of the block area under the clouds' footprints, 0..=1.
    pub covered_fraction: f32,
    /// Cloud base, metres above mean sea level.
    pub base_m: f32,
    /// Cloud top, metres above mean sea level.
    pub top_m: f32,
    /// Clouds generated (including ones whose centre lies in a neighbour's lattice overhang).
    pub clouds: u32,
    /// Boxes filled with sprites.
    pub boxes: u32,
    /// Sprites after the cull pass.
    pub sprites: u32,
    /// Sum of sprite areas over the block area (1.0 = 100 %).
    pub overdraw: f32,
}

/// The clouds of one 4 km x 4 km block: a pure function of (index, block weather, seed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CloudBlock {
    /// Which block.
    pub index: BlockIndex,
    /// The seed it was generated with.
    pub seed: u64,
    /// One summary per weather layer, lowest first.
    pub layers: Vec<LayerSummary>,
    /// The clouds, layer by layer.
    pub clouds: Vec<Cloud>,
}

impl CloudBlock {
    /// Number of sprites in the block.
    pub fn sprite_count(&self) -> usize {
        self.clouds.iter().map(|c| c.sprites.len()).sum()
    }

    /// Cloud block overdraw (Wang 2003 §6.3): sum of sprite areas / block area; 1.0 = 100 %.
    pub fn overdraw(&self) -> f64 {
        self.clouds.iter().map(Cloud::sprite_area_m2).sum::<f64>() / (BLOCK_SIZE_M * BLOCK_SIZE_M)
    }

    /// FNV-1a hash over every field, little-endian: equal on every machine for equal blocks.
    pub fn content_hash(&self) -> u64 {
        let mut h = FNV_OFFSET;
        h = fnv1a(&self.index.i.to_le_bytes(), h);
        h = fnv1a(&self.index.j.to_le_bytes(), h);
        h = fnv1a(&self.seed.to_le_bytes(), h);
        for l in &self.layers {
            h = fnv1a(l.cloud_type.name().as_bytes(), h);
            for v in [
                l.coverage_oktas,
                l.covered_fraction,
                l.base_m,
                l.top_m,
                l.overdraw,
            ] {
                h = fnv1a(&v.to_le_bytes(), h);
            }
            for v in [l.clouds, l.boxes, l.sprites] {
                h = fnv1a(&v.to_le_bytes(), h);
            }
        }
        for c in &self.clouds {
            for v in c.centre_m.to_array() {
                h = fnv1a(&v.to_le_bytes(), h);
            }
            h = fnv1a(c.cloud_type.name().as_bytes(), h);
            h = fnv1a(&[c.layer, c.flat as u8], h);
            h = fnv1a(&c.radius_m.to_le_bytes(), h);
            // Only a deck's, so the hashes of blocks without decks stay what they were.
            if c.sunlit_depth_m != 0.0 {
                h = fnv1a(&c.sunlit_depth_m.to_le_bytes(), h);
            }
            if c.shaded_base_m != 0.0 {
                h = fnv1a(&c.shaded_base_m.to_le_bytes(), h);
            }
            if c.optical_density != 1.0 {
                h = fnv1a(&c.optical_density.to_le_bytes(), h);
            }
            for lvl in &c.colour_levels {
                h = fnv1a(&lvl.height_m.to_le_bytes(), h);
                for v in lvl.rgba {
                    h = fnv1a(&v.to_le_bytes(), h);
                }
            }
            for g in &c.shading_groups {
                for v in g.centre_m {
                    h = fnv1a(&v.to_le_bytes(), h);
                }
            }
            for s in &c.sprites {
                for v in s.offset_m {
                    h = fnv1a(&v.to_le_bytes(), h);
                }
                for v in [
                    s.width_m,
                    s.height_m,
                    s.rotation_deg,
                    s.radius_fraction,
                    s.alpha_morph,
                ] {
                    h = fnv1a(&v.to_le_bytes(), h);
                }
                h = fnv1a(&[s.texture, s.upright as u8], h);
                h = fnv1a(&s.shading_group.to_le_bytes(), h);
            }
        }
        h
    }
}

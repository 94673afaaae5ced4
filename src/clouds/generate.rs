//! Block generation (Wang 2003 §3.1): a pure function of (block index, block weather, seed).
//!
//! Per weather layer: clouds are placed until the layer's coverage is met, each cloud a stack of
//! boxes filled with random sprite centres; then the cull pass drops every sprite closer than the
//! cull radius (a fraction of its height) to one already kept; then each sprite gets a texture
//! and rotation from the band of its height in the cloud, and sprites are grouped into shading
//! groups; each cloud gets its type's five colour levels.
//!
//! Two placements:
//! - scattered: random cloud centres in the block; a 100 m coverage grid tracks the fraction of
//!   the block under the clouds' footprint discs, and placement stops at oktas / 8;
//! - lattice (continuous types, and every overcast layer): one cloud per cell of a world-aligned
//!   lattice, seeded by the world cell, so neighbouring blocks agree and the layer runs on across
//!   borders without a gap (clouds overhang their cell and block).
//!
//! The cover varies across the block as the weather says ([`LayerCover`]: the field at the
//! block's sample point and rim, which the neighbours share), so a layer blends into the next
//! block's instead of stepping at the border: scattered clouds stand where the cover is, as
//! often as it is there (a candidate centre is kept with the chance cover / greatest cover, and
//! placement stops at the block's mean cover), sized and packed by the cover where they stand;
//! the lattice keeps a cell by its world key against the cover at the cell (the lowest
//! key / cover first, as many as the cells' covers add up to). A block of even cover takes
//! none of this: its layers are placed as one cover over the whole block.
//!
//! Heights: base = ground elevation + base ft AGL x 0.3048; the thickness is the layer's, clamped
//! into the type's range. Randomness: [`SplitMix64`] keyed by seed, block and layer (or world
//! cell), with no trigonometry, so the block is the same bytes on every machine.

use glam::{DVec2, DVec3};

use super::bands::DriftBand;
use super::block::{Cloud, CloudBlock, ColourLevel, LayerSummary, ShadingGroup, Sprite};
use super::config::{CloudTypeConfig, CloudTypes, TextureCategory};
use super::core::CORE_HALF_EXTENT;
use super::heap::heap_sprites;
use super::rain::add_shafts;
use super::rng::{SplitMix64, hash_keys};
use super::storm::{CellCache, part_in_block};
use super::uneven::{choose_by_cover, window_full};
use crate::weather::storms::StormCell;
use crate::weather::{
    BLOCK_SIZE_M, BlockCover, BlockIndex, BlockLayer, BlockWeather, CloudType, LayerCover,
    METRES_PER_FOOT,
};

/// Feet to metres.
/// Cells per side of the coverage grid.
pub(super) const GRID: usize = 40;
/// A round lattice cell's radius over half its side: a little more than the disc of the
/// square's area (2 / sqrt(pi), 1.13), so that the corners where four kept cells meet stay
/// covered by their sprites.
const ROUND_CELL: f64 = 1.25;
/// Layers at or above this coverage are placed on the lattice, whatever their type.
pub(super) const OVERCAST_OKTAS: f32 = 7.5;

/// Generates the clouds of one block. Pure: equal inputs give byte-identical blocks. Its
/// cumulonimbus layers are drawn as the block's own heaps: a block of the cloud field draws
/// the field's storm cells instead ([`generate_block_in_field`]).
pub fn generate_block(
    index: BlockIndex,
    weather: &BlockWeather,
    seed: u64,
    types: &CloudTypes,
) -> CloudBlock {
    generate_layers(index, weather, (false, DriftBand::WHOLE), seed, types)
}

/// Generates the clouds of one block of the cloud field, whose cumulonimbus are the weather
/// field's storm `cells` (`weather::storms`): the block draws its part of each (the cells that
/// reach over it) instead of heaps of its own. Pure, as [`generate_block`]; `cache` only saves
/// drawing a cell again for each block it spans. Only the layers of drift `band` are generated
/// (each as it would be in the whole block: the union over the bands is the whole block); the
/// cells belong to band 0 ([`super::bands`]).
pub fn generate_block_in_field(
    index: BlockIndex,
    weather: &BlockWeather,
    (cells, band): (&[StormCell], DriftBand),
    cache: &CellCache,
    seed: u64,
    types: &CloudTypes,
) -> CloudBlock {
    let mut block = generate_layers(index, weather, (true, band), seed, types);
    if band.index != 0 {
        return block;
    }
    let config = types.get(CloudType::Cumulonimbus);
    // The cells' layer: the cumulonimbus layer's place (among the band's summaries when the
    // block is cut into bands).
    let layer = match band.count {
        1 => weather
            .layers
            .iter()
            .position(|l| l.cloud_type == CloudType::Cumulonimbus)
            .unwrap_or(weather.layers.len()),
        _ => block
            .layers
            .iter()
            .position(|l| l.cloud_type == CloudType::Cumulonimbus)
            .unwrap_or(block.layers.len()),
    }
    .min(u8::MAX as usize) as u8;
    for cell in cells {
        let whole = cache.whole(cell, config, weather);
        if let Some(part) = part_in_block(&whole, index, layer) {
            block.clouds.push(part);
        }
    }
    block
}

fn generate_layers(
    index: BlockIndex,
    weather: &BlockWeather,
    (cells_decided, band): (bool, DriftBand),
    seed: u64,
    types: &CloudTypes,
) -> CloudBlock {
    let mut block = CloudBlock {
        index,
        seed,
        layers: Vec::with_capacity(weather.layers.len()),
        clouds: Vec::new(),
    };
    let layers = BlockCover::layers_over_block_grouped(weather.cover.as_ref(), &weather.layers);
    for (li, (layer, cover, group)) in layers.iter().enumerate() {
        // Another band's layer: that band's field generates it, keyed as here (`li`).
        if !band.holds(&weather.layers, layer.base_ft_agl) {
            continue;
        }
        let config = types.get(layer.cloud_type);
        let frame = LayerFrame::new(layer, config, weather.ground_elevation_m as f64);
        // The layers one layer of cloud was cut into by type, this one among them.
        let siblings: Vec<LayerCover> = layers
            .iter()
            .filter(|l| l.2 == *group)
            .map(|l| l.1)
            .collect();
        let sibling = layers[..li].iter().filter(|l| l.2 == *group).count();
        let ctx = LayerCtx {
            config,
            layer,
            li,
            frame: &frame,
            // The only wind reported is the surface wind; high cloud streaks along it too.
            wind_axis_deg: 90.0 - weather.wind.from_deg as f64,
            cover: *cover,
            share: Share {
                siblings: &siblings,
                index: sibling,
                group: *group as u64,
            },
        };
        let first = block.clouds.len();
        // The field's cells are its cumulonimbus: no heaps of the block's own.
        let cells_instead = cells_decided && layer.cloud_type == CloudType::Cumulonimbus;
        let (covered, boxes) = if cover.max_oktas() <= 0.0 || cells_instead {
            (0.0, 0)
        } else if config.continuous || layer.coverage_oktas >= OVERCAST_OKTAS {
            lattice_layer(index, &ctx, seed, &mut block.clouds)
        } else {
            scattered_layer(index, &ctx, seed, &mut block.clouds)
        };
        // A cloud names its layer by its place in the block's summaries (one a layer this
        // band holds: `li` when the block is generated whole).
        let summary = block.layers.len().min(u8::MAX as usize) as u8;
        for c in &mut block.clouds[first..] {
            c.layer = summary;
        }
        let clouds = &block.clouds[first..];
        let area: f64 = clouds.iter().map(Cloud::sprite_area_m2).sum();
        block.layers.push(LayerSummary {
            cloud_type: layer.cloud_type,
            coverage_oktas: layer.coverage_oktas,
            covered_fraction: covered as f32,
            base_m: frame.base_m as f32,
            top_m: (frame.base_m + frame.thickness_m) as f32,
            clouds: clouds.len() as u32,
            boxes,
            sprites: clouds.iter().map(|c| c.sprites.len() as u32).sum(),
            overdraw: (area / (BLOCK_SIZE_M * BLOCK_SIZE_M)) as f32,
        });
        // Rain or snow under the layer's clouds, after the layer's own figures (the paper's
        // overdraw is of the clouds).
        if let Some(precipitation) = &config.precipitation
            && weather.precipitation > 0.0
        {
            let mut rng = SplitMix64::from_keys(&[
                seed,
                index.i as u64,
                index.j as u64,
                li as u64,
                type_key(layer.cloud_type),
                RAIN_KEY,
            ]);
            for cloud in &mut block.clouds[first..] {
                add_shafts(cloud, precipitation, weather, frame.base_m, &mut rng);
            }
        }
    }
    block
}

/// Keys the randomness of a layer's precipitation apart from that of its clouds.
const RAIN_KEY: u64 = 0x7261_696e;

/// Vertical placement of one layer, metres above mean sea level.
pub(super) struct LayerFrame {
    pub(super) base_m: f64,
    pub(super) thickness_m: f64,
}

impl LayerFrame {
    fn new(layer: &BlockLayer, config: &CloudTypeConfig, ground_m: f64) -> Self {
        let [lo, hi] = config.thickness_m.map(f64::from);
        let reported = layer.thickness_ft.max(0.0) as f64 * METRES_PER_FOOT;
        Self {
            base_m: ground_m + layer.base_ft_agl.max(0.0) as f64 * METRES_PER_FOOT,
            thickness_m: reported.clamp(lo, hi),
        }
    }
}

fn type_key(t: CloudType) -> u64 {
    CloudType::ALL.iter().position(|&x| x == t).unwrap_or(0) as u64
}

/// Random clouds until the coverage grid reaches oktas / 8 (or the box budget runs out).
fn scattered_layer(
    index: BlockIndex,
    ctx: &LayerCtx,
    seed: u64,
    out: &mut Vec<Cloud>,
) -> (f64, u32) {
    let LayerCtx {
        config, layer, li, ..
    } = *ctx;
    let mut rng = SplitMix64::from_keys(&[
        seed,
        index.i as u64,
        index.j as u64,
        li as u64,
        type_key(layer.cloud_type),
    ]);
    let corner = index.min_corner_m();
    let even = ctx.cover.is_uniform();
    // The share of sky to cover here (block metres), and its mean and greatest over the block.
    let share_at = |p: DVec2| (ctx.cover.oktas_at(p) as f64 / 8.0).clamp(0.0, 1.0);
    let cell = BLOCK_SIZE_M / GRID as f64;
    let shares: Vec<f64> = if even {
        Vec::new()
    } else {
        (0..GRID * GRID)
            .map(|c| share_at(DVec2::new((c % GRID) as f64 + 0.5, (c / GRID) as f64 + 0.5) * cell))
            .collect()
    };
    let (target, most, mean_oktas) = if even {
        let t = (layer.coverage_oktas as f64 / 8.0).clamp(0.0, 1.0);
        (t, t, layer.coverage_oktas)
    } else {
        let t = shares.iter().sum::<f64>() / shares.len() as f64;
        (
            t,
            shares.iter().fold(0.0, |m, &x| f64::max(m, x)),
            (t * 8.0) as f32,
        )
    };
    let budget = config.boxes_per_block.for_oktas(mean_oktas);
    // This layer's clouds in `out` (other layers' lie where they will: layers overlap at random).
    let mine = out.len();
    let mut grid = vec![false; GRID * GRID];
    let mut covered = 0usize;
    let mut boxes = 0u32;
    let [dmin, dmax] = config.cloud_size_m.map(f64::from);
    for _attempt in 0..2000 {
        let frac = covered as f64 / (GRID * GRID) as f64;
        if frac >= target || boxes >= budget {
            break;
        }
        // Denser skies merge into bigger patches (and keep to the box budget).
        // (Sprites per box stay the same, so the patches of a scattered sky are looser than the
        // distinct heaps of a sparse one: Wang 2003 §6.3 has sparse 170 %, scattered 200 %.)
        let drawn = rng.range_f64(dmin, dmax);
        // Near the target, shrink the last clouds so they do not overshoot it.
        let remaining_m2 = (target - frac) * BLOCK_SIZE_M * BLOCK_SIZE_M;
        let streaks = config.flat && config.streak_length_over_width.is_some();
        let size = |share: f64| {
            let d = drawn * (1.0 + 3.0 * share * share);
            let disc_m2 = std::f64::consts::FRAC_PI_4 * d * d;
            if !streaks && disc_m2 > remaining_m2 * 1.3 {
                (remaining_m2 * 1.3 / std::f64::consts::FRAC_PI_4)
                    .sqrt()
                    .max(if config.anvil.is_some() {
                        dmin
                    } else {
                        dmin * 0.5
                    })
            } else {
                d
            }
        };
        let mut d = size(target);
        let margin = (d / 4.0).min(BLOCK_SIZE_M / 2.0);
        let centre = best_centre(&mut rng, config.placement_candidates, &out[mine..], |rng| {
            corner
                + DVec2::new(
                    rng.range_f64(margin, BLOCK_SIZE_M - margin),
                    rng.range_f64(margin, BLOCK_SIZE_M - margin),
                )
        });
        let cloud_seed = rng.next_u64();
        // Uneven cover: a centre is kept as often as the cover is there, and the cloud is as
        // big, as dense and as packed as the cover there asks.
        let (mut here, mut oktas) = (target, layer.coverage_oktas);
        if !even {
            here = share_at(centre - corner);
            if rng.range_f64(0.0, 1.0) * most >= here
                || window_full(&grid, &shares, centre - corner)
            {
                continue;
            }
            d = size(here);
            oktas = (here * 8.0) as f32;
        }
        // Denser skies tolerate overlap; sparse ones keep clouds apart.
        let min_new_share = if here > 0.6 { 0.15 } else { 0.5 };
        let (cloud, n_boxes) = build_cloud(ctx, centre, d, None, oktas, cloud_seed);
        if streaks {
            // A streak bigger than the block's share is not shrunk to fit (every block would
            // get one dash of the same length, an even grid of them): it is drawn whole, as
            // often as the share allows, so a few oktas of cirrus are a few long, irregular
            // streaks with clear sky between, wherever they reach.
            let footprint_m2 = streak_footprint_m2(&cloud);
            let chance = remaining_m2 / footprint_m2.max(1.0);
            if footprint_m2 > remaining_m2 * 1.3 && rng.range_f64(0.0, 1.0) > chance {
                break;
            }
        }
        let cells = cloud_cells(&cloud, corner);
        let new = cells.iter().filter(|&&c| !grid[c]).count();
        if cells.is_empty() || (new as f64) < min_new_share * cells.len() as f64 {
            continue;
        }
        for c in cells {
            if !grid[c] {
                grid[c] = true;
                covered += 1;
            }
        }
        boxes += n_boxes;
        out.push(cloud);
    }
    (covered as f64 / (GRID * GRID) as f64, boxes)
}

/// The best of `candidates` random centres (`draw` makes one) for a new scattered cloud: the
/// one farthest from the edges of the clouds already in `placed` (the first alone with none).
fn best_centre(
    rng: &mut SplitMix64,
    candidates: u32,
    placed: &[Cloud],
    mut draw: impl FnMut(&mut SplitMix64) -> DVec2,
) -> DVec2 {
    let first = draw(rng);
    if candidates <= 1 || placed.is_empty() {
        return first;
    }
    let room = |p: DVec2| {
        placed
            .iter()
            .map(|c| p.distance(c.centre_m.truncate()) - f64::from(c.radius_m))
            .fold(f64::INFINITY, f64::min)
    };
    let mut best = (room(first), first);
    for _ in 1..candidates {
        let p = draw(rng);
        let r = room(p);
        if r > best.0 {
            best = (r, p);
        }
    }
    best.1
}

/// The sky a streak covers, m2: its flat sprites' dense cores (as [`cloud_cells`] counts them),
/// wherever they lie.
fn streak_footprint_m2(cloud: &Cloud) -> f64 {
    let core = |extent: f32| CORE_HALF_EXTENT * extent as f64;
    cloud
        .sprites
        .iter()
        .map(|s| std::f64::consts::PI * core(s.width_m) * core(s.height_m))
        .sum()
}

/// Coverage-grid cells (of the block, 100 m) under a cloud: those whose centre lies under a
/// sprite's dense core ([`super::core`], what every probe asks), e.g. within 0.7 half-widths of
/// a sprite centre horizontally; for a flat sprite, within 0.7 of its half extents (an ellipse
/// turned with it); for one on a heap's base, within its half-width.
fn cloud_cells(cloud: &Cloud, corner: DVec2) -> Vec<usize> {
    let cell = BLOCK_SIZE_M / GRID as f64;
    let mut cells = Vec::new();
    for core in super::core::cores(cloud) {
        let p = (cloud.centre_m + core.centre_m).truncate() - corner;
        let r = core.box_half_m().x;
        let lo_x = ((p.x - r) / cell).floor().max(0.0) as usize;
        let hi_x = ((p.x + r) / cell).ceil().clamp(0.0, GRID as f64) as usize;
        let lo_y = ((p.y - r) / cell).floor().max(0.0) as usize;
        let hi_y = ((p.y + r) / cell).ceil().clamp(0.0, GRID as f64) as usize;
        for y in lo_y..hi_y {
            for x in lo_x..hi_x {
                let q = DVec2::new((x as f64 + 0.5) * cell, (y as f64 + 0.5) * cell) - p;
                // The core's horizontal section through its centre.
                if core.radius(core.centre_m + q.extend(0.0)) <= 1.0 {
                    cells.push(y * GRID + x);
                }
            }
        }
    }
    cells.sort_unstable();
    cells.dedup();
    cells
}

/// One cloud per world lattice cell whose origin lies in the block; below 8 oktas only the
/// coverage share of them (those with the lowest per-cell random key).
fn lattice_layer(index: BlockIndex, ctx: &LayerCtx, seed: u64, out: &mut Vec<Cloud>) -> (f64, u32) {
    let LayerCtx {
        config, layer, li, ..
    } = *ctx;
    let s = config.lattice_spacing_m as f64;
    let lo = index.min_corner_m();
    let hi = lo + DVec2::splat(BLOCK_SIZE_M);
    let (ci0, ci1) = ((lo.x / s).ceil() as i64, (hi.x / s).ceil() as i64);
    let (cj0, cj1) = ((lo.y / s).ceil() as i64, (hi.y / s).ceil() as i64);
    // Two decks of one type in a block are told apart by their layer index.
    let rank = li as u64;
    let cell_key = |ci: i64, cj: i64| {
        hash_keys(&[seed, type_key(layer.cloud_type), rank, ci as u64, cj as u64])
    };
    let mut cells: Vec<(u64, i64, i64)> = Vec::new();
    for cj in cj0..cj1 {
        for ci in ci0..ci1 {
            cells.push((cell_key(ci, cj), ci, cj));
        }
    }
    let mut chosen = cells.clone();
    let overhang = f64::from(config.lattice_overhang);
    let keep = if ctx.cover.is_uniform() {
        let fraction = cells_for_cover(layer.coverage_oktas as f64 / 8.0, overhang);
        chosen.sort_unstable();
        if layer.coverage_oktas >= OVERCAST_OKTAS {
            cells.len()
        } else {
            (fraction * cells.len() as f64).round() as usize
        }
    } else {
        choose_by_cover(&mut chosen, |ci, cj| {
            let centre = DVec2::new((ci as f64 + 0.5) * s, (cj as f64 + 0.5) * s);
            let oktas = ctx.cover.oktas_at(centre - lo);
            // An overcast cell is kept whatever its neighbours: by this layer where the
            // overcast's types share it to this one.
            match ctx.share.overcast_cell(seed, ci, cj, centre - lo) {
                Some(mine) => 8.0 * f32::from(u8::from(mine)),
                None => (8.0 * cells_for_cover(oktas as f64 / 8.0, overhang)) as f32,
            }
        })
    };
    chosen.truncate(keep);
    let mut boxes = 0;
    for &(key, ci, cj) in cells.iter().filter(|c| chosen.contains(c)) {
        let mut rng = SplitMix64::new(key);
        // Off the lattice's own points by up to a twentieth of a cell, so that the cells' sides
        // (where one cloud's sprites, sorted as a whole, overlap its neighbour's) do not lie on
        // a regular grid: on it, straight down, every cell side showed alike (1 km rows).
        // A round cell (below) by up to a fifth: its clearings then lie off the axes too.
        let on_lattice = DVec2::new((ci as f64 + 0.5) * s, (cj as f64 + 0.5) * s);
        let overcast = ctx.share.overcast_cell(seed, ci, cj, on_lattice - lo) == Some(true);
        let round =
            config.continuous && !overcast && ctx.cover.oktas_at(on_lattice - lo) < OVERCAST_OKTAS;
        let reach = if round { 0.2 } else { LATTICE_JITTER };
        let jitter = DVec2::new(rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0)) * reach * s;
        let centre = on_lattice + jitter;
        let [dmin, dmax] = config.cloud_size_m.map(f64::from);
        // Wide enough to cover the cell's corners.
        let d = rng.range_f64(dmin, dmax).max(s * 1.5);
        let oktas = if overcast {
            8.0
        } else {
            ctx.cover.oktas_at(centre - lo)
        };
        // A cell of a broken continuous layer is a round cloud: its gaps are then round
        // clearings, where square cells left square holes (a grid of them from FL350 over a
        // broken altostratus). (Other types take the lattice at an overcast only, and keep
        // its square cells; the small sprites of altocumulus leave gaps in a round one.)
        let cell = LatticeCell { side_m: s, round };
        let (cloud, n) = build_cloud(ctx, centre, d, Some(cell), oktas, rng.next_u64());
        boxes += n;
        out.push(cloud);
    }
    (keep as f64 / cells.len().max(1) as f64, boxes)
}

/// How far a square lattice cell's cloud is off its lattice point, at most, in cells.
const LATTICE_JITTER: f64 = 0.05;

/// The share of its cells a lattice layer keeps to cover `cover` of the sky, when keeping a
/// share `p` covers `p + overhang p (1 - p)` ([`CloudTypeConfig::lattice_overhang`]): the root
/// of that quadratic in 0..=1. Keeping a block's stratus cells by its cover alone covered 4.8
/// oktas where the weather asked 4, its altostratus 5.1.
fn cells_for_cover(cover: f64, overhang: f64) -> f64 {
    let c = cover.clamp(0.0, 1.0);
    if overhang.abs() < 1e-6 {
        return c;
    }
    let b = 1.0 + overhang;
    // The smaller root; the discriminant b^2 - 4 k c is at least (1 - k)^2 for k > 0, and
    // more than b^2 for k < 0.
    ((b - (b * b - 4.0 * overhang * c).max(0.0).sqrt()) / (2.0 * overhang)).clamp(0.0, 1.0)
}

/// A sprite before texture, rotation and grouping: centre relative to the cloud's horizontal
/// centre and the layer base, metres.
pub(super) struct Raw {
    pub(super) pos: DVec3,
    pub(super) width: f64,
    pub(super) height: f64,
    pub(super) group: u32,
    /// A set rotation, degrees (streak sprites lie along their streak); `None`: the band's.
    pub(super) rotation_deg: Option<f64>,
    /// Stands on the cloud base: takes the first texture band (small rotation), this category of
    /// it where the band has it (flat-bottomed on the rim, foggy under the inside).
    pub(super) base: Option<TextureCategory>,
    /// A set texture category, whatever the band (a storm's fibrous anvil edge).
    pub(super) category: Option<TextureCategory>,
    /// Stands on a deck's floor, in the texture band of its height: its core reaches down to
    /// the base as a base sprite's does ([`Sprite::base`]).
    pub(super) floor: bool,
}

/// What every cloud of one layer shares.
pub(super) struct LayerCtx<'a> {
    pub(super) config: &'a CloudTypeConfig,
    pub(super) layer: &'a BlockLayer,
    pub(super) li: usize,
    pub(super) frame: &'a LayerFrame,
    /// Direction of the wind's axis, degrees anticlockwise from east (streaks lie along it).
    pub(super) wind_axis_deg: f64,
    /// The layer's own coverage over the block.
    pub(super) cover: LayerCover,
    /// How it shares an overcast with the other types of its layer of cloud.
    pub(super) share: Share<'a>,
}

/// The layers of one layer of cloud cut by type ([`BlockCover::layers_over_block_grouped`]):
/// where their covers add up to an overcast, each lattice cell goes to one of them, by a draw
/// that all of them make alike (each type keeping its cells alone left holes where none did and
/// doubled others: an overcast of two types was broken).
#[derive(Clone, Copy)]
pub(super) struct Share<'a> {
    /// The covers of the layers of the group, in order.
    pub(super) siblings: &'a [LayerCover],
    /// Which of them this layer is.
    pub(super) index: usize,
    /// The group, keying the draw.
    pub(super) group: u64,
}

impl Share<'_> {
    /// A layer alone.
    pub(super) fn alone(cover: &LayerCover) -> Share<'_> {
        Share {
            siblings: std::slice::from_ref(cover),
            index: 0,
            group: 0,
        }
    }

    /// Whether the lattice cell (`ci`, `cj`), its point at block metres `p`, lies in the group's
    /// overcast, and if so whether it is this layer's.
    fn overcast_cell(&self, seed: u64, ci: i64, cj: i64, p: DVec2) -> Option<bool> {
        let covers: Vec<f64> = self
            .siblings
            .iter()
            .map(|c| f64::from(c.oktas_at(p)))
            .collect();
        let total: f64 = covers.iter().sum();
        if total < f64::from(OVERCAST_OKTAS) {
            return None;
        }
        let before: f64 = covers[..self.index].iter().sum();
        let draw = hash_keys(&[seed, OVERCAST_SHARE_KEY, self.group, ci as u64, cj as u64]) as f64
            / u64::MAX as f64
            * total;
        Some(draw >= before && draw < before + covers[self.index])
    }
}

/// Keys the draw that shares an overcast's cells out among its types.
const OVERCAST_SHARE_KEY: u64 = 0x6f76_6364;

/// A lattice cell a cloud fills: its side, and whether it is a round cloud (a cell of a
/// broken layer) rather than the whole square (an overcast's).
#[derive(Debug, Clone, Copy)]
struct LatticeCell {
    side_m: f64,
    round: bool,
}

/// Builds one cloud of `d` metres diameter centred (horizontally) at `centre`, as dense as a
/// layer of `oktas`; returns the cloud and the number of boxes it used.
fn build_cloud(
    ctx: &LayerCtx,
    centre: DVec2,
    d: f64,
    lattice: Option<LatticeCell>,
    oktas: f32,
    cloud_seed: u64,
) -> (Cloud, u32) {
    let LayerCtx { config, frame, .. } = *ctx;
    let lattice_cell_m = lattice.map(|c| c.side_m);
    let round = lattice.is_some_and(|c| c.round);
    let mut rng = SplitMix64::new(cloud_seed);
    // Streaks: the footprint squeezed across the wind axis, every sprite along it.
    let streak = config
        .streak_length_over_width
        .filter(|_| config.flat && lattice_cell_m.is_none());
    let along = DVec2::from_angle(ctx.wind_axis_deg.to_radians());
    let lay = |v: DVec2| match streak {
        Some(aspect) => along * v.x + along.perp() * (v.y / aspect as f64),
        None => v,
    };
    let density = config.density_by_cover.for_oktas(oktas) as f64;
    // Heaped clouds stand on a flat base and end in a dome (or an anvil).
    if lattice_cell_m.is_none() && !config.continuous && !config.flat {
        let height = frame
            .thickness_m
            .min(d * config.max_height_over_size as f64);
        let (raws, n_boxes) = heap_sprites(config, d, height, density, &mut rng);
        let kept = cull(raws, config.cull_radius_fraction as f64);
        let mut cloud = finish_cloud(ctx, centre, kept, &mut rng);
        cloud.shaded_base_m = config.shaded_base_m.unwrap_or(0.0);
        return (cloud, n_boxes);
    }
    let n_boxes = rng.range_u32(config.boxes_per_cloud[0], config.boxes_per_cloud[1]);
    let thickness = frame.thickness_m;
    let [wmin, wmax] = config.sprite_width_m.map(f64::from);
    let [rmin, rmax] = config.sprite_height_ratio.map(f64::from);
    let mut raws: Vec<Raw> = Vec::new();
    let mut group = 0u32;
    // Continuous decks lay their boxes side by side over their lattice cell; layered clouds
    // (flat cirrus, a continuous type off the lattice) spread theirs around the centre.
    for box_index in 0..n_boxes {
        // A deck's first box holds its floor: half its sprites stand on the base (their dense
        // cores reach it, foggy undersides where the type has them), so a deck is met from
        // below at its base, the relief of the rest above it.
        let floor = lattice_cell_m.is_some() && box_index == 0;
        let (half_w, offset) = if let Some(cell) = lattice_cell_m {
            // A lattice cell: every box spans the cell and no more, so that cells do not overlap
            // in strips of double density on a grid (the sprites overhang it).
            (cell * 0.5, DVec2::ZERO)
        } else {
            let off = DVec2::new(rng.range_f64(-0.15, 0.15), rng.range_f64(-0.15, 0.15)) * d;
            (d / 2.0 * if n_boxes > 1 { 0.75 } else { 1.0 }, lay(off))
        };
        let n = rng.range_u32(config.sprites_per_box[0], config.sprites_per_box[1]);
        let mut n = ((n as f64 * density).round() as u32).clamp(1, 100);
        // On the lattice, enough sprites that the jittered grid leaves no hole (at most 100).
        // (As many as when each box spanned 1.1 cells: the same sprites, closer together.)
        let grid_side = lattice_cell_m.map(|cell| {
            let cover = (1.1 * cell / (0.5 * (wmin + wmax) / 2.0)).ceil();
            (n as f64).sqrt().ceil().max(cover).clamp(1.0, 10.0) as u32
        });
        if let Some(m) = grid_side {
            n = m * m;
        }
        let group_size = rng.range_u32(config.shading_group_size[0], config.shading_group_size[1]);
        for s in 0..n {
            if s % group_size == 0 {
                group += 1;
            }
            let width = rng.range_f64(wmin, wmax);
            let height = width * rng.range_f64(rmin, rmax);
            let (x, y) = if let Some(m) = grid_side {
                // Continuous decks: one sprite anywhere in each square of an m x m grid over
                // the cell (stratified sampling), so no holes and no lattice: a sprite spread
                // over its whole square has no component at the grid's period, where a
                // jitter of a fifth of it left a regular grid that read as squares from above.
                let (gx, gy) = ((s % m) as f64, ((s / m) % m) as f64);
                let cell = 2.0 / m as f64;
                let (x, y) = (
                    -1.0 + cell * (gx + rng.range_f64(0.0, 1.0)),
                    -1.0 + cell * (gy + rng.range_f64(0.0, 1.0)),
                );
                if round {
                    // The square onto a disc (`ROUND_CELL` half-sides across), evenly: each
                    // point along its own ray from the centre, the square's edge to the
                    // circle's.
                    let k = (x.abs().max(y.abs()) / x.hypot(y).max(1e-9)) * ROUND_CELL;
                    (x * k, y * k)
                } else {
                    (x, y)
                }
            } else {
                // A random point in the box's elliptic footprint (rejection, no trigonometry).
                loop {
                    let x = rng.range_f64(-1.0, 1.0);
                    let y = rng.range_f64(-1.0, 1.0);
                    if x * x + y * y <= 1.0 {
                        break (x, y);
                    }
                }
            };
            let spread = if grid_side.is_some() {
                half_w
            } else {
                (half_w - width * 0.25).max(half_w * 0.3)
            };
            // Sprites stay inside the layer; the floor's stand on its base (their quads' lower
            // edges on it, their cores' columns down to it: `clouds::core`). Every other square
            // of the floor box's grid, a checkerboard: a deck's whole first box on one level
            // was a sheet of sprites that showed as dark blotches to a pilot just under it.
            let half_h = height / 2.0;
            let on_floor = floor && grid_side.is_some_and(|m| (s % m + (s / m) % m) % 2 == 0);
            let z = if on_floor {
                if config.flat {
                    0.0
                } else {
                    half_h.min(thickness / 2.0)
                }
            } else if config.flat {
                rng.range_f64(0.0, thickness)
            } else {
                rng.range_f64(
                    half_h.min(thickness / 2.0),
                    (thickness - half_h).max(thickness / 2.0),
                )
            };
            let local = lay(DVec2::new(x * spread, y * spread));
            raws.push(Raw {
                pos: DVec3::new(offset.x + local.x, offset.y + local.y, z),
                width,
                height,
                group: group - 1,
                rotation_deg: streak.map(|_| ctx.wind_axis_deg),
                base: None,
                floor: on_floor,
                category: None,
            });
        }
    }
    let mut kept = cull(raws, config.cull_radius_fraction as f64);
    // A deck's sprites in a shuffled order (after the cull, which keeps the same ones): until
    // its first sort a cloud is drawn in its sprites' own order, and row by row that lit every
    // lattice cell alike (a grid of squares from above, for the frames a block waits for the
    // sorting budget). Its shading groups follow the new order (a deck is lit as one slab).
    if lattice_cell_m.is_some() {
        for i in (1..kept.len()).rev() {
            let j = rng.range_u32(0, i as u32) as usize;
            kept.swap(i, j);
        }
        let [lo, hi] = config.shading_group_size;
        let size = ((lo + hi) / 2).max(1);
        for (k, r) in kept.iter_mut().enumerate() {
            r.group = k as u32 / size;
        }
    }
    let mut cloud = finish_cloud(ctx, centre, kept, &mut rng);
    // A deck on the lattice is lit from above only.
    if lattice_cell_m.is_some() {
        cloud.sunlit_depth_m = config.sunlit_depth_m.unwrap_or(0.0);
    }
    // An overcast's underside is closed, as its sprites draw it (each point of it under
    // several of their quads): its floor a slab over the whole cell and past its sides by the
    // cells' jitter, as deep as the floor sprites' cores reach up, so that no sight line
    // passes between their round cores and a pilot breaking out sees the ground only below it.
    if let Some(cell) = lattice_cell_m
        && !round
        && oktas >= OVERCAST_OKTAS
    {
        let sprite_height = 0.25 * (wmin + wmax) * (rmin + rmax);
        cloud.floor_slab_m = [
            (cell * (0.5 + LATTICE_JITTER)) as f32,
            (CORE_HALF_EXTENT * sprite_height).min(thickness / 2.0) as f32,
        ];
    }
    (cloud, n_boxes)
}

/// Wang 2003 §3.1: traverse the list, drop a sprite closer than the cull radius to a kept one.
/// A heap's base row is all kept: it closes the base seen from below. (A deck's floor is culled
/// as the rest: kept whole, it crowded the underside a pilot just below it sees into blotches.)
pub(super) fn cull(raws: Vec<Raw>, fraction: f64) -> Vec<Raw> {
    let mut kept: Vec<Raw> = Vec::with_capacity(raws.len());
    for r in raws {
        let radius = fraction * r.height;
        let r2 = radius * radius;
        if r.base.is_some() || kept.iter().all(|k| k.pos.distance_squared(r.pos) >= r2) {
            kept.push(r);
        }
    }
    kept
}

/// Textures, rotations, shading groups and colour levels; positions made relative to the centre.
pub(super) fn finish_cloud(
    ctx: &LayerCtx,
    centre: DVec2,
    kept: Vec<Raw>,
    rng: &mut SplitMix64,
) -> Cloud {
    let LayerCtx {
        config,
        layer,
        li,
        frame,
        ..
    } = *ctx;
    let thickness = frame.thickness_m;
    let centre_z = frame.base_m + thickness / 2.0;
    let origin = DVec3::new(0.0, 0.0, thickness / 2.0);
    // Renumber the surviving groups densely and find their centres.
    let mut group_ids: Vec<u32> = kept.iter().map(|r| r.group).collect();
    group_ids.dedup();
    let mut sums: Vec<(DVec3, u32)> = vec![(DVec3::ZERO, 0); group_ids.len()];
    let mut sprite_groups = Vec::with_capacity(kept.len());
    for r in &kept {
        let g = group_ids.iter().position(|&x| x == r.group).unwrap_or(0);
        sums[g].0 += r.pos - origin;
        sums[g].1 += 1;
        sprite_groups.push(g as u16);
    }
    let radius = kept
        .iter()
        .map(|r| (r.pos - origin).length())
        .fold(1.0f64, f64::max);
    let mut sprites = Vec::with_capacity(kept.len());
    for (r, &g) in kept.iter().zip(&sprite_groups) {
        let fraction = (r.pos.z / thickness).clamp(0.0, 1.0) as f32;
        // A sprite standing on the base takes the first band (flat-bottomed, small rotation).
        let band = if r.base.is_some() {
            config.texture_bands.first()
        } else {
            config.band_at(fraction)
        };
        let (categories, rotation) = match band {
            Some(band) if !band.textures.is_empty() => {
                (band.textures.as_slice(), band.rotation_deg)
            }
            _ => (&[TextureCategory::Wispy][..], [0.0, 360.0]),
        };
        let pick = rng.range_u32(0, categories.len() as u32 - 1) as usize;
        let category = match (r.category, r.base) {
            (Some(set), _) => set,
            (None, Some(wanted)) if categories.contains(&wanted) => wanted,
            _ => categories[pick],
        };
        let cells = category.cells();
        let texture = rng.range_u32(cells.start as u32, cells.end as u32 - 1) as u8;
        let square = (r.height - r.width).abs() < 1e-6 * r.width.max(1.0);
        let rotation_deg = match r.rotation_deg {
            Some(deg) => deg.rem_euclid(360.0) as f32,
            None if square => rng.range_f32(rotation[0], rotation[1]),
            None => 0.0,
        };
        let offset = r.pos - origin;
        // The flat-bottomed sprites standing on a heaped cloud's base stay upright.
        let upright = r.base.is_some() && category == TextureCategory::FlatBottom;
        sprites.push(Sprite {
            offset_m: offset.as_vec3().to_array(),
            width_m: r.width as f32,
            height_m: r.height as f32,
            rotation_deg,
            texture,
            shading_group: g,
            radius_fraction: (offset.length() / radius).min(1.0) as f32,
            alpha_morph: 1.0,
            upright,
            precipitation: false,
            base: r.base.is_some() || r.floor,
        });
    }
    let shading_groups = sums
        .iter()
        .map(|&(sum, n)| ShadingGroup {
            centre_m: (sum / n.max(1) as f64).as_vec3().to_array(),
        })
        .collect();
    let colour_levels = config.colour_levels.map(|l| ColourLevel {
        height_m: ((l.height as f64 - 0.5) * thickness) as f32,
        rgba: l.rgba,
    });
    Cloud {
        centre_m: DVec3::new(centre.x, centre.y, centre_z),
        cloud_type: layer.cloud_type,
        layer: li.min(u8::MAX as usize) as u8,
        radius_m: radius as f32,
        flat: config.flat,
        sunlit_depth_m: 0.0,
        shaded_base_m: 0.0,
        floor_m: (-thickness / 2.0) as f32,
        floor_slab_m: [0.0; 2],
        optical_density: config.optical_density.unwrap_or(1.0),
        colour_levels,
        shading_groups,
        sprites,
    }
}

#[cfg(test)]
#[path = "generate_tests.rs"]
mod tests;

#[cfg(test)]
mod golden {
    use super::*;
    use crate::weather::TypeSource;

    /// The content hash of a few pinned blocks: equal on every machine and run. A deliberate
    /// change to the generator or to config/cloud_types.toml changes it; update it then (the
    /// cirrus block's changed with its `optical_density`, part of its content).
    #[test]
    fn pinned_blocks_hash_the_same_everywhere() {
        let types = CloudTypes::builtin();
        let mut hashes = Vec::new();
        for (t, oktas, base_ft, thickness_ft) in [
            (CloudType::CumulusHumilis, 2.0, 3600.0, 1000.0),
            (CloudType::Stratus, 8.0, 800.0, 1500.0),
            (CloudType::Cumulonimbus, 3.0, 2500.0, 30000.0),
            (CloudType::Cirrus, 4.0, 28000.0, 800.0),
        ] {
            let weather = BlockWeather {
                layers: vec![BlockLayer {
                    cloud_type: t,
                    type_source: TypeSource::HeightRule,
                    coverage_oktas: oktas,
                    base_ft_agl: base_ft,
                    thickness_ft,
                }],
                ground_elevation_m: 120.0,
                ..Default::default()
            };
            let block = generate_block(BlockIndex::new(-3, 5), &weather, 2003, &types);
            hashes.push(format!("{:016x}", block.content_hash()));
        }
        assert_eq!(
            hashes,
            [
                "8162f54a59074a59",
                "7ccbffc21b226faa",
                "5393761c2f982975",
                "b74bec24fe678181"
            ]
        );
    }
}

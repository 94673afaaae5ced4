//! Heaped clouds (cumulus, cumulonimbus): Wang 2003 §3.1's few boxes of sprites, shaped.
//!
//! A heap stands on the layer's base: a row of sprites whose flat undersides lie exactly on the
//! base (Wang's flat-bottomed texture with a small rotation on the rim, foggy ones under the
//! inside where only a view from below sees them), so every cloud of a layer shows the same flat,
//! level base; above it a stack of boxes, the widest at the bottom,
//! each one higher narrower (`taper`) and shifted a little, never past the base's rim. Sprite
//! centres are drawn inside an ellipsoid per box, denser towards its core, so the heap is
//! rounded and ends in a dome. A cumulonimbus tower ends in an anvil: a slab `width_scale` times
//! the base's width, flat on top and thinning towards its rim.
//!
//! In: the type, the cloud diameter and the layer thickness (metres). Out: sprite centres in
//! metres, horizontal offsets from the cloud centre and height above the base.

use glam::{DVec2, DVec3};

use super::config::{CloudTypeConfig, TextureCategory};
use super::generate::Raw;
use super::rng::SplitMix64;
use super::sheet::FLAT_BOTTOM_V;

/// Centre height of a base sprite above the base, in sprite heights: its flat underside on it.
pub(crate) const BASE_CENTRE_FRACTION: f64 = FLAT_BOTTOM_V as f64 - 0.5;

/// Sprites of one heaped cloud of `d` metres diameter, `thickness` metres tall, and its box count.
pub(super) fn heap_sprites(
    config: &CloudTypeConfig,
    d: f64,
    thickness: f64,
    density: f64,
    rng: &mut SplitMix64,
) -> (Vec<Raw>, u32) {
    let n_boxes = rng.range_u32(config.boxes_per_cloud[0], config.boxes_per_cloud[1]);
    let [wmin, wmax] = config.sprite_width_m.map(f64::from);
    let [rmin, rmax] = config.sprite_height_ratio.map(f64::from);
    let sprite = |rng: &mut SplitMix64| {
        let w = rng.range_f64(wmin, wmax);
        (w, w * rng.range_f64(rmin, rmax))
    };
    let base_half_w = d / 2.0;
    let mut raws = Vec::new();
    let mut group = 0u32;

    // The base: a jittered grid of flat-bottomed sprites over the bottom box's footprint.
    let w_mean = 0.5 * (wmin + wmax);
    let step = 0.85 * w_mean;
    let rim = (base_half_w - 0.3 * w_mean).max(0.3 * base_half_w);
    let m = ((2.0 * rim / step).ceil() as i64).clamp(1, 12);
    let cell = 2.0 * rim / m as f64;
    for gy in 0..m {
        for gx in 0..m {
            // Cells whose centre lies in the footprint disc; the jittered point kept inside it.
            let (cx, cy) = (
                -rim + cell * (gx as f64 + 0.5),
                -rim + cell * (gy as f64 + 0.5),
            );
            if cx * cx + cy * cy > rim * rim {
                continue;
            }
            let mut x = cx + cell * rng.range_f64(-0.4, 0.4);
            let mut y = cy + cell * rng.range_f64(-0.4, 0.4);
            let r2 = x * x + y * y;
            if r2 > rim * rim {
                let k = rim / r2.sqrt();
                (x, y) = (x * k, y * k);
            }
            let (width, height) = sprite(rng);
            raws.push(Raw {
                pos: DVec3::new(x, y, BASE_CENTRE_FRACTION * height),
                width,
                height,
                group: group + (gx / 3 + gy / 3 * 4) as u32,
                rotation_deg: None,
                // Flat-bottomed on the rim (what a side view shows), foggy under the inside
                // (what a view from below shows: a smooth grey underside); a small cloud's few
                // are all rim.
                base: Some(if m >= 3 && x * x + y * y < 0.36 * rim * rim {
                    TextureCategory::Foggy
                } else {
                    TextureCategory::FlatBottom
                }),
                floor: false,
                category: None,
            });
        }
    }
    group += 16;

    let anvil = config.anvil;
    let n_tower = if anvil.is_some() {
        n_boxes.saturating_sub(1).max(1)
    } else {
        n_boxes
    };
    // The tower reaches a little into the anvil.
    let tower_top = anvil.map_or(thickness, |a| thickness * (a.from as f64 + 0.05).min(1.0));
    let mut offset = DVec2::ZERO;
    for k in 0..n_tower {
        let t = k as f64 / (n_tower.max(2) - 1) as f64;
        let half_w = base_half_w * (1.0 - config.taper as f64 * t);
        if k > 0 {
            let step = DVec2::new(rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0)) * d * 0.08;
            offset += step;
            // Never past the base's rim: what is above stands on the base.
            let room = (base_half_w - half_w).max(0.0);
            if offset.length() > room {
                offset *= room / offset.length();
            }
        }
        // Box k spans [lo, hi], overlapping the one below; the bottom one is a half ellipsoid
        // standing on the base, the others whole ellipsoids.
        let lo = if k == 0 {
            0.0
        } else {
            tower_top * (k as f64 - 0.35) / n_tower as f64
        };
        let hi = tower_top * (k as f64 + 1.0) / n_tower as f64;
        let (cz, az) = if k == 0 {
            (0.0, hi)
        } else {
            (0.5 * (lo + hi), 0.5 * (hi - lo))
        };
        let n = rng.range_u32(config.sprites_per_box[0], config.sprites_per_box[1]);
        let n = ((n as f64 * density).round() as u32).clamp(1, 100);
        let group_size = rng.range_u32(config.shading_group_size[0], config.shading_group_size[1]);
        for s in 0..n {
            if s % group_size == 0 {
                group += 1;
            }
            let (width, height) = sprite(rng);
            // Inside the ellipsoid, accepted with probability 1 - 0.35 r^2: denser at the core.
            let (x, y, z) = loop {
                let x = rng.range_f64(-1.0, 1.0);
                let y = rng.range_f64(-1.0, 1.0);
                let z = rng.range_f64(if k == 0 { 0.0 } else { -1.0 }, 1.0);
                let r2 = x * x + y * y + z * z;
                if r2 <= 1.0 && rng.next_f64() < 1.0 - 0.35 * r2 {
                    break (x, y, z);
                }
            };
            let spread = (half_w - width * 0.25).max(half_w * 0.3);
            let half_h = height / 2.0;
            let zc = (cz + z * az).clamp(
                half_h.min(thickness / 2.0),
                (thickness - half_h).max(thickness / 2.0),
            );
            raws.push(Raw {
                pos: DVec3::new(offset.x + x * spread, offset.y + y * spread, zc),
                width,
                height,
                group: group - 1,
                rotation_deg: None,
                base: None,
                floor: false,
                category: None,
            });
        }
    }

    if let Some(a) = anvil {
        // The anvil: flat on top, thickest over the tower, thinning towards its rim.
        let half_w = base_half_w * a.width_scale as f64;
        let floor = thickness * a.from as f64;
        let n = rng.range_u32(config.sprites_per_box[0], config.sprites_per_box[1]);
        let area = a.width_scale as f64 * a.width_scale as f64;
        let n = ((n as f64 * area * density).round() as u32).clamp(1, 100);
        let group_size = rng.range_u32(config.shading_group_size[0], config.shading_group_size[1]);
        for s in 0..n {
            if s % group_size == 0 {
                group += 1;
            }
            let (width, height) = sprite(rng);
            let (x, y) = loop {
                let x = rng.range_f64(-1.0, 1.0);
                let y = rng.range_f64(-1.0, 1.0);
                if x * x + y * y <= 1.0 {
                    break (x, y);
                }
            };
            let top = (thickness - height / 2.0).max(floor);
            let depth = (top - floor) * (1.0 - 0.7 * (x * x + y * y));
            let u = rng.next_f64();
            let spread = (half_w - width * 0.25).max(half_w * 0.3);
            raws.push(Raw {
                pos: DVec3::new(
                    offset.x + x * spread,
                    offset.y + y * spread,
                    top - depth * u * u,
                ),
                width,
                height,
                group: group - 1,
                rotation_deg: None,
                base: None,
                floor: false,
                category: None,
            });
        }
    }
    (raws, n_boxes)
}

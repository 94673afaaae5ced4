//! The GPU records of a resident block's sprites and clouds ([`GpuSprite`], [`GpuCloud`]):
//! sizes and group centres as halves, fractions as 16-bit units, the rotation in 1/65,536
//! turns, as `shaders/sprite_build.wgsl` unpacks them.

use glam::{DVec3, Vec3};

use crate::render::gpu_types::{
    FLOOR_NONE_M, GpuCloud, GpuSprite, SPRITE_BASE, SPRITE_PRECIPITATION, SPRITE_UPRIGHT,
};
use crate::render::scene::SkyCloud;

/// Two values as the low and high halves of a `u32` (WGSL's `pack2x16float`).
fn halves(low: f32, high: f32) -> u32 {
    let h = |v: f32| half::f16::from_f32(v).to_bits() as u32;
    h(low) | (h(high) << 16)
}

/// Two values in 0..=1 as 16-bit fractions (WGSL's `pack2x16unorm`).
fn fractions(low: f32, high: f32) -> u32 {
    // Non-negative: a half added and truncated is `round` without its library call.
    let u = |v: f32| (v.clamp(0.0, 1.0) * 65_535.0 + 0.5) as u32;
    u(low) | (u(high) << 16)
}

/// The GPU record of a sprite.
pub fn gpu_sprite(cloud: &SkyCloud, s: &crate::render::scene::SkySprite) -> GpuSprite {
    let group = cloud
        .group_centres_m
        .get(s.group as usize)
        .copied()
        .unwrap_or(Vec3::ZERO);
    // The rotation in 1/65,536 turns, wrapped into one turn. By truncation and a half, not
    // `rem_euclid` and `round` (library calls on x86-64's baseline: a tenth of the cost of a
    // frame of arrivals, which writes 32,768 records).
    let turns = s.rotation_deg / 360.0;
    let turns = turns - (turns as i64) as f32;
    let turns = if turns < 0.0 { turns + 1.0 } else { turns };
    let rotation = ((turns * 65_536.0 + 0.5) as u32) & 0xffff;
    GpuSprite {
        offset: s.offset_m.to_array(),
        size: halves(s.width_m, s.height_m),
        group_xy: halves(group.x, group.y),
        group_z_rotation: (half::f16::from_f32(group.z).to_bits() as u32) | (rotation << 16),
        morph_radius: fractions(s.alpha_morph, s.radius_fraction),
        bits: (s.cell as u32).min(15)
            | if s.upright { SPRITE_UPRIGHT } else { 0 }
            | if s.precipitation {
                SPRITE_PRECIPITATION
            } else {
                0
            }
            | if s.base { SPRITE_BASE } else { 0 },
    }
}

/// The GPU record of a cloud of the block centred at `block_m`.
pub fn gpu_cloud(cloud: &SkyCloud, block_m: DVec3) -> GpuCloud {
    let l = &cloud.colour_levels.0;
    GpuCloud {
        centre_block: (cloud.centre_m - block_m)
            .as_vec3()
            .extend(cloud.shaded_base_m.max(0.0))
            .to_array(),
        level_rgba: l.map(|level| level.rgba),
        level_height: [l[0].height_m, l[1].height_m, l[2].height_m, l[3].height_m],
        level4_radius_flat: [
            l[4].height_m,
            cloud.radius_m().max(1.0),
            if cloud.flat { 1.0 } else { 0.0 },
            cloud.sunlit_depth_m.max(0.0),
        ],
        floor_pad: [
            cloud.floor_m.max(FLOOR_NONE_M),
            cloud.optical_density.max(0.0),
            0.0,
            0.0,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sprite's record packs its rotation into 1/65,536 turns wrapped into one turn, and its
    /// morph and radius fractions into 16 bits each, as `rem_euclid` and `round` would (to a
    /// unit where a value falls on a half), for any angle a block holds, negative or past a turn.
    #[test]
    fn a_sprite_record_packs_rotation_and_fractions_as_rounded() {
        let cloud = crate::render::sprites::draw_list::tests::small_cloud();
        let near = |a: u32, b: u32, modulo: u32| {
            let d = a.abs_diff(b) % modulo;
            d.min(modulo - d) <= 1
        };
        for k in -2_000..2_000 {
            let degrees = k as f32 * 0.733;
            let fraction = (k + 2_000) as f32 / 4_000.0;
            let sprite = crate::render::scene::SkySprite {
                rotation_deg: degrees,
                alpha_morph: fraction,
                radius_fraction: 1.0 - fraction,
                ..crate::render::scene::square_sprite(glam::Vec3::ZERO, 10.0, 0, 0)
            };
            let record = gpu_sprite(&cloud, &sprite);
            let turns = degrees.rem_euclid(360.0) / 360.0;
            let rotation = ((turns * 65_536.0).round() as u32) & 0xffff;
            assert!(
                near(record.group_z_rotation >> 16, rotation, 65_536),
                "{degrees} degrees"
            );
            let unit = |v: f32| (v * 65_535.0).round() as u32;
            assert!(near(record.morph_radius & 0xffff, unit(fraction), u32::MAX));
            assert!(near(
                record.morph_radius >> 16,
                unit(1.0 - fraction),
                u32::MAX
            ));
        }
    }
}

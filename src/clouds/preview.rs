//! A CPU preview: an orthographic splat of a block's sprites with the sheet's textures, for eyes,
//! READMEs and tests (the real renderer is `render`, on the GPU).
//!
//! The camera looks north from the south, pitched by `pitch_deg` (positive looks down on the
//! clouds, negative up at them). Camera-facing sprites are screen-aligned quads of their width
//! and height, rotated by `rotation_deg`; flat sprites (cirrus) lie horizontal. Sprites are drawn
//! back to front with straight-alpha blending; colour = colour level at the pixel's height x
//! texture, alpha = level alpha x texture alpha x `alpha_morph` (Wang 2003 eq. 3, ambient only).

use glam::DVec3;

use super::block::{Cloud, CloudBlock, Sprite};
use super::config::LifecycleConfig;
use super::lifecycle::{Phase, apply};
use super::sheet::TextureSheet;
use crate::weather::{BlockLayer, BlockWeather, CloudType, TypeSource};

/// How to draw a preview.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviewSettings {
    /// Image width, pixels.
    pub width_px: u32,
    /// Image height, pixels.
    pub height_px: u32,
    /// Camera pitch, degrees: positive looks down, negative looks up.
    pub pitch_deg: f64,
}

impl Default for PreviewSettings {
    fn default() -> Self {
        Self {
            width_px: 480,
            height_px: 270,
            pitch_deg: 10.0,
        }
    }
}

struct Camera {
    up: DVec3,
    forward: DVec3,
}

impl Camera {
    fn new(pitch_deg: f64) -> Self {
        let (s, c) = pitch_deg.to_radians().sin_cos();
        // Looking north, tilted down by the pitch.
        Self {
            forward: DVec3::new(0.0, c, -s),
            up: DVec3::new(0.0, s, c),
        }
    }
}

/// One sprite ready to splat: its screen-space centre (metres), half extents along screen x and
/// y, rotation, depth and colour inputs.
struct Splat<'a> {
    centre: (f64, f64),
    half: (f64, f64),
    depth: f64,
    cloud: &'a Cloud,
    sprite: &'a Sprite,
    world_z: f64,
    height_per_screen_y: f64,
}

/// Draws the clouds of `blocks` into an image over a sky gradient.
pub fn render(
    blocks: &[&CloudBlock],
    sheet: &TextureSheet,
    settings: &PreviewSettings,
) -> image::RgbaImage {
    let cam = Camera::new(settings.pitch_deg);
    let mut splats = Vec::new();
    for block in blocks {
        for cloud in &block.clouds {
            for sprite in &cloud.sprites {
                let o = sprite.offset_m;
                let p = cloud.centre_m + DVec3::new(o[0] as f64, o[1] as f64, o[2] as f64);
                let (w, h) = (sprite.width_m as f64 / 2.0, sprite.height_m as f64 / 2.0);
                let (half, per_y) = if cloud.flat {
                    (
                        (w, (h * cam.up.y).abs().max(1.0)),
                        0.0, // a flat sprite has one height
                    )
                } else {
                    ((w, h), cam.up.z)
                };
                splats.push(Splat {
                    centre: (p.x, p.dot(cam.up)),
                    half,
                    depth: p.dot(cam.forward),
                    cloud,
                    sprite,
                    world_z: p.z,
                    height_per_screen_y: per_y,
                });
            }
        }
    }
    let (w_px, h_px) = (settings.width_px, settings.height_px);
    let mut img = image::RgbaImage::new(w_px, h_px);
    for y in 0..h_px {
        let t = y as f32 / h_px as f32;
        let sky = [
            (70.0 + 80.0 * t) as u8,
            (120.0 + 60.0 * t) as u8,
            (185.0 + 40.0 * t) as u8,
            255,
        ];
        for x in 0..w_px {
            img.put_pixel(x, y, image::Rgba(sky));
        }
    }
    if splats.is_empty() {
        return img;
    }
    // Fit the splats' bounds into the image, same scale on both axes.
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for s in &splats {
        x0 = x0.min(s.centre.0 - s.half.0);
        x1 = x1.max(s.centre.0 + s.half.0);
        y0 = y0.min(s.centre.1 - s.half.1);
        y1 = y1.max(s.centre.1 + s.half.1);
    }
    let scale = ((w_px as f64 * 0.94) / (x1 - x0)).min((h_px as f64 * 0.9) / (y1 - y0));
    let (mx, my) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let to_px = |sx: f64, sy: f64| {
        (
            w_px as f64 / 2.0 + (sx - mx) * scale,
            h_px as f64 / 2.0 - (sy - my) * scale,
        )
    };
    // Back to front.
    splats.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    for s in &splats {
        let (cx, cy) = to_px(s.centre.0, s.centre.1);
        let (hx, hy) = (s.half.0 * scale, s.half.1 * scale);
        let (sin_r, cos_r) = (s.sprite.rotation_deg as f64).to_radians().sin_cos();
        let reach = if s.sprite.rotation_deg != 0.0 {
            hx.hypot(hy)
        } else {
            hx.max(hy)
        };
        let (px0, px1) = (
            (cx - reach).floor().max(0.0),
            (cx + reach).ceil().min(w_px as f64),
        );
        let (py0, py1) = (
            (cy - reach).floor().max(0.0),
            (cy + reach).ceil().min(h_px as f64),
        );
        for py in py0 as u32..py1 as u32 {
            for px in px0 as u32..px1 as u32 {
                let (dx, dy) = (px as f64 + 0.5 - cx, py as f64 + 0.5 - cy);
                // Into the sprite's own (rotated) frame.
                let (lx, ly) = (dx * cos_r + dy * sin_r, -dx * sin_r + dy * cos_r);
                let (u, v) = (lx / (2.0 * hx) + 0.5, ly / (2.0 * hy) + 0.5);
                if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
                    continue;
                }
                let tex = sheet.sample(s.sprite.texture, u as f32, v as f32);
                if tex[3] <= 0.0 {
                    continue;
                }
                let z = s.world_z - dy / scale * s.height_per_screen_y;
                let level = colour_at(s.cloud, z - s.cloud.centre_m.z);
                let a = (tex[3] * level[3] * s.sprite.alpha_morph).clamp(0.0, 1.0);
                let dst = img.get_pixel_mut(px, py);
                for k in 0..3 {
                    let c = (tex[k] * level[k]).clamp(0.0, 1.0) * 255.0;
                    dst[k] = (c * a + dst[k] as f32 * (1.0 - a) + 0.5) as u8;
                }
            }
        }
    }
    img
}

/// The cloud's ambient colour at a height relative to its centre (Wang 2003 §5.1, eq. 1 without
/// the time of day).
pub fn colour_at(cloud: &Cloud, height_m: f64) -> [f32; 4] {
    let levels = &cloud.colour_levels;
    let h = height_m as f32;
    if h <= levels[0].height_m {
        return levels[0].rgba;
    }
    for pair in levels.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if h <= b.height_m {
            let t = if b.height_m > a.height_m {
                (h - a.height_m) / (b.height_m - a.height_m)
            } else {
                1.0
            };
            return std::array::from_fn(|k| a.rgba[k] + (b.rgba[k] - a.rgba[k]) * t);
        }
    }
    levels[4].rgba
}

/// A strip of frames of one block's life side by side: formation at the progress values
/// `forming` (0..=1), then dissipation at `dissipating`, each frame `settings`-sized, all with the
/// same framing (the fully formed block's).
pub fn lifecycle_strip(
    block: &CloudBlock,
    sheet: &TextureSheet,
    settings: &PreviewSettings,
    lifecycle: &LifecycleConfig,
    forming: &[f32],
    dissipating: &[f32],
) -> image::RgbaImage {
    let frames: Vec<(Phase, f64)> = forming
        .iter()
        .map(|&p| {
            (
                Phase::forming(0.0, lifecycle),
                p as f64 * lifecycle.formation_s as f64,
            )
        })
        .chain(dissipating.iter().map(|&q| {
            (
                Phase::dissipating(0.0, lifecycle),
                q as f64 * lifecycle.dissipation_s as f64,
            )
        }))
        .collect();
    let mut strip =
        image::RgbaImage::new(settings.width_px * frames.len() as u32, settings.height_px);
    for (k, (phase, now_s)) in frames.into_iter().enumerate() {
        let mut b = block.clone();
        for cloud in &mut b.clouds {
            apply(cloud, phase, now_s, lifecycle);
        }
        // Keep the framing of the whole block: an invisible copy of it fixes the bounds.
        let mut frame_ref = block.clone();
        for cloud in &mut frame_ref.clouds {
            cloud.sprites.iter_mut().for_each(|s| s.alpha_morph = 0.0);
        }
        let img = render(&[&frame_ref, &b], sheet, settings);
        image::imageops::replace(&mut strip, &img, (k as u32 * settings.width_px) as i64, 0);
    }
    strip
}

/// A typical one-layer weather for showing a cloud type: (base ft AGL, thickness ft, oktas) as a
/// pilot would meet it, and the camera pitch that shows it best (decks from below).
pub fn typical_weather(cloud_type: CloudType) -> (BlockWeather, f64) {
    use CloudType::*;
    let (base_ft, thickness_ft, oktas, pitch_deg) = match cloud_type {
        CumulusHumilis => (3000.0, 1500.0, 3.0, 8.0),
        CumulusMediocris => (3500.0, 3500.0, 2.0, 8.0),
        CumulusCongestus => (3000.0, 10000.0, 2.0, 6.0),
        Cumulonimbus => (3000.0, 30000.0, 2.0, 4.0),
        Stratocumulus => (2500.0, 2000.0, 6.0, 12.0),
        Stratus => (800.0, 1000.0, 8.0, -25.0),
        Nimbostratus => (1500.0, 6000.0, 8.0, -15.0),
        Altocumulus => (12000.0, 1500.0, 4.0, 20.0),
        Altostratus => (12000.0, 3000.0, 8.0, -25.0),
        Cirrus => (28000.0, 800.0, 3.0, -60.0),
        Cirrocumulus => (24000.0, 600.0, 4.0, -60.0),
        Cirrostratus => (28000.0, 1000.0, 8.0, -60.0),
        Fog => (0.0, 400.0, 8.0, 12.0),
    };
    let weather = BlockWeather {
        layers: vec![BlockLayer {
            cloud_type,
            type_source: TypeSource::Theme,
            coverage_oktas: oktas,
            base_ft_agl: base_ft,
            thickness_ft,
        }],
        visibility_m: 9999.0,
        ..Default::default()
    };
    (weather, pitch_deg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::{CloudTypes, generate_block};
    use crate::weather::BlockIndex;

    #[test]
    fn a_preview_shows_clouds_where_the_block_has_them() {
        let weather = BlockWeather {
            layers: vec![BlockLayer {
                cloud_type: CloudType::Stratus,
                type_source: TypeSource::HeightRule,
                coverage_oktas: 8.0,
                base_ft_agl: 1000.0,
                thickness_ft: 1000.0,
            }],
            ..Default::default()
        };
        let block = generate_block(BlockIndex::new(0, 0), &weather, 1, &CloudTypes::builtin());
        let sheet = TextureSheet::generate();
        let settings = PreviewSettings {
            width_px: 160,
            height_px: 90,
            pitch_deg: -20.0,
        };
        let img = render(&[&block], &sheet, &settings);
        let empty = render(&[], &sheet, &settings);
        // An overcast deck seen from below fills the middle of the picture with grey.
        let centre = img.get_pixel(80, 45);
        let sky = empty.get_pixel(80, 45);
        assert_ne!(centre, sky);
        let greyness = |p: &image::Rgba<u8>| (p[2] as i32 - p[0] as i32).abs();
        assert!(
            greyness(centre) < greyness(sky) / 2,
            "{centre:?} vs sky {sky:?}"
        );
    }

    #[test]
    fn colour_levels_interpolate_by_height() {
        let weather = BlockWeather {
            layers: vec![BlockLayer {
                cloud_type: CloudType::CumulusCongestus,
                type_source: TypeSource::HeightRule,
                coverage_oktas: 3.0,
                base_ft_agl: 3000.0,
                thickness_ft: 10000.0,
            }],
            ..Default::default()
        };
        let block = generate_block(BlockIndex::new(0, 0), &weather, 1, &CloudTypes::builtin());
        let cloud = &block.clouds[0];
        let bottom = colour_at(cloud, -10_000.0);
        let top = colour_at(cloud, 10_000.0);
        let mid = colour_at(cloud, 0.0);
        assert_eq!(bottom, cloud.colour_levels[0].rgba);
        assert_eq!(top, cloud.colour_levels[4].rgba);
        assert!(bottom[0] < mid[0] && mid[0] <= top[0]);
    }
}

//! The on-screen overlay: a few lines of figures (position, weather at the aircraft, frame
//! rate, the sky's cost) drawn top left over a darkened box. Text is rasterised on the CPU from
//! `noto-sans-mono-bitmap` (Noto Sans Mono already rasterised at 16 px, no font file or font
//! engine) into a two-channel image, text coverage and box, that the present pass blends over
//! the frame; an F12 screenshot blends the same image on the CPU, so it shows what the window
//! shows.

use noto_sans_mono_bitmap::{FontWeight, RasterHeight, get_raster, get_raster_width};
use skycast::demo::Frame;

/// Pixels between the box's edge and the text, and between the box and the window's corner.
pub const MARGIN_PX: u32 = 8;
/// What the box keeps of the frame's colour under it (legible text over a bright cloud).
pub const BOX_DIM: f32 = 0.35;

const WEIGHT: FontWeight = FontWeight::Regular;
const HEIGHT: RasterHeight = RasterHeight::Size16;

/// The overlay's pixels: per pixel text coverage and whether it is inside the box, 0..=255.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlayImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Two bytes a pixel, row-major: text coverage, box.
    pub coverage_and_box: Vec<u8>,
}

impl OverlayImage {
    /// The box with `lines` of text in it (characters the font lacks drawn as `?`).
    pub fn from_lines(lines: &[String]) -> Self {
        let char_w = get_raster_width(WEIGHT, HEIGHT) as u32;
        let line_h = HEIGHT.val() as u32;
        let columns = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) as u32;
        let width = columns * char_w + 2 * MARGIN_PX;
        let height = lines.len() as u32 * line_h + 2 * MARGIN_PX;
        let mut pixels = vec![0u8; (width * height * 2) as usize];
        for box_pixel in pixels.chunks_exact_mut(2) {
            box_pixel[1] = 255;
        }
        for (row, line) in lines.iter().enumerate() {
            for (column, c) in line.chars().enumerate() {
                let Some(glyph) =
                    get_raster(c, WEIGHT, HEIGHT).or_else(|| get_raster('?', WEIGHT, HEIGHT))
                else {
                    continue;
                };
                let x0 = MARGIN_PX + column as u32 * char_w;
                let y0 = MARGIN_PX + row as u32 * line_h;
                for (gy, glyph_row) in glyph.rows().enumerate() {
                    for (gx, &coverage) in glyph_row.iter().enumerate() {
                        let (x, y) = (x0 + gx as u32, y0 + gy as u32);
                        if x < width && y < height {
                            pixels[((y * width + x) * 2) as usize] = coverage;
                        }
                    }
                }
            }
        }
        Self {
            width,
            height,
            coverage_and_box: pixels,
        }
    }

    /// Blends the overlay into a read-back frame (linear colour) at the window's corner, as the
    /// present pass does on screen (`shaders/view_present.wgsl`, `fs_present`).
    pub fn composite(&self, frame: &mut Frame) {
        for y in 0..self.height.min(frame.height.saturating_sub(MARGIN_PX)) {
            for x in 0..self.width.min(frame.width.saturating_sub(MARGIN_PX)) {
                let i = ((y * self.width + x) * 2) as usize;
                let (text, inside) = (
                    self.coverage_and_box[i] as f32 / 255.0,
                    self.coverage_and_box[i + 1] as f32 / 255.0,
                );
                let pixel =
                    &mut frame.rgba[((y + MARGIN_PX) * frame.width + x + MARGIN_PX) as usize];
                for channel in &mut pixel[..3] {
                    let dimmed = *channel * (1.0 - inside * (1.0 - BOX_DIM));
                    *channel = dimmed + (1.0 - dimmed) * text;
                }
            }
        }
    }
}

/// Upload of an [`OverlayImage`] to a texture the present pass reads.
pub fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    image: &OverlayImage,
) -> wgpu::TextureView {
    let size = wgpu::Extent3d {
        width: image.width.max(1),
        height: image.height.max(1),
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("view.overlay"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rg8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    if image.width > 0 && image.height > 0 {
        queue.write_texture(
            texture.as_image_copy(),
            &image.coverage_and_box,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(image.width * 2),
                rows_per_image: Some(image.height),
            },
            size,
        );
    }
    texture.create_view(&Default::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lands_inside_a_box_sized_to_the_longest_line() {
        let image = OverlayImage::from_lines(&["ab".into(), "abcd".into()]);
        let char_w = get_raster_width(WEIGHT, HEIGHT) as u32;
        assert_eq!(image.width, 4 * char_w + 2 * MARGIN_PX);
        assert_eq!(image.height, 2 * 16 + 2 * MARGIN_PX);
        assert!(image.coverage_and_box.chunks(2).all(|p| p[1] == 255));
        assert!(image.coverage_and_box.chunks(2).any(|p| p[0] > 200));
    }

    #[test]
    fn the_box_darkens_and_text_brightens_the_frame() {
        let image = OverlayImage::from_lines(&["#".into()]);
        let mut frame = Frame {
            width: 64,
            height: 64,
            rgba: vec![[0.5, 0.5, 0.5, 1.0]; 64 * 64],
            depth: vec![1.0; 64 * 64],
        };
        image.composite(&mut frame);
        let corner = frame.rgba[(MARGIN_PX * 64 + MARGIN_PX) as usize];
        assert!((corner[0] - 0.5 * BOX_DIM).abs() < 1e-6, "{corner:?}");
        assert!(frame.rgba.iter().any(|p| p[0] > 0.9));
        assert_eq!(frame.rgba[63 * 64 + 63], [0.5, 0.5, 0.5, 1.0]);
    }
}

//! The benchmark's plot: frame time (milliseconds, log scale) against distance along the path
//! (kilometres), one line per run, drawn pixel by pixel into an RGB PNG. Grid: a vertical line
//! every kilometre, a horizontal line at 1, 2 and 5 times each power of ten, the powers of ten
//! darker and labelled; the kilometres are labelled along the bottom.

use std::path::Path;

use anyhow::Context;
use image::{Rgb, RgbImage};

const WIDTH: u32 = 900;
const HEIGHT: u32 = 450;
const LEFT: u32 = 50;
const RIGHT: u32 = 20;
const TOP: u32 = 20;
const BOTTOM: u32 = 40;

/// One line of the plot.
pub struct Series {
    /// Line colour.
    pub colour: [u8; 3],
    /// Dashed (impostors off) or solid (on).
    pub dashed: bool,
    /// (distance along the path in metres, frame time in milliseconds).
    pub points: Vec<(f64, f64)>,
}

/// 3 x 5 pixel glyphs of "0123456789.", rows top to bottom, 3 bits a row.
const GLYPHS: [[u8; 5]; 11] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
    [0, 0, 0, 0, 2],
];

fn put(img: &mut RgbImage, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, Rgb(c));
    }
}

/// Writes `text` (digits and dots) at twice the glyph size, top-left corner at (x, y).
fn text(img: &mut RgbImage, x: i64, y: i64, text: &str) {
    for (n, ch) in text.chars().enumerate() {
        let glyph = match ch {
            '0'..='9' => GLYPHS[ch as usize - '0' as usize],
            '.' => GLYPHS[10],
            _ => continue,
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) != 0 {
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let px = x + n as i64 * 8 + col * 2 + dx;
                        put(img, px, y + row as i64 * 2 + dy, [0, 0, 0]);
                    }
                }
            }
        }
    }
}

/// A two-pixel-wide line from a to b; dashed lines draw 6 pixels of every 10.
fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: [u8; 3], dashed: bool, run: &mut u32) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as u32;
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        *run += 1;
        if !dashed || *run % 10 < 6 {
            put(img, x.round() as i64, y.round() as i64, c);
            put(img, x.round() as i64, y.round() as i64 + 1, c);
        }
    }
}

/// Draws the series and writes the PNG.
pub fn write(path: &Path, series: &[Series]) -> anyhow::Result<()> {
    let mut img = RgbImage::from_pixel(WIDTH, HEIGHT, Rgb([255, 255, 255]));
    let all = series.iter().flat_map(|s| s.points.iter());
    let max_x_m = all.clone().map(|p| p.0).fold(1.0, f64::max);
    let positive = || all.clone().map(|p| p.1).filter(|v| *v > 0.0);
    let lo = positive().fold(f64::INFINITY, f64::min);
    let hi = positive().fold(0.0, f64::max);
    let (lo_decade, hi_decade) = if lo.is_finite() && hi > 0.0 {
        let lo_d = lo.log10().floor() as i32;
        (lo_d, (hi.log10().ceil() as i32).max(lo_d + 1))
    } else {
        (0, 1)
    };
    let (x0, x1) = (LEFT as f64, (WIDTH - RIGHT) as f64);
    let (y0, y1) = ((HEIGHT - BOTTOM) as f64, TOP as f64);
    let px = |m: f64| x0 + (x1 - x0) * m / max_x_m;
    let span = (hi_decade - lo_decade) as f64;
    let py = |ms: f64| {
        let d = ms.max(10f64.powi(lo_decade)).log10() - lo_decade as f64;
        y0 + (y1 - y0) * d / span
    };
    // Grid.
    for d in lo_decade..=hi_decade {
        for k in [1.0, 2.0, 5.0] {
            let v = k * 10f64.powi(d);
            if d == hi_decade && k > 1.0 {
                continue;
            }
            let shade = if k == 1.0 { 150 } else { 220 };
            let y = py(v).round() as i64;
            for x in x0 as i64..=x1 as i64 {
                put(&mut img, x, y, [shade; 3]);
            }
        }
        let label = if d < 0 {
            format!("{:.*}", (-d) as usize, 10f64.powi(d))
        } else {
            format!("{}", 10i64.pow(d as u32))
        };
        let width = label.len() as i64 * 8;
        text(
            &mut img,
            LEFT as i64 - 6 - width,
            py(10f64.powi(d)) as i64 - 5,
            &label,
        );
    }
    let km = (max_x_m / 1000.0).floor() as i64;
    for k in 0..=km {
        let x = px(k as f64 * 1000.0).round() as i64;
        for y in y1 as i64..=y0 as i64 {
            put(&mut img, x, y, [220; 3]);
        }
        let label = k.to_string();
        text(&mut img, x - label.len() as i64 * 4, y0 as i64 + 8, &label);
    }
    for s in series {
        let mut run = 0;
        for w in s.points.windows(2) {
            let a = (px(w[0].0), py(w[0].1));
            let b = (px(w[1].0), py(w[1].1));
            line(&mut img, a, b, s.colour, s.dashed, &mut run);
        }
    }
    img.save(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

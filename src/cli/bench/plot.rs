//! The benchmark's plot, drawn with `plotters`: steady frame time (milliseconds, log scale)
//! against distance along the path (kilometres), one line per run, and a legend naming each
//! run's scenario, impostor ring and cloud resolution scale. Drawn into a pixel buffer and saved
//! with `image`; the labels use DejaVu Sans embedded in the binary (`assets/fonts/`), so the plot
//! needs no font installed on the machine.

use std::path::Path;
use std::sync::Once;

use anyhow::Context;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 560;
/// The embedded font's family name for plotters.
const FONT: &str = "sans-serif";
const FONT_TTF: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// One line of the plot.
pub struct Series {
    /// Legend text: scenario, ring, scale.
    pub label: String,
    /// Line colour.
    pub colour: [u8; 3],
    /// Dashed (impostors off) or solid (on).
    pub dashed: bool,
    /// (distance along the path in metres, frame time in milliseconds).
    pub points: Vec<(f64, f64)>,
}

/// Registers the embedded font with plotters (once a process).
fn register_font() -> anyhow::Result<()> {
    static REGISTER: Once = Once::new();
    let mut result = Ok(());
    REGISTER.call_once(|| {
        result = plotters::style::register_font(FONT, FontStyle::Normal, FONT_TTF)
            .map_err(|_| anyhow::anyhow!("the embedded plot font does not parse"));
    });
    result
}

/// Draws the series and writes the PNG.
pub fn write(path: &Path, series: &[Series]) -> anyhow::Result<()> {
    register_font()?;
    let mut pixels = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    draw(&mut pixels, series).map_err(|e| anyhow::anyhow!("plotting frame times: {e}"))?;
    image::RgbImage::from_raw(WIDTH, HEIGHT, pixels)
        .context("plot buffer size")?
        .save(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

fn draw(pixels: &mut [u8], series: &[Series]) -> Result<(), Box<dyn std::error::Error>> {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let max_km = all().map(|p| p.0 / 1000.0).fold(1.0, f64::max);
    let positive = || all().map(|p| p.1).filter(|v| *v > 0.0);
    let lo = positive().fold(f64::INFINITY, f64::min);
    let hi = positive().fold(0.0, f64::max);
    // Whole decades around the data (1 to 10 ms when there is none).
    let (lo_ms, hi_ms) = if lo.is_finite() && hi > 0.0 {
        let lo_ms = 10f64.powf(lo.log10().floor());
        (lo_ms, 10f64.powf(hi.log10().ceil()).max(lo_ms * 10.0))
    } else {
        (1.0, 10.0)
    };
    let root = BitMapBackend::with_buffer(pixels, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "skycast bench: steady frame time along the path",
            (FONT, 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..max_km, (lo_ms..hi_ms).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("distance along the path (km)")
        .y_desc("frame time (ms, log scale)")
        .x_label_formatter(&|km| format!("{km:.0}"))
        .y_label_formatter(&|ms| format!("{ms}"))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for s in series {
        let [r, g, b] = s.colour;
        let style = RGBColor(r, g, b).stroke_width(2);
        let km: Vec<(f64, f64)> = s.points.iter().map(|&(m, ms)| (m / 1000.0, ms)).collect();
        let label = s.label.clone();
        if s.dashed {
            chart
                .draw_series(DashedLineSeries::new(km, 8, 5, style))?
                .label(label)
                .legend(move |(x, y)| {
                    DashedPathElement::new(vec![(x, y), (x + 24, y)], 8, 5, style)
                });
        } else {
            chart
                .draw_series(LineSeries::new(km, style))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

//! What the overlay says, as text: position, the weather at the aircraft, the frame rate and
//! the sky's cost. Plain numbers in, lines out, so it is tested without a window.

use skycast::weather::BlockWeather;

/// The figures of one moment of the flight.
#[derive(Debug, Clone, PartialEq)]
pub struct Figures {
    /// Degrees north.
    pub lat_deg: f64,
    /// Degrees east.
    pub lon_deg: f64,
    /// Feet above mean sea level.
    pub msl_ft: f64,
    /// Feet above the ground under the aircraft.
    pub agl_ft: f64,
    /// Degrees clockwise from true north.
    pub heading_deg: f64,
    /// Degrees above the horizon.
    pub pitch_deg: f64,
    /// Knots.
    pub speed_kt: f64,
    /// The sky's time, Unix seconds UTC.
    pub utc_unix_s: f64,
    /// Frames a second, averaged over the last frames.
    pub fps: f64,
    /// The sky's CPU time of the last frame, milliseconds.
    pub sky_cpu_ms: f64,
    /// The GPU time of the last frame (ground and sky), milliseconds, where the device has
    /// timestamp queries.
    pub gpu_ms: Option<f64>,
    /// Sprites drawn as sprites.
    pub sprites: u32,
    /// Clouds drawn.
    pub clouds: u32,
    /// Blocks drawn into the far ring's impostors.
    pub impostor_blocks: u32,
    /// Whether the vertex cache is on.
    pub vertex_cache: bool,
    /// Whether the impostor ring is on.
    pub impostors: bool,
    /// The weather of the block the aircraft is in.
    pub weather: BlockWeather,
}

impl Figures {
    /// The overlay's lines.
    pub fn lines(&self) -> Vec<String> {
        let ns = if self.lat_deg >= 0.0 { 'N' } else { 'S' };
        let ew = if self.lon_deg >= 0.0 { 'E' } else { 'W' };
        let time = jiff::Timestamp::from_millisecond((self.utc_unix_s * 1000.0) as i64)
            .map(|t| t.strftime("%Y-%m-%d %H:%MZ").to_string())
            .unwrap_or_else(|_| "time out of range".into());
        let gpu = self
            .gpu_ms
            .map_or_else(String::new, |ms| format!("  GPU {ms:.1} ms"));
        let w = &self.weather;
        let layers = if w.layers.is_empty() {
            "clear".to_string()
        } else {
            w.layers
                .iter()
                .map(|l| {
                    format!(
                        "{} {:.0}/8 {:.0} ft",
                        l.cloud_type, l.coverage_oktas, l.base_ft_agl
                    )
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        vec![
            format!(
                "{:.4} {ns} {:.4} {ew}  {:.0} ft MSL  {:.0} ft AGL",
                self.lat_deg.abs(),
                self.lon_deg.abs(),
                self.msl_ft,
                self.agl_ft
            ),
            format!(
                "heading {:03.0}  pitch {:+.0}  {:.0} kt  {time}",
                self.heading_deg, self.pitch_deg, self.speed_kt
            ),
            format!("layers: {layers}"),
            format!(
                "visibility {:.1} km  wind {:03.0}/{:.0} kt  {:.0} C",
                w.visibility_m / 1000.0,
                w.wind.from_deg,
                w.wind.speed_kt,
                w.temperature_c
            ),
            format!(
                "{:.1} fps  sky CPU {:.1} ms{gpu}  vertex cache {}",
                self.fps,
                self.sky_cpu_ms,
                on_off(self.vertex_cache)
            ),
            format!(
                "{} sprites  {} clouds  impostor ring {}: {} blocks   H: keys",
                self.sprites,
                self.clouds,
                on_off(self.impostors),
                self.impostor_blocks
            ),
        ]
    }
}

fn on_off(on: bool) -> &'static str {
    if on { "on" } else { "off" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_say_where_what_weather_and_what_it_costs() {
        let figures = Figures {
            lat_deg: 28.5,
            lon_deg: -81.45,
            msl_ft: 2500.0,
            agl_ft: 2495.4,
            heading_deg: 90.0,
            pitch_deg: 6.0,
            speed_kt: 0.0,
            utc_unix_s: 1_737_999_000.0,
            fps: 4.2,
            sky_cpu_ms: 3.24,
            gpu_ms: None,
            sprites: 106_987,
            clouds: 2_499,
            impostor_blocks: 12,
            vertex_cache: true,
            impostors: true,
            weather: BlockWeather {
                visibility_m: 9_999.0,
                ..Default::default()
            },
        };
        let lines = figures.lines();
        assert_eq!(lines[0], "28.5000 N 81.4500 W  2500 ft MSL  2495 ft AGL");
        assert_eq!(lines[1], "heading 090  pitch +6  0 kt  2025-01-27 17:30Z");
        assert_eq!(lines[2], "layers: clear");
        assert_eq!(lines[3], "visibility 10.0 km  wind 000/0 kt  0 C");
        assert_eq!(lines[4], "4.2 fps  sky CPU 3.2 ms  vertex cache on");
        assert_eq!(
            lines[5],
            "106987 sprites  2499 clouds  impostor ring on: 12 blocks   H: keys"
        );
    }
}

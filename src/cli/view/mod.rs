//! `skycast view --weather FILE --at LAT,LON [...]`: the real weather over the demo ground in a
//! window to fly through. The viewer is one more host of the library: the demo host's device
//! (made able to present to the window), its ground and its [`skycast::SkySystem`] draw each
//! frame off-screen exactly as `skycast render` does; a present pass shows it on the window's
//! surface (sRGB, vsync by default) with an overlay of figures over it: position, MSL and AGL,
//! speed, time, the weather at the aircraft, frames per second, the sky's CPU and GPU
//! milliseconds, sprites; H adds the keys.
//!
//! Without a display (no X server) it says so and names `render` and `fly`, exit status 2.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;
use skycast::weather::{LocalFrame, METRES_PER_FOOT, theme};

use super::render::{ElevationArgs, LookArgs, parse_size, parse_time, sky_config, time_or_default};
use super::weather::load;

mod app;
mod controls;
mod figures;
mod overlay;
mod present;
mod script;
mod window;

pub use controls::KEYS_HELP;

/// Flags of `skycast view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The weather file: metars.cache.csv, a NOAA cycle file, one METAR a line, a weather
    /// theme (`.toml`), or a weather model's GRIB2 file (told by its content).
    #[arg(long)]
    pub weather: PathBuf,
    /// The model under the reports.
    #[command(flatten)]
    pub model: crate::cli::model::ModelArgs,
    /// Station table placing reports the file does not place.
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Start latitude,longitude, degrees (the middle of the area flown), or a station's ICAO
    /// identifier.
    #[arg(long, value_name = "LAT,LON|ICAO", value_parser = super::weather::parse_place, allow_hyphen_values = true)]
    pub at: super::weather::Place,
    /// Start altitude, feet above mean sea level.
    #[arg(long, default_value_t = 3000.0, allow_hyphen_values = true)]
    pub alt_ft: f64,
    /// Start heading, degrees clockwise from true north.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub heading: f64,
    /// Start pitch, degrees above the horizon.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pitch: f64,
    /// UTC time at the start, RFC 3339 (default: the shipped weather file's time).
    #[arg(long, value_parser = parse_time)]
    pub time: Option<f64>,
    /// Watch the weather file: when it changes, the sky follows (changed blocks re-form).
    #[arg(long)]
    pub watch: bool,
    /// Window size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Present as fast as frames are drawn (to measure), not at the display's refresh.
    #[arg(long)]
    pub no_vsync: bool,
    /// Quit after this many presented frames (with the frame rate on standard output).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Write frame K (0 = the first) as a PNG, repeatable: K,PATH.
    #[arg(long, value_name = "K,PATH", value_parser = parse_screenshot_at)]
    pub screenshot_at: Vec<(u64, PathBuf)>,
    /// Timed key presses and mouse drags (TOML: [[press]] frame, key, frames; [[look]] frame,
    /// dx_px, dy_px), for tests and recordings.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// The look: renderer settings, cloud scale, time-of-day table.
    #[command(flatten)]
    pub look: LookArgs,
    /// The ground from an elevation file instead of the stations' elevations.
    #[command(flatten)]
    pub elevation: ElevationArgs,
}

/// `K,PATH`: a frame number and the PNG to write it to.
fn parse_screenshot_at(text: &str) -> Result<(u64, PathBuf), String> {
    let (k, path) = text
        .split_once(',')
        .ok_or_else(|| format!("`{text}` is not K,PATH (for example 30,frame.png)"))?;
    let k = k
        .trim()
        .parse()
        .map_err(|_| format!("`{k}` in `{text}` is not a frame number"))?;
    if path.is_empty() {
        return Err(format!("`{text}` names no file after the comma"));
    }
    Ok((k, PathBuf::from(path)))
}

/// What the headless commands are, for the no-display message.
const NO_DISPLAY: &str = "skycast view needs a display (an X server: DISPLAY is unset or cannot be opened); \
without one, `skycast render` draws one frame and `skycast fly` a scripted flight to PNG files";

/// Runs `skycast view`.
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    if !(-2_000.0..=100_000.0).contains(&args.alt_ft) {
        anyhow::bail!("--alt-ft {} is outside -2000..=100000 feet", args.alt_ft);
    }
    let script = match &args.script {
        Some(path) => script::load(path)?,
        None => script::Script::default(),
    };
    // The display first: without one nothing else is worth loading.
    // winit's own reason (which variables it looked at, its source line) goes to the log: the
    // user needs the one line that says what to do.
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| {
        log::debug!("winit: {e}");
        anyhow::anyhow!(NO_DISPLAY)
    })?;
    let look = args.look.load()?;
    let loaded = load(
        &args.weather,
        args.model.model.as_deref(),
        args.stations.as_deref(),
        None,
        None,
    )?
    .usable()?;
    let (lat, lon) = args.at.resolve(&loaded, args.stations.as_deref())?;
    let field = loaded
        .input
        .field(LocalFrame::new(lat, lon), &loaded.settings, &loaded.rule);
    let ground = args.elevation.ground(&field)?;
    let mut config = sky_config((lat, lon), look, &loaded);
    let watch = if args.watch {
        if !theme::is_theme_path(&args.weather) {
            config.stations = Some(crate::cli::defaults::station_table(
                args.stations.as_deref(),
            )?);
        }
        Some(args.weather.clone())
    } else {
        None
    };
    let setup = app::Setup {
        size: args.size,
        vsync: !args.no_vsync,
        frames: args.frames,
        screenshots: args.screenshot_at.clone(),
        script,
        start_unix_s: {
            let unix_s = time_or_default(args.time)?;
            crate::cli::model::warn_if_far_in_time(&loaded.input, unix_s);
            unix_s
        },
        aircraft: controls::Aircraft {
            position_m: glam::DVec3::new(0.0, 0.0, args.alt_ft * METRES_PER_FOOT),
            heading_deg: args.heading,
            pitch_deg: args.pitch,
            speed_mps: 0.0,
        },
        ground,
        config,
        field: Some(field),
        watch: watch.map(|path| (path, Duration::from_millis(500))),
    };
    let mut viewer = app::Viewer::new(setup);
    event_loop.run_app(&mut viewer)?;
    viewer.finish()
}

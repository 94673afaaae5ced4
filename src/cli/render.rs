//! `skycast render --weather FILE --at LAT,LON --alt-ft FT --heading DEG [...] --out frame.png`:
//! one frame of the real weather over the demo ground, as PNG and optionally EXR (linear RGBA
//! half floats plus depth `Z` in metres).

use std::path::PathBuf;

use clap::Args;
use glam::DVec2;
use skycast::demo::{DemoHost, GroundSettings, HeightField, demo_ground};
use skycast::flight::SkySystemConfig;
use skycast::render::RenderSettings;
use skycast::shading::{ShadingModel, TimeOfDayTable, sun_position};
use skycast::weather::{LocalFrame, METRES_PER_FOOT, WeatherField};

use super::defaults;
use super::weather::{Loaded, Place, load, parse_place};

/// Flags of `skycast render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The weather file: metars.cache.csv, a NOAA cycle file, one METAR a line, a weather
    /// theme (`.toml`), or a weather model's GRIB2 file (told by its content).
    #[arg(long)]
    pub weather: PathBuf,
    /// The model under the reports.
    #[command(flatten)]
    pub model: super::model::ModelArgs,
    /// Station table placing reports the file does not place.
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Camera latitude,longitude, degrees, or a station's ICAO identifier.
    #[arg(long, value_name = "LAT,LON|ICAO", value_parser = parse_place, allow_hyphen_values = true)]
    pub at: Place,
    /// Camera altitude, feet above mean sea level.
    #[arg(long, allow_hyphen_values = true)]
    pub alt_ft: f64,
    /// View heading, degrees clockwise from true north.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub heading: f64,
    /// View pitch, degrees above the horizon.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pitch: f64,
    /// UTC time, RFC 3339 (default: 2025-01-27T22:00:00Z, the time of the shipped weather file).
    #[arg(long, value_parser = parse_time)]
    pub time: Option<f64>,
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output PNG.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write an EXR: linear RGBA half floats and depth `Z` in metres.
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// The look: renderer settings, cloud scale, time-of-day table.
    #[command(flatten)]
    pub look: LookArgs,
    /// The ground from an elevation file instead of the stations' elevations.
    #[command(flatten)]
    pub elevation: ElevationArgs,
}

/// Flags that set the sky's look (`render`, `fly`, `view`).
#[derive(Debug, Default, Args)]
pub struct LookArgs {
    /// Renderer settings (default: the shipped config/render.toml).
    #[arg(long)]
    pub render_settings: Option<PathBuf>,
    /// Resolution the clouds are drawn at, a fraction of the image's: 1, 1/2 or 1/4 (default:
    /// the renderer settings' `[clouds] resolution_scale`).
    #[arg(long, value_parser = parse_cloud_scale)]
    pub cloud_scale: Option<f32>,
    /// Time-of-day table (default: the shipped config/time_of_day.toml).
    #[arg(long)]
    pub time_of_day: Option<PathBuf>,
    /// Cloud shading model: `wang` (Wang 2003's artist model) or `harris-lastra` (Harris and
    /// Lastra 2001: light through the cloud, phase function, skylight) (default: the
    /// time-of-day table's `[shading] model`).
    #[arg(long, value_parser = parse_shading)]
    pub shading: Option<ShadingModel>,
    /// The clouds' shadows on the ground: `on` or `off` (default: the renderer settings'
    /// `[cloud_shadows] enabled`).
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub cloud_shadows: Option<bool>,
}

impl LookArgs {
    /// The renderer settings and time-of-day table the flags name (or the shipped ones).
    pub fn load(&self) -> anyhow::Result<(RenderSettings, TimeOfDayTable)> {
        load_look(
            self.render_settings.as_ref(),
            self.time_of_day.as_ref(),
            self.cloud_scale,
        )
        .map(|(mut settings, mut table)| {
            if let Some(model) = self.shading {
                table.shading.model = model;
            }
            if let Some(on) = self.cloud_shadows {
                settings.cloud_shadows.enabled = on;
            }
            (settings, table)
        })
    }
}

/// Flags that put a real elevation model under the sky (the demo host's ground).
#[derive(Debug, Default, Args)]
pub struct ElevationArgs {
    /// A square 16-bit greyscale PNG elevation model centred on the flight area (`--at` or the
    /// flight's origin), its top row the northern edge; replaces the ground made from the
    /// stations' elevations.
    #[arg(long, requires_all = ["elevation_size_km", "elevation_range_m"])]
    pub elevation: Option<PathBuf>,
    /// Side of the square the elevation file covers, kilometres.
    #[arg(long, requires = "elevation")]
    pub elevation_size_km: Option<f64>,
    /// Metres above mean sea level of the file's values 0 and 65535.
    #[arg(
        long,
        requires = "elevation",
        value_name = "MIN,MAX",
        value_parser = parse_range_m,
        allow_hyphen_values = true
    )]
    pub elevation_range_m: Option<(f64, f64)>,
}

impl ElevationArgs {
    /// The ground under the weather `field`: the elevation file when given, else the demo
    /// ground of the stations' elevations. Cloud bases stay above the weather's ground, so a
    /// mountain of the file higher than that reaches into the clouds.
    pub fn ground(&self, field: &WeatherField) -> anyhow::Result<HeightField> {
        let (Some(path), Some(size_km), Some((min_m, max_m))) = (
            &self.elevation,
            self.elevation_size_km,
            self.elevation_range_m,
        ) else {
            return Ok(demo_ground(field, &GroundSettings::default()));
        };
        if !(1.0..=1000.0).contains(&size_km) {
            anyhow::bail!("--elevation-size-km {size_km} is outside 1..=1000");
        }
        Ok(HeightField::from_png16(
            path,
            DVec2::ZERO,
            size_km * 1000.0,
            min_m,
            max_m,
        )?)
    }
}

/// How far the demo ground reaches around a camera at `alt_ft`, metres: the shipped square's
/// half side, and from high up (above 18,000 ft) past the horizon (sqrt(2 R h), 370 km from
/// FL350, and a tenth more), so its edge does not cut the far clouds' ground (coarser, at the
/// same vertex count).
pub fn demo_ground_reach_m(alt_ft: f64) -> f64 {
    let shipped_m = GroundSettings::default().size_m / 2.0;
    if alt_ft <= 18_000.0 {
        return shipped_m;
    }
    let horizon_m = (2.0 * 6_371_000.0 * (alt_ft * METRES_PER_FOOT).max(0.0)).sqrt();
    (1.1 * horizon_m).max(shipped_m)
}

/// Parses `MIN,MAX` metres with MIN below MAX.
fn parse_range_m(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("`{s}` is not MIN,MAX (metres, e.g. 0,3000)"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{v}` is not a number of metres"))
    };
    let (min, max) = (parse(a)?, parse(b)?);
    let earthly = -500.0..=9000.0;
    if !(min < max && earthly.contains(&min) && earthly.contains(&max)) {
        return Err(format!(
            "{min},{max}: needs MIN below MAX, both within -500..=9000 m"
        ));
    }
    Ok((min, max))
}

/// The default time: that of the shipped weather file (afternoon in the Americas).
pub const DEFAULT_TIME: &str = "2025-01-27T22:00:00Z";

/// An RFC 3339 time as Unix seconds.
pub fn parse_time(text: &str) -> Result<f64, String> {
    let t: jiff::Timestamp = text.parse().map_err(|e| {
        format!("`{text}` is not an RFC 3339 time such as 2025-01-27T13:00:00Z: {e}")
    })?;
    Ok(t.as_millisecond() as f64 / 1000.0)
}

/// `WIDTHxHEIGHT` in pixels, each 16..=8192.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{text}` is not WIDTHxHEIGHT (for example 1280x720)"))?;
    let side = |s: &str| -> Result<u32, String> {
        let v: u32 = s
            .trim()
            .parse()
            .map_err(|_| format!("`{s}` in `{text}` is not a whole number"))?;
        if (16..=8192).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{v} in `{text}` is outside 16..=8192"))
        }
    };
    Ok((side(w)?, side(h)?))
}

/// Parses `--shading`: wang, or harris-lastra (or harris_lastra).
pub fn parse_shading(text: &str) -> Result<ShadingModel, String> {
    ShadingModel::from_name(text.trim())
        .ok_or_else(|| format!("`{text}` is not a shading model: wang or harris-lastra"))
}

/// Parses an `on` or `off` flag (`--cloud-shadows`).
pub fn parse_on_off(text: &str) -> Result<bool, String> {
    match text.trim() {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{text}` is neither on nor off")),
    }
}

/// Parses `--cloud-scale`: 1, 1/2 or 1/4 (or 0.5, 0.25).
pub fn parse_cloud_scale(text: &str) -> Result<f32, String> {
    let scale = match text.trim() {
        "1" | "1.0" => 1.0,
        "1/2" | "0.5" => 0.5,
        "1/4" | "0.25" => 0.25,
        _ => return Err(format!("`{text}` is not a cloud scale: 1, 1/2 or 1/4")),
    };
    Ok(scale)
}

/// The time a `--time` flag gives, or the shipped weather file's ([`DEFAULT_TIME`]), Unix seconds.
pub fn time_or_default(time: Option<f64>) -> anyhow::Result<f64> {
    match time {
        Some(t) => Ok(t),
        None => parse_time(DEFAULT_TIME).map_err(anyhow::Error::msg),
    }
}

/// The sky of the demo host around `origin` with the look and the weather settings loaded.
pub fn sky_config(
    origin: (f64, f64),
    (settings, table): (RenderSettings, TimeOfDayTable),
    loaded: &Loaded,
) -> SkySystemConfig {
    let mut config = SkySystemConfig::new(skycast::demo::headless::TARGETS, origin);
    config.sky.settings = settings;
    config.sky.time_of_day = table;
    config.field = loaded.settings.clone();
    config.rule = loaded.rule.clone();
    config
}

/// Loads the renderer settings and time-of-day table the flags name (or the shipped ones).
pub fn load_look(
    render: Option<&PathBuf>,
    time_of_day: Option<&PathBuf>,
    cloud_scale: Option<f32>,
) -> anyhow::Result<(RenderSettings, TimeOfDayTable)> {
    let mut settings: RenderSettings =
        defaults::settings(render.map(PathBuf::as_path), "render.toml")?;
    if let Some(scale) = cloud_scale {
        settings.clouds.resolution_scale = scale;
    }
    let table: TimeOfDayTable =
        defaults::settings(time_of_day.map(PathBuf::as_path), "time_of_day.toml")?;
    Ok((settings, table))
}

/// Nearest-texel stretch of a `from`-sized image to `to`.
fn stretch(values: &[f32], from: (u32, u32), to: (u32, u32)) -> Vec<f32> {
    let mut out = Vec::with_capacity((to.0 * to.1) as usize);
    for y in 0..to.1 {
        let sy = (u64::from(y) * u64::from(from.1) / u64::from(to.1.max(1))) as u32;
        for x in 0..to.0 {
            let sx = (u64::from(x) * u64::from(from.0) / u64::from(to.0.max(1))) as u32;
            out.push(
                values
                    .get((sy * from.0 + sx) as usize)
                    .copied()
                    .unwrap_or(0.0),
            );
        }
    }
    out
}

/// Runs `skycast render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if !(-2_000.0..=100_000.0).contains(&args.alt_ft) {
        anyhow::bail!("--alt-ft {} is outside -2000..=100000 feet", args.alt_ft);
    }
    let (mut settings, table) = args.look.load()?;
    // One offline frame: every block of it uploaded and every cloud sorted in that frame, not
    // the nearest few of a simulator frame's budgets. (The blocks right under the camera, out
    // of view, took the upload budget since the buffers grow in place; past the sorting budget
    // a deck's clouds were drawn in their sprites' own order, row by row, which showed each
    // lattice cell as a square from FL350 and the sorted blocks' edge as a staircase.)
    settings.vertex_cache.max_uploaded_sprites_per_frame = u32::MAX;
    settings.vertex_cache.max_sorted_sprites_per_frame = u32::MAX;
    let loaded = load(
        &args.weather,
        args.model.model.as_deref(),
        args.stations.as_deref(),
        None,
        None,
    )?
    .usable()?;
    let (lat, lon) = args.at.resolve(&loaded, args.stations.as_deref())?;
    let unix_s = time_or_default(args.time)?;
    super::model::warn_if_far_in_time(&loaded.input, unix_s);
    let field = loaded
        .input
        .field(LocalFrame::new(lat, lon), &loaded.settings, &loaded.rule);
    let mut ground = args.elevation.ground(&field)?;
    let reach_m = demo_ground_reach_m(args.alt_ft);
    let shipped = GroundSettings::default();
    if args.elevation.elevation.is_none() && 2.0 * reach_m > shipped.size_m {
        ground = demo_ground(
            &field,
            &GroundSettings {
                size_m: 2.0 * reach_m,
                ..shipped
            },
        );
    }
    let mut host = DemoHost::new(
        args.size.0,
        args.size.1,
        &ground,
        sky_config((lat, lon), (settings, table), &loaded),
    )?;
    host.sky.set_weather_field(field);
    // One offline frame: the warm-up, so it has every cloud around.
    host.sky.world_mut().set_synchronous_clouds(true);
    let position = glam::DVec3::new(0.0, 0.0, args.alt_ft * METRES_PER_FOOT);
    let camera = host.camera(position, args.heading, args.pitch);
    // The same frame step a simulator's frame runs (the clouds around generated before it).
    let (frame, stats) = host.step_frame(&camera, unix_s, 0.0)?;
    let sun = sun_position(unix_s, lat, lon);
    frame.write_png(&args.out)?;
    // The clouds' distance (the cloud target's, stretched to the frame): the EXR's
    // `cloud_distance`, and its largest value printed.
    let cloud_distance = host
        .sky
        .sky()
        .read_cloud_distance_m(&host.gpu.queue)
        .map(|(w, h, d)| stretch(&d, (w, h), (frame.width, frame.height)));
    if let Some(exr) = &args.exr {
        frame.write_exr_with(exr, camera.near_m, camera.far_m, cloud_distance.as_deref())?;
    }
    if let Some(d) = &cloud_distance {
        println!(
            "cloud_distance: largest {:.1} km",
            d.iter().fold(0.0f32, |a, &b| a.max(b)) / 1000.0
        );
    }
    let ground_m = ground.height_at_m(glam::DVec2::ZERO);
    println!(
        "{}: {}x{} on {} ({:?}); sun elevation {:.1} deg, azimuth {:.1} deg; camera {:.0} ft MSL, {:.0} ft above the ground; {} clouds, {} sprites; CPU update {} us{}",
        args.out.display(),
        frame.width,
        frame.height,
        host.gpu.adapter_info.name,
        host.gpu.adapter_info.backend,
        sun.elevation_deg,
        sun.azimuth_deg,
        args.alt_ft,
        args.alt_ft - ground_m / METRES_PER_FOOT,
        stats.clouds_drawn,
        stats.sprites_drawn,
        stats.cpu_update_us,
        if stats.sprites_lit > 0 {
            format!(
                " (Harris-Lastra light of {} sprites: {} us)",
                stats.sprites_lit, stats.light_us
            )
        } else {
            String::new()
        },
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shading_flag_names_the_two_models_and_overrides_the_table() {
        assert_eq!(parse_shading("wang"), Ok(ShadingModel::Wang));
        assert_eq!(
            parse_shading("harris-lastra"),
            Ok(ShadingModel::HarrisLastra)
        );
        let err = parse_shading("phong").unwrap_err();
        assert!(err.contains("wang or harris-lastra"), "{err}");
        let look = LookArgs {
            shading: Some(ShadingModel::HarrisLastra),
            ..LookArgs::default()
        };
        let (_, table) = look.load().unwrap();
        assert_eq!(table.shading.model, ShadingModel::HarrisLastra);
        let (_, table) = LookArgs::default().load().unwrap();
        assert_eq!(table.shading.model, ShadingModel::Wang);
    }
}

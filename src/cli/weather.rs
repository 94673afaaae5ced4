//! `skycast weather FILE [--stations FILE] [--at LAT,LON [--alt-ft FT] [--cells-km R]] [--json]`: what a
//! weather file holds and, with `--at`, the interpolated weather of the 4 km block there; with
//! `--alt-ft` too, the air data at that altitude (wind, temperature, pressure, visibility, cloud,
//! turbulence, icing: `skycast::flight::air`), the clouds around generated as a flight would.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use std::sync::Arc;

use anyhow::Context;
use clap::Args;
use glam::{DVec2, DVec3};
use serde::Serialize;
use skycast::flight::{AirData, World, WorldSettings};
use skycast::shading::{FogSettings, sun_position};
use skycast::weather::air::AirSettings;
use skycast::weather::block::{BlockLayer, ceiling_ft, cover_seen_from_below_oktas};
use skycast::weather::field::{CloudTypeRule, FieldSettings};
use skycast::weather::files::WeatherFile;
use skycast::weather::metar::{ConvectiveKind, Cover, SkyCode};
use skycast::weather::storms::{StormContext, cells_over};
use skycast::weather::theme::{self, Theme};
use skycast::weather::winds_aloft::WindsAloft;

use super::defaults;
use super::model::ModelOut;
use skycast::weather::{
    BlockIndex, BlockWeather, LineWarning, LocalFrame, StationTable, WeatherInput,
};

/// Flags of `skycast weather`.
#[derive(Debug, Args)]
pub struct WeatherArgs {
    /// The weather file: metars.cache.csv, a NOAA cycle file, one METAR a line, a weather
    /// theme (`.toml`, see weather/themes/), or a weather model's GRIB2 file (told by its
    /// content).
    pub file: PathBuf,
    /// The model under the reports.
    #[command(flatten)]
    pub model: super::model::ModelArgs,
    /// Station table (NOAA nsd_cccc.txt format) placing reports the file does not place
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Also print the interpolated weather of the block at this latitude,longitude (degrees),
    /// or at a station's ICAO identifier.
    #[arg(long, value_name = "LAT,LON|ICAO", value_parser = parse_place, allow_hyphen_values = true)]
    pub at: Option<Place>,
    /// With `--at`: the air data at this altitude, feet above mean sea level.
    #[arg(long, value_name = "FT", requires = "at", allow_hyphen_values = true)]
    pub alt_ft: Option<f64>,
    /// Air-data settings (default: the shipped config/air.toml).
    #[arg(long)]
    pub air_settings: Option<PathBuf>,
    /// With `--alt-ft`: the winds aloft.
    #[command(flatten)]
    pub aloft: WindsAloftArgs,
    /// Cloud-type rule (default: the shipped config/cloud_type_rule.toml).
    #[arg(long)]
    pub rule: Option<PathBuf>,
    /// Field settings (default: the shipped config/weather_field.toml).
    #[arg(long)]
    pub field_settings: Option<PathBuf>,
    /// With `--at`: list the storm cells within this many km of the point (`"cells"` in JSON).
    #[arg(long, value_name = "KM", requires = "at")]
    pub cells_km: Option<f64>,
    /// One JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `--winds-aloft FILE`, one definition for every command that works out air data
/// (`weather --at --alt-ft`, `fly`, `demo`).
#[derive(Debug, Clone, Default, Args)]
pub struct WindsAloftArgs {
    /// NOAA's winds and temperatures aloft (FB, e.g. FD1US1) for the air data above the
    /// boundary layer, its sites placed through `--stations`.
    #[arg(long, value_name = "FILE")]
    pub winds_aloft: Option<PathBuf>,
}

impl WindsAloftArgs {
    /// The FB product and the station table to place its sites with, if asked for.
    pub fn load(
        &self,
        stations: Option<&Path>,
    ) -> anyhow::Result<Option<(WindsAloft, Arc<StationTable>)>> {
        let Some(path) = &self.winds_aloft else {
            return Ok(None);
        };
        Ok(Some((
            match defaults::shipped(path) {
                Some(bytes) => WindsAloft::parse(&String::from_utf8_lossy(bytes), path)?,
                None => WindsAloft::load(path)?,
            },
            defaults::station_table(stations)?,
        )))
    }
}

/// Where `--at` puts a command: a latitude and longitude, or a station by its ICAO identifier.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// Degrees north and east.
    LatLon(f64, f64),
    /// An ICAO identifier, upper case.
    Station(String),
}

/// `LAT,LON` in degrees, or a station's ICAO identifier (`KOSC`).
pub fn parse_place(text: &str) -> Result<Place, String> {
    if text.contains(',') {
        let (lat, lon) = parse_lat_lon(text)?;
        return Ok(Place::LatLon(lat, lon));
    }
    let id = text.trim();
    if (3..=4).contains(&id.len()) && id.chars().all(|c| c.is_ascii_alphanumeric()) {
        return Ok(Place::Station(id.to_ascii_uppercase()));
    }
    Err(format!(
        "`{text}` is neither LAT,LON (for example 51.85,-8.48) nor a station's ICAO identifier \
         (EGLL)"
    ))
}

impl Place {
    /// Latitude and longitude, degrees: a station's as the loaded file places its report
    /// (where its ceilometer stood), else as the station table (`stations`, or the built-in
    /// one) gives it.
    pub fn resolve(&self, loaded: &Loaded, stations: Option<&Path>) -> anyhow::Result<(f64, f64)> {
        let id = match self {
            Place::LatLon(lat, lon) => return Ok((*lat, *lon)),
            Place::Station(id) => id,
        };
        let in_file = loaded
            .input
            .reports()
            .and_then(|file| file.reports.iter().find(|r| r.report.station == *id));
        if let Some(placed) = in_file {
            return Ok((placed.position.latitude_deg, placed.position.longitude_deg));
        }
        let table = defaults::station_table(stations)?;
        match table.get(id) {
            Some(s) => Ok((s.latitude_deg, s.longitude_deg)),
            None => anyhow::bail!(
                "--at {id}: no such station in the file or the station table (give LAT,LON, or \
                 a table with --stations)"
            ),
        }
    }
}

/// `LAT,LON` in degrees.
pub fn parse_lat_lon(text: &str) -> Result<(f64, f64), String> {
    let (lat, lon) = text
        .split_once(',')
        .ok_or_else(|| format!("`{text}` is not LAT,LON (for example 51.85,-8.48)"))?;
    let lat: f64 = lat
        .trim()
        .parse()
        .map_err(|_| format!("latitude `{lat}` is not a number"))?;
    let lon: f64 = lon
        .trim()
        .parse()
        .map_err(|_| format!("longitude `{lon}` is not a number"))?;
    if !(-90.0..=90.0).contains(&lat) || !(-180.0..=180.0).contains(&lon) {
        return Err(format!(
            "{lat},{lon} is not on Earth (latitude -90..90, longitude -180..180)"
        ));
    }
    Ok((lat, lon))
}

#[derive(Serialize)]
struct ThemeJsonOut<'a> {
    file: &'a Path,
    format: &'static str,
    name: &'a str,
    description: &'a str,
    points: usize,
    at: Option<&'a AtBlock>,
    #[serde(skip_serializing_if = "Option::is_none")]
    air: Option<&'a AirData>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cells: Option<&'a [CellOut]>,
}

/// Counts over the located reports of a file.
#[derive(Debug, Default, Serialize)]
pub struct Summary {
    /// Cloud groups by cover (FEW, SCT, BKN, OVC, VV, and `///` for a missing cover).
    pub layers_by_cover: BTreeMap<&'static str, usize>,
    /// Cloud groups with CB.
    pub cb: usize,
    /// Cloud groups with TCU.
    pub tcu: usize,
    /// Reports with CAVOK.
    pub cavok: usize,
    /// Reports with a no-cloud code (CLR, SKC, NSC, NCD).
    pub clear_code: usize,
    /// Reports with no sky group at all.
    pub no_sky_group: usize,
}

impl Summary {
    /// Counts the located reports of `file`.
    pub fn of(file: &WeatherFile) -> Self {
        let mut s = Summary::default();
        for p in &file.reports {
            let r = &p.report;
            for g in &r.clouds {
                let cover = match g.cover {
                    Some(Cover::Few) => "FEW",
                    Some(Cover::Sct) => "SCT",
                    Some(Cover::Bkn) => "BKN",
                    Some(Cover::Ovc) => "OVC",
                    Some(Cover::Vv) => "VV",
                    None => "///",
                };
                *s.layers_by_cover.entry(cover).or_default() += 1;
                match g.kind {
                    Some(ConvectiveKind::Cb) => s.cb += 1,
                    Some(ConvectiveKind::Tcu) => s.tcu += 1,
                    None => {}
                }
            }
            if r.cavok {
                s.cavok += 1;
            } else if matches!(
                r.sky,
                Some(SkyCode::Clr | SkyCode::Skc | SkyCode::Nsc | SkyCode::Ncd)
            ) {
                s.clear_code += 1;
            } else if r.clouds.is_empty() && r.sky.is_none() {
                s.no_sky_group += 1;
            }
        }
        s
    }
}

/// The weather of one block, for printing.
#[derive(Debug, Serialize)]
pub struct AtBlock {
    /// Latitude asked for, degrees.
    pub lat_deg: f64,
    /// Longitude asked for, degrees.
    pub lon_deg: f64,
    /// The block (of a frame whose origin is the point asked for).
    pub block: BlockIndex,
    /// Its interpolated weather.
    pub weather: BlockWeather,
}

#[derive(Serialize)]
struct JsonOut<'a> {
    file: &'a Path,
    format: skycast::weather::FileFormat,
    reports: usize,
    located: usize,
    warnings: &'a [LineWarning],
    #[serde(flatten)]
    summary: &'a Summary,
    #[serde(skip_serializing_if = "Option::is_none")]
    model: Option<&'a ModelOut>,
    at: Option<&'a AtBlock>,
    #[serde(skip_serializing_if = "Option::is_none")]
    air: Option<&'a AirData>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cells: Option<&'a [CellOut]>,
}

/// Everything `skycast weather` needs, loaded: the weather, the rule and the settings.
pub struct Loaded {
    /// The report file (decoded and placed) or the theme.
    pub input: WeatherInput,
    /// Field settings.
    pub settings: FieldSettings,
    /// Cloud-type rule.
    pub rule: CloudTypeRule,
}

impl Loaded {
    /// Itself if it holds weather to draw a sky from: a report file none of whose reports could
    /// be placed or decoded is an error naming what was skipped (a command that draws would
    /// show an empty sky; `skycast weather` lists such a file instead).
    pub fn usable(self) -> anyhow::Result<Self> {
        Ok(Self {
            input: self.input.usable()?,
            ..self
        })
    }
}

/// Loads the file (with the station table) and the model under it if `model` names one, the rule
/// and the settings.
pub fn load(
    file: &Path,
    model: Option<&Path>,
    stations: Option<&Path>,
    rule: Option<&Path>,
    field_settings: Option<&Path>,
) -> anyhow::Result<Loaded> {
    // A theme places itself; only report files need the station table.
    let table = if theme::is_theme_path(file) {
        None
    } else {
        Some(defaults::station_table(stations)?)
    };
    let input = match defaults::shipped(file) {
        Some(bytes) => WeatherInput::parse(file, bytes, table.as_deref())?,
        None => WeatherInput::load(file, table.as_deref())?,
    };
    let input = match model {
        Some(path) => super::model::attach(input, path, file)?,
        None => input,
    };
    let rule: CloudTypeRule = defaults::settings(rule, "cloud_type_rule.toml")?;
    let settings: FieldSettings = defaults::settings(field_settings, "weather_field.toml")?;
    Ok(Loaded {
        input,
        settings,
        rule,
    })
}

/// The weather of the block at a point: a frame with its origin there, so block (0, 0), whose
/// centre lies 2 km east and 2 km north of the point.
pub fn at_block(loaded: &Loaded, lat_deg: f64, lon_deg: f64) -> AtBlock {
    let frame = LocalFrame::new(lat_deg, lon_deg);
    let field = loaded.input.field(frame, &loaded.settings, &loaded.rule);
    let block = BlockIndex::new(0, 0);
    AtBlock {
        lat_deg,
        lon_deg,
        block,
        weather: field.block_weather(block),
    }
}

/// Runs `skycast weather`.
pub fn run(args: &WeatherArgs) -> anyhow::Result<()> {
    let loaded = load(
        &args.file,
        args.model.model.as_deref(),
        args.stations.as_deref(),
        args.rule.as_deref(),
        args.field_settings.as_deref(),
    )?;
    let at_deg = match &args.at {
        Some(place) => Some(place.resolve(&loaded, args.stations.as_deref())?),
        None => None,
    };
    let at = at_deg.map(|(lat, lon)| at_block(&loaded, lat, lon));
    let cells = match (at_deg, args.cells_km) {
        (Some((lat, lon)), Some(km)) => Some(cells_near(&loaded, lat, lon, km)),
        _ => None,
    };
    if args.aloft.winds_aloft.is_some() && args.alt_ft.is_none() {
        anyhow::bail!("--winds-aloft is for the air data: give --at and --alt-ft with it");
    }
    let air = match (at_deg, args.alt_ft) {
        (Some((lat, lon)), Some(alt_ft)) => {
            let settings: AirSettings =
                defaults::settings(args.air_settings.as_deref(), "air.toml")?;
            let aloft = args.aloft.load(args.stations.as_deref())?;
            Some(air_at(&loaded, lat, lon, alt_ft, settings, aloft.as_ref())?)
        }
        _ => None,
    };
    let now_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    super::model::warn_if_far_in_time(&loaded.input, now_s);
    let model = loaded.input.model().map(|m| ModelOut::of(m));
    let file = match &loaded.input {
        WeatherInput::Reports(file)
        | WeatherInput::Model {
            reports: Some(file),
            ..
        } => file,
        WeatherInput::Model { reports: None, .. } => {
            let model = model.as_ref().context("a model input has its model")?;
            if args.json {
                let out = ModelJsonOut {
                    format: "grib2",
                    model,
                    at: at.as_ref(),
                    air: air.as_ref(),
                    cells: cells.as_deref(),
                };
                println!("{}", serde_json::to_string(&out)?);
            } else {
                print!("{}", model.describe());
                print_at(at.as_ref(), air.as_ref(), cells.as_deref());
            }
            return Ok(());
        }
        WeatherInput::Theme(theme) => {
            if args.json {
                let out = ThemeJsonOut {
                    file: &args.file,
                    format: "theme",
                    name: &theme.name,
                    description: &theme.description,
                    points: theme.points.len(),
                    at: at.as_ref(),
                    air: air.as_ref(),
                    cells: cells.as_deref(),
                };
                println!("{}", serde_json::to_string(&out)?);
            } else {
                print!("{}", describe_theme(&args.file, theme));
                if let Some(at) = &at {
                    print!("{}", describe_block(at));
                }
                if let Some(air) = &air {
                    print!("{}", describe_air(air));
                }
                if let Some(cells) = &cells {
                    print!("{}", describe_cells(cells));
                }
            }
            return Ok(());
        }
    };
    let summary = Summary::of(file);
    if args.json {
        let out = JsonOut {
            file: &file.path,
            format: file.format,
            reports: file.reports_found,
            located: file.reports.len(),
            warnings: &file.warnings,
            summary: &summary,
            model: model.as_ref(),
            at: at.as_ref(),
            air: air.as_ref(),
            cells: cells.as_deref(),
        };
        println!("{}", serde_json::to_string(&out)?);
        return Ok(());
    }
    print!("{}", describe_file(file, &summary, true));
    if let Some(model) = &model {
        print!("{}", model.describe());
    }
    print_at(at.as_ref(), air.as_ref(), cells.as_deref());
    Ok(())
}

/// Prints the block, the air data and the storm cells asked for.
fn print_at(at: Option<&AtBlock>, air: Option<&AirData>, cells: Option<&[CellOut]>) {
    if let Some(at) = at {
        print!("{}", describe_block(at));
    }
    if let Some(air) = air {
        print!("{}", describe_air(air));
    }
    if let Some(cells) = cells {
        print!("{}", describe_cells(cells));
    }
}

/// `skycast weather --json` of a model file alone.
#[derive(Serialize)]
struct ModelJsonOut<'a> {
    format: &'static str,
    model: &'a ModelOut,
    at: Option<&'a AtBlock>,
    #[serde(skip_serializing_if = "Option::is_none")]
    air: Option<&'a AirData>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cells: Option<&'a [CellOut]>,
}

/// One storm cell as `--cells-km` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct CellOut {
    /// Base centre east of the point, metres.
    pub east_m: f64,
    /// Base centre north of the point, metres.
    pub north_m: f64,
    /// Base diameter, metres.
    pub base_width_m: f64,
    /// Base, feet AGL.
    pub base_ft_agl: f32,
    /// Top, feet MSL.
    pub top_ft_msl: f32,
    /// Anvil diameter, metres.
    pub anvil_width_m: f64,
    /// How far downwind the anvil's centre lies from the base's, metres.
    pub anvil_offset_m: f64,
    /// Towards which the anvil spreads, degrees true.
    pub anvil_towards_deg: f64,
    /// The cell's cloud type.
    pub cloud_type: &'static str,
    /// Thunder: 0 none, 1 -TS, 2 TS, 3 +TS.
    pub thunder: u8,
}

/// The storm cells whose base centre lies within `radius_km` of a point, nearest first: a
/// frame with its origin there, decided as the cloud field of a flight decides them.
pub fn cells_near(loaded: &Loaded, lat_deg: f64, lon_deg: f64, radius_km: f64) -> Vec<CellOut> {
    let frame = LocalFrame::new(lat_deg, lon_deg);
    let field = loaded.input.field(frame, &loaded.settings, &loaded.rule);
    let ctx = StormContext {
        lat_deg,
        ..StormContext::default()
    };
    let r = radius_km * 1000.0;
    let mut cells: Vec<_> = cells_over(
        DVec2::splat(-r),
        DVec2::splat(r),
        &mut |p| field.block_weather(BlockIndex::containing(p)),
        &ctx,
        WorldSettings::default().seed,
    )
    .into_iter()
    .filter(|c| c.centre().length() <= r)
    .collect();
    cells.sort_by(|a, b| a.centre().length().total_cmp(&b.centre().length()));
    cells
        .iter()
        .map(|c| {
            let off = c.anvil_offset();
            CellOut {
                east_m: c.centre_m[0].round(),
                north_m: c.centre_m[1].round(),
                base_width_m: c.base_width_m.round(),
                base_ft_agl: c.base_ft_agl.round(),
                top_ft_msl: c.top_ft_msl.round(),
                anvil_width_m: c.anvil_width_m.round(),
                anvil_offset_m: off.length().round(),
                anvil_towards_deg: off.x.atan2(off.y).to_degrees().rem_euclid(360.0).round(),
                cloud_type: c.cloud_type.name(),
                thunder: c.thunder,
            }
        })
        .collect()
}

/// `--cells-km` as text.
pub fn describe_cells(cells: &[CellOut]) -> String {
    use std::fmt::Write as _;
    let mut out = format!("  {} storm cells\n", cells.len());
    for c in cells {
        let _ = writeln!(
            out,
            "  {} at {:.1} km east, {:.1} km north: base {:.1} km across at {:.0} ft AGL, top {:.0} ft MSL, anvil {:.1} km across, {:.1} km downwind (towards {:.0} deg){}",
            c.cloud_type,
            c.east_m / 1000.0,
            c.north_m / 1000.0,
            c.base_width_m / 1000.0,
            c.base_ft_agl,
            c.top_ft_msl,
            c.anvil_width_m / 1000.0,
            c.anvil_offset_m / 1000.0,
            c.anvil_towards_deg,
            ["", ", -TS", ", TS", ", +TS"][c.thunder.min(3) as usize]
        );
    }
    out
}

/// The air data at a point and altitude: a world whose frame has its origin there, its clouds
/// generated around it (as far as the air data looks), the sun where it is now.
pub fn air_at(
    loaded: &Loaded,
    lat_deg: f64,
    lon_deg: f64,
    alt_ft: f64,
    settings: AirSettings,
    aloft: Option<&(WindsAloft, Arc<StationTable>)>,
) -> anyhow::Result<AirData> {
    let frame = LocalFrame::new(lat_deg, lon_deg);
    let field = loaded.input.field(frame, &loaded.settings, &loaded.rule);
    let world_settings = WorldSettings {
        // The search radius, plus a block for the clouds overhanging their blocks.
        cloud_radius_m: settings.in_cloud.search_radius_m + 4_000.0,
        ..WorldSettings::default()
    };
    let mut world = World::new(field, &world_settings);
    world.set_air_settings(settings, FogSettings::default());
    if let Some((fb, table)) = aloft {
        let (placed, unplaced) = world.set_winds_aloft(Some(fb), table);
        eprintln!(
            "winds aloft: {}: {placed} of {} sites placed (not in the station table: {})",
            fb.path.display(),
            fb.sites.len(),
            unplaced.join(" ")
        );
    }
    let point = DVec3::new(0.0, 0.0, alt_ft * skycast::weather::METRES_PER_FOOT);
    world
        .settle_clouds_around(point)
        .context("generating the clouds around the point")?;
    let now_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    let sun = sun_position(now_s, lat_deg, lon_deg).direction_enu();
    Ok(world.air_at(point, sun))
}

/// The text description of the air data.
pub fn describe_air(a: &AirData) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "air at {:.0} ft AGL: wind {:03.0}/{:.0} kt gusting {:.0}, temperature {:.1} C, \
         dewpoint {:.1} C, pressure {:.1} hPa (QNH {:.1}), pressure altitude {:.0} ft, \
         density altitude {:.0} ft",
        a.height_agl_ft,
        a.wind_from_deg,
        a.wind_kt,
        a.gust_kt,
        a.temperature_c,
        a.dewpoint_c,
        a.pressure_hpa,
        a.qnh_hpa,
        a.pressure_altitude_ft,
        a.density_altitude_ft
    );
    let nearest = a
        .nearest_cloud_m
        .map_or("none within reach".to_string(), |d| format!("{d:.0} m"));
    let _ = writeln!(
        out,
        "  visibility {:.0} m, in cloud {:.2} (nearest cloud {nearest}), precipitation {:?} \
         {:.1} mm/h, turbulence {:.2} ({:?}), icing {}",
        a.visibility_m,
        a.in_cloud,
        a.precipitation,
        a.precipitation_mm_h,
        a.turbulence,
        a.turbulence_category,
        if a.icing { "yes" } else { "no" }
    );
    let ceiling = a
        .ceiling_ft_agl
        .map_or("none".to_string(), |c| format!("{c:.0} ft AGL"));
    let _ = writeln!(
        out,
        "  layers above {}, below {}, ceiling {ceiling}, sky covered overhead {:.0}%, sun hidden {:.0}%",
        a.layers_above.len(),
        a.layers_below.len(),
        a.sky_coverage * 100.0,
        a.sun_occlusion * 100.0
    );
    out
}

/// The text summary of a theme.
pub fn describe_theme(path: &Path, theme: &Theme) -> String {
    let place = match theme.points.len() {
        0 => "the same everywhere".to_string(),
        n => format!("pinned to {n} points, interpolated between them"),
    };
    format!(
        "{}: weather theme \"{}\", {place}\n  {}\n",
        path.display(),
        theme.name,
        theme.description
    )
}

/// The text summary of a file; `all_warnings` lists every warning, else only their count.
pub fn describe_file(file: &WeatherFile, summary: &Summary, all_warnings: bool) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let f = file;
    let _ = writeln!(out, "{}: {}", f.path.display(), f.format.describe());
    let _ = writeln!(
        out,
        "  reports {}, located {}, warnings {}",
        f.reports_found,
        f.reports.len(),
        f.warnings.len()
    );
    let covers: Vec<String> = summary
        .layers_by_cover
        .iter()
        .map(|(k, v)| format!("{k} {v}"))
        .collect();
    let _ = writeln!(out, "  layers by cover: {}", covers.join(", "));
    let _ = writeln!(out, "  CB {}, TCU {}", summary.cb, summary.tcu);
    let _ = writeln!(
        out,
        "  CAVOK {}, no-cloud code {}, no sky group {}",
        summary.cavok, summary.clear_code, summary.no_sky_group
    );
    if all_warnings {
        for w in &f.warnings {
            let _ = writeln!(out, "  warning: line {}: {}", w.line, w.message);
        }
    }
    out
}

/// The text description of one block's weather.
pub fn describe_block(at: &AtBlock) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let w = &at.weather;
    let _ = writeln!(
        out,
        "block ({}, {}) at {:.4},{:.4}: visibility {:.0} m, wind {:03.0}/{:.0} kt, \
         temperature {:.1} C, dewpoint {:.1} C, precipitation {:.2}, ground {:.0} m",
        at.block.i,
        at.block.j,
        at.lat_deg,
        at.lon_deg,
        w.visibility_m,
        w.wind.from_deg,
        w.wind.speed_kt,
        w.temperature_c,
        w.dewpoint_c,
        w.precipitation,
        // Rounded first: a sea a few centimetres under the geoid reads 0 m, not -0 m.
        w.ground_elevation_m.round() + 0.0
    );
    if let Some(o) = w.obscuration {
        let name = serde_json::to_value(o)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let _ = writeln!(out, "  obscured by {name}");
    }
    if w.layers.is_empty() {
        let _ = writeln!(out, "  no cloud");
    } else {
        let ceiling =
            ceiling_ft(&w.layers, 5.0).map_or("none".to_string(), |c| format!("{c:.0} ft AGL"));
        let _ = writeln!(out, "  ceiling {ceiling}");
    }
    // The layers a report's covers sum over: CB and TCU are reported with their own amount
    // (ICAO Annex 3), outside the summation principle.
    let summed: Vec<BlockLayer> = w
        .layers
        .iter()
        .filter(|l| !l.has_own_amount())
        .copied()
        .collect();
    for l in &w.layers {
        let source = serde_json::to_value(l.type_source)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let cover = if l.has_own_amount() {
            "its own amount, not summed".to_string()
        } else {
            format!(
                "{:.1} seen from below",
                cover_seen_from_below_oktas(&summed, l.base_ft_agl)
            )
        };
        let _ = writeln!(
            out,
            "  {:<18} {:<11} {:.1} oktas ({cover}), base {:.0} ft AGL, {:.0} ft thick",
            l.cloud_type.name(),
            source,
            l.coverage_oktas,
            l.base_ft_agl,
            l.thickness_ft
        );
    }
    out
}

//! `skycast ceilometer FILE --at LAT,LON [--minutes 20] [--every-s 30] [--json]`: what a
//! ceilometer at a point would read under the clouds skycast makes of a weather file as they
//! drift over it, each reading's bases and the METAR cloud groups they sum up to
//! (`skycast::flight::ceilometer` has the algorithm).

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use serde::Serialize;
use skycast::clouds::CloudsConfig;
use skycast::flight::ceilometer::{self, Layer, Reading};
use skycast::flight::{World, WorldSettings};
use skycast::weather::BlockIndex;

use super::weather::{Place, WindsAloftArgs, load, parse_place};

/// Flags of `skycast ceilometer`.
#[derive(Debug, Args)]
pub struct CeilometerArgs {
    /// The weather file: metars.cache.csv, a NOAA cycle file, one METAR a line, or a weather
    /// theme (`.toml`).
    pub file: PathBuf,
    /// Where the ceilometer stands: latitude,longitude in degrees, or a station's ICAO
    /// identifier (where the file places its report).
    #[arg(long, value_name = "LAT,LON|ICAO", value_parser = parse_place, allow_hyphen_values = true)]
    pub at: Place,
    /// How long it reads, minutes.
    #[arg(long, default_value_t = 20.0)]
    pub minutes: f64,
    /// Seconds between readings.
    #[arg(long, default_value_t = 30.0)]
    pub every_s: f64,
    /// Station table placing reports the file does not place (default: NOAA's table built
    /// into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Seed of the cloud generation: the same report drawn with other clouds (the world's
    /// seed, 2003, unless given).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Clouds settings: the lifecycle and the drift (default: the shipped
    /// config/clouds.toml, or the one in `--config-dir`).
    #[arg(long)]
    pub clouds: Option<PathBuf>,
    /// The winds aloft the clouds drift with.
    #[command(flatten)]
    pub aloft: WindsAloftArgs,
    /// One JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct JsonOut<'a> {
    lat_deg: f64,
    lon_deg: f64,
    minutes: f64,
    every_s: f64,
    readings: &'a [Reading],
    layers: Vec<JsonLayer>,
    ceiling_ft: Option<f64>,
}

#[derive(Serialize)]
struct JsonLayer {
    group: String,
    #[serde(flatten)]
    layer: Layer,
}

/// Reads and prints.
pub fn run(args: &CeilometerArgs) -> anyhow::Result<()> {
    if !(args.minutes > 0.0 && args.minutes <= 24.0 * 60.0) {
        bail!("--minutes must be more than 0 and at most a day (1440)");
    }
    if !(args.every_s >= 1.0 && args.every_s <= args.minutes * 60.0) {
        bail!("--every-s must be at least 1 and at most --minutes");
    }
    let loaded = load(&args.file, None, args.stations.as_deref(), None, None)?.usable()?;
    let (lat, lon) = args.at.resolve(&loaded, args.stations.as_deref())?;
    let (frame, at) = ceilometer::frame_centred_on(lat, lon);
    let field = loaded.input.field(frame, &loaded.settings, &loaded.rule);
    let ground_m = f64::from(
        field
            .block_weather(BlockIndex::new(0, 0))
            .ground_elevation_m,
    );
    // The clouds over the point are the field's nearest: a few kilometres of it is enough.
    let defaults = WorldSettings::default();
    let settings = WorldSettings {
        cloud_radius_m: 6_000.0,
        seed: args.seed.unwrap_or(defaults.seed),
        ..defaults
    };
    let mut world = World::new(field, &settings);
    // As `fly` does: the clouds a flight over the same file would meet.
    if let Some(path) = super::defaults::settings_file(args.clouds.as_deref(), "clouds.toml") {
        world.set_clouds_config(CloudsConfig::load(&path)?);
    }
    if let Some((fb, table)) = args.aloft.load(args.stations.as_deref())? {
        world.set_winds_aloft(Some(&fb), &table);
    }
    let readings = ceilometer::read(&mut world, at, ground_m, args.minutes, args.every_s)?;
    let bins = ceilometer::CoverBins::for_covers(&loaded.settings.oktas);
    let layers = ceilometer::summarize(&readings, &bins);
    let ceiling = ceilometer::ceiling_ft(&layers);
    if args.json {
        let out = JsonOut {
            lat_deg: lat,
            lon_deg: lon,
            minutes: args.minutes,
            every_s: args.every_s,
            readings: &readings,
            layers: layers
                .iter()
                .map(|l| JsonLayer {
                    group: l.group(),
                    layer: *l,
                })
                .collect(),
            ceiling_ft: ceiling,
        };
        println!("{}", serde_json::to_string(&out)?);
        return Ok(());
    }
    println!(
        "ceilometer at {lat:.4},{lon:.4}: {} readings, every {:.0} s for {:.0} min",
        readings.len(),
        args.every_s,
        args.minutes
    );
    for r in &readings {
        let bases: Vec<String> = r.bases_ft.iter().map(|b| format!("{b:.0}")).collect();
        let bases = if bases.is_empty() {
            "clear".to_string()
        } else {
            format!("{} ft", bases.join(", "))
        };
        println!("  {:>6.0} s  {bases}", r.time_s);
    }
    let groups: Vec<String> = layers.iter().map(Layer::group).collect();
    println!(
        "summary: {} (ceiling {})",
        if groups.is_empty() {
            "SKC".to_string()
        } else {
            groups.join(" ")
        },
        ceiling.map_or("none".to_string(), |c| format!("{c:.0} ft"))
    );
    Ok(())
}

//! `skycast block --weather FILE [--stations FILE] --at LAT,LON [--json] [--preview PNG]`: the
//! cloud block at a place: its weather layers and types, clouds, sprites and overdraw.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use skycast::clouds::preview::{self, PreviewSettings};
use skycast::clouds::{CloudBlock, CloudTypes, CloudsConfig, TextureSheet, generate_block};
use skycast::weather::BlockWeather;

use super::weather::{Place, at_block, load, parse_place};

/// Flags of `skycast block`.
#[derive(Debug, Args)]
pub struct BlockArgs {
    /// The weather file (bulk CSV, NOAA cycle file, METAR lines or a theme).
    #[arg(long)]
    pub weather: PathBuf,
    /// Station table placing reports the file does not place.
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Where: latitude,longitude in degrees (the block whose south-west corner is there), or a
    /// station's ICAO identifier.
    #[arg(long, value_name = "LAT,LON|ICAO", value_parser = parse_place, allow_hyphen_values = true)]
    pub at: Place,
    /// Cloud types file (default: the shipped config/cloud_types.toml).
    #[arg(long)]
    pub types: Option<PathBuf>,
    /// Clouds settings, for the world seed (default: the shipped config/clouds.toml).
    #[arg(long)]
    pub clouds: Option<PathBuf>,
    /// The whole block as JSON (every cloud and sprite) instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Also draw the block (CPU orthographic splat) to this PNG.
    #[arg(long)]
    pub preview: Option<PathBuf>,
}

#[derive(Serialize)]
struct JsonOut<'a> {
    lat_deg: f64,
    lon_deg: f64,
    weather: &'a BlockWeather,
    sprites: usize,
    overdraw: f64,
    block: &'a CloudBlock,
}

/// Generates the block and prints it.
pub fn run(args: &BlockArgs) -> anyhow::Result<()> {
    let types = match super::defaults::settings_file(args.types.as_deref(), "cloud_types.toml") {
        Some(path) => CloudTypes::load(&path)?,
        None => CloudTypes::builtin(),
    };
    let config = match super::defaults::settings_file(args.clouds.as_deref(), "clouds.toml") {
        Some(path) => CloudsConfig::load(&path)?,
        None => CloudsConfig::builtin(),
    };
    let loaded = load(&args.weather, None, args.stations.as_deref(), None, None)?.usable()?;
    let (lat, lon) = args.at.resolve(&loaded, args.stations.as_deref())?;
    let at = at_block(&loaded, lat, lon);
    let block = generate_block(at.block, &at.weather, config.field.seed, &types);
    if args.json {
        let out = JsonOut {
            lat_deg: lat,
            lon_deg: lon,
            weather: &at.weather,
            sprites: block.sprite_count(),
            overdraw: block.overdraw(),
            block: &block,
        };
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        print!("{}", describe(lat, lon, &at.weather, &block));
    }
    if let Some(path) = &args.preview {
        let sheet = TextureSheet::generate();
        let settings = PreviewSettings::default();
        preview::render(&[&block], &sheet, &settings)
            .save(path)
            .with_context(|| format!("{}: cannot write image", path.display()))?;
        if !args.json {
            println!("preview: {}", path.display());
        }
    }
    Ok(())
}

/// The text summary: one line for the block, one per layer.
pub fn describe(lat: f64, lon: f64, weather: &BlockWeather, block: &CloudBlock) -> String {
    let mut s = format!(
        "block ({}, {}) at {lat:.4},{lon:.4}: {} layers, {} clouds, {} sprites, overdraw {:.0}%, ground {:.0} m\n",
        block.index.i,
        block.index.j,
        block.layers.len(),
        block.clouds.len(),
        block.sprite_count(),
        block.overdraw() * 100.0,
        weather.ground_elevation_m,
    );
    for l in &block.layers {
        s += &format!(
            "  {:<18} {:.1} oktas (covered {:.0}%), {:.0}-{:.0} m MSL: {} clouds, {} boxes, {} sprites, overdraw {:.0}%\n",
            l.cloud_type.name(),
            l.coverage_oktas,
            l.covered_fraction * 100.0,
            l.base_m,
            l.top_m,
            l.clouds,
            l.boxes,
            l.sprites,
            l.overdraw * 100.0
        );
    }
    s
}

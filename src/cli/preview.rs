//! `skycast preview (--type NAME | --all) --out PATH`: a CPU picture of one block of a cloud
//! type under a typical sky (orthographic splat of its sprites with the sheet textures).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Args;

use skycast::clouds::preview::{self, PreviewSettings};
use skycast::clouds::{CloudTypes, CloudsConfig, TextureSheet, generate_block};
use skycast::weather::{BlockIndex, CloudType};

/// Flags of `skycast preview`.
#[derive(Debug, Args)]
pub struct PreviewArgs {
    /// The cloud type to show (see `skycast types`).
    #[arg(long = "type", value_name = "NAME", conflicts_with = "all")]
    pub cloud_type: Option<String>,
    /// Show every type: writes NAME.png for each into the folder given by --out.
    #[arg(long)]
    pub all: bool,
    /// The PNG to write (a folder with --all).
    #[arg(long)]
    pub out: PathBuf,
    /// Cloud types file (default: the shipped config/cloud_types.toml).
    #[arg(long)]
    pub types: Option<PathBuf>,
    /// Draw the block's life instead: forming at 15, 40, 70 and 100 %, dissipating at 30, 60
    /// and 85 % (config/clouds.toml timings), side by side.
    #[arg(long)]
    pub lifecycle: bool,
    /// World seed.
    #[arg(long, default_value_t = 2003)]
    pub seed: u64,
    /// Image width, pixels.
    #[arg(long, default_value_t = 480)]
    pub width: u32,
    /// Image height, pixels.
    #[arg(long, default_value_t = 270)]
    pub height: u32,
}

/// Draws the block(s) and writes the PNG(s).
pub fn run(args: &PreviewArgs) -> anyhow::Result<()> {
    let types = match super::defaults::settings_file(args.types.as_deref(), "cloud_types.toml") {
        Some(path) => CloudTypes::load(&path)?,
        None => CloudTypes::builtin(),
    };
    if !(16..=4096).contains(&args.width) || !(16..=4096).contains(&args.height) {
        bail!("--width and --height must be 16..=4096 pixels");
    }
    let chosen: Vec<CloudType> = if args.all {
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("{}: cannot create folder", args.out.display()))?;
        CloudType::ALL.to_vec()
    } else {
        let Some(name) = &args.cloud_type else {
            bail!("give --type NAME or --all");
        };
        let Some(t) = CloudType::from_name(name) else {
            bail!(
                "--type {name}: unknown cloud type; expected one of: {}",
                CloudType::ALL.map(CloudType::name).join(", ")
            );
        };
        vec![t]
    };
    let sheet = TextureSheet::generate();
    for t in chosen {
        let (weather, pitch_deg) = preview::typical_weather(t);
        let block = generate_block(BlockIndex::new(0, 0), &weather, args.seed, &types);
        let settings = PreviewSettings {
            width_px: args.width,
            height_px: args.height,
            pitch_deg,
        };
        let img = if args.lifecycle {
            let lifecycle = CloudsConfig::builtin().lifecycle;
            preview::lifecycle_strip(
                &block,
                &sheet,
                &settings,
                &lifecycle,
                &[0.15, 0.4, 0.7, 1.0],
                &[0.3, 0.6, 0.85],
            )
        } else {
            preview::render(&[&block], &sheet, &settings)
        };
        let path = if args.all {
            args.out.join(format!("{}.png", t.name()))
        } else {
            args.out.clone()
        };
        save(&img, &path)?;
        let l = &block.layers[0];
        println!(
            "{}: {} clouds, {} sprites, overdraw {:.0}% -> {}",
            t,
            l.clouds,
            l.sprites,
            l.overdraw * 100.0,
            path.display()
        );
    }
    Ok(())
}

fn save(img: &image::RgbaImage, path: &Path) -> anyhow::Result<()> {
    img.save(path)
        .with_context(|| format!("{}: cannot write image", path.display()))
}

//! `skycast demo`: until the renderer lands, the weather of the default flight area on the shipped
//! bulk weather file: the file's summary, then the interpolated weather of blocks across the area.

use std::path::PathBuf;

use clap::Args;

use super::weather::{DEFAULT_STATIONS, Summary, at_block, describe_block, describe_file, load};

/// The shipped bulk weather file.
pub const DEFAULT_WEATHER: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";

/// Places across the default area: name, latitude, longitude (degrees).
const AREA: [(&str, f64, f64); 5] = [
    ("Cork (EICK, reports SCT018CB)", 51.848, -8.479),
    ("between Cork and Shannon", 52.27, -8.7),
    ("Shannon (EINN)", 52.702, -8.925),
    ("Kerry (EIKY)", 52.181, -9.524),
    ("Waterford coast", 52.0, -7.3),
];

/// Flags of `skycast demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The weather file.
    #[arg(long, default_value = DEFAULT_WEATHER)]
    pub weather: PathBuf,
    /// Station table.
    #[arg(long, default_value = DEFAULT_STATIONS)]
    pub stations: PathBuf,
}

/// Runs `skycast demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let loaded = load(&args.weather, &args.stations, None, None)?;
    print!(
        "{}",
        describe_file(&loaded.file, &Summary::of(&loaded.file), false)
    );
    println!(
        "\nThe default flight area, south-west Ireland (showers and a CB line off the Atlantic):"
    );
    for (name, lat, lon) in AREA {
        println!("\n{name}");
        print!("{}", describe_block(&at_block(&loaded, lat, lon)));
    }
    Ok(())
}

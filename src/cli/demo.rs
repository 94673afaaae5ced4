//! `skycast demo`: until the renderer lands, the weather of the default flight area on the shipped
//! bulk weather file: the file's summary, then the interpolated weather of blocks across the area.

use std::path::PathBuf;

use clap::Args;

use skycast::weather::WeatherInput;

use super::weather::{
    DEFAULT_STATIONS, Summary, at_block, describe_block, describe_file, describe_theme, load,
};

/// The shipped bulk weather file.
pub const DEFAULT_WEATHER: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";

/// Places across the default area, the Irish Sea (24 stations within 250 km in the shipped file):
/// name, latitude, longitude (degrees).
const AREA: [(&str, f64, f64); 6] = [
    (
        "Belfast Aldergrove (EGAC: RA FEW007 OVC042 //////CB)",
        54.614,
        -5.873,
    ),
    ("Isle of Man (EGNS: FEW006 BKN011)", 54.085, -4.632),
    ("the middle of the Irish Sea", 53.8, -5.2),
    ("Dublin (EIDW: -RA FEW008 SCT026 BKN045)", 53.422, -6.298),
    ("Anglesey (EGOV: RA FEW018 BKN045)", 53.252, -4.536),
    (
        "Manchester (EGCC: BKN015 BKN026 OVC031 //////TCU)",
        53.354,
        -2.275,
    ),
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
    match &loaded.input {
        WeatherInput::Reports(file) => print!("{}", describe_file(file, &Summary::of(file), false)),
        WeatherInput::Theme(theme) => print!("{}", describe_theme(&args.weather, theme)),
    }
    println!(
        "\nThe default flight area, the Irish Sea: rain, low broken cloud, a CB over Belfast:"
    );
    for (name, lat, lon) in AREA {
        println!("\n{name}");
        print!("{}", describe_block(&at_block(&loaded, lat, lon)));
    }
    Ok(())
}

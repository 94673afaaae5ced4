//! `skycast demo`: the shipped bulk weather file's summary and the interpolated weather of blocks
//! across the Irish Sea, then the default flight (along the Los Angeles coast under the cumulus
//! the file reports there, as a pilot would fly it that day) rendered through the same real
//! weather into `out/`, with how many of its frames are entirely inside cloud.

use std::path::PathBuf;

use clap::Args;

use skycast::weather::WeatherInput;

use super::weather::{Summary, at_block, describe_block, describe_file, describe_theme, load};

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
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// The flight to render.
    #[arg(long, default_value = DEFAULT_FLIGHT)]
    pub flight: PathBuf,
    /// Directory for the frames and frames.csv.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "960x540", value_parser = super::render::parse_size)]
    pub size: (u32, u32),
    /// Draw and write every Nth simulated frame (10 simulated frames a second).
    #[arg(long, default_value_t = 300)]
    pub every: u32,
    /// The winds aloft for the air data in frames.csv.
    #[command(flatten)]
    pub aloft: super::weather::WindsAloftArgs,
}

/// The default flight of the demo.
pub const DEFAULT_FLIGHT: &str = "config/flights/demo_coast_under_cumulus.toml";

/// Runs `skycast demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let loaded = load(&args.weather, None, args.stations.as_deref(), None, None)?;
    match &loaded.input {
        WeatherInput::Reports(file) => print!("{}", describe_file(file, &Summary::of(file), false)),
        WeatherInput::Theme(theme) => print!("{}", describe_theme(&args.weather, theme)),
        WeatherInput::Model { model, .. } => {
            print!("{}", super::model::ModelOut::of(model).describe())
        }
    }
    println!(
        "\nThe default flight area, the Irish Sea: rain, low broken cloud, a CB over Belfast:"
    );
    for (name, lat, lon) in AREA {
        println!("\n{name}");
        print!("{}", describe_block(&at_block(&loaded, lat, lon)));
    }
    println!(
        "\nRendering {} through {} ...",
        args.flight.display(),
        args.weather.display()
    );
    super::fly::run(&super::fly::FlyArgs {
        weather: args.weather.clone(),
        model: Default::default(),
        stations: args.stations.clone(),
        aloft: args.aloft.clone(),
        path: args.flight.clone(),
        out: args.out.clone(),
        size: args.size,
        fps: 10.0,
        every: args.every,
        time: None,
        look: super::render::LookArgs::default(),
        watch: false,
        settle_ms: 500,
        clouds: None,
        elevation: super::render::ElevationArgs::default(),
        synchronous_clouds: false,
    })?;
    println!(
        "The frames are in {}/ (frame_*.png, frames.csv).",
        args.out.display()
    );
    Ok(())
}

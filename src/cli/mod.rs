//! Command-line glue: parse flags, set up logging, call into the library, pick the exit code.
//! Each subcommand lives in a file of its own beside this one.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod bench;
mod block;
mod ceilometer;
mod defaults;
mod demo;
mod fly;
mod metar;
mod model;
mod preview;
mod render;
mod sheet;
#[cfg(feature = "view")]
mod view;
mod weather;

/// skycast: a cloud and weather sky for flight simulators.
#[derive(Debug, Parser)]
#[command(name = "skycast", version, about, long_about = None)]
struct Cli {
    /// A folder of config files replacing the built-in ones by name (render.toml,
    /// time_of_day.toml, clouds.toml, cloud_types.toml, air.toml, cloud_type_rule.toml,
    /// weather_field.toml, nsd_cccc.txt); a flag naming a file wins.
    #[arg(long, global = true, value_name = "DIR", env = defaults::CONFIG_DIR_ENV)]
    config_dir: Option<std::path::PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Lists the cloud types skycast draws, by the names config files and themes use.
    Types,
    /// Decodes METAR/SPECI reports: station, time, wind, visibility, weather, clouds,
    /// temperature, altimeter.
    Metar(metar::MetarArgs),
    /// What a weather file holds and, with --at, the interpolated weather of the block there.
    Weather(weather::WeatherArgs),
    /// What a ceilometer at a place reads as the clouds drift over it, and the METAR cloud
    /// groups its readings sum up to.
    Ceilometer(ceilometer::CeilometerArgs),
    /// The demo: the weather of the default flight area on the shipped bulk weather file.
    Demo(demo::DemoArgs),
    /// Writes the 16-texture cloud sheet (512 x 512 RGBA PNG, Wang 2003 figure 6).
    Sheet(sheet::SheetArgs),
    /// Renders one frame of real weather over the demo ground (PNG, optionally EXR with depth).
    Render(render::RenderArgs),
    /// Flies a scripted path through real weather: frames, frames.csv and a progress bar.
    Fly(fly::FlyArgs),
    /// Flies through real weather in a window (mouse and keys; needs a display).
    #[cfg(feature = "view")]
    #[command(after_help = view::KEYS_HELP)]
    View(view::ViewArgs),
    /// Draws one block of a cloud type (or of every type) to a PNG, on the CPU.
    Preview(preview::PreviewArgs),
    /// The cloud block at a place: its layers and types, clouds, sprites and overdraw.
    Block(block::BlockArgs),
    /// The frame-budget benchmark: the three overdraw scenarios along one path, impostors on
    /// and off; a table, bench.csv and a plot of frame time.
    Bench(bench::BenchArgs),
}

/// Runs the command line and maps errors to a message on standard error and exit status 2.
pub fn main() -> ExitCode {
    // wgpu probes its OpenGL backend too; on a machine without EGL that logs an error that is
    // none (the Vulkan adapter is used). A real failure to find an adapter is our own message.
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,wgpu_hal::gles=off"),
    )
    .format_timestamp(None)
    .init();
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: first thing in main, before any thread exists. Mesa's Vulkan loader prints
        // "error: XDG_RUNTIME_DIR is invalid" twice on every start without it (harmless, and
        // alarming); /tmp silences it, as the Makefile does.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", "/tmp") };
    }
    let cli = Cli::parse();
    if let Err(err) = defaults::set_config_dir(cli.config_dir) {
        eprintln!("skycast: error: {}", message(&err));
        return ExitCode::from(2);
    }
    let result: anyhow::Result<()> = match cli.command {
        Command::Types => {
            for cloud_type in skycast::weather::CloudType::ALL {
                println!("{cloud_type}");
            }
            Ok(())
        }
        Command::Metar(args) => metar::run(&args),
        Command::Weather(args) => weather::run(&args),
        Command::Ceilometer(args) => ceilometer::run(&args),
        Command::Demo(args) => demo::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Fly(args) => fly::run(&args),
        #[cfg(feature = "view")]
        Command::View(args) => view::run(&args),
        Command::Sheet(args) => sheet::run(&args),
        Command::Preview(args) => preview::run(&args),
        Command::Block(args) => block::run(&args),
        Command::Bench(args) => bench::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("skycast: error: {}", message(&err));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes, each said once: a cause whose text the message already holds (a
/// library error that names its source in its own line) is not repeated.
fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let line = cause.to_string();
        if text.contains(&line) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&line);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::message;

    #[test]
    fn a_cause_the_message_already_names_is_not_repeated() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let err = anyhow::Error::new(io).context("a.csv: cannot read: No such file");
        assert_eq!(message(&err), "a.csv: cannot read: No such file");
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let err = anyhow::Error::new(io).context("station table");
        assert_eq!(message(&err), "station table: No such file");
    }
}

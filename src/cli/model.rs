//! `--model FILE`: a numerical weather model's GRIB2 file under a report file (`weather`,
//! `render`, `fly`, `view`, `bench`), and what the commands print of a model.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use clap::Args;
use serde::Serialize;
use skycast::weather::WeatherInput;
use skycast::weather::model::{ModelField, ModelSettings};

/// `--model FILE`, one definition for every command that takes weather.
#[derive(Debug, Clone, Default, Args)]
pub struct ModelArgs {
    /// A numerical weather model's GRIB2 file (GFS layout) under the weather file's reports:
    /// near a station its report, the model between and beyond (config/weather_model.toml).
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
}

/// `input` with the model of `path` under it; a theme takes none.
pub fn attach(input: WeatherInput, path: &Path, weather: &Path) -> anyhow::Result<WeatherInput> {
    let model = Arc::new(ModelField::load(path)?);
    input.with_model(model).ok_or_else(|| {
        anyhow::anyhow!(
            "--model {}: a model goes under a report file, and {} is a weather theme",
            path.display(),
            weather.display()
        )
    })
}

/// Prints a warning when the input's model is valid far from the simulated time `unix_s`.
pub fn warn_if_far_in_time(input: &WeatherInput, unix_s: f64) {
    if let Some(model) = input.model()
        && let Some(warning) = model.time_warning(unix_s, &ModelSettings::default().time)
    {
        eprintln!("warning: {warning}");
    }
}

/// What `skycast weather` prints of a model file.
#[derive(Debug, Serialize)]
pub struct ModelOut {
    /// The file.
    pub file: PathBuf,
    /// Valid time, `YYYY-MM-DDTHHZ`.
    pub valid: String,
    /// Grid points along a parallel and a meridian.
    pub grid: [usize; 2],
    /// Grid step, degrees of longitude.
    pub step_deg: f64,
    /// Fields in the file, and those decoded.
    pub fields: usize,
    /// Fields decoded.
    pub decoded: usize,
    /// Isobaric levels of the air column, hPa.
    pub levels_hpa: Vec<f64>,
    /// Bytes the decoded fields take.
    pub memory_bytes: usize,
}

impl ModelOut {
    /// The summary of `model`.
    pub fn of(model: &ModelField) -> Self {
        let (y, m, d, h) = model.valid_time();
        let g = &model.grids().grid;
        Self {
            file: model.path.clone(),
            valid: format!("{y:04}-{m:02}-{d:02}T{h:02}Z"),
            grid: [g.ni, g.nj],
            step_deg: g.step_lon_deg,
            fields: model.grids().field_count,
            decoded: model.grids().fields.len(),
            levels_hpa: model
                .levels_pa()
                .iter()
                .map(|&p| p as f64 / 100.0)
                .collect(),
            memory_bytes: model.memory_bytes(),
        }
    }

    /// The text summary.
    pub fn describe(&self) -> String {
        format!(
            "{}: GRIB2 weather model, valid {}\n  grid {} x {} at {} deg, {} fields ({} decoded, \
             {:.1} MB), {} isobaric levels {}..{} hPa\n",
            self.file.display(),
            self.valid,
            self.grid[0],
            self.grid[1],
            self.step_deg,
            self.fields,
            self.decoded,
            self.memory_bytes as f64 / 1e6,
            self.levels_hpa.len(),
            self.levels_hpa.first().copied().unwrap_or(0.0),
            self.levels_hpa.last().copied().unwrap_or(0.0),
        )
    }
}

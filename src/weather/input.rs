//! Any weather input a command takes with `--weather FILE`: a bulk report file (METAR in any of
//! the formats of [`files`]), a weather theme (`.toml`, see [`theme`]) or a numerical weather
//! model's GRIB2 file ([`model`], told by its content), alone or under a report file. All become
//! the same [`WeatherField`].

use std::path::Path;
use std::sync::Arc;

use super::error::{Skipped, WeatherError};
use super::field::{CloudTypeRule, FieldSettings, WeatherField};
use super::files::{self, WeatherFile};
use super::frame::LocalFrame;
use super::model::{self, ModelField, ModelSettings};
use super::stations::StationTable;
use super::theme::{self, Theme};

/// A loaded weather input.
#[derive(Debug, Clone, PartialEq)]
pub enum WeatherInput {
    /// Reports from a bulk weather file, decoded and placed.
    Reports(WeatherFile),
    /// A weather theme.
    Theme(Theme),
    /// A numerical weather model's fields, with the reports of a report file over them (near a
    /// station the report, the model beyond) or alone.
    Model {
        /// The model's fields.
        model: Arc<ModelField>,
        /// The reports blended over the model, if any.
        reports: Option<WeatherFile>,
    },
}

impl WeatherInput {
    /// Loads a theme (a `.toml` file) or a report file (anything else; placed with `stations`
    /// where the file gives no positions).
    pub fn load(path: &Path, stations: Option<&StationTable>) -> Result<Self, WeatherError> {
        let bytes = std::fs::read(path).map_err(|source| WeatherError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, &bytes, stations)
    }

    /// [`load`](Self::load) on bytes already read; `path` tells a theme by its extension and
    /// names the file in errors.
    pub fn parse(
        path: &Path,
        bytes: &[u8],
        stations: Option<&StationTable>,
    ) -> Result<Self, WeatherError> {
        if model::is_grib(bytes) {
            let model = Arc::new(ModelField::parse(path, bytes)?);
            return Ok(Self::Model {
                model,
                reports: None,
            });
        }
        if !theme::is_theme_path(path) {
            return Ok(Self::Reports(files::parse(path, bytes, stations)?));
        }
        let text = String::from_utf8_lossy(bytes);
        // Another TOML file (a config, a flight path) is not weather at all; a theme with a
        // mistake in it gets the theme's own error naming line and field.
        let table: Option<toml::Table> = toml::from_str(&text).ok();
        if table.is_some_and(|t| !t.contains_key("layers") && !t.contains_key("points")) {
            return Err(WeatherError::NotWeather {
                path: path.to_path_buf(),
                reason: "a TOML file, but not a weather theme (it has no [[layers]] or [[points]])"
                    .to_string(),
            });
        }
        Ok(Self::Theme(theme::parse_theme(&text, path)?))
    }

    /// This input with a model's fields under it: a report file's reports blend over the
    /// model; a model takes the new one's place. A theme takes no model: `None`.
    pub fn with_model(self, model: Arc<ModelField>) -> Option<Self> {
        match self {
            Self::Reports(file) => Some(Self::Model {
                model,
                reports: Some(file),
            }),
            Self::Model { reports, .. } => Some(Self::Model { model, reports }),
            Self::Theme(_) => None,
        }
    }

    /// The report file of this input, alone or over a model.
    pub fn reports(&self) -> Option<&WeatherFile> {
        match self {
            Self::Reports(file) => Some(file),
            Self::Model { reports, .. } => reports.as_ref(),
            Self::Theme(_) => None,
        }
    }

    /// The model's fields of this input, if any.
    pub fn model(&self) -> Option<&Arc<ModelField>> {
        match self {
            Self::Model { model, .. } => Some(model),
            _ => None,
        }
    }

    /// What the input left out and why, counted (nothing for a theme or a model alone).
    pub fn skipped(&self) -> Skipped {
        match self.reports() {
            Some(file) => Skipped::new(file.reports_found, file.reports.len(), &file.warnings),
            None => Skipped::default(),
        }
    }

    /// The input itself if it holds weather to build a sky from; a report file none of whose
    /// reports could be used is [`WeatherError::NoUsableReport`], with what was skipped.
    pub fn usable(self) -> Result<Self, WeatherError> {
        match &self {
            Self::Reports(file) if file.reports.is_empty() => Err(WeatherError::NoUsableReport {
                path: file.path.clone(),
                skipped: self.skipped(),
            }),
            _ => Ok(self),
        }
    }

    /// The weather field of this input in `frame`.
    pub fn field(
        &self,
        frame: LocalFrame,
        settings: &FieldSettings,
        rule: &CloudTypeRule,
    ) -> WeatherField {
        match self {
            Self::Reports(file) => WeatherField::build(frame, &file.reports, settings, rule),
            Self::Theme(theme) => WeatherField::from_theme(frame, theme, settings, rule),
            Self::Model { model, reports } => {
                let reports = reports.as_ref().map_or(&[][..], |f| &f.reports[..]);
                WeatherField::build(frame, reports, settings, rule)
                    .with_model(model.clone(), ModelSettings::default())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::{BlockIndex, CloudType, TypeSource};

    fn shipped(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
    }

    fn field_at(input: &WeatherInput, lat: f64, lon: f64) -> WeatherField {
        let frame = LocalFrame::new(lat, lon);
        input.field(frame, &FieldSettings::default(), &CloudTypeRule::default())
    }

    #[test]
    fn a_theme_without_points_is_the_same_everywhere() {
        let input =
            WeatherInput::load(&shipped("weather/themes/frontal_nimbostratus.toml"), None).unwrap();
        let field = field_at(&input, 47.0, 11.0);
        let here = field.block_weather(BlockIndex::new(0, 0));
        let far = field.block_weather(BlockIndex::new(40, -25));
        // The same but where the block is sampled (the theme's one place is in block (0, 0)).
        let rims = |w: &crate::weather::BlockWeather| {
            w.cover
                .as_ref()
                .map(|c| (c.rim.clone(), c.rim_only.clone()))
        };
        assert_eq!(rims(&here), rims(&far));
        assert_eq!(here.layers, far.layers);
        assert_eq!((here.visibility_m, here.wind), (far.visibility_m, far.wind));
        let types: Vec<_> = here
            .layers
            .iter()
            .map(|l| (l.cloud_type, l.type_source))
            .collect();
        assert_eq!(
            types,
            [
                (CloudType::Nimbostratus, TypeSource::Theme),
                (CloudType::Altostratus, TypeSource::Theme)
            ]
        );
        assert_eq!(
            (here.layers[0].base_ft_agl, here.layers[0].thickness_ft),
            (1500.0, 7500.0)
        );
        assert!(
            (here.precipitation - 0.67).abs() < 1e-6,
            "{}",
            here.precipitation
        );
    }

    #[test]
    fn a_pinned_theme_interpolates_between_its_points() {
        let input = WeatherInput::load(
            &shipped("weather/themes/building_cumulus_cb_line.toml"),
            None,
        )
        .unwrap();
        let on_line = field_at(&input, 28.5, -81.3).weather_at(glam::DVec2::ZERO);
        assert_eq!(on_line.layers[0].cloud_type, CloudType::Cumulonimbus);
        assert_eq!(on_line.layers[0].type_source, TypeSource::Theme);
        let out_west = field_at(&input, 28.5, -81.8).weather_at(glam::DVec2::ZERO);
        assert_eq!(out_west.layers[0].cloud_type, CloudType::CumulusMediocris);
        let between = field_at(&input, 28.5, -81.4).weather_at(glam::DVec2::ZERO);
        assert!(
            between.wind.speed_kt < on_line.wind.speed_kt
                && between.wind.speed_kt > out_west.wind.speed_kt
        );
    }

    #[test]
    fn a_broken_theme_is_an_error_naming_file_and_line() {
        let dir = std::env::temp_dir().join(format!("skycast-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.toml");
        std::fs::write(&path, "name = \"x\"\n[[layers]]\ncloud_type = \"cumulus\"\ncover = 2\nbase_ft = 1\ntop_ft = 2\n").unwrap();
        let err = WeatherInput::load(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("bad.toml:3: field `cloud_type`: unknown cloud type `cumulus`"),
            "{err}"
        );
    }
}

//! The artist's time-of-day tables of Wang 2003 sections 5.1 (ambient percentage) and 5.2
//! (maximum directional colour), plus the sky gradient colours, indexed by sun elevation in
//! degrees and read from `config/time_of_day.toml`. Interpolation between samples is linear,
//! the `A_T` of equations (1) and (2).

use std::path::Path;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{DirectionalMapping, ForwardScattering, HarrisLastra, OvercastLight, ShadingSettings};
use crate::config::{ConfigError, ShippedFile, TomlSettings, line_of};

/// The built-in table, `config/time_of_day.toml`.
pub const DEFAULT_TIME_OF_DAY_TOML: &str = include_str!("../../config/time_of_day.toml");

/// One row of the table: the light at one sun elevation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeOfDaySample {
    /// Sun elevation this row applies at, degrees (-90..=90).
    pub sun_elevation_deg: f32,
    /// Factor for the ambient colour levels, 0..=1.
    pub ambient_percent: f32,
    /// Maximum directional (sun) colour, linear RGB.
    pub directional_rgb: [f32; 3],
    /// Sky colour straight up, linear RGB.
    pub sky_zenith_rgb: [f32; 3],
    /// Sky colour at the horizon, linear RGB.
    pub sky_horizon_rgb: [f32; 3],
}

/// The whole table as configured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeOfDayTable {
    /// Wang's Cmin / Cmedian / Cmax.
    pub directional_mapping: DirectionalMapping,
    /// Rows in increasing sun elevation.
    #[serde(rename = "sample")]
    pub samples: Vec<TimeOfDaySample>,
    /// The light under cloud cover (defaults when the table is absent).
    #[serde(default)]
    pub overcast: OvercastLight,
    /// Light scattered forward towards the eye (defaults when the table is absent).
    #[serde(default)]
    pub forward_scattering: ForwardScattering,
    /// Which cloud shading model (Wang when the table is absent).
    #[serde(default)]
    pub shading: ShadingSettings,
    /// The Harris and Lastra model's constants (defaults when the table is absent).
    #[serde(default)]
    pub harris_lastra: HarrisLastra,
}

/// The light at one moment, interpolated from the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeOfDay {
    /// Factor for the ambient colour levels.
    pub ambient_percent: f32,
    /// Maximum directional colour.
    pub directional_rgb: Vec3,
    /// Sky colour straight up.
    pub sky_zenith_rgb: Vec3,
    /// Sky colour at the horizon.
    pub sky_horizon_rgb: Vec3,
}

impl Default for TimeOfDayTable {
    /// The shipped `config/time_of_day.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

impl TomlSettings for TimeOfDayTable {
    const SHIPPED: Option<ShippedFile> =
        ShippedFile::at("config/time_of_day.toml", DEFAULT_TIME_OF_DAY_TOML);

    /// At least one row, rows in increasing sun elevation, and the tables' ranges.
    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        // Rows are checked after parsing; the line is that of the row's elevation key.
        let row_line = |row: usize| {
            text.match_indices("[[sample]]")
                .nth(row)
                .map(|(offset, _)| line_of(text, offset))
        };
        let invalid = |row: usize, field: &str, message: String| ConfigError {
            path: path.to_path_buf(),
            line: row_line(row),
            field: Some(field.to_owned()),
            message,
        };
        if self.samples.is_empty() {
            return Err(ConfigError::whole_file(
                path,
                "needs at least one [[sample]]",
            ));
        }
        for (i, pair) in self.samples.windows(2).enumerate() {
            if pair[1].sun_elevation_deg <= pair[0].sun_elevation_deg {
                return Err(invalid(
                    i + 1,
                    "sun_elevation_deg",
                    format!(
                        "sample {}: {} must be greater than the previous sample's {}",
                        i + 2,
                        pair[1].sun_elevation_deg,
                        pair[0].sun_elevation_deg
                    ),
                ));
            }
        }
        for (i, s) in self.samples.iter().enumerate() {
            if !(0.0..=4.0).contains(&s.ambient_percent) {
                return Err(invalid(
                    i,
                    "ambient_percent",
                    format!("sample {}: {} is outside 0..=4", i + 1, s.ambient_percent),
                ));
            }
        }
        let invalid = self
            .overcast
            .invalid_field()
            .or(self.forward_scattering.invalid_field())
            .or(self.harris_lastra.invalid_field());
        if let Some((field, message)) = invalid {
            return Err(ConfigError::at_key(path, text, field, message));
        }
        Ok(())
    }
}

impl TimeOfDayTable {
    /// The light when the sun stands at `sun_elevation_deg`.
    pub fn at(&self, sun_elevation_deg: f32) -> TimeOfDay {
        let s = &self.samples;
        let (a, b, t) = match s
            .iter()
            .position(|x| x.sun_elevation_deg >= sun_elevation_deg)
        {
            None => (s[s.len() - 1], s[s.len() - 1], 0.0),
            Some(0) => (s[0], s[0], 0.0),
            Some(i) => {
                let (lo, hi) = (s[i - 1], s[i]);
                let t = (sun_elevation_deg - lo.sun_elevation_deg)
                    / (hi.sun_elevation_deg - lo.sun_elevation_deg);
                (lo, hi, t)
            }
        };
        let mix3 = |x: [f32; 3], y: [f32; 3]| Vec3::from_array(x).lerp(Vec3::from_array(y), t);
        TimeOfDay {
            ambient_percent: a.ambient_percent + (b.ambient_percent - a.ambient_percent) * t,
            directional_rgb: mix3(a.directional_rgb, b.directional_rgb),
            sky_zenith_rgb: mix3(a.sky_zenith_rgb, b.sky_zenith_rgb),
            sky_horizon_rgb: mix3(a.sky_horizon_rgb, b.sky_horizon_rgb),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_table_parses_with_more_samples_around_dawn() {
        let t = TimeOfDayTable::parse(DEFAULT_TIME_OF_DAY_TOML, Path::new("built in")).unwrap();
        let near_horizon = t
            .samples
            .iter()
            .filter(|s| (-6.0..=10.0).contains(&s.sun_elevation_deg))
            .count();
        let high = t
            .samples
            .iter()
            .filter(|s| s.sun_elevation_deg > 10.0)
            .count();
        assert!(
            near_horizon >= 5 && near_horizon > high,
            "{near_horizon} vs {high}"
        );
        assert_eq!(TimeOfDayTable::default(), t);
    }

    #[test]
    fn light_fades_towards_night_and_reddens_at_dawn() {
        let t = TimeOfDayTable::default();
        let noon = t.at(60.0);
        let dawn = t.at(1.0);
        let night = t.at(-30.0);
        assert!(noon.ambient_percent > dawn.ambient_percent);
        assert!(dawn.ambient_percent > night.ambient_percent);
        assert_eq!(night.directional_rgb, Vec3::ZERO);
        assert!(dawn.directional_rgb.x > 1.5 * dawn.directional_rgb.z);
    }

    #[test]
    fn interpolates_linearly_between_samples_and_clamps_at_the_ends() {
        let t = TimeOfDayTable::parse(
            "[directional_mapping]\nc_min = 0.1\nc_median = 0.5\nc_max = 1.0\n\
             [[sample]]\nsun_elevation_deg = 0.0\nambient_percent = 0.2\ndirectional_rgb = [0,0,0]\n\
             sky_zenith_rgb = [0,0,0]\nsky_horizon_rgb = [0,0,0]\n\
             [[sample]]\nsun_elevation_deg = 10.0\nambient_percent = 0.6\ndirectional_rgb = [1,1,1]\n\
             sky_zenith_rgb = [1,1,1]\nsky_horizon_rgb = [1,1,1]\n",
            Path::new("t.toml"),
        )
        .unwrap();
        assert!((t.at(2.5).ambient_percent - 0.3).abs() < 1e-6);
        assert_eq!(t.at(2.5).directional_rgb, Vec3::splat(0.25));
        assert_eq!(t.at(-50.0).ambient_percent, 0.2);
        assert_eq!(t.at(50.0).ambient_percent, 0.6);
    }

    #[test]
    fn bad_tables_name_file_line_and_field() {
        let text = DEFAULT_TIME_OF_DAY_TOML.replacen(
            "ambient_percent = 0.0248",
            "ambient_percent = \"x\"",
            1,
        );
        let err = TimeOfDayTable::parse(&text, Path::new("my_tod.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("my_tod.toml:17: field `ambient_percent`"),
            "{err}"
        );
        let text = DEFAULT_TIME_OF_DAY_TOML.replacen(
            "sun_elevation_deg = -12.0",
            "sun_elevation_deg = -40.0",
            1,
        );
        let err = TimeOfDayTable::parse(&text, Path::new("my_tod.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("sample 3") && err.contains("sun_elevation_deg"),
            "{err}"
        );
        let text = DEFAULT_TIME_OF_DAY_TOML.replacen("grey_from = 0.6", "grey_from = 2.0", 1);
        let err = TimeOfDayTable::parse(&text, Path::new("my_tod.toml"))
            .unwrap_err()
            .to_string();
        let line = 1 + DEFAULT_TIME_OF_DAY_TOML
            .lines()
            .position(|l| l.starts_with("grey_from"))
            .unwrap();
        assert!(
            err.starts_with(&format!("my_tod.toml:{line}: field `overcast.grey_from`")),
            "{err}"
        );
    }

    #[test]
    fn the_shading_model_is_named_in_the_table_and_a_wrong_one_says_where() {
        assert_eq!(
            TimeOfDayTable::default().shading.model,
            crate::shading::ShadingModel::Wang
        );
        let text =
            DEFAULT_TIME_OF_DAY_TOML.replacen("model = \"wang\"", "model = \"harris_lastra\"", 1);
        let t = TimeOfDayTable::parse(&text, Path::new("my_tod.toml")).unwrap();
        assert_eq!(t.shading.model, crate::shading::ShadingModel::HarrisLastra);
        let text = DEFAULT_TIME_OF_DAY_TOML.replacen("model = \"wang\"", "model = \"phong\"", 1);
        let err = TimeOfDayTable::parse(&text, Path::new("my_tod.toml"))
            .unwrap_err()
            .to_string();
        let line = 1 + DEFAULT_TIME_OF_DAY_TOML
            .lines()
            .position(|l| l.starts_with("model ="))
            .unwrap();
        assert!(
            err.starts_with(&format!("my_tod.toml:{line}: field `model`")) && err.contains("phong"),
            "{err}"
        );
        let text = DEFAULT_TIME_OF_DAY_TOML.replacen("albedo = 0.9", "albedo = 2.0", 1);
        let err = TimeOfDayTable::parse(&text, Path::new("my_tod.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("field `harris_lastra.albedo`"), "{err}");
    }
}

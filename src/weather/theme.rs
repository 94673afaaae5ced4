//! Weather themes: METAR-like TOML files that name their cloud types outright, as simulator users
//! and scenario authors write them (`weather/themes/*.toml`).
//!
//! A theme has surface conditions and cloud layers (cover, base, top, type). Without `[[points]]`
//! it applies everywhere; with them, each point is a place with its own conditions (or the
//! theme's), and the weather between them comes from the same natural-neighbour field as reports.
//! Heights are feet above ground unless a layer says `reference = "msl"`.

use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use super::block::{BlockLayer, TypeSource, Wind};
use super::cloud_type::CloudType;
use crate::config::{ConfigError, parse_toml, read_text};

const FEET_PER_METRE: f32 = 3.280_84;

/// A parsed, validated theme.
#[derive(Debug, Clone, PartialEq)]
pub struct Theme {
    /// Display name.
    pub name: String,
    /// What the theme shows.
    pub description: String,
    /// The theme's own conditions: the weather everywhere when `points` is empty.
    pub everywhere: ThemeWeather,
    /// Places the weather is pinned to, each with its weather; empty when it applies everywhere.
    pub points: Vec<ThemePoint>,
}

/// A place a theme pins weather to.
#[derive(Debug, Clone, PartialEq)]
pub struct ThemePoint {
    /// Latitude, degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
    /// The weather there.
    pub weather: ThemeWeather,
}

/// The weather a theme gives one place: surface conditions and cloud layers with named types.
#[derive(Debug, Clone, PartialEq)]
pub struct ThemeWeather {
    /// Cloud layers, lowest base first, heights above ground, `TypeSource::Theme`.
    pub layers: Vec<BlockLayer>,
    /// Visibility, metres.
    pub visibility_m: f32,
    /// Surface wind.
    pub wind: Wind,
    /// Temperature, degrees C.
    pub temperature_c: f32,
    /// Dewpoint, degrees C.
    pub dewpoint_c: f32,
    /// Precipitation, as a METAR intensity (the field settings turn it into 0..=1).
    pub precipitation: Precipitation,
    /// Thunder, as METAR grades `TS` (`light` is `-TS`, `heavy` is `+TS`): what makes the
    /// theme's cumulonimbus cells flash.
    pub thunder: Precipitation,
    /// Ground elevation, metres above mean sea level.
    pub ground_elevation_m: f32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ThemeFile {
    name: String,
    #[serde(default)]
    description: String,
    #[serde(default)]
    surface: SurfaceFile,
    #[serde(default)]
    layers: Vec<LayerFile>,
    #[serde(default)]
    points: Vec<PointFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointFile {
    lat: Spanned<f64>,
    lon: Spanned<f64>,
    surface: Option<SurfaceFile>,
    layers: Option<Vec<LayerFile>>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SurfaceFile {
    visibility_m: f32,
    wind_from_deg: f32,
    wind_speed_kt: f32,
    temperature_c: f32,
    dewpoint_c: f32,
    precipitation: Precipitation,
    thunder: Precipitation,
    ground_elevation_m: f32,
}

impl Default for SurfaceFile {
    fn default() -> Self {
        Self {
            visibility_m: 30_000.0,
            wind_from_deg: 0.0,
            wind_speed_kt: 0.0,
            temperature_c: 15.0,
            dewpoint_c: 5.0,
            precipitation: Precipitation::None,
            thunder: Precipitation::None,
            ground_elevation_m: 0.0,
        }
    }
}

/// Precipitation a theme asks for, as METAR grades it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precipitation {
    /// None.
    None,
    /// Light (`-RA`).
    Light,
    /// Moderate (`RA`).
    Moderate,
    /// Heavy (`+RA`).
    Heavy,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerFile {
    cloud_type: Spanned<String>,
    cover: Spanned<CoverFile>,
    base_ft: Spanned<f32>,
    top_ft: Spanned<f32>,
    #[serde(default)]
    reference: HeightReference,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum CoverFile {
    Code(String),
    Oktas(i64),
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum HeightReference {
    /// Feet above ground level.
    #[default]
    Agl,
    /// Feet above mean sea level.
    Msl,
}

/// Whether a file looks like a theme rather than a report file (by its `.toml` extension).
pub fn is_theme_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|ext| ext.eq_ignore_ascii_case("toml"))
}

/// Reads and validates a theme file.
pub fn load_theme(path: &Path) -> Result<Theme, ConfigError> {
    let text = read_text(path)?;
    parse_theme(&text, path)
}

/// Parses and validates theme text that came from `path` (used in messages).
pub fn parse_theme(text: &str, path: &Path) -> Result<Theme, ConfigError> {
    let file: ThemeFile = parse_toml(text, path)?;
    let ctx = Ctx { path, text };
    let everywhere = ctx.weather(&file.surface, &file.layers)?;
    let mut points = Vec::with_capacity(file.points.len());
    for point in &file.points {
        let lat_deg = ctx.within(&point.lat, "lat", -90.0, 90.0)?;
        let lon_deg = ctx.within(&point.lon, "lon", -180.0, 180.0)?;
        let surface = point.surface.as_ref().unwrap_or(&file.surface);
        let layers = point.layers.as_deref().unwrap_or(&file.layers);
        points.push(ThemePoint {
            lat_deg,
            lon_deg,
            weather: ctx.weather(surface, layers)?,
        });
    }
    Ok(Theme {
        name: file.name,
        description: file.description,
        everywhere,
        points,
    })
}

struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    fn error<T>(&self, spanned: &Spanned<T>, field: &str, message: String) -> ConfigError {
        ConfigError::at(self.path, self.text, spanned.span(), field, message)
    }

    fn within(
        &self,
        value: &Spanned<f64>,
        field: &str,
        min: f64,
        max: f64,
    ) -> Result<f64, ConfigError> {
        let v = *value.get_ref();
        if (min..=max).contains(&v) {
            Ok(v)
        } else {
            Err(self.error(value, field, format!("{v} is outside {min}..={max}")))
        }
    }

    fn weather(
        &self,
        surface: &SurfaceFile,
        layers: &[LayerFile],
    ) -> Result<ThemeWeather, ConfigError> {
        let mut out: Vec<(BlockLayer, &LayerFile)> = Vec::with_capacity(layers.len());
        for layer in layers {
            out.push((self.layer(layer, surface.ground_elevation_m)?, layer));
        }
        out.sort_by(|a, b| a.0.base_ft_agl.total_cmp(&b.0.base_ft_agl));
        for pair in out.windows(2) {
            let (below, above) = (&pair[0].0, &pair[1]);
            let below_top = below.base_ft_agl + below.thickness_ft;
            if above.0.base_ft_agl < below_top {
                let message = format!(
                    "layer overlaps the {} layer from {:.0} to {:.0} ft above ground",
                    below.cloud_type, below.base_ft_agl, below_top
                );
                return Err(self.error(&above.1.base_ft, "base_ft", message));
            }
        }
        Ok(ThemeWeather {
            layers: out.into_iter().map(|(layer, _)| layer).collect(),
            visibility_m: surface.visibility_m,
            wind: Wind {
                from_deg: surface.wind_from_deg,
                speed_kt: surface.wind_speed_kt,
            },
            temperature_c: surface.temperature_c,
            dewpoint_c: surface.dewpoint_c,
            precipitation: surface.precipitation,
            thunder: surface.thunder,
            ground_elevation_m: surface.ground_elevation_m,
        })
    }

    fn layer(&self, layer: &LayerFile, ground_elevation_m: f32) -> Result<BlockLayer, ConfigError> {
        let name = layer.cloud_type.get_ref();
        let cloud_type = CloudType::from_name(name).ok_or_else(|| {
            let known: Vec<_> = CloudType::ALL.iter().map(|t| t.name()).collect();
            self.error(
                &layer.cloud_type,
                "cloud_type",
                format!("unknown cloud type `{name}`; known: {}", known.join(", ")),
            )
        })?;
        let coverage_oktas = match layer.cover.get_ref() {
            CoverFile::Code(code) => match code.as_str() {
                "FEW" => 2.0,
                "SCT" => 4.0,
                "BKN" => 6.0,
                "OVC" => 8.0,
                other => {
                    return Err(self.error(
                        &layer.cover,
                        "cover",
                        format!("`{other}` is not FEW, SCT, BKN, OVC or oktas 1..=8"),
                    ));
                }
            },
            CoverFile::Oktas(oktas @ 1..=8) => *oktas as f32,
            CoverFile::Oktas(other) => {
                return Err(self.error(
                    &layer.cover,
                    "cover",
                    format!("{other} oktas is outside 1..=8"),
                ));
            }
        };
        let (base, top) = (*layer.base_ft.get_ref(), *layer.top_ft.get_ref());
        if !base.is_finite() || base < 0.0 {
            return Err(self.error(
                &layer.base_ft,
                "base_ft",
                format!("{base} must be a height of 0 ft or more"),
            ));
        }
        if !top.is_finite() || top <= base {
            return Err(self.error(
                &layer.top_ft,
                "top_ft",
                format!("top {top} ft is not above the base {base} ft"),
            ));
        }
        let ground_ft = match layer.reference {
            HeightReference::Agl => 0.0,
            HeightReference::Msl => ground_elevation_m * FEET_PER_METRE,
        };
        if base - ground_ft < 0.0 {
            let message = format!("base {base} ft MSL is below the ground at {ground_ft:.0} ft");
            return Err(self.error(&layer.base_ft, "base_ft", message));
        }
        Ok(BlockLayer {
            cloud_type,
            type_source: TypeSource::Theme,
            coverage_oktas,
            base_ft_agl: base - ground_ft,
            thickness_ft: top - base,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FAIR: &str = r#"
name = "Fair"

[surface]
visibility_m = 40000
wind_from_deg = 250
wind_speed_kt = 8

[[layers]]
cloud_type = "cirrus"
cover = 2
base_ft = 25000
top_ft = 27000

[[layers]]
cloud_type = "cumulus_humilis"
cover = "SCT"
base_ft = 3500
top_ft = 5000
"#;

    fn parse(text: &str) -> Result<Theme, ConfigError> {
        parse_theme(text, Path::new("weather/themes/test.toml"))
    }

    fn error_of(text: &str) -> ConfigError {
        parse(text).unwrap_err()
    }

    #[test]
    fn layers_come_out_sorted_with_theme_source() {
        let theme = parse(FAIR).unwrap();
        let layers = &theme.everywhere.layers;
        assert_eq!(layers.len(), 2);
        assert_eq!(layers[0].cloud_type, CloudType::CumulusHumilis);
        assert_eq!(
            (
                layers[0].coverage_oktas,
                layers[0].base_ft_agl,
                layers[0].thickness_ft
            ),
            (4.0, 3500.0, 1500.0)
        );
        assert_eq!(layers[1].type_source, TypeSource::Theme);
        assert_eq!(
            theme.everywhere.wind,
            Wind {
                from_deg: 250.0,
                speed_kt: 8.0
            }
        );
        assert!(theme.points.is_empty());
    }

    #[test]
    fn msl_heights_become_agl_over_the_ground() {
        let text = "name = \"x\"\n[surface]\nground_elevation_m = 1000\n[[layers]]\ncloud_type = \"stratus\"\ncover = \"OVC\"\nbase_ft = 4000\ntop_ft = 5000\nreference = \"msl\"\n";
        let layer = parse(text).unwrap().everywhere.layers[0];
        assert!(
            (layer.base_ft_agl - (4000.0 - 3280.84)).abs() < 0.01,
            "{layer:?}"
        );
    }

    #[test]
    fn points_inherit_or_override() {
        let text = format!(
            "{FAIR}\n[[points]]\nlat = 47.0\nlon = 11.0\n\n[[points]]\nlat = 48.0\nlon = 12.0\n[[points.layers]]\ncloud_type = \"cumulonimbus\"\ncover = \"BKN\"\nbase_ft = 3000\ntop_ft = 35000\n"
        );
        let theme = parse(&text).unwrap();
        assert_eq!(theme.points.len(), 2);
        assert_eq!(theme.points[0].weather.layers, theme.everywhere.layers);
        assert_eq!(
            theme.points[1].weather.layers[0].cloud_type,
            CloudType::Cumulonimbus
        );
    }

    #[test]
    fn unknown_type_names_line_and_field() {
        let err = error_of(&FAIR.replace("\"cirrus\"", "\"cumulus\""));
        assert_eq!(
            (err.line, err.field.as_deref()),
            (Some(10), Some("cloud_type"))
        );
        assert!(
            err.message.contains("unknown cloud type `cumulus`"),
            "{err}"
        );
    }

    #[test]
    fn top_below_base_is_an_error() {
        let err = error_of(&FAIR.replace("top_ft = 5000", "top_ft = 3000"));
        assert_eq!((err.line, err.field.as_deref()), (Some(19), Some("top_ft")));
    }

    #[test]
    fn overlapping_layers_are_an_error() {
        let err = error_of(&FAIR.replace("base_ft = 25000", "base_ft = 4500"));
        assert_eq!(
            (err.line, err.field.as_deref()),
            (Some(12), Some("base_ft"))
        );
        assert!(
            err.message.contains("overlaps the cumulus_humilis layer"),
            "{err}"
        );
    }

    #[test]
    fn bad_cover_and_position_and_fields() {
        assert_eq!(
            error_of(&FAIR.replace("\"SCT\"", "\"LOTS\""))
                .field
                .as_deref(),
            Some("cover")
        );
        assert_eq!(
            error_of(&FAIR.replace("cover = 2", "cover = 9")).line,
            Some(11)
        );
        let err = error_of(&format!("{FAIR}\n[[points]]\nlat = 97.0\nlon = 11.0\n"));
        assert_eq!(err.field.as_deref(), Some("lat"));
        assert_eq!(
            error_of(&FAIR.replace("wind_speed_kt", "wind_speed"))
                .field
                .as_deref(),
            Some("wind_speed")
        );
        assert_eq!(
            error_of("description = \"no name\"\n").field.as_deref(),
            Some("name")
        );
    }

    #[test]
    fn every_shipped_theme_loads() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("weather/themes");
        let mut count = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let theme = load_theme(&path).unwrap_or_else(|err| panic!("{err}"));
            assert!(
                !theme.everywhere.layers.is_empty() || !theme.points.is_empty(),
                "{path:?}"
            );
            count += 1;
        }
        assert!(count >= 5, "{count} themes shipped");
    }
}

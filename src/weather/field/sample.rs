//! One station's values as the field interpolates them: per band coverage, base, thickness and
//! CB/TCU flags, plus the surface values. Built from a [`PlacedReport`] with the settings.
//!
//! Per band, the band's layers merge into one: coverage is the largest of its groups (METAR
//! covers are cumulative, each group counts all cloud at and below it), the base is the lowest
//! base (or the base of the band's lowest CB/TCU group, the cloud that will be drawn), the top the
//! highest base plus that group's default thickness. VV is a fog layer as deep
//! as the vertical visibility; FG in present weather a fog layer of the configured depth.
//! CAVOK/NSC/NCD/SKC/CLR stations have zero coverage in every band; a station with no sky group at
//! all has no cloud sample (it is left out of the cloud field).
//!
//! A band may also carry a named cloud type: from a cloud-type remark (`RMK SC4AC2`, the type of
//! the band's lowest group the remark names) or from a weather theme, whose layers name theirs.

use crate::weather::block::TypeSource;
use crate::weather::cloud_type::CloudType;
use crate::weather::files::PlacedReport;
use crate::weather::metar::{ConvectiveKind, Cover, Intensity, Report, SkyCode};
use crate::weather::remarks::remark_types;
use crate::weather::theme::{Precipitation as ThemePrecipitation, ThemeWeather};

use super::rule::Band;
use super::settings::FieldSettings;

/// Precipitation phenomena of present weather.
const PRECIPITATION: [&str; 9] = ["DZ", "RA", "SN", "SG", "IC", "PL", "GR", "GS", "UP"];

/// One band of one station.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BandSample {
    /// Coverage, oktas; 0 when the band is clear.
    pub coverage_oktas: f64,
    /// Lowest base in the band, feet AGL (meaningless when coverage is 0).
    pub base_ft: f64,
    /// Base to top, feet.
    pub thickness_ft: f64,
    /// A CB was reported in the band.
    pub cb: bool,
    /// A TCU was reported in the band.
    pub tcu: bool,
    /// The cloud type a remark or a theme names for the band, and which of the two.
    pub named: Option<(CloudType, TypeSource)>,
}

/// One station's values.
#[derive(Debug, Clone, PartialEq)]
pub struct StationSample {
    /// Per band (fog, low, middle, high); `None` when the report says nothing about the sky.
    pub bands: Option<[BandSample; 4]>,
    /// Visibility, metres.
    pub visibility_m: Option<f64>,
    /// Wind as the velocity the air moves with, knots east/north.
    pub wind_kt: Option<[f64; 2]>,
    /// Temperature, degrees C.
    pub temperature_c: Option<f64>,
    /// Dewpoint, degrees C.
    pub dewpoint_c: Option<f64>,
    /// Precipitation intensity 0..=1.
    pub precipitation: f64,
    /// Station elevation, metres.
    pub elevation_m: Option<f64>,
}

/// The band index of a base.
pub fn band_of(base_ft: f64, settings: &FieldSettings) -> Band {
    if base_ft < settings.bands.low_top_ft {
        Band::Low
    } else if base_ft > settings.bands.high_base_ft {
        Band::High
    } else {
        Band::Middle
    }
}

fn index(band: Band) -> usize {
    Band::ALL.iter().position(|&b| b == band).unwrap_or(0)
}

impl StationSample {
    /// The sample of a placed report; `None` for a NIL report (it says nothing).
    pub fn of(placed: &PlacedReport, settings: &FieldSettings) -> Option<Self> {
        let r = &placed.report;
        if r.sky == Some(SkyCode::Nil) {
            return None;
        }
        let wind_kt = r.wind.and_then(|w| {
            let speed = w.speed_kt? as f64;
            // VRB (no direction) moves the air nowhere in particular: a zero vector.
            let Some(dir) = w.dir_deg else {
                return Some([0.0, 0.0]);
            };
            Some(wind_velocity_kt(f64::from(dir), speed))
        });
        let visibility_m = if r.cavok {
            Some(settings.defaults.cavok_visibility_m)
        } else {
            r.visibility_m.map(f64::from)
        };
        Some(Self {
            bands: sky_bands(r, settings),
            visibility_m,
            wind_kt,
            temperature_c: r.temperature_c.map(f64::from),
            dewpoint_c: r.dewpoint_c.map(f64::from),
            precipitation: precipitation(r, settings),
            elevation_m: placed.position.elevation_m,
        })
    }

    /// The sample of one place of a weather theme: its layers keep the types they name.
    pub fn of_theme(weather: &ThemeWeather, settings: &FieldSettings) -> Self {
        let mut bands = [BandSample::default(); 4];
        for layer in &weather.layers {
            let band = if layer.cloud_type == CloudType::Fog {
                Band::Fog
            } else {
                band_of(f64::from(layer.base_ft_agl), settings)
            };
            let b = &mut bands[index(band)];
            let coverage = f64::from(layer.coverage_oktas);
            // Two theme layers in one band: the band is drawn as the one covering more sky.
            if coverage > b.coverage_oktas {
                *b = BandSample {
                    coverage_oktas: coverage,
                    base_ft: f64::from(layer.base_ft_agl),
                    thickness_ft: f64::from(layer.thickness_ft),
                    cb: false,
                    tcu: false,
                    named: Some((layer.cloud_type, TypeSource::Theme)),
                };
            }
        }
        let p = &settings.precipitation;
        let wind = weather.wind;
        Self {
            bands: Some(bands),
            visibility_m: Some(f64::from(weather.visibility_m)),
            wind_kt: Some(wind_velocity_kt(
                f64::from(wind.from_deg),
                f64::from(wind.speed_kt),
            )),
            temperature_c: Some(f64::from(weather.temperature_c)),
            dewpoint_c: Some(f64::from(weather.dewpoint_c)),
            precipitation: match weather.precipitation {
                ThemePrecipitation::None => 0.0,
                ThemePrecipitation::Light => p.light,
                ThemePrecipitation::Moderate => p.moderate,
                ThemePrecipitation::Heavy => p.heavy,
            },
            elevation_m: Some(f64::from(weather.ground_elevation_m)),
        }
    }
}

/// The velocity (knots east, north) of a wind blowing from `from_deg`.
fn wind_velocity_kt(from_deg: f64, speed_kt: f64) -> [f64; 2] {
    let to = (from_deg + 180.0).to_radians();
    [to.sin() * speed_kt, to.cos() * speed_kt]
}

/// The heaviest precipitation of the report's present weather, 0..=1.
pub fn precipitation(r: &Report, settings: &FieldSettings) -> f64 {
    r.weather
        .iter()
        .filter(|w| {
            w.phenomena
                .iter()
                .any(|p| PRECIPITATION.contains(&p.as_str()))
        })
        .map(|w| match w.intensity {
            Intensity::Light => settings.precipitation.light,
            Intensity::Moderate => settings.precipitation.moderate,
            Intensity::Heavy => settings.precipitation.heavy,
            Intensity::Vicinity => 0.0,
        })
        .fold(0.0, f64::max)
}

fn has_fog(r: &Report) -> bool {
    r.weather
        .iter()
        .any(|w| w.intensity != Intensity::Vicinity && w.phenomena.iter().any(|p| p == "FG"))
}

/// Per-band samples, or `None` when the report has no sky statement at all.
fn sky_bands(r: &Report, settings: &FieldSettings) -> Option<[BandSample; 4]> {
    let fog = has_fog(r);
    if !r.cavok && r.sky.is_none() && r.clouds.is_empty() && !fog {
        return None;
    }
    let mut bands = [BandSample::default(); 4];
    let mut top_ft = [0.0f64; 4];
    let mut convective_base_ft: [Option<f64>; 4] = [None; 4];
    if fog {
        let f = &mut bands[index(Band::Fog)];
        f.coverage_oktas = 8.0;
        f.thickness_ft = settings.fog.thickness_ft;
    }
    let named = remark_types(&r.clouds, &r.remarks);
    for (g, named) in r.clouds.iter().zip(named) {
        if g.cover == Some(Cover::Vv) {
            if let Some(t) = named {
                bands[index(Band::Fog)].named = Some((t, TypeSource::Remark));
            }
            let f = &mut bands[index(Band::Fog)];
            f.coverage_oktas = 8.0;
            f.base_ft = 0.0;
            let depth = g.base_ft.map_or(settings.fog.thickness_ft, f64::from);
            f.thickness_ft = f.thickness_ft.max(depth);
            continue;
        }
        let band = g
            .base_ft
            .map_or(Band::Low, |b| band_of(f64::from(b), settings));
        let i = index(band);
        let b = &mut bands[i];
        if let (None, Some(t)) = (b.named, named) {
            b.named = Some((t, TypeSource::Remark));
        }
        match g.kind {
            Some(ConvectiveKind::Cb) => b.cb = true,
            Some(ConvectiveKind::Tcu) => b.tcu = true,
            None => {}
        }
        let (Some(cover), Some(base)) = (g.cover, g.base_ft) else {
            continue;
        };
        let base = f64::from(base);
        if g.kind.is_some() {
            convective_base_ft[i] = Some(convective_base_ft[i].map_or(base, |c| c.min(base)));
        }
        let first = b.coverage_oktas == 0.0;
        b.coverage_oktas = b.coverage_oktas.max(settings.oktas.get(cover));
        b.base_ft = if first { base } else { b.base_ft.min(base) };
        top_ft[i] = top_ft[i].max(base + settings.thickness_ft.get(cover));
        b.thickness_ft = top_ft[i] - b.base_ft;
    }
    for (b, (base, top)) in bands.iter_mut().zip(convective_base_ft.iter().zip(top_ft)) {
        if let Some(base) = *base {
            b.base_ft = base;
            b.thickness_ft = top - base;
        }
    }
    // A reported CB/TCU without cover or base (`//////CB`) still gets a layer to be drawn in.
    for b in &mut bands[1..] {
        if (b.cb || b.tcu) && b.coverage_oktas == 0.0 {
            b.coverage_oktas = settings.oktas.few;
            b.base_ft = settings.convective.unknown_base_ft;
            b.thickness_ft = settings.thickness_ft.few;
        }
    }
    Some(bands)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::files::Position;
    use crate::weather::metar::{CloudGroup, PresentWeather, WindGroup};

    fn placed(report: Report) -> PlacedReport {
        PlacedReport {
            report,
            position: Position {
                latitude_deg: 0.0,
                longitude_deg: 0.0,
                elevation_m: Some(100.0),
            },
            line: 1,
        }
    }

    fn group(
        cover: Option<Cover>,
        base_ft: Option<u32>,
        kind: Option<ConvectiveKind>,
    ) -> CloudGroup {
        CloudGroup {
            cover,
            base_ft,
            kind,
        }
    }

    #[test]
    fn layers_merge_per_band() {
        let s = FieldSettings::default();
        // SCT028 BKN033 OVC050 FEW250 (KIKT, with a cirrus added).
        let r = Report {
            clouds: vec![
                group(Some(Cover::Sct), Some(2800), None),
                group(Some(Cover::Bkn), Some(3300), Some(ConvectiveKind::Tcu)),
                group(Some(Cover::Ovc), Some(5000), None),
                group(Some(Cover::Few), Some(25000), None),
            ],
            ..Report::default()
        };
        let bands = StationSample::of(&placed(r), &s).unwrap().bands.unwrap();
        let low = bands[1];
        assert_eq!(low.coverage_oktas, 8.0);
        // The TCU group's base, not the SCT028 below it.
        assert_eq!(low.base_ft, 3300.0);
        assert_eq!(low.thickness_ft, 5000.0 + 1500.0 - 3300.0);
        assert!(low.tcu && !low.cb);
        assert_eq!(bands[2].coverage_oktas, 0.0);
        assert_eq!(bands[3].coverage_oktas, 2.0);
        assert_eq!(bands[3].base_ft, 25000.0);
        assert_eq!(bands[0].coverage_oktas, 0.0);
    }

    #[test]
    fn a_convective_group_sets_its_band_base() {
        let s = FieldSettings::default();
        // EICK: FEW006 SCT018CB BKN035.
        let r = Report {
            clouds: vec![
                group(Some(Cover::Few), Some(600), None),
                group(Some(Cover::Sct), Some(1800), Some(ConvectiveKind::Cb)),
                group(Some(Cover::Bkn), Some(3500), None),
            ],
            ..Report::default()
        };
        let low = StationSample::of(&placed(r), &s).unwrap().bands.unwrap()[1];
        assert!(low.cb);
        assert_eq!(low.coverage_oktas, 6.0);
        assert_eq!(low.base_ft, 1800.0);
        assert_eq!(low.thickness_ft, 3500.0 + 1500.0 - 1800.0);
    }

    #[test]
    fn clear_codes_are_zero_and_no_sky_group_is_no_sample() {
        let s = FieldSettings::default();
        let cavok = Report {
            cavok: true,
            ..Report::default()
        };
        let sample = StationSample::of(&placed(cavok), &s).unwrap();
        assert_eq!(sample.bands, Some([BandSample::default(); 4]));
        assert_eq!(sample.visibility_m, Some(10000.0));
        let nothing = Report {
            visibility_m: Some(5000.0),
            ..Report::default()
        };
        let sample = StationSample::of(&placed(nothing), &s).unwrap();
        assert_eq!(sample.bands, None);
        assert_eq!(sample.visibility_m, Some(5000.0));
        let nil = Report {
            sky: Some(SkyCode::Nil),
            ..Report::default()
        };
        assert_eq!(StationSample::of(&placed(nil), &s), None);
    }

    #[test]
    fn vv_and_fg_are_fog_and_cb_without_base_is_kept() {
        let s = FieldSettings::default();
        let r = Report {
            clouds: vec![
                group(Some(Cover::Vv), Some(200), None),
                group(None, None, Some(ConvectiveKind::Cb)),
            ],
            weather: vec![PresentWeather {
                intensity: Intensity::Heavy,
                descriptor: Some("TS".to_string()),
                phenomena: vec!["RA".to_string()],
            }],
            wind: Some(WindGroup {
                dir_deg: Some(270),
                speed_kt: Some(10.0),
                ..WindGroup::default()
            }),
            ..Report::default()
        };
        let sample = StationSample::of(&placed(r), &s).unwrap();
        let bands = sample.bands.unwrap();
        assert_eq!(bands[0].coverage_oktas, 8.0);
        assert_eq!(bands[0].thickness_ft, 200.0);
        assert!(bands[1].cb);
        assert_eq!(bands[1].coverage_oktas, 2.0);
        assert_eq!(bands[1].base_ft, 3000.0);
        assert_eq!(sample.precipitation, 1.0);
        // From 270: the air moves east.
        let w = sample.wind_kt.unwrap();
        assert!((w[0] - 10.0).abs() < 1e-9 && w[1].abs() < 1e-9);
        let mist = Report {
            weather: vec![PresentWeather {
                intensity: Intensity::Vicinity,
                descriptor: None,
                phenomena: vec!["FG".to_string()],
            }],
            ..Report::default()
        };
        assert_eq!(StationSample::of(&placed(mist), &s).unwrap().bands, None);
    }
}

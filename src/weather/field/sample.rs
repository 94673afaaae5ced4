//! One station's values as the field interpolates them: every reported cloud layer (kind,
//! base, the cover seen from below at its base, a type a remark or a theme names), plus the
//! surface values. Built from a [`PlacedReport`] with the settings.
//!
//! Every group with a cover and a base is a layer of its own: nothing is merged. Its cover is the
//! report's (`[oktas]`: FEW 2, SCT 3.5, BKN 6, OVC 8 oktas), which by the summation principle counts all cloud
//! at and below its base; the field turns those covers into each layer's own coverage. A CB or
//! TCU group is a convective layer; `//////CB` (no cover, no base) one of FEW at the configured
//! base. VV is a fog layer on the ground, overcast, as deep as the vertical visibility. FG, BR,
//! HZ, FU and DU/SA in present weather are an [`Obscuration`] (with the visibility, the fog a
//! host draws), not a cloud layer. CAVOK/NSC/NCD/SKC/CLR stations have no layer but say the sky
//! is clear; a station with no sky group at all has no cloud sample (it is left out of the cloud
//! field).

use crate::weather::block::{Obscuration, TypeSource};
use crate::weather::cloud_type::CloudType;
use crate::weather::files::PlacedReport;
use crate::weather::metar::{ConvectiveKind, Cover, Intensity, Report, SkyCode};
use crate::weather::remarks::remark_types;
use crate::weather::theme::{Precipitation as ThemePrecipitation, ThemeWeather};

use super::settings::FieldSettings;

/// Precipitation phenomena of present weather.
const PRECIPITATION: [&str; 9] = ["DZ", "RA", "SN", "SG", "IC", "PL", "GR", "GS", "UP"];

/// What a layer is; layers of neighbouring stations blend only with layers of the same kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LayerKind {
    /// The sky obscured from the ground up (VV, or a theme's fog).
    Fog,
    /// A layer of cloud without CB/TCU.
    Plain,
    /// Cumulonimbus reported (`CB`).
    Cb,
    /// Towering cumulus reported (`TCU`).
    Tcu,
}

/// One reported layer of one station.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationLayer {
    /// What it is.
    pub kind: LayerKind,
    /// Base, feet AGL.
    pub base_ft: f64,
    /// The report's cover, oktas. For a fog or plain layer it is the cover seen from below at
    /// the base, which counts all fog and plain cloud at and below it (the summation principle).
    /// For a CB or TCU layer it is the cells' own amount: ICAO Annex 3 reports convective cloud
    /// outside that principle (`SCT008 BKN017 FEW025CB` is 1-2 oktas of Cb), so it is neither
    /// summed into the layers above nor counts the ones below.
    pub cover_below_oktas: f64,
    /// Base to top when the source says (a theme's layer, a VV depth), feet.
    pub thickness_ft: Option<f64>,
    /// The cloud type a remark or a theme names for the layer, and which of the two.
    pub named: Option<(CloudType, TypeSource)>,
}

/// One station's values.
#[derive(Debug, Clone, PartialEq)]
pub struct StationSample {
    /// The layers, lowest base first; `None` when the report says nothing about the sky, empty
    /// when it says the sky is clear.
    pub sky: Option<Vec<StationLayer>>,
    /// Visibility, metres.
    pub visibility_m: Option<f64>,
    /// What obscures the view (the heaviest of the present-weather groups).
    pub obscuration: Option<Obscuration>,
    /// Wind as the velocity the air moves with, knots east/north.
    pub wind_kt: Option<[f64; 2]>,
    /// Temperature, degrees C.
    pub temperature_c: Option<f64>,
    /// Dewpoint, degrees C.
    pub dewpoint_c: Option<f64>,
    /// Precipitation intensity 0..=1.
    pub precipitation: f64,
    /// Thunder: 0 none, 1 `-TS`, 2 `TS`, 3 `+TS` (not `VCTS`: not at the station).
    pub thunder: f64,
    /// Station elevation, metres.
    pub elevation_m: Option<f64>,
    /// Gusts above the mean wind, knots: 0 for a reported wind without gusts, `None` without
    /// a wind.
    pub gust_excess_kt: Option<f64>,
    /// Altimeter setting (QNH), hPa.
    pub qnh_hpa: Option<f64>,
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
            sky: sky_layers(r, settings),
            visibility_m,
            obscuration: obscuration(r),
            wind_kt,
            temperature_c: r.temperature_c.map(f64::from),
            dewpoint_c: r.dewpoint_c.map(f64::from),
            precipitation: precipitation(r, settings),
            thunder: thunder(r),
            elevation_m: placed.position.elevation_m,
            gust_excess_kt: r.wind.and_then(|w| {
                let speed = f64::from(w.speed_kt?);
                Some(w.gust_kt.map_or(0.0, |g| (f64::from(g) - speed).max(0.0)))
            }),
            qnh_hpa: r.altimeter_hpa.map(f64::from),
        })
    }

    /// The sample of one place of a weather theme: its layers keep the types, covers and
    /// thicknesses they name (a theme's cover is the layer's own; the cover seen from below at
    /// each base is what the layers at and below it make together).
    pub fn of_theme(weather: &ThemeWeather, settings: &FieldSettings) -> Self {
        let mut layers: Vec<_> = weather.layers.iter().collect();
        layers.sort_by(|a, b| a.base_ft_agl.total_cmp(&b.base_ft_agl));
        let mut clear = 1.0;
        let sky = layers
            .into_iter()
            .map(|l| {
                clear *= 1.0 - (f64::from(l.coverage_oktas) / 8.0).clamp(0.0, 1.0);
                StationLayer {
                    kind: if l.cloud_type == CloudType::Fog {
                        LayerKind::Fog
                    } else {
                        LayerKind::Plain
                    },
                    base_ft: f64::from(l.base_ft_agl),
                    cover_below_oktas: 8.0 * (1.0 - clear),
                    thickness_ft: Some(f64::from(l.thickness_ft)),
                    named: Some((l.cloud_type, TypeSource::Theme)),
                }
            })
            .collect();
        let p = &settings.precipitation;
        let wind = weather.wind;
        Self {
            sky: Some(sky),
            visibility_m: Some(f64::from(weather.visibility_m)),
            obscuration: None,
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
            thunder: match weather.thunder {
                ThemePrecipitation::None => 0.0,
                ThemePrecipitation::Light => 1.0,
                ThemePrecipitation::Moderate => 2.0,
                ThemePrecipitation::Heavy => 3.0,
            },
            elevation_m: Some(f64::from(weather.ground_elevation_m)),
            gust_excess_kt: Some(0.0),
            qnh_hpa: None,
        }
    }

    /// The cover of fog and plain cloud seen from below at `height_ft` by this station's report,
    /// oktas: the largest cover of those layers based at or under it (the summation principle; a
    /// report whose covers shrink upwards is read as the largest below). CB and TCU layers are
    /// left out: their amounts are their own (ICAO Annex 3).
    pub fn cover_below_oktas(&self, height_ft: f64) -> f64 {
        self.sky
            .iter()
            .flatten()
            .filter(|l| {
                l.base_ft <= height_ft && matches!(l.kind, LayerKind::Fog | LayerKind::Plain)
            })
            .map(|l| l.cover_below_oktas)
            .fold(0.0, f64::max)
    }
}

/// The velocity (knots east, north) of a wind blowing from `from_deg`.
fn wind_velocity_kt(from_deg: f64, speed_kt: f64) -> [f64; 2] {
    let to = (from_deg + 180.0).to_radians();
    [to.sin() * speed_kt, to.cos() * speed_kt]
}

/// The heaviest thunder of the report's present weather: 0 none, 1 `-TS`, 2 `TS`, 3 `+TS`
/// (`VCTS`, in the vicinity, is not over the station).
pub fn thunder(r: &Report) -> f64 {
    r.weather
        .iter()
        .filter(|w| w.descriptor.as_deref() == Some("TS"))
        .map(|w| match w.intensity {
            Intensity::Light => 1.0,
            Intensity::Moderate => 2.0,
            Intensity::Heavy => 3.0,
            Intensity::Vicinity => 0.0,
        })
        .fold(0.0, f64::max)
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

/// The obscuration of the report's present weather (not in the vicinity), the heaviest first.
pub fn obscuration(r: &Report) -> Option<Obscuration> {
    r.weather
        .iter()
        .filter(|w| w.intensity != Intensity::Vicinity)
        .flat_map(|w| w.phenomena.iter())
        .filter_map(|p| Obscuration::of_code(p))
        .max_by_key(|o| o.rank())
}

/// The report's layers, lowest base first; `None` when it has no sky statement at all.
fn sky_layers(r: &Report, settings: &FieldSettings) -> Option<Vec<StationLayer>> {
    if !r.cavok && r.sky.is_none() && r.clouds.is_empty() {
        return None;
    }
    let named = remark_types(&r.clouds, &r.remarks);
    let mut layers = Vec::with_capacity(r.clouds.len());
    for (g, named) in r.clouds.iter().zip(named) {
        let named = named.map(|t| (t, TypeSource::Remark));
        if g.cover == Some(Cover::Vv) {
            layers.push(StationLayer {
                kind: LayerKind::Fog,
                base_ft: 0.0,
                cover_below_oktas: settings.oktas.ovc,
                thickness_ft: Some(g.base_ft.map_or(settings.fog.thickness_ft, f64::from)),
                named,
            });
            continue;
        }
        let kind = match g.kind {
            Some(ConvectiveKind::Cb) => LayerKind::Cb,
            Some(ConvectiveKind::Tcu) => LayerKind::Tcu,
            None => LayerKind::Plain,
        };
        let (cover, base) = match (g.cover, g.base_ft) {
            (Some(cover), Some(base)) => (settings.oktas.get(cover), f64::from(base)),
            // A reported CB/TCU without cover or base (`//////CB`) is still drawn.
            (None, None) if kind != LayerKind::Plain => {
                (settings.oktas.few, settings.convective.unknown_base_ft)
            }
            (None, Some(base)) if kind != LayerKind::Plain => (settings.oktas.few, f64::from(base)),
            _ => continue,
        };
        layers.push(StationLayer {
            kind,
            base_ft: base,
            cover_below_oktas: cover,
            thickness_ft: None,
            named,
        });
    }
    layers.sort_by(|a, b| a.base_ft.total_cmp(&b.base_ft));
    spread_within_class(&mut layers, settings);
    Some(layers)
}

/// A run of plain layers reported with the same cover (`SCT033 SCT040 SCT047`, `BKN025
/// BKN031 BKN039`): a METAR's cover is the sky seen from below at each base, and the class's
/// drawn cover (`[oktas]`) leaves the upper ones nothing to add, yet the station's ceilometer
/// met each of their bases through the gaps of the ones below.
/// - FEW and SCT: going down the run, each lower layer is seen `[layers] min_seen_added_oktas`
///   less than the one above, never below halfway to the class under it (the layers' own rule
///   then lifts each upper one that much over the one below, up to the class's top).
/// - BKN, whose drawn 6 oktas leave room under the class's top of 7: the run's highest is seen
///   `min_seen_added_oktas` over BKN's drawn cover (as far as 7), each lower one that much less,
///   spread evenly where the lowest would fall more than that under BKN's drawn cover
///   (`BKN025 BKN031 BKN039`: 5.25, 6 and 6.75, where the own rule's 6, 6.75 and 7 left the
///   third a quarter of an okta; `BKN033 BKN041` stays 6 and 6.75).
fn spread_within_class(layers: &mut [StationLayer], settings: &FieldSettings) {
    let o = &settings.oktas;
    let step = settings.layers.min_seen_added_oktas;
    let reported: Vec<f64> = layers.iter().map(|l| l.cover_below_oktas).collect();
    let plain = |l: &StationLayer| l.kind == LayerKind::Plain;
    for i in (0..layers.len().saturating_sub(1)).rev() {
        let floor = if reported[i] == o.few {
            0.5 * o.few
        } else if reported[i] == o.sct {
            0.5 * (o.few + o.sct)
        } else {
            continue;
        };
        if !plain(&layers[i]) || !plain(&layers[i + 1]) || reported[i + 1] != reported[i] {
            continue;
        }
        let below_next = layers[i + 1].cover_below_oktas - step;
        layers[i].cover_below_oktas = below_next.max(floor).min(reported[i]);
    }
    spread_broken_runs(layers, settings);
}

/// The BKN part of [`spread_within_class`]: each run of two or more plain layers reported BKN
/// (the FEW and SCT part leaves their covers as reported).
fn spread_broken_runs(layers: &mut [StationLayer], settings: &FieldSettings) {
    let bkn = settings.oktas.bkn;
    let step = settings.layers.min_seen_added_oktas;
    let top = (bkn + step).min(BKN_TOP_OKTAS).max(bkn);
    let broken = |l: &StationLayer| l.kind == LayerKind::Plain && l.cover_below_oktas == bkn;
    for run in layers.chunk_by_mut(|a, b| broken(a) && broken(b)) {
        if run.len() < 2 {
            continue;
        }
        let steps = (run.len() - 1) as f64;
        let low = (top - steps * step).max(bkn - step);
        for (k, layer) in run.iter_mut().enumerate() {
            layer.cover_below_oktas = low + (top - low) * k as f64 / steps;
        }
    }
}

/// The most sky seen from below that METAR still calls broken, oktas.
const BKN_TOP_OKTAS: f64 = 7.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_of_one_class_steps_down_from_its_top() {
        let settings = FieldSettings::default();
        let layer = |kind, base_ft, cover_below_oktas| StationLayer {
            kind,
            base_ft,
            cover_below_oktas,
            thickness_ft: None,
            named: None,
        };
        let plain = LayerKind::Plain;
        // KA39's SCT033 SCT040 SCT047 (SCT drawn 3.5 oktas): 2.75, 2.75 and 3.5 oktas seen
        // from below, no lower than halfway to FEW's 2 (the layers' own rule then lifts the
        // middle one 0.75 okta over the lowest, and the top to SCT's 4).
        let sct = settings.oktas.sct;
        let mut three = [
            layer(plain, 3300.0, sct),
            layer(plain, 4000.0, sct),
            layer(plain, 4700.0, sct),
        ];
        spread_within_class(&mut three, &settings);
        let seen: Vec<f64> = three.iter().map(|l| l.cover_below_oktas).collect();
        assert_eq!(seen, [2.75, 2.75, 3.5]);
        // A CB stands apart; other classes stay.
        let mut mixed = [
            layer(plain, 1000.0, 2.0),
            layer(plain, 2000.0, sct),
            layer(LayerKind::Cb, 2500.0, sct),
            layer(plain, 3000.0, 6.0),
            layer(plain, 4000.0, 8.0),
        ];
        let before = mixed;
        spread_within_class(&mut mixed, &settings);
        assert_eq!(mixed, before);
        // BKN runs step down from 6.75 oktas: EGFF's BKN025 BKN031 BKN039, and a BKN033
        // BKN041 (as the own rule draws it) over a SCT020 and under an OVC070 (both as they
        // were).
        let bkn = settings.oktas.bkn;
        let mut egff = [
            layer(plain, 2500.0, bkn),
            layer(plain, 3100.0, bkn),
            layer(plain, 3900.0, bkn),
        ];
        spread_within_class(&mut egff, &settings);
        let seen: Vec<f64> = egff.iter().map(|l| l.cover_below_oktas).collect();
        assert_eq!(seen, [5.25, 6.0, 6.75]);
        let mut two = [
            layer(plain, 2000.0, sct),
            layer(plain, 3300.0, bkn),
            layer(plain, 4100.0, bkn),
            layer(plain, 7000.0, 8.0),
        ];
        spread_within_class(&mut two, &settings);
        let seen: Vec<f64> = two.iter().map(|l| l.cover_below_oktas).collect();
        assert_eq!(seen, [sct, 6.0, 6.75, 8.0]);
    }
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
    fn every_group_is_a_layer_of_its_own() {
        let s = FieldSettings::default();
        // SCT028 BKN033TCU OVC050 FEW250 (KIKT, with a TCU and a cirrus added).
        let r = Report {
            clouds: vec![
                group(Some(Cover::Sct), Some(2800), None),
                group(Some(Cover::Bkn), Some(3300), Some(ConvectiveKind::Tcu)),
                group(Some(Cover::Ovc), Some(5000), None),
                group(Some(Cover::Few), Some(25000), None),
            ],
            ..Report::default()
        };
        let sky = StationSample::of(&placed(r), &s).unwrap().sky.unwrap();
        let got: Vec<(LayerKind, f64, f64)> = sky
            .iter()
            .map(|l| (l.kind, l.base_ft, l.cover_below_oktas))
            .collect();
        assert_eq!(
            got,
            [
                (LayerKind::Plain, 2800.0, 3.5),
                (LayerKind::Tcu, 3300.0, 6.0),
                (LayerKind::Plain, 5000.0, 8.0),
                (LayerKind::Plain, 25000.0, 2.0),
            ]
        );
        let sample = StationSample {
            sky: Some(sky),
            ..StationSample::of(&placed(Report::default()), &s).unwrap()
        };
        // The FEW250 under an overcast: the sky seen from below stays overcast.
        assert_eq!(sample.cover_below_oktas(30000.0), 8.0);
        assert_eq!(sample.cover_below_oktas(3000.0), 3.5);
        // The BKN033TCU is the towers' own amount, not the sky's: still the SCT028 above it.
        assert_eq!(sample.cover_below_oktas(4000.0), 3.5);
        assert_eq!(sample.cover_below_oktas(2000.0), 0.0);
    }

    #[test]
    fn clear_codes_are_no_layer_and_no_sky_group_is_no_sample() {
        let s = FieldSettings::default();
        let cavok = Report {
            cavok: true,
            ..Report::default()
        };
        let sample = StationSample::of(&placed(cavok), &s).unwrap();
        assert_eq!(sample.sky, Some(vec![]));
        assert_eq!(sample.visibility_m, Some(10000.0));
        let nothing = Report {
            visibility_m: Some(5000.0),
            ..Report::default()
        };
        let sample = StationSample::of(&placed(nothing), &s).unwrap();
        assert_eq!(sample.sky, None);
        assert_eq!(sample.visibility_m, Some(5000.0));
        let nil = Report {
            sky: Some(SkyCode::Nil),
            ..Report::default()
        };
        assert_eq!(StationSample::of(&placed(nil), &s), None);
    }

    #[test]
    fn vv_is_fog_fg_is_an_obscuration_and_cb_without_base_is_kept() {
        let s = FieldSettings::default();
        let weather = |intensity, phenomena: &[&str]| PresentWeather {
            intensity,
            descriptor: None,
            phenomena: phenomena.iter().map(|p| p.to_string()).collect(),
        };
        let r = Report {
            clouds: vec![
                group(Some(Cover::Vv), Some(200), None),
                group(None, None, Some(ConvectiveKind::Cb)),
            ],
            weather: vec![
                PresentWeather {
                    descriptor: Some("TS".to_string()),
                    ..weather(Intensity::Heavy, &["RA"])
                },
                weather(Intensity::Moderate, &["BR"]),
            ],
            wind: Some(WindGroup {
                dir_deg: Some(270),
                speed_kt: Some(10.0),
                ..WindGroup::default()
            }),
            ..Report::default()
        };
        let sample = StationSample::of(&placed(r), &s).unwrap();
        let sky = sample.sky.unwrap();
        assert_eq!(sky[0].kind, LayerKind::Fog);
        assert_eq!((sky[0].base_ft, sky[0].cover_below_oktas), (0.0, 8.0));
        assert_eq!(sky[0].thickness_ft, Some(200.0));
        assert_eq!(sky[1].kind, LayerKind::Cb);
        assert_eq!((sky[1].base_ft, sky[1].cover_below_oktas), (3000.0, 2.0));
        assert_eq!(sample.precipitation, 1.0);
        assert_eq!(sample.obscuration, Some(Obscuration::Mist));
        // From 270: the air moves east.
        let w = sample.wind_kt.unwrap();
        assert!((w[0] - 10.0).abs() < 1e-9 && w[1].abs() < 1e-9);
        // Fog in the vicinity says nothing about the station; fog at it hides more than mist.
        let mist = Report {
            weather: vec![weather(Intensity::Vicinity, &["FG"])],
            ..Report::default()
        };
        let sample = StationSample::of(&placed(mist), &s).unwrap();
        assert_eq!((sample.sky, sample.obscuration), (None, None));
        let fog = Report {
            weather: vec![
                weather(Intensity::Moderate, &["BR"]),
                weather(Intensity::Moderate, &["FG"]),
            ],
            clouds: vec![group(Some(Cover::Bkn), Some(200), None)],
            ..Report::default()
        };
        let sample = StationSample::of(&placed(fog), &s).unwrap();
        assert_eq!(sample.obscuration, Some(Obscuration::Fog));
        // FG is not a cloud layer: the BKN002 is the only one.
        assert_eq!(sample.sky.unwrap().len(), 1);
    }
}

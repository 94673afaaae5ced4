//! The GFS model under the reports of the bulk file, from a station out over the ocean: west of
//! Horta in the Azores (LPHR, `FEW020`), the only land for 1,500 km. At the station its report;
//! 150 km and more from any station the model's layers alone; and no seam between: walked out
//! in 250 m steps, no layer's cover and not the sky covered seen from below changes by more than
//! a tenth of an okta a step (the reports' weight goes over smoothly, config/weather_model.toml
//! `[blend]`, and a model layer fades in from its least cover).

use std::path::Path;

use glam::DVec2;
use skycast::weather::block::{BlockLayer, cover_seen_from_below_oktas};
use skycast::weather::model::ModelSettings;
use skycast::weather::{
    CloudTypeRule, FieldSettings, LocalFrame, StationTable, TypeSource, WeatherField, files,
};

use super::field_bulk::gfs;

const BULK_FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/awc-metars-2025-01-27T22Z.cache.csv"
);
/// Horta, Faial (LPHR), as the bulk file places it.
const HORTA: (f64, f64) = (38.521, -28.714);

/// Great-circle distance, km.
fn distance_km(a: (f64, f64), b: (f64, f64)) -> f64 {
    let (la1, lo1, la2, lo2) = (
        a.0.to_radians(),
        a.1.to_radians(),
        b.0.to_radians(),
        b.1.to_radians(),
    );
    let h = ((la2 - la1) / 2.0).sin().powi(2)
        + la1.cos() * la2.cos() * ((lo2 - lo1) / 2.0).sin().powi(2);
    2.0 * 6_371.0 * h.sqrt().asin()
}

#[test]
fn from_a_station_out_to_the_model_without_a_seam() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("weather");
    let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
    let file = files::load(Path::new(BULK_FILE), Some(&stations)).unwrap();
    let frame = LocalFrame::new(HORTA.0, HORTA.1);
    let model = gfs();
    let settings = ModelSettings::default();
    let field = WeatherField::build(
        frame,
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    )
    .with_model(model.clone(), settings);
    let positions: Vec<(f64, f64)> = file
        .reports
        .iter()
        .map(|p| (p.position.latitude_deg, p.position.longitude_deg))
        .collect();
    let nearest_km = |p: (f64, f64)| {
        positions
            .iter()
            .map(|&q| distance_km(p, q))
            .fold(f64::INFINITY, f64::min)
    };

    // At the station: its report, FEW020, alone.
    let at = field.weather_at(DVec2::ZERO);
    assert_eq!(at.layers.len(), 1, "{:?}", at.layers);
    assert_eq!(at.layers[0].type_source, TypeSource::HeightRule);
    assert_eq!(
        (at.layers[0].coverage_oktas, at.layers[0].base_ft_agl),
        (2.0, 2000.0)
    );

    let (mut worst_step, mut worst_at_km) = (0.0f32, 0.0);
    let mut far_points = 0;
    let mut before = field.weather_at(DVec2::ZERO).layers;
    // West along the parallel, 250 m a step, out to 200 km.
    for k in 1..=800 {
        let p = DVec2::new(-250.0 * k as f64, 0.0);
        let now = field.weather_at(p).layers;
        let step = layer_step(&before, &now);
        if step > worst_step {
            (worst_step, worst_at_km) = (step, p.length() / 1000.0);
        }
        before = now;
        let (lat, lon) = frame.to_lat_lon_deg(p);
        if k % 40 == 0 && nearest_km((lat, lon)) >= 150.0 {
            // The model's layers alone.
            let got = field.weather_at(p).layers;
            let want = model.layers_at(lat, lon, &settings.layers);
            assert!(!want.is_empty(), "{lat},{lon}: the model has no cloud here");
            assert_eq!(got.len(), want.len(), "{lat},{lon}: {got:?}\n{want:?}");
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g.type_source, TypeSource::Model);
                assert!(
                    (g.coverage_oktas - w.coverage_oktas).abs() < 1e-3
                        && (g.base_ft_agl - w.base_ft_agl).abs() < 1.0,
                    "{lat},{lon}: {got:?}\n{want:?}"
                );
            }
            far_points += 1;
        }
    }
    eprintln!(
        "the largest change of a layer's cover or of the sky covered in a 250 m step: {worst_step:.3} \
         oktas, {worst_at_km:.2} km out; {far_points} points 150 km or more from a station \
         are the model's"
    );
    assert!(far_points >= 5, "{far_points}");
    assert!(worst_step <= 0.1, "{worst_step} oktas at {worst_at_km} km");
}

/// How much the sky changes between two neighbouring points' layers, oktas: the largest change
/// of a layer's own cover (a layer matched to the one of the same source and type with the
/// nearest base within 500 ft; one without a match counts its whole cover) and of the sky
/// covered seen from above all layers.
fn layer_step(before: &[BlockLayer], now: &[BlockLayer]) -> f32 {
    let matched = |a: &BlockLayer, others: &[BlockLayer]| -> f32 {
        others
            .iter()
            .filter(|b| {
                (b.type_source, b.cloud_type) == (a.type_source, a.cloud_type)
                    && (b.base_ft_agl - a.base_ft_agl).abs() <= 500.0
            })
            .map(|b| (b.coverage_oktas - a.coverage_oktas).abs())
            .fold(a.coverage_oktas, f32::min)
    };
    let layers = before
        .iter()
        .map(|a| matched(a, now))
        .chain(now.iter().map(|a| matched(a, before)))
        .fold(0.0, f32::max);
    let whole =
        (cover_seen_from_below_oktas(before, 1e6) - cover_seen_from_below_oktas(now, 1e6)).abs();
    layers.max(whole)
}

/// A host's `SkySystem::set_model`: the model goes under the weather in use at once and under
/// every report file set after, and comes away with `None`.
#[test]
fn a_host_puts_a_model_under_its_reports_and_takes_it_away() {
    use glam::DVec2 as V;
    use skycast::demo::terrain::HeightField;
    use skycast::demo::{DemoHost, headless};
    use skycast::flight::system::{SkySystemConfig, Weather};
    let ground = HeightField::from_fn(V::ZERO, 80_000.0, 16, |_| 0.0);
    let mut host = DemoHost::new(
        64,
        36,
        &ground,
        SkySystemConfig::new(headless::TARGETS, HORTA),
    )
    .expect("demo host");
    let horta = Weather::Bytes {
        name: Path::new("horta.txt"),
        bytes: b"LPHR 272200Z 27013KT 9999 FEW020 15/08 Q1028\n",
    };
    // 300 km west of Horta, over the ocean.
    let west = DVec2::new(-300_000.0, 0.0);
    let sources = |host: &DemoHost| -> Vec<TypeSource> {
        let field = host.sky.world().field();
        field
            .weather_at(west)
            .layers
            .iter()
            .map(|l| l.type_source)
            .collect()
    };
    host.sky.set_weather(horta).unwrap();
    assert_eq!(sources(&host), [TypeSource::HeightRule]);
    host.sky.set_model(Some(gfs()));
    let modelled = sources(&host);
    assert!(
        !modelled.is_empty() && modelled.iter().all(|&s| s == TypeSource::Model),
        "{modelled:?}"
    );
    // At the station the report.
    let at = host.sky.world().field().weather_at(DVec2::ZERO).layers;
    assert_eq!(at.len(), 1, "{at:?}");
    // A report file set later goes over the model too.
    host.sky.set_weather(horta).unwrap();
    assert_eq!(sources(&host), modelled);
    host.sky.set_model(None);
    assert_eq!(sources(&host), [TypeSource::HeightRule]);
}

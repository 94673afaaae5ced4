//! The model reader on the shipped GFS file.

use std::path::Path;
use std::sync::OnceLock;

use super::*;

/// The shipped GFS file, decoded once for all tests.
pub(crate) fn shipped() -> &'static ModelField {
    static MODEL: OnceLock<ModelField> = OnceLock::new();
    MODEL.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2");
        ModelField::load(&path).unwrap()
    })
}

#[test]
fn the_shipped_file_decodes_as_eccodes_decodes_it() {
    let model = shipped();
    let csv = include_str!("../../../tests/weather/model/gfs_eccodes.csv");
    let (mut checked, mut fields) = (0, std::collections::HashSet::new());
    for line in csv.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let n = |k: usize| c[k].parse::<f64>().unwrap();
        let key = FieldKey::new(n(1) as u8, n(2) as u8, n(3) as u8, n(4) as u8, n(5));
        let index = n(6) as usize;
        let values = model
            .grids()
            .fields
            .get(&key)
            .unwrap_or_else(|| panic!("{} ({key}) not decoded", c[0]));
        let got = f64::from(values[index]);
        // The grid point's position too.
        let g = &model.grids().grid;
        let (lat, lon) = g.lat_lon_deg(index % g.ni, index / g.ni);
        assert!(
            (lat - n(7)).abs() < 1e-6 && (lon - n(8)).abs() < 1e-6,
            "{line}"
        );
        if c[9] == "missing" {
            assert!(got.is_nan(), "{line}: {got}");
        } else {
            let want = n(9);
            assert!(
                (got - want).abs() <= 1e-6 * want.abs().max(1.0) + 1e-3,
                "{line}: decoded {got}"
            );
        }
        fields.insert(c[0].to_string() + c[4] + c[5]);
        checked += 1;
    }
    assert_eq!((checked, fields.len()), (288, 12));
}

#[test]
fn the_shipped_file_holds_26_levels_valid_on_the_15th_at_12z() {
    let model = shipped();
    assert_eq!(model.levels_pa().len(), 26, "{:?}", model.levels_pa());
    assert_eq!(model.levels_pa()[0], 100_000);
    assert_eq!(model.valid_time(), (2011, 1, 15, 12));
    assert_eq!(model.grids().grid.ni * model.grids().grid.nj, 144 * 73);
    assert!(model.grids().grid.wraps());
    assert_eq!(model.grids().field_count, 343);
    // About 150 fields of 10,512 points as f32: 6.4 MB.
    let mb = model.memory_bytes() as f64 / 1e6;
    assert!((5.0..8.0).contains(&mb), "{mb} MB");
}

/// A small deterministic generator (64-bit LCG, Knuth's MMIX constants).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

/// The height, metres, of `pressure_pa` at grid point `k` through the model's own geopotential
/// heights there: linear in ln(p) between the two isobaric levels around it (an independent
/// reading of the raw grids, not the reader's column).
fn raw_height_m(model: &ModelField, k: usize, pressure_pa: f64) -> f64 {
    let raw = |q: [u8; 3], p: i64| f64::from(model.grids().fields[&FieldKey::isobaric(q, p)][k]);
    let levels: Vec<(f64, f64)> = model
        .levels_pa()
        .iter()
        .map(|&p| (p as f64, raw(fields::HEIGHT, p)))
        .collect();
    let below = levels
        .windows(2)
        .find(|w| pressure_pa <= w[0].0 && pressure_pa >= w[1].0);
    let [(p0, z0), (p1, z1)] = match below {
        Some(w) => [w[0], w[1]],
        // Below 1000 hPa: the lowest two levels' slope.
        None => [levels[0], levels[1]],
    };
    z0 + (p0.ln() - pressure_pa.ln()) / (p0.ln() - p1.ln()) * (z1 - z0)
}

#[test]
fn the_model_alone_gives_its_layers_and_250_hpa_winds_at_200_random_points() {
    use crate::weather::air::{AirSettings, SurfaceAir, air_at_aloft};
    use crate::weather::field::{CloudTypeRule, FieldSettings};
    use crate::weather::{LocalFrame, METRES_PER_FOOT, WeatherField};
    let model = shipped();
    let shared = std::sync::Arc::new(model.clone());
    let g = model.grids().grid;
    let raw = |key: &FieldKey, k: usize| f64::from(model.grids().fields[key][k]);
    let mut rng = Lcg(55);
    let (mut layers_checked, mut winds_checked) = (0, 0);
    let (mut worst_cover, mut worst_base, mut worst_speed, mut worst_dir) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..200 {
        // A grid point off the poles.
        let k = g.ni + rng.below(g.ni * (g.nj - 2));
        let (lat, lon) = g.lat_lon_deg(k % g.ni, k / g.ni);
        let lon = if lon > 180.0 { lon - 360.0 } else { lon };
        let field = WeatherField::build(
            LocalFrame::new(lat, lon),
            &[],
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        )
        .with_model(shared.clone(), ModelSettings::default());
        let w = field.weather_at(glam::DVec2::ZERO);
        let ground_m = raw(&fields::OROGRAPHY, k);
        for layer in [fields::LOW, fields::MIDDLE, fields::HIGH] {
            let oktas = raw(&layer.cover, k) * 0.08;
            if oktas < 2.0 {
                continue;
            }
            let bottom_m = raw_height_m(model, k, raw(&layer.bottom, k));
            let want_ft = ((bottom_m - ground_m) / METRES_PER_FOOT).max(0.0);
            let best = w
                .layers
                .iter()
                .map(|l| {
                    let cover = (f64::from(l.coverage_oktas) - oktas).abs();
                    let base = (f64::from(l.base_ft_agl) - want_ft).abs() / want_ft.max(1.0);
                    (cover, base)
                })
                .min_by(|a, b| (a.0 / 1.5 + a.1 / 0.2).total_cmp(&(b.0 / 1.5 + b.1 / 0.2)));
            let Some((cover, base)) = best else {
                panic!(
                    "{lat},{lon}: no layer for the {} layer: {:?}",
                    layer.name, w.layers
                );
            };
            assert!(
                cover <= 1.5 && base <= 0.2,
                "{lat},{lon}: the {} layer {oktas:.1} oktas at {want_ft:.0} ft: {:?}",
                layer.name,
                w.layers
            );
            worst_cover = worst_cover.max(cover);
            worst_base = worst_base.max(base);
            layers_checked += 1;
        }
        // The air data at the 250 hPa level's height.
        let alt_m = raw(&FieldKey::isobaric(fields::HEIGHT, 25_000), k);
        let u = raw(&FieldKey::isobaric(fields::WIND_U, 25_000), k);
        let v = raw(&FieldKey::isobaric(fields::WIND_V, 25_000), k);
        let want_kt = u.hypot(v) / crate::weather::METRES_PER_KNOT;
        let want_from = (u.atan2(v).to_degrees() + 180.0).rem_euclid(360.0);
        let surface = SurfaceAir::of(&w, 0.0, 1013.25);
        let column = field
            .model()
            .map(|(m, _)| m.aloft_column_at(lat, lon))
            .unwrap();
        let air = air_at_aloft(&surface, alt_m, lat, &AirSettings::default(), Some(&column));
        let speed = (air.wind.speed_kt - want_kt).abs();
        let dir = ((air.wind.from_deg - want_from + 540.0).rem_euclid(360.0) - 180.0).abs();
        assert!(
            speed <= 3.0,
            "{lat},{lon}: {} kt, the model {want_kt} kt",
            air.wind.speed_kt
        );
        worst_speed = worst_speed.max(speed);
        // A direction means something in a wind of some knots.
        if want_kt >= 5.0 {
            assert!(
                dir <= 5.0,
                "{lat},{lon}: from {}, the model {want_from}",
                air.wind.from_deg
            );
            worst_dir = worst_dir.max(dir);
        }
        winds_checked += 1;
    }
    eprintln!(
        "{layers_checked} layers, {winds_checked} winds: worst cover {worst_cover:.2} oktas, base \
         {:.1} %, speed {worst_speed:.2} kt, direction {worst_dir:.2} deg",
        100.0 * worst_base
    );
    assert!(layers_checked >= 150, "{layers_checked}");
}

/// The shipped file's bytes: its first `messages` whole messages, then `extra` bytes of the next.
fn cut(messages: usize, extra: usize) -> Vec<u8> {
    let bytes = std::fs::read(&shipped().path).unwrap();
    let mut end = 0;
    for _ in 0..messages {
        // Section 0: "GRIB", 2 reserved, discipline, edition, then the total length (8 bytes).
        let length = u64::from_be_bytes(bytes[end + 8..end + 16].try_into().unwrap());
        end += length as usize;
    }
    bytes[..end + extra].to_vec()
}

#[test]
fn a_broken_model_file_is_one_error_naming_file_message_and_field() {
    let path = Path::new("gfs.grib2");
    let err = ModelField::parse(path, &cut(200, 1_000))
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("gfs.grib2: not a whole GRIB2 file"),
        "{err}"
    );
    let err = ModelField::parse(path, &cut(200, 0))
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        "gfs.grib2: no low cloud layer cover (parameter 0.6.1 on surface type 214) in the model file"
    );
    let mut edition1 = cut(1, 0);
    edition1[7] = 1;
    let err = ModelField::parse(path, &edition1).unwrap_err().to_string();
    assert_eq!(
        err,
        "gfs.grib2: GRIB edition 1; the model reader reads GRIB edition 2"
    );
    // A message whose grid is not a latitude/longitude one: the grid definition template
    // number (section 3, octets 13-14) changed in the first message.
    let mut bytes = cut(307, 0);
    let section3 = 16 + u32::from_be_bytes(bytes[16..20].try_into().unwrap()) as usize;
    bytes[section3 + 12..section3 + 14].copy_from_slice(&40u16.to_be_bytes());
    let err = ModelField::parse(path, &bytes).unwrap_err().to_string();
    assert_eq!(
        err,
        "gfs.grib2: message 1, field 1: grid definition template 3.40; the model reader reads \
         the regular latitude/longitude grid (3.0) only"
    );
}

#[test]
fn a_watched_model_file_hands_over_good_versions_and_rejects_broken_ones() {
    use crate::weather::watch::{WatchUpdate, WeatherWatch};
    use std::time::Duration;
    let dir = std::env::temp_dir().join(format!("skycast-model-watch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("gfs.grib2");
    let whole = cut(307, 0);
    std::fs::write(&path, &whole).unwrap();
    let watch = WeatherWatch::start(&path, None, Duration::from_millis(300), |input| {
        input.model().map(|m| m.levels_pa().len())
    })
    .unwrap();
    let next = || {
        watch
            .wait(Duration::from_secs(20))
            .expect("an update within 20 s")
    };
    // Cut short, then a file without the cloud layers: rejected, each with one message; the
    // caller keeps its last good sky.
    std::fs::write(&path, cut(250, 5_000)).unwrap();
    assert!(
        matches!(next(), WatchUpdate::Rejected(m) if m.contains("gfs.grib2: not a whole GRIB2 file")),
    );
    std::fs::write(&path, cut(200, 0)).unwrap();
    assert!(
        matches!(next(), WatchUpdate::Rejected(m) if m.contains("gfs.grib2: no low cloud layer cover")),
    );
    // The whole file again, renamed over it as download tools do: handed over.
    let staging = dir.join("download.tmp");
    std::fs::write(&staging, &whole).unwrap();
    std::fs::rename(&staging, &path).unwrap();
    match next() {
        WatchUpdate::Loaded(levels) => assert_eq!(levels, Some(26)),
        WatchUpdate::Rejected(m) => panic!("{m}"),
    }
}

#[test]
fn an_old_report_gives_way_to_the_model_and_a_fresh_one_rules() {
    use crate::weather::field::{CloudTypeRule, FieldSettings};
    use crate::weather::{LocalFrame, StationTable, TypeSource, WeatherInput};
    // Horta fresh, Lajes five hours older than it.
    let text = "LPHR 272200Z 27013KT 9999 FEW020 15/08 Q1028\n\
                LPLA 271700Z 27010KT 9999 FEW025 13/09 Q1028\n";
    let input = WeatherInput::parse(
        Path::new("azores.txt"),
        text.as_bytes(),
        Some(&StationTable::builtin()),
    )
    .unwrap();
    let reports = input.reports().unwrap();
    let field = crate::weather::WeatherField::build(
        LocalFrame::new(38.6, -28.0),
        &reports.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    )
    .with_model(
        std::sync::Arc::new(shipped().clone()),
        ModelSettings::default(),
    );
    let sources = |p: &crate::weather::PlacedReport| -> Vec<TypeSource> {
        field
            .weather_at_lat_lon(p.position.latitude_deg, p.position.longitude_deg)
            .layers
            .iter()
            .map(|l| l.type_source)
            .collect()
    };
    let (horta, lajes) = (&reports.reports[0], &reports.reports[1]);
    assert_eq!(sources(horta), [TypeSource::HeightRule]);
    let old = sources(lajes);
    assert!(
        !old.is_empty() && old.iter().all(|&s| s == TypeSource::Model),
        "{old:?}"
    );
}

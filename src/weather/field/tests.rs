//! Interpolation properties of the field, on hand-built reports.

use super::*;
use crate::weather::block::TypeSource;
use crate::weather::cloud_type::CloudType;
use crate::weather::files::Position;
use crate::weather::metar::{CloudGroup, ConvectiveKind, Cover, Report, ReportTime, WindGroup};

const LAT0: f64 = 50.0;
const LON0: f64 = 8.0;

fn station(lat: f64, lon: f64, line: usize, report: Report) -> PlacedReport {
    PlacedReport {
        report,
        position: Position {
            latitude_deg: lat,
            longitude_deg: lon,
            elevation_m: Some(100.0 * line as f64),
        },
        line,
    }
}

fn layer(cover: Cover, base_ft: u32, kind: Option<ConvectiveKind>) -> CloudGroup {
    CloudGroup {
        cover: Some(cover),
        base_ft: Some(base_ft),
        kind,
    }
}

fn report(clouds: Vec<CloudGroup>, temperature_c: f32, wind_from: u16) -> Report {
    Report {
        station: "TEST".to_string(),
        clouds,
        temperature_c: Some(temperature_c),
        dewpoint_c: Some(temperature_c - 2.0),
        wind: Some(WindGroup {
            dir_deg: Some(wind_from),
            speed_kt: Some(10.0),
            ..WindGroup::default()
        }),
        visibility_m: Some(8000.0),
        ..Report::default()
    }
}

fn cavok(temperature_c: f32) -> Report {
    Report {
        cavok: true,
        ..report(vec![], temperature_c, 270)
    }
}

/// Four stations on a square about 1 degree across, and one in the middle.
fn square() -> Vec<PlacedReport> {
    vec![
        station(
            49.5,
            7.3,
            1,
            report(vec![layer(Cover::Ovc, 1000, None)], 4.0, 270),
        ),
        station(49.5, 8.7, 2, cavok(8.0)),
        station(
            50.5,
            8.7,
            3,
            report(vec![layer(Cover::Bkn, 3000, None)], 6.0, 90),
        ),
        station(
            50.5,
            7.3,
            4,
            report(vec![layer(Cover::Few, 25000, None)], 2.0, 270),
        ),
        station(
            50.0,
            8.0,
            5,
            report(
                vec![layer(Cover::Sct, 2500, Some(ConvectiveKind::Cb))],
                5.0,
                270,
            ),
        ),
    ]
}

fn field(reports: &[PlacedReport]) -> WeatherField {
    WeatherField::build(
        LocalFrame::new(LAT0, LON0),
        reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    )
}

#[test]
fn exact_at_the_stations() {
    let f = field(&square());
    let w = f.weather_at_lat_lon(49.5, 7.3);
    assert_eq!(w.temperature_c, 4.0);
    assert_eq!(w.ground_elevation_m, 100.0);
    assert_eq!(w.layers.len(), 1);
    assert_eq!(w.layers[0].coverage_oktas, 8.0);
    assert_eq!(w.layers[0].base_ft_agl, 1000.0);
    assert_eq!(w.layers[0].cloud_type, CloudType::Stratus);
    assert_eq!(w.layers[0].type_source, TypeSource::HeightRule);
    // The CAVOK station is clear.
    let w = f.weather_at_lat_lon(49.5, 8.7);
    assert!(w.layers.is_empty(), "{:?}", w.layers);
    assert_eq!(w.visibility_m, 10000.0);
    // The CB station keeps its CB, reported.
    let w = f.weather_at_lat_lon(50.0, 8.0);
    assert_eq!(w.layers[0].cloud_type, CloudType::Cumulonimbus);
    assert_eq!(w.layers[0].type_source, TypeSource::Reported);
    assert_eq!(w.layers[0].coverage_oktas, 3.5);
    let w = f.weather_at_lat_lon(50.5, 7.3);
    assert_eq!(w.layers[0].cloud_type, CloudType::Cirrus);
}

#[test]
fn outside_the_hull_takes_the_nearest_station() {
    let f = field(&square());
    let far_south_west = f.weather_at_lat_lon(47.0, 5.0);
    let station = f.weather_at_lat_lon(49.5, 7.3);
    assert_eq!(far_south_west, station);
    let far_north_east = f.weather_at_lat_lon(53.0, 11.0);
    assert_eq!(far_north_east, f.weather_at_lat_lon(50.5, 8.7));
}

#[test]
fn between_stations_values_blend_and_clear_stations_pull_coverage_down() {
    let f = field(&square());
    // Halfway between the OVC010 station and the CAVOK one, just inside the hull (the parallel
    // 49.5 N bows south of the straight hull edge in the frame).
    let w = f.weather_at_lat_lon(49.6, 8.0);
    assert!(
        w.temperature_c > 4.0 && w.temperature_c < 8.0,
        "{}",
        w.temperature_c
    );
    let low = w.layers.iter().find(|l| l.base_ft_agl < 6500.0).unwrap();
    assert!(
        low.coverage_oktas > 0.5 && low.coverage_oktas < 8.0,
        "{}",
        low.coverage_oktas
    );
    // The clear station does not drag the base down to 0: it stays between the reported bases.
    assert!(
        low.base_ft_agl >= 1000.0 && low.base_ft_agl <= 3000.0,
        "{}",
        low.base_ft_agl
    );
    assert!(w.ground_elevation_m > 100.0 && w.ground_elevation_m < 500.0);
}

#[test]
fn cb_survives_near_its_station_only() {
    let f = field(&square());
    let near = f.weather_at_lat_lon(50.05, 8.05);
    assert!(
        near.layers
            .iter()
            .any(|l| l.cloud_type == CloudType::Cumulonimbus
                && l.type_source == TypeSource::Reported),
        "{:?}",
        near.layers
    );
    let far = f.weather_at_lat_lon(49.55, 7.35);
    assert!(
        far.layers
            .iter()
            .all(|l| l.cloud_type != CloudType::Cumulonimbus)
    );
}

#[test]
fn opposite_winds_cancel() {
    // Station 3 blows from 090, the others from 270: between 3 and its westerly neighbours the
    // vector mean is weaker than either, never a 180-degree average pointing north or south.
    let f = field(&square());
    let w = f.weather_at_lat_lon(50.25, 8.35).wind;
    assert!(w.speed_kt < 10.0, "{w:?}");
    let at3 = f.weather_at_lat_lon(50.5, 8.7).wind;
    assert!((at3.from_deg - 90.0).abs() < 1e-3 && (at3.speed_kt - 10.0).abs() < 1e-3);
}

#[test]
fn stations_without_sky_are_left_out_of_the_clouds_only() {
    let mut reports = square();
    // A sixth station, no sky group, very warm, right next to the OVC one.
    let mut no_sky = report(vec![], 30.0, 270);
    no_sky.station = "NOSK".to_string();
    reports.push(station(49.6, 7.4, 6, no_sky));
    let f = field(&reports);
    assert_eq!(f.station_count(), 6);
    assert_eq!(f.cloud_station_count(), 5);
    let w = f.weather_at_lat_lon(49.6, 7.4);
    assert_eq!(w.temperature_c, 30.0);
    // The clouds there are still interpolated from the five sky stations, not cleared.
    assert!(!w.layers.is_empty());
}

#[test]
fn identical_positions_keep_the_latest_report() {
    let mut reports = square();
    let mut later = report(vec![layer(Cover::Bkn, 800, None)], 12.0, 270);
    later.time = Some(ReportTime {
        day: 27,
        hour: 22,
        minute: 50,
    });
    let mut earlier = reports[0].report.clone();
    earlier.time = Some(ReportTime {
        day: 27,
        hour: 22,
        minute: 20,
    });
    reports[0].report = earlier;
    // The later report comes first in the file: time decides, not order.
    reports.insert(0, station(49.5, 7.3, 9, later));
    let f = field(&reports);
    assert_eq!(f.station_count(), 5);
    let w = f.weather_at_lat_lon(49.5, 7.3);
    assert_eq!(w.temperature_c, 12.0);
    assert_eq!(w.layers[0].base_ft_agl, 800.0);
    assert_eq!(w.layers[0].cloud_type, CloudType::Stratocumulus);
}

/// A block without a station is the field at its centre, `(i + 1/2, j + 1/2)` blocks from the
/// origin (worked out here, not with `centre_m`), where the weather is not its corner's nor the
/// origin's: sampling either instead fails.
#[test]
fn a_block_without_a_station_is_the_field_at_its_centre() {
    let f = field(&square());
    let block = f.frame().block_of(49.6, 8.0);
    let centre = DVec2::new(block.i as f64 + 0.5, block.j as f64 + 0.5) * 4000.0;
    let w = f.block_weather(block);
    let cover = w
        .cover
        .clone()
        .expect("a block's weather has its cover at the rim");
    assert_eq!(cover.sample_m, [2000.0, 2000.0]);
    let w = BlockWeather { cover: None, ..w };
    assert_eq!(w, f.weather_at(centre));
    assert_ne!(w, f.weather_at(centre + DVec2::splat(1900.0)));
    assert_ne!(w, f.weather_at(DVec2::ZERO));
}

#[test]
fn one_station_and_none() {
    let one = field(&square()[..1]);
    assert_eq!(one.weather_at_lat_lon(0.0, 0.0).temperature_c, 4.0);
    let none = field(&[]);
    let w = none.weather_at_lat_lon(50.0, 8.0);
    assert!(w.layers.is_empty());
    assert_eq!(w.temperature_c, 15.0);
    assert_eq!(w.visibility_m, 10000.0);
}

#[test]
fn the_field_can_be_shared_between_threads() {
    fn sync<T: Send + Sync>() {}
    sync::<WeatherField>();
}

#[test]
fn on_the_real_bulk_file_every_cb_station_keeps_its_cb() {
    use crate::weather::stations::StationTable;
    use std::path::Path;
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/weather"));
    let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
    let file = crate::weather::files::load(
        &dir.join("awc-metars-2025-01-27T22Z.cache.csv"),
        Some(&stations),
    )
    .unwrap();
    let f = WeatherField::build(
        LocalFrame::new(51.848, -8.479),
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    // 4,877 placed reports; some share coordinates and some are NIL: 4,856 stations, 4,496 of
    // them with something to say about the sky (fog without a sky group is an obscuration, not
    // a sky statement).
    assert_eq!(f.station_count(), 4_856);
    assert_eq!(f.cloud_station_count(), 4_496);
    let mut checked = 0;
    for p in &file.reports {
        let has_cb = p
            .report
            .clouds
            .iter()
            .any(|g| g.kind == Some(ConvectiveKind::Cb));
        let shares_position = file
            .reports
            .iter()
            .filter(|q| q.position.latitude_deg == p.position.latitude_deg)
            .filter(|q| q.position.longitude_deg == p.position.longitude_deg)
            .count()
            > 1;
        if !has_cb || shares_position {
            continue;
        }
        let w = f.weather_at_lat_lon(p.position.latitude_deg, p.position.longitude_deg);
        assert!(
            w.layers
                .iter()
                .any(|l| l.cloud_type == CloudType::Cumulonimbus
                    && l.type_source == TypeSource::Reported),
            "{} line {}: {:?}",
            p.report.station,
            p.line,
            w.layers
        );
        checked += 1;
    }
    assert!(checked >= 50, "{checked}");
}

#[test]
fn collinear_stations_fall_back_to_the_nearest() {
    // Three stations on the frame's meridian project onto one straight line: no triangle.
    let reports = vec![
        station(
            49.0,
            LON0,
            1,
            report(vec![layer(Cover::Ovc, 800, None)], 1.0, 270),
        ),
        station(
            50.0,
            LON0,
            2,
            report(vec![layer(Cover::Sct, 3000, None)], 2.0, 270),
        ),
        station(51.0, LON0, 3, cavok(3.0)),
    ];
    let f = field(&reports);
    assert_eq!(f.station_count(), 3);
    let w = f.weather_at_lat_lon(49.2, LON0 + 0.3);
    assert_eq!(w.temperature_c, 1.0);
    assert_eq!(w.layers[0].cloud_type, CloudType::Stratus);
    assert!(f.weather_at_lat_lon(50.9, LON0).layers.is_empty());
}

/// Two stations 1 degree of longitude apart on the 50th parallel.
fn pair(west: Vec<CloudGroup>, east: Vec<CloudGroup>) -> WeatherField {
    field(&[
        station(LAT0, 7.5, 1, report(west, 10.0, 270)),
        station(LAT0, 8.5, 2, report(east, 10.0, 270)),
        // Far corners, clear, so the two are inside the hull.
        station(48.0, 6.0, 3, cavok(10.0)),
        station(52.0, 10.0, 4, cavok(10.0)),
        station(48.0, 10.0, 5, cavok(10.0)),
        station(52.0, 6.0, 6, cavok(10.0)),
    ])
}

#[test]
fn layers_at_similar_heights_blend_and_a_layer_one_station_has_fades() {
    let f = pair(
        vec![layer(Cover::Sct, 2400, None), layer(Cover::Bkn, 9000, None)],
        vec![layer(Cover::Sct, 2800, None)],
    );
    let at = |lon: f64| f.weather_at_lat_lon(LAT0, lon).layers;
    // At each station its own report.
    let west = at(7.5);
    assert_eq!(west.len(), 2, "{west:?}");
    assert_eq!((west[0].base_ft_agl, west[1].base_ft_agl), (2400.0, 9000.0));
    let east = at(8.5);
    assert_eq!(east.len(), 1, "{east:?}");
    // Between them the SCT layers are one, its base between the two, and the BKN layer only
    // the western station has thins out towards the east.
    let mut last_base = 2400.0;
    let mut last_upper = 8.0;
    for lon in [7.7, 7.9, 8.1, 8.3] {
        let layers = at(lon);
        let low: Vec<_> = layers.iter().filter(|l| l.base_ft_agl < 5000.0).collect();
        assert_eq!(low.len(), 1, "{lon}: {layers:?}");
        assert!(low[0].base_ft_agl >= last_base, "{lon}: {layers:?}");
        assert!(
            (low[0].coverage_oktas - 3.5).abs() < 0.5,
            "{lon}: {layers:?}"
        );
        last_base = low[0].base_ft_agl;
        let upper = layers
            .iter()
            .find(|l| l.base_ft_agl > 5000.0)
            .map_or(0.0, |l| l.coverage_oktas);
        assert!(upper < last_upper, "{lon}: {layers:?}");
        last_upper = upper;
    }
    assert!(last_base > 2400.0 && last_base <= 2800.0);
    assert!(last_upper < 2.0, "{last_upper}");
}

#[test]
fn a_block_that_holds_a_station_is_its_report() {
    let f = field(&square());
    for (lat, lon) in [(49.5, 7.3), (50.0, 8.0), (50.5, 8.7)] {
        let block = f.frame().block_of(lat, lon);
        let at_station = f.weather_at_lat_lon(lat, lon);
        let w = f.block_weather(block);
        let sample = f.block_sample_point_m(block) - block.min_corner_m();
        let cover = w
            .cover
            .clone()
            .expect("a block's weather has its cover at the rim");
        assert_eq!(cover.sample_m, sample.as_vec2().to_array());
        assert_eq!(BlockWeather { cover: None, ..w }, at_station, "{lat},{lon}");
        assert_ne!(f.block_sample_point_m(block), block.centre_m());
    }
}

#[test]
fn covers_follow_the_summation_principle_and_tops_the_type() {
    use crate::weather::block::{ceiling_ft, cover_seen_from_below_oktas};
    // FEW008 SCT026 BKN045 (Dublin) next to FEW020CB BKN025 over a warm surface.
    let dublin = vec![
        layer(Cover::Few, 800, None),
        layer(Cover::Sct, 2600, None),
        layer(Cover::Bkn, 4500, None),
    ];
    let cb = vec![
        layer(Cover::Few, 2000, Some(ConvectiveKind::Cb)),
        layer(Cover::Bkn, 2500, None),
    ];
    let f = pair(dublin, cb);
    let layers = f.weather_at_lat_lon(LAT0, 7.5).layers;
    let seen: Vec<f32> = layers
        .iter()
        .map(|l| cover_seen_from_below_oktas(&layers, l.base_ft_agl))
        .collect();
    assert_eq!(layers.len(), 3);
    for (got, want) in seen.iter().zip([2.0, 3.5, 6.0]) {
        assert!((got - want).abs() < 1e-4, "{seen:?}");
    }
    assert_eq!(ceiling_ft(&layers, 5.0), Some(4500.0));
    // The lower layers stop under the next base.
    assert!(layers[0].thickness_ft <= 1800.0 && layers[1].thickness_ft <= 1900.0);
    let layers = f.weather_at_lat_lon(LAT0, 8.5).layers;
    assert_eq!(layers.len(), 2, "{layers:?}");
    let (cells, deck) = (layers[0], layers[1]);
    assert_eq!(cells.cloud_type, CloudType::Cumulonimbus);
    assert_eq!(cells.coverage_oktas, 2.0);
    // 10 degrees C: a third of the way from 25,000 to 40,000 ft.
    assert!((cells.base_ft_agl + cells.thickness_ft - 30_000.0).abs() < 1.0);
    assert_eq!(deck.cloud_type, CloudType::Stratocumulus);
    // The BKN025 is the deck's own 6 oktas: the FEW020CB stands outside the summation (ICAO
    // Annex 3), so the deck does not count the cells' 2 oktas as part of its cover.
    assert_eq!(deck.coverage_oktas, 6.0);
}

/// KNUC's `FEW024 FEW060 FEW180` (2025 file): the minimum cover the lower layers are drawn with
/// lifts the sky seen from below past FEW's 2 oktas; the top layer's room is still FEW's, the
/// class reported at its base, not the SCT class the lifts reached.
#[test]
fn a_run_of_few_layers_stays_few_from_below() {
    use crate::weather::block::cover_seen_from_below_oktas;
    let few_run = vec![
        layer(Cover::Few, 2400, None),
        layer(Cover::Few, 6000, None),
        layer(Cover::Few, 18000, None),
    ];
    let f = pair(few_run, vec![layer(Cover::Ovc, 9000, None)]);
    let layers = f.weather_at_lat_lon(LAT0, 7.5).layers;
    assert_eq!(layers.len(), 3, "{layers:?}");
    let few = FieldSettings::default().oktas.few as f32;
    for l in &layers {
        let seen = cover_seen_from_below_oktas(&layers, l.base_ft_agl);
        assert!(
            (seen - few).abs() <= 1.0,
            "{seen} oktas seen from below at {} ft: {layers:?}",
            l.base_ft_agl
        );
    }
}

#[test]
fn cb_and_tcu_keep_their_own_amount_above_a_deck() {
    use crate::weather::metar::Cover::{Bkn, Few, Sct};
    // SCT008 BKN017 FEW025CB BKN100 (a real Brazilian report): 1-2 oktas of Cb, not the 0.5
    // okta a Cb summed into the broken deck under it would add.
    let brazil = vec![
        layer(Sct, 800, None),
        layer(Bkn, 1700, None),
        layer(Few, 2500, Some(ConvectiveKind::Cb)),
        layer(Bkn, 10000, None),
    ];
    // BKN010 SCT030TCU and a Cb of unknown amount and base (`//////CB`): the towers their own
    // 3.5 oktas (SCT's), the Cb drawn as FEW.
    let unknown = vec![
        layer(Bkn, 1000, None),
        layer(Sct, 3000, Some(ConvectiveKind::Tcu)),
        CloudGroup {
            cover: None,
            base_ft: None,
            kind: Some(ConvectiveKind::Cb),
        },
    ];
    let f = pair(brazil, unknown);
    let layers = f.weather_at_lat_lon(LAT0, 7.5).layers;
    let own: Vec<(CloudType, f32, f32)> = layers
        .iter()
        .map(|l| (l.cloud_type, l.base_ft_agl, l.coverage_oktas))
        .collect();
    assert_eq!(layers.len(), 4, "{own:?}");
    assert_eq!(
        (own[2].0, own[2].1, own[2].2),
        (CloudType::Cumulonimbus, 2500.0, 2.0)
    );
    // The plain layers sum among themselves: 3.5 oktas, then 6 seen from below at 1,700 ft.
    let plain: Vec<_> = layers
        .iter()
        .filter(|l| l.cloud_type != CloudType::Cumulonimbus)
        .copied()
        .collect();
    let seen = crate::weather::block::cover_seen_from_below_oktas(&plain, 1700.0);
    assert!((seen - 6.0).abs() < 1e-4, "{own:?}");
    let layers = f.weather_at_lat_lon(LAT0, 8.5).layers;
    let towers = layers
        .iter()
        .find(|l| l.cloud_type == CloudType::CumulusCongestus)
        .expect("the TCU layer");
    assert_eq!((towers.base_ft_agl, towers.coverage_oktas), (3000.0, 3.5));
    let cells = layers
        .iter()
        .find(|l| l.cloud_type == CloudType::Cumulonimbus)
        .expect("the CB layer");
    assert_eq!(cells.coverage_oktas, 2.0, "{layers:?}");
}

/// Around a station its report holds: within `[stations] hold_m` the layers are the station's
/// (its weight raised `hold_weight` times), beyond the fade they are the plain blend, and the
/// way from one to the other has no step (the raise fades in a smoothstep).
#[test]
fn a_report_holds_around_its_station_and_fades_without_a_step() {
    let f = pair(
        vec![layer(Cover::Ovc, 1000, None)],
        vec![layer(Cover::Few, 4000, None)],
    );
    let hold = f.settings().stations;
    assert!(hold.hold_m >= 3_000.0 && hold.hold_weight > 1.0, "{hold:?}");
    let west = f.frame().to_local_m(LAT0, 7.5);
    let east = f.frame().to_local_m(LAT0, 8.5);
    let towards_east = (east - west).normalize();
    let ovc_at = |d: f64| {
        f.weather_at(west + towards_east * d)
            .layers
            .iter()
            .find(|l| l.base_ft_agl < 2000.0)
            .map_or(0.0, |l| l.coverage_oktas)
    };
    // Within the hold, 8 oktas to within a tenth: the western station's overcast, where plain
    // natural-neighbour weights 3 km out gave the eastern station's clear sky some say.
    for d in [1_000.0, 3_000.0, 0.9 * hold.hold_m] {
        assert!(ovc_at(d) > 7.9, "{d} m: {}", ovc_at(d));
    }
    let plain = FieldSettings {
        stations: crate::weather::field::StationHold {
            hold_weight: 1.0,
            ..hold
        },
        ..FieldSettings::default()
    };
    let unheld = WeatherField::build(
        LocalFrame::new(LAT0, LON0),
        &[
            station(
                LAT0,
                7.5,
                1,
                report(vec![layer(Cover::Ovc, 1000, None)], 10.0, 270),
            ),
            station(
                LAT0,
                8.5,
                2,
                report(vec![layer(Cover::Few, 4000, None)], 10.0, 270),
            ),
            station(48.0, 6.0, 3, cavok(10.0)),
            station(52.0, 10.0, 4, cavok(10.0)),
            station(48.0, 10.0, 5, cavok(10.0)),
            station(52.0, 6.0, 6, cavok(10.0)),
        ],
        &plain,
        &CloudTypeRule::default(),
    );
    let beyond = hold.hold_m + hold.fade_m + 5_000.0;
    let at = west + towards_east * beyond;
    assert_eq!(f.weather_at(at), unheld.weather_at(at), "{beyond} m");
    // 50 m steps through the fade: the cover changes by a few hundredths at most a step.
    let mut last = ovc_at(hold.hold_m - 500.0);
    let mut d = hold.hold_m - 450.0;
    while d < hold.hold_m + hold.fade_m + 500.0 {
        let now = ovc_at(d);
        assert!((now - last).abs() < 0.05, "{d} m: {last} -> {now}");
        last = now;
        d += 50.0;
    }
}

#[test]
fn the_hold_raises_a_station_smoothly() {
    let hold = FieldSettings::default().stations;
    assert_eq!(hold.raise_at(0.0), hold.hold_weight);
    assert_eq!(hold.raise_at(hold.hold_m), hold.hold_weight);
    assert_eq!(hold.raise_at(hold.hold_m + hold.fade_m), 1.0);
    let mid = hold.raise_at(hold.hold_m + 0.5 * hold.fade_m);
    assert!((mid - hold.hold_weight.sqrt()).abs() < 1e-9, "{mid}");
}

/// Above a sky that is all but overcast from below, a layer only a distant station reports
/// keeps that station's share of its own cover: the summation principle, asked what it adds to
/// 7.99 oktas, made a few oktas of it out of a hundredth.
#[test]
fn a_far_stations_layer_over_a_near_overcast_stays_faint() {
    let f = pair(
        vec![layer(Cover::Ovc, 1000, None)],
        vec![layer(Cover::Few, 1000, None), layer(Cover::Bkn, 4000, None)],
    );
    let west = f.frame().to_local_m(LAT0, 7.5);
    let east = f.frame().to_local_m(LAT0, 8.5);
    for km in [4.0, 6.0, 8.0] {
        let at = west + (east - west).normalize() * km * 1000.0;
        let layers = f.weather_at(at).layers;
        let low = layers[0].coverage_oktas;
        assert!(low > 7.5, "{km} km: {layers:?}");
        let upper = layers
            .iter()
            .find(|l| l.base_ft_agl > 3000.0)
            .map_or(0.0, |l| l.coverage_oktas);
        assert!(upper < 1.0, "{km} km: {layers:?}");
    }
}

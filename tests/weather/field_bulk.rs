//! The weather field at every cloudy station of `weather/awc-metars-2025-01-27T22Z.cache.csv`,
//! compared with the service's own decode of the same row (its `sky_cover`/`cloud_base_ft_agl`
//! pairs, `OVX` with base 0 for a vertical visibility).
//!
//! A reported layer is reproduced when the field has a layer whose base is within max(200 ft, 10%)
//! of it and whose cover seen from below ([`skycast::weather::block::cover_seen_from_below_oktas`],
//! over the field's layers that are not reported CB/TCU) is within 1 okta of the reported cover (as
//! the shipped `[oktas]` draw it: FEW 2, SCT 3.5, BKN 6, OVC and OVX 8 oktas; by the summation
//! principle the largest such cover reported at or below the base). A CB or TCU group (read from
//! the raw text, before any trend or remark) stands outside that principle (ICAO Annex 3): it is
//! reproduced by a reported CB/TCU layer whose own coverage is within 1 okta of the group's amount.
//! The ceiling is the lowest base where the cover seen from below, or a CB/TCU group's own amount,
//! reaches 5 oktas (BKN); it is right when both are absent or the bases agree as above. The field
//! is asked at each station and, the way the clouds stage asks it, for the 4 km block that holds
//! the station.
//!
//! Run alone with `cargo test --test tests field_bulk -- --nocapture` to print the figures.

use std::collections::HashMap;
use std::io::BufRead;
use std::path::Path;

use skycast::weather::block::{BlockLayer, ceiling_ft, cover_seen_from_below_oktas};
use skycast::weather::model::{ModelField, ModelSettings};
use skycast::weather::{
    CloudTypeRule, FieldSettings, LocalFrame, StationTable, WeatherField, files,
};

const BULK_FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/awc-metars-2025-01-27T22Z.cache.csv"
);

/// One row of the service's decode: position, time and the sky layers (oktas, base ft AGL,
/// whether the raw text marks the group CB or TCU).
struct Row {
    station: String,
    time: String,
    lat_deg: f64,
    lon_deg: f64,
    layers: Vec<(f32, f32, bool)>,
}

/// Whether the observation part of the raw report (before a trend or the remarks) has the group
/// of `cover` at `base_ft` marked CB or TCU.
fn convective_in(raw: &str, cover: &str, base_ft: f32) -> bool {
    let group = format!("{cover}{:03}", (base_ft / 100.0).round() as u32);
    raw.split_whitespace()
        .take_while(|t| !matches!(*t, "TEMPO" | "BECMG" | "NOSIG" | "RMK"))
        .any(|t| {
            t.strip_prefix(&group)
                .is_some_and(|kind| kind.starts_with("CB") || kind.starts_with("TCU"))
        })
}

/// A reported cover as the shipped `[oktas]` draw it.
fn oktas(cover: &str) -> Option<f32> {
    static OKTAS: std::sync::LazyLock<skycast::weather::field::PerCover> =
        std::sync::LazyLock::new(|| FieldSettings::default().oktas);
    let o = *OKTAS;
    let oktas = match cover {
        "FEW" => o.few,
        "SCT" => o.sct,
        "BKN" => o.bkn,
        "OVC" | "OVX" => o.ovc,
        _ => return None,
    };
    Some(oktas as f32)
}

fn read_rows() -> Vec<Row> {
    let file = std::fs::File::open(BULK_FILE).expect("the bulk file is in the repository");
    let mut reader = std::io::BufReader::new(file);
    let mut preamble = String::new();
    for _ in 0..5 {
        reader.read_line(&mut preamble).expect("preamble line");
    }
    let mut csv = csv::Reader::from_reader(reader);
    let header = csv.headers().expect("header").clone();
    let col = |name: &str| header.iter().position(|h| h == name).expect(name);
    let (raw, station, time, lat, lon) = (
        col("raw_text"),
        col("station_id"),
        col("observation_time"),
        col("latitude"),
        col("longitude"),
    );
    let covers: Vec<usize> = (0..header.len())
        .filter(|&i| &header[i] == "sky_cover")
        .collect();
    let mut rows = Vec::new();
    for record in csv.records() {
        let record = record.expect("a CSV row");
        let (Ok(lat_deg), Ok(lon_deg)) = (record[lat].parse(), record[lon].parse()) else {
            continue;
        };
        let layers = covers
            .iter()
            .filter_map(|&i| {
                let o = oktas(&record[i])?;
                let base: f32 = record.get(i + 1)?.parse().ok()?;
                Some((o, base, convective_in(&record[raw], &record[i], base)))
            })
            .collect();
        rows.push(Row {
            station: record[station].to_string(),
            time: record[time].to_string(),
            lat_deg,
            lon_deg,
            layers,
        });
    }
    rows
}

/// Reported layers reproduced, of all reported layers; ceilings right, of all stations.
#[derive(Default, Debug)]
struct Score {
    layers: usize,
    layers_ok: usize,
    stations: usize,
    ceilings_ok: usize,
    counts_ok: usize,
    misses: Vec<String>,
}

impl Score {
    fn add(&mut self, row: &Row, field: &[BlockLayer]) {
        let within = |a: f32, b: f32| (a - b).abs() <= 200f32.max(0.1 * b);
        let plain: Vec<BlockLayer> = field
            .iter()
            .filter(|l| !l.has_own_amount())
            .copied()
            .collect();
        let mut below = 0.0f32;
        let mut ceiling = None;
        for &(cover, base, convective) in &row.layers {
            // The summation principle: the cover seen from below never shrinks upwards; CB and
            // TCU amounts are their own.
            if !convective {
                below = below.max(cover);
            }
            if below.max(if convective { cover } else { 0.0 }) >= 5.0 && ceiling.is_none() {
                ceiling = Some(base);
            }
            self.layers += 1;
            let ok = if convective {
                field.iter().any(|l| {
                    l.has_own_amount()
                        && within(l.base_ft_agl, base)
                        && (l.coverage_oktas - cover).abs() <= 1.0
                })
            } else {
                plain.iter().any(|l| {
                    within(l.base_ft_agl, base)
                        && (cover_seen_from_below_oktas(&plain, l.base_ft_agl) - below).abs() <= 1.0
                })
            };
            if ok {
                self.layers_ok += 1;
            } else if self.misses.len() < 20 {
                self.misses
                    .push(format!("{} {cover}@{base}: {field:?}", row.station));
            }
        }
        self.stations += 1;
        let got = ceiling_ft(field, 5.0);
        if match (ceiling, got) {
            (None, None) => true,
            (Some(want), Some(got)) => within(got, want),
            _ => false,
        } {
            self.ceilings_ok += 1;
        }
        if field.len() == row.layers.len() {
            self.counts_ok += 1;
        }
    }

    fn layer_share(&self) -> f64 {
        self.layers_ok as f64 / self.layers as f64
    }

    fn ceiling_share(&self) -> f64 {
        self.ceilings_ok as f64 / self.stations as f64
    }

    fn line(&self) -> String {
        format!(
            "{} of {} reported layers ({:.2}%), ceilings right at {} of {} stations ({:.2}%), \
             layer count right at {:.2}%",
            self.layers_ok,
            self.layers,
            100.0 * self.layer_share(),
            self.ceilings_ok,
            self.stations,
            100.0 * self.ceiling_share(),
            100.0 * self.counts_ok as f64 / self.stations as f64
        )
    }
}

#[test]
fn the_field_at_every_cloudy_station_is_its_report() {
    let (at_station, in_block) = scores(false);
    for (what, score) in [
        ("at the stations", &at_station),
        ("in their blocks", &in_block),
    ] {
        assert!(
            score.layer_share() >= 0.99 && score.ceiling_share() >= 0.995,
            "{what}: {}\nfirst misses:\n{}",
            score.line(),
            score.misses.join("\n")
        );
    }
}

/// With the GFS model under the reports ([`WeatherField::with_model`]) every station still
/// gives its report: the round trip does not fall.
#[test]
fn with_a_model_under_them_every_cloudy_station_is_still_its_report() {
    let (alone, alone_block) = scores(false);
    let (with_model, with_model_block) = scores(true);
    assert_eq!(
        (with_model.layers_ok, with_model.ceilings_ok),
        (alone.layers_ok, alone.ceilings_ok),
        "at the stations: {} with the model, {} without",
        with_model.line(),
        alone.line()
    );
    assert_eq!(
        (with_model_block.layers_ok, with_model_block.ceilings_ok),
        (alone_block.layers_ok, alone_block.ceilings_ok),
        "in their blocks: {} with the model, {} without",
        with_model_block.line(),
        alone_block.line()
    );
}

/// The shipped GFS model file.
pub(super) fn gfs() -> std::sync::Arc<ModelField> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2");
    std::sync::Arc::new(ModelField::load(&path).unwrap())
}

/// The bulk file's field (over the GFS model with `model`) scored at every cloudy station and
/// in the station's block.
fn scores(model: bool) -> (Score, Score) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("weather");
    let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
    let file = files::load(Path::new(BULK_FILE), Some(&stations)).unwrap();
    let frame = LocalFrame::new(51.848, -8.479);
    let field = WeatherField::build(
        frame,
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let field = if model {
        field.with_model(gfs(), ModelSettings::default())
    } else {
        field
    };
    // The stations the field holds: placed, one report per position (the latest, as the field
    // keeps it: by observation time, then by row).
    let key = |lat: f64, lon: f64| (lat.to_bits(), lon.to_bits());
    let placed: std::collections::HashSet<_> = file
        .reports
        .iter()
        .map(|p| key(p.position.latitude_deg, p.position.longitude_deg))
        .collect();
    let rows = read_rows();
    let mut latest: HashMap<(u64, u64), &Row> = HashMap::new();
    for row in &rows {
        let k = key(row.lat_deg, row.lon_deg);
        if !placed.contains(&k) {
            continue;
        }
        latest
            .entry(k)
            .and_modify(|old| {
                if row.time >= old.time {
                    *old = row;
                }
            })
            .or_insert(row);
    }
    let mut cloudy: Vec<&Row> = latest
        .into_values()
        .filter(|r| !r.layers.is_empty())
        .collect();
    cloudy.sort_by(|a, b| a.station.cmp(&b.station));
    let (mut at_station, mut in_block) = (Score::default(), Score::default());
    for row in &cloudy {
        let w = field.weather_at_lat_lon(row.lat_deg, row.lon_deg);
        at_station.add(row, &w.layers);
        let block = field.block_weather(frame.block_of(row.lat_deg, row.lon_deg));
        in_block.add(row, &block.layers);
    }
    let with = if model { " (model under them)" } else { "" };
    eprintln!("at the stations{with}: {}", at_station.line());
    eprintln!("in their blocks{with}: {}", in_block.line());
    assert!(cloudy.len() > 2_000, "{} cloudy stations", cloudy.len());
    (at_station, in_block)
}

/// The field of the whole bulk file and the weather at one of its stations.
fn at_station(id: &str) -> skycast::weather::BlockWeather {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("weather");
    let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
    let file = files::load(Path::new(BULK_FILE), Some(&stations)).unwrap();
    let p = file
        .reports
        .iter()
        .find(|p| p.report.station == id)
        .expect(id);
    let frame = LocalFrame::new(p.position.latitude_deg, p.position.longitude_deg);
    let field = WeatherField::build(
        frame,
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    // The block that holds the station, as the clouds stage asks for it: the weather at the
    // station, and besides it the cover at the block's rim.
    let block =
        field.block_weather(frame.block_of(p.position.latitude_deg, p.position.longitude_deg));
    assert!(block.cover.is_some());
    assert_eq!(
        skycast::weather::BlockWeather {
            cover: None,
            ..block.clone()
        },
        field.weather_at_lat_lon(p.position.latitude_deg, p.position.longitude_deg)
    );
    block
}

#[test]
fn dublin_has_its_three_layers_and_a_4500_ft_ceiling() {
    // EIDW 272200Z 13004KT 100V160 9999 -RA FEW008 SCT026 BKN045 08/07 Q0966 NOSIG
    let w = at_station("EIDW");
    let bases: Vec<f32> = w.layers.iter().map(|l| l.base_ft_agl).collect();
    assert_eq!(bases, [800.0, 2600.0, 4500.0], "{:?}", w.layers);
    for (l, cover) in w.layers.iter().zip([2.0, 3.5, 6.0]) {
        let seen = cover_seen_from_below_oktas(&w.layers, l.base_ft_agl);
        assert!((seen - cover).abs() < 1e-4, "{seen} {:?}", w.layers);
    }
    assert_eq!(ceiling_ft(&w.layers, 5.0), Some(4500.0));
    assert_eq!(w.visibility_m, 10_000.0);
}

#[test]
fn timika_has_isolated_cb_cells_beside_a_broken_deck() {
    // WAYY 272200Z 35005KT 4000 -RA FEW012CB BKN013 25/24 Q1010 NOSIG CB TO N
    use skycast::weather::{CloudType, TypeSource};
    let w = at_station("WAYY");
    assert_eq!(w.layers.len(), 2, "{:?}", w.layers);
    let (cb, deck) = (w.layers[0], w.layers[1]);
    assert_eq!(
        (cb.cloud_type, cb.type_source),
        (CloudType::Cumulonimbus, TypeSource::Reported)
    );
    assert_eq!((cb.base_ft_agl, cb.coverage_oktas), (1200.0, 2.0));
    assert!(cb.base_ft_agl + cb.thickness_ft >= 25_000.0, "{cb:?}");
    assert_ne!(deck.cloud_type, CloudType::Cumulonimbus);
    assert_eq!(deck.base_ft_agl, 1300.0);
    // The deck's BKN is its own 6 oktas: the Cb's FEW stands outside the summation.
    assert_eq!(deck.coverage_oktas, 6.0);
    assert_eq!(ceiling_ft(&w.layers, 5.0), Some(1300.0));
    assert_eq!(w.visibility_m, 4000.0);
}

#[test]
fn belo_horizonte_cb_tops_pass_25000_ft() {
    // SBBH 272200Z 35014KT 3000 TSRA BKN045CB 22/19 Q1016
    use skycast::weather::CloudType;
    let w = at_station("SBBH");
    assert_eq!(w.layers.len(), 1, "{:?}", w.layers);
    let cb = w.layers[0];
    assert_eq!(cb.cloud_type, CloudType::Cumulonimbus);
    assert_eq!(cb.base_ft_agl, 4500.0);
    assert!(cb.base_ft_agl + cb.thickness_ft > 25_000.0, "{cb:?}");
    assert_eq!(ceiling_ft(&w.layers, 5.0), Some(4500.0));
}

#[test]
fn a_cb_group_keeps_its_own_amount_and_an_unknown_one_is_few() {
    // SLSV 272200Z 36006KT 9999 BKN017 FEW025CB BKN200 26/24 Q1007: ICAO Annex 3 reports the
    // Cb with its own amount, so 1-2 oktas of Cb above the broken deck, not the 0.5 okta the
    // summation principle would leave it.
    use skycast::weather::CloudType;
    let w = at_station("SLSV");
    let cb = w
        .layers
        .iter()
        .find(|l| l.cloud_type == CloudType::Cumulonimbus)
        .unwrap_or_else(|| panic!("no Cb: {:?}", w.layers));
    assert_eq!((cb.base_ft_agl, cb.coverage_oktas), (2500.0, 2.0), "{cb:?}");
    // LFRL 272200Z AUTO 22025G38KT 9999 BKN024/// BKN030/// BKN045/// //////CB 10/07 Q0983:
    // an automatic station's Cb of unknown amount is drawn as FEW.
    let w = at_station("LFRL");
    let cb = w
        .layers
        .iter()
        .find(|l| l.cloud_type == CloudType::Cumulonimbus)
        .unwrap_or_else(|| panic!("no Cb: {:?}", w.layers));
    assert_eq!(cb.coverage_oktas, 2.0, "{cb:?}");
}

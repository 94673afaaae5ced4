//! The weather stage's CPU cost. `metar_decode_bulk`: decode every report of the real bulk file
//! (4,909 METAR/SPECI from the aviation weather service, `weather/awc-metars-*.cache.csv`); the
//! texts are read once, outside the timed loop. Goal: under 10 ms for the whole file.
//! `weather_file_bulk`: the same file as a user's file is read (format detection, CSV, decoding,
//! placing); `station_table_parse`: NOAA's 6,519-station table; `weather_field_build`: the field
//! of every placed report (projection, merging, two Delaunay triangulations);
//! `weather_field_query_100_blocks`: 100 block queries (natural-neighbour interpolation).

use std::hint::black_box;
use std::io::BufRead;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use skycast::weather::metar::decode;
use skycast::weather::{
    BlockIndex, CloudTypeRule, FieldSettings, LocalFrame, StationTable, WeatherField, files,
};

const BULK_FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/awc-metars-2025-01-27T22Z.cache.csv"
);

/// The `raw_text` column of the bulk file (5 preamble lines, then a CSV header).
fn bulk_reports() -> Vec<String> {
    let file = std::fs::File::open(BULK_FILE).expect("the bulk file is in the repository");
    let mut reader = std::io::BufReader::new(file);
    let mut preamble = String::new();
    for _ in 0..5 {
        reader.read_line(&mut preamble).expect("preamble line");
    }
    let mut csv = csv::Reader::from_reader(reader);
    let column = csv
        .headers()
        .expect("header")
        .iter()
        .position(|h| h == "raw_text")
        .expect("raw_text column");
    csv.records()
        .map(|r| r.expect("CSV row")[column].to_string())
        .collect()
}

fn metar_decode_bulk(c: &mut Criterion) {
    let reports = bulk_reports();
    assert_eq!(reports.len(), 4_909);
    c.bench_function("metar_decode_bulk", |b| {
        b.iter(|| {
            let mut layers = 0;
            for text in &reports {
                if let Ok(report) = decode(black_box(text)) {
                    layers += report.clouds.len();
                }
            }
            layers
        })
    });
}

const STATION_TABLE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/weather/nsd_cccc.txt");

/// Reading the whole bulk file as a user's file is read: format detection, CSV, decoding every
/// report, placing it (the file's own positions, the station table for the rest).
fn weather_file_bulk(c: &mut Criterion) {
    let bytes = std::fs::read(BULK_FILE).expect("the bulk file is in the repository");
    let stations = StationTable::load(Path::new(STATION_TABLE)).expect("the station table");
    c.bench_function("weather_file_bulk", |b| {
        b.iter(|| {
            let file = files::parse(Path::new(BULK_FILE), black_box(&bytes), Some(&stations))
                .expect("the bulk file reads");
            file.reports.len()
        })
    });
    let text = std::fs::read_to_string(STATION_TABLE).expect("the station table");
    c.bench_function("station_table_parse", |b| {
        b.iter(|| {
            StationTable::parse(Path::new(STATION_TABLE), black_box(&text))
                .expect("the table parses")
                .len()
        })
    });
}

/// Building the weather field of every placed report of the bulk file (projection, merging,
/// two Delaunay triangulations), and querying 100 blocks of it (south-west Ireland, 40 x 40 km).
fn weather_field(c: &mut Criterion) {
    let stations = StationTable::load(Path::new(STATION_TABLE)).expect("the station table");
    let file = files::load(Path::new(BULK_FILE), Some(&stations)).expect("the bulk file reads");
    assert_eq!(file.reports.len(), 4_877);
    let settings = FieldSettings::default();
    let rule = CloudTypeRule::default();
    let frame = LocalFrame::new(51.848, -8.479);
    c.bench_function("weather_field_build", |b| {
        b.iter(|| {
            WeatherField::build(frame, black_box(&file.reports), &settings, &rule).station_count()
        })
    });
    let field = WeatherField::build(frame, &file.reports, &settings, &rule);
    c.bench_function("weather_field_query_100_blocks", |b| {
        b.iter(|| {
            let mut layers = 0;
            for i in -5..5 {
                for j in -5..5 {
                    layers += field
                        .block_weather(black_box(BlockIndex::new(i, j)))
                        .layers
                        .len();
                }
            }
            layers
        })
    });
}

criterion_group!(benches, metar_decode_bulk, weather_file_bulk, weather_field);
criterion_main!(benches);

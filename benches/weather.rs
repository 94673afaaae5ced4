//! The weather stage's CPU cost. `metar_decode_bulk`: decode every report of the real bulk file
//! (4,909 METAR/SPECI from the aviation weather service, `weather/awc-metars-*.cache.csv`); the
//! texts are read once, outside the timed loop. Goal: under 10 ms for the whole file.

use std::hint::black_box;
use std::io::BufRead;

use criterion::{Criterion, criterion_group, criterion_main};
use skycast::weather::metar::decode;

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

criterion_group!(benches, metar_decode_bulk);
criterion_main!(benches);

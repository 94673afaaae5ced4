//! Every report of `weather/awc-metars-2025-01-27T22Z.cache.csv` (4,909, the aviation weather
//! service's bulk export) through [`skycast::weather::metar::decode`], its cloud layers compared
//! with the service's own decode in the same row: up to four `sky_cover`/`cloud_base_ft_agl`
//! pairs and `vert_vis_ft`.
//!
//! The service's conventions, read off the file: `CAVOK` for CAVOK; `CLR` for CLR, NSC and NCD;
//! `SKC` for SKC; `OVX` with base 0 for a vertical visibility, whose height goes in
//! `vert_vis_ft`; a layer with no cover or no base (`BKN///`, `//////CB`) is left out.

use std::io::BufRead;

use skycast::weather::metar::{Cover, Report, SkyCode, decode};

const BULK_FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/awc-metars-2025-01-27T22Z.cache.csv"
);

/// One row: the raw report and the service's sky columns.
struct Row {
    raw: String,
    /// (sky_cover, cloud_base_ft_agl) pairs that are present.
    layers: Vec<(String, String)>,
    vert_vis_ft: String,
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
    let raw_col = header
        .iter()
        .position(|h| h == "raw_text")
        .expect("raw_text");
    let cover_cols: Vec<usize> = (0..header.len())
        .filter(|&i| &header[i] == "sky_cover")
        .collect();
    let vv_col = header
        .iter()
        .position(|h| h == "vert_vis_ft")
        .expect("vert_vis_ft");
    assert_eq!(cover_cols.len(), 4);
    csv.records()
        .map(|rec| {
            let rec = rec.expect("CSV row");
            Row {
                raw: rec[raw_col].to_string(),
                layers: cover_cols
                    .iter()
                    .filter(|&&c| !rec[c].is_empty())
                    .map(|&c| (rec[c].to_string(), rec[c + 1].to_string()))
                    .collect(),
                vert_vis_ft: rec[vv_col].to_string(),
            }
        })
        .collect()
}

/// Our decode written the way the service writes it.
fn as_service(report: &Report) -> (Vec<(String, String)>, String) {
    let mut layers = Vec::new();
    let mut vert_vis_ft = String::new();
    if report.cavok {
        layers.push(("CAVOK".to_string(), String::new()));
    }
    match report.sky {
        Some(SkyCode::Clr | SkyCode::Nsc | SkyCode::Ncd) => {
            layers.push(("CLR".into(), String::new()))
        }
        Some(SkyCode::Skc) => layers.push(("SKC".into(), String::new())),
        Some(SkyCode::Nil) | None => {}
    }
    for cloud in &report.clouds {
        match (cloud.cover, cloud.base_ft) {
            (Some(Cover::Vv), base) => {
                layers.push(("OVX".into(), "0".into()));
                vert_vis_ft = base.map(|b| b.to_string()).unwrap_or_default();
            }
            (Some(cover), Some(base)) => layers.push((cover.code().into(), base.to_string())),
            _ => {}
        }
    }
    layers.truncate(4);
    (layers, vert_vis_ft)
}

#[test]
fn every_bulk_report_decodes_and_its_layers_agree_with_the_service() {
    let rows = read_rows();
    assert_eq!(rows.len(), 4_909);
    let mut disagreements = Vec::new();
    let mut warnings = 0;
    for row in &rows {
        let report = decode(&row.raw).unwrap_or_else(|e| panic!("{}: {e}", row.raw));
        warnings += report.warnings.len();
        let (layers, vv) = as_service(&report);
        if layers != row.layers || vv != row.vert_vis_ft {
            disagreements.push(row.raw.as_str());
        }
    }
    // The one disagreement: `FEW040TCUBKN070` is two groups run together. We skip the malformed
    // group with a warning (a group we cannot read is not guessed at); the service keeps the
    // BKN070 half and drops the FEW040TCU half, so it lists SCT030 BKN070 where we list SCT030.
    assert_eq!(
        disagreements,
        ["SGES 272200Z 12006KT 9999 SCT030 FEW040TCUBKN070 27/25 Q1009"],
        "{} of {} reports disagree",
        disagreements.len(),
        rows.len()
    );
    // Warnings are groups that are not main-body METAR groups: free text after the altimeter
    // (`CB NW`, `VOLC STA MARIA`), Central American `QFE 987/4`, typing errors (`E26008KT`,
    // `36004KTT`, `2w2152Z`, `272200Z32004KT`), the malformed cloud group above. Counted so a
    // change to the decoder that starts warning on good groups shows here.
    assert_eq!(warnings, 40);
}

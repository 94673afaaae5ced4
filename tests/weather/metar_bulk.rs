//! Every report of `weather/awc-metars-2025-01-27T22Z.cache.csv` (4,909, the aviation weather
//! service's bulk export) through [`skycast::weather::metar::decode`], compared with the
//! service's own decode in the same row: its four `sky_cover`/`cloud_base_ft_agl` pairs and
//! `vert_vis_ft` (the layers past four ours alone), temperature, dewpoint, wind, gust,
//! visibility, altimeter and present weather.
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

/// The service's columns, besides the sky, that the decoder also decodes.
const COLUMNS: [&str; 8] = [
    "temp_c",
    "dewpoint_c",
    "wind_dir_degrees",
    "wind_speed_kt",
    "wind_gust_kt",
    "visibility_statute_mi",
    "altim_in_hg",
    "wx_string",
];

/// One row: the raw report and the service's decoded columns.
struct Row {
    raw: String,
    /// (sky_cover, cloud_base_ft_agl) pairs that are present.
    layers: Vec<(String, String)>,
    vert_vis_ft: String,
    /// The values of [`COLUMNS`], in order.
    columns: Vec<String>,
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
    let column_cols: Vec<usize> = COLUMNS
        .iter()
        .map(|c| header.iter().position(|h| h == *c).expect(c))
        .collect();
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
                columns: column_cols.iter().map(|&c| rec[c].to_string()).collect(),
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
    (layers, vert_vis_ft)
}

/// Whether our decode agrees with the service's `column` (one of [`COLUMNS`]), as the service
/// writes it: temperatures in tenths from the remarks' T group where there is one (the body's
/// whole degrees are within half a degree of them), knots in whole numbers, visibility in
/// statute miles to 2 places (`6+` for 9999, P6SM and CAVOK, `10+` for 10SM), the altimeter in
/// inches to 2 places (`0.00` when missing), weather groups space-separated.
fn agrees(report: &Report, column: &str, service: &str) -> bool {
    let number = |ours: Option<f32>, tolerance: f32| match (ours, service) {
        (None, "") => true,
        (Some(v), s) => s.parse::<f32>().is_ok_and(|s| (v - s).abs() <= tolerance),
        _ => false,
    };
    let wind = report.wind.as_ref();
    match column {
        "temp_c" => number(report.temperature_c, 0.51),
        "dewpoint_c" => number(report.dewpoint_c, 0.51),
        "wind_dir_degrees" => match wind.map(|w| (w.dir_deg, w.variable)) {
            Some((None, true)) => service == "VRB",
            Some((Some(d), _)) => service == d.to_string(),
            _ => service.is_empty(),
        },
        "wind_speed_kt" => number(wind.and_then(|w| w.speed_kt), 0.5),
        "wind_gust_kt" => number(wind.and_then(|w| w.gust_kt), 0.5),
        "visibility_statute_mi" => {
            let miles = report.visibility_m.map(|m| m / 1609.344);
            match service.strip_suffix('+') {
                Some(at_least) => miles.is_some_and(|m| {
                    let n: f32 = at_least.parse().unwrap();
                    m >= n - 0.005 && m <= n + 0.25
                }),
                None => number(miles, 0.0051),
            }
        }
        "altim_in_hg" => match report.altimeter_hpa {
            None => service == "0.00",
            Some(hpa) => number(Some(hpa / 33.863_89), 0.0101),
        },
        "wx_string" => {
            // The service writes one entry per phenomenon (`-SHRASN` as `-SHRA -SHSN`) in its
            // own order: compared as sorted lists of those entries.
            let mut ours: Vec<String> = Vec::new();
            for w in &report.weather {
                let whole = w.to_string();
                let prefix = &whole[..whole.len() - w.phenomena.concat().len()];
                if w.phenomena.is_empty() {
                    ours.push(whole.clone());
                }
                ours.extend(w.phenomena.iter().map(|p| format!("{prefix}{p}")));
            }
            let mut theirs: Vec<&str> = service.split_whitespace().collect();
            ours.sort();
            theirs.sort();
            ours == theirs
        }
        _ => unreachable!("{column}"),
    }
}

#[test]
fn every_bulk_report_decodes_and_its_layers_agree_with_the_service() {
    let rows = read_rows();
    assert_eq!(rows.len(), 4_909);
    let mut disagreements = Vec::new();
    let mut by_column: Vec<Vec<(&str, &str)>> = vec![Vec::new(); COLUMNS.len()];
    let (mut warnings, mut beyond_four) = (0, 0);
    for row in &rows {
        let report = decode(&row.raw).unwrap_or_else(|e| panic!("{}: {e}", row.raw));
        warnings += report.warnings.len();
        let (layers, vv) = as_service(&report);
        // The service has four layer columns; the layers past them are ours alone, and must
        // go on upwards.
        if layers.len() > 4 {
            beyond_four += 1;
            let bases: Vec<u32> = report.clouds.iter().filter_map(|c| c.base_ft).collect();
            assert!(bases.is_sorted(), "{}: {bases:?}", row.raw);
        }
        if layers[..layers.len().min(4)] != row.layers[..] || vv != row.vert_vis_ft {
            disagreements.push(row.raw.as_str());
        }
        for (k, column) in COLUMNS.iter().enumerate() {
            if !agrees(&report, column, &row.columns[k]) {
                by_column[k].push((row.raw.as_str(), row.columns[k].as_str()));
            }
        }
    }
    // The other columns, and the stations where they disagree, each for a reason of the
    // report's or the service's.
    let stations = |k: usize| -> Vec<&str> {
        by_column[k]
            .iter()
            .map(|(raw, _)| raw.split(' ').next().unwrap())
            .collect()
    };
    let expected: [(&str, &[&str]); 8] = [
        // The body says 22, its T group 22.7: the station rounded wrongly.
        ("temp_c", &["PHNG"]),
        // Body and T group a degree apart (M02 and -3.0, M07 and -7.7); `22/2` is not a
        // dewpoint to the service.
        ("dewpoint_c", &["KEVU", "KASW", "DNKA"]),
        // The service writes 000 with a speed as VRB; groups run together or mistyped
        // (`272200Z32004KT`, `E18020KT`, `00000[T`) are warnings to us, guesses to it.
        (
            "wind_dir_degrees",
            &["VOGA", "MGTU", "CWME", "KP69", "MMZC", "MMGA"],
        ),
        // `///01KT`: we keep the speed of a wind without a direction; the rest as above.
        (
            "wind_speed_kt",
            &["SVGU", "SVBI", "MGTU", "KP69", "MMZC", "MMGA"],
        ),
        ("wind_gust_kt", &[]),
        // `9999NDV` (no directional variation): the service leaves the visibility out.
        (
            "visibility_statute_mi",
            &[
                "LSZL", "LSME", "LSMD", "LSMA", "BGSF", "BGKK", "BGBW", "SKPV", "LSMP", "LSMM",
                "ENWV", "ENUG", "ENML", "ENLA", "ENFL", "ENDR",
            ],
        ),
        // Both A2999 and Q1015: the service takes the Q group.
        ("altim_in_hg", &["OTBH"]),
        // The service counts recent weather (`RERA`, `REFZRA`) and words after the body
        // (`TCURA`, `VCSH-NE`, `STA MARIA` as SA, `PKWND 12KTS` as TS) as present weather, and
        // drops the intensity of `-UP`; in `-RABR` it gives the intensity to RA only, we to
        // both.
        (
            "wx_string",
            &[
                "CYRQ", "ESOW", "EFJO", "TTPP", "MYNN", "MNPC", "MGRT", "KJQF", "ENBS",
            ],
        ),
    ];
    for (k, (column, disagree)) in expected.iter().enumerate() {
        assert_eq!(COLUMNS[k], *column);
        assert_eq!(stations(k), *disagree, "{column}: {:?}", by_column[k]);
    }
    // Reports with more than the service's four layers: every layer kept, in order upwards.
    assert_eq!(beyond_four, 2);
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

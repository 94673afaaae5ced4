//! `skycast metar` run as a user runs it: the JSON form exactly, standard input, the error line.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn skycast(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_skycast"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the skycast binary starts");
    let mut pipe = child.stdin.take().expect("stdin is piped");
    pipe.write_all(stdin.unwrap_or("").as_bytes())
        .expect("stdin takes the input");
    drop(pipe);
    child.wait_with_output().expect("skycast finishes")
}

fn stdout_lines(output: &Output) -> Vec<String> {
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

const KIKT: &str = "KIKT 272225Z AUTO VRB04KT 10SM SCT028 BKN033 OVC050 22/12 A3011 RMK A01";
const KIKT_JSON: &str = r#"{"station":"KIKT","time":"272225Z","auto":true,"wind":{"dir_deg":null,"variable":true,"speed_kt":4.0,"gust_kt":null,"var_from":null,"var_to":null},"visibility_m":16093.44,"cavok":false,"sky":null,"clouds":[{"cover":"SCT","base_ft":2800,"kind":null},{"cover":"BKN","base_ft":3300,"kind":null},{"cover":"OVC","base_ft":5000,"kind":null}],"weather":[],"temperature_c":22.0,"dewpoint_c":12.0,"altimeter_hpa":1019.642,"warnings":[]}"#;

const EGAC: &str =
    "EGAC 272220Z AUTO 25019G31KT 240V290 4200 RA FEW007/// OVC042/// //////CB 08/07 Q0969";
const EGAC_JSON: &str = r#"{"station":"EGAC","time":"272220Z","auto":true,"wind":{"dir_deg":250,"variable":true,"speed_kt":19.0,"gust_kt":31.0,"var_from":240,"var_to":290},"visibility_m":4200.0,"cavok":false,"sky":null,"clouds":[{"cover":"FEW","base_ft":700,"kind":null},{"cover":"OVC","base_ft":4200,"kind":null},{"cover":null,"base_ft":null,"kind":"CB"}],"weather":["RA"],"temperature_c":8.0,"dewpoint_c":7.0,"altimeter_hpa":969.0,"warnings":[]}"#;

const UWOO: &str = "UWOO 272223Z 15002MPS 0200 0150E R26/0550N FZFG VV001 M03/M03 Q1025 NOSIG";
const UWOO_JSON: &str = r#"{"station":"UWOO","time":"272223Z","auto":false,"wind":{"dir_deg":150,"variable":false,"speed_kt":3.887688,"gust_kt":null,"var_from":null,"var_to":null},"visibility_m":200.0,"cavok":false,"sky":null,"clouds":[{"cover":"VV","base_ft":100,"kind":null}],"weather":["FZFG"],"temperature_c":-3.0,"dewpoint_c":-3.0,"altimeter_hpa":1025.0,"warnings":[]}"#;

const SGES: &str = "SGES 272200Z 12006KT 9999 SCT030 FEW040TCUBKN070 27/25 Q1009";
const SGES_JSON: &str = r#"{"station":"SGES","time":"272200Z","auto":false,"wind":{"dir_deg":120,"variable":false,"speed_kt":6.0,"gust_kt":null,"var_from":null,"var_to":null},"visibility_m":10000.0,"cavok":false,"sky":null,"clouds":[{"cover":"SCT","base_ft":3000,"kind":null}],"weather":[],"temperature_c":27.0,"dewpoint_c":25.0,"altimeter_hpa":1009.0,"warnings":["`FEW040TCUBKN070`: cloud type is not CB, TCU or ///"]}"#;

const OPLA: &str = "OPLA 272225Z 33006KT 4000 FU NSC 11/06 Q1011 NOSIG RMK QFE986 A29.88";
const OPLA_JSON: &str = r#"{"station":"OPLA","time":"272225Z","auto":false,"wind":{"dir_deg":330,"variable":false,"speed_kt":6.0,"gust_kt":null,"var_from":null,"var_to":null},"visibility_m":4000.0,"cavok":false,"sky":"NSC","clouds":[],"weather":["FU"],"temperature_c":11.0,"dewpoint_c":6.0,"altimeter_hpa":1011.0,"warnings":[]}"#;

#[test]
fn json_from_arguments_one_object_a_line_in_order() {
    let output = skycast(&["metar", "--json", KIKT, EGAC, UWOO, SGES, OPLA], None);
    assert!(output.status.success(), "{output:?}");
    assert_eq!(
        stdout_lines(&output),
        [KIKT_JSON, EGAC_JSON, UWOO_JSON, SGES_JSON, OPLA_JSON]
    );
}

#[test]
fn json_from_standard_input_with_an_error_line() {
    let input = format!("{KIKT}\nnot a metar\n\n{OPLA}\n");
    let output = skycast(&["metar", "--json", "-"], Some(&input));
    assert_eq!(
        stdout_lines(&output),
        [
            KIKT_JSON,
            r#"{"error":"`not a metar`: no station identifier: `not` is not four letters or digits"}"#,
            OPLA_JSON,
        ]
    );
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&output.stderr).trim(),
        "skycast: error: 1 of 3 reports could not be decoded"
    );
}

#[test]
fn readable_summary() {
    let output = skycast(&["metar", EGAC], None);
    assert!(output.status.success(), "{output:?}");
    let text = String::from_utf8_lossy(&output.stdout);
    for expected in [
        "EGAC  day 27 22:20 UTC  automatic",
        "  wind        250 deg at 19 kt gusting 31 kt, varying 240-290 deg",
        "  visibility  4200 m",
        "  weather     RA",
        "  sky         FEW 700 ft, OVC 4200 ft, CB (cover and base not reported)",
        "  temperature 8 C, dewpoint 7 C",
        "  altimeter   969.0 hPa",
    ] {
        assert!(
            text.lines().any(|l| l == expected),
            "missing {expected:?} in\n{text}"
        );
    }
}

#[test]
fn no_report_is_a_usage_error() {
    let output = skycast(&["metar"], None);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("REPORT"));
}

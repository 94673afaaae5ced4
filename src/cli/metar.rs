//! `skycast metar [--json] REPORT...`: decodes METAR/SPECI reports given as arguments, or one a
//! line from standard input when the only argument is `-`.
//!
//! With `--json` each report prints as exactly one JSON object a line, in input order; a report
//! that cannot be decoded at all prints `{"error":"..."}` and the rest go on. `wind` is always an
//! object (every field null, `variable` false, when the report has no wind group); other unknown
//! values are null. Without `--json` each report prints as a short readable summary. The exit
//! status is 2 when any report could not be decoded, after all of them are printed.

use std::io::{BufRead, Write};

use anyhow::{Context, bail};
use serde::Serialize;
use skycast::weather::metar::{CloudGroup, Report, SkyCode, WindGroup, decode};

/// Flags of `skycast metar`.
#[derive(Debug, clap::Args)]
pub struct MetarArgs {
    /// One JSON object a line instead of a readable summary.
    #[arg(long)]
    json: bool,
    /// Reports to decode, each one argument (quote it); `-` alone reads one report a line from
    /// standard input.
    #[arg(required = true, value_name = "REPORT")]
    reports: Vec<String>,
}

/// The JSON form of a report; field names are the command's documented interface.
#[derive(Debug, Serialize)]
struct JsonReport<'a> {
    station: &'a str,
    time: Option<String>,
    auto: bool,
    wind: WindGroup,
    visibility_m: Option<f32>,
    cavok: bool,
    sky: Option<SkyCode>,
    clouds: &'a [CloudGroup],
    weather: Vec<String>,
    temperature_c: Option<f32>,
    dewpoint_c: Option<f32>,
    altimeter_hpa: Option<f32>,
    warnings: &'a [String],
}

impl<'a> From<&'a Report> for JsonReport<'a> {
    fn from(r: &'a Report) -> Self {
        JsonReport {
            station: &r.station,
            time: r.time.map(|t| t.to_string()),
            auto: r.auto,
            wind: r.wind.unwrap_or_default(),
            visibility_m: r.visibility_m,
            cavok: r.cavok,
            sky: r.sky,
            clouds: &r.clouds,
            weather: r.weather.iter().map(ToString::to_string).collect(),
            temperature_c: r.temperature_c,
            dewpoint_c: r.dewpoint_c,
            altimeter_hpa: r.altimeter_hpa,
            warnings: &r.warnings,
        }
    }
}

/// Runs `skycast metar`.
pub fn run(args: &MetarArgs) -> anyhow::Result<()> {
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let mut failed = 0usize;
    let mut total = 0usize;
    let mut one = |text: &str, out: &mut dyn Write| -> anyhow::Result<()> {
        total += 1;
        let result = decode(text);
        if result.is_err() {
            failed += 1;
        }
        print_one(text, result, args.json, out)
    };
    if args.reports.len() == 1 && args.reports[0] == "-" {
        let mut stdin = std::io::stdin().lock();
        let mut line = Vec::new();
        loop {
            line.clear();
            let n = stdin
                .read_until(b'\n', &mut line)
                .context("cannot read standard input")?;
            if n == 0 {
                break;
            }
            let text = String::from_utf8_lossy(&line);
            if !text.trim().is_empty() {
                one(&text, &mut out)?;
            }
        }
    } else {
        for text in &args.reports {
            one(text, &mut out)?;
        }
    }
    out.flush().context("cannot write standard output")?;
    if failed > 0 {
        bail!("{failed} of {total} reports could not be decoded");
    }
    Ok(())
}

/// Prints one report (or why it is not one) in the chosen form.
fn print_one(
    text: &str,
    result: Result<Report, skycast::weather::metar::MetarError>,
    json: bool,
    out: &mut dyn Write,
) -> anyhow::Result<()> {
    let written = match (result, json) {
        (Ok(report), true) => {
            let line = serde_json::to_string(&JsonReport::from(&report))?;
            writeln!(out, "{line}")
        }
        (Err(err), true) => {
            let line = serde_json::json!({ "error": format!("`{}`: {err}", text.trim()) });
            writeln!(out, "{line}")
        }
        (Ok(report), false) => write!(out, "{}", summary(&report)),
        (Err(err), false) => writeln!(out, "cannot decode `{}`: {err}\n", text.trim()),
    };
    written.context("cannot write standard output")
}

/// A readable multi-line summary of a report, ending with a blank line.
fn summary(r: &Report) -> String {
    let mut s = r.station.clone();
    if let Some(t) = r.time {
        s += &format!("  day {} {:02}:{:02} UTC", t.day, t.hour, t.minute);
    }
    if r.auto {
        s += "  automatic";
    }
    if r.corrected {
        s += "  corrected";
    }
    s.push('\n');
    let mut field = |name: &str, value: String| s += &format!("  {name:<12}{value}\n");
    if r.sky == Some(SkyCode::Nil) {
        field("report", "NIL (missing)".into());
    }
    if let Some(w) = r.wind {
        field("wind", wind_text(&w));
    }
    if r.cavok {
        field(
            "visibility",
            "CAVOK (10 km or more, no cloud below 5,000 ft)".into(),
        );
    } else if let Some(v) = r.visibility_m {
        field("visibility", format!("{v:.0} m"));
    }
    if !r.weather.is_empty() {
        let groups: Vec<String> = r.weather.iter().map(ToString::to_string).collect();
        field("weather", groups.join(" "));
    }
    let mut sky: Vec<String> = r.clouds.iter().map(cloud_text).collect();
    if let Some(code) = r.sky.filter(|c| *c != SkyCode::Nil) {
        sky.insert(0, code.code().to_string());
    }
    if !sky.is_empty() {
        field("sky", sky.join(", "));
    }
    let temp = |t: Option<f32>| t.map_or("?".to_string(), |t| format!("{t:.0} C"));
    if r.temperature_c.is_some() || r.dewpoint_c.is_some() {
        let value = format!("{}, dewpoint {}", temp(r.temperature_c), temp(r.dewpoint_c));
        field("temperature", value);
    }
    if let Some(a) = r.altimeter_hpa {
        field("altimeter", format!("{a:.1} hPa"));
    }
    if !r.remarks.is_empty() {
        field("remarks", r.remarks.clone());
    }
    for w in &r.warnings {
        field("warning", w.clone());
    }
    s.push('\n');
    s
}

/// `VRB at 4 kt`, `330 deg at 19 kt gusting 31 kt, varying 290-360 deg`.
fn wind_text(w: &WindGroup) -> String {
    let kt = |v: Option<f32>| v.map_or("? kt".to_string(), |v| format!("{v:.0} kt"));
    let mut s = match (w.dir_deg, w.speed_kt) {
        (_, Some(0.0)) => "calm".to_string(),
        (Some(dir), speed) => format!("{dir:03} deg at {}", kt(speed)),
        (None, speed) if w.variable => format!("variable at {}", kt(speed)),
        (None, speed) => format!("direction unknown at {}", kt(speed)),
    };
    if w.gust_kt.is_some() {
        s += &format!(" gusting {}", kt(w.gust_kt));
    }
    if let (Some(from), Some(to)) = (w.var_from, w.var_to) {
        s += &format!(", varying {from:03}-{to:03} deg");
    }
    s
}

/// `BKN 3300 ft CB`, `VV 100 ft`, `FEW base unknown`, `CB (cover and base not reported)`.
fn cloud_text(c: &CloudGroup) -> String {
    let kind = c.kind.map_or(String::new(), |k| format!(" {}", k.code()));
    match (c.cover, c.base_ft) {
        (None, None) if c.kind.is_some() => format!("{} (cover and base not reported)", &kind[1..]),
        (cover, base) => format!(
            "{} {}{kind}",
            cover.map_or("cover unknown", |c| c.code()),
            base.map_or("base unknown".to_string(), |b| format!("{b} ft")),
        ),
    }
}

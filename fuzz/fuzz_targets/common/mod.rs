//! The fuzz targets' checks, one function per target, shared with `tests/weather/fuzz_seeds.rs`,
//! which replays every seed of `fuzz/seeds/` through them under `cargo test` (the targets
//! themselves need cargo-fuzz and a nightly compiler, so `make test` does not run them).
// Each fuzz target uses one of these; the seed replay uses them all.
#![allow(dead_code)]

use std::path::Path;
use std::sync::OnceLock;

use skycast::clouds::{CloudTypes, CloudsConfig};
use skycast::config::TomlSettings;
use skycast::flight::FlightPlan;
use skycast::render::RenderSettings;
use skycast::shading::{FogSettings, TimeOfDayTable};
use skycast::weather::air::AirSettings;
use skycast::weather::files;
use skycast::weather::metar::decode;
use skycast::weather::model::ModelSettings;
use skycast::weather::storms::StormSettings;
use skycast::weather::{
    BlockIndex, CloudTypeRule, FieldSettings, LocalFrame, StationTable, WeatherField,
};

/// What `weather_csv` puts before its bytes: an aviation weather service `metars.cache.csv`
/// preamble and header.
pub const CSV_HEADER: &str = "No errors\nNo warnings\n1 ms\ndata source=metars\n1 results\n\
raw_text,station_id,observation_time,latitude,longitude,elevation_m\n";

/// What `weather_cycle` puts before its bytes: a NOAA cycle file's date line.
pub const CYCLE_DATE: &str = "2025/01/27 22:00\n";

/// `metar_decode`: any bytes through the METAR decoder: it must never panic, and what it
/// returns must hold together (a four-character station, finite non-negative quantities, every
/// weather group written back as text that decodes to the same group).
pub fn check_metar(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(report) = decode(&text) else {
        return;
    };
    assert_eq!(report.station.len(), 4);
    for value in [report.visibility_m, report.altimeter_hpa]
        .into_iter()
        .flatten()
    {
        assert!(value.is_finite() && value >= 0.0, "{value}");
    }
    if let Some(wind) = report.wind {
        for speed in [wind.speed_kt, wind.gust_kt].into_iter().flatten() {
            assert!(speed.is_finite() && speed >= 0.0, "{speed}");
        }
        assert!(wind.dir_deg.is_none_or(|d| d <= 360));
    }
    for weather in &report.weather {
        let again = decode(&format!("XXXX {weather}")).expect("a station decodes");
        assert_eq!(again.weather.first(), Some(weather), "{weather}");
    }
    if let Some(time) = report.time {
        assert!((1..=31).contains(&time.day) && time.hour <= 24 && time.minute <= 59);
    }
}

/// `station_table`: any bytes as a NOAA `nsd_cccc.txt` station table: no panic; every station
/// read has a 4-character id and a position on Earth; every skipped row names a line of the file.
pub fn check_station_table(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let lines = text.lines().count();
    let Ok(table) = StationTable::parse(Path::new("fuzz.txt"), &text) else {
        return;
    };
    assert!(!table.is_empty());
    for w in &table.skipped {
        assert!(w.line >= 1 && w.line <= lines, "{w}");
    }
    for line in text.lines() {
        let id = line.split(';').next().unwrap_or("").trim();
        if let Some(s) = table.get(id) {
            assert_eq!(s.id.len(), 4);
            assert!(s.latitude_deg.abs() <= 90.0 && s.longitude_deg.abs() <= 180.0);
            assert!(s.elevation_m.is_none_or(f64::is_finite));
        }
    }
}

/// Three real rows of weather/nsd_cccc.txt and one at the pole.
const STATIONS: &str = "EGLL;03;772;London / Heathrow Airport;;United Kingdom;6;51-28N;000-27W;51-29N;000-27W;24;24;P\r\n\
KJFK;74;486;New York;NY;United States;4;40-38N;073-46W;;;9;;\r\n\
LFBT;07;621;Tarbes / Ossun;;France;6;43-11N;000-00W;;;360;;\r\n\
NZSP;89;009;South Pole;;Antarctica;7;90-00S;000-00E;;;2835;;\r\n";

fn stations() -> &'static StationTable {
    static TABLE: OnceLock<StationTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        StationTable::parse(Path::new("stations.txt"), STATIONS).expect("the fuzz station table")
    })
}

/// `weather_file` (and, behind their prefixes, `weather_csv` and `weather_cycle`): any bytes as
/// a weather file (format detected from the content), placed with a small station table, then a
/// weather field built from whatever was placed and queried: no panic, every placed report has a
/// line inside the file and a position on Earth, every block has finite weather.
pub fn check_weather_file(data: &[u8]) {
    let lines = data.split(|&b| b == b'\n').count();
    let Ok(file) = files::parse(Path::new("fuzz.txt"), data, Some(stations())) else {
        return;
    };
    assert!(file.reports.len() <= file.reports_found);
    for p in &file.reports {
        assert!(p.line >= 1 && p.line <= lines, "line {} of {lines}", p.line);
        assert!(p.position.latitude_deg.abs() <= 90.0);
        assert!(p.position.longitude_deg.abs() <= 180.0);
    }
    for w in &file.warnings {
        assert!(w.line >= 1 && w.line <= lines, "{w}");
    }
    let Some(first) = file.reports.first() else {
        return;
    };
    let frame = LocalFrame::new(first.position.latitude_deg, first.position.longitude_deg);
    let field = WeatherField::build(
        frame,
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    for block in [
        BlockIndex::new(0, 0),
        BlockIndex::new(-3, 7),
        BlockIndex::new(500, -500),
    ] {
        let w = field.block_weather(block);
        for v in [
            w.visibility_m,
            w.temperature_c,
            w.dewpoint_c,
            w.precipitation,
            w.ground_elevation_m,
        ] {
            assert!(v.is_finite(), "{w:?}");
        }
        assert!(w.wind.speed_kt.is_finite() && w.wind.from_deg.is_finite());
        for l in &w.layers {
            assert!((0.0..=8.0).contains(&l.coverage_oktas), "{l:?}");
            assert!(
                l.base_ft_agl.is_finite() && l.thickness_ft.is_finite(),
                "{l:?}"
            );
        }
    }
}

/// `config_files`: any bytes as each TOML config file skycast reads (renderer, time of day,
/// clouds, cloud types, weather field, cloud-type rule, fog, air, storms, weather model, themes):
/// no panic; a rejected file's error names the file, and a line within the text where it names
/// one.
pub fn check_config_files(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let lines = text.lines().count().max(1);
    let path = Path::new("fuzz.toml");
    let check = |message: String| {
        assert!(message.contains("fuzz.toml"), "{message}");
        if let Some(rest) = message.strip_prefix("fuzz.toml:")
            && let Some(line) = rest.split(':').next().and_then(|l| l.parse::<usize>().ok())
        {
            assert!(line >= 1 && line <= lines, "{message}");
        }
    };
    if let Err(e) = RenderSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = TimeOfDayTable::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = CloudsConfig::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = CloudTypes::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = FieldSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = CloudTypeRule::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = FogSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = AirSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = StormSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = ModelSettings::parse(&text, path) {
        check(e.to_string());
    }
    if let Err(e) = skycast::weather::theme::parse_theme(&text, path) {
        check(e.to_string());
    }
}

/// `flight_path`: any bytes as a flight path (`config/flights/*.toml`): no panic; a plan that
/// loads can be placed and sampled anywhere along it, giving finite poses; a rejected one's error
/// names the file.
pub fn check_flight_path(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let plan = match FlightPlan::parse(&text, Path::new("fuzz.toml")) {
        Ok(plan) => plan,
        Err(e) => {
            assert!(e.to_string().contains("fuzz.toml"), "{e}");
            return;
        }
    };
    let (lat, lon) = plan.origin_lat_lon_deg;
    let placed = plan.place(&LocalFrame::new(lat, lon));
    let (start, duration) = (placed.start_s(), placed.duration_s());
    for k in 0..=8 {
        let pose = placed.pose_at(start + duration * k as f64 / 8.0);
        assert!(pose.position_m.is_finite(), "{pose:?}");
        assert!(
            pose.heading_deg.is_finite() && pose.pitch_deg.is_finite(),
            "{pose:?}"
        );
    }
}

//! Shared by the weather-file targets: read, place, build a field, query it.

use std::path::Path;
use std::sync::OnceLock;

use skycast::weather::files;
use skycast::weather::{
    BlockIndex, CloudTypeRule, FieldSettings, LocalFrame, StationTable, WeatherField,
};

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

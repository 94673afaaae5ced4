//! Any bytes through the METAR decoder: it must never panic, and what it returns must hold
//! together (a four-character station, finite non-negative quantities, every weather group
//! written back as text that decodes to the same group).
#![no_main]

use libfuzzer_sys::fuzz_target;
use skycast::weather::metar::decode;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(report) = decode(&text) else {
        return;
    };
    assert_eq!(report.station.len(), 4);
    for value in [report.visibility_m, report.altimeter_hpa].into_iter().flatten() {
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
});

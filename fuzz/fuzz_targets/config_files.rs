//! Any bytes as each TOML config file skycast reads (renderer, time of day, clouds, cloud types,
//! weather field, cloud-type rule, fog, themes): no panic; a rejected file's error names the
//! file, and a line within the text where it names one.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use skycast::clouds::{CloudTypes, CloudsConfig};
use skycast::render::RenderSettings;
use skycast::shading::{FogSettings, TimeOfDayTable};
use skycast::weather::{CloudTypeRule, FieldSettings};

fuzz_target!(|data: &[u8]| {
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
    if let Err(e) = skycast::weather::theme::parse_theme(&text, path) {
        check(e.to_string());
    }
});

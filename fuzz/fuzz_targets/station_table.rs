//! Any bytes as a NOAA `nsd_cccc.txt` station table: no panic; every station read has a 4-character
//! id and a position on Earth; every skipped row names a line of the file.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use skycast::weather::StationTable;

fuzz_target!(|data: &[u8]| {
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
});

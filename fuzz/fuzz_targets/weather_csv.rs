//! Any bytes as the rows of an aviation weather service `metars.cache.csv` (preamble and header
//! prepended), through the same checks as `weather_file`.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut file = common::CSV_HEADER.as_bytes().to_vec();
    file.extend_from_slice(data);
    common::check_weather_file(&file);
});

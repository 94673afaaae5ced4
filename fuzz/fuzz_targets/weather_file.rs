//! Any bytes as a weather file (format detected from the content), placed with a small station
//! table, then a weather field built from whatever was placed and queried: no panic, every placed
//! report has a line inside the file and a position on Earth, every block has finite weather.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_weather_file(data));

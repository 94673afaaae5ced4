//! Any bytes as a flight path (`common::check_flight_path`).
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_flight_path(data));

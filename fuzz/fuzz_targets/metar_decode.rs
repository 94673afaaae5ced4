//! Any bytes through the METAR decoder (`common::check_metar`).
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_metar(data));

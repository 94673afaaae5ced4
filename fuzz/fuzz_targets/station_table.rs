//! Any bytes as a NOAA `nsd_cccc.txt` station table (`common::check_station_table`).
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_station_table(data));

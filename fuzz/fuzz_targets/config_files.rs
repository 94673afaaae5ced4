//! Any bytes as each TOML config file skycast reads (`common::check_config_files`).
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_config_files(data));

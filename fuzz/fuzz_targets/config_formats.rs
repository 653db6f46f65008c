#![no_main]
//! See `driftless_fuzz::config_formats` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::config_formats::run(data));

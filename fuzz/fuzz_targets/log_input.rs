#![no_main]
//! See `driftless_fuzz::log_input` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::log_input::run(data));

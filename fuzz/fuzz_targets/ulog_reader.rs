#![no_main]
//! See `driftless_fuzz::ulog_reader` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::ulog_reader::run(data));

#![no_main]
//! See `driftless_fuzz::text_reader` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::text_reader::run(data));

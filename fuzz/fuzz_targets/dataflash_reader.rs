#![no_main]
//! See `driftless_fuzz::dataflash_reader` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::dataflash_reader::run(data));

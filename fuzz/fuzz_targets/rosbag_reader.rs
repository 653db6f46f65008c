#![no_main]
//! See `driftless_fuzz::rosbag_reader` for the input and the invariants.

libfuzzer_sys::fuzz_target!(|data: &[u8]| driftless_fuzz::rosbag_reader::run(data));

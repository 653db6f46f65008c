//! The fuzz targets' bodies, one module per target, each a `run(data)` that panics when an
//! invariant breaks. `fuzz_targets/*.rs` hand them to libFuzzer (nightly, `cargo fuzz`);
//! `crates/driftless/tests/fuzz_replay.rs` includes this file and runs them on the seed
//! corpora in `corpus/<target>/` and on mutations of them, under stable `cargo test`.
//! Nothing here may depend on more than `driftless` and `std`.

pub mod binary_reader;
pub mod check;
pub mod config_formats;
pub mod dataflash_reader;
pub mod log_input;
pub mod nav_formats;
pub mod rosbag_reader;
pub mod text_reader;
pub mod ulog_reader;

/// A harness body: one input, a panic when an invariant breaks.
pub type Harness = fn(&[u8]);

/// Every target, by the name of its corpus folder and binary.
pub const TARGETS: [(&str, Harness); 8] = [
    ("binary_reader", binary_reader::run),
    ("config_formats", config_formats::run),
    ("dataflash_reader", dataflash_reader::run),
    ("log_input", log_input::run),
    ("nav_formats", nav_formats::run),
    ("rosbag_reader", rosbag_reader::run),
    ("text_reader", text_reader::run),
    ("ulog_reader", ulog_reader::run),
];

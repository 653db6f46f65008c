//! Noise-model file (TOML) written by `driftless allan` and read by the filter and simulator.
//!
//! OWNER: helper "fit".

//! Readers and writers. Readers turn files into typed, columnar [`log::ImuLog`]s and
//! never do math beyond unit conversion at the edge; algorithms never parse files.
//!
//! OWNER: helper "io" (text, binary, units, errors, fuzzing).

pub mod log;

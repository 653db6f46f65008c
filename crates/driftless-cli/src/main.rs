//! `driftless` command-line tool.
fn main() {}

//! Helpers shared by the CLI integration tests.
#![allow(dead_code)]

use std::process::Command;

/// The `driftless` binary under test.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_driftless"))
}

/// Runs `cmd`, which must succeed, and parses its `--json` output.
pub fn run_json(cmd: &mut Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

//! Helpers shared by the CLI integration tests.
#![allow(dead_code)]

use std::process::Command;

/// The `driftless` binary under test.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_driftless"))
}

/// Runs `driftless ARGS`, which must fail with nothing on stdout and no panic; returns its
/// stderr.
pub fn error_of(args: &[&std::ffi::OsStr]) -> String {
    let out = bin().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "expected failure: {stderr}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
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

/// Writes `scenario` to `dir/<name>.toml`, runs `driftless simulate` on it into
/// `dir/<name>` and returns that folder.
pub fn simulate(dir: &std::path::Path, name: &str, scenario: &str) -> std::path::PathBuf {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, scenario).unwrap();
    let out = dir.join(name);
    run_json(
        bin()
            .args(["simulate", "--json", "--out"])
            .arg(&out)
            .arg(&file),
    );
    out
}

/// A new, empty folder `driftless-TAG-PID` in the temporary folder.
pub fn scratch(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A KF-GINS configuration `cfg` (as `simulate` writes it, `endtime: -1`) cut to its first
/// `seconds` from `starttime`.
pub fn kf_gins_first_seconds(cfg: &str, seconds: f64) -> String {
    let start: f64 = cfg
        .lines()
        .find_map(|l| l.strip_prefix("starttime:"))
        .and_then(|v| v.split('#').next())
        .and_then(|v| v.trim().parse().ok())
        .unwrap();
    assert!(cfg.contains("endtime: -1"), "{cfg}");
    cfg.replace("endtime: -1", &format!("endtime: {}", start + seconds))
}

//! Progress on stderr shared by the commands: spinners, and reading a big log under one.

use crate::input::InputArgs;
use anyhow::Result;
use driftless::io::ImuLog;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::time::Duration;

/// A spinner on stderr (hidden when not a terminal, when `show` is false, or with
/// `--quiet`).
pub fn spinner(show: bool, msg: String) -> ProgressBar {
    if !show || crate::verbosity::quiet() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new_spinner();
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    pb.set_message(msg);
    pb.enable_steady_tick(Duration::from_millis(120));
    pb
}

/// Read a log, with a spinner for big files.
pub fn read_with_progress(input: &InputArgs, path: &Path, quiet: bool) -> Result<ImuLog> {
    let big = std::fs::metadata(path)
        .map(|m| m.len() > 50 << 20)
        .unwrap_or(false);
    let sp = spinner(big && !quiet, format!("reading {}", path.display()));
    let log = input.read(path)?;
    sp.finish_and_clear();
    Ok(log)
}

/// Warn about the time gaps of a log read from `file` (bridged, or analysed as separate
/// segments).
pub fn warn_gaps(file: &Path, log: &ImuLog) {
    for g in &log.gaps {
        eprintln!(
            "warning: {}: time gap of {:.3} s after t = {:.3} s (row {}) — {}",
            file.display(),
            g.duration_s,
            g.start_s,
            g.index + 1,
            if log.segments.len() > 1 {
                "analysed as separate segments"
            } else {
                "bridged"
            }
        );
    }
}

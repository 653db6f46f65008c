//! `driftless convert`: delimited text ↔ compact binary log; also PX4 ULog / ArduPilot
//! DataFlash (one IMU instance, `--instance N`) → CSV or binary.

use crate::input::InputArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input log (text, binary DRIFTLOG, PX4 ULog or ArduPilot DataFlash).
    pub input: PathBuf,
    /// Output: `.dlog` (binary DRIFTLOG) or `.csv`.
    pub output: PathBuf,
    #[command(flatten)]
    pub read: InputArgs,
}

pub fn run(a: ConvertArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(&[Some(&a.output)], &[Some(&a.input)])?;
    let log = crate::allan_cmd::read_with_progress(&a.read, &a.input, false)?;
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "csv" | "txt" => driftless::io::write_csv_file(&log, &a.output),
        _ => driftless::io::write_binary_file(&log, &a.output),
    }
    .with_context(|| format!("writing {}", a.output.display()))?;
    eprintln!(
        "{} → {}: {} channels × {} samples",
        a.input.display(),
        a.output.display(),
        log.channels.len(),
        log.len()
    );
    Ok(())
}

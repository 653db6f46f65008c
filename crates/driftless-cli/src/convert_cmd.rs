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
    /// Output: `.dlog` (binary DRIFTLOG) or `.csv` / `.txt` (delimited text).
    #[arg(value_parser = log_output_path)]
    pub output: PathBuf,
    #[command(flatten)]
    pub read: InputArgs,
}

/// The output formats by file-name ending.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LogFormat {
    Text,
    Binary,
}

fn log_format(p: &std::path::Path) -> Option<LogFormat> {
    let ext = p.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "csv" | "txt" => Some(LogFormat::Text),
        "dlog" => Some(LogFormat::Binary),
        _ => None,
    }
}

/// Output value parser: the name says the format, checked before the input is read.
fn log_output_path(s: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(s);
    match log_format(&p) {
        Some(_) => Ok(p),
        None => Err(format!(
            "{s}: the output format follows the name's ending: .dlog (binary DRIFTLOG) or \
             .csv / .txt (delimited text)"
        )),
    }
}

pub fn run(a: ConvertArgs) -> Result<()> {
    let format = log_format(&a.output).context("output name ends in neither .dlog nor .csv")?;
    crate::paths::refuse_outputs_over_inputs(&[Some(&a.output)], &[Some(&a.input)])?;
    let log = crate::allan_cmd::read_with_progress(&a.read, &a.input, false)?;
    match format {
        LogFormat::Text => driftless::io::write_csv_file(&log, &a.output),
        LogFormat::Binary => driftless::io::write_binary_file(&log, &a.output),
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

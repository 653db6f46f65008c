//! `driftless convert`: delimited text ↔ compact binary log; also PX4 ULog / ArduPilot
//! DataFlash (one IMU instance, `--instance N`) → CSV or binary.

use crate::input::InputArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input log (text, binary DRIFTLOG, PX4 ULog, ArduPilot DataFlash, ROS bag or MCAP file).
    pub input: PathBuf,
    /// Output: `.dlog` (binary DRIFTLOG) or `.csv` / `.txt` (delimited text); another
    /// name (a device, a pipe) needs `--to`.
    pub output: PathBuf,
    /// Output format, instead of the name's ending.
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub to: Option<LogFormat>,
    #[command(flatten)]
    pub read: InputArgs,
}

/// The output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    /// Delimited text (CSV).
    #[value(name = "csv")]
    Text,
    /// Binary DRIFTLOG.
    #[value(name = "dlog")]
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

pub fn run(a: ConvertArgs) -> Result<()> {
    let Some(format) = a.to.or_else(|| log_format(&a.output)) else {
        anyhow::bail!(
            "{}: the output format follows the name's ending, .dlog (binary DRIFTLOG) or \
             .csv / .txt (delimited text); for another name give --to csv|dlog",
            a.output.display()
        );
    };
    crate::paths::refuse_outputs_over_inputs(&[Some(&a.output)], &[Some(&a.input)])?;
    let log = crate::progress::read_with_progress(&a.read, &a.input, false)?;
    match format {
        LogFormat::Text => driftless::io::write_csv_file(&log, &a.output),
        LogFormat::Binary => driftless::io::write_binary_file(&log, &a.output),
    }
    .with_context(|| format!("writing {}", a.output.display()))?;
    note!(
        "{} → {}: {} channels × {} samples",
        a.input.display(),
        a.output.display(),
        log.channels.len(),
        log.len()
    );
    Ok(())
}

//! Command-line options shared by every command that reads an IMU log.

use anyhow::Result;
use clap::Args;
use driftless::io::{
    ColumnSpec, Delimiter, GapPolicy, HeaderMode, ImuLog, TextOptions, TimeUnit, Unit,
    read_log_file,
};
use std::path::Path;

/// How to read a delimited text log (ignored for binary `DRIFTLOG` files).
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Sample rate in Hz (required when the file has no time column).
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
    /// Time column, by 1-based number or header name; omit for logs without time stamps.
    #[arg(long, value_name = "COL")]
    pub time_column: Option<String>,
    /// Unit of the time column: s, ms, us, ns.
    #[arg(long, value_name = "UNIT")]
    pub time_unit: Option<String>,
    /// Data column to keep, repeatable: COLUMN[:UNIT][=NAME], e.g. `gyro_x:deg/s`,
    /// `3:counts-32768*0.00875deg/s=gx`. Default: every column except time.
    #[arg(long = "column", value_name = "SPEC")]
    pub columns: Vec<String>,
    /// Unit of every data column without its own (rad/s, deg/s, deg/h, m/s^2, g, mg, ug,
    /// counts*K…; default: the header's bracketed unit, else unitless).
    #[arg(long, value_name = "UNIT")]
    pub unit: Option<String>,
    /// Comma-separated channel names (one per field of the file).
    #[arg(long, value_name = "A,B,…")]
    pub names: Option<String>,
    /// Field separator: auto, comma, semicolon, tab, whitespace.
    #[arg(long, default_value = "auto")]
    pub delimiter: String,
    /// Header row: auto, yes, no.
    #[arg(long, default_value = "auto")]
    pub header: String,
    /// Time gaps (interval > gap-factor × τ0): error, split (analyse the pieces, no term
    /// straddles a gap) or bridge (treat the data as contiguous).
    #[arg(long, default_value = "error")]
    pub gaps: String,
    /// An interval longer than this many nominal sample intervals is a gap.
    #[arg(long, default_value_t = 1.5)]
    pub gap_factor: f64,
}

impl InputArgs {
    /// Reader options from the flags.
    pub fn text_options(&self) -> Result<TextOptions> {
        let mut o = TextOptions {
            delimiter: self.delimiter.parse::<Delimiter>()?,
            header: match self.header.to_ascii_lowercase().as_str() {
                "auto" => HeaderMode::Auto,
                "yes" | "present" | "true" => HeaderMode::Present,
                "no" | "absent" | "false" => HeaderMode::Absent,
                other => anyhow::bail!("--header {other:?}: expected auto, yes or no"),
            },
            gap_policy: self.gaps.parse::<GapPolicy>()?,
            gap_factor: self.gap_factor,
            rate_hz: self.rate,
            ..TextOptions::default()
        };
        if let Some(r) = self.rate
            && !(r.is_finite() && r > 0.0)
        {
            anyhow::bail!("--rate must be a positive number of Hz, got {r}");
        }
        if let Some(t) = &self.time_column {
            o.time_column = Some(t.parse()?);
            o.time_unit = match &self.time_unit {
                Some(u) => Some(parse_time_unit(u)?),
                None => None,
            };
        }
        for c in &self.columns {
            o.columns.push(c.parse::<ColumnSpec>()?);
        }
        if let Some(u) = &self.unit {
            o.default_unit = Some(Unit::parse(u)?);
        }
        if let Some(n) = &self.names {
            o.column_names = Some(n.split(',').map(|s| s.trim().to_string()).collect());
        }
        Ok(o)
    }

    /// Read the log at `path`, text or binary.
    pub fn read(&self, path: &Path) -> Result<ImuLog> {
        let opts = self.text_options()?;
        let log = read_log_file(path, &opts)?;
        if log.is_empty() {
            anyhow::bail!("{}: no data rows", path.display());
        }
        Ok(log)
    }
}

fn parse_time_unit(s: &str) -> Result<TimeUnit> {
    Ok(match s.to_ascii_lowercase().as_str() {
        "s" => TimeUnit::Seconds,
        "ms" => TimeUnit::Milliseconds,
        "us" | "µs" => TimeUnit::Microseconds,
        "ns" => TimeUnit::Nanoseconds,
        other => anyhow::bail!("--time-unit {other:?}: expected s, ms, us or ns"),
    })
}

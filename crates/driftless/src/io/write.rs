//! CSV writer for [`ImuLog`]s (used by the simulator and demos to emit logs).
//!
//! Output: `#` comment lines with the source, τ0 and row count, then a header naming each
//! column with its SI unit in brackets (`time [s]`, `gyro_x [rad/s]`, `temp [degC]`; no
//! bracket for unitless channels), then one row per sample in SI, then the comment
//! `# end of driftless log`. The reader checks the row count and that last line, so a file
//! cut at a line end (an interrupted write) is an error, not a shorter log. Numbers use Rust's
//! shortest round-trip formatting, so [`super::read_text`] reads the file back bit for bit
//! (the header units are picked up automatically; pass `time_column = Name("time")`).

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use super::binary::check_log;
use super::error::{Location, LogError};
use super::log::ImuLog;

/// Writes `log` as CSV to a file.
pub fn write_csv_file(log: &ImuLog, path: impl AsRef<Path>) -> Result<(), LogError> {
    let (mut file, name) = super::error::create_file(path.as_ref())?;
    write_impl(log, &mut file, &name)?;
    super::error::commit_file(file, &name)
}

/// Writes `log` as CSV to any writer (errors name the output `<output>`).
pub fn write_csv<W: Write>(log: &ImuLog, writer: W) -> Result<(), LogError> {
    write_impl(log, writer, "<output>")
}

/// How a CSV written by driftless starts. Its second line states `rows: N` and the last
/// line, [`END_MARK`]; the reader checks both, so a file cut at a line end is an error and
/// not a shorter log.
pub(crate) const HEADER_MARK: &str = "# driftless log";
/// The last line of a CSV written by driftless.
pub(crate) const END_MARK: &str = "# end of driftless log";

fn push_number(s: &mut String, v: f64) {
    let a = v.abs();
    // Both forms are shortest round-trip; plain decimals are easier to read in range.
    let _ = if v == 0.0 || (1e-5..1e16).contains(&a) {
        write!(s, "{v}")
    } else {
        write!(s, "{v:e}")
    };
}

fn write_impl<W: Write>(log: &ImuLog, w: W, dest: &str) -> Result<(), LogError> {
    check_log(log, dest)?;
    let io = |error| LogError::Io {
        path: dest.to_owned(),
        error,
    };
    for c in &log.channels {
        if c.name.is_empty() || c.name.contains([',', '#', '[', ']', '\n', '\r']) {
            return Err(LogError::InvalidLog {
                at: Location::input(dest),
                message: format!(
                    "channel name {:?} cannot be written as a CSV header",
                    c.name
                ),
            });
        }
    }
    let mut w = std::io::BufWriter::with_capacity(1 << 20, w);
    let clean = |s: &str| s.replace(['\n', '\r'], " ");
    let mut head = String::new();
    let _ = writeln!(head, "{HEADER_MARK}; source: {}", clean(&log.source));
    let _ = writeln!(
        head,
        "# tau0_s: {}; rows: {}; last line: {END_MARK}",
        log.tau0_s,
        log.len()
    );
    let mut cols: Vec<String> = Vec::new();
    if log.time_s.is_some() {
        cols.push("time [s]".into());
    }
    for c in &log.channels {
        let unit = c.quantity.si_unit();
        cols.push(if unit.is_empty() {
            c.name.clone()
        } else {
            format!("{} [{unit}]", c.name)
        });
    }
    head.push_str(&cols.join(","));
    head.push('\n');
    w.write_all(head.as_bytes()).map_err(io)?;
    let mut line = String::with_capacity(256);
    for i in 0..log.len() {
        line.clear();
        let mut first = true;
        let values = log
            .time_s
            .iter()
            .map(|t| t[i])
            .chain(log.channels.iter().map(|c| c.values[i]));
        for v in values {
            if !first {
                line.push(',');
            }
            first = false;
            push_number(&mut line, v);
        }
        line.push('\n');
        w.write_all(line.as_bytes()).map_err(io)?;
    }
    writeln!(w, "{END_MARK}").map_err(io)?;
    w.flush().map_err(io)
}

//! Command-line options shared by every command that reads an IMU log.

use anyhow::Result;
use clap::Args;
use driftless::io::{
    ColumnSpec, Delimiter, GapPolicy, HeaderMode, ImuLog, LogInput, TextOptions, TimeUnit, Unit,
};
use std::path::Path;

/// How to read a delimited text log (ignored for binary `DRIFTLOG` files and for autopilot
/// logs, which are recognised by their magic bytes whatever their extension).
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// IMU instance to take from a PX4 ULog (`.ulg`) or ArduPilot DataFlash (`.bin`) log.
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = crate::numbers::whole::<u8>, allow_hyphen_values = true)]
    pub instance: u8,
    /// `sensor_msgs/Imu` topic to take from a ROS 1 bag (`.bag`; bz2/lz4 chunks too), a ROS 2
    /// MCAP (`.mcap`; zstd/lz4 chunks too) or sqlite3 (`.db3`) file, or a ROS 2 bag folder
    /// (metadata.yaml; split bags read in order) (default: the bag's only IMU topic).
    #[arg(long, value_name = "TOPIC")]
    pub topic: Option<String>,
    /// Sample rate in Hz (required when the file has no time column).
    #[arg(long, value_name = "HZ", value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub rate: Option<f64>,
    /// Time column, by 1-based number or header name. Omitted: a header field named t,
    /// time, timestamp, time_s, stamp, sec, seconds, gps_time, gpst or time_stamp (any case,
    /// unit in brackets) is the time; `none` reads such a field as data.
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
    /// An interval longer than this many nominal sample intervals is a gap (> 1).
    #[arg(long, default_value_t = 1.5, value_parser = crate::numbers::above_one, allow_hyphen_values = true)]
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
        if self
            .time_column
            .as_deref()
            .is_some_and(|t| t.eq_ignore_ascii_case("none"))
        {
            o.detect_time_column = false;
        } else if let Some(t) = &self.time_column {
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

    /// Read the log at `path`: text, binary `DRIFTLOG`, or (feature `autopilot-logs`) one
    /// IMU instance of a PX4 ULog / ArduPilot DataFlash log, chosen by the file's magic bytes.
    /// The file is opened once and sniffed on the handle that is then read, so a pipe or
    /// FIFO gives the same log as a regular file.
    pub fn read(&self, path: &Path) -> Result<ImuLog> {
        self.read_input(LogInput::open(path)?)
    }

    /// [`Self::read`] of an input already opened.
    pub fn read_input(&self, input: LogInput) -> Result<ImuLog> {
        #[cfg(feature = "autopilot-logs")]
        if input.is_autopilot() {
            return read_autopilot(input, self.instance);
        }
        let path = std::path::PathBuf::from(input.name());
        let log = if input.is_rosbag() {
            input.read_rosbag(self.topic.as_deref())?
        } else {
            if let Some(t) = &self.topic {
                anyhow::bail!(
                    "{}: --topic {t} is for ROS bags (.bag, .mcap, .db3); this input is not one",
                    path.display()
                );
            }
            input.read_log(&self.text_options()?)?
        };
        if log.is_empty() {
            anyhow::bail!("{}: no data rows", path.display());
        }
        for n in &log.notes {
            note!("note: {n}");
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

/// Reads one IMU instance of an autopilot log, telling on stderr what the log holds
/// (notes, silenced by `--quiet`; a truncated log is a warning).
#[cfg(feature = "autopilot-logs")]
fn read_autopilot(input: LogInput, instance: u8) -> Result<ImuLog> {
    let path = std::path::PathBuf::from(input.name());
    let path = path.as_path();
    let all = input.read_autopilot()?;
    let imu_topics: Vec<String> = all
        .found
        .iter()
        .filter(|(n, _)| {
            n.starts_with("sensor_gyro[") || n.starts_with("sensor_accel[") || n.starts_with("IMU")
        })
        .map(|(n, c)| format!("{n} ×{c}"))
        .collect();
    note!(
        "{}: {}, {} topics/message types; IMU data: {}",
        path.display(),
        all.format.name(),
        all.found.len(),
        imu_topics.join(", ")
    );
    for imu in &all.imus {
        let l = &imu.log;
        let span = l
            .channel("temperature")
            .map(|t| {
                let (lo, hi) = t
                    .values
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                        (a.min(x), b.max(x))
                    });
                format!(", temperature {lo:.2}–{hi:.2} °C")
            })
            .unwrap_or_default();
        note!(
            "  instance {}: {} samples, τ0 = {:.4} s, channels {}{span}{}",
            imu.instance,
            l.len(),
            l.tau0_s,
            l.channels
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(","),
            if imu.instance == instance {
                "  ← used"
            } else {
                ""
            }
        );
    }
    if let Some(at) = all.truncated_at_byte {
        eprintln!(
            "warning: {}: log truncated: stopped cleanly at the message cut off at byte {at}",
            path.display()
        );
    }
    for n in &all.notes {
        note!("  note: {n}");
    }
    let available: Vec<String> = all.imus.iter().map(|i| i.instance.to_string()).collect();
    let Some(pos) = all.imus.iter().position(|i| i.instance == instance) else {
        anyhow::bail!(
            "{}: no IMU instance {instance} (instances: {}); choose one with --instance N",
            path.display(),
            available.join(", ")
        );
    };
    all.imus
        .into_iter()
        .nth(pos)
        .map(|i| i.log)
        .ok_or_else(|| anyhow::anyhow!("{}: no IMU instance {instance}", path.display()))
}

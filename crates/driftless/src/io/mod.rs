//! Readers and writers. Readers turn files into typed, columnar [`log::ImuLog`]s and
//! never do math beyond unit conversion at the edge; algorithms never parse files.
//!
//! * [`text`]: delimited text (CSV, whitespace, tab, semicolon), streamed and parsed in parallel.
//! * [`binary`]: the compact `DRIFTLOG` column-major binary format (reader and writer).
//! * [`write`](mod@write): CSV writer.
//! * [`ulog`], [`dataflash`], [`autopilot`] (feature `autopilot-logs`, on by default): PX4
//!   ULog and ArduPilot DataFlash logs → one [`log::ImuLog`] per IMU instance.
//! * [`rosbag`]: ROS 1 bags, ROS 2 MCAP and sqlite3 (`.db3`) bags, compressed chunks
//!   included → the [`log::ImuLog`] of one `sensor_msgs/Imu` topic.
//! * [`units`]: unit strings → SI conversion.
//! * [`error`]: one error type, [`LogError`], naming file, line and column.
//! * [`input`]: an input opened once and sniffed on the handle that is then read (pipes
//!   and FIFOs work); configuration files read under a size cap.
//! * [`output`]: every output file, written atomically; checks of output paths against inputs.

#[cfg(feature = "autopilot-logs")]
pub mod autopilot;
pub mod binary;
#[cfg(feature = "autopilot-logs")]
pub mod dataflash;
pub(crate) mod edge;
pub mod error;
pub mod input;
/// The IMU log types, kept here for readers' signatures; they live in [`crate::data`].
pub mod log {
    pub use crate::data::imu::*;
}
pub mod nav;
mod number;
pub mod output;
pub mod probe;
pub mod rosbag;
pub mod sim_writer;
pub mod text;
mod timing;
#[cfg(feature = "autopilot-logs")]
pub mod ulog;
pub mod units;
pub mod write;
pub(crate) mod yaml;

#[cfg(feature = "autopilot-logs")]
pub use autopilot::{
    AutopilotFormat, AutopilotImu, AutopilotImuLogs, detect_format, imu_logs_from_autopilot,
    imu_logs_from_autopilot_file,
};
#[cfg(feature = "autopilot-logs")]
pub use dataflash::{imu_logs_from_dataflash, parse_dataflash};
#[cfg(feature = "autopilot-logs")]
pub use ulog::{imu_logs_from_ulog, parse_ulog};

pub use binary::{read_binary, read_binary_file, write_binary, write_binary_file};
pub use error::{Location, LogError};
pub use input::{InputFormat, LogInput, MAX_CONFIG_BYTES, read_config_text};
pub use log::{Channel, ImuLog, Quantity, TimeGap};
pub use rosbag::{BagFormat, read_rosbag_file};
pub use text::{
    ColumnRef, ColumnSpec, Delimiter, GapPolicy, HeaderMode, TextOptions, read_text,
    read_text_bytes, read_text_file,
};
pub use units::{TimeUnit, Unit};
pub use write::{write_csv, write_csv_file};

/// A path from a configuration or scenario file: `${DRIFTLESS_DATA}` replaced by that
/// environment variable (default `../shared/data`, relative to the working directory —
/// the repository root in the README's commands), then a relative path resolved against
/// `base_dir` (the file's folder; empty for the working directory).
pub(crate) fn resolve_data_path(
    p: &std::path::Path,
    base_dir: &std::path::Path,
) -> std::path::PathBuf {
    use std::path::PathBuf;
    let text = p.to_string_lossy();
    let p = if text.contains("${DRIFTLESS_DATA}") {
        let data = std::env::var_os("DRIFTLESS_DATA")
            .map(PathBuf::from)
            .unwrap_or_else(|| {
                std::env::current_dir()
                    .unwrap_or_default()
                    .join("../shared/data")
            });
        PathBuf::from(text.replace("${DRIFTLESS_DATA}", &data.to_string_lossy()))
    } else {
        p.to_path_buf()
    };
    if p.is_absolute() { p } else { base_dir.join(p) }
}

/// Reads a log file, choosing the reader by content: files starting with the `DRIFTLOG`
/// magic are read as binary logs (`opts` is then ignored), gzip files (`.gz`, by their
/// magic bytes) are decompressed on the fly and then read the same way, anything else as
/// delimited text. The file is opened once and sniffed on the handle that is then read
/// ([`LogInput`]), so a pipe, a FIFO or `/dev/stdin` gives the same log as a regular file.
pub fn read_log_file(
    path: impl AsRef<std::path::Path>,
    opts: &TextOptions,
) -> Result<ImuLog, LogError> {
    LogInput::open(path)?.read_log(opts)
}

/// The first two bytes of a gzip member (RFC 1952 §2.3.1: ID1 = 31, ID2 = 139).
pub const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

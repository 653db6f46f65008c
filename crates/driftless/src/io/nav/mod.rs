//! Navigation input/output formats: readers and writers only, no navigation math.
//!
//! Readers turn files into the typed, columnar records of [`types`] (SI units, names with
//! units), converting units at this edge only; writers do the reverse. Every bad input gives
//! one [`LogError`] naming the file, line and column; readers never return NaN and never
//! return partial data, except that a truncated first or last record (what a logger that
//! starts or stops mid-line leaves) is dropped and reported in the result's `notes`.
//!
//! * [`kfgins`]: the text formats of KF-GINS (i2Nav-WHU/KF-GINS, GPL-3.0; formats learnt from
//!   its README, `src/fileio/*` and `src/kf_gins.cpp`, no code taken): IMU increments,
//!   GNSS positions, and the three output files (`KF_GINS_Navresult.nav`,
//!   `KF_GINS_IMU_ERR.txt`, `KF_GINS_STD.txt`).
//! * [`kfgins_config`]: KF-GINS's YAML configuration (`kf-gins.yaml`) → [`KfGinsConfig`].
//! * [`rtklib`]: RTKLIB `.pos` solutions and binary `.tag` time-tag files, and the mapping of
//!   a tick-stamped IMU CSV to GPS time.
//! * [`gpstime`]: GPS time (GPST, no leap seconds) ↔ calendar and (week, seconds of week).

pub mod gpstime;
pub mod kfgins;
pub mod kfgins_config;
pub mod rtklib;
pub mod track;
/// The navigation record types; they live in [`crate::data::nav`].
pub mod types {
    pub use crate::data::nav::*;
}

pub use gpstime::{GpsTime, ParseTimeBaseError, TimeBase, TimeBaseError, gps_minus_utc_s};
pub use kfgins::{
    GnssReadOptions, KfGinsOutputWriter, KfGinsRow, ZeroSigma, read_kfgins_gnss,
    read_kfgins_gnss_file, read_kfgins_imu, read_kfgins_imu_file, write_kfgins_gnss,
    write_kfgins_imu, write_kfgins_imu_err, write_kfgins_nav, write_kfgins_outputs,
    write_kfgins_std,
};
pub use kfgins_config::{ImuNoise, KfGinsConfig, KfGinsConfigRaw};
pub use rtklib::{
    FposSize, TaggedTimes, TickMapping, TimeTag, map_ticks_to_gps, read_rtklib_pos,
    read_rtklib_pos_file, read_rtklib_tag, read_rtklib_tag_file, write_rtklib_pos,
};
pub use types::{GnssFixes, ImuErrors, ImuIncrements, NavSolution, NavStd, quality};

use crate::io::{Location, LogError};

/// Reads a whole file, mapping the OS error to [`LogError::Io`].
pub(crate) fn read_file(path: &std::path::Path) -> Result<Vec<u8>, LogError> {
    std::fs::read(path).map_err(|error| LogError::Io {
        path: path.display().to_string(),
        error,
    })
}

/// A whole text file (KF-GINS, RTKLIB, tagged CSV) for the in-memory readers, with the
/// binary-data and line-length checks of [`crate::io::input::read_text_input`]: `/dev/zero`
/// or a file without line ends fails within its first MiB.
pub(crate) fn read_text_file(path: &std::path::Path) -> Result<Vec<u8>, LogError> {
    crate::io::input::read_text_input(path, read_file)
}

/// [`read_text_file`] reading a large regular file with [`read_file_parallel`].
pub(crate) fn read_text_file_parallel(path: &std::path::Path) -> Result<Vec<u8>, LogError> {
    crate::io::input::read_text_input(path, read_file_parallel)
}

/// Block size of [`read_file_parallel`], bytes.
const READ_BLOCK_BYTES: usize = 4 << 20;

/// A large file read whole, in blocks read concurrently on the rayon pool (positioned
/// reads): the copies out of the page cache and the page faults of the fresh buffer are
/// shared by the cores instead of preceding all parsing on one. Same result as
/// [`read_file`], which it falls back to for anything but a regular file of stable size
/// (a file that grows or shrinks meanwhile is read again sequentially).
pub(crate) fn read_file_parallel(path: &std::path::Path) -> Result<Vec<u8>, LogError> {
    #[cfg(unix)]
    {
        use rayon::prelude::*;
        use std::os::unix::fs::FileExt;
        let io_err = |error| LogError::Io {
            path: path.display().to_string(),
            error,
        };
        let f = std::fs::File::open(path).map_err(io_err)?;
        let meta = f.metadata().map_err(io_err)?;
        let len = usize::try_from(meta.len()).unwrap_or(usize::MAX);
        if !meta.is_file() || len < 2 * READ_BLOCK_BYTES || len == usize::MAX {
            return read_file(path);
        }
        let mut buf = vec![0u8; len];
        let read = buf
            .par_chunks_mut(READ_BLOCK_BYTES)
            .enumerate()
            .try_for_each(|(k, chunk)| f.read_exact_at(chunk, (k * READ_BLOCK_BYTES) as u64));
        // A shorter file now (an error), or a longer one (a byte past the length): the
        // sequential reader, which reads to the end whatever it is.
        let mut probe = [0u8; 1];
        match read {
            Ok(()) if f.read_at(&mut probe, len as u64).map_err(io_err)? == 0 => Ok(buf),
            _ => read_file(path),
        }
    }
    #[cfg(not(unix))]
    {
        read_file(path)
    }
}

/// A small text file (a configuration) read whole, refused when larger than `max_bytes`,
/// not UTF-8 or binary (a NUL byte), with a message that says which.
pub(crate) fn read_text_capped(path: &std::path::Path, max_bytes: u64) -> Result<String, String> {
    crate::io::read_config_text(path, max_bytes).map_err(|e| match e.kind() {
        std::io::ErrorKind::InvalidData => e.to_string(),
        _ => format!("cannot read: {e}"),
    })
}

/// Text of a file as UTF-8, or an error naming the first bad byte's line and column.
pub(crate) fn as_utf8<'a>(bytes: &'a [u8], name: &str) -> Result<&'a str, LogError> {
    as_utf8_from(bytes, name, 1)
}

/// [`as_utf8`] of a piece of a text whose first line is line `line0` of the file.
pub(crate) fn as_utf8_from<'a>(
    bytes: &'a [u8],
    name: &str,
    line0: usize,
) -> Result<&'a str, LogError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let good = &bytes[..e.valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() + line0;
        let col = good.len() - good.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1) + 1;
        LogError::Malformed {
            at: Location::field(name, line, col),
            format: "text",
            message: "invalid UTF-8".into(),
        }
    })
}

/// One whitespace/comma-separated field: its 1-based byte column and text.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Field<'a> {
    pub col: usize,
    pub text: &'a str,
}

/// Splits a line on any of `seps`, skipping empty pieces (as KF-GINS's loader does with
/// `", \t"`), and records each field's 1-based byte column.
pub(crate) fn split_fields<'a>(line: &'a str, seps: &[u8]) -> Vec<Field<'a>> {
    let mut out = Vec::new();
    split_fields_into(line, seps, &mut out);
    out
}

/// [`split_fields`] into a reused vector (cleared first).
#[inline]
pub(crate) fn split_fields_into<'a>(line: &'a str, seps: &[u8], out: &mut Vec<Field<'a>>) {
    out.clear();
    let bytes = line.as_bytes();
    // Separators below 64 (all of KF-GINS's and RTKLIB's) as a bit mask: one shift and
    // test per byte instead of a scan of `seps`.
    let mask = seps
        .iter()
        .filter(|&&s| s < 64)
        .fold(0u64, |m, &s| m | 1 << s);
    let all_in_mask = seps.iter().all(|&s| s < 64);
    let is_sep = |b: u8| {
        if b < 64 {
            mask >> b & 1 == 1
        } else {
            !all_in_mask && seps.contains(&b)
        }
    };
    let mut start: Option<usize> = None;
    for (i, &b) in bytes.iter().enumerate() {
        if is_sep(b) {
            if let Some(s) = start.take() {
                out.push(Field {
                    col: s + 1,
                    text: &line[s..i],
                });
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push(Field {
            col: s + 1,
            text: &line[s..],
        });
    }
}

/// Parses a finite f64 from one field; `field` is the 1-based field number, `name` the
/// column's name (both for the message).
pub(crate) fn parse_num(
    f: Field<'_>,
    name_path: &str,
    line: usize,
    field: usize,
    name: &str,
) -> Result<f64, LogError> {
    // The location (an owned path) is built only for an error: this runs per field.
    let at = || Location::field(name_path, line, f.col);
    // The text reader's scanner: exact (Clinger's fast path, else the standard parser).
    match super::number::parse_f64(f.text.as_bytes()).ok_or(()) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(LogError::NonFinite {
            at: at(),
            value: crate::io::error::excerpt(f.text.as_bytes()),
            field,
            name: name.to_owned(),
        }),
        Err(_) => Err(LogError::NonNumeric {
            at: at(),
            value: crate::io::error::excerpt(f.text.as_bytes()),
            field,
            name: name.to_owned(),
        }),
    }
}

/// Checks that `t` is strictly after `prev` (the previous data row's time).
pub(crate) fn check_time_order(
    t: f64,
    prev: Option<f64>,
    path: &str,
    line: usize,
    field: usize,
    name: &str,
) -> Result<(), LogError> {
    if let Some(p) = prev {
        if t == p {
            return Err(LogError::DuplicateTime {
                at: Location::line(path, line),
                field,
                name: name.to_owned(),
                time_s: t,
            });
        }
        if t < p {
            return Err(LogError::NonMonotonicTime {
                at: Location::line(path, line),
                field,
                name: name.to_owned(),
                time_s: t,
                previous_s: p,
            });
        }
    }
    Ok(())
}

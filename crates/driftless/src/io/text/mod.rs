//! Delimited text reader: CSV, semicolon, tab or whitespace separated IMU logs.
//!
//! * Delimiter: auto-detected from the first non-comment row (`;` if present, else `,`,
//!   else tab if the row splits cleanly on tabs, else runs of whitespace), or given.
//! * `#` starts a comment, on its own line or after the data; blank lines are skipped;
//!   `\r\n` line ends are accepted; one trailing delimiter per row is tolerated.
//! * Header: auto-detected (a first non-comment row with a non-numeric field), forced
//!   on or off, or names given by the caller. A header name may carry its unit in
//!   brackets, `gyro_x [deg/s]` or `tick(ms)`; it is used when the caller gives none.
//! * Columns: a time column (by name or 1-based index) or none; the data columns to keep
//!   (by name or index) each with its [`Unit`](crate::io::units::Unit); unselected columns are only counted, never
//!   parsed. Values are converted to SI while parsing, the only math a reader does.
//! * Week + seconds of week: with [`TextOptions::week_column`] the time column counts
//!   seconds within a week and the week column holds the week number (whole numbers
//!   0–65 535); the log's time is `time + (week − first week) × 604 800 s`, i.e. seconds
//!   from the start of the first row's week ([`ImuLog::week`]), increasing across a week
//!   boundary.
//! * τ0: the median time-stamp difference when there is a time column (a given rate must
//!   agree within `rate_tolerance`), else `1 / rate_hz`.
//! * Field count: every row must have the reference row's; that is the header, else the
//!   first data row unless it is shorter than the common count of the rows after it (then
//!   the first such row; see `io::edge`), so an error never cites a bad row as its own
//!   reference.
//! * Truncated edge records (only with [`TextOptions::drop_truncated_edges`]): a first or
//!   last data record with fewer fields than the reference row, or whose cut field (first
//!   field of the first record, last of the last) is not a number, or — for the last record
//!   without a line end when the time column is the last field — whose time does not follow
//!   the previous row's, is dropped and reported in [`ImuLog::notes`]. Such records are
//!   what a logger leaves when it starts or stops mid-line. Anywhere else a bad row stays
//!   an error. A first record that still parses whole (a cut that left a shorter but valid
//!   number) cannot be told from a good one and is kept.
//!
//! * Binary data: the first 64 KiB are checked before anything is parsed; a NUL or other
//!   control byte, or mostly non-UTF-8 bytes, make the input [`LogError::BinaryData`]
//!   naming the byte offset (a bad row holding such bytes later in the input too).
//! * Line length: a line longer than [`TextOptions::max_line_bytes`] (1 MiB) is
//!   [`LogError::LineTooLong`] as soon as that many bytes are buffered, so memory stays
//!   bounded whatever the input.
//! * One sample rate: with a time column, a stretch of sustained shorter or longer
//!   intervals than the log's (more than 5 % off over blocks of 32 intervals; single late
//!   samples and isolated gaps do not count) is [`LogError::RateChange`], naming where and
//!   both rates: a log at two rates is refused, never analysed at an averaged τ0.
//!
//! Streaming: the input is read in chunks of [`TextOptions::chunk_bytes`] (16 MiB), cut at
//! the last line end, split into one piece per rayon thread at line ends and parsed in
//! parallel; the pieces' columns are appended in order. Output vectors are pre-sized from the
//! file size and the first chunk's bytes per row. Peak memory is the parsed columns plus
//! about two chunks (plus 8 bytes per row for the median τ0 at the end).
//!
//! Errors: the first problem in file order, as one [`LogError`] naming path, line and column
//! (see [`super::error`]).
//!
//! Layout: `options` (the options and their parsing), `fields` (lines and fields),
//! `header` (header names and column selection), `plan` (what each field becomes),
//! `parse` (data lines → columns), `time` (τ0, gaps, weeks) and `read` (the streaming loop).

use std::io::Read;
use std::path::Path;

use super::error::LogError;
use super::log::ImuLog;

mod fields;
mod header;
mod options;
mod parse;
mod plan;
mod read;
mod time;

pub use options::{
    ColumnRef, ColumnSpec, Delimiter, GapPolicy, HeaderMode, ParseSpecError, TextOptions,
};
use read::read_impl;

/// Reads a delimited text log from a file (streamed, never loaded whole).
pub fn read_text_file(path: impl AsRef<Path>, opts: &TextOptions) -> Result<ImuLog, LogError> {
    let (file, size, name) = super::error::open_file(path.as_ref())?;
    read_impl(file, &name, opts, size)
}

/// [`read_text`] with the input's size when known (pre-sizes the columns).
pub(crate) fn read_text_sized<R: Read>(
    reader: R,
    source: &str,
    opts: &TextOptions,
    size: Option<u64>,
) -> Result<ImuLog, LogError> {
    read_impl(reader, source, opts, size)
}

/// Reads a delimited text log from any reader; `source` names it in errors and in
/// [`ImuLog::source`].
pub fn read_text<R: Read>(reader: R, source: &str, opts: &TextOptions) -> Result<ImuLog, LogError> {
    read_impl(reader, source, opts, None)
}

/// Reads a delimited text log held in memory.
pub fn read_text_bytes(bytes: &[u8], source: &str, opts: &TextOptions) -> Result<ImuLog, LogError> {
    read_impl(bytes, source, opts, Some(bytes.len() as u64))
}

#[cfg(test)]
mod row_count_tests;
#[cfg(test)]
mod tests;

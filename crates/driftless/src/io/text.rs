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
//!   (by name or index) each with its [`Unit`]; unselected columns are only counted, never
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

use std::fmt;
use std::io::Read;
use std::ops::Range;
use std::path::Path;
use std::str::FromStr;

use rayon::prelude::*;

use super::edge::{Cut, Edge, REFERENCE_SAMPLE, is_number, last_data_line, note, reference_count};
use super::error::{Location, LogError, excerpt};
use super::input::{SNIFF_BYTES, binary_error};
use super::log::{Channel, ImuLog, TimeGap};
use super::number::{parse_f64, parse_prefix};
use super::timing::rate_change;
use super::units::{KNOWN_UNITS, TimeUnit, Unit};

/// Field separator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Delimiter {
    /// Detect from the first non-comment row.
    #[default]
    Auto,
    /// `,`
    Comma,
    /// `;`
    Semicolon,
    /// A single tab between fields (spaces around fields are trimmed).
    Tab,
    /// Runs of spaces and/or tabs; leading and trailing whitespace ignored.
    Whitespace,
}

/// Whether the first non-comment row names the columns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HeaderMode {
    /// A header if the first non-comment row has a non-empty, non-numeric field.
    #[default]
    Auto,
    /// The first non-comment row is a header.
    Present,
    /// There is no header; every non-comment row is data.
    Absent,
}

/// A column, by 1-based field number or by name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    /// 1-based field number.
    Index(usize),
    /// Name from the header or from [`TextOptions::column_names`] (exact match, then a
    /// unique case-insensitive match).
    Name(String),
}

/// What to do when consecutive time stamps are further apart than
/// `gap_factor × τ0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GapPolicy {
    /// Fail with [`LogError::TimeGap`].
    #[default]
    Error,
    /// Keep all rows; [`ImuLog::segments`] lists the contiguous runs between gaps and
    /// [`ImuLog::gaps`] the gaps.
    Split,
    /// Keep all rows as one segment; [`ImuLog::gaps`] lists the gaps so the caller can warn.
    Bridge,
}

/// One data column to keep: which, in what unit, and optionally under which name.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnSpec {
    /// Which column of the input.
    pub column: ColumnRef,
    /// Its unit; `None` takes the header's bracketed unit, then
    /// [`TextOptions::default_unit`], then unitless.
    pub unit: Option<Unit>,
    /// Channel name in the log; `None` keeps the input's name (`colN` without a header).
    pub rename: Option<String>,
}

/// Reader options. `TextOptions::default()` auto-detects everything, keeps every column
/// unitless, and needs either a time column or `rate_hz` to know τ0.
#[derive(Clone, Debug, PartialEq)]
pub struct TextOptions {
    /// Field separator.
    pub delimiter: Delimiter,
    /// Header detection.
    pub header: HeaderMode,
    /// Column names from the caller, one per field. Used instead of the header's names
    /// when there is a header, and instead of `col1`, `col2`, … when there is none.
    pub column_names: Option<Vec<String>>,
    /// The time column, or `None`: then a header field named as a time column
    /// ([`TIME_COLUMN_NAMES`], when `detect_time_column`) is taken, else the log has no
    /// time stamps and `rate_hz` is needed.
    pub time_column: Option<ColumnRef>,
    /// Take a header field named as a time column ([`TIME_COLUMN_NAMES`]) for the time
    /// when `time_column` is `None` (on by default; off reads such a field as data).
    pub detect_time_column: bool,
    /// Unit of the time column; `None` takes the header's bracketed unit, else seconds.
    pub time_unit: Option<TimeUnit>,
    /// Data columns to keep, in output order. Empty keeps every column except time.
    pub columns: Vec<ColumnSpec>,
    /// Unit for kept columns with neither an explicit nor a header unit.
    pub default_unit: Option<Unit>,
    /// Sample rate, Hz. Required without a time column (τ0 = 1 / rate); with one it must
    /// agree with the median interval within `rate_tolerance`.
    pub rate_hz: Option<f64>,
    /// Allowed relative difference between `rate_hz` and the time column's rate (0.02 = 2 %).
    pub rate_tolerance: f64,
    /// What to do with time gaps.
    pub gap_policy: GapPolicy,
    /// An interval longer than `gap_factor × τ0` is a gap (1.5 by default).
    pub gap_factor: f64,
    /// Bytes read per chunk (16 MiB by default; minimum 64).
    pub chunk_bytes: usize,
    /// Week-number column (by name or index) of a time given as week + seconds of week;
    /// needs `time_column` (the seconds of week). See the module docs.
    pub week_column: Option<ColumnRef>,
    /// Drop a truncated first or last data record with a note instead of failing (see
    /// the module docs). Off by default: every row must then be whole.
    pub drop_truncated_edges: bool,
    /// Longest line accepted, bytes (1 MiB by default): a longer one is an error
    /// ([`LogError::LineTooLong`]) as soon as it is seen, so a file without line ends
    /// (binary data, a wrong file) never makes the reader buffer it whole.
    pub max_line_bytes: usize,
}

impl Default for TextOptions {
    fn default() -> Self {
        TextOptions {
            delimiter: Delimiter::Auto,
            header: HeaderMode::Auto,
            column_names: None,
            time_column: None,
            detect_time_column: true,
            time_unit: None,
            columns: Vec::new(),
            default_unit: None,
            rate_hz: None,
            rate_tolerance: 0.02,
            gap_policy: GapPolicy::Error,
            gap_factor: 1.5,
            chunk_bytes: 16 << 20,
            week_column: None,
            drop_truncated_edges: false,
            max_line_bytes: 1 << 20,
        }
    }
}

impl TextOptions {
    /// Sets the time column.
    pub fn with_time(mut self, column: ColumnRef, unit: Option<TimeUnit>) -> Self {
        self.time_column = Some(column);
        self.time_unit = unit;
        self
    }
    /// Sets the sample rate, Hz.
    pub fn with_rate_hz(mut self, rate_hz: f64) -> Self {
        self.rate_hz = Some(rate_hz);
        self
    }
    /// Adds a data column to keep.
    pub fn with_column(mut self, column: ColumnRef, unit: Option<Unit>) -> Self {
        self.columns.push(ColumnSpec {
            column,
            unit,
            rename: None,
        });
        self
    }
    /// Sets the column names.
    pub fn with_names<S: Into<String>>(mut self, names: impl IntoIterator<Item = S>) -> Self {
        self.column_names = Some(names.into_iter().map(Into::into).collect());
        self
    }
    /// Sets the gap policy.
    pub fn with_gap_policy(mut self, policy: GapPolicy) -> Self {
        self.gap_policy = policy;
        self
    }
    /// Sets the week-number column of a week + seconds-of-week time.
    pub fn with_week_column(mut self, column: ColumnRef) -> Self {
        self.week_column = Some(column);
        self
    }
    /// Drops truncated first and last records with a note.
    pub fn dropping_truncated_edges(mut self) -> Self {
        self.drop_truncated_edges = true;
        self
    }
}

/// A `--column`-style specification that could not be parsed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("bad column specification {text:?}: {reason}")]
pub struct ParseSpecError {
    /// The text given.
    pub text: String,
    /// Why it was rejected.
    pub reason: String,
}

impl FromStr for ColumnRef {
    type Err = ParseSpecError;
    /// All digits → 1-based index (0 is rejected); anything else → name.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        if t.is_empty() {
            return Err(ParseSpecError {
                text: s.into(),
                reason: "empty column reference".into(),
            });
        }
        if t.bytes().all(|b| b.is_ascii_digit()) {
            match t.parse::<usize>() {
                Ok(i) if i >= 1 => Ok(ColumnRef::Index(i)),
                _ => Err(ParseSpecError {
                    text: s.into(),
                    reason: "column numbers are 1-based".into(),
                }),
            }
        } else {
            Ok(ColumnRef::Name(t.to_owned()))
        }
    }
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Index(i) => write!(f, "#{i}"),
            ColumnRef::Name(n) => write!(f, "{n:?}"),
        }
    }
}

impl FromStr for ColumnSpec {
    type Err = ParseSpecError;
    /// `COLUMN[:UNIT][=NEW_NAME]`, e.g. `gyro_x:deg/s`, `2:counts/6258rad/s=gyro_x`, `5`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (body, rename) = match s.rsplit_once('=') {
            Some((b, r)) if !r.trim().is_empty() => (b, Some(r.trim().to_owned())),
            _ => (s, None),
        };
        let (col, unit) = match body.split_once(':') {
            Some((c, u)) => (c, Some(u)),
            None => (body, None),
        };
        let column = col.parse()?;
        let unit = unit
            .map(|u| {
                Unit::parse(u).map_err(|e| ParseSpecError {
                    text: s.into(),
                    reason: e.to_string(),
                })
            })
            .transpose()?;
        Ok(ColumnSpec {
            column,
            unit,
            rename,
        })
    }
}

impl FromStr for GapPolicy {
    type Err = ParseSpecError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "error" => Ok(GapPolicy::Error),
            "split" => Ok(GapPolicy::Split),
            "bridge" => Ok(GapPolicy::Bridge),
            _ => Err(ParseSpecError {
                text: s.into(),
                reason: "expected error, split or bridge".into(),
            }),
        }
    }
}

impl FromStr for Delimiter {
    type Err = ParseSpecError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(Delimiter::Auto),
            "," | "comma" => Ok(Delimiter::Comma),
            ";" | "semicolon" => Ok(Delimiter::Semicolon),
            "\t" | "\\t" | "tab" => Ok(Delimiter::Tab),
            " " | "space" | "whitespace" | "ws" => Ok(Delimiter::Whitespace),
            _ => Err(ParseSpecError {
                text: s.into(),
                reason: "expected auto, comma, semicolon, tab or whitespace".into(),
            }),
        }
    }
}

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

// ---------------------------------------------------------------------------------------
// Internals
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Delim {
    Byte(u8),
    Whitespace,
}

#[inline]
fn is_ws(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == b'\x0b' || b == b'\x0c'
}

/// Calls `f(byte_offset, field)` for each field of a line (comment already allowed),
/// returns the number of fields. Empty trailing field after a final delimiter is dropped.
#[inline]
fn for_each_field<E>(
    line: &[u8],
    delim: Delim,
    mut f: impl FnMut(usize, usize, &[u8]) -> Result<(), E>,
) -> Result<usize, E> {
    let n = line.len();
    let mut p = 0;
    let mut field = 0;
    match delim {
        Delim::Whitespace => loop {
            while p < n && is_ws(line[p]) {
                p += 1;
            }
            if p >= n || line[p] == b'#' {
                break;
            }
            let start = p;
            while p < n && !is_ws(line[p]) && line[p] != b'#' {
                p += 1;
            }
            f(field, start, &line[start..p])?;
            field += 1;
        },
        Delim::Byte(d) => loop {
            let start = p;
            while p < n && line[p] != d && line[p] != b'#' {
                p += 1;
            }
            let end_of_row = p >= n || line[p] == b'#';
            let (mut s, mut e) = (start, p);
            while s < e && is_ws(line[s]) {
                s += 1;
            }
            while e > s && is_ws(line[e - 1]) {
                e -= 1;
            }
            if end_of_row && s == e && field > 0 {
                break; // one trailing delimiter
            }
            f(field, s, &line[s..e])?;
            field += 1;
            if end_of_row {
                break;
            }
            p += 1;
        },
    }
    Ok(field)
}

/// What the header of a CSV written by driftless states: a first line
/// `# driftless log; …` and a second `# …; rows: N[; last line: # end of driftless log]` —
/// the row count and whether the file ends with that line.
fn declared_rows(region: &[u8]) -> Option<(usize, bool)> {
    let mut ls = lines(region);
    if !ls.next()?.starts_with(super::write::HEADER_MARK.as_bytes()) {
        return None;
    }
    let second = std::str::from_utf8(ls.next()?).ok()?.trim_end();
    let (_, after) = second.strip_prefix('#')?.split_once("rows: ")?;
    let digits = after.bytes().take_while(u8::is_ascii_digit).count();
    let n = after[..digits].parse().ok()?;
    let marked = after[digits..] == format!("; last line: {}", super::write::END_MARK);
    Some((n, marked))
}

/// The header of a EuRoC / TUM-VI IMU CSV (`#timestamp [ns],w_RS_S_x [rad s^-1],…,
/// a_RS_S_z [m s^-2]`) without its `#`: a comment line by the rules above, taken as the
/// header when it is the first line with content (its bracketed units then give ns time
/// stamps, rad/s and m/s²).
fn euroc_header(line: &[u8]) -> Option<&[u8]> {
    let rest = line.trim_ascii_start().strip_prefix(b"#")?;
    let is_euroc = rest.trim_ascii_start().starts_with(b"timestamp")
        && rest.windows(8).any(|w| w == b"w_RS_S_x");
    is_euroc.then_some(rest)
}

/// True when the line holds no data (blank or comment).
#[inline]
fn is_blank_or_comment(line: &[u8]) -> bool {
    match line.iter().position(|&b| !is_ws(b)) {
        None => true,
        Some(i) => line[i] == b'#',
    }
}

/// Splits a buffer into lines without the `\n` and a trailing `\r`.
fn lines(buf: &[u8]) -> impl Iterator<Item = &[u8]> {
    let body = buf.strip_suffix(b"\n").unwrap_or(buf);
    let mut it = (!buf.is_empty()).then(|| body.split(|&b| b == b'\n'));
    std::iter::from_fn(move || it.as_mut()?.next()).map(|l| l.strip_suffix(b"\r").unwrap_or(l))
}

#[derive(Clone, Copy, Debug)]
struct Slot {
    out: usize,
    scale: f64,
    offset: f64,
}

#[derive(Debug)]
struct Plan {
    delim: Delim,
    nfields: usize,
    /// Line that fixed the field count (header or reference data row, see `io::edge`).
    reference_line: usize,
    names: Vec<String>,
    slots: Vec<Option<Slot>>,
    /// Output vectors: time (if any) first, then channels.
    nout: usize,
    time_field: Option<usize>,
    channels: Vec<(usize, String, Unit)>,
    header_line: Option<usize>,
    /// Field of the week column, whose output vector comes after the channels'.
    week_field: Option<usize>,
    /// The time column was found by its header name (for the log's notes).
    time_detected: bool,
    /// Longest line accepted, bytes.
    max_line: usize,
}

enum FieldErr {
    NonNumeric { field: usize, value: String },
    Empty { field: usize },
    NonFinite { field: usize, value: String },
    Ragged { found: usize },
    TooLong,
}

struct PieceErr {
    /// 0-based line within the piece.
    line: usize,
    /// Byte offset of the line's start within the piece.
    byte: usize,
    /// 1-based byte column.
    col: usize,
    kind: FieldErr,
}

struct PieceOut {
    cols: Vec<Vec<f64>>,
    rows: usize,
    lines: usize,
    /// (row within piece, line within piece) where the row→line offset changes.
    anchors: Vec<(usize, usize)>,
}

/// Parses one data line into `cols`. `Ok(false)` for blank/comment lines.
#[inline]
fn parse_line(line: &[u8], plan: &Plan, cols: &mut [Vec<f64>]) -> Result<bool, (usize, FieldErr)> {
    if is_blank_or_comment(line) {
        return Ok(false);
    }
    let mut extra_at = None;
    let found = for_each_field(line, plan.delim, |field, start, text| {
        let Some(slot) = plan.slots.get(field) else {
            extra_at.get_or_insert(start);
            return Ok(());
        };
        if let Some(slot) = slot {
            if text.is_empty() {
                return Err((start + 1, FieldErr::Empty { field: field + 1 }));
            }
            let raw = parse_f64(text).ok_or_else(|| {
                (
                    start + 1,
                    FieldErr::NonNumeric {
                        field: field + 1,
                        value: excerpt(text),
                    },
                )
            })?;
            let v = (raw - slot.offset) * slot.scale;
            if !v.is_finite() {
                return Err((
                    start + 1,
                    FieldErr::NonFinite {
                        field: field + 1,
                        value: excerpt(text),
                    },
                ));
            }
            if let Some(c) = cols.get_mut(slot.out) {
                c.push(v);
            }
        }
        Ok(())
    })?;
    if found != plan.nfields {
        let col = extra_at.unwrap_or(line.len()) + 1;
        return Err((col, FieldErr::Ragged { found }));
    }
    Ok(true)
}

/// Fast path for one plain data row starting at `p` (no comment, only the number forms
/// of [`parse_prefix`], single spaces/tabs): pushes one value per output column and returns
/// the offset after the row's line end. `None` sends the row to the general path
/// ([`parse_line`]), which accepts a superset, gives identical values and builds errors.
#[inline]
fn fast_row(b: &[u8], mut p: usize, plan: &Plan, cols: &mut [Vec<f64>]) -> Option<usize> {
    let n = b.len();
    let last = plan.nfields.checked_sub(1)?;
    let ws = plan.delim == Delim::Whitespace;
    let d = match plan.delim {
        Delim::Byte(d) => d,
        Delim::Whitespace => b' ',
    };
    for (field, slot) in plan.slots.iter().enumerate() {
        while p < n && (b[p] == b' ' || (ws && b[p] == b'\t')) {
            p += 1;
        }
        if let Some(slot) = slot {
            let (raw, used) = parse_prefix(b.get(p..)?)?;
            let v = (raw - slot.offset) * slot.scale;
            if !v.is_finite() {
                return None;
            }
            cols.get_mut(slot.out)?.push(v);
            p += used;
        } else if ws {
            while p < n && !matches!(b[p], b' ' | b'\t' | b'\n' | b'\r' | b'#') {
                p += 1;
            }
        } else {
            while p < n && !matches!(b[p], b'\n' | b'\r' | b'#') && b[p] != d {
                p += 1;
            }
        }
        if field < last {
            if ws {
                if p < n && (b[p] == b' ' || b[p] == b'\t') {
                    continue;
                }
                return None;
            }
            while p < n && b[p] == b' ' {
                p += 1;
            }
            if p < n && b[p] == d {
                p += 1;
                continue;
            }
            return None;
        }
    }
    while p < n && (b[p] == b' ' || b[p] == b'\t') {
        p += 1;
    }
    if !ws && p < n && b[p] == d {
        p += 1;
        while p < n && b[p] == b' ' {
            p += 1;
        }
    }
    if p < n && b[p] == b'\r' {
        p += 1;
    }
    if p >= n {
        Some(n)
    } else if b[p] == b'\n' {
        Some(p + 1)
    } else {
        None
    }
}

fn parse_piece(bytes: &[u8], plan: &Plan, row_guess: usize) -> Result<PieceOut, PieceErr> {
    let mut cols: Vec<Vec<f64>> = (0..plan.nout)
        .map(|_| Vec::with_capacity(row_guess))
        .collect();
    let mut rows = 0;
    let mut line_no = 0;
    let mut anchors = Vec::new();
    let mut next_expected = usize::MAX;
    let mut pos = 0;
    while pos < bytes.len() {
        let is_data = match fast_row(bytes, pos, plan, &mut cols) {
            Some(next) => {
                if next - pos > plan.max_line {
                    return Err(PieceErr {
                        line: line_no,
                        byte: pos,
                        col: 1,
                        kind: FieldErr::TooLong,
                    });
                }
                pos = next;
                true
            }
            None => {
                for c in &mut cols {
                    c.truncate(rows);
                }
                let rest = &bytes[pos..];
                let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
                if len > plan.max_line {
                    return Err(PieceErr {
                        line: line_no,
                        byte: pos,
                        col: 1,
                        kind: FieldErr::TooLong,
                    });
                }
                let line = &rest[..len];
                let line = line.strip_suffix(b"\r").unwrap_or(line);
                let line_start = pos;
                pos += len + 1;
                match parse_line(line, plan, &mut cols) {
                    Ok(d) => d,
                    Err((col, kind)) => {
                        return Err(PieceErr {
                            line: line_no,
                            byte: line_start,
                            col,
                            kind,
                        });
                    }
                }
            }
        };
        if is_data {
            if line_no != next_expected {
                anchors.push((rows, line_no));
            }
            rows += 1;
            next_expected = line_no + 1;
        }
        line_no += 1;
    }
    Ok(PieceOut {
        cols,
        rows,
        lines: line_no,
        anchors,
    })
}

fn detect_delimiter(line: &[u8]) -> Delim {
    let body = match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    };
    if body.contains(&b';') {
        Delim::Byte(b';')
    } else if body.contains(&b',') {
        Delim::Byte(b',')
    } else if body.contains(&b'\t') {
        let mut clean = true;
        let _ = for_each_field(body, Delim::Byte(b'\t'), |_, _, t| {
            clean &= !t.is_empty();
            Ok::<(), ()>(())
        });
        if clean {
            Delim::Byte(b'\t')
        } else {
            Delim::Whitespace
        }
    } else {
        Delim::Whitespace
    }
}

/// `name [unit]` / `name(unit)` → (name, unit).
fn split_name_unit(raw: &str) -> (String, Option<String>) {
    let t = raw.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(inner) = t.strip_suffix(close)
            && let Some(i) = inner.rfind(open)
        {
            let name = inner[..i].trim();
            let unit = inner[i + open.len_utf8()..].trim();
            if !name.is_empty() {
                return (name.to_owned(), Some(unit.to_owned()));
            }
        }
    }
    (t.to_owned(), None)
}

/// Header names (case-insensitive, unit in brackets stripped, a leading `#` ignored)
/// taken for the time column when none is given.
pub const TIME_COLUMN_NAMES: [&str; 10] = [
    "t",
    "time",
    "timestamp",
    "time_s",
    "stamp",
    "sec",
    "seconds",
    "gps_time",
    "gpst",
    "time_stamp",
];

/// The one header field named as a time column, if any; two such fields are an error
/// (which one is the time cannot be guessed).
fn detect_time_field(names: &[String], at: &Location) -> Result<Option<usize>, LogError> {
    let hits: Vec<usize> = (0..names.len())
        .filter(|&i| {
            let n = names[i].trim().trim_start_matches('#').trim();
            TIME_COLUMN_NAMES.iter().any(|t| n.eq_ignore_ascii_case(t))
        })
        .collect();
    match hits.as_slice() {
        [] => Ok(None),
        [f] => Ok(Some(*f)),
        many => Err(LogError::InvalidOptions {
            at: at.clone(),
            message: format!(
                "{} header fields look like time columns ({}): name the time column with \
                 `--time-column`",
                many.len(),
                many.iter()
                    .map(|&i| format!("{}={}", i + 1, names[i]))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
    }
}

fn resolve(r: &ColumnRef, names: &[String], at: &Location) -> Result<usize, LogError> {
    let unknown = || LogError::UnknownColumn {
        at: at.clone(),
        column: r.to_string(),
        available: names
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{}={n}", i + 1))
            .collect::<Vec<_>>()
            .join(", "),
    };
    match r {
        ColumnRef::Index(i) => {
            if *i >= 1 && *i <= names.len() {
                Ok(i - 1)
            } else {
                Err(unknown())
            }
        }
        ColumnRef::Name(n) => {
            let exact: Vec<usize> = (0..names.len()).filter(|&i| names[i] == *n).collect();
            let hits = if exact.is_empty() {
                (0..names.len())
                    .filter(|&i| names[i].eq_ignore_ascii_case(n))
                    .collect()
            } else {
                exact
            };
            match hits.as_slice() {
                [i] => Ok(*i),
                [] => Err(unknown()),
                _ => Err(LogError::InvalidOptions {
                    at: at.clone(),
                    message: format!(
                        "column name {n:?} is ambiguous (fields {}); select it by number",
                        hits.iter()
                            .map(|i| (i + 1).to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                }),
            }
        }
    }
}

/// A non-comment line of the first chunk: 1-based number, byte range of the line with its
/// line end in the chunk, and its text without the line end.
struct SampleLine<'a> {
    line: usize,
    end: usize,
    text: &'a [u8],
}

/// Number of fields of a line.
fn field_count(line: &[u8], delim: Delim) -> usize {
    for_each_field(line, delim, |_, _, _| Ok::<(), ()>(())).unwrap_or(0)
}

/// 1-based byte column where a row with `found` fields departs from `expected`: the start
/// of the first extra field, or the end of the line.
fn ragged_col(line: &[u8], delim: Delim, expected: usize) -> usize {
    let mut extra = None;
    let _ = for_each_field(line, delim, |field, start, _| {
        if field == expected {
            extra.get_or_insert(start);
        }
        Ok::<(), ()>(())
    });
    extra.unwrap_or(line.len()) + 1
}

/// The text of field `k` (0-based) of a line.
fn field_text(line: &[u8], delim: Delim, k: usize) -> Option<Vec<u8>> {
    let mut out = None;
    let _ = for_each_field(line, delim, |field, _, t| {
        if field == k {
            out = Some(t.to_vec());
        }
        Ok::<(), ()>(())
    });
    out
}

/// The plan, and where the data starts: the index into the sample of the first data line
/// to parse (`sample.len()` when the sample holds none), with the note for a dropped first
/// record.
type PlanStart = (Plan, usize, Option<String>);

/// Builds the plan from the first non-comment lines of the input (`sample[0]` is the
/// first; the rest vote on the reference field count and, with `Delimiter::Auto`, on the
/// delimiter).
fn make_plan(
    sample: &[SampleLine<'_>],
    source: &str,
    opts: &TextOptions,
) -> Result<PlanStart, LogError> {
    let Some(head) = sample.first() else {
        return Err(LogError::Empty {
            at: Location::input(source),
        });
    };
    let (first, line_no) = (head.text, head.line);
    let delim = match opts.delimiter {
        Delimiter::Auto => {
            // The first line's delimiter unless most sampled lines say otherwise (a cut
            // first record may hold a single field).
            let votes: Vec<Delim> = sample.iter().map(|l| detect_delimiter(l.text)).collect();
            let count = |d: Delim| votes.iter().filter(|&&v| v == d).count();
            let mut best = votes[0];
            for &v in &votes {
                if count(v) > count(best) {
                    best = v;
                }
            }
            best
        }
        Delimiter::Comma => Delim::Byte(b','),
        Delimiter::Semicolon => Delim::Byte(b';'),
        Delimiter::Tab => Delim::Byte(b'\t'),
        Delimiter::Whitespace => Delim::Whitespace,
    };
    let mut fields: Vec<String> = Vec::new();
    let mut numeric = true;
    let mut rest_numeric = true;
    let _ = for_each_field(first, delim, |k, _, t| {
        let bad = !t.is_empty() && parse_f64(t).is_none();
        numeric &= !bad;
        if k > 0 {
            rest_numeric &= is_number(t);
        }
        fields.push(String::from_utf8_lossy(t).into_owned());
        Ok::<(), ()>(())
    });
    // With dropping on, a first line whose fields are numbers but for the first is a
    // record cut inside its first number, not a header.
    let cut_first_line =
        opts.drop_truncated_edges && fields.len() >= 2 && rest_numeric && sample.len() >= 2;
    let has_header = match opts.header {
        HeaderMode::Auto => !numeric && !cut_first_line,
        HeaderMode::Present => true,
        HeaderMode::Absent => false,
    };
    let data = if has_header { &sample[1..] } else { sample };
    let (nfields, reference_line) = if has_header {
        (fields.len(), line_no)
    } else {
        let rows: Vec<(usize, usize)> = data
            .iter()
            .take(REFERENCE_SAMPLE + 1)
            .map(|l| (l.line, field_count(l.text, delim)))
            .collect();
        reference_count(&rows).unwrap_or((fields.len(), line_no))
    };
    let at_line = Location::line(source, line_no);
    let at_input = Location::input(source);
    let (mut names, hints): (Vec<String>, Vec<Option<String>>) = if has_header {
        fields.iter().map(|f| split_name_unit(f)).unzip()
    } else {
        (
            (1..=nfields).map(|i| format!("col{i}")).collect(),
            vec![None; nfields],
        )
    };
    for (i, n) in names.iter_mut().enumerate() {
        if n.is_empty() {
            *n = format!("col{}", i + 1);
        }
    }
    if let Some(given) = &opts.column_names {
        if given.len() != nfields {
            let at = if has_header || reference_line == line_no {
                at_line
            } else {
                Location::line(source, reference_line)
            };
            return Err(LogError::InvalidOptions {
                at,
                message: format!(
                    "{} column names given, but the row has {nfields} fields",
                    given.len()
                ),
            });
        }
        names = given.clone();
    }
    let loc = if has_header { &at_line } else { &at_input };
    let hint_unit = |field: usize, column: &str| -> Result<Option<Unit>, LogError> {
        match hints.get(field).and_then(|h| h.as_deref()) {
            None => Ok(None),
            Some(h) => Unit::parse(h).map(Some).map_err(|_| LogError::UnknownUnit {
                at: at_line.clone(),
                unit: h.to_owned(),
                column: column.to_owned(),
                known: KNOWN_UNITS,
            }),
        }
    };

    let mut slots: Vec<Option<Slot>> = vec![None; nfields];
    let mut nout = 0;
    let detected = match (&opts.time_column, opts.detect_time_column && has_header) {
        (None, true) => detect_time_field(&names, &at_line)?,
        _ => None,
    };
    if opts.time_column.is_none() && detected.is_none() && opts.rate_hz.is_none() {
        return Err(LogError::InvalidOptions {
            at: if has_header { at_line } else { at_input },
            message: format!(
                "no time column and no sample rate: no header field is named as a time column \
                 ({}); give the time column (`--time-column NAME|N`) or the sample rate \
                 (`--rate HZ`)",
                TIME_COLUMN_NAMES.join(", ")
            ),
        });
    }
    let time_ref = opts
        .time_column
        .clone()
        .or(detected.map(|f| ColumnRef::Index(f + 1)));
    let time_field = match &time_ref {
        None => None,
        Some(r) => {
            let f = resolve(r, &names, loc)?;
            let unit = match opts.time_unit {
                Some(u) => u,
                None => match hints.get(f).and_then(|h| h.as_deref()) {
                    None => TimeUnit::Seconds,
                    Some(h) => h.parse().map_err(|_| LogError::UnknownUnit {
                        at: at_line.clone(),
                        unit: h.to_owned(),
                        column: names[f].clone(),
                        known: "s, ms, us, ns",
                    })?,
                },
            };
            slots[f] = Some(Slot {
                out: 0,
                scale: unit.to_s(),
                offset: 0.0,
            });
            nout = 1;
            Some(f)
        }
    };
    let week_field = match &opts.week_column {
        Some(r) => Some(resolve(r, &names, loc)?),
        None => None,
    };
    let specs: Vec<ColumnSpec> = if opts.columns.is_empty() {
        (1..=nfields)
            .filter(|&i| Some(i - 1) != time_field && Some(i - 1) != week_field)
            .map(|i| ColumnSpec {
                column: ColumnRef::Index(i),
                unit: None,
                rename: None,
            })
            .collect()
    } else {
        opts.columns.clone()
    };
    let twice = |f: usize, names: &[String]| LogError::InvalidOptions {
        at: at_input.clone(),
        message: format!(
            "column {} ({}) is selected twice (as time, week or data)",
            f + 1,
            names[f]
        ),
    };
    let mut channels = Vec::with_capacity(specs.len());
    for spec in &specs {
        let f = resolve(&spec.column, &names, loc)?;
        if slots[f].is_some() || Some(f) == week_field {
            return Err(twice(f, &names));
        }
        let unit = match &spec.unit {
            Some(u) => u.clone(),
            None => match hint_unit(f, &names[f]) {
                Ok(Some(u)) => u,
                Ok(None) => opts.default_unit.clone().unwrap_or_default(),
                Err(e) if opts.default_unit.is_none() => return Err(e),
                Err(_) => opts.default_unit.clone().unwrap_or_default(),
            },
        };
        slots[f] = Some(Slot {
            out: nout,
            scale: unit.scale_si,
            offset: unit.offset_raw,
        });
        nout += 1;
        let name = spec.rename.clone().unwrap_or_else(|| names[f].clone());
        channels.push((f, name, unit));
    }
    if channels.is_empty() {
        return Err(LogError::InvalidOptions {
            at: at_input,
            message: "no data columns to read (the only column is the time column)".into(),
        });
    }
    if let Some(f) = week_field {
        if time_field.is_none() {
            return Err(LogError::InvalidOptions {
                at: at_input,
                message: "a week column needs a time column (the seconds of week)".into(),
            });
        }
        if slots[f].is_some() {
            return Err(twice(f, &names));
        }
        slots[f] = Some(Slot {
            out: nout,
            scale: 1.0,
            offset: 0.0,
        });
        nout += 1;
    }
    let plan = Plan {
        delim,
        nfields,
        reference_line,
        names,
        slots,
        nout,
        time_field,
        channels,
        header_line: has_header.then_some(line_no),
        week_field,
        time_detected: detected.is_some(),
        max_line: opts.max_line_bytes,
    };
    // The first data row: whole, dropped as a cut record, or an error citing a good row.
    let k = usize::from(has_header);
    let mut note_first = None;
    let mut start = k;
    if let Some(row) = sample.get(k) {
        let found = field_count(row.text, delim);
        let parsed_first = plan.slots.first().is_some_and(Option::is_some);
        let cut = if found < nfields {
            Some(Cut::Fields {
                found,
                expected: nfields,
                reference_line,
            })
        } else if found == nfields
            && parsed_first
            && !field_text(row.text, delim, 0).is_some_and(|t| is_number(&t))
        {
            Some(Cut::Number { field: 1 })
        } else {
            None
        };
        match cut {
            Some(cut) if opts.drop_truncated_edges && sample.len() > k + 1 => {
                note_first = Some(note(source, row.line, Edge::First, &cut, row.text));
                start = k + 1;
            }
            _ if found != nfields => {
                return Err(LogError::Ragged {
                    at: Location::field(source, row.line, ragged_col(row.text, delim, nfields)),
                    found,
                    expected: nfields,
                    reference_line,
                });
            }
            _ => {}
        }
    }
    Ok((plan, start, note_first))
}

fn validate(opts: &TextOptions, source: &str) -> Result<(), LogError> {
    let bad = |message: String| {
        Err(LogError::InvalidOptions {
            at: Location::input(source),
            message,
        })
    };
    if let Some(r) = opts.rate_hz
        && !(r.is_finite() && r > 0.0)
    {
        return bad(format!("rate_hz must be positive and finite, got {r}"));
    }
    if !(opts.gap_factor.is_finite() && opts.gap_factor > 1.0) {
        return bad(format!(
            "gap_factor must be finite and > 1, got {}",
            opts.gap_factor
        ));
    }
    if !(opts.rate_tolerance.is_finite() && opts.rate_tolerance >= 0.0) {
        return bad(format!(
            "rate_tolerance must be finite and ≥ 0, got {}",
            opts.rate_tolerance
        ));
    }
    if opts.time_column.is_none() && opts.rate_hz.is_none() && !opts.detect_time_column {
        return bad(
            "no time column and no sample rate: cannot determine the sample interval τ0; give \
             the time column (`--time-column NAME|N`) or the sample rate (`--rate HZ`)"
                .into(),
        );
    }
    Ok(())
}

/// Row → 1-based line lookup from sparse anchors.
struct LineMap {
    anchors: Vec<(usize, usize)>,
}

impl LineMap {
    fn line_of(&self, row: usize) -> usize {
        let i = self.anchors.partition_point(|a| a.0 <= row);
        match i.checked_sub(1).and_then(|i| self.anchors.get(i)) {
            Some(&(r, l)) => l + (row - r),
            None => row + 1,
        }
    }
}

fn read_impl<R: Read>(
    mut reader: R,
    source: &str,
    opts: &TextOptions,
    size_hint: Option<u64>,
) -> Result<ImuLog, LogError> {
    validate(opts, source)?;
    let io = |error| LogError::Io {
        path: source.to_owned(),
        error,
    };
    let threads = rayon::current_num_threads().max(1);
    let mut buf = vec![0u8; opts.chunk_bytes.max(64)];
    let mut filled = 0;
    let mut eof = false;
    let mut plan: Option<Plan> = None;
    let mut line_base = 1usize; // 1-based line number of buf[0]
    let mut out: Vec<Vec<f64>> = Vec::new();
    let mut rows_total = 0usize;
    let mut anchors: Vec<(usize, usize)> = Vec::new();
    let mut bytes_per_row: Option<f64> = None;
    let mut notes: Vec<String> = Vec::new();
    // Line and text of a last record kept although it had no line end.
    let mut unterminated_last: Option<(usize, Vec<u8>)> = None;
    // Rows the header of a file written by driftless states (`write::write_csv`), and
    // whether it ends with the end mark; whether the input read so far does.
    let mut declared: Option<(usize, bool)> = None;
    let mut ends_marked = false;
    // Bytes of the input before buf[0].
    let mut consumed = 0u64;
    loop {
        while filled < buf.len() && !eof {
            match reader.read(&mut buf[filled..]) {
                Ok(0) => eof = true,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        }
        // The input's first SNIFF_BYTES, whatever the chunk size: read them whole before
        // judging (the share of bytes that are not UTF-8 is a share of this window), once.
        if consumed == 0 {
            if !eof && filled < SNIFF_BYTES {
                buf.resize(SNIFF_BYTES, 0);
                continue;
            }
            if let Some(e) = binary_error(&buf[..filled.min(SNIFF_BYTES)], 0, source) {
                return Err(e);
            }
        }
        let end = if eof {
            filled
        } else {
            match buf[..filled].iter().rposition(|&b| b == b'\n') {
                Some(i) => i + 1,
                None if filled > opts.max_line_bytes => {
                    // A line longer than the cap: stop before buffering more of it.
                    return Err(
                        binary_error(&buf[..filled.min(SNIFF_BYTES)], consumed, source)
                            .unwrap_or_else(|| LogError::LineTooLong {
                                at: Location::line(source, line_base),
                                limit: opts.max_line_bytes,
                            }),
                    );
                }
                None => {
                    // One line longer than the buffer: grow and read on.
                    let n = buf.len();
                    buf.resize(n.saturating_mul(2), 0);
                    continue;
                }
            }
        };
        let region = &buf[..end];
        let mut start = 0;
        if line_base == 1 && plan.is_none() {
            declared = declared.or_else(|| declared_rows(region));
        }
        let tail = region.trim_ascii_end();
        if !tail.is_empty() {
            ends_marked = tail.ends_with(super::write::END_MARK.as_bytes());
        }
        if plan.is_none() {
            let mut offset = 0;
            let mut sample = Vec::new();
            let mut starts = Vec::new();
            for (i, line) in lines(region).enumerate() {
                let this_len = line_len_with_end(region, offset);
                if line.len() > opts.max_line_bytes {
                    let at = consumed + offset as u64;
                    return Err(
                        binary_error(&line[..line.len().min(SNIFF_BYTES)], at, source)
                            .unwrap_or_else(|| LogError::LineTooLong {
                                at: Location::line(source, line_base + i),
                                limit: opts.max_line_bytes,
                            }),
                    );
                }
                let euroc = sample.is_empty().then(|| euroc_header(line)).flatten();
                if let Some(text) = euroc.or((!is_blank_or_comment(line)).then_some(line)) {
                    starts.push(offset);
                    sample.push(SampleLine {
                        line: line_base + i,
                        end: offset + this_len,
                        text,
                    });
                    if sample.len() > REFERENCE_SAMPLE + 2 {
                        break;
                    }
                }
                offset += this_len;
            }
            if !eof && !sample.is_empty() && sample.len() <= REFERENCE_SAMPLE + 2 {
                // The plan's votes (delimiter, reference field count) take the same lines
                // whatever the chunk size: read on until the sample is full or the input
                // ends (at most REFERENCE_SAMPLE + 3 lines of at most `max_line_bytes`).
                let n = buf.len();
                buf.resize(n.saturating_mul(2), 0);
                continue;
            }
            if sample.is_empty() {
                line_base += lines(region).count();
                start = end;
            } else {
                let (p, first, note_first) = make_plan(&sample, source, opts)?;
                notes.extend(note_first);
                match (sample.get(first), first.checked_sub(1).map(|i| &sample[i])) {
                    (Some(row), _) => {
                        start = starts[first];
                        line_base = row.line;
                    }
                    (None, Some(prev)) => {
                        start = prev.end;
                        line_base = prev.line + 1;
                    }
                    (None, None) => {}
                }
                plan = Some(p);
            }
        }
        if let Some(p) = &plan
            && start < end
        {
            // The last data record, parsed on its own when it may be dropped.
            let (body_end, tail) = match (eof && opts.drop_truncated_edges)
                .then(|| last_data_line(&region[start..end], |l| !is_blank_or_comment(l)))
                .flatten()
            {
                Some((ls, le, terminated)) => {
                    (start + ls, Some((start + ls, start + le, terminated)))
                }
                None => (end, None),
            };
            let data = &region[start..body_end];
            let pieces = split_pieces(data, if data.len() >= (1 << 20) { threads } else { 1 });
            let row_guess = bytes_per_row
                .map(|b| ((data.len() as f64 / pieces.len() as f64) / b * 1.05) as usize + 16)
                .unwrap_or(0);
            let results: Vec<Result<PieceOut, PieceErr>> = if pieces.len() > 1 {
                pieces
                    .par_iter()
                    .map(|s| parse_piece(s, p, row_guess))
                    .collect()
            } else {
                pieces
                    .iter()
                    .map(|s| parse_piece(s, p, row_guess))
                    .collect()
            };
            let region_rows: usize = results
                .iter()
                .map(|r| r.as_ref().map_or(0, |o| o.rows))
                .sum();
            if out.is_empty() {
                out = (0..p.nout).map(|_| Vec::new()).collect();
                if region_rows > 0 {
                    let bpr = data.len() as f64 / region_rows as f64;
                    bytes_per_row = Some(bpr);
                    let est = match size_hint {
                        Some(size) => (size as f64 / bpr * 1.02) as usize + 1024,
                        None => region_rows,
                    };
                    for c in &mut out {
                        c.reserve_exact(est);
                    }
                }
            }
            let mut piece_start = start;
            for (r, piece) in results.into_iter().zip(&pieces) {
                let this_start = piece_start;
                piece_start += piece.len();
                match r {
                    Ok(piece) => {
                        for (o, c) in out.iter_mut().zip(&piece.cols) {
                            if o.capacity() - o.len() < c.len() {
                                // Estimate too low: grow by at least 1/8 rather than doubling.
                                o.reserve_exact(c.len().max(o.capacity() / 8));
                            }
                            o.extend_from_slice(c);
                        }
                        for &(r, l) in &piece.anchors {
                            let (row, line) = (rows_total + r, line_base + l);
                            let predicted = anchors.last().map(|&(ar, al)| al + (row - ar));
                            if predicted != Some(line) {
                                anchors.push((row, line));
                            }
                        }
                        rows_total += piece.rows;
                        line_base += piece.lines;
                    }
                    Err(e) => {
                        // A bad line holding binary data is reported as such.
                        let line = piece.get(e.byte..).unwrap_or(&[]);
                        let len = line.iter().position(|&b| b == b'\n').unwrap_or(line.len());
                        let line = &line[..len.min(SNIFF_BYTES)];
                        let at = consumed + (this_start + e.byte) as u64;
                        return Err(binary_error(line, at, source)
                            .unwrap_or_else(|| piece_error(e, line_base, p, source)));
                    }
                }
            }
            if let Some((ls, le, terminated)) = tail {
                let text = region[ls..le]
                    .strip_suffix(b"\r")
                    .unwrap_or(&region[ls..le]);
                let mut row: Vec<Vec<f64>> = (0..p.nout).map(|_| Vec::with_capacity(1)).collect();
                match parse_line(text, p, &mut row) {
                    Ok(_) => {
                        if out.is_empty() {
                            out = (0..p.nout).map(|_| Vec::new()).collect();
                        }
                        for (o, c) in out.iter_mut().zip(&row) {
                            o.extend_from_slice(c);
                        }
                        if anchors.last().map(|&(ar, al)| al + (rows_total - ar)) != Some(line_base)
                        {
                            anchors.push((rows_total, line_base));
                        }
                        rows_total += 1;
                        if !terminated {
                            unterminated_last = Some((line_base, text.to_vec()));
                        }
                    }
                    Err((col, kind)) => {
                        let found = field_count(text, p.delim);
                        let cut = match kind {
                            FieldErr::Ragged { found } if found < p.nfields => Some(Cut::Fields {
                                found,
                                expected: p.nfields,
                                reference_line: p.reference_line,
                            }),
                            FieldErr::NonNumeric { field, .. } | FieldErr::Empty { field }
                                if field == found =>
                            {
                                Some(Cut::Number { field })
                            }
                            _ => None,
                        };
                        match cut {
                            Some(cut) => {
                                notes.push(note(source, line_base, Edge::Last, &cut, text))
                            }
                            None => {
                                return Err(piece_error(
                                    PieceErr {
                                        line: 0,
                                        byte: 0,
                                        col,
                                        kind,
                                    },
                                    line_base,
                                    p,
                                    source,
                                ));
                            }
                        }
                    }
                }
            }
        }
        if eof {
            break;
        }
        buf.copy_within(end..filled, 0);
        filled -= end;
        consumed += end as u64;
    }
    let Some(plan) = plan else {
        return Err(LogError::Empty {
            at: Location::input(source),
        });
    };
    if rows_total == 0 {
        return Err(match plan.header_line {
            Some(l) => LogError::HeaderOnly {
                at: Location::line(source, l),
            },
            None => LogError::Empty {
                at: Location::input(source),
            },
        });
    }
    // A last record without a line end whose time (its last field) does not advance was
    // cut inside the time stamp.
    if let (Some((line, text)), Some(tf), Some(t)) =
        (&unterminated_last, plan.time_field, out.first())
        && tf + 1 == plan.nfields
        && let [.., previous_s, time_s] = t[..]
        && time_s <= previous_s
    {
        let cut = Cut::Time { time_s, previous_s };
        notes.push(note(source, *line, Edge::Last, &cut, text));
        for c in &mut out {
            c.pop();
        }
        rows_total -= 1;
    }
    if let Some((expected, marked)) = declared
        && (expected != rows_total || (marked && !ends_marked))
    {
        return Err(LogError::RowCountMismatch {
            at: Location::input(source),
            expected,
            found: rows_total,
            end_mark: if marked && !ends_marked {
                "its last line is missing"
            } else {
                "its last line is there"
            },
        });
    }
    for c in &mut out {
        c.shrink_to_fit();
    }
    let map = LineMap { anchors };
    if plan.time_detected
        && let Some(f) = plan.time_field
    {
        notes.push(format!(
            "{source}: column {} ({}) taken for the time by its name (`--time-column` names \
             another)",
            f + 1,
            plan.names[f]
        ));
    }
    let week = match plan.week_field {
        Some(wf) => {
            let weeks = out.pop().unwrap_or_default();
            Some(combine_weeks(&mut out[0], &weeks, wf, &plan, &map, source)?)
        }
        None => None,
    };
    let mut cols = out.into_iter();
    let time_s = if plan.time_field.is_some() {
        cols.next()
    } else {
        None
    };
    let (tau0_s, segments, gaps) = match (&time_s, plan.time_field) {
        (Some(t), Some(tf)) => time_analysis(t, tf, &plan, &map, source, opts)?,
        _ => {
            let rate = opts.rate_hz.unwrap_or(f64::NAN);
            (
                1.0 / rate,
                std::iter::once(0..rows_total).collect(),
                Vec::new(),
            )
        }
    };
    let channels = plan
        .channels
        .iter()
        .zip(cols)
        .map(|((_, name, unit), values)| Channel {
            name: name.clone(),
            quantity: unit.quantity,
            source_unit: unit.label.clone(),
            values,
        })
        .collect();
    Ok(ImuLog {
        source: source.to_owned(),
        time_s,
        tau0_s,
        channels,
        segments,
        gaps,
        week,
        notes,
    })
}

/// Seconds of week + week numbers → seconds from the start of the first row's week
/// (`t += (week − week₀) × 604 800 s`); returns week₀. Weeks must be whole numbers in
/// 0–65 535.
fn combine_weeks(
    t: &mut [f64],
    weeks: &[f64],
    wf: usize,
    plan: &Plan,
    map: &LineMap,
    source: &str,
) -> Result<u16, LogError> {
    const WEEK_S: f64 = 604_800.0;
    let name = plan.names.get(wf).cloned().unwrap_or_default();
    for (i, &w) in weeks.iter().enumerate() {
        if !(w.fract() == 0.0 && (0.0..=f64::from(u16::MAX)).contains(&w)) {
            return Err(LogError::InvalidValue {
                at: Location::line(source, map.line_of(i)),
                message: format!(
                    "week {w} in column {} ({name}) is not a whole number in 0–65535",
                    wf + 1
                ),
            });
        }
    }
    let w0 = weeks.first().copied().unwrap_or(0.0);
    for (ti, &w) in t.iter_mut().zip(weeks) {
        *ti += (w - w0) * WEEK_S;
    }
    Ok(w0 as u16)
}

/// Length of the line starting at `offset` including its `\n`.
fn line_len_with_end(region: &[u8], offset: usize) -> usize {
    let rest = region.get(offset..).unwrap_or(&[]);
    match rest.iter().position(|&b| b == b'\n') {
        Some(i) => i + 1,
        None => rest.len(),
    }
}

/// Splits `data` into about `k` pieces at line ends.
fn split_pieces(data: &[u8], k: usize) -> Vec<&[u8]> {
    let mut pieces = Vec::with_capacity(k);
    let mut start = 0;
    for j in 1..k {
        let target = (data.len() * j / k).max(start);
        let cut = match data
            .get(target..)
            .and_then(|r| r.iter().position(|&b| b == b'\n'))
        {
            Some(i) => target + i + 1,
            None => data.len(),
        };
        if cut > start {
            pieces.push(&data[start..cut]);
            start = cut;
        }
    }
    if start < data.len() || pieces.is_empty() {
        pieces.push(&data[start..]);
    }
    pieces
}

fn piece_error(e: PieceErr, line_base: usize, plan: &Plan, source: &str) -> LogError {
    let at = Location::field(source, line_base + e.line, e.col);
    let name = |field: usize| plan.names.get(field - 1).cloned().unwrap_or_default();
    match e.kind {
        FieldErr::NonNumeric { field, value } => LogError::NonNumeric {
            at,
            value,
            field,
            name: name(field),
        },
        FieldErr::Empty { field } => LogError::EmptyField {
            at,
            field,
            name: name(field),
        },
        FieldErr::NonFinite { field, value } => LogError::NonFinite {
            at,
            value,
            field,
            name: name(field),
        },
        FieldErr::Ragged { found } => LogError::Ragged {
            at,
            found,
            expected: plan.nfields,
            reference_line: plan.reference_line,
        },
        FieldErr::TooLong => LogError::LineTooLong {
            at: Location::line(source, line_base + e.line),
            limit: plan.max_line,
        },
    }
}

type TimeResult = (f64, Vec<Range<usize>>, Vec<TimeGap>);

fn time_analysis(
    t: &[f64],
    tf: usize,
    plan: &Plan,
    map: &LineMap,
    source: &str,
    opts: &TextOptions,
) -> Result<TimeResult, LogError> {
    let name = plan.names.get(tf).cloned().unwrap_or_default();
    let field = tf + 1;
    for i in 1..t.len() {
        let (a, b) = (t[i - 1], t[i]);
        if b < a {
            return Err(LogError::NonMonotonicTime {
                at: Location::line(source, map.line_of(i)),
                field,
                name,
                time_s: b,
                previous_s: a,
            });
        }
        if b == a {
            return Err(LogError::DuplicateTime {
                at: Location::line(source, map.line_of(i)),
                field,
                name,
                time_s: b,
            });
        }
    }
    let tau0_s = if t.len() >= 2 {
        let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = dt.len() / 2;
        let (_, m, _) = dt.select_nth_unstable_by(mid, f64::total_cmp);
        let mut median = *m;
        if dt.len().is_multiple_of(2) {
            // even count: mean of the two middle values; the lower one is the max of the left half
            let lower = dt[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
            median = 0.5 * (median + lower);
        }
        if let Some(rate) = opts.rate_hz {
            let nominal = 1.0 / rate;
            if ((median - nominal) / nominal).abs() > opts.rate_tolerance {
                return Err(LogError::RateMismatch {
                    at: Location::input(source),
                    rate_hz: rate,
                    median_dt_s: median,
                    measured_hz: 1.0 / median,
                    tolerance_pct: opts.rate_tolerance * 100.0,
                });
            }
        }
        median
    } else {
        match opts.rate_hz {
            Some(r) => 1.0 / r,
            None => {
                return Err(LogError::InvalidOptions {
                    at: Location::input(source),
                    message: "a single time stamp cannot give the sample interval τ0; give rate_hz"
                        .into(),
                });
            }
        }
    };
    let limit = opts.gap_factor * tau0_s;
    if let Some(r) = rate_change(t, limit) {
        return Err(LogError::RateChange {
            at: Location::line(source, map.line_of(r.start)),
            interval_s: r.interval_s,
            other_interval_s: r.other_interval_s,
            first: map.line_of(r.start),
            last: map.line_of(r.end),
            start_s: t[r.start],
            end_s: t[r.end],
        });
    }
    let mut gaps = Vec::new();
    for i in 1..t.len() {
        let d = t[i] - t[i - 1];
        if d > limit {
            if opts.gap_policy == GapPolicy::Error {
                return Err(LogError::TimeGap {
                    at: Location::line(source, map.line_of(i)),
                    field,
                    name,
                    duration_s: d,
                    ratio: d / tau0_s,
                    tau0_s,
                    gap_factor: opts.gap_factor,
                });
            }
            gaps.push(TimeGap {
                index: i,
                start_s: t[i - 1],
                duration_s: d,
            });
        }
    }
    let segments = match opts.gap_policy {
        GapPolicy::Split => {
            let mut s = Vec::with_capacity(gaps.len() + 1);
            let mut start = 0;
            for g in &gaps {
                s.push(start..g.index);
                start = g.index;
            }
            s.push(start..t.len());
            s
        }
        _ => std::iter::once(0..t.len()).collect(),
    };
    Ok((tau0_s, segments, gaps))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_cover_data_at_line_ends() {
        let data = b"1\n22\n333\n4444\n55555\n";
        for k in 1..8 {
            let p = split_pieces(data, k);
            assert_eq!(p.concat(), data.to_vec());
            for piece in &p {
                assert_eq!(piece.last(), Some(&b'\n'));
            }
        }
    }

    /// The outcome must not depend on how much of the input the first chunk holds:
    /// inputs whose first lines disagree on the delimiter, and one whose first bytes are
    /// partly not UTF-8 (found by fuzzing), give the same log or error at every chunk size
    /// as in one piece.
    #[test]
    fn chunk_size_does_not_change_the_outcome() {
        let inputs: [&[u8]; 4] = [
            b"# rate-only log\ngyro_x [deg/\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\
              \x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\
              \x8d\x8d\x8d\x8ds];gyro_y [deg/s];gyro_z [deg/s]\n0.5;-0.25;1e-3\n\
              0.52;-0.26;1.1e-3\n0.49;-0.24;0.9e-3\n",
            b"time,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n0.00,nan-0.02,0.03,0.1,0.2,-9.8\n\
              0.01,0.011,-0.021,0.031,0.11,0.21,-9.81\n0.02,0.012,-0.022,0.032,0.12,0.22,-9.79\n",
            b"\" rate-only log\ngyro_x [deg/s];gyro_y [deg/s];gyro_z [deg/s]\n0.5;-0.25;1e-3\n\
              0.52;-0.26;1.1e-3\n0.49;-0.24;0.9e-3\n",
            b"t,a,b\n0,1,2\n1 2 3\n2 3 4\n3 4 5\n4 5 6\n",
        ];
        for (k, input) in inputs.into_iter().enumerate() {
            let base = TextOptions::default().with_rate_hz(100.0);
            let whole = read_text_bytes(input, "f", &base).map_err(|e| e.to_string());
            for chunk_bytes in [1, 16, 40, 64, 65, 100] {
                let o = TextOptions {
                    chunk_bytes,
                    ..base.clone()
                };
                let chunked = read_text(input, "f", &o).map_err(|e| e.to_string());
                assert_eq!(chunked, whole, "input {k}, chunk {chunk_bytes}");
            }
        }
    }

    #[test]
    fn header_units_in_brackets() {
        assert_eq!(
            split_name_unit("gyro_x [deg/s]"),
            ("gyro_x".into(), Some("deg/s".into()))
        );
        assert_eq!(
            split_name_unit("tick(ms)"),
            ("tick".into(), Some("ms".into()))
        );
        assert_eq!(split_name_unit("acc_z"), ("acc_z".into(), None));
    }

    #[test]
    fn delimiter_detection() {
        assert_eq!(detect_delimiter(b"1,2,3"), Delim::Byte(b','));
        assert_eq!(detect_delimiter(b"1;2,5;3"), Delim::Byte(b';'));
        assert_eq!(detect_delimiter(b"a\tb c\td"), Delim::Byte(b'\t'));
        assert_eq!(detect_delimiter(b"  1\t\t2 3"), Delim::Whitespace);
        assert_eq!(detect_delimiter(b"1 2 3 # a, b"), Delim::Whitespace);
    }

    #[test]
    fn line_map_follows_anchors() {
        let m = LineMap {
            anchors: vec![(0, 3), (5, 10)],
        };
        assert_eq!(m.line_of(0), 3);
        assert_eq!(m.line_of(4), 7);
        assert_eq!(m.line_of(5), 10);
        assert_eq!(m.line_of(9), 14);
    }
}

#[cfg(test)]
mod row_count_tests {
    use super::*;

    fn opts() -> TextOptions {
        TextOptions {
            time_column: Some(ColumnRef::Name("time".into())),
            ..TextOptions::default()
        }
    }

    #[test]
    fn a_driftless_csv_cut_at_a_line_end_is_an_error() {
        let rows: String = (0..50)
            .map(|i| format!("{},{}\n", i as f64 * 0.01, i))
            .collect();
        let whole = format!(
            "# driftless log; source: test\n# tau0_s: 0.01; rows: 50; last line: # end of driftless log\n\
             time [s],gyro_x [rad/s]\n{rows}# end of driftless log\n"
        );
        assert_eq!(
            read_text_bytes(whole.as_bytes(), "w.csv", &opts())
                .unwrap()
                .len(),
            50
        );
        let cut: String = whole.lines().take(40).map(|l| format!("{l}\n")).collect();
        let e = read_text_bytes(cut.as_bytes(), "w.csv", &opts()).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(
                e,
                LogError::RowCountMismatch {
                    expected: 50,
                    found: 37,
                    ..
                }
            ) && msg.contains("w.csv"),
            "{msg}"
        );
        // All rows there, the end mark cut off.
        let unmarked = whole.strip_suffix("# end of driftless log\n").unwrap();
        let msg = read_text_bytes(unmarked.as_bytes(), "w.csv", &opts())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("50 found, its last line is missing"), "{msg}");
        // A file of an earlier writer: rows counted, no end mark expected.
        let older = unmarked.replace("; last line: # end of driftless log", "");
        assert_eq!(
            read_text_bytes(older.as_bytes(), "w.csv", &opts())
                .unwrap()
                .len(),
            50
        );
        // Without the driftless header the rows present are read.
        let other = cut.replacen("# driftless log", "# some log", 1);
        assert_eq!(
            read_text_bytes(other.as_bytes(), "o.csv", &opts())
                .unwrap()
                .len(),
            37
        );
    }
}

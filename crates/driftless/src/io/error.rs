//! Reader and writer errors.
//!
//! Every error names the input and, where the problem sits on a line, the place:
//! `PATH:LINE:COL: message`. LINE is 1-based. COL is the 1-based **byte** column of the
//! start of the offending field (what editors and compilers use to jump to a spot); the
//! message itself names the 1-based **field number** and the column's name, e.g.
//! `imu.csv:12:17: non-numeric value "abc" in column 3 (gyro_y)`. Problems that concern a
//! whole row (time order, gaps) name the line and the time column's field number but no
//! byte column; problems with the options or the whole input name only the input.
//!
//! Binary inputs have no lines: errors at one place in them (the autopilot logs of
//! `io::ulog` and `io::dataflash`) are [`LogError::AtByte`], naming the 0-based **byte
//! offset** of the offending message instead, `PATH@byte OFFSET: FORMAT: message` (the
//! offset a hex dump shows).

use std::fmt;

/// Where an error was found: the input's display name, and a line and byte column when
/// they apply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// File path or other display name of the input.
    pub path: String,
    /// 1-based line number, if the error concerns one line.
    pub line: Option<usize>,
    /// 1-based byte column of the offending field, if the error concerns one field.
    pub column: Option<usize>,
}

impl Location {
    /// The whole input.
    pub fn input(path: &str) -> Self {
        Location {
            path: path.to_owned(),
            line: None,
            column: None,
        }
    }
    /// One line of the input.
    pub fn line(path: &str, line: usize) -> Self {
        Location {
            path: path.to_owned(),
            line: Some(line),
            column: None,
        }
    }
    /// One field of one line.
    pub fn field(path: &str, line: usize, column: usize) -> Self {
        Location {
            path: path.to_owned(),
            line: Some(line),
            column: Some(column),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.path)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.column {
                write!(f, ":{col}")?;
            }
        }
        Ok(())
    }
}

/// Why reading or writing a log failed. One error per failed read; a failed read never
/// returns partial data.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// The operating system failed to open, read or write the input/output.
    #[error("{path}: {error}")]
    Io {
        /// Input or output display name.
        path: String,
        /// Underlying error.
        #[source]
        error: std::io::Error,
    },
    /// A field that should hold a number does not.
    #[error("{at}: non-numeric value {value:?} in column {field} ({name})")]
    NonNumeric {
        /// Where.
        at: Location,
        /// The offending text (shortened when long, lossy UTF-8).
        value: String,
        /// 1-based field number.
        field: usize,
        /// Column name.
        name: String,
    },
    /// A field is empty (two delimiters in a row).
    #[error("{at}: empty value in column {field} ({name})")]
    EmptyField {
        /// Where.
        at: Location,
        /// 1-based field number.
        field: usize,
        /// Column name.
        name: String,
    },
    /// NaN, infinity, or a number too large for f64.
    #[error(
        "{at}: non-finite value {value:?} in column {field} ({name}); NaN and infinity are not valid samples"
    )]
    NonFinite {
        /// Where.
        at: Location,
        /// The offending text.
        value: String,
        /// 1-based field number.
        field: usize,
        /// Column name.
        name: String,
    },
    /// A row with a different number of fields than the header / first row.
    #[error("{at}: row has {found} fields, expected {expected} (as on line {reference_line})")]
    Ragged {
        /// Where (the column is where the extra field starts or where the line ends).
        at: Location,
        /// Fields found on this row (counting stops at `expected + 1`).
        found: usize,
        /// Fields on the reference row.
        expected: usize,
        /// Line of the header or reference data row that fixed the field count: the first
        /// data row, or the first of the rows after it when the first row is shorter than
        /// most of them — never the offending row itself.
        reference_line: usize,
    },
    /// A time stamp smaller than its predecessor.
    #[error(
        "{at}: time goes backwards in column {field} ({name}): {time_s} s after {previous_s} s"
    )]
    NonMonotonicTime {
        /// Where.
        at: Location,
        /// 1-based field number of the time column.
        field: usize,
        /// Time column name.
        name: String,
        /// Time on this row, s.
        time_s: f64,
        /// Time on the previous data row, s.
        previous_s: f64,
    },
    /// A time stamp equal to its predecessor.
    #[error(
        "{at}: duplicated time stamp {time_s} s in column {field} ({name}), same as the previous data row"
    )]
    DuplicateTime {
        /// Where.
        at: Location,
        /// 1-based field number of the time column.
        field: usize,
        /// Time column name.
        name: String,
        /// The repeated time, s.
        time_s: f64,
    },
    /// A gap in time larger than the configured factor times τ0 (with `GapPolicy::Error`).
    #[error(
        "{at}: time gap of {d} s before this row ({ratio:.1} × τ0, τ0 = {t} s, limit {gap_factor} × τ0) in column {field} ({name}); accept gaps with the gap policy `split` or `bridge` (CLI: --gaps split|bridge)",
        d = crate::io::error::sig6(*duration_s),
        t = crate::io::error::sig6(*tau0_s)
    )]
    TimeGap {
        /// Where (the first row after the gap).
        at: Location,
        /// 1-based field number of the time column.
        field: usize,
        /// Time column name.
        name: String,
        /// Length of the interval, s.
        duration_s: f64,
        /// `duration_s / tau0_s`.
        ratio: f64,
        /// Nominal interval, s.
        tau0_s: f64,
        /// The configured limit factor.
        gap_factor: f64,
    },
    /// The time column's median interval disagrees with the given rate.
    #[error(
        "{at}: rate {rate_hz} Hz given, but the time column's median interval is {median_dt_s} s ({measured_hz} Hz); they differ by more than {tolerance_pct} %"
    )]
    RateMismatch {
        /// The input.
        at: Location,
        /// Rate the caller gave, Hz.
        rate_hz: f64,
        /// Median time-stamp difference, s.
        median_dt_s: f64,
        /// `1 / median_dt_s`, Hz.
        measured_hz: f64,
        /// Allowed relative difference, %.
        tolerance_pct: f64,
    },
    /// No data rows at all (empty, blank or comment-only input).
    #[error("{at}: no data rows (the input is empty or holds only comments and blank lines)")]
    Empty {
        /// The input.
        at: Location,
    },
    /// A header but no data rows.
    #[error("{at}: header row but no data rows")]
    HeaderOnly {
        /// The header's line.
        at: Location,
    },
    /// A unit string that is not recognised.
    #[error("{at}: unknown unit {unit:?} for column {column}; known units: {known}")]
    UnknownUnit {
        /// Where the unit came from (the input for options, the header line for header hints).
        at: Location,
        /// The unit text.
        unit: String,
        /// Which column it was for.
        column: String,
        /// List of accepted units.
        known: &'static str,
    },
    /// A column name or index the caller asked for that the input does not have.
    #[error("{at}: no column {column} (columns: {available})")]
    UnknownColumn {
        /// The input (the header line when there is one).
        at: Location,
        /// The requested name or `#index`.
        column: String,
        /// The columns the input has.
        available: String,
    },
    /// Options that contradict each other or the input.
    #[error("{at}: {message}")]
    InvalidOptions {
        /// The input.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// Binary log: not a driftless binary log.
    #[error("{at}: not a driftless binary log (bad magic {found:?}, expected \"DRIFTLOG\")")]
    BadMagic {
        /// The input.
        at: Location,
        /// The first bytes found (lossy).
        found: String,
    },
    /// Binary log: a format version this build does not read.
    #[error(
        "{at}: unsupported driftless binary log version {version} (this build reads version {supported})"
    )]
    UnsupportedVersion {
        /// The input.
        at: Location,
        /// Version in the file.
        version: u32,
        /// Version this build reads.
        supported: u32,
    },
    /// Binary log: the header text is malformed or inconsistent.
    #[error("{at}: bad binary log header: {message}")]
    BadHeader {
        /// The input.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// Binary log: the input ends before the header says it should.
    #[error("{at}: truncated binary log: {message}")]
    Truncated {
        /// The input.
        at: Location,
        /// What was missing.
        message: String,
    },
    /// Text log written by driftless: fewer or more data rows than its header states (the
    /// file was cut at a line end, e.g. by an interrupted write).
    #[error(
        "{at}: truncated log: its header says {expected} rows, {found} found, {end_mark} (the \
         file was cut, e.g. by an interrupted write; to read the rows present, delete the \
         header's second comment line)"
    )]
    RowCountMismatch {
        /// The input.
        at: Location,
        /// Rows the header states.
        expected: usize,
        /// Data rows read.
        found: usize,
        /// Whether the end mark the header announces is there.
        end_mark: &'static str,
    },
    /// Binary log: the data size disagrees with the header's row and column counts.
    #[error(
        "{at}: binary log size mismatch: header says {rows} rows × {columns} columns = {expected_bytes} bytes of data, found {found_bytes}"
    )]
    CountMismatch {
        /// The input.
        at: Location,
        /// Rows in the header.
        rows: usize,
        /// Columns (time included) in the header.
        columns: usize,
        /// Bytes of data the header implies.
        expected_bytes: u64,
        /// Bytes of data present.
        found_bytes: u64,
    },
    /// Binary log: a stored sample is NaN or infinite.
    #[error("{at}: non-finite value in binary log column {column}, row {row}")]
    NonFiniteStored {
        /// The input.
        at: Location,
        /// Column name.
        column: String,
        /// 0-based row.
        row: usize,
    },
    /// Binary log: the data contradict the format's invariants (time order, segments).
    #[error("{at}: corrupt binary log: {message}")]
    Corrupt {
        /// The input.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// A value that parses but is not acceptable: out of range, of the wrong YAML type or
    /// length, in an apparently wrong unit, a GNSS σ ≤ 0, … (navigation formats).
    #[error("{at}: {message}")]
    InvalidValue {
        /// Where.
        at: Location,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A file in a fixed third-party format (KF-GINS YAML, RTKLIB `.pos` / `.tag`, …) whose
    /// structure is wrong or unsupported.
    #[error("{at}: malformed {format}: {message}")]
    Malformed {
        /// Where.
        at: Location,
        /// The format's name.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A binary third-party log (PX4 ULog, ArduPilot DataFlash) that is wrong at one place:
    /// a malformed message, a value that is not acceptable (NaN sample, time going back).
    #[error("{path}@byte {byte_offset}: {format}: {message}")]
    AtByte {
        /// Input display name.
        path: String,
        /// 0-based byte offset of the offending message.
        byte_offset: u64,
        /// The format's name.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Text reader: the input holds binary data (a NUL or other control byte, or mostly
    /// bytes that are not UTF-8), so it is no text log; nothing is parsed from it.
    #[error(
        "{path}: binary data, not a text log (byte offset {byte_offset}: {what}); if it is a \
         driftless/ULog/DataFlash binary, it lacks the magic bytes"
    )]
    BinaryData {
        /// Input display name.
        path: String,
        /// 0-based byte offset of the first byte that gave it away.
        byte_offset: u64,
        /// What was found there.
        what: String,
    },
    /// Text reader: a line longer than the reader's cap (`TextOptions::max_line_bytes`);
    /// reading stops there instead of buffering the line whole.
    #[error(
        "{at}: line {line} is longer than {limit_text} ({limit} bytes): binary data, or not a \
         text log? (the lines of a text log are short; for real lines this long raise \
         TextOptions::max_line_bytes)",
        line = at.line.unwrap_or(0),
        limit_text = crate::io::input::human_bytes(*limit as u64)
    )]
    LineTooLong {
        /// The line.
        at: Location,
        /// The cap, bytes.
        limit: usize,
    },
    /// The sample interval changes for a stretch of the log (shorter or longer intervals
    /// than the median, sustained, not single late samples or isolated gaps): the log holds
    /// two sample rates. Refused, never averaged into one τ0.
    #[error(
        "{at}: the sample rate changes: {main} Hz (interval {dt} s) for most of the log, but \
         {other} Hz (interval {other_dt} s) from {counted_as} {first} (t = {t0} s) to \
         {counted_as} {last} (t = {t1} s) by the time stamps; an analysis needs one rate: cut \
         the log into parts of one rate each, or resample it",
        counted_as = if at.line.is_some() { "line" } else { "sample" },
        main = crate::io::error::sig6(1.0 / *interval_s),
        dt = crate::io::error::sig6(*interval_s),
        other = crate::io::error::sig6(1.0 / *other_interval_s),
        other_dt = crate::io::error::sig6(*other_interval_s),
        t0 = crate::io::error::sig6(*start_s),
        t1 = crate::io::error::sig6(*end_s)
    )]
    RateChange {
        /// The input; for a text log, at the stretch's first line.
        at: Location,
        /// The interval of most of the log, s.
        interval_s: f64,
        /// The interval in the stretch, s.
        other_interval_s: f64,
        /// First line of the stretch (text logs: `at`'s line), or its first 0-based sample
        /// (binary and autopilot logs, which have no lines).
        first: usize,
        /// Last line or 0-based sample of the stretch, as `first`.
        last: usize,
        /// Time at the stretch's first line, s.
        start_s: f64,
        /// Time at the stretch's last line, s.
        end_s: f64,
    },
    /// Writer: the log itself is inconsistent (channel lengths differ, …).
    #[error("{at}: cannot write log: {message}")]
    InvalidLog {
        /// The output.
        at: Location,
        /// What is wrong.
        message: String,
    },
}

impl LogError {
    /// The location the error names.
    pub fn location(&self) -> Option<&Location> {
        use LogError::*;
        match self {
            Io { .. } | AtByte { .. } | BinaryData { .. } => None,
            NonNumeric { at, .. }
            | EmptyField { at, .. }
            | NonFinite { at, .. }
            | Ragged { at, .. }
            | NonMonotonicTime { at, .. }
            | DuplicateTime { at, .. }
            | TimeGap { at, .. }
            | LineTooLong { at, .. }
            | RateChange { at, .. }
            | RateMismatch { at, .. }
            | Empty { at }
            | HeaderOnly { at }
            | UnknownUnit { at, .. }
            | UnknownColumn { at, .. }
            | InvalidOptions { at, .. }
            | BadMagic { at, .. }
            | UnsupportedVersion { at, .. }
            | BadHeader { at, .. }
            | Truncated { at, .. }
            | CountMismatch { at, .. }
            | RowCountMismatch { at, .. }
            | NonFiniteStored { at, .. }
            | Corrupt { at, .. }
            | InvalidLog { at, .. }
            | InvalidValue { at, .. }
            | Malformed { at, .. } => Some(at),
        }
    }

    /// The 0-based byte offset the error names, if any (binary inputs).
    pub fn byte_offset(&self) -> Option<u64> {
        match self {
            LogError::AtByte { byte_offset, .. } | LogError::BinaryData { byte_offset, .. } => {
                Some(*byte_offset)
            }
            _ => None,
        }
    }

    /// The 1-based line the error names, if any.
    pub fn line(&self) -> Option<usize> {
        self.location().and_then(|l| l.line)
    }
}

/// Shortens and sanitises user text for an error message.
pub(crate) fn excerpt(bytes: &[u8]) -> String {
    const MAX: usize = 40;
    let s = String::from_utf8_lossy(bytes);
    if s.chars().count() > MAX {
        let mut t: String = s.chars().take(MAX).collect();
        t.push('…');
        t
    } else {
        s.into_owned()
    }
}

/// A number with at most 6 significant digits, trailing zeros dropped (for messages).
pub fn sig6(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let digits = (5 - v.abs().log10().floor() as i32).clamp(0, 15) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Opens `path` for reading: (file, its size in bytes when it is a regular file — pipes,
/// FIFOs and devices have none —, display name); errors name the file.
pub(crate) fn open_file(
    path: &std::path::Path,
) -> Result<(std::fs::File, Option<u64>, String), LogError> {
    let name = path.display().to_string();
    let io = |error| LogError::Io {
        path: name.clone(),
        error,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    Ok((file, meta.is_file().then_some(meta.len()), name))
}

/// Starts writing `path` atomically ([`crate::io::output::AtomicFile`]): (file, display
/// name); errors name the file. [`commit_file`] puts it under its final name.
pub(crate) fn create_file(
    path: &std::path::Path,
) -> Result<(crate::io::output::AtomicFile, String), LogError> {
    let name = path.display().to_string();
    let file = crate::io::output::AtomicFile::create(path).map_err(|error| LogError::Io {
        path: name.clone(),
        error,
    })?;
    Ok((file, name))
}

/// Flushes, syncs and renames a file from [`create_file`] over its final name.
pub(crate) fn commit_file(file: crate::io::output::AtomicFile, name: &str) -> Result<(), LogError> {
    file.commit().map_err(|error| LogError::Io {
        path: name.to_owned(),
        error,
    })
}

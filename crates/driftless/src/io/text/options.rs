//! Options of the text reader and their parsing from command-line strings.

use std::fmt;
use std::str::FromStr;

use crate::io::error::{Location, LogError};
use crate::io::units::{TimeUnit, Unit};

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
    /// Keep all rows; [`ImuLog::segments`](crate::io::ImuLog::segments) lists the contiguous runs between gaps and
    /// [`ImuLog::gaps`](crate::io::ImuLog::gaps) the gaps.
    Split,
    /// Keep all rows as one segment; [`ImuLog::gaps`](crate::io::ImuLog::gaps) lists the gaps so the caller can warn.
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
    /// (`TIME_COLUMN_NAMES`, when `detect_time_column`) is taken, else the log has no
    /// time stamps and `rate_hz` is needed.
    pub time_column: Option<ColumnRef>,
    /// Take a header field named as a time column (`TIME_COLUMN_NAMES`) for the time
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

pub(super) fn validate(opts: &TextOptions, source: &str) -> Result<(), LogError> {
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

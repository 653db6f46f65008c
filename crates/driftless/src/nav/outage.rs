//! Simulated GNSS outages: the `--outages` specification, its parsing and its resolution
//! into absolute time windows.
//!
//! # Grammar
//!
//! Case-insensitive; numbers are decimal seconds with an optional `s` suffix; spaces are
//! free around every token.
//!
//! * `none` (or an empty string): no outages.
//! * **Explicit windows**: a comma-separated list of `START+LENGTH` items.
//!   * `300+60`: starts 300 s after the **first GNSS epoch**, lasts 60 s.
//!   * `@243600+60`: starts at GPS time 243 600 s (seconds of the GNSS data's week, the
//!     time column of [`crate::io::nav::GnssFixes`]), lasts 60 s.
//!
//!   Relative and absolute items may be mixed; the list need not be sorted.
//! * **Generator**: `N x LENGTH every PERIOD [from START]` — `N` windows of `LENGTH`
//!   seconds, starting every `PERIOD` seconds, the first `START` seconds after the first
//!   GNSS epoch (`START` defaults to `PERIOD`, so the filter first converges for one
//!   period). `×` may be written for `x`. Example: `9x60s every 300s from 300s` gives
//!   windows starting at 300, 600, …, 2700 s.
//! * **Automatic**: `auto:N x LENGTH` (`auto:9x60`, `auto: 9 × 60s`) — `N` windows of
//!   `LENGTH` seconds chosen on a reference trajectory to cover the vehicle's dynamics
//!   (`crate::eval::select::select_outages`). Parsing only records the request: [`resolve`]
//!   cannot place them without the reference and says so
//!   ([`OutageError::NeedsReference`]); `crate::eval::select::resolve_outages` does.
//!
//! # Validation
//!
//! Parsing ([`OutageSpec::from_str`]) rejects malformed text, non-finite or negative
//! numbers, zero lengths, zero counts and a generator whose period is shorter than its
//! length (its windows would overlap). [`resolve`] then checks against the GNSS data:
//! a window longer than the whole GNSS span, starting before the first or ending after
//! the last GNSS epoch, or overlapping another window is an error naming the window(s).
//! Windows that merely touch (one ends where the next starts) are accepted.
//!
//! # Semantics
//!
//! A window is the half-open interval `(start_s, end_s]`: a GNSS epoch t is withheld
//! when `start_s < t ≤ end_s` — the fixes a user deletes from a file to simulate an
//! outage from `start_s` to `end_s`. The fix at `start_s` is still used (the filter is
//! GNSS-aided up to the start), the fix at `end_s` is not, so the navigation solution at
//! `end_s` is pure dead reckoning over the whole length `end_s − start_s` and the first
//! fix used again lies strictly after `end_s`. The filter
//! ([`crate::nav::filter::FilterConfig::outages_s`]), [`is_masked`], the session's
//! evaluation and `crate::eval` all use this convention. See [`TimeSpan::contains`].

use std::str::FromStr;

/// One outage in absolute GPS time (seconds of week of the GNSS data): the crate's
/// interval type read as the half-open (start, end] — the fix at `start_s` is used, the
/// fixes at `start_s < t ≤ end_s` are withheld ([`TimeSpan::contains`]).
pub type OutageWindow = TimeSpan;

/// Where a window's start is measured from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutageStart {
    /// Seconds after the first GNSS epoch.
    AfterFirstGnss(f64),
    /// Absolute GPS time, s of week.
    Gps(f64),
}

/// One explicit window as written: a start and a length, s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutageItem {
    /// Start (relative or absolute).
    pub start: OutageStart,
    /// Length, s (> 0).
    pub length_s: f64,
}

/// A parsed `--outages` specification (see the module docs for the grammar).
#[derive(Clone, Debug, PartialEq)]
pub enum OutageSpec {
    /// No outages.
    None,
    /// Explicit windows, in the order written.
    Windows(Vec<OutageItem>),
    /// `count` windows of `length_s`, starting every `period_s`, the first `start_s` after
    /// the first GNSS epoch.
    Every {
        /// Number of windows (≥ 1).
        count: usize,
        /// Length of each window, s (> 0).
        length_s: f64,
        /// Start-to-start spacing, s (≥ `length_s`).
        period_s: f64,
        /// First start, s after the first GNSS epoch (≥ 0).
        start_s: f64,
    },
    /// `count` windows of `length_s` chosen on a reference trajectory
    /// (`crate::eval::select::select_outages`).
    Auto {
        /// Number of windows (≥ 1).
        count: usize,
        /// Length of each window, s (> 0).
        length_s: f64,
    },
}

/// The GNSS time span outages are resolved against: first and last GNSS epoch, GPS s
/// ([`TimeSpan::of`] of the GNSS time column).
pub use crate::data::TimeSpan;

/// Why an outage specification was rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OutageError {
    /// The text does not follow the grammar.
    #[error(
        "bad outage specification {text:?}: {reason} (expected e.g. \"300+60,600+60\", \"@243600+60\", \"9x60s every 300s from 300s\" or \"auto:9x60\")"
    )]
    Syntax {
        /// The whole specification.
        text: String,
        /// What is wrong, naming the offending piece.
        reason: String,
    },
    /// Two windows overlap.
    #[error("outage windows {first} and {second} overlap")]
    Overlap {
        /// The earlier window (absolute GPS s).
        first: OutageWindow,
        /// The later window.
        second: OutageWindow,
    },
    /// A window is longer than the whole GNSS data.
    #[error("outage window {window} lasts {length_s} s, longer than the GNSS data ({data_s} s)")]
    LongerThanData {
        /// The window.
        window: OutageWindow,
        /// Its length, s.
        length_s: f64,
        /// The GNSS span, s.
        data_s: f64,
    },
    /// A window starts before the first or ends after the last GNSS epoch.
    #[error("outage window {window} lies outside the GNSS data [{} s, {} s]: {reason}", span.start_s, span.end_s)]
    OutsideData {
        /// The window.
        window: OutageWindow,
        /// The GNSS span.
        span: TimeSpan,
        /// Which end is outside.
        reason: &'static str,
    },
    /// `auto:NxL` needs a reference trajectory to choose its windows from.
    #[error(
        "outages \"auto:{count}x{length_s}\" are chosen on a reference trajectory: resolve them \
         with driftless::eval::select::resolve_outages, not against a bare time span"
    )]
    NeedsReference {
        /// Windows asked for.
        count: usize,
        /// Their length, s.
        length_s: f64,
    },
    /// The GNSS span itself is unusable (empty, non-finite or reversed).
    #[error("cannot place outages: GNSS time span [{} s, {} s] is empty or invalid", span.start_s, span.end_s)]
    BadSpan {
        /// The span given.
        span: TimeSpan,
    },
}

fn syntax(text: &str, reason: impl Into<String>) -> OutageError {
    OutageError::Syntax {
        text: text.to_owned(),
        reason: reason.into(),
    }
}

/// Parses `123`, `123.5`, `123s` (seconds, finite, ≥ 0).
fn seconds(piece: &str, what: &str, whole: &str) -> Result<f64, OutageError> {
    let t = piece.trim();
    let num = t.strip_suffix('s').unwrap_or(t).trim_end();
    match num.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(v) => Err(syntax(
            whole,
            format!("{what} {piece:?} must be a finite number ≥ 0, got {v}"),
        )),
        Err(_) => Err(syntax(
            whole,
            format!("{what} {piece:?} is not a number of seconds"),
        )),
    }
}

fn positive(v: f64, piece: &str, what: &str, whole: &str) -> Result<f64, OutageError> {
    if v > 0.0 {
        Ok(v)
    } else {
        Err(syntax(whole, format!("{what} {piece:?} must be > 0")))
    }
}

impl FromStr for OutageSpec {
    type Err = OutageError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let norm = text.trim().to_lowercase().replace('×', "x");
        if norm.is_empty() || norm == "none" {
            return Ok(OutageSpec::None);
        }
        if let Some(rest) = norm.strip_prefix("auto") {
            return parse_auto(text, rest);
        }
        let tokens: Vec<&str> = norm.split_whitespace().collect();
        if let Some(every) = tokens.iter().position(|&t| t == "every") {
            return parse_generator(text, &tokens, every);
        }
        let mut items = Vec::new();
        for piece in norm.split(',') {
            let p = piece.trim();
            if p.is_empty() {
                return Err(syntax(
                    text,
                    "empty item in the list (doubled or trailing comma)",
                ));
            }
            let (abs, body) = match p.strip_prefix('@') {
                Some(rest) => (true, rest),
                None => (false, p),
            };
            let Some((start, length)) = body.split_once('+') else {
                return Err(syntax(
                    text,
                    format!("item {p:?} is not START+LENGTH (nor a generator with \"every\")"),
                ));
            };
            let start_s = seconds(start, "start", text)?;
            let length_s = positive(seconds(length, "length", text)?, length, "length", text)?;
            items.push(OutageItem {
                start: if abs {
                    OutageStart::Gps(start_s)
                } else {
                    OutageStart::AfterFirstGnss(start_s)
                },
                length_s,
            });
        }
        Ok(OutageSpec::Windows(items))
    }
}

/// The `COUNT` and `LENGTH` of a `COUNTxLENGTH` pair: a whole count ≥ 1 and a positive
/// duration.
fn count_and_length(text: &str, n: &str, length: &str) -> Result<(usize, f64), OutageError> {
    let count = match n.parse::<usize>() {
        Ok(c) if c > 0 => c,
        _ => {
            return Err(syntax(
                text,
                format!("count {n:?} must be a whole number ≥ 1"),
            ));
        }
    };
    let length_s = positive(seconds(length, "length", text)?, length, "length", text)?;
    Ok((count, length_s))
}

/// `auto:COUNTxLENGTH`, `rest` the lower-case text after `auto`.
fn parse_auto(text: &str, rest: &str) -> Result<OutageSpec, OutageError> {
    let body: String = rest
        .trim_start()
        .strip_prefix(':')
        .ok_or_else(|| syntax(text, "expected \"auto:COUNTxLENGTH\", e.g. \"auto:9x60\""))?
        .split_whitespace()
        .collect();
    let Some((n, length)) = body.split_once('x') else {
        return Err(syntax(
            text,
            format!("{body:?} after \"auto:\" is not COUNTxLENGTH"),
        ));
    };
    let (count, length_s) = count_and_length(text, n, length)?;
    Ok(OutageSpec::Auto { count, length_s })
}

/// `N x LENGTH every PERIOD [from START]`, tokens already lower-case and split on spaces.
fn parse_generator(text: &str, tokens: &[&str], every: usize) -> Result<OutageSpec, OutageError> {
    let head: String = tokens[..every].concat();
    let Some((n, length)) = head.split_once('x') else {
        return Err(syntax(
            text,
            format!("{head:?} before \"every\" is not COUNTxLENGTH"),
        ));
    };
    let (count, length_s) = count_and_length(text, n, length)?;
    let rest = &tokens[every + 1..];
    let (period, start) = match rest {
        [p] => (*p, None),
        [p, "from", s] => (*p, Some(*s)),
        _ => {
            return Err(syntax(
                text,
                format!(
                    "after \"every\" expected PERIOD [from START], found {:?}",
                    rest.join(" ")
                ),
            ));
        }
    };
    let period_s = positive(seconds(period, "period", text)?, period, "period", text)?;
    let start_s = match start {
        Some(s) => seconds(s, "start", text)?,
        None => period_s,
    };
    if period_s < length_s {
        return Err(syntax(
            text,
            format!(
                "period {period_s} s is shorter than the length {length_s} s: the windows would overlap"
            ),
        ));
    }
    Ok(OutageSpec::Every {
        count,
        length_s,
        period_s,
        start_s,
    })
}

impl OutageSpec {
    /// Absolute windows for GNSS data spanning `span` (see [`resolve`]).
    pub fn resolve(&self, span: TimeSpan) -> Result<Vec<OutageWindow>, OutageError> {
        resolve(self, span)
    }
}

/// Turns a specification into absolute, sorted, validated windows for GNSS data whose
/// first and last epochs are `span` (GPS s of week). Errors: invalid span; a window longer
/// than the span; a window starting before the first or ending after the last epoch; two
/// windows overlapping (touching is allowed); `auto:` windows, which need a reference
/// trajectory ([`OutageError::NeedsReference`]).
pub fn resolve(spec: &OutageSpec, span: TimeSpan) -> Result<Vec<OutageWindow>, OutageError> {
    if !(span.start_s.is_finite() && span.end_s.is_finite() && span.end_s > span.start_s) {
        return Err(OutageError::BadSpan { span });
    }
    let mut windows: Vec<OutageWindow> = match spec {
        OutageSpec::None => Vec::new(),
        OutageSpec::Auto { count, length_s } => {
            return Err(OutageError::NeedsReference {
                count: *count,
                length_s: *length_s,
            });
        }
        OutageSpec::Windows(items) => items
            .iter()
            .map(|it| {
                let start_s = match it.start {
                    OutageStart::AfterFirstGnss(s) => span.start_s + s,
                    OutageStart::Gps(s) => s,
                };
                OutageWindow {
                    start_s,
                    end_s: start_s + it.length_s,
                }
            })
            .collect(),
        OutageSpec::Every {
            count,
            length_s,
            period_s,
            start_s,
        } => (0..*count)
            .map(|k| {
                let s = span.start_s + start_s + k as f64 * period_s;
                OutageWindow {
                    start_s: s,
                    end_s: s + length_s,
                }
            })
            .collect(),
    };
    windows.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
    for w in &windows {
        if w.duration_s() > span.duration_s() {
            return Err(OutageError::LongerThanData {
                window: *w,
                length_s: w.duration_s(),
                data_s: span.duration_s(),
            });
        }
        if w.start_s < span.start_s {
            return Err(OutageError::OutsideData {
                window: *w,
                span,
                reason: "it starts before the first GNSS epoch",
            });
        }
        if w.end_s > span.end_s {
            return Err(OutageError::OutsideData {
                window: *w,
                span,
                reason: "it ends after the last GNSS epoch",
            });
        }
    }
    for pair in windows.windows(2) {
        if pair[1].start_s < pair[0].end_s {
            return Err(OutageError::Overlap {
                first: pair[0],
                second: pair[1],
            });
        }
    }
    Ok(windows)
}

/// True when `time_s` lies in any of `windows` (half-open (start, end], see
/// [`TimeSpan::contains`]).
pub fn is_masked(windows: &[OutageWindow], time_s: f64) -> bool {
    windows.iter().any(|w| w.contains(time_s))
}

//! The time column after parsing: week + seconds of week combined, τ0, gaps and rate
//! changes.

use std::ops::Range;

use crate::io::error::{Location, LogError};
use crate::io::log::TimeGap;
use crate::io::timing::rate_change;

use super::options::{GapPolicy, TextOptions};
use super::parse::LineMap;
use super::plan::Plan;

/// Seconds of week + week numbers → seconds from the start of the first row's week
/// (`t += (week − week₀) × 604 800 s`); returns week₀. Weeks must be whole numbers in
/// 0–65 535.
pub(super) fn combine_weeks(
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

pub(super) type TimeResult = (f64, Vec<Range<usize>>, Vec<TimeGap>);

pub(super) fn time_analysis(
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

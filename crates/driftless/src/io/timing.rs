//! Interval statistics of a time column, for the readers' checks: whether a log keeps one
//! sample rate. Only statistics of the time-stamp differences, no resampling or fit.

/// Intervals per block of the rate-change check: enough that one late sample (±25 % of an
/// interval) moves a block's mean by under 1 %, and that time stamps rounded to 1 ms at
/// 800 Hz move it by under 3 %.
const RATE_BLOCK: usize = 32;

/// A block whose mean interval differs from the log's by more than this fraction is at
/// another sample rate.
const RATE_CHANGE_TOLERANCE: f64 = 0.05;

/// A stretch of a log at another sample rate: rows `start..=end`.
pub(crate) struct RateStretch {
    /// First row.
    pub start: usize,
    /// Last row.
    pub end: usize,
    /// Interval of most of the log, s.
    pub interval_s: f64,
    /// Interval of the stretch, s.
    pub other_interval_s: f64,
}

/// Looks for a stretch of sustained shorter or longer intervals: the intervals are cut into
/// blocks of [`RATE_BLOCK`]; a block's interval is the mean of those up to `gap_limit`
/// (isolated gaps are the gap policy's business), or of all when most are longer (then the
/// long intervals are the rate, not gaps); the log's interval is the median of the blocks'.
/// Consecutive blocks off by more than [`RATE_CHANGE_TOLERANCE`] on the same side form the
/// stretch, trimmed to its first and last interval on that side. Only interval statistics:
/// no resampling, no fit.
pub(crate) fn rate_change(t: &[f64], gap_limit: f64) -> Option<RateStretch> {
    let n = t.len().saturating_sub(1);
    let nb = n / RATE_BLOCK;
    if nb < 2 {
        return None;
    }
    // Block k covers intervals k·B .. (k+1)·B, the last one also the remainder.
    let block = |k: usize| k * RATE_BLOCK..if k + 1 == nb { n } else { (k + 1) * RATE_BLOCK };
    let means: Vec<f64> = (0..nb)
        .map(|k| {
            let r = block(k);
            let len = r.len();
            let (mut sum, mut count, mut all) = (0.0, 0usize, 0.0);
            for i in r {
                let d = t[i + 1] - t[i];
                all += d;
                if d <= gap_limit {
                    sum += d;
                    count += 1;
                }
            }
            if 2 * count >= len {
                sum / count as f64
            } else {
                all / len as f64
            }
        })
        .collect();
    let mut sorted = means.clone();
    let mid = sorted.len() / 2;
    let (_, &mut interval_s, _) = sorted.select_nth_unstable_by(mid, f64::total_cmp);
    let side = |m: f64| {
        let dev = m / interval_s - 1.0;
        if dev > RATE_CHANGE_TOLERANCE {
            1
        } else if dev < -RATE_CHANGE_TOLERANCE {
            -1
        } else {
            0
        }
    };
    let first = (0..nb).find(|&k| side(means[k]) != 0)?;
    let dir = side(means[first]);
    let last = (first..nb)
        .take_while(|&k| side(means[k]) == dir)
        .last()
        .unwrap_or(first);
    let off = |i: usize| side(t[i + 1] - t[i]) == dir;
    let lo = block(first).start;
    let hi = block(last).end;
    // The stretch's own intervals, followed past the blocks' bounds.
    let mut start = (lo..hi).find(|&i| off(i)).unwrap_or(lo);
    while start > 0 && off(start - 1) {
        start -= 1;
    }
    let mut end = (lo..hi).rev().find(|&i| off(i)).map_or(hi, |i| i + 1);
    while end < n && off(end) {
        end += 1;
    }
    let other_interval_s = (t[end] - t[start]) / (end - start).max(1) as f64;
    Some(RateStretch {
        start,
        end,
        interval_s,
        other_interval_s,
    })
}

/// [`LogError::RateChange`] for a log without lines (binary and autopilot logs): the
/// stretch named by its samples. `gap_limit` as in [`rate_change`].
pub(crate) fn check_one_rate(
    t: &[f64],
    gap_limit: f64,
    source: &str,
) -> Result<(), super::error::LogError> {
    match rate_change(t, gap_limit) {
        None => Ok(()),
        Some(r) => Err(super::error::LogError::RateChange {
            at: super::error::Location::input(source),
            interval_s: r.interval_s,
            other_interval_s: r.other_interval_s,
            first: r.start,
            last: r.end,
            start_s: t[r.start],
            end_s: t[r.end],
        }),
    }
}

/// The intervals of `t` longer than `limit_s`, as [`TimeGap`](super::log::TimeGap)s (for
/// the readers that list gaps but keep one segment: autopilot logs, ROS bags).
pub(crate) fn gaps_over(t: &[f64], limit_s: f64) -> Vec<super::log::TimeGap> {
    (1..t.len())
        .filter(|&i| t[i] - t[i - 1] > limit_s)
        .map(|i| super::log::TimeGap {
            index: i,
            start_s: t[i - 1],
            duration_s: t[i] - t[i - 1],
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_rate_with_isolated_gaps_and_rounded_stamps_has_no_stretch() {
        // Gaps of 5 intervals every 100 samples: the gap policy's business.
        let mut t = Vec::new();
        let mut s = 0.0;
        for k in 0..5000 {
            t.push(s);
            s += if k % 100 == 99 { 0.05 } else { 0.01 };
        }
        assert!(rate_change(&t, 0.015).is_none());
        // 400 Hz stamped in whole ms: intervals of 2 and 3 ms.
        let t: Vec<f64> = (0..5000).map(|k| (k as f64 * 2.5).floor() / 1e3).collect();
        assert!(rate_change(&t, 0.0045).is_none());
    }

    #[test]
    fn a_stretch_of_long_intervals_is_a_rate_not_gaps() {
        let mut t: Vec<f64> = (0..3000).map(|k| k as f64 * 0.01).collect();
        let t0 = t[2999];
        t.extend((1..=1000).map(|k| t0 + k as f64 * 0.03));
        let t1 = t[t.len() - 1];
        t.extend((1..=3000).map(|k| t1 + k as f64 * 0.01));
        let r = rate_change(&t, 0.015).expect("a stretch");
        assert_eq!((r.start, r.end), (2999, 3999));
        assert!((r.interval_s - 0.01).abs() < 1e-12);
        assert!((r.other_interval_s - 0.03).abs() < 1e-12);
    }
}

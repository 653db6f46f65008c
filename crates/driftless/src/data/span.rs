//! The crate's one interval of time.

use std::fmt;

use serde::{Deserialize, Serialize};

/// An interval of time, s, on the time axis of the data it refers to (GPS seconds of
/// week for navigation data, the log's own axis for a log).
///
/// Where membership matters it is half-open, (start, end]: an instant at `start_s`
/// belongs to what came before. An outage window withholds the fixes at
/// `start_s < t ≤ end_s`; the fix at `start_s` is still used.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeSpan {
    /// Start, s.
    pub start_s: f64,
    /// End, s (≥ `start_s`).
    pub end_s: f64,
}

impl TimeSpan {
    /// First to last element of a sorted time column (`None` when empty).
    pub fn of(time_s: &[f64]) -> Option<TimeSpan> {
        Some(TimeSpan {
            start_s: *time_s.first()?,
            end_s: *time_s.last()?,
        })
    }
    /// Length, s.
    pub fn duration_s(&self) -> f64 {
        self.end_s - self.start_s
    }
    /// True when `time_s` lies in the half-open span: `start_s < time_s ≤ end_s`.
    pub fn contains(&self, time_s: f64) -> bool {
        time_s > self.start_s && time_s <= self.end_s
    }
}

impl fmt::Display for TimeSpan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({} s, {} s]", self.start_s, self.end_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn membership_is_half_open() {
        let s = TimeSpan::of(&[10.0, 11.0, 12.5]).unwrap();
        assert_eq!(s.duration_s(), 2.5);
        assert!(!s.contains(10.0) && s.contains(10.5) && s.contains(12.5));
        assert!(!s.contains(12.6));
        assert_eq!(TimeSpan::of(&[]), None);
        assert_eq!(s.to_string(), "(10 s, 12.5 s]");
    }
}

//! Time spans where a channel leaves its range (sensor limits or temperature window).

use super::*;

/// Spans where `temperature_c` leaves `range_c` (°C) — for warning when compensating
/// data outside a model's calibrated range instead of extrapolating silently. `time_s`
/// gives the span times (sample index × `tau0_s` when `None`). Consecutive samples out of
/// range form one [`RangeExcursion`].
pub fn out_of_range_spans(
    time_s: Option<&[f64]>,
    tau0_s: f64,
    temperature_c: &[f64],
    range_c: [f64; 2],
) -> Vec<RangeExcursion> {
    let at = |i: usize| {
        time_s
            .and_then(|t| t.get(i).copied())
            .unwrap_or(i as f64 * tau0_s)
    };
    let mut out: Vec<RangeExcursion> = Vec::new();
    let mut open = false;
    for (i, &t) in temperature_c.iter().enumerate() {
        let outside = !(t >= range_c[0] && t <= range_c[1]);
        if outside {
            match out.last_mut() {
                Some(e) if open => {
                    e.span.end_s = at(i);
                    e.samples += 1;
                    e.min_c = e.min_c.min(t);
                    e.max_c = e.max_c.max(t);
                }
                _ => out.push(RangeExcursion {
                    span: TimeSpan {
                        start_s: at(i),
                        end_s: at(i),
                    },
                    samples: 1,
                    min_c: t,
                    max_c: t,
                }),
            }
        }
        open = outside;
    }
    out
}

/// A run of samples outside a model's calibrated temperature range.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RangeExcursion {
    /// Where.
    pub span: TimeSpan,
    /// Samples in it.
    pub samples: usize,
    /// Lowest temperature in it, °C (NaN readings do not lower it).
    pub min_c: f64,
    /// Highest, °C.
    pub max_c: f64,
}

impl RangeExcursion {
    /// One line: "t = a–b s (n samples, lo–hi °C)".
    pub fn describe(&self) -> String {
        format!(
            "t = {} ({} samples, {:.2}–{:.2} °C)",
            fmt_span(&self.span),
            self.samples,
            self.min_c,
            self.max_c
        )
    }
}

//! Axis maths: range fitting, ticks and tick labels for log₁₀ axes
//! ([`log_ticks`]) and linear axes ([`linear_ticks`]).

use super::figure::AxisScale;

/// A tick on an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Position in data units.
    pub value: f64,
    /// Axis coordinate: `log10(value)` on a log axis, `value` itself on a
    /// linear axis.
    pub log: f64,
    /// Major tick: a decade on a log axis, a labelled step on a linear one
    /// (gets a gridline and, normally, a label).
    pub major: bool,
    /// Text under / beside the tick, e.g. `"10⁻²"` or `"-0.5"`.
    pub label: Option<String>,
}

/// Smallest shown span, in decades.
const MIN_SPAN: f64 = 1.0;
/// Guard against sub-normal / overflow logs: every finite positive f64 has
/// log10 within this.
const LOG_LIMIT: f64 = 330.0;

/// `log10` of the finite, strictly positive values, as `(min, max)`.
/// `None` when there are none (all NaN / zero / negative / empty).
pub(crate) fn log_extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    let mut ext: Option<(f64, f64)> = None;
    for v in values {
        if v.is_finite() && v > 0.0 {
            let l = v.log10();
            ext = Some(match ext {
                None => (l, l),
                Some((a, b)) => (a.min(l), b.max(l)),
            });
        }
    }
    ext
}

/// Displayed log-range for data spanning `[lmin, lmax]` (log10 units): a
/// margin of 4 % each side (so markers on a decade are not cut by the frame),
/// widened symmetrically to at least one decade.
pub(crate) fn padded_range(lmin: f64, lmax: f64) -> (f64, f64) {
    let (mut lo, mut hi) = if lmin <= lmax {
        (lmin, lmax)
    } else {
        (lmax, lmin)
    };
    let span = hi - lo;
    let pad = (0.04 * span).max(0.03);
    lo -= pad;
    hi += pad;
    if hi - lo < MIN_SPAN {
        let mid = 0.5 * (lo + hi);
        lo = mid - 0.5 * MIN_SPAN;
        hi = mid + 0.5 * MIN_SPAN;
    }
    (lo.max(-LOG_LIMIT), hi.min(LOG_LIMIT))
}

/// Log-range for a user-given `(min, max)` in data units; `None` if it is not
/// a valid positive range.
pub(crate) fn explicit_range(range: (f64, f64)) -> Option<(f64, f64)> {
    let (a, b) = range;
    if !(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0 && a != b) {
        return None;
    }
    let (a, b) = (a.log10(), b.log10());
    Some(if a < b { (a, b) } else { (b, a) })
}

const SUPERSCRIPT_DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];

/// `n` written with Unicode superscript characters, e.g. `-12` → `"⁻¹²"`.
pub fn superscript(n: i32) -> String {
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for d in n.unsigned_abs().to_string().bytes() {
        s.push(SUPERSCRIPT_DIGITS[usize::from(d - b'0')]);
    }
    s
}

/// Label of the decade `10^k`, e.g. `"10⁻²"`.
pub fn decade_label(k: i32) -> String {
    format!("10{}", superscript(k))
}

/// Label of `m·10^k` for a minor tick (`m` in 2..=9): plain decimals for
/// moderate exponents (`"0.02"`, `"500"`), `"2×10⁻⁷"` otherwise.
pub fn minor_label(m: u32, k: i32) -> String {
    match k {
        0..=3 => format!("{}{}", m, "0".repeat(k as usize)),
        -3..=-1 => format!("0.{}{}", "0".repeat((-k - 1) as usize), m),
        _ => format!("{}×{}", m, decade_label(k)),
    }
}

/// Ticks for a log axis showing `[lo, hi]` (log10 units) over `length_px`
/// pixels, with labels at least `min_label_gap_px` apart.
///
/// * A major tick at every decade (only every n-th if decades are packed
///   tighter than 5 px); labels thinned to every n-th decade when needed.
/// * Minor ticks at 2…9 × 10ᵏ when a decade is at least 30 px long.
/// * When fewer than two decades are visible, the minor ticks 2, 3 and 5 (or
///   all, if there is room) are labelled too, so the axis is always readable;
///   with exactly two, 2 and 5 are labelled if there is room.
///
/// Never panics; the number of ticks is bounded (≤ ~700 + 8 per decade shown).
pub fn log_ticks(lo: f64, hi: f64, length_px: f64, min_label_gap_px: f64) -> Vec<Tick> {
    let mut ticks = Vec::new();
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return ticks;
    }
    let (lo, hi) = (lo.max(-LOG_LIMIT), hi.min(LOG_LIMIT));
    let length_px = if length_px.is_finite() && length_px > 1.0 {
        length_px
    } else {
        1.0
    };
    let px_per_decade = length_px / (hi - lo);
    let eps = 1e-9 * (hi - lo).max(1.0);
    let k_lo = (lo - eps).ceil() as i32;
    let k_hi = (hi + eps).floor() as i32;
    let n_dec = (k_hi - k_lo + 1).max(0);

    let gap = min_label_gap_px.max(1.0);
    let label_stride = nice_stride((gap / px_per_decade).ceil());
    let tick_stride = if px_per_decade >= 5.0 {
        1
    } else {
        label_stride
    };
    let show_minor = px_per_decade >= 30.0 && (hi - lo) < 40.0;
    // Which minor multipliers get labels when the axis is short: with fewer
    // than two decade labels the axis needs them; with two, 2 and 5 help.
    let minor_labelled: &[u32] = if n_dec >= 3 {
        &[]
    } else if n_dec == 2 {
        if px_per_decade * 2f64.log10() >= gap {
            &[2, 5]
        } else {
            &[]
        }
    } else if px_per_decade * (9f64 / 8.0).log10() >= gap {
        &[2, 3, 4, 5, 6, 7, 8, 9]
    } else if px_per_decade * (3f64 / 2.0).log10() >= gap {
        &[2, 3, 5]
    } else if px_per_decade * 2f64.log10() >= gap {
        &[2, 5]
    } else {
        &[]
    };

    let in_range = |l: f64| l >= lo - eps && l <= hi + eps;
    for k in (k_lo - 1)..=k_hi {
        let is_tick_decade = k >= k_lo && k.rem_euclid(tick_stride) == 0;
        if is_tick_decade {
            let labelled = k.rem_euclid(label_stride) == 0;
            ticks.push(Tick {
                value: 10f64.powi(k),
                log: f64::from(k),
                major: true,
                label: labelled.then(|| decade_label(k)),
            });
        }
        if show_minor {
            for m in 2..=9u32 {
                let l = f64::from(k) + f64::from(m).log10();
                if in_range(l) {
                    let labelled = minor_labelled.contains(&m);
                    ticks.push(Tick {
                        value: f64::from(m) * 10f64.powi(k),
                        log: l,
                        major: false,
                        label: labelled.then(|| minor_label(m, k)),
                    });
                }
            }
        }
    }
    ticks
}

/// Smallest "round" decade stride (1, 2, 5, 10, 20, 50 …) ≥ `need`, so that
/// thinned labels fall on round exponents (10⁻²⁰⁰, 10⁻¹⁰⁰, 10⁰ …).
fn nice_stride(need: f64) -> i32 {
    let mut base = 1i32;
    loop {
        for m in [1, 2, 5] {
            let s = base.saturating_mul(m);
            if f64::from(s) >= need || s >= 1_000 {
                return s;
            }
        }
        base = base.saturating_mul(10);
    }
}

/// Largest magnitude a linear axis shows; data beyond it is clamped for range
/// fitting (so spans and steps stay finite).
const LINEAR_LIMIT: f64 = 1e300;
/// Most major ticks on a linear axis.
const MAX_LINEAR_TICKS: f64 = 8.0;

/// `(min, max)` of the finite values (clamped to ±10³⁰⁰); `None` when there
/// are none.
pub fn linear_extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    let mut ext: Option<(f64, f64)> = None;
    for v in values {
        if v.is_finite() {
            let v = v.clamp(-LINEAR_LIMIT, LINEAR_LIMIT);
            ext = Some(match ext {
                None => (v, v),
                Some((a, b)) => (a.min(v), b.max(v)),
            });
        }
    }
    ext
}

/// Widens a degenerate range (empty, or narrower than 10⁻⁹ of its magnitude)
/// symmetrically to 20 % of its magnitude (to `[-0.5, 0.5]` around zero).
fn widen_degenerate(lo: f64, hi: f64) -> (f64, f64) {
    let mid = 0.5 * lo + 0.5 * hi;
    if hi - lo > 1e-9 * mid.abs() && hi - lo >= 1e-290 {
        return (lo, hi);
    }
    let half = if mid.abs() < 1e-290 {
        0.5
    } else {
        0.1 * mid.abs()
    };
    (mid - half, mid + half)
}

/// Displayed linear range for data spanning `[min, max]` (data units): a
/// margin of 5 % of the span each side, a degenerate range (e.g. a single
/// value `[5, 5]` → `[4.5, 5.5]`) widened first. Zero is not forced in.
pub fn linear_padded_range(min: f64, max: f64) -> (f64, f64) {
    let clamp = |v: f64| {
        if v.is_nan() {
            0.0
        } else {
            v.clamp(-LINEAR_LIMIT, LINEAR_LIMIT)
        }
    };
    let (a, b) = (clamp(min), clamp(max));
    let (lo, hi) = widen_degenerate(a.min(b), a.max(b));
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Linear range for a user-given `(min, max)`; `None` unless both are finite
/// and distinct. Reversed bounds are swapped; a range too narrow to label is
/// widened as in [`linear_padded_range`].
pub fn explicit_linear_range(range: (f64, f64)) -> Option<(f64, f64)> {
    let (a, b) = range;
    if !(a.is_finite() && b.is_finite() && a != b) {
        return None;
    }
    let (a, b) = (
        a.clamp(-LINEAR_LIMIT, LINEAR_LIMIT),
        b.clamp(-LINEAR_LIMIT, LINEAR_LIMIT),
    );
    Some(widen_degenerate(a.min(b), a.max(b)))
}

/// The smallest "nice" step `m·10^k` (`m` ∈ {1, 2, 5}) giving at most
/// `max_ticks` multiples of the step inside `[lo, hi]`, as `(step, m, k)`;
/// `None` if the range is unusable.
fn nice_step(lo: f64, hi: f64, max_ticks: f64) -> Option<(f64, u32, i32)> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return None;
    }
    let eps = 1e-9 * span;
    let mut k = (span / max_ticks).log10().floor() as i32 - 1;
    for _ in 0..5 {
        for m in [1u32, 2, 5] {
            let step = f64::from(m) * 10f64.powi(k);
            if !(step.is_finite() && step > 0.0) {
                continue;
            }
            let count = ((hi + eps) / step).floor() - ((lo - eps) / step).ceil() + 1.0;
            if count <= max_ticks {
                return Some((step, m, k));
            }
        }
        k += 1;
    }
    None
}

/// Labels `i·step` for the given integer multiples with one precision for
/// the whole axis: fixed-point (`"-0.5"`, `"0"`, `"2.5"`) for moderate
/// magnitudes, `"1.05e-3"` / `"-1.0e6"` when the largest |tick| is ≥ 10⁵ or
/// below 10⁻² (or fixed-point would need more than 6 decimals). Zero is
/// always `"0"`.
fn linear_labels(multiples: &[f64], step: f64, k: i32) -> Vec<String> {
    let max_abs = multiples
        .iter()
        .map(|i| (i * step).abs())
        .fold(0.0, f64::max);
    let fixed_decimals = (-k).max(0);
    let sci = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-2) || fixed_decimals > 6;
    let e = if max_abs > 0.0 {
        (max_abs.log10() + 1e-9).floor() as i32
    } else {
        0
    };
    multiples
        .iter()
        .map(|&i| {
            let v = i * step;
            if i == 0.0 {
                "0".to_owned()
            } else if sci {
                let d = (e - k).clamp(0, 16) as usize;
                let mant = v / 10f64.powi(e);
                format!("{mant:.d$}e{e}")
            } else {
                let d = fixed_decimals.min(16) as usize;
                format!("{v:.d$}")
            }
        })
        .collect()
}

/// Ticks for a linear axis showing `[lo, hi]` (data units) over `length_px`
/// pixels, major tick labels at least `min_label_gap_px` apart.
///
/// * Major ticks at multiples of a 1-2-5 × 10ᵏ step, at most 8 of them
///   (fewer if the labels would be closer than `min_label_gap_px`), each
///   labelled with one precision per axis (see the module docs).
/// * Unlabelled minor ticks at step/5 (step/4 for a 2 × 10ᵏ step) when they
///   are at least 8 px apart.
///
/// Never panics; returns nothing for a non-finite or empty range.
pub fn linear_ticks(lo: f64, hi: f64, length_px: f64, min_label_gap_px: f64) -> Vec<Tick> {
    let mut ticks = Vec::new();
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return ticks;
    }
    let length_px = if length_px.is_finite() && length_px > 1.0 {
        length_px
    } else {
        1.0
    };
    let span = hi - lo;
    let gap = if min_label_gap_px.is_finite() {
        min_label_gap_px.max(1.0)
    } else {
        1.0
    };
    let max_ticks = (length_px / gap + 1.0).floor().clamp(2.0, MAX_LINEAR_TICKS);
    let Some((step, m, k)) = nice_step(lo, hi, max_ticks) else {
        return ticks;
    };
    let eps = 1e-9 * span;
    let i0 = ((lo - eps) / step).ceil();
    let i1 = ((hi + eps) / step).floor();
    if !(i0.is_finite() && i1.is_finite()) || i1 - i0 > 2.0 * MAX_LINEAR_TICKS {
        return ticks;
    }
    let multiples: Vec<f64> = (0..=((i1 - i0).max(-1.0) + 1.0) as usize)
        .map(|j| i0 + j as f64)
        .filter(|&i| i <= i1)
        .collect();
    let labels = linear_labels(&multiples, step, k);
    let n_minor: u32 = if m == 2 { 4 } else { 5 };
    let minor_step = step / f64::from(n_minor);
    let show_minor = minor_step / span * length_px >= 8.0;
    // Minor ticks run from one step below the first major to the last.
    for (&i, label) in multiples.iter().zip(labels) {
        if show_minor && i == i0 {
            for j in 1..n_minor {
                let v = (i - 1.0) * step + f64::from(j) * minor_step;
                if v >= lo - eps {
                    ticks.push(Tick {
                        value: v,
                        log: v,
                        major: false,
                        label: None,
                    });
                }
            }
        }
        let v = i * step;
        ticks.push(Tick {
            value: v,
            log: v,
            major: true,
            label: Some(label),
        });
        if show_minor {
            for j in 1..n_minor {
                let v = i * step + f64::from(j) * minor_step;
                if v <= hi + eps {
                    ticks.push(Tick {
                        value: v,
                        log: v,
                        major: false,
                        label: None,
                    });
                }
            }
        }
    }
    ticks
}

/// Map from one axis (log or linear) onto pixels. `lo`/`hi` are axis
/// coordinates (log10 units on a log axis, data units on a linear one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisMap {
    pub scale: AxisScale,
    pub lo: f64,
    pub hi: f64,
    pub p0: f64,
    pub p1: f64,
}

impl AxisMap {
    /// Whether the axis can show `v` (finite, and positive on a log axis).
    pub(crate) fn accepts(&self, v: f64) -> bool {
        match self.scale {
            AxisScale::Log => v.is_finite() && v > 0.0,
            AxisScale::Linear => v.is_finite(),
        }
    }

    /// Pixel of a data value; `None` unless [`accepts`](Self::accepts).
    pub fn px(&self, v: f64) -> Option<f64> {
        if !self.accepts(v) {
            return None;
        }
        Some(match self.scale {
            AxisScale::Log => self.px_log(v.log10()),
            AxisScale::Linear => self.px_log(v),
        })
    }

    /// Pixel of an axis coordinate (e.g. [`Tick::log`]).
    pub(crate) fn px_log(&self, l: f64) -> f64 {
        self.p0 + (l - self.lo) / (self.hi - self.lo) * (self.p1 - self.p0)
    }
}

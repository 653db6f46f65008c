//! Log₁₀ axis maths: range fitting, decade / minor ticks and tick labels.

/// A tick on a log axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Position in data units.
    pub value: f64,
    /// `log10(value)`.
    pub log: f64,
    /// Decade tick (gets a gridline and, normally, a label).
    pub major: bool,
    /// Text under / beside the tick, e.g. `"10⁻²"`.
    pub label: Option<String>,
}

/// Smallest shown span, in decades.
const MIN_SPAN: f64 = 1.0;
/// Guard against sub-normal / overflow logs: every finite positive f64 has
/// log10 within this.
const LOG_LIMIT: f64 = 330.0;

/// `log10` of the finite, strictly positive values, as `(min, max)`.
/// `None` when there are none (all NaN / zero / negative / empty).
pub fn log_extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
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
pub fn padded_range(lmin: f64, lmax: f64) -> (f64, f64) {
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
pub fn explicit_range(range: (f64, f64)) -> Option<(f64, f64)> {
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

/// Linear map from a log range onto pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LogMap {
    pub lo: f64,
    pub hi: f64,
    pub p0: f64,
    pub p1: f64,
}

impl LogMap {
    /// Pixel of a data value; `None` unless finite and positive.
    pub fn px(&self, v: f64) -> Option<f64> {
        (v.is_finite() && v > 0.0).then(|| self.px_log(v.log10()))
    }

    pub fn px_log(&self, l: f64) -> f64 {
        self.p0 + (l - self.lo) / (self.hi - self.lo) * (self.p1 - self.p0)
    }
}

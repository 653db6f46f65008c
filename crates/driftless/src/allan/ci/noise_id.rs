//! Power-law noise identification.
//!
//! Primary method: the lag-1 autocorrelation of W. J. Riley and C. A. Greenhall,
//! "Power law noise identification using the lag 1 autocorrelation", Proc. 18th EFTF
//! (2004); NIST SP 1065 §5.6. For fewer than `MIN_ACF_POINTS` points after averaging,
//! the B1 bias ratio (Barnes) with the R(n) = MVAR/AVAR ratio to split white from
//! flicker PM (SP 1065 §5.6, "noise identification using B1 and R(n)").

/// Fewest points the lag-1 ACF method is used on (Riley & Greenhall recommend ≥ 30).
pub(crate) const MIN_ACF_POINTS: usize = 30;

/// Most decimated points the lag-1 ACF is computed on (the first ones). With 2¹⁴ points
/// the standard error of r1 is ≈ 1/√n ≈ 0.008, thirty times below the method's
/// decision margins (δ thresholds 0.25 apart), while an 18-h 100 Hz log would otherwise be
/// re-read in full for every small averaging factor. Shorter series are used whole, so
/// results on Stable32-sized data are unchanged.
pub(crate) const MAX_ACF_POINTS: usize = 1 << 14;

/// Fewest frequency averages the B1 ratio is used on (with 2 it is identically 1).
pub(crate) const MIN_B1_POINTS: usize = 4;

/// How an alpha was identified.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum NoiseIdMethod {
    /// Lag-1 autocorrelation: `d` differences were taken, δ is the final
    /// r1/(1 + r1), and `p` = −2(δ + d) is the phase-PSD exponent estimate.
    Lag1Acf {
        /// Number of differences taken.
        d: u32,
        /// δ = r1/(1 + r1) of the final series.
        delta: f64,
    },
    /// B1 ratio (standard variance / Allan variance of the m-averaged frequency),
    /// possibly refined by R(n).
    B1 {
        /// Measured B1.
        b1: f64,
        /// Measured R(n) = MVAR/AVAR, when it was needed and available.
        rn: Option<f64>,
    },
}

/// Result of [`identify_noise`](super::identify_noise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct NoiseId {
    /// Integer noise exponent α (S_y ∝ f^α), clamped to the allowed range.
    pub alpha: i32,
    /// Unrounded estimate of α (for the ACF method p + 2; for B1 the class value).
    pub alpha_est: f64,
    /// Method and its statistics.
    pub method: NoiseIdMethod,
}

/// Lag-1 autocorrelation r1 = Σ(xᵢ−x̄)(xᵢ₊₁−x̄) / Σ(xᵢ−x̄)² (Riley & Greenhall 2004 eq. 2).
/// A constant series has no correlation evidence and gives 0.
pub fn lag1_acf(x: &[f64]) -> f64 {
    if x.len() < 2 {
        return 0.0;
    }
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let den: f64 = x.iter().map(|v| (v - mean) * (v - mean)).sum();
    let num: f64 = x.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    if den > 0.0 && den.is_finite() {
        num / den
    } else {
        0.0
    }
}

/// Remove the least-squares polynomial of degree `deg` (≤ 2) by Gram–Schmidt on the
/// sample grid (numerically stable for long series).
fn detrend(x: &mut [f64], deg: usize) {
    let n = x.len();
    if n <= deg + 1 {
        return;
    }
    let c = (n as f64 - 1.0) / 2.0;
    let t: Vec<f64> = (0..n).map(|i| (i as f64 - c) / c.max(1.0)).collect();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for k in 0..=deg {
        let mut v: Vec<f64> = t.iter().map(|&ti| ti.powi(k as i32)).collect();
        for b in &basis {
            let proj: f64 = v.iter().zip(b).map(|(a, c)| a * c).sum();
            v.iter_mut().zip(b).for_each(|(a, c)| *a -= proj * c);
        }
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm > 0.0 {
            v.iter_mut().for_each(|a| *a /= norm);
            basis.push(v);
        }
    }
    for b in &basis {
        let proj: f64 = x.iter().zip(b).map(|(a, c)| a * c).sum();
        x.iter_mut().zip(b).for_each(|(a, c)| *a -= proj * c);
    }
}

/// Lag-1 ACF identification on phase `x` at averaging factor `m`.
///
/// The phase is decimated by m (every m-th point; its first difference is m times the
/// frequency averaged over m, i.e. the data "averaged by m"), a quadratic (frequency
/// offset and linear drift) is removed, then the series is differenced until
/// δ = r1/(1 + r1) < 0.25 or d = `dmax`. The phase-PSD exponent is p = −2(δ + d) and
/// α = round(p) + 2. Returns `None` with fewer than `MIN_ACF_POINTS` decimated points.
pub(crate) fn acf_noise_id(x: &[f64], m: usize, dmax: u32) -> Option<NoiseId> {
    let m = m.max(1);
    let mut z: Vec<f64> = x.iter().step_by(m).take(MAX_ACF_POINTS).copied().collect();
    if z.len() < MIN_ACF_POINTS {
        return None;
    }
    let x0 = z[0];
    z.iter_mut().for_each(|v| *v -= x0);
    detrend(&mut z, 2);
    let mut d = 0u32;
    loop {
        let r1 = lag1_acf(&z);
        let delta = r1 / (1.0 + r1);
        let delta = if delta.is_finite() { delta } else { 0.5 };
        if delta < 0.25 || d >= dmax || z.len() < 3 {
            let p = -2.0 * (delta + f64::from(d));
            return Some(NoiseId {
                alpha: p.round() as i32 + 2,
                alpha_est: p + 2.0,
                method: NoiseIdMethod::Lag1Acf { d, delta },
            });
        }
        z = z.windows(2).map(|w| w[1] - w[0]).collect();
        d += 1;
    }
}

/// Barnes' B1(N, μ): expected ratio of the N-sample standard variance to the Allan
/// variance for σ²_y(τ) ∝ τ^μ: N(1 − N^μ) / [2(N − 1)(1 − 2^μ)], μ = 0 limit
/// N ln N / [2(N − 1) ln 2] (SP 1065 §5.6).
pub(crate) fn b1_theory(n: f64, mu: f64) -> f64 {
    if mu.abs() < 1e-12 {
        n * n.ln() / (2.0 * (n - 1.0) * std::f64::consts::LN_2)
    } else {
        n * (1.0 - n.powf(mu)) / (2.0 * (n - 1.0) * (1.0 - 2f64.powf(mu)))
    }
}

/// Expected R(n) = MVAR/AVAR at averaging factor m for white PM (1/m) and flicker PM
/// (with the usual f_h = 1/(2τ0): 3 ln(256/27)/(8π²) over (1.038 + 3 ln(π m))/(4π²)).
fn rn_theory(m: f64) -> (f64, f64) {
    let wpm = 1.0 / m;
    let fpm = 1.5 * (256.0f64 / 27.0).ln() / (1.038 + 3.0 * (std::f64::consts::PI * m).ln());
    (wpm, fpm)
}

/// Overlapping Allan variance and modified Allan variance of phase `x` at factor m
/// (unnormalized by τ², the ratio is all that is needed). `None` if N < 3m + 1.
fn avar_mvar(x: &[f64], m: usize) -> Option<(f64, f64)> {
    let n = x.len();
    if m == 0 || n < 3 * m + 1 {
        return None;
    }
    let mf = m as f64;
    let d2 = |i: usize| x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    let navar = n - 2 * m;
    let avar = (0..navar).map(|i| d2(i).powi(2)).sum::<f64>() / (2.0 * mf * mf * navar as f64);
    // MVAR: average m consecutive second differences, stride 1.
    let nm = n - 3 * m + 1;
    let mut s: f64 = (0..m).map(d2).sum();
    let mut acc = s * s;
    for j in 1..nm {
        s += d2(j + m - 1) - d2(j - 1);
        acc += s * s;
    }
    let mvar = acc / (2.0 * mf.powi(4) * nm as f64);
    Some((avar, mvar))
}

/// B1 / R(n) identification for short series (SP 1065 §5.6). `None` with fewer than
/// `MIN_B1_POINTS` frequency averages. The B1 ratio cannot see below α = −2 (the Allan
/// variance diverges there), so it returns α ∈ −2..=2.
pub(crate) fn b1_noise_id(x: &[f64], m: usize) -> Option<NoiseId> {
    let m = m.max(1);
    if x.len() < 2 {
        return None;
    }
    let nav = (x.len() - 1) / m;
    if nav < MIN_B1_POINTS {
        return None;
    }
    let y: Vec<f64> = (0..nav)
        .map(|k| (x[(k + 1) * m] - x[k * m]) / m as f64)
        .collect();
    let n = nav as f64;
    let mean = y.iter().sum::<f64>() / n;
    let svar = y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let avar = y.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (2.0 * (n - 1.0));
    if !(avar > 0.0 && svar.is_finite()) {
        return None;
    }
    let b1 = svar / avar;
    // Classes μ = −2 (α = 2 or 1), −1 (α = 0), 0 (α = −1), 1 (α = −2); boundary between
    // adjacent classes = geometric mean of their expected B1.
    let mus = [-2.0, -1.0, 0.0, 1.0];
    let mut mu = -2.0;
    for w in mus.windows(2) {
        let bound = (b1_theory(n, w[0]) * b1_theory(n, w[1])).sqrt();
        if b1 > bound {
            mu = w[1];
        }
    }
    let (alpha, rn) = if mu > -1.5 {
        ((-mu - 1.0) as i32, None)
    } else if m >= 4 {
        // White vs flicker PM by R(n) = MVAR/AVAR.
        match avar_mvar(x, m) {
            Some((av, mv)) if av > 0.0 => {
                let rn = mv / av;
                let (w, f) = rn_theory(m as f64);
                (if rn > (w * f).sqrt() { 1 } else { 2 }, Some(rn))
            }
            _ => (2, None),
        }
    } else {
        // At m < 4 MVAR ≈ AVAR for both PM types: R(n) cannot decide; take white PM.
        (2, None)
    };
    Some(NoiseId {
        alpha,
        alpha_est: f64::from(alpha),
        method: NoiseIdMethod::B1 { b1, rn },
    })
}

//! Cochran's Q and the DerSimonian–Laird random-effects combination of k estimates
//! (equations in the parent module doc).

use serde::{Deserialize, Serialize};

use crate::allan::ci;
use crate::allan::fit::Term;

/// Fixed- and random-effects combination of k estimates with their standard errors
/// (see the module doc for the equations).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetaAnalysis {
    /// Cochran's Q.
    pub q: f64,
    /// Degrees of freedom, k − 1.
    pub df: usize,
    /// P(χ²_df ≥ Q).
    pub p_value: f64,
    /// DerSimonian–Laird between-run variance τ² (in the units of the estimates squared).
    pub tau2: f64,
    /// I² = max(0, (Q − df)/Q).
    pub i2: f64,
    /// Fixed-effect (inverse-variance) mean.
    pub fixed_mean: f64,
    /// Its standard error.
    pub fixed_se: f64,
    /// Random-effects mean.
    pub random_mean: f64,
    /// Its standard error.
    pub random_se: f64,
}

/// Cochran's Q and the DerSimonian–Laird random-effects mean of estimates `y` with
/// standard errors `se` (module doc). None with fewer than two estimates, unequal
/// lengths, or a non-finite estimate or non-positive standard error.
pub fn cochran_dersimonian_laird(y: &[f64], se: &[f64]) -> Option<MetaAnalysis> {
    let k = y.len();
    if k < 2
        || se.len() != k
        || y.iter().any(|v| !v.is_finite())
        || se.iter().any(|s| !(s.is_finite() && *s > 0.0))
    {
        return None;
    }
    let w: Vec<f64> = se.iter().map(|s| 1.0 / (s * s)).collect();
    let sw: f64 = w.iter().sum();
    let sw2: f64 = w.iter().map(|v| v * v).sum();
    let fixed = w.iter().zip(y).map(|(w, y)| w * y).sum::<f64>() / sw;
    let q: f64 = w.iter().zip(y).map(|(w, y)| w * (y - fixed).powi(2)).sum();
    let df = k - 1;
    let p_value = ci::chi2::gamma_pq(0.5 * df as f64, 0.5 * q).1;
    let c = sw - sw2 / sw;
    let tau2 = if c > 0.0 {
        ((q - df as f64) / c).max(0.0)
    } else {
        0.0
    };
    let i2 = if q > 0.0 {
        ((q - df as f64) / q).max(0.0)
    } else {
        0.0
    };
    let ws: Vec<f64> = se.iter().map(|s| 1.0 / (s * s + tau2)).collect();
    let sws: f64 = ws.iter().sum();
    let random = ws.iter().zip(y).map(|(w, y)| w * y).sum::<f64>() / sws;
    Some(MetaAnalysis {
        q,
        df,
        p_value,
        tau2,
        i2,
        fixed_mean: fixed,
        fixed_se: 1.0 / sw.sqrt(),
        random_mean: random,
        random_se: 1.0 / sws.sqrt(),
    })
}

/// Standard error of ln(value) from a two-sided interval [lo, hi] at confidence `cl`:
/// (ln hi − ln lo)/(2 z), z = Φ⁻¹((1 + cl)/2). None when the interval does not bound a
/// positive value.
pub fn log_standard_error(t: &Term, cl: f64) -> Option<f64> {
    let z = crate::allan::fit::normal_quantile(0.5 + 0.5 * cl);
    let ok = t.lo > 0.0 && t.hi.is_finite() && t.hi > t.lo && z.is_finite() && z > 0.0;
    ok.then(|| (t.hi.ln() - t.lo.ln()) / (2.0 * z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cochran's Q and the DerSimonian–Laird τ² on numbers worked by hand:
    /// y = (1, 2, 4), s = (1, 1, 2) → w = (1, 1, 0.25), Σw = 2.25,
    /// ȳ = (1 + 2 + 1)/2.25 = 16/9, Q = (7/9)² + (2/9)² + 0.25·(20/9)² < df = 2.
    #[test]
    fn cochran_and_dersimonian_laird_closed_form() {
        let m = cochran_dersimonian_laird(&[1.0, 2.0, 4.0], &[1.0, 1.0, 2.0]).unwrap();
        assert!((m.fixed_mean - 16.0 / 9.0).abs() < 1e-12, "{m:?}");
        let q = (7.0f64 / 9.0).powi(2) + (2.0f64 / 9.0).powi(2) + 0.25 * (20.0f64 / 9.0).powi(2);
        assert!((m.q - q).abs() < 1e-12, "{} vs {q}", m.q);
        assert_eq!(m.df, 2);
        // Q < df: no between-run variance, random = fixed.
        assert_eq!(m.tau2, 0.0);
        assert_eq!(m.i2, 0.0);
        assert!((m.random_mean - m.fixed_mean).abs() < 1e-12);
        assert!((m.fixed_se - 1.0 / 2.25f64.sqrt()).abs() < 1e-12);
        // χ² with 2 dof: P(χ² ≥ Q) = e^{−Q/2}.
        assert!(
            (m.p_value - (-q / 2.0).exp()).abs() < 1e-12,
            "{}",
            m.p_value
        );

        // Two runs far apart: y = (0, 3), s = (0.5, 0.5): w = (4, 4), ȳ = 1.5,
        // Q = 4·2.25·2 = 18, df = 1, c = 8 − 32/8 = 4, τ² = (18 − 1)/4 = 4.25,
        // w* = 1/(0.25 + 4.25) = 2/9 each, μ* = 1.5, se* = 1/√(4/9) = 1.5.
        let m = cochran_dersimonian_laird(&[0.0, 3.0], &[0.5, 0.5]).unwrap();
        assert!((m.q - 18.0).abs() < 1e-12);
        assert!((m.tau2 - 4.25).abs() < 1e-12);
        assert!((m.random_mean - 1.5).abs() < 1e-12);
        assert!((m.random_se - 1.5).abs() < 1e-12);
        assert!((m.i2 - 17.0 / 18.0).abs() < 1e-12);
        // χ² with 1 dof: P(χ² ≥ 18) = erfc(√9) = erfc(3) = 2.209e-5.
        assert!(
            (m.p_value / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-6,
            "{}",
            m.p_value
        );
        // Unequal weights, Q > df: y = (0, 1, 3), s = (1, 0.5, 1): w = (1, 4, 1), Σw = 6,
        // ȳ = 7/6, Q = (7/6)² + 4(1/6)² + (11/6)² = 174/36, c = 6 − 18/6 = 3,
        // τ² = (174/36 − 2)/3 = 17/18.
        let m = cochran_dersimonian_laird(&[0.0, 1.0, 3.0], &[1.0, 0.5, 1.0]).unwrap();
        assert!((m.q - 174.0 / 36.0).abs() < 1e-12, "{}", m.q);
        assert!((m.tau2 - 17.0 / 18.0).abs() < 1e-12, "{}", m.tau2);
        let ws = [
            1.0 / (1.0 + 17.0 / 18.0),
            1.0 / (0.25 + 17.0 / 18.0),
            1.0 / (1.0 + 17.0 / 18.0),
        ];
        let mu = (ws[1] + 3.0 * ws[2]) / ws.iter().sum::<f64>();
        assert!((m.random_mean - mu).abs() < 1e-12);
    }

    #[test]
    fn identical_runs_pool_to_the_value() {
        let m = cochran_dersimonian_laird(&[0.7, 0.7, 0.7], &[0.1, 0.2, 0.3]).unwrap();
        assert_eq!(m.q, 0.0);
        assert_eq!(m.tau2, 0.0);
        assert_eq!(m.p_value, 1.0);
        assert!((m.random_mean - 0.7).abs() < 1e-15 && (m.fixed_mean - 0.7).abs() < 1e-15);
        assert!(cochran_dersimonian_laird(&[1.0], &[1.0]).is_none());
        assert!(cochran_dersimonian_laird(&[1.0, 2.0], &[1.0, 0.0]).is_none());
        assert!(cochran_dersimonian_laird(&[1.0, f64::NAN], &[1.0, 1.0]).is_none());
    }

    #[test]
    fn log_standard_error_from_interval() {
        // A ±1σ interval e^{±0.1} around 1 at 68.27 %: se = 0.1.
        let t = Term {
            value: 1.0,
            lo: (-0.1f64).exp(),
            hi: 0.1f64.exp(),
        };
        let cl = 2.0 * crate::allan::fit::normal_cdf(1.0) - 1.0;
        assert!((log_standard_error(&t, cl).unwrap() - 0.1).abs() < 1e-9);
        assert!(log_standard_error(&Term { lo: 0.0, ..t }, cl).is_none());
    }
}

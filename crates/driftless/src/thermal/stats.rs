//! Student-t quantiles (and the normal quantile, re-exported from [`crate::numeric`]) for the confidence intervals of [`super::fit`](mod@super::fit).
//!
//! The Student-t distribution function is evaluated through the regularized incomplete
//! beta function (Abramowitz & Stegun 26.7.1, 26.5.8 continued fraction, evaluated with
//! the modified Lentz method — Press et al., *Numerical Recipes*, §6.4):
//!
//! ```text
//! P(|T_ν| > t) = I_{ν/(ν+t²)}(ν/2, ½)
//! ```
//!
//! and inverted by safeguarded bisection (monotone, so ≤ 200 halvings reach machine
//! precision; the quantile is used only as a coverage factor, computed once per fit).

use crate::allan::ci::chi2::ln_gamma;
pub use crate::numeric::normal_quantile;

/// Continued fraction of the incomplete beta function (NR `betacf`, modified Lentz).
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let qab = a + b;
    let qap = a + 1.0;
    let qam = a - 1.0;
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=500 {
        let m = m as f64;
        let m2 = 2.0 * m;
        // even and odd terms of the fraction, each one modified-Lentz step
        h *= lentz_step(m * (b - m) * x / ((qam + m2) * (a + m2)), &mut c, &mut d);
        let del = lentz_step(
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
            &mut c,
            &mut d,
        );
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// Regularized incomplete beta function I_x(a, b) for a, b > 0, 0 ≤ x ≤ 1.
pub(crate) fn inc_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (-x).ln_1p();
    let front = ln_front.exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_cf(a, b, x) / a
    } else {
        1.0 - front * beta_cf(b, a, 1.0 - x) / b
    }
}

/// Student-t distribution function P(T_ν ≤ t), ν > 0 degrees of freedom.
pub(crate) fn student_t_cdf(t: f64, dof: f64) -> f64 {
    if t.is_nan() || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if t.is_infinite() {
        return if t > 0.0 { 1.0 } else { 0.0 };
    }
    let tail = 0.5 * inc_beta(dof / (dof + t * t), 0.5 * dof, 0.5);
    if t > 0.0 { 1.0 - tail } else { tail }
}

/// Student-t quantile t_ν(p): P(T_ν ≤ t) = p, for 0 < p < 1 and ν > 0 (NaN otherwise).
///
/// E.g. `student_t_quantile(0.975, 10.0)` = 2.228 138 851 986 (the two-sided 95 %
/// coverage factor with 10 degrees of freedom).
pub(crate) fn student_t_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if p == 0.5 {
        return 0.0;
    }
    // Work on the upper half and reflect (the distribution is symmetric).
    let (q, sign) = if p > 0.5 { (p, 1.0) } else { (1.0 - p, -1.0) };
    let mut hi = normal_quantile(q).max(1.0);
    let mut guard = 0;
    while student_t_cdf(hi, dof) < q && guard < 2000 {
        hi *= 2.0;
        guard += 1;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if student_t_cdf(mid, dof) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    sign * 0.5 * (lo + hi)
}

/// Floor of |C| and |D| in the modified Lentz method.
const TINY: f64 = 1e-300;

/// One modified-Lentz step with partial numerator `aa` (denominator 1): updates C and D
/// and returns their product, the factor of the convergent (Press et al., *Numerical
/// Recipes*, 3rd ed., §5.2).
fn lentz_step(aa: f64, c: &mut f64, d: &mut f64) -> f64 {
    *d = 1.0 + aa * *d;
    if d.abs() < TINY {
        *d = TINY;
    }
    *c = 1.0 + aa / *c;
    if c.abs() < TINY {
        *c = TINY;
    }
    *d = 1.0 / *d;
    *d * *c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_tables() {
        // Reference values: R qt(); Abramowitz & Stegun table 26.10.
        let cases = [
            (0.975, 1.0, 12.706_204_736_174_7),
            (0.975, 2.0, 4.302_652_729_749_46),
            (0.975, 5.0, 2.570_581_835_636_31),
            (0.975, 10.0, 2.228_138_851_986_27),
            (0.975, 30.0, 2.042_272_456_301_24),
            (0.95, 3.0, 2.353_363_434_801_82),
            (0.995, 15.0, 2.946_712_883_475_38),
        ];
        for (p, nu, want) in cases {
            let got = student_t_quantile(p, nu);
            assert!(
                (got - want).abs() < 1e-9 * want,
                "t({p}, {nu}) = {got}, want {want}"
            );
            let lo = student_t_quantile(1.0 - p, nu);
            assert!((lo + want).abs() < 1e-9 * want);
        }
        // Large ν → normal.
        assert!((student_t_quantile(0.975, 1e7) - 1.959_963_984_540_05).abs() < 1e-6);
        assert!(student_t_quantile(1.0, 3.0).is_nan());
        assert!(student_t_quantile(0.5, 3.0) == 0.0);
    }

    #[test]
    fn t_cdf_symmetry_and_cauchy() {
        // ν = 1 is Cauchy: F(t) = ½ + atan(t)/π.
        for t in [-5.0, -1.0, 0.3, 2.0, 40.0] {
            let want = 0.5 + f64::atan(t) / std::f64::consts::PI;
            assert!((student_t_cdf(t, 1.0) - want).abs() < 1e-13);
        }
    }
}

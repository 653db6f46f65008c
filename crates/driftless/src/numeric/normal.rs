//! The standard normal distribution: erfc, Φ and Φ⁻¹.

use std::f64::consts::{PI, SQRT_2};

/// Complementary error function, |relative error| < 1e-13 (power series of erf for
/// |x| < 2, Laplace's continued fraction beyond; Abramowitz & Stegun 7.1.5, 7.1.14).
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    if x < 2.0 {
        // erf(x) = 2/√π Σ (−1)ⁿ x^{2n+1}/(n!(2n+1))
        let x2 = x * x;
        let mut term = x;
        let mut sum = x;
        let mut n = 0.0;
        loop {
            n += 1.0;
            term *= -x2 / n;
            let add = term / (2.0 * n + 1.0);
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() || n > 200.0 {
                break;
            }
        }
        return 1.0 - 2.0 / PI.sqrt() * sum;
    }
    if x > 27.0 {
        return 0.0;
    }
    // erfc(x) = e^{−x²}/√π · 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + 2/(x + …)))))
    let mut f = x;
    for k in (1..=80).rev() {
        f = x + (k as f64 / 2.0) / f;
    }
    (-x * x).exp() / PI.sqrt() / f
}

/// Standard normal CDF Φ(x) = ½ erfc(−x/√2).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / SQRT_2)
}

/// Standard normal quantile Φ⁻¹(p): −∞ at p = 0, +∞ at p = 1, NaN outside [0, 1].
///
/// Acklam's rational approximation (P. J. Acklam, "An algorithm for computing the
/// inverse normal cumulative distribution function", 2003; |relative error| < 1.2e-9)
/// refined by one Halley step on [`normal_cdf`]:
///
/// ```text
/// e = Φ(x) − p,  u = e·√(2π)·exp(x²/2),  x ← x − u / (1 + x·u/2)
/// ```
///
/// Halley's step is cubically convergent, so the result is limited by [`erfc`]
/// (|error| < 1e-12 for 1e-300 < p < 1 − 1e-16). The lower half is computed directly and
/// p > ½ by reflection, Φ⁻¹(p) = −Φ⁻¹(1 − p) (1 − p is exact there by Sterbenz's lemma),
/// so the upper tail keeps its precision (Φ(x) rounds to 1 − k·2⁻⁵³ near p = 1).
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return if p == 0.0 {
            f64::NEG_INFINITY
        } else if p == 1.0 {
            f64::INFINITY
        } else {
            f64::NAN
        };
    }
    if p > 0.5 {
        return -normal_quantile(1.0 - p);
    }
    let x = acklam_lower(p);
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * PI).sqrt() * (0.5 * x * x).exp();
    if u.is_finite() {
        x - u / (1.0 + 0.5 * x * u)
    } else {
        // p below ~1e-306: exp(x²/2) overflows; Acklam's value stands.
        x
    }
}

/// Acklam's approximation of Φ⁻¹(p) for 0 < p ≤ ½ (the lower tail below 0.02425, the
/// central rational function above).
fn acklam_lower(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    if p < 0.02425 {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfc_matches_tables() {
        // Reference values: Abramowitz & Stegun table 7.1, R 2*pnorm(-x*sqrt(2)).
        assert!((erfc(1.0) - 0.157_299_207_050_285_13).abs() < 1e-14);
        assert!((erfc(2.0) / 0.004_677_734_981_047_266 - 1.0).abs() < 1e-12);
        assert!((erfc(3.0) / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-12);
        assert!((erfc(-0.5) - 1.520_499_877_813_046_5).abs() < 1e-14);
        assert!(erfc(f64::NAN).is_nan());
        assert_eq!(erfc(30.0), 0.0);
    }

    #[test]
    fn quantiles_match_tables() {
        // Reference values: R qnorm().
        let cases = [
            (0.975, 1.959_963_984_540_054),
            (0.5 + 0.683 / 2.0, 1.000_641_828_762_449),
            (0.841_344_746_068_542_9, 1.0),
            (1.0 - 1e-6, 4.753_424_308_817_088),
            (1.0 - 1e-12, 7.034_486_910_047_835),
        ];
        for (p, want) in cases {
            let got = normal_quantile(p);
            assert!(
                (got - want).abs() < 1e-12 * want.abs().max(1.0),
                "Φ⁻¹({p}) = {got}, want {want}"
            );
        }
        assert_eq!(normal_quantile(0.5), 0.0);
        assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
        assert_eq!(normal_quantile(1.0), f64::INFINITY);
        assert!(normal_quantile(1.5).is_nan());
        assert!(normal_quantile(f64::NAN).is_nan());
    }

    /// Φ(Φ⁻¹(p)) = p to the precision of Φ over 300 decades of the lower tail and the
    /// whole centre, and the function is odd about ½ and strictly increasing.
    #[test]
    fn quantile_inverts_cdf_and_is_monotone() {
        let mut prev = f64::NEG_INFINITY;
        for k in 1..=3000 {
            let p = 10f64.powf(-300.0 + 0.1 * k as f64).min(0.5);
            let x = normal_quantile(p);
            assert!(x >= prev, "not monotone at p = {p}");
            prev = x;
            let back = normal_cdf(x);
            assert!((back / p - 1.0).abs() < 1e-11, "Φ(Φ⁻¹({p})) = {back}");
        }
        for k in 1..1024 {
            // Dyadic p: 1 − p is exact, so the reflection is exact too.
            let p = k as f64 / 1024.0;
            let back = normal_cdf(normal_quantile(p));
            assert!((back - p).abs() < 1e-15, "Φ(Φ⁻¹({p})) = {back}");
            assert_eq!(normal_quantile(1.0 - p), -normal_quantile(p));
        }
        assert!(normal_quantile(f64::MIN_POSITIVE / 1e10) < -38.0);
    }
}

//! Tests of the public CI API: EDF dispatch, bounds, and noise identification on
//! synthetic power-law noise made here (xorshift + Box–Muller, no dependencies).

use super::noise_id::NoiseIdMethod;
use super::*;

/// xorshift64* with Box–Muller normals.
struct Rng(u64, Option<f64>);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1, None)
    }
    fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        // 53 random bits in (0, 1)
        ((x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        if let Some(v) = self.1.take() {
            return v;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let th = 2.0 * std::f64::consts::PI * u2;
        self.1 = Some(r * th.sin());
        r * th.cos()
    }
    fn white(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.normal()).collect()
    }
}

/// Cumulative sum with a leading zero (frequency → phase, N → N + 1 points).
fn integrate(y: &[f64]) -> Vec<f64> {
    let mut x = Vec::with_capacity(y.len() + 1);
    x.push(0.0);
    let mut acc = 0.0;
    for v in y {
        acc += v;
        x.push(acc);
    }
    x
}

/// Approximate flicker (1/f) noise: white noise through the fractional-integration
/// filter h₀ = 1, h_k = h_{k−1}(k − ½)/k (Kasdin & Walter 1992), truncated at n taps.
fn flicker(rng: &mut Rng, n: usize) -> Vec<f64> {
    let w = rng.white(n);
    let mut h = vec![1.0; n];
    for k in 1..n {
        h[k] = h[k - 1] * (k as f64 - 0.5) / k as f64;
    }
    (0..n)
        .map(|i| (0..=i).map(|k| h[k] * w[i - k]).sum())
        .collect()
}

/// Phase data for frequency-noise exponent alpha (2 … −4), `n` frequency samples.
fn power_law_phase(alpha: i32, n: usize, seed: u64) -> Vec<f64> {
    let mut rng = Rng::new(seed);
    match alpha {
        2 => rng.white(n + 1),
        1 => flicker(&mut rng, n + 1),
        0 => integrate(&rng.white(n)),
        -1 => integrate(&flicker(&mut rng, n)),
        -2 => integrate(&integrate(&rng.white(n - 1))),
        -3 => integrate(&integrate(&flicker(&mut rng, n - 1))),
        _ => integrate(&integrate(&integrate(&rng.white(n - 2)))),
    }
}

/// Fraction of `seeds` on which identify_alpha(·, m, est) returns `alpha` within `tol`.
fn hit_rate_tol(alpha: i32, n: usize, m: usize, est: Estimator, seeds: u64, tol: i32) -> f64 {
    let hits = (0..seeds)
        .filter(|&s| {
            let x = power_law_phase(alpha, n, 1000 * (alpha + 10) as u64 + s);
            (identify_alpha(&x, m, est).unwrap() - alpha).abs() <= tol
        })
        .count();
    hits as f64 / seeds as f64
}

fn hit_rate(alpha: i32, n: usize, m: usize, est: Estimator, seeds: u64) -> f64 {
    hit_rate_tol(alpha, n, m, est, seeds, 0)
}

#[test]
fn acf_identifies_allan_range_noises() {
    for alpha in [2, 1, 0, -1, -2] {
        for m in [1usize, 4] {
            // Decimating flicker-PM phase aliases its high-frequency part, which makes
            // it look whiter (δ of the differenced series drifts from −0.5 toward −1):
            // at m > 1 flicker PM is sometimes called white PM.
            let need = if alpha == 1 && m > 1 { 0.6 } else { 0.9 };
            let rate = hit_rate(alpha, 2048, m, Estimator::Oadev, 12);
            assert!(rate >= need, "alpha={alpha} m={m}: hit rate {rate}");
        }
    }
}

#[test]
fn acf_identifies_hadamard_range_noises() {
    for alpha in [0, -1, -2, -3, -4] {
        let rate = hit_rate(alpha, 2048, 1, Estimator::Ohdev, 12);
        assert!(rate >= 0.9, "alpha={alpha} m=1: hit rate {rate}");
    }
    // At m > 1 the m-averaging inherent in decimated phase biases flicker-walk FM
    // (alpha = −3) toward −4; the other Hadamard-range noises are unaffected.
    for alpha in [0, -2, -4] {
        let rate = hit_rate(alpha, 2048, 4, Estimator::Ohdev, 12);
        assert!(rate >= 0.9, "alpha={alpha} m=4: hit rate {rate}");
    }
    let x = power_law_phase(-3, 2048, 5);
    assert!(identify_alpha(&x, 4, Estimator::Ohdev).unwrap() <= -3);
}

#[test]
fn allan_estimators_clamp_divergent_noise_to_minus_two() {
    // Random-run FM (alpha = −4) is outside the Allan range: clamped to −2, while the
    // Hadamard estimators see it.
    let x = power_law_phase(-4, 2048, 7);
    assert_eq!(identify_alpha(&x, 1, Estimator::Adev).unwrap(), -2);
    assert_eq!(identify_alpha(&x, 1, Estimator::Hdev).unwrap(), -4);
}

#[test]
fn acf_reports_method_and_statistics() {
    let x = power_law_phase(0, 4096, 3);
    let id = identify_noise(&x, 1, Estimator::Oadev).unwrap();
    match id.method {
        NoiseIdMethod::Lag1Acf { d, delta } => {
            assert_eq!(d, 1, "white FM phase needs one difference");
            assert!(delta.abs() < 0.1, "delta {delta}");
        }
        other => panic!("expected ACF, got {other:?}"),
    }
    assert!((id.alpha_est - 0.0).abs() < 0.2, "{}", id.alpha_est);
}

#[test]
fn b1_fallback_for_short_series() {
    // 2048 samples at m = 128 leave 17 decimated points (< 30): B1 / R(n) is used.
    let x = power_law_phase(0, 2048, 11);
    let id = identify_noise(&x, 128, Estimator::Oadev).unwrap();
    assert!(matches!(id.method, NoiseIdMethod::B1 { .. }), "{id:?}");
    // B1 from 16 averages is a coarse statistic (the standard variance of a random walk
    // has very few degrees of freedom): require mostly-right, and nearly always within
    // one class.
    for alpha in [2, 0, -2] {
        let rate = hit_rate(alpha, 2048, 128, Estimator::Oadev, 20);
        let near = hit_rate_tol(alpha, 2048, 128, Estimator::Oadev, 20, 1);
        assert!(
            rate >= 0.4 && near >= 0.9,
            "alpha={alpha}: B1 hit rate {rate}, ±1 {near}"
        );
    }
}

#[test]
fn b1_theory_special_cases() {
    // B1(N, −1) = 1 (white FM), B1(N, 1) = N/2 (RW FM), μ → 0 limit continuous.
    assert!((noise_id::b1_theory(10.0, -1.0) - 1.0).abs() < 1e-12);
    assert!((noise_id::b1_theory(10.0, 1.0) - 5.0).abs() < 1e-12);
    let l = noise_id::b1_theory(10.0, 0.0);
    assert!((noise_id::b1_theory(10.0, 1e-6) - l).abs() < 1e-4);
}

#[test]
fn identify_errors_and_tiny_inputs() {
    let x = power_law_phase(0, 100, 1);
    assert!(matches!(
        identify_alpha(&x, 0, Estimator::Adev),
        Err(AllanError::Invalid(_))
    ));
    let mut bad = x.clone();
    bad[5] = f64::NAN;
    assert!(matches!(
        identify_alpha(&bad, 1, Estimator::Adev),
        Err(AllanError::NonFinite { index: 5, .. })
    ));
    assert!(identify_alpha(&x[..3], 1, Estimator::Adev).is_err());
    assert!(identify_alpha(&[], 1, Estimator::Adev).is_err());
    // m far too large for the data: falls back to the longest identifiable factor.
    let a = identify_alpha(&x, 90, Estimator::Adev).unwrap();
    assert!((-2..=2).contains(&a));
    // 10 points: B1 at m = 1.
    let a = identify_alpha(&x[..10], 1, Estimator::Ohdev).unwrap();
    assert!((-2..=2).contains(&a));
    // Constant data does not produce NaN or panic.
    let a = identify_alpha(&[1.0; 64], 2, Estimator::Adev).unwrap();
    assert!((-2..=2).contains(&a));
}

#[test]
fn edf_dispatch() {
    let n = 10_001;
    for alpha in -2..=2 {
        for m in [1usize, 3, 64, 1000] {
            assert_eq!(
                edf(Estimator::Tdev, alpha, m, n),
                edf(Estimator::Mdev, alpha, m, n)
            );
            assert_eq!(
                edf(Estimator::Oadev, alpha, m, n),
                edf_greenhall(alpha, 2, m, m as f64, m as f64, n)
            );
        }
    }
    // Overlapping estimators have more EDF than non-overlapping ones.
    for alpha in -2..=2 {
        assert!(edf(Estimator::Oadev, alpha, 16, n) > edf(Estimator::Adev, alpha, 16, n));
        assert!(edf(Estimator::Ohdev, alpha, 16, n) > edf(Estimator::Hdev, alpha, 16, n));
    }
    // Clamping of alpha to the estimator's range.
    assert_eq!(
        edf(Estimator::Adev, -4, 8, n),
        edf(Estimator::Adev, -2, 8, n)
    );
    assert_eq!(
        edf(Estimator::Oadev, 7, 8, n),
        edf(Estimator::Oadev, 2, 8, n)
    );
    assert_ne!(
        edf(Estimator::Hdev, -4, 8, n),
        edf(Estimator::Hdev, -2, 8, n)
    );
    // TOTDEV: b·(N−1)/m − c.
    assert!((edf(Estimator::Totdev, -1, 10, n) - (1.17 * 1000.0 - 0.22)).abs() < 1e-9);
    assert!((edf(Estimator::Totdev, 0, 4, n) - 1.5 * 2500.0).abs() < 1e-9);
}

#[test]
fn strided_edf_spans_adev_to_oadev() {
    let n = 100_001;
    for alpha in -2..=2 {
        for m in [1usize, 8, 64, 1000] {
            let full = edf(Estimator::Oadev, alpha, m, n);
            let none = edf(Estimator::Adev, alpha, m, n);
            assert!((edf_strided(alpha, m, 1, n) - full).abs() <= 1e-9 * full);
            assert!((edf_strided(alpha, m, m, n) - none).abs() <= 1e-9 * none);
            // More overlap (smaller stride) never loses degrees of freedom, up to the
            // ~1–3 % accuracy of the paper's Table 2 fit (used once (d+1)S > J_max; for
            // random-walk FM extra overlap adds almost nothing, so the fit error shows).
            let mut prev = none;
            for stride in [m / 2, m / 8, m / 64].into_iter().filter(|&s| s >= 1) {
                let e = edf_strided(alpha, m, stride, n);
                assert!(
                    e >= prev * 0.97,
                    "a={alpha} m={m} stride={stride}: {e} < {prev}"
                );
                prev = e;
            }
            // Fully overlapping OADEV has clearly more EDF than ADEV except for RW FM.
            if alpha > -2 && m > 1 {
                assert!(full > 1.2 * none, "a={alpha} m={m}: {full} vs {none}");
            }
        }
    }
    // Out-of-range stride is clamped.
    assert_eq!(edf_strided(0, 8, 0, n), edf_strided(0, 8, 1, n));
    assert_eq!(edf_strided(0, 8, 99, n), edf_strided(0, 8, 8, n));
}

#[test]
fn edf_is_finite_and_positive_for_any_input() {
    for est in Estimator::ALL {
        for alpha in [-100, -5, -4, -3, -2, -1, 0, 1, 2, 3, 100] {
            for m in [0usize, 1, 2, 7, 100, 1 << 20, usize::MAX] {
                for n in [0usize, 1, 2, 3, 5, 10, 1000, 1 << 30] {
                    let e = edf(est, alpha, m, n);
                    assert!(
                        e.is_finite() && e >= 1.0,
                        "{est:?} a={alpha} m={m} n={n}: {e}"
                    );
                }
            }
        }
    }
}

#[test]
fn bounds_properties() {
    let dev = 2.5e-11;
    let (lo, hi) = bounds(dev, 50.0, 0.683);
    assert!(lo < dev && dev < hi);
    // Definition: lo² = dev²·edf/χ²(1 − (1 − cl)/2), hi² = dev²·edf/χ²((1 − cl)/2).
    let p = 0.5 * (1.0 - 0.683);
    assert!((lo * lo - dev * dev * 50.0 / chi2_quantile(1.0 - p, 50.0)).abs() < 1e-12 * dev * dev);
    assert!((hi * hi - dev * dev * 50.0 / chi2_quantile(p, 50.0)).abs() < 1e-12 * dev * dev);
    // Large EDF: half-width → σ/√(2·edf) at 1σ.
    let nu = 1e6;
    let (lo, hi) = bounds(1.0, nu, ONE_SIGMA_CL);
    let hw = 0.5 * (hi - lo);
    assert!((hw * (2.0 * nu).sqrt() - 1.0).abs() < 1e-3, "{hw}");
    // Wider at higher confidence and for fewer degrees of freedom.
    let (l1, h1) = bounds(1.0, 10.0, 0.683);
    let (l2, h2) = bounds(1.0, 10.0, 0.95);
    let (l3, h3) = bounds(1.0, 3.0, 0.683);
    assert!(l2 < l1 && h2 > h1 && l3 < l1 && h3 > h1);
    // Degenerate inputs: never NaN.
    assert_eq!(bounds(1.0, f64::INFINITY, 0.683), (1.0, 1.0));
    assert_eq!(bounds(1.0, 0.0, 0.683), (0.0, f64::INFINITY));
    assert_eq!(bounds(1.0, f64::NAN, 0.683), (0.0, f64::INFINITY));
    assert_eq!(bounds(1.0, 5.0, 1.0), (0.0, f64::INFINITY));
    let (l, h) = bounds(1.0, 5.0, f64::NAN);
    assert_eq!((l, h), bounds(1.0, 5.0, ONE_SIGMA_CL));
    // Sub-unity EDF (never produced by `edf`): still ordered and not NaN.
    let (l, h) = bounds(1.0, 1e-3, 0.683);
    assert!(!l.is_nan() && !h.is_nan() && l <= h, "{l} {h}");
}

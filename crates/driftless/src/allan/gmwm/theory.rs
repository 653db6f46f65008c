//! Closed-form Haar wavelet variance of each GMWM process.
//!
//! Sampled rate data y_t (interval τ0), averaging length m samples, τ = m·τ0. The Haar
//! MODWT coefficient at level j (filter width L_j = 2m, m = 2^{j−1}) is half the
//! difference of two adjacent m-sample means, W = (ȳ_b − ȳ_a)/2, so the wavelet variance
//! is ν²(τ) = E\[W²\] = σ²_A(τ)/2, half the Allan variance at the same τ (Percival &
//! Guttorp 1994; Percival & Walden 2000, §8.6). Each formula below is the exact Allan
//! variance of the *discrete* process at integer m, halved:
//!
//! | process | parameters (SI) | ν²(m) |
//! |---|---|---|
//! | white noise | N \[u·√s], sample variance σ² = N²/τ0 | σ²/(2m) |
//! | quantization | Q \[u·s], white phase error of variance Q², y = Δe/τ0 | 3Q²/(2τ²) |
//! | random walk | K \[u/√s], step variance γ² = K²·τ0 | γ²(2m² + 1)/(12m) |
//! | drift | R \[u/s], y_t = R·t·τ0 | R²τ²/4 |
//! | Gauss–Markov (AR(1)) | stationary σ_b \[u], T \[s], φ = e^{−τ0/T} | σ_b²·f/(2(1−φ)²m²) |
//!
//! with f = m(1 − φ²) − 3φ + 4φ^{m+1} − φ^{2m+1} (Zhang 2008, "Allan variance of time
//! series models for measurement data", Metrologia 45, eq. for AR(1); Guerrier et al.
//! 2013, JASA 108, §2, where the same forms are written with τ_j = 2m). Derivations:
//! white and quantization from the variance of the second difference of phase; random
//! walk from ȳ_{k+1} − ȳ_k = (1/m)Σ c_l ε_l with c_l = min(l, 2m − l), Σc_l² =
//! m(2m² + 1)/3; AR(1) from σ²_A = Var ȳ − Cov(ȳ_k, ȳ_{k+1}) with γ(h) = σ_b² φ^|h|.
//! For φ → 1 the AR(1) numerator cancels catastrophically; with a = τ0/T and u = m·a it
//! is evaluated as f = e^{−a}[c(u) + 2m(sinh a − a)], c(u) = 2u − 3 + 4e^{−u} − e^{−2u},
//! each bracket by its Taylor series where it is small. `m` may be non-integer (a τ
//! that is not a multiple of τ0) in every formula: that is the natural interpolation.

/// c(u) = 2u − 3 + 4e^{−u} − e^{−2u} ≥ 0, accurate to ~1e-15 relative for every u ≥ 0:
/// series Σ_{k≥3} (−1)^k (4 − 2^k) u^k / k! below u = 1, expm1 form above.
pub(crate) fn c_u(u: f64) -> f64 {
    if u < 1.0 {
        let mut s = 0.0;
        let mut pow = u * u * u / 6.0; // u^k / k! at k = 3
        let mut two_k = 8.0;
        let mut sign = -1.0;
        for k in 3..40 {
            let t = sign * (4.0 - two_k) * pow;
            s += t;
            if t.abs() < 1e-17 * s.abs() {
                break;
            }
            pow *= u / (k as f64 + 1.0);
            two_k *= 2.0;
            sign = -sign;
        }
        s
    } else {
        2.0 * u + 4.0 * (-u).exp_m1() - (-2.0 * u).exp_m1()
    }
}

/// sinh(a) − a, accurate for small a (series a³/3! + a⁵/5! + …).
fn sinh_minus_x(a: f64) -> f64 {
    if a < 0.1 {
        let a2 = a * a;
        a * a2 / 6.0 * (1.0 + a2 / 20.0 * (1.0 + a2 / 42.0 * (1.0 + a2 / 72.0)))
    } else {
        a.sinh() - a
    }
}

/// Haar WV of white noise with density `n` (u·√s) at averaging length `m` samples.
pub(crate) fn wv_white(n: f64, m: f64, tau0_s: f64) -> f64 {
    n * n / (2.0 * m * tau0_s)
}

/// Haar WV of quantization noise Q (u·s).
pub(crate) fn wv_quantization(q: f64, m: f64, tau0_s: f64) -> f64 {
    let tau = m * tau0_s;
    1.5 * q * q / (tau * tau)
}

/// Haar WV of a random walk of density `k` (u/√s), step variance γ² = K²τ0.
pub(crate) fn wv_random_walk(k: f64, m: f64, tau0_s: f64) -> f64 {
    k * k * tau0_s * (2.0 * m * m + 1.0) / (12.0 * m)
}

/// Haar WV of a linear drift of slope `r` (u/s).
pub(crate) fn wv_drift(r: f64, m: f64, tau0_s: f64) -> f64 {
    let tau = m * tau0_s;
    r * r * tau * tau / 4.0
}

/// Haar WV of a stationary first-order Gauss–Markov (AR(1)) process sampled at τ0:
/// stationary σ_b (u), correlation time T (s), φ = e^{−τ0/T}.
pub(crate) fn wv_gauss_markov(sigma: f64, tau_c_s: f64, m: f64, tau0_s: f64) -> f64 {
    let a = tau0_s / tau_c_s;
    let one_minus_phi = -(-a).exp_m1();
    let f = (-a).exp() * (c_u(m * a) + 2.0 * m * sinh_minus_x(a));
    sigma * sigma * f / (2.0 * one_minus_phi * one_minus_phi * m * m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct O(m²) evaluation of the AR(1) Allan variance from its autocovariance:
    /// σ²_A = Var ȳ − Cov(ȳ_k, ȳ_{k+1}).
    fn ar1_avar_direct(sigma: f64, phi: f64, m: usize) -> f64 {
        let g = |h: i64| sigma * sigma * phi.powi(h.unsigned_abs() as i32);
        let mut var = 0.0;
        let mut cov = 0.0;
        for i in 0..m as i64 {
            for j in 0..m as i64 {
                var += g(i - j);
                cov += g(m as i64 + i - j);
            }
        }
        (var - cov) / (m * m) as f64
    }

    #[test]
    fn gauss_markov_form_matches_the_autocovariance_sum() {
        let tau0 = 0.01;
        // Up to T = 1e4 s: beyond, the O(m²) reference itself loses digits (Var ȳ and
        // the covariance agree to 1 − τ0/T); the random-walk limit test covers T ≫ τ.
        for &t in &[0.003f64, 0.05, 1.0, 30.0, 1e4] {
            let phi = (-tau0 / t).exp();
            for &m in &[1usize, 2, 3, 8, 64, 200] {
                let want = 0.5 * ar1_avar_direct(2.0, phi, m);
                let got = wv_gauss_markov(2.0, t, m as f64, tau0);
                assert!(
                    (got / want - 1.0).abs() < 1e-6,
                    "T={t} m={m}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn c_u_series_and_closed_form_agree_at_the_switch() {
        let direct = |u: f64| 2.0 * u - 3.0 + 4.0 * (-u).exp() - (-2.0 * u).exp();
        for &u in &[0.5, 0.9, 0.999, 1.0, 1.5] {
            assert!((c_u(u) / direct(u) - 1.0).abs() < 1e-12, "{u}");
        }
        // Leading term (2/3)u³ for tiny u.
        assert!((c_u(1e-6) / (2.0 / 3.0 * 1e-18) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn limits_of_the_gauss_markov_form() {
        let tau0 = 0.01;
        // T ≫ τ: a random walk of step variance σ_b²(1 − φ²) ≈ 2σ_b²τ0/T.
        let (s, t) = (1.0f64, 1e7f64);
        let k = (2.0 * s * s / t).sqrt();
        let m = 100.0;
        let rw = wv_random_walk(k, m, tau0);
        assert!((wv_gauss_markov(s, t, m, tau0) / rw - 1.0).abs() < 1e-4);
        // T ≪ τ: white noise of density N² = 2σ_b²T (two-sided PSD at f = 0).
        let t = 0.5f64;
        let m = 1e6;
        let n = (2.0 * s * s * t).sqrt();
        let w = wv_white(n, m, tau0);
        assert!((wv_gauss_markov(s, t, m, tau0) / w - 1.0).abs() < 1e-3);
        // m = 1: ν² = σ_b²(1 − φ)/2.
        let phi = (-tau0 / 0.2f64).exp();
        assert!((wv_gauss_markov(s, 0.2, 1.0, tau0) / (0.5 * (1.0 - phi)) - 1.0).abs() < 1e-12);
    }
}

//! IMU noise-term fit to an Allan variance curve.
//!
//! OWNER: helper "fit". Model (IEEE Std 952-1997 Annex C; SP 1065):
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2 [+ Gauss-Markov term].
//! All values SI: data units u (rad/s or m/s²) → Q [u·s], N [u·√s], B [u],
//! K [u/√s], R [u/s].

use serde::{Deserialize, Serialize};

/// Which terms to fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitConfig {
    /// Quantization noise Q.
    pub quantization: bool,
    /// White noise N (ARW / VRW).
    pub white: bool,
    /// Bias instability B (flicker floor).
    pub bias_instability: bool,
    /// Rate random walk K.
    pub rate_random_walk: bool,
    /// Rate ramp R.
    pub rate_ramp: bool,
    /// One first-order Gauss-Markov term (σ, correlation time).
    pub gauss_markov: bool,
}

impl Default for FitConfig {
    fn default() -> Self {
        FitConfig {
            quantization: true,
            white: true,
            bias_instability: true,
            rate_random_walk: true,
            rate_ramp: true,
            gauss_markov: false,
        }
    }
}

/// A fitted coefficient with its confidence interval (same confidence level as the fit).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Term {
    /// Estimate, SI units.
    pub value: f64,
    /// Lower confidence bound.
    pub lo: f64,
    /// Upper confidence bound.
    pub hi: f64,
}

/// First-order Gauss-Markov term: b' = −b/T + w, stationary σ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussMarkovTerm {
    /// Stationary standard deviation, data units.
    pub sigma: Term,
    /// Correlation time T, s.
    pub tau_c_s: Term,
}

/// Result of the noise-term fit. A `None` term was switched off (or fitted to zero and dropped).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseFit {
    /// Quantization Q, u·s.
    pub quantization: Option<Term>,
    /// White noise density N, u·√s (ARW rad/√s, VRW m/s/√s).
    pub white: Option<Term>,
    /// Bias instability B, u.
    pub bias_instability: Option<Term>,
    /// Rate random walk K, u/√s.
    pub rate_random_walk: Option<Term>,
    /// Rate ramp R, u/s.
    pub rate_ramp: Option<Term>,
    /// Optional Gauss-Markov term.
    pub gauss_markov: Option<GaussMarkovTerm>,
    /// Confidence level of the term intervals.
    pub confidence: f64,
    /// RMS of log10(model/measured) over the fitted points.
    pub rms_log10_residual: f64,
}

impl NoiseFit {
    /// Model Allan variance at `tau` from the fitted terms.
    pub fn model_avar(&self, tau: f64) -> f64 {
        let v = |t: &Option<Term>| t.map(|t| t.value).unwrap_or(0.0);
        let (q, n, b, k, r) = (
            v(&self.quantization),
            v(&self.white),
            v(&self.bias_instability),
            v(&self.rate_random_walk),
            v(&self.rate_ramp),
        );
        let mut s = 3.0 * q * q / (tau * tau)
            + n * n / tau
            + 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI * b * b
            + k * k * tau / 3.0
            + r * r * tau * tau / 2.0;
        if let Some(gm) = &self.gauss_markov {
            s += gauss_markov_avar(gm.sigma.value, gm.tau_c_s.value, tau);
        }
        s
    }
}

/// Allan variance of a first-order Gauss-Markov process with stationary σ and
/// correlation time T (IEEE Std 952-1997 Annex C, exponentially correlated noise):
/// with u = τ/T: σ²_A(τ) = (σ²/u²)·(2u − 3 + 4e^{−u} − e^{−2u}), i.e. the
/// standard (q_c²T²/τ)[1 − (T/2τ)(3 − 4e^{−τ/T} + e^{−2τ/T})] with q_c² = 2σ²/T.
/// Small u behaves like rate random walk (2σ²u/3), large u like white noise (2σ²/u).
pub fn gauss_markov_avar(sigma: f64, tau_c: f64, tau: f64) -> f64 {
    let u = tau / tau_c;
    if u < 1e-3 {
        // series: 2u − 3 + 4e^{−u} − e^{−2u} = (2/3)u³ − (1/2)u⁴ + (7/30)u⁵ + O(u⁶)
        return sigma * sigma * u * (2.0 / 3.0 - u / 2.0 + 7.0 / 30.0 * u * u);
    }
    sigma * sigma / (u * u) * (2.0 * u - 3.0 + 4.0 * (-u).exp() - (-2.0 * u).exp())
}

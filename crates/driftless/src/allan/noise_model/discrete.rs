//! The per-sample view of the continuous terms that a discrete-time filter or simulator
//! needs, and the τ where the model's floor lies.

use serde::{Deserialize, Serialize};

use crate::allan::fit::{BIAS_AVAR_COEF, NoiseFit, Term, gauss_markov_avar_peak};

/// Discrete first-order Gauss-Markov process b_{k+1} = φ b_k + w_k.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiscreteGaussMarkov {
    /// Stationary σ_b, u.
    pub sigma: f64,
    /// Correlation time T_c, s.
    pub tau_c_s: f64,
    /// φ = e^{−Δt/T_c}.
    pub phi: f64,
    /// Std of the per-sample driving noise w_k, σ_b·√(1 − φ²), u.
    pub sigma_w: f64,
    /// Continuous driving-noise PSD q_c = 2σ_b²/T_c, u²/s.
    pub q_c: f64,
}

impl DiscreteGaussMarkov {
    /// Discretise (σ, T_c) at sample interval `dt`.
    pub fn new(sigma: f64, tau_c_s: f64, dt: f64) -> DiscreteGaussMarkov {
        let phi = (-dt / tau_c_s).exp();
        DiscreteGaussMarkov {
            sigma,
            tau_c_s,
            phi,
            sigma_w: sigma * (1.0 - phi * phi).max(0.0).sqrt(),
            q_c: 2.0 * sigma * sigma / tau_c_s,
        }
    }
}

/// Per-sample (discrete-time) noise parameters at the model's sample rate, SI units
/// (u = rad/s or m/s²). `None` = term absent. See the module table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiscreteNoise {
    /// Sample rate the discrete values refer to, Hz.
    pub sample_rate_hz: f64,
    /// Std of the white noise on each rate sample, σ_d = N·√f_s, u.
    pub white_sigma: Option<f64>,
    /// Continuous white-noise PSD N² (two-sided), u²/Hz — for continuous-time filters.
    pub white_psd: Option<f64>,
    /// Std of the bias random-walk step per sample, K·√Δt, u.
    pub rate_random_walk_sigma: Option<f64>,
    /// Continuous PSD of the bias derivative K², u²/s.
    pub rate_random_walk_psd: Option<f64>,
    /// Std of the quantization noise of each integrated sample (angle/velocity), Q, u·s.
    pub quantization_sigma: Option<f64>,
    /// Bias change per sample from the rate ramp, R·Δt, u.
    pub rate_ramp_per_sample: Option<f64>,
    /// First-order Gauss-Markov stand-in for the bias instability: Allan-variance peak
    /// (0.3811 σ_b² at τ = 1.893 T_c) equal to the floor (2 ln2/π)B² at the τ where the
    /// fitted curve is lowest. An approximation: one GM reproduces the floor only near
    /// that τ.
    pub bias_instability_gm: Option<DiscreteGaussMarkov>,
    /// The fitted Gauss-Markov term, discretised.
    pub gauss_markov: Option<DiscreteGaussMarkov>,
}

/// Discrete per-sample parameters of a fit at sample rate `fs` (Hz).
pub fn discrete_noise(fit: &NoiseFit, fs: f64) -> DiscreteNoise {
    let dt = 1.0 / fs;
    let v = |t: Option<Term>| t.map(|t| t.value);
    let bias_instability_gm = v(fit.bias_instability).and_then(|b| {
        let (u_peak, peak) = gauss_markov_avar_peak();
        let tau_floor = bias_floor_tau(fit)?;
        let sigma = (BIAS_AVAR_COEF * b * b / peak).sqrt();
        Some(DiscreteGaussMarkov::new(sigma, tau_floor / u_peak, dt))
    });
    DiscreteNoise {
        sample_rate_hz: fs,
        white_sigma: v(fit.white).map(|n| n * fs.sqrt()),
        white_psd: v(fit.white).map(|n| n * n),
        rate_random_walk_sigma: v(fit.rate_random_walk).map(|k| k * dt.sqrt()),
        rate_random_walk_psd: v(fit.rate_random_walk).map(|k| k * k),
        quantization_sigma: v(fit.quantization),
        rate_ramp_per_sample: v(fit.rate_ramp).map(|r| r * dt),
        bias_instability_gm,
        gauss_markov: fit
            .gauss_markov
            .map(|g| DiscreteGaussMarkov::new(g.sigma.value, g.tau_c_s.value, dt)),
    }
}

/// τ of the fitted curve's floor when the fit saw it: the model minimum
/// ([`model_minimum_tau`]) if it lies inside the fitted τ range, None beyond it (the
/// floor's place, and so the correlation time of a Gauss-Markov stand-in, is then not
/// known — without a rate random walk the minimum is only the scan's end).
pub fn bias_floor_tau(fit: &NoiseFit) -> Option<f64> {
    let t = model_minimum_tau(fit);
    match fit.fit_range {
        Some(r) if t > r.tau_max_s => None,
        _ => Some(t),
    }
}

/// τ (s) minimising the fitted Allan variance over 1e-4 … 1e7 s (log-spaced scan then
/// golden refinement). With only white + bias + RRW this is √3·N/K.
pub fn model_minimum_tau(fit: &NoiseFit) -> f64 {
    let f = |lt: f64| fit.model_avar(lt.exp());
    let (lo, hi) = (1e-4f64.ln(), 1e7f64.ln());
    let n = 221;
    let mut best = (lo, f64::INFINITY);
    for i in 0..n {
        let x = lo + (hi - lo) * i as f64 / (n - 1) as f64;
        let v = f(x);
        if v < best.1 {
            best = (x, v);
        }
    }
    let step = (hi - lo) / (n - 1) as f64;
    let (x, _) = crate::allan::fit::golden_max(|x| -f(x), best.0 - step, best.0 + step);
    x.exp()
}

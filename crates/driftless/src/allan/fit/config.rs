//! What to fit: the terms switched on, and what the fit knows of the record (sample
//! interval, length, model-error floor).

use serde::{Deserialize, Serialize};

use crate::allan::AllanError;

use super::result::TermKind;

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

impl FitConfig {
    /// Every term switched off (a starting point for building a selection).
    pub const NONE: FitConfig = FitConfig {
        quantization: false,
        white: false,
        bias_instability: false,
        rate_random_walk: false,
        rate_ramp: false,
        gauss_markov: false,
    };
}

/// Parses a comma-separated term list: `q` quantization, `n` white noise, `b` bias
/// instability, `k` rate random walk, `r` rate ramp, `gm` one Gauss-Markov term.
impl std::str::FromStr for FitConfig {
    type Err = AllanError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut c = FitConfig::NONE;
        for t in s.split(',').map(|t| t.trim().to_ascii_lowercase()) {
            match t.as_str() {
                "q" => c.quantization = true,
                "n" => c.white = true,
                "b" => c.bias_instability = true,
                "k" => c.rate_random_walk = true,
                "r" => c.rate_ramp = true,
                "gm" => c.gauss_markov = true,
                "" => {}
                other => {
                    return Err(AllanError::Invalid(format!(
                        "unknown noise term {other:?} in {s:?} (expected q, n, b, k, r, gm)"
                    )));
                }
            }
        }
        Ok(c)
    }
}

impl FitConfig {
    /// The same selection with `kind` switched off.
    pub fn without(self, kind: TermKind) -> FitConfig {
        let mut c = self;
        match kind {
            TermKind::Quantization => c.quantization = false,
            TermKind::White => c.white = false,
            TermKind::BiasInstability => c.bias_instability = false,
            TermKind::RateRandomWalk => c.rate_random_walk = false,
            TermKind::RateRamp => c.rate_ramp = false,
            TermKind::GaussMarkov => c.gauss_markov = false,
        }
        c
    }

    /// The five terms of IEEE Std 952-1997: quantization, white noise, bias
    /// instability, rate random walk, rate ramp.
    pub const IEEE_952: FitConfig = FitConfig {
        quantization: true,
        white: true,
        bias_instability: true,
        rate_random_walk: true,
        rate_ramp: true,
        gauss_markov: false,
    };
}

/// The IEEE 952 terms and one Gauss-Markov term. Real MEMS gyros and accelerometers
/// often carry a correlated bias whose Allan curve rises and falls again between the
/// flicker floor and the longest τ (the sums of Gauss-Markov processes their makers and
/// the GMWM literature model them with); the five IEEE terms can only follow it by
/// bending a rate random walk through it. The term stays only where the data resolve
/// it (see `noise_model::fit_supported_terms`).
impl Default for FitConfig {
    fn default() -> Self {
        FitConfig {
            gauss_markov: true,
            ..FitConfig::IEEE_952
        }
    }
}

impl FitConfig {
    /// The linear terms switched on, in model order.
    pub(crate) fn linear_terms(&self) -> Vec<TermKind> {
        let mut v = Vec::new();
        for (on, k) in [
            (self.quantization, TermKind::Quantization),
            (self.white, TermKind::White),
            (self.bias_instability, TermKind::BiasInstability),
            (self.rate_random_walk, TermKind::RateRandomWalk),
            (self.rate_ramp, TermKind::RateRamp),
        ] {
            if on {
                v.push(k);
            }
        }
        v
    }
}

/// Relative model-error floor f of the fit weights: var σ̂²_i = m_i²·(2/ν_i + f²), so a
/// point never counts as more precise than f, whatever its EDF.
pub(crate) const MODEL_ERROR_FLOOR: f64 = 0.003;

/// Smallest Gauss-Markov correlation time, in sample intervals: a shorter one is white
/// noise at every τ the curve has.
pub(crate) const GM_MIN_SAMPLES: f64 = 5.0;
/// Resolution of the Gauss-Markov correlation-time search in ln T (relative, so
/// 1e-5·(1 + |ln T|): a few 0.01 % of T, far inside its interval).
pub(super) const GM_LN_T_TOL: f64 = 1e-5;
/// Largest Gauss-Markov correlation time as a fraction of the record: a longer one is a
/// random walk over the record and its σ and T cannot be separated.
pub(crate) const GM_MAX_RECORD_FRACTION: f64 = 0.1;

/// What the fit needs to know about the record beyond the curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Sample interval, s (bounds the Gauss-Markov correlation time from below at
    /// `GM_MIN_SAMPLES`·τ0).
    pub tau0_s: Option<f64>,
    /// Record length, s (bounds the Gauss-Markov correlation time from above at
    /// `GM_MAX_RECORD_FRACTION` of it).
    pub record_s: Option<f64>,
    /// Relative model-error floor of the weights (see `MODEL_ERROR_FLOOR`).
    pub model_error_floor: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            tau0_s: None,
            record_s: None,
            model_error_floor: MODEL_ERROR_FLOOR,
        }
    }
}

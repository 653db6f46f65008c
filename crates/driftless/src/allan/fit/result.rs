//! The fitted noise terms with their intervals, upper limits of undetected terms, and the
//! reading of χ²_red.

use serde::{Deserialize, Serialize};

use super::range::FitRange;
use super::{BIAS_AVAR_COEF, gauss_markov_avar, gauss_markov_avar_peak};

/// The noise terms of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TermKind {
    /// Quantization Q.
    Quantization,
    /// White noise N.
    White,
    /// Bias instability B.
    BiasInstability,
    /// Rate random walk K.
    RateRandomWalk,
    /// Rate ramp R.
    RateRamp,
    /// Gauss-Markov σ.
    GaussMarkov,
}

impl TermKind {
    /// The linear terms of IEEE Std 952, in model order.
    pub const LINEAR: [TermKind; 5] = [
        TermKind::Quantization,
        TermKind::White,
        TermKind::BiasInstability,
        TermKind::RateRandomWalk,
        TermKind::RateRamp,
    ];

    /// Allan variance per unit squared coefficient at `tau` (linear terms; the
    /// Gauss-Markov shape depends on T, see [`gauss_markov_avar`]).
    pub(crate) fn basis(self, tau: f64) -> f64 {
        match self {
            TermKind::Quantization => 3.0 / (tau * tau),
            TermKind::White => 1.0 / tau,
            TermKind::BiasInstability => BIAS_AVAR_COEF,
            TermKind::RateRandomWalk => tau / 3.0,
            TermKind::RateRamp => tau * tau / 2.0,
            TermKind::GaussMarkov => f64::NAN,
        }
    }

    /// Power-law exponent α of the frequency PSD (S_y ∝ f^α) the term corresponds to,
    /// clamped to the Allan-variance range −2..=2 (rate ramp is treated as random walk).
    pub fn alpha(self) -> i32 {
        match self {
            TermKind::Quantization => 2,
            TermKind::White => 0,
            TermKind::BiasInstability => -1,
            TermKind::RateRandomWalk | TermKind::RateRamp => -2,
            TermKind::GaussMarkov => -1,
        }
    }

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            TermKind::Quantization => "quantization",
            TermKind::White => "white",
            TermKind::BiasInstability => "bias_instability",
            TermKind::RateRandomWalk => "rate_random_walk",
            TermKind::RateRamp => "rate_ramp",
            TermKind::GaussMarkov => "gauss_markov",
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

impl Term {
    /// Whether `x` lies inside [lo, hi].
    pub fn covers(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
}

/// First-order Gauss-Markov term: b' = −b/T + w, stationary σ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussMarkovTerm {
    /// Stationary standard deviation, data units.
    pub sigma: Term,
    /// Correlation time T, s.
    pub tau_c_s: Term,
}

/// A term that was switched on but fitted to zero: not detected, with an upper limit
/// (upper end of the two-sided interval at the fit's confidence), SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct UpperLimit {
    /// Which term.
    pub term: TermKind,
    /// Upper limit of the coefficient (Q, N, B, K, R or σ_GM), SI units.
    pub upper: f64,
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
    /// Terms that were fitted but came out zero, with upper limits.
    #[serde(default)]
    pub not_detected: Vec<UpperLimit>,
    /// Weighted χ² per degree of freedom of the final fit (≈ ≤ 1 for an adequate model;
    /// the points are correlated, so this is a misfit indicator, not a test statistic).
    #[serde(default)]
    pub chi2_reduced: f64,
    /// Number of (tau, avar) points fitted.
    #[serde(default)]
    pub n_points: usize,
    /// The τ range the model was fitted over and how it was chosen (absent in files
    /// written before the range was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_range: Option<FitRange>,
    /// Terms the data cannot pin down (a Gauss-Markov correlation time at its search
    /// bound, a quantization far above the resolution step, …): reported here, never
    /// stored as values.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_identifiable: Vec<NotIdentifiable>,
}

/// A term that was switched on but that the data cannot determine, with the reason.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NotIdentifiable {
    /// Which term.
    pub term: TermKind,
    /// Why, in plain words.
    pub reason: String,
}

/// χ²_red above which a fit is reported as not describing the curve.
pub const CHI2_RED_WARN: f64 = 5.0;
/// χ²_red up to which a fit is reported as following the curve within its uncertainty.
pub(crate) const CHI2_RED_GOOD: f64 = 2.0;

/// Plain-words reading of χ²_red and whether it deserves a warning.
pub fn chi2_verdict(chi2_red: f64) -> (&'static str, bool) {
    if !chi2_red.is_finite() {
        ("no goodness of fit (too few points)", true)
    } else if chi2_red <= CHI2_RED_GOOD {
        (
            "good: the model follows the curve within its uncertainty",
            false,
        )
    } else if chi2_red <= CHI2_RED_WARN {
        ("fair: small systematic departures from the curve", false)
    } else {
        (
            "poor: the model does not describe the curve (check the fit range and the terms)",
            true,
        )
    }
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

    /// The band of Allan variances the stated intervals allow at `tau`: every term at
    /// the lower end of its interval (undetected terms at zero), and every term at the
    /// upper end (undetected terms at their upper limit; a Gauss-Markov term at the
    /// correlation time within its interval that gives the most, resp. least). A
    /// conservative envelope — the terms' errors are not all of one sign — for reading
    /// where a model's intervals say another recording of the sensor may lie.
    pub fn model_avar_band(&self, tau: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (0.0, 0.0);
        for kind in TermKind::LINEAR {
            let basis = kind.basis(tau);
            if let Some(t) = self.term(kind) {
                lo += t.lo * t.lo * basis;
                hi += t.hi * t.hi * basis;
            } else if let Some(u) = self.not_detected.iter().find(|u| u.term == kind)
                && u.upper.is_finite()
            {
                hi += u.upper * u.upper * basis;
            }
        }
        if let Some(g) = &self.gauss_markov {
            let shapes = [g.tau_c_s.lo, g.tau_c_s.value, g.tau_c_s.hi]
                .map(|tc| gauss_markov_avar(1.0, tc, tau))
                .into_iter()
                .filter(|v| v.is_finite());
            let (smin, smax) =
                shapes.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
            if smax > 0.0 {
                lo += g.sigma.lo * g.sigma.lo * smin;
                hi += g.sigma.hi * g.sigma.hi * smax;
            }
        } else if let Some(u) = self
            .not_detected
            .iter()
            .find(|u| u.term == TermKind::GaussMarkov)
            && u.upper.is_finite()
        {
            // No correlation time was fitted: the largest a σ at the upper limit can
            // give at this τ is its peak over T (0.381·σ² at T ≈ τ/1.89).
            hi += u.upper * u.upper * gauss_markov_avar_peak().1;
        }
        (lo, hi)
    }

    /// Removes the fitted term of a kind from the values.
    pub(crate) fn clear_term(&mut self, kind: TermKind) {
        match kind {
            TermKind::Quantization => self.quantization = None,
            TermKind::White => self.white = None,
            TermKind::BiasInstability => self.bias_instability = None,
            TermKind::RateRandomWalk => self.rate_random_walk = None,
            TermKind::RateRamp => self.rate_ramp = None,
            TermKind::GaussMarkov => self.gauss_markov = None,
        }
    }

    /// The fitted term of a kind (Gauss-Markov: its σ).
    pub fn term(&self, kind: TermKind) -> Option<Term> {
        match kind {
            TermKind::Quantization => self.quantization,
            TermKind::White => self.white,
            TermKind::BiasInstability => self.bias_instability,
            TermKind::RateRandomWalk => self.rate_random_walk,
            TermKind::RateRamp => self.rate_ramp,
            TermKind::GaussMarkov => self.gauss_markov.map(|g| g.sigma),
        }
    }

    /// The term contributing most Allan variance at `tau` (None if the model is empty).
    pub(crate) fn dominant_term(&self, tau: f64) -> Option<TermKind> {
        let mut best: Option<(TermKind, f64)> = None;
        let mut consider = |k: TermKind, v: f64| {
            if v > 0.0 && best.is_none_or(|(_, b)| v > b) {
                best = Some((k, v));
            }
        };
        for k in TermKind::LINEAR {
            if let Some(t) = self.term(k) {
                consider(k, t.value * t.value * k.basis(tau));
            }
        }
        if let Some(gm) = &self.gauss_markov {
            consider(
                TermKind::GaussMarkov,
                gauss_markov_avar(gm.sigma.value, gm.tau_c_s.value, tau),
            );
        }
        best.map(|(k, _)| k)
    }

    /// Power-law exponent α (−2..=2) of the dominant term at `tau`, for choosing the EDF
    /// of each Allan point. A Gauss-Markov term behaves like random walk (α = −2) well
    /// below its correlation time, like white noise (α = 0) well above it and is given
    /// α = −1 in between (0.3 T … 3 T). Empty model: 0.
    pub(crate) fn dominant_alpha(&self, tau: f64) -> i32 {
        match self.dominant_term(tau) {
            None => 0,
            Some(TermKind::GaussMarkov) => {
                let t = self.gauss_markov.map(|g| g.tau_c_s.value).unwrap_or(1.0);
                let u = tau / t;
                if u < 0.3 {
                    -2
                } else if u > 3.0 {
                    0
                } else {
                    -1
                }
            }
            Some(k) => k.alpha(),
        }
    }
}

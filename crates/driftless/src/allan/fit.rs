//! IMU noise-term fit to an Allan variance curve.
//!
//! Model (IEEE Std 952-1997 Annex C; IEEE Std 1293-2018 Annex; El-Sheimy, Hou & Niu 2008,
//! "Analysis and modeling of inertial sensors using Allan variance", IEEE TIM 57(1)):
//!
//! ```text
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2  [+ σ_GM²·g(τ/T)]
//! ```
//!
//! All values SI: data units u (rad/s or m/s²) → Q \[u·s], N \[u·√s], B \[u], K \[u/√s], R \[u/s].
//!
//! # Method
//!
//! The model is linear in θ = (Q², N², B², K², R²). Each Allan-variance estimate
//! σ̂²(τ_i) is approximately a scaled χ² variable with ν_i equivalent degrees of freedom
//! (Greenhall & Riley 2003; NIST SP 1065 §5.3), so var σ̂²_i ≈ 2σ⁴(τ_i)/ν_i. The fit
//! minimises Σ w_i (σ̂²_i − m_i(θ))² with w_i = 1/(m_i²(2/ν_i + f²)) where m_i is the
//! **model** value (weighting by the data instead biases the fit low, because low
//! estimates get large weights) and f a relative model-error floor
//! ([`MODEL_ERROR_FLOOR`]: no point counts as more precise than f, so the few short-τ
//! points with EDF of 10⁵–10⁶ cannot decide the fit alone; the floor only bites where
//! 2/ν < f², i.e. ν > 2/f²), subject to θ ≥ 0. The weights are updated from the model and the
//! non-negative least squares (NNLS) problem re-solved until the model stops changing
//! (iteratively reweighted least squares). The NNLS is solved exactly by enumerating the
//! at most 2⁶ supports (a feasible support with the smallest weighted residual is the
//! NNLS optimum). A term whose coefficient goes to zero is reported as not detected,
//! with an upper limit, instead of a negative or imaginary value.
//!
//! A first-order Gauss-Markov term (σ, T) is linear in σ² for fixed T; T is found by a
//! grid over ln T followed by golden-section refinement (separable least squares, Golub &
//! Pereyra 1973), with the NNLS above inside.
//!
//! # Confidence intervals
//!
//! Covariance of θ̂ from the weighted normal equations, (XᵀWX)⁻¹, multiplied by
//! * an inflation for the correlation between Allan-variance estimates at neighbouring
//!   taus (they share the same data): the information is counted as one independent point
//!   per decade of tau rather than one per tau — see [`correlation_inflation`]; the factor
//!   was calibrated and checked by Monte Carlo (`tests/noise_recovery.rs`);
//! * max(1, χ²_red) (Birge ratio) so that a misfitting model widens its intervals.
//!
//! The interval on the square θ_j ± z·s_j (z the two-sided normal quantile) is clamped at
//! zero and square-rooted, so Q, N, B, K, R intervals are asymmetric and never negative.
//!
//! # Where the model applies
//!
//! Below a few sample intervals a real sensor's output is not white: its anti-alias
//! filtering and decimation correlate neighbouring samples, σ²(τ) falls below N²/τ, and no
//! IEEE 952 term describes that. [`short_tau_coloured`] tells from the lag-1
//! autocorrelation of the samples; the noise model then chooses the first point of the fit
//! among [`auto_range_candidates`] (see `noise_model::NoiseModel::from_curves_with`).
//! χ²_red is read by [`chi2_verdict`]. A Gauss-Markov correlation time is searched only
//! where the record can show it ([`FitOptions`]); a bound hit is reported in
//! [`NoiseFit::not_identifiable`].
//!
//! The classic single-point "slope" readings (N at τ = 1 s on the −½ line, B = σ_min/0.664,
//! K at τ = 3 s on the +½ line; IEEE 952 Fig. C.2) are available as a diagnostic through
//! [`slope_readings`].

use std::f64::consts::{LN_2, PI};

use serde::{Deserialize, Serialize};

use super::AllanError;

/// (2 ln2/π): Allan variance of bias instability per B².
pub const BIAS_AVAR_COEF: f64 = 2.0 * LN_2 / PI;
/// √(2 ln2/π) ≈ 0.6643: the Allan-deviation floor per unit bias instability.
pub const BIAS_ADEV_FLOOR: f64 = 0.664_282_470_267_960_1;

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
    pub fn linear_terms(&self) -> Vec<TermKind> {
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
    pub fn basis(self, tau: f64) -> f64 {
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

/// How the τ range of the fit was chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeSource {
    /// The whole curve.
    Full,
    /// Short τ left out automatically where the averaged rates are correlated
    /// ([`auto_fit_start`]).
    Auto,
    /// Given by the user (`--fit-range`).
    User,
}

/// The τ range of a fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRange {
    /// Smallest fitted τ, s.
    pub tau_min_s: f64,
    /// Largest fitted τ, s.
    pub tau_max_s: f64,
    /// How the range was chosen.
    pub source: RangeSource,
    /// Curve points below the range (left out).
    pub excluded_short: usize,
    /// Curve points above the range (left out).
    pub excluded_long: usize,
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
pub const CHI2_RED_GOOD: f64 = 2.0;

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

/// A user-given fit range `TMIN:TMAX` in seconds; an empty side means the curve's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitRangeSpec {
    /// Smallest τ to fit, s (None: from the start of the curve).
    pub tau_min_s: Option<f64>,
    /// Largest τ to fit, s (None: to the end of the curve).
    pub tau_max_s: Option<f64>,
}

impl std::str::FromStr for FitRangeSpec {
    type Err = AllanError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = |why: &str| {
            AllanError::Invalid(format!(
                "fit range {s:?}: {why} (expected TMIN:TMAX in seconds, e.g. 0.2:2000 or 0.2:)"
            ))
        };
        let (a, b) = s.split_once(':').ok_or_else(|| bad("no ':'"))?;
        let side = |t: &str, which: &str| -> Result<Option<f64>, AllanError> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(None);
            }
            let v: f64 = t
                .parse()
                .map_err(|_| bad(&format!("{which} {t:?} is not a number")))?;
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(&format!(
                    "{which} must be a positive number of seconds"
                )));
            }
            Ok(Some(v))
        };
        let spec = FitRangeSpec {
            tau_min_s: side(a, "TMIN")?,
            tau_max_s: side(b, "TMAX")?,
        };
        if let (Some(lo), Some(hi)) = (spec.tau_min_s, spec.tau_max_s)
            && lo >= hi
        {
            return Err(bad("TMIN must be below TMAX"));
        }
        Ok(spec)
    }
}

/// Largest averaging factor the automatic range may leave out: the sensor's own
/// filtering acts over a few to a few tens of samples.
pub const AUTO_RANGE_MAX_M: usize = 200;
/// Smallest lag-1 autocorrelation of the τ-averaged rates that counts as coloured.
pub const ACF_COLOURED: f64 = 0.02;

/// Whether the shortest-τ point of a curve is coloured by the sensor's own filtering:
/// the lag-1 autocorrelation r₁ of the rate samples lies above max([`ACF_COLOURED`],
/// 3/√n) (white noise gives r₁ ≈ 0 with standard error 1/√n; Box & Jenkins 1976
/// §2.1.6) or below −[`ACF_COLOURED`] while above −0.3 (a narrow-band hump; quantization
/// alone gives r₁ → −½ and is a modelled term). `acf1` is the curve's
/// [`crate::allan::analysis::ChannelResult::rate_acf1`], `n_samples` the samples behind it.
pub fn short_tau_coloured(acf1: &[f64], n_samples: usize) -> bool {
    let Some(&r) = acf1.first() else {
        return false;
    };
    let limit = ACF_COLOURED.max(3.0 / (n_samples.max(1) as f64).sqrt());
    r.is_finite() && (r > limit || (r < -limit && r > -0.3))
}

/// Candidate first points of the automatic fit range: the curve's first point, then
/// points whose averaging factor m has grown by at least half since the previous
/// candidate, up to m = [`AUTO_RANGE_MAX_M`].
pub fn auto_range_candidates(m: &[usize]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut last = 0usize;
    for (i, &mi) in m.iter().enumerate() {
        if mi > AUTO_RANGE_MAX_M {
            break;
        }
        if out.is_empty() || 2 * mi >= 3 * last {
            out.push(i);
            last = mi;
        }
    }
    out
}

/// Relative model-error floor f of the fit weights: var σ̂²_i = m_i²·(2/ν_i + f²), so a
/// point never counts as more precise than f, whatever its EDF.
pub const MODEL_ERROR_FLOOR: f64 = 0.003;

/// Smallest Gauss-Markov correlation time, in sample intervals: a shorter one is white
/// noise at every τ the curve has.
pub const GM_MIN_SAMPLES: f64 = 5.0;
/// Resolution of the Gauss-Markov correlation-time search in ln T (relative, so
/// 1e-5·(1 + |ln T|): a few 0.01 % of T, far inside its interval).
const GM_LN_T_TOL: f64 = 1e-5;
/// Largest Gauss-Markov correlation time as a fraction of the record: a longer one is a
/// random walk over the record and its σ and T cannot be separated.
pub const GM_MAX_RECORD_FRACTION: f64 = 0.1;

/// What the fit needs to know about the record beyond the curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Sample interval, s (bounds the Gauss-Markov correlation time from below at
    /// [`GM_MIN_SAMPLES`]·τ0).
    pub tau0_s: Option<f64>,
    /// Record length, s (bounds the Gauss-Markov correlation time from above at
    /// [`GM_MAX_RECORD_FRACTION`] of it).
    pub record_s: Option<f64>,
    /// Relative model-error floor of the weights (see [`MODEL_ERROR_FLOOR`]).
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
    pub fn clear_term(&mut self, kind: TermKind) {
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
    pub fn dominant_term(&self, tau: f64) -> Option<TermKind> {
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
    pub fn dominant_alpha(&self, tau: f64) -> i32 {
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

/// Location u* = τ/T and height of the maximum of the Gauss-Markov Allan variance per σ²:
/// max_u (2u − 3 + 4e^{−u} − e^{−2u})/u² (found numerically: u* ≈ 1.8926, 0.38114).
pub fn gauss_markov_avar_peak() -> (f64, f64) {
    let g = |u: f64| gauss_markov_avar(1.0, 1.0, u);
    let (u, v) = golden_max(|lu: f64| g(lu.exp()), -3.0, 3.0);
    (u.exp(), v)
}

// ---------------------------------------------------------------------------------------
// Normal distribution helpers: one implementation, in [`crate::numeric::normal`].

pub use crate::numeric::normal::{erfc, normal_cdf, normal_quantile};

// ---------------------------------------------------------------------------------------
// Fit.

/// Inflation of the least-squares covariance for the correlation between Allan-variance
/// estimates at neighbouring taus (overlapping estimates at nearby taus are computed
/// from the same data, and for flicker and random-walk noise the correlation reaches
/// across octaves): `n_points / n_independent` with n_independent = log10(τ_max/τ_min) + 1,
/// i.e. one independent estimate per decade of tau. Never below 1.
///
/// Calibrated empirically: with ~100 log-spaced taus over 5.9 decades (18 h at 100 Hz)
/// and 4.9 decades (2 h) and N, B, K present, the uninflated covariance (n_independent =
/// n_points) under-states the spread of N², B², K² by factors of 2–3 in variance
/// (rms z-scores 1.5–1.8); one-per-octave counting still leaves rms z ≈ 1.5–1.8 for
/// B and K; one per decade brings them to ≈ 0.8–1.1 (coverage in `tests/noise_recovery.rs`).
pub fn correlation_inflation(tau: &[f64]) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &t in tau {
        lo = lo.min(t);
        hi = hi.max(t);
    }
    if tau.is_empty() || hi <= lo {
        return 1.0;
    }
    let independent = (hi / lo).log10() + 1.0;
    (tau.len() as f64 / independent).max(1.0)
}

fn validate_inputs(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    confidence: f64,
) -> Result<(), AllanError> {
    if tau.len() != avar.len() || tau.len() != edf.len() {
        return Err(AllanError::Invalid(format!(
            "fit: tau, avar and edf must have the same length (got {}, {}, {})",
            tau.len(),
            avar.len(),
            edf.len()
        )));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Invalid(format!(
            "fit: confidence must be in (0, 1), got {confidence}"
        )));
    }
    for (i, ((&t, &a), &e)) in tau.iter().zip(avar).zip(edf).enumerate() {
        for v in [t, a, e] {
            if !v.is_finite() {
                return Err(AllanError::NonFinite { index: i, value: v });
            }
        }
        if t <= 0.0 || a <= 0.0 || e <= 0.0 {
            return Err(AllanError::Invalid(format!(
                "fit: point {i} needs tau > 0, avar > 0 and edf > 0 (tau = {t}, avar = {a}, edf = {e})"
            )));
        }
    }
    Ok(())
}

/// Fit the IEEE 952 noise terms to an Allan-variance curve.
///
/// * `tau`, `avar`: the curve (Allan **variance**, not deviation), any estimator of the
///   Allan family whose expectation follows the model (overlapping ADEV recommended).
/// * `edf`: equivalent degrees of freedom of each point (e.g. `ci::edf` with the α of the
///   dominant term; see [`fit_noise_with_edf`] which iterates that choice).
/// * `confidence`: two-sided confidence level of the reported intervals, e.g. 0.683.
///
/// Errors: mismatched lengths, non-finite or non-positive inputs, no term switched on,
/// fewer points than fitted parameters.
pub fn fit_noise(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    cfg: &FitConfig,
    confidence: f64,
) -> Result<NoiseFit, AllanError> {
    fit_noise_opts(tau, avar, edf, cfg, confidence, &FitOptions::default())
}

/// [`fit_noise`] with the record's sample interval and length (which bound a
/// Gauss-Markov correlation time to what the record can show) and the weights'
/// model-error floor. A correlation time that ends at a bound of its search — from
/// the longer of [`GM_MIN_SAMPLES`]·τ0 and the curve's shortest τ (a shorter one falls
/// as 1/τ over the whole curve, like white noise, and would trade places with N) to the
/// shorter of [`GM_MAX_RECORD_FRACTION`]·record and ten times the longest τ — is
/// reported in [`NoiseFit::not_identifiable`] and the model refitted without the term.
pub fn fit_noise_opts(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    cfg: &FitConfig,
    confidence: f64,
    opts: &FitOptions,
) -> Result<NoiseFit, AllanError> {
    validate_inputs(tau, avar, edf, confidence)?;
    let floor = opts.model_error_floor;
    if !(floor.is_finite() && (0.0..1.0).contains(&floor)) {
        return Err(AllanError::Invalid(format!(
            "fit: the model-error floor must be in [0, 1), got {floor}"
        )));
    }
    let kinds = cfg.linear_terms();
    // A Gauss-Markov term needs two parameters beyond the linear terms; a curve too short
    // for them is fitted without it, and says so.
    let mut not_identifiable = Vec::new();
    let with_gm = cfg.gauss_markov && (kinds.is_empty() || tau.len() > kinds.len() + 2);
    if cfg.gauss_markov && !with_gm {
        not_identifiable.push(NotIdentifiable {
            term: TermKind::GaussMarkov,
            reason: format!(
                "{} curve points are too few for its σ and correlation time beside {} other \
                 term(s)",
                tau.len(),
                kinds.len()
            ),
        });
    }
    let n_par = kinds.len() + if with_gm { 2 } else { 0 };
    if n_par == 0 {
        return Err(AllanError::Invalid("fit: no noise term switched on".into()));
    }
    if tau.len() <= n_par {
        return Err(AllanError::Invalid(format!(
            "fit: {} points cannot constrain {} parameters",
            tau.len(),
            n_par
        )));
    }
    let mut cols: Vec<Vec<f64>> = kinds
        .iter()
        .map(|k| tau.iter().map(|&t| k.basis(t)).collect())
        .collect();

    let z = normal_quantile(0.5 + confidence / 2.0);
    let inflation = correlation_inflation(tau);

    // Optional Gauss-Markov: separable search over ln T.
    let mut gm_t: Option<f64> = None;
    if with_gm {
        let (tmin, tmax) = tau
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
        let t_lo = opts
            .tau0_s
            .map_or(tmin / 10.0, |t0| tmin.max(GM_MIN_SAMPLES * t0));
        let t_hi = opts.record_s.map_or(tmax * 10.0, |r| {
            (tmax * 10.0).min(GM_MAX_RECORD_FRACTION * r)
        });
        let (lo, hi) = (t_lo.ln(), t_hi.ln());
        let objective = |lt: f64| -> f64 {
            let mut c = cols.clone();
            c.push(gm_column(tau, lt.exp()));
            irls(&c, avar, edf, floor).chi2
        };
        let ngrid = 21;
        let grid: Vec<f64> = (0..ngrid)
            .map(|i| lo + (hi - lo) * i as f64 / (ngrid - 1) as f64)
            .collect();
        let vals: Vec<f64> = grid.iter().map(|&g| objective(g)).collect();
        let ibest = vals
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let a = grid[ibest.saturating_sub(1)];
        let b = grid[(ibest + 1).min(ngrid - 1)];
        let (lt, _) = golden_max_tol(|x| -objective(x), a, b, GM_LN_T_TOL);
        // Within 2 % of a bound: the curve wants a correlation time outside what the
        // record can show.
        if hi - lo < 0.1 || lt - lo < 0.02 || hi - lt < 0.02 {
            let reason = if hi - lo >= 0.1 && lt - lo < 0.02 && (t_lo - tmin).abs() <= 1e-12 * tmin
            {
                format!(
                    "no correlated hump: the best correlation time is below the fitted \
                     range's first τ ({} s), where it is white noise",
                    sig3(t_lo)
                )
            } else {
                format!(
                    "correlation time at the bound of its search ({} s; allowed {} … {} s: \
                     at least {GM_MIN_SAMPLES} sample intervals and the range's first τ, at \
                     most {GM_MAX_RECORD_FRACTION} of the record)",
                    sig3(lt.exp()),
                    sig3(t_lo),
                    sig3(t_hi)
                )
            };
            not_identifiable.push(NotIdentifiable {
                term: TermKind::GaussMarkov,
                reason,
            });
        } else {
            gm_t = Some(lt.exp());
            cols.push(gm_column(tau, lt.exp()));
        }
    }

    let sol = irls(&cols, avar, edf, floor);
    let n = tau.len();
    let n_active = sol.coef.iter().filter(|&&c| c > 0.0).count();
    let dof = n
        .saturating_sub(n_active + usize::from(gm_t.is_some()))
        .max(1);
    let chi2_reduced = sol.chi2 / dof as f64;
    let scale = inflation * chi2_reduced.max(1.0);

    // Jacobian of the active parameters (+ ln T if the GM term is active).
    let active: Vec<usize> = (0..cols.len()).filter(|&j| sol.coef[j] > 0.0).collect();
    let mut jac: Vec<Vec<f64>> = active.iter().map(|&j| cols[j].clone()).collect();
    let gm_index = kinds.len();
    let gm_active = gm_t.is_some() && sol.coef.get(gm_index).is_some_and(|&c| c > 0.0);
    if let (true, Some(t)) = (gm_active, gm_t) {
        let s2 = sol.coef[gm_index];
        let h = 1e-4;
        let d: Vec<f64> = tau
            .iter()
            .map(|&x| {
                s2 * (gauss_markov_avar(1.0, (t.ln() + h).exp(), x)
                    - gauss_markov_avar(1.0, (t.ln() - h).exp(), x))
                    / (2.0 * h)
            })
            .collect();
        jac.push(d);
    }
    let cov = covariance(&jac, &sol.w);

    let mut out = NoiseFit {
        quantization: None,
        white: None,
        bias_instability: None,
        rate_random_walk: None,
        rate_ramp: None,
        gauss_markov: None,
        confidence,
        rms_log10_residual: (sol
            .model
            .iter()
            .zip(avar)
            .map(|(m, a)| (m / a).log10().powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt(),
        not_detected: Vec::new(),
        chi2_reduced,
        n_points: n,
        fit_range: Some(FitRange {
            tau_min_s: tau.iter().copied().fold(f64::INFINITY, f64::min),
            tau_max_s: tau.iter().copied().fold(0.0, f64::max),
            source: RangeSource::Full,
            excluded_short: 0,
            excluded_long: 0,
        }),
        not_identifiable,
    };
    let sq_term = |p: f64, var: f64| -> Term {
        let s = (var * scale).max(0.0).sqrt();
        Term {
            value: p.sqrt(),
            lo: (p - z * s).max(0.0).sqrt(),
            hi: (p + z * s).sqrt(),
        }
    };
    let var_of = |j: usize| -> f64 {
        active
            .iter()
            .position(|&a| a == j)
            .and_then(|pos| cov.as_ref().map(|c| c[pos][pos]))
            .unwrap_or(f64::NAN)
    };
    for (j, &k) in kinds.iter().enumerate() {
        if sol.coef[j] > 0.0 {
            let t = sq_term(sol.coef[j], var_of(j));
            match k {
                TermKind::Quantization => out.quantization = Some(t),
                TermKind::White => out.white = Some(t),
                TermKind::BiasInstability => out.bias_instability = Some(t),
                TermKind::RateRandomWalk => out.rate_random_walk = Some(t),
                TermKind::RateRamp => out.rate_ramp = Some(t),
                TermKind::GaussMarkov => {}
            }
        } else {
            out.not_detected.push(UpperLimit {
                term: k,
                upper: upper_limit(&cols, &sol, j, z, scale),
            });
        }
    }
    if let Some(t) = gm_t {
        if gm_active {
            let sigma = sq_term(sol.coef[gm_index], var_of(gm_index));
            let var_lt = cov
                .as_ref()
                .map(|c| c[active.len()][active.len()])
                .unwrap_or(f64::NAN);
            let s = (var_lt * scale).max(0.0).sqrt();
            out.gauss_markov = Some(GaussMarkovTerm {
                sigma,
                tau_c_s: Term {
                    value: t,
                    lo: t * (-z * s).exp(),
                    hi: t * (z * s).exp(),
                },
            });
        } else {
            out.not_detected.push(UpperLimit {
                term: TermKind::GaussMarkov,
                upper: upper_limit(&cols, &sol, gm_index, z, scale),
            });
        }
    }
    Ok(out)
}

/// [`fit_noise`] with the EDF of each point chosen from the power-law exponent α of the
/// noise that dominates there: `edf_of(i, alpha)` returns the EDF of point `i` for α
/// (typically `ci::edf(Estimator::Oadev, alpha, m[i], n_phase)`). The first pass takes
/// α from the local log-log slope μ of the Allan variance (α = −μ − 1, clamped to
/// −2..=2); then α is re-derived from the fitted model's dominant term and the fit
/// repeated until the α assignment stops changing (at most 5 passes).
pub fn fit_noise_with_edf<F: Fn(usize, i32) -> f64>(
    tau: &[f64],
    avar: &[f64],
    edf_of: F,
    cfg: &FitConfig,
    confidence: f64,
) -> Result<NoiseFit, AllanError> {
    fit_noise_with_edf_opts(tau, avar, edf_of, cfg, confidence, &FitOptions::default())
}

/// [`fit_noise_with_edf`] with [`FitOptions`] (see [`fit_noise_opts`]).
pub fn fit_noise_with_edf_opts<F: Fn(usize, i32) -> f64>(
    tau: &[f64],
    avar: &[f64],
    edf_of: F,
    cfg: &FitConfig,
    confidence: f64,
    opts: &FitOptions,
) -> Result<NoiseFit, AllanError> {
    if tau.len() != avar.len() {
        return Err(AllanError::Invalid(format!(
            "fit: tau and avar lengths differ ({} vs {})",
            tau.len(),
            avar.len()
        )));
    }
    let mut alpha = slope_alpha(tau, avar);
    let mut fit = None;
    for _ in 0..5 {
        let edf: Vec<f64> = alpha
            .iter()
            .enumerate()
            .map(|(i, &a)| edf_of(i, a))
            .collect();
        let f = fit_noise_opts(tau, avar, &edf, cfg, confidence, opts)?;
        let next: Vec<i32> = tau.iter().map(|&t| f.dominant_alpha(t)).collect();
        let done = next == alpha;
        fit = Some(f);
        if done {
            break;
        }
        alpha = next;
    }
    fit.ok_or_else(|| AllanError::Invalid("fit: no pass ran".into()))
}

/// α from the local log-log slope of the Allan variance (3-point centred differences).
fn slope_alpha(tau: &[f64], avar: &[f64]) -> Vec<i32> {
    let n = tau.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(2), (i + 2).min(n.saturating_sub(1)));
            if b <= a || tau[b] <= tau[a] || avar[a] <= 0.0 || avar[b] <= 0.0 {
                return 0;
            }
            let mu = (avar[b] / avar[a]).ln() / (tau[b] / tau[a]).ln();
            ((-mu - 1.0).round() as i32).clamp(-2, 2)
        })
        .collect()
}

/// Three significant digits for messages.
fn sig3(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) {
        format!("{v:.2e}")
    } else {
        format!("{}", (v * 1e3).round() / 1e3)
    }
}

fn gm_column(tau: &[f64], t: f64) -> Vec<f64> {
    tau.iter().map(|&x| gauss_markov_avar(1.0, t, x)).collect()
}

struct IrlsSolution {
    data: Vec<f64>,
    coef: Vec<f64>,
    model: Vec<f64>,
    w: Vec<f64>,
    chi2: f64,
}

/// Weight 1/var of an Allan-variance point with EDF ν and model value m: the χ² variance
/// 2m²/ν (Greenhall & Riley 2003) plus the model-error floor (f·m)².
fn weight(edf: f64, model: f64, floor: f64) -> f64 {
    1.0 / (model * model * (2.0 / edf + floor * floor))
}

/// IRLS with model-based weights w_i = 1/(m_i²(2/ν_i + f²)) and an exact NNLS inside.
fn irls(cols: &[Vec<f64>], avar: &[f64], edf: &[f64], floor: f64) -> IrlsSolution {
    let n = avar.len();
    let mut model = avar.to_vec();
    let mut w = vec![0.0; n];
    let mut coef = vec![0.0; cols.len()];
    for _ in 0..200 {
        for i in 0..n {
            w[i] = weight(edf[i], model[i], floor);
        }
        coef = nnls(cols, avar, &w);
        let mut change = 0.0f64;
        for i in 0..n {
            let m: f64 = cols.iter().zip(&coef).map(|(c, p)| c[i] * p).sum();
            // Guard: an all-zero model (nothing detected) keeps a tiny positive weight base.
            let m = m.max(1e-6 * avar[i]);
            change = change.max(((m - model[i]) / model[i]).abs());
            model[i] = m;
        }
        if change < 1e-10 {
            break;
        }
    }
    for i in 0..n {
        w[i] = weight(edf[i], model[i], floor);
    }
    let chi2 = (0..n).map(|i| w[i] * (avar[i] - model[i]).powi(2)).sum();
    IrlsSolution {
        data: avar.to_vec(),
        coef,
        model,
        w,
        chi2,
    }
}

/// Most columns of the small least-squares systems of the fit: five linear terms, the
/// Gauss-Markov σ² and its ln T, with room to spare. The systems live on the stack: the
/// fit solves thousands of them per channel (IRLS iterations × supports × the
/// Gauss-Markov search), and allocating each cost more than solving it.
const MAXP: usize = 8;

/// Column-scaled weighted normal equations A_jk = Σ w c_j c_k/(s_j s_k),
/// b_j = Σ w c_j y/s_j, yᵀWy, with s_j = √(Σ w c_j²) (unit diagonal, so a pivot test
/// can tell near-collinear columns).
struct NormalEquations {
    p: usize,
    a: [[f64; MAXP]; MAXP],
    b: [f64; MAXP],
    yy: f64,
    s: [f64; MAXP],
}

/// The normal equations of `cols` (at most [`MAXP`]) against `y`, or None with more.
fn normal_equations(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Option<NormalEquations> {
    let p = cols.len();
    if p > MAXP {
        return None;
    }
    let mut ne = NormalEquations {
        p,
        a: [[0.0; MAXP]; MAXP],
        b: [0.0; MAXP],
        yy: 0.0,
        s: [1.0; MAXP],
    };
    for (j, c) in cols.iter().enumerate() {
        let s = c.iter().zip(w).map(|(v, w)| w * v * v).sum::<f64>().sqrt();
        ne.s[j] = if s > 0.0 && s.is_finite() { s } else { 1.0 };
    }
    for j in 0..p {
        for k in 0..=j {
            let v: f64 = (0..y.len())
                .map(|i| w[i] * cols[j][i] * cols[k][i])
                .sum::<f64>()
                / (ne.s[j] * ne.s[k]);
            ne.a[j][k] = v;
            ne.a[k][j] = v;
        }
        ne.b[j] = (0..y.len()).map(|i| w[i] * cols[j][i] * y[i]).sum::<f64>() / ne.s[j];
    }
    ne.yy = (0..y.len()).map(|i| w[i] * y[i] * y[i]).sum();
    Some(ne)
}

/// Cholesky solve of the sub-system of `a`, `b` on the columns `idx`; None if (near)
/// singular: the scaled matrix has a unit diagonal, so a pivot below 1e-12 is a
/// near-collinear support.
fn solve_subset(a: &[[f64; MAXP]; MAXP], b: &[f64; MAXP], idx: &[usize]) -> Option<[f64; MAXP]> {
    let n = idx.len();
    let mut l = [[0.0; MAXP]; MAXP];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            let aij = a[idx[i]][idx[j]];
            if i == j {
                let d = aij - s;
                if d.is_nan() || d <= 1e-12 {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (aij - s) / l[j][j];
            }
        }
    }
    let mut y = [0.0; MAXP];
    for i in 0..n {
        let s: f64 = (0..i).map(|k| l[i][k] * y[k]).sum();
        y[i] = (b[idx[i]] - s) / l[i][i];
    }
    let mut x = [0.0; MAXP];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| l[k][i] * x[k]).sum();
        x[i] = (y[i] - s) / l[i][i];
    }
    Some(x)
}

/// Exact non-negative weighted least squares for a handful of columns, by the active-set
/// method of Lawson & Hanson (1974, ch. 23) on the normal equations (the form of Bro &
/// De Jong 1997): move into the passive set the column whose gradient b − Ax is largest
/// and positive, solve the passive sub-system, step back along the segment to the
/// feasible region when a coefficient turns non-positive and release it; stop when no
/// gradient is positive. The problem is convex, so this is the optimum the enumeration
/// of every support would find, at a few sub-system solves instead of 2^p. A column
/// nearly collinear with the passive set is left out.
fn nnls(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Vec<f64> {
    let Some(ne) = normal_equations(cols, y, w) else {
        return vec![0.0; cols.len()];
    };
    let p = ne.p;
    let scale = ne.b[..p].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-12 * (1.0 + scale);
    let mut x = [0.0; MAXP];
    let mut passive = [false; MAXP];
    let mut barred = [false; MAXP];
    let mut idx = [0usize; MAXP];
    let gradient =
        |x: &[f64; MAXP], j: usize| ne.b[j] - (0..p).map(|k| ne.a[j][k] * x[k]).sum::<f64>();
    for _ in 0..(4 * MAXP) {
        let Some(j) = (0..p)
            .filter(|&j| !passive[j] && !barred[j])
            .map(|j| (j, gradient(&x, j)))
            .filter(|&(_, g)| g > tol)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(j, _)| j)
        else {
            break;
        };
        passive[j] = true;
        let mut entered = true;
        for _ in 0..(4 * MAXP) {
            let mut k = 0;
            for (c, &on) in passive[..p].iter().enumerate() {
                if on {
                    idx[k] = c;
                    k += 1;
                }
            }
            let Some(sol) = solve_subset(&ne.a, &ne.b, &idx[..k]) else {
                // Collinear with the passive set: leave the newcomer out for good.
                passive[j] = false;
                barred[j] = true;
                entered = false;
                break;
            };
            let mut z = [0.0; MAXP];
            for t in 0..k {
                z[idx[t]] = sol[t];
            }
            if idx[..k].iter().all(|&c| z[c] > 0.0) {
                x = z;
                break;
            }
            // Step from x towards z as far as feasibility allows.
            let alpha = idx[..k]
                .iter()
                .filter(|&&c| z[c] <= 0.0)
                .map(|&c| x[c] / (x[c] - z[c]))
                .fold(f64::INFINITY, f64::min);
            for &c in &idx[..k] {
                x[c] += alpha * (z[c] - x[c]);
                if x[c] <= tol {
                    x[c] = 0.0;
                    passive[c] = false;
                }
            }
            if !passive[..p].iter().any(|&on| on) {
                break;
            }
        }
        if !entered {
            continue;
        }
    }
    // Undo the column scaling.
    (0..p).map(|j| x[j].max(0.0) / ne.s[j]).collect()
}

/// (JᵀWJ)⁻¹ for the given Jacobian columns, None if singular.
fn covariance(jac: &[Vec<f64>], w: &[f64]) -> Option<Vec<Vec<f64>>> {
    let p = jac.len();
    if p == 0 {
        return Some(Vec::new());
    }
    let dummy = vec![0.0; w.len()];
    let ne = normal_equations(jac, &dummy, w)?;
    let all: Vec<usize> = (0..p).collect();
    let mut inv = vec![vec![0.0; p]; p];
    for k in 0..p {
        let mut e = [0.0; MAXP];
        e[k] = 1.0;
        let col = solve_subset(&ne.a, &e, &all)?;
        for j in 0..p {
            inv[j][k] = col[j] / (ne.s[j] * ne.s[k]);
        }
    }
    Some(inv)
}

/// Upper limit of a term fitted to zero: refit the final active set plus column `j`
/// without the sign constraint at the final weights; upper = √(max(θ̂_j, 0) + z·s_j).
fn upper_limit(cols: &[Vec<f64>], sol: &IrlsSolution, j: usize, z: f64, scale: f64) -> f64 {
    let mut idx: Vec<usize> = (0..cols.len()).filter(|&k| sol.coef[k] > 0.0).collect();
    idx.push(j);
    let sub: Vec<Vec<f64>> = idx.iter().map(|&k| cols[k].clone()).collect();
    let last = idx.len() - 1;
    let all: Vec<usize> = (0..sub.len()).collect();
    let Some(ne) = normal_equations(&sub, &sol.data, &sol.w) else {
        return f64::NAN;
    };
    let (Some(x), Some(cov)) = (solve_subset(&ne.a, &ne.b, &all), covariance(&sub, &sol.w)) else {
        return f64::NAN;
    };
    let theta = x[last] / ne.s[last];
    let sd = (cov[last][last] * scale).max(0.0).sqrt();
    (theta.max(0.0) + z * sd).sqrt()
}

/// Golden-section maximisation of a unimodal function on [a, b]; returns (x*, f(x*)).
pub(crate) fn golden_max<F: Fn(f64) -> f64>(f: F, a: f64, b: f64) -> (f64, f64) {
    golden_max_tol(f, a, b, 1e-10)
}

/// [`golden_max`] stopping when the bracket is narrower than `tol`·(1 + |a| + |b|).
pub(crate) fn golden_max_tol<F: Fn(f64) -> f64>(f: F, a: f64, b: f64, tol: f64) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if (b - a).abs() < tol * (1.0 + a.abs() + b.abs()) {
            break;
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

// ---------------------------------------------------------------------------------------
// Classic slope readings.

/// The classic graphical readings of an Allan-deviation curve (IEEE Std 952-1997
/// Fig. C.2; El-Sheimy et al. 2008): a diagnostic next to the full fit, which is
/// considerably more accurate for K and B.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeReadings {
    /// N: value at τ = 1 s of the −½-slope line through the point whose local slope is
    /// closest to −½ (None if no point has a slope within ±0.15 of −½), u·√s.
    pub white: Option<f64>,
    /// B = σ_min/0.664 if the minimum is interior to the curve, u.
    pub bias_instability: Option<f64>,
    /// τ of the minimum, s.
    pub tau_min: Option<f64>,
    /// K: value at τ = 3 s of the +½-slope line through the point whose local slope is
    /// closest to +½ (None if none within ±0.15), u/√s.
    pub rate_random_walk: Option<f64>,
}

/// Classic slope readings from an Allan **deviation** curve (ascending tau). Local slopes
/// are centred log-log differences over ±2 points.
pub fn slope_readings(tau: &[f64], adev: &[f64]) -> SlopeReadings {
    let n = tau.len().min(adev.len());
    let ok = |i: usize| tau[i] > 0.0 && adev[i] > 0.0 && tau[i].is_finite() && adev[i].is_finite();
    let slope = |i: usize| -> Option<f64> {
        let (a, b) = (i.saturating_sub(2), (i + 2).min(n.saturating_sub(1)));
        if b <= a || !ok(a) || !ok(b) || tau[b] <= tau[a] {
            return None;
        }
        Some((adev[b] / adev[a]).ln() / (tau[b] / tau[a]).ln())
    };
    let closest = |target: f64| -> Option<usize> {
        (0..n)
            .filter(|&i| ok(i))
            .filter_map(|i| slope(i).map(|s| (i, (s - target).abs())))
            .filter(|&(_, d)| d < 0.15)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    let white = closest(-0.5).map(|i| adev[i] * tau[i].sqrt());
    let rate_random_walk = closest(0.5).map(|i| adev[i] * (3.0 / tau[i]).sqrt());
    let imin = (0..n)
        .filter(|&i| ok(i))
        .min_by(|&a, &b| adev[a].total_cmp(&adev[b]));
    let (bias_instability, tau_min) = match imin {
        Some(i) if i > 0 && i + 1 < n => (Some(adev[i] / BIAS_ADEV_FLOOR), Some(tau[i])),
        _ => (None, None),
    };
    SlopeReadings {
        white,
        bias_instability,
        tau_min,
        rate_random_walk,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn taus(n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n)
            .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
            .collect()
    }

    /// The exact NNLS by enumeration of every support, as a reference.
    fn nnls_by_enumeration(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Vec<f64> {
        let ne = normal_equations(cols, y, w).expect("small");
        let p = ne.p;
        let mut best = (ne.yy, [0.0; MAXP]);
        for mask in 1u32..(1 << p) {
            let idx: Vec<usize> = (0..p).filter(|j| mask & (1 << j) != 0).collect();
            let Some(x) = solve_subset(&ne.a, &ne.b, &idx) else {
                continue;
            };
            if x[..idx.len()].iter().any(|&v| v.is_nan() || v <= 0.0) {
                continue;
            }
            let wssr = ne.yy - (0..idx.len()).map(|t| x[t] * ne.b[idx[t]]).sum::<f64>();
            if wssr < best.0 {
                let mut c = [0.0; MAXP];
                for (t, &j) in idx.iter().enumerate() {
                    c[j] = x[t];
                }
                best = (wssr, c);
            }
        }
        (0..p).map(|j| best.1[j] / ne.s[j]).collect()
    }

    #[test]
    fn active_set_nnls_matches_the_enumeration_of_supports() {
        // Allan-variance bases with noisy data from models with terms switched off, so
        // the unconstrained optimum is often infeasible.
        let tau = taus(60, 0.05, 3000.0);
        let kinds = [
            TermKind::Quantization,
            TermKind::White,
            TermKind::BiasInstability,
            TermKind::RateRandomWalk,
            TermKind::RateRamp,
        ];
        let mut cols: Vec<Vec<f64>> = kinds
            .iter()
            .map(|k| tau.iter().map(|&t| k.basis(t)).collect())
            .collect();
        cols.push(gm_column(&tau, 30.0));
        let mut state = 12345u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut zeros = 0;
        for trial in 0..300 {
            let truth: Vec<f64> = (0..cols.len())
                .map(|j| {
                    if j != 1 && uniform() < 0.4 {
                        0.0
                    } else {
                        [1e-12, 1e-8, 1e-10, 1e-14, 1e-18, 1e-10][j] * (0.2 + uniform())
                    }
                })
                .collect();
            let y: Vec<f64> = (0..tau.len())
                .map(|i| {
                    let m: f64 = cols.iter().zip(&truth).map(|(c, t)| c[i] * t).sum();
                    m * (1.0 + 0.3 * (uniform() - 0.5))
                })
                .collect();
            let w: Vec<f64> = y.iter().map(|v| 1.0 / (v * v)).collect();
            let fast = nnls(&cols, &y, &w);
            let exact = nnls_by_enumeration(&cols, &y, &w);
            zeros += exact.iter().filter(|&&c| c == 0.0).count();
            let ssr = |c: &[f64]| -> f64 {
                (0..tau.len())
                    .map(|i| {
                        let m: f64 = cols.iter().zip(c).map(|(col, x)| col[i] * x).sum();
                        w[i] * (y[i] - m).powi(2)
                    })
                    .sum()
            };
            assert!(fast.iter().all(|&c| c >= 0.0), "trial {trial}: {fast:?}");
            let (a, b) = (ssr(&fast), ssr(&exact));
            assert!(a <= b * (1.0 + 1e-9) + 1e-300, "trial {trial}: {a} vs {b}");
            for (f, e) in fast.iter().zip(&exact) {
                assert!(
                    (f - e).abs() <= 1e-6 * e.abs().max(1e-30)
                        || (*f == 0.0 && *e == 0.0)
                        || a <= b,
                    "trial {trial}: {fast:?} vs {exact:?}"
                );
            }
        }
        assert!(
            zeros > 100,
            "the trials must exercise the constraint: {zeros}"
        );
    }

    #[test]
    fn a_curve_too_short_for_a_gauss_markov_term_is_fitted_without_it() {
        // Six octave points of white noise plus a floor: enough for the five linear
        // terms, not for seven parameters.
        let tau: Vec<f64> = (0..6).map(|i| 2f64.powi(i)).collect();
        let avar: Vec<f64> = tau.iter().map(|t| 1e-6 / t + 1e-9).collect();
        let edf = vec![100.0; 6];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.683).expect("fit");
        assert!(f.gauss_markov.is_none());
        let ni = f
            .not_identifiable
            .iter()
            .find(|n| n.term == TermKind::GaussMarkov)
            .expect("reported");
        assert!(ni.reason.contains("too few"), "{ni:?}");
        assert!(f.white.is_some());
    }

    #[test]
    fn erfc_and_quantile() {
        assert!((erfc(1.0) - 0.157_299_207_050_285_13).abs() < 1e-14);
        assert!((erfc(2.0) / 0.004_677_734_981_047_266 - 1.0).abs() < 1e-12);
        assert!((erfc(3.0) / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-12);
        assert!((erfc(-0.5) - 1.520_499_877_813_046_5).abs() < 1e-14);
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-10);
        assert!((normal_quantile(0.5 + 0.683 / 2.0) - 1.000_641_828_762_449).abs() < 1e-9);
        // Upper tail, against mpmath (40 digits) at the f64 argument: no loss near p = 1.
        assert!((normal_quantile(1.0 - 1e-6) - 4.753_424_308_817_088).abs() < 1e-12);
        assert!((normal_quantile(1.0 - 1e-12) - 7.034_486_910_047_835).abs() < 1e-12);
    }

    #[test]
    fn bias_constant() {
        assert!((BIAS_ADEV_FLOOR - BIAS_AVAR_COEF.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn gm_peak() {
        let (u, v) = gauss_markov_avar_peak();
        assert!((u - 1.89).abs() < 0.01, "u* = {u}");
        assert!((v - 0.381_138_658).abs() < 1e-6, "peak = {v}");
    }

    #[test]
    fn exact_model_is_recovered() {
        let tau = taus(60, 0.01, 1e4);
        let (q, n, b, k, r) = (1e-6, 1e-4, 2e-5, 3e-7, 1e-9);
        let truth = NoiseFit {
            quantization: Some(Term {
                value: q,
                lo: q,
                hi: q,
            }),
            white: Some(Term {
                value: n,
                lo: n,
                hi: n,
            }),
            bias_instability: Some(Term {
                value: b,
                lo: b,
                hi: b,
            }),
            rate_random_walk: Some(Term {
                value: k,
                lo: k,
                hi: k,
            }),
            rate_ramp: Some(Term {
                value: r,
                lo: r,
                hi: r,
            }),
            gauss_markov: None,
            confidence: 0.683,
            rms_log10_residual: 0.0,
            not_detected: vec![],
            chi2_reduced: 0.0,
            n_points: 0,
            fit_range: None,
            not_identifiable: Vec::new(),
        };
        let avar: Vec<f64> = tau.iter().map(|&t| truth.model_avar(t)).collect();
        let edf = vec![100.0; tau.len()];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.683).unwrap();
        for (got, want) in [
            (f.quantization, q),
            (f.white, n),
            (f.bias_instability, b),
            (f.rate_random_walk, k),
            (f.rate_ramp, r),
        ] {
            let g = got.expect("term detected").value;
            assert!((g / want - 1.0).abs() < 1e-6, "{g} vs {want}");
        }
        assert!(f.rms_log10_residual < 1e-8);
    }

    #[test]
    fn absent_term_is_not_detected() {
        // White + RRW only, with a deterministic dip making the B coefficient want < 0.
        let tau = taus(40, 0.1, 1e3);
        let avar: Vec<f64> = tau.iter().map(|&t| 1e-8 / t + 1e-12 * t / 3.0).collect();
        let edf = vec![50.0; tau.len()];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.95).unwrap();
        assert!((f.white.unwrap().value / 1e-4 - 1.0).abs() < 1e-6);
        assert!((f.rate_random_walk.unwrap().value / 1e-6 - 1.0).abs() < 1e-6);
        assert!(f.bias_instability.is_none() || f.bias_instability.unwrap().value < 1e-9);
        for u in &f.not_detected {
            assert!(u.upper.is_finite() && u.upper >= 0.0, "{u:?}");
        }
    }

    #[test]
    fn gauss_markov_recovered() {
        let tau = taus(80, 0.01, 1e4);
        let (n, s, t) = (1e-4, 3e-5, 50.0);
        let avar: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(s, t, x))
            .collect();
        let edf = vec![100.0; tau.len()];
        let cfg = FitConfig {
            quantization: false,
            white: true,
            bias_instability: false,
            rate_random_walk: false,
            rate_ramp: false,
            gauss_markov: true,
        };
        let f = fit_noise(&tau, &avar, &edf, &cfg, 0.683).unwrap();
        let gm = f.gauss_markov.expect("GM found");
        assert!((gm.sigma.value / s - 1.0).abs() < 1e-4, "{gm:?}");
        assert!((gm.tau_c_s.value / t - 1.0).abs() < 1e-4, "{gm:?}");
        assert!((f.white.unwrap().value / n - 1.0).abs() < 1e-4);
        assert!(gm.tau_c_s.lo <= t && t <= gm.tau_c_s.hi);
    }

    #[test]
    fn rejects_bad_input() {
        let cfg = FitConfig::default();
        assert!(fit_noise(&[1.0], &[1.0, 2.0], &[1.0], &cfg, 0.68).is_err());
        assert!(matches!(
            fit_noise(&[1.0, 2.0], &[f64::NAN, 1.0], &[1.0, 1.0], &cfg, 0.68),
            Err(AllanError::NonFinite { index: 0, .. })
        ));
        let t = taus(10, 1.0, 10.0);
        assert!(fit_noise(&t, &t, &t, &cfg, 1.5).is_err());
        assert!(fit_noise(&t[..4], &t[..4], &t[..4], &cfg, 0.68).is_err());
        assert!(fit_noise(&t, &t, &t, &FitConfig::NONE, 0.68).is_err());
        let parsed: FitConfig = "n, b,K".parse().unwrap();
        assert!(parsed.white && parsed.bias_instability && parsed.rate_random_walk);
        assert!(!parsed.quantization && !parsed.rate_ramp && !parsed.gauss_markov);
        assert!("n,x".parse::<FitConfig>().is_err());
    }

    #[test]
    fn fit_range_spec_parses_and_refuses_bad_values() {
        let r: FitRangeSpec = "0.2:2000".parse().unwrap();
        assert_eq!((r.tau_min_s, r.tau_max_s), (Some(0.2), Some(2000.0)));
        let r: FitRangeSpec = " 0.5 : ".parse().unwrap();
        assert_eq!((r.tau_min_s, r.tau_max_s), (Some(0.5), None));
        for bad in ["0.2", "x:1", "1:0.5", "-1:3", "0:3", "1:inf", "2:2"] {
            let e = bad.parse::<FitRangeSpec>().unwrap_err().to_string();
            assert!(e.contains("TMIN:TMAX"), "{bad}: {e}");
        }
    }

    #[test]
    fn short_tau_colour_from_the_lag1_autocorrelation() {
        // White: r1 within its standard error; filtered: clearly positive; quantization
        // (r1 → −½) is a modelled term, not colour.
        assert!(!short_tau_coloured(&[0.001, 0.0], 1_000_000));
        assert!(short_tau_coloured(&[0.17, 0.08], 1_000_000));
        assert!(short_tau_coloured(&[-0.1], 1_000_000));
        assert!(!short_tau_coloured(&[-0.48], 1_000_000));
        // Too few samples to call 0.05 significant.
        assert!(!short_tau_coloured(&[0.05], 1_000));
        assert!(!short_tau_coloured(&[f64::NAN], 1_000_000));
        assert!(!short_tau_coloured(&[], 1_000_000));
        let m: Vec<usize> = (1..=400).collect();
        let c = auto_range_candidates(&m);
        let cm: Vec<usize> = c.iter().map(|&i| m[i]).collect();
        assert_eq!(&cm[..5], &[1, 2, 3, 5, 8]);
        assert!(c.iter().all(|&i| m[i] <= AUTO_RANGE_MAX_M));
        assert!(c.windows(2).all(|w| 2 * m[w[1]] >= 3 * m[w[0]]));
    }

    #[test]
    fn model_error_floor_caps_the_weight_of_huge_edf() {
        // Weight of a point with EDF 10⁶ and 10 % floor ≈ that of EDF 200.
        let w_big = weight(1e6, 1.0, 0.1);
        let w_200 = weight(200.0, 1.0, 0.0);
        assert!((w_big / w_200 - 1.0).abs() < 0.01, "{w_big} vs {w_200}");
        // Small EDF: the floor barely matters.
        assert!((weight(10.0, 1.0, 0.01) / weight(10.0, 1.0, 0.0) - 1.0).abs() < 1e-3);
        let t = taus(20, 1.0, 100.0);
        let opts = FitOptions {
            model_error_floor: 1.5,
            ..FitOptions::default()
        };
        assert!(fit_noise_opts(&t, &t, &t, &FitConfig::default(), 0.68, &opts).is_err());
    }

    #[test]
    fn gauss_markov_shorter_than_a_few_samples_is_not_identifiable() {
        // White noise plus a Gauss-Markov term of 3 ms at 100 Hz: at every τ of the curve
        // the term is white noise, so its correlation time runs to the lower bound
        // (5 samples) and must not come out as a value.
        let tau = taus(60, 0.01, 1e3);
        let (n, s, t) = (1e-4, 3e-3, 0.003);
        let avar: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(s, t, x) + 1e-12 * x / 3.0)
            .collect();
        let edf = vec![100.0; tau.len()];
        let cfg: FitConfig = "n,k,gm".parse().unwrap();
        let opts = FitOptions {
            tau0_s: Some(0.01),
            record_s: Some(1e4),
            model_error_floor: 0.0,
        };
        let f = fit_noise_opts(&tau, &avar, &edf, &cfg, 0.683, &opts).unwrap();
        assert!(f.gauss_markov.is_none(), "{f:?}");
        let ni = f
            .not_identifiable
            .iter()
            .find(|u| u.term == TermKind::GaussMarkov)
            .expect("reported");
        assert!(ni.reason.contains("bound"), "{ni:?}");
        // The white noise takes the term's power, N² + 2σ²T at τ ≫ T (a little less at
        // the shortest τ, where τ/T is only 3).
        let want = (n * n + 2.0 * s * s * t).sqrt();
        assert!((f.white.unwrap().value / want - 1.0).abs() < 0.05, "{f:?}");
        // A correlation time inside the bounds is still found.
        let avar2: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(3e-5, 20.0, x))
            .collect();
        let f2 = fit_noise_opts(&tau, &avar2, &edf, &cfg, 0.683, &opts).unwrap();
        let gm = f2.gauss_markov.expect("found");
        assert!((gm.tau_c_s.value / 20.0 - 1.0).abs() < 1e-3, "{gm:?}");
        assert!(f2.not_identifiable.is_empty());
    }

    #[test]
    fn slope_readings_on_model_curve() {
        let tau = taus(100, 0.01, 1e4);
        let (n, b, k) = (1e-5, 1e-5, 1e-6);
        let adev: Vec<f64> = tau
            .iter()
            .map(|&t| (n * n / t + BIAS_AVAR_COEF * b * b + k * k * t / 3.0).sqrt())
            .collect();
        let s = slope_readings(&tau, &adev);
        assert!((s.white.unwrap() / n - 1.0).abs() < 0.05, "{s:?}");
        // The floor reading overestimates B when N and K terms overlap it.
        let br = s.bias_instability.unwrap() / b;
        assert!(br > 1.0 && br < 1.6, "{s:?}");
        assert!(s.rate_random_walk.unwrap() / k > 0.9, "{s:?}");
    }
}

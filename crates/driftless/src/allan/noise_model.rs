//! Noise-model file (TOML) written by `driftless allan --save-model` and read by the
//! filter-tuning and simulation commands.
//!
//! Each channel stores the fitted IEEE Std 952-1997 terms **in SI** (the authoritative
//! values, with confidence intervals), plus two derived views that are written for humans
//! and for filter code and ignored when the model is used programmatically:
//!
//! * **display** — the same continuous-time terms in the customary datasheet units
//!   (gyro: deg, deg/√h, deg/h, deg/h/√h, deg/h²; accel: m/s, m/s/√h, mg/µg, m/s²/√s …);
//! * **discrete** — what a discrete-time filter or simulator running at the sample rate
//!   f_s = 1/Δt needs per sample. Continuous and discrete are easy to confuse:
//!
//! | term | continuous (SI) | discrete, per sample at f_s |
//! |------|-----------------|-----------------------------|
//! | white N | density N \[u·√s], two-sided PSD N² \[u²/Hz] | σ_d = N·√f_s \[u] (std of each rate sample) |
//! | rate random walk K | density K \[u/√s], PSD of the bias derivative K² \[u²/s] | σ_Δb = K·√Δt \[u] (std of the bias change per step) |
//! | bias instability B | flicker floor, ADEV ≈ 0.664·B | no exact finite-state form; a first-order Gauss-Markov (σ_b, T_c) whose Allan-variance peak equals the floor at the floor's τ: φ = e^{−Δt/T_c}, σ_w = σ_b·√(1−φ²) |
//! | quantization Q | angle/velocity noise [u·s] | std Q of each integrated (angle/velocity) sample |
//! | rate ramp R | [u/s] | R·Δt per sample (deterministic) |
//!
//! Sources: IEEE Std 952-1997 Annex C; IEEE Std 1293-2018; El-Sheimy, Hou & Niu 2008;
//! discrete Gauss-Markov: Gelb, *Applied Optimal Estimation* (1974) §4.4.

use std::path::{Path, PathBuf};

use driftless_model::units::{
    DEG, DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, HOUR_S, M_PER_S_PER_SQRT_H, MICRO_G,
    MILLI_G,
};
use serde::{Deserialize, Serialize};

use super::AllanError;
use super::analysis::ChannelResult;
use super::fit::{
    BIAS_AVAR_COEF, CHI2_RED_GOOD, FitConfig, FitOptions, FitRange, FitRangeSpec,
    MODEL_ERROR_FLOOR, NoiseFit, NotIdentifiable, RangeSource, SlopeReadings, Term, TermKind,
    UpperLimit, auto_range_candidates, chi2_verdict, fit_noise_with_edf_opts,
    gauss_markov_avar_peak, short_tau_coloured, slope_readings,
};

const ALL_TERMS: [TermKind; 6] = [
    TermKind::Quantization,
    TermKind::White,
    TermKind::BiasInstability,
    TermKind::RateRandomWalk,
    TermKind::RateRamp,
    TermKind::GaussMarkov,
];

pub(crate) fn term_label(k: TermKind) -> &'static str {
    match k {
        TermKind::Quantization => "quantization Q",
        TermKind::White => "white N",
        TermKind::BiasInstability => "bias instab. B",
        TermKind::RateRandomWalk => "rate rand. walk K",
        TermKind::RateRamp => "rate ramp R",
        TermKind::GaussMarkov => "GM sigma",
    }
}

/// SI unit of each term for rate samples in `unit` (u·s, u·√s, u, u/√s, u/s).
pub(crate) fn si_term_units(unit: &str) -> impl Fn(TermKind) -> String + '_ {
    let u = if unit.is_empty() { "u" } else { unit };
    move |k| match k {
        TermKind::Quantization => format!("({u})·s"),
        TermKind::White => format!("({u})·sqrt(s)"),
        TermKind::BiasInstability | TermKind::GaussMarkov => u.to_string(),
        TermKind::RateRandomWalk => format!("({u})/sqrt(s)"),
        TermKind::RateRamp => format!("({u})/s"),
    }
}

pub(crate) fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        format!("{v}")
    } else if (1e-3..1e5).contains(&v.abs()) {
        // five significant digits
        let d = (4 - v.abs().log10().floor() as i32).clamp(0, 7) as usize;
        format!("{v:.d$}")
    } else {
        format!("{v:.4e}")
    }
}

/// Current file format version.
pub const FORMAT_VERSION: u32 = 1;

pub use crate::io::Quantity;

/// Display units of a term for a channel quantity: (unit name, size of one display unit
/// in SI). Angular rate → gyro units, specific force → accelerometer units; other
/// quantities have none (their terms stay in SI).
pub fn display_units(quantity: Quantity, term: TermKind) -> &'static [(&'static str, f64)] {
    GyroOrAccel::of(quantity).map_or(&[], |g| g.display_units(term))
}

#[derive(Clone, Copy)]
enum GyroOrAccel {
    Gyro,
    Accel,
}

impl GyroOrAccel {
    fn of(q: Quantity) -> Option<GyroOrAccel> {
        match q {
            Quantity::AngularRate => Some(GyroOrAccel::Gyro),
            Quantity::SpecificForce => Some(GyroOrAccel::Accel),
            Quantity::Temperature | Quantity::Other => None,
        }
    }

    /// Display units of a term: (unit name, size of one display unit in SI).
    fn display_units(self, term: TermKind) -> &'static [(&'static str, f64)] {
        const DEG_PER_H2: f64 = DEG / (HOUR_S * HOUR_S);
        const M_PER_S_PER_H15: f64 = 1.0 / (HOUR_S * 60.0);
        match (self, term) {
            (GyroOrAccel::Gyro, TermKind::Quantization) => &[("deg", DEG), ("urad", 1e-6)],
            (GyroOrAccel::Gyro, TermKind::White) => {
                &[("deg/sqrt(h)", DEG_PER_SQRT_H), ("deg/s/sqrt(Hz)", DEG)]
            }
            (GyroOrAccel::Gyro, TermKind::BiasInstability | TermKind::GaussMarkov) => {
                &[("deg/h", DEG_PER_H)]
            }
            (GyroOrAccel::Gyro, TermKind::RateRandomWalk) => {
                &[("deg/h/sqrt(h)", DEG_PER_H_PER_SQRT_H)]
            }
            (GyroOrAccel::Gyro, TermKind::RateRamp) => &[("deg/h^2", DEG_PER_H2)],
            (GyroOrAccel::Accel, TermKind::Quantization) => &[("m/s", 1.0)],
            (GyroOrAccel::Accel, TermKind::White) => &[
                ("m/s/sqrt(h)", M_PER_S_PER_SQRT_H),
                ("ug/sqrt(Hz)", MICRO_G),
            ],
            (GyroOrAccel::Accel, TermKind::BiasInstability | TermKind::GaussMarkov) => {
                &[("ug", MICRO_G), ("mg", MILLI_G)]
            }
            (GyroOrAccel::Accel, TermKind::RateRandomWalk) => {
                &[("m/s^2/sqrt(s)", 1.0), ("m/s/h^1.5", M_PER_S_PER_H15)]
            }
            (GyroOrAccel::Accel, TermKind::RateRamp) => &[("m/s^3", 1.0)],
        }
    }
}

/// One term in a display unit. A term that was fitted but not detected has
/// `detected = false`, value = lo = 0 and `hi` = its upper limit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisplayValue {
    /// Which term.
    pub term: TermKind,
    /// Display unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Lower confidence bound.
    pub lo: f64,
    /// Upper confidence bound (upper limit when not detected).
    pub hi: f64,
    /// Whether the term was detected.
    pub detected: bool,
}

/// Continuous-time terms of a fit in display units (every unit of
/// [`display_units`]), detected terms first in model order, then upper limits.
pub fn display_terms(fit: &NoiseFit, quantity: Quantity) -> Vec<DisplayValue> {
    let mut out = Vec::new();
    for kind in [
        TermKind::Quantization,
        TermKind::White,
        TermKind::BiasInstability,
        TermKind::RateRandomWalk,
        TermKind::RateRamp,
        TermKind::GaussMarkov,
    ] {
        let (t, detected) = match fit.term(kind) {
            Some(t) => (t, true),
            None => match fit.not_detected.iter().find(|u| u.term == kind) {
                Some(u) => (
                    Term {
                        value: 0.0,
                        lo: 0.0,
                        hi: u.upper,
                    },
                    false,
                ),
                None => continue,
            },
        };
        for &(unit, size) in display_units(quantity, kind) {
            out.push(DisplayValue {
                term: kind,
                unit: unit.to_string(),
                value: t.value / size,
                lo: t.lo / size,
                hi: t.hi / size,
                detected,
            });
        }
    }
    out
}

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
    let (x, _) = super::fit::golden_max(|x| -f(x), best.0 - step, best.0 + step);
    x.exp()
}

/// One channel of a noise model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelNoise {
    /// Channel name (e.g. `gyro_x`).
    pub name: String,
    /// Gyro or accelerometer.
    pub quantity: Quantity,
    /// SI unit of the rate samples (`rad/s`, `m/s^2`).
    pub unit: String,
    /// Fitted continuous-time terms, SI, with confidence intervals (authoritative).
    pub fit: NoiseFit,
    /// Classic slope readings, if computed.
    #[serde(default)]
    pub slope_readings: Option<SlopeReadings>,
    /// Same terms in display units (informational; recomputed by [`ChannelNoise::new`]).
    #[serde(default)]
    pub display: Vec<DisplayValue>,
    /// Per-sample discrete parameters at the model's sample rate (informational).
    pub discrete: DiscreteNoise,
    /// The complete GMWM model when the channel was fitted by the GMWM (every
    /// Gauss–Markov term, the selection criterion and the candidates); `fit` then holds
    /// its mapping onto the IEEE 952 terms. Absent in files of the Allan fit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gmwm: Option<super::gmwm::GmwmFit>,
}

impl ChannelNoise {
    /// Build a channel, deriving the display and discrete views from `fit`.
    pub fn new(name: &str, quantity: Quantity, fit: NoiseFit, sample_rate_hz: f64) -> Self {
        ChannelNoise {
            name: name.to_string(),
            quantity,
            unit: quantity.si_unit().to_string(),
            display: display_terms(&fit, quantity),
            discrete: discrete_noise(&fit, sample_rate_hz),
            fit,
            slope_readings: None,
            gmwm: None,
        }
    }
}

/// A noise-model file: one entry per analysed channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    /// File format version ([`FORMAT_VERSION`]).
    pub format_version: u32,
    /// Log the model was fitted from.
    #[serde(default)]
    pub source_file: Option<String>,
    /// Sample rate of that log, Hz.
    pub sample_rate_hz: f64,
    /// Estimator the curve came from (`oadev`, …).
    #[serde(default)]
    pub estimator: Option<String>,
    /// Channels.
    pub channels: Vec<ChannelNoise>,
}

/// Errors reading or writing a noise-model file.
#[derive(Debug, thiserror::Error)]
pub enum NoiseModelError {
    /// The file could not be read.
    #[error("cannot read noise model {path}: {source}")]
    Read {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// The file could not be written.
    #[error("cannot write noise model {path}: {source}")]
    Write {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Not a valid noise-model TOML document.
    #[error("noise model {path}: {source}")]
    Parse {
        /// File (`<string>` when parsed from memory).
        path: PathBuf,
        /// Cause, with line and column.
        source: Box<toml::de::Error>,
    },
    /// Serialisation failed (a value TOML cannot hold).
    #[error("cannot serialise noise model: {0}")]
    Serialize(#[from] toml::ser::Error),
    /// Parsed, but the contents are unusable.
    #[error("noise model {path}: {why}")]
    Invalid {
        /// File (`<string>` when parsed from memory).
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

/// How [`NoiseModel::from_curves_with`] chooses the fit range and checks the terms.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelOptions {
    /// A user-given τ range; None: automatic ([`super::fit::auto_range_candidates`]).
    pub fit_range: Option<FitRangeSpec>,
    /// Resolution step of each curve's rate samples (same order as the curves), when
    /// the samples are quantized ([`super::checks::resolution_step`]).
    pub resolution: Vec<Option<f64>>,
    /// Relative model-error floor of the fit weights.
    pub model_error_floor: f64,
    /// The automatic range ends at the last τ whose σ̂ is known to this relative
    /// standard uncertainty ([`auto_fit_end`]); None: at the curve's end.
    pub curve_precision: Option<f64>,
}

impl Default for ModelOptions {
    fn default() -> Self {
        ModelOptions {
            fit_range: None,
            resolution: Vec::new(),
            model_error_floor: MODEL_ERROR_FLOOR,
            curve_precision: Some(CURVE_PRECISION),
        }
    }
}

/// Relative half-width of the 68.3 % interval of σ̂(τ) up to which the automatic fit
/// range reaches: a model can be held to ±10 % of the curve only where the curve itself
/// is known to 10 %.
pub const CURVE_PRECISION: f64 = 0.10;
/// Confidence level of the curve interval [`CURVE_PRECISION`] applies to (one σ).
pub const CURVE_PRECISION_CONFIDENCE: f64 = 0.683;

/// Fewest curve points the automatic range keeps, whatever their precision.
pub const AUTO_RANGE_MIN_POINTS: usize = 12;

/// End (exclusive) of the automatic fit range: before the first point whose 68.3 %
/// interval reaches beyond ±`precision` of σ̂, with the EDF ν of the long-τ noise types
/// (flicker and random-walk FM, the smaller of the two, so that the end does not depend
/// on a noise identification that is itself uncertain at long τ). σ̂² is ≈ σ²·χ²_ν/ν, so
/// the interval's wider, upper side is σ̂·√(ν/χ²_ν(0.1587)) (NIST SP 1065 §5.3); it stays
/// within +10 % for ν ≳ 68 — a few tens of independent averages. Beyond it the points
/// scatter by more than the tolerance a model is held to, and on real sensors the
/// longest τ carry slow effects (temperature, run-to-run changes of the bias) that no
/// stationary term describes; they stay on the curve, with their intervals, but do not
/// shape the model. At least [`AUTO_RANGE_MIN_POINTS`]
/// points are kept.
pub fn auto_fit_end(c: &ChannelResult, precision: f64) -> usize {
    let n = c.points.len();
    // The lower χ² point of the two-sided interval (Wilson–Hilferty: a few 0.1 % at the
    // ν of a few tens this decides at).
    let z_lo = super::fit::normal_quantile(0.5 * (1.0 - CURVE_PRECISION_CONFIDENCE));
    let end = (0..n)
        .position(|i| {
            let nu = c.edf_for_alpha(i, -1).min(c.edf_for_alpha(i, -2));
            !(nu.is_finite()
                && nu > 0.0
                && (nu / super::checks::chi2_quantile(nu, z_lo)).sqrt() <= 1.0 + precision)
        })
        .unwrap_or(n);
    end.max(AUTO_RANGE_MIN_POINTS).min(n)
}

/// Quantization above this multiple of Δτ0/√12 is not taken as quantization.
pub const QUANTIZATION_RESOLUTION_FACTOR: f64 = 3.0;

/// The curve points inside a user range, [i0, i1).
fn user_indices(c: &ChannelResult, r: FitRangeSpec) -> Result<(usize, usize), AllanError> {
    let n = c.points.len();
    let tol = 1e-9;
    let lo = r.tau_min_s.map_or(0.0, |t| t * (1.0 - tol));
    let hi = r.tau_max_s.map_or(f64::INFINITY, |t| t * (1.0 + tol));
    let i0 = c.points.iter().position(|p| p.tau >= lo).unwrap_or(n);
    let i1 = c
        .points
        .iter()
        .rposition(|p| p.tau <= hi)
        .map_or(0, |i| i + 1);
    if i1 <= i0 {
        return Err(AllanError::Invalid(format!(
            "channel '{}': no curve point inside the fit range (the curve spans {} … {} s)",
            c.name,
            fmt_num(c.points.first().map_or(0.0, |p| p.tau)),
            fmt_num(c.points.last().map_or(0.0, |p| p.tau))
        )));
    }
    Ok((i0, i1))
}

/// Widens the interval of the white-noise term — the term the start of the range
/// decides — by the bias the sensor's filtering may leave at the start. That leftover
/// decays as 1/τ (a low-pass of time constant T_f changes σ²(τ) of white noise by
/// ≈ −3N²T_f/τ²; a decimation filter's is of the same form), so the bias of the fitted
/// θ = N² from a start τ_s is b(τ_s) ∝ 1/τ_s, and the fit from the next start r·τ_s
/// (`later`, r = `ratio` > 1) differs from the one from τ_s (`at_start`, same terms) by
/// Δ = θ_later − θ_start = −b(τ_s)·(1 − 1/r); hence b(τ_s) = −Δ·r/(r − 1) (Richardson's
/// extrapolation). The bias is systematic and its sign known, so the interval is
/// extended on that side by |b| (added to the statistical half-width, not in
/// quadrature); the value itself is left as fitted.
pub fn widen_for_the_start(fit: &mut NoiseFit, at_start: &NoiseFit, later: &NoiseFit, ratio: f64) {
    let (Some(t), Some(s0), Some(l)) = (fit.white.as_mut(), at_start.white, later.white) else {
        return;
    };
    if !(ratio.is_finite() && ratio > 1.0) {
        return;
    }
    let theta = t.value * t.value;
    let (lo, hi) = (t.lo * t.lo, t.hi * t.hi);
    // The truth lies on the side the later start moves towards.
    let shift = (l.value * l.value - s0.value * s0.value) * ratio / (ratio - 1.0);
    if !(shift.is_finite() && lo.is_finite() && hi.is_finite() && lo <= theta && theta <= hi) {
        return;
    }
    if shift > 0.0 {
        t.hi = (hi + shift).sqrt();
    } else {
        t.lo = (lo + shift).max(0.0).sqrt();
    }
}

/// The automatic fit range: the fit from each candidate first point (shortest first)
/// to the curve's end; the first whose χ²_red is at most [`CHI2_RED_GOOD`] over the whole
/// range *and* over its first half decade (`head(i0, fit)`: where a filter's leftover
/// shows, and where the whole-range χ²_red would dilute it) — the widest range over which
/// the model follows the curve within its uncertainty — or, if none is, the candidate
/// with the smallest χ²_red.
fn auto_range<F, H>(
    candidates: &[usize],
    n: usize,
    fit_over: &F,
    head: &H,
) -> Result<(usize, usize, RangeSource, NoiseFit), AllanError>
where
    F: Fn(usize, usize) -> Result<NoiseFit, AllanError>,
    H: Fn(usize, &NoiseFit) -> f64,
{
    let mut best: Option<(usize, NoiseFit)> = None;
    let mut first_err = None;
    for &i0 in candidates {
        match fit_over(i0, n) {
            Ok(f) => {
                let good = f.chi2_reduced <= CHI2_RED_GOOD && head(i0, &f) <= CHI2_RED_GOOD;
                if best
                    .as_ref()
                    .is_none_or(|(_, b)| f.chi2_reduced < b.chi2_reduced)
                {
                    best = Some((i0, f));
                }
                if good {
                    break;
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    match (best, first_err) {
        (Some((i0, f)), _) => {
            let source = if i0 == 0 {
                RangeSource::Full
            } else {
                RangeSource::Auto
            };
            Ok((i0, n, source, f))
        }
        (None, Some(e)) => Err(e),
        (None, None) => Err(AllanError::Invalid("no curve point to fit".into())),
    }
}

/// What a term the data do not support is reported as instead of a value.
#[derive(Clone, Debug, PartialEq)]
pub enum Unsupported {
    /// Its interval reaches zero: the upper end of the interval is the upper limit.
    UpperLimit(UpperLimit),
    /// Its value cannot be what the term describes (see [`least_supported_term`]).
    NotIdentifiable(NotIdentifiable),
}

/// The term of `fit` the data support least, if any does not stand:
/// * a quantization above [`QUANTIZATION_RESOLUTION_FACTOR`]·Δτ0/√12 — what angle
///   increments quantized at the rate resolution step Δ = `step` would give (IEEE Std
///   952-1997 C.1) — is not quantization (filtering, a spectral hump): not identifiable;
/// * otherwise, of the terms whose interval reaches zero, the one with the smallest
///   significance θ/(z·s_θ) (θ the squared coefficient, z·s_θ its interval half-width,
///   so θ/(z·s_θ) = v²/(hi² − v²)): an upper limit at its interval's upper end.
pub fn least_supported_term(
    fit: &NoiseFit,
    step: Option<f64>,
    tau0_s: f64,
) -> Option<(TermKind, Unsupported)> {
    if let (Some(q), Some(step)) = (fit.quantization, step) {
        let implied = step * tau0_s / 12f64.sqrt();
        if q.value > QUANTIZATION_RESOLUTION_FACTOR * implied {
            return Some((
                TermKind::Quantization,
                Unsupported::NotIdentifiable(NotIdentifiable {
                    term: TermKind::Quantization,
                    reason: format!(
                        "{:.1}x what the resolution step {} implies ({} (u)·s): the short-τ \
                         rise is not quantization (filtering, a spectral hump)",
                        q.value / implied,
                        fmt_num(step),
                        fmt_num(implied)
                    ),
                }),
            ));
        }
    }
    let significance = |t: &Term| {
        let half = t.hi * t.hi - t.value * t.value;
        if half > 0.0 {
            t.value * t.value / half
        } else {
            f64::INFINITY
        }
    };
    let mut candidates: Vec<(TermKind, Term)> = TermKind::LINEAR
        .into_iter()
        .filter_map(|k| fit.term(k).map(|t| (k, t)))
        .collect();
    if let Some(g) = fit.gauss_markov {
        candidates.push((TermKind::GaussMarkov, g.sigma));
    }
    candidates
        .into_iter()
        .filter(|(_, t)| t.lo <= 0.0)
        .min_by(|a, b| significance(&a.1).total_cmp(&significance(&b.1)))
        .map(|(kind, t)| {
            (
                kind,
                Unsupported::UpperLimit(UpperLimit {
                    term: kind,
                    upper: t.hi,
                }),
            )
        })
}

/// The fit with physically possible, resolved terms only, by backward elimination: fit
/// with `cfg`, drop the [`least_supported_term`], refit without it and repeat until every
/// remaining term stands. Each dropped term is reported (upper limit or not
/// identifiable) from the fit that still had it; the returned fit's values, χ²_red and
/// model curve are those of the terms that stand, so the saved model is the model
/// that was fitted. `fit_with(cfg)` fits the curve with the terms `cfg` switches on.
pub fn fit_supported_terms<F>(
    cfg: &FitConfig,
    step: Option<f64>,
    tau0_s: f64,
    fit_with: F,
) -> Result<NoiseFit, AllanError>
where
    F: Fn(&FitConfig) -> Result<NoiseFit, AllanError>,
{
    let mut cfg = *cfg;
    let mut dropped: Vec<Unsupported> = Vec::new();
    let mut fit = fit_with(&cfg)?;
    while let Some((kind, why)) = least_supported_term(&fit, step, tau0_s) {
        dropped.push(why);
        let next = cfg.without(kind);
        let refit = if next.linear_terms().is_empty() && !next.gauss_markov {
            None
        } else {
            fit_with(&next).ok()
        };
        match refit {
            Some(f) => {
                fit = f;
                cfg = next;
            }
            None => {
                // Nothing left to refit with: report the term and leave it out.
                fit.clear_term(kind);
                break;
            }
        }
    }
    for d in dropped {
        match d {
            Unsupported::UpperLimit(u) => {
                fit.not_detected.retain(|x| x.term != u.term);
                fit.not_detected.push(u);
            }
            Unsupported::NotIdentifiable(n) => fit.not_identifiable.push(n),
        }
    }
    Ok(fit)
}

/// The fit range, χ²_red and its verdict, as printed under each channel.
pub fn fit_quality_lines(fit: &NoiseFit) -> String {
    let mut s = String::new();
    if let Some(r) = &fit.fit_range {
        let how = match r.source {
            RangeSource::Full => "the whole curve".to_string(),
            RangeSource::User => "set by --fit-range".to_string(),
            RangeSource::Auto => {
                let mut why = Vec::new();
                if r.excluded_short > 0 {
                    why.push(format!(
                        "{} short-tau point(s) left out, where the sensor's own filtering \
                         colours the noise and the model does not apply",
                        r.excluded_short
                    ));
                }
                if r.excluded_long > 0 {
                    why.push(format!(
                        "{} long-tau point(s) left out, known to worse than {:.0} % (too few \
                         averages to hold a model to)",
                        r.excluded_long,
                        100.0 * CURVE_PRECISION
                    ));
                }
                format!("automatic: {}", why.join("; "))
            }
        };
        s.push_str(&format!(
            "  fit range {} … {} s ({} points; {how})\n",
            fmt_num(r.tau_min_s),
            fmt_num(r.tau_max_s),
            fit.n_points
        ));
    }
    let (verdict, warn) = chi2_verdict(fit.chi2_reduced);
    s.push_str(&format!(
        "  chi2_red {} — {}{verdict}\n",
        fmt_num(fit.chi2_reduced),
        if warn { "WARNING: " } else { "" }
    ));
    s
}

impl NoiseModel {
    /// New empty model.
    pub fn new(
        source_file: Option<String>,
        sample_rate_hz: f64,
        estimator: Option<String>,
    ) -> Self {
        NoiseModel {
            format_version: FORMAT_VERSION,
            source_file,
            sample_rate_hz,
            estimator,
            channels: Vec::new(),
        }
    }

    /// Channel by name.
    pub fn channel(&self, name: &str) -> Option<&ChannelNoise> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// The fits, in channel order.
    pub fn fits(&self) -> impl Iterator<Item = &NoiseFit> {
        self.channels.iter().map(|c| &c.fit)
    }

    /// Fit every channel's Allan curve (an OADEV-family [`ChannelResult`]) and collect the
    /// model. The EDF of each point follows the dominant term's noise exponent
    /// ([`super::fit::fit_noise_with_edf`] with [`ChannelResult::edf_for_alpha`]); the classic slope
    /// readings are stored alongside. `quantities[i]` belongs to `curves[i]`.
    pub fn from_curves(
        source: &str,
        curves: &[ChannelResult],
        quantities: &[Quantity],
        cfg: &FitConfig,
        confidence: f64,
    ) -> Result<NoiseModel, AllanError> {
        Self::from_curves_with(
            source,
            curves,
            quantities,
            cfg,
            confidence,
            &ModelOptions::default(),
        )
    }

    /// [`NoiseModel::from_curves`] over a chosen τ range, with physically possible terms
    /// only:
    /// * the fit range is `opts.fit_range` or, by default, the curve without the short τ
    ///   where the sensor's own filtering colours the noise ([`super::fit::auto_range_candidates`] on
    ///   [`ChannelResult::rate_acf1`]);
    /// * a Gauss-Markov correlation time is searched between a few sample intervals and a
    ///   tenth of the record ([`fit_noise_with_edf_opts`]); one at a bound is reported
    ///   not identifiable;
    /// * a term whose confidence interval reaches zero becomes an upper limit
    ///   ([`NoiseFit::not_detected`]), not a value, and a quantization the resolution
    ///   step (`opts.resolution`) cannot explain is reported not identifiable; either is
    ///   dropped and the rest refitted ([`fit_supported_terms`]), so the model describes
    ///   the curve with the terms that stand.
    pub fn from_curves_with(
        source: &str,
        curves: &[ChannelResult],
        quantities: &[Quantity],
        cfg: &FitConfig,
        confidence: f64,
        opts: &ModelOptions,
    ) -> Result<NoiseModel, AllanError> {
        if curves.len() != quantities.len() {
            return Err(AllanError::Invalid(format!(
                "noise model: {} curves but {} quantities",
                curves.len(),
                quantities.len()
            )));
        }
        let fs = curves.first().map_or(0.0, |c| 1.0 / c.tau0_s);
        let estimator = curves.first().map(|c| c.estimator.name().to_string());
        let mut model = NoiseModel::new(Some(source.to_string()), fs, estimator);
        for (k, (c, &q)) in curves.iter().zip(quantities).enumerate() {
            let tau: Vec<f64> = c.points.iter().map(|p| p.tau).collect();
            let avar: Vec<f64> = c.points.iter().map(|p| p.dev * p.dev).collect();
            let adev: Vec<f64> = c.points.iter().map(|p| p.dev).collect();
            let samples: usize = c
                .segment_phase_points
                .iter()
                .map(|n| n.saturating_sub(1))
                .sum();
            let fit_opts = FitOptions {
                tau0_s: Some(c.tau0_s),
                record_s: Some(samples as f64 * c.tau0_s),
                model_error_floor: opts.model_error_floor,
            };
            let step = opts.resolution.get(k).copied().flatten();
            // EDF of every point for every noise exponent, once: the fits below ask for
            // them thousands of times.
            let edf_table: Vec<[f64; 5]> = (0..tau.len())
                .map(|i| [-2, -1, 0, 1, 2].map(|a| c.edf_for_alpha(i, a)))
                .collect();
            let edf_of = |i: usize, alpha: i32| edf_table[i][(alpha.clamp(-2, 2) + 2) as usize];
            let fit_with = |i0: usize, i1: usize, cfg: &FitConfig| {
                if i0 >= i1 || i1 > tau.len() {
                    return Err(AllanError::Invalid(format!(
                        "no curve point between τ index {i0} and {i1}"
                    )));
                }
                fit_supported_terms(cfg, step, c.tau0_s, |cfg| {
                    fit_noise_with_edf_opts(
                        &tau[i0..i1],
                        &avar[i0..i1],
                        |i, a| edf_of(i0 + i, a),
                        cfg,
                        confidence,
                        &fit_opts,
                    )
                })
            };
            let fit_over = |i0: usize, i1: usize| fit_with(i0, i1, cfg);
            // The start is searched with the linear terms only: it is decided by the
            // short τ, and a Gauss-Markov search per candidate would cost tens of times
            // the rest of the fit.
            let search_cfg = if cfg.linear_terms().is_empty() {
                *cfg
            } else {
                FitConfig {
                    gauss_markov: false,
                    ..*cfg
                }
            };
            let search_over = |i0: usize, i1: usize| fit_with(i0, i1, &search_cfg);
            let named = |e: AllanError, user: bool| {
                AllanError::Invalid(format!(
                    "noise fit of channel '{}': {e}{}",
                    c.name,
                    if user {
                        " (choose a wider --fit-range)"
                    } else {
                        ""
                    }
                ))
            };
            let n = opts
                .curve_precision
                .map_or(tau.len(), |p| auto_fit_end(c, p));
            let (i0, i1, source, mut fit) = match opts.fit_range {
                Some(r) => {
                    let (i0, i1) = user_indices(c, r)?;
                    let f = fit_over(i0, i1).map_err(|e| named(e, true))?;
                    (i0, i1, RangeSource::User, f)
                }
                None => {
                    let longest = c
                        .segment_phase_points
                        .iter()
                        .max()
                        .map_or(0, |n| n.saturating_sub(1));
                    let coloured = short_tau_coloured(
                        &c.rate_acf1,
                        longest.min(super::analysis::MAX_ACF_BLOCKS),
                    );
                    let m: Vec<usize> = c.points.iter().map(|p| p.m).collect();
                    // Mean squared normalised residual over points `idx`, with the
                    // fit's own weights.
                    let msr = |idx: &mut dyn Iterator<Item = usize>, f: &NoiseFit| -> f64 {
                        let (mut sum, mut k) = (0.0, 0usize);
                        for i in idx {
                            let model = f.model_avar(tau[i]);
                            let nu = edf_of(i, f.dominant_alpha(tau[i]));
                            if model > 0.0 && nu > 0.0 {
                                let var =
                                    model * model * (2.0 / nu + opts.model_error_floor.powi(2));
                                sum += (avar[i] - model).powi(2) / var;
                                k += 1;
                            }
                        }
                        if k == 0 { 0.0 } else { sum / k as f64 }
                    };
                    // The first half decade of the range, where a filter's leftover shows.
                    let head = |i0: usize, f: &NoiseFit| {
                        msr(&mut (i0..n).take_while(|&i| tau[i] <= 3.0 * tau[i0]), f)
                    };
                    if coloured {
                        let candidates: Vec<usize> = auto_range_candidates(&m)
                            .into_iter()
                            .filter(|&i0| i0 < n)
                            .collect();
                        let (i0, i1, src, found) = auto_range(&candidates, n, &search_over, &head)
                            .map_err(|e| named(e, false))?;
                        let mut f = if search_cfg == *cfg {
                            found.clone()
                        } else {
                            fit_over(i0, i1).map_err(|e| named(e, false))?
                        };
                        // The leftover of the sensor's filtering at the chosen start.
                        if let Some(&next) = candidates.iter().find(|&&j| j > i0 && j + 1 < i1)
                            && let Ok(later) = search_over(next, i1)
                        {
                            widen_for_the_start(&mut f, &found, &later, tau[next] / tau[i0]);
                        }
                        (i0, i1, src, f)
                    } else {
                        let f = fit_over(0, n).map_err(|e| named(e, false))?;
                        (0, n, RangeSource::Full, f)
                    }
                }
            };
            let source = if source == RangeSource::Full && i1 < tau.len() {
                RangeSource::Auto
            } else {
                source
            };
            fit.fit_range = Some(FitRange {
                tau_min_s: tau[i0],
                tau_max_s: tau[i1 - 1],
                source,
                excluded_short: i0,
                excluded_long: tau.len() - i1,
            });
            let mut ch = ChannelNoise::new(&c.name, q, fit, 1.0 / c.tau0_s);
            if ch.fit.bias_instability.is_some() && ch.discrete.bias_instability_gm.is_none() {
                ch.fit.not_identifiable.push(NotIdentifiable {
                    term: TermKind::BiasInstability,
                    reason: "its Gauss-Markov stand-in: the model's floor lies beyond the \
                             fitted range, so its correlation time is unknown (B itself stands)"
                        .into(),
                });
            }
            ch.slope_readings = Some(slope_readings(&tau, &adev));
            model.channels.push(ch);
        }
        Ok(model)
    }

    /// Human-readable summary: per channel the continuous terms in display units with
    /// their intervals, upper limits of undetected terms, and the per-sample discrete σ.
    pub fn human_table(&self) -> String {
        let mut s = String::new();
        let conf = self
            .channels
            .first()
            .map_or(0.0, |c| 100.0 * c.fit.confidence);
        s.push_str(&format!(
            "Noise terms (IEEE 952 fit, {conf:.1} % intervals). Continuous-time densities first; \
             'discrete' lines are per-sample values at {} Hz.\n",
            fmt_num(self.sample_rate_hz)
        ));
        for c in &self.channels {
            s.push_str(&format!(
                "\n{} [{}]\n",
                c.name,
                if c.unit.is_empty() {
                    "data units"
                } else {
                    &c.unit
                }
            ));
            s.push_str(&fit_quality_lines(&c.fit));
            s.push_str(&format!(
                "  {:<18} {:>11} {:>11} {:>11}  {}\n",
                "term", "value", "lo", "hi", "unit"
            ));
            let mut rows: Vec<(String, f64, f64, f64, String)> = Vec::new();
            let si_units = si_term_units(&c.unit);
            for k in ALL_TERMS {
                let label = term_label(k);
                if let Some(t) = c.fit.term(k) {
                    match display_units(c.quantity, k).first() {
                        Some(&(u, size)) => rows.push((
                            label.into(),
                            t.value / size,
                            t.lo / size,
                            t.hi / size,
                            u.into(),
                        )),
                        None => rows.push((label.into(), t.value, t.lo, t.hi, si_units(k))),
                    }
                }
                if k == TermKind::GaussMarkov
                    && let Some(g) = &c.fit.gauss_markov
                {
                    let t = g.tau_c_s;
                    rows.push(("GM corr. time".into(), t.value, t.lo, t.hi, "s".into()));
                }
            }
            for (label, v, lo, hi, u) in rows {
                s.push_str(&format!(
                    "  {:<18} {:>11} {:>11} {:>11}  {}\n",
                    label,
                    fmt_num(v),
                    fmt_num(lo),
                    fmt_num(hi),
                    u
                ));
            }
            for u in &c.fit.not_detected {
                let (val, unit) = match display_units(c.quantity, u.term).first() {
                    Some(&(name, size)) => (u.upper / size, name.to_string()),
                    None => (u.upper, si_units(u.term)),
                };
                s.push_str(&format!(
                    "  {:<18} not detected (< {} {})\n",
                    term_label(u.term),
                    fmt_num(val),
                    unit
                ));
            }
            for u in &c.fit.not_identifiable {
                s.push_str(&format!(
                    "  {:<18} not identifiable: {}\n",
                    term_label(u.term),
                    u.reason
                ));
            }
            let d = &c.discrete;
            let su = if c.unit.is_empty() {
                "u"
            } else {
                c.unit.as_str()
            };
            let mut parts = Vec::new();
            if let Some(v) = d.white_sigma {
                parts.push(format!("white σ_d = N·√fs = {} {su}", fmt_num(v)));
            }
            if let Some(v) = d.rate_random_walk_sigma {
                parts.push(format!("RRW step σ = K·√Δt = {} {su}", fmt_num(v)));
            }
            if let Some(g) = &d.bias_instability_gm {
                parts.push(format!(
                    "bias-instability GM σ_b = {} {su}, T_c = {} s (φ = {}, σ_w = {} {su})",
                    fmt_num(g.sigma),
                    fmt_num(g.tau_c_s),
                    fmt_num(g.phi),
                    fmt_num(g.sigma_w)
                ));
            }
            for p in parts {
                s.push_str(&format!("  discrete: {p}\n"));
            }
        }
        s
    }

    /// Serialise to TOML.
    pub fn to_toml_string(&self) -> Result<String, NoiseModelError> {
        Ok(toml::to_string_pretty(self)?)
    }

    /// Parse from TOML (errors name the source as `<string>`).
    pub fn from_toml_str(s: &str) -> Result<NoiseModel, NoiseModelError> {
        Self::parse(s, Path::new("<string>"))
    }

    fn parse(s: &str, path: &Path) -> Result<NoiseModel, NoiseModelError> {
        let m: NoiseModel = toml::from_str(s).map_err(|e| NoiseModelError::Parse {
            path: path.to_path_buf(),
            source: Box::new(e),
        })?;
        let invalid = |why: String| NoiseModelError::Invalid {
            path: path.to_path_buf(),
            why,
        };
        if m.format_version == 0 || m.format_version > FORMAT_VERSION {
            return Err(invalid(format!(
                "format_version {} is not supported (this build reads 1..={FORMAT_VERSION})",
                m.format_version
            )));
        }
        if !(m.sample_rate_hz.is_finite() && m.sample_rate_hz > 0.0) {
            return Err(invalid(format!(
                "sample_rate_hz must be > 0, got {}",
                m.sample_rate_hz
            )));
        }
        for c in &m.channels {
            for k in [
                TermKind::Quantization,
                TermKind::White,
                TermKind::BiasInstability,
                TermKind::RateRandomWalk,
                TermKind::RateRamp,
                TermKind::GaussMarkov,
            ] {
                if let Some(t) = c.fit.term(k)
                    && !(t.value.is_finite() && t.value >= 0.0)
                {
                    return Err(invalid(format!(
                        "channel '{}': {} = {} is not a finite non-negative value",
                        c.name,
                        k.name(),
                        t.value
                    )));
                }
            }
        }
        Ok(m)
    }

    /// Write the model to `path`.
    pub fn save(&self, path: &Path) -> Result<(), NoiseModelError> {
        let s = self.to_toml_string()?;
        crate::io::output::write(path, s).map_err(|e| NoiseModelError::Write {
            path: path.to_path_buf(),
            source: e,
        })
    }

    /// Read a model from `path`.
    pub fn load(path: &Path) -> Result<NoiseModel, NoiseModelError> {
        let s = crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|e| {
            NoiseModelError::Read {
                path: path.to_path_buf(),
                source: e,
            }
        })?;
        Self::parse(&s, path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::fit::{GaussMarkovTerm, UpperLimit};

    fn term(v: f64) -> Option<Term> {
        Some(Term {
            value: v,
            lo: 0.9 * v,
            hi: 1.1 * v,
        })
    }

    fn gyro_fit() -> NoiseFit {
        NoiseFit {
            quantization: None,
            white: term(0.15 * DEG_PER_SQRT_H),
            bias_instability: term(3.0 * DEG_PER_H),
            rate_random_walk: term(0.5 * DEG_PER_H_PER_SQRT_H),
            rate_ramp: None,
            gauss_markov: Some(GaussMarkovTerm {
                sigma: Term {
                    value: 1e-5,
                    lo: 5e-6,
                    hi: 2e-5,
                },
                tau_c_s: Term {
                    value: 100.0,
                    lo: 50.0,
                    hi: 200.0,
                },
            }),
            confidence: 0.683,
            rms_log10_residual: 0.01,
            not_detected: vec![UpperLimit {
                term: TermKind::RateRamp,
                upper: 1e-9,
            }],
            chi2_reduced: 0.8,
            n_points: 100,
            fit_range: None,
            not_identifiable: Vec::new(),
        }
    }

    #[test]
    fn display_units_gyro() {
        let d = display_terms(&gyro_fit(), Quantity::AngularRate);
        let get = |u: &str| d.iter().find(|v| v.unit == u).unwrap().value;
        assert!((get("deg/sqrt(h)") - 0.15).abs() < 1e-12);
        assert!((get("deg/h") - 3.0).abs() < 1e-12);
        assert!((get("deg/h/sqrt(h)") - 0.5).abs() < 1e-12);
        // 0.15 deg/√h = 0.15/60 deg/√s = 0.0025 deg/s/√Hz
        assert!((get("deg/s/sqrt(Hz)") - 0.0025).abs() < 1e-12);
        let ramp = d.iter().find(|v| v.term == TermKind::RateRamp).unwrap();
        assert!(!ramp.detected && ramp.value == 0.0 && ramp.hi > 0.0);
    }

    #[test]
    fn display_units_accel() {
        let n = 0.02 * M_PER_S_PER_SQRT_H;
        let fit = NoiseFit {
            white: term(n),
            bias_instability: term(50.0 * MICRO_G),
            rate_random_walk: term(1e-4),
            ..gyro_fit()
        };
        let d = display_terms(&fit, Quantity::SpecificForce);
        let get = |u: &str| d.iter().find(|v| v.unit == u).unwrap().value;
        assert!((get("m/s/sqrt(h)") - 0.02).abs() < 1e-12);
        assert!((get("mg") - 0.05).abs() < 1e-12);
        assert!((get("ug") - 50.0).abs() < 1e-9);
        assert!((get("m/s/h^1.5") - 1e-4 * 216_000.0).abs() < 1e-9);
        // 0.02 m/s/√h = 3.33e-4 m/s²/√Hz = 34.0 µg/√Hz
        assert!((get("ug/sqrt(Hz)") - n / MICRO_G).abs() < 1e-9);
    }

    #[test]
    fn discrete_values() {
        let fit = gyro_fit();
        let d = discrete_noise(&fit, 100.0);
        let n = fit.white.unwrap().value;
        assert!((d.white_sigma.unwrap() - n * 10.0).abs() < 1e-15);
        let k = fit.rate_random_walk.unwrap().value;
        assert!((d.rate_random_walk_sigma.unwrap() - k * 0.1).abs() < 1e-18);
        let gm = d.bias_instability_gm.unwrap();
        // The GM stand-in peaks at the floor value.
        let b = fit.bias_instability.unwrap().value;
        let (_, peak) = gauss_markov_avar_peak();
        assert!((gm.sigma * gm.sigma * peak / (BIAS_AVAR_COEF * b * b) - 1.0).abs() < 1e-9);
        assert!((gm.sigma_w - gm.sigma * (1.0 - gm.phi * gm.phi).sqrt()).abs() < 1e-18);
        assert!(gm.tau_c_s > 0.0 && gm.phi < 1.0);
    }

    #[test]
    fn model_minimum_matches_closed_form() {
        let fit = NoiseFit {
            gauss_markov: None,
            ..gyro_fit()
        };
        let n = fit.white.unwrap().value;
        let k = fit.rate_random_walk.unwrap().value;
        let t = model_minimum_tau(&fit);
        assert!((t / (3f64.sqrt() * n / k) - 1.0).abs() < 1e-4, "{t}");
    }

    #[test]
    fn a_short_coloured_record_is_fitted_or_refused_without_a_panic() {
        use crate::allan::analysis::{AnalysisConfig, analyse};
        // AR(1) samples (lag-1 autocorrelation 0.6): coloured at the shortest τ, and so
        // short that the curve is precise to 10 % only over its first few points, before
        // some of the candidate starts.
        for len in [300usize, 1_000, 3_000] {
            let mut state = 7u64;
            let mut e = move || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let mut x = 0.0;
            let y: Vec<f64> = (0..len)
                .map(|_| {
                    x = 0.6 * x + e();
                    x
                })
                .collect();
            let c = analyse("g", &y, 0.01, &AnalysisConfig::default()).expect("curve");
            let r = NoiseModel::from_curves_with(
                "short",
                &[c],
                &[Quantity::AngularRate],
                &FitConfig::default(),
                0.683,
                &ModelOptions::default(),
            );
            if let Ok(m) = r {
                let f = &m.channels[0].fit;
                let range = f.fit_range.expect("range");
                assert!(range.tau_min_s < range.tau_max_s, "{len}: {range:?}");
            }
        }
    }

    #[test]
    fn eliminated_terms_are_refitted_so_the_model_is_the_fitted_one() {
        use crate::allan::fit::fit_noise_opts;
        // N + B curve with a weak K and a deterministic ±3 % ripple; few EDF so the
        // weak terms cannot be resolved.
        let (n, b, kk) = (1e-3, 1e-4, 2e-7);
        let tau: Vec<f64> = (0..60).map(|i| 0.1 * 1.15f64.powi(i)).collect();
        let avar: Vec<f64> = tau
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                (n * n / t + BIAS_AVAR_COEF * b * b + kk * kk * t / 3.0)
                    * (1.0 + 0.03 * (i as f64 * 1.7).sin())
            })
            .collect();
        let edf: Vec<f64> = tau.iter().map(|&t| (2e4 / t).clamp(2.0, 1e5)).collect();
        let fit_with =
            |cfg: &FitConfig| fit_noise_opts(&tau, &avar, &edf, cfg, 0.683, &FitOptions::default());
        let all = FitConfig::default();
        let fit = fit_supported_terms(&all, None, 0.01, fit_with).expect("fit");
        // Every term that stands is resolved from zero …
        for k in TermKind::LINEAR {
            if let Some(t) = fit.term(k) {
                assert!(t.lo > 0.0, "{k:?} {t:?}");
            }
        }
        assert!(
            fit.white.is_some() && fit.bias_instability.is_some(),
            "{fit:?}"
        );
        // … something was eliminated …
        assert!(!fit.not_detected.is_empty(), "{fit:?}");
        // … and the curve is the one a direct fit with the standing terms gives.
        let standing = FitConfig {
            quantization: fit.quantization.is_some(),
            white: true,
            bias_instability: true,
            rate_random_walk: fit.rate_random_walk.is_some(),
            rate_ramp: fit.rate_ramp.is_some(),
            gauss_markov: false,
        };
        let direct = fit_with(&standing).expect("direct");
        for &t in &tau {
            assert!((fit.model_avar(t) / direct.model_avar(t) - 1.0).abs() < 1e-12);
        }
        assert_eq!(fit.chi2_reduced, direct.chi2_reduced);
    }

    #[test]
    fn unresolved_terms_become_upper_limits_and_quantization_is_checked() {
        let mut fit = gyro_fit();
        fit.rate_random_walk = Some(Term {
            value: 1e-6,
            lo: 0.0,
            hi: 3e-6,
        });
        fit.quantization = Some(Term {
            value: 1e-5,
            lo: 5e-6,
            hi: 2e-5,
        });
        // Step 1e-3 at 100 Hz: Δτ0/√12 = 2.9e-6 < 1e-5/3: the quantization goes first.
        let (kind, why) = least_supported_term(&fit, Some(1e-3), 0.01).expect("a term");
        assert_eq!(kind, TermKind::Quantization);
        let Unsupported::NotIdentifiable(q) = why else {
            panic!("{why:?}")
        };
        assert!(q.reason.contains("3.5x"), "{q:?}");
        // Without a step, the unresolved K is next, as an upper limit.
        let (kind, why) = least_supported_term(&fit, None, 0.01).expect("a term");
        assert_eq!(kind, TermKind::RateRandomWalk);
        assert_eq!(
            why,
            Unsupported::UpperLimit(UpperLimit {
                term: TermKind::RateRandomWalk,
                upper: 3e-6
            })
        );
        // A quantization the step explains stays.
        let mut ok = gyro_fit();
        ok.quantization = Some(Term {
            value: 5e-6,
            lo: 4e-6,
            hi: 6e-6,
        });
        assert_eq!(least_supported_term(&ok, Some(1e-3), 0.01), None);
        let text = fit_quality_lines(&NoiseFit {
            chi2_reduced: 12.0,
            fit_range: Some(FitRange {
                tau_min_s: 0.2,
                tau_max_s: 2500.0,
                source: RangeSource::Auto,
                excluded_short: 14,
                excluded_long: 0,
            }),
            ..gyro_fit()
        });
        assert!(text.contains("fit range 0.20000 … 2500.0 s"), "{text}");
        assert!(text.contains("14 short-tau point(s) left out"), "{text}");
        assert!(text.contains("WARNING: poor"), "{text}");
    }

    #[test]
    fn bias_stand_in_needs_the_floor_inside_the_range() {
        // Without a rate random walk the model has no minimum: no stand-in.
        let fit = NoiseFit {
            rate_random_walk: None,
            gauss_markov: None,
            fit_range: Some(FitRange {
                tau_min_s: 0.1,
                tau_max_s: 1e3,
                source: RangeSource::Full,
                excluded_short: 0,
                excluded_long: 0,
            }),
            ..gyro_fit()
        };
        assert!(bias_floor_tau(&fit).is_none());
        assert!(discrete_noise(&fit, 100.0).bias_instability_gm.is_none());
        // With K the floor is at √3·N/K ≈ 1 870 s: inside a range to 10⁴ s.
        let with_k = NoiseFit {
            gauss_markov: None,
            fit_range: fit.fit_range.map(|r| FitRange {
                tau_max_s: 1e4,
                ..r
            }),
            ..gyro_fit()
        };
        assert!(discrete_noise(&with_k, 100.0).bias_instability_gm.is_some());
        let short = NoiseFit {
            fit_range: fit.fit_range,
            ..with_k.clone()
        };
        assert!(discrete_noise(&short, 100.0).bias_instability_gm.is_none());
    }

    #[test]
    fn toml_round_trip_and_errors() {
        let mut m = NoiseModel::new(Some("log.csv".into()), 100.0, Some("oadev".into()));
        m.channels.push(ChannelNoise::new(
            "gyro_x",
            Quantity::AngularRate,
            gyro_fit(),
            100.0,
        ));
        let mut acc = ChannelNoise::new("accel_z", Quantity::SpecificForce, gyro_fit(), 100.0);
        acc.slope_readings = Some(SlopeReadings {
            white: Some(1.0),
            bias_instability: None,
            tau_min: None,
            rate_random_walk: Some(2.0),
        });
        m.channels.push(acc);
        let s = m.to_toml_string().unwrap();
        let back = NoiseModel::from_toml_str(&s).unwrap();
        assert_eq!(back, m);
        assert!(s.contains("gyro_x") && s.contains("deg/sqrt(h)"));

        let dir = std::env::temp_dir().join(format!("driftless-nm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("model.toml");
        m.save(&p).unwrap();
        assert_eq!(NoiseModel::load(&p).unwrap(), m);

        let missing = dir.join("missing.toml");
        let e = NoiseModel::load(&missing).unwrap_err();
        assert!(e.to_string().contains("missing.toml"), "{e}");
        std::fs::write(&p, "format_version = 1\nsample_rate_hz = \"x\"\n").unwrap();
        let e = NoiseModel::load(&p).unwrap_err();
        assert!(matches!(e, NoiseModelError::Parse { .. }));
        assert!(e.to_string().contains("model.toml"), "{e}");
        std::fs::write(
            &p,
            "format_version = 9\nsample_rate_hz = 100.0\nchannels = []\n",
        )
        .unwrap();
        assert!(matches!(
            NoiseModel::load(&p).unwrap_err(),
            NoiseModelError::Invalid { .. }
        ));
        std::fs::remove_dir_all(&dir).ok();
    }
}

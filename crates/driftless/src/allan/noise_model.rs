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

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::AllanError;
use super::analysis::ChannelResult;
use super::fit::{
    FitConfig, FitOptions, FitRange, FitRangeSpec, MODEL_ERROR_FLOOR, NoiseFit, NotIdentifiable,
    RangeSource, SlopeReadings, TermKind, auto_range_candidates, fit_noise_with_edf_opts,
    short_tau_coloured, slope_readings,
};

mod discrete;
mod display;
mod file;
mod selection;
mod table;

pub use discrete::{
    DiscreteGaussMarkov, DiscreteNoise, bias_floor_tau, discrete_noise, model_minimum_tau,
};
pub use display::{DisplayValue, display_terms, display_units};
pub(crate) use display::{fmt_num, si_term_units, term_label};
pub(crate) use selection::CURVE_PRECISION;
pub use selection::{auto_fit_end, fit_supported_terms, widen_for_the_start};
use selection::{auto_range, user_indices};
pub use table::fit_quality_lines;

/// Current file format version.
pub const FORMAT_VERSION: u32 = 1;

pub use crate::io::Quantity;

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
            let ch = ChannelFit::new(c, cfg, confidence, opts, k);
            let (i0, i1, source, mut fit) = match opts.fit_range {
                Some(r) => {
                    let (i0, i1) = user_indices(c, r)?;
                    let f = ch.fit_over(i0, i1).map_err(|e| ch.named(e, true))?;
                    (i0, i1, RangeSource::User, f)
                }
                None => ch.auto_fit()?,
            };
            let tau = &ch.tau;
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
            let mut noise = ChannelNoise::new(&c.name, q, fit, 1.0 / c.tau0_s);
            if noise.fit.bias_instability.is_some() && noise.discrete.bias_instability_gm.is_none()
            {
                noise.fit.not_identifiable.push(NotIdentifiable {
                    term: TermKind::BiasInstability,
                    reason: "its Gauss-Markov stand-in: the model's floor lies beyond the \
                             fitted range, so its correlation time is unknown (B itself stands)"
                        .into(),
                });
            }
            let adev: Vec<f64> = c.points.iter().map(|p| p.dev).collect();
            noise.slope_readings = Some(slope_readings(tau, &adev));
            model.channels.push(noise);
        }
        Ok(model)
    }
}

/// One channel's curve prepared for fitting: τ, σ², the EDF of every point for every
/// noise exponent, and what every fit of it shares.
struct ChannelFit<'a> {
    c: &'a ChannelResult,
    tau: Vec<f64>,
    avar: Vec<f64>,
    /// EDF of every point for noise exponents −2 … 2, computed once: the fits ask for
    /// them thousands of times.
    edf_table: Vec<[f64; 5]>,
    /// Resolution step of the channel, if known.
    step: Option<f64>,
    fit_opts: FitOptions,
    cfg: &'a FitConfig,
    /// The configuration the start is searched with: the linear terms only, since the
    /// start is decided by the short τ and a Gauss-Markov search per candidate would cost
    /// tens of times the rest of the fit.
    search_cfg: FitConfig,
    confidence: f64,
    opts: &'a ModelOptions,
}

impl<'a> ChannelFit<'a> {
    fn new(
        c: &'a ChannelResult,
        cfg: &'a FitConfig,
        confidence: f64,
        opts: &'a ModelOptions,
        k: usize,
    ) -> Self {
        let tau: Vec<f64> = c.points.iter().map(|p| p.tau).collect();
        let avar: Vec<f64> = c.points.iter().map(|p| p.dev * p.dev).collect();
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
        let edf_table: Vec<[f64; 5]> = (0..tau.len())
            .map(|i| [-2, -1, 0, 1, 2].map(|a| c.edf_for_alpha(i, a)))
            .collect();
        let search_cfg = if cfg.linear_terms().is_empty() {
            *cfg
        } else {
            FitConfig {
                gauss_markov: false,
                ..*cfg
            }
        };
        ChannelFit {
            c,
            tau,
            avar,
            edf_table,
            step: opts.resolution.get(k).copied().flatten(),
            fit_opts,
            cfg,
            search_cfg,
            confidence,
            opts,
        }
    }

    fn edf_of(&self, i: usize, alpha: i32) -> f64 {
        self.edf_table[i][(alpha.clamp(-2, 2) + 2) as usize]
    }

    /// The supported terms of `cfg` fitted over points `i0..i1`.
    fn fit_with(&self, i0: usize, i1: usize, cfg: &FitConfig) -> Result<NoiseFit, AllanError> {
        let tau = &self.tau;
        if i0 >= i1 || i1 > tau.len() {
            return Err(AllanError::Invalid(format!(
                "no curve point between τ index {i0} and {i1}"
            )));
        }
        fit_supported_terms(cfg, self.step, self.c.tau0_s, |cfg| {
            fit_noise_with_edf_opts(
                &tau[i0..i1],
                &self.avar[i0..i1],
                |i, a| self.edf_of(i0 + i, a),
                cfg,
                self.confidence,
                &self.fit_opts,
            )
        })
    }

    /// The fit asked for, over points `i0..i1`.
    fn fit_over(&self, i0: usize, i1: usize) -> Result<NoiseFit, AllanError> {
        self.fit_with(i0, i1, self.cfg)
    }

    /// The fit the start is searched with, over points `i0..i1`.
    fn search_over(&self, i0: usize, i1: usize) -> Result<NoiseFit, AllanError> {
        self.fit_with(i0, i1, &self.search_cfg)
    }

    /// A fit error naming the channel (and, for a user range, what to change).
    fn named(&self, e: AllanError, user: bool) -> AllanError {
        AllanError::Invalid(format!(
            "noise fit of channel '{}': {e}{}",
            self.c.name,
            if user {
                " (choose a wider --fit-range)"
            } else {
                ""
            }
        ))
    }

    /// Mean squared normalised residual over points `idx`, with the fit's own weights.
    fn msr(&self, idx: &mut dyn Iterator<Item = usize>, f: &NoiseFit) -> f64 {
        let (mut sum, mut k) = (0.0, 0usize);
        for i in idx {
            let model = f.model_avar(self.tau[i]);
            let nu = self.edf_of(i, f.dominant_alpha(self.tau[i]));
            if model > 0.0 && nu > 0.0 {
                let var = model * model * (2.0 / nu + self.opts.model_error_floor.powi(2));
                sum += (self.avar[i] - model).powi(2) / var;
                k += 1;
            }
        }
        if k == 0 { 0.0 } else { sum / k as f64 }
    }

    /// The automatic range: up to where the curve is known well enough, starting past the
    /// short τ the sensor's filtering colours (when it does), with the start's leftover
    /// widening the intervals.
    fn auto_fit(&self) -> Result<(usize, usize, RangeSource, NoiseFit), AllanError> {
        let (c, tau) = (self.c, &self.tau);
        let n = self
            .opts
            .curve_precision
            .map_or(tau.len(), |p| auto_fit_end(c, p));
        let longest = c
            .segment_phase_points
            .iter()
            .max()
            .map_or(0, |n| n.saturating_sub(1));
        let coloured =
            short_tau_coloured(&c.rate_acf1, longest.min(super::analysis::MAX_ACF_BLOCKS));
        if !coloured {
            let f = self.fit_over(0, n).map_err(|e| self.named(e, false))?;
            return Ok((0, n, RangeSource::Full, f));
        }
        let m: Vec<usize> = c.points.iter().map(|p| p.m).collect();
        // The first half decade of the range, where a filter's leftover shows.
        let head = |i0: usize, f: &NoiseFit| {
            self.msr(&mut (i0..n).take_while(|&i| tau[i] <= 3.0 * tau[i0]), f)
        };
        let search_over = |i0: usize, i1: usize| self.search_over(i0, i1);
        let candidates: Vec<usize> = auto_range_candidates(&m)
            .into_iter()
            .filter(|&i0| i0 < n)
            .collect();
        let (i0, i1, src, found) =
            auto_range(&candidates, n, &search_over, &head).map_err(|e| self.named(e, false))?;
        let mut f = if self.search_cfg == *self.cfg {
            found.clone()
        } else {
            self.fit_over(i0, i1).map_err(|e| self.named(e, false))?
        };
        // The leftover of the sensor's filtering at the chosen start.
        if let Some(&next) = candidates.iter().find(|&&j| j > i0 && j + 1 < i1)
            && let Ok(later) = self.search_over(next, i1)
        {
            widen_for_the_start(&mut f, &found, &later, tau[next] / tau[i0]);
        }
        Ok((i0, i1, src, f))
    }
}

#[cfg(test)]
mod tests {
    use super::selection::{Unsupported, least_supported_term};
    use super::*;
    use crate::allan::fit::{
        BIAS_AVAR_COEF, GaussMarkovTerm, Term, UpperLimit, gauss_markov_avar_peak,
    };
    use driftless_model::units::{
        DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MICRO_G,
    };

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

//! Generalized method of wavelet moments (GMWM): a second noise-model estimator beside
//! the Allan-variance fit (Guerrier, Skaloud, Stebler & Victoria-Feser 2013,
//! "Wavelet-variance-based estimation for composite stochastic processes", JASA
//! 108(503), 1021–1030).
//!
//! # Method
//!
//! 1. **Haar wavelet variance** ν̂²(τ_j) at the dyadic averaging lengths m_j = 2^{j−1}
//!    samples, τ_j = m_j·τ0, j = 1 … J with 4·m_J ≤ N (the largest scale the overlapping
//!    Allan estimator allows). The unbiased MODWT estimator over the M_j = N − 2m_j + 1
//!    non-boundary coefficients equals exactly half the fully overlapping Allan variance
//!    (both sum the same squared differences of adjacent m-sample means), so it is
//!    computed with the fast OADEV sums of [`super::estimators`]. Data split at time gaps
//!    contribute segment by segment.
//! 2. **Intervals on ν̂²**: ν̂²/ν² ≈ χ²_η/η with η = max(M_j/2^j, 1) (the η₃ EDF of
//!    Percival & Walden 2000, *Wavelet Methods for Time Series Analysis*, §8.4, eq. 314c);
//!    segments' EDFs add.
//! 3. **Model**: a sum of independent processes — white noise, quantization, random
//!    walk, drift and up to four first-order Gauss–Markov (AR(1)) terms; their Haar WV is
//!    additive and each has the closed form of [`theory`].
//! 4. **GMM fit**: θ̂ = argmin (ν̂ − ν(θ))ᵀ Ω (ν̂ − ν(θ)) with Ω diagonal,
//!    Ω_jj = η_j / (2 ν_j(θ̃)²) — the inverse of the χ² variance 2ν⁴/η, i.e. the diagonal
//!    approximation of the inverse covariance of ν̂ (cross-scale correlation ignored).
//!    θ̃ is the previous iterate (data values ν̂ in the first round, then the model twice:
//!    weighting by the data biases the fit low, as low estimates get large weights).
//!    Parameters are transformed (ln of every squared amplitude, ln of each
//!    Gauss–Markov correlation time) and fitted by Levenberg–Marquardt from several
//!    starts: correlation times on a log grid with the amplitudes from a non-negative
//!    least-squares fit for each grid combination (variable projection), best three
//!    polished.
//! 5. **Model selection** among every subset of the allowed processes (with 0 … max
//!    Gauss–Markov terms) by the wavelet information criterion WIC = J(θ̂) + 2p: the WIC's
//!    optimism term 2·tr(Ω·cov(ν̂, ν(θ̂))) (Guerrier et al.) evaluated to first order
//!    with Ω = V⁻¹ reduces to 2p, p the number of parameters; J(θ̂) is the objective above.
//!    The lowest WIC wins.
//! 6. **Intervals on the parameters** by a parametric bootstrap: B series of the data's
//!    segment lengths are simulated from θ̂ (with [`crate::sim::noise::generate`]), their
//!    WV computed and the model refitted by the same multi-start procedure as the data;
//!    the interval is θ̂ ± z·sd* in the transformed space (sd* = 1.4826 × the median
//!    absolute deviation of the replicates, a standard deviation robust to the few
//!    replicates that drop a term; z the normal quantile), mapped back.
//!    Their coverage over seeds is measured in `tests/gmwm.rs`.
//!
//! The result maps onto the noise-model file ([`noise_model`]): white → `white`,
//! quantization → `quantization`, random walk → `rate_random_walk`, drift → `rate_ramp`,
//! the Gauss–Markov term of longest correlation time → `gauss_markov`; the complete
//! GMWM model (every Gauss–Markov term, criterion, candidates) is stored beside it in
//! the channel's optional `gmwm` table, which older files simply lack.

mod solve;
pub mod theory;

use std::str::FromStr;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::analysis::ChannelResult;
use super::fit::{GaussMarkovTerm, NoiseFit, Term};
use super::noise_model::{ChannelNoise, NoiseModel};
use super::phase::frequency_to_phase;
use super::{AllanError, Estimator, ci, estimators};
use crate::io::Quantity;

pub use solve::{fit_gmwm, simulate};

/// Largest number of Gauss–Markov terms a GMWM model may hold.
pub(crate) const MAX_GAUSS_MARKOV: usize = 4;

/// One process of a GMWM model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Process {
    /// Quantization noise Q (white phase error), u·s.
    Quantization,
    /// White noise density N, u·√s.
    White,
    /// Random walk density K (rate random walk), u/√s.
    RandomWalk,
    /// Linear drift R (rate ramp), u/s.
    Drift,
    /// First-order Gauss–Markov: stationary σ_b (u) and correlation time T (s).
    GaussMarkov,
}

impl Process {
    /// Conventional short label (QN, WN, RW, DR, GM).
    pub fn label(self) -> &'static str {
        match self {
            Process::Quantization => "QN",
            Process::White => "WN",
            Process::RandomWalk => "RW",
            Process::Drift => "DR",
            Process::GaussMarkov => "GM",
        }
    }
}

/// One process with its parameters, SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ProcessParams {
    /// Quantization Q, u·s.
    Quantization {
        /// Q, u·s.
        q: f64,
    },
    /// White noise density N, u·√s.
    White {
        /// N, u·√s.
        n: f64,
    },
    /// Random walk density K, u/√s.
    RandomWalk {
        /// K, u/√s.
        k: f64,
    },
    /// Drift slope R, u/s.
    Drift {
        /// R, u/s.
        r: f64,
    },
    /// Gauss–Markov σ_b (u), T (s).
    GaussMarkov {
        /// Stationary σ_b, u.
        sigma: f64,
        /// Correlation time T, s.
        tau_c_s: f64,
    },
}

impl ProcessParams {
    /// Haar wavelet variance at averaging length `m` samples (closed forms of [`theory`]).
    pub fn wv(&self, m: f64, tau0_s: f64) -> f64 {
        match *self {
            ProcessParams::Quantization { q } => theory::wv_quantization(q, m, tau0_s),
            ProcessParams::White { n } => theory::wv_white(n, m, tau0_s),
            ProcessParams::RandomWalk { k } => theory::wv_random_walk(k, m, tau0_s),
            ProcessParams::Drift { r } => theory::wv_drift(r, m, tau0_s),
            ProcessParams::GaussMarkov { sigma, tau_c_s } => {
                theory::wv_gauss_markov(sigma, tau_c_s, m, tau0_s)
            }
        }
    }
}

/// Haar wavelet variance of one channel with its confidence intervals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WaveletVariance {
    /// Sample interval τ0, s.
    pub tau0_s: f64,
    /// Averaging length m_j = 2^{j−1} samples.
    pub m: Vec<usize>,
    /// τ_j = m_j·τ0, s.
    pub tau_s: Vec<f64>,
    /// ν̂²(τ_j), u².
    pub wv: Vec<f64>,
    /// Lower confidence bound of ν², u².
    pub wv_lo: Vec<f64>,
    /// Upper confidence bound of ν², u².
    pub wv_hi: Vec<f64>,
    /// η₃ equivalent degrees of freedom of each ν̂².
    pub edf: Vec<f64>,
    /// Confidence level of the bounds.
    pub confidence: f64,
    /// Samples of each gap-free segment (the parametric bootstrap simulates the same).
    pub segment_samples: Vec<usize>,
}

/// Haar wavelet variance of rate samples given as gap-free segments, at every dyadic
/// scale with 4m ≤ (samples of the longest segment), with χ² bounds at `confidence`.
pub fn wavelet_variance(
    segments: &[&[f64]],
    tau0_s: f64,
    confidence: f64,
) -> Result<WaveletVariance, AllanError> {
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::Invalid(format!(
            "sample interval must be finite and > 0 s, got {tau0_s}"
        )));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Invalid(format!(
            "confidence level must be between 0 and 1, got {confidence}"
        )));
    }
    let mut offset = 0usize;
    for seg in segments {
        if let Some(i) = seg.iter().position(|v| !v.is_finite()) {
            return Err(AllanError::NonFinite {
                index: offset + i,
                value: seg[i],
            });
        }
        offset += seg.len();
    }
    let longest = segments.iter().map(|s| s.len()).max().unwrap_or(0);
    let mut ms = Vec::new();
    let mut m = 1usize;
    while 4 * m <= longest {
        ms.push(m);
        m *= 2;
    }
    if ms.len() < 3 {
        return Err(AllanError::TooFewSamples {
            estimator: "gmwm",
            tau: 4.0 * tau0_s,
            m: 4,
            needed: 16,
            have: longest,
        });
    }
    let (wv, edf) = raw_wavelet_variance(segments, tau0_s, &ms);
    let mut lo = Vec::with_capacity(ms.len());
    let mut hi = Vec::with_capacity(ms.len());
    for (&v, &e) in wv.iter().zip(&edf) {
        let (l, h) = ci::bounds(v.sqrt(), e, confidence);
        lo.push(l * l);
        hi.push(h * h);
    }
    Ok(WaveletVariance {
        tau0_s,
        tau_s: ms.iter().map(|&m| m as f64 * tau0_s).collect(),
        m: ms,
        wv,
        wv_lo: lo,
        wv_hi: hi,
        edf,
        confidence,
        segment_samples: segments.iter().map(|s| s.len()).collect(),
    })
}

/// ν̂² and η₃ at averaging lengths `ms`: per segment the OADEV sums Σ(Δ²x)² over
/// M = N − 2m + 1 terms, ν̂² = Σ/(4τ²M) summed over segments; η = Σ_seg max(M/2m, 1).
pub(crate) fn raw_wavelet_variance(
    segments: &[&[f64]],
    tau0_s: f64,
    ms: &[usize],
) -> (Vec<f64>, Vec<f64>) {
    let mut sum = vec![0.0; ms.len()];
    let mut count = vec![0usize; ms.len()];
    let mut edf = vec![0.0; ms.len()];
    for seg in segments {
        let x = frequency_to_phase(seg, tau0_s);
        for (i, s) in estimators::sums(Estimator::Oadev, &x, ms)
            .into_iter()
            .enumerate()
        {
            if s.n > 0 {
                sum[i] += s.sum;
                count[i] += s.n;
                edf[i] += (s.n as f64 / (2.0 * s.m as f64)).max(1.0);
            }
        }
    }
    let wv = ms
        .iter()
        .zip(sum.iter().zip(&count))
        .map(|(&m, (&s, &n))| {
            let tau = m as f64 * tau0_s;
            if n == 0 {
                0.0
            } else {
                s / (4.0 * tau * tau * n as f64)
            }
        })
        .collect();
    (wv, edf)
}

/// Which processes the model selection may use, and how the intervals are made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GmwmConfig {
    /// Quantization may enter.
    pub quantization: bool,
    /// White noise may enter.
    pub white: bool,
    /// Random walk may enter.
    pub random_walk: bool,
    /// Drift may enter.
    pub drift: bool,
    /// Up to this many Gauss–Markov terms (0 ..= `MAX_GAUSS_MARKOV`).
    pub max_gauss_markov: usize,
    /// Confidence level of the parameter intervals.
    pub confidence: f64,
    /// Parametric-bootstrap replicates for the intervals (0: no intervals, lo = hi = value).
    pub bootstrap: usize,
    /// Seed of the bootstrap simulations (results are reproducible).
    pub seed: u64,
}

impl Default for GmwmConfig {
    /// White noise, quantization, random walk, drift and up to three Gauss–Markov terms
    /// as candidates; 68.3 % intervals from 100 bootstrap replicates.
    fn default() -> Self {
        GmwmConfig {
            quantization: true,
            white: true,
            random_walk: true,
            drift: true,
            max_gauss_markov: 3,
            confidence: 0.683,
            bootstrap: 100,
            seed: 1,
        }
    }
}

/// Parses the candidate processes from the `--terms` list: `q` quantization, `n` white,
/// `k` random walk, `r` drift, `gm` up to three Gauss–Markov terms, `gmN` up to N.
/// Bias instability (`b`) has no GMWM process (it is modelled by Gauss–Markov terms).
impl FromStr for GmwmConfig {
    type Err = AllanError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut c = GmwmConfig {
            quantization: false,
            white: false,
            random_walk: false,
            drift: false,
            max_gauss_markov: 0,
            ..GmwmConfig::default()
        };
        for t in s.split(',').map(|t| t.trim().to_ascii_lowercase()) {
            match t.as_str() {
                "q" => c.quantization = true,
                "n" => c.white = true,
                "k" => c.random_walk = true,
                "r" => c.drift = true,
                "gm" => c.max_gauss_markov = 3,
                "" => {}
                "b" => {
                    return Err(AllanError::Invalid(format!(
                        "term 'b' (bias instability) in {s:?} has no GMWM process model: \
                         the GMWM represents it by Gauss-Markov terms, use gm or gm2..gm{MAX_GAUSS_MARKOV}"
                    )));
                }
                other => {
                    let n = other
                        .strip_prefix("gm")
                        .and_then(|d| d.parse::<usize>().ok())
                        .filter(|&n| (1..=MAX_GAUSS_MARKOV).contains(&n));
                    match n {
                        Some(n) => c.max_gauss_markov = n,
                        None => {
                            return Err(AllanError::Invalid(format!(
                                "unknown GMWM term {other:?} in {s:?} (expected q, n, k, r, gm, \
                                 gm1..gm{MAX_GAUSS_MARKOV})"
                            )));
                        }
                    }
                }
            }
        }
        if !(c.quantization || c.white || c.random_walk || c.drift || c.max_gauss_markov > 0) {
            return Err(AllanError::Invalid(format!(
                "GMWM term list {s:?} selects no process"
            )));
        }
        Ok(c)
    }
}

/// One fitted GMWM term with its interval (at the fit's confidence), SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GmwmTerm {
    /// Which process.
    pub process: Process,
    /// Q (u·s), N (u·√s), K (u/√s), R (u/s) or the Gauss–Markov σ_b (u).
    pub value: Term,
    /// Gauss–Markov correlation time T, s (None for the other processes).
    #[serde(default)]
    pub tau_c_s: Option<Term>,
}

/// Score of one candidate model in the selection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    /// Model label, e.g. `WN+RW+2GM`.
    pub model: String,
    /// Number of parameters p.
    pub n_params: usize,
    /// GMM objective J(θ̂).
    pub objective: f64,
    /// WIC = J(θ̂) + 2p.
    pub wic: f64,
}

/// A GMWM fit of one channel: the selected model, its intervals and the selection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GmwmFit {
    /// Selected model label.
    pub model: String,
    /// Its terms (Gauss–Markov terms by increasing correlation time).
    pub terms: Vec<GmwmTerm>,
    /// Selection criterion, stated.
    pub criterion: String,
    /// GMM objective J(θ̂) of the selected model.
    pub objective: f64,
    /// Its WIC.
    pub wic: f64,
    /// Parameters of the selected model.
    pub n_params: usize,
    /// Wavelet scales fitted.
    pub n_scales: usize,
    /// Every candidate, lowest WIC first.
    pub candidates: Vec<CandidateScore>,
    /// Confidence level of the intervals.
    pub confidence: f64,
    /// Bootstrap replicates that went into the intervals.
    pub bootstrap: usize,
    /// Sample interval, s.
    pub tau0_s: f64,
    /// RMS of log10(model/measured) wavelet variance over the scales.
    pub rms_log10_residual: f64,
}

/// Gauss–Markov terms (other than the slowest) with T below this many sample intervals
/// are white noise to a filter and go into the file's `white` term.
pub(crate) const WHITE_FOLD_SAMPLES: f64 = 10.0;

/// The criterion as reported.
pub const CRITERION: &str = "WIC = J(theta) + 2p (GMM objective with the diagonal eta3 \
                              weights plus twice the number of parameters)";

impl GmwmFit {
    /// Parameters of the fitted terms (point estimates).
    pub fn params(&self) -> Vec<ProcessParams> {
        self.terms.iter().map(term_params).collect()
    }

    /// Model Haar wavelet variance at averaging time `tau_s`.
    pub fn model_wv(&self, tau_s: f64) -> f64 {
        let m = tau_s / self.tau0_s;
        self.params().iter().map(|p| p.wv(m, self.tau0_s)).sum()
    }

    /// Model Allan variance at `tau_s`: twice the wavelet variance.
    pub fn model_avar(&self, tau_s: f64) -> f64 {
        2.0 * self.model_wv(tau_s)
    }

    /// Map into the noise-model file's fit: white → `white`, quantization →
    /// `quantization`, random walk → `rate_random_walk`, drift → `rate_ramp`, the
    /// Gauss–Markov term of longest correlation time → `gauss_markov` (the complete model
    /// is kept in [`ChannelNoise::gmwm`]). `chi2_reduced` is J/(J_scales − p).
    ///
    /// Any other Gauss–Markov term with T < `WHITE_FOLD_SAMPLES`·τ0 is, for a filter
    /// or simulator, white noise: it is folded into `white` with its low-frequency
    /// density N² = 2σ_b²T (the two-sided PSD at f = 0; Gelb 1974, §4.4), so that a
    /// model whose "white" part the GMWM found correlated over a few samples still
    /// carries it. The folded interval adds the squared bounds (errors treated as fully
    /// correlated, i.e. the wider choice).
    pub fn to_noise_fit(&self) -> NoiseFit {
        let find = |p: Process| self.terms.iter().find(|t| t.process == p).map(|t| t.value);
        let gms: Vec<(Term, Term)> = self
            .terms
            .iter()
            .filter(|t| t.process == Process::GaussMarkov)
            .filter_map(|t| t.tau_c_s.map(|tc| (t.value, tc)))
            .collect();
        let slowest = gms
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.1.value.total_cmp(&b.1.1.value))
            .map(|(i, _)| i);
        let gauss_markov = slowest.map(|i| GaussMarkovTerm {
            sigma: gms[i].0,
            tau_c_s: gms[i].1,
        });
        let mut white = find(Process::White);
        for (i, (sigma, tc)) in gms.iter().enumerate() {
            if Some(i) == slowest || tc.value >= WHITE_FOLD_SAMPLES * self.tau0_s {
                continue;
            }
            let d2 = |s: f64, t: f64| 2.0 * s * s * t;
            let w = white.unwrap_or(Term {
                value: 0.0,
                lo: 0.0,
                hi: 0.0,
            });
            white = Some(Term {
                value: (w.value.powi(2) + d2(sigma.value, tc.value)).sqrt(),
                lo: (w.lo.powi(2) + d2(sigma.lo, tc.lo)).sqrt(),
                hi: (w.hi.powi(2) + d2(sigma.hi, tc.hi)).sqrt(),
            });
        }
        let dof = self.n_scales.saturating_sub(self.n_params).max(1);
        NoiseFit {
            quantization: find(Process::Quantization),
            white,
            bias_instability: None,
            rate_random_walk: find(Process::RandomWalk),
            rate_ramp: find(Process::Drift),
            gauss_markov,
            confidence: self.confidence,
            rms_log10_residual: self.rms_log10_residual,
            not_detected: Vec::new(),
            chi2_reduced: self.objective / dof as f64,
            n_points: self.n_scales,
            fit_range: None,
            not_identifiable: Vec::new(),
        }
    }
}

fn term_params(t: &GmwmTerm) -> ProcessParams {
    let v = t.value.value;
    match t.process {
        Process::Quantization => ProcessParams::Quantization { q: v },
        Process::White => ProcessParams::White { n: v },
        Process::RandomWalk => ProcessParams::RandomWalk { k: v },
        Process::Drift => ProcessParams::Drift { r: v },
        Process::GaussMarkov => ProcessParams::GaussMarkov {
            sigma: v,
            tau_c_s: t.tau_c_s.map_or(f64::NAN, |t| t.value),
        },
    }
}

/// GMWM of one channel given as gap-free segments of rate samples.
pub fn gmwm_segments(
    segments: &[&[f64]],
    tau0_s: f64,
    cfg: &GmwmConfig,
) -> Result<(WaveletVariance, GmwmFit), AllanError> {
    let wv = wavelet_variance(segments, tau0_s, cfg.confidence)?;
    let fit = fit_gmwm(&wv, cfg)?;
    Ok((wv, fit))
}

/// One channel's GMWM result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GmwmChannel {
    /// Channel name.
    pub name: String,
    /// Its wavelet variance.
    pub wavelet_variance: WaveletVariance,
    /// Its fit.
    pub fit: GmwmFit,
}

/// GMWM of several channels (each as its gap-free segments) in parallel; the error
/// names the channel.
pub(crate) fn gmwm_channels(
    channels: &[(&str, Vec<&[f64]>)],
    tau0_s: f64,
    cfg: &GmwmConfig,
) -> Result<Vec<GmwmChannel>, AllanError> {
    channels
        .par_iter()
        .map(|(name, segs)| {
            let (wavelet_variance, fit) = gmwm_segments(segs, tau0_s, cfg)
                .map_err(|e| AllanError::Invalid(format!("GMWM of channel '{name}': {e}")))?;
            Ok(GmwmChannel {
                name: name.to_string(),
                wavelet_variance,
                fit,
            })
        })
        .collect()
}

/// The noise-model file of GMWM fits (`estimator = "gmwm"`); `quantities[i]` belongs
/// to `channels[i]`. Each channel carries the mapped fit and the full GMWM model.
pub fn noise_model(
    source: &str,
    channels: &[GmwmChannel],
    quantities: &[Quantity],
) -> Result<NoiseModel, AllanError> {
    if channels.len() != quantities.len() {
        return Err(AllanError::Invalid(format!(
            "noise model: {} channels but {} quantities",
            channels.len(),
            quantities.len()
        )));
    }
    let fs = channels.first().map_or(0.0, |c| 1.0 / c.fit.tau0_s);
    let mut model = NoiseModel::new(Some(source.to_string()), fs, Some("gmwm".into()));
    for (c, &q) in channels.iter().zip(quantities) {
        let mut ch = ChannelNoise::new(&c.name, q, c.fit.to_noise_fit(), fs);
        ch.gmwm = Some(c.fit.clone());
        model.channels.push(ch);
    }
    Ok(model)
}

/// Human-readable GMWM summary of a model built by [`noise_model`]: per channel the
/// selected model, its WIC, every term with its interval in display units, and the
/// three best candidates.
pub fn human_table(model: &NoiseModel) -> String {
    use super::noise_model::display_units;
    let mut s = String::new();
    for c in &model.channels {
        let Some(g) = &c.gmwm else { continue };
        s.push_str(&format!(
            "\n{} [{}]  GMWM model {}  (WIC {:.1}, J {:.1}, p {}, {} scales, {:.1} % intervals \
             from {} bootstrap replicates)\n",
            c.name,
            c.unit,
            g.model,
            g.wic,
            g.objective,
            g.n_params,
            g.n_scales,
            100.0 * g.confidence,
            g.bootstrap
        ));
        s.push_str(&format!(
            "  {:<18} {:>11} {:>11} {:>11}  {}\n",
            "term", "value", "lo", "hi", "unit"
        ));
        let kind = |p: Process| match p {
            Process::Quantization => super::fit::TermKind::Quantization,
            Process::White => super::fit::TermKind::White,
            Process::RandomWalk => super::fit::TermKind::RateRandomWalk,
            Process::Drift => super::fit::TermKind::RateRamp,
            Process::GaussMarkov => super::fit::TermKind::GaussMarkov,
        };
        for t in &g.terms {
            let (unit, size) = display_units(c.quantity, kind(t.process))
                .first()
                .copied()
                .unwrap_or(("SI", 1.0));
            let label = match t.process {
                Process::Quantization => "quantization Q",
                Process::White => "white N",
                Process::RandomWalk => "random walk K",
                Process::Drift => "drift R",
                Process::GaussMarkov => "GM sigma",
            };
            s.push_str(&format!(
                "  {:<18} {:>11.4e} {:>11.4e} {:>11.4e}  {}\n",
                label,
                t.value.value / size,
                t.value.lo / size,
                t.value.hi / size,
                unit
            ));
            if let Some(tc) = t.tau_c_s {
                s.push_str(&format!(
                    "  {:<18} {:>11.4e} {:>11.4e} {:>11.4e}  s\n",
                    "GM corr. time", tc.value, tc.lo, tc.hi
                ));
            }
        }
        s.push_str("  candidates (WIC):");
        for cand in g.candidates.iter().take(3) {
            s.push_str(&format!(" {} {:.1};", cand.model, cand.wic));
        }
        s.push('\n');
    }
    s
}

/// Ratio of a model's Allan deviation to a measured OADEV curve at every point with
/// τ in `[tau_lo_s, tau_hi_s]`: σ_model(τ)/σ̂(τ) − 1 (for comparing estimators on a
/// run they were not fitted to).
pub fn adev_ratio_errors(
    curve: &ChannelResult,
    model_avar: impl Fn(f64) -> f64,
    tau_lo_s: f64,
    tau_hi_s: f64,
) -> Vec<f64> {
    curve
        .points
        .iter()
        .filter(|p| p.tau >= tau_lo_s && p.tau <= tau_hi_s && p.dev > 0.0)
        .map(|p| model_avar(p.tau).sqrt() / p.dev - 1.0)
        .collect()
}

//! Replicate logs of one sensor: do the runs agree, and what is the best model of them
//! all?
//!
//! Each run has its own Allan curves and fitted noise model (IEEE Std 952-1997 terms with
//! confidence intervals). [`compare_replicates`] matches the runs' channels by name and,
//! per channel and term:
//!
//! * **homogeneity** — Cochran's Q on the log of the per-run estimates (Cochran 1954,
//!   *Biometrics* 10:101–129): with y_i = ln v_i and standard error s_i read off each
//!   run's interval, s_i = (ln hi_i − ln lo_i)/(2 z), z = Φ⁻¹((1 + c)/2) at the fit's
//!   confidence c, weights w_i = 1/s_i², ȳ = Σ w_i y_i / Σ w_i,
//!   Q = Σ w_i (y_i − ȳ)², which is χ²-distributed with k − 1 degrees of freedom when the
//!   k runs share one true value; p = P(χ²_{k−1} ≥ Q). The log makes the scale factors of
//!   the terms comparable and their intervals (χ²-based, asymmetric) nearly symmetric.
//! * **pooled value** — the random-effects inverse-variance mean (DerSimonian & Laird
//!   1986, *Controlled Clinical Trials* 7:177–188): between-run variance
//!   τ² = max(0, (Q − (k − 1)) / (Σ w − Σ w² / Σ w)), weights w*_i = 1/(s_i² + τ²),
//!   μ* = Σ w*_i y_i / Σ w*_i, se* = 1/√Σ w*_i, pooled = e^{μ*} with interval
//!   e^{μ* ± z·se*}. When the runs agree (τ² = 0) this is the fixed-effect mean; when
//!   they disagree the interval widens by the between-run spread instead of claiming the
//!   precision of one long run. I² = max(0, (Q − (k − 1))/Q) (Higgins & Thompson 2002,
//!   *Statistics in Medicine* 21:1539–1558) is the share of the spread beyond chance.
//! * **spread** — min and max across runs, and (max − min)/mean.
//! * **cross-run check** — each run's model against every other run's measured curve:
//!   the worst |σ_model(τ)/σ_curve(τ) − 1| over 0.2 s ≤ τ ≤ 30 s, narrowed to the
//!   model's fit range.
//!
//! It also fits a **joint model** to the runs' Allan variances combined per τ. For
//! independent runs of one process each run's σ̂²_i(τ) is distributed as
//! σ²(τ)·χ²_{ν_i}/ν_i (ν_i its equivalent degrees of freedom, EDF), so
//! Σ ν_i σ̂²_i / σ² ~ χ²_{Σν_i}: the EDF-weighted mean σ̂² = Σ ν_i σ̂²_i / Σ ν_i is unbiased,
//! is itself σ²·χ²_ν/ν with ν = Σ ν_i, and — since Var σ̂²_i = 2σ⁴/ν_i — it is the
//! minimum-variance (inverse-variance) combination (NIST SP 1065 §5.3: the χ² model of the
//! variance estimates; the same argument pools the gap-separated segments of one log).
//! The joint curve is fitted with [`NoiseModel::from_curves_with`]; its EDFs add over the
//! runs' segments. Without a user range each channel is fitted over the τ range all the
//! runs' automatic fits accepted (latest start, earliest end). Where the runs disagree on a term, the joint model's interval for
//! that term is widened to cover the random-effects interval.

use serde::{Deserialize, Serialize};

use super::analysis::ChannelResult;
use super::ci;
use super::fit::{
    FitConfig, FitRangeSpec, MODEL_ERROR_FLOOR, NoiseFit, RangeSource, Term, TermKind,
};
use super::noise_model::{
    ModelOptions, NoiseModel, Quantity, display_terms, display_units, fmt_num, si_term_units,
    term_label,
};
use super::{AllanError, DevPoint};

/// The terms compared, in model order.
const TERMS: [TermKind; 6] = [
    TermKind::Quantization,
    TermKind::White,
    TermKind::BiasInstability,
    TermKind::RateRandomWalk,
    TermKind::RateRamp,
    TermKind::GaussMarkov,
];

/// Default level of the homogeneity test: the runs are said to disagree when p < 0.01.
pub const DEFAULT_LEVEL: f64 = 0.01;

/// Default τ span of the cross-run check, s: where white noise and the flicker floor of
/// a MEMS IMU show and a model of one run should predict another run's curve.
pub const CROSS_CHECK_TAU_S: (f64, f64) = (0.2, 30.0);

/// Largest relative difference of the runs' sample intervals taken as one sample rate
/// (timestamps of real logs give slightly different estimates of one nominal rate).
pub const SAMPLE_RATE_TOLERANCE: f64 = 1e-3;

/// One run: its name (file), the OADEV curves its noise model was fitted to and that
/// model.
#[derive(Clone, Copy, Debug)]
pub struct ReplicateRun<'a> {
    /// Name of the run (its file), used in messages and the report.
    pub source: &'a str,
    /// The curves the model was fitted to (OADEV family), one per channel.
    pub curves: &'a [ChannelResult],
    /// The run's fitted model (a channel per curve, matched by name).
    pub model: &'a NoiseModel,
    /// Resolution step of each curve's rate samples (same order as `curves`; may be
    /// empty), for the joint model's quantization check ([`ModelOptions::resolution`]).
    pub resolution: &'a [Option<f64>],
}

/// How the runs are compared and the joint model fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplicateOptions {
    /// Terms of the joint fit (the runs' fits should use the same).
    pub fit: FitConfig,
    /// User fit range of the joint fit; None: automatic, as for one run.
    pub fit_range: Option<FitRangeSpec>,
    /// Relative model-error floor of the joint fit's weights.
    pub model_error_floor: f64,
    /// Level of the homogeneity test (runs disagree when p < level).
    pub level: f64,
    /// τ span of the cross-run check, s.
    pub cross_check_tau_s: (f64, f64),
}

impl Default for ReplicateOptions {
    fn default() -> Self {
        ReplicateOptions {
            fit: FitConfig::default(),
            fit_range: None,
            model_error_floor: MODEL_ERROR_FLOOR,
            level: DEFAULT_LEVEL,
            cross_check_tau_s: CROSS_CHECK_TAU_S,
        }
    }
}

/// Errors of the replicate comparison.
#[derive(Debug, thiserror::Error)]
pub enum ReplicateError {
    /// Fewer than two runs.
    #[error("comparing replicates needs at least 2 runs, got {0}")]
    TooFewRuns(usize),
    /// Two runs are not logs of the same channels at the same rate.
    #[error("{first} and {other} are not replicates of one sensor: {what}")]
    Mismatch {
        /// The first run.
        first: String,
        /// The run that differs from it.
        other: String,
        /// What differs.
        what: String,
    },
    /// A run whose curves and model do not belong together.
    #[error("{run}: {what}")]
    Incomplete {
        /// The run.
        run: String,
        /// What is missing.
        what: String,
    },
    /// The joint fit failed.
    #[error("joint model of {runs}: {source}")]
    JointFit {
        /// The runs, comma-separated.
        runs: String,
        /// Cause.
        source: AllanError,
    },
    /// An unusable option.
    #[error("{0}")]
    Invalid(String),
}

/// Fixed- and random-effects combination of k estimates with their standard errors
/// (see the module doc for the equations).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetaAnalysis {
    /// Cochran's Q.
    pub q: f64,
    /// Degrees of freedom, k − 1.
    pub df: usize,
    /// P(χ²_df ≥ Q).
    pub p_value: f64,
    /// DerSimonian–Laird between-run variance τ² (in the units of the estimates squared).
    pub tau2: f64,
    /// I² = max(0, (Q − df)/Q).
    pub i2: f64,
    /// Fixed-effect (inverse-variance) mean.
    pub fixed_mean: f64,
    /// Its standard error.
    pub fixed_se: f64,
    /// Random-effects mean.
    pub random_mean: f64,
    /// Its standard error.
    pub random_se: f64,
}

/// Cochran's Q and the DerSimonian–Laird random-effects mean of estimates `y` with
/// standard errors `se` (module doc). None with fewer than two estimates, unequal
/// lengths, or a non-finite estimate or non-positive standard error.
pub fn cochran_dersimonian_laird(y: &[f64], se: &[f64]) -> Option<MetaAnalysis> {
    let k = y.len();
    if k < 2
        || se.len() != k
        || y.iter().any(|v| !v.is_finite())
        || se.iter().any(|s| !(s.is_finite() && *s > 0.0))
    {
        return None;
    }
    let w: Vec<f64> = se.iter().map(|s| 1.0 / (s * s)).collect();
    let sw: f64 = w.iter().sum();
    let sw2: f64 = w.iter().map(|v| v * v).sum();
    let fixed = w.iter().zip(y).map(|(w, y)| w * y).sum::<f64>() / sw;
    let q: f64 = w.iter().zip(y).map(|(w, y)| w * (y - fixed).powi(2)).sum();
    let df = k - 1;
    let p_value = ci::chi2::gamma_pq(0.5 * df as f64, 0.5 * q).1;
    let c = sw - sw2 / sw;
    let tau2 = if c > 0.0 {
        ((q - df as f64) / c).max(0.0)
    } else {
        0.0
    };
    let i2 = if q > 0.0 {
        ((q - df as f64) / q).max(0.0)
    } else {
        0.0
    };
    let ws: Vec<f64> = se.iter().map(|s| 1.0 / (s * s + tau2)).collect();
    let sws: f64 = ws.iter().sum();
    let random = ws.iter().zip(y).map(|(w, y)| w * y).sum::<f64>() / sws;
    Some(MetaAnalysis {
        q,
        df,
        p_value,
        tau2,
        i2,
        fixed_mean: fixed,
        fixed_se: 1.0 / sw.sqrt(),
        random_mean: random,
        random_se: 1.0 / sws.sqrt(),
    })
}

/// Standard error of ln(value) from a two-sided interval [lo, hi] at confidence `cl`:
/// (ln hi − ln lo)/(2 z), z = Φ⁻¹((1 + cl)/2). None when the interval does not bound a
/// positive value.
pub fn log_standard_error(t: &Term, cl: f64) -> Option<f64> {
    let z = super::fit::normal_quantile(0.5 + 0.5 * cl);
    let ok = t.lo > 0.0 && t.hi.is_finite() && t.hi > t.lo && z.is_finite() && z > 0.0;
    ok.then(|| (t.hi.ln() - t.lo.ln()) / (2.0 * z))
}

/// One run's estimate of a term.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunEstimate {
    /// Detected: value with its interval (SI).
    Value(Term),
    /// Fitted but not detected: upper limit (SI).
    UpperLimit(f64),
    /// Not fitted in this run.
    Absent,
}

/// Spread of the runs' values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Smallest run value (SI).
    pub min: f64,
    /// Largest run value (SI).
    pub max: f64,
    /// (max − min)/mean of the run values.
    pub relative: f64,
}

/// One term across the runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TermComparison {
    /// Which term (Gauss-Markov: its σ).
    pub term: TermKind,
    /// Each run's estimate, in run order.
    pub runs: Vec<RunEstimate>,
    /// Cochran's Q and the random-effects combination on ln(value); None unless every
    /// run detected the term with a finite interval.
    pub test: Option<MetaAnalysis>,
    /// Whether the runs agree at the test level (None: not tested).
    pub consistent: Option<bool>,
    /// "consistent (p = …)", "the runs disagree (p = …)" or why it was not tested.
    pub verdict: String,
    /// Random-effects pooled value with its interval at the fit's confidence (SI).
    pub pooled: Option<Term>,
    /// Fixed-effect (inverse-variance) pooled value (SI).
    pub fixed_effect: Option<f64>,
    /// Spread of the runs' values (None unless at least two runs detected the term).
    pub spread: Option<Spread>,
    /// The joint model's value of the term, after widening (SI).
    pub joint: Option<Term>,
    /// Whether the joint model's interval was widened to the random-effects one.
    pub joint_widened: bool,
}

/// One run's model against another run's curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossCheck {
    /// Run whose model is used (index into [`Replicates::runs`]).
    pub model_run: usize,
    /// Run whose measured curve it is compared with.
    pub curve_run: usize,
    /// τ span compared, s.
    pub tau_min_s: f64,
    /// τ span compared, s.
    pub tau_max_s: f64,
    /// Worst |σ_model/σ_curve − 1| over the span.
    pub worst: f64,
    /// τ of the worst point, s.
    pub at_tau_s: f64,
}

/// One channel across the runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplicateChannel {
    /// Channel name.
    pub name: String,
    /// Physical quantity.
    pub quantity: Quantity,
    /// SI unit of the rate samples.
    pub unit: String,
    /// Each term fitted in at least one run.
    pub terms: Vec<TermComparison>,
    /// Each ordered pair of runs (model of one, curve of the other) with a common span.
    pub cross_checks: Vec<CrossCheck>,
    /// Largest [`CrossCheck::worst`].
    pub worst_cross_check: Option<f64>,
}

/// Result of [`compare_replicates`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Replicates {
    /// The runs, in the order given.
    pub runs: Vec<String>,
    /// Level of the homogeneity test.
    pub level: f64,
    /// Confidence of the intervals (the runs' fits').
    pub confidence: f64,
    /// Per channel, in the first run's order.
    pub channels: Vec<ReplicateChannel>,
    /// The model fitted to the combined curves, intervals widened where the runs disagree.
    pub joint: NoiseModel,
    /// The combined curves the joint model was fitted to (not serialised: large, and the
    /// CLI writes them as its top-level curves).
    #[serde(skip)]
    pub joint_curves: Vec<ChannelResult>,
}

fn term_mut(fit: &mut NoiseFit, kind: TermKind) -> Option<&mut Term> {
    match kind {
        TermKind::Quantization => fit.quantization.as_mut(),
        TermKind::White => fit.white.as_mut(),
        TermKind::BiasInstability => fit.bias_instability.as_mut(),
        TermKind::RateRandomWalk => fit.rate_random_walk.as_mut(),
        TermKind::RateRamp => fit.rate_ramp.as_mut(),
        TermKind::GaussMarkov => fit.gauss_markov.as_mut().map(|g| &mut g.sigma),
    }
}

fn estimate(fit: &NoiseFit, kind: TermKind) -> RunEstimate {
    if let Some(t) = fit.term(kind) {
        RunEstimate::Value(t)
    } else if let Some(u) = fit.not_detected.iter().find(|u| u.term == kind) {
        RunEstimate::UpperLimit(u.upper)
    } else {
        RunEstimate::Absent
    }
}

/// A curve's (σ², EDF, lag-1 ACF, n) at averaging factor `m`: its own point when it has
/// one, else interpolated log-log (ACF: linearly in ln m) between the neighbouring
/// points. None outside the curve.
fn sample_at(c: &ChannelResult, m: usize) -> Option<(f64, f64, f64, usize)> {
    let i = c.points.iter().position(|p| p.m >= m)?;
    let at = |j: usize| {
        let p: &DevPoint = &c.points[j];
        (
            p.dev * p.dev,
            c.edf.get(j).copied().unwrap_or(0.0),
            c.rate_acf1.get(j).copied().unwrap_or(f64::NAN),
            p.n,
        )
    };
    if c.points[i].m == m {
        return Some(at(i));
    }
    if i == 0 {
        return None;
    }
    let (a, b) = (at(i - 1), at(i));
    let (ma, mb) = (c.points[i - 1].m as f64, c.points[i].m as f64);
    let u = (m as f64 / ma).ln() / (mb / ma).ln();
    let logi = |x: f64, y: f64| {
        if x > 0.0 && y > 0.0 {
            (x.ln() + u * (y.ln() - x.ln())).exp()
        } else {
            x + u * (y - x)
        }
    };
    Some((logi(a.0, b.0), logi(a.1, b.1), a.2 + u * (b.2 - a.2), a.3))
}

/// The runs' curves of one channel combined per τ: EDF-weighted mean of σ², EDFs summed
/// (module doc). The grid is the shortest run's (its longest τ lies inside every run);
/// the other runs are read at its factors, interpolated where their grid differs. The
/// segments of all runs are kept so that [`ChannelResult::edf_for_alpha`] sums their
/// EDFs.
pub fn combine_curves(curves: &[&ChannelResult]) -> Option<ChannelResult> {
    let reference = curves
        .iter()
        .min_by(|a, b| {
            let end = |c: &ChannelResult| c.points.last().map_or(0, |p| p.m);
            end(a).cmp(&end(b))
        })
        .copied()?;
    let mut points = Vec::with_capacity(reference.points.len());
    let (mut lo, mut hi, mut alpha, mut edf, mut acf) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    'points: for (i, p) in reference.points.iter().enumerate() {
        let (mut sw, mut swv, mut sv, mut n) = (0.0, 0.0, 0.0, 0usize);
        let (mut acf_sum, mut acf_n) = (0.0, 0usize);
        for c in curves {
            let Some((v, nu, r, ni)) = sample_at(c, p.m) else {
                continue 'points;
            };
            if nu.is_finite() && nu > 0.0 {
                sw += nu;
                swv += nu * v;
            }
            sv += v;
            n += ni;
            if r.is_finite() {
                acf_sum += r;
                acf_n += 1;
            }
        }
        let avar = if sw > 0.0 {
            swv / sw
        } else {
            sv / curves.len() as f64
        };
        let dev = avar.sqrt();
        let (l, h) = if sw > 0.0 {
            ci::bounds(dev, sw, reference.confidence)
        } else {
            (0.0, f64::INFINITY)
        };
        points.push(DevPoint {
            m: p.m,
            tau: p.tau,
            n,
            dev,
        });
        lo.push(l);
        hi.push(h);
        alpha.push(reference.alpha.get(i).copied().unwrap_or(0));
        edf.push(sw);
        acf.push(if acf_n > 0 {
            acf_sum / acf_n as f64
        } else {
            f64::NAN
        });
    }
    Some(ChannelResult {
        name: reference.name.clone(),
        estimator: reference.estimator,
        tau0_s: reference.tau0_s,
        points,
        dev_lo: lo,
        dev_hi: hi,
        alpha,
        edf,
        confidence: reference.confidence,
        segment_phase_points: curves
            .iter()
            .flat_map(|c| c.segment_phase_points.iter().copied())
            .collect(),
        fast: reference.fast,
        rate_acf1: acf,
    })
}

/// Worst |σ_model/σ_curve − 1| of `fit` on `curve` over `span` ∩ the fit's range.
fn cross_check(
    fit: &NoiseFit,
    curve: &ChannelResult,
    span: (f64, f64),
) -> Option<(f64, f64, f64, f64)> {
    let (mut lo, mut hi) = span;
    if let Some(r) = &fit.fit_range {
        lo = lo.max(r.tau_min_s);
        hi = hi.min(r.tau_max_s);
    }
    let tol = 1e-9;
    let mut worst: Option<(f64, f64)> = None;
    for p in &curve.points {
        if p.tau < lo * (1.0 - tol)
            || p.tau > hi * (1.0 + tol)
            || p.dev.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            continue;
        }
        let d = (fit.model_avar(p.tau).sqrt() / p.dev - 1.0).abs();
        if d.is_finite() && worst.is_none_or(|(w, _)| d > w) {
            worst = Some((d, p.tau));
        }
    }
    worst.map(|(w, t)| (lo, hi, w, t))
}

fn fmt_p(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.3}")
    } else {
        format!("{p:.1e}")
    }
}

/// What two runs must share to be replicates: channels (name, quantity) and the sample
/// interval. Known once the logs are read, before any analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct RunShape<'a> {
    /// Name of the run (its file).
    pub source: &'a str,
    /// The analysed channels: name and quantity.
    pub channels: Vec<(&'a str, Quantity)>,
    /// Sample interval, s.
    pub tau0_s: f64,
}

/// Whether `other` can be a replicate of `first`: the same channel names (any order) with
/// the same quantities and sample rates within [`SAMPLE_RATE_TOLERANCE`]. The error names
/// both runs and what differs.
pub fn check_same_sensor(first: &RunShape<'_>, other: &RunShape<'_>) -> Result<(), ReplicateError> {
    let mismatch = |what: String| ReplicateError::Mismatch {
        first: first.source.into(),
        other: other.source.into(),
        what,
    };
    fn only<'x>(a: &RunShape<'x>, b: &RunShape<'_>) -> Vec<&'x str> {
        let mut v: Vec<&'x str> = a
            .channels
            .iter()
            .map(|(n, _)| *n)
            .filter(|n| !b.channels.iter().any(|(c, _)| c == n))
            .collect();
        v.sort_unstable();
        v
    }
    let (only_a, only_b) = (only(first, other), only(other, first));
    if !only_a.is_empty() || !only_b.is_empty() || first.channels.len() != other.channels.len() {
        let mut parts = Vec::new();
        if !only_a.is_empty() {
            parts.push(format!("only {} has {}", first.source, only_a.join(", ")));
        }
        if !only_b.is_empty() {
            parts.push(format!("only {} has {}", other.source, only_b.join(", ")));
        }
        if parts.is_empty() {
            parts.push(format!(
                "{} vs {} channels",
                first.channels.len(),
                other.channels.len()
            ));
        }
        return Err(mismatch(format!(
            "the channels differ ({})",
            parts.join("; ")
        )));
    }
    for (n, qa) in &first.channels {
        if let Some((_, qb)) = other.channels.iter().find(|(m, _)| m == n)
            && qa != qb
        {
            return Err(mismatch(format!(
                "channel '{n}' is {qa:?} in one and {qb:?} in the other"
            )));
        }
    }
    if !(first.tau0_s > 0.0 && other.tau0_s > 0.0)
        || (other.tau0_s / first.tau0_s - 1.0).abs() > SAMPLE_RATE_TOLERANCE
    {
        return Err(mismatch(format!(
            "the sample rates differ ({} Hz vs {} Hz)",
            fmt_num(1.0 / first.tau0_s),
            fmt_num(1.0 / other.tau0_s)
        )));
    }
    Ok(())
}

/// Compare replicate runs of one sensor and fit their joint model (module doc).
///
/// Channels are matched by name; the runs must have the same channels with the same
/// quantities, the same estimator and confidence, and sample rates within
/// [`SAMPLE_RATE_TOLERANCE`] — otherwise the error names both files and what differs.
pub fn compare_replicates<'a>(
    runs: &[ReplicateRun<'a>],
    opts: &ReplicateOptions,
) -> Result<Replicates, ReplicateError> {
    let [first, rest @ ..] = runs else {
        return Err(ReplicateError::TooFewRuns(0));
    };
    if rest.is_empty() {
        return Err(ReplicateError::TooFewRuns(1));
    }
    if !(opts.level > 0.0 && opts.level < 1.0) {
        return Err(ReplicateError::Invalid(format!(
            "the homogeneity test level must be between 0 and 1, got {}",
            opts.level
        )));
    }
    // Each run's curves must have model channels.
    for r in runs {
        if r.curves.is_empty() {
            return Err(ReplicateError::Incomplete {
                run: r.source.into(),
                what: "no channel curves".into(),
            });
        }
        for c in r.curves {
            if r.model.channel(&c.name).is_none() {
                return Err(ReplicateError::Incomplete {
                    run: r.source.into(),
                    what: format!("channel '{}' has a curve but no fitted model", c.name),
                });
            }
        }
    }
    let shape = |r: &ReplicateRun<'a>| RunShape {
        source: r.source,
        channels: r
            .curves
            .iter()
            .map(|c| {
                let q = r
                    .model
                    .channel(&c.name)
                    .map_or(Quantity::Other, |m| m.quantity);
                (c.name.as_str(), q)
            })
            .collect(),
        tau0_s: r.curves[0].tau0_s,
    };
    let first_shape = shape(first);
    let c0 = &first.curves[0];
    for r in rest {
        let mismatch = |what: String| ReplicateError::Mismatch {
            first: first.source.into(),
            other: r.source.into(),
            what,
        };
        check_same_sensor(&first_shape, &shape(r))?;
        for c in r.curves {
            let Some(f) = first.curves.iter().find(|f| f.name == c.name) else {
                continue;
            };
            if (c.tau0_s / f.tau0_s - 1.0).abs() > SAMPLE_RATE_TOLERANCE {
                return Err(mismatch(format!(
                    "channel '{}': the sample rates differ ({} Hz vs {} Hz)",
                    c.name,
                    fmt_num(1.0 / f.tau0_s),
                    fmt_num(1.0 / c.tau0_s)
                )));
            }
            if c.estimator != f.estimator || c.fast != f.fast {
                return Err(mismatch(format!(
                    "channel '{}': the curves come from different estimators",
                    c.name
                )));
            }
            if (c.confidence - f.confidence).abs() > 1e-12 {
                return Err(mismatch(format!(
                    "the confidence levels differ ({} vs {})",
                    f.confidence, c.confidence
                )));
            }
        }
    }

    let confidence = first
        .model
        .channels
        .first()
        .map_or(c0.confidence, |c| c.fit.confidence);
    let run_names: Vec<String> = runs.iter().map(|r| r.source.to_string()).collect();

    // Joint curves and model.
    let mut joint_curves = Vec::with_capacity(first.curves.len());
    let mut quantities = Vec::with_capacity(first.curves.len());
    let mut resolution = Vec::with_capacity(first.curves.len());
    for c in first.curves {
        let per_run: Vec<&ChannelResult> = runs
            .iter()
            .filter_map(|r| r.curves.iter().find(|x| x.name == c.name))
            .collect();
        let joint = combine_curves(&per_run).ok_or_else(|| ReplicateError::Incomplete {
            run: first.source.into(),
            what: format!("channel '{}': no curve to combine", c.name),
        })?;
        joint_curves.push(joint);
        quantities.push(
            first
                .model
                .channel(&c.name)
                .map_or(Quantity::Other, |m| m.quantity),
        );
        // The most lenient step of the runs (any run without one: no check).
        let steps: Vec<Option<f64>> = runs
            .iter()
            .map(|r| {
                r.curves
                    .iter()
                    .position(|x| x.name == c.name)
                    .and_then(|j| r.resolution.get(j).copied().flatten())
            })
            .collect();
        resolution.push(if steps.iter().all(Option::is_some) {
            steps.into_iter().flatten().reduce(f64::max)
        } else {
            None
        });
    }
    let joined = run_names.join(", ");
    // Each channel over the τ range every run's automatic choice accepted (the latest
    // start, the earliest end): where the sensor's own filtering colours the noise is a
    // property of the sensor, and the summed EDF of the joint curve would otherwise make
    // the automatic choice read the small differences between the runs as misfit.
    let mut joint = NoiseModel::new(
        Some(format!("joint of {joined}")),
        1.0 / c0.tau0_s,
        Some(c0.estimator.name().to_string()),
    );
    for ((jc, &q), step) in joint_curves.iter().zip(&quantities).zip(&resolution) {
        let ranges: Option<Vec<_>> = runs
            .iter()
            .map(|r| r.model.channel(&jc.name).and_then(|m| m.fit.fit_range))
            .collect();
        let runs_range = match (opts.fit_range, ranges) {
            (None, Some(rs)) if !rs.is_empty() => Some(FitRangeSpec {
                tau_min_s: rs.iter().map(|r| r.tau_min_s).reduce(f64::max),
                tau_max_s: rs.iter().map(|r| r.tau_max_s).reduce(f64::min),
            })
            .filter(|r| r.tau_min_s <= r.tau_max_s),
            _ => None,
        };
        let model_opts = ModelOptions {
            fit_range: opts.fit_range.or(runs_range),
            resolution: vec![*step],
            model_error_floor: opts.model_error_floor,
        };
        let one = NoiseModel::from_curves_with(
            &format!("joint of {joined}"),
            std::slice::from_ref(jc),
            &[q],
            &opts.fit,
            confidence,
            &model_opts,
        )
        .map_err(|e| ReplicateError::JointFit {
            runs: joined.clone(),
            source: e,
        })?;
        for mut ch in one.channels {
            if runs_range.is_some()
                && let Some(r) = ch.fit.fit_range.as_mut()
            {
                r.source = RangeSource::Auto;
            }
            joint.channels.push(ch);
        }
    }

    let z = super::fit::normal_quantile(0.5 + 0.5 * confidence);
    let mut channels = Vec::with_capacity(first.curves.len());
    for (ci_, c) in first.curves.iter().enumerate() {
        let fits: Vec<&NoiseFit> = runs
            .iter()
            .filter_map(|r| r.model.channel(&c.name).map(|m| &m.fit))
            .collect();
        let joint_ch = &mut joint.channels[ci_];
        let mut terms = Vec::new();
        for kind in TERMS {
            let ests: Vec<RunEstimate> = fits.iter().map(|f| estimate(f, kind)).collect();
            let values: Vec<Term> = ests
                .iter()
                .filter_map(|e| match e {
                    RunEstimate::Value(t) => Some(*t),
                    _ => None,
                })
                .collect();
            if values.is_empty() {
                continue;
            }
            let spread = (values.len() >= 2).then(|| {
                let min = values.iter().map(|t| t.value).fold(f64::INFINITY, f64::min);
                let max = values.iter().map(|t| t.value).fold(0.0, f64::max);
                let mean = values.iter().map(|t| t.value).sum::<f64>() / values.len() as f64;
                Spread {
                    min,
                    max,
                    relative: if mean > 0.0 { (max - min) / mean } else { 0.0 },
                }
            });
            let (mut test, mut verdict) = (None, String::new());
            if values.len() < ests.len() {
                verdict = format!(
                    "not tested: detected in {} of {} runs",
                    values.len(),
                    ests.len()
                );
            } else {
                let y: Vec<f64> = values.iter().map(|t| t.value.ln()).collect();
                let se: Option<Vec<f64>> = values
                    .iter()
                    .map(|t| log_standard_error(t, confidence))
                    .collect();
                match se.and_then(|se| cochran_dersimonian_laird(&y, &se)) {
                    Some(m) => test = Some(m),
                    None => verdict = "not tested: an interval does not bound the value".into(),
                }
            }
            let consistent = test.map(|m| m.p_value >= opts.level);
            if let Some(m) = &test {
                verdict = if m.p_value >= opts.level {
                    format!("consistent (p = {})", fmt_p(m.p_value))
                } else {
                    format!("the runs disagree (p = {})", fmt_p(m.p_value))
                };
            }
            let pooled = test.map(|m| Term {
                value: m.random_mean.exp(),
                lo: (m.random_mean - z * m.random_se).exp(),
                hi: (m.random_mean + z * m.random_se).exp(),
            });
            let mut joint_widened = false;
            if let (Some(false), Some(p), Some(t)) =
                (consistent, pooled, term_mut(&mut joint_ch.fit, kind))
            {
                if p.lo < t.lo {
                    t.lo = p.lo;
                    joint_widened = true;
                }
                if p.hi > t.hi {
                    t.hi = p.hi;
                    joint_widened = true;
                }
            }
            terms.push(TermComparison {
                term: kind,
                runs: ests,
                test,
                consistent,
                verdict,
                pooled,
                fixed_effect: test.map(|m| m.fixed_mean.exp()),
                spread,
                joint: joint_ch.fit.term(kind),
                joint_widened,
            });
        }
        joint_ch.display = display_terms(&joint_ch.fit, joint_ch.quantity);
        let mut cross_checks = Vec::new();
        for (i, ri) in runs.iter().enumerate() {
            let Some(fit) = ri.model.channel(&c.name).map(|m| &m.fit) else {
                continue;
            };
            for (j, rj) in runs.iter().enumerate() {
                if i == j {
                    continue;
                }
                let Some(curve) = rj.curves.iter().find(|x| x.name == c.name) else {
                    continue;
                };
                if let Some((lo, hi, worst, at)) = cross_check(fit, curve, opts.cross_check_tau_s) {
                    cross_checks.push(CrossCheck {
                        model_run: i,
                        curve_run: j,
                        tau_min_s: lo,
                        tau_max_s: hi,
                        worst,
                        at_tau_s: at,
                    });
                }
            }
        }
        let worst_cross_check = cross_checks.iter().map(|x| x.worst).reduce(f64::max);
        channels.push(ReplicateChannel {
            name: c.name.clone(),
            quantity: joint_ch.quantity,
            unit: joint_ch.unit.clone(),
            terms,
            cross_checks,
            worst_cross_check,
        });
    }
    Ok(Replicates {
        runs: run_names,
        level: opts.level,
        confidence,
        channels,
        joint,
        joint_curves,
    })
}

impl Replicates {
    /// One warning per term on which the runs disagree, with the runs' range.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in &self.channels {
            for t in &c.terms {
                if t.consistent == Some(false) {
                    let (unit, size) = unit_of(c, t.term);
                    let range = t.spread.map_or(String::new(), |s| {
                        format!(
                            ": {} … {} {unit} across the runs",
                            fmt_num(s.min / size),
                            fmt_num(s.max / size)
                        )
                    });
                    out.push(format!(
                        "{}: {}: {}{range}; the pooled and joint intervals include the \
                         between-run spread",
                        c.name,
                        term_label(t.term),
                        t.verdict
                    ));
                }
            }
        }
        out
    }

    /// Human-readable report: per channel a table of term, each run's value, pooled
    /// value [lo, hi], spread and verdict, then the cross-run check.
    pub fn human_table(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "Replicates: {} runs of one sensor. Test: Cochran's Q on ln(value), runs disagree \
             when p < {}; pooled: random-effects (DerSimonian–Laird) mean, {:.1} % interval.\n",
            self.runs.len(),
            self.level,
            100.0 * self.confidence
        ));
        for (i, r) in self.runs.iter().enumerate() {
            s.push_str(&format!("  run {}: {r}\n", i + 1));
        }
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
            let mut header = format!("  {:<18}", "term");
            for i in 0..self.runs.len() {
                header.push_str(&format!(" {:>11}", format!("run {}", i + 1)));
            }
            header.push_str(&format!(
                " {:>35} {:>8}  {:<14} {}\n",
                "pooled [lo, hi]", "spread", "unit", "test"
            ));
            s.push_str(&header);
            for t in &c.terms {
                let (unit, size) = unit_of(c, t.term);
                let mut row = format!("  {:<18}", term_label(t.term));
                for e in &t.runs {
                    let cell = match e {
                        RunEstimate::Value(v) => fmt_num(v.value / size),
                        RunEstimate::UpperLimit(u) => format!("< {}", fmt_num(u / size)),
                        RunEstimate::Absent => "-".into(),
                    };
                    row.push_str(&format!(" {cell:>11}"));
                }
                let pooled = t.pooled.map_or("-".to_string(), |p| {
                    format!(
                        "{} [{}, {}]",
                        fmt_num(p.value / size),
                        fmt_num(p.lo / size),
                        fmt_num(p.hi / size)
                    )
                });
                let spread = t.spread.map_or("-".to_string(), |sp| {
                    format!("{:.1} %", 100.0 * sp.relative)
                });
                row.push_str(&format!(
                    " {pooled:>35} {spread:>8}  {unit:<14} {}\n",
                    t.verdict
                ));
                s.push_str(&row);
            }
            if let Some(w) = c
                .cross_checks
                .iter()
                .max_by(|a, b| a.worst.total_cmp(&b.worst))
            {
                s.push_str(&format!(
                    "  cross-run check: worst |model/curve − 1| = {:.1} % (run {}'s model on \
                     run {}'s curve at τ = {} s; span {} … {} s, every pair of runs)\n",
                    100.0 * w.worst,
                    w.model_run + 1,
                    w.curve_run + 1,
                    fmt_num(w.at_tau_s),
                    fmt_num(w.tau_min_s),
                    fmt_num(w.tau_max_s)
                ));
            }
        }
        s
    }
}

/// First display unit of a term for the channel's quantity: (name, size in SI).
fn unit_of(c: &ReplicateChannel, kind: TermKind) -> (String, f64) {
    match display_units(c.quantity, kind).first() {
        Some(&(u, size)) => (u.to_string(), size),
        None => (si_term_units(&c.unit)(kind), 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cochran's Q and the DerSimonian–Laird τ² on numbers worked by hand:
    /// y = (1, 2, 4), s = (1, 1, 2) → w = (1, 1, 0.25), Σw = 2.25,
    /// ȳ = (1 + 2 + 1)/2.25 = 16/9, Q = (7/9)² + (2/9)² + 0.25·(20/9)² < df = 2.
    #[test]
    fn cochran_and_dersimonian_laird_closed_form() {
        let m = cochran_dersimonian_laird(&[1.0, 2.0, 4.0], &[1.0, 1.0, 2.0]).unwrap();
        assert!((m.fixed_mean - 16.0 / 9.0).abs() < 1e-12, "{m:?}");
        let q = (7.0f64 / 9.0).powi(2) + (2.0f64 / 9.0).powi(2) + 0.25 * (20.0f64 / 9.0).powi(2);
        assert!((m.q - q).abs() < 1e-12, "{} vs {q}", m.q);
        assert_eq!(m.df, 2);
        // Q < df: no between-run variance, random = fixed.
        assert_eq!(m.tau2, 0.0);
        assert_eq!(m.i2, 0.0);
        assert!((m.random_mean - m.fixed_mean).abs() < 1e-12);
        assert!((m.fixed_se - 1.0 / 2.25f64.sqrt()).abs() < 1e-12);
        // χ² with 2 dof: P(χ² ≥ Q) = e^{−Q/2}.
        assert!(
            (m.p_value - (-q / 2.0).exp()).abs() < 1e-12,
            "{}",
            m.p_value
        );

        // Two runs far apart: y = (0, 3), s = (0.5, 0.5): w = (4, 4), ȳ = 1.5,
        // Q = 4·2.25·2 = 18, df = 1, c = 8 − 32/8 = 4, τ² = (18 − 1)/4 = 4.25,
        // w* = 1/(0.25 + 4.25) = 2/9 each, μ* = 1.5, se* = 1/√(4/9) = 1.5.
        let m = cochran_dersimonian_laird(&[0.0, 3.0], &[0.5, 0.5]).unwrap();
        assert!((m.q - 18.0).abs() < 1e-12);
        assert!((m.tau2 - 4.25).abs() < 1e-12);
        assert!((m.random_mean - 1.5).abs() < 1e-12);
        assert!((m.random_se - 1.5).abs() < 1e-12);
        assert!((m.i2 - 17.0 / 18.0).abs() < 1e-12);
        // χ² with 1 dof: P(χ² ≥ 18) = erfc(√9) = erfc(3) = 2.209e-5.
        assert!(
            (m.p_value / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-6,
            "{}",
            m.p_value
        );
        // Unequal weights, Q > df: y = (0, 1, 3), s = (1, 0.5, 1): w = (1, 4, 1), Σw = 6,
        // ȳ = 7/6, Q = (7/6)² + 4(1/6)² + (11/6)² = 174/36, c = 6 − 18/6 = 3,
        // τ² = (174/36 − 2)/3 = 17/18.
        let m = cochran_dersimonian_laird(&[0.0, 1.0, 3.0], &[1.0, 0.5, 1.0]).unwrap();
        assert!((m.q - 174.0 / 36.0).abs() < 1e-12, "{}", m.q);
        assert!((m.tau2 - 17.0 / 18.0).abs() < 1e-12, "{}", m.tau2);
        let ws = [
            1.0 / (1.0 + 17.0 / 18.0),
            1.0 / (0.25 + 17.0 / 18.0),
            1.0 / (1.0 + 17.0 / 18.0),
        ];
        let mu = (ws[1] + 3.0 * ws[2]) / ws.iter().sum::<f64>();
        assert!((m.random_mean - mu).abs() < 1e-12);
    }

    #[test]
    fn identical_runs_pool_to_the_value() {
        let m = cochran_dersimonian_laird(&[0.7, 0.7, 0.7], &[0.1, 0.2, 0.3]).unwrap();
        assert_eq!(m.q, 0.0);
        assert_eq!(m.tau2, 0.0);
        assert_eq!(m.p_value, 1.0);
        assert!((m.random_mean - 0.7).abs() < 1e-15 && (m.fixed_mean - 0.7).abs() < 1e-15);
        assert!(cochran_dersimonian_laird(&[1.0], &[1.0]).is_none());
        assert!(cochran_dersimonian_laird(&[1.0, 2.0], &[1.0, 0.0]).is_none());
        assert!(cochran_dersimonian_laird(&[1.0, f64::NAN], &[1.0, 1.0]).is_none());
    }

    #[test]
    fn same_sensor_check_names_both_runs_and_what_differs() {
        let a = RunShape {
            source: "a.csv",
            channels: vec![
                ("gyro_x", Quantity::AngularRate),
                ("accel_x", Quantity::SpecificForce),
            ],
            tau0_s: 0.01,
        };
        // Same channels in another order, a rate within the tolerance: replicates.
        let b = RunShape {
            source: "b.csv",
            channels: vec![a.channels[1], a.channels[0]],
            tau0_s: 0.01 * (1.0 + 1e-4),
        };
        assert!(check_same_sensor(&a, &b).is_ok());
        let q = RunShape {
            channels: vec![
                ("gyro_x", Quantity::AngularRate),
                ("accel_x", Quantity::Other),
            ],
            ..b.clone()
        };
        let e = check_same_sensor(&a, &q).unwrap_err().to_string();
        assert!(
            e.contains("a.csv") && e.contains("b.csv") && e.contains("accel_x"),
            "{e}"
        );
        let r = RunShape {
            tau0_s: 0.005,
            ..b.clone()
        };
        let e = check_same_sensor(&a, &r).unwrap_err().to_string();
        assert!(e.contains("100.00 Hz vs 200.00 Hz"), "{e}");
        let c = RunShape {
            channels: vec![("gyro_x", Quantity::AngularRate)],
            ..b
        };
        let e = check_same_sensor(&a, &c).unwrap_err().to_string();
        assert!(e.contains("only a.csv has accel_x"), "{e}");
    }

    #[test]
    fn log_standard_error_from_interval() {
        // A ±1σ interval e^{±0.1} around 1 at 68.27 %: se = 0.1.
        let t = Term {
            value: 1.0,
            lo: (-0.1f64).exp(),
            hi: 0.1f64.exp(),
        };
        let cl = 2.0 * super::super::fit::normal_cdf(1.0) - 1.0;
        assert!((log_standard_error(&t, cl).unwrap() - 0.1).abs() < 1e-9);
        assert!(log_standard_error(&Term { lo: 0.0, ..t }, cl).is_none());
    }
}

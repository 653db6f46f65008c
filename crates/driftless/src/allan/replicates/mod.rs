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

use super::AllanError;
use super::analysis::ChannelResult;
use super::fit::{
    FitConfig, FitRangeSpec, MODEL_ERROR_FLOOR, NoiseFit, RangeSource, Term, TermKind,
    normal_quantile,
};
use super::noise_model::{ModelOptions, NoiseModel, Quantity, display_terms, fmt_num};

mod combine;
mod display;
mod meta;

pub use combine::combine_curves;
pub use meta::{MetaAnalysis, cochran_dersimonian_laird, log_standard_error};

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
pub(crate) const CROSS_CHECK_TAU_S: (f64, f64) = (0.2, 30.0);

/// Largest relative difference of the runs' sample intervals taken as one sample rate
/// (timestamps of real logs give slightly different estimates of one nominal rate).
pub(crate) const SAMPLE_RATE_TOLERANCE: f64 = 1e-3;

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

/// What two runs must share to be replicates: channels (name, quantity) and the sample
/// interval. Known once the logs are read, before any analysis.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RunShape<'a> {
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
pub(crate) fn check_same_sensor(
    first: &RunShape<'_>,
    other: &RunShape<'_>,
) -> Result<(), ReplicateError> {
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
/// `SAMPLE_RATE_TOLERANCE` — otherwise the error names both files and what differs.
pub fn compare_replicates(
    runs: &[ReplicateRun<'_>],
    opts: &ReplicateOptions,
) -> Result<Replicates, ReplicateError> {
    check_runs(runs, opts)?;
    let Some(first) = runs.first() else {
        return Err(ReplicateError::TooFewRuns(0));
    };
    let confidence = first
        .model
        .channels
        .first()
        .map_or(first.curves[0].confidence, |c| c.fit.confidence);
    let run_names: Vec<String> = runs.iter().map(|r| r.source.to_string()).collect();
    let (mut joint, joint_curves) = fit_joint(runs, opts, confidence, &run_names.join(", "))?;
    let mut channels = Vec::with_capacity(first.curves.len());
    for c in first.curves {
        let fits: Vec<&NoiseFit> = runs
            .iter()
            .filter_map(|r| r.model.channel(&c.name).map(|m| &m.fit))
            .collect();
        let joint_ch = joint
            .channels
            .iter_mut()
            .find(|j| j.name == c.name)
            .ok_or_else(|| ReplicateError::Incomplete {
                run: first.source.into(),
                what: format!("channel '{}': no joint model", c.name),
            })?;
        let terms: Vec<TermComparison> = TERMS
            .into_iter()
            .filter_map(|kind| compare_term(kind, &fits, &mut joint_ch.fit, confidence, opts.level))
            .collect();
        joint_ch.display = display_terms(&joint_ch.fit, joint_ch.quantity);
        let cross_checks = cross_checks(runs, &c.name, opts.cross_check_tau_s);
        channels.push(ReplicateChannel {
            name: c.name.clone(),
            quantity: joint_ch.quantity,
            unit: joint_ch.unit.clone(),
            terms,
            worst_cross_check: cross_checks.iter().map(|x| x.worst).reduce(f64::max),
            cross_checks,
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

/// At least two runs, a usable level, a model channel for every curve, and runs that are
/// replicates of the first (channels, quantities, rates, estimator, confidence).
fn check_runs(runs: &[ReplicateRun<'_>], opts: &ReplicateOptions) -> Result<(), ReplicateError> {
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
    fn shape<'x>(r: &ReplicateRun<'x>) -> RunShape<'x> {
        RunShape {
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
            tau0_s: r.curves.first().map_or(0.0, |c| c.tau0_s),
        }
    }
    let first_shape = shape(first);
    for r in rest {
        check_same_sensor(&first_shape, &shape(r))?;
        let mismatch = |what: String| ReplicateError::Mismatch {
            first: first.source.into(),
            other: r.source.into(),
            what,
        };
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
    Ok(())
}

/// The combined curves (first run's channel order) and the joint model fitted to them.
///
/// Each channel is fitted over the τ range every run's automatic choice accepted (the
/// latest start, the earliest end) unless the user gave one: where the sensor's own
/// filtering colours the noise is a property of the sensor, and the summed EDF of the
/// joint curve would otherwise make the automatic choice read the small differences
/// between the runs as misfit.
fn fit_joint(
    runs: &[ReplicateRun<'_>],
    opts: &ReplicateOptions,
    confidence: f64,
    joined: &str,
) -> Result<(NoiseModel, Vec<ChannelResult>), ReplicateError> {
    let Some(first) = runs.first() else {
        return Err(ReplicateError::TooFewRuns(0));
    };
    let c0 = &first.curves[0];
    let source = format!("joint of {joined}");
    let mut joint = NoiseModel::new(
        Some(source.clone()),
        1.0 / c0.tau0_s,
        Some(c0.estimator.name().to_string()),
    );
    let mut joint_curves = Vec::with_capacity(first.curves.len());
    for c in first.curves {
        let per_run: Vec<&ChannelResult> = runs
            .iter()
            .filter_map(|r| r.curves.iter().find(|x| x.name == c.name))
            .collect();
        let jc = combine_curves(&per_run).ok_or_else(|| ReplicateError::Incomplete {
            run: first.source.into(),
            what: format!("channel '{}': no curve to combine", c.name),
        })?;
        let q = first
            .model
            .channel(&c.name)
            .map_or(Quantity::Other, |m| m.quantity);
        // The most lenient resolution step of the runs (a run without one: no check).
        let steps: Option<Vec<f64>> = runs
            .iter()
            .map(|r| {
                r.curves
                    .iter()
                    .position(|x| x.name == c.name)
                    .and_then(|j| r.resolution.get(j).copied().flatten())
            })
            .collect();
        let ranges: Option<Vec<_>> = runs
            .iter()
            .map(|r| r.model.channel(&c.name).and_then(|m| m.fit.fit_range))
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
            resolution: vec![steps.and_then(|v| v.into_iter().reduce(f64::max))],
            model_error_floor: opts.model_error_floor,
            // The range is the runs' common one, whose ends their own fits chose.
            curve_precision: None,
        };
        // A Gauss-Markov term only where a run resolved one: the combined curve's larger
        // EDF would otherwise let the joint fit trade white noise for a correlated term no
        // run shows (on simulated runs of the IEEE terms alone its N was then further
        // from the truth than the worse run's in 6 of 20 pairs, against 3 without).
        let fit_cfg = FitConfig {
            gauss_markov: opts.fit.gauss_markov
                && runs.iter().any(|r| {
                    r.model
                        .channel(&c.name)
                        .is_some_and(|m| m.fit.gauss_markov.is_some())
                }),
            ..opts.fit
        };
        let one = NoiseModel::from_curves_with(
            &source,
            std::slice::from_ref(&jc),
            &[q],
            &fit_cfg,
            confidence,
            &model_opts,
        )
        .map_err(|e| ReplicateError::JointFit {
            runs: joined.to_string(),
            source: e,
        })?;
        for mut ch in one.channels {
            if runs_range.is_some()
                && let Some(r) = ch.fit.fit_range.as_mut()
            {
                r.source = if r.excluded_short == 0 && r.excluded_long == 0 {
                    RangeSource::Full
                } else {
                    RangeSource::Auto
                };
            }
            joint.channels.push(ch);
        }
        joint_curves.push(jc);
    }
    Ok((joint, joint_curves))
}

/// One term across the runs' fits: estimates, test, pooled value and spread; widens the
/// joint fit's interval of the term to the pooled one when the runs disagree. None when
/// no run detected the term.
fn compare_term(
    kind: TermKind,
    fits: &[&NoiseFit],
    joint: &mut NoiseFit,
    confidence: f64,
    level: f64,
) -> Option<TermComparison> {
    let ests: Vec<RunEstimate> = fits.iter().map(|f| estimate(f, kind)).collect();
    let values: Vec<Term> = ests
        .iter()
        .filter_map(|e| match e {
            RunEstimate::Value(t) => Some(*t),
            _ => None,
        })
        .collect();
    if values.is_empty() {
        return None;
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
    let test = if values.len() < ests.len() {
        None
    } else {
        let y: Vec<f64> = values.iter().map(|t| t.value.ln()).collect();
        let se: Option<Vec<f64>> = values
            .iter()
            .map(|t| log_standard_error(t, confidence))
            .collect();
        se.and_then(|se| cochran_dersimonian_laird(&y, &se))
    };
    let verdict = match &test {
        Some(m) if m.p_value >= level => format!("consistent (p = {})", display::fmt_p(m.p_value)),
        Some(m) => format!("the runs disagree (p = {})", display::fmt_p(m.p_value)),
        None if values.len() < ests.len() => format!(
            "not tested: detected in {} of {} runs",
            values.len(),
            ests.len()
        ),
        None => "not tested: an interval does not bound the value".into(),
    };
    let consistent = test.map(|m| m.p_value >= level);
    let z = normal_quantile(0.5 + 0.5 * confidence);
    let pooled = test.map(|m| Term {
        value: m.random_mean.exp(),
        lo: (m.random_mean - z * m.random_se).exp(),
        hi: (m.random_mean + z * m.random_se).exp(),
    });
    let mut joint_widened = false;
    if let (Some(false), Some(p), Some(t)) = (consistent, pooled, term_mut(joint, kind)) {
        if p.lo < t.lo {
            t.lo = p.lo;
            joint_widened = true;
        }
        if p.hi > t.hi {
            t.hi = p.hi;
            joint_widened = true;
        }
    }
    Some(TermComparison {
        term: kind,
        runs: ests,
        test,
        consistent,
        verdict,
        pooled,
        fixed_effect: test.map(|m| m.fixed_mean.exp()),
        spread,
        joint: joint.term(kind),
        joint_widened,
    })
}

/// Every ordered pair of runs: the model of one on the curve of the other.
fn cross_checks(runs: &[ReplicateRun<'_>], name: &str, span: (f64, f64)) -> Vec<CrossCheck> {
    let mut out = Vec::new();
    for (i, ri) in runs.iter().enumerate() {
        let Some(fit) = ri.model.channel(name).map(|m| &m.fit) else {
            continue;
        };
        for (j, rj) in runs.iter().enumerate() {
            if i == j {
                continue;
            }
            let Some(curve) = rj.curves.iter().find(|x| x.name == name) else {
                continue;
            };
            if let Some((lo, hi, worst, at)) = cross_check(fit, curve, span) {
                out.push(CrossCheck {
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
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
}

//! Per-channel stability analysis: tau grid → estimator sums → deviation → noise type
//! → equivalent degrees of freedom → chi-square confidence bounds.

use super::estimators::{self, Sums};
use super::phase::frequency_to_phase;
use super::taus::{TauSpec, averaging_factors};
use super::{AllanError, DataType, DevPoint, Estimator, ci};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How to analyse a channel.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisConfig {
    /// Which estimator.
    pub estimator: Estimator,
    /// Which taus.
    pub taus: TauSpec,
    /// Whether the samples are rates (frequency) or integrated (phase).
    pub data_type: DataType,
    /// Fixed noise exponent for the confidence intervals; `None` identifies it per tau
    /// by the lag-1 autocorrelation method.
    pub alpha: Option<i32>,
    /// Confidence level of the bounds (0.683 = 1σ).
    pub confidence: f64,
    /// Opt-in reduced-overlap OADEV (second differences every m/`FAST_OVERLAP` samples);
    /// only valid with [`Estimator::Oadev`]. EDF drops accordingly (stride factor in the
    /// Greenhall EDF).
    pub fast: bool,
}

impl Default for AnalysisConfig {
    fn default() -> Self {
        AnalysisConfig {
            estimator: Estimator::Oadev,
            taus: TauSpec::Octave,
            data_type: DataType::Frequency,
            alpha: None,
            confidence: 0.683,
            fast: false,
        }
    }
}

/// Overlap of the fast estimator: second differences every ⌈m/8⌉ samples.
pub const FAST_OVERLAP: usize = 8;

/// Stability curve of one channel with confidence bounds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelResult {
    /// Channel name.
    pub name: String,
    /// Estimator used.
    pub estimator: Estimator,
    /// Sample interval, s.
    pub tau0_s: f64,
    /// Points (m, τ, n, σ).
    pub points: Vec<DevPoint>,
    /// Lower confidence bound per point.
    pub dev_lo: Vec<f64>,
    /// Upper confidence bound per point.
    pub dev_hi: Vec<f64>,
    /// Noise exponent used for each point's bounds.
    pub alpha: Vec<i32>,
    /// Equivalent degrees of freedom per point.
    pub edf: Vec<f64>,
    /// Confidence level of the bounds.
    pub confidence: f64,
    /// Phase points of each gap-free segment the curve was computed from (one entry
    /// for a contiguous log); lets callers recompute EDFs for another noise type.
    pub segment_phase_points: Vec<usize>,
    /// Whether the reduced-overlap fast estimator produced the curve.
    pub fast: bool,
    /// Lag-1 autocorrelation of the rates averaged over τ (non-overlapping blocks of m
    /// samples of the longest segment), per point; NaN where fewer than
    /// `MIN_ACF_BLOCKS` blocks exist. ≈ 0 for white noise, negative where quantization
    /// dominates, positive where the sensor's own filtering colours the noise (see
    /// [`super::fit::auto_range_candidates`]).
    #[serde(default)]
    pub rate_acf1: Vec<f64>,
}

/// Fewest averaged blocks for which [`rate_lag1_acf`] is computed.
pub(crate) const MIN_ACF_BLOCKS: usize = 30;
/// Most averaged blocks [`rate_lag1_acf`] reads (from the start of the record): its
/// standard error is then ≤ 1/√65536 = 0.004, well inside the 0.02 the fit-range gate
/// asks for, and the short-τ points no longer read the whole record each.
pub(crate) const MAX_ACF_BLOCKS: usize = 65_536;

/// Lag-1 autocorrelation of the rates averaged over non-overlapping blocks of `m`
/// samples, read from phase `x` (x_k = τ0·Σ y): ȳ_j = (x_{(j+1)m} − x_{jm})/(mτ0), then
/// r₁ = Σ (ȳ_j − ȳ)(ȳ_{j+1} − ȳ) / Σ (ȳ_j − ȳ)² (Box & Jenkins 1976 §2.1.5; the statistic
/// behind the noise identification of Riley & Greenhall 2004). NaN when fewer than
/// `MIN_ACF_BLOCKS` blocks exist or the blocks are constant; at most the first
/// `MAX_ACF_BLOCKS` blocks are read. The scale τ0 cancels.
pub fn rate_lag1_acf(x: &[f64], m: usize) -> f64 {
    if m == 0 || x.len() < 2 {
        return f64::NAN;
    }
    let nb = ((x.len() - 1) / m).min(MAX_ACF_BLOCKS);
    if nb < MIN_ACF_BLOCKS {
        return f64::NAN;
    }
    // One pass, no copy: the mean telescopes, Σ ȳ_j = x_{nb·m} − x_0.
    let mean = (x[nb * m] - x[0]) / nb as f64;
    let (mut c0, mut c1) = (0.0, 0.0);
    let mut prev = x[m] - x[0] - mean;
    c0 += prev * prev;
    for j in 1..nb {
        let d = x[(j + 1) * m] - x[j * m] - mean;
        c0 += d * d;
        c1 += prev * d;
        prev = d;
    }
    if c0 > 0.0 { c1 / c0 } else { f64::NAN }
}

impl ChannelResult {
    /// EDF of point `i` had the noise exponent been `alpha` (segments' EDFs add).
    pub fn edf_for_alpha(&self, i: usize, alpha: i32) -> f64 {
        let Some(p) = self.points.get(i) else {
            return 0.0;
        };
        self.segment_phase_points
            .iter()
            .filter(|&&n| n > p.m)
            .map(|&n| {
                if self.fast {
                    ci::edf_strided(alpha, p.m, (p.m / FAST_OVERLAP).max(1), n)
                } else {
                    ci::edf(self.estimator, alpha, p.m, n)
                }
            })
            .filter(|e| e.is_finite() && *e > 0.0)
            .sum()
    }
}

/// Analyse one channel given as one or more contiguous segments (segments come from
/// splitting a log at time gaps; terms never straddle a gap).
pub(crate) fn analyse_segments(
    name: &str,
    segments: &[&[f64]],
    tau0_s: f64,
    cfg: &AnalysisConfig,
) -> Result<ChannelResult, AllanError> {
    check_config(cfg)?;
    check_samples(segments)?;
    // Phase for each segment.
    let phases: Vec<Vec<f64>> = segments
        .par_iter()
        .map(|seg| match cfg.data_type {
            DataType::Frequency => frequency_to_phase(seg, tau0_s),
            DataType::Phase => seg.to_vec(),
        })
        .collect();
    let longest = phases
        .iter()
        .max_by_key(|p| p.len())
        .ok_or_else(|| AllanError::Invalid("no data".into()))?;
    let ms = averaging_factors(&cfg.taus, tau0_s, longest.len(), cfg.estimator)?;

    let total = merged_sums(&phases, &ms, cfg);

    let mut points = Vec::with_capacity(ms.len());
    let mut dev_lo = Vec::with_capacity(ms.len());
    let mut dev_hi = Vec::with_capacity(ms.len());
    let mut alphas = Vec::with_capacity(ms.len());
    let mut edfs = Vec::with_capacity(ms.len());
    let total: Vec<Sums> = total.into_iter().filter(|s| s.n > 0).collect();
    // Noise identification per tau is independent: run it on all cores.
    let identified: Vec<Result<i32, AllanError>> = total
        .par_iter()
        .map(|s| match cfg.alpha {
            Some(a) => Ok(a),
            None => ci::identify_alpha(longest, s.m, cfg.estimator),
        })
        .collect();
    // Lag-1 autocorrelation of the τ-averaged rates, for the automatic fit range.
    let rate_acf1: Vec<f64> = total
        .par_iter()
        .map(|s| rate_lag1_acf(longest, s.m))
        .collect();
    let mut last_alpha: Option<i32> = None;
    for (s, id) in total.into_iter().zip(identified) {
        let dev = estimators::finish(cfg.estimator, s, tau0_s);
        let alpha = match id {
            Ok(a) => a,
            // Too few points left at this tau to identify: keep the last identified type.
            Err(e) => match last_alpha {
                Some(a) => a,
                None => return Err(e),
            },
        };
        last_alpha = Some(alpha);
        // Independent segments: chi-square degrees of freedom add.
        let edf: f64 = phases
            .iter()
            .filter(|x| x.len() > s.m)
            .map(|x| {
                if cfg.fast {
                    let stride = (s.m / FAST_OVERLAP).max(1);
                    ci::edf_strided(alpha, s.m, stride, x.len())
                } else {
                    ci::edf(cfg.estimator, alpha, s.m, x.len())
                }
            })
            .filter(|e| e.is_finite() && *e > 0.0)
            .sum();
        let (lo, hi) = if edf > 0.0 {
            ci::bounds(dev, edf, cfg.confidence)
        } else {
            (0.0, f64::INFINITY)
        };
        points.push(DevPoint {
            m: s.m,
            tau: s.m as f64 * tau0_s,
            n: s.n,
            dev,
        });
        dev_lo.push(lo);
        dev_hi.push(hi);
        alphas.push(alpha);
        edfs.push(edf);
    }
    Ok(ChannelResult {
        name: name.to_string(),
        estimator: cfg.estimator,
        tau0_s,
        points,
        dev_lo,
        dev_hi,
        alpha: alphas,
        edf: edfs,
        confidence: cfg.confidence,
        segment_phase_points: phases.iter().map(Vec::len).collect(),
        fast: cfg.fast,
        rate_acf1,
    })
}

/// The configuration's confidence level, estimator and fixed noise exponent are usable.
fn check_config(cfg: &AnalysisConfig) -> Result<(), AllanError> {
    if !(cfg.confidence > 0.0 && cfg.confidence < 1.0) {
        return Err(AllanError::Invalid(format!(
            "confidence level must be between 0 and 1, got {}",
            cfg.confidence
        )));
    }
    if cfg.fast && cfg.estimator != Estimator::Oadev {
        return Err(AllanError::Invalid(
            "the fast estimator is a reduced-overlap OADEV; use it with --estimator oadev".into(),
        ));
    }
    if let Some(a) = cfg.alpha {
        let range = if cfg.estimator.is_hadamard() {
            -4..=2
        } else {
            -2..=2
        };
        if !range.contains(&a) {
            return Err(AllanError::Invalid(format!(
                "alpha {a} is outside {}..={} for {}",
                range.start(),
                range.end(),
                cfg.estimator.name()
            )));
        }
    }
    Ok(())
}

/// Every sample is finite and within [`super::MAX_SAMPLE_MAGNITUDE`]; the error names the
/// index counted over all segments.
fn check_samples(segments: &[&[f64]]) -> Result<(), AllanError> {
    let mut offset = 0usize;
    for seg in segments {
        if let Some(i) = seg.iter().position(|v| !v.is_finite()) {
            return Err(AllanError::NonFinite {
                index: offset + i,
                value: seg[i],
            });
        }
        if let Some(i) = seg
            .iter()
            .position(|v| v.abs() > super::MAX_SAMPLE_MAGNITUDE)
        {
            return Err(AllanError::OutOfRange {
                index: offset + i,
                value: seg[i],
                limit: super::MAX_SAMPLE_MAGNITUDE,
            });
        }
        offset += seg.len();
    }
    Ok(())
}

/// The estimator's sums at every averaging factor, per segment and merged.
fn merged_sums(phases: &[Vec<f64>], ms: &[usize], cfg: &AnalysisConfig) -> Vec<Sums> {
    let mut total: Vec<Sums> = ms.iter().map(|&m| Sums { m, sum: 0.0, n: 0 }).collect();
    for x in phases {
        let s = if cfg.fast {
            estimators::oadev_strided_sums(x, ms, FAST_OVERLAP)
        } else {
            estimators::sums(cfg.estimator, x, ms)
        };
        for (t, s) in total.iter_mut().zip(s) {
            if s.n > 0 {
                *t = t.merge(s);
            }
        }
    }
    total
}

/// Analyse one contiguous channel.
pub fn analyse(
    name: &str,
    values: &[f64],
    tau0_s: f64,
    cfg: &AnalysisConfig,
) -> Result<ChannelResult, AllanError> {
    analyse_segments(name, &[values], tau0_s, cfg)
}

/// Analyse several channels (each given as its gap-free segments) in parallel.
/// Results come back in input order; the first error wins.
pub fn analyse_channels(
    channels: &[(&str, Vec<&[f64]>)],
    tau0_s: f64,
    cfg: &AnalysisConfig,
) -> Result<Vec<ChannelResult>, AllanError> {
    channels
        .par_iter()
        .map(|(name, segs)| analyse_segments(name, segs, tau0_s, cfg))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass form equals the textbook two-pass lag-1 autocorrelation of the (first
    /// [`MAX_ACF_BLOCKS`]) block means, and white noise gives ≈ 0, an AR(1) with φ = 0.6
    /// ≈ 0.6 at m = 1.
    #[test]
    fn rate_lag1_acf_matches_the_two_pass_definition() {
        let mut rng = crate::sim::rng::Rng::seed_from_u64(5);
        let n = 100_000;
        let (mut ar, mut white) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut a = 0.0;
        for _ in 0..n {
            a = 0.6 * a + rng.normal();
            ar.push(a);
            white.push(rng.normal());
        }
        let phase = |y: &[f64]| {
            let mut x = vec![0.0];
            for v in y {
                x.push(x.last().copied().unwrap_or(0.0) + v);
            }
            x
        };
        let naive = |x: &[f64], m: usize| {
            let nb = ((x.len() - 1) / m).min(MAX_ACF_BLOCKS);
            let y: Vec<f64> = (0..nb).map(|j| x[(j + 1) * m] - x[j * m]).collect();
            let mean = y.iter().sum::<f64>() / nb as f64;
            let c0: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
            let c1: f64 = y.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
            c1 / c0
        };
        let (xa, xw) = (phase(&ar), phase(&white));
        for m in [1, 2, 7, 100] {
            for x in [&xa, &xw] {
                let (got, want) = (rate_lag1_acf(x, m), naive(x, m));
                assert!((got - want).abs() < 1e-9, "m = {m}: {got} vs {want}");
            }
        }
        assert!((rate_lag1_acf(&xa, 1) - 0.6).abs() < 0.02);
        assert!(rate_lag1_acf(&xw, 1).abs() < 0.02);
        assert!(rate_lag1_acf(&xw, n).is_nan());
    }
}

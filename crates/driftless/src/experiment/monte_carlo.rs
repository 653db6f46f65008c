//! The whole experiment with Monte Carlo repetitions, and its statistics.
//!
//! Run 0 is the *detailed* run (solutions kept for the figures and Table 1). Runs 1…K−1
//! redraw the chamber log, the vehicle IMU (turn-on biases and noise) and the GNSS noise
//! from new seeds; the sensor design and the noise model (one static log) stay. Runs are
//! processed in parallel (rayon; the cases of a run also run in parallel).
//!
//! Per case the statistic of a run is its mean end-of-outage horizontal error over the
//! outages (the paper's Table 1 "Mean"); over runs we report its mean and the 5th, 50th
//! and 95th percentiles (linear interpolation between order statistics). The ratio
//! (b)/(c) is the ratio of the two means over runs; its interval is a percentile
//! bootstrap over runs (the same resampled runs for both cases, so their correlation is
//! kept; 4000 resamples, fixed seed), which needs no normality of the per-run errors.
//! (d)/(c) — what the thermal model adds to a full room calibration — is reported the
//! same way, and so is how often, over every run and outage, a more compensated case
//! ended worse than a less compensated one ([`super::budget`]).

use rayon::prelude::*;
use serde::Serialize;

use super::ExperimentError;
use super::budget::{ReversalCount, reversal_counts};
use super::run::{
    Case, NoiseStage, Prepared, ThermalStage, VehicleRun, noise_stage, thermal_stage, vehicle_run,
};
use crate::numeric::splitmix::splitmix64_mix;

impl ExperimentResult {
    /// Per case (run 0's order): label and each run's mean end-of-outage horizontal
    /// error of the forward filter (`None` where the case failed).
    pub(crate) fn per_run_forward_means(&self) -> Vec<(String, Vec<Option<f64>>)> {
        self.detailed
            .cases
            .iter()
            .map(|c| {
                (
                    c.case.label().to_string(),
                    self.runs
                        .iter()
                        .map(|run| run.case(c.case).and_then(|x| x.forward_mean_end_m()))
                        .collect(),
                )
            })
            .collect()
    }
}

/// Everything an experiment produced.
#[derive(Debug)]
pub struct ExperimentResult {
    /// The noise stage.
    pub noise: Option<NoiseStage>,
    /// The thermal stage of run 0.
    pub thermal: Option<ThermalStage>,
    /// Run 0, with its solutions.
    pub detailed: VehicleRun,
    /// Every run's case results (run 0 first, solutions dropped).
    pub runs: Vec<VehicleRun>,
    /// Statistics over the runs.
    pub summary: MonteCarloSummary,
}

/// Percentiles of a sample.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Spread {
    /// Number of values.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// 5th percentile.
    pub p5: f64,
    /// Median.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl Spread {
    /// Statistics of finite `values` (`None` when there are none).
    pub fn of(values: &[f64]) -> Option<Spread> {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(Spread {
            n: v.len(),
            mean: v.iter().sum::<f64>() / v.len() as f64,
            p5: percentile(&v, 0.05),
            p50: percentile(&v, 0.5),
            p95: percentile(&v, 0.95),
        })
    }
}

/// Percentile of sorted values, linear between order statistics (type 7).
pub(crate) fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = (sorted.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Statistics of one case over the runs.
#[derive(Clone, Debug, Serialize)]
pub struct CaseSpread {
    /// The case.
    pub case: Case,
    /// Label.
    pub label: String,
    /// Per-run mean end-of-outage horizontal error of the forward filter, m.
    pub forward_mean_end_m: Option<Spread>,
    /// Same for the smoothed solution, m.
    pub smoothed_mean_end_m: Option<Spread>,
    /// Runs in which the case failed (filter error), with the first message.
    pub failed_runs: usize,
    /// First failure message, if any.
    pub first_failure: Option<String>,
}

/// Ratio of two cases' mean errors with its bootstrap interval.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RatioInterval {
    /// Mean over runs of the numerator case / of the denominator case.
    pub ratio: f64,
    /// Lower end of the interval.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Confidence level.
    pub confidence: f64,
    /// Runs used (those where both cases succeeded).
    pub runs: usize,
}

impl MonteCarloSummary {
    /// The per-case statistics as a table: header and rows (metres).
    pub fn table(&self) -> (Vec<String>, Vec<Vec<String>>) {
        let header = [
            "case",
            "mean [m]",
            "p5 [m]",
            "median [m]",
            "p95 [m]",
            "failed runs",
        ]
        .map(String::from)
        .to_vec();
        let f = super::table::fmt_m;
        let rows = self
            .cases
            .iter()
            .map(|c| {
                let mut row = vec![c.label.clone()];
                match &c.forward_mean_end_m {
                    Some(s) => row.extend([f(s.mean), f(s.p5), f(s.p50), f(s.p95)]),
                    None => row.extend(["–"; 4].map(String::from)),
                }
                row.push(c.failed_runs.to_string());
                row
            })
            .collect();
        (header, rows)
    }
}

/// Statistics over the runs.
#[derive(Clone, Debug, Serialize)]
pub struct MonteCarloSummary {
    /// Number of runs.
    pub runs: usize,
    /// Per case.
    pub cases: Vec<CaseSpread>,
    /// (b)/(c) of the forward filter's mean end-of-outage error, when (c) was run: room
    /// biases only against bias, scale and thermal model (the paper's ratio).
    pub ratio_room_over_thermal: Option<RatioInterval>,
    /// (b)/(c) of the smoothed solution.
    pub ratio_room_over_thermal_smoothed: Option<RatioInterval>,
    /// (d)/(c), forward: the full room calibration against the same plus the thermal
    /// model — what the thermal model alone buys.
    pub ratio_full_room_over_thermal: Option<RatioInterval>,
    /// Over all runs and outages, how often a more compensated case ended worse than a
    /// less compensated one.
    pub reversals: Vec<ReversalCount>,
}

/// Percentile-bootstrap interval of mean(num)/mean(den) over paired runs.
pub(crate) fn ratio_interval(
    num: &[f64],
    den: &[f64],
    confidence: f64,
    seed: u64,
) -> Option<RatioInterval> {
    let pairs: Vec<(f64, f64)> = num
        .iter()
        .zip(den)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pairs.len();
    if n == 0 {
        return None;
    }
    let sum = |f: fn(&(f64, f64)) -> f64| pairs.iter().map(f).sum::<f64>();
    let ratio = sum(|p| p.0) / sum(|p| p.1);
    if !ratio.is_finite() {
        return None;
    }
    const RESAMPLES: usize = 4000;
    let mut state = seed;
    let mut rs: Vec<f64> = (0..RESAMPLES)
        .map(|_| {
            let (mut s1, mut s2) = (0.0, 0.0);
            for _ in 0..n {
                state = splitmix64_mix(state);
                let (a, b) = pairs[(state % n as u64) as usize];
                s1 += a;
                s2 += b;
            }
            s1 / s2
        })
        .filter(|r| r.is_finite())
        .collect();
    rs.sort_by(f64::total_cmp);
    let a = (1.0 - confidence) / 2.0;
    Some(RatioInterval {
        ratio,
        lo: percentile(&rs, a),
        hi: percentile(&rs, 1.0 - a),
        confidence,
        runs: n,
    })
}

/// Statistics of the runs.
pub(crate) fn summarise(runs: &[VehicleRun], confidence: f64, seed: u64) -> MonteCarloSummary {
    let mut cases = Vec::new();
    let present: Vec<Case> = runs
        .first()
        .map(|r| r.cases.iter().map(|c| c.case).collect())
        .unwrap_or_default();
    let col = |case: Case, smoothed: bool| -> Vec<f64> {
        runs.iter()
            .map(|r| {
                r.case(case)
                    .and_then(|c| {
                        if smoothed {
                            c.smoothed_mean_end_m()
                        } else {
                            c.forward_mean_end_m()
                        }
                    })
                    .unwrap_or(f64::NAN)
            })
            .collect()
    };
    // Smoothed statistics only when every run was smoothed.
    let all_smoothed = runs
        .iter()
        .all(|r| r.cases.iter().all(|c| c.smoothed.is_some()));
    for &case in &present {
        let failures: Vec<&str> = runs
            .iter()
            .filter_map(|r| r.case(case))
            .filter_map(|c| c.forward.as_ref().err().map(String::as_str))
            .collect();
        cases.push(CaseSpread {
            case,
            label: case.label().to_string(),
            forward_mean_end_m: Spread::of(&col(case, false)),
            smoothed_mean_end_m: all_smoothed.then(|| Spread::of(&col(case, true))).flatten(),
            failed_runs: failures.len(),
            first_failure: failures.first().map(|s| s.to_string()),
        });
    }
    let ratio = |num: Case, smoothed| {
        (present.contains(&num) && present.contains(&Case::Thermal))
            .then(|| {
                ratio_interval(
                    &col(num, smoothed),
                    &col(Case::Thermal, smoothed),
                    confidence,
                    seed,
                )
            })
            .flatten()
    };
    MonteCarloSummary {
        runs: runs.len(),
        cases,
        ratio_room_over_thermal: ratio(Case::RoomBias, false),
        ratio_room_over_thermal_smoothed: all_smoothed
            .then(|| ratio(Case::RoomBias, true))
            .flatten(),
        ratio_full_room_over_thermal: ratio(Case::RoomFull, false),
        reversals: reversal_counts(runs),
    }
}

/// Run `i` ≥ 1 (not detailed): its own chamber when the chamber is simulated (redrawn
/// per run), else run 0's thermal stage (a model file is read once), then the vehicle.
pub(super) fn later_run(
    p: &Prepared,
    noise: Option<&NoiseStage>,
    run0_thermal: Option<&ThermalStage>,
    i: usize,
) -> Result<VehicleRun, ExperimentError> {
    let redraw = (p.scenario.chamber.as_ref()).is_some_and(|c| c.protocol.is_some());
    let redrawn = if redraw {
        thermal_stage(p, noise, i)?
    } else {
        None
    };
    let thermal = if redraw {
        redrawn.as_ref()
    } else {
        run0_thermal
    };
    vehicle_run(p, noise, thermal, i, false)
}

/// The statistics of runs 0…K−1 (in run order) at the scenario's confidence, with the
/// bootstrap seeded from the scenario seed.
pub(super) fn summarise_runs(p: &Prepared, runs: &[VehicleRun]) -> MonteCarloSummary {
    summarise(
        runs,
        p.scenario.monte_carlo.confidence,
        splitmix64_mix(p.scenario.seed ^ 0xB007),
    )
}

/// Runs the whole experiment: the noise stage once, then `runs` (default: the
/// scenario's) chamber + vehicle runs. `progress(stage, done, total)` is called as
/// stages finish.
pub fn run_experiment(
    p: &Prepared,
    runs: Option<usize>,
    progress: super::run::Progress<'_>,
) -> Result<ExperimentResult, ExperimentError> {
    let k = runs.unwrap_or(p.scenario.monte_carlo.runs);
    if k == 0 {
        return Err(p.scenario.invalid("--runs must be at least 1"));
    }
    if k > 1 && p.recorded.is_some() {
        return Err(p.scenario.invalid(format!(
            "--runs {k}: a recorded run cannot be redrawn; Monte Carlo needs a simulated [vehicle]"
        )));
    }
    progress("noise", 0, 1);
    let noise = noise_stage(p)?;
    progress("noise", 1, 1);
    progress("runs", 0, k as u64);
    let thermal = thermal_stage(p, noise.as_ref(), 0)?;
    let detailed = vehicle_run(p, noise.as_ref(), thermal.as_ref(), 0, true)?;
    let done = std::sync::atomic::AtomicU64::new(1);
    progress("runs", 1, k as u64);
    let rest: Vec<VehicleRun> = (1..k)
        .into_par_iter()
        .map(|i| {
            let r = later_run(p, noise.as_ref(), thermal.as_ref(), i)?;
            let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress("runs", d, k as u64);
            Ok(r)
        })
        .collect::<Result<_, ExperimentError>>()?;
    let mut all = Vec::with_capacity(k);
    all.push(detailed.without_solutions());
    all.extend(rest);
    let summary = summarise_runs(p, &all);
    Ok(ExperimentResult {
        noise,
        thermal,
        detailed,
        runs: all,
        summary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_are_type_7() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&v, 1.0), 5.0);
        assert!((percentile(&v, 0.05) - 1.2).abs() < 1e-12);
    }

    #[test]
    fn bootstrap_interval_brackets_the_ratio_and_shrinks_with_runs() {
        // Runs in pairs with the same denominator and multipliers u, 2 − u (u ∈ [0.8,
        // 1.2)): num = 3·den·u, so the sample ratio of means is exactly 3 while single
        // runs scatter ±20 %.
        let mut s = 7u64;
        let mut u = || {
            s = splitmix64_mix(s);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mk = |pairs: usize, u: &mut dyn FnMut() -> f64| {
            let (mut num, mut den) = (Vec::new(), Vec::new());
            for _ in 0..pairs {
                let d = 1.0 + u();
                let m = 0.8 + 0.4 * u();
                num.extend([3.0 * d * m, 3.0 * d * (2.0 - m)]);
                den.extend([d, d]);
            }
            (num, den)
        };
        let (n1, d1) = mk(10, &mut u);
        let (n2, d2) = mk(1000, &mut u);
        let a = ratio_interval(&n1, &d1, 0.95, 1).expect("a");
        let b = ratio_interval(&n2, &d2, 0.95, 1).expect("b");
        assert!(a.lo < a.ratio && a.ratio < a.hi, "{a:?}");
        assert!((a.ratio - 3.0).abs() < 1e-12 && (b.ratio - 3.0).abs() < 1e-12);
        assert!(b.lo < 3.0 && 3.0 < b.hi, "{b:?}");
        assert!(b.hi - b.lo < 0.3 * (a.hi - a.lo), "{a:?} {b:?}");
        // Failed runs (NaN) are dropped pairwise.
        let mut n3 = n1.clone();
        n3[0] = f64::NAN;
        assert_eq!(ratio_interval(&n3, &d1, 0.95, 1).expect("c").runs, 19);
    }
}

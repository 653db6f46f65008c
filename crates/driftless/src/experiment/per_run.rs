//! The Monte Carlo experiment one run at a time, for runs spread over processes or
//! machines: [`MonteCarloContext::run_one`] computes run `i` exactly as
//! [`super::monte_carlo::run_experiment`] does (the same seeds, [`super::run::run_seed`] of
//! the scenario seed and `i`; run 0 the detailed run), [`RunRecord`] keeps what the
//! statistics need of it, and [`summarise_records`] gives the experiment's
//! [`MonteCarloSummary`] from the records of runs 0…K−1, in any order of arrival.
//!
//! A context holds what every run shares: the checked scenario, the noise stage (one
//! static log analysed, or a model read) and the thermal stage of run 0 (runs ≥ 1 redraw
//! a simulated chamber; a thermal model file is read once). Building it costs the noise
//! stage; a worker builds it once and runs many indices with it.

use super::ExperimentError;
use super::monte_carlo::{MonteCarloSummary, later_run, summarise_runs};
use super::run::{
    Case, CaseRun, NoiseStage, Prepared, ThermalStage, VehicleRun, noise_stage, thermal_stage,
    vehicle_run,
};
use crate::eval::metrics::{OutageErrors, OutageReport, OutageSummary, Stat};

/// What every run of an experiment shares (module docs).
#[derive(Debug)]
pub struct MonteCarloContext {
    /// The checked scenario with its outage windows.
    pub prepared: Prepared,
    /// The noise stage.
    pub noise: Option<NoiseStage>,
    /// The thermal stage of run 0 (and of every run when the chamber is a model file).
    pub thermal: Option<ThermalStage>,
}

impl MonteCarloContext {
    /// The noise stage and run 0's thermal stage of a prepared experiment.
    pub fn new(prepared: Prepared) -> Result<MonteCarloContext, ExperimentError> {
        let noise = noise_stage(&prepared)?;
        let thermal = thermal_stage(&prepared, noise.as_ref(), 0)?;
        Ok(MonteCarloContext {
            prepared,
            noise,
            thermal,
        })
    }

    /// The scenario's number of runs (`[monte_carlo] runs`).
    pub fn runs(&self) -> usize {
        self.prepared.scenario.monte_carlo.runs
    }

    /// Run `run` in every case, as [`super::monte_carlo::run_experiment`] computes it
    /// (run 0 detailed: smoothed when the scenario smooths, with its error budgets),
    /// without the solutions.
    pub fn run_one(&self, run: usize) -> Result<VehicleRun, ExperimentError> {
        let p = &self.prepared;
        if run > 0 && p.recorded.is_some() {
            return Err(p.scenario.invalid(format!(
                "run {run}: a recorded run cannot be redrawn; Monte Carlo needs a simulated [vehicle]"
            )));
        }
        if run == 0 {
            let r = vehicle_run(p, self.noise.as_ref(), self.thermal.as_ref(), 0, true)?;
            return Ok(r.without_solutions());
        }
        later_run(p, self.noise.as_ref(), self.thermal.as_ref(), run)
    }
}

/// One solution's end-of-outage errors in a run (what the statistics read).
#[derive(Clone, Debug, PartialEq)]
pub struct SolutionRecord {
    /// Why the filter (or smoother) failed; `None` when it ran.
    pub failure: Option<String>,
    /// Horizontal end-of-outage error per outage window, m (NaN where the outage had no
    /// epoch to compare); empty when it failed.
    pub end_horizontal_m: Vec<f64>,
    /// Mean of `end_horizontal_m` (the run's statistic, Table 1 "Mean"), m; `None` when
    /// it failed or there are no outages.
    pub mean_end_horizontal_m: Option<f64>,
}

impl SolutionRecord {
    fn of(r: &Result<OutageReport, String>) -> SolutionRecord {
        match r {
            Ok(o) => SolutionRecord {
                failure: None,
                end_horizontal_m: o.outages.iter().map(|e| e.end_horizontal_m).collect(),
                mean_end_horizontal_m: o.summary.end_horizontal_m.map(|s| s.mean),
            },
            Err(m) => SolutionRecord {
                failure: Some(m.clone()),
                end_horizontal_m: Vec::new(),
                mean_end_horizontal_m: None,
            },
        }
    }

    /// The outage report the statistics read: the end errors and their mean; the fields
    /// they do not read (heights, headings, maxima, growth) are NaN or empty.
    fn report(&self, p: &Prepared) -> Result<OutageReport, String> {
        if let Some(m) = &self.failure {
            return Err(m.clone());
        }
        let windows = p.windows();
        let outages: Vec<OutageErrors> = (self.end_horizontal_m.iter().enumerate())
            .map(|(i, &e)| OutageErrors {
                window: windows.get(i).copied().unwrap_or(crate::data::TimeSpan {
                    start_s: f64::NAN,
                    end_s: f64::NAN,
                }),
                end_time_s: f64::NAN,
                end_horizontal_m: e,
                end_ned_m: [f64::NAN; 3],
                end_height_m: f64::NAN,
                end_heading_deg: None,
                max_horizontal_m: f64::NAN,
                max_time_s: f64::NAN,
                epochs: 0,
                growth: Vec::new(),
            })
            .collect();
        let n = outages.len();
        Ok(OutageReport {
            outages,
            summary: OutageSummary {
                outages: n,
                end_horizontal_m: self.mean_end_horizontal_m.map(|mean| Stat {
                    count: n,
                    mean,
                    rms: f64::NAN,
                    max: f64::NAN,
                }),
                ..OutageSummary::default()
            },
        })
    }
}

/// One case of a run as the statistics see it.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseRecord {
    /// The case.
    pub case: Case,
    /// The forward (real-time) filter.
    pub forward: SolutionRecord,
    /// The smoothed solution, when this run was smoothed.
    pub smoothed: Option<SolutionRecord>,
    /// GNSS fixes the filter accepted.
    pub gnss_accepted: usize,
    /// GNSS fixes the gate rejected.
    pub gnss_rejected: usize,
}

/// One run as the statistics see it: per case the end-of-outage errors (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// Monte Carlo index.
    pub run: usize,
    /// Sensor temperature over the run, first and last reading, °C (simulated runs).
    pub temperature_c: Option<(f64, f64)>,
    /// Cases in the run's order.
    pub cases: Vec<CaseRecord>,
}

impl From<&VehicleRun> for RunRecord {
    fn from(r: &VehicleRun) -> RunRecord {
        RunRecord {
            run: r.run,
            temperature_c: r.temperature_c,
            cases: r
                .cases
                .iter()
                .map(|c| CaseRecord {
                    case: c.case,
                    forward: SolutionRecord::of(&c.forward),
                    smoothed: c.smoothed.as_ref().map(SolutionRecord::of),
                    gnss_accepted: c.gnss_accepted,
                    gnss_rejected: c.gnss_rejected,
                })
                .collect(),
        }
    }
}

impl CaseRecord {
    /// The case as the statistics read it; no solution and no budgets (they do not read
    /// them).
    fn case_run(&self, p: &Prepared) -> CaseRun {
        CaseRun {
            forward: self.forward.report(p),
            smoothed: self.smoothed.as_ref().map(|s| s.report(p)),
            gnss_accepted: self.gnss_accepted,
            gnss_rejected: self.gnss_rejected,
            ..CaseRun::failed(self.case, String::new())
        }
    }
}

impl RunRecord {
    fn vehicle_run(&self, p: &Prepared) -> VehicleRun {
        let cases = self.cases.iter().map(|c| c.case_run(p)).collect();
        VehicleRun {
            run: self.run,
            cases,
            reference: None,
            fixes: None,
            temperature_c: self.temperature_c,
        }
    }
}

/// The experiment's statistics over runs 0…K−1 from their records (any order; the
/// summary of [`super::monte_carlo::run_experiment`] with K runs). Refuses a set that is
/// not exactly the runs 0…K−1 once each.
pub fn summarise_records(
    p: &Prepared,
    records: &[RunRecord],
) -> Result<MonteCarloSummary, ExperimentError> {
    let mut sorted: Vec<&RunRecord> = records.iter().collect();
    sorted.sort_by_key(|r| r.run);
    if sorted.is_empty() {
        return Err(p.scenario.invalid("no runs to summarise"));
    }
    for (i, r) in sorted.iter().enumerate() {
        if r.run != i {
            return Err(p.scenario.invalid(format!(
                "the runs to summarise must be 0…{} once each; run {} is {}",
                sorted.len() - 1,
                i,
                if r.run < i { "repeated" } else { "missing" }
            )));
        }
    }
    let runs: Vec<VehicleRun> = sorted.iter().map(|r| r.vehicle_run(p)).collect();
    Ok(summarise_runs(p, &runs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::monte_carlo::run_experiment;
    use crate::experiment::{ExperimentScenario, prepare};

    /// `examples/experiment/small.toml`: the built-in scenario cut down to seconds of work.
    fn small_scenario() -> ExperimentScenario {
        let text = include_str!("../../../../examples/experiment/small.toml");
        ExperimentScenario::from_toml_str(text, "small.toml", Default::default())
            .expect("small scenario")
    }

    #[test]
    fn runs_one_at_a_time_equal_the_whole_experiment() {
        let p = prepare(small_scenario()).expect("prepare");
        let whole = run_experiment(&p, None, &|_, _, _| {}).expect("experiment");
        let ctx =
            MonteCarloContext::new(prepare(small_scenario()).expect("prepare")).expect("context");
        assert_eq!(ctx.runs(), 5);
        // Out of order, as workers finish.
        let records: Vec<RunRecord> = [2, 0, 4, 1, 3]
            .iter()
            .map(|&i| RunRecord::from(&ctx.run_one(i).expect("run")))
            .collect();
        for rec in &records {
            let serial = RunRecord::from(&whole.runs[rec.run]);
            // Bit for bit (NaN equal to NaN).
            assert_eq!(format!("{rec:?}"), format!("{serial:?}"), "run {}", rec.run);
        }
        assert!(records.iter().any(|r| r.cases[0].forward.failure.is_none()));
        let summary = summarise_records(&ctx.prepared, &records).expect("summary");
        assert_eq!(format!("{summary:?}"), format!("{:?}", whole.summary));
        // A missing or repeated run is refused.
        let e = summarise_records(&ctx.prepared, &records[..2]).expect_err("missing");
        assert!(e.to_string().contains("run 1 is missing"), "{e}");
        let twice = [records[1].clone(), records[1].clone()];
        let e = summarise_records(&ctx.prepared, &twice).expect_err("repeated");
        assert!(e.to_string().contains("repeated"), "{e}");
    }
}

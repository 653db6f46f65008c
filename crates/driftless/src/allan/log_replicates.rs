//! Replicate logs of one sensor: each run analysed as a single log ([`analyse_log`]),
//! then the runs' noise terms compared and a joint model fitted ([`compare_replicates`]).
//!
//! [`ReplicateAnalysis`] serializes to the `allan --json` document with several runs: the
//! single-run shape for the joint result (`channels`: the combined curves, `noise`: the
//! joint model), `runs`: each run's own document with its `file`, `replicates`: the
//! comparison.

use super::log_analysis::{
    CurvesDocument, LogAnalysis, LogAnalysisError, LogAnalysisOptions, NoiseDocument, NoiseMethod,
    analyse_log,
};
use super::replicates::{
    DEFAULT_LEVEL, ReplicateError, ReplicateOptions, ReplicateRun, Replicates, RunShape,
    check_same_sensor, compare_replicates,
};
use crate::io::{ImuLog, Quantity};
use serde::Serialize;

/// Why [`analyse_replicates`] failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplicateLogsError {
    /// The comparison needs the Allan fit (not the GMWM, not the curves alone).
    #[error("comparing {0} logs needs the Allan noise fit")]
    NeedsAllanFit(usize),
    /// One run's analysis failed.
    #[error("analysing {run}")]
    Run {
        /// The run.
        run: String,
        /// Cause.
        source: LogAnalysisError,
    },
    /// A run without a fitted model.
    #[error("{0}: no noise model was fitted")]
    NoModel(String),
    /// The runs are not replicates, or their comparison failed.
    #[error(transparent)]
    Compare(#[from] ReplicateError),
}

/// One analysed run.
#[derive(Clone, Debug)]
pub struct ReplicateRunAnalysis {
    /// Name of the run (its file).
    pub name: String,
    /// Its analysis.
    pub analysis: LogAnalysis,
}

/// The runs, their comparison and joint model.
#[derive(Clone, Debug)]
pub struct ReplicateAnalysis {
    /// Each run's own analysis, in the order given.
    pub runs: Vec<ReplicateRunAnalysis>,
    /// The comparison and the joint model.
    pub replicates: Replicates,
    /// Every run's warnings, then the comparison's (terms the runs disagree on).
    pub warnings: Vec<String>,
}

/// Whether the logs can be replicates of one sensor (the same channels, quantities and
/// sample rate; [`check_same_sensor`]), checked before any analysis.
pub(crate) fn check_replicate_logs(logs: &[(&str, &ImuLog)]) -> Result<(), ReplicateError> {
    let shapes: Vec<RunShape<'_>> = logs
        .iter()
        .map(|(name, log)| RunShape {
            source: name,
            channels: log
                .channels
                .iter()
                .filter(|c| c.quantity != Quantity::Temperature)
                .map(|c| (c.name.as_str(), c.quantity))
                .collect(),
            tau0_s: log.tau0_s,
        })
        .collect();
    if let [first, rest @ ..] = shapes.as_slice() {
        for other in rest {
            check_same_sensor(first, other)?;
        }
    }
    Ok(())
}

/// Checks that `logs` (name, log) are replicates, analyses each with `opts` (which must
/// fit the Allan noise model), compares the runs' terms and fits the joint model at the
/// [`DEFAULT_LEVEL`]. `on_run(k)` is called before run `k` is analysed (for progress).
pub fn analyse_replicates(
    logs: &[(&str, &ImuLog)],
    opts: &LogAnalysisOptions,
    on_run: &dyn Fn(usize),
) -> Result<ReplicateAnalysis, ReplicateLogsError> {
    let Some(NoiseMethod::Allan(fit, fit_range)) = &opts.method else {
        return Err(ReplicateLogsError::NeedsAllanFit(logs.len()));
    };
    check_replicate_logs(logs)?;
    let mut runs = Vec::with_capacity(logs.len());
    for (k, (name, log)) in logs.iter().enumerate() {
        on_run(k);
        let analysis = analyse_log(log, opts).map_err(|source| ReplicateLogsError::Run {
            run: name.to_string(),
            source,
        })?;
        runs.push(ReplicateRunAnalysis {
            name: name.to_string(),
            analysis,
        });
    }
    let mut inputs = Vec::with_capacity(runs.len());
    for r in &runs {
        let model = r
            .analysis
            .noise
            .as_ref()
            .ok_or_else(|| ReplicateLogsError::NoModel(r.name.clone()))?;
        inputs.push(ReplicateRun {
            source: &r.name,
            curves: &r.analysis.fit_curves,
            model,
            resolution: &r.analysis.resolution,
        });
    }
    let replicates = compare_replicates(
        &inputs,
        &ReplicateOptions {
            fit: *fit,
            fit_range: *fit_range,
            level: DEFAULT_LEVEL,
            ..ReplicateOptions::default()
        },
    )?;
    let mut warnings: Vec<String> = runs
        .iter()
        .flat_map(|r| r.analysis.warnings.iter().cloned())
        .collect();
    warnings.extend(replicates.warnings());
    Ok(ReplicateAnalysis {
        runs,
        replicates,
        warnings,
    })
}

impl ReplicateAnalysis {
    /// Unit of each joint curve's channel (from the first run).
    pub(crate) fn joint_units(&self) -> Vec<String> {
        match self.runs.first() {
            Some(r) => self
                .replicates
                .joint_curves
                .iter()
                .map(|c| {
                    r.analysis
                        .fit_curves
                        .iter()
                        .position(|x| x.name == c.name)
                        .and_then(|k| r.analysis.units.get(k).cloned())
                        .unwrap_or_default()
                })
                .collect(),
            None => Vec::new(),
        }
    }
}

/// A run of the `runs` array: its single-log document and its `file`.
#[derive(Serialize)]
struct RunDocument<'a> {
    #[serde(flatten)]
    analysis: &'a LogAnalysis,
    file: &'a str,
}

impl Serialize for ReplicateAnalysis {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let units = self.joint_units();
        let mut st = s.serialize_struct("ReplicateAnalysis", 6)?;
        st.serialize_field(
            "channels",
            &CurvesDocument {
                results: &self.replicates.joint_curves,
                units: &units,
            },
        )?;
        st.serialize_field(
            "noise",
            &NoiseDocument {
                model: &self.replicates.joint,
                allan_fit: true,
            },
        )?;
        st.serialize_field("warnings", &self.warnings)?;
        st.serialize_field("lines", &[] as &[()])?;
        let runs: Vec<RunDocument<'_>> = self
            .runs
            .iter()
            .map(|r| RunDocument {
                analysis: &r.analysis,
                file: &r.name,
            })
            .collect();
        st.serialize_field("runs", &runs)?;
        st.serialize_field("replicates", &self.replicates)?;
        st.end()
    }
}

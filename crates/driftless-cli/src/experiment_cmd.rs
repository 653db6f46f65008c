//! `driftless experiment SCENARIO.toml`: the seed paper's experiment end to end
//! (`driftless::experiment`) — Allan → noise model, chamber → thermal model, the vehicle
//! run in cases (a) raw, (b) room biases, (c) room bias, scale factor and thermal model,
//! (d) full room calibration, forward and smoothed,
//! GNSS outages, Table 1, figures and one self-contained HTML report. `driftless demo`
//! runs it on the built-in `adi-like` scenario.

use crate::experiment_run::{OutputFolder, run_scenario};
use anyhow::Result;
use clap::Args;
use driftless::experiment::ExperimentScenario;
use std::path::PathBuf;
#[derive(Args, Debug)]
pub struct ExperimentArgs {
    /// Experiment scenario (TOML; see `driftless::experiment::scenario` or the README).
    pub scenario: PathBuf,
    /// Output folder.
    #[arg(long, default_value = "driftless-experiment")]
    pub out: PathBuf,
    /// Write into an output folder that already holds files: this run's files replace
    /// theirs, and figures an earlier run wrote that this run does not are removed.
    /// Without it such a folder is refused, so that runs never mix.
    #[arg(long)]
    pub force: bool,
    /// Monte Carlo runs (default: the scenario's `[monte_carlo] runs`).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numbers::count)]
    pub runs: Option<usize>,
    /// Print the JSON document instead of tables.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: ExperimentArgs) -> Result<()> {
    let sc = ExperimentScenario::from_file(&a.scenario)?;
    let out = OutputFolder {
        dir: &a.out,
        force: a.force,
    };
    run_scenario(sc, out, a.runs, a.json)
}

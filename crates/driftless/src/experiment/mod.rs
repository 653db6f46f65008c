//! The seed paper's experiment end to end: Allan analysis of a static log → noise model
//! (filter tuning); chamber soak → thermal model; a vehicle run processed with GNSS
//! outages as the paper's three columns — (a) raw, (b) the biases removed at room
//! temperature, no scale factor and no thermal model, (c) room bias, scale factor and
//! misalignment plus the thermal model — and (d) the full room calibration without the
//! thermal model; forward filter (real time) and RTS-smoothed; per-outage errors against
//! a reference (the truth when simulated, otherwise the smoothed full-GNSS solution) and
//! the outages where a more compensated case ended worse, with the cause.
//!
//! * [`scenario`]: the TOML file and every check that needs no data;
//! * [`run`]: the stages ([`run::prepare`] fails fast — outage windows are chosen or
//!   checked on a cheap reference before any long computation);
//! * [`monte_carlo`]: repetitions with new seeds, per-case statistics and the ratios
//!   (b)/(c), (d)/(c) with bootstrap intervals;
//! * [`per_run`]: the same Monte Carlo one run at a time (runs spread over processes or
//!   machines) and its statistics from the runs' records;
//! * [`budget`]: each outage's linearised error budget and the reversals it explains;
//! * [`table`]: the paper's Table 1 as Markdown and CSV.
//!
//! Convention: the end-of-outage error is the solution's error at its last epoch inside
//! the window against the reference interpolated there ([`crate::eval::metrics`]), for
//! forward and smoothed solutions alike; the maximum is over every epoch in the window.

pub mod budget;
pub mod monte_carlo;
pub mod per_run;
pub mod report;
pub mod run;
pub mod scenario;
pub mod table;

pub use run::{Case, prepare};
pub use scenario::ExperimentScenario;

/// Why an experiment could not be set up or run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The scenario file is wrong (message names the key).
    #[error("{path}: {message}")]
    Scenario {
        /// Scenario name or file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A stage failed.
    #[error("{stage}: {message}")]
    Stage {
        /// Which stage.
        stage: &'static str,
        /// What went wrong.
        message: String,
    },
}

impl ExperimentError {
    pub(crate) fn stage(stage: &'static str, e: impl std::fmt::Display) -> ExperimentError {
        ExperimentError::Stage {
            stage,
            message: e.to_string(),
        }
    }
}

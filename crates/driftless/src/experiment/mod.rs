//! The seed paper's experiment end to end (issue 7): Allan analysis of a static log →
//! noise model (filter tuning); chamber soak → thermal model; a vehicle run processed
//! with GNSS outages as (a) raw, (b) room-temperature calibration only (the paper's
//! "uncompensated": biases removed at 25 °C), (c) room calibration + thermal model —
//! forward filter (real time) and RTS-smoothed — and per-outage errors against a
//! reference (the truth when simulated, otherwise the smoothed full-GNSS solution).
//!
//! * [`scenario`]: the TOML file and every check that needs no data;
//! * [`run`]: the stages ([`run::prepare`] fails fast — outage windows are chosen or
//!   checked on a cheap reference before any long computation);
//! * [`monte_carlo`]: repetitions with new seeds, per-case statistics and the ratio
//!   (b)/(c) with a bootstrap interval;
//! * [`table`]: the paper's Table 1 as Markdown and CSV.
//!
//! Convention: the end-of-outage error is the solution's error at its last epoch inside
//! the window against the reference interpolated there ([`crate::eval::metrics`]), for
//! forward and smoothed solutions alike; the maximum is over every epoch in the window.

pub mod monte_carlo;
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

//! The names most programs need, one `use` away:
//!
//! ```
//! use driftless::prelude::*;
//! ```
//!
//! The data types ([`ImuLog`], [`GnssFixes`], [`NavSolution`], [`TimeSpan`]), the crate's
//! [`Error`] and [`Result`], and the entry point of each stage: [`read_log_file`];
//! [`analyse`] / [`NoiseModel`]; [`calibrate_accel`] / [`calibrate_gyro`] and
//! [`CalibrationFile`]; [`fit()`] and [`ThermalModelFile`]; [`run_session`] (whose result
//! [`SessionResult::smooth`]s itself) and [`run_kf_gins_job`]; [`horizontal_rms_m`];
//! [`Scenario`].

pub use crate::allan::analysis::{AnalysisConfig, ChannelResult, analyse};
pub use crate::allan::noise_model::NoiseModel;
pub use crate::calib::model_file::CalibrationFile;
pub use crate::calib::six_position::{
    PositionMean, RateMean, SixPositionOptions, calibrate_accel, calibrate_gyro,
};
pub use crate::data::{DataError, GnssFixes, ImuLog, NavSolution, Quantity, TimeSpan};
pub use crate::error::{Error, Result};
pub use crate::eval::accuracy::horizontal_rms_m;
pub use crate::io::{TextOptions, read_log_file};
pub use crate::nav::filter::{FilterConfig, ImuNoise, SmoothedRun};
pub use crate::nav::kfgins_job::{KfGinsJob, KfGinsJobOptions, run_kf_gins_job};
pub use crate::nav::pipeline::ImuStream;
pub use crate::nav::session::{SessionConfig, SessionResult, run_session};
pub use crate::sim::scenario::{Scenario, Simulation};
pub use crate::thermal::model_file::ThermalModelFile;
pub use crate::thermal::{FitOptions, ThermalFit, fit};

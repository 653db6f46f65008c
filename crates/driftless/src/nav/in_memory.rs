//! The filter on data in memory: an [`ImuStream`] from an [`ImuLog`] of rates, a
//! forward session that smooths itself, and the forward filter's and the smoother's
//! epochs as [`NavSolution`] columns.

use super::filter::NavError;
use super::filter::run::ForwardRun;
use super::filter::smoother::{SmoothedRun, smooth};
use super::pipeline::{
    ImuStream, ImuStreamOptions, PipelineError, RateChannels, imu_from_rates_log,
};
use super::session::SessionResult;
use crate::data::ImuLog;
use crate::eval::reference::from_nav_states;
use crate::io::nav::NavSolution;

impl ImuStream {
    /// Increments for the filter from a log of rates (three angular-rate and three
    /// specific-force channels, gyro x, y, z and accelerometer x, y, z in that order;
    /// time stamps in GPS seconds of week), with the default options: no mounting
    /// rotation, no time shift, a gap of more than two nominal intervals an error. Other
    /// options: [`imu_from_rates_log`].
    pub fn from_log(log: &ImuLog) -> Result<ImuStream, PipelineError> {
        imu_from_rates_log(log, &RateChannels::ByQuantity, &ImuStreamOptions::default())
    }
}

impl ForwardRun {
    /// The filtered states as a trajectory (IMU centre; Euler angles of q_bn), one
    /// epoch per IMU epoch.
    pub fn solution(&self) -> NavSolution {
        from_nav_states(self.epochs.iter().map(|e| &e.nav))
    }
}

impl SmoothedRun {
    /// The smoothed states as a trajectory (IMU centre; Euler angles of q_bn), aligned
    /// with the forward run's epochs.
    pub fn solution(&self) -> NavSolution {
        from_nav_states(self.epochs.iter().map(|e| &e.nav))
    }
}

impl SessionResult {
    /// The forward (real-time) solution.
    pub fn solution(&self) -> NavSolution {
        self.run.solution()
    }

    /// Rauch–Tung–Striebel smoothing of this forward run with the initial state and
    /// filter configuration it ran with ([`smooth`]).
    pub fn smooth(&self) -> Result<SmoothedRun, NavError> {
        smooth(&self.run, &self.init, &self.filter)
    }
}

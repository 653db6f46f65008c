//! Loosely coupled GNSS/INS integration: a 21-state closed-loop error-state Kalman filter
//! (ESKF) around the strapdown mechanization of [`super::mechanization`], its forward
//! driver and the initial alignment.
//!
//! * [`state`]: error-state layout, sensor-error estimates, covariance storage helpers.
//! * [`model`]: continuous-time error dynamics F, process noise, discretization and the
//!   block-sparse covariance propagation.
//! * [`eskf`]: the filter ([`Eskf`]): predict, GNSS position/velocity updates with lever
//!   arm, innovation gating ([`Gate`]), Joseph form, feedback and reset, covariance health checks.
//! * [`run`]: [`run_forward`], the forward pass over an IMU log and GNSS fixes (IMU
//!   increment split at GNSS epochs, outage windows) storing what an RTS smoother needs.
//! * [`aids`]: land-vehicle aids — non-holonomic constraint, standstill detection,
//!   zero-velocity and zero-angular-rate updates.
//! * [`smoother`]: the Rauch–Tung–Striebel smoother over a forward run ([`smooth`]).
//! * [`align`]: static coarse alignment (levelling, gyrocompassing) and heading from GNSS
//!   velocity.
//!
//! Frames and conventions follow [`super::attitude`]: NED navigation frame, body FRD,
//! `q_bn` body → NED. Error conventions (used everywhere in this module):
//!
//! * navigation errors are *estimated minus true*: δr = r̂ − r in NED metres
//!   (δr_N = (R_M + h)δφ, δr_E = (R_N + h)cos φ δλ, δr_D = −δh), δv = v̂ − v, and the
//!   attitude (phi-angle) error φ is defined by Ĉ_bn = (I − [φ×]) C_bn (Groves 2013 §14.2;
//!   Shin 2005 ch. 3, the "phi-angle" model);
//! * sensor-error states are the *residual errors of the compensated outputs*:
//!   ω̂_ib = ω_ib + b_g + diag(ω_ib) s_g, f̂ = f + b_a + diag(f) s_a, i.e. true minus
//!   estimated sensor error. Feedback therefore *adds* them to the estimates.

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix equations

pub mod aids;
pub mod align;
pub mod eskf;
pub mod model;
pub mod run;
pub mod smoother;
pub mod state;

pub use aids::{NhcConfig, StandstillConfig, StandstillDetector};
pub use align::{
    AlignConfig, Alignment, coarse_align_static, heading_from_gnss_velocity, level_static,
};
pub use eskf::{Eskf, UpdateKind, UpdateOutcome};
pub use model::{FilterConfig, Gate, GaussMarkov, ImuNoise, QualityScale, Transition};
pub use run::{
    EpochRecord, ForwardRun, InitialState, RecoveryEvent, RecoveryTrigger, RunOptions,
    UpdateRecord, run_forward, run_forward_observed, run_forward_with,
};
pub use smoother::{SmoothedEpoch, SmoothedRun, smooth, smooth_with_covariances};
pub use state::{N_STATES, SensorErrors};

/// Errors of the navigation filter, its driver and the alignment.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NavError {
    /// The covariance lost symmetry, positive definiteness or finiteness.
    #[error("covariance check failed at t = {time_s} s: {diagnosis}")]
    Covariance {
        /// Epoch of the failed check, s.
        time_s: f64,
        /// What was wrong (state index, value).
        diagnosis: String,
    },
    /// An IMU increment that cannot be processed (non-finite, dt ≤ 0, …).
    #[error("invalid IMU increment at t = {time_s} s: {reason}")]
    InvalidIncrement {
        /// End time of the increment, s.
        time_s: f64,
        /// Why.
        reason: String,
    },
    /// IMU epochs duplicated, out of order or with a gap.
    #[error("IMU time error at t = {time_s} s: {reason}")]
    ImuTiming {
        /// Offending epoch, s.
        time_s: f64,
        /// Why.
        reason: String,
    },
    /// A measurement that cannot be used (σ ≤ 0, non-finite values, inconsistent columns).
    #[error("invalid measurement at t = {time_s} s: {reason}")]
    InvalidMeasurement {
        /// Epoch, s.
        time_s: f64,
        /// Why.
        reason: String,
    },
    /// Invalid configuration value.
    #[error("invalid filter configuration: {0}")]
    Config(String),
    /// Alignment impossible or refused.
    #[error("alignment failed: {0}")]
    Alignment(String),
}

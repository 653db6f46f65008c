//! Navigation: Earth model, attitude conventions, strapdown mechanization, the loosely
//! coupled GNSS/INS error-state Kalman filter and the Rauch–Tung–Striebel smoother.
//!
//! In memory: [`session::run_session`] on an [`pipeline::ImuStream`] and
//! [`crate::io::nav::GnssFixes`] gives the forward run; [`session::SessionResult::smooth`]
//! smooths it; `.solution()` on either gives the trajectory. From files:
//! [`kfgins_job`] runs a KF-GINS configuration.
//!
//! Frames: navigation = local NED, body = forward-right-down, Earth = WGS-84. SI inside.

pub mod attitude;
pub mod config;
pub mod earth;
pub mod filter;
pub mod gnss_floor;
pub mod imu_check;
pub mod in_memory;
pub mod job;
pub mod kfgins_job;
pub mod mechanization;
pub mod outage;
pub mod pipeline;
pub mod session;

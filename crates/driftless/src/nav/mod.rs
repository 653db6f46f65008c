//! Navigation: Earth model, attitude conventions, strapdown mechanization and (next) the
//! GNSS/INS error-state Kalman filter and smoother.
//!
//! Frames: navigation = local NED, body = forward-right-down, Earth = WGS-84. SI inside.

pub mod attitude;
pub mod config;
pub mod earth;
pub mod filter;
pub mod gnss_floor;
pub mod imu_check;
pub mod job;
pub mod kfgins_job;
pub mod mechanization;
pub mod outage;
pub mod pipeline;
pub mod session;

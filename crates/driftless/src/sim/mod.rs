//! Simulation with known truth.
//!
//! * [`rng`]: seedable xoshiro256++ generator with a ziggurat standard normal.
//! * [`noise`]: static IMU noise (quantization, white, bias instability, rate random walk,
//!   rate ramp, Gauss-Markov, turn-on bias) following IEEE Std 952-1997 Annex C.
//! * [`gnss`]: GNSS fixes at the antenna of a trajectory (lever arm, σ, quality flags,
//!   outage windows).
//! * [`ideal_imu`]: error-free IMU increments along analytic trajectories.
//! * [`recorded`]: a smooth trajectory through recorded positions (smoothing splines,
//!   attitude from the velocity direction).
//! * [`profile`]: land-vehicle motion profiles in TOML.

pub mod gnss;
pub mod ideal_imu;
pub mod noise;
pub mod profile;
pub mod recorded;
pub mod rng;
mod spline;

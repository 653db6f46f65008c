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
//! * [`temperature`]: sensor temperature profiles (constant, chamber steps with a
//!   first-order lag, warm-up, user series).
//! * [`sensor`]: the six-axis sensor-error model (bias, scale factor, misalignment,
//!   g-sensitivity, thermal polynomials, noise, quantization) applied to ideal rates or
//!   increments ([`sensor_config`]: its configuration, [`sensor_data`]: ideal input and
//!   simulated output); [`presets`]: named sensor classes.
//! * [`chamber`]: the thermal-chamber calibration protocol as a trajectory plus a
//!   segment manifest ([`crate::calib::protocol`]).

pub mod chamber;
pub mod gnss;
pub mod ideal_imu;
pub mod noise;
pub mod presets;
pub mod profile;
pub mod recorded;
pub mod rng;
pub mod scenario;
pub mod sensor;
pub mod sensor_config;
pub mod sensor_data;
pub mod sensor_error;
mod spline;
pub mod temperature;

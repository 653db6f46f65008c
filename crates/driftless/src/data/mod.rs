//! The validated in-memory types every stage works on, between the readers of
//! [`crate::io`] and the algorithms:
//!
//! * [`ImuLog`]: an IMU log as columns in SI units (rates or increments, temperature),
//!   with optional time stamps — what noise analysis, calibration and thermal fits read.
//!   Build one from arrays with [`ImuLog::from_rates`].
//! * [`GnssFixes`]: GNSS positions (and velocities) with their σ — the filter's aiding.
//!   Build one from arrays with [`GnssFixes::new`].
//! * [`NavSolution`], [`NavStd`], [`ImuErrors`]: what a filter or smoother produces.
//! * [`TimeSpan`]: an interval of time.
//!
//! The constructors check what the algorithms rely on (equal column lengths, finite
//! values, increasing time, positive σ) and say which column and row is wrong.

pub mod imu;
pub mod nav;
mod span;
mod validate;

pub use imu::{Channel, ImuLog, Quantity, TimeGap};
pub use nav::{GnssFixes, ImuErrors, ImuIncrements, NavSolution, NavStd, quality};
pub use span::TimeSpan;
pub use validate::DataError;

//! Numerical helpers shared by every stage, one implementation each:
//!
//! * [`normal`] — erfc, the standard normal CDF Φ and its inverse Φ⁻¹;
//! * [`mod@cholesky`] — dense Cholesky factorisation, solves and inverse of small SPD
//!   matrices (least squares, covariance whitening);
//! * [`splitmix`] — the SplitMix64 mixer used to seed generators and derive sub-seeds;
//! * [`order`] — medians of samples (sorting with `f64::total_cmp`, NaN-safe).
//!
//! No external crate: each function states its algorithm and its source.

pub mod cholesky;
pub mod normal;
pub mod order;
pub mod splitmix;

pub use cholesky::{cholesky, cholesky_inverse, cholesky_solve};
pub use normal::{erfc, normal_cdf, normal_quantile};
pub use order::{median, upper_median};
pub use splitmix::{splitmix64, splitmix64_mix};

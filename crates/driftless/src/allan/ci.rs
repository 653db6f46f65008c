//! Confidence intervals for the stability estimators.
//!
//! OWNER: helper "ci" — Greenhall–Riley EDF, chi-square quantiles, lag-1 ACF noise ID.
//! Signatures below are the contract the rest of the crate codes against.

use super::{AllanError, Estimator};

/// Equivalent degrees of freedom of `estimator` at averaging factor `m` for power-law
/// noise exponent `alpha` (frequency PSD ∝ f^alpha, −2..=2) with `n_phase` phase points
/// (Greenhall & Riley 2003; SP 1065 §5.3; TOTDEV per SP 1065 Table 12).
pub fn edf(estimator: Estimator, alpha: i32, m: usize, n_phase: usize) -> f64 {
    let _ = (estimator, alpha, m, n_phase);
    todo!("helper ci")
}

/// Quantile of the chi-square distribution with `dof` (real, > 0) degrees of freedom.
pub fn chi2_quantile(p: f64, dof: f64) -> f64 {
    let _ = (p, dof);
    todo!("helper ci")
}

/// Two-sided confidence bounds (lo, hi) of a deviation `dev` with `edf` degrees of
/// freedom at confidence `cl` (e.g. 0.683): σ·√(edf/χ²(1−(1−cl)/2)), σ·√(edf/χ²((1−cl)/2)).
pub fn bounds(dev: f64, edf: f64, cl: f64) -> (f64, f64) {
    let _ = (dev, edf, cl);
    todo!("helper ci")
}

/// Dominant power-law noise exponent alpha at averaging factor `m`, identified by the
/// lag-1 autocorrelation method (Riley & Greenhall 2004) on phase data `phase`.
/// `estimator` selects the allowed alpha range (−2..=2 for Allan types, −4..=2 Hadamard).
pub fn identify_alpha(phase: &[f64], m: usize, estimator: Estimator) -> Result<i32, AllanError> {
    let _ = (phase, m, estimator);
    todo!("helper ci")
}

/// EDF of the reduced-overlap OADEV (second differences every `stride` samples).
pub fn edf_strided(alpha: i32, m: usize, stride: usize, n_phase: usize) -> f64 {
    let _ = (alpha, m, stride, n_phase);
    todo!("helper ci")
}

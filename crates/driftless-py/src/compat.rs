//! The allantools calling convention on top of the library's estimators.
//!
//! allantools (`adev`, `oadev`, … `totdev`) returns `(taus, devs, errs, ns)` where
//! τ = m/rate, `errs = dev/√n` (n = the estimator's number of terms, SP 1065 §5.2), and
//! every factor with n ≤ 1 is dropped. The averaging factors m themselves are chosen on
//! the Python side (`driftless/__init__.py`), where NumPy's rounding is at hand.

use driftless::allan::estimators::{finish, sums};
use driftless::allan::phase::frequency_to_phase;
use driftless::allan::{AllanError, Estimator, MAX_SAMPLE_MAGNITUDE};

/// One allantools-style result: equal-length columns.
#[derive(Debug, Default, PartialEq)]
pub struct CompatCurve {
    /// τ = m/rate, s.
    pub taus_s: Vec<f64>,
    /// The deviation at each τ.
    pub devs: Vec<f64>,
    /// dev/√n.
    pub errs: Vec<f64>,
    /// Terms summed (as f64, the type allantools returns).
    pub ns: Vec<f64>,
}

/// First non-finite or out-of-range sample, as the library's error.
pub fn check_samples(values: &[f64]) -> Result<(), AllanError> {
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(AllanError::NonFinite {
            index,
            value: values[index],
        });
    }
    if let Some(index) = values.iter().position(|v| v.abs() > MAX_SAMPLE_MAGNITUDE) {
        return Err(AllanError::OutOfRange {
            index,
            value: values[index],
            limit: MAX_SAMPLE_MAGNITUDE,
        });
    }
    Ok(())
}

/// τ0 = 1/rate for a positive, finite sample rate.
pub fn sample_interval_s(rate_hz: f64) -> Result<f64, AllanError> {
    if rate_hz.is_finite() && rate_hz > 0.0 {
        Ok(1.0 / rate_hz)
    } else {
        Err(AllanError::Invalid(format!(
            "rate must be a positive number of samples per second, got {rate_hz}"
        )))
    }
}

/// Deviations of `estimator` on `data` (phase, or rates when `is_frequency`) at the
/// averaging factors `ms`, in allantools' form. Rates are integrated to phase with the
/// mean removed (x₀ = 0, N+1 points), as allantools' `frequency2phase` does.
pub fn curve(
    estimator: Estimator,
    data: &[f64],
    rate_hz: f64,
    is_frequency: bool,
    ms: &[usize],
) -> Result<CompatCurve, AllanError> {
    let tau0_s = sample_interval_s(rate_hz)?;
    check_samples(data)?;
    let integrated;
    let phase: &[f64] = if is_frequency {
        integrated = frequency_to_phase(data, tau0_s);
        &integrated
    } else {
        data
    };
    let mut out = CompatCurve::default();
    for s in sums(estimator, phase, ms) {
        if s.n <= 1 {
            continue;
        }
        let dev = finish(estimator, s, tau0_s);
        let n = s.n as f64;
        out.taus_s.push(s.m as f64 / rate_hz);
        out.devs.push(dev);
        out.errs.push(dev / n.sqrt());
        out.ns.push(n);
    }
    if out.taus_s.is_empty() {
        return Err(AllanError::Invalid(format!(
            "{} has no tau with at least 2 terms: {} phase points, averaging factors {:?}; \
             give shorter taus or more data",
            estimator.name(),
            phase.len(),
            &ms[..ms.len().min(8)]
        )));
    }
    Ok(out)
}

//! Confidence intervals for the stability estimators.
//!
//! A stability variance estimate σ̂² is modelled as σ²·χ²_ν/ν with ν the *equivalent
//! degrees of freedom* (EDF) of the estimator for the dominant power-law noise
//! (NIST SP 1065, Riley 2008, §5.3). The pieces:
//!
//! * [`edf`] — ν per estimator: the Greenhall–Riley (2003) general algorithm
//!   ([`edf_greenhall`]) for ADEV, OADEV, MDEV, TDEV, HDEV, OHDEV and the SP 1065
//!   empirical b·T/τ − c law for TOTDEV ([`edf_totdev`]);
//! * [`chi2_quantile`] — χ² quantiles for real ν (own implementation, see [`chi2`]);
//! * [`bounds`] — the two-sided interval, SP 1065 eq. (45);
//! * [`identify_alpha`] — the noise exponent α that selects ν, by the lag-1
//!   autocorrelation method (Riley & Greenhall 2004) with a B1/R(n) fallback.

pub mod chi2;
pub mod greenhall;
pub mod noise_id;

pub use chi2::{chi2_cdf, chi2_quantile};
pub use greenhall::edf_greenhall;
pub(crate) use noise_id::NoiseId;
pub use noise_id::lag1_acf;
pub(crate) use noise_id::{acf_noise_id, b1_noise_id};

use super::{AllanError, Estimator};

/// The 1-σ confidence level erf(1/√2) ≈ 0.6827 (Stable32 prints it as 0.683).
pub const ONE_SIGMA_CL: f64 = 0.682_689_492_137_085_9;

/// Range of alpha the estimator's EDF model covers: −2..=2 for the Allan family
/// (the Allan variance diverges for α ≤ −3), −4..=2 for the Hadamard variances.
pub fn alpha_range(estimator: Estimator) -> (i32, i32) {
    if estimator.is_hadamard() {
        (-4, 2)
    } else {
        (-2, 2)
    }
}

/// (d, S, F) of an estimator at factor m in Greenhall–Riley terms: difference order d
/// (2 Allan, 3 Hadamard), stride factor S (1 non-overlapping, m overlapping — terms
/// m/S samples apart) and filter factor F (m unmodified, 1 modified).
/// `None` for TOTDEV, which is not a plain finite-difference variance.
pub fn greenhall_params(estimator: Estimator, m: usize) -> Option<(u32, f64, f64)> {
    let mf = m.max(1) as f64;
    match estimator {
        Estimator::Adev => Some((2, 1.0, mf)),
        Estimator::Oadev => Some((2, mf, mf)),
        Estimator::Mdev | Estimator::Tdev => Some((2, mf, 1.0)),
        Estimator::Hdev => Some((3, 1.0, mf)),
        Estimator::Ohdev => Some((3, mf, mf)),
        Estimator::Totdev => None,
    }
}

/// Equivalent degrees of freedom of `estimator` at averaging factor `m` for power-law
/// noise exponent `alpha` (frequency PSD ∝ f^alpha, −2..=2) with `n_phase` phase points
/// (Greenhall & Riley 2003; SP 1065 §5.3; TOTDEV per SP 1065 Table 12).
///
/// * ADEV/OADEV/MDEV/TDEV/HDEV/OHDEV: [`edf_greenhall`] with the (d, S, F) of
///   [`greenhall_params`]; TDEV has the EDF of MDEV (TVAR = τ²/3·MVAR).
/// * TOTDEV: [`edf_totdev`].
///
/// `alpha` outside [`alpha_range`] is clamped into it; `m = 0` is treated as 1. The
/// result is always finite and ≥ 1 (1 when `n_phase` is too short for a single term).
pub fn edf(estimator: Estimator, alpha: i32, m: usize, n_phase: usize) -> f64 {
    let (lo, hi) = alpha_range(estimator);
    let alpha = alpha.clamp(lo, hi);
    match greenhall_params(estimator, m) {
        Some((d, s, f)) => edf_greenhall(alpha, d, m, s, f, n_phase),
        None => edf_totdev(alpha, m, n_phase),
    }
}

/// EDF of the reduced-overlap ("fast") OADEV whose second differences are taken every
/// `stride` samples (1 = fully overlapping OADEV, m = non-overlapping ADEV): Greenhall–
/// Riley with d = 2, F = m and stride factor S = m/stride ([`edf_greenhall`]); then
/// M = 1 + ⌊(N − 1 − 2m)/stride⌋ terms, the count the strided estimator sums.
///
/// `stride` is clamped to 1..=m, `alpha` to −2..=2; finite and ≥ 1 like [`edf`].
pub(crate) fn edf_strided(alpha: i32, m: usize, stride: usize, n_phase: usize) -> f64 {
    let m = m.max(1);
    let stride = stride.clamp(1, m);
    let s = m as f64 / stride as f64;
    edf_greenhall(alpha.clamp(-2, 2), 2, m, s, m as f64, n_phase)
}

/// EDF of the total deviation (SP 1065 §5.2.11, Table 12; Howe & Greenhall):
///
/// ```text
/// edf = b·(T/τ) − c,   T/τ = (N − 1)/m  (record length over averaging time)
/// ```
///
/// with (b, c) = (1.50, 0) white FM, (1.17, 0.22) flicker FM, (0.93, 0.36) random-walk
/// FM. The table has no PM rows; for α = 1, 2 the SP 1065 §5.3.2 (Table 5) simple
/// Allan-variance approximations [`edf_simple_pm`] are used, as Stable32 does (this
/// reproduces Stable32's TOTDEV intervals on the OCXO reference set).
/// The result is floored at 1 (tiny N, m ≥ N).
pub fn edf_totdev(alpha: i32, m: usize, n_phase: usize) -> f64 {
    let m = m.max(1);
    let (b, c) = match alpha.clamp(-2, 2) {
        0 => (1.50, 0.0),
        -1 => (1.17, 0.22),
        -2 => (0.93, 0.36),
        a => return edf_simple_pm(a, m, n_phase),
    };
    let t_over_tau = n_phase.saturating_sub(1) as f64 / m as f64;
    (b * t_over_tau - c).max(1.0)
}

/// Simple EDF approximations for the Allan variance under PM noise (SP 1065 §5.3.2,
/// Table 5, after Howe, Allan & Barnes 1981), N = phase points:
///
/// ```text
/// white PM   (α = 2):  edf = (N + 1)(N − 2m) / (2(N − m))
/// flicker PM (α = 1):  edf = exp √( ln((N − 1)/(2m)) · ln((2m + 1)(N − 1)/4) )
/// ```
///
/// Any other `alpha` is treated as the nearer of the two. Floored at 1.
pub fn edf_simple_pm(alpha: i32, m: usize, n_phase: usize) -> f64 {
    let m = m.max(1) as f64;
    let n = n_phase as f64;
    let e = if alpha >= 2 {
        (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m))
    } else {
        let a = ((n - 1.0) / (2.0 * m)).ln();
        let b = ((2.0 * m + 1.0) * (n - 1.0) / 4.0).ln();
        if a > 0.0 && b > 0.0 {
            (a * b).sqrt().exp()
        } else {
            1.0
        }
    };
    if e.is_finite() { e.max(1.0) } else { 1.0 }
}

/// Two-sided confidence bounds (lo, hi) of a deviation `dev` with `edf` degrees of
/// freedom at confidence `cl` (e.g. 0.683): σ·√(edf/χ²(1−(1−cl)/2)), σ·√(edf/χ²((1−cl)/2)).
///
/// This is SP 1065 eq. (45) for the variance, square-rooted, with exact χ² quantiles.
///
/// Stable32 1.60 differs slightly (reconstructed from its reference outputs): for
/// edf > 100 it uses the Wilson–Hilferty approximation with z = Φ⁻¹(0.84) ≈ 0.9945
/// instead of the exact quantiles at the requested level, so its intervals there are
/// about 0.6 % narrower in half-width (≤ 5e-4 relative in the bounds); for edf ≤ 100
/// it agrees with this function at cl = erf(1/√2) to the printed 5 digits.
///
/// Degenerate inputs never
/// give NaN: `cl` is clamped to [0, 1] (non-finite `cl` means [`ONE_SIGMA_CL`]);
/// `edf` = +∞ gives (dev, dev); `edf` ≤ 0 or NaN (no information) gives (0, +∞), as
/// does `cl` = 1. A NaN `dev` is returned as is.
pub fn bounds(dev: f64, edf: f64, cl: f64) -> (f64, f64) {
    let cl = if cl.is_finite() {
        cl.clamp(0.0, 1.0)
    } else {
        ONE_SIGMA_CL
    };
    if edf == f64::INFINITY {
        return (dev, dev);
    }
    if edf.is_nan() || edf <= 0.0 || cl >= 1.0 {
        return (0.0, f64::INFINITY);
    }
    let p_lo = 0.5 * (1.0 - cl);
    let chi_hi = chi2_quantile(1.0 - p_lo, edf);
    let chi_lo = chi2_quantile(p_lo, edf);
    let lo = if chi_hi > 0.0 {
        dev * (edf / chi_hi).sqrt()
    } else {
        f64::INFINITY
    };
    let hi = if chi_lo > 0.0 {
        dev * (edf / chi_lo).sqrt()
    } else {
        f64::INFINITY
    };
    (lo, hi)
}

/// Dominant power-law noise exponent alpha at averaging factor `m`, identified by the
/// lag-1 autocorrelation method (Riley & Greenhall 2004) on phase data `phase`.
/// `estimator` selects the allowed alpha range (−2..=2 for Allan types, −4..=2 Hadamard).
///
/// Procedure (SP 1065 §5.6): decimate the phase by m, remove a quadratic, difference up
/// to d_max = 2 (Allan family) or 3 (Hadamard) times until δ = r1/(1+r1) < 0.25;
/// α = round(−2(δ + d)) + 2, clamped to [`alpha_range`].
///
/// With fewer than 30 decimated points the B1 ratio with R(n) is used instead
/// (`b1_noise_id`, α ∈ −2..=2); with fewer than 4 frequency averages at m, the ACF at
/// the largest factor that still leaves 30 points is used (the noise type of the
/// longest τ that can be identified). Errors: `m = 0`, non-finite samples, or fewer
/// than 5 phase points.
///
/// Known limits (measured on synthetic noise in this module's tests): at m > 1 the
/// decimation aliases flicker PM toward white PM (≈ 1 in 3 misses at 512 points), and
/// the m-averaging inherent in decimated phase biases flicker-walk FM (α = −3) toward
/// −4; at m = 1 both are identified reliably.
pub fn identify_alpha(phase: &[f64], m: usize, estimator: Estimator) -> Result<i32, AllanError> {
    identify_noise(phase, m, estimator).map(|id| id.alpha)
}

/// [`identify_alpha`] with the method and its statistics.
pub(crate) fn identify_noise(
    phase: &[f64],
    m: usize,
    estimator: Estimator,
) -> Result<NoiseId, AllanError> {
    if m == 0 {
        return Err(AllanError::Invalid(
            "noise identification needs an averaging factor m ≥ 1".into(),
        ));
    }
    // The methods below read only every k-th phase point (k = m, or a coarser stride in
    // the fallbacks), at most MAX_ACF_POINTS of them: check exactly those, so a 10⁷-point
    // log is not rescanned per tau.
    let check = |k: usize| -> Result<(), AllanError> {
        match phase
            .iter()
            .enumerate()
            .step_by(k.max(1))
            .take(noise_id::MAX_ACF_POINTS)
            .find(|(_, v)| !v.is_finite())
        {
            Some((index, &value)) => Err(AllanError::NonFinite { index, value }),
            None => Ok(()),
        }
    };
    check(m)?;
    let dmax = if estimator.is_hadamard() { 3 } else { 2 };
    let (lo, hi) = alpha_range(estimator);
    let clamp = |mut id: NoiseId| {
        id.alpha = id.alpha.clamp(lo, hi);
        id
    };
    if let Some(id) = acf_noise_id(phase, m, dmax) {
        return Ok(clamp(id));
    }
    if let Some(id) = b1_noise_id(phase, m) {
        return Ok(clamp(id));
    }
    if phase.len() >= noise_id::MIN_ACF_POINTS {
        let m_acf = ((phase.len() - 1) / (noise_id::MIN_ACF_POINTS - 1)).max(1);
        check(m_acf)?;
        if let Some(id) = acf_noise_id(phase, m_acf, dmax) {
            return Ok(clamp(id));
        }
    }
    check(1)?;
    if let Some(id) = b1_noise_id(phase, 1) {
        return Ok(clamp(id));
    }
    Err(AllanError::Invalid(format!(
        "noise identification at m = {m} needs at least {} phase points; the data has {}",
        noise_id::MIN_B1_POINTS + 1,
        phase.len()
    )))
}

#[cfg(test)]
mod tests;

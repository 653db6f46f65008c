//! Local log-log slopes of the curve and the classic single-point slope readings.

use serde::{Deserialize, Serialize};

use super::BIAS_ADEV_FLOOR;

/// α from the local log-log slope of the Allan variance (3-point centred differences).
pub(super) fn slope_alpha(tau: &[f64], avar: &[f64]) -> Vec<i32> {
    let n = tau.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(2), (i + 2).min(n.saturating_sub(1)));
            if b <= a || tau[b] <= tau[a] || avar[a] <= 0.0 || avar[b] <= 0.0 {
                return 0;
            }
            let mu = (avar[b] / avar[a]).ln() / (tau[b] / tau[a]).ln();
            ((-mu - 1.0).round() as i32).clamp(-2, 2)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Classic slope readings.

/// The classic graphical readings of an Allan-deviation curve (IEEE Std 952-1997
/// Fig. C.2; El-Sheimy et al. 2008): a diagnostic next to the full fit, which is
/// considerably more accurate for K and B.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeReadings {
    /// N: value at τ = 1 s of the −½-slope line through the point whose local slope is
    /// closest to −½ (None if no point has a slope within ±0.15 of −½), u·√s.
    pub white: Option<f64>,
    /// B = σ_min/0.664 if the minimum is interior to the curve, u.
    pub bias_instability: Option<f64>,
    /// τ of the minimum, s.
    pub tau_min: Option<f64>,
    /// K: value at τ = 3 s of the +½-slope line through the point whose local slope is
    /// closest to +½ (None if none within ±0.15), u/√s.
    pub rate_random_walk: Option<f64>,
}

/// Classic slope readings from an Allan **deviation** curve (ascending tau). Local slopes
/// are centred log-log differences over ±2 points.
pub fn slope_readings(tau: &[f64], adev: &[f64]) -> SlopeReadings {
    let n = tau.len().min(adev.len());
    let ok = |i: usize| tau[i] > 0.0 && adev[i] > 0.0 && tau[i].is_finite() && adev[i].is_finite();
    let slope = |i: usize| -> Option<f64> {
        let (a, b) = (i.saturating_sub(2), (i + 2).min(n.saturating_sub(1)));
        if b <= a || !ok(a) || !ok(b) || tau[b] <= tau[a] {
            return None;
        }
        Some((adev[b] / adev[a]).ln() / (tau[b] / tau[a]).ln())
    };
    let closest = |target: f64| -> Option<usize> {
        (0..n)
            .filter(|&i| ok(i))
            .filter_map(|i| slope(i).map(|s| (i, (s - target).abs())))
            .filter(|&(_, d)| d < 0.15)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    let white = closest(-0.5).map(|i| adev[i] * tau[i].sqrt());
    let rate_random_walk = closest(0.5).map(|i| adev[i] * (3.0 / tau[i]).sqrt());
    let imin = (0..n)
        .filter(|&i| ok(i))
        .min_by(|&a, &b| adev[a].total_cmp(&adev[b]));
    let (bias_instability, tau_min) = match imin {
        Some(i) if i > 0 && i + 1 < n => (Some(adev[i] / BIAS_ADEV_FLOOR), Some(tau[i])),
        _ => (None, None),
    };
    SlopeReadings {
        white,
        bias_instability,
        tau_min,
        rate_random_walk,
    }
}

//! Whether a record suits a noise analysis: the Allan-variance noise terms describe a
//! *stationary* process (IEEE Std 952-1997 Annex C assumes the sensor at rest in a
//! constant environment), and a term can only be read at averaging times τ the record
//! covers many times over.
//!
//! * Stationarity: the sample variance s_w² of consecutive windows of W samples (each
//!   about 1 s, 10 ≤ W ≤ N/20), each about its own mean. For a stationary record whose
//!   short-term noise is white, (W − 1)s_w²/σ² follows χ²_{W−1}, so the ratio of the
//!   90th to the 10th percentile of s_w² is about q₀.₉/q₀.₁ of χ²_{W−1} (Wilson–Hilferty:
//!   q_p(k) ≈ k(1 − 2/(9k) + z_p√(2/(9k)))³); 1.4 for W = 100. Motion (a vehicle turning,
//!   stopping, vibrating) makes the short-term variance change by orders of magnitude. A
//!   ratio above `NON_STATIONARY_FACTOR` times the expected one is reported.
//! * Record length: a fitted bias-instability, rate-random-walk, rate-ramp or
//!   Gauss–Markov term is *read* where it dominates the fitted model; where that is only
//!   at τ > T/10 (T the record length), fewer than 10 independent averages carry it, and
//!   where it dominates at no analysed τ it is extrapolated, not measured.
//!
//! The fit's χ²_red is no test of stationarity: it is 98 on the gyro z of a real car drive
//! but 480–2070 on the six channels of a real ADIS16405 at rest (filtering below 0.2 s, a
//! 0.5 Hz line; the points are correlated and their EDF large), so it is not used here.

use super::fit::{NoiseFit, TermKind};

/// How many times the expected percentile ratio of the window variances counts as
/// non-stationary.
pub(crate) const NON_STATIONARY_FACTOR: f64 = 10.0;

/// χ²_k quantile at standard-normal quantile z (Wilson–Hilferty).
pub(crate) fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3).max(0.0)
}

/// The stationarity figures of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Stationarity {
    /// Window length W, samples.
    pub window_samples: usize,
    /// Ratio of the 90th to the 10th percentile of the window variances.
    pub ratio: f64,
    /// The same ratio expected for stationary white noise.
    pub expected_ratio: f64,
}

impl Stationarity {
    /// True when the ratio exceeds `NON_STATIONARY_FACTOR` × the expected one.
    pub fn is_static(&self) -> bool {
        self.ratio <= NON_STATIONARY_FACTOR * self.expected_ratio || self.ratio.is_nan()
    }
}

/// The window-variance test of the module on rate (frequency) data `y` sampled every
/// `tau0_s`. `None` when the record has fewer than 20 windows of 10 samples, or when
/// the lower percentile is zero (a quantized output constant over whole windows).
pub fn stationarity(y: &[f64], tau0_s: f64) -> Option<Stationarity> {
    let n = y.len();
    if n < 200 || !(tau0_s > 0.0 && tau0_s.is_finite()) {
        return None;
    }
    let w = ((1.0 / tau0_s).round() as usize).clamp(10, n / 20);
    let mut vars: Vec<f64> = y
        .chunks_exact(w)
        .map(|c| {
            let m = c.iter().sum::<f64>() / w as f64;
            c.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (w - 1) as f64
        })
        .filter(|v| v.is_finite())
        .collect();
    if vars.len() < 20 {
        return None;
    }
    vars.sort_by(f64::total_cmp);
    let at = |q: f64| vars[((vars.len() - 1) as f64 * q).round() as usize];
    let (lo, hi) = (at(0.1), at(0.9));
    if lo <= 0.0 {
        return None;
    }
    let k = (w - 1) as f64;
    let z = 1.281_551_565_544_6;
    Some(Stationarity {
        window_samples: w,
        ratio: hi / lo,
        expected_ratio: chi2_quantile(k, z) / chi2_quantile(k, -z),
    })
}

/// A warning when channel `name` (rate data `y`, one sample every `tau0_s`) is not
/// static by [`stationarity`].
pub fn stationarity_warning(name: &str, y: &[f64], tau0_s: f64) -> Option<String> {
    let s = stationarity(y, tau0_s)?;
    if s.is_static() {
        return None;
    }
    Some(format!(
        "{name}: the input is not static: the variance over {:.3} s windows changes {:.0}-fold between its 10th and 90th percentiles (stationary noise: {:.1}-fold), as when the sensor moves or vibrates; noise terms describe a sensor at rest in a constant environment, so use a log recorded at rest (or only its static part)",
        s.window_samples as f64 * tau0_s,
        s.ratio,
        s.expected_ratio
    ))
}

/// Warnings for the fitted long-τ terms of channel `name` whose reading the record does
/// not support (module rule), `taus` the analysed averaging times, `record_s` the
/// record length T.
pub fn record_length_warnings(
    name: &str,
    fit: &NoiseFit,
    taus: &[f64],
    record_s: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    let tau_max = taus.iter().copied().fold(0.0, f64::max);
    for kind in [
        TermKind::BiasInstability,
        TermKind::RateRandomWalk,
        TermKind::RateRamp,
        TermKind::GaussMarkov,
    ] {
        if !fit.term(kind).is_some_and(|t| t.value > 0.0) {
            continue;
        }
        let first = taus
            .iter()
            .copied()
            .find(|&t| fit.dominant_term(t) == Some(kind));
        match first {
            None => out.push(format!(
                "{name}: the fitted {} dominates the model at no analysed τ (up to {} s of a {} s record): it is extrapolated, not measured; record at least 10× longer than the τ where it should show, or drop it from the fitted terms",
                kind.name().replace('_', " "),
                crate::io::error::sig6(tau_max),
                crate::io::error::sig6(record_s)
            )),
            Some(t) if t > record_s / 10.0 => out.push(format!(
                "{name}: the fitted {} is read at τ ≥ {} s, but the record is only {} s long (fewer than 10 independent averages there): record at least {} s, or treat it as an estimate with few degrees of freedom",
                kind.name().replace('_', " "),
                crate::io::error::sig6(t),
                crate::io::error::sig6(record_s),
                crate::io::error::sig6(10.0 * t)
            )),
            Some(_) => {}
        }
    }
    out
}

/// Samples read for [`resolution_step`].
const RESOLUTION_SAMPLES: usize = 200_000;

/// The resolution step Δ of quantized samples: the smallest gap between distinct values
/// of (up to the first 200 000) samples, accepted when the values repeat (fewer distinct
/// values than a tenth of the samples) and at least 95 % of the gaps between neighbouring
/// distinct values are whole multiples of it (within 1 %). None for unquantized data.
pub fn resolution_step(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values
        .iter()
        .take(RESOLUTION_SAMPLES)
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    if v.len() < 100 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    v.dedup();
    if v.len() < 2 || v.len() * 10 > values.len().min(RESOLUTION_SAMPLES) {
        return None;
    }
    let gaps: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let step = gaps.iter().copied().fold(f64::INFINITY, f64::min);
    if !(step > 0.0 && step.is_finite()) {
        return None;
    }
    let whole = gaps
        .iter()
        .filter(|&&g| {
            let k = g / step;
            (k - k.round()).abs() < 0.01
        })
        .count();
    (whole as f64 >= 0.95 * gaps.len() as f64).then_some(step)
}

#[cfg(test)]
mod tests {

    #[test]
    fn resolution_step_of_quantized_and_continuous_samples() {
        let step = 0.05 * std::f64::consts::PI / 180.0;
        let q: Vec<f64> = (0..10_000)
            .map(|i| ((i * 7919 % 13) as f64 - 6.0) * step)
            .collect();
        let got = resolution_step(&q).expect("quantized");
        assert!((got / step - 1.0).abs() < 1e-9, "{got}");
        let c: Vec<f64> = (0..10_000).map(|i| (i as f64 * 0.37).sin()).collect();
        assert!(resolution_step(&c).is_none());
        assert!(resolution_step(&q[..50]).is_none());
    }
    use super::*;

    #[test]
    fn chi2_quantiles_are_close() {
        // χ²_99: 10 % 81.45, 90 % 117.4 (tables)
        assert!((chi2_quantile(99.0, -1.2815516) - 81.45).abs() < 0.1);
        assert!((chi2_quantile(99.0, 1.2815516) - 117.4).abs() < 0.1);
    }
}

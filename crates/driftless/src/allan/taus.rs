//! Tau grids: which averaging factors m (τ = m·τ0) to evaluate.
//!
//! `octave` (m = 1, 2, 4, …), `decade` (m = 1, 2, 5, 10, 20, 50, …), `all` (every m),
//! `log:N` (N log-spaced factors between 1 and the largest allowed, rounded and
//! deduplicated, so fewer than N may come back for short logs) or an explicit
//! comma-separated list of taus in seconds. Grids stop at the estimator's largest
//! factor ([`Estimator::max_m`]), which reproduces Stable32's lists.

use super::{AllanError, Estimator};
use std::str::FromStr;

/// A tau-grid specification as given on the command line.
#[derive(Clone, Debug, PartialEq)]
pub enum TauSpec {
    /// m = 2^k.
    Octave,
    /// m = 1, 2, 5 × 10^k.
    Decade,
    /// Every m from 1 to the maximum.
    All,
    /// N log-spaced m, deduplicated.
    Log(usize),
    /// Explicit taus in seconds.
    List(Vec<f64>),
}

impl FromStr for TauSpec {
    type Err = AllanError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = |why: &str| AllanError::BadTauSpec {
            spec: s.to_string(),
            why: why.to_string(),
        };
        let t = s.trim();
        match t.to_ascii_lowercase().as_str() {
            "octave" => return Ok(TauSpec::Octave),
            "decade" => return Ok(TauSpec::Decade),
            "all" => return Ok(TauSpec::All),
            _ => {}
        }
        if let Some(n) = t.strip_prefix("log:") {
            let n: usize = n
                .trim()
                .parse()
                .map_err(|_| bad("expected log:N with N a positive integer"))?;
            if n == 0 {
                return Err(bad("log:N needs N ≥ 1"));
            }
            return Ok(TauSpec::Log(n));
        }
        let mut taus = Vec::new();
        for (i, part) in t.split(',').enumerate() {
            let p = part.trim();
            let v: f64 = p.parse().map_err(|_| {
                bad(&format!(
                    "item {} ('{p}') is not a number; use octave, decade, all, log:N or a comma-separated list of taus in seconds",
                    i + 1
                ))
            })?;
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(&format!(
                    "item {} ('{p}') must be a positive tau in seconds",
                    i + 1
                )));
            }
            taus.push(v);
        }
        Ok(TauSpec::List(taus))
    }
}

/// Averaging factors for `spec` with sample interval `tau0_s` on `n_phase` phase points.
///
/// Generated grids are cut at [`Estimator::max_m`]; an explicit list that asks for more
/// than the data allows is an error ([`AllanError::TooFewSamples`]), as is any grid
/// that would be empty.
pub fn averaging_factors(
    spec: &TauSpec,
    tau0_s: f64,
    n_phase: usize,
    estimator: Estimator,
) -> Result<Vec<usize>, AllanError> {
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::Invalid(format!(
            "sample interval must be positive, got {tau0_s} s"
        )));
    }
    let max_m = estimator.max_m(n_phase);
    let too_few = |m: usize| AllanError::TooFewSamples {
        estimator: estimator.name(),
        tau: m as f64 * tau0_s,
        m,
        needed: min_samples(estimator, m),
        have: n_phase.saturating_sub(1),
    };
    let ms: Vec<usize> = match spec {
        TauSpec::Octave => {
            let mut v = Vec::new();
            let mut m = 1usize;
            while m <= max_m {
                v.push(m);
                m = match m.checked_mul(2) {
                    Some(x) => x,
                    None => break,
                };
            }
            v
        }
        TauSpec::Decade => {
            let mut v = Vec::new();
            let mut base = 1usize;
            'outer: loop {
                for k in [1usize, 2, 5] {
                    let m = base.saturating_mul(k);
                    if m > max_m {
                        break 'outer;
                    }
                    v.push(m);
                }
                base = match base.checked_mul(10) {
                    Some(b) => b,
                    None => break,
                };
            }
            v
        }
        TauSpec::All => (1..=max_m).collect(),
        TauSpec::Log(n) => log_spaced(*n, max_m),
        TauSpec::List(taus) => {
            let mut v = Vec::with_capacity(taus.len());
            for &tau in taus {
                let m = (tau / tau0_s).round();
                if m < 1.0 {
                    return Err(AllanError::BadTauSpec {
                        spec: format!("{tau}"),
                        why: format!("tau {tau} s is shorter than the sample interval {tau0_s} s"),
                    });
                }
                let m = m as usize;
                if m > max_m {
                    return Err(too_few(m));
                }
                v.push(m);
            }
            v.sort_unstable();
            v.dedup();
            v
        }
    };
    if ms.is_empty() {
        return Err(too_few(1));
    }
    Ok(ms)
}

/// `n` log-spaced integers from 1 to `max_m` inclusive, deduplicated.
fn log_spaced(n: usize, max_m: usize) -> Vec<usize> {
    if max_m == 0 {
        return Vec::new();
    }
    if n == 1 {
        return vec![1];
    }
    let top = (max_m as f64).ln();
    let mut v: Vec<usize> = (0..n)
        .map(|i| {
            let m = (top * i as f64 / (n - 1) as f64).exp().round() as usize;
            m.clamp(1, max_m)
        })
        .collect();
    v.dedup();
    v
}

/// Phase points minus one (= frequency samples) the estimator needs for factor m.
pub(crate) fn min_samples(estimator: Estimator, m: usize) -> usize {
    match estimator {
        Estimator::Adev | Estimator::Hdev => 5 * m,
        Estimator::Oadev | Estimator::Mdev | Estimator::Ohdev | Estimator::Tdev => 4 * m,
        Estimator::Totdev => 2 * m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_specs() {
        assert_eq!("octave".parse::<TauSpec>(), Ok(TauSpec::Octave));
        assert_eq!("log:100".parse::<TauSpec>(), Ok(TauSpec::Log(100)));
        assert_eq!(
            "1, 10,100".parse::<TauSpec>(),
            Ok(TauSpec::List(vec![1.0, 10.0, 100.0]))
        );
        assert!("log:0".parse::<TauSpec>().is_err());
        assert!("1,x".parse::<TauSpec>().is_err());
        assert!("-1".parse::<TauSpec>().is_err());
    }

    #[test]
    fn octave_grid_matches_stable32_limits() {
        // PHASE.DAT: 1001 phase points → ADEV to m=128, TOTDEV to m=256.
        let a = averaging_factors(&TauSpec::Octave, 1.0, 1001, Estimator::Adev).unwrap();
        assert_eq!(*a.last().unwrap(), 128);
        let t = averaging_factors(&TauSpec::Octave, 1.0, 1001, Estimator::Totdev).unwrap();
        assert_eq!(*t.last().unwrap(), 256);
        // ocxo: 19983 phase points → ADEV to 2048, OADEV to 4096, TOTDEV to 8192.
        let a = averaging_factors(&TauSpec::Octave, 1.0, 19983, Estimator::Adev).unwrap();
        assert_eq!(*a.last().unwrap(), 2048);
        let o = averaging_factors(&TauSpec::Octave, 1.0, 19983, Estimator::Oadev).unwrap();
        assert_eq!(*o.last().unwrap(), 4096);
        let t = averaging_factors(&TauSpec::Octave, 1.0, 19983, Estimator::Totdev).unwrap();
        assert_eq!(*t.last().unwrap(), 8192);
    }

    #[test]
    fn log_grid_is_deduplicated_and_bounded() {
        let v = averaging_factors(&TauSpec::Log(100), 0.01, 6_480_001, Estimator::Oadev).unwrap();
        assert_eq!(v.first(), Some(&1));
        assert_eq!(v.last(), Some(&1_620_000));
        assert!(v.windows(2).all(|w| w[0] < w[1]));
        assert!(v.len() > 80 && v.len() <= 100, "{}", v.len());
    }

    #[test]
    fn explicit_list_rounds_and_rejects_too_long() {
        let v = averaging_factors(&TauSpec::List(vec![0.1, 1.0]), 0.01, 1001, Estimator::Oadev)
            .unwrap();
        assert_eq!(v, vec![10, 100]);
        let e = averaging_factors(&TauSpec::List(vec![100.0]), 1.0, 101, Estimator::Oadev);
        assert!(matches!(e, Err(AllanError::TooFewSamples { m: 100, .. })));
        let e = averaging_factors(&TauSpec::Octave, 1.0, 3, Estimator::Oadev);
        assert!(matches!(e, Err(AllanError::TooFewSamples { .. })));
    }

    #[test]
    fn decade_grid() {
        let v = averaging_factors(&TauSpec::Decade, 1.0, 1001, Estimator::Oadev).unwrap();
        assert_eq!(v, vec![1, 2, 5, 10, 20, 50, 100, 200]);
    }
}

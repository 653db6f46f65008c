//! The τ range of a fit: given by the user, or its first point chosen past the short τ
//! that the sensor's own filtering colours.

use serde::{Deserialize, Serialize};

use crate::allan::AllanError;

/// How the τ range of the fit was chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeSource {
    /// The whole curve.
    Full,
    /// Short τ left out automatically where the averaged rates are correlated
    /// ([`auto_range_candidates`]).
    Auto,
    /// Given by the user (`--fit-range`).
    User,
}

/// The τ range of a fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRange {
    /// Smallest fitted τ, s.
    pub tau_min_s: f64,
    /// Largest fitted τ, s.
    pub tau_max_s: f64,
    /// How the range was chosen.
    pub source: RangeSource,
    /// Curve points below the range (left out).
    pub excluded_short: usize,
    /// Curve points above the range (left out).
    pub excluded_long: usize,
}

/// A user-given fit range `TMIN:TMAX` in seconds; an empty side means the curve's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitRangeSpec {
    /// Smallest τ to fit, s (None: from the start of the curve).
    pub tau_min_s: Option<f64>,
    /// Largest τ to fit, s (None: to the end of the curve).
    pub tau_max_s: Option<f64>,
}

impl std::str::FromStr for FitRangeSpec {
    type Err = AllanError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = |why: &str| {
            AllanError::Invalid(format!(
                "fit range {s:?}: {why} (expected TMIN:TMAX in seconds, e.g. 0.2:2000 or 0.2:)"
            ))
        };
        let (a, b) = s.split_once(':').ok_or_else(|| bad("no ':'"))?;
        let side = |t: &str, which: &str| -> Result<Option<f64>, AllanError> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(None);
            }
            let v: f64 = t
                .parse()
                .map_err(|_| bad(&format!("{which} {t:?} is not a number")))?;
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(&format!(
                    "{which} must be a positive number of seconds"
                )));
            }
            Ok(Some(v))
        };
        let spec = FitRangeSpec {
            tau_min_s: side(a, "TMIN")?,
            tau_max_s: side(b, "TMAX")?,
        };
        if let (Some(lo), Some(hi)) = (spec.tau_min_s, spec.tau_max_s)
            && lo >= hi
        {
            return Err(bad("TMIN must be below TMAX"));
        }
        Ok(spec)
    }
}

/// Largest averaging factor the automatic range may leave out: the sensor's own
/// filtering acts over a few to a few tens of samples.
pub(crate) const AUTO_RANGE_MAX_M: usize = 200;
/// Smallest lag-1 autocorrelation of the τ-averaged rates that counts as coloured.
pub(crate) const ACF_COLOURED: f64 = 0.02;

/// Whether the shortest-τ point of a curve is coloured by the sensor's own filtering:
/// the lag-1 autocorrelation r₁ of the rate samples lies above max(`ACF_COLOURED`,
/// 3/√n) (white noise gives r₁ ≈ 0 with standard error 1/√n; Box & Jenkins 1976
/// §2.1.6) or below −`ACF_COLOURED` while above −0.3 (a narrow-band hump; quantization
/// alone gives r₁ → −½ and is a modelled term). `acf1` is the curve's
/// [`crate::allan::analysis::ChannelResult::rate_acf1`], `n_samples` the samples behind it.
pub fn short_tau_coloured(acf1: &[f64], n_samples: usize) -> bool {
    let Some(&r) = acf1.first() else {
        return false;
    };
    let limit = ACF_COLOURED.max(3.0 / (n_samples.max(1) as f64).sqrt());
    r.is_finite() && (r > limit || (r < -limit && r > -0.3))
}

/// Candidate first points of the automatic fit range: the curve's first point, then
/// points whose averaging factor m has grown by at least half since the previous
/// candidate, up to m = `AUTO_RANGE_MAX_M`.
pub fn auto_range_candidates(m: &[usize]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut last = 0usize;
    for (i, &mi) in m.iter().enumerate() {
        if mi > AUTO_RANGE_MAX_M {
            break;
        }
        if out.is_empty() || 2 * mi >= 3 * last {
            out.push(i);
            last = mi;
        }
    }
    out
}

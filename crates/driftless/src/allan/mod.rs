//! Allan-variance family of stability estimators, their confidence intervals and
//! the IMU noise-term fit.
//!
//! Vocabulary (NIST SP 1065, Riley 2008): an IMU rate output (rad/s, m/s²) is
//! *frequency* data y; its integral (angle, velocity) is *phase* data x, with
//! N rate samples giving N+1 phase points (leading zero). Every estimator here
//! works on phase internally.

pub mod analysis;
pub mod checks;
pub mod ci;
pub mod estimators;
pub mod export;
pub mod fit;
pub mod gmwm;
pub mod lines;
pub mod log_analysis;
pub mod log_replicates;
pub mod noise_model;
pub mod phase;
pub mod plausibility;
pub mod replicates;
pub mod taus;

use serde::{Deserialize, Serialize};

/// The stability estimators `driftless allan --estimator` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Estimator {
    /// Non-overlapping Allan deviation (SP 1065 eq. 7).
    Adev,
    /// Fully overlapping Allan deviation (SP 1065 eq. 11).
    Oadev,
    /// Modified Allan deviation (SP 1065 eq. 14).
    Mdev,
    /// Non-overlapping Hadamard deviation (SP 1065 eq. 17).
    Hdev,
    /// Overlapping Hadamard deviation (SP 1065 eq. 18).
    Ohdev,
    /// Time deviation, TDEV = τ/√3 · MDEV (SP 1065 eq. 16).
    Tdev,
    /// Total deviation with reflected phase extension (SP 1065 eq. 25).
    Totdev,
}

impl Estimator {
    /// All estimators, in CLI order.
    pub const ALL: [Estimator; 7] = [
        Estimator::Adev,
        Estimator::Oadev,
        Estimator::Mdev,
        Estimator::Hdev,
        Estimator::Ohdev,
        Estimator::Tdev,
        Estimator::Totdev,
    ];

    /// The CLI / JSON name (`oadev`, …).
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Adev => "adev",
            Estimator::Oadev => "oadev",
            Estimator::Mdev => "mdev",
            Estimator::Hdev => "hdev",
            Estimator::Ohdev => "ohdev",
            Estimator::Tdev => "tdev",
            Estimator::Totdev => "totdev",
        }
    }

    /// Parse a CLI name.
    pub fn from_name(s: &str) -> Option<Estimator> {
        Estimator::ALL
            .into_iter()
            .find(|e| e.name().eq_ignore_ascii_case(s))
    }

    /// Largest averaging factor `m` the estimator accepts for `n_phase` phase points.
    /// The limits reproduce Stable32's tau lists: the non-overlapping ADEV and HDEV need
    /// ⌊(N−1)/m⌋ ≥ 5, the overlapping ones m ≤ (N−1)/4, TOTDEV m ≤ (N−1)/2.
    pub fn max_m(self, n_phase: usize) -> usize {
        let span = n_phase.saturating_sub(1);
        match self {
            Estimator::Adev | Estimator::Hdev => span / 5,
            Estimator::Oadev | Estimator::Mdev | Estimator::Ohdev | Estimator::Tdev => span / 4,
            Estimator::Totdev => span / 2,
        }
    }

    /// Whether the estimator is a Hadamard (third-difference) variance.
    pub(crate) fn is_hadamard(self) -> bool {
        matches!(self, Estimator::Hdev | Estimator::Ohdev)
    }
}

/// Whether input values are rates (frequency) or their integral (phase).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DataType {
    /// Rate-like samples (rad/s, m/s², fractional frequency).
    Frequency,
    /// Integrated samples (rad, m/s, time error).
    Phase,
}

/// One point of a stability curve: averaging factor, tau, number of terms summed
/// (Stable32's `#` column) and the deviation (in the data's units per tau0-sample
/// rate, i.e. the same units as frequency data).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DevPoint {
    /// Averaging factor m (τ = m·τ0).
    pub m: usize,
    /// Averaging time τ, s.
    pub tau: f64,
    /// Number of terms in the sum.
    pub n: usize,
    /// The deviation σ(τ).
    pub dev: f64,
}

/// Errors from the Allan computations.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AllanError {
    /// Too few samples for even the smallest averaging factor requested.
    #[error(
        "{estimator} at tau = {t} s (m = {m}) needs at least {needed} samples; the log has {have}",
        t = crate::io::error::sig6(*tau)
    )]
    TooFewSamples {
        /// Estimator name.
        estimator: &'static str,
        /// Requested tau.
        tau: f64,
        /// Requested averaging factor.
        m: usize,
        /// Samples needed.
        needed: usize,
        /// Samples present.
        have: usize,
    },
    /// A tau specification that cannot be turned into averaging factors.
    #[error("bad tau specification '{spec}': {why}")]
    BadTauSpec {
        /// The spec as given.
        spec: String,
        /// Why it was refused.
        why: String,
    },
    /// Non-finite input value.
    #[error("sample {index} is not finite ({value})")]
    NonFinite {
        /// Index of the offending sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A value so large that the sums of squared differences would overflow to infinity.
    #[error(
        "sample {index} is {value:e}, beyond the ±{limit:e} the Allan sums hold without \
         overflowing; rescale the data (its unit) before the analysis"
    )]
    OutOfRange {
        /// Index of the offending sample.
        index: usize,
        /// Its value.
        value: f64,
        /// The largest magnitude analysed.
        limit: f64,
    },
    /// Invalid parameter.
    #[error("{0}")]
    Invalid(String),
}

/// The largest sample magnitude analysed: phase (a sum of up to 10⁹ samples times τ0)
/// squared and summed again stays far below `f64::MAX` (1.8e308).
pub const MAX_SAMPLE_MAGNITUDE: f64 = 1e100;

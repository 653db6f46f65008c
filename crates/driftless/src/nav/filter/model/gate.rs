//! Innovation gating: the [`Gate`] choices, their text form and parsing.

use super::*;

/// Innovation gating of a measurement update with m = 2 or 3 components, innovation y,
/// innovation covariance S = H P Hᵀ + R and normalized innovation squared
/// q = yᵀ S⁻¹ y (NIS; χ²(m)-distributed for a consistent filter). χ²_p(m) below is the
/// p-quantile of the χ² distribution with m degrees of freedom
/// ([`crate::allan::ci::chi2_quantile`]).
///
/// Text form (`FromStr` / `Display`): `off`, `chi2:P`, `robust` or
/// `robust:P_INFLATE:P_REJECT:MAX_SIGMA_SCALE`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gate {
    /// Every measurement is applied with its R.
    Off,
    /// Classical χ² test (Groves 2013 §17.3, innovation-based outlier detection):
    /// reject the measurement (state and P untouched) when q > χ²_p(m), else apply it
    /// with its R. `p` in (0, 1), e.g. 0.9999 (χ²_p(3) = 21.11).
    Chi2 {
        /// Probability of the quantile.
        p: f64,
    },
    /// Robust down-weighting by a scalar inflation of R on the Mahalanobis distance of
    /// the innovation (Huber 1964's M-estimator weight c/q in its multivariate, NIS form;
    /// λ = q/c is the R-dominated solution of the condition yᵀ(H P Hᵀ + λR)⁻¹y = c of
    /// the robust Kalman filter of Chang 2014, J. Geodesy 88:391–401; like the IGG
    /// scheme of Yang 1999 it has an unchanged, a down-weighted and a rejected zone, the
    /// last decided here by the ceiling test; outlier detection on the innovations as in
    /// Groves 2013 §17.3):
    ///
    /// * c = χ²_{p_inflate}(m). If q ≤ c the update is the ordinary one (λ = 1).
    /// * Otherwise R is replaced by λR with λ = min(q/c, λ_max), λ_max =
    ///   `max_sigma_scale`² (σ inflated at most `max_sigma_scale` times): Huber's weight
    ///   c/q applied to the squared normalized residual. When R dominates S the inflated
    ///   NIS is ≈ c — the measurement's weight falls smoothly with the size of its
    ///   innovation instead of dropping to zero; when H P Hᵀ dominates (the prediction,
    ///   not the fix, is uncertain, e.g. after an outage) inflating R changes S little
    ///   and a fix that corrects a drifted state keeps its weight.
    /// * Rejection (state and P untouched) only when the innovation is inconsistent even
    ///   at the ceiling: yᵀ(H P Hᵀ + λ_max R)⁻¹y > χ²_{p_reject}(m). With the default
    ///   `max_sigma_scale` = 100 a fix with a 1-cm formal σ is still used (weighted as
    ///   σ ≤ 1 m) with 5–60 cm of antenna motion, while a 50-m jump is rejected.
    ///   `p_reject` = 1 never rejects.
    ///
    /// Applied updates with λ > 1 are counted as inflated (`ForwardRun::gnss_inflated`,
    /// `UpdateOutcome::r_scale`).
    Robust {
        /// Probability of the inflation threshold c (default 0.99).
        p_inflate: f64,
        /// Probability of the rejection test at the ceiling (default 0.9999; 1 = never).
        p_reject: f64,
        /// Largest σ multiplier √λ_max (default 100).
        max_sigma_scale: f64,
    },
}

impl Default for Gate {
    /// `robust` with p_inflate 0.99, p_reject 0.9999, max_sigma_scale 100.
    fn default() -> Self {
        Gate::Robust {
            p_inflate: 0.99,
            p_reject: 0.9999,
            max_sigma_scale: 100.0,
        }
    }
}

/// The accepted text forms of a [`Gate`], for error messages.
pub(crate) const GATE_CHOICES: &str = "off, chi2:P (P a probability in (0, 1), e.g. chi2:0.9999), \
     robust, or robust:P_INFLATE:P_REJECT:MAX_SIGMA_SCALE (e.g. robust:0.99:0.9999:100)";

impl Gate {
    /// Checks the parameters (probabilities in range, scale ≥ 1 and finite).
    pub fn validate(&self) -> Result<(), NavError> {
        let prob = |p: f64| p.is_finite() && p > 0.0 && p < 1.0;
        let ok = match *self {
            Gate::Off => true,
            Gate::Chi2 { p } => prob(p),
            Gate::Robust {
                p_inflate,
                p_reject,
                max_sigma_scale,
            } => {
                prob(p_inflate)
                    && (prob(p_reject) || p_reject == 1.0)
                    && p_reject >= p_inflate
                    && max_sigma_scale.is_finite()
                    && max_sigma_scale >= 1.0
            }
        };
        if ok {
            Ok(())
        } else {
            Err(NavError::Config(format!(
                "gate {self}: probabilities must lie in (0, 1) (p_reject may be 1 and must \
                 be ≥ p_inflate) and max_sigma_scale must be finite and ≥ 1"
            )))
        }
    }

    /// The same gate, but one that never rejects: `Robust` with `p_reject` = 1 (still
    /// inflating R); `Off` and `Chi2` become `Off`.
    pub fn never_reject(&self) -> Gate {
        match *self {
            Gate::Robust {
                p_inflate,
                max_sigma_scale,
                ..
            } => Gate::Robust {
                p_inflate,
                p_reject: 1.0,
                max_sigma_scale,
            },
            _ => Gate::Off,
        }
    }
}

impl std::fmt::Display for Gate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Gate::Off => write!(f, "off"),
            Gate::Chi2 { p } => write!(f, "chi2:{p}"),
            g if g == Gate::default() => write!(f, "robust"),
            Gate::Robust {
                p_inflate,
                p_reject,
                max_sigma_scale,
            } => write!(f, "robust:{p_inflate}:{p_reject}:{max_sigma_scale}"),
        }
    }
}

impl std::str::FromStr for Gate {
    type Err = NavError;

    /// Parses the text forms of [`Gate`] (case-insensitive, spaces around tokens free).
    fn from_str(text: &str) -> Result<Gate, NavError> {
        let bad = |why: &str| {
            NavError::Config(format!(
                "gate {text:?}: {why}; expected one of {GATE_CHOICES}"
            ))
        };
        let lower = text.trim().to_ascii_lowercase();
        let mut parts = lower.split(':').map(str::trim);
        let head = parts.next().unwrap_or("");
        let nums: Vec<&str> = parts.collect();
        let num = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| bad(&format!("{s:?} is not a number")))
        };
        let g = match (head, nums.as_slice()) {
            ("off", []) => Gate::Off,
            ("chi2", [p]) => Gate::Chi2 { p: num(p)? },
            ("robust", []) => Gate::default(),
            ("robust", [a, b, c]) => Gate::Robust {
                p_inflate: num(a)?,
                p_reject: num(b)?,
                max_sigma_scale: num(c)?,
            },
            ("off" | "chi2" | "robust", _) => return Err(bad("wrong number of parameters")),
            _ => return Err(bad("unknown gating mode")),
        };
        g.validate().map_err(|e| bad(&e.to_string()))?;
        Ok(g)
    }
}

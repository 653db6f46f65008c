//! IMU noise-term fit to an Allan variance curve.
//!
//! Model (IEEE Std 952-1997 Annex C; IEEE Std 1293-2018 Annex; El-Sheimy, Hou & Niu 2008,
//! "Analysis and modeling of inertial sensors using Allan variance", IEEE TIM 57(1)):
//!
//! ```text
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2  [+ σ_GM²·g(τ/T)]
//! ```
//!
//! All values SI: data units u (rad/s or m/s²) → Q \[u·s], N \[u·√s], B \[u], K \[u/√s], R \[u/s].
//!
//! # Method
//!
//! The model is linear in θ = (Q², N², B², K², R²). Each Allan-variance estimate
//! σ̂²(τ_i) is approximately a scaled χ² variable with ν_i equivalent degrees of freedom
//! (Greenhall & Riley 2003; NIST SP 1065 §5.3), so var σ̂²_i ≈ 2σ⁴(τ_i)/ν_i. The fit
//! minimises Σ w_i (σ̂²_i − m_i(θ))² with w_i = 1/(m_i²(2/ν_i + f²)) where m_i is the
//! **model** value (weighting by the data instead biases the fit low, because low
//! estimates get large weights) and f a relative model-error floor
//! (`MODEL_ERROR_FLOOR`: no point counts as more precise than f, so the few short-τ
//! points with EDF of 10⁵–10⁶ cannot decide the fit alone; the floor only bites where
//! 2/ν < f², i.e. ν > 2/f²), subject to θ ≥ 0. The weights are updated from the model and the
//! non-negative least squares (NNLS) problem re-solved until the model stops changing
//! (iteratively reweighted least squares). The NNLS is solved exactly by enumerating the
//! at most 2⁶ supports (a feasible support with the smallest weighted residual is the
//! NNLS optimum). A term whose coefficient goes to zero is reported as not detected,
//! with an upper limit, instead of a negative or imaginary value.
//!
//! A first-order Gauss-Markov term (σ, T) is linear in σ² for fixed T; T is found by a
//! grid over ln T followed by golden-section refinement (separable least squares, Golub &
//! Pereyra 1973), with the NNLS above inside.
//!
//! # Confidence intervals
//!
//! Covariance of θ̂ from the weighted normal equations, (XᵀWX)⁻¹, multiplied by
//! * an inflation for the correlation between Allan-variance estimates at neighbouring
//!   taus (they share the same data): the information is counted as one independent point
//!   per decade of tau rather than one per tau — see [`correlation_inflation`]; the factor
//!   was calibrated and checked by Monte Carlo (`tests/noise_recovery.rs`);
//! * max(1, χ²_red) (Birge ratio) so that a misfitting model widens its intervals.
//!
//! The interval on the square θ_j ± z·s_j (z the two-sided normal quantile) is clamped at
//! zero and square-rooted, so Q, N, B, K, R intervals are asymmetric and never negative.
//!
//! # Where the model applies
//!
//! Below a few sample intervals a real sensor's output is not white: its anti-alias
//! filtering and decimation correlate neighbouring samples, σ²(τ) falls below N²/τ, and no
//! IEEE 952 term describes that. [`short_tau_coloured`] tells from the lag-1
//! autocorrelation of the samples; the noise model then chooses the first point of the fit
//! among [`auto_range_candidates`] (see `noise_model::NoiseModel::from_curves_with`).
//! χ²_red is read by [`chi2_verdict`]. A Gauss-Markov correlation time is searched only
//! where the record can show it ([`FitOptions`]); a bound hit is reported in
//! [`NoiseFit::not_identifiable`].
//!
//! The classic single-point "slope" readings (N at τ = 1 s on the −½ line, B = σ_min/0.664,
//! K at τ = 3 s on the +½ line; IEEE 952 Fig. C.2) are available as a diagnostic through
//! [`slope_readings`].

use std::f64::consts::{LN_2, PI};

use super::AllanError;

mod config;
mod range;
mod result;
mod slopes;
mod solve;

use config::GM_LN_T_TOL;
pub use config::{FitConfig, FitOptions};
pub(crate) use config::{GM_MAX_RECORD_FRACTION, GM_MIN_SAMPLES, MODEL_ERROR_FLOOR};
pub use range::{FitRange, FitRangeSpec, RangeSource, auto_range_candidates, short_tau_coloured};
pub(crate) use result::CHI2_RED_GOOD;
pub use result::{
    CHI2_RED_WARN, GaussMarkovTerm, NoiseFit, NotIdentifiable, Term, TermKind, UpperLimit,
    chi2_verdict,
};
use slopes::slope_alpha;
pub use slopes::{SlopeReadings, slope_readings};
pub(crate) use solve::golden_max;
use solve::{IrlsSolution, covariance, golden_max_tol, irls, upper_limit};

/// (2 ln2/π): Allan variance of bias instability per B².
pub(crate) const BIAS_AVAR_COEF: f64 = 2.0 * LN_2 / PI;
/// √(2 ln2/π) ≈ 0.6643: the Allan-deviation floor per unit bias instability.
pub(crate) const BIAS_ADEV_FLOOR: f64 = 0.664_282_470_267_960_1;

/// Allan variance of a first-order Gauss-Markov process with stationary σ and
/// correlation time T (IEEE Std 952-1997 Annex C, exponentially correlated noise):
/// with u = τ/T: σ²_A(τ) = (σ²/u²)·(2u − 3 + 4e^{−u} − e^{−2u}), i.e. the
/// standard (q_c²T²/τ)[1 − (T/2τ)(3 − 4e^{−τ/T} + e^{−2τ/T})] with q_c² = 2σ²/T.
/// Small u behaves like rate random walk (2σ²u/3), large u like white noise (2σ²/u).
pub(crate) fn gauss_markov_avar(sigma: f64, tau_c: f64, tau: f64) -> f64 {
    let u = tau / tau_c;
    if u < 1e-3 {
        // series: 2u − 3 + 4e^{−u} − e^{−2u} = (2/3)u³ − (1/2)u⁴ + (7/30)u⁵ + O(u⁶)
        return sigma * sigma * u * (2.0 / 3.0 - u / 2.0 + 7.0 / 30.0 * u * u);
    }
    sigma * sigma / (u * u) * (2.0 * u - 3.0 + 4.0 * (-u).exp() - (-2.0 * u).exp())
}

/// Location u* = τ/T and height of the maximum of the Gauss-Markov Allan variance per σ²:
/// max_u (2u − 3 + 4e^{−u} − e^{−2u})/u² (found numerically: u* ≈ 1.8926, 0.38114).
pub(crate) fn gauss_markov_avar_peak() -> (f64, f64) {
    let g = |u: f64| gauss_markov_avar(1.0, 1.0, u);
    let (u, v) = golden_max(|lu: f64| g(lu.exp()), -3.0, 3.0);
    (u.exp(), v)
}

// ---------------------------------------------------------------------------------------
// Normal distribution helpers: one implementation, in [`crate::numeric::normal`].

pub use crate::numeric::normal::{erfc, normal_cdf, normal_quantile};

// ---------------------------------------------------------------------------------------
// Fit.

/// Inflation of the least-squares covariance for the correlation between Allan-variance
/// estimates at neighbouring taus (overlapping estimates at nearby taus are computed
/// from the same data, and for flicker and random-walk noise the correlation reaches
/// across octaves): `n_points / n_independent` with n_independent = log10(τ_max/τ_min) + 1,
/// i.e. one independent estimate per decade of tau. Never below 1.
///
/// Calibrated empirically: with ~100 log-spaced taus over 5.9 decades (18 h at 100 Hz)
/// and 4.9 decades (2 h) and N, B, K present, the uninflated covariance (n_independent =
/// n_points) under-states the spread of N², B², K² by factors of 2–3 in variance
/// (rms z-scores 1.5–1.8); one-per-octave counting still leaves rms z ≈ 1.5–1.8 for
/// B and K; one per decade brings them to ≈ 0.8–1.1 (coverage in `tests/noise_recovery.rs`).
pub fn correlation_inflation(tau: &[f64]) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &t in tau {
        lo = lo.min(t);
        hi = hi.max(t);
    }
    if tau.is_empty() || hi <= lo {
        return 1.0;
    }
    let independent = (hi / lo).log10() + 1.0;
    (tau.len() as f64 / independent).max(1.0)
}

fn validate_inputs(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    confidence: f64,
) -> Result<(), AllanError> {
    if tau.len() != avar.len() || tau.len() != edf.len() {
        return Err(AllanError::Invalid(format!(
            "fit: tau, avar and edf must have the same length (got {}, {}, {})",
            tau.len(),
            avar.len(),
            edf.len()
        )));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Invalid(format!(
            "fit: confidence must be in (0, 1), got {confidence}"
        )));
    }
    for (i, ((&t, &a), &e)) in tau.iter().zip(avar).zip(edf).enumerate() {
        for v in [t, a, e] {
            if !v.is_finite() {
                return Err(AllanError::NonFinite { index: i, value: v });
            }
        }
        if t <= 0.0 || a <= 0.0 || e <= 0.0 {
            return Err(AllanError::Invalid(format!(
                "fit: point {i} needs tau > 0, avar > 0 and edf > 0 (tau = {t}, avar = {a}, edf = {e})"
            )));
        }
    }
    Ok(())
}

/// Fit the IEEE 952 noise terms to an Allan-variance curve.
///
/// * `tau`, `avar`: the curve (Allan **variance**, not deviation), any estimator of the
///   Allan family whose expectation follows the model (overlapping ADEV recommended).
/// * `edf`: equivalent degrees of freedom of each point (e.g. `ci::edf` with the α of the
///   dominant term; see [`fit_noise_with_edf`] which iterates that choice).
/// * `confidence`: two-sided confidence level of the reported intervals, e.g. 0.683.
///
/// Errors: mismatched lengths, non-finite or non-positive inputs, no term switched on,
/// fewer points than fitted parameters.
pub fn fit_noise(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    cfg: &FitConfig,
    confidence: f64,
) -> Result<NoiseFit, AllanError> {
    fit_noise_opts(tau, avar, edf, cfg, confidence, &FitOptions::default())
}

/// [`fit_noise`] with the record's sample interval and length (which bound a
/// Gauss-Markov correlation time to what the record can show) and the weights'
/// model-error floor. A correlation time that ends at a bound of its search — from
/// the longer of `GM_MIN_SAMPLES`·τ0 and the curve's shortest τ (a shorter one falls
/// as 1/τ over the whole curve, like white noise, and would trade places with N) to the
/// shorter of `GM_MAX_RECORD_FRACTION`·record and ten times the longest τ — is
/// reported in [`NoiseFit::not_identifiable`] and the model refitted without the term.
pub fn fit_noise_opts(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    cfg: &FitConfig,
    confidence: f64,
    opts: &FitOptions,
) -> Result<NoiseFit, AllanError> {
    validate_inputs(tau, avar, edf, confidence)?;
    let floor = opts.model_error_floor;
    if !(floor.is_finite() && (0.0..1.0).contains(&floor)) {
        return Err(AllanError::Invalid(format!(
            "fit: the model-error floor must be in [0, 1), got {floor}"
        )));
    }
    let kinds = cfg.linear_terms();
    // A Gauss-Markov term needs two parameters beyond the linear terms; a curve too short
    // for them is fitted without it, and says so.
    let mut not_identifiable = Vec::new();
    let with_gm = cfg.gauss_markov && (kinds.is_empty() || tau.len() > kinds.len() + 2);
    if cfg.gauss_markov && !with_gm {
        not_identifiable.push(NotIdentifiable {
            term: TermKind::GaussMarkov,
            reason: format!(
                "{} curve points are too few for its σ and correlation time beside {} other \
                 term(s)",
                tau.len(),
                kinds.len()
            ),
        });
    }
    let n_par = kinds.len() + if with_gm { 2 } else { 0 };
    if n_par == 0 {
        return Err(AllanError::Invalid("fit: no noise term switched on".into()));
    }
    if tau.len() <= n_par {
        return Err(AllanError::Invalid(format!(
            "fit: {} points cannot constrain {} parameters",
            tau.len(),
            n_par
        )));
    }
    let mut cols: Vec<Vec<f64>> = kinds
        .iter()
        .map(|k| tau.iter().map(|&t| k.basis(t)).collect())
        .collect();

    let z = normal_quantile(0.5 + confidence / 2.0);
    let inflation = correlation_inflation(tau);

    // Optional Gauss-Markov: separable search over ln T.
    let gm_t = if with_gm {
        match gm_search(tau, avar, edf, &cols, floor, opts) {
            Ok(t) => {
                cols.push(gm_column(tau, t));
                Some(t)
            }
            Err(reason) => {
                not_identifiable.push(NotIdentifiable {
                    term: TermKind::GaussMarkov,
                    reason,
                });
                None
            }
        }
    } else {
        None
    };

    let sol = irls(&cols, avar, edf, floor);
    let n = tau.len();
    let n_active = sol.coef.iter().filter(|&&c| c > 0.0).count();
    let dof = n
        .saturating_sub(n_active + usize::from(gm_t.is_some()))
        .max(1);
    let chi2_reduced = sol.chi2 / dof as f64;
    let scale = inflation * chi2_reduced.max(1.0);

    // Jacobian of the active parameters (+ ln T if the GM term is active).
    let active: Vec<usize> = (0..cols.len()).filter(|&j| sol.coef[j] > 0.0).collect();
    let mut jac: Vec<Vec<f64>> = active.iter().map(|&j| cols[j].clone()).collect();
    let gm_index = kinds.len();
    let gm_active = gm_t.is_some() && sol.coef.get(gm_index).is_some_and(|&c| c > 0.0);
    if let (true, Some(t)) = (gm_active, gm_t) {
        let s2 = sol.coef[gm_index];
        let h = 1e-4;
        let d: Vec<f64> = tau
            .iter()
            .map(|&x| {
                s2 * (gauss_markov_avar(1.0, (t.ln() + h).exp(), x)
                    - gauss_markov_avar(1.0, (t.ln() - h).exp(), x))
                    / (2.0 * h)
            })
            .collect();
        jac.push(d);
    }
    let cov = covariance(&jac, &sol.w);

    let mut out = NoiseFit {
        quantization: None,
        white: None,
        bias_instability: None,
        rate_random_walk: None,
        rate_ramp: None,
        gauss_markov: None,
        confidence,
        rms_log10_residual: (sol
            .model
            .iter()
            .zip(avar)
            .map(|(m, a)| (m / a).log10().powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt(),
        not_detected: Vec::new(),
        chi2_reduced,
        n_points: n,
        fit_range: Some(FitRange {
            tau_min_s: tau.iter().copied().fold(f64::INFINITY, f64::min),
            tau_max_s: tau.iter().copied().fold(0.0, f64::max),
            source: RangeSource::Full,
            excluded_short: 0,
            excluded_long: 0,
        }),
        not_identifiable,
    };
    let est = Estimates {
        cols: &cols,
        sol: &sol,
        active: &active,
        cov: cov.as_ref(),
        z,
        scale,
    };
    est.report_terms(&kinds, gm_t.map(|t| (t, gm_active)), &mut out);
    Ok(out)
}

/// The Gauss-Markov correlation time that best fits the curve beside the linear terms
/// `cols`: a grid over ln T refined by golden section, within the bounds the record allows
/// ([`fit_noise_opts`]). A time at a bound of its search is an error saying why.
fn gm_search(
    tau: &[f64],
    avar: &[f64],
    edf: &[f64],
    cols: &[Vec<f64>],
    floor: f64,
    opts: &FitOptions,
) -> Result<f64, String> {
    let (tmin, tmax) = tau
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    let t_lo = opts
        .tau0_s
        .map_or(tmin / 10.0, |t0| tmin.max(GM_MIN_SAMPLES * t0));
    let t_hi = opts.record_s.map_or(tmax * 10.0, |r| {
        (tmax * 10.0).min(GM_MAX_RECORD_FRACTION * r)
    });
    let (lo, hi) = (t_lo.ln(), t_hi.ln());
    let objective = |lt: f64| -> f64 {
        let mut c = cols.to_vec();
        c.push(gm_column(tau, lt.exp()));
        irls(&c, avar, edf, floor).chi2
    };
    let ngrid = 21;
    let grid: Vec<f64> = (0..ngrid)
        .map(|i| lo + (hi - lo) * i as f64 / (ngrid - 1) as f64)
        .collect();
    let vals: Vec<f64> = grid.iter().map(|&g| objective(g)).collect();
    let ibest = vals
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let a = grid[ibest.saturating_sub(1)];
    let b = grid[(ibest + 1).min(ngrid - 1)];
    let (lt, _) = golden_max_tol(|x| -objective(x), a, b, GM_LN_T_TOL);
    // Within 2 % of a bound: the curve wants a correlation time outside what the
    // record can show.
    if hi - lo < 0.1 || lt - lo < 0.02 || hi - lt < 0.02 {
        let reason = if hi - lo >= 0.1 && lt - lo < 0.02 && (t_lo - tmin).abs() <= 1e-12 * tmin {
            format!(
                "no correlated hump: the best correlation time is below the fitted \
                     range's first τ ({} s), where it is white noise",
                sig3(t_lo)
            )
        } else {
            format!(
                "correlation time at the bound of its search ({} s; allowed {} … {} s: \
                     at least {GM_MIN_SAMPLES} sample intervals and the range's first τ, at \
                     most {GM_MAX_RECORD_FRACTION} of the record)",
                sig3(lt.exp()),
                sig3(t_lo),
                sig3(t_hi)
            )
        };
        Err(reason)
    } else {
        Ok(lt.exp())
    }
}

/// The solved fit and what its intervals need: the design columns, the IRLS solution, the
/// active parameters and their covariance, the normal quantile and the variance scale.
struct Estimates<'a> {
    cols: &'a [Vec<f64>],
    sol: &'a IrlsSolution,
    active: &'a [usize],
    cov: Option<&'a Vec<Vec<f64>>>,
    z: f64,
    scale: f64,
}

impl Estimates<'_> {
    /// Interval of √p from the variance of p: p ± z·s clamped at zero, square-rooted.
    fn sq_term(&self, p: f64, var: f64) -> Term {
        let s = (var * self.scale).max(0.0).sqrt();
        Term {
            value: p.sqrt(),
            lo: (p - self.z * s).max(0.0).sqrt(),
            hi: (p + self.z * s).sqrt(),
        }
    }

    /// Variance of parameter `j` (NaN when inactive or without covariance).
    fn var_of(&self, j: usize) -> f64 {
        self.active
            .iter()
            .position(|&a| a == j)
            .and_then(|pos| self.cov.map(|c| c[pos][pos]))
            .unwrap_or(f64::NAN)
    }

    /// Fills the detected terms with their intervals and the undetected ones' upper limits;
    /// `gm` is the Gauss-Markov correlation time and whether its σ² came out positive.
    fn report_terms(&self, kinds: &[TermKind], gm: Option<(f64, bool)>, out: &mut NoiseFit) {
        let (sol, z, scale) = (self.sol, self.z, self.scale);
        for (j, &k) in kinds.iter().enumerate() {
            if sol.coef[j] > 0.0 {
                let t = self.sq_term(sol.coef[j], self.var_of(j));
                match k {
                    TermKind::Quantization => out.quantization = Some(t),
                    TermKind::White => out.white = Some(t),
                    TermKind::BiasInstability => out.bias_instability = Some(t),
                    TermKind::RateRandomWalk => out.rate_random_walk = Some(t),
                    TermKind::RateRamp => out.rate_ramp = Some(t),
                    TermKind::GaussMarkov => {}
                }
            } else {
                out.not_detected.push(UpperLimit {
                    term: k,
                    upper: upper_limit(self.cols, sol, j, z, scale),
                });
            }
        }
        let gm_index = kinds.len();
        if let Some((t, gm_active)) = gm {
            if gm_active {
                let sigma = self.sq_term(sol.coef[gm_index], self.var_of(gm_index));
                let var_lt = self
                    .cov
                    .map(|c| c[self.active.len()][self.active.len()])
                    .unwrap_or(f64::NAN);
                let s = (var_lt * scale).max(0.0).sqrt();
                out.gauss_markov = Some(GaussMarkovTerm {
                    sigma,
                    tau_c_s: Term {
                        value: t,
                        lo: t * (-z * s).exp(),
                        hi: t * (z * s).exp(),
                    },
                });
            } else {
                out.not_detected.push(UpperLimit {
                    term: TermKind::GaussMarkov,
                    upper: upper_limit(self.cols, sol, gm_index, z, scale),
                });
            }
        }
    }
}

/// [`fit_noise`] with the EDF of each point chosen from the power-law exponent α of the
/// noise that dominates there: `edf_of(i, alpha)` returns the EDF of point `i` for α
/// (typically `ci::edf(Estimator::Oadev, alpha, m[i], n_phase)`). The first pass takes
/// α from the local log-log slope μ of the Allan variance (α = −μ − 1, clamped to
/// −2..=2); then α is re-derived from the fitted model's dominant term and the fit
/// repeated until the α assignment stops changing (at most 5 passes).
pub fn fit_noise_with_edf<F: Fn(usize, i32) -> f64>(
    tau: &[f64],
    avar: &[f64],
    edf_of: F,
    cfg: &FitConfig,
    confidence: f64,
) -> Result<NoiseFit, AllanError> {
    fit_noise_with_edf_opts(tau, avar, edf_of, cfg, confidence, &FitOptions::default())
}

/// [`fit_noise_with_edf`] with [`FitOptions`] (see [`fit_noise_opts`]).
pub fn fit_noise_with_edf_opts<F: Fn(usize, i32) -> f64>(
    tau: &[f64],
    avar: &[f64],
    edf_of: F,
    cfg: &FitConfig,
    confidence: f64,
    opts: &FitOptions,
) -> Result<NoiseFit, AllanError> {
    if tau.len() != avar.len() {
        return Err(AllanError::Invalid(format!(
            "fit: tau and avar lengths differ ({} vs {})",
            tau.len(),
            avar.len()
        )));
    }
    let mut alpha = slope_alpha(tau, avar);
    let mut fit = None;
    for _ in 0..5 {
        let edf: Vec<f64> = alpha
            .iter()
            .enumerate()
            .map(|(i, &a)| edf_of(i, a))
            .collect();
        let f = fit_noise_opts(tau, avar, &edf, cfg, confidence, opts)?;
        let next: Vec<i32> = tau.iter().map(|&t| f.dominant_alpha(t)).collect();
        let done = next == alpha;
        fit = Some(f);
        if done {
            break;
        }
        alpha = next;
    }
    fit.ok_or_else(|| AllanError::Invalid("fit: no pass ran".into()))
}

/// Three significant digits for messages.
fn sig3(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) {
        format!("{v:.2e}")
    } else {
        format!("{}", (v * 1e3).round() / 1e3)
    }
}

fn gm_column(tau: &[f64], t: f64) -> Vec<f64> {
    tau.iter().map(|&x| gauss_markov_avar(1.0, t, x)).collect()
}

#[cfg(test)]
mod tests {
    use super::solve::{MAXP, nnls, normal_equations, solve_subset, weight};
    use super::*;

    fn taus(n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n)
            .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
            .collect()
    }

    /// The exact NNLS by enumeration of every support, as a reference.
    fn nnls_by_enumeration(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Vec<f64> {
        let ne = normal_equations(cols, y, w).expect("small");
        let p = ne.p;
        let mut best = (ne.yy, [0.0; MAXP]);
        for mask in 1u32..(1 << p) {
            let idx: Vec<usize> = (0..p).filter(|j| mask & (1 << j) != 0).collect();
            let Some(x) = solve_subset(&ne.a, &ne.b, &idx) else {
                continue;
            };
            if x[..idx.len()].iter().any(|&v| v.is_nan() || v <= 0.0) {
                continue;
            }
            let wssr = ne.yy - (0..idx.len()).map(|t| x[t] * ne.b[idx[t]]).sum::<f64>();
            if wssr < best.0 {
                let mut c = [0.0; MAXP];
                for (t, &j) in idx.iter().enumerate() {
                    c[j] = x[t];
                }
                best = (wssr, c);
            }
        }
        (0..p).map(|j| best.1[j] / ne.s[j]).collect()
    }

    #[test]
    fn active_set_nnls_matches_the_enumeration_of_supports() {
        // Allan-variance bases with noisy data from models with terms switched off, so
        // the unconstrained optimum is often infeasible.
        let tau = taus(60, 0.05, 3000.0);
        let kinds = [
            TermKind::Quantization,
            TermKind::White,
            TermKind::BiasInstability,
            TermKind::RateRandomWalk,
            TermKind::RateRamp,
        ];
        let mut cols: Vec<Vec<f64>> = kinds
            .iter()
            .map(|k| tau.iter().map(|&t| k.basis(t)).collect())
            .collect();
        cols.push(gm_column(&tau, 30.0));
        let mut state = 12345u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut zeros = 0;
        for trial in 0..300 {
            let truth: Vec<f64> = (0..cols.len())
                .map(|j| {
                    if j != 1 && uniform() < 0.4 {
                        0.0
                    } else {
                        [1e-12, 1e-8, 1e-10, 1e-14, 1e-18, 1e-10][j] * (0.2 + uniform())
                    }
                })
                .collect();
            let y: Vec<f64> = (0..tau.len())
                .map(|i| {
                    let m: f64 = cols.iter().zip(&truth).map(|(c, t)| c[i] * t).sum();
                    m * (1.0 + 0.3 * (uniform() - 0.5))
                })
                .collect();
            let w: Vec<f64> = y.iter().map(|v| 1.0 / (v * v)).collect();
            let fast = nnls(&cols, &y, &w);
            let exact = nnls_by_enumeration(&cols, &y, &w);
            zeros += exact.iter().filter(|&&c| c == 0.0).count();
            let ssr = |c: &[f64]| -> f64 {
                (0..tau.len())
                    .map(|i| {
                        let m: f64 = cols.iter().zip(c).map(|(col, x)| col[i] * x).sum();
                        w[i] * (y[i] - m).powi(2)
                    })
                    .sum()
            };
            assert!(fast.iter().all(|&c| c >= 0.0), "trial {trial}: {fast:?}");
            let (a, b) = (ssr(&fast), ssr(&exact));
            assert!(a <= b * (1.0 + 1e-9) + 1e-300, "trial {trial}: {a} vs {b}");
            for (f, e) in fast.iter().zip(&exact) {
                assert!(
                    (f - e).abs() <= 1e-6 * e.abs().max(1e-30)
                        || (*f == 0.0 && *e == 0.0)
                        || a <= b,
                    "trial {trial}: {fast:?} vs {exact:?}"
                );
            }
        }
        assert!(
            zeros > 100,
            "the trials must exercise the constraint: {zeros}"
        );
    }

    #[test]
    fn a_curve_too_short_for_a_gauss_markov_term_is_fitted_without_it() {
        // Six octave points of white noise plus a floor: enough for the five linear
        // terms, not for seven parameters.
        let tau: Vec<f64> = (0..6).map(|i| 2f64.powi(i)).collect();
        let avar: Vec<f64> = tau.iter().map(|t| 1e-6 / t + 1e-9).collect();
        let edf = vec![100.0; 6];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.683).expect("fit");
        assert!(f.gauss_markov.is_none());
        let ni = f
            .not_identifiable
            .iter()
            .find(|n| n.term == TermKind::GaussMarkov)
            .expect("reported");
        assert!(ni.reason.contains("too few"), "{ni:?}");
        assert!(f.white.is_some());
    }

    #[test]
    fn erfc_and_quantile() {
        assert!((erfc(1.0) - 0.157_299_207_050_285_13).abs() < 1e-14);
        assert!((erfc(2.0) / 0.004_677_734_981_047_266 - 1.0).abs() < 1e-12);
        assert!((erfc(3.0) / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-12);
        assert!((erfc(-0.5) - 1.520_499_877_813_046_5).abs() < 1e-14);
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-10);
        assert!((normal_quantile(0.5 + 0.683 / 2.0) - 1.000_641_828_762_449).abs() < 1e-9);
        // Upper tail, against mpmath (40 digits) at the f64 argument: no loss near p = 1.
        assert!((normal_quantile(1.0 - 1e-6) - 4.753_424_308_817_088).abs() < 1e-12);
        assert!((normal_quantile(1.0 - 1e-12) - 7.034_486_910_047_835).abs() < 1e-12);
    }

    #[test]
    fn bias_constant() {
        assert!((BIAS_ADEV_FLOOR - BIAS_AVAR_COEF.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn gm_peak() {
        let (u, v) = gauss_markov_avar_peak();
        assert!((u - 1.89).abs() < 0.01, "u* = {u}");
        assert!((v - 0.381_138_658).abs() < 1e-6, "peak = {v}");
    }

    #[test]
    fn exact_model_is_recovered() {
        let tau = taus(60, 0.01, 1e4);
        let (q, n, b, k, r) = (1e-6, 1e-4, 2e-5, 3e-7, 1e-9);
        let truth = NoiseFit {
            quantization: Some(Term {
                value: q,
                lo: q,
                hi: q,
            }),
            white: Some(Term {
                value: n,
                lo: n,
                hi: n,
            }),
            bias_instability: Some(Term {
                value: b,
                lo: b,
                hi: b,
            }),
            rate_random_walk: Some(Term {
                value: k,
                lo: k,
                hi: k,
            }),
            rate_ramp: Some(Term {
                value: r,
                lo: r,
                hi: r,
            }),
            gauss_markov: None,
            confidence: 0.683,
            rms_log10_residual: 0.0,
            not_detected: vec![],
            chi2_reduced: 0.0,
            n_points: 0,
            fit_range: None,
            not_identifiable: Vec::new(),
        };
        let avar: Vec<f64> = tau.iter().map(|&t| truth.model_avar(t)).collect();
        let edf = vec![100.0; tau.len()];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.683).unwrap();
        for (got, want) in [
            (f.quantization, q),
            (f.white, n),
            (f.bias_instability, b),
            (f.rate_random_walk, k),
            (f.rate_ramp, r),
        ] {
            let g = got.expect("term detected").value;
            assert!((g / want - 1.0).abs() < 1e-6, "{g} vs {want}");
        }
        assert!(f.rms_log10_residual < 1e-8);
    }

    #[test]
    fn absent_term_is_not_detected() {
        // White + RRW only, with a deterministic dip making the B coefficient want < 0.
        let tau = taus(40, 0.1, 1e3);
        let avar: Vec<f64> = tau.iter().map(|&t| 1e-8 / t + 1e-12 * t / 3.0).collect();
        let edf = vec![50.0; tau.len()];
        let f = fit_noise(&tau, &avar, &edf, &FitConfig::default(), 0.95).unwrap();
        assert!((f.white.unwrap().value / 1e-4 - 1.0).abs() < 1e-6);
        assert!((f.rate_random_walk.unwrap().value / 1e-6 - 1.0).abs() < 1e-6);
        assert!(f.bias_instability.is_none() || f.bias_instability.unwrap().value < 1e-9);
        for u in &f.not_detected {
            assert!(u.upper.is_finite() && u.upper >= 0.0, "{u:?}");
        }
    }

    #[test]
    fn gauss_markov_recovered() {
        let tau = taus(80, 0.01, 1e4);
        let (n, s, t) = (1e-4, 3e-5, 50.0);
        let avar: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(s, t, x))
            .collect();
        let edf = vec![100.0; tau.len()];
        let cfg = FitConfig {
            quantization: false,
            white: true,
            bias_instability: false,
            rate_random_walk: false,
            rate_ramp: false,
            gauss_markov: true,
        };
        let f = fit_noise(&tau, &avar, &edf, &cfg, 0.683).unwrap();
        let gm = f.gauss_markov.expect("GM found");
        assert!((gm.sigma.value / s - 1.0).abs() < 1e-4, "{gm:?}");
        assert!((gm.tau_c_s.value / t - 1.0).abs() < 1e-4, "{gm:?}");
        assert!((f.white.unwrap().value / n - 1.0).abs() < 1e-4);
        assert!(gm.tau_c_s.lo <= t && t <= gm.tau_c_s.hi);
    }

    #[test]
    fn rejects_bad_input() {
        let cfg = FitConfig::default();
        assert!(fit_noise(&[1.0], &[1.0, 2.0], &[1.0], &cfg, 0.68).is_err());
        assert!(matches!(
            fit_noise(&[1.0, 2.0], &[f64::NAN, 1.0], &[1.0, 1.0], &cfg, 0.68),
            Err(AllanError::NonFinite { index: 0, .. })
        ));
        let t = taus(10, 1.0, 10.0);
        assert!(fit_noise(&t, &t, &t, &cfg, 1.5).is_err());
        assert!(fit_noise(&t[..4], &t[..4], &t[..4], &cfg, 0.68).is_err());
        assert!(fit_noise(&t, &t, &t, &FitConfig::NONE, 0.68).is_err());
        let parsed: FitConfig = "n, b,K".parse().unwrap();
        assert!(parsed.white && parsed.bias_instability && parsed.rate_random_walk);
        assert!(!parsed.quantization && !parsed.rate_ramp && !parsed.gauss_markov);
        assert!("n,x".parse::<FitConfig>().is_err());
    }

    #[test]
    fn fit_range_spec_parses_and_refuses_bad_values() {
        let r: FitRangeSpec = "0.2:2000".parse().unwrap();
        assert_eq!((r.tau_min_s, r.tau_max_s), (Some(0.2), Some(2000.0)));
        let r: FitRangeSpec = " 0.5 : ".parse().unwrap();
        assert_eq!((r.tau_min_s, r.tau_max_s), (Some(0.5), None));
        for bad in ["0.2", "x:1", "1:0.5", "-1:3", "0:3", "1:inf", "2:2"] {
            let e = bad.parse::<FitRangeSpec>().unwrap_err().to_string();
            assert!(e.contains("TMIN:TMAX"), "{bad}: {e}");
        }
    }

    #[test]
    fn short_tau_colour_from_the_lag1_autocorrelation() {
        // White: r1 within its standard error; filtered: clearly positive; quantization
        // (r1 → −½) is a modelled term, not colour.
        assert!(!short_tau_coloured(&[0.001, 0.0], 1_000_000));
        assert!(short_tau_coloured(&[0.17, 0.08], 1_000_000));
        assert!(short_tau_coloured(&[-0.1], 1_000_000));
        assert!(!short_tau_coloured(&[-0.48], 1_000_000));
        // Too few samples to call 0.05 significant.
        assert!(!short_tau_coloured(&[0.05], 1_000));
        assert!(!short_tau_coloured(&[f64::NAN], 1_000_000));
        assert!(!short_tau_coloured(&[], 1_000_000));
        let m: Vec<usize> = (1..=400).collect();
        let c = auto_range_candidates(&m);
        let cm: Vec<usize> = c.iter().map(|&i| m[i]).collect();
        assert_eq!(&cm[..5], &[1, 2, 3, 5, 8]);
        assert!(c.iter().all(|&i| m[i] <= range::AUTO_RANGE_MAX_M));
        assert!(c.windows(2).all(|w| 2 * m[w[1]] >= 3 * m[w[0]]));
    }

    #[test]
    fn model_error_floor_caps_the_weight_of_huge_edf() {
        // Weight of a point with EDF 10⁶ and 10 % floor ≈ that of EDF 200.
        let w_big = weight(1e6, 1.0, 0.1);
        let w_200 = weight(200.0, 1.0, 0.0);
        assert!((w_big / w_200 - 1.0).abs() < 0.01, "{w_big} vs {w_200}");
        // Small EDF: the floor barely matters.
        assert!((weight(10.0, 1.0, 0.01) / weight(10.0, 1.0, 0.0) - 1.0).abs() < 1e-3);
        let t = taus(20, 1.0, 100.0);
        let opts = FitOptions {
            model_error_floor: 1.5,
            ..FitOptions::default()
        };
        assert!(fit_noise_opts(&t, &t, &t, &FitConfig::default(), 0.68, &opts).is_err());
    }

    #[test]
    fn gauss_markov_shorter_than_a_few_samples_is_not_identifiable() {
        // White noise plus a Gauss-Markov term of 3 ms at 100 Hz: at every τ of the curve
        // the term is white noise, so its correlation time runs to the lower bound
        // (5 samples) and must not come out as a value.
        let tau = taus(60, 0.01, 1e3);
        let (n, s, t) = (1e-4, 3e-3, 0.003);
        let avar: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(s, t, x) + 1e-12 * x / 3.0)
            .collect();
        let edf = vec![100.0; tau.len()];
        let cfg: FitConfig = "n,k,gm".parse().unwrap();
        let opts = FitOptions {
            tau0_s: Some(0.01),
            record_s: Some(1e4),
            model_error_floor: 0.0,
        };
        let f = fit_noise_opts(&tau, &avar, &edf, &cfg, 0.683, &opts).unwrap();
        assert!(f.gauss_markov.is_none(), "{f:?}");
        let ni = f
            .not_identifiable
            .iter()
            .find(|u| u.term == TermKind::GaussMarkov)
            .expect("reported");
        assert!(ni.reason.contains("bound"), "{ni:?}");
        // The white noise takes the term's power, N² + 2σ²T at τ ≫ T (a little less at
        // the shortest τ, where τ/T is only 3).
        let want = (n * n + 2.0 * s * s * t).sqrt();
        assert!((f.white.unwrap().value / want - 1.0).abs() < 0.05, "{f:?}");
        // A correlation time inside the bounds is still found.
        let avar2: Vec<f64> = tau
            .iter()
            .map(|&x| n * n / x + gauss_markov_avar(3e-5, 20.0, x))
            .collect();
        let f2 = fit_noise_opts(&tau, &avar2, &edf, &cfg, 0.683, &opts).unwrap();
        let gm = f2.gauss_markov.expect("found");
        assert!((gm.tau_c_s.value / 20.0 - 1.0).abs() < 1e-3, "{gm:?}");
        assert!(f2.not_identifiable.is_empty());
    }

    #[test]
    fn slope_readings_on_model_curve() {
        let tau = taus(100, 0.01, 1e4);
        let (n, b, k) = (1e-5, 1e-5, 1e-6);
        let adev: Vec<f64> = tau
            .iter()
            .map(|&t| (n * n / t + BIAS_AVAR_COEF * b * b + k * k * t / 3.0).sqrt())
            .collect();
        let s = slope_readings(&tau, &adev);
        assert!((s.white.unwrap() / n - 1.0).abs() < 0.05, "{s:?}");
        // The floor reading overestimates B when N and K terms overlap it.
        let br = s.bias_instability.unwrap() / b;
        assert!(br > 1.0 && br < 1.6, "{s:?}");
        assert!(s.rate_random_walk.unwrap() / k > 0.9, "{s:?}");
    }
}

//! Least-squares thermal polynomial fit by Householder QR on a centred, scaled
//! temperature (seed paper §3.3 eqs. 1–2).
//!
//! # Model
//!
//! ```text
//! y(T) = Σ_{k=0}^{p} c_k (T − T_ref)^k,      p = 1 … 5 (default 3), T_ref = 25 °C
//! ```
//!
//! # Solution
//!
//! A Vandermonde matrix in ΔT = T − T_ref is badly conditioned (columns ΔT⁰ … ΔT⁵ span
//! ~10 decades over −25…70 °C), and the normal equations square that condition number.
//! The fit is therefore made in the scaled variable
//!
//! ```text
//! u = (T − T_c)/h,   T_c = (T_min + T_max)/2,   h = (T_max − T_min)/2,   u ∈ [−1, 1]
//! ```
//!
//! by Householder QR of the (row-weighted) Vandermonde matrix V_ij = w_i u_iʲ, w_i = 1/σ_i
//! (or 1): V = QR, R a = (Qᵀ w y)[0..m], m = p + 1 (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., §5.1–5.3). Cov(a) = s² R⁻¹R⁻ᵀ, with s² = 1 when σ_i are given
//! (weights 1/σ_i²), or s² = RSS/(n − m) when the noise level is estimated from the
//! residuals.
//!
//! The scaled coefficients a are mapped *exactly* to powers of ΔT with d = T_c − T_ref:
//!
//! ```text
//! uʲ = h⁻ʲ (ΔT − d)ʲ = h⁻ʲ Σ_{k≤j} C(j,k) ΔTᵏ (−d)^{j−k}
//! c = M a,  M_kj = h⁻ʲ C(j,k) (−d)^{j−k}  (k ≤ j),     Cov(c) = M Cov(a) Mᵀ
//! ```
//!
//! # Input policy
//!
//! * Temperatures need not be sorted (least squares is permutation-invariant; the
//!   cross-validation groups them internally). Repeated temperatures are allowed as
//!   repeated measurements, but the number of *distinct* temperatures (exact `f64`
//!   equality) must be at least p + 1.
//! * NaN/infinite temperatures or values, σ_i ≤ 0 or non-finite, and mismatched lengths
//!   are errors naming the first offending index.
//! * Without σ_i the noise level is estimated from the residuals, which needs n ≥ p + 2
//!   points.

use driftless_model::thermal::{MAX_ORDER, ThermalPoly, ThermalPolyError};

use super::stats::{normal_quantile, student_t_quantile};

mod solve;
mod validation;
use solve::*;
pub use validation::*;

/// Why a thermal fit could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ThermalFitError {
    /// The polynomial order is outside 1 ..= 5.
    #[error("polynomial order {0} not supported (1..={MAX_ORDER})")]
    BadOrder(usize),
    /// Two input slices have different lengths.
    #[error("{what} has {got} entries, expected {expected} (one per temperature)")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Number of temperatures.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A temperature is NaN or infinite (its index).
    #[error("temperature #{0} is not finite")]
    NonFiniteTemperature(usize),
    /// A value is NaN or infinite (its index).
    #[error("value #{0} is not finite")]
    NonFiniteValue(usize),
    /// A standard error is ≤ 0, NaN or infinite (its index).
    #[error("standard error #{0} must be finite and > 0")]
    BadSigma(usize),
    /// The reference temperature is NaN or infinite.
    #[error("reference temperature is not finite")]
    NonFiniteReference,
    /// Not enough distinct temperatures to determine the polynomial.
    #[error("{distinct} distinct temperature(s) cannot determine an order-{order} polynomial (need at least {})", order + 1)]
    TooFewTemperatures {
        /// Distinct temperatures given.
        distinct: usize,
        /// Requested order.
        order: usize,
    },
    /// Without per-point σ the noise level is estimated from the residuals, which needs
    /// at least one residual degree of freedom.
    #[error(
        "{points} points leave no residual degree of freedom for an order-{order} fit without given standard errors"
    )]
    NoResidualDof {
        /// Points given.
        points: usize,
        /// Requested order.
        order: usize,
    },
    /// The weighted design matrix is numerically rank-deficient.
    #[error("the design matrix is numerically rank-deficient (column {0})")]
    RankDeficient(usize),
    /// The covariance given to [`fit_correlated`] is not symmetric positive definite.
    #[error("the point covariance is not symmetric positive definite")]
    CovarianceNotPositiveDefinite,
    /// The confidence level is not in (0, 1).
    #[error("confidence level {0} is not in (0, 1)")]
    BadLevel(f64),
    /// The coefficient index is above the fitted order.
    #[error("coefficient c{index} does not exist in an order-{order} fit")]
    NoSuchCoefficient {
        /// Requested index.
        index: usize,
        /// Fitted order.
        order: usize,
    },
    /// The fitted polynomial could not be represented (non-finite coefficients).
    #[error("fitted polynomial rejected: {0}")]
    Poly(ThermalPolyError),
}

/// Fit settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Polynomial order p, 1 ..= 5 (default 3, seed paper §3.3).
    pub order: usize,
    /// Reference temperature T_ref, °C (default 25 °C, seed paper §3.3).
    pub t_ref_c: f64,
    /// When σ_i are given: also scale the covariance by χ²/dof (Birge ratio) and use
    /// Student-t coverage factors — for σ_i that are only relative weights. Default
    /// `false`: the σ_i are taken as absolute.
    pub rescale_given_sigma: bool,
    /// When σ_i are given as absolute: if the points scatter more than they say
    /// (χ²/dof > 1), multiply the covariance by χ²/dof (the Birge ratio R² =
    /// χ²/(n − p − 1); Birge, Phys. Rev. 40:207, 1932; the Particle Data Group's scale
    /// factor) and use Student-t coverage factors — never shrink it when χ²/dof < 1.
    /// Default `true`: per-step or per-bin σ describe the scatter within a step, not the
    /// drift between steps, and bands from them alone are narrower than the points'
    /// spread. The applied factor is [`ThermalFit::sigma_scale`].
    pub inflate_by_scatter: bool,
}

impl Default for FitOptions {
    fn default() -> FitOptions {
        FitOptions {
            order: 3,
            t_ref_c: 25.0,
            rescale_given_sigma: false,
            inflate_by_scatter: true,
        }
    }
}

/// Where the coefficient covariance's noise scale comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseScale {
    /// Absolute per-point σ_i: Cov = (VᵀWV)⁻¹, normal coverage factors.
    Given,
    /// Estimated: s² = RSS_w/(n − p − 1) (RSS_w = χ² when σ_i are given as relative
    /// weights); Student-t coverage factors with n − p − 1 dof.
    Estimated,
    /// Absolute σ_i whose χ²/dof exceeded 1: Cov = (χ²/dof)·(VᵀWV)⁻¹
    /// ([`FitOptions::inflate_by_scatter`]); Student-t coverage factors with n − p − 1 dof.
    Inflated,
}

/// Result of [`fit`]: y(T) = Σ c_k (T − T_ref)^k with uncertainties.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalFit {
    /// The fitted polynomial (coefficients about T_ref, valid range [min T, max T]).
    pub poly: ThermalPoly,
    /// Order p.
    pub order: usize,
    /// Coefficients c_0 … c_p of (T − T_ref)^k.
    pub coeffs: Vec<f64>,
    /// Covariance of the coefficients, (p+1)×(p+1) row-major.
    pub covariance: Vec<f64>,
    /// Standard errors √Cov_kk.
    pub std_errors: Vec<f64>,
    /// √(Σ r_i²/n), r_i = y_i − ŷ(T_i) (unweighted), in the unit of y.
    pub residual_rms: f64,
    /// χ² = Σ (r_i/σ_i)² when σ_i are given.
    pub chi2: Option<f64>,
    /// χ²/(n − p − 1) when σ_i are given and n > p + 1.
    pub chi2_per_dof: Option<f64>,
    /// Residual degrees of freedom n − p − 1.
    pub dof: usize,
    /// Points used.
    pub n_points: usize,
    /// Distinct temperatures.
    pub n_distinct: usize,
    /// How the covariance is scaled.
    pub noise_scale: NoiseScale,
    /// Factor applied to the points' σ_i (or, without σ_i, the estimated σ itself): 1 for
    /// [`NoiseScale::Given`], √(χ²/dof) for [`NoiseScale::Inflated`] and for rescaled
    /// relative weights, s = √(RSS/(n − p − 1)) without σ_i. The covariance carries its
    /// square; [`ThermalFit::prediction_band`] uses it for a new point's own scatter.
    pub sigma_scale: f64,
    /// Birge ratio √(χ²/dof) observed when σ_i are given (n > p + 1): the points' scatter
    /// relative to their stated σ, whether or not it was applied.
    pub scatter_ratio: Option<f64>,
    t_centre: f64,
    half_range: f64,
    /// Scaled coefficients a_j of u^j, u = (T − T_c)/h.
    coeffs_scaled: Vec<f64>,
    /// Cov(a) of the scaled coefficients (row-major), used for the band.
    cov_scaled: Vec<f64>,
}

/// A confidence band value at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandPoint {
    /// Fitted value ŷ(T).
    pub value: f64,
    /// Standard error of the fitted curve σ_fit(T) = √(gᵀ C g).
    pub std_error: f64,
    /// Lower bound ŷ − k σ_fit.
    pub lo: f64,
    /// Upper bound ŷ + k σ_fit.
    pub hi: f64,
}

impl ThermalFit {
    /// Reference temperature, °C.
    pub fn t_ref_c(&self) -> f64 {
        self.poly.t_ref_c()
    }

    /// Valid range [min T, max T], °C.
    pub fn range_c(&self) -> (f64, f64) {
        self.poly.range_c()
    }

    /// Fitted value at `t_c` (evaluated on the scaled basis; agrees with
    /// `self.poly.eval` to rounding).
    pub fn eval(&self, t_c: f64) -> f64 {
        horner_scaled(&self.coeffs_scaled, self.t_centre, self.half_range, t_c)
    }

    /// Two-sided coverage factor for `level` (e.g. 0.95): z_{(1+level)/2} for
    /// [`NoiseScale::Given`], t_{n−p−1, (1+level)/2} for [`NoiseScale::Estimated`].
    pub fn coverage_factor(&self, level: f64) -> Result<f64, ThermalFitError> {
        if !(level > 0.0 && level < 1.0) {
            return Err(ThermalFitError::BadLevel(level));
        }
        let p = 0.5 * (1.0 + level);
        Ok(match self.noise_scale {
            NoiseScale::Given => normal_quantile(p),
            NoiseScale::Estimated | NoiseScale::Inflated => student_t_quantile(p, self.dof as f64),
        })
    }

    /// Prediction band for a *new* measurement at `t_c` with standard error
    /// `point_sigma` (the unit of y; `None` without per-point σ: the fit's estimated
    /// noise): ŷ ± k·√(σ_fit(T)² + (λ·σ_point)²), λ = [`ThermalFit::sigma_scale`], k as
    /// for [`ThermalFit::band`]. This is the band a held-out point should fall in; the
    /// confidence band [`ThermalFit::band`] is that of the curve alone.
    pub fn prediction_band(
        &self,
        t_c: f64,
        level: f64,
        point_sigma: Option<f64>,
    ) -> Result<BandPoint, ThermalFitError> {
        let k = self.coverage_factor(level)?;
        let value = self.eval(t_c);
        let own = self.sigma_scale * point_sigma.unwrap_or(1.0);
        let s = (self.std_error_at(t_c).powi(2) + own * own).sqrt();
        Ok(BandPoint {
            value,
            std_error: s,
            lo: value - k * s,
            hi: value + k * s,
        })
    }

    /// Standard error of the fitted curve at `t_c`: σ_fit(T)² = gᵀ C g,
    /// g = (1, ΔT, …, ΔT^p) — computed in the equivalent scaled basis
    /// g_u = (1, u, …, u^p), σ² = g_uᵀ Cov(a) g_u, for conditioning.
    pub(crate) fn std_error_at(&self, t_c: f64) -> f64 {
        let m = self.order + 1;
        let u = (t_c - self.t_centre) / self.half_range;
        let mut g = vec![1.0; m];
        for j in 1..m {
            g[j] = g[j - 1] * u;
        }
        let mut v = 0.0;
        for i in 0..m {
            for j in 0..m {
                v += g[i] * self.cov_scaled[i * m + j] * g[j];
            }
        }
        v.max(0.0).sqrt()
    }

    /// Confidence band of the fitted curve at `t_c`: ŷ ± k σ_fit(T) with k from
    /// [`ThermalFit::coverage_factor`] (a pointwise, not simultaneous, band).
    pub fn band(&self, t_c: f64, level: f64) -> Result<BandPoint, ThermalFitError> {
        let k = self.coverage_factor(level)?;
        let value = self.eval(t_c);
        let s = self.std_error_at(t_c);
        Ok(BandPoint {
            value,
            std_error: s,
            lo: value - k * s,
            hi: value + k * s,
        })
    }

    /// Confidence interval (lo, hi) = c_k ± factor · σ(c_k) of coefficient `index`.
    pub fn coeff_interval(&self, index: usize, level: f64) -> Result<(f64, f64), ThermalFitError> {
        if index > self.order {
            return Err(ThermalFitError::NoSuchCoefficient {
                index,
                order: self.order,
            });
        }
        let k = self.coverage_factor(level)?;
        let c = self.coeffs[index];
        let s = self.std_errors[index];
        Ok((c - k * s, c + k * s))
    }
}

/// Validate inputs; returns the number of distinct temperatures.
fn validate(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    order: usize,
    t_ref_c: f64,
) -> Result<usize, ThermalFitError> {
    if !(1..=MAX_ORDER).contains(&order) {
        return Err(ThermalFitError::BadOrder(order));
    }
    if !t_ref_c.is_finite() {
        return Err(ThermalFitError::NonFiniteReference);
    }
    let n = t_c.len();
    if y.len() != n {
        return Err(ThermalFitError::LengthMismatch {
            what: "values",
            expected: n,
            got: y.len(),
        });
    }
    if let Some(s) = sigma {
        if s.len() != n {
            return Err(ThermalFitError::LengthMismatch {
                what: "standard errors",
                expected: n,
                got: s.len(),
            });
        }
        if let Some(i) = s.iter().position(|&v| !(v.is_finite() && v > 0.0)) {
            return Err(ThermalFitError::BadSigma(i));
        }
    }
    if let Some(i) = t_c.iter().position(|v| !v.is_finite()) {
        return Err(ThermalFitError::NonFiniteTemperature(i));
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(ThermalFitError::NonFiniteValue(i));
    }
    let distinct = distinct_groups(t_c).len();
    if distinct < order + 1 {
        return Err(ThermalFitError::TooFewTemperatures { distinct, order });
    }
    Ok(distinct)
}

/// Fit y(T) = Σ c_k (T − T_ref)^k to `(t_c[i], y[i])`, optionally weighted by 1/σ_i².
///
/// See the module docs for the algorithm and the input policy.
pub fn fit(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    opts: &FitOptions,
) -> Result<ThermalFit, ThermalFitError> {
    fit_impl(t_c, y, sigma, None, opts)
}

/// Generalised least squares: [`fit`] with the points' errors correlated, full
/// covariance `covariance` (n×n row-major, symmetric positive definite; e.g. a bias
/// random walk shared by measurements made one after another). Solved by whitening with
/// the Cholesky factor C = LLᵀ; Cov(c) = (AᵀC⁻¹A)⁻¹ (given noise scale, or × χ²/dof with
/// `rescale_given_sigma`). The fit's χ² is the Mahalanobis norm rᵀC⁻¹r.
pub fn fit_correlated(
    t_c: &[f64],
    y: &[f64],
    covariance: &[f64],
    opts: &FitOptions,
) -> Result<ThermalFit, ThermalFitError> {
    let n = t_c.len();
    if covariance.len() != n * n {
        return Err(ThermalFitError::LengthMismatch {
            what: "covariance (n×n)",
            expected: n * n,
            got: covariance.len(),
        });
    }
    let sigma: Vec<f64> = (0..n).map(|i| covariance[i * n + i].sqrt()).collect();
    validate(t_c, y, Some(&sigma), opts.order, opts.t_ref_c)?;
    let l = cholesky(covariance, n).ok_or(ThermalFitError::CovarianceNotPositiveDefinite)?;
    fit_impl(t_c, y, Some(&sigma), Some(&l), opts)
}

/// Lower-triangular L with C = LLᵀ ([`crate::numeric::cholesky`]), or `None` when C is
/// not symmetric (to 1e-12 of √(C_ii C_jj)) or not positive definite.
fn cholesky(c: &[f64], n: usize) -> Option<Vec<f64>> {
    for i in 0..n {
        for j in 0..i {
            if (c[i * n + j] - c[j * n + i]).abs() > 1e-12 * (c[i * n + i] * c[j * n + j]).sqrt() {
                return None;
            }
        }
    }
    crate::numeric::cholesky(c, n)
}

/// Data whose largest magnitude lies outside 2^±[`SAFE_EXPONENT`] are fitted scaled by a
/// power of two (exact in binary floating point) and the results scaled back: squares of
/// residuals near 1e-310 underflow to zero (an uncertainty of exactly 0), those near 1e160
/// overflow.
const SAFE_EXPONENT: i32 = 300;

fn fit_impl(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    chol: Option<&[f64]>,
    opts: &FitOptions,
) -> Result<ThermalFit, ThermalFitError> {
    let largest = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(largest.is_finite() && largest > 0.0) {
        return fit_unscaled(t_c, y, sigma, chol, opts);
    }
    let exponent = largest.log2().round() as i32;
    if exponent.abs() <= SAFE_EXPONENT {
        return fit_unscaled(t_c, y, sigma, chol, opts);
    }
    // y / 2^e, in two steps so that neither factor leaves the normal range.
    let down = |v: f64| v * 2f64.powi(-exponent / 2) * 2f64.powi(-(exponent - exponent / 2));
    let up = |v: f64| v * 2f64.powi(exponent / 2) * 2f64.powi(exponent - exponent / 2);
    let ys: Vec<f64> = y.iter().map(|&v| down(v)).collect();
    let sigmas: Option<Vec<f64>> = sigma.map(|s| s.iter().map(|&v| down(v)).collect());
    let chols: Option<Vec<f64>> = chol.map(|l| l.iter().map(|&v| down(v)).collect());
    let mut f = fit_unscaled(t_c, &ys, sigmas.as_deref(), chols.as_deref(), opts)?;
    for c in f
        .coeffs
        .iter_mut()
        .chain(&mut f.coeffs_scaled)
        .chain(&mut f.std_errors)
    {
        *c = up(*c);
    }
    for c in f.covariance.iter_mut().chain(&mut f.cov_scaled) {
        *c = up(up(*c));
    }
    f.residual_rms = up(f.residual_rms);
    if sigma.is_none() {
        // Without given σ the noise scale is the residual scatter, in the data's unit.
        f.sigma_scale = up(f.sigma_scale);
    }
    let (t_min, t_max) = f.poly.range_c();
    f.poly =
        ThermalPoly::new(opts.t_ref_c, &f.coeffs, t_min, t_max).map_err(ThermalFitError::Poly)?;
    Ok(f)
}

fn fit_unscaled(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    chol: Option<&[f64]>,
    opts: &FitOptions,
) -> Result<ThermalFit, ThermalFitError> {
    let order = opts.order;
    let n_distinct = validate(t_c, y, sigma, order, opts.t_ref_c)?;
    let n = t_c.len();
    let m = order + 1;
    let dof = n - m;
    let mut noise_scale = match sigma {
        Some(_) if !opts.rescale_given_sigma => NoiseScale::Given,
        _ => NoiseScale::Estimated,
    };
    if noise_scale == NoiseScale::Estimated && dof == 0 {
        return Err(ThermalFitError::NoResidualDof { points: n, order });
    }
    let idx: Vec<usize> = (0..n).collect();
    // With a full covariance the whitening carries the weights.
    let row_sigma = if chol.is_some() { None } else { sigma };
    let core = solve_scaled_whitened(t_c, y, row_sigma, chol, &idx, m)?;
    let birge2 = (sigma.is_some() && dof > 0).then(|| core.rss_w / dof as f64);
    if noise_scale == NoiseScale::Given
        && opts.inflate_by_scatter
        && birge2.is_some_and(|r2| r2 > 1.0)
    {
        noise_scale = NoiseScale::Inflated;
    }
    let s2 = match noise_scale {
        NoiseScale::Given => 1.0,
        NoiseScale::Estimated | NoiseScale::Inflated => core.rss_w / dof as f64,
    };
    // Cov(a) = s² R⁻¹ R⁻ᵀ.
    let mut cov_a = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            let s: f64 = (i.max(j)..m)
                .map(|k| core.r_inv[i * m + k] * core.r_inv[j * m + k])
                .sum();
            cov_a[i * m + j] = s2 * s;
        }
    }
    let d = core.t_centre - opts.t_ref_c;
    let mm = scaled_to_dt(m, d, core.half_range);
    let coeffs: Vec<f64> = (0..m)
        .map(|k| (0..m).map(|j| mm[k * m + j] * core.a[j]).sum())
        .collect();
    // Cov(c) = M Cov(a) Mᵀ.
    let mut tmp = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            tmp[i * m + j] = (0..m).map(|k| mm[i * m + k] * cov_a[k * m + j]).sum();
        }
    }
    let mut covariance = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            covariance[i * m + j] = (0..m).map(|k| tmp[i * m + k] * mm[j * m + k]).sum();
        }
    }
    let std_errors = (0..m)
        .map(|k| covariance[k * m + k].max(0.0).sqrt())
        .collect();
    let (t_min, t_max) = t_c
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    let poly =
        ThermalPoly::new(opts.t_ref_c, &coeffs, t_min, t_max).map_err(ThermalFitError::Poly)?;
    let rss: f64 = (0..n)
        .map(|i| (y[i] - horner_scaled(&core.a, core.t_centre, core.half_range, t_c[i])).powi(2))
        .sum();
    let chi2 = sigma.map(|_| core.rss_w);
    let chi2_per_dof = chi2.filter(|_| dof > 0).map(|c| c / dof as f64);
    Ok(ThermalFit {
        poly,
        order,
        coeffs,
        covariance,
        std_errors,
        residual_rms: (rss / n as f64).sqrt(),
        chi2,
        chi2_per_dof,
        dof,
        n_points: n,
        n_distinct,
        noise_scale,
        sigma_scale: s2.sqrt(),
        scatter_ratio: birge2.map(f64::sqrt),
        t_centre: core.t_centre,
        half_range: core.half_range,
        coeffs_scaled: core.a,
        cov_scaled: cov_a,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Data near 1e-301 (and near 1e+301) give the fit of the same data near 1, scaled:
    /// no uncertainty lost to underflowing squares, none overflowing.
    #[test]
    fn tiny_and_huge_data_keep_their_uncertainties() {
        let t: Vec<f64> = (0..30).map(|k| 5.0 + 1.5 * k as f64).collect();
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(k, &x)| 0.3 + 0.01 * x - 2e-4 * x * x + 1e-3 * ((k * 7 % 11) as f64 - 5.0))
            .collect();
        let opts = FitOptions {
            order: 2,
            ..FitOptions::default()
        };
        let base = fit(&t, &y, None, &opts).unwrap();
        assert!(base.std_errors.iter().all(|&s| s > 0.0));
        for e in [-1000, 1000] {
            let k = 2f64.powi(e);
            let ys: Vec<f64> = y.iter().map(|v| v * k).collect();
            let f = fit(&t, &ys, None, &opts).unwrap();
            let close = |a: f64, b: f64| (a - b * k).abs() <= 1e-12 * (b * k).abs();
            for (a, b) in f.std_errors.iter().zip(&base.std_errors) {
                assert!(close(*a, *b), "2^{e}: σ {a:e} vs {b:e}");
            }
            for (a, b) in f.coeffs.iter().zip(&base.coeffs) {
                assert!(close(*a, *b), "2^{e}: c {a:e} vs {b:e}");
            }
            assert!(close(f.residual_rms, base.residual_rms));
            assert!(close(f.sigma_scale, base.sigma_scale));
        }
    }

    #[test]
    fn binomials() {
        assert_eq!(binom(5, 0), 1.0);
        assert_eq!(binom(5, 2), 10.0);
        assert_eq!(binom(4, 4), 1.0);
    }

    #[test]
    fn scaled_to_dt_map_is_exact_reexpansion() {
        // Σ a_j u^j and Σ (M a)_k ΔT^k agree at any T.
        let (tc, h, tref) = (22.5, 47.5, 25.0);
        let a = [0.3, -1.2, 0.7, 0.25, -0.1, 0.05];
        let mm = scaled_to_dt(6, tc - tref, h);
        let c: Vec<f64> = (0..6)
            .map(|k| (0..6).map(|j| mm[k * 6 + j] * a[j]).sum())
            .collect();
        for t in [-40.0, -25.0, 0.0, 25.0, 70.0, 85.0] {
            let u = horner_scaled(&a, tc, h, t);
            let dt = c.iter().rev().fold(0.0, |acc, &v| acc * (t - tref) + v);
            assert!(
                (u - dt).abs() < 1e-13 * u.abs().max(1.0),
                "{t}: {u} vs {dt}"
            );
        }
    }

    #[test]
    fn groups_sort_and_merge_repeats() {
        let g = distinct_groups(&[30.0, -10.0, 30.0, 5.0, -10.0]);
        assert_eq!(g, vec![vec![1, 4], vec![3], vec![0, 2]]);
    }

    #[test]
    fn qr_matches_straight_line() {
        // y = 1 + 2 (T − 25) exactly through three points; covariance of a line fit
        // with σ = 1: Var(c1) = 1/Σ(T − T̄)².
        let t = [15.0, 25.0, 35.0];
        let y = [-19.0, 1.0, 21.0];
        let s = [1.0; 3];
        let o = FitOptions {
            order: 1,
            ..FitOptions::default()
        };
        let f = fit(&t, &y, Some(&s), &o).unwrap();
        assert!((f.coeffs[0] - 1.0).abs() < 1e-14 && (f.coeffs[1] - 2.0).abs() < 1e-14);
        assert!((f.covariance[3] - 1.0 / 200.0).abs() < 1e-16);
        assert!((f.covariance[0] - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(f.dof, 1);
    }

    #[test]
    fn gls_diagonal_equals_weighted_and_common_offset_goes_into_c0() {
        let t = [-20.0, -5.0, 10.0, 25.0, 40.0, 55.0, 70.0];
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(i, &t)| 0.3 + 1e-3 * (t - 25.0) + 0.01 * (i as f64 * 1.7).sin())
            .collect();
        let s: Vec<f64> = (0..t.len()).map(|i| 0.01 + 0.002 * i as f64).collect();
        let n = t.len();
        let o = FitOptions {
            order: 2,
            ..FitOptions::default()
        };
        let w = fit(&t, &y, Some(&s), &o).unwrap();
        let mut c = vec![0.0; n * n];
        for i in 0..n {
            c[i * n + i] = s[i] * s[i];
        }
        let g = fit_correlated(&t, &y, &c, &o).unwrap();
        for k in 0..3 {
            assert!((w.coeffs[k] - g.coeffs[k]).abs() <= 1e-14 * w.coeffs[k].abs().max(1e-3));
            assert!((w.std_errors[k] - g.std_errors[k]).abs() <= 1e-12 * w.std_errors[k]);
        }
        assert!((w.chi2.unwrap() - g.chi2.unwrap()).abs() <= 1e-12 * w.chi2.unwrap());
        // Equal σ plus a common offset of variance k² (C = σ²I + k²·11ᵀ): a constant
        // error is absorbed by c₀ alone, so the estimates equal the unweighted ones,
        // Var(c₁), Var(c₂) are unchanged and Var at any T grows by exactly k².
        let (sig, k) = (0.01, 0.05);
        let mut c = vec![k * k; n * n];
        for i in 0..n {
            c[i * n + i] += sig * sig;
        }
        let e = fit(&t, &y, Some(&[sig; 7]), &o).unwrap();
        let g = fit_correlated(&t, &y, &c, &o).unwrap();
        for j in 0..3 {
            assert!((e.coeffs[j] - g.coeffs[j]).abs() <= 1e-12 * e.coeffs[j].abs().max(1e-3));
        }
        for j in 1..3 {
            assert!((e.std_errors[j] - g.std_errors[j]).abs() <= 1e-9 * e.std_errors[j]);
        }
        for tt in [-20.0, 0.0, 33.0, 70.0] {
            let (ve, vg) = (e.std_error_at(tt).powi(2), g.std_error_at(tt).powi(2));
            assert!(
                (vg - ve - k * k).abs() <= 1e-9 * vg,
                "{tt}: {vg} vs {ve} + {}",
                k * k
            );
        }
        // Not positive definite → an error, not a NaN fit.
        let mut bad = vec![0.0; n * n];
        for i in 0..n {
            bad[i * n + i] = 1.0;
        }
        bad[1] = 2.0;
        bad[n] = 2.0;
        assert_eq!(
            fit_correlated(&t, &y, &bad, &o).unwrap_err(),
            ThermalFitError::CovarianceNotPositiveDefinite
        );
    }
}

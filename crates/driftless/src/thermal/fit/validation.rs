//! Validation of a fitted order: leave-one-temperature-out cross-validation, held-out
//! prediction bands and the order advice (BIC with a parsimony margin).

use super::*;

/// Indices grouped by equal temperature, groups in ascending temperature order.
pub(super) fn distinct_groups(t_c: &[f64]) -> Vec<Vec<usize>> {
    let mut idx: Vec<usize> = (0..t_c.len()).collect();
    idx.sort_by(|&a, &b| t_c[a].total_cmp(&t_c[b]));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in idx {
        match groups.last_mut() {
            Some(g) if t_c[g[0]] == t_c[i] => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    groups
}

/// `keep` ← the indices of every group but group `g`.
pub(super) fn all_but(groups: &[Vec<usize>], g: usize, keep: &mut Vec<usize>) {
    keep.clear();
    for (h, other) in groups.iter().enumerate() {
        if h != g {
            keep.extend_from_slice(other);
        }
    }
}
/// Leave-one-temperature-out cross-validation result.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossValidation {
    /// Order p.
    pub order: usize,
    /// Prediction residual y_i − ŷ_{−T_i}(T_i) of each input point (input order), where
    /// ŷ_{−T_i} is refitted without every point at temperature T_i.
    pub residuals: Vec<f64>,
    /// √(Σ residuals²/n) (unweighted), in the unit of y.
    pub rms: f64,
}

/// Leave-one-temperature-out CV: for each distinct temperature, refit (same weights,
/// same order) without all points at it and predict it. Removing an end temperature makes
/// that prediction an extrapolation — deliberately: it measures how the order behaves at
/// the edges, where cubics go wrong. Needs at least p + 2 distinct temperatures.
pub fn cross_validate(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    opts: &FitOptions,
) -> Result<CrossValidation, ThermalFitError> {
    let order = opts.order;
    let distinct = validate(t_c, y, sigma, order, opts.t_ref_c)?;
    if distinct < order + 2 {
        return Err(ThermalFitError::TooFewTemperatures {
            distinct: distinct - 1,
            order,
        });
    }
    let groups = distinct_groups(t_c);
    let n = t_c.len();
    let mut residuals = vec![0.0; n];
    let mut keep = Vec::with_capacity(n);
    for (g, group) in groups.iter().enumerate() {
        all_but(&groups, g, &mut keep);
        let core = solve_scaled(t_c, y, sigma, &keep, order + 1)?;
        for &i in group {
            residuals[i] = y[i] - horner_scaled(&core.a, core.t_centre, core.half_range, t_c[i]);
        }
    }
    let rms = (residuals.iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt();
    Ok(CrossValidation {
        order,
        residuals,
        rms,
    })
}

/// Held-out check of a fit's uncertainty ([`held_out`]): each point predicted by the fit
/// without its temperature, and the standard error that prediction error should have.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOut {
    /// Order p.
    pub order: usize,
    /// Prediction error e_i = y_i − ŷ_{−T_i}(T_i) of each input point (input order).
    pub residuals: Vec<f64>,
    /// Its standard error under the fit's noise model (module docs of [`held_out`]).
    pub std_errors: Vec<f64>,
    /// Coverage factor used for each point (normal, or Student-t with the reduced fit's
    /// residual dof when the noise scale was estimated or inflated).
    pub coverage_factors: Vec<f64>,
    /// |e_i| ≤ k_i·σ(e_i).
    pub inside: Vec<bool>,
}

impl HeldOut {
    /// Fraction of points inside their band.
    pub fn coverage(&self) -> f64 {
        let n = self.inside.len().max(1) as f64;
        self.inside.iter().filter(|&&b| b).count() as f64 / n
    }
}

/// Leave-one-temperature-out check of the *uncertainty*, not only of the curve: for each
/// distinct temperature, the fit is made again (same order, weights, covariance and
/// noise-scale rule as [`fit`] / [`fit_correlated`] with `opts`) without every point at
/// it, and each held-out point is compared with its prediction band at `level`.
///
/// With C the points' covariance (`covariance` n×n row-major; else diag(σ_i²); else I),
/// K the kept points, A_K their design and ŷ_i = g_iᵀ(A_KᵀC_KK⁻¹A_K)⁻¹A_KᵀC_KK⁻¹ y_K, the
/// prediction error e_i = y_i − ŷ_i has, exactly,
///
/// ```text
/// Var(e_i) = s²·( C_ii − 2 g_iᵀ(AᵀC⁻¹A)⁻¹AᵀC⁻¹ C_Ki + g_iᵀ(AᵀC⁻¹A)⁻¹ g_i )
/// ```
///
/// — the middle term is the correlation of the held-out point with the kept ones (a
/// shared drift), zero for independent points — with s² = 1 for absolute σ, the reduced
/// fit's χ²/dof when it is estimated or inflated ([`FitOptions::inflate_by_scatter`]).
/// A well-calibrated noise model puts ≈ `level` of the points inside; far fewer means
/// the σ are too small, far more that they are too large.
pub fn held_out(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    covariance: Option<&[f64]>,
    opts: &FitOptions,
    level: f64,
) -> Result<HeldOut, ThermalFitError> {
    if !(level > 0.0 && level < 1.0) {
        return Err(ThermalFitError::BadLevel(level));
    }
    let n = t_c.len();
    let order = opts.order;
    let m = order + 1;
    if let Some(c) = covariance
        && c.len() != n * n
    {
        return Err(ThermalFitError::LengthMismatch {
            what: "covariance (n×n)",
            expected: n * n,
            got: c.len(),
        });
    }
    let diag: Option<Vec<f64>> = covariance.map(|c| (0..n).map(|i| c[i * n + i].sqrt()).collect());
    let sig = diag.as_deref().or(sigma);
    let distinct = validate(t_c, y, sig, order, opts.t_ref_c)?;
    if distinct < order + 2 {
        return Err(ThermalFitError::TooFewTemperatures {
            distinct: distinct - 1,
            order,
        });
    }
    let cfull: Vec<f64> = match (covariance, sig) {
        (Some(c), _) => c.to_vec(),
        (None, s) => {
            let mut c = vec![0.0; n * n];
            for i in 0..n {
                c[i * n + i] = s.map_or(1.0, |s| s[i] * s[i]);
            }
            c
        }
    };
    let estimated = sig.is_none() || opts.rescale_given_sigma;
    let p = 0.5 * (1.0 + level);
    let groups = distinct_groups(t_c);
    let mut out = HeldOut {
        order,
        residuals: vec![0.0; n],
        std_errors: vec![0.0; n],
        coverage_factors: vec![0.0; n],
        inside: vec![false; n],
    };
    let mut keep = Vec::with_capacity(n);
    for (g, group) in groups.iter().enumerate() {
        all_but(&groups, g, &mut keep);
        let nk = keep.len();
        let ck: Vec<f64> = (0..nk * nk)
            .map(|q| cfull[keep[q / nk] * n + keep[q % nk]])
            .collect();
        let l = cholesky(&ck, nk).ok_or(ThermalFitError::CovarianceNotPositiveDefinite)?;
        let core = solve_scaled_whitened(t_c, y, None, Some(&l), &keep, m)?;
        let dof = nk - m;
        let r2 = if dof > 0 {
            core.rss_w / dof as f64
        } else {
            f64::NAN
        };
        let scaled = estimated || (opts.inflate_by_scatter && r2 > 1.0);
        if scaled && dof == 0 {
            return Err(ThermalFitError::NoResidualDof { points: nk, order });
        }
        let (s2, k) = if scaled {
            (r2, student_t_quantile(p, dof as f64))
        } else {
            (1.0, normal_quantile(p))
        };
        // (AᵀC⁻¹A)⁻¹ = R⁻¹R⁻ᵀ on the scaled basis, and the whitened design Ã = L⁻¹A.
        let cov_a: Vec<f64> = (0..m * m)
            .map(|q| {
                let (i, j) = (q / m, q % m);
                (i.max(j)..m)
                    .map(|r| core.r_inv[i * m + r] * core.r_inv[j * m + r])
                    .sum()
            })
            .collect();
        let basis = |t: f64| -> Vec<f64> {
            let u = (t - core.t_centre) / core.half_range;
            let mut gv = vec![1.0; m];
            for j in 1..m {
                gv[j] = gv[j - 1] * u;
            }
            gv
        };
        let mut aw = vec![0.0; nk * m];
        let mut col = vec![0.0; nk];
        for j in 0..m {
            for (r, &i) in keep.iter().enumerate() {
                col[r] = basis(t_c[i])[j];
            }
            forward_substitute(&l, nk, &mut col);
            for r in 0..nk {
                aw[r * m + j] = col[r];
            }
        }
        for &i in group {
            let gi = basis(t_c[i]);
            let mut v: Vec<f64> = keep.iter().map(|&r| cfull[r * n + i]).collect();
            forward_substitute(&l, nk, &mut v);
            let q: Vec<f64> = (0..m)
                .map(|j| (0..nk).map(|r| aw[r * m + j] * v[r]).sum())
                .collect();
            let (mut cross, mut fitv) = (0.0, 0.0);
            for a in 0..m {
                for b in 0..m {
                    cross += gi[a] * cov_a[a * m + b] * q[b];
                    fitv += gi[a] * cov_a[a * m + b] * gi[b];
                }
            }
            let var = s2 * (cfull[i * n + i] - 2.0 * cross + fitv).max(0.0);
            let e = y[i] - horner_scaled(&core.a, core.t_centre, core.half_range, t_c[i]);
            let sd = var.sqrt();
            out.residuals[i] = e;
            out.std_errors[i] = sd;
            out.coverage_factors[i] = k;
            out.inside[i] = e.abs() <= k * sd;
        }
    }
    Ok(out)
}

/// One candidate order in [`OrderAdvice`].
#[derive(Clone, Debug, PartialEq)]
pub struct OrderRow {
    /// Order p.
    pub order: usize,
    /// Residual RMS of the fit.
    pub residual_rms: f64,
    /// χ²/dof when σ_i are given.
    pub chi2_per_dof: Option<f64>,
    /// Akaike information criterion −2 ln L̂ + 2K.
    pub aic: f64,
    /// Small-sample AICc = AIC + 2K(K+1)/(n − K − 1) (+∞ when n ≤ K + 1).
    pub aicc: f64,
    /// Bayesian (Schwarz) criterion −2 ln L̂ + K ln n.
    pub bic: f64,
    /// Leave-one-temperature-out CV RMS.
    pub cv_rms: f64,
}

/// Order advice over p = 1 ..= min(5, n_distinct − 2) (the upper limit keeps the
/// cross-validation defined).
#[derive(Clone, Debug, PartialEq)]
pub struct OrderAdvice {
    /// One row per candidate order, ascending.
    pub rows: Vec<OrderRow>,
    /// Order with the lowest BIC (ties → lower order).
    pub min_bic: usize,
    /// Recommended order: the lowest order whose BIC is within `BIC_PARSIMONY` (= 2) of
    /// the minimum — a higher order is adopted only on at least "positive" evidence
    /// (ΔBIC > 2, Kass & Raftery, JASA 90:773, 1995). BIC's ln n penalty already favours
    /// parsimony more than AIC, which suits extrapolation-prone polynomials (Burnham &
    /// Anderson 2002, §6.3); the ΔBIC margin further cuts spurious quartics/quintics.
    pub recommended: usize,
}

/// ΔBIC margin below which the lower order is preferred (see [`OrderAdvice::recommended`]).
pub(crate) const BIC_PARSIMONY: f64 = 2.0;

/// Compare orders by AIC, AICc, BIC and CV (Burnham & Anderson, *Model Selection and
/// Multimodel Inference*, 2nd ed., 2002, §2.2–2.4, §6.3), with the Gaussian likelihood:
///
/// ```text
/// σ unknown:  −2 ln L̂ = n [ln(2π RSS/n) + 1],        K = p + 2  (c₀…c_p and σ²)
/// σ_i given:  −2 ln L̂ = χ² + Σ ln(2π σ_i²),          K = p + 1
/// AIC = −2 ln L̂ + 2K,   AICc = AIC + 2K(K+1)/(n−K−1),   BIC = −2 ln L̂ + K ln n
/// ```
///
/// (`rescale_given_sigma` and `order` in `opts` are ignored; RSS is floored at
/// n·(10⁻¹⁴ max|y|)² so noise-free data do not give −∞.)
pub fn advise_order(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    t_ref_c: f64,
) -> Result<OrderAdvice, ThermalFitError> {
    let distinct = validate(t_c, y, sigma, 1, t_ref_c)?;
    if distinct < 3 {
        return Err(ThermalFitError::TooFewTemperatures { distinct, order: 1 });
    }
    let n = t_c.len();
    let nf = n as f64;
    let max_order = MAX_ORDER.min(distinct - 2);
    let ymax = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let floor = nf * (1e-14 * ymax).powi(2);
    let ln2pi = (2.0 * std::f64::consts::PI).ln();
    let mut rows = Vec::with_capacity(max_order);
    for order in 1..=max_order {
        let opts = FitOptions {
            order,
            t_ref_c,
            rescale_given_sigma: false,
            inflate_by_scatter: false,
        };
        let f = fit(t_c, y, sigma, &opts)?;
        let cv = cross_validate(t_c, y, sigma, &opts)?;
        let (m2ll, k) = match (sigma, f.chi2) {
            (Some(s), Some(chi2)) => (
                chi2.max(floor) + s.iter().map(|v| ln2pi + 2.0 * v.ln()).sum::<f64>(),
                order + 1,
            ),
            _ => {
                let rss = (f.residual_rms.powi(2) * nf).max(floor.max(f64::MIN_POSITIVE));
                (nf * (ln2pi + (rss / nf).ln() + 1.0), order + 2)
            }
        };
        let kf = k as f64;
        let aic = m2ll + 2.0 * kf;
        let aicc = if nf > kf + 1.0 {
            aic + 2.0 * kf * (kf + 1.0) / (nf - kf - 1.0)
        } else {
            f64::INFINITY
        };
        rows.push(OrderRow {
            order,
            residual_rms: f.residual_rms,
            chi2_per_dof: f.chi2_per_dof,
            aic,
            aicc,
            bic: m2ll + kf * nf.ln(),
            cv_rms: cv.rms,
        });
    }
    let mut min_bic = rows.first().map_or(1, |r| r.order);
    let mut best = f64::INFINITY;
    for r in &rows {
        if r.bic < best {
            best = r.bic;
            min_bic = r.order;
        }
    }
    let recommended = rows
        .iter()
        .find(|r| r.bic <= best + BIC_PARSIMONY)
        .map_or(min_bic, |r| r.order);
    Ok(OrderAdvice {
        rows,
        min_bic,
        recommended,
    })
}

//! The weighted linear fit of one triad (bias, scale/misalignment and g-sensitivity) with
//! its parameter covariance.

use super::*;

/// One equation: regressor row, observation, its standard error.
pub(super) struct Row {
    pub(super) x: Vec<f64>,
    pub(super) y: f64,
    pub(super) sigma: f64,
}

/// Weighted LS of one output axis: (params, covariance (JᵀWJ)⁻¹, χ²).
pub(super) fn weighted_fit(
    rows: &[Row],
    n: usize,
    triad: &'static str,
    axis: usize,
    names: &[String],
) -> Result<(Vec<f64>, Vec<f64>, f64), SixPositionError> {
    let m = rows.len();
    // Floor the standard errors at 1e-3 of the largest (noise-free data: all ≈ 0) so
    // that rounding-level σ do not dominate the conditioning; all zero → unit weights.
    let smax = rows.iter().map(|r| r.sigma).fold(0.0, f64::max);
    let sig = |s: f64| if smax > 0.0 { s.max(1e-3 * smax) } else { 1.0 };
    let mut j = Vec::with_capacity(m * n);
    let mut y = Vec::with_capacity(m);
    for r in rows {
        let s = sig(r.sigma);
        j.extend(r.x.iter().map(|v| v / s));
        y.push(r.y / s);
    }
    let lsq_err = |source: LsqError| {
        let param = match &source {
            LsqError::Unobservable { param } => names.get(*param).cloned().unwrap_or_default(),
            _ => String::new(),
        };
        SixPositionError::Lsq {
            triad,
            axis: AX[axis],
            param,
            source,
        }
    };
    let fit = lsq::linear(&j, &y, m, n).map_err(lsq_err)?;
    let (jtj, _) = lsq::normal_equations(&j, &y, m, n);
    let l = crate::numeric::cholesky(&jtj, n)
        .ok_or_else(|| lsq_err(LsqError::Unobservable { param: 0 }))?;
    let chi2: f64 = (0..m)
        .map(|r| {
            let pred: f64 = (0..n).map(|c| j[r * n + c] * fit.params[c]).sum();
            (y[r] - pred).powi(2)
        })
        .sum();
    let cov = crate::numeric::cholesky_inverse(&l, n);
    Ok((fit.params, cov, chi2))
}

/// Assembles A, b and their 12 × 12 covariance (θ_A = vec(A) row-major, then b) from
/// per-axis fits whose first four parameters are (A_i0, A_i1, A_i2, b_i); returns the
/// [`TriadEstimate`] of M = A⁻¹.
pub(super) fn triad_estimate(
    fits: &[(Vec<f64>, Vec<f64>, f64); 3],
    n_params: usize,
    n_eq: usize,
    triad: &'static str,
) -> Result<TriadEstimate, SixPositionError> {
    let mut a = Mat3::ZERO;
    let mut bias = [0.0; 3];
    let mut cov_a = vec![0.0; 144];
    let idx = |i: usize, p: usize| if p < 3 { 3 * i + p } else { 9 + i };
    // Scatter beyond the white-noise σ (bias drift between positions: bias instability,
    // rate random walk) shows as χ²/dof > 1: inflate the covariance by it (Birge ratio),
    // pooled over the three axes of the triad (2–3 degrees of freedom per axis alone
    // would make the factor itself too noisy).
    let dof = 3 * n_eq.saturating_sub(n_params);
    let inflation = if dof > 0 {
        (fits.iter().map(|f| f.2).sum::<f64>() / dof as f64).max(1.0)
    } else {
        1.0
    };
    for (i, (p, c, _)) in fits.iter().enumerate() {
        a.0[i] = [p[0], p[1], p[2]];
        bias[i] = p[3];
        for r in 0..4 {
            for s in 0..4 {
                cov_a[idx(i, r) * 12 + idx(i, s)] = c[r * n_params + s] * inflation;
            }
        }
    }
    let m = a.inverse().ok_or_else(|| {
        SixPositionError::Invalid(format!("{triad}: the estimated A is singular"))
    })?;
    // Jacobian of θ_M = (vec M, b) w.r.t. θ_A: ∂M_ab/∂A_ij = −M_ai·M_jb; b → b.
    let mut jac = vec![0.0; 144];
    for a_ in 0..3 {
        for b_ in 0..3 {
            for i in 0..3 {
                for j in 0..3 {
                    jac[(3 * a_ + b_) * 12 + 3 * i + j] = -m.0[a_][i] * m.0[j][b_];
                }
            }
        }
    }
    for i in 0..3 {
        jac[(9 + i) * 12 + 9 + i] = 1.0;
    }
    let mut tmp = vec![0.0; 144];
    for r in 0..12 {
        for c in 0..12 {
            tmp[r * 12 + c] = (0..12).map(|k| jac[r * 12 + k] * cov_a[k * 12 + c]).sum();
        }
    }
    let mut cov = vec![0.0; 144];
    for r in 0..12 {
        for c in 0..12 {
            cov[r * 12 + c] = (0..12).map(|k| tmp[r * 12 + k] * jac[c * 12 + k]).sum();
        }
    }
    Ok(TriadEstimate {
        calibration: TriadCalibration { bias, matrix: m },
        forward_matrix: a,
        covariance: cov,
        chi2: fits.iter().map(|f| f.2).sum(),
        dof: 3 * n_eq.saturating_sub(n_params),
    })
}

pub(super) fn param_names(triad: &str, i: usize, with_g: bool) -> Vec<String> {
    let mut v: Vec<String> = (0..3)
        .map(|j| format!("{triad} A_{}{}", AX[i], AX[j]))
        .collect();
    v.push(format!("{triad} bias b_{}", AX[i]));
    if with_g {
        v.extend((0..3).map(|j| format!("gyro g-sensitivity G_{}{}", AX[i], AX[j])));
    }
    v
}

pub(super) fn std_error(std: f64, n: usize) -> f64 {
    std / (n as f64).sqrt()
}

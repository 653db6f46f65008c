//! The least-squares core of the thermal fit: QR solves on the scaled temperature basis
//! (plain and whitened by the Cholesky factor of the covariance) and the map from the
//! scaled basis back to powers of (T − T_ref).

use super::*;

/// Householder QR least-squares solution on the scaled basis.
pub(super) struct Core {
    pub(super) t_centre: f64,
    pub(super) half_range: f64,
    /// Scaled coefficients a_0 … a_p.
    pub(super) a: Vec<f64>,
    /// R⁻¹ (upper triangular, m×m row-major).
    pub(super) r_inv: Vec<f64>,
    /// Weighted residual sum of squares ‖w ⊙ (y − ŷ)‖².
    pub(super) rss_w: f64,
}

/// Weighted least squares on u = (T − T_c)/h over the points `idx` by Householder QR
/// (Golub & Van Loan §5.1.2 Householder vectors, §5.3.3 LS via QR).
pub(super) fn solve_scaled(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    idx: &[usize],
    m: usize,
) -> Result<Core, ThermalFitError> {
    solve_scaled_whitened(t_c, y, sigma, None, idx, m)
}

/// Forward substitution x ← L⁻¹x for lower-triangular L (n×n row-major).
pub(super) fn forward_substitute(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let s: f64 = (0..i).map(|j| l[i * n + j] * x[j]).sum();
        x[i] = (x[i] - s) / l[i * n + i];
    }
}

/// [`solve_scaled`], or with `chol` = L (lower-triangular Cholesky factor of the points'
/// full covariance C = LLᵀ, over all points in input order, `idx` = 0..n): generalised
/// least squares by whitening, A ← L⁻¹A, y ← L⁻¹y (Golub & Van Loan §6.1.2).
pub(super) fn solve_scaled_whitened(
    t_c: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    chol: Option<&[f64]>,
    idx: &[usize],
    m: usize,
) -> Result<Core, ThermalFitError> {
    let n = idx.len();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &i in idx {
        lo = lo.min(t_c[i]);
        hi = hi.max(t_c[i]);
    }
    let t_centre = 0.5 * (lo + hi);
    let half_range = if hi > lo { 0.5 * (hi - lo) } else { 1.0 };
    // Weighted design A (n×m row-major) and right-hand side b.
    let mut a = vec![0.0; n * m];
    let mut b = vec![0.0; n];
    for (r, &i) in idx.iter().enumerate() {
        let w = sigma.map_or(1.0, |s| 1.0 / s[i]);
        let u = (t_c[i] - t_centre) / half_range;
        let mut p = w;
        for j in 0..m {
            a[r * m + j] = p;
            p *= u;
        }
        b[r] = w * y[i];
    }
    if let Some(l) = chol {
        let mut col = vec![0.0; n];
        for j in 0..m {
            for r in 0..n {
                col[r] = a[r * m + j];
            }
            forward_substitute(l, n, &mut col);
            for r in 0..n {
                a[r * m + j] = col[r];
            }
        }
        forward_substitute(l, n, &mut b);
    }
    // Householder triangularisation, applying each reflector to b as well.
    let mut diag_max: f64 = 0.0;
    for k in 0..m {
        let norm = (k..n).map(|r| a[r * m + k].powi(2)).sum::<f64>().sqrt();
        if norm == 0.0 {
            return Err(ThermalFitError::RankDeficient(k));
        }
        let alpha = if a[k * m + k] > 0.0 { -norm } else { norm };
        // v = x − α e₁, stored in place of column k (rows k..n).
        a[k * m + k] -= alpha;
        let vtv: f64 = (k..n).map(|r| a[r * m + k].powi(2)).sum();
        if vtv > 0.0 {
            for j in (k + 1)..m {
                let s: f64 = (k..n).map(|r| a[r * m + k] * a[r * m + j]).sum();
                let f = 2.0 * s / vtv;
                for r in k..n {
                    a[r * m + j] -= f * a[r * m + k];
                }
            }
            let s: f64 = (k..n).map(|r| a[r * m + k] * b[r]).sum();
            let f = 2.0 * s / vtv;
            for r in k..n {
                b[r] -= f * a[r * m + k];
            }
        }
        a[k * m + k] = alpha;
        diag_max = diag_max.max(alpha.abs());
    }
    let tol = 1e-13 * diag_max * (n as f64);
    if let Some(k) = (0..m).find(|&k| a[k * m + k].abs() <= tol) {
        return Err(ThermalFitError::RankDeficient(k));
    }
    // Back substitution R x = (Qᵀb)[0..m].
    let mut x = vec![0.0; m];
    for k in (0..m).rev() {
        let s: f64 = ((k + 1)..m).map(|j| a[k * m + j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k * m + k];
    }
    // R⁻¹ column by column (upper triangular).
    let mut r_inv = vec![0.0; m * m];
    for c in 0..m {
        for k in (0..=c).rev() {
            let rhs = if k == c { 1.0 } else { 0.0 };
            let s: f64 = ((k + 1)..=c).map(|j| a[k * m + j] * r_inv[j * m + c]).sum();
            r_inv[k * m + c] = (rhs - s) / a[k * m + k];
        }
    }
    // Residuals recomputed directly (more accurate than ‖(Qᵀb)[m..]‖ when tiny).
    let mut res: Vec<f64> = idx
        .iter()
        .map(|&i| {
            let w = sigma.map_or(1.0, |s| 1.0 / s[i]);
            w * (y[i] - horner_scaled(&x, t_centre, half_range, t_c[i]))
        })
        .collect();
    if let Some(l) = chol {
        forward_substitute(l, n, &mut res);
    }
    let rss_w = res.iter().map(|r| r * r).sum();
    Ok(Core {
        t_centre,
        half_range,
        a: x,
        r_inv,
        rss_w,
    })
}

/// Σ a_j u^j with u = (T − T_c)/h (Horner).
pub(super) fn horner_scaled(a: &[f64], t_centre: f64, half_range: f64, t_c: f64) -> f64 {
    let u = (t_c - t_centre) / half_range;
    a.iter().rev().fold(0.0, |acc, &c| acc * u + c)
}

/// Binomial coefficient C(j, k) for j ≤ 5 (exact in f64).
pub(super) fn binom(j: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (j - i) as f64 / (i + 1) as f64)
}

/// The map M with c = M a (see module docs), m×m row-major; d = T_c − T_ref.
pub(super) fn scaled_to_dt(m: usize, d: f64, h: f64) -> Vec<f64> {
    let mut mm = vec![0.0; m * m];
    for j in 0..m {
        let hj = h.powi(-(j as i32));
        for k in 0..=j {
            mm[k * m + j] = hj * binom(j, k) * (-d).powi((j - k) as i32);
        }
    }
    mm
}

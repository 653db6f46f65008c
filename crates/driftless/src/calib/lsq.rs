//! Small dense least squares for calibration: Cholesky solves of normal equations, the
//! parameter covariance σ̂²(JᵀJ)⁻¹, and a Levenberg–Marquardt driver for nonlinear
//! problems of a few dozen parameters (Madsen, Nielsen & Tingleff, *Methods for
//! non-linear least squares problems*, 2004, §3.2: damping μ adapted by the gain ratio).
//!
//! Matrices are row-major `Vec<f64>` of n × n (or m × n for Jacobians).

use crate::numeric::{cholesky, cholesky_inverse, cholesky_solve};

/// JᵀJ (n × n) and Jᵀr (n) of an m × n Jacobian and m residuals.
pub(crate) fn normal_equations(j: &[f64], r: &[f64], m: usize, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut jtj = vec![0.0; n * n];
    let mut jtr = vec![0.0; n];
    for row in 0..m {
        let jr = &j[row * n..(row + 1) * n];
        for a in 0..n {
            jtr[a] += jr[a] * r[row];
            for b in a..n {
                jtj[a * n + b] += jr[a] * jr[b];
            }
        }
    }
    for a in 0..n {
        for b in 0..a {
            jtj[a * n + b] = jtj[b * n + a];
        }
    }
    (jtj, jtr)
}

/// Result of a least-squares fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// Parameters.
    pub params: Vec<f64>,
    /// Covariance σ̂²(JᵀJ)⁻¹ with σ̂² = Σr²/(m − n) (row-major n × n).
    pub covariance: Vec<f64>,
    /// RMS of the residuals at the solution.
    pub rms: f64,
    /// Iterations used (1 for a linear fit).
    pub iterations: usize,
}

impl Fit {
    /// Standard deviation of parameter `i`.
    pub fn sigma(&self, i: usize) -> f64 {
        let n = self.params.len();
        self.covariance[i * n + i].max(0.0).sqrt()
    }
}

/// Why a fit failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LsqError {
    /// Fewer residuals than parameters.
    #[error("{m} equations cannot determine {n} parameters")]
    TooFewEquations {
        /// Residuals.
        m: usize,
        /// Parameters.
        n: usize,
    },
    /// JᵀJ is singular: some parameter (combination) is not observable.
    #[error("the normal matrix is singular: parameter {param} is not observable from these data")]
    Unobservable {
        /// Index of the first parameter whose pivot vanished (a hint, not a proof).
        param: usize,
    },
    /// A non-finite residual or Jacobian entry.
    #[error("non-finite residual or derivative")]
    NonFinite,
}

/// Index of the first vanishing pivot of a symmetric matrix scaled to unit diagonal
/// (relative tolerance `tol`), for naming an unobservable parameter.
fn first_degenerate(a: &[f64], n: usize, tol: f64) -> usize {
    let d: Vec<f64> = (0..n)
        .map(|i| a[i * n + i].abs().sqrt().max(1e-300))
        .collect();
    let mut s: Vec<f64> = (0..n * n).map(|k| a[k] / (d[k / n] * d[k % n])).collect();
    for i in 0..n {
        let p = s[i * n + i];
        if p.is_nan() || p <= tol {
            return i;
        }
        for r in (i + 1)..n {
            let f = s[r * n + i] / p;
            for c in i..n {
                s[r * n + c] -= f * s[i * n + c];
            }
        }
    }
    n.saturating_sub(1)
}

fn covariance_of(jtj: &[f64], n: usize, ss: f64, m: usize) -> Result<Vec<f64>, LsqError> {
    let l = cholesky(jtj, n).ok_or(LsqError::Unobservable {
        param: first_degenerate(jtj, n, 1e-12),
    })?;
    let dof = (m - n).max(1) as f64;
    Ok(cholesky_inverse(&l, n)
        .into_iter()
        .map(|v| v * ss / dof)
        .collect())
}

/// Linear least squares min ‖J x − y‖ (J m × n row-major).
pub fn linear(j: &[f64], y: &[f64], m: usize, n: usize) -> Result<Fit, LsqError> {
    if m < n {
        return Err(LsqError::TooFewEquations { m, n });
    }
    if j.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(LsqError::NonFinite);
    }
    let (jtj, jty) = normal_equations(j, y, m, n);
    // Jacobi scaling for conditioning.
    let d: Vec<f64> = (0..n).map(|i| jtj[i * n + i].sqrt().max(1e-300)).collect();
    let scaled: Vec<f64> = (0..n * n).map(|k| jtj[k] / (d[k / n] * d[k % n])).collect();
    let l = cholesky(&scaled, n).ok_or(LsqError::Unobservable {
        param: first_degenerate(&jtj, n, 1e-12),
    })?;
    let b: Vec<f64> = (0..n).map(|i| jty[i] / d[i]).collect();
    let x: Vec<f64> = cholesky_solve(&l, n, &b)
        .iter()
        .zip(&d)
        .map(|(v, di)| v / di)
        .collect();
    let mut ss = 0.0;
    for row in 0..m {
        let pred: f64 = (0..n).map(|c| j[row * n + c] * x[c]).sum();
        ss += (y[row] - pred).powi(2);
    }
    Ok(Fit {
        covariance: covariance_of(&jtj, n, ss, m)?,
        params: x,
        rms: (ss / m as f64).sqrt(),
        iterations: 1,
    })
}

/// Levenberg–Marquardt settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmOptions {
    /// Maximum iterations.
    pub max_iterations: usize,
    /// Stop when the relative step ‖Δp‖/(‖p‖ + tol) falls below this.
    pub step_tol: f64,
    /// Stop when the relative decrease of Σr² falls below this.
    pub cost_tol: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 100,
            step_tol: 1e-12,
            cost_tol: 1e-15,
        }
    }
}

/// Minimises Σ r_i(p)² from `p0`. `f(p, r, jac)` fills the m residuals and, when `jac`
/// is `Some`, the m × n Jacobian ∂r/∂p (row-major); use [`numeric_jacobian`] when no
/// analytic one is at hand.
pub fn levenberg_marquardt(
    p0: &[f64],
    m: usize,
    opts: &LmOptions,
    mut f: impl FnMut(&[f64], &mut [f64], Option<&mut [f64]>),
) -> Result<Fit, LsqError> {
    let n = p0.len();
    if m < n {
        return Err(LsqError::TooFewEquations { m, n });
    }
    let mut p = p0.to_vec();
    let mut r = vec![0.0; m];
    let mut j = vec![0.0; m * n];
    f(&p, &mut r, Some(&mut j));
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut c = cost(&r);
    if !c.is_finite() || j.iter().any(|v| !v.is_finite()) {
        return Err(LsqError::NonFinite);
    }
    let (mut jtj, mut jtr) = normal_equations(&j, &r, m, n);
    let mut mu = 1e-3 * (0..n).map(|i| jtj[i * n + i]).fold(0.0, f64::max);
    let mut nu = 2.0;
    let mut it = 0;
    let mut r_new = vec![0.0; m];
    while it < opts.max_iterations {
        it += 1;
        let mut a = jtj.clone();
        for i in 0..n {
            a[i * n + i] += mu.max(1e-300) * jtj[i * n + i].max(1e-300);
        }
        let Some(l) = cholesky(&a, n) else {
            mu *= nu;
            nu *= 2.0;
            continue;
        };
        let neg: Vec<f64> = jtr.iter().map(|v| -v).collect();
        let dp = cholesky_solve(&l, n, &neg);
        let p_new: Vec<f64> = p.iter().zip(&dp).map(|(a, b)| a + b).collect();
        f(&p_new, &mut r_new, None);
        let c_new = cost(&r_new);
        // Gain ratio: actual / predicted decrease.
        let pred: f64 = (0..n)
            .map(|i| dp[i] * (mu * jtj[i * n + i].max(1e-300) * dp[i] - jtr[i]))
            .sum();
        let rho = if pred > 0.0 { (c - c_new) / pred } else { -1.0 };
        if c_new.is_finite() && rho > 0.0 {
            let step = dp.iter().map(|v| v * v).sum::<f64>().sqrt();
            let size = p.iter().map(|v| v * v).sum::<f64>().sqrt();
            let decrease = (c - c_new) / c.max(1e-300);
            p = p_new;
            f(&p, &mut r, Some(&mut j));
            c = cost(&r);
            (jtj, jtr) = normal_equations(&j, &r, m, n);
            mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
            nu = 2.0;
            if step <= opts.step_tol * (size + opts.step_tol) || decrease < opts.cost_tol {
                break;
            }
        } else {
            mu *= nu;
            nu *= 2.0;
            if !mu.is_finite() {
                break;
            }
        }
    }
    Ok(Fit {
        covariance: covariance_of(&jtj, n, c, m)?,
        params: p,
        rms: (c / m as f64).sqrt(),
        iterations: it,
    })
}

/// Central-difference Jacobian of `f` at `p` (steps h_i = 1e-6·max(|p_i|, scale_i)).
pub fn numeric_jacobian(
    p: &[f64],
    m: usize,
    scale: &[f64],
    mut f: impl FnMut(&[f64], &mut [f64]),
    jac: &mut [f64],
) {
    let n = p.len();
    let mut q = p.to_vec();
    let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
    for c in 0..n {
        let h = 1e-6 * p[c].abs().max(scale[c]);
        q[c] = p[c] + h;
        f(&q, &mut rp);
        q[c] = p[c] - h;
        f(&q, &mut rm);
        q[c] = p[c];
        for row in 0..m {
            jac[row * n + c] = (rp[row] - rm[row]) / (2.0 * h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_fit_recovers_a_line_with_sigma() {
        // y = 2 + 3x exactly, then with known noise for σ
        let xs: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let j: Vec<f64> = xs.iter().flat_map(|&x| [1.0, x]).collect();
        let y: Vec<f64> = xs.iter().map(|&x| 2.0 + 3.0 * x).collect();
        let fit = linear(&j, &y, 50, 2).unwrap();
        assert!((fit.params[0] - 2.0).abs() < 1e-12 && (fit.params[1] - 3.0).abs() < 1e-12);
        // a singular design names a parameter
        let j2: Vec<f64> = xs.iter().flat_map(|&x| [x, 2.0 * x]).collect();
        assert!(matches!(
            linear(&j2, &y, 50, 2),
            Err(LsqError::Unobservable { param: 1 })
        ));
    }

    #[test]
    fn lm_fits_a_circle() {
        // points on a circle centre (1, −2), radius 3: residual |x − c| − R
        let pts: Vec<[f64; 2]> = (0..20)
            .map(|i| {
                let a = i as f64 * 0.3;
                [1.0 + 3.0 * a.cos(), -2.0 + 3.0 * a.sin()]
            })
            .collect();
        let f = |p: &[f64], r: &mut [f64], jac: Option<&mut [f64]>| {
            for (i, q) in pts.iter().enumerate() {
                let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                let d = dx.hypot(dy);
                r[i] = d - p[2];
            }
            if let Some(j) = jac {
                for (i, q) in pts.iter().enumerate() {
                    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                    let d = dx.hypot(dy);
                    j[i * 3] = -dx / d;
                    j[i * 3 + 1] = -dy / d;
                    j[i * 3 + 2] = -1.0;
                }
            }
        };
        let fit = levenberg_marquardt(&[0.0, 0.0, 1.0], 20, &LmOptions::default(), f).unwrap();
        for (got, want) in fit.params.iter().zip([1.0, -2.0, 3.0]) {
            assert!((got - want).abs() < 1e-9, "{:?}", fit.params);
        }
        assert!(fit.rms < 1e-9);
    }
}

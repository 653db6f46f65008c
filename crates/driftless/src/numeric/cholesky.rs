//! Dense Cholesky factorisation of small symmetric positive-definite matrices.
//!
//! Matrices are row-major `&[f64]` of n × n. The factor is computed row by row with the
//! Cholesky–Banachiewicz recurrence (Golub & Van Loan, *Matrix Computations*, 4th ed.,
//! Algorithm 4.2.1):
//!
//! ```text
//! L_ij = (A_ij − Σ_{k<j} L_ik L_jk) / L_jj,   L_ii = √(A_ii − Σ_{k<i} L_ik²)
//! ```
//!
//! Only the lower triangle of A is read.

/// Cholesky factor L (row-major, lower) of a symmetric positive-definite n × n matrix,
/// or `None` when it is not numerically positive definite (a pivot ≤ 0 or not finite).
pub fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    Some(l)
}

/// Solves L Lᵀ x = b by forward then back substitution.
pub fn cholesky_solve(l: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] -= l[i * n + k] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    for i in (0..n).rev() {
        for k in (i + 1)..n {
            y[i] -= l[k * n + i] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    y
}

/// (L Lᵀ)⁻¹, column by column through [`cholesky_solve`].
pub fn cholesky_inverse(l: &[f64], n: usize) -> Vec<f64> {
    let mut inv = vec![0.0; n * n];
    for c in 0..n {
        let mut e = vec![0.0; n];
        e[c] = 1.0;
        let x = cholesky_solve(l, n, &e);
        for r in 0..n {
            inv[r * n + c] = x[r];
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matmul_t(l: &[f64], n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| l[i * n + k] * l[j * n + k]).sum();
            }
        }
        a
    }

    #[test]
    fn factor_solve_and_inverse_reproduce_the_matrix() {
        // A = M Mᵀ + I for a fixed non-symmetric M: SPD with condition number ~ 100.
        let n = 4;
        let m: Vec<f64> = (0..n * n)
            .map(|k| ((k * 7 + 3) % 11) as f64 - 5.0)
            .collect();
        let mut a = matmul_t(&m, n);
        for i in 0..n {
            a[i * n + i] += 1.0;
        }
        let l = cholesky(&a, n).expect("SPD");
        for i in 0..n {
            assert!(l[i * n + i] > 0.0);
            for j in i + 1..n {
                assert_eq!(l[i * n + j], 0.0);
            }
        }
        for (got, want) in matmul_t(&l, n).iter().zip(&a) {
            assert!((got - want).abs() < 1e-12 * want.abs().max(1.0));
        }
        let b = [1.0, -2.0, 0.5, 3.0];
        let x = cholesky_solve(&l, n, &b);
        for i in 0..n {
            let ax: f64 = (0..n).map(|k| a[i * n + k] * x[k]).sum();
            assert!((ax - b[i]).abs() < 1e-10, "row {i}: {ax} vs {}", b[i]);
        }
        let inv = cholesky_inverse(&l, n);
        for i in 0..n {
            for j in 0..n {
                let e: f64 = (0..n).map(|k| a[i * n + k] * inv[k * n + j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((e - want).abs() < 1e-10, "(A A⁻¹)[{i}][{j}] = {e}");
            }
        }
    }

    #[test]
    fn rejects_indefinite_and_non_finite() {
        assert!(cholesky(&[1.0, 2.0, 2.0, 1.0], 2).is_none());
        assert!(cholesky(&[0.0], 1).is_none());
        assert!(cholesky(&[f64::NAN], 1).is_none());
        assert!(cholesky(&[f64::INFINITY], 1).is_none());
        assert_eq!(cholesky(&[4.0], 1), Some(vec![2.0]));
        assert_eq!(cholesky(&[], 0), Some(vec![]));
    }
}

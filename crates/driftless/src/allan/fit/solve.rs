//! The numerical core of the fit: iteratively reweighted non-negative least squares,
//! covariance of the active parameters, upper limits, and a golden-section search.

pub(super) struct IrlsSolution {
    pub(super) data: Vec<f64>,
    pub(super) coef: Vec<f64>,
    pub(super) model: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) chi2: f64,
}

/// Weight 1/var of an Allan-variance point with EDF ν and model value m: the χ² variance
/// 2m²/ν (Greenhall & Riley 2003) plus the model-error floor (f·m)².
pub(super) fn weight(edf: f64, model: f64, floor: f64) -> f64 {
    1.0 / (model * model * (2.0 / edf + floor * floor))
}

/// IRLS with model-based weights w_i = 1/(m_i²(2/ν_i + f²)) and an exact NNLS inside.
pub(super) fn irls(cols: &[Vec<f64>], avar: &[f64], edf: &[f64], floor: f64) -> IrlsSolution {
    let n = avar.len();
    let mut model = avar.to_vec();
    let mut w = vec![0.0; n];
    let mut coef = vec![0.0; cols.len()];
    for _ in 0..200 {
        for i in 0..n {
            w[i] = weight(edf[i], model[i], floor);
        }
        coef = nnls(cols, avar, &w);
        let mut change = 0.0f64;
        for i in 0..n {
            let m: f64 = cols.iter().zip(&coef).map(|(c, p)| c[i] * p).sum();
            // Guard: an all-zero model (nothing detected) keeps a tiny positive weight base.
            let m = m.max(1e-6 * avar[i]);
            change = change.max(((m - model[i]) / model[i]).abs());
            model[i] = m;
        }
        if change < 1e-10 {
            break;
        }
    }
    for i in 0..n {
        w[i] = weight(edf[i], model[i], floor);
    }
    let chi2 = (0..n).map(|i| w[i] * (avar[i] - model[i]).powi(2)).sum();
    IrlsSolution {
        data: avar.to_vec(),
        coef,
        model,
        w,
        chi2,
    }
}

/// Most columns of the small least-squares systems of the fit: five linear terms, the
/// Gauss-Markov σ² and its ln T, with room to spare. The systems live on the stack: the
/// fit solves thousands of them per channel (IRLS iterations × supports × the
/// Gauss-Markov search), and allocating each cost more than solving it.
pub(super) const MAXP: usize = 8;

/// Column-scaled weighted normal equations A_jk = Σ w c_j c_k/(s_j s_k),
/// b_j = Σ w c_j y/s_j, yᵀWy, with s_j = √(Σ w c_j²) (unit diagonal, so a pivot test
/// can tell near-collinear columns).
pub(super) struct NormalEquations {
    pub(super) p: usize,
    pub(super) a: [[f64; MAXP]; MAXP],
    pub(super) b: [f64; MAXP],
    pub(super) yy: f64,
    pub(super) s: [f64; MAXP],
}

/// The normal equations of `cols` (at most [`MAXP`]) against `y`, or None with more.
pub(super) fn normal_equations(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Option<NormalEquations> {
    let p = cols.len();
    if p > MAXP {
        return None;
    }
    let mut ne = NormalEquations {
        p,
        a: [[0.0; MAXP]; MAXP],
        b: [0.0; MAXP],
        yy: 0.0,
        s: [1.0; MAXP],
    };
    for (j, c) in cols.iter().enumerate() {
        let s = c.iter().zip(w).map(|(v, w)| w * v * v).sum::<f64>().sqrt();
        ne.s[j] = if s > 0.0 && s.is_finite() { s } else { 1.0 };
    }
    for j in 0..p {
        for k in 0..=j {
            let v: f64 = (0..y.len())
                .map(|i| w[i] * cols[j][i] * cols[k][i])
                .sum::<f64>()
                / (ne.s[j] * ne.s[k]);
            ne.a[j][k] = v;
            ne.a[k][j] = v;
        }
        ne.b[j] = (0..y.len()).map(|i| w[i] * cols[j][i] * y[i]).sum::<f64>() / ne.s[j];
    }
    ne.yy = (0..y.len()).map(|i| w[i] * y[i] * y[i]).sum();
    Some(ne)
}

/// Cholesky solve of the sub-system of `a`, `b` on the columns `idx`; None if (near)
/// singular: the scaled matrix has a unit diagonal, so a pivot below 1e-12 is a
/// near-collinear support.
pub(super) fn solve_subset(
    a: &[[f64; MAXP]; MAXP],
    b: &[f64; MAXP],
    idx: &[usize],
) -> Option<[f64; MAXP]> {
    let n = idx.len();
    let mut l = [[0.0; MAXP]; MAXP];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            let aij = a[idx[i]][idx[j]];
            if i == j {
                let d = aij - s;
                if d.is_nan() || d <= 1e-12 {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (aij - s) / l[j][j];
            }
        }
    }
    let mut y = [0.0; MAXP];
    for i in 0..n {
        let s: f64 = (0..i).map(|k| l[i][k] * y[k]).sum();
        y[i] = (b[idx[i]] - s) / l[i][i];
    }
    let mut x = [0.0; MAXP];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| l[k][i] * x[k]).sum();
        x[i] = (y[i] - s) / l[i][i];
    }
    Some(x)
}

/// Exact non-negative weighted least squares for a handful of columns, by the active-set
/// method of Lawson & Hanson (1974, ch. 23) on the normal equations (the form of Bro &
/// De Jong 1997): move into the passive set the column whose gradient b − Ax is largest
/// and positive, solve the passive sub-system, step back along the segment to the
/// feasible region when a coefficient turns non-positive and release it; stop when no
/// gradient is positive. The problem is convex, so this is the optimum the enumeration
/// of every support would find, at a few sub-system solves instead of 2^p. A column
/// nearly collinear with the passive set is left out.
pub(super) fn nnls(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Vec<f64> {
    let Some(ne) = normal_equations(cols, y, w) else {
        return vec![0.0; cols.len()];
    };
    let p = ne.p;
    let scale = ne.b[..p].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-12 * (1.0 + scale);
    let mut x = [0.0; MAXP];
    let mut passive = [false; MAXP];
    let mut barred = [false; MAXP];
    let mut idx = [0usize; MAXP];
    let gradient =
        |x: &[f64; MAXP], j: usize| ne.b[j] - (0..p).map(|k| ne.a[j][k] * x[k]).sum::<f64>();
    for _ in 0..(4 * MAXP) {
        let Some(j) = (0..p)
            .filter(|&j| !passive[j] && !barred[j])
            .map(|j| (j, gradient(&x, j)))
            .filter(|&(_, g)| g > tol)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(j, _)| j)
        else {
            break;
        };
        passive[j] = true;
        let mut entered = true;
        for _ in 0..(4 * MAXP) {
            let mut k = 0;
            for (c, &on) in passive[..p].iter().enumerate() {
                if on {
                    idx[k] = c;
                    k += 1;
                }
            }
            let Some(sol) = solve_subset(&ne.a, &ne.b, &idx[..k]) else {
                // Collinear with the passive set: leave the newcomer out for good.
                passive[j] = false;
                barred[j] = true;
                entered = false;
                break;
            };
            let mut z = [0.0; MAXP];
            for t in 0..k {
                z[idx[t]] = sol[t];
            }
            if idx[..k].iter().all(|&c| z[c] > 0.0) {
                x = z;
                break;
            }
            // Step from x towards z as far as feasibility allows.
            let alpha = idx[..k]
                .iter()
                .filter(|&&c| z[c] <= 0.0)
                .map(|&c| x[c] / (x[c] - z[c]))
                .fold(f64::INFINITY, f64::min);
            for &c in &idx[..k] {
                x[c] += alpha * (z[c] - x[c]);
                if x[c] <= tol {
                    x[c] = 0.0;
                    passive[c] = false;
                }
            }
            if !passive[..p].iter().any(|&on| on) {
                break;
            }
        }
        if !entered {
            continue;
        }
    }
    // Undo the column scaling.
    (0..p).map(|j| x[j].max(0.0) / ne.s[j]).collect()
}

/// (JᵀWJ)⁻¹ for the given Jacobian columns, None if singular.
pub(super) fn covariance(jac: &[Vec<f64>], w: &[f64]) -> Option<Vec<Vec<f64>>> {
    let p = jac.len();
    if p == 0 {
        return Some(Vec::new());
    }
    let dummy = vec![0.0; w.len()];
    let ne = normal_equations(jac, &dummy, w)?;
    let all: Vec<usize> = (0..p).collect();
    let mut inv = vec![vec![0.0; p]; p];
    for k in 0..p {
        let mut e = [0.0; MAXP];
        e[k] = 1.0;
        let col = solve_subset(&ne.a, &e, &all)?;
        for j in 0..p {
            inv[j][k] = col[j] / (ne.s[j] * ne.s[k]);
        }
    }
    Some(inv)
}

/// Upper limit of a term fitted to zero: refit the final active set plus column `j`
/// without the sign constraint at the final weights; upper = √(max(θ̂_j, 0) + z·s_j).
pub(super) fn upper_limit(
    cols: &[Vec<f64>],
    sol: &IrlsSolution,
    j: usize,
    z: f64,
    scale: f64,
) -> f64 {
    let mut idx: Vec<usize> = (0..cols.len()).filter(|&k| sol.coef[k] > 0.0).collect();
    idx.push(j);
    let sub: Vec<Vec<f64>> = idx.iter().map(|&k| cols[k].clone()).collect();
    let last = idx.len() - 1;
    let all: Vec<usize> = (0..sub.len()).collect();
    let Some(ne) = normal_equations(&sub, &sol.data, &sol.w) else {
        return f64::NAN;
    };
    let (Some(x), Some(cov)) = (solve_subset(&ne.a, &ne.b, &all), covariance(&sub, &sol.w)) else {
        return f64::NAN;
    };
    let theta = x[last] / ne.s[last];
    let sd = (cov[last][last] * scale).max(0.0).sqrt();
    (theta.max(0.0) + z * sd).sqrt()
}

/// Golden-section maximisation of a unimodal function on [a, b]; returns (x*, f(x*)).
pub(crate) fn golden_max<F: Fn(f64) -> f64>(f: F, a: f64, b: f64) -> (f64, f64) {
    golden_max_tol(f, a, b, 1e-10)
}

/// [`golden_max`] stopping when the bracket is narrower than `tol`·(1 + |a| + |b|).
pub(crate) fn golden_max_tol<F: Fn(f64) -> f64>(f: F, a: f64, b: f64, tol: f64) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if (b - a).abs() < tol * (1.0 + a.abs() + b.abs()) {
            break;
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

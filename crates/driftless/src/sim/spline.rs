//! Quintic smoothing splines on uniform knots (penalised regression splines).
//!
//! Given samples (tᵢ, yᵢ) and a uniform knot grid τ_k = t₀ + k·h, k = 0..K, the spline
//! s(t) = Σⱼ cⱼ Bⱼ(t) in the quintic B-spline basis (de Boor 1978/2001, *A Practical
//! Guide to Splines*, ch. IX–X) minimises
//!
//! Σᵢ (yᵢ − s(tᵢ))² + λ ∫ (s‴(t))² dt,
//!
//! the roughness-penalised least-squares criterion of the classic smoothing spline
//! (Reinsch 1967, *Numerische Mathematik* 10; with the penalty on the m-th derivative the
//! exact minimiser over all functions is a natural spline of degree 2m − 1 = 5 with knots
//! at the data; here the basis is restricted to uniform knots, O'Sullivan 1986,
//! *Statistical Science* 1, so evaluation needs no search). The normal equations
//! (BᵀB + λG)c = Bᵀy, G_jk = ∫Bⱼ‴Bₖ‴ dt, are banded (half-bandwidth 5) and solved by a
//! banded Cholesky factorisation in O(K).
//!
//! A quintic spline on simple knots is C⁴: value, velocity and acceleration of a position
//! spline are C⁴, C³, C², and the jerk is continuous.
//!
//! Smoothing parameter: for samples Δ apart the data term ≈ (1/Δ)∫(y − s)² dt, so on a
//! long record the smoother acts as the zero-phase filter H(f) = 1/(1 + λΔ(2πf)⁶)
//! (a sixth-order Butterworth-like magnitude response squared). [`lambda_for_cutoff`]
//! chooses λ so that H(f_c) = ½: λ = 1/(Δ(2πf_c)⁶).
//!
//! After the fit each knot interval stores the power-basis coefficients of its piece in
//! τ = t − τ_k (seconds), so evaluation is an index computed from t plus Horner's rule.

/// Number of coefficients of a quintic piece.
const NC: usize = 6;
/// Half-bandwidth of the normal equations (= degree).
const BW: usize = 5;

/// λ giving the smoother the half-gain frequency `cutoff_hz` for samples
/// `sample_spacing_s` apart (module documentation).
pub(crate) fn lambda_for_cutoff(cutoff_hz: f64, sample_spacing_s: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * cutoff_hz;
    1.0 / (sample_spacing_s * w.powi(6))
}

/// dst += src·(a + b·u) for polynomials in u (coefficient of u^m at index m).
fn add_mul_linear(dst: &mut [f64; NC], src: &[f64; NC], a: f64, b: f64) {
    for m in 0..NC {
        dst[m] += a * src[m];
        if m + 1 < NC {
            dst[m + 1] += b * src[m];
        }
    }
}

/// The six polynomial pieces of the cardinal quintic B-spline N₅ (support [0, 6]):
/// `pieces[i]` is N₅(i + u), u ∈ [0, 1], by the recurrence
/// N_p(x) = [x N_{p−1}(x) + (p + 1 − x) N_{p−1}(x − 1)]/p, N₀ = 1 on [0, 1)
/// (de Boor, ch. IX).
fn cardinal_quintic_pieces() -> [[f64; NC]; NC] {
    let mut prev = [[0.0; NC]; NC];
    prev[0][0] = 1.0;
    for p in 1..NC {
        let mut cur = [[0.0; NC]; NC];
        for (i, piece) in cur.iter_mut().enumerate().take(p + 1) {
            if i < p {
                add_mul_linear(piece, &prev[i], i as f64, 1.0);
            }
            if i >= 1 {
                add_mul_linear(piece, &prev[i - 1], (p + 1 - i) as f64, -1.0);
            }
            for c in piece.iter_mut() {
                *c /= p as f64;
            }
        }
        prev = cur;
    }
    prev
}

/// Basis pieces on one knot interval: `local[j]` is the polynomial (in u = (t − τ_k)/h)
/// of the B-spline with global index k + j, j = 0..5 (it is N₅ shifted so that the
/// interval is its piece 5 − j).
fn local_basis() -> [[f64; NC]; NC] {
    let pieces = cardinal_quintic_pieces();
    std::array::from_fn(|j| pieces[NC - 1 - j])
}

fn poly_eval(c: &[f64; NC], u: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &x| acc * u + x)
}

/// Third derivative of a quintic (coefficients of u⁰..u²).
fn third_derivative(c: &[f64; NC]) -> [f64; 3] {
    std::array::from_fn(|i| {
        let m = i + 3;
        c[m] * (m * (m - 1) * (m - 2)) as f64
    })
}

/// E_ab = ∫₀¹ P_a‴(u) P_b‴(u) du of the local basis (exact polynomial integration).
fn penalty_element(local: &[[f64; NC]; NC]) -> [[f64; NC]; NC] {
    let d3: [[f64; 3]; NC] = std::array::from_fn(|j| third_derivative(&local[j]));
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let mut s = 0.0;
            for (i, x) in d3[a].iter().enumerate() {
                for (j, y) in d3[b].iter().enumerate() {
                    s += x * y / (i + j + 1) as f64;
                }
            }
            s
        })
    })
}

/// Symmetric positive-definite band matrix, lower band stored: `band[i][d]` = A[i][i − d].
struct Band {
    band: Vec<[f64; BW + 1]>,
}

impl Band {
    fn zeros(n: usize) -> Band {
        Band {
            band: vec![[0.0; BW + 1]; n],
        }
    }

    /// In-place Cholesky factorisation A = LLᵀ (L in the band). False if A is not
    /// numerically positive definite.
    fn cholesky(&mut self) -> bool {
        let n = self.band.len();
        for i in 0..n {
            let diag = self.band[i][0];
            let lo = i.saturating_sub(BW);
            for j in lo..=i {
                let mut s = self.band[i][i - j];
                for m in lo.max(j.saturating_sub(BW))..j {
                    s -= self.band[i][i - m] * self.band[j][j - m];
                }
                if i == j {
                    // A pivot lost to rounding (relative to its diagonal): singular.
                    if !(s > 1e-13 * diag && s.is_finite()) {
                        return false;
                    }
                    self.band[i][0] = s.sqrt();
                } else {
                    self.band[i][i - j] = s / self.band[j][0];
                }
            }
        }
        true
    }

    /// Solves LLᵀx = b in place (after [`Band::cholesky`]) for D right-hand sides.
    fn solve<const D: usize>(&self, b: &mut [[f64; D]]) {
        let n = self.band.len();
        // Forward: L z = b.
        for i in 0..n {
            let lo = i.saturating_sub(BW);
            let (done, rest) = b.split_at_mut(i);
            let mut s = rest[0];
            for (m, bm) in done.iter().enumerate().skip(lo) {
                let l = self.band[i][i - m];
                for (sc, bc) in s.iter_mut().zip(bm) {
                    *sc -= l * bc;
                }
            }
            rest[0] = s.map(|x| x / self.band[i][0]);
        }
        // Backward: Lᵀ x = z.
        for i in (0..n).rev() {
            let hi = (i + BW + 1).min(n);
            let (head, done) = b.split_at_mut(i + 1);
            let mut s = head[i];
            for (m, bm) in done[..hi - i - 1].iter().enumerate() {
                let l = self.band[i + 1 + m][m + 1];
                for (sc, bc) in s.iter_mut().zip(bm) {
                    *sc -= l * bc;
                }
            }
            head[i] = s.map(|x| x / self.band[i][0]);
        }
    }
}

/// A D-component quintic spline on uniform knots τ_k = t₀ + k·h, k = 0..K, stored as
/// power-basis pieces; outside [τ₀, τ_K] the end pieces are continued (polynomial
/// extrapolation: meant for a few samples at most).
#[derive(Clone, Debug)]
pub(crate) struct QuinticSpline<const D: usize> {
    t0_s: f64,
    h_s: f64,
    inv_h: f64,
    /// Per interval k and component c: coefficients a_m of (t − τ_k)^m, m = 0..5.
    coef: Vec<[[f64; NC]; D]>,
}

impl<const D: usize> QuinticSpline<D> {
    /// Penalised least-squares fit (module documentation) of samples `y` at times `t`
    /// (all within [t0_s, t0_s + n_intervals·h_s]) with penalty weight `lambda`
    /// (s⁵·unit⁻²·unit²: compare [`lambda_for_cutoff`]). `None` when the normal equations
    /// are not positive definite (fewer than three distinct sample times, λ ≤ 0 with
    /// empty knot intervals, non-finite input).
    pub(crate) fn fit(
        t: &[f64],
        y: &[[f64; D]],
        t0_s: f64,
        h_s: f64,
        n_intervals: usize,
        lambda: f64,
    ) -> Option<QuinticSpline<D>> {
        if n_intervals == 0
            || t.len() != y.len()
            || h_s.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            return None;
        }
        let local = local_basis();
        let n = n_intervals + BW;
        let mut a = Band::zeros(n);
        let mut rhs = vec![[0.0; D]; n];
        let locate = |ti: f64| {
            let x = (ti - t0_s) / h_s;
            let k = (x.floor().max(0.0) as usize).min(n_intervals - 1);
            (k, x - k as f64)
        };
        for (&ti, yi) in t.iter().zip(y) {
            let (k, u) = locate(ti);
            let b: [f64; NC] = std::array::from_fn(|j| poly_eval(&local[j], u));
            for p in 0..NC {
                for q in 0..=p {
                    a.band[k + p][p - q] += b[p] * b[q];
                }
                for c in 0..D {
                    rhs[k + p][c] += b[p] * yi[c];
                }
            }
        }
        let e = penalty_element(&local);
        let w = lambda / h_s.powi(5);
        for k in 0..n_intervals {
            for (p, row) in e.iter().enumerate() {
                for (q, epq) in row.iter().enumerate().take(p + 1) {
                    a.band[k + p][p - q] += w * epq;
                }
            }
        }
        if !a.cholesky() {
            return None;
        }
        a.solve(&mut rhs);
        // Power-basis pieces in τ = t − τ_k: a_m = Σⱼ c_{k+j} P_j[m] / h^m.
        let hp: [f64; NC] = std::array::from_fn(|m| h_s.powi(-(m as i32)));
        let coef = (0..n_intervals)
            .map(|k| {
                std::array::from_fn(|c| {
                    std::array::from_fn(|m| {
                        (0..NC).map(|j| rhs[k + j][c] * local[j][m]).sum::<f64>() * hp[m]
                    })
                })
            })
            .collect();
        Some(QuinticSpline {
            t0_s,
            h_s,
            inv_h: 1.0 / h_s,
            coef,
        })
    }

    /// Knot interval of `t_s` (clamped to the ends) and τ = t − τ_k.
    #[inline]
    fn locate(&self, t_s: f64) -> (usize, f64) {
        let x = (t_s - self.t0_s) * self.inv_h;
        let last = self.coef.len() - 1;
        let k = if x <= 0.0 { 0 } else { (x as usize).min(last) };
        (k, t_s - (self.t0_s + k as f64 * self.h_s))
    }

    /// Value and first derivative.
    #[inline]
    pub(crate) fn eval1(&self, t_s: f64) -> ([f64; D], [f64; D]) {
        let (k, x) = self.locate(t_s);
        let cf = &self.coef[k];
        let mut v = [0.0; D];
        let mut d1 = [0.0; D];
        for c in 0..D {
            let a = &cf[c];
            v[c] = ((((a[5] * x + a[4]) * x + a[3]) * x + a[2]) * x + a[1]) * x + a[0];
            d1[c] = (((5.0 * a[5] * x + 4.0 * a[4]) * x + 3.0 * a[3]) * x + 2.0 * a[2]) * x + a[1];
        }
        (v, d1)
    }

    /// Value, first and second derivatives.
    #[inline]
    pub(crate) fn eval2(&self, t_s: f64) -> ([f64; D], [f64; D], [f64; D]) {
        let (k, x) = self.locate(t_s);
        let cf = &self.coef[k];
        let mut v = [0.0; D];
        let mut d1 = [0.0; D];
        let mut d2 = [0.0; D];
        for c in 0..D {
            let a = &cf[c];
            v[c] = ((((a[5] * x + a[4]) * x + a[3]) * x + a[2]) * x + a[1]) * x + a[0];
            d1[c] = (((5.0 * a[5] * x + 4.0 * a[4]) * x + 3.0 * a[3]) * x + 2.0 * a[2]) * x + a[1];
            d2[c] = ((20.0 * a[5] * x + 12.0 * a[4]) * x + 6.0 * a[3]) * x + 2.0 * a[2];
        }
        (v, d1, d2)
    }

    /// Third derivative (tests: continuity of the jerk across knots).
    #[cfg(test)]
    pub(crate) fn eval3(&self, t_s: f64) -> [f64; D] {
        let (k, x) = self.locate(t_s);
        let cf = &self.coef[k];
        std::array::from_fn(|c| {
            let a = &cf[c];
            (60.0 * a[5] * x + 24.0 * a[4]) * x + 6.0 * a[3]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_a_partition_of_unity_and_c4() {
        let local = local_basis();
        for u in [0.0, 0.3, 0.77, 1.0] {
            let s: f64 = local.iter().map(|p| poly_eval(p, u)).sum();
            assert!((s - 1.0).abs() < 1e-14, "{u}: {s}");
        }
        // N₅ pieces join C⁴ at the interior integer knots.
        let pieces = cardinal_quintic_pieces();
        for i in 0..NC - 1 {
            let mut a = pieces[i];
            let mut b = pieces[i + 1];
            for _ in 0..5 {
                let ra = poly_eval(&a, 1.0);
                let rb = poly_eval(&b, 0.0);
                assert!((ra - rb).abs() < 1e-13, "piece {i}: {ra} {rb}");
                a = std::array::from_fn(|m| {
                    if m + 1 < NC {
                        a[m + 1] * (m + 1) as f64
                    } else {
                        0.0
                    }
                });
                b = std::array::from_fn(|m| {
                    if m + 1 < NC {
                        b[m + 1] * (m + 1) as f64
                    } else {
                        0.0
                    }
                });
            }
        }
    }

    /// Quadratics are in the null space of the penalty: reproduced exactly at any λ.
    #[test]
    fn reproduces_quadratics_and_smooths_noise() {
        let t: Vec<f64> = (0..41).map(|i| 10.0 + 0.5 * i as f64).collect();
        let y: Vec<[f64; 2]> = t
            .iter()
            .map(|&x| [3.0 - 2.0 * x + 0.25 * x * x, -1.0 + 0.1 * x])
            .collect();
        let s = QuinticSpline::fit(&t, &y, 10.0, 0.7, 29, 50.0).expect("fit");
        for x in [9.9, 10.0, 13.3, 21.0, 29.99, 30.0] {
            let (v, d1, d2) = s.eval2(x);
            assert!((v[0] - (3.0 - 2.0 * x + 0.25 * x * x)).abs() < 1e-9, "{x}");
            assert!((d1[0] - (-2.0 + 0.5 * x)).abs() < 1e-9, "{x}");
            assert!((d2[0] - 0.5).abs() < 1e-9, "{x}");
            assert!((v[1] - (-1.0 + 0.1 * x)).abs() < 1e-10, "{x}");
            assert!(s.eval3(x)[0].abs() < 1e-8, "{x}");
        }
        // Jerk (third derivative) continuous across a knot for a generic fit.
        let y2: Vec<[f64; 1]> = t.iter().map(|&x| [(0.9 * x).sin()]).collect();
        let s2 = QuinticSpline::fit(&t, &y2, 10.0, 0.5, 40, 1e-3).expect("fit");
        for k in [3.0, 17.0] {
            let knot = 10.0 + k * 0.5;
            let (a, b) = (s2.eval3(knot - 1e-9)[0], s2.eval3(knot + 1e-9)[0]);
            assert!((a - b).abs() < 1e-6, "{a} {b}");
        }
        // Small λ follows the data closely away from the ends (at the ends the natural
        // boundary conditions s‴ = s⁗ = 0 of the smoothing spline bias the fit).
        for (x, yv) in t.iter().zip(&y2).skip(4).take(t.len() - 8) {
            let r = s2.eval1(*x).0[0] - yv[0];
            assert!(r.abs() < 5e-4, "{x}: {r}");
        }
    }

    #[test]
    fn rejects_degenerate_input() {
        let t = [0.0, 0.0, 0.0];
        let y = [[1.0], [1.0], [1.0]];
        assert!(QuinticSpline::fit(&t, &y, 0.0, 1.0, 3, 1.0).is_none());
        assert!(QuinticSpline::<1>::fit(&[], &[], 0.0, 1.0, 0, 1.0).is_none());
    }
}

//! Equivalent degrees of freedom of finite-difference stability variances by the
//! general algorithm of C. A. Greenhall and W. J. Riley, "Uncertainty of stability
//! variances based on finite differences", Proc. 35th PTTI Meeting (2003), pp. 267–280.
//!
//! # Model
//! A variance of order `d` (d = 1 first difference, 2 Allan, 3 Hadamard) at averaging
//! factor `m` is estimated as the mean of M squared filtered phase values
//! z_n = (d-th difference over m of the phase, averaged over m/F samples), taken with
//! stride m/S samples:
//!
//! * F (filter factor) = m for the unmodified variances, 1 for the modified ones
//!   (MVAR, TVAR), whose phase is first averaged over m samples;
//! * S (stride factor) = 1 for non-overlapping estimators (stride τ), m for fully
//!   overlapping ones (stride τ0).
//!
//! With L = m/F + m·d phase samples per term, M = 1 + ⌊S(N − L)/m⌋ terms and J = min(M,
//! (d+1)S) correlated lags,
//!
//! ```text
//! 1/edf = BasicSum(J, M, S, F, α, d) / (M · sz(0, F, α, d)²)                    (13)
//! BasicSum = sz(0)² + (1 − J/M)·sz(J/S)² + 2 Σ_{j=1}^{J−1} (1 − j/M)·sz(j/S)²    (10)
//! sz(t) = Σ_{k=−d}^{d} (−1)^k C(2d, d+k) sx(t + k)                              (9)
//! sx(t) = F²[2 sw(t) − sw(t − 1/F) − sw(t + 1/F)],  sx(t, ∞) = sw(t, α + 2)     (8)
//! sw(t) = −|t|, t² ln|t|, |t|³, −t⁴ ln|t|, −|t|⁵, t⁶ ln|t|, |t|⁷ for α = 2 … −4  (7)
//! ```
//!
//! sz is (up to a constant) the autocovariance of z at lag t·m samples for power-law
//! frequency noise S_y(f) ∝ f^α. The paper's §5 algorithm bounds the work at
//! J_max = 100 terms and switches to the fitted asymptotic forms of its Tables 1–3 for
//! large J; that is reproduced here case by case (cases 1–4 below).

/// The J limit of the paper's algorithm.
const J_MAX: f64 = 100.0;

/// sw(t, α), eq. (7). Only the shape matters: every EDF is a ratio of sums of sz².
fn sw(t: f64, alpha: i32) -> f64 {
    let a = t.abs();
    let tlog = |p: i32| if a == 0.0 { 0.0 } else { a.powi(p) * a.ln() };
    match alpha {
        2 => -a,
        1 => tlog(2),
        0 => a * a * a,
        -1 => -tlog(4),
        -2 => -a.powi(5),
        -3 => tlog(6),
        _ => a.powi(7), // −4 (callers clamp alpha to −4..=4)
    }
}

/// sx(t, F, α), eq. (8); `f = ∞` selects the F → ∞ limit sw(t, α + 2).
fn sx(t: f64, f: f64, alpha: i32) -> f64 {
    if f.is_infinite() {
        sw(t, alpha + 2)
    } else {
        let h = 1.0 / f;
        f * f * (2.0 * sw(t, alpha) - sw(t - h, alpha) - sw(t + h, alpha))
    }
}

/// Binomial coefficient C(n, k) for small n.
fn binom(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * f64::from(n - i) / f64::from(i + 1))
}

/// sz(t, F, α, d), eq. (9).
fn sz(t: f64, f: f64, alpha: i32, d: u32) -> f64 {
    let d_i = d as i32;
    (-d_i..=d_i)
        .map(|k| {
            let c = binom(2 * d, (d_i + k) as u32);
            let s = if k % 2 == 0 { c } else { -c };
            s * sx(t + f64::from(k), f, alpha)
        })
        .sum()
}

/// BasicSum(J, M, S, F, α, d), eq. (10).
fn basic_sum(j: f64, m_terms: f64, s: f64, f: f64, alpha: i32, d: u32) -> f64 {
    let mut sum = sz(0.0, f, alpha, d).powi(2);
    sum += (1.0 - j / m_terms) * sz(j / s, f, alpha, d).powi(2);
    let jn = j as u64;
    for jj in 1..jn {
        let jf = jj as f64;
        sum += 2.0 * (1.0 - jf / m_terms) * sz(jf / s, f, alpha, d).powi(2);
    }
    sum
}

/// Table 1 (modified variances, F = 1): 1/edf ≈ (a0 − a1/r)/r for r = M/S ≥ d + 1.
/// Rows α = 2 … −4, columns d = 1, 2, 3; `None` where α + 2d ≤ 1.
fn table1(alpha: i32, d: u32) -> Option<(f64, f64)> {
    const T: [[Option<(f64, f64)>; 3]; 7] = [
        [
            Some((2.0 / 3.0, 1.0 / 3.0)),
            Some((7.0 / 9.0, 1.0 / 2.0)),
            Some((22.0 / 25.0, 2.0 / 3.0)),
        ],
        [
            Some((0.840, 0.345)),
            Some((0.997, 0.616)),
            Some((1.141, 0.843)),
        ],
        [
            Some((1.079, 0.368)),
            Some((1.033, 0.607)),
            Some((1.184, 0.848)),
        ],
        [None, Some((1.048, 0.534)), Some((1.180, 0.816))],
        [None, Some((1.302, 0.535)), Some((1.175, 0.777))],
        [None, None, Some((1.194, 0.703))],
        [None, None, Some((1.489, 0.702))],
    ];
    T.get((2 - alpha) as usize)?
        .get((d - 1) as usize)
        .copied()?
}

/// Table 2 (unmodified variances, F = m): 1/edf ≈ (a0 − a1/r)/r (times 1/(b0 + b1 ln m)²
/// for α = 1, Table 3). Rows α = 2 … −4, columns d = 1, 2, 3.
fn table2(alpha: i32, d: u32) -> Option<(f64, f64)> {
    const T: [[Option<(f64, f64)>; 3]; 7] = [
        [
            Some((3.0 / 2.0, 1.0 / 2.0)),
            Some((35.0 / 18.0, 1.0)),
            Some((231.0 / 100.0, 3.0 / 2.0)),
        ],
        [
            Some((78.6, 25.2)),
            Some((790.0, 410.0)),
            Some((9950.0, 6520.0)),
        ],
        [
            Some((2.0 / 3.0, 1.0 / 6.0)),
            Some((2.0 / 3.0, 1.0 / 3.0)),
            Some((7.0 / 9.0, 1.0 / 2.0)),
        ],
        [None, Some((0.852, 0.375)), Some((0.997, 0.617))],
        [None, Some((1.079, 0.368)), Some((1.033, 0.607))],
        [None, None, Some((1.053, 0.553))],
        [None, None, Some((1.302, 0.535))],
    ];
    T.get((2 - alpha) as usize)?
        .get((d - 1) as usize)
        .copied()?
}

/// Table 3 (unmodified, α = 1): sz(0, m, 1, d) ≈ b0 + b1 ln m.
fn table3(d: u32) -> (f64, f64) {
    match d {
        1 => (6.0, 4.0),
        2 => (15.23, 12.0),
        _ => (47.8, 40.0),
    }
}

/// Equivalent degrees of freedom of a general finite-difference variance (Greenhall &
/// Riley 2003, §5 algorithm with J_max = 100).
///
/// * `alpha` — frequency-noise exponent (S_y ∝ f^α). The model needs α + 2d > 1 and
///   α ∈ −4..=2; values outside are clamped into that range.
/// * `d` — difference order: 1, 2 (Allan family) or 3 (Hadamard); clamped to 1..=3.
/// * `m` — averaging factor (τ = m τ0); 0 is treated as 1.
/// * `s` — stride factor S: the estimator's terms are m/S samples apart (1 =
///   non-overlapping, m = fully overlapping; a reduced-overlap "fast" estimator with
///   stride k samples has S = m/k). Clamped to [1, m]; it need not be an integer.
/// * `f` — filter factor F: 1 for the modified variances (MVAR, TVAR), m for the
///   unmodified ones. The paper's algorithm covers only these two; any other value
///   is treated as the nearer of them on a log scale.
/// * `n_phase` — number of phase points N.
///
/// Returns a finite value ≥ 1. If N < L = m/F + m·d (not even one term fits) the
/// estimate does not exist and 1.0 is returned; a single χ² term carries one degree
/// of freedom, the least any estimate has (every 1/edf from eq. (13) is ≤ 1).
pub fn edf_greenhall(alpha: i32, d: u32, m: usize, s: f64, f: f64, n_phase: usize) -> f64 {
    let d = d.clamp(1, 3);
    let alpha = alpha.clamp(2 - 2 * d as i32, 2);
    let m = m.max(1) as f64;
    let s = if s.is_finite() { s.clamp(1.0, m) } else { 1.0 };
    // Modified (F = 1) or unmodified (F = m)?
    let modified = m > 1.0 && f.is_finite() && f > 0.0 && f * f < m;
    let f = if modified { 1.0 } else { m };
    let n = n_phase as f64;
    let dd = f64::from(d);

    let l = m / f + m * dd;
    if n < l {
        return 1.0;
    }
    let m_terms = 1.0 + (s * (n - l) / m).floor();
    let j = m_terms.min(((dd + 1.0) * s).floor());
    let r = m_terms / s;

    let inv_edf = if modified {
        // Case 1: modified variances, all α.
        if j <= J_MAX {
            basic_sum(j, m_terms, s, 1.0, alpha, d) / (m_terms * sz(0.0, 1.0, alpha, d).powi(2))
        } else if r >= dd + 1.0
            && let Some((a0, a1)) = table1(alpha, d)
        {
            (a0 - a1 / r) / r
        } else {
            let m_prime = J_MAX / r;
            basic_sum(J_MAX, J_MAX, m_prime, 1.0, alpha, d)
                / (J_MAX * sz(0.0, 1.0, alpha, d).powi(2))
        }
    } else if alpha <= 0 {
        // Case 2: unmodified variances, α ≤ 0.
        if j <= J_MAX {
            // Beyond m(d+1) > J_max the F → ∞ limit avoids round-off in eq. (8).
            let fp = if m * (dd + 1.0) <= J_MAX {
                m
            } else {
                f64::INFINITY
            };
            basic_sum(j, m_terms, s, fp, alpha, d) / (m_terms * sz(0.0, fp, alpha, d).powi(2))
        } else if r >= dd + 1.0
            && let Some((a0, a1)) = table2(alpha, d)
        {
            (a0 - a1 / r) / r
        } else {
            let m_prime = J_MAX / r;
            basic_sum(J_MAX, J_MAX, m_prime, f64::INFINITY, alpha, d)
                / (J_MAX * sz(0.0, f64::INFINITY, alpha, d).powi(2))
        }
    } else if alpha == 1 {
        // Case 3: unmodified variances, flicker PM.
        let (b0, b1) = table3(d);
        if j <= J_MAX && m < 1e6 {
            basic_sum(j, m_terms, s, m, 1, d) / (m_terms * sz(0.0, m, 1, d).powi(2))
        } else if r >= dd + 1.0
            && let Some((a0, a1)) = table2(1, d)
        {
            (a0 - a1 / r) / ((b0 + b1 * m.ln()).powi(2) * r)
        } else {
            let m_prime = J_MAX / r;
            basic_sum(J_MAX, J_MAX, m_prime, m_prime, 1, d) / ((b0 + b1 * m.ln()).powi(2) * J_MAX)
        }
    } else {
        // Case 4: unmodified variances, white PM. The phase samples are independent, so
        // z_n and z_n' correlate only when their distance (n'−n)·m/S is k·m, |k| ≤ d,
        // with ρ_k = (−1)^k C(2d, d+k)/C(2d, d):
        //   1/edf = (1/M) [1 + 2 Σ_{k=1}^{min(d, K−1)} (1 − k/r) ρ_k²],  K = ⌈r⌉,
        // which for K > d is the paper's (1/M)(a0 − a1/r) with a0 = C(4d,2d)/C(2d,d)²,
        // a1 = d/2 (Table 2, α = 2).
        let c0 = binom(2 * d, d);
        let mut acc = 1.0;
        for k in 1..=d {
            let kf = f64::from(k);
            let lag = kf * s; // in units of terms
            if lag < m_terms && (lag - lag.round()).abs() < 1e-9 {
                let rho = binom(2 * d, d + k) / c0;
                acc += 2.0 * (1.0 - kf / r) * rho * rho;
            }
        }
        acc / m_terms
    };

    let edf = 1.0 / inv_edf;
    // Eq. (13) always gives edf ≥ 1; only the fitted tables could dip below it.
    if edf.is_finite() && edf >= 1.0 {
        edf
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact eq. (13) with no J_max shortcut (used to check the tables).
    fn exact(alpha: i32, d: u32, m: f64, s: f64, f: f64, n: f64) -> f64 {
        let l = m / f + m * f64::from(d);
        let mt = 1.0 + (s * (n - l) / m).floor();
        let j = mt.min(((f64::from(d) + 1.0) * s).floor());
        mt * sz(0.0, f, alpha, d).powi(2) / basic_sum(j, mt, s, f, alpha, d)
    }

    #[test]
    fn white_fm_point_sampled_allan_closed_form() {
        // Non-overlapping ADEV, white FM, m(d+1) > J_max so the algorithm uses F = ∞
        // (point-sampled phase): second differences are first differences of independent
        // m-averages of y, correlated only at lag 1 with ρ = −1/2, so
        // 1/edf = (1/M)(1 + 2(1 − 1/M)/4).
        let n = 100_001;
        for m in [50usize, 64, 1000] {
            let e = edf_greenhall(0, 2, m, 1.0, m as f64, n);
            let mt = 1.0 + ((n as f64 - 1.0 - 2.0 * m as f64) / m as f64).floor();
            let expect = mt / (1.0 + 0.5 * (1.0 - 1.0 / mt));
            assert!((e - expect).abs() / expect < 1e-9, "m={m} {e} vs {expect}");
        }
        // At m = 1 the F = m model averages the phase over τ0, which decorrelates
        // neighbouring terms less: the EDF is larger than the point-sampled 2M/3
        // (782.03 for the NBS14 set, as Stable32 prints it).
        let e1 = edf_greenhall(0, 2, 1, 1.0, 1.0, 1001);
        assert!(e1 > 999.0 / 1.5 * 1.1 && e1 < 999.0, "{e1}");
    }

    #[test]
    fn white_pm_closed_form_matches_basic_sum() {
        // Case 4's closed form equals eq. (13) evaluated directly (small m, no round-off).
        for d in 1..=3u32 {
            for (m, s) in [(3usize, 1.0), (3, 3.0), (5, 5.0), (4, 2.0)] {
                for n in [40usize, 200] {
                    let c = edf_greenhall(2, d, m, s, m as f64, n);
                    let e = exact(2, d, m as f64, s, m as f64, n as f64);
                    assert!(
                        (c - e).abs() / e < 1e-9,
                        "d={d} m={m} s={s} n={n}: {c} vs {e}"
                    );
                }
            }
        }
    }

    #[test]
    fn tables_agree_with_exact_sums() {
        // Tables 1 and 2 are fits to eq. (13) for large r; check them (to the paper's
        // 3-digit precision plus fit error) against the exact sum where J just exceeds
        // J_max, so the algorithm takes the table branch.
        for d in 1..=3u32 {
            for alpha in (2 - 2 * d as i32)..=0 {
                // overlapped, S = m = 60: J = (d+1)S > J_max for every d
                let (m, n) = (60usize, 60_000usize);
                let t = edf_greenhall(alpha, d, m, m as f64, 1.0, n);
                let e = exact(alpha, d, m as f64, m as f64, 1.0, n as f64);
                assert!((t - e).abs() / e < 0.01, "mod a={alpha} d={d}: {t} vs {e}");
                // overlapped unmodified
                let t = edf_greenhall(alpha, d, m, m as f64, m as f64, n);
                let e = exact(alpha, d, m as f64, m as f64, f64::INFINITY, n as f64);
                assert!(
                    (t - e).abs() / e < 0.01,
                    "unmod a={alpha} d={d}: {t} vs {e}"
                );
            }
        }
    }

    #[test]
    fn flicker_pm_table3_matches_sz() {
        // Table 3: sz(0, m, 1, d) ≈ b0 + b1 ln m for large m.
        for d in 1..=3u32 {
            let (b0, b1) = table3(d);
            for m in [64.0f64, 512.0] {
                let direct = sz(0.0, m, 1, d).abs();
                let fit = b0 + b1 * m.ln();
                assert!(
                    (direct - fit).abs() / direct < 0.01,
                    "d={d} m={m}: {direct} vs {fit}"
                );
            }
        }
    }

    #[test]
    fn table_branches_close_to_exact_sum_at_the_switch() {
        // At the first m where J = (d+1)S exceeds J_max the algorithm leaves eq. (13) for
        // the fitted Tables 1–3. There the exact sum (with the true F) is still cheap:
        // the tables must agree to a few percent (they are fitted to the F → ∞ limit,
        // which is ~3 % off at m = 34 for unmodified white FM; flicker PM's Table 3 fit
        // is ~2 % off).
        let n = 20_000;
        for (alpha, d, modified) in [
            (0, 2, false),
            (-1, 2, true),
            (-2, 3, false),
            (1, 2, false),
            (2, 2, true),
            (-4, 3, true),
        ] {
            let m = 34usize; // (d+1)·34 > 100 for d ≥ 2
            let f = if modified { 1.0 } else { m as f64 };
            let alg = edf_greenhall(alpha, d, m, m as f64, f, n);
            let ex = exact(alpha, d, m as f64, m as f64, f, n as f64);
            assert!(
                (alg - ex).abs() / ex < 0.035,
                "a={alpha} d={d} mod={modified}: {alg} vs exact {ex}"
            );
        }
    }

    #[test]
    fn degenerate_inputs_stay_finite() {
        for alpha in -9..=9 {
            for d in 0..=5u32 {
                for (m, n) in [
                    (0usize, 0usize),
                    (1, 1),
                    (1, 3),
                    (5, 10),
                    (1000, 3),
                    (7, 1 << 40),
                ] {
                    let e = edf_greenhall(alpha, d, m, m as f64, 1.0, n);
                    assert!(e.is_finite() && e >= 1.0, "{alpha} {d} {m} {n}: {e}");
                    let e = edf_greenhall(alpha, d, m, f64::NAN, m as f64, n);
                    assert!(e.is_finite() && e >= 1.0, "{alpha} {d} {m} {n}: {e}");
                }
            }
        }
    }
}

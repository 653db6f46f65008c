//! Stability estimators on phase data x (N points, spacing τ0), NIST SP 1065 §5.2.
//!
//! With τ = m·τ0 and second differences Δ²ᵢ = x_{i+2m} − 2x_{i+m} + x_i:
//!
//! * ADEV  σ²(τ) = Σ_{i=0,m,2m,…} (Δ²ᵢ)² / (2τ²·n),  n = ⌊(N−1)/m⌋ − 1 (SP 1065 eq. 7)
//! * OADEV σ²(τ) = Σ_{i=0}^{N−2m−1} (Δ²ᵢ)² / (2τ²·n), n = N − 2m (eq. 11)
//! * MDEV  σ²(τ) = Σ_{j=0}^{N−3m} (Σ_{i=j}^{j+m−1} Δ²ᵢ)² / (2m²τ²·n), n = N − 3m + 1 (eq. 14)
//! * TDEV  σ_x²(τ) = (τ²/3)·MVAR (eq. 16), same n as MDEV
//! * HDEV  third differences Δ³ᵢ = x_{i+3m} − 3x_{i+2m} + 3x_{i+m} − x_i at stride m:
//!   σ²(τ) = Σ (Δ³ᵢ)² / (6τ²·n), n = ⌊(N−1)/m⌋ − 2 (eq. 17)
//! * OHDEV the same at stride 1, n = N − 3m (eq. 18)
//! * TOTDEV OADEV-type sum over i = 1..N−2 of the phase extended by reflection at both
//!   ends, x*_{−j} = 2x_0 − x_j, x*_{N−1+j} = 2x_{N−1} − x_{N−1−j}; σ² = Σ/(2τ²(N−2)) (eq. 25)
//!
//! Every estimator first produces raw [`Sums`] (sum of squares and term count) so that
//! data split at gaps can be combined segment by segment without a term straddling a gap.
//!
//! Speed: the overlapping second/third-difference sums dominate (6 channels × 6.5 M
//! points × 100 taus ≈ 4·10⁹ terms). Taus whose difference span fits in L2 are evaluated
//! together block by block, so each block of x is read from memory once for all of them;
//! longer taus stream x three times. Both are split across cores with rayon.

use super::{DevPoint, Estimator};
use rayon::prelude::*;

/// Raw estimator output for one averaging factor: Σ of squared differences and the
/// number of terms. [`finish`] turns it into a deviation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sums {
    /// Averaging factor.
    pub m: usize,
    /// Sum of squared (second or third) differences, phase units².
    pub sum: f64,
    /// Number of terms summed.
    pub n: usize,
}

impl Sums {
    /// Combine two sums for the same m (e.g. from two gap-separated segments).
    pub(crate) fn merge(self, other: Sums) -> Sums {
        debug_assert_eq!(self.m, other.m);
        Sums {
            m: self.m,
            sum: self.sum + other.sum,
            n: self.n + other.n,
        }
    }
}

/// Elements of x a block covers in the cache-blocked sweep.
const BLOCK: usize = 32 * 1024;
/// Difference spans (order·m) up to this many elements are processed in the blocked sweep
/// (block + span ≈ 40k f64 = 320 KiB stays in L2).
const SMALL_SPAN: usize = usize::MAX / 4;
/// Blocks handed to one rayon task.
const BLOCKS_PER_TASK: usize = 16;

/// Compute raw sums of `estimator` on phase `x` for each factor in `ms`.
///
/// Factors the data cannot support yield `n = 0` (callers check with
/// [`super::taus::averaging_factors`] first).
pub fn sums(estimator: Estimator, x: &[f64], ms: &[usize]) -> Vec<Sums> {
    match estimator {
        Estimator::Oadev => overlapping::<2>(x, ms),
        Estimator::Ohdev => overlapping::<3>(x, ms),
        Estimator::Adev => ms.par_iter().map(|&m| strided::<2>(x, m, m)).collect(),
        Estimator::Hdev => ms.par_iter().map(|&m| strided::<3>(x, m, m)).collect(),
        Estimator::Mdev | Estimator::Tdev => ms.par_iter().map(|&m| modified(x, m)).collect(),
        Estimator::Totdev => total(x, ms),
    }
}

/// Reduced-overlap OADEV: second differences taken every `max(1, m / overlap)` samples
/// instead of every sample. `overlap = 1` is the non-overlapping estimator's stride,
/// large `overlap` approaches the fully overlapping one. The estimate is unbiased; it
/// has fewer degrees of freedom (see `ci::edf_greenhall` with stride factor
/// S = m / stride) in exchange for touching ~overlap·N/m terms per tau.
pub fn oadev_strided_sums(x: &[f64], ms: &[usize], overlap: usize) -> Vec<Sums> {
    let overlap = overlap.max(1);
    // Factors whose stride is 1 are the fully overlapping estimator: use the blocked,
    // vectorised path for them.
    let dense: Vec<usize> = ms.iter().copied().filter(|&m| m / overlap <= 1).collect();
    let mut dense_sums = overlapping::<2>(x, &dense).into_iter();
    let sparse: Vec<Sums> = ms
        .par_iter()
        .filter(|&&m| m / overlap > 1)
        .map(|&m| strided::<2>(x, m, m / overlap))
        .collect();
    let mut sparse = sparse.into_iter();
    ms.iter()
        .filter_map(|&m| {
            if m / overlap <= 1 {
                dense_sums.next()
            } else {
                sparse.next()
            }
        })
        .collect()
}

/// Deviation from raw sums (see the module docs for each normalisation).
/// Returns NaN only when `s.n == 0`, which [`deviations`] never passes on.
pub fn finish(estimator: Estimator, s: Sums, tau0_s: f64) -> f64 {
    let m = s.m as f64;
    let n = s.n as f64;
    let tau = m * tau0_s;
    let var = match estimator {
        Estimator::Adev | Estimator::Oadev | Estimator::Totdev => s.sum / (2.0 * tau * tau * n),
        Estimator::Hdev | Estimator::Ohdev => s.sum / (6.0 * tau * tau * n),
        Estimator::Mdev => s.sum / (2.0 * m * m * tau * tau * n),
        Estimator::Tdev => s.sum / (6.0 * m * m * n),
    };
    var.sqrt()
}

/// Convenience: deviations of `estimator` on phase `x` at factors `ms`, dropping
/// factors with no terms.
pub fn deviations(estimator: Estimator, x: &[f64], tau0_s: f64, ms: &[usize]) -> Vec<DevPoint> {
    sums(estimator, x, ms)
        .into_iter()
        .filter(|s| s.n > 0)
        .map(|s| DevPoint {
            m: s.m,
            tau: s.m as f64 * tau0_s,
            n: s.n,
            dev: finish(estimator, s, tau0_s),
        })
        .collect()
}

/// Overlapping ADEV on phase data (shorthand for [`deviations`] with [`Estimator::Oadev`]).
pub fn oadev(x: &[f64], tau0_s: f64, ms: &[usize]) -> Vec<DevPoint> {
    deviations(Estimator::Oadev, x, tau0_s, ms)
}

/// Σ_{i=start}^{end−1} (finite difference of order D at lag m, starting at i)².
/// D = 2: x_{i+2m} − 2x_{i+m} + x_i;  D = 3: x_{i+3m} − 3x_{i+2m} + 3x_{i+m} − x_i.
/// Requires end − 1 + D·m < x.len().
///
/// Dispatches at run time to a copy compiled for AVX2 when the CPU has it (≈1.4× faster
/// on the OADEV benchmark); both copies add in the same 8-lane order, so the results are
/// bit-identical.
#[inline]
#[allow(unsafe_code)]
fn diff_sumsq<const D: usize>(x: &[f64], m: usize, start: usize, end: usize) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `diff_sumsq_avx2` differs from the portable kernel only in being
            // compiled with the `avx2` target feature; the CPU supports AVX2 (checked just
            // above), which is the sole requirement for calling it.
            return unsafe { diff_sumsq_avx2::<D>(x, m, start, end) };
        }
    }
    diff_sumsq_portable::<D>(x, m, start, end)
}

/// [`diff_sumsq`] compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn diff_sumsq_avx2<const D: usize>(x: &[f64], m: usize, start: usize, end: usize) -> f64 {
    diff_sumsq_portable::<D>(x, m, start, end)
}

/// The portable kernel (also the body of the AVX2 copy).
#[inline(always)]
fn diff_sumsq_portable<const D: usize>(x: &[f64], m: usize, start: usize, end: usize) -> f64 {
    let len = end.saturating_sub(start);
    if len == 0 {
        return 0.0;
    }
    let a = &x[start..start + len];
    let b = &x[start + m..start + m + len];
    let c = &x[start + 2 * m..start + 2 * m + len];
    const L: usize = 8;
    let mut acc = [0.0f64; L];
    let mut tail = 0.0f64;
    if D == 2 {
        let (ac, bc, cc) = (a.chunks_exact(L), b.chunks_exact(L), c.chunks_exact(L));
        let (ar, br, cr) = (ac.remainder(), bc.remainder(), cc.remainder());
        for ((aa, bb), cc) in ac.zip(bc).zip(cc) {
            for k in 0..L {
                let d = (cc[k] + aa[k]) - 2.0 * bb[k];
                acc[k] += d * d;
            }
        }
        for k in 0..ar.len() {
            let d = (cr[k] + ar[k]) - 2.0 * br[k];
            tail += d * d;
        }
    } else {
        let e = &x[start + 3 * m..start + 3 * m + len];
        let (ac, bc, cc, ec) = (
            a.chunks_exact(L),
            b.chunks_exact(L),
            c.chunks_exact(L),
            e.chunks_exact(L),
        );
        let (ar, br, cr, er) = (
            ac.remainder(),
            bc.remainder(),
            cc.remainder(),
            ec.remainder(),
        );
        for (((aa, bb), cc), ee) in ac.zip(bc).zip(cc).zip(ec) {
            for k in 0..L {
                let d = (ee[k] - aa[k]) + 3.0 * (bb[k] - cc[k]);
                acc[k] += d * d;
            }
        }
        for k in 0..ar.len() {
            let d = (er[k] - ar[k]) + 3.0 * (br[k] - cr[k]);
            tail += d * d;
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// Fully overlapping sums of order D (OADEV: 2, OHDEV: 3), cache-blocked for short spans.
fn overlapping<const D: usize>(x: &[f64], ms: &[usize]) -> Vec<Sums> {
    let n = x.len();
    let terms = |m: usize| n.saturating_sub(D * m);
    let mut out: Vec<Sums> = ms
        .iter()
        .map(|&m| Sums {
            m,
            sum: 0.0,
            n: if m == 0 { 0 } else { terms(m) },
        })
        .collect();

    let small: Vec<usize> = (0..ms.len())
        .filter(|&j| ms[j] > 0 && D * ms[j] <= SMALL_SPAN && terms(ms[j]) > 0)
        .collect();
    let large: Vec<usize> = (0..ms.len())
        .filter(|&j| ms[j] > 0 && D * ms[j] > SMALL_SPAN && terms(ms[j]) > 0)
        .collect();

    if !small.is_empty() {
        let max_terms = small.iter().map(|&j| terms(ms[j])).max().unwrap_or(0);
        let n_blocks = max_terms.div_ceil(BLOCK);
        let task_starts: Vec<usize> = (0..n_blocks).step_by(BLOCKS_PER_TASK).collect();
        let partial: Vec<f64> = task_starts
            .par_iter()
            .map(|&b0| {
                let mut acc = vec![0.0f64; small.len()];
                for b in b0..(b0 + BLOCKS_PER_TASK).min(n_blocks) {
                    let start = b * BLOCK;
                    for (slot, &j) in small.iter().enumerate() {
                        let m = ms[j];
                        let end = (start + BLOCK).min(terms(m));
                        if start < end {
                            acc[slot] += diff_sumsq::<D>(x, m, start, end);
                        }
                    }
                }
                acc
            })
            .reduce(
                || vec![0.0f64; small.len()],
                |mut a, b| {
                    for (u, v) in a.iter_mut().zip(b) {
                        *u += v;
                    }
                    a
                },
            );
        for (slot, &j) in small.iter().enumerate() {
            out[j].sum = partial[slot];
        }
    }

    // Long spans: split each tau's range into chunks so both cores share the work.
    let chunk = 1 << 20;
    let jobs: Vec<(usize, usize, usize)> = large
        .iter()
        .flat_map(|&j| {
            let t = terms(ms[j]);
            (0..t)
                .step_by(chunk)
                .map(move |s| (j, s, (s + chunk).min(t)))
        })
        .collect();
    let parts: Vec<(usize, f64)> = jobs
        .par_iter()
        .map(|&(j, s, e)| (j, diff_sumsq::<D>(x, ms[j], s, e)))
        .collect();
    for (j, v) in parts {
        out[j].sum += v;
    }
    out
}

/// Order-D differences at lag m taken every `stride` samples (ADEV/HDEV: stride = m).
/// Term count: non-overlapping ADEV n = ⌊(N−1)/m⌋ − 1, HDEV n = ⌊(N−1)/m⌋ − 2.
fn strided<const D: usize>(x: &[f64], m: usize, stride: usize) -> Sums {
    let n_pts = x.len();
    if m == 0 || n_pts <= D * m {
        return Sums { m, sum: 0.0, n: 0 };
    }
    let last_start = n_pts - 1 - D * m; // inclusive
    let n = last_start / stride + 1;
    let mut sum = 0.0;
    let mut i = 0;
    while i <= last_start {
        let d = if D == 2 {
            (x[i + 2 * m] + x[i]) - 2.0 * x[i + m]
        } else {
            (x[i + 3 * m] - x[i]) + 3.0 * (x[i + m] - x[i + 2 * m])
        };
        sum += d * d;
        i += stride;
    }
    Sums { m, sum, n }
}

/// MVAR sum: Σ_j (Σ_{i=j}^{j+m−1} Δ²ᵢ)², the inner sum carried as a running sum
/// (add the entering difference, drop the leaving one): O(N) per factor.
fn modified(x: &[f64], m: usize) -> Sums {
    let n_pts = x.len();
    if m == 0 || n_pts < 3 * m {
        return Sums { m, sum: 0.0, n: 0 };
    }
    let outer = n_pts - 3 * m + 1;
    let d2 = |i: usize| (x[i + 2 * m] + x[i]) - 2.0 * x[i + m];
    let mut s: f64 = (0..m).map(d2).sum();
    let mut sum = s * s;
    for j in 1..outer {
        s += d2(j + m - 1) - d2(j - 1);
        sum += s * s;
    }
    Sums { m, sum, n: outer }
}

/// TOTVAR sums on the reflection-extended phase (SP 1065 eq. 25).
fn total(x: &[f64], ms: &[usize]) -> Vec<Sums> {
    let n = x.len();
    if n < 3 {
        return ms.iter().map(|&m| Sums { m, sum: 0.0, n: 0 }).collect();
    }
    // e[off + k] = x[k]; off = N − 2 reflected points on each side.
    let off = n - 2;
    let mut e = Vec::with_capacity(n + 2 * off);
    let (first, last) = (x[0], x[n - 1]);
    for j in (1..=off).rev() {
        e.push(2.0 * first - x[j]);
    }
    e.extend_from_slice(x);
    for j in 1..=off {
        e.push(2.0 * last - x[n - 1 - j]);
    }
    ms.par_iter()
        .map(|&m| {
            if m == 0 || m > off + 1 {
                return Sums { m, sum: 0.0, n: 0 };
            }
            // centre index off+k for k = 1..N−2 → start index off + 1 − m.
            let start = off + 1 - m;
            let sum = diff_sumsq::<2>(&e, m, start, start + (n - 2));
            Sums { m, sum, n: n - 2 }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::frequency_to_phase;

    /// NIST SP 1065 NBS14 1000-point test set: n0 = 1234567890, n ← 16807·n mod (2³¹−1),
    /// y = n/(2³¹−1), starting with n0 itself (the published values need the seed as y₁).
    fn nbs14() -> Vec<f64> {
        let mut n: u64 = 1_234_567_890;
        (0..1000)
            .map(|i| {
                if i > 0 {
                    n = (16807 * n) % 2_147_483_647;
                }
                n as f64 / 2_147_483_647.0
            })
            .collect()
    }

    fn naive_oadev(x: &[f64], m: usize) -> f64 {
        let k = x.len() - 2 * m;
        let s: f64 = (0..k)
            .map(|i| (x[i + 2 * m] - 2.0 * x[i + m] + x[i]).powi(2))
            .sum();
        (s / (2.0 * (m * m) as f64 * k as f64)).sqrt()
    }

    /// SP 1065 Table 31 values, frequency input, tau = 1, 10, 100.
    #[test]
    fn nbs14_reference_values_from_frequency_and_phase() {
        let y = nbs14();
        let x = frequency_to_phase(&y, 1.0);
        assert_eq!(x.len(), 1001);
        let expected: [(Estimator, [f64; 3]); 5] = [
            (Estimator::Adev, [2.922319e-01, 9.965736e-02, 3.897804e-02]),
            (Estimator::Oadev, [2.922319e-01, 9.159953e-02, 3.241343e-02]),
            (Estimator::Mdev, [2.922319e-01, 6.172376e-02, 2.170921e-02]),
            (Estimator::Hdev, [2.943883e-01, 1.052754e-01, 3.910860e-02]),
            (Estimator::Tdev, [1.687202e-01, 3.563623e-01, 1.253382e+00]),
        ];
        // phase input: integrate without the mean removal a user's phase file would have
        let mut x_raw = vec![0.0];
        for v in &y {
            let last = *x_raw.last().unwrap();
            x_raw.push(last + v);
        }
        for phase in [&x, &x_raw] {
            for (est, vals) in &expected {
                let got = deviations(*est, phase, 1.0, &[1, 10, 100]);
                assert_eq!(got.len(), 3, "{est:?}");
                for (p, want) in got.iter().zip(vals) {
                    let rel = (p.dev - want).abs() / want;
                    assert!(
                        rel < 1e-6,
                        "{est:?} m={} got {} want {want} rel {rel:e}",
                        p.m,
                        p.dev
                    );
                }
            }
        }
    }

    #[test]
    fn blocked_overlapping_matches_naive_for_small_and_large_spans() {
        // a random walk phase long enough for both code paths
        let mut s = 0x1234_5678_9abc_def0u64;
        let mut acc = 0.0;
        let x: Vec<f64> = (0..200_000)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                acc += (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                acc
            })
            .collect();
        let ms = [1, 3, 1000, 16_384, 16_385, 20_000, 49_999];
        let got = oadev(&x, 1.0, &ms);
        for p in &got {
            let want = naive_oadev(&x, p.m);
            assert!(
                (p.dev - want).abs() / want < 1e-12,
                "m={} {} {}",
                p.m,
                p.dev,
                want
            );
            assert_eq!(p.n, x.len() - 2 * p.m);
        }
        // OHDEV vs naive third differences
        for &m in &[1usize, 7, 11_000, 20_000] {
            let k = x.len() - 3 * m;
            let s: f64 = (0..k)
                .map(|i| (x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i]).powi(2))
                .sum();
            let want = (s / (6.0 * (m * m) as f64 * k as f64)).sqrt();
            let got = deviations(Estimator::Ohdev, &x, 1.0, &[m]);
            assert!((got[0].dev - want).abs() / want < 1e-12);
        }
    }

    #[test]
    fn totdev_at_m1_equals_oadev() {
        let x = frequency_to_phase(&nbs14(), 1.0);
        let t = deviations(Estimator::Totdev, &x, 1.0, &[1]);
        let o = deviations(Estimator::Oadev, &x, 1.0, &[1]);
        assert!((t[0].dev - o[0].dev).abs() < 1e-14);
        assert_eq!(t[0].n, 999);
    }

    #[test]
    fn white_fm_adev_scales_as_inverse_sqrt_tau() {
        // closed form: white FM of variance s² per sample → AVAR(τ) = s²·τ0/τ
        let mut st = 42u64;
        let mut gauss = || {
            // sum of 12 uniforms − 6: unit variance
            let mut a = 0.0;
            for _ in 0..12 {
                st ^= st << 13;
                st ^= st >> 7;
                st ^= st << 17;
                a += (st >> 11) as f64 / (1u64 << 53) as f64;
            }
            a - 6.0
        };
        let y: Vec<f64> = (0..400_000).map(|_| gauss()).collect();
        let x = frequency_to_phase(&y, 1.0);
        for p in oadev(&x, 1.0, &[1, 10, 100]) {
            let want = (1.0 / p.m as f64).sqrt();
            assert!((p.dev - want).abs() / want < 0.05, "m={} {}", p.m, p.dev);
        }
    }

    #[test]
    fn strided_oadev_is_close_to_full() {
        let y = nbs14();
        let x = frequency_to_phase(&y, 1.0);
        let full = oadev(&x, 1.0, &[1, 8, 64]);
        let fast = oadev_strided_sums(&x, &[1, 8, 64], 8);
        for (f, s) in full.iter().zip(fast) {
            let d = finish(Estimator::Oadev, s, 1.0);
            assert!(
                (d - f.dev).abs() / f.dev < 0.15,
                "m={} {} {}",
                f.m,
                d,
                f.dev
            );
        }
    }
}

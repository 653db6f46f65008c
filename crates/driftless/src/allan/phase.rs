//! Frequency → phase conversion.
//!
//! x₀ = 0, x_{k+1} = x_k + τ0·(y_k − ȳ) (SP 1065 §4.1, eq. 4 with the mean removed).
//! N rate samples give N+1 phase points. The mean is removed first and the sum is
//! carried in f64, so a 9.81 m/s² offset does not eat the significant digits; the
//! mean cancels exactly in every estimator here (all are second or higher
//! differences of x, or a reflected extension of x, which TOTDEV handles itself).

/// Integrate rate samples (frequency data) to phase, removing the mean first.
/// Returns `y.len() + 1` points (empty input gives `[0.0]`).
///
/// The running sum is Kahan-compensated. To break its serial dependency chain the series
/// is cut into `LANES` consecutive pieces whose compensated sums advance together in one
/// loop; each piece is then shifted by the compensated total of the pieces before it.
pub fn frequency_to_phase(y: &[f64], tau0: f64) -> Vec<f64> {
    let n = y.len();
    let mut x = vec![0.0f64; n + 1];
    if n == 0 {
        return x;
    }
    let mean = mean_f64(y);
    let piece = n.div_ceil(LANES);
    // (sum, compensation) per lane; lane k integrates y[k·piece .. (k+1)·piece).
    let mut sum = [0.0f64; LANES];
    let mut comp = [0.0f64; LANES];
    let mut add = |k: usize, v: f64, out: &mut f64| {
        let term = (v - mean) * tau0 - comp[k];
        let t = sum[k] + term;
        comp[k] = (t - sum[k]) - term;
        sum[k] = t;
        *out = t;
    };
    let (body, _) = x[1..].split_at_mut(n);
    let mut outs: Vec<&mut [f64]> = body.chunks_mut(piece).collect();
    let ins: Vec<&[f64]> = y.chunks(piece).collect();
    let full = ins.iter().map(|c| c.len()).min().unwrap_or(0);
    for i in 0..full {
        for k in 0..ins.len() {
            add(k, ins[k][i], &mut outs[k][i]);
        }
    }
    for k in 0..ins.len() {
        for i in full..ins[k].len() {
            add(k, ins[k][i], &mut outs[k][i]);
        }
    }
    // Shift piece k by the (compensated) totals of pieces 0..k.
    let mut offset = 0.0f64;
    let mut offset_c = 0.0f64;
    for k in 0..outs.len() {
        if k > 0 {
            for v in outs[k].iter_mut() {
                *v = offset + (*v - offset_c);
            }
        }
        // total of piece k = sum[k] − comp[k]; accumulate with compensation
        let term = (sum[k] - comp[k]) - offset_c;
        let t = offset + term;
        offset_c = (t - offset) - term;
        offset = t;
    }
    x
}

/// Independent compensated sums advanced together by [`frequency_to_phase`].
const LANES: usize = 4;

/// Differentiate phase to frequency: y_k = (x_{k+1} − x_k)/τ0.
pub fn phase_to_frequency(x: &[f64], tau0: f64) -> Vec<f64> {
    x.windows(2).map(|w| (w[1] - w[0]) / tau0).collect()
}

/// Mean of a slice with pairwise-blocked summation (accurate to ~1e-16 relative).
pub(crate) fn mean_f64(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut total = 0.0f64;
    for chunk in v.chunks(4096) {
        let mut acc = [0.0f64; 8];
        let mut it = chunk.chunks_exact(8);
        for c in &mut it {
            for k in 0..8 {
                acc[k] += c[k];
            }
        }
        let mut s: f64 = acc.iter().sum();
        s += it.remainder().iter().sum::<f64>();
        total += s;
    }
    total / v.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_a_plain_compensated_sum() {
        // Compare with a single-chain Kahan sum on an awkward length.
        let y: Vec<f64> = (0..10_007)
            .map(|i| ((i * 7919) % 1013) as f64 * 1e-3 + 9.81)
            .collect();
        let x = frequency_to_phase(&y, 0.01);
        let mean = mean_f64(&y);
        let (mut s, mut c) = (0.0f64, 0.0f64);
        for (i, v) in y.iter().enumerate() {
            let term = (v - mean) * 0.01 - c;
            let t = s + term;
            c = (t - s) - term;
            s = t;
            assert!((x[i + 1] - s).abs() <= 1e-14 * (1.0 + s.abs()), "i={i}");
        }
        for n in 0..9 {
            assert_eq!(frequency_to_phase(&y[..n], 1.0).len(), n + 1);
        }
    }

    #[test]
    fn phase_has_n_plus_one_points_and_round_trips() {
        let y = [1.0, 2.0, 4.0, 8.0];
        let x = frequency_to_phase(&y, 0.5);
        assert_eq!(x.len(), 5);
        assert_eq!(x[0], 0.0);
        let back = phase_to_frequency(&x, 0.5);
        let mean = 3.75;
        for (a, b) in back.iter().zip(y.iter()) {
            assert!((a - (b - mean)).abs() < 1e-12);
        }
        // mean removed: the phase returns to zero at the end
        assert!(x[4].abs() < 1e-12);
    }
}

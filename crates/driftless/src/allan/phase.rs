//! Frequency → phase conversion.
//!
//! x₀ = 0, x_{k+1} = x_k + τ0·(y_k − ȳ) (SP 1065 §4.1, eq. 4 with the mean removed).
//! N rate samples give N+1 phase points. The mean is removed first and the sum is
//! carried in f64, so a 9.81 m/s² offset does not eat the significant digits; the
//! mean cancels exactly in every estimator here (all are second or higher
//! differences of x, or a reflected extension of x, which TOTDEV handles itself).

/// Integrate rate samples (frequency data) to phase, removing the mean first.
/// Returns `y.len() + 1` points (empty input gives `[0.0]`).
pub fn frequency_to_phase(y: &[f64], tau0: f64) -> Vec<f64> {
    let mut x = Vec::with_capacity(y.len() + 1);
    x.push(0.0);
    if y.is_empty() {
        return x;
    }
    let mean = mean_f64(y);
    // Kahan-compensated running sum keeps the phase exact to ~1 ulp over 1e7 samples.
    let mut sum = 0.0f64;
    let mut c = 0.0f64;
    for &v in y {
        let term = (v - mean) * tau0 - c;
        let t = sum + term;
        c = (t - sum) - term;
        sum = t;
        x.push(sum);
    }
    x
}

/// Differentiate phase to frequency: y_k = (x_{k+1} − x_k)/τ0.
pub fn phase_to_frequency(x: &[f64], tau0: f64) -> Vec<f64> {
    x.windows(2).map(|w| (w[1] - w[0]) / tau0).collect()
}

/// Mean of a slice with pairwise-blocked summation (accurate to ~1e-16 relative).
pub fn mean_f64(v: &[f64]) -> f64 {
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

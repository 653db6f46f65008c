//! Error-state layout and the sensor-error estimates of the 21-state filter.
//!
//! | index | state | unit |
//! |---|---|---|
//! | 0..3 | δr, position error N, E, D | m |
//! | 3..6 | δv, velocity error N, E, D | m/s |
//! | 6..9 | φ, attitude (phi-angle) error, NED | rad |
//! | 9..12 | b_g, residual gyro bias, body x, y, z | rad/s |
//! | 12..15 | b_a, residual accelerometer bias | m/s² |
//! | 15..18 | s_g, residual gyro scale-factor error | – |
//! | 18..21 | s_a, residual accelerometer scale-factor error | – |
//!
//! (Shin 2005 ch. 3; Groves 2013 §14.2; same layout as KF-GINS's output files.)

use driftless_model::linalg::Vec3;

/// Number of error states.
pub const N_STATES: usize = 21;
/// First index of the position error.
pub const POS: usize = 0;
/// First index of the velocity error.
pub const VEL: usize = 3;
/// First index of the attitude error.
pub const ATT: usize = 6;
/// First index of the gyro bias.
pub const BG: usize = 9;
/// First index of the accelerometer bias.
pub const BA: usize = 12;
/// First index of the gyro scale factor.
pub const SG: usize = 15;
/// First index of the accelerometer scale factor.
pub const SA: usize = 18;

/// A full 21 × 21 covariance (row-major, symmetric).
pub(crate) type Cov = [[f64; N_STATES]; N_STATES];

/// Number of elements of the packed upper triangle of a [`Cov`].
pub(crate) const N_PACKED: usize = N_STATES * (N_STATES + 1) / 2;

/// Packed upper triangle (row by row: (0,0), (0,1), …, (0,20), (1,1), …) of a covariance.
pub(crate) type PackedCov = [f64; N_PACKED];

/// Pack the upper triangle of `p`.
pub(crate) fn pack(p: &Cov) -> Box<PackedCov> {
    let mut out = Box::new([0.0; N_PACKED]);
    let mut k = 0;
    for (i, row) in p.iter().enumerate() {
        for &v in &row[i..] {
            out[k] = v;
            k += 1;
        }
    }
    out
}

/// Unpack a packed upper triangle into a full symmetric covariance.
pub fn unpack(packed: &PackedCov) -> Cov {
    let mut p = [[0.0; N_STATES]; N_STATES];
    let mut k = 0;
    for i in 0..N_STATES {
        for j in i..N_STATES {
            p[i][j] = packed[k];
            p[j][i] = packed[k];
            k += 1;
        }
    }
    p
}

/// Estimated IMU errors. The sensor model is
/// ω̃ = (I + diag(s_g)) ω + b_g, f̃ = (I + diag(s_a)) f + b_a (raw output ω̃, f̃), and the
/// compensation is ω̂ = (ω̃ − b̂_g) ⊘ (1 + ŝ_g) per axis (the same on increments,
/// Δθ̂ = (Δθ̃ − b̂_gΔt) ⊘ (1 + ŝ_g)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorErrors {
    /// Gyro bias, body x, y, z, rad/s.
    pub gyro_bias_rad_s: Vec3,
    /// Accelerometer bias, m/s².
    pub accel_bias_m_s2: Vec3,
    /// Gyro scale-factor error (1e-6 = 1 ppm).
    pub gyro_scale: Vec3,
    /// Accelerometer scale-factor error.
    pub accel_scale: Vec3,
}

/// Cheap check of the diagonal: finite and > 0. Returns the offending index and value.
pub(crate) fn check_diagonal(p: &Cov) -> Result<(), (usize, f64)> {
    for (i, row) in p.iter().enumerate() {
        let v = row[i];
        if !(v.is_finite() && v > 0.0) {
            return Err((i, v));
        }
    }
    Ok(())
}

/// Full health check of a covariance: finite, symmetric to `rel_tol` (relative to
/// √(P_ii P_jj)), positive diagonal, and positive definite (a Cholesky factorisation
/// succeeds). On failure returns a diagnosis naming the offending entry.
pub fn check_covariance(p: &Cov, rel_tol: f64) -> Result<(), String> {
    let d: [f64; N_STATES] = std::array::from_fn(|i| p[i][i]);
    check_covariance_scaled(p, rel_tol, &d)
}

/// [`check_covariance`] with the symmetry tolerance relative to √(s_i s_j) for a given
/// variance scale `s` (e.g. the prior diagonal of an update, whose rounding the
/// posterior inherits when an update shrinks a variance by orders of magnitude).
pub(crate) fn check_covariance_scaled(
    p: &Cov,
    rel_tol: f64,
    scale_diag: &[f64; N_STATES],
) -> Result<(), String> {
    if let Err((i, v)) = check_diagonal(p) {
        return Err(format!(
            "variance of state {i} ({}) is {v:e}: not finite and positive",
            state_name(i)
        ));
    }
    for i in 0..N_STATES {
        for j in (i + 1)..N_STATES {
            let (a, b) = (p[i][j], p[j][i]);
            if !(a.is_finite() && b.is_finite()) {
                return Err(format!("P[{i}][{j}] is not finite ({a:e}, {b:e})"));
            }
            let s = (p[i][i] * p[j][j])
                .sqrt()
                .max((scale_diag[i] * scale_diag[j]).abs().sqrt());
            if (a - b).abs() > rel_tol * s {
                return Err(format!(
                    "asymmetric: P[{i}][{j}] = {a:e} but P[{j}][{i}] = {b:e} (scale {s:e})"
                ));
            }
        }
    }
    // Cholesky (Golub & Van Loan alg. 4.2.1) on the upper triangle.
    let mut l = [[0.0f64; N_STATES]; N_STATES];
    for j in 0..N_STATES {
        let mut d = p[j][j];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        let positive = d > 1e-14 * p[j][j];
        if !positive {
            return Err(format!(
                "not positive definite: Cholesky pivot {j} ({}) is {d:e} (variance {:e})",
                state_name(j),
                p[j][j]
            ));
        }
        let djj = d.sqrt();
        l[j][j] = djj;
        for i in (j + 1)..N_STATES {
            let mut s = p[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = s / djj;
        }
    }
    Ok(())
}

/// Human-readable name of error state `i`.
pub(crate) fn state_name(i: usize) -> &'static str {
    const NAMES: [&str; N_STATES] = [
        "δr_N", "δr_E", "δr_D", "δv_N", "δv_E", "δv_D", "φ_N", "φ_E", "φ_D", "b_gx", "b_gy",
        "b_gz", "b_ax", "b_ay", "b_az", "s_gx", "s_gy", "s_gz", "s_ax", "s_ay", "s_az",
    ];
    NAMES.get(i).copied().unwrap_or("?")
}

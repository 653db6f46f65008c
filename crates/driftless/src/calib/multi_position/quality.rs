//! Plausibility of a multi-position fit: residual scatter against the noise seen at
//! rest (Allan variance at the interval length) and the verdict with its likely causes.

use super::*;

/// Variance of the mean of `x` from 10 block means: Σ_b (x̄_b − x̄)² / (n_b(n_b − 1)).
pub(super) fn mean_variance(x: &[f64]) -> f64 {
    let len = x.len();
    let nb = 10.min(len / 2).max(2);
    let bl = (len / nb).max(1);
    let nb = (len / bl).max(1);
    let used = &x[..nb * bl];
    let mean = used.iter().sum::<f64>() / used.len().max(1) as f64;
    let ss: f64 = used
        .chunks(bl)
        .map(|c| (c.iter().sum::<f64>() / bl as f64 - mean).powi(2))
        .sum();
    ss / ((nb * nb.saturating_sub(1)).max(1)) as f64
}

/// Overlapping Allan variance per axis of `x` at an averaging length of `len` samples,
/// ½⟨(x̄_{k+len} − x̄_k)²⟩ (IEEE Std 952 Annex C); `None` when `x` holds fewer than three
/// such lengths.
pub(super) fn allan_variance_at(x: &[Vec3], len: usize) -> Option<Vec3> {
    let n = x.len();
    if len == 0 || n < 3 * len {
        return None;
    }
    let mut cum = vec![[0.0; 3]; n + 1];
    for (k, v) in x.iter().enumerate() {
        cum[k + 1] = [0, 1, 2].map(|j| cum[k][j] + v[j]);
    }
    let count = n + 1 - 2 * len;
    let mut out = [0.0; 3];
    for k in 0..count {
        for j in 0..3 {
            let a = (cum[k + len][j] - cum[k][j]) / len as f64;
            let b = (cum[k + 2 * len][j] - cum[k + len][j]) / len as f64;
            out[j] += 0.5 * (b - a).powi(2) / count as f64;
        }
    }
    Some(out)
}

pub(super) const ACCEL_CAUSES: &str = "motion or vibration inside the static intervals, accelerometer nonlinearity or temperature drift during the recording, a wrong local gravity, or noise more correlated than the block means of each interval show";
pub(super) const GYRO_CAUSES: &str = "gyro bias drift after the initial rest, a time offset between the gyro and accelerometer logs or irregular time stamps, moves too fast for the sample rate or clipped, or gyro g-sensitivity";

/// The noise-weighted quality figures of a multi-position calibration.
///
/// Accelerometer: r_i = ‖a_i‖ − g per static interval, σ_i² the variance of the interval
/// mean of u_i·a_k (calibrated samples projected on the interval's gravity direction u_i):
/// the larger of its value from 10 block means of the interval and Σ_j u_ij² σ²_A,j(τ_i),
/// the Allan variance of the calibrated accelerometer over the initial rest at the
/// interval's length τ_i (it carries the bias wander between intervals that the scatter
/// inside one interval misses); χ² = Σ r_i²/σ_i², ν = m − 9. Implausible above
/// [`MultiPositionOptions::max_accel_chi2_per_dof`].
///
/// Gyro: per move, the two components ⟂ u_{i+1} of the carried direction R_iᵀu_i
/// ([`gravity_angle_rms`]); each with σ² = (σ⊥,i² + σ⊥,i+1²)/g² + σ_ω²·Δt·T_i + σ_b²·T_i²,
/// σ⊥ the σ of an interval's mean across gravity (as above, average of two axes), σ_ω
/// the per-sample σ of the calibrated gyro over the initial rest (average over the axes),
/// σ_b the σ of the calibrated bias, T_i the move's duration, Δt the sample interval;
/// ν = 2(m − 1) − 9. Implausible when the RMS gravity angle exceeds
/// [`MultiPositionOptions::max_gravity_angle_rms_rad`].
#[allow(clippy::too_many_arguments)]
pub fn multi_position_quality(
    time_s: &[f64],
    accel_raw: &[Vec3],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    cal: &ImuCalibration,
    gyro_bias_sigma_raw: Vec3,
    opts: &MultiPositionOptions,
) -> (FitQuality, FitQuality) {
    let g = opts.gravity_m_s2;
    let rest = &intervals[0];
    let rest_accel: Vec<Vec3> = accel_raw[rest.start..rest.end]
        .iter()
        .map(|r| cal.accel.apply(*r))
        .collect();
    let mut chi2_a = 0.0;
    let mut perp_var = Vec::with_capacity(intervals.len());
    for iv in intervals {
        let avar = allan_variance_at(&rest_accel, iv.len()).unwrap_or([0.0; 3]);
        let floor = |e: Vec3| (0..3).map(|j| e[j] * e[j] * avar[j]).sum::<f64>();
        let a_mean = cal.accel.apply(iv.mean_accel_raw);
        let n = norm(a_mean).max(1e-300);
        let u = a_mean.map(|v| v / n);
        let (e1, e2) = perp_basis(u);
        let cal_k: Vec<Vec3> = accel_raw[iv.start..iv.end]
            .iter()
            .map(|r| cal.accel.apply(*r))
            .collect();
        let proj = |e: Vec3| -> Vec<f64> { cal_k.iter().map(|a| dot(e, *a)).collect() };
        let var_u = mean_variance(&proj(u)).max(floor(u));
        perp_var.push(
            0.5 * (mean_variance(&proj(e1)).max(floor(e1))
                + mean_variance(&proj(e2)).max(floor(e2))),
        );
        chi2_a += (n - g).powi(2) / var_u.max(1e-300);
    }
    let mut accel_q = FitQuality::from_chi2(
        chi2_a,
        intervals.len().saturating_sub(9),
        opts.warn_chi2_per_dof,
        ACCEL_CAUSES,
    );
    let rms_a = accel_norm_rms(intervals, &cal.accel, g);
    if accel_q.chi2_per_dof > opts.max_accel_chi2_per_dof {
        accel_q.implausible.push(format!(
            "RMS |a| − g {rms_a:.5} m/s² is {:.0}× its noise (χ²/dof {:.0}, limit {}): the accelerometer model does not fit these poses; check the local gravity, that the static intervals are really static, and that no axis is clipped",
            accel_q.chi2_per_dof.sqrt(),
            accel_q.chi2_per_dof,
            opts.max_accel_chi2_per_dof
        ));
    }
    // Gyro noise over the rest.
    let w: Vec<Vec3> = gyro_raw[rest.start..rest.end]
        .iter()
        .map(|r| cal.gyro.apply(*r))
        .collect();
    let nw = w.len().max(2) as f64;
    let mut var_w = 0.0;
    for j in 0..3 {
        let m = w.iter().map(|v| v[j]).sum::<f64>() / nw;
        var_w += w.iter().map(|v| (v[j] - m).powi(2)).sum::<f64>() / (nw - 1.0) / 3.0;
    }
    let mm = cal.gyro.matrix.0;
    let var_b: f64 = (0..3)
        .map(|j| {
            (0..3)
                .map(|l| (mm[j][l] * gyro_bias_sigma_raw[l]).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / 3.0;
    let pairs = carried_directions(time_s, gyro_raw, intervals, cal);
    let mut chi2_g = 0.0;
    for (i, (pred, meas)) in pairs.iter().enumerate() {
        let (e1, e2) = perp_basis(*meas);
        let (a, b) = (&intervals[i], &intervals[i + 1]);
        let t = time_s[b.start] - time_s[a.end - 1];
        let dt = t / (b.start + 1 - a.end).max(1) as f64;
        let var = (perp_var[i] + perp_var[i + 1]) / (g * g) + var_w * dt * t + var_b * t * t;
        chi2_g += (dot(e1, *pred).powi(2) + dot(e2, *pred).powi(2)) / var.max(1e-300);
    }
    let mut gyro_q = FitQuality::from_chi2(
        chi2_g,
        (2 * pairs.len()).saturating_sub(9),
        opts.warn_chi2_per_dof,
        GYRO_CAUSES,
    );
    let ang = gravity_angle_rms(time_s, gyro_raw, intervals, cal);
    if ang > opts.max_gravity_angle_rms_rad {
        gyro_q.implausible.push(format!(
            "the gravity direction after integrating the gyro is off by {:.3}° RMS (limit {:.1}°): the gyro scale or axes are wrong; check the gyro log's units and scale (raw counts need the scale found from the data or given), that it was recorded with the accelerometer log, and that it is not clipped during the moves",
            ang.to_degrees(),
            opts.max_gravity_angle_rms_rad.to_degrees()
        ));
    }
    (accel_q, gyro_q)
}

//! Static-interval detection for calibration without fixtures (Tedaldi, Pretto &
//! Menegatti, "A robust and easy to implement method for IMU calibration without external
//! equipments", ICRA 2014, §IV-A).
//!
//! The detector is a moving variance of the accelerometer axes. With var_w(a_j)(t) the
//! variance of axis j over a centred window of `window_s` seconds, the variance magnitude
//!
//! ```text
//! ς(t) = √( var_w(a_x)(t)² + var_w(a_y)(t)² + var_w(a_z)(t)² )
//! ```
//!
//! is compared with a threshold k·ς_init, where ς_init is the same magnitude computed
//! over the whole initial rest period of `init_rest_s` seconds (the recording must start
//! at rest). Samples with ς(t) < k·ς_init are static; runs of static samples at least
//! `min_interval_s` long are the static intervals. The multiple k is a free parameter;
//! [`super::multi_position`] sweeps it and keeps the one whose accelerometer fit has the
//! smallest residual, as the paper does.
//!
//! Each interval reports its sample range, times, the mean raw accelerometer and gyro
//! and, for six-position use, which body axis points up ([`Orientation`]): at rest the
//! accelerometer measures the specific force, +g along the upward vertical, so the axis
//! whose (offset-corrected) reading is closest to +|a| points up.

use driftless_model::linalg::{Vec3, norm, sub};

use super::multi_position::CalibError;

/// Which body axis points up in a static interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Orientation {
    /// +x up.
    XUp,
    /// +x down.
    XDown,
    /// +y up.
    YUp,
    /// +y down.
    YDown,
    /// +z up.
    ZUp,
    /// +z down.
    ZDown,
    /// No axis within the tolerance of the vertical.
    Other,
}

/// Orientation of an accelerometer reading `f` (specific force, any units, offset
/// removed): the axis j with the largest |f_j| when the angle between f and ±e_j is at
/// most `tolerance_deg`, else [`Orientation::Other`].
pub(crate) fn classify_orientation(f: Vec3, tolerance_deg: f64) -> Orientation {
    let n = norm(f);
    if !(n > 0.0 && n.is_finite()) {
        return Orientation::Other;
    }
    let (j, v) = (0..3).map(|j| (j, f[j])).fold((0, 0.0f64), |best, c| {
        if c.1.abs() > best.1.abs() { c } else { best }
    });
    let cos_angle = v.abs() / n;
    if cos_angle < tolerance_deg.to_radians().cos() {
        return Orientation::Other;
    }
    match (j, v > 0.0) {
        (0, true) => Orientation::XUp,
        (0, false) => Orientation::XDown,
        (1, true) => Orientation::YUp,
        (1, false) => Orientation::YDown,
        (2, true) => Orientation::ZUp,
        _ => Orientation::ZDown,
    }
}

/// Settings of [`detect_static`].
#[derive(Clone, Debug, PartialEq)]
pub struct StaticDetectOptions {
    /// Moving-variance window t_w, s (Tedaldi et al. use about 1–2 s).
    pub window_s: f64,
    /// Length of the initial rest period T_init, s (the paper recommends ≈ 50 s).
    pub init_rest_s: f64,
    /// Threshold multiple k: static when ς(t) < k·ς_init.
    pub threshold_multiple: f64,
    /// Shortest static interval kept, s.
    pub min_interval_s: f64,
    /// Subtracted from the mean raw accelerometer before classifying the orientation
    /// (e.g. 32768 counts for an offset-binary ADC; 0 for SI data).
    pub accel_offset_raw: Vec3,
    /// Largest angle between the reading and a body axis for [`Orientation`] ≠ Other, °.
    pub orientation_tolerance_deg: f64,
}

impl Default for StaticDetectOptions {
    fn default() -> Self {
        StaticDetectOptions {
            window_s: 1.0,
            init_rest_s: 50.0,
            threshold_multiple: 4.0,
            min_interval_s: 1.0,
            accel_offset_raw: [0.0; 3],
            orientation_tolerance_deg: 15.0,
        }
    }
}

/// One static interval.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticInterval {
    /// First sample index.
    pub start: usize,
    /// One past the last sample index.
    pub end: usize,
    /// Time of the first sample, s.
    pub start_time_s: f64,
    /// Time of the last sample, s.
    pub end_time_s: f64,
    /// Mean raw accelerometer over the interval (raw units).
    pub mean_accel_raw: Vec3,
    /// Mean raw gyro over the interval (raw units).
    pub mean_gyro_raw: Vec3,
    /// Which body axis points up.
    pub orientation: Orientation,
}

impl StaticInterval {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// True when the interval holds no sample.
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// The variance magnitude ς over a window, per sample, and ς_init; shared by the
/// threshold sweep so that it is computed once.
#[derive(Clone, Debug)]
pub struct VarianceProfile {
    /// ς(t_k) for each sample (centred window, shrunk at the ends).
    pub sigma: Vec<f64>,
    /// ς over the initial rest period.
    pub sigma_init: f64,
    /// Samples in the initial rest period.
    pub init_samples: usize,
    /// Sample interval (median of the time differences), s.
    pub dt_s: f64,
}

/// Median sample interval of `time_s` (needs ≥ 2 samples).
pub(crate) fn median_dt(time_s: &[f64]) -> Result<f64, CalibError> {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return Err(CalibError::TooShort {
            what: "log",
            have_s: 0.0,
            need_s: 0.0,
        });
    }
    let dt = crate::numeric::upper_median(&mut d).unwrap_or(f64::NAN);
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(CalibError::BadInput(format!(
            "time stamps are not increasing (median interval {dt} s)"
        )));
    }
    Ok(dt)
}

fn variance_magnitude(v: Vec3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// ς(t) and ς_init of an accelerometer log (module equations).
pub(crate) fn variance_profile(
    time_s: &[f64],
    accel_raw: &[Vec3],
    opts: &StaticDetectOptions,
) -> Result<VarianceProfile, CalibError> {
    let n = accel_raw.len();
    if time_s.len() != n {
        return Err(CalibError::BadInput(format!(
            "{} time stamps for {n} accelerometer samples",
            time_s.len()
        )));
    }
    if accel_raw.iter().flatten().any(|v| !v.is_finite()) {
        return Err(CalibError::BadInput(
            "non-finite accelerometer sample".into(),
        ));
    }
    let dt = median_dt(time_s)?;
    let init = ((opts.init_rest_s / dt).round() as usize).max(2);
    let have_s = time_s[n - 1] - time_s[0];
    if init > n {
        return Err(CalibError::TooShort {
            what: "initial rest period",
            have_s,
            need_s: opts.init_rest_s,
        });
    }
    let half = ((0.5 * opts.window_s / dt).round() as usize).max(1);
    // Prefix sums of x and x² about the first sample (numerical conditioning).
    let origin = accel_raw[0];
    let mut s1 = vec![[0.0; 3]; n + 1];
    let mut s2 = vec![[0.0; 3]; n + 1];
    for (k, a) in accel_raw.iter().enumerate() {
        for j in 0..3 {
            let x = a[j] - origin[j];
            s1[k + 1][j] = s1[k][j] + x;
            s2[k + 1][j] = s2[k][j] + x * x;
        }
    }
    let var = |lo: usize, hi: usize| -> Vec3 {
        let m = (hi - lo) as f64;
        let mut v = [0.0; 3];
        for j in 0..3 {
            let mean = (s1[hi][j] - s1[lo][j]) / m;
            v[j] = ((s2[hi][j] - s2[lo][j]) / m - mean * mean).max(0.0) * m / (m - 1.0).max(1.0);
        }
        v
    };
    let sigma: Vec<f64> = (0..n)
        .map(|k| variance_magnitude(var(k.saturating_sub(half), (k + half + 1).min(n))))
        .collect();
    Ok(VarianceProfile {
        sigma,
        sigma_init: variance_magnitude(var(0, init)),
        init_samples: init,
        dt_s: dt,
    })
}

/// Static intervals from a precomputed [`VarianceProfile`] at threshold multiple `k`.
pub(crate) fn intervals_from_profile(
    profile: &VarianceProfile,
    time_s: &[f64],
    accel_raw: &[Vec3],
    gyro_raw: &[Vec3],
    k: f64,
    opts: &StaticDetectOptions,
) -> Vec<StaticInterval> {
    let th = k * profile.sigma_init;
    let min_len = ((opts.min_interval_s / profile.dt_s).round() as usize).max(2);
    let n = profile.sigma.len();
    let mut out = Vec::new();
    let mut k0 = 0;
    while k0 < n {
        if profile.sigma[k0] >= th {
            k0 += 1;
            continue;
        }
        let mut k1 = k0;
        while k1 < n && profile.sigma[k1] < th {
            k1 += 1;
        }
        if k1 - k0 >= min_len {
            out.push(make_interval(time_s, accel_raw, gyro_raw, k0, k1, opts));
        }
        k0 = k1;
    }
    out
}

fn mean3(x: &[Vec3]) -> Vec3 {
    let mut m = [0.0; 3];
    for v in x {
        for j in 0..3 {
            m[j] += v[j];
        }
    }
    m.map(|s| s / x.len().max(1) as f64)
}

fn make_interval(
    time_s: &[f64],
    accel_raw: &[Vec3],
    gyro_raw: &[Vec3],
    start: usize,
    end: usize,
    opts: &StaticDetectOptions,
) -> StaticInterval {
    let mean_accel_raw = mean3(&accel_raw[start..end]);
    let mean_gyro_raw = if gyro_raw.len() >= end {
        mean3(&gyro_raw[start..end])
    } else {
        [f64::NAN; 3]
    };
    StaticInterval {
        start,
        end,
        start_time_s: time_s[start],
        end_time_s: time_s[end - 1],
        mean_accel_raw,
        mean_gyro_raw,
        orientation: classify_orientation(
            sub(mean_accel_raw, opts.accel_offset_raw),
            opts.orientation_tolerance_deg,
        ),
    }
}

/// Static intervals of a log at the threshold multiple `opts.threshold_multiple`
/// (module equations). `gyro_raw` may be empty (then the gyro means are NaN); otherwise
/// it must have one sample per accelerometer sample.
pub fn detect_static(
    time_s: &[f64],
    accel_raw: &[Vec3],
    gyro_raw: &[Vec3],
    opts: &StaticDetectOptions,
) -> Result<Vec<StaticInterval>, CalibError> {
    if !gyro_raw.is_empty() && gyro_raw.len() != accel_raw.len() {
        return Err(CalibError::BadInput(format!(
            "{} gyro samples for {} accelerometer samples",
            gyro_raw.len(),
            accel_raw.len()
        )));
    }
    let p = variance_profile(time_s, accel_raw, opts)?;
    Ok(intervals_from_profile(
        &p,
        time_s,
        accel_raw,
        gyro_raw,
        opts.threshold_multiple,
        opts,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_classes() {
        assert_eq!(
            classify_orientation([0.1, 0.0, 9.8], 10.0),
            Orientation::ZUp
        );
        assert_eq!(
            classify_orientation([-9.8, 0.3, 0.0], 10.0),
            Orientation::XDown
        );
        assert_eq!(
            classify_orientation([0.0, 9.8, 0.0], 10.0),
            Orientation::YUp
        );
        assert_eq!(
            classify_orientation([5.0, 5.0, 5.0], 10.0),
            Orientation::Other
        );
        assert_eq!(classify_orientation([0.0; 3], 10.0), Orientation::Other);
    }

    #[test]
    fn detects_a_step() {
        // 60 s rest (alternating ±1 noise), 5 s of large swings, 10 s rest
        let n = 7500;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let a: Vec<Vec3> = (0..n)
            .map(|k| {
                let e = if k % 2 == 0 { 1.0 } else { -1.0 };
                if (6000..6500).contains(&k) {
                    [e * 50.0 * ((k % 7) as f64), 0.0, 100.0]
                } else {
                    [e, e, 100.0 + e]
                }
            })
            .collect();
        let iv = detect_static(&t, &a, &[], &StaticDetectOptions::default()).unwrap();
        assert_eq!(iv.len(), 2, "{iv:?}");
        assert_eq!(iv[0].start, 0);
        assert!(iv[0].end > 5900 && iv[0].end <= 6000);
        assert!(iv[1].start >= 6500 && iv[1].end == n);
        assert_eq!(iv[1].orientation, Orientation::ZUp);
    }
}

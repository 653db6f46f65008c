//! Multi-position calibration without external equipment (Tedaldi, Pretto & Menegatti,
//! "A robust and easy to implement method for IMU calibration without external
//! equipments", ICRA 2014). The sensor is left at rest for T_init (≈ 50 s), then placed by
//! hand in many static orientations joined by rotations. Written from the paper's
//! description; the model is that of [`driftless_model::calib::TriadCalibration`],
//! calibrated = M·(raw − b).
//!
//! # Accelerometer (paper §III-A, §IV-B)
//!
//! M_a = T·K with K = diag(k_x, k_y, k_z) (scale, SI per raw unit) and T unit lower
//! triangular with the three non-orthogonality terms α₁₀, α₂₀, α₂₁ (small angles, rad):
//!
//! ```text
//!       ⎡ 1    0    0 ⎤
//!   T = ⎢ α₁₀  1    0 ⎥        calibrated a = T·K·(raw − b)
//!       ⎣ α₂₀  α₂₁  1 ⎦
//! ```
//!
//! i.e. the body frame is *defined* by the accelerometer: body x is sensing axis x, body y
//! lies in the plane of sensing axes x and y. The 9 parameters (b, k, α) minimise
//! Σ_i (‖T·K·(ā_i − b)‖ − g)² over the static intervals' mean raw readings ā_i
//! (Levenberg–Marquardt, [`super::lsq::levenberg_marquardt`], analytic Jacobian), from
//! b = mean of the ā_i and k = g / mean‖ā_i − b‖. The static detector's threshold
//! multiple is swept ([`MultiPositionOptions::threshold_multiples`]) and the detection
//! whose fit has the smallest residual RMS is kept (paper §IV-A).
//!
//! # Gyroscope (paper §III-B, §IV-C)
//!
//! The bias b_g is the mean raw gyro over the initial rest (the first static interval).
//! M_g is a full 3 × 3 matrix (3 scales and 6 misalignments w.r.t. the accelerometer body
//! frame). Between consecutive static intervals i and i+1 the calibrated rate
//! ω_k = M_g(raw_k − b_g) is integrated over the samples from the end of interval i to the
//! start of interval i+1 as a product of exact per-step rotations,
//!
//! ```text
//!   R = Π_k exp([φ_k×]),   φ_k = M_g·((raw_k + raw_{k+1})/2 − b_g)·(t_{k+1} − t_k),
//! ```
//!
//! (trapezoidal rate, second order), and the gravity direction measured by the calibrated
//! accelerometer at interval i, u_i = a_i/‖a_i‖, is carried to the next: û_{i+1} = Rᵀ u_i.
//! The residuals are the two components of û_{i+1} in an orthonormal basis (e₁, e₂) of the
//! plane ⟂ u_{i+1} (≈ the tilt error in rad). The Jacobian is analytic to first order:
//! with P_k = Π_{l≤k} exp([φ_l×]), a perturbation δM_g gives
//! δû = Rᵀ(u_i × Σ_k P_k δφ_k).
//!
//! The starting matrix of the fit is s·I. The isotropic scale s (rad/s per raw unit) is
//! given, or found from the data: the accelerometer's gravity directions u_i, u_{i+1} at
//! the ends of move i are θ_i apart, so s ≥ θ_i/L_i with L_i the path length of the raw
//! bias-removed increments; s is searched on a log grid from half to 20 times the largest
//! of these bounds for the smallest RMS angle ∠(R(s)ᵀu_i, u_{i+1}), and must be unique
//! ([`estimate_gyro_scale`]). The gyro axes are taken nominally parallel to the
//! accelerometer's (the matrix fit removes misalignments of a few degrees).
//!
//! # Quality
//!
//! [`multi_position_quality`] weights the residuals by the noise the data imply (block
//! means of each interval, the Allan variance of the initial rest) and gives χ²/dof for
//! each triad, warnings, and an implausibility verdict: gravity direction after
//! integrating the gyro beyond a few degrees, or |a| − g far above its noise.
//!
//! # Uncertainties
//!
//! Every fitted parameter carries the LM covariance σ̂²(JᵀJ)⁻¹ (σ̂² = Σr²/(m − n)); the
//! covariance of (b, M) is propagated by a central-difference Jacobian. The gyro bias
//! variance is that of the mean of the rest period estimated from the scatter of block
//! means (10 blocks; this absorbs correlated noise better than s²/n).

use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::linalg::{Mat3, Vec3, cross, dot, norm, sub};

use super::lsq::{LmOptions, LsqError, levenberg_marquardt};
use super::quality::FitQuality;
use super::static_detect::{
    StaticDetectOptions, StaticInterval, intervals_from_profile, variance_profile,
};

/// Why a calibration could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CalibError {
    /// Inconsistent or non-finite input.
    #[error("bad input: {0}")]
    BadInput(String),
    /// The log (or its initial rest) is too short.
    #[error("the {what} is too short: {have_s:.1} s, need {need_s:.1} s")]
    TooShort {
        /// What is too short.
        what: &'static str,
        /// Available duration, s.
        have_s: f64,
        /// Needed duration, s.
        need_s: f64,
    },
    /// Fewer static intervals than the fit needs.
    #[error(
        "only {found} static intervals were found (at best over the threshold sweep); the multi-position calibration needs at least {needed}: place the sensor in more distinct static orientations"
    )]
    TooFewIntervals {
        /// Intervals found.
        found: usize,
        /// Intervals needed.
        needed: usize,
    },
    /// The log does not start at rest.
    #[error(
        "the log must start with a rest period of {need_s:.1} s: the first static interval starts at {start_s:.2} s and lasts {have_s:.1} s"
    )]
    NoInitialRest {
        /// Start of the first static interval, s.
        start_s: f64,
        /// Its duration, s.
        have_s: f64,
        /// Required rest, s.
        need_s: f64,
    },
    /// A parameter cannot be determined from these poses or motions.
    #[error("{sensor} {parameter} is not observable: {reason}")]
    Unobservable {
        /// "accelerometer" or "gyro".
        sensor: &'static str,
        /// The parameter, e.g. "x scale".
        parameter: String,
        /// Why.
        reason: String,
    },
    /// A raw reading at the sensor's rail inside a used part of the log.
    #[error(
        "{sensor} {axis} axis is saturated at {value_raw} (rail) at {time_s:.2} s{where_}: the reading is clipped, reduce the motion or exclude that pose"
    )]
    Saturated {
        /// "accelerometer" or "gyro".
        sensor: &'static str,
        /// 'x', 'y' or 'z'.
        axis: char,
        /// The raw value.
        value_raw: f64,
        /// Time, s.
        time_s: f64,
        /// ", in static interval n" or ", between static intervals n and n+1".
        where_: String,
    },
    /// The least-squares fit failed.
    #[error("{sensor} fit failed: {source}")]
    Fit {
        /// "accelerometer" or "gyro".
        sensor: &'static str,
        /// The cause.
        source: LsqError,
    },
}

const AXES: [char; 3] = ['x', 'y', 'z'];

/// Settings of [`calibrate_multi_position`].
#[derive(Clone, Debug, PartialEq)]
pub struct MultiPositionOptions {
    /// Local gravity magnitude g, m/s² (see [`gravity_at`]).
    pub gravity_m_s2: f64,
    /// Static detector (its `threshold_multiple` is replaced by the sweep).
    pub detect: StaticDetectOptions,
    /// Threshold multiples k swept by the detector.
    pub threshold_multiples: Vec<f64>,
    /// Fewest static intervals accepted (≥ 10: 9 accelerometer parameters).
    pub min_intervals: usize,
    /// Initial gyro scale, rad/s per raw unit (1 for data already in rad/s; about
    /// 1/6258 for the Xsens counts of imu_tk), within ≈ 20 % of the truth. `None`
    /// (default): found from the data ([`estimate_gyro_scale`]).
    pub gyro_scale_guess_rad_s_per_raw: Option<f64>,
    /// Largest RMS gravity-direction angle the scale search accepts with M_g = s·I, rad
    /// (default 10°; the matrix fit then removes the misalignments).
    pub max_scale_search_angle_rad: f64,
    /// Largest plausible RMS gravity-direction angle after the gyro fit, rad (default
    /// 3°): above it the result is marked implausible.
    pub max_gravity_angle_rms_rad: f64,
    /// Largest plausible accelerometer χ²/dof (default 900: |a| − g residuals 30× their
    /// noise); above it the result is marked implausible.
    pub max_accel_chi2_per_dof: f64,
    /// χ²/dof above which a fit warns (default
    /// [`super::quality::DEFAULT_WARN_CHI2_PER_DOF`]).
    pub warn_chi2_per_dof: f64,
    /// Accelerometer rails [min, max] in raw units (e.g. [0, 65535] for a 16-bit ADC); a
    /// static-interval sample at or beyond one is an error. `None`: not checked.
    pub accel_range_raw: Option<[f64; 2]>,
    /// Gyro rails [min, max] in raw units; a sample at or beyond one during the rotations
    /// or the rest is an error. `None`: not checked.
    pub gyro_range_raw: Option<[f64; 2]>,
    /// Smallest spread of the gravity direction per accelerometer axis (see
    /// [`calibrate_accel`]): 0.5 by default.
    pub min_direction_spread: f64,
    /// Smallest net rotation about each gyro axis summed over the moves, rad (default
    /// 30°).
    pub min_rotation_rad: f64,
    /// Levenberg–Marquardt settings.
    pub lm: LmOptions,
}

impl Default for MultiPositionOptions {
    fn default() -> Self {
        MultiPositionOptions {
            gravity_m_s2: 9.80665,
            detect: StaticDetectOptions::default(),
            threshold_multiples: (2..=10).map(f64::from).collect(),
            min_intervals: 10,
            gyro_scale_guess_rad_s_per_raw: None,
            max_scale_search_angle_rad: 10f64.to_radians(),
            max_gravity_angle_rms_rad: 3f64.to_radians(),
            max_accel_chi2_per_dof: 900.0,
            warn_chi2_per_dof: super::quality::DEFAULT_WARN_CHI2_PER_DOF,
            accel_range_raw: None,
            gyro_range_raw: None,
            min_direction_spread: 0.5,
            min_rotation_rad: 30f64.to_radians(),
            lm: LmOptions::default(),
        }
    }
}

/// Normal gravity magnitude at geodetic latitude `lat_rad` and ellipsoidal height
/// `height_m` ([`crate::nav::earth::gravity_ned`]), m/s².
pub fn gravity_at(lat_rad: f64, height_m: f64) -> f64 {
    norm(crate::nav::earth::gravity_ned(lat_rad, height_m))
}

/// One fitted triad with uncertainties.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadFit {
    /// The calibration M·(raw − b).
    pub calibration: TriadCalibration,
    /// Names of the fitted parameters.
    pub param_names: Vec<&'static str>,
    /// Fitted parameters (raw units for biases, SI per raw unit for scales, rad for
    /// angles; gyro: b then M row-major).
    pub params: Vec<f64>,
    /// Their covariance, row-major.
    pub param_covariance: Vec<f64>,
    /// Covariance of (b_x, b_y, b_z, M₀₀, M₀₁, …, M₂₂), 12 × 12 row-major.
    pub bm_covariance: Vec<f64>,
    /// RMS residual of the fit (m/s² for the accelerometer, rad for the gyro).
    pub residual_rms: f64,
    /// LM iterations.
    pub iterations: usize,
}

impl TriadFit {
    /// σ of parameter `i`.
    pub fn param_sigma(&self, i: usize) -> f64 {
        let n = self.params.len();
        self.param_covariance[i * n + i].max(0.0).sqrt()
    }

    /// σ of the bias, raw units.
    pub fn bias_sigma(&self) -> Vec3 {
        [0, 1, 2].map(|i| self.bm_covariance[i * 12 + i].max(0.0).sqrt())
    }

    /// σ of each element of M.
    pub fn matrix_sigma(&self) -> Mat3 {
        let mut s = [[0.0; 3]; 3];
        for (r, row) in s.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                let i = 3 + 3 * r + c;
                *v = self.bm_covariance[i * 12 + i].max(0.0).sqrt();
            }
        }
        Mat3(s)
    }
}

/// One detector setting tried by the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// Threshold multiple k.
    pub threshold_multiple: f64,
    /// Static intervals found.
    pub intervals: usize,
    /// Accelerometer fit residual RMS, m/s² (`None` when the fit was not possible).
    pub residual_rms_m_s2: Option<f64>,
}

/// Result of [`calibrate_multi_position`].
#[derive(Clone, Debug, PartialEq)]
pub struct MultiPositionCalibration {
    /// The static intervals used.
    pub intervals: Vec<StaticInterval>,
    /// The chosen threshold multiple.
    pub threshold_multiple: f64,
    /// Every setting tried.
    pub sweep: Vec<SweepPoint>,
    /// Accelerometer fit.
    pub accel: TriadFit,
    /// Gyro fit.
    pub gyro: TriadFit,
    /// RMS over the intervals of ‖a_cal‖ − g, m/s².
    pub accel_norm_rms_m_s2: f64,
    /// RMS angle between the gravity direction carried by the calibrated gyro from one
    /// interval to the next and the one measured there, rad.
    pub gravity_angle_rms_rad: f64,
    /// The gyro scale found from the data (`None` when a guess was given).
    pub gyro_scale: Option<GyroScaleEstimate>,
    /// Accelerometer fit quality: χ²/dof of |a_i| − g over the intervals.
    pub accel_quality: FitQuality,
    /// Gyro fit quality: χ²/dof of the gravity-direction residuals over the moves.
    pub gyro_quality: FitQuality,
}

impl MultiPositionCalibration {
    /// Both triads.
    pub fn calibration(&self) -> ImuCalibration {
        ImuCalibration {
            accel: self.accel.calibration,
            gyro: self.gyro.calibration,
        }
    }
}

/// Central-difference propagation of `cov` (n × n) through `f`: J·cov·Jᵀ, with step
/// h_i = 1e-3·σ_i (or 1e-8·max(|p_i|, 1) when σ_i = 0).
pub fn propagate_covariance(p: &[f64], cov: &[f64], f: impl Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
    let n = p.len();
    let m = f(p).len();
    let mut jac = vec![0.0; m * n];
    let mut q = p.to_vec();
    for c in 0..n {
        let s = cov[c * n + c].max(0.0).sqrt();
        let h = if s > 0.0 {
            1e-3 * s
        } else {
            1e-8 * p[c].abs().max(1.0)
        };
        q[c] = p[c] + h;
        let fp = f(&q);
        q[c] = p[c] - h;
        let fm = f(&q);
        q[c] = p[c];
        for r in 0..m {
            jac[r * n + c] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    let mut out = vec![0.0; m * m];
    for a in 0..m {
        for b in 0..m {
            let mut s = 0.0;
            for i in 0..n {
                let ja = jac[a * n + i];
                if ja == 0.0 {
                    continue;
                }
                for k in 0..n {
                    s += ja * cov[i * n + k] * jac[b * n + k];
                }
            }
            out[a * m + b] = s;
        }
    }
    out
}

fn accel_matrix(k: Vec3, a10: f64, a20: f64, a21: f64) -> Mat3 {
    Mat3([
        [k[0], 0.0, 0.0],
        [a10 * k[0], k[1], 0.0],
        [a20 * k[0], a21 * k[1], k[2]],
    ])
}

/// RMS over the intervals of ‖cal.apply(ā_i)‖ − g.
pub fn accel_norm_rms(intervals: &[StaticInterval], cal: &TriadCalibration, g: f64) -> f64 {
    let s: f64 = intervals
        .iter()
        .map(|iv| (norm(cal.apply(iv.mean_accel_raw)) - g).powi(2))
        .sum();
    (s / intervals.len().max(1) as f64).sqrt()
}

/// Accelerometer fit of the module equations over the intervals' mean raw readings.
///
/// Before fitting, the poses are checked with the gravity directions
/// u_i = (ā_i − o)/‖ā_i − o‖, o = `accel_offset_raw` (the nominal zero): for each axis j
/// the scale is observable only when some pose has |u_ij| ≥ `min_spread` (the axis within
/// 60° of the vertical for 0.5), and its bias is separable from its scale only when
/// max_i u_ij − min_i u_ij ≥ `min_spread`. E.g. all poses with z up leave the x scale
/// (and y scale, and z bias vs z scale) unobservable.
pub fn calibrate_accel(
    intervals: &[StaticInterval],
    gravity_m_s2: f64,
    accel_offset_raw: Vec3,
    min_spread: f64,
    lm: &LmOptions,
) -> Result<TriadFit, CalibError> {
    const NAMES: [&str; 9] = [
        "bias x", "bias y", "bias z", "scale x", "scale y", "scale z", "alpha10", "alpha20",
        "alpha21",
    ];
    let m = intervals.len();
    if m < 10 {
        return Err(CalibError::TooFewIntervals {
            found: m,
            needed: 10,
        });
    }
    if !(gravity_m_s2 > 0.0 && gravity_m_s2.is_finite()) {
        return Err(CalibError::BadInput(format!("gravity {gravity_m_s2} m/s²")));
    }
    let raw: Vec<Vec3> = intervals.iter().map(|iv| iv.mean_accel_raw).collect();
    if raw.iter().flatten().any(|v| !v.is_finite()) {
        return Err(CalibError::BadInput("non-finite interval mean".into()));
    }
    // Pose geometry.
    let dirs: Vec<Vec3> = raw
        .iter()
        .map(|a| {
            let d = sub(*a, accel_offset_raw);
            let n = norm(d).max(1e-300);
            d.map(|v| v / n)
        })
        .collect();
    for j in 0..3 {
        let top = dirs.iter().map(|u| u[j].abs()).fold(0.0, f64::max);
        if top < min_spread {
            return Err(CalibError::Unobservable {
                sensor: "accelerometer",
                parameter: format!("{} scale", AXES[j]),
                reason: format!(
                    "no static pose has the {} axis within {:.0}° of the vertical (largest |cos| {top:.2}); add poses with {} up and down",
                    AXES[j],
                    min_spread.acos().to_degrees(),
                    AXES[j]
                ),
            });
        }
    }
    for j in 0..3 {
        let hi = dirs.iter().map(|u| u[j]).fold(f64::MIN, f64::max);
        let lo = dirs.iter().map(|u| u[j]).fold(f64::MAX, f64::min);
        if hi - lo < min_spread {
            return Err(CalibError::Unobservable {
                sensor: "accelerometer",
                parameter: format!("{} bias", AXES[j]),
                reason: format!(
                    "the gravity component along {} spans only {:.2} g over the poses, so its bias cannot be told from its scale; add poses with {} up and down",
                    AXES[j],
                    hi - lo,
                    AXES[j]
                ),
            });
        }
    }
    // Normalised problem: x_i = (ā_i − b0)/c, calibrated = T·Kn·(x − β).
    let mut b0 = [0.0; 3];
    for a in &raw {
        for j in 0..3 {
            b0[j] += a[j] / m as f64;
        }
    }
    let c = raw.iter().map(|a| norm(sub(*a, b0))).sum::<f64>() / m as f64;
    if c.is_nan() || c <= 0.0 {
        return Err(CalibError::BadInput(
            "all static intervals have the same mean reading".into(),
        ));
    }
    let x: Vec<Vec3> = raw.iter().map(|a| sub(*a, b0).map(|v| v / c)).collect();
    let g = gravity_m_s2;
    let p0 = [0.0, 0.0, 0.0, g, g, g, 0.0, 0.0, 0.0];
    let f = |p: &[f64], r: &mut [f64], jac: Option<&mut [f64]>| {
        let mm = accel_matrix([p[3], p[4], p[5]], p[6], p[7], p[8]);
        let mut jac = jac;
        for (i, xi) in x.iter().enumerate() {
            let d = [xi[0] - p[0], xi[1] - p[1], xi[2] - p[2]];
            let cal = mm.mul_vec(d);
            let n = norm(cal);
            r[i] = n - g;
            if let Some(j) = jac.as_deref_mut() {
                let u = cal.map(|v| v / n.max(1e-300));
                let row = &mut j[i * 9..(i + 1) * 9];
                for (q, v) in row[..3].iter_mut().enumerate() {
                    // ∂r/∂β_q = −uᵀ M e_q
                    *v = -(u[0] * mm.0[0][q] + u[1] * mm.0[1][q] + u[2] * mm.0[2][q]);
                }
                // ∂cal/∂k_q = T[:, q] d_q
                row[3] = (u[0] + u[1] * p[6] + u[2] * p[7]) * d[0];
                row[4] = (u[1] + u[2] * p[8]) * d[1];
                row[5] = u[2] * d[2];
                row[6] = u[1] * p[3] * d[0];
                row[7] = u[2] * p[3] * d[0];
                row[8] = u[2] * p[4] * d[1];
            }
        }
    };
    let fit =
        levenberg_marquardt(&p0, m, lm, f).map_err(|e| lsq_error("accelerometer", e, &NAMES))?;
    // Physical parameters: b = b0 + c·β, k = kn/c, α unchanged.
    let to_phys = |p: &[f64]| -> Vec<f64> {
        vec![
            b0[0] + c * p[0],
            b0[1] + c * p[1],
            b0[2] + c * p[2],
            p[3] / c,
            p[4] / c,
            p[5] / c,
            p[6],
            p[7],
            p[8],
        ]
    };
    let params = to_phys(&fit.params);
    let param_covariance = propagate_covariance(&fit.params, &fit.covariance, to_phys);
    let to_bm = |q: &[f64]| -> Vec<f64> {
        let mm = accel_matrix([q[3], q[4], q[5]], q[6], q[7], q[8]);
        let mut v = vec![q[0], q[1], q[2]];
        v.extend(mm.0.iter().flatten());
        v
    };
    let bm_covariance = propagate_covariance(&params, &param_covariance, to_bm);
    let calibration = TriadCalibration {
        bias: [params[0], params[1], params[2]],
        matrix: accel_matrix(
            [params[3], params[4], params[5]],
            params[6],
            params[7],
            params[8],
        ),
    };
    Ok(TriadFit {
        calibration,
        param_names: NAMES.to_vec(),
        params,
        param_covariance,
        bm_covariance,
        residual_rms: fit.rms,
        iterations: fit.iterations,
    })
}

fn lsq_error(sensor: &'static str, e: LsqError, names: &[&'static str]) -> CalibError {
    match e {
        LsqError::Unobservable { param } => CalibError::Unobservable {
            sensor,
            parameter: names.get(param).copied().unwrap_or("?").to_string(),
            reason: "the normal matrix of the fit is singular for these poses".into(),
        },
        source => CalibError::Fit { sensor, source },
    }
}

/// exp([φ×]) (Rodrigues).
fn rot_exp(phi: Vec3) -> Mat3 {
    let t2 = dot(phi, phi);
    let (a, b) = if t2 < 1e-12 {
        (1.0 - t2 / 6.0, 0.5 - t2 / 24.0)
    } else {
        let t = t2.sqrt();
        (t.sin() / t, (1.0 - t.cos()) / t2)
    };
    let k = Mat3::skew(phi);
    let k2 = k.mul_mat(&k);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = f64::from(u8::from(i == j)) + a * k.0[i][j] + b * k2.0[i][j];
        }
    }
    Mat3(r)
}

/// One move between static intervals, prepared for the gyro fit.
struct Move {
    /// Bias-removed trapezoidal raw increment ((raw_k + raw_{k+1})/2 − b_g)·Δt per step,
    /// raw·s; multiplied by the scale in use before the matrix fit.
    w: Vec<Vec3>,
    /// Calibrated gravity direction at the start.
    u0: Vec3,
    /// Measured gravity direction at the end.
    u1: Vec3,
    /// Basis of the plane ⟂ the measured direction at the end.
    e1: Vec3,
    e2: Vec3,
    /// Σ_k ‖w_k‖ (the path length of the raw increments), raw·s.
    path_raw_s: f64,
    /// |Σ_k w_k| per axis, raw·s.
    net_raw_s: Vec3,
}

fn perp_basis(u: Vec3) -> (Vec3, Vec3) {
    let a = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = cross(u, a);
    let n1 = norm(e1);
    let e1 = e1.map(|v| v / n1);
    (e1, cross(u, e1))
}

fn angle_between(a: Vec3, b: Vec3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Carries u0 through the move with G; returns the predicted direction Rᵀu0 and, when
/// `jac` is asked, the 9 derivative vectors ∂û/∂G_jl (row-major j, l).
fn carry(g: &Mat3, mv: &Move, want_jac: bool) -> (Vec3, [Vec3; 9]) {
    let mut p = Mat3::IDENTITY;
    let mut acc = [[0.0; 3]; 9];
    for wk in &mv.w {
        p = p.mul_mat(&rot_exp(g.mul_vec(*wk)));
        if want_jac {
            for j in 0..3 {
                let col = [p.0[0][j], p.0[1][j], p.0[2][j]];
                for l in 0..3 {
                    let s = wk[l];
                    let a = &mut acc[3 * j + l];
                    a[0] += col[0] * s;
                    a[1] += col[1] * s;
                    a[2] += col[2] * s;
                }
            }
        }
    }
    let pt = p.t();
    let pred = pt.mul_vec(mv.u0);
    let mut d = [[0.0; 3]; 9];
    if want_jac {
        for (dv, a) in d.iter_mut().zip(&acc) {
            *dv = pt.mul_vec(cross(mv.u0, *a));
        }
    }
    (pred, d)
}

/// The gyro bias from the initial rest and the moves between static intervals.
struct GyroPrep {
    bias: Vec3,
    bias_var: Vec3,
    moves: Vec<Move>,
}

fn prepare_gyro(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<GyroPrep, CalibError> {
    let n = gyro_raw.len();
    if time_s.len() != n {
        return Err(CalibError::BadInput(format!(
            "{} time stamps for {n} gyro samples",
            time_s.len()
        )));
    }
    if intervals.len() < 2 {
        return Err(CalibError::TooFewIntervals {
            found: intervals.len(),
            needed: 2,
        });
    }
    if intervals.iter().any(|iv| iv.end > n || iv.start >= iv.end) {
        return Err(CalibError::BadInput(
            "a static interval lies outside the gyro log".into(),
        ));
    }
    let last_end = intervals[intervals.len() - 1].end;
    if let Some(k) = (0..last_end).find(|&k| gyro_raw[k].iter().any(|v| !v.is_finite())) {
        return Err(CalibError::BadInput(format!(
            "non-finite gyro sample at {:.3} s (sample {}): remove or repair that row",
            time_s[k],
            k + 1
        )));
    }
    // Rails: the rest and every move.
    if let Some([lo, hi]) = opts.gyro_range_raw {
        let last = intervals[intervals.len() - 1].start;
        for (k, w) in gyro_raw[..last].iter().enumerate() {
            if let Some(j) = (0..3).find(|&j| w[j] <= lo || w[j] >= hi) {
                let i = intervals.iter().rposition(|iv| iv.start <= k).unwrap_or(0);
                return Err(CalibError::Saturated {
                    sensor: "gyro",
                    axis: AXES[j],
                    value_raw: w[j],
                    time_s: time_s[k],
                    where_: format!(", between static intervals {i} and {}", i + 1),
                });
            }
        }
    }
    // Bias: mean over the initial rest, σ from 10 block means.
    let rest = &intervals[0];
    let len = rest.len();
    let mut bias = [0.0; 3];
    for w in &gyro_raw[rest.start..rest.end] {
        for j in 0..3 {
            bias[j] += w[j] / len as f64;
        }
    }
    let nb = 10.min(len / 2).max(2);
    let bl = (len / nb).max(1);
    let mut bias_var = [0.0; 3];
    for b in 0..nb {
        let seg = &gyro_raw[rest.start + b * bl..(rest.start + (b + 1) * bl).min(rest.end)];
        for j in 0..3 {
            let m = seg.iter().map(|w| w[j]).sum::<f64>() / seg.len().max(1) as f64;
            bias_var[j] += (m - bias[j]).powi(2) / ((nb - 1) as f64 * nb as f64);
        }
    }
    let dir = |iv: &StaticInterval| {
        let a = accel.apply(iv.mean_accel_raw);
        let nn = norm(a).max(1e-300);
        a.map(|v| v / nn)
    };
    let mut moves = Vec::with_capacity(intervals.len() - 1);
    for pair in intervals.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let (k0, k1) = (a.end - 1, b.start);
        let mut w = Vec::with_capacity(k1.saturating_sub(k0));
        let mut tot = [0.0; 3];
        let mut path = 0.0;
        for k in k0..k1 {
            let dt = time_s[k + 1] - time_s[k];
            let v: Vec3 =
                [0, 1, 2].map(|j| (0.5 * (gyro_raw[k][j] + gyro_raw[k + 1][j]) - bias[j]) * dt);
            for j in 0..3 {
                tot[j] += v[j];
            }
            path += norm(v);
            w.push(v);
        }
        let u1 = dir(b);
        let (e1, e2) = perp_basis(u1);
        moves.push(Move {
            w,
            u0: dir(a),
            u1,
            e1,
            e2,
            path_raw_s: path,
            net_raw_s: tot.map(f64::abs),
        });
    }
    Ok(GyroPrep {
        bias,
        bias_var,
        moves,
    })
}

/// The isotropic gyro scale s (rad/s per raw unit) found from the data; see
/// [`estimate_gyro_scale`].
#[derive(Clone, Debug, PartialEq)]
pub struct GyroScaleEstimate {
    /// s, rad/s per raw unit.
    pub scale_rad_s_per_raw: f64,
    /// RMS gravity-direction angle over the moves with M_g = s·I, rad.
    pub gravity_angle_rms_rad: f64,
    /// The best other scale (a separate minimum more than 15 % away) and its RMS angle,
    /// rad: how clearly the data single out s.
    pub runner_up: Option<(f64, f64)>,
    /// Moves that tilt the gravity direction by at least 10°.
    pub tilting_moves: usize,
}

/// Smallest gravity-direction change of a move that bounds the scale, rad.
const MIN_TILT_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

fn scale_cost(moves: &[Move], s: f64) -> f64 {
    let g = Mat3::diag([s; 3]);
    let sum: f64 = moves
        .iter()
        .map(|mv| angle_between(carry(&g, mv, false).0, mv.u1).powi(2))
        .sum();
    (sum / moves.len().max(1) as f64).sqrt()
}

fn span(intervals: &[StaticInterval], i: usize) -> String {
    format!(
        "{:.2}–{:.2} s",
        intervals[i].end_time_s,
        intervals[i + 1].start_time_s
    )
}

/// Scale search over the prepared moves (raw increments).
///
/// The gravity directions u_i, u_{i+1} measured by the accelerometer at the ends of move i
/// are θ_i = ∠(u_i, u_{i+1}) apart; the sensor turned by at least θ_i, and by at most
/// s·L_i, L_i = Σ_k ‖w_k‖ the path length of the raw increments. So s ≥ θ_i / L_i for
/// every move, and s is searched on a 2 % log grid over [½, 20]·max_i θ_i/L_i (moves with
/// θ_i ≥ 10°) for the smallest RMS over the moves of ∠(R(s)ᵀu_i, u_{i+1}) with
/// R(s) = Π_k exp([s·w_k ×]), then refined by golden section. Moves of different angles
/// alias at different scales (a turn by θ about one axis is also matched by
/// s' = s·(1 + 2πk/θ)), so the global minimum is unique when the moves differ; a second
/// minimum more than 15 % away with less than twice the best RMS angle is an error.
fn search_scale(
    moves: &[Move],
    intervals: &[StaticInterval],
    opts: &MultiPositionOptions,
) -> Result<GyroScaleEstimate, CalibError> {
    let tilts: Vec<f64> = moves.iter().map(|m| angle_between(m.u0, m.u1)).collect();
    let total: f64 = tilts.iter().sum();
    let tilting: Vec<usize> = (0..moves.len())
        .filter(|&i| tilts[i] >= MIN_TILT_RAD)
        .collect();
    if total < opts.min_rotation_rad || tilting.len() < 3 {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the gravity direction turns by only {:.1}° in total over {} moves ({} of them by 10° or more; need {:.0}° and 3 such moves), so the rotations cannot fix the gyro scale: tilt the sensor between poses (about horizontal axes), or set the gyro scale guess",
                total.to_degrees(),
                moves.len(),
                tilting.len(),
                opts.min_rotation_rad.to_degrees()
            ),
        });
    }
    if let Some(&i) = tilting.iter().find(|&&i| moves[i].path_raw_s <= 0.0) {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the gyro reads no rotation over {} although the gravity direction turns by {:.1}° there: check that the gyro log was recorded with the accelerometer log (same time base)",
                span(intervals, i),
                tilts[i].to_degrees()
            ),
        });
    }
    let bound = tilting
        .iter()
        .map(|&i| tilts[i] / moves[i].path_raw_s)
        .fold(0.0, f64::max);
    let (lo, hi) = ((0.5 * bound).ln(), (20.0 * bound).ln());
    let step = 0.02f64;
    let n = ((hi - lo) / step).ceil() as usize + 1;
    let grid: Vec<f64> = (0..n).map(|i| lo + step * i as f64).collect();
    let cost: Vec<f64> = grid.iter().map(|&l| scale_cost(moves, l.exp())).collect();
    let ibest = (0..n)
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]))
        .unwrap_or(0);
    // Golden section on ln s around the grid minimum.
    let (mut a, mut b) = (grid[ibest] - step, grid[ibest] + step);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (scale_cost(moves, c.exp()), scale_cost(moves, d.exp()));
    for _ in 0..30 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = scale_cost(moves, c.exp());
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = scale_cost(moves, d.exp());
        }
    }
    let (l_best, f_best) = if fc < fd { (c, fc) } else { (d, fd) };
    let (l_best, f_best) = if f_best <= cost[ibest] {
        (l_best, f_best)
    } else {
        (grid[ibest], cost[ibest])
    };
    let runner_up = (0..n)
        .filter(|&i| {
            (grid[i] - l_best).abs() > 0.15
                && (i == 0 || cost[i] <= cost[i - 1])
                && (i + 1 == n || cost[i] <= cost[i + 1])
        })
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]))
        .map(|i| (grid[i].exp(), cost[i]));
    let s = l_best.exp();
    if ibest == 0 || ibest + 1 == n {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the best scale lies at the edge of the searched range {:.4e}…{:.4e} rad/s per raw unit (RMS gravity angle {:.2}°): the moves' rotations do not fit the gravity directions; check the gyro log's time base and axes, or set the gyro scale guess",
                grid[0].exp(),
                grid[n - 1].exp(),
                f_best.to_degrees()
            ),
        });
    }
    if f_best > opts.max_scale_search_angle_rad {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "no single scale makes the integrated gyro carry the gravity direction from pose to pose (best {:.4e} rad/s per raw unit leaves an RMS angle of {:.1}°, limit {:.1}°): check that the gyro log was recorded with the accelerometer log (same time base), that its axes match the accelerometer's, and that it is not clipped during the moves; or set the gyro scale guess",
                s,
                f_best.to_degrees(),
                opts.max_scale_search_angle_rad.to_degrees()
            ),
        });
    }
    if let Some((s2, f2)) = runner_up
        && f2 < 2.0 * f_best
    {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "two gyro scales fit the moves about equally well ({s:.4e} rad/s per raw unit: RMS {:.2}°; {s2:.4e}: {:.2}°), so the rotations do not single one out: add moves of different sizes about different axes, or set the gyro scale guess",
                f_best.to_degrees(),
                f2.to_degrees()
            ),
        });
    }
    Ok(GyroScaleEstimate {
        scale_rad_s_per_raw: s,
        gravity_angle_rms_rad: f_best,
        runner_up,
        tilting_moves: tilting.len(),
    })
}

/// Finds the gyro scale s (rad/s per raw unit) of a multi-position log from the data: the
/// accelerometer fixes the tilt between consecutive static intervals, the integrated raw
/// gyro gives the same rotation in raw units (see the search in the module source:
/// bounds s ≥ θ_i/L_i, log grid, golden section, uniqueness check). Errors when the
/// moves cannot identify it: too little tilt in total, no rotation read by the gyro while
/// gravity turns, no scale that fits (wrong log, axes or clipping), or two scales that
/// fit alike.
pub fn estimate_gyro_scale(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<GyroScaleEstimate, CalibError> {
    let prep = prepare_gyro(time_s, gyro_raw, intervals, accel, opts)?;
    search_scale(&prep.moves, intervals, opts)
}

/// Gyro fit of the module equations. `intervals` must come from the same log (their
/// sample ranges index `time_s` and `gyro_raw`), the first being the initial rest;
/// `accel` calibrates the interval means to gravity directions. The starting matrix is
/// s·I with s = [`MultiPositionOptions::gyro_scale_guess_rad_s_per_raw`], or, when that
/// is `None`, the scale found by [`estimate_gyro_scale`].
pub fn calibrate_gyro(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<TriadFit, CalibError> {
    gyro_fit(time_s, gyro_raw, intervals, accel, opts).map(|(fit, _)| fit)
}

fn gyro_fit(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<(TriadFit, Option<GyroScaleEstimate>), CalibError> {
    const NAMES: [&str; 12] = [
        "bias x", "bias y", "bias z", "M00", "M01", "M02", "M10", "M11", "M12", "M20", "M21", "M22",
    ];
    if let Some(s0) = opts.gyro_scale_guess_rad_s_per_raw
        && !(s0 > 0.0 && s0.is_finite())
    {
        return Err(CalibError::BadInput(format!(
            "gyro scale guess {s0}: give a positive rad/s per raw unit, or none to find it from the data"
        )));
    }
    let GyroPrep {
        bias,
        bias_var,
        mut moves,
    } = prepare_gyro(time_s, gyro_raw, intervals, accel, opts)?;
    let (s0, estimate) = match opts.gyro_scale_guess_rad_s_per_raw {
        Some(s0) => (s0, None),
        None => {
            let e = search_scale(&moves, intervals, opts)?;
            (e.scale_rad_s_per_raw, Some(e))
        }
    };
    let mut net = [0.0; 3];
    for mv in &mut moves {
        for w in &mut mv.w {
            *w = w.map(|v| v * s0);
        }
        for (n, r) in net.iter_mut().zip(mv.net_raw_s) {
            *n += r * s0;
        }
    }
    for j in 0..3 {
        if net[j] < opts.min_rotation_rad {
            return Err(CalibError::Unobservable {
                sensor: "gyro",
                parameter: format!("{} scale", AXES[j]),
                reason: format!(
                    "the moves between static intervals rotate the sensor by only {:.1}° in total about the {} axis (need {:.0}°); rotate it between poses",
                    net[j].to_degrees(),
                    AXES[j],
                    opts.min_rotation_rad.to_degrees()
                ),
            });
        }
    }
    let m = 2 * moves.len();
    let f = |p: &[f64], r: &mut [f64], jac: Option<&mut [f64]>| {
        let gm = Mat3([[p[0], p[1], p[2]], [p[3], p[4], p[5]], [p[6], p[7], p[8]]]);
        let mut jac = jac;
        let want = jac.is_some();
        for (i, mv) in moves.iter().enumerate() {
            let (pred, d) = carry(&gm, mv, want);
            r[2 * i] = dot(mv.e1, pred);
            r[2 * i + 1] = dot(mv.e2, pred);
            if let Some(j) = jac.as_deref_mut() {
                for q in 0..9 {
                    j[2 * i * 9 + q] = dot(mv.e1, d[q]);
                    j[(2 * i + 1) * 9 + q] = dot(mv.e2, d[q]);
                }
            }
        }
    };
    let p0 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let fit =
        levenberg_marquardt(&p0, m, &opts.lm, f).map_err(|e| lsq_error("gyro", e, &NAMES[3..]))?;
    let mut params = bias.to_vec();
    params.extend(fit.params.iter().map(|v| v * s0));
    let mut cov = vec![0.0; 144];
    for j in 0..3 {
        cov[j * 12 + j] = bias_var[j];
    }
    for a in 0..9 {
        for b in 0..9 {
            cov[(3 + a) * 12 + 3 + b] = fit.covariance[a * 9 + b] * s0 * s0;
        }
    }
    let gm = &params[3..];
    let calibration = TriadCalibration {
        bias,
        matrix: Mat3([
            [gm[0], gm[1], gm[2]],
            [gm[3], gm[4], gm[5]],
            [gm[6], gm[7], gm[8]],
        ]),
    };
    Ok((
        TriadFit {
            calibration,
            param_names: NAMES.to_vec(),
            params,
            param_covariance: cov.clone(),
            bm_covariance: cov,
            residual_rms: fit.rms,
            iterations: fit.iterations,
        },
        estimate,
    ))
}

/// For each move, the gravity direction at its start carried by the calibrated gyro to
/// its end, R_iᵀu_i, and the one measured there, u_{i+1} (both unit vectors).
fn carried_directions(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    cal: &ImuCalibration,
) -> Vec<(Vec3, Vec3)> {
    let dir = |iv: &StaticInterval| {
        let a = cal.accel.apply(iv.mean_accel_raw);
        let nn = norm(a).max(1e-300);
        a.map(|v| v / nn)
    };
    intervals
        .windows(2)
        .map(|pair| {
            let (a, b) = (&pair[0], &pair[1]);
            let mut p = Mat3::IDENTITY;
            for k in (a.end - 1)..b.start {
                let dt = time_s[k + 1] - time_s[k];
                let w0 = cal.gyro.apply(gyro_raw[k]);
                let w1 = cal.gyro.apply(gyro_raw[k + 1]);
                p = p.mul_mat(&rot_exp([0, 1, 2].map(|j| 0.5 * (w0[j] + w1[j]) * dt)));
            }
            (p.t().mul_vec(dir(a)), dir(b))
        })
        .collect()
}

/// RMS angle (rad) between the gravity direction carried by the calibrated gyro across
/// each move and the one measured by the calibrated accelerometer at its end.
pub fn gravity_angle_rms(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    cal: &ImuCalibration,
) -> f64 {
    let pairs = carried_directions(time_s, gyro_raw, intervals, cal);
    let s: f64 = pairs
        .iter()
        .map(|(p, m)| angle_between(*p, *m).powi(2))
        .sum();
    (s / pairs.len().max(1) as f64).sqrt()
}

/// Variance of the mean of `x` from 10 block means: Σ_b (x̄_b − x̄)² / (n_b(n_b − 1)).
fn mean_variance(x: &[f64]) -> f64 {
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
fn allan_variance_at(x: &[Vec3], len: usize) -> Option<Vec3> {
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

const ACCEL_CAUSES: &str = "motion or vibration inside the static intervals, accelerometer nonlinearity or temperature drift during the recording, a wrong local gravity, or noise more correlated than the block means of each interval show";
const GYRO_CAUSES: &str = "gyro bias drift after the initial rest, a time offset between the gyro and accelerometer logs or irregular time stamps, moves too fast for the sample rate or clipped, or gyro g-sensitivity";

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

/// The whole multi-position calibration of a log that starts at rest: static detection
/// swept over the threshold multiples, accelerometer fit per detection (the smallest
/// residual RMS wins), then the gyro fit (module equations). `accel_raw` and `gyro_raw`
/// are sampled at `time_s`.
pub fn calibrate_multi_position(
    time_s: &[f64],
    accel_raw: &[Vec3],
    gyro_raw: &[Vec3],
    opts: &MultiPositionOptions,
) -> Result<MultiPositionCalibration, CalibError> {
    if gyro_raw.len() != accel_raw.len() {
        return Err(CalibError::BadInput(format!(
            "{} gyro samples for {} accelerometer samples",
            gyro_raw.len(),
            accel_raw.len()
        )));
    }
    let needed = opts.min_intervals.max(10);
    let profile = variance_profile(time_s, accel_raw, &opts.detect)?;
    let mut sweep = Vec::new();
    let mut best: Option<(f64, Vec<StaticInterval>, TriadFit)> = None;
    let mut first_err: Option<CalibError> = None;
    let mut most = 0;
    for &k in &opts.threshold_multiples {
        let iv = intervals_from_profile(&profile, time_s, accel_raw, gyro_raw, k, &opts.detect);
        most = most.max(iv.len());
        let mut point = SweepPoint {
            threshold_multiple: k,
            intervals: iv.len(),
            residual_rms_m_s2: None,
        };
        if iv.len() >= needed {
            if let Some(e) = check_rest(&iv, time_s[0], &opts.detect) {
                first_err.get_or_insert(e);
            } else if let Some(e) = check_rails(&iv, time_s, accel_raw, opts.accel_range_raw) {
                first_err.get_or_insert(e);
            } else {
                match calibrate_accel(
                    &iv,
                    opts.gravity_m_s2,
                    opts.detect.accel_offset_raw,
                    opts.min_direction_spread,
                    &opts.lm,
                ) {
                    Ok(fit) => {
                        point.residual_rms_m_s2 = Some(fit.residual_rms);
                        if best
                            .as_ref()
                            .is_none_or(|b| fit.residual_rms < b.2.residual_rms)
                        {
                            best = Some((k, iv, fit));
                        }
                    }
                    Err(e) => {
                        first_err.get_or_insert(e);
                    }
                }
            }
        }
        sweep.push(point);
    }
    let Some((threshold_multiple, intervals, accel)) = best else {
        return Err(first_err.unwrap_or(CalibError::TooFewIntervals {
            found: most,
            needed,
        }));
    };
    let (gyro, gyro_scale) = gyro_fit(time_s, gyro_raw, &intervals, &accel.calibration, opts)?;
    let cal = ImuCalibration {
        accel: accel.calibration,
        gyro: gyro.calibration,
    };
    let (accel_quality, gyro_quality) = multi_position_quality(
        time_s,
        accel_raw,
        gyro_raw,
        &intervals,
        &cal,
        gyro.bias_sigma(),
        opts,
    );
    Ok(MultiPositionCalibration {
        accel_norm_rms_m_s2: accel_norm_rms(&intervals, &cal.accel, opts.gravity_m_s2),
        gravity_angle_rms_rad: gravity_angle_rms(time_s, gyro_raw, &intervals, &cal),
        intervals,
        threshold_multiple,
        sweep,
        accel,
        gyro,
        gyro_scale,
        accel_quality,
        gyro_quality,
    })
}

fn check_rest(iv: &[StaticInterval], t0_s: f64, det: &StaticDetectOptions) -> Option<CalibError> {
    let first = iv.first()?;
    let have = first.end_time_s - first.start_time_s;
    // The moving window may trim up to half a window at the start; allow one window, and
    // a rest 20 % shorter than nominal.
    if first.start_time_s - t0_s > det.window_s || have < 0.8 * det.init_rest_s {
        return Some(CalibError::NoInitialRest {
            start_s: first.start_time_s,
            have_s: have,
            need_s: det.init_rest_s,
        });
    }
    None
}

fn check_rails(
    iv: &[StaticInterval],
    time_s: &[f64],
    accel_raw: &[Vec3],
    range: Option<[f64; 2]>,
) -> Option<CalibError> {
    let [lo, hi] = range?;
    for (i, s) in iv.iter().enumerate() {
        for k in s.start..s.end {
            if let Some(j) = (0..3).find(|&j| accel_raw[k][j] <= lo || accel_raw[k][j] >= hi) {
                return Some(CalibError::Saturated {
                    sensor: "accelerometer",
                    axis: AXES[j],
                    value_raw: accel_raw[k][j],
                    time_s: time_s[k],
                    where_: format!(", in static interval {i}"),
                });
            }
        }
    }
    None
}

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

mod gyro;
mod quality;
pub use gyro::*;
pub use quality::*;

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
pub(crate) fn propagate_covariance(
    p: &[f64],
    cov: &[f64],
    f: impl Fn(&[f64]) -> Vec<f64>,
) -> Vec<f64> {
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

//! Initial alignment: static coarse alignment (levelling + gyrocompassing) and attitude
//! from GNSS velocity in motion.
//!
//! # Static coarse alignment (Titterton & Weston 2004 §10.2; Groves 2013 §5.6.2)
//!
//! Over a static window the mean specific force is f̄^b = C_nb (0, 0, −g) and the mean
//! angular rate ω̄^b = C_nb ω_ie^n, ω_ie^n = Ω(cos φ, 0, −sin φ). Levelling (body FRD):
//!
//!   roll θ_x = atan2(−f̄_y, −f̄_z),  pitch θ_y = atan2(f̄_x, √(f̄_y² + f̄_z²)).
//!
//! Gyrocompassing: the rate levelled with roll and pitch, ω^h = C_y(θ_y) C_x(θ_x) ω̄^b
//! (heading frame), equals C_z(ψ)ᵀ ω_ie^n, so ω^h_x = Ω cos φ cos ψ, ω^h_y = −Ω cos φ sin ψ
//! and ψ = atan2(−ω^h_y, ω^h_x).
//!
//! Precision (first order): the mean-rate error σ_ω = √(ARW²/T + σ_bg²) over a window of
//! length T gives σ_ψ ≈ √((σ_ω/(Ω cos φ))² + (tan φ · σ_tilt)²), σ_tilt = σ_f/g with
//! σ_f = √(VRW²/T + σ_ba²) (Titterton & Weston §10.2.2; Groves §5.6.2). Gyrocompassing is
//! refused when the horizontal Earth rate Ω cos φ is less than `min_earth_rate_snr` times
//! σ_ω — the heading would be noise (a MEMS gyro with ~10 °/h bias instability against
//! Ω cos φ ≈ 13 °/h at 30° N).
//!
//! # In-motion heading from GNSS velocity
//!
//! For a land vehicle whose body x axis follows the track: yaw = atan2(v_E, v_N),
//! pitch = atan2(−v_D, √(v_N² + v_E²)), roll = 0, valid above a speed threshold.

use driftless_model::linalg::{Vec3, norm};

use super::NavError;
use crate::nav::attitude::{Euler, Quat};
use crate::nav::earth;
use crate::nav::mechanization::ImuIncrement;

/// Sensor grade for the alignment precision and the gyrocompassing decision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignConfig {
    /// Gyro angle random walk, rad/√s.
    pub gyro_arw_rad_sqrt_s: f64,
    /// Gyro (turn-on / in-run) bias uncertainty, rad/s.
    pub gyro_bias_sigma_rad_s: f64,
    /// Accelerometer velocity random walk, m/s/√s.
    pub accel_vrw_m_s_sqrt_s: f64,
    /// Accelerometer bias uncertainty, m/s².
    pub accel_bias_sigma_m_s2: f64,
    /// Required ratio Ω cos φ / σ_ω for gyrocompassing (default 3).
    pub min_earth_rate_snr: f64,
    /// Largest accepted | |f̄| − g |, m/s², for the window to count as static
    /// (default 0.5).
    pub max_gravity_mismatch_m_s2: f64,
}

impl AlignConfig {
    /// A configuration with the given grade and default thresholds.
    pub fn new(
        gyro_arw_rad_sqrt_s: f64,
        gyro_bias_sigma_rad_s: f64,
        accel_vrw_m_s_sqrt_s: f64,
        accel_bias_sigma_m_s2: f64,
    ) -> AlignConfig {
        AlignConfig {
            gyro_arw_rad_sqrt_s,
            gyro_bias_sigma_rad_s,
            accel_vrw_m_s_sqrt_s,
            accel_bias_sigma_m_s2,
            min_earth_rate_snr: 3.0,
            max_gravity_mismatch_m_s2: 0.5,
        }
    }
}

/// Result of an alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// Roll, pitch, yaw.
    pub attitude: Euler,
    /// The same as q_bn.
    pub q_bn: Quat,
    /// Estimated σ of roll, pitch, yaw, rad.
    pub sigma_rad: Vec3,
    /// End of the alignment window, s.
    pub time_s: f64,
}

/// Mean specific force and angular rate over the window, and its length.
fn means(imu: &[ImuIncrement]) -> Result<(Vec3, Vec3, f64), NavError> {
    if imu.len() < 2 {
        return Err(NavError::Alignment(format!(
            "static window has {} IMU epochs; need at least 2",
            imu.len()
        )));
    }
    let (mut th, mut dv, mut t) = ([0.0; 3], [0.0; 3], 0.0);
    for i in imu {
        let dt_ok = i.dt_s.is_finite() && i.dt_s > 0.0;
        let values_ok = i
            .dtheta_rad
            .iter()
            .chain(i.dvel_m_s.iter())
            .all(|v| v.is_finite());
        if !dt_ok || !values_ok {
            return Err(NavError::Alignment(format!(
                "invalid increment at t = {} s",
                i.time_s
            )));
        }
        for k in 0..3 {
            th[k] += i.dtheta_rad[k];
            dv[k] += i.dvel_m_s[k];
        }
        t += i.dt_s;
    }
    Ok((dv.map(|v| v / t), th.map(|v| v / t), t))
}

/// Levelling only: (roll, pitch) rad and their σ from a static window at latitude
/// `lat_rad`, height `height_m`.
pub fn level_static(
    imu: &[ImuIncrement],
    lat_rad: f64,
    height_m: f64,
    cfg: &AlignConfig,
) -> Result<(f64, f64, f64), NavError> {
    let (f, _, t) = means(imu)?;
    let g = earth::normal_gravity_m_s2(lat_rad, height_m);
    let fn_ = norm(f);
    if (fn_ - g).abs() > cfg.max_gravity_mismatch_m_s2 {
        return Err(NavError::Alignment(format!(
            "mean specific force {fn_:.4} m/s² differs from gravity {g:.4} m/s² by more than \
             {} m/s²: the IMU is not static (or the accelerometer unit is wrong)",
            cfg.max_gravity_mismatch_m_s2
        )));
    }
    let roll = (-f[1]).atan2(-f[2]);
    let pitch = f[0].atan2(f[1].hypot(f[2]));
    let sigma_f = (cfg.accel_vrw_m_s_sqrt_s.powi(2) / t + cfg.accel_bias_sigma_m_s2.powi(2)).sqrt();
    Ok((roll, pitch, sigma_f / g))
}

/// Static coarse alignment with gyrocompassing (module docs). Refuses (error) when the
/// window is not static or the gyro cannot resolve the Earth rate.
pub fn coarse_align_static(
    imu: &[ImuIncrement],
    lat_rad: f64,
    height_m: f64,
    cfg: &AlignConfig,
) -> Result<Alignment, NavError> {
    let (roll, pitch, sigma_tilt) = level_static(imu, lat_rad, height_m, cfg)?;
    let (_, w, t) = means(imu)?;
    let sigma_w = (cfg.gyro_arw_rad_sqrt_s.powi(2) / t + cfg.gyro_bias_sigma_rad_s.powi(2)).sqrt();
    let w_h = earth::OMEGA_IE * lat_rad.cos();
    let observable = w_h >= cfg.min_earth_rate_snr * sigma_w;
    if !observable {
        return Err(NavError::Alignment(format!(
            "gyrocompassing refused: horizontal Earth rate {:.2} °/h at latitude {:.2}° is \
             below {} × the gyro noise of the mean rate, σ_ω = {:.2} °/h (ARW over {t:.0} s \
             and bias); use heading from GNSS velocity or a given heading",
            w_h.to_degrees() * 3600.0,
            lat_rad.to_degrees(),
            cfg.min_earth_rate_snr,
            sigma_w.to_degrees() * 3600.0
        )));
    }
    if norm(w) > earth::OMEGA_IE + 5.0 * sigma_w {
        return Err(NavError::Alignment(format!(
            "mean angular rate {:.2} °/h exceeds the Earth rate by more than 5σ: the IMU is \
             rotating",
            norm(w).to_degrees() * 3600.0
        )));
    }
    let lev = Euler {
        roll_rad: roll,
        pitch_rad: pitch,
        yaw_rad: 0.0,
    }
    .to_dcm();
    let wh = lev.mul_vec(w);
    let yaw = (-wh[1]).atan2(wh[0]);
    let sigma_yaw = ((sigma_w / w_h).powi(2) + (lat_rad.tan() * sigma_tilt).powi(2)).sqrt();
    let attitude = Euler {
        roll_rad: roll,
        pitch_rad: pitch,
        yaw_rad: yaw,
    };
    Ok(Alignment {
        attitude,
        q_bn: attitude.to_quat(),
        sigma_rad: [sigma_tilt, sigma_tilt, sigma_yaw],
        time_s: imu.last().map_or(0.0, |i| i.time_s),
    })
}

/// Attitude from the GNSS velocity of a vehicle moving along its body x axis (module
/// docs); refuses below `min_speed_m_s` (course undefined at rest).
pub fn heading_from_gnss_velocity(v_ned_m_s: Vec3, min_speed_m_s: f64) -> Result<Euler, NavError> {
    if !v_ned_m_s.iter().all(|v| v.is_finite()) {
        return Err(NavError::Alignment(format!(
            "GNSS velocity {v_ned_m_s:?} is not finite"
        )));
    }
    let horiz = v_ned_m_s[0].hypot(v_ned_m_s[1]);
    let fast_enough = horiz > min_speed_m_s;
    if !fast_enough {
        return Err(NavError::Alignment(format!(
            "horizontal speed {horiz:.3} m/s is below the {min_speed_m_s} m/s needed for \
             heading from GNSS velocity"
        )));
    }
    Ok(Euler {
        roll_rad: 0.0,
        pitch_rad: (-v_ned_m_s[2]).atan2(horiz),
        yaw_rad: v_ned_m_s[1].atan2(v_ned_m_s[0]),
    })
}

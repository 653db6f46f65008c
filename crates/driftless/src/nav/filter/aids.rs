//! Land-vehicle aids: the non-holonomic constraint (NHC) and zero-velocity /
//! zero-angular-rate updates (ZUPT / ZARU) with automatic standstill detection.
//!
//! Each aid is optional ([`FilterConfig::nhc`](super::model::FilterConfig::nhc), [`FilterConfig::standstill`](super::model::FilterConfig::standstill), both `None`
//! by default) and is applied by [`super::run_forward`] after the prediction of a whole
//! IMU epoch; the measurement models are in [`super::Eskf::update_nhc`],
//! [`super::Eskf::update_zupt`] and [`super::Eskf::update_zaru`].
//!
//! # NHC
//!
//! A wheeled vehicle on a road does not slip sideways or leave the ground: in the vehicle
//! frame v (forward, right, down) the velocity of the rear-axle / wheel-contact point has
//! v^v_y ≈ v^v_z ≈ 0 (Sukkarieh 2000; Dissanayake et al. 2001; Shin 2001; Groves 2013
//! §16.4.1). The IMU may be rotated relative to the vehicle (C_vb, e.g. from
//! [`crate::nav::pipeline::Mounting::c_vb`]) and offset from the axle (lever arm).
//! The constraint is applied at [`NhcConfig::interval_s`] (default 0.1 s = 10 Hz; the
//! information of consecutive NHCs at 200 Hz is highly correlated through the slowly
//! varying errors, and a lower rate costs far less), with σ 0.1 m/s per axis
//! (Shin 2001 uses 0.1 m/s; σ absorbs skid, suspension motion and road bumps).
//!
//! It is *skipped* (documented choice, common practice) when
//! * the estimated speed is below [`NhcConfig::min_speed_m_s`] (default 1 m/s): at
//!   crawl speed the constraint carries no heading information, and at rest ZUPT
//!   handles the velocity, and the wheel-slip assumption is worst when starting;
//! * the vehicle yaw rate exceeds [`NhcConfig::max_yaw_rate_rad_s`] (default 30°/s):
//!   in very sharp turns side slip at the axle grows (tyre slip angles); ordinary
//!   road turns (≤ 20°/s) are kept, because turning is where NHC bounds heading drift;
//! * a standstill is detected (ZUPT active).
//!
//! # Standstill detection
//!
//! A sliding window of [`StandstillConfig::window_s`] of compensated IMU samples (rate
//! ω̂ = Δθ̂/Δt, specific force f̂ = Δv̂/Δt) is *static* when all of
//!
//! 1. per-axis standard deviation of f̂ ≤ `accel_std_max_m_s2` (vibration, starting and
//!    braking transients);
//! 2. per-axis standard deviation of ω̂ ≤ `gyro_std_max_rad_s`;
//! 3. |mean ω̂| ≤ `gyro_mean_max_rad_s` (a steady turn has a small variance but a large
//!    mean rate);
//! 4. ||mean f̂| − g| ≤ `accel_mean_tol_m_s2` (a strong steady acceleration);
//!    4b. the horizontal part of the mean specific force resolved with the filter's
//!    attitude, |(Ĉ_bn f̄)_NE| ≤ `accel_horizontal_max_m_s2` (a steady acceleration: the
//!    magnitude test 4 is only second order in it, |f| − g ≈ a²/2g);
//! 5. the filter's speed |v̂^n| ≤ `max_speed_m_s` (if set) and the speed of the latest
//!    GNSS velocity (≤ 2 s old, if the fixes carry velocity and
//!    `gnss_speed_max_m_s` is set) ≤ `gnss_speed_max_m_s`,
//!
//! in the spirit of the moving-variance / angular-rate-energy detectors of Skog et al.
//! 2010 (IEEE TBME 57(11)) and Groves 2013 §16.2.3. A standstill is declared once
//! windows have been static for `min_duration_s` counted from the start of the first
//! static window; its interval is recorded as [start of the first static window, end of
//! the last static window] — so its start is found retrospectively and its end at the
//! first moving sample. ZUPT and ZARU are applied (causally) from the declaration on,
//! every `interval_s`.
//!
//! **Why condition 5.** An IMU cannot tell rest from uniform straight motion: both give
//! f̂ ≈ −g and ω̂ ≈ ω_ie. Real vehicles vibrate in motion (engine, road: accelerometer
//! σ typically 0.2–1 m/s², gyro 0.5–2°/s on consumer MEMS), which conditions 1–2 catch,
//! but a smooth road or a vibration-free simulation does not; the speed gate (filter
//! velocity, which GNSS or NHC keeps honest) removes such false standstills. Default
//! 3 m/s: above the velocity drift of a consumer IMU in a 60-s outage with NHC, far
//! below cruising speed. (Tests `nav_aids.rs` show both: with vibration and no gate, and
//! vibration-free with the gate.)
//!
//! **Defaults** (consumer MEMS at 100–200 Hz, e.g. ICM-4xxxx / BMI088 class:
//! ARW ≈ 0.2–0.5°/√h ⇒ per-sample σ_ω ≈ ARW/√Δt ≈ 0.04–0.12°/s at 200 Hz;
//! VRW ≈ 0.05–0.15 m/s/√h ⇒ σ_f ≈ 0.01–0.035 m/s²; idling engine adds a little):
//! window 0.5 s, minimum duration 1 s, σ_f ≤ 0.08 m/s², σ_ω ≤ 0.3°/s,
//! |ω̄| ≤ 1°/s (room for an uncalibrated bias of a few tenths °/s),
//! ||f̄| − g| ≤ 0.2 m/s² (≈ 20 mg: accelerometer bias plus scale error),
//! |(Ĉ_bn f̄)_NE| ≤ 0.3 m/s² (attitude error ≲ 1° plus bias; a gentler steady
//! acceleration below 3 m/s lasting over 1 s can still pass: an accepted limitation),
//! filter speed ≤ 3 m/s; ZUPT σ 0.01 m/s, ZARU σ 0.05°/s (σ of the mean rate over one
//! 0.1-s interval: 0.12°/s/√20 ≈ 0.03°/s white noise plus margin); both at 10 Hz.
//!
//! ZARU uses the mean *raw* rate over the standstill samples since its previous update
//! (non-overlapping, so successive ZARUs have independent noise), compensated with the
//! current estimates at update time.
//!
//! Every aid update is stored in [`super::ForwardRun::updates`] like a GNSS update
//! (P prior and posterior at that epoch; aids at an epoch that also had a GNSS update
//! are merged into its record), so an RTS smoother sees them.

use driftless_model::linalg::{Mat3, Vec3};
use driftless_model::units::DEG;

use super::NavError;

/// Non-holonomic constraint settings ([module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NhcConfig {
    /// IMU-to-vehicle rotation C_vb (x_v = C_vb x_b); identity when the IMU axes are
    /// the vehicle's forward, right, down.
    pub c_vb: Mat3,
    /// Lever arm from the IMU to the constrained point (rear-axle centre / wheel
    /// contact), body axes, m. Zero ignores the rotation term ω_nb × l.
    pub lever_arm_b_m: Vec3,
    /// σ of the lateral and vertical vehicle-frame velocity, m/s. Default (0.1, 0.1).
    pub sigma_m_s: [f64; 2],
    /// Interval between NHC updates, s. Default 0.1 (10 Hz).
    pub interval_s: f64,
    /// No NHC below this estimated speed, m/s. Default 1.
    pub min_speed_m_s: f64,
    /// No NHC above this vehicle yaw rate |ω_z^v|, rad/s. Default 30°/s.
    pub max_yaw_rate_rad_s: f64,
    /// Gate of the NHC update (2 dof); `None` (default) uses the filter's
    /// [`super::FilterConfig::gate`]. Under the default robust gate an NHC innovation
    /// larger than the constraint's σ explains (side slip, a kerb, a hand-held rig that
    /// is not a vehicle) inflates R instead of being rejected.
    pub gate: Option<super::Gate>,
}

impl Default for NhcConfig {
    fn default() -> Self {
        NhcConfig {
            c_vb: Mat3::IDENTITY,
            lever_arm_b_m: [0.0; 3],
            sigma_m_s: [0.1, 0.1],
            interval_s: 0.1,
            min_speed_m_s: 1.0,
            max_yaw_rate_rad_s: 30.0 * DEG,
            gate: None,
        }
    }
}

impl NhcConfig {
    /// NHC with the IMU rotated by `c_vb` relative to the vehicle, defaults elsewhere.
    pub fn with_mounting(c_vb: Mat3) -> Self {
        NhcConfig {
            c_vb,
            ..Self::default()
        }
    }

    pub(crate) fn validate(&self) -> Result<(), NavError> {
        let c = &self.c_vb;
        let ctc = c.t().mul_mat(c);
        let mut orth = c.0.iter().flatten().all(|v| v.is_finite());
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { 1.0 } else { 0.0 };
                orth &= (ctc.0[i][j] - e).abs() < 1e-6;
            }
        }
        if !orth || c.det() < 0.0 {
            return Err(NavError::Config(format!(
                "NHC mounting C_vb {:?} is not a rotation matrix",
                c.0
            )));
        }
        let ok = self.sigma_m_s.iter().all(|s| s.is_finite() && *s > 0.0)
            && self.interval_s.is_finite()
            && self.interval_s >= 0.0
            && self.min_speed_m_s.is_finite()
            && self.min_speed_m_s >= 0.0
            && self.max_yaw_rate_rad_s > 0.0
            && self
                .lever_arm_b_m
                .iter()
                .all(|v| v.is_finite() && v.abs() < 100.0)
            && self.gate.is_none_or(|g| g.validate().is_ok());
        if !ok {
            return Err(NavError::Config(format!(
                "NHC settings invalid (σ > 0 m/s, interval ≥ 0 s, min speed ≥ 0, max yaw \
                 rate > 0 rad/s, lever arm < 100 m, gate > 0): {self:?}"
            )));
        }
        Ok(())
    }
}

/// Standstill detection and ZUPT / ZARU settings ([module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandstillConfig {
    /// Sliding-window length, s. Default 0.5.
    pub window_s: f64,
    /// Minimum static time before a standstill is declared, s (≥ window). Default 1.
    pub min_duration_s: f64,
    /// Largest per-axis σ of the specific force in the window, m/s². Default 0.08.
    pub accel_std_max_m_s2: f64,
    /// Largest per-axis σ of the angular rate, rad/s. Default 0.3°/s.
    pub gyro_std_max_rad_s: f64,
    /// Largest |mean angular rate|, rad/s. Default 1°/s.
    pub gyro_mean_max_rad_s: f64,
    /// Largest ||mean specific force| − g|, m/s². Default 0.2.
    pub accel_mean_tol_m_s2: f64,
    /// Largest horizontal component of the mean specific force resolved with the
    /// filter's attitude, |(Ĉ_bn f̄)_NE|, m/s²; `None` disables. Default 0.3 (an
    /// attitude error of 1° alone gives 0.17).
    pub accel_horizontal_max_m_s2: Option<f64>,
    /// Largest filter speed |v̂^n| for a standstill, m/s; `None` disables. Default 3.
    pub max_speed_m_s: Option<f64>,
    /// Largest GNSS speed (fixes with velocity only), m/s; `None` disables. Default
    /// `None`.
    pub gnss_speed_max_m_s: Option<f64>,
    /// ZUPT σ, m/s; `None` disables ZUPT. Default 0.01.
    pub zupt_sigma_m_s: Option<f64>,
    /// ZARU σ of the mean rate over one interval, rad/s; `None` disables ZARU.
    /// Default 0.05°/s.
    pub zaru_sigma_rad_s: Option<f64>,
    /// Interval between ZUPT/ZARU updates during a standstill, s. Default 0.1.
    pub interval_s: f64,
}

impl Default for StandstillConfig {
    fn default() -> Self {
        StandstillConfig {
            window_s: 0.5,
            min_duration_s: 1.0,
            accel_std_max_m_s2: 0.08,
            gyro_std_max_rad_s: 0.3 * DEG,
            gyro_mean_max_rad_s: 1.0 * DEG,
            accel_mean_tol_m_s2: 0.2,
            accel_horizontal_max_m_s2: Some(0.3),
            max_speed_m_s: Some(3.0),
            gnss_speed_max_m_s: None,
            zupt_sigma_m_s: Some(0.01),
            zaru_sigma_rad_s: Some(0.05 * DEG),
            interval_s: 0.1,
        }
    }
}

impl StandstillConfig {
    pub(crate) fn validate(&self) -> Result<(), NavError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let ok = pos(self.window_s)
            && self.window_s <= 60.0
            && self.min_duration_s.is_finite()
            && self.min_duration_s >= 0.0
            && pos(self.accel_std_max_m_s2)
            && pos(self.gyro_std_max_rad_s)
            && self.gyro_std_max_rad_s < 0.2
            && pos(self.gyro_mean_max_rad_s)
            && self.gyro_mean_max_rad_s < 0.2
            && pos(self.accel_mean_tol_m_s2)
            && self.accel_horizontal_max_m_s2.is_none_or(pos)
            && self.max_speed_m_s.is_none_or(pos)
            && self.gnss_speed_max_m_s.is_none_or(pos)
            && self.zupt_sigma_m_s.is_none_or(pos)
            && self.zaru_sigma_rad_s.is_none_or(|s| pos(s) && s < 0.1)
            && self.interval_s.is_finite()
            && self.interval_s >= 0.0;
        if !ok {
            return Err(NavError::Config(format!(
                "standstill settings invalid (positive σ's and thresholds, window ≤ 60 s, \
                 angular rates in rad/s — a rate threshold ≥ 0.2 rad/s or a ZARU σ ≥ 0.1 \
                 rad/s suggests degrees): {self:?}"
            )));
        }
        Ok(())
    }
}

/// Sliding-window standstill detector over compensated IMU samples ([module
/// docs](self)). Cost per sample O(1): running sums of the six channels and their
/// squares, re-summed from the buffer at every wrap of the ring to bound rounding drift.
#[derive(Clone, Debug)]
pub struct StandstillDetector {
    cfg: StandstillConfig,
    dt_s: f64,
    buf: Vec<[f64; 6]>,
    head: usize,
    len: usize,
    sum: [f64; 6],
    sum_sq: [f64; 6],
    candidate_start_s: Option<f64>,
    last_static_s: f64,
    active: bool,
    intervals: Vec<(f64, f64)>,
}

impl StandstillDetector {
    /// A detector for samples every `dt_s` seconds (the window holds
    /// max(2, round(window_s/dt_s)) samples).
    pub fn new(cfg: &StandstillConfig, dt_s: f64) -> Result<Self, NavError> {
        cfg.validate()?;
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(NavError::Config(format!(
                "standstill detector: sample interval {dt_s} s must be > 0"
            )));
        }
        let n = ((cfg.window_s / dt_s).round() as usize).max(2);
        Ok(StandstillDetector {
            cfg: *cfg,
            dt_s,
            buf: vec![[0.0; 6]; n],
            head: 0,
            len: 0,
            sum: [0.0; 6],
            sum_sq: [0.0; 6],
            candidate_start_s: None,
            last_static_s: f64::NAN,
            active: false,
            intervals: Vec::new(),
        })
    }

    /// True while a standstill is declared.
    pub fn is_standstill(&self) -> bool {
        self.active
    }

    /// Closed standstill intervals so far, (start, end) s.
    pub fn intervals(&self) -> &[(f64, f64)] {
        &self.intervals
    }

    /// Whether the current window is static by the IMU criteria 1–4 (and 4b with
    /// `c_bn`).
    fn window_static(&self, gravity_m_s2: f64, c_bn: Option<&Mat3>) -> bool {
        let n = self.buf.len();
        if self.len < n {
            return false;
        }
        let inv = 1.0 / n as f64;
        let mean: [f64; 6] = std::array::from_fn(|k| self.sum[k] * inv);
        let var: [f64; 6] =
            std::array::from_fn(|k| (self.sum_sq[k] * inv - mean[k] * mean[k]).max(0.0));
        let (gs, as_) = (
            self.cfg.gyro_std_max_rad_s.powi(2),
            self.cfg.accel_std_max_m_s2.powi(2),
        );
        let w2 = mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2];
        let f = (mean[3] * mean[3] + mean[4] * mean[4] + mean[5] * mean[5]).sqrt();
        let imu_ok = var[..3].iter().all(|&v| v <= gs)
            && var[3..].iter().all(|&v| v <= as_)
            && w2 <= self.cfg.gyro_mean_max_rad_s.powi(2)
            && (f - gravity_m_s2).abs() <= self.cfg.accel_mean_tol_m_s2;
        match (imu_ok, self.cfg.accel_horizontal_max_m_s2, c_bn) {
            (true, Some(hmax), Some(c)) => {
                let f_n = c.mul_vec([mean[3], mean[4], mean[5]]);
                f_n[0] * f_n[0] + f_n[1] * f_n[1] <= hmax * hmax
            }
            _ => imu_ok,
        }
    }

    /// Add the sample ending at `time_s` (compensated rate, specific force);
    /// `gate_ok` is criterion 5 (speed gates), `gravity_m_s2` the local g, `c_bn` the
    /// current attitude estimate for criterion 4b (`None` skips it). Returns whether a
    /// standstill is declared after this sample.
    pub fn push(
        &mut self,
        time_s: f64,
        omega_rad_s: Vec3,
        f_m_s2: Vec3,
        gate_ok: bool,
        gravity_m_s2: f64,
        c_bn: Option<&Mat3>,
    ) -> bool {
        let x = [
            omega_rad_s[0],
            omega_rad_s[1],
            omega_rad_s[2],
            f_m_s2[0],
            f_m_s2[1],
            f_m_s2[2],
        ];
        let n = self.buf.len();
        if self.len == n {
            let old = self.buf[self.head];
            for k in 0..6 {
                self.sum[k] -= old[k];
                self.sum_sq[k] -= old[k] * old[k];
            }
        } else {
            self.len += 1;
        }
        self.buf[self.head] = x;
        for k in 0..6 {
            self.sum[k] += x[k];
            self.sum_sq[k] += x[k] * x[k];
        }
        self.head += 1;
        if self.head == n {
            self.head = 0;
            // Re-sum from the buffer to bound rounding drift of the running sums.
            self.sum = [0.0; 6];
            self.sum_sq = [0.0; 6];
            for s in &self.buf[..self.len] {
                for k in 0..6 {
                    self.sum[k] += s[k];
                    self.sum_sq[k] += s[k] * s[k];
                }
            }
        }
        let is_static = gate_ok && self.window_static(gravity_m_s2, c_bn);
        if is_static {
            let start = *self
                .candidate_start_s
                .get_or_insert(time_s - n as f64 * self.dt_s);
            self.last_static_s = time_s;
            if !self.active && time_s - start >= self.cfg.min_duration_s - 1e-9 {
                self.active = true;
            }
        } else {
            self.close();
        }
        self.active
    }

    /// End a declared standstill (at the last static sample) and forget the candidate.
    pub fn close(&mut self) {
        if self.active
            && let Some(s) = self.candidate_start_s
        {
            self.intervals.push((s, self.last_static_s));
        }
        self.active = false;
        self.candidate_start_s = None;
    }

    /// Close any open standstill and return all intervals.
    pub fn finish(mut self) -> Vec<(f64, f64)> {
        self.close();
        self.intervals
    }
}

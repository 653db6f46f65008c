//! The 21-state closed-loop error-state Kalman filter.
//!
//! # Cycle
//!
//! * [`Eskf::predict`]: compensate the raw increment with the current sensor-error
//!   estimates (Δθ̂ = (Δθ̃ − b̂_gΔt) ⊘ (1 + ŝ_g), Δv̂ likewise), mechanize
//!   ([`mechanize`]), propagate P with Φ and Q_d built at the state of the start of the
//!   interval ([`super::model`]). The error state itself stays zero (closed loop).
//! * [`Eskf::update_position`] / [`Eskf::update_velocity`]: innovation, gate
//!   ([`Gate`]: off, χ² test, or robust inflation of R), gain,
//!   Joseph-form covariance update (Bucy & Joseph; Brown & Hwang 2012 §4.2, eq. 4.2.18),
//!   P⁺ = (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ, which keeps P symmetric PD under rounding and
//!   for any K; then feedback of δx̂ = K y into the navigation state and the sensor
//!   estimates, and reset of δx̂ to zero. (The reset Jacobian I − ½[δφ×] of Groves
//!   §14.2.7 / Shin §3.4 is taken as I: its effect is second order in the corrections.)
//!   After each update P is checked for symmetry, finiteness and positive definiteness
//!   (Cholesky); failure is a [`NavError::Covariance`] with a diagnosis.
//!
//! # Measurement models (errors as in [`super`]: estimated minus true)
//!
//! Position of the antenna at lever arm l (body) from the IMU: r_a = r + C_bn l. The
//! innovation is y = (Ĉ_bn l) − Δr_meas, Δr_meas the NED offset (m) of the GNSS fix from
//! the estimated IMU position (radii at the estimate), i.e. predicted minus measured
//! antenna position. With Ĉ = (I − [φ×])C: Ĉl = Cl + (Ĉl) × φ, so
//! y = δr + [(Ĉ_bn l)×] φ + noise, H_r = [I₃, 0, [(Ĉ_bn l)×], 0, …] (Shin 2005 ch. 4;
//! Groves 2013 §14.3.1 lever-arm model; sign derived here for this error convention).
//!
//! Velocity of the antenna: v_a = v + C_bn(ω_ib^b × l) − ω_in^n × (C_bn l) (Groves
//! §14.3.1; the ω_in term is ≤ 1e-4·|l| m/s and enters the prediction only).
//! y = v̂_a − v_meas = δv + [(Ĉ(ω̂×l))×] φ − Ĉ[l×] b_g − Ĉ[l×]diag(ω̂) s_g + noise.
//!
//! # Attitude feedback
//!
//! From Ĉ = (I − [φ×]) C the corrected attitude is C = (I − [φ×])⁻¹ Ĉ ≈ (I + [φ×]) Ĉ,
//! applied exactly as a rotation on the navigation side: q_bn ← q(φ) ⊗ q̂_bn, q(φ) the
//! quaternion of the rotation vector φ (Groves §14.2.7 with the opposite sign convention
//! for the error; Shin §3.4).

use driftless_model::linalg::{Mat3, Vec3, add, cross, sub};

use super::NavError;
use super::model::{FilterConfig, Gate, Transition, omega_in, skew};
use super::state::{
    ATT, BA, BG, Cov, N_STATES, POS, SA, SG, SensorErrors, VEL, check_covariance,
    check_covariance_scaled, check_diagonal, state_name,
};
use crate::allan::ci::chi2_quantile;
use crate::nav::attitude::Quat;
use crate::nav::earth;
use crate::nav::mechanization::{ImuIncrement, NavState, mechanize};

/// Which measurement an update used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateKind {
    /// GNSS antenna position.
    Position,
    /// GNSS antenna velocity.
    Velocity,
    /// Non-holonomic constraint (lateral and vertical vehicle-frame velocity = 0;
    /// innovation (y, z, 0)), [`Eskf::update_nhc`].
    Nhc,
    /// Zero-velocity update, [`Eskf::update_zupt`].
    Zupt,
    /// Zero-angular-rate update, [`Eskf::update_zaru`].
    Zaru,
}

/// Result of one measurement update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOutcome {
    /// Measurement type.
    pub kind: UpdateKind,
    /// Epoch, s.
    pub time_s: f64,
    /// Innovation y (predicted − measured): NED m or m/s for GNSS and ZUPT, body rad/s
    /// for ZARU, vehicle-frame (lateral, vertical, 0) m/s for NHC.
    pub innovation: Vec3,
    /// Normalized innovation squared yᵀS⁻¹y.
    pub nis: f64,
    /// False when the gate rejected the measurement (state and P untouched).
    pub accepted: bool,
    /// Factor λ ≥ 1 by which the robust gate ([`Gate::Robust`]) inflated R for this
    /// update (1 when not inflated or not applied).
    pub r_scale: f64,
    /// Diagonal of H P⁻ Hᵀ, the predicted measurement's own variance before the update
    /// (same units as the innovation, squared; 0 beyond the measurement's dimension).
    pub hph_diag: Vec3,
}

/// The filter. See the module documentation.
#[derive(Clone, Debug)]
pub struct Eskf {
    nav: NavState,
    sensors: SensorErrors,
    p: Cov,
    prev_inc: Option<ImuIncrement>,
    last_omega_b_rad_s: Vec3,
    q_c: [f64; N_STATES],
    neg_inv_tau: [f64; 12],
    coupling_sigma_rad: f64,
    gate: Gate,
    symmetry_tol: f64,
}

impl Eskf {
    /// The gate applied to GNSS updates.
    pub fn gate(&self) -> Gate {
        self.gate
    }

    /// Replace the gate applied to GNSS updates.
    pub(crate) fn set_gate(&mut self, gate: Gate) {
        self.gate = gate;
    }

    /// A filter at `nav` with sensor-error estimates `sensors`, initial covariance
    /// `p0` (checked) and the noise model of `cfg` (validated). `prev_inc` is the raw
    /// increment of the interval before `nav.time_s` (for the two-sample corrections), if
    /// known.
    pub fn new(
        nav: NavState,
        sensors: SensorErrors,
        p0: Cov,
        prev_inc: Option<ImuIncrement>,
        cfg: &FilterConfig,
    ) -> Result<Eskf, NavError> {
        cfg.validate()?;
        let ok = [nav.lat_rad, nav.lon_rad, nav.height_m, nav.time_s]
            .iter()
            .chain(nav.vel_ned_m_s.iter())
            .chain(nav.q_bn.0.iter())
            .all(|v| v.is_finite());
        if !ok || nav.lat_rad.abs() >= 89.9f64.to_radians() {
            return Err(NavError::Config(format!(
                "initial state not finite or too close to a pole: {nav:?}"
            )));
        }
        check_covariance(&p0, cfg.symmetry_tol).map_err(|d| NavError::Covariance {
            time_s: nav.time_s,
            diagnosis: format!("initial covariance: {d}"),
        })?;
        let mut f = Eskf {
            nav,
            sensors,
            p: p0,
            prev_inc: None,
            last_omega_b_rad_s: [0.0; 3],
            q_c: cfg.q_c_diag(),
            neg_inv_tau: cfg.neg_inv_tau(),
            coupling_sigma_rad: cfg.gyro_coupling_sigma_rad,
            gate: cfg.gate,
            symmetry_tol: cfg.symmetry_tol,
        };
        f.nav.q_bn = f.nav.q_bn.normalized();
        if let Some(raw) = prev_inc {
            f.prev_inc = Some(f.compensate(&raw));
        }
        Ok(f)
    }

    /// Current navigation state (IMU centre).
    pub fn nav(&self) -> &NavState {
        &self.nav
    }

    /// Current sensor-error estimates.
    pub fn sensors(&self) -> &SensorErrors {
        &self.sensors
    }

    /// Current error covariance.
    pub fn covariance(&self) -> &Cov {
        &self.p
    }

    /// Mutable access to the covariance (diagnostics, fault injection in tests). The
    /// next predict/update checks it.
    pub fn covariance_mut(&mut self) -> &mut Cov {
        &mut self.p
    }

    /// Standard deviations √P_ii (NaN-free: a non-positive variance gives 0; such a P
    /// never survives a predict or update).
    pub fn std(&self) -> [f64; N_STATES] {
        std::array::from_fn(|i| self.p[i][i].max(0.0).sqrt())
    }

    /// Re-initialise the navigation states: the position, velocity and attitude of `nav`
    /// (its time is ignored; the filter's stays) with a diagonal covariance of the given
    /// σ, uncorrelated with the sensor-error states, whose estimates and covariance are
    /// kept. Used when the state has diverged from the measurements
    /// ([`super::FilterConfig::gate_recovery_s`]).
    pub fn reset_navigation(
        &mut self,
        nav: NavState,
        sigma_pos_ned_m: Vec3,
        sigma_vel_ned_m_s: Vec3,
        sigma_att_rad: Vec3,
    ) -> Result<(), NavError> {
        let sig = sigma_pos_ned_m
            .iter()
            .chain(sigma_vel_ned_m_s.iter())
            .chain(sigma_att_rad.iter());
        let ok = [nav.lat_rad, nav.lon_rad, nav.height_m]
            .iter()
            .chain(nav.vel_ned_m_s.iter())
            .chain(nav.q_bn.0.iter())
            .all(|v| v.is_finite());
        if !ok || !sig.clone().all(|s| s.is_finite() && *s > 0.0) {
            return Err(NavError::InvalidMeasurement {
                time_s: self.nav.time_s,
                reason: format!("navigation reset to a non-finite state or σ: {nav:?}"),
            });
        }
        let t = self.nav.time_s;
        self.nav = NavState {
            time_s: t,
            q_bn: nav.q_bn.normalized(),
            ..nav
        };
        for i in 0..9 {
            for j in 0..N_STATES {
                self.p[i][j] = 0.0;
                self.p[j][i] = 0.0;
            }
        }
        for (i, s) in sig.enumerate() {
            self.p[i][i] = s * s;
        }
        Ok(())
    }

    /// Last compensated angular rate ω̂_ib^b, rad/s.
    pub(crate) fn omega_ib_b_rad_s(&self) -> Vec3 {
        self.last_omega_b_rad_s
    }

    /// The compensated increment used by the last predict.
    pub(crate) fn last_compensated(&self) -> Option<ImuIncrement> {
        self.prev_inc
    }

    /// Raw increment → compensated increment (module docs).
    #[inline]
    pub fn compensate(&self, raw: &ImuIncrement) -> ImuIncrement {
        let s = &self.sensors;
        let dt = raw.dt_s;
        ImuIncrement {
            time_s: raw.time_s,
            dt_s: dt,
            dtheta_rad: std::array::from_fn(|k| {
                (raw.dtheta_rad[k] - s.gyro_bias_rad_s[k] * dt) / (1.0 + s.gyro_scale[k])
            }),
            dvel_m_s: std::array::from_fn(|k| {
                (raw.dvel_m_s[k] - s.accel_bias_m_s2[k] * dt) / (1.0 + s.accel_scale[k])
            }),
        }
    }

    /// Time update over one raw increment ending at `raw.time_s` (interval `raw.dt_s`,
    /// which must start at the current state time). Returns the transition used (the
    /// smoother can also rebuild it, see [`super::run`]).
    pub fn predict(&mut self, raw: &ImuIncrement) -> Result<Transition, NavError> {
        let dt = raw.dt_s;
        let finite = raw
            .dtheta_rad
            .iter()
            .chain(raw.dvel_m_s.iter())
            .all(|v| v.is_finite());
        if !(dt.is_finite() && dt > 0.0 && dt < 10.0 && finite && raw.time_s.is_finite()) {
            return Err(NavError::InvalidIncrement {
                time_s: raw.time_s,
                reason: format!(
                    "dt = {dt} s, Δθ = {:?}, Δv = {:?}",
                    raw.dtheta_rad, raw.dvel_m_s
                ),
            });
        }
        let comp = self.compensate(raw);
        let inv = 1.0 / dt;
        let omega = comp.dtheta_rad.map(|v| v * inv);
        let f_b = comp.dvel_m_s.map(|v| v * inv);
        let tr = Transition::new(&self.nav, omega, f_b, dt, &self.neg_inv_tau)
            .with_rotation_noise(self.coupling_sigma_rad);
        let prev = self.prev_inc.unwrap_or(comp);
        let next = mechanize(&self.nav, &prev, &comp);
        let ok = [next.lat_rad, next.lon_rad, next.height_m]
            .iter()
            .chain(next.vel_ned_m_s.iter())
            .all(|v| v.is_finite());
        if !ok {
            return Err(NavError::InvalidIncrement {
                time_s: raw.time_s,
                reason: format!("navigation state became non-finite: {next:?}"),
            });
        }
        self.nav = next;
        self.prev_inc = Some(comp);
        self.last_omega_b_rad_s = omega;
        tr.propagate(&mut self.p, &self.q_c);
        check_diagonal(&self.p).map_err(|(i, v)| NavError::Covariance {
            time_s: raw.time_s,
            diagnosis: format!(
                "after prediction the variance of state {i} ({}) is {v:e}",
                state_name(i)
            ),
        })?;
        Ok(tr)
    }

    /// GNSS position update: `fix_llh` = (lat rad, lon rad, h m) of the antenna,
    /// `sigma_ned_m` its σ (m, > 0), `lever_arm_b_m` the antenna offset from the IMU in
    /// body axes. See the module docs for the model.
    pub fn update_position(
        &mut self,
        fix_llh: [f64; 3],
        sigma_ned_m: Vec3,
        lever_arm_b_m: Vec3,
    ) -> Result<UpdateOutcome, NavError> {
        let t = self.nav.time_s;
        check_meas(t, &fix_llh, &sigma_ned_m, &lever_arm_b_m)?;
        let c_bn = self.nav.q_bn.to_dcm();
        let cl = c_bn.mul_vec(lever_arm_b_m);
        let d = earth::ned_offset_m(
            (self.nav.lat_rad, self.nav.lon_rad, self.nav.height_m),
            (fix_llh[0], fix_llh[1], fix_llh[2]),
        );
        let y = sub(cl, d);
        let mut h = [[0.0; N_STATES]; 3];
        let sk = skew(cl);
        for m in 0..3 {
            h[m][POS + m] = 1.0;
            for k in 0..3 {
                h[m][ATT + k] = sk[m][k];
            }
        }
        const COLS: [usize; 6] = [POS, POS + 1, POS + 2, ATT, ATT + 1, ATT + 2];
        self.update(UpdateKind::Position, y, &h, &COLS, sigma_ned_m, self.gate)
    }

    /// GNSS velocity update: `v_ned_m_s` the antenna velocity, `sigma_ned_m_s` its σ.
    pub fn update_velocity(
        &mut self,
        v_ned_m_s: Vec3,
        sigma_ned_m_s: Vec3,
        lever_arm_b_m: Vec3,
    ) -> Result<UpdateOutcome, NavError> {
        let t = self.nav.time_s;
        check_meas(t, &v_ned_m_s, &sigma_ned_m_s, &lever_arm_b_m)?;
        let c_bn = self.nav.q_bn.to_dcm();
        let w = self.last_omega_b_rad_s;
        let wxl = c_bn.mul_vec(cross(w, lever_arm_b_m));
        let cl = c_bn.mul_vec(lever_arm_b_m);
        let pred: Vec3 = std::array::from_fn(|k| {
            self.nav.vel_ned_m_s[k] + wxl[k] - cross(omega_in(&self.nav), cl)[k]
        });
        let y = sub(pred, v_ned_m_s);
        let s_att = skew(wxl);
        let c_lx = (c_bn * Mat3::skew(lever_arm_b_m)).0;
        let mut h = [[0.0; N_STATES]; 3];
        for m in 0..3 {
            h[m][VEL + m] = 1.0;
            for k in 0..3 {
                h[m][ATT + k] = s_att[m][k];
                h[m][BG + k] = -c_lx[m][k];
                h[m][SG + k] = -c_lx[m][k] * w[k];
            }
        }
        const COLS: [usize; 12] = [3, 4, 5, 6, 7, 8, 9, 10, 11, 15, 16, 17];
        self.update(UpdateKind::Velocity, y, &h, &COLS, sigma_ned_m_s, self.gate)
    }

    /// Non-holonomic constraint (land vehicle): the velocity of the wheel-contact /
    /// rear-axle point at lever arm `lever_b_m` (body axes, from the IMU) resolved in the
    /// vehicle frame has zero lateral and vertical components (Shin 2001; Dissanayake et
    /// al. 2001; Groves 2013 §16.4.1):
    ///
    ///   v^v = C_vb (C_nb v^n + ω_nb^b × l),  ω_nb^b = ω_ib^b − C_nb ω_in^n,
    ///   z = (v^v_y, v^v_z) = 0 with R = diag(σ_y², σ_z²),
    ///
    /// `c_vb` the IMU-to-vehicle rotation (x_v = C_vb x_b). With Ĉ_nb = C_nb(I + [φ×])
    /// (error convention of [`super`]), Ĉ_nb v̂ = C_nb v + C_nb δv − C_nb[v×]φ, and
    /// ω̂_ib × l = ω_ib × l − [l×](b_g + diag(ω̂)s_g), so y = ẑ − 0 = H δx + noise with
    /// rows y and z of
    ///
    ///   H_δv = C_vb Ĉ_nb,  H_φ = −C_vb Ĉ_nb [v̂^n×],
    ///   H_bg = −C_vb [l×],  H_sg = −C_vb [l×] diag(ω̂_ib^b)
    ///
    /// (the error of C_nb ω_in^n, ≤ 1e-4·|φ|, is neglected in H and kept in ẑ). ω̂_ib^b is
    /// the compensated rate of the last prediction interval.
    pub fn update_nhc(
        &mut self,
        c_vb: &Mat3,
        lever_b_m: Vec3,
        sigma_m_s: [f64; 2],
        gate: Gate,
    ) -> Result<UpdateOutcome, NavError> {
        let t = self.nav.time_s;
        let sig3 = [sigma_m_s[0], sigma_m_s[1], 1.0];
        check_meas(t, &[0.0; 3], &sig3, &lever_b_m)?;
        let c_nb = self.nav.q_bn.to_dcm().t();
        let a = c_vb.mul_mat(&c_nb);
        let w = self.last_omega_b_rad_s;
        let w_nb = sub(w, c_nb.mul_vec(omega_in(&self.nav)));
        let v_b = add(c_nb.mul_vec(self.nav.vel_ned_m_s), cross(w_nb, lever_b_m));
        let v_v = c_vb.mul_vec(v_b);
        let h_att = (a * Mat3::skew(self.nav.vel_ned_m_s)).0;
        let c_lx = (*c_vb * Mat3::skew(lever_b_m)).0;
        let mut h = [[0.0; N_STATES]; 2];
        for (m, row) in h.iter_mut().enumerate() {
            let r = m + 1;
            for k in 0..3 {
                row[VEL + k] = a.0[r][k];
                row[ATT + k] = -h_att[r][k];
                row[BG + k] = -c_lx[r][k];
                row[SG + k] = -c_lx[r][k] * w[k];
            }
        }
        const COLS_L: [usize; 12] = [3, 4, 5, 6, 7, 8, 9, 10, 11, 15, 16, 17];
        let cols: &[usize] = if lever_b_m == [0.0; 3] {
            &COLS_L[..6]
        } else {
            &COLS_L
        };
        self.update(UpdateKind::Nhc, [v_v[1], v_v[2]], &h, cols, sigma_m_s, gate)
    }

    /// Zero-velocity update at standstill: z = v^n = 0 (the IMU at rest), y = v̂^n,
    /// H = [0, I₃, 0, …], R = σ²I (Groves 2013 §16.2.3; Shin 2005 ch. 5).
    pub fn update_zupt(&mut self, sigma_m_s: f64, gate: Gate) -> Result<UpdateOutcome, NavError> {
        let t = self.nav.time_s;
        check_meas(t, &[0.0; 3], &[sigma_m_s; 3], &[0.0; 3])?;
        let mut h = [[0.0; N_STATES]; 3];
        for (m, row) in h.iter_mut().enumerate() {
            row[VEL + m] = 1.0;
        }
        const COLS: [usize; 3] = [VEL, VEL + 1, VEL + 2];
        let y = self.nav.vel_ned_m_s;
        self.update(UpdateKind::Zupt, y, &h, &COLS, [sigma_m_s; 3], gate)
    }

    /// Zero-angular-rate update at standstill (Groves 2013 §16.2.3): the body does not
    /// rotate relative to the Earth, ω_ib^b − C_nb ω_ie^n = 0. The measurement is the
    /// mean compensated rate over a stretch of standstill given by its *raw* angle
    /// increment `raw_dtheta_rad` over `dt_s` (compensated here with the current
    /// estimates: ω̂ = (Δθ̃/Δt − b̂_g) ⊘ (1 + ŝ_g)); y = ω̂ − Ĉ_nb ω_ie^n. With
    /// ω̂ = ω + b_g + diag(ω)s_g and Ĉ_nb ω_ie = C_nb ω_ie − C_nb[ω_ie×]φ:
    ///
    ///   H_bg = I₃,  H_sg = diag(ω̂),  H_φ = Ĉ_nb [ω_ie^n×],
    ///
    /// so ZARU observes the gyro biases directly — including the vertical one, which a
    /// ZUPT (or GNSS at rest) cannot — and stops the heading drift at rest. `sigma_rad_s`
    /// is the σ of that mean rate (white gyro noise ARW/√Δt plus vibration).
    pub fn update_zaru(
        &mut self,
        raw_dtheta_rad: Vec3,
        dt_s: f64,
        sigma_rad_s: f64,
        gate: Gate,
    ) -> Result<UpdateOutcome, NavError> {
        let t = self.nav.time_s;
        check_meas(t, &raw_dtheta_rad, &[sigma_rad_s; 3], &[0.0; 3])?;
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(NavError::InvalidMeasurement {
                time_s: t,
                reason: format!("ZARU interval {dt_s} s must be > 0"),
            });
        }
        let s = &self.sensors;
        let w: Vec3 = std::array::from_fn(|k| {
            (raw_dtheta_rad[k] / dt_s - s.gyro_bias_rad_s[k]) / (1.0 + s.gyro_scale[k])
        });
        let c_nb = self.nav.q_bn.to_dcm().t();
        let w_ie = earth::earth_rate_ned(self.nav.lat_rad);
        let y = sub(w, c_nb.mul_vec(w_ie));
        let h_att = (c_nb * Mat3::skew(w_ie)).0;
        let mut h = [[0.0; N_STATES]; 3];
        for (m, row) in h.iter_mut().enumerate() {
            row[BG + m] = 1.0;
            row[SG + m] = w[m];
            row[ATT..ATT + 3].copy_from_slice(&h_att[m]);
        }
        const COLS: [usize; 9] = [
            ATT,
            ATT + 1,
            ATT + 2,
            BG,
            BG + 1,
            BG + 2,
            SG,
            SG + 1,
            SG + 2,
        ];
        self.update(UpdateKind::Zaru, y, &h, &COLS, [sigma_rad_s; 3], gate)
    }

    /// Generic M-dimensional update (M = 2 or 3) with H non-zero only in `cols`,
    /// R = diag(σ²), gated by `gate` ([`Gate`]).
    fn update<const M: usize>(
        &mut self,
        kind: UpdateKind,
        y: [f64; M],
        h: &[[f64; N_STATES]; M],
        cols: &[usize],
        sigma: [f64; M],
        gate: Gate,
    ) -> Result<UpdateOutcome, NavError> {
        const { assert!(M >= 1 && M <= 3) };
        let t = self.nav.time_s;
        check_diagonal(&self.p).map_err(|(i, v)| NavError::Covariance {
            time_s: t,
            diagnosis: format!(
                "before update the variance of state {i} ({}) is {v:e}",
                state_name(i)
            ),
        })?;
        let p = &self.p;
        // PHᵀ (21 × M).
        let mut pht = [[0.0; M]; N_STATES];
        for (i, row) in pht.iter_mut().enumerate() {
            for (m, v) in row.iter_mut().enumerate() {
                *v = cols.iter().map(|&c| p[i][c] * h[m][c]).sum();
            }
        }
        let r0 = sigma.map(|s| s * s);
        // H P Hᵀ (M × M block of S without R).
        let mut hph = [[0.0; 3]; 3];
        for m in 0..M {
            for n in 0..M {
                hph[m][n] = cols.iter().map(|&c| h[m][c] * pht[c][n]).sum::<f64>();
            }
        }
        // S⁻¹ and the NIS for R scaled by λ.
        let solve = |lambda: f64| innovation_test::<M>(t, &hph, &r0, lambda, &y);
        let (mut s_inv, nis) = solve(1.0)?;
        let mut lambda = 1.0;
        let accepted = match gate {
            Gate::Off => true,
            Gate::Chi2 { p } => nis <= chi2_quantile(p, M as f64),
            Gate::Robust {
                p_inflate,
                p_reject,
                max_sigma_scale,
            } => {
                let c = chi2_quantile(p_inflate, M as f64);
                if nis <= c {
                    true
                } else {
                    let lambda_max = max_sigma_scale * max_sigma_scale;
                    let (_, nis_max) = solve(lambda_max)?;
                    lambda = (nis / c).min(lambda_max);
                    s_inv = solve(lambda)?.0;
                    nis_max <= chi2_quantile(p_reject, M as f64)
                }
            }
        };
        let r = r0.map(|v| v * lambda);
        let mut innovation = [0.0; 3];
        innovation[..M].copy_from_slice(&y);
        let mut hph_diag = [0.0; 3];
        for (m, v) in hph_diag.iter_mut().enumerate().take(M) {
            *v = hph[m][m];
        }
        let out = UpdateOutcome {
            kind,
            time_s: t,
            innovation,
            nis,
            accepted,
            r_scale: if accepted { lambda } else { 1.0 },
            hph_diag,
        };
        if !accepted {
            return Ok(out);
        }
        // K = PHᵀS⁻¹, δx = K y.
        let mut k = [[0.0; M]; N_STATES];
        let mut dx = [0.0; N_STATES];
        for i in 0..N_STATES {
            for n in 0..M {
                k[i][n] = (0..M).map(|m| pht[i][m] * s_inv.0[m][n]).sum();
            }
            let mut a = 0.0;
            for m in 0..M {
                a += k[i][m] * y[m];
            }
            dx[i] = a;
        }
        // Joseph form: W = (I − KH)P = P − K(PHᵀ)ᵀ; P⁺ = W − (WHᵀ)Kᵀ + K R Kᵀ.
        let mut w = *p;
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                let mut a = 0.0;
                for m in 0..M {
                    a += k[i][m] * pht[j][m];
                }
                w[i][j] -= a;
            }
        }
        let mut wht = [[0.0; M]; N_STATES];
        for i in 0..N_STATES {
            for m in 0..M {
                wht[i][m] = cols.iter().map(|&c| w[i][c] * h[m][c]).sum();
            }
        }
        let mut pn = w;
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                let mut a = 0.0;
                for m in 0..M {
                    a += (k[i][m] * r[m] - wht[i][m]) * k[j][m];
                }
                pn[i][j] += a;
            }
        }

        let prior_diag: [f64; N_STATES] = std::array::from_fn(|i| p[i][i]);
        check_covariance_scaled(&pn, self.symmetry_tol, &prior_diag).map_err(|d| {
            NavError::Covariance {
                time_s: t,
                diagnosis: format!("after {kind:?} update: {d}"),
            }
        })?;
        for i in 0..N_STATES {
            for j in (i + 1)..N_STATES {
                let a = 0.5 * (pn[i][j] + pn[j][i]);
                pn[i][j] = a;
                pn[j][i] = a;
            }
        }
        self.p = pn;
        self.feedback(&dx);
        Ok(out)
    }

    /// Apply the estimated error state and reset it (module docs).
    fn feedback(&mut self, dx: &[f64; N_STATES]) {
        apply_error_state(&mut self.nav, &mut self.sensors, dx);
    }
}

/// Correct a navigation state and sensor-error estimates by an error state δx (module
/// docs for the sign conventions): position and velocity are "estimate − truth", the
/// attitude error φ rotates by q(φ) ⊗ q_bn, sensor-error states add. Shared by the
/// filter's feedback and the smoother.
pub(crate) fn apply_error_state(n: &mut NavState, s: &mut SensorErrors, dx: &[f64; N_STATES]) {
    let rm_h = earth::meridian_radius_m(n.lat_rad) + n.height_m;
    let rn_h = earth::prime_vertical_radius_m(n.lat_rad) + n.height_m;
    n.lon_rad -= dx[POS + 1] / (rn_h * n.lat_rad.cos());
    n.lat_rad -= dx[POS] / rm_h;
    n.height_m += dx[POS + 2];
    for k in 0..3 {
        n.vel_ned_m_s[k] -= dx[VEL + k];
    }
    let phi = [dx[ATT], dx[ATT + 1], dx[ATT + 2]];
    if phi != [0.0; 3] {
        n.q_bn = Quat::from_rotation_vector(phi).mul(&n.q_bn).normalized();
    }
    for k in 0..3 {
        s.gyro_bias_rad_s[k] += dx[BG + k];
        s.accel_bias_m_s2[k] += dx[BA + k];
        s.gyro_scale[k] += dx[SG + k];
        s.accel_scale[k] += dx[SA + k];
    }
}

/// S = H P Hᵀ + λR (padded to 3 × 3 with an identity block, whose inverse then carries
/// the inverse of the M × M block unchanged), its inverse and the NIS yᵀS⁻¹y.
fn innovation_test<const M: usize>(
    t: f64,
    hph: &[[f64; 3]; 3],
    r: &[f64; M],
    lambda: f64,
    y: &[f64; M],
) -> Result<(Mat3, f64), NavError> {
    let mut s = [[0.0; 3]; 3];
    for m in M..3 {
        s[m][m] = 1.0;
    }
    for m in 0..M {
        s[m][..M].copy_from_slice(&hph[m][..M]);
        s[m][m] += lambda * r[m];
    }
    // Symmetrize S against rounding before inverting.
    for m in 0..3 {
        for n in (m + 1)..3 {
            let a = 0.5 * (s[m][n] + s[n][m]);
            s[m][n] = a;
            s[n][m] = a;
        }
    }
    let s_inv = Mat3(s).inverse().ok_or_else(|| NavError::Covariance {
        time_s: t,
        diagnosis: format!("innovation covariance S = {s:?} is singular"),
    })?;
    let mut nis = 0.0;
    for m in 0..M {
        for n in 0..M {
            nis += y[m] * s_inv.0[m][n] * y[n];
        }
    }
    if !nis.is_finite() || nis < 0.0 {
        return Err(NavError::Covariance {
            time_s: t,
            diagnosis: format!(
                "innovation covariance S = {s:?} is not positive definite (NIS {nis})"
            ),
        });
    }
    Ok((s_inv, nis))
}

fn check_meas(t: f64, value: &[f64; 3], sigma: &Vec3, lever: &Vec3) -> Result<(), NavError> {
    if !value.iter().chain(lever.iter()).all(|v| v.is_finite()) {
        return Err(NavError::InvalidMeasurement {
            time_s: t,
            reason: format!("non-finite value {value:?} or lever arm {lever:?}"),
        });
    }
    if !sigma.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(NavError::InvalidMeasurement {
            time_s: t,
            reason: format!("σ = {sigma:?} must be finite and > 0"),
        });
    }
    Ok(())
}

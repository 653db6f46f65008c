//! Error dynamics, process noise and covariance propagation of the 21-state filter.
//!
//! # Continuous-time error model (NED, phi-angle)
//!
//! Sources: Shin 2005 ch. 3 (error states in NED metres, phi-angle attitude error);
//! Groves 2013 §14.2.4 (local-navigation-frame error equations); Titterton & Weston 2004
//! §12.3. Errors as in [`super`] (estimated minus true; sensor states are residual errors
//! of the compensated outputs). With R_M, R_N the meridian/prime-vertical radii,
//! ω_in = ω_ie + ω_en and the sensor-error coupling
//! δω_ib^b = b_g + diag(ω_ib^b) s_g, δf^b = b_a + diag(f^b) s_a:
//!
//! * position: δṙ = F_rr δr + δv with (ignoring dR/dφ) F_rr rows
//!   (−v_D/(R_M+h), 0, v_N/(R_M+h)),
//!   (v_E tan φ/(R_M+h), −(v_D/(R_N+h) + v_N tan φ/(R_M+h)), v_E/(R_N+h)), (0, 0, 0)
//!   (differentiating δr_N = (R_M+h)δφ, δr_E = (R_N+h)cos φ δλ, δr_D = −δh along the
//!   trajectory);
//! * velocity: δv̇ = C_bn δf^b + f^n × φ − (2δω_ie + δω_en) × v − (2ω_ie + ω_en) × δv + δg,
//!   δg = (0, 0, 2g/(√(R_M R_N)+h)·δr_D) (free-air gradient; the unstable vertical channel);
//! * attitude: φ̇ = −ω_in × φ + δω_in − C_bn δω_ib^b;
//!
//! where δω_ie = ∂ω_ie/∂r δr and δω_en = ∂ω_en/∂r δr + ∂ω_en/∂v δv are written as the
//! 3 × 3 Jacobians M_ie,r, M_en,r, M_en,v (δφ = δr_N/(R_M+h), δh = −δr_D);
//! * sensor errors: first-order Gauss–Markov, ẋ = −x/T + w, E(w²) = q = 2σ²/T
//!   (Brown & Hwang 2012 §4.2; Groves §14.2.7).
//!
//! Noise vector w = (w_v, w_φ, w_bg, w_ba, w_sg, w_sa): VRW and ARW enter as
//! δv̇ += C_bn w_a, φ̇ −= C_bn w_g with PSDs VRW², ARW² (m²/s³, rad²/s), isotropic, so
//! G Q Gᵀ is *diagonal*: q_c = (0₃, VRW²·1₃, ARW²·1₃, 2σ²/T per sensor state).
//!
//! # Unmodelled gyro axis coupling (optional)
//!
//! A gyro whose axes are misaligned or cross-coupled measures ω̃ = (I + diag(s_g) + M)ω;
//! the filter estimates s_g but has no state for the off-diagonal M. With the elements of
//! M independent, zero-mean, of σ_c ([`FilterConfig::gyro_coupling_sigma_rad`]), the rate
//! error Mω has the body-frame covariance σ_c² diag(|ω|² − ω_k²): none along a rotation
//! about a body axis, σ_c²|ω|² across it. Its attitude error is coherent while the body
//! keeps turning the same way (a yaw turn by θ tilts by up to σ_c·θ) and, resolved in the
//! navigation frame, stays bounded (≤ 2|M| over whole turns). It is modelled as a random
//! walk in the angle turned — each axis across the rotation gains σ_c² of variance per
//! radian:
//!
//!   Q_φ,rot = σ_c² C_bn diag(|ω̂| − ω̂_k²/|ω̂|) C_bnᵀ   (rad²/s, added to Q_c's attitude block),
//!
//! so a 180° yaw turn adds a tilt σ of √π·σ_c ≈ 1.8σ_c against the coherent 2σ_c. This is
//! an allowance in Q for an error without a state (derived here), not an estimate of M;
//! oscillating rotation (hand sway) is counted at its full angle and so over-allowed.
//!
//! # Discretization
//!
//! Over the IMU interval Δt (5 ms at 200 Hz) Φ ≈ I + FΔt (first order: the neglected
//! ½(FΔt)² is ~1e-9 relative for a 200 Hz land vehicle), F evaluated at the state at the
//! start of the interval with the compensated mean rate and specific force of the
//! interval. Q_d by the trapezoid rule Q_d ≈ ½(Φ Q_c Φᵀ + Q_c)Δt (Brown & Hwang §3.9;
//! Shin 2005 ch. 3), applied as
//!
//!   P⁻_{k+1} = Φ (P_k + ½Q_cΔt) Φᵀ + ½Q_cΔt,
//!
//! which is the same thing and costs only two diagonal additions because Q_c is diagonal.
//!
//! # Cost
//!
//! A = Φ − I = FΔt has 11 non-zero 3 × 3 blocks and a diagonal for the 12 sensor states
//! ([`Transition`]), so ΦPΦᵀ = P + AP + (AP)ᵀ + A(AP)ᵀ is evaluated with 42 sparse
//! matrix-vector products A·x (~110 multiply-adds each) instead of two dense 21³
//! products; see [`Transition::propagate`].

use driftless_model::linalg::{Mat3, Vec3, add, cross, scale};

use super::NavError;
use super::state::{ATT, BA, BG, Cov, N_STATES, POS, SA, SG, VEL};
use crate::io::nav::quality;
use crate::nav::earth;
use crate::nav::mechanization::NavState;

mod gate;
mod transition;
pub use gate::*;
pub use transition::*;

/// First-order Gauss–Markov process parameters: stationary σ (state units) and
/// correlation time T (s). Driving-noise PSD q = 2σ²/T.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussMarkov {
    /// Stationary standard deviation (rad/s, m/s² or dimensionless).
    pub sigma: f64,
    /// Correlation time T, s (> 0).
    pub tau_s: f64,
}

impl GaussMarkov {
    /// Continuous driving-noise PSD q = 2σ²/T.
    pub(crate) fn psd(&self) -> f64 {
        2.0 * self.sigma * self.sigma / self.tau_s
    }
}

/// IMU noise and sensor-error model (e.g. from the Allan-variance noise-model file:
/// ARW = white-noise coefficient N of the gyro, VRW = N of the accelerometer, bias
/// instability → GM σ, RRW/long-term drift → T).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuNoise {
    /// Angle random walk, rad/√s (= rad/s/√Hz).
    pub gyro_arw_rad_sqrt_s: f64,
    /// Velocity random walk, m/s/√s.
    pub accel_vrw_m_s_sqrt_s: f64,
    /// Gyro bias, rad/s.
    pub gyro_bias: GaussMarkov,
    /// Accelerometer bias, m/s².
    pub accel_bias: GaussMarkov,
    /// Gyro scale-factor error, dimensionless.
    pub gyro_scale: GaussMarkov,
    /// Accelerometer scale-factor error, dimensionless.
    pub accel_scale: GaussMarkov,
}

impl ImuNoise {
    /// Noise parameters from an Allan-variance noise model (`allan::noise_model`, the
    /// noise-model file), worst axis per sensor:
    ///
    /// * ARW / VRW = the white-noise coefficient N (rad/√s, m/s/√s);
    /// * bias: a fitted Gauss–Markov term is used as is; otherwise a GM with correlation
    ///   time `bias_tau_s` and σ² = B² + K²T/2, B the bias-instability coefficient and
    ///   K the rate-random-walk coefficient (a random walk of PSD K² reaches the variance
    ///   of a GM with q = 2σ²/T after ≈ T/2 — the usual first-order stand-in; Groves 2013
    ///   §4.4.3 and §14.2.7; El-Sheimy, Hou & Niu 2008 for the Allan terms);
    /// * scale factors are not observable in a static Allan recording and are given.
    ///
    /// Errors when a sensor has no channel or no white-noise term.
    pub fn from_noise_model(
        model: &crate::allan::noise_model::NoiseModel,
        bias_tau_s: f64,
        gyro_scale: GaussMarkov,
        accel_scale: GaussMarkov,
    ) -> Result<ImuNoise, NavError> {
        use crate::allan::noise_model::Quantity;
        if !(bias_tau_s.is_finite() && bias_tau_s > 0.0) {
            return Err(NavError::Config(format!(
                "bias correlation time {bias_tau_s} s"
            )));
        }
        let pick = |q: Quantity| -> Result<(f64, GaussMarkov), NavError> {
            let mut white: Option<f64> = None;
            let mut bias = GaussMarkov {
                sigma: 0.0,
                tau_s: bias_tau_s,
            };
            for c in model.channels.iter().filter(|c| c.quantity == q) {
                let f = &c.fit;
                if let Some(w) = f.white {
                    white = Some(white.map_or(w.value, |x: f64| x.max(w.value)));
                }
                let gm = if let Some(g) = f.gauss_markov {
                    GaussMarkov {
                        sigma: g.sigma.value,
                        tau_s: g.tau_c_s.value,
                    }
                } else {
                    let b = f.bias_instability.map_or(0.0, |t| t.value);
                    let k = f.rate_random_walk.map_or(0.0, |t| t.value);
                    GaussMarkov {
                        sigma: (b * b + k * k * bias_tau_s / 2.0).sqrt(),
                        tau_s: bias_tau_s,
                    }
                };
                if gm.sigma > bias.sigma {
                    bias = gm;
                }
            }
            let white = white.ok_or_else(|| {
                NavError::Config(format!("noise model has no {q:?} channel with white noise"))
            })?;
            if bias.sigma.is_nan() || bias.sigma <= 0.0 {
                return Err(NavError::Config(format!(
                    "noise model has no {q:?} bias term (bias instability, RRW or GM)"
                )));
            }
            Ok((white, bias))
        };
        let (arw, gyro_bias) = pick(Quantity::AngularRate)?;
        let (vrw, accel_bias) = pick(Quantity::SpecificForce)?;
        Ok(ImuNoise {
            gyro_arw_rad_sqrt_s: arw,
            accel_vrw_m_s_sqrt_s: vrw,
            gyro_bias,
            accel_bias,
            gyro_scale,
            accel_scale,
        })
    }
}

/// Multipliers of the reported GNSS σ per RTKLIB quality flag (index = flag 0..=6:
/// unspecified, fix, float, SBAS, DGPS, single, PPP). R = (k·σ)².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QualityScale(pub [f64; 7]);

impl Default for QualityScale {
    /// Unspecified 1, fix 1, float 3, SBAS 10, DGPS 10, single 30, PPP 2. RTKLIB's σ of a
    /// float or single solution is a formal precision that is typically optimistic by
    /// these factors against a fixed reference; tune per receiver.
    fn default() -> Self {
        QualityScale([1.0, 1.0, 3.0, 10.0, 10.0, 30.0, 2.0])
    }
}

impl QualityScale {
    /// σ multiplier for a quality flag; unknown flags get the "single" factor.
    pub fn factor(&self, q: u8) -> f64 {
        self.0
            .get(q as usize)
            .copied()
            .unwrap_or(self.0[quality::SINGLE as usize])
    }
}

/// Filter configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterConfig {
    /// IMU noise / sensor-error model.
    pub imu: ImuNoise,
    /// GNSS antenna lever arm from the IMU centre, body FRD, m.
    pub lever_arm_b_m: Vec3,
    /// Innovation gating of the GNSS updates and (unless an aid sets its own) of the
    /// vehicle aids ([`Gate`]). Default [`Gate::default`] (robust).
    pub gate: Gate,
    /// σ multipliers per RTKLIB quality flag.
    pub quality_scale: QualityScale,
    /// Use GNSS velocity (when present) as a second update.
    pub use_gnss_velocity: bool,
    /// Gate recovery: when no GNSS position fix has been accepted for longer than this
    /// many seconds — counting only time *outside* the outage windows `outages_s` — the
    /// next position fix is applied with [`Gate::Off`] and the reported σ (counted in
    /// `ForwardRun::gnss_forced`). Without it a transient that pushes every innovation
    /// past the gate (a diverged state after an IMU fault) makes every later fix look like
    /// an outlier and the filter never recovers. Isolated outliers (a single 50-m jump)
    /// are still rejected. `None` disables. Default 3 s.
    pub gate_recovery_s: Option<f64>,
    /// Gate recovery by count: after this many *consecutive* position fixes rejected
    /// grossly — rejected by the configured gate and also by the default robust gate at
    /// its ceiling ([`Gate::Robust`]: inconsistent even with the fix's σ inflated 100
    /// times; under the default gate every rejection is gross) — the next one is applied
    /// as under `gate_recovery_s` (whichever rule fires first). With fast GNSS (4–10 Hz)
    /// it acts before the time rule: K = 5 is 1.25 s at 4 Hz, against 3 s; with 1-Hz
    /// fixes the time rule comes first. A consistent filter rejects five fixes in a row
    /// with probability (1 − 0.9999)⁵ = 10⁻²⁰ under the default gate; the χ² gate's
    /// ordinary rejections (a fix a few σ off) do not count, so a run whose state never
    /// diverges is unchanged by this rule. It is not armed after an outage window or a
    /// gap in the fixes longer than `gate_recovery_s` until a fix is accepted (the drift
    /// of dead reckoning is expected there; the clock decides, as before this rule).
    /// `None` disables; `Some(0)` is refused.
    /// Default 5.
    pub gate_recovery_rejections: Option<usize>,
    /// GNSS outage windows (start, end], s: a fix at t is withheld when
    /// start < t ≤ end (the fix at `start` is used, the one at `end` is not; see
    /// [`crate::nav::outage`]).
    pub outages_s: Vec<(f64, f64)>,
    /// RTKLIB quality flags ([`crate::io::nav::quality`]: 1 fix, 2 float, 3 SBAS,
    /// 4 DGPS, 5 single, 6 PPP; 0 unspecified) of the fixes the filter uses; a fix with
    /// another flag is skipped and counted in `ForwardRun::gnss_quality_skipped`. Empty
    /// (default) accepts every flag.
    pub accept_quality: Vec<u8>,
    /// Largest accepted IMU interval as a multiple of the nominal (first) interval;
    /// longer gaps are an error. Default 2.5 (a gap of more than two samples).
    pub max_gap_factor: f64,
    /// Relative asymmetry tolerated in P before it is reported as corrupted.
    pub symmetry_tol: f64,
    /// Non-holonomic constraint ([`super::aids`]); `None` (default) disables it.
    pub nhc: Option<super::aids::NhcConfig>,
    /// Standstill detection with ZUPT / ZARU ([`super::aids`]); `None` (default)
    /// disables it.
    pub standstill: Option<super::aids::StandstillConfig>,
    /// σ_c of the gyro's axis coupling the filter has no state for — misalignment and
    /// cross-axis sensitivity, the off-diagonal elements of M in ω̃ = (I + diag(s_g) + M)ω
    /// — rad (1 % cross-axis = 0.01). It enters as rotation-driven attitude process noise
    /// (module docs, [`Transition::with_rotation_noise`]). Default 0 (off): on the
    /// simulated hand-held walk the fixes' σ floor alone makes the filter consistent, and
    /// on the tuned car drive the term on top of its ×10 white noise lengthens the outage
    /// errors; a noise model without such an allowance can set it from the data sheet's
    /// cross-axis sensitivity.
    pub gyro_coupling_sigma_rad: f64,
}

impl FilterConfig {
    /// A configuration with the given noise model and lever arm and defaults elsewhere.
    pub fn new(imu: ImuNoise, lever_arm_b_m: Vec3) -> FilterConfig {
        FilterConfig {
            imu,
            lever_arm_b_m,
            gate: Gate::default(),
            quality_scale: QualityScale::default(),
            use_gnss_velocity: false,
            gate_recovery_s: Some(3.0),
            gate_recovery_rejections: Some(5),
            outages_s: Vec::new(),
            accept_quality: Vec::new(),
            max_gap_factor: 2.5,
            symmetry_tol: 1e-9,
            nhc: None,
            standstill: None,
            gyro_coupling_sigma_rad: 0.0,
        }
    }

    /// Checks every value; a wrong unit typically shows as an absurd magnitude.
    pub fn validate(&self) -> Result<(), NavError> {
        let n = &self.imu;
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(NavError::Config(format!(
                    "{name} = {v} must be finite and ≥ 0"
                )))
            }
        };
        pos("gyro ARW (rad/√s)", n.gyro_arw_rad_sqrt_s)?;
        pos("accel VRW (m/s/√s)", n.accel_vrw_m_s_sqrt_s)?;
        if n.gyro_arw_rad_sqrt_s > 0.01 {
            return Err(NavError::Config(format!(
                "gyro ARW {} rad/√s = {:.0} °/√h is implausible: was it given in °/√h?",
                n.gyro_arw_rad_sqrt_s,
                n.gyro_arw_rad_sqrt_s.to_degrees() * 60.0
            )));
        }
        for (name, gm) in [
            ("gyro bias", n.gyro_bias),
            ("accel bias", n.accel_bias),
            ("gyro scale", n.gyro_scale),
            ("accel scale", n.accel_scale),
        ] {
            if !(gm.sigma.is_finite() && gm.sigma > 0.0 && gm.tau_s.is_finite() && gm.tau_s > 0.0) {
                return Err(NavError::Config(format!(
                    "{name}: Gauss–Markov σ = {} and T = {} s must be finite and > 0",
                    gm.sigma, gm.tau_s
                )));
            }
        }
        if n.gyro_bias.sigma > 0.1 {
            return Err(NavError::Config(format!(
                "gyro bias σ {} rad/s is implausible: was it given in °/h?",
                n.gyro_bias.sigma
            )));
        }
        if !self
            .lever_arm_b_m
            .iter()
            .all(|v| v.is_finite() && v.abs() < 100.0)
        {
            return Err(NavError::Config(format!(
                "lever arm {:?} m is not finite or longer than 100 m",
                self.lever_arm_b_m
            )));
        }
        self.gate.validate()?;
        let c = self.gyro_coupling_sigma_rad;
        if !(c.is_finite() && (0.0..=0.2).contains(&c)) {
            return Err(NavError::Config(format!(
                "gyro axis-coupling σ {c} rad must be finite and in [0, 0.2] \
                 (0.01 = 1 % cross-axis sensitivity)"
            )));
        }
        if let Some(r) = self.gate_recovery_s
            && !(r.is_finite() && r > 0.0)
        {
            return Err(NavError::Config(format!(
                "gate recovery time {r} s must be finite and > 0"
            )));
        }
        if self.gate_recovery_rejections == Some(0) {
            return Err(NavError::Config(
                "gate recovery after 0 rejected fixes would apply every fix ungated: give \
                 K ≥ 1, or none to disable the rule"
                    .into(),
            ));
        }
        if !self
            .quality_scale
            .0
            .iter()
            .all(|k| k.is_finite() && *k > 0.0)
        {
            return Err(NavError::Config("quality σ multipliers must be > 0".into()));
        }
        if !(self.max_gap_factor.is_finite() && self.max_gap_factor > 1.0) {
            return Err(NavError::Config("max_gap_factor must be > 1".into()));
        }
        for &(a, b) in &self.outages_s {
            if !(a.is_finite() && b.is_finite() && b >= a) {
                return Err(NavError::Config(format!(
                    "outage window ({a}, {b}] is invalid: start and end must be finite, \
                     end ≥ start"
                )));
            }
        }
        if let Some(n) = &self.nhc {
            n.validate()?;
        }
        if let Some(s) = &self.standstill {
            s.validate()?;
        }
        Ok(())
    }

    /// The stationary Gauss–Markov σ of the 12 sensor states (b_g, b_a, s_g, s_a, three
    /// each): the default initial uncertainty.
    pub(crate) fn stationary_sensor_sigma(&self) -> [f64; 12] {
        let n = &self.imu;
        let mut s = [0.0; 12];
        for k in 0..3 {
            s[k] = n.gyro_bias.sigma;
            s[3 + k] = n.accel_bias.sigma;
            s[6 + k] = n.gyro_scale.sigma;
            s[9 + k] = n.accel_scale.sigma;
        }
        s
    }

    /// Diagonal of the continuous process-noise PSD G Q Gᵀ (module docs).
    pub fn q_c_diag(&self) -> [f64; N_STATES] {
        let n = &self.imu;
        let mut q = [0.0; N_STATES];
        for k in 0..3 {
            q[VEL + k] = n.accel_vrw_m_s_sqrt_s * n.accel_vrw_m_s_sqrt_s;
            q[ATT + k] = n.gyro_arw_rad_sqrt_s * n.gyro_arw_rad_sqrt_s;
            q[BG + k] = n.gyro_bias.psd();
            q[BA + k] = n.accel_bias.psd();
            q[SG + k] = n.gyro_scale.psd();
            q[SA + k] = n.accel_scale.psd();
        }
        q
    }

    /// −1/T for the 12 sensor states (b_g, b_a, s_g, s_a, three each).
    pub fn neg_inv_tau(&self) -> [f64; 12] {
        let n = &self.imu;
        let mut r = [0.0; 12];
        for k in 0..3 {
            r[k] = -1.0 / n.gyro_bias.tau_s;
            r[3 + k] = -1.0 / n.accel_bias.tau_s;
            r[6 + k] = -1.0 / n.gyro_scale.tau_s;
            r[9 + k] = -1.0 / n.accel_scale.tau_s;
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::attitude::Quat;

    fn cfg() -> FilterConfig {
        let gm = |s| GaussMarkov {
            sigma: s,
            tau_s: 3600.0,
        };
        FilterConfig::new(
            ImuNoise {
                gyro_arw_rad_sqrt_s: 1e-4,
                accel_vrw_m_s_sqrt_s: 1e-3,
                gyro_bias: gm(1e-4),
                accel_bias: gm(1e-2),
                gyro_scale: gm(1e-3),
                accel_scale: gm(1e-3),
            },
            [0.0; 3],
        )
    }

    /// Noise model → filter noise: white noise, GM σ² = B² + K²T/2, worst axis.
    #[test]
    fn noise_from_allan_model() {
        use crate::allan::fit::{NoiseFit, Term};
        use crate::allan::noise_model::{ChannelNoise, NoiseModel, Quantity};
        let t = |v: f64| {
            Some(Term {
                value: v,
                lo: 0.9 * v,
                hi: 1.1 * v,
            })
        };
        let fit = |n: f64, b: f64, k: f64| NoiseFit {
            quantization: None,
            white: t(n),
            bias_instability: t(b),
            rate_random_walk: t(k),
            rate_ramp: None,
            gauss_markov: None,
            confidence: 0.683,
            rms_log10_residual: 0.0,
            not_detected: Vec::new(),
            chi2_reduced: 1.0,
            n_points: 10,
            fit_range: None,
            not_identifiable: Vec::new(),
        };
        let mut m = NoiseModel::new(None, 200.0, None);
        m.channels.push(ChannelNoise::new(
            "gx",
            Quantity::AngularRate,
            fit(1e-4, 1e-5, 1e-7),
            200.0,
        ));
        m.channels.push(ChannelNoise::new(
            "gy",
            Quantity::AngularRate,
            fit(2e-4, 1e-5, 1e-7),
            200.0,
        ));
        m.channels.push(ChannelNoise::new(
            "ax",
            Quantity::SpecificForce,
            fit(1e-3, 1e-4, 0.0),
            200.0,
        ));
        let sc = GaussMarkov {
            sigma: 1e-3,
            tau_s: 1e4,
        };
        let n = ImuNoise::from_noise_model(&m, 1000.0, sc, sc).expect("noise");
        assert_eq!(n.gyro_arw_rad_sqrt_s, 2e-4);
        assert_eq!(n.accel_vrw_m_s_sqrt_s, 1e-3);
        let want = (1e-10f64 + 1e-14 * 500.0).sqrt();
        assert!((n.gyro_bias.sigma - want).abs() < 1e-18 && n.gyro_bias.tau_s == 1000.0);
        assert!((n.accel_bias.sigma - 1e-4).abs() < 1e-18);
        m.channels.pop();
        assert!(matches!(
            ImuNoise::from_noise_model(&m, 1000.0, sc, sc),
            Err(NavError::Config(_))
        ));
    }

    /// The rotation-driven attitude noise: a yaw turn of a level body adds σ_c²|ω|Δt to
    /// the north and east tilt and nothing to yaw, in whatever heading (the whole of P
    /// changes by Φ(½Q_rotΔt)Φᵀ + ½Q_rotΔt); a roll about a body x axis pointing east adds
    /// to north tilt and yaw; σ_c = 0 or no rotation adds nothing.
    #[test]
    fn rotation_noise_is_across_the_rotation() {
        let c = cfg();
        let (sigma, dt) = (0.01, 0.01);
        let nav = |yaw: f64| NavState {
            time_s: 0.0,
            lat_rad: 0.5,
            lon_rad: 1.0,
            height_m: 100.0,
            vel_ned_m_s: [1.0, 0.0, 0.0],
            q_bn: Quat::from_rotation_vector([0.0, 0.0, yaw]),
        };
        let f = [0.0, 0.0, -9.8];
        let added = |yaw: f64, w: Vec3, s: f64| {
            let t = Transition::new(&nav(yaw), w, f, dt, &c.neg_inv_tau());
            let mut p0 = [[0.0; N_STATES]; N_STATES];
            for i in 0..N_STATES {
                p0[i][i] = 1e-4;
            }
            let mut plain = p0;
            t.propagate(&mut plain, &c.q_c_diag());
            let mut noisy = p0;
            t.with_rotation_noise(s)
                .propagate(&mut noisy, &c.q_c_diag());
            let mut d = [[0.0; N_STATES]; N_STATES];
            for i in 0..N_STATES {
                for j in 0..N_STATES {
                    d[i][j] = noisy[i][j] - plain[i][j];
                }
            }
            d
        };
        let yaw_rate = 0.5;
        for yaw in [0.0, 0.7, -2.5] {
            let w = [0.0, 0.0, yaw_rate];
            let d = added(yaw, w, sigma);
            // Expected: Φ(½Q_rot Δt)Φᵀ + ½Q_rot Δt with Q_rot = σ²|ω| diag(1, 1, 0) (NED).
            let want = sigma * sigma * yaw_rate * dt;
            let phi = Transition::new(&nav(yaw), w, f, dt, &c.neg_inv_tau()).phi_dense();
            for i in 0..N_STATES {
                for j in 0..N_STATES {
                    let mut e = (0..2)
                        .map(|k| 0.5 * want * phi[i][ATT + k] * phi[j][ATT + k])
                        .sum::<f64>();
                    if i == j && (ATT..ATT + 2).contains(&i) {
                        e += 0.5 * want;
                    }
                    assert!(
                        (d[i][j] - e).abs() < 1e-9 * want,
                        "yaw {yaw}: P[{i}][{j}] changed by {}, expected {e}",
                        d[i][j]
                    );
                }
            }
            assert!((d[ATT][ATT] - want).abs() < 1e-6 * want);
            assert!(d[ATT + 2][ATT + 2].abs() < 1e-6 * want);
        }
        // Body x east (yaw 90°), rolling: north tilt and yaw get the noise, east does not.
        let roll_rate = 0.2;
        let d = added(std::f64::consts::FRAC_PI_2, [roll_rate, 0.0, 0.0], sigma);
        let want = sigma * sigma * roll_rate * dt;
        assert!((d[ATT][ATT] - want).abs() < 1e-9 * want);
        assert!((d[ATT + 2][ATT + 2] - want).abs() < 1e-9 * want);
        assert!(d[ATT + 1][ATT + 1].abs() < 1e-9 * want);
        for (w, s) in [([0.0; 3], sigma), ([0.0, 0.0, yaw_rate], 0.0)] {
            let d = added(0.3, w, s);
            assert!(d.iter().flatten().all(|v| *v == 0.0));
        }
    }

    /// The sparse propagation equals the dense Φ(P + ½QΔt)Φᵀ + ½QΔt.
    #[test]
    fn sparse_propagation_matches_dense() {
        let c = cfg();
        let nav = NavState {
            time_s: 0.0,
            lat_rad: 0.5,
            lon_rad: 1.0,
            height_m: 100.0,
            vel_ned_m_s: [10.0, -5.0, 0.3],
            q_bn: Quat::from_rotation_vector([0.1, -0.2, 2.0]),
        };
        let t = Transition::new(
            &nav,
            [0.1, -0.05, 0.3],
            [1.0, 0.5, -9.7],
            0.005,
            &c.neg_inv_tau(),
        );
        let phi = t.phi_dense();
        let mut p = [[0.0; N_STATES]; N_STATES];
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                p[i][j] = 0.1 * ((i + j) as f64).cos() / (1.0 + (i as f64 - j as f64).abs());
            }
            p[i][i] += 2.0;
        }
        let q = c.q_c_diag();
        let mut pq = p;
        for i in 0..N_STATES {
            pq[i][i] += 0.0025 * q[i];
        }
        let mut dense = [[0.0; N_STATES]; N_STATES];
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                let mut s = 0.0;
                for k in 0..N_STATES {
                    for l in 0..N_STATES {
                        s += phi[i][k] * pq[k][l] * phi[j][l];
                    }
                }
                dense[i][j] = s + if i == j { 0.0025 * q[i] } else { 0.0 };
            }
        }
        t.propagate(&mut p, &q);
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                assert!((p[i][j] - dense[i][j]).abs() < 1e-13, "{i} {j}");
            }
        }
    }

    /// The previous propagation: zero coefficients of A skipped as found.
    fn propagate_skipping_zeros(t: &Transition, p: &mut Cov, q_c_diag: &[f64; N_STATES]) {
        let half = 0.5 * t.dt_s;
        for i in 0..N_STATES {
            p[i][i] += half * q_c_diag[i];
        }
        let a = t.nav_rows();
        let mut z = [[0.0; N_STATES]; 9];
        for i in 0..9 {
            let mut acc = p[i];
            for k in 0..N_STATES {
                if a[i][k] != 0.0 {
                    for c in 0..N_STATES {
                        acc[c] += a[i][k] * p[k][c];
                    }
                }
            }
            z[i] = acc;
        }
        for j in 0..9 {
            let mut acc: [f64; 9] = std::array::from_fn(|i| z[i][j]);
            for k in 0..N_STATES {
                if a[j][k] != 0.0 {
                    for c in 0..9 {
                        acc[c] += a[j][k] * z[c][k];
                    }
                }
            }
            for i in 0..=j {
                p[i][j] = acc[i];
                p[j][i] = acc[i];
            }
        }
        let e: [f64; 12] = std::array::from_fn(|s| 1.0 + t.sensor[s]);
        for i in 0..9 {
            for s in 0..12 {
                p[i][BG + s] = z[i][BG + s] * e[s];
                p[BG + s][i] = p[i][BG + s];
            }
        }
        for s in 0..12 {
            for u in s..12 {
                p[BG + s][BG + u] *= e[s] * e[u];
                p[BG + u][BG + s] = p[BG + s][BG + u];
            }
        }
        for i in 0..N_STATES {
            p[i][i] += half * q_c_diag[i];
        }
    }

    /// Over random states (with exact zeros in velocity, rates and specific force), the
    /// entries of A outside the fixed column lists are exactly zero, and the propagation
    /// (the AVX2 copy where the CPU has it, and the portable kernel) equals the
    /// zero-skipping one bit for bit.
    #[test]
    fn fixed_sparsity_propagation_is_bit_identical() {
        let c = cfg();
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for case in 0..400 {
            let zero_if = |x: f64, k: usize| if case % 4 == k { 0.0 } else { x };
            let nav = NavState {
                time_s: 0.0,
                lat_rad: 3.0 * next(),
                lon_rad: 6.0 * next(),
                height_m: 2000.0 * next(),
                vel_ned_m_s: [
                    zero_if(60.0 * next(), 0),
                    zero_if(60.0 * next(), 1),
                    zero_if(4.0 * next(), 0),
                ],
                q_bn: Quat::from_rotation_vector([6.0 * next(), 6.0 * next(), 6.0 * next()]),
            };
            let omega = [zero_if(next(), 2), next(), zero_if(next(), 1)];
            let f_b = [zero_if(4.0 * next(), 3), 4.0 * next(), -9.8 + next()];
            let t = Transition::new(
                &nav,
                omega,
                f_b,
                0.005 + 0.01 * next().abs(),
                &c.neg_inv_tau(),
            );
            let a = t.nav_rows();
            for (i, row) in a.iter().enumerate() {
                for (k, v) in row.iter().enumerate() {
                    if !NAV_ROW_COLS[i].contains(&k) {
                        assert_eq!(*v, 0.0, "case {case}: A[{i}][{k}] = {v:e}");
                    }
                }
                assert!(NAV_ROW_COLS[i].windows(2).all(|w| w[0] < w[1]));
            }
            let mut p = [[0.0; N_STATES]; N_STATES];
            for i in 0..N_STATES {
                for j in 0..=i {
                    let v = if i == j {
                        1.0 + next().abs()
                    } else {
                        0.05 * next()
                    };
                    p[i][j] = v;
                    p[j][i] = v;
                }
            }
            let q = c.q_c_diag();
            let mut reference = p;
            propagate_skipping_zeros(&t, &mut reference, &q);
            let mut fast = p;
            t.propagate(&mut fast, &q);
            let mut portable = p;
            t.propagate_portable(&mut portable, &q);
            for i in 0..N_STATES {
                for j in 0..N_STATES {
                    // Equal values (a zero may differ in sign only).
                    assert_eq!(fast[i][j], reference[i][j], "case {case}: P[{i}][{j}]");
                    assert_eq!(fast[i][j].to_bits(), portable[i][j].to_bits());
                }
            }
        }
    }
}

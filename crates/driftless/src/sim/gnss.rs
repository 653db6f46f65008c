//! Simulated GNSS fixes at the antenna of a known trajectory.
//!
//! At each epoch t_k = `start_s` + k/`rate_hz` (k ≥ 0, t_k ≤ `end_s`) outside the outage
//! windows, the antenna position is the IMU position moved by the lever arm l^b (body
//! frame, forward-right-down, from the IMU to the antenna phase centre):
//!
//! ```text
//! r_ant^n = r^n + C_bn l^b,   φ_a = φ + Δn/(R_M + h),  λ_a = λ + Δe/((R_N + h) cos φ),  h_a = h − Δd
//! v_ant^n = v^n + C_bn (ω_nb^b × l^b)
//! ```
//!
//! (Groves 2013, §14.2.1 — the loosely coupled measurement model of
//! [`crate::nav::filter`] inverted; the Earth-rate term of the antenna velocity,
//! |ω_ie × C_bn l| ≤ 7e-5 m/s per metre of lever arm, is left out as the filter leaves
//! it out.) Errors are white Gaussian per NED axis with the configured σ, optionally
//! plus a first-order Gauss–Markov error per axis (multipath-like, correlated over
//! `correlated_tau_s`) — the reported σ then covers both. Reproducible from `seed`.

use serde::{Deserialize, Serialize};

use super::ideal_imu::Trajectory;
use super::noise::SimError;
use super::rng::Rng;
use crate::io::nav::GnssFixes;
use crate::nav::earth;
use driftless_model::linalg::{Vec3, add, cross};

/// GNSS simulation settings (SI units; times on the trajectory's clock).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSimConfig {
    /// Fix rate, Hz.
    pub rate_hz: f64,
    /// First epoch, s.
    #[serde(default)]
    pub start_s: f64,
    /// Last epoch at or before this time, s.
    pub end_s: f64,
    /// White position error σ north, east, down, m.
    pub sigma_ned_m: Vec3,
    /// Correlated (first-order Gauss–Markov) position error σ per NED axis, m.
    #[serde(default)]
    pub correlated_sigma_ned_m: Vec3,
    /// Correlation time of that error, s.
    #[serde(default = "default_tau")]
    pub correlated_tau_s: f64,
    /// Also output NED velocity with this white σ per axis, m/s.
    #[serde(default)]
    pub velocity_sigma_ned_m_s: Option<Vec3>,
    /// Lever arm IMU → antenna in the body frame (forward, right, down), m.
    #[serde(default)]
    pub lever_arm_b_m: Vec3,
    /// RTKLIB quality flag of every fix ([`crate::io::nav::quality`]).
    #[serde(default = "default_quality")]
    pub quality: u8,
    /// Number of satellites reported.
    #[serde(default = "default_sats")]
    pub n_sats: u8,
    /// Windows (start, end] without fixes, s: no fix at start < t ≤ end (the convention
    /// of [`crate::nav::outage::OutageWindow`]).
    #[serde(default)]
    pub outages_s: Vec<(f64, f64)>,
    /// Added to every time stamp on output (e.g. GPS seconds of week at t = 0), s.
    #[serde(default)]
    pub time_offset_s: f64,
    /// GPS week of the output time stamps.
    #[serde(default)]
    pub gps_week: Option<u16>,
}

fn default_tau() -> f64 {
    60.0
}
fn default_quality() -> u8 {
    crate::io::nav::quality::FIX
}
fn default_sats() -> u8 {
    12
}

impl GnssSimConfig {
    /// `rate_hz` fixes from `start_s` to `end_s` with white σ `sigma_m` on every axis,
    /// RTK-fixed quality, no lever arm, no velocity.
    pub fn new(rate_hz: f64, start_s: f64, end_s: f64, sigma_m: f64) -> GnssSimConfig {
        GnssSimConfig {
            rate_hz,
            start_s,
            end_s,
            sigma_ned_m: [sigma_m; 3],
            correlated_sigma_ned_m: [0.0; 3],
            correlated_tau_s: default_tau(),
            velocity_sigma_ned_m_s: None,
            lever_arm_b_m: [0.0; 3],
            quality: default_quality(),
            n_sats: default_sats(),
            outages_s: Vec::new(),
            time_offset_s: 0.0,
            gps_week: None,
        }
    }

    /// Checks every value (rates and times finite and positive where needed, σ ≥ 0 with a
    /// positive total per axis, outage windows ordered).
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |name: &'static str, value: f64, why: &'static str| {
            Err(SimError::Invalid { name, value, why })
        };
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return bad(
                "gnss.rate_hz",
                self.rate_hz,
                "must be a positive number of Hz",
            );
        }
        if !self.start_s.is_finite() {
            return bad("gnss.start_s", self.start_s, "must be finite");
        }
        if !(self.end_s.is_finite() && self.end_s >= self.start_s) {
            return bad("gnss.end_s", self.end_s, "must be finite and ≥ start_s");
        }
        for k in 0..3 {
            let (w, c) = (self.sigma_ned_m[k], self.correlated_sigma_ned_m[k]);
            if !(w.is_finite() && w >= 0.0) {
                return bad("gnss.sigma_ned_m", w, "must be finite and ≥ 0");
            }
            if !(c.is_finite() && c >= 0.0) {
                return bad("gnss.correlated_sigma_ned_m", c, "must be finite and ≥ 0");
            }
            if w.hypot(c) <= 0.0 {
                return bad(
                    "gnss.sigma_ned_m",
                    w,
                    "the total σ of every axis must be > 0 (a filter cannot weigh a σ of 0)",
                );
            }
        }
        if !(self.correlated_tau_s.is_finite() && self.correlated_tau_s > 0.0) {
            return bad(
                "gnss.correlated_tau_s",
                self.correlated_tau_s,
                "must be > 0",
            );
        }
        if let Some(sv) = self.velocity_sigma_ned_m_s
            && let Some(&v) = sv.iter().find(|v| !(v.is_finite() && **v > 0.0))
        {
            return bad("gnss.velocity_sigma_ned_m_s", v, "must be finite and > 0");
        }
        if let Some(&v) = self.lever_arm_b_m.iter().find(|v| !v.is_finite()) {
            return bad("gnss.lever_arm_b_m", v, "must be finite");
        }
        if !self.time_offset_s.is_finite() {
            return bad("gnss.time_offset_s", self.time_offset_s, "must be finite");
        }
        for &(a, b) in &self.outages_s {
            if !(a.is_finite() && b.is_finite() && b > a) {
                return bad("gnss.outages_s", a, "each window needs finite start < end");
            }
        }
        Ok(())
    }
}

/// Simulated fixes of `traj` (module equations).
pub fn simulate_gnss<T: Trajectory + ?Sized>(
    traj: &T,
    cfg: &GnssSimConfig,
    seed: u64,
) -> Result<GnssFixes, SimError> {
    cfg.validate()?;
    let n = ((cfg.end_s - cfg.start_s) * cfg.rate_hz + 1e-9).floor() as usize + 1;
    let mut white = Rng::stream(seed, 0x6e55_0001);
    let mut corr_rng = Rng::stream(seed, 0x6e55_0002);
    let mut vel_rng = Rng::stream(seed, 0x6e55_0003);
    let dt = 1.0 / cfg.rate_hz;
    let phi = (-dt / cfg.correlated_tau_s).exp();
    let drive = (1.0 - phi * phi).sqrt();
    let mut corr: Vec3 = [0.0; 3];
    for (c, s) in corr.iter_mut().zip(cfg.correlated_sigma_ned_m) {
        *c = s * corr_rng.normal(); // stationary start
    }
    let sigma_total: Vec3 =
        std::array::from_fn(|k| cfg.sigma_ned_m[k].hypot(cfg.correlated_sigma_ned_m[k]));
    let mut g = GnssFixes {
        gps_week: cfg.gps_week,
        n_sats: Some(Vec::with_capacity(n)),
        ..GnssFixes::default()
    };
    let mut vel = Vec::new();
    for k in 0..n {
        let t = cfg.start_s + k as f64 * dt;
        // The correlated error evolves whether or not a fix is output.
        if k > 0 {
            for (c, s) in corr.iter_mut().zip(cfg.correlated_sigma_ned_m) {
                *c = phi * *c + s * drive * corr_rng.normal();
            }
        }
        let e: Vec3 = std::array::from_fn(|a| cfg.sigma_ned_m[a] * white.normal() + corr[a]);
        let ve: Vec3 = match cfg.velocity_sigma_ned_m_s {
            Some(s) => std::array::from_fn(|a| s[a] * vel_rng.normal()),
            None => [0.0; 3],
        };
        if cfg.outages_s.iter().any(|&(a, b)| t > a && t <= b) {
            continue;
        }
        let p = traj.point(t);
        let d = add(p.c_bn.mul_vec(cfg.lever_arm_b_m), e);
        let rm = earth::meridian_radius_m(p.lat_rad) + p.height_m;
        let rn = earth::prime_vertical_radius_m(p.lat_rad) + p.height_m;
        g.time_s.push(t + cfg.time_offset_s);
        g.lat_rad.push(p.lat_rad + d[0] / rm);
        g.lon_rad.push(p.lon_rad + d[1] / (rn * p.lat_rad.cos()));
        g.height_m.push(p.height_m - d[2]);
        g.sigma_ned_m.push(sigma_total);
        g.quality.push(cfg.quality);
        if let Some(ns) = g.n_sats.as_mut() {
            ns.push(cfg.n_sats);
        }
        if cfg.velocity_sigma_ned_m_s.is_some() {
            let lever_v = p.c_bn.mul_vec(cross(p.omega_nb_b_rad_s, cfg.lever_arm_b_m));
            vel.push(add(add(p.vel_ned_m_s, lever_v), ve));
        }
    }
    if let Some(s) = cfg.velocity_sigma_ned_m_s {
        g.sigma_vel_ned_m_s = Some(vec![s; vel.len()]);
        g.vel_ned_m_s = Some(vel);
    }
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ideal_imu::ConstantTurn;

    fn turn() -> ConstantTurn {
        ConstantTurn {
            lat_rad: 0.5,
            lon_rad: 2.0,
            height_m: 30.0,
            speed_m_s: 12.0,
            yaw0_rad: 0.2,
            yaw_rate_rad_s: 0.05,
            roll_rad: 0.0,
            pitch_rad: 0.0,
        }
    }

    #[test]
    fn noise_free_fixes_sit_at_the_antenna() {
        let traj = turn();
        let mut cfg = GnssSimConfig::new(2.0, 0.0, 30.0, 1e-300);
        cfg.lever_arm_b_m = [1.0, -0.5, -1.5];
        cfg.velocity_sigma_ned_m_s = Some([1e-300; 3]);
        cfg.outages_s = vec![(10.0, 12.0)];
        cfg.time_offset_s = 1000.0;
        let g = simulate_gnss(&traj, &cfg, 1).unwrap();
        // 61 epochs from 0 to 30 s at 2 Hz, minus 10.5, 11, …, 12 (4 of them: the window
        // (10, 12] keeps the fix at 10 s)
        assert_eq!(g.len(), 57);
        assert_eq!(g.time_s[0], 1000.0);
        for i in 0..g.len() {
            let t = g.time_s[i] - 1000.0;
            let p = traj.point(t);
            let want = p.c_bn.mul_vec(cfg.lever_arm_b_m);
            let got = earth::ned_offset_m(
                (p.lat_rad, p.lon_rad, p.height_m),
                (g.lat_rad[i], g.lon_rad[i], g.height_m[i]),
            );
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() < 1e-6,
                    "t {t}: {got:?} vs {want:?}"
                );
            }
            // antenna velocity by finite differences of the antenna position
            let h = 1e-3;
            let pos = |t: f64| {
                let q = traj.point(t);
                let d = q.c_bn.mul_vec(cfg.lever_arm_b_m);
                earth::ned_offset_m(
                    (p.lat_rad, p.lon_rad, p.height_m),
                    (q.lat_rad, q.lon_rad, q.height_m),
                )
                .iter()
                .zip(d)
                .map(|(a, b)| a + b)
                .collect::<Vec<_>>()
            };
            let (a, b) = (pos(t - h), pos(t + h));
            let v = g.vel_ned_m_s.as_ref().unwrap()[i];
            for k in 0..3 {
                let fd = (b[k] - a[k]) / (2.0 * h);
                assert!((v[k] - fd).abs() < 1e-4, "t {t}: v {v:?} fd {fd}");
            }
        }
    }

    #[test]
    fn noise_has_the_configured_sigma_and_is_reproducible() {
        let traj = turn();
        let mut cfg = GnssSimConfig::new(10.0, 0.0, 2000.0, 0.02);
        cfg.correlated_sigma_ned_m = [0.0, 0.03, 0.0];
        cfg.correlated_tau_s = 5.0;
        let g = simulate_gnss(&traj, &cfg, 7).unwrap();
        assert_eq!(g, simulate_gnss(&traj, &cfg, 7).unwrap());
        assert_ne!(g, simulate_gnss(&traj, &cfg, 8).unwrap());
        let mut ss = [0.0; 3];
        for i in 0..g.len() {
            let p = traj.point(g.time_s[i]);
            let e = earth::ned_offset_m(
                (p.lat_rad, p.lon_rad, p.height_m),
                (g.lat_rad[i], g.lon_rad[i], g.height_m[i]),
            );
            for k in 0..3 {
                ss[k] += e[k] * e[k];
            }
        }
        let n = g.len() as f64;
        let want = [0.02, 0.02f64.hypot(0.03), 0.02];
        for k in 0..3 {
            let s = (ss[k] / n).sqrt();
            // 20 001 samples: the white axes to ~1 %; the correlated one has ~400
            // independent blocks, so ~4 %
            assert!(
                (s / want[k] - 1.0).abs() < 0.1,
                "axis {k}: {s} vs {}",
                want[k]
            );
            assert!((g.sigma_ned_m[0][k] - want[k]).abs() < 1e-15);
        }
    }

    #[test]
    fn bad_settings_are_named() {
        let traj = turn();
        type Edit = fn(&mut GnssSimConfig);
        let cases: [(&str, Edit); 6] = [
            ("gnss.rate_hz", |c| c.rate_hz = 0.0),
            ("gnss.end_s", |c| c.end_s = -1.0),
            ("gnss.sigma_ned_m", |c| c.sigma_ned_m = [0.0; 3]),
            ("gnss.sigma_ned_m", |c| c.sigma_ned_m[1] = f64::NAN),
            ("gnss.correlated_tau_s", |c| c.correlated_tau_s = 0.0),
            ("gnss.outages_s", |c| c.outages_s = vec![(5.0, 4.0)]),
        ];
        for (name, f) in cases {
            let mut cfg = GnssSimConfig::new(1.0, 0.0, 10.0, 0.02);
            f(&mut cfg);
            let e = simulate_gnss(&traj, &cfg, 1).unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }
}

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
//! plus a first-order Gauss–Markov error per axis (multipath-like, or the motion of a
//! hand-held antenna relative to the IMU-carried point, correlated over
//! `correlated_tau_s`): x_k = φx_{k−1} + σ√(1 − φ²)·w_k, φ = exp(−Δt/τ), started from its
//! stationary distribution, so Var x_k = σ² and E x_k x_{k+m} = σ²φ^m.
//!
//! The σ written with each fix is by default the true total σ per axis,
//! √(σ_white² + σ_corr²). Real receivers report a *formal* σ that ignores such errors
//! (a u-blox RTK fixed solution reports ~1 cm whatever the antenna does):
//! `reported_sigma_ned_m` writes that σ instead, while the error stays as configured.
//!
//! [`DegradedWindow`]s model stretches of worse solutions, e.g. RTK float: inside a
//! window the fixes carry its quality flag (default float, 2), its reported σ, and an
//! extra first-order Gauss–Markov error of its own σ and τ (stationary at the window's
//! first epoch, independent between windows) on top of the errors above — the float
//! ambiguities' slowly wandering decimetre-level offset. Reproducible from `seed`.

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
    /// σ written with every fix outside the degraded windows (the receiver's formal σ),
    /// north, east, down, m; `None` writes the true total σ (module documentation).
    #[serde(default)]
    pub reported_sigma_ned_m: Option<Vec3>,
    /// Windows of degraded solutions (RTK float …), ordered and not overlapping.
    #[serde(default)]
    pub degraded_windows: Vec<DegradedWindow>,
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

/// A stretch of degraded fixes (module documentation), times on the trajectory's clock
/// (inclusive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DegradedWindow {
    /// First time in the window, s.
    pub start_s: f64,
    /// Last time in the window, s.
    pub end_s: f64,
    /// RTKLIB quality flag of its fixes (default float, 2).
    #[serde(default = "default_degraded_quality")]
    pub quality: u8,
    /// Extra first-order Gauss–Markov error σ per NED axis, m.
    pub sigma_ned_m: Vec3,
    /// Its correlation time, s.
    pub tau_s: f64,
    /// σ written with its fixes, north, east, down, m.
    pub reported_sigma_ned_m: Vec3,
}

fn default_degraded_quality() -> u8 {
    crate::io::nav::quality::FLOAT
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
            reported_sigma_ned_m: None,
            degraded_windows: Vec::new(),
            outages_s: Vec::new(),
            time_offset_s: 0.0,
            gps_week: None,
        }
    }

    /// Checks every value (rates and times finite and positive where needed, σ ≥ 0 with a
    /// positive total per axis, reported σ > 0, outage windows ordered, degraded windows
    /// ordered and disjoint).
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
        let positive3 =
            |name: &'static str, v: &Vec3| match v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                Some(&x) => bad(name, x, "must be finite and > 0 on every axis"),
                None => Ok(()),
            };
        if let Some(r) = &self.reported_sigma_ned_m {
            positive3("gnss.reported_sigma_ned_m", r)?;
        }
        let mut last_end = f64::NEG_INFINITY;
        for w in &self.degraded_windows {
            if !(w.start_s.is_finite() && w.end_s.is_finite() && w.end_s > w.start_s) {
                return bad(
                    "gnss.degraded_windows.start_s",
                    w.start_s,
                    "each window needs finite start_s < end_s",
                );
            }
            if w.start_s <= last_end {
                return bad(
                    "gnss.degraded_windows.start_s",
                    w.start_s,
                    "windows must be in time order and must not overlap",
                );
            }
            last_end = w.end_s;
            if let Some(&x) = w
                .sigma_ned_m
                .iter()
                .find(|x| !(x.is_finite() && **x >= 0.0))
            {
                return bad(
                    "gnss.degraded_windows.sigma_ned_m",
                    x,
                    "must be finite and ≥ 0",
                );
            }
            if !(w.tau_s.is_finite() && w.tau_s > 0.0) {
                return bad("gnss.degraded_windows.tau_s", w.tau_s, "must be > 0");
            }
            positive3(
                "gnss.degraded_windows.reported_sigma_ned_m",
                &w.reported_sigma_ned_m,
            )?;
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
    let sigma_total: Vec3 = cfg.reported_sigma_ned_m.unwrap_or_else(|| {
        std::array::from_fn(|k| cfg.sigma_ned_m[k].hypot(cfg.correlated_sigma_ned_m[k]))
    });
    // Degraded windows: index of the window of the previous epoch and its error.
    let mut deg_rng = Rng::stream(seed, 0x6e55_0004);
    let mut deg: Option<(usize, Vec3)> = None;
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
        let mut e: Vec3 = std::array::from_fn(|a| cfg.sigma_ned_m[a] * white.normal() + corr[a]);
        let window = cfg
            .degraded_windows
            .iter()
            .position(|w| t >= w.start_s && t <= w.end_s);
        deg = window.map(|i| {
            let w = &cfg.degraded_windows[i];
            let x: Vec3 = match deg {
                Some((j, x)) if j == i => {
                    let phi = (-dt / w.tau_s).exp();
                    let drive = (1.0 - phi * phi).sqrt();
                    std::array::from_fn(|a| {
                        phi * x[a] + w.sigma_ned_m[a] * drive * deg_rng.normal()
                    })
                }
                _ => std::array::from_fn(|a| w.sigma_ned_m[a] * deg_rng.normal()),
            };
            (i, x)
        });
        if let Some((_, x)) = deg {
            e = add(e, x);
        }
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
        match window {
            Some(i) => {
                let w = &cfg.degraded_windows[i];
                g.sigma_ned_m.push(w.reported_sigma_ned_m);
                g.quality.push(w.quality);
            }
            None => {
                g.sigma_ned_m.push(sigma_total);
                g.quality.push(cfg.quality);
            }
        }
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

    /// A receiver's formal σ (1 cm) is written while the true error is the configured
    /// 0.25-m antenna motion (lag-τ autocorrelation e⁻¹); inside a degraded window the
    /// fixes carry the float flag, its σ, and the extra error.
    #[test]
    fn reported_sigma_and_degraded_windows() {
        let traj = turn();
        let mut cfg = GnssSimConfig::new(4.0, 0.0, 4000.0, 0.005);
        cfg.correlated_sigma_ned_m = [0.25, 0.25, 0.1];
        cfg.correlated_tau_s = 3.0;
        cfg.reported_sigma_ned_m = Some([0.01, 0.01, 0.02]);
        cfg.degraded_windows = vec![DegradedWindow {
            start_s: 2000.0,
            end_s: 3000.0,
            quality: crate::io::nav::quality::FLOAT,
            sigma_ned_m: [0.4, 0.4, 0.8],
            tau_s: 5.0,
            reported_sigma_ned_m: [0.2, 0.2, 0.4],
        }];
        let g = simulate_gnss(&traj, &cfg, 11).unwrap();
        let err = |i: usize| {
            let p = traj.point(g.time_s[i]);
            earth::ned_offset_m(
                (p.lat_rad, p.lon_rad, p.height_m),
                (g.lat_rad[i], g.lon_rad[i], g.height_m[i]),
            )
        };
        let inside = |t: f64| (2000.0..=3000.0).contains(&t);
        let (mut ss_out, mut ss_in, mut n_out, mut n_in) = ([0.0; 3], [0.0; 3], 0.0, 0.0);
        let lag = 12; // τ = 3 s at 4 Hz
        let (mut c0, mut c1) = (0.0, 0.0);
        for i in 0..g.len() {
            let e = err(i);
            let t = g.time_s[i];
            if inside(t) {
                assert_eq!(g.quality[i], crate::io::nav::quality::FLOAT);
                assert_eq!(g.sigma_ned_m[i], [0.2, 0.2, 0.4]);
                (0..3).for_each(|k| ss_in[k] += e[k] * e[k]);
                n_in += 1.0;
            } else {
                assert_eq!(g.quality[i], crate::io::nav::quality::FIX);
                assert_eq!(g.sigma_ned_m[i], [0.01, 0.01, 0.02]);
                (0..3).for_each(|k| ss_out[k] += e[k] * e[k]);
                n_out += 1.0;
                if i + lag < g.len() && !inside(g.time_s[i + lag]) {
                    c0 += e[0] * e[0];
                    c1 += e[0] * err(i + lag)[0];
                }
            }
        }
        assert_eq!(n_in, 4001.0);
        let want_out = [0.25, 0.25, 0.1].map(|c: f64| c.hypot(0.005));
        let want_in: Vec<f64> = [0.4, 0.4, 0.8]
            .iter()
            .zip(want_out)
            .map(|(d, o): (&f64, f64)| d.hypot(o))
            .collect();
        for k in 0..3 {
            // ≈ 1000 (outside) and 200 (inside) correlation times: a few % and ≈ 7 %.
            let (o, i) = ((ss_out[k] / n_out).sqrt(), (ss_in[k] / n_in).sqrt());
            assert!((o / want_out[k] - 1.0).abs() < 0.1, "axis {k}: {o}");
            assert!((i / want_in[k] - 1.0).abs() < 0.2, "axis {k}: {i}");
        }
        let rho = c1 / c0;
        assert!(
            (rho - (-1.0f64).exp()).abs() < 0.1,
            "lag-τ autocorrelation {rho}"
        );
    }

    #[test]
    fn bad_settings_are_named() {
        let traj = turn();
        type Edit = fn(&mut GnssSimConfig);
        fn deg(c: &mut GnssSimConfig, a: f64, b: f64) {
            c.degraded_windows.push(DegradedWindow {
                start_s: a,
                end_s: b,
                quality: 2,
                sigma_ned_m: [0.3; 3],
                tau_s: 10.0,
                reported_sigma_ned_m: [0.1; 3],
            })
        }
        let cases: [(&str, Edit); 11] = [
            ("gnss.reported_sigma_ned_m", |c| {
                c.reported_sigma_ned_m = Some([0.01, 0.0, 0.01])
            }),
            ("gnss.degraded_windows.start_s", |c| {
                deg(c, 2.0, 5.0);
                deg(c, 4.0, 6.0)
            }),
            ("gnss.degraded_windows.start_s", |c| deg(c, 5.0, 5.0)),
            ("gnss.degraded_windows.tau_s", |c| {
                deg(c, 2.0, 5.0);
                c.degraded_windows[0].tau_s = 0.0
            }),
            ("gnss.degraded_windows.reported_sigma_ned_m", |c| {
                deg(c, 2.0, 5.0);
                c.degraded_windows[0].reported_sigma_ned_m[2] = f64::NAN
            }),
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

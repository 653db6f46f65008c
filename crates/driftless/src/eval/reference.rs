//! Reference trajectories as [`NavSolution`] columns: validation, interpolation to
//! another trajectory's epochs, and construction from RTK fixes or a simulation's truth.
//!
//! # Rules for a trajectory
//!
//! At least two epochs; every column as long as `time_s`; times finite and strictly
//! increasing; latitude, longitude, height and NED velocity finite. Roll, pitch and yaw
//! may be NaN where they are **unknown** (a reference built from GNSS fixes has no
//! heading while the vehicle stands still); heading errors are then not reported.
//!
//! # Interpolation
//!
//! [`interpolate`] takes the reference at time t linearly between the two bracketing
//! epochs t₀ ≤ t < t₁ with weight a = (t − t₀)/(t₁ − t₀): latitude, height and velocity
//! by plain linear interpolation, longitude and yaw through their wrapped difference
//! (so a track crossing ±180° of longitude or a heading crossing ±180° interpolates the
//! short way). At an epoch of the reference (a = 0) the sample itself is returned,
//! bit for bit. Linear interpolation of a position sampled at Δt has an error of at most
//! |a_max|·Δt²/8 (|a_max| the largest acceleration): 2 cm at 4 Hz and 5 m/s², 0.6 m at
//! 1 Hz — sample the reference at least as densely as the accuracy asked for.
//! Across a reference gap longer than `max_gap_s` nothing is interpolated (`None`).

use crate::io::nav::{GnssFixes, NavSolution};
use crate::nav::attitude::Euler;
use crate::nav::earth::ned_offset_m;
use crate::nav::mechanization::NavState;
use crate::sim::ideal_imu::Trajectory;
use driftless_model::linalg::Vec3;

use super::EvalError;

/// Wraps an angle to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let r = a - two_pi * (a / two_pi).round();
    if r <= -std::f64::consts::PI {
        r + two_pi
    } else {
        r
    }
}

/// The reference at one instant (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferencePoint {
    /// Geodetic latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// NED velocity, m/s.
    pub vel_ned_m_s: Vec3,
    /// Yaw (heading), rad in (−π, π]; `None` where unknown.
    pub yaw_rad: Option<f64>,
}

/// Checks a trajectory against the rules of the module docs; `which` names it in the
/// error (`"reference"`, `"solution"`).
pub fn validate(t: &NavSolution, which: &'static str) -> Result<(), EvalError> {
    let bad = |reason: String| EvalError::BadTrajectory { which, reason };
    let n = t.time_s.len();
    if n < 2 {
        return Err(bad(format!("{n} epoch(s): at least 2 are needed")));
    }
    for (name, len) in [
        ("lat_rad", t.lat_rad.len()),
        ("lon_rad", t.lon_rad.len()),
        ("height_m", t.height_m.len()),
        ("vel_ned_m_s", t.vel_ned_m_s.len()),
        ("roll_pitch_yaw_rad", t.roll_pitch_yaw_rad.len()),
    ] {
        if len != n {
            return Err(bad(format!("column {name} has {len} rows, time_s has {n}")));
        }
    }
    for k in 0..n {
        let finite = [t.time_s[k], t.lat_rad[k], t.lon_rad[k], t.height_m[k]]
            .iter()
            .chain(t.vel_ned_m_s[k].iter())
            .all(|x| x.is_finite());
        if !finite {
            return Err(bad(format!(
                "epoch {k} (t = {} s): non-finite time, position or velocity",
                t.time_s[k]
            )));
        }
        if k > 0 && t.time_s[k] <= t.time_s[k - 1] {
            return Err(bad(format!(
                "time not strictly increasing at epoch {k}: {} s after {} s",
                t.time_s[k],
                t.time_s[k - 1]
            )));
        }
    }
    Ok(())
}

/// The reference at `time_s` (module docs), `None` outside it or across a gap longer
/// than `max_gap_s`. The trajectory is assumed valid ([`validate`]).
pub fn interpolate(r: &NavSolution, time_s: f64, max_gap_s: f64) -> Option<ReferencePoint> {
    let t = &r.time_s;
    let j = t.partition_point(|&x| x <= time_s);
    if j == 0 {
        return None;
    }
    let i = j - 1;
    if t[i] == time_s || j == t.len() {
        return (t[i] == time_s).then(|| sample(r, i));
    }
    let (t0, t1) = (t[i], t[j]);
    if t1 - t0 > max_gap_s {
        return None;
    }
    let a = (time_s - t0) / (t1 - t0);
    let lerp = |x0: f64, x1: f64| x0 + a * (x1 - x0);
    let (v0, v1) = (r.vel_ned_m_s[i], r.vel_ned_m_s[j]);
    let (y0, y1) = (r.roll_pitch_yaw_rad[i][2], r.roll_pitch_yaw_rad[j][2]);
    let yaw = (y0.is_finite() && y1.is_finite()).then(|| wrap_pi(y0 + a * wrap_pi(y1 - y0)));
    Some(ReferencePoint {
        lat_rad: lerp(r.lat_rad[i], r.lat_rad[j]),
        lon_rad: wrap_pi(r.lon_rad[i] + a * wrap_pi(r.lon_rad[j] - r.lon_rad[i])),
        height_m: lerp(r.height_m[i], r.height_m[j]),
        vel_ned_m_s: [lerp(v0[0], v1[0]), lerp(v0[1], v1[1]), lerp(v0[2], v1[2])],
        yaw_rad: yaw,
    })
}

fn sample(r: &NavSolution, k: usize) -> ReferencePoint {
    let y = r.roll_pitch_yaw_rad[k][2];
    ReferencePoint {
        lat_rad: r.lat_rad[k],
        lon_rad: r.lon_rad[k],
        height_m: r.height_m[k],
        vel_ned_m_s: r.vel_ned_m_s[k],
        yaw_rad: y.is_finite().then_some(y),
    }
}

/// Samples a simulated truth trajectory at `times_s` (e.g. the solution's epochs, which
/// makes [`interpolate`] exact). Attitude: the Euler angles of the body frame's C_bn
/// (for an IMU mounted with a yaw offset on the vehicle this is the body's yaw, not the
/// vehicle's heading).
pub fn sample_trajectory<T: Trajectory + ?Sized>(traj: &T, times_s: &[f64]) -> NavSolution {
    let mut s = NavSolution::default();
    for &t in times_s {
        let p = traj.point(t);
        let e = Euler::from_dcm(&p.c_bn);
        s.push_epoch(
            t,
            p.lat_rad,
            p.lon_rad,
            p.height_m,
            p.vel_ned_m_s,
            [e.roll_rad, e.pitch_rad, e.yaw_rad],
        );
    }
    s
}

/// A filter's or smoother's states as a trajectory to score (IMU centre; Euler angles
/// of q_bn): `from_nav_states(run.epochs.iter().map(|e| &e.nav))` for a forward run,
/// the same over `SmoothedRun::epochs` for the smoothed one.
pub fn from_nav_states<'a>(states: impl IntoIterator<Item = &'a NavState>) -> NavSolution {
    let mut s = NavSolution::default();
    for n in states {
        let e = Euler::from_dcm(&n.q_bn.to_dcm());
        s.push_epoch(
            n.time_s,
            n.lat_rad,
            n.lon_rad,
            n.height_m,
            n.vel_ned_m_s,
            [e.roll_rad, e.pitch_rad, e.yaw_rad],
        );
    }
    s
}

/// Horizontal speed below which a fix-derived reference has no heading, m/s: with RTK
/// velocity noise of ~2 cm/s the course over ground is good to ≈ 1° at 1 m/s.
pub(crate) const COURSE_MIN_SPEED_M_S: f64 = 1.0;

/// A reference trajectory from GNSS fixes (RTK, as on `drive_0708`, where the fixes are
/// the only reference). Velocity: the fixes' own velocity, or else the central difference
/// of the neighbouring fixes (one-sided at the ends; a neighbour more than 2.5 s away is
/// not used). Attitude of a land vehicle without side slip: roll 0, pitch the flight-path
/// angle atan2(−v_D, v_H), yaw the course over ground atan2(v_E, v_N) — NaN (unknown)
/// below `COURSE_MIN_SPEED_M_S`. The positions are those of the antenna: score
/// solutions at the antenna too.
pub fn reference_from_fixes(g: &GnssFixes) -> Result<NavSolution, EvalError> {
    let n = g.time_s.len();
    let bad = |reason: String| EvalError::BadTrajectory {
        which: "reference",
        reason,
    };
    if n < 2 {
        return Err(bad(format!("{n} GNSS fix(es): at least 2 are needed")));
    }
    if g.lat_rad.len() != n || g.lon_rad.len() != n || g.height_m.len() != n {
        return Err(bad("GNSS position columns differ in length".into()));
    }
    let pos = |k: usize| (g.lat_rad[k], g.lon_rad[k], g.height_m[k]);
    let mut out = NavSolution::default();
    for k in 0..n {
        let v = match g.vel_ned_m_s.as_ref().and_then(|v| v.get(k)) {
            Some(v) => *v,
            None => {
                let near = |j: usize| (g.time_s[j] - g.time_s[k]).abs() <= 2.5;
                let a = if k > 0 && near(k - 1) { k - 1 } else { k };
                let b = if k + 1 < n && near(k + 1) { k + 1 } else { k };
                let dt = g.time_s[b] - g.time_s[a];
                if b > a && dt > 0.0 {
                    let d = ned_offset_m(pos(a), pos(b));
                    [d[0] / dt, d[1] / dt, d[2] / dt]
                } else {
                    [0.0; 3]
                }
            }
        };
        let vh = v[0].hypot(v[1]);
        let (pitch, yaw) = if vh >= COURSE_MIN_SPEED_M_S {
            ((-v[2]).atan2(vh), v[1].atan2(v[0]))
        } else {
            (f64::NAN, f64::NAN)
        };
        out.time_s.push(g.time_s[k]);
        out.lat_rad.push(g.lat_rad[k]);
        out.lon_rad.push(g.lon_rad[k]);
        out.height_m.push(g.height_m[k]);
        out.vel_ned_m_s.push(v);
        out.roll_pitch_yaw_rad.push([0.0, pitch, yaw]);
    }
    validate(&out, "reference")?;
    Ok(out)
}

/// Median epoch interval of a time column, s (0 for fewer than two epochs).
pub fn median_interval_s(time_s: &[f64]) -> f64 {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line() -> NavSolution {
        // 1 Hz, moving north-east at constant rates in latitude/longitude.
        let mut s = NavSolution::default();
        for k in 0..5 {
            let t = 100.0 + k as f64;
            s.time_s.push(t);
            s.lat_rad.push(0.5 + 1e-6 * k as f64);
            s.lon_rad
                .push(std::f64::consts::PI - 2e-6 + 1e-6 * k as f64);
            s.height_m.push(10.0 + 0.5 * k as f64);
            s.vel_ned_m_s.push([6.0, 4.0, -0.5]);
            s.roll_pitch_yaw_rad
                .push([0.0, 0.0, (179.0 + k as f64).to_radians()]);
        }
        s
    }

    #[test]
    fn interpolation_is_linear_wraps_and_returns_samples_exactly() {
        let s = line();
        validate(&s, "reference").unwrap();
        // At a sample: bit-exact.
        let p = interpolate(&s, 102.0, 2.0).unwrap();
        assert_eq!(p.lat_rad, s.lat_rad[2]);
        assert_eq!(p.height_m, s.height_m[2]);
        // Between samples: linear (exact for these linear columns).
        let p = interpolate(&s, 101.25, 2.0).unwrap();
        assert!((p.lat_rad - (0.5 + 1.25e-6)).abs() < 1e-15);
        assert!((p.height_m - 10.625).abs() < 1e-12);
        // Longitude crosses +π between epochs 2 and 3 (π − 2e-6 + 2e-6 = π, then past):
        let p = interpolate(&s, 102.5, 2.0).unwrap();
        assert!((wrap_pi(p.lon_rad - (std::f64::consts::PI + 0.5e-6))).abs() < 1e-12);
        // Yaw 180° → 181° (= −179°): the midpoint is 180.5°, i.e. −179.5°, not 0.5°.
        let p = interpolate(&s, 101.5, 2.0).unwrap();
        let y = p.yaw_rad.unwrap().to_degrees();
        assert!((y - (-179.5)).abs() < 1e-9, "{y}");
        // Outside and across a gap: nothing.
        assert!(interpolate(&s, 99.9, 2.0).is_none());
        assert!(interpolate(&s, 104.1, 2.0).is_none());
        assert!(interpolate(&s, 104.0, 2.0).is_some());
        assert!(interpolate(&s, 100.5, 0.5).is_none());
        // Unknown yaw at one end: no heading, the rest is interpolated.
        let mut u = s.clone();
        u.roll_pitch_yaw_rad[1][2] = f64::NAN;
        let p = interpolate(&u, 100.5, 2.0).unwrap();
        assert!(p.yaw_rad.is_none() && p.lat_rad.is_finite());
    }

    #[test]
    fn wrap_is_half_open() {
        use std::f64::consts::PI;
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap_pi(-7.0 * PI / 2.0) - PI / 2.0).abs() < 1e-14);
    }

    #[test]
    fn bad_trajectories_are_named() {
        let mut s = line();
        s.time_s[3] = s.time_s[2];
        let e = validate(&s, "reference").unwrap_err().to_string();
        assert!(e.contains("reference") && e.contains("epoch 3"), "{e}");
        let mut s = line();
        s.height_m.pop();
        let e = validate(&s, "solution").unwrap_err().to_string();
        assert!(e.contains("solution") && e.contains("height_m"), "{e}");
        let mut s = line();
        s.lat_rad[1] = f64::NAN;
        assert!(validate(&s, "reference").is_err());
        assert!(validate(&NavSolution::default(), "reference").is_err());
    }

    #[test]
    fn fixes_give_course_and_no_heading_at_standstill() {
        let mut g = GnssFixes::default();
        for k in 0..6 {
            let moving = k >= 3;
            g.time_s.push(k as f64);
            // 3 m/s east once moving: Δλ = 3 m / (R_N cos φ) per second.
            let rn = crate::nav::earth::prime_vertical_radius_m(0.7);
            let e = if moving { 3.0 * (k - 3) as f64 } else { 0.0 };
            g.lat_rad.push(0.7);
            g.lon_rad.push(0.1 + e / (rn * 0.7f64.cos()));
            g.height_m.push(5.0);
            g.sigma_ned_m.push([0.01, 0.01, 0.02]);
            g.quality.push(1);
        }
        let r = reference_from_fixes(&g).unwrap();
        assert!(r.roll_pitch_yaw_rad[0][2].is_nan());
        let v = r.vel_ned_m_s[4];
        // (R_N + h)/R_N = 1 + 8e-7 between the test's spacing and the velocity.
        assert!((v[1] - 3.0).abs() < 1e-5 && v[0].abs() < 1e-6, "{v:?}");
        assert!((r.roll_pitch_yaw_rad[4][2].to_degrees() - 90.0).abs() < 1e-6);
    }
}

//! A smooth trajectory through recorded positions (e.g. 1 Hz RTK fixes of a real
//! vehicle), usable as exact truth for ideal IMU increments ([`super::ideal_imu`]).
//!
//! **Position.** The fixes (tᵢ, φᵢ, λᵢ, hᵢ) are mapped to the scaled local coordinates
//! (n, e, d) of [`super::ideal_imu`]'s local origin (placed at the first fix):
//! n = (φ − φ₀)(R_M(φ₀) + h₀), e = (λ − λ₀)(R_N(φ₀) + h₀)cos φ₀, d = h₀ − h, the exact
//! inverse of the map the analytic trajectories use. Each coordinate is fitted by a
//! quintic smoothing spline on uniform knots (Reinsch 1967; de Boor 2001, *A Practical
//! Guide to Splines*; penalty λ∫(s‴)² dt, see the private `spline` module): position is
//! C⁴, acceleration C², the jerk continuous, so the Gauss–Legendre quadrature of the
//! ideal increments stays accurate across knots. The velocity v^n and its derivative
//! v̇^n are then the exact derivatives on the ellipsoid (radius-derivative terms
//! included). The smoothing is set by a half-gain frequency f_c (λ = 1/(Δ(2πf_c)⁶), Δ the
//! mean fix spacing): the spline passes signal well below f_c and removes fix noise
//! above it.
//!
//! **Attitude.** The vehicle frame (forward, right, down) follows the velocity
//! direction (Groves 2013, §2.2 and §5.4 for the kinematics): samples every h/2 (h the
//! knot spacing) of
//!
//! * yaw ψ = atan2(v_E, v_N) (course over ground),
//! * pitch θ = atan2(−v_D, √(v_N² + v_E²)) (flight-path angle),
//! * roll φ = 0, or atan(a_lat/g) for a coordinated turn, a_lat = (v_N v̇_E − v_E v̇_N)/V_h,
//!
//! taken from the position spline wherever the speed exceeds a hold threshold; below it
//! (standstills, where the course is undefined and the yaw rate of atan2 would blow up)
//! yaw and pitch hold their last moving value (the first moving value before the first
//! move), roll is 0. Yaw is unwrapped, and the three angles are fitted by their own
//! quintic smoothing spline, so attitude is a smooth (C⁴) function of time that follows
//! the velocity direction when moving and turns smoothly where a stop's held heading
//! differs from the next course. C_vn = R_z(ψ)R_y(θ)R_x(φ) and the body rate is the
//! exact z-y-x Euler-rate relation (Titterton & Weston 2004, §3.6):
//!
//! ω_nv^v = (φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, ψ̇ cos φ cos θ − θ̇ sin φ).
//!
//! An optional IMU mounting C_vb gives C_bn = C_vn C_vb and ω_nb^b = C_vbᵀ ω_nv^v.
//!
//! The trajectory is therefore its own truth: position, velocity, acceleration,
//! attitude and body rate returned by [`Trajectory::point`] are mutually exact
//! derivatives; the distance to the recorded fixes and the heading-vs-course deviation
//! are reported in [`FitReport`]. Outside [first fix, last fix] the end polynomials are
//! continued: fine for a few IMU samples, not for long extrapolation.

use driftless_model::linalg::{Mat3, Vec3};

use super::ideal_imu::{LocalOrigin, Trajectory, TrajectoryPoint};
use super::noise::SimError;
use super::spline::{QuinticSpline, lambda_for_cutoff};
use crate::io::nav::GnssFixes;
use crate::nav::earth;

/// Fewest fixes accepted.
pub(crate) const MIN_POINTS: usize = 6;

/// Roll model of a [`RecordedTrajectory`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RollModel {
    /// Zero roll (a car on a level-cross-section road).
    #[default]
    Zero,
    /// Coordinated turn, φ = atan(a_lat/g): the apparent gravity stays in the body x–z
    /// plane (aircraft-like; a car body rolls the other way, by less).
    CoordinatedTurn,
}

/// Options of [`RecordedTrajectory::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordedOptions {
    /// Knot spacing h of the splines, s (> 0). Default 0.5 s.
    pub knot_spacing_s: f64,
    /// Half-gain frequency of the position smoother, Hz (> 0). Default 0.5 Hz (the
    /// Nyquist frequency of 1 Hz fixes: RTK fixes are followed to a few mm; lower it for
    /// noisier positions).
    pub position_cutoff_hz: f64,
    /// Half-gain frequency of the attitude smoother, Hz (> 0). Default 1 Hz (yaw follows
    /// the course to ≈ 0.1° on the Wuhan drive).
    pub attitude_cutoff_hz: f64,
    /// Below this speed yaw and pitch hold their last value, m/s (≥ 0). Default 0.5 m/s.
    pub hold_speed_m_s: f64,
    /// Roll model. Default [`RollModel::Zero`].
    pub roll: RollModel,
    /// IMU mounting, x_v = C_vb x_b. Default identity.
    pub c_vb: Mat3,
}

impl Default for RecordedOptions {
    fn default() -> RecordedOptions {
        RecordedOptions {
            knot_spacing_s: 0.5,
            position_cutoff_hz: 0.5,
            attitude_cutoff_hz: 1.0,
            hold_speed_m_s: 0.5,
            roll: RollModel::Zero,
            c_vb: Mat3::IDENTITY,
        }
    }
}

/// How closely the smooth trajectory follows the recording.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FitReport {
    /// RMS horizontal distance between the trajectory and the fixes, m.
    pub horizontal_rms_m: f64,
    /// Largest horizontal distance, m.
    pub horizontal_max_m: f64,
    /// RMS vertical difference, m.
    pub vertical_rms_m: f64,
    /// Largest vertical difference, m.
    pub vertical_max_m: f64,
    /// RMS of yaw − course over the attitude samples faster than 2 × the hold speed, rad.
    pub yaw_course_rms_rad: f64,
    /// Largest |yaw − course| over those samples, rad.
    pub yaw_course_max_rad: f64,
    /// Fraction of the attitude samples below the hold speed (standstill), 0..1.
    pub held_fraction: f64,
}

/// A smooth trajectory through recorded positions (module documentation).
#[derive(Clone, Debug)]
pub struct RecordedTrajectory {
    origin: LocalOrigin,
    /// Local (n, e, d), m.
    pos: QuinticSpline<3>,
    /// (roll, pitch, yaw), rad (yaw unwrapped).
    att: QuinticSpline<3>,
    c_vb: Option<Mat3>,
    /// Roll identically zero ([`RollModel::Zero`]): its trigonometry is skipped.
    roll_zero: bool,
    start_s: f64,
    end_s: f64,
    fit: FitReport,
}

fn bad(why: String) -> SimError {
    SimError::Recorded { why }
}

/// Checks the fixes (module constraints) and the options.
fn validate(
    time_s: &[f64],
    lat_rad: &[f64],
    lon_rad: &[f64],
    height_m: &[f64],
    o: &RecordedOptions,
) -> Result<(), SimError> {
    let n = time_s.len();
    if lat_rad.len() != n || lon_rad.len() != n || height_m.len() != n {
        return Err(bad(format!(
            "column lengths differ: time {n}, lat {}, lon {}, height {}",
            lat_rad.len(),
            lon_rad.len(),
            height_m.len()
        )));
    }
    if n < MIN_POINTS {
        return Err(bad(format!(
            "{n} positions, at least {MIN_POINTS} are needed"
        )));
    }
    for i in 0..n {
        let vals = [
            ("time_s", time_s[i]),
            ("lat_rad", lat_rad[i]),
            ("lon_rad", lon_rad[i]),
            ("height_m", height_m[i]),
        ];
        if let Some((name, v)) = vals.iter().find(|(_, v)| !v.is_finite()) {
            return Err(bad(format!("{name}[{i}] = {v} is not finite")));
        }
        if lat_rad[i].abs() >= 0.5 * std::f64::consts::PI {
            return Err(bad(format!(
                "lat_rad[{i}] = {} outside (−π/2, π/2)",
                lat_rad[i]
            )));
        }
        if i > 0 && time_s[i] <= time_s[i - 1] {
            return Err(bad(format!(
                "time_s[{i}] = {} is not after time_s[{}] = {}",
                time_s[i],
                i - 1,
                time_s[i - 1]
            )));
        }
    }
    let checks = [
        ("knot_spacing_s", o.knot_spacing_s, true),
        ("position_cutoff_hz", o.position_cutoff_hz, true),
        ("attitude_cutoff_hz", o.attitude_cutoff_hz, true),
        ("hold_speed_m_s", o.hold_speed_m_s, false),
    ];
    for (name, v, strict) in checks {
        if !v.is_finite() || v < 0.0 || (strict && v == 0.0) {
            return Err(bad(format!(
                "option {name} = {v} must be finite and {}",
                if strict { "> 0" } else { ">= 0" }
            )));
        }
    }
    Ok(())
}

/// Wraps an angle to (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    let r = a - tau * (a / tau).round();
    if r <= -std::f64::consts::PI {
        r + tau
    } else {
        r
    }
}

/// Attitude samples (module documentation): `(roll, pitch, yaw)` at `times`, from the
/// position spline; also the fraction held.
fn attitude_samples(
    origin: &LocalOrigin,
    pos: &QuinticSpline<3>,
    times: &[f64],
    o: &RecordedOptions,
) -> (Vec<[f64; 3]>, f64) {
    // Raw (yaw, pitch) where moving, None where held.
    let mut raw: Vec<Option<(f64, f64)>> = Vec::with_capacity(times.len());
    let mut roll = Vec::with_capacity(times.len());
    for &t in times {
        let (p, v, a) = pos.eval2(t);
        let pt = origin.point(p, v, a, Mat3::IDENTITY, [0.0; 3]);
        let [vn, ve, vd] = pt.vel_ned_m_s;
        let vh = vn.hypot(ve);
        if vh > o.hold_speed_m_s {
            raw.push(Some((ve.atan2(vn), (-vd).atan2(vh))));
            roll.push(match o.roll {
                RollModel::Zero => 0.0,
                RollModel::CoordinatedTurn => {
                    let [an, ae, _] = pt.acc_ned_m_s2;
                    let g = earth::normal_gravity_m_s2(pt.lat_rad, pt.height_m);
                    ((vn * ae - ve * an) / vh / g).atan()
                }
            });
        } else {
            raw.push(None);
            roll.push(0.0);
        }
    }
    let held = raw.iter().filter(|r| r.is_none()).count();
    let first = raw.iter().flatten().next().copied().unwrap_or((0.0, 0.0));
    let mut out = Vec::with_capacity(times.len());
    let (mut yaw, mut pitch) = first;
    for (r, roll) in raw.iter().zip(roll) {
        if let Some((y, p)) = *r {
            yaw += wrap_pi(y - yaw);
            pitch = p;
        }
        out.push([roll, pitch, yaw]);
    }
    (out, held as f64 / times.len().max(1) as f64)
}

impl RecordedTrajectory {
    /// Fits the trajectory to fixes at `time_s` (strictly increasing, ≥ `MIN_POINTS`)
    /// with geodetic `lat_rad`, `lon_rad`, `height_m` (all finite, |φ| < 90°). The
    /// trajectory's time axis is `time_s`'s.
    pub fn new(
        time_s: &[f64],
        lat_rad: &[f64],
        lon_rad: &[f64],
        height_m: &[f64],
        opts: &RecordedOptions,
    ) -> Result<RecordedTrajectory, SimError> {
        validate(time_s, lat_rad, lon_rad, height_m, opts)?;
        let n = time_s.len();
        let (start_s, end_s) = (time_s[0], time_s[n - 1]);
        let origin = LocalOrigin::new(lat_rad[0], lon_rad[0], height_m[0]);
        let local: Vec<Vec3> = (0..n)
            .map(|i| origin.local_of(lat_rad[i], lon_rad[i], height_m[i]))
            .collect();
        let h = opts.knot_spacing_s;
        let span = end_s - start_s;
        let n_int = ((span / h - 1e-9).ceil() as usize).max(1);
        let spacing = span / (n - 1) as f64;
        let lam = lambda_for_cutoff(opts.position_cutoff_hz, spacing);
        let pos = QuinticSpline::fit(time_s, &local, start_s, h, n_int, lam)
            .ok_or_else(|| bad("position fit: normal equations not positive definite".into()))?;

        let att_times: Vec<f64> = (0..=2 * n_int)
            .map(|j| (start_s + 0.5 * h * j as f64).min(end_s))
            .collect();
        let (att_samples, held_fraction) = attitude_samples(&origin, &pos, &att_times, opts);
        let lam_att = lambda_for_cutoff(opts.attitude_cutoff_hz, 0.5 * h);
        let att = QuinticSpline::fit(&att_times, &att_samples, start_s, h, n_int, lam_att)
            .ok_or_else(|| bad("attitude fit: normal equations not positive definite".into()))?;
        let c_vb = (opts.c_vb != Mat3::IDENTITY).then_some(opts.c_vb);
        let mut traj = RecordedTrajectory {
            origin,
            pos,
            att,
            c_vb,
            roll_zero: opts.roll == RollModel::Zero,
            start_s,
            end_s,
            fit: FitReport {
                held_fraction,
                ..FitReport::default()
            },
        };
        traj.fit = traj.fit_report(time_s, lat_rad, lon_rad, height_m, &att_times, opts);
        Ok(traj)
    }

    /// [`RecordedTrajectory::new`] from GNSS fixes (e.g. from
    /// [`crate::io::nav::read_kfgins_gnss_file`]); velocities and σ are not used.
    pub fn from_fixes(
        fixes: &GnssFixes,
        opts: &RecordedOptions,
    ) -> Result<RecordedTrajectory, SimError> {
        RecordedTrajectory::new(
            &fixes.time_s,
            &fixes.lat_rad,
            &fixes.lon_rad,
            &fixes.height_m,
            opts,
        )
    }

    /// Time of the first fix, s.
    pub fn start_s(&self) -> f64 {
        self.start_s
    }

    /// Time of the last fix, s.
    pub fn end_s(&self) -> f64 {
        self.end_s
    }

    /// Distances to the fixes and heading-vs-course deviation.
    pub fn fit(&self) -> &FitReport {
        &self.fit
    }

    fn fit_report(
        &self,
        time_s: &[f64],
        lat_rad: &[f64],
        lon_rad: &[f64],
        height_m: &[f64],
        att_times: &[f64],
        o: &RecordedOptions,
    ) -> FitReport {
        let mut r = self.fit;
        let (mut sh, mut sv) = (0.0, 0.0);
        for i in 0..time_s.len() {
            let p = self.point(time_s[i]);
            let d = earth::ned_offset_m(
                (lat_rad[i], lon_rad[i], height_m[i]),
                (p.lat_rad, p.lon_rad, p.height_m),
            );
            let dh = d[0].hypot(d[1]);
            sh += dh * dh;
            sv += d[2] * d[2];
            r.horizontal_max_m = r.horizontal_max_m.max(dh);
            r.vertical_max_m = r.vertical_max_m.max(d[2].abs());
        }
        let n = time_s.len() as f64;
        r.horizontal_rms_m = (sh / n).sqrt();
        r.vertical_rms_m = (sv / n).sqrt();
        let (mut sy, mut ny) = (0.0, 0usize);
        for &t in att_times {
            let (p, v, a) = self.pos.eval2(t);
            let pt = self.origin.point(p, v, a, Mat3::IDENTITY, [0.0; 3]);
            let [vn, ve, _] = pt.vel_ned_m_s;
            if vn.hypot(ve) > 2.0 * o.hold_speed_m_s {
                let yaw = self.att.eval1(t).0[2];
                let e = wrap_pi(yaw - ve.atan2(vn));
                sy += e * e;
                ny += 1;
                r.yaw_course_max_rad = r.yaw_course_max_rad.max(e.abs());
            }
        }
        r.yaw_course_rms_rad = if ny > 0 { (sy / ny as f64).sqrt() } else { 0.0 };
        r
    }
}

impl Trajectory for RecordedTrajectory {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let (p, v, a) = self.pos.eval2(t_s);
        let ([roll, pitch, yaw], [roll_d, pitch_d, yaw_d]) = self.att.eval1(t_s);
        let (sr, cr) = if self.roll_zero {
            (0.0, 1.0)
        } else {
            roll.sin_cos()
        };
        let (sp, cp) = pitch.sin_cos();
        let (sy, cy) = yaw.sin_cos();
        // C_vn = R_z(ψ)R_y(θ)R_x(φ) (as `Euler::to_dcm`, trigonometry shared).
        let c_vn = Mat3([
            [cp * cy, -cr * sy + sr * sp * cy, sr * sy + cr * sp * cy],
            [cp * sy, cr * cy + sr * sp * sy, -sr * cy + cr * sp * sy],
            [-sp, sr * cp, cr * cp],
        ]);
        let omega_nv_v = [
            roll_d - yaw_d * sp,
            pitch_d * cr + yaw_d * sr * cp,
            yaw_d * cr * cp - pitch_d * sr,
        ];
        let (c_bn, omega_nb_b) = match &self.c_vb {
            None => (c_vn, omega_nv_v),
            Some(c_vb) => (c_vn.mul_mat(c_vb), c_vb.t().mul_vec(omega_nv_v)),
        };
        self.origin.point(p, v, a, c_bn, omega_nb_b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::attitude::Euler;
    use crate::sim::ideal_imu::FiniteDifference;
    use driftless_model::units::DEG;

    const LAT0: f64 = 30.5 * DEG;
    const LON0: f64 = 114.4 * DEG;
    const H0: f64 = 20.0;

    /// A smooth synthetic drive in local metres: a stop, a loop with speed changes and
    /// a gentle hill, another stop. Returns (t, n, e, d).
    fn synthetic_path(t: f64) -> Vec3 {
        // Distance along the path with stops at both ends: s(t) smooth, ṡ = 0 for
        // t ≤ 20 s and t ≥ 220 s, peak speed ≈ 12 m/s.
        let s = |t: f64| {
            let x = ((t - 20.0) / 200.0).clamp(0.0, 1.0);
            // 7th-degree smoothstep (ṡ, s̈, s⃛ zero at both ends).
            let p = x * x * x * x * (35.0 - 84.0 * x + 70.0 * x * x - 20.0 * x * x * x);
            1400.0 * p
        };
        let d = s(t);
        let r = 150.0;
        let ang = d / r;
        [
            r * ang.sin() + 0.02 * d,
            r * (1.0 - ang.cos()),
            -3.0 * (1.0 - (d / 700.0 * std::f64::consts::PI).cos()),
        ]
    }

    fn synthetic(opts: &RecordedOptions, step_s: f64) -> (RecordedTrajectory, Vec<f64>) {
        let origin = LocalOrigin::new(LAT0, LON0, H0);
        let times: Vec<f64> = (0..)
            .map(|i| 1000.0 + i as f64 * step_s)
            .take_while(|&t| t <= 1240.0 + 1e-9)
            .collect();
        let (mut lat, mut lon, mut h) = (vec![], vec![], vec![]);
        for &t in &times {
            let p = synthetic_path(t - 1000.0);
            let pt = origin.point(p, [0.0; 3], [0.0; 3], Mat3::IDENTITY, [0.0; 3]);
            lat.push(pt.lat_rad);
            lon.push(pt.lon_rad);
            h.push(pt.height_m);
        }
        (
            RecordedTrajectory::new(&times, &lat, &lon, &h, opts).expect("valid input"),
            times,
        )
    }

    /// Analytic v̇^n and ω_nb^b agree with finite differences of the trajectory's own
    /// position/velocity/attitude (also with a coordinated-turn roll and a mounting),
    /// and finite differences of position reproduce the velocity.
    #[test]
    fn analytic_derivatives_match_finite_differences() {
        for roll in [RollModel::Zero, RollModel::CoordinatedTurn] {
            let opts = RecordedOptions {
                roll,
                c_vb: Euler {
                    roll_rad: 2.0 * DEG,
                    pitch_rad: -3.0 * DEG,
                    yaw_rad: 5.0 * DEG,
                }
                .to_dcm(),
                ..RecordedOptions::default()
            };
            let (traj, _) = synthetic(&opts, 1.0);
            let fd = FiniteDifference {
                state: |t: f64| {
                    let p = traj.point(t);
                    (p.lat_rad, p.lon_rad, p.height_m, p.vel_ned_m_s, p.c_bn)
                },
                step_s: 1e-3,
            };
            // Inside knot intervals, at a knot, at a stop, near the ends.
            for t in [
                1000.01, 1010.0, 1021.3, 1050.25, 1100.5, 1177.77, 1230.0, 1239.9,
            ] {
                let (a, b) = (traj.point(t), fd.point(t));
                for k in 0..3 {
                    assert!(
                        (a.acc_ned_m_s2[k] - b.acc_ned_m_s2[k]).abs() < 1e-7,
                        "{roll:?} t {t} acc {k}: {:?} {:?}",
                        a.acc_ned_m_s2,
                        b.acc_ned_m_s2
                    );
                    assert!(
                        (a.omega_nb_b_rad_s[k] - b.omega_nb_b_rad_s[k]).abs() < 1e-9,
                        "{roll:?} t {t} ω {k}: {:?} {:?}",
                        a.omega_nb_b_rad_s,
                        b.omega_nb_b_rad_s
                    );
                }
                let d = 1e-3;
                let (p1, m1) = (traj.point(t + d), traj.point(t - d));
                let rm = earth::meridian_radius_m(a.lat_rad) + a.height_m;
                let rn = earth::prime_vertical_radius_m(a.lat_rad) + a.height_m;
                let vn = (p1.lat_rad - m1.lat_rad) / (2.0 * d) * rm;
                let ve = (p1.lon_rad - m1.lon_rad) / (2.0 * d) * rn * a.lat_rad.cos();
                let vd = -(p1.height_m - m1.height_m) / (2.0 * d);
                for (k, v) in [vn, ve, vd].into_iter().enumerate() {
                    assert!((v - a.vel_ned_m_s[k]).abs() < 1e-5, "t {t} vel {k}");
                }
            }
        }
    }

    /// Smooth input: the fit stays within millimetres (1 Hz) of the path, heading follows
    /// the course when moving and is held (finite, steady) during the stops.
    #[test]
    fn fit_follows_a_smooth_path() {
        let opts = RecordedOptions::default();
        let (traj, _) = synthetic(&opts, 1.0);
        let f = traj.fit();
        assert!(f.horizontal_rms_m < 0.005, "{f:?}");
        assert!(f.horizontal_max_m < 1e-3, "{f:?}");
        assert!(f.vertical_max_m < 0.005, "{f:?}");
        assert!(f.yaw_course_max_rad < 0.5 * DEG, "{f:?}");
        assert!(f.held_fraction > 0.15 && f.held_fraction < 0.4, "{f:?}");
        // Between fixes too.
        let origin = LocalOrigin::new(LAT0, LON0, H0);
        for k in 0..480 {
            let t = 1000.25 + 0.5 * k as f64;
            let p = traj.point(t);
            let truth = origin.point(
                synthetic_path(t - 1000.0),
                [0.0; 3],
                [0.0; 3],
                Mat3::IDENTITY,
                [0.0; 3],
            );
            let d = earth::ned_offset_m(
                (truth.lat_rad, truth.lon_rad, truth.height_m),
                (p.lat_rad, p.lon_rad, p.height_m),
            );
            assert!(
                d[0].hypot(d[1]) < 0.02 && d[2].abs() < 0.005,
                "t {t}: {d:?}"
            );
        }
        // Stops: speed ≈ 0, yaw steady.
        for t in [1002.0, 1010.0, 1235.0] {
            let p = traj.point(t);
            let v = p.vel_ned_m_s;
            assert!(v.iter().all(|x| x.abs() < 0.01), "t {t}: {v:?}");
            assert!(p.omega_nb_b_rad_s.iter().all(|x| x.abs() < 1e-3), "t {t}");
        }
        // At cruise, the body x axis is along the velocity.
        let p = traj.point(1120.0);
        let v_b = p.c_bn.t().mul_vec(p.vel_ned_m_s);
        assert!(v_b[0] > 5.0 && v_b[1].abs() < 0.01 * v_b[0] && v_b[2].abs() < 0.01 * v_b[0]);
    }

    /// Noisy fixes (1 cm white per axis, as RTK) smoothed with f_c = 0.2 Hz: the
    /// trajectory is closer to the noise-free path than the fixes are.
    #[test]
    fn fit_smooths_fix_noise() {
        let origin = LocalOrigin::new(LAT0, LON0, H0);
        let mut rng = crate::sim::rng::Rng::seed_from_u64(7);
        let times: Vec<f64> = (0..=240).map(|i| i as f64).collect();
        let (mut lat, mut lon, mut h) = (vec![], vec![], vec![]);
        for &t in &times {
            let mut p = synthetic_path(t);
            for x in &mut p {
                *x += 0.01 * rng.normal();
            }
            let pt = origin.point(p, [0.0; 3], [0.0; 3], Mat3::IDENTITY, [0.0; 3]);
            lat.push(pt.lat_rad);
            lon.push(pt.lon_rad);
            h.push(pt.height_m);
        }
        // A cutoff well below the 0.5-Hz Nyquist frequency of 1 Hz fixes.
        let opts = RecordedOptions {
            position_cutoff_hz: 0.2,
            ..RecordedOptions::default()
        };
        let traj = RecordedTrajectory::new(&times, &lat, &lon, &h, &opts).unwrap();
        let mut se = 0.0;
        for &t in &times {
            let p = traj.point(t);
            let truth = origin.point(
                synthetic_path(t),
                [0.0; 3],
                [0.0; 3],
                Mat3::IDENTITY,
                [0.0; 3],
            );
            let d = earth::ned_offset_m(
                (truth.lat_rad, truth.lon_rad, truth.height_m),
                (p.lat_rad, p.lon_rad, p.height_m),
            );
            se += d[0] * d[0] + d[1] * d[1];
        }
        let rms_truth = (se / times.len() as f64).sqrt();
        let f = traj.fit();
        eprintln!("1 cm noise, f_c 0.2 Hz: fit {f:?}, horizontal RMS to the truth {rms_truth} m");
        // 1 Hz white noise of 1.41 cm horizontal RMS; the smoother passes the share
        // ∫H² df/0.5 Hz ≈ 0.36 of its power: ≈ 0.85 cm remains in the trajectory and the
        // residual to the fixes is ≈ 1.1 cm.
        assert!(
            f.horizontal_rms_m > 0.009 && f.horizontal_rms_m < 0.013,
            "{f:?}"
        );
        assert!(rms_truth < 0.0105, "{rms_truth}");
        // Stops: held heading, no spinning.
        assert!(traj.point(5.0).omega_nb_b_rad_s[2].abs() < 0.02);
    }

    #[test]
    fn invalid_input_is_rejected() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let lat = [0.5; 7];
        let lon = [2.0; 7];
        let h = [10.0; 7];
        let o = RecordedOptions::default();
        let err = |r: Result<RecordedTrajectory, SimError>| match r {
            Err(SimError::Recorded { why }) => why,
            other => panic!("expected an error, got {other:?}"),
        };
        assert!(RecordedTrajectory::new(&t, &lat, &lon, &h, &o).is_ok());
        assert!(
            err(RecordedTrajectory::new(
                &t[..5],
                &lat[..5],
                &lon[..5],
                &h[..5],
                &o
            ))
            .contains("at least 6")
        );
        assert!(err(RecordedTrajectory::new(&t, &lat[..6], &lon, &h, &o)).contains("lengths"));
        let mut t2 = t;
        t2[3] = 2.0;
        assert!(err(RecordedTrajectory::new(&t2, &lat, &lon, &h, &o)).contains("time_s[3]"));
        let mut h2 = h;
        h2[4] = f64::NAN;
        assert!(err(RecordedTrajectory::new(&t, &lat, &lon, &h2, &o)).contains("height_m[4]"));
        let mut lat2 = lat;
        lat2[1] = 2.0;
        assert!(err(RecordedTrajectory::new(&t, &lat2, &lon, &h, &o)).contains("lat_rad[1]"));
        let o2 = RecordedOptions {
            knot_spacing_s: 0.0,
            ..o
        };
        assert!(err(RecordedTrajectory::new(&t, &lat, &lon, &h, &o2)).contains("knot_spacing_s"));
        let o3 = RecordedOptions {
            hold_speed_m_s: f64::NAN,
            ..o
        };
        assert!(err(RecordedTrajectory::new(&t, &lat, &lon, &h, &o3)).contains("hold_speed_m_s"));
    }
}

//! Error-free IMU increments along a known trajectory, exactly consistent with the physics
//! of [`crate::nav::mechanization`] (same WGS-84 radii, normal gravity, Earth rate and
//! transport rate), so that a mechanization started from the true state must reproduce
//! the trajectory up to its own algorithmic and rounding errors.
//!
//! For a trajectory t ↦ (φ, λ, h, v^n, C_bn) with time derivatives v̇^n and ω_nb^b, the
//! ideal sensor outputs are (Groves 2013, §5.4; Shin 2005, ch. 2):
//!
//! * ω_ib^b = ω_nb^b + C_nb(ω_ie^n + ω_en^n),
//! * f^n = v̇^n + (2ω_ie^n + ω_en^n) × v^n − g^n,  f^b = C_nb f^n,
//!
//! and the increments over (t_{k−1}, t_k] are Δθ = ∫ω_ib^b dt and Δv = ∫f^b dt, the plain
//! integrals in the rotating body frame (what a strapdown IMU's increments are),
//! evaluated by 6-node Gauss–Legendre quadrature (exact for polynomials of degree 11;
//! for the smooth analytic trajectories here the quadrature error is far below f64
//! rounding at 200 Hz). Where a trajectory's acceleration or body rate jumps (joins of
//! closed-form pieces, [`Trajectory::next_break_s`]) the rule is applied on each side.
//! [`ideal_increments_par`] spreads the epochs over threads (rayon).
//!
//! Trajectories through recorded positions are in [`super::recorded`]; land-vehicle
//! drives described in TOML in [`super::profile`].
//!
//! Analytic trajectories ([`Stationary`], [`ConstantTurn`], [`StraightRun`], [`LandVehicle`]) are defined
//! by a path in *scaled local coordinates* (n, e, d)(t) about an origin (φ₀, λ₀, h₀):
//! φ = φ₀ + n/(R_M(φ₀) + h₀), λ = λ₀ + e/((R_N(φ₀) + h₀)cos φ₀), h = h₀ − d. Position is
//! then exact by definition and the NED velocity and its derivative are the exact time
//! derivatives on the ellipsoid:
//! v_N = (R_M(φ) + h)φ̇, v_E = (R_N(φ) + h)cos φ·λ̇, v_D = −ḣ, differentiated once more
//! with dR_M/dφ = 3a(1 − e²)e² sin φ cos φ/W^{5/2}, dR_N/dφ = a e² sin φ cos φ/W^{3/2},
//! W = 1 − e² sin²φ. Near the origin (n, e, d) are metres north/east/down; far from it
//! the speed differs from |(ṅ, ė, ḋ)| by the relative change of R + h (≈ 1.6e-7 per
//! metre of climb, ≈ 1e-6 over a few km at mid latitudes), which does not affect the
//! consistency of truth and increments.

use driftless_model::linalg::{Mat3, Vec3, add, cross, scale, sub};

use crate::nav::attitude::{Euler, Quat};
use crate::nav::earth;
use crate::nav::mechanization::{ImuIncrement, NavState};

mod land_vehicle;
pub use land_vehicle::*;

/// The full kinematic state of a trajectory at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrajectoryPoint {
    /// Geodetic latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// NED velocity relative to the Earth, m/s.
    pub vel_ned_m_s: Vec3,
    /// Time derivative of the NED velocity components, v̇^n, m/s².
    pub acc_ned_m_s2: Vec3,
    /// Body → NED DCM.
    pub c_bn: Mat3,
    /// Body rate relative to NED resolved in body axes, ω_nb^b (Ċ_bn = C_bn[ω_nb^b×]), rad/s.
    pub omega_nb_b_rad_s: Vec3,
}

impl TrajectoryPoint {
    /// The navigation state at time `time_s` of this point.
    pub fn nav_state(&self, time_s: f64) -> NavState {
        NavState {
            time_s,
            lat_rad: self.lat_rad,
            lon_rad: self.lon_rad,
            height_m: self.height_m,
            vel_ned_m_s: self.vel_ned_m_s,
            q_bn: Quat::from_dcm(&self.c_bn),
        }
    }

    /// Ideal sensor outputs (ω_ib^b rad/s, f^b m/s²) at this point (module equations).
    ///
    /// The Earth model is that of [`crate::nav::earth`] (`earth_rate_ned`,
    /// `transport_rate_ned`, `gravity_ned`), evaluated here with one sin/cos of the
    /// latitude shared by all terms (the same formulas; results agree to rounding).
    #[inline]
    pub fn imu_rates(&self) -> (Vec3, Vec3) {
        let (s, c) = self.lat_rad.sin_cos();
        let s2 = s * s;
        let w = 1.0 - earth::E2 * s2;
        let sw = w.sqrt();
        let rm = earth::A_M * (1.0 - earth::E2) / (w * sw) + self.height_m;
        let rn = earth::A_M / sw + self.height_m;
        let v = self.vel_ned_m_s;
        let w_ie = [earth::OMEGA_IE * c, 0.0, -earth::OMEGA_IE * s];
        let w_en = [v[1] / rn, -v[0] / rm, -v[1] * (s / c) / rn];
        let c_nb = self.c_bn.t();
        let omega_ib_b = add(self.omega_nb_b_rad_s, c_nb.mul_vec(add(w_ie, w_en)));
        let m =
            earth::OMEGA_IE * earth::OMEGA_IE * earth::A_M * earth::A_M * earth::B_M / earth::GM;
        let h = self.height_m;
        let g0 = earth::GAMMA_E * (1.0 + earth::SOMIGLIANA_K * s2) / sw;
        let g = g0
            * (1.0 - 2.0 / earth::A_M * (1.0 + earth::F + m - 2.0 * earth::F * s2) * h
                + 3.0 / (earth::A_M * earth::A_M) * h * h);
        let cor = cross(add(scale(w_ie, 2.0), w_en), v);
        let f_n = sub(add(self.acc_ned_m_s2, cor), [0.0, 0.0, g]);
        (omega_ib_b, c_nb.mul_vec(f_n))
    }

    /// [`TrajectoryPoint::imu_rates`] with the `earth` functions themselves (tests).
    #[cfg(test)]
    fn imu_rates_reference(&self) -> (Vec3, Vec3) {
        let w_ie = earth::earth_rate_ned(self.lat_rad);
        let w_en = earth::transport_rate_ned(self.lat_rad, self.height_m, self.vel_ned_m_s);
        let c_nb = self.c_bn.t();
        let omega_ib_b = add(self.omega_nb_b_rad_s, c_nb.mul_vec(add(w_ie, w_en)));
        let g = earth::gravity_ned(self.lat_rad, self.height_m);
        let cor = cross(add(scale(w_ie, 2.0), w_en), self.vel_ned_m_s);
        let f_n = sub(add(self.acc_ned_m_s2, cor), g);
        (omega_ib_b, c_nb.mul_vec(f_n))
    }
}

/// A trajectory: its kinematic state at any time.
pub trait Trajectory {
    /// State at `t_s`.
    fn point(&self, t_s: f64) -> TrajectoryPoint;

    /// The first instant after `t_s` at which the acceleration or the body rate may jump
    /// (a join of closed-form pieces), if any. [`ideal_increment`] splits its quadrature
    /// there, so that each Gauss–Legendre rule integrates a smooth function. The default
    /// (`None`) declares the trajectory smooth.
    fn next_break_s(&self, _t_s: f64) -> Option<f64> {
        None
    }
}

impl<F: Fn(f64) -> TrajectoryPoint> Trajectory for F {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        self(t_s)
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1], 6 points.
const GL_X: [f64; 6] = [
    -0.932_469_514_203_152,
    -0.661_209_386_466_264_5,
    -0.238_619_186_083_196_9,
    0.238_619_186_083_196_9,
    0.661_209_386_466_264_5,
    0.932_469_514_203_152,
];
const GL_W: [f64; 6] = [
    0.171_324_492_379_170_3,
    0.360_761_573_048_138_6,
    0.467_913_934_572_691,
    0.467_913_934_572_691,
    0.360_761_573_048_138_6,
    0.171_324_492_379_170_3,
];

/// Adds the 6-node Gauss–Legendre approximations of ∫ω_ib^b dt and ∫f^b dt over [a, b].
fn gauss_legendre<T: Trajectory + ?Sized>(
    traj: &T,
    a_s: f64,
    b_s: f64,
    dth: &mut Vec3,
    dv: &mut Vec3,
) {
    let half = 0.5 * (b_s - a_s);
    let mid = 0.5 * (b_s + a_s);
    for (x, w) in GL_X.iter().zip(GL_W.iter()) {
        let (om, f) = traj.point(mid + half * x).imu_rates();
        for k in 0..3 {
            dth[k] += w * half * om[k];
            dv[k] += w * half * f[k];
        }
    }
}

/// Ideal increment over (t_start_s, t_end_s]: Δθ = ∫ω_ib^b dt, Δv = ∫f^b dt by 6-node
/// Gauss–Legendre quadrature, applied piecewise between the trajectory's break points
/// ([`Trajectory::next_break_s`]) inside the interval.
pub fn ideal_increment<T: Trajectory + ?Sized>(
    traj: &T,
    t_start_s: f64,
    t_end_s: f64,
) -> ImuIncrement {
    let mut dth = [0.0; 3];
    let mut dv = [0.0; 3];
    let mut a = t_start_s;
    while let Some(b) = traj.next_break_s(a) {
        if !(b > a && b < t_end_s) {
            break;
        }
        gauss_legendre(traj, a, b, &mut dth, &mut dv);
        a = b;
    }
    gauss_legendre(traj, a, t_end_s, &mut dth, &mut dv);
    ImuIncrement {
        time_s: t_end_s,
        dt_s: t_end_s - t_start_s,
        dtheta_rad: dth,
        dvel_m_s: dv,
    }
}

/// `count` ideal increments of length `dt_s`, the i-th (from 0) ending at
/// `first_end_s + i·dt_s`. Start a mechanization at `first_end_s` with the first one as
/// the "previous" increment.
pub fn ideal_increments<T: Trajectory + ?Sized>(
    traj: &T,
    first_end_s: f64,
    dt_s: f64,
    count: usize,
) -> impl Iterator<Item = ImuIncrement> + '_ {
    (0..count).map(move |i| {
        let t_end = first_end_s + i as f64 * dt_s;
        ideal_increment(traj, t_end - dt_s, t_end)
    })
}

/// The same increments as [`ideal_increments`], computed in parallel (rayon) and
/// collected in order.
pub fn ideal_increments_par<T: Trajectory + Sync + ?Sized>(
    traj: &T,
    first_end_s: f64,
    dt_s: f64,
    count: usize,
) -> Vec<ImuIncrement> {
    use rayon::prelude::*;
    (0..count)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let t_end = first_end_s + i as f64 * dt_s;
            ideal_increment(traj, t_end - dt_s, t_end)
        })
        .collect()
}

/// Scaled local coordinates → exact geodetic position, NED velocity and v̇^n (module
/// documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LocalOrigin {
    lat0: f64,
    lon0: f64,
    h0: f64,
    rho_n: f64,
    rho_e: f64,
}

impl LocalOrigin {
    pub(crate) fn new(lat_rad: f64, lon_rad: f64, height_m: f64) -> LocalOrigin {
        LocalOrigin {
            lat0: lat_rad,
            lon0: lon_rad,
            h0: height_m,
            rho_n: earth::meridian_radius_m(lat_rad) + height_m,
            rho_e: (earth::prime_vertical_radius_m(lat_rad) + height_m) * lat_rad.cos(),
        }
    }

    /// Scaled local coordinates (n, e, d) of a geodetic position: the exact inverse of
    /// the position map of [`LocalOrigin::point`] (longitude difference wrapped to
    /// (−π, π]).
    pub(crate) fn local_of(&self, lat_rad: f64, lon_rad: f64, height_m: f64) -> Vec3 {
        let tau = 2.0 * std::f64::consts::PI;
        let mut dlon = (lon_rad - self.lon0) % tau;
        if dlon > std::f64::consts::PI {
            dlon -= tau;
        } else if dlon <= -std::f64::consts::PI {
            dlon += tau;
        }
        [
            (lat_rad - self.lat0) * self.rho_n,
            dlon * self.rho_e,
            self.h0 - height_m,
        ]
    }

    /// `p`, `v`, `a`: local (n, e, d) and its first two derivatives.
    pub(crate) fn point(
        &self,
        p: Vec3,
        v: Vec3,
        a: Vec3,
        c_bn: Mat3,
        omega_nb_b: Vec3,
    ) -> TrajectoryPoint {
        let lat = self.lat0 + p[0] / self.rho_n;
        let lat_d = v[0] / self.rho_n;
        let lat_dd = a[0] / self.rho_n;
        let lon = self.lon0 + p[1] / self.rho_e;
        let lon_d = v[1] / self.rho_e;
        let lon_dd = a[1] / self.rho_e;
        let h = self.h0 - p[2];
        let h_d = -v[2];
        let (s, c) = lat.sin_cos();
        let w = 1.0 - earth::E2 * s * s;
        let sw = w.sqrt();
        let rm = earth::A_M * (1.0 - earth::E2) / (w * sw);
        let rn = earth::A_M / sw;
        let drm = 3.0 * earth::A_M * (1.0 - earth::E2) * earth::E2 * s * c / (w * w * sw);
        let drn = earth::A_M * earth::E2 * s * c / (w * sw);
        let v_n = (rm + h) * lat_d;
        let a_n = (drm * lat_d + h_d) * lat_d + (rm + h) * lat_dd;
        let pe = (rn + h) * c;
        let pe_d = (drn * lat_d + h_d) * c - (rn + h) * s * lat_d;
        let v_e = pe * lon_d;
        let a_e = pe_d * lon_d + pe * lon_dd;
        TrajectoryPoint {
            lat_rad: lat,
            lon_rad: lon,
            height_m: h,
            vel_ned_m_s: [v_n, v_e, v[2]],
            acc_ned_m_s2: [a_n, a_e, a[2]],
            c_bn,
            omega_nb_b_rad_s: omega_nb_b,
        }
    }
}

/// (a) At rest at a fixed position and attitude.
#[derive(Clone, Copy, Debug)]
pub struct Stationary {
    /// Latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// Attitude.
    pub attitude: Euler,
}

impl Trajectory for Stationary {
    fn point(&self, _t_s: f64) -> TrajectoryPoint {
        TrajectoryPoint {
            lat_rad: self.lat_rad,
            lon_rad: self.lon_rad,
            height_m: self.height_m,
            vel_ned_m_s: [0.0; 3],
            acc_ned_m_s2: [0.0; 3],
            c_bn: self.attitude.to_dcm(),
            omega_nb_b_rad_s: [0.0; 3],
        }
    }
}

/// (b) Constant-speed turn at constant height: the vehicle is at the origin at t = 0
/// heading `yaw0_rad` and its yaw grows at the constant rate `yaw_rate_rad_s`; its
/// course equals its yaw. Roll and pitch are constant (zero for a level vehicle; non-zero
/// values model a tilted IMU mount). Local path: n = r(sin ψ − sin ψ₀),
/// e = r(cos ψ₀ − cos ψ), r = V/ψ̇, ψ = ψ₀ + ψ̇t; ω_nb^b = C_nb(0, 0, ψ̇).
#[derive(Clone, Copy, Debug)]
pub struct ConstantTurn {
    /// Latitude at t = 0, rad.
    pub lat_rad: f64,
    /// Longitude at t = 0, rad.
    pub lon_rad: f64,
    /// Height, m.
    pub height_m: f64,
    /// Speed along the local path, m/s.
    pub speed_m_s: f64,
    /// Yaw at t = 0, rad.
    pub yaw0_rad: f64,
    /// Yaw rate (positive = turning right, clockwise seen from above), rad/s.
    pub yaw_rate_rad_s: f64,
    /// Constant roll, rad.
    pub roll_rad: f64,
    /// Constant pitch, rad.
    pub pitch_rad: f64,
}

impl Trajectory for ConstantTurn {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let o = LocalOrigin::new(self.lat_rad, self.lon_rad, self.height_m);
        let w = self.yaw_rate_rad_s;
        let v = self.speed_m_s;
        let psi = self.yaw0_rad + w * t_s;
        let (sp, cp) = psi.sin_cos();
        let (s0, c0) = self.yaw0_rad.sin_cos();
        let p = if w.abs() > 1e-9 {
            let r = v / w;
            [r * (sp - s0), r * (c0 - cp), 0.0]
        } else {
            [v * t_s * c0, v * t_s * s0, 0.0]
        };
        let vel = [v * cp, v * sp, 0.0];
        let acc = [-v * w * sp, v * w * cp, 0.0];
        let c_bn = Euler {
            roll_rad: self.roll_rad,
            pitch_rad: self.pitch_rad,
            yaw_rad: psi,
        }
        .to_dcm();
        let omega_nb_b = c_bn.t().mul_vec([0.0, 0.0, w]);
        o.point(p, vel, acc, c_bn, omega_nb_b)
    }
}

/// (c) Straight run with constant acceleration along the path: distance
/// s(t) = v₀t + ½at², heading `yaw_rad`, flight-path angle `climb_rad` (positive up);
/// local path n = s cos γ cos ψ, e = s cos γ sin ψ, d = −s sin γ. The body is aligned with
/// the path (pitch = γ, yaw = ψ) with a constant `roll_rad`.
#[derive(Clone, Copy, Debug)]
pub struct StraightRun {
    /// Latitude at t = 0, rad.
    pub lat_rad: f64,
    /// Longitude at t = 0, rad.
    pub lon_rad: f64,
    /// Height at t = 0, m.
    pub height_m: f64,
    /// Heading, rad.
    pub yaw_rad: f64,
    /// Flight-path angle (and pitch), rad.
    pub climb_rad: f64,
    /// Constant roll, rad.
    pub roll_rad: f64,
    /// Speed at t = 0, m/s.
    pub speed0_m_s: f64,
    /// Acceleration along the path, m/s².
    pub accel_m_s2: f64,
}

impl Trajectory for StraightRun {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let o = LocalOrigin::new(self.lat_rad, self.lon_rad, self.height_m);
        let s = self.speed0_m_s * t_s + 0.5 * self.accel_m_s2 * t_s * t_s;
        let sd = self.speed0_m_s + self.accel_m_s2 * t_s;
        let sdd = self.accel_m_s2;
        let (sy, cy) = self.yaw_rad.sin_cos();
        let (sg, cg) = self.climb_rad.sin_cos();
        let u = [cg * cy, cg * sy, -sg];
        let c_bn = Euler {
            roll_rad: self.roll_rad,
            pitch_rad: self.climb_rad,
            yaw_rad: self.yaw_rad,
        }
        .to_dcm();
        o.point(scale(u, s), scale(u, sd), scale(u, sdd), c_bn, [0.0; 3])
    }
}

/// A trajectory given only by t ↦ (φ, λ, h, v^n, C_bn), with v̇^n and ω_nb^b from
/// fourth-order central differences of step `step_s`:
/// ẋ ≈ [8(x(t+δ) − x(t−δ)) − (x(t+2δ) − x(t−2δ))]/(12δ), and ω_nb^b the axial vector of
/// the skew part of C_nb·Ċ_bn. Truncation error O(δ⁴), rounding O(ε/δ): with δ ≈ 1e-3 s
/// the rates are good to ≈ 1e-10 relative — adequate for checks at the cm level; use an
/// analytic trajectory for sub-millimetre truth.
pub struct FiniteDifference<F> {
    /// The state function: (lat rad, lon rad, h m, v_ned m/s, C_bn).
    pub state: F,
    /// Difference step δ, s.
    pub step_s: f64,
}

impl<F: Fn(f64) -> (f64, f64, f64, Vec3, Mat3)> Trajectory for FiniteDifference<F> {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let d = self.step_s;
        let (lat, lon, h, v, c) = (self.state)(t_s);
        let p1 = (self.state)(t_s + d);
        let m1 = (self.state)(t_s - d);
        let p2 = (self.state)(t_s + 2.0 * d);
        let m2 = (self.state)(t_s - 2.0 * d);
        let diff = |a1: f64, b1: f64, a2: f64, b2: f64| (8.0 * (a1 - b1) - (a2 - b2)) / (12.0 * d);
        let acc = [0, 1, 2].map(|k| diff(p1.3[k], m1.3[k], p2.3[k], m2.3[k]));
        let mut c_dot = Mat3::ZERO;
        for i in 0..3 {
            for j in 0..3 {
                c_dot.0[i][j] = diff(p1.4.0[i][j], m1.4.0[i][j], p2.4.0[i][j], m2.4.0[i][j]);
            }
        }
        let w = c.t().mul_mat(&c_dot);
        let omega = [
            0.5 * (w.0[2][1] - w.0[1][2]),
            0.5 * (w.0[0][2] - w.0[2][0]),
            0.5 * (w.0[1][0] - w.0[0][1]),
        ];
        TrajectoryPoint {
            lat_rad: lat,
            lon_rad: lon,
            height_m: h,
            vel_ned_m_s: v,
            acc_ned_m_s2: acc,
            c_bn: c,
            omega_nb_b_rad_s: omega,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use driftless_model::units::DEG;

    /// Finite differences of the analytic position reproduce the analytic NED velocity,
    /// and of the velocity the analytic v̇^n (checks the radius-derivative algebra).
    #[test]
    fn analytic_derivatives_match_finite_differences() {
        let traj = StraightRun {
            lat_rad: 50.0 * DEG,
            lon_rad: 7.0 * DEG,
            height_m: 300.0,
            yaw_rad: 40.0 * DEG,
            climb_rad: 5.0 * DEG,
            roll_rad: 0.0,
            speed0_m_s: 20.0,
            accel_m_s2: 3.0,
        };
        let t = 50.0;
        let d = 1e-3;
        let p = traj.point(t);
        let f = |k: f64| traj.point(t + k * d);
        let (p1, m1, p2, m2) = (f(1.0), f(-1.0), f(2.0), f(-2.0));
        let diff = |a1: f64, b1: f64, a2: f64, b2: f64| (8.0 * (a1 - b1) - (a2 - b2)) / (12.0 * d);
        let lat_d = diff(p1.lat_rad, m1.lat_rad, p2.lat_rad, m2.lat_rad);
        let lon_d = diff(p1.lon_rad, m1.lon_rad, p2.lon_rad, m2.lon_rad);
        let h_d = diff(p1.height_m, m1.height_m, p2.height_m, m2.height_m);
        let rm = earth::meridian_radius_m(p.lat_rad) + p.height_m;
        let rn = earth::prime_vertical_radius_m(p.lat_rad) + p.height_m;
        assert!((lat_d * rm - p.vel_ned_m_s[0]).abs() < 1e-6);
        assert!((lon_d * rn * p.lat_rad.cos() - p.vel_ned_m_s[1]).abs() < 1e-6);
        assert!((-h_d - p.vel_ned_m_s[2]).abs() < 1e-9);
        for k in 0..3 {
            let a = diff(
                p1.vel_ned_m_s[k],
                m1.vel_ned_m_s[k],
                p2.vel_ned_m_s[k],
                m2.vel_ned_m_s[k],
            );
            assert!(
                (a - p.acc_ned_m_s2[k]).abs() < 1e-8,
                "{k}: {a} {:?}",
                p.acc_ned_m_s2
            );
        }
        // Independent check of v̇_N = (R_M + h)φ̈ + (dR_M/dφ·φ̇ + ḣ)φ̇ with the radii of
        // `earth` and dR_M/dφ by a central difference: the ellipsoid terms are ≈ 2e-4
        // relative here (climb 400 m, 3.6 km north) and must be reproduced.
        let a_flat = 3.0 * (5.0 * DEG).cos() * (40.0 * DEG).cos();
        let rho_n = earth::meridian_radius_m(50.0 * DEG) + 300.0;
        let lat_dot = p.vel_ned_m_s[0] / rm;
        let drm = (earth::meridian_radius_m(p.lat_rad + 1e-6)
            - earth::meridian_radius_m(p.lat_rad - 1e-6))
            / 2e-6;
        let a_exp = rm * a_flat / rho_n + (drm * lat_dot - p.vel_ned_m_s[2]) * lat_dot;
        assert!(
            (p.acc_ned_m_s2[0] - a_exp).abs() < 1e-10,
            "{} {a_exp}",
            p.acc_ned_m_s2[0]
        );
        assert!((p.acc_ned_m_s2[0] - a_flat).abs() > 1e-4 * a_flat);
    }

    /// A climbing, turning land vehicle with a tilted mount: analytic v̇^n and ω_nb^b
    /// agree with finite differences; the velocity stays along the vehicle x axis.
    #[test]
    fn land_vehicle_climb_derivatives() {
        let c_vb = Euler {
            roll_rad: 1.0 * DEG,
            pitch_rad: -2.0 * DEG,
            yaw_rad: 3.0 * DEG,
        }
        .to_dcm();
        let lv = LandVehicle::new(
            30.0 * DEG,
            114.0 * DEG,
            20.0,
            10.0 * DEG,
            8.0,
            c_vb,
            &[
                DriveSegment::Climb {
                    height_change_m: 5.0,
                    duration_s: 10.0,
                },
                DriveSegment::Turn {
                    angle_rad: 60.0 * DEG,
                    duration_s: 5.0,
                },
                DriveSegment::Climb {
                    height_change_m: -3.0,
                    duration_s: 6.0,
                },
            ],
        );
        let fd = FiniteDifference {
            state: |t: f64| {
                let p = lv.point(t);
                (p.lat_rad, p.lon_rad, p.height_m, p.vel_ned_m_s, p.c_bn)
            },
            step_s: 1e-3,
        };
        for t in [0.5, 2.5, 5.0, 9.0, 12.0, 16.5, 19.0, 20.9] {
            let (a, b) = (lv.point(t), fd.point(t));
            for k in 0..3 {
                assert!(
                    (a.acc_ned_m_s2[k] - b.acc_ned_m_s2[k]).abs() < 1e-8,
                    "t {t} acc {k}: {:?} {:?}",
                    a.acc_ned_m_s2,
                    b.acc_ned_m_s2
                );
                assert!(
                    (a.omega_nb_b_rad_s[k] - b.omega_nb_b_rad_s[k]).abs() < 1e-9,
                    "t {t} ω {k}: {:?} {:?}",
                    a.omega_nb_b_rad_s,
                    b.omega_nb_b_rad_s
                );
            }
            let v_v = c_vb.mul_vec(a.c_bn.t().mul_vec(a.vel_ned_m_s));
            assert!(
                v_v[1].abs() < 2e-4 * v_v[0] && v_v[2].abs() < 2e-4 * v_v[0],
                "{v_v:?}"
            );
        }
        assert!((lv.point(30.0).height_m - 22.0).abs() < 1e-9);
        assert!(Euler::from_dcm(&lv.point(5.0).c_bn.mul_mat(&c_vb.t())).pitch_rad > 5.0 * DEG);
    }

    /// A walk with a gait (start from rest, a 3-m-radius turn, a stop): analytic v̇^n and
    /// ω_nb^b agree with finite differences of the position and attitude, the bob and
    /// sway have their closed-form values and stop with the walker.
    #[test]
    fn walk_with_gait_derivatives() {
        let gait = Gait {
            step_length_m: 0.6,
            bob_amplitude_m: 0.02,
            pitch_amplitude_rad: 1.5 * DEG,
            roll_amplitude_rad: 2.0 * DEG,
        };
        let v = 1.2;
        let lv = LandVehicle::new(
            45.0 * DEG,
            7.0 * DEG,
            300.0,
            30.0 * DEG,
            0.0,
            Mat3::IDENTITY,
            &[
                DriveSegment::Stop { duration_s: 2.0 },
                DriveSegment::Speed {
                    to_m_s: v,
                    duration_s: 1.5,
                },
                DriveSegment::Turn {
                    angle_rad: -1.5,
                    duration_s: 1.5 * 3.0 / v,
                },
                DriveSegment::Speed {
                    to_m_s: 0.0,
                    duration_s: 1.0,
                },
                DriveSegment::Stop { duration_s: 2.0 },
            ],
        )
        .with_gait(Some(gait));
        let fd = FiniteDifference {
            state: |t: f64| {
                let p = lv.point(t);
                (p.lat_rad, p.lon_rad, p.height_m, p.vel_ned_m_s, p.c_bn)
            },
            step_s: 1e-4,
        };
        for t in [2.3, 2.9, 3.4, 3.8, 4.6, 5.5, 6.9, 7.3] {
            let (a, b) = (lv.point(t), fd.point(t));
            for k in 0..3 {
                assert!(
                    (a.acc_ned_m_s2[k] - b.acc_ned_m_s2[k]).abs() < 1e-6,
                    "t {t} acc {k}: {:?} {:?}",
                    a.acc_ned_m_s2,
                    b.acc_ned_m_s2
                );
                assert!(
                    (a.omega_nb_b_rad_s[k] - b.omega_nb_b_rad_s[k]).abs() < 1e-7,
                    "t {t} ω {k}: {:?} {:?}",
                    a.omega_nb_b_rad_s,
                    b.omega_nb_b_rad_s
                );
            }
        }
        // Mid-turn: 1.2 m/s at 3 m radius, 2 steps/s: bob −A_b sin(ks), roll A_r sin(ks/2)
        // with s the distance walked (the speed-up covers v·T/2 = 0.9 m).
        let t = 4.0;
        let s = 0.9 + v * (t - 3.5);
        let k = 2.0 * std::f64::consts::PI / 0.6;
        let p = lv.point(t);
        let plain = LandVehicle::new(
            45.0 * DEG,
            7.0 * DEG,
            300.0,
            30.0 * DEG,
            0.0,
            Mat3::IDENTITY,
            &lv.segs.iter().map(|g| g.seg).take(5).collect::<Vec<_>>(),
        );
        let q = plain.point(t);
        assert!((p.height_m - q.height_m - 0.02 * (k * s).sin()).abs() < 1e-9);
        let e = Euler::from_dcm(&p.c_bn);
        assert!((e.roll_rad - 2.0 * DEG * (0.5 * k * s).sin()).abs() < 1e-12);
        assert!((e.pitch_rad - 1.5 * DEG * (k * s).sin()).abs() < 1e-12);
        // The peak vertical acceleration A_b(kV)² ≈ 3.2 m/s² shows while walking.
        let peak = (0..200)
            .map(|i| lv.point(3.5 + i as f64 * 0.005).acc_ned_m_s2[2].abs())
            .fold(0.0, f64::max);
        assert!((peak - 0.02 * (k * v).powi(2)).abs() < 0.05, "{peak}");
        // Standing still at the end: no motion at all.
        let z = lv.point(lv.duration_s() - 0.5);
        assert!(
            z.vel_ned_m_s
                .iter()
                .chain(&z.omega_nb_b_rad_s)
                .all(|x| *x == 0.0)
        );
        assert!(z.acc_ned_m_s2.iter().all(|x| *x == 0.0));
    }

    /// A join inside an IMU interval (a yaw rate switching on) is integrated piecewise:
    /// the increment equals a fine quadrature aligned with the join, while one 6-node
    /// rule across the jump is off by more than 1e-6 rad.
    #[test]
    fn increments_split_at_breaks() {
        let lv = LandVehicle::new(
            30.0 * DEG,
            114.0 * DEG,
            20.0,
            0.0,
            10.0,
            Mat3::IDENTITY,
            &[
                DriveSegment::Speed {
                    to_m_s: 10.0,
                    duration_s: 1.0013,
                },
                DriveSegment::Turn {
                    angle_rad: 0.5,
                    duration_s: 2.0,
                },
            ],
        );
        assert_eq!(lv.next_break_s(1.0), Some(1.0013));
        let smooth = |t: f64| lv.point(t); // no break information
        let inc = ideal_increment(&lv, 1.0, 1.005);
        let mut fine = [0.0; 3];
        for i in 0..500 {
            let a = 1.0 + i as f64 * 1e-5;
            fine = add(fine, ideal_increment(&smooth, a, a + 1e-5).dtheta_rad);
        }
        let blind = ideal_increment(&smooth, 1.0, 1.005).dtheta_rad;
        assert!(
            (inc.dtheta_rad[2] - fine[2]).abs() < 1e-14,
            "{inc:?} {fine:?}"
        );
        assert!((inc.dtheta_rad[2] - 0.25 * 0.0037).abs() < 1e-6);
        assert!((blind[2] - fine[2]).abs() > 1e-6, "{blind:?} {fine:?}");
    }

    /// The fused Earth-model evaluation of `imu_rates` equals the `earth` functions'.
    #[test]
    fn fused_imu_rates_match_earth_functions() {
        for (lat, h, yaw) in [
            (30.0, 25.0, 10.0),
            (-67.0, 3000.0, 200.0),
            (0.0, -50.0, 90.0),
        ] {
            let turn = ConstantTurn {
                lat_rad: lat * DEG,
                lon_rad: 1.0,
                height_m: h,
                speed_m_s: 25.0,
                yaw0_rad: yaw * DEG,
                yaw_rate_rad_s: 0.2,
                roll_rad: 0.1,
                pitch_rad: -0.05,
            };
            let p = turn.point(3.7);
            let (a, b) = (p.imu_rates(), p.imu_rates_reference());
            for k in 0..3 {
                assert!(
                    (a.0[k] - b.0[k]).abs() < 1e-17,
                    "ω {k}: {:?} {:?}",
                    a.0,
                    b.0
                );
                assert!(
                    (a.1[k] - b.1[k]).abs() < 1e-14,
                    "f {k}: {:?} {:?}",
                    a.1,
                    b.1
                );
            }
        }
    }

    /// Stationary: the gyro senses Earth rate only and the accelerometer −g rotated into
    /// the body; a finite-difference wrapper of the turn agrees with the analytic one.
    #[test]
    fn stationary_and_finite_difference_rates() {
        let s = Stationary {
            lat_rad: 30.0 * DEG,
            lon_rad: 0.0,
            height_m: 0.0,
            attitude: Euler {
                roll_rad: 0.0,
                pitch_rad: 0.0,
                yaw_rad: 0.0,
            },
        };
        let inc = ideal_increment(&s, 0.0, 0.01);
        let w = earth::OMEGA_IE * 0.01;
        assert!((inc.dtheta_rad[0] - w * (30.0 * DEG).cos()).abs() < 1e-20);
        assert!((inc.dtheta_rad[2] + w * 0.5).abs() < 1e-20);
        let g = earth::normal_gravity_m_s2(30.0 * DEG, 0.0);
        assert!((inc.dvel_m_s[2] + g * 0.01).abs() < 1e-16);

        let turn = ConstantTurn {
            lat_rad: -33.0 * DEG,
            lon_rad: 151.0 * DEG,
            height_m: 40.0,
            speed_m_s: 15.0,
            yaw0_rad: 10.0 * DEG,
            yaw_rate_rad_s: -12.0 * DEG,
            roll_rad: 3.0 * DEG,
            pitch_rad: -2.0 * DEG,
        };
        let fd = FiniteDifference {
            state: |t: f64| {
                let p = turn.point(t);
                (p.lat_rad, p.lon_rad, p.height_m, p.vel_ned_m_s, p.c_bn)
            },
            step_s: 1e-3,
        };
        let (a, b) = (turn.point(7.3), fd.point(7.3));
        for k in 0..3 {
            assert!((a.acc_ned_m_s2[k] - b.acc_ned_m_s2[k]).abs() < 1e-8);
            assert!((a.omega_nb_b_rad_s[k] - b.omega_nb_b_rad_s[k]).abs() < 1e-10);
        }
        // ω_nb^b of a turn about the NED down axis with a tilted mount.
        assert!(
            (a.omega_nb_b_rad_s[2] - (-12.0 * DEG) * (3.0 * DEG).cos() * (2.0 * DEG).cos()).abs()
                < 1e-15
        );
    }
}

//! Simulation shared by the filter and smoother tests: ideal increments of an analytic
//! figure-of-eight drive (`sim::ideal_imu`) plus injected biases and white noise, GNSS at
//! the antenna (lever arm) at 1 Hz with 2 cm σ. Included with `#[path]` by
//! `tests/nav_filter.rs`, `tests/nav_smoother.rs` and (for [`perturbed_start`]) `tests/nav_gating.rs`.
#![allow(dead_code)] // each test file uses a different subset

use driftless::io::nav::{GnssFixes, quality};
use driftless::nav::attitude::{Euler, Quat};
use driftless::nav::earth;
use driftless::nav::filter::{FilterConfig, GaussMarkov, ImuNoise, InitialState, SensorErrors};
use driftless::nav::mechanization::{ImuIncrement, NavState};
use driftless::sim::ideal_imu::{FiniteDifference, Trajectory, TrajectoryPoint, ideal_increments};
use driftless::sim::rng::Rng;
use driftless_model::linalg::{Mat3, Vec3};
use driftless_model::units::{DEG, DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MILLI_G};

pub const DT: f64 = 0.005;
pub const LAT0: f64 = 30.0 * DEG;
pub const LON0: f64 = 114.0 * DEG;
pub const H0: f64 = 50.0;
pub const LEVER_B_M: Vec3 = [0.6, -0.3, -1.2];

/// Injected sensor errors.
pub const GYRO_BIAS: Vec3 = [10.0 * DEG_PER_H, -8.0 * DEG_PER_H, 6.0 * DEG_PER_H];
pub const ACCEL_BIAS: Vec3 = [3.0 * MILLI_G, -2.0 * MILLI_G, 4.0 * MILLI_G];
pub const ARW: f64 = 0.1 * DEG_PER_SQRT_H;
pub const VRW: f64 = 0.05 * M_PER_S_PER_SQRT_H;

/// Figure-of-eight drive with height undulation and a slow roll oscillation, given as
/// scaled local coordinates (exact position; velocity the exact derivative on the
/// ellipsoid; v̇ and ω_nb by finite differences).
pub fn drive() -> impl Trajectory {
    let rm0 = earth::meridian_radius_m(LAT0) + H0;
    let rn0 = earth::prime_vertical_radius_m(LAT0) + H0;
    let w = 2.0 * std::f64::consts::PI / 120.0;
    let w3 = 2.0 * std::f64::consts::PI / 50.0;
    let (a, b, dz) = (300.0, 150.0, 3.0);
    FiniteDifference {
        state: move |t: f64| {
            let n = a * (w * t).sin();
            let e = b * (2.0 * w * t).sin();
            let d = dz * (w3 * t).sin();
            let (nd, ed, dd) = (
                a * w * (w * t).cos(),
                2.0 * b * w * (2.0 * w * t).cos(),
                dz * w3 * (w3 * t).cos(),
            );
            let lat = LAT0 + n / rm0;
            let h = H0 - d;
            let lon = LON0 + e / (rn0 * LAT0.cos());
            let v = [
                (earth::meridian_radius_m(lat) + h) * nd / rm0,
                (earth::prime_vertical_radius_m(lat) + h) * lat.cos() * ed / (rn0 * LAT0.cos()),
                dd,
            ];
            let c = Euler {
                roll_rad: 0.03 * (0.3 * t).sin(),
                pitch_rad: (-dd).atan2(nd.hypot(ed)),
                yaw_rad: ed.atan2(nd),
            }
            .to_dcm();
            (lat, lon, h, v, c)
        },
        step_s: 1e-3,
    }
}

/// Raw IMU: ideal increments over (−DT, duration] plus biases and white noise.
pub fn simulate_imu<T: Trajectory>(traj: &T, duration_s: f64, seed: u64) -> Vec<ImuIncrement> {
    simulate_imu_with(traj, duration_s, seed, [GYRO_BIAS, ACCEL_BIAS], [ARW, VRW])
}

/// [`simulate_imu`] with other constant biases `[gyro rad/s, accel m/s²]` and white
/// noise `[ARW rad/√s, VRW m/s/√s]`.
pub fn simulate_imu_with<T: Trajectory>(
    traj: &T,
    duration_s: f64,
    seed: u64,
    bias: [Vec3; 2],
    white: [f64; 2],
) -> Vec<ImuIncrement> {
    let n = (duration_s / DT).round() as usize + 1;
    let mut rng = Rng::seed_from_u64(seed);
    let (sg, sa) = (white[0] * DT.sqrt(), white[1] * DT.sqrt());
    ideal_increments(traj, 0.0, DT, n)
        .map(|i| ImuIncrement {
            dtheta_rad: std::array::from_fn(|k| {
                i.dtheta_rad[k] + bias[0][k] * DT + sg * rng.normal()
            }),
            dvel_m_s: std::array::from_fn(|k| i.dvel_m_s[k] + bias[1][k] * DT + sa * rng.normal()),
            ..i
        })
        .collect()
}

/// Antenna position (lat, lon, h) of a trajectory point.
pub fn antenna(p: &TrajectoryPoint) -> [f64; 3] {
    let d = p.c_bn.mul_vec(LEVER_B_M);
    let rm = earth::meridian_radius_m(p.lat_rad) + p.height_m;
    let rn = earth::prime_vertical_radius_m(p.lat_rad) + p.height_m;
    [
        p.lat_rad + d[0] / rm,
        p.lon_rad + d[1] / (rn * p.lat_rad.cos()),
        p.height_m - d[2],
    ]
}

/// 1 Hz GNSS at the antenna with 2 cm white noise per axis.
pub fn simulate_gnss<T: Trajectory>(traj: &T, duration_s: f64, seed: u64) -> GnssFixes {
    let mut rng = Rng::seed_from_u64(seed);
    let mut g = GnssFixes::default();
    let sigma = 0.02;
    for k in 1..=(duration_s as usize) {
        let t = k as f64;
        let p = traj.point(t);
        let a = antenna(&p);
        let rm = earth::meridian_radius_m(a[0]) + a[2];
        let rn = earth::prime_vertical_radius_m(a[0]) + a[2];
        g.time_s.push(t);
        g.lat_rad.push(a[0] + sigma * rng.normal() / rm);
        g.lon_rad
            .push(a[1] + sigma * rng.normal() / (rn * a[0].cos()));
        g.height_m.push(a[2] + sigma * rng.normal());
        g.sigma_ned_m.push([sigma; 3]);
        g.quality.push(quality::FIX);
    }
    g
}

pub fn config() -> FilterConfig {
    // Long correlation times: the injected errors are constant, and the GM driving
    // noise 2σ²/T sets how fast the filter lets the estimates wander.
    let gm = |sigma| GaussMarkov {
        sigma,
        tau_s: 36_000.0,
    };
    FilterConfig::new(
        ImuNoise {
            gyro_arw_rad_sqrt_s: 1.5 * ARW,
            accel_vrw_m_s_sqrt_s: 1.5 * VRW,
            gyro_bias: gm(20.0 * DEG_PER_H),
            accel_bias: gm(5.0 * MILLI_G),
            gyro_scale: gm(1000e-6),
            accel_scale: gm(1000e-6),
        },
        LEVER_B_M,
    )
}

/// Initial state: truth at t = 0 perturbed by 0.3 m, 0.1 m/s, (0.5°, −0.5°, 3°).
pub fn initial<T: Trajectory>(traj: &T) -> InitialState {
    perturbed_start(traj, 0.1, [0.5 * DEG, -0.5 * DEG, 3.0 * DEG], 0.5)
}

/// Truth at t = 0 moved 0.3 m north, `dv_east_m_s` east in velocity and rotated by the
/// attitude error `att_err_rad` (phi-angle); σ 1 m, `sigma_vel_m_s`, (1°, 1°, 5°).
pub fn perturbed_start<T: Trajectory>(
    traj: &T,
    dv_east_m_s: f64,
    att_err_rad: Vec3,
    sigma_vel_m_s: f64,
) -> InitialState {
    let p = traj.point(0.0);
    let mut nav = p.nav_state(0.0);
    let rm = earth::meridian_radius_m(nav.lat_rad) + nav.height_m;
    nav.lat_rad += 0.3 / rm;
    nav.vel_ned_m_s[1] += dv_east_m_s;
    nav.q_bn = Quat::from_rotation_vector(att_err_rad)
        .mul(&nav.q_bn)
        .normalized();
    InitialState {
        nav,
        sensors: SensorErrors::default(),
        sigma_pos_ned_m: [1.0; 3],
        sigma_vel_ned_m_s: [sigma_vel_m_s; 3],
        sigma_att_rad: [1.0 * DEG, 1.0 * DEG, 5.0 * DEG],
        sigma_sensors: None,
    }
}

/// NED error (m) of the estimated IMU position against the truth.
pub fn pos_err(nav: &NavState, truth: &TrajectoryPoint) -> Vec3 {
    earth::ned_offset_m(
        (truth.lat_rad, truth.lon_rad, truth.height_m),
        (nav.lat_rad, nav.lon_rad, nav.height_m),
    )
}

/// Attitude error angle vector (rad, NED) of an estimate against the truth.
pub fn att_err(q: &Quat, c_true: &Mat3) -> Vec3 {
    // C_true Ĉᵀ ≈ I + [φ×] for Ĉ = (I − [φ×])C.
    let q_true = Quat::from_dcm(c_true);
    q_true.mul(&q.conj()).to_rotation_vector()
}

pub struct Scenario<T> {
    pub traj: T,
    pub imu: Vec<ImuIncrement>,
    pub gnss: GnssFixes,
}

pub fn scenario(duration_s: f64) -> Scenario<impl Trajectory> {
    let traj = drive();
    let imu = simulate_imu(&traj, duration_s, 11);
    let gnss = simulate_gnss(&traj, duration_s, 12);
    Scenario { traj, imu, gnss }
}

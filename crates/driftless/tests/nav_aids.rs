//! Land-vehicle aids of the GNSS/INS filter:
//! non-holonomic constraint with IMU mounting rotation, standstill detection, ZUPT and
//! ZARU. Simulated data: an exact composite land-vehicle drive
//! (`sim::ideal_imu::LandVehicle`: stops, straight runs with smooth speed changes,
//! constant-speed turns; no side slip, level road) with consumer-grade IMU errors
//! (biases of 0.04–0.06°/s and 8–15 mg, ARW 0.3°/√h, VRW 0.1 m/s/√h, 200 Hz) and 1 Hz
//! GNSS with 2 cm σ. The vehicle's non-holonomic point is the IMU itself (NHC lever arm
//! zero). Run with `cargo test --release`; the measured figures are printed.

use driftless::io::nav::{GnssFixes, quality};
use driftless::nav::attitude::{Euler, Quat};
use driftless::nav::earth;
use driftless::nav::filter::{
    FilterConfig, ForwardRun, GaussMarkov, ImuNoise, InitialState, NhcConfig, SensorErrors,
    StandstillConfig, StandstillDetector, UpdateKind, run_forward,
};
use driftless::nav::mechanization::{ImuIncrement, NavState};
use driftless::sim::ideal_imu::{
    DriveSegment, LandVehicle, Trajectory, TrajectoryPoint, ideal_increments,
};
use driftless::sim::rng::Rng;
use driftless_model::linalg::{Mat3, Vec3};
use driftless_model::units::{DEG, DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MILLI_G};

const DT: f64 = 0.005;
const LAT0: f64 = 30.0 * DEG;
const LON0: f64 = 114.0 * DEG;
const H0: f64 = 50.0;
const DURATION: f64 = 440.0;

/// Injected consumer-grade sensor errors.
const GYRO_BIAS: Vec3 = [0.05 * DEG, -0.04 * DEG, 0.06 * DEG];
const ACCEL_BIAS: Vec3 = [10.0 * MILLI_G, -8.0 * MILLI_G, 15.0 * MILLI_G];
const ARW: f64 = 0.3 * DEG_PER_SQRT_H;
const VRW: f64 = 0.1 * M_PER_S_PER_SQRT_H;

/// GNSS outage in motion (turns, an acceleration) and the one covering the standstill.
const OUTAGE_MOTION: (f64, f64) = (200.0, 260.0);
const OUTAGE_STOP: (f64, f64) = (326.0, 360.0);
/// True standstills (the drive's Stop segments).
const STOPS: [(f64, f64); 2] = [(0.0, 10.0), (324.0, 364.0)];

fn segments() -> Vec<DriveSegment> {
    use DriveSegment::{Speed, Stop, Turn};
    let sp = |to_m_s: f64, duration_s: f64| Speed { to_m_s, duration_s };
    let tn = |deg: f64, duration_s: f64| Turn {
        angle_rad: deg * DEG,
        duration_s,
    };
    vec![
        Stop { duration_s: 10.0 },
        sp(10.0, 8.0),
        sp(10.0, 20.0),
        tn(90.0, 10.0),
        sp(10.0, 15.0),
        tn(-90.0, 12.0),
        sp(15.0, 8.0),
        sp(15.0, 20.0),
        tn(180.0, 20.0),
        sp(15.0, 20.0),
        sp(8.0, 6.0),
        tn(-90.0, 10.0),
        sp(12.0, 6.0),
        sp(12.0, 30.0), // → 195 s
        tn(60.0, 10.0),
        sp(12.0, 20.0),
        tn(-90.0, 15.0),
        sp(15.0, 8.0),
        sp(15.0, 30.0),
        tn(45.0, 8.0),
        sp(15.0, 30.0), // → 316 s
        sp(0.0, 8.0),
        Stop { duration_s: 40.0 }, // 324–364 s
        sp(10.0, 8.0),
        sp(10.0, 30.0),
        tn(90.0, 10.0),
        sp(10.0, 20.0),
    ]
}

fn drive(c_vb: Mat3) -> LandVehicle {
    LandVehicle::new(LAT0, LON0, H0, 20.0 * DEG, 0.0, c_vb, &segments())
}

/// Vehicle vibration added while moving (per-sample white σ), test (c).
#[derive(Clone, Copy)]
struct Vibration {
    accel_m_s2: f64,
    gyro_rad_s: f64,
}

/// Raw IMU: ideal increments plus biases, white noise and optional vibration in motion.
fn simulate_imu<T: Trajectory>(traj: &T, seed: u64, vib: Option<Vibration>) -> Vec<ImuIncrement> {
    let n = (DURATION / DT).round() as usize + 1;
    let mut rng = Rng::seed_from_u64(seed);
    let (sg, sa) = (ARW * DT.sqrt(), VRW * DT.sqrt());
    ideal_increments(traj, 0.0, DT, n)
        .map(|i| {
            let moving = traj
                .point(i.time_s)
                .vel_ned_m_s
                .iter()
                .any(|v| v.abs() > 1e-3);
            let (va, vg) = match vib {
                Some(v) if moving => (v.accel_m_s2 * DT, v.gyro_rad_s * DT),
                _ => (0.0, 0.0),
            };
            ImuIncrement {
                dtheta_rad: std::array::from_fn(|k| {
                    i.dtheta_rad[k] + GYRO_BIAS[k] * DT + sg * rng.normal() + vg * rng.normal()
                }),
                dvel_m_s: std::array::from_fn(|k| {
                    i.dvel_m_s[k] + ACCEL_BIAS[k] * DT + sa * rng.normal() + va * rng.normal()
                }),
                ..i
            }
        })
        .collect()
}

/// 1 Hz GNSS at the IMU (no lever arm) with 2 cm white noise per axis.
fn simulate_gnss<T: Trajectory>(traj: &T, seed: u64) -> GnssFixes {
    let mut rng = Rng::seed_from_u64(seed);
    let mut g = GnssFixes::default();
    let sigma = 0.02;
    for k in 1..=(DURATION as usize) {
        let t = k as f64;
        let p = traj.point(t);
        let rm = earth::meridian_radius_m(p.lat_rad) + p.height_m;
        let rn = earth::prime_vertical_radius_m(p.lat_rad) + p.height_m;
        g.time_s.push(t);
        g.lat_rad.push(p.lat_rad + sigma * rng.normal() / rm);
        g.lon_rad
            .push(p.lon_rad + sigma * rng.normal() / (rn * p.lat_rad.cos()));
        g.height_m.push(p.height_m + sigma * rng.normal());
        g.sigma_ned_m.push([sigma; 3]);
        g.quality.push(quality::FIX);
    }
    g
}

fn base_config() -> FilterConfig {
    let gm = |sigma| GaussMarkov {
        sigma,
        tau_s: 3600.0,
    };
    let mut cfg = FilterConfig::new(
        ImuNoise {
            gyro_arw_rad_sqrt_s: 1.5 * ARW,
            accel_vrw_m_s_sqrt_s: 1.5 * VRW,
            gyro_bias: gm(0.1 * DEG),
            accel_bias: gm(20.0 * MILLI_G),
            gyro_scale: gm(3000e-6),
            accel_scale: gm(3000e-6),
        },
        [0.0; 3],
    );
    cfg.outages_s = vec![OUTAGE_MOTION, OUTAGE_STOP];
    cfg
}

/// Initial state: truth at t = 0 (at rest) perturbed by 0.3 m, 0.05 m/s,
/// (0.3°, −0.3°, 2°).
fn initial<T: Trajectory>(traj: &T) -> InitialState {
    let p = traj.point(0.0);
    let mut nav = p.nav_state(0.0);
    let rm = earth::meridian_radius_m(nav.lat_rad) + nav.height_m;
    nav.lat_rad += 0.3 / rm;
    nav.vel_ned_m_s[1] += 0.05;
    nav.q_bn = Quat::from_rotation_vector([0.3 * DEG, -0.3 * DEG, 2.0 * DEG])
        .mul(&nav.q_bn)
        .normalized();
    InitialState {
        nav,
        sensors: SensorErrors::default(),
        sigma_pos_ned_m: [1.0; 3],
        sigma_vel_ned_m_s: [0.3; 3],
        sigma_att_rad: [1.0 * DEG, 1.0 * DEG, 5.0 * DEG],
        sigma_sensors: None,
    }
}

/// NED error (m) of the estimated IMU position against the truth.
fn pos_err(nav: &NavState, truth: &TrajectoryPoint) -> Vec3 {
    earth::ned_offset_m(
        (truth.lat_rad, truth.lon_rad, truth.height_m),
        (nav.lat_rad, nav.lon_rad, nav.height_m),
    )
}

/// The record at (the last epoch at or before) `t`.
fn at(run: &ForwardRun, t: f64) -> &driftless::nav::filter::EpochRecord {
    let i = run
        .epochs
        .partition_point(|e| e.nav.time_s <= t + 1e-9)
        .saturating_sub(1);
    &run.epochs[i]
}

fn horiz_err_at<T: Trajectory>(run: &ForwardRun, traj: &T, t: f64) -> f64 {
    let e = at(run, t);
    let d = pos_err(&e.nav, &traj.point(e.nav.time_s));
    d[0].hypot(d[1])
}

struct Data {
    traj: LandVehicle,
    imu: Vec<ImuIncrement>,
    gnss: GnssFixes,
}

fn data(c_vb: Mat3, vib: Option<Vibration>) -> Data {
    let traj = drive(c_vb);
    assert!(traj.duration_s() <= DURATION);
    let imu = simulate_imu(&traj, 21, vib);
    let gnss = simulate_gnss(&traj, 22);
    Data { traj, imu, gnss }
}

fn run(d: &Data, cfg: &FilterConfig) -> (ForwardRun, f64) {
    let t = std::time::Instant::now();
    let r = run_forward(&d.imu, &d.gnss, initial(&d.traj), cfg).expect("forward run");
    let us = t.elapsed().as_secs_f64() / r.epochs.len() as f64 * 1e6;
    (r, us)
}

/// The composite trajectory is exact: the truth's velocity is along the vehicle axis
/// (non-holonomic) and finite differences of position reproduce the velocity.
#[test]
fn land_vehicle_trajectory_is_consistent() {
    let c_vb = Euler {
        roll_rad: 1.0 * DEG,
        pitch_rad: -4.0 * DEG,
        yaw_rad: 6.0 * DEG,
    }
    .to_dcm();
    let traj = drive(c_vb);
    for t in [5.0, 14.0, 43.0, 70.0, 120.0, 230.0, 320.0, 340.0, 420.0] {
        let p = traj.point(t);
        // vehicle-frame velocity: C_vb C_nb v^n
        let v_b = p.c_bn.t().mul_vec(p.vel_ned_m_s);
        let v_v = c_vb.mul_vec(v_b);
        // (the local-coordinate scaling tilts v^n from the path yaw by ≈ tan φ·Δn/R,
        // ≲ 1e-4 rad within a few km: ≤ 1.5 mm/s at 15 m/s, 1.5 % of the NHC σ)
        assert!(
            v_v[1].abs() <= 2e-4 * v_v[0].abs() && v_v[2].abs() < 1e-9,
            "t {t}: {v_v:?}"
        );
        let d = 1e-3;
        let (a, b) = (traj.point(t + d), traj.point(t - d));
        let rm = earth::meridian_radius_m(p.lat_rad) + p.height_m;
        let rn = earth::prime_vertical_radius_m(p.lat_rad) + p.height_m;
        let vn = (a.lat_rad - b.lat_rad) / (2.0 * d) * rm;
        let ve = (a.lon_rad - b.lon_rad) / (2.0 * d) * rn * p.lat_rad.cos();
        assert!((vn - p.vel_ned_m_s[0]).abs() < 1e-4, "t {t}");
        assert!((ve - p.vel_ned_m_s[1]).abs() < 1e-4, "t {t}");
        for k in 0..2 {
            let acc = (a.vel_ned_m_s[k] - b.vel_ned_m_s[k]) / (2.0 * d);
            assert!((acc - p.acc_ned_m_s2[k]).abs() < 1e-4, "t {t} acc {k}");
        }
    }
    // Segment joins are continuous in position and velocity.
    for t0 in traj.segment_starts_s() {
        let (a, b) = (traj.point(t0 - 1e-9), traj.point(t0 + 1e-9));
        let d = pos_err(&a.nav_state(t0), &b);
        assert!(d.iter().all(|v| v.abs() < 1e-6), "join {t0}: {d:?}");
        for k in 0..3 {
            assert!((a.vel_ned_m_s[k] - b.vel_ned_m_s[k]).abs() < 1e-6);
        }
    }
}

/// (a) NHC during a 60-s outage in motion; (d) with a mounting rotation, configured or
/// not.
#[test]
fn nhc_bounds_outage_drift_and_needs_the_mounting() {
    let id = data(Mat3::IDENTITY, None);
    let base = base_config();
    let (r0, us0) = run(&id, &base);
    let mut cfg = base_config();
    cfg.nhc = Some(NhcConfig::default());
    let (r1, us1) = run(&id, &cfg);
    let t_end = OUTAGE_MOTION.1;
    let (e0, e1) = (
        horiz_err_at(&r0, &id.traj, t_end),
        horiz_err_at(&r1, &id.traj, t_end),
    );
    eprintln!(
        "(a) end of 60-s outage in motion: horizontal error without NHC {e0:.2} m, with NHC \
         {e1:.2} m (×{:.1}); NHC updates {} accepted / {} rejected; {:.2} vs {:.2} µs/epoch",
        e0 / e1,
        r1.nhc_applied,
        r1.aids_rejected,
        us0,
        us1
    );
    assert_eq!(r0.nhc_applied, 0);
    assert!(r1.nhc_applied > 3000, "{}", r1.nhc_applied);
    assert!(e1 < 0.5 * e0, "NHC {e1} m vs none {e0} m");
    assert!(e1 < 5.0, "NHC outage error {e1} m");
    // GNSS bookkeeping unchanged by the aids.
    assert_eq!(r0.gnss_accepted, r1.gnss_accepted);
    // Aid updates are stored for the smoother: epoch indices strictly increasing, each
    // record's P prior/posterior present.
    assert!(
        r1.updates
            .windows(2)
            .all(|w| w[0].epoch_index < w[1].epoch_index)
    );
    let n_nhc = r1
        .updates
        .iter()
        .flat_map(|u| u.outcomes.iter())
        .filter(|o| o.kind == UpdateKind::Nhc)
        .count();
    assert_eq!(n_nhc, r1.nhc_applied + r1.aids_rejected);

    // (d) IMU rotated relative to the vehicle.
    let c_vb = Euler {
        roll_rad: 1.0 * DEG,
        pitch_rad: -4.0 * DEG,
        yaw_rad: 6.0 * DEG,
    }
    .to_dcm();
    let rot = data(c_vb, None);
    let (rn, _) = run(&rot, &base);
    let mut good = base_config();
    good.nhc = Some(NhcConfig::with_mounting(c_vb));
    let (rg, _) = run(&rot, &good);
    let (rb, _) = run(&rot, &cfg); // NHC assuming C_vb = I
    let (en, eg, eb) = (
        horiz_err_at(&rn, &rot.traj, t_end),
        horiz_err_at(&rg, &rot.traj, t_end),
        horiz_err_at(&rb, &rot.traj, t_end),
    );
    eprintln!(
        "(d) C_vb = E(1°, −4°, 6°): outage error without NHC {en:.2} m, NHC with C_vb \
         {eg:.2} m, NHC assuming I {eb:.2} m ({} of {} NHC rejected)",
        rb.aids_rejected,
        rb.aids_rejected + rb.nhc_applied
    );
    assert!(eg < 0.5 * en, "configured mounting {eg} vs none {en}");
    assert!(
        (eg - e1).abs() < 0.5 * e1.max(0.5),
        "rotation changes result: {eg} vs {e1}"
    );
    assert!(eb > 2.0 * eg, "misconfigured mounting {eb} vs {eg}");
}

/// (b) ZUPT holds the position at a standstill inside an outage; ZARU improves the
/// vertical gyro bias.
#[test]
fn zupt_holds_position_and_zaru_observes_vertical_gyro_bias() {
    let d = data(Mat3::IDENTITY, None);
    let base = base_config();
    let (r0, _) = run(&d, &base);
    let mut zupt_only = base_config();
    zupt_only.standstill = Some(StandstillConfig {
        zaru_sigma_rad_s: None,
        ..StandstillConfig::default()
    });
    let (r1, us1) = run(&d, &zupt_only);
    let mut both = base_config();
    both.standstill = Some(StandstillConfig::default());
    let (r2, us2) = run(&d, &both);
    let (t_a, t_b) = (OUTAGE_STOP.0 + 2.0, OUTAGE_STOP.0 + 32.0);
    let drift = |r: &ForwardRun| {
        let (a, b) = (at(r, t_a), at(r, t_b));
        let x = earth::ned_offset_m(
            (a.nav.lat_rad, a.nav.lon_rad, a.nav.height_m),
            (b.nav.lat_rad, b.nav.lon_rad, b.nav.height_m),
        );
        x[0].hypot(x[1]).hypot(x[2])
    };
    let bz = |r: &ForwardRun, t: f64| {
        let e = at(r, t);
        (
            (e.sensors.gyro_bias_rad_s[2] - GYRO_BIAS[2]) / DEG_PER_H,
            e.std[11] / DEG_PER_H,
        )
    };
    let yaw_err = |r: &ForwardRun, t: f64| {
        let e = at(r, t);
        let q_true = Quat::from_dcm(&d.traj.point(e.nav.time_s).c_bn);
        q_true.mul(&e.nav.q_bn.conj()).to_rotation_vector()[2] / DEG
    };
    let (d0, d1, d2) = (drift(&r0), drift(&r1), drift(&r2));
    let (h1, h2) = (
        yaw_err(&r1, OUTAGE_STOP.1) - yaw_err(&r1, OUTAGE_STOP.0),
        yaw_err(&r2, OUTAGE_STOP.1) - yaw_err(&r2, OUTAGE_STOP.0),
    );
    eprintln!(
        "(b) standstill in outage, estimated position change {t_a}–{t_b} s: no ZUPT {d0:.3} m, \
         ZUPT {:.1} mm, ZUPT+ZARU {:.1} mm; ZUPT {} ZARU {} updates; standstills {:?}; \
         {us1:.2} / {us2:.2} µs/epoch",
        d1 * 1e3,
        d2 * 1e3,
        r2.zupt_applied,
        r2.zaru_applied,
        r2.standstills
    );
    let t_s = OUTAGE_STOP.1;
    let (b_in, _) = bz(&r2, OUTAGE_STOP.0);
    let (b1, s1) = bz(&r1, t_s);
    let (b2, s2) = bz(&r2, t_s);
    eprintln!(
        "(b) vertical gyro bias error at {t_s} s (entering the stop {b_in:.1} °/h): ZUPT only \
         {b1:.1} °/h (σ {s1:.1}), ZUPT+ZARU {b2:.1} °/h (σ {s2:.1}); heading drift over \
         the stop: ZUPT only {h1:.3}°, ZUPT+ZARU {h2:.3}°"
    );
    assert!(d1 < 0.05 && d2 < 0.05, "ZUPT drift {d1} {d2} m");
    assert!(d0 > 10.0 * d2, "no-ZUPT drift {d0} m");
    assert!(r1.zaru_applied == 0 && r2.zaru_applied > 200);
    assert!(s2 < 0.5 * s1, "ZARU σ {s2} vs {s1}");
    assert!(b2.abs() < 0.5 * b1.abs().max(10.0), "ZARU {b2} vs {b1} °/h");
    assert!(b2.abs() < 3.0 * s2 + 1.0, "ZARU error {b2} vs σ {s2}");
    // ZARU stops the heading drift at rest (the gyro's ARW and residual z bias).
    assert!(h2.abs() < 0.5 * h1.abs(), "heading drift {h2}° vs {h1}°");
    // Detected stop matches the truth; outage-free record of ZUPT/ZARU in `updates`.
    assert!((r2.standstills[1].0 - STOPS[1].0).abs() < 0.5);
    let n_zero = r2
        .updates
        .iter()
        .flat_map(|u| u.outcomes.iter())
        .filter(|o| matches!(o.kind, UpdateKind::Zupt | UpdateKind::Zaru))
        .count();
    assert_eq!(n_zero, r2.zupt_applied + r2.zaru_applied + r2.aids_rejected);
}

/// (c) The detector finds the stops within ±0.5 s and nothing while driving.
#[test]
fn standstill_detector_finds_the_stops_only() {
    let check = |found: &[(f64, f64)], what: &str| {
        assert_eq!(found.len(), STOPS.len(), "{what}: {found:?}");
        for (f, s) in found.iter().zip(STOPS.iter()) {
            assert!(
                (f.0 - s.0).abs() <= 0.5 && (f.1 - s.1).abs() <= 0.5,
                "{what}: found {f:?}, true {s:?}"
            );
        }
    };
    // Realistic: vibration in motion (0.5 m/s², 1°/s per sample), IMU statistics alone
    // (no speed gate).
    let vib = data(
        Mat3::IDENTITY,
        Some(Vibration {
            accel_m_s2: 0.5,
            gyro_rad_s: 1.0 * DEG,
        }),
    );
    let mut cfg = base_config();
    cfg.outages_s.clear();
    cfg.standstill = Some(StandstillConfig {
        max_speed_m_s: None,
        ..StandstillConfig::default()
    });
    let (r, _) = run(&vib, &cfg);
    eprintln!(
        "(c) with vibration, no speed gate: standstills {:.2?}",
        r.standstills
    );
    check(&r.standstills, "vibration, IMU criteria only");

    // Vibration-free simulation: constant-speed straight driving is indistinguishable
    // from rest for the IMU; the speed gate (default) removes it.
    let calm = data(Mat3::IDENTITY, None);
    let (rn, _) = run(&calm, &cfg);
    let false_s: f64 = rn
        .standstills
        .iter()
        .filter(|(a, _)| STOPS.iter().all(|s| (a - s.0).abs() > 0.5))
        .map(|(a, b)| b - a)
        .sum();
    cfg.standstill = Some(StandstillConfig::default());
    let (rg, _) = run(&calm, &cfg);
    eprintln!(
        "(c) vibration-free: IMU criteria only {} intervals ({false_s:.0} s of false \
         standstill while cruising); with the 3 m/s speed gate {:.2?}",
        rn.standstills.len(),
        rg.standstills
    );
    assert!(false_s > 20.0, "vibration-free cruising should look static");
    check(&rg.standstills, "vibration-free, speed gate");

    // The detector on its own: samples of a steady turn (large mean rate) and a
    // steady 1 m/s² acceleration (|f| − g only 0.05 m/s²: caught by the horizontal
    // specific force, criterion 4b) are not static; rest is, after the minimum duration.
    let g = 9.79;
    let c = StandstillConfig::default();
    let mut det = StandstillDetector::new(&c, DT).expect("detector");
    let mut rng = Rng::seed_from_u64(5);
    let mut t = 0.0;
    let mut first = None;
    for k in 0..2000 {
        t += DT;
        let turn = k < 500;
        let accel = (500..1000).contains(&k);
        let w = [0.0, 0.0, if turn { 5.0 * DEG } else { 0.0 }];
        let f = [if accel { 1.0 } else { 0.0 }, 0.0, -g];
        let n = |s: f64, r: &mut Rng| s * r.normal();
        let st = det.push(
            t,
            w.map(|v| v + n(0.05 * DEG, &mut rng)),
            f.map(|v| v + n(0.02, &mut rng)),
            true,
            g,
            Some(&Mat3::IDENTITY), // level body: criterion 4b sees the acceleration
        );
        if st && first.is_none() {
            first = Some(t);
        }
        assert!(!(st && k < 1000), "static at sample {k}");
    }
    let first = first.expect("standstill declared");
    eprintln!(
        "(c) unit: rest from 5.0 s declared at {first:.3} s, intervals {:?}",
        det.intervals()
    );
    assert!((first - 6.0).abs() < 0.02);
    let iv = det.finish();
    assert_eq!(iv.len(), 1);
    assert!(
        (iv[0].0 - 5.0).abs() < 0.02 && (iv[0].1 - t).abs() < 1e-9,
        "{iv:?}"
    );
}

/// Invalid aid settings are configuration errors.
#[test]
fn invalid_aid_settings_are_rejected() {
    let mut cfg = base_config();
    cfg.nhc = Some(NhcConfig {
        sigma_m_s: [0.0, 0.1],
        ..NhcConfig::default()
    });
    assert!(cfg.validate().is_err());
    cfg.nhc = Some(NhcConfig::with_mounting(Mat3::diag([1.0, 1.0, 2.0])));
    assert!(cfg.validate().is_err());
    cfg.nhc = None;
    cfg.standstill = Some(StandstillConfig {
        gyro_std_max_rad_s: 0.3, // degrees given as radians
        ..StandstillConfig::default()
    });
    assert!(cfg.validate().is_err());
    cfg.standstill = Some(StandstillConfig {
        window_s: f64::NAN,
        ..StandstillConfig::default()
    });
    assert!(cfg.validate().is_err());
    cfg.standstill = Some(StandstillConfig::default());
    cfg.nhc = Some(NhcConfig::default());
    assert!(cfg.validate().is_ok());
}

/// `run_forward_observed` hands out every epoch record once, in order, in its final
/// form (GNSS and vehicle-aid updates rewrite the newest record after it is pushed),
/// and changes nothing in the run.
#[test]
fn observer_sees_the_final_records() {
    use driftless::nav::filter::run::OBSERVER_BLOCK;
    use driftless::nav::filter::run_forward_observed;
    let d = data(Mat3::IDENTITY, None);
    let mut cfg = base_config();
    cfg.nhc = Some(NhcConfig::default());
    cfg.standstill = Some(StandstillConfig::default());
    let plain = run_forward(&d.imu, &d.gnss, initial(&d.traj), &cfg).expect("forward run");
    let mut seen = Vec::new();
    let mut blocks = 0;
    let observed = run_forward_observed(
        &d.imu,
        &d.gnss,
        initial(&d.traj),
        &cfg,
        &mut |b| {
            blocks += 1;
            seen.extend_from_slice(b);
        },
        true,
    )
    .expect("forward run");
    assert_eq!(observed, plain);
    assert!(plain.nhc_applied > 0 && plain.zupt_applied > 0 && plain.gnss_accepted > 0);
    assert_eq!(seen, plain.epochs);
    assert!(blocks > 1 && blocks <= plain.epochs.len() / OBSERVER_BLOCK + 1);
    // Dropping the records once observed: the same records reach the observer, the
    // update records point at the same epochs, the run keeps only its tail.
    let mut seen2 = Vec::new();
    let lean = run_forward_observed(
        &d.imu,
        &d.gnss,
        initial(&d.traj),
        &cfg,
        &mut |b| seen2.extend_from_slice(b),
        false,
    )
    .expect("forward run");
    assert_eq!(seen2, plain.epochs);
    assert_eq!(lean.updates, plain.updates);
    assert_eq!(lean.first_epoch + lean.epochs.len(), plain.epochs.len());
    assert!(lean.epochs.len() <= OBSERVER_BLOCK + 1);
    assert!(
        driftless::nav::filter::smoother::smooth(&lean, &initial(&d.traj), &cfg).is_err(),
        "a run without its records cannot be smoothed"
    );
}

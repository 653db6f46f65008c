//! Closed-form acceptance of the strapdown mechanization:
//! perfect increments from `sim::ideal_imu`, mechanization started from the true state,
//! errors against the analytic truth. Run in release; the figures are printed for
//! VALIDATION.md.

use driftless::nav::earth;
use driftless::nav::mechanization::{NavState, mechanize};
use driftless::sim::ideal_imu::{
    ConstantTurn, Stationary, StraightRun, Trajectory, ideal_increments,
};
use driftless_model::units::DEG;

const RATE_HZ: f64 = 200.0;

#[derive(Debug, Default)]
struct Errors {
    /// Largest horizontal position error over the run, m.
    horiz_max_m: f64,
    /// Horizontal error at the end, m.
    horiz_end_m: f64,
    /// |∫(v_est − v_true)_NE dt| at the end, m: the horizontal drift implied by the
    /// velocity error, not limited by the ≈ 0.7 nm resolution of latitude/longitude in
    /// f64 radians (which rounds sub-nanometre steps away at rest).
    horiz_from_vel_m: f64,
    /// Largest vertical error, m.
    vert_max_m: f64,
    /// Largest velocity error norm, m/s.
    vel_max_m_s: f64,
    /// Largest attitude error angle, rad.
    att_max_rad: f64,
}

/// Mechanize `duration_s` of ideal increments from the true state at t = 0, comparing
/// with the truth at every epoch.
fn run<T: Trajectory>(traj: &T, duration_s: f64) -> (Errors, NavState) {
    let dt = 1.0 / RATE_HZ;
    let n = (duration_s * RATE_HZ).round() as usize;
    let mut state = traj.point(0.0).nav_state(0.0);
    let mut incs = ideal_increments(traj, 0.0, dt, n + 1);
    // The increment over (−Δt, 0] primes the two-sample corrections.
    let mut prev = incs.next().expect("n + 1 ≥ 1 increments");
    let mut e = Errors::default();
    let mut drift_ne = [0.0f64; 2];
    let mut dv_prev = [0.0f64; 3];
    for (k, inc) in incs.enumerate() {
        state = mechanize(&state, &prev, &inc);
        prev = inc;
        let t = (k + 1) as f64 * dt;
        let truth = traj.point(t);
        let d = earth::ned_offset_m(
            (truth.lat_rad, truth.lon_rad, truth.height_m),
            (state.lat_rad, state.lon_rad, state.height_m),
        );
        let horiz = d[0].hypot(d[1]);
        e.horiz_max_m = e.horiz_max_m.max(horiz);
        e.horiz_end_m = horiz;
        e.vert_max_m = e.vert_max_m.max(d[2].abs());
        let dv = [0, 1, 2].map(|i| state.vel_ned_m_s[i] - truth.vel_ned_m_s[i]);
        drift_ne[0] += 0.5 * (dv_prev[0] + dv[0]) * dt;
        drift_ne[1] += 0.5 * (dv_prev[1] + dv[1]) * dt;
        dv_prev = dv;
        e.vel_max_m_s = e
            .vel_max_m_s
            .max((dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]).sqrt());
        let q_true = truth.nav_state(t).q_bn;
        let r = q_true.conj().mul(&state.q_bn).to_rotation_vector();
        e.att_max_rad = e
            .att_max_rad
            .max((r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt());
        assert!((state.time_s - t).abs() < 1e-9);
    }
    e.horiz_from_vel_m = drift_ne[0].hypot(drift_ne[1]);
    (e, state)
}

#[test]
fn stationary_30n_one_hour_drift_below_1mm() {
    let traj = Stationary {
        lat_rad: 30.0 * DEG,
        lon_rad: 114.0 * DEG,
        height_m: 25.0,
        attitude: driftless::nav::attitude::Euler {
            roll_rad: 1.0 * DEG,
            pitch_rad: -2.0 * DEG,
            yaw_rad: 75.0 * DEG,
        },
    };
    let (e, _) = run(&traj, 3600.0);
    eprintln!(
        "stationary 30°N 1 h @200 Hz: horizontal max {:.3e} m (end {:.3e} m, from ∫velocity error {:.3e} m), vertical max {:.3e} m, \
         velocity max {:.3e} m/s, attitude max {:.3e} rad",
        e.horiz_max_m,
        e.horiz_end_m,
        e.horiz_from_vel_m,
        e.vert_max_m,
        e.vel_max_m_s,
        e.att_max_rad
    );
    assert!(e.horiz_max_m < 1e-3, "{e:?}");
    assert!(e.horiz_from_vel_m < 1e-3, "{e:?}");
    // Vertical: the free-inertial vertical channel is unstable (time constant
    // √(R/2g) ≈ 570 s), so rounding at 1e-13 m/s² grows ~270-fold over the hour.
    assert!(e.vert_max_m < 1e-3, "{e:?}");
    assert!(e.vel_max_m_s < 1e-8, "{e:?}");
    assert!(e.att_max_rad < 1e-12, "{e:?}");
}

#[test]
fn constant_rate_turn_60s_below_1mm() {
    // 20 m/s, 15°/s (2.5 full circles in 60 s, 1.35 m/s² centripetal), tilted mount.
    let traj = ConstantTurn {
        lat_rad: 30.0 * DEG,
        lon_rad: 114.0 * DEG,
        height_m: 50.0,
        speed_m_s: 20.0,
        yaw0_rad: 20.0 * DEG,
        yaw_rate_rad_s: 15.0 * DEG,
        roll_rad: 2.0 * DEG,
        pitch_rad: -1.5 * DEG,
    };
    let (e, _) = run(&traj, 60.0);
    eprintln!(
        "turn 20 m/s 15°/s 60 s @200 Hz: horizontal max {:.3e} m (end {:.3e} m, from ∫velocity error {:.3e} m), vertical max {:.3e} m, \
         velocity max {:.3e} m/s, attitude max {:.3e} rad",
        e.horiz_max_m,
        e.horiz_end_m,
        e.horiz_from_vel_m,
        e.vert_max_m,
        e.vel_max_m_s,
        e.att_max_rad
    );
    assert!(e.horiz_max_m < 1e-3, "{e:?}");
    assert!(e.vert_max_m < 1e-3, "{e:?}");
    assert!(e.vel_max_m_s < 1e-6, "{e:?}");
    assert!(e.att_max_rad < 1e-9, "{e:?}");
}

#[test]
fn constant_acceleration_run_60s_below_1mm() {
    // 5 → 125 m/s at 2 m/s² on heading 30°, climbing at 3° (3.9 km, 200 m up).
    let traj = StraightRun {
        lat_rad: 30.0 * DEG,
        lon_rad: 114.0 * DEG,
        height_m: 50.0,
        yaw_rad: 30.0 * DEG,
        climb_rad: 3.0 * DEG,
        roll_rad: 1.0 * DEG,
        speed0_m_s: 5.0,
        accel_m_s2: 2.0,
    };
    let (e, end) = run(&traj, 60.0);
    eprintln!(
        "straight 2 m/s² 60 s @200 Hz: horizontal max {:.3e} m (end {:.3e} m, from ∫velocity error {:.3e} m), vertical max {:.3e} m, \
         velocity max {:.3e} m/s, attitude max {:.3e} rad",
        e.horiz_max_m,
        e.horiz_end_m,
        e.horiz_from_vel_m,
        e.vert_max_m,
        e.vel_max_m_s,
        e.att_max_rad
    );
    // The run really went somewhere.
    let start = traj.point(0.0);
    let d = earth::ned_offset_m(
        (start.lat_rad, start.lon_rad, start.height_m),
        (end.lat_rad, end.lon_rad, end.height_m),
    );
    assert!(d[0].hypot(d[1]) > 3800.0 && d[2] < -190.0, "{d:?}");
    assert!(e.horiz_max_m < 1e-3, "{e:?}");
    assert!(e.vert_max_m < 1e-3, "{e:?}");
    assert!(e.vel_max_m_s < 1e-7, "{e:?}");
    assert!(e.att_max_rad < 1e-10, "{e:?}");
}

//! Innovation gating, outage-window semantics and the gate-recovery rule of the GNSS/INS
//! filter on a simulated hand-held walk: an exact composite trajectory
//! (`sim::ideal_imu::LandVehicle`: 1.2 m/s, tight turns of 45–90 °/s, stops) with
//! consumer-grade IMU errors (biases 0.04–0.06 °/s and 8–15 mg, ARW 0.3 °/√h,
//! VRW 0.1 m/s/√h, 200 Hz) and 4-Hz GNSS whose formal σ is 1 cm while the actual error
//! is 1 cm white plus a Gauss–Markov error of 25 cm (horizontal) / 40 cm (vertical) σ
//! correlated over 10 s (`sim::gnss`, antenna motion and multipath of a hand-held RTK
//! rover). Run with `cargo test --release`; the measured figures are printed.

use driftless::io::nav::GnssFixes;
use driftless::nav::attitude::Euler;
use driftless::nav::earth;
use driftless::nav::filter::{
    FilterConfig, ForwardRun, Gate, GaussMarkov, ImuNoise, InitialState, UpdateKind, run_forward,
};
use driftless::nav::mechanization::{ImuIncrement, NavState};
use driftless::nav::outage::OutageWindow;
use driftless::nav::pipeline::ImuStream;
use driftless::nav::session::{SessionConfig, run_session};
use driftless::sim::gnss::{GnssSimConfig, simulate_gnss};
use driftless::sim::ideal_imu::{DriveSegment, LandVehicle, Trajectory};
use driftless_model::linalg::{Mat3, Vec3};
use driftless_model::units::{DEG, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MILLI_G};

#[path = "common/nav_sim.rs"]
mod nav_sim;
use nav_sim::{perturbed_start, simulate_imu_with};

const DT: f64 = 0.005;
const LAT0: f64 = 30.0 * DEG;
const LON0: f64 = 114.0 * DEG;
const H0: f64 = 50.0;
const GYRO_BIAS: Vec3 = [0.05 * DEG, -0.04 * DEG, 0.06 * DEG];
const ACCEL_BIAS: Vec3 = [10.0 * MILLI_G, -8.0 * MILLI_G, 15.0 * MILLI_G];
const ARW: f64 = 0.3 * DEG_PER_SQRT_H;
const VRW: f64 = 0.1 * M_PER_S_PER_SQRT_H;
const WALK_M_S: f64 = 1.2;

fn walk_segments() -> Vec<DriveSegment> {
    use DriveSegment::{Speed, Stop, Turn};
    let sp = |to_m_s: f64, duration_s: f64| Speed { to_m_s, duration_s };
    let tn = |deg: f64, duration_s: f64| Turn {
        angle_rad: deg * DEG,
        duration_s,
    };
    let mut s = vec![Stop { duration_s: 10.0 }];
    for _ in 0..3 {
        s.extend([
            sp(WALK_M_S, 3.0),
            sp(WALK_M_S, 15.0),
            tn(90.0, 2.0),
            sp(WALK_M_S, 10.0),
            tn(-120.0, 3.0),
            sp(WALK_M_S, 20.0),
            tn(180.0, 4.0),
            sp(WALK_M_S, 12.0),
            sp(0.0, 2.0),
            Stop { duration_s: 5.0 },
            sp(WALK_M_S, 3.0),
            tn(-90.0, 2.0),
            sp(WALK_M_S, 15.0),
        ]);
    }
    s
}

/// The walk; its duration, s.
fn walk() -> (LandVehicle, f64) {
    let t = LandVehicle::new(
        LAT0,
        LON0,
        H0,
        20.0 * DEG,
        0.0,
        Mat3::IDENTITY,
        &walk_segments(),
    );
    let d = t.duration_s();
    (t, d)
}

/// 4-Hz fixes at the IMU with 1 cm white + 25/40 cm correlated error, reported σ 1 cm.
fn simulate_rtk<T: Trajectory>(traj: &T, duration_s: f64, seed: u64) -> GnssFixes {
    let mut c = GnssSimConfig::new(4.0, 0.25, duration_s, 0.01);
    c.correlated_sigma_ned_m = [0.25, 0.25, 0.4];
    c.correlated_tau_s = 10.0;
    let mut g = simulate_gnss(traj, &c, seed).expect("GNSS simulation");
    for s in &mut g.sigma_ned_m {
        *s = [0.01; 3];
    }
    g
}

/// Consumer-grade filter noise (1.5 × the simulated white noise, biases GM 1 h).
fn consumer_config() -> FilterConfig {
    let gm = |sigma| GaussMarkov {
        sigma,
        tau_s: 3600.0,
    };
    FilterConfig::new(
        ImuNoise {
            gyro_arw_rad_sqrt_s: 1.5 * ARW,
            accel_vrw_m_s_sqrt_s: 1.5 * VRW,
            gyro_bias: gm(0.1 * DEG),
            accel_bias: gm(20.0 * MILLI_G),
            gyro_scale: gm(3000e-6),
            accel_scale: gm(3000e-6),
        },
        [0.0; 3],
    )
}

/// Truth at t = 0 (at rest) perturbed by 0.3 m, 0.05 m/s, (0.3°, −0.3°, 2°).
fn initial<T: Trajectory>(traj: &T) -> InitialState {
    perturbed_start(traj, 0.05, [0.3 * DEG, -0.3 * DEG, 2.0 * DEG], 0.3)
}

/// Horizontal error of the estimated IMU position against the truth, m.
fn horizontal_error<T: Trajectory>(traj: &T, nav: &NavState) -> f64 {
    let p = traj.point(nav.time_s);
    let d = earth::ned_offset_m(
        (p.lat_rad, p.lon_rad, p.height_m),
        (nav.lat_rad, nav.lon_rad, nav.height_m),
    );
    d[0].hypot(d[1])
}

/// RMS horizontal error over the epochs from `t0` on (every 10th), m.
fn rms_from<T: Trajectory>(run: &ForwardRun, traj: &T, t0: f64) -> f64 {
    let e: Vec<f64> = run
        .epochs
        .iter()
        .step_by(10)
        .filter(|e| e.nav.time_s >= t0)
        .map(|e| horizontal_error(traj, &e.nav).powi(2))
        .collect();
    (e.iter().sum::<f64>() / e.len() as f64).sqrt()
}

/// Position outcomes of a run, in time order.
fn position_outcomes(run: &ForwardRun) -> Vec<driftless::nav::filter::UpdateOutcome> {
    run.updates
        .iter()
        .flat_map(|u| u.outcomes.iter())
        .filter(|o| o.kind == UpdateKind::Position)
        .copied()
        .collect()
}

struct Walk {
    traj: LandVehicle,
    duration_s: f64,
    imu: Vec<ImuIncrement>,
    gnss: GnssFixes,
}

fn walk_data() -> Walk {
    let (traj, duration_s) = walk();
    let imu = simulate_imu_with(&traj, duration_s, 31, [GYRO_BIAS, ACCEL_BIAS], [ARW, VRW]);
    let gnss = simulate_rtk(&traj, duration_s, 32);
    Walk {
        traj,
        duration_s,
        imu,
        gnss,
    }
}

#[test]
fn gate_text_forms() {
    for (text, want) in [
        ("off", Gate::Off),
        ("OFF", Gate::Off),
        ("chi2:0.9999", Gate::Chi2 { p: 0.9999 }),
        (" chi2 : 0.99 ", Gate::Chi2 { p: 0.99 }),
        ("robust", Gate::default()),
        (
            "robust:0.95:0.999:30",
            Gate::Robust {
                p_inflate: 0.95,
                p_reject: 0.999,
                max_sigma_scale: 30.0,
            },
        ),
    ] {
        let g: Gate = text.parse().unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(g, want, "{text}");
        // Display round-trips.
        assert_eq!(g.to_string().parse::<Gate>().expect("round trip"), g);
    }
    assert_eq!(Gate::default().to_string(), "robust");
    assert!(matches!(Gate::default(), Gate::Robust { .. }));
    for bad in [
        "",
        "chi2",
        "chi2:",
        "chi2:1.5",
        "chi2:0",
        "chi2:x",
        "huber",
        "robust:0.9",
        "robust:0.99:0.9:100",
        "robust:0.99:0.9999:0.5",
        "off:1",
    ] {
        let e = bad.parse::<Gate>().expect_err(bad).to_string();
        assert!(
            e.contains("off") && e.contains("chi2:P") && e.contains("robust"),
            "{bad}: {e}"
        );
    }
    let mut c = consumer_config();
    c.gate = Gate::Chi2 { p: 1.0 };
    assert!(c.validate().is_err());
}

/// The default (robust) gate keeps the fixes whose 1-cm formal σ understates 25–40 cm of
/// correlated error; the χ² test drops many of them.
#[test]
fn robust_gate_does_not_starve_on_optimistic_rtk_sigma() {
    let w = walk_data();
    let init = initial(&w.traj);
    let robust = consumer_config();
    let mut chi2 = consumer_config();
    chi2.gate = Gate::Chi2 { p: 0.9999 };
    let rr = run_forward(&w.imu, &w.gnss, init, &robust).expect("robust run");
    let rc = run_forward(&w.imu, &w.gnss, init, &chi2).expect("χ² run");
    let n = w.gnss.len() as f64;
    let (fr, fc) = (rr.gnss_rejected as f64 / n, rc.gnss_rejected as f64 / n);
    let (er, ec) = (rms_from(&rr, &w.traj, 30.0), rms_from(&rc, &w.traj, 30.0));
    eprintln!(
        "walk {:.0} s, {} fixes: robust rejected {} ({:.2} %), inflated {}, forced {}, RMS {:.3} m; \
         chi2:0.9999 rejected {} ({:.1} %), forced {}, RMS {:.3} m",
        w.duration_s,
        w.gnss.len(),
        rr.gnss_rejected,
        100.0 * fr,
        rr.gnss_inflated,
        rr.gnss_forced,
        er,
        rc.gnss_rejected,
        100.0 * fc,
        rc.gnss_forced,
        ec
    );
    assert!(fr < 0.02, "robust gate rejected {:.2} %", 100.0 * fr);
    assert!(rr.gnss_inflated > 0 && rr.gnss_inflated <= rr.gnss_accepted);
    assert!(fc > 0.1 && fc > 5.0 * fr, "χ² rejected {:.1} %", 100.0 * fc);
    assert_eq!(rc.gnss_inflated, 0);
    // The robust solution follows the (25-cm-correlated) fixes: within 1.5 × their own
    // horizontal error, and better than the starved χ² solution.
    let gnss_rms = (w
        .gnss
        .time_s
        .iter()
        .enumerate()
        .filter(|(_, t)| **t >= 30.0)
        .map(|(i, &t)| {
            let p = w.traj.point(t);
            let d = earth::ned_offset_m(
                (p.lat_rad, p.lon_rad, p.height_m),
                (w.gnss.lat_rad[i], w.gnss.lon_rad[i], w.gnss.height_m[i]),
            );
            d[0].powi(2) + d[1].powi(2)
        })
        .sum::<f64>()
        / w.gnss.time_s.iter().filter(|t| **t >= 30.0).count() as f64)
        .sqrt();
    eprintln!("  GNSS horizontal error RMS {gnss_rms:.3} m");
    assert!(er < 1.5 * gnss_rms && er < ec, "robust RMS {er} m");
    // Every accepted robust update reports its inflation factor.
    for o in position_outcomes(&rr) {
        assert!(o.r_scale >= 1.0 && o.r_scale <= 1e4 + 1e-6, "{o:?}");
    }
}

/// A single 50-m jump is rejected under the default gate; the state is untouched.
#[test]
fn fifty_metre_jump_is_rejected_by_the_robust_gate() {
    let mut w = walk_data();
    let idx = w
        .gnss
        .time_s
        .iter()
        .position(|&t| (t - 120.0).abs() < 1e-9)
        .expect("fix at 120 s");
    let rm = earth::meridian_radius_m(w.gnss.lat_rad[idx]);
    w.gnss.lat_rad[idx] += 50.0 / rm;
    let run = run_forward(&w.imu, &w.gnss, initial(&w.traj), &consumer_config()).expect("run");
    let rej: Vec<_> = run.rejections().collect();
    eprintln!(
        "50 m jump: rejections {:?}",
        rej.iter().map(|o| (o.time_s, o.nis)).collect::<Vec<_>>()
    );
    assert!(rej.iter().any(|o| (o.time_s - 120.0).abs() < 1e-9));
    let e = run
        .epochs
        .iter()
        .find(|e| e.nav.time_s >= 120.0)
        .expect("epoch");
    let err = horizontal_error(&w.traj, &e.nav);
    eprintln!("  horizontal error right after the jump {err:.3} m");
    assert!(err < 1.0, "{err}");
}

/// One gyro sample of 1e6 rad/s about x (5000 rad in one increment: a roll jump of
/// −82° and, through the rotation correction of the velocity increment, a velocity error
/// of ~10⁵ m/s) wrecks the state; under the default gate the gate-recovery rule resets the
/// navigation states after five rejected fixes (1.25 s at 4 Hz, before the 3-s clock),
/// the fixes are accepted again and the run ends as good as without the spike.
#[test]
fn gyro_spike_is_recovered_from() {
    let clean = walk_data();
    let cfg = consumer_config();
    let base = run_forward(&clean.imu, &clean.gnss, initial(&clean.traj), &cfg).expect("run");
    let mut w = walk_data();
    let k = w
        .imu
        .iter()
        .position(|i| i.time_s >= 100.0)
        .expect("epoch at 100 s");
    w.imu[k].dtheta_rad[0] += 1e6 * DT;
    let run = run_forward(&w.imu, &w.gnss, initial(&w.traj), &cfg).expect("run");
    let pos = position_outcomes(&run);
    let first_ok = pos
        .iter()
        .filter(|o| o.time_s > 100.0)
        .find(|o| o.accepted)
        .map(|o| o.time_s)
        .expect("an accepted fix after the spike");
    let after: Vec<_> = pos.iter().filter(|o| o.time_s > 110.0).collect();
    let frac_ok = after.iter().filter(|o| o.accepted).count() as f64 / after.len() as f64;
    let end = |r: &ForwardRun| horizontal_error(&w.traj, &r.epochs.last().expect("epochs").nav);
    let (rms, rms_base) = (
        rms_from(&run, &w.traj, 150.0),
        rms_from(&base, &w.traj, 150.0),
    );
    eprintln!(
        "gyro spike at 100 s: first accepted fix {:.2} s, forced {}, resets {}, rejected {}, \
         accepted after 110 s {:.1} %; from 150 s RMS {:.3} m (without the spike {:.3} m); end \
         error {:.3} m (without {:.3} m)",
        first_ok,
        run.gnss_forced,
        run.gnss_resets,
        run.gnss_rejected,
        100.0 * frac_ok,
        rms,
        rms_base,
        end(&run),
        end(&base)
    );
    assert!(
        first_ok <= 103.0 + 1e-9,
        "first accepted fix at {first_ok} s"
    );
    assert_eq!((run.gnss_forced, run.gnss_resets), (1, 1));
    assert_eq!(base.gnss_forced, 0);
    assert!(frac_ok > 0.98, "{frac_ok}");
    assert!(rms < 1.2 * rms_base, "RMS {rms} m vs {rms_base} m");
    assert!(
        end(&run) < 2.0 * end(&base) + 0.2,
        "end error {} m",
        end(&run)
    );
}

/// Outage windows are half-open (s, e]: the fix exactly at s is used, the one exactly at
/// e is withheld; the recovery clock does not run inside the window, and after 30 s of
/// dead reckoning on the biased consumer IMU the first fix after the window is accepted
/// (not forced) under the default gate.
#[test]
fn outage_window_is_half_open_and_the_first_fix_after_it_is_accepted() {
    let w = walk_data();
    let mut cfg = consumer_config();
    cfg.outages_s = vec![(150.0, 180.0)];
    let run = run_forward(&w.imu, &w.gnss, initial(&w.traj), &cfg).expect("run");
    let pos = position_outcomes(&run);
    let at = |t: f64| pos.iter().find(|o| (o.time_s - t).abs() < 1e-9);
    assert!(at(150.0).is_some_and(|o| o.accepted), "fix at s used");
    assert!(at(180.0).is_none(), "fix at e withheld");
    assert!(pos.iter().all(|o| !(o.time_s > 150.0 && o.time_s <= 180.0)));
    assert_eq!(run.gnss_withheld, 120); // 150.25, 150.5, …, 180.0 at 4 Hz
    let first = pos
        .iter()
        .find(|o| o.time_s > 180.0)
        .expect("fix after the window");
    eprintln!(
        "30 s outage: first fix after it at {:.2} s, innovation {:.3?} m, NIS {:.1}, R × {:.1}, \
         accepted {}; forced {}",
        first.time_s, first.innovation, first.nis, first.r_scale, first.accepted, run.gnss_forced
    );
    assert!((first.time_s - 180.25).abs() < 1e-9);
    assert!(first.accepted);
    assert_eq!(run.gnss_forced, 0);
    // The outage was real: the prediction was off by more than the fixes' noise.
    assert!(first.innovation[0].hypot(first.innovation[1]) > 0.3);
}

fn stream(imu: &[ImuIncrement]) -> ImuStream {
    ImuStream {
        source: "simulated walk".into(),
        gps_week: None,
        nominal_dt_s: DT,
        epochs: imu.to_vec(),
        gaps: Vec::new(),
        notes: Vec::new(),
    }
}

/// Yaw error of an epoch against the truth, rad (wrapped to ±π).
fn yaw_error<T: Trajectory>(traj: &T, nav: &NavState) -> f64 {
    let est = Euler::from_dcm(&nav.q_bn.to_dcm()).yaw_rad;
    let tru = Euler::from_dcm(&traj.point(nav.time_s).c_bn).yaw_rad;
    let d = est - tru;
    (d + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
}

fn walk_session() -> SessionConfig {
    let mut c = SessionConfig::new(consumer_config());
    // The hand-held rover's 1-cm formal σ floored, as a user would.
    c.sigma_floor_m = Some((0.1, 0.2));
    c
}

/// The default session aligns a 1.2 m/s walk (position-only 4-Hz GNSS) from the GNSS
/// course as soon as it walks, with roll and pitch levelled at the static start; it
/// converges, and the session's outage evaluation uses (s, e].
#[test]
fn session_aligns_a_walk_and_evaluates_half_open_outages() {
    let w = walk_data();
    let mut cfg = walk_session();
    cfg.outages = vec![OutageWindow {
        start_s: 150.0,
        end_s: 180.0,
    }];
    let res = run_session(&stream(&w.imu), &w.gnss, &cfg).expect("session");
    let t0 = res.init.nav.time_s;
    let yaw0 = yaw_error(&w.traj, &res.init.nav);
    let p0 = w.traj.point(t0);
    let speed0 = p0.vel_ned_m_s[0].hypot(p0.vel_ned_m_s[1]);
    let sig = res.init.sigma_att_rad;
    let last = res.run.epochs.last().expect("epochs");
    let yaw_end = yaw_error(&w.traj, &last.nav);
    let sig_end = last.std[8];
    // RMS from 60 s outside the outage and 10 s of reconvergence.
    let rms = {
        let e: Vec<f64> = res
            .run
            .epochs
            .iter()
            .step_by(10)
            .filter(|e| e.nav.time_s >= 60.0 && !(e.nav.time_s > 150.0 && e.nav.time_s <= 190.0))
            .map(|e| horizontal_error(&w.traj, &e.nav).powi(2))
            .collect();
        (e.iter().sum::<f64>() / e.len() as f64).sqrt()
    };
    eprintln!(
        "walk alignment at {t0:.2} s (true speed {speed0:.2} m/s): yaw error {:.2}° (σ {:.2}°), \
         roll/pitch σ {:.2}°/{:.2}°, primed bias {:?}; end yaw error {:.2}° (σ {:.2}°), RMS \
         from 60 s outside the outage {rms:.3} m; fixes rejected {} inflated {} forced {}",
        yaw0.to_degrees(),
        sig[2].to_degrees(),
        sig[0].to_degrees(),
        sig[1].to_degrees(),
        res.primed_gyro_bias_rad_s.is_some(),
        yaw_end.to_degrees(),
        sig_end.to_degrees(),
        res.run.gnss_rejected,
        res.run.gnss_inflated,
        res.run.gnss_forced
    );
    // Starts while accelerating to walking pace, i.e. below 1.2 m/s, right after the stop.
    assert!(t0 > 10.0 && t0 < 14.0, "start at {t0} s");
    assert!(res.primed_gyro_bias_rad_s.is_some());
    assert!(yaw0.abs() < 3.0 * sig[2] && sig[2] < 10f64.to_radians());
    // Levelled at the static start: σ from the accelerometer bias, not the 2° guess.
    assert!(sig[0] < 2f64.to_radians() && sig[0] == sig[1]);
    // Converged to a few degrees (the filter's σ, ≈ 1°, is optimistic here: the fixes'
    // 25-cm error correlated over 10 s is modelled as white 10-cm noise).
    assert!(
        yaw_end.abs() < 5f64.to_radians() && sig_end < 2f64.to_radians(),
        "end yaw error {yaw_end}"
    );
    assert!(rms < 1.0, "RMS {rms} m");
    // Evaluation of the window (150, 180]: end error = innovation of the fix at 180.25 s.
    let o = &res.outages[0];
    let first = position_outcomes(&res.run)
        .into_iter()
        .find(|x| x.time_s > 180.0)
        .expect("fix after the window");
    assert!((first.time_s - 180.25).abs() < 1e-9 && first.accepted);
    let want = first.innovation[0].hypot(first.innovation[1]);
    assert_eq!(o.end_horizontal_m, Some(want));
    assert!(o.max_horizontal_m >= 0.5 * want && o.max_horizontal_m.is_finite());
    assert_eq!(res.run.gnss_forced, 0);
}

/// A given yaw starts the filter at rest, at the first usable fix; without it a walk
/// slower than the alignment speed is a clear error naming what to change.
#[test]
fn given_yaw_starts_at_rest_and_too_slow_is_a_clear_error() {
    let w = walk_data();
    let mut cfg = walk_session();
    let true_yaw = Euler::from_dcm(&w.traj.point(1.0).c_bn).yaw_rad;
    cfg.initial_yaw_rad = Some(true_yaw + 3f64.to_radians());
    let res = run_session(&stream(&w.imu), &w.gnss, &cfg).expect("session");
    let t0 = res.init.nav.time_s;
    let last = res.run.epochs.last().expect("epochs");
    let yaw_end = yaw_error(&w.traj, &last.nav);
    let sig_end = last.std[8];
    let rms = rms_from(&res.run, &w.traj, 60.0);
    eprintln!(
        "given yaw: start at {t0:.2} s (at rest), yaw σ {:.1}°, end yaw error {:.2}° (σ {:.2}°), \
         RMS from 60 s {rms:.3} m",
        res.init.sigma_att_rad[2].to_degrees(),
        yaw_end.to_degrees(),
        sig_end.to_degrees()
    );
    assert!(t0 < 2.0, "start at {t0} s");
    assert!(w.traj.point(t0).vel_ned_m_s.iter().all(|v| v.abs() < 1e-9));
    assert!((res.init.sigma_att_rad[2] - 5f64.to_radians()).abs() < 1e-12);
    // Converged to a few degrees (the filter's σ, ≈ 1°, is optimistic here: the fixes'
    // 25-cm error correlated over 10 s is modelled as white 10-cm noise).
    assert!(
        yaw_end.abs() < 5f64.to_radians() && sig_end < 2f64.to_radians(),
        "end yaw error {yaw_end}"
    );
    assert!(rms < 1.0, "RMS {rms} m");
    // A full attitude given.
    let mut full = walk_session();
    full.initial_attitude_rad = Some([0.0, 0.0, true_yaw]);
    let res = run_session(&stream(&w.imu), &w.gnss, &full).expect("session");
    assert!(res.init.nav.time_s < 2.0);
    assert!((res.init.sigma_att_rad[0] - 1f64.to_radians()).abs() < 1e-12);
    // Too slow for a 3 m/s alignment speed, no yaw given.
    let mut slow = walk_session();
    slow.min_speed_m_s = 3.0;
    let e = run_session(&stream(&w.imu), &w.gnss, &slow)
        .expect_err("walk never reaches 3 m/s")
        .to_string();
    eprintln!("{e}");
    assert!(
        e.contains("--initial-yaw-deg") && e.contains("--align-min-speed") && e.contains("3 m/s"),
        "{e}"
    );
    assert!(
        e.contains("fastest usable fix moves at 1."),
        "names the speed reached: {e}"
    );
}

/// `accept_quality` skips the fixes with other RTKLIB flags (and says how many).
#[test]
fn quality_filter_skips_other_flags() {
    let mut w = walk_data();
    // Every 4th fix a float solution.
    for (i, q) in w.gnss.quality.iter_mut().enumerate() {
        if i % 4 == 0 {
            *q = driftless::io::nav::quality::FLOAT;
        }
    }
    let n_float = w.gnss.quality.iter().filter(|&&q| q == 2).count();
    let mut cfg = consumer_config();
    cfg.accept_quality = vec![driftless::io::nav::quality::FIX];
    let run = run_forward(&w.imu, &w.gnss, initial(&w.traj), &cfg).expect("run");
    assert_eq!(run.gnss_quality_skipped, n_float);
    let floats: Vec<f64> = (0..w.gnss.len())
        .filter(|&i| w.gnss.quality[i] == 2)
        .map(|i| w.gnss.time_s[i])
        .collect();
    assert!(
        position_outcomes(&run)
            .iter()
            .all(|o| !floats.iter().any(|t| (t - o.time_s).abs() < 1e-9))
    );
    assert_eq!(
        run.gnss_accepted + run.gnss_rejected,
        w.gnss.len() - n_float
    );
    // Empty list: every flag used.
    cfg.accept_quality.clear();
    let run = run_forward(&w.imu, &w.gnss, initial(&w.traj), &cfg).expect("run");
    assert_eq!(run.gnss_quality_skipped, 0);
}

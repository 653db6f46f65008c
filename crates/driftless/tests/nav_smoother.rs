//! Acceptance tests of the Rauch–Tung–Striebel smoother on the
//! simulation of `tests/nav_filter.rs` (analytic figure-of-eight drive, injected biases
//! and white noise, 1 Hz GNSS with 2 cm σ at a lever arm). Run with
//! `cargo test --release`; the measured figures are printed (eprintln).

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix equations

use driftless::nav::filter::state::check_covariance;
use driftless::nav::filter::{
    ForwardRun, NavError, SensorErrors, SmoothedRun, run_forward, smooth, smooth_with_covariances,
};
use driftless::nav::mechanization::NavState;
use driftless::sim::ideal_imu::Trajectory;
use driftless_model::linalg::Vec3;
use driftless_model::units::{DEG, DEG_PER_H};

#[path = "common/nav_sim.rs"]
mod nav_sim;
use nav_sim::*;

/// Per-epoch errors of a state sequence: horizontal position error (m), position
/// NED error, velocity error, attitude error.
struct Errs {
    t: f64,
    pos: Vec3,
    vel: Vec3,
    att: Vec3,
}

fn errors<T: Trajectory>(navs: impl Iterator<Item = NavState>, traj: &T) -> Vec<Errs> {
    navs.map(|nav| {
        let tr = traj.point(nav.time_s);
        Errs {
            t: nav.time_s,
            pos: pos_err(&nav, &tr),
            vel: std::array::from_fn(|k| nav.vel_ned_m_s[k] - tr.vel_ned_m_s[k]),
            att: att_err(&nav.q_bn, &tr.c_bn),
        }
    })
    .collect()
}

fn fwd_errors<T: Trajectory>(run: &ForwardRun, traj: &T) -> Vec<Errs> {
    errors(run.epochs.iter().map(|e| e.nav), traj)
}

fn sm_errors<T: Trajectory>(sm: &SmoothedRun, traj: &T) -> Vec<Errs> {
    errors(sm.epochs.iter().map(|e| e.nav), traj)
}

/// (RMS, max) of the horizontal error over epochs with t in [t0, t1].
fn h_stats(e: &[Errs], t0: f64, t1: f64) -> (f64, f64) {
    let (mut s, mut n, mut mx) = (0.0, 0usize, 0.0f64);
    for x in e.iter().filter(|x| x.t >= t0 && x.t <= t1) {
        let h = x.pos[0].hypot(x.pos[1]);
        s += h * h;
        n += 1;
        mx = mx.max(h);
    }
    ((s / n.max(1) as f64).sqrt(), mx)
}

fn rms_of(e: &[Errs], t0: f64, t1: f64, f: impl Fn(&Errs) -> f64) -> f64 {
    let v: Vec<f64> = e
        .iter()
        .filter(|x| x.t >= t0 && x.t <= t1)
        .map(|x| f(x).powi(2))
        .collect();
    (v.iter().sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// (a) Full GNSS: smoothed errors no larger than the forward ones; (c) boundary
/// condition at the last epoch; (d) P_s symmetric positive definite.
#[test]
fn full_gnss_smoothing_improves_and_keeps_boundary() {
    let sc = scenario(600.0);
    let cfg = config();
    let init = initial(&sc.traj);
    let t = std::time::Instant::now();
    let run = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run");
    let t_fwd = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let sm = smooth(&run, &init, &cfg).expect("smoother");
    let t_sm = t.elapsed().as_secs_f64();
    let n = run.epochs.len();
    assert_eq!(sm.epochs.len(), n);
    eprintln!(
        "full GNSS, {n} epochs: forward {:.3} s ({:.2} µs/epoch), smoother {:.3} s ({:.2} µs/epoch)",
        t_fwd,
        t_fwd / n as f64 * 1e6,
        t_sm,
        t_sm / n as f64 * 1e6
    );
    let ef = fwd_errors(&run, &sc.traj);
    let es = sm_errors(&sm, &sc.traj);
    let (rf, mf) = h_stats(&ef, 60.0, 600.0);
    let (rs, ms) = h_stats(&es, 60.0, 600.0);
    let vf = rms_of(&ef, 60.0, 600.0, |x| x.vel[0].hypot(x.vel[1]));
    let vs = rms_of(&es, 60.0, 600.0, |x| x.vel[0].hypot(x.vel[1]));
    let af = rms_of(&ef, 60.0, 600.0, |x| x.att[2]);
    let as_ = rms_of(&es, 60.0, 600.0, |x| x.att[2]);
    eprintln!(
        "full GNSS 60–600 s: horizontal RMS forward {:.2} mm (max {:.2}), smoothed {:.2} mm \
         (max {:.2}); velocity RMS {:.2} / {:.2} mm/s; heading RMS {:.4} / {:.4}°",
        rf * 1e3,
        mf * 1e3,
        rs * 1e3,
        ms * 1e3,
        vf * 1e3,
        vs * 1e3,
        af / DEG,
        as_ / DEG
    );
    assert!(rs <= rf, "smoothed horizontal RMS {rs} > forward {rf}");
    assert!(vs <= vf, "smoothed velocity RMS {vs} > forward {vf}");
    assert!(
        as_ <= af * 1.05,
        "smoothed heading RMS {as_} vs forward {af}"
    );
    // Smoothed σ never above the filtered σ (P_s ≤ P⁺).
    for (f, s) in run.epochs.iter().zip(&sm.epochs) {
        for i in 0..21 {
            assert!(
                s.std[i] <= f.std[i] * (1.0 + 1e-9),
                "σ_{i} at {}",
                f.nav.time_s
            );
        }
    }
    // (c) RTS boundary condition: at the last epoch smoothed = filtered.
    let (lf, ls) = (&run.epochs[n - 1], &sm.epochs[n - 1]);
    for i in 0..21 {
        assert!(
            (lf.std[i] - ls.std[i]).abs() <= 1e-9 * lf.std[i],
            "last-epoch σ_{i}: {} vs {}",
            lf.std[i],
            ls.std[i]
        );
    }
    assert_eq!(lf.nav, ls.nav);
    assert_eq!(lf.sensors, ls.sensors);
    eprintln!(
        "last epoch σ_N forward {:.4e} m smoothed {:.4e} m",
        lf.std[0], ls.std[0]
    );
    // Smoothed bias estimates at the start are better than the forward ones there (the
    // forward filter has not converged yet at 30 s).
    let k30 = run
        .epochs
        .iter()
        .position(|e| e.nav.time_s >= 30.0)
        .expect("30 s");
    let bg = |s: &SensorErrors| -> f64 {
        (0..3)
            .map(|k| (s.gyro_bias_rad_s[k] - GYRO_BIAS[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            / DEG_PER_H
    };
    let (bf, bs) = (bg(&run.epochs[k30].sensors), bg(&sm.epochs[k30].sensors));
    eprintln!("gyro-bias error at 30 s: forward {bf:.3} °/h, smoothed {bs:.3} °/h");
    assert!(bs < bf, "smoothed gyro bias at 30 s {bs} vs forward {bf}");
    // (d) P_s symmetric positive definite (every 97th epoch and the last).
    let mut checked = 0;
    let mut worst_asym = 0.0f64;
    let sm2 = smooth_with_covariances(&run, &init, &cfg, 97, |k, ps| {
        checked += 1;
        for i in 0..21 {
            for j in 0..21 {
                let s = (ps[i][i] * ps[j][j]).sqrt();
                worst_asym = worst_asym.max((ps[i][j] - ps[j][i]).abs() / s);
            }
        }
        if let Err(d) = check_covariance(ps, 1e-6) {
            panic!("P_s at epoch {k}: {d}");
        }
        if k == n - 1 {
            // Boundary: the full P_s equals the forward posterior at the last update
            // epoch (the run ends at a fix).
            for i in 0..21 {
                assert!((ps[i][i].sqrt() - lf.std[i]).abs() <= 1e-9 * lf.std[i]);
            }
        }
    })
    .expect("smoother with covariances");
    eprintln!(
        "P_s checked at {checked} epochs: symmetric (worst relative asymmetry {worst_asym:.2e}) \
         and positive definite"
    );
    assert!(checked > n / 97);
    // The parallel and the single-thread paths agree.
    for (a, b) in sm.epochs.iter().zip(&sm2.epochs) {
        let d = pos_err(&a.nav, &sc.traj.point(a.nav.time_s));
        let e = pos_err(&b.nav, &sc.traj.point(b.nav.time_s));
        assert!((0..3).all(|k| (d[k] - e[k]).abs() < 1e-9), "paths differ");
        assert!((0..21).all(|i| (a.std[i] - b.std[i]).abs() <= 1e-9 * a.std[i]));
    }
}

/// (b) A 60 s outage: the smoothed error inside it is much smaller than the forward one,
/// its σ is smaller and covers the smoothed error.
#[test]
fn outage_is_bridged_by_the_smoother() {
    let sc = scenario(480.0);
    let mut cfg = config();
    let (t0, t1) = (360.5, 420.5);
    cfg.outages_s = vec![(t0, t1)];
    let init = initial(&sc.traj);
    let run = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run");
    assert_eq!(run.gnss_withheld, 60);
    let sm = smooth(&run, &init, &cfg).expect("smoother");
    let ef = fwd_errors(&run, &sc.traj);
    let es = sm_errors(&sm, &sc.traj);
    let (rf, mf) = h_stats(&ef, t0, t1);
    let (rs, ms) = h_stats(&es, t0, t1);
    let in_out: Vec<usize> = (0..run.epochs.len())
        .filter(|&k| run.epochs[k].nav.time_s >= t0 && run.epochs[k].nav.time_s <= t1)
        .collect();
    let sig_h = |std: &[f64; 21]| std[0].hypot(std[1]);
    let max_sf = in_out
        .iter()
        .map(|&k| sig_h(&run.epochs[k].std))
        .fold(0.0, f64::max);
    let max_ss = in_out
        .iter()
        .map(|&k| sig_h(&sm.epochs[k].std))
        .fold(0.0, f64::max);
    eprintln!(
        "60 s outage: horizontal error forward max {:.3} m (RMS {:.3}), smoothed max {:.3} m \
         (RMS {:.3}); max σ_h forward {:.3} m, smoothed {:.3} m",
        mf, rf, ms, rs, max_sf, max_ss
    );
    assert!(mf > 0.05, "the outage must show some drift: {mf}");
    assert!(ms < 0.5 * mf, "smoothed max {ms} vs forward max {mf}");
    // σ smaller at every epoch of the outage (P_s ≤ P⁺) and much smaller at its middle.
    for &k in &in_out {
        for i in 0..9 {
            assert!(sm.epochs[k].std[i] <= run.epochs[k].std[i] * (1.0 + 1e-9));
        }
    }
    let mid = in_out[in_out.len() / 2];
    assert!(sig_h(&sm.epochs[mid].std) < 0.5 * sig_h(&run.epochs[mid].std));
    // Coverage: smoothed error within 3σ per axis.
    let names = [
        "r_N", "r_E", "r_D", "v_N", "v_E", "v_D", "φ_N", "φ_E", "φ_D",
    ];
    let mut line = String::new();
    for i in 0..9 {
        let inside = in_out
            .iter()
            .filter(|&&k| {
                let e = &es[k];
                let v = match i {
                    0..3 => e.pos[i],
                    3..6 => e.vel[i - 3],
                    _ => e.att[i - 6],
                };
                v.abs() <= 3.0 * sm.epochs[k].std[i]
            })
            .count() as f64
            / in_out.len() as f64;
        line += &format!(" {} {:.1}%", names[i], 100.0 * inside);
        assert!(inside >= 0.9, "3σ coverage of {} is {inside}", names[i]);
    }
    eprintln!("smoothed 3σ coverage in the outage:{line}");
}

/// Without any update the smoother returns the forward run (λ = Λ = 0), also across the
/// chunked re-propagation of a long segment; a different configuration is detected.
#[test]
fn no_updates_and_config_mismatch() {
    let sc = scenario(30.0);
    let mut cfg = config();
    cfg.outages_s = vec![(0.0, 100.0)];
    let init = initial(&sc.traj);
    let run = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run");
    assert!(run.updates.is_empty() && run.epochs.len() > 4096);
    let sm = smooth(&run, &init, &cfg).expect("smoother");
    for (f, s) in run.epochs.iter().zip(&sm.epochs) {
        assert_eq!(f.nav, s.nav);
        assert_eq!(f.sensors, s.sensors);
        for i in 0..21 {
            assert!((f.std[i] - s.std[i]).abs() <= 1e-12 * f.std[i]);
        }
    }
    // With GNSS: a configuration other than the forward run's is refused.
    let cfg = config();
    let run = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run");
    let mut other = config();
    other.imu.accel_vrw_m_s_sqrt_s *= 2.0;
    match smooth(&run, &init, &other) {
        Err(NavError::Config(msg)) => eprintln!("mismatch detected: {msg}"),
        r => panic!("expected a configuration error, got {:?}", r.map(|_| ())),
    }
    let mut init2 = init;
    init2.sigma_pos_ned_m = [2.0; 3];
    assert!(matches!(
        smooth(&run, &init2, &cfg),
        Err(NavError::Config(_))
    ));
}

/// With the rotation-driven attitude noise of an unmodelled gyro axis coupling
/// (`FilterConfig::gyro_coupling_sigma_rad`) the smoother rebuilds the forward run's
/// covariances (its re-propagated priors match the stored ones, else it errors), the
/// forward attitude σ grows over the turns, and P_s ≤ P⁺ still holds.
#[test]
fn smoother_rebuilds_the_rotation_noise() {
    let sc = scenario(480.0);
    let mut cfg = config();
    let (t0, t1) = (360.5, 420.5);
    cfg.outages_s = vec![(t0, t1)];
    let init = initial(&sc.traj);
    let plain = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run");
    cfg.gyro_coupling_sigma_rad = 0.01;
    let run = run_forward(&sc.imu, &sc.gnss, init, &cfg).expect("forward run with coupling");
    let sm = smooth(&run, &init, &cfg).expect("smoother with the coupling noise");
    let last = run.epochs.len() - 1;
    let tilt = |e: &[f64; 21]| e[6].hypot(e[7]);
    assert!(
        tilt(&run.epochs[last].std) > 1.05 * tilt(&plain.epochs[last].std),
        "tilt σ {} vs {} without the term",
        tilt(&run.epochs[last].std),
        tilt(&plain.epochs[last].std)
    );
    for k in 0..run.epochs.len() {
        for i in 0..9 {
            assert!(sm.epochs[k].std[i] <= run.epochs[k].std[i] * (1.0 + 1e-9));
        }
    }
}

//! A real vehicle's motion as simulation truth: the
//! 57-min, 28-km Wuhan RTK trajectory of the KF-GINS demo data set
//! (`shared/data/trajectories/kfgins_wuhan_gnss_rtk_1hz.txt`, i2Nav-WHU/KF-GINS, GPL-3.0)
//! smoothed into `sim::recorded::RecordedTrajectory`, ideal 200-Hz increments, and our
//! mechanization started from the true state. Run with
//! `cargo test --release --test sim_trajectory -- --ignored --nocapture`; the figures
//! are printed for VALIDATION.md.

use std::path::PathBuf;
use std::time::Instant;

use driftless::io::nav::{GnssReadOptions, read_kfgins_gnss_file};
use driftless::nav::earth;
use driftless::nav::mechanization::mechanize;
use driftless::sim::ideal_imu::{Trajectory, ideal_increments_par};
use driftless::sim::recorded::{RecordedOptions, RecordedTrajectory};

fn data(rel: &str) -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join(rel)
}

const RATE_HZ: f64 = 200.0;

fn wuhan() -> RecordedTrajectory {
    let fixes = read_kfgins_gnss_file(
        data("trajectories/kfgins_wuhan_gnss_rtk_1hz.txt"),
        &GnssReadOptions::default(),
    )
    .expect("Wuhan RTK trajectory");
    let t0 = Instant::now();
    let traj = RecordedTrajectory::from_fixes(&fixes, &RecordedOptions::default())
        .expect("valid trajectory");
    let f = traj.fit();
    eprintln!(
        "Wuhan fit ({} fixes, {:.0} s, fitted in {:.3} s): horizontal RMS {:.4} m (max {:.4} m), \
         vertical RMS {:.4} m (max {:.4} m); yaw − course RMS {:.3}° (max {:.3}°) above 1 m/s; \
         {:.1} % of the time held (below 0.5 m/s)",
        fixes.len(),
        traj.end_s() - traj.start_s(),
        t0.elapsed().as_secs_f64(),
        f.horizontal_rms_m,
        f.horizontal_max_m,
        f.vertical_rms_m,
        f.vertical_max_m,
        f.yaw_course_rms_rad.to_degrees(),
        f.yaw_course_max_rad.to_degrees(),
        100.0 * f.held_fraction
    );
    traj
}

/// Free-inertial navigation with perfect increments along the real trajectory: the
/// horizontal error is the mechanization's own (algorithmic and rounding) error.
#[test]
#[ignore = "needs shared data"]
fn wuhan_trajectory_ideal_imu_mechanization() {
    let traj = wuhan();
    let f = traj.fit();
    assert!(f.horizontal_rms_m < 0.05, "{f:?}");
    assert!(f.yaw_course_rms_rad < 1f64.to_radians(), "{f:?}");

    let dt = 1.0 / RATE_HZ;
    let t0 = traj.start_s();
    let n = ((traj.end_s() - t0) * RATE_HZ).round() as usize;
    let clock = Instant::now();
    let incs = ideal_increments_par(&traj, t0, dt, n + 1);
    let gen_s = clock.elapsed().as_secs_f64();
    eprintln!(
        "ideal increments: {} epochs at {RATE_HZ} Hz in {gen_s:.3} s ({} threads)",
        incs.len(),
        rayon::current_num_threads()
    );

    let mut state = traj.point(t0).nav_state(t0);
    let mut prev = incs[0];
    let mut horiz_at = Vec::new();
    let mut horiz_max = 0.0f64;
    let mut vert_end = 0.0;
    for (k, inc) in incs[1..].iter().enumerate() {
        state = mechanize(&state, &prev, inc);
        prev = *inc;
        let step = k + 1;
        let t = t0 + step as f64 * dt;
        let truth = traj.point(t);
        let d = earth::ned_offset_m(
            (truth.lat_rad, truth.lon_rad, truth.height_m),
            (state.lat_rad, state.lon_rad, state.height_m),
        );
        let h = d[0].hypot(d[1]);
        horiz_max = horiz_max.max(h);
        if step % (60 * RATE_HZ as usize) == 0 || step == n {
            horiz_at.push((step as f64 * dt, h));
        }
        vert_end = d[2];
    }
    let at = |s: f64| {
        horiz_at
            .iter()
            .find(|(t, _)| (t - s).abs() < 1e-6)
            .map_or(f64::NAN, |x| x.1)
    };
    let end = horiz_at.last().copied().unwrap_or((0.0, f64::NAN));
    eprintln!(
        "Wuhan ideal IMU @200 Hz, mechanization from the true state: horizontal error 60 s {:.2e} m, \
         600 s {:.3e} m, 3000 s {:.3} m, end ({:.0} s) {:.3} m, max {:.3} m; vertical at end {:.3} m",
        at(60.0),
        at(600.0),
        at(3000.0),
        end.0,
        end.1,
        horiz_max,
        vert_end
    );
    for (t, h) in horiz_at.iter().step_by(5) {
        eprintln!("  t = {t:6.0} s: horizontal {h:.3e} m");
    }
    assert!(at(60.0) <= 0.05, "{horiz_at:?}");
    assert!(end.1 <= 2.0, "{horiz_at:?}");
}

/// Generation speed of 1 h worth of ideal 200-Hz increments (720 000 epochs) along the
/// recorded trajectory (printed, not asserted). The record is 3412 s long, so the
/// 720 000 epochs are spread over it (Δt ≈ 4.7 ms instead of 5 ms; same work per epoch).
#[test]
#[ignore = "needs shared data; timing"]
fn wuhan_one_hour_generation_time() {
    let traj = wuhan();
    let n = (3600.0 * RATE_HZ) as usize;
    let dt = (traj.end_s() - traj.start_s()) / n as f64;
    for _ in 0..3 {
        let clock = Instant::now();
        let incs = ideal_increments_par(&traj, traj.start_s(), dt, n);
        eprintln!(
            "1 h @200 Hz worth: {} increments in {:.3} s ({} threads)",
            incs.len(),
            clock.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        );
    }
}

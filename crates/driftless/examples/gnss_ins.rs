//! Loosely coupled GNSS/INS on simulated data held in memory: forward filter + smoother.
//!
//! Simulates a short drive (consumer-grade IMU at 100 Hz, 1 Hz GNSS with a lever arm
//! and one 20 s outage) from an inline scenario ([`driftless::sim::scenario`]), runs the
//! error-state Kalman filter ([`driftless::nav::session::run_session`]: static gyro
//! priming, alignment from the GNSS course, forward pass), smooths the run
//! ([`driftless::nav::session::SessionResult::smooth`], Rauch–Tung–Striebel), and prints
//! the horizontal RMS error of both against the simulation truth after 60 s of
//! convergence.
//!
//! With your own data, build the inputs from arrays instead of a scenario:
//! `ImuStream::from_log(&ImuLog::from_rates(name, time_s, &gyro_rad_s, &accel_m_s2)?)?`
//! and `GnssFixes::new(time_s, lat_rad, lon_rad, height_m, sigma_ned_m)?`.
//!
//! Run: `cargo run --release -p driftless --example gnss_ins`

use driftless::nav::session::consumer_mems_noise;
use driftless::prelude::*;

const SCENARIO: &str = r#"
seed = 5
imu = { rate_hz = 100.0, preset = "consumer" }
gnss = { rate_hz = 1.0, sigma_ned_m = [0.05, 0.05, 0.1], lever_arm_b_m = [0.5, 0.0, -1.0], outages = "1x20s every 60s from 100s" }
[trajectory]
type = "profile"
start = { lat_deg = 30.5, lon_deg = 114.3, height_m = 20.0, heading_deg = 45.0 }
segment = [
  { type = "stop", duration_s = 20.0 },
  { type = "accelerate", to_speed_m_s = 10.0, duration_s = 10.0 },
  { type = "turn", angle_deg = 90.0, radius_m = 40.0 },
  { type = "cruise", duration_s = 60.0 },
  { type = "turn", angle_deg = -180.0, rate_deg_s = 10.0 },
  { type = "cruise", duration_s = 60.0 },
]
"#;

fn main() -> driftless::Result<()> {
    let sim = Scenario::from_toml_str(SCENARIO, "inline scenario")?.run()?;
    let gnss = sim
        .gnss
        .as_ref()
        .expect("the scenario has a [gnss] section");
    let filter = FilterConfig::new(consumer_mems_noise(), sim.lever_arm_b_m);
    let forward = run_session(&sim.imu_stream("sim"), gnss, &SessionConfig::new(filter))?;
    let smoothed = forward.smooth()?;
    // Horizontal RMS error against the truth, from 60 s after the first fix.
    let from_s = gnss.time_s[0] + 60.0;
    let (rms_fwd, _) = horizontal_rms_m(&sim.truth, &forward.solution(), from_s, 1.0)?;
    let (rms_sm, _) = horizontal_rms_m(&sim.truth, &smoothed.solution(), from_s, 1.0)?;

    println!("horizontal RMS vs truth: forward {rms_fwd:.3} m, smoothed {rms_sm:.3} m");
    assert!(rms_fwd < 2.0, "forward RMS {rms_fwd} m");
    assert!(
        rms_sm <= rms_fwd,
        "smoothed {rms_sm} m > forward {rms_fwd} m"
    );
    Ok(())
}

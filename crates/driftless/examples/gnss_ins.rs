//! Loosely coupled GNSS/INS on simulated data held in memory: forward filter + smoother.
//!
//! Simulates a short drive (consumer-grade IMU at 100 Hz, 1 Hz GNSS with a lever arm
//! and one 20 s outage) from an inline scenario ([`driftless::sim::scenario`]), runs the
//! error-state Kalman filter ([`driftless::nav::session::run_session`]: static gyro
//! priming, alignment from the GNSS course, forward pass) and the Rauch–Tung–Striebel
//! smoother ([`driftless::nav::filter::smooth`]), and prints the horizontal RMS error of
//! both against the simulation truth after 60 s of convergence.
//!
//! Run: `cargo run --release -p driftless --example gnss_ins`

use std::error::Error;

use driftless::eval::metrics::horizontal_errors;
use driftless::eval::reference::from_nav_states;
use driftless::io::nav::NavSolution;
use driftless::nav::filter::{FilterConfig, smooth};
use driftless::nav::session::{SessionConfig, consumer_mems_noise, run_session};
use driftless::sim::scenario::Scenario;

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

fn main() -> Result<(), Box<dyn Error>> {
    let sim = Scenario::from_toml_str(SCENARIO, "inline scenario")?.run()?;
    let gnss = sim
        .gnss
        .as_ref()
        .ok_or("the scenario has a [gnss] section")?;
    let cfg = SessionConfig::new(FilterConfig::new(consumer_mems_noise(), sim.lever_arm_b_m));
    let forward = run_session(&sim.imu_stream("sim"), gnss, &cfg)?;
    let smoothed = smooth(&forward.run, &forward.init, &cfg.filter)?;

    // Horizontal RMS error against the truth, epochs from 60 s after the first fix.
    let t_start = gnss.time_s[0] + 60.0;
    let rms = |sol: NavSolution| -> Result<f64, Box<dyn Error>> {
        let errs = horizontal_errors(&sim.truth, &sol, 1.0)?;
        let sq: Vec<f64> = sol
            .time_s
            .iter()
            .zip(errs)
            .filter(|(t, _)| **t >= t_start)
            .filter_map(|(_, e)| e.map(|e| e * e))
            .collect();
        if sq.is_empty() {
            return Err("no solution epoch overlaps the truth".into());
        }
        Ok((sq.iter().sum::<f64>() / sq.len().max(1) as f64).sqrt())
    };
    let rms_fwd = rms(from_nav_states(forward.run.epochs.iter().map(|e| &e.nav)))?;
    let rms_sm = rms(from_nav_states(smoothed.epochs.iter().map(|e| &e.nav)))?;
    println!("horizontal RMS vs truth: forward {rms_fwd:.3} m, smoothed {rms_sm:.3} m");
    assert!(rms_fwd < 2.0, "forward RMS {rms_fwd} m");
    assert!(
        rms_sm <= rms_fwd,
        "smoothed {rms_sm} m > forward {rms_fwd} m"
    );
    Ok(())
}

//! `driftless`: from raw MEMS IMU logs to a navigation error budget.
//!
//! Data flows one way: [`io`] readers → the validated in-memory types of [`data`]
//! ([`data::ImuLog`], [`data::GnssFixes`], [`data::NavSolution`]) → algorithms
//! ([`allan`], [`calib`], [`thermal`], [`nav`], [`eval`]) → results → writers and
//! [`report`]s. Algorithms never touch files; readers never do math. [`sim`] makes data
//! with known truth; [`experiment`] runs the seed paper's outage study.
//!
//! Start with `use driftless::prelude::*;` ([`prelude`]): the data types, the entry
//! point of each stage, and the crate's one [`Error`] (every stage's error converts
//! into it with `?`; its `source()` chain is the stage error's).
//!
//! Conventions: SI inside (s, m, rad, m/s, m/s², rad/s, °C). Display/file units
//! (deg/h, deg/√h, mg, g …) are converted at the edges only; names carry units and
//! frames (`gyro_rad_s`, `sigma_ned_m`, `lever_arm_b_m`).
//!
//! Runnable programs for each stage are in `crates/driftless/examples/`
//! (`cargo run --release -p driftless --example allan_oadev`, `six_position`,
//! `thermal`, `gnss_ins`). The snippets below show one call of each stage.
//!
//! # Noise analysis ([`allan`])
//!
//! Overlapping Allan deviation with confidence bounds from rate samples in memory:
//!
//! ```
//! use driftless::allan::analysis::{AnalysisConfig, analyse};
//! use driftless::sim::rng::Rng;
//!
//! let mut rng = Rng::seed_from_u64(1);
//! let gyro_rad_s: Vec<f64> = (0..20_000).map(|_| 0.01 * rng.normal()).collect();
//! let curve = analyse("gyro_x", &gyro_rad_s, 0.01, &AnalysisConfig::default())?;
//! // White noise: σ(τ0) is the sample σ and falls as 1/√τ (×1/√2 per octave).
//! let (p0, p1) = (curve.points[0], curve.points[1]);
//! assert!((p0.dev / 0.01 - 1.0).abs() < 0.03);
//! assert!((p1.dev / p0.dev - 0.5f64.sqrt()).abs() < 0.03);
//! assert!(curve.dev_lo[0] < p0.dev && p0.dev < curve.dev_hi[0]);
//! # Ok::<(), driftless::allan::AllanError>(())
//! ```
//!
//! # Calibration ([`calib`])
//!
//! Six-position accelerometer calibration from the mean raw output of each position
//! (here an accelerometer with bias b and no scale error: raw = f + b):
//!
//! ```
//! use driftless::calib::six_position::{PositionMean, SixPositionOptions, calibrate_accel};
//! use driftless::sim::chamber::SignedAxis;
//!
//! let opts = SixPositionOptions::at_site(45f64.to_radians(), 0.0);
//! let bias = [0.1, -0.2, 0.05];
//! let positions: Vec<PositionMean> = SignedAxis::POSITIONS
//!     .iter()
//!     .map(|&up| {
//!         let mut raw = bias;
//!         raw[up.axis.index()] += up.sign() * opts.gravity_m_s2;
//!         PositionMean::new(up, raw, [0.01; 3], [0.0; 3], [1e-4; 3], 100)
//!     })
//!     .collect();
//! let est = calibrate_accel(&positions, &opts)?;
//! for k in 0..3 {
//!     assert!((est.calibration.bias[k] - bias[k]).abs() < 1e-9);
//! }
//! # Ok::<(), driftless::calib::six_position::SixPositionError>(())
//! ```
//!
//! # Thermal models ([`thermal`])
//!
//! A cubic in ΔT = T − 25 °C fitted to bias readings; the result carries the
//! polynomial the compensation kernel (`driftless_model`) evaluates:
//!
//! ```
//! use driftless::thermal::{FitOptions, fit};
//!
//! let temps_c: Vec<f64> = (0..10).map(|i| -20.0 + 10.0 * i as f64).collect();
//! let bias = |t: f64| 1e-3 + 2e-5 * (t - 25.0) - 1e-7 * (t - 25.0).powi(3);
//! let y: Vec<f64> = temps_c.iter().map(|&t| bias(t)).collect();
//! let f = fit(&temps_c, &y, None, &FitOptions::default())?;
//! assert!((f.coeffs[0] - 1e-3).abs() < 1e-12);
//! assert!((f.poly.eval(61.3) - bias(61.3)).abs() < 1e-12);
//! # Ok::<(), driftless::thermal::ThermalFitError>(())
//! ```
//!
//! # Simulation ([`sim`])
//!
//! A scenario (the TOML of `driftless simulate`) run in memory: an error-free IMU at
//! rest senses the Earth rate and the specific force −g along the down axis:
//!
//! ```
//! use driftless::sim::scenario::Scenario;
//!
//! let text = r#"
//! [imu]
//! rate_hz = 100.0
//! preset = "ideal"
//! output = "rates"
//! [trajectory]
//! type = "static"
//! lat_deg = 45.0
//! duration_s = 1.0
//! "#;
//! let sim = Scenario::from_toml_str(text, "inline")?.run()?;
//! assert_eq!(sim.imu.len(), 101);
//! let g = driftless::nav::earth::gravity_ned(45f64.to_radians(), 0.0)[2];
//! assert!((sim.imu.accel_at(0)[2] + g).abs() < 1e-9);
//! # Ok::<(), driftless::sim::scenario::ScenarioError>(())
//! ```
//!
//! # Navigation ([`nav`])
//!
//! The loosely coupled GNSS/INS filter and smoother on arrays in memory (here an
//! error-free IMU at rest for 60 s and a fix every second at the same place): the
//! solution stays put.
//!
//! ```
//! use driftless::prelude::*;
//!
//! let (lat_rad, lon_rad, h_m) = (30f64.to_radians(), 114f64.to_radians(), 20.0);
//! let g = driftless::nav::earth::gravity_ned(lat_rad, h_m)[2];
//! let w_ie = driftless::nav::earth::OMEGA_IE;
//! let n = 6001; // 100 Hz
//! let t: Vec<f64> = (0..n).map(|k| 1000.0 + k as f64 / 100.0).collect();
//! // Body = NED (level, heading north): the gyros sense the Earth rate.
//! let gyro = vec![[w_ie * lat_rad.cos(), 0.0, -w_ie * lat_rad.sin()]; n];
//! let accel = vec![[0.0, 0.0, -g]; n];
//! let imu = ImuStream::from_log(&ImuLog::from_rates("memory", t, &gyro, &accel)?)?;
//! let fix_t: Vec<f64> = (1..60).map(|k| 1000.0 + k as f64).collect();
//! let m = fix_t.len();
//! let gnss = GnssFixes::new(fix_t, vec![lat_rad; m], vec![lon_rad; m], vec![h_m; m], vec![[0.5; 3]; m])?;
//! let mut cfg = SessionConfig::new(FilterConfig::new(driftless::nav::session::consumer_mems_noise(), [0.0; 3]));
//! cfg.initial_yaw_rad = Some(0.0);
//! let forward = run_session(&imu, &gnss, &cfg)?;
//! let s = forward.smooth()?.solution();
//! let mid = s.time_s.len() / 2;
//! let at = (s.lat_rad[mid], s.lon_rad[mid], s.height_m[mid]);
//! let offset = driftless::nav::earth::ned_offset_m((lat_rad, lon_rad, h_m), at);
//! assert!(offset.iter().all(|d| d.abs() < 0.5), "{offset:?}");
//! # Ok::<(), driftless::Error>(())
//! ```
// One audited exception: the AVX2 dispatch of the Allan kernel (allan::estimators).
#![deny(unsafe_code)]

pub mod allan;
pub mod calib;
pub mod data;
pub mod error;
pub mod eval;
pub mod experiment;
pub mod io;
pub mod nav;
pub mod numeric;
pub mod prelude;
pub mod report;
pub mod sim;
pub mod thermal;

pub use error::{Error, Result};

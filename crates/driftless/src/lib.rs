//! `driftless`: from raw MEMS IMU logs to a navigation error budget.
//!
//! Data flows one way: [`io`] readers → typed columnar logs ([`io::log`]) →
//! algorithms ([`allan`], …) → results → writers and [`report`]s.
//! Algorithms never parse files; readers never do math.
//!
//! Conventions: SI inside (s, m, rad, m/s, m/s², rad/s, °C). Display/file units
//! (deg/h, deg/√h, mg, g …) are converted at the edges only.
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
//! Strapdown mechanization of increments (here of an error-free IMU at rest, 10 s):
//! the position stays put. The GNSS/INS filter and smoother are
//! [`nav::session::run_session`] and [`nav::filter::smooth`] (example `gnss_ins`).
//!
//! ```
//! use driftless::nav::{earth, mechanization::mechanize};
//! use driftless::sim::scenario::Scenario;
//!
//! let text = r#"
//! [imu]
//! rate_hz = 100.0
//! preset = "ideal"
//! [trajectory]
//! type = "static"
//! lat_deg = 30.0
//! duration_s = 10.0
//! "#;
//! let sim = Scenario::from_toml_str(text, "inline")?.run()?;
//! let epochs = sim.imu_stream("static").epochs;
//! let (mut nav, mut prev) = (sim.initial, epochs[0]);
//! for inc in &epochs {
//!     nav = mechanize(&nav, &prev, inc);
//!     prev = *inc;
//! }
//! let start = (sim.initial.lat_rad, sim.initial.lon_rad, sim.initial.height_m);
//! let drift_m = earth::ned_offset_m(start, (nav.lat_rad, nav.lon_rad, nav.height_m));
//! assert!(drift_m.iter().all(|d| d.abs() < 1e-3), "{drift_m:?}");
//! # Ok::<(), driftless::sim::scenario::ScenarioError>(())
//! ```
// One audited exception: the AVX2 dispatch of the Allan kernel (allan::estimators).
#![deny(unsafe_code)]

pub mod allan;
pub mod calib;
pub mod eval;
pub mod experiment;
pub mod io;
pub mod nav;
pub mod numeric;
pub mod report;
pub mod sim;
pub mod thermal;

//! Compensation: a simulated vehicle log whose temperature rises
//! 25 → 45 °C; residual bias after compensation ≤ 5 % of the uncompensated thermal bias.
//!
//! The whole pipeline, with every noise term of the `adi-like` preset:
//! 1. a chamber soak of the sensor (−25…70 °C in 5 °C steps, interleaved order, six
//!    positions and ±ω rate-table segments per step; seed 31) → `soak_calibration` with
//!    the drift model from the preset's Allan terms → the compensation model;
//! 2. a 30-min drive of the *same* sensor (same deterministic errors, new turn-on biases
//!    and noise; seed 32): stop, accelerations, cruises, turns, braking, while the sensor
//!    warms from 25 to 45 °C (τ = 300 s), temperature read in 0.1 °C steps;
//! 3. the same drive simulated without any error gives the truth, sample by sample.
//!
//! The **thermal bias** of a channel is the 60-s mean of (output − truth), minus its
//! value in the first minute (at 25 °C): the constant part is the run's turn-on bias,
//! which no thermal model can know (the navigation filter estimates it). Uncompensated =
//! the room calibration at 25 °C only (the paper's "uncompensated"); compensated = room
//! calibration + thermal deltas at the sensor's temperature reading. The bar is asserted
//! per triad on the RMS over the three axes and every minute.

use driftless::calib::six_position::SixPositionOptions;
use driftless::sim::chamber::ChamberConfig;
use driftless::sim::presets::Preset;
use driftless::sim::scenario::Scenario;
use driftless::sim::sensor::{OutputKind, SensorModel};
use driftless::thermal::FitOptions;
use driftless::thermal::soak::{SoakDrift, soak_calibration};
use driftless_model::compensation::OutOfRange;

const DRIVE: &str = r#"
seed = 32
[imu]
rate_hz = 100.0
preset = "adi-like"
output = "rates"
errors = "ERRORS"
[trajectory]
type = "profile"
[trajectory.start]
lat_deg = 51.08
lon_deg = -114.13
height_m = 1100.0
heading_deg = 30.0
[[trajectory.segment]]
type = "stop"
duration_s = 60.0
[[trajectory.segment]]
type = "accelerate"
to_speed_m_s = 15.0
duration_s = 10.0
[[trajectory.segment]]
type = "cruise"
duration_s = 300.0
[[trajectory.segment]]
type = "turn"
angle_deg = 90.0
rate_deg_s = 10.0
[[trajectory.segment]]
type = "cruise"
duration_s = 400.0
[[trajectory.segment]]
type = "turn"
angle_deg = -180.0
radius_m = 60.0
[[trajectory.segment]]
type = "cruise"
duration_s = 500.0
[[trajectory.segment]]
type = "turn"
angle_deg = 45.0
rate_deg_s = 5.0
[[trajectory.segment]]
type = "cruise"
duration_s = 400.0
[[trajectory.segment]]
type = "brake"
duration_s = 10.0
[[trajectory.segment]]
type = "stop"
duration_s = 60.0
[temperature]
kind = "warm_up"
t0_c = 25.0
t1_c = 45.0
tau_s = 300.0
"#;

#[test]
fn vehicle_warm_up_residual_thermal_bias_below_five_percent() {
    // 1. Soak → model.
    let proto = ChamberConfig {
        soak_s: 600.0,
        lag_tau_s: 60.0,
        position_dwell_s: 30.0,
        move_s: 5.0,
        rate_revolutions: 2,
        spin_s: 2.0,
        sample_rate_hz: 100.0,
        temperatures_c: (0..20)
            .map(|i| -25.0 + 5.0 * ((i * 7) % 20) as f64)
            .collect(),
        ..ChamberConfig::default()
    }
    .build()
    .expect("protocol");
    let cfg = Preset::AdiLike.config();
    let curve = proto.temperature.curve().expect("temperature");
    let chamber = SensorModel::new(cfg.clone())
        .expect("model")
        .simulate(&proto.ideal(OutputKind::Rates), &curve, 31)
        .expect("simulate");
    let drift = SoakDrift::from(&cfg);
    let soak = soak_calibration(
        &proto.manifest,
        chamber.accel.each_ref().map(Vec::as_slice),
        chamber.gyro.each_ref().map(Vec::as_slice),
        1.0,
        &SixPositionOptions::from_manifest(&proto.manifest),
        &FitOptions::default(),
        Some(&drift),
    )
    .expect("soak");
    let model = soak
        .compensation_model(1, OutOfRange::Clamp)
        .expect("model");
    let room = *model.calibration();

    // 2.–3. The drive, with every error and without any.
    let run = |errors: &str| {
        Scenario::from_toml_str(&DRIVE.replace("ERRORS", errors), "drive")
            .expect("scenario")
            .run()
            .expect("simulate")
            .imu
    };
    let (real, ideal) = (run("all"), run("none"));
    assert_eq!(real.len(), ideal.len());
    let n = real.len();
    let per_min = (60.0 / real.dt_s).round() as usize;
    let minutes = n / per_min;
    assert!(minutes >= 25, "{minutes} minutes");
    // Per channel (gyro x, y, z, accel x, y, z), per minute: mean error uncompensated
    // and compensated.
    let mut e_room = vec![[0.0f64; 6]; minutes];
    let mut e_comp = vec![[0.0f64; 6]; minutes];
    for k in 0..minutes * per_min {
        let (g, a, t) = (real.gyro_at(k), real.accel_at(k), real.temperature_c[k]);
        let (gc, ac) = model.compensate(g, a, t).expect("compensate");
        let (gr, ar) = (room.gyro.apply(g), room.accel.apply(a));
        let (gi, ai) = (ideal.gyro_at(k), ideal.accel_at(k));
        let m = k / per_min;
        for j in 0..3 {
            e_room[m][j] += (gr[j] - gi[j]) / per_min as f64;
            e_comp[m][j] += (gc[j] - gi[j]) / per_min as f64;
            e_room[m][3 + j] += (ar[j] - ai[j]) / per_min as f64;
            e_comp[m][3 + j] += (ac[j] - ai[j]) / per_min as f64;
        }
    }
    let t_end = real.temperature_c[minutes * per_min - 1];
    assert!((t_end - 45.0).abs() < 0.5, "final temperature {t_end} °C");
    // Thermal bias: minus the first minute's value.
    let rms = |e: &[[f64; 6]], chans: std::ops::Range<usize>| -> f64 {
        let (mut s, mut c) = (0.0, 0usize);
        for row in e {
            for j in chans.clone() {
                s += (row[j] - e[0][j]).powi(2);
                c += 1;
            }
        }
        (s / c as f64).sqrt()
    };
    for j in 0..6 {
        eprintln!(
            "{}: thermal bias RMS uncompensated {:.3e}, compensated {:.3e} ({:.1} %)",
            [
                "gyro x", "gyro y", "gyro z", "accel x", "accel y", "accel z"
            ][j],
            rms(&e_room, j..j + 1),
            rms(&e_comp, j..j + 1),
            100.0 * rms(&e_comp, j..j + 1) / rms(&e_room, j..j + 1)
        );
    }
    for (name, chans, unit) in [("gyro", 0..3, "rad/s"), ("accel", 3..6, "m/s²")] {
        let (u, c) = (rms(&e_room, chans.clone()), rms(&e_comp, chans));
        eprintln!(
            "{name}: thermal bias over 25 → 45 °C, RMS over axes and minutes: uncompensated \
             {u:.3e} {unit}, compensated {c:.3e} {unit} = {:.2} %",
            100.0 * c / u
        );
        assert!(c <= 0.05 * u, "{name}: {c} vs {u}");
    }
}

//! Thermal calibration: gyro bias versus temperature, then compensation of a sample.
//!
//! Per axis, fits a cubic in ΔT = T − 25 °C to bias readings at soak temperatures
//! ([`driftless::thermal::fit`]), turns the three fits into a compensation model
//! ([`driftless_model::compensation::CompensationModel`], the `no_std` kernel a device
//! runs) and compensates one raw sample taken at 61.3 °C.
//!
//! Run: `cargo run --release -p driftless --example thermal`

use std::error::Error;

use driftless::sim::rng::Rng;
use driftless::thermal::{FitOptions, fit};
use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::compensation::{CompensationModel, OutOfRange, TriadThermal};
use driftless_model::thermal::ThermalPoly;

/// True gyro bias of axis `k` at `t_c`, rad/s: a cubic about 25 °C.
fn bias_true(k: usize, t_c: f64) -> f64 {
    let d = t_c - 25.0;
    let c = [
        [2e-3, 4e-5, -3e-7, 2e-9],
        [-1e-3, -2e-5, 5e-7, 0.0],
        [5e-4, 1e-5, 0.0, -4e-9],
    ][k];
    c[0] + c[1] * d + c[2] * d * d + c[3] * d * d * d
}

fn main() -> Result<(), Box<dyn Error>> {
    // Soak temperatures −20…70 °C every 5 °C, each bias read with 2e-6 rad/s noise.
    let temps_c: Vec<f64> = (0..19).map(|i| -20.0 + 5.0 * i as f64).collect();
    let mut rng = Rng::seed_from_u64(3);
    let mut polys = [ThermalPoly::constant(0.0); 3];
    let mut bias_ref = [0.0; 3];
    for k in 0..3 {
        let bias: Vec<f64> = temps_c
            .iter()
            .map(|&t| bias_true(k, t) + 2e-6 * rng.normal())
            .collect();
        let f = fit(&temps_c, &bias, None, &FitOptions::default())?;
        let c: Vec<String> = f.coeffs.iter().map(|c| format!("{c:+.3e}")).collect();
        println!(
            "axis {k}: c0…c3 = {} (residual RMS {:.1e} rad/s)",
            c.join(" "),
            f.residual_rms
        );
        polys[k] = f.poly;
        bias_ref[k] = f.coeffs[0];
    }

    // Room calibration b(25 °C) with unit scale; the thermal part adds Δb(T) = b(T) − b(25 °C).
    let gyro_thermal = TriadThermal::from_forward(&polys, &[ThermalPoly::constant(0.0); 3])?;
    let calibration = ImuCalibration {
        gyro: TriadCalibration {
            bias: bias_ref,
            ..TriadCalibration::IDENTITY
        },
        accel: TriadCalibration::IDENTITY,
    };
    let range_c = [temps_c[0], temps_c[temps_c.len() - 1]];
    let model = CompensationModel::new(
        1,
        calibration,
        Some(gyro_thermal),
        None,
        range_c,
        OutOfRange::default(),
    )?;

    // One raw sample at 61.3 °C: true rate plus the bias at that temperature.
    let (t_c, rate_true) = (61.3, [0.1, -0.2, 0.05]);
    let raw: [f64; 3] = std::array::from_fn(|k| rate_true[k] + bias_true(k, t_c));
    let (gyro_rad_s, _) = model.compensate(raw, [0.0, 0.0, -9.81], t_c)?;
    println!("raw {raw:.5?} → compensated {gyro_rad_s:.5?} (true {rate_true:?}) rad/s");
    let worst = (0..3)
        .map(|k| (gyro_rad_s[k] - rate_true[k]).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "compensated rate off by {worst} rad/s");
    Ok(())
}

//! Six-position accelerometer calibration from six static means.
//!
//! Builds the mean raw output of the six "axis up / axis down" positions from a known
//! forward model raw = A·f + b (scale factor and misalignment in A, bias b), runs
//! [`driftless::calib::six_position::calibrate_accel`] and prints the recovered bias
//! and scale factors against the truth. The reported calibration is
//! calibrated = M·(raw − b) with M = A⁻¹.
//!
//! Run: `cargo run --release -p driftless --example six_position`

use std::error::Error;

use driftless::calib::six_position::{PositionMean, SixPositionOptions, calibrate_accel};
use driftless::sim::chamber::SignedAxis;
use driftless_model::linalg::Mat3;

fn main() -> Result<(), Box<dyn Error>> {
    let opts = SixPositionOptions::at_site(48f64.to_radians(), 300.0);
    let g = opts.gravity_m_s2;
    // Truth: bias (m/s²), scale-factor errors on the diagonal, small misalignments.
    let bias_true = [0.05, -0.03, 0.08];
    let scale_true = [1.002, 0.997, 1.004];
    let a_true = Mat3([
        [scale_true[0], 1e-3, -2e-3],
        [0.5e-3, scale_true[1], 1e-3],
        [1.5e-3, -1e-3, scale_true[2]],
    ]);

    // Mean raw output of each position: the specific force is +g along the up axis.
    let positions: Vec<PositionMean> = SignedAxis::POSITIONS
        .iter()
        .map(|&up| {
            let mut f = [0.0; 3];
            f[up.axis.index()] = up.sign() * g;
            let raw = a_true.mul_vec(f);
            let raw = std::array::from_fn(|i| raw[i] + bias_true[i]);
            // 1000 samples of σ = 0.01 m/s² each; the gyro is not used here.
            PositionMean::new(up, raw, [0.01; 3], [0.0; 3], [1e-4; 3], 1000)
        })
        .collect();

    let est = calibrate_accel(&positions, &opts)?;
    let a = est.forward_matrix;
    let sigma = est.bias_sigma();
    println!("axis  bias (m/s²)  ±1σ        true    scale     true");
    for i in 0..3 {
        let b = est.calibration.bias[i];
        println!(
            "{}    {b:+.5}    {:.1e}  {:+.3}  {:.5}  {:.5}",
            ['x', 'y', 'z'][i],
            sigma[i],
            bias_true[i],
            a.0[i][i],
            scale_true[i]
        );
        assert!((b - bias_true[i]).abs() < 1e-9, "bias {i}: {b}");
        assert!((a.0[i][i] - scale_true[i]).abs() < 1e-9, "scale {i}");
    }
    let worst = (0..9)
        .map(|k| (a.0[k / 3][k % 3] - a_true.0[k / 3][k % 3]).abs())
        .fold(0.0, f64::max);
    println!("largest error of A (scale + misalignment): {worst:.1e}");
    assert!(worst < 1e-9);
    // The calibration maps raw back to SI: +z up reads (0, 0, +g).
    let raw_up = positions[1].accel_raw;
    println!(
        "calibrated {} up: {:?}",
        positions[1].up,
        est.calibration.apply(raw_up)
    );
    Ok(())
}

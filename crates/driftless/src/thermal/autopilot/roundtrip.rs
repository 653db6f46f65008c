//! Round-trip checks: the bias an exported parameter set gives against the model it came
//! from, over a grid of temperatures.

use super::*;

/// What the model subtracts from a raw sample at `t_c`, in SI, per triad (accel, gyro):
/// b(T) = b + Δb(T) from [`CompensationModel::calibration_at`] (the model's own evaluation,
/// not the exporter's), converted with the file's raw units. The model is evaluated with
/// the clamp policy, as the autopilots do.
pub fn model_bias_si(
    f: &ThermalModelFile,
    model: &CompensationModel,
    t_c: f64,
) -> Result<[[f64; 3]; 2], AutopilotError> {
    let cal = model
        .with_policy(OutOfRange::Clamp)
        .calibration_at(t_c)
        .map_err(|e| AutopilotError::Model(e.to_string()))?;
    let ua = si_conversion("accel", &f.accel.raw_unit, Quantity::SpecificForce)?;
    let ug = si_conversion("gyro", &f.gyro.raw_unit, Quantity::AngularRate)?;
    Ok([
        cal.accel.bias.map(|b| ua.to_si(b)),
        cal.gyro.bias.map(|b| ug.to_si(b)),
    ])
}

/// Largest |model − autopilot| of the subtracted bias over given temperatures, SI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoundTripError {
    /// Accelerometer, m/s², autopilot formula in f64 on the float32 parameters.
    pub accel: f64,
    /// Gyro, rad/s, same.
    pub gyro: f64,
    /// Accelerometer, m/s², autopilot formula in float32 arithmetic.
    pub accel_f32: f64,
    /// Gyro, rad/s, same.
    pub gyro_f32: f64,
}

/// `n` (≥ 2) temperatures evenly spaced over `range_c`, ends included.
pub fn check_temperatures(range_c: [f64; 2], n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|i| range_c[0] + (range_c[1] - range_c[0]) * i as f64 / (n - 1) as f64)
        .collect()
}

pub(super) fn fold_err(err: &mut f64, a: [f64; 3], b: [f64; 3]) {
    for i in 0..3 {
        *err = err.max((a[i] - b[i]).abs());
    }
}

/// Compares the model with re-imported PX4 parameters at `temps`. With `thermal_only`
/// (export without offsets) the model's Δb(T) = b(T) − b is compared with the thermal
/// offset alone.
pub fn compare_px4(
    f: &ThermalModelFile,
    model: &CompensationModel,
    p: &Px4Thermal,
    temps: &[f64],
    thermal_only: bool,
) -> Result<RoundTripError, AutopilotError> {
    let mut e = RoundTripError::default();
    let base = model_bias_si(f, model, f.t_ref_c)?;
    for &t in temps {
        let mut m = model_bias_si(f, model, t)?;
        if thermal_only {
            for (k, mk) in m.iter_mut().enumerate() {
                for i in 0..3 {
                    mk[i] -= base[k][i];
                }
            }
        }
        for (k, tri) in [&p.accel, &p.gyro].into_iter().enumerate() {
            let Some(tri) = tri else { continue };
            let (e64, e32) = if k == 0 {
                (&mut e.accel, &mut e.accel_f32)
            } else {
                (&mut e.gyro, &mut e.gyro_f32)
            };
            let (got, got32) = if thermal_only {
                (tri.offset(t), tri.offset_f32(t as f32))
            } else {
                (tri.correction(t), tri.correction_f32(t as f32))
            };
            fold_err(e64, m[k], got);
            fold_err(e32, m[k], got32.map(f64::from));
        }
    }
    Ok(e)
}

/// Compares the model with re-imported ArduPilot parameters at `temps`. With
/// `thermal_only` the model's Δb(T) − Δb(CALTEMP) is compared with the thermal term
/// alone (offsets treated as absent).
pub fn compare_ardupilot(
    f: &ThermalModelFile,
    model: &CompensationModel,
    p: &ArduPilotTcal,
    temps: &[f64],
    thermal_only: bool,
) -> Result<RoundTripError, AutopilotError> {
    let mut e = RoundTripError::default();
    let mut q = p.clone();
    if thermal_only {
        q.acc_offs = None;
        q.gyr_offs = None;
    }
    let base = [
        model_bias_si(f, model, q.acc_caltemp as f64)?[0],
        model_bias_si(f, model, q.gyr_caltemp as f64)?[1],
    ];
    for &t in temps {
        let mut m = model_bias_si(f, model, t)?;
        if thermal_only {
            for (k, mk) in m.iter_mut().enumerate() {
                for i in 0..3 {
                    mk[i] -= base[k][i];
                }
            }
        }
        fold_err(&mut e.accel, m[0], q.correction(true, t));
        fold_err(&mut e.gyro, m[1], q.correction(false, t));
        fold_err(
            &mut e.accel_f32,
            m[0],
            q.correction_f32(true, t as f32).map(f64::from),
        );
        fold_err(
            &mut e.gyro_f32,
            m[1],
            q.correction_f32(false, t as f32).map(f64::from),
        );
    }
    Ok(e)
}

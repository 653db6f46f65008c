//! Autopilot thermal-compensation parameters: export the **bias
//! part** of a thermal model to PX4 `TC_*` parameters (QGroundControl `.params` file) and to
//! ArduPilot `INS_TCAL*` parameters (Mission Planner `.param` file), read such files back,
//! and evaluate each autopilot's own correction formula on what was read.
//!
//! The formulas below were taken from the autopilots' sources (read, not copied) and are
//! restated in `docs/autopilot-thermal.md` with a worked example:
//!
//! * **PX4** (`src/modules/temperature_compensation/TemperatureCompensation.cpp`,
//!   `calc_thermal_offsets_3D`; `src/lib/sensor_calibration/Accelerometer.hpp`, `Correct`),
//!   per axis i of accelerometer or gyro instance n, in float:
//!
//!   ```text
//!   ΔT     = clamp(T, TMIN, TMAX) − TREF
//!   offset = X0 + X1·ΔT + X2·ΔT² + X3·ΔT³                 (m/s², rad/s)
//!   out    = R_board · ((raw − offset − CAL_ACCn_OFF) ⊙ CAL_ACCn_SCALE)
//!   ```
//!
//!   applied only when `TC_A_ENABLE` / `TC_G_ENABLE` = 1 and `TC_An_ID` / `TC_Gn_ID`
//!   equals the sensor's device id. Current PX4 has no thermal scale parameters
//!   (`TC_*_SCL` were removed; the documentation page still mentions them).
//! * **ArduPilot** (`libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp`,
//!   `TCal::correct_sensor`, `polynomial_eval`; applied in
//!   `AP_InertialSensor_Backend::_rotate_and_correct_accel`/`_gyro`), in float:
//!
//!   ```text
//!   P(d)  = (A1·d + A2·d² + A3·d³) · 1e-6                 (no constant term)
//!   Tc    = clamp(T, TMIN, TMAX),  Tcal = clamp(CALTEMP, TMIN, TMAX)
//!   v    ← v − P(Tc − 35) + P(Tcal − 35)                 (35 °C: TEMP_REFERENCE)
//!   out   = R_board · ((v − INS_ACCOFFS) ⊙ INS_ACCSCAL)
//!   ```
//!
//!   applied only when `INS_TCALn_ENABLE` = 1; `CALTEMP` is `INS_ACCn_CALTEMP` /
//!   `INS_GYRn_CALTEMP`, the temperature of the regular accelerometer / gyro calibration
//!   (default −300, i.e. clamped to TMIN).
//!
//! Both apply the thermal offset in the sensor frame (after the driver's fixed chip
//! rotation, before the board rotation), in m/s² and rad/s: the model's axes must be those
//! of the autopilot's raw `sensor_accel`/`sensor_gyro` (PX4) or raw IMU (ArduPilot) data.
//!
//! # What is exported
//!
//! Our model's bias at T is b + Δb(T) (raw units; [`crate::thermal::model_file`]), Δb a
//! polynomial about T_ref with no constant term. With [`ExportOptions::include_offsets`]
//! (the default) the exported files make each autopilot subtract exactly b + Δb(T):
//!
//! * PX4: `TREF` = T_ref, `X0` = b, `X1..X3` = Δb's coefficients (no re-expansion), and
//!   `CAL_ACCn_{X,Y,Z}OFF` = `CAL_GYROn_{X,Y,Z}OFF` = 0 (PX4 puts the whole offset into X0
//!   once thermal compensation is enabled: its own accelerometer/gyro calibration then
//!   shifts X0 and resets the CAL offsets).
//! * ArduPilot: the cubic is re-expanded exactly about 35 °C ([`taylor_shift`]):
//!   Δb(T) = Σ e_j (T − 35)^j; `A_j` = 1e6·e_j (j = 1..3; e₀ cancels in the formula),
//!   `CALTEMP` = T_ref and `INS_ACCOFFS`/`INS_GYROFFS` = b + Δb(clamp(T_ref)) (= b when
//!   T_ref lies in the range). Then P(Tc − 35) − P(Tcal − 35) = Δb(Tc) − Δb(Tcal).
//!
//! Without offsets only the temperature dependence is written (PX4 `X0` = 0, no `CAL_*`;
//! ArduPilot no `OFFS`/`CALTEMP`): the vehicle's own room calibration stays in charge.
//!
//! **Scale-factor and misalignment terms have no place in these parameters**: neither
//! autopilot models a temperature-dependent scale factor, so our Δs(T) is dropped, which
//! leaves an error of |Δs_k(T)|·|f_k| on axis k (e.g. 1e-4 × 9.81 m/s² ≈ 1 mg at 1 g);
//! the room-temperature matrix M is left to the autopilot's own calibration (per-axis scale
//! only). [`TriadBias::scale_delta_max`] reports the dropped Δs.
//!
//! # Precision
//!
//! The autopilots store float32. Values are written as the shortest decimal that reads
//! back as the float32 nearest the exact value, never in exponent notation (ArduPilot's
//! 1e6 coefficient scaling exists for editors that do not read it).
//! [`Px4Triad::offset`]/[`ArduPilotTcal::correction`] evaluate the documented formula in f64
//! on the float32 parameters (the parameter rounding alone);
//! [`Px4Triad::offset_f32`]/[`ArduPilotTcal::correction_f32`] repeat the autopilots'
//! float arithmetic.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use driftless_model::compensation::{CompensationModel, OutOfRange};

use super::model_file::ThermalModelFile;
use crate::io::Quantity;
use crate::io::units::Unit;

mod export;
mod parse;
mod roundtrip;
pub use export::*;
pub use parse::*;
pub use roundtrip::*;

/// ArduPilot's fixed reference temperature of the `INS_TCAL*` polynomial (`TEMP_REFERENCE`).
pub(crate) const ARDUPILOT_TEMP_REFERENCE_C: f64 = 35.0;
/// ArduPilot stores coefficients multiplied by this (`SCALE_FACTOR`).
pub(crate) const ARDUPILOT_COEFF_SCALE: f64 = 1.0e6;
/// ArduPilot's default of `INS_ACCn_CALTEMP` / `INS_GYRn_CALTEMP` (unset).
pub(crate) const ARDUPILOT_CALTEMP_DEFAULT_C: f32 = -300.0;
/// PX4 accelerometer/gyro thermal-compensation instances (`TC_A0` … `TC_A3`).
pub(crate) const PX4_INSTANCES: usize = 4;
/// ArduPilot `INS_TCAL1_` … `INS_TCAL3_` groups.
pub(crate) const ARDUPILOT_INSTANCES: usize = 3;
/// Highest exportable polynomial order.
pub(crate) const MAX_EXPORT_ORDER: usize = 3;

const AXES: [char; 3] = ['X', 'Y', 'Z'];

/// Why an export or an import failed.
#[derive(Debug, thiserror::Error)]
pub enum AutopilotError {
    /// A bias polynomial of order > 3.
    #[error(
        "[{triad}] bias_delta[{axis}] has order {order}: PX4 TC_* and ArduPilot INS_TCAL* hold \
         at most a cubic; refit with order 3 (e.g. `driftless thermal soak|ramp --order 3`)"
    )]
    OrderTooHigh {
        /// `accel` or `gyro`.
        triad: &'static str,
        /// 0, 1, 2.
        axis: usize,
        /// The order found.
        order: usize,
    },
    /// A raw unit that cannot be converted to the autopilots' SI units.
    #[error("[{triad}] raw_unit {unit:?}: {why}")]
    Unit {
        /// `accel` or `gyro`.
        triad: &'static str,
        /// The unit.
        unit: String,
        /// What is wrong.
        why: String,
    },
    /// Instance number out of the autopilot's range.
    #[error("instance {instance}: {autopilot} has instances 0..={max}")]
    Instance {
        /// Asked for.
        instance: usize,
        /// `PX4` or `ArduPilot`.
        autopilot: &'static str,
        /// Highest instance.
        max: usize,
    },
    /// The model itself is invalid, or a value cannot be stored as float32.
    #[error("{0}")]
    Model(String),
    /// A malformed line or value of a parameter file.
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        /// File name.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (characters).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Unknown, duplicate or missing parameters.
    #[error("{file}: {message}")]
    Params {
        /// File name.
        file: String,
        /// What is wrong.
        message: String,
    },
}

/// The temperature model of one triad's bias, in SI (m/s² or rad/s).
#[derive(Clone, Debug, PartialEq)]
pub struct TriadBias {
    /// b at T_ref per axis, SI.
    pub bias_si: [f64; 3],
    /// Δb per axis: coefficients c₀ (= 0) … c₃ of (T − T_ref)^k, SI per °C^k.
    pub delta_si: [[f64; 4]; 3],
    /// max over the range of |Δs_k(T)| (dimensionless): the scale-factor change the
    /// export drops.
    pub scale_delta_max: [f64; 3],
    /// Largest |off-diagonal / diagonal| of the room matrix M (misalignment, not exported).
    pub misalignment_max: f64,
}

/// The bias part of a thermal model, ready for export.
#[derive(Clone, Debug, PartialEq)]
pub struct BiasModel {
    /// Model id.
    pub model_id: u64,
    /// T_ref, °C.
    pub t_ref_c: f64,
    /// Fitted range, °C.
    pub range_c: [f64; 2],
    /// The model's out-of-range policy (the autopilots always clamp).
    pub policy: OutOfRange,
    /// Accelerometer, m/s².
    pub accel: TriadBias,
    /// Gyro, rad/s.
    pub gyro: TriadBias,
}

/// SI conversion of a model raw unit: (SI per unit, offset in raw units).
fn si_conversion(triad: &'static str, unit: &str, want: Quantity) -> Result<Unit, AutopilotError> {
    let u = Unit::parse(unit).map_err(|e| AutopilotError::Unit {
        triad,
        unit: unit.to_owned(),
        why: e.to_string(),
    })?;
    if u.quantity != want {
        return Err(AutopilotError::Unit {
            triad,
            unit: unit.to_owned(),
            why: format!(
                "measures {:?}, expected {want:?} (the autopilots take {})",
                u.quantity,
                want.si_unit()
            ),
        });
    }
    Ok(u)
}

impl BiasModel {
    /// The bias part of a model file (validated by [`ThermalModelFile::model`]; `name`
    /// names it in errors). Fails on a bias polynomial of order > 3 or a raw unit that is
    /// not an accelerometer / gyro unit convertible to SI.
    pub fn from_model_file(f: &ThermalModelFile, name: &str) -> Result<BiasModel, AutopilotError> {
        let model = f
            .model(name)
            .map_err(|e| AutopilotError::Model(e.to_string()))?;
        let triad = |tname: &'static str,
                     s: &super::model_file::TriadSection,
                     q: Quantity|
         -> Result<TriadBias, AutopilotError> {
            let u = si_conversion(tname, &s.raw_unit, q)?;
            let mut delta_si = [[0.0; 4]; 3];
            for (k, c) in s.bias_delta.iter().enumerate() {
                let order = c.iter().rposition(|&v| v != 0.0).unwrap_or(0);
                if order > MAX_EXPORT_ORDER {
                    return Err(AutopilotError::OrderTooHigh {
                        triad: tname,
                        axis: k,
                        order,
                    });
                }
                for (j, v) in c.iter().take(MAX_EXPORT_ORDER + 1).enumerate() {
                    delta_si[k][j] = v * u.scale_si;
                }
            }
            let [lo, hi] = f.range_c;
            let mut scale_delta_max = [0.0f64; 3];
            for (k, c) in s.scale_delta.iter().enumerate() {
                const N: usize = 400;
                for i in 0..=N {
                    let t = lo + (hi - lo) * i as f64 / N as f64;
                    let d = t - f.t_ref_c;
                    let v: f64 = c.iter().rev().fold(0.0, |acc, ck| acc * d + ck);
                    scale_delta_max[k] = scale_delta_max[k].max(v.abs());
                }
            }
            let m = s.matrix;
            let mut mis = 0.0f64;
            for (i, row) in m.iter().enumerate() {
                for (j, v) in row.iter().enumerate() {
                    if i != j && m[j][j] != 0.0 {
                        mis = mis.max((v / m[j][j]).abs());
                    }
                }
            }
            Ok(TriadBias {
                bias_si: s.bias.map(|b| u.to_si(b)),
                delta_si,
                scale_delta_max,
                misalignment_max: mis,
            })
        };
        Ok(BiasModel {
            model_id: f.model_id,
            t_ref_c: f.t_ref_c,
            range_c: f.range_c,
            policy: model.policy(),
            accel: triad("accel", &f.accel, Quantity::SpecificForce)?,
            gyro: triad("gyro", &f.gyro, Quantity::AngularRate)?,
        })
    }
}

// ---------------------------------------------------------------------------------------
// Import

// ---------------------------------------------------------------------------------------
// Verification

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taylor_shift_is_exact_on_a_cubic() {
        let c = [0.0, 2e-3, -1e-5, 3e-7];
        let e = taylor_shift(&c, 25.0, 35.0);
        for t in [-40.0, 0.0, 25.0, 35.0, 85.0] {
            let p = |c: &[f64], r: f64| c.iter().rev().fold(0.0, |a, ck| a * (t - r) + ck);
            let (want, got) = (p(&c, 25.0), p(&e, 35.0));
            assert!(
                (want - got).abs() <= 1e-16 + 1e-14 * want.abs(),
                "{t}: {want} {got}"
            );
        }
        // e0 = p(35): the value at the new centre.
        assert!((e[0] - (2e-2 - 1e-3 + 3e-4)).abs() < 1e-16);
        assert_eq!(binomial(3, 2), 3.0);
        assert_eq!(taylor_shift(&c, 25.0, 25.0), c.to_vec());
    }

    #[test]
    fn fields_report_one_based_columns() {
        let f = fields("1\t1\tTC_A0_X0_0\t0.5\t9", |c| c == '\t');
        assert_eq!(
            f,
            vec![
                (1, "1"),
                (3, "1"),
                (5, "TC_A0_X0_0"),
                (16, "0.5"),
                (20, "9")
            ]
        );
        let f = fields("  A,  1.5", |c| c == ',' || c == ' ');
        assert_eq!(f, vec![(3, "A"), (7, "1.5")]);
    }
}

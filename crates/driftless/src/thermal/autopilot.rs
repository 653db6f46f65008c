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

/// ArduPilot's fixed reference temperature of the `INS_TCAL*` polynomial (`TEMP_REFERENCE`).
pub const ARDUPILOT_TEMP_REFERENCE_C: f64 = 35.0;
/// ArduPilot stores coefficients multiplied by this (`SCALE_FACTOR`).
pub const ARDUPILOT_COEFF_SCALE: f64 = 1.0e6;
/// ArduPilot's default of `INS_ACCn_CALTEMP` / `INS_GYRn_CALTEMP` (unset).
pub const ARDUPILOT_CALTEMP_DEFAULT_C: f32 = -300.0;
/// PX4 accelerometer/gyro thermal-compensation instances (`TC_A0` … `TC_A3`).
pub const PX4_INSTANCES: usize = 4;
/// ArduPilot `INS_TCAL1_` … `INS_TCAL3_` groups.
pub const ARDUPILOT_INSTANCES: usize = 3;
/// Highest exportable polynomial order.
pub const MAX_EXPORT_ORDER: usize = 3;

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

/// Re-expands p(T) = Σ c_k (T − from)^k about `to`: returns e with
/// p(T) = Σ e_j (T − to)^j, exactly in exact arithmetic (binomial / Taylor shift):
///
/// ```text
/// e_j = Σ_{k ≥ j} C(k, j) · h^(k−j) · c_k,   h = to − from
/// ```
pub fn taylor_shift(c: &[f64], from: f64, to: f64) -> Vec<f64> {
    let h = to - from;
    let n = c.len();
    let mut e = vec![0.0; n];
    for (j, ej) in e.iter_mut().enumerate() {
        // Σ_k C(k, j) h^(k−j) c_k, accumulated from the highest k (Horner in h).
        let mut acc = 0.0;
        for k in (j..n).rev() {
            acc = acc * h + binomial(k, j) * c[k];
        }
        *ej = acc;
    }
    e
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// A parameter value as the autopilots store it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    /// float32 (MAV_PARAM_TYPE_REAL32 = 9).
    Float(f32),
    /// int32 (MAV_PARAM_TYPE_INT32 = 6).
    Int(i32),
}

impl ParamValue {
    fn text(&self) -> String {
        match self {
            // Rust's Display: shortest round-trip digits, never exponent notation.
            ParamValue::Float(v) => format!("{v}"),
            ParamValue::Int(v) => format!("{v}"),
        }
    }
    fn mav_type(&self) -> u8 {
        match self {
            ParamValue::Float(_) => 9,
            ParamValue::Int(_) => 6,
        }
    }
}

/// One named parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Parameter name.
    pub name: String,
    /// Its value.
    pub value: ParamValue,
}

fn float(name: String, v: f64) -> Result<Param, AutopilotError> {
    let f = v as f32;
    if !f.is_finite() {
        return Err(AutopilotError::Model(format!(
            "{name} = {v} does not fit a float32 parameter"
        )));
    }
    Ok(Param {
        name,
        value: ParamValue::Float(f),
    })
}

/// Export settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Sensor instance: PX4 `TC_A<n>` (0–3), ArduPilot `INS_TCAL<n+1>` (0–2).
    pub instance: usize,
    /// Write the room offset b too (module docs); otherwise only the temperature
    /// dependence.
    pub include_offsets: bool,
    /// PX4 `TC_A<n>_ID`: the accelerometer's device id (`CAL_ACC<n>_ID`); 0 matches no
    /// sensor, and PX4 then applies nothing.
    pub px4_accel_id: i32,
    /// PX4 `TC_G<n>_ID` (`CAL_GYRO<n>_ID`).
    pub px4_gyro_id: i32,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            instance: 0,
            include_offsets: true,
            px4_accel_id: 0,
            px4_gyro_id: 0,
        }
    }
}

/// `instance` if the autopilot has that many sensor instances (`count`), else the error
/// naming the largest.
fn check_instance(
    instance: usize,
    count: usize,
    autopilot: &'static str,
) -> Result<usize, AutopilotError> {
    if instance >= count {
        return Err(AutopilotError::Instance {
            instance,
            autopilot,
            max: count - 1,
        });
    }
    Ok(instance)
}

/// PX4 parameters of the bias part (module docs).
pub fn px4_params(m: &BiasModel, o: &ExportOptions) -> Result<Vec<Param>, AutopilotError> {
    let n = check_instance(o.instance, PX4_INSTANCES, "PX4")?;
    let mut p = Vec::new();
    for (letter, cal, t, id) in [
        ('A', "ACC", &m.accel, o.px4_accel_id),
        ('G', "GYRO", &m.gyro, o.px4_gyro_id),
    ] {
        p.push(Param {
            name: format!("TC_{letter}_ENABLE"),
            value: ParamValue::Int(1),
        });
        p.push(Param {
            name: format!("TC_{letter}{n}_ID"),
            value: ParamValue::Int(id),
        });
        p.push(float(format!("TC_{letter}{n}_TREF"), m.t_ref_c)?);
        p.push(float(format!("TC_{letter}{n}_TMIN"), m.range_c[0])?);
        p.push(float(format!("TC_{letter}{n}_TMAX"), m.range_c[1])?);
        for k in 0..=MAX_EXPORT_ORDER {
            for axis in 0..3 {
                let v = if k == 0 {
                    if o.include_offsets {
                        t.bias_si[axis]
                    } else {
                        0.0
                    }
                } else {
                    t.delta_si[axis][k]
                };
                p.push(float(format!("TC_{letter}{n}_X{k}_{axis}"), v)?);
            }
        }
        if o.include_offsets {
            for a in AXES {
                p.push(float(format!("CAL_{cal}{n}_{a}OFF"), 0.0)?);
            }
        }
    }
    Ok(p)
}

/// ArduPilot's name of the offset parameter of instance `n` (`INS_ACCOFFS_X`,
/// `INS_ACC2OFFS_X`, `INS_GYROFFS_X`, `INS_GYR2OFFS_X`, …).
fn ardupilot_offs_name(accel: bool, n: usize, axis: char) -> String {
    match (accel, n) {
        (true, 0) => format!("INS_ACCOFFS_{axis}"),
        (true, _) => format!("INS_ACC{}OFFS_{axis}", n + 1),
        (false, 0) => format!("INS_GYROFFS_{axis}"),
        (false, _) => format!("INS_GYR{}OFFS_{axis}", n + 1),
    }
}

/// ArduPilot parameters of the bias part (module docs).
pub fn ardupilot_params(m: &BiasModel, o: &ExportOptions) -> Result<Vec<Param>, AutopilotError> {
    let n = check_instance(o.instance, ARDUPILOT_INSTANCES, "ArduPilot")?;
    let g = format!("INS_TCAL{}_", n + 1);
    let mut p = vec![
        Param {
            name: format!("{g}ENABLE"),
            value: ParamValue::Int(1),
        },
        float(format!("{g}TMIN"), m.range_c[0])?,
        float(format!("{g}TMAX"), m.range_c[1])?,
    ];
    let shifted = |t: &TriadBias| -> [[f64; 4]; 3] {
        std::array::from_fn(|axis| {
            let e = taylor_shift(&t.delta_si[axis], m.t_ref_c, ARDUPILOT_TEMP_REFERENCE_C);
            [e[0], e[1], e[2], e[3]]
        })
    };
    let (ea, eg) = (shifted(&m.accel), shifted(&m.gyro));
    for k in 1..=MAX_EXPORT_ORDER {
        for (axis, a) in AXES.iter().enumerate() {
            p.push(float(
                format!("{g}ACC{k}_{a}"),
                ea[axis][k] * ARDUPILOT_COEFF_SCALE,
            )?);
        }
        for (axis, a) in AXES.iter().enumerate() {
            p.push(float(
                format!("{g}GYR{k}_{a}"),
                eg[axis][k] * ARDUPILOT_COEFF_SCALE,
            )?);
        }
    }
    if o.include_offsets {
        // OFFS = b + Δb(clamp(T_ref)): ArduPilot clamps CALTEMP into [TMIN, TMAX] too.
        let t_cal = m.t_ref_c.clamp(m.range_c[0], m.range_c[1]);
        for (accel, t, caltemp) in [
            (true, &m.accel, format!("INS_ACC{}_CALTEMP", n + 1)),
            (false, &m.gyro, format!("INS_GYR{}_CALTEMP", n + 1)),
        ] {
            for (axis, a) in AXES.iter().enumerate() {
                let d = t_cal - m.t_ref_c;
                let db: f64 = t.delta_si[axis]
                    .iter()
                    .rev()
                    .fold(0.0, |acc, c| acc * d + c);
                p.push(float(
                    ardupilot_offs_name(accel, n, *a),
                    t.bias_si[axis] + db,
                )?);
            }
            p.push(float(caltemp, m.t_ref_c)?);
        }
    }
    Ok(p)
}

fn sci(v: f64) -> String {
    format!("{v:.3e}")
}

/// The caveats every exported file carries as comments (`#` lines).
fn header(m: &BiasModel, o: &ExportOptions, autopilot: &str) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "# driftless thermal export for {autopilot}, instance {}: model {:#018x}, T_ref {} °C, \
         range [{}, {}] °C",
        o.instance, m.model_id, m.t_ref_c, m.range_c[0], m.range_c[1]
    );
    let _ = writeln!(
        h,
        "# BIAS ONLY. Scale-factor and misalignment terms have no place in these parameters:"
    );
    let _ = writeln!(
        h,
        "# the model's thermal scale-factor change is dropped, an error of |ds(T)|*|f| per axis:"
    );
    for (name, t, unit, per) in [
        ("accel", &m.accel, "m/s^2", 9.80665),
        ("gyro", &m.gyro, "rad/s", 1.0),
    ] {
        let ds = t.scale_delta_max.iter().fold(0.0f64, |a, b| a.max(*b));
        let _ = writeln!(
            h,
            "#   {name}: max |ds| {} over the range = {} {unit} at {} {unit}; room misalignment \
             {} (left to the autopilot's own calibration)",
            sci(ds),
            sci(ds * per),
            per,
            sci(t.misalignment_max)
        );
    }
    let _ = writeln!(
        h,
        "# Sensor frame (before the board rotation), m/s^2 and rad/s; float32 values."
    );
    if m.policy != OutOfRange::Clamp {
        let _ = writeln!(
            h,
            "# Note: the model's out-of-range policy is not clamp; {autopilot} always clamps."
        );
    }
    if o.include_offsets {
        let _ = writeln!(
            h,
            "# Offsets included: the autopilot subtracts the model's full bias b + db(T)."
        );
    } else {
        let _ = writeln!(
            h,
            "# Offsets not included: only the temperature dependence; the vehicle's own \
             calibration offsets stay."
        );
    }
    h
}

/// The PX4 parameter file (QGroundControl `.params`: tab-separated
/// `vehicle-id component-id name value type` lines after `#` comments).
pub fn export_px4(m: &BiasModel, o: &ExportOptions) -> Result<String, AutopilotError> {
    let params = px4_params(m, o)?;
    let mut s = header(m, o, "PX4");
    let _ = writeln!(
        s,
        "# PX4 subtracts offset = X0 + X1*dT + X2*dT^2 + X3*dT^3, dT = clamp(T, TMIN, TMAX) - TREF."
    );
    if o.px4_accel_id == 0 || o.px4_gyro_id == 0 {
        let _ = writeln!(
            s,
            "# TC_A{n}_ID / TC_G{n}_ID = 0 match no sensor: set them to CAL_ACC{n}_ID / \
             CAL_GYRO{n}_ID (or export with the device ids) or PX4 applies nothing.",
            n = o.instance
        );
    }
    let _ = writeln!(s, "#\n# Vehicle-Id Component-Id Name Value Type");
    for p in &params {
        let _ = writeln!(
            s,
            "1\t1\t{}\t{}\t{}",
            p.name,
            p.value.text(),
            p.value.mav_type()
        );
    }
    Ok(s)
}

/// The ArduPilot parameter file (Mission Planner `.param`: `NAME,VALUE` lines after `#`
/// comments).
pub fn export_ardupilot(m: &BiasModel, o: &ExportOptions) -> Result<String, AutopilotError> {
    let params = ardupilot_params(m, o)?;
    let mut s = header(m, o, "ArduPilot");
    let _ = writeln!(
        s,
        "# ArduPilot subtracts P(Tc-35) - P(Tcal-35), P(d) = (A1*d + A2*d^2 + A3*d^3)*1e-6, \
         Tc, Tcal = T, CALTEMP clamped to [TMIN, TMAX]."
    );
    for p in &params {
        let _ = writeln!(s, "{},{}", p.name, p.value.text());
    }
    Ok(s)
}

// ---------------------------------------------------------------------------------------
// Import

/// A parsed parameter: value text as written, its position, and the float32 it holds.
#[derive(Clone, Debug)]
struct Entry {
    value: f64,
    line: usize,
    column: usize,
    /// MAV_PARAM_TYPE (PX4 files only).
    mav_type: Option<u8>,
}

/// Name → entry of a parameter file, duplicates refused.
struct ParamFile {
    file: String,
    entries: BTreeMap<String, Entry>,
    ignored: usize,
}

fn syntax(file: &str, line: usize, column: usize, message: String) -> AutopilotError {
    AutopilotError::Syntax {
        file: file.to_owned(),
        line,
        column,
        message,
    }
}

/// Splits `line` into fields at `is_sep`, each with its 1-based character column.
fn fields(line: &str, is_sep: impl Fn(char) -> bool) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None; // (byte, column)
    for (col0, (bi, ch)) in line.char_indices().enumerate() {
        if is_sep(ch) {
            if let Some((s, c)) = start.take() {
                out.push((c, &line[s..bi]));
            }
        } else if start.is_none() {
            start = Some((bi, col0 + 1));
        }
    }
    if let Some((s, c)) = start {
        out.push((c, &line[s..]));
    }
    out
}

/// A parameter name field (column, text): letters, digits and `_` only.
fn parameter_name<'a>(
    file: &str,
    line: usize,
    (col, name): (usize, &'a str),
) -> Result<&'a str, AutopilotError> {
    if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(syntax(
            file,
            line,
            col,
            format!("{name:?} is not a parameter name"),
        ));
    }
    Ok(name)
}
/// Column to blame for a wrong field count: the first extra field, or just past the end.
fn count_column(line: &str, f: &[(usize, &str)], want: usize) -> usize {
    f.get(want).map_or(line.chars().count() + 1, |x| x.0)
}

fn parse_number(file: &str, line: usize, column: usize, text: &str) -> Result<f64, AutopilotError> {
    let v: f64 = text.parse().map_err(|_| {
        syntax(
            file,
            line,
            column,
            format!("value {text:?} is not a number"),
        )
    })?;
    if !v.is_finite() {
        return Err(syntax(
            file,
            line,
            column,
            format!("value {text:?} is not finite"),
        ));
    }
    Ok(v)
}

impl ParamFile {
    fn insert(&mut self, name: &str, e: Entry, relevant: bool) -> Result<(), AutopilotError> {
        if !relevant {
            self.ignored += 1;
            return Ok(());
        }
        if let Some(prev) = self.entries.get(name) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} given again (first on line {})", prev.line),
            ));
        }
        self.entries.insert(name.to_owned(), e);
        Ok(())
    }

    /// Takes a required float parameter as float32.
    fn take_f32(&mut self, name: &str) -> Result<f32, AutopilotError> {
        self.take_opt_f32(name)?
            .ok_or_else(|| AutopilotError::Params {
                file: self.file.clone(),
                message: format!("missing required parameter {name}"),
            })
    }

    fn take_opt_f32(&mut self, name: &str) -> Result<Option<f32>, AutopilotError> {
        let Some(e) = self.entries.remove(name) else {
            return Ok(None);
        };
        if let Some(t) = e.mav_type.filter(|t| *t != 9) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} is a float parameter: type must be 9 (REAL32), not {t}"),
            ));
        }
        let f = e.value as f32;
        if !f.is_finite() {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} = {} overflows a float32", e.value),
            ));
        }
        Ok(Some(f))
    }

    fn take_int(&mut self, name: &str) -> Result<i32, AutopilotError> {
        let Some(e) = self.entries.remove(name) else {
            return Err(AutopilotError::Params {
                file: self.file.clone(),
                message: format!("missing required parameter {name}"),
            });
        };
        if let Some(t) = e.mav_type.filter(|t| *t != 6) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} is an integer parameter: type must be 6 (INT32), not {t}"),
            ));
        }
        if e.value.fract() != 0.0 || e.value < i32::MIN as f64 || e.value > i32::MAX as f64 {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} = {} is not a 32-bit integer", e.value),
            ));
        }
        Ok(e.value as i32)
    }

    /// Fails naming any parameter of the autopilot's namespace left unused.
    fn finish(self) -> Result<usize, AutopilotError> {
        if let Some((name, e)) = self.entries.iter().next() {
            let hint = if name.contains("_SCL") {
                " (PX4 removed the thermal scale parameters; scale-factor terms have no place here)"
            } else {
                ""
            };
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("unknown parameter {name}{hint}"),
            ));
        }
        Ok(self.ignored)
    }
}

/// PX4 thermal parameters of one triad of one instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Px4Triad {
    /// `TC_A_ENABLE` / `TC_G_ENABLE` = 1.
    pub enabled: bool,
    /// `TC_*n_ID`.
    pub device_id: i32,
    /// `TREF`, `TMIN`, `TMAX`, °C.
    pub tref: f32,
    /// See `tref`.
    pub tmin: f32,
    /// See `tref`.
    pub tmax: f32,
    /// `X<k>_<axis>`: `x[k][axis]`.
    pub x: [[f32; 3]; 4],
    /// `CAL_ACCn_{X,Y,Z}OFF` / `CAL_GYROn_…` when the file has them (else PX4's 0 default
    /// is not assumed: the vehicle's own value applies).
    pub cal_offset: Option<[f32; 3]>,
}

impl Px4Triad {
    /// PX4's thermal offset at `t_c` (°C) in f64 arithmetic on the float32 parameters:
    /// X0 + X1·ΔT + X2·ΔT² + X3·ΔT³, ΔT = clamp(T, TMIN, TMAX) − TREF (upper bound tested
    /// first, as PX4 does); zero when disabled.
    pub fn offset(&self, t_c: f64) -> [f64; 3] {
        if !self.enabled {
            return [0.0; 3];
        }
        let dt = if t_c > self.tmax as f64 {
            self.tmax as f64 - self.tref as f64
        } else if t_c < self.tmin as f64 {
            self.tmin as f64 - self.tref as f64
        } else {
            t_c - self.tref as f64
        };
        std::array::from_fn(|i| {
            let x = |k: usize| self.x[k][i] as f64;
            x(0) + x(1) * dt + x(2) * dt * dt + x(3) * dt * dt * dt
        })
    }

    /// [`Self::offset`] in float32 arithmetic, in PX4's order of operations.
    pub fn offset_f32(&self, t_c: f32) -> [f32; 3] {
        if !self.enabled {
            return [0.0; 3];
        }
        let dt = if t_c > self.tmax {
            self.tmax - self.tref
        } else if t_c < self.tmin {
            self.tmin - self.tref
        } else {
            t_c - self.tref
        };
        let dt2 = dt * dt;
        let dt3 = dt2 * dt;
        std::array::from_fn(|i| {
            self.x[0][i] + self.x[1][i] * dt + self.x[2][i] * dt2 + self.x[3][i] * dt3
        })
    }

    /// Everything PX4 subtracts from the raw sample at `t_c`: thermal offset + CAL offset
    /// (0 when the file has none), f64 arithmetic.
    pub fn correction(&self, t_c: f64) -> [f64; 3] {
        let o = self.offset(t_c);
        let c = self.cal_offset.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| o[i] + c[i] as f64)
    }

    /// [`Self::correction`] in float32 (PX4 subtracts the two in turn; summed here).
    pub fn correction_f32(&self, t_c: f32) -> [f32; 3] {
        let o = self.offset_f32(t_c);
        let c = self.cal_offset.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| o[i] + c[i])
    }
}

/// The PX4 thermal parameters of one instance read from a `.params` file.
#[derive(Clone, Debug, PartialEq)]
pub struct Px4Thermal {
    /// Instance read.
    pub instance: usize,
    /// Accelerometer (None: no `TC_A*` parameters in the file).
    pub accel: Option<Px4Triad>,
    /// Gyro.
    pub gyro: Option<Px4Triad>,
    /// Parameters of other instances or subsystems, skipped.
    pub ignored: usize,
}

/// Reads the PX4 thermal parameters of `instance` from a QGroundControl `.params` text
/// (`file` names it in errors). Lines: `vehicle component NAME VALUE TYPE` separated by
/// tabs or spaces; `#` starts a comment line. Refused, naming line and column: a malformed
/// line, a non-numeric or non-finite value, a wrong type code, a duplicate, an unknown
/// `TC_A<n>_…`/`TC_G<n>_…` name (e.g. the removed `…_SCL_…`). Refused naming the file: a
/// triad with some but not all of its parameters, or a file without either triad.
pub fn parse_px4(text: &str, file: &str, instance: usize) -> Result<Px4Thermal, AutopilotError> {
    if instance >= PX4_INSTANCES {
        return Err(AutopilotError::Instance {
            instance,
            autopilot: "PX4",
            max: PX4_INSTANCES - 1,
        });
    }
    let mut pf = ParamFile {
        file: file.to_owned(),
        entries: BTreeMap::new(),
        ignored: 0,
    };
    let prefixes = [
        format!("TC_A{instance}_"),
        format!("TC_G{instance}_"),
        format!("CAL_ACC{instance}_"),
        format!("CAL_GYRO{instance}_"),
    ];
    for (li, raw) in text.lines().enumerate() {
        let line = li + 1;
        let body = raw.trim_end_matches('\r');
        if body.trim().is_empty() || body.trim_start().starts_with('#') {
            continue;
        }
        let f = fields(body, |c| c == '\t' || c == ' ');
        if f.len() != 5 {
            return Err(syntax(
                file,
                line,
                count_column(body, &f, 5),
                format!(
                    "expected 5 fields `vehicle-id component-id name value type`, found {}",
                    f.len()
                ),
            ));
        }
        for &(col, t) in &f[..2] {
            if t.parse::<u8>().is_err() {
                return Err(syntax(
                    file,
                    line,
                    col,
                    format!("{t:?} is not a vehicle/component id (0–255)"),
                ));
            }
        }
        let name = parameter_name(file, line, f[2])?;
        let (vcol, vtext) = f[3];
        let value = parse_number(file, line, vcol, vtext)?;
        let (tcol, ttext) = f[4];
        let mav_type: u8 = ttext.parse().map_err(|_| {
            syntax(
                file,
                line,
                tcol,
                format!("{ttext:?} is not a MAV_PARAM_TYPE code"),
            )
        })?;
        let cal_off = (name.starts_with(&prefixes[2]) || name.starts_with(&prefixes[3]))
            && name.ends_with("OFF");
        let relevant = name == "TC_A_ENABLE"
            || name == "TC_G_ENABLE"
            || name.starts_with(&prefixes[0])
            || name.starts_with(&prefixes[1])
            || cal_off;
        pf.insert(
            name,
            Entry {
                value,
                line,
                column: vcol,
                mav_type: Some(mav_type),
            },
            relevant,
        )?;
    }
    let mut triad = |letter: char, cal: &str| -> Result<Option<Px4Triad>, AutopilotError> {
        let g = format!("TC_{letter}{instance}_");
        let present = pf.entries.keys().any(|k| k.starts_with(&g));
        if !present {
            return Ok(None);
        }
        let enabled = pf.take_int(&format!("TC_{letter}_ENABLE"))? == 1;
        let device_id = pf.take_int(&format!("{g}ID"))?;
        let tref = pf.take_f32(&format!("{g}TREF"))?;
        let tmin = pf.take_f32(&format!("{g}TMIN"))?;
        let tmax = pf.take_f32(&format!("{g}TMAX"))?;
        if tmin > tmax {
            return Err(AutopilotError::Params {
                file: pf.file.clone(),
                message: format!("{g}TMIN {tmin} > {g}TMAX {tmax}"),
            });
        }
        let mut x = [[0.0f32; 3]; 4];
        for (k, row) in x.iter_mut().enumerate() {
            for (axis, v) in row.iter_mut().enumerate() {
                *v = pf.take_f32(&format!("{g}X{k}_{axis}"))?;
            }
        }
        let offs: Vec<Option<f32>> = AXES
            .iter()
            .map(|a| pf.take_opt_f32(&format!("CAL_{cal}{instance}_{a}OFF")))
            .collect::<Result<_, _>>()?;
        let cal_offset = match offs.as_slice() {
            [Some(a), Some(b), Some(c)] => Some([*a, *b, *c]),
            [None, None, None] => None,
            _ => {
                return Err(AutopilotError::Params {
                    file: pf.file.clone(),
                    message: format!("CAL_{cal}{instance}_XOFF/YOFF/ZOFF: give all three or none"),
                });
            }
        };
        Ok(Some(Px4Triad {
            enabled,
            device_id,
            tref,
            tmin,
            tmax,
            x,
            cal_offset,
        }))
    };
    let accel = triad('A', "ACC")?;
    let gyro = triad('G', "GYRO")?;
    if accel.is_none() && gyro.is_none() {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("no TC_A{instance}_* or TC_G{instance}_* parameters"),
        });
    }
    let ignored = pf.finish()?;
    Ok(Px4Thermal {
        instance,
        accel,
        gyro,
        ignored,
    })
}

/// ArduPilot `INS_TCAL<n+1>_*` parameters and the calibration temperature/offsets read.
#[derive(Clone, Debug, PartialEq)]
pub struct ArduPilotTcal {
    /// Instance read (0 → `INS_TCAL1_`).
    pub instance: usize,
    /// `ENABLE` (0 disabled, 1 enabled, 2 learning; only 1 applies the correction).
    pub enable: i32,
    /// `TMIN`, °C.
    pub tmin: f32,
    /// `TMAX`, °C.
    pub tmax: f32,
    /// `ACC<k>_<axis>`: `acc[k − 1][axis]` (scaled by 1e6).
    pub acc: [[f32; 3]; 3],
    /// `GYR<k>_<axis>`.
    pub gyr: [[f32; 3]; 3],
    /// `INS_ACC<n+1>_CALTEMP` (ArduPilot's default −300 when absent).
    pub acc_caltemp: f32,
    /// `INS_GYR<n+1>_CALTEMP`.
    pub gyr_caltemp: f32,
    /// `INS_ACC[n+1]OFFS_*` when present.
    pub acc_offs: Option<[f32; 3]>,
    /// `INS_GYR[n+1]OFFS_*` when present.
    pub gyr_offs: Option<[f32; 3]>,
    /// Other parameters, skipped.
    pub ignored: usize,
}

impl ArduPilotTcal {
    fn poly(c: &[[f32; 3]; 3], axis: usize, d: f64) -> f64 {
        let a = |k: usize| c[k][axis] as f64;
        (a(0) + (a(1) + a(2) * d) * d) * d / ARDUPILOT_COEFF_SCALE
    }

    /// What ArduPilot subtracts from the raw sample at `t_c`, f64 arithmetic on the float32
    /// parameters: P(Tc − 35) − P(Tcal − 35) (when ENABLE = 1) + OFFS (when given).
    pub fn correction(&self, accel: bool, t_c: f64) -> [f64; 3] {
        let (c, cal, offs) = if accel {
            (&self.acc, self.acc_caltemp, self.acc_offs)
        } else {
            (&self.gyr, self.gyr_caltemp, self.gyr_offs)
        };
        let (lo, hi) = (self.tmin as f64, self.tmax as f64);
        // constrain_float: lower bound first, then upper.
        let clamp = |t: f64| {
            if t < lo {
                lo
            } else if t > hi {
                hi
            } else {
                t
            }
        };
        let tc = clamp(t_c);
        let tcal = clamp(cal as f64);
        let o = offs.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| {
            let th = if self.enable == 1 {
                Self::poly(c, i, tc - ARDUPILOT_TEMP_REFERENCE_C)
                    - Self::poly(c, i, tcal - ARDUPILOT_TEMP_REFERENCE_C)
            } else {
                0.0
            };
            th + o[i] as f64
        })
    }

    /// [`Self::correction`] in float32 arithmetic, in ArduPilot's order of operations
    /// (the sample is corrected in two steps; the net subtracted amount is returned).
    pub fn correction_f32(&self, accel: bool, t_c: f32) -> [f32; 3] {
        let (c, cal, offs) = if accel {
            (&self.acc, self.acc_caltemp, self.acc_offs)
        } else {
            (&self.gyr, self.gyr_caltemp, self.gyr_offs)
        };
        let clamp = |t: f32| {
            if t < self.tmin {
                self.tmin
            } else if t > self.tmax {
                self.tmax
            } else {
                t
            }
        };
        let p = |axis: usize, d: f32| {
            (c[0][axis] + (c[1][axis] + c[2][axis] * d) * d) * d * (1.0e-6f64 as f32)
        };
        let (tc, tcal) = (clamp(t_c), clamp(cal));
        let refc = ARDUPILOT_TEMP_REFERENCE_C as f32;
        let o = offs.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| {
            let th = if self.enable == 1 {
                p(i, tc - refc) - p(i, tcal - refc)
            } else {
                0.0
            };
            th + o[i]
        })
    }
}

/// Reads `INS_TCAL<instance+1>_*` (all 21 required), `INS_ACC<n>_CALTEMP`,
/// `INS_GYR<n>_CALTEMP` and the instance's `INS_ACC…OFFS_*`/`INS_GYR…OFFS_*` (optional)
/// from a Mission Planner `.param` text: `NAME,VALUE` (or `NAME VALUE`, `NAME\tVALUE`) per
/// line, `#` starts a comment (also after the value). Errors as [`parse_px4`].
pub fn parse_ardupilot(
    text: &str,
    file: &str,
    instance: usize,
) -> Result<ArduPilotTcal, AutopilotError> {
    if instance >= ARDUPILOT_INSTANCES {
        return Err(AutopilotError::Instance {
            instance,
            autopilot: "ArduPilot",
            max: ARDUPILOT_INSTANCES - 1,
        });
    }
    let n1 = instance + 1;
    let g = format!("INS_TCAL{n1}_");
    let acc_cal = format!("INS_ACC{n1}_CALTEMP");
    let gyr_cal = format!("INS_GYR{n1}_CALTEMP");
    let offs: Vec<String> = [true, false]
        .iter()
        .flat_map(|&a| {
            AXES.iter()
                .map(move |&x| ardupilot_offs_name(a, instance, x))
        })
        .collect();
    let mut pf = ParamFile {
        file: file.to_owned(),
        entries: BTreeMap::new(),
        ignored: 0,
    };
    for (li, raw) in text.lines().enumerate() {
        let line = li + 1;
        let body = raw.trim_end_matches('\r');
        let body = body.split('#').next().unwrap_or("");
        if body.trim().is_empty() {
            continue;
        }
        let f = fields(body, |c| c == ',' || c == ' ' || c == '\t');
        if f.len() != 2 {
            return Err(syntax(
                file,
                line,
                count_column(body, &f, 2),
                format!("expected `NAME,VALUE`, found {} fields", f.len()),
            ));
        }
        let name = parameter_name(file, line, f[0])?;
        let (vcol, vtext) = f[1];
        let value = parse_number(file, line, vcol, vtext)?;
        let relevant = name.starts_with(&g)
            || name == acc_cal
            || name == gyr_cal
            || offs.iter().any(|o| o == name);
        pf.insert(
            name,
            Entry {
                value,
                line,
                column: vcol,
                mav_type: None,
            },
            relevant,
        )?;
    }
    if !pf.entries.keys().any(|k| k.starts_with(&g)) {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("no {g}* parameters"),
        });
    }
    let enable = pf.take_int(&format!("{g}ENABLE"))?;
    let tmin = pf.take_f32(&format!("{g}TMIN"))?;
    let tmax = pf.take_f32(&format!("{g}TMAX"))?;
    if tmin > tmax {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("{g}TMIN {tmin} > {g}TMAX {tmax}"),
        });
    }
    let mut acc = [[0.0f32; 3]; 3];
    let mut gyr = [[0.0f32; 3]; 3];
    for k in 0..3 {
        for (axis, a) in AXES.iter().enumerate() {
            acc[k][axis] = pf.take_f32(&format!("{g}ACC{}_{a}", k + 1))?;
            gyr[k][axis] = pf.take_f32(&format!("{g}GYR{}_{a}", k + 1))?;
        }
    }
    let acc_caltemp = pf
        .take_opt_f32(&acc_cal)?
        .unwrap_or(ARDUPILOT_CALTEMP_DEFAULT_C);
    let gyr_caltemp = pf
        .take_opt_f32(&gyr_cal)?
        .unwrap_or(ARDUPILOT_CALTEMP_DEFAULT_C);
    let mut triple = |names: &[String]| -> Result<Option<[f32; 3]>, AutopilotError> {
        let v: Vec<Option<f32>> = names
            .iter()
            .map(|n| pf.take_opt_f32(n))
            .collect::<Result<_, _>>()?;
        match v.as_slice() {
            [Some(a), Some(b), Some(c)] => Ok(Some([*a, *b, *c])),
            [None, None, None] => Ok(None),
            _ => Err(AutopilotError::Params {
                file: file.to_owned(),
                message: format!("{}: give all three axes or none", names.join("/")),
            }),
        }
    };
    let acc_offs = triple(&offs[..3])?;
    let gyr_offs = triple(&offs[3..])?;
    let ignored = pf.finish()?;
    Ok(ArduPilotTcal {
        instance,
        enable,
        tmin,
        tmax,
        acc,
        gyr,
        acc_caltemp,
        gyr_caltemp,
        acc_offs,
        gyr_offs,
        ignored,
    })
}

// ---------------------------------------------------------------------------------------
// Verification

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

fn fold_err(err: &mut f64, a: [f64; 3], b: [f64; 3]) {
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

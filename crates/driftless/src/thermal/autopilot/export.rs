//! Export of a bias model as PX4 or ArduPilot thermal-compensation parameters (the
//! parameter lists and the parameter-file text), with the Taylor shift to the
//! autopilot's reference temperature.

use super::*;

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

pub(super) fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// A parameter value as the autopilots store it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum ParamValue {
    /// float32 (MAV_PARAM_TYPE_REAL32 = 9).
    Float(f32),
    /// int32 (MAV_PARAM_TYPE_INT32 = 6).
    Int(i32),
}

impl ParamValue {
    pub(super) fn text(&self) -> String {
        match self {
            // Rust's Display: shortest round-trip digits, never exponent notation.
            ParamValue::Float(v) => format!("{v}"),
            ParamValue::Int(v) => format!("{v}"),
        }
    }
    pub(super) fn mav_type(&self) -> u8 {
        match self {
            ParamValue::Float(_) => 9,
            ParamValue::Int(_) => 6,
        }
    }
}

/// One named parameter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Param {
    /// Parameter name.
    pub name: String,
    /// Its value.
    pub value: ParamValue,
}

pub(super) fn float(name: String, v: f64) -> Result<Param, AutopilotError> {
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
pub(super) fn check_instance(
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
pub(crate) fn px4_params(m: &BiasModel, o: &ExportOptions) -> Result<Vec<Param>, AutopilotError> {
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
pub(super) fn ardupilot_offs_name(accel: bool, n: usize, axis: char) -> String {
    match (accel, n) {
        (true, 0) => format!("INS_ACCOFFS_{axis}"),
        (true, _) => format!("INS_ACC{}OFFS_{axis}", n + 1),
        (false, 0) => format!("INS_GYROFFS_{axis}"),
        (false, _) => format!("INS_GYR{}OFFS_{axis}", n + 1),
    }
}

/// ArduPilot parameters of the bias part (module docs).
pub(crate) fn ardupilot_params(
    m: &BiasModel,
    o: &ExportOptions,
) -> Result<Vec<Param>, AutopilotError> {
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

pub(super) fn sci(v: f64) -> String {
    format!("{v:.3e}")
}

/// The caveats every exported file carries as comments (`#` lines).
pub(super) fn header(m: &BiasModel, o: &ExportOptions, autopilot: &str) -> String {
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

//! The six writers of [`super::export`]; mappings and sources in the parent module's docs.

use driftless_model::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H};

use super::{
    AxisNoise, ExportError, ExportFormat, ExportOptions, Exported, ImuNoise, Sensor, SensorNoise,
    Slot, ValueSource, missing,
};
use crate::allan::noise_model::fmt_num;

/// One mGal in m/s² (KF-GINS's accelerometer bias unit).
pub(crate) const MILLIGAL: f64 = 1e-5;

/// A float as plain YAML 1.1 *and* 1.2 read it as a float: the shortest digits that read
/// back to the same f64, always with a decimal point and a signed exponent
/// (`5.817764173314432e-5`, `1.0e+2`). PyYAML's YAML 1.1 resolver takes `1e-5` (no point)
/// or `1.0e5` (unsigned exponent) for strings.
pub fn yaml_float(v: f64) -> String {
    let s = format!("{v:e}");
    let (m, e) = s.split_once('e').unwrap_or((s.as_str(), "0"));
    let m = if m.contains('.') {
        m.to_string()
    } else {
        format!("{m}.0")
    };
    let e = if e.starts_with('-') {
        e.to_string()
    } else {
        format!("+{e}")
    };
    format!("{m}e{e}")
}

fn term_name(slot: Slot) -> &'static str {
    match slot {
        Slot::White => "white noise N",
        Slot::RandomWalk => "rate random walk K",
        Slot::Bias => "Gauss-Markov bias",
    }
}

/// Where a value came from, for its comment; flagged values start with `CHECK:`.
fn origin(e: &Exported, slot: Slot, n_axes: usize) -> String {
    let ch = e.channel.as_deref().unwrap_or("?");
    let of_axes = if n_axes > 1 {
        format!(" (largest of {n_axes} axes)")
    } else {
        String::new()
    };
    let term = term_name(slot);
    match (slot, e.source) {
        (_, ValueSource::Fitted) => format!("{term} of {ch}{of_axes}"),
        (_, ValueSource::Given) => "given by the user".to_string(),
        (_, ValueSource::UpperLimit) => {
            format!("CHECK: {term} not detected on {ch}: its upper limit{of_axes}")
        }
        (Slot::Bias, ValueSource::GaussMarkov { tau_c_s }) => format!(
            "fitted Gauss-Markov term of {ch} (T_c = {} s){of_axes}",
            fmt_num(tau_c_s)
        ),
        (Slot::Bias, ValueSource::BiasInstability { tau_c_s }) => format!(
            "CHECK: the Gauss-Markov stand-in of the bias instability of {ch} (T_c = {} s), \
             whose Allan peak equals the floor{of_axes}",
            fmt_num(tau_c_s)
        ),
        (Slot::Bias, ValueSource::BiasInstabilityRangeEnd { tau_c_s }) => format!(
            "CHECK: the Gauss-Markov stand-in of the bias instability of {ch}, its Allan peak \
             put at the end of the fitted range (T_c = {} s; the floor runs on past it, so the \
             real T_c is longer){of_axes}",
            fmt_num(tau_c_s)
        ),
        (_, ValueSource::BiasInstabilityRangeEnd { tau_c_s }) => format!(
            "CHECK: K not detected on {ch}: sigma_b*sqrt(2/T_c) of the bias instability's \
             Gauss-Markov stand-in, its Allan peak put at the end of the fitted range \
             (T_c = {} s), a conservative bound{of_axes}",
            fmt_num(tau_c_s)
        ),
        (_, ValueSource::BiasInstability { tau_c_s }) => format!(
            "CHECK: K not detected on {ch}: sigma_b*sqrt(2/T_c) of the bias instability's \
             Gauss-Markov stand-in (T_c = {} s), a conservative bound{of_axes}",
            fmt_num(tau_c_s)
        ),
        (_, ValueSource::GaussMarkov { tau_c_s }) => format!(
            "CHECK: K not detected on {ch}: sigma*sqrt(2/T_c) of its Gauss-Markov term \
             (T_c = {} s), a conservative bound{of_axes}",
            fmt_num(tau_c_s)
        ),
    }
}

fn header(s: &mut String, title: &str, imu: &ImuNoise) {
    s.push_str(&format!("# {title}\n"));
    s.push_str(&format!(
        "# From the driftless noise model of {} (IMU rate {} Hz).\n",
        imu.source_file.as_deref().unwrap_or("an unnamed log"),
        fmt_num(imu.sample_rate_hz)
    ));
    s.push_str(
        "# Values of a static record, not inflated: motion, vibration and temperature add \
         noise the\n# estimator may need on top (see docs/noise-exports.md). Lines marked \
         CHECK hold a bound.\n",
    );
}

/// A required value of a sensor, or the error naming it.
fn need(
    format: ExportFormat,
    imu: &ImuNoise,
    s: Sensor,
    slot: Slot,
) -> Result<(Exported, usize), ExportError> {
    let n = s.noise(imu);
    let v = match slot {
        Slot::White => n.white_density.clone(),
        Slot::RandomWalk => n.random_walk_density.clone(),
        Slot::Bias => n.bias.as_ref().map(|b| Exported {
            value: b.sigma,
            source: b.source,
            channel: b.channel.clone(),
        }),
    };
    v.map(|e| (e, n.axes.len()))
        .ok_or_else(|| missing(format, s, slot, imu))
}

/// The four continuous-time values of Kalibr, OpenVINS and VINS, in Kalibr's key order
/// (accel N, accel K, gyro N, gyro K), each with its comment.
fn kalibr_values(
    format: ExportFormat,
    imu: &ImuNoise,
) -> Result<[(Exported, String); 4], ExportError> {
    let one = |s: Sensor, slot: Slot| -> Result<(Exported, String), ExportError> {
        let (e, n) = need(format, imu, s, slot)?;
        let c = origin(&e, slot, n);
        Ok((e, c))
    };
    Ok([
        one(Sensor::Accel, Slot::White)?,
        one(Sensor::Accel, Slot::RandomWalk)?,
        one(Sensor::Gyro, Slot::White)?,
        one(Sensor::Gyro, Slot::RandomWalk)?,
    ])
}

const KALIBR_KEYS: [(&str, &str); 4] = [
    ("accelerometer_noise_density", "m/s^2/sqrt(Hz)"),
    ("accelerometer_random_walk", "m/s^3/sqrt(Hz)"),
    ("gyroscope_noise_density", "rad/s/sqrt(Hz)"),
    ("gyroscope_random_walk", "rad/s^2/sqrt(Hz)"),
];

fn kalibr_body(s: &mut String, indent: &str, v: &[(Exported, String); 4]) {
    for ((key, unit), (e, why)) in KALIBR_KEYS.iter().zip(v) {
        s.push_str(&format!(
            "{indent}{key}: {}    # [{unit}] {why}\n",
            yaml_float(e.value)
        ));
    }
}

/// Kalibr `imu.yaml` (plain YAML, no tags or directives).
pub(super) fn kalibr(imu: &ImuNoise, opts: &ExportOptions) -> Result<String, ExportError> {
    let v = kalibr_values(ExportFormat::Kalibr, imu)?;
    let mut s = String::new();
    header(
        &mut s,
        "Kalibr IMU noise model (imu.yaml): continuous-time densities, SI units.",
        imu,
    );
    kalibr_body(&mut s, "", &v);
    s.push_str(&format!(
        "rostopic: {}    # the IMU topic of your bag\n",
        yaml_scalar(&opts.rostopic)
    ));
    s.push_str(&format!(
        "update_rate: {}    # [Hz]\n",
        yaml_float(imu.sample_rate_hz)
    ));
    Ok(s)
}

/// A string as a YAML scalar: plain when safe, else double-quoted.
fn yaml_scalar(t: &str) -> String {
    let plain = !t.is_empty()
        && t.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '/' | '_' | '-' | '.'))
        && !t.starts_with(['-', '.'])
        && t.parse::<f64>().is_err();
    if plain {
        t.to_string()
    } else {
        format!("\"{}\"", t.replace('\\', "\\\\").replace('"', "\\\""))
    }
}

/// OpenVINS `kalibr_imu_chain.yaml`: the `imu0:` block OpenVINS reads with OpenCV's
/// `FileStorage` (hence the `%YAML:1.0` first line), identity IMU intrinsics.
pub(super) fn openvins(imu: &ImuNoise, opts: &ExportOptions) -> Result<String, ExportError> {
    let v = kalibr_values(ExportFormat::OpenVins, imu)?;
    let mut s = String::from("%YAML:1.0\n\n");
    header(
        &mut s,
        "OpenVINS IMU chain (kalibr_imu_chain.yaml): continuous-time densities, SI units.",
        imu,
    );
    s.push_str("imu0:\n  T_i_b:\n");
    for r in 0..4 {
        let row: Vec<&str> = (0..4).map(|c| if r == c { "1.0" } else { "0.0" }).collect();
        s.push_str(&format!("    - [{}]\n", row.join(", ")));
    }
    kalibr_body(&mut s, "  ", &v);
    s.push_str(&format!(
        "  rostopic: {}    # the IMU topic of your bag\n",
        yaml_scalar(&opts.rostopic)
    ));
    s.push_str("  time_offset: 0.0\n");
    s.push_str(&format!(
        "  update_rate: {}    # [Hz]\n",
        yaml_float(imu.sample_rate_hz)
    ));
    s.push_str("  model: \"kalibr\"\n");
    for (name, identity) in [
        ("Tw", true),
        ("R_IMUtoGYRO", true),
        ("Ta", true),
        ("R_IMUtoACC", true),
        ("Tg", false),
    ] {
        s.push_str(&format!("  {name}:\n"));
        for r in 0..3 {
            let row: Vec<&str> = (0..3)
                .map(|c| if identity && r == c { "1.0" } else { "0.0" })
                .collect();
            s.push_str(&format!("    - [ {} ]\n", row.join(", ")));
        }
    }
    Ok(s)
}

/// VINS-Fusion / VINS-Mono config keys: per-sample σ at the IMU rate f (N·√f, K·√f).
pub(super) fn vins(imu: &ImuNoise) -> Result<String, ExportError> {
    let v = kalibr_values(ExportFormat::Vins, imu)?;
    let f = imu.sample_rate_hz;
    let mut s = String::new();
    header(
        &mut s,
        "VINS-Fusion / VINS-Mono IMU noise: paste into the estimator config (replacing its \
         acc_n, gyr_n, acc_w, gyr_w).",
        imu,
    );
    s.push_str(&format!(
        "# Per-sample standard deviations at the IMU rate f = {} Hz: density * sqrt(f) (VINS \
         adds (sigma*dt)^2 per\n# sample). If VINS receives the IMU at another rate f2, \
         multiply by sqrt(f2/f).\n",
        fmt_num(f)
    ));
    let [an, aw, gn, gw] = v;
    for (key, unit, (e, why)) in [
        ("acc_n", "m/s^2", an),
        ("gyr_n", "rad/s", gn),
        ("acc_w", "m/s^3", aw),
        ("gyr_w", "rad/s^2", gw),
    ] {
        s.push_str(&format!(
            "{key}: {}    # [{unit}] {why}\n",
            yaml_float(e.value * f.sqrt())
        ));
    }
    Ok(s)
}

/// The value of `slot` on one axis.
fn axis_value(a: &AxisNoise, slot: Slot) -> Option<Exported> {
    match slot {
        Slot::White => a.white_density.clone(),
        Slot::RandomWalk => a.random_walk_density.clone(),
        Slot::Bias => a.bias.as_ref().map(|b| Exported {
            value: b.sigma,
            source: b.source,
            channel: b.channel.clone(),
        }),
    }
}

/// Per-axis values of `slot` when the sensor has exactly the three channels ending in x,
/// y and z, each with that value; None: use the largest on all axes.
fn xyz_values(n: &SensorNoise, slot: Slot) -> Option<[(String, Exported); 3]> {
    if n.axes.len() != 3 {
        return None;
    }
    let find = |suffix: char| {
        let mut it = n
            .axes
            .iter()
            .filter(|a| a.channel.to_ascii_lowercase().ends_with(suffix));
        match (it.next(), it.next()) {
            (Some(a), None) => Some((a.channel.clone(), axis_value(a, slot)?)),
            _ => None,
        }
    };
    Some([find('x')?, find('y')?, find('z')?])
}

/// KF-GINS's three per-axis values of `slot` in its unit (`scale` = one KF-GINS unit in
/// SI) and the comment.
fn kfgins_triple(
    imu: &ImuNoise,
    s: Sensor,
    slot: Slot,
    scale: f64,
) -> Result<([f64; 3], String), ExportError> {
    let n = s.noise(imu);
    let (agg, count) = need(ExportFormat::KfGins, imu, s, slot)?;
    let per_axis = if agg.source == ValueSource::Given {
        None
    } else {
        xyz_values(n, slot)
    };
    if let Some(axes) = per_axis {
        let v = [0, 1, 2].map(|i| axes[i].1.value / scale);
        let names: Vec<&str> = axes.iter().map(|(c, _)| c.as_str()).collect();
        let mut why = format!("{} of {}", term_name(slot), names.join(", "));
        for (_, e) in &axes {
            let o = origin(e, slot, 1);
            if o.starts_with("CHECK") {
                why = format!("{why}; {o}");
            }
        }
        Ok((v, why))
    } else {
        let why = format!(
            "{}; the same on all three axes (the model's channels are not one each of x, y \
             and z with this term)",
            origin(&agg, slot, count)
        );
        Ok(([agg.value / scale; 3], why))
    }
}

/// KF-GINS `imunoise:` block, readable by [`crate::io::nav::kfgins_config`].
pub(super) fn kfgins(imu: &ImuNoise) -> Result<String, ExportError> {
    let (arw, arw_why) = kfgins_triple(imu, Sensor::Gyro, Slot::White, DEG_PER_SQRT_H)?;
    let (vrw, vrw_why) = kfgins_triple(imu, Sensor::Accel, Slot::White, M_PER_S_PER_SQRT_H)?;
    let (gb, gb_why) = kfgins_triple(imu, Sensor::Gyro, Slot::Bias, DEG_PER_H)?;
    let (ab, ab_why) = kfgins_triple(imu, Sensor::Accel, Slot::Bias, MILLIGAL)?;
    let bias_source = |s: Sensor| s.noise(imu).bias.as_ref().map(|b| b.tau_c_s);
    let (tau_s, tau_why) = match imu.given_corr_time_s {
        Some(t) => (t, "given by the user".to_string()),
        None => {
            let (g, a) = (bias_source(Sensor::Gyro), bias_source(Sensor::Accel));
            match (g, a) {
                (Some(g), Some(a)) => (
                    g.min(a),
                    "the shortest Gauss-Markov correlation time of all channels (KF-GINS has \
                     one for all biases)"
                        .to_string(),
                ),
                _ => {
                    let s = if g.is_none() {
                        Sensor::Gyro
                    } else {
                        Sensor::Accel
                    };
                    return Err(missing(ExportFormat::KfGins, s, Slot::Bias, imu));
                }
            }
        }
    };
    let v = |a: [f64; 3]| {
        format!(
            "[ {}, {}, {} ]",
            yaml_float(a[0]),
            yaml_float(a[1]),
            yaml_float(a[2])
        )
    };
    let mut s = String::new();
    header(
        &mut s,
        "KF-GINS IMU noise (imunoise block): replace the imunoise block of your kf-gins.yaml.",
        imu,
    );
    s.push_str("imunoise:\n");
    for (key, values, unit, why) in [
        ("arw", arw, "deg/sqrt(hr)", arw_why),
        ("vrw", vrw, "m/s/sqrt(hr)", vrw_why),
        (
            "gbstd",
            gb,
            "deg/hr",
            format!("Gauss-Markov sigma: {gb_why}"),
        ),
        ("abstd", ab, "mGal", format!("Gauss-Markov sigma: {ab_why}")),
    ] {
        s.push_str(&format!("  {key}: {}    # [{unit}] {why}\n", v(values)));
    }
    for key in ["gsstd", "asstd"] {
        s.push_str(&format!(
            "  {key}: {}    # [ppm] CHECK: not measured by a static Allan record; 0 keeps \
             KF-GINS's scale-factor states fixed: set your sensor's scale-factor stability\n",
            v([0.0; 3])
        ));
    }
    s.push_str(&format!(
        "  corrtime: {}    # [hr] {tau_why}\n",
        yaml_float(tau_s / 3600.0)
    ));
    Ok(s)
}

/// What the four autopilot parameters hold, in the order of the tables below: sensor,
/// value and unit.
const AUTOPILOT_SLOTS: [(Sensor, Slot, &str); 4] = [
    (Sensor::Gyro, Slot::White, "rad/s"),
    (Sensor::Accel, Slot::White, "m/s^2"),
    (Sensor::Gyro, Slot::RandomWalk, "rad/s^2"),
    (Sensor::Accel, Slot::RandomWalk, "m/s^3"),
];

/// An autopilot parameter: name, default and documented range (for the comment).
type Param = (&'static str, f64, (f64, f64));

/// PX4 EKF2 (`ekf2/module.yaml`).
const PX4_PARAMS: [Param; 4] = [
    ("EKF2_GYR_NOISE", 0.015, (0.0001, 0.1)),
    ("EKF2_ACC_NOISE", 0.35, (0.01, 1.0)),
    ("EKF2_GYR_B_NOISE", 0.001, (0.0, 0.01)),
    ("EKF2_ACC_B_NOISE", 0.003, (0.0, 0.01)),
];

/// ArduPilot EKF3 (`AP_NavEKF3.cpp` parameter table).
const ARDUPILOT_PARAMS: [Param; 4] = [
    ("EK3_GYRO_P_NSE", 0.015, (0.0001, 0.1)),
    ("EK3_ACC_P_NSE", 0.35, (0.01, 1.0)),
    ("EK3_GBIAS_P_NSE", 0.001, (0.00001, 0.001)),
    ("EK3_ABIAS_P_NSE", 0.003, (0.00001, 0.005)),
];

/// A parameter to write: name, value, comment.
type ParamLine = (&'static str, f64, String);

/// The parameters that exist, and the names left out.
fn autopilot_values(
    format: ExportFormat,
    imu: &ImuNoise,
    params: &[Param],
    rate_hz: f64,
) -> Result<(Vec<ParamLine>, Vec<String>), ExportError> {
    let mut out = Vec::new();
    let mut left_out = Vec::new();
    for (&(name, default, range), &(sensor, slot, unit)) in params.iter().zip(&AUTOPILOT_SLOTS) {
        match need(format, imu, sensor, slot) {
            Ok((e, n)) => {
                let value = e.value * rate_hz.sqrt();
                let mut why = format!(
                    "[{unit}] {} * sqrt({} Hz filter rate); {}; default {default}",
                    if slot == Slot::White {
                        "density"
                    } else {
                        "random-walk density"
                    },
                    fmt_num(rate_hz),
                    origin(&e, slot, n),
                );
                if !(range.0..=range.1).contains(&value) {
                    why.push_str(&format!(
                        "; NOTE: outside the documented range [{}, {}]",
                        range.0, range.1
                    ));
                }
                out.push((name, value, why));
            }
            Err(e) => left_out.push(format!("{name}: not written ({e})")),
        }
    }
    if out.is_empty() {
        return Err(missing(format, Sensor::Gyro, Slot::White, imu));
    }
    Ok((out, left_out))
}

/// An autopilot parameter file: the header, `preamble`, then per parameter a comment line
/// and `line(name, value)`.
fn autopilot_file(
    format: ExportFormat,
    imu: &ImuNoise,
    params: &[Param],
    rate_hz: f64,
    title: &str,
    preamble: &str,
    line: impl Fn(&str, f64) -> String,
) -> Result<String, ExportError> {
    let (values, left_out) = autopilot_values(format, imu, params, rate_hz)?;
    let mut s = String::new();
    header(&mut s, title, imu);
    s.push_str(
        "# The defaults are tens of times a bench value: they also cover vibration and \
         model errors.\n",
    );
    for l in left_out {
        s.push_str(&format!("# {l}\n"));
    }
    s.push_str(preamble);
    for (name, value, why) in values {
        s.push_str(&format!("# {name}: {why}\n{}\n", line(name, value)));
    }
    Ok(s)
}

/// PX4 EKF2 parameters as a QGroundControl `.params` file (tab-separated, type 9 = float).
pub(super) fn px4(imu: &ImuNoise, opts: &ExportOptions) -> Result<String, ExportError> {
    autopilot_file(
        ExportFormat::Px4,
        imu,
        &PX4_PARAMS,
        opts.px4_filter_rate_hz,
        "PX4 EKF2 IMU process noise (QGroundControl parameter file).",
        "#\n# Vehicle-Id\tComponent-Id\tName\tValue\tType\n",
        |name, value| format!("1\t1\t{name}\t{value}\t9"),
    )
}

/// ArduPilot EKF3 parameters as a `.param` file (`NAME,VALUE`, as Mission Planner writes).
pub(super) fn ardupilot(imu: &ImuNoise, opts: &ExportOptions) -> Result<String, ExportError> {
    autopilot_file(
        ExportFormat::ArduPilot,
        imu,
        &ARDUPILOT_PARAMS,
        opts.ardupilot_filter_rate_hz,
        "ArduPilot EKF3 IMU process noise (parameter file).",
        "",
        |name, value| format!("{name},{value}"),
    )
}

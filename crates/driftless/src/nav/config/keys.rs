//! The keys of a navigation configuration: TOML path, command-line flag, value kind and
//! help, in the order `driftless nav --print-config` writes them. One table serves the
//! file, the flags and the printed default, so the three cannot drift apart.

/// How a flag's text becomes a TOML value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueKind {
    /// A number (`-0.125`).
    Float,
    /// A number or the word `auto`.
    FloatOrAuto,
    /// `true` / `false`; the flag alone means `true`.
    Bool,
    /// Text (a name, a path, a value with its unit).
    Text,
    /// Three comma-separated numbers (`180,0,180`).
    Vec3,
    /// Comma-separated names (`fix,float`).
    List,
    /// Comma-separated `name=number` pairs (`fix=1,float=3`).
    Table,
}

/// One configuration key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Key {
    /// Dotted TOML path, `section.key`.
    pub path: &'static str,
    /// Long flag without the dashes.
    pub flag: &'static str,
    /// Value placeholder for the flag's help.
    pub value_name: &'static str,
    /// How the flag's text is read.
    pub kind: ValueKind,
    /// One-line help (flag help and comment in the printed configuration).
    pub help: &'static str,
    /// For keys without a default: an example value (TOML), printed commented out.
    pub example: &'static str,
}

const fn key(
    path: &'static str,
    flag: &'static str,
    value_name: &'static str,
    kind: ValueKind,
    help: &'static str,
    example: &'static str,
) -> Key {
    Key {
        path,
        flag,
        value_name,
        kind,
        help,
        example,
    }
}

use ValueKind::{Bool, Float, FloatOrAuto, List, Table, Text, Vec3};

/// Every key, section by section.
pub const KEYS: &[Key] = &[
    // [imu]
    key(
        "imu.file",
        "imu",
        "FILE",
        Text,
        "IMU log (relative paths resolve against this file's folder)",
        "\"imu.txt\"",
    ),
    key(
        "imu.format",
        "imu-format",
        "FORMAT",
        Text,
        "auto | kfgins (time, dθ, dv increments) | tagged-csv (RTKLIB-tagged acc [g], gyro [deg/s], tick [ms]) | csv (rates with units in the header); auto: tagged-csv when a tag file is given or FILE.tag exists, csv when the first line is a header, else kfgins",
        "",
    ),
    key(
        "imu.tag",
        "tag",
        "FILE.tag",
        Text,
        "RTKLIB time-tag file of a tagged CSV (default FILE.tag); giving it selects the tagged-CSV reader",
        "\"imu.csv.tag\"",
    ),
    key(
        "imu.time_offset_s",
        "imu-time-offset",
        "S",
        Float,
        "added to every IMU time stamp, s (an IMU that lags GNSS by 0.125 s takes -0.125)",
        "",
    ),
    key(
        "imu.time_base",
        "imu-time-base",
        "BASE",
        Text,
        "IMU time column: gps-sow (GPS seconds of week), gps-week-sow (with a week column), gpst-unix (Unix seconds in GPS time), utc-unix (Unix seconds in UTC; leap seconds applied)",
        "",
    ),
    key(
        "imu.week_column",
        "imu-week-column",
        "COL",
        Text,
        "GPS week column of a rates CSV (header name or 1-based number), for gps-week-sow",
        "\"week\"",
    ),
    key(
        "imu.rate_hz",
        "imu-rate",
        "HZ",
        Float,
        "nominal sample rate, Hz; default: from the time stamps (median interval), which is what real logs run at",
        "100.0",
    ),
    key(
        "imu.mounting_rpy_deg",
        "mounting-rpy-deg",
        "R,P,Y",
        Vec3,
        "IMU axes rotated from the vehicle forward-right-down frame by roll, pitch, yaw (z-y-x: yaw first, then pitch, then roll), deg",
        "",
    ),
    key(
        "imu.misalignment_rpy_deg",
        "misalignment-rpy-deg",
        "R,P,Y",
        Vec3,
        "small misalignment on top of the mounting, about the vehicle axes: C_vb = E(misalignment)·E(mounting), deg",
        "",
    ),
    key(
        "imu.calibration",
        "calibration",
        "FILE.toml",
        Text,
        "calibration model (`driftless calibrate --out`) applied to the IMU first; its raw units must be SI",
        "\"imu-cal.toml\"",
    ),
    key(
        "imu.gaps",
        "imu-gaps",
        "POLICY",
        Text,
        "error | bridge: an IMU interval longer than twice the nominal one stops the run, or is integrated across with a note",
        "",
    ),
    key(
        "imu.repair_spikes",
        "repair-spikes",
        "BOOL",
        Bool,
        "replace isolated non-physical or outlier IMU samples (one or two in a row) by interpolation of their neighbours; without it a non-physical sample stops the run",
        "",
    ),
    key(
        "imu.max_gyro_deg_s",
        "max-gyro-deg-s",
        "DEG_S",
        Float,
        "hard limit on a gyro sample, deg/s: above it a sample is non-physical (twice the widest MEMS range, ±2000 deg/s)",
        "",
    ),
    key(
        "imu.max_accel_g",
        "max-accel-g",
        "G",
        Float,
        "hard limit on an accelerometer sample, g: above it a sample is non-physical (twice the ±200 g of high-g MEMS parts)",
        "",
    ),
    // [gnss]
    key(
        "gnss.file",
        "gnss",
        "FILE",
        Text,
        "GNSS fixes: RTKLIB .pos or KF-GINS GNSS text (detected)",
        "\"gnss.pos\"",
    ),
    key(
        "gnss.lever_arm_m",
        "lever-arm",
        "X,Y,Z",
        Vec3,
        "antenna phase centre from the IMU, vehicle forward-right-down frame, m",
        "",
    ),
    key(
        "gnss.sigma_floor_m",
        "gnss-sigma-floor",
        "auto|M",
        FloatOrAuto,
        "floor on the fixes' σ: `auto` estimates it per solution quality from the innovations of a first pass (a receiver's formal RTK σ of ~1 cm ignores antenna motion, multipath and time-tag error; where the file's σ is right the estimate stays below it); a number is a fixed horizontal floor in m, 0 the file's σ",
        "",
    ),
    key(
        "gnss.sigma_floor_vertical_m",
        "gnss-sigma-floor-vertical",
        "M",
        Float,
        "floor on the vertical σ, m; default: estimated with `auto`, else twice the horizontal floor",
        "0.1",
    ),
    key(
        "gnss.sigma_scale",
        "gnss-sigma-scale",
        "QUALITY=K,..",
        Table,
        "σ multiplier per solution quality (fix, float, sbas, dgps, single, ppp, unspecified)",
        "",
    ),
    key(
        "gnss.accept",
        "gnss-accept",
        "QUALITY,..",
        List,
        "solution qualities used; others are dropped before the filter",
        "",
    ),
    key(
        "gnss.use_velocity",
        "gnss-velocity",
        "BOOL",
        Bool,
        "use GNSS velocity as a measurement when the file has it with σ",
        "",
    ),
    // [noise]
    key(
        "noise.model",
        "noise-model",
        "FILE.toml",
        Text,
        "Allan noise model (`driftless allan --save-model`); the values below override it",
        "\"noise.toml\"",
    ),
    key(
        "noise.gyro_white",
        "gyro-noise",
        "VALUE",
        Text,
        "gyro white noise: `0.23 deg/sqrt(h)` or `3.8 mdeg/s/sqrt(Hz)` (built-in: 0.5 deg/sqrt(h))",
        "\"3.8 mdeg/s/sqrt(Hz)\"",
    ),
    key(
        "noise.accel_white",
        "accel-noise",
        "VALUE",
        Text,
        "accelerometer white noise: `0.04 m/s/sqrt(h)` or `70 ug/sqrt(Hz)` (built-in: 0.08 m/s/sqrt(h))",
        "\"70 ug/sqrt(Hz)\"",
    ),
    key(
        "noise.gyro_bias_instability",
        "gyro-bias-instability",
        "VALUE",
        Text,
        "gyro bias instability (`8 deg/h`): with the random walk, the in-run bias as a Gauss–Markov process of σ² = B² + K²T/2",
        "\"8 deg/h\"",
    ),
    key(
        "noise.accel_bias_instability",
        "accel-bias-instability",
        "VALUE",
        Text,
        "accelerometer bias instability (`40 ug`)",
        "\"40 ug\"",
    ),
    key(
        "noise.gyro_bias_random_walk",
        "gyro-bias-random-walk",
        "VALUE",
        Text,
        "gyro rate random walk, the bias PSD (`40 deg/h/sqrt(h)`)",
        "\"40 deg/h/sqrt(h)\"",
    ),
    key(
        "noise.accel_bias_random_walk",
        "accel-bias-random-walk",
        "VALUE",
        Text,
        "accelerometer bias random walk (`3e-5 m/s^2/sqrt(s)`)",
        "\"3e-5 m/s^2/sqrt(s)\"",
    ),
    key(
        "noise.gyro_bias_sigma",
        "gyro-bias-sigma",
        "VALUE",
        Text,
        "in-run gyro bias as a Gauss–Markov σ (`0.3 deg/s`); replaces instability and random walk (built-in: 0.3 deg/s)",
        "\"0.3 deg/s\"",
    ),
    key(
        "noise.accel_bias_sigma",
        "accel-bias-sigma",
        "VALUE",
        Text,
        "in-run accelerometer bias as a Gauss–Markov σ (built-in: 30 mg)",
        "\"30 mg\"",
    ),
    key(
        "noise.bias_tau_s",
        "bias-tau",
        "S",
        Float,
        "Gauss–Markov correlation time of the biases, s",
        "",
    ),
    key(
        "noise.gyro_bias_initial",
        "gyro-bias-initial",
        "VALUE",
        Text,
        "σ of the turn-on gyro bias (data sheet zero-rate offset), the filter's initial uncertainty",
        "",
    ),
    key(
        "noise.accel_bias_initial",
        "accel-bias-initial",
        "VALUE",
        Text,
        "σ of the turn-on accelerometer bias (data sheet zero-g offset)",
        "",
    ),
    key(
        "noise.gyro_scale_sigma",
        "gyro-scale-sigma",
        "VALUE",
        Text,
        "gyro scale-factor error σ (`5000 ppm`, `0.5 %`)",
        "",
    ),
    key(
        "noise.accel_scale_sigma",
        "accel-scale-sigma",
        "VALUE",
        Text,
        "accelerometer scale-factor error σ",
        "",
    ),
    key(
        "noise.scale_tau_s",
        "scale-tau",
        "S",
        Float,
        "Gauss–Markov correlation time of the scale factors, s",
        "",
    ),
    key(
        "noise.multiplier",
        "noise-multiplier",
        "GROUP=K,..",
        Table,
        "multipliers for unmodelled errors: white (both white noises), bias (in-run bias σ), scale",
        "",
    ),
    // [align]
    key(
        "align.min_speed_m_s",
        "align-min-speed",
        "M_PER_S",
        Float,
        "start at the first fix whose GNSS course is trusted: horizontal speed above this, m/s",
        "",
    ),
    key(
        "align.max_heading_sigma_deg",
        "align-max-heading-sigma",
        "DEG",
        Float,
        "largest heading σ accepted from the GNSS course (σ_v/v and the turn over the baseline); a fix above it is passed over for a later one, deg",
        "",
    ),
    key(
        "align.baseline_s",
        "align-baseline",
        "S",
        Float,
        "baseline of the fixes whose chord gives the course for position-only GNSS, s",
        "",
    ),
    key(
        "align.initial_yaw_deg",
        "initial-yaw-deg",
        "Y",
        Float,
        "given initial heading, deg from north: start at the first fix whatever the speed",
        "90.0",
    ),
    key(
        "align.initial_attitude_deg",
        "initial-attitude-deg",
        "R,P,Y",
        Vec3,
        "given initial roll, pitch, yaw, deg",
        "[0.0, 0.0, 90.0]",
    ),
    key(
        "align.static_s",
        "align-static",
        "S",
        Float,
        "length of the static start used for the gyro biases and levelling, s (0 = off)",
        "",
    ),
    // [aids]
    key(
        "aids.zupt",
        "zupt",
        "BOOL",
        Bool,
        "standstill detection with zero-velocity and zero-rate updates",
        "",
    ),
    key(
        "aids.zupt_sigma_m_s",
        "zupt-sigma",
        "M_PER_S",
        Float,
        "ZUPT σ per axis, m/s",
        "",
    ),
    key(
        "aids.zaru_sigma_deg_s",
        "zaru-sigma",
        "DEG_PER_S",
        Float,
        "ZARU σ per axis, deg/s",
        "",
    ),
    key(
        "aids.standstill_window_s",
        "standstill-window",
        "S",
        Float,
        "standstill detector window, s",
        "",
    ),
    key(
        "aids.standstill_min_s",
        "standstill-min",
        "S",
        Float,
        "static time before a standstill is declared, s",
        "",
    ),
    key(
        "aids.standstill_accel_std_m_s2",
        "standstill-accel-std",
        "M_PER_S2",
        Float,
        "largest specific-force σ in a static window, m/s²",
        "",
    ),
    key(
        "aids.standstill_gyro_std_deg_s",
        "standstill-gyro-std",
        "DEG_PER_S",
        Float,
        "largest angular-rate σ in a static window, deg/s",
        "",
    ),
    key(
        "aids.standstill_max_speed_m_s",
        "standstill-max-speed",
        "M_PER_S",
        Float,
        "no standstill above this filter speed, m/s",
        "",
    ),
    key(
        "aids.nhc",
        "nhc",
        "BOOL",
        Bool,
        "non-holonomic constraint (wheeled vehicles: no sideways or vertical velocity)",
        "",
    ),
    key(
        "aids.nhc_sigma_m_s",
        "nhc-sigma",
        "M_PER_S",
        Float,
        "NHC σ, lateral and vertical, m/s",
        "",
    ),
    key(
        "aids.nhc_min_speed_m_s",
        "nhc-min-speed",
        "M_PER_S",
        Float,
        "NHC only above this speed, m/s",
        "",
    ),
    key(
        "aids.nhc_max_yaw_rate_deg_s",
        "nhc-max-yaw-rate",
        "DEG_PER_S",
        Float,
        "NHC skipped above this yaw rate, deg/s",
        "",
    ),
    // [filter]
    key(
        "filter.gate",
        "gate",
        "off|chi2:P|robust",
        Text,
        "innovation gate: off, chi2:P (reject beyond the χ² quantile P), robust (inflate σ of large innovations instead of dropping fixes)",
        "",
    ),
    key(
        "filter.smooth",
        "smooth",
        "BOOL",
        Bool,
        "also run the RTS smoother",
        "",
    ),
    // [outages]
    key(
        "outages.spec",
        "outages",
        "SPEC",
        Text,
        "simulated GNSS outages (s, e]: none | 300+60,600+60 (s after the first fix) | @243600+60 (absolute) | 6x60s every 80s from 80s | auto:9x60",
        "",
    ),
    key(
        "outages.converge_s",
        "converge",
        "S",
        Float,
        "time after the start left out of the full-GNSS fit, s",
        "",
    ),
    key(
        "outages.reconverge_s",
        "reconverge",
        "S",
        Float,
        "time after each outage left out of the full-GNSS fit, s",
        "",
    ),
];

/// The key with this dotted path.
pub fn key_by_path(path: &str) -> Option<&'static Key> {
    KEYS.iter().find(|k| k.path == path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_and_flags_are_unique() {
        for (i, a) in KEYS.iter().enumerate() {
            for b in &KEYS[i + 1..] {
                assert_ne!(a.path, b.path);
                assert_ne!(a.flag, b.flag);
            }
        }
    }
}

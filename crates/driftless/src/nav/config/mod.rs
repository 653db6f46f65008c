//! A navigation configuration a dataset's author can fill in: what the data are (formats,
//! time offset, mounting, lever arm), how noisy the sensor is (an Allan model or data-sheet
//! values in the units people have), how to treat GNSS, how to start, which aids to use.
//!
//! One TOML file (`driftless nav --config nav.toml`; `driftless nav --print-config` writes
//! the commented default), every key also a flag ([`KEYS`]); flags override the file.
//! [`NavConfig::load`] reads both, checks every value and names where a bad one came from:
//! `FILE:LINE:COL` for the file, the flag for a flag. Nothing here reads a data file or
//! runs a filter: [`crate::nav::job`] does that with the settings this module resolves.
//!
//! Defaults are chosen to be safe on any platform (a car, a walk, a robot): identity
//! mounting, no aids, consumer-MEMS noise when nothing is said, the robust gate, heading
//! from the GNSS course above 1 m/s.

mod keys;
mod load;
pub mod quantity;
mod settings;
mod validate;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use keys::{KEYS, Key, ValueKind, key_by_path};
use quantity::{Kind, parse_quantity};
use validate::*;

use crate::nav::filter::aids::{NhcConfig, StandstillConfig};
use crate::nav::filter::model::{Gate, GaussMarkov, ImuNoise, QualityScale};
use crate::nav::pipeline::{ImuGapPolicy, ImuStreamOptions, Mounting};

/// The whole configuration (module docs). Every section and key has a default.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NavConfig {
    /// The IMU log and how to read it.
    pub imu: ImuSection,
    /// The GNSS fixes and how to weight them.
    pub gnss: GnssSection,
    /// IMU noise and sensor-error model.
    pub noise: NoiseSection,
    /// Initial alignment.
    pub align: AlignSection,
    /// Vehicle aids.
    pub aids: AidsSection,
    /// Filter options.
    pub filter: FilterSection,
    /// Simulated outages and the evaluation.
    pub outages: OutageSection,
}

/// `[imu]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImuSection {
    /// IMU log.
    pub file: Option<PathBuf>,
    /// `auto`, `kfgins`, `tagged-csv` or `csv`.
    pub format: String,
    /// RTKLIB time-tag file of a tagged CSV.
    pub tag: Option<PathBuf>,
    /// Added to the IMU time stamps, s.
    pub time_offset_s: f64,
    /// Time base of the IMU time column ([`crate::io::nav::TimeBase`] name).
    pub time_base: String,
    /// Week column of a rates CSV.
    pub week_column: Option<String>,
    /// Nominal rate, Hz; `None` = from the time stamps.
    pub rate_hz: Option<f64>,
    /// Mounting roll, pitch, yaw, deg ([`Mounting`]).
    pub mounting_rpy_deg: [f64; 3],
    /// Misalignment on top of the mounting, deg.
    pub misalignment_rpy_deg: [f64; 3],
    /// Calibration model file.
    pub calibration: Option<PathBuf>,
    /// `error` or `bridge`.
    pub gaps: String,
    /// Replace isolated non-physical or outlier samples by interpolation of their
    /// neighbours ([`crate::nav::imu_check::repair_spikes`]) instead of refusing to
    /// navigate through non-physical values.
    pub repair_spikes: bool,
    /// Hard limit on a gyro sample, °/s ([`crate::nav::imu_check::ImuCheckConfig`]).
    pub max_gyro_deg_s: f64,
    /// Hard limit on an accelerometer sample, g (9.806 65 m/s²).
    pub max_accel_g: f64,
}

impl Default for ImuSection {
    fn default() -> Self {
        ImuSection {
            file: None,
            format: "auto".into(),
            tag: None,
            time_offset_s: 0.0,
            time_base: "gps-sow".into(),
            week_column: None,
            rate_hz: None,
            mounting_rpy_deg: [0.0; 3],
            misalignment_rpy_deg: [0.0; 3],
            calibration: None,
            gaps: "error".into(),
            repair_spikes: false,
            max_gyro_deg_s: 4000.0,
            max_accel_g: 400.0,
        }
    }
}

/// `[gnss]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GnssSection {
    /// GNSS file.
    pub file: Option<PathBuf>,
    /// Antenna from the IMU, vehicle FRD, m.
    pub lever_arm_m: [f64; 3],
    /// Horizontal σ floor: `auto` (estimated from the innovations of a first pass,
    /// [`crate::nav::gnss_floor`]) or metres (0 = the file's σ).
    pub sigma_floor_m: FloorSetting,
    /// Vertical σ floor, m (default: estimated with `auto`, else 2 × horizontal).
    pub sigma_floor_vertical_m: Option<f64>,
    /// σ multiplier per quality name.
    pub sigma_scale: QualityTable,
    /// Quality names used.
    pub accept: Vec<String>,
    /// Use GNSS velocity when present.
    pub use_velocity: bool,
}

impl Default for GnssSection {
    fn default() -> Self {
        GnssSection {
            file: None,
            lever_arm_m: [0.0; 3],
            sigma_floor_m: FloorSetting::Auto,
            sigma_floor_vertical_m: None,
            sigma_scale: QualityTable::default(),
            accept: QUALITY_NAMES.iter().map(|s| (*s).to_owned()).collect(),
            use_velocity: true,
        }
    }
}

/// `gnss.sigma_floor_m`: the word `auto` or a number of metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FloorSetting {
    /// Estimated from the data ([`crate::nav::gnss_floor`]).
    Auto,
    /// A fixed floor, m (0 = none).
    Metres(f64),
}

impl Serialize for FloorSetting {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            FloorSetting::Auto => s.serialize_str("auto"),
            FloorSetting::Metres(m) => s.serialize_f64(*m),
        }
    }
}

impl<'de> Deserialize<'de> for FloorSetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = FloorSetting;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"auto\" or a number of metres")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<FloorSetting, E> {
                if v.trim() == "auto" {
                    Ok(FloorSetting::Auto)
                } else {
                    Err(E::custom(format!(
                        "{v:?}: expected \"auto\" or a number of metres"
                    )))
                }
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<FloorSetting, E> {
                Ok(FloorSetting::Metres(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<FloorSetting, E> {
                Ok(FloorSetting::Metres(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<FloorSetting, E> {
                Ok(FloorSetting::Metres(v as f64))
            }
        }
        d.deserialize_any(V)
    }
}

/// RTKLIB solution-quality names, in flag order 0..=6.
pub const QUALITY_NAMES: [&str; 7] = [
    "unspecified",
    "fix",
    "float",
    "sbas",
    "dgps",
    "single",
    "ppp",
];

/// σ multiplier per solution quality.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QualityTable {
    /// Flag 0.
    pub unspecified: f64,
    /// Fixed RTK.
    pub fix: f64,
    /// Float RTK.
    pub float: f64,
    /// SBAS.
    pub sbas: f64,
    /// DGPS.
    pub dgps: f64,
    /// Single point.
    pub single: f64,
    /// PPP.
    pub ppp: f64,
}

impl Default for QualityTable {
    fn default() -> Self {
        let q = QualityScale::default().0;
        QualityTable {
            unspecified: q[0],
            fix: q[1],
            float: q[2],
            sbas: q[3],
            dgps: q[4],
            single: q[5],
            ppp: q[6],
        }
    }
}

impl QualityTable {
    fn as_array(&self) -> [f64; 7] {
        [
            self.unspecified,
            self.fix,
            self.float,
            self.sbas,
            self.dgps,
            self.single,
            self.ppp,
        ]
    }
}

/// `[noise]`: values with units ([`quantity`]); unset values come from the noise model
/// file, else from the built-in consumer-MEMS defaults
/// ([`crate::nav::session::consumer_mems_noise`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseSection {
    /// Allan noise-model file.
    pub model: Option<PathBuf>,
    /// Gyro white noise.
    pub gyro_white: Option<String>,
    /// Accelerometer white noise.
    pub accel_white: Option<String>,
    /// Gyro bias instability.
    pub gyro_bias_instability: Option<String>,
    /// Accelerometer bias instability.
    pub accel_bias_instability: Option<String>,
    /// Gyro rate random walk.
    pub gyro_bias_random_walk: Option<String>,
    /// Accelerometer bias random walk.
    pub accel_bias_random_walk: Option<String>,
    /// In-run gyro bias Gauss–Markov σ.
    pub gyro_bias_sigma: Option<String>,
    /// In-run accelerometer bias Gauss–Markov σ.
    pub accel_bias_sigma: Option<String>,
    /// Bias correlation time, s.
    pub bias_tau_s: f64,
    /// Turn-on gyro bias σ.
    pub gyro_bias_initial: String,
    /// Turn-on accelerometer bias σ.
    pub accel_bias_initial: String,
    /// Gyro scale-factor σ.
    pub gyro_scale_sigma: String,
    /// Accelerometer scale-factor σ.
    pub accel_scale_sigma: String,
    /// Scale-factor correlation time, s.
    pub scale_tau_s: f64,
    /// Multipliers for unmodelled errors.
    pub multiplier: NoiseMultipliers,
}

impl Default for NoiseSection {
    fn default() -> Self {
        NoiseSection {
            model: None,
            gyro_white: None,
            accel_white: None,
            gyro_bias_instability: None,
            accel_bias_instability: None,
            gyro_bias_random_walk: None,
            accel_bias_random_walk: None,
            gyro_bias_sigma: None,
            accel_bias_sigma: None,
            bias_tau_s: 3600.0,
            gyro_bias_initial: "0.3 deg/s".into(),
            accel_bias_initial: "30 mg".into(),
            gyro_scale_sigma: "5000 ppm".into(),
            accel_scale_sigma: "5000 ppm".into(),
            scale_tau_s: 3600.0,
            multiplier: NoiseMultipliers::default(),
        }
    }
}

/// One multiplier per group of noise terms (authors' allowance for unmodelled errors:
/// vibration, temperature, nonlinearity).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseMultipliers {
    /// Both white-noise densities.
    pub white: f64,
    /// The in-run bias σ (both sensors).
    pub bias: f64,
    /// The scale-factor σ (both sensors).
    pub scale: f64,
}

impl Default for NoiseMultipliers {
    fn default() -> Self {
        NoiseMultipliers {
            white: 1.0,
            bias: 1.0,
            scale: 1.0,
        }
    }
}

/// `[align]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AlignSection {
    /// Speed above which the GNSS course gives the heading, m/s.
    pub min_speed_m_s: f64,
    /// Largest heading σ accepted from the GNSS course, deg.
    pub max_heading_sigma_deg: f64,
    /// Baseline of the fixes whose chord gives the course, s.
    pub baseline_s: f64,
    /// Given initial yaw, deg.
    pub initial_yaw_deg: Option<f64>,
    /// Given initial roll, pitch, yaw, deg.
    pub initial_attitude_deg: Option<[f64; 3]>,
    /// Static start used for the gyro biases and levelling, s.
    pub static_s: f64,
}

impl Default for AlignSection {
    fn default() -> Self {
        let s =
            crate::nav::session::SessionConfig::new(crate::nav::filter::model::FilterConfig::new(
                crate::nav::session::consumer_mems_noise(),
                [0.0; 3],
            ));
        AlignSection {
            min_speed_m_s: s.min_speed_m_s,
            max_heading_sigma_deg: s.max_heading_sigma_rad.to_degrees(),
            baseline_s: s.align_baseline_s,
            initial_yaw_deg: None,
            initial_attitude_deg: None,
            static_s: 10.0,
        }
    }
}

/// `[aids]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AidsSection {
    /// Standstill detection with ZUPT / ZARU.
    pub zupt: bool,
    /// ZUPT σ, m/s.
    pub zupt_sigma_m_s: f64,
    /// ZARU σ, deg/s.
    pub zaru_sigma_deg_s: f64,
    /// Detector window, s.
    pub standstill_window_s: f64,
    /// Static time before a standstill, s.
    pub standstill_min_s: f64,
    /// Largest specific-force σ at rest, m/s².
    pub standstill_accel_std_m_s2: f64,
    /// Largest rate σ at rest, deg/s.
    pub standstill_gyro_std_deg_s: f64,
    /// No standstill above this speed, m/s.
    pub standstill_max_speed_m_s: f64,
    /// Non-holonomic constraint.
    pub nhc: bool,
    /// NHC σ, m/s.
    pub nhc_sigma_m_s: f64,
    /// NHC minimum speed, m/s.
    pub nhc_min_speed_m_s: f64,
    /// NHC maximum yaw rate, deg/s.
    pub nhc_max_yaw_rate_deg_s: f64,
}

impl Default for AidsSection {
    fn default() -> Self {
        let s = StandstillConfig::default();
        let n = NhcConfig::default();
        AidsSection {
            zupt: false,
            zupt_sigma_m_s: s.zupt_sigma_m_s.unwrap_or(0.01),
            zaru_sigma_deg_s: s.zaru_sigma_rad_s.unwrap_or(0.0).to_degrees(),
            standstill_window_s: s.window_s,
            standstill_min_s: s.min_duration_s,
            standstill_accel_std_m_s2: s.accel_std_max_m_s2,
            standstill_gyro_std_deg_s: s.gyro_std_max_rad_s.to_degrees(),
            standstill_max_speed_m_s: s.max_speed_m_s.unwrap_or(3.0),
            nhc: false,
            nhc_sigma_m_s: n.sigma_m_s[0],
            nhc_min_speed_m_s: n.min_speed_m_s,
            nhc_max_yaw_rate_deg_s: n.max_yaw_rate_rad_s.to_degrees(),
        }
    }
}

/// `[filter]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterSection {
    /// `off`, `chi2:P` or `robust`.
    pub gate: String,
    /// Also run the smoother.
    pub smooth: bool,
}

impl Default for FilterSection {
    fn default() -> Self {
        FilterSection {
            gate: "robust".into(),
            smooth: false,
        }
    }
}

/// `[outages]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutageSection {
    /// Outage specification ([`crate::nav::outage::OutageSpec`]).
    pub spec: String,
    /// Left out of the fit after the start, s.
    pub converge_s: f64,
    /// Left out of the fit after each outage, s.
    pub reconverge_s: f64,
}

impl Default for OutageSection {
    fn default() -> Self {
        OutageSection {
            spec: "none".into(),
            converge_s: 60.0,
            reconverge_s: 30.0,
        }
    }
}

/// A value that is wrong, by its key (located by [`NavConfig::load`]).
#[derive(Clone, Debug, PartialEq)]
pub struct KeyError {
    /// Dotted path of the key.
    pub key: String,
    /// What is wrong and what to change.
    pub message: String,
}

fn key_err(key: &str, message: impl Into<String>) -> KeyError {
    KeyError {
        key: key.to_owned(),
        message: message.into(),
    }
}

/// A configuration that could not be read, located.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{location}: {message}")]
pub struct ConfigError {
    /// `FILE:LINE:COL (key)`, `flag --x VALUE`, or the file alone.
    pub location: String,
    /// What is wrong and what to change.
    pub message: String,
}

/// A flag given on the command line: the key it sets and its text.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// The key ([`KEYS`]).
    pub key: &'static Key,
    /// The flag's text (`"true"` for a bare boolean flag).
    pub value: String,
}

/// A configuration read by [`NavConfig::load`], with where its values came from.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedConfig {
    /// The values.
    pub config: NavConfig,
    /// Folder that relative paths of the file resolve against (the file's folder); flags'
    /// paths resolve against the working directory.
    pub base_dir: PathBuf,
    /// Keys set by flags (their paths resolve against the working directory).
    pub from_flags: BTreeSet<&'static str>,
    /// The configuration file, if any.
    pub file: Option<PathBuf>,
    source_text: Option<String>,
}

/// Largest configuration file read, bytes: a configuration is a page of text.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

#[cfg(test)]
mod tests;

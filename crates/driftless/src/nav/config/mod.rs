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
pub mod quantity;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use keys::{KEYS, Key, ValueKind, key_by_path};
use quantity::{Kind, parse_quantity};

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

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

fn flag_value(k: &Key, text: &str) -> Result<toml::Value, String> {
    let num = |s: &str| -> Result<f64, String> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("{s:?} is not a number"))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{s:?} is not finite"))
        }
    };
    Ok(match k.kind {
        ValueKind::Float => toml::Value::Float(num(text)?),
        ValueKind::FloatOrAuto => match text.trim() {
            "auto" => toml::Value::String("auto".into()),
            t => toml::Value::Float(num(t).map_err(|e| format!("{e} (or `auto`)"))?),
        },
        ValueKind::Bool => match text.trim() {
            "true" | "yes" | "on" | "1" => toml::Value::Boolean(true),
            "false" | "no" | "off" | "0" => toml::Value::Boolean(false),
            other => return Err(format!("{other:?} is not true or false")),
        },
        ValueKind::Text => toml::Value::String(text.to_owned()),
        ValueKind::Vec3 => {
            let parts: Vec<&str> = text.split(',').collect();
            if parts.len() != 3 {
                return Err(format!(
                    "{text:?}: expected three comma-separated numbers ({})",
                    k.value_name
                ));
            }
            toml::Value::Array(
                parts
                    .iter()
                    .map(|p| num(p).map(toml::Value::Float))
                    .collect::<Result<_, _>>()?,
            )
        }
        ValueKind::List => toml::Value::Array(
            text.split(',')
                .map(|s| toml::Value::String(s.trim().to_owned()))
                .collect(),
        ),
        ValueKind::Table => {
            let mut t = toml::Table::new();
            for pair in text.split(',') {
                let (name, v) = pair
                    .split_once('=')
                    .ok_or_else(|| format!("{pair:?}: expected NAME=NUMBER"))?;
                t.insert(name.trim().to_owned(), toml::Value::Float(num(v)?));
            }
            toml::Value::Table(t)
        }
    })
}

fn merge(into: &mut toml::Table, from: toml::Table) {
    for (k, v) in from {
        match (into.get_mut(&k), v) {
            (Some(toml::Value::Table(a)), toml::Value::Table(b)) => merge(a, b),
            (_, v) => {
                into.insert(k, v);
            }
        }
    }
}

impl LoadedConfig {
    /// Where key `path` was set, for messages.
    pub fn locate(&self, path: &str) -> String {
        if self.from_flags.contains(path) {
            let flag = key_by_path(path).map_or(path, |k| k.flag);
            return format!("flag --{flag}");
        }
        let Some(file) = &self.file else {
            return format!("key `{path}` (default)");
        };
        let name = file.display();
        if let Some(text) = &self.source_text
            && let Ok(doc) = text.parse::<toml_edit::ImDocument<String>>()
        {
            let mut item: Option<&toml_edit::Item> = None;
            for (i, part) in path.split('.').enumerate() {
                item = if i == 0 {
                    doc.get(part)
                } else {
                    item.and_then(|it| it.get(part))
                };
            }
            if let Some(span) = item.and_then(|it| it.span()) {
                let (l, c) = line_col(text, span.start);
                return format!("{name}:{l}:{c} (key `{path}`)");
            }
        }
        format!("{name} (key `{path}`, default)")
    }

    /// A [`KeyError`] located.
    pub fn error(&self, e: KeyError) -> ConfigError {
        ConfigError {
            location: self.locate(&e.key),
            message: e.message,
        }
    }

    /// A path value of key `path`: `${DRIFTLESS_DATA}` expanded, then resolved against the
    /// configuration's folder (file values) or the working directory (flags).
    pub fn path(&self, key_path: &str, p: &Path) -> PathBuf {
        let base = if self.from_flags.contains(key_path) {
            Path::new("")
        } else {
            self.base_dir.as_path()
        };
        crate::io::resolve_data_path(p, base)
    }
}

impl NavConfig {
    /// Reads `file` (if any), applies `overrides` on top, checks every value
    /// ([`NavConfig::validate`]). Errors name the file, line and column or the flag.
    pub fn load(file: Option<&Path>, overrides: &[Override]) -> Result<LoadedConfig, ConfigError> {
        let source = match file {
            Some(f) => {
                let text = crate::io::nav::read_text_capped(f, MAX_CONFIG_BYTES).map_err(|e| {
                    ConfigError {
                        location: f.display().to_string(),
                        message: e,
                    }
                })?;
                let base_dir = f.parent().map(Path::to_path_buf).unwrap_or_default();
                Some((text, f.to_path_buf(), base_dir))
            }
            None => None,
        };
        NavConfig::load_text(source, overrides)
    }

    /// [`NavConfig::load`] of a configuration text: (text, name for messages, folder its
    /// relative paths resolve against).
    pub fn load_text(
        source: Option<(String, PathBuf, PathBuf)>,
        overrides: &[Override],
    ) -> Result<LoadedConfig, ConfigError> {
        let mut table = toml::Table::new();
        let mut source_text = None;
        let mut base_dir = PathBuf::new();
        let mut file = None;
        if let Some((text, path, dir)) = source {
            let name = path.display().to_string();
            // Types and unknown keys, with the file's own positions.
            if let Err(e) = toml::from_str::<NavConfig>(&text) {
                let location = match e.span() {
                    Some(s) => {
                        let (l, c) = line_col(&text, s.start);
                        format!("{name}:{l}:{c}")
                    }
                    None => name.clone(),
                };
                return Err(ConfigError {
                    location,
                    message: format!(
                        "{} (`driftless nav --print-config` lists every key with its type)",
                        e.message().trim()
                    ),
                });
            }
            table = toml::from_str(&text).map_err(|e| ConfigError {
                location: name.clone(),
                message: e.message().to_owned(),
            })?;
            source_text = Some(text);
            base_dir = dir;
            file = Some(path);
        }
        let mut from_flags = BTreeSet::new();
        for o in overrides {
            let value = flag_value(o.key, &o.value).map_err(|m| ConfigError {
                location: format!("flag --{} {}", o.key.flag, o.value),
                message: m,
            })?;
            let (section, name) = o.key.path.split_once('.').unwrap_or(("", o.key.path));
            let mut inner = toml::Table::new();
            inner.insert(name.to_owned(), value);
            let mut outer = toml::Table::new();
            outer.insert(section.to_owned(), toml::Value::Table(inner));
            // Each flag's value must fit its key on its own.
            if let Err(e) = NavConfig::deserialize(toml::Value::Table(outer.clone())) {
                return Err(ConfigError {
                    location: format!("flag --{} {}", o.key.flag, o.value),
                    message: e.to_string(),
                });
            }
            merge(&mut table, outer);
            from_flags.insert(o.key.path);
        }
        let config =
            NavConfig::deserialize(toml::Value::Table(table)).map_err(|e| ConfigError {
                location: file
                    .as_ref()
                    .map_or("flags".into(), |f| f.display().to_string()),
                message: e.to_string(),
            })?;
        let loaded = LoadedConfig {
            config,
            base_dir,
            from_flags,
            file,
            source_text,
        };
        loaded.config.validate().map_err(|e| loaded.error(e))?;
        Ok(loaded)
    }

    /// Checks every value: ranges, names, units. The first problem, by key.
    pub fn validate(&self) -> Result<(), KeyError> {
        let i = &self.imu;
        if !["auto", "kfgins", "tagged-csv", "csv"].contains(&i.format.as_str()) {
            return Err(key_err(
                "imu.format",
                format!(
                    "{:?} is not a format: auto, kfgins, tagged-csv or csv",
                    i.format
                ),
            ));
        }
        if i.tag.is_some() && !["auto", "tagged-csv"].contains(&i.format.as_str()) {
            return Err(key_err(
                "imu.tag",
                format!(
                    "a time-tag file goes with the tagged-CSV reader, but imu.format = {:?}: drop the tag or set format tagged-csv (or auto)",
                    i.format
                ),
            ));
        }
        if !i.time_offset_s.is_finite() || i.time_offset_s.abs() > 86_400.0 {
            return Err(key_err(
                "imu.time_offset_s",
                format!(
                    "{} s: give the offset in seconds, |offset| ≤ 1 day",
                    i.time_offset_s
                ),
            ));
        }
        let base = self.time_base().map_err(|e| key_err("imu.time_base", e))?;
        if base == crate::io::nav::TimeBase::GpsWeekAndSeconds && i.week_column.is_none() {
            return Err(key_err(
                "imu.time_base",
                "gps-week-sow needs the week column: set imu.week_column (--imu-week-column)",
            ));
        }
        if let Some(r) = i.rate_hz
            && !(r.is_finite() && r > 0.0 && r <= 100_000.0)
        {
            return Err(key_err(
                "imu.rate_hz",
                format!("{r} Hz: a rate is > 0 (or leave it out to take it from the time stamps)"),
            ));
        }
        for (k, v) in [
            ("imu.mounting_rpy_deg", i.mounting_rpy_deg),
            ("imu.misalignment_rpy_deg", i.misalignment_rpy_deg),
        ] {
            check_angles(k, v)?;
        }
        if !["error", "bridge"].contains(&i.gaps.as_str()) {
            return Err(key_err(
                "imu.gaps",
                format!("{:?}: error or bridge", i.gaps),
            ));
        }
        for (k, v, unit) in [
            ("imu.max_gyro_deg_s", i.max_gyro_deg_s, "deg/s"),
            ("imu.max_accel_g", i.max_accel_g, "g"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(key_err(k, format!("{v} {unit}: a limit is > 0")));
            }
        }
        let g = &self.gnss;
        if !g
            .lever_arm_m
            .iter()
            .all(|v| v.is_finite() && v.abs() <= 100.0)
        {
            return Err(key_err(
                "gnss.lever_arm_m",
                format!(
                    "{:?} m: three lengths in metres, each within ±100 m",
                    g.lever_arm_m
                ),
            ));
        }
        if let FloorSetting::Metres(m) = g.sigma_floor_m {
            nonneg("gnss.sigma_floor_m", m, 1000.0, "m")?;
        }
        if let Some(v) = g.sigma_floor_vertical_m {
            nonneg("gnss.sigma_floor_vertical_m", v, 1000.0, "m")?;
        }
        for (name, k) in QUALITY_NAMES.iter().zip(g.sigma_scale.as_array()) {
            if !(k.is_finite() && k > 0.0 && k <= 1e6) {
                return Err(key_err(
                    "gnss.sigma_scale",
                    format!("{name} = {k}: a σ multiplier is > 0"),
                ));
            }
        }
        if g.accept.is_empty() {
            return Err(key_err(
                "gnss.accept",
                format!(
                    "no quality accepted: list some of {}",
                    QUALITY_NAMES.join(", ")
                ),
            ));
        }
        for q in &g.accept {
            if !QUALITY_NAMES.contains(&q.as_str()) {
                return Err(key_err(
                    "gnss.accept",
                    format!(
                        "{q:?} is not a solution quality: {}",
                        QUALITY_NAMES.join(", ")
                    ),
                ));
            }
        }
        self.noise_settings(None)?;
        let a = &self.align;
        nonneg("align.min_speed_m_s", a.min_speed_m_s, 1000.0, "m/s")?;
        nonneg("align.static_s", a.static_s, 3600.0, "s")?;
        positive(
            "align.max_heading_sigma_deg",
            a.max_heading_sigma_deg,
            180.0,
            "deg",
        )?;
        positive("align.baseline_s", a.baseline_s, 600.0, "s")?;
        if let Some(y) = a.initial_yaw_deg {
            check_angles("align.initial_yaw_deg", [0.0, 0.0, y])?;
        }
        if let Some(att) = a.initial_attitude_deg {
            check_angles("align.initial_attitude_deg", att)?;
            if att[1].abs() > 90.0 {
                return Err(key_err(
                    "align.initial_attitude_deg",
                    format!("pitch {}°: within ±90°", att[1]),
                ));
            }
        }
        if a.initial_yaw_deg.is_some() && a.initial_attitude_deg.is_some() {
            return Err(key_err(
                "align.initial_yaw_deg",
                "give either initial_yaw_deg or initial_attitude_deg, not both",
            ));
        }
        let x = &self.aids;
        for (k, v, max, unit) in [
            ("aids.zupt_sigma_m_s", x.zupt_sigma_m_s, 10.0, "m/s"),
            ("aids.zaru_sigma_deg_s", x.zaru_sigma_deg_s, 100.0, "deg/s"),
            ("aids.standstill_window_s", x.standstill_window_s, 60.0, "s"),
            (
                "aids.standstill_accel_std_m_s2",
                x.standstill_accel_std_m_s2,
                100.0,
                "m/s²",
            ),
            (
                "aids.standstill_gyro_std_deg_s",
                x.standstill_gyro_std_deg_s,
                1000.0,
                "deg/s",
            ),
            ("aids.nhc_sigma_m_s", x.nhc_sigma_m_s, 100.0, "m/s"),
            (
                "aids.nhc_max_yaw_rate_deg_s",
                x.nhc_max_yaw_rate_deg_s,
                10_000.0,
                "deg/s",
            ),
        ] {
            positive(k, v, max, unit)?;
        }
        nonneg("aids.standstill_min_s", x.standstill_min_s, 3600.0, "s")?;
        nonneg(
            "aids.standstill_max_speed_m_s",
            x.standstill_max_speed_m_s,
            1000.0,
            "m/s",
        )?;
        nonneg("aids.nhc_min_speed_m_s", x.nhc_min_speed_m_s, 1000.0, "m/s")?;
        self.gate()?;
        let o = &self.outages;
        o.spec
            .parse::<crate::nav::outage::OutageSpec>()
            .map_err(|e| key_err("outages.spec", e.to_string()))?;
        nonneg("outages.converge_s", o.converge_s, 1e7, "s")?;
        nonneg("outages.reconverge_s", o.reconverge_s, 1e7, "s")?;
        Ok(())
    }

    /// The IMU time base.
    pub fn time_base(&self) -> Result<crate::io::nav::TimeBase, String> {
        self.imu
            .time_base
            .parse()
            .map_err(|e: crate::io::nav::ParseTimeBaseError| e.to_string())
    }

    /// The IMU stream options: time offset, time base, mounting, gap policy, nominal
    /// interval.
    pub fn stream_options(&self) -> ImuStreamOptions {
        let i = &self.imu;
        ImuStreamOptions {
            time_base: self.time_base().unwrap_or_default(),
            time_shift_s: i.time_offset_s,
            mounting: Mounting {
                rpy_deg: i.mounting_rpy_deg,
                misalignment_rpy_deg: i.misalignment_rpy_deg,
            },
            gap_policy: if i.gaps == "bridge" {
                ImuGapPolicy::Bridge
            } else {
                ImuGapPolicy::Error
            },
            nominal_dt_s: i.rate_hz.map(|r| 1.0 / r),
            ..ImuStreamOptions::default()
        }
    }

    /// The IMU value checks ([`crate::nav::imu_check`]) with the configured hard limits.
    pub fn imu_check_config(&self) -> crate::nav::imu_check::ImuCheckConfig {
        crate::nav::imu_check::ImuCheckConfig {
            max_gyro_rad_s: self.imu.max_gyro_deg_s.to_radians(),
            max_accel_m_s2: self.imu.max_accel_g * driftless_model::units::STANDARD_GRAVITY,
            ..Default::default()
        }
    }

    /// The quality flags accepted (index = RTKLIB flag).
    pub fn accepted_qualities(&self) -> [bool; 7] {
        let mut ok = [false; 7];
        for (k, name) in QUALITY_NAMES.iter().enumerate() {
            ok[k] = self.gnss.accept.iter().any(|a| a == name);
        }
        ok
    }

    /// σ multipliers per quality flag.
    pub fn quality_scale(&self) -> QualityScale {
        QualityScale(self.gnss.sigma_scale.as_array())
    }

    /// (horizontal, vertical) fixed σ floor, m; `None` when both are zero. With `auto`
    /// the horizontal part is 0 and the vertical one is `sigma_floor_vertical_m` if given.
    pub fn sigma_floor_m(&self) -> Option<(f64, f64)> {
        let (h, v) = match self.gnss.sigma_floor_m {
            FloorSetting::Auto => (0.0, self.gnss.sigma_floor_vertical_m.unwrap_or(0.0)),
            FloorSetting::Metres(h) => (h, self.gnss.sigma_floor_vertical_m.unwrap_or(2.0 * h)),
        };
        (h > 0.0 || v > 0.0).then_some((h, v))
    }

    /// True when the σ floor is estimated from the data (`gnss.sigma_floor_m = "auto"`).
    pub fn auto_sigma_floor(&self) -> bool {
        self.gnss.sigma_floor_m == FloorSetting::Auto
    }

    /// The innovation gate ([`Gate`]: `off`, `chi2:P`, `robust` or
    /// `robust:P_INFLATE:P_REJECT:MAX_SIGMA_SCALE`).
    pub fn gate(&self) -> Result<Gate, KeyError> {
        self.filter.gate.trim().parse::<Gate>().map_err(|_| {
            key_err(
                "filter.gate",
                format!(
                    "{:?} is not a gate: expected one of {}",
                    self.filter.gate,
                    crate::nav::filter::model::GATE_CHOICES
                ),
            )
        })
    }

    /// The filter's noise model and the initial σ of its 12 sensor states, from the
    /// `[noise]` values over `model` (the noise-model file, when given) over the built-in
    /// consumer-MEMS values ([`NoiseSection`]).
    ///
    /// In-run bias: a Gauss–Markov σ when given; else σ² = B² + K²T/2 from the bias
    /// instability B and random walk K (as [`ImuNoise::from_noise_model`]); else the
    /// model's; else the built-in. Multipliers scale the white densities, the in-run bias
    /// σ and the scale-factor σ.
    pub fn noise_settings(
        &self,
        model: Option<&crate::allan::noise_model::NoiseModel>,
    ) -> Result<(ImuNoise, [f64; 12]), KeyError> {
        let n = &self.noise;
        let q = |key: &str, v: &Option<String>, kind: Kind| -> Result<Option<f64>, KeyError> {
            v.as_deref()
                .map(|s| parse_quantity(s, kind).map_err(|e| key_err(key, e.to_string())))
                .transpose()
        };
        positive("noise.bias_tau_s", n.bias_tau_s, 1e9, "s")?;
        positive("noise.scale_tau_s", n.scale_tau_s, 1e9, "s")?;
        for (k, v) in [
            ("white", n.multiplier.white),
            ("bias", n.multiplier.bias),
            ("scale", n.multiplier.scale),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= 1e4) {
                return Err(key_err(
                    "noise.multiplier",
                    format!("{k} = {v}: a multiplier is > 0 (1 = as given)"),
                ));
            }
        }
        let base = match model {
            Some(m) => {
                let dummy = GaussMarkov {
                    sigma: 1.0,
                    tau_s: n.scale_tau_s,
                };
                ImuNoise::from_noise_model(m, n.bias_tau_s, dummy, dummy)
                    .map_err(|e| key_err("noise.model", e.to_string()))?
            }
            None => crate::nav::session::consumer_mems_noise(),
        };
        let mut out = base;
        if let Some(v) = q("noise.gyro_white", &n.gyro_white, Kind::AngleRandomWalk)? {
            out.gyro_arw_rad_sqrt_s = v;
        }
        if let Some(v) = q(
            "noise.accel_white",
            &n.accel_white,
            Kind::VelocityRandomWalk,
        )? {
            out.accel_vrw_m_s_sqrt_s = v;
        }
        let t = n.bias_tau_s;
        let bias = |sigma_key: &str,
                    sigma: &Option<String>,
                    b_key: &str,
                    b: &Option<String>,
                    k_key: &str,
                    k: &Option<String>,
                    kinds: (Kind, Kind),
                    base: GaussMarkov|
         -> Result<GaussMarkov, KeyError> {
            if let Some(s) = q(sigma_key, sigma, kinds.0)? {
                return Ok(GaussMarkov { sigma: s, tau_s: t });
            }
            let bi = q(b_key, b, kinds.0)?;
            let rw = q(k_key, k, kinds.1)?;
            if bi.is_none() && rw.is_none() {
                return Ok(GaussMarkov {
                    sigma: base.sigma,
                    tau_s: if model.is_some() { base.tau_s } else { t },
                });
            }
            let (b, k) = (bi.unwrap_or(0.0), rw.unwrap_or(0.0));
            Ok(GaussMarkov {
                sigma: (b * b + k * k * t / 2.0).sqrt(),
                tau_s: t,
            })
        };
        out.gyro_bias = bias(
            "noise.gyro_bias_sigma",
            &n.gyro_bias_sigma,
            "noise.gyro_bias_instability",
            &n.gyro_bias_instability,
            "noise.gyro_bias_random_walk",
            &n.gyro_bias_random_walk,
            (Kind::AngularRate, Kind::RateRandomWalk),
            base.gyro_bias,
        )?;
        out.accel_bias = bias(
            "noise.accel_bias_sigma",
            &n.accel_bias_sigma,
            "noise.accel_bias_instability",
            &n.accel_bias_instability,
            "noise.accel_bias_random_walk",
            &n.accel_bias_random_walk,
            (Kind::SpecificForce, Kind::AccelRandomWalk),
            base.accel_bias,
        )?;
        let req = |key: &str, v: &str, kind: Kind| {
            parse_quantity(v, kind).map_err(|e| key_err(key, e.to_string()))
        };
        let sg = req("noise.gyro_scale_sigma", &n.gyro_scale_sigma, Kind::Scale)?;
        let sa = req("noise.accel_scale_sigma", &n.accel_scale_sigma, Kind::Scale)?;
        let m = n.multiplier;
        out.gyro_arw_rad_sqrt_s *= m.white;
        out.accel_vrw_m_s_sqrt_s *= m.white;
        out.gyro_bias.sigma *= m.bias;
        out.accel_bias.sigma *= m.bias;
        out.gyro_scale = GaussMarkov {
            sigma: sg * m.scale,
            tau_s: n.scale_tau_s,
        };
        out.accel_scale = GaussMarkov {
            sigma: sa * m.scale,
            tau_s: n.scale_tau_s,
        };
        for (key, v, kind) in [
            ("noise.gyro_scale_sigma", out.gyro_scale.sigma, "scale"),
            ("noise.accel_scale_sigma", out.accel_scale.sigma, "scale"),
            ("noise.gyro_bias_sigma", out.gyro_bias.sigma, "bias"),
            ("noise.accel_bias_sigma", out.accel_bias.sigma, "bias"),
        ] {
            if v <= 0.0 {
                return Err(key_err(
                    key,
                    format!(
                        "the {kind} σ is zero: give a value > 0 (the filter needs some uncertainty)"
                    ),
                ));
            }
        }
        if out.gyro_arw_rad_sqrt_s <= 0.0 || out.accel_vrw_m_s_sqrt_s <= 0.0 {
            return Err(key_err("noise.gyro_white", "white noise must be > 0"));
        }
        let bg0 = req(
            "noise.gyro_bias_initial",
            &n.gyro_bias_initial,
            Kind::AngularRate,
        )?;
        let ba0 = req(
            "noise.accel_bias_initial",
            &n.accel_bias_initial,
            Kind::SpecificForce,
        )?;
        // Plausibility: the usual unit mix-ups show as absurd magnitudes.
        let deg_s = |v: f64| v.to_degrees();
        if out.gyro_arw_rad_sqrt_s > 0.01 {
            return Err(key_err(
                "noise.gyro_white",
                format!(
                    "{:.0} deg/sqrt(h) is implausible for a gyro: check the unit (deg/sqrt(h) vs deg/s/sqrt(Hz))",
                    deg_s(out.gyro_arw_rad_sqrt_s) * 60.0
                ),
            ));
        }
        if bg0 > 0.2 || out.gyro_bias.sigma > 0.2 {
            return Err(key_err(
                "noise.gyro_bias_initial",
                format!(
                    "gyro bias σ {:.1} deg/s is implausible: check the unit (deg/h vs deg/s)",
                    deg_s(bg0.max(out.gyro_bias.sigma))
                ),
            ));
        }
        if ba0 > 20.0 || out.accel_bias.sigma > 20.0 {
            return Err(key_err(
                "noise.accel_bias_initial",
                "accelerometer bias σ above 2 g is implausible: check the unit (mg vs m/s^2)",
            ));
        }
        let mut s0 = [0.0; 12];
        for k in 0..3 {
            s0[k] = bg0.max(out.gyro_bias.sigma);
            s0[3 + k] = ba0.max(out.accel_bias.sigma);
            s0[6 + k] = out.gyro_scale.sigma;
            s0[9 + k] = out.accel_scale.sigma;
        }
        if s0.iter().any(|v| *v <= 0.0) {
            return Err(key_err(
                "noise.gyro_bias_initial",
                "initial bias σ must be > 0",
            ));
        }
        Ok((out, s0))
    }

    /// The commented default configuration (`driftless nav --print-config`): every key
    /// with its help, defaults as values, optional keys commented out with an example.
    pub fn default_toml() -> String {
        let defaults = toml::Value::try_from(NavConfig::default())
            .unwrap_or(toml::Value::Table(toml::Table::new()));
        let mut out = String::from(
            "# driftless navigation configuration (`driftless nav --config FILE`).\n\
             # Every key is also a flag (shown after the help); flags override this file.\n\
             # Relative paths resolve against this file's folder; ${DRIFTLESS_DATA} expands.\n",
        );
        let mut section = "";
        for k in KEYS {
            let (sec, name) = k.path.split_once('.').unwrap_or(("", k.path));
            if sec != section {
                out.push_str(&format!("\n[{sec}]\n"));
                section = sec;
            }
            out.push_str(&format!("# {} (--{})\n", k.help, k.flag));
            match defaults.get(sec).and_then(|s| s.get(name)) {
                Some(v) => out.push_str(&format!("{name} = {}\n", render(v))),
                None => out.push_str(&format!("# {name} = {}\n", k.example)),
            }
        }
        out
    }
}

fn render(v: &toml::Value) -> String {
    match v {
        toml::Value::Table(t) => {
            let inner: Vec<String> = t
                .iter()
                .map(|(k, v)| format!("{k} = {}", render(v)))
                .collect();
            format!("{{ {} }}", inner.join(", "))
        }
        toml::Value::Array(a) => {
            let inner: Vec<String> = a.iter().map(render).collect();
            format!("[{}]", inner.join(", "))
        }
        toml::Value::Float(f) => {
            let s = format!("{f:?}");
            if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
                s
            } else {
                format!("{s}.0")
            }
        }
        other => other.to_string(),
    }
}

fn check_angles(key: &str, v: [f64; 3]) -> Result<(), KeyError> {
    if v.iter().all(|a| a.is_finite() && a.abs() <= 360.0) {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!(
                "{v:?}: angles in degrees, each within ±360° (were radians or another unit meant?)"
            ),
        ))
    }
}

fn nonneg(key: &str, v: f64, max: f64, unit: &str) -> Result<(), KeyError> {
    if v.is_finite() && (0.0..=max).contains(&v) {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!("{v} {unit}: must be ≥ 0 and ≤ {max} {unit}"),
        ))
    }
}

fn positive(key: &str, v: f64, max: f64, unit: &str) -> Result<(), KeyError> {
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!("{v} {unit}: must be > 0 and ≤ {max} {unit}"),
        ))
    }
}

#[cfg(test)]
mod tests;

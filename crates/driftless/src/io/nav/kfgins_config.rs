//! KF-GINS YAML configuration (`kf-gins.yaml`, i2Nav-WHU/KF-GINS, GPL-3.0; fields and units
//! learnt from its `dataset/kf-gins.yaml` and `loadConfig` in `src/kf_gins.cpp`, no code
//! taken).
//!
//! [`KfGinsConfigRaw`] holds the values exactly as KF-GINS documents them (deg, deg/h,
//! mGal, ppm, deg/√h, m/s/√h, h) and writes them back ([`KfGinsConfigRaw::to_yaml`]);
//! [`KfGinsConfig`] is the same configuration in SI, converted at this edge with KF-GINS's
//! own factors (ARW × π/180/60 → rad/√s, VRW / 60 → m/s/√s, deg/h × π/180/3600 → rad/s,
//! mGal × 1e-5 → m/s², ppm × 1e-6, h × 3600 → s).
//!
//! | key | KF-GINS unit | required |
//! |---|---|---|
//! | `imupath`, `gnsspath`, `outputpath` | path | yes |
//! | `imudatalen` (int ≥ 7), `imudatarate` (int, Hz) | – | yes |
//! | `starttime`, `endtime` (< 0: to the end of the IMU file) | GPS s of week | yes |
//! | `initpos` | \[deg, deg, m\] | yes |
//! | `initvel` | \[m/s\] NED | yes |
//! | `initatt` roll, pitch, yaw | \[deg\] | yes |
//! | `initgyrbias`, `initaccbias`, `initgyrscale`, `initaccscale` | deg/h, mGal, ppm, ppm | yes |
//! | `initposstd`, `initvelstd`, `initattstd` | m, m/s, deg | yes |
//! | `initbgstd`, `initbastd`, `initsgstd`, `initsastd` | deg/h, mGal, ppm, ppm | no: default to `imunoise`'s `gbstd`, `abstd`, `gsstd`, `asstd` |
//! | `imunoise`: `arw`, `vrw`, `gbstd`, `abstd`, `gsstd`, `asstd` | deg/√h, m/s/√h, deg/h, mGal, ppm, ppm | yes |
//! | `imunoise`: `corrtime` | h | yes |
//! | `antlever` | \[m\] IMU frame forward-right-down | yes |
//!
//! **Paths.** KF-GINS opens `imupath` and `gnsspath` as written and its outputs as
//! `outputpath + "/KF_GINS_*"`, so relative paths are relative to the **process working
//! directory**, not to the YAML file (its demo, `./bin/KF-GINS ./dataset/kf-gins.yaml`,
//! names `./dataset/...` from the repository root). The paths are kept as written; resolve
//! them with [`KfGinsConfig::resolve`] against the directory KF-GINS would run in.
//!
//! **Checks beyond KF-GINS** (which ignores unknown keys and reads the first 3 elements of
//! any list): every list must have exactly 3 numbers; integers must be integers; numbers
//! may be written quoted (yaml-cpp converts them); latitude in \[-90, 90\]; standard
//! deviations and noise ≥ 0; `corrtime` > 0 and ≤ 1000 h (a larger value is almost surely
//! seconds); `imunoise.arw` ≤ 100 deg/√h and `vrw` ≤ 100 m/s/√h (larger ones are almost
//! surely deg/h or m/s/h); roll/pitch within ±180/±90 deg (values written in radians pass,
//! but nothing larger). Each failure is one error naming the file, line and column of the
//! value. Unknown top-level keys are kept in [`KfGinsConfig::unknown_keys`] for the caller
//! to log.
//!
//! **YAML crate.** `saphyr` (MIT/Apache-2.0, pure Rust, YAML 1.2, maintained successor of
//! `yaml-rust`): its `MarkedYaml` keeps every node's line and column, which gives the
//! file:line:col errors this project requires; `serde_yaml_ng`/`serde_norway` wrap the C
//! libyaml port (unsafe, larger) and report positions only for syntax errors; a hand parser
//! would have to match yaml-cpp on configs we have not seen. Default features are off (no
//! `encoding_rs`).

use std::path::{Path, PathBuf};

use saphyr::{MarkedYaml, Scalar, YamlData};

use crate::io::yaml::mapping_get;

use crate::io::{Location, LogError};

const D2R: f64 = std::f64::consts::PI / 180.0;

/// IMU noise parameters in KF-GINS's units (`imunoise:` block).
#[derive(Clone, Debug, PartialEq)]
pub struct ImuNoiseRaw {
    /// Angle random walk, deg/√h.
    pub arw: [f64; 3],
    /// Velocity random walk, m/s/√h.
    pub vrw: [f64; 3],
    /// Gyro bias instability (Gauss-Markov σ), deg/h.
    pub gbstd: [f64; 3],
    /// Accelerometer bias instability, mGal.
    pub abstd: [f64; 3],
    /// Gyro scale-factor instability, ppm.
    pub gsstd: [f64; 3],
    /// Accelerometer scale-factor instability, ppm.
    pub asstd: [f64; 3],
    /// Gauss-Markov correlation time, h.
    pub corrtime: f64,
}

/// A KF-GINS configuration with the values exactly as written, in KF-GINS's units (see the
/// module table).
#[derive(Clone, Debug, PartialEq)]
pub struct KfGinsConfigRaw {
    /// IMU file path, as written.
    pub imupath: String,
    /// GNSS file path, as written.
    pub gnsspath: String,
    /// Output directory, as written.
    pub outputpath: String,
    /// Columns of the IMU file.
    pub imudatalen: i64,
    /// IMU rate, Hz.
    pub imudatarate: i64,
    /// Start of processing, GPS s of week.
    pub starttime: f64,
    /// End of processing, GPS s of week; < 0 means the end of the IMU file.
    pub endtime: f64,
    /// Initial latitude, longitude \[deg\], height \[m\].
    pub initpos: [f64; 3],
    /// Initial velocity north, east, down, m/s.
    pub initvel: [f64; 3],
    /// Initial roll, pitch, yaw, deg.
    pub initatt: [f64; 3],
    /// Initial gyro bias, deg/h.
    pub initgyrbias: [f64; 3],
    /// Initial accelerometer bias, mGal.
    pub initaccbias: [f64; 3],
    /// Initial gyro scale factor, ppm.
    pub initgyrscale: [f64; 3],
    /// Initial accelerometer scale factor, ppm.
    pub initaccscale: [f64; 3],
    /// Initial position σ north, east, down, m.
    pub initposstd: [f64; 3],
    /// Initial velocity σ, m/s.
    pub initvelstd: [f64; 3],
    /// Initial attitude σ roll, pitch, yaw, deg.
    pub initattstd: [f64; 3],
    /// Initial gyro bias σ, deg/h (default: `imunoise.gbstd`).
    pub initbgstd: Option<[f64; 3]>,
    /// Initial accelerometer bias σ, mGal (default: `imunoise.abstd`).
    pub initbastd: Option<[f64; 3]>,
    /// Initial gyro scale σ, ppm (default: `imunoise.gsstd`).
    pub initsgstd: Option<[f64; 3]>,
    /// Initial accelerometer scale σ, ppm (default: `imunoise.asstd`).
    pub initsastd: Option<[f64; 3]>,
    /// IMU noise block.
    pub imunoise: ImuNoiseRaw,
    /// GNSS antenna lever arm in the IMU frame (forward, right, down), m.
    pub antlever: [f64; 3],
}

/// IMU noise parameters in SI.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuNoise {
    /// Angle random walk, rad/√s.
    pub arw_rad_sqrt_s: [f64; 3],
    /// Velocity random walk, m/s/√s.
    pub vrw_m_s_sqrt_s: [f64; 3],
    /// Gyro bias Gauss-Markov σ, rad/s.
    pub gyro_bias_std_rad_s: [f64; 3],
    /// Accelerometer bias Gauss-Markov σ, m/s².
    pub accel_bias_std_m_s2: [f64; 3],
    /// Gyro scale-factor Gauss-Markov σ, dimensionless.
    pub gyro_scale_std: [f64; 3],
    /// Accelerometer scale-factor Gauss-Markov σ, dimensionless.
    pub accel_scale_std: [f64; 3],
    /// Gauss-Markov correlation time, s.
    pub corr_time_s: f64,
}

/// A KF-GINS configuration in SI units (see the module docs for the conversions).
#[derive(Clone, Debug, PartialEq)]
pub struct KfGinsConfig {
    /// IMU file, as written (relative to the process working directory in KF-GINS).
    pub imu_path: PathBuf,
    /// GNSS file, as written.
    pub gnss_path: PathBuf,
    /// Output directory, as written.
    pub output_dir: PathBuf,
    /// Columns of the IMU file (≥ 7).
    pub imu_columns: usize,
    /// IMU rate, Hz (> 0).
    pub imu_rate_hz: f64,
    /// Start of processing, GPS s of week.
    pub start_time_s: f64,
    /// End of processing, GPS s of week; `None`: the end of the IMU file.
    pub end_time_s: Option<f64>,
    /// Initial latitude, rad.
    pub init_lat_rad: f64,
    /// Initial longitude, rad.
    pub init_lon_rad: f64,
    /// Initial ellipsoidal height, m.
    pub init_height_m: f64,
    /// Initial velocity NED, m/s.
    pub init_vel_ned_m_s: [f64; 3],
    /// Initial roll, pitch, yaw, rad.
    pub init_roll_pitch_yaw_rad: [f64; 3],
    /// Initial gyro bias, rad/s.
    pub init_gyro_bias_rad_s: [f64; 3],
    /// Initial accelerometer bias, m/s².
    pub init_accel_bias_m_s2: [f64; 3],
    /// Initial gyro scale factor, dimensionless.
    pub init_gyro_scale: [f64; 3],
    /// Initial accelerometer scale factor, dimensionless.
    pub init_accel_scale: [f64; 3],
    /// Initial position σ NED, m.
    pub init_pos_std_ned_m: [f64; 3],
    /// Initial velocity σ NED, m/s.
    pub init_vel_std_ned_m_s: [f64; 3],
    /// Initial attitude σ roll, pitch, yaw, rad.
    pub init_att_std_rad: [f64; 3],
    /// Initial gyro bias σ, rad/s (defaulted from the noise block when absent).
    pub init_gyro_bias_std_rad_s: [f64; 3],
    /// Initial accelerometer bias σ, m/s².
    pub init_accel_bias_std_m_s2: [f64; 3],
    /// Initial gyro scale σ, dimensionless.
    pub init_gyro_scale_std: [f64; 3],
    /// Initial accelerometer scale σ, dimensionless.
    pub init_accel_scale_std: [f64; 3],
    /// IMU noise, SI.
    pub imu_noise: ImuNoise,
    /// Antenna lever arm in the IMU frame (forward, right, down), m.
    pub antenna_lever_frd_m: [f64; 3],
    /// Top-level keys KF-GINS does not read (KF-GINS ignores them; callers may log them).
    pub unknown_keys: Vec<String>,
    /// The configuration as written, in KF-GINS units.
    pub raw: KfGinsConfigRaw,
}

const KNOWN_KEYS: [&str; 25] = [
    "imupath",
    "gnsspath",
    "outputpath",
    "imudatalen",
    "imudatarate",
    "starttime",
    "endtime",
    "initpos",
    "initvel",
    "initatt",
    "initgyrbias",
    "initaccbias",
    "initgyrscale",
    "initaccscale",
    "initposstd",
    "initvelstd",
    "initattstd",
    "initbgstd",
    "initbastd",
    "initsgstd",
    "initsastd",
    "imunoise",
    "antlever",
    // Not read by KF-GINS's main program but present in some i2Nav configs; accepted
    // silently so they are not reported as typos.
    "odolever",
    "installangle",
];

/// Error helpers bound to one input name.
struct Ctx<'a> {
    name: &'a str,
}

impl Ctx<'_> {
    fn at(&self, n: &MarkedYaml<'_>) -> Location {
        Location::field(self.name, n.span.start.line(), n.span.start.col() + 1)
    }
    fn invalid(&self, at: Location, message: String) -> LogError {
        LogError::InvalidValue { at, message }
    }
    fn malformed(&self, at: Location, message: String) -> LogError {
        LogError::Malformed {
            at,
            format: "KF-GINS YAML config",
            message,
        }
    }
}

fn describe(n: &MarkedYaml<'_>) -> String {
    match &n.data {
        YamlData::Value(Scalar::String(s)) => format!("the string {s:?}"),
        YamlData::Value(Scalar::Integer(i)) => format!("the integer {i}"),
        YamlData::Value(Scalar::FloatingPoint(f)) => format!("the number {}", f.0),
        YamlData::Value(Scalar::Boolean(b)) => format!("the boolean {b}"),
        YamlData::Value(Scalar::Null) => "nothing (null)".into(),
        YamlData::Sequence(s) => format!("a list of {} items", s.len()),
        YamlData::Mapping(_) => "a mapping".into(),
        _ => "an unsupported YAML node".into(),
    }
}

/// A required key's value, or an error naming the mapping that lacks it.
fn req<'a, 'i>(
    cx: &Ctx<'_>,
    m: &'a saphyr::AnnotatedMapping<'i, MarkedYaml<'i>>,
    key: &str,
    at: &Location,
) -> Result<&'a MarkedYaml<'i>, LogError> {
    mapping_get(m, key)
        .map(|(_, v)| v)
        .ok_or_else(|| cx.malformed(at.clone(), format!("missing required key `{key}`")))
}

/// The top-level mapping of a configuration, for reading and checking its keys.
struct TopLevel<'a, 'i> {
    cx: &'a Ctx<'a>,
    map: &'a saphyr::AnnotatedMapping<'i, MarkedYaml<'i>>,
    /// Location of the mapping (reported for missing keys).
    at: Location,
}

impl<'a, 'i> TopLevel<'a, 'i> {
    /// A required key's value.
    fn req(&self, key: &str) -> Result<&'a MarkedYaml<'i>, LogError> {
        req(self.cx, self.map, key, &self.at)
    }

    /// A required path: a non-empty string, or a number taken as its text.
    fn path(&self, key: &str) -> Result<String, LogError> {
        let cx = self.cx;
        let v = self.req(key)?;
        match &v.data {
            YamlData::Value(Scalar::String(s)) if !s.is_empty() => Ok(s.to_string()),
            YamlData::Value(Scalar::Integer(i)) => Ok(i.to_string()),
            YamlData::Value(Scalar::FloatingPoint(f)) => Ok(f.0.to_string()),
            _ => Err(cx.invalid(
                cx.at(v),
                format!("`{key}` must be a path, found {}", describe(v)),
            )),
        }
    }

    /// A required integer (or a string holding one) and its location.
    fn int(&self, key: &str) -> Result<(i64, Location), LogError> {
        let cx = self.cx;
        let v = self.req(key)?;
        let i = match &v.data {
            YamlData::Value(Scalar::Integer(i)) => Some(*i),
            YamlData::Value(Scalar::String(s)) => s.trim().parse::<i64>().ok(),
            _ => None,
        };
        match i {
            Some(i) => Ok((i, cx.at(v))),
            None => Err(cx.invalid(
                cx.at(v),
                format!("`{key}` must be an integer, found {}", describe(v)),
            )),
        }
    }

    /// A required list of 3 numbers and its location.
    fn v3(&self, key: &str) -> Result<([f64; 3], Location), LogError> {
        vec3(self.cx, self.req(key)?, key)
    }

    /// A required list of 3 standard deviations (each ≥ 0).
    fn std3(&self, key: &str) -> Result<[f64; 3], LogError> {
        let v = self.req(key)?;
        let (a, _) = vec3(self.cx, v, key)?;
        check_nonneg(self.cx, v, key, &a)?;
        Ok(a)
    }

    /// An optional list of 3 standard deviations (each ≥ 0).
    fn std3_opt(&self, key: &str) -> Result<Option<[f64; 3]>, LogError> {
        match mapping_get(self.map, key) {
            None => Ok(None),
            Some((_, v)) => {
                let (a, _) = vec3(self.cx, v, key)?;
                check_nonneg(self.cx, v, key, &a)?;
                Ok(Some(a))
            }
        }
    }

    /// `imudatalen` (≥ 7), `imudatarate` (> 0 Hz), `starttime` (GPS seconds of week)
    /// and `endtime` (< 0, or in [starttime, 604800]).
    fn imu_timing(&self) -> Result<(i64, i64, f64, f64), LogError> {
        let cx = self.cx;
        let (imudatalen, n) = self.int("imudatalen")?;
        if imudatalen < 7 {
            return Err(cx.invalid(
                n,
                format!("`imudatalen` must be ≥ 7 (time + 6 increments), found {imudatalen}"),
            ));
        }
        let (imudatarate, n) = self.int("imudatarate")?;
        if imudatarate <= 0 {
            return Err(cx.invalid(
                n,
                format!("`imudatarate` must be > 0 Hz, found {imudatarate}"),
            ));
        }
        let (starttime, n) = number(cx, self.req("starttime")?, "starttime")?;
        if !(0.0..=604_800.0).contains(&starttime) {
            return Err(cx.invalid(
                n,
                format!(
                    "`starttime` must be GPS seconds of week in [0, 604800], found {starttime}"
                ),
            ));
        }
        let (endtime, n) = number(cx, self.req("endtime")?, "endtime")?;
        if endtime >= 0.0 && !(starttime..=604_800.0).contains(&endtime) {
            return Err(cx.invalid(
                n,
                format!(
                    "`endtime` must be < 0 (to the end) or in [starttime, 604800], found {endtime}"
                ),
            ));
        }
        Ok((imudatalen, imudatarate, starttime, endtime))
    }

    /// `initpos`: latitude in [-90, 90] deg, longitude in [-360, 360] deg, height m.
    fn initpos(&self) -> Result<[f64; 3], LogError> {
        let (initpos, n) = self.v3("initpos")?;
        if !(-90.0..=90.0).contains(&initpos[0]) || !(-360.0..=360.0).contains(&initpos[1]) {
            return Err(self.cx.invalid(
                n,
                format!(
                    "`initpos` must be [latitude deg in [-90, 90], longitude deg, height m], found [{}, {}, {}]",
                    initpos[0], initpos[1], initpos[2]
                ),
            ));
        }
        Ok(initpos)
    }

    /// `initatt`: roll, pitch, yaw in deg with |roll| ≤ 180, |pitch| ≤ 90, |yaw| ≤ 360.
    fn initatt(&self) -> Result<[f64; 3], LogError> {
        let (initatt, n) = self.v3("initatt")?;
        if initatt[0].abs() > 180.0 || initatt[1].abs() > 90.0 || initatt[2].abs() > 360.0 {
            return Err(self.cx.invalid(
                n,
                format!(
                    "`initatt` must be [roll, pitch, yaw] in deg (|roll| ≤ 180, |pitch| ≤ 90, |yaw| ≤ 360), found [{}, {}, {}]",
                    initatt[0], initatt[1], initatt[2]
                ),
            ));
        }
        Ok(initatt)
    }
}

/// Parses a KF-GINS configuration file.
impl KfGinsConfig {
    /// Reads and converts a KF-GINS YAML configuration file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<KfGinsConfig, LogError> {
        let (name, text) = crate::io::yaml::read_named(path.as_ref())?;
        KfGinsConfig::from_yaml_str(&text, &name)
    }

    /// Parses and converts KF-GINS YAML text; `name` is used in error messages.
    pub fn from_yaml_str(text: &str, name: &str) -> Result<KfGinsConfig, LogError> {
        let (raw, unknown_keys) = KfGinsConfigRaw::from_yaml_str(text, name)?;
        let mut cfg = KfGinsConfig::from_raw(raw);
        cfg.unknown_keys = unknown_keys;
        Ok(cfg)
    }

    /// Converts a raw (KF-GINS-unit) configuration to SI with KF-GINS's factors. The raw
    /// values are assumed checked (as [`KfGinsConfigRaw::from_yaml_str`] does).
    pub(crate) fn from_raw(raw: KfGinsConfigRaw) -> KfGinsConfig {
        let d2r3 = |v: [f64; 3]| v.map(|x| x * D2R);
        let dph = |v: [f64; 3]| v.map(|x| x * D2R / 3600.0);
        let mgal = |v: [f64; 3]| v.map(|x| x * 1e-5);
        let ppm = |v: [f64; 3]| v.map(|x| x * 1e-6);
        let n = &raw.imunoise;
        let imu_noise = ImuNoise {
            arw_rad_sqrt_s: n.arw.map(|x| x * D2R / 60.0),
            vrw_m_s_sqrt_s: n.vrw.map(|x| x / 60.0),
            gyro_bias_std_rad_s: dph(n.gbstd),
            accel_bias_std_m_s2: mgal(n.abstd),
            gyro_scale_std: ppm(n.gsstd),
            accel_scale_std: ppm(n.asstd),
            corr_time_s: n.corrtime * 3600.0,
        };
        KfGinsConfig {
            imu_path: PathBuf::from(&raw.imupath),
            gnss_path: PathBuf::from(&raw.gnsspath),
            output_dir: PathBuf::from(&raw.outputpath),
            imu_columns: usize::try_from(raw.imudatalen).unwrap_or(0),
            imu_rate_hz: raw.imudatarate as f64,
            start_time_s: raw.starttime,
            end_time_s: (raw.endtime >= 0.0).then_some(raw.endtime),
            init_lat_rad: raw.initpos[0] * D2R,
            init_lon_rad: raw.initpos[1] * D2R,
            init_height_m: raw.initpos[2],
            init_vel_ned_m_s: raw.initvel,
            init_roll_pitch_yaw_rad: d2r3(raw.initatt),
            init_gyro_bias_rad_s: dph(raw.initgyrbias),
            init_accel_bias_m_s2: mgal(raw.initaccbias),
            init_gyro_scale: ppm(raw.initgyrscale),
            init_accel_scale: ppm(raw.initaccscale),
            init_pos_std_ned_m: raw.initposstd,
            init_vel_std_ned_m_s: raw.initvelstd,
            init_att_std_rad: d2r3(raw.initattstd),
            init_gyro_bias_std_rad_s: dph(raw.initbgstd.unwrap_or(n.gbstd)),
            init_accel_bias_std_m_s2: mgal(raw.initbastd.unwrap_or(n.abstd)),
            init_gyro_scale_std: ppm(raw.initsgstd.unwrap_or(n.gsstd)),
            init_accel_scale_std: ppm(raw.initsastd.unwrap_or(n.asstd)),
            imu_noise,
            antenna_lever_frd_m: raw.antlever,
            unknown_keys: Vec::new(),
            raw,
        }
    }

    /// `path` resolved as KF-GINS would when run from `working_dir` (absolute paths stay).
    pub fn resolve(path: &Path, working_dir: &Path) -> PathBuf {
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            working_dir.join(path)
        }
    }
}

impl KfGinsConfigRaw {
    /// Parses KF-GINS YAML text and checks it (see the module docs); returns the raw
    /// configuration and the unknown top-level keys.
    pub fn from_yaml_str(
        text: &str,
        name: &str,
    ) -> Result<(KfGinsConfigRaw, Vec<String>), LogError> {
        let cx = Ctx { name };
        let root = &crate::io::yaml::load_root(text, name, "KF-GINS YAML config")?;
        let YamlData::Mapping(map) = &root.data else {
            return Err(cx.malformed(
                cx.at(root),
                format!("expected a mapping of keys, found {}", describe(root)),
            ));
        };
        let unknown = unknown_keys(&cx, map)?;
        let top = TopLevel {
            cx: &cx,
            map,
            at: cx.at(root),
        };
        let imupath = top.path("imupath")?;
        let gnsspath = top.path("gnsspath")?;
        let outputpath = top.path("outputpath")?;
        let (imudatalen, imudatarate, starttime, endtime) = top.imu_timing()?;
        let initpos = top.initpos()?;
        let (initvel, _) = top.v3("initvel")?;
        let initatt = top.initatt()?;
        let (initgyrbias, _) = top.v3("initgyrbias")?;
        let (initaccbias, _) = top.v3("initaccbias")?;
        let (initgyrscale, _) = top.v3("initgyrscale")?;
        let (initaccscale, _) = top.v3("initaccscale")?;
        let initposstd = top.std3("initposstd")?;
        let initvelstd = top.std3("initvelstd")?;
        let initattstd = top.std3("initattstd")?;
        let initbgstd = top.std3_opt("initbgstd")?;
        let initbastd = top.std3_opt("initbastd")?;
        let initsgstd = top.std3_opt("initsgstd")?;
        let initsastd = top.std3_opt("initsastd")?;

        let imunoise = imu_noise(&cx, map, &top.at)?;
        let (antlever, _) = top.v3("antlever")?;
        Ok((
            KfGinsConfigRaw {
                imupath,
                gnsspath,
                outputpath,
                imudatalen,
                imudatarate,
                starttime,
                endtime,
                initpos,
                initvel,
                initatt,
                initgyrbias,
                initaccbias,
                initgyrscale,
                initaccscale,
                initposstd,
                initvelstd,
                initattstd,
                initbgstd,
                initbastd,
                initsgstd,
                initsastd,
                imunoise,
                antlever,
            },
            unknown,
        ))
    }

    /// Writes the configuration back as KF-GINS YAML (same keys and units; values printed
    /// in Rust's shortest round-trip form, so reading it back gives the same numbers).
    pub fn to_yaml(&self) -> String {
        let v = |a: &[f64; 3]| format!("[ {}, {}, {} ]", a[0], a[1], a[2]);
        let q = |s: &str| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""));
        let mut s = String::new();
        s.push_str("# KF-GINS configuration (written by driftless)\n");
        s.push_str(&format!("imupath: {}\n", q(&self.imupath)));
        s.push_str(&format!("gnsspath: {}\n", q(&self.gnsspath)));
        s.push_str(&format!("outputpath: {}\n", q(&self.outputpath)));
        s.push_str(&format!("imudatalen: {}\n", self.imudatalen));
        s.push_str(&format!("imudatarate: {}    # [Hz]\n", self.imudatarate));
        s.push_str(&format!(
            "starttime: {}    # [s of GPS week]\n",
            self.starttime
        ));
        s.push_str(&format!(
            "endtime: {}    # -1: to the end of the IMU file\n",
            self.endtime
        ));
        s.push_str(&format!(
            "initpos: {}    # [deg, deg, m]\n",
            v(&self.initpos)
        ));
        s.push_str(&format!("initvel: {}    # [m/s] NED\n", v(&self.initvel)));
        s.push_str(&format!(
            "initatt: {}    # roll, pitch, yaw [deg]\n",
            v(&self.initatt)
        ));
        s.push_str(&format!(
            "initgyrbias: {}    # [deg/h]\n",
            v(&self.initgyrbias)
        ));
        s.push_str(&format!(
            "initaccbias: {}    # [mGal]\n",
            v(&self.initaccbias)
        ));
        s.push_str(&format!(
            "initgyrscale: {}    # [ppm]\n",
            v(&self.initgyrscale)
        ));
        s.push_str(&format!(
            "initaccscale: {}    # [ppm]\n",
            v(&self.initaccscale)
        ));
        s.push_str(&format!("initposstd: {}    # [m]\n", v(&self.initposstd)));
        s.push_str(&format!("initvelstd: {}    # [m/s]\n", v(&self.initvelstd)));
        s.push_str(&format!("initattstd: {}    # [deg]\n", v(&self.initattstd)));
        for (key, val, unit) in [
            ("initbgstd", &self.initbgstd, "deg/h"),
            ("initbastd", &self.initbastd, "mGal"),
            ("initsgstd", &self.initsgstd, "ppm"),
            ("initsastd", &self.initsastd, "ppm"),
        ] {
            if let Some(a) = val {
                s.push_str(&format!("{key}: {}    # [{unit}]\n", v(a)));
            }
        }
        let n = &self.imunoise;
        s.push_str("imunoise:\n");
        s.push_str(&format!("  arw: {}    # [deg/sqrt(hr)]\n", v(&n.arw)));
        s.push_str(&format!("  vrw: {}    # [m/s/sqrt(hr)]\n", v(&n.vrw)));
        s.push_str(&format!("  gbstd: {}    # [deg/hr]\n", v(&n.gbstd)));
        s.push_str(&format!("  abstd: {}    # [mGal]\n", v(&n.abstd)));
        s.push_str(&format!("  gsstd: {}    # [ppm]\n", v(&n.gsstd)));
        s.push_str(&format!("  asstd: {}    # [ppm]\n", v(&n.asstd)));
        s.push_str(&format!("  corrtime: {}    # [hr]\n", n.corrtime));
        s.push_str(&format!(
            "antlever: {}    # [m] forward, right, down\n",
            v(&self.antlever)
        ));
        s
    }
}

/// The top-level keys that KF-GINS does not know (kept for a note); a key that is not a
/// name is an error.
fn unknown_keys(
    cx: &Ctx<'_>,
    map: &saphyr::AnnotatedMapping<'_, MarkedYaml<'_>>,
) -> Result<Vec<String>, LogError> {
    let mut unknown = Vec::new();
    for (k, _) in map.iter() {
        match &k.data {
            YamlData::Value(Scalar::String(s)) => {
                if !KNOWN_KEYS.contains(&s.as_ref()) {
                    unknown.push(s.to_string());
                }
            }
            _ => {
                return Err(cx.malformed(
                    cx.at(k),
                    format!("expected a key name, found {}", describe(k)),
                ));
            }
        }
    }
    Ok(unknown)
}

/// The `imunoise` mapping: noise densities, bias and scale-factor σ, correlation time;
/// values in the wrong units (deg/h for ARW, seconds for the correlation time) refused.
fn imu_noise(
    cx: &Ctx<'_>,
    map: &saphyr::AnnotatedMapping<'_, MarkedYaml<'_>>,
    root_at: &Location,
) -> Result<ImuNoiseRaw, LogError> {
    let req = |m, key: &str, at: &Location| req(cx, m, key, at);
    let noise = req(map, "imunoise", root_at)?;
    let YamlData::Mapping(nmap) = &noise.data else {
        return Err(cx.invalid(
            cx.at(noise),
            format!(
                "`imunoise` must be a mapping (arw, vrw, …), found {}",
                describe(noise)
            ),
        ));
    };
    let noise_at = cx.at(noise);
    let nstd = |key: &str| -> Result<([f64; 3], Location), LogError> {
        let v = req(nmap, key, &noise_at)?;
        let (a, at) = vec3(cx, v, &format!("imunoise.{key}"))?;
        check_nonneg(cx, v, &format!("imunoise.{key}"), &a)?;
        Ok((a, at))
    };
    let (arw, n) = nstd("arw")?;
    if arw.iter().any(|&x| x > 100.0) {
        return Err(cx.invalid(
            n,
            format!(
                "`imunoise.arw` {arw:?} deg/√h is implausibly large; KF-GINS expects deg/sqrt(h) (deg/h or deg/s values do not fit)"
            ),
        ));
    }
    let (vrw, n) = nstd("vrw")?;
    if vrw.iter().any(|&x| x > 100.0) {
        return Err(cx.invalid(
            n,
            format!(
                "`imunoise.vrw` {vrw:?} m/s/√h is implausibly large; KF-GINS expects m/s/sqrt(h)"
            ),
        ));
    }
    let (gbstd, _) = nstd("gbstd")?;
    let (abstd, _) = nstd("abstd")?;
    let (gsstd, _) = nstd("gsstd")?;
    let (asstd, _) = nstd("asstd")?;
    let ct = req(nmap, "corrtime", &noise_at)?;
    let (corrtime, n) = number(cx, ct, "imunoise.corrtime")?;
    if !(corrtime > 0.0 && corrtime <= 1000.0) {
        return Err(cx.invalid(
            n,
            format!(
                "`imunoise.corrtime` must be in (0, 1000] hours, found {corrtime}{}",
                if corrtime > 1000.0 {
                    " (KF-GINS expects hours; this looks like seconds)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(ImuNoiseRaw {
        arw,
        vrw,
        gbstd,
        abstd,
        gsstd,
        asstd,
        corrtime,
    })
}

/// A finite number from a scalar node (integers, floats, and quoted numbers as yaml-cpp
/// accepts them).
fn number(cx: &Ctx<'_>, v: &MarkedYaml<'_>, key: &str) -> Result<(f64, Location), LogError> {
    match crate::io::yaml::scalar_number(v) {
        Some(x) if x.is_finite() => Ok((x, cx.at(v))),
        _ => Err(cx.invalid(
            cx.at(v),
            format!("`{key}` must be a finite number, found {}", describe(v)),
        )),
    }
}

/// A list of exactly three finite numbers.
fn vec3(cx: &Ctx<'_>, v: &MarkedYaml<'_>, key: &str) -> Result<([f64; 3], Location), LogError> {
    let YamlData::Sequence(items) = &v.data else {
        return Err(cx.invalid(
            cx.at(v),
            format!("`{key}` must be a list of 3 numbers, found {}", describe(v)),
        ));
    };
    if items.len() != 3 {
        return Err(cx.invalid(
            cx.at(v),
            format!(
                "`{key}` must be a list of 3 numbers, found {} items",
                items.len()
            ),
        ));
    }
    let mut out = [0.0; 3];
    for (o, item) in out.iter_mut().zip(items) {
        *o = number(cx, item, key)?.0;
    }
    Ok((out, cx.at(v)))
}

fn check_nonneg(cx: &Ctx<'_>, v: &MarkedYaml<'_>, key: &str, a: &[f64; 3]) -> Result<(), LogError> {
    if a.iter().any(|&x| x < 0.0) {
        return Err(cx.invalid(
            cx.at(v),
            format!(
                "`{key}` is a standard deviation or noise density and must be ≥ 0, found {a:?}"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small configuration in KF-GINS's layout (own values, not KF-GINS's demo file).
    const CFG: &str = r#"# test configuration
imupath: "./data/imu.txt"
gnsspath: ./data/gnss.txt
outputpath: "./out"
imudatalen: 7
imudatarate: 200
starttime: 100000
endtime: -1
initpos: [ 45.0, -120.5, 150.25 ]
initvel: [ 1.0, -2.0, 0.5 ]
initatt: [ 1.5, -2.5, 270.0 ]
initgyrbias: [ 3600, 0, -36 ]    # [deg/h]
initaccbias: [ 100, 0, 0 ]    # [mGal]
initgyrscale: [ 1000, 0, 0 ]   # [ppm]
initaccscale: [ 0, 500, 0 ]   # [ppm]
initposstd: [ 1.0, 2.0, 3.0 ]
initvelstd:
  - 0.1
  - 0.2
  - 0.3
initattstd: [ 0.5, 0.5, 2.0 ]
initbastd: [ 50, 50, 50 ]
imunoise:
  arw: [0.6, 0.6, "0.6"]
  vrw: [0.3, 0.3, 0.3]
  gbstd: [36.0, 36.0, 36.0]
  abstd: [200.0, 200.0, 200.0]
  gsstd: [1000.0, 1000.0, 1000.0]
  asstd: [1000.0, 1000.0, 1000.0]
  corrtime: 0.5
antlever: [ 0.1, -0.2, -0.3 ]
odolever: [0, 0, 0]
mystery: 3
"#;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn parses_and_converts_to_si() {
        let c = KfGinsConfig::from_yaml_str(CFG, "kf.yaml").unwrap();
        assert_eq!(c.imu_path, PathBuf::from("./data/imu.txt"));
        assert_eq!(c.gnss_path, PathBuf::from("./data/gnss.txt"));
        assert_eq!(c.output_dir, PathBuf::from("./out"));
        assert_eq!((c.imu_columns, c.imu_rate_hz), (7, 200.0));
        assert_eq!((c.start_time_s, c.end_time_s), (100000.0, None));
        assert!(close(c.init_lat_rad, 45f64.to_radians()));
        assert!(close(c.init_lon_rad, (-120.5f64).to_radians()));
        assert_eq!(c.init_height_m, 150.25);
        assert_eq!(c.init_vel_ned_m_s, [1.0, -2.0, 0.5]);
        assert!(close(c.init_roll_pitch_yaw_rad[2], 270f64.to_radians()));
        // 3600 deg/h = 1 deg/s.
        assert!(close(c.init_gyro_bias_rad_s[0], 1f64.to_radians()));
        assert!(close(c.init_accel_bias_m_s2[0], 1e-3));
        assert!(close(c.init_gyro_scale[0], 1e-3));
        assert!(close(c.init_accel_scale[1], 5e-4));
        assert!(close(c.init_att_std_rad[2], 2f64.to_radians()));
        assert_eq!(c.init_vel_std_ned_m_s, [0.1, 0.2, 0.3]);
        // Defaults from the noise block where absent, the given value where present.
        assert!(close(c.init_gyro_bias_std_rad_s[1], 0.01f64.to_radians()));
        assert!(close(c.init_accel_bias_std_m_s2[2], 50e-5));
        assert!(close(c.init_gyro_scale_std[0], 1e-3));
        let n = &c.imu_noise;
        // 0.6 deg/√h = 0.01 deg/√s.
        assert!(close(n.arw_rad_sqrt_s[2], 0.01f64.to_radians()));
        assert!(close(n.vrw_m_s_sqrt_s[0], 0.005));
        assert!(close(n.gyro_bias_std_rad_s[0], 0.01f64.to_radians()));
        assert!(close(n.accel_bias_std_m_s2[0], 2e-3));
        assert!(close(n.accel_scale_std[0], 1e-3));
        assert_eq!(n.corr_time_s, 1800.0);
        assert_eq!(c.antenna_lever_frd_m, [0.1, -0.2, -0.3]);
        assert_eq!(c.unknown_keys, vec!["mystery".to_string()]);
        assert_eq!(c.raw.initgyrbias, [3600.0, 0.0, -36.0]);
        assert_eq!(
            KfGinsConfig::resolve(&c.imu_path, Path::new("/run")),
            PathBuf::from("/run/./data/imu.txt")
        );
    }

    #[test]
    fn writes_back_and_reads_the_same() {
        let c = KfGinsConfig::from_yaml_str(CFG, "kf.yaml").unwrap();
        let text = c.raw.to_yaml();
        let (back, unknown) = KfGinsConfigRaw::from_yaml_str(&text, "back.yaml").unwrap();
        assert_eq!(back, c.raw);
        assert!(unknown.is_empty());
    }

    fn err(text: &str) -> LogError {
        KfGinsConfig::from_yaml_str(text, "kf.yaml").unwrap_err()
    }

    #[test]
    fn bad_types_name_line_and_column() {
        // A string where a list is expected.
        let e = err(&CFG.replace("initvel: [ 1.0, -2.0, 0.5 ]", "initvel: fast"));
        assert_eq!(
            e.to_string(),
            "kf.yaml:10:10: `initvel` must be a list of 3 numbers, found the string \"fast\""
        );
        // Two elements.
        let e = err(&CFG.replace("antlever: [ 0.1, -0.2, -0.3 ]", "antlever: [ 0.1, -0.2 ]"));
        assert!(matches!(e, LogError::InvalidValue { .. }), "{e}");
        assert!(e.to_string().contains("found 2 items"), "{e}");
        assert_eq!(e.line(), Some(31));
        // A non-numeric element inside a list points at the element.
        let e = err(&CFG.replace("vrw: [0.3, 0.3, 0.3]", "vrw: [0.3, x, 0.3]"));
        assert_eq!(e.location().unwrap().line, Some(25));
        assert_eq!(e.location().unwrap().column, Some(14));
        // A float where KF-GINS reads an int.
        let e = err(&CFG.replace("imudatarate: 200", "imudatarate: 200.5"));
        assert!(
            e.to_string().contains("`imudatarate` must be an integer"),
            "{e}"
        );
        // A missing key names the mapping.
        let e = err(&CFG.replace("initattstd: [ 0.5, 0.5, 2.0 ]\n", ""));
        assert!(matches!(e, LogError::Malformed { .. }), "{e}");
        assert!(
            e.to_string().contains("missing required key `initattstd`"),
            "{e}"
        );
        let e = err(&CFG.replace("  corrtime: 0.5\n", ""));
        assert!(e.to_string().contains("`corrtime`"), "{e}");
        // Located at the `imunoise` block (its first entry).
        assert_eq!(e.line(), Some(24));
        // YAML syntax error.
        let e = err("imupath: [unclosed\n");
        assert!(matches!(e, LogError::Malformed { .. }), "{e}");
        assert!(e.line().is_some());
        // Not a mapping.
        assert!(matches!(err("- a\n- b\n"), LogError::Malformed { .. }));
        assert!(matches!(err(""), LogError::Empty { .. }));
    }

    #[test]
    fn wrong_units_and_ranges() {
        // corrtime in seconds.
        let e = err(&CFG.replace("corrtime: 0.5", "corrtime: 3600"));
        assert!(e.to_string().contains("looks like seconds"), "{e}");
        assert_eq!(e.line(), Some(30));
        // ARW in deg/h.
        let e = err(&CFG.replace("arw: [0.6, 0.6, \"0.6\"]", "arw: [360, 360, 360]"));
        assert!(e.to_string().contains("implausibly large"), "{e}");
        // Negative std.
        let e = err(&CFG.replace(
            "initposstd: [ 1.0, 2.0, 3.0 ]",
            "initposstd: [ 1.0, -2.0, 3.0 ]",
        ));
        assert!(e.to_string().contains("must be ≥ 0"), "{e}");
        // Latitude out of range.
        let e = err(&CFG.replace("initpos: [ 45.0,", "initpos: [ 145.0,"));
        assert_eq!(e.line(), Some(9));
        // Pitch beyond 90 deg.
        let e = err(&CFG.replace("initatt: [ 1.5, -2.5,", "initatt: [ 1.5, -92.5,"));
        assert!(e.to_string().contains("initatt"), "{e}");
        // endtime before starttime; imudatalen too small; NaN.
        assert!(
            err(&CFG.replace("endtime: -1", "endtime: 5"))
                .to_string()
                .contains("endtime")
        );
        assert!(
            err(&CFG.replace("imudatalen: 7", "imudatalen: 6"))
                .to_string()
                .contains("≥ 7")
        );
        assert!(
            err(&CFG.replace("initvel: [ 1.0,", "initvel: [ .nan,"))
                .to_string()
                .contains("finite number")
        );
    }
}

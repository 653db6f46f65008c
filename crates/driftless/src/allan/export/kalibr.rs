//! Kalibr IMU noise file reader: Kalibr's `imu.yaml` (top-level keys) or an OpenVINS /
//! Kalibr chain file (`imu0:` block, an OpenCV `%YAML:1.0` first line allowed). Values are
//! kept as written: continuous-time densities in SI (Kalibr wiki, "IMU Noise Model").
//!
//! | key | unit | required |
//! |---|---|---|
//! | `accelerometer_noise_density` | m/s²/√Hz | yes |
//! | `accelerometer_random_walk` | m/s³/√Hz | yes |
//! | `gyroscope_noise_density` | rad/s/√Hz | yes |
//! | `gyroscope_random_walk` | rad/s²/√Hz | yes |
//! | `update_rate` | Hz | yes |
//! | `rostopic` | – | no |
//!
//! Every value must be a finite number > 0; each failure names the file, line and column.

use std::path::Path;

use saphyr::{MarkedYaml, Scalar, YamlData};

use crate::io::yaml::{load_root, mapping_get, read_named, scalar_number};
use crate::io::{Location, LogError};

const FORMAT: &str = "Kalibr IMU YAML";

/// The noise values of a Kalibr IMU file, SI, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct KalibrImu {
    /// `accelerometer_noise_density`, m/s²/√Hz.
    pub accel_noise_density_m_s2_sqrt_hz: f64,
    /// `accelerometer_random_walk`, m/s³/√Hz.
    pub accel_random_walk_m_s3_sqrt_hz: f64,
    /// `gyroscope_noise_density`, rad/s/√Hz.
    pub gyro_noise_density_rad_s_sqrt_hz: f64,
    /// `gyroscope_random_walk`, rad/s²/√Hz.
    pub gyro_random_walk_rad_s2_sqrt_hz: f64,
    /// `update_rate`, Hz.
    pub update_rate_hz: f64,
    /// `rostopic`, if present.
    pub rostopic: Option<String>,
}

fn at(name: &str, n: &MarkedYaml<'_>) -> Location {
    Location::field(name, n.span.start.line(), n.span.start.col() + 1)
}

fn get<'a, 'i>(
    map: &'a saphyr::AnnotatedMapping<'i, MarkedYaml<'i>>,
    key: &str,
) -> Option<&'a MarkedYaml<'i>> {
    mapping_get(map, key).map(|(_, v)| v)
}

impl KalibrImu {
    /// Reads a Kalibr IMU file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<KalibrImu, LogError> {
        let (name, text) = read_named(path.as_ref())?;
        KalibrImu::from_yaml_str(&text, &name)
    }

    /// Parses Kalibr IMU YAML text; `name` is used in error messages.
    pub fn from_yaml_str(text: &str, name: &str) -> Result<KalibrImu, LogError> {
        let malformed = |at: Location, message: String| LogError::Malformed {
            at,
            format: FORMAT,
            message,
        };
        // OpenCV's FileStorage header is not a YAML directive: blank it, keeping lines.
        let text = match text.strip_prefix("%YAML:") {
            Some(rest) => format!("\n{}", rest.split_once('\n').map_or("", |(_, r)| r)),
            None => text.to_string(),
        };
        let root = &load_root(&text, name, FORMAT)?;
        let YamlData::Mapping(top) = &root.data else {
            return Err(malformed(
                at(name, root),
                "expected a mapping of keys (accelerometer_noise_density, …)".into(),
            ));
        };
        let (map, node) = match get(top, "imu0") {
            Some(n) => match &n.data {
                YamlData::Mapping(m) => (m, n),
                _ => {
                    return Err(malformed(
                        at(name, n),
                        "`imu0` must be a mapping of the IMU's keys".into(),
                    ));
                }
            },
            None => (top, root),
        };
        let number = |key: &str| -> Result<f64, LogError> {
            let v = get(map, key).ok_or_else(|| {
                malformed(at(name, node), format!("missing required key `{key}`"))
            })?;
            match scalar_number(v) {
                Some(x) if x.is_finite() && x > 0.0 => Ok(x),
                Some(x) => Err(LogError::InvalidValue {
                    at: at(name, v),
                    message: format!("`{key}` must be a finite number > 0, found {x}"),
                }),
                None => Err(LogError::InvalidValue {
                    at: at(name, v),
                    message: format!("`{key}` must be a number"),
                }),
            }
        };
        let rostopic = get(map, "rostopic").and_then(|v| match &v.data {
            YamlData::Value(Scalar::String(s)) => Some(s.to_string()),
            _ => None,
        });
        Ok(KalibrImu {
            accel_noise_density_m_s2_sqrt_hz: number("accelerometer_noise_density")?,
            accel_random_walk_m_s3_sqrt_hz: number("accelerometer_random_walk")?,
            gyro_noise_density_rad_s_sqrt_hz: number("gyroscope_noise_density")?,
            gyro_random_walk_rad_s2_sqrt_hz: number("gyroscope_random_walk")?,
            update_rate_hz: number("update_rate")?,
            rostopic,
        })
    }
}

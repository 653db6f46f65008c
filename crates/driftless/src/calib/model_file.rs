//! The calibration model file (TOML): `calibrated = matrix · (raw − bias)` per triad, in
//! SI (m/s², rad/s) with the raw unit named, each value with its standard deviation,
//! how it was obtained, and the static intervals used. Read by `compensate`, `nav` and
//! the thermal module; converts to the device model
//! [`driftless_model::calib::ImuCalibration`].
//!
//! ```toml
//! format_version = 1
//! method = "multi-position"
//! source = "xsens_acc.txt + xsens_gyro.txt"
//! gravity_m_s2 = 9.81744
//!
//! [accel]
//! raw_unit = "counts"
//! bias = [32768.1, 32802.4, 32910.0]            # raw units
//! bias_sigma = [0.3, 0.3, 0.4]
//! matrix = [[0.0024, 0.0, 0.0], [0.0, 0.0024, 0.0], [0.0, 0.0, 0.0024]]  # SI per raw unit
//! matrix_sigma = [[1e-7, 0.0, 0.0], [0.0, 1e-7, 0.0], [0.0, 0.0, 1e-7]]
//! residual_rms = 0.0011                          # SI
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::linalg::Mat3;

/// Current file format version.
pub const FORMAT_VERSION: u32 = 1;

/// One triad's calibration with uncertainties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriadEntry {
    /// Unit of the raw samples the bias is in (`counts`, `m/s^2`, `rad/s`, …).
    pub raw_unit: String,
    /// Bias b, raw units.
    pub bias: [f64; 3],
    /// 1σ of b, raw units.
    pub bias_sigma: [f64; 3],
    /// M: SI per raw unit (scale, misalignment).
    pub matrix: [[f64; 3]; 3],
    /// 1σ of each entry of M.
    pub matrix_sigma: [[f64; 3]; 3],
    /// RMS of the fit residuals, SI (m/s² or rad/s; for a gyro fitted on attitude, rad).
    #[serde(default)]
    pub residual_rms: Option<f64>,
}

impl TriadEntry {
    /// The device model.
    pub fn calibration(&self) -> TriadCalibration {
        TriadCalibration {
            bias: self.bias,
            matrix: Mat3(self.matrix),
        }
    }
}

/// A calibration model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// `six-position`, `multi-position`, …
    pub method: String,
    /// Input file(s).
    pub source: String,
    /// Gravity magnitude used, m/s².
    pub gravity_m_s2: f64,
    /// Accelerometer.
    pub accel: TriadEntry,
    /// Gyroscope.
    pub gyro: TriadEntry,
    /// Static intervals used, [start, end] s.
    #[serde(default)]
    pub static_intervals: Vec<[f64; 2]>,
    /// Gyro g-sensitivity G (raw gyro units per m/s² of specific force, raw = … + G·f),
    /// when estimated.
    #[serde(default)]
    pub gyro_g_sensitivity: Option<[[f64; 3]; 3]>,
}

/// Why a calibration file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// I/O.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// Syntax, unknown key or wrong type (the message names line and column).
    #[error("{path}: {message}")]
    Parse {
        /// File.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A value that cannot be a calibration.
    #[error("{path}: {message}")]
    Invalid {
        /// File.
        path: String,
        /// What is wrong.
        message: String,
    },
}

impl CalibrationFile {
    /// The device model of both triads.
    pub fn calibration(&self) -> ImuCalibration {
        ImuCalibration {
            accel: self.accel.calibration(),
            gyro: self.gyro.calibration(),
        }
    }

    /// Checks the version, finiteness, σ ≥ 0 and that each M is invertible.
    pub fn validate(&self, path: &str) -> Result<(), ModelFileError> {
        let bad = |message: String| {
            Err(ModelFileError::Invalid {
                path: path.to_owned(),
                message,
            })
        };
        if self.format_version != FORMAT_VERSION {
            return bad(format!(
                "format_version {} is not supported (this driftless reads {FORMAT_VERSION})",
                self.format_version
            ));
        }
        if !(self.gravity_m_s2.is_finite() && self.gravity_m_s2 > 0.0) {
            return bad(format!("gravity_m_s2 = {} must be > 0", self.gravity_m_s2));
        }
        for (name, t) in [("accel", &self.accel), ("gyro", &self.gyro)] {
            let vals = t
                .bias
                .iter()
                .chain(t.matrix.iter().flatten())
                .chain(t.bias_sigma.iter())
                .chain(t.matrix_sigma.iter().flatten());
            if vals.clone().any(|v| !v.is_finite()) {
                return bad(format!("[{name}]: every value must be finite"));
            }
            if t.bias_sigma
                .iter()
                .chain(t.matrix_sigma.iter().flatten())
                .any(|v| *v < 0.0)
            {
                return bad(format!("[{name}]: standard deviations must be ≥ 0"));
            }
            let det = Mat3(t.matrix).det();
            let size: f64 = t.matrix.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
            if det.abs() <= 1e-12 * size.powi(3) {
                return bad(format!("[{name}]: matrix is singular (det {det:e})"));
            }
        }
        Ok(())
    }

    /// Reads and validates a file.
    pub fn load(path: impl AsRef<Path>) -> Result<CalibrationFile, ModelFileError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text =
            crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|source| {
                ModelFileError::Io {
                    path: name.clone(),
                    source,
                }
            })?;
        CalibrationFile::from_toml_str(&text, &name)
    }

    /// Parses and validates a file's text; `name` (the file's path) leads every error.
    pub fn from_toml_str(text: &str, name: &str) -> Result<CalibrationFile, ModelFileError> {
        let f: CalibrationFile = toml::from_str(text).map_err(|e| ModelFileError::Parse {
            path: name.to_owned(),
            message: e.to_string(),
        })?;
        f.validate(name)?;
        Ok(f)
    }

    /// The file's text.
    pub fn to_toml_string(&self) -> Result<String, ModelFileError> {
        toml::to_string(self).map_err(|e| ModelFileError::Invalid {
            path: "<calibration>".into(),
            message: e.to_string(),
        })
    }

    /// Writes the file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), ModelFileError> {
        let path = path.as_ref();
        crate::io::output::write(path, self.to_toml_string()?).map_err(|source| {
            ModelFileError::Io {
                path: path.display().to_string(),
                source,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> CalibrationFile {
        let t = |unit: &str, b: f64, m: f64| TriadEntry {
            raw_unit: unit.into(),
            bias: [b, b + 1.0, b - 1.0],
            bias_sigma: [0.1; 3],
            matrix: [[m, 1e-6, 0.0], [0.0, m, 2e-6], [0.0, 0.0, m]],
            matrix_sigma: [[1e-7; 3]; 3],
            residual_rms: Some(1e-3),
        };
        CalibrationFile {
            format_version: FORMAT_VERSION,
            method: "multi-position".into(),
            source: "test".into(),
            gravity_m_s2: 9.81744,
            accel: t("counts", 32768.0, 2.4e-3),
            gyro: t("counts", 32768.0, 1.6e-4),
            static_intervals: vec![[0.0, 50.0], [55.0, 60.0]],
            gyro_g_sensitivity: None,
        }
    }

    #[test]
    fn round_trips_and_applies() {
        let f = sample();
        let text = f.to_toml_string().unwrap();
        let back: CalibrationFile = toml::from_str(&text).unwrap();
        assert_eq!(back, f);
        let c = back.calibration();
        let si = c.accel.apply([32768.0, 32769.0, 32767.0 + 1000.0]);
        assert!((si[2] - 2.4).abs() < 1e-12, "{si:?}");
    }

    #[test]
    fn bad_files_are_named() {
        let mut f = sample();
        f.gyro.matrix = [[0.0; 3]; 3];
        let e = f.validate("c.toml").unwrap_err().to_string();
        assert!(
            e.contains("c.toml") && e.contains("gyro") && e.contains("singular"),
            "{e}"
        );
        let mut f = sample();
        f.accel.bias_sigma[1] = -1.0;
        assert!(
            f.validate("c.toml")
                .unwrap_err()
                .to_string()
                .contains("≥ 0")
        );
        let text = sample()
            .to_toml_string()
            .unwrap()
            .replace("raw_unit", "raw_units");
        let e = toml::from_str::<CalibrationFile>(&text)
            .unwrap_err()
            .to_string();
        assert!(e.contains("raw_units"), "{e}");
    }
}

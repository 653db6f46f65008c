//! The thermal compensation model file (TOML): the room
//! calibration at T_ref and, per triad and axis, the bias and scale-factor deltas as
//! polynomial coefficients of ΔT = T − T_ref, with the valid temperature range and the
//! out-of-range policy; converts to and from
//! [`driftless_model::compensation::CompensationModel`] (whose doc states the equation).
//!
//! ```toml
//! format_version = 2
//! model_id = 7
//! t_ref_c = 25.0
//! range_c = [-25.0, 70.0]
//! out_of_range = "clamp"          # clamp | extrapolate | error
//! # optional: gyro g-sensitivity G, raw gyro units per m/s² (raw_ω = A·ω + b + G·f)
//! gyro_g_sensitivity = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 2e-4]]
//!
//! [accel]
//! raw_unit = "m/s^2"
//! bias = [0.1, -0.2, 0.05]        # b at T_ref, raw units
//! matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
//! bias_delta = [[0.0, 1e-3, 2e-6, -1e-7], …]   # per axis: c0 (= 0), c1 °C⁻¹, c2, c3 …
//! scale_delta = [[0.0, 2e-5, 0.0, 0.0], …]      # dimensionless per °C^k
//! ```
//!
//! Version 2 added `gyro_g_sensitivity`; version-1 files (without it) still read.

use std::path::Path;

use serde::{Deserialize, Serialize};

use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::compensation::{CompensationModel, OutOfRange, TriadThermal};
use driftless_model::linalg::Mat3;
use driftless_model::thermal::ThermalPoly;

/// Current format version (2: optional `gyro_g_sensitivity`).
pub const FORMAT_VERSION: u32 = 2;

/// Oldest format version still read (1: no g-sensitivity).
pub(crate) const OLDEST_FORMAT_VERSION: u32 = 1;

/// One triad of the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriadSection {
    /// Unit of the raw samples.
    pub raw_unit: String,
    /// b at T_ref, raw units.
    pub bias: [f64; 3],
    /// M at T_ref (SI per raw unit).
    pub matrix: [[f64; 3]; 3],
    /// Δb per axis: coefficients of ΔT⁰ … ΔT^p (c₀ = 0), raw units per °C^k.
    pub bias_delta: [Vec<f64>; 3],
    /// Δs per axis: coefficients of ΔT⁰ … ΔT^p (c₀ = 0), per °C^k.
    pub scale_delta: [Vec<f64>; 3],
}

/// The file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThermalModelFile {
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Identifies the model (recorded in the stamp of compensated output); < 2⁶³, as
    /// TOML integers are signed 64-bit.
    pub model_id: u64,
    /// T_ref, °C.
    pub t_ref_c: f64,
    /// Valid range [min, max], °C.
    pub range_c: [f64; 2],
    /// `clamp`, `extrapolate` or `error`.
    pub out_of_range: String,
    /// Gyro g-sensitivity G, raw gyro units per m/s² (raw_ω = A·ω + b + G·f), applied
    /// with the compensated specific force; absent: none compensated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_g_sensitivity: Option<[[f64; 3]; 3]>,
    /// Accelerometer.
    pub accel: TriadSection,
    /// Gyroscope.
    pub gyro: TriadSection,
}

/// Why a model file could not be read, written or converted.
#[derive(Debug, thiserror::Error)]
pub enum ThermalModelError {
    /// I/O.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// Syntax, unknown key, wrong type, or a value the model refuses.
    #[error("{path}: {message}")]
    Invalid {
        /// File.
        path: String,
        /// What is wrong.
        message: String,
    },
}

fn policy_name(p: OutOfRange) -> &'static str {
    match p {
        OutOfRange::Clamp => "clamp",
        OutOfRange::Extrapolate => "extrapolate",
        OutOfRange::Error => "error",
    }
}

impl ThermalModelFile {
    /// The file form of a model (`units`: raw unit of the accelerometer and gyro).
    pub fn from_model(m: &CompensationModel, units: [&str; 2]) -> ThermalModelFile {
        let t_ref = m
            .accel()
            .or(m.gyro())
            .map_or(25.0, |t| t.bias_delta[0].t_ref_c());
        let section = |cal: &TriadCalibration, th: Option<&TriadThermal>, unit: &str| {
            let coeffs = |p: &ThermalPoly| p.coeffs()[..=p.order()].to_vec();
            TriadSection {
                raw_unit: unit.to_owned(),
                bias: cal.bias,
                matrix: cal.matrix.0,
                bias_delta: std::array::from_fn(|k| {
                    th.map_or(vec![0.0], |t| coeffs(&t.bias_delta[k]))
                }),
                scale_delta: std::array::from_fn(|k| {
                    th.map_or(vec![0.0], |t| coeffs(&t.scale_delta[k]))
                }),
            }
        };
        ThermalModelFile {
            format_version: FORMAT_VERSION,
            model_id: m.id(),
            t_ref_c: t_ref,
            range_c: m.range_c(),
            out_of_range: policy_name(m.policy()).into(),
            gyro_g_sensitivity: m.gyro_g_sensitivity().map(|g| g.0),
            accel: section(&m.calibration().accel, m.accel(), units[0]),
            gyro: section(&m.calibration().gyro, m.gyro(), units[1]),
        }
    }

    /// The device model; `path` names the file in errors.
    pub fn model(&self, path: &str) -> Result<CompensationModel, ThermalModelError> {
        let bad = |message: String| ThermalModelError::Invalid {
            path: path.to_owned(),
            message,
        };
        if !(OLDEST_FORMAT_VERSION..=FORMAT_VERSION).contains(&self.format_version) {
            return Err(bad(format!(
                "format_version {} is not supported (this driftless reads \
                 {OLDEST_FORMAT_VERSION} to {FORMAT_VERSION})",
                self.format_version
            )));
        }
        let policy = match self.out_of_range.as_str() {
            "clamp" => OutOfRange::Clamp,
            "extrapolate" => OutOfRange::Extrapolate,
            "error" => OutOfRange::Error,
            other => {
                return Err(bad(format!(
                    "out_of_range = {other:?}: expected \"clamp\", \"extrapolate\" or \"error\""
                )));
            }
        };
        let [lo, hi] = self.range_c;
        let triad = |name: &str,
                     s: &TriadSection|
         -> Result<(TriadCalibration, TriadThermal), ThermalModelError> {
            let poly = |what: &str, k: usize, c: &[f64]| {
                ThermalPoly::new(self.t_ref_c, c, lo, hi)
                    .map_err(|e| bad(format!("[{name}] {what}[{k}]: {e}")))
            };
            let mut bias_delta = [ThermalPoly::constant(0.0); 3];
            let mut scale_delta = [ThermalPoly::constant(0.0); 3];
            for k in 0..3 {
                bias_delta[k] = poly("bias_delta", k, &s.bias_delta[k])?;
                scale_delta[k] = poly("scale_delta", k, &s.scale_delta[k])?;
            }
            Ok((
                TriadCalibration {
                    bias: s.bias,
                    matrix: Mat3(s.matrix),
                },
                TriadThermal {
                    bias_delta,
                    scale_delta,
                },
            ))
        };
        let (ca, ta) = triad("accel", &self.accel)?;
        let (cg, tg) = triad("gyro", &self.gyro)?;
        let model = CompensationModel::new(
            self.model_id,
            ImuCalibration {
                accel: ca,
                gyro: cg,
            },
            Some(tg),
            Some(ta),
            self.range_c,
            policy,
        )
        .map_err(|e| bad(e.to_string()))?;
        match self.gyro_g_sensitivity {
            Some(g) => model
                .with_gyro_g_sensitivity(Mat3(g))
                .map_err(|e| bad(format!("gyro_g_sensitivity: {e}"))),
            None => Ok(model),
        }
    }

    /// Reads a file and builds its model.
    pub fn load(
        path: impl AsRef<Path>,
    ) -> Result<(ThermalModelFile, CompensationModel), ThermalModelError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text =
            crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|source| {
                ThermalModelError::Io {
                    path: name.clone(),
                    source,
                }
            })?;
        ThermalModelFile::from_toml_str(&text, &name)
    }

    /// Parses a file's text and builds its model; `name` (the file's path) leads every
    /// error.
    pub fn from_toml_str(
        text: &str,
        name: &str,
    ) -> Result<(ThermalModelFile, CompensationModel), ThermalModelError> {
        let f: ThermalModelFile = toml::from_str(text).map_err(|e| ThermalModelError::Invalid {
            path: name.to_owned(),
            message: e.to_string(),
        })?;
        let m = f.model(name)?;
        Ok((f, m))
    }

    /// The file's text (what [`Self::save`] writes); `name` leads an error.
    pub fn to_toml_string(&self, name: &str) -> Result<String, ThermalModelError> {
        toml::to_string(self).map_err(|e| ThermalModelError::Invalid {
            path: name.to_owned(),
            message: e.to_string(),
        })
    }

    /// Writes the file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), ThermalModelError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text = self.to_toml_string(&name)?;
        crate::io::output::write(path, text)
            .map_err(|source| ThermalModelError::Io { path: name, source })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_round_trips_and_names_the_file_on_error() {
        let section = |unit: &str, b: f64| TriadSection {
            raw_unit: unit.into(),
            bias: [b, -b, 0.5 * b],
            matrix: [[1.0, 1e-3, 0.0], [0.0, 1.0, -2e-3], [0.0, 0.0, 1.0]],
            bias_delta: std::array::from_fn(|k| vec![0.0, 1e-3 * (k as f64 + 1.0), -2e-6, 3e-8]),
            scale_delta: std::array::from_fn(|_| vec![0.0, 2e-5]),
        };
        let f = ThermalModelFile {
            format_version: FORMAT_VERSION,
            model_id: 12345,
            t_ref_c: 25.0,
            range_c: [-20.0, 60.0],
            out_of_range: "clamp".into(),
            gyro_g_sensitivity: None,
            accel: section("m/s^2", 0.1),
            gyro: section("rad/s", 2e-3),
        };
        let text = f.to_toml_string("m.toml").unwrap();
        let (back, model) = ThermalModelFile::from_toml_str(&text, "m.toml").unwrap();
        assert_eq!(back, f);
        assert_eq!(model.id(), 12345);
        let e = ThermalModelFile::from_toml_str(&text.replace("clamp", "hold"), "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.toml: ") && e.contains("hold"), "{e}");
    }
}

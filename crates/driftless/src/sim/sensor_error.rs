//! Errors of the sensor-error simulation ([`super::sensor`], [`super::temperature`],
//! [`super::presets`], [`super::chamber`]).

use super::noise::SimError;

/// What went wrong configuring or running the sensor simulation.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SensorSimError {
    /// A noise-generator parameter was refused.
    #[error(transparent)]
    Noise(#[from] SimError),
    /// A configuration value out of range (`what` names the field, with its value).
    #[error("invalid {what}: {why}")]
    Invalid {
        /// Field and value, e.g. `gyro.noise[1].white = -1`.
        what: String,
        /// Why it was refused.
        why: String,
    },
    /// The sensor temperature left the range the thermal model is valid over.
    #[error(
        "sensor temperature {t_c} °C at t = {t_s} s is outside the thermal model's valid range \
         [{min_c}, {max_c}] °C (the polynomials are not extrapolated)"
    )]
    TemperatureOutOfRange {
        /// Offending temperature, °C.
        t_c: f64,
        /// Time, s.
        t_s: f64,
        /// Lower end of the valid range, °C.
        min_c: f64,
        /// Upper end of the valid range, °C.
        max_c: f64,
    },
    /// A preset name that does not exist.
    #[error("unknown sensor preset '{name}'; valid presets: {valid}")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The valid names, comma-separated.
        valid: String,
    },
    /// A noise-model file lacks a channel the sensor model needs.
    #[error("noise model has no channel '{name}' (it has: {present})")]
    MissingChannel {
        /// The channel needed (`gyro_x` … `acc_z`).
        name: String,
        /// The channels present, comma-separated.
        present: String,
    },
    /// A manifest could not be written or read as TOML.
    #[error("chamber manifest: {0}")]
    Manifest(String),
}

impl From<crate::calib::protocol::ManifestError> for SensorSimError {
    fn from(e: crate::calib::protocol::ManifestError) -> SensorSimError {
        SensorSimError::Manifest(e.0)
    }
}

impl SensorSimError {
    /// Shorthand for [`SensorSimError::Invalid`].
    pub fn invalid(what: impl Into<String>, why: impl Into<String>) -> SensorSimError {
        SensorSimError::Invalid {
            what: what.into(),
            why: why.into(),
        }
    }
}

/// `Ok` if `v` is finite and ≥ 0, else an [`SensorSimError::Invalid`] naming `what = v`.
pub(crate) fn check_nonneg(what: &str, v: f64) -> Result<(), SensorSimError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SensorSimError::invalid(
            format!("{what} = {v}"),
            "must be finite and >= 0",
        ))
    }
}

/// `Ok` if `v` is finite and > 0.
pub(crate) fn check_pos(what: &str, v: f64) -> Result<(), SensorSimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SensorSimError::invalid(
            format!("{what} = {v}"),
            "must be finite and > 0",
        ))
    }
}

/// `Ok` if `v` is finite.
pub(crate) fn check_finite(what: &str, v: f64) -> Result<(), SensorSimError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SensorSimError::invalid(
            format!("{what} = {v}"),
            "must be finite",
        ))
    }
}

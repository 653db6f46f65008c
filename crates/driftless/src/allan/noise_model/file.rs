//! The noise-model file: TOML text, read and written.

use std::path::Path;

use crate::allan::fit::TermKind;

use super::{FORMAT_VERSION, NoiseModel, NoiseModelError};

impl NoiseModel {
    /// Serialise to TOML.
    pub fn to_toml_string(&self) -> Result<String, NoiseModelError> {
        Ok(toml::to_string_pretty(self)?)
    }

    /// Parse from TOML (errors name the source as `<string>`).
    pub fn from_toml_str(s: &str) -> Result<NoiseModel, NoiseModelError> {
        Self::parse(s, Path::new("<string>"))
    }

    fn parse(s: &str, path: &Path) -> Result<NoiseModel, NoiseModelError> {
        let m: NoiseModel = toml::from_str(s).map_err(|e| NoiseModelError::Parse {
            path: path.to_path_buf(),
            source: Box::new(e),
        })?;
        let invalid = |why: String| NoiseModelError::Invalid {
            path: path.to_path_buf(),
            why,
        };
        if m.format_version == 0 || m.format_version > FORMAT_VERSION {
            return Err(invalid(format!(
                "format_version {} is not supported (this build reads 1..={FORMAT_VERSION})",
                m.format_version
            )));
        }
        if !(m.sample_rate_hz.is_finite() && m.sample_rate_hz > 0.0) {
            return Err(invalid(format!(
                "sample_rate_hz must be > 0, got {}",
                m.sample_rate_hz
            )));
        }
        for c in &m.channels {
            for k in [
                TermKind::Quantization,
                TermKind::White,
                TermKind::BiasInstability,
                TermKind::RateRandomWalk,
                TermKind::RateRamp,
                TermKind::GaussMarkov,
            ] {
                if let Some(t) = c.fit.term(k)
                    && !(t.value.is_finite() && t.value >= 0.0)
                {
                    return Err(invalid(format!(
                        "channel '{}': {} = {} is not a finite non-negative value",
                        c.name,
                        k.name(),
                        t.value
                    )));
                }
            }
        }
        Ok(m)
    }

    /// Write the model to `path`.
    pub fn save(&self, path: &Path) -> Result<(), NoiseModelError> {
        let s = self.to_toml_string()?;
        crate::io::output::write(path, s).map_err(|e| NoiseModelError::Write {
            path: path.to_path_buf(),
            source: e,
        })
    }

    /// Read a model from `path`.
    pub fn load(path: &Path) -> Result<NoiseModel, NoiseModelError> {
        let s = crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|e| {
            NoiseModelError::Read {
                path: path.to_path_buf(),
                source: e,
            }
        })?;
        Self::parse(&s, path)
    }
}

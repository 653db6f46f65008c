//! Pieces shared by the YAML configuration readers (KF-GINS, Kalibr): reading the file,
//! parsing it with `saphyr` (which keeps each node's line and column for the errors) and
//! looking up a key.

use std::path::Path;

use saphyr::{LoadableYamlNode, MarkedYaml, Scalar, YamlData};

use super::{Location, LogError};

/// Reads a YAML configuration file: its display name (for errors) and text.
pub(crate) fn read_named(path: &Path) -> Result<(String, String), LogError> {
    let name = path.display().to_string();
    match super::read_config_text(path, super::MAX_CONFIG_BYTES) {
        Ok(text) => Ok((name, text)),
        Err(error) => Err(LogError::Io { path: name, error }),
    }
}

/// The first document of `text`; a syntax error is a `format` error at its line and
/// column, an empty text [`LogError::Empty`].
pub(crate) fn load_root<'i>(
    text: &'i str,
    name: &str,
    format: &'static str,
) -> Result<MarkedYaml<'i>, LogError> {
    let docs = MarkedYaml::load_from_str(text).map_err(|e| LogError::Malformed {
        at: Location::field(name, e.marker().line(), e.marker().col() + 1),
        format,
        message: e.info().to_owned(),
    })?;
    docs.into_iter().next().ok_or_else(|| LogError::Empty {
        at: Location::input(name),
    })
}

/// The (key, value) nodes of `key` in a mapping.
pub(crate) fn mapping_get<'a, 'i>(
    map: &'a saphyr::AnnotatedMapping<'i, MarkedYaml<'i>>,
    key: &str,
) -> Option<(&'a MarkedYaml<'i>, &'a MarkedYaml<'i>)> {
    map.iter()
        .find(|(k, _)| matches!(&k.data, YamlData::Value(Scalar::String(s)) if s.as_ref() == key))
}

/// The number of a scalar node: an integer, a float, or a quoted number (as yaml-cpp and
/// Python's YAML readers of these files accept them).
pub(crate) fn scalar_number(v: &MarkedYaml<'_>) -> Option<f64> {
    match &v.data {
        YamlData::Value(Scalar::Integer(i)) => Some(*i as f64),
        YamlData::Value(Scalar::FloatingPoint(f)) => Some(f.0),
        YamlData::Value(Scalar::String(s)) => s.trim().parse::<f64>().ok(),
        _ => None,
    }
}

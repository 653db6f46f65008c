//! Header names: units in brackets, the time column found by its name, and columns
//! given by name or 1-based index resolved to fields.

use crate::io::error::{Location, LogError};

use super::options::ColumnRef;

/// `name [unit]` / `name(unit)` → (name, unit).
pub(super) fn split_name_unit(raw: &str) -> (String, Option<String>) {
    let t = raw.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(inner) = t.strip_suffix(close)
            && let Some(i) = inner.rfind(open)
        {
            let name = inner[..i].trim();
            let unit = inner[i + open.len_utf8()..].trim();
            if !name.is_empty() {
                return (name.to_owned(), Some(unit.to_owned()));
            }
        }
    }
    (t.to_owned(), None)
}

/// Header names (case-insensitive, unit in brackets stripped, a leading `#` ignored)
/// taken for the time column when none is given.
pub(crate) const TIME_COLUMN_NAMES: [&str; 10] = [
    "t",
    "time",
    "timestamp",
    "time_s",
    "stamp",
    "sec",
    "seconds",
    "gps_time",
    "gpst",
    "time_stamp",
];

/// The one header field named as a time column, if any; two such fields are an error
/// (which one is the time cannot be guessed).
pub(super) fn detect_time_field(
    names: &[String],
    at: &Location,
) -> Result<Option<usize>, LogError> {
    let hits: Vec<usize> = (0..names.len())
        .filter(|&i| {
            let n = names[i].trim().trim_start_matches('#').trim();
            TIME_COLUMN_NAMES.iter().any(|t| n.eq_ignore_ascii_case(t))
        })
        .collect();
    match hits.as_slice() {
        [] => Ok(None),
        [f] => Ok(Some(*f)),
        many => Err(LogError::InvalidOptions {
            at: at.clone(),
            message: format!(
                "{} header fields look like time columns ({}): name the time column with \
                 `--time-column`",
                many.len(),
                many.iter()
                    .map(|&i| format!("{}={}", i + 1, names[i]))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
    }
}

pub(super) fn resolve(r: &ColumnRef, names: &[String], at: &Location) -> Result<usize, LogError> {
    let unknown = || LogError::UnknownColumn {
        at: at.clone(),
        column: r.to_string(),
        available: names
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{}={n}", i + 1))
            .collect::<Vec<_>>()
            .join(", "),
    };
    match r {
        ColumnRef::Index(i) => {
            if *i >= 1 && *i <= names.len() {
                Ok(i - 1)
            } else {
                Err(unknown())
            }
        }
        ColumnRef::Name(n) => {
            let exact: Vec<usize> = (0..names.len()).filter(|&i| names[i] == *n).collect();
            let hits = if exact.is_empty() {
                (0..names.len())
                    .filter(|&i| names[i].eq_ignore_ascii_case(n))
                    .collect()
            } else {
                exact
            };
            match hits.as_slice() {
                [i] => Ok(*i),
                [] => Err(unknown()),
                _ => Err(LogError::InvalidOptions {
                    at: at.clone(),
                    message: format!(
                        "column name {n:?} is ambiguous (fields {}); select it by number",
                        hits.iter()
                            .map(|i| (i + 1).to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                }),
            }
        }
    }
}

//! Format definitions (`F` messages) flattened to scalar fields, and the values of
//! information and parameter messages.

use std::collections::BTreeMap;

use crate::io::autopilot::Scalar;

use super::{InfoValue, MAX_NESTING, MAX_ROW, ULogField};

/// One field of a format definition before flattening.
pub(super) struct FieldDef<'a> {
    pub(super) type_name: &'a str,
    pub(super) array: Option<usize>,
    pub(super) name: &'a str,
}

/// Splits `type[n] name` (the spec's field syntax).
pub(super) fn parse_field(text: &str) -> Option<FieldDef<'_>> {
    let (ty, name) = text.trim().split_once(' ')?;
    let name = name.trim();
    if name.is_empty() || ty.is_empty() {
        return None;
    }
    match ty.split_once('[') {
        Some((base, rest)) => {
            let n: usize = rest.strip_suffix(']')?.parse().ok()?;
            Some(FieldDef {
                type_name: base,
                array: Some(n),
                name,
            })
        }
        None => Some(FieldDef {
            type_name: ty,
            array: None,
            name,
        }),
    }
}

pub(super) fn builtin(type_name: &str) -> Option<Scalar> {
    Some(match type_name {
        "int8_t" => Scalar::I8,
        "uint8_t" => Scalar::U8,
        "int16_t" => Scalar::I16,
        "uint16_t" => Scalar::U16,
        "int32_t" => Scalar::I32,
        "uint32_t" => Scalar::U32,
        "int64_t" => Scalar::I64,
        "uint64_t" => Scalar::U64,
        "float" => Scalar::F32,
        "double" => Scalar::F64,
        "bool" => Scalar::Bool,
        "char" => Scalar::Char,
        _ => return None,
    })
}

/// Flattened layout of a format: (fields, row size, bytes of trailing padding).
pub(super) struct Layout {
    pub(super) fields: Vec<ULogField>,
    pub(super) size: usize,
    pub(super) trailing_padding: usize,
}

/// Flattens format `name` (nested types and arrays) into scalar fields.
pub(super) fn flatten(formats: &BTreeMap<String, String>, name: &str) -> Result<Layout, String> {
    let mut fields = Vec::new();
    let mut size = 0usize;
    let trailing_padding = flatten_into(formats, name, "", 0, &mut size, &mut fields)?;
    Ok(Layout {
        fields,
        size,
        trailing_padding,
    })
}

/// Appends the fields of format `name` at `*size` with prefix `prefix`; returns the size
/// of the format's own trailing padding field (0 if its last field is not padding).
pub(super) fn flatten_into(
    formats: &BTreeMap<String, String>,
    name: &str,
    prefix: &str,
    depth: usize,
    size: &mut usize,
    out: &mut Vec<ULogField>,
) -> Result<usize, String> {
    if depth > MAX_NESTING {
        return Err(format!(
            "format nesting deeper than {MAX_NESTING} at {name:?} (recursive definition?)"
        ));
    }
    let body = formats
        .get(name)
        .ok_or_else(|| format!("no format definition for type {name:?}"))?;
    let mut trailing = 0;
    for text in body.split(';').filter(|s| !s.trim().is_empty()) {
        let f =
            parse_field(text).ok_or_else(|| format!("bad field {text:?} in format {name:?}"))?;
        let count = f.array.unwrap_or(1);
        let start = *size;
        let padding = f.name.starts_with("_padding");
        for k in 0..count {
            let field_name = match f.array {
                Some(_) => format!("{prefix}{}[{k}]", f.name),
                None => format!("{prefix}{}", f.name),
            };
            match builtin(f.type_name) {
                Some(s) => {
                    if !padding {
                        out.push(ULogField {
                            name: field_name,
                            scalar: s,
                            offset: *size,
                        });
                    }
                    *size += s.size();
                }
                None => {
                    flatten_into(
                        formats,
                        f.type_name,
                        &format!("{field_name}."),
                        depth + 1,
                        size,
                        out,
                    )?;
                }
            }
            if *size > MAX_ROW || out.len() > MAX_ROW {
                return Err(format!(
                    "format {name:?} is larger than {MAX_ROW} bytes, the most a message holds"
                ));
            }
        }
        trailing = if padding { *size - start } else { 0 };
    }
    Ok(trailing)
}

/// Decodes the value of an `I`/`M`/`P` message given its `type key` string.
pub(super) fn info_value(type_name: &str, value: &[u8]) -> InfoValue {
    let (base, array) = match type_name.split_once('[') {
        Some((b, _)) => (b, true),
        None => (type_name, false),
    };
    if base == "char" {
        return InfoValue::Text(String::from_utf8_lossy(value).into_owned());
    }
    match builtin(base) {
        Some(s) if !array && value.len() == s.size() => match s.read_f64(value) {
            Some(v) => InfoValue::Number(v),
            None => InfoValue::Bytes(value.to_vec()),
        },
        _ => InfoValue::Bytes(value.to_vec()),
    }
}

/// Splits an `I`-style payload (`u8` key length, key `type name`, value).
pub(super) fn key_value(p: &[u8]) -> Option<(&str, &str, &[u8])> {
    let n = usize::from(*p.first()?);
    let key = std::str::from_utf8(p.get(1..1 + n)?).ok()?;
    let (ty, name) = key.split_once(' ')?;
    Some((ty, name, p.get(1 + n..)?))
}

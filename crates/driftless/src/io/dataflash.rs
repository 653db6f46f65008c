//! ArduPilot DataFlash binary log reader (`.bin` from the SD card), written from the
//! ArduPilot documentation ("Downloading and Analyzing Data Logs", log message reference at
//! ardupilot.org) and the format description in `AP_Logger/LogStructure.h`.
//!
//! Every message is `0xA3 0x95`, a one-byte message type, then a payload whose length the
//! type's FMT message fixes. Type 128 is FMT itself (89 bytes: `Type u8, Length u8,
//! Name char[4], Format char[16], Columns char[64]`), so a log describes itself as it goes:
//! each FMT defines one type's total length (header included), name, one format character
//! per field and comma-separated field labels. Format characters (little-endian):
//!
//! | char | type | value |
//! |---|---|---|
//! | `b` `B` `M` | int8, uint8, uint8 (flight mode) | as is |
//! | `h` `H` | int16, uint16 | as is |
//! | `i` `I` | int32, uint32 | as is |
//! | `q` `Q` | int64, uint64 | as is |
//! | `f` `d` `g` | float, double, half float | as is |
//! | `c` `C` | int16, uint16 | × 0.01 |
//! | `e` `E` | int32, uint32 | × 0.01 |
//! | `L` | int32 latitude/longitude | × 1e-7 (degrees) |
//! | `n` `N` `Z` | `char[4]`, `char[16]`, `char[64]` | text |
//! | `a` | `int16[32]` | array (not decoded as a column) |
//!
//! FMTU / UNIT / MULT messages are read like any other type (they only annotate units).
//!
//! **Robustness policy.** A log is a stream: logs cut off by a power loss end inside a
//! message, and SD-card corruption leaves garbage between messages. This reader:
//! * stops cleanly at a final message that the input cuts short, keeping everything before
//!   it, and reports the message's start in [`DataFlash::truncated_at_byte`];
//! * **resynchronises** on a bad header or a message type without a FMT: it skips forward
//!   to the next `0xA3 0x95` followed by a known type, counts the skipped bytes in
//!   [`DataFlash::skipped_bytes`] and notes where the first skip happened (as pymavlink's
//!   reader does) — a corrupt stretch costs the messages in it, not the log;
//! * returns [`LogError::AtByte`] naming the byte offset for a FMT message that cannot
//!   be right (length shorter than the header, a redefinition of FMT itself, a length that
//!   contradicts its own format string, a name another type already has, a new length for
//!   a type that already has messages): after that, framing or naming would be guesswork;
//! * a FMT with format characters this reader does not know frames its messages by the
//!   declared length but leaves them undecoded (noted).

use std::collections::BTreeMap;

use super::autopilot::{
    AutopilotFormat, AutopilotImu, AutopilotImuLogs, Column, Scalar, build_imu_log,
};
use super::error::{Location, LogError};
use super::log::Quantity;

/// First byte of every message header.
pub const HEAD1: u8 = 0xA3;
/// Second byte of every message header.
pub const HEAD2: u8 = 0x95;
/// Message type of FMT.
pub(crate) const FMT_TYPE: u8 = 128;
const FMT_LENGTH: usize = 89;
const FORMAT: &str = "ArduPilot DataFlash";

/// How a field's bytes become a value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DfKind {
    /// A number: scalar type and multiplier (1 for plain, 0.01 for `c C e E`, 1e-7 for `L`).
    Number(Scalar, f64),
    /// A NUL-padded string of this many bytes (`n N Z`).
    Text(usize),
    /// `a`: `int16[32]`.
    Array,
}

impl DfKind {
    fn from_char(c: u8) -> Option<DfKind> {
        use DfKind::*;
        use Scalar::*;
        Some(match c {
            b'b' => Number(I8, 1.0),
            b'B' | b'M' => Number(U8, 1.0),
            b'h' => Number(I16, 1.0),
            b'H' => Number(U16, 1.0),
            b'i' => Number(I32, 1.0),
            b'I' => Number(U32, 1.0),
            b'q' => Number(I64, 1.0),
            b'Q' => Number(U64, 1.0),
            b'f' => Number(F32, 1.0),
            b'd' => Number(F64, 1.0),
            b'g' => Number(F16, 1.0),
            b'c' => Number(I16, 0.01),
            b'C' => Number(U16, 0.01),
            b'e' => Number(I32, 0.01),
            b'E' => Number(U32, 0.01),
            b'L' => Number(I32, 1e-7),
            b'n' => Text(4),
            b'N' => Text(16),
            b'Z' => Text(64),
            b'a' => Array,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            DfKind::Number(s, _) => s.size(),
            DfKind::Text(n) => n,
            DfKind::Array => 64,
        }
    }
}

/// One field of a message type.
#[derive(Clone, Debug, PartialEq)]
pub struct DfField {
    /// Label from the FMT `Columns` list.
    pub name: String,
    /// Decoding.
    pub kind: DfKind,
    /// Offset in the payload (after the 3-byte header).
    pub offset: usize,
}

/// A message type defined by a FMT message.
#[derive(Clone, Debug, PartialEq)]
pub struct DfFormat {
    /// Message type id.
    pub type_id: u8,
    /// Total message length including the 3-byte header, bytes.
    pub length: usize,
    /// Name (`IMU`, `PARM`, …).
    pub name: String,
    /// Format characters.
    pub format: String,
    /// Decoded layout; `None` when a format character is unknown or the labels do not
    /// match the characters (messages are then framed but not decoded).
    pub fields: Option<Vec<DfField>>,
}

/// Messages of one type: raw payloads back to back.
#[derive(Clone, Debug, Default, PartialEq)]
struct Rows {
    payload: usize,
    data: Vec<u8>,
    offsets: Vec<u64>,
}

/// A parsed DataFlash log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DataFlash {
    /// Formats by type id, as last defined.
    pub formats: BTreeMap<u8, DfFormat>,
    rows: BTreeMap<u8, Rows>,
    /// `Some(offset)` when the input ends inside the message starting at this byte offset.
    pub truncated_at_byte: Option<u64>,
    /// Bytes skipped while resynchronising after bad headers or unknown types.
    pub skipped_bytes: u64,
    /// Things skipped or worth knowing.
    pub notes: Vec<String>,
}

impl DataFlash {
    fn format_by_name(&self, name: &str) -> Option<&DfFormat> {
        self.formats.values().find(|f| f.name == name)
    }
    /// Message names with their counts, by name.
    pub fn message_counts(&self) -> Vec<(String, usize)> {
        let mut v: Vec<(String, usize)> = self
            .rows
            .iter()
            .filter_map(|(id, r)| Some((self.formats.get(id)?.name.clone(), r.offsets.len())))
            .collect();
        v.sort();
        v
    }
    /// Number of messages named `name`.
    pub fn count(&self, name: &str) -> usize {
        self.format_by_name(name)
            .and_then(|f| self.rows.get(&f.type_id))
            .map_or(0, |r| r.offsets.len())
    }
    /// Byte offsets of the messages named `name`.
    pub(crate) fn byte_offsets(&self, name: &str) -> Vec<u64> {
        self.format_by_name(name)
            .and_then(|f| self.rows.get(&f.type_id))
            .map_or_else(Vec::new, |r| r.offsets.clone())
    }
    fn field(&self, message: &str, field: &str) -> Option<(&DfField, &Rows)> {
        let f = self.format_by_name(message)?;
        let fld = f.fields.as_ref()?.iter().find(|x| x.name == field)?;
        Some((fld, self.rows.get(&f.type_id)?))
    }
    /// A numeric field of every `message`, scaled (`c C e E L` multipliers applied);
    /// `None` when there is no such numeric field. NaN stays NaN here.
    pub fn column(&self, message: &str, field: &str) -> Option<Vec<f64>> {
        let (f, rows) = self.field(message, field)?;
        let DfKind::Number(s, mult) = f.kind else {
            return None;
        };
        Some(
            rows.data
                .chunks_exact(rows.payload.max(1))
                .map(|r| {
                    r.get(f.offset..)
                        .and_then(|b| s.read_f64(b))
                        .map_or(f64::NAN, |v| v * mult)
                })
                .collect(),
        )
    }
    /// A 64-bit unsigned field exactly (time stamps such as `TimeUS`).
    pub(crate) fn column_u64(&self, message: &str, field: &str) -> Option<Vec<u64>> {
        let (f, rows) = self.field(message, field)?;
        if f.kind != DfKind::Number(Scalar::U64, 1.0) {
            return None;
        }
        Some(
            rows.data
                .chunks_exact(rows.payload.max(1))
                .map(|r| super::autopilot::u64_at(r, f.offset).unwrap_or(0))
                .collect(),
        )
    }
    /// A text field (`n N Z`) of every `message`, NULs trimmed, lossy UTF-8.
    pub(crate) fn text_column(&self, message: &str, field: &str) -> Option<Vec<String>> {
        let (f, rows) = self.field(message, field)?;
        let DfKind::Text(n) = f.kind else {
            return None;
        };
        Some(
            rows.data
                .chunks_exact(rows.payload.max(1))
                .map(|r| {
                    let b = r.get(f.offset..f.offset + n).unwrap_or(&[]);
                    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
                    String::from_utf8_lossy(&b[..end]).into_owned()
                })
                .collect(),
        )
    }
    /// Parameters from PARM messages (`Name`, `Value`), last value of each name, by name.
    pub fn parameters(&self) -> BTreeMap<String, f64> {
        let (Some(names), Some(values)) = (
            self.text_column("PARM", "Name"),
            self.column("PARM", "Value"),
        ) else {
            return BTreeMap::new();
        };
        names.into_iter().zip(values).collect()
    }
}

fn malformed(source: &str, offset: usize, message: String) -> LogError {
    LogError::AtByte {
        path: source.to_owned(),
        byte_offset: offset as u64,
        format: FORMAT,
        message,
    }
}

fn text(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).trim().to_owned()
}

/// Layout from format characters and labels, or why not.
fn layout(format: &str, labels: &str) -> Result<(Vec<DfField>, usize), String> {
    let names: Vec<&str> = labels.split(',').collect();
    let mut fields = Vec::new();
    let mut offset = 0;
    for (k, c) in format.bytes().enumerate() {
        let kind = DfKind::from_char(c)
            .ok_or_else(|| format!("unknown format character {:?}", c as char))?;
        fields.push(DfField {
            name: names.get(k).copied().unwrap_or("").to_owned(),
            kind,
            offset,
        });
        offset += kind.size();
    }
    if names.len() != fields.len() {
        return Err(format!(
            "{} labels for {} format characters",
            names.len(),
            fields.len()
        ));
    }
    Ok((fields, offset))
}

/// Parses a DataFlash log held in memory.
pub fn parse_dataflash(bytes: &[u8], source: &str) -> Result<DataFlash, LogError> {
    let mut log = DataFlash::default();
    let fmt_format = "BBnNZ";
    let (fmt_fields, _) = layout(fmt_format, "Type,Length,Name,Format,Columns")
        .map_err(|m| malformed(source, 0, m))?;
    log.formats.insert(
        FMT_TYPE,
        DfFormat {
            type_id: FMT_TYPE,
            length: FMT_LENGTH,
            name: "FMT".into(),
            format: fmt_format.into(),
            fields: Some(fmt_fields),
        },
    );
    let mut first_skip: Option<usize> = None;
    let mut pos = 0usize;
    let known = |log: &DataFlash, at: usize| -> bool {
        matches!(bytes.get(at..at + 3), Some(&[HEAD1, HEAD2, id]) if log.formats.contains_key(&id))
    };
    while pos < bytes.len() {
        if !known(&log, pos) {
            // A cut-off header at the very end is truncation, not garbage.
            let rest = &bytes[pos..];
            if rest.len() < 3 && [HEAD1, HEAD2][..rest.len()] == *rest {
                log.truncated_at_byte = Some(pos as u64);
                break;
            }
            let next = (pos + 1..bytes.len())
                .find(|&i| known(&log, i))
                .unwrap_or(bytes.len());
            first_skip.get_or_insert(pos);
            log.skipped_bytes += (next - pos) as u64;
            pos = next;
            continue;
        }
        let id = bytes[pos + 2];
        let Some(len) = log.formats.get(&id).map(|f| f.length) else {
            break;
        };
        let Some(payload) = bytes.get(pos + 3..pos + len) else {
            log.truncated_at_byte = Some(pos as u64);
            break;
        };
        if id == FMT_TYPE {
            define(&mut log, payload, source, pos)?;
        }
        let rows = log.rows.entry(id).or_default();
        rows.payload = len - 3;
        rows.data.extend_from_slice(payload);
        rows.offsets.push(pos as u64);
        pos += len;
    }
    if let Some(at) = first_skip {
        log.notes.push(format!(
            "{} byte(s) skipped resynchronising on bad headers or unknown message types, first at byte {at}",
            log.skipped_bytes
        ));
    }
    if let Some(at) = log.truncated_at_byte {
        log.notes.push(format!(
            "log truncated: the message at byte {at} is cut off; read up to it"
        ));
    }
    Ok(log)
}

/// Applies one FMT message.
fn define(log: &mut DataFlash, p: &[u8], source: &str, at: usize) -> Result<(), LogError> {
    let (Some(&type_id), Some(&length), Some(name), Some(format), Some(labels)) = (
        p.first(),
        p.get(1),
        p.get(2..6),
        p.get(6..22),
        p.get(22..86),
    ) else {
        return Err(malformed(source, at, "FMT message too short".into()));
    };
    let length = usize::from(length);
    let (name, format, labels) = (text(name), text(format), text(labels));
    if length < 3 {
        return Err(malformed(
            source,
            at,
            format!(
                "FMT for type {type_id} ({name}) declares length {length}, less than the 3-byte header"
            ),
        ));
    }
    if type_id == FMT_TYPE {
        if length != FMT_LENGTH {
            return Err(malformed(
                source,
                at,
                format!("FMT redefines FMT with length {length} (must be {FMT_LENGTH})"),
            ));
        }
        return Ok(());
    }
    let fields = match layout(&format, &labels) {
        Ok((fields, size)) if size + 3 == length => Some(fields),
        Ok((_, size)) => {
            return Err(malformed(
                source,
                at,
                format!(
                    "FMT for type {type_id} ({name}): length {length} but format {format:?} needs {}",
                    size + 3
                ),
            ));
        }
        Err(why) => {
            log.notes.push(format!(
                "type {type_id} ({name}) at byte {at}: {why}; its messages are skipped undecoded"
            ));
            None
        }
    };
    if let Some(other) = log
        .formats
        .values()
        .find(|f| f.name == name && f.type_id != type_id)
    {
        return Err(malformed(
            source,
            at,
            format!(
                "FMT gives type {type_id} the name {name:?}, already the name of type {}",
                other.type_id
            ),
        ));
    }
    if let Some(old) = log.formats.get(&type_id)
        && old.length != length
        && log
            .rows
            .get(&type_id)
            .is_some_and(|r| !r.offsets.is_empty())
    {
        return Err(malformed(
            source,
            at,
            format!(
                "FMT redefines type {type_id} ({}) from length {} to {length} after messages of it",
                old.name, old.length
            ),
        ));
    }
    log.formats.insert(
        type_id,
        DfFormat {
            type_id,
            length,
            name,
            format,
            fields,
        },
    );
    Ok(())
}

/// One [`crate::io::ImuLog`] per IMU instance from the `IMU` messages: `TimeUS` (µs),
/// `GyrX/Y/Z` (rad/s), `AccX/Y/Z` (m/s²) and `T` (°C) when logged. The instance is the `I`
/// field; logs from before ArduPilot 4.1 use separate `IMU2`, `IMU3` messages without `I`,
/// read as instances 1 and 2. Gyro and accelerometer share a message, hence a time stamp:
/// no alignment is needed. A truncated final message is reported in
/// [`AutopilotImuLogs::truncated_at_byte`] and notes; the rows before it are kept.
pub fn imu_logs_from_dataflash(bytes: &[u8], source: &str) -> Result<AutopilotImuLogs, LogError> {
    let df = parse_dataflash(bytes, source)?;
    let found = df.message_counts();
    let notes = df.notes.clone();
    // (instance → (time, offsets, 6 channels, temperature))
    type Acc = (Vec<u64>, Vec<u64>, [Vec<f64>; 6], Vec<f64>, bool);
    let mut by_instance: BTreeMap<u8, Acc> = BTreeMap::new();
    for (name, legacy) in [("IMU", 0u8), ("IMU2", 1), ("IMU3", 2)] {
        if df.count(name) == 0 {
            continue;
        }
        let offsets = df.byte_offsets(name);
        let at0 = offsets.first().copied().unwrap_or(0);
        let need = |field: &str| {
            df.column(name, field).ok_or_else(|| LogError::AtByte {
                path: source.to_owned(),
                byte_offset: at0,
                format: FORMAT,
                message: format!("{name} messages have no numeric field {field}"),
            })
        };
        let time: Vec<u64> = match df.column_u64(name, "TimeUS") {
            Some(t) => t,
            None => need("TimeMS")?
                .into_iter()
                .map(|ms| (ms * 1000.0) as u64)
                .collect(),
        };
        let axes = [
            need("GyrX")?,
            need("GyrY")?,
            need("GyrZ")?,
            need("AccX")?,
            need("AccY")?,
            need("AccZ")?,
        ];
        let inst = df.column(name, "I");
        let temp = df.column(name, "T");
        for (r, &t_us) in time.iter().enumerate() {
            let id = match &inst {
                Some(i) => i.get(r).copied().unwrap_or(0.0) as u8,
                None => legacy,
            };
            let e = by_instance.entry(id).or_insert_with(|| {
                (
                    Vec::new(),
                    Vec::new(),
                    Default::default(),
                    Vec::new(),
                    temp.is_some(),
                )
            });
            e.0.push(t_us);
            e.1.push(offsets.get(r).copied().unwrap_or(0));
            for (k, a) in axes.iter().enumerate() {
                e.2[k].push(a.get(r).copied().unwrap_or(f64::NAN));
            }
            if let Some(t) = &temp {
                e.3.push(t.get(r).copied().unwrap_or(f64::NAN));
            }
        }
    }
    if by_instance.is_empty() {
        return Err(LogError::Malformed {
            at: Location::input(source),
            format: FORMAT,
            message: format!(
                "no IMU messages (message types: {})",
                super::autopilot::list_counts(&found)
            ),
        });
    }
    const NAMES: [(&str, Quantity, &str); 6] = [
        ("gyro_x", Quantity::AngularRate, "rad/s"),
        ("gyro_y", Quantity::AngularRate, "rad/s"),
        ("gyro_z", Quantity::AngularRate, "rad/s"),
        ("acc_x", Quantity::SpecificForce, "m/s^2"),
        ("acc_y", Quantity::SpecificForce, "m/s^2"),
        ("acc_z", Quantity::SpecificForce, "m/s^2"),
    ];
    let mut imus = Vec::new();
    for (instance, (time, offsets, axes, temp, has_temp)) in by_instance {
        let mut cols: Vec<Column> = axes
            .into_iter()
            .zip(NAMES)
            .map(|(values, (name, quantity, source_unit))| Column {
                name,
                quantity,
                source_unit,
                values,
            })
            .collect();
        if has_temp && temp.len() == time.len() {
            cols.push(Column {
                name: "temperature",
                quantity: Quantity::Temperature,
                source_unit: "degC",
                values: temp,
            });
        }
        let log = build_imu_log(source, FORMAT, &time, &offsets, cols)?;
        imus.push(AutopilotImu { instance, log });
    }
    Ok(AutopilotImuLogs {
        format: AutopilotFormat::DataFlash,
        imus,
        truncated_at_byte: df.truncated_at_byte,
        found,
        notes,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn fixed(s: &str, n: usize) -> Vec<u8> {
        let mut v = s.as_bytes().to_vec();
        v.resize(n, 0);
        v
    }

    fn fmt(out: &mut Vec<u8>, id: u8, len: u8, name: &str, format: &str, labels: &str) {
        out.extend_from_slice(&[HEAD1, HEAD2, FMT_TYPE, id, len]);
        out.extend(fixed(name, 4));
        out.extend(fixed(format, 16));
        out.extend(fixed(labels, 64));
    }

    /// A small valid log: FMT of FMT, FMT of IMU (`QBffffffcf`: a scaled `c` field too)
    /// and PARM, two PARM, three IMU rows for each of two instances.
    pub(crate) fn sample() -> Vec<u8> {
        let mut b = Vec::new();
        fmt(
            &mut b,
            128,
            89,
            "FMT",
            "BBnNZ",
            "Type,Length,Name,Format,Columns",
        );
        fmt(
            &mut b,
            163,
            3 + 8 + 1 + 24 + 2 + 4,
            "IMU",
            "QBffffffcf",
            "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,T",
        );
        fmt(
            &mut b,
            32,
            3 + 8 + 16 + 4,
            "PARM",
            "QNf",
            "TimeUS,Name,Value",
        );
        for (k, (name, v)) in [("INS_TCAL1_ENABLE", 1.0f32), ("LOG_BITMASK", 65535.0)]
            .into_iter()
            .enumerate()
        {
            b.extend_from_slice(&[HEAD1, HEAD2, 32]);
            b.extend_from_slice(&(k as u64).to_le_bytes());
            b.extend(fixed(name, 16));
            b.extend_from_slice(&v.to_le_bytes());
        }
        for k in 0..3u64 {
            for inst in 0..2u8 {
                b.extend_from_slice(&[HEAD1, HEAD2, 163]);
                b.extend_from_slice(&(1_000_000 + 2_500 * k).to_le_bytes());
                b.push(inst);
                for v in [0.001f32, -0.002, 0.003, 0.1, 0.2, -9.8] {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                b.extend_from_slice(&(-1234i16).to_le_bytes());
                b.extend_from_slice(&(35.0f32 + inst as f32 + k as f32 * 0.5).to_le_bytes());
            }
        }
        b
    }

    #[test]
    fn parses_a_hand_built_log() {
        let df = parse_dataflash(&sample(), "m.bin").unwrap();
        assert_eq!(df.truncated_at_byte, None);
        assert_eq!(df.skipped_bytes, 0);
        assert_eq!(df.count("IMU"), 6);
        assert_eq!(df.count("FMT"), 3);
        assert_eq!(df.parameters()["LOG_BITMASK"], 65535.0);
        assert_eq!(df.column("IMU", "EG").unwrap()[0], -12.34);
        let r = imu_logs_from_dataflash(&sample(), "m.bin").unwrap();
        assert_eq!(r.imus.len(), 2);
        let l = &r.imus[1].log;
        assert_eq!(r.imus[1].instance, 1);
        assert_eq!(l.len(), 3);
        assert_eq!(
            l.channel("temperature").unwrap().values,
            vec![36.0, 36.5, 37.0]
        );
        assert!((l.channel("acc_z").unwrap().values[0] + 9.8).abs() < 1e-6);
        assert!((l.tau0_s - 0.0025).abs() < 1e-12);
    }

    #[test]
    fn every_truncation_stops_cleanly() {
        let b = sample();
        for cut in 0..=b.len() {
            let df = parse_dataflash(&b[..cut], "m").unwrap();
            assert_eq!(df.skipped_bytes, 0, "cut {cut}");
            // Every message that started before the cut is either complete or reported.
            match df.truncated_at_byte {
                Some(t) => assert!(t < cut as u64),
                None => assert!(
                    cut == 0 || cut == b.len() || is_boundary(&b, cut),
                    "cut {cut}"
                ),
            }
            let _ = imu_logs_from_dataflash(&b[..cut], "m");
        }
    }

    fn is_boundary(b: &[u8], cut: usize) -> bool {
        let df = parse_dataflash(b, "m").unwrap();
        df.rows
            .values()
            .flat_map(|r| r.offsets.iter())
            .any(|&o| o as usize == cut)
    }

    #[test]
    fn garbage_is_skipped_and_counted() {
        let mut b = sample();
        let n = b.len();
        // Garbage between FMTs and the data, and an unknown type.
        let at = 89 * 3;
        b.splice(at..at, [1u8, 2, 3, HEAD1, HEAD2, 7, 9]);
        let df = parse_dataflash(&b, "g.bin").unwrap();
        assert_eq!(df.skipped_bytes, 7);
        assert_eq!(df.count("IMU"), 6);
        assert!(
            df.notes[0].contains(&format!("first at byte {at}")),
            "{:?}",
            df.notes
        );
        assert_eq!(b.len(), n + 7);
    }

    #[test]
    fn inconsistent_fmt_is_an_error_naming_its_offset() {
        let mut b = Vec::new();
        fmt(
            &mut b,
            128,
            89,
            "FMT",
            "BBnNZ",
            "Type,Length,Name,Format,Columns",
        );
        fmt(&mut b, 10, 9, "X", "Qf", "TimeUS,V");
        let e = parse_dataflash(&b, "f.bin").unwrap_err().to_string();
        assert!(
            e.starts_with("f.bin@byte 89: ArduPilot DataFlash: FMT for type 10 (X): length 9"),
            "{e}"
        );
        let mut b = Vec::new();
        fmt(&mut b, 10, 2, "X", "", "");
        assert!(parse_dataflash(&b, "f").is_err());
    }

    #[test]
    fn a_name_used_by_two_types_is_an_error() {
        let mut b = Vec::new();
        fmt(&mut b, 10, 3 + 4, "X", "f", "V");
        fmt(&mut b, 11, 3 + 4, "X", "i", "V");
        let e = parse_dataflash(&b, "f").unwrap_err().to_string();
        assert!(
            e.contains("@byte 89") && e.contains("already the name of type 10"),
            "{e}"
        );
    }

    #[test]
    fn unknown_format_character_frames_but_does_not_decode() {
        let mut b = Vec::new();
        fmt(&mut b, 10, 3 + 4, "X", "Y", "V");
        b.extend_from_slice(&[HEAD1, HEAD2, 10, 1, 2, 3, 4]);
        let df = parse_dataflash(&b, "f").unwrap();
        assert_eq!(df.count("X"), 1);
        assert_eq!(df.column("X", "V"), None);
        assert!(
            df.notes
                .iter()
                .any(|n| n.contains("unknown format character"))
        );
    }
}

//! PX4 ULog reader (`.ulg`), written from the format specification "ULog File Format"
//! (docs.px4.io, `dev_log/ulog_file_format`, versions 1.12–1.16).
//!
//! Layout: a 16-byte header (7-byte magic `ULog\x01\x12\x35`, version byte, `u64` start
//! time in µs), then messages, each a 3-byte header (`u16` payload size, `u8` type) and
//! its payload. All integers little-endian. Handled types:
//!
//! | type | meaning | what this reader does |
//! |---|---|---|
//! | `B` | flag bits (first message) | refuses unknown incompatible flags; honours `DATA_APPENDED` offsets |
//! | `F` | format `name:type field;…` | parsed lazily; nested formats and `type[n]` arrays flattened to `a.b[2].c` |
//! | `I` / `M` | (multi-)information `type key` = value | numbers and strings kept in [`ULog::info`] |
//! | `P` | parameter (`float` / `int32_t`) | last value kept in [`ULog::parameters`] |
//! | `A` / `R` | add / remove a logged topic instance (`multi_id`, `msg_id`) | |
//! | `D` | data row of a topic | kept raw per topic; columns decoded on demand |
//! | `L` / `C` | (tagged) log string | kept in [`ULog::log_messages`] |
//! | `O` | drop-out (ms lost) | kept in [`ULog::dropouts`] |
//! | `S`, `Q`, others | sync, default parameters, future types | skipped by size, as the spec asks |
//!
//! Padding fields (`_padding0`, …) occupy bytes but are not columns; when the last field
//! is padding, PX4 does not write it, so data rows may be that much shorter than the
//! format (the spec says so) — shorter by anything else is an error.
//!
//! Robustness: the reader never panics and never trusts a size it has not checked. A file
//! that ends inside a message stops there cleanly ([`ULog::truncated_at_byte`]); with
//! appended data, a message cut by the start of an appended block is dropped and reading
//! resumes at the block (the spec's recovery rule). Structural errors (a data row for a
//! format it does not fit, a format naming an unknown type, …) are
//! [`LogError::AtByte`] naming the file and the 0-based byte offset of the message.

use std::collections::BTreeMap;

use super::autopilot::{Scalar, u16_at, u64_at};
use super::error::LogError;

mod format;
mod imu;

use format::{flatten, info_value, key_value};
pub use imu::imu_logs_from_ulog;

/// The 7 magic bytes a ULog file starts with (then a version byte).
pub const MAGIC: [u8; 7] = [0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35];
const FORMAT: &str = "PX4 ULog";
/// Nesting depth of formats accepted (PX4 uses 2–3).
const MAX_NESTING: usize = 16;
/// Largest flattened row, bytes: a data message cannot carry more.
const MAX_ROW: usize = u16::MAX as usize;
/// Most flattened fields over all subscribed topics (a real log has a few thousand): bounds
/// the work a hostile file full of huge nested formats can cause.
const MAX_FIELDS: usize = 1 << 20;

/// A value of an information or parameter message.
#[derive(Clone, Debug, PartialEq)]
pub enum InfoValue {
    /// A number (any integer or float type).
    Number(f64),
    /// A `char[n]` string (lossy UTF-8).
    Text(String),
    /// Anything else (arrays of numbers, nested types): the raw bytes.
    Bytes(Vec<u8>),
}

/// One flattened scalar field of a topic row.
#[derive(Clone, Debug, PartialEq)]
pub struct ULogField {
    /// Full name: `x`, `clip_counter[2]`, `nested.field`, `arr[1].field`.
    pub name: String,
    /// Its type.
    pub scalar: Scalar,
    /// Byte offset inside the row.
    pub offset: usize,
}

/// A logged string (`L` or `C` message).
#[derive(Clone, Debug, PartialEq)]
pub struct ULogString {
    /// Log level, as in syslog (`'0'`..`'7'` in ASCII, i.e. 48..55).
    pub level: u8,
    /// Tag of a `C` message, `None` for `L`.
    pub tag: Option<u16>,
    /// Time stamp, µs.
    pub timestamp_us: u64,
    /// The text (lossy UTF-8).
    pub text: String,
}

/// A drop-out: the logger lost data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dropout {
    /// Byte offset of the `O` message.
    pub byte_offset: u64,
    /// Length of the loss, ms.
    pub duration_ms: u16,
}

/// One logged topic instance: its layout and raw rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// Topic (format) name, e.g. `sensor_gyro`.
    pub name: String,
    /// Instance number (`multi_id`).
    pub multi_id: u8,
    /// Flattened fields, padding excluded, in row order.
    pub fields: Vec<ULogField>,
    row_size: usize,
    data: Vec<u8>,
    row_offsets: Vec<u64>,
}

impl Topic {
    /// Number of rows (data messages).
    pub fn len(&self) -> usize {
        self.row_offsets.len()
    }
    /// True when no rows were logged.
    pub fn is_empty(&self) -> bool {
        self.row_offsets.is_empty()
    }
    /// The field names, in row order.
    pub fn field_names(&self) -> impl Iterator<Item = &str> {
        self.fields.iter().map(|f| f.name.as_str())
    }
    /// Byte offset in the file of row `i`'s data message.
    pub(crate) fn row_byte_offset(&self, i: usize) -> Option<u64> {
        self.row_offsets.get(i).copied()
    }
    /// A field as f64 for every row (`None` when the topic has no such field). Floats are
    /// returned as logged: NaN stays NaN here — [`imu_logs_from_ulog`] rejects them.
    pub fn column(&self, field: &str) -> Option<Vec<f64>> {
        let f = self.fields.iter().find(|f| f.name == field)?;
        Some(
            self.data
                .chunks_exact(self.row_size.max(1))
                .map(|row| {
                    row.get(f.offset..)
                        .and_then(|b| f.scalar.read_f64(b))
                        .unwrap_or(f64::NAN)
                })
                .collect(),
        )
    }
    /// The `timestamp` field (µs) of every row, exactly (as `u64`).
    pub fn timestamps_us(&self) -> Option<Vec<u64>> {
        let f = self
            .fields
            .iter()
            .find(|f| f.name == "timestamp" && f.scalar == Scalar::U64)?;
        Some(
            self.data
                .chunks_exact(self.row_size.max(1))
                .map(|row| u64_at(row, f.offset).unwrap_or(0))
                .collect(),
        )
    }
}

/// A parsed ULog file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ULog {
    /// File format version (header byte 7).
    pub version: u8,
    /// Logging start, µs (header).
    pub start_time_us: u64,
    /// Raw format definitions by name: `name` → `type field;type field;…`.
    pub formats: BTreeMap<String, String>,
    /// Information (`I`), and multi-information (`M`, values in order) by key name.
    pub info: BTreeMap<String, Vec<InfoValue>>,
    /// Parameters by name (initial value overwritten by later changes).
    pub parameters: BTreeMap<String, f64>,
    /// Logged topic instances, in order of subscription.
    pub topics: Vec<Topic>,
    /// Logged strings.
    pub log_messages: Vec<ULogString>,
    /// Drop-outs.
    pub dropouts: Vec<Dropout>,
    /// `Some(offset)` when the file ends inside the message starting at this byte offset.
    pub truncated_at_byte: Option<u64>,
    /// Offsets of appended data blocks (flag bits), if any.
    pub appended_offsets: Vec<u64>,
    /// Things skipped or repaired.
    pub notes: Vec<String>,
}

impl ULog {
    /// The topic instance `name[multi_id]`.
    pub fn topic(&self, name: &str, multi_id: u8) -> Option<&Topic> {
        self.topics
            .iter()
            .find(|t| t.name == name && t.multi_id == multi_id)
    }
    /// Every instance of topic `name`, by increasing `multi_id`.
    pub fn instances(&self, name: &str) -> Vec<&Topic> {
        let mut v: Vec<&Topic> = self.topics.iter().filter(|t| t.name == name).collect();
        v.sort_by_key(|t| t.multi_id);
        v
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

/// Parses a whole ULog file held in memory.
pub fn parse_ulog(bytes: &[u8], source: &str) -> Result<ULog, LogError> {
    if bytes.len() < 16 || !bytes.starts_with(&MAGIC) {
        let what = if bytes.starts_with(&MAGIC) || MAGIC.starts_with(bytes) {
            format!(
                "{} bytes: shorter than the 16-byte ULog header",
                bytes.len()
            )
        } else {
            format!(
                "not a ULog file: the first bytes are {:02x?}, expected {:02x?}",
                &bytes[..bytes.len().min(7)],
                MAGIC
            )
        };
        return Err(malformed(source, 0, what));
    }
    let mut r = Reader {
        bytes,
        source,
        log: ULog {
            version: bytes[7],
            start_time_us: u64_at(bytes, 8).unwrap_or(0),
            ..ULog::default()
        },
        subscribed: BTreeMap::new(),
        layouts: Vec::new(),
        unknown_types: BTreeMap::new(),
        unsubscribed_rows: 0,
        flattened: 0,
        appended: Vec::new(),
    };
    let mut pos = 16usize;
    let mut first = true;
    while pos < bytes.len() {
        let start = pos;
        let (Some(size), Some(&kind)) = (u16_at(bytes, pos), bytes.get(pos + 2)) else {
            r.log.truncated_at_byte = Some(start as u64);
            break;
        };
        let end = pos + 3 + usize::from(size);
        // A block of appended data starts inside this message: the message was cut when
        // the data was appended; resume at the block.
        if let Some(&next) = r.appended.iter().find(|&&a| a > start && a < end) {
            r.log.notes.push(format!(
                "message at byte {start} cut by appended data at byte {next}; skipped"
            ));
            pos = next;
            continue;
        }
        let Some(p) = bytes.get(pos + 3..end) else {
            r.log.truncated_at_byte = Some(start as u64);
            break;
        };
        r.message(kind, start, end, p, first)?;
        first = false;
        pos = end;
    }
    Ok(r.finish())
}

/// The state of [`parse_ulog`] between messages.
struct Reader<'a> {
    bytes: &'a [u8],
    source: &'a str,
    log: ULog,
    /// msg_id → index into `log.topics`.
    subscribed: BTreeMap<u16, usize>,
    /// Per topic: (row size, min row size).
    layouts: Vec<(usize, usize)>,
    unknown_types: BTreeMap<u8, usize>,
    unsubscribed_rows: usize,
    /// Fields of all subscribed topics so far.
    flattened: usize,
    /// Byte offsets where appended data blocks start.
    appended: Vec<usize>,
}

impl Reader<'_> {
    fn bad(&self, start: usize, m: String) -> LogError {
        malformed(self.source, start, m)
    }

    /// One message of type `kind` with payload `p` (bytes `start..end` of the file).
    fn message(
        &mut self,
        kind: u8,
        start: usize,
        end: usize,
        p: &[u8],
        first: bool,
    ) -> Result<(), LogError> {
        let bad = |m: String| malformed(self.source, start, m);
        match kind {
            b'B' => {
                if !first {
                    self.log.notes.push(format!(
                        "flag bits message at byte {start} not first; ignored"
                    ));
                } else {
                    self.flag_bits(start, end, p)?;
                }
            }
            b'F' => {
                let text = std::str::from_utf8(p)
                    .map_err(|_| bad("format definition is not UTF-8".into()))?;
                let (name, body) = text
                    .split_once(':')
                    .ok_or_else(|| bad(format!("format definition without ':': {text:?}")))?;
                self.log.formats.insert(name.to_owned(), body.to_owned());
            }
            b'I' | b'M' | b'P' => self.key_value(kind, start, p)?,
            b'A' => self.subscribe(start, p)?,
            b'R' => {
                if let Some(id) = u16_at(p, 0) {
                    self.subscribed.remove(&id);
                }
            }
            b'D' => self.data(start, p)?,
            b'L' | b'C' => {
                let tagged = kind == b'C';
                let head = if tagged { 11 } else { 9 };
                let (Some(&level), Some(ts), Some(text)) =
                    (p.first(), u64_at(p, head - 8), p.get(head..))
                else {
                    return Err(bad("log string message too short".into()));
                };
                self.log.log_messages.push(ULogString {
                    level,
                    tag: if tagged { u16_at(p, 1) } else { None },
                    timestamp_us: ts,
                    text: String::from_utf8_lossy(text).into_owned(),
                });
            }
            b'O' => {
                let duration_ms = u16_at(p, 0).unwrap_or(0);
                self.log.dropouts.push(Dropout {
                    byte_offset: start as u64,
                    duration_ms,
                });
            }
            b'S' | b'Q' => {}
            other => *self.unknown_types.entry(other).or_default() += 1,
        }
        Ok(())
    }

    /// The flag bits message: unknown incompatible flags refused, appended-data offsets kept.
    fn flag_bits(&mut self, start: usize, end: usize, p: &[u8]) -> Result<(), LogError> {
        if p.len() < 40 {
            return Err(self.bad(
                start,
                format!(
                    "flag bits message of {} bytes, expected at least 40",
                    p.len()
                ),
            ));
        }
        let incompat = &p[8..16];
        if incompat[0] & !1 != 0 || incompat[1..].iter().any(|&b| b != 0) {
            return Err(self.bad(
                start,
                format!(
                    "unknown incompatible flags {incompat:02x?}: this file needs a newer ULog reader"
                ),
            ));
        }
        if incompat[0] & 1 != 0 {
            for k in 0..3 {
                let off = u64_at(p, 16 + 8 * k).unwrap_or(0);
                if off != 0 {
                    self.log.appended_offsets.push(off);
                    if let Ok(o) = usize::try_from(off)
                        && o > end
                        && o <= self.bytes.len()
                    {
                        self.appended.push(o);
                    }
                }
            }
            self.appended.sort_unstable();
        }
        Ok(())
    }

    /// An information (`I`), multi-information (`M`) or parameter (`P`) message.
    fn key_value(&mut self, kind: u8, start: usize, p: &[u8]) -> Result<(), LogError> {
        let p = if kind == b'M' {
            p.get(1..).unwrap_or(&[])
        } else {
            p
        };
        let (ty, name, value) = key_value(p).ok_or_else(|| {
            self.bad(
                start,
                format!("malformed '{}' key/value message", kind as char),
            )
        })?;
        let v = info_value(ty, value);
        if kind == b'P' {
            match v {
                InfoValue::Number(x) => {
                    self.log.parameters.insert(name.to_owned(), x);
                }
                _ => self.log.notes.push(format!(
                    "parameter {name:?} of type {ty:?} at byte {start} skipped"
                )),
            }
        } else {
            let e = self.log.info.entry(name.to_owned()).or_default();
            if kind == b'I' {
                e.clear();
            }
            e.push(v);
        }
        Ok(())
    }

    /// A subscription: the topic instance's format flattened (once) and its msg_id bound.
    fn subscribe(&mut self, start: usize, p: &[u8]) -> Result<(), LogError> {
        let bad = |m: String| malformed(self.source, start, m);
        let (Some(&multi_id), Some(msg_id), Some(name)) = (p.first(), u16_at(p, 1), p.get(3..))
        else {
            return Err(bad("subscription message shorter than 3 bytes".into()));
        };
        let name = std::str::from_utf8(name).map_err(|_| bad("topic name is not UTF-8".into()))?;
        let idx = match self
            .log
            .topics
            .iter()
            .position(|t| t.name == name && t.multi_id == multi_id)
        {
            Some(i) => i,
            None => {
                let layout = flatten(&self.log.formats, name)
                    .map_err(|m| bad(format!("topic {name:?}: {m}")))?;
                self.flattened += layout.fields.len();
                if self.flattened > MAX_FIELDS {
                    return Err(bad(format!(
                        "more than {MAX_FIELDS} fields in all subscribed topics"
                    )));
                }
                self.log.topics.push(Topic {
                    name: name.to_owned(),
                    multi_id,
                    fields: layout.fields,
                    row_size: layout.size,
                    data: Vec::new(),
                    row_offsets: Vec::new(),
                });
                self.layouts
                    .push((layout.size, layout.size - layout.trailing_padding));
                self.log.topics.len() - 1
            }
        };
        self.subscribed.insert(msg_id, idx);
        Ok(())
    }

    /// A data row: appended to its topic (padded to the full row size), after checking
    /// its length against the format.
    fn data(&mut self, start: usize, p: &[u8]) -> Result<(), LogError> {
        let bad = |m: String| malformed(self.source, start, m);
        let Some(id) = u16_at(p, 0) else {
            return Err(bad("data message shorter than its 2-byte id".into()));
        };
        let row = &p[2..];
        match self.subscribed.get(&id) {
            None => self.unsubscribed_rows += 1,
            Some(&i) => {
                let (full, min) = self.layouts.get(i).copied().unwrap_or((0, 0));
                let Some(t) = self.log.topics.get_mut(i) else {
                    return Err(bad(format!("internal: no topic for msg_id {id}")));
                };
                if row.len() > full || row.len() < min {
                    return Err(bad(format!(
                        "data row of {} bytes for topic {}[{}], whose format has {full} bytes{}",
                        row.len(),
                        t.name,
                        t.multi_id,
                        if min < full {
                            format!(" ({min} without trailing padding)")
                        } else {
                            String::new()
                        }
                    )));
                }
                t.data.extend_from_slice(row);
                t.data.resize(t.data.len() + full - row.len(), 0);
                t.row_offsets.push(start as u64);
            }
        }
        Ok(())
    }

    /// The log with notes on what was skipped and on logger drop-outs.
    fn finish(mut self) -> ULog {
        let log = &mut self.log;
        if self.unsubscribed_rows > 0 {
            log.notes.push(format!(
                "{} data message(s) for unsubscribed ids skipped",
                self.unsubscribed_rows
            ));
        }
        for (k, n) in &self.unknown_types {
            log.notes
                .push(format!("{n} message(s) of unknown type 0x{k:02x} skipped"));
        }
        if !log.dropouts.is_empty() {
            let total: u64 = log.dropouts.iter().map(|d| u64::from(d.duration_ms)).sum();
            log.notes.push(format!(
                "{} logger drop-out(s), {total} ms in all",
                log.dropouts.len()
            ));
        }
        self.log
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn msg(out: &mut Vec<u8>, kind: u8, payload: &[u8]) {
        out.extend_from_slice(&(payload.len() as u16).to_le_bytes());
        out.push(kind);
        out.extend_from_slice(payload);
    }

    fn data_row(out: &mut Vec<u8>, msg_id: u16, fields: &[u8]) {
        let mut p = msg_id.to_le_bytes().to_vec();
        p.extend_from_slice(fields);
        msg(out, b'D', &p);
    }

    fn sensor_row(t_us: u64, xyz: [f32; 3], temp: f32, padded: bool) -> Vec<u8> {
        let mut r = t_us.to_le_bytes().to_vec();
        r.extend_from_slice(&42u32.to_le_bytes()); // device_id
        for v in xyz {
            r.extend_from_slice(&v.to_le_bytes());
        }
        r.extend_from_slice(&temp.to_le_bytes());
        r.extend_from_slice(&[1, 2, 3]); // clip[3] via nested type
        if padded {
            r.push(0); // the trailing _padding0 is normally not written
        }
        r
    }

    /// A small valid ULog: flag bits, formats with a nested type and trailing padding,
    /// info, a parameter, two topics (gyro and accel, instance 0), a log string, a
    /// drop-out, a sync message and an unknown message type.
    pub(crate) fn sample() -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend_from_slice(&1000u64.to_le_bytes());
        msg(&mut b, b'B', &[0u8; 40]);
        msg(&mut b, b'F', b"clips:uint8_t[3] c;");
        msg(
            &mut b,
            b'F',
            b"sensor_gyro:uint64_t timestamp;uint32_t device_id;float x;float y;float z;float temperature;clips clip;uint8_t[1] _padding0;",
        );
        msg(
            &mut b,
            b'F',
            b"sensor_accel:uint64_t timestamp;uint32_t device_id;float x;float y;float z;float temperature;clips clip;uint8_t[1] _padding0;",
        );
        let mut info = vec![12u8];
        info.extend_from_slice(b"char[3] name");
        info.extend_from_slice(b"PX4");
        msg(&mut b, b'I', &info);
        let mut par = vec![13u8];
        par.extend_from_slice(b"float TC_A_EN");
        par.extend_from_slice(&1.0f32.to_le_bytes());
        msg(&mut b, b'P', &par);
        let mut a = vec![0u8, 5, 0];
        a.extend_from_slice(b"sensor_gyro");
        msg(&mut b, b'A', &a);
        let mut a = vec![0u8, 6, 0];
        a.extend_from_slice(b"sensor_accel");
        msg(&mut b, b'A', &a);
        for k in 0..4u64 {
            let t = 2_000_000 + 10_000 * k;
            let temp = 30.0 + k as f32;
            data_row(&mut b, 5, &sensor_row(t, [0.01, -0.02, 0.03], temp, k == 0));
            data_row(
                &mut b,
                6,
                &sensor_row(t + 50, [0.1, 0.2, -9.8], temp, false),
            );
            if k == 1 {
                let mut l = vec![b'6'];
                l.extend_from_slice(&t.to_le_bytes());
                l.extend_from_slice(b"hello");
                msg(&mut b, b'L', &l);
                msg(&mut b, b'O', &7u16.to_le_bytes());
                msg(
                    &mut b,
                    b'S',
                    &[0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12],
                );
                msg(&mut b, b'Z', b"future");
            }
        }
        b
    }

    #[test]
    fn parses_a_hand_built_log() {
        let b = sample();
        let u = parse_ulog(&b, "mem.ulg").unwrap();
        assert_eq!(u.version, 1);
        assert_eq!(u.start_time_us, 1000);
        assert_eq!(u.truncated_at_byte, None);
        assert_eq!(u.info["name"], vec![InfoValue::Text("PX4".into())]);
        assert_eq!(u.parameters["TC_A_EN"], 1.0);
        assert_eq!(u.log_messages[0].text, "hello");
        assert_eq!(u.dropouts.len(), 1);
        assert!(u.notes.iter().any(|n| n.contains("unknown type 0x5a")));
        let g = u.topic("sensor_gyro", 0).unwrap();
        assert_eq!(g.len(), 4);
        let names: Vec<&str> = g.field_names().collect();
        assert_eq!(
            names,
            [
                "timestamp",
                "device_id",
                "x",
                "y",
                "z",
                "temperature",
                "clip.c[0]",
                "clip.c[1]",
                "clip.c[2]"
            ]
        );
        assert_eq!(g.column("clip.c[2]").unwrap(), vec![3.0; 4]);
        assert_eq!(
            g.column("temperature").unwrap(),
            vec![30.0, 31.0, 32.0, 33.0]
        );
        assert_eq!(g.timestamps_us().unwrap()[3], 2_030_000);
        assert!(g.column("_padding0").is_none());
    }

    #[test]
    fn imu_logs_join_gyro_and_accel() {
        let r = imu_logs_from_ulog(&sample(), "mem.ulg").unwrap();
        assert_eq!(r.imus.len(), 1);
        let log = &r.imus[0].log;
        assert_eq!(log.len(), 4);
        let names: Vec<&str> = log.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "gyro_x",
                "gyro_y",
                "gyro_z",
                "acc_x",
                "acc_y",
                "acc_z",
                "temperature"
            ]
        );
        assert!((log.channel("acc_z").unwrap().values[2] + 9.8).abs() < 1e-6);
        assert_eq!(log.time_s.as_ref().unwrap()[0], 2.0);
        assert!((log.tau0_s - 0.01).abs() < 1e-12);
    }

    #[test]
    fn every_truncation_stops_cleanly_or_errors() {
        let b = sample();
        let full = parse_ulog(&b, "m").unwrap();
        for cut in 0..b.len() {
            match parse_ulog(&b[..cut], "m") {
                Ok(u) => {
                    assert!(cut >= 16);
                    let t = u.truncated_at_byte;
                    assert!(t.is_none() || t.unwrap() < cut as u64);
                    let rows: usize = u.topics.iter().map(Topic::len).sum();
                    assert!(rows <= full.topics.iter().map(Topic::len).sum());
                }
                Err(e) => {
                    assert!(cut < 16, "cut {cut}: {e}");
                    assert!(e.to_string().contains("m@byte 0: PX4 ULog"));
                }
            }
            let _ = imu_logs_from_ulog(&b[..cut], "m");
        }
    }

    #[test]
    fn malformed_row_names_the_byte_offset() {
        let mut b = sample();
        let at = b.len();
        data_row(&mut b, 5, &[0u8; 5]);
        let e = parse_ulog(&b, "x.ulg").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("x.ulg@byte {at}: PX4 ULog: data row of 5 bytes")),
            "{e}"
        );
    }

    #[test]
    fn bad_magic_and_unknown_incompat_flags_are_errors() {
        let e = parse_ulog(b"DRIFTLOG-not-a-ulog", "f").unwrap_err();
        assert!(e.to_string().contains("not a ULog file"), "{e}");
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend_from_slice(&0u64.to_le_bytes());
        let mut flags = [0u8; 40];
        flags[8] = 2;
        msg(&mut b, b'B', &flags);
        let e = parse_ulog(&b, "f").unwrap_err();
        assert!(e.to_string().contains("incompatible flags"), "{e}");
    }

    #[test]
    fn recursive_format_is_an_error_not_a_stack_overflow() {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend_from_slice(&0u64.to_le_bytes());
        msg(&mut b, b'F', b"loop:loop inner;");
        let mut a = vec![0u8, 1, 0];
        a.extend_from_slice(b"loop");
        msg(&mut b, b'A', &a);
        let e = parse_ulog(&b, "f").unwrap_err();
        assert!(e.to_string().contains("nesting"), "{e}");
        let mut b2 = MAGIC.to_vec();
        b2.push(1);
        b2.extend_from_slice(&0u64.to_le_bytes());
        msg(&mut b2, b'F', b"big:double[99999999] x;");
        let mut a = vec![0u8, 1, 0];
        a.extend_from_slice(b"big");
        msg(&mut b2, b'A', &a);
        assert!(parse_ulog(&b2, "f").is_err());
    }

    #[test]
    fn appended_data_resumes_at_its_offset() {
        // Log with DATA_APPENDED: a data row cut short by the appended block.
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend_from_slice(&0u64.to_le_bytes());
        let flags_at = b.len();
        msg(&mut b, b'B', &[0u8; 40]);
        msg(&mut b, b'F', b"t:uint64_t timestamp;float v;");
        let mut a = vec![0u8, 1, 0];
        a.extend_from_slice(b"t");
        msg(&mut b, b'A', &a);
        let mut row = 5u64.to_le_bytes().to_vec();
        row.extend_from_slice(&1.0f32.to_le_bytes());
        data_row(&mut b, 1, &row);
        // A row whose tail was lost: only its first 6 bytes made it.
        let mut cut = Vec::new();
        data_row(&mut cut, 1, &row);
        b.extend_from_slice(&cut[..6]);
        let appended = b.len() as u64;
        let mut row2 = 9u64.to_le_bytes().to_vec();
        row2.extend_from_slice(&2.0f32.to_le_bytes());
        data_row(&mut b, 1, &row2);
        // Set incompat flag and offset in the flag bits message.
        b[flags_at + 3 + 8] = 1;
        b[flags_at + 3 + 16..flags_at + 3 + 24].copy_from_slice(&appended.to_le_bytes());
        let u = parse_ulog(&b, "f").unwrap();
        let t = u.topic("t", 0).unwrap();
        assert_eq!(t.column("v").unwrap(), vec![1.0, 2.0]);
        assert_eq!(u.appended_offsets, vec![appended]);
        assert!(u.notes.iter().any(|n| n.contains("appended")));
    }

    #[test]
    fn nan_sample_is_an_error_with_offset() {
        let mut b = sample();
        let at = b.len();
        data_row(
            &mut b,
            5,
            &sensor_row(2_040_000, [f32::NAN, 0.0, 0.0], 33.0, false),
        );
        data_row(
            &mut b,
            6,
            &sensor_row(2_040_050, [0.0, 0.0, -9.8], 33.0, false),
        );
        let e = imu_logs_from_ulog(&b, "n.ulg").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("n.ulg@byte {at}: PX4 ULog: non-finite gyro_x")),
            "{e}"
        );
    }
}

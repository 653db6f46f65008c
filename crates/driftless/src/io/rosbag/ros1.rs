//! ROS 1 bag format 2.0 (ROS wiki, "Bags/Format/2.0"): after the magic line, records of
//! `u32 header_len, header, u32 data_len, data`, the header a list of `u32 len, name=value`
//! fields with `op` the record type. Messages (op 0x02) and their connections (op 0x07) sit
//! inside chunks (op 0x05); the index section at the end repeats the connections. All
//! integers little-endian.

use super::compress::{self, Codec};
use super::{Item, Source, le_u32};
use crate::io::error::LogError;

const FORMAT: &str = "ROS 1 bag";

const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_INDEX: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// The value of header field `name`, if present; an error for a malformed field list.
fn field<'a>(header: &'a [u8], name: &[u8]) -> Result<Option<&'a [u8]>, String> {
    let mut at = 0;
    while at < header.len() {
        let len = le_u32(header, at).ok_or("header field length cut off")? as usize;
        let f = header
            .get(at + 4..(at + 4).saturating_add(len))
            .ok_or_else(|| format!("header field of {len} bytes runs past its header"))?;
        let eq = f
            .iter()
            .position(|&b| b == b'=')
            .ok_or("header field without '='")?;
        if &f[..eq] == name {
            return Ok(Some(&f[eq + 1..]));
        }
        at += 4 + len;
    }
    Ok(None)
}

fn required<'a>(header: &'a [u8], name: &str) -> Result<&'a [u8], String> {
    field(header, name.as_bytes())?.ok_or_else(|| format!("record header without field {name}"))
}

fn u32_field(header: &[u8], name: &str) -> Result<u32, String> {
    let v = required(header, name)?;
    le_u32(v, 0)
        .filter(|_| v.len() == 4)
        .ok_or_else(|| format!("field {name} is {} bytes, not 4", v.len()))
}

fn str_field<'a>(header: &'a [u8], name: &str) -> Result<&'a str, String> {
    std::str::from_utf8(required(header, name)?).map_err(|_| format!("field {name} is not UTF-8"))
}

fn op_of(header: &[u8]) -> Result<u8, String> {
    match required(header, "op")? {
        [op] => Ok(*op),
        v => Err(format!("field op is {} bytes, not 1", v.len())),
    }
}

/// Hands on the connections and messages of records `data` (a chunk's content) that starts
/// at file offset `base`; for a decompressed chunk (`compressed`), `base` is the chunk
/// record's offset and every record inside is reported there.
fn records_in_chunk(
    src: &Source<'_>,
    data: &[u8],
    base: u64,
    compressed: bool,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let mut at = 0usize;
    while at < data.len() {
        let record_at = if compressed { base } else { base + at as u64 };
        let err = |m: String| src.error(FORMAT, record_at, m);
        let truncated = || err("record runs past the end of its chunk".into());
        let hlen = le_u32(data, at).ok_or_else(truncated)? as usize;
        let header = data
            .get(at + 4..(at + 4).saturating_add(hlen))
            .ok_or_else(truncated)?;
        let dat = at + 4 + hlen;
        let dlen = le_u32(data, dat).ok_or_else(truncated)? as usize;
        let body = data
            .get(dat + 4..(dat + 4).saturating_add(dlen))
            .ok_or_else(truncated)?;
        record(header, body, record_at, visit).map_err(|m| match m {
            Failure::Message(m) => err(m),
            Failure::Error(e) => *e,
        })?;
        at = dat + 4 + dlen;
    }
    Ok(())
}

enum Failure {
    Message(String),
    Error(Box<LogError>),
}

impl From<String> for Failure {
    fn from(m: String) -> Self {
        Failure::Message(m)
    }
}

/// One connection or message record (outside or inside a chunk).
fn record(
    header: &[u8],
    body: &[u8],
    record_at: u64,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), Failure> {
    match op_of(header)? {
        OP_CONNECTION => {
            let id = u32_field(header, "conn")?;
            let topic = str_field(header, "topic")?;
            let msg_type = str_field(body, "type")?;
            visit(Item::Connection {
                id,
                topic,
                msg_type,
            })
            .map_err(|e| Failure::Error(Box::new(e)))
        }
        OP_MESSAGE => {
            let conn = u32_field(header, "conn")?;
            visit(Item::Message {
                conn,
                byte_offset: record_at,
                data: body,
            })
            .map_err(|e| Failure::Error(Box::new(e)))
        }
        OP_INDEX | OP_CHUNK_INFO | OP_BAG_HEADER => Ok(()),
        op => Err(format!("unknown record type (op 0x{op:02x})").into()),
    }
}

/// Reads the bag front to back, handing on connections and messages in file order.
///
/// With `topics_only`, a bag whose header points to an index section (`index_pos` ≠ 0: the
/// recording was closed) is read without opening its chunks: the index section repeats
/// every connection record, and each chunk-info record counts the chunk's messages per
/// connection ([`Item::Count`]), so a compressed bag is decompressed once, not twice.
pub(crate) fn scan(
    src: &mut Source<'_>,
    topics_only: bool,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let mut buf = Vec::new();
    src.read_into(
        FORMAT,
        0,
        super::ROS1_MAGIC.len() as u64,
        "the magic line",
        &mut buf,
    )?;
    if buf != super::ROS1_MAGIC {
        return Err(src.error(
            FORMAT,
            0,
            format!(
                "magic line {:?}: only bag format 2.0 (#ROSBAG V2.0) is read (ROS 1 bags of \
                 1.2 and older: migrate them with `rosbag fix`)",
                String::from_utf8_lossy(&buf).trim_end()
            ),
        ));
    }
    let mut header = Vec::new();
    let mut body = Vec::new();
    let mut plain = Vec::new();
    let mut indexed = false;
    while src.remaining() > 0 {
        let record_at = src.pos;
        src.read_into(FORMAT, record_at, 4, "a record's header length", &mut buf)?;
        let hlen = le_u32(&buf, 0).unwrap_or(0);
        src.read_into(
            FORMAT,
            record_at,
            hlen.into(),
            "a record header",
            &mut header,
        )?;
        src.read_into(FORMAT, record_at, 4, "a record's data length", &mut buf)?;
        let dlen = le_u32(&buf, 0).unwrap_or(0);
        let op = op_of(&header).map_err(|m| src.error(FORMAT, record_at, m))?;
        match op {
            OP_CHUNK if topics_only && indexed => {
                src.skip(FORMAT, record_at, dlen.into(), "a chunk")?;
            }
            OP_CHUNK_INFO if topics_only && indexed => {
                src.read_into(FORMAT, record_at, dlen.into(), "a record's data", &mut body)?;
                let err = |m: String| src.error(FORMAT, record_at, format!("chunk info: {m}"));
                let n = u32_field(&header, "count").map_err(err)?;
                for k in 0..n as usize {
                    let pair = body
                        .get(8 * k..8 * k + 8)
                        .ok_or_else(|| err(format!("{n} connections, data of {dlen} bytes")))?;
                    visit(Item::Count {
                        conn: le_u32(pair, 0).unwrap_or(0),
                        messages: le_u32(pair, 4).unwrap_or(0).into(),
                    })?;
                }
            }
            OP_BAG_HEADER => {
                if let Ok(Some(pos)) = field(&header, b"index_pos") {
                    indexed = pos.len() == 8 && pos.iter().any(|&b| b != 0);
                }
                src.skip(FORMAT, record_at, dlen.into(), "a record's data")?;
            }
            OP_CHUNK => {
                let chunk_err = |src: &Source<'_>, m: String| {
                    src.error(FORMAT, record_at, format!("chunk: {m}"))
                };
                let codec = str_field(&header, "compression")
                    .and_then(|c| Codec::of(c, &[Codec::Bz2, Codec::Lz4]))
                    .map_err(|m| chunk_err(src, m))?;
                let data_at = src.pos;
                src.read_into(FORMAT, record_at, dlen.into(), "a chunk", &mut body)?;
                match codec {
                    None => records_in_chunk(src, &body, data_at, false, visit)?,
                    Some(codec) => {
                        let size = u32_field(&header, "size").map_err(|m| chunk_err(src, m))?;
                        compress::decompress(codec, &body, Some(size.into()), &mut plain)
                            .map_err(|m| chunk_err(src, m))?;
                        records_in_chunk(src, &plain, record_at, true, visit)?;
                    }
                }
            }
            OP_CONNECTION | OP_MESSAGE => {
                src.read_into(FORMAT, record_at, dlen.into(), "a record's data", &mut body)?;
                record(&header, &body, record_at, visit).map_err(|m| match m {
                    Failure::Message(m) => src.error(FORMAT, record_at, m),
                    Failure::Error(e) => *e,
                })?;
            }
            OP_INDEX | OP_CHUNK_INFO => {
                src.skip(FORMAT, record_at, dlen.into(), "a record's data")?;
            }
            op => {
                return Err(src.error(
                    FORMAT,
                    record_at,
                    format!("unknown record type (op 0x{op:02x})"),
                ));
            }
        }
    }
    Ok(())
}

//! MCAP (specification at mcap.dev, "Format"): after the 8-byte magic, records of
//! `u8 opcode, u64 length, content`, little-endian, strings and byte arrays with a `u32`
//! length prefix. Schemas (0x03) name the message type, channels (0x04) the topic; messages
//! (0x05) sit in the data section directly or inside chunks (0x06). The summary section
//! repeats schemas and channels.

use super::compress::{self, Codec};
use super::{Item, Source, le_u16, le_u32, le_u64};
use crate::io::error::LogError;

const FORMAT: &str = "MCAP";

const OP_FOOTER: u8 = 0x02;
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;

/// A `u32`-prefixed string at `at`: (the string, the offset after it).
fn string_at(b: &[u8], at: usize) -> Result<(&str, usize), String> {
    let len = le_u32(b, at).ok_or("string length cut off")? as usize;
    let s = b
        .get(at + 4..(at + 4).saturating_add(len))
        .ok_or_else(|| format!("string of {len} bytes runs past its record"))?;
    let s = std::str::from_utf8(s).map_err(|_| "string is not UTF-8".to_owned())?;
    Ok((s, at + 4 + len))
}

/// The schemas seen: (id, type name).
#[derive(Default)]
struct Schemas(Vec<(u16, String)>);

/// One record's content: schemas are kept, channels and messages handed on.
fn record(
    op: u8,
    content: &[u8],
    record_at: u64,
    schemas: &mut Schemas,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<Result<(), LogError>, String> {
    match op {
        OP_SCHEMA => {
            let id = le_u16(content, 0).ok_or("schema id cut off")?;
            let (name, _) = string_at(content, 2)?;
            if !schemas.0.iter().any(|(i, _)| *i == id) {
                schemas.0.push((id, name.to_owned()));
            }
            Ok(Ok(()))
        }
        OP_CHANNEL => {
            let id = le_u16(content, 0).ok_or("channel id cut off")?;
            let schema = le_u16(content, 2).ok_or("channel schema id cut off")?;
            let (topic, next) = string_at(content, 4)?;
            let (encoding, _) = string_at(content, next)?;
            let ty = schemas
                .0
                .iter()
                .find(|(i, _)| *i == schema)
                .map_or("(no schema)", |(_, n)| n.as_str());
            // Only CDR is decoded: another encoding makes the type one that is not read.
            let msg_type = if encoding == "cdr" {
                ty.to_owned()
            } else {
                format!("{ty} in {encoding} encoding")
            };
            Ok(visit(Item::Connection {
                id: id.into(),
                topic,
                msg_type: &msg_type,
            }))
        }
        OP_MESSAGE => {
            let conn = le_u16(content, 0).ok_or("message channel id cut off")?;
            let data = content.get(22..).ok_or("message header cut off")?;
            Ok(visit(Item::Message {
                conn: conn.into(),
                byte_offset: record_at,
                data,
            }))
        }
        _ => Ok(Ok(())),
    }
}

/// The records of a chunk's `records`, which start at file offset `base`; for a
/// decompressed chunk (`compressed`), `base` is the chunk record's offset and every record
/// inside is reported there.
fn records_in_chunk(
    src: &Source<'_>,
    data: &[u8],
    base: u64,
    compressed: bool,
    schemas: &mut Schemas,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let mut at = 0usize;
    while at < data.len() {
        let record_at = if compressed { base } else { base + at as u64 };
        let err = |m: String| src.error(FORMAT, record_at, m);
        let op = data[at];
        let len = le_u64(data, at + 1)
            .and_then(|l| usize::try_from(l).ok())
            .ok_or_else(|| err("record length cut off at the end of its chunk".into()))?;
        let content = data
            .get(at + 9..(at + 9).saturating_add(len))
            .ok_or_else(|| {
                err(format!(
                    "record of {len} bytes runs past the end of its chunk"
                ))
            })?;
        record(op, content, record_at, schemas, visit).map_err(err)??;
        at += 9 + len;
    }
    Ok(())
}

/// Reads the file front to back, handing on channels and messages in file order.
pub(crate) fn scan(
    src: &mut Source<'_>,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let mut buf = Vec::new();
    src.read_into(FORMAT, 0, 8, "the magic", &mut buf)?;
    if buf != super::MCAP_MAGIC {
        return Err(src.error(FORMAT, 0, "bad magic: not an MCAP file".into()));
    }
    let mut schemas = Schemas::default();
    let mut content = Vec::new();
    let mut plain = Vec::new();
    loop {
        let record_at = src.pos;
        if src.remaining() == 0 {
            return Err(src.error(
                FORMAT,
                record_at,
                "truncated: the file ends before its footer (an interrupted recording?)".into(),
            ));
        }
        src.read_into(
            FORMAT,
            record_at,
            9,
            "a record's opcode and length",
            &mut buf,
        )?;
        let op = buf[0];
        let len = le_u64(&buf, 1).unwrap_or(0);
        let err = |src: &Source<'_>, m: String| src.error(FORMAT, record_at, m);
        match op {
            OP_FOOTER => {
                src.skip(FORMAT, record_at, len, "the footer")?;
                let end_at = src.pos;
                src.read_into(FORMAT, end_at, 8, "the closing magic", &mut buf)?;
                if buf != super::MCAP_MAGIC {
                    return Err(err(src, "no closing magic after the footer".into()));
                }
                return Ok(());
            }
            OP_SCHEMA | OP_CHANNEL | OP_MESSAGE => {
                src.read_into(FORMAT, record_at, len, "a record", &mut content)?;
                record(op, &content, record_at, &mut schemas, visit).map_err(|m| err(src, m))??;
            }
            OP_CHUNK => {
                src.read_into(FORMAT, record_at, len, "a chunk", &mut content)?;
                let content_at = record_at + 9;
                let (compression, next) =
                    string_at(&content, 28).map_err(|m| err(src, format!("chunk: {m}")))?;
                let codec = Codec::of(compression, &[Codec::Zstd, Codec::Lz4])
                    .map_err(|m| err(src, format!("chunk: {m}")))?;
                let n = le_u64(&content, next)
                    .and_then(|l| usize::try_from(l).ok())
                    .ok_or_else(|| err(src, "chunk records length cut off".into()))?;
                let records = content
                    .get(next + 8..(next + 8).saturating_add(n))
                    .ok_or_else(|| {
                        err(
                            src,
                            format!("chunk records of {n} bytes run past the chunk"),
                        )
                    })?;
                match codec {
                    None => records_in_chunk(
                        src,
                        records,
                        content_at + (next + 8) as u64,
                        false,
                        &mut schemas,
                        visit,
                    )?,
                    Some(codec) => {
                        // Chunk: message_start_time u64, message_end_time u64,
                        // uncompressed_size u64, uncompressed_crc u32, compression, records.
                        let size = le_u64(&content, 16).unwrap_or(0);
                        compress::decompress(codec, records, Some(size), &mut plain)
                            .map_err(|m| err(src, format!("chunk: {m}")))?;
                        records_in_chunk(src, &plain, record_at, true, &mut schemas, visit)?;
                    }
                }
            }
            _ => src.skip(FORMAT, record_at, len, "a record")?,
        }
    }
}

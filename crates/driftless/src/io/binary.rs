//! `DRIFTLOG`: a compact, column-major binary format for big IMU logs.
//!
//! Layout (all integers little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 0..8 | magic `DRIFTLOG` |
//! | 8..12 | format version, `u32` (= `VERSION`) |
//! | 12..16 | header length `H`, `u32` (≤ 1 MiB) |
//! | 16..16+H | header: UTF-8 TOML (`source`, `rows`, `tau0_s`, `time_column`, `encoding = "f64le"`, `segments`, `[[gaps]]`, `[[channels]]` with `name`, `quantity`, `source_unit`) |
//! | … | zero padding to a multiple of 8 bytes |
//! | … | columns, one after the other: the time column (if `time_column`), then each channel; each `rows` little-endian IEEE-754 f64 |
//!
//! The file ends right after the last column; anything else is an error.
//!
//! Why f64: the values are already converted to SI and the analysis accumulates in f64;
//! f32 would lose digits that matter (an OCXO at 10 MHz needs 17 significant digits, time
//! stamps of an 18 h log at 100 Hz need more than f32's 24 bits), and raw integer counts
//! would push unit conversion into every consumer. f64 is lossless for everything the text
//! reader produces, so text → binary → text round-trips bit for bit.

use std::io::{Read, Write};
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::{Location, LogError, excerpt};
use super::log::{Channel, ImuLog, Quantity, TimeGap};

/// The 8 magic bytes every binary log starts with.
pub const MAGIC: &[u8; 8] = b"DRIFTLOG";
/// The format version this build writes and reads.
pub(crate) const VERSION: u32 = 1;
/// Largest header accepted, bytes.
const MAX_HEADER: u32 = 1 << 20;
/// Bytes converted per read/write call.
const IO_BLOCK: usize = 1 << 20;

#[derive(Serialize, Deserialize)]
struct Header {
    source: String,
    rows: usize,
    tau0_s: f64,
    time_column: bool,
    encoding: String,
    #[serde(default)]
    segments: Vec<[usize; 2]>,
    #[serde(default)]
    gaps: Vec<GapHeader>,
    channels: Vec<ChannelHeader>,
}

#[derive(Serialize, Deserialize)]
struct GapHeader {
    index: usize,
    start_s: f64,
    duration_s: f64,
}

#[derive(Serialize, Deserialize)]
struct ChannelHeader {
    name: String,
    quantity: Quantity,
    source_unit: String,
}

/// Writes `log` as a binary log to a file.
pub fn write_binary_file(log: &ImuLog, path: impl AsRef<Path>) -> Result<(), LogError> {
    let (mut file, name) = super::error::create_file(path.as_ref())?;
    write_impl(log, &mut file, &name)?;
    super::error::commit_file(file, &name)
}

/// Writes `log` as a binary log to any writer (errors name the output `<output>`).
pub fn write_binary<W: Write>(log: &ImuLog, writer: W) -> Result<(), LogError> {
    write_impl(log, writer, "<output>")
}

/// Checks that a log is consistent enough to be written.
pub(crate) fn check_log(log: &ImuLog, dest: &str) -> Result<(), LogError> {
    let bad = |message: String| {
        Err(LogError::InvalidLog {
            at: Location::input(dest),
            message,
        })
    };
    let n = log.len();
    if log.channels.is_empty() {
        return bad("no channels".into());
    }
    if let Some(c) = log.channels.iter().find(|c| c.values.len() != n) {
        return bad(format!(
            "channel {} has {} samples, expected {n}",
            c.name,
            c.values.len()
        ));
    }
    if let Some(t) = &log.time_s
        && t.len() != n
    {
        return bad(format!("time column has {} samples, expected {n}", t.len()));
    }
    if !(log.tau0_s.is_finite() && log.tau0_s > 0.0) {
        return bad(format!(
            "tau0_s must be positive and finite, got {}",
            log.tau0_s
        ));
    }
    let cols = log
        .time_s
        .iter()
        .map(|t| ("time", t))
        .chain(log.channels.iter().map(|c| (c.name.as_str(), &c.values)));
    for (name, v) in cols {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return bad(format!("non-finite value in column {name}, row {i}"));
        }
    }
    Ok(())
}

fn write_impl<W: Write>(log: &ImuLog, mut w: W, dest: &str) -> Result<(), LogError> {
    check_log(log, dest)?;
    let io = |error| LogError::Io {
        path: dest.to_owned(),
        error,
    };
    let header = Header {
        source: log.source.clone(),
        rows: log.len(),
        tau0_s: log.tau0_s,
        time_column: log.time_s.is_some(),
        encoding: "f64le".into(),
        segments: log.segments.iter().map(|r| [r.start, r.end]).collect(),
        gaps: log
            .gaps
            .iter()
            .map(|g| GapHeader {
                index: g.index,
                start_s: g.start_s,
                duration_s: g.duration_s,
            })
            .collect(),
        channels: log
            .channels
            .iter()
            .map(|c| ChannelHeader {
                name: c.name.clone(),
                quantity: c.quantity,
                source_unit: c.source_unit.clone(),
            })
            .collect(),
    };
    let text = toml::to_string(&header).map_err(|e| LogError::InvalidLog {
        at: Location::input(dest),
        message: format!("header: {e}"),
    })?;
    let hlen = u32::try_from(text.len())
        .ok()
        .filter(|&l| l <= MAX_HEADER)
        .ok_or_else(|| LogError::InvalidLog {
            at: Location::input(dest),
            message: "header longer than 1 MiB".into(),
        })?;
    let mut pre = Vec::with_capacity(16 + text.len() + 8);
    pre.extend_from_slice(MAGIC);
    pre.extend_from_slice(&VERSION.to_le_bytes());
    pre.extend_from_slice(&hlen.to_le_bytes());
    pre.extend_from_slice(text.as_bytes());
    pre.resize(pre.len().next_multiple_of(8), 0);
    w.write_all(&pre).map_err(io)?;
    let mut block = Vec::with_capacity(IO_BLOCK);
    let cols = log
        .time_s
        .iter()
        .chain(log.channels.iter().map(|c| &c.values));
    for col in cols {
        for part in col.chunks(IO_BLOCK / 8) {
            block.clear();
            for v in part {
                block.extend_from_slice(&v.to_le_bytes());
            }
            w.write_all(&block).map_err(io)?;
        }
    }
    w.flush().map_err(io)
}

/// Reads a binary log from a file. The file size is checked against the header before any
/// data is read.
pub fn read_binary_file(path: impl AsRef<Path>) -> Result<ImuLog, LogError> {
    let (file, size, name) = super::error::open_file(path.as_ref())?;
    read_impl(&file, &name, size, Some(&file))
}

/// Reads a binary log from `reader`, positioned at the magic; `size` (a regular file's
/// length) is checked against the header, and with `file` the columns are then read at
/// their offsets in parallel.
pub(crate) fn read_binary_parts<R: Read>(
    reader: R,
    source: &str,
    size: Option<u64>,
    file: Option<&std::fs::File>,
) -> Result<ImuLog, LogError> {
    read_impl(reader, source, size, file)
}

/// Reads a binary log from any reader; `source` names it in errors.
pub fn read_binary<R: Read>(reader: R, source: &str) -> Result<ImuLog, LogError> {
    read_impl(reader, source, None, None)
}

fn read_full<R: Read>(r: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Converts little-endian bytes to f64s, appending to `v`; false if any is non-finite.
#[inline]
fn decode_into(bytes: &[u8], v: &mut Vec<f64>) -> bool {
    let (chunks, _) = bytes.as_chunks::<8>();
    let start = v.len();
    v.extend(chunks.iter().map(|c| f64::from_le_bytes(*c)));
    v[start..].iter().fold(true, |ok, x| ok & x.is_finite())
}

/// Reads one column at a known file offset with positioned reads (no shared cursor, so
/// columns can be read in parallel).
#[cfg(unix)]
fn read_column_at(
    file: &std::fs::File,
    offset: u64,
    rows: usize,
    name: &str,
    source: &str,
) -> Result<Vec<f64>, LogError> {
    use std::os::unix::fs::FileExt;
    let at = || Location::input(source);
    let mut v: Vec<f64> = Vec::with_capacity(rows);
    let mut block = vec![0u8; IO_BLOCK];
    let mut finite = true;
    while v.len() < rows {
        let want = ((rows - v.len()) * 8).min(IO_BLOCK);
        let buf = &mut block[..want];
        file.read_exact_at(buf, offset + v.len() as u64 * 8)
            .map_err(|error| match error.kind() {
                std::io::ErrorKind::UnexpectedEof => LogError::Truncated {
                    at: at(),
                    message: format!("column {name} ends before row {rows}"),
                },
                _ => LogError::Io {
                    path: source.to_owned(),
                    error,
                },
            })?;
        finite &= decode_into(buf, &mut v);
    }
    if !finite {
        let row = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
        return Err(LogError::NonFiniteStored {
            at: at(),
            column: name.to_owned(),
            row,
        });
    }
    Ok(v)
}

fn read_impl<R: Read>(
    mut r: R,
    source: &str,
    size: Option<u64>,
    file: Option<&std::fs::File>,
) -> Result<ImuLog, LogError> {
    let at = || Location::input(source);

    let (h, padded) = read_header(&mut r, source)?;
    let ncols = h.channels.len() + usize::from(h.time_column);
    let data_bytes = (h.rows as u64)
        .checked_mul(ncols as u64)
        .and_then(|x| x.checked_mul(8))
        .ok_or_else(|| LogError::BadHeader {
            at: at(),
            message: format!("row count {} too large", h.rows),
        })?;
    let data_start = 16 + padded as u64;
    if let Some(size) = size {
        let found = size.saturating_sub(data_start);
        if found != data_bytes {
            return Err(LogError::CountMismatch {
                at: at(),
                rows: h.rows,
                columns: ncols,
                expected_bytes: data_bytes,
                found_bytes: found,
            });
        }
    }
    check_segments_and_gaps(&h, source)?;

    let names: Vec<&str> = h
        .time_column
        .then_some("time")
        .into_iter()
        .chain(h.channels.iter().map(|c| c.name.as_str()))
        .collect();
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(ncols);
    #[cfg(unix)]
    if let (Some(file), Some(_)) = (file, size) {
        // Size already checked against the header: read the columns in parallel.
        use rayon::prelude::*;
        let col_bytes = h.rows as u64 * 8;
        columns = names
            .par_iter()
            .enumerate()
            .map(|(i, name)| {
                read_column_at(
                    file,
                    data_start + i as u64 * col_bytes,
                    h.rows,
                    name,
                    source,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
    }
    #[cfg(not(unix))]
    let _ = file;
    if columns.is_empty() {
        columns = read_columns(&mut r, &names, &h, size.is_some(), data_bytes, source)?;
    }
    let mut it = columns.into_iter();
    let time_s = if h.time_column { it.next() } else { None };
    if let Some(t) = &time_s
        && let Some(i) = t.windows(2).position(|w| w[1] <= w[0])
    {
        return Err(LogError::Corrupt {
            at: at(),
            message: format!("time column not strictly increasing at row {}", i + 1),
        });
    }
    if let Some(t) = &time_s {
        super::timing::check_one_rate(t, 1.5 * h.tau0_s, source)?;
    }
    let channels = h
        .channels
        .into_iter()
        .zip(it)
        .map(|(c, values)| Channel {
            name: c.name,
            quantity: c.quantity,
            source_unit: c.source_unit,
            values,
        })
        .collect();
    let segments = if h.segments.is_empty() && h.rows > 0 {
        std::iter::once(0..h.rows).collect()
    } else {
        h.segments.iter().map(|s| s[0]..s[1]).collect()
    };
    Ok(ImuLog {
        source: h.source,
        time_s,
        tau0_s: h.tau0_s,
        channels,
        segments,
        gaps: h
            .gaps
            .into_iter()
            .map(|g| TimeGap {
                index: g.index,
                start_s: g.start_s,
                duration_s: g.duration_s,
            })
            .collect(),
        ..ImuLog::default()
    })
}

/// The preamble (magic, version, header length) and the TOML header, checked; returns the
/// header and its length padded to 8 bytes.
fn read_header<R: Read>(r: &mut R, source: &str) -> Result<(Header, usize), LogError> {
    let at = || Location::input(source);
    let io = |error| LogError::Io {
        path: source.to_owned(),
        error,
    };
    let truncated = |message: String| LogError::Truncated { at: at(), message };
    let bad_header = |message: String| LogError::BadHeader { at: at(), message };
    let mut pre = [0u8; 16];
    let got = read_full(r, &mut pre).map_err(io)?;
    if got < 8 || pre[..8] != MAGIC[..] {
        return Err(LogError::BadMagic {
            at: at(),
            found: excerpt(&pre[..got.min(8)]),
        });
    }
    if got < 16 {
        return Err(truncated(format!(
            "file ends inside the 16-byte preamble (after {got} bytes)"
        )));
    }
    let word = |i: usize| u32::from_le_bytes([pre[i], pre[i + 1], pre[i + 2], pre[i + 3]]);
    let version = word(8);
    if version != VERSION {
        return Err(LogError::UnsupportedVersion {
            at: at(),
            version,
            supported: VERSION,
        });
    }
    let hlen = word(12);
    if hlen > MAX_HEADER {
        return Err(bad_header(format!(
            "header length {hlen} bytes exceeds 1 MiB"
        )));
    }
    let padded = (16 + hlen as usize).next_multiple_of(8) - 16;
    let mut htext = vec![0u8; padded];
    let got = read_full(r, &mut htext).map_err(io)?;
    if got < padded {
        return Err(truncated(format!(
            "file ends inside the {hlen}-byte header"
        )));
    }
    let htext = htext.get(..hlen as usize).unwrap_or(&[]);
    let htext = std::str::from_utf8(htext).map_err(|e| bad_header(format!("not UTF-8: {e}")))?;
    let h: Header = toml::from_str(htext).map_err(|e| bad_header(e.message().to_owned()))?;
    if h.encoding != "f64le" {
        return Err(bad_header(format!(
            "unsupported encoding {:?} (expected \"f64le\")",
            h.encoding
        )));
    }
    if h.channels.is_empty() {
        return Err(bad_header("no channels".into()));
    }
    if !(h.tau0_s.is_finite() && h.tau0_s > 0.0) {
        return Err(bad_header(format!(
            "tau0_s must be positive and finite, got {}",
            h.tau0_s
        )));
    }
    Ok((h, padded))
}

/// Segments in order within the rows, gaps inside them.
fn check_segments_and_gaps(h: &Header, source: &str) -> Result<(), LogError> {
    let bad_header = |message: String| LogError::BadHeader {
        at: Location::input(source),
        message,
    };
    let mut prev_end = 0;
    for s in &h.segments {
        if !(s[0] < s[1] && s[1] <= h.rows && s[0] >= prev_end) {
            return Err(bad_header(format!(
                "segment {}..{} out of order or beyond {} rows",
                s[0], s[1], h.rows
            )));
        }
        prev_end = s[1];
    }
    if let Some(g) = h.gaps.iter().find(|g| g.index == 0 || g.index >= h.rows) {
        return Err(bad_header(format!(
            "gap at row {} outside 1..{}",
            g.index, h.rows
        )));
    }
    Ok(())
}

/// The columns read one after the other from a stream, each checked to be finite, and
/// nothing after the last. `size_known`: the file size confirmed the row count (which then
/// sizes the columns up front).
fn read_columns<R: Read>(
    r: &mut R,
    names: &[&str],
    h: &Header,
    size_known: bool,
    data_bytes: u64,
    source: &str,
) -> Result<Vec<Vec<f64>>, LogError> {
    let at = || Location::input(source);
    let io = |error| LogError::Io {
        path: source.to_owned(),
        error,
    };
    let truncated = |message: String| LogError::Truncated { at: at(), message };
    let ncols = names.len();
    let mut columns = Vec::with_capacity(ncols);
    let mut block = vec![0u8; IO_BLOCK];
    for name in names {
        // Trust the row count for capacity only when the file size confirmed it.
        let cap = if size_known {
            h.rows
        } else {
            h.rows.min(1 << 20)
        };
        let mut v: Vec<f64> = Vec::with_capacity(cap);
        let mut finite = true;
        while v.len() < h.rows {
            let want = ((h.rows - v.len()) * 8).min(IO_BLOCK);
            let buf = &mut block[..want];
            let got = read_full(r, buf).map_err(io)?;
            if got < want {
                return Err(truncated(format!(
                    "column {name} ends after {} of {} rows",
                    v.len() + got / 8,
                    h.rows
                )));
            }
            finite &= decode_into(buf, &mut v);
        }
        if !finite {
            let row = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(LogError::NonFiniteStored {
                at: at(),
                column: (*name).to_owned(),
                row,
            });
        }
        columns.push(v);
    }
    let mut extra = [0u8; 1];
    if read_full(r, &mut extra).map_err(io)? > 0 {
        let rest = std::io::copy(r, &mut std::io::sink()).map_err(io)?;
        return Err(LogError::CountMismatch {
            at: at(),
            rows: h.rows,
            columns: ncols,
            expected_bytes: data_bytes,
            found_bytes: data_bytes + 1 + rest,
        });
    }
    Ok(columns)
}

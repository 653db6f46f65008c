//! One opened input, read once: the format is sniffed from the first bytes of the very
//! handle that is then parsed, so pipes, FIFOs, `/dev/stdin` and gzip streams give the
//! same log as the same bytes in a regular file (opening a path twice loses the sniffed
//! bytes of a pipe, and blocks on a FIFO whose writer has gone).
//!
//! Also here: [`read_config_text`], the one way configuration and model files (TOML, YAML,
//! JSON) are read whole, under a size cap, so that a wrong path (a log, `/dev/zero`) ends
//! in an error instead of filling the memory.

use std::io::{Cursor, Read};
use std::path::Path;

use super::error::{Location, LogError};
use super::log::ImuLog;
use super::text::TextOptions;

/// Bytes sniffed at the start of an input: enough for every magic recognised here.
const HEAD_BYTES: usize = 8;

/// What an input holds, by its first bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputFormat {
    /// Delimited text (anything without a known magic).
    Text,
    /// A driftless `DRIFTLOG` binary log.
    Binary,
    /// A gzip stream (decompressed, then sniffed again).
    Gzip,
    /// A PX4 ULog log (feature `autopilot-logs`).
    ULog,
    /// An ArduPilot DataFlash log (feature `autopilot-logs`).
    DataFlash,
    /// A ROS 1 bag, an MCAP file or a ROS 2 sqlite3 bag ([`super::rosbag`]).
    RosBag(super::rosbag::BagFormat),
}

/// An input file opened once, its first bytes already read. Every reader takes the bytes
/// from here: the sniffed head, then the rest of the same handle.
#[derive(Debug)]
pub struct LogInput {
    name: String,
    head: Vec<u8>,
    file: std::fs::File,
    /// Size in bytes when the input is a regular file (pipes, FIFOs and devices have none).
    size: Option<u64>,
    /// The ROS 2 bag folder the input was opened from (its first storage file is `file`).
    folder: Option<super::rosbag::Ros2BagFolder>,
}

impl LogInput {
    /// Opens `path` and reads its first bytes. Errors name the file.
    pub fn open(path: impl AsRef<Path>) -> Result<LogInput, LogError> {
        let mut path = path.as_ref();
        // A ROS 2 bag is a folder: its metadata.yaml and its storage files.
        let folder = if path.is_dir() {
            super::rosbag::ros2_bag_folder(path)?
        } else {
            None
        };
        if let Some(p) = folder.as_ref().and_then(|f| f.storage.first()) {
            path = p;
        }
        let name = path.display().to_string();
        let io = |error| LogError::Io {
            path: name.clone(),
            error,
        };
        let mut file = std::fs::File::open(path).map_err(io)?;
        let meta = file.metadata().map_err(io)?;
        let size = meta.is_file().then_some(meta.len());
        let mut head = Vec::with_capacity(HEAD_BYTES);
        (&mut file)
            .take(HEAD_BYTES as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        Ok(LogInput {
            name,
            head,
            file,
            size,
            folder,
        })
    }

    /// The input's display name (its path).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The format its first bytes show.
    pub fn format(&self) -> InputFormat {
        sniff(&self.head)
    }

    /// Whether the input is a regular file (has a size and can be read at offsets).
    pub fn is_regular_file(&self) -> bool {
        self.size.is_some()
    }

    /// Reads the input as one log: `DRIFTLOG` binary (`opts` ignored), gzip (decompressed,
    /// then read as binary or text by the decompressed bytes), or delimited text. An
    /// autopilot log holds one log per IMU and is refused here with a message saying so
    /// ([`Self::read_autopilot`] reads it).
    pub fn read_log(self, opts: &TextOptions) -> Result<ImuLog, LogError> {
        match self.format() {
            InputFormat::Binary => {
                let stream = Cursor::new(self.head).chain(&self.file);
                super::binary::read_binary_parts(stream, &self.name, self.size, Some(&self.file))
            }
            InputFormat::Gzip => {
                let stream = Cursor::new(self.head).chain(self.file);
                read_gzip(stream, &self.name, opts)
            }
            InputFormat::RosBag(_) => self.read_rosbag(None),
            f @ (InputFormat::ULog | InputFormat::DataFlash) => Err(LogError::InvalidOptions {
                at: Location::input(&self.name),
                message: format!(
                    "a {} log holds one log per IMU; read it with the autopilot reader \
                     (`io::imu_logs_from_autopilot_file`, or the CLI's `--instance N`)",
                    match f {
                        InputFormat::ULog => "PX4 ULog",
                        _ => "ArduPilot DataFlash",
                    }
                ),
            }),
            InputFormat::Text => {
                let stream = Cursor::new(self.head).chain(self.file);
                super::text::read_text_sized(stream, &self.name, opts, self.size)
            }
        }
    }

    /// Reads the whole input into memory (the autopilot parsers need random access):
    /// the sniffed head, then the rest of the same handle.
    pub fn read_all(mut self) -> Result<Vec<u8>, LogError> {
        let mut bytes = self.head;
        if let Some(size) = self.size {
            bytes.reserve(
                usize::try_from(size)
                    .unwrap_or(0)
                    .saturating_sub(bytes.len()),
            );
        }
        self.file
            .read_to_end(&mut bytes)
            .map_err(|error| LogError::Io {
                path: self.name.clone(),
                error,
            })?;
        Ok(bytes)
    }

    /// Whether the input is a ROS bag, MCAP file or sqlite3 bag (by its magic bytes).
    pub fn is_rosbag(&self) -> bool {
        matches!(self.format(), InputFormat::RosBag(_))
    }

    /// Reads the IMU topic `topic` of a ROS bag, MCAP file, sqlite3 bag or ROS 2 bag folder
    /// (without one, its only IMU topic); see [`super::rosbag`].
    pub fn read_rosbag(self, topic: Option<&str>) -> Result<ImuLog, LogError> {
        super::rosbag::read_rosbag_parts(self.file, &self.name, self.folder.as_ref(), topic)
    }

    /// Whether the input is a PX4 ULog or ArduPilot DataFlash log (by its magic bytes).
    pub fn is_autopilot(&self) -> bool {
        matches!(self.format(), InputFormat::ULog | InputFormat::DataFlash)
    }

    /// Reads every IMU of a PX4 ULog / ArduPilot DataFlash log; an input that is not one
    /// (see [`Self::is_autopilot`]) is an error saying so.
    #[cfg(feature = "autopilot-logs")]
    pub fn read_autopilot(self) -> Result<super::AutopilotImuLogs, LogError> {
        let name = self.name.clone();
        if !self.is_autopilot() {
            return Err(LogError::InvalidOptions {
                at: Location::input(&name),
                message: "not a PX4 ULog or ArduPilot DataFlash log (no magic bytes)".into(),
            });
        }
        let bytes = self.read_all()?;
        super::autopilot::imu_logs_from_autopilot(&bytes, &name)?.ok_or_else(|| {
            LogError::InvalidOptions {
                at: Location::input(&name),
                message: "not a PX4 ULog or ArduPilot DataFlash log (no magic bytes)".into(),
            }
        })
    }
}

/// The format shown by the first bytes of an input.
fn sniff(head: &[u8]) -> InputFormat {
    if head.starts_with(&super::GZIP_MAGIC) {
        return InputFormat::Gzip;
    }
    if head == super::binary::MAGIC {
        return InputFormat::Binary;
    }
    if let Some(f) = super::rosbag::detect_format(head) {
        return InputFormat::RosBag(f);
    }
    #[cfg(feature = "autopilot-logs")]
    match super::autopilot::detect_format(head) {
        Some(super::AutopilotFormat::ULog) => return InputFormat::ULog,
        Some(super::AutopilotFormat::DataFlash) => return InputFormat::DataFlash,
        None => {}
    }
    InputFormat::Text
}

/// Reads a gzip stream (every member, as `gzip -dc` does), choosing binary or text by the
/// decompressed bytes. A corrupt or truncated stream is an error naming the input, never a
/// shorter log.
fn read_gzip<R: Read>(stream: R, name: &str, opts: &TextOptions) -> Result<ImuLog, LogError> {
    let mut gz =
        flate2::read::MultiGzDecoder::new(std::io::BufReader::with_capacity(1 << 20, stream));
    let mut head = Vec::with_capacity(HEAD_BYTES);
    (&mut gz)
        .take(HEAD_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(|error| LogError::Io {
            path: name.to_owned(),
            error,
        })?;
    let is_binary = head.as_slice() == super::binary::MAGIC;
    let stream = Cursor::new(head).chain(gz);
    if is_binary {
        super::binary::read_binary(stream, name)
    } else {
        super::text::read_text(stream, name, opts)
    }
}

/// Bytes at the start of a text input checked for binary data.
pub(crate) const SNIFF_BYTES: usize = 64 << 10;

/// Whether a byte cannot occur in a text log: a C0 control other than the white space
/// (tab, line feed, vertical tab, form feed, carriage return), SUB (a DOS end of file) and
/// ESC (terminal colours). NUL is the common one: every binary format is full of them.
#[inline]
fn is_binary_byte(b: u8) -> bool {
    b < 0x20 && !matches!(b, b'\t' | b'\n' | 0x0b | 0x0c | b'\r' | 0x1a | 0x1b)
}

/// The first sign that `bytes` are binary data, not text: (offset, what). A byte of
/// [`is_binary_byte`], or more than one byte in eight (and at least 16) not UTF-8 — a few
/// Latin-1 degree signs in a header stay text.
fn binary_evidence(bytes: &[u8]) -> Option<(usize, String)> {
    if let Some(i) = bytes.iter().position(|&b| is_binary_byte(b)) {
        let what = match bytes[i] {
            0 => "a NUL byte".to_owned(),
            b => format!("control byte 0x{b:02x}"),
        };
        return Some((i, what));
    }
    let (mut bad, mut first, mut pos) = (0usize, None, 0usize);
    for chunk in bytes.utf8_chunks() {
        pos += chunk.valid().len();
        let n = chunk.invalid().len();
        if n > 0 {
            first.get_or_insert(pos);
            bad += n;
        }
        pos += n;
    }
    match first {
        Some(i) if bad >= 16 && bad * 8 > bytes.len() => Some((
            i,
            format!("{bad} of the first {} bytes are not UTF-8", bytes.len()),
        )),
        _ => None,
    }
}

/// [`LogError::BinaryData`] when `bytes` (at byte `offset` of the input) show binary data.
pub(crate) fn binary_error(bytes: &[u8], offset: u64, source: &str) -> Option<LogError> {
    binary_evidence(bytes).map(|(i, what)| LogError::BinaryData {
        path: source.to_owned(),
        byte_offset: offset + i as u64,
        what,
    })
}

/// Largest configuration or model file (TOML, YAML, JSON) read: 16 MiB. Real ones are a
/// few KiB; the cap keeps a wrong path (a log, `/dev/zero`) from filling the memory.
pub const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// Reads a configuration or model file whole as UTF-8 text, refusing one larger than
/// `max_bytes` (reading stops there), one with a NUL byte (binary data) and one that is not
/// UTF-8. The refusals are [`std::io::ErrorKind::InvalidData`] errors whose message says
/// which and, for the size, the cap; callers put the file's name in front.
pub fn read_config_text(path: impl AsRef<Path>, max_bytes: u64) -> std::io::Result<String> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidData, m);
    let f = std::fs::File::open(path)?;
    let mut bytes = Vec::new();
    f.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(invalid(format!(
            "larger than {} ({max_bytes} bytes), the limit for a configuration or model file: \
             binary data or a log given by mistake?",
            human_bytes(max_bytes)
        )));
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(invalid(format!(
            "binary data (a NUL byte at byte offset {at}), not a text configuration or model file"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        invalid(format!(
            "not UTF-8 text (first bad byte at byte offset {}): not a configuration or model file",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// `n` bytes as `16 MiB`, `1 KiB` or `123 bytes` (for messages).
pub(crate) fn human_bytes(n: u64) -> String {
    if n >= 1 << 20 && n.is_multiple_of(1 << 20) {
        format!("{} MiB", n >> 20)
    } else if n >= 1 << 10 && n.is_multiple_of(1 << 10) {
        format!("{} KiB", n >> 10)
    } else {
        format!("{n} bytes")
    }
}

/// Longest line a whole-file text reader ([`read_text_input`]) accepts: 1 MiB, the
/// default of [`TextOptions::max_line_bytes`].
pub(crate) const MAX_TEXT_LINE_BYTES: usize = 1 << 20;

/// Block read at a time by [`read_text_input`] from a pipe or device.
const TEXT_BLOCK_BYTES: usize = 1 << 20;

/// Reads a whole text input (the KF-GINS and RTKLIB readers parse from memory) with the
/// checks that keep a wrong input from filling the memory: binary data in the first
/// [`SNIFF_BYTES`] is [`LogError::BinaryData`], and a first line longer than
/// [`MAX_TEXT_LINE_BYTES`] is [`LogError::LineTooLong`]. A regular file is then read whole
/// by `read_regular` (its size is known and its bytes are kept as rows; the parsers check
/// the later lines). A pipe, FIFO or device is read through the same handle, block by
/// block, each block checked for NUL bytes and over-long lines, so `/dev/zero` or an
/// endless stream without line ends fails within the first MiB instead of growing
/// without bound.
pub(crate) fn read_text_input(
    path: &Path,
    read_regular: impl FnOnce(&Path) -> Result<Vec<u8>, LogError>,
) -> Result<Vec<u8>, LogError> {
    let name = path.display().to_string();
    let io = |error| LogError::Io {
        path: name.clone(),
        error,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let regular = file.metadata().map_err(io)?.is_file();
    let mut bytes = Vec::new();
    (&mut file)
        .take(SNIFF_BYTES as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if let Some(e) = binary_error(&bytes, 0, &name) {
        return Err(e);
    }
    let too_long = |bytes: &[u8], line_start: usize| LogError::LineTooLong {
        at: Location::line(
            &name,
            1 + bytes[..line_start].iter().filter(|&&b| b == b'\n').count(),
        ),
        limit: MAX_TEXT_LINE_BYTES,
    };
    if regular {
        if bytes.len() == SNIFF_BYTES && !bytes.contains(&b'\n') {
            (&mut file)
                .take((MAX_TEXT_LINE_BYTES + 1 - SNIFF_BYTES) as u64)
                .read_to_end(&mut bytes)
                .map_err(io)?;
            if bytes.len() > MAX_TEXT_LINE_BYTES && !bytes.contains(&b'\n') {
                return Err(too_long(&bytes, 0));
            }
        }
        drop(bytes);
        return read_regular(path);
    }
    let mut line_start = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    if bytes.len() < SNIFF_BYTES {
        // The first read ended short: the stream is at its end.
        return Ok(bytes);
    }
    loop {
        let from = bytes.len();
        let got = (&mut file)
            .take(TEXT_BLOCK_BYTES as u64)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        let block = &bytes[from..];
        if let Some(i) = block.iter().position(|&b| b == 0) {
            return Err(LogError::BinaryData {
                path: name,
                byte_offset: (from + i) as u64,
                what: "a NUL byte".into(),
            });
        }
        if let Some(i) = block.iter().rposition(|&b| b == b'\n') {
            line_start = from + i + 1;
        }
        if bytes.len() - line_start > MAX_TEXT_LINE_BYTES {
            return Err(too_long(&bytes, line_start));
        }
        if got < TEXT_BLOCK_BYTES {
            return Ok(bytes);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sniffing_by_magic() {
        assert_eq!(sniff(b"DRIFTLOG"), InputFormat::Binary);
        assert_eq!(sniff(&[0x1f, 0x8b, 8, 0]), InputFormat::Gzip);
        assert_eq!(sniff(b"t,gx\n0,1"), InputFormat::Text);
        assert_eq!(sniff(b""), InputFormat::Text);
    }

    #[test]
    fn sizes_in_messages() {
        assert_eq!(human_bytes(16 << 20), "16 MiB");
        assert_eq!(human_bytes(1 << 10), "1 KiB");
        assert_eq!(human_bytes(1000), "1000 bytes");
    }
}

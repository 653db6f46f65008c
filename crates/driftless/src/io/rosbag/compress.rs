//! Decompression of one chunk (or one message) at a time: ROS 1 chunks `bz2` and `lz4`,
//! MCAP chunks `zstd` and `lz4`, rosbag2 message compression `zstd`.
//!
//! * `bz2`: one bzip2 stream (as Python's `bz2.compress` and ROS 1's `rosbag` write it).
//! * `lz4`: the LZ4 *frame* format (magic `04 22 4D 18`), in both ROS 1 (`roslz4`) and MCAP;
//!   linked or independent blocks, optional checksums checked.
//! * `zstd`: one Zstandard frame.
//!
//! The output is capped: a chunk declaring more than [`MAX_CHUNK_BYTES`] is refused before
//! anything is decompressed, and a decompressor producing more than was declared is cut
//! off and reported, so one chunk is all the memory a bag's decompression ever takes.

use std::io::Read;

/// The largest uncompressed chunk or message read (ROS tools write chunks of about 1 MiB).
pub(crate) const MAX_CHUNK_BYTES: u64 = 256 << 20;

/// A chunk compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Codec {
    Bz2,
    Lz4,
    Zstd,
}

impl Codec {
    /// The codec of a ROS 1 `compression` field or MCAP `compression` string (`""` and
    /// `"none"` are no compression: `Ok(None)`), an error for another name.
    pub(crate) fn of(name: &str, known: &[Codec]) -> Result<Option<Codec>, String> {
        let codec = match name {
            "" | "none" => return Ok(None),
            "bz2" => Codec::Bz2,
            "lz4" => Codec::Lz4,
            "zstd" => Codec::Zstd,
            _ => {
                return Err(format!(
                    "unknown chunk compression {name:?} (read: none, {})",
                    names(known)
                ));
            }
        };
        if known.contains(&codec) {
            Ok(Some(codec))
        } else {
            Err(format!(
                "chunk compression {name:?} is not one this format uses (read: none, {})",
                names(known)
            ))
        }
    }

    fn name(self) -> &'static str {
        match self {
            Codec::Bz2 => "bz2",
            Codec::Lz4 => "lz4",
            Codec::Zstd => "zstd",
        }
    }
}

fn names(known: &[Codec]) -> String {
    known
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Decompresses `input` into `out` (replacing its content); `declared` is the uncompressed
/// size the container states, `None` when it states none (rosbag2 message compression:
/// then up to [`MAX_CHUNK_BYTES`]).
pub(crate) fn decompress(
    codec: Codec,
    input: &[u8],
    declared: Option<u64>,
    out: &mut Vec<u8>,
) -> Result<(), String> {
    let cap = declared.unwrap_or(MAX_CHUNK_BYTES);
    if cap > MAX_CHUNK_BYTES {
        return Err(format!(
            "{}-compressed chunk declares {cap} bytes uncompressed, over the {MAX_CHUNK_BYTES}-byte \
             limit of one chunk (corrupt, or written with a huge chunk size: rewrite it with \
             smaller chunks)",
            codec.name()
        ));
    }
    out.clear();
    // Reserve what is declared only up to a few MiB: a corrupt header must not make a
    // large allocation before the data shows it decompresses that far.
    out.reserve(usize::try_from(declared.unwrap_or(0).min(4 << 20)).unwrap_or(0));
    let fail = |e: std::io::Error| format!("{} data does not decompress: {e}", codec.name());
    // Read one byte past the declared size, to tell a lying header from an exact one.
    let limit = cap + 1;
    match codec {
        Codec::Bz2 => bzip2::read::BzDecoder::new(input)
            .take(limit)
            .read_to_end(out)
            .map_err(fail)?,
        Codec::Lz4 => lz4_flex::frame::FrameDecoder::new(input)
            .take(limit)
            .read_to_end(out)
            .map_err(fail)?,
        Codec::Zstd => ruzstd::decoding::StreamingDecoder::new(input)
            .map_err(|e| format!("zstd data does not decompress: {e}"))?
            .take(limit)
            .read_to_end(out)
            .map_err(fail)?,
    };
    let got = out.len() as u64;
    match declared {
        Some(d) if got != d => Err(format!(
            "{}-compressed chunk declares {d} bytes uncompressed, holds {}",
            codec.name(),
            if got > d {
                "more".to_owned()
            } else {
                got.to_string()
            }
        )),
        None if got > MAX_CHUNK_BYTES => Err(format!(
            "{}-compressed message over the {MAX_CHUNK_BYTES}-byte limit uncompressed",
            codec.name()
        )),
        _ => Ok(()),
    }
}

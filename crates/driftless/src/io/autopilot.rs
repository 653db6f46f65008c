//! What the autopilot log readers ([`super::ulog`], [`super::dataflash`]) share: the
//! little-endian scalar types both formats use, the per-IMU result, format detection by
//! magic bytes, and the checks that turn decoded columns into an [`ImuLog`].
//!
//! Conventions of every IMU log built here:
//! * `time_s` is the autopilot's boot time in seconds (µs time stamps / 1e6), not zero-based,
//!   strictly increasing (a repeated or backwards stamp is an error naming its byte offset);
//! * channels `gyro_x/y/z` (rad/s), `acc_x/y/z` (m/s²) and `temperature` (°C) — the units
//!   both autopilots already log in, so no conversion happens;
//! * `tau0_s` is the median time-stamp interval; intervals longer than 1.5 τ0 are listed in
//!   [`ImuLog::gaps`] (logger drop-outs) while the log stays one segment (as with the text
//!   reader's `bridge` policy): thermal ramps do not care, Allan analyses should look;
//! * a NaN or infinite sample is an error naming the byte offset of its message, never a
//!   silent NaN.

use super::error::{Location, LogError};
use super::log::{Channel, ImuLog, Quantity};

/// Which autopilot log format a byte buffer holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AutopilotFormat {
    /// PX4 ULog (`.ulg`).
    ULog,
    /// ArduPilot DataFlash (`.bin`).
    DataFlash,
}

impl AutopilotFormat {
    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            AutopilotFormat::ULog => "PX4 ULog",
            AutopilotFormat::DataFlash => "ArduPilot DataFlash",
        }
    }
}

/// The format of `bytes` judged by their first bytes only (never by a file extension):
/// the 7-byte ULog magic `ULog\x01\x12\x35`, or a DataFlash message header `0xA3 0x95`
/// followed by the FMT id 128 (every DataFlash log starts with the FMT of FMT). Our own
/// `DRIFTLOG` binary format (also sometimes called `.bin`) matches neither.
pub fn detect_format(bytes: &[u8]) -> Option<AutopilotFormat> {
    if bytes.starts_with(&super::ulog::MAGIC) {
        Some(AutopilotFormat::ULog)
    } else if bytes.starts_with(&[super::dataflash::HEAD1, super::dataflash::HEAD2, 128]) {
        Some(AutopilotFormat::DataFlash)
    } else {
        None
    }
}

/// One IMU of an autopilot log.
#[derive(Clone, Debug, PartialEq)]
pub struct AutopilotImu {
    /// The autopilot's instance number (ULog `multi_id`, DataFlash `I`), 0-based.
    pub instance: u8,
    /// Time, gyro/accel triads and temperature (see the module docs for the conventions).
    pub log: ImuLog,
}

/// Every IMU found in an autopilot log, plus what the reader noticed on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct AutopilotImuLogs {
    /// The format read.
    pub format: AutopilotFormat,
    /// One entry per IMU instance, by increasing instance number.
    pub imus: Vec<AutopilotImu>,
    /// `Some(offset)` when the input ended inside a message that starts at this 0-based
    /// byte offset: the reader stopped cleanly there and kept everything before it.
    pub truncated_at_byte: Option<u64>,
    /// Topics (ULog `name[multi_id]`) or message types (DataFlash) present, with their
    /// message counts, in name order.
    pub found: Vec<(String, usize)>,
    /// Things worth telling the user (skipped bytes, unpaired samples, drop-outs, …).
    pub notes: Vec<String>,
}

impl AutopilotImuLogs {
    /// The IMU with this instance number.
    pub fn instance(&self, instance: u8) -> Option<&AutopilotImu> {
        self.imus.iter().find(|i| i.instance == instance)
    }
}

/// Reads `bytes` as whichever autopilot format [`detect_format`] finds; `Ok(None)` when
/// the bytes are neither ULog nor DataFlash.
pub fn imu_logs_from_autopilot(
    bytes: &[u8],
    source: &str,
) -> Result<Option<AutopilotImuLogs>, LogError> {
    match detect_format(bytes) {
        Some(AutopilotFormat::ULog) => super::ulog::imu_logs_from_ulog(bytes, source).map(Some),
        Some(AutopilotFormat::DataFlash) => {
            super::dataflash::imu_logs_from_dataflash(bytes, source).map(Some)
        }
        None => Ok(None),
    }
}

/// Reads a file as an autopilot log; `Ok(None)` when it is neither ULog nor DataFlash.
pub fn imu_logs_from_autopilot_file(
    path: impl AsRef<std::path::Path>,
) -> Result<Option<AutopilotImuLogs>, LogError> {
    let input = super::input::LogInput::open(path)?;
    if !input.is_autopilot() {
        return Ok(None);
    }
    input.read_autopilot().map(Some)
}

/// Little-endian scalar types of the two formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    /// `int8_t`.
    I8,
    /// `uint8_t`.
    U8,
    /// `int16_t`.
    I16,
    /// `uint16_t`.
    U16,
    /// `int32_t`.
    I32,
    /// `uint32_t`.
    U32,
    /// `int64_t` (values beyond 2^53 lose digits as f64).
    I64,
    /// `uint64_t` (values beyond 2^53 lose digits as f64).
    U64,
    /// IEEE-754 half precision (DataFlash `g`).
    F16,
    /// `float`.
    F32,
    /// `double`.
    F64,
    /// `bool` (one byte, non-zero is true → 1.0).
    Bool,
    /// `char` (one byte, its code as a number).
    Char,
}

impl Scalar {
    /// Size in bytes.
    pub fn size(self) -> usize {
        use Scalar::*;
        match self {
            I8 | U8 | Bool | Char => 1,
            I16 | U16 | F16 => 2,
            I32 | U32 | F32 => 4,
            I64 | U64 | F64 => 8,
        }
    }

    /// Decodes the value at the start of `b` as f64; `None` when `b` is too short.
    pub(crate) fn read_f64(self, b: &[u8]) -> Option<f64> {
        use Scalar::*;
        Some(match self {
            I8 => f64::from(*b.first()? as i8),
            U8 | Char => f64::from(*b.first()?),
            Bool => f64::from(u8::from(*b.first()? != 0)),
            I16 => f64::from(i16::from_le_bytes(arr(b)?)),
            U16 => f64::from(u16::from_le_bytes(arr(b)?)),
            F16 => half_to_f64(u16::from_le_bytes(arr(b)?)),
            I32 => f64::from(i32::from_le_bytes(arr(b)?)),
            U32 => f64::from(u32::from_le_bytes(arr(b)?)),
            F32 => f64::from(f32::from_le_bytes(arr(b)?)),
            I64 => i64::from_le_bytes(arr(b)?) as f64,
            U64 => u64::from_le_bytes(arr(b)?) as f64,
            F64 => f64::from_le_bytes(arr(b)?),
        })
    }
}

/// The first `N` bytes of `b` as an array.
pub(crate) fn arr<const N: usize>(b: &[u8]) -> Option<[u8; N]> {
    b.get(..N)?.try_into().ok()
}

/// `u16` at `at`, little-endian.
pub(crate) fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    arr(b.get(at..)?).map(u16::from_le_bytes)
}

/// `u64` at `at`, little-endian.
pub(crate) fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    arr(b.get(at..)?).map(u64::from_le_bytes)
}

/// "NAME ×count, …": the message types or topics a log holds, for the error that says
/// it holds no IMU data.
pub(crate) fn list_counts(found: &[(String, usize)]) -> String {
    found
        .iter()
        .map(|(n, c)| format!("{n} ×{c}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// IEEE-754 binary16 → f64 (subnormals, infinities and NaN included).
fn half_to_f64(h: u16) -> f64 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f64::from(h & 0x3ff);
    sign * match exp {
        0 => frac * 2f64.powi(-24),
        31 if frac == 0.0 => f64::INFINITY,
        31 => f64::NAN,
        e => (1.0 + frac / 1024.0) * 2f64.powi(e - 15),
    }
}

/// One decoded column destined for an [`ImuLog`] channel.
pub(crate) struct Column {
    pub name: &'static str,
    pub quantity: Quantity,
    pub source_unit: &'static str,
    pub values: Vec<f64>,
}

/// Builds an IMU log from µs time stamps and columns of equal length, checking time order
/// and finiteness; `offsets[i]` is the byte offset of row `i`'s message (for errors).
pub(crate) fn build_imu_log(
    source: &str,
    format: &'static str,
    time_us: &[u64],
    offsets: &[u64],
    columns: Vec<Column>,
) -> Result<ImuLog, LogError> {
    let at = |i: usize, message: String| LogError::AtByte {
        path: source.to_owned(),
        byte_offset: offsets.get(i).copied().unwrap_or(0),
        format,
        message,
    };
    for w in 1..time_us.len() {
        if time_us[w] <= time_us[w - 1] {
            return Err(at(
                w,
                format!(
                    "IMU time stamp {} µs {} the previous one ({} µs); time must increase",
                    time_us[w],
                    if time_us[w] == time_us[w - 1] {
                        "repeats"
                    } else {
                        "is before"
                    },
                    time_us[w - 1]
                ),
            ));
        }
    }
    for c in &columns {
        if let Some(i) = c.values.iter().position(|v| !v.is_finite()) {
            return Err(at(
                i,
                format!(
                    "non-finite {} ({}) in sample {i} of this IMU; NaN and infinity are not valid samples",
                    c.name, c.values[i]
                ),
            ));
        }
    }
    // Division (correctly rounded) so that 140575610 µs is exactly the f64 nearest 140.57561 s.
    let time_s: Vec<f64> = time_us.iter().map(|&t| t as f64 / 1e6).collect();
    let mut dt: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    let tau0_s = match dt.get(dt.len() / 2) {
        Some(&d) if d > 0.0 => d,
        _ => {
            return Err(LogError::Malformed {
                at: Location::input(source),
                format,
                message: format!(
                    "{} IMU sample(s): at least 2 are needed for a time base",
                    time_s.len()
                ),
            });
        }
    };
    super::timing::check_one_rate(&time_s, 1.5 * tau0_s, source)?;
    let gaps = super::timing::gaps_over(&time_s, 1.5 * tau0_s);
    let channels = columns
        .into_iter()
        .map(|c| Channel {
            name: c.name.to_owned(),
            quantity: c.quantity,
            source_unit: c.source_unit.to_owned(),
            values: c.values,
        })
        .collect();
    let mut log = ImuLog::new(source, Some(time_s), tau0_s, channels);
    log.gaps = gaps;
    Ok(log)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_precision_values() {
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc000), -2.0);
        assert_eq!(half_to_f64(0x7bff), 65504.0);
        assert_eq!(half_to_f64(0x0001), 2f64.powi(-24));
        assert!(half_to_f64(0x7c00).is_infinite());
        assert!(half_to_f64(0x7e00).is_nan());
    }

    #[test]
    fn scalars_decode_little_endian_and_refuse_short_input() {
        assert_eq!(Scalar::I16.read_f64(&[0xfe, 0xff]), Some(-2.0));
        assert_eq!(Scalar::U32.read_f64(&[1, 0, 0, 1]), Some(16777217.0));
        assert_eq!(Scalar::F32.read_f64(&1.5f32.to_le_bytes()), Some(1.5));
        assert_eq!(Scalar::Bool.read_f64(&[7]), Some(1.0));
        assert_eq!(Scalar::U64.read_f64(&[0; 7]), None);
        assert_eq!(Scalar::I8.read_f64(&[]), None);
    }

    #[test]
    fn detection_is_by_magic() {
        assert_eq!(
            detect_format(b"ULog\x01\x12\x35\x01rest"),
            Some(AutopilotFormat::ULog)
        );
        assert_eq!(
            detect_format(&[0xA3, 0x95, 128, 128, 89]),
            Some(AutopilotFormat::DataFlash)
        );
        assert_eq!(detect_format(b"DRIFTLOG\x01\0\0\0"), None);
        assert_eq!(detect_format(b"time,gx\n"), None);
        assert_eq!(detect_format(&[]), None);
    }

    /// Deterministic mutation fuzzing of both readers on the hand-built logs: bit flips,
    /// byte overwrites, insertions, deletions and truncations. No panic; every IMU log that
    /// comes out is finite with equal-length channels; truncation offsets lie inside.
    #[test]
    fn mutated_autopilot_logs_never_panic() {
        let seeds = [
            super::super::ulog::tests::sample(),
            super::super::dataflash::tests::sample(),
        ];
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..20_000 {
            let k = (next() % 2) as usize;
            let mut v = seeds[k].clone();
            for _ in 0..1 + next() % 4 {
                let len = v.len().max(1) as u64;
                let i = (next() % len) as usize;
                let j = i.min(v.len().saturating_sub(1));
                match next() % 5 {
                    0 if !v.is_empty() => v[j] ^= 1 << (next() % 8),
                    1 if !v.is_empty() => v[j] = next() as u8,
                    2 => v.insert(i.min(v.len()), next() as u8),
                    3 if !v.is_empty() => {
                        v.remove(j);
                    }
                    _ => v.truncate(i),
                }
            }
            check_no_nan(&v);
        }
    }

    pub(crate) fn check_no_nan(v: &[u8]) {
        if let Ok(Some(r)) = imu_logs_from_autopilot(v, "mut") {
            assert!(r.truncated_at_byte.is_none_or(|t| t < v.len() as u64));
            for imu in &r.imus {
                for c in &imu.log.channels {
                    assert_eq!(c.values.len(), imu.log.len());
                    assert!(c.values.iter().all(|x| x.is_finite()));
                }
            }
        }
        let _ = super::super::ulog::parse_ulog(v, "mut");
        let _ = super::super::dataflash::parse_dataflash(v, "mut");
    }
}

//! Robotics logs: IMU messages from ROS 1 bags (`.bag`, format 2.0), ROS 2 MCAP bags
//! (`.mcap`) and ROS 2 sqlite3 bags (`.db3`), or a ROS 2 bag folder (`metadata.yaml` naming
//! one or more storage files, read in that order as one recording) → one [`ImuLog`].
//!
//! * The topic is chosen by name ([`read_rosbag_file`]'s `topic`); without one, a bag with
//!   exactly one `sensor_msgs/Imu` topic uses it, any other count is an error listing the
//!   IMU topics. A `sensor_msgs/Temperature` topic, when the bag has exactly one, gives the
//!   `temperature` channel, each IMU sample taking the temperature message nearest in
//!   header stamp.
//! * Channels `gyro_x/y/z` (rad/s, `angular_velocity`), `acc_x/y/z` (m/s²,
//!   `linear_acceleration`) and `temperature` (°C): the units of `sensor_msgs`, so nothing is
//!   converted. Orientation and covariances are read past, not kept.
//! * `time_s` is the header stamp, `sec + nanosec · 1e-9` s (not zero-based). The messages
//!   must come in strictly increasing header-stamp order as stored in the bag (file order;
//!   rowid order in a `.db3`, i.e. the order they were recorded): a repeated or earlier
//!   stamp is an error naming the message's index, byte offset and both stamps (never
//!   silently sorted: an IMU driver stamps in order, so disorder is a recording fault the
//!   user should see).
//! * `tau0_s` is the median stamp interval, taken from the integer nanosecond stamps (epoch
//!   seconds as f64 are quantised to ≈ 0.24 µs); intervals over 1.5 τ0 are listed in
//!   [`ImuLog::gaps`] while the log stays one segment, as for autopilot logs.
//! * Streamed: the bag is read twice (once for its topics, once for the messages), one
//!   record, chunk or SQLite page at a time, so the memory beyond the output columns is one
//!   chunk (≈ 1 MiB as written by ROS tools) or one B-tree path of pages, whatever the
//!   bag's length.
//! * Compressed chunks are decompressed one at a time: ROS 1 `bz2` and `lz4`, MCAP `zstd`
//!   and `lz4`; rosbag2's per-message `zstd` compression
//!   (`compression_mode: message` in `metadata.yaml`) likewise. A whole-file compressed bag
//!   (`compression_mode: file`, `*.db3.zstd`) is refused with the command that decompresses
//!   it.

mod cdr;
mod compress;
mod db3;
mod folder;
mod mcap;
mod ros1;
mod sqlite;

use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::error::{Location, LogError};
use super::log::{Channel, ImuLog, Quantity};
pub(crate) use folder::{Ros2BagFolder, ros2_bag_folder};

/// Which robotics log format an input holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BagFormat {
    /// ROS 1 bag, format version 2.0.
    Ros1,
    /// MCAP (ROS 2 default storage since Iron), CDR-encoded messages.
    Mcap,
    /// ROS 2 sqlite3 storage (`.db3`).
    Sqlite3,
}

impl BagFormat {
    /// The format's name for messages.
    pub fn name(self) -> &'static str {
        match self {
            BagFormat::Ros1 => "ROS 1 bag",
            BagFormat::Mcap => "MCAP",
            BagFormat::Sqlite3 => "ROS 2 sqlite3 bag",
        }
    }
}

/// The ROS 1 bag magic line (format 2.0).
pub(crate) const ROS1_MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// The MCAP magic (MCAP specification, "Magic").
pub(crate) const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// The start of an sqlite3 database file.
pub(crate) const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";

/// The format shown by the first bytes of an input (at least 8 are needed).
pub fn detect_format(head: &[u8]) -> Option<BagFormat> {
    let starts =
        |magic: &[u8]| head.len() >= 8 && magic.starts_with(&head[..head.len().min(magic.len())]);
    if starts(ROS1_MAGIC) {
        Some(BagFormat::Ros1)
    } else if starts(MCAP_MAGIC) {
        Some(BagFormat::Mcap)
    } else if starts(SQLITE_MAGIC) {
        Some(BagFormat::Sqlite3)
    } else {
        None
    }
}

/// Reads the IMU topic `topic` (or the bag's only IMU topic) of the ROS bag at `path` (a
/// `.bag`, `.mcap`, `.db3`, or a ROS 2 bag folder). See the module doc for the conventions.
pub fn read_rosbag_file(path: impl AsRef<Path>, topic: Option<&str>) -> Result<ImuLog, LogError> {
    let path = path.as_ref();
    let folder = if path.is_dir() {
        ros2_bag_folder(path)?
    } else {
        None
    };
    let first = folder
        .as_ref()
        .and_then(|f| f.storage.first())
        .map_or(path, |p| p.as_path());
    let name = first.display().to_string();
    let file = std::fs::File::open(first).map_err(|error| LogError::Io {
        path: name.clone(),
        error,
    })?;
    read_rosbag_parts(file, &name, folder.as_ref(), topic)
}

/// [`read_rosbag_file`] of an opened file (read from its start; it must be seekable: the
/// bag is read twice).
pub fn read_rosbag(
    file: std::fs::File,
    name: &str,
    topic: Option<&str>,
) -> Result<ImuLog, LogError> {
    read_rosbag_parts(file, name, None, topic)
}

/// [`read_rosbag_file`] of a bag whose first storage file is `first` (opened, named
/// `name`) and, for a ROS 2 bag folder, the rest of `folder.storage` after it.
pub(crate) fn read_rosbag_parts(
    first: std::fs::File,
    name: &str,
    folder: Option<&Ros2BagFolder>,
    topic: Option<&str>,
) -> Result<ImuLog, LogError> {
    let rest: Vec<String> = folder
        .map(|f| {
            f.storage
                .iter()
                .skip(1)
                .map(|p| p.display().to_string())
                .collect()
        })
        .unwrap_or_default();
    let message_zstd = folder.is_some_and(|f| f.message_zstd);
    let mut first = Some(first);
    let mut parts = Vec::with_capacity(1 + rest.len());
    for part_name in std::iter::once(name).chain(rest.iter().map(String::as_str)) {
        let file = match first.take() {
            Some(f) => f,
            None => std::fs::File::open(part_name).map_err(|error| LogError::Io {
                path: part_name.to_owned(),
                error,
            })?,
        };
        parts.push(Part::open(file, part_name)?);
    }
    // Pass 1: the topics.
    let mut topics = Topics::default();
    for (p, part) in parts.iter_mut().enumerate() {
        part.scan(true, &mut |item| {
            match item {
                Item::Connection {
                    id,
                    topic,
                    msg_type,
                } => topics.add((p, id), topic, msg_type),
                Item::Message { conn, .. } => topics.count((p, conn), 1),
                Item::Count { conn, messages } => topics.count((p, conn), messages),
            }
            Ok(())
        })?;
    }
    let imu_topic = topics.choose_imu(topic, name)?;
    let temp_topic = topics.only_of(Kind::Temperature);
    // Pass 2: the messages of the chosen topics.
    let mut imu = ImuColumns::default();
    let mut temp: Vec<(f64, f64)> = Vec::new();
    let mut plain = Vec::new();
    for (p, part) in parts.iter_mut().enumerate() {
        let (part_name, format) = (part.name, part.format);
        let encoding = match format {
            BagFormat::Ros1 => Encoding::Ros1,
            _ => Encoding::Cdr,
        };
        part.scan(false, &mut |item| {
            let Item::Message {
                conn,
                byte_offset,
                data,
            } = item
            else {
                return Ok(());
            };
            let Some(t) = topics.topic_of((p, conn)) else {
                return Ok(());
            };
            if t != imu_topic && Some(t) != temp_topic {
                return Ok(());
            }
            let bad = |message: String| LogError::AtByte {
                path: part_name.to_owned(),
                byte_offset,
                format: format.name(),
                message,
            };
            let data = if message_zstd {
                compress::decompress(compress::Codec::Zstd, data, None, &mut plain)
                    .map_err(|m| bad(format!("message on {}: {m}", topics.name(t))))?;
                &plain[..]
            } else {
                data
            };
            if t == imu_topic {
                let s = cdr::decode_imu(data, encoding).map_err(|m| {
                    bad(format!(
                        "{} message {} on {}: {m}",
                        encoding.type_name(Kind::Imu),
                        imu.len(),
                        topics.name(t)
                    ))
                })?;
                imu.push(s, byte_offset).map_err(bad)?;
            } else {
                let (stamp, celsius) = cdr::decode_temperature(data, encoding).map_err(|m| {
                    bad(format!(
                        "{} message {} on {}: {m}",
                        encoding.type_name(Kind::Temperature),
                        temp.len(),
                        topics.name(t)
                    ))
                })?;
                if !celsius.is_finite() {
                    return Err(bad(format!(
                        "non-finite temperature {celsius} on {}",
                        topics.name(t)
                    )));
                }
                temp.push((stamp, celsius));
            }
            Ok(())
        })?;
    }
    let format = parts.first().map_or("ROS bag", |p| p.format.name());
    imu.into_log(name, format, temp)
}

/// One storage file of a bag, opened, its format known.
struct Part<'n> {
    file: std::fs::File,
    name: &'n str,
    size: u64,
    format: BagFormat,
}

impl<'n> Part<'n> {
    fn open(mut file: std::fs::File, name: &'n str) -> Result<Self, LogError> {
        let io = |error| LogError::Io {
            path: name.to_owned(),
            error,
        };
        let meta = file.metadata().map_err(io)?;
        if !meta.is_file() {
            return Err(LogError::InvalidOptions {
                at: Location::input(name),
                message: "a ROS bag is read twice (topics, then messages): give a regular \
                          file, not a pipe or device"
                    .into(),
            });
        }
        file.seek(SeekFrom::Start(0)).map_err(io)?;
        let mut head = [0u8; 16];
        let n = (&mut file).take(16).read(&mut head).map_err(io)?;
        let format = detect_format(&head[..n]).ok_or_else(|| LogError::InvalidOptions {
            at: Location::input(name),
            message: "not a ROS 1 bag (#ROSBAG V2.0), MCAP file or ROS 2 sqlite3 bag (no magic \
                      bytes)"
                .into(),
        })?;
        Ok(Part {
            file,
            name,
            size: meta.len(),
            format,
        })
    }

    /// Reads the file from its start, handing on connections and messages in stored order
    /// (`topics_only`: messages may be handed on as counts instead).
    fn scan(
        &mut self,
        topics_only: bool,
        visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
    ) -> Result<(), LogError> {
        if self.format == BagFormat::Sqlite3 {
            return db3::scan(&mut self.file, self.name, self.size, visit);
        }
        self.file
            .seek(SeekFrom::Start(0))
            .map_err(|error| LogError::Io {
                path: self.name.to_owned(),
                error,
            })?;
        let mut src = Source::new(&mut self.file, self.name, self.size);
        match self.format {
            BagFormat::Ros1 => ros1::scan(&mut src, topics_only, visit),
            _ => mcap::scan(&mut src, visit),
        }
    }
}

/// What a format scanner hands on, in file order.
pub(crate) enum Item<'a> {
    /// A connection (ROS 1) or channel (MCAP): its id, topic and message type.
    Connection {
        id: u32,
        topic: &'a str,
        msg_type: &'a str,
    },
    /// How many messages a connection has in one chunk, from a ROS 1 index (when the
    /// messages themselves are not read: [`Part::scan`]'s `topics_only`).
    Count { conn: u32, messages: u64 },
    /// One message: its connection, the byte offset of its record (for errors; within a
    /// chunk, the chunk's offset) and its serialized bytes.
    Message {
        conn: u32,
        byte_offset: u64,
        data: &'a [u8],
    },
}

/// Message serialization.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// ROS 1 serialization: little-endian, unaligned, `time` = (u32 sec, u32 nsec).
    Ros1,
    /// ROS 2 CDR: a 4-byte encapsulation header, then aligned primitives.
    Cdr,
}

impl Encoding {
    fn type_name(self, kind: Kind) -> &'static str {
        match (self, kind) {
            (Encoding::Ros1, Kind::Imu) => "sensor_msgs/Imu",
            (Encoding::Ros1, _) => "sensor_msgs/Temperature",
            (Encoding::Cdr, Kind::Imu) => "sensor_msgs/msg/Imu",
            (Encoding::Cdr, _) => "sensor_msgs/msg/Temperature",
        }
    }
}

/// The message types read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Imu,
    Temperature,
    Other,
}

fn kind_of(msg_type: &str) -> Kind {
    match msg_type {
        "sensor_msgs/Imu" | "sensor_msgs/msg/Imu" => Kind::Imu,
        "sensor_msgs/Temperature" | "sensor_msgs/msg/Temperature" => Kind::Temperature,
        _ => Kind::Other,
    }
}

/// A connection: (index of its storage file, its id in that file).
type ConnKey = (usize, u32);

/// The bag's topics (several connections may share one topic).
#[derive(Default)]
struct Topics {
    /// (topic, type, kind, messages).
    list: Vec<(String, String, Kind, u64)>,
    /// ((storage file, connection id), index into `list`).
    conns: Vec<(ConnKey, usize)>,
}

impl Topics {
    fn add(&mut self, id: ConnKey, topic: &str, msg_type: &str) {
        if self.conns.iter().any(|&(c, _)| c == id) {
            return;
        }
        let i = match self
            .list
            .iter()
            .position(|(t, ty, _, _)| t == topic && ty == msg_type)
        {
            Some(i) => i,
            None => {
                self.list
                    .push((topic.to_owned(), msg_type.to_owned(), kind_of(msg_type), 0));
                self.list.len() - 1
            }
        };
        self.conns.push((id, i));
    }
    fn topic_of(&self, conn: ConnKey) -> Option<usize> {
        self.conns
            .iter()
            .find(|&&(c, _)| c == conn)
            .map(|&(_, i)| i)
    }
    fn count(&mut self, conn: ConnKey, messages: u64) {
        if let Some(i) = self.topic_of(conn) {
            self.list[i].3 += messages;
        }
    }
    fn name(&self, i: usize) -> &str {
        &self.list[i].0
    }
    fn of_kind(&self, kind: Kind) -> Vec<usize> {
        (0..self.list.len())
            .filter(|&i| self.list[i].2 == kind)
            .collect()
    }
    fn only_of(&self, kind: Kind) -> Option<usize> {
        match self.of_kind(kind).as_slice() {
            &[i] => Some(i),
            _ => None,
        }
    }
    fn describe(&self, idx: &[usize]) -> String {
        if idx.is_empty() {
            return "none".into();
        }
        idx.iter()
            .map(|&i| {
                let (t, ty, _, n) = &self.list[i];
                format!("{t} ({ty}, {n} messages)")
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
    /// The IMU topic: `wanted` by name, else the only one.
    fn choose_imu(&self, wanted: Option<&str>, name: &str) -> Result<usize, LogError> {
        let imus = self.of_kind(Kind::Imu);
        let all: Vec<usize> = (0..self.list.len()).collect();
        let err = |message: String| LogError::InvalidOptions {
            at: Location::input(name),
            message,
        };
        match wanted {
            Some(w) => {
                let Some(i) = self.list.iter().position(|(t, _, _, _)| t == w) else {
                    return Err(err(format!(
                        "no topic {w:?}; topics: {}",
                        self.describe(&all)
                    )));
                };
                match imus.iter().find(|&&j| self.list[j].0 == w) {
                    Some(&j) => Ok(j),
                    None => Err(err(format!(
                        "topic {w} holds {}, not sensor_msgs/Imu; IMU topics: {}",
                        self.list[i].1,
                        self.describe(&imus)
                    ))),
                }
            }
            None => match imus.as_slice() {
                &[i] => Ok(i),
                [] => Err(err(format!(
                    "no sensor_msgs/Imu topic; topics: {}",
                    self.describe(&all)
                ))),
                _ => Err(err(format!(
                    "{} sensor_msgs/Imu topics: {}; choose one with --topic NAME",
                    imus.len(),
                    self.describe(&imus)
                ))),
            },
        }
    }
}

/// One decoded IMU message.
pub(crate) struct ImuSample {
    /// Header stamp, ns since the epoch.
    pub stamp_ns: i64,
    /// `angular_velocity`, rad/s.
    pub gyro_rad_s: [f64; 3],
    /// `linear_acceleration`, m/s².
    pub acc_m_s2: [f64; 3],
}

/// The output columns, filled message by message.
#[derive(Default)]
struct ImuColumns {
    time_ns: Vec<i64>,
    gyro_rad_s: [Vec<f64>; 3],
    acc_m_s2: [Vec<f64>; 3],
}

impl ImuColumns {
    fn len(&self) -> usize {
        self.time_ns.len()
    }

    /// Appends a sample after checking its stamp order and finiteness.
    fn push(&mut self, s: ImuSample, _byte_offset: u64) -> Result<(), String> {
        let k = self.time_ns.len();
        if let Some(&prev) = self.time_ns.last()
            && s.stamp_ns <= prev
        {
            return Err(format!(
                "IMU message {k} has header stamp {} s, {} message {} ({} s); the messages \
                 must be in increasing stamp order",
                seconds_of_ns(s.stamp_ns),
                if s.stamp_ns == prev {
                    "the same as"
                } else {
                    "before"
                },
                k - 1,
                seconds_of_ns(prev)
            ));
        }
        if let Some(v) = s
            .gyro_rad_s
            .iter()
            .chain(&s.acc_m_s2)
            .find(|v| !v.is_finite())
        {
            return Err(format!(
                "IMU message {k}: non-finite sample {v}; NaN and infinity are not valid samples"
            ));
        }
        self.time_ns.push(s.stamp_ns);
        for a in 0..3 {
            self.gyro_rad_s[a].push(s.gyro_rad_s[a]);
            self.acc_m_s2[a].push(s.acc_m_s2[a]);
        }
        Ok(())
    }

    /// The log: channels, τ0 (median interval), gaps and the temperature nearest in stamp.
    fn into_log(
        self,
        source: &str,
        format: &'static str,
        mut temp: Vec<(f64, f64)>,
    ) -> Result<ImuLog, LogError> {
        // τ0 from the integer stamps: epoch seconds as f64 are quantised to ~0.24 µs, which
        // would bias a 5 ms interval by up to 24 ppm.
        let mut dt_ns: Vec<i64> = self.time_ns.windows(2).map(|w| w[1] - w[0]).collect();
        dt_ns.sort_unstable();
        let tau0_s = match dt_ns.get(dt_ns.len() / 2) {
            Some(&d) if d > 0 => d as f64 / 1e9,
            _ => {
                return Err(LogError::Malformed {
                    at: Location::input(source),
                    format,
                    message: format!(
                        "{} IMU message(s) on the topic: at least 2 are needed for a time base",
                        self.time_ns.len()
                    ),
                });
            }
        };
        drop(dt_ns);
        let time_s: Vec<f64> = self.time_ns.iter().map(|&t| seconds_of_ns(t)).collect();
        drop(self.time_ns);
        super::timing::check_one_rate(&time_s, 1.5 * tau0_s, source)?;
        let gaps = super::timing::gaps_over(&time_s, 1.5 * tau0_s);
        let [gx, gy, gz] = self.gyro_rad_s;
        let [ax, ay, az] = self.acc_m_s2;
        let mut channels: Vec<Channel> = [("gyro_x", gx), ("gyro_y", gy), ("gyro_z", gz)]
            .into_iter()
            .map(|(n, v)| channel(n, Quantity::AngularRate, "rad/s", v))
            .chain(
                [("acc_x", ax), ("acc_y", ay), ("acc_z", az)]
                    .into_iter()
                    .map(|(n, v)| channel(n, Quantity::SpecificForce, "m/s^2", v)),
            )
            .collect();
        if !temp.is_empty() {
            temp.sort_by(|a, b| a.0.total_cmp(&b.0));
            channels.push(channel(
                "temperature",
                Quantity::Temperature,
                "degC",
                nearest_in_time(&time_s, &temp),
            ));
        }
        let mut log = ImuLog::new(source, Some(time_s), tau0_s, channels);
        log.gaps = gaps;
        Ok(log)
    }
}

/// Seconds of a stamp in ns: `sec + nanosec · 1e-9` (as the two header fields).
pub(crate) fn seconds_of_ns(ns: i64) -> f64 {
    ns.div_euclid(1_000_000_000) as f64 + ns.rem_euclid(1_000_000_000) as f64 * 1e-9
}

fn channel(name: &str, quantity: Quantity, unit: &str, values: Vec<f64>) -> Channel {
    Channel {
        name: name.to_owned(),
        quantity,
        source_unit: unit.to_owned(),
        values,
    }
}

/// For each time in `t` (increasing), the value of the sample of `samples` (time, value;
/// sorted by time, not empty) nearest in time; on a tie the earlier one.
fn nearest_in_time(t: &[f64], samples: &[(f64, f64)]) -> Vec<f64> {
    let mut j = 0;
    t.iter()
        .map(|&ti| {
            while j + 1 < samples.len() && (samples[j + 1].0 - ti).abs() < (samples[j].0 - ti).abs()
            {
                j += 1;
            }
            samples[j].1
        })
        .collect()
}

/// A bag file read front to back, tracking the byte offset (for errors) and the size (so
/// that a record length past the end is a truncation error, never a huge allocation).
pub(crate) struct Source<'f> {
    r: BufReader<&'f mut std::fs::File>,
    pub pos: u64,
    pub size: u64,
    pub name: &'f str,
}

impl<'f> Source<'f> {
    fn new(file: &'f mut std::fs::File, name: &'f str, size: u64) -> Self {
        Source {
            r: BufReader::with_capacity(1 << 16, file),
            pos: 0,
            size,
            name,
        }
    }

    /// A [`LogError::AtByte`] at `byte_offset`.
    pub fn error(&self, format: &'static str, byte_offset: u64, message: String) -> LogError {
        LogError::AtByte {
            path: self.name.to_owned(),
            byte_offset,
            format,
            message,
        }
    }

    /// Bytes left.
    pub fn remaining(&self) -> u64 {
        self.size.saturating_sub(self.pos)
    }

    /// Checks that `n` bytes are left for `what` (a record starting at `record_at`).
    pub fn need(
        &self,
        format: &'static str,
        record_at: u64,
        n: u64,
        what: &str,
    ) -> Result<(), LogError> {
        if n > self.remaining() {
            return Err(self.error(
                format,
                record_at,
                format!(
                    "truncated: {what} needs {n} bytes from byte {}, the file ends at byte {} \
                     (an interrupted recording?)",
                    self.pos, self.size
                ),
            ));
        }
        Ok(())
    }

    /// Reads exactly `n` bytes into `buf` (replacing its content), after [`Self::need`].
    pub fn read_into(
        &mut self,
        format: &'static str,
        record_at: u64,
        n: u64,
        what: &str,
        buf: &mut Vec<u8>,
    ) -> Result<(), LogError> {
        self.need(format, record_at, n, what)?;
        buf.clear();
        let got = (&mut self.r)
            .take(n)
            .read_to_end(buf)
            .map_err(|error| LogError::Io {
                path: self.name.to_owned(),
                error,
            })?;
        self.pos += got as u64;
        if (got as u64) < n {
            return Err(self.error(
                format,
                record_at,
                format!("truncated: {what} ends early at byte {}", self.pos),
            ));
        }
        Ok(())
    }

    /// Skips `n` bytes, after [`Self::need`].
    pub fn skip(
        &mut self,
        format: &'static str,
        record_at: u64,
        n: u64,
        what: &str,
    ) -> Result<(), LogError> {
        self.need(format, record_at, n, what)?;
        let n_i = i64::try_from(n).map_err(|_| {
            self.error(
                format,
                record_at,
                format!("{what}: length {n} out of range"),
            )
        })?;
        self.r.seek_relative(n_i).map_err(|error| LogError::Io {
            path: self.name.to_owned(),
            error,
        })?;
        self.pos += n;
        Ok(())
    }
}

/// Little-endian readers over a byte slice that return `None` past its end.
pub(crate) fn le_u16(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(
        b.get(at..at.checked_add(2)?)?.try_into().ok()?,
    ))
}
pub(crate) fn le_u32(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(
        b.get(at..at.checked_add(4)?)?.try_into().ok()?,
    ))
}
pub(crate) fn le_u64(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(
        b.get(at..at.checked_add(8)?)?.try_into().ok()?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_temperature_takes_the_closer_stamp() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let s = [(0.2, 10.0), (1.9, 20.0), (2.6, 30.0)];
        assert_eq!(nearest_in_time(&t, &s), vec![10.0, 10.0, 20.0, 30.0]);
    }

    #[test]
    fn detection_by_magic() {
        assert_eq!(detect_format(b"#ROSBAG V2.0\n"), Some(BagFormat::Ros1));
        assert_eq!(detect_format(b"\x89MCAP0\r\n"), Some(BagFormat::Mcap));
        assert_eq!(
            detect_format(b"SQLite format 3\0"),
            Some(BagFormat::Sqlite3)
        );
        assert_eq!(detect_format(b"#ROSBAG V1.2\n"), None);
        assert_eq!(detect_format(b"t,gx\n0,1"), None);
        assert_eq!(detect_format(b"#ROS"), None);
    }

    #[test]
    fn unsorted_stamps_are_an_error_naming_the_message() {
        let mut c = ImuColumns::default();
        let s = |t: f64| ImuSample {
            stamp_ns: (t * 1e9) as i64,
            gyro_rad_s: [0.0; 3],
            acc_m_s2: [0.0; 3],
        };
        c.push(s(1.0), 0).unwrap();
        c.push(s(2.0), 0).unwrap();
        let e = c.push(s(1.5), 0).unwrap_err();
        assert!(
            e.contains("message 2") && e.contains("1.5 s") && e.contains("2 s"),
            "{e}"
        );
    }
}

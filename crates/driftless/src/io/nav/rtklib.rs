//! RTKLIB formats: `.pos` solution files and binary `.tag` time-tag files.
//!
//! **`.pos`** (RTKLIB `outsolheads`/`outsols`, layout learnt from RTKLIB's `solution.c`,
//! no code taken): `%` lines are header/comments; the last `%` line naming the columns,
//! e.g. `%  GPST  latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) sdu(m) sdne(m)
//! sdeu(m) sdun(m) age(s) ratio [vn(m/s) ve(m/s) vu(m/s) sdvn sdve sdvu sdvne sdveu sdvun]`,
//! fixes the columns; the reader finds them by name, so the optional velocity block is
//! detected from that line. Each epoch starts with its time as two fields, either
//! `YYYY/MM/DD HH:MM:SS.sss` or `WWWW SSSSSS.sss` (GPS week, seconds of week). Supported:
//! time system GPST (UTC/JST need leap seconds and are refused with a message), positions
//! as latitude/longitude in decimal degrees and ellipsoidal height (ECEF, ENU-baseline and
//! deg-min-sec layouts are refused). Units at the edge: degrees → rad; RTKLIB's
//! north/east/**up** velocity becomes NED (`vD = −vu`); σ_D is `sdu` and σ_vD is `sdvu`
//! (a σ does not change sign). Cross-covariances (`sdne`…), `age` and `ratio` are checked
//! to be numbers and not kept. A truncated first or last epoch line (fewer fields than the
//! column header names, or — last line — a last field that is not a number: a solution
//! logger stopped mid-line) is dropped and reported in [`GnssFixes::notes`]; anywhere else
//! such a line is an error.
//!
//! **`.tag`** (RTKLIB stream time tags, written by `stream.c` when a file stream has the
//! `::T` option; layout learnt from RTKLIB/demo5 `stream.c`, no code taken), little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 0–59 | text `TIMETAG RTKLIB <version>`, NUL-padded |
//! | 60–63 | `tick_f`: u32 host tick at the start, ms |
//! | 64–67 | u32 whole GPST seconds since 1970-01-01 (RTKLIB `gtime_t.time`) |
//! | 68–75 | f64 fraction of the second |
//! | 76… | records: u32 tick (ms since the start) + file position (u32, or u64 with `::P=8`) |
//!
//! (RTKLIB before 2.4.3/demo5 wrote the whole `gtime_t` structure instead of 4 + 8 bytes;
//! that platform-dependent layout is not read.)

use std::path::Path;

use super::gpstime::{Calendar, GpsTime};
use super::kfgins::{GnssReadOptions, check_lat_lon, check_sigma};
use super::types::GnssFixes;
use super::{Field, as_utf8, check_time_order, parse_num, read_text_file, split_fields};
use crate::io::edge::{Cut, Edge, cut_record, last_data_line, line_of_offset, note};
use crate::io::{Location, LogError};

const FORMAT_POS: &str = "RTKLIB .pos";
const FORMAT_TAG: &str = "RTKLIB .tag";

fn malformed(at: Location, format: &'static str, message: impl Into<String>) -> LogError {
    LogError::Malformed {
        at,
        format,
        message: message.into(),
    }
}

/// Column indices (into the fields after the two time fields) of a `.pos` layout.
#[derive(Debug, Default)]
struct PosColumns {
    names: Vec<String>,
    lat: usize,
    lon: usize,
    h: usize,
    q: usize,
    ns: Option<usize>,
    sd: [usize; 3],
    vel: Option<[usize; 3]>,
    sdv: Option<[usize; 3]>,
}

fn parse_pos_header(line: &str, path: &str, line_no: usize) -> Result<PosColumns, LogError> {
    let body = line.trim_start_matches('%');
    let toks: Vec<&str> = body
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .collect();
    let at = Location::line(path, line_no);
    match toks.first().copied() {
        Some("GPST") => {}
        Some(ts @ ("UTC" | "JST" | "BJT")) => {
            return Err(malformed(
                at,
                FORMAT_POS,
                format!(
                    "time system {ts} is not supported (it needs leap seconds); output the solution in GPST (RTKLIB option out-timesys=gpst)"
                ),
            ));
        }
        other => {
            return Err(malformed(
                at,
                FORMAT_POS,
                format!("column header must start with the time system GPST, found {other:?}"),
            ));
        }
    }
    let names: Vec<String> = toks[1..].iter().map(|s| s.to_string()).collect();
    let find = |n: &str| names.iter().position(|x| x == n);
    let need = |n: &str| {
        find(n).ok_or_else(|| {
            malformed(
                Location::line(path, line_no),
                FORMAT_POS,
                format!("column header lacks the column {n}"),
            )
        })
    };
    let lat = need("latitude(deg)")?;
    let vel = match (find("vn(m/s)"), find("ve(m/s)"), find("vu(m/s)")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let sdv = match (find("sdvn"), find("sdve"), find("sdvu")) {
        (Some(a), Some(b), Some(c)) if vel.is_some() => Some([a, b, c]),
        _ => None,
    };
    Ok(PosColumns {
        lat,
        lon: need("longitude(deg)")?,
        h: need("height(m)")?,
        q: need("Q")?,
        ns: find("ns"),
        sd: [need("sdn(m)")?, need("sde(m)")?, need("sdu(m)")?],
        vel,
        sdv,
        names,
    })
}

/// Parses the two time fields of an epoch.
fn parse_pos_time(
    f0: Field<'_>,
    f1: Field<'_>,
    path: &str,
    line: usize,
) -> Result<GpsTime, LogError> {
    let bad = |f: Field<'_>, field: usize, name: &str| LogError::NonNumeric {
        at: Location::field(path, line, f.col),
        value: crate::io::error::excerpt(f.text.as_bytes()),
        field,
        name: name.to_owned(),
    };
    if f0.text.contains('/') {
        let d: Vec<&str> = f0.text.split('/').collect();
        let t: Vec<&str> = f1.text.split(':').collect();
        if d.len() != 3 {
            return Err(bad(f0, 1, "date (YYYY/MM/DD)"));
        }
        if t.len() != 3 {
            return Err(bad(f1, 2, "time (HH:MM:SS)"));
        }
        let (Ok(year), Ok(month), Ok(day)) = (d[0].parse(), d[1].parse(), d[2].parse()) else {
            return Err(bad(f0, 1, "date (YYYY/MM/DD)"));
        };
        let (Ok(hour), Ok(minute), Ok(second)) = (t[0].parse(), t[1].parse(), t[2].parse::<f64>())
        else {
            return Err(bad(f1, 2, "time (HH:MM:SS)"));
        };
        let c = Calendar {
            year,
            month,
            day,
            hour,
            minute,
            second,
        };
        GpsTime::from_calendar(&c).ok_or_else(|| LogError::InvalidValue {
            at: Location::field(path, line, f0.col),
            message: format!("invalid or pre-1980 GPST date/time {} {}", f0.text, f1.text),
        })
    } else {
        let week: u16 = f0.text.parse().map_err(|_| bad(f0, 1, "GPS week"))?;
        let sow = parse_num(f1, path, line, 2, "GPS seconds of week")?;
        if !(0.0..super::gpstime::SECONDS_PER_WEEK).contains(&sow) {
            return Err(LogError::InvalidValue {
                at: Location::field(path, line, f1.col),
                message: format!("seconds of week {sow} outside [0, 604800)"),
            });
        }
        Ok(GpsTime { week, sow_s: sow })
    }
}

fn small_int(
    v: f64,
    max: u8,
    f: Field<'_>,
    path: &str,
    line: usize,
    name: &str,
) -> Result<u8, LogError> {
    if v.fract() != 0.0 || v < 0.0 || v > f64::from(max) {
        return Err(LogError::InvalidValue {
            at: Location::field(path, line, f.col),
            message: format!("column {name} must be an integer in [0, {max}], found {v}"),
        });
    }
    Ok(v as u8)
}

/// Reads an RTKLIB `.pos` file (see the module docs).
pub fn read_rtklib_pos_file(
    path: impl AsRef<Path>,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, LogError> {
    let path = path.as_ref();
    read_rtklib_pos(&read_text_file(path)?, &path.display().to_string(), opts)
}

/// Reads RTKLIB `.pos` text from memory; `name` is used in error messages. `time_s` is
/// seconds of the week of the first epoch (`gps_week`).
pub fn read_rtklib_pos(
    bytes: &[u8],
    name: &str,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, LogError> {
    let text = as_utf8(bytes, name)?;
    let mut cols: Option<PosColumns> = None;
    let mut epochs = PosEpochs::default();
    let mut header_line = 0;
    let (first_epoch, last_epoch) = edge_epoch_lines(text);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let l = raw.strip_suffix('\r').unwrap_or(raw);
        if l.trim().is_empty() {
            continue;
        }
        if l.starts_with('%') {
            if let Some(c) = parse_pos_comment(l, name, line, !epochs.out.is_empty())? {
                cols = Some(c);
                header_line = line;
            }
            continue;
        }
        let Some(c) = cols.as_ref() else {
            return Err(malformed(
                Location::line(name, line),
                FORMAT_POS,
                "epoch before the column header line (`%  GPST  latitude(deg) …`)",
            ));
        };
        let fields = split_fields(l, b" \t,");
        let expected = c.names.len() + 2;
        let edge = if Some(line) == first_epoch && last_epoch.is_some() {
            Some(Edge::First)
        } else if Some(line) == last_epoch {
            Some(Edge::Last)
        } else {
            None
        };
        if let Some(edge) = edge {
            let texts: Vec<&[u8]> = fields.iter().map(|f| f.text.as_bytes()).collect();
            // A cut first epoch line shows as missing fields; its first field is a date.
            let cut = cut_record(&texts, expected, header_line, edge)
                .filter(|cut| edge == Edge::Last || matches!(cut, Cut::Fields { .. }));
            if let Some(cut) = cut {
                epochs
                    .out
                    .notes
                    .push(note(name, line, edge, &cut, l.as_bytes()));
                continue;
            }
        }
        if fields.len() != expected {
            let col = fields.get(expected).map_or(l.len() + 1, |f| f.col);
            return Err(LogError::Ragged {
                at: Location::field(name, line, col),
                found: fields.len(),
                expected,
                reference_line: header_line,
            });
        }
        let time_s = epochs.epoch_time(fields[0], fields[1], name, line)?;
        epochs.push(c, &fields, time_s, name, line, opts)?;
    }
    epochs.finish(cols, name)
}

/// The 1-based lines of the first and the last epoch (the last only when it differs
/// from the first): the records that may have been cut.
fn edge_epoch_lines(text: &str) -> (Option<usize>, Option<usize>) {
    let is_epoch = |l: &[u8]| {
        let t = l.trim_ascii();
        !t.is_empty() && !l.starts_with(b"%")
    };
    let first_epoch = text
        .lines()
        .position(|l| is_epoch(l.as_bytes()))
        .map(|i| i + 1);
    let last_epoch = last_data_line(text.as_bytes(), is_epoch)
        .map(|(ls, _, _)| line_of_offset(text.as_bytes(), ls))
        .filter(|&l| Some(l) != first_epoch);
    (first_epoch, last_epoch)
}

/// A `%` comment line: the parsed columns when it is the column header, `None` for
/// other comments; an error for unsupported coordinate formats or a header after
/// epochs (`after_epochs`).
fn parse_pos_comment(
    l: &str,
    name: &str,
    line: usize,
    after_epochs: bool,
) -> Result<Option<PosColumns>, LogError> {
    if l.contains("x-ecef(m)") || l.contains("e-baseline(m)") || l.contains("latitude(d'") {
        return Err(malformed(
            Location::line(name, line),
            FORMAT_POS,
            "only latitude/longitude in decimal degrees is supported (RTKLIB out-solformat=llh, out-degform=deg)",
        ));
    }
    if !l.contains("latitude(deg)") {
        return Ok(None);
    }
    if after_epochs {
        return Err(malformed(
            Location::line(name, line),
            FORMAT_POS,
            "a second column header after the first epoch",
        ));
    }
    parse_pos_header(l, name, line).map(Some)
}

/// The epochs of a `.pos` file read so far, with the optional columns kept apart
/// until the header says whether they exist.
#[derive(Default)]
struct PosEpochs {
    out: GnssFixes,
    vel: Vec<[f64; 3]>,
    sdv: Vec<[f64; 3]>,
    ns: Vec<u8>,
    prev: Option<f64>,
    week0: Option<u16>,
}

impl PosEpochs {
    /// Parses an epoch's time as seconds since the first epoch's GPS week and checks it
    /// follows the previous epoch.
    fn epoch_time(
        &mut self,
        f0: Field<'_>,
        f1: Field<'_>,
        name: &str,
        line: usize,
    ) -> Result<f64, LogError> {
        let t = parse_pos_time(f0, f1, name, line)?;
        let w0 = *self.week0.get_or_insert(t.week);
        if t.week < w0 {
            return Err(LogError::NonMonotonicTime {
                at: Location::line(name, line),
                field: 1,
                name: "GPST".into(),
                time_s: t.seconds_since_week(w0),
                previous_s: self.prev.unwrap_or(0.0),
            });
        }
        let time_s = t.seconds_since_week(w0);
        check_time_order(time_s, self.prev, name, line, 1, "GPST")?;
        self.prev = Some(time_s);
        Ok(time_s)
    }

    /// Parses and checks the value fields of an epoch at `time_s` and appends it.
    fn push(
        &mut self,
        c: &PosColumns,
        fields: &[Field<'_>],
        time_s: f64,
        name: &str,
        line: usize,
        opts: &GnssReadOptions,
    ) -> Result<(), LogError> {
        let mut v = Vec::with_capacity(c.names.len());
        for (k, f) in fields[2..].iter().enumerate() {
            v.push(parse_num(*f, name, line, k + 3, &c.names[k])?);
        }
        let fld = |k: usize| fields[k + 2];
        check_lat_lon(v[c.lat], v[c.lon], name, line, fld(c.lat), fld(c.lon))?;
        let mut sig = [0.0; 3];
        for (s, &k) in sig.iter_mut().zip(&c.sd) {
            *s = check_sigma(
                v[k],
                false,
                opts,
                Location::field(name, line, fld(k).col),
                &c.names[k],
            )?;
        }
        let out = &mut self.out;
        out.time_s.push(time_s);
        out.lat_rad.push(v[c.lat].to_radians());
        out.lon_rad.push(v[c.lon].to_radians());
        out.height_m.push(v[c.h]);
        out.sigma_ned_m.push(sig);
        out.quality
            .push(small_int(v[c.q], 7, fld(c.q), name, line, "Q")?);
        if let Some(k) = c.ns {
            self.ns
                .push(small_int(v[k], u8::MAX, fld(k), name, line, "ns")?);
        }
        if let Some([n, e, u]) = c.vel {
            self.vel.push([v[n], v[e], -v[u]]);
        }
        if let Some(ks) = c.sdv {
            let mut s = [0.0; 3];
            for (o, &k) in s.iter_mut().zip(&ks) {
                *o = check_sigma(
                    v[k],
                    true,
                    opts,
                    Location::field(name, line, fld(k).col),
                    &c.names[k],
                )?;
            }
            self.sdv.push(s);
        }
        Ok(())
    }

    /// The fixes, with the optional columns the header `cols` has; an error when no
    /// epoch was read.
    fn finish(self, cols: Option<PosColumns>, name: &str) -> Result<GnssFixes, LogError> {
        let mut out = self.out;
        if out.is_empty() {
            return Err(LogError::Empty {
                at: Location::input(name),
            });
        }
        out.gps_week = self.week0;
        if let Some(c) = cols {
            if c.ns.is_some() {
                out.n_sats = Some(self.ns);
            }
            if c.vel.is_some() {
                out.vel_ned_m_s = Some(self.vel);
            }
            if c.sdv.is_some() {
                out.sigma_vel_ned_m_s = Some(self.sdv);
            }
        }
        Ok(out)
    }
}

/// Size of the file-position field in `.tag` records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FposSize {
    /// Choose from the data: 4 bytes when the body is a whole number of 8-byte records
    /// with non-decreasing ticks and positions, else 8 bytes under the same test.
    #[default]
    Auto,
    /// 4-byte positions (RTKLIB default).
    Four,
    /// 8-byte positions (RTKLIB stream option `::P=8`).
    Eight,
}

/// A parsed RTKLIB `.tag` time-tag file.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeTag {
    /// The header text, e.g. `TIMETAG RTKLIB demo5`.
    pub header: String,
    /// Host tick at the start of the recording, ms.
    pub tick_f_ms: u32,
    /// Start time (GPST) as RTKLIB stores it: whole seconds since 1970-01-01 (GPST scale).
    pub start_gtime_s: u32,
    /// Fraction of a second of the start time, s.
    pub start_frac_s: f64,
    /// Start time as GPS week and seconds of week.
    pub start: GpsTime,
    /// Tick of each record, ms since the start.
    pub ticks_ms: Vec<u32>,
    /// Byte position in the data file after each record's write.
    pub fpos: Vec<u64>,
    /// The record layout that was read.
    pub fpos_size: FposSize,
}

/// The first bytes of every `.tag` file.
const TAG_MAGIC: &[u8] = b"TIMETAG RTKLIB";
/// Header size: 60 bytes of text + 4-byte tick.
const TAG_HEADER: usize = 64;
/// Header + 4-byte seconds + 8-byte fraction.
const TAG_BODY_START: usize = 76;

/// Reads an RTKLIB `.tag` file.
pub fn read_rtklib_tag_file(path: impl AsRef<Path>, fpos: FposSize) -> Result<TimeTag, LogError> {
    use std::io::Read;
    let path = path.as_ref();
    let name = path.display().to_string();
    let io = |error| LogError::Io {
        path: name.clone(),
        error,
    };
    // The header first: anything without the magic (a wrong path, `/dev/zero`) is refused
    // before the rest is read.
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    (&mut file)
        .take(TAG_BODY_START as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.starts_with(TAG_MAGIC) {
        file.read_to_end(&mut bytes).map_err(io)?;
    }
    read_rtklib_tag(&bytes, &name, fpos)
}

fn u32_at(b: &[u8], off: usize) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[off..off + 4]);
    u32::from_le_bytes(a)
}

fn records(body: &[u8], size: usize) -> Option<(Vec<u32>, Vec<u64>)> {
    if !body.len().is_multiple_of(4 + size) {
        return None;
    }
    let n = body.len() / (4 + size);
    let (mut t, mut p) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for r in body.chunks_exact(4 + size) {
        t.push(u32_at(r, 0));
        p.push(if size == 4 {
            u64::from(u32_at(r, 4))
        } else {
            let mut a = [0u8; 8];
            a.copy_from_slice(&r[4..12]);
            u64::from_le_bytes(a)
        });
    }
    Some((t, p))
}

fn first_decrease(v: &[impl PartialOrd]) -> Option<usize> {
    v.windows(2).position(|w| w[1] < w[0]).map(|i| i + 1)
}

/// Reads RTKLIB `.tag` bytes; `name` is used in error messages (which give byte offsets:
/// a binary file has no lines).
pub fn read_rtklib_tag(bytes: &[u8], name: &str, fpos: FposSize) -> Result<TimeTag, LogError> {
    let at = || Location::input(name);
    if bytes.len() < TAG_BODY_START {
        return Err(LogError::Truncated {
            at: at(),
            message: format!(
                "RTKLIB time-tag header needs {TAG_BODY_START} bytes, file has {}",
                bytes.len()
            ),
        });
    }
    if !bytes.starts_with(TAG_MAGIC) {
        return Err(malformed(
            at(),
            FORMAT_TAG,
            format!(
                "does not start with \"TIMETAG RTKLIB\" (found {:?})",
                crate::io::error::excerpt(&bytes[..TAG_MAGIC.len()])
            ),
        ));
    }
    let text = &bytes[..TAG_HEADER - 4];
    let end = text.iter().position(|&b| b == 0).unwrap_or(text.len());
    let header = String::from_utf8_lossy(&text[..end]).into_owned();
    let tick_f_ms = u32_at(bytes, 60);
    let start_gtime_s = u32_at(bytes, 64);
    let mut a = [0u8; 8];
    a.copy_from_slice(&bytes[68..76]);
    let start_frac_s = f64::from_le_bytes(a);
    if !(0.0..1.0).contains(&start_frac_s) {
        return Err(malformed(
            at(),
            FORMAT_TAG,
            format!("start-time fraction {start_frac_s} at byte 68 is not in [0, 1)"),
        ));
    }
    let start = GpsTime::from_gtime(i64::from(start_gtime_s), start_frac_s).ok_or_else(|| {
        malformed(
            at(),
            FORMAT_TAG,
            format!("start time {start_gtime_s} s since 1970 is before the GPS epoch"),
        )
    })?;
    let body = &bytes[TAG_BODY_START..];
    let ordered =
        |r: &(Vec<u32>, Vec<u64>)| first_decrease(&r.0).is_none() && first_decrease(&r.1).is_none();
    let (ticks_ms, fpos_v, size) = match fpos {
        FposSize::Four | FposSize::Eight => {
            let size = if fpos == FposSize::Four { 4 } else { 8 };
            let rec = 4 + size;
            let Some((t, p)) = records(body, size) else {
                let whole = body.len() / rec;
                return Err(LogError::Truncated {
                    at: at(),
                    message: format!(
                        "time-tag record {} at byte {} has {} of {rec} bytes",
                        whole + 1,
                        TAG_BODY_START + whole * rec,
                        body.len() % rec
                    ),
                });
            };
            if let Some(i) = first_decrease(&t) {
                return Err(malformed(
                    at(),
                    FORMAT_TAG,
                    format!(
                        "tick goes backwards at record {} (byte {})",
                        i + 1,
                        TAG_BODY_START + i * rec
                    ),
                ));
            }
            (t, p, fpos)
        }
        FposSize::Auto => {
            if let Some(r) = records(body, 4).filter(ordered) {
                (r.0, r.1, FposSize::Four)
            } else if let Some(r) = records(body, 8).filter(ordered) {
                (r.0, r.1, FposSize::Eight)
            } else if !body.len().is_multiple_of(4) {
                let whole = body.len() / 8;
                return Err(LogError::Truncated {
                    at: at(),
                    message: format!(
                        "time-tag record {} at byte {} has {} of 8 bytes",
                        whole + 1,
                        TAG_BODY_START + whole * 8,
                        body.len() % 8
                    ),
                });
            } else {
                return Err(malformed(
                    at(),
                    FORMAT_TAG,
                    "records are neither 8-byte nor 12-byte (tick, file position) pairs with increasing ticks and positions (truncated or corrupt)",
                ));
            }
        }
    };
    Ok(TimeTag {
        header,
        tick_f_ms,
        start_gtime_s,
        start_frac_s,
        start,
        ticks_ms,
        fpos: fpos_v,
        fpos_size: size,
    })
}

/// How device ticks of a tick-stamped data file (e.g. the IMU CSV's `tick [ms]` column)
/// are mapped to GPS time with a `.tag` file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TickMapping {
    /// First device tick → the tag's start time; last device tick → start + the tag's
    /// last record tick; linear in between. This rescales the device clock to the host
    /// clock over the recording; it is what the data's authors do
    /// (rtklibexplorer/GNSS_IMU `convert_imu_file.py`).
    #[default]
    Stretch,
    /// First device tick → the tag's start time, then 1 ms per tick (device clock trusted).
    Offset,
}

/// GPS times of a tick-stamped series.
#[derive(Clone, Debug, PartialEq)]
pub struct TaggedTimes {
    /// GPS week of the tag's start.
    pub gps_week: u16,
    /// Seconds of week `gps_week` (may pass 604 800 across a week boundary).
    pub time_s: Vec<f64>,
}

/// Maps device ticks \[ms\] to GPS time with a `.tag` file (see [`TickMapping`]).
/// `ticks_ms` must be finite and strictly increasing; `name` and `first_line` (the line of
/// `ticks_ms[0]` in the caller's file) locate errors.
pub fn map_ticks_to_gps(
    tag: &TimeTag,
    ticks_ms: &[f64],
    mapping: TickMapping,
    name: &str,
    first_line: usize,
) -> Result<TaggedTimes, LogError> {
    let (Some(&t0), Some(&tn)) = (ticks_ms.first(), ticks_ms.last()) else {
        return Err(LogError::Empty {
            at: Location::input(name),
        });
    };
    for (i, &t) in ticks_ms.iter().enumerate() {
        if !t.is_finite() {
            return Err(LogError::InvalidValue {
                at: Location::line(name, first_line + i),
                message: format!("non-finite tick {t}"),
            });
        }
        if i > 0 {
            check_time_order(t, Some(ticks_ms[i - 1]), name, first_line + i, 0, "tick_ms")?;
        }
    }
    let scale = match mapping {
        TickMapping::Offset => 1e-3,
        TickMapping::Stretch => {
            let span_s = tag.ticks_ms.last().map_or(0.0, |&t| f64::from(t) * 1e-3);
            if span_s <= 0.0 || tn <= t0 {
                return Err(LogError::InvalidOptions {
                    at: Location::input(name),
                    message: "the stretch mapping needs at least two device ticks and a time-tag file with records".into(),
                });
            }
            span_s / (tn - t0)
        }
    };
    let start = tag.start.sow_s;
    Ok(TaggedTimes {
        gps_week: tag.start.week,
        time_s: ticks_ms.iter().map(|&t| start + (t - t0) * scale).collect(),
    })
}

/// Writes fixes as an RTKLIB `.pos` file (GPST, `WWWW SSSSSS.sss` time, latitude and
/// longitude in degrees, ellipsoidal height, `Q`, `ns`, σ north/east/up, zero
/// cross-covariances, age 0, ratio 0, and the velocity block when `g` has velocities),
/// laid out as RTKLIB's `outsols` does; [`read_rtklib_pos`] reads it back. Time goes to
/// 1 ms, angles to 1e-9 deg (0.1 mm), heights and σ to 0.1 mm.
pub fn write_rtklib_pos(
    mut w: impl std::io::Write,
    name: &str,
    g: &GnssFixes,
    program: &str,
) -> Result<(), LogError> {
    let n = super::types::common_len(&[
        ("time_s", g.time_s.len()),
        ("lat_rad", g.lat_rad.len()),
        ("lon_rad", g.lon_rad.len()),
        ("height_m", g.height_m.len()),
        ("sigma_ned_m", g.sigma_ned_m.len()),
        ("quality", g.quality.len()),
    ])
    .map_err(|message| LogError::InvalidLog {
        at: Location::input(name),
        message,
    })?;
    let vel = match (&g.vel_ned_m_s, &g.sigma_vel_ned_m_s) {
        (Some(v), Some(s)) if v.len() == n && s.len() == n => Some((v, s)),
        (None, _) => None,
        _ => {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: "velocities without matching σ or of another length".into(),
            });
        }
    };
    let io = |error| LogError::Io {
        path: name.to_owned(),
        error,
    };
    let week = g.gps_week.unwrap_or(0);
    writeln!(w, "% program   : {program}").map_err(io)?;
    writeln!(w, "% pos mode  : simulated").map_err(io)?;
    writeln!(w, "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)").map_err(io)?;
    write!(
        w,
        "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio"
    )
    .map_err(io)?;
    if vel.is_some() {
        write!(
            w,
            "    vn(m/s)    ve(m/s)    vu(m/s)      sdvn     sdve     sdvu    sdvne    sdveu    sdvun"
        )
        .map_err(io)?;
    }
    writeln!(w).map_err(io)?;
    for i in 0..n {
        let s = g.sigma_ned_m[i];
        let vals = [
            g.time_s[i],
            g.lat_rad[i],
            g.lon_rad[i],
            g.height_m[i],
            s[0],
            s[1],
            s[2],
        ];
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: format!("non-finite value {v} in fix {i}"),
            });
        }
        let ns = g
            .n_sats
            .as_ref()
            .and_then(|v| v.get(i))
            .copied()
            .unwrap_or(0);
        // seconds of week may pass 604 800 within one file: carry into the week
        let wk_carry = (g.time_s[i] / 604_800.0).floor();
        let sow = g.time_s[i] - wk_carry * 604_800.0;
        write!(
            w,
            "{:4} {:10.3} {:14.9} {:14.9} {:10.4} {:3} {:3} {:8.4} {:8.4} {:8.4} {:8.4} {:8.4} {:8.4} {:6.2} {:6.1}",
            i64::from(week) + wk_carry as i64,
            sow,
            g.lat_rad[i].to_degrees(),
            g.lon_rad[i].to_degrees(),
            g.height_m[i],
            g.quality[i],
            ns,
            s[0],
            s[1],
            s[2],
            0.0,
            0.0,
            0.0,
            0.0,
            0.0
        )
        .map_err(io)?;
        if let Some((v, sv)) = vel {
            let (v, sv) = (v[i], sv[i]);
            if v.iter().chain(&sv).any(|x| !x.is_finite()) {
                return Err(LogError::InvalidLog {
                    at: Location::input(name),
                    message: format!("non-finite velocity in fix {i}"),
                });
            }
            write!(
                w,
                " {:10.5} {:10.5} {:10.5} {:9.5} {:8.5} {:8.5} {:8.5} {:8.5} {:8.5}",
                v[0], v[1], -v[2], sv[0], sv[1], sv[2], 0.0, 0.0, 0.0
            )
            .map_err(io)?;
        }
        writeln!(w).map_err(io)?;
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    const POS: &str = "\
% program   : handmade test fixture
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST            latitude(deg) longitude(deg) height(m) Q  ns  sdn(m) sde(m) sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio vn(m/s) ve(m/s) vu(m/s) sdvn sdve sdvu sdvne sdveu sdvun
2025/07/08 19:34:18.500 40.0 -105.0 1601.5 1 21 0.01 0.02 0.03 0 0 0 0.0 3.2 1.0 2.0 0.5 0.05 0.06 0.07 0 0 0
2025/07/08 19:34:18.750 40.1 -105.1 1601.6 2 20 0.01 0.02 0.03 0 0 0 0.0 3.2 1.0 2.0 -0.5 0.05 0.06 0.07 0 0 0
";

    #[test]
    fn pos_with_velocity() {
        let g = read_rtklib_pos(POS.as_bytes(), "p.pos", &GnssReadOptions::default()).unwrap();
        assert_eq!(g.len(), 2);
        assert_eq!(g.gps_week, Some(2374));
        assert_eq!(g.time_s, vec![243_258.5, 243_258.75]);
        assert!((g.lat_rad[1] - 40.1f64.to_radians()).abs() < 1e-15);
        assert_eq!(g.quality, vec![1, 2]);
        assert_eq!(g.n_sats, Some(vec![21, 20]));
        assert_eq!(g.sigma_ned_m[0], [0.01, 0.02, 0.03]);
        // NEU → NED.
        assert_eq!(g.vel_ned_m_s.as_ref().unwrap()[0], [1.0, 2.0, -0.5]);
        assert_eq!(g.vel_ned_m_s.as_ref().unwrap()[1], [1.0, 2.0, 0.5]);
        assert_eq!(g.sigma_vel_ned_m_s.as_ref().unwrap()[1], [0.05, 0.06, 0.07]);
    }

    #[test]
    fn pos_week_tow_without_velocity() {
        let t = "%  GPST latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio\n\
                 2374 604799.000 40 -105 1600 5 8 1.5 1.5 3 0 0 0 0 0\n\
                 2375 0.500 40 -105 1600 5 8 1.5 1.5 3 0 0 0 0 0\n";
        let g = read_rtklib_pos(t.as_bytes(), "p", &GnssReadOptions::default()).unwrap();
        assert_eq!(g.gps_week, Some(2374));
        // Across the week boundary the column keeps increasing.
        assert_eq!(g.time_s, vec![604_799.0, 604_800.5]);
        assert!(g.vel_ned_m_s.is_none() && g.sigma_vel_ned_m_s.is_none());
    }

    #[test]
    fn pos_cut_edges() {
        let opts = GnssReadOptions::default();
        let hdr = POS.lines().take(3).collect::<Vec<_>>().join("\n") + "\n";
        let rows: Vec<&str> = POS.lines().skip(3).collect();
        let mid = rows[1].replace("18.750", "19.000");
        let last = rows[1].replace("18.750", "19.250");
        let clean = format!("{hdr}{}\n{}\n{mid}\n{last}\n", rows[0], rows[1]);
        let whole = read_rtklib_pos(clean.as_bytes(), "p.pos", &opts).unwrap();
        assert_eq!(whole.len(), 4);
        assert!(whole.notes.is_empty());
        // The logger stopped inside the last epoch's velocity block, without a line end.
        let cut_at = last.len() - 12;
        let cut = format!("{hdr}{}\n{}\n{mid}\n{}", rows[0], rows[1], &last[..cut_at]);
        let g = read_rtklib_pos(cut.as_bytes(), "p.pos", &opts).unwrap();
        assert_eq!(g.time_s, whole.time_s[..3].to_vec());
        assert_eq!(g.lat_rad, whole.lat_rad[..3].to_vec());
        assert_eq!(g.notes.len(), 1);
        assert!(
            g.notes[0].starts_with("p.pos:7: dropped the last record")
                && g.notes[0].contains("line 3 has 24"),
            "{}",
            g.notes[0]
        );
        // A cut first epoch line (fewer fields) is dropped too.
        let first_cut = &rows[0][30..];
        let t = format!("{hdr}{first_cut}\n{}\n{mid}\n", rows[1]);
        let g = read_rtklib_pos(t.as_bytes(), "p.pos", &opts).unwrap();
        assert_eq!(g.time_s, whole.time_s[1..3].to_vec());
        assert!(g.notes[0].starts_with("p.pos:4: dropped the first record"));
        // The same short row in the middle stays an error.
        let t = format!("{hdr}{}\n{}\n{mid}\n", rows[0], &rows[1][..cut_at]);
        let e = read_rtklib_pos(t.as_bytes(), "p.pos", &opts).unwrap_err();
        assert!(e.to_string().starts_with("p.pos:5:"), "{e}");
    }

    #[test]
    fn pos_errors() {
        let opts = GnssReadOptions::default();
        let hdr = POS.lines().take(3).collect::<Vec<_>>().join("\n") + "\n";
        let row = POS.lines().nth(3).unwrap();
        // Missing column.
        let t = format!("{hdr}{}\n", row.rsplit_once(' ').unwrap().0);
        let e = read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Ragged {
                    found: 23,
                    expected: 24,
                    reference_line: 3,
                    ..
                }
            ),
            "{e}"
        );
        // Extra column.
        let t = format!("{hdr}{row} 9\n");
        assert!(matches!(
            read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err(),
            LogError::Ragged { found: 25, .. }
        ));
        // Non-numeric latitude, named by column.
        let t = format!("{hdr}{}\n", row.replace(" 40.0 ", " 4O.0 "));
        let e = read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err();
        assert_eq!(
            e.to_string(),
            "p:4:25: non-numeric value \"4O.0\" in column 3 (latitude(deg))"
        );
        // Bad time.
        let t = format!("{hdr}{}\n", row.replace("19:34:18.500", "19:34"));
        assert!(matches!(
            read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err(),
            LogError::NonNumeric { field: 2, .. }
        ));
        // Duplicated and out-of-order epochs.
        let t = format!("{hdr}{row}\n{row}\n");
        let e = read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err();
        assert!(
            matches!(e, LogError::DuplicateTime { .. }) && e.line() == Some(5),
            "{e}"
        );
        let earlier = row.replace("18.500", "17.000");
        let t = format!("{hdr}{row}\n{earlier}\n");
        assert!(matches!(
            read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err(),
            LogError::NonMonotonicTime { .. }
        ));
        // σ = 0.
        let t = format!("{hdr}{}\n", row.replace(" 0.02 0.03 ", " 0 0.03 "));
        let e = read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err();
        assert!(
            e.to_string()
                .contains("standard deviation 0 in column sde(m)"),
            "{e}"
        );
        // Q not an integer flag.
        let t = format!("{hdr}{}\n", row.replace(" 1 21 ", " 1.5 21 "));
        assert!(read_rtklib_pos(t.as_bytes(), "p", &opts).is_err());
        // UTC, ECEF, no header.
        let t = hdr.replace("GPST", "UTC ") + row + "\n";
        let e = read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err();
        assert!(e.to_string().contains("leap seconds"), "{e}");
        let t = "%  GPST x-ecef(m) y-ecef(m) z-ecef(m) Q ns\n";
        assert!(matches!(
            read_rtklib_pos(t.as_bytes(), "p", &opts).unwrap_err(),
            LogError::Malformed { .. }
        ));
        let e = read_rtklib_pos(format!("{row}\n").as_bytes(), "p", &opts).unwrap_err();
        assert!(e.to_string().contains("before the column header"), "{e}");
        assert!(matches!(
            read_rtklib_pos(hdr.as_bytes(), "p", &opts).unwrap_err(),
            LogError::Empty { .. }
        ));
    }

    /// A small tag file built byte by byte from the documented layout.
    fn tag_bytes(records: &[(u32, u32)]) -> Vec<u8> {
        let mut b = vec![0u8; 64];
        b[..20].copy_from_slice(b"TIMETAG RTKLIB test1");
        b[60..64].copy_from_slice(&1000u32.to_le_bytes());
        b.extend_from_slice(&1_752_003_261u32.to_le_bytes());
        b.extend_from_slice(&0.5f64.to_le_bytes());
        for &(t, p) in records {
            b.extend_from_slice(&t.to_le_bytes());
            b.extend_from_slice(&p.to_le_bytes());
        }
        b
    }

    #[test]
    fn tag_reads_and_maps() {
        let b = tag_bytes(&[(100, 40), (200, 80), (10_000, 4000)]);
        let tag = read_rtklib_tag(&b, "t.tag", FposSize::Auto).unwrap();
        assert_eq!(tag.header, "TIMETAG RTKLIB test1");
        assert_eq!(tag.tick_f_ms, 1000);
        assert_eq!(tag.start.week, 2374);
        assert_eq!(tag.start.sow_s, 243_261.5);
        assert_eq!(tag.ticks_ms, vec![100, 200, 10_000]);
        assert_eq!(tag.fpos, vec![40, 80, 4000]);
        assert_eq!(tag.fpos_size, FposSize::Four);
        // Device ticks 5000..=25000 ms (20 s) stretched onto the tag's 10 s.
        let m = map_ticks_to_gps(
            &tag,
            &[5000.0, 15_000.0, 25_000.0],
            TickMapping::Stretch,
            "imu",
            1,
        )
        .unwrap();
        assert_eq!(m.gps_week, 2374);
        assert_eq!(m.time_s, vec![243_261.5, 243_266.5, 243_271.5]);
        let m = map_ticks_to_gps(&tag, &[5000.0, 6000.5], TickMapping::Offset, "imu", 1).unwrap();
        assert_eq!(m.time_s, vec![243_261.5, 243_262.500_5]);
        let e =
            map_ticks_to_gps(&tag, &[1.0, 3.0, 2.0], TickMapping::Offset, "imu", 10).unwrap_err();
        assert!(
            matches!(e, LogError::NonMonotonicTime { .. }) && e.line() == Some(12),
            "{e}"
        );
    }

    #[test]
    fn tag_truncated_and_corrupt() {
        let b = tag_bytes(&[(100, 40), (200, 80)]);
        // Header cut.
        let e = read_rtklib_tag(&b[..70], "t.tag", FposSize::Auto).unwrap_err();
        assert!(matches!(e, LogError::Truncated { .. }), "{e}");
        // Last record cut (3 of 8 bytes).
        let e = read_rtklib_tag(&b[..b.len() - 5], "t.tag", FposSize::Four).unwrap_err();
        assert!(matches!(e, LogError::Truncated { .. }), "{e}");
        assert!(
            e.to_string()
                .contains("record 2 at byte 84 has 3 of 8 bytes"),
            "{e}"
        );
        let e = read_rtklib_tag(&b[..b.len() - 5], "t.tag", FposSize::Auto).unwrap_err();
        assert!(matches!(e, LogError::Truncated { .. }), "{e}");
        // Not a tag file.
        let mut bad = b.clone();
        bad[0] = b'X';
        assert!(matches!(
            read_rtklib_tag(&bad, "t.tag", FposSize::Auto).unwrap_err(),
            LogError::Malformed { .. }
        ));
        // Ticks going backwards.
        let b = tag_bytes(&[(200, 40), (100, 80)]);
        assert!(read_rtklib_tag(&b, "t.tag", FposSize::Four).is_err());
        assert!(read_rtklib_tag(&b, "t.tag", FposSize::Auto).is_err());
    }

    fn data_dir() -> std::path::PathBuf {
        std::env::var("DRIFTLESS_DATA").map_or_else(
            |_| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
            std::path::PathBuf::from,
        )
    }

    #[test]
    #[ignore = "needs shared data"]
    fn drive_pos_and_tag() {
        let dir = data_dir().join("drive/drive_0708");
        let g = read_rtklib_pos_file(dir.join("gnss_1934_sf.pos"), &GnssReadOptions::default())
            .unwrap();
        assert_eq!(g.len(), 2197);
        let fixed = g.quality.iter().filter(|&&q| q == 1).count() as f64 / g.len() as f64;
        assert!(fixed > 0.995 && fixed < 0.997, "Q=1 fraction {fixed}");
        assert_eq!(g.gps_week, Some(2374));
        // 19:34:18.499 .. 19:43:27 GPST on Tuesday 2025-07-08.
        assert!((g.time_s[0] - 243_258.499).abs() < 1e-6, "{}", g.time_s[0]);
        let last = *g.time_s.last().unwrap();
        assert!((243_807.0..243_808.0).contains(&last), "{last}");
        assert!(g.vel_ned_m_s.is_some() && g.sigma_vel_ned_m_s.is_some());
        let lat = g.lat_rad[0].to_degrees();
        assert!((lat - 40.0966268).abs() < 1e-9 && (g.height_m[0] - 1601.474).abs() < 1e-9);
        println!(
            "pos: {} epochs, Q=1 {:.2} %, {:.3}..{:.3} s of week {}",
            g.len(),
            fixed * 100.0,
            g.time_s[0],
            last,
            2374
        );

        let tag = read_rtklib_tag_file(dir.join("imu_1934.csv.tag"), FposSize::Auto).unwrap();
        assert!(tag.header.starts_with("TIMETAG RTKLIB"));
        assert_eq!(tag.fpos_size, FposSize::Four);
        assert_eq!(tag.start.week, 2374);
        assert!(
            (tag.start.sow_s - 243_261.854).abs() < 1e-6,
            "{}",
            tag.start.sow_s
        );
        let csv = std::fs::read_to_string(dir.join("imu_1934.csv")).unwrap();
        let ticks: Vec<f64> = csv
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.rsplit(',').next().unwrap().trim().parse().unwrap())
            .collect();
        assert_eq!(ticks.len(), 54_860);
        let m = map_ticks_to_gps(&tag, &ticks, TickMapping::Stretch, "imu_1934.csv", 1).unwrap();
        let (t0, t1) = (m.time_s[0], *m.time_s.last().unwrap());
        // The IMU span must overlap the RTK span, and cover most of it.
        assert!(t0 < last && t1 > g.time_s[0]);
        let overlap = t1.min(last) - t0.max(g.time_s[0]);
        assert!(overlap > 540.0, "overlap {overlap} s");
        assert!((t1 - t0 - 548.731).abs() < 1e-6, "span {}", t1 - t0);
        let o = map_ticks_to_gps(&tag, &ticks, TickMapping::Offset, "imu_1934.csv", 1).unwrap();
        // Device ticks span 548.590 s where the host's tag spans 548.731 s: trusting the
        // device clock (Offset) ends 0.141 s (≈ 257 ppm) earlier than Stretch.
        let d = o.time_s.last().unwrap() - t1;
        assert!((d + 0.141).abs() < 1e-3, "offset-vs-stretch {d}");
        println!(
            "tag: start {:.3}, IMU {:.3}..{:.3} s ({} ticks, {} tag records), overlap {overlap:.3} s, offset-vs-stretch end {:.4} s",
            tag.start.sow_s,
            t0,
            t1,
            ticks.len(),
            tag.ticks_ms.len(),
            o.time_s.last().unwrap() - t1
        );
    }

    #[test]
    fn pos_writer_round_trips() {
        let g = GnssFixes {
            gps_week: Some(2345),
            time_s: vec![356_400.0, 356_401.0, 604_800.5],
            lat_rad: vec![0.531_3, 0.531_300_01, 0.531_300_02],
            lon_rad: vec![1.997_9, 1.997_900_02, 1.997_900_04],
            height_m: vec![21.5, 21.25, 21.125],
            sigma_ned_m: vec![[0.01, 0.012, 0.03]; 3],
            vel_ned_m_s: Some(vec![[1.5, -2.25, 0.125]; 3]),
            sigma_vel_ned_m_s: Some(vec![[0.02, 0.02, 0.04]; 3]),
            quality: vec![1, 2, 1],
            n_sats: Some(vec![12, 11, 12]),
            notes: Vec::new(),
        };
        let mut buf = Vec::new();
        write_rtklib_pos(&mut buf, "x.pos", &g, "test").unwrap();
        let back = read_rtklib_pos(&buf, "x.pos", &GnssReadOptions::default()).unwrap();
        assert_eq!(back.gps_week, Some(2345));
        assert_eq!(back.time_s, g.time_s);
        assert_eq!(back.quality, g.quality);
        assert_eq!(back.n_sats, g.n_sats);
        assert_eq!(back.sigma_ned_m, g.sigma_ned_m);
        assert_eq!(back.vel_ned_m_s, g.vel_ned_m_s);
        for i in 0..3 {
            assert!((back.lat_rad[i] - g.lat_rad[i]).abs() < 1e-11);
            assert!((back.lon_rad[i] - g.lon_rad[i]).abs() < 1e-11);
            assert!((back.height_m[i] - g.height_m[i]).abs() < 1e-4);
        }
        let mut no_vel = g.clone();
        no_vel.vel_ned_m_s = None;
        no_vel.sigma_vel_ned_m_s = None;
        let mut buf = Vec::new();
        write_rtklib_pos(&mut buf, "x.pos", &no_vel, "test").unwrap();
        let back = read_rtklib_pos(&buf, "x.pos", &GnssReadOptions::default()).unwrap();
        assert!(back.vel_ned_m_s.is_none());
        no_vel.height_m[1] = f64::NAN;
        assert!(write_rtklib_pos(&mut Vec::new(), "x.pos", &no_vel, "t").is_err());
    }
}

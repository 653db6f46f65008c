//! KF-GINS text formats (i2Nav-WHU/KF-GINS, GPL-3.0). Formats learnt from its README
//! ("2.2 Data format"), `src/fileio/{fileloader.cc,imufileloader.h,gnssfileloader.h,
//! filesaver.cc}` and `src/kf_gins.cpp`; no code taken.
//!
//! **Input files.** One epoch per line; fields separated by any run of spaces, tabs or
//! commas (KF-GINS splits on `", \t"` and skips empty pieces). No header, no comments.
//! KF-GINS feeds every field to `strtod` without checks; here every field must be a finite
//! number, every row must have as many fields as the reference row (the first, unless it is
//! shorter than the rows after it; see `io::edge`), and time must strictly increase —
//! otherwise one [`LogError`] names the file, line and column. Blank lines are skipped
//! (KF-GINS stops reading at the first blank line). A truncated first or last record (fewer
//! fields than the reference row, or a cut field that is not a number: what a logger that
//! starts or stops mid-line leaves) is dropped and reported in the result's `notes`.
//!
//! * IMU (`imupath`): `time [GPS s of week], dθx, dθy, dθz [rad], dvx, dvy, dvz [m/s]`,
//!   increments over the interval ending at `time`, body frame forward-right-down. KF-GINS
//!   reads `imudatalen` ≥ 7 columns and uses the first 7 (an 8th is an odometer speed,
//!   m/s); extra columns are accepted and ignored here too.
//! * GNSS (`gnsspath`): 7 columns `time [s], lat [deg], lon [deg], h [m], σN, σE, σD [m]`,
//!   or 13 columns, which KF-GINS's loader reads as `time, lat, lon, h, vN, vE, vD [m/s],
//!   σN, σE, σD [m], σvN, σvE, σvD [m/s]` (it takes σ from columns 8–10 of a 13-column file;
//!   the velocity meaning of columns 5–7 and 11–13 follows its comment "13-column GNSS
//!   files contain GNSS velocity").
//!
//! **Output files** (written by `kf_gins.cpp` into `outputpath`): every value printed with
//! C's `"%-15.9lf "` (left-aligned, width 15, 9 decimals, one space after), lines ending
//! in `\n`:
//! * `KF_GINS_Navresult.nav`: `week, time [s], lat [deg], lon [deg], h [m], vN, vE, vD
//!   [m/s], roll, pitch, yaw [deg]` — KF-GINS always writes 0 as the week, and yaw in
//!   \[0°, 360°) ([`kfgins_heading_rad`]; the writers here write the yaw they are given).
//! * `KF_GINS_IMU_ERR.txt`: `time, gyro bias xyz [deg/h], accel bias xyz [mGal], gyro
//!   scale xyz [ppm], accel scale xyz [ppm]`.
//! * `KF_GINS_STD.txt`: `time, pos NED [m], vel NED [m/s], att [deg], gyro bias [deg/h],
//!   accel bias [mGal], gyro scale [ppm], accel scale [ppm]` (22 columns).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::types::{GnssFixes, ImuErrors, ImuIncrements, NavSolution, NavStd, common_len};
use super::{
    Field, as_utf8, check_time_order, parse_num, read_text_file, read_text_file_parallel,
    split_fields, split_fields_into,
};
use crate::io::edge::{
    Edge, REFERENCE_SAMPLE, cut_record, last_data_line, line_of_offset, note, reference_count,
};
use crate::io::output::AtomicFile;
use crate::io::{Location, LogError};

/// Field separators of KF-GINS's text loader.
const SEPS: &[u8] = b", \t\r";

/// Degrees per radian.
const R2D: f64 = 180.0 / std::f64::consts::PI;
/// 1 mGal = 1e-5 m/s².
const MGAL_PER_M_S2: f64 = 1e5;
/// 1 ppm = 1e-6.
const PPM: f64 = 1e6;

/// File names KF-GINS writes into `outputpath`.
pub(crate) const NAV_FILE: &str = "KF_GINS_Navresult.nav";
/// IMU-error file name.
pub(crate) const IMU_ERR_FILE: &str = "KF_GINS_IMU_ERR.txt";
/// State-std file name.
pub(crate) const STD_FILE: &str = "KF_GINS_STD.txt";

/// What a GNSS reader does with a standard deviation of zero.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum ZeroSigma {
    /// σ = 0 is an error naming the field (default): a zero σ makes a measurement
    /// infinitely trusted, which a Kalman filter cannot digest.
    #[default]
    Error,
    /// Replace σ below the floor (zero included) by the floor; negative σ is still an error.
    Floor {
        /// Floor for position σ, m (must be > 0).
        pos_m: f64,
        /// Floor for velocity σ, m/s (must be > 0).
        vel_m_s: f64,
    },
}

/// Options of the GNSS readers (KF-GINS and RTKLIB).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct GnssReadOptions {
    /// Handling of σ = 0.
    pub zero_sigma: ZeroSigma,
}

/// Applies the σ policy to one σ value.
pub(crate) fn check_sigma(
    v: f64,
    vel: bool,
    opts: &GnssReadOptions,
    at: Location,
    name: &str,
) -> Result<f64, LogError> {
    if v < 0.0 {
        return Err(LogError::InvalidValue {
            at,
            message: format!("negative standard deviation {v} in column {name}"),
        });
    }
    match opts.zero_sigma {
        ZeroSigma::Error if v == 0.0 => Err(LogError::InvalidValue {
            at,
            message: format!(
                "standard deviation 0 in column {name}: a zero σ would make the fix infinitely trusted; set a σ floor (ZeroSigma::Floor) to accept it"
            ),
        }),
        ZeroSigma::Error => Ok(v),
        ZeroSigma::Floor { pos_m, vel_m_s } => {
            let floor = if vel { vel_m_s } else { pos_m };
            if !(floor > 0.0 && floor.is_finite()) {
                return Err(LogError::InvalidOptions {
                    at: Location::input(&at.path),
                    message: format!("σ floor must be finite and > 0, got {floor}"),
                });
            }
            Ok(v.max(floor))
        }
    }
}

/// Checks latitude and longitude ranges (degrees) of one epoch.
pub(crate) fn check_lat_lon(
    lat_deg: f64,
    lon_deg: f64,
    path: &str,
    line: usize,
    lat_f: Field<'_>,
    lon_f: Field<'_>,
) -> Result<(), LogError> {
    if !(-90.0..=90.0).contains(&lat_deg) {
        return Err(LogError::InvalidValue {
            at: Location::field(path, line, lat_f.col),
            message: format!("latitude {lat_deg} deg outside [-90, 90]"),
        });
    }
    if !(-360.0..=360.0).contains(&lon_deg) {
        return Err(LogError::InvalidValue {
            at: Location::field(path, line, lon_f.col),
            message: format!("longitude {lon_deg} deg outside [-360, 360]"),
        });
    }
    Ok(())
}

/// Data lines of a text input: (1-based line number, line text), blank lines skipped.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty())
}

/// The rows of a KF-GINS input to parse, after the edge checks.
struct Body {
    /// Field count of every row.
    expected: usize,
    /// Its reference line.
    ref_line: usize,
    /// Byte range of the rows to parse and the 1-based line of its start.
    start: usize,
    end: usize,
    first_line: usize,
    /// Notes on dropped edge records.
    notes: Vec<String>,
}

/// Fixes the reference field count (`io::edge`) and drops a truncated first or last
/// record. `valid` checks the reference count (`Err(message)` names what the format
/// needs). A first row with another count that is not a cut record is an error citing
/// the reference row.
fn edge_body(
    text: &str,
    name: &str,
    format: &'static str,
    valid: impl Fn(usize) -> Result<(), String>,
) -> Result<Body, LogError> {
    let sample: Vec<(usize, &str)> = data_lines(text).take(REFERENCE_SAMPLE + 1).collect();
    let counts: Vec<(usize, usize)> = sample
        .iter()
        .map(|&(l, t)| (l, split_fields(t, SEPS).len()))
        .collect();
    let Some((expected, ref_line)) = reference_count(&counts) else {
        return Err(LogError::Empty {
            at: Location::input(name),
        });
    };
    if let Err(message) = valid(expected) {
        let len = sample
            .iter()
            .find(|s| s.0 == ref_line)
            .map_or(0, |s| s.1.len());
        return Err(LogError::Malformed {
            at: Location::field(name, ref_line, len + 1),
            format,
            message,
        });
    }
    let texts = |l: &str| -> Vec<Vec<u8>> {
        split_fields(l, SEPS)
            .iter()
            .map(|f| f.text.as_bytes().to_vec())
            .collect()
    };
    let mut body = Body {
        expected,
        ref_line,
        start: 0,
        end: text.len(),
        first_line: 1,
        notes: Vec::new(),
    };
    let (l0, t0) = sample[0];
    let f0 = texts(t0);
    let f0: Vec<&[u8]> = f0.iter().map(Vec::as_slice).collect();
    match cut_record(&f0, expected, ref_line, Edge::First) {
        Some(cut) if sample.len() > 1 => {
            body.notes
                .push(note(name, l0, Edge::First, &cut, t0.as_bytes()));
            // Start at the line after the dropped one.
            let off = t0.as_ptr() as usize - text.as_ptr() as usize + t0.len();
            body.start = text[off..].find('\n').map_or(text.len(), |p| off + p + 1);
            body.first_line = l0 + 1;
        }
        _ if f0.len() != expected => {
            let fields = split_fields(t0, SEPS);
            let col = fields.get(expected).map_or(t0.len() + 1, |f| f.col);
            return Err(LogError::Ragged {
                at: Location::field(name, l0, col),
                found: fields.len(),
                expected,
                reference_line: ref_line,
            });
        }
        _ => {}
    }
    let bytes = text.as_bytes();
    if let Some((ls, le, _)) = last_data_line(bytes, |l| !l.trim_ascii().is_empty())
        && ls >= body.start
        && !text[body.start..ls].trim().is_empty()
    {
        let l = text[ls..le].strip_suffix('\r').unwrap_or(&text[ls..le]);
        let f = texts(l);
        let f: Vec<&[u8]> = f.iter().map(Vec::as_slice).collect();
        if let Some(cut) = cut_record(&f, expected, ref_line, Edge::Last) {
            let line = line_of_offset(bytes, ls);
            body.notes
                .push(note(name, line, Edge::Last, &cut, l.as_bytes()));
            body.end = ls;
        }
    }
    Ok(body)
}

/// Checks the field count of a row against the first row's.
fn check_count(
    fields: &[Field<'_>],
    line_text: &str,
    expected: usize,
    reference_line: usize,
    path: &str,
    line: usize,
) -> Result<(), LogError> {
    if fields.len() != expected {
        let col = fields.get(expected).map_or(line_text.len() + 1, |f| f.col);
        return Err(LogError::Ragged {
            at: Location::field(path, line, col),
            found: fields.len(),
            expected,
            reference_line,
        });
    }
    Ok(())
}

const IMU_NAMES: [&str; 7] = [
    "time_s",
    "dtheta_x_rad",
    "dtheta_y_rad",
    "dtheta_z_rad",
    "dvel_x_m_s",
    "dvel_y_m_s",
    "dvel_z_m_s",
];

/// Reads a KF-GINS IMU text file (see the module docs for the format).
pub fn read_kfgins_imu_file(path: impl AsRef<Path>) -> Result<ImuIncrements, LogError> {
    let path = path.as_ref();
    read_kfgins_imu(&read_text_file_parallel(path)?, &path.display().to_string())
}

/// Reads KF-GINS IMU text from memory; `name` is used in error messages. Large inputs
/// are parsed in parallel blocks of whole lines; the first error in file order is
/// reported, as a sequential reader would.
pub fn read_kfgins_imu(bytes: &[u8], name: &str) -> Result<ImuIncrements, LogError> {
    read_imu_in_blocks(bytes, name, IMU_BLOCK_BYTES)
}

fn read_imu_in_blocks(
    bytes: &[u8],
    name: &str,
    block_bytes: usize,
) -> Result<ImuIncrements, LogError> {
    use rayon::prelude::*;
    let text = as_utf8(bytes, name)?;
    let body = edge_body(text, name, "KF-GINS IMU", |n| {
        if n < 7 {
            Err(format!(
                "rows have {n} fields; the format needs at least 7 (time, Δθ x y z, Δv x y z)"
            ))
        } else {
            Ok(())
        }
    })?;
    let (expected, ref_line) = (body.expected, body.ref_line);
    let blocks = line_blocks(
        &text[body.start..body.end],
        block_bytes.max(1),
        body.first_line,
    );
    let mut parts: Vec<ImuBlock> = blocks
        .par_iter()
        .map(|&(line0, block)| parse_imu_block(block, line0, expected, ref_line, name))
        .collect();
    let mut prev: Option<f64> = None;
    for part in &mut parts {
        // Time order across the block boundary, at the block's first data line.
        if let (Some(prev), Some(&t)) = (prev, part.data.time_s.first()) {
            check_time_order(t, Some(prev), name, part.first_data_line, 1, IMU_NAMES[0])?;
        }
        if let Some(e) = part.error.take() {
            return Err(e);
        }
        prev = part.data.time_s.last().copied().or(prev);
    }
    // The blocks copied into their places concurrently (and freed there): the page
    // faults of the columns and the copies shared by the cores.
    let n = parts.iter().map(|p| p.data.len()).sum();
    let mut out = ImuIncrements {
        time_s: vec![0.0; n],
        dtheta_rad: vec![[0.0; 3]; n],
        dvel_m_s: vec![[0.0; 3]; n],
        notes: body.notes,
    };
    let (mut t, mut a, mut v) = (
        &mut out.time_s[..],
        &mut out.dtheta_rad[..],
        &mut out.dvel_m_s[..],
    );
    let mut places = Vec::with_capacity(parts.len());
    for part in parts {
        let k = part.data.len();
        let (t0, t1) = std::mem::take(&mut t).split_at_mut(k);
        let (a0, a1) = std::mem::take(&mut a).split_at_mut(k);
        let (v0, v1) = std::mem::take(&mut v).split_at_mut(k);
        places.push((part, t0, a0, v0));
        (t, a, v) = (t1, a1, v1);
    }
    places.into_par_iter().for_each(|(part, t, a, v)| {
        t.copy_from_slice(&part.data.time_s);
        a.copy_from_slice(&part.data.dtheta_rad);
        v.copy_from_slice(&part.data.dvel_m_s);
    });
    Ok(out)
}

/// Target size of the blocks [`read_kfgins_imu`] parses in parallel, bytes.
const IMU_BLOCK_BYTES: usize = 1 << 22;

/// Splits `text` after newlines into blocks of about `target` bytes, each with the
/// 1-based number of its first line (`text` starts at line `first_line`).
fn line_blocks(text: &str, target: usize, first_line: usize) -> Vec<(usize, &str)> {
    use rayon::prelude::*;
    let bytes = text.as_bytes();
    let mut cuts = vec![0];
    let mut at = 0;
    while at + target < bytes.len() {
        let next = bytes[at + target..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| at + target + p + 1);
        cuts.push(next);
        at = next;
    }
    if *cuts.last().unwrap_or(&0) < bytes.len() {
        cuts.push(bytes.len());
    }
    // Cuts are just after a '\n' (ASCII), so every slice is on a char boundary.
    let pieces: Vec<&str> = cuts.windows(2).map(|w| &text[w[0]..w[1]]).collect();
    let newlines: Vec<usize> = pieces
        .par_iter()
        .map(|p| p.bytes().filter(|&b| b == b'\n').count())
        .collect();
    let mut line0 = first_line;
    pieces
        .into_iter()
        .zip(newlines)
        .map(|(p, nl)| {
            let block = (line0, p);
            line0 += nl;
            block
        })
        .collect()
}

/// One parsed block: the rows before the first error, and that error.
struct ImuBlock {
    data: ImuIncrements,
    first_data_line: usize,
    error: Option<LogError>,
}

fn parse_imu_block(
    block: &str,
    line0: usize,
    expected: usize,
    ref_line: usize,
    name: &str,
) -> ImuBlock {
    let mut out = ImuBlock {
        data: ImuIncrements::default(),
        first_data_line: line0,
        error: None,
    };
    let mut prev: Option<f64> = None;
    let mut fields = Vec::with_capacity(expected);
    for (k, (line, l)) in data_lines(block).enumerate() {
        let line = line + line0 - 1;
        if k == 0 {
            out.first_data_line = line;
        }
        let fast = if expected == 7 {
            imu_row_fast(l).filter(|v| prev.is_none_or(|p| v[0] > p))
        } else {
            None
        };
        let row = match fast {
            Some(v) => Ok(v),
            None => parse_imu_row(l, line, expected, ref_line, name, prev, &mut fields),
        };
        match row {
            Ok(v) => {
                prev = Some(v[0]);
                out.data.time_s.push(v[0]);
                out.data.dtheta_rad.push([v[1], v[2], v[3]]);
                out.data.dvel_m_s.push([v[4], v[5], v[6]]);
            }
            Err(e) => {
                out.error = Some(e);
                break;
            }
        }
    }
    out
}

/// The seven values of a well-formed 7-field IMU row in one pass over its bytes (each
/// field parsed where it starts by the exact fast path of the number scanner, which must
/// end at a separator or the line's end), or `None` for anything else — more or fewer
/// fields, a field that is not a plain number, a non-finite value — which
/// [`parse_imu_row`] then reads (same values, or the error naming line and column).
fn imu_row_fast(l: &str) -> Option<[f64; 7]> {
    // KF-GINS's separators (`SEPS`) as a bit mask.
    const MASK: u64 = 1 << b',' | 1 << b' ' | 1 << b'\t' | 1 << b'\r';
    let is_sep = |b: u8| b < 64 && MASK >> b & 1 == 1;
    let b = l.as_bytes();
    let mut v = [0.0; 7];
    let mut i = 0;
    let mut k = 0;
    loop {
        while i < b.len() && is_sep(b[i]) {
            i += 1;
        }
        if i == b.len() {
            break;
        }
        let slot = v.get_mut(k)?;
        let (x, used) = crate::io::number::parse_prefix(&b[i..])?;
        i += used;
        if (i < b.len() && !is_sep(b[i])) || !x.is_finite() {
            return None;
        }
        *slot = x;
        k += 1;
    }
    (k == 7).then_some(v)
}

fn parse_imu_row<'a>(
    l: &'a str,
    line: usize,
    expected: usize,
    ref_line: usize,
    name: &str,
    prev: Option<f64>,
    fields: &mut Vec<Field<'a>>,
) -> Result<[f64; 7], LogError> {
    split_fields_into(l, SEPS, fields);
    check_count(fields, l, expected, ref_line, name, line)?;
    let mut v = [0.0; 7];
    for (k, slot) in v.iter_mut().enumerate() {
        *slot = parse_num(fields[k], name, line, k + 1, IMU_NAMES[k])?;
    }
    // Extra columns (odometer, …) must still be numbers, as KF-GINS reads them.
    for (k, f) in fields.iter().enumerate().skip(7) {
        parse_num(*f, name, line, k + 1, "extra")?;
    }
    check_time_order(v[0], prev, name, line, 1, IMU_NAMES[0])?;
    Ok(v)
}

const GNSS_NAMES_7: [&str; 7] = [
    "time_s",
    "lat_deg",
    "lon_deg",
    "height_m",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
];
const GNSS_NAMES_13: [&str; 13] = [
    "time_s",
    "lat_deg",
    "lon_deg",
    "height_m",
    "vel_n_m_s",
    "vel_e_m_s",
    "vel_d_m_s",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
    "sigma_vel_n_m_s",
    "sigma_vel_e_m_s",
    "sigma_vel_d_m_s",
];

/// Reads a KF-GINS GNSS text file (7 or 13 columns, see the module docs).
pub fn read_kfgins_gnss_file(
    path: impl AsRef<Path>,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, LogError> {
    let path = path.as_ref();
    read_kfgins_gnss(&read_text_file(path)?, &path.display().to_string(), opts)
}

/// Reads KF-GINS GNSS text from memory; `name` is used in error messages. Quality flags
/// are [`super::quality::UNSPECIFIED`]; `gps_week` and `n_sats` are `None`.
pub fn read_kfgins_gnss(
    bytes: &[u8],
    name: &str,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, LogError> {
    let text = as_utf8(bytes, name)?;
    let body = edge_body(text, name, "KF-GINS GNSS", |n| {
        if n == 7 || n == 13 {
            Ok(())
        } else {
            Err(format!(
                "rows have {n} fields; the format has 7 (time, lat, lon, h, σ N E D) or 13 (with velocity and its σ)"
            ))
        }
    })?;
    let (expected, ref_line) = (body.expected, body.ref_line);
    let mut out = GnssFixes {
        notes: body.notes,
        ..GnssFixes::default()
    };
    let mut vel = Vec::new();
    let mut svel = Vec::new();
    let mut prev: Option<f64> = None;
    for (line, l) in data_lines(&text[body.start..body.end]) {
        let line = line + body.first_line - 1;
        let fields = split_fields(l, SEPS);
        check_count(&fields, l, expected, ref_line, name, line)?;
        let names: &[&str] = if expected == 7 {
            &GNSS_NAMES_7
        } else {
            &GNSS_NAMES_13
        };
        let mut v = [0.0; 13];
        for k in 0..expected {
            v[k] = parse_num(fields[k], name, line, k + 1, names[k])?;
        }
        check_time_order(v[0], prev, name, line, 1, names[0])?;
        prev = Some(v[0]);
        check_lat_lon(v[1], v[2], name, line, fields[1], fields[2])?;
        let s0 = if expected == 7 { 4 } else { 7 };
        let mut sig = [0.0; 3];
        for (i, slot) in sig.iter_mut().enumerate() {
            let k = s0 + i;
            *slot = check_sigma(
                v[k],
                false,
                opts,
                Location::field(name, line, fields[k].col),
                names[k],
            )?;
        }
        if expected == 13 {
            let mut sv = [0.0; 3];
            for (i, slot) in sv.iter_mut().enumerate() {
                let k = 10 + i;
                *slot = check_sigma(
                    v[k],
                    true,
                    opts,
                    Location::field(name, line, fields[k].col),
                    names[k],
                )?;
            }
            vel.push([v[4], v[5], v[6]]);
            svel.push(sv);
        }
        out.time_s.push(v[0]);
        out.lat_rad.push(v[1].to_radians());
        out.lon_rad.push(v[2].to_radians());
        out.height_m.push(v[3]);
        out.sigma_ned_m.push(sig);
        out.quality.push(super::quality::UNSPECIFIED);
    }
    if out.is_empty() {
        return Err(LogError::Empty {
            at: Location::input(name),
        });
    }
    if expected == 13 {
        out.vel_ned_m_s = Some(vel);
        out.sigma_vel_ned_m_s = Some(svel);
    }
    Ok(out)
}

/// Appends one value in KF-GINS's `"%-15.9lf "` format ([`put_value`], else the standard
/// formatter) after bytes of garbage: every byte of the value must be written.
#[cfg(test)]
fn push_value(line: &mut Vec<u8>, v: f64) {
    let len = line.len();
    line.resize(len + SLOW_MAX, 0xAA);
    let n = put_value(&mut line[len..], v).unwrap_or_else(|| put_slow(&mut line[len..], v));
    line.truncate(len + n);
}

/// Bytes [`put_value`] may touch.
const VALUE_MAX: usize = 24;

/// Bytes the standard formatter may write for one finite value in `"%-15.9lf "`: f64::MAX
/// has 309 integer digits, then the point, 9 decimals, a sign and the trailing space.
const SLOW_MAX: usize = 330;

/// Writes `v` in KF-GINS's `"%-15.9lf "` format (left-aligned, width 15, 9 decimals, one
/// space after) at the start of `out` (≥ [`VALUE_MAX`] bytes; the padding spaces are
/// written too) and returns the bytes written, or `None` when the fast path does not apply.
///
/// Fast path for |v| < 1e8: the integer part and 9 fractional digits by integer
/// arithmetic (the fraction v − trunc(v) is exact; its scaling by 1e9 errs by < 1e-6 of a
/// unit, so the rounding is the correctly rounded decimal except within 1e-6 of a tie,
/// where the standard formatter takes over), eight digits at a time in one register
/// ([`eight_digits`]) and stored with one 8-byte write. Output is identical to
/// `format!("{v:<15.9} ")`, several times faster — the writers emit ~33 M values per hour
/// of 200 Hz data.
#[inline(always)]
fn put_value(out: &mut [u8], v: f64) -> Option<usize> {
    let a = v.abs();
    if a.is_nan() || a >= 1.0e8 {
        return None;
    }
    // Truncation by conversion (exact below 2^53), no libm call; through i64, which
    // converts to and from f64 in one instruction (u64 needs a branchy sequence).
    let int0 = a as i64;
    let f = (a - int0 as f64) * 1e9;
    let f_floor = f as i64;
    let rem = f - f_floor as f64;
    if (rem - 0.5).abs() <= 1e-6 {
        return None;
    }
    let mut int = int0 as u64;
    let mut frac = f_floor as u64 + u64::from(rem > 0.5);
    if frac >= 1_000_000_000 {
        frac -= 1_000_000_000;
        int += 1;
        if int >= 100_000_000 {
            return None;
        }
    }
    let out = &mut out[..VALUE_MAX];
    // The padding (at most 19 bytes are digits, sign and point; the rest spaces).
    out.fill(b' ');
    let mut n = usize::from(v.is_sign_negative());
    out[0] = if n == 1 { b'-' } else { b' ' };
    if int < 10 {
        // One digit (σ's, biases, angles below 10): no digit split needed.
        out[n] = b'0' + int as u8;
        n += 1;
    } else {
        // The digit values (not yet ASCII), most significant first: the leading zero
        // digits are the low-order zero bytes (int ≥ 10, so at most six of them). The
        // integer's digits are the last `int_digits` of its eight; the zero bytes
        // shifted in behind them are overwritten by the point and the fraction.
        let digits = eight_digit_values(int as u32);
        let lead = (digits.trailing_zeros() / 8) as usize;
        let int_ascii = (digits + ASCII_ZEROS) >> (8 * lead);
        out[n..n + 8].copy_from_slice(&int_ascii.to_le_bytes());
        n += 8 - lead;
    }
    out[n] = b'.';
    out[n + 1] = b'0' + (frac / 100_000_000) as u8;
    out[n + 2..n + 10].copy_from_slice(&eight_digits((frac % 100_000_000) as u32).to_le_bytes());
    n += 10;
    Some(n.max(15) + 1)
}

/// Writes finite `v` in `"%-15.9lf "` with the standard formatter at the start of `out`
/// (≥ [`SLOW_MAX`] bytes) and returns the bytes written: the values [`put_value`] leaves.
fn put_slow(out: &mut [u8], v: f64) -> usize {
    let room = out.len();
    let mut rest = &mut out[..];
    // Cannot fail: `out` has room for any finite value (SLOW_MAX).
    let _ = write!(rest, "{v:<15.9} ");
    room - rest.len()
}

/// Eight ASCII `'0'` bytes.
const ASCII_ZEROS: u64 = 0x3030_3030_3030_3030;

/// The eight decimal digits of `x` < 10⁸ (zero-padded) as ASCII bytes of a little-endian
/// u64, the most significant digit first ([`eight_digit_values`] plus `'0'`).
fn eight_digits(x: u32) -> u64 {
    eight_digit_values(x) + ASCII_ZEROS
}

/// The eight decimal digits of `x` < 10⁸ (zero-padded) as byte values 0–9 of a
/// little-endian u64, the most significant digit first: x splits into two 4-digit halves
/// in 32-bit lanes, each into two 2-digit quarters in 16-bit lanes, each into two digits
/// in bytes, by multiply-shift division (x/100 = ⌊10486x / 2²⁰⌋ for x < 10⁴,
/// x/10 = ⌊103x / 2¹⁰⌋ for x < 100; no carry crosses a lane).
fn eight_digit_values(x: u32) -> u64 {
    let hi = u64::from(x / 10_000);
    let lo = u64::from(x % 10_000);
    let v = hi | (lo << 32);
    let q = ((v * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let v = q | ((v - q * 100) << 16);
    let q = ((v * 103) >> 10) & 0x000F_000F_000F_000F;
    q | ((v - q * 10) << 8)
}

#[cfg(test)]
mod push_value_tests {
    use super::push_value;

    #[test]
    fn matches_the_standard_formatter() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut checked = 0;
        for i in 0..1_000_000u64 {
            let r = next();
            let mag = 10f64.powi((r % 24) as i32 - 12);
            let v = match i % 5 {
                0 => (r >> 11) as f64 / (1u64 << 53) as f64 * mag,
                1 => -((r >> 11) as f64 / (1u64 << 53) as f64) * mag,
                2 => (r % 1_000_000_000) as f64 * 1e-9 + (r % 1000) as f64, // on the grid
                3 => 243_300.0 + (r >> 11) as f64 / (1u64 << 53) as f64 * 600.0,
                _ => f64::from_bits(r) % 5e9,
            };
            if !v.is_finite() {
                continue;
            }
            let mut fast = Vec::new();
            push_value(&mut fast, v);
            assert_eq!(fast, format!("{v:<15.9} ").as_bytes(), "value {v:e}");
            checked += 1;
        }
        for v in [
            0.0,
            -0.0,
            0.5e-9,
            1.5e-9,
            -2.5e-9,
            3_999_999_999.999_999_9,
            1e10,
            -1e12,
        ] {
            let mut fast = Vec::new();
            push_value(&mut fast, v);
            assert_eq!(fast, format!("{v:<15.9} ").as_bytes(), "value {v:e}");
        }
        assert!(checked > 900_000);
    }
}

/// Bytes a [`LineBuf`] collects before it is written out: 512 KiB, so that the three
/// files' buffers stay in a core's L2 cache while the kernel copies them into the page
/// cache (with 4 MiB buffers that copy was 3–4× slower: 0.8–1.2 s of system time per
/// hour of rows instead of 0.35–0.45 s).
const CHUNK: usize = 1 << 19;
/// Most values in one line of the output files (the std file's 22).
const MAX_COLS: usize = 22;

/// Staging buffer of an output file: lines of `"%-15.9lf "` values are formatted into a
/// buffer whose length is set once ([`CHUNK`] plus room for one line of the longest
/// values), behind a cursor, so a row costs no resize, fill or capacity check; the filled
/// part is written out once past [`CHUNK`].
struct LineBuf {
    buf: Vec<u8>,
    pos: usize,
}

impl LineBuf {
    fn new() -> Self {
        LineBuf {
            buf: vec![b' '; CHUNK + MAX_COLS * SLOW_MAX + 1],
            pos: 0,
        }
    }

    /// Appends `vals` as one line; `Err(k)`, nothing appended, when `vals[k]` is the first
    /// value that is not finite.
    fn line<const N: usize>(&mut self, vals: &[f64; N]) -> Result<(), usize> {
        const { assert!(N <= MAX_COLS) };
        if let Some(k) = vals.iter().position(|v| !v.is_finite()) {
            return Err(k);
        }
        let mut pos = self.pos;
        for &v in vals {
            let out = &mut self.buf[pos..];
            pos += match put_value(out, v) {
                Some(m) => m,
                None => put_slow(out, v),
            };
        }
        self.buf[pos] = b'\n';
        self.pos = pos + 1;
        Ok(())
    }

    fn is_full(&self) -> bool {
        self.pos >= CHUNK
    }

    /// Writes the filled part to `w` and empties the buffer.
    fn drain_to(&mut self, w: &mut impl Write, name: &str) -> Result<(), LogError> {
        let filled = &self.buf[..self.pos];
        self.pos = 0;
        w.write_all(filled).map_err(|error| io_error(name, error))
    }
}

/// The error of a value that is not finite in row `row` (0-based), column `col` (0-based).
fn non_finite(name: &str, v: f64, row: usize, col: usize) -> LogError {
    LogError::InvalidLog {
        at: Location::input(name),
        message: format!("non-finite value {v} in row {row}, column {}", col + 1),
    }
}

/// Writes `n` rows of values (`row(i)`) after checking that every value is finite;
/// `first_row` numbers the rows in error messages. The rows go through a [`LineBuf`]
/// kept per thread between calls (a fresh one per block of rows would be page-faulted and
/// zeroed by the kernel anew), handed to `w` in chunks of [`CHUNK`] bytes (a `BufWriter`
/// of at most that capacity passes them straight through). Does not flush.
fn write_rows<const N: usize>(
    w: &mut impl Write,
    name: &str,
    n: usize,
    first_row: usize,
    row: impl Fn(usize) -> [f64; N],
) -> Result<(), LogError> {
    thread_local! {
        static SCRATCH: std::cell::Cell<Option<Box<LineBuf>>> = const { std::cell::Cell::new(None) };
    }
    let mut buf = SCRATCH.take().unwrap_or_else(|| Box::new(LineBuf::new()));
    buf.pos = 0;
    let mut r = Ok(());
    for i in 0..n {
        let vals = row(i);
        if let Err(k) = buf.line(&vals) {
            r = Err(non_finite(name, vals[k], first_row + i, k));
            break;
        }
        if buf.is_full() {
            r = buf.drain_to(w, name);
            if r.is_err() {
                break;
            }
        }
    }
    if r.is_ok() {
        r = buf.drain_to(w, name);
    }
    buf.pos = 0;
    SCRATCH.set(Some(buf));
    r
}

fn io_error(name: &str, error: std::io::Error) -> LogError {
    LogError::Io {
        path: name.to_owned(),
        error,
    }
}

fn lens_err(name: &str, message: String) -> LogError {
    LogError::InvalidLog {
        at: Location::input(name),
        message,
    }
}

/// Writes increments as a KF-GINS IMU input file: `time [s], dθ xyz [rad], dv xyz [m/s]`,
/// space separated, time to 1 µs and increments with 13 significant digits (the `.nav`
/// output format's 9 decimals would cut 1e-5 rad increments to 4 digits).
pub fn write_kfgins_imu(
    mut w: impl Write,
    name: &str,
    imu: &ImuIncrements,
) -> Result<(), LogError> {
    let n = common_len(&[
        ("time_s", imu.time_s.len()),
        ("dtheta_rad", imu.dtheta_rad.len()),
        ("dvel_m_s", imu.dvel_m_s.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    let io_err = |error| LogError::Io {
        path: name.to_owned(),
        error,
    };
    for i in 0..n {
        let (a, b) = (imu.dtheta_rad[i], imu.dvel_m_s[i]);
        let vals = [imu.time_s[i], a[0], a[1], a[2], b[0], b[1], b[2]];
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: format!("non-finite value {v} in row {i}"),
            });
        }
        writeln!(
            w,
            "{:.6} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}",
            vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6]
        )
        .map_err(io_err)?;
    }
    w.flush().map_err(io_err)
}

/// Writes fixes as a 7-column KF-GINS GNSS input file: `time [s], lat, lon [deg], h [m],
/// σN, σE, σD [m]`.
pub fn write_kfgins_gnss(mut w: impl Write, name: &str, g: &GnssFixes) -> Result<(), LogError> {
    let n = common_len(&[
        ("time_s", g.time_s.len()),
        ("lat_rad", g.lat_rad.len()),
        ("lon_rad", g.lon_rad.len()),
        ("height_m", g.height_m.len()),
        ("sigma_ned_m", g.sigma_ned_m.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    let io_err = |error| LogError::Io {
        path: name.to_owned(),
        error,
    };
    for i in 0..n {
        let s = g.sigma_ned_m[i];
        let vals = [
            g.time_s[i],
            g.lat_rad[i] * R2D,
            g.lon_rad[i] * R2D,
            g.height_m[i],
            s[0],
            s[1],
            s[2],
        ];
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: format!("non-finite value {v} in row {i}"),
            });
        }
        writeln!(
            w,
            "{:.6} {:.11} {:.11} {:.4} {:.4} {:.4} {:.4}",
            vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6]
        )
        .map_err(io_err)?;
    }
    w.flush().map_err(io_err)
}

#[cfg(test)]
mod input_writer_tests {
    use super::*;

    #[test]
    fn imu_and_gnss_writers_round_trip_through_the_readers() {
        let imu = ImuIncrements {
            time_s: vec![100.005, 100.010],
            dtheta_rad: vec![[1.234_567_890_123e-5, -2e-6, 3e-7], [4e-5, 5e-5, -6e-5]],
            dvel_m_s: vec![[0.049_031, 1e-4, -2e-4], [0.05, 0.0, 0.001]],
            notes: Vec::new(),
        };
        let mut buf = Vec::new();
        write_kfgins_imu(&mut buf, "imu.txt", &imu).unwrap();
        let back = read_kfgins_imu(&buf, "imu.txt").unwrap();
        for i in 0..2 {
            assert!((back.time_s[i] - imu.time_s[i]).abs() < 1e-9);
            for k in 0..3 {
                assert!(
                    (back.dtheta_rad[i][k] - imu.dtheta_rad[i][k]).abs()
                        <= 1e-12 * imu.dtheta_rad[i][k].abs()
                );
                assert!(
                    (back.dvel_m_s[i][k] - imu.dvel_m_s[i][k]).abs()
                        <= 1e-12 * imu.dvel_m_s[i][k].abs()
                );
            }
        }
        let g = GnssFixes {
            time_s: vec![101.0, 102.0],
            lat_rad: vec![0.5, 0.500_001],
            lon_rad: vec![2.0, 2.000_001],
            height_m: vec![20.0, 20.5],
            sigma_ned_m: vec![[0.02, 0.02, 0.04]; 2],
            quality: vec![0; 2],
            ..GnssFixes::default()
        };
        let mut buf = Vec::new();
        write_kfgins_gnss(&mut buf, "gnss.txt", &g).unwrap();
        let back = read_kfgins_gnss(&buf, "gnss.txt", &GnssReadOptions::default()).unwrap();
        for i in 0..2 {
            // 11 decimals of a degree ≈ 1 µm on the ground
            assert!((back.lat_rad[i] - g.lat_rad[i]).abs() < 1e-12);
            assert!((back.lon_rad[i] - g.lon_rad[i]).abs() < 1e-12);
            assert_eq!(back.sigma_ned_m[i], g.sigma_ned_m[i]);
        }
    }
}

/// Writes a navigation solution in KF-GINS's `.nav` format (11 columns, see the module
/// docs); `gps_week` goes into column 1 (KF-GINS itself always writes 0).
pub fn write_kfgins_nav(
    mut w: impl Write,
    name: &str,
    sol: &NavSolution,
    gps_week: u16,
) -> Result<(), LogError> {
    append_nav(&mut w, name, sol, gps_week, 0)?;
    w.flush().map_err(|e| io_error(name, e))
}

/// One row of KF-GINS's three output files in SI units (angles in rad, as the column
/// structs [`NavSolution`], [`ImuErrors`] and [`NavStd`] hold them); the writers convert to
/// the files' units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KfGinsRow {
    /// GPS seconds of week, s.
    pub time_s: f64,
    /// Geodetic latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// Velocity north, east, down, m/s.
    pub vel_ned_m_s: [f64; 3],
    /// Roll, pitch, yaw, rad (written as given; KF-GINS's yaw range is
    /// [`kfgins_heading_rad`]).
    pub roll_pitch_yaw_rad: [f64; 3],
    /// Gyroscope bias x, y, z, rad/s.
    pub gyro_bias_rad_s: [f64; 3],
    /// Accelerometer bias x, y, z, m/s².
    pub accel_bias_m_s2: [f64; 3],
    /// Gyroscope scale-factor error x, y, z (dimensionless).
    pub gyro_scale: [f64; 3],
    /// Accelerometer scale-factor error x, y, z (dimensionless).
    pub accel_scale: [f64; 3],
    /// σ of position north, east, down, m.
    pub std_pos_ned_m: [f64; 3],
    /// σ of velocity north, east, down, m/s.
    pub std_vel_ned_m_s: [f64; 3],
    /// σ of roll, pitch, yaw, rad.
    pub std_att_rad: [f64; 3],
    /// σ of the gyroscope bias, rad/s.
    pub std_gyro_bias_rad_s: [f64; 3],
    /// σ of the accelerometer bias, m/s².
    pub std_accel_bias_m_s2: [f64; 3],
    /// σ of the gyroscope scale-factor error.
    pub std_gyro_scale: [f64; 3],
    /// σ of the accelerometer scale-factor error.
    pub std_accel_scale: [f64; 3],
}

/// Gyroscope bias, rad/s → deg/h.
fn deg_h(b: [f64; 3]) -> [f64; 3] {
    b.map(|x| x * R2D * 3600.0)
}

/// Values scaled by `k` (rad → deg, m/s² → mGal, 1 → ppm).
fn times(a: [f64; 3], k: f64) -> [f64; 3] {
    a.map(|x| x * k)
}

impl KfGinsRow {
    /// The `.nav` line: week, time, lat, lon [deg], h, v NED, roll, pitch, yaw [deg].
    fn nav_values(&self, gps_week: u16) -> [f64; 11] {
        let [vn, ve, vd] = self.vel_ned_m_s;
        let [r, p, y] = times(self.roll_pitch_yaw_rad, R2D);
        let h = self.height_m;
        let (lat, lon) = (self.lat_rad * R2D, self.lon_rad * R2D);
        [
            f64::from(gps_week),
            self.time_s,
            lat,
            lon,
            h,
            vn,
            ve,
            vd,
            r,
            p,
            y,
        ]
    }

    /// The IMU-error line: time, gyro bias [deg/h], accel bias [mGal], scales [ppm].
    fn imu_err_values(&self) -> [f64; 13] {
        let mut v = [self.time_s; 13];
        v[1..4].copy_from_slice(&deg_h(self.gyro_bias_rad_s));
        v[4..7].copy_from_slice(&times(self.accel_bias_m_s2, MGAL_PER_M_S2));
        v[7..10].copy_from_slice(&times(self.gyro_scale, PPM));
        v[10..13].copy_from_slice(&times(self.accel_scale, PPM));
        v
    }

    /// The std line: time, pos NED [m], vel NED [m/s], att [deg], gyro bias [deg/h],
    /// accel bias [mGal], scales [ppm].
    fn std_values(&self) -> [f64; 22] {
        let mut v = [self.time_s; 22];
        v[1..4].copy_from_slice(&self.std_pos_ned_m);
        v[4..7].copy_from_slice(&self.std_vel_ned_m_s);
        v[7..10].copy_from_slice(&times(self.std_att_rad, R2D));
        v[10..13].copy_from_slice(&deg_h(self.std_gyro_bias_rad_s));
        v[13..16].copy_from_slice(&times(self.std_accel_bias_m_s2, MGAL_PER_M_S2));
        v[16..19].copy_from_slice(&times(self.std_gyro_scale, PPM));
        v[19..22].copy_from_slice(&times(self.std_accel_scale, PPM));
        v
    }
}

fn append_nav(
    w: &mut impl Write,
    name: &str,
    sol: &NavSolution,
    gps_week: u16,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = common_len(&[
        ("time_s", sol.time_s.len()),
        ("lat_rad", sol.lat_rad.len()),
        ("lon_rad", sol.lon_rad.len()),
        ("height_m", sol.height_m.len()),
        ("vel_ned_m_s", sol.vel_ned_m_s.len()),
        ("roll_pitch_yaw_rad", sol.roll_pitch_yaw_rad.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    write_rows(w, name, n, first_row, |i| {
        nav_row(sol, i).nav_values(gps_week)
    })?;
    Ok(n)
}

/// Row `i` of `sol` (the navigation columns; the others zero).
fn nav_row(sol: &NavSolution, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: sol.time_s[i],
        lat_rad: sol.lat_rad[i],
        lon_rad: sol.lon_rad[i],
        height_m: sol.height_m[i],
        vel_ned_m_s: sol.vel_ned_m_s[i],
        roll_pitch_yaw_rad: sol.roll_pitch_yaw_rad[i],
        ..KfGinsRow::default()
    }
}

/// Row `i` of `e` (time and the IMU-error columns; the others zero).
fn imu_err_row(e: &ImuErrors, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: e.time_s[i],
        gyro_bias_rad_s: e.gyro_bias_rad_s[i],
        accel_bias_m_s2: e.accel_bias_m_s2[i],
        gyro_scale: e.gyro_scale[i],
        accel_scale: e.accel_scale[i],
        ..KfGinsRow::default()
    }
}

/// Row `i` of `s` (time and the std columns; the others zero).
fn std_row(s: &NavStd, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: s.time_s[i],
        std_pos_ned_m: s.pos_ned_m[i],
        std_vel_ned_m_s: s.vel_ned_m_s[i],
        std_att_rad: s.att_rad[i],
        std_gyro_bias_rad_s: s.gyro_bias_rad_s[i],
        std_accel_bias_m_s2: s.accel_bias_m_s2[i],
        std_gyro_scale: s.gyro_scale[i],
        std_accel_scale: s.accel_scale[i],
        ..KfGinsRow::default()
    }
}

/// Writes estimated IMU errors in KF-GINS's `KF_GINS_IMU_ERR.txt` format (13 columns).
pub fn write_kfgins_imu_err(mut w: impl Write, name: &str, e: &ImuErrors) -> Result<(), LogError> {
    append_imu_err(&mut w, name, e, 0)?;
    w.flush().map_err(|err| io_error(name, err))
}

/// Rows in `e` (all columns the same length).
fn imu_err_len(name: &str, e: &ImuErrors) -> Result<usize, LogError> {
    common_len(&[
        ("time_s", e.time_s.len()),
        ("gyro_bias_rad_s", e.gyro_bias_rad_s.len()),
        ("accel_bias_m_s2", e.accel_bias_m_s2.len()),
        ("gyro_scale", e.gyro_scale.len()),
        ("accel_scale", e.accel_scale.len()),
    ])
    .map_err(|m| lens_err(name, m))
}

fn append_imu_err(
    w: &mut impl Write,
    name: &str,
    e: &ImuErrors,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = imu_err_len(name, e)?;
    write_rows(w, name, n, first_row, |i| {
        imu_err_row(e, i).imu_err_values()
    })?;
    Ok(n)
}

/// Writes state standard deviations in KF-GINS's `KF_GINS_STD.txt` format (22 columns).
pub fn write_kfgins_std(mut w: impl Write, name: &str, s: &NavStd) -> Result<(), LogError> {
    append_std(&mut w, name, s, 0)?;
    w.flush().map_err(|e| io_error(name, e))
}

/// Rows in `s` (all columns the same length).
fn std_len(name: &str, s: &NavStd) -> Result<usize, LogError> {
    common_len(&[
        ("time_s", s.time_s.len()),
        ("pos_ned_m", s.pos_ned_m.len()),
        ("vel_ned_m_s", s.vel_ned_m_s.len()),
        ("att_rad", s.att_rad.len()),
        ("gyro_bias_rad_s", s.gyro_bias_rad_s.len()),
        ("accel_bias_m_s2", s.accel_bias_m_s2.len()),
        ("gyro_scale", s.gyro_scale.len()),
        ("accel_scale", s.accel_scale.len()),
    ])
    .map_err(|m| lens_err(name, m))
}

fn append_std(
    w: &mut impl Write,
    name: &str,
    s: &NavStd,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = std_len(name, s)?;
    write_rows(w, name, n, first_row, |i| std_row(s, i).std_values())?;
    Ok(n)
}

/// The three output paths in `dir`: `.nav`, IMU error, std.
fn output_paths(dir: &Path) -> [PathBuf; 3] {
    [NAV_FILE, IMU_ERR_FILE, STD_FILE].map(|f| dir.join(f))
}

/// Suffix of the smoothed solution's files: `KF_GINS_Navresult_smoothed.nav`,
/// `KF_GINS_IMU_ERR_smoothed.txt`, `KF_GINS_STD_smoothed.txt` (same formats).
pub const SMOOTHED_SUFFIX: &str = "_smoothed";

/// KF-GINS's three output file names with `suffix` before the extension (`""`: KF-GINS's
/// own names).
pub(crate) fn output_file_names(suffix: &str) -> [String; 3] {
    [NAV_FILE, IMU_ERR_FILE, STD_FILE].map(|f| match f.rsplit_once('.') {
        Some((stem, ext)) => format!("{stem}{suffix}.{ext}"),
        None => format!("{f}{suffix}"),
    })
}

/// Heading in KF-GINS's range \[0, 2π): its Euler conversion (`Rotation::matrix2euler`)
/// adds 2π to a negative `atan2` yaw, so its `.nav` files give yaw in \[0°, 360°).
pub fn kfgins_heading_rad(yaw_rad: f64) -> f64 {
    if yaw_rad < 0.0 {
        yaw_rad + 2.0 * std::f64::consts::PI
    } else {
        yaw_rad
    }
}

/// Writes one output file atomically ([`AtomicFile`]) through a 64 KiB buffer:
/// [`write_rows`] hands it whole chunks, which a buffer smaller than them passes straight
/// to the file.
fn write_output(
    p: &Path,
    body: impl FnOnce(std::io::BufWriter<&mut AtomicFile>, &str) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let name = p.display().to_string();
    let mut file = AtomicFile::create(p).map_err(|e| io_error(&name, e))?;
    body(std::io::BufWriter::with_capacity(1 << 16, &mut file), &name)?;
    file.commit().map_err(|e| io_error(&name, e))
}

/// Commits the three files of one run concurrently (each sync waits for its own data to
/// reach the disk).
fn commit_outputs(files: [AtomicFile; 3], names: &[String; 3]) -> Result<(), LogError> {
    let [a, b, c] = files;
    let commit = |f: AtomicFile, name: &str| f.commit().map_err(|e| io_error(name, e));
    let ((ra, rb), rc) = rayon::join(
        || rayon::join(|| commit(a, &names[0]), || commit(b, &names[1])),
        || commit(c, &names[2]),
    );
    ra.and(rb).and(rc)
}

/// KF-GINS's three output files, written row by row or block by block — e.g. on one
/// thread while a filter on another produces the rows
/// ([`crate::nav::filter::run_forward_observed`]). Each file has its own line buffer,
/// written to the file in chunks of 512 KiB.
pub struct KfGinsOutputWriter {
    files: [AtomicFile; 3],
    bufs: [Box<LineBuf>; 3],
    paths: [PathBuf; 3],
    names: [String; 3],
    rows: usize,
    gps_week: u16,
}

impl KfGinsOutputWriter {
    /// Starts the three files in `dir` (KF-GINS's `outputpath`, which must exist, as in
    /// KF-GINS). They replace earlier files of those names only in
    /// [`KfGinsOutputWriter::finish`]; dropped before, the earlier files stay.
    pub fn create(dir: impl AsRef<Path>, gps_week: u16) -> Result<Self, LogError> {
        Self::create_with_suffix(dir, gps_week, "")
    }

    /// [`KfGinsOutputWriter::create`] with `suffix` before each file's extension
    /// ([`output_file_names`], e.g. [`SMOOTHED_SUFFIX`]).
    pub(crate) fn create_with_suffix(
        dir: impl AsRef<Path>,
        gps_week: u16,
        suffix: &str,
    ) -> Result<Self, LogError> {
        let paths = output_file_names(suffix).map(|f| dir.as_ref().join(f));
        // Each file is new (a temporary name beside the final one), so ext4's flush of a
        // file truncated to zero when its handle closes (`auto_da_alloc`) does not apply;
        // the data is synced once, all three files at once, in `finish`.
        let create = |p: &Path| {
            AtomicFile::create(p)
                .map(|f| f.durable(false))
                .map_err(|e| io_error(&p.display().to_string(), e))
        };
        Ok(KfGinsOutputWriter {
            files: [create(&paths[0])?, create(&paths[1])?, create(&paths[2])?],
            bufs: [(); 3].map(|()| Box::new(LineBuf::new())),
            names: [0, 1, 2].map(|k| paths[k].display().to_string()),
            paths,
            rows: 0,
            gps_week,
        })
    }

    /// Appends one row to each file. A value that is not finite is an error naming the
    /// file, row (0-based) and column.
    pub fn append_row(&mut self, row: &KfGinsRow) -> Result<(), LogError> {
        let [nav, err, std] = &mut self.bufs;
        let r = self.rows;
        let names = &self.names;
        let nav_v = row.nav_values(self.gps_week);
        nav.line(&nav_v)
            .map_err(|k| non_finite(&names[0], nav_v[k], r, k))?;
        let err_v = row.imu_err_values();
        err.line(&err_v)
            .map_err(|k| non_finite(&names[1], err_v[k], r, k))?;
        let std_v = row.std_values();
        std.line(&std_v)
            .map_err(|k| non_finite(&names[2], std_v[k], r, k))?;
        self.rows += 1;
        for k in 0..3 {
            if self.bufs[k].is_full() {
                self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
            }
        }
        Ok(())
    }

    /// Appends one block of rows (all three parts the same length).
    pub fn append(
        &mut self,
        sol: &NavSolution,
        imu_err: &ImuErrors,
        std: &NavStd,
    ) -> Result<(), LogError> {
        // Rows appended one by one come first.
        for k in 0..3 {
            self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
        }
        let [nav_f, err_f, std_f] = &mut self.files;
        let (names, rows) = (&self.names, self.rows);
        let n = append_nav(nav_f, &names[0], sol, self.gps_week, rows)?;
        let m = append_imu_err(err_f, &names[1], imu_err, rows)?;
        let k = append_std(std_f, &names[2], std, rows)?;
        if n != m || n != k {
            return Err(lens_err(
                &self.names[0],
                format!("blocks of {n} solution, {m} IMU-error and {k} std rows"),
            ));
        }
        self.rows += n;
        Ok(())
    }

    /// Writes the rest of the rows, puts the three files under their final names and
    /// returns the paths: `.nav`, IMU error, std.
    pub fn finish(mut self) -> Result<[PathBuf; 3], LogError> {
        for k in 0..3 {
            self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
        }
        commit_outputs(self.files, &self.names)?;
        Ok(self.paths)
    }
}

/// Writes KF-GINS's three output files into `dir` (KF-GINS's `outputpath`, which must
/// exist, as in KF-GINS) and returns their paths: `.nav`, IMU error, std.
pub fn write_kfgins_outputs(
    dir: impl AsRef<Path>,
    sol: &NavSolution,
    imu_err: &ImuErrors,
    std: &NavStd,
    gps_week: u16,
) -> Result<[PathBuf; 3], LogError> {
    let paths = output_paths(dir.as_ref());
    // The three files are independent and formatting-bound: write them concurrently.
    let ((nav, err), std_res) = rayon::join(
        || {
            rayon::join(
                || write_output(&paths[0], |w, n| write_kfgins_nav(w, n, sol, gps_week)),
                || write_output(&paths[1], |w, n| write_kfgins_imu_err(w, n, imu_err)),
            )
        },
        || write_output(&paths[2], |w, n| write_kfgins_std(w, n, std)),
    );
    nav?;
    err?;
    std_res?;
    Ok(paths)
}

#[cfg(test)]
mod tests {
    use super::*;

    const IMU: &str = "\
456300.000 1.0e-5 -2.0e-5 3.0e-5 0.001 -0.002 0.049
456300.005, 1.1e-5, -2.1e-5, 3.1e-5, 0.0011, -0.0021, 0.0491
\t456300.010\t1.2e-5\t-2.2e-5\t3.2e-5\t0.0012\t-0.0022\t0.0492\r
";

    #[test]
    fn imu_blocks_parse_as_one() {
        let mut text = String::new();
        for i in 0..200 {
            if i % 17 == 3 {
                text.push_str("  \n");
            }
            text.push_str(&format!(
                "{:.3} {} -2e-5 3e-5, 0.001 -0.002 0.049\n",
                100.0 + 0.005 * i as f64,
                1e-5 * i as f64
            ));
        }
        let whole = read_imu_in_blocks(text.as_bytes(), "i", 1 << 30).unwrap();
        for block in [1, 7, 64, 333] {
            let parts = read_imu_in_blocks(text.as_bytes(), "i", block).unwrap();
            assert_eq!(parts, whole, "block size {block}");
        }
        assert_eq!(whole.len(), 200);
        // Errors: the first in file order, whatever the block size; a time-order error
        // across a block boundary is found.
        let lines: Vec<&str> = text.lines().collect();
        let mut bad = lines.clone();
        bad[150] = "oops";
        let swapped_a = lines[60].to_string();
        let mut bad2 = lines.clone();
        bad2[60] = lines[61];
        bad2[61] = &swapped_a;
        for (t, want) in [(bad.join("\n"), "i:151:5"), (bad2.join("\n"), "i:62")] {
            let whole = read_imu_in_blocks(t.as_bytes(), "i", 1 << 30)
                .unwrap_err()
                .to_string();
            assert!(whole.contains(want), "{whole}");
            for block in [1, 7, 64, 333] {
                let e = read_imu_in_blocks(t.as_bytes(), "i", block)
                    .unwrap_err()
                    .to_string();
                assert_eq!(e, whole, "block size {block}");
            }
        }
    }

    /// The file reader's chunks of whole lines give the in-memory result and errors
    /// (line numbers included) whatever the chunk size.
    #[test]
    fn imu_fast_rows_agree_with_the_field_reader() {
        let rows = [
            "456300.005 1.0e-5 -2.0e-5 3.0e-5 0.001 -0.002 0.049",
            "  456300.005,\t1.1e-5, -2.1e-5 ,3.1e-5,0.0011,-0.0021,+0.0491\r",
            "1 2 3 4 5 6 7",
            "0.1234567890123456789 2 3 4 5 6 7",
            "1e400 2 3 4 5 6 7",
            "1 2 3 4 5 6",
            "1 2 3 4 5 6 7 8",
            "1 2 3 4 5x 6 7",
            "1 2 3 4 5 6 nan",
            "1 2 3 4 5 6 .5",
            "1 2 3 4 5 6 7.",
            "1 2 3 4 5 6 1e-3",
        ];
        let mut fields = Vec::new();
        let mut fast_rows = 0;
        for l in rows {
            let general = parse_imu_row(l, 1, 7, 1, "imu", None, &mut fields).ok();
            match imu_row_fast(l) {
                Some(v) => {
                    fast_rows += 1;
                    assert_eq!(
                        Some(v.map(f64::to_bits)),
                        general.map(|g| g.map(f64::to_bits)),
                        "{l}"
                    );
                }
                // Not taken: the field reader decides (value or error).
                None => assert!(!matches!(l, "1 2 3 4 5 6 7" | "1 2 3 4 5 6 1e-3"), "{l}"),
            }
        }
        assert!(fast_rows >= 6);
    }

    #[test]
    fn imu_reads_all_separators() {
        let imu = read_kfgins_imu(IMU.as_bytes(), "imu.txt").unwrap();
        assert_eq!(imu.len(), 3);
        assert_eq!(imu.time_s, vec![456300.0, 456300.005, 456300.010]);
        assert_eq!(imu.dtheta_rad[1], [1.1e-5, -2.1e-5, 3.1e-5]);
        assert_eq!(imu.dvel_m_s[2], [0.0012, -0.0022, 0.0492]);
    }

    #[test]
    fn imu_eight_columns_ok_but_ragged_rejected() {
        let ok = "1 0 0 0 0 0 0 5.0\n2 0 0 0 0 0 0 5.1\n";
        assert_eq!(read_kfgins_imu(ok.as_bytes(), "i").unwrap().len(), 2);
        let extra = "1 0 0 0 0 0 0\n2 0 0 0 0 0 0 9\n3 0 0 0 0 0 0\n";
        let e = read_kfgins_imu(extra.as_bytes(), "i").unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Ragged {
                    found: 8,
                    expected: 7,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(
            e.to_string(),
            "i:2:15: row has 8 fields, expected 7 (as on line 1)"
        );
        let missing = "1 0 0 0 0 0 0\n2 0 0 0 0 0\n3 0 0 0 0 0 0\n";
        let e = read_kfgins_imu(missing.as_bytes(), "i").unwrap_err();
        assert!(matches!(e, LogError::Ragged { found: 6, .. }), "{e}");
        assert_eq!(e.line(), Some(2));
        // Too few columns for the format: the message names what it needs, not a line as
        // its own reference.
        let short = "1 0 0 0 0 0\n2 0 0 0 0 0\n";
        let e = read_kfgins_imu(short.as_bytes(), "i").unwrap_err();
        assert!(matches!(e, LogError::Malformed { .. }), "{e}");
        assert_eq!(
            e.to_string(),
            "i:1:12: malformed KF-GINS IMU: rows have 6 fields; the format needs at least 7 (time, Δθ x y z, Δv x y z)"
        );
    }

    #[test]
    fn imu_cut_edge_records_dropped_with_notes() {
        let whole: Vec<String> = (0..6)
            .map(|i| format!("{}.005 1e-5 -2e-5 3e-5 0.001 0.002 -0.0981", 100 + i))
            .collect();
        let clean = read_kfgins_imu(whole.join("\n").as_bytes(), "i").unwrap();
        assert!(clean.notes.is_empty());
        // Cut at the start (inside the time) and at the end (inside the last field).
        let mut cut = whole.clone();
        cut[0] = "5e-5 3e-5 0.001 0.002 -0.0981".into();
        cut[5] = "105.005 1e-5 -2e-5 3e-5 0.001 0.0".into();
        for block in [1 << 20, 40] {
            let r = read_imu_in_blocks(cut.join("\n").as_bytes(), "i", block).unwrap();
            assert_eq!(r.time_s, clean.time_s[1..5].to_vec());
            assert_eq!(r.dvel_m_s, clean.dvel_m_s[1..5].to_vec());
            assert_eq!(r.notes.len(), 2, "{:?}", r.notes);
            assert!(
                r.notes[0].starts_with("i:1: dropped the first record \"5e-5")
                    && r.notes[0].ends_with("it has 5 fields, line 2 has 7"),
                "{}",
                r.notes[0]
            );
            assert!(
                r.notes[1].starts_with("i:6: dropped the last record")
                    && r.notes[1].ends_with("it has 6 fields, line 2 has 7"),
                "{}",
                r.notes[1]
            );
        }
        // A last field cut to a non-number ("1.5e") is a cut record too.
        let mut num = whole.clone();
        num[5] = "105.005 1e-5 -2e-5 3e-5 0.001 0.002 -9.8e".into();
        let r = read_kfgins_imu(num.join("\n").as_bytes(), "i").unwrap();
        assert_eq!(r.len(), 5);
        assert!(
            r.notes[0].ends_with("its field 7 is not a number"),
            "{:?}",
            r.notes
        );
        // The same bad row inside the file is an error, and so is a second short row
        // after a dropped first one, citing a good reference line.
        let mut mid = whole.clone();
        mid[3] = "103.005 1e-5 -2e-5".into();
        let e = read_kfgins_imu(mid.join("\n").as_bytes(), "i").unwrap_err();
        assert_eq!(
            e.to_string(),
            "i:4:19: row has 3 fields, expected 7 (as on line 1)"
        );
        let mut two = whole.clone();
        two[0] = "1e-5 0.002 -0.0981".into();
        two[1] = "0.002 -0.0981".into();
        let e = read_kfgins_imu(two.join("\n").as_bytes(), "i").unwrap_err();
        assert_eq!(
            e.to_string(),
            "i:2:14: row has 2 fields, expected 7 (as on line 3)"
        );
        // A first row with more fields than the next ones is no cut record: an error at
        // line 2 citing line 1, as before.
        let mut long = whole;
        long[0].push_str(" 5.0");
        let e = read_kfgins_imu(long.join("\n").as_bytes(), "i").unwrap_err();
        assert!(e.to_string().starts_with("i:2:"), "{e}");
        assert!(e.to_string().ends_with("(as on line 1)"), "{e}");
    }

    #[test]
    fn imu_non_numeric_and_non_finite() {
        let bad = "1 0 0 0 0 0 0\n2 0 abc 0 0 0 0\n";
        let e = read_kfgins_imu(bad.as_bytes(), "imu.txt").unwrap_err();
        assert_eq!(
            e.to_string(),
            "imu.txt:2:5: non-numeric value \"abc\" in column 3 (dtheta_y_rad)"
        );
        let nan = "1 0 0 0 0 0 nan\n";
        assert!(matches!(
            read_kfgins_imu(nan.as_bytes(), "i").unwrap_err(),
            LogError::NonFinite { field: 7, .. }
        ));
        assert!(matches!(
            read_kfgins_imu(b"\n\n", "i").unwrap_err(),
            LogError::Empty { .. }
        ));
    }

    #[test]
    fn imu_time_order() {
        let dup = "1 0 0 0 0 0 0\n1 0 0 0 0 0 0\n";
        let e = read_kfgins_imu(dup.as_bytes(), "i").unwrap_err();
        assert!(
            matches!(e, LogError::DuplicateTime { time_s: 1.0, .. }),
            "{e}"
        );
        assert_eq!(e.line(), Some(2));
        let back = "1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n\n1.5 0 0 0 0 0 0\n";
        let e = read_kfgins_imu(back.as_bytes(), "i").unwrap_err();
        assert!(matches!(e, LogError::NonMonotonicTime { .. }), "{e}");
        assert_eq!(e.line(), Some(4));
    }

    const GNSS7: &str = "\
456250.000    30.4447858054   114.4718661162     21.095    0.010    0.009    0.019
456251.000    30.4447857891   114.4718661133     21.091    0.011    0.008    0.020
";

    #[test]
    fn gnss_seven_columns() {
        let g = read_kfgins_gnss(GNSS7.as_bytes(), "g", &GnssReadOptions::default()).unwrap();
        assert_eq!(g.len(), 2);
        assert!((g.lat_rad[0] - 30.4447858054f64.to_radians()).abs() < 1e-15);
        assert!((g.lon_rad[1] - 114.4718661133f64.to_radians()).abs() < 1e-15);
        assert_eq!(g.height_m, vec![21.095, 21.091]);
        assert_eq!(g.sigma_ned_m[1], [0.011, 0.008, 0.020]);
        assert!(g.vel_ned_m_s.is_none() && g.n_sats.is_none() && g.gps_week.is_none());
        assert_eq!(g.quality, vec![0, 0]);
    }

    #[test]
    fn gnss_thirteen_columns() {
        let t = "10 30 114 20 1.0 -2.0 0.5 0.01 0.02 0.03 0.1 0.2 0.3\n\
                 11 30 114 20 1.1 -2.1 0.6 0.01 0.02 0.03 0.1 0.2 0.3\n";
        let g = read_kfgins_gnss(t.as_bytes(), "g", &GnssReadOptions::default()).unwrap();
        assert_eq!(g.vel_ned_m_s.as_ref().unwrap()[1], [1.1, -2.1, 0.6]);
        assert_eq!(g.sigma_ned_m[0], [0.01, 0.02, 0.03]);
        assert_eq!(g.sigma_vel_ned_m_s.as_ref().unwrap()[0], [0.1, 0.2, 0.3]);
        // 8 columns: neither format.
        let e = read_kfgins_gnss(b"1 30 114 20 1 1 1 1\n", "g", &GnssReadOptions::default())
            .unwrap_err();
        assert!(matches!(e, LogError::Malformed { .. }), "{e}");
        assert!(e.to_string().contains("rows have 8 fields"), "{e}");
        // A missing column on line 2.
        let t = "1 30 114 20 1 1 1\n2 30 114 20 1 1\n3 30 114 20 1 1 1\n";
        let e = read_kfgins_gnss(t.as_bytes(), "g", &GnssReadOptions::default()).unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Ragged {
                    found: 6,
                    expected: 7,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn gnss_cut_edges() {
        let opts = GnssReadOptions::default();
        let rows = [
            "114.4718661162 21.095 0.010 0.009 0.019",
            "456251.000 30.44478 114.47186 21.091 0.011 0.008 0.020",
            "456252.000 30.44478 114.47186 21.091 0.011 0.008 0.020",
            "456253.000 30.44478 114.4",
        ];
        let g = read_kfgins_gnss(rows.join("\n").as_bytes(), "g.txt", &opts).unwrap();
        assert_eq!(g.time_s, vec![456_251.0, 456_252.0]);
        assert_eq!(g.notes.len(), 2);
        assert!(g.notes[0].starts_with("g.txt:1: dropped the first record"));
        assert!(g.notes[1].starts_with("g.txt:4: dropped the last record"));
        // A short first row of a file whose other rows are 13 wide: reference is line 2.
        let t = "1 30 114 20 1 1 1\n2 30 114 20 1 1 1 0.1 0.1 0.1 0.1 0.1 0.1\n3 30 114 20 1 1 1 0.1 0.1 0.1 0.1 0.1 0.1\n";
        let g = read_kfgins_gnss(t.as_bytes(), "g", &opts).unwrap();
        assert_eq!(g.len(), 2);
        assert!(g.vel_ned_m_s.is_some());
        assert!(
            g.notes[0].ends_with("it has 7 fields, line 2 has 13"),
            "{:?}",
            g.notes
        );
    }

    #[test]
    fn gnss_sigma_zero_and_ranges() {
        let t = "1 30 114 20 0.01 0 0.02\n";
        let e = read_kfgins_gnss(t.as_bytes(), "g.txt", &GnssReadOptions::default()).unwrap_err();
        assert!(matches!(e, LogError::InvalidValue { .. }), "{e}");
        assert!(
            e.to_string()
                .starts_with("g.txt:1:18: standard deviation 0"),
            "{e}"
        );
        let floor = GnssReadOptions {
            zero_sigma: ZeroSigma::Floor {
                pos_m: 0.005,
                vel_m_s: 0.01,
            },
        };
        let g = read_kfgins_gnss(t.as_bytes(), "g", &floor).unwrap();
        assert_eq!(g.sigma_ned_m[0], [0.01, 0.005, 0.02]);
        let neg = "1 30 114 20 0.01 -0.1 0.02\n";
        assert!(read_kfgins_gnss(neg.as_bytes(), "g", &floor).is_err());
        let lat = "1 95 114 20 0.01 0.01 0.02\n";
        let e = read_kfgins_gnss(lat.as_bytes(), "g", &floor).unwrap_err();
        assert_eq!(e.to_string(), "g:1:3: latitude 95 deg outside [-90, 90]");
        let dup = "1 30 114 20 1 1 1\n1 30 114 20 1 1 1\n";
        assert!(matches!(
            read_kfgins_gnss(dup.as_bytes(), "g", &floor).unwrap_err(),
            LogError::DuplicateTime { .. }
        ));
    }

    fn nav_fixture() -> NavSolution {
        NavSolution {
            time_s: vec![456300.005, 456300.010],
            lat_rad: vec![30.5f64.to_radians(), 30.25f64.to_radians()],
            lon_rad: vec![114.5f64.to_radians(), -114.5f64.to_radians()],
            height_m: vec![20.9, -3.5],
            vel_ned_m_s: vec![[0.1, -0.2, 0.3], [0.0, 0.0, -0.0]],
            roll_pitch_yaw_rad: vec![
                [1f64.to_radians(), -2f64.to_radians(), 185f64.to_radians()],
                [0.0, 0.0, -90f64.to_radians()],
            ],
        }
    }

    #[test]
    fn nav_writer_matches_kfgins_layout() {
        let mut out = Vec::new();
        write_kfgins_nav(&mut out, "nav", &nav_fixture(), 0).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        // Every field is padded to 15 characters and followed by one space; the time
        // (16 digits) overflows its field as C's printf does: 11 × 16 + 1 characters.
        assert_eq!(lines[0].len(), 11 * 16 + 1);
        assert!(lines[0].starts_with("0.000000000     456300.005000000 30.500000000    "));
        let f: Vec<f64> = lines[1]
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(f.len(), 11);
        assert_eq!(f[2], 30.25);
        assert_eq!(f[3], -114.5);
        assert_eq!(f[4], -3.5);
        assert!((f[10] + 90.0).abs() < 1e-9);
        // Mismatched lengths and NaN are refused.
        let mut bad = nav_fixture();
        bad.height_m.pop();
        assert!(matches!(
            write_kfgins_nav(Vec::new(), "nav", &bad, 0).unwrap_err(),
            LogError::InvalidLog { .. }
        ));
        let mut bad = nav_fixture();
        bad.height_m[1] = f64::NAN;
        assert!(write_kfgins_nav(Vec::new(), "nav", &bad, 0).is_err());
    }

    #[test]
    fn imu_err_and_std_writers_convert_units() {
        let d2r = 1f64.to_radians();
        let e = ImuErrors {
            time_s: vec![10.0],
            gyro_bias_rad_s: vec![[d2r / 3600.0, 2.0 * d2r / 3600.0, 0.0]],
            accel_bias_m_s2: vec![[1e-5, 0.0, -5e-4]],
            gyro_scale: vec![[1e-6, 0.0, 0.0]],
            accel_scale: vec![[0.0, -3e-4, 0.0]],
        };
        let mut out = Vec::new();
        write_kfgins_imu_err(&mut out, "e", &e).unwrap();
        let f: Vec<f64> = String::from_utf8(out)
            .unwrap()
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        let want = [
            10.0, 1.0, 2.0, 0.0, 1.0, 0.0, -50.0, 1.0, 0.0, 0.0, 0.0, -300.0, 0.0,
        ];
        assert_eq!(f.len(), 13);
        for (a, b) in f.iter().zip(want) {
            assert!((a - b).abs() < 1e-8, "{f:?}");
        }
        let s = NavStd {
            time_s: vec![10.0],
            pos_ned_m: vec![[0.1, 0.2, 0.3]],
            vel_ned_m_s: vec![[0.01, 0.02, 0.03]],
            att_rad: vec![[d2r, 0.0, 2.0 * d2r]],
            gyro_bias_rad_s: vec![[d2r / 3600.0; 3]],
            accel_bias_m_s2: vec![[1e-5; 3]],
            gyro_scale: vec![[1e-6; 3]],
            accel_scale: vec![[2e-6; 3]],
        };
        let mut out = Vec::new();
        write_kfgins_std(&mut out, "s", &s).unwrap();
        let f: Vec<f64> = String::from_utf8(out)
            .unwrap()
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(f.len(), 22);
        assert!((f[7] - 1.0).abs() < 1e-9 && (f[9] - 2.0).abs() < 1e-9);
        assert!((f[10] - 1.0).abs() < 1e-9 && (f[13] - 1.0).abs() < 1e-9);
        assert!((f[16] - 1.0).abs() < 1e-9 && (f[21] - 2.0).abs() < 1e-9);
    }

    #[test]
    fn outputs_round_trip_through_the_reader_layouts() {
        let dir = std::env::temp_dir().join(format!("driftless-navio-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let sol = nav_fixture();
        let e = ImuErrors {
            time_s: sol.time_s.clone(),
            gyro_bias_rad_s: vec![[0.0; 3]; 2],
            accel_bias_m_s2: vec![[0.0; 3]; 2],
            gyro_scale: vec![[0.0; 3]; 2],
            accel_scale: vec![[0.0; 3]; 2],
        };
        let s = NavStd {
            time_s: sol.time_s.clone(),
            pos_ned_m: vec![[1.0; 3]; 2],
            vel_ned_m_s: vec![[1.0; 3]; 2],
            att_rad: vec![[1.0; 3]; 2],
            gyro_bias_rad_s: vec![[1.0; 3]; 2],
            accel_bias_m_s2: vec![[1.0; 3]; 2],
            gyro_scale: vec![[1.0; 3]; 2],
            accel_scale: vec![[1.0; 3]; 2],
        };
        let paths = write_kfgins_outputs(&dir, &sol, &e, &s, 2374).unwrap();
        assert!(paths[0].ends_with("KF_GINS_Navresult.nav"));
        assert!(paths[1].ends_with("KF_GINS_IMU_ERR.txt"));
        assert!(paths[2].ends_with("KF_GINS_STD.txt"));
        let nav = std::fs::read_to_string(&paths[0]).unwrap();
        assert!(nav.starts_with("2374.000000000  456300.005000000"));
        let cols: Vec<usize> = [&paths[1], &paths[2]]
            .iter()
            .map(|p| {
                let t = std::fs::read_to_string(p).unwrap();
                t.lines().next().unwrap().split_whitespace().count()
            })
            .collect();
        assert_eq!(cols, vec![13, 22]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Rows with values on both paths of the formatter: small, negative, ≥ 1e8 (the
    /// standard formatter), near ties.
    fn mixed_rows(n: usize) -> (NavSolution, ImuErrors, NavStd) {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = |i: usize| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            match i % 4 {
                0 => u * 1e-3,
                1 => u * 3e9,
                2 => (u * 2e6).round() * 0.5e-9,
                _ => u * 200.0,
            }
        };
        let mut k = 0;
        let mut tri = || {
            k += 1;
            [next(k), next(k + 1), next(k + 2)]
        };
        let mut sol = NavSolution::default();
        let mut e = ImuErrors::default();
        let mut sd = NavStd::default();
        for i in 0..n {
            let t = 456_300.0 + i as f64 * 0.005;
            let [a, b, c] = tri();
            sol.push_epoch(t, a, b, c, tri(), tri());
            e.time_s.push(t);
            e.gyro_bias_rad_s.push(tri());
            e.accel_bias_m_s2.push(tri());
            e.gyro_scale.push(tri());
            e.accel_scale.push(tri());
            sd.time_s.push(t);
            sd.pos_ned_m.push(tri());
            sd.vel_ned_m_s.push(tri());
            sd.att_rad.push(tri());
            sd.gyro_bias_rad_s.push(tri());
            sd.accel_bias_m_s2.push(tri());
            sd.gyro_scale.push(tri());
            sd.accel_scale.push(tri());
        }
        (sol, e, sd)
    }

    #[test]
    fn line_buffer_matches_the_standard_formatter_and_refuses_non_finite() {
        let (_, _, sd) = mixed_rows(300);
        let mut buf = LineBuf::new();
        let mut want = String::new();
        for i in 0..300 {
            let v = std_row(&sd, i).std_values();
            buf.line(&v).unwrap();
            for x in v {
                want.push_str(&format!("{x:<15.9} "));
            }
            want.push('\n');
        }
        assert_eq!(std::str::from_utf8(&buf.buf[..buf.pos]).unwrap(), want);
        // Both paths of the formatter were taken.
        let big = (0..300).flat_map(|i| std_row(&sd, i).std_values());
        assert!(big.filter(|v| v.abs() >= 1e8).count() > 100);
        let before = buf.pos;
        let mut bad = std_row(&sd, 0).std_values();
        bad[5] = f64::NAN;
        assert_eq!(buf.line(&bad), Err(5));
        bad[2] = f64::NEG_INFINITY;
        assert_eq!(buf.line(&bad), Err(2));
        assert_eq!(buf.pos, before);
    }

    #[test]
    fn row_writer_matches_the_column_writers_and_replaces_old_files() {
        let dir = std::env::temp_dir().join(format!("driftless-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // An earlier, longer run's files: nothing of them may remain.
        for f in output_file_names("") {
            std::fs::write(dir.join(f), vec![b'x'; 3 << 20]).unwrap();
        }
        // More rows than one chunk of the std file holds.
        let n = 13_000;
        let (sol, e, sd) = mixed_rows(n);
        let mut w = KfGinsOutputWriter::create(&dir, 7).unwrap();
        for i in 0..n {
            let row = KfGinsRow {
                lat_rad: sol.lat_rad[i],
                lon_rad: sol.lon_rad[i],
                height_m: sol.height_m[i],
                vel_ned_m_s: sol.vel_ned_m_s[i],
                roll_pitch_yaw_rad: sol.roll_pitch_yaw_rad[i],
                gyro_bias_rad_s: e.gyro_bias_rad_s[i],
                accel_bias_m_s2: e.accel_bias_m_s2[i],
                gyro_scale: e.gyro_scale[i],
                accel_scale: e.accel_scale[i],
                ..std_row(&sd, i)
            };
            w.append_row(&row).unwrap();
        }
        let paths = w.finish().unwrap();
        let mut want = [Vec::new(), Vec::new(), Vec::new()];
        write_kfgins_nav(&mut want[0], "nav", &sol, 7).unwrap();
        write_kfgins_imu_err(&mut want[1], "err", &e).unwrap();
        write_kfgins_std(&mut want[2], "std", &sd).unwrap();
        assert!(want[2].len() > CHUNK);
        for (p, want) in paths.iter().zip(&want) {
            assert!(std::fs::read(p).unwrap() == *want, "{}", p.display());
        }
        // A value that is not finite names the file, row and column.
        let mut w = KfGinsOutputWriter::create(&dir, 0).unwrap();
        let row = nav_row(&sol, 0);
        w.append_row(&row).unwrap();
        let bad = KfGinsRow {
            std_vel_ned_m_s: [0.0, f64::INFINITY, 0.0],
            ..row
        };
        let msg = w.append_row(&bad).unwrap_err().to_string();
        assert!(
            msg.contains("KF_GINS_STD.txt") && msg.contains("row 1, column 6"),
            "{msg}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    #[ignore = "needs shared data"]
    fn wuhan_kfgins_gnss_file() {
        let dir = std::env::var("DRIFTLESS_DATA").map_or_else(
            |_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
            PathBuf::from,
        );
        let g = read_kfgins_gnss_file(
            dir.join("trajectories/kfgins_wuhan_gnss_rtk_1hz.txt"),
            &GnssReadOptions::default(),
        )
        .unwrap();
        assert_eq!(g.len(), 3413);
        assert_eq!(g.time_s[0], 456_250.0);
        assert_eq!(g.sigma_ned_m[0], [0.010, 0.009, 0.019]);
        assert!((g.lat_rad[0].to_degrees() - 30.4447858054).abs() < 1e-10);
        assert!(g.vel_ned_m_s.is_none());
    }
}

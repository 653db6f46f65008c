//! The readers of KF-GINS's IMU and GNSS input files.

use super::*;

/// Data lines of a text input: (1-based line number, line text), blank lines skipped.
pub(super) fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty())
}

/// The rows of a KF-GINS input to parse, after the edge checks.
pub(super) struct Body {
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
pub(super) fn edge_body(
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
pub(super) fn check_count(
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

pub(super) const IMU_NAMES: [&str; 7] = [
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

pub(super) fn read_imu_in_blocks(
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
pub(super) const IMU_BLOCK_BYTES: usize = 1 << 22;

/// Splits `text` after newlines into blocks of about `target` bytes, each with the
/// 1-based number of its first line (`text` starts at line `first_line`).
pub(super) fn line_blocks(text: &str, target: usize, first_line: usize) -> Vec<(usize, &str)> {
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
pub(super) struct ImuBlock {
    data: ImuIncrements,
    first_data_line: usize,
    error: Option<LogError>,
}

pub(super) fn parse_imu_block(
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
pub(super) fn imu_row_fast(l: &str) -> Option<[f64; 7]> {
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

pub(super) fn parse_imu_row<'a>(
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

pub(super) const GNSS_NAMES_7: [&str; 7] = [
    "time_s",
    "lat_deg",
    "lon_deg",
    "height_m",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
];
pub(super) const GNSS_NAMES_13: [&str; 13] = [
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
/// are [`super::super::quality::UNSPECIFIED`]; `gps_week` and `n_sats` are `None`.
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
        out.quality.push(super::super::quality::UNSPECIFIED);
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

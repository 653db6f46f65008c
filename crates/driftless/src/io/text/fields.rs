//! Lines and fields: splitting the input into lines, lines into fields, detecting the
//! delimiter, and cutting a chunk into pieces at line ends for parallel parsing.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Delim {
    Byte(u8),
    Whitespace,
}

#[inline]
pub(super) fn is_ws(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == b'\x0b' || b == b'\x0c'
}

/// Calls `f(byte_offset, field)` for each field of a line (comment already allowed),
/// returns the number of fields. Empty trailing field after a final delimiter is dropped.
#[inline]
pub(super) fn for_each_field<E>(
    line: &[u8],
    delim: Delim,
    mut f: impl FnMut(usize, usize, &[u8]) -> Result<(), E>,
) -> Result<usize, E> {
    let n = line.len();
    let mut p = 0;
    let mut field = 0;
    match delim {
        Delim::Whitespace => loop {
            while p < n && is_ws(line[p]) {
                p += 1;
            }
            if p >= n || line[p] == b'#' {
                break;
            }
            let start = p;
            while p < n && !is_ws(line[p]) && line[p] != b'#' {
                p += 1;
            }
            f(field, start, &line[start..p])?;
            field += 1;
        },
        Delim::Byte(d) => loop {
            let start = p;
            while p < n && line[p] != d && line[p] != b'#' {
                p += 1;
            }
            let end_of_row = p >= n || line[p] == b'#';
            let (mut s, mut e) = (start, p);
            while s < e && is_ws(line[s]) {
                s += 1;
            }
            while e > s && is_ws(line[e - 1]) {
                e -= 1;
            }
            if end_of_row && s == e && field > 0 {
                break; // one trailing delimiter
            }
            f(field, s, &line[s..e])?;
            field += 1;
            if end_of_row {
                break;
            }
            p += 1;
        },
    }
    Ok(field)
}

/// What the header of a CSV written by driftless states: a first line
/// `# driftless log; …` and a second `# …; rows: N[; last line: # end of driftless log]` —
/// the row count and whether the file ends with that line.
pub(super) fn declared_rows(region: &[u8]) -> Option<(usize, bool)> {
    let mut ls = lines(region);
    if !ls
        .next()?
        .starts_with(crate::io::write::HEADER_MARK.as_bytes())
    {
        return None;
    }
    let second = std::str::from_utf8(ls.next()?).ok()?.trim_end();
    let (_, after) = second.strip_prefix('#')?.split_once("rows: ")?;
    let digits = after.bytes().take_while(u8::is_ascii_digit).count();
    let n = after[..digits].parse().ok()?;
    let marked = after[digits..] == format!("; last line: {}", crate::io::write::END_MARK);
    Some((n, marked))
}

/// The header of a EuRoC / TUM-VI IMU CSV (`#timestamp [ns],w_RS_S_x [rad s^-1],…,
/// a_RS_S_z [m s^-2]`) without its `#`: a comment line by the rules above, taken as the
/// header when it is the first line with content (its bracketed units then give ns time
/// stamps, rad/s and m/s²).
pub(super) fn euroc_header(line: &[u8]) -> Option<&[u8]> {
    let rest = line.trim_ascii_start().strip_prefix(b"#")?;
    let is_euroc = rest.trim_ascii_start().starts_with(b"timestamp")
        && rest.windows(8).any(|w| w == b"w_RS_S_x");
    is_euroc.then_some(rest)
}

/// True when the line holds no data (blank or comment).
#[inline]
pub(super) fn is_blank_or_comment(line: &[u8]) -> bool {
    match line.iter().position(|&b| !is_ws(b)) {
        None => true,
        Some(i) => line[i] == b'#',
    }
}

/// Splits a buffer into lines without the `\n` and a trailing `\r`.
pub(super) fn lines(buf: &[u8]) -> impl Iterator<Item = &[u8]> {
    let body = buf.strip_suffix(b"\n").unwrap_or(buf);
    let mut it = (!buf.is_empty()).then(|| body.split(|&b| b == b'\n'));
    std::iter::from_fn(move || it.as_mut()?.next()).map(|l| l.strip_suffix(b"\r").unwrap_or(l))
}

pub(super) fn detect_delimiter(line: &[u8]) -> Delim {
    let body = match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    };
    if body.contains(&b';') {
        Delim::Byte(b';')
    } else if body.contains(&b',') {
        Delim::Byte(b',')
    } else if body.contains(&b'\t') {
        let mut clean = true;
        let _ = for_each_field(body, Delim::Byte(b'\t'), |_, _, t| {
            clean &= !t.is_empty();
            Ok::<(), ()>(())
        });
        if clean {
            Delim::Byte(b'\t')
        } else {
            Delim::Whitespace
        }
    } else {
        Delim::Whitespace
    }
}

/// Number of fields of a line.
pub(super) fn field_count(line: &[u8], delim: Delim) -> usize {
    for_each_field(line, delim, |_, _, _| Ok::<(), ()>(())).unwrap_or(0)
}

/// 1-based byte column where a row with `found` fields departs from `expected`: the start
/// of the first extra field, or the end of the line.
pub(super) fn ragged_col(line: &[u8], delim: Delim, expected: usize) -> usize {
    let mut extra = None;
    let _ = for_each_field(line, delim, |field, start, _| {
        if field == expected {
            extra.get_or_insert(start);
        }
        Ok::<(), ()>(())
    });
    extra.unwrap_or(line.len()) + 1
}

/// The text of field `k` (0-based) of a line.
pub(super) fn field_text(line: &[u8], delim: Delim, k: usize) -> Option<Vec<u8>> {
    let mut out = None;
    let _ = for_each_field(line, delim, |field, _, t| {
        if field == k {
            out = Some(t.to_vec());
        }
        Ok::<(), ()>(())
    });
    out
}

/// Length of the line starting at `offset` including its `\n`.
pub(super) fn line_len_with_end(region: &[u8], offset: usize) -> usize {
    let rest = region.get(offset..).unwrap_or(&[]);
    match rest.iter().position(|&b| b == b'\n') {
        Some(i) => i + 1,
        None => rest.len(),
    }
}

/// Splits `data` into about `k` pieces at line ends.
pub(super) fn split_pieces(data: &[u8], k: usize) -> Vec<&[u8]> {
    let mut pieces = Vec::with_capacity(k);
    let mut start = 0;
    for j in 1..k {
        let target = (data.len() * j / k).max(start);
        let cut = match data
            .get(target..)
            .and_then(|r| r.iter().position(|&b| b == b'\n'))
        {
            Some(i) => target + i + 1,
            None => data.len(),
        };
        if cut > start {
            pieces.push(&data[start..cut]);
            start = cut;
        }
    }
    if start < data.len() || pieces.is_empty() {
        pieces.push(&data[start..]);
    }
    pieces
}

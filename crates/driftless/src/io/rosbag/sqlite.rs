//! A read-only reader of rowid tables in an SQLite 3 database file, as much of the file
//! format (sqlite.org, "Database File Format") as reading a ROS 2 `.db3` bag needs:
//!
//! * the 100-byte header (page size, reserved bytes per page, text encoding);
//! * table B-trees (interior pages type 5, leaf pages type 13) walked in rowid order, one
//!   page per level held at a time;
//! * cells whose payload spills to overflow pages (§ 1.6: with `U` the usable page size,
//!   `X = U − 35`, `M = ⌊(U − 12)·32/255⌋ − 23`, `K = M + (P − M) mod (U − 4)`, a payload of
//!   `P > X` bytes keeps `K` bytes on the page if `K ≤ X`, else `M`; each overflow page is a
//!   4-byte next-page number and `U − 4` payload bytes);
//! * the record format (§ 2.1: a varint header length, one varint serial type per column,
//!   then the values: integers big-endian two's complement of 1, 2, 3, 4, 6 or 8 bytes, 8
//!   and 9 the constants 0 and 1, 7 an IEEE double, `N ≥ 12` even a blob of `(N − 12)/2`
//!   bytes, odd a text of `(N − 13)/2` bytes);
//! * varints (1 to 9 bytes, big-endian, 7 bits per byte with the high bit set on all but
//!   the last; the 9th byte gives 8 bits).
//!
//! Everything read is checked against the file: page numbers within the file, cells within
//! their page, B-tree depth ≤ 20 (SQLite's own limit), a table scan visiting no more pages
//! than the file has (so a page loop ends in an error), rowids increasing, payloads under
//! a cap. Nothing is written, nothing is cached beyond the pages of the current path.

use std::io::{Read, Seek, SeekFrom};

use crate::io::error::LogError;

const FORMAT: &str = "ROS 2 sqlite3 bag";

/// The deepest table B-tree walked (SQLite's `BTCURSOR_MAX_DEPTH`).
const MAX_DEPTH: usize = 20;

/// Largest row payload read (one row is held at a time).
pub(crate) const MAX_PAYLOAD_BYTES: u64 = 256 << 20;

/// A varint at the start of `b`: (value, bytes used), `None` when `b` ends first.
pub(crate) fn varint(b: &[u8]) -> Option<(u64, usize)> {
    let mut v: u64 = 0;
    for i in 0..9 {
        let byte = *b.get(i)?;
        if i == 8 {
            return Some(((v << 8) | u64::from(byte), 9));
        }
        v = (v << 7) | u64::from(byte & 0x7f);
        if byte & 0x80 == 0 {
            return Some((v, i + 1));
        }
    }
    None
}

/// One column value of a record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Value<'a> {
    Null,
    Int(i64),
    Real(f64),
    Text(&'a [u8]),
    Blob(&'a [u8]),
}

/// The size in bytes of a value of serial type `t`, `None` for the reserved types 10, 11.
fn serial_size(t: u64) -> Option<u64> {
    Some(match t {
        0 | 8 | 9 => 0,
        1..=4 => t,
        5 => 6,
        6 | 7 => 8,
        10 | 11 => return None,
        _ => (t - 12) / 2,
    })
}

/// The values of a record (a row's whole payload).
pub(crate) fn record(payload: &[u8]) -> Result<Vec<Value<'_>>, String> {
    let (hlen, n) = varint(payload).ok_or("record header length cut off")?;
    let hlen = usize::try_from(hlen)
        .ok()
        .filter(|&h| h >= n && h <= payload.len())
        .ok_or_else(|| {
            format!(
                "record header of {hlen} bytes in a payload of {} bytes",
                payload.len()
            )
        })?;
    let mut types = &payload[n..hlen];
    let mut body = &payload[hlen..];
    let mut out = Vec::new();
    while !types.is_empty() {
        let (t, used) = varint(types).ok_or("serial type cut off")?;
        types = &types[used..];
        let size = serial_size(t).ok_or_else(|| format!("reserved serial type {t}"))?;
        let size = usize::try_from(size)
            .ok()
            .filter(|&s| s <= body.len())
            .ok_or_else(|| format!("value of {size} bytes runs past the record"))?;
        let (v, rest) = body.split_at(size);
        body = rest;
        out.push(match t {
            0 => Value::Null,
            1..=6 => {
                // Big-endian two's complement, sign-extended from the top byte.
                let mut x: i64 = if v[0] & 0x80 != 0 { -1 } else { 0 };
                for &byte in v {
                    x = (x << 8) | i64::from(byte);
                }
                Value::Int(x)
            }
            7 => Value::Real(f64::from_be_bytes(
                v.try_into().map_err(|_| "real cut off")?,
            )),
            8 => Value::Int(0),
            9 => Value::Int(1),
            t if t % 2 == 0 => Value::Blob(v),
            _ => Value::Text(v),
        });
    }
    Ok(out)
}

/// How many bytes of a `payload`-byte table-leaf payload stay on the page (§ 1.6), for
/// usable page size `usable`.
pub(crate) fn local_payload(payload: u64, usable: u64) -> u64 {
    let x = usable - 35;
    if payload <= x {
        return payload;
    }
    let m = (usable - 12) * 32 / 255 - 23;
    let k = m + (payload - m) % (usable - 4);
    if k <= x { k } else { m }
}

/// The column names of a `CREATE TABLE name(col type ..., ...)` statement, in order
/// (table constraints skipped; quoting removed).
pub(crate) fn column_names(sql: &str) -> Vec<String> {
    let Some(open) = sql.find('(') else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut start = open + 1;
    for (i, c) in sql.char_indices().skip_while(|&(i, _)| i <= open) {
        match c {
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            ',' | ')' if depth == 0 => {
                let def = sql[start..i].trim();
                let name: String = match def.chars().next() {
                    Some(q @ ('"' | '`' | '[')) => {
                        let close = if q == '[' { ']' } else { q };
                        def[1..].chars().take_while(|&c| c != close).collect()
                    }
                    _ => def
                        .chars()
                        .take_while(|c| !c.is_whitespace() && *c != '(')
                        .collect(),
                };
                let constraint = ["CONSTRAINT", "PRIMARY", "UNIQUE", "CHECK", "FOREIGN"]
                    .iter()
                    .any(|k| name.eq_ignore_ascii_case(k));
                if !constraint && !name.is_empty() {
                    out.push(name);
                }
                start = i + 1;
                if c == ')' {
                    break;
                }
            }
            _ => {}
        }
    }
    out
}

/// A [`LogError::AtByte`] in database `name` at byte `at`.
fn error_at(name: &str, at: u64, message: String) -> LogError {
    LogError::AtByte {
        path: name.to_owned(),
        byte_offset: at,
        format: FORMAT,
        message,
    }
}

/// What a table scan calls for each row: `(db, rowid, byte offset of the cell, payload)`.
pub(crate) type RowVisitor<'v> = dyn FnMut(&Db<'_>, i64, u64, &[u8]) -> Result<(), LogError> + 'v;

/// An open database file.
pub(crate) struct Db<'f> {
    file: &'f mut std::fs::File,
    pub name: &'f str,
    page_size: usize,
    usable: usize,
    pages: u32,
}

/// A table of the schema: its name, root page and `CREATE` statement.
pub(crate) struct Table {
    pub name: String,
    pub root: u32,
    pub sql: String,
}

impl<'f> Db<'f> {
    /// Reads and checks the header of the database `file` of `size` bytes.
    pub fn open(file: &'f mut std::fs::File, name: &'f str, size: u64) -> Result<Self, LogError> {
        let err = |at: u64, m: String| LogError::AtByte {
            path: name.to_owned(),
            byte_offset: at,
            format: FORMAT,
            message: m,
        };
        let mut h = [0u8; 100];
        file.seek(SeekFrom::Start(0))
            .and_then(|_| file.read_exact(&mut h))
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::UnexpectedEof {
                    err(
                        0,
                        format!(
                            "truncated: {size} bytes, shorter than the 100-byte database header"
                        ),
                    )
                } else {
                    LogError::Io {
                        path: name.to_owned(),
                        error: e,
                    }
                }
            })?;
        if &h[..16] != super::SQLITE_MAGIC {
            return Err(err(0, "not an SQLite 3 database (no magic)".into()));
        }
        let page_size = match u16::from_be_bytes([h[16], h[17]]) {
            1 => 65536,
            p if p >= 512 && p.is_power_of_two() => usize::from(p),
            p => {
                return Err(err(
                    16,
                    format!("page size {p}: not a power of two from 512 to 65536"),
                ));
            }
        };
        if h[19] > 2 {
            return Err(err(
                19,
                format!(
                    "file format read version {}: only 1 (rollback) and 2 (WAL) are read",
                    h[19]
                ),
            ));
        }
        let usable = page_size - usize::from(h[20]);
        if usable < 480 {
            return Err(err(
                20,
                format!("{} reserved bytes per page leave {usable} usable", h[20]),
            ));
        }
        let encoding = u32::from_be_bytes([h[56], h[57], h[58], h[59]]);
        if encoding > 1 {
            return Err(err(
                56,
                format!("text encoding {encoding} (UTF-16): only UTF-8 databases are read"),
            ));
        }
        let in_file = size / page_size as u64;
        let declared = u32::from_be_bytes([h[28], h[29], h[30], h[31]]);
        let valid = declared > 0 && h[24..28] == h[92..96];
        if valid && u64::from(declared) > in_file {
            return Err(err(
                28,
                format!(
                    "truncated: the header declares {declared} pages of {page_size} bytes, the \
                     file holds {in_file} (an interrupted copy?)"
                ),
            ));
        }
        let pages = if valid {
            declared
        } else {
            u32::try_from(in_file).unwrap_or(u32::MAX)
        };
        Ok(Db {
            file,
            name,
            page_size,
            usable,
            pages,
        })
    }

    fn error(&self, at: u64, message: String) -> LogError {
        error_at(self.name, at, message)
    }

    fn page_offset(&self, pgno: u32) -> u64 {
        u64::from(pgno.saturating_sub(1)) * self.page_size as u64
    }

    /// Reads page `pgno` (1-based) into `buf`; `from` names the referring place for errors.
    fn read_page(&mut self, pgno: u32, from: u64, buf: &mut Vec<u8>) -> Result<(), LogError> {
        if pgno == 0 || pgno > self.pages {
            return Err(self.error(
                from,
                format!(
                    "page number {pgno} outside the file's {} pages (truncated or corrupt)",
                    self.pages
                ),
            ));
        }
        buf.resize(self.page_size, 0);
        let at = self.page_offset(pgno);
        let name = self.name;
        self.file
            .seek(SeekFrom::Start(at))
            .and_then(|_| self.file.read_exact(buf))
            .map_err(|error| LogError::Io {
                path: name.to_owned(),
                error,
            })
    }

    /// The tables of the schema (page 1).
    pub fn tables(&mut self) -> Result<Vec<Table>, LogError> {
        let mut out = Vec::new();
        self.scan(1, &mut |db, _rowid, at, payload| {
            let v = record(payload).map_err(|m| db.error(at, format!("schema row: {m}")))?;
            if let [
                Value::Text(b"table"),
                Value::Text(name),
                _,
                Value::Int(root),
                sql,
                ..,
            ] = v.as_slice()
            {
                let sql = match sql {
                    Value::Text(s) => String::from_utf8_lossy(s).into_owned(),
                    _ => String::new(),
                };
                out.push(Table {
                    name: String::from_utf8_lossy(name).into_owned(),
                    root: u32::try_from(*root).unwrap_or(0),
                    sql,
                });
            }
            Ok(())
        })?;
        Ok(out)
    }

    /// Visits the rows of the table B-tree rooted at `root` in rowid order:
    /// `visit(db, rowid, byte offset of the cell, payload)`.
    pub fn scan(&mut self, root: u32, visit: &mut RowVisitor<'_>) -> Result<(), LogError> {
        // The path from the root: (page bytes, page number, next child to descend into).
        let mut stack: Vec<(Vec<u8>, u32, usize)> = Vec::new();
        let mut visited: u64 = 0;
        let mut payload = Vec::new();
        let mut overflow = Vec::new();
        let mut last_rowid: Option<i64> = None;
        let mut next = Some((root, 0u64));
        loop {
            if let Some((pgno, from)) = next.take() {
                visited += 1;
                if visited > u64::from(self.pages) {
                    return Err(self.error(
                        from,
                        format!("table B-tree (root page {root}) visits more pages than the file has: a page loop"),
                    ));
                }
                if stack.len() >= MAX_DEPTH {
                    return Err(self.error(
                        from,
                        format!("table B-tree (root page {root}) deeper than {MAX_DEPTH} levels"),
                    ));
                }
                let mut page = Vec::new();
                self.read_page(pgno, from, &mut page)?;
                let head = if pgno == 1 { 100 } else { 0 };
                let at = self.page_offset(pgno) + head as u64;
                match page[head] {
                    0x05 => stack.push((page, pgno, 0)),
                    0x0d => {
                        self.leaf(
                            &page,
                            pgno,
                            head,
                            &mut payload,
                            &mut overflow,
                            &mut visited,
                            &mut last_rowid,
                            visit,
                        )?;
                    }
                    t => {
                        return Err(self.error(
                            at,
                            format!(
                                "page {pgno} of type {t} in a table B-tree (5 or 13 expected): \
                                 corrupt, or not a rowid table"
                            ),
                        ));
                    }
                }
                continue;
            }
            // Descend into the next child of the deepest interior page, or pop it.
            let Some((page, pgno, child)) = stack.last_mut() else {
                return Ok(());
            };
            let (page, pgno) = (&*page, *pgno);
            let head = if pgno == 1 { 100 } else { 0 };
            let base = self.page_offset(pgno);
            let cells = usize::from(u16::from_be_bytes([page[head + 3], page[head + 4]]));
            if *child > cells {
                stack.pop();
                continue;
            }
            let from = base + head as u64;
            let target = if *child == cells {
                u32::from_be_bytes([
                    page[head + 8],
                    page[head + 9],
                    page[head + 10],
                    page[head + 11],
                ])
            } else {
                let ptr_at = head + 12 + 2 * *child;
                let cell = page
                    .get(ptr_at..ptr_at + 2)
                    .map(|p| usize::from(u16::from_be_bytes([p[0], p[1]])))
                    .ok_or_else(|| {
                        self.error(
                            from,
                            format!("page {pgno}: cell pointer array runs past the page"),
                        )
                    })?;
                page.get(cell..cell + 4)
                    .filter(|_| cell >= head + 12)
                    .map(|c| u32::from_be_bytes([c[0], c[1], c[2], c[3]]))
                    .ok_or_else(|| {
                        self.error(
                            from,
                            format!("page {pgno}: cell at {cell} outside the page"),
                        )
                    })?
            };
            *child += 1;
            next = Some((target, from));
        }
    }

    /// The cells of one leaf page.
    #[allow(clippy::too_many_arguments)]
    fn leaf(
        &mut self,
        page: &[u8],
        pgno: u32,
        head: usize,
        payload: &mut Vec<u8>,
        overflow: &mut Vec<u8>,
        visited: &mut u64,
        last_rowid: &mut Option<i64>,
        visit: &mut RowVisitor<'_>,
    ) -> Result<(), LogError> {
        let base = self.page_offset(pgno);
        let cells = usize::from(u16::from_be_bytes([page[head + 3], page[head + 4]]));
        let usable = self.usable;
        let name = self.name;
        for i in 0..cells {
            let ptr_at = head + 8 + 2 * i;
            let page_err =
                |m: String| error_at(name, base + head as u64, format!("page {pgno}: {m}"));
            let cell = page
                .get(ptr_at..ptr_at + 2)
                .map(|p| usize::from(u16::from_be_bytes([p[0], p[1]])))
                .ok_or_else(|| page_err("cell pointer array runs past the page".into()))?;
            let body = page
                .get(cell..usable)
                .filter(|_| cell >= head + 8)
                .ok_or_else(|| {
                    // Reported at its pointer: the offset itself may lie past the file.
                    let m = format!("page {pgno} cell {i}: offset {cell} outside the page");
                    error_at(name, base + ptr_at as u64, m)
                })?;
            let at = base + cell as u64;
            let cell_err = |m: String| error_at(name, at, format!("page {pgno} cell {i}: {m}"));
            let (p, n1) = varint(body).ok_or_else(|| cell_err("payload size cut off".into()))?;
            let (rowid, n2) =
                varint(&body[n1..]).ok_or_else(|| cell_err("rowid cut off".into()))?;
            let rowid = rowid as i64;
            if last_rowid.is_some_and(|r| rowid <= r) {
                return Err(cell_err(format!(
                    "rowid {rowid} after {}: the table B-tree is out of order (corrupt)",
                    last_rowid.unwrap_or(0)
                )));
            }
            *last_rowid = Some(rowid);
            if p > MAX_PAYLOAD_BYTES {
                return Err(cell_err(format!(
                    "row {rowid} of {p} bytes, over the {MAX_PAYLOAD_BYTES}-byte limit of one row"
                )));
            }
            let local = local_payload(p, usable as u64) as usize;
            let start = n1 + n2;
            let here = body
                .get(start..start + local)
                .ok_or_else(|| cell_err(format!("payload of {local} bytes runs past the page")))?;
            payload.clear();
            payload.extend_from_slice(here);
            let mut next_page = if (local as u64) < p {
                let b = body
                    .get(start + local..start + local + 4)
                    .ok_or_else(|| cell_err("overflow page number cut off".into()))?;
                u32::from_be_bytes([b[0], b[1], b[2], b[3]])
            } else {
                0
            };
            let p = p as usize;
            while payload.len() < p {
                *visited += 1;
                if *visited > u64::from(self.pages) {
                    return Err(cell_err(
                        "overflow chain loops (more pages than the file has)".into(),
                    ));
                }
                self.read_page(next_page, at, overflow)?;
                let take = (p - payload.len()).min(usable - 4);
                payload.extend_from_slice(&overflow[4..4 + take]);
                next_page =
                    u32::from_be_bytes([overflow[0], overflow[1], overflow[2], overflow[3]]);
            }
            visit(self, rowid, at, payload)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_of_one_to_nine_bytes() {
        assert_eq!(varint(&[0x00]), Some((0, 1)));
        assert_eq!(varint(&[0x7f]), Some((127, 1)));
        assert_eq!(varint(&[0x81, 0x00]), Some((128, 2)));
        assert_eq!(varint(&[0x82, 0x2c]), Some((300, 2)));
        // 0x3fff: the largest two-byte value.
        assert_eq!(varint(&[0xff, 0x7f]), Some((0x3fff, 2)));
        // Nine bytes: 8 × 7 bits then 8 bits, 64 bits in all.
        assert_eq!(varint(&[0xff; 9]), Some((u64::MAX, 9)));
        assert_eq!(
            varint(&[0x81, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x01]),
            Some((1 << 57 | 1, 9))
        );
        assert_eq!(varint(&[0x81]), None);
        assert_eq!(varint(&[]), None);
    }

    #[test]
    fn record_of_each_serial_type() {
        // Header: length 10, types NULL, i8, i16, i24, i48, i64, real, 0, 1, blob(2),
        // text(3) → header = 1 + 11 = 12 bytes.
        let mut b = vec![12u8, 0, 1, 2, 3, 5, 6, 7, 8, 9, 16, 19];
        b.push(0xff); // i8 −1
        b.extend([0x01, 0x00]); // i16 256
        b.extend([0x80, 0x00, 0x00]); // i24 −2^23
        b.extend([0x00, 0x00, 0x00, 0x01, 0x00, 0x00]); // i48 2^16
        b.extend((-5i64).to_be_bytes());
        b.extend(2.5f64.to_be_bytes());
        b.extend([0xab, 0xcd]);
        b.extend(b"abc");
        let v = record(&b).unwrap();
        assert_eq!(
            v,
            vec![
                Value::Null,
                Value::Int(-1),
                Value::Int(256),
                Value::Int(-(1 << 23)),
                Value::Int(1 << 16),
                Value::Int(-5),
                Value::Real(2.5),
                Value::Int(0),
                Value::Int(1),
                Value::Blob(&[0xab, 0xcd]),
                Value::Text(b"abc"),
            ]
        );
        // Every cut is an error, never a panic.
        for n in 0..b.len() {
            assert!(record(&b[..n]).is_err(), "cut at {n}");
        }
        // Reserved serial types.
        assert!(record(&[2, 10]).is_err());
    }

    #[test]
    fn local_payload_follows_the_spill_rule() {
        // U = 4096: X = 4061, M = ⌊4084·32/255⌋ − 23 = 512 − 23 = 489.
        assert_eq!(local_payload(4061, 4096), 4061);
        // P = 4062: K = 489 + (4062 − 489) mod 4092 = 4062 > X → M.
        assert_eq!(local_payload(4062, 4096), 489);
        // P = 10000: K = 489 + 9511 mod 4092 = 489 + 1327 = 1816 ≤ X → K.
        assert_eq!(local_payload(10_000, 4096), 1816);
        // U = 512: X = 477, M = ⌊500·32/255⌋ − 23 = 62 − 23 = 39. P = 478: K = 39 + 439 =
        // 478 > X → M; P = 647: K = 39 + 608 mod 508 = 139 ≤ X → K.
        assert_eq!(local_payload(478, 512), 39);
        assert_eq!(local_payload(647, 512), 139);
    }

    /// A 4-page database (page size 512, all usable) built byte by byte: page 1 the schema
    /// with table `t(a)` rooted at page 2; page 2 a leaf with one row (rowid 7) whose
    /// 1000-byte payload (one 997-byte blob) keeps M = 39 bytes on the page and spills 508
    /// bytes to page 3 and the last 453 to page 4.
    fn spilling_database() -> (Vec<u8>, Vec<u8>) {
        const PS: usize = 512;
        let mut file = vec![0u8; 4 * PS];
        let h = &mut file[..100];
        h[..16].copy_from_slice(crate::io::rosbag::SQLITE_MAGIC);
        h[16..18].copy_from_slice(&512u16.to_be_bytes());
        h[18] = 1;
        h[19] = 1;
        h[21..24].copy_from_slice(&[64, 32, 32]);
        h[24..28].copy_from_slice(&1u32.to_be_bytes());
        h[28..32].copy_from_slice(&4u32.to_be_bytes());
        h[56..60].copy_from_slice(&1u32.to_be_bytes());
        h[92..96].copy_from_slice(&1u32.to_be_bytes());
        // Leaf page with one cell at the end of the page: 8-byte header, one pointer.
        let leaf = |page: &mut [u8], head: usize, cell: &[u8]| {
            let at = PS - cell.len();
            page[head] = 0x0d;
            page[head + 3..head + 5].copy_from_slice(&1u16.to_be_bytes());
            page[head + 5..head + 7].copy_from_slice(&(at as u16).to_be_bytes());
            page[head + 8..head + 10].copy_from_slice(&(at as u16).to_be_bytes());
            page[at..].copy_from_slice(cell);
        };
        let sql = b"CREATE TABLE t(a)";
        let mut schema = vec![6u8, 13 + 2 * 5, 15, 15, 1, 13 + 2 * sql.len() as u8];
        schema.extend(b"table");
        schema.extend(b"tt");
        schema.push(2);
        schema.extend(sql);
        let mut cell = vec![schema.len() as u8, 1];
        cell.extend(&schema);
        leaf(&mut file[..PS], 100, &cell);
        // The row: header [3, serial 12 + 2·997 = 2006 as a 2-byte varint], the blob.
        let blob: Vec<u8> = (0..997u32).map(|i| (i * 7 % 251) as u8).collect();
        let mut payload = vec![3u8, 0x80 | (2006 >> 7) as u8, (2006 & 0x7f) as u8];
        payload.extend(&blob);
        assert_eq!(payload.len(), 1000);
        // Cell: varint 1000 (2 bytes), rowid 7, the first 39 bytes, overflow page 3.
        let mut cell = vec![0x80 | (1000 >> 7) as u8, (1000 & 0x7f) as u8, 7];
        cell.extend(&payload[..39]);
        cell.extend(3u32.to_be_bytes());
        leaf(&mut file[PS..2 * PS], 0, &cell);
        file[2 * PS..2 * PS + 4].copy_from_slice(&4u32.to_be_bytes());
        file[2 * PS + 4..3 * PS].copy_from_slice(&payload[39..39 + 508]);
        file[3 * PS + 4..3 * PS + 4 + 453].copy_from_slice(&payload[39 + 508..]);
        (file, blob)
    }

    /// The rows of table `t` of the database `bytes`: (rowid, payload).
    fn rows_of(bytes: &[u8], tag: &str) -> Result<Vec<(i64, Vec<u8>)>, LogError> {
        let path = std::env::temp_dir().join(format!(
            "driftless-sqlite-test-{}-{tag}.db3",
            std::process::id()
        ));
        std::fs::write(&path, bytes).unwrap();
        let mut file = std::fs::File::open(&path).unwrap();
        let size = bytes.len() as u64;
        let out = (|| {
            let mut db = Db::open(&mut file, "test.db3", size)?;
            let tables = db.tables()?;
            assert_eq!(tables.len(), 1);
            assert_eq!((tables[0].name.as_str(), tables[0].root), ("t", 2));
            assert_eq!(column_names(&tables[0].sql), ["a"]);
            let mut rows = Vec::new();
            db.scan(2, &mut |_, rowid, _, payload| {
                rows.push((rowid, payload.to_vec()));
                Ok(())
            })?;
            Ok(rows)
        })();
        let _ = std::fs::remove_file(&path);
        out
    }

    #[test]
    fn overflow_chain_gives_back_the_payload() {
        let (file, blob) = spilling_database();
        let rows = rows_of(&file, "spill").unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].0, 7);
        assert_eq!(record(&rows[0].1).unwrap(), vec![Value::Blob(&blob)]);
    }

    #[test]
    fn broken_chains_and_loops_are_errors() {
        let (file, _) = spilling_database();
        // The last overflow page cut off (header and file say 3 pages).
        let mut cut = file[..3 * 512].to_vec();
        cut[28..32].copy_from_slice(&3u32.to_be_bytes());
        let e = rows_of(&cut, "cut").unwrap_err().to_string();
        assert!(
            e.contains("page number 4 outside the file's 3 pages"),
            "{e}"
        );
        // Page 2 made an interior page whose right-most child is itself.
        let mut looped = file.clone();
        looped[512..524].copy_from_slice(&[5, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 2]);
        let e = rows_of(&looped, "loop").unwrap_err().to_string();
        assert!(e.contains("page loop"), "{e}");
        // A cell pointer past the end of its page (and of the file): reported at the
        // pointer (page 2 at byte 512, its first pointer 8 bytes in).
        let mut wild = file.clone();
        wild[520..522].copy_from_slice(&0xfff6u16.to_be_bytes());
        match rows_of(&wild, "wild") {
            Err(LogError::AtByte {
                byte_offset,
                message,
                ..
            }) => {
                assert_eq!(byte_offset, 520);
                assert!(
                    message.contains("offset 65526 outside the page"),
                    "{message}"
                );
            }
            other => panic!("{other:?}"),
        }
        // The header declaring more pages than the file holds.
        let mut short = file.clone();
        short[28..32].copy_from_slice(&9u32.to_be_bytes());
        let e = rows_of(&short, "short").unwrap_err().to_string();
        assert!(e.contains("truncated") && e.contains("9 pages"), "{e}");
    }

    #[test]
    fn column_names_of_create_statements() {
        assert_eq!(
            column_names(
                "CREATE TABLE messages(\n  id INTEGER PRIMARY KEY,\n  topic_id INTEGER NOT \
                 NULL,\n  timestamp INTEGER NOT NULL,\n  data BLOB NOT NULL\n)"
            ),
            ["id", "topic_id", "timestamp", "data"]
        );
        assert_eq!(
            column_names(
                "CREATE TABLE \"t\"(\"a b\" NUMERIC(10, 2), [c] TEXT, `d`, PRIMARY KEY(a, c))"
            ),
            ["a b", "c", "d"]
        );
        assert!(column_names("CREATE TABLE x").is_empty());
    }
}

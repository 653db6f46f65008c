//! Parsing data lines to SI columns by the plan, one piece of a chunk at a time, and the
//! row → line map and errors that locate a bad field.

use crate::io::error::{Location, LogError, excerpt};
use crate::io::number::{parse_f64, parse_prefix};

use super::fields::{Delim, for_each_field, is_blank_or_comment};
use super::plan::Plan;

pub(super) enum FieldErr {
    NonNumeric { field: usize, value: String },
    Empty { field: usize },
    NonFinite { field: usize, value: String },
    Ragged { found: usize },
    TooLong,
}

pub(super) struct PieceErr {
    /// 0-based line within the piece.
    pub(super) line: usize,
    /// Byte offset of the line's start within the piece.
    pub(super) byte: usize,
    /// 1-based byte column.
    pub(super) col: usize,
    pub(super) kind: FieldErr,
}

pub(super) struct PieceOut {
    pub(super) cols: Vec<Vec<f64>>,
    pub(super) rows: usize,
    pub(super) lines: usize,
    /// (row within piece, line within piece) where the row→line offset changes.
    pub(super) anchors: Vec<(usize, usize)>,
}

/// Parses one data line into `cols`. `Ok(false)` for blank/comment lines.
#[inline]
pub(super) fn parse_line(
    line: &[u8],
    plan: &Plan,
    cols: &mut [Vec<f64>],
) -> Result<bool, (usize, FieldErr)> {
    if is_blank_or_comment(line) {
        return Ok(false);
    }
    let mut extra_at = None;
    let found = for_each_field(line, plan.delim, |field, start, text| {
        let Some(slot) = plan.slots.get(field) else {
            extra_at.get_or_insert(start);
            return Ok(());
        };
        if let Some(slot) = slot {
            if text.is_empty() {
                return Err((start + 1, FieldErr::Empty { field: field + 1 }));
            }
            let raw = parse_f64(text).ok_or_else(|| {
                (
                    start + 1,
                    FieldErr::NonNumeric {
                        field: field + 1,
                        value: excerpt(text),
                    },
                )
            })?;
            let v = (raw - slot.offset) * slot.scale;
            if !v.is_finite() {
                return Err((
                    start + 1,
                    FieldErr::NonFinite {
                        field: field + 1,
                        value: excerpt(text),
                    },
                ));
            }
            if let Some(c) = cols.get_mut(slot.out) {
                c.push(v);
            }
        }
        Ok(())
    })?;
    if found != plan.nfields {
        let col = extra_at.unwrap_or(line.len()) + 1;
        return Err((col, FieldErr::Ragged { found }));
    }
    Ok(true)
}

/// Fast path for one plain data row starting at `p` (no comment, only the number forms
/// of [`parse_prefix`], single spaces/tabs): pushes one value per output column and returns
/// the offset after the row's line end. `None` sends the row to the general path
/// ([`parse_line`]), which accepts a superset, gives identical values and builds errors.
#[inline]
pub(super) fn fast_row(
    b: &[u8],
    mut p: usize,
    plan: &Plan,
    cols: &mut [Vec<f64>],
) -> Option<usize> {
    let n = b.len();
    let last = plan.nfields.checked_sub(1)?;
    let ws = plan.delim == Delim::Whitespace;
    let d = match plan.delim {
        Delim::Byte(d) => d,
        Delim::Whitespace => b' ',
    };
    for (field, slot) in plan.slots.iter().enumerate() {
        while p < n && (b[p] == b' ' || (ws && b[p] == b'\t')) {
            p += 1;
        }
        if let Some(slot) = slot {
            let (raw, used) = parse_prefix(b.get(p..)?)?;
            let v = (raw - slot.offset) * slot.scale;
            if !v.is_finite() {
                return None;
            }
            cols.get_mut(slot.out)?.push(v);
            p += used;
        } else if ws {
            while p < n && !matches!(b[p], b' ' | b'\t' | b'\n' | b'\r' | b'#') {
                p += 1;
            }
        } else {
            while p < n && !matches!(b[p], b'\n' | b'\r' | b'#') && b[p] != d {
                p += 1;
            }
        }
        if field < last {
            if ws {
                if p < n && (b[p] == b' ' || b[p] == b'\t') {
                    continue;
                }
                return None;
            }
            while p < n && b[p] == b' ' {
                p += 1;
            }
            if p < n && b[p] == d {
                p += 1;
                continue;
            }
            return None;
        }
    }
    while p < n && (b[p] == b' ' || b[p] == b'\t') {
        p += 1;
    }
    if !ws && p < n && b[p] == d {
        p += 1;
        while p < n && b[p] == b' ' {
            p += 1;
        }
    }
    if p < n && b[p] == b'\r' {
        p += 1;
    }
    if p >= n {
        Some(n)
    } else if b[p] == b'\n' {
        Some(p + 1)
    } else {
        None
    }
}

pub(super) fn parse_piece(
    bytes: &[u8],
    plan: &Plan,
    row_guess: usize,
) -> Result<PieceOut, PieceErr> {
    let mut cols: Vec<Vec<f64>> = (0..plan.nout)
        .map(|_| Vec::with_capacity(row_guess))
        .collect();
    let mut rows = 0;
    let mut line_no = 0;
    let mut anchors = Vec::new();
    let mut next_expected = usize::MAX;
    let mut pos = 0;
    while pos < bytes.len() {
        let is_data = match fast_row(bytes, pos, plan, &mut cols) {
            Some(next) => {
                if next - pos > plan.max_line {
                    return Err(PieceErr {
                        line: line_no,
                        byte: pos,
                        col: 1,
                        kind: FieldErr::TooLong,
                    });
                }
                pos = next;
                true
            }
            None => {
                for c in &mut cols {
                    c.truncate(rows);
                }
                let rest = &bytes[pos..];
                let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
                if len > plan.max_line {
                    return Err(PieceErr {
                        line: line_no,
                        byte: pos,
                        col: 1,
                        kind: FieldErr::TooLong,
                    });
                }
                let line = &rest[..len];
                let line = line.strip_suffix(b"\r").unwrap_or(line);
                let line_start = pos;
                pos += len + 1;
                match parse_line(line, plan, &mut cols) {
                    Ok(d) => d,
                    Err((col, kind)) => {
                        return Err(PieceErr {
                            line: line_no,
                            byte: line_start,
                            col,
                            kind,
                        });
                    }
                }
            }
        };
        if is_data {
            if line_no != next_expected {
                anchors.push((rows, line_no));
            }
            rows += 1;
            next_expected = line_no + 1;
        }
        line_no += 1;
    }
    Ok(PieceOut {
        cols,
        rows,
        lines: line_no,
        anchors,
    })
}

/// Row → 1-based line lookup from sparse anchors.
pub(super) struct LineMap {
    pub(super) anchors: Vec<(usize, usize)>,
}

impl LineMap {
    pub(super) fn line_of(&self, row: usize) -> usize {
        let i = self.anchors.partition_point(|a| a.0 <= row);
        match i.checked_sub(1).and_then(|i| self.anchors.get(i)) {
            Some(&(r, l)) => l + (row - r),
            None => row + 1,
        }
    }
}

pub(super) fn piece_error(e: PieceErr, line_base: usize, plan: &Plan, source: &str) -> LogError {
    let at = Location::field(source, line_base + e.line, e.col);
    let name = |field: usize| plan.names.get(field - 1).cloned().unwrap_or_default();
    match e.kind {
        FieldErr::NonNumeric { field, value } => LogError::NonNumeric {
            at,
            value,
            field,
            name: name(field),
        },
        FieldErr::Empty { field } => LogError::EmptyField {
            at,
            field,
            name: name(field),
        },
        FieldErr::NonFinite { field, value } => LogError::NonFinite {
            at,
            value,
            field,
            name: name(field),
        },
        FieldErr::Ragged { found } => LogError::Ragged {
            at,
            found,
            expected: plan.nfields,
            reference_line: plan.reference_line,
        },
        FieldErr::TooLong => LogError::LineTooLong {
            at: Location::line(source, line_base + e.line),
            limit: plan.max_line,
        },
    }
}

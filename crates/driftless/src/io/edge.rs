//! Rows at the edges of a recording: the field-count reference row and records cut by the
//! start or end of a recording, shared by the text readers.
//!
//! **Reference row.** The field count every row must have is the first data row's, unless
//! the first row is shorter than the most common count of the rows after it (up to
//! [`REFERENCE_SAMPLE`] of them) and that count is not its own: then the first of those rows
//! with the most common count is the reference, so an error about a short first row cites a
//! row that is itself good. (A first row longer than the next ones stays the reference: a
//! cut record has fewer fields, never more.)
//!
//! **Truncated edge records.** A logger that starts or stops mid-line leaves a first record
//! that is the tail of a line and a last record that is the head of one. Such a record is
//! recognised by having fewer fields than the reference row, or by its cut field (the first
//! field of the first record, the last field of the last record) not being a number; a
//! reader that drops it reports a note naming the file, the line and the text dropped.

use super::error::excerpt;
use super::number::parse_f64;

/// Rows after the first that vote on the reference field count.
pub(crate) const REFERENCE_SAMPLE: usize = 16;

/// The reference field count and its 1-based line, from `(line, field count)` of the first
/// data rows in file order (the first row, then up to [`REFERENCE_SAMPLE`] more).
pub(crate) fn reference_count(rows: &[(usize, usize)]) -> Option<(usize, usize)> {
    let (&(line0, n0), rest) = rows.split_first()?;
    let rest = &rest[..rest.len().min(REFERENCE_SAMPLE)];
    if rest.is_empty() {
        return Some((n0, line0));
    }
    let freq = |n: usize| rest.iter().filter(|r| r.1 == n).count();
    let best = rest.iter().map(|r| freq(r.1)).max().unwrap_or(0);
    if freq(n0) == best {
        return Some((n0, line0));
    }
    match rest.iter().find(|r| freq(r.1) == best) {
        Some(&(line, n)) if n > n0 => Some((n, line)),
        _ => Some((n0, line0)),
    }
}

/// Which end of the recording a dropped record sat at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Edge {
    First,
    Last,
}

/// Why an edge record counts as truncated.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Cut {
    /// Fewer fields than the reference row.
    Fields {
        found: usize,
        expected: usize,
        reference_line: usize,
    },
    /// The cut field is not a number.
    Number { field: usize },
    /// The last record has no line end and its time stamp (the row's last field) does not
    /// follow the previous row's.
    Time { time_s: f64, previous_s: f64 },
}

/// True when a field's text is a (finite or not) number.
pub(crate) fn is_number(t: &[u8]) -> bool {
    !t.is_empty() && parse_f64(t).is_some()
}

/// Whether an edge record with field texts `fields` is cut, against the reference row's
/// `expected` fields: fewer fields, or the cut field (the first of the first record, the
/// last of the last) is not a number.
pub(crate) fn cut_record(
    fields: &[&[u8]],
    expected: usize,
    reference_line: usize,
    edge: Edge,
) -> Option<Cut> {
    if fields.len() < expected {
        return Some(Cut::Fields {
            found: fields.len(),
            expected,
            reference_line,
        });
    }
    let (k, f) = match edge {
        Edge::First => (1, fields.first()),
        Edge::Last => (fields.len(), fields.last()),
    };
    match f {
        Some(t) if fields.len() == expected && !is_number(t) => Some(Cut::Number { field: k }),
        _ => None,
    }
}

/// The last data line of `data` (`is_data` tells data lines from blank and comment lines,
/// given the line without its line end): its start and end (before the line end, `\r`
/// included) and whether a line end follows it.
pub(crate) fn last_data_line(
    data: &[u8],
    is_data: impl Fn(&[u8]) -> bool,
) -> Option<(usize, usize, bool)> {
    let mut hi = data.len();
    while hi > 0 {
        let (content_end, terminated) = if data[hi - 1] == b'\n' {
            (hi - 1, true)
        } else {
            (hi, false)
        };
        let ls = data[..content_end]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        let line = &data[ls..content_end];
        if is_data(line.strip_suffix(b"\r").unwrap_or(line)) {
            return Some((ls, content_end, terminated));
        }
        hi = ls;
    }
    None
}

/// 1-based line number of byte offset `at` of `data`.
pub(crate) fn line_of_offset(data: &[u8], at: usize) -> usize {
    data[..at.min(data.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The words of a note that say which record was dropped.
fn dropped_phrase(edge: Edge) -> &'static str {
    match edge {
        Edge::First => "dropped the first record",
        Edge::Last => "dropped the last record",
    }
}

/// True when `notes` report a dropped record at `edge`.
pub(crate) fn was_dropped(notes: &[String], edge: Edge) -> bool {
    notes.iter().any(|n| n.contains(dropped_phrase(edge)))
}

/// The note reported for a dropped edge record.
pub(crate) fn note(source: &str, line: usize, edge: Edge, cut: &Cut, text: &[u8]) -> String {
    let by = match edge {
        Edge::First => "start",
        Edge::Last => "end",
    };
    let why = match cut {
        Cut::Fields {
            found,
            expected,
            reference_line,
        } => format!("it has {found} fields, line {reference_line} has {expected}"),
        Cut::Number { field } => format!("its field {field} is not a number"),
        Cut::Time { time_s, previous_s } => format!(
            "it has no line end and its time stamp {time_s} s does not follow the previous {previous_s} s"
        ),
    };
    format!(
        "{source}:{line}: {} {:?}, cut by the {by} of the recording: {why}",
        dropped_phrase(edge),
        excerpt(text)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn last_line_and_cuts() {
        let data = b"1 2\n3 4\n# end\n\n";
        let hash = |l: &[u8]| !l.is_empty() && !l.starts_with(b"#");
        assert_eq!(last_data_line(data, hash), Some((4, 7, true)));
        assert_eq!(last_data_line(b"1 2\n3", hash), Some((4, 5, false)));
        assert_eq!(last_data_line(b"\n# x\n", hash), None);
        assert_eq!(line_of_offset(data, 4), 2);
        let row: Vec<&[u8]> = vec![b"1", b"2", b"3e"];
        assert_eq!(
            cut_record(&row, 3, 1, Edge::Last),
            Some(Cut::Number { field: 3 })
        );
        assert_eq!(cut_record(&row, 3, 1, Edge::First), None);
        assert_eq!(
            cut_record(&row[..2], 3, 5, Edge::First),
            Some(Cut::Fields {
                found: 2,
                expected: 3,
                reference_line: 5
            })
        );
    }

    #[test]
    fn reference_is_first_row_unless_outvoted() {
        assert_eq!(reference_count(&[]), None);
        assert_eq!(reference_count(&[(3, 5)]), Some((5, 3)));
        // The first row agrees with the rows after it.
        assert_eq!(reference_count(&[(1, 7), (2, 7), (3, 6)]), Some((7, 1)));
        // A short first row: the next rows' count wins, cited at its first line.
        assert_eq!(reference_count(&[(1, 6), (2, 7), (4, 7)]), Some((7, 2)));
        assert_eq!(reference_count(&[(1, 3), (2, 4)]), Some((4, 2)));
        // A tie that includes the first row's count keeps the first row.
        assert_eq!(reference_count(&[(1, 3), (2, 4), (3, 3)]), Some((3, 1)));
        // Many short rows after a full first row: the first row stays the reference.
        assert_eq!(
            reference_count(&[(1, 7), (2, 6), (3, 6), (4, 7)]),
            Some((7, 1))
        );
        assert_eq!(reference_count(&[(1, 4), (2, 3)]), Some((4, 1)));
    }
}

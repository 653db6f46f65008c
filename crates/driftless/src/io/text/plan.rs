//! The parse plan: delimiter, header, reference field count and which field goes to which
//! output column (with its unit's scale), built from the first non-comment lines.

use crate::io::edge::{Cut, Edge, REFERENCE_SAMPLE, is_number, note, reference_count};
use crate::io::error::{Location, LogError};
use crate::io::number::parse_f64;
use crate::io::units::{KNOWN_UNITS, TimeUnit, Unit};

use super::fields::{Delim, detect_delimiter, field_count, field_text, for_each_field, ragged_col};
use super::header::{TIME_COLUMN_NAMES, detect_time_field, resolve, split_name_unit};
use super::options::{ColumnRef, ColumnSpec, Delimiter, HeaderMode, TextOptions};

#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    pub(super) out: usize,
    pub(super) scale: f64,
    pub(super) offset: f64,
}

#[derive(Debug)]
pub(super) struct Plan {
    pub(super) delim: Delim,
    pub(super) nfields: usize,
    /// Line that fixed the field count (header or reference data row, see `io::edge`).
    pub(super) reference_line: usize,
    pub(super) names: Vec<String>,
    pub(super) slots: Vec<Option<Slot>>,
    /// Output vectors: time (if any) first, then channels.
    pub(super) nout: usize,
    pub(super) time_field: Option<usize>,
    pub(super) channels: Vec<(usize, String, Unit)>,
    pub(super) header_line: Option<usize>,
    /// Field of the week column, whose output vector comes after the channels'.
    pub(super) week_field: Option<usize>,
    /// The time column was found by its header name (for the log's notes).
    pub(super) time_detected: bool,
    /// Longest line accepted, bytes.
    pub(super) max_line: usize,
}

/// A non-comment line of the first chunk: 1-based number, byte range of the line with its
/// line end in the chunk, and its text without the line end.
pub(super) struct SampleLine<'a> {
    pub(super) line: usize,
    pub(super) end: usize,
    pub(super) text: &'a [u8],
}

/// The plan, and where the data starts: the index into the sample of the first data line
/// to parse (`sample.len()` when the sample holds none), with the note for a dropped first
/// record.
pub(super) type PlanStart = (Plan, usize, Option<String>);

/// Builds the plan from the first non-comment lines of the input (`sample[0]` is the
/// first; the rest vote on the reference field count and, with `Delimiter::Auto`, on the
/// delimiter).
pub(super) fn make_plan(
    sample: &[SampleLine<'_>],
    source: &str,
    opts: &TextOptions,
) -> Result<PlanStart, LogError> {
    let Some(head) = sample.first() else {
        return Err(LogError::Empty {
            at: Location::input(source),
        });
    };
    let line_no = head.line;
    let delim = choose_delimiter(sample, opts.delimiter);
    let first = FirstRow::scan(head.text, delim);
    // With dropping on, a first line whose fields are numbers but for the first is a
    // record cut inside its first number, not a header.
    let cut_first_line = opts.drop_truncated_edges
        && first.fields.len() >= 2
        && first.rest_numeric
        && sample.len() >= 2;
    let has_header = match opts.header {
        HeaderMode::Auto => !first.numeric && !cut_first_line,
        HeaderMode::Present => true,
        HeaderMode::Absent => false,
    };
    let data = if has_header { &sample[1..] } else { sample };
    let (nfields, reference_line) = if has_header {
        (first.fields.len(), line_no)
    } else {
        let rows: Vec<(usize, usize)> = data
            .iter()
            .take(REFERENCE_SAMPLE + 1)
            .map(|l| (l.line, field_count(l.text, delim)))
            .collect();
        reference_count(&rows).unwrap_or((first.fields.len(), line_no))
    };
    let at_line = Location::line(source, line_no);
    let (names, hints) = column_names(
        &first.fields,
        has_header,
        nfields,
        reference_line,
        line_no,
        source,
        opts,
    )?;
    let header = HeaderInfo {
        has_header,
        at_line,
        at_input: Location::input(source),
        hints,
    };
    let columns = assign_columns(&names, nfields, &header, opts)?;
    let plan = Plan {
        delim,
        nfields,
        reference_line,
        names,
        slots: columns.slots,
        nout: columns.nout,
        time_field: columns.time_field,
        channels: columns.channels,
        header_line: has_header.then_some(line_no),
        week_field: columns.week_field,
        time_detected: columns.time_detected,
        max_line: opts.max_line_bytes,
    };
    let (start, note_first) = first_data_row(&plan, sample, usize::from(has_header), source, opts)?;
    Ok((plan, start, note_first))
}

/// The delimiter given, or with `Delimiter::Auto` the first line's unless most sampled
/// lines say otherwise (a cut first record may hold a single field).
fn choose_delimiter(sample: &[SampleLine<'_>], given: Delimiter) -> Delim {
    match given {
        Delimiter::Auto => {
            let votes: Vec<Delim> = sample.iter().map(|l| detect_delimiter(l.text)).collect();
            let count = |d: Delim| votes.iter().filter(|&&v| v == d).count();
            let mut best = votes[0];
            for &v in &votes {
                if count(v) > count(best) {
                    best = v;
                }
            }
            best
        }
        Delimiter::Comma => Delim::Byte(b','),
        Delimiter::Semicolon => Delim::Byte(b';'),
        Delimiter::Tab => Delim::Byte(b'\t'),
        Delimiter::Whitespace => Delim::Whitespace,
    }
}

/// The first non-comment line split into fields, and whether they are numbers.
struct FirstRow {
    fields: Vec<String>,
    /// Every non-empty field is a number.
    numeric: bool,
    /// Every field after the first is a number.
    rest_numeric: bool,
}

impl FirstRow {
    fn scan(first: &[u8], delim: Delim) -> Self {
        let mut fields: Vec<String> = Vec::new();
        let mut numeric = true;
        let mut rest_numeric = true;
        let _ = for_each_field(first, delim, |k, _, t| {
            let bad = !t.is_empty() && parse_f64(t).is_none();
            numeric &= !bad;
            if k > 0 {
                rest_numeric &= is_number(t);
            }
            fields.push(String::from_utf8_lossy(t).into_owned());
            Ok::<(), ()>(())
        });
        Self {
            fields,
            numeric,
            rest_numeric,
        }
    }
}

/// Column names (the header's without units, `colN` for empty ones and without a header,
/// or the names given) and the header's unit hints per field.
fn column_names(
    fields: &[String],
    has_header: bool,
    nfields: usize,
    reference_line: usize,
    line_no: usize,
    source: &str,
    opts: &TextOptions,
) -> Result<(Vec<String>, Vec<Option<String>>), LogError> {
    let (mut names, hints): (Vec<String>, Vec<Option<String>>) = if has_header {
        fields.iter().map(|f| split_name_unit(f)).unzip()
    } else {
        (
            (1..=nfields).map(|i| format!("col{i}")).collect(),
            vec![None; nfields],
        )
    };
    for (i, n) in names.iter_mut().enumerate() {
        if n.is_empty() {
            *n = format!("col{}", i + 1);
        }
    }
    if let Some(given) = &opts.column_names {
        if given.len() != nfields {
            let at = if has_header || reference_line == line_no {
                Location::line(source, line_no)
            } else {
                Location::line(source, reference_line)
            };
            return Err(LogError::InvalidOptions {
                at,
                message: format!(
                    "{} column names given, but the row has {nfields} fields",
                    given.len()
                ),
            });
        }
        names = given.clone();
    }
    Ok((names, hints))
}

/// What the header says that column selection needs: whether there is one, where errors
/// point, and the unit hints per field.
struct HeaderInfo {
    has_header: bool,
    /// The first line (the header's, when there is one).
    at_line: Location,
    at_input: Location,
    hints: Vec<Option<String>>,
}

impl HeaderInfo {
    /// Where an error about a column selected by name or number points.
    fn loc(&self) -> &Location {
        if self.has_header {
            &self.at_line
        } else {
            &self.at_input
        }
    }

    /// The unit given in the header for `field`, if any.
    fn hint_unit(&self, field: usize, column: &str) -> Result<Option<Unit>, LogError> {
        match self.hints.get(field).and_then(|h| h.as_deref()) {
            None => Ok(None),
            Some(h) => Unit::parse(h).map(Some).map_err(|_| LogError::UnknownUnit {
                at: self.at_line.clone(),
                unit: h.to_owned(),
                column: column.to_owned(),
                known: KNOWN_UNITS,
            }),
        }
    }
}

/// The selected fields and their output vectors: time first, then channels, then week.
struct Columns {
    slots: Vec<Option<Slot>>,
    nout: usize,
    time_field: Option<usize>,
    week_field: Option<usize>,
    channels: Vec<(usize, String, Unit)>,
    time_detected: bool,
}

/// Resolves the time, week and data columns to fields with their units.
fn assign_columns(
    names: &[String],
    nfields: usize,
    header: &HeaderInfo,
    opts: &TextOptions,
) -> Result<Columns, LogError> {
    let mut slots: Vec<Option<Slot>> = vec![None; nfields];
    let mut nout = 0;
    let detected = match (
        &opts.time_column,
        opts.detect_time_column && header.has_header,
    ) {
        (None, true) => detect_time_field(names, &header.at_line)?,
        _ => None,
    };
    if opts.time_column.is_none() && detected.is_none() && opts.rate_hz.is_none() {
        return Err(LogError::InvalidOptions {
            at: header.loc().clone(),
            message: format!(
                "no time column and no sample rate: no header field is named as a time column \
                 ({}); give the time column (`--time-column NAME|N`) or the sample rate \
                 (`--rate HZ`)",
                TIME_COLUMN_NAMES.join(", ")
            ),
        });
    }
    let time_ref = opts
        .time_column
        .clone()
        .or(detected.map(|f| ColumnRef::Index(f + 1)));
    let time_field = match &time_ref {
        None => None,
        Some(r) => {
            let f = resolve(r, names, header.loc())?;
            let unit = match opts.time_unit {
                Some(u) => u,
                None => match header.hints.get(f).and_then(|h| h.as_deref()) {
                    None => TimeUnit::Seconds,
                    Some(h) => h.parse().map_err(|_| LogError::UnknownUnit {
                        at: header.at_line.clone(),
                        unit: h.to_owned(),
                        column: names[f].clone(),
                        known: "s, ms, us, ns",
                    })?,
                },
            };
            slots[f] = Some(Slot {
                out: 0,
                scale: unit.to_s(),
                offset: 0.0,
            });
            nout = 1;
            Some(f)
        }
    };
    let week_field = match &opts.week_column {
        Some(r) => Some(resolve(r, names, header.loc())?),
        None => None,
    };
    let channels = assign_channels(
        names,
        nfields,
        header,
        opts,
        (time_field, week_field),
        &mut slots,
        &mut nout,
    )?;
    if let Some(f) = week_field {
        if time_field.is_none() {
            return Err(LogError::InvalidOptions {
                at: header.at_input.clone(),
                message: "a week column needs a time column (the seconds of week)".into(),
            });
        }
        if slots[f].is_some() {
            return Err(selected_twice(f, names, header));
        }
        slots[f] = Some(Slot {
            out: nout,
            scale: 1.0,
            offset: 0.0,
        });
        nout += 1;
    }
    Ok(Columns {
        slots,
        nout,
        time_field,
        week_field,
        channels,
        time_detected: detected.is_some(),
    })
}

/// The error for a field selected as more than one of time, week and data.
fn selected_twice(f: usize, names: &[String], header: &HeaderInfo) -> LogError {
    LogError::InvalidOptions {
        at: header.at_input.clone(),
        message: format!(
            "column {} ({}) is selected twice (as time, week or data)",
            f + 1,
            names[f]
        ),
    }
}

/// The data columns (those given, else every field but the time and week), each with its
/// unit: given, else the header's, else the default.
fn assign_channels(
    names: &[String],
    nfields: usize,
    header: &HeaderInfo,
    opts: &TextOptions,
    (time_field, week_field): (Option<usize>, Option<usize>),
    slots: &mut [Option<Slot>],
    nout: &mut usize,
) -> Result<Vec<(usize, String, Unit)>, LogError> {
    let specs: Vec<ColumnSpec> = if opts.columns.is_empty() {
        (1..=nfields)
            .filter(|&i| Some(i - 1) != time_field && Some(i - 1) != week_field)
            .map(|i| ColumnSpec {
                column: ColumnRef::Index(i),
                unit: None,
                rename: None,
            })
            .collect()
    } else {
        opts.columns.clone()
    };
    let mut channels = Vec::with_capacity(specs.len());
    for spec in &specs {
        let f = resolve(&spec.column, names, header.loc())?;
        if slots[f].is_some() || Some(f) == week_field {
            return Err(selected_twice(f, names, header));
        }
        let unit = match &spec.unit {
            Some(u) => u.clone(),
            None => match header.hint_unit(f, &names[f]) {
                Ok(Some(u)) => u,
                Ok(None) => opts.default_unit.clone().unwrap_or_default(),
                Err(e) if opts.default_unit.is_none() => return Err(e),
                Err(_) => opts.default_unit.clone().unwrap_or_default(),
            },
        };
        slots[f] = Some(Slot {
            out: *nout,
            scale: unit.scale_si,
            offset: unit.offset_raw,
        });
        *nout += 1;
        let name = spec.rename.clone().unwrap_or_else(|| names[f].clone());
        channels.push((f, name, unit));
    }
    if channels.is_empty() {
        return Err(LogError::InvalidOptions {
            at: header.at_input.clone(),
            message: "no data columns to read (the only column is the time column)".into(),
        });
    }
    Ok(channels)
}

/// The first data row (`sample[k]`): whole, dropped as a cut record (returning the note),
/// or an error citing a good row. Returns the index of the first data line to parse.
fn first_data_row(
    plan: &Plan,
    sample: &[SampleLine<'_>],
    k: usize,
    source: &str,
    opts: &TextOptions,
) -> Result<(usize, Option<String>), LogError> {
    let (delim, nfields, reference_line) = (plan.delim, plan.nfields, plan.reference_line);
    let Some(row) = sample.get(k) else {
        return Ok((k, None));
    };
    let found = field_count(row.text, delim);
    let parsed_first = plan.slots.first().is_some_and(Option::is_some);
    let cut = if found < nfields {
        Some(Cut::Fields {
            found,
            expected: nfields,
            reference_line,
        })
    } else if found == nfields
        && parsed_first
        && !field_text(row.text, delim, 0).is_some_and(|t| is_number(&t))
    {
        Some(Cut::Number { field: 1 })
    } else {
        None
    };
    match cut {
        Some(cut) if opts.drop_truncated_edges && sample.len() > k + 1 => Ok((
            k + 1,
            Some(note(source, row.line, Edge::First, &cut, row.text)),
        )),
        _ if found != nfields => Err(LogError::Ragged {
            at: Location::field(source, row.line, ragged_col(row.text, delim, nfields)),
            found,
            expected: nfields,
            reference_line,
        }),
        _ => Ok((k, None)),
    }
}

//! The streaming read: chunks cut at line ends, the plan from the first lines, pieces parsed
//! in parallel, truncated edge records and the row count a driftless CSV declares.

use std::io::Read;

use rayon::prelude::*;

use crate::io::edge::{Cut, Edge, REFERENCE_SAMPLE, last_data_line, note};
use crate::io::error::{Location, LogError};
use crate::io::input::{SNIFF_BYTES, binary_error};
use crate::io::log::{Channel, ImuLog};

use super::fields::{
    declared_rows, euroc_header, field_count, is_blank_or_comment, line_len_with_end, lines,
    split_pieces,
};
use super::options::{TextOptions, validate};
use super::parse::{FieldErr, LineMap, PieceErr, PieceOut, parse_line, parse_piece, piece_error};
use super::plan::{Plan, SampleLine, make_plan};
use super::time::{combine_weeks, time_analysis};

/// Reads a whole text log: chunks cut at the last line end, the plan from the first
/// non-comment lines, then every chunk parsed by it.
pub(super) fn read_impl<R: Read>(
    mut reader: R,
    source: &str,
    opts: &TextOptions,
    size_hint: Option<u64>,
) -> Result<ImuLog, LogError> {
    validate(opts, source)?;
    let ctx = Context {
        source,
        opts,
        threads: rayon::current_num_threads().max(1),
        size_hint,
    };
    let mut buf = vec![0u8; opts.chunk_bytes.max(64)];
    let mut filled = 0;
    let mut eof = false;
    let mut plan: Option<Plan> = None;
    let mut line_base = 1usize; // 1-based line number of buf[0]
    let mut acc = Collected::default();
    // Rows the header of a file written by driftless states (`write::write_csv`), and
    // whether it ends with the end mark; whether the input read so far does.
    let mut declared: Option<(usize, bool)> = None;
    let mut ends_marked = false;
    // Bytes of the input before buf[0].
    let mut consumed = 0u64;
    loop {
        fill(&mut reader, &mut buf, &mut filled, &mut eof, source)?;
        // The input's first SNIFF_BYTES, whatever the chunk size: read them whole before
        // judging (the share of bytes that are not UTF-8 is a share of this window), once.
        if consumed == 0 {
            if !eof && filled < SNIFF_BYTES {
                buf.resize(SNIFF_BYTES, 0);
                continue;
            }
            if let Some(e) = binary_error(&buf[..filled.min(SNIFF_BYTES)], 0, source) {
                return Err(e);
            }
        }
        let end = if eof {
            filled
        } else {
            match buf[..filled].iter().rposition(|&b| b == b'\n') {
                Some(i) => i + 1,
                None if filled > opts.max_line_bytes => {
                    // A line longer than the cap: stop before buffering more of it.
                    return Err(
                        binary_error(&buf[..filled.min(SNIFF_BYTES)], consumed, source)
                            .unwrap_or_else(|| LogError::LineTooLong {
                                at: Location::line(source, line_base),
                                limit: opts.max_line_bytes,
                            }),
                    );
                }
                None => {
                    // One line longer than the buffer: grow and read on.
                    let n = buf.len();
                    buf.resize(n.saturating_mul(2), 0);
                    continue;
                }
            }
        };
        let region = &buf[..end];
        let mut start = 0;
        if line_base == 1 && plan.is_none() {
            declared = declared.or_else(|| declared_rows(region));
        }
        let tail = region.trim_ascii_end();
        if !tail.is_empty() {
            ends_marked = tail.ends_with(crate::io::write::END_MARK.as_bytes());
        }
        if plan.is_none() {
            let (sample, starts) = sample_lines(region, line_base, consumed, source, opts)?;
            if !eof && !sample.is_empty() && sample.len() <= REFERENCE_SAMPLE + 2 {
                // The plan's votes (delimiter, reference field count) take the same lines
                // whatever the chunk size: read on until the sample is full or the input
                // ends (at most REFERENCE_SAMPLE + 3 lines of at most `max_line_bytes`).
                let n = buf.len();
                buf.resize(n.saturating_mul(2), 0);
                continue;
            }
            if sample.is_empty() {
                line_base += lines(region).count();
                start = end;
            } else {
                let (p, first, note_first) = make_plan(&sample, source, opts)?;
                acc.notes.extend(note_first);
                match (sample.get(first), first.checked_sub(1).map(|i| &sample[i])) {
                    (Some(row), _) => {
                        start = starts[first];
                        line_base = row.line;
                    }
                    (None, Some(prev)) => {
                        start = prev.end;
                        line_base = prev.line + 1;
                    }
                    (None, None) => {}
                }
                plan = Some(p);
            }
        }
        if let Some(p) = &plan
            && start < end
        {
            let region = Region {
                bytes: region,
                start,
                end,
                consumed,
                eof,
            };
            acc.parse_region(p, &region, &mut line_base, &ctx)?;
        }
        if eof {
            break;
        }
        buf.copy_within(end..filled, 0);
        filled -= end;
        consumed += end as u64;
    }
    let Some(plan) = plan else {
        return Err(LogError::Empty {
            at: Location::input(source),
        });
    };
    acc.finish(&plan, declared, ends_marked, source, opts)
}

/// Reads until the buffer is full or the input ends.
fn fill<R: Read>(
    reader: &mut R,
    buf: &mut [u8],
    filled: &mut usize,
    eof: &mut bool,
    source: &str,
) -> Result<(), LogError> {
    while *filled < buf.len() && !*eof {
        match reader.read(&mut buf[*filled..]) {
            Ok(0) => *eof = true,
            Ok(n) => *filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(error) => {
                return Err(LogError::Io {
                    path: source.to_owned(),
                    error,
                });
            }
        }
    }
    Ok(())
}

/// The first non-comment lines of a chunk for the plan (at most `REFERENCE_SAMPLE + 3`)
/// and their byte offsets; a line longer than the cap is an error.
fn sample_lines<'a>(
    region: &'a [u8],
    line_base: usize,
    consumed: u64,
    source: &str,
    opts: &TextOptions,
) -> Result<(Vec<SampleLine<'a>>, Vec<usize>), LogError> {
    let mut offset = 0;
    let mut sample = Vec::new();
    let mut starts = Vec::new();
    for (i, line) in lines(region).enumerate() {
        let this_len = line_len_with_end(region, offset);
        if line.len() > opts.max_line_bytes {
            let at = consumed + offset as u64;
            return Err(
                binary_error(&line[..line.len().min(SNIFF_BYTES)], at, source).unwrap_or_else(
                    || LogError::LineTooLong {
                        at: Location::line(source, line_base + i),
                        limit: opts.max_line_bytes,
                    },
                ),
            );
        }
        let euroc = sample.is_empty().then(|| euroc_header(line)).flatten();
        if let Some(text) = euroc.or((!is_blank_or_comment(line)).then_some(line)) {
            starts.push(offset);
            sample.push(SampleLine {
                line: line_base + i,
                end: offset + this_len,
                text,
            });
            if sample.len() > REFERENCE_SAMPLE + 2 {
                break;
            }
        }
        offset += this_len;
    }
    Ok((sample, starts))
}

/// The part of a chunk to parse: `bytes[start..end]`, with `consumed` bytes of the input
/// before `bytes[0]`; `eof` when the chunk ends the input.
struct Region<'a> {
    bytes: &'a [u8],
    start: usize,
    end: usize,
    consumed: u64,
    eof: bool,
}

/// What every chunk of one read shares: the input's name, the options, the threads to
/// parse on and the input's size when known (to pre-size the columns).
struct Context<'a> {
    source: &'a str,
    opts: &'a TextOptions,
    threads: usize,
    size_hint: Option<u64>,
}

/// What the streaming read has gathered so far.
#[derive(Default)]
struct Collected {
    /// Output columns, as the plan orders them.
    out: Vec<Vec<f64>>,
    rows_total: usize,
    /// (row, line) where the row → line offset changes.
    anchors: Vec<(usize, usize)>,
    bytes_per_row: Option<f64>,
    notes: Vec<String>,
    /// Line and text of a last record kept although it had no line end.
    unterminated_last: Option<(usize, Vec<u8>)>,
}

impl Collected {
    /// Parses the data of a chunk: the body in pieces (in parallel when large), then — at
    /// the end of the input, when truncated edges may be dropped — the last record on its
    /// own.
    fn parse_region(
        &mut self,
        p: &Plan,
        region: &Region<'_>,
        line_base: &mut usize,
        ctx: &Context<'_>,
    ) -> Result<(), LogError> {
        let (bytes, start, end) = (region.bytes, region.start, region.end);
        let (source, opts) = (ctx.source, ctx.opts);
        // The last data record, parsed on its own when it may be dropped.
        let (body_end, tail) = match (region.eof && opts.drop_truncated_edges)
            .then(|| last_data_line(&bytes[start..end], |l| !is_blank_or_comment(l)))
            .flatten()
        {
            Some((ls, le, terminated)) => (start + ls, Some((start + ls, start + le, terminated))),
            None => (end, None),
        };
        let data = &bytes[start..body_end];
        let pieces = split_pieces(
            data,
            if data.len() >= (1 << 20) {
                ctx.threads
            } else {
                1
            },
        );
        let row_guess = self
            .bytes_per_row
            .map(|b| ((data.len() as f64 / pieces.len() as f64) / b * 1.05) as usize + 16)
            .unwrap_or(0);
        let results: Vec<Result<PieceOut, PieceErr>> = if pieces.len() > 1 {
            pieces
                .par_iter()
                .map(|s| parse_piece(s, p, row_guess))
                .collect()
        } else {
            pieces
                .iter()
                .map(|s| parse_piece(s, p, row_guess))
                .collect()
        };
        let region_rows: usize = results
            .iter()
            .map(|r| r.as_ref().map_or(0, |o| o.rows))
            .sum();
        if self.out.is_empty() {
            self.out = (0..p.nout).map(|_| Vec::new()).collect();
            if region_rows > 0 {
                let bpr = data.len() as f64 / region_rows as f64;
                self.bytes_per_row = Some(bpr);
                let est = match ctx.size_hint {
                    Some(size) => (size as f64 / bpr * 1.02) as usize + 1024,
                    None => region_rows,
                };
                for c in &mut self.out {
                    c.reserve_exact(est);
                }
            }
        }
        let mut piece_start = start;
        for (r, piece) in results.into_iter().zip(&pieces) {
            let this_start = piece_start;
            piece_start += piece.len();
            match r {
                Ok(piece) => self.append_piece(&piece, line_base),
                Err(e) => {
                    // A bad line holding binary data is reported as such.
                    let line = piece.get(e.byte..).unwrap_or(&[]);
                    let len = line.iter().position(|&b| b == b'\n').unwrap_or(line.len());
                    let line = &line[..len.min(SNIFF_BYTES)];
                    let at = region.consumed + (this_start + e.byte) as u64;
                    return Err(binary_error(line, at, source)
                        .unwrap_or_else(|| piece_error(e, *line_base, p, source)));
                }
            }
        }
        if let Some((ls, le, terminated)) = tail {
            let text = bytes[ls..le].strip_suffix(b"\r").unwrap_or(&bytes[ls..le]);
            self.parse_last(p, text, terminated, *line_base, source)?;
        }
        Ok(())
    }

    /// Appends a parsed piece's columns and its row → line anchors.
    fn append_piece(&mut self, piece: &PieceOut, line_base: &mut usize) {
        for (o, c) in self.out.iter_mut().zip(&piece.cols) {
            if o.capacity() - o.len() < c.len() {
                // Estimate too low: grow by at least 1/8 rather than doubling.
                o.reserve_exact(c.len().max(o.capacity() / 8));
            }
            o.extend_from_slice(c);
        }
        for &(r, l) in &piece.anchors {
            let (row, line) = (self.rows_total + r, *line_base + l);
            let predicted = self.anchors.last().map(|&(ar, al)| al + (row - ar));
            if predicted != Some(line) {
                self.anchors.push((row, line));
            }
        }
        self.rows_total += piece.rows;
        *line_base += piece.lines;
    }

    /// The input's last data record (line `line_base`): kept when whole, dropped with a
    /// note when cut short, else an error.
    fn parse_last(
        &mut self,
        p: &Plan,
        text: &[u8],
        terminated: bool,
        line_base: usize,
        source: &str,
    ) -> Result<(), LogError> {
        let mut row: Vec<Vec<f64>> = (0..p.nout).map(|_| Vec::with_capacity(1)).collect();
        match parse_line(text, p, &mut row) {
            Ok(_) => {
                if self.out.is_empty() {
                    self.out = (0..p.nout).map(|_| Vec::new()).collect();
                }
                for (o, c) in self.out.iter_mut().zip(&row) {
                    o.extend_from_slice(c);
                }
                if self
                    .anchors
                    .last()
                    .map(|&(ar, al)| al + (self.rows_total - ar))
                    != Some(line_base)
                {
                    self.anchors.push((self.rows_total, line_base));
                }
                self.rows_total += 1;
                if !terminated {
                    self.unterminated_last = Some((line_base, text.to_vec()));
                }
                Ok(())
            }
            Err((col, kind)) => {
                let found = field_count(text, p.delim);
                let cut = match kind {
                    FieldErr::Ragged { found } if found < p.nfields => Some(Cut::Fields {
                        found,
                        expected: p.nfields,
                        reference_line: p.reference_line,
                    }),
                    FieldErr::NonNumeric { field, .. } | FieldErr::Empty { field }
                        if field == found =>
                    {
                        Some(Cut::Number { field })
                    }
                    _ => None,
                };
                match cut {
                    Some(cut) => {
                        self.notes
                            .push(note(source, line_base, Edge::Last, &cut, text));
                        Ok(())
                    }
                    None => Err(piece_error(
                        PieceErr {
                            line: 0,
                            byte: 0,
                            col,
                            kind,
                        },
                        line_base,
                        p,
                        source,
                    )),
                }
            }
        }
    }

    /// The log from the parsed columns: checks of the row count, a cut last time stamp
    /// dropped, weeks combined, τ0, segments and gaps from the time column.
    fn finish(
        mut self,
        plan: &Plan,
        declared: Option<(usize, bool)>,
        ends_marked: bool,
        source: &str,
        opts: &TextOptions,
    ) -> Result<ImuLog, LogError> {
        if self.rows_total == 0 {
            return Err(match plan.header_line {
                Some(l) => LogError::HeaderOnly {
                    at: Location::line(source, l),
                },
                None => LogError::Empty {
                    at: Location::input(source),
                },
            });
        }
        // A last record without a line end whose time (its last field) does not advance was
        // cut inside the time stamp.
        if let (Some((line, text)), Some(tf), Some(t)) =
            (&self.unterminated_last, plan.time_field, self.out.first())
            && tf + 1 == plan.nfields
            && let [.., previous_s, time_s] = t[..]
            && time_s <= previous_s
        {
            let cut = Cut::Time { time_s, previous_s };
            self.notes.push(note(source, *line, Edge::Last, &cut, text));
            for c in &mut self.out {
                c.pop();
            }
            self.rows_total -= 1;
        }
        let rows_total = self.rows_total;
        if let Some((expected, marked)) = declared
            && (expected != rows_total || (marked && !ends_marked))
        {
            return Err(LogError::RowCountMismatch {
                at: Location::input(source),
                expected,
                found: rows_total,
                end_mark: if marked && !ends_marked {
                    "its last line is missing"
                } else {
                    "its last line is there"
                },
            });
        }
        let Collected {
            mut out,
            anchors,
            mut notes,
            ..
        } = self;
        for c in &mut out {
            c.shrink_to_fit();
        }
        let map = LineMap { anchors };
        if plan.time_detected
            && let Some(f) = plan.time_field
        {
            notes.push(format!(
                "{source}: column {} ({}) taken for the time by its name (`--time-column` names \
                 another)",
                f + 1,
                plan.names[f]
            ));
        }
        let week = match plan.week_field {
            Some(wf) => {
                let weeks = out.pop().unwrap_or_default();
                Some(combine_weeks(&mut out[0], &weeks, wf, plan, &map, source)?)
            }
            None => None,
        };
        let mut cols = out.into_iter();
        let time_s = if plan.time_field.is_some() {
            cols.next()
        } else {
            None
        };
        let (tau0_s, segments, gaps) = match (&time_s, plan.time_field) {
            (Some(t), Some(tf)) => time_analysis(t, tf, plan, &map, source, opts)?,
            _ => {
                let rate = opts.rate_hz.unwrap_or(f64::NAN);
                (
                    1.0 / rate,
                    std::iter::once(0..rows_total).collect(),
                    Vec::new(),
                )
            }
        };
        let channels = plan
            .channels
            .iter()
            .zip(cols)
            .map(|((_, name, unit), values)| Channel {
                name: name.clone(),
                quantity: unit.quantity,
                source_unit: unit.label.clone(),
                values,
            })
            .collect();
        Ok(ImuLog {
            source: source.to_owned(),
            time_s,
            tau0_s,
            channels,
            segments,
            gaps,
            week,
            notes,
        })
    }
}

//! IMU rates from a tagged CSV (columns and units from an RTKLIB `.tag`).

use super::*;

/// Options for a tick-stamped IMU CSV with an RTKLIB `.tag` file.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TaggedCsvOptions {
    /// How device ticks map to GPS time.
    pub tick_mapping: TickMapping,
    /// Time shift, mounting, gap policy.
    pub stream: ImuStreamOptions,
}

/// Column names of the tagged IMU CSV, in file order.
pub(crate) const TAGGED_CSV_COLUMNS: [&str; 7] =
    ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z", "tick"];

/// Stream from a tick-stamped IMU CSV in memory (`acc_x, acc_y, acc_z [g], gyr_x, gyr_y,
/// gyr_z [deg/s], tick [ms]`, no header or a header, which is then ignored) and its parsed
/// `.tag` file. Units are converted by the text reader (g → m/s² with standard gravity
/// 9.806 65, deg/s → rad/s); duplicate or decreasing ticks are reported there with file and
/// line. Times: ticks → GPS s of week of the tag's week ([`map_ticks_to_gps`]), then
/// `opts.stream.time_shift_s`; `opts.stream.time_base` must be the default
/// ([`TimeBase::GpsSecondsOfWeek`]): the `.tag` file fixes the time.
///
/// A truncated first or last CSV record (the logger starts and stops mid-line) is dropped
/// and reported in [`ImuStream::notes`] (see [`crate::io::TextOptions::drop_truncated_edges`]);
/// a bad row anywhere else is an error naming file, line and column. The tick mapping keeps
/// the anchors the whole records would have given: a cut first record keeps its line end,
/// so its tick (the last field) is intact and still maps to the tag's start; a cut last
/// record's tick is lost and is taken as the last kept tick plus the median tick interval
/// (with [`TickMapping::Stretch`] this end anchor then errs by the tick jitter, ±1 ms on
/// the drive data, instead of one whole sample interval).
pub fn imu_from_tagged_csv(
    csv: &[u8],
    csv_name: &str,
    tag: &TimeTag,
    opts: &TaggedCsvOptions,
) -> Result<ImuStream, PipelineError> {
    if opts.stream.time_base != TimeBase::GpsSecondsOfWeek {
        return Err(PipelineError::Option(format!(
            "{csv_name}: the tagged CSV's time comes from its .tag file (GPS time); time base {} does not apply",
            opts.stream.time_base
        )));
    }
    let mut text = TextOptions {
        header: HeaderMode::Auto,
        // The ticks jitter by ±1 ms around 10 ms; gaps are judged later on GPS time
        // with the pipeline's own policy, so the reader only lists them.
        gap_policy: crate::io::GapPolicy::Bridge,
        drop_truncated_edges: true,
        ..TextOptions::default()
    }
    .with_names(TAGGED_CSV_COLUMNS)
    .with_time(ColumnRef::Name("tick".into()), Some(TimeUnit::Milliseconds));
    let g = Unit::parse("g").map_err(|e| PipelineError::Option(e.to_string()))?;
    let dps = Unit::parse("deg/s").map_err(|e| PipelineError::Option(e.to_string()))?;
    for name in &TAGGED_CSV_COLUMNS[..3] {
        text = text.with_column(ColumnRef::Name((*name).into()), Some(g.clone()));
    }
    for name in &TAGGED_CSV_COLUMNS[3..6] {
        text = text.with_column(ColumnRef::Name((*name).into()), Some(dps.clone()));
    }
    let log = read_text_bytes(csv, csv_name, &text)?;
    let Some(t_s) = log.time_s.as_deref() else {
        return Err(PipelineError::NoTime {
            source_name: csv_name.to_owned(),
        });
    };
    let mut ticks_ms: Vec<f64> = t_s.iter().map(|t| t * 1e3).collect();
    let n = ticks_ms.len();
    // Anchors of dropped edge records (see the doc comment).
    let first_tick = cut_first_tick(csv).filter(|&t| {
        was_dropped(&log.notes, Edge::First) && ticks_ms.first().is_some_and(|&f| t < f)
    });
    let last_tick = match ticks_ms.as_slice() {
        &[_, .., b] if was_dropped(&log.notes, Edge::Last) => {
            let mut d: Vec<f64> = ticks_ms.windows(2).map(|w| w[1] - w[0]).collect();
            let mid = d.len() / 2;
            let step = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
            Some(b + step)
        }
        _ => None,
    };
    if let Some(t) = first_tick {
        ticks_ms.insert(0, t);
    }
    if let Some(t) = last_tick {
        ticks_ms.push(t);
    }
    let mut gps = map_ticks_to_gps(tag, &ticks_ms, opts.tick_mapping, csv_name, 1)?;
    let skip = usize::from(first_tick.is_some());
    gps.time_s = gps.time_s[skip..skip + n].to_vec();
    let ch = |k: usize| log.channels[k].values.as_slice();
    let mut s = rates_to_stream(
        csv_name,
        Some(gps.gps_week),
        &gps.time_s,
        [ch(3), ch(4), ch(5)],
        [ch(0), ch(1), ch(2)],
        &opts.stream,
    )?;
    s.notes = log.notes;
    Ok(s)
}

/// The tick (last field, ms) of the first data line of a tagged CSV (the first line whose
/// last field is a number, so a header is passed over), when that line is not a whole
/// record (fewer than 7 fields, or a first field that is not a number): the line end of a
/// record cut at its start, with its tick, is intact.
pub(super) fn cut_first_tick(csv: &[u8]) -> Option<f64> {
    let last_is_number = |l: &[u8]| {
        std::str::from_utf8(l)
            .ok()
            .and_then(|t| t.rsplit(',').next())
            .is_some_and(|f| f.trim().parse::<f64>().is_ok())
    };
    let line = csv
        .split(|&b| b == b'\n')
        .map(|l| l.trim_ascii())
        .find(|l| !l.is_empty() && !l.starts_with(b"#") && last_is_number(l))?;
    let text = std::str::from_utf8(line).ok()?;
    let fields: Vec<&str> = text.split(',').map(str::trim).collect();
    let whole = fields.len() >= TAGGED_CSV_COLUMNS.len()
        && fields.first().is_some_and(|f| f.parse::<f64>().is_ok());
    if whole {
        return None;
    }
    fields.last()?.parse::<f64>().ok().filter(|t| t.is_finite())
}

/// [`imu_from_tagged_csv`] from files; the `.tag` record layout is detected
/// ([`crate::io::nav::FposSize::Auto`]).
pub fn imu_from_tagged_csv_files(
    csv_path: impl AsRef<Path>,
    tag_path: impl AsRef<Path>,
    opts: &TaggedCsvOptions,
) -> Result<ImuStream, PipelineError> {
    let csv_path = csv_path.as_ref();
    let tag = read_rtklib_tag_file(tag_path, crate::io::nav::FposSize::Auto)?;
    let bytes = crate::io::nav::read_text_file(csv_path)?;
    imu_from_tagged_csv(&bytes, &csv_path.display().to_string(), &tag, opts)
}

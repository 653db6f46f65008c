//! The paper's Table 1 ("Obtained position errors during 60 s GPS outages"): one row per
//! outage and the mean, one column per case — as Markdown and CSV — and the
//! machine-readable document of the whole experiment.

use serde::Serialize;

use super::budget::{OutageBudget, Reversal, ReversalCause, reversals};
use super::monte_carlo::{ExperimentResult, MonteCarloSummary};
use super::run::{Case, Prepared, VehicleRun};
use crate::eval::metrics::OutageReport;
use crate::eval::select::SelectedOutage;

/// Which error a table shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Column {
    /// Horizontal error at the end of the outage, forward filter.
    ForwardEnd,
    /// Largest horizontal error inside the outage, forward filter.
    ForwardMax,
    /// Largest horizontal error inside the outage, smoothed (its end error is pinned by
    /// the fix after the window, so the maximum is the informative figure).
    SmoothedMax,
    /// Height error (solution − reference) at the end of the outage, forward filter;
    /// mean and RMS rows of |error|.
    ForwardEndHeight,
    /// Heading error at the end of the outage, forward filter, deg; mean and RMS rows of
    /// |error|.
    ForwardEndHeading,
}

impl Column {
    /// Every table, in report order.
    pub const ALL: [Column; 5] = [
        Column::ForwardEnd,
        Column::ForwardMax,
        Column::SmoothedMax,
        Column::ForwardEndHeight,
        Column::ForwardEndHeading,
    ];

    /// Title.
    pub fn title(self) -> &'static str {
        match self {
            Column::ForwardEnd => "end-of-outage horizontal error, forward filter (real time)",
            Column::ForwardMax => "maximum horizontal error inside the outage, forward filter",
            Column::SmoothedMax => "maximum horizontal error inside the outage, smoothed",
            Column::ForwardEndHeight => "end-of-outage height error, forward filter",
            Column::ForwardEndHeading => "end-of-outage heading error, forward filter (deg)",
        }
    }

    /// Unit of the cells.
    pub fn unit(self) -> &'static str {
        match self {
            Column::ForwardEndHeading => "deg",
            _ => "m",
        }
    }
}

fn report(run: &VehicleRun, case: Case, col: Column) -> Option<&OutageReport> {
    let c = run.case(case)?;
    match col {
        Column::ForwardEnd
        | Column::ForwardMax
        | Column::ForwardEndHeight
        | Column::ForwardEndHeading => c.forward.as_ref().ok(),
        Column::SmoothedMax => c.smoothed.as_ref()?.as_ref().ok(),
    }
}

/// The rows of a table: header, then one row per outage, then mean and RMS.
pub fn table_rows(p: &Prepared, run: &VehicleRun, col: Column) -> (Vec<String>, Vec<Vec<String>>) {
    let cases: Vec<Case> = run.cases.iter().map(|c| c.case).collect();
    let mut header = vec![
        "outage".to_string(),
        "start [s]".to_string(),
        "dynamics".to_string(),
    ];
    header.extend(
        cases
            .iter()
            .map(|c| format!("{} [{}]", c.label(), col.unit())),
    );
    let t0 = p.span_s.0;
    let mut rows = Vec::new();
    for (i, o) in p.outages.iter().enumerate() {
        let mut row = vec![
            format!("#{}", i + 1),
            format!("{:.0}", o.window.start_s - t0),
            o.chosen_for.unwrap_or(o.dominant).name().to_string(),
        ];
        for &c in &cases {
            row.push(match report(run, c, col).and_then(|r| r.outages.get(i)) {
                Some(e) => fmt_m(match col {
                    Column::ForwardEnd => e.end_horizontal_m,
                    Column::ForwardEndHeight => e.end_height_m,
                    Column::ForwardEndHeading => e.end_heading_deg.unwrap_or(f64::NAN),
                    Column::ForwardMax | Column::SmoothedMax => e.max_horizontal_m,
                }),
                None => failed_cell(run, c, col),
            });
        }
        rows.push(row);
    }
    let abs = matches!(col, Column::ForwardEndHeight | Column::ForwardEndHeading);
    for (name, pick) in [("mean", 0usize), ("RMS", 1)] {
        let name = if abs {
            format!("{name} |·|")
        } else {
            name.to_string()
        };
        let mut row = vec![name, String::new(), String::new()];
        for &c in &cases {
            let stat = report(run, c, col).and_then(|r| match col {
                Column::ForwardEnd => r.summary.end_horizontal_m,
                Column::ForwardEndHeight => r.summary.end_height_abs_m,
                Column::ForwardEndHeading => r.summary.end_heading_abs_deg,
                Column::ForwardMax | Column::SmoothedMax => r.summary.max_horizontal_m,
            });
            row.push(match stat {
                Some(s) => fmt_m(if pick == 0 { s.mean } else { s.rms }),
                None => failed_cell(run, c, col),
            });
        }
        rows.push(row);
    }
    (header, rows)
}

fn failed_cell(run: &VehicleRun, c: Case, col: Column) -> String {
    match run.case(c) {
        Some(cr) if cr.forward.is_err() => "failed".into(),
        Some(cr) if col == Column::SmoothedMax && cr.smoothed.is_none() => "–".into(),
        Some(_) if col == Column::SmoothedMax => "failed".into(),
        _ => "–".into(),
    }
}

/// Metres (or degrees) with sensible digits: 3 significant below 100, whole units above.
pub(crate) fn fmt_m(v: f64) -> String {
    if !v.is_finite() {
        "n/a".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// A Markdown table. A `|` inside a cell (e.g. `mean |·|`) is escaped as `\|` so that
/// every row keeps the header's number of cells.
pub fn markdown(header: &[String], rows: &[Vec<String>]) -> String {
    let cells = |r: &[String]| {
        r.iter()
            .map(|c| c.replace('|', "\\|"))
            .collect::<Vec<_>>()
            .join(" | ")
    };
    let mut s = String::new();
    s.push_str(&format!("| {} |\n", cells(header)));
    s.push_str(&format!(
        "|{}|\n",
        header
            .iter()
            .enumerate()
            .map(|(i, _)| if i < 3 { "---" } else { "---:" })
            .collect::<Vec<_>>()
            .join("|")
    ));
    for r in rows {
        s.push_str(&format!("| {} |\n", cells(r)));
    }
    s
}

/// CSV (RFC 4180: a field holding a comma, a quote, CR or LF is quoted, quotes doubled).
pub fn csv(header: &[String], rows: &[Vec<String>]) -> String {
    let q = |f: &String| {
        if f.contains([',', '"', '\n', '\r']) {
            format!("\"{}\"", f.replace('"', "\"\""))
        } else {
            f.clone()
        }
    };
    let mut s = String::new();
    for r in std::iter::once(header).chain(rows.iter().map(Vec::as_slice)) {
        s.push_str(&r.iter().map(q).collect::<Vec<_>>().join(","));
        s.push('\n');
    }
    s
}

/// The paper's reference figures (Table 1 means): column 2, without scale factor and
/// thermal compensation models, m.
pub(crate) const PAPER_MEAN_ROOM_M: f64 = 1254.2;
/// The paper's mean with the thermal model, m.
pub(crate) const PAPER_MEAN_THERMAL_M: f64 = 150.1361;

/// One case of the detailed run, for the JSON document.
#[derive(Serialize)]
pub struct CaseDocument<'a> {
    /// Case.
    pub case: Case,
    /// Label.
    pub label: &'a str,
    /// Forward errors or the failure.
    pub forward: Result<&'a OutageReport, &'a str>,
    /// Smoothed errors or the failure.
    pub smoothed: Option<Result<&'a OutageReport, &'a str>>,
    /// Fixes accepted.
    pub gnss_accepted: usize,
    /// Fixes rejected by the gate.
    pub gnss_rejected: usize,
    /// Error budget per outage ([`super::budget`]).
    pub budgets: Option<&'a [Option<OutageBudget>]>,
}

/// The experiment as one JSON-ready document.
#[derive(Serialize)]
pub struct ExperimentDocument<'a> {
    /// Scenario name.
    pub scenario: &'a str,
    /// Title.
    pub title: Option<&'a str>,
    /// Seed.
    pub seed: u64,
    /// Outage windows.
    pub outages: &'a [SelectedOutage],
    /// Reference span start, s (outage starts in the tables are relative to it).
    pub reference_start_s: f64,
    /// Vehicle-run temperature, first and last reading, °C.
    pub vehicle_temperature_c: Option<(f64, f64)>,
    /// Detailed run (run 0).
    pub run0: Vec<CaseDocument<'a>>,
    /// Run 0's outages where a more compensated case ended worse, with the cause.
    pub run0_reversals: Vec<Reversal>,
    /// Monte Carlo statistics.
    pub monte_carlo: &'a MonteCarloSummary,
    /// Per-run mean end-of-outage errors (forward), per case label.
    pub per_run_forward_mean_end_m: Vec<(String, Vec<Option<f64>>)>,
    /// The paper's means (biases only, with scale factor and thermal model), m.
    pub paper_means_m: (f64, f64),
}

impl<'a> ExperimentDocument<'a> {
    /// Builds the document.
    pub fn new(p: &'a Prepared, r: &'a ExperimentResult) -> ExperimentDocument<'a> {
        let run0 = r
            .detailed
            .cases
            .iter()
            .map(|c| CaseDocument {
                case: c.case,
                label: c.case.label(),
                forward: c.forward.as_ref().map_err(String::as_str),
                smoothed: c
                    .smoothed
                    .as_ref()
                    .map(|s| s.as_ref().map_err(String::as_str)),
                gnss_accepted: c.gnss_accepted,
                gnss_rejected: c.gnss_rejected,
                budgets: c.budgets.as_deref(),
            })
            .collect();
        let per_run = r.per_run_forward_means();
        ExperimentDocument {
            scenario: &p.scenario.name,
            title: p.scenario.title.as_deref(),
            seed: p.scenario.seed,
            outages: &p.outages,
            reference_start_s: p.span_s.0,
            vehicle_temperature_c: r.detailed.temperature_c,
            run0,
            run0_reversals: reversals(&r.detailed),
            monte_carlo: &r.summary,
            per_run_forward_mean_end_m: per_run,
            paper_means_m: (PAPER_MEAN_ROOM_M, PAPER_MEAN_THERMAL_M),
        }
    }
}

/// Bias change the thermal model predicts between two temperatures: largest |Δb| over
/// the gyro axes (rad/s) and over the accelerometer axes (m/s²).
pub(crate) fn thermal_bias_change(
    model: &driftless_model::compensation::CompensationModel,
    t0_c: f64,
    t1_c: f64,
) -> Option<(f64, f64)> {
    let a = model.calibration_at(t0_c).ok()?;
    let b = model.calibration_at(t1_c).ok()?;
    let max_diff =
        |x: [f64; 3], y: [f64; 3]| (0..3).map(|k| (x[k] - y[k]).abs()).fold(0.0, f64::max);
    Some((
        max_diff(a.gyro.bias, b.gyro.bias),
        max_diff(a.accel.bias, b.accel.bias),
    ))
}

/// Where more compensation did worse, as plain text lines: how often each pair reversed
/// over all runs, and run 0's reversals with their causes ([`super::budget`]); ties
/// (within 5 %) in one line.
pub fn reversal_explanation(r: &ExperimentResult) -> Vec<String> {
    let mut out = Vec::new();
    let counts: Vec<String> = r
        .summary
        .reversals
        .iter()
        .filter(|c| c.compared > 0)
        .map(|c| {
            format!(
                "{} worse than {} in {} of {} outages ({:.0} %; {} by more than 5 %)",
                c.case.label(),
                c.than.label(),
                c.worse,
                c.compared,
                100.0 * c.worse as f64 / c.compared as f64,
                c.worse_beyond_tie
            )
        })
        .collect();
    if counts.is_empty() {
        return out;
    }
    out.push(format!(
        "Over {} run(s), end-of-outage error, forward filter: {}.",
        r.summary.runs,
        counts.join("; ")
    ));
    let (ties, rev): (Vec<Reversal>, Vec<Reversal>) = reversals(&r.detailed)
        .into_iter()
        .partition(|v| v.cause == ReversalCause::Tie);
    if rev.is_empty() {
        out.push(
            "In run 0 no more compensated case ended an outage worse than a less compensated one \
             by more than 5 %."
                .into(),
        );
    } else {
        out.push(format!(
            "Run 0, outages where a more compensated case ended worse by more than 5 % ({}). \
             Each case's error is split by coasting the strapdown mechanization through the \
             outage: from the filter's state with the exact start (start state), from the exact \
             start with the filter's increments (sensor error), and from the exact start with \
             the case's stream before the filter's correction (left by the compensation alone):",
            rev.len()
        ));
        out.extend(rev.iter().map(|v| format!("• {}", v.describe())));
    }
    if !ties.is_empty() {
        out.push(format!(
            "Ties (worse by at most 5 %): {}.",
            ties.iter()
                .map(|v| format!(
                    "#{} {} {} m vs {} {} m",
                    v.outage + 1,
                    v.case.label(),
                    fmt_m(v.end_m),
                    v.than.label(),
                    fmt_m(v.than_end_m)
                ))
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
    out
}

/// The ratio (b)/(c) beside the paper's 8.4× and what sets it, as plain text lines.
pub fn ratio_explanation(p: &Prepared, r: &ExperimentResult) -> Vec<String> {
    let paper = PAPER_MEAN_ROOM_M / PAPER_MEAN_THERMAL_M;
    let mut out = Vec::new();
    let s = &r.summary;
    match &s.ratio_room_over_thermal {
        Some(q) => out.push(format!(
            "Ratio (b)/(c) of the mean 60-s end-of-outage error, forward filter, over {} run(s) \
             — room biases only against bias, scale factor and thermal model, the paper's \
             columns 2 and 3: {:.2}× ({:.0} % interval {:.2}–{:.2}×). The paper: {:.1}× \
             ({:.0} m → {:.0} m).",
            q.runs,
            q.ratio,
            100.0 * q.confidence,
            q.lo,
            q.hi,
            paper,
            PAPER_MEAN_ROOM_M,
            PAPER_MEAN_THERMAL_M
        )),
        None => out.push(format!(
            "No thermal model in this experiment (cases a and b only), so no (b)/(c) ratio; the \
             paper's was {paper:.1}× ({PAPER_MEAN_ROOM_M:.0} m → {PAPER_MEAN_THERMAL_M:.0} m)."
        )),
    }
    if s.ratio_room_over_thermal.is_none() {
        return out;
    }
    if let Some(q) = &s.ratio_full_room_over_thermal {
        out.push(format!(
            "Ratio (d)/(c) — the full room calibration (bias, scale factor, misalignment at \
             25 °C) against the same plus the thermal model, i.e. what the thermal model alone \
             buys: {:.2}× ({:.0} % interval {:.2}–{:.2}×).",
            q.ratio,
            100.0 * q.confidence,
            q.lo,
            q.hi
        ));
    }
    out.push("What sets the ratio:".into());
    let mean_of = |c: Case| {
        s.cases
            .iter()
            .find(|x| x.case == c)
            .and_then(|x| x.forward_mean_end_m)
            .map(|m| m.mean)
    };
    if let (Some(b), Some(d)) = (mean_of(Case::RoomBias), mean_of(Case::RoomFull)) {
        out.push(format!(
            "• scale factor and misalignment: (b) removes only the biases; correcting scale \
             factor and misalignment as well, case (d), moves the mean from {} m to {} m. The \
             rest of the gap to (c) is the thermal model's.",
            fmt_m(b),
            fmt_m(d)
        ));
    }
    if let (Some((t0, t1)), Some(th)) = (r.detailed.temperature_c, &r.thermal) {
        let d = thermal_bias_change(&th.model, t0, t1);
        out.push(format!(
            "• thermal swing during the run: the sensor went from {t0:.1} °C to {t1:.1} °C{}. \
             Over the paper's chamber range (−25…70 °C) the same sensor's biases move up to 5 deg/s \
             and 0.94 m/s²; the paper does not give its vehicle's temperatures. A larger swing \
             inside the run makes (b) worse and leaves (c) nearly unchanged.",
            match d {
                Some((g, a)) => format!(
                    ", over which the thermal model moves the biases by up to {:.2} deg/s (gyro) \
                     and {:.3} m/s² (accel)",
                    g.to_degrees(),
                    a
                ),
                None => String::new(),
            }
        ));
    }
    if let Some(crate::sim::temperature::TemperatureProfile::WarmUp {
        t0_c, t1_c, tau_s, ..
    }) = &p.scenario.vehicle.temperature
    {
        out.push(format!(
            "• warm-up rate: {:.2} °C/min at the start (τ = {:.0} s), {:.2} °C/min after 20 min. \
             While GNSS is available the filter re-estimates the biases, so (b) suffers from the \
             bias change since the last fix and from the filter's lag behind it: a faster warm-up \
             widens the gap, a sensor already warm closes it.",
            (t1_c - t0_c) / tau_s * 60.0,
            tau_s,
            (t1_c - t0_c) / tau_s * 60.0 * (-1200.0 / tau_s).exp(),
        ));
    }
    out.push(
        "• IMU grade: case (c) is limited by what no thermal model removes (turn-on bias, bias \
         instability, angle random walk, rate random walk, model error); a better IMU lowers that \
         floor and raises the ratio for the same thermal swing."
            .into(),
    );
    out.push(format!(
        "• filter tuning: the noise model (Allan analysis) lets the bias states wander (Gauss–Markov, \
         τ = {:.0} s), so between outages the filter tracks part of the thermal drift in case (b); \
         a stiffer bias model — or none, as when the paper's uncompensated data \"failed to \
         converge\" — makes (b) worse and the ratio larger.",
        p.scenario.filter.bias_tau_s
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cells of a Markdown row, split on unescaped `|`.
    fn cells(line: &str) -> usize {
        let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
        let mut n = 1;
        let mut prev = ' ';
        for c in inner.chars() {
            if c == '|' && prev != '\\' {
                n += 1;
            }
            prev = c;
        }
        n
    }

    #[test]
    fn markdown_rows_keep_the_header_cell_count() {
        let header: Vec<String> = ["outage", "start", "case a"].map(String::from).to_vec();
        let rows = vec![
            ["#1", "10", "3.2"].map(String::from).to_vec(),
            ["mean |·|", "", "1.5"].map(String::from).to_vec(),
        ];
        let md = markdown(&header, &rows);
        for line in md.lines() {
            assert_eq!(cells(line), 3, "{line}");
        }
        assert!(md.contains("mean \\|·\\|"), "{md}");
    }

    /// RFC 4180: fields with a comma, a quote, CR or LF are quoted (a bare CR would end
    /// the record for many readers), quotes doubled; plain fields stay as they are.
    #[test]
    fn csv_quotes_comma_quote_cr_and_lf() {
        let header: Vec<String> = ["case", "note"].map(String::from).to_vec();
        let rows = vec![
            ["a", "x\ry"].map(String::from).to_vec(),
            ["b", "x\ny"].map(String::from).to_vec(),
            ["c", "x,y"].map(String::from).to_vec(),
            ["d", "say \"hi\""].map(String::from).to_vec(),
            ["e", "plain"].map(String::from).to_vec(),
        ];
        let out = csv(&header, &rows);
        assert_eq!(
            out,
            "case,note\na,\"x\ry\"\nb,\"x\ny\"\nc,\"x,y\"\nd,\"say \"\"hi\"\"\"\ne,plain\n"
        );
    }
}

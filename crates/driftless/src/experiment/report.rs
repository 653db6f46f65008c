//! The experiment's figures and its one self-contained HTML report.
//!
//! Figures: the north-east trajectory with the GNSS gaps and each case's drift in them
//! (the paper's Fig. 2), per-outage error bars (Table 1 as a chart), error growth inside
//! each outage, bias and scale factor versus temperature with the fits and bands
//! (Figs. 3–4), the Allan deviation of the static log with the fitted noise model, and
//! the Monte Carlo per-run means.

use super::monte_carlo::ExperimentResult;
use super::run::{Case, Prepared, VehicleRun};
use super::table::{Column, ratio_explanation, reversal_explanation, table_rows};
use crate::io::nav::NavSolution;
use crate::nav::earth::{meridian_radius_m, prime_vertical_radius_m};
use crate::nav::outage::OutageWindow;
use crate::report::experiment_plots::{
    FIGURE_WIDTH, GrowthCurves, error_growth_figure, fit_to_width, grouped_bars_figure,
    outage_bars_figure, trajectory_figure,
};
use crate::report::html::HtmlReport;
use crate::report::plot::{Figure, PlotError};
use crate::report::{allan_plot, thermal_plot};

/// North-east offsets (m) of a solution's epochs from an origin (lat, lon rad), on the
/// ellipsoid's local radii at the origin — plenty for a figure of a few km.
fn ne_of(
    sol: &NavSolution,
    idx: impl Iterator<Item = usize>,
    origin: (f64, f64, f64),
) -> Vec<[f64; 2]> {
    let (lat0, lon0, h0) = origin;
    let (m, n) = (
        meridian_radius_m(lat0) + h0,
        prime_vertical_radius_m(lat0) + h0,
    );
    idx.map(|k| {
        [
            (sol.lon_rad[k] - lon0) * n * lat0.cos(),
            (sol.lat_rad[k] - lat0) * m,
        ]
    })
    .collect()
}

fn indices_in(t: &[f64], a: f64, b: f64) -> std::ops::Range<usize> {
    t.partition_point(|&x| x < a)..t.partition_point(|&x| x <= b)
}

/// The named figures of an experiment, in report order.
pub fn figures(p: &Prepared, r: &ExperimentResult) -> Vec<(String, String, Figure)> {
    let mut out = Vec::new();
    let run = &r.detailed;
    let windows = p.windows();
    let labels: Vec<String> = (1..=windows.len()).map(|i| format!("#{i}")).collect();
    out.extend(trajectory(run, &windows));
    let bars: Vec<(String, Vec<f64>)> = run
        .cases
        .iter()
        .map(|c| {
            let v = match &c.forward {
                Ok(rep) => rep.outages.iter().map(|o| o.end_horizontal_m).collect(),
                Err(_) => vec![f64::NAN; windows.len()],
            };
            (c.case.label().to_string(), v)
        })
        .collect();
    out.push((
        "outage-errors".into(),
        "End-of-outage horizontal error per outage and case, forward filter (Table 1 as a \
         chart; log scale)"
            .into(),
        outage_bars_figure(&labels, &bars, "horizontal error [m]", true),
    ));
    let growth: Vec<(String, GrowthCurves)> = run
        .cases
        .iter()
        .filter_map(|c| {
            let rep = c.forward.as_ref().ok()?;
            Some((
                c.case.label().to_string(),
                rep.outages
                    .iter()
                    .map(|o| {
                        o.growth
                            .iter()
                            .map(|g| (g.since_start_s, g.horizontal_m))
                            .collect()
                    })
                    .collect(),
            ))
        })
        .collect();
    out.push((
        "error-growth".into(),
        "Horizontal error growth inside each outage, forward filter (one line per outage)".into(),
        error_growth_figure(&growth, "horizontal error [m]"),
    ));
    if let Some(soak) = r.thermal.as_ref().and_then(|t| t.soak.as_ref()) {
        out.push((
            "thermal".into(),
            "Bias and scale factor versus temperature from the chamber soak: dots are the \
             per-step six-position / rate-table estimates, lines and bands the cubic fit about \
             25 °C with its 95 % band (paper Figs. 3–4)"
                .into(),
            thermal_plot::thermal_figure(soak, [("m/s²", 1.0), ("deg/s", 1.0f64.to_degrees())]),
        ));
    }
    if let (Some(noise), Some(curves)) =
        (&r.noise, r.noise.as_ref().and_then(|n| n.curves.as_ref()))
    {
        let fits: Vec<Option<&crate::allan::fit::NoiseFit>> =
            noise.model.fits().map(Some).collect();
        out.push((
            "allan".into(),
            "Allan deviation of the static log with the fitted noise model (the filter's \
             tuning)"
                .into(),
            allan_plot::figure(
                &format!("Allan deviation: {}", noise.source),
                &curves.results,
                &curves.quantities,
                &curves.units,
                &fits,
            ),
        ));
    }
    if r.runs.len() > 1 {
        let run_labels: Vec<String> = (1..=r.runs.len()).map(|i| i.to_string()).collect();
        let per_run: Vec<(String, Vec<f64>)> = r
            .per_run_forward_means()
            .into_iter()
            .map(|(l, v)| (l, v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect()))
            .collect();
        out.push((
            "monte-carlo".into(),
            format!(
                "Mean end-of-outage error of each Monte Carlo run per case, forward filter ({} runs)",
                r.runs.len()
            ),
            grouped_bars_figure(
                "Mean end-of-outage error per Monte Carlo run",
                "Monte Carlo run",
                &run_labels,
                &per_run,
                "mean horizontal error [m]",
                true,
            ),
        ));
    }
    out.into_iter()
        .map(|(name, caption, fig)| (name, caption, fit_to_width(fig, FIGURE_WIDTH)))
        .collect()
}

/// The trajectory figure: the reference track with the outage windows and each case's
/// forward solution inside them (none without a reference).
fn trajectory(run: &VehicleRun, windows: &[OutageWindow]) -> Option<(String, String, Figure)> {
    let reference = run.reference.as_ref().filter(|r| !r.time_s.is_empty())?;
    let origin = (
        reference.lat_rad[0],
        reference.lon_rad[0],
        reference.height_m[0],
    );
    let n = reference.time_s.len();
    let step = (n / 3000).max(1);
    let full = ne_of(reference, (0..n).step_by(step), origin);
    let tracks: Vec<Vec<[f64; 2]>> = windows
        .iter()
        .map(|w| {
            ne_of(
                reference,
                indices_in(&reference.time_s, w.start_s, w.end_s),
                origin,
            )
        })
        .collect();
    let solutions: Vec<(String, Vec<Vec<[f64; 2]>>)> = run
        .cases
        .iter()
        .filter(|c| c.case != Case::Raw)
        .filter_map(|c| {
            let sol = c.forward_solution.as_ref()?;
            Some((
                format!("{} forward", c.case.label()),
                windows
                    .iter()
                    .map(|w| {
                        let r = indices_in(&sol.time_s, w.start_s, w.end_s);
                        let st = (r.len() / 300).max(1);
                        ne_of(sol, r.step_by(st), origin)
                    })
                    .collect(),
            ))
        })
        .collect();
    Some((
        "trajectory".into(),
        "Trajectory (north-east, m from the start) with the GNSS outages (bold, numbered) \
         and the forward filter's drift inside them (paper Fig. 2)"
            .into(),
        trajectory_figure(&full, &tracks, &solutions),
    ))
}

/// The HTML report: headline ratio, Table 1, Monte Carlo statistics, outage selection,
/// every figure.
pub fn html_report(
    p: &Prepared,
    r: &ExperimentResult,
    figs: &[(String, String, Figure)],
) -> Result<HtmlReport, PlotError> {
    let title = p
        .scenario
        .title
        .clone()
        .unwrap_or_else(|| p.scenario.name.clone());
    let mut h = HtmlReport::new(&title);
    h.paragraph(&format!(
        "Scenario {} (seed {}): {} outage(s); {} Monte Carlo run(s); cases: {}.{}",
        p.scenario.name,
        p.scenario.seed,
        p.outages.len(),
        r.runs.len(),
        r.detailed
            .cases
            .iter()
            .map(|c| c.case.label())
            .collect::<Vec<_>>()
            .join(", "),
        match r.detailed.temperature_c {
            Some((a, b)) =>
                format!(" Sensor temperature during the vehicle run: {a:.1} → {b:.1} °C."),
            None => String::new(),
        }
    ));
    h.heading(2, "What the thermal model buys");
    for line in ratio_explanation(p, r) {
        h.paragraph(&line);
    }
    h.heading(2, "Where more compensation did worse");
    let lines = reversal_explanation(r);
    if lines.is_empty() {
        h.paragraph("Only one case ran: nothing to compare.");
    }
    for line in lines {
        h.paragraph(&line);
    }
    h.heading(2, "Table 1");
    for col in Column::ALL {
        let (head, rows) = table_rows(p, &r.detailed, col);
        h.table(&format!("Run 0: {}", col.title()), &head, &rows);
    }
    h.heading(2, "Monte Carlo");
    let (head, rows) = r.summary.table();
    h.table(
        &format!(
            "Per-run mean end-of-outage horizontal error, forward filter, over {} run(s)",
            r.summary.runs
        ),
        &head,
        &rows,
    );
    h.heading(2, "Outages");
    let t0 = p.span_s.0;
    let head: Vec<String> = [
        "outage",
        "start [s]",
        "end [s]",
        "chosen for",
        "dominant",
        "GNSS before [s]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let rows: Vec<Vec<String>> = p
        .outages
        .iter()
        .enumerate()
        .map(|(i, o)| {
            vec![
                format!("#{}", i + 1),
                format!("{:.0}", o.window.start_s - t0),
                format!("{:.0}", o.window.end_s - t0),
                o.chosen_for.map_or("–".into(), |d| d.name().to_string()),
                o.dominant.name().to_string(),
                format!("{:.0}", o.gap_before_s),
            ]
        })
        .collect();
    h.table(
        "Outage windows (s from the first reference epoch)",
        &head,
        &rows,
    );
    h.heading(2, "Figures");
    for (_, caption, fig) in figs {
        h.figure(caption, fig)?;
    }
    h.heading(2, "Conventions");
    h.paragraph(
        "End-of-outage error: the solution's horizontal error at its last epoch inside the \
         window, against the reference interpolated there (the truth for simulated runs, the \
         smoothed full-GNSS solution for recorded ones). Case (b), the paper's column 2 \
         (\"without scale factor and thermal compensation models\"): the biases of the \
         room-temperature calibration at 25 °C removed, nothing else; on recorded data without \
         a calibration, the gyro biases of the static start removed. Case (c): the room bias, \
         scale factor and misalignment plus the thermal model at the sensor's temperature \
         reading. Case (d): the full room calibration without the thermal model. \
         Compensation order (a) ⊂ (b) ⊂ (d) ⊂ (c). The ratio's interval is a percentile bootstrap over runs.",
    );
    Ok(h)
}

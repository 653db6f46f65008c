//! Running an experiment scenario with progress on stderr, its tables on stdout and its
//! files in an output folder: shared by `driftless experiment` and `driftless demo`.

use anyhow::{Context, Result};
use driftless::experiment::monte_carlo::{ExperimentResult, run_experiment};
use driftless::experiment::run::Prepared;
use driftless::experiment::table::{
    Column, ExperimentDocument, csv, markdown, ratio_explanation, reversal_explanation, table_rows,
};
use driftless::experiment::{ExperimentScenario, prepare};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Where and how [`run_scenario`] writes.
pub struct OutputFolder<'a> {
    /// The folder.
    pub dir: &'a Path,
    /// Replace the files of an earlier run (`--force`).
    pub force: bool,
}

/// Runs a loaded scenario and writes every output into `out.dir`, which it holds locked
/// against other runs until the last file is written.
pub fn run_scenario(
    scenario: ExperimentScenario,
    out: OutputFolder,
    runs: Option<usize>,
    json: bool,
) -> Result<()> {
    let t_all = Instant::now();
    let _lock = driftless::io::output::claim_folder(out.dir, out.force)?;
    driftless::io::output::remove_stale_partials(out.dir.join(FIGURES));
    let out = out.dir;
    let show = !json;
    let sp = crate::progress::spinner(
        show,
        "checking the scenario and choosing the outage windows".into(),
    );
    let p = prepare(scenario)?;
    sp.finish_and_clear();
    let k = runs.unwrap_or(p.scenario.monte_carlo.runs);
    if show {
        outln!(
            "{} — {} outage(s) of {}; {} run(s)",
            p.scenario.title.as_deref().unwrap_or(&p.scenario.name),
            p.outages.len(),
            p.outages.first().map_or("–".into(), |o| format!(
                "{:.0} s",
                o.window.end_s - o.window.start_s
            )),
            k
        );
    }

    let noise_bar = crate::progress::spinner(
        show,
        "noise stage: static log → Allan deviation → noise model".into(),
    );
    let runs_bar = if show && !crate::verbosity::quiet() {
        let b = ProgressBar::new(k as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} chamber + vehicle runs {pos}/{len} [{bar:30}] {elapsed} (eta {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        b.enable_steady_tick(Duration::from_millis(150));
        b
    } else {
        ProgressBar::hidden()
    };
    runs_bar.set_position(0);
    let progress = |stage: &str, done: u64, _total: u64| match stage {
        "noise" if done >= 1 => noise_bar.finish_and_clear(),
        "runs" => runs_bar.set_position(done),
        _ => {}
    };
    let result = run_experiment(&p, runs, &progress)?;
    runs_bar.finish_and_clear();
    let written = write_outputs(out, &p, &result)?;
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&ExperimentDocument::new(&p, &result))?
        );
        return Ok(());
    }
    print_human(&p, &result);
    outln!(
        "\nwrote {} files to {} in {:.1} s",
        written.len(),
        out.display(),
        t_all.elapsed().as_secs_f64()
    );
    for w in &written {
        outln!("  {}", w.display());
    }
    Ok(())
}

fn print_human(p: &Prepared, r: &ExperimentResult) {
    outln!();
    for col in [Column::ForwardEnd, Column::SmoothedMax] {
        let (h, rows) = table_rows(p, &r.detailed, col);
        outln!("Table 1 (run 0): {}", col.title());
        let mut t = crate::output::Table::new(h);
        for row in rows {
            t.row(row);
        }
        out!("{}", t.render());
        outln!();
    }
    let s = &r.summary;
    outln!(
        "Monte Carlo over {} run(s): mean end-of-outage horizontal error per run, forward filter [m]",
        s.runs
    );
    let (head, rows) = s.table();
    let mut t = crate::output::Table::new(head);
    for row in rows {
        t.row(row);
    }
    out!("{}", t.render());
    for c in &s.cases {
        if let Some(m) = &c.first_failure {
            outln!(
                "{}: failed in {} run(s), first: {m}",
                c.label,
                c.failed_runs
            );
        }
    }
    outln!();
    for line in ratio_explanation(p, r) {
        outln!("{line}");
    }
    let reversals = reversal_explanation(r);
    if !reversals.is_empty() {
        outln!();
        for line in reversals {
            outln!("{line}");
        }
    }
}

/// Writes Table 1 (Markdown, CSV), the JSON document and the report; returns the paths.
pub fn write_outputs(out: &Path, p: &Prepared, r: &ExperimentResult) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let mut md = String::new();
    md.push_str(&format!(
        "# {}\n\n",
        p.scenario.title.as_deref().unwrap_or(&p.scenario.name)
    ));
    for (col, file) in [
        (Column::ForwardEnd, "table1.csv"),
        (Column::ForwardMax, "table1-max.csv"),
        (Column::SmoothedMax, "table1-smoothed.csv"),
        (Column::ForwardEndHeight, "table1-height.csv"),
        (Column::ForwardEndHeading, "table1-heading.csv"),
    ] {
        let (h, rows) = table_rows(p, &r.detailed, col);
        md.push_str(&format!("## Table 1 (run 0): {}\n\n", col.title()));
        md.push_str(&markdown(&h, &rows));
        md.push('\n');
        let path = out.join(file);
        driftless::io::output::write(&path, csv(&h, &rows))
            .with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    md.push_str("## Monte Carlo and the paper's ratio\n\n");
    for line in ratio_explanation(p, r) {
        md.push_str(&line);
        md.push_str("\n\n");
    }
    md.push_str("## Where more compensation did worse\n\n");
    for line in reversal_explanation(r) {
        md.push_str(&line);
        md.push_str("\n\n");
    }
    let path = out.join("table1.md");
    driftless::io::output::write(&path, md)
        .with_context(|| format!("writing {}", path.display()))?;
    written.push(path);
    let figs = driftless::experiment::report::figures(p, r);
    let fig_dir = out.join(FIGURES);
    std::fs::create_dir_all(&fig_dir).with_context(|| format!("creating {}", fig_dir.display()))?;
    for (name, _, fig) in &figs {
        let path = fig_dir.join(format!("{name}.svg"));
        driftless::report::plot::write_figure(fig, &path)
            .with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    remove_earlier_figures(&fig_dir, &written)?;
    let html = driftless::experiment::report::html_report(p, r, &figs)?;
    let path = out.join("report.html");
    driftless::report::html::write_html(&path, &html)
        .with_context(|| format!("writing {}", path.display()))?;
    written.push(path);
    let path = out.join("experiment.json");
    driftless::io::output::write(
        &path,
        serde_json::to_string_pretty(&ExperimentDocument::new(p, r))?,
    )
    .with_context(|| format!("writing {}", path.display()))?;
    written.push(path);
    Ok(written)
}

/// The figures' folder inside the output folder.
const FIGURES: &str = "figures";

/// Removes the figures (`*.svg`) in `fig_dir` that this run did not write (`written`): a
/// figure of an earlier experiment must not sit beside this run's.
fn remove_earlier_figures(fig_dir: &Path, written: &[PathBuf]) -> Result<()> {
    let entries =
        std::fs::read_dir(fig_dir).with_context(|| format!("reading {}", fig_dir.display()))?;
    for e in entries {
        let p = e
            .with_context(|| format!("reading {}", fig_dir.display()))?
            .path();
        let svg = p.extension().is_some_and(|x| x == "svg") && p.is_file();
        if svg && !written.iter().any(|w| w.file_name() == p.file_name()) {
            std::fs::remove_file(&p)
                .with_context(|| format!("removing {} of an earlier run", p.display()))?;
        }
    }
    Ok(())
}

//! `driftless allan RUN1 RUN2 …`: replicate logs of one sensor — each run analysed as a
//! single log, then the runs' noise terms compared and a joint model fitted
//! ([`driftless::allan::replicates`]).

use super::{AllanArgs, NoiseMethod, analysis_error, analysis_options, human};
use anyhow::{Context, Result, bail};
use driftless::allan::log_replicates::{ReplicateAnalysis, ReplicateLogsError, analyse_replicates};
use driftless::io::Quantity;
use driftless::report::allan_plot::{self, RunCurves};
use std::path::Path;

pub(super) fn run_replicates(a: &AllanArgs, exports: &super::Exports) -> Result<()> {
    if a.no_fit {
        bail!(
            "comparing {} logs needs the noise fit: drop --no-fit, or analyse the files one \
             at a time",
            a.files.len()
        );
    }
    let opts = analysis_options(a)?;
    if let Some(NoiseMethod::Gmwm(_)) = opts.method {
        bail!(
            "--method gmwm with {} logs: the replicate comparison and the joint model use the \
             Allan fit; drop --method gmwm, or analyse the files one at a time",
            a.files.len()
        );
    }
    let mut logs = Vec::with_capacity(a.files.len());
    for file in &a.files {
        let log = crate::progress::read_with_progress(&a.input, file, a.json)?;
        crate::progress::warn_gaps(file, &log);
        logs.push((file.display().to_string(), log));
    }
    let named: Vec<(&str, &_)> = logs.iter().map(|(n, l)| (n.as_str(), l)).collect();
    let spinner = crate::progress::spinner(!a.json, String::new());
    let rep = analyse_replicates(&named, &opts, &|k| {
        let (name, log) = named[k];
        spinner.set_message(format!(
            "{name}: {} on {} channel(s) × {} samples",
            opts.analysis.estimator.name().to_uppercase(),
            log.channels.len(),
            log.len()
        ));
    })
    .map_err(|e| match e {
        ReplicateLogsError::Run { run, source } => {
            analysis_error(source).context(format!("analysing {run}"))
        }
        other => anyhow::Error::new(other),
    })?;
    spinner.finish_and_clear();
    for w in &rep.warnings {
        eprintln!("warning: {w}");
    }
    let joint = &rep.replicates.joint;
    if let Some(p) = &a.save_model {
        joint
            .save(p)
            .with_context(|| format!("writing noise model {}", p.display()))?;
    }
    let exported = if exports.is_empty() {
        Vec::new()
    } else {
        exports.write(joint)?
    };
    if let Some(p) = &a.plot {
        write_plot(p, &rep)?;
    }
    if a.json {
        outln!("{}", crate::output::json_text(&rep)?);
        return Ok(());
    }
    for (r, (file, (_, log))) in rep.runs.iter().zip(a.files.iter().zip(&logs)) {
        out!("{}", human::human_output(&r.analysis, log, file));
        out!("\n");
    }
    out!("{}", rep.replicates.human_table());
    out!(
        "\nJoint model: the runs' Allan variances combined per τ (EDF-weighted mean, EDFs \
         summed); intervals widened to the pooled ones where the runs disagree.\n"
    );
    out!("{}", joint.human_table());
    if let Some(p) = &a.plot {
        outln!("plot written to {}", p.display());
    }
    if let Some(p) = &a.save_model {
        outln!("joint noise model written to {}", p.display());
    }
    for line in &exported {
        outln!("{line}");
    }
    Ok(())
}

fn write_plot(path: &Path, rep: &ReplicateAnalysis) -> Result<()> {
    let Some(first) = rep.runs.first() else {
        return Ok(());
    };
    let joint_model = &rep.replicates.joint;
    let curves: Vec<RunCurves<'_>> = rep
        .runs
        .iter()
        .map(|r| RunCurves {
            name: Path::new(&r.name)
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or(&r.name),
            results: &r.analysis.fit_curves,
        })
        .collect();
    let first = &first.analysis;
    let joint: Vec<Option<&_>> = first
        .fit_curves
        .iter()
        .map(|c| joint_model.channel(&c.name).map(|j| &j.fit))
        .collect();
    let quantities: Vec<_> = first
        .fit_curves
        .iter()
        .map(|c| {
            joint_model
                .channel(&c.name)
                .map_or(Quantity::Other, |j| j.quantity)
        })
        .collect();
    allan_plot::write_replicates(
        path,
        &format!("{} runs and their joint model", rep.runs.len()),
        &curves,
        &quantities,
        &first.units,
        &joint,
    )
    .with_context(|| format!("writing plot {}", path.display()))
}

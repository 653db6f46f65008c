//! `driftless allan RUN1 RUN2 …`: replicate logs of one sensor — each run analysed as a
//! single log, then the runs' noise terms compared and a joint model fitted
//! ([`driftless::allan::replicates`]).

use super::{
    AllanArgs, AllanOutput, NoiseMethod, analyse_log_with, analysis_config, channels_json,
    human_output, noise_json, noise_method, read_with_progress,
};
use anyhow::{Context, Result, bail};
use driftless::allan::replicates::{
    DEFAULT_LEVEL, ReplicateOptions, ReplicateRun, Replicates, RunShape, check_same_sensor,
    compare_replicates,
};
use driftless::io::{ImuLog, Quantity};
use driftless::report::allan_plot::{self, RunCurves};
use std::path::PathBuf;

/// One analysed run.
struct Run {
    file: PathBuf,
    name: String,
    log: ImuLog,
    out: AllanOutput,
}

pub(super) fn run_replicates(a: &AllanArgs, exports: &super::Exports) -> Result<()> {
    if a.no_fit {
        bail!(
            "comparing {} logs needs the noise fit: drop --no-fit, or analyse the files one \
             at a time",
            a.files.len()
        );
    }
    let cfg = analysis_config(a)?;
    let method = noise_method(a)?;
    let (fit, fit_range) = match &method {
        NoiseMethod::Allan(f, r) => (*f, *r),
        NoiseMethod::Gmwm(_) => bail!(
            "--method gmwm with {} logs: the replicate comparison and the joint model use the \
             Allan fit; drop --method gmwm, or analyse the files one at a time",
            a.files.len()
        ),
    };
    // Read every log and check that they are replicates before the long work.
    let mut logs = Vec::with_capacity(a.files.len());
    for file in &a.files {
        let log = read_with_progress(&a.input, file, a.json)?;
        for g in &log.gaps {
            eprintln!(
                "warning: {}: time gap of {:.3} s after t = {:.3} s (row {}) — {}",
                file.display(),
                g.duration_s,
                g.start_s,
                g.index + 1,
                if log.segments.len() > 1 {
                    "analysed as separate segments"
                } else {
                    "bridged"
                }
            );
        }
        logs.push((file.clone(), file.display().to_string(), log));
    }
    {
        let shapes: Vec<RunShape<'_>> = logs
            .iter()
            .map(|(_, name, log)| RunShape {
                source: name,
                channels: log
                    .channels
                    .iter()
                    .filter(|c| c.quantity != Quantity::Temperature)
                    .map(|c| (c.name.as_str(), c.quantity))
                    .collect(),
                tau0_s: log.tau0_s,
            })
            .collect();
        if let [first, rest @ ..] = shapes.as_slice() {
            for other in rest {
                check_same_sensor(first, other)?;
            }
        }
    }
    let mut runs = Vec::with_capacity(logs.len());
    for (file, name, log) in logs {
        let spinner = crate::demo_cmd::spinner(
            !a.json,
            format!(
                "{name}: {} on {} channel(s) × {} samples",
                cfg.estimator.name().to_uppercase(),
                log.channels.len(),
                log.len()
            ),
        );
        let out = analyse_log_with(&log, &cfg, Some(&method), a.scale, !a.keep_lines)
            .with_context(|| format!("analysing {name}"))?;
        spinner.finish_and_clear();
        runs.push(Run {
            file,
            name,
            log,
            out,
        });
    }
    let mut inputs = Vec::with_capacity(runs.len());
    for r in &runs {
        let model = r
            .out
            .noise
            .as_ref()
            .with_context(|| format!("{}: no noise model was fitted", r.name))?;
        inputs.push(ReplicateRun {
            source: &r.name,
            curves: &r.out.fit_curves,
            model,
            resolution: &r.out.resolution,
        });
    }
    let rep = compare_replicates(
        &inputs,
        &ReplicateOptions {
            fit,
            fit_range,
            level: DEFAULT_LEVEL,
            ..ReplicateOptions::default()
        },
    )?;
    let mut warnings: Vec<String> = runs
        .iter()
        .flat_map(|r| r.out.warnings.iter().cloned())
        .collect();
    warnings.extend(rep.warnings());
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if let Some(p) = &a.save_model {
        rep.joint
            .save(p)
            .with_context(|| format!("writing noise model {}", p.display()))?;
    }
    let exported = if exports.is_empty() {
        Vec::new()
    } else {
        exports.write(&rep.joint)?
    };
    if let Some(p) = &a.plot {
        write_plot(p, &runs, &rep)?;
    }
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&json_output(&runs, &rep, &warnings))?
        );
    } else {
        for r in &runs {
            out!("{}", human_output(&r.out, &r.log, &r.file));
            out!("\n");
        }
        out!("{}", rep.human_table());
        out!(
            "\nJoint model: the runs' Allan variances combined per τ (EDF-weighted mean, EDFs \
             summed); intervals widened to the pooled ones where the runs disagree.\n"
        );
        out!("{}", rep.joint.human_table());
        if let Some(p) = &a.plot {
            outln!("plot written to {}", p.display());
        }
        if let Some(p) = &a.save_model {
            outln!("joint noise model written to {}", p.display());
        }
        for line in &exported {
            outln!("{line}");
        }
    }
    Ok(())
}

fn write_plot(path: &std::path::Path, runs: &[Run], rep: &Replicates) -> Result<()> {
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let curves: Vec<RunCurves<'_>> = runs
        .iter()
        .map(|r| RunCurves {
            name: r
                .file
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or(&r.name),
            results: &r.out.fit_curves,
        })
        .collect();
    let joint: Vec<Option<&_>> = first
        .out
        .fit_curves
        .iter()
        .map(|c| rep.joint.channel(&c.name).map(|j| &j.fit))
        .collect();
    let quantities: Vec<_> = first
        .out
        .fit_curves
        .iter()
        .map(|c| {
            rep.joint
                .channel(&c.name)
                .map_or(Quantity::Other, |j| j.quantity)
        })
        .collect();
    allan_plot::write_replicates(
        path,
        &format!("{} runs and their joint model", runs.len()),
        &curves,
        &quantities,
        &first.out.units,
        &joint,
    )
    .with_context(|| format!("writing plot {}", path.display()))
}

/// The `--json` document with several runs: the single-run shape for the joint result
/// (`channels`: the combined curves, `noise`: the joint model), `runs`: each run's own
/// document with its `file`, `replicates`: the comparison.
fn json_output(runs: &[Run], rep: &Replicates, warnings: &[String]) -> serde_json::Value {
    let units: Vec<String> = match runs.first() {
        Some(r) => rep
            .joint_curves
            .iter()
            .map(|c| {
                r.out
                    .fit_curves
                    .iter()
                    .position(|x| x.name == c.name)
                    .and_then(|k| r.out.units.get(k).cloned())
                    .unwrap_or_default()
            })
            .collect(),
        None => Vec::new(),
    };
    let per_run: Vec<serde_json::Value> = runs
        .iter()
        .map(|r| {
            let mut d = super::json_output(&r.out);
            d["file"] = r.name.clone().into();
            d
        })
        .collect();
    serde_json::json!({
        "channels": channels_json(&rep.joint_curves, &units),
        "noise": noise_json(&rep.joint, true),
        "warnings": warnings,
        "lines": [],
        "runs": per_run,
        "replicates": serde_json::to_value(rep).unwrap_or(serde_json::Value::Null),
    })
}

//! `driftless demo`: the seed paper's experiment on the built-in `adi-like` scenario
//! (`driftless::experiment`, results in `./driftless-demo/`). `driftless demo --noise`:
//! the noise-analysis demo — an 18-h, 100 Hz static six-axis IMU log with known noise
//! terms, the Allan analysis and noise fit on it, compared with the truth.

use crate::output::{Table, sci};
use crate::progress::spinner;
use anyhow::Result;
use clap::Args;
use driftless::allan::analysis::AnalysisConfig;
use driftless::allan::fit::FitConfig;
use driftless::allan::log_analysis::{LogAnalysis, LogAnalysisOptions, analyse_log};
use driftless::allan::taus::TauSpec;
use driftless::allan::{DataType, Estimator};
use driftless::io::{Channel, ImuLog, Quantity};
use driftless::sim::noise::{StaticNoiseConfig, generate_channels};
use driftless_model::units::{
    DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MICRO_G,
};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "driftless-demo")]
    pub out: PathBuf,
    /// Write into an output folder that already holds files: this run's files replace
    /// theirs (the experiment also removes figures an earlier run wrote that this one
    /// does not). Without it such a folder is refused, so that runs never mix.
    #[arg(long)]
    pub force: bool,
    /// Monte Carlo runs of the experiment (default: the built-in scenario's 20).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numbers::count)]
    pub runs: Option<usize>,
    /// Instead of the experiment: the noise-analysis demo (18-h static log → Allan).
    #[arg(long)]
    pub noise: bool,
    /// Print the built-in scenario (a starting point for `driftless experiment`) and exit.
    #[arg(long)]
    pub print_scenario: bool,
    /// (--noise) Length of the simulated static log, hours.
    #[arg(long, default_value_t = 18.0, allow_hyphen_values = true, value_parser = crate::numbers::positive)]
    pub hours: f64,
    /// (--noise) Sample rate, Hz.
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true, value_parser = crate::numbers::positive)]
    pub rate: f64,
    /// (--noise) Random seed (the run is reproducible from it).
    #[arg(long, default_value_t = 2026)]
    pub seed: u64,
    /// (--noise) Also write the simulated log (binary DRIFTLOG, ~300 MB for 18 h).
    #[arg(long)]
    pub write_log: bool,
    /// Print the JSON document of `driftless allan --json` instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// The demo's true noise terms, per axis (ADIS16465-1-class numbers: ARW 0.15 deg/√h,
/// in-run bias stability 2 deg/h, VRW 0.012 m/s/√h, accel in-run stability 3.6 µg from the
/// ADIS16465 data sheet, Table 1). Rate random walk is not in the data sheet; it is set so
/// that its +½ slope crosses the bias-instability floor near τ = 300 s and so is observable
/// within an 18-h log (a K whose slope only emerges near the last tau cannot be recovered
/// by any method: the fit then reports a wide interval or "not detected").
pub fn demo_truth(rate_hz: f64, duration_s: f64) -> Vec<(String, Quantity, StaticNoiseConfig)> {
    let gyro = StaticNoiseConfig {
        sample_rate_hz: rate_hz,
        duration_s,
        white: 0.15 * DEG_PER_SQRT_H,
        bias_instability: 2.0 * DEG_PER_H,
        rate_random_walk: 8.0 * DEG_PER_H_PER_SQRT_H,
        ..StaticNoiseConfig::default()
    };
    let acc = StaticNoiseConfig {
        sample_rate_hz: rate_hz,
        duration_s,
        white: 0.012 * M_PER_S_PER_SQRT_H,
        bias_instability: 3.6 * MICRO_G,
        rate_random_walk: 4.0e-6,
        ..StaticNoiseConfig::default()
    };
    let mut v = Vec::new();
    for ax in ["x", "y", "z"] {
        v.push((format!("gyro_{ax}"), Quantity::AngularRate, gyro.clone()));
    }
    for ax in ["x", "y", "z"] {
        v.push((format!("acc_{ax}"), Quantity::SpecificForce, acc.clone()));
    }
    v
}

pub fn run(a: DemoArgs) -> Result<()> {
    if a.print_scenario {
        out!("{}", driftless::experiment::scenario::BUILTIN_ADI_LIKE);
        return Ok(());
    }
    if !a.noise {
        let sc = driftless::experiment::ExperimentScenario::builtin_adi_like()?;
        let out = crate::experiment_run::OutputFolder {
            dir: &a.out,
            force: a.force,
        };
        return crate::experiment_run::run_scenario(sc, out, a.runs, a.json);
    }
    noise_demo(a)
}

fn noise_demo(a: DemoArgs) -> Result<()> {
    let t_all = Instant::now();
    // Held until the last file is written.
    let _lock = driftless::io::output::claim_folder(&a.out, a.force)?;
    let duration_s = a.hours * 3600.0;
    let truth = demo_truth(a.rate, duration_s);
    let n = (duration_s * a.rate).round() as usize;

    let sp = spinner(
        !a.json,
        format!(
            "simulating {:.1} h × {} Hz × 6 axes ({n} samples each)",
            a.hours, a.rate
        ),
    );
    let t0 = Instant::now();
    let cfgs: Vec<StaticNoiseConfig> = truth.iter().map(|t| t.2.clone()).collect();
    let data = generate_channels(&cfgs, a.seed)?;
    let t_sim = t0.elapsed();
    sp.finish_and_clear();
    let channels: Vec<Channel> = truth
        .iter()
        .zip(data)
        .map(|((name, q, _), values)| Channel {
            name: name.clone(),
            quantity: *q,
            source_unit: q.si_unit().to_string(),
            values,
        })
        .collect();
    let log = ImuLog::new(
        format!("simulated:static-18h-seed{}", a.seed),
        None,
        1.0 / a.rate,
        channels,
    );
    if a.write_log {
        let p = a.out.join("static.dlog");
        driftless::io::write_binary_file(&log, &p)?;
    }

    let sp = spinner(
        !a.json,
        "overlapping Allan deviation, 6 channels, log:100 taus".into(),
    );
    let t0 = Instant::now();
    let cfg = AnalysisConfig {
        estimator: Estimator::Oadev,
        taus: TauSpec::Log(100),
        data_type: DataType::Frequency,
        alpha: None,
        confidence: 0.683,
        fast: false,
    };
    let fit_cfg = FitConfig {
        white: true,
        bias_instability: true,
        rate_random_walk: true,
        ..FitConfig::NONE
    };
    let out = analyse_log(&log, &LogAnalysisOptions::allan(cfg, Some(fit_cfg)))?;
    let t_allan = t0.elapsed();
    sp.finish_and_clear();

    let plot_path = a.out.join("allan.svg");
    crate::plots::write_allan_plot(
        &plot_path,
        &out,
        "driftless demo: simulated 18-h static IMU",
    )?;
    let model_path = a.out.join("noise-model.toml");
    if let Some(m) = &out.noise {
        m.save(&model_path)?;
    }
    let json = crate::output::json_text(&out)?;
    driftless::io::output::write(a.out.join("allan.json"), &json)?;

    if a.json {
        outln!("{json}");
        return Ok(());
    }
    outln!(
        "driftless demo — simulated static six-axis IMU, {:.1} h at {} Hz ({} samples/axis), seed {}\n",
        a.hours,
        a.rate,
        n,
        a.seed
    );
    out!("{}", truth_table(&truth, &out));
    outln!();
    if let Some(m) = &out.noise {
        out!("{}", m.human_table());
    }
    outln!(
        "\ntimings: simulation {:.2} s, OADEV + CI + fit {:.2} s, total {:.2} s",
        t_sim.as_secs_f64(),
        t_allan.as_secs_f64(),
        t_all.elapsed().as_secs_f64()
    );
    outln!(
        "wrote {}, {}, {}",
        plot_path.display(),
        model_path.display(),
        a.out.join("allan.json").display()
    );
    Ok(())
}

/// Fitted vs true terms, in display units, with the error relative to truth.
fn truth_table(truth: &[(String, Quantity, StaticNoiseConfig)], out: &LogAnalysis) -> String {
    let mut t = Table::new([
        "channel", "term", "unit", "true", "fitted", "lo", "hi", "error",
    ]);
    let Some(model) = &out.noise else {
        return String::new();
    };
    for ((name, q, cfg), fit) in truth.iter().zip(model.fits()) {
        let gyro = *q == Quantity::AngularRate;
        let rows: [(&str, &str, f64, f64, Option<driftless::allan::fit::Term>); 3] = [
            (
                "N",
                if gyro { "deg/√h" } else { "m/s/√h" },
                if gyro {
                    DEG_PER_SQRT_H
                } else {
                    M_PER_S_PER_SQRT_H
                },
                cfg.white,
                fit.white,
            ),
            (
                "B",
                if gyro { "deg/h" } else { "µg" },
                if gyro { DEG_PER_H } else { MICRO_G },
                cfg.bias_instability,
                fit.bias_instability,
            ),
            (
                "K",
                if gyro { "deg/h/√h" } else { "m/s²/√s" },
                if gyro { DEG_PER_H_PER_SQRT_H } else { 1.0 },
                cfg.rate_random_walk,
                fit.rate_random_walk,
            ),
        ];
        for (term, unit, k, truth_v, fitted) in rows {
            let (f, lo, hi, err) = match fitted {
                Some(tm) => (
                    sci(tm.value / k),
                    sci(tm.lo / k),
                    sci(tm.hi / k),
                    format!("{:+.1} %", 100.0 * (tm.value - truth_v) / truth_v),
                ),
                None => ("not found".into(), "".into(), "".into(), "".into()),
            };
            t.row(vec![
                name.clone(),
                term.into(),
                unit.into(),
                sci(truth_v / k),
                f,
                lo,
                hi,
                err,
            ]);
        }
    }
    format!(
        "fitted noise terms vs the simulation's truth\n{}",
        t.render()
    )
}

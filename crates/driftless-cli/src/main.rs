//! `driftless` — from raw MEMS IMU logs to a navigation error budget.
//!
//! Subcommands: `allan` (noise analysis), `convert` (text ↔ compact binary log),
//! `experiment` (the seed paper's experiment end to end), `demo` (the experiment on
//! built-in simulated data; `--noise`: the Allan demo), `bench`, `nav` (GNSS/INS),
//! `simulate` (scenario → IMU, GNSS and truth files), `calibrate`, `thermal`,
//! `compensate`.

#[macro_use]
mod stdout;

mod allan_cmd;
mod bench_cmd;
mod calibrate_cmd;
mod compensate_cmd;
mod convert_cmd;
mod demo_cmd;
mod experiment_cmd;
mod input;
mod nav_cmd;
mod output;
mod paths;
mod segment_view;
mod simulate_cmd;
mod thermal_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "driftless",
    version,
    about = "MEMS IMU noise analysis, calibration and GNSS/INS error budgets",
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Allan-family deviations, confidence intervals and IMU noise terms of a log.
    Allan(allan_cmd::AllanArgs),
    /// Room-temperature calibration (bias, scale, misalignment with σ): six-position +
    /// rate table, or multi-position without fixtures.
    Calibrate(calibrate_cmd::CalibrateArgs),
    /// Apply a thermal compensation model to a log (refuses a log compensated already).
    Compensate(compensate_cmd::CompensateArgs),
    /// Convert a delimited text log to the compact binary log format (or back).
    Convert(convert_cmd::ConvertArgs),
    /// Speed benchmarks (parse, binary read, exact and fast OADEV) on generated data.
    Bench(bench_cmd::BenchArgs),
    /// Loosely coupled GNSS/INS on recorded data, with simulated GNSS outages.
    Nav(nav_cmd::NavArgs),
    /// Thermal calibration: soak (chamber) data → bias and scale-factor polynomials and
    /// the real-time compensation model.
    Thermal(thermal_cmd::ThermalArgs),
    /// Simulate IMU, GNSS and truth from a scenario file (trajectory, sensor errors,
    /// temperature, GNSS).
    Simulate(simulate_cmd::SimulateArgs),
    /// The paper's experiment end to end: noise model, thermal model, vehicle run with
    /// GNSS outages in three cases, Table 1, figures and an HTML report.
    Experiment(experiment_cmd::ExperimentArgs),
    /// The experiment on the built-in adi-like scenario (`--noise`: the Allan demo).
    Demo(demo_cmd::DemoArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run(cli.command)?;
        stdout::flush().map_err(|e| anyhow::Error::new(stdout::StdoutFailed(e)))
    }));
    let result = match result {
        Ok(r) => r,
        Err(payload) => match payload.downcast::<stdout::StdoutFailed>() {
            Ok(failed) => Err(anyhow::Error::new(*failed)),
            Err(other) => std::panic::resume_unwind(other),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match e.downcast_ref::<stdout::StdoutFailed>() {
            // The reader has gone (`| head`): nothing left to say to anyone.
            Some(f) if f.0.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
            _ => {
                eprintln!("error: {}", error_chain(&e));
                ExitCode::from(1)
            }
        },
    }
}

fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Allan(a) => allan_cmd::run(a),
        Command::Convert(a) => convert_cmd::run(a),
        Command::Calibrate(a) => calibrate_cmd::run(a),
        Command::Compensate(a) => compensate_cmd::run(a),
        Command::Demo(a) => demo_cmd::run(a),
        Command::Experiment(a) => experiment_cmd::run(a),
        Command::Bench(a) => bench_cmd::run(a),
        Command::Nav(a) => nav_cmd::run(a),
        Command::Simulate(a) => simulate_cmd::run(a),
        Command::Thermal(a) => thermal_cmd::run(a),
    }
}

/// The error and its causes on one line, skipping a cause whose text the message already
/// contains (library errors often quote their source).
fn error_chain(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.contains(&text) {
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
    }
    msg
}

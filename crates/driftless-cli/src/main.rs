//! `driftless` — from raw MEMS IMU logs to a navigation error budget.
//!
//! Subcommands: `allan` (noise analysis), `convert` (text ↔ compact binary log),
//! `experiment` (the seed paper's experiment end to end), `demo` (the experiment on
//! built-in simulated data; `--noise`: the Allan demo), `bench`, `nav` (GNSS/INS),
//! `simulate` (scenario → IMU, GNSS and truth files), `calibrate`, `thermal`,
//! `compensate`, and `completions` / `man` (shell completion scripts and man pages).
//!
//! Standard output carries only the result (tables or JSON); errors, warnings, notes and
//! progress bars go to standard error ([`verbosity`]). Exit status: 0 success, 1 error,
//! 2 usage error ([`EXIT_CODES`]).

#[macro_use]
mod stdout;
#[macro_use]
mod verbosity;

mod allan_cmd;
mod bench_cmd;
mod calibrate_cmd;
mod compensate_cmd;
mod completions_cmd;
mod convert_cmd;
mod demo_cmd;
mod experiment_cmd;
mod experiment_run;
mod input;
mod man_cmd;
mod nav_cmd;
mod numbers;
mod output;
mod paths;
mod plots;
mod progress;
mod segment_view;
mod simulate_cmd;
mod thermal_cmd;

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;

/// The exit statuses, as `--help` and the man page state them.
pub const EXIT_CODES: &str = "\
Exit status:
  0  success: the result was printed and every output file written
  1  error: the result cannot be stood behind (unreadable or bad input, a check that
     failed, an output that could not be written); the message on stderr names the
     file, line or time span and what to change
  2  usage error: an unknown command or flag, a missing or malformed argument

Standard output carries only the result (tables or JSON); errors, warnings, notes and
progress bars go to standard error. --quiet leaves errors and the warnings the result
depends on; --verbose adds detail where a command has it.";

#[derive(Parser)]
#[command(
    name = "driftless",
    version,
    about = "MEMS IMU noise analysis, calibration and GNSS/INS error budgets",
    propagate_version = true,
    after_long_help = EXIT_CODES
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No notes or progress bars on stderr (errors and the warnings the result depends
    /// on are still printed).
    #[arg(long, short = 'q', global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// More detail on stderr where a command has it (every rejected GNSS fix, every IMU
    /// value finding).
    #[arg(long, short = 'v', global = true)]
    verbose: bool,
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
    /// Print a shell completion script (bash, zsh or fish).
    Completions(completions_cmd::CompletionsArgs),
    /// Print the man page (roff), or write one page per command into a folder.
    Man(man_cmd::ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    verbosity::set(if cli.quiet {
        verbosity::Verbosity::Quiet
    } else if cli.verbose {
        verbosity::Verbosity::Verbose
    } else {
        verbosity::Verbosity::Normal
    });
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
        Command::Completions(a) => completions_cmd::run(a, Cli::command()),
        Command::Man(a) => man_cmd::run(a, Cli::command()),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// clap's own consistency checks of the definition (no two flags with one short
    /// name, a global flag that a subcommand does not shadow, …), which a release
    /// build skips.
    #[test]
    fn command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}

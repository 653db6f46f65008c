//! `driftless allan`: stability curves with confidence intervals and IMU noise terms
//! ([`driftless::allan::log_analysis`]).

use crate::input::InputArgs;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use driftless::allan::analysis::AnalysisConfig;
use driftless::allan::fit::{FitConfig, FitRangeSpec};
use driftless::allan::gmwm::GmwmConfig;
use driftless::allan::log_analysis::{
    ChannelSelection, LogAnalysis, LogAnalysisError, LogAnalysisOptions, NoiseMethod, analyse_log,
};
use driftless::allan::taus::TauSpec;
use driftless::allan::{DataType, Estimator};
use std::path::{Path, PathBuf};

mod export;
mod human;
mod replicates;
use export::Exports;
use replicates::run_replicates;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum DataTypeArg {
    /// Rates (rad/s, m/s², fractional frequency).
    #[value(alias = "frequency")]
    Freq,
    /// Integrated values (angle, velocity, time error).
    Phase,
}

/// Which estimator produces the noise model.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// IEEE 952 term fit to the overlapping Allan variance.
    Allan,
    /// Generalized method of wavelet moments: Haar wavelet variance, GMM fit of a sum of
    /// processes (white, quantization, random walk, drift, Gauss-Markov), WIC selection.
    Gmwm,
}

#[derive(Args, Debug)]
pub struct AllanArgs {
    /// The log(s): delimited text (CSV, whitespace, single column) or binary DRIFTLOG
    /// files. Several files are replicate runs of one sensor: each is analysed, the runs'
    /// noise terms are compared and a joint model is fitted to them all.
    #[arg(required_unless_present = "model", num_args = 1.., value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Whether the values are rates (freq) or integrated (phase).
    #[arg(long, value_enum, default_value = "freq")]
    pub data_type: DataTypeArg,
    /// Multiply every data value by K first (after unit conversion), e.g. 1e-7 to turn a
    /// 10 MHz counter reading into fractional frequency.
    #[arg(long, value_name = "K", allow_hyphen_values = true, value_parser = crate::numbers::finite_nonzero)]
    pub scale: Option<f64>,
    /// Tau grid: octave, decade, all, log:N, or a comma-separated list of taus in seconds.
    #[arg(long, default_value = "log:100", value_name = "SPEC")]
    pub taus: String,
    /// adev | oadev | mdev | hdev | ohdev | tdev | totdev.
    #[arg(long, default_value = "oadev", value_name = "NAME")]
    pub estimator: String,
    /// Fix the power-law noise exponent α (−2..2; −4..2 for Hadamard) used for the
    /// confidence intervals instead of identifying it per tau (lag-1 autocorrelation).
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    pub alpha: Option<i32>,
    /// Confidence level of the intervals.
    #[arg(long, default_value_t = 0.683, value_name = "CL", allow_hyphen_values = true, value_parser = crate::numbers::probability)]
    pub confidence: f64,
    /// Reduced-overlap OADEV (differences every m/8 samples): ~3-4x faster on long logs,
    /// slightly wider intervals (the EDF accounts for it). Only with --estimator oadev.
    #[arg(long)]
    pub fast: bool,
    /// Noise-model estimator: allan (IEEE 952 fit to the Allan variance) or gmwm
    /// (wavelet-variance GMM with model selection).
    #[arg(long, value_enum, default_value = "allan")]
    pub method: MethodArg,
    /// Noise terms to fit, comma-separated from q (quantization), n (white: ARW/VRW),
    /// b (bias instability), k (rate random walk), r (rate ramp), gm (one Gauss-Markov).
    /// Default q,n,b,k,r,gm (a Gauss-Markov term kept only where the data resolve it;
    /// q,n,b,k,r for the IEEE 952 terms alone). With --method gmwm the candidates of the
    /// model selection: q, n, k, r, gm (up to three Gauss-Markov terms) or gm1..gm4;
    /// default q,n,k,r,gm.
    #[arg(long, value_name = "LIST")]
    pub terms: Option<String>,
    /// Fit the Allan noise terms over TMIN:TMAX seconds only (either side may be empty:
    /// the curve's end). By default the short taus where the sensor's own filtering
    /// colours the noise (averaged rates still correlated) are left out automatically.
    #[arg(long, value_name = "TMIN:TMAX")]
    pub fit_range: Option<String>,
    /// Skip the noise-term fit.
    #[arg(long)]
    pub no_fit: bool,
    /// Fit the noise model to the data as they are, spectral lines included (by default
    /// lines — vibration, pumps, mains — are found, reported and notched out before the fit).
    #[arg(long)]
    pub keep_lines: bool,
    /// Machine-readable output (see README: the `allan` JSON contract).
    #[arg(long)]
    pub json: bool,
    /// Write a log-log plot (SVG, or PNG when built with the `png` feature).
    #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = crate::output::figure_path)]
    pub plot: Option<PathBuf>,
    /// Save the fitted noise model (TOML) for the filter and the simulator.
    #[arg(long, value_name = "FILE")]
    pub save_model: Option<PathBuf>,
    /// Write the noise model in other estimators' units: comma-separated FORMAT=PATH
    /// pairs, FORMAT one of kalibr (imu.yaml), openvins (kalibr_imu_chain.yaml), vins
    /// (acc_n, gyr_n, acc_w, gyr_w), kfgins (imunoise block), px4 (EKF2 .params),
    /// ardupilot (EKF3 .param). Mappings: docs/noise-exports.md.
    #[arg(long, value_name = "FORMAT=PATH,...")]
    pub export: Vec<String>,
    /// Values for --export, SI, replacing the model's or filling what it lacks:
    /// KEY=VALUE,... with keys gyroscope_noise_density, gyroscope_random_walk,
    /// accelerometer_noise_density, accelerometer_random_walk (continuous densities as in
    /// Kalibr), gyroscope_bias_sigma, accelerometer_bias_sigma, bias_correlation_time
    /// (KF-GINS's Gauss-Markov bias, s).
    #[arg(long, value_name = "KEY=VALUE,...")]
    pub export_set: Option<String>,
    /// Export a saved noise model (from --save-model) instead of analysing a log; needs
    /// --export.
    #[arg(long, value_name = "FILE", conflicts_with = "files")]
    pub model: Option<PathBuf>,
    #[command(flatten)]
    pub input: InputArgs,
}

/// The analysis settings from the flags.
pub fn analysis_config(a: &AllanArgs) -> Result<AnalysisConfig> {
    let estimator = Estimator::from_name(&a.estimator).with_context(|| {
        format!(
            "--estimator {:?}: expected adev, oadev, mdev, hdev, ohdev, tdev or totdev",
            a.estimator
        )
    })?;
    let taus: TauSpec = a.taus.parse()?;
    Ok(AnalysisConfig {
        estimator,
        taus,
        data_type: match a.data_type {
            DataTypeArg::Freq => DataType::Frequency,
            DataTypeArg::Phase => DataType::Phase,
        },
        alpha: a.alpha,
        confidence: a.confidence,
        fast: a.fast,
    })
}

/// The analysis options from the flags.
pub fn analysis_options(a: &AllanArgs) -> Result<LogAnalysisOptions> {
    Ok(LogAnalysisOptions {
        analysis: analysis_config(a)?,
        method: if a.no_fit {
            None
        } else {
            Some(noise_method(a)?)
        },
        scale: a.scale,
        remove_lines: !a.keep_lines,
        resolution_from_data: true,
        channels: ChannelSelection::AllButTemperature,
    })
}

/// A failed analysis, the user's τ range named by its flag.
pub fn analysis_error(e: LogAnalysisError) -> anyhow::Error {
    match e {
        LogAnalysisError::FitRange(inner) => anyhow::Error::new(inner).context("--fit-range"),
        other => anyhow::Error::new(other),
    }
}

pub fn run(a: AllanArgs) -> Result<()> {
    if let Some(m) = &a.model {
        return export::run_saved_model(&a, m);
    }
    let exports = Exports::from_args(&a)?;
    if a.no_fit && !exports.is_empty() {
        bail!("--export needs the noise fit (drop --no-fit)");
    }
    let inputs: Vec<Option<&Path>> = a.files.iter().map(|f| Some(f.as_path())).collect();
    let mut outputs = vec![a.save_model.as_deref(), a.plot.as_deref()];
    outputs.extend(exports.paths().map(Some));
    crate::paths::refuse_outputs_over_inputs(&outputs, &inputs)?;
    let file = match a.files.as_slice() {
        [] => bail!("allan needs a log file"),
        [one] => one,
        _ => return run_replicates(&a, &exports),
    };
    let opts = analysis_options(&a)?;
    let log = crate::progress::read_with_progress(&a.input, file, a.json)?;
    crate::progress::warn_gaps(file, &log);
    let spinner = crate::progress::spinner(
        !a.json,
        format!(
            "{} on {} channel(s) × {} samples",
            opts.analysis.estimator.name().to_uppercase(),
            log.channels.len(),
            log.len()
        ),
    );
    let out = analyse_log(&log, &opts).map_err(analysis_error)?;
    spinner.finish_and_clear();
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    let exported = write_model_outputs(&a, &exports, &out)?;
    if let Some(p) = &a.plot {
        crate::plots::write_allan_plot(p, &out, &file.display().to_string())?;
    }
    if a.json {
        outln!("{}", crate::output::json_text(&out)?);
    } else {
        out!("{}", human::human_output(&out, &log, file));
        if let Some(p) = &a.plot {
            outln!("plot written to {}", p.display());
        }
        if let Some(p) = &a.save_model {
            outln!("noise model written to {}", p.display());
        }
        for line in &exported {
            outln!("{line}");
        }
    }
    Ok(())
}

/// `--save-model` and `--export` of the fitted model; returns the export's lines to print.
fn write_model_outputs(a: &AllanArgs, exports: &Exports, out: &LogAnalysis) -> Result<Vec<String>> {
    if let Some(p) = &a.save_model {
        let model = out
            .noise
            .as_ref()
            .context("--save-model needs the noise fit (drop --no-fit)")?;
        model
            .save(p)
            .with_context(|| format!("writing noise model {}", p.display()))?;
    }
    if exports.is_empty() {
        return Ok(Vec::new());
    }
    let model = out
        .noise
        .as_ref()
        .context("--export needs the noise fit (drop --no-fit)")?;
    exports.write(model)
}

/// The noise-model method and its term selection from `--method`, `--terms` and
/// `--confidence`.
pub fn noise_method(a: &AllanArgs) -> Result<NoiseMethod> {
    Ok(match a.method {
        MethodArg::Allan => NoiseMethod::Allan(
            a.terms
                .as_deref()
                .unwrap_or("q,n,b,k,r,gm")
                .parse::<FitConfig>()
                .context("--terms")?,
            a.fit_range
                .as_deref()
                .map(str::parse::<FitRangeSpec>)
                .transpose()
                .context("--fit-range")?,
        ),
        MethodArg::Gmwm => {
            if a.fit_range.is_some() {
                bail!("--fit-range applies to the Allan fit; drop it with --method gmwm");
            }
            let terms = match &a.terms {
                Some(t) => t
                    .parse::<GmwmConfig>()
                    .context("--terms (with --method gmwm)")?,
                None => GmwmConfig::default(),
            };
            NoiseMethod::Gmwm(GmwmConfig {
                confidence: a.confidence,
                ..terms
            })
        }
    })
}

//! `driftless allan`: stability curves with confidence intervals and IMU noise terms.

use crate::input::InputArgs;
use crate::output::{Table, sci};
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use driftless::allan::analysis::{AnalysisConfig, ChannelResult, analyse_channels};
use driftless::allan::fit::{FitConfig, FitRangeSpec, chi2_verdict};
use driftless::allan::gmwm::{self, GmwmChannel, GmwmConfig};
use driftless::allan::lines::{self, ChannelLines, LineConfig, SpectralLine};
use driftless::allan::noise_model::{ModelOptions, NoiseModel};
use driftless::allan::taus::TauSpec;
use driftless::allan::{DataType, Estimator};
use driftless::allan::{checks, plausibility};
use driftless::io::{ImuLog, Quantity};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

mod export;
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

/// Everything `allan` computes for one log.
pub struct AllanOutput {
    pub results: Vec<ChannelResult>,
    pub quantities: Vec<Quantity>,
    pub units: Vec<String>,
    pub noise: Option<NoiseModel>,
    /// The GMWM per channel (wavelet variance and fit) when `--method gmwm`.
    pub gmwm: Vec<GmwmChannel>,
    /// Whether the record suits the analysis: not static, too short for a fitted term
    /// (see `driftless::allan::checks`).
    pub warnings: Vec<String>,
    /// Spectral lines found per channel (removed before the noise fit).
    pub lines: Vec<ChannelLines>,
    /// The OADEV curves the Allan noise model was fitted to (line-free where lines were
    /// found), in channel order; empty without the Allan fit.
    pub fit_curves: Vec<ChannelResult>,
    /// Resolution step of each channel's rate samples, as used by the Allan fit.
    pub resolution: Vec<Option<f64>>,
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

/// Which noise model to fit.
#[derive(Clone, Debug)]
pub enum NoiseMethod {
    /// IEEE 952 term fit to the OADEV curve, over a user range (None: automatic).
    Allan(FitConfig, Option<FitRangeSpec>),
    /// GMWM.
    Gmwm(GmwmConfig),
}

/// Analyse every non-temperature channel of `log` and (optionally) fit noise terms
/// with the Allan fit.
pub fn analyse_log(
    log: &ImuLog,
    cfg: &AnalysisConfig,
    fit: Option<&FitConfig>,
    scale: Option<f64>,
    remove_lines: bool,
) -> Result<AllanOutput> {
    analyse_log_with(
        log,
        cfg,
        fit.cloned().map(|f| NoiseMethod::Allan(f, None)).as_ref(),
        scale,
        remove_lines,
    )
}

/// Analyse every non-temperature channel of `log` and (optionally) fit a noise model
/// by `method`.
pub fn analyse_log_with(
    log: &ImuLog,
    cfg: &AnalysisConfig,
    method: Option<&NoiseMethod>,
    scale: Option<f64>,
    remove_lines: bool,
) -> Result<AllanOutput> {
    let keep: Vec<usize> = (0..log.channels.len())
        .filter(|&i| log.channels[i].quantity != Quantity::Temperature)
        .collect();
    if keep.is_empty() {
        bail!(
            "{}: no data channel to analyse (only temperature)",
            log.source
        );
    }
    let scaled: Vec<Vec<f64>>;
    let data: Vec<&[f64]> = match scale {
        Some(k) => {
            if !(k.is_finite() && k != 0.0) {
                bail!("--scale must be a finite non-zero number, got {k}");
            }
            scaled = keep
                .iter()
                .map(|&i| log.channels[i].values.iter().map(|v| v * k).collect())
                .collect();
            scaled.iter().map(Vec::as_slice).collect()
        }
        None => keep
            .iter()
            .map(|&i| log.channels[i].values.as_slice())
            .collect(),
    };
    let segments: Vec<std::ops::Range<usize>> = if log.segments.is_empty() {
        std::iter::once(0..log.len()).collect()
    } else {
        log.segments.clone()
    };
    let inputs: Vec<(&str, Vec<&[f64]>)> = keep
        .iter()
        .zip(&data)
        .map(|(&i, d)| {
            let segs = segments.iter().map(|r| &d[r.clone()]).collect();
            (log.channels[i].name.as_str(), segs)
        })
        .collect();
    let results = analyse_channels(&inputs, log.tau0_s, cfg)
        .with_context(|| format!("analysing {}", log.source))?;
    let quantities: Vec<Quantity> = keep.iter().map(|&i| log.channels[i].quantity).collect();
    let units: Vec<String> = keep
        .iter()
        .map(|&i| {
            let q = log.channels[i].quantity;
            if q == Quantity::Other {
                log.channels[i].source_unit.clone()
            } else {
                q.si_unit().to_string()
            }
        })
        .collect();

    // Spectral lines (rate data, when a noise model is fitted): found on each channel's
    // longest segment, notched out of every segment before the fit.
    let found: Vec<Vec<SpectralLine>> =
        if remove_lines && method.is_some() && cfg.data_type == DataType::Frequency {
            inputs
                .par_iter()
                .map(|(_, segs)| {
                    let longest = segs.iter().max_by_key(|s| s.len()).copied().unwrap_or(&[]);
                    lines::detect_lines(longest, log.tau0_s, &LineConfig::default())
                })
                .collect()
        } else {
            vec![Vec::new(); inputs.len()]
        };
    let with_lines: Vec<usize> = (0..found.len()).filter(|&k| !found[k].is_empty()).collect();
    let cleaned: Vec<Vec<Vec<f64>>> = with_lines
        .par_iter()
        .map(|&k| {
            inputs[k]
                .1
                .iter()
                .map(|s| lines::remove_lines(s, log.tau0_s, &found[k]))
                .collect()
        })
        .collect();
    let mut fit_inputs: Vec<(&str, Vec<&[f64]>)> = inputs.clone();
    for (&k, c) in with_lines.iter().zip(&cleaned) {
        fit_inputs[k].1 = c.iter().map(Vec::as_slice).collect();
    }
    // The Allan fit's curve: the requested one when it is OADEV, else OADEV on a log grid;
    // recomputed on the line-free data only for the channels that had lines.
    let fit_cfg = if cfg.estimator == Estimator::Oadev {
        cfg.clone()
    } else {
        AnalysisConfig {
            estimator: Estimator::Oadev,
            taus: TauSpec::Log(100),
            fast: false,
            ..cfg.clone()
        }
    };
    let needs_curves = matches!(method, Some(NoiseMethod::Allan(..))) || !with_lines.is_empty();
    let base_curves;
    let base: &[ChannelResult] = if cfg.estimator == Estimator::Oadev {
        &results
    } else if needs_curves {
        base_curves = analyse_channels(&inputs, log.tau0_s, &fit_cfg)?;
        &base_curves
    } else {
        &[]
    };
    let line_inputs: Vec<(&str, Vec<&[f64]>)> =
        with_lines.iter().map(|&k| fit_inputs[k].clone()).collect();
    let clean_curves = if line_inputs.is_empty() {
        Vec::new()
    } else {
        analyse_channels(&line_inputs, log.tau0_s, &fit_cfg)?
    };
    let mut fit_curves: Vec<ChannelResult> = base.to_vec();
    let mut lines_out = Vec::new();
    for (&k, cc) in with_lines.iter().zip(clean_curves) {
        let tau: Vec<f64> = cc.points.iter().map(|p| p.tau).collect();
        let with: Vec<f64> = base[k].points.iter().map(|p| p.dev).collect();
        let without: Vec<f64> = cc.points.iter().map(|p| p.dev).collect();
        let (inc, at) = lines::sigma_increase(&tau, &with, &without);
        lines_out.push(ChannelLines {
            channel: inputs[k].0.to_string(),
            lines: found[k].clone(),
            max_sigma_increase: inc,
            at_tau_s: at,
        });
        fit_curves[k] = cc;
    }
    let mut gmwm_channels = Vec::new();
    let mut resolution_used = Vec::new();
    let noise = match method {
        None => None,
        Some(NoiseMethod::Gmwm(gc)) => {
            gmwm_channels = gmwm::gmwm_channels(&fit_inputs, log.tau0_s, gc)
                .with_context(|| format!("GMWM of {}", log.source))?;
            Some(gmwm::noise_model(&log.source, &gmwm_channels, &quantities)?)
        }
        Some(NoiseMethod::Allan(fc, range)) => {
            let resolution = match cfg.data_type {
                DataType::Frequency => data
                    .par_iter()
                    .map(|d| checks::resolution_step(d))
                    .collect(),
                DataType::Phase => Vec::new(),
            };
            resolution_used.clone_from(&resolution);
            let opts = ModelOptions {
                fit_range: *range,
                resolution,
                ..ModelOptions::default()
            };
            let model = NoiseModel::from_curves_with(
                &log.source,
                &fit_curves,
                &quantities,
                fc,
                cfg.confidence,
                &opts,
            );
            Some(if range.is_some() {
                model.context("--fit-range")?
            } else {
                model?
            })
        }
    };
    let mut warnings = Vec::new();
    for (&i, d) in keep.iter().zip(&data) {
        let name = &log.channels[i].name;
        let rates: Vec<f64>;
        let y: &[f64] = match cfg.data_type {
            DataType::Frequency => d,
            DataType::Phase => {
                rates = d.windows(2).map(|w| (w[1] - w[0]) / log.tau0_s).collect();
                &rates
            }
        };
        warnings.extend(checks::stationarity_warning(name, y, log.tau0_s));
    }
    if cfg.data_type == DataType::Frequency {
        let inputs: Vec<plausibility::ChannelInput<'_>> = keep
            .iter()
            .zip(&data)
            .map(|(&i, d)| plausibility::ChannelInput {
                name: &log.channels[i].name,
                quantity: log.channels[i].quantity,
                stated_unit: &log.channels[i].source_unit,
                values: d,
            })
            .collect();
        warnings.extend(plausibility::unit_warnings(&inputs, log.tau0_s));
    }
    for l in &lines_out {
        let unit = keep
            .iter()
            .position(|&i| log.channels[i].name == l.channel)
            .map_or("", |k| units[k].as_str());
        warnings.push(l.describe(unit));
    }
    if let Some(model) = &noise
        && gmwm_channels.is_empty()
    {
        for c in &model.channels {
            let (verdict, warn) = chi2_verdict(c.fit.chi2_reduced);
            if warn {
                warnings.push(format!(
                    "{}: noise fit chi2_red = {:.3} — {verdict}",
                    c.name, c.fit.chi2_reduced
                ));
            }
        }
    }
    if let Some(model) = &noise {
        let record_s = log.len() as f64 * log.tau0_s;
        for (c, r) in model.channels.iter().zip(&results) {
            let taus: Vec<f64> = r.points.iter().map(|p| p.tau).collect();
            warnings.extend(checks::record_length_warnings(
                &c.name, &c.fit, &taus, record_s,
            ));
        }
    }
    let warnings = warnings
        .into_iter()
        .map(|w| format!("{}: {w}", log.source))
        .collect();
    Ok(AllanOutput {
        results,
        quantities,
        units,
        noise,
        gmwm: gmwm_channels,
        warnings,
        lines: lines_out,
        fit_curves: if matches!(method, Some(NoiseMethod::Allan(..))) {
            fit_curves
        } else {
            Vec::new()
        },
        resolution: resolution_used,
    })
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
    let cfg = analysis_config(&a)?;
    let fit = if a.no_fit {
        None
    } else {
        Some(noise_method(&a)?)
    };
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
    let spinner = crate::demo_cmd::spinner(
        !a.json,
        format!(
            "{} on {} channel(s) × {} samples",
            cfg.estimator.name().to_uppercase(),
            log.channels.len(),
            log.len()
        ),
    );
    let out = analyse_log_with(&log, &cfg, fit.as_ref(), a.scale, !a.keep_lines)?;
    spinner.finish_and_clear();
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }

    if let Some(p) = &a.save_model {
        let model = out
            .noise
            .as_ref()
            .context("--save-model needs the noise fit (drop --no-fit)")?;
        model
            .save(p)
            .with_context(|| format!("writing noise model {}", p.display()))?;
    }
    let exported = if exports.is_empty() {
        Vec::new()
    } else {
        let model = out
            .noise
            .as_ref()
            .context("--export needs the noise fit (drop --no-fit)")?;
        exports.write(model)?
    };
    if let Some(p) = &a.plot {
        crate::demo_cmd::write_plot(p, &out, &file.display().to_string())?;
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&json_output(&out))?);
    } else {
        out!("{}", human_output(&out, &log, file));
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

/// Read a log, with a spinner for big files.
pub fn read_with_progress(input: &InputArgs, path: &Path, quiet: bool) -> Result<ImuLog> {
    let big = std::fs::metadata(path)
        .map(|m| m.len() > 50 << 20)
        .unwrap_or(false);
    let sp = crate::demo_cmd::spinner(big && !quiet, format!("reading {}", path.display()));
    let log = input.read(path)?;
    sp.finish_and_clear();
    Ok(log)
}

/// The `--json` document: `{"channels":[…], "noise": {…}}`.
pub fn json_output(out: &AllanOutput) -> serde_json::Value {
    let channels = channels_json(&out.results, &out.units);
    let noise = match &out.noise {
        Some(m) => noise_json(m, out.gmwm.is_empty()),
        None => serde_json::Value::Null,
    };
    let mut doc = serde_json::json!({
        "channels": channels,
        "noise": noise,
        "warnings": out.warnings,
        "lines": out.lines,
    });
    if !out.gmwm.is_empty() {
        doc["gmwm"] = serde_json::to_value(&out.gmwm).unwrap_or(serde_json::Value::Null);
    }
    doc
}

/// The curves of the `--json` document.
fn channels_json(results: &[ChannelResult], units: &[String]) -> Vec<serde_json::Value> {
    results
        .iter()
        .zip(units)
        .map(|(r, unit)| {
            serde_json::json!({
                "name": r.name,
                "estimator": r.estimator.name(),
                "unit": unit,
                "tau0": r.tau0_s,
                "confidence": r.confidence,
                "tau": r.points.iter().map(|p| p.tau).collect::<Vec<_>>(),
                "m": r.points.iter().map(|p| p.m).collect::<Vec<_>>(),
                "n": r.points.iter().map(|p| p.n).collect::<Vec<_>>(),
                "dev": r.points.iter().map(|p| p.dev).collect::<Vec<_>>(),
                "dev_lo": r.dev_lo,
                "dev_hi": r.dev_hi,
                "alpha": r.alpha,
                "edf": r.edf,
                "rate_acf1": r.rate_acf1,
            })
        })
        .collect()
}

/// A noise model in the `--json` document; an Allan fit's channels carry the χ²_red
/// verdict.
fn noise_json(m: &NoiseModel, allan_fit: bool) -> serde_json::Value {
    let mut noise = serde_json::to_value(m).unwrap_or(serde_json::Value::Null);
    if allan_fit
        && let Some(chs) = noise
            .get_mut("channels")
            .and_then(serde_json::Value::as_array_mut)
    {
        for (j, c) in chs.iter_mut().zip(&m.channels) {
            let (verdict, warn) = chi2_verdict(c.fit.chi2_reduced);
            if let Some(fit) = j.get_mut("fit").and_then(serde_json::Value::as_object_mut) {
                fit.insert("chi2_verdict".into(), verdict.into());
                fit.insert("chi2_warning".into(), warn.into());
            }
        }
    }
    noise
}

fn human_output(out: &AllanOutput, log: &ImuLog, file: &Path) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} samples at {} Hz ({:.2} h), {} channel(s)\n\n",
        file.display(),
        log.len(),
        sci(1.0 / log.tau0_s),
        log.len() as f64 * log.tau0_s / 3600.0,
        out.results.len()
    ));
    for (r, unit) in out.results.iter().zip(&out.units) {
        s.push_str(&format!(
            "{} — {} [{}], {:.1} % confidence\n",
            r.name,
            r.estimator.name().to_uppercase(),
            if unit.is_empty() { "data units" } else { unit },
            100.0 * r.confidence
        ));
        let mut t = Table::new([
            "tau [s]", "m", "n", "alpha", "edf", "dev_lo", "dev", "dev_hi",
        ]);
        for (i, p) in r.points.iter().enumerate() {
            t.row(vec![
                sci(p.tau),
                p.m.to_string(),
                p.n.to_string(),
                r.alpha[i].to_string(),
                sci(r.edf[i]),
                sci(r.dev_lo[i]),
                sci(p.dev),
                sci(r.dev_hi[i]),
            ]);
        }
        s.push_str(&t.render());
        s.push('\n');
    }
    for g in &out.gmwm {
        let w = &g.wavelet_variance;
        s.push_str(&format!(
            "{} — Haar wavelet variance, {:.1} % confidence (eta3 EDF)\n",
            g.name,
            100.0 * w.confidence
        ));
        let mut t = Table::new(["tau [s]", "edf", "wv_lo", "wv", "wv_hi", "model"]);
        for j in 0..w.m.len() {
            t.row(vec![
                sci(w.tau_s[j]),
                sci(w.edf[j]),
                sci(w.wv_lo[j]),
                sci(w.wv[j]),
                sci(w.wv_hi[j]),
                sci(g.fit.model_wv(w.tau_s[j])),
            ]);
        }
        s.push_str(&t.render());
        s.push('\n');
    }
    if let Some(m) = &out.noise {
        if out.gmwm.is_empty() {
            s.push_str(&m.human_table());
        } else {
            s.push_str(&format!(
                "GMWM noise models (selection by {}):\n",
                gmwm::CRITERION
            ));
            s.push_str(&gmwm::human_table(m));
        }
    }
    s
}

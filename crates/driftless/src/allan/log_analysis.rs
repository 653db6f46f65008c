//! The Allan analysis of a whole log: every data channel's stability curve with
//! confidence intervals, the spectral lines found and notched out, the noise model
//! (IEEE 952 fit to the OADEV or the GMWM), and the warnings about whether the record
//! suits the analysis — what `driftless allan` prints and what the experiment's noise
//! stage fits.
//!
//! [`LogAnalysis`] serializes to the `allan --json` document:
//! `{"channels": […], "noise": {…} | null, "warnings": […], "lines": […], "gmwm": […]}`
//! (`gmwm` only with the GMWM).

use super::analysis::{AnalysisConfig, ChannelResult, analyse_channels};
use super::fit::{FitConfig, FitRangeSpec, chi2_verdict};
use super::gmwm::{self, GmwmChannel, GmwmConfig};
use super::lines::{self, ChannelLines, LineConfig, SpectralLine};
use super::noise_model::{ModelOptions, NoiseModel};
use super::taus::TauSpec;
use super::{AllanError, DataType, Estimator, checks, plausibility};
use crate::io::{ImuLog, Quantity};
use rayon::prelude::*;
use serde::ser::SerializeStruct;
use serde::{Serialize, Serializer};
use std::ops::Range;

/// Which noise model [`analyse_log`] fits.
#[derive(Clone, Debug)]
pub enum NoiseMethod {
    /// IEEE 952 term fit to the OADEV curve, over a user range (None: automatic,
    /// [`super::fit::auto_range_candidates`]).
    Allan(FitConfig, Option<FitRangeSpec>),
    /// Generalized method of wavelet moments.
    Gmwm(GmwmConfig),
}

/// Which channels of the log are analysed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChannelSelection {
    /// Every channel except temperatures.
    AllButTemperature,
    /// Angular-rate and specific-force channels only.
    Inertial,
}

/// How [`analyse_log`] analyses a log.
#[derive(Clone, Debug)]
pub struct LogAnalysisOptions {
    /// Estimator, τ grid, data type, confidence.
    pub analysis: AnalysisConfig,
    /// The noise model to fit; None: the curves only.
    pub method: Option<NoiseMethod>,
    /// Multiply every value by this factor first (finite, non-zero).
    pub scale: Option<f64>,
    /// Find spectral lines (rate data with a noise fit) and notch them out before the fit.
    pub remove_lines: bool,
    /// Give the Allan fit each channel's quantization step found in the data
    /// ([`checks::resolution_step`]); false: fit as if unquantized.
    pub resolution_from_data: bool,
    /// The channels analysed.
    pub channels: ChannelSelection,
}

impl LogAnalysisOptions {
    /// The curves of `analysis` with the Allan fit of `fit` over the automatic range,
    /// spectral lines removed, quantization taken from the data, every non-temperature
    /// channel.
    pub fn allan(analysis: AnalysisConfig, fit: Option<FitConfig>) -> Self {
        LogAnalysisOptions {
            analysis,
            method: fit.map(|f| NoiseMethod::Allan(f, None)),
            scale: None,
            remove_lines: true,
            resolution_from_data: true,
            channels: ChannelSelection::AllButTemperature,
        }
    }
}

/// Why [`analyse_log`] failed.
#[derive(Debug, thiserror::Error)]
pub enum LogAnalysisError {
    /// The log has no channel to analyse.
    #[error("{log}: no data channel to analyse (only temperature)")]
    NoDataChannel {
        /// The log's source.
        log: String,
    },
    /// The scale factor is zero or not finite.
    #[error("scale must be a finite non-zero number, got {0}")]
    Scale(f64),
    /// The stability curves could not be computed.
    #[error("analysing {log}")]
    Curves {
        /// The log's source.
        log: String,
        /// Cause.
        source: AllanError,
    },
    /// The GMWM failed.
    #[error("GMWM of {log}")]
    Gmwm {
        /// The log's source.
        log: String,
        /// Cause.
        source: AllanError,
    },
    /// The Allan fit over the user's τ range failed.
    #[error("fit range")]
    FitRange(#[source] AllanError),
    /// The noise model could not be built.
    #[error(transparent)]
    Model(#[from] AllanError),
}

/// Everything the Allan analysis of one log yields.
#[derive(Clone, Debug)]
pub struct LogAnalysis {
    /// The requested curve per analysed channel.
    pub results: Vec<ChannelResult>,
    /// Quantity of each analysed channel.
    pub quantities: Vec<Quantity>,
    /// Unit of each analysed channel: the SI unit, or the log's own for other quantities.
    pub units: Vec<String>,
    /// The fitted noise model, when a method was given.
    pub noise: Option<NoiseModel>,
    /// The GMWM per channel (wavelet variance and fit) with [`NoiseMethod::Gmwm`].
    pub gmwm: Vec<GmwmChannel>,
    /// Whether the record suits the analysis (not static, too short for a fitted term,
    /// implausible units, lines found, a poor fit), each prefixed with the log's source.
    pub warnings: Vec<String>,
    /// Spectral lines found per channel (removed before the noise fit).
    pub lines: Vec<ChannelLines>,
    /// The OADEV curves the Allan noise model was fitted to (line-free where lines were
    /// found), in channel order; empty without the Allan fit.
    pub fit_curves: Vec<ChannelResult>,
    /// Resolution step of each channel's rate samples, as used by the Allan fit.
    pub resolution: Vec<Option<f64>>,
}

/// Analyses the selected channels of `log` (each gap-free segment separately) and fits
/// the noise model of `opts.method`.
///
/// With spectral-line removal, lines are found on each channel's longest segment
/// ([`lines::detect_lines`]) and notched out of every segment; the Allan fit then uses
/// the OADEV of the line-free data. The fit's curve is the requested one when it is the
/// OADEV, else the OADEV on 100 log-spaced τ.
pub fn analyse_log(
    log: &ImuLog,
    opts: &LogAnalysisOptions,
) -> Result<LogAnalysis, LogAnalysisError> {
    let cfg = &opts.analysis;
    let method = opts.method.as_ref();
    let keep: Vec<usize> = (0..log.channels.len())
        .filter(|&i| match opts.channels {
            ChannelSelection::AllButTemperature => {
                log.channels[i].quantity != Quantity::Temperature
            }
            ChannelSelection::Inertial => matches!(
                log.channels[i].quantity,
                Quantity::AngularRate | Quantity::SpecificForce
            ),
        })
        .collect();
    if keep.is_empty() {
        return Err(LogAnalysisError::NoDataChannel {
            log: log.source.clone(),
        });
    }
    let scaled: Vec<Vec<f64>>;
    let data: Vec<&[f64]> = match opts.scale {
        Some(k) => {
            if !(k.is_finite() && k != 0.0) {
                return Err(LogAnalysisError::Scale(k));
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
    let segments: Vec<Range<usize>> = if log.segments.is_empty() {
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
    let results =
        analyse_channels(&inputs, log.tau0_s, cfg).map_err(|source| LogAnalysisError::Curves {
            log: log.source.clone(),
            source,
        })?;
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

    let (cleaned, fit_curves, lines_out) =
        without_lines(log, cfg, method, opts.remove_lines, &inputs, &results)?;
    let mut fit_inputs: Vec<(&str, Vec<&[f64]>)> = inputs.clone();
    for (k, c) in &cleaned {
        fit_inputs[*k].1 = c.iter().map(Vec::as_slice).collect();
    }
    let mut gmwm_channels = Vec::new();
    let mut resolution_used = Vec::new();
    let noise = match method {
        None => None,
        Some(NoiseMethod::Gmwm(gc)) => {
            gmwm_channels = gmwm::gmwm_channels(&fit_inputs, log.tau0_s, gc).map_err(|source| {
                LogAnalysisError::Gmwm {
                    log: log.source.clone(),
                    source,
                }
            })?;
            Some(gmwm::noise_model(&log.source, &gmwm_channels, &quantities)?)
        }
        Some(NoiseMethod::Allan(fc, range)) => {
            let resolution = match cfg.data_type {
                DataType::Frequency if opts.resolution_from_data => data
                    .par_iter()
                    .map(|d| checks::resolution_step(d))
                    .collect(),
                _ => Vec::new(),
            };
            resolution_used.clone_from(&resolution);
            let model_opts = ModelOptions {
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
                &model_opts,
            );
            Some(match model {
                Ok(m) => m,
                Err(e) if range.is_some() => return Err(LogAnalysisError::FitRange(e)),
                Err(e) => return Err(e.into()),
            })
        }
    };
    let found = Found {
        keep: &keep,
        data: &data,
        units: &units,
        results: &results,
        lines: &lines_out,
        noise: noise.as_ref(),
        allan_fit: gmwm_channels.is_empty(),
    };
    let warnings = found.warnings(log, cfg.data_type);
    Ok(LogAnalysis {
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

/// The line-free segments of each channel that had lines (by channel index), the OADEV
/// curves of the Allan fit, and the lines found.
type LineFree = (
    Vec<(usize, Vec<Vec<f64>>)>,
    Vec<ChannelResult>,
    Vec<ChannelLines>,
);

/// Spectral lines (rate data, when a noise model is fitted): found on each channel's
/// longest segment, notched out of every segment before the fit; the fit's OADEV curves
/// recomputed on the line-free data only for the channels that had lines.
fn without_lines(
    log: &ImuLog,
    cfg: &AnalysisConfig,
    method: Option<&NoiseMethod>,
    remove_lines: bool,
    inputs: &[(&str, Vec<&[f64]>)],
    results: &[ChannelResult],
) -> Result<LineFree, LogAnalysisError> {
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
        results
    } else if needs_curves {
        base_curves = analyse_channels(inputs, log.tau0_s, &fit_cfg)?;
        &base_curves
    } else {
        &[]
    };
    let line_inputs: Vec<(&str, Vec<&[f64]>)> = with_lines
        .iter()
        .zip(&cleaned)
        .map(|(&k, c)| (inputs[k].0, c.iter().map(Vec::as_slice).collect()))
        .collect();
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
    Ok((
        with_lines.into_iter().zip(cleaned).collect(),
        fit_curves,
        lines_out,
    ))
}

/// What the warnings of [`analyse_log`] are drawn from.
struct Found<'a> {
    keep: &'a [usize],
    data: &'a [&'a [f64]],
    units: &'a [String],
    results: &'a [ChannelResult],
    lines: &'a [ChannelLines],
    noise: Option<&'a NoiseModel>,
    allan_fit: bool,
}

impl Found<'_> {
    /// Stationarity, unit plausibility (rate data), lines found, the χ²_red verdict of an
    /// Allan fit and the record length each fitted term needs; prefixed with the source.
    fn warnings(&self, log: &ImuLog, data_type: DataType) -> Vec<String> {
        let mut warnings = Vec::new();
        for (&i, d) in self.keep.iter().zip(self.data) {
            let name = &log.channels[i].name;
            let rates: Vec<f64>;
            let y: &[f64] = match data_type {
                DataType::Frequency => d,
                DataType::Phase => {
                    rates = d.windows(2).map(|w| (w[1] - w[0]) / log.tau0_s).collect();
                    &rates
                }
            };
            warnings.extend(checks::stationarity_warning(name, y, log.tau0_s));
        }
        if data_type == DataType::Frequency {
            let inputs: Vec<plausibility::ChannelInput<'_>> = self
                .keep
                .iter()
                .zip(self.data)
                .map(|(&i, d)| plausibility::ChannelInput {
                    name: &log.channels[i].name,
                    quantity: log.channels[i].quantity,
                    stated_unit: &log.channels[i].source_unit,
                    values: d,
                })
                .collect();
            warnings.extend(plausibility::unit_warnings(&inputs, log.tau0_s));
        }
        for l in self.lines {
            let unit = self
                .keep
                .iter()
                .position(|&i| log.channels[i].name == l.channel)
                .map_or("", |k| self.units[k].as_str());
            warnings.push(l.describe(unit));
        }
        if let Some(model) = self.noise
            && self.allan_fit
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
        if let Some(model) = self.noise {
            let record_s = log.len() as f64 * log.tau0_s;
            for (c, r) in model.channels.iter().zip(self.results) {
                let taus: Vec<f64> = r.points.iter().map(|p| p.tau).collect();
                warnings.extend(checks::record_length_warnings(
                    &c.name, &c.fit, &taus, record_s,
                ));
            }
        }
        warnings
            .into_iter()
            .map(|w| format!("{}: {w}", log.source))
            .collect()
    }
}

/// The curves of the `--json` document: per channel `name`, `estimator`, `unit`, `tau0`,
/// `confidence`, and per point `tau`, `m`, `n`, `dev`, `dev_lo`, `dev_hi`, `alpha`, `edf`,
/// `rate_acf1`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CurvesDocument<'a> {
    /// The curves.
    pub results: &'a [ChannelResult],
    /// Unit of each curve's channel (same order).
    pub units: &'a [String],
}

impl Serialize for CurvesDocument<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(
            self.results
                .iter()
                .zip(self.units)
                .map(|(r, unit)| CurveDocument { r, unit }),
        )
    }
}

/// One channel of [`CurvesDocument`].
struct CurveDocument<'a> {
    r: &'a ChannelResult,
    unit: &'a str,
}

impl Serialize for CurveDocument<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let r = self.r;
        let col = |f: fn(&super::DevPoint) -> f64| -> Vec<f64> { r.points.iter().map(f).collect() };
        let mut st = s.serialize_struct("Curve", 14)?;
        st.serialize_field("name", &r.name)?;
        st.serialize_field("estimator", r.estimator.name())?;
        st.serialize_field("unit", self.unit)?;
        st.serialize_field("tau0", &r.tau0_s)?;
        st.serialize_field("confidence", &r.confidence)?;
        st.serialize_field("tau", &col(|p| p.tau))?;
        st.serialize_field("m", &r.points.iter().map(|p| p.m).collect::<Vec<_>>())?;
        st.serialize_field("n", &r.points.iter().map(|p| p.n).collect::<Vec<_>>())?;
        st.serialize_field("dev", &col(|p| p.dev))?;
        st.serialize_field("dev_lo", &r.dev_lo)?;
        st.serialize_field("dev_hi", &r.dev_hi)?;
        st.serialize_field("alpha", &r.alpha)?;
        st.serialize_field("edf", &r.edf)?;
        st.serialize_field("rate_acf1", &r.rate_acf1)?;
        st.end()
    }
}

/// A noise model in the `--json` document: the model as saved, each channel's `fit`
/// of an Allan fit carrying its χ²_red verdict (`chi2_verdict`, `chi2_warning`,
/// [`chi2_verdict`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct NoiseDocument<'a> {
    /// The model.
    pub model: &'a NoiseModel,
    /// Whether it is an Allan fit (the verdict applies).
    pub allan_fit: bool,
}

impl Serialize for NoiseDocument<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if !self.allan_fit {
            return self.model.serialize(s);
        }
        let m = self.model;
        let mut st = s.serialize_struct("NoiseModel", 5)?;
        st.serialize_field("format_version", &m.format_version)?;
        st.serialize_field("source_file", &m.source_file)?;
        st.serialize_field("sample_rate_hz", &m.sample_rate_hz)?;
        st.serialize_field("estimator", &m.estimator)?;
        let channels: Vec<ChannelVerdict<'_>> = m
            .channels
            .iter()
            .map(|c| {
                let (verdict, warning) = chi2_verdict(c.fit.chi2_reduced);
                ChannelVerdict {
                    name: &c.name,
                    quantity: c.quantity,
                    unit: &c.unit,
                    fit: FitVerdict {
                        fit: &c.fit,
                        chi2_verdict: verdict,
                        chi2_warning: warning,
                    },
                    slope_readings: &c.slope_readings,
                    display: &c.display,
                    discrete: &c.discrete,
                    gmwm: &c.gmwm,
                }
            })
            .collect();
        st.serialize_field("channels", &channels)?;
        st.end()
    }
}

/// A channel of [`NoiseDocument`]: [`ChannelNoise`]'s fields, the fit with its verdict.
#[derive(Serialize)]
struct ChannelVerdict<'a> {
    name: &'a str,
    quantity: Quantity,
    unit: &'a str,
    fit: FitVerdict<'a>,
    slope_readings: &'a Option<super::fit::SlopeReadings>,
    display: &'a [super::noise_model::DisplayValue],
    discrete: &'a super::noise_model::DiscreteNoise,
    #[serde(skip_serializing_if = "Option::is_none")]
    gmwm: &'a Option<gmwm::GmwmFit>,
}

/// A fit and its χ²_red verdict.
#[derive(Serialize)]
struct FitVerdict<'a> {
    #[serde(flatten)]
    fit: &'a super::fit::NoiseFit,
    chi2_verdict: &'a str,
    chi2_warning: bool,
}

impl Serialize for LogAnalysis {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let gmwm = !self.gmwm.is_empty();
        let mut st = s.serialize_struct("LogAnalysis", if gmwm { 5 } else { 4 })?;
        st.serialize_field(
            "channels",
            &CurvesDocument {
                results: &self.results,
                units: &self.units,
            },
        )?;
        st.serialize_field(
            "noise",
            &self.noise.as_ref().map(|model| NoiseDocument {
                model,
                allan_fit: !gmwm,
            }),
        )?;
        st.serialize_field("warnings", &self.warnings)?;
        st.serialize_field("lines", &self.lines)?;
        if gmwm {
            st.serialize_field("gmwm", &self.gmwm)?;
        }
        st.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Channel;
    use crate::sim::noise::{StaticNoiseConfig, generate_channels};

    /// A 2-h, 10 Hz static log: three gyro and three accelerometer channels of white
    /// noise plus rate random walk, a temperature and a channel of another quantity.
    fn static_log() -> ImuLog {
        let cfg = |white: f64| StaticNoiseConfig {
            sample_rate_hz: 10.0,
            duration_s: 7200.0,
            white,
            rate_random_walk: white * 1e-2,
            ..StaticNoiseConfig::default()
        };
        let cfgs = [1e-3, 1.1e-3, 0.9e-3, 2e-3, 2.1e-3, 1.9e-3].map(cfg);
        let data = generate_channels(&cfgs, 7).expect("valid noise configuration");
        let n = data[0].len();
        let mut channels: Vec<Channel> = data
            .into_iter()
            .enumerate()
            .map(|(k, values)| {
                let q = if k < 3 {
                    Quantity::AngularRate
                } else {
                    Quantity::SpecificForce
                };
                Channel {
                    name: format!("ch{k}"),
                    quantity: q,
                    source_unit: q.si_unit().into(),
                    values,
                }
            })
            .collect();
        channels.push(Channel {
            name: "temp".into(),
            quantity: Quantity::Temperature,
            source_unit: "degC".into(),
            values: vec![25.0; n],
        });
        channels.push(Channel {
            name: "pressure".into(),
            quantity: Quantity::Other,
            source_unit: "hPa".into(),
            values: (0..n).map(|i| 1000.0 + (i % 7) as f64 * 0.01).collect(),
        });
        ImuLog::new("static-test", None, 0.1, channels)
    }

    fn opts(channels: ChannelSelection) -> LogAnalysisOptions {
        LogAnalysisOptions {
            channels,
            ..LogAnalysisOptions::allan(
                AnalysisConfig {
                    taus: TauSpec::Log(40),
                    ..AnalysisConfig::default()
                },
                Some(FitConfig::IEEE_952),
            )
        }
    }

    #[test]
    fn channel_selection_and_units() {
        let log = static_log();
        let all = analyse_log(&log, &opts(ChannelSelection::AllButTemperature)).unwrap();
        let names: Vec<&str> = all.results.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(
            names,
            ["ch0", "ch1", "ch2", "ch3", "ch4", "ch5", "pressure"]
        );
        assert_eq!(all.units[0], "rad/s");
        assert_eq!(all.units[6], "hPa", "another quantity keeps the log's unit");
        let inertial = analyse_log(&log, &opts(ChannelSelection::Inertial)).unwrap();
        assert_eq!(inertial.results.len(), 6);
        // The same channel gives the same curve whatever else is analysed (the points:
        // the lag-1 autocorrelations hold NaN where too few blocks exist).
        for (a, b) in inertial.results.iter().zip(&all.results) {
            assert_eq!(a.points, b.points);
            assert_eq!(a.dev_hi, b.dev_hi);
        }
        let model = inertial
            .noise
            .as_ref()
            .expect("the Allan fit was asked for");
        assert_eq!(model.channels.len(), 6);
        // The simulated white-noise density, N = 1e-3 rad/√s, recovered within 10 %.
        let n = model.channels[0]
            .fit
            .white
            .expect("white noise resolved")
            .value;
        assert!((n / 1e-3 - 1.0).abs() < 0.1, "N = {n}");
        assert_eq!(inertial.fit_curves.len(), 6);
    }

    #[test]
    fn refuses_a_log_of_temperatures_and_a_zero_scale() {
        let mut log = static_log();
        let e = analyse_log(
            &log,
            &LogAnalysisOptions {
                scale: Some(0.0),
                ..opts(ChannelSelection::Inertial)
            },
        )
        .unwrap_err();
        assert!(matches!(e, LogAnalysisError::Scale(_)), "{e}");
        log.channels.retain(|c| c.quantity == Quantity::Temperature);
        let e = analyse_log(&log, &opts(ChannelSelection::AllButTemperature)).unwrap_err();
        assert!(
            e.to_string().contains("static-test: no data channel"),
            "{e}"
        );
    }

    /// The noise model of the document is the model as saved, each Allan fit carrying
    /// its χ² verdict: a field added to the model cannot go missing from the document.
    #[test]
    fn json_document_is_the_model_with_the_verdict() {
        let log = static_log();
        let out = analyse_log(&log, &opts(ChannelSelection::Inertial)).unwrap();
        let doc = serde_json::to_value(&out).unwrap();
        let model = out.noise.as_ref().unwrap();
        let mut want = serde_json::to_value(model).unwrap();
        for (c, m) in want["channels"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .zip(&model.channels)
        {
            let (verdict, warn) = chi2_verdict(m.fit.chi2_reduced);
            c["fit"]["chi2_verdict"] = verdict.into();
            c["fit"]["chi2_warning"] = warn.into();
        }
        assert_eq!(doc["noise"], want);
        let keys: Vec<&String> = doc.as_object().unwrap().keys().collect();
        assert_eq!(keys, ["channels", "lines", "noise", "warnings"]);
        let ch = &doc["channels"][0];
        assert_eq!(ch["name"], "ch0");
        assert_eq!(ch["estimator"], "oadev");
        assert_eq!(
            ch["tau"].as_array().unwrap().len(),
            out.results[0].points.len()
        );
        assert_eq!(
            ch["dev_hi"],
            serde_json::to_value(&out.results[0].dev_hi).unwrap()
        );
    }
}

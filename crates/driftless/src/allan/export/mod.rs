//! A noise model written out in the units and convention of the estimators people use:
//! Kalibr, OpenVINS, VINS-Fusion / VINS-Mono, KF-GINS, PX4 EKF2 and ArduPilot EKF3; and
//! Kalibr's `imu.yaml` read back ([`kalibr::KalibrImu`]).
//!
//! The library builds the text ([`export`]); writing it is the caller's job. Everything
//! here starts from the fitted IEEE Std 952-1997 terms of [`NoiseModel`] in SI: the white
//! noise density N \[u·√s = u/√Hz] and the rate random walk K \[u/√s = u/s/√Hz], with
//! u = rad/s (gyro) or m/s² (accelerometer).
//!
//! # What each consumer wants
//!
//! f = the model's sample rate (the log's IMU rate); f_ekf = the autopilot filter's
//! prediction rate (PX4: 1/`EKF2_PREDICT_US` = 100 Hz by default; ArduPilot EKF3:
//! 1/`EKF_TARGET_DT` = 1/0.012 s = 83.3 Hz). "per step" means per filter time step Δt.
//!
//! | consumer | key | unit | from | continuous or per step | source of the convention |
//! |---|---|---|---|---|---|
//! | Kalibr `imu.yaml` | `gyroscope_noise_density`, `accelerometer_noise_density` | rad/s/√Hz, m/s²/√Hz | N | continuous (Kalibr divides by √Δt itself) | Kalibr wiki "IMU Noise Model" |
//! | Kalibr | `gyroscope_random_walk`, `accelerometer_random_walk` | rad/s²/√Hz, m/s³/√Hz | K (see below) | continuous | same |
//! | Kalibr | `update_rate` | Hz | f | – | same |
//! | OpenVINS `kalibr_imu_chain.yaml` `imu0:` | same four keys | same | same | continuous (its propagator divides by Δt) | OpenVINS `config/*/kalibr_imu_chain.yaml` |
//! | VINS-Fusion / VINS-Mono | `gyr_n`, `acc_n` | rad/s, m/s² | N·√f | per IMU sample: the pre-integration adds `V·diag(acc_n²…)·Vᵀ` with V ∝ Δt | `integration_base.h` (`midPointIntegration`) |
//! | VINS | `gyr_w`, `acc_w` | rad/s², m/s³ | K·√f | per IMU sample: bias block of V is I·Δt | same |
//! | KF-GINS `imunoise:` | `arw`, `vrw` | deg/√h, m/s/√h | N / (π/180/60), N·60 | continuous | KF-GINS `dataset/kf-gins.yaml`, our reader [`crate::io::nav::kfgins_config`] |
//! | KF-GINS | `gbstd`, `abstd` | deg/h, mGal | Gauss-Markov σ_b (see below) / (π/180/3600), σ_b / 1e-5 | stationary σ | same |
//! | KF-GINS | `corrtime` | h | T_c / 3600, the shortest of all channels | – | same |
//! | KF-GINS | `gsstd`, `asstd` | ppm | 0: a static record does not measure scale-factor stability (flagged) | – | same |
//! | PX4 EKF2 `.params` | `EKF2_GYR_NOISE`, `EKF2_ACC_NOISE` | rad/s, m/s² | N·√f_ekf | per step: `d_ang_var = (Δt·EKF2_GYR_NOISE)²` | PX4 `ekf2/EKF/covariance.cpp` `predictCovariance` |
//! | PX4 | `EKF2_GYR_B_NOISE`, `EKF2_ACC_B_NOISE` | rad/s², m/s³ | K·√f_ekf | per step: bias variance += (Δt·p)² | same |
//! | ArduPilot EKF3 `.param` | `EK3_GYRO_P_NSE`, `EK3_ACC_P_NSE` | rad/s, m/s² | N·√f_ekf | per step: `daxVar = (dt·_gyrNoise)²` | `AP_NavEKF3_core.cpp` `CovariancePrediction` |
//! | ArduPilot | `EK3_GBIAS_P_NSE`, `EK3_ABIAS_P_NSE` | rad/s², m/s³ | K·√f_ekf | per step: delta-angle bias σ = dt²·p, i.e. rate-bias variance += (dt·p)² | same |
//!
//! Why N·√f for a per-step σ: white rate noise of density N integrates over Δt to an
//! angle (velocity) variance N²·Δt; a filter that adds (Δt·σ)² per step matches it for
//! σ = N/√Δt. Likewise a bias random walk of density K grows by K²·Δt per step, which
//! (Δt·p)² matches for p = K/√Δt. The autopilots integrate the IMU into delta angles at
//! their own prediction rate, so f_ekf — not the sensor rate — enters there.
//!
//! # Which Allan term is the "random walk"
//!
//! Every consumer above models the bias as a random walk (Kalibr, OpenVINS, VINS, PX4,
//! ArduPilot) or as one first-order Gauss-Markov process (KF-GINS). The random walk is the
//! **rate random walk K** — not the bias instability B, which is a flicker floor in rate
//! units and has no random-walk density. When K was not detected the export still needs a
//! value, and uses the **largest** of (a conservative bound, flagged by a comment on the
//! value's line):
//!
//! * K's upper limit from the fit (the true K lies below it);
//! * the driving noise of the bias instability's Gauss-Markov stand-in, σ_b·√(2/T_c)
//!   ([`crate::allan::noise_model::DiscreteNoise::bias_instability_gm`]): a Gauss-Markov
//!   process (σ_b, T_c) is driven by white noise of PSD q = 2σ_b²/T_c and, for times short
//!   against T_c, wanders like a random walk of that density — and without bound beyond
//!   it, so the random walk over-covers the bounded process (Gelb 1974, §4.4);
//!   When the floor runs on past the fitted range (no minimum inside it) the stand-in's
//!   Allan peak is put at the range's end, T_c = τ_max/1.89: the real T_c is longer and
//!   its driving noise smaller, so this too is a bound;
//! * the same σ·√(2/T_c) of a fitted Gauss-Markov term.
//!
//! With none of these the value is missing and the export fails naming it, unless given
//! ([`GivenValues`]). A detected K is used as it is.
//!
//! KF-GINS's bias is a Gauss-Markov process: its σ and T_c are those of the fitted
//! Gauss-Markov term if there is one, else of the bias instability's stand-in. KF-GINS has
//! one correlation time for all six biases; the shortest is written (the largest driving
//! noise 2σ²/T_c for each σ).
//!
//! # Axes, missing quantities
//!
//! The single-value formats take the largest value over the axes of a quantity (the
//! comment names the channel). KF-GINS takes per-axis values when a quantity has exactly
//! the three channels ending in x, y and z, each with the term; otherwise the largest on
//! all three axes. A format that needs both sensors (all but PX4 and ArduPilot) fails
//! naming the missing quantity unless its values are given; PX4 and ArduPilot get the
//! parameters that exist and a comment naming the ones left out.
//!
//! # Inflation
//!
//! The values are those of a static record. Moving platforms see more (vibration,
//! temperature, unmodelled scale and misalignment): Kalibr's maintainers advise inflating
//! the densities (by 10 or more) for calibration, and the autopilot defaults (PX4/ArduPilot
//! `0.015 rad/s`, `0.35 m/s²`) are tens of times the static values of common MEMS sensors.
//! Nothing is inflated here; each file says so, with the default for comparison.

mod formats;
pub mod kalibr;

use std::fmt;
use std::str::FromStr;

use super::fit::{BIAS_AVAR_COEF, TermKind, gauss_markov_avar_peak};
use super::noise_model::{ChannelNoise, NoiseModel, Quantity, discrete_noise};

pub use formats::yaml_float;

/// The formats [`export`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExportFormat {
    /// Kalibr `imu.yaml`.
    Kalibr,
    /// OpenVINS `kalibr_imu_chain.yaml` (`imu0:` block, OpenCV `%YAML:1.0` header).
    OpenVins,
    /// VINS-Fusion / VINS-Mono config keys `acc_n`, `gyr_n`, `acc_w`, `gyr_w`.
    Vins,
    /// KF-GINS `imunoise:` block.
    KfGins,
    /// PX4 EKF2 parameters, QGroundControl `.params` file.
    Px4,
    /// ArduPilot EKF3 parameters, `.param` file (`NAME,VALUE`).
    ArduPilot,
}

impl ExportFormat {
    /// All formats, in CLI order.
    pub const ALL: [ExportFormat; 6] = [
        ExportFormat::Kalibr,
        ExportFormat::OpenVins,
        ExportFormat::Vins,
        ExportFormat::KfGins,
        ExportFormat::Px4,
        ExportFormat::ArduPilot,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Kalibr => "kalibr",
            ExportFormat::OpenVins => "openvins",
            ExportFormat::Vins => "vins",
            ExportFormat::KfGins => "kfgins",
            ExportFormat::Px4 => "px4",
            ExportFormat::ArduPilot => "ardupilot",
        }
    }
}

impl FromStr for ExportFormat {
    type Err = ExportError;
    fn from_str(s: &str) -> Result<Self, ExportError> {
        ExportFormat::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| ExportError::UnknownFormat(s.to_string()))
    }
}

impl fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Errors building an export.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// A format name that is not one of [`ExportFormat::ALL`].
    #[error(
        "unknown export format {0:?}: expected kalibr, openvins, vins, kfgins, px4 or ardupilot"
    )]
    UnknownFormat(String),
    /// A value the format needs is neither in the model nor given.
    #[error("{format} needs {key} ({unit}): {why}; give it with --export-set {key}=VALUE")]
    Missing {
        /// The format.
        format: ExportFormat,
        /// The key of [`GivenValues`] that would supply it.
        key: &'static str,
        /// Its SI unit.
        unit: &'static str,
        /// Why the model does not have it.
        why: String,
    },
    /// A given value that cannot be used.
    #[error("export value {spec:?}: {why}")]
    BadValue {
        /// The `KEY=VALUE` text.
        spec: String,
        /// What is wrong.
        why: String,
    },
}

/// Where an exported value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ValueSource {
    /// The fitted (detected) term.
    Fitted,
    /// The upper limit of a term the fit did not detect.
    UpperLimit,
    /// σ_b·√(2/T_c) of the bias instability's Gauss-Markov stand-in (random walk), or that
    /// stand-in itself (Gauss-Markov bias).
    BiasInstability {
        /// Correlation time of the stand-in, s.
        tau_c_s: f64,
    },
    /// As [`ValueSource::BiasInstability`], but the floor runs on past the fitted range:
    /// the stand-in's Allan peak is placed at the range's end, T_c = τ_max/1.89 (the
    /// shortest correlation time the record allows: a bound).
    BiasInstabilityRangeEnd {
        /// Correlation time of the stand-in, s.
        tau_c_s: f64,
    },
    /// σ·√(2/T_c) of the fitted Gauss-Markov term (random walk), or the term itself.
    GaussMarkov {
        /// Its correlation time, s.
        tau_c_s: f64,
    },
    /// Given by the user ([`GivenValues`]).
    Given,
}

impl ValueSource {
    /// Whether the value is a bound or a stand-in rather than the fitted term (flagged in
    /// the output).
    pub fn is_flagged(self) -> bool {
        !matches!(self, ValueSource::Fitted)
    }
}

/// One exported value, SI, with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Exported {
    /// The value.
    pub value: f64,
    /// Where it came from.
    pub source: ValueSource,
    /// The channel it came from (None when given).
    pub channel: Option<String>,
}

/// A bias modelled as a first-order Gauss-Markov process (KF-GINS).
#[derive(Clone, Debug, PartialEq)]
pub struct BiasProcess {
    /// Stationary σ_b, u.
    pub sigma: f64,
    /// Correlation time T_c, s.
    pub tau_c_s: f64,
    /// Where σ_b and T_c came from.
    pub source: ValueSource,
    /// The channel (None when given).
    pub channel: Option<String>,
}

/// The exportable values of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisNoise {
    /// Channel name.
    pub channel: String,
    /// White noise density N, u/√Hz.
    pub white_density: Option<Exported>,
    /// Bias random-walk density, u/s/√Hz (see the module docs for the rule).
    pub random_walk_density: Option<Exported>,
    /// Gauss-Markov bias.
    pub bias: Option<BiasProcess>,
}

/// The exportable values of one quantity (gyro or accelerometer).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SensorNoise {
    /// Its channels, in model order.
    pub axes: Vec<AxisNoise>,
    /// Largest white noise density over the axes (or given), u/√Hz.
    pub white_density: Option<Exported>,
    /// Largest random-walk density over the axes (or given), u/s/√Hz.
    pub random_walk_density: Option<Exported>,
    /// Gauss-Markov bias: largest σ_b and shortest T_c over the axes (or given).
    pub bias: Option<BiasProcess>,
}

/// Everything the writers need, resolved from a model by [`imu_noise`].
#[derive(Clone, Debug, PartialEq)]
pub struct ImuNoise {
    /// IMU sample rate, Hz.
    pub sample_rate_hz: f64,
    /// The log the model was fitted from.
    pub source_file: Option<String>,
    /// Gyro values (rad/s units).
    pub gyro: SensorNoise,
    /// Accelerometer values (m/s² units).
    pub accel: SensorNoise,
    /// Bias correlation time given by the user, s (KF-GINS).
    pub given_corr_time_s: Option<f64>,
}

/// Values the user supplies, SI (continuous-time densities as in Kalibr). Each replaces
/// the model's value of the quantity; they also fill a quantity the model lacks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GivenValues {
    /// `gyroscope_noise_density`, rad/s/√Hz.
    pub gyro_noise_density: Option<f64>,
    /// `gyroscope_random_walk`, rad/s²/√Hz.
    pub gyro_random_walk: Option<f64>,
    /// `accelerometer_noise_density`, m/s²/√Hz.
    pub accel_noise_density: Option<f64>,
    /// `accelerometer_random_walk`, m/s³/√Hz.
    pub accel_random_walk: Option<f64>,
    /// `gyroscope_bias_sigma` (Gauss-Markov σ_b, KF-GINS), rad/s.
    pub gyro_bias_sigma: Option<f64>,
    /// `accelerometer_bias_sigma`, m/s².
    pub accel_bias_sigma: Option<f64>,
    /// `bias_correlation_time` (KF-GINS), s.
    pub bias_corr_time_s: Option<f64>,
}

/// The keys of [`GivenValues`] with their SI units.
pub(crate) const GIVEN_KEYS: [(&str, &str); 7] = [
    ("gyroscope_noise_density", "rad/s/sqrt(Hz)"),
    ("gyroscope_random_walk", "rad/s^2/sqrt(Hz)"),
    ("accelerometer_noise_density", "m/s^2/sqrt(Hz)"),
    ("accelerometer_random_walk", "m/s^3/sqrt(Hz)"),
    ("gyroscope_bias_sigma", "rad/s"),
    ("accelerometer_bias_sigma", "m/s^2"),
    ("bias_correlation_time", "s"),
];

fn unit_of(key: &str) -> &'static str {
    GIVEN_KEYS
        .iter()
        .find(|(k, _)| *k == key)
        .map_or("", |(_, u)| u)
}

impl FromStr for GivenValues {
    type Err = ExportError;
    /// `KEY=VALUE[,KEY=VALUE…]` with the keys of `GIVEN_KEYS`, SI values > 0.
    fn from_str(s: &str) -> Result<Self, ExportError> {
        let mut g = GivenValues::default();
        for item in s.split(',').map(str::trim).filter(|t| !t.is_empty()) {
            let bad = |why: String| ExportError::BadValue {
                spec: item.to_string(),
                why,
            };
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| bad("expected KEY=VALUE".into()))?;
            let key = key.trim();
            let v: f64 = value
                .trim()
                .parse()
                .map_err(|_| bad(format!("{:?} is not a number", value.trim())))?;
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(format!("{key} must be a finite value > 0")));
            }
            let slot = match key {
                "gyroscope_noise_density" => &mut g.gyro_noise_density,
                "gyroscope_random_walk" => &mut g.gyro_random_walk,
                "accelerometer_noise_density" => &mut g.accel_noise_density,
                "accelerometer_random_walk" => &mut g.accel_random_walk,
                "gyroscope_bias_sigma" => &mut g.gyro_bias_sigma,
                "accelerometer_bias_sigma" => &mut g.accel_bias_sigma,
                "bias_correlation_time" => &mut g.bias_corr_time_s,
                _ => {
                    let keys: Vec<&str> = GIVEN_KEYS.iter().map(|(k, _)| *k).collect();
                    return Err(bad(format!(
                        "unknown key {key:?}; expected one of {}",
                        keys.join(", ")
                    )));
                }
            };
            *slot = Some(v);
        }
        Ok(g)
    }
}

/// Options of the writers.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Kalibr / OpenVINS `rostopic`.
    pub rostopic: String,
    /// PX4 EKF2 prediction rate, Hz (1/`EKF2_PREDICT_US`).
    pub px4_filter_rate_hz: f64,
    /// ArduPilot EKF3 prediction rate, Hz (1/`EKF_TARGET_DT`).
    pub ardupilot_filter_rate_hz: f64,
}

/// PX4 EKF2's default prediction period `EKF2_PREDICT_US` = 10 000 µs.
pub(crate) const PX4_FILTER_RATE_HZ: f64 = 100.0;
/// ArduPilot EKF3's `EKF_TARGET_DT` = 0.012 s (the filter runs no faster).
pub(crate) const ARDUPILOT_FILTER_RATE_HZ: f64 = 1.0 / 0.012;

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            rostopic: "/imu0".into(),
            px4_filter_rate_hz: PX4_FILTER_RATE_HZ,
            ardupilot_filter_rate_hz: ARDUPILOT_FILTER_RATE_HZ,
        }
    }
}

/// The exportable values of one channel (see the module docs for the rules).
pub(crate) fn axis_noise(ch: &ChannelNoise, sample_rate_hz: f64) -> AxisNoise {
    let fit = &ch.fit;
    let channel = Some(ch.name.clone());
    let upper = |k: TermKind| {
        fit.not_detected
            .iter()
            .find(|u| u.term == k)
            .map(|u| u.upper)
            .filter(|u| u.is_finite() && *u > 0.0)
    };
    let exported = |value: f64, source: ValueSource| Exported {
        value,
        source,
        channel: channel.clone(),
    };
    let white_density = match fit.white {
        Some(t) => Some(exported(t.value, ValueSource::Fitted)),
        None => upper(TermKind::White).map(|u| exported(u, ValueSource::UpperLimit)),
    };
    // (σ_b, T_c, whether T_c was placed at the end of the fitted range).
    let stand_in = discrete_noise(fit, sample_rate_hz)
        .bias_instability_gm
        .map(|g| (g.sigma, g.tau_c_s, false))
        .or_else(|| {
            // The floor runs on past the fitted range: the stand-in whose Allan peak lies
            // at the range's end has the shortest correlation time the record allows, and
            // so the largest driving noise σ_b·√(2/T_c).
            let b = fit.bias_instability?.value;
            let tau_max = fit.fit_range?.tau_max_s;
            let (u_peak, peak) = gauss_markov_avar_peak();
            Some((
                (BIAS_AVAR_COEF * b * b / peak).sqrt(),
                tau_max / u_peak,
                true,
            ))
        })
        .filter(|&(s, t, _)| s > 0.0 && t.is_finite() && t > 0.0);
    let stand_in_source = |tau_c_s: f64, range_end: bool| {
        if range_end {
            ValueSource::BiasInstabilityRangeEnd { tau_c_s }
        } else {
            ValueSource::BiasInstability { tau_c_s }
        }
    };
    let gm = fit
        .gauss_markov
        .filter(|g| g.sigma.value > 0.0 && g.tau_c_s.value > 0.0);
    let random_walk_density = match fit.rate_random_walk {
        Some(k) => Some(exported(k.value, ValueSource::Fitted)),
        None => {
            let mut candidates = Vec::new();
            if let Some(u) = upper(TermKind::RateRandomWalk) {
                candidates.push(exported(u, ValueSource::UpperLimit));
            }
            if let Some((s, t, end)) = stand_in {
                candidates.push(exported(s * (2.0 / t).sqrt(), stand_in_source(t, end)));
            }
            if let Some(g) = gm {
                let (s, t) = (g.sigma.value, g.tau_c_s.value);
                candidates.push(exported(
                    s * (2.0 / t).sqrt(),
                    ValueSource::GaussMarkov { tau_c_s: t },
                ));
            }
            candidates
                .into_iter()
                .max_by(|a, b| a.value.total_cmp(&b.value))
        }
    };
    let bias = match (gm, stand_in) {
        (Some(g), _) => Some(BiasProcess {
            sigma: g.sigma.value,
            tau_c_s: g.tau_c_s.value,
            source: ValueSource::GaussMarkov {
                tau_c_s: g.tau_c_s.value,
            },
            channel: channel.clone(),
        }),
        (None, Some((s, t, end))) => Some(BiasProcess {
            sigma: s,
            tau_c_s: t,
            source: stand_in_source(t, end),
            channel: channel.clone(),
        }),
        (None, None) => None,
    };
    AxisNoise {
        channel: ch.name.clone(),
        white_density,
        random_walk_density,
        bias,
    }
}

fn largest(values: impl Iterator<Item = Exported>) -> Option<Exported> {
    values.max_by(|a, b| a.value.total_cmp(&b.value))
}

fn sensor_noise(
    axes: Vec<AxisNoise>,
    white: Option<f64>,
    random_walk: Option<f64>,
    bias_sigma: Option<f64>,
    corr_time_s: Option<f64>,
) -> SensorNoise {
    let given_value = |v: f64| Exported {
        value: v,
        source: ValueSource::Given,
        channel: None,
    };
    let white_density = white
        .map(given_value)
        .or_else(|| largest(axes.iter().filter_map(|a| a.white_density.clone())));
    let random_walk_density = random_walk
        .map(given_value)
        .or_else(|| largest(axes.iter().filter_map(|a| a.random_walk_density.clone())));
    let fitted_bias = {
        let mut it = axes.iter().filter_map(|a| a.bias.clone());
        it.next().map(|first| {
            it.fold(first, |acc, b| {
                let tau = acc.tau_c_s.min(b.tau_c_s);
                let mut keep = if b.sigma > acc.sigma { b } else { acc };
                keep.tau_c_s = tau;
                keep
            })
        })
    };
    let bias = match bias_sigma {
        Some(s) => {
            let tau = corr_time_s.or(fitted_bias.as_ref().map(|b| b.tau_c_s));
            tau.map(|t| BiasProcess {
                sigma: s,
                tau_c_s: t,
                source: ValueSource::Given,
                channel: None,
            })
        }
        None => fitted_bias,
    };
    SensorNoise {
        axes,
        white_density,
        random_walk_density,
        bias,
    }
}

/// Resolve the exportable values of `model`, with `given` replacing or filling values.
pub fn imu_noise(model: &NoiseModel, given: &GivenValues) -> ImuNoise {
    let axes = |q: Quantity| -> Vec<AxisNoise> {
        model
            .channels
            .iter()
            .filter(|c| c.quantity == q)
            .map(|c| axis_noise(c, model.sample_rate_hz))
            .collect()
    };
    ImuNoise {
        sample_rate_hz: model.sample_rate_hz,
        source_file: model.source_file.clone(),
        gyro: sensor_noise(
            axes(Quantity::AngularRate),
            given.gyro_noise_density,
            given.gyro_random_walk,
            given.gyro_bias_sigma,
            given.bias_corr_time_s,
        ),
        accel: sensor_noise(
            axes(Quantity::SpecificForce),
            given.accel_noise_density,
            given.accel_random_walk,
            given.accel_bias_sigma,
            given.bias_corr_time_s,
        ),
        given_corr_time_s: given.bias_corr_time_s,
    }
}

/// Which of the two sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sensor {
    Gyro,
    Accel,
}

impl Sensor {
    pub(crate) fn noise(self, imu: &ImuNoise) -> &SensorNoise {
        match self {
            Sensor::Gyro => &imu.gyro,
            Sensor::Accel => &imu.accel,
        }
    }
    fn word(self) -> &'static str {
        match self {
            Sensor::Gyro => "gyroscope",
            Sensor::Accel => "accelerometer",
        }
    }
    fn quantity_word(self) -> &'static str {
        match self {
            Sensor::Gyro => "angular-rate (gyro)",
            Sensor::Accel => "specific-force (accelerometer)",
        }
    }
}

/// Which value of a sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Slot {
    White,
    RandomWalk,
    Bias,
}

impl Slot {
    fn key(self, s: Sensor) -> &'static str {
        match (s, self) {
            (Sensor::Gyro, Slot::White) => "gyroscope_noise_density",
            (Sensor::Gyro, Slot::RandomWalk) => "gyroscope_random_walk",
            (Sensor::Gyro, Slot::Bias) => "gyroscope_bias_sigma",
            (Sensor::Accel, Slot::White) => "accelerometer_noise_density",
            (Sensor::Accel, Slot::RandomWalk) => "accelerometer_random_walk",
            (Sensor::Accel, Slot::Bias) => "accelerometer_bias_sigma",
        }
    }
}

/// Why a value is missing, for [`ExportError::Missing`].
pub(crate) fn missing(format: ExportFormat, s: Sensor, slot: Slot, imu: &ImuNoise) -> ExportError {
    let key = slot.key(s);
    let n = s.noise(imu);
    let why = if n.axes.is_empty() {
        format!(
            "the noise model has no {} channel, and {format} needs both the gyroscope's and \
             the accelerometer's values",
            s.quantity_word()
        )
    } else {
        let what = match slot {
            Slot::White => "a white noise term N (fitted or as an upper limit)".to_string(),
            Slot::RandomWalk => "a rate random walk K (fitted or as an upper limit), a bias \
                                 instability B or a Gauss-Markov term"
                .to_string(),
            Slot::Bias => "a Gauss-Markov term or a bias instability B (the bias is a \
                           Gauss-Markov process there; a random walk K alone fixes neither \
                           its sigma nor its correlation time)"
                .to_string(),
        };
        format!("no {} channel of the model has {what}", s.word())
    };
    ExportError::Missing {
        format,
        key,
        unit: unit_of(key),
        why,
    }
}

/// The text of `format` for `imu` (see the module docs for every mapping).
pub fn export(
    format: ExportFormat,
    imu: &ImuNoise,
    opts: &ExportOptions,
) -> Result<String, ExportError> {
    match format {
        ExportFormat::Kalibr => formats::kalibr(imu, opts),
        ExportFormat::OpenVins => formats::openvins(imu, opts),
        ExportFormat::Vins => formats::vins(imu),
        ExportFormat::KfGins => formats::kfgins(imu),
        ExportFormat::Px4 => formats::px4(imu, opts),
        ExportFormat::ArduPilot => formats::ardupilot(imu, opts),
    }
}

#[cfg(test)]
mod tests;

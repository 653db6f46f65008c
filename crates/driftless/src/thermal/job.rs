//! Thermal calibration of read logs, end to end — what `driftless thermal soak` and
//! `driftless thermal ramp` run: the checks that refuse a log before the long work
//! ([`soak_precheck`], [`ramp_precheck`]), the triads or channels taken from the log, the
//! calibration ([`super::soak`], [`super::ramp`]) and the compensation model with its id.

use super::FitOptions;
use super::check::{CheckOptions, FindingKind, Impact, check_log};
use super::model_file::ThermalModelFile;
use super::ramp::{RampCalibration, RampError, RampOptions, ramp_calibration};
use super::soak::{SoakCalibration, SoakDrift, SoakError, soak_calibration};
use crate::calib::protocol::ChamberManifest;
use crate::calib::six_position::SixPositionOptions;
use crate::io::{ImuLog, Quantity};
use driftless_model::compensation::{CompensationModel, OutOfRange};
use std::time::Instant;

/// Why a thermal calibration job failed.
#[derive(Debug, thiserror::Error)]
pub enum ThermalJobError {
    /// The manifest's set temperatures span less than the rise required.
    #[error(
        "{manifest}: set temperatures span {lo}–{hi} °C ({span:.1} °C); a thermal model needs \
         at least {min_rise_c} °C (add set points, or lower --min-rise)",
        span = hi - lo
    )]
    NarrowSpan {
        /// The manifest (or the log whose plateaus were found).
        manifest: String,
        /// Lowest set temperature, °C.
        lo: f64,
        /// Highest, °C.
        hi: f64,
        /// The rise required, °C.
        min_rise_c: f64,
    },
    /// A finding of the log check that refuses it.
    #[error("{0}")]
    Refused(String),
    /// The ramp method's blocking findings.
    #[error(
        "the ramp method cannot give a model from this log:\n  {}\n(`driftless thermal \
         check` prints the full report; --min-rise lowers the rise required)",
        .0.join("\n  ")
    )]
    RampBlocked(Vec<String>),
    /// A log without the three columns of a triad.
    #[error("{log}: needs three {what} columns with units (found {found})")]
    Triad {
        /// The log.
        log: String,
        /// `angular-rate` or `specific-force`.
        what: &'static str,
        /// Columns of that quantity found.
        found: usize,
    },
    /// A log without time stamps.
    #[error("{0}: no time column")]
    NoTime(String),
    /// A log without a temperature.
    #[error("{0}: no temperature column (a column with unit degC, or `--column N:degC`)")]
    NoTemperature(String),
    /// A log without inertial channels.
    #[error("{0}: no angular-rate or specific-force column with a unit")]
    NoInertial(String),
    /// A bias model asked of a log without a whole triad.
    #[error("{0}: --out needs three gyro or three accelerometer columns")]
    NoTriadForModel(String),
    /// The soak calibration failed.
    #[error(transparent)]
    Soak(#[from] SoakError),
    /// The ramp calibration of a log failed.
    #[error("{log}")]
    Ramp {
        /// The log.
        log: String,
        /// Cause.
        source: RampError,
    },
    /// The ramp's bias model failed.
    #[error(transparent)]
    RampModel(RampError),
}

/// A model id from fit coefficients: FNV-1a over their bits, halved so that it stays
/// below 2⁶³ (TOML integers are signed 64-bit); stable for the same fit.
pub fn model_id<'a>(coeffs: impl IntoIterator<Item = &'a f64>) -> u64 {
    coeffs.into_iter().fold(0xcbf2_9ce4_8422_2325u64, |h, c| {
        (h ^ c.to_bits()).wrapping_mul(0x0100_0000_01b3)
    }) >> 1
}

/// The checks the soak method runs first: the set temperatures of `manifest` must span
/// `opts.min_rise_c`; the log's temperature, when it has one, must be finite. The
/// positions come from the manifest, so plateau and orientation findings of the log
/// alone do not apply. Returns the warnings (gaps, coarse resolution).
pub fn soak_precheck(
    log: &ImuLog,
    log_name: &str,
    manifest: &ChamberManifest,
    manifest_source: &str,
    opts: &CheckOptions,
) -> Result<Vec<String>, ThermalJobError> {
    let steps = manifest.steps();
    let (lo, hi) = steps
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(s.0), b.max(s.0))
        });
    if !(hi - lo).is_finite() || hi - lo < opts.min_rise_c {
        return Err(ThermalJobError::NarrowSpan {
            manifest: manifest_source.into(),
            lo,
            hi,
            min_rise_c: opts.min_rise_c,
        });
    }
    let mut warnings = Vec::new();
    if log.indices_of(Quantity::Temperature).is_empty() {
        return Ok(warnings);
    }
    let r = check_log(log, log_name, opts);
    for f in &r.findings {
        match f.kind {
            FindingKind::NoData | FindingKind::BadTemperature => {
                return Err(ThermalJobError::Refused(f.message.clone()));
            }
            FindingKind::Gaps | FindingKind::CoarseResolution => warnings.push(f.message.clone()),
            _ => {}
        }
    }
    Ok(warnings)
}

/// A soak calibration and its compensation model.
#[derive(Clone, Debug)]
pub struct SoakRun {
    /// Six-position calibrations per step and the fits of every series.
    pub soak: SoakCalibration,
    /// The compensation model.
    pub model: CompensationModel,
    /// Its id ([`model_id`] of the coefficients).
    pub model_id: u64,
    /// Wall time, s.
    pub seconds: f64,
}

/// Soak method: six-position + rate-table calibration at every set temperature of
/// `manifest` on the rate triads of `log` (by quantity, with units), the polynomial fits
/// of each bias and scale series, and the compensation model with out-of-range `policy`.
pub fn run_soak(
    log: &ImuLog,
    log_name: &str,
    manifest: &ChamberManifest,
    fit: &FitOptions,
    drift: Option<&SoakDrift>,
    policy: OutOfRange,
) -> Result<SoakRun, ThermalJobError> {
    let pick = |q: Quantity, what: &'static str| {
        log.triad_of(q).ok_or_else(|| ThermalJobError::Triad {
            log: log_name.into(),
            what,
            found: log.indices_of(q).len(),
        })
    };
    let gyro = pick(Quantity::AngularRate, "angular-rate")?;
    let accel = pick(Quantity::SpecificForce, "specific-force")?;
    let six = SixPositionOptions::from_manifest(manifest);
    let t = Instant::now();
    let soak = soak_calibration(manifest, accel, gyro, 1.0, &six, fit, drift)?;
    let id = model_id(soak.series.iter().flat_map(|x| x.fit.coeffs.iter()));
    let model = soak.compensation_model(id, policy)?;
    Ok(SoakRun {
        soak,
        model,
        model_id: id,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// The checks the ramp method runs first: refuses a log without time stamps, and (with
/// every blocking finding) a log the ramp method cannot give a model from; returns the
/// warnings.
pub fn ramp_precheck(
    log: &ImuLog,
    log_name: &str,
    opts: &CheckOptions,
) -> Result<Vec<String>, ThermalJobError> {
    if log.time_s.is_none() {
        return Err(ThermalJobError::NoTime(log_name.into()));
    }
    let r = check_log(log, log_name, opts);
    let warnings = r
        .findings
        .iter()
        .filter(|f| f.ramp == Impact::Warn)
        .map(|f| f.message.clone())
        .collect();
    let blocking = r.blocking(true);
    if !blocking.is_empty() {
        return Err(ThermalJobError::RampBlocked(
            blocking.iter().map(|f| f.message.clone()).collect(),
        ));
    }
    Ok(warnings)
}

/// What the ramp method calibrates in a log: its time, temperature and inertial
/// channels.
#[derive(Clone, Debug)]
pub struct RampInput<'a> {
    /// The log.
    pub log: &'a ImuLog,
    /// Its name in messages.
    pub log_name: &'a str,
    /// Sample times, s.
    pub time_s: &'a [f64],
    /// Temperature, °C.
    pub temperature_c: &'a [f64],
    /// The angular-rate and specific-force channels (name, values), in log order.
    pub channels: Vec<(&'a str, &'a [f64])>,
}

impl<'a> RampInput<'a> {
    /// The time, first temperature channel and inertial channels of `log`.
    pub fn from_log(log: &'a ImuLog, log_name: &'a str) -> Result<Self, ThermalJobError> {
        let Some(time_s) = log.time_s.as_deref() else {
            return Err(ThermalJobError::NoTime(log_name.into()));
        };
        let Some(temp) = log
            .channels
            .iter()
            .find(|c| c.quantity == Quantity::Temperature)
        else {
            return Err(ThermalJobError::NoTemperature(log_name.into()));
        };
        let channels: Vec<(&str, &[f64])> = log
            .channels
            .iter()
            .filter(|c| inertial(c.quantity))
            .map(|c| (c.name.as_str(), c.values.as_slice()))
            .collect();
        Ok(RampInput {
            log,
            log_name,
            time_s,
            temperature_c: &temp.values,
            channels,
        })
    }

    /// Lowest and highest temperature, °C.
    pub fn temperature_range_c(&self) -> (f64, f64) {
        self.temperature_c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            })
    }

    /// Time from the first sample to the last, s.
    pub fn span_s(&self) -> f64 {
        self.time_s.last().copied().unwrap_or(0.0) - self.time_s.first().copied().unwrap_or(0.0)
    }
}

fn inertial(q: Quantity) -> bool {
    matches!(q, Quantity::AngularRate | Quantity::SpecificForce)
}

/// A ramp calibration and, when asked, its bias-only model file.
#[derive(Clone, Debug)]
pub struct RampRun {
    /// Bin points, hysteresis and fits per channel.
    pub result: RampCalibration,
    /// Bins of the heating direction.
    pub heating_bins: usize,
    /// The bias-only model file.
    pub model_file: Option<ThermalModelFile>,
}

/// Ramp method on `input` (bins of `opts.bin_c`, a polynomial per channel); with
/// `bias_model`, the bias-only model file of the triads that have three channels.
pub fn run_ramp(
    input: &RampInput<'_>,
    opts: &RampOptions,
    bias_model: bool,
) -> Result<RampRun, ThermalJobError> {
    if input.channels.is_empty() {
        return Err(ThermalJobError::NoInertial(input.log_name.into()));
    }
    let res = ramp_calibration(input.time_s, input.temperature_c, &input.channels, opts).map_err(
        |source| ThermalJobError::Ramp {
            log: input.log_name.into(),
            source,
        },
    )?;
    let heating_bins = res.points.iter().filter(|p| p.heating).count();
    let model_file = if bias_model {
        // x, y, z channel indices (into the channels) of each triad, when it has three.
        let triad = |q: Quantity| -> Option<[usize; 3]> {
            let idx: Vec<usize> = input
                .log
                .channels
                .iter()
                .filter(|c| inertial(c.quantity))
                .enumerate()
                .filter(|(_, c)| c.quantity == q)
                .map(|(i, _)| i)
                .collect();
            <[usize; 3]>::try_from(idx).ok()
        };
        let (acc, gyr) = (triad(Quantity::SpecificForce), triad(Quantity::AngularRate));
        if acc.is_none() && gyr.is_none() {
            return Err(ThermalJobError::NoTriadForModel(input.log_name.into()));
        }
        let id = model_id(res.fits.iter().flat_map(|f| f.coeffs.iter()));
        Some(
            res.bias_model_file(acc, gyr, id)
                .map_err(ThermalJobError::RampModel)?,
        )
    } else {
        None
    };
    Ok(RampRun {
        result: res,
        heating_bins,
        model_file,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_id_is_stable_below_2_63_and_follows_the_coefficients() {
        let a = model_id(&[1.0, 2.0, 3.0]);
        assert_eq!(a, model_id(&[1.0, 2.0, 3.0]));
        assert!(a < 1 << 63);
        assert_ne!(a, model_id(&[1.0, 2.0, 3.000_000_1]));
        assert_ne!(a, model_id(&[3.0, 2.0, 1.0]));
    }
}

//! Room-temperature calibration of read logs, end to end: the triads taken from the logs,
//! the calibration ([`super::multi_position`], [`super::six_position`]), the calibration
//! model file ([`CalibrationFile`]) and the accelerometer residuals per static interval
//! or position — what `driftless calibrate` prints and writes.

use super::model_file::{CalibrationFile, FORMAT_VERSION, TriadEntry};
use super::multi_position::{
    CalibError, MultiPositionCalibration, MultiPositionOptions, accel_norm_rms,
    calibrate_multi_position,
};
use super::six_position::{
    SixPositionCalibration, SixPositionError, SixPositionInput, SixPositionOptions, calibrate,
};
use crate::calib::protocol::ChamberManifest;
use crate::io::{ImuLog, Quantity};
use driftless_model::calib::TriadCalibration;
use driftless_model::linalg::{Mat3, Vec3, norm, sub};
use std::time::Instant;

/// Why a calibration job failed.
#[derive(Debug, thiserror::Error)]
pub enum CalibJobError {
    /// A log without the three columns of a triad.
    #[error("{log}: needs three {what} columns, found {found} data columns")]
    Triad {
        /// The log.
        log: String,
        /// `accelerometer` or `gyro`.
        what: &'static str,
        /// Data columns found.
        found: usize,
    },
    /// Accelerometer and gyro logs of different lengths.
    #[error(
        "{accel} has {accel_len} samples, {gyro} has {gyro_len}: the two files must be sampled together"
    )]
    Lengths {
        /// Accelerometer log.
        accel: String,
        /// Its samples.
        accel_len: usize,
        /// Gyro log.
        gyro: String,
        /// Its samples.
        gyro_len: usize,
    },
    /// Accelerometer and gyro logs whose time stamps differ.
    #[error(
        "{accel} and {gyro} are not sampled together: sample {sample} is at t = {t_accel} s in \
         the first and t = {t_gyro} s in the second (more than half a sample interval apart); \
         give files recorded at the same instants, or one file with both triads"
    )]
    NotTogether {
        /// Accelerometer log.
        accel: String,
        /// Gyro log.
        gyro: String,
        /// The first sample that differs (1-based).
        sample: usize,
        /// Its time in the accelerometer log, s.
        t_accel: f64,
        /// Its time in the gyro log, s.
        t_gyro: f64,
    },
    /// A log without time stamps.
    #[error("{0}: no time column")]
    NoTime(String),
    /// The multi-position calibration failed.
    #[error("calibrating {sources} ({span})")]
    MultiPosition {
        /// The logs.
        sources: String,
        /// Their time span.
        span: String,
        /// Cause.
        source: CalibError,
    },
    /// Log and manifest sampled at different rates.
    #[error("{log} is sampled at {rate_hz} Hz, the manifest at {manifest_hz} Hz")]
    Rate {
        /// The log.
        log: String,
        /// Its rate.
        rate_hz: f64,
        /// The manifest's.
        manifest_hz: f64,
    },
    /// The six-position calibration failed.
    #[error(transparent)]
    SixPosition(#[from] SixPositionError),
}

/// Three columns of `log`: by quantity when it has exactly three of it (units given),
/// else the channels at `first..first + 3` (raw counts).
pub fn triad_columns<'a>(
    log: &'a ImuLog,
    q: Quantity,
    first: usize,
    what: &'static str,
) -> Result<[&'a [f64]; 3], CalibJobError> {
    if let Some(t) = log.triad_of(q) {
        return Ok(t);
    }
    if first + 3 > log.channels.len() {
        return Err(CalibJobError::Triad {
            log: log.source.clone(),
            what,
            found: log.channels.len(),
        });
    }
    Ok(std::array::from_fn(|k| {
        log.channels[first + k].values.as_slice()
    }))
}

/// [`triad_columns`] as one vector per sample.
pub fn triad(
    log: &ImuLog,
    q: Quantity,
    first: usize,
    what: &'static str,
) -> Result<Vec<Vec3>, CalibJobError> {
    let c = triad_columns(log, q, first, what)?;
    Ok((0..log.len()).map(|i| c.map(|col| col[i])).collect())
}

/// The raw unit of a triad in the model file: the SI unit when the log names the
/// quantity, else `raw`.
fn raw_unit(log: &ImuLog, q: Quantity) -> String {
    match log.channels.iter().find(|c| c.quantity == q) {
        Some(_) => q.si_unit().to_string(),
        None => "raw".into(),
    }
}

fn entry(
    cal: &TriadCalibration,
    bias_sigma: Vec3,
    matrix_sigma: [[f64; 3]; 3],
    unit: String,
    rms: Option<f64>,
) -> TriadEntry {
    TriadEntry {
        raw_unit: unit,
        bias: cal.bias,
        bias_sigma,
        matrix: cal.matrix.0,
        matrix_sigma,
        residual_rms: rms,
    }
}

/// The logs of a multi-position calibration: one with both triads, or an accelerometer
/// and a gyro log sampled together, each with the name used in messages.
#[derive(Clone, Copy, Debug)]
pub struct MultiPositionLogs<'a> {
    /// The accelerometer log (both triads when `gyro` is None: channels by quantity, or
    /// the first three = accel, the next three = gyro).
    pub accel: (&'a str, &'a ImuLog),
    /// The gyro log.
    pub gyro: Option<(&'a str, &'a ImuLog)>,
}

/// A multi-position calibration of logs and what is reported of it.
#[derive(Clone, Debug)]
pub struct MultiPositionRun {
    /// The calibration.
    pub result: MultiPositionCalibration,
    /// The calibration model file.
    pub file: CalibrationFile,
    /// The accelerometer zero offset used to classify poses, raw units.
    pub offset_raw: Vec3,
    /// |a| − g of the calibrated accelerometer per static interval, m/s².
    pub residuals_m_s2: Vec<f64>,
    /// RMS |a| − g before: the nominal offset and the best single scale, m/s².
    pub before_rms_m_s2: f64,
    /// The logs' names (`ACCEL + GYRO`).
    pub sources: String,
    /// The time span calibrated (`t0–t1 s`).
    pub span: String,
    /// Wall time of the calibration, s.
    pub seconds: f64,
}

impl MultiPositionRun {
    /// The reasons the result is implausible (accelerometer, then gyro); empty when it is
    /// plausible.
    pub fn implausible(&self) -> Vec<&String> {
        self.result
            .accel_quality
            .implausible
            .iter()
            .chain(&self.result.gyro_quality.implausible)
            .collect()
    }
}

/// Calibrates both triads from hand-placed static poses: `opts` as given, except the
/// accelerometer offset of pose detection — `accel_offset_raw` on every axis, or by
/// default per axis the middle of the 1st and 99th percentiles of the log.
pub fn run_multi_position(
    logs: MultiPositionLogs<'_>,
    accel_offset_raw: Option<f64>,
    opts: &MultiPositionOptions,
) -> Result<MultiPositionRun, CalibJobError> {
    let (acc_name, acc_log) = logs.accel;
    let (accel, gyro, gyro_log) = match logs.gyro {
        Some((gyro_name, gl)) => {
            check_sampled_together(logs.accel, (gyro_name, gl))?;
            (
                triad(acc_log, Quantity::SpecificForce, 0, "accelerometer")?,
                triad(gl, Quantity::AngularRate, 0, "gyro")?,
                gl,
            )
        }
        None => (
            triad(acc_log, Quantity::SpecificForce, 0, "accelerometer")?,
            triad(acc_log, Quantity::AngularRate, 3, "gyro")?,
            acc_log,
        ),
    };
    let Some(time) = &acc_log.time_s else {
        return Err(CalibJobError::NoTime(acc_name.to_string()));
    };
    let offset: Vec3 = match accel_offset_raw {
        Some(o) => [o; 3],
        None => std::array::from_fn(|k| {
            let mut v: Vec<f64> = accel.iter().map(|a| a[k]).collect();
            v.sort_by(f64::total_cmp);
            let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
            0.5 * (at(0.01) + at(0.99))
        }),
    };
    let mut opts = opts.clone();
    opts.detect.accel_offset_raw = offset;
    let g = opts.gravity_m_s2;
    let sources = match logs.gyro {
        Some((gyro_name, _)) => format!("{acc_name} + {gyro_name}"),
        None => acc_name.to_string(),
    };
    let span = match (time.first(), time.last()) {
        (Some(a), Some(b)) => format!("{a:.2}–{b:.2} s"),
        _ => "empty".into(),
    };
    let t = Instant::now();
    let res = calibrate_multi_position(time, &accel, &gyro, &opts).map_err(|source| {
        CalibJobError::MultiPosition {
            sources: sources.clone(),
            span: span.clone(),
            source,
        }
    })?;
    let seconds = t.elapsed().as_secs_f64();
    let file = CalibrationFile {
        format_version: FORMAT_VERSION,
        method: "multi-position".into(),
        source: sources.clone(),
        gravity_m_s2: g,
        accel: entry(
            &res.accel.calibration,
            res.accel.bias_sigma(),
            res.accel.matrix_sigma().0,
            raw_unit(acc_log, Quantity::SpecificForce),
            Some(res.accel_norm_rms_m_s2),
        ),
        gyro: entry(
            &res.gyro.calibration,
            res.gyro.bias_sigma(),
            res.gyro.matrix_sigma().0,
            raw_unit(gyro_log, Quantity::AngularRate),
            Some(res.gravity_angle_rms_rad),
        ),
        static_intervals: res
            .intervals
            .iter()
            .map(|iv| [iv.start_time_s, iv.end_time_s])
            .collect(),
        gyro_g_sensitivity: None,
    };
    let residuals_m_s2: Vec<f64> = res
        .intervals
        .iter()
        .map(|iv| norm(res.accel.calibration.apply(iv.mean_accel_raw)) - g)
        .collect();
    // Before: the nominal zero offset and the best single scale s (least squares of
    // s·|ā − o| = g over the intervals: s = g·Σ|r| / Σ|r|²).
    let r: Vec<f64> = res
        .intervals
        .iter()
        .map(|iv| norm(sub(iv.mean_accel_raw, offset)))
        .collect();
    let single = g * r.iter().sum::<f64>() / r.iter().map(|v| v * v).sum::<f64>().max(1e-300);
    let before_rms_m_s2 = accel_norm_rms(
        &res.intervals,
        &TriadCalibration {
            bias: offset,
            matrix: Mat3::diag([single; 3]),
        },
        g,
    );
    Ok(MultiPositionRun {
        result: res,
        file,
        offset_raw: offset,
        residuals_m_s2,
        before_rms_m_s2,
        sources,
        span,
        seconds,
    })
}

/// Whether an accelerometer and a gyro log are sampled together: the same number of
/// samples at the same instants (within half a sample interval) — a file's own time
/// stamps are not set aside for its row order.
pub(crate) fn check_sampled_together(
    accel: (&str, &ImuLog),
    gyro: (&str, &ImuLog),
) -> Result<(), CalibJobError> {
    let ((acc_name, acc), (gyro_name, gl)) = (accel, gyro);
    if gl.len() != acc.len() {
        return Err(CalibJobError::Lengths {
            accel: acc_name.into(),
            accel_len: acc.len(),
            gyro: gyro_name.into(),
            gyro_len: gl.len(),
        });
    }
    if let (Some(ta), Some(tg)) = (&acc.time_s, &gl.time_s) {
        let tol = 0.5 * acc.tau0_s.min(gl.tau0_s);
        if let Some(i) = ta
            .iter()
            .zip(tg)
            .position(|(a, b)| (a - b).abs().is_nan() || (a - b).abs() > tol)
        {
            return Err(CalibJobError::NotTogether {
                accel: acc_name.into(),
                gyro: gyro_name.into(),
                sample: i + 1,
                t_accel: ta[i],
                t_gyro: tg[i],
            });
        }
    }
    Ok(())
}

/// The accelerometer residual of one calibrated position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionResidual {
    /// Calibrated specific force minus gravity in the body frame, m/s².
    pub a_minus_g_m_s2: Vec3,
    /// |a| − g, m/s².
    pub norm_m_s2: f64,
}

/// A six-position + rate-table calibration of a log and what is reported of it.
#[derive(Clone, Debug)]
pub struct SixPositionRun {
    /// The positions and rate segments taken from the log.
    pub input: SixPositionInput,
    /// The options used (gravity, g-sensitivity).
    pub opts: SixPositionOptions,
    /// The calibration.
    pub result: SixPositionCalibration,
    /// The calibration model file.
    pub file: CalibrationFile,
    /// Accelerometer residual per position (the order of `input.positions`).
    pub residuals: Vec<PositionResidual>,
    /// Wall time of the calibration, s.
    pub seconds: f64,
}

/// Calibrates the triads of `log` (gyro first: channels by quantity, or columns 0..3
/// gyro, 3..6 accel) at the set temperature `temp_c` of `manifest`; `gravity_m_s2`
/// replaces the manifest's gravity. `log_name` and `source` name the data in messages
/// and in the model file.
pub fn run_six_position(
    log: &ImuLog,
    log_name: &str,
    manifest: &ChamberManifest,
    temp_c: f64,
    gravity_m_s2: Option<f64>,
    estimate_g_sensitivity: bool,
    source: String,
) -> Result<SixPositionRun, CalibJobError> {
    let rate = 1.0 / log.tau0_s;
    if (rate - manifest.sample_rate_hz).abs() > 1e-6 * rate {
        return Err(CalibJobError::Rate {
            log: log_name.into(),
            rate_hz: rate,
            manifest_hz: manifest.sample_rate_hz,
        });
    }
    let gyro = triad_columns(log, Quantity::AngularRate, 0, "gyro")?;
    let accel = triad_columns(log, Quantity::SpecificForce, 3, "accelerometer")?;
    let input = SixPositionInput::from_manifest_columns(manifest, accel, gyro, 1.0, temp_c)?;
    let mut opts = SixPositionOptions::from_manifest(manifest);
    opts.estimate_g_sensitivity = estimate_g_sensitivity;
    if let Some(g) = gravity_m_s2 {
        opts.gravity_m_s2 = g;
    }
    let t = Instant::now();
    let res = calibrate(&input, &opts)?;
    let seconds = t.elapsed().as_secs_f64();
    let file = CalibrationFile {
        format_version: FORMAT_VERSION,
        method: "six-position".into(),
        source,
        gravity_m_s2: opts.gravity_m_s2,
        accel: entry(
            &res.accel.calibration,
            res.accel.bias_sigma(),
            res.accel.matrix_sigma(),
            raw_unit(log, Quantity::SpecificForce),
            None,
        ),
        gyro: entry(
            &res.gyro.calibration,
            res.gyro.bias_sigma(),
            res.gyro.matrix_sigma(),
            raw_unit(log, Quantity::AngularRate),
            None,
        ),
        static_intervals: Vec::new(),
        gyro_g_sensitivity: res
            .gyro_g_sensitivity
            .as_ref()
            .map(|g| g.matrix_raw_per_m_s2.0),
    };
    let g = opts.gravity_m_s2;
    let residuals = input
        .positions
        .iter()
        .map(|p| {
            let a = res.accel.calibration.apply(p.accel_raw);
            PositionResidual {
                a_minus_g_m_s2: sub(a, p.c_bn.t().mul_vec([0.0, 0.0, -g])),
                norm_m_s2: norm(a) - g,
            }
        })
        .collect();
    Ok(SixPositionRun {
        input,
        opts,
        result: res,
        file,
        residuals,
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Channel;

    fn log(name: &str, time_s: Vec<f64>, q: Quantity) -> ImuLog {
        let n = time_s.len();
        let channels = (0..3)
            .map(|k| Channel {
                name: format!("{name}{k}"),
                quantity: q,
                source_unit: q.si_unit().into(),
                values: vec![k as f64; n],
            })
            .collect();
        ImuLog::new(name, Some(time_s), 0.01, channels)
    }

    #[test]
    fn paired_logs_must_share_their_instants() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        let acc = log("acc", t.clone(), Quantity::SpecificForce);
        let gyro = log("gyro", t.clone(), Quantity::AngularRate);
        check_sampled_together(("a.csv", &acc), ("g.csv", &gyro)).unwrap();
        let mut shifted = t.clone();
        shifted[40] += 0.006;
        let late = log("gyro", shifted, Quantity::AngularRate);
        let e = check_sampled_together(("a.csv", &acc), ("g.csv", &late)).unwrap_err();
        assert!(
            matches!(e, CalibJobError::NotTogether { sample: 41, .. }),
            "{e}"
        );
        let short = log("gyro", t[..99].to_vec(), Quantity::AngularRate);
        let e = check_sampled_together(("a.csv", &acc), ("g.csv", &short)).unwrap_err();
        assert!(
            e.to_string()
                .contains("a.csv has 100 samples, g.csv has 99"),
            "{e}"
        );
    }

    #[test]
    fn triads_by_quantity_or_position() {
        let t: Vec<f64> = (0..10).map(|i| i as f64 * 0.01).collect();
        let acc = log("acc", t, Quantity::SpecificForce);
        let by_q = triad(&acc, Quantity::SpecificForce, 3, "accelerometer").unwrap();
        assert_eq!(by_q[0], [0.0, 1.0, 2.0]);
        let e = triad_columns(&acc, Quantity::AngularRate, 3, "gyro").unwrap_err();
        assert!(
            e.to_string().contains("needs three gyro columns, found 3"),
            "{e}"
        );
    }
}

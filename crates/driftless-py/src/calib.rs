//! `driftless.calibrate_six_position` / `calibrate_multi_position`: room-temperature
//! calibration calibrated = M·(raw − b) of both triads — the library's
//! [`run_six_position`] and [`run_multi_position`], the jobs `driftless calibrate` runs —
//! on a log read from a file (as the CLI reads it: time in column 1) or built from NumPy
//! columns. The result goes back as the calibration model file's serde JSON and TOML
//! text (the file `driftless calibrate --out` writes) plus the quality figures and the
//! accelerometer residuals; the Python side turns them into a `CalibrationResult`.

use driftless::calib::job::{MultiPositionLogs, run_multi_position, run_six_position};
use driftless::calib::model_file::CalibrationFile;
use driftless::calib::multi_position::{MultiPositionOptions, gravity_at};
use driftless::calib::protocol::ChamberManifest;
use driftless::calib::quality::DEFAULT_WARN_CHI2_PER_DOF;
use driftless::io::{Channel, ColumnRef, ImuLog, Quantity, TextOptions, read_log_file};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::value_error;

/// One column from Python: name, quantity (`angular_rate`, `specific_force`,
/// `temperature`, or `other` for raw counts) and samples (SI, or raw).
pub(crate) type PyColumn<'py> = (String, String, PyReadonlyArray1<'py, f64>);

/// A log as the Python side passes it: `(path, columns, time_s, tau0_s, name)` — a
/// file path, or columns with optional time stamps and the sample interval; the name
/// leads messages.
pub(crate) type LogArgs<'py> = (
    Option<String>,
    Vec<PyColumn<'py>>,
    Option<PyReadonlyArray1<'py, f64>>,
    Option<f64>,
    String,
);

/// Where a log comes from: a file read as `driftless` reads it, or columns.
pub(crate) enum LogSource {
    /// A log file (CSV/text, DRIFTLOG, …); time in column 1 unless its header names one.
    File(String),
    /// Columns already in memory.
    Columns(ImuLog),
}

impl LogSource {
    /// The log (reads the file; call with the GIL released).
    pub(crate) fn into_log(self) -> Result<ImuLog, String> {
        match self {
            LogSource::Columns(log) => Ok(log),
            LogSource::File(path) => {
                let opts = TextOptions::default().with_time(ColumnRef::Index(1), None);
                let log = read_log_file(&path, &opts).map_err(|e| e.to_string())?;
                if log.is_empty() {
                    return Err(format!("{path}: no data rows"));
                }
                Ok(log)
            }
        }
    }
}

fn quantity(name: &str, q: &str) -> PyResult<Quantity> {
    match q {
        "angular_rate" => Ok(Quantity::AngularRate),
        "specific_force" => Ok(Quantity::SpecificForce),
        "temperature" => Ok(Quantity::Temperature),
        // raw counts: the jobs take the triads by position
        "other" => Ok(Quantity::Other),
        other => Err(value_error(format!(
            "column {name:?}: unknown quantity {other:?}; expected angular_rate, \
             specific_force, temperature or other"
        ))),
    }
}

/// The log of `path` or of `columns` (equal lengths, checked) with time stamps
/// `time_s` (optional) at sample interval `tau0_s`; `name` is its source in messages.
pub(crate) fn log_source(args: LogArgs<'_>) -> PyResult<LogSource> {
    let (path, columns, time_s, tau0_s, name) = args;
    let name = name.as_str();
    if let Some(p) = path {
        return Ok(LogSource::File(p));
    }
    let mut channels = Vec::with_capacity(columns.len());
    for (col_name, q, values) in &columns {
        let quantity = quantity(col_name, q)?;
        channels.push(Channel {
            name: col_name.clone(),
            quantity,
            source_unit: match quantity {
                Quantity::Other => "raw".into(),
                q => q.si_unit().into(),
            },
            values: values.as_array().iter().copied().collect(),
        });
    }
    let n = channels.first().map_or(0, |c| c.values.len());
    if let Some(c) = channels.iter().find(|c| c.values.len() != n) {
        return Err(value_error(format!(
            "{name}: column {:?} has {} samples, {:?} has {n}",
            c.name,
            c.values.len(),
            channels[0].name
        )));
    }
    let time: Option<Vec<f64>> = time_s.map(|t| t.as_array().iter().copied().collect());
    if let Some(t) = &time
        && t.len() != n
    {
        return Err(value_error(format!(
            "{name}: time_s has {} samples, the data columns {n}",
            t.len()
        )));
    }
    let Some(tau0_s) = tau0_s.filter(|t| t.is_finite() && *t > 0.0) else {
        return Err(value_error(format!(
            "{name}: the sample interval must be a positive number of seconds, got {tau0_s:?}"
        )));
    };
    Ok(LogSource::Columns(ImuLog::new(
        name, time, tau0_s, channels,
    )))
}

/// The segment manifest from its TOML text; `name` (its path or `<manifest>`) leads
/// errors.
pub(crate) fn manifest(text: &str, name: &str) -> PyResult<ChamberManifest> {
    ChamberManifest::from_toml_str(text).map_err(|e| value_error(format!("{name}: {e}")))
}

fn set_file(d: &Bound<'_, PyDict>, file: &CalibrationFile) -> PyResult<()> {
    d.set_item(
        "file_json",
        serde_json::to_string(file).map_err(value_error)?,
    )?;
    d.set_item("file_toml", file.to_toml_string().map_err(value_error)?)?;
    Ok(())
}

/// Six-position + rate-table calibration of the log at set temperature
/// `temperature_c` of the manifest (None: its only one) — `driftless calibrate
/// six-position LOG --manifest M`.
#[pyfunction]
pub(crate) fn calib_six_position<'py>(
    py: Python<'py>,
    log: LogArgs<'py>,
    manifest_toml: &str,
    manifest_name: &str,
    temperature_c: Option<f64>,
    gravity_m_s2: Option<f64>,
    g_sensitivity: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let name = log.4.clone();
    let source = log_source(log)?;
    let m = manifest(manifest_toml, manifest_name)?;
    let mut temps = m.set_temperatures_c();
    temps.sort_by(f64::total_cmp);
    temps.dedup();
    let temp = match (temperature_c, temps.as_slice()) {
        (Some(t), _) if temps.contains(&t) => t,
        (Some(t), _) => {
            return Err(value_error(format!(
                "temperature_c = {t}: the manifest's set temperatures are {temps:?}"
            )));
        }
        (None, [t]) => *t,
        (None, _) => {
            return Err(value_error(format!(
                "{manifest_name}: {} set temperatures ({temps:?}); choose one with temperature_c",
                temps.len()
            )));
        }
    };
    if let Some(g) = gravity_m_s2 {
        check_gravity(g)?;
    }
    let file_source = format!("{name} + {manifest_name}");
    let log_name = name;
    let run = py
        .detach(move || {
            let log = source.into_log()?;
            run_six_position(
                &log,
                &log_name,
                &m,
                temp,
                gravity_m_s2,
                g_sensitivity,
                file_source,
            )
            .map_err(|e| e.to_string())
        })
        .map_err(value_error)?;
    let (accel_q, gyro_q) = run.result.quality(DEFAULT_WARN_CHI2_PER_DOF);
    let d = PyDict::new(py);
    set_file(&d, &run.file)?;
    d.set_item(
        "quality_json",
        serde_json::to_string(&serde_json::json!({"accel": accel_q, "gyro": gyro_q}))
            .map_err(value_error)?,
    )?;
    d.set_item("temperature_c", temp)?;
    d.set_item(
        "positions",
        run.input
            .positions
            .iter()
            .map(|p| p.up.to_string())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("rate_segments", run.input.rates.len())?;
    let resid: Vec<f64> = run
        .residuals
        .iter()
        .flat_map(|r| r.a_minus_g_m_s2)
        .collect();
    d.set_item("a_minus_g_m_s2", resid.into_pyarray(py))?;
    d.set_item(
        "residuals_m_s2",
        run.residuals
            .iter()
            .map(|r| r.norm_m_s2)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("seconds", run.seconds)?;
    Ok(d)
}

fn check_gravity(g: f64) -> PyResult<()> {
    if !(g.is_finite() && (9.7..=9.9).contains(&g)) {
        return Err(value_error(format!(
            "gravity_m_s2 = {g} is not an Earth gravity (9.7–9.9 m/s²)"
        )));
    }
    Ok(())
}

/// Fixture-free multi-position calibration of a log with both triads (Tedaldi et al.
/// 2014) — `driftless calibrate multi-position LOG`. An implausible result is refused
/// (with the reasons) unless `accept_poor_fit`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn calib_multi_position<'py>(
    py: Python<'py>,
    log: LogArgs<'py>,
    gravity_m_s2: Option<f64>,
    lat_deg: f64,
    height_m: f64,
    gyro_scale_guess: Option<f64>,
    accel_offset: Option<f64>,
    accept_poor_fit: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let log_name = log.4.clone();
    let source = log_source(log)?;
    let g = gravity_m_s2.unwrap_or_else(|| gravity_at(lat_deg.to_radians(), height_m));
    check_gravity(g)?;
    if let Some(s) = gyro_scale_guess
        && !(s.is_finite() && s > 0.0)
    {
        return Err(value_error(format!(
            "gyro_scale_guess = {s}: give rad/s per raw unit, > 0"
        )));
    }
    let opts = MultiPositionOptions {
        gravity_m_s2: g,
        gyro_scale_guess_rad_s_per_raw: gyro_scale_guess,
        ..MultiPositionOptions::default()
    };
    let run = py
        .detach(move || {
            let log = source.into_log()?;
            let logs = MultiPositionLogs {
                accel: (&log_name, &log),
                gyro: None,
            };
            run_multi_position(logs, accel_offset, &opts).map_err(|e| {
                // the cause chain: the job names the log and span, the source says why
                let mut msg = e.to_string();
                let mut src = std::error::Error::source(&e);
                while let Some(s) = src {
                    msg = format!("{msg}: {s}");
                    src = s.source();
                }
                msg
            })
        })
        .map_err(value_error)?;
    let implausible = run.implausible();
    if !implausible.is_empty() && !accept_poor_fit {
        let list: Vec<String> = implausible.iter().map(|r| format!("  - {r}")).collect();
        return Err(value_error(format!(
            "{} ({}): the multi-position calibration is implausible:\n{}\n(pass \
             accept_poor_fit=True to keep it anyway)",
            run.sources,
            run.span,
            list.join("\n")
        )));
    }
    let res = &run.result;
    let d = PyDict::new(py);
    set_file(&d, &run.file)?;
    d.set_item(
        "quality_json",
        serde_json::to_string(
            &serde_json::json!({"accel": res.accel_quality, "gyro": res.gyro_quality}),
        )
        .map_err(value_error)?,
    )?;
    d.set_item(
        "residuals_m_s2",
        run.residuals_m_s2.clone().into_pyarray(py),
    )?;
    d.set_item("before_rms_m_s2", run.before_rms_m_s2)?;
    d.set_item("accel_norm_rms_m_s2", res.accel_norm_rms_m_s2)?;
    d.set_item("gravity_angle_rms_rad", res.gravity_angle_rms_rad)?;
    d.set_item("threshold_multiple", res.threshold_multiple)?;
    d.set_item(
        "gyro_scale_estimate",
        res.gyro_scale.as_ref().map(|e| e.scale_rad_s_per_raw),
    )?;
    d.set_item("accepted_poor_fit", !implausible.is_empty())?;
    d.set_item("seconds", run.seconds)?;
    Ok(d)
}

/// Reads and validates a calibration model file: its TOML text and serde JSON.
#[pyfunction]
pub(crate) fn calib_load(py: Python<'_>, path: String) -> PyResult<(String, String)> {
    let f = py
        .detach(move || CalibrationFile::load(&path))
        .map_err(value_error)?;
    Ok((
        f.to_toml_string().map_err(value_error)?,
        serde_json::to_string(&f).map_err(value_error)?,
    ))
}

/// Writes a calibration model file (TOML text, validated) through the library's
/// writer (temporary file + rename).
#[pyfunction]
pub(crate) fn calib_save(py: Python<'_>, text: &str, path: String) -> PyResult<()> {
    let f = CalibrationFile::from_toml_str(text, "<calibration>").map_err(value_error)?;
    py.detach(move || f.save(&path)).map_err(value_error)
}

/// A calibration model file from its serde JSON (the Python side's `to_dict()`),
/// validated: its TOML text and JSON.
#[pyfunction]
pub(crate) fn calib_from_json(text: &str) -> PyResult<(String, String)> {
    let f: CalibrationFile =
        serde_json::from_str(text).map_err(|e| value_error(format!("calibration model: {e}")))?;
    f.validate("<calibration>").map_err(value_error)?;
    Ok((
        f.to_toml_string().map_err(value_error)?,
        serde_json::to_string(&f).map_err(value_error)?,
    ))
}

/// The columns of a log as a dict of NumPy arrays (`time_s` first when it has one).
pub(crate) fn log_columns<'py>(py: Python<'py>, log: &ImuLog) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    if let Some(t) = &log.time_s {
        d.set_item("time_s", t.clone().into_pyarray(py))?;
    }
    for c in &log.channels {
        d.set_item(&c.name, c.values.clone().into_pyarray(py))?;
    }
    Ok(d)
}

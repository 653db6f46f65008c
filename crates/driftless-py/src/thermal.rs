//! `driftless.thermal_fit` and `ThermalModel`: the soak and ramp methods of thermal
//! calibration ([`run_soak`], [`run_ramp`], with the checks `driftless thermal soak|ramp`
//! runs first) on a log from a file or from NumPy columns; the model file's TOML text
//! and serde JSON ([`ThermalModelFile`], what `--out` writes); the real-time compensation
//! of samples ([`CompensationModel::compensate_block`], what `driftless compensate`
//! applies); and a simulated chamber session with its segment manifest.

use driftless::sim::presets::Preset;
use driftless::sim::scenario::Scenario;
use driftless::sim::sensor_config::SensorConfig;
use driftless::thermal::FitOptions;
use driftless::thermal::check::CheckOptions;
use driftless::thermal::job::{RampInput, ramp_precheck, run_ramp, run_soak, soak_precheck};
use driftless::thermal::model_file::ThermalModelFile;
use driftless::thermal::ramp::RampOptions;
use driftless_model::compensation::OutOfRange;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::calib::{LogArgs, log_columns, log_source, manifest};
use crate::value_error;

fn policy(name: &str) -> PyResult<OutOfRange> {
    match name {
        "clamp" => Ok(OutOfRange::Clamp),
        "extrapolate" => Ok(OutOfRange::Extrapolate),
        "error" => Ok(OutOfRange::Error),
        other => Err(value_error(format!(
            "out_of_range = {other:?}: expected \"clamp\", \"extrapolate\" or \"error\""
        ))),
    }
}

fn check_options(order: usize, min_rise_c: f64) -> PyResult<CheckOptions> {
    if !(min_rise_c.is_finite() && min_rise_c >= 0.0) {
        return Err(value_error(format!(
            "min_rise_c = {min_rise_c}: give a temperature rise in °C, ≥ 0"
        )));
    }
    Ok(CheckOptions {
        order,
        min_rise_c,
        ..CheckOptions::default()
    })
}

fn set_model(d: &Bound<'_, PyDict>, file: &ThermalModelFile) -> PyResult<()> {
    // Refuse what `compensate` would not read (as the CLI does before writing).
    file.model("<thermal model>").map_err(value_error)?;
    d.set_item(
        "model_toml",
        file.to_toml_string("<thermal model>")
            .map_err(value_error)?,
    )?;
    d.set_item(
        "model_json",
        serde_json::to_string(file).map_err(value_error)?,
    )?;
    Ok(())
}

fn fit_dict<'py>(
    py: Python<'py>,
    f: &driftless::thermal::ThermalFit,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("coefficients", f.coeffs.clone().into_pyarray(py))?;
    d.set_item("std_errors", f.std_errors.clone().into_pyarray(py))?;
    d.set_item("residual_rms", f.residual_rms)?;
    d.set_item("chi2_per_dof", f.chi2_per_dof)?;
    d.set_item("scatter_ratio", f.scatter_ratio)?;
    d.set_item("sigma_scale", f.sigma_scale)?;
    d.set_item("dof", f.dof)?;
    d.set_item("n_points", f.n_points)?;
    Ok(d)
}

/// Soak method on a chamber log and its manifest — `driftless thermal soak LOG
/// --manifest M`: six-position + rate-table calibration at every set temperature, a
/// polynomial per bias and scale series, and the compensation model.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn thermal_soak<'py>(
    py: Python<'py>,
    log: LogArgs<'py>,
    manifest_toml: &str,
    manifest_name: &str,
    order: usize,
    t_ref_c: f64,
    out_of_range: &str,
    min_rise_c: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let log_name = log.4.clone();
    let source = log_source(log)?;
    let m = manifest(manifest_toml, manifest_name)?;
    let policy = policy(out_of_range)?;
    let check = check_options(order, min_rise_c)?;
    let fit = FitOptions {
        order,
        t_ref_c,
        ..FitOptions::default()
    };
    let manifest_name = manifest_name.to_string();
    let (run, warnings) = py
        .detach(move || {
            let log = source.into_log()?;
            let warnings = soak_precheck(&log, &log_name, &m, &manifest_name, &check)
                .map_err(|e| e.to_string())?;
            let run =
                run_soak(&log, &log_name, &m, &fit, None, policy).map_err(|e| e.to_string())?;
            Ok::<_, String>((run, warnings))
        })
        .map_err(value_error)?;
    let d = PyDict::new(py);
    set_model(
        &d,
        &ThermalModelFile::from_model(&run.model, ["m/s^2", "rad/s"]),
    )?;
    d.set_item("method", "soak")?;
    d.set_item("temperatures_c", run.soak.temperatures_c.clone())?;
    let series = PyList::empty(py);
    for s in &run.soak.series {
        let f = fit_dict(py, &s.fit)?;
        f.set_item("triad", s.triad)?;
        f.set_item("quantity", s.quantity)?;
        f.set_item("axis", ["x", "y", "z"][s.axis])?;
        f.set_item("values", s.values.clone().into_pyarray(py))?;
        f.set_item("sigma", s.sigma.clone().into_pyarray(py))?;
        series.append(f)?;
    }
    d.set_item("fits", series)?;
    d.set_item("warnings", warnings)?;
    d.set_item("seconds", run.seconds)?;
    Ok(d)
}

/// Ramp method on a static log with a temperature column — `driftless thermal ramp LOG
/// --out M`: binned bias versus temperature per channel, a polynomial each, and the
/// bias-only model of the triads with three channels.
#[pyfunction]
pub(crate) fn thermal_ramp<'py>(
    py: Python<'py>,
    log: LogArgs<'py>,
    order: usize,
    t_ref_c: f64,
    bin_c: f64,
    min_rise_c: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let log_name = log.4.clone();
    let source = log_source(log)?;
    let check = check_options(order, min_rise_c)?;
    if !(bin_c.is_finite() && bin_c > 0.0) {
        return Err(value_error(format!(
            "bin_c = {bin_c}: give a bin width in °C, > 0"
        )));
    }
    let opts = RampOptions {
        bin_c,
        fit: FitOptions {
            order,
            t_ref_c,
            ..FitOptions::default()
        },
        ..RampOptions::default()
    };
    let (run, warnings) = py
        .detach(move || {
            let log = source.into_log()?;
            let warnings = ramp_precheck(&log, &log_name, &check).map_err(|e| e.to_string())?;
            let input = RampInput::from_log(&log, &log_name).map_err(|e| e.to_string())?;
            let run = run_ramp(&input, &opts, true).map_err(|e| e.to_string())?;
            Ok::<_, String>((run, warnings))
        })
        .map_err(value_error)?;
    let d = PyDict::new(py);
    if let Some(file) = &run.model_file {
        set_model(&d, file)?;
    }
    d.set_item("method", "ramp")?;
    let fits = PyList::empty(py);
    let res = &run.result;
    for (k, (n, f)) in res.names.iter().zip(&res.fits).enumerate() {
        let fd = fit_dict(py, f)?;
        fd.set_item("channel", n)?;
        fd.set_item("hysteresis_rms", res.hysteresis.as_ref().map(|h| h[k]))?;
        fits.append(fd)?;
    }
    d.set_item("fits", fits)?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// Reads a thermal model file and builds its model (refusing what `compensate` would
/// refuse): its TOML text and serde JSON.
#[pyfunction]
pub(crate) fn thermal_load(py: Python<'_>, path: String) -> PyResult<(String, String)> {
    let (file, _) = py
        .detach(move || ThermalModelFile::load(&path))
        .map_err(value_error)?;
    Ok((
        file.to_toml_string("<thermal model>")
            .map_err(value_error)?,
        serde_json::to_string(&file).map_err(value_error)?,
    ))
}

/// A thermal model file from its serde JSON (the Python side's `to_dict()`), checked
/// to build a compensation model: its TOML text and JSON.
#[pyfunction]
pub(crate) fn thermal_from_json(text: &str) -> PyResult<(String, String)> {
    let file: ThermalModelFile =
        serde_json::from_str(text).map_err(|e| value_error(format!("thermal model: {e}")))?;
    file.model("<thermal model>").map_err(value_error)?;
    Ok((
        file.to_toml_string("<thermal model>")
            .map_err(value_error)?,
        serde_json::to_string(&file).map_err(value_error)?,
    ))
}

/// Writes a thermal model file (TOML text, checked) through the library's writer.
#[pyfunction]
pub(crate) fn thermal_save(py: Python<'_>, text: &str, path: String) -> PyResult<()> {
    let (file, _) =
        ThermalModelFile::from_toml_str(text, "<thermal model>").map_err(value_error)?;
    py.detach(move || file.save(&path)).map_err(value_error)
}

/// Compensated gyro and accelerometer rows, flat.
type Rows<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// Raw samples through the real-time compensation of a model (its TOML text): gyro and
/// accelerometer as flat x, y, z rows (3·N values each), the temperature per sample.
/// Returns the compensated rows, flat, in the same layout.
#[pyfunction]
pub(crate) fn thermal_compensate<'py>(
    py: Python<'py>,
    model_toml: &str,
    gyro_flat: PyReadonlyArray1<'py, f64>,
    accel_flat: PyReadonlyArray1<'py, f64>,
    temperature_c: PyReadonlyArray1<'py, f64>,
) -> PyResult<Rows<'py>> {
    let (_, model) =
        ThermalModelFile::from_toml_str(model_toml, "<thermal model>").map_err(value_error)?;
    let rows = |a: &PyReadonlyArray1<'py, f64>, what: &str| -> PyResult<Vec<[f64; 3]>> {
        let v = a.as_array();
        if !v.len().is_multiple_of(3) {
            return Err(value_error(format!(
                "{what}: {} values are not x, y, z rows",
                v.len()
            )));
        }
        let v: Vec<f64> = v.iter().copied().collect();
        Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    };
    let mut gyro = rows(&gyro_flat, "gyro")?;
    let mut accel = rows(&accel_flat, "accel")?;
    let temp: Vec<f64> = temperature_c.as_array().iter().copied().collect();
    let (gyro, accel) = py
        .detach(move || {
            model
                .compensate_block(&mut gyro, &mut accel, &temp)
                .map(|()| (gyro, accel))
        })
        .map_err(value_error)?;
    let flat = |v: Vec<[f64; 3]>| v.into_iter().flatten().collect::<Vec<f64>>();
    Ok((flat(gyro).into_pyarray(py), flat(accel).into_pyarray(py)))
}

/// A preset's sensor-error configuration as JSON (the `[imu.sensor]` table of a
/// scenario).
#[pyfunction]
pub(crate) fn sensor_preset_json(name: &str) -> PyResult<String> {
    let p: Preset = name.parse().map_err(value_error)?;
    serde_json::to_string(&p.config()).map_err(value_error)
}

/// Runs a chamber scenario (TOML text) with, when given, the sensor configuration
/// `sensor_json` in place of the scenario's: the IMU output as rate columns (with
/// `temp` and `time_s`) and the segment manifest's TOML text.
#[pyfunction]
#[pyo3(signature = (scenario_toml, name, sensor_json=None))]
pub(crate) fn chamber_simulate<'py>(
    py: Python<'py>,
    scenario_toml: &str,
    name: &str,
    sensor_json: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut scenario = Scenario::from_toml_str(scenario_toml, name).map_err(value_error)?;
    if let Some(j) = sensor_json {
        let cfg: SensorConfig = serde_json::from_str(j)
            .map_err(|e| value_error(format!("{name}: sensor configuration: {e}")))?;
        scenario.imu.sensor = Some(cfg);
        scenario.imu.preset = None;
    }
    let sim = py.detach(move || scenario.run()).map_err(value_error)?;
    let Some(manifest) = &sim.manifest else {
        return Err(value_error(format!(
            "{name}: not a chamber scenario ([trajectory] type = \"chamber\")"
        )));
    };
    let log = sim.rates_log(name);
    let d = PyDict::new(py);
    d.set_item("tau0_s", log.tau0_s)?;
    d.set_item("imu", log_columns(py, &log)?)?;
    d.set_item(
        "manifest_toml",
        manifest.to_toml_string().map_err(value_error)?,
    )?;
    d.set_item(
        "sensor_json",
        serde_json::to_string(&sim.sensor).map_err(value_error)?,
    )?;
    Ok(d)
}

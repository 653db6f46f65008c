//! The `driftless._driftless` Python extension: NumPy arrays in, NumPy arrays and plain
//! Python objects out. Every computation runs with the GIL released
//! ([`Python::detach`]) on a copy of the input, so other Python threads go on and cannot
//! change the samples under the computation. The user-facing API (argument defaults,
//! allantools' tau selection, result classes) is the pure-Python `driftless` package.

mod analysis;
mod calib;
mod compat;
mod experiment;
mod nav;
mod thermal;

use driftless::allan::fit::FitConfig;
use driftless::allan::{DataType, DevPoint, Estimator};
use driftless::prelude::Scenario;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Columns<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The samples as an owned vector (any stride; the copy is what the GIL-free
/// computation reads).
fn owned(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

fn estimator(name: &str) -> PyResult<Estimator> {
    Estimator::from_name(name).ok_or_else(|| {
        value_error(format!(
            "unknown estimator {name:?}; expected one of adev, oadev, mdev, hdev, ohdev, tdev, totdev"
        ))
    })
}

fn is_frequency(data_type: &str) -> PyResult<bool> {
    match data_type {
        "phase" => Ok(false),
        "freq" => Ok(true),
        other => Err(value_error(format!(
            "unknown data_type {other:?}; expected \"phase\" or \"freq\""
        ))),
    }
}

/// `(taus, devs, errs, ns)` of `estimator` at averaging factors `ms`, allantools' form.
#[pyfunction]
fn allan_compat<'py>(
    py: Python<'py>,
    estimator_name: &str,
    data: PyReadonlyArray1<'py, f64>,
    rate: f64,
    data_type: &str,
    ms: Vec<usize>,
) -> PyResult<Columns<'py>> {
    let est = estimator(estimator_name)?;
    let freq = is_frequency(data_type)?;
    let values = owned(&data);
    let c = py
        .detach(move || compat::curve(est, &values, rate, freq, &ms))
        .map_err(value_error)?;
    Ok((
        c.taus_s.into_pyarray(py),
        c.devs.into_pyarray(py),
        c.errs.into_pyarray(py),
        c.ns.into_pyarray(py),
    ))
}

/// One channel's curve with confidence bounds and, when `quantity` is given, its fitted
/// noise model: a dict of NumPy columns and scalars plus the serde JSON of the curve and
/// the model (the Python side turns them into result objects).
#[pyfunction]
#[pyo3(signature = (data, rate, name, estimator_name, taus, data_type, alpha, confidence, quantity, terms))]
#[allow(clippy::too_many_arguments)]
fn analyse_channel<'py>(
    py: Python<'py>,
    data: PyReadonlyArray1<'py, f64>,
    rate: f64,
    name: &str,
    estimator_name: &str,
    taus: &str,
    data_type: &str,
    alpha: Option<i32>,
    confidence: f64,
    quantity: Option<&str>,
    terms: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let req = analysis::Request {
        name: name.to_string(),
        estimator: estimator(estimator_name)?,
        taus: taus.parse().map_err(value_error)?,
        data_type: if is_frequency(data_type)? {
            DataType::Frequency
        } else {
            DataType::Phase
        },
        alpha,
        confidence,
        quantity: quantity
            .map(analysis::quantity)
            .transpose()
            .map_err(value_error)?,
        terms: match terms {
            Some(t) => t.parse().map_err(value_error)?,
            None => FitConfig::default(),
        },
    };
    let values = owned(&data);
    let out = py
        .detach(move || analysis::run(&values, rate, &req))
        .map_err(value_error)?;
    let c = &out.curve;
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&DevPoint) -> f64| -> Vec<f64> { c.points.iter().map(f).collect() };
    d.set_item("name", &c.name)?;
    d.set_item("estimator", c.estimator.name())?;
    d.set_item("tau0_s", c.tau0_s)?;
    d.set_item("confidence", c.confidence)?;
    d.set_item("m", col(&|p| p.m as f64).into_pyarray(py))?;
    d.set_item("tau_s", col(&|p| p.tau).into_pyarray(py))?;
    d.set_item("n", col(&|p| p.n as f64).into_pyarray(py))?;
    d.set_item("dev", col(&|p| p.dev).into_pyarray(py))?;
    d.set_item("dev_lo", c.dev_lo.clone().into_pyarray(py))?;
    d.set_item("dev_hi", c.dev_hi.clone().into_pyarray(py))?;
    d.set_item("alpha", c.alpha.clone().into_pyarray(py))?;
    d.set_item("edf", c.edf.clone().into_pyarray(py))?;
    d.set_item("rate_acf1", c.rate_acf1.clone().into_pyarray(py))?;
    d.set_item("curve_json", serde_json::to_string(c).map_err(value_error)?)?;
    if let Some(model) = &out.model {
        d.set_item(
            "model_json",
            serde_json::to_string(model).map_err(value_error)?,
        )?;
        d.set_item("model_toml", model.to_toml_string().map_err(value_error)?)?;
        d.set_item("model_table", model.human_table())?;
    }
    Ok(d)
}

/// Run a scenario given as TOML text (the format of `driftless simulate`): the IMU
/// output as rates (one NumPy column per channel, SI, plus `time_s`), the GNSS fixes if
/// the scenario has a receiver, and the resolved sensor configuration as JSON.
#[pyfunction]
fn simulate_scenario<'py>(
    py: Python<'py>,
    scenario_toml: &str,
    name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let scenario = Scenario::from_toml_str(scenario_toml, name).map_err(value_error)?;
    let sim = py.detach(move || scenario.run()).map_err(value_error)?;
    let log = sim.rates_log(name);
    let d = PyDict::new(py);
    d.set_item("tau0_s", log.tau0_s)?;
    d.set_item("imu", calib::log_columns(py, &log)?)?;
    if let Some(g) = &sim.gnss {
        let gnss = PyDict::new(py);
        gnss.set_item("time_s", g.time_s.clone().into_pyarray(py))?;
        gnss.set_item("lat_rad", g.lat_rad.clone().into_pyarray(py))?;
        gnss.set_item("lon_rad", g.lon_rad.clone().into_pyarray(py))?;
        gnss.set_item("height_m", g.height_m.clone().into_pyarray(py))?;
        let axis = |v: &[[f64; 3]], k: usize| v.iter().map(|x| x[k]).collect::<Vec<f64>>();
        for (k, n) in ["n", "e", "d"].iter().enumerate() {
            gnss.set_item(
                format!("sigma_{n}_m"),
                axis(&g.sigma_ned_m, k).into_pyarray(py),
            )?;
            if let (Some(v), Some(sv)) = (&g.vel_ned_m_s, &g.sigma_vel_ned_m_s) {
                gnss.set_item(format!("vel_{n}_m_s"), axis(v, k).into_pyarray(py))?;
                gnss.set_item(format!("sigma_vel_{n}_m_s"), axis(sv, k).into_pyarray(py))?;
            }
        }
        d.set_item("gnss", gnss)?;
    }
    d.set_item(
        "sensor_json",
        serde_json::to_string(&sim.sensor).map_err(value_error)?,
    )?;
    d.set_item("truth", nav::trajectory_columns(py, &sim.truth)?)?;
    d.set_item("lever_arm_b_m", sim.lever_arm_b_m.to_vec())?;
    Ok(d)
}

#[pymodule]
fn _driftless(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(allan_compat, m)?)?;
    m.add_function(wrap_pyfunction!(analyse_channel, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calib_six_position, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calib_multi_position, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calib_load, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calib_save, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calib_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_soak, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_ramp, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_load, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_save, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_compensate, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::sensor_preset_json, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::chamber_simulate, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(nav::nav_default_config, m)?)?;
    m.add_function(wrap_pyfunction!(nav::navigate_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(nav::navigate_files, m)?)?;
    m.add_function(wrap_pyfunction!(nav::navigate_kf_gins, m)?)?;
    m.add_function(wrap_pyfunction!(nav::horizontal_rms, m)?)?;
    m.add_function(wrap_pyfunction!(
        experiment::experiment_builtin_scenario,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(experiment::experiment_run, m)?)?;
    m.add_function(wrap_pyfunction!(experiment::montecarlo_prepare, m)?)?;
    m.add_function(wrap_pyfunction!(experiment::montecarlo_run_one, m)?)?;
    m.add_function(wrap_pyfunction!(experiment::montecarlo_summarise, m)?)?;
    Ok(())
}

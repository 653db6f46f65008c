//! The `driftless._driftless` Python extension: NumPy arrays in, NumPy arrays and plain
//! Python objects out. Every computation runs with the GIL released
//! ([`Python::detach`]) on a copy of the input, so other Python threads go on and cannot
//! change the samples under the computation. The user-facing API (argument defaults,
//! allantools' tau selection, result classes) is the pure-Python `driftless` package.

mod compat;

use driftless::allan::Estimator;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

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

#[pymodule]
fn _driftless(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(allan_compat, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

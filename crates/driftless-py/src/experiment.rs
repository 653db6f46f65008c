//! `driftless.experiment` and `driftless.montecarlo`: the experiment of
//! `driftless experiment` in one call ([`run_experiment`]), and the same Monte Carlo one
//! run at a time ([`MonteCarloContext::run_one`]) with its statistics from the runs'
//! records ([`summarise_records`]). A run's record crosses to Python as one flat row
//! (column name → number, text or flag) so that rows from many processes or machines
//! tabulate and pickle as they are; [`row_record`] reads such a row back.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use driftless::experiment::monte_carlo::{MonteCarloSummary, run_experiment};
use driftless::experiment::per_run::{
    CaseRecord, MonteCarloContext, RunRecord, SolutionRecord, summarise_records,
};
use driftless::experiment::run::{Case, Prepared};
use driftless::experiment::scenario::BUILTIN_ADI_LIKE;
use driftless::experiment::table::ExperimentDocument;
use driftless::experiment::{ExperimentScenario, prepare};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::value_error;

/// The cases in the order an experiment processes them, with their column prefixes.
const CASES: [(Case, &str); 4] = [
    (Case::Raw, "raw"),
    (Case::RoomBias, "room_bias"),
    (Case::Thermal, "thermal"),
    (Case::RoomFull, "room_full"),
];

fn prefix(case: Case) -> &'static str {
    CASES
        .iter()
        .find(|(c, _)| *c == case)
        .map_or("case", |(_, p)| p)
}

fn prepared(text: &str, name: &str, base_dir: &str) -> PyResult<Prepared> {
    let sc = ExperimentScenario::from_toml_str(text, name, PathBuf::from(base_dir))
        .map_err(value_error)?;
    prepare(sc).map_err(value_error)
}

/// The scenario of `driftless demo` (TOML text).
#[pyfunction]
pub fn experiment_builtin_scenario() -> &'static str {
    BUILTIN_ADI_LIKE
}

/// The checked scenario: its number of runs, seed, and outage windows.
#[pyfunction]
pub fn montecarlo_prepare<'py>(
    py: Python<'py>,
    text: &str,
    name: &str,
    base_dir: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let (text, name, base) = (text.to_owned(), name.to_owned(), base_dir.to_owned());
    let p = py.detach(move || prepared(&text, &name, &base))?;
    let d = PyDict::new(py);
    d.set_item("runs", p.scenario.monte_carlo.runs)?;
    d.set_item("seed", p.scenario.seed)?;
    let windows: Vec<(f64, f64)> = p.windows().iter().map(|w| (w.start_s, w.end_s)).collect();
    d.set_item("outages", windows)?;
    Ok(d)
}

/// The context of the last scenario a process ran (built once per process: the noise
/// stage is the costly part), keyed by scenario text, name and folder.
type Cached = Option<((String, String, String), Arc<MonteCarloContext>)>;
static CONTEXT: Mutex<Cached> = Mutex::new(None);

fn context(text: &str, name: &str, base_dir: &str) -> PyResult<Arc<MonteCarloContext>> {
    let key = (text.to_owned(), name.to_owned(), base_dir.to_owned());
    // Held while building so that threads of one process build it once.
    let mut guard = CONTEXT
        .lock()
        .map_err(|_| value_error("a previous run panicked while building the experiment"))?;
    if let Some((k, ctx)) = guard.as_ref()
        && *k == key
    {
        return Ok(Arc::clone(ctx));
    }
    let ctx =
        Arc::new(MonteCarloContext::new(prepared(text, name, base_dir)?).map_err(value_error)?);
    *guard = Some((key, Arc::clone(&ctx)));
    Ok(ctx)
}

/// Run `run` of the scenario as one flat row.
#[pyfunction]
pub fn montecarlo_run_one<'py>(
    py: Python<'py>,
    text: &str,
    name: &str,
    base_dir: &str,
    run: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, n, b) = (text.to_owned(), name.to_owned(), base_dir.to_owned());
    let (record, outages) = py.detach(move || -> PyResult<_> {
        let ctx = context(&t, &n, &b)?;
        let r = ctx.run_one(run).map_err(value_error)?;
        Ok((RunRecord::from(&r), ctx.prepared.windows().len()))
    })?;
    record_row(py, &record, outages)
}

/// A run's record as a flat row: `run`, the temperature at its start and end, and per
/// case (prefix `raw`, `room_bias`, `thermal`, `room_full`) the forward and smoothed
/// failure message (empty when it ran), mean and per-outage end errors (NaN where
/// missing), whether it was smoothed, and the GNSS counts.
fn record_row<'py>(py: Python<'py>, r: &RunRecord, outages: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("run", r.run)?;
    let (t0, t1) = r.temperature_c.unwrap_or((f64::NAN, f64::NAN));
    d.set_item("temperature_start_c", t0)?;
    d.set_item("temperature_end_c", t1)?;
    for c in &r.cases {
        let p = prefix(c.case);
        let put = |kind: &str, s: Option<&SolutionRecord>| -> PyResult<()> {
            let failure = s.and_then(|s| s.failure.clone()).unwrap_or_default();
            d.set_item(format!("{p}_{kind}_failure"), failure)?;
            let mean = s.and_then(|s| s.mean_end_horizontal_m).unwrap_or(f64::NAN);
            d.set_item(format!("{p}_{kind}_mean_end_m"), mean)?;
            for i in 0..outages {
                let e = s
                    .and_then(|s| s.end_horizontal_m.get(i).copied())
                    .unwrap_or(f64::NAN);
                d.set_item(format!("{p}_{kind}_end_m_{}", i + 1), e)?;
            }
            Ok(())
        };
        put("forward", Some(&c.forward))?;
        put("smoothed", c.smoothed.as_ref())?;
        d.set_item(format!("{p}_smoothed"), c.smoothed.is_some())?;
        d.set_item(format!("{p}_gnss_accepted"), c.gnss_accepted)?;
        d.set_item(format!("{p}_gnss_rejected"), c.gnss_rejected)?;
    }
    Ok(d)
}

fn get<'py, T: FromPyObjectOwned<'py>>(row: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
    match row.get_item(key)? {
        Some(v) => v.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            value_error(format!("run row: column {key:?}: {}", e.value(row.py())))
        }),
        None => Err(value_error(format!("run row: no column {key:?}"))),
    }
}

/// A flat row (as [`record_row`] writes it) read back.
fn row_record(row: &Bound<'_, PyDict>, outages: usize) -> PyResult<RunRecord> {
    let t: (f64, f64) = (
        get(row, "temperature_start_c")?,
        get(row, "temperature_end_c")?,
    );
    let mut cases = Vec::new();
    for (case, p) in CASES {
        if row.get_item(format!("{p}_forward_failure"))?.is_none() {
            continue;
        }
        let solution = |kind: &str| -> PyResult<SolutionRecord> {
            let failure: String = get(row, &format!("{p}_{kind}_failure"))?;
            if !failure.is_empty() {
                return Ok(SolutionRecord {
                    failure: Some(failure),
                    end_horizontal_m: Vec::new(),
                    mean_end_horizontal_m: None,
                });
            }
            let mean: f64 = get(row, &format!("{p}_{kind}_mean_end_m"))?;
            Ok(SolutionRecord {
                failure: None,
                end_horizontal_m: (1..=outages)
                    .map(|i| get(row, &format!("{p}_{kind}_end_m_{i}")))
                    .collect::<PyResult<_>>()?,
                mean_end_horizontal_m: (!mean.is_nan()).then_some(mean),
            })
        };
        let smoothed: bool = get(row, &format!("{p}_smoothed"))?;
        cases.push(CaseRecord {
            case,
            forward: solution("forward")?,
            smoothed: if smoothed {
                Some(solution("smoothed")?)
            } else {
                None
            },
            gnss_accepted: get(row, &format!("{p}_gnss_accepted"))?,
            gnss_rejected: get(row, &format!("{p}_gnss_rejected"))?,
        });
    }
    Ok(RunRecord {
        run: get(row, "run")?,
        temperature_c: (!t.0.is_nan() || !t.1.is_nan()).then_some(t),
        cases,
    })
}

/// The summary as a dict entry: its serde JSON and the per-case table.
fn summary_items(d: &Bound<'_, PyDict>, s: &MonteCarloSummary) -> PyResult<()> {
    d.set_item(
        "summary_json",
        serde_json::to_string(s).map_err(value_error)?,
    )?;
    let (header, rows) = s.table();
    d.set_item("summary_header", header)?;
    d.set_item("summary_rows", rows)?;
    Ok(())
}

/// The statistics of the experiment from the rows of runs 0…K−1.
#[pyfunction]
pub fn montecarlo_summarise<'py>(
    py: Python<'py>,
    text: &str,
    name: &str,
    base_dir: &str,
    rows: &Bound<'py, PyList>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = prepared(text, name, base_dir)?;
    let outages = p.windows().len();
    let records: Vec<RunRecord> = rows
        .iter()
        .map(|r| row_record(r.cast::<PyDict>()?, outages))
        .collect::<PyResult<_>>()?;
    let s = py
        .detach(|| summarise_records(&p, &records))
        .map_err(value_error)?;
    let d = PyDict::new(py);
    summary_items(&d, &s)?;
    Ok(d)
}

/// The whole experiment (`driftless experiment SCENARIO --json`): every run's row, the
/// summary, and the JSON document.
#[pyfunction]
#[pyo3(signature = (text, name, base_dir, runs=None))]
pub fn experiment_run<'py>(
    py: Python<'py>,
    text: &str,
    name: &str,
    base_dir: &str,
    runs: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, n, b) = (text.to_owned(), name.to_owned(), base_dir.to_owned());
    let (p, r) = py.detach(move || -> PyResult<_> {
        let p = prepared(&t, &n, &b)?;
        let r = run_experiment(&p, runs, &|_, _, _| {}).map_err(value_error)?;
        Ok((p, r))
    })?;
    let outages = p.windows().len();
    let d = PyDict::new(py);
    let rows = PyList::empty(py);
    for run in &r.runs {
        rows.append(record_row(py, &RunRecord::from(run), outages)?)?;
    }
    d.set_item("rows", rows)?;
    summary_items(&d, &r.summary)?;
    d.set_item(
        "document_json",
        serde_json::to_string(&ExperimentDocument::new(&p, &r)).map_err(value_error)?,
    )?;
    Ok(d)
}

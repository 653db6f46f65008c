//! `driftless.navigate`: the loosely coupled GNSS/INS filter and its RTS smoother on
//! NumPy columns or on files, with the settings of `driftless nav --config`
//! ([`driftless::nav::config::NavConfig`], given as its serde form) or a KF-GINS YAML
//! (`driftless nav --kf-gins`). The same library calls as the CLI:
//! [`run_nav_job`] for files, [`run_nav_job_in_memory`] for arrays, [`run_kf_gins_job`].

use std::path::{Path, PathBuf};

use driftless::data::{GnssFixes, ImuLog, NavSolution};
use driftless::io::TextOptions;
use driftless::nav::config::{LoadedConfig, NavConfig, Override, key_by_path};
use driftless::nav::filter::N_STATES;
use driftless::nav::filter::run::ForwardRun;
use driftless::nav::filter::state::{ATT, BA, BG, POS, SA, SG, VEL};
use driftless::nav::filter::{SensorErrors, SmoothedRun};
use driftless::nav::job::{NavJobResult, run_nav_job, run_nav_job_in_memory};
use driftless::nav::kfgins_job::{KfGinsJobOptions, run_kf_gins_job};
use driftless::nav::mechanization::NavState;
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{owned, value_error};

/// The default configuration in its serde form (JSON text): the keys a dict may set.
#[pyfunction]
pub fn nav_default_config() -> PyResult<String> {
    serde_json::to_string(&NavConfig::default()).map_err(value_error)
}

/// Loads a configuration: a nav TOML file, or the serde form given as JSON text, with
/// the IMU and GNSS files (when given) set as `--imu`/`--gnss` flags set them (relative
/// to the working directory).
fn load(
    config_json: Option<&str>,
    config_path: Option<&str>,
    files: Option<(&str, &str)>,
) -> PyResult<LoadedConfig> {
    let mut overrides = Vec::new();
    if let Some((imu, gnss)) = files {
        for (key, value) in [("imu.file", imu), ("gnss.file", gnss)] {
            let key = key_by_path(key)
                .ok_or_else(|| value_error(format!("no configuration key {key}")))?;
            overrides.push(Override {
                key,
                value: value.to_owned(),
            });
        }
    }
    let loaded = match (config_json, config_path) {
        (_, Some(path)) => NavConfig::load(Some(Path::new(path)), &overrides),
        (Some(json), None) => {
            let value: serde_json::Value = serde_json::from_str(json).map_err(value_error)?;
            let table =
                toml::Value::try_from(value).map_err(|e| value_error(format!("config: {e}")))?;
            let text = toml::to_string(&table).map_err(|e| value_error(format!("config: {e}")))?;
            NavConfig::load_text(
                Some((text, PathBuf::from("config"), PathBuf::new())),
                &overrides,
            )
        }
        (None, None) => NavConfig::load(None, &overrides),
    };
    loaded.map_err(value_error)
}

/// Columns of a trajectory: time, position, velocity NED, roll/pitch/yaw.
pub(crate) fn trajectory_columns<'py>(
    py: Python<'py>,
    sol: &NavSolution,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let put = |name: &str, v: Vec<f64>| d.set_item(name, v.into_pyarray(py));
    put("time_s", sol.time_s.clone())?;
    put("lat_rad", sol.lat_rad.clone())?;
    put("lon_rad", sol.lon_rad.clone())?;
    put("height_m", sol.height_m.clone())?;
    for (k, n) in ["vel_n_m_s", "vel_e_m_s", "vel_d_m_s"].iter().enumerate() {
        put(n, sol.vel_ned_m_s.iter().map(|v| v[k]).collect())?;
    }
    for (k, n) in ["roll_rad", "pitch_rad", "yaw_rad"].iter().enumerate() {
        put(n, sol.roll_pitch_yaw_rad.iter().map(|v| v[k]).collect())?;
    }
    Ok(d)
}

/// One triad of the sensor-error estimates.
type SensorTriad = fn(&SensorErrors) -> [f64; 3];

/// Columns of a solution: [`trajectory_columns`], and per epoch the estimated sensor
/// errors and the state σ (√diag P).
fn solution_columns<'a, 'py>(
    py: Python<'py>,
    sol: &NavSolution,
    states: impl Iterator<Item = (&'a NavState, &'a SensorErrors, &'a [f64; N_STATES])>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = trajectory_columns(py, sol)?;
    let put = |name: &str, v: Vec<f64>| d.set_item(name, v.into_pyarray(py));
    let rows: Vec<(SensorErrors, [f64; N_STATES])> = states.map(|(_, s, p)| (*s, *p)).collect();
    let sensor_cols: [(&str, SensorTriad); 4] = [
        ("gyro_bias_{}_rad_s", |s| s.gyro_bias_rad_s),
        ("accel_bias_{}_m_s2", |s| s.accel_bias_m_s2),
        ("gyro_scale_{}", |s| s.gyro_scale),
        ("accel_scale_{}", |s| s.accel_scale),
    ];
    for (pattern, f) in sensor_cols {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            put(
                &pattern.replace("{}", axis),
                rows.iter().map(|r| f(&r.0)[k]).collect(),
            )?;
        }
    }
    let std_cols: [(&str, usize, [&str; 3]); 7] = [
        ("sigma_{}_m", POS, ["n", "e", "d"]),
        ("sigma_vel_{}_m_s", VEL, ["n", "e", "d"]),
        ("sigma_att_{}_rad", ATT, ["n", "e", "d"]),
        ("sigma_gyro_bias_{}_rad_s", BG, ["x", "y", "z"]),
        ("sigma_accel_bias_{}_m_s2", BA, ["x", "y", "z"]),
        ("sigma_gyro_scale_{}", SG, ["x", "y", "z"]),
        ("sigma_accel_scale_{}", SA, ["x", "y", "z"]),
    ];
    for (pattern, at, axes) in std_cols {
        for (k, axis) in axes.iter().enumerate() {
            put(
                &pattern.replace("{}", axis),
                rows.iter().map(|r| r.1[at + k]).collect(),
            )?;
        }
    }
    Ok(d)
}

/// The forward (and smoothed) solution columns and the GNSS counts of a run.
fn run_dict<'py>(
    py: Python<'py>,
    run: &ForwardRun,
    smoothed: Option<&SmoothedRun>,
    gnss_fixes: usize,
    start_time_s: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let fwd = run.epochs.iter().map(|e| (&e.nav, &e.sensors, &e.std));
    d.set_item("forward", solution_columns(py, &run.solution(), fwd)?)?;
    if let Some(sm) = smoothed {
        let states = sm.epochs.iter().map(|e| (&e.nav, &e.sensors, &e.std));
        d.set_item("smoothed", solution_columns(py, &sm.solution(), states)?)?;
    }
    d.set_item("gnss_accepted", run.gnss_accepted)?;
    d.set_item("gnss_rejected", run.gnss_rejected)?;
    d.set_item("gnss_withheld", run.gnss_withheld)?;
    d.set_item("gnss_fixes", gnss_fixes)?;
    d.set_item("start_time_s", start_time_s)?;
    Ok(d)
}

/// The dict of a finished job: forward and (when asked) smoothed columns, the counts, the
/// full-GNSS accuracy, the outages and the configuration in effect.
fn job_dict<'py>(
    py: Python<'py>,
    job: &NavJobResult,
    config: &LoadedConfig,
    smooth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let s = &job.session;
    let run = &s.run;
    let smoothed = if smooth {
        Some(py.detach(|| s.smooth()).map_err(value_error)?)
    } else {
        None
    };
    let d = run_dict(
        py,
        run,
        smoothed.as_ref(),
        job.fixes.time_s.len(),
        s.init.nav.time_s,
    )?;
    d.set_item("prediction_rms_m", s.horizontal_rms_m.map(|r| r.0))?;
    d.set_item("prediction_rms_fixes", s.horizontal_rms_m.map(|r| r.1))?;
    let outages: Vec<(f64, f64, Option<f64>, f64)> = s
        .outages
        .iter()
        .map(|o| {
            (
                o.window.start_s,
                o.window.end_s,
                o.end_horizontal_m,
                o.max_horizontal_m,
            )
        })
        .collect();
    d.set_item("outages", outages)?;
    d.set_item("notes", job.notes.clone())?;
    d.set_item(
        "config_json",
        serde_json::to_string(&config.config).map_err(value_error)?,
    )?;
    Ok(d)
}

fn triads(cols: &[PyReadonlyArray1<'_, f64>]) -> Vec<[f64; 3]> {
    let v: Vec<Vec<f64>> = cols.iter().map(owned).collect();
    (0..v[0].len())
        .map(|i| [v[0][i], v[1][i], v[2][i]])
        .collect()
}

/// Navigation on columns in memory. `imu` = time, gyro x/y/z (rad/s), accel x/y/z
/// (m/s²); `gnss` = time, lat, lon (rad), height (m), σ N/E/D (m); `gnss_velocity` =
/// velocity N/E/D and its σ (m/s). Lengths were checked by the caller.
#[pyfunction]
#[pyo3(signature = (config_json, config_path, imu, gnss, gnss_velocity, smooth))]
#[allow(clippy::type_complexity)]
pub fn navigate_arrays<'py>(
    py: Python<'py>,
    config_json: Option<&str>,
    config_path: Option<&str>,
    imu: Vec<PyReadonlyArray1<'py, f64>>,
    gnss: Vec<PyReadonlyArray1<'py, f64>>,
    gnss_velocity: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    smooth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if imu.len() != 7 || gnss.len() != 7 || gnss_velocity.as_ref().is_some_and(|v| v.len() != 6) {
        return Err(value_error("navigate_arrays: wrong number of columns"));
    }
    let cfg = load(config_json, config_path, None)?;
    let log = ImuLog::from_rates(
        "imu",
        owned(&imu[0]),
        &triads(&imu[1..4]),
        &triads(&imu[4..7]),
    )
    .map_err(value_error)?;
    let mut fixes = GnssFixes::new(
        owned(&gnss[0]),
        owned(&gnss[1]),
        owned(&gnss[2]),
        owned(&gnss[3]),
        triads(&gnss[4..7]),
    )
    .map_err(value_error)?;
    if let Some(v) = &gnss_velocity {
        fixes = fixes
            .with_velocity(triads(&v[0..3]), triads(&v[3..6]))
            .map_err(value_error)?;
    }
    let job = py
        .detach(|| run_nav_job_in_memory(&cfg, &log, fixes))
        .map_err(value_error)?;
    job_dict(py, &job, &cfg, smooth)
}

/// Navigation on files, as `driftless nav --imu IMU --gnss GNSS [--config FILE]` reads
/// them (a rates CSV's first column is its time).
#[pyfunction]
#[pyo3(signature = (config_json, config_path, imu_path, gnss_path, smooth))]
pub fn navigate_files<'py>(
    py: Python<'py>,
    config_json: Option<&str>,
    config_path: Option<&str>,
    imu_path: &str,
    gnss_path: &str,
    smooth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let cfg = load(config_json, config_path, Some((imu_path, gnss_path)))?;
    let csv = TextOptions {
        time_column: Some("1".parse().map_err(value_error)?),
        ..TextOptions::default()
    };
    let job = py.detach(|| run_nav_job(&cfg, &csv)).map_err(value_error)?;
    job_dict(py, &job, &cfg, smooth)
}

/// A KF-GINS configuration run as `driftless nav --kf-gins CONFIG` runs it (its three
/// output files, and with `smooth` the smoothed ones, written to its `outputpath`); the
/// columns are every epoch of the run, the initial one included, yaw in (−π, π].
#[pyfunction]
#[pyo3(signature = (path, outages, gate, smooth))]
pub fn navigate_kf_gins<'py>(
    py: Python<'py>,
    path: &str,
    outages: &str,
    gate: Option<&str>,
    smooth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = KfGinsJobOptions {
        outages: outages
            .parse()
            .map_err(|e| value_error(format!("outages {outages:?}: {e}")))?,
        gate: gate
            .map(|g| {
                g.parse()
                    .map_err(|e| value_error(format!("gate {g:?}: {e}")))
            })
            .transpose()?,
        smooth,
        keep_records: true,
    };
    let path = PathBuf::from(path);
    let job = py
        .detach(|| run_kf_gins_job(&path, &opts))
        .map_err(value_error)?;
    let d = run_dict(
        py,
        &job.run,
        job.smoothed.as_ref(),
        job.gnss_fixes,
        job.start_time_s,
    )?;
    d.set_item("notes", job.notes.clone())?;
    let files: Vec<String> = (job.files.iter().chain(job.smoothed_files.iter().flatten()))
        .map(|p| p.display().to_string())
        .collect();
    d.set_item("files", files)?;
    Ok(d)
}

fn trajectory(cols: &[PyReadonlyArray1<'_, f64>]) -> NavSolution {
    let n = cols[0].len().unwrap_or(0);
    NavSolution {
        time_s: owned(&cols[0]),
        lat_rad: owned(&cols[1]),
        lon_rad: owned(&cols[2]),
        height_m: owned(&cols[3]),
        vel_ned_m_s: vec![[0.0; 3]; n],
        roll_pitch_yaw_rad: vec![[0.0; 3]; n],
    }
}

/// Horizontal RMS error of a solution (time, lat, lon, height) against a reference (the
/// same columns) over the solution epochs at or after `from_s`
/// ([`driftless::eval::accuracy::horizontal_rms_m`]): (RMS in m, epochs).
#[pyfunction]
pub fn horizontal_rms<'py>(
    py: Python<'py>,
    reference: Vec<PyReadonlyArray1<'py, f64>>,
    solution: Vec<PyReadonlyArray1<'py, f64>>,
    from_s: f64,
    max_reference_gap_s: f64,
) -> PyResult<(f64, usize)> {
    if reference.len() != 4 || solution.len() != 4 {
        return Err(value_error(
            "horizontal_rms: expected time, lat, lon, height columns",
        ));
    }
    let (r, s) = (trajectory(&reference), trajectory(&solution));
    py.detach(|| driftless::eval::accuracy::horizontal_rms_m(&r, &s, from_s, max_reference_gap_s))
        .map_err(value_error)
}

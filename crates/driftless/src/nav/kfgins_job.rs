//! A KF-GINS job (i2Nav-WHU/KF-GINS, GPL-3.0): its YAML configuration, IMU and GNSS text
//! files in, its three output files out — KF-GINS's semantics, this crate's filter.
//! Behaviour learnt from KF-GINS's `src/kf_gins.cpp`, `src/kf-gins/gi_engine.{h,cpp}`,
//! `src/common/rotation.h` and `src/fileio/*`; no code taken.
//!
//! # What is as in KF-GINS
//!
//! * **Start.** The initial state of the configuration is the state at the first IMU epoch
//!   at or after `starttime` (KF-GINS skips IMU records while `time < starttime` and uses
//!   that record only as the previous sample of the two-sample corrections). GNSS fixes
//!   at or before `starttime` are not used (KF-GINS skips fixes while
//!   `time <= starttime`), so the first update is with the first fix strictly after it
//!   ([`RunOptions::skip_gnss_until_s`]).
//! * **End.** IMU epochs up to and including `endtime` (< 0: the end of the IMU file).
//! * **Updates.** Position updates with the file's σ, no χ² gate and no gate recovery
//!   ([`KfGinsJobOptions::gate`] `None`). A fix between two IMU epochs: the increment is
//!   split at the fix time (linear interpolation, as KF-GINS's `imuInterpolate`), the
//!   filter predicts to the fix, updates, and predicts the rest of the increment.
//! * **Output rows.** One row per IMU epoch after the initial one, at that epoch's time
//!   stamp: the state after any update at or before it ([`RunOptions::observe_split_points`]
//!   false; the states at split points are not written, nor is the initial state, as in
//!   KF-GINS, which writes after processing each IMU record). Row count = IMU epochs in
//!   (initial epoch, `endtime`].
//! * **Formats.** `KF_GINS_Navresult.nav`, `KF_GINS_IMU_ERR.txt`, `KF_GINS_STD.txt` in
//!   `outputpath`, every value `%-15.9lf ` ([`crate::io::nav::kfgins`]), GPS week 0, yaw in
//!   \[0°, 360°) ([`kfgins_heading_rad`]).
//! * **IMU gaps** are integrated across (KF-GINS takes dt from the time tags), with a note.
//!
//! # Remaining differences from KF-GINS
//!
//! 1. Noise per sensor, not per axis: KF-GINS's three-axis ARW, VRW and Gauss–Markov σ's
//!    become one value per sensor, the largest axis (the initial σ's stay per axis).
//! 2. A fix within 1 ms of an IMU epoch but not on it (more than 1 µs away) is applied by
//!    splitting the increment; KF-GINS (`TIME_ALIGN_ERR` = 1 ms) applies it at the nearer
//!    epoch without interpolation.
//! 3. More than one fix inside one IMU interval: each is used; KF-GINS uses at most one
//!    per IMU epoch.
//! 4. `starttime` before the first IMU epoch: KF-GINS refuses the configuration ("Process
//!    time ERROR"); here the initial state is taken at `starttime` and the first increment
//!    is integrated from it, with a note.
//! 5. Inputs are checked (KF-GINS feeds every field to `strtod`): a malformed line is an
//!    error naming file, line and column; an IMU file without a final newline keeps its
//!    last record (KF-GINS drops it).
//! 6. Covariance health: P is checked for symmetry and positive definiteness and a failure
//!    stops the run with a diagnosis; KF-GINS checks only that the diagonal is ≥ 0.
//!
//! # Additions (off by default)
//!
//! Outage windows ([`KfGinsJobOptions::outages`]: fixes inside are withheld), a χ² gate
//! ([`KfGinsJobOptions::gate`]), and the RTS smoother ([`KfGinsJobOptions::smooth`]), whose
//! solution is written beside the forward files in the same three formats, with the same
//! rows, as `KF_GINS_Navresult_smoothed.nav`, `KF_GINS_IMU_ERR_smoothed.txt` and
//! `KF_GINS_STD_smoothed.txt` (`SMOOTHED_SUFFIX`).
//!
//! # Speed
//!
//! The IMU text is parsed in parallel blocks; the filter runs on the calling thread and
//! hands blocks of settled records to a second thread that formats each record straight
//! into the three files' buffers ([`KfGinsOutputWriter::append_row`]) and writes them
//! while the filter runs; record buffers are recycled between the two, and the records
//! are dropped once written unless smoothing or [`KfGinsJobOptions::keep_records`] asks
//! for them.

use std::path::{Path, PathBuf};
use std::sync::mpsc;

use super::filter::model::{FilterConfig, GaussMarkov, ImuNoise};
use super::filter::run::{
    EpochRecord, ForwardRun, InitialState, OBSERVER_BLOCK, RunOptions, run_forward_with,
};
use super::filter::smoother::{SmoothedRun, smooth};
use super::filter::state::SensorErrors;
use super::filter::{N_STATES, NavError};
use super::mechanization::NavState;
use super::outage::{OutageError, OutageItem, OutageSpec, OutageStart};
use super::pipeline::{
    GnssOutsideImu, ImuGapPolicy, ImuStreamOptions, PipelineError, imu_from_kfgins, select_gnss,
};
use super::session::state_solution_records;
use crate::eval::{EvalError, SelectOptions, SelectedOutage};
use crate::io::LogError;
use crate::io::nav::kfgins::{GnssReadOptions, SMOOTHED_SUFFIX, kfgins_heading_rad};
use crate::io::nav::{
    GnssFixes, ImuErrors, KfGinsConfig, KfGinsOutputWriter, KfGinsRow, NavSolution, NavStd,
    read_kfgins_gnss_file, read_kfgins_imu_file,
};

/// Options of [`run_kf_gins_job`].
#[derive(Clone, Debug, PartialEq)]
pub struct KfGinsJobOptions {
    /// GNSS outage windows (fixes inside are withheld); `auto:` windows are chosen on the
    /// fixes inside the IMU span ([`resolve_auto_outages`]). Default none.
    pub outages: OutageSpec,
    /// Innovation gate with the filter's gate-recovery rule
    /// ([`FilterConfig::gate_recovery_s`], 3 s). `None` (default): no gate and no
    /// recovery, as KF-GINS.
    pub gate: Option<crate::nav::filter::model::Gate>,
    /// Also run the RTS smoother and write its solution (`SMOOTHED_SUFFIX` files).
    pub smooth: bool,
    /// Keep the forward records in [`KfGinsJob::run`] (e.g. for further outputs); implied
    /// by `smooth`.
    pub keep_records: bool,
}

impl Default for KfGinsJobOptions {
    fn default() -> Self {
        KfGinsJobOptions {
            outages: OutageSpec::None,
            gate: None,
            smooth: false,
            keep_records: false,
        }
    }
}

/// What [`run_kf_gins_job`] produced.
#[derive(Clone, Debug)]
pub struct KfGinsJob {
    /// The forward run: counts, update records, and the epoch records when kept
    /// (otherwise only the last, [`ForwardRun::first_epoch`]).
    pub run: ForwardRun,
    /// The smoothed run (aligned with `run.epochs`), with [`KfGinsJobOptions::smooth`].
    pub smoothed: Option<SmoothedRun>,
    /// The three forward files: `.nav`, IMU error, std.
    pub files: [PathBuf; 3],
    /// The three smoothed files, with [`KfGinsJobOptions::smooth`].
    pub smoothed_files: Option<[PathBuf; 3]>,
    /// Rows in each output file (= IMU epochs after the initial one).
    pub rows: usize,
    /// Time of the initial state, s (the first IMU epoch at or after `starttime`).
    pub start_time_s: f64,
    /// Nominal IMU interval, s.
    pub dt_s: f64,
    /// IMU epochs read.
    pub imu_epochs: usize,
    /// GNSS fixes read.
    pub gnss_fixes: usize,
    /// Automatically chosen outage windows (`auto:` outages).
    pub outage_selection: Option<Vec<SelectedOutage>>,
    /// Notes for the user (unknown keys, IMU gaps bridged, start before the IMU data).
    pub notes: Vec<String>,
    /// The initial state and filter configuration used (to smooth again or compare).
    pub init: InitialState,
    /// Filter configuration used.
    pub config: FilterConfig,
}

impl KfGinsJob {
    /// The rows of the forward files (KF-GINS heading range), when the records were kept.
    pub fn solution(&self) -> Option<(NavSolution, ImuErrors, NavStd)> {
        if self.run.first_epoch != 0 {
            return None;
        }
        let rows = output_rows(&self.run);
        Some(kfgins_rows(
            rows.map(|k| &self.run.epochs[k])
                .map(|e| (&e.nav, &e.sensors, &e.std)),
        ))
    }
}

/// Errors of [`run_kf_gins_job`]; each message names the file, time or option at fault.
#[derive(Debug, thiserror::Error)]
pub enum KfGinsJobError {
    /// Reading the configuration or a data file, or writing an output file.
    #[error(transparent)]
    Io(#[from] Box<LogError>),
    /// Turning the IMU file into a stream, or selecting the fixes.
    #[error(transparent)]
    Pipeline(#[from] Box<PipelineError>),
    /// Outage specification.
    #[error("outages: {0}")]
    Outage(#[from] OutageError),
    /// Automatic outage selection.
    #[error("outages auto: {0}")]
    Auto(#[from] EvalError),
    /// The filter or the smoother.
    #[error(transparent)]
    Nav(#[from] NavError),
    /// The configuration's time span does not fit the IMU data.
    #[error("{config}: {message}")]
    TimeSpan {
        /// Configuration file.
        config: String,
        /// What is wrong and what to change.
        message: String,
    },
    /// The GNSS file's position at the start disagrees with the configured initial
    /// position: a GNSS file of another trajectory, or a wrong `initpos`.
    #[error("{config}: {message}")]
    InitialPosition {
        /// Configuration file.
        config: String,
        /// What disagrees and what to check.
        message: String,
    },
    /// The output folder: it cannot be created, or another run is writing it.
    #[error(transparent)]
    OutputFolder(#[from] crate::io::output::OutputError),
    /// The output writer thread stopped abnormally.
    #[error("the output writer thread panicked")]
    WriterPanicked,
}

impl From<LogError> for KfGinsJobError {
    fn from(e: LogError) -> Self {
        KfGinsJobError::Io(Box::new(e))
    }
}

impl From<PipelineError> for KfGinsJobError {
    fn from(e: PipelineError) -> Self {
        KfGinsJobError::Pipeline(Box::new(e))
    }
}

/// `auto:NxL` outages chosen on `fixes` (the GNSS track is the only reference of a
/// recorded drive) before any filtering, so an impossible request fails at once; returned
/// as absolute windows with the selection. Other specifications pass through unchanged.
pub fn resolve_auto_outages(
    spec: OutageSpec,
    fixes: &GnssFixes,
) -> Result<(OutageSpec, Option<Vec<SelectedOutage>>), EvalError> {
    if !matches!(spec, OutageSpec::Auto { .. }) {
        return Ok((spec, None));
    }
    let reference = crate::eval::reference::reference_from_fixes(fixes)?;
    let sel = crate::eval::resolve_outages(&spec, &reference, &SelectOptions::default())?;
    let items = sel
        .iter()
        .map(|s| OutageItem {
            start: OutageStart::Gps(s.window.start_s),
            length_s: s.window.duration_s(),
        })
        .collect();
    Ok((OutageSpec::Windows(items), Some(sel)))
}

/// Largest absolute value of three.
fn max3(v: [f64; 3]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The filter's noise model from KF-GINS's per-axis noise (the largest axis per sensor).
fn filter_noise(k: &KfGinsConfig) -> ImuNoise {
    let n = &k.imu_noise;
    let gm = |sigma: [f64; 3]| GaussMarkov {
        sigma: max3(sigma),
        tau_s: n.corr_time_s,
    };
    ImuNoise {
        gyro_arw_rad_sqrt_s: max3(n.arw_rad_sqrt_s),
        accel_vrw_m_s_sqrt_s: max3(n.vrw_m_s_sqrt_s),
        gyro_bias: gm(n.gyro_bias_std_rad_s),
        accel_bias: gm(n.accel_bias_std_m_s2),
        gyro_scale: gm(n.gyro_scale_std),
        accel_scale: gm(n.accel_scale_std),
    }
}

/// The configuration's initial state at `time_s`.
fn initial_state(k: &KfGinsConfig, time_s: f64) -> InitialState {
    let [r, p, y] = k.init_roll_pitch_yaw_rad;
    let nav = NavState {
        time_s,
        lat_rad: k.init_lat_rad,
        lon_rad: k.init_lon_rad,
        height_m: k.init_height_m,
        vel_ned_m_s: k.init_vel_ned_m_s,
        q_bn: super::attitude::Euler {
            roll_rad: r,
            pitch_rad: p,
            yaw_rad: y,
        }
        .to_quat(),
    };
    let mut s = [0.0; 12];
    for (i, v) in [
        k.init_gyro_bias_std_rad_s,
        k.init_accel_bias_std_m_s2,
        k.init_gyro_scale_std,
        k.init_accel_scale_std,
    ]
    .iter()
    .enumerate()
    {
        s[3 * i..3 * i + 3].copy_from_slice(v);
    }
    InitialState {
        nav,
        sensors: SensorErrors {
            gyro_bias_rad_s: k.init_gyro_bias_rad_s,
            accel_bias_m_s2: k.init_accel_bias_m_s2,
            gyro_scale: k.init_gyro_scale,
            accel_scale: k.init_accel_scale,
        },
        sigma_pos_ned_m: k.init_pos_std_ned_m,
        sigma_vel_ned_m_s: k.init_vel_std_ned_m_s,
        sigma_att_rad: k.init_att_std_rad,
        sigma_sensors: Some(s),
    }
}

/// Indices into `run.epochs` of the records KF-GINS writes: every record after the
/// initial one except the split points (records kept).
fn output_rows(run: &ForwardRun) -> impl Iterator<Item = usize> + '_ {
    let mut splits = run.split_points.iter().copied().peekable();
    (1..run.epochs.len()).filter(move |&k| {
        while splits.peek().is_some_and(|&s| s < k) {
            splits.next();
        }
        splits.peek() != Some(&k)
    })
}

/// Output rows of states, heading in KF-GINS's range.
fn kfgins_rows<'a>(
    states: impl Iterator<Item = (&'a NavState, &'a SensorErrors, &'a [f64; N_STATES])>,
) -> (NavSolution, ImuErrors, NavStd) {
    let (mut sol, err, std) = state_solution_records(states);
    for a in &mut sol.roll_pitch_yaw_rad {
        a[2] = kfgins_heading_rad(a[2]);
    }
    (sol, err, std)
}

/// One output row of a state, as [`kfgins_rows`] gives it: attitude as Euler angles of
/// the attitude matrix (`Euler::from_dcm`), heading in KF-GINS's range.
fn kfgins_row(n: &NavState, sensors: &SensorErrors, sd: &[f64; N_STATES]) -> KfGinsRow {
    use super::filter::state::{ATT, BA, BG, POS, SA, SG, VEL};
    let att = super::attitude::Euler::from_dcm(&n.q_bn.to_dcm());
    let tri = |i: usize| [sd[i], sd[i + 1], sd[i + 2]];
    KfGinsRow {
        time_s: n.time_s,
        lat_rad: n.lat_rad,
        lon_rad: n.lon_rad,
        height_m: n.height_m,
        vel_ned_m_s: n.vel_ned_m_s,
        roll_pitch_yaw_rad: [att.roll_rad, att.pitch_rad, kfgins_heading_rad(att.yaw_rad)],
        gyro_bias_rad_s: sensors.gyro_bias_rad_s,
        accel_bias_m_s2: sensors.accel_bias_m_s2,
        gyro_scale: sensors.gyro_scale,
        accel_scale: sensors.accel_scale,
        std_pos_ned_m: tri(POS),
        std_vel_ned_m_s: tri(VEL),
        std_att_rad: tri(ATT),
        std_gyro_bias_rad_s: tri(BG),
        std_accel_bias_m_s2: tri(BA),
        std_gyro_scale: tri(SG),
        std_accel_scale: tri(SA),
    }
}

/// Run the KF-GINS configuration at `config_path` with `opts` (module docs): read it and
/// its IMU and GNSS files (paths as written, i.e. relative to the working directory, as
/// KF-GINS), run the forward filter while writing KF-GINS's three output files into its
/// `outputpath` (created if missing, and locked against other runs while this one
/// writes: [`crate::io::output::lock_folder`]), and with [`KfGinsJobOptions::smooth`] the smoother
/// and its three files.
pub fn run_kf_gins_job(
    config_path: &Path,
    opts: &KfGinsJobOptions,
) -> Result<KfGinsJob, KfGinsJobError> {
    let k = KfGinsConfig::from_file(config_path)?;
    // Held until the last file is committed: a second run into the folder fails at once.
    let _lock = crate::io::output::lock_folder(&k.output_dir)?;
    let cfg_name = config_path.display().to_string();
    let mut notes: Vec<String> = k
        .unknown_keys
        .iter()
        .map(|key| format!("{cfg_name}: key `{key}` is not used by KF-GINS and is ignored"))
        .collect();
    let inc = read_kfgins_imu_file(&k.imu_path)?;
    let imu_name = k.imu_path.display().to_string();
    // KF-GINS integrates across missing IMU samples; so does this job, and says so.
    let imu = imu_from_kfgins(
        &inc,
        &imu_name,
        &ImuStreamOptions {
            gap_policy: ImuGapPolicy::Bridge,
            ..ImuStreamOptions::default()
        },
    )?;
    drop(inc);
    for g in imu.gaps.iter().take(20) {
        notes.push(format!(
            "{imu_name}: IMU gap of {:.4} s before t = {:.4} s (epoch {}): integrated across, as KF-GINS does",
            g.gap_s,
            g.time_s,
            g.index + 1
        ));
    }
    if imu.gaps.len() > 20 {
        notes.push(format!("… {} more IMU gaps", imu.gaps.len() - 20));
    }
    let gnss = read_kfgins_gnss_file(&k.gnss_path, &GnssReadOptions::default())?;

    // Time span, as KF-GINS: the initial state at the first IMU epoch ≥ starttime, epochs
    // up to endtime.
    let span_err = |message: String| KfGinsJobError::TimeSpan {
        config: cfg_name.clone(),
        message,
    };
    let (first_t, last_t) = match (imu.epochs.first(), imu.epochs.last()) {
        (Some(a), Some(b)) => (a.time_s, b.time_s),
        _ => return Err(span_err(format!("{imu_name} has no IMU epochs"))),
    };
    let start = k.start_time_s;
    let end = k.end_time_s.unwrap_or(f64::INFINITY);
    if end < start {
        return Err(span_err(format!(
            "endtime {end} s is before starttime {start} s: set endtime ≥ starttime, or −1 for the end of the IMU file"
        )));
    }
    let i0 = imu.epochs.partition_point(|e| e.time_s < start);
    let t_init = if start < first_t {
        notes.push(format!(
            "{cfg_name}: starttime {start} s is before the first IMU epoch ({first_t} s) of {imu_name}; \
             KF-GINS refuses this (\"Process time ERROR\"), this run takes the initial state at starttime"
        ));
        start
    } else if i0 < imu.epochs.len() && imu.epochs[i0].time_s <= end {
        imu.epochs[i0].time_s
    } else {
        return Err(span_err(format!(
            "no IMU epoch of {imu_name} ({first_t}–{last_t} s) in starttime {start} s – endtime {end} s"
        )));
    };
    let n_end = imu.epochs.partition_point(|e| e.time_s <= end);
    let epochs = &imu.epochs[..n_end];

    let mut cfg = FilterConfig::new(filter_noise(&k), k.antenna_lever_frd_m);
    match opts.gate {
        Some(g) => cfg.gate = g,
        None => {
            cfg.gate = crate::nav::filter::model::Gate::Off;
            cfg.gate_recovery_s = None;
        }
    }
    if let Some(longest) = imu.gaps.iter().map(|g| g.gap_s).reduce(f64::max) {
        cfg.max_gap_factor = cfg.max_gap_factor.max(1.01 * longest / imu.nominal_dt_s);
    }
    let mut outage_selection = None;
    if opts.outages != OutageSpec::None {
        let in_span = select_gnss(&gnss, &imu, &OutageSpec::None, GnssOutsideImu::Drop)?;
        let (spec, selection) = resolve_auto_outages(opts.outages.clone(), &in_span.fixes)?;
        outage_selection = selection;
        let sel = select_gnss(&gnss, &imu, &spec, GnssOutsideImu::Drop)?;
        cfg.outages_s = sel.windows.iter().map(|w| (w.start_s, w.end_s)).collect();
    }
    check_initial_position(&k, &gnss, t_init, &cfg_name)?;
    let init = initial_state(&k, t_init);

    let keep = opts.smooth || opts.keep_records;
    let run_opts = RunOptions {
        keep_epochs: keep,
        observe_split_points: false,
        skip_gnss_until_s: Some(start),
    };
    let (run, files, rows) = forward_writing(epochs, &gnss, init, &cfg, &run_opts, &k.output_dir)?;

    let (smoothed, smoothed_files) = if opts.smooth {
        let s = smooth(&run, &init, &cfg)?;
        let mut w = KfGinsOutputWriter::create_with_suffix(&k.output_dir, 0, SMOOTHED_SUFFIX)?;
        for e in output_rows(&run).map(|i| &s.epochs[i]) {
            w.append_row(&kfgins_row(&e.nav, &e.sensors, &e.std))?;
        }
        (Some(s), Some(w.finish()?))
    } else {
        (None, None)
    };
    Ok(KfGinsJob {
        run,
        smoothed,
        files,
        smoothed_files,
        rows,
        start_time_s: t_init,
        dt_s: imu.nominal_dt_s,
        imu_epochs: imu.len(),
        gnss_fixes: gnss.len(),
        outage_selection,
        notes,
        init,
        config: cfg,
    })
}

/// Fixes within this many seconds of the start are compared with `initpos`.
const INITPOS_CHECK_WINDOW_S: f64 = 5.0;

/// Refuses a run whose GNSS fix nearest the start (within [`INITPOS_CHECK_WINDOW_S`]) lies
/// farther from `initpos` than any consistent pair could: 500 m, plus five times the
/// configured and the fix's horizontal σ, plus the distance the vehicle can cover in the
/// time between them at the initial speed + 50 m/s. KF-GINS would start from `initpos`
/// and be pulled to the other trajectory's fixes, a solution of neither.
fn check_initial_position(
    k: &KfGinsConfig,
    gnss: &GnssFixes,
    t_init: f64,
    cfg_name: &str,
) -> Result<(), KfGinsJobError> {
    let Some(i) = (0..gnss.len())
        .filter(|&i| (gnss.time_s[i] - t_init).abs() <= INITPOS_CHECK_WINDOW_S)
        .min_by(|&a, &b| {
            (gnss.time_s[a] - t_init)
                .abs()
                .total_cmp(&(gnss.time_s[b] - t_init).abs())
        })
    else {
        return Ok(());
    };
    let d = crate::nav::earth::ned_offset_m(
        (k.init_lat_rad, k.init_lon_rad, k.init_height_m),
        (gnss.lat_rad[i], gnss.lon_rad[i], gnss.height_m[i]),
    );
    let horizontal_m = d[0].hypot(d[1]);
    let sigma_h = |s: [f64; 3]| s[0].hypot(s[1]);
    let v = k.init_vel_ned_m_s;
    let speed = v[0].hypot(v[1]);
    let dt = (gnss.time_s[i] - t_init).abs();
    let allowed = 500.0
        + 5.0 * (sigma_h(k.init_pos_std_ned_m) + sigma_h(gnss.sigma_ned_m[i]))
        + dt * (speed + 50.0);
    if horizontal_m.is_finite() && horizontal_m <= allowed {
        return Ok(());
    }
    Err(KfGinsJobError::InitialPosition {
        config: cfg_name.to_owned(),
        message: format!(
            "the GNSS fix at {} s in {} is {:.1} km from initpos (at most {:.1} km fits the \
             σ and the time between them): the GNSS file belongs to another trajectory, or \
             initpos is wrong; check gnsspath and initpos",
            gnss.time_s[i],
            k.gnss_path.display(),
            horizontal_m / 1e3,
            allowed / 1e3
        ),
    })
}

/// The forward filter on this thread; the three output files created (truncating an
/// earlier run's), formatted and written on another from blocks of the records KF-GINS
/// writes (the initial record and split points left out). Block buffers go back to the
/// filter for reuse, so an hour of records is not allocated (and page-faulted) anew.
fn forward_writing(
    epochs: &[crate::nav::mechanization::ImuIncrement],
    gnss: &GnssFixes,
    init: InitialState,
    cfg: &FilterConfig,
    run_opts: &RunOptions,
    out_dir: &Path,
) -> Result<(ForwardRun, [PathBuf; 3], usize), KfGinsJobError> {
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::sync_channel::<Vec<EpochRecord>>(4);
        let (back_tx, back_rx) = mpsc::channel::<Vec<EpochRecord>>();
        let formatter = scope.spawn(move || -> Result<([PathBuf; 3], usize), LogError> {
            let mut writer = KfGinsOutputWriter::create(out_dir, 0)?;
            let mut rows = 0;
            for mut block in rx {
                for e in &block {
                    writer.append_row(&kfgins_row(&e.nav, &e.sensors, &e.std))?;
                }
                rows += block.len();
                block.clear();
                // The filter may have finished: then the buffer is simply dropped.
                let _ = back_tx.send(block);
            }
            Ok((writer.finish()?, rows))
        });
        let mut initial = true;
        let mut buf: Vec<EpochRecord> = Vec::with_capacity(2 * OBSERVER_BLOCK);
        let run = run_forward_with(epochs, gnss, init, cfg, run_opts, &mut |b| {
            // The first record handed out is the initial state: KF-GINS does not write it.
            let b = if std::mem::take(&mut initial) {
                &b[1..]
            } else {
                b
            };
            buf.extend_from_slice(b);
            if buf.len() >= OBSERVER_BLOCK {
                let next = back_rx
                    .try_recv()
                    .unwrap_or_else(|_| Vec::with_capacity(2 * OBSERVER_BLOCK));
                // A send fails only when the formatter has stopped on an error, which
                // `join` reports below.
                let _ = tx.send(std::mem::replace(&mut buf, next));
            }
        });
        if !buf.is_empty() {
            let _ = tx.send(buf);
        }
        drop(tx);
        let written = formatter
            .join()
            .map_err(|_| KfGinsJobError::WriterPanicked)?;
        let run = run?;
        let (files, rows) = written?;
        Ok((run, files, rows))
    })
}

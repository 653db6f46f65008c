//! One navigation job from a [`crate::nav::config`] configuration: read the IMU and GNSS
//! files it names, check the IMU values ([`crate::nav::imu_check`]: a non-physical sample
//! stops the job unless `imu.repair_spikes` replaces isolated ones by interpolation), build
//! the filter and session settings, choose the outages, run
//! [`crate::nav::session::run_session`]. The CLI's `driftless nav` is this call plus
//! printing.

use std::path::{Path, PathBuf};

use crate::eval::SelectedOutage;
use crate::io::TextOptions;
use crate::io::nav::GnssFixes;
use crate::io::nav::kfgins::GnssReadOptions;
use crate::io::probe::{self, PathKind};
use crate::nav::config::{ConfigError, KeyError, LoadedConfig};
use crate::nav::filter::aids::{NhcConfig, StandstillConfig};
use crate::nav::filter::model::{FilterConfig, ImuNoise};
use crate::nav::imu_check::{ImuCheckReport, check_imu, non_physical_error, repair_spikes};
use crate::nav::outage::OutageSpec;
use crate::nav::pipeline::{
    GnssOutsideImu, ImuStream, PipelineError, RateChannels, TaggedCsvOptions, imu_from_kfgins,
    imu_from_rates_log, imu_from_tagged_csv_files, read_gnss_file, select_gnss, subset_fixes,
};
use crate::nav::session::{SessionConfig, SessionResult, run_session};

/// Why a job could not run.
#[derive(Debug, thiserror::Error)]
pub enum NavJobError {
    /// A configuration value (located).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// An input file or its timing.
    #[error(transparent)]
    Input(#[from] PipelineError),
    /// Reading a log (the CSV path). Boxed: [`crate::io::LogError`] is large.
    #[error(transparent)]
    Read(Box<crate::io::LogError>),
    /// The calibration model file.
    #[error(transparent)]
    Calibration(#[from] crate::calib::model_file::ModelFileError),
    /// The noise model file.
    #[error(transparent)]
    NoiseModel(#[from] crate::allan::noise_model::NoiseModelError),
    /// Choosing the outages.
    #[error("outages: {0}")]
    Outages(#[from] crate::eval::EvalError),
    /// The filter or the session.
    #[error(transparent)]
    Nav(#[from] crate::nav::filter::NavError),
    /// IMU values navigation refuses (non-physical, not repaired), with the report of
    /// every finding.
    #[error("{error}")]
    ImuValues {
        /// The first refused value, naming time, channel and the repair option.
        error: Box<crate::nav::imu_check::ImuCheckError>,
        /// Every finding of the check.
        report: Box<ImuCheckReport>,
    },
}

impl From<crate::io::LogError> for NavJobError {
    fn from(e: crate::io::LogError) -> Self {
        NavJobError::Read(Box::new(e))
    }
}

/// The IMU reader a job uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImuFormat {
    /// KF-GINS increments.
    Kfgins,
    /// RTKLIB-tagged CSV with a `.tag` file.
    TaggedCsv,
    /// Delimited text of rates with units.
    Csv,
}

/// What a job produced.
#[derive(Debug)]
pub struct NavJobResult {
    /// The IMU stream navigated (after time offset and mounting).
    pub imu: ImuStream,
    /// The IMU reader used.
    pub imu_format: ImuFormat,
    /// GNSS fixes inside the IMU span that passed the quality filter.
    pub fixes: GnssFixes,
    /// Fixes dropped by the quality filter.
    pub dropped_by_quality: usize,
    /// The session's result.
    pub session: SessionResult,
    /// The settings used.
    pub session_config: SessionConfig,
    /// Automatically chosen outages with their dynamics (`auto:` specifications).
    pub selection: Option<Vec<SelectedOutage>>,
    /// What the readers and the job noted (skipped records, bridged gaps, settings taken
    /// from the data).
    pub notes: Vec<String>,
    /// The IMU value checks ([`crate::nav::imu_check`]): non-physical samples, outliers,
    /// saturation, and which were repaired.
    pub imu_check: ImuCheckReport,
}

fn located(cfg: &LoadedConfig, key: &str, message: String) -> NavJobError {
    NavJobError::Config(cfg.error(KeyError {
        key: key.into(),
        message,
    }))
}

fn required(
    cfg: &LoadedConfig,
    key: &str,
    v: &Option<PathBuf>,
    what: &str,
) -> Result<PathBuf, NavJobError> {
    match v {
        Some(p) => {
            let p = cfg.path(key, p);
            match PathKind::of(&p) {
                // A pipe, FIFO or `/dev/stdin` is read once, as a file is.
                PathKind::File | PathKind::Other => Ok(p),
                PathKind::Dir => Err(located(
                    cfg,
                    key,
                    format!("{}: a folder, not a file", p.display()),
                )),
                PathKind::Missing => {
                    Err(located(cfg, key, format!("{}: no such file", p.display())))
                }
            }
        }
        None => Err(NavJobError::Config(ConfigError {
            location: cfg.locate(key),
            message: format!(
                "no {what} file: set `{key}` in the configuration or pass --{}",
                crate::nav::config::key_by_path(key).map_or("?", |k| k.flag)
            ),
        })),
    }
}

/// The IMU format: as configured, or detected (`auto`): a tag file given or `FILE.tag`
/// beside the log → tagged CSV; a first line with a non-numeric field (a header) → rates
/// CSV; otherwise KF-GINS increments.
pub(crate) fn detect_imu_format(format: &str, file: &Path, tag_given: bool) -> ImuFormat {
    match format {
        "kfgins" => ImuFormat::Kfgins,
        "tagged-csv" => ImuFormat::TaggedCsv,
        "csv" => ImuFormat::Csv,
        _ => {
            if tag_given || PathKind::of(&default_tag(file)) == PathKind::File {
                return ImuFormat::TaggedCsv;
            }
            let head = probe::first_line(file, 64 * 1024);
            let header = head.is_some_and(|l| {
                l.split([',', ' ', '\t', ';'])
                    .map(str::trim)
                    .filter(|f| !f.is_empty())
                    .any(|f| f.parse::<f64>().is_err())
            });
            if header {
                ImuFormat::Csv
            } else {
                ImuFormat::Kfgins
            }
        }
    }
}

fn default_tag(file: &Path) -> PathBuf {
    let mut p = file.as_os_str().to_owned();
    p.push(".tag");
    PathBuf::from(p)
}

/// The session settings of a configuration with its noise model (no file access).
pub fn session_config(
    cfg: &LoadedConfig,
    noise: ImuNoise,
    initial_sensor_sigma: [f64; 12],
) -> Result<SessionConfig, NavJobError> {
    let c = &cfg.config;
    let mut f = FilterConfig::new(noise, c.gnss.lever_arm_m);
    f.gate = c.gate().map_err(|e| NavJobError::Config(cfg.error(e)))?;
    f.quality_scale = c.quality_scale();
    f.use_gnss_velocity = c.gnss.use_velocity;
    let a = &c.aids;
    if a.nhc {
        let d = NhcConfig::default();
        f.nhc = Some(NhcConfig {
            sigma_m_s: [a.nhc_sigma_m_s; 2],
            min_speed_m_s: a.nhc_min_speed_m_s,
            max_yaw_rate_rad_s: a.nhc_max_yaw_rate_deg_s.to_radians(),
            ..d
        });
    }
    if a.zupt {
        let d = StandstillConfig::default();
        f.standstill = Some(StandstillConfig {
            window_s: a.standstill_window_s,
            min_duration_s: a.standstill_min_s,
            accel_std_max_m_s2: a.standstill_accel_std_m_s2,
            gyro_std_max_rad_s: a.standstill_gyro_std_deg_s.to_radians(),
            max_speed_m_s: Some(a.standstill_max_speed_m_s),
            zupt_sigma_m_s: Some(a.zupt_sigma_m_s),
            zaru_sigma_rad_s: Some(a.zaru_sigma_deg_s.to_radians()),
            ..d
        });
    }
    let mut s = SessionConfig::new(f);
    s.min_speed_m_s = c.align.min_speed_m_s;
    s.max_heading_sigma_rad = c.align.max_heading_sigma_deg.to_radians();
    s.align_baseline_s = c.align.baseline_s;
    s.initial_yaw_rad = c.align.initial_yaw_deg.map(f64::to_radians);
    s.initial_attitude_rad = c.align.initial_attitude_deg.map(|a| a.map(f64::to_radians));
    s.static_prime_s = c.align.static_s;
    s.converge_s = c.outages.converge_s;
    s.reconverge_s = c.outages.reconverge_s;
    s.sigma_floor_m = c.sigma_floor_m();
    s.auto_sigma_floor = c.auto_sigma_floor();
    s.smooth = c.filter.smooth;
    s.initial_sensor_sigma = Some(initial_sensor_sigma);
    Ok(s)
}

/// The inputs of a job, read and checked: the IMU stream, the fixes, the settings.
#[derive(Debug)]
pub(crate) struct NavInputs {
    /// The IMU stream (after time offset, mounting and calibration).
    pub imu: ImuStream,
    /// The IMU reader used.
    pub imu_format: ImuFormat,
    /// GNSS fixes inside the IMU span that passed the quality filter.
    pub fixes: GnssFixes,
    /// Fixes dropped by the quality filter.
    pub dropped_by_quality: usize,
    /// The session settings (no outages yet).
    pub session_config: SessionConfig,
    /// The outage specification.
    pub outages: OutageSpec,
    /// What the readers noted.
    pub notes: Vec<String>,
    /// The IMU value checks and repairs.
    pub imu_check: ImuCheckReport,
}

/// Runs the job of `cfg`: `read_nav_inputs`, the outages, [`run_session`].
pub fn run_nav_job(cfg: &LoadedConfig, csv: &TextOptions) -> Result<NavJobResult, NavJobError> {
    run_inputs(read_nav_inputs(cfg, csv)?)
}

/// The outages and the session on checked inputs.
fn run_inputs(inputs: NavInputs) -> Result<NavJobResult, NavJobError> {
    let NavInputs {
        imu,
        imu_format,
        fixes,
        dropped_by_quality,
        mut session_config,
        outages,
        notes,
        imu_check,
    } = inputs;
    let (spec, selection) = choose_outages(outages, &fixes)?;
    session_config.outages = select_gnss(&fixes, &imu, &spec, GnssOutsideImu::Drop)?.windows;
    let session = run_session(&imu, &fixes, &session_config)?;
    Ok(NavJobResult {
        imu,
        imu_format,
        fixes,
        dropped_by_quality,
        session,
        session_config,
        selection,
        notes,
        imu_check,
    })
}

/// Runs the job of `cfg` on data in memory: `log` a log of rates (three angular-rate and
/// three specific-force channels, time stamps in `imu.time_base`, as a rates CSV gives
/// them) and `gnss` the fixes; `imu.file`, `gnss.file` and the reader settings of `cfg`
/// are not used (the result names the format [`ImuFormat::Csv`], rates). Everything else
/// is [`run_nav_job`]'s: the same stream options, IMU
/// checks, calibration, quality filter, outages and session, so a log and fixes read from
/// files give the same result as [`run_nav_job`] on those files.
pub fn run_nav_job_in_memory(
    cfg: &LoadedConfig,
    log: &crate::data::ImuLog,
    gnss: GnssFixes,
) -> Result<NavJobResult, NavJobError> {
    let settings = job_settings(cfg)?;
    let imu = imu_from_rates_log(log, &RateChannels::ByQuantity, &cfg.config.stream_options())?;
    let gnss_name = "GNSS fixes in memory";
    gnss.validate().map_err(|e| {
        NavJobError::Config(ConfigError {
            location: gnss_name.into(),
            message: e.to_string(),
        })
    })?;
    let source = log.source.clone();
    let inputs = finish_inputs(
        cfg,
        settings,
        imu,
        ImuFormat::Csv,
        &source,
        || Ok(gnss),
        gnss_name,
    )?;
    run_inputs(inputs)
}

/// Reads the files of `cfg` and builds the settings. `csv` says how to read a rates CSV
/// (`imu.format = "csv"`): columns, units, time column. Everything that needs no data
/// file (noise values, the outage specification, the calibration file) is checked before
/// the data are read.
pub(crate) fn read_nav_inputs(
    cfg: &LoadedConfig,
    csv: &TextOptions,
) -> Result<NavInputs, NavJobError> {
    let c = &cfg.config;
    let imu_path = required(cfg, "imu.file", &c.imu.file, "IMU")?;
    let gnss_path = required(cfg, "gnss.file", &c.gnss.file, "GNSS")?;
    let tag = c.imu.tag.as_ref().map(|t| cfg.path("imu.tag", t));
    if c.imu.format == "auto"
        && tag.is_none()
        && matches!(PathKind::of(&imu_path), PathKind::Dir | PathKind::Other)
    {
        // Detection reads the first line; from a pipe those bytes would be gone for the
        // reader.
        return Err(located(
            cfg,
            "imu.format",
            format!(
                "{}: not a regular file (a pipe or device), so its format cannot be detected \
                 without consuming it; set imu.format (--imu-format) to kfgins, csv or tagged-csv",
                imu_path.display()
            ),
        ));
    }
    let format = detect_imu_format(&c.imu.format, &imu_path, tag.is_some());
    let settings = job_settings(cfg)?;
    let opts = c.stream_options();
    let imu = match format {
        ImuFormat::Kfgins => {
            let inc = crate::io::nav::read_kfgins_imu_file(&imu_path)?;
            imu_from_kfgins(&inc, &imu_path.display().to_string(), &opts)?
        }
        ImuFormat::TaggedCsv => {
            let tag = tag.unwrap_or_else(|| default_tag(&imu_path));
            if PathKind::of(&tag) != PathKind::File {
                return Err(located(
                    cfg,
                    "imu.tag",
                    format!(
                        "{}: no such tag file; a tagged CSV needs its RTKLIB .tag (pass --tag)",
                        tag.display()
                    ),
                ));
            }
            imu_from_tagged_csv_files(
                &imu_path,
                &tag,
                &TaggedCsvOptions {
                    stream: opts,
                    ..TaggedCsvOptions::default()
                },
            )?
        }
        ImuFormat::Csv => {
            let mut text = csv.clone();
            text.drop_truncated_edges = true;
            if let Some(w) = &c.imu.week_column {
                text.week_column =
                    Some(w.parse().map_err(|e: crate::io::text::ParseSpecError| {
                        located(cfg, "imu.week_column", e.to_string())
                    })?);
            }
            let log = crate::io::read_log_file(&imu_path, &text)?;
            imu_from_rates_log(&log, &RateChannels::ByQuantity, &opts)?
        }
    };
    let name = imu_path.display().to_string();
    finish_inputs(
        cfg,
        settings,
        imu,
        format,
        &name,
        || Ok(read_gnss_file(&gnss_path, &GnssReadOptions::default())?),
        &gnss_path.display().to_string(),
    )
}

/// What a job needs besides the data: the noise settings (with the noise model file, if
/// any), the outage specification and the calibration (with its file, if any).
struct JobSettings {
    noise: ImuNoise,
    sigma0: [f64; 12],
    spec: OutageSpec,
    calibration: Option<(
        driftless_model::calib::ImuCalibration,
        Option<driftless_model::linalg::Mat3>,
    )>,
}

/// The settings of `cfg` that need no data file, checked (before any data are read).
fn job_settings(cfg: &LoadedConfig) -> Result<JobSettings, NavJobError> {
    let c = &cfg.config;
    let model = match &c.noise.model {
        Some(p) => Some(crate::allan::noise_model::NoiseModel::load(
            &cfg.path("noise.model", p),
        )?),
        None => None,
    };
    let (noise, sigma0) = c
        .noise_settings(model.as_ref())
        .map_err(|e| NavJobError::Config(cfg.error(e)))?;
    let spec: OutageSpec =
        c.outages
            .spec
            .parse()
            .map_err(|e: crate::nav::outage::OutageError| {
                located(cfg, "outages.spec", e.to_string())
            })?;
    let calibration = match &c.imu.calibration {
        Some(p) => {
            let path = cfg.path("imu.calibration", p);
            let f = crate::calib::model_file::CalibrationFile::load(&path)?;
            for (t, si) in [(&f.accel, ["m/s^2", "m/s²"]), (&f.gyro, ["rad/s", "rad/s"])] {
                if !si.contains(&t.raw_unit.as_str()) {
                    return Err(located(
                        cfg,
                        "imu.calibration",
                        format!(
                            "{}: raw unit {:?}: navigation reads SI samples, so it can apply only a calibration of SI samples ({} / rad/s)",
                            path.display(),
                            t.raw_unit,
                            si[0]
                        ),
                    ));
                }
            }
            Some((
                f.calibration(),
                f.gyro_g_sensitivity.map(driftless_model::linalg::Mat3),
            ))
        }
        None => None,
    };
    Ok(JobSettings {
        noise,
        sigma0,
        spec,
        calibration,
    })
}

/// The rest of a job's inputs once the IMU stream is built: its notes, the IMU value
/// checks (and repairs), the calibration, the GNSS fixes from `read_gnss` (called after
/// the IMU checks) inside the IMU span that pass the quality filter, the session settings.
/// `imu_name` and `gnss_name` name the sources in notes and messages.
fn finish_inputs(
    cfg: &LoadedConfig,
    settings: JobSettings,
    mut imu: ImuStream,
    format: ImuFormat,
    imu_name: &str,
    read_gnss: impl FnOnce() -> Result<GnssFixes, NavJobError>,
    gnss_name: &str,
) -> Result<NavInputs, NavJobError> {
    let c = &cfg.config;
    let JobSettings {
        noise,
        sigma0,
        spec,
        calibration,
    } = settings;
    let opts = c.stream_options();
    let mut notes = Vec::new();
    notes.extend(imu.notes.iter().cloned());
    for g in imu.gaps.iter().take(20) {
        notes.push(format!(
            "{imu_name}: IMU gap of {:.4} s before t = {:.4} s: integrated across",
            g.gap_s, g.time_s
        ));
    }
    if imu.gaps.len() > 20 {
        notes.push(format!("… {} more IMU gaps", imu.gaps.len() - 20));
    }
    if let Some(r) = c.imu.rate_hz {
        let measured = 1.0 / median_interval(&imu);
        if (measured - r).abs() > 0.05 * r {
            notes.push(format!(
                "imu.rate_hz = {r} Hz but the time stamps run at {measured:.1} Hz: the time stamps are integrated as they are"
            ));
        }
    }
    // The IMU values, on the sensor's axes, before the calibration (module docs of
    // `imu_check`): refused when non-physical unless repair is asked for.
    let check_cfg = c.imu_check_config();
    let c_vb = (!opts.mounting.is_identity()).then(|| opts.mounting.c_vb());
    let mut imu_check =
        check_imu(&imu, c_vb.as_ref(), &check_cfg).map_err(|e| NavJobError::ImuValues {
            error: Box::new(e),
            report: Box::default(),
        })?;
    if c.imu.repair_spikes {
        repair_spikes(&mut imu, c_vb.as_ref(), &mut imu_check, &check_cfg).map_err(|e| {
            NavJobError::ImuValues {
                error: Box::new(e),
                report: Box::new(imu_check.clone()),
            }
        })?;
    } else if let Some(error) = non_physical_error(&imu_check, &imu.source) {
        return Err(NavJobError::ImuValues {
            error: Box::new(error),
            report: Box::new(imu_check),
        });
    }
    if let Some((cal, g)) = &calibration {
        imu.apply_calibration(cal, g.as_ref());
    }
    let gnss = read_gnss()?;
    notes.extend(gnss.notes.iter().cloned());
    let all = select_gnss(&gnss, &imu, &OutageSpec::None, GnssOutsideImu::Drop)?;
    let accepted = c.accepted_qualities();
    let keep: Vec<bool> = all
        .fixes
        .quality
        .iter()
        .map(|&q| accepted.get(q as usize).copied().unwrap_or(false))
        .collect();
    let dropped = keep.iter().filter(|k| !**k).count();
    let fixes = if dropped > 0 {
        subset_fixes(&all.fixes, &keep)
    } else {
        all.fixes
    };
    if fixes.is_empty() {
        return Err(located(
            cfg,
            "gnss.accept",
            format!(
                "{gnss_name}: no GNSS fix inside the IMU span passes the quality filter ({dropped} dropped)"
            ),
        ));
    }
    let session_config = session_config(cfg, noise, sigma0)?;
    Ok(NavInputs {
        imu,
        imu_format: format,
        fixes,
        dropped_by_quality: dropped,
        session_config,
        outages: spec,
        notes,
        imu_check,
    })
}

/// Upper median of the positive epoch intervals, s (NaN when there are none).
fn median_interval(imu: &ImuStream) -> f64 {
    let mut d: Vec<f64> = imu
        .epochs
        .iter()
        .map(|e| e.dt_s)
        .filter(|d| *d > 0.0)
        .collect();
    crate::numeric::upper_median(&mut d).unwrap_or(f64::NAN)
}

/// `auto:NxL` outages: chosen on the GNSS fixes inside the IMU span (the only reference of
/// a recorded run) before any filtering, so an impossible request fails at once; returned
/// as absolute windows. Other specifications pass through unchanged.
pub(crate) fn choose_outages(
    spec: OutageSpec,
    fixes: &GnssFixes,
) -> Result<(OutageSpec, Option<Vec<SelectedOutage>>), NavJobError> {
    Ok(crate::nav::kfgins_job::resolve_auto_outages(spec, fixes)?)
}

//! From files to filter inputs: a validated [`ImuStream`] of increments in the vehicle
//! body frame on GPS time, and the GNSS epochs a filter may use after outage masking.
//!
//! Nothing here estimates anything: this module converts units and frames at the edge,
//! validates time stamps, and selects GNSS epochs.
//!
//! # IMU sources
//!
//! * KF-GINS increments ([`ImuIncrements`], [`imu_from_kfgins`]): used as they are.
//! * An [`ImuLog`] of rates ([`imu_from_rates_log`]): gyro rad/s and specific force m/s²,
//!   channels found by quantity or named explicitly ([`RateChannels`]).
//! * A tick-stamped IMU CSV with an RTKLIB `.tag` file, the layout of
//!   `drive/drive_0708/imu_1934.csv` ([`imu_from_tagged_csv`]): `acc_x, acc_y, acc_z [g],
//!   gyr_x, gyr_y, gyr_z [deg/s], tick [ms]`, ticks mapped to GPS time with
//!   [`map_ticks_to_gps`].
//!
//! **Rates → increments** ("at the edge", [`increments_from_rates`]): the sample at t_i
//! is taken as the average rate over (t_{i−1}, t_i], so Δθ_i = ω_i·(t_i − t_{i−1}) and
//! Δv_i = f_i·(t_i − t_{i−1}). The first sample has no predecessor; its interval is the
//! nominal one (the median time-stamp difference), so no epoch is dropped.
//!
//! **Time**: IMU time stamps are in [`ImuStreamOptions::time_base`] (GPS seconds of week by
//! default; GPS week + seconds of week, Unix time in the GPST scale or in UTC, see
//! [`TimeBase`]) and are converted to GPS seconds of the week of the first epoch
//! ([`ImuStream::gps_week`]); a log that crosses a week boundary keeps counting past
//! 604 800 s, as [`GnssFixes::time_s`] does. Then every stamp gets
//! [`ImuStreamOptions::time_shift_s`] added (the drive data's authors give −0.125 s: its IMU
//! stamps lag). The GNSS time is the reference.
//!
//! **Cut records**: the tagged-CSV reader drops a truncated first or last CSV record (what a
//! logger that starts or stops mid-line leaves) and the KF-GINS readers do the same; each
//! drop is a note in [`ImuStream::notes`] naming file and line. A bad row anywhere else is
//! an error.
//!
//! **Mounting** ([`Mounting`]): a constant rotation C_vb from IMU axes (b) to the vehicle
//! forward-right-down frame (v), applied to Δθ and Δv (exact: a constant rotation commutes
//! with integration). See [`Mounting`] for the composition order.
//!
//! # Validation (errors name the source and the epoch index and time)
//!
//! * Non-finite values: error.
//! * Duplicated time stamps and time going backwards: error ([`PipelineError::DuplicateEpoch`],
//!   [`PipelineError::OutOfOrder`]). Text readers catch these first with file and line.
//! * Gaps: an interval longer than [`ImuStreamOptions::gap_factor`] × nominal (2 by
//!   default: a whole sample missing, allowing the drive data's ±1 ms tick jitter) is an
//!   error ([`ImuGapPolicy::Error`], default) or is kept as one long increment and listed in
//!   [`ImuStream::gaps`] ([`ImuGapPolicy::Bridge`]).
//! * GNSS before the first (or after the last) IMU epoch: dropped and counted in
//!   [`GnssSelection`] ([`GnssOutsideImu::Drop`], default; the library does not print,
//!   the caller logs the counts) or an error ([`GnssOutsideImu::Error`]).
//! * GNSS σ = 0: handled by the GNSS readers through [`GnssReadOptions`], which
//!   [`read_gnss_file`] passes through.

use std::path::Path;

use driftless_model::linalg::{Mat3, Vec3};

use super::attitude::Euler;
use super::mechanization::{ImuIncrement, increments_from_rates};
use super::outage::{OutageError, OutageSpec, OutageWindow, TimeSpan, is_masked};
use crate::io::edge::{Edge, was_dropped};
pub use crate::io::nav::TimeBase;
use crate::io::nav::{
    GnssFixes, GnssReadOptions, ImuIncrements, TickMapping, TimeBaseError, TimeTag,
    map_ticks_to_gps, read_kfgins_gnss, read_rtklib_pos, read_rtklib_tag_file,
};
use crate::io::{
    ColumnRef, HeaderMode, ImuLog, LogError, Quantity, TextOptions, TimeUnit, Unit, read_text_bytes,
};

mod gnss_select;
mod tagged;
pub use gnss_select::*;
pub use tagged::*;

/// Errors of the pipeline. Messages name the source and the epoch (0-based index and time).
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// A reader failed (file, line and column in the message). Boxed: [`LogError`] is
    /// large and this error travels through every `?`.
    #[error(transparent)]
    Read(Box<LogError>),
    /// An outage specification could not be resolved.
    #[error(transparent)]
    Outage(#[from] OutageError),
    /// Two epochs with the same time stamp.
    #[error(
        "{source_name}: IMU epoch {index} at t = {time_s} s duplicates the previous epoch's time"
    )]
    DuplicateEpoch {
        /// Source of the IMU data.
        source_name: String,
        /// 0-based epoch index.
        index: usize,
        /// Its time, s (after the time shift).
        time_s: f64,
    },
    /// Time going backwards.
    #[error(
        "{source_name}: IMU epoch {index} at t = {time_s} s is earlier than the previous epoch ({previous_s} s)"
    )]
    OutOfOrder {
        /// Source of the IMU data.
        source_name: String,
        /// 0-based epoch index.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Previous epoch's time, s.
        previous_s: f64,
    },
    /// An interval longer than the gap limit, with [`ImuGapPolicy::Error`].
    #[error(
        "{source_name}: IMU gap of {gap_s:.6} s before epoch {index} at t = {time_s} s (nominal interval {nominal_dt_s:.6} s, limit {limit_s:.6} s); use the bridge gap policy to integrate across it"
    )]
    Gap {
        /// Source of the IMU data.
        source_name: String,
        /// 0-based index of the first epoch after the gap.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Interval, s.
        gap_s: f64,
        /// Nominal interval, s.
        nominal_dt_s: f64,
        /// Gap limit, s.
        limit_s: f64,
    },
    /// A non-finite value.
    #[error("{source_name}: non-finite {what} at IMU epoch {index}")]
    NonFinite {
        /// Source of the IMU data.
        source_name: String,
        /// 0-based epoch index.
        index: usize,
        /// Which quantity.
        what: &'static str,
    },
    /// Fewer than two IMU epochs (no interval can be formed).
    #[error("{source_name}: {count} IMU epoch(s); at least 2 are needed")]
    TooFewEpochs {
        /// Source of the IMU data.
        source_name: String,
        /// Epochs found.
        count: usize,
    },
    /// An IMU log without time stamps.
    #[error("{source_name}: the IMU log has no time column; navigation needs time stamps")]
    NoTime {
        /// Source of the IMU data.
        source_name: String,
    },
    /// Gyro/accelerometer channels not found or ambiguous, or of the wrong quantity.
    #[error("{source_name}: {message}")]
    Channels {
        /// Source of the IMU data.
        source_name: String,
        /// What is wrong, naming channels and units.
        message: String,
    },
    /// A GNSS epoch outside the IMU's time span, with [`GnssOutsideImu::Error`].
    #[error(
        "GNSS epoch {index} at t = {time_s} s lies outside the IMU data [{imu_start_s} s, {imu_end_s} s]"
    )]
    GnssOutsideImu {
        /// 0-based GNSS epoch index.
        index: usize,
        /// Its time, GPS s.
        time_s: f64,
        /// First IMU epoch, s.
        imu_start_s: f64,
        /// Last IMU epoch, s.
        imu_end_s: f64,
    },
    /// No GNSS epoch inside the IMU's time span.
    #[error("no GNSS epoch lies inside the IMU data [{imu_start_s} s, {imu_end_s} s]")]
    NoGnssInImuSpan {
        /// First IMU epoch, s.
        imu_start_s: f64,
        /// Last IMU epoch, s.
        imu_end_s: f64,
    },
    /// An option out of range.
    #[error("invalid option: {0}")]
    Option(String),
    /// An IMU time stamp that cannot be converted to GPS time.
    #[error("{source_name}: IMU epoch {index}: {error}")]
    Time {
        /// Source of the IMU data.
        source_name: String,
        /// 0-based epoch index (0 when the first stamp fixes the week).
        index: usize,
        /// What is wrong.
        error: TimeBaseError,
    },
}

impl From<LogError> for PipelineError {
    fn from(e: LogError) -> Self {
        PipelineError::Read(Box::new(e))
    }
}

/// Gyro x, y, z and accelerometer x, y, z columns borrowed from a log.
type RateColumns<'a> = ([&'a [f64]; 3], [&'a [f64]; 3]);

/// What to do with an IMU interval longer than `gap_factor` × nominal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ImuGapPolicy {
    /// Stop with [`PipelineError::Gap`] naming the epoch and time.
    #[default]
    Error,
    /// Keep the long interval as one increment (rates × the long Δt; KF-GINS increments as
    /// given) and list it in [`ImuStream::gaps`] for the caller to log.
    Bridge,
}

/// Rotation from IMU sensor axes (b) to the vehicle forward-right-down frame (v), given as
/// the data's authors do: a nominal mounting plus a small misalignment, each as
/// roll/pitch/yaw in degrees of the z-y-x sequence of [`Euler`].
///
/// **Convention.** "The IMU axes are rotated by (roll, pitch, yaw) from the vehicle frame"
/// means the IMU frame is reached from v by yaw ψ about z, then pitch θ about the new y,
/// then roll φ about the new x, exactly as the body frame is reached from NED; hence
/// C_vb = R_z(ψ)·R_y(θ)·R_x(φ) = `Euler{..}.to_dcm()`, and f_v = C_vb·f_b.
///
/// **Composition.** An intermediate frame v′ is reached from v by the small
/// misalignment (angles about the vehicle's own axes, C_vv′ = E(misalignment)), and the
/// IMU frame b from v′ by the nominal mounting (C_v′b = E(nominal)). Hence
/// C_vb = C_vv′ · C_v′b = `E(misalignment) · E(nominal)`: applied to data, first undo the gross
/// mounting, then correct by the small angles, which is how a misalignment calibrated
/// against vehicle motion (forward/lateral/down) is naturally stated.
///
/// The order matters only for the roll and yaw parts of the misalignment: with the
/// drive's nominal (180°, 0, 180°), a half-turn about y, the opposite order
/// E(nominal)·E(misalignment) equals this one with the yaw (and roll) misalignment
/// negated; the pitch part commutes. The drive data decides between them: on straight
/// driving the lateral specific force must not follow the longitudinal one. Regressing
/// 1-s means of f_y on f_x where |ω_z| < 0.02 rad/s (311 blocks) gives a slope of −0.024
/// with this order, −0.200 with the opposite order and −0.110 with the nominal rotation
/// alone (≈ −tan 6.3°: a yaw misalignment of ≈ 5–6° left uncorrected), so this order is
/// the one the authors' angles were estimated for (test `drive_0708_stream` in
/// `crates/driftless/tests/nav_pipeline.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mounting {
    /// Nominal mounting roll, pitch, yaw, deg.
    pub rpy_deg: [f64; 3],
    /// Misalignment on top of the nominal mounting, roll, pitch, yaw, deg.
    pub misalignment_rpy_deg: [f64; 3],
}

impl Mounting {
    /// No rotation: IMU axes are vehicle FRD.
    pub const IDENTITY: Mounting = Mounting {
        rpy_deg: [0.0; 3],
        misalignment_rpy_deg: [0.0; 3],
    };

    fn euler(rpy_deg: [f64; 3]) -> Euler {
        Euler {
            roll_rad: rpy_deg[0].to_radians(),
            pitch_rad: rpy_deg[1].to_radians(),
            yaw_rad: rpy_deg[2].to_radians(),
        }
    }

    /// C_vb = E(misalignment)·E(nominal) (see the type docs): f_v = C_vb·f_b.
    pub fn c_vb(&self) -> Mat3 {
        Self::euler(self.misalignment_rpy_deg)
            .to_dcm()
            .mul_mat(&Self::euler(self.rpy_deg).to_dcm())
    }

    /// True when both rotations are zero.
    pub(crate) fn is_identity(&self) -> bool {
        self.rpy_deg == [0.0; 3] && self.misalignment_rpy_deg == [0.0; 3]
    }
}

impl Default for Mounting {
    fn default() -> Self {
        Mounting::IDENTITY
    }
}

/// Options shared by every IMU source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuStreamOptions {
    /// Added to every IMU time stamp, s (drive data: −0.125).
    pub time_shift_s: f64,
    /// IMU → vehicle rotation applied to the increments.
    pub mounting: Mounting,
    /// Gap handling.
    pub gap_policy: ImuGapPolicy,
    /// An interval longer than `gap_factor` × nominal is a gap (> 1; default 2).
    pub gap_factor: f64,
    /// Nominal interval, s; `None` takes the median time-stamp difference.
    pub nominal_dt_s: Option<f64>,
    /// What the IMU time stamps count ([`TimeBase`]; GPS seconds of week by default).
    pub time_base: TimeBase,
    /// GPS week of stamps in a week-based time base when the data do not name it (a
    /// `gps-sow` column of a known week); it must agree with a week the data name.
    /// Rejected with the Unix time bases, whose stamps fix the week.
    pub gps_week: Option<u16>,
}

impl Default for ImuStreamOptions {
    fn default() -> Self {
        ImuStreamOptions {
            time_shift_s: 0.0,
            mounting: Mounting::IDENTITY,
            gap_policy: ImuGapPolicy::Error,
            gap_factor: 2.0,
            nominal_dt_s: None,
            time_base: TimeBase::GpsSecondsOfWeek,
            gps_week: None,
        }
    }
}

/// A bridged IMU gap ([`ImuGapPolicy::Bridge`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuGap {
    /// Index of the first epoch after the gap.
    pub index: usize,
    /// Its time, s.
    pub time_s: f64,
    /// Interval length, s.
    pub gap_s: f64,
}

/// Validated IMU increments in the vehicle body frame (FRD), on GPS time, ready for the
/// mechanization and the filter.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuStream {
    /// Where the data came from (for messages).
    pub source: String,
    /// GPS week of `time_s` (the week of the first epoch; `time_s` passes 604 800 s after a
    /// week boundary), when the source names it (tagged CSV, a week column, Unix time
    /// stamps, [`ImuStreamOptions::gps_week`]); `None` otherwise.
    pub gps_week: Option<u16>,
    /// Nominal interval, s.
    pub nominal_dt_s: f64,
    /// The epochs, strictly increasing in time; `dt_s` > 0 everywhere.
    pub epochs: Vec<ImuIncrement>,
    /// Gaps bridged under [`ImuGapPolicy::Bridge`] (empty otherwise).
    pub gaps: Vec<ImuGap>,
    /// What the readers dropped and why (truncated first or last records), one message
    /// per item naming file and line, for the caller to show. Empty when nothing was.
    pub notes: Vec<String>,
}

impl ImuStream {
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.epochs.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.epochs.is_empty()
    }
    /// Time of the first and last epoch, s (`None` when empty).
    pub fn time_span(&self) -> Option<TimeSpan> {
        Some(TimeSpan {
            start_s: self.epochs.first()?.time_s,
            end_s: self.epochs.last()?.time_s,
        })
    }

    /// Applies a room-temperature calibration whose raw units are SI (rad/s, m/s²) to
    /// the increments: Δv' = M_a(Δv − b_a·Δt), Δθ' = M_g(Δθ − b_g·Δt − G·Δv') — the rate
    /// model f = M_a(f̃ − b_a), ω = M_g(ω̃ − b_g − G f) with the gyro g-sensitivity G
    /// (rad/s per m/s², raw = … + G·f, as six-position calibration estimates it; none when
    /// `gyro_g_sensitivity` is `None`) integrated over each interval (exact for constant
    /// M, b, G).
    pub(crate) fn apply_calibration(
        &mut self,
        cal: &driftless_model::calib::ImuCalibration,
        gyro_g_sensitivity: Option<&driftless_model::linalg::Mat3>,
    ) {
        use driftless_model::linalg::{scale, sub};
        for e in &mut self.epochs {
            e.dvel_m_s = cal
                .accel
                .matrix
                .mul_vec(sub(e.dvel_m_s, scale(cal.accel.bias, e.dt_s)));
            let mut dtheta = sub(e.dtheta_rad, scale(cal.gyro.bias, e.dt_s));
            if let Some(g) = gyro_g_sensitivity {
                dtheta = sub(dtheta, g.mul_vec(e.dvel_m_s));
            }
            e.dtheta_rad = cal.gyro.matrix.mul_vec(dtheta);
        }
    }
}

/// Median of the successive differences of a strictly increasing series (len ≥ 2; NaN
/// otherwise).
fn median_diff(time_s: &[f64]) -> f64 {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    crate::numeric::upper_median(&mut d).unwrap_or(f64::NAN)
}

/// Checks time stamps (already shifted) and returns the nominal interval and the gaps.
fn check_times(
    time_s: &[f64],
    source: &str,
    opts: &ImuStreamOptions,
) -> Result<(f64, Vec<ImuGap>), PipelineError> {
    if !(opts.gap_factor.is_finite() && opts.gap_factor > 1.0) {
        return Err(PipelineError::Option(format!(
            "gap_factor must be finite and > 1, got {}",
            opts.gap_factor
        )));
    }
    if !opts.time_shift_s.is_finite() {
        return Err(PipelineError::Option(format!(
            "time shift must be finite, got {}",
            opts.time_shift_s
        )));
    }
    if time_s.len() < 2 {
        return Err(PipelineError::TooFewEpochs {
            source_name: source.to_owned(),
            count: time_s.len(),
        });
    }
    for (i, &t) in time_s.iter().enumerate() {
        if !t.is_finite() {
            return Err(PipelineError::NonFinite {
                source_name: source.to_owned(),
                index: i,
                what: "time",
            });
        }
        if i > 0 {
            let p = time_s[i - 1];
            if t == p {
                return Err(PipelineError::DuplicateEpoch {
                    source_name: source.to_owned(),
                    index: i,
                    time_s: t,
                });
            }
            if t < p {
                return Err(PipelineError::OutOfOrder {
                    source_name: source.to_owned(),
                    index: i,
                    time_s: t,
                    previous_s: p,
                });
            }
        }
    }
    let nominal = match opts.nominal_dt_s {
        Some(dt) if dt.is_finite() && dt > 0.0 => dt,
        Some(dt) => {
            return Err(PipelineError::Option(format!(
                "nominal IMU interval must be finite and > 0 s, got {dt}"
            )));
        }
        None => median_diff(time_s),
    };
    let limit = opts.gap_factor * nominal;
    let mut gaps = Vec::new();
    for (i, w) in time_s.windows(2).enumerate() {
        let gap_s = w[1] - w[0];
        if gap_s > limit {
            match opts.gap_policy {
                ImuGapPolicy::Error => {
                    return Err(PipelineError::Gap {
                        source_name: source.to_owned(),
                        index: i + 1,
                        time_s: w[1],
                        gap_s,
                        nominal_dt_s: nominal,
                        limit_s: limit,
                    });
                }
                ImuGapPolicy::Bridge => gaps.push(ImuGap {
                    index: i + 1,
                    time_s: w[1],
                    gap_s,
                }),
            }
        }
    }
    Ok((nominal, gaps))
}

fn finite3(v: Vec3) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Builds a stream from time stamps and per-epoch (Δθ, Δv) producers, applying the time
/// shift, validation and mounting rotation. `make(i, dt_s)` returns epoch i's increments in
/// sensor axes.
fn build_stream(
    source: &str,
    gps_week: Option<u16>,
    raw_time_s: &[f64],
    opts: &ImuStreamOptions,
    mut make: impl FnMut(usize, f64) -> (Vec3, Vec3),
) -> Result<ImuStream, PipelineError> {
    let (gps_week, gps_time_s) = to_gps_time(source, gps_week, raw_time_s, opts)?;
    let time_s: Vec<f64> = gps_time_s.iter().map(|t| t + opts.time_shift_s).collect();
    let (nominal, gaps) = check_times(&time_s, source, opts)?;
    let c_vb = (!opts.mounting.is_identity()).then(|| opts.mounting.c_vb());
    let mut epochs = Vec::with_capacity(time_s.len());
    for (i, &t) in time_s.iter().enumerate() {
        let dt = if i == 0 { nominal } else { t - time_s[i - 1] };
        let (dth, dv) = make(i, dt);
        if !finite3(dth) {
            return Err(PipelineError::NonFinite {
                source_name: source.to_owned(),
                index: i,
                what: "angle increment / angular rate",
            });
        }
        if !finite3(dv) {
            return Err(PipelineError::NonFinite {
                source_name: source.to_owned(),
                index: i,
                what: "velocity increment / specific force",
            });
        }
        let (dtheta_rad, dvel_m_s) = match &c_vb {
            Some(c) => (c.mul_vec(dth), c.mul_vec(dv)),
            None => (dth, dv),
        };
        epochs.push(ImuIncrement {
            time_s: t,
            dt_s: dt,
            dtheta_rad,
            dvel_m_s,
        });
    }
    Ok(ImuStream {
        source: source.to_owned(),
        gps_week,
        nominal_dt_s: nominal,
        epochs,
        gaps,
        notes: Vec::new(),
    })
}

/// Stamps in `opts.time_base` → (GPS week of the first, seconds from that week's start),
/// see [`TimeBase::to_gps_week_seconds`]. `data_week` is the week the data name (tag file,
/// week column); it and `opts.gps_week` must agree, and neither may be given with a Unix
/// time base.
fn to_gps_time(
    source: &str,
    data_week: Option<u16>,
    time_s: &[f64],
    opts: &ImuStreamOptions,
) -> Result<(Option<u16>, Vec<f64>), PipelineError> {
    let base = opts.time_base;
    let week = match (data_week, opts.gps_week) {
        (Some(a), Some(b)) if a != b => {
            return Err(PipelineError::Option(format!(
                "{source}: GPS week {b} given, but the data name week {a}"
            )));
        }
        (a, b) => a.or(b),
    };
    if base.is_absolute() && week.is_some() {
        return Err(PipelineError::Option(format!(
            "{source}: time base {base} stamps name their own GPS week; do not give a week (column) with it"
        )));
    }
    if base == TimeBase::GpsWeekAndSeconds && week.is_none() {
        return Err(PipelineError::Option(format!(
            "{source}: time base {base} needs the GPS week column of the IMU log (the text reader's week column)"
        )));
    }
    base.to_gps_week_seconds(time_s, week).map_err(|error| {
        let bad = |e: &TimeBaseError| match e {
            TimeBaseError::BeforeGpsEpoch { value_s, .. }
            | TimeBaseError::NonFinite { value_s, .. }
            | TimeBaseError::PastLastWeek { value_s, .. } => *value_s,
        };
        let v = bad(&error);
        PipelineError::Time {
            source_name: source.to_owned(),
            index: time_s
                .iter()
                .position(|t| t.to_bits() == v.to_bits())
                .unwrap_or(0),
            error,
        }
    })
}

/// Increments as KF-GINS columns (the inverse of [`imu_from_kfgins`]; for writing them
/// with [`crate::io::nav::write_kfgins_imu`]).
pub fn increment_columns(incs: &[ImuIncrement]) -> ImuIncrements {
    ImuIncrements {
        time_s: incs.iter().map(|i| i.time_s).collect(),
        dtheta_rad: incs.iter().map(|i| i.dtheta_rad).collect(),
        dvel_m_s: incs.iter().map(|i| i.dvel_m_s).collect(),
        notes: Vec::new(),
    }
}

/// Stream from KF-GINS increments (already Δθ rad, Δv m/s per interval ending at `time_s`).
/// The first epoch's `dt_s` is the nominal interval. `source` names the data in messages.
pub fn imu_from_kfgins(
    inc: &ImuIncrements,
    source: &str,
    opts: &ImuStreamOptions,
) -> Result<ImuStream, PipelineError> {
    let n = inc.time_s.len();
    if inc.dtheta_rad.len() != n || inc.dvel_m_s.len() != n {
        return Err(PipelineError::Channels {
            source_name: source.to_owned(),
            message: format!(
                "column lengths differ: time {n}, dtheta {}, dvel {}",
                inc.dtheta_rad.len(),
                inc.dvel_m_s.len()
            ),
        });
    }
    let mut s = build_stream(source, None, &inc.time_s, opts, |i, _dt| {
        (inc.dtheta_rad[i], inc.dvel_m_s[i])
    })?;
    s.notes.clone_from(&inc.notes);
    Ok(s)
}

/// Which channels of an [`ImuLog`] hold the gyro and accelerometer axes x, y, z.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum RateChannels {
    /// The log's three [`Quantity::AngularRate`] channels (gyro x, y, z in that order) and
    /// three [`Quantity::SpecificForce`] channels; any other count is an error.
    #[default]
    ByQuantity,
    /// Channels by name; each must carry the right quantity (a channel read without a unit
    /// is rejected: its scale is unknown).
    Named {
        /// Gyro x, y, z channel names (rad/s after reading).
        gyro: [String; 3],
        /// Accelerometer x, y, z channel names (m/s² after reading).
        accel: [String; 3],
    },
}

fn pick_channels<'a>(log: &'a ImuLog, which: &RateChannels) -> Result<RateColumns<'a>, String> {
    let available = || {
        log.channels
            .iter()
            .map(|c| format!("{} [{}]", c.name, c.source_unit))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let by_quantity = |q: Quantity, what: &str| -> Result<[&'a [f64]; 3], String> {
        log.triad_of(q).ok_or_else(|| {
            format!(
                "expected exactly 3 {what} channels ({}), found {}; channels: {}; name them explicitly or give their units",
                q.si_unit(),
                log.indices_of(q).len(),
                available()
            )
        })
    };
    let by_name = |names: &[String; 3], q: Quantity| -> Result<[&'a [f64]; 3], String> {
        let mut out: [&[f64]; 3] = [&[]; 3];
        for (k, name) in names.iter().enumerate() {
            let c = log
                .channel(name)
                .ok_or_else(|| format!("no channel {name:?}; channels: {}", available()))?;
            if c.quantity != q {
                return Err(format!(
                    "channel {name:?} has unit {:?} ({:?}), expected a unit of {:?} ({})",
                    c.source_unit,
                    c.quantity,
                    q,
                    q.si_unit()
                ));
            }
            out[k] = &c.values;
        }
        Ok(out)
    };
    match which {
        RateChannels::ByQuantity => Ok((
            by_quantity(Quantity::AngularRate, "angular-rate")?,
            by_quantity(Quantity::SpecificForce, "specific-force")?,
        )),
        RateChannels::Named { gyro, accel } => Ok((
            by_name(gyro, Quantity::AngularRate)?,
            by_name(accel, Quantity::SpecificForce)?,
        )),
    }
}

/// Stream from an [`ImuLog`] of rates (angular rate rad/s, specific force m/s², converted
/// by the reader from the file's units): Δθ = ω·Δt, Δv = f·Δt with Δt from successive time
/// stamps (see the module docs). The log's time stamps are in `opts.time_base`, converted to
/// GPS time, then shifted by `opts.time_shift_s`; a log read with a week column
/// ([`crate::io::TextOptions::week_column`], base [`TimeBase::GpsWeekAndSeconds`]) names the
/// week in [`ImuLog::week`]. The log's notes are carried into [`ImuStream::notes`].
pub fn imu_from_rates_log(
    log: &ImuLog,
    channels: &RateChannels,
    opts: &ImuStreamOptions,
) -> Result<ImuStream, PipelineError> {
    let source = log.source.as_str();
    let Some(time_s) = log.time_s.as_deref() else {
        return Err(PipelineError::NoTime {
            source_name: source.to_owned(),
        });
    };
    let (gyro, accel) =
        pick_channels(log, channels).map_err(|message| PipelineError::Channels {
            source_name: source.to_owned(),
            message,
        })?;
    let n = time_s.len();
    if gyro.iter().chain(accel.iter()).any(|c| c.len() != n) {
        return Err(PipelineError::Channels {
            source_name: source.to_owned(),
            message: format!("channel lengths differ from the {n} time stamps"),
        });
    }
    let mut s = rates_to_stream(source, log.week, time_s, gyro, accel, opts)?;
    s.notes.clone_from(&log.notes);
    Ok(s)
}

/// Stream from rate columns (angular rate rad/s, specific force m/s²) at time stamps
/// `time_s` in `opts.time_base` (GPS seconds of week `gps_week` by default): Δθ = ω·Δt,
/// Δv = f·Δt with Δt from successive stamps, as [`imu_from_rates_log`] does for a log.
/// `gps_week` is the week the week-based stamps count from, when the data name it.
pub fn rates_to_stream(
    source: &str,
    gps_week: Option<u16>,
    time_s: &[f64],
    gyro_rad_s: [&[f64]; 3],
    accel_m_s2: [&[f64]; 3],
    opts: &ImuStreamOptions,
) -> Result<ImuStream, PipelineError> {
    build_stream(source, gps_week, time_s, opts, |i, dt| {
        let w = [gyro_rad_s[0][i], gyro_rad_s[1][i], gyro_rad_s[2][i]];
        let f = [accel_m_s2[0][i], accel_m_s2[1][i], accel_m_s2[2][i]];
        let inc = increments_from_rates(0.0, dt, w, f);
        (inc.dtheta_rad, inc.dvel_m_s)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use driftless_model::calib::{ImuCalibration, TriadCalibration};

    #[test]
    fn calibration_applies_to_increments_as_to_rates() {
        let dt = 0.01;
        let mut s = ImuStream {
            nominal_dt_s: dt,
            epochs: vec![ImuIncrement {
                time_s: 1.0,
                dt_s: dt,
                dtheta_rad: [0.02 * dt, -0.01 * dt, 0.5 * dt],
                dvel_m_s: [0.3 * dt, 0.1 * dt, -9.8 * dt],
            }],
            ..ImuStream::default()
        };
        let m = Mat3([[1.01, 0.002, 0.0], [0.0, 0.99, -0.001], [0.003, 0.0, 1.0]]);
        let cal = ImuCalibration {
            gyro: TriadCalibration {
                bias: [0.01, 0.0, -0.02],
                matrix: m,
            },
            accel: TriadCalibration {
                bias: [0.1, -0.2, 0.05],
                matrix: m,
            },
        };
        let mut with_g = s.clone();
        s.apply_calibration(&cal, None);
        let w = cal.gyro.apply([0.02, -0.01, 0.5]);
        let f = cal.accel.apply([0.3, 0.1, -9.8]);
        for k in 0..3 {
            assert!((s.epochs[0].dtheta_rad[k] - w[k] * dt).abs() < 1e-15);
            assert!((s.epochs[0].dvel_m_s[k] - f[k] * dt).abs() < 1e-14);
        }
        // g-sensitivity: ω = M_g(ω̃ − b_g − G f) with f the calibrated specific force.
        let g = Mat3([
            [2e-4, -1e-4, 3e-4],
            [0.0, 1.5e-4, -2e-4],
            [1e-4, 0.0, 2.5e-4],
        ]);
        with_g.apply_calibration(&cal, Some(&g));
        let gf = g.mul_vec(f);
        let raw = [0.02 - gf[0], -0.01 - gf[1], 0.5 - gf[2]];
        let w_g = cal.gyro.apply(raw);
        for k in 0..3 {
            assert!((with_g.epochs[0].dtheta_rad[k] - w_g[k] * dt).abs() < 1e-15);
            assert!(
                (w_g[k] - w[k]).abs() > 1e-4,
                "G changed nothing on axis {k}"
            );
            assert!((with_g.epochs[0].dvel_m_s[k] - f[k] * dt).abs() < 1e-14);
        }
    }
}

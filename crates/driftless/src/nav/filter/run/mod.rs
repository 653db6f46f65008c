//! Forward pass of the filter over an IMU log and GNSS fixes, storing what a
//! Rauch–Tung–Striebel smoother needs.
//!
//! # Algorithm
//!
//! IMU epochs are walked in order (each increment covers (t_{k−1}, t_k]; the interval is
//! taken from the time tags, which must increase, with gaps of at most
//! `max_gap_factor` nominal intervals). A GNSS fix at t_g inside an interval splits the
//! increment linearly, Δθ₁ = αΔθ, Δv₁ = αΔv, α = (t_g − t_{k−1})/(t_k − t_{k−1}), and the
//! remainder (1 − α); the filter predicts to t_g, updates, and continues (the same
//! first-order interpolation KF-GINS and Shin 2005 use; the two-sample corrections of
//! the split parts see the preceding part as their previous increment). Fixes within
//! 1 µs of an epoch are applied at the epoch. The record of each split point is listed in
//! [`ForwardRun::split_points`]; [`RunOptions::observe_split_points`] false hands an
//! observer only the whole-epoch records (one per IMU epoch, as KF-GINS writes them).
//! Fixes inside an outage window
//! ([`FilterConfig::outages_s`], half-open (start, end]) are withheld; fixes before the
//! initial state or out of order are skipped and counted, and so are fixes whose quality
//! flag is not in [`FilterConfig::accept_quality`] (when that is not empty). Each fix's σ
//! is multiplied by the quality factor of its RTKLIB flag ([`super::QualityScale`]).
//!
//! # Gating and its recovery
//!
//! Every update is gated by [`FilterConfig::gate`] (the NHC by its own gate when it sets
//! one). Two rules keep the filter from starving:
//!
//! * **Gate recovery** ([`FilterConfig::gate_recovery_s`] = R,
//!   [`FilterConfig::gate_recovery_rejections`] = K): the time since the last
//!   accepted position fix is counted *outside* the outage windows only, i.e.
//!   τ = (t_fix − t_accept) − |(t_accept, t_fix] ∩ ⋃ windows|. When τ > R, or when the K
//!   position fixes before this one were all rejected grossly (also by the default robust
//!   gate at its ceiling; see [`FilterConfig::gate_recovery_rejections`]; not after an
//!   outage window or a gap in the fixes longer than R until a fix is accepted again:
//!   there the drift of dead reckoning is expected and the clock alone decides), the fix is
//!   applied with [`super::Gate::Off`] (counted in [`ForwardRun::gnss_forced`], listed
//!   with what triggered it in [`ForwardRun::recoveries`]): a state
//!   that every fix contradicts for R seconds of GNSS coverage has diverged (e.g. after
//!   an IMU fault) and the fixes are trusted over it. When that fix is a gross outlier
//!   even for the default robust gate at its ceiling (the state is far off, not merely
//!   over-confident), the navigation states are first re-initialised
//!   ([`Eskf::reset_navigation`], counted in [`ForwardRun::gnss_resets`]): position from
//!   the fix (lever arm removed); velocity from the chord to the previous fix when it is
//!   at most 2R earlier (σ the chord's, at least 1 m/s), else zero with σ 10 m/s; roll
//!   and pitch levelled from the mean specific force of the last second (exponential
//!   mean, time constant 1 s; σ 5°, covering accelerations up to ≈ 0.9 m/s²); yaw kept
//!   with σ at least 10°, unless the chord's speed is at least 1 m/s and its course
//!   atan2(v_E, v_N) differs from the kept yaw by more than 30°: then the yaw is the
//!   course with σ 10° (the heading a land vehicle or walker moves along, as at the
//!   initialisation; a vehicle reversing at that moment gets the opposite heading and is
//!   left to the filter). The sensor-error states are kept. A gyro fault about any axis
//!   (a roll, pitch or yaw jump) is thus undone.
//! * **First fix after an outage window**: under [`super::Gate::Robust`] it is applied
//!   with the robust weight but never rejected ([`super::Gate::never_reject`]), so an
//!   outage is never lengthened by rejected fixes because the window was long. Under
//!   [`super::Gate::Chi2`] it is tested like any fix (the user asked for the χ² test).
//!
//! # Storage for the smoother (memory per epoch)
//!
//! One [`EpochRecord`] per prediction step (IMU epochs plus split points): the
//! post-update navigation state (88 B), sensor-error estimates (96 B), the 21 σ's
//! (168 B) and the compensated increment of the interval that ended at the epoch (64 B)
//! — **416 B per epoch** (1 h at 200 Hz: 300 MB). Φ is not stored: it is rebuilt
//! exactly, bit for bit, by [`ForwardRun::transition`] from the previous record's state
//! and this record's compensated increment, and Q_d from the configuration, so P at any
//! epoch between two updates is recomputed by re-propagating from the last stored
//! covariance. The full covariance is stored only at update epochs ([`UpdateRecord`]:
//! packed prior and posterior, 2 × 231 f64 = 3.7 kB per GNSS epoch, 13 MB per hour at
//! 1 Hz). Between updates P_{k+1|k} = P_{k+1|k+1}, so the RTS recursion
//! C_k = P_{k|k} Φ_kᵀ P_{k+1|k}⁻¹ can be run segment by segment (re-propagate a segment
//! forward into a scratch buffer, then sweep it backwards).
//!
//! # Vehicle aids
//!
//! With [`FilterConfig::nhc`] / [`FilterConfig::standstill`] set, after the prediction
//! of each whole IMU epoch the standstill detector takes the compensated sample, and
//! ZUPT/ZARU (during a declared standstill) and NHC (otherwise) are applied at their
//! configured intervals ([`super::aids`]). Such an epoch gets an [`UpdateRecord`] like a
//! GNSS epoch (P before and after all its updates; merged into the GNSS record when a fix
//! was applied at the same epoch), so `updates` is ordered by strictly increasing
//! `epoch_index` and the segment-wise RTS recursion above applies unchanged. Memory: one
//! 3.7 kB record per aided epoch — NHC at 10 Hz adds ≈ 133 MB per hour of driving.

use driftless_model::linalg::{Vec3, norm};

use super::NavError;
use super::aids::{NhcConfig, StandstillConfig, StandstillDetector};
use super::eskf::{Eskf, UpdateKind, UpdateOutcome};
use super::model::{FilterConfig, Transition};
use super::state::{ATT, BG, Cov, N_STATES, PackedCov, SensorErrors, VEL, pack};
use crate::io::nav::GnssFixes;
use crate::nav::attitude::Euler;
use crate::nav::earth;
use crate::nav::mechanization::{ImuIncrement, NavState};

mod aid;
mod step;
use aid::*;
use step::*;

/// Time tolerance for "the fix is at this epoch", s.
const EPS_T: f64 = 1e-6;

/// Smallest chord speed whose course can replace the yaw at a reset, m/s (module docs).
const RESET_COURSE_MIN_SPEED_M_S: f64 = 1.0;

/// Largest difference between the kept yaw and the course at a reset before the course
/// replaces it, rad (30°; module docs).
const RESET_COURSE_MAX_DIFF_RAD: f64 = std::f64::consts::PI / 6.0;

/// Initial state of a forward run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialState {
    /// Navigation state at the start; its `time_s` is the start time.
    pub nav: NavState,
    /// Initial sensor-error estimates (usually zero).
    pub sensors: SensorErrors,
    /// Initial position σ, NED, m.
    pub sigma_pos_ned_m: Vec3,
    /// Initial velocity σ, NED, m/s.
    pub sigma_vel_ned_m_s: Vec3,
    /// Initial attitude σ (phi-angle N, E, D), rad.
    pub sigma_att_rad: Vec3,
    /// Initial σ of the 12 sensor states (b_g, b_a, s_g, s_a); `None` = the stationary
    /// Gauss–Markov σ of the configuration.
    pub sigma_sensors: Option<[f64; 12]>,
}

impl InitialState {
    /// Diagonal initial covariance.
    pub fn covariance(&self, cfg: &FilterConfig) -> Cov {
        let s = self
            .sigma_sensors
            .unwrap_or_else(|| cfg.stationary_sensor_sigma());
        let mut p = [[0.0; N_STATES]; N_STATES];
        for k in 0..3 {
            p[k][k] = self.sigma_pos_ned_m[k].powi(2);
            p[VEL + k][VEL + k] = self.sigma_vel_ned_m_s[k].powi(2);
            p[ATT + k][ATT + k] = self.sigma_att_rad[k].powi(2);
        }
        for (k, sk) in s.iter().enumerate() {
            p[BG + k][BG + k] = sk * sk;
        }
        p
    }
}

/// What the forward pass keeps per prediction step (module docs: 416 B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpochRecord {
    /// Navigation state after any update at this epoch.
    pub nav: NavState,
    /// Sensor-error estimates after any update.
    pub sensors: SensorErrors,
    /// √diag(P) after any update (order of [`super::state`]).
    pub std: [f64; N_STATES],
    /// Compensated increment of the interval ending here (zero-length for the first
    /// record).
    pub comp: ImuIncrement,
}

/// The updates of one epoch: a GNSS epoch's position/velocity updates and/or the
/// vehicle aids (NHC, ZUPT, ZARU; [`super::aids`]) applied at that epoch — all updates
/// at one epoch share one record, so `epoch_index` is strictly increasing.
#[derive(Clone, Debug, PartialEq)]
pub struct UpdateRecord {
    /// Index into [`ForwardRun::epochs`].
    pub epoch_index: usize,
    /// GNSS time, s.
    pub time_s: f64,
    /// The updates (GNSS position, velocity; NHC, ZUPT, ZARU) with innovation, NIS and
    /// gate result, in the order applied.
    pub outcomes: Vec<UpdateOutcome>,
    /// P before the updates (packed upper triangle).
    pub p_prior: Box<PackedCov>,
    /// P after the updates.
    pub p_post: Box<PackedCov>,
}

/// What made a position fix bypass the gate (module docs, gate recovery).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecoveryTrigger {
    /// [`FilterConfig::gate_recovery_rejections`] consecutive fixes rejected.
    Rejections,
    /// No fix accepted for longer than [`FilterConfig::gate_recovery_s`] (outside the
    /// outage windows).
    Time,
}

/// One gate recovery: a position fix applied without the gate after the filter had
/// rejected the fixes before it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecoveryEvent {
    /// Time of the fix, s.
    pub time_s: f64,
    /// What triggered it.
    pub trigger: RecoveryTrigger,
    /// Position fixes rejected in a row before it.
    pub rejected_fixes: usize,
    /// Time since the last accepted position fix, outside the outage windows, s.
    pub starved_s: f64,
    /// Horizontal distance between the predicted antenna position and the fix, m.
    pub horizontal_innovation_m: f64,
    /// The navigation states were re-initialised at the fix (the state was far off,
    /// not merely over-confident).
    pub reset: bool,
    /// At the reset the yaw was taken from the GNSS course (module docs).
    pub yaw_from_course: bool,
}

impl RecoveryEvent {
    /// One line: time, trigger, what was done.
    pub fn describe(&self) -> String {
        let what = if self.reset {
            format!(
                "navigation state reset to the fix (position, velocity from the fixes, tilt \
                 levelled, {})",
                if self.yaw_from_course {
                    "yaw from the GNSS course"
                } else {
                    "yaw kept"
                }
            )
        } else {
            "the fix applied without the gate".to_string()
        };
        let why = match self.trigger {
            RecoveryTrigger::Rejections => "consecutive rejections",
            RecoveryTrigger::Time => "time without an accepted fix",
        };
        format!(
            "gate recovery at t = {:.3} s after {} rejected fixes in {:.1} s ({why}); \
             predicted position {:.1} m from the fix; {what}",
            self.time_s, self.rejected_fixes, self.starved_s, self.horizontal_innovation_m
        )
    }
}

/// Result of [`run_forward`].
#[derive(Clone, Debug, PartialEq)]
pub struct ForwardRun {
    /// One record per prediction step, the first at the initial state.
    pub epochs: Vec<EpochRecord>,
    /// One record per GNSS epoch used (accepted or rejected) and per epoch with vehicle
    /// aids (see [`UpdateRecord`]).
    pub updates: Vec<UpdateRecord>,
    /// Fixes withheld by outage windows.
    pub gnss_withheld: usize,
    /// Fixes before the initial state, after the last IMU epoch, or out of order.
    pub gnss_skipped: usize,
    /// Fixes skipped because their quality flag is not in
    /// [`FilterConfig::accept_quality`].
    pub gnss_quality_skipped: usize,
    /// Measurements rejected by the gate (each logged in `updates`).
    pub gnss_rejected: usize,
    /// Accepted measurements whose R the robust gate inflated
    /// ([`super::Gate::Robust`]; a subset of `gnss_accepted`).
    pub gnss_inflated: usize,
    /// Position fixes applied without the gate by the gate-recovery rule
    /// ([`FilterConfig::gate_recovery_s`]).
    pub gnss_forced: usize,
    /// Forced fixes before which the navigation states were re-initialised (module docs;
    /// a subset of `gnss_forced`).
    pub gnss_resets: usize,
    /// Every gate recovery after rejected fixes or with a reset, in time order (module
    /// docs): what triggered it and whether the state was reset. Empty on a run whose
    /// fixes the gate never rejected in a row. (A fix forced only because the GNSS data
    /// had a gap longer than the clock is counted in `gnss_forced`, not listed.)
    pub recoveries: Vec<RecoveryEvent>,
    /// Measurements accepted.
    pub gnss_accepted: usize,
    /// NHC updates accepted ([`super::aids`]).
    pub nhc_applied: usize,
    /// ZUPT updates accepted.
    pub zupt_applied: usize,
    /// ZARU updates accepted.
    pub zaru_applied: usize,
    /// NHC / ZUPT / ZARU updates rejected by their gates (logged in `updates`).
    pub aids_rejected: usize,
    /// Accepted NHC / ZUPT / ZARU updates whose R the robust gate inflated.
    pub aids_inflated: usize,
    /// Detected standstill intervals (start, end), s ([`super::aids`]).
    pub standstills: Vec<(f64, f64)>,
    /// Index in the whole run of `epochs[0]`: 0, unless the records were handed to an
    /// observer and dropped ([`run_forward_observed`] with `keep_epochs` false), when
    /// `epochs` holds only the last record and `epoch_index` values count from the
    /// start of the run.
    pub first_epoch: usize,
    /// Indices in the whole run (like `epoch_index`) of the records at GNSS split points:
    /// the prediction steps that end at a fix time strictly between two IMU epochs. All
    /// other records after the first are at IMU epochs.
    pub split_points: Vec<usize>,
    /// −1/T of the sensor states (to rebuild Φ).
    neg_inv_tau: [f64; 12],
    /// σ_c of the unmodelled gyro axis coupling (to rebuild the interval's Q_c).
    coupling_sigma_rad: f64,
}

impl ForwardRun {
    /// A = Φ − I of the interval ending at epoch `k` (≥ 1), rebuilt exactly as the forward
    /// pass built it.
    pub fn transition(&self, k: usize) -> Option<Transition> {
        if k == 0 || k >= self.epochs.len() {
            return None;
        }
        let prev = &self.epochs[k - 1];
        let c = &self.epochs[k].comp;
        let inv = 1.0 / c.dt_s;
        Some(
            Transition::new(
                &prev.nav,
                c.dtheta_rad.map(|v| v * inv),
                c.dvel_m_s.map(|v| v * inv),
                c.dt_s,
                &self.neg_inv_tau,
            )
            .with_rotation_noise(self.coupling_sigma_rad),
        )
    }

    /// The rejected measurements (gate).
    pub fn rejections(&self) -> impl Iterator<Item = &UpdateOutcome> {
        self.updates
            .iter()
            .flat_map(|u| u.outcomes.iter())
            .filter(|o| !o.accepted)
    }
}

fn record(f: &Eskf, comp: ImuIncrement) -> EpochRecord {
    EpochRecord {
        nav: *f.nav(),
        sensors: *f.sensors(),
        std: f.std(),
        comp,
    }
}

fn scaled(inc: &ImuIncrement, k: f64, time_s: f64, dt_s: f64) -> ImuIncrement {
    ImuIncrement {
        time_s,
        dt_s,
        dtheta_rad: inc.dtheta_rad.map(|v| v * k),
        dvel_m_s: inc.dvel_m_s.map(|v| v * k),
    }
}

fn check_gnss(gnss: &GnssFixes) -> Result<(), NavError> {
    let n = gnss.len();
    let bad = |what: &str, len: usize| {
        Err(NavError::InvalidMeasurement {
            time_s: f64::NAN,
            reason: format!("GNSS column {what} has {len} entries, time has {n}"),
        })
    };
    for (what, len) in [
        ("lat", gnss.lat_rad.len()),
        ("lon", gnss.lon_rad.len()),
        ("height", gnss.height_m.len()),
        ("sigma", gnss.sigma_ned_m.len()),
        ("quality", gnss.quality.len()),
    ] {
        if len != n {
            return bad(what, len);
        }
    }
    if let Some(v) = &gnss.vel_ned_m_s
        && v.len() != n
    {
        return bad("velocity", v.len());
    }
    if let Some(v) = &gnss.sigma_vel_ned_m_s
        && v.len() != n
    {
        return bad("velocity σ", v.len());
    }
    Ok(())
}

/// Run the filter forward from `init` over `imu` (increments ending at `time_s`), with
/// GNSS `gnss` (position; velocity too if `cfg.use_gnss_velocity`). See the module docs.
///
/// Errors: invalid configuration or initial state, IMU epochs duplicated / out of order /
/// with a gap, invalid increments or fixes (σ ≤ 0, non-finite), covariance failure
/// ([`NavError::Covariance`] with a diagnosis). Never returns NaN output.
pub fn run_forward(
    imu: &[ImuIncrement],
    gnss: &GnssFixes,
    init: InitialState,
    cfg: &FilterConfig,
) -> Result<ForwardRun, NavError> {
    run_forward_observed(imu, gnss, init, cfg, &mut |_: &[EpochRecord]| {}, true)
}

/// Epoch records are handed to the observer of [`run_forward_observed`] in blocks of at
/// least this many.
pub const OBSERVER_BLOCK: usize = 4096;

/// [`run_forward`], handing the epoch records to `observer` while the filter runs: in
/// order, each exactly once, in blocks of at least [`OBSERVER_BLOCK`] records once they
/// are final (no later update at their epoch can change them), the last block at the
/// end. Lets a caller write outputs on another thread while the filter runs. With
/// `keep_epochs` false the records are dropped once observed (memory stays small; the
/// run cannot then be smoothed), see [`ForwardRun::first_epoch`].
pub fn run_forward_observed(
    imu: &[ImuIncrement],
    gnss: &GnssFixes,
    init: InitialState,
    cfg: &FilterConfig,
    observer: &mut dyn FnMut(&[EpochRecord]),
    keep_epochs: bool,
) -> Result<ForwardRun, NavError> {
    let opts = RunOptions {
        keep_epochs,
        ..RunOptions::default()
    };
    run_forward_with(imu, gnss, init, cfg, &opts, observer)
}

/// How [`run_forward_with`] stores and hands out its records, and which fixes it skips.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunOptions {
    /// Keep every record in [`ForwardRun::epochs`] (default true; the smoother needs
    /// them). False: records are dropped once observed ([`ForwardRun::first_epoch`]).
    pub keep_epochs: bool,
    /// Hand the records at GNSS split points ([`ForwardRun::split_points`]) to the
    /// observer too (default true). False: the observer sees the initial record and one
    /// record per IMU epoch — the state after any update at or before that epoch, as a
    /// filter that writes one row per IMU epoch reports it; the split records are still
    /// kept in `epochs` when `keep_epochs` is set.
    pub observe_split_points: bool,
    /// Skip (count in [`ForwardRun::gnss_skipped`]) every fix at or before this time, s.
    /// `None` (default): fixes before the initial time are skipped and a fix at the
    /// initial time is applied at once. KF-GINS updates only with fixes strictly after
    /// its `starttime`: `Some(starttime)`.
    pub skip_gnss_until_s: Option<f64>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            keep_epochs: true,
            observe_split_points: true,
            skip_gnss_until_s: None,
        }
    }
}

/// Hands `epochs[from..to]` to the observer, leaving out the split-point records when
/// `with_splits` is false (`splits`: whole-run indices, increasing; `first`: the
/// whole-run index of `epochs[0]`).
fn observe(
    observer: &mut dyn FnMut(&[EpochRecord]),
    epochs: &[EpochRecord],
    (from, to): (usize, usize),
    first: usize,
    splits: &[usize],
    with_splits: bool,
) {
    if with_splits {
        observer(&epochs[from..to]);
        return;
    }
    let lo = splits.partition_point(|&k| k < first + from);
    let mut a = from;
    for &k in splits[lo..].iter().take_while(|&&k| k < first + to) {
        let k = k - first;
        if k > a {
            observer(&epochs[a..k]);
        }
        a = k + 1;
    }
    if to > a {
        observer(&epochs[a..to]);
    }
}

/// The forward pass of [`run_forward`] with [`RunOptions`], handing the records to
/// `observer` as [`run_forward_observed`] does (each exactly once, in order, once final;
/// without split points when [`RunOptions::observe_split_points`] is false, so then in
/// runs between the left-out records).
pub fn run_forward_with(
    imu: &[ImuIncrement],
    gnss: &GnssFixes,
    init: InitialState,
    cfg: &FilterConfig,
    opts: &RunOptions,
    observer: &mut dyn FnMut(&[EpochRecord]),
) -> Result<ForwardRun, NavError> {
    cfg.validate()?;
    check_gnss(gnss)?;
    let t0 = init.nav.time_s;
    let (start, prev_inc, nominal_dt) = first_increment(imu, t0)?;
    let mut f = Eskf::new(init.nav, init.sensors, init.covariance(cfg), prev_inc, cfg)?;
    let capacity = if opts.keep_epochs {
        imu.len() - start + gnss.len() + 1
    } else {
        2 * OBSERVER_BLOCK
    };
    let mut ctx = start_ctx(gnss, cfg, t0, capacity);
    let mut aids = AidState::new(cfg, nominal_dt, t0)?;
    let zero = ImuIncrement {
        time_s: t0,
        dt_s: 0.0,
        dtheta_rad: [0.0; 3],
        dvel_m_s: [0.0; 3],
    };
    ctx.run.epochs.push(record(&f, zero));
    let mut g = apply_start_fixes(&mut ctx, &mut f, t0, opts.skip_gnss_until_s)?;
    let mut t_prev = t0;
    let mut observed = 0;
    for inc in &imu[start..] {
        let dt = epoch_interval(t_prev, inc.time_s, nominal_dt, cfg.max_gap_factor)?;
        update_mean_force(&mut ctx, inc, dt);
        g = propagate_epoch(&mut ctx, &mut f, inc, dt, t_prev, g)?;
        if aids.enabled {
            let raw = ImuIncrement { dt_s: dt, ..*inc };
            aids.after_epoch(&mut f, &raw, &mut ctx)?;
        }
        t_prev = inc.time_s;
        observed = observe_settled(&mut ctx, observer, observed, opts);
    }
    let r = &ctx.run;
    observe(
        observer,
        &r.epochs,
        (observed, r.epochs.len()),
        r.first_epoch,
        &r.split_points,
        opts.observe_split_points,
    );
    ctx.run.gnss_skipped += gnss.len() - g;
    if let Some(d) = aids.detector {
        ctx.run.standstills = d.finish();
    }
    Ok(ctx.run)
}

/// Index of the first IMU increment that ends after the start `t0`, the increment
/// ending at `t0` (it primes the two-sample corrections) if any, and the nominal
/// interval (that of the first increment), s.
fn first_increment(
    imu: &[ImuIncrement],
    t0: f64,
) -> Result<(usize, Option<ImuIncrement>, f64), NavError> {
    let start = imu.partition_point(|i| i.time_s <= t0 + EPS_T);
    if start >= imu.len() {
        return Err(NavError::ImuTiming {
            time_s: t0,
            reason: "no IMU epoch after the initial time".into(),
        });
    }
    let prev_inc = start
        .checked_sub(1)
        .map(|i| imu[i])
        .filter(|i| (i.time_s - t0).abs() <= EPS_T);
    let nominal_dt = imu[start].dt_s;
    if !(nominal_dt.is_finite() && nominal_dt > 0.0) {
        return Err(NavError::InvalidIncrement {
            time_s: imu[start].time_s,
            reason: format!("interval {nominal_dt} s"),
        });
    }
    Ok((start, prev_inc, nominal_dt))
}

/// The run context at the start `t0`: no fix seen yet, all counters zero, room for
/// `capacity` records.
fn start_ctx<'a>(gnss: &'a GnssFixes, cfg: &'a FilterConfig, t0: f64, capacity: usize) -> Ctx<'a> {
    Ctx {
        gnss,
        cfg,
        gnss_speed: None,
        last_position_accept_s: t0,
        last_fix_s: t0,
        prev_fix: None,
        f_mean_b: None,
        rejected_in_row: 0,
        gross_in_row: 0,
        count_armed: true,
        run: ForwardRun {
            epochs: Vec::with_capacity(capacity),
            first_epoch: 0,
            split_points: Vec::new(),
            updates: Vec::new(),
            gnss_withheld: 0,
            gnss_skipped: 0,
            gnss_quality_skipped: 0,
            gnss_rejected: 0,
            gnss_inflated: 0,
            gnss_forced: 0,
            gnss_resets: 0,
            recoveries: Vec::new(),
            gnss_accepted: 0,
            nhc_applied: 0,
            zupt_applied: 0,
            zaru_applied: 0,
            aids_rejected: 0,
            aids_inflated: 0,
            standstills: Vec::new(),
            neg_inv_tau: cfg.neg_inv_tau(),
            coupling_sigma_rad: cfg.gyro_coupling_sigma_rad,
        },
    }
}

/// Skips the fixes before the start `t0` (and those at or before `skip_until_s`), then
/// applies the fixes at the start; returns the index of the first fix after it.
fn apply_start_fixes(
    ctx: &mut Ctx,
    f: &mut Eskf,
    t0: f64,
    skip_until_s: Option<f64>,
) -> Result<usize, NavError> {
    let gnss = ctx.gnss;
    let ng = gnss.len();
    let mut g = 0;
    while g < ng {
        let tg = gnss.time_s[g];
        let before = tg < t0 - EPS_T || tg.is_nan() || skip_until_s.is_some_and(|s| tg <= s);
        if !before {
            break;
        }
        ctx.run.gnss_skipped += 1;
        g += 1;
    }
    while g < ng && gnss.time_s[g] <= t0 + EPS_T {
        if ctx.withheld(gnss.time_s[g]) {
            ctx.run.gnss_withheld += 1;
        } else if ctx.quality_skipped(g) {
            ctx.run.gnss_quality_skipped += 1;
        } else {
            ctx.apply_fix(f, g)?;
        }
        g += 1;
    }
    Ok(g)
}

/// Interval from the previous epoch `t_prev` to `t_end`, s; an error when the epoch is
/// not after the previous one or the gap exceeds `max_gap_factor` nominal intervals.
fn epoch_interval(
    t_prev: f64,
    t_end: f64,
    nominal_dt: f64,
    max_gap_factor: f64,
) -> Result<f64, NavError> {
    let dt = t_end - t_prev;
    let forward = dt > 0.0;
    if !forward {
        return Err(NavError::ImuTiming {
            time_s: t_end,
            reason: format!(
                "epoch not after the previous one ({t_prev} s): duplicated or out of order"
            ),
        });
    }
    if dt > max_gap_factor * nominal_dt {
        return Err(NavError::ImuTiming {
            time_s: t_end,
            reason: format!("gap of {dt} s after {t_prev} s (nominal interval {nominal_dt} s)"),
        });
    }
    Ok(dt)
}

/// Updates the exponential mean of the raw specific force with the increment `inc` over
/// `dt`: m ← m + min(dt, 1)·(f − m), time constant 1 s (the first sample starts it).
fn update_mean_force(ctx: &mut Ctx, inc: &ImuIncrement, dt: f64) {
    let f_now = inc.dvel_m_s.map(|v| v / dt);
    ctx.f_mean_b = Some(match ctx.f_mean_b {
        Some(m) => {
            let a = dt.min(1.0);
            std::array::from_fn(|k| m[k] + a * (f_now[k] - m[k]))
        }
        None => f_now,
    });
}

/// Propagates over one IMU epoch (`t_prev` to the end of `inc`, interval `dt`), splitting
/// the increment at each fix inside it and applying the fixes from index `g` on that fall
/// in the epoch; returns the index of the first fix after it.
fn propagate_epoch(
    ctx: &mut Ctx,
    f: &mut Eskf,
    inc: &ImuIncrement,
    dt: f64,
    t_prev: f64,
    mut g: usize,
) -> Result<usize, NavError> {
    let gnss = ctx.gnss;
    let ng = gnss.len();
    let t_end = inc.time_s;
    let mut rest = ImuIncrement { dt_s: dt, ..*inc };
    let mut t_start = t_prev;
    let mut done = false;
    while g < ng && gnss.time_s[g] <= t_end + EPS_T {
        let tg = gnss.time_s[g];
        let in_order = tg >= t_start - EPS_T;
        if !in_order {
            // Out of order (or NaN) time tag.
            ctx.run.gnss_skipped += 1;
            g += 1;
            continue;
        }
        if ctx.withheld(tg) {
            ctx.run.gnss_withheld += 1;
            g += 1;
            continue;
        }
        if ctx.quality_skipped(g) {
            ctx.run.gnss_quality_skipped += 1;
            g += 1;
            continue;
        }
        if tg >= t_end - EPS_T {
            if !done {
                f.predict(&rest)?;
                ctx.run
                    .epochs
                    .push(record(f, f.last_compensated().unwrap_or(rest)));
                done = true;
                t_start = t_end;
            }
        } else if tg > t_start + EPS_T {
            let alpha = (tg - t_start) / (t_end - t_start);
            let first = scaled(&rest, alpha, tg, tg - t_start);
            rest = scaled(&rest, 1.0 - alpha, t_end, t_end - tg);
            f.predict(&first)?;
            ctx.run
                .epochs
                .push(record(f, f.last_compensated().unwrap_or(first)));
            let idx = ctx.run.first_epoch + ctx.run.epochs.len() - 1;
            ctx.run.split_points.push(idx);
            t_start = tg;
        }
        ctx.apply_fix(f, g)?;
        g += 1;
    }
    if !done {
        f.predict(&rest)?;
        ctx.run
            .epochs
            .push(record(f, f.last_compensated().unwrap_or(rest)));
    }
    Ok(g)
}

/// Hands the settled records from `observed` on to the observer once there are at least
/// [`OBSERVER_BLOCK`] of them, dropping them when the run does not keep its records;
/// returns the new count of records already handed over (in `ctx.run.epochs`).
fn observe_settled(
    ctx: &mut Ctx,
    observer: &mut dyn FnMut(&[EpochRecord]),
    mut observed: usize,
    opts: &RunOptions,
) -> usize {
    // Only the newest record can still change (updates at its epoch).
    let settled = ctx.run.epochs.len() - 1;
    if settled - observed >= OBSERVER_BLOCK {
        let r = &ctx.run;
        observe(
            observer,
            &r.epochs,
            (observed, settled),
            r.first_epoch,
            &r.split_points,
            opts.observe_split_points,
        );
        observed = settled;
        if !opts.keep_epochs {
            ctx.run.epochs.drain(..settled);
            ctx.run.first_epoch += settled;
            observed = 0;
        }
    }
    observed
}

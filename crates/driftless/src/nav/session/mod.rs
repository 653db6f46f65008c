//! One navigation job on recorded data: initialise (at rest or in motion), run the
//! forward filter with GNSS outages, and evaluate against the reference fixes.
//!
//! * **Initialisation** ([`initialise`]): the gyro biases are primed from the mean
//!   angular rate of a static stretch at the start of the log when the IMU is static
//!   there (|f̄| ≈ g and a small rate spread; the Earth rate, ≤ 15 deg/h, is left in the
//!   estimate and absorbed by the filter). The filter starts at a GNSS fix inside the IMU
//!   span, outside the outage windows, with an accepted quality flag and with a velocity:
//!   * **yaw**: given ([`SessionConfig::initial_yaw_rad`] or the third component of
//!     [`SessionConfig::initial_attitude_rad`]; the filter then starts at the first such
//!     fix whatever the speed), else the course over ground atan2(v_E, v_N) at the first
//!     fix with a horizontal speed above [`SessionConfig::min_speed_m_s`] and a course σ
//!     at most [`SessionConfig::max_heading_sigma_rad`] (below);
//!   * **roll, pitch**: given (`initial_attitude_rad`), else levelled from the
//!     accelerometer over the static start ([`super::filter::level_static`]) and carried
//!     to the start epoch by integrating the bias-compensated gyro (the tilt is yaw-free:
//!     the down vector in the body frame rotates with the body alone; Earth rate and
//!     transport rate, < 0.005 deg/s, neglected), else the land-vehicle guess: pitch the
//!     climb angle atan2(−v_D, v_H) (0 below `min_speed_m_s`), roll 0;
//!   * **velocity**: the GNSS velocity, or for position-only GNSS the chord of the fixes
//!     around the start fix over [`SessionConfig::align_baseline_s`] (the first and last
//!     fix within ±baseline/2; for a path of constant curvature the chord is parallel to
//!     the tangent at the middle fix, so the course is unbiased in a steady turn);
//!   * **position**: the fix moved from the antenna to the IMU by the lever arm.
//!
//!   Initial σ, consistent with how each value was obtained: given angles
//!   [`SessionConfig::given_attitude_sigma_rad`]; levelled roll/pitch
//!   √(σ_level² + (σ_ω Δt)²), σ_level = σ_f/g from [`super::filter::level_static`],
//!   σ_ω = Ω_ie + ARW/√T_static the residual rate after priming, Δt the time from the
//!   static window's end to the start; the vehicle guess 2°; the course
//!   σ_ψ = √((σ_vH/v_H)² + (δ/2)²) with σ_vH the horizontal velocity σ (GNSS velocity σ,
//!   else √(σ_a² + σ_b²)/(t_b − t_a) of the chord's two fixes, σ after the floor and
//!   quality scaling) and δ the angle between the chords of the two halves of the
//!   baseline (turning and antenna sway; conservative in a steady turn), floored at 1°.
//!   Example: a 1.2 m/s walk with 4-Hz fixes of 5 cm σ, 2-s baseline, straight:
//!   σ_vH = 0.035 m/s, σ_ψ ≈ 1.7°; with 10-cm σ 3.4°.
//! * **GNSS σ floor** ([`SessionConfig::auto_sigma_floor`], on by default): a first
//!   forward pass with the file's σ (after any fixed floor), without the outage windows,
//!   gives the innovations from which [`super::gnss_floor`] estimates per solution quality
//!   the σ the fixes really carry; the final pass uses the file's σ floored at that,
//!   starting at the same fix as the first pass (its initial σ recomputed from the
//!   floored fixes). The estimate describes the recording's GNSS, as a noise model
//!   describes its IMU: withheld fixes count in it, one number per class and axis group.
//!   Fixes around a reset of the first pass's gate recovery (from the last accepted fix
//!   before it to [`SessionConfig::reconverge_s`] after it: an IMU fault, not the GNSS)
//!   are left out.
//! * **Evaluation**: the reference is the GNSS fixes themselves (on `drive_0708` an RTK
//!   solution, cm level). The full-GNSS accuracy is the one-step prediction error at each
//!   accepted fix — the horizontal innovation, i.e. the filter's antenna position *before*
//!   it sees the fix vs the fix — which is stricter than comparing the updated solution.
//!   Per outage window (s, e] see [`OutageResult`].

use super::attitude::Euler;
use super::attitude::Quat;
use super::earth::{meridian_radius_m, ned_offset_m, prime_vertical_radius_m};
use super::filter::NavError;
use super::filter::align::{AlignConfig, level_static};
use super::filter::eskf::UpdateKind;
use super::filter::model::FilterConfig;
use super::filter::run::{ForwardRun, InitialState, run_forward};
use super::filter::state::SensorErrors;
use super::mechanization::{ImuIncrement, NavState};
use super::outage::OutageWindow;
use super::pipeline::ImuStream;
use crate::io::nav::GnssFixes;
use driftless_model::linalg::{Vec3, add, norm, scale};

mod init;
mod records;
pub use init::*;
pub use records::*;

/// Settings of a session beyond the filter's own.
#[derive(Clone, Debug)]
pub struct SessionConfig {
    /// The filter (noise, lever arm, gating …). Leave its `outages_s` empty: the session
    /// sets it from `outages` ([`run_session`] refuses a different list there).
    pub filter: FilterConfig,
    /// GNSS outage windows, absolute GNSS times.
    pub outages: Vec<OutageWindow>,
    /// Horizontal speed needed to take the heading from the GNSS course, m/s. Default
    /// 0.5: a slow walk or a slow robot still aligns, and the course σ (module docs:
    /// σ_vH/v_H plus turning) tells the filter how good the course is; a fix whose
    /// course σ exceeds `max_heading_sigma_rad` is passed over for a later one.
    pub min_speed_m_s: f64,
    /// Largest heading σ accepted from the GNSS course, rad. Default 10°.
    pub max_heading_sigma_rad: f64,
    /// Baseline of the fixes whose chord gives the velocity for position-only GNSS, s.
    /// Default 2 (at 4 Hz the chord spans 9 fixes; at 1 Hz 3).
    pub align_baseline_s: f64,
    /// Given initial yaw, rad: the filter starts at the first usable fix regardless of
    /// speed. Ignored when `initial_attitude_rad` is set.
    pub initial_yaw_rad: Option<f64>,
    /// Given initial roll, pitch, yaw, rad (body FRD to NED, z-y-x Euler angles).
    pub initial_attitude_rad: Option<[f64; 3]>,
    /// σ of given roll, pitch, yaw, rad. Default (1°, 1°, 5°).
    pub given_attitude_sigma_rad: [f64; 3],
    /// Length of the static stretch at the start used to prime the gyro biases, s (0 = off).
    pub static_prime_s: f64,
    /// Time after the start excluded from the full-GNSS accuracy figure, s.
    pub converge_s: f64,
    /// Time after each outage excluded from the full-GNSS accuracy figure, s.
    pub reconverge_s: f64,
    /// Floor on the fixes' σ (horizontal, vertical), m: receivers' formal σ (RTKLIB's
    /// ~1 cm for a fixed RTK solution) ignore antenna vibration and IMU–GNSS time-tag
    /// error of a moving vehicle. `None` (default) keeps the file's σ.
    pub sigma_floor_m: Option<(f64, f64)>,
    /// Floor the fixes' σ (after `sigma_floor_m`) at what the innovations of a first pass
    /// call for, per solution quality ([`super::gnss_floor`]; module docs). Default true:
    /// it finds decimetres on a swaying hand-held antenna and stays at or below the file's
    /// σ where that is right. Costs a second forward pass.
    pub auto_sigma_floor: bool,
    /// Also run the RTS smoother and report its errors inside the outages.
    pub smooth: bool,
    /// Initial σ of the 12 sensor states (b_g, b_a, s_g, s_a; e.g. the turn-on bias σ of
    /// a data sheet); `None` = the stationary Gauss–Markov σ of the noise model. A gyro
    /// bias primed from a static start keeps its smaller σ.
    pub initial_sensor_sigma: Option<[f64; 12]>,
}

impl SessionConfig {
    /// Defaults around a filter configuration.
    pub fn new(filter: FilterConfig) -> SessionConfig {
        SessionConfig {
            filter,
            outages: Vec::new(),
            min_speed_m_s: 0.5,
            max_heading_sigma_rad: 10f64.to_radians(),
            align_baseline_s: 2.0,
            initial_yaw_rad: None,
            initial_attitude_rad: None,
            given_attitude_sigma_rad: [1f64.to_radians(), 1f64.to_radians(), 5f64.to_radians()],
            static_prime_s: 10.0,
            converge_s: 60.0,
            reconverge_s: 30.0,
            sigma_floor_m: None,
            auto_sigma_floor: true,
            smooth: false,
            initial_sensor_sigma: None,
        }
    }
}

/// Errors of one outage window (s, e] (fixes at s < t ≤ e withheld,
/// [`OutageWindow::contains`]).
///
/// * **End-of-outage error**: the innovation of the first position fix after the window
///   (t > e, within 2 s of e) — the filter's predicted antenna position before that fix
///   minus the fix, i.e. the error after dead reckoning from the last fix used (at or
///   before s) to that fix. Reported whether the gate accepted the fix or not.
/// * **Maximum error inside**: the largest horizontal distance between the antenna
///   position of the solution and the reference (the fixes interpolated linearly, gaps
///   ≤ 2 s) over the IMU epochs with s < t ≤ e.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutageResult {
    /// The window.
    pub window: OutageWindow,
    /// Horizontal end-of-outage error, m.
    pub end_horizontal_m: Option<f64>,
    /// Largest horizontal error inside the window, m.
    pub max_horizontal_m: f64,
    /// Vertical end-of-outage error, m.
    pub end_vertical_m: Option<f64>,
}

/// Result of [`run_session`].
#[derive(Debug)]
pub struct SessionResult {
    /// The forward run.
    pub run: ForwardRun,
    /// The GNSS σ floors estimated from a first pass (empty unless
    /// [`SessionConfig::auto_sigma_floor`]).
    pub sigma_floors: Vec<super::gnss_floor::ClassFloor>,
    /// The initial state used.
    pub init: InitialState,
    /// The filter configuration of the forward run (the session's outage windows in
    /// `outages_s`): with `init`, what the smoother needs ([`SessionResult::smooth`]).
    pub filter: FilterConfig,
    /// Gyro bias primed from the static start, if it was static.
    pub primed_gyro_bias_rad_s: Option<Vec3>,
    /// RMS horizontal one-step prediction error at accepted fixes outside the convergence
    /// periods (after the start, after each outage window and after each gap in the
    /// GNSS data longer than three median fix intervals), m, and the number of fixes it
    /// covers.
    pub horizontal_rms_m: Option<(f64, usize)>,
    /// Per-outage errors of the forward (real-time) filter.
    pub outages: Vec<OutageResult>,
    /// Per-outage errors of the smoothed solution (when `smooth`); `end_horizontal_m` is
    /// the smoothed error at the last IMU epoch of the window.
    pub smoothed_outages: Option<Vec<OutageResult>>,
}

/// Run the forward filter on `imu` and `gnss` and evaluate it. The fixes are checked
/// first ([`GnssFixes::validate`]: equal column lengths, finite values, increasing time,
/// σ > 0).
pub fn run_session(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
) -> Result<SessionResult, NavError> {
    gnss.validate()
        .map_err(|e| NavError::Config(e.to_string()))?;
    let primed = if cfg.static_prime_s > 0.0 {
        prime_gyro_bias(imu, cfg.static_prime_s)
    } else {
        None
    };
    let floored;
    let used: &GnssFixes = match cfg.sigma_floor_m {
        Some((h, v)) => {
            floored = with_sigma_floor(gnss, h, v);
            &floored
        }
        None => gnss,
    };
    let fcfg = session_filter_config(cfg)?;
    let data_gaps = gnss_data_gaps(&used.time_s);
    let mut floors = Vec::new();
    let mut start_s = None;
    let auto;
    let used = if cfg.auto_sigma_floor {
        let (t, estimated) = first_pass_floors(imu, used, cfg, &fcfg, primed, &data_gaps)?;
        start_s = Some(t);
        floors = estimated;
        auto = super::gnss_floor::apply(used, &floors, &fcfg.quality_scale);
        &auto
    } else {
        used
    };
    let init = match start_s {
        // The first pass ran without the outage windows: start there unless a window
        // withholds that fix, then as usual.
        Some(t) if !cfg.outages.iter().any(|w| w.contains(t)) => {
            initialise_at(imu, used, cfg, primed, Some(t))
                .or_else(|_| initialise(imu, used, cfg, primed))?
        }
        _ => initialise(imu, used, cfg, primed)?,
    };
    let run = run_forward(&imu.epochs, used, init, &fcfg)?;

    // Full-GNSS accuracy: prior innovations at accepted position fixes.
    let excluded = ConvergencePeriods::new(init.nav.time_s, &cfg.outages, &data_gaps, cfg);
    let horizontal_rms_m = horizontal_rms(&run, &excluded);

    let lever = fcfg.lever_arm_b_m;
    let states: Vec<&NavState> = run.epochs.iter().map(|e| &e.nav).collect();
    let outages = cfg
        .outages
        .iter()
        .map(|w| outage_errors(&states, &run, gnss, *w, lever))
        .collect();
    let smoothed_outages = if cfg.smooth {
        Some(smoothed_outage_errors(&run, &init, &fcfg, cfg, gnss)?)
    } else {
        None
    };
    Ok(SessionResult {
        run,
        init,
        filter: fcfg,
        sigma_floors: floors,
        primed_gyro_bias_rad_s: primed,
        horizontal_rms_m,
        outages,
        smoothed_outages,
    })
}

/// A copy of `gnss` with the σ floored: horizontal components at `h`, vertical at `v`, m.
fn with_sigma_floor(gnss: &GnssFixes, h: f64, v: f64) -> GnssFixes {
    let mut g = gnss.clone();
    for s in &mut g.sigma_ned_m {
        s[0] = s[0].max(h);
        s[1] = s[1].max(h);
        s[2] = s[2].max(v);
    }
    g
}

/// The session's filter configuration with the session's outage windows in `outages_s`;
/// an error when the filter configuration names other windows of its own.
fn session_filter_config(cfg: &SessionConfig) -> Result<FilterConfig, NavError> {
    let mut fcfg = cfg.filter.clone();
    let outages_s: Vec<(f64, f64)> = cfg.outages.iter().map(|w| (w.start_s, w.end_s)).collect();
    if !fcfg.outages_s.is_empty() && fcfg.outages_s != outages_s {
        return Err(NavError::Config(format!(
            "two outage lists: the filter configuration names {} window(s) in outages_s, \
             the session {} in outages; set the windows in SessionConfig::outages only",
            fcfg.outages_s.len(),
            outages_s.len()
        )));
    }
    fcfg.outages_s = outages_s;
    Ok(fcfg)
}

/// The convergence periods: `converge_s` after the start t0, and `reconverge_s` after
/// each of some windows (outage windows, data gaps).
struct ConvergencePeriods {
    /// Start time, s.
    t0: f64,
    /// Length of the period after the start, s.
    converge_s: f64,
    /// Length of the period after each window, s.
    reconverge_s: f64,
    /// (start, end] of each window, s.
    windows: Vec<(f64, f64)>,
}

impl ConvergencePeriods {
    /// The periods after the start `t0`, each of `outages` and each of the data `gaps`,
    /// with the lengths of `cfg`.
    fn new(t0: f64, outages: &[OutageWindow], gaps: &[(f64, f64)], cfg: &SessionConfig) -> Self {
        let windows: Vec<(f64, f64)> = outages
            .iter()
            .map(|w| (w.start_s, w.end_s))
            .chain(gaps.iter().copied())
            .collect();
        ConvergencePeriods {
            t0,
            converge_s: cfg.converge_s,
            reconverge_s: cfg.reconverge_s,
            windows,
        }
    }

    /// `t` falls in a convergence period: before t0 + converge_s, or inside a window
    /// (start, end + reconverge_s].
    fn contains(&self, t: f64) -> bool {
        t < self.t0 + self.converge_s
            || self
                .windows
                .iter()
                .any(|&(a, b)| t > a && t <= b + self.reconverge_s)
    }
}

/// First pass of an estimated σ floor: a run without the outage windows on `used`, its
/// fix outcomes outside the convergence periods (and the stretches before gate-recovery
/// resets) give the floors per class ([`super::gnss_floor::estimate`]). Returns the start
/// time of that pass and the floors.
fn first_pass_floors(
    imu: &ImuStream,
    used: &GnssFixes,
    cfg: &SessionConfig,
    fcfg: &FilterConfig,
    primed: Option<Vec3>,
    data_gaps: &[(f64, f64)],
) -> Result<(f64, Vec<super::gnss_floor::ClassFloor>), NavError> {
    let mut full = cfg.clone();
    full.outages.clear();
    let init = initialise(imu, used, &full, primed)?;
    let mut ffull = fcfg.clone();
    ffull.outages_s.clear();
    let first = run_forward(&imu.epochs, used, init, &ffull)?;
    // A reset by the gate recovery (an IMU fault, a state far off) is no evidence
    // about the GNSS: its fixes, from the last accepted one before it to
    // `reconverge_s` after it, are left out like a convergence period. (Fixes the
    // gate rejected for a few σ and the clock then forced are kept: they are the
    // evidence of an optimistic σ the floor is there to find.)
    let recoveries: Vec<OutageWindow> = first
        .recoveries
        .iter()
        .filter(|r| r.reset)
        .map(|r| OutageWindow {
            start_s: r.time_s - r.starved_s,
            end_s: r.time_s,
        })
        .collect();
    let excluded = ConvergencePeriods::new(init.nav.time_s, &recoveries, data_gaps, cfg);
    let floors = super::gnss_floor::estimate(
        first
            .updates
            .iter()
            .flat_map(|u| u.outcomes.iter().copied()),
        used,
        &fcfg.quality_scale,
        |t| !excluded.contains(t),
    );
    Ok((init.nav.time_s, floors))
}

/// RMS of the horizontal prior innovations √(Σ(δN² + δE²)/n) at the accepted position
/// fixes outside the `excluded` periods, m, and their count n; `None` without such fixes.
fn horizontal_rms(run: &ForwardRun, excluded: &ConvergencePeriods) -> Option<(f64, usize)> {
    let mut sum2 = 0.0;
    let mut count = 0usize;
    for u in &run.updates {
        for o in &u.outcomes {
            if o.kind == UpdateKind::Position && o.accepted && !excluded.contains(o.time_s) {
                sum2 += o.innovation[0].powi(2) + o.innovation[1].powi(2);
                count += 1;
            }
        }
    }
    (count > 0).then(|| ((sum2 / count as f64).sqrt(), count))
}

/// Per-outage errors of the smoothed solution of `run`, the end error taken at the last
/// IMU epoch inside each window (no vertical end error).
fn smoothed_outage_errors(
    run: &ForwardRun,
    init: &InitialState,
    fcfg: &FilterConfig,
    cfg: &SessionConfig,
    gnss: &GnssFixes,
) -> Result<Vec<OutageResult>, NavError> {
    let lever = fcfg.lever_arm_b_m;
    let sm = super::filter::smoother::smooth(run, init, fcfg)?;
    let states: Vec<&NavState> = sm.epochs.iter().map(|e| &e.nav).collect();
    Ok(cfg
        .outages
        .iter()
        .map(|w| {
            let mut o = outage_errors(&states, run, gnss, *w, lever);
            o.end_horizontal_m = end_error(&states, gnss, *w, lever);
            o.end_vertical_m = None;
            o
        })
        .collect())
}

/// Largest departure of the static mean |f| from 9.8 m/s² for [`static_start`], m/s².
/// It must pass an uncompensated consumer accelerometer: turn-on biases of 20 mg σ per
/// axis (e.g. the `consumer` simulation preset, ICM-42688-class data sheets) move |f| by
/// up to ≈ 0.6 m/s² at 3σ on the vertical axis, plus ≈ 0.05 m/s² of 0.5 % scale error; a
/// tighter test leaves such a gyro unprimed (its 0.5 °/s turn-on bias then far beyond
/// the filter's in-run bias σ). Whether the IMU moves is decided by the rate test.
pub const STATIC_GRAVITY_TOL_M_S2: f64 = 1.0;

/// The first `seconds` of the log when the IMU is static there: |mean f| within
/// [`STATIC_GRAVITY_TOL_M_S2`] of 9.8 and every 1-s mean rate within 0.02 rad/s of the
/// total mean; at least 10 epochs covering half of `seconds`. `None` otherwise.
pub fn static_start(imu: &ImuStream, seconds: f64) -> Option<&[ImuIncrement]> {
    let first = imu.epochs.first()?;
    let t_end = first.time_s + seconds;
    let n = imu.epochs.partition_point(|e| e.time_s <= t_end);
    let win = &imu.epochs[..n];
    let total_t: f64 = win.iter().map(|e| e.dt_s).sum();
    if win.len() < 10 || total_t < 0.5 * seconds {
        return None;
    }
    let (w, f) = mean_rate_force(win);
    if (norm(f) - 9.8).abs() > STATIC_GRAVITY_TOL_M_S2 {
        return None;
    }
    // Rate steadiness: 1-s block means stay near the overall mean.
    let mut block = [0.0; 3];
    let mut bt = 0.0;
    for e in win {
        block = add(block, e.dtheta_rad);
        bt += e.dt_s;
        if bt >= 1.0 {
            let m = scale(block, 1.0 / bt);
            if (0..3).any(|k| (m[k] - w[k]).abs() > 0.02) {
                return None;
            }
            block = [0.0; 3];
            bt = 0.0;
        }
    }
    Some(win)
}

/// Mean angular rate and specific force of a block of increments.
fn mean_rate_force(win: &[ImuIncrement]) -> (Vec3, Vec3) {
    let total_t: f64 = win.iter().map(|e| e.dt_s).sum();
    let mut dth = [0.0; 3];
    let mut dv = [0.0; 3];
    for e in win {
        dth = add(dth, e.dtheta_rad);
        dv = add(dv, e.dvel_m_s);
    }
    (scale(dth, 1.0 / total_t), scale(dv, 1.0 / total_t))
}

/// Mean angular rate over the first `seconds` of the log when it is static there
/// ([`static_start`]). `None` otherwise.
pub fn prime_gyro_bias(imu: &ImuStream, seconds: f64) -> Option<Vec3> {
    static_start(imu, seconds).map(|w| mean_rate_force(w).0)
}

/// Gaps in a GNSS time column longer than three median intervals, as (last fix before,
/// first fix after), s: the fix after such a gap ends an outage of the data itself.
fn gnss_data_gaps(time_s: &[f64]) -> Vec<(f64, f64)> {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return Vec::new();
    }
    d.sort_by(f64::total_cmp);
    let limit = 3.0 * d[d.len() / 2];
    time_s
        .windows(2)
        .filter(|w| w[1] - w[0] > limit)
        .map(|w| (w[0], w[1]))
        .collect()
}

/// Antenna position of a record, (lat, lon, h).
fn antenna(nav: &NavState, lever_b_m: Vec3) -> (f64, f64, f64) {
    let l_n = nav.q_bn.rotate(lever_b_m);
    let rm = meridian_radius_m(nav.lat_rad) + nav.height_m;
    let rn = prime_vertical_radius_m(nav.lat_rad) + nav.height_m;
    (
        nav.lat_rad + l_n[0] / rm,
        nav.lon_rad + l_n[1] / (rn * nav.lat_rad.cos()),
        nav.height_m - l_n[2],
    )
}

/// Reference position at `t` interpolated linearly between the bracketing fixes.
fn reference_at(g: &GnssFixes, t: f64) -> Option<(f64, f64, f64)> {
    let j = g.time_s.partition_point(|&x| x <= t);
    if j == 0 || j >= g.time_s.len() {
        return None;
    }
    let (t0, t1) = (g.time_s[j - 1], g.time_s[j]);
    if t1 - t0 > 2.0 {
        return None;
    }
    let a = (t - t0) / (t1 - t0);
    let lerp = |v: &[f64]| v[j - 1] + a * (v[j] - v[j - 1]);
    Some((lerp(&g.lat_rad), lerp(&g.lon_rad), lerp(&g.height_m)))
}

/// Horizontal error of the last state inside the window against the reference.
fn end_error(states: &[&NavState], g: &GnssFixes, w: OutageWindow, lever: Vec3) -> Option<f64> {
    let last = states.iter().rev().find(|n| w.contains(n.time_s))?;
    let r = reference_at(g, last.time_s)?;
    let d = ned_offset_m(r, antenna(last, lever));
    Some(d[0].hypot(d[1]))
}

fn outage_errors(
    states: &[&NavState],
    run: &ForwardRun,
    g: &GnssFixes,
    w: OutageWindow,
    lever: Vec3,
) -> OutageResult {
    let mut max_h = 0.0f64;
    for n in states {
        let t = n.time_s;
        if !w.contains(t) {
            continue;
        }
        if let Some(r) = reference_at(g, t) {
            let d = ned_offset_m(r, antenna(n, lever));
            max_h = max_h.max(d[0].hypot(d[1]));
        }
    }
    let first_after = run
        .updates
        .iter()
        .flat_map(|u| u.outcomes.iter())
        .find(|o| o.kind == UpdateKind::Position && o.time_s > w.end_s);
    let (end_h, end_v) = match first_after {
        Some(o) if o.time_s - w.end_s < 2.0 => (
            Some(o.innovation[0].hypot(o.innovation[1])),
            Some(o.innovation[2].abs()),
        ),
        _ => (None, None),
    };
    // `max_h` covers the states inside the window; the end-of-outage innovation (the
    // forward filter's error just before the first fix) is reported separately.
    OutageResult {
        window: w,
        end_horizontal_m: end_h,
        max_horizontal_m: max_h,
        end_vertical_m: end_v,
    }
}

/// Noise parameters for a consumer MEMS IMU (ICM-4xxxx class, as on `drive_0708`), for
/// when no Allan noise model of the unit is at hand. White noise from data-sheet densities
/// of the order of 4 mdeg/s/√Hz and 70 µg/√Hz, doubled for vehicle vibration
/// (ARW 0.5 deg/√h, VRW 0.08 m/s/√h); uncalibrated turn-on biases up to a few tenths of a
/// deg/s and tens of mg (the drive's static start shows gyro means up to 0.17 deg/s),
/// modelled as Gauss–Markov with 1 h correlation; scale-factor errors 0.5 % (1 h).
pub fn consumer_mems_noise() -> super::filter::model::ImuNoise {
    use super::filter::model::{GaussMarkov, ImuNoise};
    use driftless_model::units::{DEG, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MILLI_G};
    ImuNoise {
        gyro_arw_rad_sqrt_s: 0.5 * DEG_PER_SQRT_H,
        accel_vrw_m_s_sqrt_s: 0.08 * M_PER_S_PER_SQRT_H,
        gyro_bias: GaussMarkov {
            sigma: 0.3 * DEG,
            tau_s: 3600.0,
        },
        accel_bias: GaussMarkov {
            sigma: 30.0 * MILLI_G,
            tau_s: 3600.0,
        },
        gyro_scale: GaussMarkov {
            sigma: 5e-3,
            tau_s: 3600.0,
        },
        accel_scale: GaussMarkov {
            sigma: 5e-3,
            tau_s: 3600.0,
        },
    }
}

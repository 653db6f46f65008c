//! One navigation job on recorded data: initialise in motion, run the forward filter with
//! GNSS outages, and evaluate against the reference fixes.
//!
//! * **Initialisation** (issue 3 deliverable 4, in-motion variant): the gyro biases are
//!   primed from the mean angular rate of a static stretch at the start of the log (when
//!   the IMU is static there — |f̄| ≈ g and a small rate spread; the Earth rate, ≤ 15 deg/h,
//!   is left in the estimate and absorbed by the filter). The filter starts at the first
//!   GNSS epoch with a velocity and a horizontal speed above `min_speed_m_s`: heading from
//!   the course over ground, pitch from the climb angle, roll 0 (a land vehicle without
//!   sideslip, IMU axes already rotated into the vehicle frame), position from the fix
//!   moved from the antenna to the IMU by the lever arm, velocity from GNSS — or, for
//!   position-only GNSS, the central difference of the neighbouring fixes (σ 0.3 m/s).
//! * **Evaluation**: the reference is the GNSS fixes themselves (on `drive_0708` an RTK
//!   solution, cm level). The full-GNSS accuracy is the one-step prediction error at each
//!   accepted fix — the horizontal innovation, i.e. the filter's antenna position *before*
//!   it sees the fix vs the fix — which is stricter than comparing the updated solution.
//!   For each outage window, the end-of-outage error is the horizontal innovation of the
//!   first fix after the window, and the maximum error inside it compares the antenna
//!   position at every IMU epoch with the reference interpolated linearly between fixes.

use super::attitude::Euler;
use super::earth::{meridian_radius_m, ned_offset_m, prime_vertical_radius_m};
use super::filter::NavError;
use super::filter::eskf::UpdateKind;
use super::filter::model::FilterConfig;
use super::filter::run::{ForwardRun, InitialState, run_forward};
use super::filter::state::SensorErrors;
use super::mechanization::NavState;
use super::outage::OutageWindow;
use super::pipeline::ImuStream;
use crate::io::nav::GnssFixes;
use driftless_model::linalg::{Vec3, add, norm, scale};

/// Settings of a session beyond the filter's own.
#[derive(Clone, Debug)]
pub struct SessionConfig {
    /// The filter (noise, lever arm, gating …); its `outages_s` is overwritten from `outages`.
    pub filter: FilterConfig,
    /// GNSS outage windows, absolute GNSS times.
    pub outages: Vec<OutageWindow>,
    /// Horizontal speed needed to take the heading from GNSS velocity, m/s.
    pub min_speed_m_s: f64,
    /// Length of the static stretch at the start used to prime the gyro biases, s (0 = off).
    pub static_prime_s: f64,
    /// Time after the start excluded from the full-GNSS accuracy figure, s.
    pub converge_s: f64,
    /// Time after each outage excluded from the full-GNSS accuracy figure, s.
    pub reconverge_s: f64,
    /// Floor on the fixes' σ (horizontal, vertical), m: receivers' formal σ (RTKLIB's
    /// ~1 cm for a fixed RTK solution) ignore antenna vibration and IMU–GNSS time-tag
    /// error of a moving vehicle. `None` keeps the file's σ.
    pub sigma_floor_m: Option<(f64, f64)>,
    /// Also run the RTS smoother and report its errors inside the outages.
    pub smooth: bool,
}

impl SessionConfig {
    /// Defaults around a filter configuration.
    pub fn new(filter: FilterConfig) -> SessionConfig {
        SessionConfig {
            filter,
            outages: Vec::new(),
            min_speed_m_s: 3.0,
            static_prime_s: 10.0,
            converge_s: 60.0,
            reconverge_s: 30.0,
            sigma_floor_m: None,
            smooth: false,
        }
    }

    /// Settings for `shared/data/drive/drive_0708` (roof-mounted car, consumer IMU):
    /// antenna (0, −0.05, 0) m from the IMU in the vehicle frame; consumer-MEMS noise
    /// with the white-noise terms ×10 for the vehicle's vibration; RTK σ floored at
    /// 3 cm / 6 cm; non-holonomic constraint and standstill ZUPT/ZARU on; smoother on.
    /// The ×10 and the floor were chosen on this drive from a 12-point grid
    /// ({1, 3, 10}× noise × {none, 3 cm} floor × aids off/on; VALIDATION.md lists it),
    /// so the drive figures are in-sample.
    pub fn drive_0708() -> SessionConfig {
        let mut n = consumer_mems_noise();
        n.gyro_arw_rad_sqrt_s *= 10.0;
        n.accel_vrw_m_s_sqrt_s *= 10.0;
        let mut f = FilterConfig::new(n, [0.0, -0.05, 0.0]);
        f.nhc = Some(super::filter::aids::NhcConfig::default());
        f.standstill = Some(super::filter::aids::StandstillConfig::default());
        let mut c = SessionConfig::new(f);
        c.sigma_floor_m = Some((0.03, 0.06));
        c.smooth = true;
        c
    }
}

/// Errors of one outage window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutageResult {
    /// The window.
    pub window: OutageWindow,
    /// Horizontal error at the end of the outage (innovation of the first fix after it), m.
    pub end_horizontal_m: Option<f64>,
    /// Largest horizontal error inside the window, m.
    pub max_horizontal_m: f64,
    /// Vertical error at the end of the outage, m.
    pub end_vertical_m: Option<f64>,
}

/// Result of [`run_session`].
#[derive(Debug)]
pub struct SessionResult {
    /// The forward run.
    pub run: ForwardRun,
    /// The initial state used.
    pub init: InitialState,
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

/// Run the forward filter on `imu` and `gnss` and evaluate it.
pub fn run_session(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
) -> Result<SessionResult, NavError> {
    let primed = if cfg.static_prime_s > 0.0 {
        prime_gyro_bias(imu, cfg.static_prime_s)
    } else {
        None
    };
    let floored;
    let used: &GnssFixes = match cfg.sigma_floor_m {
        Some((h, v)) => {
            let mut g = gnss.clone();
            for s in &mut g.sigma_ned_m {
                s[0] = s[0].max(h);
                s[1] = s[1].max(h);
                s[2] = s[2].max(v);
            }
            floored = g;
            &floored
        }
        None => gnss,
    };
    let init = initialise_in_motion(imu, used, cfg, primed)?;
    let mut fcfg = cfg.filter.clone();
    fcfg.outages_s = cfg.outages.iter().map(|w| (w.start_s, w.end_s)).collect();
    let run = run_forward(&imu.epochs, used, init, &fcfg)?;

    // Full-GNSS accuracy: prior innovations at accepted position fixes.
    let t0 = init.nav.time_s;
    let data_gaps = gnss_data_gaps(&used.time_s);
    let excluded = |t: f64| {
        t < t0 + cfg.converge_s
            || cfg
                .outages
                .iter()
                .map(|w| (w.start_s, w.end_s))
                .chain(data_gaps.iter().copied())
                .any(|(a, b)| t >= a && t <= b + cfg.reconverge_s)
    };
    let mut sum2 = 0.0;
    let mut count = 0usize;
    for u in &run.updates {
        for o in &u.outcomes {
            if o.kind == UpdateKind::Position && o.accepted && !excluded(o.time_s) {
                sum2 += o.innovation[0].powi(2) + o.innovation[1].powi(2);
                count += 1;
            }
        }
    }
    let horizontal_rms_m = (count > 0).then(|| ((sum2 / count as f64).sqrt(), count));

    let lever = fcfg.lever_arm_b_m;
    let states: Vec<&NavState> = run.epochs.iter().map(|e| &e.nav).collect();
    let outages = cfg
        .outages
        .iter()
        .map(|w| outage_errors(&states, &run, gnss, *w, lever))
        .collect();
    let smoothed_outages = if cfg.smooth {
        let sm = super::filter::smoother::smooth(&run, &init, &fcfg)?;
        let states: Vec<&NavState> = sm.epochs.iter().map(|e| &e.nav).collect();
        Some(
            cfg.outages
                .iter()
                .map(|w| {
                    let mut o = outage_errors(&states, &run, gnss, *w, lever);
                    o.end_horizontal_m = end_error(&states, gnss, *w, lever);
                    o.end_vertical_m = None;
                    o
                })
                .collect(),
        )
    } else {
        None
    };
    Ok(SessionResult {
        run,
        init,
        primed_gyro_bias_rad_s: primed,
        horizontal_rms_m,
        outages,
        smoothed_outages,
    })
}

/// Mean angular rate over the first `seconds` of the log when it is static there:
/// |mean f| within 0.3 m/s² of 9.8 and every 1-s mean rate within 0.02 rad/s of the total
/// mean. `None` otherwise.
pub fn prime_gyro_bias(imu: &ImuStream, seconds: f64) -> Option<Vec3> {
    let first = imu.epochs.first()?;
    let t_end = first.time_s + seconds;
    let win: Vec<_> = imu
        .epochs
        .iter()
        .take_while(|e| e.time_s <= t_end)
        .collect();
    let total_t: f64 = win.iter().map(|e| e.dt_s).sum();
    if win.len() < 10 || total_t < 0.5 * seconds {
        return None;
    }
    let mut dth = [0.0; 3];
    let mut dv = [0.0; 3];
    for e in &win {
        dth = add(dth, e.dtheta_rad);
        dv = add(dv, e.dvel_m_s);
    }
    let w = scale(dth, 1.0 / total_t);
    let f = scale(dv, 1.0 / total_t);
    if (norm(f) - 9.8).abs() > 0.3 {
        return None;
    }
    // Rate steadiness: 1-s block means stay near the overall mean.
    let mut block = [0.0; 3];
    let mut bt = 0.0;
    for e in &win {
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
    Some(w)
}

/// Initial state at the first GNSS epoch with velocity and enough speed (see module docs).
pub fn initialise_in_motion(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
) -> Result<InitialState, NavError> {
    // GNSS velocity, or the central difference of the neighbouring fixes (≤ 2.5 s apart
    // on each side) for position-only GNSS.
    let derived: Vec<Option<Vec3>>;
    let vel: Vec<Option<Vec3>> = match gnss.vel_ned_m_s.as_ref() {
        Some(v) => v.iter().map(|&v| Some(v)).collect(),
        None => {
            derived = (0..gnss.time_s.len())
                .map(|i| velocity_from_fixes(gnss, i, 2.5))
                .collect();
            derived
        }
    };
    let vel_sigma = if gnss.vel_ned_m_s.is_some() { 0.1 } else { 0.3 };
    let imu_start = imu
        .epochs
        .first()
        .map(|e| e.time_s)
        .unwrap_or(f64::INFINITY);
    let imu_end = imu
        .epochs
        .last()
        .map(|e| e.time_s)
        .unwrap_or(f64::NEG_INFINITY);
    let in_outage = |t: f64| cfg.outages.iter().any(|w| t >= w.start_s && t <= w.end_s);
    let i = (0..gnss.time_s.len())
        .find(|&i| {
            let t = gnss.time_s[i];
            vel[i].is_some_and(|v| {
                t > imu_start + 0.05
                    && t < imu_end - 1.0
                    && !in_outage(t)
                    && v[0].hypot(v[1]) > cfg.min_speed_m_s
            })
        })
        .ok_or_else(|| {
            NavError::Config(format!(
                "no GNSS epoch inside the IMU span with a horizontal speed above {} m/s to \
                 initialise the heading",
                cfg.min_speed_m_s
            ))
        })?;
    let Some(v) = vel[i] else {
        return Err(NavError::Config(
            "no GNSS velocity at the chosen epoch".into(),
        ));
    };
    let horiz = v[0].hypot(v[1]);
    let att = Euler {
        roll_rad: 0.0,
        pitch_rad: (-v[2]).atan2(horiz),
        yaw_rad: v[1].atan2(v[0]),
    };
    let q_bn = att.to_quat();
    // Antenna → IMU: r_imu = r_ant − C_bn·l (NED metres, converted with the local radii).
    let l_n = q_bn.rotate(cfg.filter.lever_arm_b_m);
    let (lat_a, lon_a, h_a) = (gnss.lat_rad[i], gnss.lon_rad[i], gnss.height_m[i]);
    let rm = meridian_radius_m(lat_a) + h_a;
    let rn = prime_vertical_radius_m(lat_a) + h_a;
    let nav = NavState {
        time_s: gnss.time_s[i],
        lat_rad: lat_a - l_n[0] / rm,
        lon_rad: lon_a - l_n[1] / (rn * lat_a.cos()),
        height_m: h_a + l_n[2],
        vel_ned_m_s: v,
        q_bn,
    };
    let mut sensors = SensorErrors::default();
    let mut sigma_sensors = None;
    if let Some(b) = primed_gyro_bias {
        sensors.gyro_bias_rad_s = b;
        let n = &cfg.filter.imu;
        // Primed from ≥ a few seconds of static data: the residual is the Earth rate plus
        // the short-term drift; keep the other sensor states at their stationary σ.
        let mut s = [0.0; 12];
        for k in 0..3 {
            s[k] = (0.05f64.to_radians()).min(n.gyro_bias.sigma);
            s[3 + k] = n.accel_bias.sigma;
            s[6 + k] = n.gyro_scale.sigma;
            s[9 + k] = n.accel_scale.sigma;
        }
        sigma_sensors = Some(s);
    }
    let sp = gnss.sigma_ned_m[i];
    Ok(InitialState {
        nav,
        sensors,
        sigma_pos_ned_m: [sp[0].max(0.05), sp[1].max(0.05), sp[2].max(0.1)],
        sigma_vel_ned_m_s: [vel_sigma; 3],
        sigma_att_rad: [2f64.to_radians(), 2f64.to_radians(), 3f64.to_radians()],
        sigma_sensors,
    })
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

/// NED velocity at fix `i` from the central difference of fixes `i − 1` and `i + 1`
/// (second-order accurate in the spacing when the fixes are evenly spaced), when both
/// neighbours exist within `max_gap_s`.
fn velocity_from_fixes(gnss: &GnssFixes, i: usize, max_gap_s: f64) -> Option<Vec3> {
    let (a, b) = (i.checked_sub(1)?, i + 1);
    if b >= gnss.time_s.len() {
        return None;
    }
    let (ta, t, tb) = (gnss.time_s[a], gnss.time_s[i], gnss.time_s[b]);
    if !(t - ta > 0.0 && t - ta <= max_gap_s && tb - t > 0.0 && tb - t <= max_gap_s) {
        return None;
    }
    let d = ned_offset_m(
        (gnss.lat_rad[a], gnss.lon_rad[a], gnss.height_m[a]),
        (gnss.lat_rad[b], gnss.lon_rad[b], gnss.height_m[b]),
    );
    let v = scale(d, 1.0 / (tb - ta));
    v.iter().all(|x| x.is_finite()).then_some(v)
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
    let last = states
        .iter()
        .rev()
        .find(|n| n.time_s <= w.end_s && n.time_s >= w.start_s)?;
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
        if t < w.start_s || t > w.end_s {
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

/// The forward run as KF-GINS-style output records (navigation solution, IMU errors,
/// state standard deviations), one row per IMU epoch.
pub fn solution_records(
    run: &ForwardRun,
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    epoch_solution_records(&run.epochs)
}

/// [`solution_records`] of a block of epoch records (e.g. one handed out by
/// [`super::filter::run_forward_observed`]).
pub fn epoch_solution_records(
    epochs: &[super::filter::EpochRecord],
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    state_solution_records(epochs.iter().map(|e| (&e.nav, &e.sensors, &e.std)))
}

/// Output records of any sequence of states — navigation state, sensor-error estimates,
/// √diag(P) in the order of [`super::filter::state`] — e.g. forward records or smoothed
/// epochs ([`super::filter::SmoothedEpoch`]). Attitude as roll, pitch, yaw from
/// [`Euler::from_dcm`] (yaw in (−π, π]).
pub fn state_solution_records<'a>(
    states: impl IntoIterator<
        Item = (
            &'a NavState,
            &'a super::filter::SensorErrors,
            &'a [f64; super::filter::N_STATES],
        ),
    >,
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    use super::filter::state::{ATT, BA, BG, POS, SA, SG, VEL};
    let mut sol = crate::io::nav::NavSolution::default();
    let mut err = crate::io::nav::ImuErrors::default();
    let mut std = crate::io::nav::NavStd::default();
    let tri = |s: &[f64], i: usize| [s[i], s[i + 1], s[i + 2]];
    for (n, sensors, sd) in states {
        let att = Euler::from_dcm(&n.q_bn.to_dcm());
        sol.push_epoch(
            n.time_s,
            n.lat_rad,
            n.lon_rad,
            n.height_m,
            n.vel_ned_m_s,
            [att.roll_rad, att.pitch_rad, att.yaw_rad],
        );
        err.time_s.push(n.time_s);
        err.gyro_bias_rad_s.push(sensors.gyro_bias_rad_s);
        err.accel_bias_m_s2.push(sensors.accel_bias_m_s2);
        err.gyro_scale.push(sensors.gyro_scale);
        err.accel_scale.push(sensors.accel_scale);
        std.time_s.push(n.time_s);
        std.pos_ned_m.push(tri(sd, POS));
        std.vel_ned_m_s.push(tri(sd, VEL));
        std.att_rad.push(tri(sd, ATT));
        std.gyro_bias_rad_s.push(tri(sd, BG));
        std.accel_bias_m_s2.push(tri(sd, BA));
        std.gyro_scale.push(tri(sd, SG));
        std.accel_scale.push(tri(sd, SA));
    }
    (sol, err, std)
}

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
//! 1 µs of an epoch are applied at the epoch. Fixes inside an outage window
//! ([`FilterConfig::outages_s`]) are withheld; fixes before the initial state or out of
//! order are skipped and counted. Each fix's σ is multiplied by the quality factor of
//! its RTKLIB flag ([`super::QualityScale`]).
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

use driftless_model::linalg::Vec3;

use super::NavError;
use super::eskf::{Eskf, UpdateOutcome};
use super::model::{FilterConfig, Transition};
use super::state::{ATT, BG, Cov, N_STATES, PackedCov, SensorErrors, VEL, pack};
use crate::io::nav::GnssFixes;
use crate::nav::mechanization::{ImuIncrement, NavState};

/// Time tolerance for "the fix is at this epoch", s.
const EPS_T: f64 = 1e-6;

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
        let n = &cfg.imu;
        let s = self.sigma_sensors.unwrap_or_else(|| {
            let mut s = [0.0; 12];
            for k in 0..3 {
                s[k] = n.gyro_bias.sigma;
                s[3 + k] = n.accel_bias.sigma;
                s[6 + k] = n.gyro_scale.sigma;
                s[9 + k] = n.accel_scale.sigma;
            }
            s
        });
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

/// One GNSS epoch's updates.
#[derive(Clone, Debug, PartialEq)]
pub struct UpdateRecord {
    /// Index into [`ForwardRun::epochs`].
    pub epoch_index: usize,
    /// GNSS time, s.
    pub time_s: f64,
    /// The position (and velocity, if used) updates with innovation, NIS and gate result.
    pub outcomes: Vec<UpdateOutcome>,
    /// P before the updates (packed upper triangle).
    pub p_prior: Box<PackedCov>,
    /// P after the updates.
    pub p_post: Box<PackedCov>,
}

/// Result of [`run_forward`].
#[derive(Clone, Debug, PartialEq)]
pub struct ForwardRun {
    /// One record per prediction step, the first at the initial state.
    pub epochs: Vec<EpochRecord>,
    /// One record per GNSS epoch used (accepted or rejected).
    pub updates: Vec<UpdateRecord>,
    /// Fixes withheld by outage windows.
    pub gnss_withheld: usize,
    /// Fixes before the initial state, after the last IMU epoch, or out of order.
    pub gnss_skipped: usize,
    /// Measurements rejected by the χ² gate (each logged in `updates`).
    pub gnss_rejected: usize,
    /// Measurements accepted.
    pub gnss_accepted: usize,
    /// −1/T of the sensor states (to rebuild Φ).
    neg_inv_tau: [f64; 12],
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
        Some(Transition::new(
            &prev.nav,
            c.dtheta_rad.map(|v| v * inv),
            c.dvel_m_s.map(|v| v * inv),
            c.dt_s,
            &self.neg_inv_tau,
        ))
    }

    /// The rejected measurements (χ² gate).
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

struct Ctx<'a> {
    gnss: &'a GnssFixes,
    cfg: &'a FilterConfig,
    run: ForwardRun,
}

impl Ctx<'_> {
    fn withheld(&self, t: f64) -> bool {
        self.cfg.outages_s.iter().any(|&(a, b)| t >= a && t <= b)
    }

    /// Apply fix `g` at the current filter epoch and refresh the last record.
    fn apply_fix(&mut self, f: &mut Eskf, g: usize) -> Result<(), NavError> {
        let gn = self.gnss;
        let k = self.cfg.quality_scale.factor(gn.quality[g]);
        let p_prior = pack(f.covariance());
        let mut outcomes = Vec::with_capacity(2);
        let sigma = gn.sigma_ned_m[g].map(|s| s * k);
        let o = f.update_position(
            [gn.lat_rad[g], gn.lon_rad[g], gn.height_m[g]],
            sigma,
            self.cfg.lever_arm_b_m,
        )?;
        outcomes.push(o);
        if self.cfg.use_gnss_velocity
            && let (Some(v), Some(sv)) = (&gn.vel_ned_m_s, &gn.sigma_vel_ned_m_s)
        {
            let o = f.update_velocity(v[g], sv[g].map(|s| s * k), self.cfg.lever_arm_b_m)?;
            outcomes.push(o);
        }
        for o in &outcomes {
            if o.accepted {
                self.run.gnss_accepted += 1;
            } else {
                self.run.gnss_rejected += 1;
            }
        }
        let idx = self.run.epochs.len() - 1;
        let comp = self.run.epochs[idx].comp;
        self.run.epochs[idx] = record(f, comp);
        self.run.updates.push(UpdateRecord {
            epoch_index: idx,
            time_s: gn.time_s[g],
            outcomes,
            p_prior,
            p_post: pack(f.covariance()),
        });
        Ok(())
    }
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
    cfg.validate()?;
    check_gnss(gnss)?;
    let t0 = init.nav.time_s;
    // First increment that ends after the start; the one before primes the two-sample
    // corrections when it ends at the start.
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
    let mut f = Eskf::new(init.nav, init.sensors, init.covariance(cfg), prev_inc, cfg)?;
    let mut ctx = Ctx {
        gnss,
        cfg,
        run: ForwardRun {
            epochs: Vec::with_capacity(imu.len() - start + gnss.len() + 1),
            updates: Vec::new(),
            gnss_withheld: 0,
            gnss_skipped: 0,
            gnss_rejected: 0,
            gnss_accepted: 0,
            neg_inv_tau: cfg.neg_inv_tau(),
        },
    };
    let zero = ImuIncrement {
        time_s: t0,
        dt_s: 0.0,
        dtheta_rad: [0.0; 3],
        dvel_m_s: [0.0; 3],
    };
    ctx.run.epochs.push(record(&f, zero));
    let ng = gnss.len();
    let mut g = 0;
    // Fixes before the start are skipped; a fix at the start is applied at once.
    while g < ng {
        let before = gnss.time_s[g] < t0 - EPS_T || gnss.time_s[g].is_nan();
        if !before {
            break;
        }
        ctx.run.gnss_skipped += 1;
        g += 1;
    }
    while g < ng && gnss.time_s[g] <= t0 + EPS_T {
        if ctx.withheld(gnss.time_s[g]) {
            ctx.run.gnss_withheld += 1;
        } else {
            ctx.apply_fix(&mut f, g)?;
        }
        g += 1;
    }
    let mut t_prev = t0;
    for inc in &imu[start..] {
        let t_end = inc.time_s;
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
        if dt > cfg.max_gap_factor * nominal_dt {
            return Err(NavError::ImuTiming {
                time_s: t_end,
                reason: format!("gap of {dt} s after {t_prev} s (nominal interval {nominal_dt} s)"),
            });
        }
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
            if tg >= t_end - EPS_T {
                if !done {
                    f.predict(&rest)?;
                    ctx.run
                        .epochs
                        .push(record(&f, f.last_compensated().unwrap_or(rest)));
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
                    .push(record(&f, f.last_compensated().unwrap_or(first)));
                t_start = tg;
            }
            ctx.apply_fix(&mut f, g)?;
            g += 1;
        }
        if !done {
            f.predict(&rest)?;
            ctx.run
                .epochs
                .push(record(&f, f.last_compensated().unwrap_or(rest)));
        }
        t_prev = t_end;
    }
    ctx.run.gnss_skipped += ng - g;
    Ok(ctx.run)
}

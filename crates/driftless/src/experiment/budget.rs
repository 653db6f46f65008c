//! Why one case drifted more than another in an outage: each outage's error split into
//! what the state at the outage start and what the sensor error contributed, and the
//! outages where a more compensated case ended worse than a less compensated one
//! ("reversals") with the part that explains the difference.
//!
//! **Budget.** Inside an outage the forward filter coasts: it integrates its compensated
//! increments c_k (the case's stream corrected by the filter's bias and scale estimates)
//! from its state x̂₀ at the outage start. With the strapdown mechanization
//! Φ(x₀; u₁…u_n) ([`mechanize`], the same two-sample algorithm the filter runs) and the
//! reference x₀, x_n at the start and end (the truth, or the smoothed full-GNSS solution),
//! each outage's horizontal end error is split into
//!
//! ```text
//! free inertial  E  = |Φ(x̂₀; c) − x_n|
//! start state    E₀ = |Φ(x̂₀; c) − Φ(x₀; c)|     (same increments, different start)
//! sensor error   E_s = |Φ(x₀; c) − x_n|          (exact start, the filter's increments)
//! compensation   E_c = |Φ(x₀; s) − x_n|          (exact start, the case's stream s, no
//!                                                 filter correction)
//! ```
//!
//! E₀ and E_s are the two contributions (their vector sum is E, up to the nonlinearity of
//! Φ); E_c is what the case's compensation alone leaves, which separates the compensation
//! from the filter's bias estimate. With vehicle aids (NHC) the filter does not coast
//! freely and E is not its error; the split still ranks the causes.
//!
//! **Reversal.** Case X is more compensated than Y when it corrects everything Y does
//! and more ([`Case::compensation_rank`]); a reversal is an outage where X's end error
//! exceeds Y's. Its cause is the part whose difference (X − Y) is the larger and positive
//! — the start state, or the sensor error and then whether X's compensation itself left
//! more than Y's (E_c) or left less but the filter's estimate was further from it — a tie
//! when the end errors agree to 5 %, and a combination when neither part is larger for X
//! (Y's start-state and sensor parts cancelled: the filter's tilt, velocity and bias errors
//! are correlated, since an accelerometer bias and a tilt are not separable on a straight
//! drive, so its start state partly offsets its sensor error; X's smaller parts did not).

use serde::Serialize;

use super::run::{Case, VehicleRun};
use crate::io::nav::NavSolution;
use crate::nav::attitude::Euler;
use crate::nav::earth::{meridian_radius_m, prime_vertical_radius_m};
use crate::nav::filter::run::EpochRecord;
use crate::nav::mechanization::{ImuIncrement, NavState, mechanize};
use crate::nav::outage::OutageWindow;

/// End errors below this fraction apart are a tie, not a reversal to explain.
pub(crate) const TIE_FRACTION: f64 = 0.05;

/// One case's budget of one outage (module docs).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct OutageBudget {
    /// Time from the start state to the end state, s.
    pub duration_s: f64,
    /// E: horizontal end error of free-inertial coasting from the filter's start state, m.
    pub free_inertial_m: f64,
    /// E₀: the start state's contribution, m.
    pub start_state_m: f64,
    /// E_s: the contribution of the sensor error the filter integrated, m.
    pub sensor_error_m: f64,
    /// E_c: the error the case's compensation alone leaves from the exact start, m.
    pub compensation_m: f64,
    /// Horizontal position error at the start, m.
    pub start_horizontal_m: f64,
    /// Horizontal velocity error at the start, m/s.
    pub start_velocity_m_s: f64,
    /// Tilt error (roll and pitch) at the start, rad.
    pub start_tilt_rad: f64,
    /// Heading error at the start, rad (wrapped to ±π).
    pub start_heading_rad: f64,
}

fn wrap_pi(a: f64) -> f64 {
    let w = (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI);
    w - std::f64::consts::PI
}

/// Index of the sample stamped `t` (to a microsecond), if any.
fn index_at(time_s: &[f64], t: f64) -> Option<usize> {
    let k = time_s.partition_point(|&x| x < t - 1e-6);
    (k < time_s.len() && (time_s[k] - t).abs() <= 1e-6).then_some(k)
}

/// The reference's state at epoch `j`.
fn state_of(r: &NavSolution, j: usize) -> NavState {
    let [roll_rad, pitch_rad, yaw_rad] = r.roll_pitch_yaw_rad[j];
    NavState {
        time_s: r.time_s[j],
        lat_rad: r.lat_rad[j],
        lon_rad: r.lon_rad[j],
        height_m: r.height_m[j],
        vel_ned_m_s: r.vel_ned_m_s[j],
        q_bn: Euler {
            roll_rad,
            pitch_rad,
            yaw_rad,
        }
        .to_quat(),
    }
}

/// Horizontal distance of `a` from `b`, m (local radii at `b`).
fn horizontal_m(a: &NavState, b: &NavState) -> f64 {
    let dn = (a.lat_rad - b.lat_rad) * (meridian_radius_m(b.lat_rad) + b.height_m);
    let de = (a.lon_rad - b.lon_rad)
        * (prime_vertical_radius_m(b.lat_rad) + b.height_m)
        * b.lat_rad.cos();
    dn.hypot(de)
}

/// Φ(x₀; u): free-inertial coasting from `start` over `incs` (`prev` precedes them).
fn coast(start: &NavState, prev: &ImuIncrement, incs: &[ImuIncrement]) -> NavState {
    let (mut x, mut p) = (*start, *prev);
    for u in incs.iter().filter(|u| u.dt_s > 0.0) {
        x = mechanize(&x, &p, u);
        p = *u;
    }
    x
}

/// The budget of each outage for one case: `epochs` (its forward records: states and
/// compensated increments) and `stream` (the increments the case fed the filter),
/// against `reference`. `None` for an outage the records or the reference do not cover
/// at the same epochs.
pub(crate) fn outage_budgets(
    windows: &[OutageWindow],
    reference: &NavSolution,
    epochs: &[EpochRecord],
    stream: &[ImuIncrement],
) -> Vec<Option<OutageBudget>> {
    let rec_t: Vec<f64> = epochs.iter().map(|e| e.nav.time_s).collect();
    let stream_t: Vec<f64> = stream.iter().map(|e| e.time_s).collect();
    windows
        .iter()
        .map(|w| {
            // Start: the last record at or before the window's start (the state the
            // filter coasts from); end: the last record inside the window.
            let i0 = rec_t.partition_point(|&t| t <= w.start_s).checked_sub(1)?;
            let i1 = rec_t.partition_point(|&t| t <= w.end_s).checked_sub(1)?;
            if i1 <= i0 {
                return None;
            }
            let (t0, t1) = (rec_t[i0], rec_t[i1]);
            let (j0, j1) = (
                index_at(&reference.time_s, t0)?,
                index_at(&reference.time_s, t1)?,
            );
            let (k0, k1) = (index_at(&stream_t, t0)?, index_at(&stream_t, t1)?);
            let (x0, xn) = (state_of(reference, j0), state_of(reference, j1));
            let est0 = epochs[i0].nav;
            let comp: Vec<ImuIncrement> = epochs[i0 + 1..=i1].iter().map(|e| e.comp).collect();
            let prev = epochs[i0].comp;
            let from_est = coast(&est0, &prev, &comp);
            let from_ref = coast(&x0, &prev, &comp);
            let from_ref_stream = coast(&x0, &stream[k0], &stream[k0 + 1..=k1]);
            let (a, b) = (est0.q_bn, x0.q_bn);
            let (ea, eb) = (Euler::from_dcm(&a.to_dcm()), Euler::from_dcm(&b.to_dcm()));
            Some(OutageBudget {
                duration_s: t1 - t0,
                free_inertial_m: horizontal_m(&from_est, &xn),
                start_state_m: horizontal_m(&from_est, &from_ref),
                sensor_error_m: horizontal_m(&from_ref, &xn),
                compensation_m: horizontal_m(&from_ref_stream, &xn),
                start_horizontal_m: horizontal_m(&est0, &x0),
                start_velocity_m_s: (est0.vel_ned_m_s[0] - x0.vel_ned_m_s[0])
                    .hypot(est0.vel_ned_m_s[1] - x0.vel_ned_m_s[1]),
                start_tilt_rad: wrap_pi(ea.roll_rad - eb.roll_rad)
                    .hypot(wrap_pi(ea.pitch_rad - eb.pitch_rad)),
                start_heading_rad: wrap_pi(ea.yaw_rad - eb.yaw_rad),
            })
        })
        .collect()
}

/// What explains a reversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReversalCause {
    /// The end errors agree to `TIE_FRACTION`: nothing to explain.
    Tie,
    /// The worse case entered the outage with the larger navigation error (its filter
    /// state when GNSS stopped), not with a larger sensor error.
    StartState,
    /// The worse case's compensation left the larger sensor error in the window.
    Compensation,
    /// The worse case's compensation left the smaller sensor error, but the filter's
    /// estimate at the outage start was further from it.
    FilterEstimate,
    /// Neither part is larger for the worse case: in the other case the start-state error
    /// and the sensor error cancelled (the filter had traded tilt and velocity against an
    /// error it could not separate from them), here they did not.
    Combination,
    /// No budget for this outage (a record or reference epoch missing).
    Unknown,
}

impl ReversalCause {
    /// One sentence for reports.
    pub(crate) fn explanation(self) -> &'static str {
        match self {
            ReversalCause::Tie => "a tie: the end errors agree to within 5 %",
            ReversalCause::StartState => {
                "it entered the outage with the larger navigation error (position, velocity, \
                 tilt or heading when GNSS stopped), not with a larger sensor error"
            }
            ReversalCause::Compensation => {
                "its compensation left the larger sensor error in the window (the model's error \
                 at this temperature, or a correction that does not fit this run's sensor)"
            }
            ReversalCause::FilterEstimate => {
                "its compensation left the smaller sensor error, but the filter's bias estimate \
                 at the outage start was further from it (in the less compensated case the \
                 filter had absorbed more of the error it was left)"
            }
            ReversalCause::Combination => {
                "neither its start state nor its sensor error contributed more; in the less \
                 compensated case the two cancelled — its filter had set its tilt and velocity \
                 against the sensor error it could not separate from them (an accelerometer bias \
                 and a tilt look alike while the vehicle drives straight), while here the smaller \
                 parts did not cancel"
            }
            ReversalCause::Unknown => "no budget for this outage",
        }
    }
}

/// An outage where a more compensated case ended with the larger error.
#[derive(Clone, Debug, Serialize)]
pub struct Reversal {
    /// Outage index (0-based).
    pub outage: usize,
    /// The more compensated case.
    pub case: Case,
    /// The less compensated case it did worse than.
    pub than: Case,
    /// End error of `case`, m.
    pub end_m: f64,
    /// End error of `than`, m.
    pub than_end_m: f64,
    /// Budgets of `case` and `than` for this outage.
    pub budgets: Option<(OutageBudget, OutageBudget)>,
    /// The cause (module docs).
    pub cause: ReversalCause,
}

/// The cause of a reversal of `x` over `y` (end errors `ex` > `ey`).
pub(crate) fn reversal_cause(
    ex: f64,
    ey: f64,
    x: &OutageBudget,
    y: &OutageBudget,
) -> ReversalCause {
    if ex - ey <= TIE_FRACTION * ey {
        return ReversalCause::Tie;
    }
    let d_start = x.start_state_m - y.start_state_m;
    let d_sensor = x.sensor_error_m - y.sensor_error_m;
    if d_start <= 0.0 && d_sensor <= 0.0 {
        ReversalCause::Combination
    } else if d_start >= d_sensor {
        ReversalCause::StartState
    } else if x.compensation_m > y.compensation_m {
        ReversalCause::Compensation
    } else {
        ReversalCause::FilterEstimate
    }
}

impl Reversal {
    /// One line for reports, outages numbered from 1.
    pub fn describe(&self) -> String {
        let f = super::table::fmt_m;
        let mut s = format!(
            "outage #{}: {} {} m vs {} {} m",
            self.outage + 1,
            self.case.label(),
            f(self.end_m),
            self.than.label(),
            f(self.than_end_m),
        );
        if let Some((x, y)) = &self.budgets {
            s.push_str(&format!(
                "; start state {} vs {} m, sensor error {} vs {} m, left by the compensation \
                 alone {} vs {} m",
                f(x.start_state_m),
                f(y.start_state_m),
                f(x.sensor_error_m),
                f(y.sensor_error_m),
                f(x.compensation_m),
                f(y.compensation_m),
            ));
        }
        s.push_str(&format!(". Cause: {}.", self.cause.explanation()));
        s
    }
}

/// The reversals of one run: for every pair of processed cases with different
/// compensation ranks and every outage both finished, where the more compensated one's
/// end error is larger, with the cause from the cases' budgets
/// ([`super::run::CaseRun::budgets`], kept for the detailed run).
pub fn reversals(run: &VehicleRun) -> Vec<Reversal> {
    let mut out = Vec::new();
    for x in &run.cases {
        for y in &run.cases {
            if x.case.compensation_rank() <= y.case.compensation_rank() {
                continue;
            }
            let (Ok(rx), Ok(ry)) = (&x.forward, &y.forward) else {
                continue;
            };
            for (i, (ox, oy)) in rx.outages.iter().zip(&ry.outages).enumerate() {
                let (ex, ey) = (ox.end_horizontal_m, oy.end_horizontal_m);
                // NaN (a failed outage) compares false: not a reversal.
                if ex.partial_cmp(&ey) != Some(std::cmp::Ordering::Greater) {
                    continue;
                }
                let budget = |c: &super::run::CaseRun| {
                    c.budgets.as_ref().and_then(|b| b.get(i).cloned()).flatten()
                };
                let budgets = budget(x).zip(budget(y));
                let cause = match &budgets {
                    Some((bx, by)) => reversal_cause(ex, ey, bx, by),
                    None if ex - ey <= TIE_FRACTION * ey => ReversalCause::Tie,
                    None => ReversalCause::Unknown,
                };
                out.push(Reversal {
                    outage: i,
                    case: x.case,
                    than: y.case,
                    end_m: ex,
                    than_end_m: ey,
                    budgets,
                    cause,
                });
            }
        }
    }
    out.sort_by_key(|r| {
        (
            r.outage,
            r.case.compensation_rank(),
            r.than.compensation_rank(),
        )
    });
    out
}

/// How often a more compensated case ended an outage worse than a less compensated one,
/// over all runs.
#[derive(Clone, Debug, Serialize)]
pub struct ReversalCount {
    /// The more compensated case.
    pub case: Case,
    /// The less compensated case.
    pub than: Case,
    /// Outages (over all runs) where `case` ended worse.
    pub worse: usize,
    /// Of those, the ones worse by more than `TIE_FRACTION`.
    pub worse_beyond_tie: usize,
    /// Outages (over all runs) both finished.
    pub compared: usize,
}

/// Reversal counts over runs, for each pair of cases of different rank.
pub(crate) fn reversal_counts(runs: &[VehicleRun]) -> Vec<ReversalCount> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for x in &first.cases {
        for y in &first.cases {
            if x.case.compensation_rank() <= y.case.compensation_rank() {
                continue;
            }
            let (mut worse, mut beyond, mut compared) = (0, 0, 0);
            for r in runs {
                let (Some(Ok(rx)), Some(Ok(ry))) = (
                    r.case(x.case).map(|c| &c.forward),
                    r.case(y.case).map(|c| &c.forward),
                ) else {
                    continue;
                };
                for (ox, oy) in rx.outages.iter().zip(&ry.outages) {
                    let (ex, ey) = (ox.end_horizontal_m, oy.end_horizontal_m);
                    if ex.is_finite() && ey.is_finite() {
                        compared += 1;
                        worse += usize::from(ex > ey);
                        beyond += usize::from(ex - ey > TIE_FRACTION * ey);
                    }
                }
            }
            out.push(ReversalCount {
                case: x.case,
                than: y.case,
                worse,
                worse_beyond_tie: beyond,
                compared,
            });
        }
    }
    out.sort_by_key(|c| (c.case.compensation_rank(), c.than.compensation_rank()));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::filter::state::SensorErrors;

    /// A level, stationary reference at 45° N and the filter's records coasting from a
    /// start state 1 m north of it with a body-x accelerometer error of 0.01 m/s².
    /// Closed form (T = 60 s ≪ the Schuler period): sensor part ½·δf·T² = 18 m (less
    /// the Schuler term (ω_s·T)²/12 ≈ 0.2 %), start part 1 m plus its Schuler growth
    /// (negligible).
    #[test]
    fn budget_splits_a_start_offset_from_a_sensor_error() {
        let (dt, n) = (0.01, 8000usize);
        let lat = 45f64.to_radians();
        let g = crate::nav::earth::gravity_ned(lat, 100.0)[2];
        let omega_ie = 7.292115e-5;
        // Ideal increments of a level, north-facing, stationary IMU (earth rate and gravity).
        let ideal = |k: usize| ImuIncrement {
            time_s: k as f64 * dt,
            dt_s: if k == 0 { 0.0 } else { dt },
            dtheta_rad: [omega_ie * lat.cos() * dt, 0.0, -omega_ie * lat.sin() * dt],
            dvel_m_s: [0.0, 0.0, -g * dt],
        };
        let still = |t: f64, dn_m: f64| NavState {
            time_s: t,
            lat_rad: lat + dn_m / (meridian_radius_m(lat) + 100.0),
            lon_rad: 0.0,
            height_m: 100.0,
            vel_ned_m_s: [0.0; 3],
            q_bn: Euler {
                roll_rad: 0.0,
                pitch_rad: 0.0,
                yaw_rad: 0.0,
            }
            .to_quat(),
        };
        let mut reference = NavSolution::default();
        for k in 0..n {
            reference.push_epoch(k as f64 * dt, lat, 0.0, 100.0, [0.0; 3], [0.0; 3]);
        }
        let with_bias = |k: usize| {
            let mut u = ideal(k);
            u.dvel_m_s[0] += 0.01 * u.dt_s;
            u
        };
        let epochs: Vec<EpochRecord> = (0..n)
            .map(|k| EpochRecord {
                nav: still(k as f64 * dt, 1.0),
                sensors: SensorErrors::default(),
                std: [0.0; crate::nav::filter::state::N_STATES],
                comp: with_bias(k),
            })
            .collect();
        // The case's own stream: twice the filter's error (the filter removed half).
        let stream: Vec<ImuIncrement> = (0..n)
            .map(|k| {
                let mut u = ideal(k);
                u.dvel_m_s[0] += 0.02 * u.dt_s;
                u
            })
            .collect();
        let w = OutageWindow {
            start_s: 10.0,
            end_s: 70.0,
        };
        let b = outage_budgets(&[w], &reference, &epochs, &stream)[0]
            .clone()
            .expect("budget");
        assert!((b.duration_s - 60.0).abs() < 1e-6, "{b:?}");
        assert!((b.sensor_error_m - 18.0).abs() < 0.1, "{b:?}");
        assert!((b.compensation_m - 36.0).abs() < 0.2, "{b:?}");
        assert!((b.start_state_m - 1.0).abs() < 0.01, "{b:?}");
        assert!((b.start_horizontal_m - 1.0).abs() < 1e-6, "{b:?}");
        // Start 1 m north, drift 18 m north: they add.
        assert!((b.free_inertial_m - 19.0).abs() < 0.1, "{b:?}");
        // A window the records do not reach has no budget.
        let late = OutageWindow {
            start_s: 100.0,
            end_s: 160.0,
        };
        assert!(outage_budgets(&[late], &reference, &epochs, &stream)[0].is_none());
    }

    #[test]
    fn reversal_causes() {
        let b = |start: f64, sensor: f64, comp: f64| OutageBudget {
            duration_s: 60.0,
            free_inertial_m: start + sensor,
            start_state_m: start,
            sensor_error_m: sensor,
            compensation_m: comp,
            start_horizontal_m: 0.0,
            start_velocity_m_s: 0.0,
            start_tilt_rad: 0.0,
            start_heading_rad: 0.0,
        };
        use ReversalCause::*;
        // (worse end, better end, worse budget, better budget, cause)
        let cases = [
            (104.0, b(0.0, 0.0, 0.0), b(1.0, 1.0, 1.0), Tie),
            (150.0, b(80.0, 50.0, 9.0), b(20.0, 60.0, 1.0), StartState),
            (
                150.0,
                b(20.0, 140.0, 90.0),
                b(20.0, 90.0, 50.0),
                Compensation,
            ),
            (
                150.0,
                b(20.0, 140.0, 40.0),
                b(20.0, 90.0, 500.0),
                FilterEstimate,
            ),
            (150.0, b(20.0, 80.0, 40.0), b(30.0, 90.0, 50.0), Combination),
        ];
        for (ex, x, y, cause) in cases {
            assert_eq!(reversal_cause(ex, 100.0, &x, &y), cause, "{x:?} {y:?}");
        }
    }
}

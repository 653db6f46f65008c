//! Land-vehicle dynamics classes of a reference trajectory, epoch by epoch: standstill,
//! straight, turn, acceleration, braking — what the outage windows of an evaluation
//! should cover (the paper's nine outages "cover all typical dynamics of the land
//! vehicle").
//!
//! # Signals (pure functions over columns)
//!
//! For each epoch k at time t_k, over the reference epochs i…j inside the centred window
//! [t_k − W/2, t_k + W/2] (W = [`DynamicsThresholds::window_s`], clipped at the data
//! ends):
//!
//! * horizontal speed v̄_k = mean of v_H = √(v_N² + v_E²) over i…j;
//! * longitudinal acceleration a_k = (v_H,j − v_H,i)/(t_j − t_i) — the rate of change of
//!   the speed, i.e. the tangential acceleration, with no gravity or centripetal term; a
//!   difference over the window equals the mean of the derivative over it, so it is the
//!   W-long moving average of dv_H/dt without differentiating noise sample by sample;
//! * yaw rate ψ̇_k = wrap(ψ_j − ψ_i)/(t_j − t_i), ψ the yaw column where known, else the
//!   course over ground atan2(v_E, v_N) when v_H ≥ [`DynamicsThresholds::course_min_speed_m_s`];
//!   0 when either end has no heading. A land vehicle turns < 180° in W, so the wrapped
//!   difference is the true one.
//!
//! # Classes (first rule that holds)
//!
//! 1. **standstill**: v̄ < `standstill_speed_m_s` (0.5 m/s);
//! 2. **turn**: |ψ̇| ≥ `turn_rate_rad_s` (5°/s);
//! 3. **braking**: a ≤ −`accel_m_s2` (0.5 m/s²);
//! 4. **acceleration**: a ≥ `accel_m_s2`;
//! 5. **straight**: otherwise (moving at nearly constant speed and heading, climbs
//!    included).
//!
//! Turning outranks speed changes because heading changes are what make a GNSS outage
//! hard for a MEMS INS (gyro bias and scale errors turn into heading error, heading error
//! into cross-track drift); braking into a turn counts as a turn.
//!
//! Threshold rationale: 0.5 m/s is walking pace, well above RTK velocity noise (~2 cm/s)
//! and below any deliberate vehicle motion. Intersection turns and roundabouts run at
//! 10–20°/s, sweeping curves and lane changes mostly below 3–4°/s: 5°/s separates them
//! (at 10 m/s it is a lateral acceleration v·ψ̇ ≈ 0.9 m/s²). Gentle urban acceleration
//! and braking are 1–3 m/s², speed wander while cruising a few 0.1 m/s²: 0.5 m/s²
//! (≈ 0.05 g) separates them. W = 2 s suppresses RTK noise (2 cm/s velocity noise over
//! 2 s gives 0.01 m/s² and < 0.1°/s at 10 m/s) while a 3-s braking still reaches its
//! full value. Near class changes the smoothing blurs the timeline by about W/2.

use serde::{Deserialize, Serialize};

use super::EvalError;
use super::reference::{validate, wrap_pi};
use crate::io::nav::NavSolution;

/// Dynamics class of an epoch (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dynamics {
    /// Speed below the standstill threshold.
    Standstill,
    /// Moving at nearly constant speed and heading.
    Straight,
    /// Heading changing faster than the turn threshold.
    Turn,
    /// Speeding up.
    Acceleration,
    /// Slowing down.
    Braking,
}

impl Dynamics {
    /// All classes, in index order.
    pub const ALL: [Dynamics; 5] = [
        Dynamics::Standstill,
        Dynamics::Straight,
        Dynamics::Turn,
        Dynamics::Acceleration,
        Dynamics::Braking,
    ];

    /// Index 0…4 (the order of [`Dynamics::ALL`]).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name (`"standstill"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Dynamics::Standstill => "standstill",
            Dynamics::Straight => "straight",
            Dynamics::Turn => "turn",
            Dynamics::Acceleration => "acceleration",
            Dynamics::Braking => "braking",
        }
    }
}

impl std::fmt::Display for Dynamics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Thresholds of the classification (module docs for the values and why).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DynamicsThresholds {
    /// Smoothed horizontal speed below which the vehicle stands still, m/s (0.5).
    pub standstill_speed_m_s: f64,
    /// |yaw rate| from which the vehicle turns, rad/s (5°/s).
    pub turn_rate_rad_s: f64,
    /// |longitudinal acceleration| from which it accelerates or brakes, m/s² (0.5).
    pub accel_m_s2: f64,
    /// Centred smoothing window W, s (2).
    pub window_s: f64,
    /// Speed above which the course over ground stands in for an unknown yaw, m/s (1).
    pub course_min_speed_m_s: f64,
}

impl Default for DynamicsThresholds {
    fn default() -> Self {
        DynamicsThresholds {
            standstill_speed_m_s: 0.5,
            turn_rate_rad_s: 5f64.to_radians(),
            accel_m_s2: 0.5,
            window_s: 2.0,
            course_min_speed_m_s: 1.0,
        }
    }
}

impl DynamicsThresholds {
    /// Every threshold finite and > 0.
    pub fn check(&self) -> Result<(), EvalError> {
        for (name, value) in [
            ("standstill_speed_m_s", self.standstill_speed_m_s),
            ("turn_rate_rad_s", self.turn_rate_rad_s),
            ("accel_m_s2", self.accel_m_s2),
            ("window_s", self.window_s),
            ("course_min_speed_m_s", self.course_min_speed_m_s),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(EvalError::BadOption {
                    name,
                    value,
                    reason: "must be a finite number > 0",
                });
            }
        }
        Ok(())
    }
}

/// The smoothed signals of the module docs, one value per epoch.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct DynamicsSignals {
    /// Mean horizontal speed over the window, m/s.
    pub speed_m_s: Vec<f64>,
    /// Longitudinal (tangential) acceleration, m/s².
    pub long_accel_m_s2: Vec<f64>,
    /// Yaw rate, rad/s (positive turning right, from north towards east).
    pub yaw_rate_rad_s: Vec<f64>,
}

/// Smoothed speed, longitudinal acceleration and yaw rate (module docs). `yaw_rad` may
/// hold NaN where the heading is unknown. Columns of equal length, times increasing
/// (not checked here: [`classify`] validates a whole trajectory).
pub(crate) fn dynamics_signals(
    time_s: &[f64],
    vel_ned_m_s: &[[f64; 3]],
    yaw_rad: &[f64],
    thr: &DynamicsThresholds,
) -> DynamicsSignals {
    let n = time_s.len().min(vel_ned_m_s.len()).min(yaw_rad.len());
    let vh: Vec<f64> = vel_ned_m_s[..n].iter().map(|v| v[0].hypot(v[1])).collect();
    let heading: Vec<Option<f64>> = (0..n)
        .map(|k| {
            let y = yaw_rad[k];
            if y.is_finite() {
                Some(y)
            } else if vh[k] >= thr.course_min_speed_m_s {
                let v = vel_ned_m_s[k];
                Some(v[1].atan2(v[0]))
            } else {
                None
            }
        })
        .collect();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for &v in &vh {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v);
    }
    let half = 0.5 * thr.window_s;
    let mut out = DynamicsSignals::default();
    let (mut i, mut j) = (0usize, 0usize);
    for k in 0..n {
        let t = time_s[k];
        while time_s[i] < t - half {
            i += 1;
        }
        if j < k {
            j = k;
        }
        while j + 1 < n && time_s[j + 1] <= t + half {
            j += 1;
        }
        out.speed_m_s
            .push((prefix[j + 1] - prefix[i]) / (j + 1 - i) as f64);
        let dt = time_s[j] - time_s[i];
        if j > i && dt > 0.0 {
            out.long_accel_m_s2.push((vh[j] - vh[i]) / dt);
            out.yaw_rate_rad_s.push(match (heading[i], heading[j]) {
                (Some(a), Some(b)) => wrap_pi(b - a) / dt,
                _ => 0.0,
            });
        } else {
            out.long_accel_m_s2.push(0.0);
            out.yaw_rate_rad_s.push(0.0);
        }
    }
    out
}

/// The class of each epoch from its signals (the rules of the module docs).
pub(crate) fn classify_signals(s: &DynamicsSignals, thr: &DynamicsThresholds) -> Vec<Dynamics> {
    s.speed_m_s
        .iter()
        .zip(&s.long_accel_m_s2)
        .zip(&s.yaw_rate_rad_s)
        .map(|((&v, &a), &w)| {
            if v < thr.standstill_speed_m_s {
                Dynamics::Standstill
            } else if w.abs() >= thr.turn_rate_rad_s {
                Dynamics::Turn
            } else if a <= -thr.accel_m_s2 {
                Dynamics::Braking
            } else if a >= thr.accel_m_s2 {
                Dynamics::Acceleration
            } else {
                Dynamics::Straight
            }
        })
        .collect()
}

/// Validates a reference trajectory and classifies each of its epochs.
pub fn classify(
    reference: &NavSolution,
    thr: &DynamicsThresholds,
) -> Result<Vec<Dynamics>, EvalError> {
    validate(reference, "reference")?;
    thr.check()?;
    let yaw: Vec<f64> = reference.roll_pitch_yaw_rad.iter().map(|a| a[2]).collect();
    let s = dynamics_signals(&reference.time_s, &reference.vel_ned_m_s, &yaw, thr);
    Ok(classify_signals(&s, thr))
}

/// Share of each class among a set of epochs (fractions summing to 1, or all 0 for no
/// epochs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ClassMix {
    /// Fraction of standstill epochs.
    pub standstill: f64,
    /// Fraction of straight epochs.
    pub straight: f64,
    /// Fraction of turn epochs.
    pub turn: f64,
    /// Fraction of acceleration epochs.
    pub acceleration: f64,
    /// Fraction of braking epochs.
    pub braking: f64,
}

impl ClassMix {
    /// Mix of the given epochs' classes (epochs weigh equally: with a uniformly sampled
    /// reference that is a share of time).
    pub fn of(classes: &[Dynamics]) -> ClassMix {
        let mut c = [0usize; 5];
        for d in classes {
            c[d.index()] += 1;
        }
        ClassMix::from_counts(c)
    }

    /// Mix from per-class counts (index order of [`Dynamics::ALL`]).
    pub(crate) fn from_counts(c: [usize; 5]) -> ClassMix {
        let n: usize = c.iter().sum();
        let f = |k: usize| if n == 0 { 0.0 } else { c[k] as f64 / n as f64 };
        ClassMix {
            standstill: f(0),
            straight: f(1),
            turn: f(2),
            acceleration: f(3),
            braking: f(4),
        }
    }

    /// Fraction of one class.
    pub fn get(&self, d: Dynamics) -> f64 {
        match d {
            Dynamics::Standstill => self.standstill,
            Dynamics::Straight => self.straight,
            Dynamics::Turn => self.turn,
            Dynamics::Acceleration => self.acceleration,
            Dynamics::Braking => self.braking,
        }
    }

    /// The class with the largest share (the first in [`Dynamics::ALL`] order on ties).
    pub fn dominant(&self) -> Dynamics {
        let mut best = Dynamics::Straight;
        let mut share = -1.0;
        for d in Dynamics::ALL {
            if self.get(d) > share {
                share = self.get(d);
                best = d;
            }
        }
        best
    }
}

impl std::fmt::Display for ClassMix {
    /// e.g. `straight 62 %, turn 20 %, braking 18 %` (classes present, largest first).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut v: Vec<(Dynamics, f64)> = Dynamics::ALL
            .iter()
            .map(|&d| (d, self.get(d)))
            .filter(|x| x.1 > 0.0)
            .collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let parts: Vec<String> = v
            .iter()
            .map(|(d, s)| format!("{d} {:.0} %", 100.0 * s))
            .collect();
        f.write_str(&parts.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_signals() {
        // 10 Hz: speed 10 + 1·t m/s northward, then a 10°/s turn from t = 20 s.
        let thr = DynamicsThresholds::default();
        let mut t = vec![];
        let mut v = vec![];
        let mut y = vec![];
        for k in 0..400 {
            let tk = k as f64 * 0.1;
            let speed = if tk < 10.0 { 10.0 + tk } else { 20.0 };
            let yaw = if tk < 20.0 {
                0.0
            } else {
                (10.0 * (tk - 20.0)).to_radians()
            };
            t.push(tk);
            v.push([speed * yaw.cos(), speed * yaw.sin(), 0.0]);
            y.push(f64::NAN); // heading from the course
        }
        let s = dynamics_signals(&t, &v, &y, &thr);
        assert!((s.long_accel_m_s2[50] - 1.0).abs() < 1e-9);
        assert!((s.speed_m_s[50] - 15.0).abs() < 1e-9);
        assert!((s.yaw_rate_rad_s[300].to_degrees() - 10.0).abs() < 1e-9);
        let c = classify_signals(&s, &thr);
        assert_eq!(c[50], Dynamics::Acceleration);
        assert_eq!(c[150], Dynamics::Straight);
        assert_eq!(c[300], Dynamics::Turn);
        let m = ClassMix::of(&c[..]);
        assert!(
            (m.standstill + m.straight + m.turn + m.acceleration + m.braking - 1.0).abs() < 1e-12
        );
    }

    #[test]
    fn bad_thresholds_are_refused() {
        let thr = DynamicsThresholds {
            window_s: 0.0,
            ..DynamicsThresholds::default()
        };
        assert!(matches!(
            thr.check(),
            Err(EvalError::BadOption {
                name: "window_s",
                ..
            })
        ));
    }
}

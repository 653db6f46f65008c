//! Sensor temperature T(t) for the simulation: constant, thermal-chamber steps with a
//! first-order lag, exponential warm-up, or a user series.
//!
//! A [`TemperatureProfile`] is the (TOML) description; [`TemperatureProfile::curve`]
//! validates it and precomputes a [`TemperatureCurve`] that evaluates T(t), °C, at any
//! time t, s (the same time axis as the IMU samples).
//!
//! * **Constant**: T(t) = T.
//! * **Chamber** (soak method, seed paper §2.3/§3.2): the chamber air a(t) follows a list
//!   of set points S_i, each held for its dwell D_i (the first starts at t = 0); the air
//!   either jumps to the next set point or, with `ramp_c_per_min`, moves to it linearly at
//!   that rate (the ramp counts towards the step's dwell). The sensor follows the air with
//!   a first-order lag, dT/dt = (a(t) − T)/τ (Newton cooling of a lumped body). On every
//!   piece where the air is linear, a(t) = a₀ + r(t − t₀), the solution is exact:
//!
//!   ```text
//!   T(t) = a₀ + r(t − t₀) − rτ + (T₀ − a₀ + rτ)·e^{−(t − t₀)/τ}
//!   ```
//!
//!   (with r = 0 for a held set point), chained from piece to piece, so T(t) is exact to
//!   rounding at any t. Before t = 0 the sensor and the air are at `initial_c` (default:
//!   the first set point, i.e. already soaked); after the last step the last set point
//!   is held.
//! * **Warm-up**: T(t) = T₁ − (T₁ − T₀)·e^{−(t − t_s)/τ} for t ≥ t_s, T₀ before (a
//!   cold-soaked board warming up after power-on: the "ramp method" data of autopilots).
//! * **Series**: linear interpolation in user points (t_k, T_k) with strictly increasing
//!   times; the end values are held outside the series.

use serde::{Deserialize, Serialize};

use super::sensor_error::{SensorSimError, check_finite, check_pos};

/// One chamber set point and how long it is held.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamberStep {
    /// Chamber set temperature, °C.
    pub set_c: f64,
    /// Dwell at this set point (including any ramp towards it), s.
    pub duration_s: f64,
}

/// How the sensor temperature evolves (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TemperatureProfile {
    /// Constant temperature.
    Constant {
        /// Temperature, °C.
        t_c: f64,
    },
    /// Thermal-chamber set points with a first-order sensor lag.
    Chamber {
        /// Set points in order; step i starts when step i − 1 ends (the first at t = 0).
        steps: Vec<ChamberStep>,
        /// Sensor time constant τ, s (> 0).
        lag_tau_s: f64,
        /// Sensor (and air) temperature before t = 0, °C (default: the first set point).
        #[serde(default)]
        initial_c: Option<f64>,
        /// Air ramp rate between set points, °C/min (default: instantaneous steps).
        #[serde(default)]
        ramp_c_per_min: Option<f64>,
    },
    /// Exponential warm-up from `t0_c` to `t1_c`.
    WarmUp {
        /// Temperature before and at `start_s`, °C.
        t0_c: f64,
        /// Final temperature, °C.
        t1_c: f64,
        /// Time constant τ, s (> 0).
        tau_s: f64,
        /// Start of the warm-up, s (default 0).
        #[serde(default)]
        start_s: f64,
    },
    /// Linear interpolation in a user series.
    Series {
        /// Times, s, strictly increasing.
        time_s: Vec<f64>,
        /// Temperatures, °C, one per time.
        t_c: Vec<f64>,
    },
}

/// A validated temperature profile, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct TemperatureCurve {
    kind: Curve,
}

#[derive(Clone, Debug, PartialEq)]
enum Curve {
    Constant(f64),
    Lag {
        tau_s: f64,
        before_c: f64,
        pieces: Vec<LagPiece>,
    },
    WarmUp {
        t0_c: f64,
        t1_c: f64,
        tau_s: f64,
        start_s: f64,
    },
    Series {
        time_s: Vec<f64>,
        t_c: Vec<f64>,
    },
}

/// A piece of the chamber profile on which the air is linear: from `start_s` the air is
/// `air0_c + slope·(t − start_s)` and the sensor starts at `sensor0_c`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LagPiece {
    start_s: f64,
    air0_c: f64,
    slope_c_per_s: f64,
    sensor0_c: f64,
}

impl LagPiece {
    /// Exact first-order-lag response at `t_s` (module equation).
    #[inline]
    fn eval(&self, tau_s: f64, t_s: f64) -> f64 {
        let dt = t_s - self.start_s;
        let r = self.slope_c_per_s;
        let e0 = self.sensor0_c - self.air0_c + r * tau_s;
        self.air0_c + r * (dt - tau_s) + e0 * (-dt / tau_s).exp()
    }
}

impl TemperatureProfile {
    /// A constant temperature.
    pub fn constant(t_c: f64) -> TemperatureProfile {
        TemperatureProfile::Constant { t_c }
    }

    /// Validate and precompute.
    pub fn curve(&self) -> Result<TemperatureCurve, SensorSimError> {
        let kind = match self {
            TemperatureProfile::Constant { t_c } => {
                check_finite("temperature.t_c", *t_c)?;
                Curve::Constant(*t_c)
            }
            TemperatureProfile::Chamber {
                steps,
                lag_tau_s,
                initial_c,
                ramp_c_per_min,
            } => chamber_curve(steps, *lag_tau_s, *initial_c, *ramp_c_per_min)?,
            TemperatureProfile::WarmUp {
                t0_c,
                t1_c,
                tau_s,
                start_s,
            } => {
                check_finite("temperature.t0_c", *t0_c)?;
                check_finite("temperature.t1_c", *t1_c)?;
                check_pos("temperature.tau_s", *tau_s)?;
                check_finite("temperature.start_s", *start_s)?;
                Curve::WarmUp {
                    t0_c: *t0_c,
                    t1_c: *t1_c,
                    tau_s: *tau_s,
                    start_s: *start_s,
                }
            }
            TemperatureProfile::Series { time_s, t_c } => {
                if time_s.is_empty() || time_s.len() != t_c.len() {
                    return Err(SensorSimError::invalid(
                        format!(
                            "temperature series ({} times, {} temperatures)",
                            time_s.len(),
                            t_c.len()
                        ),
                        "needs at least one point and as many temperatures as times",
                    ));
                }
                for (k, (&t, &v)) in time_s.iter().zip(t_c).enumerate() {
                    check_finite(&format!("temperature.time_s[{k}]"), t)?;
                    check_finite(&format!("temperature.t_c[{k}]"), v)?;
                    if k > 0 && t <= time_s[k - 1] {
                        return Err(SensorSimError::invalid(
                            format!("temperature.time_s[{k}] = {t}"),
                            format!(
                                "times must be strictly increasing (time_s[{}] = {})",
                                k - 1,
                                time_s[k - 1]
                            ),
                        ));
                    }
                }
                Curve::Series {
                    time_s: time_s.clone(),
                    t_c: t_c.clone(),
                }
            }
        };
        Ok(TemperatureCurve { kind })
    }
}

fn chamber_curve(
    steps: &[ChamberStep],
    tau_s: f64,
    initial_c: Option<f64>,
    ramp_c_per_min: Option<f64>,
) -> Result<Curve, SensorSimError> {
    check_pos("temperature.lag_tau_s", tau_s)?;
    let Some(first) = steps.first() else {
        return Err(SensorSimError::invalid(
            "temperature.steps (empty)",
            "a chamber profile needs at least one set point",
        ));
    };
    let ramp = match ramp_c_per_min {
        Some(r) => {
            check_pos("temperature.ramp_c_per_min", r)?;
            Some(r / 60.0)
        }
        None => None,
    };
    let before_c = initial_c.unwrap_or(first.set_c);
    check_finite("temperature.initial_c", before_c)?;
    let mut pieces = Vec::with_capacity(2 * steps.len());
    let (mut t, mut air, mut sensor) = (0.0f64, before_c, before_c);
    for (i, s) in steps.iter().enumerate() {
        check_finite(&format!("temperature.steps[{i}].set_c"), s.set_c)?;
        check_pos(&format!("temperature.steps[{i}].duration_s"), s.duration_s)?;
        let mut held_from = t;
        if let Some(r) = ramp
            && s.set_c != air
        {
            let d = (s.set_c - air).abs() / r;
            if d > s.duration_s {
                return Err(SensorSimError::invalid(
                    format!("temperature.steps[{i}].duration_s = {}", s.duration_s),
                    format!(
                        "shorter than the {d} s ramp from {air} °C to {} °C at {} °C/min",
                        s.set_c,
                        r * 60.0
                    ),
                ));
            }
            let p = LagPiece {
                start_s: t,
                air0_c: air,
                slope_c_per_s: r * (s.set_c - air).signum(),
                sensor0_c: sensor,
            };
            sensor = p.eval(tau_s, t + d);
            pieces.push(p);
            held_from = t + d;
        }
        let p = LagPiece {
            start_s: held_from,
            air0_c: s.set_c,
            slope_c_per_s: 0.0,
            sensor0_c: sensor,
        };
        t += s.duration_s;
        sensor = p.eval(tau_s, t);
        air = s.set_c;
        pieces.push(p);
    }
    Ok(Curve::Lag {
        tau_s,
        before_c,
        pieces,
    })
}

impl TemperatureCurve {
    /// Sensor temperature at `t_s`, °C.
    pub fn t_c(&self, t_s: f64) -> f64 {
        match &self.kind {
            Curve::Constant(v) => *v,
            Curve::Lag {
                tau_s,
                before_c,
                pieces,
            } => {
                let i = pieces.partition_point(|p| p.start_s <= t_s);
                if i == 0 {
                    *before_c
                } else {
                    pieces[i - 1].eval(*tau_s, t_s)
                }
            }
            Curve::WarmUp {
                t0_c,
                t1_c,
                tau_s,
                start_s,
            } => {
                if t_s <= *start_s {
                    *t0_c
                } else {
                    t1_c - (t1_c - t0_c) * (-(t_s - start_s) / tau_s).exp()
                }
            }
            Curve::Series { time_s, t_c } => {
                let i = time_s.partition_point(|&t| t <= t_s);
                if i == 0 {
                    t_c[0]
                } else if i == time_s.len() {
                    t_c[i - 1]
                } else {
                    let (ta, tb) = (time_s[i - 1], time_s[i]);
                    let w = (t_s - ta) / (tb - ta);
                    t_c[i - 1] + w * (t_c[i] - t_c[i - 1])
                }
            }
        }
    }

    /// Whether the temperature never changes.
    pub(crate) fn is_constant(&self) -> bool {
        matches!(self.kind, Curve::Constant(_))
    }

    /// T at the times `first_s + k·dt_s`, k = 0 … out.len() − 1, into `out` (parallel).
    pub(crate) fn sample_into(&self, first_s: f64, dt_s: f64, out: &mut [f64]) {
        use rayon::prelude::*;
        if let Curve::Constant(v) = self.kind {
            out.fill(v);
            return;
        }
        const CHUNK: usize = 1 << 16;
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let k0 = c * CHUNK;
                let time = |j: usize| first_s + (k0 + j) as f64 * dt_s;
                match &self.kind {
                    // Walk the pieces in order instead of a binary search per sample.
                    Curve::Lag {
                        tau_s,
                        before_c,
                        pieces,
                    } => {
                        let mut i = pieces.partition_point(|p| p.start_s <= time(0));
                        for (j, v) in chunk.iter_mut().enumerate() {
                            let t = time(j);
                            while i < pieces.len() && pieces[i].start_s <= t {
                                i += 1;
                            }
                            *v = if i == 0 {
                                *before_c
                            } else {
                                pieces[i - 1].eval(*tau_s, t)
                            };
                        }
                    }
                    _ => {
                        for (j, v) in chunk.iter_mut().enumerate() {
                            *v = self.t_c(time(j));
                        }
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chamber(steps: &[(f64, f64)], tau: f64, ramp: Option<f64>) -> TemperatureProfile {
        TemperatureProfile::Chamber {
            steps: steps
                .iter()
                .map(|&(set_c, duration_s)| ChamberStep { set_c, duration_s })
                .collect(),
            lag_tau_s: tau,
            initial_c: None,
            ramp_c_per_min: ramp,
        }
    }

    #[test]
    fn chamber_lag_is_exact_first_order_response() {
        let c = chamber(
            &[(-25.0, 1000.0), (-20.0, 1000.0), (40.0, 500.0)],
            100.0,
            None,
        )
        .curve()
        .unwrap();
        assert_eq!(c.t_c(-5.0), -25.0);
        assert_eq!(c.t_c(500.0), -25.0);
        // 300 s into the second step: −20 − 5·e^{−3}.
        let want = -20.0 - 5.0 * (-3.0f64).exp();
        assert!((c.t_c(1300.0) - want).abs() < 1e-12);
        // Third step starts from the value reached at t = 2000 s.
        let t2000 = -20.0 - 5.0 * (-10.0f64).exp();
        assert!((c.t_c(2000.0) - t2000).abs() < 1e-12);
        let want = 40.0 + (t2000 - 40.0) * (-2.5f64).exp();
        assert!((c.t_c(2250.0) - want).abs() < 1e-12);
        // After the last step the set point is held.
        assert!((c.t_c(1e6) - 40.0).abs() < 1e-12);
        // Bulk sampling equals point evaluation.
        let mut out = vec![0.0; 300_000];
        c.sample_into(-10.0, 0.01, &mut out);
        for k in (0..out.len()).step_by(997) {
            assert_eq!(out[k], c.t_c(-10.0 + k as f64 * 0.01), "{k}");
        }
        // Continuity and the differential equation by a central difference.
        for t in [999.999, 1000.0, 1000.001, 1712.3, 2000.0] {
            let h = 1e-3;
            let d = (c.t_c(t + h) - c.t_c(t - h)) / (2.0 * h);
            let air = if t < 1000.0 {
                -25.0
            } else if t < 2000.0 {
                -20.0
            } else {
                40.0
            };
            if (t - 1000.0f64).abs() > 2e-3 && (t - 2000.0f64).abs() > 2e-3 {
                assert!((d - (air - c.t_c(t)) / 100.0).abs() < 1e-7, "t={t}");
            }
            assert!((c.t_c(t + 1e-9) - c.t_c(t - 1e-9)).abs() < 1e-6);
        }
    }

    #[test]
    fn chamber_ramp_matches_numerical_integration() {
        let c = chamber(&[(0.0, 100.0), (10.0, 600.0)], 50.0, Some(2.0))
            .curve()
            .unwrap();
        // Integrate dT/dt = (a − T)/τ with RK4, air ramping at 2 °C/min from t = 100 s.
        let air = |t: f64| {
            if t < 100.0 {
                0.0
            } else {
                (2.0 / 60.0 * (t - 100.0)).min(10.0)
            }
        };
        let (mut t, mut y, h) = (0.0f64, 0.0f64, 0.01);
        while t < 699.999 {
            let f = |t: f64, y: f64| (air(t) - y) / 50.0;
            let k1 = f(t, y);
            let k2 = f(t + h / 2.0, y + h / 2.0 * k1);
            let k3 = f(t + h / 2.0, y + h / 2.0 * k2);
            let k4 = f(t + h, y + h * k3);
            y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            t += h;
        }
        assert!((c.t_c(t) - y).abs() < 1e-8, "{} vs {y}", c.t_c(t));
    }

    #[test]
    fn warm_up_and_series() {
        let w = TemperatureProfile::WarmUp {
            t0_c: 5.0,
            t1_c: 45.0,
            tau_s: 600.0,
            start_s: 0.0,
        }
        .curve()
        .unwrap();
        assert_eq!(w.t_c(-1.0), 5.0);
        assert!((w.t_c(600.0) - (45.0 - 40.0 / std::f64::consts::E)).abs() < 1e-12);
        let s = TemperatureProfile::Series {
            time_s: vec![0.0, 10.0, 30.0],
            t_c: vec![20.0, 30.0, 10.0],
        }
        .curve()
        .unwrap();
        assert_eq!(s.t_c(-3.0), 20.0);
        assert!((s.t_c(5.0) - 25.0).abs() < 1e-12);
        assert!((s.t_c(20.0) - 20.0).abs() < 1e-12);
        assert_eq!(s.t_c(99.0), 10.0);
        let mut out = vec![0.0; 7];
        s.sample_into(0.0, 5.0, &mut out);
        assert_eq!(out, vec![20.0, 25.0, 30.0, 25.0, 20.0, 15.0, 10.0]);
    }

    #[test]
    fn rejects_bad_profiles() {
        let e = chamber(&[(20.0, 10.0)], 0.0, None).curve().unwrap_err();
        assert!(e.to_string().contains("lag_tau_s = 0"), "{e}");
        assert!(chamber(&[(20.0, 10.0)], -1.0, None).curve().is_err());
        assert!(chamber(&[], 1.0, None).curve().is_err());
        assert!(chamber(&[(f64::NAN, 10.0)], 1.0, None).curve().is_err());
        let e = chamber(&[(0.0, 10.0), (50.0, 10.0)], 1.0, Some(1.0))
            .curve()
            .unwrap_err();
        assert!(e.to_string().contains("ramp"), "{e}");
        let e = TemperatureProfile::Series {
            time_s: vec![0.0, 1.0, 1.0],
            t_c: vec![1.0, 2.0, 3.0],
        }
        .curve()
        .unwrap_err();
        assert!(e.to_string().contains("time_s[2] = 1"), "{e}");
        assert!(
            TemperatureProfile::Series {
                time_s: vec![0.0],
                t_c: vec![]
            }
            .curve()
            .is_err()
        );
        assert!(
            TemperatureProfile::WarmUp {
                t0_c: 0.0,
                t1_c: 1.0,
                tau_s: 0.0,
                start_s: 0.0
            }
            .curve()
            .is_err()
        );
        assert!(TemperatureProfile::constant(f64::NAN).curve().is_err());
    }

    #[test]
    fn toml_round_trip_and_unknown_fields() {
        let p = chamber(&[(-25.0, 3600.0), (-20.0, 3600.0)], 300.0, Some(1.0));
        let s = toml::to_string(&p).unwrap();
        let back: TemperatureProfile = toml::from_str(&s).unwrap();
        assert_eq!(back, p);
        let bad = "kind = \"constant\"\nt_c = 20.0\ntypo = 1\n";
        assert!(toml::from_str::<TemperatureProfile>(bad).is_err());
        let ok: TemperatureProfile = toml::from_str("kind = \"constant\"\nt_c = 20.0\n").unwrap();
        assert_eq!(ok, TemperatureProfile::constant(20.0));
    }
}

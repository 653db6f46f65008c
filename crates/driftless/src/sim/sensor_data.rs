//! Input and output of the sensor-error model ([`super::sensor`]): ideal rates or
//! increments (constant, per sample, or from a [`Trajectory`]) and the simulated output
//! with its truth.

use driftless_model::linalg::Vec3;
use serde::{Deserialize, Serialize};

use super::ideal_imu::{Trajectory, TrajectoryPoint, ideal_increment};
use super::sensor_config::CHANNEL_NAMES;
use super::sensor_error::{SensorSimError, check_finite, check_pos};
use crate::calib::protocol::ChamberManifest;
use crate::calib::six_position::{SixPositionError, SixPositionInput};
use crate::io::{Channel, ImuLog, Quantity};
use crate::nav::mechanization::ImuIncrement;

/// Whether the samples are rates (ω rad/s, f m/s² at t_k) or increments (Δθ rad, Δv m/s
/// over (t_k − Δt, t_k]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputKind {
    /// Point samples of ω_ib^b and f^b.
    Rates,
    /// Interval integrals Δθ, Δv.
    Increments,
}

/// One ideal input signal: a constant (static IMU) or one value per sample.
#[derive(Clone, Debug, PartialEq)]
pub enum Signal {
    /// The same value at every sample.
    Constant(Vec3),
    /// One value per sample.
    Samples(Vec<Vec3>),
}

impl Signal {
    /// Value at sample `k` (panics if `k` is out of range of `Samples`).
    #[inline]
    pub fn at(&self, k: usize) -> Vec3 {
        match self {
            Signal::Constant(v) => *v,
            Signal::Samples(s) => s[k],
        }
    }
}

/// The ideal (error-free) IMU input to [`super::sensor::SensorModel::simulate`]: sample k is at time
/// `first_time_s + k·dt_s` (for increments: the end of its interval).
#[derive(Clone, Debug, PartialEq)]
pub struct IdealImu {
    /// Rates or increments.
    pub kind: OutputKind,
    /// Time of sample 0, s.
    pub first_time_s: f64,
    /// Sample interval Δt, s.
    pub dt_s: f64,
    /// Number of samples.
    pub n_samples: usize,
    /// ω_ib^b (rad/s) or Δθ (rad).
    pub gyro: Signal,
    /// f^b (m/s²) or Δv (m/s).
    pub accel: Signal,
}

impl IdealImu {
    /// A static IMU: constant ideal rates, or for increments the rates times Δt.
    pub fn constant(
        kind: OutputKind,
        first_time_s: f64,
        dt_s: f64,
        n_samples: usize,
        omega_ib_b_rad_s: Vec3,
        f_b_m_s2: Vec3,
    ) -> IdealImu {
        let w = match kind {
            OutputKind::Rates => 1.0,
            OutputKind::Increments => dt_s,
        };
        IdealImu {
            kind,
            first_time_s,
            dt_s,
            n_samples,
            gyro: Signal::Constant(omega_ib_b_rad_s.map(|v| v * w)),
            accel: Signal::Constant(f_b_m_s2.map(|v| v * w)),
        }
    }

    /// Ideal samples along a trajectory, computed in parallel: rates at t_k
    /// ([`TrajectoryPoint::imu_rates`]) or exact increments over
    /// (t_k − Δt, t_k] ([`ideal_increment`], integrated on a local time axis so that the
    /// interval length is exactly Δt), t_k = `first_time_s` + k·`dt_s`.
    pub fn from_trajectory<T: Trajectory + Sync + ?Sized>(
        traj: &T,
        kind: OutputKind,
        first_time_s: f64,
        dt_s: f64,
        n_samples: usize,
    ) -> IdealImu {
        IdealImu::from_fn(kind, first_time_s, dt_s, n_samples, |k| {
            ideal_sample(traj, kind, first_time_s + k as f64 * dt_s, dt_s)
        })
    }

    /// Ideal samples from a function of the sample index returning (gyro, accel), in
    /// parallel.
    pub fn from_fn<F: Fn(usize) -> (Vec3, Vec3) + Sync>(
        kind: OutputKind,
        first_time_s: f64,
        dt_s: f64,
        n_samples: usize,
        sample: F,
    ) -> IdealImu {
        use rayon::prelude::*;
        let (gyro, accel): (Vec<Vec3>, Vec<Vec3>) = (0..n_samples)
            .into_par_iter()
            .with_min_len(4096)
            .map(&sample)
            .unzip();
        IdealImu {
            kind,
            first_time_s,
            dt_s,
            n_samples,
            gyro: Signal::Samples(gyro),
            accel: Signal::Samples(accel),
        }
    }

    pub(crate) fn validate(&self) -> Result<(), SensorSimError> {
        check_pos("input.dt_s", self.dt_s)?;
        check_finite("input.first_time_s", self.first_time_s)?;
        if self.n_samples == 0 {
            return Err(SensorSimError::invalid(
                "input.n_samples = 0",
                "nothing to simulate",
            ));
        }
        for (name, s) in [("gyro", &self.gyro), ("accel", &self.accel)] {
            match s {
                Signal::Constant(v) => {
                    for (i, &x) in v.iter().enumerate() {
                        check_finite(&format!("input.{name}[{i}]"), x)?;
                    }
                }
                Signal::Samples(v) if v.len() != self.n_samples => {
                    return Err(SensorSimError::invalid(
                        format!("input.{name} ({} samples)", v.len()),
                        format!("n_samples is {}", self.n_samples),
                    ));
                }
                Signal::Samples(_) => {}
            }
        }
        Ok(())
    }
}

/// One ideal sample of a trajectory: the rates at `t_s`, or the increment over
/// (t_s − Δt, t_s] integrated on a local time axis starting at the interval start, so
/// that the quadrature weights use Δt itself and not the difference of two large times
/// (which loses ~1e-12 relative at t ≈ 1e4 s).
pub fn ideal_sample<T: Trajectory + ?Sized>(
    traj: &T,
    kind: OutputKind,
    t_s: f64,
    dt_s: f64,
) -> (Vec3, Vec3) {
    match kind {
        OutputKind::Rates => traj.point(t_s).imu_rates(),
        OutputKind::Increments => {
            let local = Shifted {
                inner: traj,
                offset_s: t_s - dt_s,
            };
            let inc = ideal_increment(&local, 0.0, dt_s);
            (inc.dtheta_rad, inc.dvel_m_s)
        }
    }
}

/// `inner` on a time axis shifted by `offset_s`: point(τ) = inner.point(offset_s + τ).
struct Shifted<'a, T: ?Sized> {
    inner: &'a T,
    offset_s: f64,
}

impl<T: Trajectory + ?Sized> Trajectory for Shifted<'_, T> {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        self.inner.point(self.offset_s + t_s)
    }

    fn next_break_s(&self, t_s: f64) -> Option<f64> {
        self.inner
            .next_break_s(self.offset_s + t_s)
            .map(|b| b - self.offset_s)
    }
}

/// Simulated IMU output with its truth.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorOutput {
    /// Rates or increments.
    pub kind: OutputKind,
    /// Time of sample 0, s.
    pub first_time_s: f64,
    /// Sample interval, s.
    pub dt_s: f64,
    /// Gyro x, y, z: rad/s (rates) or rad (increments).
    pub gyro: [Vec<f64>; 3],
    /// Accelerometer x, y, z: m/s² (rates) or m/s (increments).
    pub accel: [Vec<f64>; 3],
    /// Temperature the IMU reports per sample, °C (the true sensor temperature when the
    /// [`super::sensor_config::TemperatureSensor`] is ideal; otherwise the truth is the profile's T at
    /// [`SensorOutput::temperature_time_s`]).
    pub temperature_c: Vec<f64>,
    /// The turn-on gyro biases drawn for this run, rad/s.
    pub gyro_turn_on_bias_rad_s: Vec3,
    /// The turn-on accelerometer biases drawn for this run, m/s².
    pub accel_turn_on_bias_m_s2: Vec3,
}

impl SensorOutput {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.temperature_c.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.temperature_c.is_empty()
    }

    /// Time of sample `k`, s.
    pub fn time_s(&self, k: usize) -> f64 {
        self.first_time_s + k as f64 * self.dt_s
    }

    /// Time at which sample `k`'s temperature was taken: t_k for rates, the interval
    /// midpoint t_k − Δt/2 for increments.
    pub fn temperature_time_s(&self, k: usize) -> f64 {
        match self.kind {
            OutputKind::Rates => self.time_s(k),
            OutputKind::Increments => self.time_s(k) - 0.5 * self.dt_s,
        }
    }

    /// Gyro sample `k` as a vector.
    pub fn gyro_at(&self, k: usize) -> Vec3 {
        [self.gyro[0][k], self.gyro[1][k], self.gyro[2][k]]
    }

    /// Accelerometer sample `k` as a vector.
    pub fn accel_at(&self, k: usize) -> Vec3 {
        [self.accel[0][k], self.accel[1][k], self.accel[2][k]]
    }

    /// The samples as navigation increments (rates are taken as interval averages over
    /// (t_k − Δt, t_k]: Δθ = ω·Δt, Δv = f·Δt).
    pub fn to_increments(&self) -> Vec<ImuIncrement> {
        let w = match self.kind {
            OutputKind::Rates => self.dt_s,
            OutputKind::Increments => 1.0,
        };
        (0..self.len())
            .map(|k| ImuIncrement {
                time_s: self.time_s(k),
                dt_s: self.dt_s,
                dtheta_rad: self.gyro_at(k).map(|v| v * w),
                dvel_m_s: self.accel_at(k).map(|v| v * w),
            })
            .collect()
    }

    /// The position and rate segments at set temperature `set_temperature_c` of a chamber
    /// manifest, averaged from a simulated (or recorded, same layout) output: rates are
    /// used as they are, increments divided by Δt. Samples per segment:
    /// [`crate::calib::protocol::Segment::sample_range`].
    pub fn six_position_input(
        &self,
        manifest: &ChamberManifest,
        set_temperature_c: f64,
    ) -> Result<SixPositionInput, SixPositionError> {
        let fs = manifest.sample_rate_hz;
        if !(fs > 0.0 && self.dt_s > 0.0) || ((1.0 / fs) - self.dt_s).abs() > 1e-9 * self.dt_s {
            return Err(SixPositionError::Invalid(format!(
                "manifest rate {fs} Hz does not match the output's Δt = {} s",
                self.dt_s
            )));
        }
        let scale = match self.kind {
            OutputKind::Rates => 1.0,
            OutputKind::Increments => 1.0 / self.dt_s,
        };
        SixPositionInput::from_manifest_columns(
            manifest,
            self.accel.each_ref().map(Vec::as_slice),
            self.gyro.each_ref().map(Vec::as_slice),
            scale,
            set_temperature_c,
        )
    }

    /// A columnar log (`gyro_x` … `acc_z`, `temp`) with a time column, e.g. for
    /// `driftless allan` or the writers in [`crate::io`]. Rate channels carry their
    /// quantities; increment channels are `Other` with unit `rad` / `m/s`.
    pub fn to_imu_log(&self, source: impl Into<String>) -> ImuLog {
        let (qg, qa, ug, ua) = match self.kind {
            OutputKind::Rates => (
                Quantity::AngularRate,
                Quantity::SpecificForce,
                "rad/s",
                "m/s^2",
            ),
            OutputKind::Increments => (Quantity::Other, Quantity::Other, "rad", "m/s"),
        };
        let mut channels = Vec::with_capacity(7);
        for (a, name) in CHANNEL_NAMES.iter().enumerate() {
            let (q, u, v) = if a < 3 {
                (qg, ug, &self.gyro[a])
            } else {
                (qa, ua, &self.accel[a - 3])
            };
            channels.push(Channel {
                name: name.to_string(),
                quantity: q,
                source_unit: u.to_string(),
                values: v.clone(),
            });
        }
        channels.push(Channel {
            name: "temp".into(),
            quantity: Quantity::Temperature,
            source_unit: "degC".into(),
            values: self.temperature_c.clone(),
        });
        let time = (0..self.len()).map(|k| self.time_s(k)).collect();
        ImuLog::new(source, Some(time), self.dt_s, channels)
    }
}

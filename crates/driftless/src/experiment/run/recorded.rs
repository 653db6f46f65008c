//! Recorded vehicle data: the IMU and GNSS files read in `prepare`, and a rates log
//! with a temperature column split into SI triads.

use crate::io::nav::GnssFixes;
use crate::io::{ImuLog, Quantity};
use crate::nav::pipeline::{ImuStream, ImuStreamOptions};
use crate::nav::session::SessionConfig;

/// Recorded vehicle data, read in [`prepare`](super::prepare).
#[derive(Debug)]
pub struct RecordedVehicle {
    /// The IMU stream (vehicle frame).
    pub imu: ImuStream,
    /// The rates log with its temperature column (`csv` format only): cases b and c
    /// compensate it sample by sample.
    pub rates: Option<RatesWithTemperature>,
    /// GNSS fixes inside the IMU span.
    pub fixes: GnssFixes,
    /// Session settings (filter, aids, floors) of the data set.
    pub session: SessionConfig,
}

/// A rates log split into SI triads and the temperature reading (`csv` vehicle data).
#[derive(Clone, Debug)]
pub struct RatesWithTemperature {
    /// Where it came from.
    pub source: String,
    /// Time stamps, GPS s.
    pub time_s: Vec<f64>,
    /// Angular rate x, y, z, rad/s.
    pub gyro_rad_s: [Vec<f64>; 3],
    /// Specific force x, y, z, m/s².
    pub accel_m_s2: [Vec<f64>; 3],
    /// Sensor temperature, °C (`None` without a temperature column).
    pub temperature_c: Option<Vec<f64>>,
}

impl RatesWithTemperature {
    /// Splits a log: the first three angular-rate and specific-force channels in file
    /// order, and the temperature channel if there is one.
    pub fn from_log(log: &ImuLog) -> Result<RatesWithTemperature, String> {
        let Some(t) = &log.time_s else {
            return Err(format!("{}: no time column", log.source));
        };
        let pick = |q: Quantity, what: &str| -> Result<[Vec<f64>; 3], String> {
            let idx = log.indices_of(q);
            if idx.len() != 3 {
                return Err(format!(
                    "{}: {} {what} columns found, 3 needed (name the units in the header, e.g. \
                     gyro_x [rad/s], acc_x [m/s^2])",
                    log.source,
                    idx.len()
                ));
            }
            Ok([0, 1, 2].map(|k| log.channels[idx[k]].values.clone()))
        };
        let temperature_c = log
            .indices_of(Quantity::Temperature)
            .first()
            .map(|&i| log.channels[i].values.clone());
        Ok(RatesWithTemperature {
            source: log.source.clone(),
            time_s: t.clone(),
            gyro_rad_s: pick(Quantity::AngularRate, "angular-rate")?,
            accel_m_s2: pick(Quantity::SpecificForce, "specific-force")?,
            temperature_c,
        })
    }

    /// The stream after `f(sample index, ω, f) → (ω', f')`.
    pub(super) fn stream(
        &self,
        label: &str,
        f: impl Fn(usize, [f64; 3], [f64; 3]) -> Result<([f64; 3], [f64; 3]), String>,
    ) -> Result<ImuStream, String> {
        let n = self.time_s.len();
        let mut g: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        let mut a: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        for k in 0..n {
            let w = [0, 1, 2].map(|j| self.gyro_rad_s[j][k]);
            let fb = [0, 1, 2].map(|j| self.accel_m_s2[j][k]);
            let (wc, fc) = f(k, w, fb)?;
            for j in 0..3 {
                g[j].push(wc[j]);
                a[j].push(fc[j]);
            }
        }
        crate::nav::pipeline::rates_to_stream(
            &format!("{} ({label})", self.source),
            None,
            &self.time_s,
            g.each_ref().map(Vec::as_slice),
            a.each_ref().map(Vec::as_slice),
            &ImuStreamOptions::default(),
        )
        .map_err(|e| e.to_string())
    }
}

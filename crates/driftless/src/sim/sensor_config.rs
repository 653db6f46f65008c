//! Configuration of the sensor-error model ([`super::sensor`]): per-triad error terms,
//! per-axis noise, the temperature sensor, all TOML-serialisable with
//! `deny_unknown_fields`, SI units (explicit in the field names where the triad fixes
//! them).

use serde::{Deserialize, Serialize};

use super::noise::{FlickerConfig, GaussMarkovConfig, StaticNoiseConfig};
use super::sensor_error::{SensorSimError, check_finite, check_nonneg, check_pos};
use crate::allan::fit::NoiseFit;
use crate::allan::noise_model::NoiseModel;
use crate::io::Quantity;

/// Names of the six channels, in axis order (gyro x, y, z, accelerometer x, y, z); also
/// the channel names looked up in a [`NoiseModel`].
pub const CHANNEL_NAMES: [&str; 6] = ["gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"];

/// Largest |M_ij| accepted, rad: beyond this the small-angle model is not meaningful.
pub(crate) const MAX_MISALIGNMENT_RAD: f64 = 0.1;

/// Stochastic terms of one axis, continuous-time, SI; u = rad/s (gyro) or m/s² (accel).
/// Same meaning as the fields of [`StaticNoiseConfig`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AxisNoise {
    /// Quantization noise Q (angle/velocity domain), u·s.
    pub quantization: f64,
    /// White noise density N (ARW rad/√s, VRW m/s/√s), u·√s.
    pub white: f64,
    /// Bias instability B (flicker floor of the Allan deviation ≈ 0.664·B), u.
    pub bias_instability: f64,
    /// Rate random walk K, u/√s.
    pub rate_random_walk: f64,
    /// Rate ramp R, u/s.
    pub rate_ramp: f64,
    /// Optional first-order Gauss-Markov term (σ u, correlation time s).
    pub gauss_markov: Option<GaussMarkovConfig>,
}

impl AxisNoise {
    /// The fitted terms of a noise fit (terms not fitted or not detected are zero).
    pub(crate) fn from_fit(fit: &NoiseFit) -> AxisNoise {
        let v = |t: Option<crate::allan::fit::Term>| t.map_or(0.0, |t| t.value);
        AxisNoise {
            quantization: v(fit.quantization),
            white: v(fit.white),
            bias_instability: v(fit.bias_instability),
            rate_random_walk: v(fit.rate_random_walk),
            rate_ramp: v(fit.rate_ramp),
            gauss_markov: fit.gauss_markov.map(|g| GaussMarkovConfig {
                sigma: g.sigma.value,
                tau_c_s: g.tau_c_s.value,
            }),
        }
    }

    /// True when every term is zero.
    pub(crate) fn is_zero(&self) -> bool {
        self.quantization == 0.0
            && self.white == 0.0
            && self.bias_instability == 0.0
            && self.rate_random_walk == 0.0
            && self.rate_ramp == 0.0
            && self.gauss_markov.is_none_or(|g| g.sigma == 0.0)
    }

    pub(crate) fn validate(&self, what: &str) -> Result<(), SensorSimError> {
        check_nonneg(&format!("{what}.quantization"), self.quantization)?;
        check_nonneg(&format!("{what}.white"), self.white)?;
        check_nonneg(&format!("{what}.bias_instability"), self.bias_instability)?;
        check_nonneg(&format!("{what}.rate_random_walk"), self.rate_random_walk)?;
        check_finite(&format!("{what}.rate_ramp"), self.rate_ramp)?;
        if let Some(g) = &self.gauss_markov {
            check_nonneg(&format!("{what}.gauss_markov.sigma"), g.sigma)?;
            check_pos(&format!("{what}.gauss_markov.tau_c_s"), g.tau_c_s)?;
        }
        Ok(())
    }

    pub(crate) fn static_config(
        &self,
        dt_s: f64,
        n: usize,
        flicker: FlickerConfig,
    ) -> StaticNoiseConfig {
        StaticNoiseConfig {
            sample_rate_hz: 1.0 / dt_s,
            duration_s: n as f64 * dt_s,
            quantization: self.quantization,
            white: self.white,
            bias_instability: self.bias_instability,
            rate_random_walk: self.rate_random_walk,
            rate_ramp: self.rate_ramp,
            gauss_markov: self.gauss_markov,
            turn_on_bias: 0.0,
            flicker,
        }
    }
}

/// Gyro triad errors (see the forward equation in [`super::sensor`]), SI.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GyroErrors {
    /// 1σ of the turn-on bias b_on per axis, rad/s.
    pub turn_on_bias_sigma_rad_s: [f64; 3],
    /// Bias b(T) per axis: coefficients of ΔT^k (k = 0 … 5), rad/s/°C^k.
    pub bias_poly_rad_s: [Vec<f64>; 3],
    /// Scale-factor error s(T) per axis: coefficients of ΔT^k, 1/°C^k (dimensionless c₀).
    pub scale_factor_poly: [Vec<f64>; 3],
    /// Misalignment M, rad (zero diagonal; row i = sensing axis i, see module docs).
    pub misalignment_rad: [[f64; 3]; 3],
    /// g-sensitivity G, rad/s per m/s² (row i: axis i's response to f^b).
    pub g_sensitivity_rad_s_per_m_s2: [[f64; 3]; 3],
    /// Stochastic terms per axis (u = rad/s).
    pub noise: [AxisNoise; 3],
    /// Output LSB of rate samples, rad/s (0 = no quantization).
    pub rate_lsb_rad_s: f64,
    /// Output LSB of angle increments, rad (0 = no quantization).
    pub increment_lsb_rad: f64,
}

/// Accelerometer triad errors (see the forward equation in [`super::sensor`]), SI.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AccelErrors {
    /// 1σ of the turn-on bias b_on per axis, m/s².
    pub turn_on_bias_sigma_m_s2: [f64; 3],
    /// Bias b(T) per axis: coefficients of ΔT^k (k = 0 … 5), m/s²/°C^k.
    pub bias_poly_m_s2: [Vec<f64>; 3],
    /// Scale-factor error s(T) per axis: coefficients of ΔT^k, 1/°C^k (dimensionless c₀).
    pub scale_factor_poly: [Vec<f64>; 3],
    /// Misalignment M, rad (zero diagonal; row i = sensing axis i, see module docs).
    pub misalignment_rad: [[f64; 3]; 3],
    /// Stochastic terms per axis (u = m/s²).
    pub noise: [AxisNoise; 3],
    /// Output LSB of specific-force samples, m/s² (0 = no quantization).
    pub rate_lsb_m_s2: f64,
    /// Output LSB of velocity increments, m/s (0 = no quantization).
    pub increment_lsb_m_s: f64,
}

/// The temperature the IMU reports: T_true + offset + N(0, σ²), rounded to the LSB.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TemperatureSensor {
    /// Constant offset of the reading, °C.
    pub offset_c: f64,
    /// White noise of each reading (1σ), °C.
    pub noise_sigma_c: f64,
    /// Reading resolution, °C (0 = none; many IMUs report 1 °C or 0.1 °C steps).
    pub lsb_c: f64,
}

impl TemperatureSensor {
    pub(crate) fn is_ideal(&self) -> bool {
        self.offset_c == 0.0 && self.noise_sigma_c == 0.0 && self.lsb_c == 0.0
    }
}

/// A complete six-axis sensor-error configuration (TOML-serialisable).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorConfig {
    /// Free-text name (e.g. the preset it came from).
    pub name: String,
    /// Reference temperature T_ref of the thermal polynomials, °C.
    pub t_ref_c: f64,
    /// Temperature range [min, max] the thermal polynomials are valid over, °C.
    pub valid_range_c: [f64; 2],
    /// Gyro triad.
    pub gyro: GyroErrors,
    /// Accelerometer triad.
    pub accel: AccelErrors,
    /// Reported temperature.
    pub temperature_sensor: TemperatureSensor,
    /// Flicker (bias-instability) synthesis settings of the noise generator.
    pub flicker: FlickerConfig,
}

impl Default for SensorConfig {
    fn default() -> Self {
        SensorConfig {
            name: String::new(),
            t_ref_c: 25.0,
            valid_range_c: [-40.0, 85.0],
            gyro: GyroErrors::default(),
            accel: AccelErrors::default(),
            temperature_sensor: TemperatureSensor::default(),
            flicker: FlickerConfig::default(),
        }
    }
}

impl SensorConfig {
    /// Replace the six axes' stochastic terms by the fitted terms of a noise-model file
    /// (channels `gyro_x` … `acc_z`, see [`CHANNEL_NAMES`]). A missing channel, or one
    /// whose quantity is the wrong kind, is an error.
    pub fn apply_noise_model(&mut self, model: &NoiseModel) -> Result<(), SensorSimError> {
        for (a, name) in CHANNEL_NAMES.iter().enumerate() {
            let ch = model
                .channel(name)
                .ok_or_else(|| SensorSimError::MissingChannel {
                    name: name.to_string(),
                    present: model
                        .channels
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                })?;
            let want = if a < 3 {
                Quantity::AngularRate
            } else {
                Quantity::SpecificForce
            };
            if ch.quantity != want && ch.quantity != Quantity::Other {
                return Err(SensorSimError::invalid(
                    format!("noise model channel '{name}' ({:?})", ch.quantity),
                    format!("expected {want:?}"),
                ));
            }
            let n = AxisNoise::from_fit(&ch.fit);
            if a < 3 {
                self.gyro.noise[a] = n;
            } else {
                self.accel.noise[a - 3] = n;
            }
        }
        Ok(())
    }

    /// The same sensor with every random term removed (noise, turn-on bias, output and
    /// temperature quantization, temperature-sensor noise): the deterministic part only.
    pub fn deterministic_only(&self) -> SensorConfig {
        let mut c = self.clone();
        c.gyro.noise = Default::default();
        c.accel.noise = Default::default();
        c.gyro.turn_on_bias_sigma_rad_s = [0.0; 3];
        c.accel.turn_on_bias_sigma_m_s2 = [0.0; 3];
        c.gyro.rate_lsb_rad_s = 0.0;
        c.gyro.increment_lsb_rad = 0.0;
        c.accel.rate_lsb_m_s2 = 0.0;
        c.accel.increment_lsb_m_s = 0.0;
        c.temperature_sensor.noise_sigma_c = 0.0;
        c.temperature_sensor.lsb_c = 0.0;
        c
    }

    /// The same sensor with white noise as its only noise term: bias instability, rate
    /// random walk, quantization noise, Gauss–Markov terms and output quantization
    /// removed; turn-on biases and every deterministic term kept.
    pub fn without_slow_noise(&self) -> SensorConfig {
        let mut c = self.clone();
        for n in c.gyro.noise.iter_mut().chain(c.accel.noise.iter_mut()) {
            n.bias_instability = 0.0;
            n.rate_random_walk = 0.0;
            n.quantization = 0.0;
            n.gauss_markov = None;
        }
        c.accel.rate_lsb_m_s2 = 0.0;
        c.gyro.rate_lsb_rad_s = 0.0;
        c
    }

    /// The same sensor's stochastic terms only (no biases, scale factors, misalignment,
    /// g-sensitivity, thermal dependence or quantization).
    pub fn noise_only(&self) -> SensorConfig {
        SensorConfig {
            name: format!("{} (noise only)", self.name),
            t_ref_c: self.t_ref_c,
            valid_range_c: self.valid_range_c,
            gyro: GyroErrors {
                noise: self.gyro.noise.clone(),
                ..Default::default()
            },
            accel: AccelErrors {
                noise: self.accel.noise.clone(),
                ..Default::default()
            },
            temperature_sensor: TemperatureSensor::default(),
            flicker: self.flicker,
        }
    }
}

/// The bias-instability and rate-random-walk terms of a simulated sensor's configuration
/// (SI), e.g. a preset's, as the slow-drift model of a thermal soak fit.
impl From<&SensorConfig> for crate::thermal::soak::SoakDrift {
    fn from(cfg: &SensorConfig) -> crate::thermal::soak::SoakDrift {
        use crate::thermal::soak::ChannelDrift;
        let ch = |n: &AxisNoise| ChannelDrift {
            bias_instability: n.bias_instability,
            rate_random_walk: n.rate_random_walk,
        };
        crate::thermal::soak::SoakDrift {
            accel: cfg.accel.noise.each_ref().map(ch),
            gyro: cfg.gyro.noise.each_ref().map(ch),
        }
    }
}

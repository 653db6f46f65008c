//! Named sensor classes for the error model ([`SensorConfig`]), selectable by name
//! (`"adi-like".parse::<Preset>()`).
//!
//! | preset | gyro N / B / K | accel N / B / K | thermal (over the valid range) | valid range |
//! |---|---|---|---|---|
//! | `adi-like` | 3 °/√h / 40 °/h / 160 °/h/√h | 0.13 m/s/√h / 200 µg / 1.3e-4 m/s²/√s | gyro bias swing 5.0 / 3.0 / 2.0 °/s, accel 0.94 / 0.60 / 0.40 m/s²; SF swing ≈ 2 % (gyro), 0.5 % (accel) | −25 … 70 °C |
//! | `adis16465-like` | 0.15 °/√h / 2 °/h / 8 °/h/√h | 0.012 m/s/√h / 3.6 µg / 4e-6 m/s²/√s | bias ≈ ±0.1 °/s, ±1.5 mg; SF ≈ ±0.1 % | −40 … 85 °C |
//! | `consumer` | 0.17 °/√h / 8 °/h / 40 °/h/√h | 0.041 m/s/√h / 40 µg / 3e-5 m/s²/√s | bias 0.005 °/s/°C, 0.15 mg/°C; SF 50 ppm/°C | −40 … 85 °C |
//! | `tactical` | 0.05 °/√h / 0.3 °/h / 0.5 °/h/√h | 0.02 m/s/√h / 20 µg / 1e-6 m/s²/√s | bias 0.01 °/h/°C, 2 µg/°C; SF 1 ppm/°C | −40 … 85 °C |
//!
//! (N: ARW/VRW density, B: bias instability, K: rate random walk.) Each preset's function
//! documents every number and where it comes from. Rate random walk is rarely in a data
//! sheet; where it is not, K is set so that its +½ slope crosses the bias-instability floor
//! at τ of a few hundred seconds, i.e. it is observable in an 18-h static log (as in the
//! `driftless demo` truth).

use std::fmt;
use std::str::FromStr;

use driftless_model::units::{
    DEG, DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MICRO_G, MILLI_G,
    STANDARD_GRAVITY,
};

use super::sensor::{AccelErrors, AxisNoise, GyroErrors, SensorConfig, TemperatureSensor};
use super::sensor_error::SensorSimError;

/// A named sensor class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Preset {
    /// The seed paper's custom ADI MEMS triad (University of Calgary MMSS group, 2005).
    AdiLike,
    /// Analog Devices ADIS16465-1 class (industrial MEMS IMU).
    Adis16465Like,
    /// Consumer MEMS IMU chip (TDK InvenSense ICM-42688-P / ICM-45686 class).
    Consumer,
    /// Tactical-grade IMU.
    Tactical,
}

impl Preset {
    /// Every preset, in documentation order.
    pub const ALL: [Preset; 4] = [
        Preset::AdiLike,
        Preset::Adis16465Like,
        Preset::Consumer,
        Preset::Tactical,
    ];

    /// The name `FromStr` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Preset::AdiLike => "adi-like",
            Preset::Adis16465Like => "adis16465-like",
            Preset::Consumer => "consumer",
            Preset::Tactical => "tactical",
        }
    }

    /// The preset's sensor configuration.
    pub fn config(self) -> SensorConfig {
        match self {
            Preset::AdiLike => adi_like(),
            Preset::Adis16465Like => adis16465_like(),
            Preset::Consumer => consumer(),
            Preset::Tactical => tactical(),
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = SensorSimError;

    /// Exact preset name (ASCII case-insensitive, `_` accepted for `-`).
    fn from_str(s: &str) -> Result<Preset, SensorSimError> {
        let want = s.trim().to_ascii_lowercase().replace('_', "-");
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == want)
            .ok_or_else(|| SensorSimError::UnknownPreset {
                name: s.to_string(),
                valid: Preset::ALL.map(Preset::name).join(", "),
            })
    }
}

/// 1 g (standard gravity), m/s² — for "per g" data-sheet figures.
const G: f64 = STANDARD_GRAVITY;

fn noise3(n: f64, b: f64, k: f64) -> [AxisNoise; 3] {
    let a = AxisNoise {
        white: n,
        bias_instability: b,
        rate_random_walk: k,
        ..Default::default()
    };
    [a.clone(), a.clone(), a]
}

fn scaled(c: &[f64], unit: f64) -> Vec<f64> {
    c.iter().map(|v| v * unit).collect()
}

/// **`adi-like`**: the seed paper's "ADI MEMS IMU", a custom triad of Analog Devices
/// MEMS sensors built by the MMSS group (University of Calgary), calibrated in a chamber
/// at −25 … 70 °C in 5 °C steps, logged at 100 Hz through a 16-bit A/D card.
///
/// * **Thermal** (valid −25 … 70 °C, T_ref = 25 °C, cubics as in the paper's eqs. 1–2):
///   the paper's text gives only magnitudes — accelerometer bias variations "may reach
///   about 0.94 m/s²" and gyro biases "drifts of 5 deg/s" over −25 … 70 °C (§4, §5); the
///   curves of its Figs. 3–4 are not legible in the available text. The cubics below are
///   therefore *synthetic shapes* scaled so that the worst axis swings (max − min over the
///   range) by exactly those amounts: accel x/y/z 0.94 / 0.60 / 0.40 m/s², gyro x/y/z
///   5.0 / 3.0 / 2.0 °/s (the unit test `adi_like_matches_the_paper_magnitudes` checks
///   this). Scale-factor errors vary by ≈ 2 % (gyros) and ≈ 0.5 % (accelerometers) over
///   the range — an assumption of this class of 2005 analog MEMS parts, the paper gives
///   no number.
/// * **Noise**: the paper defers its Allan results to Hou (2004), not available here.
///   Values typical of the Analog Devices parts of that time: gyro rate noise
///   0.05 °/s/√Hz (ADXRS150-class data sheet) → N = 3 °/√h; B = 40 °/h; K = 160 °/h/√h.
///   Accelerometer noise ≈ 225 µg/√Hz (ADXL-class) → N ≈ 0.13 m/s/√h; B = 200 µg;
///   K = 1.3e-4 m/s²/√s. B and K are representative assumptions, not paper values.
/// * **Deterministic**: bias at 25 °C 0.3 / −0.5 / 0.2 °/s and 0.15 / −0.10 / 0.20 m/s²;
///   turn-on σ 0.1 °/s and 5 mg; scale-factor errors at 25 °C of a few 1e-3;
///   misalignment of a few mrad (hand-assembled triad); gyro g-sensitivity 0.2 °/s/g on
///   the sensing axis and 0.05 °/s/g across (ADXRS150-class data sheet order).
/// * **Quantization**: 16-bit A/D over ±10 V (the paper's NI card; the ±10 V input range
///   is an assumption): 0.305 mV/LSB, i.e. with 12.5 mV/(°/s) and 250 mV/g sensor
///   sensitivities 0.0244 °/s and 1.22 mg per LSB on rate samples. Increments: none (the
///   card samples rates). Temperature reported to 0.1 °C.
pub(crate) fn adi_like() -> SensorConfig {
    let lsb_v = 20.0 / 65536.0;
    let gyro = GyroErrors {
        turn_on_bias_sigma_rad_s: [0.1 * DEG; 3],
        bias_poly_rad_s: [
            scaled(&[0.3, -0.0407, -1.36e-3, 2.72e-5], DEG),
            scaled(&[-0.5, 0.0363, 9.07e-4, -1.81e-5], DEG),
            scaled(&[0.2, -0.0211, 6.32e-4, 1.68e-5], DEG),
        ],
        scale_factor_poly: [
            vec![5e-3, -2.0e-4, 1.0e-6],
            vec![-8e-3, 1.6e-4, 1.5e-6, -2e-8],
            vec![3e-3, -1.8e-4, -1.0e-6],
        ],
        misalignment_rad: [[0.0, 3e-3, -5e-3], [2e-3, 0.0, 4e-3], [-6e-3, 1e-3, 0.0]],
        g_sensitivity_rad_s_per_m_s2: [
            [0.2 * DEG / G, 0.05 * DEG / G, 0.0],
            [0.0, 0.2 * DEG / G, -0.05 * DEG / G],
            [0.05 * DEG / G, 0.0, 0.2 * DEG / G],
        ],
        noise: noise3(
            3.0 * DEG_PER_SQRT_H,
            40.0 * DEG_PER_H,
            160.0 * DEG_PER_H_PER_SQRT_H,
        ),
        rate_lsb_rad_s: lsb_v / 12.5e-3 * DEG,
        increment_lsb_rad: 0.0,
    };
    let accel = AccelErrors {
        turn_on_bias_sigma_m_s2: [5.0 * MILLI_G; 3],
        bias_poly_m_s2: [
            vec![0.15, 0.0132, 1.98e-4, -2.48e-6],
            vec![-0.10, -8.65e-3, 1.04e-4, 1.73e-6],
            vec![0.20, 2.69e-3, -7.19e-5, 4.49e-7],
        ],
        scale_factor_poly: [
            vec![3e-3, 5e-5, 2e-7],
            vec![-2e-3, -4e-5, 3e-7],
            vec![4e-3, 3e-5, -2e-7],
        ],
        misalignment_rad: [[0.0, -2e-3, 3e-3], [1e-3, 0.0, -4e-3], [5e-3, 2e-3, 0.0]],
        noise: noise3(0.13 * M_PER_S_PER_SQRT_H, 200.0 * MICRO_G, 1.3e-4),
        rate_lsb_m_s2: lsb_v / 0.25 * G,
        increment_lsb_m_s: 0.0,
    };
    SensorConfig {
        name: "adi-like".into(),
        t_ref_c: 25.0,
        valid_range_c: [-25.0, 70.0],
        gyro,
        accel,
        temperature_sensor: TemperatureSensor {
            lsb_c: 0.1,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// **`adis16465-like`**: Analog Devices ADIS16465-1 (±125 °/s, ±8 g), factory calibrated
/// over −40 … 85 °C (the valid range here).
///
/// Source: ADIS16465 data sheet (Analog Devices, *Precision MEMS IMU Module*, Rev. C).
/// Confirmed from the data sheet's feature list: gyro in-run bias stability 2 °/h and
/// ARW 0.15 °/√h (ADIS16465-1), ±0.05° axis-to-axis misalignment, accelerometer in-run
/// bias stability 3.6 µg, ±8 g, calibration range −40 … 85 °C. VRW 0.012 m/s/√h is the
/// Table 1 value used by `driftless demo`. The remaining numbers are Table 1 orders of
/// magnitude as recalled (not re-verified against the PDF here — treat them as
/// class-typical): gyro bias over temperature ≈ ±0.1 °/s, linear-acceleration effect
/// ≈ 0.002 °/s/g, sensitivity error ≈ ±0.1 % over temperature; accelerometer bias over
/// temperature ≈ ±1.5 mg, sensitivity ≈ ±0.1 %. Rate random walk (not in the data sheet):
/// 8 °/h/√h and 4e-6 m/s²/√s as in the demo truth. Output LSBs: the 32-bit registers —
/// gyro 0.00625 °/s / 2¹⁶, accel 0.25 mg / 2¹⁶, delta angle 360° / 2³¹, delta velocity
/// 100 m/s / 2³¹; temperature 0.1 °C/LSB. Turn-on σ 0.05 °/s and 1 mg (assumed; the
/// factory calibration removes the bias at 25 °C, so c₀ = 0).
pub fn adis16465_like() -> SensorConfig {
    let mis = 0.05 * DEG;
    let gyro = GyroErrors {
        turn_on_bias_sigma_rad_s: [0.05 * DEG; 3],
        bias_poly_rad_s: [
            scaled(&[0.0, 1.0e-3, 2.0e-5, -4.0e-7], DEG),
            scaled(&[0.0, -8.0e-4, 1.5e-5, 3.0e-7], DEG),
            scaled(&[0.0, 6.0e-4, -2.0e-5, 2.0e-7], DEG),
        ],
        scale_factor_poly: [
            vec![0.0, 1.0e-5, 1.0e-7],
            vec![0.0, -1.2e-5, 8.0e-8],
            vec![0.0, 8.0e-6, -1.0e-7],
        ],
        misalignment_rad: [
            [0.0, 0.6 * mis, -0.4 * mis],
            [0.3 * mis, 0.0, 0.8 * mis],
            [-0.7 * mis, 0.2 * mis, 0.0],
        ],
        g_sensitivity_rad_s_per_m_s2: [
            [0.002 * DEG / G, 0.0, 0.0],
            [0.0, 0.002 * DEG / G, 0.0],
            [0.0, 0.0, 0.002 * DEG / G],
        ],
        noise: noise3(
            0.15 * DEG_PER_SQRT_H,
            2.0 * DEG_PER_H,
            8.0 * DEG_PER_H_PER_SQRT_H,
        ),
        rate_lsb_rad_s: 0.00625 * DEG / 65536.0,
        increment_lsb_rad: 360.0 * DEG / 2f64.powi(31),
    };
    let accel = AccelErrors {
        turn_on_bias_sigma_m_s2: [1.0 * MILLI_G; 3],
        bias_poly_m_s2: [
            vec![0.0, 1.5e-5 * G, 3.0e-7 * G, -5.0e-9 * G],
            vec![0.0, -1.2e-5 * G, 2.0e-7 * G, 4.0e-9 * G],
            vec![0.0, 1.0e-5 * G, -3.0e-7 * G, 3.0e-9 * G],
        ],
        scale_factor_poly: [
            vec![0.0, 8.0e-6, 5.0e-8],
            vec![0.0, -6.0e-6, 6.0e-8],
            vec![0.0, 1.0e-5, -4.0e-8],
        ],
        misalignment_rad: [
            [0.0, -0.5 * mis, 0.7 * mis],
            [0.4 * mis, 0.0, -0.3 * mis],
            [0.6 * mis, -0.8 * mis, 0.0],
        ],
        noise: noise3(0.012 * M_PER_S_PER_SQRT_H, 3.6 * MICRO_G, 4.0e-6),
        rate_lsb_m_s2: 0.25 * MILLI_G / 65536.0,
        increment_lsb_m_s: 100.0 / 2f64.powi(31),
    };
    SensorConfig {
        name: "adis16465-like".into(),
        t_ref_c: 25.0,
        valid_range_c: [-40.0, 85.0],
        gyro,
        accel,
        temperature_sensor: TemperatureSensor {
            lsb_c: 0.1,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// **`consumer`**: a consumer MEMS IMU chip of the TDK InvenSense ICM-42688-P /
/// ICM-45686 class (±2000 °/s, ±16 g), uncalibrated, operating range −40 … 85 °C.
///
/// Source: ICM-42688-P data sheet DS-000347 v1.7 (TDK InvenSense): gyro rate noise
/// 2.8 mdps/√Hz → N = 0.168 °/√h, accelerometer noise 70 µg/√Hz → N = 0.041 m/s/√h
/// (feature list, confirmed); zero-rate output ±0.5 °/s and its temperature drift
/// ±0.005 °/s/°C, sensitivity tolerance ±0.5 %, accelerometer offset tempco
/// ±0.15 mg/°C (Table 1/2 typicals, as recalled). Not in the data sheet, typical of
/// published Allan analyses of this class: gyro B = 8 °/h, accel B = 40 µg; K set to be
/// observable in 18 h (40 °/h/√h, 3e-5 m/s²/√s). Turn-on σ 0.5 °/s and 20 mg;
/// sensitivity tempco 50 ppm/°C (assumed, within the data sheet's ±0.005 %/°C order);
/// cross-axis sensitivity ±1 % → misalignment up to 0.01 rad. g-sensitivity 0.1 °/s/g
/// (assumed). 16-bit outputs: 2000/32768 °/s and 16 g/32768 per LSB; no increments;
/// temperature 1/132.48 °C per LSB (rounded here to 0.01 °C).
pub fn consumer() -> SensorConfig {
    let gyro = GyroErrors {
        turn_on_bias_sigma_rad_s: [0.5 * DEG; 3],
        bias_poly_rad_s: [
            scaled(&[0.0, 0.005], DEG),
            scaled(&[0.0, -0.004, 2e-5], DEG),
            scaled(&[0.0, 0.003, -1e-5], DEG),
        ],
        scale_factor_poly: [vec![3e-3, 5e-5], vec![-2e-3, -4e-5], vec![4e-3, 5e-5]],
        misalignment_rad: [[0.0, 8e-3, -5e-3], [6e-3, 0.0, 9e-3], [-7e-3, 4e-3, 0.0]],
        g_sensitivity_rad_s_per_m_s2: [
            [0.1 * DEG / G, 0.0, 0.0],
            [0.0, 0.1 * DEG / G, 0.0],
            [0.0, 0.0, 0.1 * DEG / G],
        ],
        noise: noise3(2.8e-3 * DEG, 8.0 * DEG_PER_H, 40.0 * DEG_PER_H_PER_SQRT_H),
        rate_lsb_rad_s: 2000.0 / 32768.0 * DEG,
        increment_lsb_rad: 0.0,
    };
    let accel = AccelErrors {
        turn_on_bias_sigma_m_s2: [20.0 * MILLI_G; 3],
        bias_poly_m_s2: [
            vec![0.0, 0.15 * MILLI_G],
            vec![0.0, -0.12 * MILLI_G, 2e-3 * MILLI_G],
            vec![0.0, 0.10 * MILLI_G],
        ],
        scale_factor_poly: [vec![2e-3, 5e-5], vec![-3e-3, -5e-5], vec![1e-3, 4e-5]],
        misalignment_rad: [[0.0, -6e-3, 8e-3], [5e-3, 0.0, -7e-3], [9e-3, -4e-3, 0.0]],
        noise: noise3(70.0 * MICRO_G, 40.0 * MICRO_G, 3.0e-5),
        rate_lsb_m_s2: 16.0 * G / 32768.0,
        increment_lsb_m_s: 0.0,
    };
    SensorConfig {
        name: "consumer".into(),
        t_ref_c: 25.0,
        valid_range_c: [-40.0, 85.0],
        gyro,
        accel,
        temperature_sensor: TemperatureSensor {
            lsb_c: 0.01,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// **`tactical`**: a tactical-grade IMU (ring-laser / FOG or high-end MEMS, e.g. the
/// Honeywell HG1700 class), factory compensated.
///
/// Source: the tactical grade of Groves, *Principles of GNSS, Inertial, and Multisensor
/// Integrated Navigation Systems*, 2nd ed. (2013), §4.4 (accelerometer biases 0.1 … 1 mg,
/// gyro biases 1 … 10 °/h, ARW of order 0.05 … 0.5 °/√h, scale factors 100 … 1000 ppm);
/// representative values within those ranges: gyro turn-on σ 1 °/h, N = 0.05 °/√h,
/// B = 0.3 °/h, K = 0.5 °/h/√h, scale factor 150 ppm, misalignment 0.1 mrad,
/// g-sensitivity 1 °/h/g; accelerometer turn-on σ 0.3 mg, N = 0.02 m/s/√h, B = 20 µg,
/// K = 1e-6 m/s²/√s, scale factor 300 ppm. Residual thermal dependence after factory
/// compensation (assumed): 0.01 °/h/°C, 2 µg/°C, 1 ppm/°C. Increment outputs with
/// 2⁻³¹-class LSBs (1e-9 rad, 1e-8 m/s); temperature 0.01 °C.
pub fn tactical() -> SensorConfig {
    let gyro = GyroErrors {
        turn_on_bias_sigma_rad_s: [1.0 * DEG_PER_H; 3],
        bias_poly_rad_s: [
            scaled(&[0.0, 0.01], DEG_PER_H),
            scaled(&[0.0, -0.01], DEG_PER_H),
            scaled(&[0.0, 0.008], DEG_PER_H),
        ],
        scale_factor_poly: [vec![150e-6, 1e-6], vec![-150e-6, -1e-6], vec![100e-6, 1e-6]],
        misalignment_rad: [[0.0, 1e-4, -1e-4], [1e-4, 0.0, 1e-4], [-1e-4, 1e-4, 0.0]],
        g_sensitivity_rad_s_per_m_s2: [
            [DEG_PER_H / G, 0.0, 0.0],
            [0.0, DEG_PER_H / G, 0.0],
            [0.0, 0.0, DEG_PER_H / G],
        ],
        noise: noise3(
            0.05 * DEG_PER_SQRT_H,
            0.3 * DEG_PER_H,
            0.5 * DEG_PER_H_PER_SQRT_H,
        ),
        rate_lsb_rad_s: 0.0,
        increment_lsb_rad: 1e-9,
    };
    let accel = AccelErrors {
        turn_on_bias_sigma_m_s2: [0.3 * MILLI_G; 3],
        bias_poly_m_s2: [
            vec![0.0, 2.0 * MICRO_G],
            vec![0.0, -2.0 * MICRO_G],
            vec![0.0, 1.5 * MICRO_G],
        ],
        scale_factor_poly: [vec![300e-6, 1e-6], vec![-300e-6, -1e-6], vec![200e-6, 1e-6]],
        misalignment_rad: [[0.0, -1e-4, 1e-4], [1e-4, 0.0, -1e-4], [1e-4, -1e-4, 0.0]],
        noise: noise3(0.02 * M_PER_S_PER_SQRT_H, 20.0 * MICRO_G, 1.0e-6),
        rate_lsb_m_s2: 0.0,
        increment_lsb_m_s: 1e-8,
    };
    SensorConfig {
        name: "tactical".into(),
        t_ref_c: 25.0,
        valid_range_c: [-40.0, 85.0],
        gyro,
        accel,
        temperature_sensor: TemperatureSensor {
            lsb_c: 0.01,
            ..Default::default()
        },
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::super::sensor::SensorModel;
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_lists_valid() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>().unwrap(), p);
            assert_eq!(p.to_string(), p.name());
            SensorModel::new(p.config()).unwrap();
        }
        assert_eq!(
            "ADIS16465_like".parse::<Preset>().unwrap(),
            Preset::Adis16465Like
        );
        let e = "navigation-grade"
            .parse::<Preset>()
            .unwrap_err()
            .to_string();
        assert!(e.contains("navigation-grade"), "{e}");
        assert!(
            e.contains("adi-like, adis16465-like, consumer, tactical"),
            "{e}"
        );
    }

    /// The worst-axis bias swings over −25 … 70 °C are the paper's 0.94 m/s² and 5 °/s.
    #[test]
    fn adi_like_matches_the_paper_magnitudes() {
        let m = SensorModel::new(adi_like()).unwrap();
        let swing = |axis: usize| {
            let v: Vec<f64> = (0..=950)
                .map(|i| m.bias_at(axis, -25.0 + 0.1 * i as f64))
                .collect();
            let max = v.iter().cloned().fold(f64::MIN, f64::max);
            let min = v.iter().cloned().fold(f64::MAX, f64::min);
            max - min
        };
        let gyro: Vec<f64> = (0..3).map(|a| swing(a) / DEG).collect();
        let acc: Vec<f64> = (3..6).map(swing).collect();
        assert!((gyro[0] - 5.0).abs() < 0.05, "{gyro:?}");
        assert!((acc[0] - 0.94).abs() < 0.01, "{acc:?}");
        assert!(gyro.iter().all(|&s| s <= 5.05) && acc.iter().all(|&s| s <= 0.95));
    }

    #[test]
    fn adis16465_headline_numbers() {
        let c = adis16465_like();
        assert!((c.gyro.noise[0].white / DEG_PER_SQRT_H - 0.15).abs() < 1e-12);
        assert!((c.gyro.noise[0].bias_instability / DEG_PER_H - 2.0).abs() < 1e-12);
        assert!((c.accel.noise[0].bias_instability / MICRO_G - 3.6).abs() < 1e-12);
        assert!((c.accel.noise[0].white / M_PER_S_PER_SQRT_H - 0.012).abs() < 1e-12);
        let mis = c
            .gyro
            .misalignment_rad
            .iter()
            .flatten()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(mis <= 0.05 * DEG + 1e-15);
    }
}

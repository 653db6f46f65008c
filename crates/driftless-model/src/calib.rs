//! Room-temperature calibration of one sensor triad and of a six-axis IMU — the model
//! the calibration module estimates and a device applies, sample by sample:
//!
//! ```text
//! calibrated = M · (raw − b)
//! ```
//!
//! with `raw` in the sensor's output units (counts, or SI for an IMU that already
//! scales), `b` the bias in those units and `M` (3 × 3) scaling to SI (m/s² or rad/s)
//! while correcting scale-factor errors and axis misalignment / non-orthogonality.
//! This is the convention of `driftless calibrate --json` and of imu_tk
//! (Tedaldi et al., ICRA 2014: `T·K·(raw − b)`, whose product T·K is M). Thermal
//! dependence is added on top by the thermal model.

use crate::linalg::{Mat3, Vec3, sub};

/// `calibrated = matrix · (raw − bias)` for one triad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadCalibration {
    /// Bias b, raw units.
    pub bias: Vec3,
    /// M: raw units → SI, with scale and misalignment.
    pub matrix: Mat3,
}

impl TriadCalibration {
    /// No correction: zero bias, identity matrix (raw already in SI).
    pub const IDENTITY: TriadCalibration = TriadCalibration {
        bias: [0.0; 3],
        matrix: Mat3::IDENTITY,
    };

    /// Applies the calibration to one raw sample.
    #[inline]
    pub fn apply(&self, raw: Vec3) -> Vec3 {
        self.matrix.mul_vec(sub(raw, self.bias))
    }

    /// The raw sample that calibrates to `si` (None when M is singular).
    pub fn raw_of(&self, si: Vec3) -> Option<Vec3> {
        let r = self.matrix.inverse()?.mul_vec(si);
        Some(crate::linalg::add(r, self.bias))
    }
}

/// Both triads of a six-axis IMU.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuCalibration {
    /// Accelerometer: raw → m/s².
    pub accel: TriadCalibration,
    /// Gyroscope: raw → rad/s.
    pub gyro: TriadCalibration,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apply_and_invert() {
        let c = TriadCalibration {
            bias: [32768.0, 32700.0, 32800.0],
            matrix: Mat3([
                [1e-3, 2e-6, 0.0],
                [0.0, 1.01e-3, -3e-6],
                [1e-6, 0.0, 0.99e-3],
            ]),
        };
        let raw = [33000.0, 31000.0, 42000.0];
        let si = c.apply(raw);
        let back = c.raw_of(si).unwrap();
        for k in 0..3 {
            assert!((back[k] - raw[k]).abs() < 1e-9);
        }
        assert_eq!(
            TriadCalibration::IDENTITY.apply([1.0, 2.0, 3.0]),
            [1.0, 2.0, 3.0]
        );
    }
}

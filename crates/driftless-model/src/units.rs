//! Unit constants. SI inside (rad, s, m); these convert display/file units at the edges.

/// Degrees to radians.
pub const DEG: f64 = core::f64::consts::PI / 180.0;
/// One hour in seconds.
pub const HOUR_S: f64 = 3600.0;
/// Standard gravity (CGPM 1901), m/s², used only to convert `g`/`mg` units, never as local gravity.
pub const STANDARD_GRAVITY: f64 = 9.806_65;
/// 1 deg/s in rad/s.
pub const DEG_PER_S: f64 = DEG;
/// 1 deg/h in rad/s.
pub const DEG_PER_H: f64 = DEG / HOUR_S;
/// 1 deg/√h in rad/√s (angle random walk density).
pub const DEG_PER_SQRT_H: f64 = DEG / 60.0;
/// 1 deg/h/√h in rad/s/√s (rate random walk density).
pub const DEG_PER_H_PER_SQRT_H: f64 = DEG / (HOUR_S * 60.0);
/// 1 m/s/√h in m/s/√s (velocity random walk density).
pub const M_PER_S_PER_SQRT_H: f64 = 1.0 / 60.0;
/// 1 mg in m/s².
pub const MILLI_G: f64 = STANDARD_GRAVITY * 1e-3;
/// 1 µg in m/s².
pub const MICRO_G: f64 = STANDARD_GRAVITY * 1e-6;
/// 0 °C in kelvin (°C = K − 273.15).
pub const KELVIN_OFFSET: f64 = 273.15;

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn arw_conversion_matches_definition() {
        // 1 deg/sqrt(h) = (pi/180) rad / sqrt(3600 s) = (pi/180)/60 rad/sqrt(s)
        let v = DEG / HOUR_S.sqrt();
        assert!((v - DEG_PER_SQRT_H).abs() < 1e-18);
        let k = DEG / HOUR_S / HOUR_S.sqrt();
        assert!((k - DEG_PER_H_PER_SQRT_H).abs() < 1e-20);
    }
}

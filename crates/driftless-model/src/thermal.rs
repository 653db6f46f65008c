//! Thermal polynomials: a sensor parameter as a polynomial in the temperature difference
//! ΔT = T − T_ref, valid over a stated temperature range.
//!
//! The seed paper (§3.3, eqs. 1–2) models each axis's bias and scale factor about the room
//! temperature t₀ = 25 °C as cubics fitted by least squares to soak-test results:
//!
//! ```text
//! b(t) = b(t₀) + c₁(t − t₀) + c₂(t − t₀)² + c₃(t − t₀)³
//! S(t) = S(t₀) + d₁(t − t₀) + d₂(t − t₀)² + d₃(t − t₀)³
//! ```
//!
//! [`ThermalPoly`] holds such a polynomial up to order [`MAX_ORDER`] (= 5) in a fixed
//! array, so it is `Copy`, allocation-free and usable on a device (the real-time
//! compensation evaluates the same type the simulator uses to generate the errors).
//! The coefficients carry the unit of the modelled quantity per °C^k (e.g. rad/s/°C² for
//! c₂ of a gyro bias; 1/°C for d₁ of a dimensionless scale-factor error); the polynomial
//! itself is unit-agnostic.
//!
//! A fitted polynomial is only trustworthy inside the temperature range it was fitted
//! over (cubics extrapolate wildly — a known pain with autopilot thermal calibrations), so
//! the type carries that range: [`ThermalPoly::eval_checked`] refuses to extrapolate,
//! [`ThermalPoly::eval_clamped`] holds the end values outside it (the PX4/ArduPilot
//! behaviour), and [`ThermalPoly::eval`] evaluates anywhere.

use core::fmt;

/// Highest supported polynomial order (coefficients c₀ … c₅).
pub const MAX_ORDER: usize = 5;

/// Why a [`ThermalPoly`] could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThermalPolyError {
    /// More than `MAX_ORDER + 1` coefficients were given (the count).
    TooManyCoefficients(usize),
    /// A coefficient is NaN or infinite (its index).
    NonFiniteCoefficient(usize),
    /// The reference temperature is NaN or infinite.
    NonFiniteReference,
    /// The valid range is not finite with min ≤ max.
    BadRange,
}

impl fmt::Display for ThermalPolyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalPolyError::TooManyCoefficients(n) => write!(
                f,
                "{n} coefficients given, at most {} (order {MAX_ORDER}) supported",
                MAX_ORDER + 1
            ),
            ThermalPolyError::NonFiniteCoefficient(k) => {
                write!(f, "coefficient c{k} is not finite")
            }
            ThermalPolyError::NonFiniteReference => {
                write!(f, "reference temperature is not finite")
            }
            ThermalPolyError::BadRange => {
                write!(f, "valid range must be finite with min <= max")
            }
        }
    }
}

impl core::error::Error for ThermalPolyError {}

/// p(T) = Σ_{k=0}^{5} c_k (T − T_ref)^k, valid for T_min ≤ T ≤ T_max (°C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalPoly {
    t_ref_c: f64,
    coeffs: [f64; MAX_ORDER + 1],
    t_min_c: f64,
    t_max_c: f64,
}

impl ThermalPoly {
    /// Polynomial with coefficients `coeffs[k]` of ΔT^k about `t_ref_c`, valid over
    /// [`t_min_c`, `t_max_c`]. Missing high-order coefficients are zero.
    pub fn new(
        t_ref_c: f64,
        coeffs: &[f64],
        t_min_c: f64,
        t_max_c: f64,
    ) -> Result<ThermalPoly, ThermalPolyError> {
        if coeffs.len() > MAX_ORDER + 1 {
            return Err(ThermalPolyError::TooManyCoefficients(coeffs.len()));
        }
        if !t_ref_c.is_finite() {
            return Err(ThermalPolyError::NonFiniteReference);
        }
        if !(t_min_c.is_finite() && t_max_c.is_finite() && t_min_c <= t_max_c) {
            return Err(ThermalPolyError::BadRange);
        }
        let mut c = [0.0; MAX_ORDER + 1];
        for (k, (dst, &src)) in c.iter_mut().zip(coeffs).enumerate() {
            if !src.is_finite() {
                return Err(ThermalPolyError::NonFiniteCoefficient(k));
            }
            *dst = src;
        }
        Ok(ThermalPoly {
            t_ref_c,
            coeffs: c,
            t_min_c,
            t_max_c,
        })
    }

    /// The constant `c0` (no temperature dependence), valid at every finite temperature.
    pub const fn constant(c0: f64) -> ThermalPoly {
        ThermalPoly {
            t_ref_c: 0.0,
            coeffs: [c0, 0.0, 0.0, 0.0, 0.0, 0.0],
            t_min_c: f64::MIN,
            t_max_c: f64::MAX,
        }
    }

    /// Reference temperature T_ref, °C.
    pub fn t_ref_c(&self) -> f64 {
        self.t_ref_c
    }

    /// Coefficients c₀ … c₅ of ΔT^k.
    pub fn coeffs(&self) -> &[f64; MAX_ORDER + 1] {
        &self.coeffs
    }

    /// Valid range (T_min, T_max), °C.
    pub fn range_c(&self) -> (f64, f64) {
        (self.t_min_c, self.t_max_c)
    }

    /// Whether `t_c` lies in the valid range (NaN does not).
    pub fn in_range(&self, t_c: f64) -> bool {
        t_c >= self.t_min_c && t_c <= self.t_max_c
    }

    /// Order: index of the highest non-zero coefficient (0 for a constant or zero).
    pub fn order(&self) -> usize {
        self.coeffs.iter().rposition(|&c| c != 0.0).unwrap_or(0)
    }

    /// p(t_c) by Horner's rule, anywhere (extrapolates outside the valid range).
    #[inline]
    pub fn eval(&self, t_c: f64) -> f64 {
        let d = t_c - self.t_ref_c;
        let c = &self.coeffs;
        ((((c[5] * d + c[4]) * d + c[3]) * d + c[2]) * d + c[1]) * d + c[0]
    }

    /// p(t_c) inside the valid range, `None` outside it (and for NaN).
    #[inline]
    pub fn eval_checked(&self, t_c: f64) -> Option<f64> {
        if self.in_range(t_c) {
            Some(self.eval(t_c))
        } else {
            None
        }
    }

    /// p at `t_c` clamped into the valid range (end values held outside; NaN → T_ref
    /// clamped into the range).
    #[inline]
    pub fn eval_clamped(&self, t_c: f64) -> f64 {
        let t = if t_c.is_nan() { self.t_ref_c } else { t_c };
        self.eval(t.clamp(self.t_min_c, self.t_max_c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horner_matches_power_sum_and_range_is_enforced() {
        let c = [0.1, -2e-3, 3e-5, -4e-7, 5e-9, -6e-11];
        let p = ThermalPoly::new(25.0, &c, -40.0, 85.0).unwrap();
        for t in [-40.0, -3.5, 25.0, 61.0, 85.0] {
            let d: f64 = t - 25.0;
            let mut want = 0.0;
            let mut dk = 1.0;
            for ck in c {
                want += ck * dk;
                dk *= d;
            }
            assert!((p.eval(t) - want).abs() <= 1e-15 * want.abs().max(1.0));
            assert_eq!(p.eval_checked(t), Some(p.eval(t)));
        }
        assert_eq!(p.order(), 5);
        assert_eq!(p.eval_checked(85.000_001), None);
        assert_eq!(p.eval_checked(f64::NAN), None);
        assert_eq!(p.eval_clamped(200.0), p.eval(85.0));
        assert_eq!(p.eval_clamped(-200.0), p.eval(-40.0));
        assert_eq!(ThermalPoly::constant(2.5).eval(1e6), 2.5);
        assert_eq!(ThermalPoly::constant(2.5).order(), 0);
    }

    #[test]
    fn rejects_bad_input() {
        assert_eq!(
            ThermalPoly::new(25.0, &[0.0; 7], 0.0, 1.0),
            Err(ThermalPolyError::TooManyCoefficients(7))
        );
        assert_eq!(
            ThermalPoly::new(25.0, &[0.0, f64::NAN], 0.0, 1.0),
            Err(ThermalPolyError::NonFiniteCoefficient(1))
        );
        assert_eq!(
            ThermalPoly::new(25.0, &[0.0], 2.0, 1.0),
            Err(ThermalPolyError::BadRange)
        );
        assert_eq!(
            ThermalPoly::new(f64::INFINITY, &[0.0], 0.0, 1.0),
            Err(ThermalPolyError::NonFiniteReference)
        );
    }
}

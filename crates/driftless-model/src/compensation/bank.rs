//! Single-precision helpers of the compensation: the triad in f32, the bounds that keep
//! f32 deltas within tolerance, and the bank of precomputed temperature deltas.

use super::*;

/// raw − G·f (f64).
#[inline(always)]
pub(super) fn minus_g(raw: Vec3, g: &Mat3, f: Vec3) -> Vec3 {
    let gf = g.mul_vec(f);
    [raw[0] - gf[0], raw[1] - gf[1], raw[2] - gf[2]]
}

/// raw − G·f (f32).
#[inline(always)]
pub(super) fn minus_g32(raw: [f32; 3], g: &[[f32; 3]; 3], f: [f32; 3]) -> [f32; 3] {
    core::array::from_fn(|k| raw[k] - (g[k][0] * f[0] + g[k][1] * f[1] + g[k][2] * f[2]))
}

/// Effective f32 calibration of one triad at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Triad32 {
    pub(super) bias: [f32; 3],
    pub(super) m: [[f32; 3]; 3],
}

impl Triad32 {
    pub(super) fn from_f64(c: &TriadCalibration) -> Triad32 {
        let mut m = [[0.0f32; 3]; 3];
        for (dst, src) in m.iter_mut().zip(&c.matrix.0) {
            for (d, &s) in dst.iter_mut().zip(src) {
                *d = s as f32;
            }
        }
        Triad32 {
            bias: [c.bias[0] as f32, c.bias[1] as f32, c.bias[2] as f32],
            m,
        }
    }

    #[inline(always)]
    pub(super) fn apply(&self, raw: [f32; 3]) -> [f32; 3] {
        let r = [
            raw[0] - self.bias[0],
            raw[1] - self.bias[1],
            raw[2] - self.bias[2],
        ];
        let m = &self.m;
        [
            m[0][0] * r[0] + m[0][1] * r[1] + m[0][2] * r[2],
            m[1][0] * r[0] + m[1][1] * r[1] + m[1][2] * r[2],
            m[2][0] * r[0] + m[2][1] * r[1] + m[2][2] * r[2],
        ]
    }
}

/// Σ_j |c_j|·R^j with R the largest |T − T_ref| over `range_c`: a bound on |p(T)| there.
pub(super) fn poly_bound(p: &ThermalPoly, range_c: [f64; 2]) -> f64 {
    let r = (range_c[0] - p.t_ref_c())
        .abs()
        .max((range_c[1] - p.t_ref_c()).abs());
    p.coeffs()
        .iter()
        .rev()
        .fold(0.0, |acc, c| acc * r + c.abs())
}

pub(super) fn check_delta(
    p: &ThermalPoly,
    range_c: [f64; 2],
    max: f64,
) -> Result<(), CompensationError> {
    if p.coeffs()[0] != 0.0 {
        return Err(CompensationError::InvalidModel(
            "thermal deltas must be zero at T_ref (c0 = 0): the room calibration carries it",
        ));
    }
    let (lo, hi) = p.range_c();
    if lo > range_c[0] || hi < range_c[1] {
        return Err(CompensationError::InvalidModel(
            "the model's range must lie inside every polynomial's valid range",
        ));
    }
    // Guarantees that evaluation inside the range (and so under Clamp) cannot fail.
    let bound = poly_bound(p, range_c);
    if bound.is_nan() || bound >= max {
        return Err(CompensationError::InvalidModel(
            "a thermal delta is not bounded over the range (scale delta must stay below 1)",
        ));
    }
    Ok(())
}

/// Lanes of a [`DeltaBank`]: bias deltas gyro x, y, z, accelerometer x, y, z, then the
/// scale deltas in the same order.
pub(super) const LANES: usize = 12;

/// The 12 delta polynomials of a model in structure-of-arrays form, so that one
/// temperature evaluates all of them (and the six reciprocal scale factors) in loops the
/// compiler vectorises. Each lane is p(t_c) in the form (c₀ + c₁d) + d²(c₂ + c₃d) +
/// d⁴(c₄ + c₅d), d = t_c − T_ref — the same polynomial as [`ThermalPoly::eval`] with a
/// shorter dependency chain. Lanes of an absent triad are zero and ignored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct DeltaBank {
    pub(super) t_ref_c: [f64; LANES],
    pub(super) c: [[f64; LANES]; MAX_ORDER + 1],
    /// Every lane has c₄ = c₅ = 0 (the usual cubic model): skip the d⁴ term, which is
    /// exactly +0 then.
    pub(super) cubic: bool,
}

/// The evaluated deltas at one temperature: Δb per lane (gyro x, y, z, accel x, y, z)
/// and 1/(1 + Δs) per lane, with whether every 1 + Δs of the triad was finite and
/// non-zero.
pub(super) struct Deltas {
    pub(super) bias: [f64; 6],
    pub(super) inv_scale: [f64; 6],
    pub(super) ok: [bool; 2],
}

impl DeltaBank {
    pub(super) fn new(gyro: &Option<TriadThermal>, accel: &Option<TriadThermal>) -> DeltaBank {
        let mut bank = DeltaBank {
            t_ref_c: [0.0; LANES],
            c: [[0.0; LANES]; MAX_ORDER + 1],
            cubic: true,
        };
        for (base, th) in [(0, gyro), (3, accel)] {
            let Some(th) = th else { continue };
            let lanes = (0..3).map(|k| (base + k, &th.bias_delta[k]));
            let lanes = lanes.chain((0..3).map(|k| (6 + base + k, &th.scale_delta[k])));
            for (lane, p) in lanes {
                bank.t_ref_c[lane] = p.t_ref_c();
                for (row, &ck) in bank.c.iter_mut().zip(p.coeffs()) {
                    row[lane] = ck;
                }
            }
        }
        bank.cubic = bank.c[4..].iter().flatten().all(|&c| c == 0.0);
        bank
    }

    #[inline(always)]
    pub(super) fn eval(&self, t_c: f64) -> Deltas {
        let mut v = [0.0; LANES];
        let [c0, c1, c2, c3, c4, c5] = &self.c;
        if self.cubic {
            for l in 0..LANES {
                let d = t_c - self.t_ref_c[l];
                v[l] = (c0[l] + c1[l] * d) + d * d * (c2[l] + c3[l] * d);
            }
        } else {
            for l in 0..LANES {
                let d = t_c - self.t_ref_c[l];
                let d2 = d * d;
                let d4 = d2 * d2;
                v[l] = (c0[l] + c1[l] * d) + d2 * (c2[l] + c3[l] * d) + d4 * (c4[l] + c5[l] * d);
            }
        }
        let mut out = Deltas {
            bias: [0.0; 6],
            inv_scale: [0.0; 6],
            ok: [true; 2],
        };
        out.bias.copy_from_slice(&v[..6]);
        for l in 0..6 {
            let den = 1.0 + v[6 + l];
            out.ok[l / 3] &= den != 0.0 && den.is_finite() && v[l].is_finite();
            out.inv_scale[l] = 1.0 / den;
        }
        out
    }
}

/// Effective calibration of one triad from its evaluated bias deltas and reciprocal
/// scale factors; `t_c` is the reading, for the error.
#[inline(always)]
pub(super) fn triad_at(
    cal: &TriadCalibration,
    bias: &[f64],
    inv_scale: &[f64],
    ok: bool,
    t_c: f64,
) -> Result<TriadCalibration, CompensationError> {
    if !ok {
        return Err(CompensationError::SingularScale { t_c });
    }
    let mut out = *cal;
    for k in 0..3 {
        out.bias[k] += bias[k];
        for row in out.matrix.0.iter_mut() {
            row[k] *= inv_scale[k];
        }
    }
    if !out.bias.iter().all(|b| b.is_finite()) {
        return Err(CompensationError::SingularScale { t_c });
    }
    Ok(out)
}

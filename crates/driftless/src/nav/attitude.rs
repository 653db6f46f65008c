//! Attitude representations and the one convention the project uses.
//!
//! * Frames: navigation = local NED; body = forward-right-down.
//! * `c_bn` is the direction cosine matrix from body to navigation: v_n = C_bn·v_b.
//! * Quaternions are Hamilton (scalar first, q = [w, x, y, z], i² = j² = k² = ijk = −1);
//!   `q_bn` rotates body vectors into the navigation frame: v_n = q_bn ⊗ v_b ⊗ q_bn*.
//! * Euler angles (roll φ, pitch θ, yaw ψ) are the aerospace z-y-x sequence:
//!   C_bn = R_z(ψ)·R_y(θ)·R_x(φ) (Groves eqs. 2.22/2.24, Titterton & Weston §3.6).
//! * Rotation vectors φ (axis × angle) map to quaternions [cos(|φ|/2), sin(|φ|/2)·φ/|φ|]
//!   (Savage, *Strapdown Analytics*, §3.2.2; Shin 2005, eq. 2.48).

use driftless_model::linalg::{Mat3, Vec3, cross};

/// A unit quaternion, Hamilton convention, scalar first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quat(pub [f64; 4]);

impl Quat {
    /// No rotation.
    pub const IDENTITY: Quat = Quat([1.0, 0.0, 0.0, 0.0]);

    /// Hamilton product self ⊗ o.
    #[inline]
    pub fn mul(&self, o: &Quat) -> Quat {
        let [a0, a1, a2, a3] = self.0;
        let [b0, b1, b2, b3] = o.0;
        Quat([
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ])
    }

    /// Conjugate (the inverse rotation for a unit quaternion).
    pub fn conj(&self) -> Quat {
        let [w, x, y, z] = self.0;
        Quat([w, -x, -y, -z])
    }

    /// Unit-norm copy, with non-negative scalar part.
    pub fn normalized(&self) -> Quat {
        let n = self.0.iter().map(|v| v * v).sum::<f64>().sqrt();
        let s = if self.0[0] < 0.0 { -1.0 / n } else { 1.0 / n };
        Quat(self.0.map(|v| v * s))
    }

    /// Quaternion of a rotation vector φ (rad).
    pub fn from_rotation_vector(phi: Vec3) -> Quat {
        let a2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2];
        let a = a2.sqrt();
        // cos(a/2) and sin(a/2)/a by their Taylor series for small angles (every IMU
        // increment and every filter correction): terms to a⁸, so the first omitted term
        // is below 3e-23 for a < 0.05 rad — exact to rounding, and no libm call.
        let (c, s) = if a < 0.05 {
            (
                1.0 + a2
                    * (-1.0 / 8.0
                        + a2 * (1.0 / 384.0 + a2 * (-1.0 / 46_080.0 + a2 / 10_321_920.0))),
                0.5 + a2
                    * (-1.0 / 48.0
                        + a2 * (1.0 / 3840.0 + a2 * (-1.0 / 645_120.0 + a2 / 185_794_560.0))),
            )
        } else {
            ((a / 2.0).cos(), (a / 2.0).sin() / a)
        };
        Quat([c, phi[0] * s, phi[1] * s, phi[2] * s])
    }

    /// Rotation vector of the quaternion (angle in [0, π]).
    pub fn to_rotation_vector(&self) -> Vec3 {
        let q = self.normalized();
        let v = [q.0[1], q.0[2], q.0[3]];
        let sn = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if sn < 1e-12 {
            return [2.0 * v[0], 2.0 * v[1], 2.0 * v[2]];
        }
        let angle = 2.0 * sn.atan2(q.0[0]);
        [v[0] / sn * angle, v[1] / sn * angle, v[2] / sn * angle]
    }

    /// The DCM this quaternion represents (for `q_bn`, C_bn).
    pub fn to_dcm(&self) -> Mat3 {
        let [w, x, y, z] = self.0;
        Mat3([
            [
                w * w + x * x - y * y - z * z,
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                w * w - x * x + y * y - z * z,
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                w * w - x * x - y * y + z * z,
            ],
        ])
    }

    /// Quaternion of a proper orthogonal DCM (Shepperd's method: the largest of the four
    /// candidate pivots, numerically stable for every attitude).
    pub fn from_dcm(c: &Mat3) -> Quat {
        let m = &c.0;
        let tr = m[0][0] + m[1][1] + m[2][2];
        let cand = [tr, m[0][0], m[1][1], m[2][2]];
        let k = (0..4)
            .max_by(|&a, &b| cand[a].total_cmp(&cand[b]))
            .unwrap_or(0);
        let q = match k {
            0 => {
                let s = 2.0 * (1.0 + tr).sqrt();
                [
                    s / 4.0,
                    (m[2][1] - m[1][2]) / s,
                    (m[0][2] - m[2][0]) / s,
                    (m[1][0] - m[0][1]) / s,
                ]
            }
            1 => {
                let s = 2.0 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
                [
                    (m[2][1] - m[1][2]) / s,
                    s / 4.0,
                    (m[0][1] + m[1][0]) / s,
                    (m[0][2] + m[2][0]) / s,
                ]
            }
            2 => {
                let s = 2.0 * (1.0 - m[0][0] + m[1][1] - m[2][2]).sqrt();
                [
                    (m[0][2] - m[2][0]) / s,
                    (m[0][1] + m[1][0]) / s,
                    s / 4.0,
                    (m[1][2] + m[2][1]) / s,
                ]
            }
            _ => {
                let s = 2.0 * (1.0 - m[0][0] - m[1][1] + m[2][2]).sqrt();
                [
                    (m[1][0] - m[0][1]) / s,
                    (m[0][2] + m[2][0]) / s,
                    (m[1][2] + m[2][1]) / s,
                    s / 4.0,
                ]
            }
        };
        Quat(q).normalized()
    }

    /// Rotate a vector: q ⊗ v ⊗ q*.
    pub fn rotate(&self, v: Vec3) -> Vec3 {
        self.to_dcm().mul_vec(v)
    }
}

/// Euler angles (roll, pitch, yaw), rad, of the z-y-x sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Euler {
    /// Roll φ about body x.
    pub roll_rad: f64,
    /// Pitch θ about body y.
    pub pitch_rad: f64,
    /// Yaw (heading) ψ about down, from north towards east.
    pub yaw_rad: f64,
}

impl Euler {
    /// C_bn = R_z(ψ)·R_y(θ)·R_x(φ).
    pub fn to_dcm(&self) -> Mat3 {
        let (sr, cr) = self.roll_rad.sin_cos();
        let (sp, cp) = self.pitch_rad.sin_cos();
        let (sy, cy) = self.yaw_rad.sin_cos();
        Mat3([
            [cp * cy, -cr * sy + sr * sp * cy, sr * sy + cr * sp * cy],
            [cp * sy, cr * cy + sr * sp * sy, -sr * cy + cr * sp * sy],
            [-sp, sr * cp, cr * cp],
        ])
    }

    /// Euler angles of C_bn; yaw in (−π, π]. At pitch = ±90° roll is set to 0 and the
    /// combined rotation goes into yaw.
    pub fn from_dcm(c: &Mat3) -> Euler {
        let m = &c.0;
        let pitch = (-m[2][0]).clamp(-1.0, 1.0).asin();
        if m[2][0].abs() > 1.0 - 1e-12 {
            return Euler {
                roll_rad: 0.0,
                pitch_rad: pitch,
                yaw_rad: (-m[0][1]).atan2(m[1][1]),
            };
        }
        Euler {
            roll_rad: m[2][1].atan2(m[2][2]),
            pitch_rad: pitch,
            yaw_rad: m[1][0].atan2(m[0][0]),
        }
    }

    /// Quaternion q_bn of these angles.
    pub fn to_quat(&self) -> Quat {
        Quat::from_dcm(&self.to_dcm())
    }
}

/// Small-angle DCM I + [φ×] (first order), e.g. for attitude-error feedback.
pub fn small_angle_dcm(phi: Vec3) -> Mat3 {
    Mat3::IDENTITY + Mat3::skew(phi)
}

/// Rotation vector of the body rotation over one interval from two successive angle
/// increments with the two-sample coning correction: φ_k = Δθ_k + (1/12)·Δθ_{k−1} × Δθ_k
/// (Savage 1998; Shin 2005, eq. 2.74).
pub fn coning_rotation_vector(dtheta_prev: Vec3, dtheta: Vec3) -> Vec3 {
    let c = cross(dtheta_prev, dtheta);
    [
        dtheta[0] + c[0] / 12.0,
        dtheta[1] + c[1] / 12.0,
        dtheta[2] + c[2] / 12.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use driftless_model::units::DEG;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a.0[i][j] - b.0[i][j]).abs() < tol))
    }

    #[test]
    fn euler_dcm_quaternion_round_trips() {
        for &(r, p, y) in &[
            (10.0, -20.0, 135.0),
            (-170.0, 45.0, -60.0),
            (0.0, 0.0, 0.0),
            (5.0, 89.0, 30.0),
        ] {
            let e = Euler {
                roll_rad: r * DEG,
                pitch_rad: p * DEG,
                yaw_rad: y * DEG,
            };
            let c = e.to_dcm();
            // orthonormal, det +1
            assert!(close(&(c * c.t()), &Mat3::IDENTITY, 1e-14));
            assert!((c.det() - 1.0).abs() < 1e-14);
            let q = e.to_quat();
            assert!(close(&q.to_dcm(), &c, 1e-14));
            let back = Euler::from_dcm(&c);
            assert!(close(&back.to_dcm(), &c, 1e-12), "{r} {p} {y}");
        }
    }

    #[test]
    fn yaw_rotates_north_to_east() {
        // Heading 90° (east): body forward axis points east in NED.
        let e = Euler {
            roll_rad: 0.0,
            pitch_rad: 0.0,
            yaw_rad: 90.0 * DEG,
        };
        let f = e.to_dcm().mul_vec([1.0, 0.0, 0.0]);
        assert!(f[0].abs() < 1e-15 && (f[1] - 1.0).abs() < 1e-15);
        // Positive pitch raises the nose: forward axis gets a negative down component.
        let e = Euler {
            roll_rad: 0.0,
            pitch_rad: 10.0 * DEG,
            yaw_rad: 0.0,
        };
        assert!(e.to_dcm().mul_vec([1.0, 0.0, 0.0])[2] < 0.0);
    }

    #[test]
    fn rotation_vector_round_trip_and_composition() {
        let phi = [0.3, -0.2, 0.9];
        let q = Quat::from_rotation_vector(phi);
        let back = q.to_rotation_vector();
        for k in 0..3 {
            assert!((back[k] - phi[k]).abs() < 1e-14);
        }
        // tiny increments keep full relative precision
        let tiny = [1e-9, -2e-9, 3e-9];
        let t = Quat::from_rotation_vector(tiny).to_rotation_vector();
        for k in 0..3 {
            assert!((t[k] - tiny[k]).abs() < 1e-22);
        }
        // two rotations about the same axis add
        let a = Quat::from_rotation_vector([0.0, 0.0, 0.4]);
        let b = Quat::from_rotation_vector([0.0, 0.0, 0.5]);
        let ab = a.mul(&b).to_rotation_vector();
        assert!((ab[2] - 0.9).abs() < 1e-14);
        // q ⊗ v ⊗ q* equals the DCM product
        let v = [1.0, 2.0, 3.0];
        let qv = q.mul(&Quat([0.0, v[0], v[1], v[2]])).mul(&q.conj());
        let dv = q.rotate(v);
        for (k, d) in dv.iter().enumerate() {
            assert!((qv.0[k + 1] - d).abs() < 1e-14);
        }
    }

    #[test]
    fn coning_correction_vanishes_for_fixed_axis() {
        let a = [0.01, 0.02, -0.005];
        let b = [0.02, 0.04, -0.01];
        assert_eq!(coning_rotation_vector(a, b), b);
    }
}

#[cfg(test)]
mod rotation_series_tests {
    use super::Quat;

    #[test]
    fn series_matches_sin_cos_up_to_the_switch() {
        for a in [1e-9, 1e-6, 1e-4, 1e-3, 0.01, 0.03, 0.0499] {
            let q = Quat::from_rotation_vector([a * 0.6, -a * 0.8, 0.0]);
            let (c, s) = ((a / 2.0_f64).cos(), (a / 2.0_f64).sin() / a);
            assert!((q.0[0] - c).abs() <= 2e-16, "a {a}: cos");
            assert!((q.0[1] - 0.6 * a * s).abs() <= 2e-16 * a, "a {a}: sin");
        }
    }
}

//! The error-state transition matrix Φ and discrete process noise Q of one step, and the
//! row/column layout of the navigation block.

use super::*;

pub(super) type M3 = [[f64; 3]; 3];

#[inline(always)]
pub(super) fn mv(m: &M3, x: &[f64]) -> Vec3 {
    [
        m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
        m[1][0] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
        m[2][0] * x[0] + m[2][1] * x[1] + m[2][2] * x[2],
    ]
}

pub(super) fn sm(m: &M3, k: f64) -> M3 {
    m.map(|r| r.map(|v| v * k))
}

pub(super) fn madd(a: &M3, b: &M3) -> M3 {
    let mut o = *a;
    for i in 0..3 {
        for j in 0..3 {
            o[i][j] += b[i][j];
        }
    }
    o
}

pub(super) fn mmul(a: &M3, b: &M3) -> M3 {
    Mat3(*a).mul_mat(&Mat3(*b)).0
}

/// The non-trivial blocks of A = Φ − I = FΔt for one interval (module docs). Everything
/// not listed is zero, except the identity block Δt·I of ∂δṙ/∂δv.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// Interval Δt, s.
    pub dt_s: f64,
    /// F_rr Δt.
    pub rr: M3,
    /// F_vr Δt.
    pub vr: M3,
    /// F_vv Δt.
    pub vv: M3,
    /// F_vφ Δt = [f^n×]Δt.
    pub vphi: M3,
    /// F_v,ba Δt = C_bn Δt.
    pub vba: M3,
    /// F_v,sa Δt = C_bn diag(f^b) Δt.
    pub vsa: M3,
    /// F_φr Δt.
    pub phir: M3,
    /// F_φv Δt.
    pub phiv: M3,
    /// F_φφ Δt = −[ω_in×]Δt.
    pub phiphi: M3,
    /// F_φ,bg Δt = −C_bn Δt.
    pub phibg: M3,
    /// F_φ,sg Δt = −C_bn diag(ω_ib^b) Δt.
    pub phisg: M3,
    /// −Δt/T for the 12 sensor states.
    pub sensor: [f64; 12],
    /// Rotation-driven attitude PSD block of the interval, NED, rad²/s (added to Q_c's
    /// attitude block; [`Transition::with_rotation_noise`]). Zero unless set there.
    pub att_rotation_q: M3,
    /// Compensated mean angular rate ω̂_ib^b of the interval, rad/s.
    pub rate_b_rad_s: Vec3,
}

impl Transition {
    /// The same transition with the rotation-driven attitude process noise of an
    /// unmodelled gyro axis coupling of σ `coupling_sigma_rad` = σ_c
    /// ([`FilterConfig::gyro_coupling_sigma_rad`]; model in the module docs):
    /// Q_φ,rot = σ_c² C_bn diag(|ω̂| − ω̂_k²/|ω̂|) C_bnᵀ, ω̂ = ω̂_ib^b the compensated mean
    /// rate of the interval.
    pub fn with_rotation_noise(mut self, coupling_sigma_rad: f64) -> Transition {
        let w = &self.rate_b_rad_s;
        let norm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if !(coupling_sigma_rad > 0.0 && norm > 0.0 && self.dt_s > 0.0) {
            return self;
        }
        let s2 = coupling_sigma_rad * coupling_sigma_rad;
        let d: Vec3 = std::array::from_fn(|k| s2 * (norm - w[k] * w[k] / norm));
        let c = sm(&self.vba, 1.0 / self.dt_s);
        for i in 0..3 {
            for j in i..3 {
                let v =
                    c[i][0] * d[0] * c[j][0] + c[i][1] * d[1] * c[j][1] + c[i][2] * d[2] * c[j][2];
                self.att_rotation_q[i][j] = v;
                self.att_rotation_q[j][i] = v;
            }
        }
        self
    }

    /// Build A = FΔt at the state `nav` (start of the interval) for the compensated
    /// mean angular rate `omega_ib_b_rad_s` and specific force `f_b_m_s2` over `dt_s`.
    /// `neg_inv_tau` from [`FilterConfig::neg_inv_tau`].
    pub fn new(
        nav: &NavState,
        omega_ib_b_rad_s: Vec3,
        f_b_m_s2: Vec3,
        dt_s: f64,
        neg_inv_tau: &[f64; 12],
    ) -> Transition {
        let dt = dt_s;
        let (s, c) = nav.lat_rad.sin_cos();
        let tan = s / c;
        let h = nav.height_m;
        let rm = earth::meridian_radius_m(nav.lat_rad);
        let rn = earth::prime_vertical_radius_m(nav.lat_rad);
        let (rm_h, rn_h) = (rm + h, rn + h);
        let v = nav.vel_ned_m_s;
        let g = earth::normal_gravity_m_s2(nav.lat_rad, h);
        let w = earth::OMEGA_IE;
        let w_ie = [w * c, 0.0, -w * s];
        let w_en = [v[1] / rn_h, -v[0] / rm_h, -v[1] * tan / rn_h];
        let w_in = add(w_ie, w_en);
        let c_bn = nav.q_bn.to_dcm().0;
        let f_n = mv(&c_bn, &f_b_m_s2);

        // Jacobians of ω_ie and ω_en with respect to δr = (δr_N, δr_E, δr_D) and δv.
        let m_ie_r: M3 = [
            [-w * s / rm_h, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [-w * c / rm_h, 0.0, 0.0],
        ];
        let m_en_r: M3 = [
            [0.0, 0.0, v[1] / (rn_h * rn_h)],
            [0.0, 0.0, -v[0] / (rm_h * rm_h)],
            [
                -v[1] / (c * c * rn_h * rm_h),
                0.0,
                -v[1] * tan / (rn_h * rn_h),
            ],
        ];
        let m_en_v: M3 = [
            [0.0, 1.0 / rn_h, 0.0],
            [-1.0 / rm_h, 0.0, 0.0],
            [0.0, -tan / rn_h, 0.0],
        ];
        let vx = Mat3::skew(v).0;
        let rr: M3 = [
            [-v[2] / rm_h, 0.0, v[0] / rm_h],
            [
                v[1] * tan / rm_h,
                -(v[2] / rn_h + v[0] * tan / rm_h),
                v[1] / rn_h,
            ],
            [0.0, 0.0, 0.0],
        ];
        let mut vr = mmul(&vx, &madd(&sm(&m_ie_r, 2.0), &m_en_r));
        vr[2][2] += 2.0 * g / ((rm * rn).sqrt() + h);
        let w2 = add(scale(w_ie, 2.0), w_en);
        let vv = madd(&mmul(&vx, &m_en_v), &sm(&Mat3::skew(w2).0, -1.0));
        let vphi = Mat3::skew(f_n).0;
        let mut vsa = c_bn;
        let mut phisg = c_bn;
        for row in 0..3 {
            for col in 0..3 {
                vsa[row][col] *= f_b_m_s2[col];
                phisg[row][col] *= -omega_ib_b_rad_s[col];
            }
        }
        Transition {
            dt_s: dt,
            rr: sm(&rr, dt),
            vr: sm(&vr, dt),
            vv: sm(&vv, dt),
            vphi: sm(&vphi, dt),
            vba: sm(&c_bn, dt),
            vsa: sm(&vsa, dt),
            phir: sm(&madd(&m_ie_r, &m_en_r), dt),
            phiv: sm(&m_en_v, dt),
            phiphi: sm(&Mat3::skew(w_in).0, -dt),
            phibg: sm(&c_bn, -dt),
            phisg: sm(&phisg, dt),
            sensor: neg_inv_tau.map(|k| k * dt),
            att_rotation_q: [[0.0; 3]; 3],
            rate_b_rad_s: omega_ib_b_rad_s,
        }
    }

    /// y = A x (A = Φ − I), exploiting the block structure.
    #[inline(always)]
    pub fn apply(&self, x: &[f64; N_STATES]) -> [f64; N_STATES] {
        let mut y = [0.0; N_STATES];
        let xr = &x[POS..POS + 3];
        let xv = &x[VEL..VEL + 3];
        let xp = &x[ATT..ATT + 3];
        let a = mv(&self.rr, xr);
        for k in 0..3 {
            y[POS + k] = a[k] + self.dt_s * xv[k];
        }
        let a = mv(&self.vr, xr);
        let b = mv(&self.vv, xv);
        let c = mv(&self.vphi, xp);
        let d = mv(&self.vba, &x[BA..BA + 3]);
        let e = mv(&self.vsa, &x[SA..SA + 3]);
        for k in 0..3 {
            y[VEL + k] = a[k] + b[k] + c[k] + d[k] + e[k];
        }
        let a = mv(&self.phir, xr);
        let b = mv(&self.phiv, xv);
        let c = mv(&self.phiphi, xp);
        let d = mv(&self.phibg, &x[BG..BG + 3]);
        let e = mv(&self.phisg, &x[SG..SG + 3]);
        for k in 0..3 {
            y[ATT + k] = a[k] + b[k] + c[k] + d[k] + e[k];
        }
        for k in 0..12 {
            y[BG + k] = self.sensor[k] * x[BG + k];
        }
        y
    }

    /// Φ as a dense matrix (for tests and smoothers that want it explicitly).
    pub fn phi_dense(&self) -> Cov {
        let mut phi = [[0.0; N_STATES]; N_STATES];
        for j in 0..N_STATES {
            let mut e = [0.0; N_STATES];
            e[j] = 1.0;
            let col = self.apply(&e);
            for i in 0..N_STATES {
                phi[i][j] = col[i] + if i == j { 1.0 } else { 0.0 };
            }
        }
        phi
    }

    /// The 9 navigation rows of A as a dense 9 × 21 array (sensor rows are diagonal).
    #[inline]
    pub(crate) fn nav_rows(&self) -> [[f64; N_STATES]; 9] {
        let mut a = [[0.0; N_STATES]; 9];
        for r in 0..3 {
            for c in 0..3 {
                a[POS + r][POS + c] = self.rr[r][c];
                a[VEL + r][POS + c] = self.vr[r][c];
                a[VEL + r][VEL + c] = self.vv[r][c];
                a[VEL + r][ATT + c] = self.vphi[r][c];
                a[VEL + r][BA + c] = self.vba[r][c];
                a[VEL + r][SA + c] = self.vsa[r][c];
                a[ATT + r][POS + c] = self.phir[r][c];
                a[ATT + r][VEL + c] = self.phiv[r][c];
                a[ATT + r][ATT + c] = self.phiphi[r][c];
                a[ATT + r][BG + c] = self.phibg[r][c];
                a[ATT + r][SG + c] = self.phisg[r][c];
            }
            a[POS + r][VEL + r] = self.dt_s;
        }
        a
    }

    /// P ← Φ (P + ½Q_cΔt) Φᵀ + ½Q_cΔt with Φ = I + A (module docs), in place.
    /// `q_c_diag` from [`FilterConfig::q_c_diag`]. Result is exactly symmetric.
    ///
    /// Block form with n = the 9 navigation states, s = the 12 sensor states:
    /// Φ = [[Φ_nn, Φ_ns], [0, E]], E = diag(1 − Δt/T) and
    ///
    /// * Z = [Φ_nn Φ_ns] P (9 × 21: the navigation rows of ΦP), as row combinations
    ///   (axpy over whole 21-element rows of P) over the structurally non-zero columns of
    ///   each row of A (a fixed list per row), in increasing column order;
    /// * (ΦPΦᵀ)_nn = Z [Φ_nn Φ_ns]ᵀ, as row combinations of Zᵀ (9-element rows);
    /// * (ΦPΦᵀ)_ns = Z_s E, (ΦPΦᵀ)_ss = E P_ss E (element-wise).
    ///
    /// ≈ 100 axpys of length 21 plus 100 of length 9 instead of two dense 21³ products.
    /// The column lists are fixed, so there is no data-dependent branch per coefficient
    /// (a coefficient that happens to be zero adds an exact zero). On x86-64 CPUs with
    /// AVX2 a copy compiled for AVX2 runs (four lanes instead of two); it performs the
    /// same operations in the same order, so the result is bit-identical.
    #[inline]
    #[allow(unsafe_code)]
    pub fn propagate(&self, p: &mut Cov, q_c_diag: &[f64; N_STATES]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: `propagate_avx2` differs from the portable kernel only in being
                // compiled with the `avx2` target feature; the CPU supports AVX2 (checked
                // just above), which is the sole requirement for calling it.
                return unsafe { self.propagate_avx2(p, q_c_diag) };
            }
        }
        self.propagate_portable(p, q_c_diag)
    }

    /// [`Transition::propagate`] compiled with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn propagate_avx2(&self, p: &mut Cov, q_c_diag: &[f64; N_STATES]) {
        self.propagate_portable(p, q_c_diag)
    }

    /// The portable kernel of [`Transition::propagate`] (also the body of the AVX2 copy).
    #[inline(always)]
    pub(super) fn propagate_portable(&self, p: &mut Cov, q_c_diag: &[f64; N_STATES]) {
        let half = 0.5 * self.dt_s;
        for i in 0..N_STATES {
            p[i][i] += half * q_c_diag[i];
        }
        for i in 0..3 {
            for j in 0..3 {
                p[ATT + i][ATT + j] += half * self.att_rotation_q[i][j];
            }
        }
        let a = self.nav_rows();
        // Z = rows 0..9 of Φ P.
        let mut z = [[0.0; N_STATES]; 9];
        for i in 0..9 {
            let mut acc = p[i];
            for &k in NAV_ROW_COLS[i] {
                let coef = a[i][k];
                let row = &p[k];
                for c in 0..N_STATES {
                    acc[c] += coef * row[c];
                }
            }
            z[i] = acc;
        }
        // Zᵀ (21 × 9).
        let mut zt = [[0.0; 9]; N_STATES];
        for i in 0..9 {
            for k in 0..N_STATES {
                zt[k][i] = z[i][k];
            }
        }
        // (ΦPΦᵀ)_nn, row j = Φ_j · Zᵀ.
        for j in 0..9 {
            let mut acc = zt[j];
            for &k in NAV_ROW_COLS[j] {
                let coef = a[j][k];
                let row = &zt[k];
                for c in 0..9 {
                    acc[c] += coef * row[c];
                }
            }
            // acc[i] = (ΦPΦᵀ)[i][j]; keep the upper triangle (i ≤ j) and mirror.
            for i in 0..=j {
                p[i][j] = acc[i];
                p[j][i] = acc[i];
            }
        }
        let e: [f64; 12] = std::array::from_fn(|s| 1.0 + self.sensor[s]);
        for i in 0..9 {
            for s in 0..12 {
                let v = z[i][BG + s] * e[s];
                p[i][BG + s] = v;
                p[BG + s][i] = v;
            }
        }
        for s in 0..12 {
            for t in s..12 {
                let v = p[BG + s][BG + t] * (e[s] * e[t]);
                p[BG + s][BG + t] = v;
                p[BG + t][BG + s] = v;
            }
        }
        for i in 0..N_STATES {
            p[i][i] += half * q_c_diag[i];
        }
        for i in 0..3 {
            for j in 0..3 {
                p[ATT + i][ATT + j] += half * self.att_rotation_q[i][j];
            }
        }
    }
}

/// The columns of each navigation row of A = Φ − I that can be non-zero (the blocks of
/// [`Transition`], in increasing order; the structural zeros — row 3 of F_rr, the
/// diagonals of the skew blocks F_vφ and F_φφ, the zeros of F_φv — left out).
#[rustfmt::skip]
pub(crate) const NAV_ROW_COLS: [&[usize]; 9] = [
    // δr_N: F_rr (N, D), δv_N.
    &[POS, POS + 2, VEL],
    // δr_E: F_rr (N, E, D), δv_E.
    &[POS, POS + 1, POS + 2, VEL + 1],
    // δr_D: δv_D.
    &[VEL + 2],
    // δv: F_vr (N, D: δr_E does not enter), F_vv, F_vφ off-diagonal, C_bn (b_a),
    // C_bn diag(f) (s_a).
    &[POS, POS + 2, VEL, VEL + 1, VEL + 2, ATT + 1, ATT + 2, BA, BA + 1, BA + 2, SA, SA + 1, SA + 2],
    &[POS, POS + 2, VEL, VEL + 1, VEL + 2, ATT, ATT + 2, BA, BA + 1, BA + 2, SA, SA + 1, SA + 2],
    &[POS, POS + 2, VEL, VEL + 1, VEL + 2, ATT, ATT + 1, BA, BA + 1, BA + 2, SA, SA + 1, SA + 2],
    // φ: F_φr (N, D of row N and D; D of row E), F_φv (one entry per row), F_φφ
    // off-diagonal, −C_bn (b_g), −C_bn diag(ω) (s_g).
    &[POS, POS + 2, VEL + 1, ATT + 1, ATT + 2, BG, BG + 1, BG + 2, SG, SG + 1, SG + 2],
    &[POS + 2, VEL, ATT, ATT + 2, BG, BG + 1, BG + 2, SG, SG + 1, SG + 2],
    &[POS, POS + 2, VEL + 1, ATT, ATT + 1, BG, BG + 1, BG + 2, SG, SG + 1, SG + 2],
];

/// Transport-plus-Earth rate ω_in^n at a state, rad/s.
pub(crate) fn omega_in(nav: &NavState) -> Vec3 {
    add(
        earth::earth_rate_ned(nav.lat_rad),
        earth::transport_rate_ned(nav.lat_rad, nav.height_m, nav.vel_ned_m_s),
    )
}

/// [a×] as a 3 × 3 array.
pub(crate) fn skew(a: Vec3) -> M3 {
    Mat3::skew(a).0
}

#[allow(dead_code)]
pub(crate) fn cross3(a: Vec3, b: Vec3) -> Vec3 {
    cross(a, b)
}

//! Rauch–Tung–Striebel fixed-interval smoother over a closed-loop forward pass
//! ([`super::run_forward`]).
//!
//! # The RTS recursion (Rauch, Tung & Striebel 1965)
//!
//! For a linear(ised) system x_{k+1} = Φ_{k+1} x_k + w_k with forward filtered estimates
//! x⁺_k, P⁺_k and one-step predictions x⁻_{k+1} = Φ_{k+1} x⁺_k,
//! P⁻_{k+1} = Φ_{k+1} P⁺_k Φ_{k+1}ᵀ + Q_k, the smoothed estimates are, backwards from
//! x_s(N) = x⁺_N, P_s(N) = P⁺_N,
//!
//! ```text
//! A_k    = P⁺_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹
//! x_s(k) = x⁺_k + A_k (x_s(k+1) − x⁻_{k+1})
//! P_s(k) = P⁺_k + A_k (P_s(k+1) − P⁻_{k+1}) A_kᵀ
//! ```
//!
//! (Brown & Hwang 2012 §6.2, eqs. 6.2.4–6.2.6; Gelb 1974 §5.3).
//!
//! # Closed-loop error-state form (Shin 2005 §3.4 and ch. 5)
//!
//! The forward filter feeds every estimated error back into the navigation state and the
//! sensor-error estimates and resets it to zero ([`super::eskf`]), so the filtered error
//! state relative to the *stored* (post-update) state is zero at every epoch and
//! x⁻_{k+1} = Φ x⁺_k = 0 relative to the forward prediction. The smoother estimates a
//! correction e_s(k) to the stored state at each epoch, in the filter's error convention
//! (navigation errors estimated − true, sensor states true − estimated; [`super`]). Two
//! frames must be distinguished at an update epoch u: the prior P⁻_u refers to errors of
//! the *predicted* state x̂⁻_u, the posterior P⁺_u to errors of the *corrected* state x̂⁺_u,
//! and the two differ by the applied correction d_u = x̂⁻_u ⊖ x̂⁺_u (the δx̂ = K y the filter
//! fed back; zero where there was no update). With the reset Jacobian taken as I, as the
//! forward filter does (Groves 2013 §14.2.7: it is I − ½[δφ×], second order in the
//! correction), the smoothed error of the predicted state is d_u + e_s(u), and
//!
//! ```text
//! e_s(N) = 0,   e_s(k) = A_k (e_s(k+1) + d_{k+1}),
//! P_s(k) = P⁺_k + A_k (P_s(k+1) − P⁻_{k+1}) A_kᵀ.
//! ```
//!
//! (Without d the recursion would be identically zero: in the closed loop the whole
//! measurement information reaches the smoother through the corrections that were fed
//! back.) d_u is rebuilt from the records: x̂⁻_u is the mechanization of the stored state
//! at u − 1 over the stored compensated increment of u (bit-identical to the forward
//! prediction, except at u = 1 where the increment before the start that primed the
//! two-sample corrections is not stored; its effect is O(Δθ·Δv) over 5 ms), x̂⁺_u is the
//! stored record; d is their difference in the filter's error coordinates (the exact
//! inverse of [`super::Eskf`]'s feedback).
//!
//! # Evaluation without a 21 × 21 inverse per epoch
//!
//! The gain needs (P⁻_{k+1})⁻¹, a dense 21 × 21 factorisation per epoch. Between updates
//! P⁺ = P⁻, and the recursion is rewritten with the adjoint variables
//! λ(k) = (P⁻_k)⁻¹ (e_s(k) + d_k), Λ(k) = (P⁻_k)⁻¹ (P⁻_k − P_s(k)) (P⁻_k)⁻¹ (the form of the
//! modified Bryson–Frazier smoother, Bierman 1977 ch. X; algebraically the RTS recursion
//! above): with λ⁺(N) = 0, Λ⁺(N) = 0,
//!
//! ```text
//! e_s(k) = P⁺_k λ⁺(k),                P_s(k) = P⁺_k − P⁺_k Λ⁺(k) P⁺_k,
//! λ⁻(k) = λ⁺(k), Λ⁻(k) = Λ⁺(k)                         (no update at k)
//! λ⁻(u) = (P⁻_u)⁻¹ (d_u + e_s(u)),  Λ⁻(u) = (P⁻_u)⁻¹ (P⁻_u − P_s(u)) (P⁻_u)⁻¹   (update)
//! λ⁺(k−1) = Φ_kᵀ λ⁻(k),             Λ⁺(k−1) = Φ_kᵀ Λ⁻(k) Φ_k.
//! ```
//!
//! Check: e_s(k−1) = P⁺ Φᵀ (P⁻_k)⁻¹ (e_s(k) + d_k) = A_{k−1}(e_s(k) + d_k) and
//! P⁺ − P⁺ΦᵀΛ⁻Φ P⁺ = P⁺ − A (P⁻ − P_s) Aᵀ. Only update epochs need a factorisation (of
//! the stored prior, Cholesky with Jacobi scaling); Φᵀ Λ Φ uses the block sparsity of
//! Φ = I + A ([`Transition`]).
//!
//! # Segments, memory and cost
//!
//! P is stored by the forward pass only at updates ([`super::UpdateRecord`]). Each
//! segment between two updates is re-propagated forward from the stored posterior at its
//! start with [`super::ForwardRun::transition`] and [`Transition::propagate`] with the
//! configuration's Q (the forward pass's own code, so the result is bit-identical; the
//! re-propagated prior at the segment end is compared with the stored prior and a
//! mismatch — a different configuration — is an error), into a scratch buffer, then swept
//! backwards. Segments longer than `CHUNK` epochs (long outages) are re-propagated
//! twice, keeping only a checkpoint every `CHUNK` epochs, so the scratch never exceeds
//! `CHUNK` × (3528 B covariance + 904 B transition) ≈ 18 MB.
//!
//! Output: one [`SmoothedEpoch`] per forward record, **352 B per epoch** (navigation
//! state 88 B, sensor errors 96 B, 21 σ 168 B; 1 h at 200 Hz: 253 MB, on top of the
//! forward run's 416 B per epoch).
//!
//! Per epoch: one covariance propagation, Φᵀ Λ Φ (≈ 6 k multiply-adds), and the outputs
//! P λ and diag(P Λ P) (≈ 10 k multiply-adds): measured 4.4 µs per epoch on one core
//! (1 h at 200 Hz: 3.2 s smoother + 1.0 s forward). A two-thread split of the run (the
//! earlier half seeded by an adjoint-only pass over the later half) was tried and was
//! slower on the 2-vCPU test machine, and so was re-propagating the next chunk's
//! covariances on a second thread while the backward sweep works on the current one
//! (3.27 s vs 3.10 s: the sweep then reads every covariance from the other core's
//! cache), so the smoother runs on one thread.

use super::NavError;
use super::model::{FilterConfig, NAV_ROW_COLS, Transition};
use super::run::{ForwardRun, InitialState};
use super::state::{ATT, BA, BG, Cov, N_STATES, POS, SA, SG, SensorErrors, VEL, unpack};
use crate::nav::earth;
use crate::nav::mechanization::{NavState, mechanize};

/// Longest stretch of epochs whose covariances are held at once (see the module docs).
pub(crate) const CHUNK: usize = 4096;

/// Relative tolerance of the re-propagated prior against the stored prior.
const REBUILD_TOL: f64 = 1e-9;

/// Smoothed estimate at one epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothedEpoch {
    /// Smoothed navigation state (IMU centre).
    pub nav: NavState,
    /// Smoothed sensor-error estimates.
    pub sensors: SensorErrors,
    /// √diag(P_s), order of [`super::state`].
    pub std: [f64; N_STATES],
}

/// Result of [`smooth`]: one epoch per forward record (352 B per epoch; module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothedRun {
    /// Smoothed epochs, aligned with [`ForwardRun::epochs`].
    pub epochs: Vec<SmoothedEpoch>,
}

/// Smooth a forward run. `init` and `cfg` must be those given to
/// [`super::run_forward`] (the initial covariance and Q are not stored in the run; a
/// mismatch is detected and reported as [`NavError::Config`]).
///
/// Errors: empty run or inconsistent records ([`NavError::Config`]), a stored prior that
/// is not positive definite or a smoothed variance that is not positive
/// ([`NavError::Covariance`]).
pub fn smooth(
    run: &ForwardRun,
    init: &InitialState,
    cfg: &FilterConfig,
) -> Result<SmoothedRun, NavError> {
    smooth_impl(run, init, cfg, 0, &mut |_, _| {})
}

/// [`smooth`], also handing the full smoothed covariance P_s (as computed, not
/// symmetrised) of every `stride`-th epoch (and of the last) to `visit(epoch, P_s)`, for
/// diagnostics and tests. `stride` = 0 visits nothing.
pub fn smooth_with_covariances(
    run: &ForwardRun,
    init: &InitialState,
    cfg: &FilterConfig,
    stride: usize,
    mut visit: impl FnMut(usize, &Cov),
) -> Result<SmoothedRun, NavError> {
    smooth_impl(run, init, cfg, stride.max(1), &mut visit)
}

/// Update epochs and the indices of their first and last [`super::UpdateRecord`].
#[derive(Clone, Copy, Debug)]
struct UpdEpoch {
    k: usize,
    first: usize,
    last: usize,
}

/// Adjoint variables λ, Λ (module docs).
#[derive(Clone)]
struct Adjoint {
    lam: [f64; N_STATES],
    big: Cov,
}

impl Adjoint {
    fn zero() -> Adjoint {
        Adjoint {
            lam: [0.0; N_STATES],
            big: [[0.0; N_STATES]; N_STATES],
        }
    }
}

struct Ctx<'a> {
    run: &'a ForwardRun,
    q: [f64; N_STATES],
    p0: Cov,
    upd: Vec<UpdEpoch>,
}

fn smooth_impl(
    run: &ForwardRun,
    init: &InitialState,
    cfg: &FilterConfig,
    stride: usize,
    visit: &mut dyn FnMut(usize, &Cov),
) -> Result<SmoothedRun, NavError> {
    cfg.validate()?;
    if run.first_epoch != 0 {
        return Err(NavError::Config(
            "the forward run dropped its epoch records (run_forward_observed without \
             keep_epochs): nothing to smooth"
                .into(),
        ));
    }
    let n = run.epochs.len();
    if n == 0 {
        return Err(NavError::Config(
            "smoother: the forward run has no epochs".into(),
        ));
    }
    let mut upd: Vec<UpdEpoch> = Vec::new();
    for (i, u) in run.updates.iter().enumerate() {
        if u.epoch_index >= n {
            return Err(NavError::Config(format!(
                "smoother: update record {i} refers to epoch {} of {n}",
                u.epoch_index
            )));
        }
        match upd.last_mut() {
            Some(l) if l.k == u.epoch_index => l.last = i,
            Some(l) if l.k > u.epoch_index => {
                return Err(NavError::Config(format!(
                    "smoother: update records out of order at record {i}"
                )));
            }
            _ => upd.push(UpdEpoch {
                k: u.epoch_index,
                first: i,
                last: i,
            }),
        }
    }
    let p0 = init.covariance(cfg);
    if upd.first().is_none_or(|u| u.k != 0) {
        let s = &run.epochs[0].std;
        let mismatch = (0..N_STATES).any(|i| (p0[i][i].sqrt() - s[i]).abs() > 1e-9 * s[i]);
        if mismatch {
            return Err(NavError::Config(
                "smoother: the initial covariance differs from the forward run's \
                 (not the same initial state / configuration?)"
                    .into(),
            ));
        }
    }
    let ctx = Ctx {
        run,
        q: cfg.q_c_diag(),
        p0,
        upd,
    };
    // Segment boundaries: 0, every update epoch > 0, and the last epoch.
    let mut bounds: Vec<usize> = vec![0];
    bounds.extend(ctx.upd.iter().map(|u| u.k).filter(|&k| k > 0));
    if bounds.last().is_some_and(|&b| b < n - 1) {
        bounds.push(n - 1);
    }
    let mut out = vec![
        SmoothedEpoch {
            nav: run.epochs[0].nav,
            sensors: run.epochs[0].sensors,
            std: [0.0; N_STATES],
        };
        n
    ];
    if bounds.len() == 1 {
        // A single epoch: smoothed = filtered.
        out[0] = output(&ctx, 0, &ctx.p_post_at(0), &Adjoint::zero(), None)?.0;
    } else {
        sweep(&ctx, &bounds, Adjoint::zero(), &mut out, 0, stride, visit)?;
    }
    Ok(SmoothedRun { epochs: out })
}

impl Ctx<'_> {
    fn upd_at(&self, k: usize) -> Option<&UpdEpoch> {
        self.upd
            .binary_search_by_key(&k, |u| u.k)
            .ok()
            .map(|i| &self.upd[i])
    }

    /// P⁺ at a segment start `a` (0 or an update epoch).
    fn p_post_at(&self, a: usize) -> Cov {
        match self.upd_at(a) {
            Some(u) => unpack(&self.run.updates[u.last].p_post),
            None => self.p0,
        }
    }

    fn transition(&self, k: usize) -> Result<Transition, NavError> {
        self.run
            .transition(k)
            .ok_or_else(|| NavError::Config(format!("smoother: no transition for epoch {k}")))
    }

    /// Correction d_u fed back at update epoch `u` ≥ 1 (module docs), error coordinates.
    fn correction(&self, u: usize) -> [f64; N_STATES] {
        let e = &self.run.epochs;
        let pre = mechanize(&e[u - 1].nav, &e[u - 1].comp, &e[u].comp);
        let post = &e[u].nav;
        let mut d = [0.0; N_STATES];
        let rm_h = earth::meridian_radius_m(pre.lat_rad) + pre.height_m;
        let rn_h = earth::prime_vertical_radius_m(pre.lat_rad) + pre.height_m;
        // Inverse of Eskf::feedback: lon⁺ = lon⁻ − d_E/((R_N+h)cos φ), lat⁺ = lat⁻ −
        // d_N/(R_M+h), h⁺ = h⁻ + d_D, v⁺ = v⁻ − d_v, q⁺ = q(φ) ⊗ q⁻, s⁺ = s⁻ + d_s.
        d[POS] = (pre.lat_rad - post.lat_rad) * rm_h;
        d[POS + 1] = (pre.lon_rad - post.lon_rad) * rn_h * pre.lat_rad.cos();
        d[POS + 2] = post.height_m - pre.height_m;
        for k in 0..3 {
            d[VEL + k] = pre.vel_ned_m_s[k] - post.vel_ned_m_s[k];
        }
        let phi = post.q_bn.mul(&pre.q_bn.conj()).to_rotation_vector();
        d[ATT..ATT + 3].copy_from_slice(&phi);
        let (s0, s1) = (&e[u - 1].sensors, &e[u].sensors);
        for k in 0..3 {
            d[BG + k] = s1.gyro_bias_rad_s[k] - s0.gyro_bias_rad_s[k];
            d[BA + k] = s1.accel_bias_m_s2[k] - s0.accel_bias_m_s2[k];
            d[SG + k] = s1.gyro_scale[k] - s0.gyro_scale[k];
            d[SA + k] = s1.accel_scale[k] - s0.accel_scale[k];
        }
        d
    }

    /// Convert λ⁺, Λ⁺ at update epoch `u` (with e_s, P_s there) to the prior frame.
    fn to_prior(
        &self,
        u: &UpdEpoch,
        adj: &mut Adjoint,
        e_s: &[f64; N_STATES],
        p_s: &Cov,
    ) -> Result<(), NavError> {
        let prior = unpack(&self.run.updates[u.first].p_prior);
        let chol = Chol::new(&prior).map_err(|d| NavError::Covariance {
            time_s: self.run.epochs[u.k].nav.time_s,
            diagnosis: format!("smoother: stored prior covariance: {d}"),
        })?;
        let d = self.correction(u.k);
        let r: [f64; N_STATES] = std::array::from_fn(|i| d[i] + e_s[i]);
        adj.lam = chol.solve(&r);
        // Λ⁻ = P⁻⁻¹ (P⁻ − P_s) P⁻⁻¹: X = P⁻⁻¹ D (column by column; D symmetric, so rows),
        // then Λ = P⁻⁻¹ Xᵀ.
        let mut x = [[0.0; N_STATES]; N_STATES];
        for i in 0..N_STATES {
            let col: [f64; N_STATES] =
                std::array::from_fn(|j| prior[j][i] - 0.5 * (p_s[j][i] + p_s[i][j]));
            x[i] = chol.solve(&col); // x[i] = (P⁻⁻¹ D)[:, i]
        }
        // x is (P⁻⁻¹ D)ᵀ = D P⁻⁻¹ stored by rows; Λ = P⁻⁻¹ (D P⁻⁻¹) column by column.
        let mut big = [[0.0; N_STATES]; N_STATES];
        for j in 0..N_STATES {
            let col: [f64; N_STATES] = std::array::from_fn(|i| x[i][j]);
            let c = chol.solve(&col);
            for i in 0..N_STATES {
                big[i][j] = c[i];
            }
        }
        symmetrize(&mut big);
        adj.big = big;
        Ok(())
    }
}

fn symmetrize(m: &mut Cov) {
    for i in 0..N_STATES {
        for j in (i + 1)..N_STATES {
            let a = 0.5 * (m[i][j] + m[j][i]);
            m[i][j] = a;
            m[j][i] = a;
        }
    }
}

/// Dense navigation rows of A = Φ − I (9 × 21, the transition's own) and the diagonal
/// of Φ.
fn nav_rows(t: &Transition) -> ([[f64; N_STATES]; 9], [f64; N_STATES]) {
    let mut e = [1.0; N_STATES];
    for s in 0..12 {
        e[BG + s] = 1.0 + t.sensor[s];
    }
    (t.nav_rows(), e)
}

/// λ ← Φᵀ λ, Λ ← Φᵀ Λ Φ. On x86-64 CPUs with AVX2 a copy compiled for AVX2 runs; it
/// performs the same operations in the same order (bit-identical results).
#[inline]
#[allow(unsafe_code)]
fn adjoint_step(t: &Transition, adj: &mut Adjoint) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `adjoint_step_avx2` differs from the portable kernel only in being
            // compiled with the `avx2` target feature; the CPU supports AVX2 (checked just
            // above), which is the sole requirement for calling it.
            return unsafe { adjoint_step_avx2(t, adj) };
        }
    }
    adjoint_step_portable(t, adj)
}

/// [`adjoint_step`] compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn adjoint_step_avx2(t: &Transition, adj: &mut Adjoint) {
    adjoint_step_portable(t, adj)
}

/// The portable kernel of [`adjoint_step`]. The sparse row combinations run over the
/// structurally non-zero columns of each navigation row of A ([`NAV_ROW_COLS`]), so no
/// branch per coefficient (a coefficient that happens to be zero adds an exact zero).
#[inline(always)]
fn adjoint_step_portable(t: &Transition, adj: &mut Adjoint) {
    let (a, e) = nav_rows(t);
    let lam = &adj.lam;
    let mut l2: [f64; N_STATES] = std::array::from_fn(|i| e[i] * lam[i]);
    for m in 0..9 {
        for i in 0..N_STATES {
            l2[i] += a[m][i] * lam[m];
        }
    }
    adj.lam = l2;
    let big = &adj.big;
    // V = Φᵀ Λ: row i = e_i Λ_i + Σ_{m<9} a[m][i] Λ_m.
    let mut v = [[0.0; N_STATES]; N_STATES];
    for i in 0..N_STATES {
        let ei = e[i];
        let src = &big[i];
        let dst = &mut v[i];
        for c in 0..N_STATES {
            dst[c] = ei * src[c];
        }
    }
    for m in 0..9 {
        let src = &big[m];
        for &i in NAV_ROW_COLS[m] {
            let coef = a[m][i];
            let dst = &mut v[i];
            for c in 0..N_STATES {
                dst[c] += coef * src[c];
            }
        }
    }
    // V = ΦᵀΛ = (ΛΦ)ᵀ, so W = ΛΦ = Vᵀ and R = Φᵀ W: row i = e_i W_i + Σ_m a[m][i] W_m
    // (the same sparse row combination).
    let mut w = [[0.0; N_STATES]; N_STATES];
    for i in 0..N_STATES {
        for c in 0..N_STATES {
            w[c][i] = v[i][c];
        }
    }
    let mut r = [[0.0; N_STATES]; N_STATES];
    for i in 0..N_STATES {
        let ei = e[i];
        let src = &w[i];
        let dst = &mut r[i];
        for c in 0..N_STATES {
            dst[c] = ei * src[c];
        }
    }
    for m in 0..9 {
        let src = &w[m];
        for &i in NAV_ROW_COLS[m] {
            let coef = a[m][i];
            let dst = &mut r[i];
            for c in 0..N_STATES {
                dst[c] += coef * src[c];
            }
        }
    }
    symmetrize(&mut r);
    adj.big = r;
}

/// M = Λ P (dense rows), dispatched like [`adjoint_step`] (bit-identical copies).
#[inline]
#[allow(unsafe_code)]
fn lambda_times_p(big: &Cov, p: &Cov) -> Cov {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: as in `adjoint_step`: only the target feature differs, and the CPU
            // has AVX2.
            return unsafe { lambda_times_p_avx2(big, p) };
        }
    }
    lambda_times_p_portable(big, p)
}

/// [`lambda_times_p`] compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn lambda_times_p_avx2(big: &Cov, p: &Cov) -> Cov {
    lambda_times_p_portable(big, p)
}

/// The portable kernel of [`lambda_times_p`]: row i of M = Σ_j Λ_ij P_j, j ascending.
#[inline(always)]
fn lambda_times_p_portable(big: &Cov, p: &Cov) -> Cov {
    let mut m = [[0.0; N_STATES]; N_STATES];
    for i in 0..N_STATES {
        let li = &big[i];
        let mut acc = [0.0; N_STATES];
        for j in 0..N_STATES {
            let coef = li[j];
            let pj = &p[j];
            for c in 0..N_STATES {
                acc[c] += coef * pj[c];
            }
        }
        m[i] = acc;
    }
    m
}

/// Smoothed epoch k from the stored record, P⁺_k and λ⁺, Λ⁺; also e_s and (if
/// `full`) P_s.
fn output(
    ctx: &Ctx,
    k: usize,
    p: &Cov,
    adj: &Adjoint,
    full: Option<&mut Cov>,
) -> Result<(SmoothedEpoch, [f64; N_STATES]), NavError> {
    let rec = &ctx.run.epochs[k];
    // e_s = P λ.
    let e_s: [f64; N_STATES] = std::array::from_fn(|i| {
        let row = &p[i];
        let mut s = 0.0;
        for j in 0..N_STATES {
            s += row[j] * adj.lam[j];
        }
        s
    });
    // M = Λ P (rows), diag(P M).
    let m = lambda_times_p(&adj.big, p);
    let mut std = [0.0; N_STATES];
    for i in 0..N_STATES {
        let mut s = 0.0;
        for j in 0..N_STATES {
            s += p[i][j] * m[j][i];
        }
        let var = p[i][i] - s;
        if !(var.is_finite() && var > 0.0) {
            return Err(NavError::Covariance {
                time_s: rec.nav.time_s,
                diagnosis: format!(
                    "smoothed variance of state {i} ({}) is {var:e} (filtered {:e})",
                    super::state::state_name(i),
                    p[i][i]
                ),
            });
        }
        std[i] = var.sqrt();
    }
    if let Some(ps) = full {
        for i in 0..N_STATES {
            let mut acc = p[i];
            for j in 0..N_STATES {
                let coef = p[i][j];
                let mj = &m[j];
                for c in 0..N_STATES {
                    acc[c] -= coef * mj[c];
                }
            }
            ps[i] = acc;
        }
    }
    // Apply e_s to the stored state exactly as the filter's feedback applies δx̂.
    let mut nav = rec.nav;
    let mut sensors = rec.sensors;
    super::eskf::apply_error_state(&mut nav, &mut sensors, &e_s);
    Ok((SmoothedEpoch { nav, sensors, std }, e_s))
}

/// Full smoothing of the segments `bounds` (b_0 < b_1 < …), starting from the adjoint
/// `adj` = λ⁺, Λ⁺ at the last boundary. Writes epochs (b_0, b_last] into `out`
/// (`out[k − offset]`), plus epoch 0 when b_0 = 0 and `offset` = 0.
fn sweep(
    ctx: &Ctx,
    bounds: &[usize],
    mut adj: Adjoint,
    out: &mut [SmoothedEpoch],
    offset: usize,
    stride: usize,
    visit: &mut dyn FnMut(usize, &Cov),
) -> Result<(), NavError> {
    let n = ctx.run.epochs.len();
    let mut ps = [[0.0; N_STATES]; N_STATES];
    let mut scratch_p: Vec<Cov> = Vec::new();
    let mut scratch_t: Vec<Transition> = Vec::new();
    for w in bounds.windows(2).rev() {
        let (a, b) = (w[0], w[1]);
        let upd_b = ctx.upd_at(b).copied();
        // Checkpoints every CHUNK epochs: P at a, a + CHUNK, … (all < b).
        let mut checkpoints: Vec<Cov> = vec![ctx.p_post_at(a)];
        let mut p = checkpoints[0];
        let mut k = a;
        while k + CHUNK < b {
            for j in (k + 1)..=(k + CHUNK) {
                ctx.transition(j)?.propagate(&mut p, &ctx.q);
            }
            k += CHUNK;
            checkpoints.push(p);
        }
        for (ci, cp) in checkpoints.iter().enumerate().rev() {
            let c0 = a + ci * CHUNK;
            let c1 = (c0 + CHUNK).min(b);
            // Re-propagate P_c0 … P⁻_c1 with the transitions c0+1 … c1.
            scratch_p.clear();
            scratch_t.clear();
            let mut p = *cp;
            scratch_p.push(p);
            for j in (c0 + 1)..=c1 {
                let t = ctx.transition(j)?;
                t.propagate(&mut p, &ctx.q);
                scratch_p.push(p);
                scratch_t.push(t);
            }
            if c1 == b
                && let Some(u) = &upd_b
            {
                let stored = unpack(&ctx.run.updates[u.first].p_prior);
                check_rebuild(ctx, &p, &stored, a, b)?;
            }
            for k in ((c0 + 1)..=c1).rev() {
                let at_upd = if k == b { upd_b } else { None };
                let post;
                let pk = match &at_upd {
                    Some(u) => {
                        post = unpack(&ctx.run.updates[u.last].p_post);
                        &post
                    }
                    None => &scratch_p[k - c0],
                };
                let want_full = at_upd.is_some() || (stride > 0 && (k % stride == 0 || k == n - 1));
                let (ep, e_s) = output(ctx, k, pk, &adj, want_full.then_some(&mut ps))?;
                if stride > 0 && (k % stride == 0 || k == n - 1) {
                    visit(k, &ps);
                }
                out[k - offset] = ep;
                if let Some(u) = &at_upd {
                    ctx.to_prior(u, &mut adj, &e_s, &ps)?;
                }
                adjoint_step(&scratch_t[k - c0 - 1], &mut adj);
            }
        }
        if a == 0 && offset == 0 {
            let p0 = ctx.p_post_at(0);
            let (ep, _) = output(ctx, 0, &p0, &adj, (stride > 0).then_some(&mut ps))?;
            if stride > 0 {
                visit(0, &ps);
            }
            out[0] = ep;
        }
    }
    Ok(())
}

fn check_rebuild(ctx: &Ctx, p: &Cov, stored: &Cov, a: usize, b: usize) -> Result<(), NavError> {
    for i in 0..N_STATES {
        for j in i..N_STATES {
            let scale = (stored[i][i] * stored[j][j]).sqrt();
            let close = (p[i][j] - stored[i][j]).abs() <= REBUILD_TOL * scale;
            if !close {
                return Err(NavError::Config(format!(
                    "smoother: covariance re-propagated over epochs {a}..{b} (t = {} s) differs \
                     from the forward pass's prior at P[{i}][{j}] ({:e} vs {:e}): not the \
                     configuration of the forward run, or updates not recorded",
                    ctx.run.epochs[b].nav.time_s, p[i][j], stored[i][j]
                )));
            }
        }
    }
    Ok(())
}

/// Cholesky factor of a symmetric positive-definite matrix with Jacobi scaling
/// (P = S L Lᵀ S, S = diag(√P_ii)), which keeps the factorisation accurate for the
/// 10¹⁴ spread of variances between position and sensor states.
struct Chol {
    l: Cov,
    s: [f64; N_STATES],
}

impl Chol {
    fn new(p: &Cov) -> Result<Chol, String> {
        let mut s = [0.0; N_STATES];
        for i in 0..N_STATES {
            let v = p[i][i];
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("variance {i} is {v:e}"));
            }
            s[i] = v.sqrt();
        }
        let mut l = [[0.0; N_STATES]; N_STATES];
        for j in 0..N_STATES {
            let mut d = p[j][j] / (s[j] * s[j]);
            for k in 0..j {
                d -= l[j][k] * l[j][k];
            }
            let positive = d > 1e-15;
            if !positive {
                return Err(format!(
                    "not positive definite: scaled Cholesky pivot {j} is {d:e}"
                ));
            }
            let djj = d.sqrt();
            l[j][j] = djj;
            for i in (j + 1)..N_STATES {
                let mut v = 0.5 * (p[i][j] + p[j][i]) / (s[i] * s[j]);
                for k in 0..j {
                    v -= l[i][k] * l[j][k];
                }
                l[i][j] = v / djj;
            }
        }
        Ok(Chol { l, s })
    }

    /// x = P⁻¹ b.
    fn solve(&self, b: &[f64; N_STATES]) -> [f64; N_STATES] {
        let l = &self.l;
        let mut y: [f64; N_STATES] = std::array::from_fn(|i| b[i] / self.s[i]);
        for i in 0..N_STATES {
            let mut v = y[i];
            for k in 0..i {
                v -= l[i][k] * y[k];
            }
            y[i] = v / l[i][i];
        }
        for i in (0..N_STATES).rev() {
            let mut v = y[i];
            for k in (i + 1)..N_STATES {
                v -= l[k][i] * y[k];
            }
            y[i] = v / l[i][i];
        }
        std::array::from_fn(|i| y[i] / self.s[i])
    }
}

//! Gyro calibration from the rotations between static intervals: the gravity direction
//! carried through each move, the scale search and the Levenberg–Marquardt fit of the gyro
//! triad (module docs of [`super`]).

use super::*;

/// exp([φ×]) (Rodrigues).
pub(super) fn rot_exp(phi: Vec3) -> Mat3 {
    let t2 = dot(phi, phi);
    let (a, b) = if t2 < 1e-12 {
        (1.0 - t2 / 6.0, 0.5 - t2 / 24.0)
    } else {
        let t = t2.sqrt();
        (t.sin() / t, (1.0 - t.cos()) / t2)
    };
    let k = Mat3::skew(phi);
    let k2 = k.mul_mat(&k);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = f64::from(u8::from(i == j)) + a * k.0[i][j] + b * k2.0[i][j];
        }
    }
    Mat3(r)
}

/// One move between static intervals, prepared for the gyro fit.
pub(super) struct Move {
    /// Bias-removed trapezoidal raw increment ((raw_k + raw_{k+1})/2 − b_g)·Δt per step,
    /// raw·s; multiplied by the scale in use before the matrix fit.
    pub(super) w: Vec<Vec3>,
    /// Calibrated gravity direction at the start.
    pub(super) u0: Vec3,
    /// Measured gravity direction at the end.
    pub(super) u1: Vec3,
    /// Basis of the plane ⟂ the measured direction at the end.
    pub(super) e1: Vec3,
    pub(super) e2: Vec3,
    /// Σ_k ‖w_k‖ (the path length of the raw increments), raw·s.
    pub(super) path_raw_s: f64,
    /// |Σ_k w_k| per axis, raw·s.
    pub(super) net_raw_s: Vec3,
}

pub(super) fn perp_basis(u: Vec3) -> (Vec3, Vec3) {
    let a = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = cross(u, a);
    let n1 = norm(e1);
    let e1 = e1.map(|v| v / n1);
    (e1, cross(u, e1))
}

pub(super) fn angle_between(a: Vec3, b: Vec3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Carries u0 through the move with G; returns the predicted direction Rᵀu0 and, when
/// `jac` is asked, the 9 derivative vectors ∂û/∂G_jl (row-major j, l).
pub(super) fn carry(g: &Mat3, mv: &Move, want_jac: bool) -> (Vec3, [Vec3; 9]) {
    let mut p = Mat3::IDENTITY;
    let mut acc = [[0.0; 3]; 9];
    for wk in &mv.w {
        p = p.mul_mat(&rot_exp(g.mul_vec(*wk)));
        if want_jac {
            for j in 0..3 {
                let col = [p.0[0][j], p.0[1][j], p.0[2][j]];
                for l in 0..3 {
                    let s = wk[l];
                    let a = &mut acc[3 * j + l];
                    a[0] += col[0] * s;
                    a[1] += col[1] * s;
                    a[2] += col[2] * s;
                }
            }
        }
    }
    let pt = p.t();
    let pred = pt.mul_vec(mv.u0);
    let mut d = [[0.0; 3]; 9];
    if want_jac {
        for (dv, a) in d.iter_mut().zip(&acc) {
            *dv = pt.mul_vec(cross(mv.u0, *a));
        }
    }
    (pred, d)
}

/// The gyro bias from the initial rest and the moves between static intervals.
pub(super) struct GyroPrep {
    pub(super) bias: Vec3,
    pub(super) bias_var: Vec3,
    pub(super) moves: Vec<Move>,
}

pub(super) fn prepare_gyro(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<GyroPrep, CalibError> {
    let n = gyro_raw.len();
    if time_s.len() != n {
        return Err(CalibError::BadInput(format!(
            "{} time stamps for {n} gyro samples",
            time_s.len()
        )));
    }
    if intervals.len() < 2 {
        return Err(CalibError::TooFewIntervals {
            found: intervals.len(),
            needed: 2,
        });
    }
    if intervals.iter().any(|iv| iv.end > n || iv.start >= iv.end) {
        return Err(CalibError::BadInput(
            "a static interval lies outside the gyro log".into(),
        ));
    }
    let last_end = intervals[intervals.len() - 1].end;
    if let Some(k) = (0..last_end).find(|&k| gyro_raw[k].iter().any(|v| !v.is_finite())) {
        return Err(CalibError::BadInput(format!(
            "non-finite gyro sample at {:.3} s (sample {}): remove or repair that row",
            time_s[k],
            k + 1
        )));
    }
    // Rails: the rest and every move.
    if let Some([lo, hi]) = opts.gyro_range_raw {
        let last = intervals[intervals.len() - 1].start;
        for (k, w) in gyro_raw[..last].iter().enumerate() {
            if let Some(j) = (0..3).find(|&j| w[j] <= lo || w[j] >= hi) {
                let i = intervals.iter().rposition(|iv| iv.start <= k).unwrap_or(0);
                return Err(CalibError::Saturated {
                    sensor: "gyro",
                    axis: AXES[j],
                    value_raw: w[j],
                    time_s: time_s[k],
                    where_: format!(", between static intervals {i} and {}", i + 1),
                });
            }
        }
    }
    // Bias: mean over the initial rest, σ from 10 block means.
    let rest = &intervals[0];
    let len = rest.len();
    let mut bias = [0.0; 3];
    for w in &gyro_raw[rest.start..rest.end] {
        for j in 0..3 {
            bias[j] += w[j] / len as f64;
        }
    }
    let nb = 10.min(len / 2).max(2);
    let bl = (len / nb).max(1);
    let mut bias_var = [0.0; 3];
    for b in 0..nb {
        let seg = &gyro_raw[rest.start + b * bl..(rest.start + (b + 1) * bl).min(rest.end)];
        for j in 0..3 {
            let m = seg.iter().map(|w| w[j]).sum::<f64>() / seg.len().max(1) as f64;
            bias_var[j] += (m - bias[j]).powi(2) / ((nb - 1) as f64 * nb as f64);
        }
    }
    let dir = |iv: &StaticInterval| {
        let a = accel.apply(iv.mean_accel_raw);
        let nn = norm(a).max(1e-300);
        a.map(|v| v / nn)
    };
    let mut moves = Vec::with_capacity(intervals.len() - 1);
    for pair in intervals.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let (k0, k1) = (a.end - 1, b.start);
        let mut w = Vec::with_capacity(k1.saturating_sub(k0));
        let mut tot = [0.0; 3];
        let mut path = 0.0;
        for k in k0..k1 {
            let dt = time_s[k + 1] - time_s[k];
            let v: Vec3 =
                [0, 1, 2].map(|j| (0.5 * (gyro_raw[k][j] + gyro_raw[k + 1][j]) - bias[j]) * dt);
            for j in 0..3 {
                tot[j] += v[j];
            }
            path += norm(v);
            w.push(v);
        }
        let u1 = dir(b);
        let (e1, e2) = perp_basis(u1);
        moves.push(Move {
            w,
            u0: dir(a),
            u1,
            e1,
            e2,
            path_raw_s: path,
            net_raw_s: tot.map(f64::abs),
        });
    }
    Ok(GyroPrep {
        bias,
        bias_var,
        moves,
    })
}

/// The isotropic gyro scale s (rad/s per raw unit) found from the data; see
/// [`estimate_gyro_scale`].
#[derive(Clone, Debug, PartialEq)]
pub struct GyroScaleEstimate {
    /// s, rad/s per raw unit.
    pub scale_rad_s_per_raw: f64,
    /// RMS gravity-direction angle over the moves with M_g = s·I, rad.
    pub gravity_angle_rms_rad: f64,
    /// The best other scale (a separate minimum more than 15 % away) and its RMS angle,
    /// rad: how clearly the data single out s.
    pub runner_up: Option<(f64, f64)>,
    /// Moves that tilt the gravity direction by at least 10°.
    pub tilting_moves: usize,
}

/// Smallest gravity-direction change of a move that bounds the scale, rad.
pub(super) const MIN_TILT_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

pub(super) fn scale_cost(moves: &[Move], s: f64) -> f64 {
    let g = Mat3::diag([s; 3]);
    let sum: f64 = moves
        .iter()
        .map(|mv| angle_between(carry(&g, mv, false).0, mv.u1).powi(2))
        .sum();
    (sum / moves.len().max(1) as f64).sqrt()
}

pub(super) fn span(intervals: &[StaticInterval], i: usize) -> String {
    format!(
        "{:.2}–{:.2} s",
        intervals[i].end_time_s,
        intervals[i + 1].start_time_s
    )
}

/// Scale search over the prepared moves (raw increments).
///
/// The gravity directions u_i, u_{i+1} measured by the accelerometer at the ends of move i
/// are θ_i = ∠(u_i, u_{i+1}) apart; the sensor turned by at least θ_i, and by at most
/// s·L_i, L_i = Σ_k ‖w_k‖ the path length of the raw increments. So s ≥ θ_i / L_i for
/// every move, and s is searched on a 2 % log grid over [½, 20]·max_i θ_i/L_i (moves with
/// θ_i ≥ 10°) for the smallest RMS over the moves of ∠(R(s)ᵀu_i, u_{i+1}) with
/// R(s) = Π_k exp([s·w_k ×]), then refined by golden section. Moves of different angles
/// alias at different scales (a turn by θ about one axis is also matched by
/// s' = s·(1 + 2πk/θ)), so the global minimum is unique when the moves differ; a second
/// minimum more than 15 % away with less than twice the best RMS angle is an error.
pub(super) fn search_scale(
    moves: &[Move],
    intervals: &[StaticInterval],
    opts: &MultiPositionOptions,
) -> Result<GyroScaleEstimate, CalibError> {
    let tilts: Vec<f64> = moves.iter().map(|m| angle_between(m.u0, m.u1)).collect();
    let total: f64 = tilts.iter().sum();
    let tilting: Vec<usize> = (0..moves.len())
        .filter(|&i| tilts[i] >= MIN_TILT_RAD)
        .collect();
    if total < opts.min_rotation_rad || tilting.len() < 3 {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the gravity direction turns by only {:.1}° in total over {} moves ({} of them by 10° or more; need {:.0}° and 3 such moves), so the rotations cannot fix the gyro scale: tilt the sensor between poses (about horizontal axes), or set the gyro scale guess",
                total.to_degrees(),
                moves.len(),
                tilting.len(),
                opts.min_rotation_rad.to_degrees()
            ),
        });
    }
    if let Some(&i) = tilting.iter().find(|&&i| moves[i].path_raw_s <= 0.0) {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the gyro reads no rotation over {} although the gravity direction turns by {:.1}° there: check that the gyro log was recorded with the accelerometer log (same time base)",
                span(intervals, i),
                tilts[i].to_degrees()
            ),
        });
    }
    let bound = tilting
        .iter()
        .map(|&i| tilts[i] / moves[i].path_raw_s)
        .fold(0.0, f64::max);
    let (lo, hi) = ((0.5 * bound).ln(), (20.0 * bound).ln());
    let step = 0.02f64;
    let n = ((hi - lo) / step).ceil() as usize + 1;
    let grid: Vec<f64> = (0..n).map(|i| lo + step * i as f64).collect();
    let cost: Vec<f64> = grid.iter().map(|&l| scale_cost(moves, l.exp())).collect();
    let ibest = (0..n)
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]))
        .unwrap_or(0);
    // Golden section on ln s around the grid minimum.
    let (mut a, mut b) = (grid[ibest] - step, grid[ibest] + step);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (scale_cost(moves, c.exp()), scale_cost(moves, d.exp()));
    for _ in 0..30 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = scale_cost(moves, c.exp());
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = scale_cost(moves, d.exp());
        }
    }
    let (l_best, f_best) = if fc < fd { (c, fc) } else { (d, fd) };
    let (l_best, f_best) = if f_best <= cost[ibest] {
        (l_best, f_best)
    } else {
        (grid[ibest], cost[ibest])
    };
    let runner_up = (0..n)
        .filter(|&i| {
            (grid[i] - l_best).abs() > 0.15
                && (i == 0 || cost[i] <= cost[i - 1])
                && (i + 1 == n || cost[i] <= cost[i + 1])
        })
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]))
        .map(|i| (grid[i].exp(), cost[i]));
    let s = l_best.exp();
    if ibest == 0 || ibest + 1 == n {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "the best scale lies at the edge of the searched range {:.4e}…{:.4e} rad/s per raw unit (RMS gravity angle {:.2}°): the moves' rotations do not fit the gravity directions; check the gyro log's time base and axes, or set the gyro scale guess",
                grid[0].exp(),
                grid[n - 1].exp(),
                f_best.to_degrees()
            ),
        });
    }
    if f_best > opts.max_scale_search_angle_rad {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "no single scale makes the integrated gyro carry the gravity direction from pose to pose (best {:.4e} rad/s per raw unit leaves an RMS angle of {:.1}°, limit {:.1}°): check that the gyro log was recorded with the accelerometer log (same time base), that its axes match the accelerometer's, and that it is not clipped during the moves; or set the gyro scale guess",
                s,
                f_best.to_degrees(),
                opts.max_scale_search_angle_rad.to_degrees()
            ),
        });
    }
    if let Some((s2, f2)) = runner_up
        && f2 < 2.0 * f_best
    {
        return Err(CalibError::Unobservable {
            sensor: "gyro",
            parameter: "scale".into(),
            reason: format!(
                "two gyro scales fit the moves about equally well ({s:.4e} rad/s per raw unit: RMS {:.2}°; {s2:.4e}: {:.2}°), so the rotations do not single one out: add moves of different sizes about different axes, or set the gyro scale guess",
                f_best.to_degrees(),
                f2.to_degrees()
            ),
        });
    }
    Ok(GyroScaleEstimate {
        scale_rad_s_per_raw: s,
        gravity_angle_rms_rad: f_best,
        runner_up,
        tilting_moves: tilting.len(),
    })
}

/// Finds the gyro scale s (rad/s per raw unit) of a multi-position log from the data: the
/// accelerometer fixes the tilt between consecutive static intervals, the integrated raw
/// gyro gives the same rotation in raw units (see the search in the module source:
/// bounds s ≥ θ_i/L_i, log grid, golden section, uniqueness check). Errors when the
/// moves cannot identify it: too little tilt in total, no rotation read by the gyro while
/// gravity turns, no scale that fits (wrong log, axes or clipping), or two scales that
/// fit alike.
pub fn estimate_gyro_scale(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<GyroScaleEstimate, CalibError> {
    let prep = prepare_gyro(time_s, gyro_raw, intervals, accel, opts)?;
    search_scale(&prep.moves, intervals, opts)
}

/// Gyro fit of the module equations. `intervals` must come from the same log (their
/// sample ranges index `time_s` and `gyro_raw`), the first being the initial rest;
/// `accel` calibrates the interval means to gravity directions. The starting matrix is
/// s·I with s = [`MultiPositionOptions::gyro_scale_guess_rad_s_per_raw`], or, when that
/// is `None`, the scale found by [`estimate_gyro_scale`].
pub fn calibrate_gyro(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<TriadFit, CalibError> {
    gyro_fit(time_s, gyro_raw, intervals, accel, opts).map(|(fit, _)| fit)
}

pub(super) fn gyro_fit(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    accel: &TriadCalibration,
    opts: &MultiPositionOptions,
) -> Result<(TriadFit, Option<GyroScaleEstimate>), CalibError> {
    const NAMES: [&str; 12] = [
        "bias x", "bias y", "bias z", "M00", "M01", "M02", "M10", "M11", "M12", "M20", "M21", "M22",
    ];
    if let Some(s0) = opts.gyro_scale_guess_rad_s_per_raw
        && !(s0 > 0.0 && s0.is_finite())
    {
        return Err(CalibError::BadInput(format!(
            "gyro scale guess {s0}: give a positive rad/s per raw unit, or none to find it from the data"
        )));
    }
    let GyroPrep {
        bias,
        bias_var,
        mut moves,
    } = prepare_gyro(time_s, gyro_raw, intervals, accel, opts)?;
    let (s0, estimate) = match opts.gyro_scale_guess_rad_s_per_raw {
        Some(s0) => (s0, None),
        None => {
            let e = search_scale(&moves, intervals, opts)?;
            (e.scale_rad_s_per_raw, Some(e))
        }
    };
    let mut net = [0.0; 3];
    for mv in &mut moves {
        for w in &mut mv.w {
            *w = w.map(|v| v * s0);
        }
        for (n, r) in net.iter_mut().zip(mv.net_raw_s) {
            *n += r * s0;
        }
    }
    for j in 0..3 {
        if net[j] < opts.min_rotation_rad {
            return Err(CalibError::Unobservable {
                sensor: "gyro",
                parameter: format!("{} scale", AXES[j]),
                reason: format!(
                    "the moves between static intervals rotate the sensor by only {:.1}° in total about the {} axis (need {:.0}°); rotate it between poses",
                    net[j].to_degrees(),
                    AXES[j],
                    opts.min_rotation_rad.to_degrees()
                ),
            });
        }
    }
    let m = 2 * moves.len();
    let f = |p: &[f64], r: &mut [f64], jac: Option<&mut [f64]>| {
        let gm = Mat3([[p[0], p[1], p[2]], [p[3], p[4], p[5]], [p[6], p[7], p[8]]]);
        let mut jac = jac;
        let want = jac.is_some();
        for (i, mv) in moves.iter().enumerate() {
            let (pred, d) = carry(&gm, mv, want);
            r[2 * i] = dot(mv.e1, pred);
            r[2 * i + 1] = dot(mv.e2, pred);
            if let Some(j) = jac.as_deref_mut() {
                for q in 0..9 {
                    j[2 * i * 9 + q] = dot(mv.e1, d[q]);
                    j[(2 * i + 1) * 9 + q] = dot(mv.e2, d[q]);
                }
            }
        }
    };
    let p0 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let fit =
        levenberg_marquardt(&p0, m, &opts.lm, f).map_err(|e| lsq_error("gyro", e, &NAMES[3..]))?;
    let mut params = bias.to_vec();
    params.extend(fit.params.iter().map(|v| v * s0));
    let mut cov = vec![0.0; 144];
    for j in 0..3 {
        cov[j * 12 + j] = bias_var[j];
    }
    for a in 0..9 {
        for b in 0..9 {
            cov[(3 + a) * 12 + 3 + b] = fit.covariance[a * 9 + b] * s0 * s0;
        }
    }
    let gm = &params[3..];
    let calibration = TriadCalibration {
        bias,
        matrix: Mat3([
            [gm[0], gm[1], gm[2]],
            [gm[3], gm[4], gm[5]],
            [gm[6], gm[7], gm[8]],
        ]),
    };
    Ok((
        TriadFit {
            calibration,
            param_names: NAMES.to_vec(),
            params,
            param_covariance: cov.clone(),
            bm_covariance: cov,
            residual_rms: fit.rms,
            iterations: fit.iterations,
        },
        estimate,
    ))
}

/// For each move, the gravity direction at its start carried by the calibrated gyro to
/// its end, R_iᵀu_i, and the one measured there, u_{i+1} (both unit vectors).
pub(super) fn carried_directions(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    cal: &ImuCalibration,
) -> Vec<(Vec3, Vec3)> {
    let dir = |iv: &StaticInterval| {
        let a = cal.accel.apply(iv.mean_accel_raw);
        let nn = norm(a).max(1e-300);
        a.map(|v| v / nn)
    };
    intervals
        .windows(2)
        .map(|pair| {
            let (a, b) = (&pair[0], &pair[1]);
            let mut p = Mat3::IDENTITY;
            for k in (a.end - 1)..b.start {
                let dt = time_s[k + 1] - time_s[k];
                let w0 = cal.gyro.apply(gyro_raw[k]);
                let w1 = cal.gyro.apply(gyro_raw[k + 1]);
                p = p.mul_mat(&rot_exp([0, 1, 2].map(|j| 0.5 * (w0[j] + w1[j]) * dt)));
            }
            (p.t().mul_vec(dir(a)), dir(b))
        })
        .collect()
}

/// RMS angle (rad) between the gravity direction carried by the calibrated gyro across
/// each move and the one measured by the calibrated accelerometer at its end.
pub fn gravity_angle_rms(
    time_s: &[f64],
    gyro_raw: &[Vec3],
    intervals: &[StaticInterval],
    cal: &ImuCalibration,
) -> f64 {
    let pairs = carried_directions(time_s, gyro_raw, intervals, cal);
    let s: f64 = pairs
        .iter()
        .map(|(p, m)| angle_between(*p, *m).powi(2))
        .sum();
    (s / pairs.len().max(1) as f64).sqrt()
}

//! Initial state of a session: static or moving start, levelling and the initial velocity.

use super::*;

/// Velocity of a candidate start fix and the σ that go with it (module docs).
pub(super) struct StartVelocity {
    /// NED velocity, m/s.
    pub(super) v: Vec3,
    /// σ of one horizontal velocity component, m/s.
    pub(super) sigma_h_m_s: f64,
    /// σ of the vertical component, m/s.
    pub(super) sigma_v_m_s: f64,
    /// Angle between the chords of the two halves of the baseline, rad (0 for GNSS
    /// velocity).
    pub(super) turn_rad: f64,
}

impl StartVelocity {
    /// Course σ σ_ψ = √((σ_vH/v_H)² + (δ/2)²), floored at 1°.
    pub(super) fn heading_sigma_rad(&self) -> f64 {
        let vh = self.v[0].hypot(self.v[1]);
        (self.sigma_h_m_s / vh)
            .hypot(0.5 * self.turn_rad)
            .max(1f64.to_radians())
    }
}

/// Initial state at the first usable GNSS fix (module docs: given or levelled attitude,
/// course over ground at speed).
///
/// Errors: no usable fix (names the speed reached and what to change), or a given
/// attitude that is not finite.
pub fn initialise(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
) -> Result<InitialState, NavError> {
    initialise_at(imu, gnss, cfg, primed_gyro_bias, None)
}

/// [`initialise`], or with `start_s` at the fix of that time whatever its speed and
/// course σ (the second pass of an estimated σ floor starts where the first did, its σ
/// recomputed from the floored fixes).
pub(super) fn initialise_at(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
    start_s: Option<f64>,
) -> Result<InitialState, NavError> {
    let fcfg = &cfg.filter;
    let fixes = StartFixes::new(imu, gnss, cfg);
    let given_yaw = given_yaw(cfg)?;
    let (i, sv) = select_start(&fixes, cfg, given_yaw, start_s)?;
    let t_start = gnss.time_s[i];
    let (att, sigma_att_rad) =
        initial_attitude(imu, gnss, cfg, primed_gyro_bias, given_yaw, &sv, t_start);
    let q_bn = att.to_quat();
    let (lat_rad, lon_rad, height_m) = imu_position(gnss, i, q_bn.rotate(fcfg.lever_arm_b_m));
    let nav = NavState {
        time_s: t_start,
        lat_rad,
        lon_rad,
        height_m,
        vel_ned_m_s: sv.v,
        q_bn,
    };
    let (sensors, sigma_sensors) = initial_sensors(cfg, primed_gyro_bias);
    let (sh, sv_pos) = fixes.sigma_fix(i);
    // The chord is the mean velocity over the baseline: allow 0.3 m/s for the change of
    // velocity over it (and GNSS velocity 0.1 m/s at least).
    let floor_v = if gnss.vel_ned_m_s.is_some() { 0.1 } else { 0.3 };
    Ok(InitialState {
        nav,
        sensors,
        sigma_pos_ned_m: [sh.max(0.05), sh.max(0.05), sv_pos.max(0.1)],
        sigma_vel_ned_m_s: [
            sv.sigma_h_m_s.max(floor_v),
            sv.sigma_h_m_s.max(floor_v),
            sv.sigma_v_m_s.max(floor_v),
        ],
        sigma_att_rad,
        sigma_sensors,
    })
}

/// The GNSS fixes as candidates for the start: which are usable, their σ and velocity.
struct StartFixes<'a> {
    gnss: &'a GnssFixes,
    cfg: &'a SessionConfig,
    /// Time of the first IMU epoch, s (+∞ without epochs).
    imu_start: f64,
    /// Time of the last IMU epoch, s (−∞ without epochs).
    imu_end: f64,
}

impl<'a> StartFixes<'a> {
    /// The candidates among `gnss` for the IMU span of `imu`.
    fn new(imu: &ImuStream, gnss: &'a GnssFixes, cfg: &'a SessionConfig) -> Self {
        let imu_start = imu
            .epochs
            .first()
            .map(|e| e.time_s)
            .unwrap_or(f64::INFINITY);
        let imu_end = imu
            .epochs
            .last()
            .map(|e| e.time_s)
            .unwrap_or(f64::NEG_INFINITY);
        StartFixes {
            gnss,
            cfg,
            imu_start,
            imu_end,
        }
    }

    /// Fix `i` usable for the chord: a fix the filter would use (outside the outage
    /// windows, of an accepted quality).
    fn fix_ok(&self, i: usize) -> bool {
        let (gnss, cfg) = (self.gnss, self.cfg);
        let fcfg = &cfg.filter;
        let in_outage = |t: f64| cfg.outages.iter().any(|w| w.contains(t));
        let quality_ok = |i: usize| {
            fcfg.accept_quality.is_empty() || fcfg.accept_quality.contains(&gnss.quality[i])
        };
        !in_outage(gnss.time_s[i]) && quality_ok(i)
    }

    /// (horizontal, vertical) σ of fix `i` after the quality scaling, m.
    fn sigma_fix(&self, i: usize) -> (f64, f64) {
        let k = self.cfg.filter.quality_scale.factor(self.gnss.quality[i]);
        let s = self.gnss.sigma_ned_m[i];
        (s[0].max(s[1]) * k, s[2] * k)
    }

    /// Fix `i` usable as the start: inside the IMU span (0.05 s after its start, 1 s
    /// before its end) and usable for the chord.
    fn usable(&self, i: usize) -> bool {
        let t = self.gnss.time_s[i];
        t > self.imu_start + 0.05 && t < self.imu_end - 1.0 && self.fix_ok(i)
    }

    /// Velocity at fix `i` with its σ: the GNSS velocity when given, else the chord
    /// between the fixes at the ends of the alignment baseline around it and the turn
    /// between the chords of its halves; `None` when unusable.
    fn velocity(&self, i: usize) -> Option<StartVelocity> {
        let (gnss, cfg) = (self.gnss, self.cfg);
        if let Some(v) = gnss.vel_ned_m_s.as_ref() {
            let (sh, sv) = match gnss.sigma_vel_ned_m_s.as_ref() {
                Some(s) => (s[i][0].max(s[i][1]), s[i][2]),
                None => (0.1, 0.1),
            };
            let k = cfg.filter.quality_scale.factor(gnss.quality[i]);
            return Some(StartVelocity {
                v: v[i],
                sigma_h_m_s: sh * k,
                sigma_v_m_s: sv * k,
                turn_rad: 0.0,
            });
        }
        let n = gnss.time_s.len();
        let half = 0.5 * cfg.align_baseline_s;
        let t = gnss.time_s[i];
        let a = gnss.time_s.partition_point(|&x| x < t - half - 1e-9);
        let b = gnss.time_s.partition_point(|&x| x <= t + half + 1e-9) - 1;
        if a >= i || b <= i || b >= n || !self.fix_ok(a) || !self.fix_ok(b) {
            return None;
        }
        let (ta, tb) = (gnss.time_s[a], gnss.time_s[b]);
        if cfg.outages.iter().any(|w| w.end_s > ta && w.start_s < tb) {
            return None;
        }
        let llh = |j: usize| (gnss.lat_rad[j], gnss.lon_rad[j], gnss.height_m[j]);
        let d = ned_offset_m(llh(a), llh(b));
        let d1 = ned_offset_m(llh(a), llh(i));
        let d2 = ned_offset_m(llh(i), llh(b));
        let v = scale(d, 1.0 / (tb - ta));
        let mut turn = d2[1].atan2(d2[0]) - d1[1].atan2(d1[0]);
        turn = (turn + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        let ((ha, va), (hb, vb)) = (self.sigma_fix(a), self.sigma_fix(b));
        let ok = v.iter().all(|x| x.is_finite()) && turn.is_finite();
        ok.then(|| StartVelocity {
            v,
            sigma_h_m_s: ha.hypot(hb) / (tb - ta),
            sigma_v_m_s: va.hypot(vb) / (tb - ta),
            turn_rad: turn.abs(),
        })
    }
}

/// The given heading, rad (of the given attitude, else the given yaw), if any; an error
/// when the given attitude or yaw is not finite.
fn given_yaw(cfg: &SessionConfig) -> Result<Option<f64>, NavError> {
    let given_yaw = cfg
        .initial_attitude_rad
        .map(|a| a[2])
        .or(cfg.initial_yaw_rad);
    if let Some(a) = cfg.initial_attitude_rad
        && !a.iter().all(|v| v.is_finite())
    {
        return Err(NavError::Config(format!(
            "initial attitude {a:?} rad is not finite"
        )));
    }
    if given_yaw.is_some_and(|y| !y.is_finite()) {
        return Err(NavError::Config("initial yaw is not finite".into()));
    }
    Ok(given_yaw)
}

/// The start fix and its velocity: the fix at `start_s` when given, else the first usable
/// fix with a velocity (with a given heading) or fast enough with a small enough course σ;
/// an alignment error naming the speed reached and what to change when there is none.
fn select_start(
    fixes: &StartFixes,
    cfg: &SessionConfig,
    given_yaw: Option<f64>,
    start_s: Option<f64>,
) -> Result<(usize, StartVelocity), NavError> {
    let gnss = fixes.gnss;
    let n = gnss.time_s.len();
    let mut fastest: Option<(f64, f64)> = None;
    let start = (0..n).filter(|&i| fixes.usable(i)).find_map(|i| {
        if let Some(t) = start_s {
            return ((gnss.time_s[i] - t).abs() < 1e-6)
                .then(|| fixes.velocity(i).map(|sv| (i, sv)))
                .flatten();
        }
        let sv = fixes.velocity(i)?;
        if given_yaw.is_some() {
            return Some((i, sv));
        }
        let vh = sv.v[0].hypot(sv.v[1]);
        if fastest.is_none_or(|(v, _)| vh > v) {
            fastest = Some((vh, gnss.time_s[i]));
        }
        (vh > cfg.min_speed_m_s && sv.heading_sigma_rad() <= cfg.max_heading_sigma_rad)
            .then_some((i, sv))
    });
    start.ok_or_else(|| {
        let reached = match fastest {
            Some((v, t)) => format!("the fastest usable fix moves at {v:.2} m/s (t = {t} s)"),
            None => "no fix inside the IMU span has a velocity (GNSS velocity, or fixes on \
                     both sides within the alignment baseline)"
                .to_string(),
        };
        NavError::Alignment(format!(
            "no GNSS fix to initialise the heading from: it needs a horizontal speed above \
             {} m/s with a course σ ≤ {:.1}°, and {reached}; pass the initial heading \
             (--initial-yaw-deg) or lower the alignment speed (--align-min-speed)",
            cfg.min_speed_m_s,
            cfg.max_heading_sigma_rad.to_degrees()
        ))
    })
}

/// Initial attitude and its σ (roll, pitch, yaw), rad: heading given or the course over
/// ground; tilt given, levelled ([`levelled_tilt`]) or, failing that, zero roll and the
/// flight-path pitch atan2(−v_D, v_H) at speed, σ 2°.
fn initial_attitude(
    imu: &ImuStream,
    gnss: &GnssFixes,
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
    given_yaw: Option<f64>,
    sv: &StartVelocity,
    t_start: f64,
) -> (Euler, [f64; 3]) {
    let v = sv.v;
    let horiz = v[0].hypot(v[1]);
    let (yaw, sigma_yaw) = match given_yaw {
        Some(y) => (y, cfg.given_attitude_sigma_rad[2]),
        None => (v[1].atan2(v[0]), sv.heading_sigma_rad()),
    };
    let (roll, pitch, sigma_roll, sigma_pitch) = match cfg.initial_attitude_rad {
        Some(a) => (
            a[0],
            a[1],
            cfg.given_attitude_sigma_rad[0],
            cfg.given_attitude_sigma_rad[1],
        ),
        None => match levelled_tilt(imu, cfg, primed_gyro_bias, gnss, t_start) {
            Some((r, p, s)) => (r, p, s, s),
            None => {
                let pitch = if horiz > cfg.min_speed_m_s {
                    (-v[2]).atan2(horiz)
                } else {
                    0.0
                };
                (0.0, pitch, 2f64.to_radians(), 2f64.to_radians())
            }
        },
    };
    let att = Euler {
        roll_rad: roll,
        pitch_rad: pitch,
        yaw_rad: yaw,
    };
    (att, [sigma_roll, sigma_pitch, sigma_yaw])
}

/// IMU position (lat, lon rad, h m) at fix `i` from the antenna's, the lever arm `l_n` in
/// NED: r_imu = r_ant − C_bn·l (NED metres converted with the local radii R_M + h, R_N + h).
fn imu_position(gnss: &GnssFixes, i: usize, l_n: Vec3) -> (f64, f64, f64) {
    let (lat_a, lon_a, h_a) = (gnss.lat_rad[i], gnss.lon_rad[i], gnss.height_m[i]);
    let rm = meridian_radius_m(lat_a) + h_a;
    let rn = prime_vertical_radius_m(lat_a) + h_a;
    (
        lat_a - l_n[0] / rm,
        lon_a - l_n[1] / (rn * lat_a.cos()),
        h_a + l_n[2],
    )
}

/// Initial sensor errors and the σ of the 12 sensor states: the primed gyro bias, when
/// given, with its σ at most 0.05°/s; else zero and the configured σ.
fn initial_sensors(
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
) -> (SensorErrors, Option<[f64; 12]>) {
    let fcfg = &cfg.filter;
    let mut sensors = SensorErrors::default();
    let mut sigma_sensors = cfg.initial_sensor_sigma;
    if let Some(b) = primed_gyro_bias {
        sensors.gyro_bias_rad_s = b;
        let n = &fcfg.imu;
        // Primed from ≥ a few seconds of static data: the residual is the Earth rate plus
        // the short-term drift; keep the other sensor states at their initial σ.
        let mut s = cfg
            .initial_sensor_sigma
            .unwrap_or_else(|| fcfg.stationary_sensor_sigma());
        for v in &mut s[..3] {
            *v = (0.05f64.to_radians()).min(n.gyro_bias.sigma);
        }
        sigma_sensors = Some(s);
    }
    (sensors, sigma_sensors)
}

/// Roll, pitch (rad) at `t_start` and their σ from levelling the static start of the log
/// and carrying the tilt forward with the bias-compensated gyro (module docs); `None`
/// when the log does not start static or levelling refuses.
pub(super) fn levelled_tilt(
    imu: &ImuStream,
    cfg: &SessionConfig,
    primed_gyro_bias: Option<Vec3>,
    gnss: &GnssFixes,
    t_start: f64,
) -> Option<(f64, f64, f64)> {
    if cfg.static_prime_s <= 0.0 {
        return None;
    }
    let win = static_start(imu, cfg.static_prime_s)?;
    let n = &cfg.filter.imu;
    let acfg = AlignConfig::new(
        n.gyro_arw_rad_sqrt_s,
        n.gyro_bias.sigma,
        n.accel_vrw_m_s_sqrt_s,
        n.accel_bias.sigma,
    );
    let (lat, h) = (*gnss.lat_rad.first()?, *gnss.height_m.first()?);
    let (roll0, pitch0, sigma_level) = level_static(win, lat, h, &acfg).ok()?;
    let t_static = win.last()?.time_s;
    let t_len: f64 = win.iter().map(|e| e.dt_s).sum();
    // Down vector in the body frame at the end of the static window: C_nb (0, 0, 1).
    let c_bn = Euler {
        roll_rad: roll0,
        pitch_rad: pitch0,
        yaw_rad: 0.0,
    }
    .to_dcm();
    let d0: Vec3 = [c_bn.0[2][0], c_bn.0[2][1], c_bn.0[2][2]];
    // q from the body at t to the body at the end of the static window.
    let b = primed_gyro_bias.unwrap_or([0.0; 3]);
    let mut q = Quat::from_rotation_vector([0.0; 3]);
    let mut dt_total = 0.0;
    for e in imu
        .epochs
        .iter()
        .skip_while(|e| e.time_s <= t_static)
        .take_while(|e| e.time_s <= t_start)
    {
        let dth: Vec3 = std::array::from_fn(|k| e.dtheta_rad[k] - b[k] * e.dt_s);
        q = q.mul(&Quat::from_rotation_vector(dth)).normalized();
        dt_total += e.dt_s;
    }
    let d = q.conj().rotate(d0);
    let roll = d[1].atan2(d[2]);
    let pitch = (-d[0]).atan2(d[1].hypot(d[2]));
    let sigma_w = super::super::earth::OMEGA_IE + n.gyro_arw_rad_sqrt_s / t_len.sqrt();
    Some((roll, pitch, sigma_level.hypot(sigma_w * dt_total)))
}

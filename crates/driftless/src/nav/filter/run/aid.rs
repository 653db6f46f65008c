//! State of the aids between epochs (GNSS speed age, standstill and course-reset
//! bookkeeping).

use super::*;

/// GNSS speeds older than this do not gate the standstill detector, s.
pub(super) const GNSS_SPEED_MAX_AGE_S: f64 = 2.0;

/// Run-time state of the vehicle aids ([`super::super::aids`]).
pub(super) struct AidState {
    pub(super) enabled: bool,
    pub(super) nhc: Option<NhcConfig>,
    pub(super) ss: Option<StandstillConfig>,
    pub(super) detector: Option<StandstillDetector>,
    pub(super) next_nhc_s: f64,
    pub(super) next_zero_s: f64,
    /// Raw angle increment and time accumulated at standstill since the last ZARU.
    pub(super) zaru_dtheta: Vec3,
    pub(super) zaru_dt: f64,
}

impl AidState {
    pub(super) fn new(cfg: &FilterConfig, nominal_dt: f64, t0: f64) -> Result<AidState, NavError> {
        let detector = match &cfg.standstill {
            Some(s) => Some(StandstillDetector::new(s, nominal_dt)?),
            None => None,
        };
        Ok(AidState {
            enabled: cfg.nhc.is_some() || cfg.standstill.is_some(),
            nhc: cfg.nhc,
            ss: cfg.standstill,
            detector,
            next_nhc_s: t0,
            next_zero_s: t0,
            zaru_dtheta: [0.0; 3],
            zaru_dt: 0.0,
        })
    }

    /// Detector, ZUPT/ZARU and NHC after the whole IMU epoch ending at `raw.time_s`
    /// (`raw` the raw increment over the whole epoch).
    pub(super) fn after_epoch(
        &mut self,
        f: &mut Eskf,
        raw: &ImuIncrement,
        ctx: &mut Ctx,
    ) -> Result<(), NavError> {
        const EPS: f64 = 1e-9;
        let t = raw.time_s;
        let mut outcomes: Vec<UpdateOutcome> = Vec::new();
        let mut p_prior = None;
        let mut standstill = false;
        if let (Some(det), Some(ss)) = (&mut self.detector, &self.ss) {
            let comp = f.compensate(raw);
            let inv = 1.0 / raw.dt_s;
            let nav = f.nav();
            let speed = norm(nav.vel_ned_m_s);
            let gate_filter = ss.max_speed_m_s.is_none_or(|v| speed <= v);
            let gate_gnss = match (ss.gnss_speed_max_m_s, ctx.gnss_speed) {
                (Some(vmax), Some((tg, v))) if t - tg <= GNSS_SPEED_MAX_AGE_S => v <= vmax,
                _ => true,
            };
            let g = earth::normal_gravity_m_s2(nav.lat_rad, nav.height_m);
            let c_bn = ss.accel_horizontal_max_m_s2.map(|_| nav.q_bn.to_dcm());
            standstill = det.push(
                t,
                comp.dtheta_rad.map(|v| v * inv),
                comp.dvel_m_s.map(|v| v * inv),
                gate_filter && gate_gnss,
                g,
                c_bn.as_ref(),
            );
            if standstill {
                for k in 0..3 {
                    self.zaru_dtheta[k] += raw.dtheta_rad[k];
                }
                self.zaru_dt += raw.dt_s;
                if t >= self.next_zero_s - EPS {
                    self.next_zero_s = t + ss.interval_s;
                    p_prior = Some(pack(f.covariance()));
                    if let Some(s) = ss.zupt_sigma_m_s {
                        outcomes.push(f.update_zupt(s, ctx.cfg.gate)?);
                    }
                    if let Some(s) = ss.zaru_sigma_rad_s {
                        outcomes.push(f.update_zaru(
                            self.zaru_dtheta,
                            self.zaru_dt,
                            s,
                            ctx.cfg.gate,
                        )?);
                    }
                    self.zaru_dtheta = [0.0; 3];
                    self.zaru_dt = 0.0;
                }
            } else {
                self.zaru_dtheta = [0.0; 3];
                self.zaru_dt = 0.0;
            }
        }
        if let Some(nhc) = &self.nhc
            && !standstill
            && t >= self.next_nhc_s - EPS
        {
            let nav = f.nav();
            let speed = norm(nav.vel_ned_m_s);
            // Vehicle yaw rate ≈ z component of C_vb ω̂_ib (Earth rate negligible here).
            let w_v = nhc.c_vb.mul_vec(f.omega_ib_b_rad_s());
            if speed >= nhc.min_speed_m_s && w_v[2].abs() <= nhc.max_yaw_rate_rad_s {
                self.next_nhc_s = t + nhc.interval_s;
                if p_prior.is_none() {
                    p_prior = Some(pack(f.covariance()));
                }
                outcomes.push(f.update_nhc(
                    &nhc.c_vb,
                    nhc.lever_arm_b_m,
                    nhc.sigma_m_s,
                    nhc.gate.unwrap_or(ctx.cfg.gate),
                )?);
            }
        }
        let Some(p_prior) = p_prior else {
            return Ok(());
        };
        let run = &mut ctx.run;
        for o in &outcomes {
            if o.accepted && o.r_scale > 1.0 {
                run.aids_inflated += 1;
            }
            match (o.accepted, o.kind) {
                (false, _) => run.aids_rejected += 1,
                (true, UpdateKind::Nhc) => run.nhc_applied += 1,
                (true, UpdateKind::Zupt) => run.zupt_applied += 1,
                (true, UpdateKind::Zaru) => run.zaru_applied += 1,
                (true, _) => {}
            }
        }
        let idx = run.epochs.len() - 1;
        let comp = run.epochs[idx].comp;
        run.epochs[idx] = record(f, comp);
        let idx = idx + run.first_epoch;
        let p_post = pack(f.covariance());
        match run.updates.last_mut() {
            // A GNSS update at this very epoch: merge (prior stays the GNSS prior).
            Some(u) if u.epoch_index == idx => {
                u.outcomes.extend(outcomes);
                u.p_post = p_post;
            }
            _ => run.updates.push(UpdateRecord {
                epoch_index: idx,
                time_s: t,
                outcomes,
                p_prior,
                p_post,
            }),
        }
        Ok(())
    }
}

//! One epoch of the forward run: the propagation and the aids applied at it (the run's
//! context, [`Ctx`]).

use super::*;

pub(super) struct Ctx<'a> {
    pub(super) gnss: &'a GnssFixes,
    pub(super) cfg: &'a FilterConfig,
    pub(super) run: ForwardRun,
    /// Time and speed of the latest applied fix with velocity.
    pub(super) gnss_speed: Option<(f64, f64)>,
    /// Time of the latest accepted position fix (the start time before any).
    pub(super) last_position_accept_s: f64,
    /// Time of the latest fix handed to [`Ctx::apply_fix`] (the start time before any).
    pub(super) last_fix_s: f64,
    /// That fix: (time, (lat, lon, h), horizontal σ after the quality scaling).
    pub(super) prev_fix: Option<(f64, (f64, f64, f64), f64)>,
    /// Exponential mean (time constant 1 s) of the raw specific force, body, m/s².
    pub(super) f_mean_b: Option<Vec3>,
    /// Position fixes rejected since the last accepted one.
    pub(super) rejected_in_row: usize,
    /// Of those, the trailing run rejected also by the default robust gate at its
    /// ceiling ([`FilterConfig::gate_recovery_rejections`]).
    pub(super) gross_in_row: usize,
    /// The count rule may fire: false from a fix after an outage window or a gap in the
    /// fixes until the next accepted fix.
    pub(super) count_armed: bool,
}

impl Ctx<'_> {
    /// Fix at `t` withheld by an outage window (start, end].
    pub(super) fn withheld(&self, t: f64) -> bool {
        self.cfg.outages_s.iter().any(|&(a, b)| a < t && t <= b)
    }

    /// Fix `g` not used because of its quality flag.
    pub(super) fn quality_skipped(&self, g: usize) -> bool {
        let q = &self.cfg.accept_quality;
        !q.is_empty() && !q.contains(&self.gnss.quality[g])
    }

    /// Length of (t0, t1] outside every outage window, s.
    pub(super) fn time_outside_windows(&self, t0: f64, t1: f64) -> f64 {
        let mut cut: Vec<(f64, f64)> = self
            .cfg
            .outages_s
            .iter()
            .map(|&(a, b)| (a.max(t0), b.min(t1)))
            .filter(|(a, b)| b > a)
            .collect();
        cut.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (mut inside, mut reach) = (0.0, f64::NEG_INFINITY);
        for (a, b) in cut {
            let a = a.max(reach);
            if b > a {
                inside += b - a;
            }
            reach = reach.max(b);
        }
        (t1 - t0 - inside).max(0.0)
    }

    /// Re-initialise the navigation states at the fix `llh` (module docs, gate recovery);
    /// true when the yaw was taken from the course.
    pub(super) fn reset_to_fix(
        &self,
        f: &mut Eskf,
        llh: [f64; 3],
        sigma: Vec3,
        prev_fix: Option<(f64, (f64, f64, f64), f64)>,
    ) -> Result<bool, NavError> {
        let t = f.nav().time_s;
        let kept_yaw = Euler::from_dcm(&f.nav().q_bn.to_dcm()).yaw_rad;
        let max_chord_s = 2.0 * self.cfg.gate_recovery_s.unwrap_or(0.0);
        let chord = match prev_fix {
            Some((tp, p, sp)) if t - tp > 0.0 && t - tp <= max_chord_s => {
                let d = earth::ned_offset_m(p, (llh[0], llh[1], llh[2]));
                let dt = t - tp;
                Some((
                    d.map(|x| x / dt),
                    (sp.hypot(sigma[0].max(sigma[1])) / dt).max(1.0),
                ))
            }
            _ => None,
        };
        // Yaw from the course when the chord moves and the kept yaw is far from it.
        let course = chord
            .filter(|(v, _)| v[0].hypot(v[1]) >= RESET_COURSE_MIN_SPEED_M_S)
            .map(|(v, _)| v[1].atan2(v[0]))
            .filter(|c| {
                let d = (kept_yaw - c + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                d.abs() > RESET_COURSE_MAX_DIFF_RAD
            });
        let yaw = course.unwrap_or(kept_yaw);
        let (roll, pitch) = match self.f_mean_b {
            Some(fm) if norm(fm) > 1.0 => ((-fm[1]).atan2(-fm[2]), fm[0].atan2(fm[1].hypot(fm[2]))),
            _ => (0.0, 0.0),
        };
        let q_bn = Euler {
            roll_rad: roll,
            pitch_rad: pitch,
            yaw_rad: yaw,
        }
        .to_quat();
        let l_n = q_bn.rotate(self.cfg.lever_arm_b_m);
        let rm = earth::meridian_radius_m(llh[0]) + llh[2];
        let rn = earth::prime_vertical_radius_m(llh[0]) + llh[2];
        let (vel, sigma_v) = chord.unwrap_or(([0.0; 3], 10.0));
        let nav = NavState {
            time_s: t,
            lat_rad: llh[0] - l_n[0] / rm,
            lon_rad: llh[1] - l_n[1] / (rn * llh[0].cos()),
            height_m: llh[2] + l_n[2],
            vel_ned_m_s: vel,
            q_bn,
        };
        let sigma_yaw = if course.is_some() {
            10f64.to_radians()
        } else {
            f.std()[ATT + 2].max(10f64.to_radians())
        };
        let tilt = 5f64.to_radians();
        f.reset_navigation(nav, sigma, [sigma_v; 3], [tilt, tilt, sigma_yaw])?;
        Ok(course.is_some())
    }

    /// Apply fix `g` at the current filter epoch and refresh the last record.
    pub(super) fn apply_fix(&mut self, f: &mut Eskf, g: usize) -> Result<(), NavError> {
        let gn = self.gnss;
        let k = self.cfg.quality_scale.factor(gn.quality[g]);
        let p_prior = pack(f.covariance());
        let mut outcomes = Vec::with_capacity(2);
        let sigma = gn.sigma_ned_m[g].map(|s| s * k);
        let t_fix = gn.time_s[g];
        // Recovery clock: time without an accepted position fix, outside the windows.
        let starved = self.time_outside_windows(self.last_position_accept_s, t_fix);
        let by_time = self.cfg.gate_recovery_s.is_some_and(|r| starved > r);
        let after_window = self
            .cfg
            .outages_s
            .iter()
            .any(|&(_, b)| b >= self.last_fix_s && b < t_fix);
        // The count rule is for a state that diverges while fixes keep coming; after an
        // outage window or a gap in the fixes longer than the clock, the clock alone
        // decides until a fix is accepted again (dead-reckoning drift is expected there).
        if after_window
            || self
                .cfg
                .gate_recovery_s
                .is_some_and(|r| t_fix - self.last_fix_s > r)
        {
            self.count_armed = false;
        }
        let by_count = self.count_armed
            && self
                .cfg
                .gate_recovery_rejections
                .is_some_and(|k| self.gross_in_row >= k);
        let forced = by_time || by_count;
        self.last_fix_s = t_fix;
        let llh = [gn.lat_rad[g], gn.lon_rad[g], gn.height_m[g]];
        let prev_fix =
            self.prev_fix
                .replace((t_fix, (llh[0], llh[1], llh[2]), sigma[0].max(sigma[1])));
        let gate = f.gate();
        if forced {
            let mut trial = f.clone();
            trial.set_gate(super::super::Gate::default());
            let o = trial.update_position(llh, sigma, self.cfg.lever_arm_b_m);
            let gross = o.as_ref().map_or(true, |o| !o.accepted);
            let innovation = o.map_or(f64::NAN, |o| o.innovation[0].hypot(o.innovation[1]));
            let mut yaw_from_course = false;
            if gross {
                yaw_from_course = self.reset_to_fix(f, llh, sigma, prev_fix)?;
                self.run.gnss_resets += 1;
            }
            // A fix forced after a gap in the GNSS data, with nothing rejected and no
            // reset, is the clock at work, not a recovery: counted in `gnss_forced` only.
            if self.rejected_in_row > 0 || gross {
                self.run.recoveries.push(RecoveryEvent {
                    time_s: t_fix,
                    trigger: if by_time {
                        RecoveryTrigger::Time
                    } else {
                        RecoveryTrigger::Rejections
                    },
                    rejected_fixes: self.rejected_in_row,
                    starved_s: starved,
                    horizontal_innovation_m: innovation,
                    reset: gross,
                    yaw_from_course,
                });
            }
            f.set_gate(super::super::Gate::Off);
        } else if after_window && matches!(gate, super::super::Gate::Robust { .. }) {
            f.set_gate(gate.never_reject());
        }
        let o = f.update_position(llh, sigma, self.cfg.lever_arm_b_m);
        f.set_gate(gate);
        let o = o?;
        if o.accepted {
            self.last_position_accept_s = t_fix;
            self.rejected_in_row = 0;
            self.gross_in_row = 0;
            self.count_armed = true;
            if forced {
                self.run.gnss_forced += 1;
            }
        } else {
            self.rejected_in_row += 1;
            // Gross: rejected even by the default robust gate at its 100-σ ceiling (the
            // same test as the configured gate when that is the default; a rejected
            // update left the state as it was, so the trial starts from it).
            let gross = gate == super::super::Gate::default() || {
                let mut trial = f.clone();
                trial.set_gate(super::super::Gate::default());
                trial
                    .update_position(llh, sigma, self.cfg.lever_arm_b_m)
                    .map_or(true, |o| !o.accepted)
            };
            self.gross_in_row = if gross { self.gross_in_row + 1 } else { 0 };
        }
        outcomes.push(o);
        if let Some(v) = &gn.vel_ned_m_s {
            let v = v[g];
            self.gnss_speed = Some((gn.time_s[g], norm(v)));
        }
        if self.cfg.use_gnss_velocity
            && let (Some(v), Some(sv)) = (&gn.vel_ned_m_s, &gn.sigma_vel_ned_m_s)
        {
            let o = f.update_velocity(v[g], sv[g].map(|s| s * k), self.cfg.lever_arm_b_m)?;
            outcomes.push(o);
        }
        for o in &outcomes {
            if o.accepted {
                self.run.gnss_accepted += 1;
                if o.r_scale > 1.0 {
                    self.run.gnss_inflated += 1;
                }
            } else {
                self.run.gnss_rejected += 1;
            }
        }
        let idx = self.run.epochs.len() - 1;
        let comp = self.run.epochs[idx].comp;
        self.run.epochs[idx] = record(f, comp);
        let idx = idx + self.run.first_epoch;
        self.run.updates.push(UpdateRecord {
            epoch_index: idx,
            time_s: gn.time_s[g],
            outcomes,
            p_prior,
            p_post: pack(f.covariance()),
        });
        Ok(())
    }
}

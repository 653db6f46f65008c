//! Land-vehicle trajectories from drive segments (straight runs, turns, stops) with a gait
//! for pedestrian-like motion.

use super::*;

/// One piece of a [`LandVehicle`] drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriveSegment {
    /// Standing still for `duration_s` (the speed must already be zero: the segment
    /// itself has zero velocity).
    Stop {
        /// Duration, s.
        duration_s: f64,
    },
    /// Straight, changing speed from the current value to `to_m_s` with the smooth
    /// profile v(τ) = v₀ + ½Δv(1 − cos(πτ/T)) (acceleration ½Δv(π/T) sin(πτ/T), zero at
    /// both ends, so the specific force is continuous); Δv = 0 is a constant-speed run.
    Speed {
        /// Speed at the end, m/s (≥ 0).
        to_m_s: f64,
        /// Duration T, s.
        duration_s: f64,
    },
    /// Turn at the current (constant) speed through `angle_rad` (positive right) at
    /// the constant yaw rate angle/T: a circular arc of radius V·T/angle.
    Turn {
        /// Heading change, rad.
        angle_rad: f64,
        /// Duration T, s.
        duration_s: f64,
    },
    /// Straight climb (or descent, Δh < 0) at the current horizontal speed V and
    /// heading, with the height profile h(τ) = h₀ + Δh/T·(τ − T/(2π)·sin(2πτ/T)):
    /// ḣ = Δh/T·(1 − cos(2πτ/T)), ḧ = 2πΔh/T²·sin(2πτ/T), both zero at the ends, so
    /// velocity and acceleration join the level segments continuously (peak grade
    /// 2Δh/(VT), twice the mean). The vehicle's pitch is the flight-path angle
    /// θ = atan2(ḣ, V), θ̇ = Vḧ/(V² + ḣ²), so its velocity stays along its x axis.
    /// Needs V > 0 (at V = 0 the pitch would be ±90°).
    Climb {
        /// Height change Δh, m (positive up).
        height_change_m: f64,
        /// Duration T, s.
        duration_s: f64,
    },
}

impl DriveSegment {
    /// Duration of the segment, s.
    pub fn duration_s(&self) -> f64 {
        match *self {
            DriveSegment::Stop { duration_s }
            | DriveSegment::Speed { duration_s, .. }
            | DriveSegment::Turn { duration_s, .. }
            | DriveSegment::Climb { duration_s, .. } => duration_s,
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) struct SegStart {
    pub(super) t0: f64,
    /// Local (n, e, d) at the start.
    pub(super) p0: Vec3,
    /// Horizontal distance travelled before the segment, m.
    pub(super) s0: f64,
    pub(super) yaw0: f64,
    /// Horizontal speed at the start, m/s.
    pub(super) v0: f64,
    pub(super) seg: DriveSegment,
}

/// Kinematics of the vehicle frame at one instant of a segment.
#[derive(Clone, Copy, Debug)]
pub(super) struct Kinematics {
    /// Local (n, e, d), its first and second derivatives.
    pub(super) p: Vec3,
    pub(super) v: Vec3,
    pub(super) a: Vec3,
    pub(super) yaw: f64,
    pub(super) yaw_rate: f64,
    pub(super) pitch: f64,
    pub(super) pitch_rate: f64,
    /// Horizontal speed, m/s.
    pub(super) speed: f64,
    /// Horizontal distance travelled since the start of the drive, m.
    pub(super) dist: f64,
    /// Rate of change of the horizontal speed, m/s².
    pub(super) along_acc: f64,
}

/// Hand-held carriage of the IMU by a walker, superposed on a [`LandVehicle`] path
/// (its speeds then being walking speeds). The motion is a function of the horizontal
/// distance walked s (so it stops when the walker stops and its frequency follows the
/// speed: V/L steps per second), with k = 2π/L:
///
/// * vertical bob, one period per step: Δd = −A_b sin(ks) (positive up);
/// * pitch sway, one period per step: Δθ = A_p sin(ks), added to the path pitch;
/// * roll sway, one period per stride of two steps: φ = A_r sin(ks/2).
///
/// Derivatives by the chain rule with ṡ = V and s̈ = V̇:
/// Δḋ = −A_b k cos(ks)·ṡ, Δd̈ = A_b k² sin(ks)·ṡ² − A_b k cos(ks)·s̈,
/// Δθ̇ = A_p k cos(ks)·ṡ, φ̇ = ½A_r k cos(ks/2)·ṡ. Typical hand-held values: step length
/// 0.6–0.75 m (≈ 2 steps/s at 1.2–1.5 m/s), bob 1–3 cm (vertical acceleration amplitude
/// A_b(kV)² ≈ 1.6–4.7 m/s² at 2 Hz), sway 1–3°.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gait {
    /// Step length L, m (> 0).
    pub step_length_m: f64,
    /// Vertical bob amplitude A_b, m.
    pub bob_amplitude_m: f64,
    /// Pitch sway amplitude A_p, rad.
    pub pitch_amplitude_rad: f64,
    /// Roll sway amplitude A_r, rad.
    pub roll_amplitude_rad: f64,
}

impl Gait {
    /// (Δd, Δḋ, Δd̈, φ, φ̇, Δθ, Δθ̇) at distance `s`, speed `sd`, along-track acceleration
    /// `sdd` (type documentation).
    pub(super) fn offsets(&self, s: f64, sd: f64, sdd: f64) -> [f64; 7] {
        let k = 2.0 * std::f64::consts::PI / self.step_length_m;
        let (sn, cs) = (k * s).sin_cos();
        let (sh, ch) = (0.5 * k * s).sin_cos();
        let ab = self.bob_amplitude_m;
        [
            -ab * sn,
            -ab * k * cs * sd,
            ab * k * k * sn * sd * sd - ab * k * cs * sdd,
            self.roll_amplitude_rad * sh,
            0.5 * self.roll_amplitude_rad * k * ch * sd,
            self.pitch_amplitude_rad * sn,
            self.pitch_amplitude_rad * k * cs * sd,
        ]
    }
}

/// (d) A land-vehicle drive composed of [`DriveSegment`]s: stops, straight runs with
/// smooth speed changes, constant-speed level turns and straight climbs, every piece in
/// closed form (local path in scaled local coordinates as for the other analytic
/// trajectories, so position, v^n and v̇^n are exact). The *vehicle* frame v (forward,
/// right, down) has yaw ψ(t), pitch θ(t) (non-zero only in climbs) and zero roll, its
/// velocity is along its x axis (non-holonomic: no side slip, up to the
/// scaled-coordinate approximation: the NED velocity deviates from the path yaw by
/// ≈ tan φ₀·Δn/R — ≲ 1e-4 rad within a few km of the origin, a "side slip"
/// ≤ 1.5 mm/s at 15 m/s); the IMU (body b) is mounted with the constant rotation C_vb
/// (x_v = C_vb x_b), so C_bn = C_vn C_vb and ω_nb^b = C_vbᵀ ω_nv^v with the z-y-x
/// Euler-rate relation at zero roll, ω_nv^v = (−ψ̇ sin θ, θ̇, ψ̇ cos θ) (Groves 2013,
/// §2.2; Titterton & Weston 2004, §3.6). Before t = 0 the first segment is extended
/// analytically; after the last one the vehicle keeps its final speed and heading.
/// Acceleration and body rate may jump at segment joins (a turn's yaw rate starts at
/// once): the joins are reported by [`Trajectory::next_break_s`] so that the ideal
/// increments integrate each piece separately. [`LandVehicle::with_gait`] turns the
/// drive into a hand-held walk: a [`Gait`] adds a vertical bob and pitch/roll sway to
/// the vehicle frame (then the velocity is no longer along its x axis, and the body
/// rate uses the general z-y-x Euler-rate relation with the roll).
#[derive(Clone, Debug)]
pub struct LandVehicle {
    origin: LocalOrigin,
    c_vb: Mat3,
    pub(super) segs: Vec<SegStart>,
    gait: Option<Gait>,
}

impl LandVehicle {
    /// Drive starting at (lat, lon, h) with heading `yaw0_rad` and speed `speed0_m_s`.
    /// Segment durations must be > 0 (non-positive ones are skipped). No other checks:
    /// [`crate::sim::profile`] validates a drive before building it.
    pub fn new(
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        yaw0_rad: f64,
        speed0_m_s: f64,
        c_vb: Mat3,
        segments: &[DriveSegment],
    ) -> LandVehicle {
        let mut segs = Vec::with_capacity(segments.len());
        let (mut t, mut p, mut yaw, mut v) = (0.0, [0.0; 3], yaw0_rad, speed0_m_s);
        let mut dist = 0.0;
        for &seg in segments {
            let st = SegStart {
                t0: t,
                p0: p,
                s0: dist,
                yaw0: yaw,
                v0: v,
                seg,
            };
            let dur = seg.duration_s();
            if dur.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let end = st.eval(dur);
            segs.push(st);
            t += dur;
            p = end.p;
            yaw = end.yaw;
            v = end.speed;
            dist = end.dist;
        }
        if segs.is_empty() {
            segs.push(SegStart {
                t0: 0.0,
                p0: [0.0; 3],
                s0: 0.0,
                yaw0: yaw0_rad,
                v0: speed0_m_s,
                seg: DriveSegment::Stop { duration_s: 1.0 },
            });
        }
        // Tail: constant speed and heading.
        segs.push(SegStart {
            t0: t,
            p0: p,
            s0: dist,
            yaw0: yaw,
            v0: v,
            seg: DriveSegment::Speed {
                to_m_s: v,
                duration_s: f64::INFINITY,
            },
        });
        LandVehicle {
            origin: LocalOrigin::new(lat_rad, lon_rad, height_m),
            c_vb,
            segs,
            gait: None,
        }
    }

    /// The same drive carried by a walker ([`Gait`]); `None` removes the gait.
    pub fn with_gait(mut self, gait: Option<Gait>) -> LandVehicle {
        self.gait = gait;
        self
    }

    /// Total duration of the given segments, s.
    pub fn duration_s(&self) -> f64 {
        self.segs.last().map_or(0.0, |s| s.t0)
    }

    /// Start times (s) of the segments (in the order given, zero-length ones dropped).
    pub fn segment_starts_s(&self) -> Vec<f64> {
        self.segs.iter().map(|s| s.t0).collect()
    }
}

impl SegStart {
    /// Kinematics at τ into the segment.
    pub(super) fn eval(&self, tau: f64) -> Kinematics {
        let (sy, cy) = self.yaw0.sin_cos();
        let level = |pn: f64, pe: f64, vn: f64, ve: f64, an: f64, ae: f64| Kinematics {
            p: [pn, pe, self.p0[2]],
            v: [vn, ve, 0.0],
            a: [an, ae, 0.0],
            yaw: self.yaw0,
            yaw_rate: 0.0,
            pitch: 0.0,
            pitch_rate: 0.0,
            speed: 0.0,
            dist: self.s0,
            along_acc: 0.0,
        };
        match self.seg {
            DriveSegment::Stop { .. } => level(self.p0[0], self.p0[1], 0.0, 0.0, 0.0, 0.0),
            DriveSegment::Speed { to_m_s, duration_s } => {
                let dv = to_m_s - self.v0;
                let (s, v, a) = if duration_s.is_finite() && dv != 0.0 {
                    let k = std::f64::consts::PI / duration_s;
                    let (sn, cs) = (k * tau).sin_cos();
                    (
                        self.v0 * tau + 0.5 * dv * (tau - sn / k),
                        self.v0 + 0.5 * dv * (1.0 - cs),
                        0.5 * dv * k * sn,
                    )
                } else {
                    (self.v0 * tau, self.v0, 0.0)
                };
                Kinematics {
                    speed: v,
                    dist: self.s0 + s,
                    along_acc: a,
                    ..level(
                        self.p0[0] + s * cy,
                        self.p0[1] + s * sy,
                        v * cy,
                        v * sy,
                        a * cy,
                        a * sy,
                    )
                }
            }
            DriveSegment::Turn {
                angle_rad,
                duration_s,
            } => {
                let w = angle_rad / duration_s;
                let v = self.v0;
                let psi = self.yaw0 + w * tau;
                let (sp, cp) = psi.sin_cos();
                let (pn, pe) = if w.abs() > 1e-12 {
                    let r = v / w;
                    (self.p0[0] + r * (sp - sy), self.p0[1] + r * (cy - cp))
                } else {
                    (self.p0[0] + v * tau * cy, self.p0[1] + v * tau * sy)
                };
                Kinematics {
                    yaw: psi,
                    yaw_rate: w,
                    speed: v,
                    dist: self.s0 + v * tau,
                    ..level(pn, pe, v * cp, v * sp, -v * w * sp, v * w * cp)
                }
            }
            DriveSegment::Climb {
                height_change_m,
                duration_s,
            } => {
                let v = self.v0;
                let k = 2.0 * std::f64::consts::PI / duration_s;
                let (sn, cs) = (k * tau).sin_cos();
                let r = height_change_m / duration_s;
                let dh = r * (tau - sn / k);
                let h_d = r * (1.0 - cs);
                let h_dd = r * k * sn;
                let s = v * tau;
                Kinematics {
                    p: [self.p0[0] + s * cy, self.p0[1] + s * sy, self.p0[2] - dh],
                    v: [v * cy, v * sy, -h_d],
                    a: [0.0, 0.0, -h_dd],
                    yaw: self.yaw0,
                    yaw_rate: 0.0,
                    pitch: h_d.atan2(v),
                    pitch_rate: v * h_dd / (v * v + h_d * h_d),
                    speed: v,
                    dist: self.s0 + s,
                    along_acc: 0.0,
                }
            }
        }
    }
}

impl Trajectory for LandVehicle {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let i = self.segs.partition_point(|s| s.t0 <= t_s).saturating_sub(1);
        let sg = &self.segs[i];
        let mut k = sg.eval(t_s - sg.t0);
        let mut roll = (0.0, 0.0);
        if let Some(g) = &self.gait {
            let [d, dd, ddd, r, rd, th, thd] = g.offsets(k.dist, k.speed, k.along_acc);
            k.p[2] += d;
            k.v[2] += dd;
            k.a[2] += ddd;
            k.pitch += th;
            k.pitch_rate += thd;
            roll = (r, rd);
        }
        let c_vn = Euler {
            roll_rad: roll.0,
            pitch_rad: k.pitch,
            yaw_rad: k.yaw,
        }
        .to_dcm();
        let c_bn = c_vn.mul_mat(&self.c_vb);
        // z-y-x Euler rates → body rate (Titterton & Weston 2004, §3.6):
        // ω = (φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, −θ̇ sin φ + ψ̇ cos φ cos θ).
        let (sp, cp) = k.pitch.sin_cos();
        let (sr, cr) = roll.0.sin_cos();
        let omega_nv_v = [
            roll.1 - k.yaw_rate * sp,
            k.pitch_rate * cr + k.yaw_rate * sr * cp,
            -k.pitch_rate * sr + k.yaw_rate * cr * cp,
        ];
        let omega_nb_b = self.c_vb.t().mul_vec(omega_nv_v);
        self.origin.point(k.p, k.v, k.a, c_bn, omega_nb_b)
    }

    fn next_break_s(&self, t_s: f64) -> Option<f64> {
        let i = self.segs.partition_point(|s| s.t0 <= t_s);
        self.segs.get(i).map(|s| s.t0)
    }
}

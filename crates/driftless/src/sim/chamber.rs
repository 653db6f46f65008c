//! The thermal-chamber calibration protocol (seed paper §2.3, §3.2: soak method, −25 … 70 °C
//! in 5 °C steps; six-position and rate-table tests per Titterton & Weston 2004, §8.3;
//! IEEE Std 1293-2018) as a [`Trajectory`] plus a manifest of its segments.
//!
//! # Protocol
//!
//! For each set temperature, in order:
//!
//! 1. **soak**: static at the home attitude (level, x north, z down: "−z up") while the
//!    chamber moves to the new set point and the sensor settles (first-order lag τ, see
//!    [`super::temperature`]);
//! 2. **six positions**, each a static dwell with one body axis pointing up:
//!    −z (home), +z, +x, −x, +y, −y, joined by smooth rotations;
//! 3. **rate table** for each axis k = x, y, z: rotate to "+k up" (the table axis is
//!    vertical and the tested body axis is on it), spin up smoothly to +ω about body +k,
//!    turn exactly `rate_revolutions` full revolutions at constant +ω (the "rate"
//!    segment), spin down, spin up to −ω, the same number of revolutions at −ω, spin
//!    down (back at "+k up" exactly);
//! 4. rotate back to the home attitude.
//!
//! ## Palindromic order ([`StepOrder::Palindromic`])
//!
//! Steps 2 and 3 are run forwards and then backwards, each dwell half as long:
//! positions −z, +z, +x, −x, +y, −y, −y, +y, −x, +x, +z, −z (the two −y halves are
//! adjacent: one dwell split in two segments), `position_dwell_s`/2 each; rate segments
//! +ω, −ω, −ω, +ω per axis, `rate_revolutions`/2 revolutions each (the two −ω halves are
//! one continuous spin, split in two segments; `rate_revolutions` must be even; the two
//! +ω ramp pairs against one −ω pair leave the table turned by ω·`spin_s` about the
//! vertical, which the move to the next axis takes back). Every piece of the second
//! half mirrors one of the first, so the sample-weighted
//! mean time of the +k and −k visits (and of the +ω and −ω segments) is the same instant,
//! the centre of the block. A bias that drifts linearly in time,
//! b(t) = b(t_c) + ḃ·(t − t_c), then cancels exactly in the ± differences that give the
//! scale factors, (f̄₊ − f̄₋)/(2g), and its mean over the block is b(t_c) for every
//! orientation (the "ABBA" reversal design of drift-balanced comparisons, e.g. the
//! weighing cycles of OIML R 111-1). A rate random walk, which is not linear, still
//! leaves its increments between the adjacent visits of an axis, but those are half a
//! dwell plus a move apart instead of one or more dwells.
//!
//! ## Position cycles (`position_cycles`)
//!
//! The position sequence of a step (six positions, or the palindrome) can be run c times
//! back to back, each visit 1/c as long (the total dwell per orientation is unchanged, so
//! is the white-noise part of every mean). The reason is the flicker (bias instability
//! B): its Allan deviation is flat, ≈ 0.664·B at every averaging time, so the difference
//! of two adjacent visit means — which is what a scale factor (f̄₊ − f̄₋)/(2g) is made
//! of — has about the same σ ≈ √2·0.664·B whether a visit lasts 15 s or 60 s. Only more
//! reversals help: the c independent differences average to σ/√c. With the `adi-like`
//! accelerometers (B = 200 µg) one palindrome per step leaves ≈ 6e-5 of scale-factor
//! noise per step against a thermal swing of 3e-3 (accelerometer z); three cycles
//! cut it by √3 for one extra move per visit.
//!
//! The IMU stays at a fixed location (no lever arm: the table rotates about the IMU),
//! so the ideal specific force in every static position is exactly the normal gravity
//! of the site along the up axis ([`ChamberManifest::gravity_m_s2`]). Over whole
//! revolutions about a vertical axis, the horizontal Earth-rate components average to
//! zero and the vertical one is the same for +ω and −ω, so the ±ω difference isolates the
//! scale factor.
//!
//! # Attitude program
//!
//! Every piece is a rotation about a body-fixed unit axis u starting from an attitude
//! C₀: C_bn(t) = C₀·R(u, θ(t)), R by Rodrigues' formula, so ω_nb^b = u·θ̇ exactly
//! (Ċ_bn = C₀R[u×]θ̇ = C_bn[ω_nb^b×]). With s = (t − t₀)/T on a piece of duration T:
//!
//! * hold: θ = 0;
//! * move through Θ: θ = Θ(s − sin(2πs)/(2π)), θ̇ = (Θ/T)(1 − cos 2πs) — rate and angular
//!   acceleration are zero at both ends;
//! * spin-up to ω: θ̇ = ω(1 − cos πs)/2, θ = ω(t − t₀)/2 − ωT sin(πs)/(2π);
//!   spin: θ = ω(t − t₀); spin-down: θ̇ = ω(1 + cos πs)/2, θ = ω(t − t₀)/2 + ωT sin(πs)/(2π).
//!
//! ω_nb^b is therefore continuous everywhere (no infinite rates) and analytic inside each
//! piece. Every piece lasts a whole number of samples and starts on the sample grid, so
//! the 6-node Gauss–Legendre increments of [`super::ideal_imu::ideal_increment`] never
//! straddle a piece boundary and stay exact to rounding; the constant rate is adjusted so
//! that the spin segment is a whole number of samples long
//! (ω = 2π·revolutions/(n·Δt), recorded in the manifest).
//!
//! # Manifest
//!
//! [`ChamberManifest`] lists every segment (time range, kind — soak / position (which
//! axis up) / rate (axis, signed ω) / move — and set temperature) and serialises to TOML,
//! so the thermal-calibration step can find the data of each test. Sample `i` of an
//! increment log covers (iΔt, (i+1)Δt]; sample `i` of a rate log is at iΔt;
//! [`Segment::sample_range`] returns the samples of a segment in either convention.

use driftless_model::linalg::{Mat3, Vec3};
use driftless_model::units::DEG;
use serde::{Deserialize, Serialize};

use super::ideal_imu::{Trajectory, TrajectoryPoint};
use super::sensor::{IdealImu, OutputKind, ideal_sample};
use super::sensor_error::{SensorSimError, check_finite, check_pos};
use super::temperature::{ChamberStep, TemperatureProfile};
pub use crate::calib::protocol::{
    BodyAxis, ChamberManifest, MANIFEST_VERSION, Segment, SegmentKind, SignedAxis,
};
use crate::nav::attitude::Quat;
use crate::nav::earth;

/// Order of the static positions and rate-table segments within a temperature step
/// (module docs). TOML: `step_order = "sequential" | "palindromic"`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepOrder {
    /// Each position and each ±ω segment once, in protocol order (the default).
    #[default]
    Sequential,
    /// The sequence, then the same sequence reversed, each dwell and each rate segment
    /// half as long: linear drift cancels in the ± differences.
    Palindromic,
}

/// Protocol settings (TOML-serialisable; every field has a default).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChamberConfig {
    /// Set temperatures in order, °C (default −25 … 70 in 5 °C steps, the paper's 20).
    pub temperatures_c: Vec<f64>,
    /// Soak dwell at the start of each step, s (default 3600).
    pub soak_s: f64,
    /// Soak dwell of the first step only, s (default: `soak_s`). The sensor starts at
    /// the first set point (the temperature profile's initial value), so a run that
    /// starts where the sensor was switched on — e.g. a reference step at ambient — can
    /// measure at once; the earlier the first positions, the less rate random walk since
    /// turn-on sits in every bias value ([`crate::thermal::soak`]).
    pub first_soak_s: Option<f64>,
    /// Dwell per static position, s (default 60; with [`StepOrder::Palindromic`] or
    /// `position_cycles` > 1 the total over all visits of the position).
    pub position_dwell_s: f64,
    /// How many times the position sequence of a step is run (default 1): the six
    /// positions (sequential) or the palindrome (palindromic) repeated back to back,
    /// each visit `position_dwell_s` / (visits per position) long. More reversals per
    /// step average the flicker between the +k and −k visits that the scale factors
    /// difference (module docs, "Position cycles").
    pub position_cycles: u32,
    /// Duration of each rotation between positions, s (default 10).
    pub move_s: f64,
    /// Rate-table rate |ω|, deg/s (default 50; adjusted to whole samples, see module docs).
    pub rate_deg_s: f64,
    /// Whole revolutions per rate segment (default 5; with [`StepOrder::Palindromic`] the
    /// total over both segments of one sign, which must then be even).
    pub rate_revolutions: u32,
    /// Order of the positions and rate segments within a step (default sequential).
    pub step_order: StepOrder,
    /// Duration of each spin-up and spin-down, s (default 5).
    pub spin_s: f64,
    /// Sensor thermal time constant τ, s (default 300).
    pub lag_tau_s: f64,
    /// Chamber air ramp rate, °C/min (default: instantaneous set-point steps).
    pub ramp_c_per_min: Option<f64>,
    /// Sample rate, Hz (default 100).
    pub sample_rate_hz: f64,
    /// Site latitude, deg (default 51.08, Calgary, where the paper's chamber was).
    pub latitude_deg: f64,
    /// Site longitude, deg (default −114.13).
    pub longitude_deg: f64,
    /// Site ellipsoidal height, m (default 1100).
    pub height_m: f64,
    /// A prefix before the first step, s (default 0: the log starts at the first soak):
    /// static at home for a third, a move to an attitude with no body axis vertical
    /// (35° about body x from home), static there, a move back, static at home for the
    /// rest — the handling a real session records before its protocol starts. One
    /// `move` segment of the manifest, at the first set temperature.
    pub prefix_s: f64,
    /// Relative jitter of every soak and position dwell (default 0): each is multiplied
    /// by 1 + j·u, u uniform on [−1, 1) drawn from `jitter_seed` (uneven dwells of a
    /// hand-run session). Moves and rate segments keep their lengths.
    pub dwell_jitter: f64,
    /// Seed of the dwell jitter (default 0).
    pub jitter_seed: u64,
    /// Positions left out (default none): every visit of `up` in the steps at
    /// `set_temperature_c` is skipped with the move to it — a position missed in a
    /// session. The manifest then lacks it too.
    pub skip_positions: Vec<SkippedPosition>,
}

/// A static position left out of the steps at one set temperature
/// ([`ChamberConfig::skip_positions`]). TOML: `{ set_temperature_c = 10.0, up = "+x" }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkippedPosition {
    /// Set temperature of the step(s), °C.
    pub set_temperature_c: f64,
    /// The position (axis up) left out.
    pub up: SignedAxis,
}

impl Default for ChamberConfig {
    fn default() -> Self {
        ChamberConfig {
            temperatures_c: (0..20).map(|i| -25.0 + 5.0 * i as f64).collect(),
            soak_s: 3600.0,
            first_soak_s: None,
            position_dwell_s: 60.0,
            position_cycles: 1,
            move_s: 10.0,
            rate_deg_s: 50.0,
            rate_revolutions: 5,
            step_order: StepOrder::Sequential,
            spin_s: 5.0,
            lag_tau_s: 300.0,
            ramp_c_per_min: None,
            sample_rate_hz: 100.0,
            latitude_deg: 51.08,
            longitude_deg: -114.13,
            height_m: 1100.0,
            prefix_s: 0.0,
            dwell_jitter: 0.0,
            jitter_seed: 0,
            skip_positions: Vec::new(),
        }
    }
}

/// How θ evolves on a piece (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Motion {
    Hold,
    Move { angle_rad: f64 },
    SpinUp { rate_rad_s: f64 },
    Spin { rate_rad_s: f64 },
    SpinDown { rate_rad_s: f64 },
}

/// One piece of the attitude program.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    start_s: f64,
    duration_s: f64,
    c0: Mat3,
    axis: Vec3,
    motion: Motion,
}

impl Piece {
    /// (θ, θ̇) at `tau` seconds into the piece.
    fn angle_rate(&self, tau: f64) -> (f64, f64) {
        use std::f64::consts::{PI, TAU};
        let t = self.duration_s;
        match self.motion {
            Motion::Hold => (0.0, 0.0),
            Motion::Move { angle_rad } => {
                let s = tau / t;
                (
                    angle_rad * (s - (TAU * s).sin() / TAU),
                    angle_rad / t * (1.0 - (TAU * s).cos()),
                )
            }
            Motion::SpinUp { rate_rad_s: w } => {
                let s = tau / t;
                (
                    w * (0.5 * tau - t * (PI * s).sin() / TAU),
                    0.5 * w * (1.0 - (PI * s).cos()),
                )
            }
            Motion::Spin { rate_rad_s: w } => (w * tau, w),
            Motion::SpinDown { rate_rad_s: w } => {
                let s = tau / t;
                (
                    w * (0.5 * tau + t * (PI * s).sin() / TAU),
                    0.5 * w * (1.0 + (PI * s).cos()),
                )
            }
        }
    }

    /// (C_bn, ω_nb^b) at `tau` into the piece.
    fn attitude(&self, tau: f64) -> (Mat3, Vec3) {
        if self.motion == Motion::Hold {
            return (self.c0, [0.0; 3]);
        }
        let (th, th_d) = self.angle_rate(tau);
        let k = Mat3::skew(self.axis);
        let (s, c) = th.sin_cos();
        let r = Mat3::IDENTITY + k.scaled(s) + k.mul_mat(&k).scaled(1.0 - c);
        (self.c0.mul_mat(&r), self.axis.map(|u| u * th_d))
    }
}

/// The protocol's motion at a fixed site: a [`Trajectory`].
#[derive(Clone, Debug)]
pub struct ChamberTrajectory {
    lat_rad: f64,
    lon_rad: f64,
    height_m: f64,
    pieces: Vec<Piece>,
}

impl Trajectory for ChamberTrajectory {
    fn point(&self, t_s: f64) -> TrajectoryPoint {
        let i = self
            .pieces
            .partition_point(|p| p.start_s <= t_s)
            .saturating_sub(1);
        let (c_bn, omega) = match self.pieces.get(i) {
            Some(p) => p.attitude((t_s - p.start_s).clamp(0.0, p.duration_s)),
            None => (Mat3::IDENTITY, [0.0; 3]),
        };
        TrajectoryPoint {
            lat_rad: self.lat_rad,
            lon_rad: self.lon_rad,
            height_m: self.height_m,
            vel_ned_m_s: [0.0; 3],
            acc_ned_m_s2: [0.0; 3],
            c_bn,
            omega_nb_b_rad_s: omega,
        }
    }
}

/// A built protocol: motion, segment manifest and the chamber temperature profile (all
/// on the same time axis, t = 0 at the start of the first soak).
#[derive(Clone, Debug)]
pub struct ChamberProtocol {
    /// The motion.
    pub trajectory: ChamberTrajectory,
    /// The segments.
    pub manifest: ChamberManifest,
    /// Chamber set points (one step per set temperature, lasting the whole step) with
    /// the sensor lag.
    pub temperature: TemperatureProfile,
}

impl ChamberProtocol {
    /// Number of samples covering the whole run.
    pub fn n_samples(&self) -> usize {
        (self.manifest.duration_s * self.manifest.sample_rate_hz).round() as usize
    }

    /// Ideal IMU data of the whole run (parallel): rates at iΔt or increments over
    /// (iΔt, (i+1)Δt], i = 0 … n − 1. A sample inside a static piece is the piece's
    /// constant rates (× Δt for increments), evaluated once per piece; the others come
    /// from [`super::sensor::ideal_sample`] (exact Gauss–Legendre increments).
    pub fn ideal(&self, kind: OutputKind) -> IdealImu {
        let fs = self.manifest.sample_rate_hz;
        let dt = 1.0 / fs;
        let first = match kind {
            OutputKind::Rates => 0.0,
            OutputKind::Increments => dt,
        };
        let tr = &self.trajectory;
        // Per piece: (first sample index, end sample index, static rates).
        type Span = (u64, u64, Option<(Vec3, Vec3)>);
        let spans: Vec<Span> = tr
            .pieces
            .iter()
            .map(|p| {
                let k0 = (p.start_s * fs).round() as u64;
                let k1 = if p.duration_s.is_finite() {
                    ((p.start_s + p.duration_s) * fs).round() as u64
                } else {
                    u64::MAX
                };
                let rates = (p.motion == Motion::Hold).then(|| tr.point(p.start_s).imu_rates());
                (k0, k1, rates)
            })
            .collect();
        let w = match kind {
            OutputKind::Rates => 1.0,
            OutputKind::Increments => dt,
        };
        IdealImu::from_fn(kind, first, dt, self.n_samples(), |k| {
            // Rate sample k is at kΔt, increment k covers (kΔt, (k+1)Δt]: either lies
            // in a piece [k0Δt, k1Δt] when k0 ≤ k < k1.
            let k = k as u64;
            let i = spans.partition_point(|s| s.0 <= k).saturating_sub(1);
            match spans.get(i) {
                Some(&(k0, k1, Some((g, f)))) if k0 <= k && k < k1 => {
                    (g.map(|v| v * w), f.map(|v| v * w))
                }
                _ => ideal_sample(tr, kind, first + k as f64 * dt, dt),
            }
        })
    }
}

/// Builds the piece list and the manifest on a whole-sample grid.
struct Builder {
    dt: f64,
    k: u64,
    c: Mat3,
    set_c: f64,
    pieces: Vec<Piece>,
    segments: Vec<Segment>,
}

impl Builder {
    fn push(&mut self, n: u64, axis: Vec3, motion: Motion, end: Mat3, kind: SegmentKind) {
        let start_s = self.k as f64 * self.dt;
        let end_s = (self.k + n) as f64 * self.dt;
        self.pieces.push(Piece {
            start_s,
            duration_s: end_s - start_s,
            c0: self.c,
            axis,
            motion,
        });
        match self.segments.last_mut() {
            // Consecutive transitions at the same set point form one "move" segment.
            Some(last)
                if kind == SegmentKind::Move
                    && last.kind == SegmentKind::Move
                    && last.set_temperature_c == self.set_c
                    && last.end_s == start_s =>
            {
                last.end_s = end_s;
            }
            _ => self.segments.push(Segment {
                start_s,
                end_s,
                set_temperature_c: self.set_c,
                kind,
            }),
        }
        self.k += n;
        self.c = end;
    }

    fn hold(&mut self, n: u64, kind: SegmentKind) {
        let c = self.c;
        self.push(n, [0.0, 0.0, 1.0], Motion::Hold, c, kind);
    }

    /// Smooth rotation to attitude `to` (skipped if already there).
    fn move_to(&mut self, n: u64, to: Mat3) {
        let rel = self.c.t().mul_mat(&to);
        let phi = Quat::from_dcm(&rel).to_rotation_vector();
        let angle = (phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]).sqrt();
        if angle < 1e-12 {
            self.c = to;
            return;
        }
        let axis = phi.map(|v| v / angle);
        self.push(
            n,
            axis,
            Motion::Move { angle_rad: angle },
            to,
            SegmentKind::Move,
        );
    }

    /// The prefix of `n_total` samples: home, tilted 35° about body x (no axis
    /// vertical), home again, with moves of `n_move` samples between three holds.
    fn prefix(&mut self, home: Mat3, n_total: u64, n_move: u64) {
        let n_hold = (n_total - 2 * n_move) / 3;
        let tilt = rotate(home, [1.0, 0.0, 0.0], 35.0 * DEG);
        self.hold(n_hold.max(1), SegmentKind::Move);
        self.move_to(n_move, tilt);
        self.hold(n_hold.max(1), SegmentKind::Move);
        self.move_to(n_move, home);
        self.hold(
            (n_total - 2 * n_move).saturating_sub(2 * n_hold).max(1),
            SegmentKind::Move,
        );
    }

    /// The rate segments about `axis`, starting at "+axis up" (`at`): one spin of
    /// `n_spin` samples at `sign`·`omega` per entry of `signs`, with spin-up and
    /// spin-down ramps of `n_ramp` samples where the rate changes.
    fn spin_program(
        &mut self,
        axis: BodyAxis,
        at: Mat3,
        signs: &[f64],
        omega: f64,
        n_ramp: u64,
        n_spin: u64,
    ) {
        let dt = self.dt;
        let u = axis.unit();
        // Net angle of the program so far, in units of ω·Δt/2.
        let mut net: i64 = 0;
        for (i, &sign) in signs.iter().enumerate() {
            let s = sign as i64;
            let w = sign * omega;
            let kind = SegmentKind::Rate {
                axis,
                rate_rad_s: w,
            };
            // Spin up unless the previous segment turns at the same rate.
            if i == 0 || signs[i - 1] != sign {
                let c = self.c;
                self.push(
                    n_ramp,
                    u,
                    Motion::SpinUp { rate_rad_s: w },
                    rotate(c, u, 0.5 * w * n_ramp as f64 * dt),
                    SegmentKind::Move,
                );
                net += s * n_ramp as i64;
            }
            let c = self.c;
            self.push(
                n_spin,
                u,
                Motion::Spin { rate_rad_s: w },
                rotate(c, u, w * n_spin as f64 * dt),
                kind,
            );
            net += 2 * s * n_spin as i64;
            // Spin down unless the next segment turns at the same rate. When the
            // net angle of the program is zero (sequential: one ramp pair per
            // sign) the last spin-down ends exactly at "+axis up"; otherwise
            // (palindromic: two +ω ramp pairs, one −ω) the table has turned by
            // ω·spin_s about the vertical axis, which `move_to` then undoes.
            let last = i + 1 == signs.len();
            if last || signs[i + 1] != sign {
                net += s * n_ramp as i64;
                let end = if last && net == 0 {
                    at
                } else {
                    rotate(self.c, u, 0.5 * w * n_ramp as f64 * dt)
                };
                self.push(
                    n_ramp,
                    u,
                    Motion::SpinDown { rate_rad_s: w },
                    end,
                    SegmentKind::Move,
                );
            }
        }
    }
}

impl ChamberConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), SensorSimError> {
        if self.temperatures_c.is_empty() {
            return Err(SensorSimError::invalid(
                "chamber.temperatures_c (empty)",
                "needs at least one set temperature",
            ));
        }
        for (i, &t) in self.temperatures_c.iter().enumerate() {
            check_finite(&format!("chamber.temperatures_c[{i}]"), t)?;
        }
        check_pos("chamber.sample_rate_hz", self.sample_rate_hz)?;
        check_pos("chamber.soak_s", self.soak_s)?;
        if let Some(d) = self.first_soak_s {
            check_pos("chamber.first_soak_s", d)?;
        }
        check_pos("chamber.position_dwell_s", self.position_dwell_s)?;
        check_pos("chamber.move_s", self.move_s)?;
        check_pos("chamber.rate_deg_s", self.rate_deg_s)?;
        check_pos("chamber.spin_s", self.spin_s)?;
        check_pos("chamber.lag_tau_s", self.lag_tau_s)?;
        if self.rate_revolutions == 0 {
            return Err(SensorSimError::invalid(
                "chamber.rate_revolutions = 0",
                "must be at least 1",
            ));
        }
        if self.position_cycles == 0 {
            return Err(SensorSimError::invalid(
                "chamber.position_cycles = 0",
                "must be at least 1",
            ));
        }
        let palindromic = self.step_order == StepOrder::Palindromic;
        if palindromic && !self.rate_revolutions.is_multiple_of(2) {
            return Err(SensorSimError::invalid(
                format!("chamber.rate_revolutions = {}", self.rate_revolutions),
                "must be even with step_order = \"palindromic\" (two segments of whole \
                 revolutions per sign)",
            ));
        }
        if !self.latitude_deg.is_finite() || self.latitude_deg.abs() >= 90.0 {
            return Err(SensorSimError::invalid(
                format!("chamber.latitude_deg = {}", self.latitude_deg),
                "must be finite and within (-90, 90)",
            ));
        }
        check_finite("chamber.longitude_deg", self.longitude_deg)?;
        check_finite("chamber.height_m", self.height_m)?;
        if let Some(r) = self.ramp_c_per_min {
            check_pos("chamber.ramp_c_per_min", r)?;
            let mut prev = self.temperatures_c[0];
            for &t in &self.temperatures_c {
                let d = (t - prev).abs() / r * 60.0;
                if d > self.soak_s {
                    return Err(SensorSimError::invalid(
                        format!("chamber.soak_s = {}", self.soak_s),
                        format!(
                            "shorter than the {d} s ramp from {prev} °C to {t} °C at {r} °C/min"
                        ),
                    ));
                }
                prev = t;
            }
        }
        if !(self.prefix_s.is_finite() && self.prefix_s >= 0.0) {
            return Err(SensorSimError::invalid(
                format!("chamber.prefix_s = {}", self.prefix_s),
                "must be finite and ≥ 0",
            ));
        }
        if self.prefix_s > 0.0 && self.prefix_s < 2.0 * self.move_s + 3.0 / self.sample_rate_hz {
            return Err(SensorSimError::invalid(
                format!("chamber.prefix_s = {}", self.prefix_s),
                format!(
                    "too short for its two moves of move_s = {} s and three holds (0, or at \
                     least {} s)",
                    self.move_s,
                    2.0 * self.move_s + 3.0 / self.sample_rate_hz
                ),
            ));
        }
        if !(self.dwell_jitter.is_finite() && (0.0..0.9).contains(&self.dwell_jitter)) {
            return Err(SensorSimError::invalid(
                format!("chamber.dwell_jitter = {}", self.dwell_jitter),
                "must be a fraction in [0, 0.9)",
            ));
        }
        for (i, sp) in self.skip_positions.iter().enumerate() {
            if !self.temperatures_c.contains(&sp.set_temperature_c) {
                return Err(SensorSimError::invalid(
                    format!(
                        "chamber.skip_positions[{i}].set_temperature_c = {}",
                        sp.set_temperature_c
                    ),
                    format!("not one of temperatures_c {:?}", self.temperatures_c),
                ));
            }
        }
        // Every duration must be at least one sample.
        let dwell = self.visit_dwell_s() * (1.0 - self.dwell_jitter);
        for (name, d) in [
            ("soak_s", self.soak_s),
            (
                "first_soak_s",
                self.first_soak_s.unwrap_or(self.soak_s) * (1.0 - self.dwell_jitter),
            ),
            ("position_dwell_s", dwell),
            ("move_s", self.move_s),
            ("spin_s", self.spin_s),
        ] {
            if (d * self.sample_rate_hz).round() < 1.0 {
                return Err(SensorSimError::invalid(
                    format!("chamber.{name} = {d}"),
                    "shorter than one sample",
                ));
            }
        }
        Ok(())
    }

    /// Dwell of one visit of a static position, s: `position_dwell_s` over the visits
    /// per position of a step (2 per cycle palindromic, 1 sequential).
    pub(crate) fn visit_dwell_s(&self) -> f64 {
        let per_cycle = match self.step_order {
            StepOrder::Sequential => 1.0,
            StepOrder::Palindromic => 2.0,
        };
        self.position_dwell_s / (per_cycle * f64::from(self.position_cycles.max(1)))
    }

    /// Positions of one step's cycle, the signs of its rate segments and the whole
    /// revolutions of each rate segment (half per segment when palindromic).
    fn step_schedule(&self) -> (Vec<SignedAxis>, &'static [f64], u32) {
        match self.step_order {
            StepOrder::Sequential => (
                SignedAxis::POSITIONS.to_vec(),
                &[1.0, -1.0],
                self.rate_revolutions,
            ),
            StepOrder::Palindromic => (
                SignedAxis::POSITIONS
                    .iter()
                    .chain(SignedAxis::POSITIONS.iter().rev())
                    .copied()
                    .collect(),
                &[1.0, -1.0, -1.0, 1.0],
                self.rate_revolutions / 2,
            ),
        }
    }

    /// Build the protocol (module docs). Durations are rounded to whole samples.
    pub fn build(&self) -> Result<ChamberProtocol, SensorSimError> {
        self.validate()?;
        let fs = self.sample_rate_hz;
        let dt = 1.0 / fs;
        let ns = |d: f64| ((d * fs).round() as u64).max(1);
        // Positions and signed rates of one step, and the length of each dwell / spin.
        let (cycle, signs, revs) = self.step_schedule();
        let positions = cycle.repeat(self.position_cycles as usize);
        let n_dwell = ns(self.visit_dwell_s());
        let n_spin = ns(revs as f64 * 360.0 / self.rate_deg_s);
        let omega = revs as f64 * std::f64::consts::TAU / (n_spin as f64 * dt);
        let n_ramp = ns(self.spin_s);
        let home = SignedAxis::POSITIONS[0].c_bn_up();
        let mut b = Builder {
            dt,
            k: 0,
            c: home,
            set_c: self.temperatures_c[0],
            pieces: Vec::new(),
            segments: Vec::new(),
        };
        let mut steps = Vec::with_capacity(self.temperatures_c.len());
        let mut jitter_rng = super::rng::Rng::stream(self.jitter_seed, 0);
        let mut jitter = |d: f64| -> f64 {
            if self.dwell_jitter > 0.0 {
                d * (1.0 + self.dwell_jitter * jitter_rng.uniform_pm1())
            } else {
                d
            }
        };
        let mut prefix_n = 0;
        if self.prefix_s > 0.0 {
            b.prefix(home, ns(self.prefix_s), ns(self.move_s));
            prefix_n = b.k;
        }
        for (i, &set_c) in self.temperatures_c.iter().enumerate() {
            let k_start = if i == 0 { b.k - prefix_n } else { b.k };
            b.set_c = set_c;
            b.move_to(ns(self.move_s), home);
            let soak_s = match self.first_soak_s {
                Some(d) if i == 0 => d,
                _ => self.soak_s,
            };
            b.hold(ns(jitter(soak_s)), SegmentKind::Soak);
            // A position repeated back to back (the middle of the palindrome) needs no
            // move: `move_to` skips it.
            for &up in &positions {
                if self
                    .skip_positions
                    .iter()
                    .any(|sp| sp.set_temperature_c == set_c && sp.up == up)
                {
                    continue;
                }
                b.move_to(ns(self.move_s), up.c_bn_up());
                let n = if self.dwell_jitter > 0.0 {
                    ns(jitter(self.visit_dwell_s()))
                } else {
                    n_dwell
                };
                b.hold(n, SegmentKind::Position { up });
            }
            for axis in BodyAxis::ALL {
                let at = SignedAxis::new(axis, true).c_bn_up();
                b.move_to(ns(self.move_s), at);
                b.spin_program(axis, at, signs, omega, n_ramp, n_spin);
            }
            b.move_to(ns(self.move_s), home);
            steps.push(ChamberStep {
                set_c,
                duration_s: (b.k - k_start) as f64 * dt,
            });
        }
        Ok(self.protocol(b, home, steps))
    }

    /// The protocol from the built pieces and steps: a final hold at `home`, the
    /// manifest (normal gravity at the site) and the chamber temperature profile.
    fn protocol(&self, mut b: Builder, home: Mat3, steps: Vec<ChamberStep>) -> ChamberProtocol {
        // Hold at home after the end.
        let end_s = b.k as f64 * b.dt;
        b.pieces.push(Piece {
            start_s: end_s,
            duration_s: f64::INFINITY,
            c0: home,
            axis: [0.0, 0.0, 1.0],
            motion: Motion::Hold,
        });
        let lat = self.latitude_deg * DEG;
        let manifest = ChamberManifest {
            format_version: MANIFEST_VERSION,
            sample_rate_hz: self.sample_rate_hz,
            latitude_deg: self.latitude_deg,
            longitude_deg: self.longitude_deg,
            height_m: self.height_m,
            gravity_m_s2: earth::normal_gravity_m_s2(lat, self.height_m),
            earth_rate_rad_s: earth::OMEGA_IE,
            lag_tau_s: self.lag_tau_s,
            duration_s: end_s,
            segments: b.segments,
        };
        ChamberProtocol {
            trajectory: ChamberTrajectory {
                lat_rad: lat,
                lon_rad: self.longitude_deg * DEG,
                height_m: self.height_m,
                pieces: b.pieces,
            },
            manifest,
            temperature: TemperatureProfile::Chamber {
                steps,
                lag_tau_s: self.lag_tau_s,
                initial_c: None,
                ramp_c_per_min: self.ramp_c_per_min,
            },
        }
    }
}

/// C·R(u, θ).
fn rotate(c: Mat3, u: Vec3, th: f64) -> Mat3 {
    let k = Mat3::skew(u);
    let (s, co) = th.sin_cos();
    c.mul_mat(&(Mat3::IDENTITY + k.scaled(s) + k.mul_mat(&k).scaled(1.0 - co)))
}

#[cfg(test)]
mod tests {
    use super::super::ideal_imu::FiniteDifference;
    use super::*;

    fn small() -> ChamberConfig {
        ChamberConfig {
            temperatures_c: vec![-5.0, 0.0],
            soak_s: 20.0,
            position_dwell_s: 3.0,
            move_s: 2.0,
            rate_deg_s: 90.0,
            rate_revolutions: 1,
            spin_s: 1.0,
            lag_tau_s: 2.0,
            ..Default::default()
        }
    }

    /// Sample-weighted mean time of segments, s.
    fn mean_time(segs: &[&Segment]) -> f64 {
        let w: f64 = segs.iter().map(|s| s.duration_s()).sum();
        segs.iter()
            .map(|s| s.duration_s() * 0.5 * (s.start_s + s.end_s))
            .sum::<f64>()
            / w
    }

    #[test]
    fn positions_put_the_named_axis_up() {
        for up in SignedAxis::POSITIONS {
            let c = up.c_bn_up();
            assert_eq!(c.det(), 1.0);
            let i = c.t().mul_mat(&c);
            assert_eq!(i, Mat3::IDENTITY);
            // f^b = C_nb·(0, 0, −g): +g on the up axis.
            let f = c.t().mul_vec([0.0, 0.0, -1.0]);
            assert_eq!(f, up.axis.unit().map(|v| v * up.sign()));
            assert_eq!(up.to_string().parse::<SignedAxis>().unwrap(), up);
        }
        assert!("x".parse::<SignedAxis>().is_err());
        assert!("+w".parse::<SignedAxis>().is_err());
    }

    #[test]
    fn attitude_is_continuous_and_rates_match_finite_differences() {
        let p = small().build().unwrap();
        let tr = &p.trajectory;
        // Continuity at every piece boundary.
        for w in tr.pieces.windows(2) {
            let t = w[1].start_s;
            let (a, wa) = w[0].attitude(w[0].duration_s);
            let (b, wb) = w[1].attitude(0.0);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((a.0[r][c] - b.0[r][c]).abs() < 1e-12, "t={t}");
                }
                assert!((wa[r] - wb[r]).abs() < 1e-12, "t={t}");
            }
        }
        // ω_nb^b equals the finite-difference rate inside moves and spins.
        let fd = FiniteDifference {
            state: |t: f64| {
                let q = tr.point(t);
                (q.lat_rad, q.lon_rad, q.height_m, q.vel_ned_m_s, q.c_bn)
            },
            step_s: 1e-4,
        };
        let mut checked = 0;
        for pc in &tr.pieces {
            if pc.motion == Motion::Hold || !pc.duration_s.is_finite() {
                continue;
            }
            let t = pc.start_s + 0.37 * pc.duration_s;
            let (a, b) = (tr.point(t), fd.point(t));
            for k in 0..3 {
                assert!(
                    (a.omega_nb_b_rad_s[k] - b.omega_nb_b_rad_s[k]).abs() < 1e-7,
                    "{:?} {:?} {:?}",
                    pc.motion,
                    a.omega_nb_b_rad_s,
                    b.omega_nb_b_rad_s
                );
            }
            checked += 1;
        }
        assert!(checked > 20);
    }

    #[test]
    fn static_shortcut_matches_quadrature() {
        let p = small().build().unwrap();
        for kind in [OutputKind::Rates, OutputKind::Increments] {
            let fast = p.ideal(kind);
            let dt = 1.0 / p.manifest.sample_rate_hz;
            let first = if kind == OutputKind::Rates { 0.0 } else { dt };
            let slow = IdealImu::from_trajectory(&p.trajectory, kind, first, dt, p.n_samples());
            let scale = if kind == OutputKind::Rates { 10.0 } else { 0.1 };
            for k in 0..p.n_samples() {
                let (a, b) = (fast.gyro.at(k), slow.gyro.at(k));
                let (c, d) = (fast.accel.at(k), slow.accel.at(k));
                for i in 0..3 {
                    assert!((a[i] - b[i]).abs() < 1e-15 * scale, "{kind:?} {k}");
                    assert!((c[i] - d[i]).abs() < 1e-15 * scale, "{kind:?} {k}");
                }
            }
        }
    }

    #[test]
    fn manifest_covers_the_run_and_round_trips() {
        let p = small().build().unwrap();
        let m = &p.manifest;
        assert_eq!(m.set_temperatures_c(), vec![-5.0, 0.0]);
        assert_eq!(m.segments[0].start_s, 0.0);
        for w in m.segments.windows(2) {
            assert_eq!(w[0].end_s, w[1].start_s);
        }
        assert_eq!(m.segments.last().map(|s| s.end_s), Some(m.duration_s));
        for set in [-5.0, 0.0] {
            for up in SignedAxis::POSITIONS {
                let s = m.position(set, up).unwrap();
                assert!((s.duration_s() - 3.0).abs() < 1e-9);
            }
            for axis in BodyAxis::ALL {
                for pos in [true, false] {
                    let s = m.rate(set, axis, pos).unwrap();
                    let SegmentKind::Rate { rate_rad_s, .. } = s.kind else {
                        panic!()
                    };
                    // Whole revolutions.
                    let revs = rate_rad_s.abs() * s.duration_s() / std::f64::consts::TAU;
                    assert!((revs - 1.0).abs() < 1e-12);
                }
            }
        }
        let text = m.to_toml_string().unwrap();
        assert!(text.contains("kind = \"position\"") && text.contains("up = \"+x\""));
        let back = ChamberManifest::from_toml_str(&text).unwrap();
        assert_eq!(&back, m);
        let bad = text.replacen("kind = \"soak\"", "kind = \"soak\"\naxis = \"x\"", 1);
        assert!(ChamberManifest::from_toml_str(&bad).is_err());
        // Temperature steps span the segments of each set point.
        let TemperatureProfile::Chamber { steps, .. } = &p.temperature else {
            panic!()
        };
        let total: f64 = steps.iter().map(|s| s.duration_s).sum();
        assert!((total - m.duration_s).abs() < 1e-9);
    }

    /// Palindromic order: every orientation twice per step with half the dwell, the two
    /// visits of +k and −k (and of +ω and −ω) centred on the same instant, the attitude
    /// continuous and back home, and the static shortcut still exact.
    #[test]
    fn palindromic_order_balances_the_mean_times() {
        let cfg = ChamberConfig {
            step_order: StepOrder::Palindromic,
            rate_revolutions: 2,
            ..small()
        };
        let p = cfg.build().unwrap();
        let m = &p.manifest;
        let steps = m.steps();
        assert_eq!(steps.len(), 2);
        for (set, range) in steps {
            let segs = &m.segments[range];
            let mut centre = None;
            for axis in BodyAxis::ALL {
                let pos = |positive: bool| -> Vec<&Segment> {
                    let up = SignedAxis::new(axis, positive);
                    segs.iter()
                        .filter(|s| s.kind == SegmentKind::Position { up })
                        .collect()
                };
                let (plus, minus) = (pos(true), pos(false));
                assert_eq!((plus.len(), minus.len()), (2, 2), "{set} °C {axis:?}");
                for s in plus.iter().chain(&minus) {
                    assert!((s.duration_s() - 1.5).abs() < 1e-9);
                }
                let (tp, tm) = (mean_time(&plus), mean_time(&minus));
                assert!((tp - tm).abs() < 1e-9, "{set} °C {axis:?}: {tp} vs {tm}");
                // All orientations share one centre.
                let c = *centre.get_or_insert(tp);
                assert!((tp - c).abs() < 1e-9, "{set} °C {axis:?}: {tp} vs {c}");
                let rate = |positive: bool| -> Vec<&Segment> {
                    segs.iter()
                        .filter(|s| {
                            matches!(s.kind, SegmentKind::Rate { axis: a, rate_rad_s }
                            if a == axis && (rate_rad_s > 0.0) == positive)
                        })
                        .collect()
                };
                let (plus, minus) = (rate(true), rate(false));
                assert_eq!((plus.len(), minus.len()), (2, 2));
                let (tp, tm) = (mean_time(&plus), mean_time(&minus));
                assert!(
                    (tp - tm).abs() < 1e-9,
                    "{set} °C {axis:?} rates: {tp} vs {tm}"
                );
                for s in plus.iter().chain(&minus) {
                    let SegmentKind::Rate { rate_rad_s, .. } = s.kind else {
                        panic!()
                    };
                    let revs = rate_rad_s.abs() * s.duration_s() / std::f64::consts::TAU;
                    assert!((revs - 1.0).abs() < 1e-12, "{revs}");
                }
            }
        }
        let tr = &p.trajectory;
        for w in tr.pieces.windows(2) {
            let (a, wa) = w[0].attitude(w[0].duration_s);
            let (b, wb) = w[1].attitude(0.0);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((a.0[r][c] - b.0[r][c]).abs() < 1e-12);
                }
                assert!((wa[r] - wb[r]).abs() < 1e-12);
            }
        }
        assert_eq!(tr.point(m.duration_s + 1.0).c_bn, Mat3::IDENTITY);
        let fast = p.ideal(OutputKind::Rates);
        let dt = 1.0 / m.sample_rate_hz;
        let slow = IdealImu::from_trajectory(tr, OutputKind::Rates, 0.0, dt, p.n_samples());
        for k in 0..p.n_samples() {
            for i in 0..3 {
                assert!((fast.gyro.at(k)[i] - slow.gyro.at(k)[i]).abs() < 1e-14);
                assert!((fast.accel.at(k)[i] - slow.accel.at(k)[i]).abs() < 1e-14);
            }
        }
        // Default order unchanged by the new field; the TOML name round-trips.
        let text = toml::to_string(&cfg).unwrap();
        assert!(text.contains("step_order = \"palindromic\""), "{text}");
        assert_eq!(toml::from_str::<ChamberConfig>(&text).unwrap(), cfg);
        assert_eq!(
            toml::from_str::<ChamberConfig>("soak_s = 20.0\n")
                .unwrap()
                .step_order,
            StepOrder::Sequential
        );
        // An odd revolution count cannot be halved into whole revolutions.
        let e = ChamberConfig {
            rate_revolutions: 3,
            ..cfg
        }
        .build()
        .unwrap_err();
        assert!(e.to_string().contains("even"), "{e}");
    }

    /// Position cycles: the sequence of a step repeated c times, each visit 1/(visits per
    /// position) of the dwell, the ± visits still centred on one instant (palindromic),
    /// and the TOML key round-trips (zero cycles: `rejects_bad_settings`).
    #[test]
    fn position_cycles_repeat_the_sequence() {
        for (order, cycles, visits) in [
            (StepOrder::Sequential, 2, 2),
            (StepOrder::Palindromic, 3, 6),
        ] {
            let cfg = ChamberConfig {
                step_order: order,
                rate_revolutions: 2,
                position_cycles: cycles,
                ..small()
            };
            assert!((cfg.visit_dwell_s() - 3.0 / visits as f64).abs() < 1e-12);
            let p = cfg.build().unwrap();
            let m = &p.manifest;
            for (set, range) in m.steps() {
                let segs = &m.segments[range];
                for up in SignedAxis::POSITIONS {
                    let v: Vec<&Segment> = segs
                        .iter()
                        .filter(|s| s.kind == SegmentKind::Position { up })
                        .collect();
                    // Back-to-back visits of one orientation (the turn of a palindrome,
                    // the join of two cycles) are separate segments of one dwell.
                    assert_eq!(v.len(), visits, "{set} °C {up}");
                    let total: f64 = v.iter().map(|s| s.duration_s()).sum();
                    assert!((total - 3.0).abs() < 1e-9, "{set} °C {up}: {total}");
                    if order == StepOrder::Palindromic {
                        let down = SignedAxis::new(up.axis, !up.positive);
                        let w: Vec<&Segment> = segs
                            .iter()
                            .filter(|s| s.kind == SegmentKind::Position { up: down })
                            .collect();
                        let (a, b) = (mean_time(&v), mean_time(&w));
                        assert!((a - b).abs() < 1e-9, "{set} °C {up}: {a} vs {b}");
                    }
                }
            }
            let text = toml::to_string(&cfg).unwrap();
            assert!(
                text.contains(&format!("position_cycles = {cycles}")),
                "{text}"
            );
            assert_eq!(toml::from_str::<ChamberConfig>(&text).unwrap(), cfg);
        }
    }

    /// The session variants: a prefix (one move segment, tilted in its middle), jittered
    /// dwells and a skipped position, with the attitude still continuous and the TOML
    /// keys round-tripping.
    #[test]
    fn prefix_jitter_and_skipped_positions() {
        let plus_x = SignedAxis::new(BodyAxis::X, true);
        let cfg = ChamberConfig {
            prefix_s: 30.0,
            dwell_jitter: 0.3,
            jitter_seed: 5,
            skip_positions: vec![SkippedPosition {
                set_temperature_c: 0.0,
                up: plus_x,
            }],
            ..small()
        };
        let p = cfg.build().unwrap();
        let m = &p.manifest;
        assert_eq!(m.segments[0].kind, SegmentKind::Move);
        assert!((m.segments[0].duration_s() - 30.0).abs() < 1e-9);
        assert_eq!(m.segments[1].kind, SegmentKind::Soak);
        // Tilted mid-prefix: no body axis within 20° of the vertical.
        let f = p.trajectory.point(15.0).c_bn.t().mul_vec([0.0, 0.0, -1.0]);
        assert!(
            f.iter().all(|v| v.abs() < 20f64.to_radians().cos()),
            "{f:?}"
        );
        assert_eq!(p.trajectory.point(29.0).c_bn, Mat3::IDENTITY);
        let dwell: Vec<f64> = m
            .segments
            .iter()
            .filter(|s| matches!(s.kind, SegmentKind::Position { .. }))
            .map(|s| s.duration_s())
            .collect();
        assert_eq!(dwell.len(), 11);
        assert!(
            dwell.iter().all(|d| (2.1 - 1e-9..=3.9 + 1e-9).contains(d)),
            "{dwell:?}"
        );
        let spread = dwell.iter().fold(0.0f64, |a, &b| a.max(b))
            - dwell.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        assert!(spread > 0.3, "{dwell:?}");
        let soaks: Vec<f64> = m
            .segments
            .iter()
            .filter(|s| s.kind == SegmentKind::Soak)
            .map(|s| s.duration_s())
            .collect();
        assert!(
            soaks
                .iter()
                .all(|d| (14.0 - 1e-9..=26.0 + 1e-9).contains(d)),
            "{soaks:?}"
        );
        assert!(soaks.iter().any(|&d| (d - 20.0).abs() > 1e-6), "{soaks:?}");
        assert!(m.position(0.0, plus_x).is_none());
        assert!(m.position(-5.0, plus_x).is_some());
        assert_eq!(m.steps().len(), 2);
        let TemperatureProfile::Chamber { steps, .. } = &p.temperature else {
            panic!()
        };
        let total: f64 = steps.iter().map(|s| s.duration_s).sum();
        assert!((total - m.duration_s).abs() < 1e-9);
        for w in p.trajectory.pieces.windows(2) {
            let (a, wa) = w[0].attitude(w[0].duration_s);
            let (b, wb) = w[1].attitude(0.0);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((a.0[r][c] - b.0[r][c]).abs() < 1e-12);
                }
                assert!((wa[r] - wb[r]).abs() < 1e-12);
            }
        }
        let text = toml::to_string(&cfg).unwrap();
        assert!(text.contains("up = \"+x\""), "{text}");
        assert_eq!(toml::from_str::<ChamberConfig>(&text).unwrap(), cfg);
        let bad = |c: ChamberConfig| c.build().unwrap_err().to_string();
        let e = bad(ChamberConfig {
            skip_positions: vec![SkippedPosition {
                set_temperature_c: 7.0,
                up: plus_x,
            }],
            ..small()
        });
        assert!(e.contains("skip_positions[0].set_temperature_c = 7"), "{e}");
        let e = bad(ChamberConfig {
            dwell_jitter: 0.95,
            ..small()
        });
        assert!(e.contains("dwell_jitter = 0.95"), "{e}");
        let e = bad(ChamberConfig {
            prefix_s: 3.0,
            ..small()
        });
        assert!(e.contains("prefix_s = 3") && e.contains("too short"), "{e}");
    }

    #[test]
    fn rejects_bad_settings() {
        let cases = [
            (
                ChamberConfig {
                    lag_tau_s: 0.0,
                    ..small()
                },
                "lag_tau_s = 0",
            ),
            (
                ChamberConfig {
                    temperatures_c: vec![],
                    ..small()
                },
                "at least one set temperature",
            ),
            (
                ChamberConfig {
                    rate_revolutions: 0,
                    ..small()
                },
                "rate_revolutions = 0",
            ),
            (
                ChamberConfig {
                    position_cycles: 0,
                    ..small()
                },
                "position_cycles = 0",
            ),
            (
                ChamberConfig {
                    ramp_c_per_min: Some(1.0),
                    ..small()
                },
                "ramp",
            ),
        ];
        for (cfg, want) in cases {
            let e = cfg.build().unwrap_err().to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
        assert!(toml::from_str::<ChamberConfig>("soak = 10\n").is_err());
    }
}

//! Real-time thermal compensation of a six-axis IMU: the kernel a device (or the host's
//! `driftless compensate`) runs on every sample. `no_std`, no allocation, no panics.
//!
//! # Model
//!
//! The room-temperature calibration ([`ImuCalibration`], `calibrated = M·(raw − b)`,
//! see [`crate::calib`]) is extended per triad by temperature-dependent *deltas*
//! ([`TriadThermal`]): a bias delta Δb_k(T) (raw units) and a scale-factor delta Δs_k(T)
//! (dimensionless) per axis k, each a [`ThermalPoly`] — the seed paper's eqs. (1)–(2)
//! (§3.3: bias and scale factor as cubics in t − t₀ about room temperature t₀) with the
//! constant term removed. **Both deltas are zero at T_ref** (their c₀ must be 0): the
//! value at the reference temperature is carried by the room-temperature calibration
//! (b and M), so a model without thermal terms is exactly the room calibration.
//!
//! # Equation
//!
//! ```text
//! r   = raw − b − Δb(T)                  (raw units)
//! r_k ← r_k / (1 + Δs_k(T))              (k = x, y, z)
//! out = M · r                            (rad/s or m/s²)
//! ```
//!
//! i.e. out = M(T)·(raw − b(T)) with the effective calibration at T
//! b(T) = b + Δb(T), M(T) = M·diag(1/(1 + Δs(T))) ([`CompensationModel::calibration_at`]).
//! This is the usual inverse of the inertial-sensor error model (Groves 2013, *Principles
//! of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., §4.4:
//! ỹ = b + (I + M_s)·y, solved for y) with temperature-dependent b and M_s.
//!
//! ## Derivation: exact inverse of the simulator's deterministic model
//!
//! The simulator (`driftless::sim::sensor`) generates, per triad at temperature T,
//!
//! ```text
//! y = (I + S(T))·(I + M_mis)·x + b_on + b_sim(T)      (+ G·f + n, ignored here)
//! ```
//!
//! with S(T) = diag(s_k(T)). Choose
//!
//! ```text
//! M      = ((I + S(T_ref))·(I + M_mis))⁻¹
//! b      = b_on + b_sim(T_ref)
//! Δb(T)  = b_sim(T) − b_sim(T_ref)
//! Δs(T)  = (s(T) − s(T_ref)) / (1 + s(T_ref))          (per axis)
//! ```
//!
//! Then y − b − Δb(T) = (I + S(T))·(I + M_mis)·x. Diagonal matrices commute and
//! 1 + s_k(T) = (1 + s_k(T_ref))·(1 + Δs_k(T)), so
//! (I + S(T)) = diag(1 + Δs(T))·(I + S(T_ref)); dividing component k by 1 + Δs_k(T)
//! leaves (I + S(T_ref))·(I + M_mis)·x, and M maps that to x. ∎ Both deltas are again
//! polynomials in ΔT = T − T_ref (Δs's coefficients are d_j/(1 + d₀), j ≥ 1), built by
//! [`TriadThermal::from_forward`].
//!
//! ## Gyro g-sensitivity
//!
//! A MEMS gyro also responds to specific force: raw_ω = A·ω + b + G·f (G in raw gyro
//! units per m/s²; Groves 2013 §4.4.4). A model may carry G
//! ([`CompensationModel::with_gyro_g_sensitivity`], estimated by the soak's six-position
//! fits); the gyro is then compensated with the compensated specific force of the same
//! sample as the best estimate of f:
//!
//! ```text
//! f_out = M_a(T)·(raw_a − b_a(T))
//! ω_out = M_g(T)·(raw_ω − b_g(T) − G·f_out)
//! ```
//!
//! Without G the gyro line is ω_out = M_g(T)·(raw_ω − b_g(T)), as before.
//!
//! # Temperature range
//!
//! The fitted range is [`CompensationModel::range_c`] (the polynomials' own ranges must
//! contain it). Outside it the [`OutOfRange`] policy applies: hold the end values
//! (`Clamp`, default — the PX4/ArduPilot behaviour), evaluate anyway (`Extrapolate`), or
//! refuse (`Error`). A NaN or infinite temperature is always an error.
//!
//! # Throughput
//!
//! Evaluating 12 polynomials costs more than applying the result. Temperature changes
//! slowly and is reported quantised, so the block APIs
//! ([`CompensationModel::compensate_block`], [`CompensationModel::compensate_block_f32`])
//! evaluate the polynomials once per run of equal temperatures and apply the cached
//! effective calibration to the run. They give bit-for-bit the per-sample results.
//!
//! # f32
//!
//! The f32 APIs evaluate the polynomials and form M(T), b(T) in f64, round them to f32
//! once per temperature, and do the per-sample arithmetic (3 subtractions, a 3×3
//! product) in f32. The error versus the f64 path is a few f32 ulps of the terms:
//! |out₃₂ − out₆₄|_k ≤ 4·2⁻²⁴·Σ_j |M(T)_kj|·(|raw_j| + |b(T)_j|) (tested). For raw
//! values already in SI this is ~1e-7 relative; for raw counts with a large bias it is
//! ~2⁻²⁴·|b| counts (e.g. 0.002 counts at b = 32768), below the quantisation of the
//! input.
//!
//! # Guard against double application
//!
//! Compensating an already compensated stream silently corrupts it. Every model has an
//! `id`; whoever stores compensated output records a [`CompensationStamp`] (the host
//! writes `model_id` into the log's metadata) and checks incoming data with
//! [`check_not_compensated`] before compensating: `driftless compensate` refuses a
//! stamped input, naming the model that compensated it.

use core::fmt;

use crate::calib::{ImuCalibration, TriadCalibration};
use crate::linalg::{Mat3, Vec3};
use crate::thermal::{MAX_ORDER, ThermalPoly};

mod bank;
use bank::*;

/// Temperature-dependent deltas of one triad, about T_ref (zero there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadThermal {
    /// Δb_k(T), raw units: bias minus its value at T_ref (c₀ = 0).
    pub bias_delta: [ThermalPoly; 3],
    /// Δs_k(T), dimensionless: relative scale-factor change from T_ref (c₀ = 0).
    pub scale_delta: [ThermalPoly; 3],
}

impl TriadThermal {
    /// The deltas that invert a forward model with bias b_sim(T) and scale-factor error
    /// s(T) per axis (each polynomial about its own T_ref; see the module doc):
    /// Δb = b_sim − c₀, Δs = (s − s₀)/(1 + s₀). Fails when 1 + s₀ is 0 or a coefficient
    /// overflows.
    pub fn from_forward(
        bias: &[ThermalPoly; 3],
        scale: &[ThermalPoly; 3],
    ) -> Result<TriadThermal, CompensationError> {
        let mut bias_delta = [ThermalPoly::constant(0.0); 3];
        let mut scale_delta = [ThermalPoly::constant(0.0); 3];
        for k in 0..3 {
            let (lo, hi) = bias[k].range_c();
            let mut c = *bias[k].coeffs();
            c[0] = 0.0;
            bias_delta[k] = ThermalPoly::new(bias[k].t_ref_c(), &c, lo, hi)
                .map_err(|_| CompensationError::InvalidModel("bias delta not finite"))?;
            let (lo, hi) = scale[k].range_c();
            let s = scale[k].coeffs();
            let den = 1.0 + s[0];
            if den == 0.0 || !den.is_finite() {
                return Err(CompensationError::InvalidModel(
                    "scale factor 1 + s(T_ref) is zero",
                ));
            }
            let mut d = [0.0; 6];
            for j in 1..d.len() {
                d[j] = s[j] / den;
            }
            scale_delta[k] = ThermalPoly::new(scale[k].t_ref_c(), &d, lo, hi)
                .map_err(|_| CompensationError::InvalidModel("scale delta not finite"))?;
        }
        Ok(TriadThermal {
            bias_delta,
            scale_delta,
        })
    }
}

/// What to do with a temperature outside the model's fitted range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OutOfRange {
    /// Evaluate at the nearest range end (hold the end values).
    #[default]
    Clamp,
    /// Evaluate the polynomials anyway (cubics diverge quickly outside the fit).
    Extrapolate,
    /// Return [`CompensationError::TemperatureOutOfRange`].
    Error,
}

/// Why a sample could not be compensated or a model not built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CompensationError {
    /// The temperature is NaN or infinite (°C).
    NonFiniteTemperature {
        /// The offending value.
        t_c: f64,
    },
    /// The temperature is outside the fitted range and the policy is
    /// [`OutOfRange::Error`].
    TemperatureOutOfRange {
        /// The temperature, °C.
        t_c: f64,
        /// The fitted range, °C.
        range_c: [f64; 2],
    },
    /// 1 + Δs_k(T) is zero or not finite at this temperature (only when extrapolating
    /// far outside the fit).
    SingularScale {
        /// The temperature, °C.
        t_c: f64,
    },
    /// The input carries a compensation stamp: compensating again would corrupt it.
    AlreadyCompensated {
        /// The model named by the stamp.
        stamped_model_id: u64,
        /// The model the caller was about to apply.
        model_id: u64,
    },
    /// The model is inconsistent (the reason).
    InvalidModel(&'static str),
}

impl fmt::Display for CompensationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompensationError::NonFiniteTemperature { t_c } => {
                write!(f, "temperature {t_c} °C is not finite")
            }
            CompensationError::TemperatureOutOfRange { t_c, range_c } => write!(
                f,
                "temperature {t_c} °C outside the model's fitted range [{}, {}] °C",
                range_c[0], range_c[1]
            ),
            CompensationError::SingularScale { t_c } => write!(
                f,
                "scale-factor correction 1 + Δs(T) is zero or not finite at {t_c} °C"
            ),
            CompensationError::AlreadyCompensated {
                stamped_model_id,
                model_id,
            } => write!(
                f,
                "input already compensated by model {stamped_model_id:#018x}; refusing to \
                 apply model {model_id:#018x} on top of it"
            ),
            CompensationError::InvalidModel(why) => write!(f, "invalid compensation model: {why}"),
        }
    }
}

impl core::error::Error for CompensationError {}

/// Why a block could not be compensated. On error **no sample is modified**.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlockError {
    /// The three slices differ in length.
    LengthMismatch {
        /// gyro.len()
        gyro: usize,
        /// accel.len()
        accel: usize,
        /// t_c.len()
        temperature: usize,
    },
    /// Sample `index` failed (the first failing one).
    Sample {
        /// Index into the slices.
        index: usize,
        /// The reason.
        error: CompensationError,
    },
}

impl fmt::Display for BlockError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BlockError::LengthMismatch {
                gyro,
                accel,
                temperature,
            } => write!(
                f,
                "block lengths differ: gyro {gyro}, accel {accel}, temperature {temperature}"
            ),
            BlockError::Sample { index, error } => write!(f, "sample {index}: {error}"),
        }
    }
}

impl core::error::Error for BlockError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            BlockError::Sample { error, .. } => Some(error),
            BlockError::LengthMismatch { .. } => None,
        }
    }
}

/// Marks output as compensated by model `model_id`. The host stores it with the data
/// (log metadata); [`check_not_compensated`] refuses to compensate stamped data again.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CompensationStamp {
    /// [`CompensationModel::id`] of the model that was applied.
    pub model_id: u64,
}

/// `Ok` when `stamp` is `None` (raw data); otherwise
/// [`CompensationError::AlreadyCompensated`] naming the stamping model and `model_id`.
pub fn check_not_compensated(stamp: Option<u64>, model_id: u64) -> Result<(), CompensationError> {
    match stamp {
        None => Ok(()),
        Some(stamped_model_id) => Err(CompensationError::AlreadyCompensated {
            stamped_model_id,
            model_id,
        }),
    }
}

/// A six-axis thermal compensation model: room-temperature calibration plus optional
/// thermal deltas per triad, a fitted range and an out-of-range policy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensationModel {
    id: u64,
    calibration: ImuCalibration,
    gyro: Option<TriadThermal>,
    accel: Option<TriadThermal>,
    range_c: [f64; 2],
    policy: OutOfRange,
    bank: DeltaBank,
    /// G, raw gyro units per m/s², and its f32 copy.
    g_sens: Option<(Mat3, [[f32; 3]; 3])>,
}

impl CompensationModel {
    /// A model. `range_c` = [T_min, T_max] (°C, finite, min ≤ max) must lie inside every
    /// delta polynomial's valid range, every delta must have c₀ = 0, and the crude bound
    /// Σ_j |c_j|·max|T − T_ref|^j over the range must be finite (bias) and below 1
    /// (scale) — so compensation inside the range (and under `Clamp`) cannot fail.
    pub fn new(
        id: u64,
        calibration: ImuCalibration,
        gyro: Option<TriadThermal>,
        accel: Option<TriadThermal>,
        range_c: [f64; 2],
        policy: OutOfRange,
    ) -> Result<CompensationModel, CompensationError> {
        if !(range_c[0].is_finite() && range_c[1].is_finite() && range_c[0] <= range_c[1]) {
            return Err(CompensationError::InvalidModel(
                "range must be finite with min <= max",
            ));
        }
        let cals = [calibration.gyro, calibration.accel];
        if !cals.iter().all(|c| {
            c.bias
                .iter()
                .chain(c.matrix.0.iter().flatten())
                .all(|v| v.is_finite())
        }) {
            return Err(CompensationError::InvalidModel(
                "calibration bias and matrix must be finite",
            ));
        }
        for th in [&gyro, &accel].into_iter().flatten() {
            for p in &th.bias_delta {
                check_delta(p, range_c, f64::MAX)?;
            }
            for p in &th.scale_delta {
                check_delta(p, range_c, 1.0)?;
            }
        }
        Ok(CompensationModel {
            id,
            calibration,
            gyro,
            accel,
            range_c,
            policy,
            bank: DeltaBank::new(&gyro, &accel),
            g_sens: None,
        })
    }

    /// The same model with the gyro g-sensitivity G (raw gyro units per m/s²: raw_ω =
    /// A·ω + b + G·f) compensated too (module doc). Every entry must be finite.
    pub fn with_gyro_g_sensitivity(
        mut self,
        g: Mat3,
    ) -> Result<CompensationModel, CompensationError> {
        if !g.0.iter().flatten().all(|v| v.is_finite()) {
            return Err(CompensationError::InvalidModel(
                "gyro g-sensitivity must be finite",
            ));
        }
        self.g_sens = Some((g, g.0.map(|r| r.map(|v| v as f32))));
        Ok(self)
    }

    /// The gyro g-sensitivity G compensated by this model, raw gyro units per m/s².
    pub fn gyro_g_sensitivity(&self) -> Option<&Mat3> {
        self.g_sens.as_ref().map(|g| &g.0)
    }

    /// Applies an effective calibration to one sample (with G when present).
    #[inline(always)]
    fn apply(&self, c: &ImuCalibration, gyro_raw: Vec3, accel_raw: Vec3) -> (Vec3, Vec3) {
        let f = c.accel.apply(accel_raw);
        let w = match &self.g_sens {
            Some((g, _)) => c.gyro.apply(minus_g(gyro_raw, g, f)),
            None => c.gyro.apply(gyro_raw),
        };
        (w, f)
    }

    /// [`Self::apply`] in f32.
    #[inline(always)]
    fn apply32(
        &self,
        c: &[Triad32; 2],
        gyro_raw: [f32; 3],
        accel_raw: [f32; 3],
    ) -> ([f32; 3], [f32; 3]) {
        let f = c[1].apply(accel_raw);
        let w = match &self.g_sens {
            Some((_, g)) => c[0].apply(minus_g32(gyro_raw, g, f)),
            None => c[0].apply(gyro_raw),
        };
        (w, f)
    }

    /// The model id (recorded in a [`CompensationStamp`]).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The room-temperature calibration (M, b at T_ref).
    pub fn calibration(&self) -> &ImuCalibration {
        &self.calibration
    }

    /// Gyro thermal deltas (`None`: none applied).
    pub fn gyro(&self) -> Option<&TriadThermal> {
        self.gyro.as_ref()
    }

    /// Accelerometer thermal deltas (`None`: none applied).
    pub fn accel(&self) -> Option<&TriadThermal> {
        self.accel.as_ref()
    }

    /// Fitted range [T_min, T_max], °C.
    pub fn range_c(&self) -> [f64; 2] {
        self.range_c
    }

    /// The out-of-range policy.
    pub fn policy(&self) -> OutOfRange {
        self.policy
    }

    /// The same model with another out-of-range policy.
    pub fn with_policy(mut self, policy: OutOfRange) -> CompensationModel {
        self.policy = policy;
        self
    }

    /// The stamp to attach to this model's output.
    pub fn stamp(&self) -> CompensationStamp {
        CompensationStamp { model_id: self.id }
    }

    /// The temperature the polynomials are evaluated at, after the policy.
    #[inline]
    fn eval_temperature(&self, t_c: f64) -> Result<f64, CompensationError> {
        if !t_c.is_finite() {
            return Err(CompensationError::NonFiniteTemperature { t_c });
        }
        let [lo, hi] = self.range_c;
        if t_c >= lo && t_c <= hi {
            return Ok(t_c);
        }
        match self.policy {
            OutOfRange::Clamp => Ok(if t_c < lo { lo } else { hi }),
            OutOfRange::Extrapolate => Ok(t_c),
            OutOfRange::Error => Err(CompensationError::TemperatureOutOfRange {
                t_c,
                range_c: self.range_c,
            }),
        }
    }

    /// The effective calibration at `t_c` (°C): b(T) = b + Δb(T),
    /// M(T) = M·diag(1/(1 + Δs(T))), per triad, after the out-of-range policy.
    pub fn calibration_at(&self, t_c: f64) -> Result<ImuCalibration, CompensationError> {
        let t = self.eval_temperature(t_c)?;
        let v = self.bank.eval(t);
        let (b, s) = (&v.bias, &v.inv_scale);
        Ok(ImuCalibration {
            gyro: match self.gyro {
                Some(_) => triad_at(&self.calibration.gyro, &b[..3], &s[..3], v.ok[0], t_c)?,
                None => self.calibration.gyro,
            },
            accel: match self.accel {
                Some(_) => triad_at(&self.calibration.accel, &b[3..], &s[3..], v.ok[1], t_c)?,
                None => self.calibration.accel,
            },
        })
    }

    fn calibration_at_f32(&self, t_c: f32) -> Result<[Triad32; 2], CompensationError> {
        let c = self.calibration_at(t_c as f64)?;
        Ok([Triad32::from_f64(&c.gyro), Triad32::from_f64(&c.accel)])
    }

    /// Compensates one six-axis sample: raw gyro and accelerometer (raw units) at sensor
    /// temperature `t_c` (°C) → (rad/s, m/s²).
    pub fn compensate(
        &self,
        gyro_raw: Vec3,
        accel_raw: Vec3,
        t_c: f64,
    ) -> Result<(Vec3, Vec3), CompensationError> {
        let c = self.calibration_at(t_c)?;
        Ok(self.apply(&c, gyro_raw, accel_raw))
    }

    /// [`Self::compensate`] with f32 samples: factors in f64, rounded to f32, applied in
    /// f32 (accuracy: module doc).
    pub fn compensate_f32(
        &self,
        gyro_raw: [f32; 3],
        accel_raw: [f32; 3],
        t_c: f32,
    ) -> Result<([f32; 3], [f32; 3]), CompensationError> {
        let c = self.calibration_at_f32(t_c)?;
        Ok(self.apply32(&c, gyro_raw, accel_raw))
    }

    /// Checks lengths and every temperature (once per run of equal bit patterns).
    fn check_block<T: Copy>(
        &self,
        n_gyro: usize,
        n_accel: usize,
        t_c: &[T],
        bits: impl Fn(T) -> u64,
        to_f64: impl Fn(T) -> f64,
    ) -> Result<(), BlockError> {
        if n_gyro != n_accel || n_gyro != t_c.len() {
            return Err(BlockError::LengthMismatch {
                gyro: n_gyro,
                accel: n_accel,
                temperature: t_c.len(),
            });
        }
        let mut last: Option<u64> = None;
        for (index, &t) in t_c.iter().enumerate() {
            let b = bits(t);
            if last == Some(b) {
                continue;
            }
            let t = to_f64(t);
            self.eval_temperature(t)
                .map_err(|error| BlockError::Sample { index, error })?;
            // Inside the range (and so under Clamp) evaluation cannot fail (bounds checked
            // by `new`); only an extrapolated temperature needs the full evaluation.
            let in_range = t >= self.range_c[0] && t <= self.range_c[1];
            if !in_range && self.policy == OutOfRange::Extrapolate {
                self.calibration_at(t)
                    .map_err(|error| BlockError::Sample { index, error })?;
            }
            last = Some(b);
        }
        Ok(())
    }

    /// Compensates a block in place: `gyro[i]`, `accel[i]` (raw units → rad/s, m/s²) at
    /// `t_c[i]` (°C). The polynomials are evaluated once per run of equal temperatures;
    /// the result equals [`Self::compensate`] bit for bit. On error nothing is modified.
    pub fn compensate_block(
        &self,
        gyro: &mut [Vec3],
        accel: &mut [Vec3],
        t_c: &[f64],
    ) -> Result<(), BlockError> {
        self.check_block(gyro.len(), accel.len(), t_c, f64::to_bits, |t| t)?;
        let mut i = 0;
        while i < t_c.len() {
            let t = t_c[i];
            let mut j = i + 1;
            while j < t_c.len() && t_c[j].to_bits() == t.to_bits() {
                j += 1;
            }
            let c = self
                .calibration_at(t)
                .map_err(|error| BlockError::Sample { index: i, error })?;
            for (g, a) in gyro[i..j].iter_mut().zip(&mut accel[i..j]) {
                (*g, *a) = self.apply(&c, *g, *a);
            }
            i = j;
        }
        Ok(())
    }

    /// [`Self::compensate_block`] for f32 samples (bit-identical to
    /// [`Self::compensate_f32`]).
    pub fn compensate_block_f32(
        &self,
        gyro: &mut [[f32; 3]],
        accel: &mut [[f32; 3]],
        t_c: &[f32],
    ) -> Result<(), BlockError> {
        self.check_block(
            gyro.len(),
            accel.len(),
            t_c,
            |t| u64::from(t.to_bits()),
            f64::from,
        )?;
        let mut i = 0;
        while i < t_c.len() {
            let t = t_c[i];
            let mut j = i + 1;
            while j < t_c.len() && t_c[j].to_bits() == t.to_bits() {
                j += 1;
            }
            let c = self
                .calibration_at_f32(t)
                .map_err(|error| BlockError::Sample { index: i, error })?;
            for (g, a) in gyro[i..j].iter_mut().zip(&mut accel[i..j]) {
                (*g, *a) = self.apply32(&c, *g, *a);
            }
            i = j;
        }
        Ok(())
    }
}

/// Helper for hosts and tests: the room calibration that inverts a forward triad
/// (I + S(T_ref))·(I + M_mis)·x + b_on + b_sim(T_ref) (module doc): M = ((I + S₀)(I +
/// M_mis))⁻¹, b = b_on + b_sim(T_ref). `None` when the matrix is singular.
pub fn room_calibration_from_forward(
    scale_at_ref: Vec3,
    i_plus_misalignment: &Mat3,
    bias_at_ref: Vec3,
) -> Option<TriadCalibration> {
    let d = Mat3::diag([
        1.0 + scale_at_ref[0],
        1.0 + scale_at_ref[1],
        1.0 + scale_at_ref[2],
    ]);
    Some(TriadCalibration {
        bias: bias_at_ref,
        matrix: d.mul_mat(i_plus_misalignment).inverse()?,
    })
}

/// Streaming per-sample compensation, as on a device: one call per sample, the effective
/// calibration at the last temperature reading cached, so the polynomials are evaluated
/// only when the reading changes (temperature moves slowly; sensors report it quantised).
/// Results equal [`CompensationModel::compensate`] / [`CompensationModel::compensate_f32`]
/// bit for bit.
#[derive(Clone, Debug)]
pub struct Compensator<'a> {
    model: &'a CompensationModel,
    last_bits: Option<u64>,
    cal: ImuCalibration,
    last_bits32: Option<u32>,
    cal32: [Triad32; 2],
}

impl<'a> Compensator<'a> {
    /// A compensator with an empty cache.
    pub fn new(model: &'a CompensationModel) -> Compensator<'a> {
        Compensator {
            model,
            last_bits: None,
            cal: model.calibration,
            last_bits32: None,
            cal32: [Triad32::from_f64(&model.calibration.gyro); 2],
        }
    }

    /// [`CompensationModel::compensate`] with the cached factors.
    pub fn compensate(
        &mut self,
        gyro_raw: Vec3,
        accel_raw: Vec3,
        t_c: f64,
    ) -> Result<(Vec3, Vec3), CompensationError> {
        if self.last_bits != Some(t_c.to_bits()) {
            self.cal = self.model.calibration_at(t_c)?;
            self.last_bits = Some(t_c.to_bits());
        }
        Ok(self.model.apply(&self.cal, gyro_raw, accel_raw))
    }

    /// [`CompensationModel::compensate_f32`] with the cached factors.
    pub fn compensate_f32(
        &mut self,
        gyro_raw: [f32; 3],
        accel_raw: [f32; 3],
        t_c: f32,
    ) -> Result<([f32; 3], [f32; 3]), CompensationError> {
        if self.last_bits32 != Some(t_c.to_bits()) {
            self.cal32 = self.model.calibration_at_f32(t_c)?;
            self.last_bits32 = Some(t_c.to_bits());
        }
        Ok(self.model.apply32(&self.cal32, gyro_raw, accel_raw))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::add;

    const T_REF: f64 = 25.0;
    const RANGE: [f64; 2] = [-20.0, 70.0];

    /// A hand-built forward model (simulator's deterministic part) for one triad.
    struct Forward {
        bias: [ThermalPoly; 3],
        scale: [ThermalPoly; 3],
        i_plus_m: Mat3,
        b_on: Vec3,
    }

    impl Forward {
        fn y(&self, x: Vec3, t_c: f64) -> Vec3 {
            let s = Mat3::diag([
                1.0 + self.scale[0].eval(t_c),
                1.0 + self.scale[1].eval(t_c),
                1.0 + self.scale[2].eval(t_c),
            ]);
            let b = [
                self.bias[0].eval(t_c),
                self.bias[1].eval(t_c),
                self.bias[2].eval(t_c),
            ];
            add(add(s.mul_mat(&self.i_plus_m).mul_vec(x), self.b_on), b)
        }

        fn room(&self) -> TriadCalibration {
            let s0 = [
                self.scale[0].eval(T_REF),
                self.scale[1].eval(T_REF),
                self.scale[2].eval(T_REF),
            ];
            let b0 = [
                self.b_on[0] + self.bias[0].eval(T_REF),
                self.b_on[1] + self.bias[1].eval(T_REF),
                self.b_on[2] + self.bias[2].eval(T_REF),
            ];
            room_calibration_from_forward(s0, &self.i_plus_m, b0).unwrap()
        }
    }

    fn poly(c: &[f64]) -> ThermalPoly {
        ThermalPoly::new(T_REF, c, RANGE[0], RANGE[1]).unwrap()
    }

    /// Counts-like gyro (LSB = 1e-3 rad/s·…, large bias) and SI accelerometer.
    fn forwards() -> (Forward, Forward) {
        let gyro = Forward {
            bias: [
                poly(&[12.0, 0.3, -4e-3, 2e-5]),
                poly(&[-7.0, -0.2, 3e-3, -1e-5]),
                poly(&[3.0, 0.1, 1e-3, 4e-6]),
            ],
            scale: [
                poly(&[1e-3, 2e-5, -3e-7, 1e-9]),
                poly(&[-2e-3, -1e-5, 2e-7, -2e-9]),
                poly(&[5e-4, 3e-5, 1e-7, 3e-9]),
            ],
            i_plus_m: Mat3([
                [1.0, 2e-3, -1e-3],
                [-1.5e-3, 1.0, 3e-3],
                [0.5e-3, -2e-3, 1.0],
            ])
            .mul_mat(&Mat3::diag([1000.0, 1000.0, 1000.0])),
            b_on: [30.0, -20.0, 10.0],
        };
        let accel = Forward {
            bias: [
                poly(&[0.05, 1e-3, -2e-5, 1e-7]),
                poly(&[-0.03, -8e-4, 1e-5, -3e-7]),
                poly(&[0.02, 5e-4, 3e-5, 2e-7]),
            ],
            scale: [
                poly(&[3e-3, -4e-5, 2e-7, -1e-9]),
                poly(&[-1e-3, 2e-5, -1e-7, 2e-9]),
                poly(&[2e-3, 1e-5, 3e-7, 1e-9]),
            ],
            i_plus_m: Mat3([[1.0, -1e-3, 2e-3], [1e-3, 1.0, -2e-3], [3e-3, 1e-3, 1.0]]),
            b_on: [0.01, -0.02, 0.005],
        };
        (gyro, accel)
    }

    fn model(policy: OutOfRange) -> (CompensationModel, Forward, Forward) {
        let (g, a) = forwards();
        let m = CompensationModel::new(
            0xD1F7,
            ImuCalibration {
                gyro: g.room(),
                accel: a.room(),
            },
            Some(TriadThermal::from_forward(&g.bias, &g.scale).unwrap()),
            Some(TriadThermal::from_forward(&a.bias, &a.scale).unwrap()),
            RANGE,
            policy,
        )
        .unwrap();
        (m, g, a)
    }

    const TEMPS: [f64; 7] = [-20.0, -5.5, 10.0, 25.0, 41.25, 60.0, 70.0];
    const W: Vec3 = [0.7, -1.3, 0.25];
    const F: Vec3 = [1.2, -0.4, 9.80665];

    fn rel_err(got: Vec3, want: Vec3) -> f64 {
        let n = libm::sqrt(want.iter().map(|v| v * v).sum::<f64>());
        let e = libm::sqrt(
            (0..3)
                .map(|k| (got[k] - want[k]) * (got[k] - want[k]))
                .sum::<f64>(),
        );
        e / n
    }

    /// With the gyro g-sensitivity raw_ω = y(ω) + G·f (counts per m/s²), a model that
    /// carries G inverts it exactly; block, streaming and f32 paths agree with the
    /// per-sample one; the model without G leaves G·f in the gyro (what is fixed).
    #[test]
    fn compensates_gyro_g_sensitivity() {
        let (m, g, a) = model(OutOfRange::Error);
        let gs = Mat3([
            [0.02, -0.004, 0.001],
            [0.003, 0.015, -0.002],
            [0.0, 0.005, 0.03],
        ]);
        let mg = m.with_gyro_g_sensitivity(gs).unwrap();
        assert_eq!(mg.gyro_g_sensitivity(), Some(&gs));
        let mut gyro = [[0.0; 3]; TEMPS.len()];
        let mut accel = [[0.0; 3]; TEMPS.len()];
        let temp = TEMPS;
        for (i, &t) in TEMPS.iter().enumerate() {
            let raw_w = add(g.y(W, t), gs.mul_vec(F));
            let (w, f) = mg.compensate(raw_w, a.y(F, t), t).unwrap();
            assert!(rel_err(w, W) <= 1e-12, "gyro at {t}: {:e}", rel_err(w, W));
            assert!(rel_err(f, F) <= 1e-12, "accel at {t}: {:e}", rel_err(f, F));
            let (w0, _) = m.compensate(raw_w, a.y(F, t), t).unwrap();
            assert!(
                rel_err(w0, W) > 1e-4,
                "without G the error stays: {:e}",
                rel_err(w0, W)
            );
            gyro[i] = raw_w;
            accel[i] = a.y(F, t);
        }
        let (mut bg, mut ba) = (gyro, accel);
        mg.compensate_block(&mut bg, &mut ba, &temp).unwrap();
        let mut streaming = Compensator::new(&mg);
        for i in 0..temp.len() {
            let want = mg.compensate(gyro[i], accel[i], temp[i]).unwrap();
            assert_eq!((bg[i], ba[i]), want);
            assert_eq!(
                streaming.compensate(gyro[i], accel[i], temp[i]).unwrap(),
                want
            );
            let g32 = gyro[i].map(|v| v as f32);
            let a32 = accel[i].map(|v| v as f32);
            let (w32, _) = mg.compensate_f32(g32, a32, temp[i] as f32).unwrap();
            let w64 = [w32[0] as f64, w32[1] as f64, w32[2] as f64];
            assert!(rel_err(w64, W) <= 1e-4, "f32 gyro: {:e}", rel_err(w64, W));
        }
        let bad = Mat3([[f64::NAN, 0.0, 0.0], [0.0; 3], [0.0; 3]]);
        assert!(matches!(
            m.with_gyro_g_sensitivity(bad),
            Err(CompensationError::InvalidModel(_))
        ));
    }

    #[test]
    fn inverts_the_forward_model_exactly() {
        let (m, g, a) = model(OutOfRange::Error);
        for t in TEMPS {
            let (w, f) = m.compensate(g.y(W, t), a.y(F, t), t).unwrap();
            assert!(rel_err(w, W) <= 1e-12, "gyro at {t}: {:e}", rel_err(w, W));
            assert!(rel_err(f, F) <= 1e-12, "accel at {t}: {:e}", rel_err(f, F));
        }
        // Without thermal terms: exactly the room calibration.
        let plain =
            CompensationModel::new(1, *m.calibration(), None, None, RANGE, OutOfRange::Clamp)
                .unwrap();
        let raw = g.y(W, 40.0);
        assert_eq!(
            plain.compensate(raw, raw, 40.0).unwrap().0,
            m.calibration().gyro.apply(raw)
        );
    }

    /// f32 vs f64: bound 4·2⁻²⁴·Σ_j |M(T)_kj|·(|raw_j| + |b(T)_j|) per component.
    #[test]
    fn f32_accuracy() {
        let (m, g, a) = model(OutOfRange::Clamp);
        let mut worst_rel = 0.0f64;
        for t in TEMPS {
            let c = m.calibration_at(t).unwrap();
            for (k, x) in [W, [-3.0, 2.0, 0.01], [0.0, 0.0, 0.0]]
                .into_iter()
                .enumerate()
            {
                let yg = g.y(x, t);
                let ya = a.y(if k == 0 { F } else { x }, t);
                let to32 = |v: Vec3| [v[0] as f32, v[1] as f32, v[2] as f32];
                let (g32, a32) = m.compensate_f32(to32(yg), to32(ya), t as f32).unwrap();
                // The f64 reference on the same (f32-rounded) inputs and temperature.
                let back = |v: [f32; 3]| [v[0] as f64, v[1] as f64, v[2] as f64];
                let (g64, a64) = m
                    .compensate(back(to32(yg)), back(to32(ya)), t as f32 as f64)
                    .unwrap();
                for (out32, out64, raw, cal) in [
                    (g32, g64, back(to32(yg)), &c.gyro),
                    (a32, a64, back(to32(ya)), &c.accel),
                ] {
                    for i in 0..3 {
                        let scale: f64 = (0..3)
                            .map(|j| cal.matrix.0[i][j].abs() * (raw[j].abs() + cal.bias[j].abs()))
                            .sum();
                        let err = (out32[i] as f64 - out64[i]).abs();
                        assert!(
                            err <= 4.0 * f32::EPSILON as f64 / 2.0 * scale,
                            "{err:e} vs {scale:e}"
                        );
                        worst_rel = worst_rel.max(err / scale);
                    }
                }
            }
        }
        assert!(worst_rel > 0.0);
    }

    #[test]
    fn out_of_range_policies() {
        let (clamp, g, a) = model(OutOfRange::Clamp);
        let (raw_g, raw_a) = (g.y(W, 50.0), a.y(F, 50.0));
        for (t, end) in [(95.0, 70.0), (-41.0, -20.0)] {
            assert_eq!(
                clamp.compensate(raw_g, raw_a, t).unwrap(),
                clamp.compensate(raw_g, raw_a, end).unwrap()
            );
            let ext = clamp.with_policy(OutOfRange::Extrapolate);
            let (w, f) = ext.compensate(g.y(W, t), a.y(F, t), t).unwrap();
            assert!(rel_err(w, W) <= 1e-12 && rel_err(f, F) <= 1e-12);
            let err = clamp.with_policy(OutOfRange::Error);
            assert_eq!(
                err.compensate(raw_g, raw_a, t),
                Err(CompensationError::TemperatureOutOfRange {
                    t_c: t,
                    range_c: RANGE
                })
            );
            assert_eq!(
                err.compensate_f32([0.0; 3], [0.0; 3], t as f32),
                Err(CompensationError::TemperatureOutOfRange {
                    t_c: t,
                    range_c: RANGE
                })
            );
        }
        // Range ends are inside.
        let err = clamp.with_policy(OutOfRange::Error);
        assert!(err.compensate(raw_g, raw_a, 70.0).is_ok());
        assert!(err.compensate(raw_g, raw_a, -20.0).is_ok());
    }

    #[test]
    fn non_finite_temperature_is_an_error_under_every_policy() {
        for p in [
            OutOfRange::Clamp,
            OutOfRange::Extrapolate,
            OutOfRange::Error,
        ] {
            let (m, _, _) = model(p);
            for t in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                match m.compensate([0.0; 3], [0.0; 3], t) {
                    Err(CompensationError::NonFiniteTemperature { t_c }) => {
                        assert_eq!(t_c.to_bits(), t.to_bits())
                    }
                    other => panic!("{other:?}"),
                }
                assert!(matches!(
                    m.compensate_f32([0.0; 3], [0.0; 3], t as f32),
                    Err(CompensationError::NonFiniteTemperature { .. })
                ));
            }
        }
    }

    fn block_inputs(n: usize) -> (Vec3Buf, Vec3Buf, [f64; N_BLOCK]) {
        let (_, g, a) = model(OutOfRange::Clamp);
        let mut gy = [[0.0; 3]; N_BLOCK];
        let mut ac = [[0.0; 3]; N_BLOCK];
        let mut t = [0.0; N_BLOCK];
        for i in 0..n {
            // Quantised ramp beyond the range (exercises clamping), with repeats.
            t[i] = -30.0 + 0.25 * (i / 3) as f64;
            let x = [0.1 * i as f64, -0.05 * i as f64, 1.0];
            gy[i] = g.y(x, t[i]);
            ac[i] = a.y(x, t[i]);
        }
        (gy, ac, t)
    }

    const N_BLOCK: usize = 600;
    type Vec3Buf = [Vec3; N_BLOCK];

    #[test]
    fn block_equals_per_sample_bit_for_bit() {
        let (m, _, _) = model(OutOfRange::Clamp);
        let (mut gy, mut ac, t) = block_inputs(N_BLOCK);
        let (g0, a0) = (gy, ac);
        m.compensate_block(&mut gy, &mut ac, &t).unwrap();
        let mut g32 = [[0.0f32; 3]; N_BLOCK];
        let mut a32 = [[0.0f32; 3]; N_BLOCK];
        let mut t32 = [0.0f32; N_BLOCK];
        for i in 0..N_BLOCK {
            let (w, f) = m.compensate(g0[i], a0[i], t[i]).unwrap();
            assert_eq!(w.map(f64::to_bits), gy[i].map(f64::to_bits));
            assert_eq!(f.map(f64::to_bits), ac[i].map(f64::to_bits));
            g32[i] = g0[i].map(|v| v as f32);
            a32[i] = a0[i].map(|v| v as f32);
            t32[i] = t[i] as f32;
        }
        let (g32_0, a32_0) = (g32, a32);
        m.compensate_block_f32(&mut g32, &mut a32, &t32).unwrap();
        for i in 0..N_BLOCK {
            let (w, f) = m.compensate_f32(g32_0[i], a32_0[i], t32[i]).unwrap();
            assert_eq!(w.map(f32::to_bits), g32[i].map(f32::to_bits));
            assert_eq!(f.map(f32::to_bits), a32[i].map(f32::to_bits));
        }
    }

    #[test]
    fn block_errors_leave_data_untouched() {
        let (m, _, _) = model(OutOfRange::Error);
        let (mut gy, mut ac, mut t) = block_inputs(N_BLOCK);
        t[0] = 25.0;
        let before = (gy, ac);
        // t[i] first leaves the range at -30 + 0.25·(i/3) < -20 … i.e. index 1.
        assert_eq!(
            m.compensate_block(&mut gy, &mut ac, &t),
            Err(BlockError::Sample {
                index: 1,
                error: CompensationError::TemperatureOutOfRange {
                    t_c: -30.0,
                    range_c: RANGE
                }
            })
        );
        assert_eq!((gy, ac), before);
        let m = m.with_policy(OutOfRange::Clamp);
        t[400] = f64::NAN;
        assert!(matches!(
            m.compensate_block(&mut gy, &mut ac, &t),
            Err(BlockError::Sample {
                index: 400,
                error: CompensationError::NonFiniteTemperature { .. }
            })
        ));
        assert_eq!((gy, ac), before);
        assert_eq!(
            m.compensate_block(&mut gy[..3], &mut ac[..2], &t[..3]),
            Err(BlockError::LengthMismatch {
                gyro: 3,
                accel: 2,
                temperature: 3
            })
        );
        assert!(m.compensate_block(&mut [], &mut [], &[]).is_ok());
    }

    #[test]
    fn model_validation_and_stamp() {
        let (m, g, _) = model(OutOfRange::Clamp);
        let th = TriadThermal::from_forward(&g.bias, &g.scale).unwrap();
        let cal = *m.calibration();
        let mut bad = th;
        bad.bias_delta[1] = poly(&[0.5, 1e-3]);
        assert!(matches!(
            CompensationModel::new(1, cal, Some(bad), None, RANGE, OutOfRange::Clamp),
            Err(CompensationError::InvalidModel(_))
        ));
        // Range wider than the polynomials' fit.
        assert!(matches!(
            CompensationModel::new(1, cal, Some(th), None, [-40.0, 70.0], OutOfRange::Clamp),
            Err(CompensationError::InvalidModel(_))
        ));
        assert!(matches!(
            CompensationModel::new(1, cal, None, None, [1.0, 0.0], OutOfRange::Clamp),
            Err(CompensationError::InvalidModel(_))
        ));
        // |Δs| may reach 1 inside the range: rejected.
        let mut bad = th;
        bad.scale_delta[2] = poly(&[0.0, 0.0, 1e-3]);
        assert!(matches!(
            CompensationModel::new(1, cal, None, Some(bad), RANGE, OutOfRange::Clamp),
            Err(CompensationError::InvalidModel(_))
        ));
        // Δs = −0.01·ΔT is fine in range, singular at 125 °C when extrapolating; the block
        // API reports it before touching anything.
        let mut lin = th;
        lin.scale_delta[0] = poly(&[0.0, -0.01]);
        let ext = CompensationModel::new(1, cal, Some(lin), None, RANGE, OutOfRange::Extrapolate)
            .unwrap();
        assert_eq!(
            ext.compensate([1.0; 3], [1.0; 3], 125.0),
            Err(CompensationError::SingularScale { t_c: 125.0 })
        );
        let mut gy = [[1.0; 3]; 3];
        let mut ac = [[2.0; 3]; 3];
        assert_eq!(
            ext.compensate_block(&mut gy, &mut ac, &[25.0, 30.0, 125.0]),
            Err(BlockError::Sample {
                index: 2,
                error: CompensationError::SingularScale { t_c: 125.0 }
            })
        );
        assert_eq!((gy, ac), ([[1.0; 3]; 3], [[2.0; 3]; 3]));
        // Δs of a forward scale polynomial: zero at T_ref, coefficients d_j/(1 + d0).
        assert_eq!(th.scale_delta[0].eval(T_REF), 0.0);
        assert_eq!(th.scale_delta[0].coeffs()[1], 2e-5 / (1.0 + 1e-3));

        assert_eq!(check_not_compensated(None, m.id()), Ok(()));
        let stamp = m.stamp();
        assert_eq!(
            check_not_compensated(Some(stamp.model_id), m.id()),
            Err(CompensationError::AlreadyCompensated {
                stamped_model_id: 0xD1F7,
                model_id: 0xD1F7
            })
        );
    }

    #[test]
    fn compensator_equals_the_model_bit_for_bit() {
        let (m, _, _) = model(OutOfRange::Clamp);
        let mut c = Compensator::new(&m);
        for (k, t) in [25.0, 25.0, 31.5, 31.5, -20.0, 60.0, 60.0]
            .into_iter()
            .enumerate()
        {
            let g = [0.1 * k as f64, -0.02, 0.3];
            let a = [0.5, -9.8 + 0.01 * k as f64, 0.2];
            assert_eq!(c.compensate(g, a, t), m.compensate(g, a, t));
            let g32 = g.map(|v| v as f32);
            let a32 = a.map(|v| v as f32);
            assert_eq!(
                c.compensate_f32(g32, a32, t as f32),
                m.compensate_f32(g32, a32, t as f32)
            );
        }
        assert!(c.compensate([0.0; 3], [0.0; 3], f64::NAN).is_err());
    }
}

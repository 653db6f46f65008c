//! Six-position (accelerometer) and rate-table (gyro) calibration with parameter
//! covariances — IEEE Std 1293-2018 (Annex: the multi-position "tumble" test), Titterton
//! & Weston, *Strapdown inertial navigation technology*, 2nd ed. 2004, §8.3 (six-position
//! and rate-transfer tests), Groves, *Principles of GNSS, inertial, and multisensor
//! integrated navigation systems*, 2nd ed. 2013, §4.4 (error models).
//!
//! # Model
//!
//! Per triad, the raw output (raw units; SI for simulated data) of a true input x is
//!
//! ```text
//! raw = A·x + b (+ G·f for the gyro, optional)
//! ```
//!
//! with A (3 × 3) scale factor and misalignment, b the bias and G the gyro g-sensitivity
//! in raw units per m/s². The reported calibration is
//! [`TriadCalibration`] `{ bias: b, matrix: M = A⁻¹ }`, i.e. calibrated = M·(raw − b).
//! With the simulator's forward model (`sim::sensor`), A = (I + S)(I + M_mis).
//!
//! # Accelerometer (12 parameters, linear least squares)
//!
//! In a static position with body axis u (a signed unit axis) pointing up the specific
//! force is f = g·u (g the local normal gravity, [`crate::nav::earth::normal_gravity_m_s2`],
//! or an override). Every output axis i gives one linear equation per position,
//!
//! ```text
//! raw_i(p) = Σ_j A_ij·f_j(p) + b_i,
//! ```
//!
//! four unknowns per output axis, solved separately (the axes' noises are independent)
//! from all positions (≥ 6, each axis up and down; repeats are welcome).
//!
//! # Gyro (12 parameters, or 21 with G)
//!
//! Per output axis i, one linear least squares over static positions and rate segments:
//!
//! * static position p (attitude C_bn(p)): the truth is Earth rate
//!   ω^b = C_bnᵀ·ω_ie^n, ω_ie^n = Ω(cos L, 0, −sin L) (Groves eq. 2.123), so
//!   raw_i = A_i·ω^b + b_i (+ G_i·f^b): the Earth rate is *modelled*, not averaged out.
//!   It depends on the heading in each position: [`PositionMean::c_bn`] defaults to the
//!   chamber protocol's attitude ([`SignedAxis::c_bn_up`]: a horizontal axis north);
//!   set it for another fixture, or set the Earth rate to 0 to ignore it.
//! * rate segment: a constant rate ω about body axis k over whole revolutions with the
//!   table axis vertical and body axis u (normally +k) up. The horizontal Earth rate
//!   averages to zero over whole revolutions and the vertical part is Ω sin L along u, so
//!   the mean truth is ω^b = ω·e_k + Ω sin L·u and f^b = g·u. Opposite rates ±ω thus give
//!   column k of A from (raw⁺ − raw⁻)/(2ω) (Titterton & Weston §8.3.3); the joint fit
//!   uses the same information plus the bias.
//!
//! # Gyro g-sensitivity
//!
//! A MEMS gyro also responds to the specific force it feels (the g-dependent bias of
//! Groves §4.4; the acceleration-sensitive drift rate of IEEE Std 1431-2004 for Coriolis
//! vibratory gyros), so the gyro model of every observation is
//!
//! ```text
//! ω_meas,i = Σ_j A_ij·ω_j + b_i + Σ_j G_ij·f_j,      f = g·u   (u: the body axis up)
//! ```
//!
//! G (raw units per m/s²) is estimated with [`SixPositionOptions::estimate_g_sensitivity`]
//! (3 more parameters per output axis, [`GSensitivityEstimate`] with σ). Everything
//! observed here is level with a body axis up, so the G terms enter each row only
//! through its intercept b_i + g·G_i·u.
//!
//! **Identifiability.** G is separable from b iff the intercept regressors (1, u) of the
//! observations span R⁴ — for u among the signed body axes: every axis is seen up or
//! down, and at least one both ways ([`g_sensitivity_identifiable`]). The static
//! positions of this calibration (each axis up *and* down, checked:
//! [`SixPositionError::MissingDirection`]) always satisfy it on their own: the ±k pair
//! gives b_i ± g·G_ik (plus modelled Earth-rate terms), so column k of G is half their
//! difference over g. The rate segments alone cannot supply it: all turned with +k up (the
//! chamber protocol, [`SixPositionInput::from_manifest_columns`]), their intercept is
//! b_i + g·G_ik. That is also why G must be modelled when the rate segments are all +k
//! up: left out, the intercepts b_i + g·G_ik of the rate rows pull the least-squares
//! bias towards them (on `adi-like`, 0.2 °/s/g on the sensing axis, the gyro-z bias of a
//! soak was off by ≈ 1.9 % of its thermal swing, `tests/thermal_soak.rs`). With rate
//! segments balanced between +k and −k up the effect would cancel in b, but not in
//! [`SixPositionOptions::from_manifest`]'s protocols, which is why that constructor turns
//! G on whenever every step of the manifest identifies it.
//!
//! # Covariances
//!
//! Each observation is weighted by its own standard error: the sample standard deviation
//! within the segment divided by √n (per-position sample std / √n, **not** the LS
//! residuals). The parameter covariance is then (JᵀWJ)⁻¹ — honest for white noise within
//! the dwells — multiplied by max(1, χ²/dof) pooled over the triad's three axes (the
//! Birge ratio), which absorbs scatter between positions beyond the white noise (bias
//! drift). The bias estimated is the bias in effect during the recording: the realised
//! run-mean of slow terms (bias instability, rate random walk) is indistinguishable from
//! a bias offset (simulated coverage at 1.96σ with every noise term on: 95–99.6 %
//! against that bias, 87–90 % against the turn-on bias alone; `tests/calib_six.rs`).
//! The covariance of M = A⁻¹ is propagated to first order: dM = −M·dA·M.

use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::linalg::{Mat3, Vec3};

use super::lsq::{self, LsqError};
use super::protocol::{BodyAxis, ChamberManifest, SegmentKind, SignedAxis};
use super::quality::FitQuality;
use crate::nav::earth;

mod fit;
mod input;
use fit::*;

/// Mean raw output of one static position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionMean {
    /// The body axis pointing up.
    pub up: SignedAxis,
    /// Attitude C_bn in the position (for the Earth rate); `up.c_bn_up()` by default.
    pub c_bn: Mat3,
    /// Mean raw accelerometer output.
    pub accel_raw: Vec3,
    /// Sample standard deviation of the raw accelerometer output.
    pub accel_std_raw: Vec3,
    /// Largest |raw accelerometer sample| (saturation check).
    pub accel_peak_abs_raw: Vec3,
    /// Mean raw gyro output.
    pub gyro_raw: Vec3,
    /// Sample standard deviation of the raw gyro output.
    pub gyro_std_raw: Vec3,
    /// Largest |raw gyro sample|.
    pub gyro_peak_abs_raw: Vec3,
    /// Number of samples averaged.
    pub n: usize,
}

impl PositionMean {
    /// A position in the chamber attitude of `up`, with the peaks taken as |mean|.
    pub fn new(
        up: SignedAxis,
        accel_raw: Vec3,
        accel_std_raw: Vec3,
        gyro_raw: Vec3,
        gyro_std_raw: Vec3,
        n: usize,
    ) -> PositionMean {
        PositionMean {
            up,
            c_bn: up.c_bn_up(),
            accel_raw,
            accel_std_raw,
            accel_peak_abs_raw: accel_raw.map(f64::abs),
            gyro_raw,
            gyro_std_raw,
            gyro_peak_abs_raw: gyro_raw.map(f64::abs),
            n,
        }
    }
}

/// Mean raw gyro output of one rate-table segment (whole revolutions at a constant rate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateMean {
    /// Rotation axis (body).
    pub axis: BodyAxis,
    /// Commanded ω_nb about +axis, rad/s (signed).
    pub rate_rad_s: f64,
    /// The body axis pointing up during the rotation (the table axis is vertical).
    pub up: SignedAxis,
    /// Mean raw gyro output (= integrated raw angle / duration).
    pub gyro_raw: Vec3,
    /// Sample standard deviation of the raw gyro output.
    pub gyro_std_raw: Vec3,
    /// Largest |raw gyro sample|.
    pub gyro_peak_abs_raw: Vec3,
    /// Number of samples averaged.
    pub n: usize,
}

/// Everything the calibration needs from a recording.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SixPositionInput {
    /// Static positions (≥ 6, every axis up and down).
    pub positions: Vec<PositionMean>,
    /// Rate-table segments (≥ 1 per axis for the gyro).
    pub rates: Vec<RateMean>,
}

/// Site constants and switches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SixPositionOptions {
    /// Local gravity |f| in a static position, m/s².
    pub gravity_m_s2: f64,
    /// Site latitude, rad (for the Earth rate).
    pub latitude_rad: f64,
    /// Earth rotation rate, rad/s (0 ignores the Earth rate).
    pub earth_rate_rad_s: f64,
    /// Accelerometer output rail, raw units: a sample with |raw| ≥ this is saturated.
    pub accel_rail_raw: Option<f64>,
    /// Gyro output rail, raw units.
    pub gyro_rail_raw: Option<f64>,
    /// Also estimate the gyro g-sensitivity G (9 more parameters; module docs). Needs
    /// up-directions that identify it ([`g_sensitivity_identifiable`]); the static
    /// positions this calibration requires always do (an input without them is refused
    /// with [`SixPositionError::MissingDirection`] first, G or not; the gyro fit also
    /// refuses unidentifiable directions itself, [`SixPositionError::Invalid`]).
    pub estimate_g_sensitivity: bool,
}

impl SixPositionOptions {
    /// Normal gravity and Earth rate at latitude `lat_rad`, height `height_m`; the gyro
    /// g-sensitivity is not estimated (no protocol is known here; set
    /// [`SixPositionOptions::estimate_g_sensitivity`] for one that identifies it).
    pub fn at_site(lat_rad: f64, height_m: f64) -> SixPositionOptions {
        SixPositionOptions {
            gravity_m_s2: earth::normal_gravity_m_s2(lat_rad, height_m),
            latitude_rad: lat_rad,
            earth_rate_rad_s: earth::OMEGA_IE,
            accel_rail_raw: None,
            gyro_rail_raw: None,
            estimate_g_sensitivity: false,
        }
    }

    /// The site constants of a chamber manifest (its exact gravity and Earth rate), with
    /// the gyro g-sensitivity estimated when the manifest identifies it: every
    /// temperature step ([`ChamberManifest::steps`]) has static positions whose
    /// up-directions pass [`g_sensitivity_identifiable`] (the six positions do). The
    /// manifest's rate segments are all turned with +k up, so leaving G out would bias
    /// the gyro biases (module docs). A manifest that does not identify G in some step
    /// gets it off; the six-position calibration of that step then names what is
    /// missing ([`SixPositionError::MissingDirection`]).
    pub fn from_manifest(m: &ChamberManifest) -> SixPositionOptions {
        let steps = m.steps();
        let identifiable = !steps.is_empty()
            && steps.iter().all(|(_, range)| {
                g_sensitivity_identifiable(m.segments[range.clone()].iter().filter_map(|s| {
                    match s.kind {
                        SegmentKind::Position { up } => Some(up),
                        _ => None,
                    }
                }))
            });
        SixPositionOptions {
            gravity_m_s2: m.gravity_m_s2,
            latitude_rad: m.latitude_deg.to_radians(),
            earth_rate_rad_s: m.earth_rate_rad_s,
            accel_rail_raw: None,
            gyro_rail_raw: None,
            estimate_g_sensitivity: identifiable,
        }
    }
}

/// Whether observations level with these body axes up identify the gyro g-sensitivity
/// G beside the bias (module docs): the intercept regressors (1, u) span R⁴, i.e. every
/// body axis appears (either sign) and at least one appears with both signs. Static
/// positions alone suffice to test (their A-terms are only the Earth rate); rate
/// segments add nothing new when turned with +k up.
pub fn g_sensitivity_identifiable(ups: impl IntoIterator<Item = SignedAxis>) -> bool {
    // seen[k] = (+k seen, −k seen)
    let mut seen = [(false, false); 3];
    for u in ups {
        let s = &mut seen[u.axis.index()];
        if u.positive {
            s.0 = true;
        } else {
            s.1 = true;
        }
    }
    seen.iter().all(|s| s.0 || s.1) && seen.iter().any(|s| s.0 && s.1)
}

/// Why a calibration failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SixPositionError {
    /// Fewer than six static positions.
    #[error("{n} static positions given; the six-position calibration needs at least 6")]
    TooFewPositions {
        /// Positions given.
        n: usize,
    },
    /// No position with `up` pointing up.
    #[error(
        "no static position with {up} up: column {axis} of the scale/misalignment matrix and \
         the biases (and the gyro g-sensitivity column) are not separable"
    )]
    MissingDirection {
        /// The missing direction.
        up: SignedAxis,
        /// Body axis letter of the unobservable column.
        axis: char,
    },
    /// No rate segment about an axis.
    #[error(
        "no rate-table segment about body {axis}: gyro scale/misalignment column {axis} is \
         unobservable"
    )]
    MissingRate {
        /// Axis letter.
        axis: char,
    },
    /// A sample at the output rail.
    #[error("{what}: {triad} axis {axis} reaches the rail ({value} ≥ {rail} raw units)")]
    Saturated {
        /// Which segment.
        what: String,
        /// "accelerometer" or "gyro".
        triad: &'static str,
        /// Axis letter.
        axis: char,
        /// |raw| seen.
        value: f64,
        /// The rail.
        rail: f64,
    },
    /// A rate segment whose gyro output does not follow the command.
    #[error(
        "rate segment about {axis} at {commanded_rad_s} rad/s: the gyro saw \
         {measured_rad_s} rad/s above its static bias — no (or reversed) rotation"
    )]
    NoRotation {
        /// Axis letter.
        axis: char,
        /// Commanded rate.
        commanded_rad_s: f64,
        /// Mean gyro minus the static bias estimate.
        measured_rad_s: f64,
    },
    /// NaN or infinity in the input.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Where.
        what: String,
    },
    /// An inconsistent input (bad option, attitude not matching the label, empty segment).
    #[error("invalid input: {0}")]
    Invalid(String),
    /// The least squares failed.
    #[error("{triad} axis {axis}: {source} ({param})")]
    Lsq {
        /// "accelerometer" or "gyro".
        triad: &'static str,
        /// Output axis letter.
        axis: char,
        /// Name of the parameter the solver flagged.
        param: String,
        /// Solver error.
        source: LsqError,
    },
}

/// One triad's estimate with its uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadEstimate {
    /// M = A⁻¹ and b.
    pub calibration: TriadCalibration,
    /// A (raw = A·x + b).
    pub forward_matrix: Mat3,
    /// Covariance (12 × 12, row-major) of θ = (M₀₀, M₀₁, …, M₂₂, b₀, b₁, b₂).
    pub covariance: Vec<f64>,
    /// Σ (weighted residual)² over all equations.
    pub chi2: f64,
    /// Equations minus parameters.
    pub dof: usize,
}

impl TriadEstimate {
    /// 1σ of b, raw units.
    pub fn bias_sigma(&self) -> Vec3 {
        std::array::from_fn(|i| self.covariance[(9 + i) * 13].max(0.0).sqrt())
    }

    /// 1σ of each entry of M.
    pub fn matrix_sigma(&self) -> [[f64; 3]; 3] {
        std::array::from_fn(|a| {
            std::array::from_fn(|b| self.covariance[(3 * a + b) * 13].max(0.0).sqrt())
        })
    }

    /// χ²/dof of the weighted residuals (≈ 1 when the σ are honest; NaN without
    /// redundancy).
    pub fn chi2_per_dof(&self) -> f64 {
        self.chi2 / self.dof as f64
    }
}

/// Gyro g-sensitivity estimate (raw = A·ω + b + G·f).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GSensitivityEstimate {
    /// G, raw gyro units per m/s².
    pub matrix_raw_per_m_s2: Mat3,
    /// 1σ of each entry.
    pub sigma_raw_per_m_s2: [[f64; 3]; 3],
}

/// Result of [`calibrate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SixPositionCalibration {
    /// Accelerometer.
    pub accel: TriadEstimate,
    /// Gyro.
    pub gyro: TriadEstimate,
    /// Gyro g-sensitivity, when asked for.
    pub gyro_g_sensitivity: Option<GSensitivityEstimate>,
}

impl SixPositionCalibration {
    /// Both calibrations.
    pub fn imu(&self) -> ImuCalibration {
        ImuCalibration {
            accel: self.accel.calibration,
            gyro: self.gyro.calibration,
        }
    }

    /// χ²/dof of both triads' noise-weighted residuals (σ = sample σ/√n of each position
    /// or rate segment), each with a warning and its likely causes above
    /// `warn_chi2_per_dof` (e.g. [`super::quality::DEFAULT_WARN_CHI2_PER_DOF`]). The
    /// covariances are already inflated by χ²/dof when it exceeds 1; the warning says
    /// the residuals are not white noise.
    pub fn quality(&self, warn_chi2_per_dof: f64) -> (FitQuality, FitQuality) {
        let common = "noise more correlated than σ/√n assumes (bias instability or rate random walk over long dwells), motion or vibration during a segment, segments whose times or orientations are not the manifest's, or temperature drift during the run";
        let accel = FitQuality::from_chi2(
            self.accel.chi2,
            self.accel.dof,
            warn_chi2_per_dof,
            &format!("{common}, or accelerometer nonlinearity"),
        );
        let g_sens = if self.gyro_g_sensitivity.is_none() {
            ", gyro g-sensitivity (not estimated: estimate it)"
        } else {
            ""
        };
        let gyro = FitQuality::from_chi2(
            self.gyro.chi2,
            self.gyro.dof,
            warn_chi2_per_dof,
            &format!(
                "{common}, rate-table rates or site latitude (Earth rate) other than given{g_sens}"
            ),
        );
        (accel, gyro)
    }
}

const AX: [char; 3] = ['x', 'y', 'z'];

fn finite3(v: &Vec3, what: &str) -> Result<(), SixPositionError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(SixPositionError::NonFinite { what: what.into() })
    }
}

fn check_rail(
    peak: &Vec3,
    rail: Option<f64>,
    what: &str,
    triad: &'static str,
) -> Result<(), SixPositionError> {
    let Some(rail) = rail else { return Ok(()) };
    for (k, &p) in peak.iter().enumerate() {
        if p >= rail {
            return Err(SixPositionError::Saturated {
                what: what.into(),
                triad,
                axis: AX[k],
                value: p,
                rail,
            });
        }
    }
    Ok(())
}

fn unit(s: SignedAxis) -> Vec3 {
    let mut u = s.axis.unit();
    u[s.axis.index()] = s.sign();
    u
}

/// Validates the static positions (count, directions, finiteness, rails, attitude).
fn check_positions(ps: &[PositionMean], opt: &SixPositionOptions) -> Result<(), SixPositionError> {
    if ps.len() < 6 {
        return Err(SixPositionError::TooFewPositions { n: ps.len() });
    }
    for up in SignedAxis::POSITIONS {
        if !ps.iter().any(|p| p.up == up) {
            return Err(SixPositionError::MissingDirection {
                up,
                axis: AX[up.axis.index()],
            });
        }
    }
    for p in ps {
        let what = format!("position {} up", p.up);
        for v in [
            &p.accel_raw,
            &p.accel_std_raw,
            &p.accel_peak_abs_raw,
            &p.gyro_raw,
            &p.gyro_std_raw,
            &p.gyro_peak_abs_raw,
        ] {
            finite3(v, &what)?;
        }
        if p.c_bn.0.iter().flatten().any(|x| !x.is_finite()) {
            return Err(SixPositionError::NonFinite { what });
        }
        if p.n == 0 {
            return Err(SixPositionError::Invalid(format!("{what}: no samples")));
        }
        // The attitude must put `up` up: C_bnᵀ·(0, 0, −1) = u.
        let c = &p.c_bn.0;
        let u = unit(p.up);
        let err = (0..3).map(|k| (-c[2][k] - u[k]).abs()).fold(0.0, f64::max);
        if err > 1e-6 {
            return Err(SixPositionError::Invalid(format!(
                "{what}: the attitude C_bn does not put {} up",
                p.up
            )));
        }
        check_rail(
            &p.accel_peak_abs_raw,
            opt.accel_rail_raw,
            &what,
            "accelerometer",
        )?;
        check_rail(&p.gyro_peak_abs_raw, opt.gyro_rail_raw, &what, "gyro")?;
    }
    Ok(())
}

fn check_options(opt: &SixPositionOptions) -> Result<(), SixPositionError> {
    let ok = opt.gravity_m_s2.is_finite()
        && opt.gravity_m_s2 > 0.0
        && opt.latitude_rad.is_finite()
        && opt.earth_rate_rad_s.is_finite()
        && opt.accel_rail_raw.is_none_or(|r| r > 0.0)
        && opt.gyro_rail_raw.is_none_or(|r| r > 0.0);
    if ok {
        Ok(())
    } else {
        Err(SixPositionError::Invalid(format!(
            "options {opt:?} (gravity > 0, finite latitude and Earth rate, rails > 0)"
        )))
    }
}

/// Accelerometer: 12-parameter LS over the static positions (module docs).
pub fn calibrate_accel(
    positions: &[PositionMean],
    opt: &SixPositionOptions,
) -> Result<TriadEstimate, SixPositionError> {
    check_options(opt)?;
    check_positions(positions, opt)?;
    let g = opt.gravity_m_s2;
    let mut fits = Vec::with_capacity(3);
    for i in 0..3 {
        let rows: Vec<Row> = positions
            .iter()
            .map(|p| {
                let f = unit(p.up).map(|u| g * u);
                Row {
                    x: vec![f[0], f[1], f[2], 1.0],
                    y: p.accel_raw[i],
                    sigma: std_error(p.accel_std_raw[i], p.n),
                }
            })
            .collect();
        fits.push(weighted_fit(
            &rows,
            4,
            "accelerometer",
            i,
            &param_names("accelerometer", i, false),
        )?);
    }
    let fits: [_; 3] = fits
        .try_into()
        .map_err(|_| SixPositionError::Invalid("internal: three axes".into()))?;
    triad_estimate(&fits, 4, positions.len(), "accelerometer")
}

/// Gyro: bias, scale/misalignment (and optionally G) from the static positions (Earth
/// rate modelled) and the rate-table segments (module docs).
pub fn calibrate_gyro(
    positions: &[PositionMean],
    rates: &[RateMean],
    opt: &SixPositionOptions,
) -> Result<(TriadEstimate, Option<GSensitivityEstimate>), SixPositionError> {
    check_options(opt)?;
    check_positions(positions, opt)?;
    for axis in BodyAxis::ALL {
        if !rates.iter().any(|r| r.axis == axis) {
            return Err(SixPositionError::MissingRate {
                axis: AX[axis.index()],
            });
        }
    }
    // Static bias guess for the rotation check: the mean over all positions.
    let np = positions.len() as f64;
    let b0: Vec3 =
        std::array::from_fn(|k| positions.iter().map(|p| p.gyro_raw[k]).sum::<f64>() / np);
    for r in rates {
        let k = r.axis.index();
        let what = format!("rate segment about {} at {} rad/s", AX[k], r.rate_rad_s);
        finite3(&r.gyro_raw, &what)?;
        finite3(&r.gyro_std_raw, &what)?;
        finite3(&r.gyro_peak_abs_raw, &what)?;
        if !r.rate_rad_s.is_finite() || r.rate_rad_s == 0.0 || r.n == 0 {
            return Err(SixPositionError::Invalid(format!(
                "{what}: needs a finite non-zero rate and samples"
            )));
        }
        if r.up.axis != r.axis {
            return Err(SixPositionError::Invalid(format!(
                "{what}: the rotation axis must be vertical (up = {})",
                r.up
            )));
        }
        check_rail(&r.gyro_peak_abs_raw, opt.gyro_rail_raw, &what, "gyro")?;
        let measured = r.gyro_raw[k] - b0[k];
        let ratio = measured / r.rate_rad_s;
        if ratio.is_nan() || ratio <= 0.5 {
            return Err(SixPositionError::NoRotation {
                axis: AX[k],
                commanded_rad_s: r.rate_rad_s,
                measured_rad_s: measured,
            });
        }
    }
    let g = opt.gravity_m_s2;
    let w_ie = [
        opt.earth_rate_rad_s * opt.latitude_rad.cos(),
        0.0,
        -opt.earth_rate_rad_s * opt.latitude_rad.sin(),
    ];
    let w_up = opt.earth_rate_rad_s * opt.latitude_rad.sin();
    let with_g = opt.estimate_g_sensitivity;
    // Unreachable while every direction is required above, but the G columns must never
    // reach the solver unidentified.
    if with_g
        && !g_sensitivity_identifiable(
            positions
                .iter()
                .map(|p| p.up)
                .chain(rates.iter().map(|r| r.up)),
        )
    {
        return Err(SixPositionError::Invalid(
            "the gyro g-sensitivity is not identifiable from these up-directions (needs every \
             axis up or down and one both ways); turn estimate_g_sensitivity off"
                .into(),
        ));
    }
    let n = if with_g { 7 } else { 4 };
    let mut fits = Vec::with_capacity(3);
    for i in 0..3 {
        let mut rows = Vec::with_capacity(positions.len() + rates.len());
        for p in positions {
            let w = p.c_bn.t().mul_vec(w_ie);
            let f = unit(p.up).map(|u| g * u);
            let mut x = vec![w[0], w[1], w[2], 1.0];
            if with_g {
                x.extend_from_slice(&f);
            }
            rows.push(Row {
                x,
                y: p.gyro_raw[i],
                sigma: std_error(p.gyro_std_raw[i], p.n),
            });
        }
        for r in rates {
            let u = unit(r.up);
            let mut w = u.map(|c| w_up * c);
            w[r.axis.index()] += r.rate_rad_s;
            let mut x = vec![w[0], w[1], w[2], 1.0];
            if with_g {
                x.extend(u.map(|c| g * c));
            }
            rows.push(Row {
                x,
                y: r.gyro_raw[i],
                sigma: std_error(r.gyro_std_raw[i], r.n),
            });
        }
        fits.push(weighted_fit(
            &rows,
            n,
            "gyro",
            i,
            &param_names("gyro", i, with_g),
        )?);
    }
    let fits: [_; 3] = fits
        .try_into()
        .map_err(|_| SixPositionError::Invalid("internal: three axes".into()))?;
    let gs = with_g.then(|| GSensitivityEstimate {
        matrix_raw_per_m_s2: Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| fits[i].0[4 + j])
        })),
        sigma_raw_per_m_s2: std::array::from_fn(|i| {
            std::array::from_fn(|j| fits[i].1[(4 + j) * n + 4 + j].max(0.0).sqrt())
        }),
    });
    let est = triad_estimate(&fits, n, positions.len() + rates.len(), "gyro")?;
    Ok((est, gs))
}

/// Both triads (module docs).
pub fn calibrate(
    input: &SixPositionInput,
    opt: &SixPositionOptions,
) -> Result<SixPositionCalibration, SixPositionError> {
    let accel = calibrate_accel(&input.positions, opt)?;
    let (gyro, gyro_g_sensitivity) = calibrate_gyro(&input.positions, &input.rates, opt)?;
    Ok(SixPositionCalibration {
        accel,
        gyro,
        gyro_g_sensitivity,
    })
}

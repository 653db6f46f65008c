//! The soak method (seed paper §3.3): at every set temperature of
//! a chamber recording, a six-position + rate-table calibration
//! ([`crate::calib::six_position`]) gives each axis's bias b_k(T) and scale factor
//! A_kk(T) with their standard errors; each series is then fitted by a polynomial in
//! T − T_ref ([`super::fit`](mod@super::fit)), weighted by those errors.
//!
//! Quantities per axis k, from the forward model raw = A·x + b of each temperature:
//! * bias b_k(T), raw units;
//! * scale factor A_kk(T): for raw data already in SI this is 1 + s_k(T), s the
//!   scale-factor error of the seed paper's eq. 2; for counts it is counts per SI unit.
//!
//! σ(A_kk) is propagated from the covariance of M = A⁻¹ reported by the calibration:
//! dA = −A·dM·A, so ∂A_kk/∂M_ij = −A_ki·A_jk.
//!
//! # Gyro g-sensitivity
//!
//! The rate-table segments of a chamber step are all turned with +k up, so the gyro's
//! g-sensitivity, ω_meas = A·ω + b + G·f with f = g·u in every level observation, adds
//! g·G_ik to each rate row of output axis i; unmodelled, it offsets the gyro bias series
//! (≈ 1.9 % of the gyro-z swing on `adi-like`). The six-position fit of each step estimates
//! G when [`SixPositionOptions::estimate_g_sensitivity`] is set —
//! [`SixPositionOptions::from_manifest`] sets it whenever every step's static positions
//! identify G (each axis up and down; [`crate::calib::six_position`] module docs) — and
//! the result reports it per step ([`SoakCalibration::gyro_g_sensitivity`], with σ) and
//! as an inverse-variance mean ([`SoakCalibration::gyro_g_sensitivity_mean`]), which the
//! compensation model carries ([`SoakCalibration::compensation_model`]; applied with the
//! compensated specific force, [`driftless_model::compensation`]). The bias series are
//! the zero-g biases b_k(T).
//!
//! The temperature of each point is the set temperature (the protocol soaks until the
//! sensor has settled; the manifest's soak is sized for that).
//!
//! # Steps and repeated visits
//!
//! A point is one temperature *step* of the manifest (a run of consecutive segments at
//! one set temperature, [`ChamberManifest::steps`]), not one set temperature: a
//! temperature visited twice (a reference step at the start and the end of the run, a
//! common repeatability check) gives two points at the same T, each with its own time
//! in the drift covariance below — the polynomial fits take repeated temperatures
//! as they come. Within a step, every static position and rate segment is one
//! observation of the six-position least squares: a position visited twice (the
//! palindromic order of [`crate::sim::chamber::StepOrder`]) is a multi-position set with
//! each orientation repeated. With the (nearly) equal standard errors of equal dwells the
//! design is balanced and the estimate equals that of the visit-averaged six positions,
//! so the drift cancellation of the palindrome carries over; the difference between the
//! two visits of an orientation enters the χ² and so the calibration's scatter inflation
//! ([`crate::calib::six_position`], Birge ratio) instead of being averaged away unseen.
//!
//! # Slow bias noise (drift) between temperature steps
//!
//! The six-position σ describes the scatter *within* one temperature step. The bias also
//! wanders *between* steps — bias instability (flicker) and rate random walk — and a soak
//! visits the temperatures one after another over hours, so that wander is correlated
//! with temperature and no fit can tell it from b(T). Given the channel's Allan noise
//! terms ([`SoakDrift`], e.g. from `driftless allan` on a static log), the bias series are
//! fitted by generalised least squares ([`super::fit::fit_correlated`]) with the
//! covariance of the step means t_i (mid-time of the step's static positions, from the
//! protocol start):
//!
//! ```text
//! C_ij = σ_i² δ_ij + K²·min(t_i, t_j) + Σ_k σ_k² e^{−|t_i − t_j|/T_k}
//! ```
//!
//! — the rate random walk K as Brownian motion from the start (the truth is the bias
//! at the start plus b(T)); the flicker of bias instability B as the sum of first-order
//! Gauss-Markov processes with T_k three per decade from the step's averaging time to
//! ten times the protocol, σ_k² = B²·ln(r)/π (r = 10^⅓; the same synthesis the simulator
//! documents in [`crate::sim::noise`], after Kasdin 1995). The band then states how well
//! the *thermal* curve is known, drift included; the fit itself cannot remove the drift.
//!
//! # What the bias curve estimates, and a protocol that gets it
//!
//! The estimand is the bias at the start of the run plus b(T). "At the start" includes
//! the turn-on bias and the part of the flicker slower than a step: those components of
//! a 1/f process are constant over the run and no measurement can tell them from the
//! turn-on bias (σ ≈ 1.5·B for `adi-like`). The rate random walk since power-on
//! is different: it grows as K·√t₁ until the first positions at t₁, so a protocol can
//! keep it small by measuring early. The drift covariance above puts the flicker's
//! slow components in the band, so the band stays honest about them.
//!
//! On simulated `adi-like` chambers with every noise term, these choices kept the worst
//! of the 12 curves within 2 % of its swing in 48 of 48 runs (worst 1.63 %; the Recovery
//! test in `tests/thermal_soak.rs` has the table of protocols):
//! 1. Start at the reference temperature, at ambient, and measure at once. This keeps
//!    the rate random walk since power-on out of every bias value.
//! 2. Visit the other temperatures interleaved. The drift is then not a smooth function
//!    of T, and the GLS fit sees it as scatter.
//! 3. Revisit the reference at the end.
//! 4. Run the palindromic order ([`crate::sim::chamber::StepOrder::Palindromic`]) with
//!    three position cycles per step
//!    ([`crate::sim::chamber::ChamberConfig::position_cycles`]). A linear drift cancels,
//!    and the flicker between ± visits averages down.

use super::fit::{FitOptions, ThermalFit, ThermalFitError, fit, fit_correlated};
use crate::calib::protocol::{ChamberManifest, SegmentKind};
use crate::calib::six_position::{
    GSensitivityEstimate, SixPositionError, SixPositionInput, SixPositionOptions, TriadEstimate,
    calibrate,
};
use driftless_model::linalg::Mat3;

/// Why a soak calibration failed.
#[derive(Debug, thiserror::Error)]
pub enum SoakError {
    /// The manifest has fewer set temperatures than the fit needs.
    #[error("{found} set temperatures in the manifest; an order-{order} fit needs at least {}", order + 2)]
    TooFewTemperatures {
        /// Distinct set temperatures.
        found: usize,
        /// Polynomial order asked for.
        order: usize,
    },
    /// The six-position calibration at one temperature failed.
    #[error("at {t_c} °C: {source}")]
    Calibration {
        /// Set temperature.
        t_c: f64,
        /// Cause.
        source: SixPositionError,
    },
    /// The compensation model could not be built.
    #[error("compensation model: {0}")]
    Model(String),
    /// A polynomial fit failed.
    #[error("{what}: {source}")]
    Fit {
        /// Which series.
        what: String,
        /// Cause.
        source: ThermalFitError,
    },
}

/// One fitted series: its points and the polynomial.
#[derive(Clone, Debug)]
pub struct SeriesFit {
    /// `accel` or `gyro`.
    pub triad: &'static str,
    /// `bias` or `scale`.
    pub quantity: &'static str,
    /// Axis 0, 1, 2 (x, y, z).
    pub axis: usize,
    /// Values per temperature.
    pub values: Vec<f64>,
    /// Their standard errors.
    pub sigma: Vec<f64>,
    /// The full covariance of the values the fit used (n×n row-major, the drift model
    /// plus σ² on the diagonal) when the series was fitted by generalised least squares;
    /// `None` for a weighted (or, with a zero σ, unweighted) fit.
    pub covariance: Option<Vec<f64>>,
    /// The fit.
    pub fit: ThermalFit,
}

/// Slow bias noise of one channel, in the unit of the (scaled) samples: Allan terms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ChannelDrift {
    /// Bias instability B (flicker floor of the Allan deviation ≈ 0.664·B), unit.
    pub bias_instability: f64,
    /// Rate random walk K, unit/√s.
    pub rate_random_walk: f64,
}

/// Slow bias noise of every channel (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SoakDrift {
    /// Accelerometer x, y, z.
    pub accel: [ChannelDrift; 3],
    /// Gyro x, y, z.
    pub gyro: [ChannelDrift; 3],
}

impl SoakDrift {
    /// The bias-instability and rate-random-walk terms of a noise-model file
    /// (`driftless allan --save-model`): its angular-rate channels are gyro x, y, z and
    /// its specific-force channels accel x, y, z, in file order (SI units, so the soak's
    /// samples must be in SI too). A triad without exactly three channels is an error.
    pub fn from_noise_model(
        model: &crate::allan::noise_model::NoiseModel,
    ) -> Result<SoakDrift, SoakError> {
        use crate::io::Quantity;
        let triad = |q: Quantity, what: &str| -> Result<[ChannelDrift; 3], SoakError> {
            let ch: Vec<ChannelDrift> = model
                .channels
                .iter()
                .filter(|c| c.quantity == q)
                .map(|c| ChannelDrift {
                    bias_instability: c.fit.bias_instability.map_or(0.0, |t| t.value),
                    rate_random_walk: c.fit.rate_random_walk.map_or(0.0, |t| t.value),
                })
                .collect();
            <[ChannelDrift; 3]>::try_from(ch).map_err(|v| {
                SoakError::Model(format!(
                    "noise model has {} {what} channel(s); the drift model needs 3",
                    v.len()
                ))
            })
        };
        Ok(SoakDrift {
            accel: triad(Quantity::SpecificForce, "specific-force")?,
            gyro: triad(Quantity::AngularRate, "angular-rate")?,
        })
    }
}

/// C_ij of the drift between step means at `times_s` (module docs), `average_s` the
/// averaging time of one step, `span_s` the protocol length.
fn drift_covariance(times_s: &[f64], d: &ChannelDrift, average_s: f64, span_s: f64) -> Vec<f64> {
    let n = times_s.len();
    let mut c = vec![0.0; n * n];
    let k2 = d.rate_random_walk.powi(2);
    let r: f64 = 10f64.powf(1.0 / 3.0);
    let var_k = d.bias_instability.powi(2) * r.ln() / std::f64::consts::PI;
    let mut taus = Vec::new();
    if var_k > 0.0 {
        let mut t = average_s.max(1e-3);
        while t <= 10.0 * span_s.max(average_s) {
            taus.push(t);
            t *= r;
        }
    }
    for i in 0..n {
        for j in 0..n {
            let dt = (times_s[i] - times_s[j]).abs();
            let flicker: f64 = taus.iter().map(|tk| var_k * (-dt / tk).exp()).sum();
            c[i * n + j] = k2 * times_s[i].min(times_s[j]) + flicker;
        }
    }
    c
}

/// Result of [`soak_calibration`].
#[derive(Clone, Debug)]
pub struct SoakCalibration {
    /// Set temperature of each step, ascending, °C (a temperature visited in two steps
    /// appears twice, its steps in time order).
    pub temperatures_c: Vec<f64>,
    /// The six-position estimates (accelerometer, gyro) of each step.
    pub estimates: Vec<(TriadEstimate, TriadEstimate)>,
    /// The gyro g-sensitivity G of each step (raw gyro units per m/s², with σ), in the
    /// order of `temperatures_c`; `None` where it was not estimated
    /// ([`SixPositionOptions::estimate_g_sensitivity`] off).
    pub gyro_g_sensitivity: Vec<Option<GSensitivityEstimate>>,
    /// 12 series: accel bias x/y/z, accel scale x/y/z, gyro bias x/y/z, gyro scale x/y/z.
    pub series: Vec<SeriesFit>,
}

impl SoakCalibration {
    /// The real-time compensation model ([`driftless_model::compensation`]): the room
    /// calibration at T_ref — M from the six-position estimate at the set temperature
    /// nearest T_ref, b from the bias fits' value at T_ref — and the thermal deltas of
    /// the fits, Δb(T) = b(T) − b(T_ref), Δs(T) = (A_kk(T) − A_kk(T_ref))/A_kk(T_ref),
    /// valid over the soaked range; with the gyro g-sensitivity G
    /// ([`Self::gyro_g_sensitivity_mean`]) when every step estimated it.
    pub fn compensation_model(
        &self,
        id: u64,
        policy: driftless_model::compensation::OutOfRange,
    ) -> Result<driftless_model::compensation::CompensationModel, SoakError> {
        use driftless_model::calib::{ImuCalibration, TriadCalibration};
        use driftless_model::compensation::{CompensationModel, TriadThermal};
        use driftless_model::thermal::ThermalPoly;
        let invalid =
            |e: driftless_model::compensation::CompensationError| SoakError::Model(e.to_string());
        let t_ref = self.series[0].fit.t_ref_c();
        let nearest = (0..self.temperatures_c.len())
            .min_by(|&a, &b| {
                (self.temperatures_c[a] - t_ref)
                    .abs()
                    .total_cmp(&(self.temperatures_c[b] - t_ref).abs())
            })
            .ok_or_else(|| SoakError::Model("no temperatures".into()))?;
        let mut triads = Vec::with_capacity(2);
        let mut rooms = Vec::with_capacity(2);
        for (t, triad) in ["accel", "gyro"].iter().enumerate() {
            let mut bias = [ThermalPoly::constant(0.0); 3];
            let mut scale = [ThermalPoly::constant(0.0); 3];
            let mut b_ref = [0.0; 3];
            for axis in 0..3 {
                let sb = self
                    .get(triad, "bias", axis)
                    .ok_or_else(|| SoakError::Model(format!("{triad} bias {axis} missing")))?;
                let ss = self
                    .get(triad, "scale", axis)
                    .ok_or_else(|| SoakError::Model(format!("{triad} scale {axis} missing")))?;
                bias[axis] = sb.fit.poly;
                b_ref[axis] = sb.fit.eval(t_ref);
                // s(T) = A_kk(T) − 1 as a polynomial: the fit with c₀ − 1
                let (lo, hi) = ss.fit.range_c();
                let mut c = *ss.fit.poly.coeffs();
                c[0] -= 1.0;
                scale[axis] = ThermalPoly::new(t_ref, &c, lo, hi)
                    .map_err(|e| SoakError::Model(format!("{triad} scale {axis}: {e}")))?;
            }
            triads.push(TriadThermal::from_forward(&bias, &scale).map_err(invalid)?);
            let est = if t == 0 {
                &self.estimates[nearest].0
            } else {
                &self.estimates[nearest].1
            };
            rooms.push(TriadCalibration {
                bias: b_ref,
                matrix: est.calibration.matrix,
            });
        }
        let range = [
            self.temperatures_c[0],
            self.temperatures_c[self.temperatures_c.len() - 1],
        ];
        // The six-position M at the nearest temperature already holds that temperature's
        // scale; refer it to T_ref: M_ref = M_near · diag(A_kk(T_near) / A_kk(T_ref)).
        let t_near = self.temperatures_c[nearest];
        for (t, triad) in ["accel", "gyro"].iter().enumerate() {
            for axis in 0..3 {
                let f = self
                    .get(triad, "scale", axis)
                    .map(|s| s.fit.eval(t_near) / s.fit.eval(t_ref))
                    .unwrap_or(1.0);
                for r in 0..3 {
                    rooms[t].matrix.0[r][axis] *= f;
                }
            }
        }
        let model = CompensationModel::new(
            id,
            ImuCalibration {
                accel: rooms[0],
                gyro: rooms[1],
            },
            Some(triads[1]),
            Some(triads[0]),
            range,
            policy,
        )
        .map_err(invalid)?;
        // The gyro g-sensitivity, when every step estimated it: the inverse-variance mean.
        match self.gyro_g_sensitivity_mean() {
            Some(g) => model
                .with_gyro_g_sensitivity(g.matrix_raw_per_m_s2)
                .map_err(invalid),
            None => Ok(model),
        }
    }

    /// Inverse-variance weighted mean of the per-step g-sensitivity, entry by entry:
    /// Ḡ_ij = Σ_s G_ij(s)/σ_ij(s)² / Σ_s 1/σ_ij(s)², σ(Ḡ_ij) = (Σ_s 1/σ_ij(s)²)^(−½) —
    /// treating G as independent of temperature and the steps' errors as independent.
    /// `None` unless every step estimated G with σ > 0 (noise-free data gives σ = 0:
    /// then the plain mean, σ 0).
    pub fn gyro_g_sensitivity_mean(&self) -> Option<GSensitivityEstimate> {
        let steps: Vec<&GSensitivityEstimate> = self
            .gyro_g_sensitivity
            .iter()
            .map(Option::as_ref)
            .collect::<Option<Vec<_>>>()?;
        if steps.is_empty() {
            return None;
        }
        // (mean, σ) of entry (i, j)
        let entry = |i: usize, j: usize| -> (f64, f64) {
            let weighted = steps.iter().all(|g| g.sigma_raw_per_m_s2[i][j] > 0.0);
            let (mut sw, mut swx) = (0.0, 0.0);
            for g in &steps {
                let w = if weighted {
                    g.sigma_raw_per_m_s2[i][j].powi(-2)
                } else {
                    1.0
                };
                sw += w;
                swx += w * g.matrix_raw_per_m_s2.0[i][j];
            }
            (swx / sw, if weighted { sw.powf(-0.5) } else { 0.0 })
        };
        let e: [[(f64, f64); 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| entry(i, j)));
        let mean = Mat3(e.map(|r| r.map(|x| x.0)));
        let sigma = e.map(|r| r.map(|x| x.1));
        Some(GSensitivityEstimate {
            matrix_raw_per_m_s2: mean,
            sigma_raw_per_m_s2: sigma,
        })
    }

    /// Leave-one-temperature-out check of a series' uncertainty ([`super::fit::held_out`]):
    /// each step predicted by the fit without its temperature, with the same weights,
    /// drift covariance and noise-scale rule (`fit_opts`, as given to
    /// [`soak_calibration`]), against its `level` prediction band.
    pub fn held_out(
        &self,
        series: &SeriesFit,
        fit_opts: &FitOptions,
        level: f64,
    ) -> Result<super::fit::HeldOut, SoakError> {
        let weights = series
            .sigma
            .iter()
            .all(|s| *s > 0.0)
            .then_some(series.sigma.as_slice());
        super::fit::held_out(
            &self.temperatures_c,
            &series.values,
            weights,
            series.covariance.as_deref(),
            fit_opts,
            level,
        )
        .map_err(|source| SoakError::Fit {
            what: format!(
                "{} {} {} held out",
                series.triad,
                series.quantity,
                ["x", "y", "z"][series.axis]
            ),
            source,
        })
    }

    /// The series of `triad` / `quantity` / `axis`.
    pub fn get(&self, triad: &str, quantity: &str, axis: usize) -> Option<&SeriesFit> {
        self.series
            .iter()
            .find(|s| s.triad == triad && s.quantity == quantity && s.axis == axis)
    }
}

/// σ of the diagonal of A = M⁻¹ from the covariance of (vec M, b) (module docs).
fn scale_sigma(est: &TriadEstimate) -> [f64; 3] {
    let a = est.forward_matrix.0;
    std::array::from_fn(|k| {
        // gradient of A_kk w.r.t. vec(M): −A_ki·A_jk at index 3i + j
        let g: Vec<f64> = (0..9).map(|p| -a[k][p / 3] * a[p % 3][k]).collect();
        let mut v = 0.0;
        for (r, gr) in g.iter().enumerate() {
            for (c, gc) in g.iter().enumerate() {
                v += gr * est.covariance[r * 12 + c] * gc;
            }
        }
        v.max(0.0).sqrt()
    })
}

/// Six-position calibration at every temperature step of `manifest`
/// ([`ChamberManifest::steps`]; sample columns as for
/// [`SixPositionInput::from_manifest_columns`]; with the gyro g-sensitivity when `six`
/// asks for it — [`SixPositionOptions::from_manifest`] does whenever the manifest
/// identifies it, module docs), then a polynomial fit of every bias and
/// scale series weighted by its standard errors — with `drift`, the bias series by
/// generalised least squares with the drift covariance (module docs).
pub fn soak_calibration(
    manifest: &ChamberManifest,
    accel: [&[f64]; 3],
    gyro: [&[f64]; 3],
    scale: f64,
    six: &SixPositionOptions,
    fit_opts: &FitOptions,
    drift: Option<&SoakDrift>,
) -> Result<SoakCalibration, SoakError> {
    // One calibration point per step, ascending in temperature (a temperature visited
    // twice keeps its steps in time order).
    let mut steps = manifest.steps();
    steps.sort_by(|a, b| a.0.total_cmp(&b.0));
    let temps: Vec<f64> = steps.iter().map(|s| s.0).collect();
    let mut distinct = temps.clone();
    distinct.dedup();
    if distinct.len() < fit_opts.order + 2 {
        return Err(SoakError::TooFewTemperatures {
            found: distinct.len(),
            order: fit_opts.order,
        });
    }
    // per step: (accel, gyro) estimates
    let mut ests = Vec::with_capacity(temps.len());
    let mut g_sens = Vec::with_capacity(temps.len());
    for (t, range) in &steps {
        let t = *t;
        let step = manifest.step_manifest(range.clone());
        let input = SixPositionInput::from_manifest_columns(&step, accel, gyro, scale, t)
            .map_err(|source| SoakError::Calibration { t_c: t, source })?;
        let cal =
            calibrate(&input, six).map_err(|source| SoakError::Calibration { t_c: t, source })?;
        ests.push((cal.accel, cal.gyro));
        g_sens.push(cal.gyro_g_sensitivity);
    }
    // Per step: mid-time and total duration of its static positions.
    let (mut times, mut average_s) = (Vec::with_capacity(temps.len()), f64::INFINITY);
    for (_, range) in &steps {
        let (mut w, mut tw) = (0.0, 0.0);
        for g in &manifest.segments[range.clone()] {
            if matches!(g.kind, SegmentKind::Position { .. }) {
                let d = g.end_s - g.start_s;
                w += d;
                tw += d * 0.5 * (g.start_s + g.end_s);
            }
        }
        times.push(if w > 0.0 { tw / w } else { 0.0 });
        average_s = average_s.min(w);
    }
    let span_s = manifest.duration_s;
    let mut series = Vec::with_capacity(12);
    for (triad, pick) in [("accel", 0usize), ("gyro", 1usize)] {
        let get =
            |e: &(TriadEstimate, TriadEstimate)| if pick == 0 { e.0.clone() } else { e.1.clone() };
        for quantity in ["bias", "scale"] {
            for axis in 0..3 {
                let (mut values, mut sigma) = (Vec::new(), Vec::new());
                for e in &ests {
                    let est = get(e);
                    if quantity == "bias" {
                        values.push(est.calibration.bias[axis]);
                        sigma.push(est.bias_sigma()[axis]);
                    } else {
                        values.push(est.forward_matrix.0[axis][axis]);
                        sigma.push(scale_sigma(&est)[axis]);
                    }
                }
                let what = format!("{triad} {quantity} {}", ["x", "y", "z"][axis]);
                let channel_drift = drift
                    .map(|d| {
                        if pick == 0 {
                            d.accel[axis]
                        } else {
                            d.gyro[axis]
                        }
                    })
                    .filter(|d| quantity == "bias" && *d != ChannelDrift::default());
                // A zero σ (noise-free data) cannot weight a fit: use unit weights then.
                let weights = sigma.iter().all(|s| *s > 0.0).then_some(sigma.as_slice());
                let covariance = match (channel_drift, weights) {
                    (Some(d), Some(w)) => {
                        let n = temps.len();
                        let mut c = drift_covariance(&times, &d, average_s, span_s);
                        for i in 0..n {
                            c[i * n + i] += w[i] * w[i];
                        }
                        Some(c)
                    }
                    _ => None,
                };
                let f = match &covariance {
                    Some(c) => fit_correlated(&temps, &values, c, fit_opts),
                    None => fit(&temps, &values, weights, fit_opts),
                }
                .map_err(|source| SoakError::Fit { what, source })?;
                series.push(SeriesFit {
                    triad,
                    quantity,
                    axis,
                    values,
                    sigma,
                    covariance,
                    fit: f,
                });
            }
        }
    }
    Ok(SoakCalibration {
        temperatures_c: temps,
        estimates: ests,
        gyro_g_sensitivity: g_sens,
        series,
    })
}

//! The vehicle stage: one run in every case — the sensor output compensated as the case
//! says, the filter run forward (and smoothed), and the errors in the outages.

use rayon::prelude::*;

use crate::allan::noise_model::NoiseModel;
use crate::eval::metrics::{MetricOptions, OutageReport, outage_errors};
use crate::eval::reference::from_nav_states;
use crate::experiment::ExperimentError;
use crate::experiment::budget::{OutageBudget, outage_budgets};
use crate::experiment::scenario::{ExperimentScenario, VehicleSource};
use crate::io::nav::{GnssFixes, NavSolution};
use crate::nav::filter::aids::NhcConfig;
use crate::nav::filter::model::{FilterConfig, GaussMarkov, ImuNoise};
use crate::nav::filter::run::{InitialState, run_forward};
use crate::nav::filter::smoother::smooth;
use crate::nav::outage::OutageWindow;
use crate::nav::pipeline::ImuStream;
use crate::nav::session::{SessionConfig, initialise, prime_gyro_bias};
use crate::sim::scenario::ErrorTerms;
use crate::sim::sensor_data::{OutputKind, SensorOutput};
use driftless_model::compensation::CompensationModel;
use driftless_model::units::DEG;

use super::thermal::ThermalStage;
use super::{Case, NoiseStage, Prepared, TAG_VEHICLE, run_seed, sim_scenario};

/// One case of one vehicle run.
#[derive(Clone, Debug)]
pub struct CaseRun {
    /// Which case.
    pub case: Case,
    /// Forward (real-time) errors, or why the filter failed.
    pub forward: Result<OutageReport, String>,
    /// Smoothed errors (when smoothing is on).
    pub smoothed: Option<Result<OutageReport, String>>,
    /// GNSS fixes accepted by the filter.
    pub gnss_accepted: usize,
    /// GNSS fixes rejected by the χ² gate.
    pub gnss_rejected: usize,
    /// The forward solution (kept for the detailed run only).
    pub forward_solution: Option<NavSolution>,
    /// Error budget per outage (detailed run only; [`super::budget`](crate::experiment::budget)).
    pub budgets: Option<Vec<Option<OutageBudget>>>,
}

impl CaseRun {
    /// A case whose processing failed before or in the filter.
    pub fn failed(case: Case, message: String) -> CaseRun {
        CaseRun {
            case,
            forward: Err(message),
            smoothed: None,
            gnss_accepted: 0,
            gnss_rejected: 0,
            forward_solution: None,
            budgets: None,
        }
    }

    /// Mean end-of-outage horizontal error of the forward filter, m (`None` if it failed).
    pub fn forward_mean_end_m(&self) -> Option<f64> {
        mean_end(&self.forward)
    }

    /// Mean end-of-outage horizontal error of the smoothed solution, m.
    pub(crate) fn smoothed_mean_end_m(&self) -> Option<f64> {
        self.smoothed.as_ref().and_then(mean_end)
    }
}

pub(super) fn mean_end(r: &Result<OutageReport, String>) -> Option<f64> {
    r.as_ref()
        .ok()
        .and_then(|o| o.summary.end_horizontal_m)
        .map(|s| s.mean)
}

/// One vehicle run in every case.
#[derive(Clone, Debug)]
pub struct VehicleRun {
    /// Monte Carlo index.
    pub run: usize,
    /// Cases in order (a), (b), (c) when available.
    pub cases: Vec<CaseRun>,
    /// The reference (kept for the detailed run only).
    pub reference: Option<NavSolution>,
    /// The GNSS fixes (kept for the detailed run only).
    pub fixes: Option<GnssFixes>,
    /// Sensor temperature over the run, first and last reading, °C (simulated runs).
    pub temperature_c: Option<(f64, f64)>,
}

impl VehicleRun {
    /// A copy without the reference, fixes and solutions (for the Monte Carlo list).
    pub(crate) fn without_solutions(&self) -> VehicleRun {
        VehicleRun {
            run: self.run,
            cases: self
                .cases
                .iter()
                .map(|c| CaseRun {
                    case: c.case,
                    forward: c.forward.clone(),
                    smoothed: c.smoothed.clone(),
                    gnss_accepted: c.gnss_accepted,
                    gnss_rejected: c.gnss_rejected,
                    forward_solution: None,
                    budgets: c.budgets.clone(),
                })
                .collect(),
            reference: None,
            fixes: None,
            temperature_c: self.temperature_c,
        }
    }

    /// The case `c`, if it was processed.
    pub fn case(&self, c: Case) -> Option<&CaseRun> {
        self.cases.iter().find(|r| r.case == c)
    }
}

/// Largest departure of a room calibration's matrices from the identity: removing the
/// biases alone, case (b), is meaningful only for output already in SI units.
pub(super) const MAX_BIAS_ONLY_MATRIX_DEPARTURE: f64 = 0.1;

/// Checks that case (b) (biases only) applies to data calibrated by `model`.
pub(super) fn check_bias_only(model: &CompensationModel) -> Result<(), String> {
    let room = model.calibration();
    for (name, m) in [
        ("gyro", &room.gyro.matrix),
        ("accelerometer", &room.accel.matrix),
    ] {
        let dev = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| (m.0[i][j] - if i == j { 1.0 } else { 0.0 }).abs())
            .fold(0.0, f64::max);
        if dev > MAX_BIAS_ONLY_MATRIX_DEPARTURE {
            return Err(format!(
                "the room calibration's {name} matrix departs from the identity by {dev:.3} \
                 (more than {MAX_BIAS_ONLY_MATRIX_DEPARTURE}): the data are not in SI units, so \
                 removing only the biases (case b) leaves them unscaled; give data in rad/s and \
                 m/s² or a model calibrated on them"
            ));
        }
    }
    Ok(())
}

/// One sample of case `case` from the sensor's output (ω̃ rad/s, f̃ m/s²) at
/// temperature `t_c` (°C), with the thermal model `model`: (a) as is; (b) ω̃ − b_g,
/// f̃ − b_a with the room biases; (d) the room calibration M(x̃ − b); (c) the whole
/// model at `t_c` ([`CompensationModel::compensate`]).
pub(super) fn compensate_case(
    case: Case,
    model: &CompensationModel,
    gyro_rad_s: [f64; 3],
    accel_m_s2: [f64; 3],
    t_c: f64,
) -> Result<([f64; 3], [f64; 3]), String> {
    let room = model.calibration();
    let minus = |x: [f64; 3], b: [f64; 3]| [x[0] - b[0], x[1] - b[1], x[2] - b[2]];
    match case {
        Case::Raw => Ok((gyro_rad_s, accel_m_s2)),
        Case::RoomBias => Ok((
            minus(gyro_rad_s, room.gyro.bias),
            minus(accel_m_s2, room.accel.bias),
        )),
        Case::RoomFull => Ok((room.gyro.apply(gyro_rad_s), room.accel.apply(accel_m_s2))),
        Case::Thermal => model
            .compensate(gyro_rad_s, accel_m_s2, t_c)
            .map_err(|e| e.to_string()),
    }
}

/// The navigation stream of one case from simulated rates: the increments of
/// [`SensorOutput::to_increments`] (Δθ = ω·Δt, Δv = f·Δt) of the rates compensated as
/// the case says ([`compensate_case`]).
pub(super) fn case_stream(
    raw: &SensorOutput,
    case: Case,
    thermal: Option<&ThermalStage>,
) -> Result<ImuStream, String> {
    if raw.kind != OutputKind::Rates {
        return Err("the simulated vehicle IMU must output rates".into());
    }
    let mut epochs = raw.to_increments();
    if let Some(t) = thermal
        && case != Case::Raw
    {
        if case == Case::RoomBias {
            check_bias_only(&t.model)?;
        }
        for (k, e) in epochs.iter_mut().enumerate() {
            let (gc, ac) = compensate_case(
                case,
                &t.model,
                raw.gyro_at(k),
                raw.accel_at(k),
                raw.temperature_c[k],
            )
            .map_err(|e| format!("sample {k}: {e}"))?;
            e.dtheta_rad = gc.map(|v| v * raw.dt_s);
            e.dvel_m_s = ac.map(|v| v * raw.dt_s);
        }
    }
    Ok(ImuStream {
        source: case.label().to_string(),
        gps_week: None,
        nominal_dt_s: raw.dt_s,
        epochs,
        gaps: Vec::new(),
        notes: Vec::new(),
    })
}

/// Filter noise: the noise model's terms (bias as Gauss–Markov with the scenario's τ,
/// [`ImuNoise::from_noise_model`]) and scale-factor states of σ `scale_sigma`.
pub fn filter_noise(
    sc: &ExperimentScenario,
    model: &NoiseModel,
) -> Result<ImuNoise, ExperimentError> {
    let gm = GaussMarkov {
        sigma: sc.filter.scale_sigma,
        tau_s: sc.filter.bias_tau_s,
    };
    ImuNoise::from_noise_model(model, sc.filter.bias_tau_s, gm, gm)
        .map_err(|e| ExperimentError::stage("filter", e))
}

pub(super) struct CaseInput<'a> {
    pub(super) case: Case,
    pub(super) imu: ImuStream,
    pub(super) fixes: &'a GnssFixes,
    pub(super) session: SessionConfig,
    pub(super) prime: bool,
}

pub(super) fn run_case(
    input: CaseInput<'_>,
    sc: &ExperimentScenario,
    windows: &[OutageWindow],
    reference: &NavSolution,
    keep_solution: bool,
) -> CaseRun {
    let mut session = input.session;
    session.outages = windows.to_vec();
    let mut fcfg = session.filter.clone();
    fcfg.outages_s = windows.iter().map(|w| (w.start_s, w.end_s)).collect();
    let failed = CaseRun::failed;
    let primed = if input.prime {
        prime_gyro_bias(&input.imu, session.static_prime_s.max(1.0))
    } else {
        None
    };
    let mut init: InitialState = match initialise(&input.imu, input.fixes, &session, primed) {
        Ok(i) => i,
        Err(e) => return failed(input.case, format!("initialisation: {e}")),
    };
    let f = &sc.filter;
    if f.initial_gyro_bias_sigma_deg_s.is_some() || f.initial_accel_bias_sigma_m_s2.is_some() {
        let n = &fcfg.imu;
        let mut s = [0.0; 12];
        for k in 0..3 {
            s[k] = f
                .initial_gyro_bias_sigma_deg_s
                .map_or(n.gyro_bias.sigma, |v| (v * DEG).max(n.gyro_bias.sigma));
            s[3 + k] = f
                .initial_accel_bias_sigma_m_s2
                .map_or(n.accel_bias.sigma, |v| v.max(n.accel_bias.sigma));
            s[6 + k] = n.gyro_scale.sigma;
            s[9 + k] = n.accel_scale.sigma;
        }
        init.sigma_sensors = Some(s);
    }
    let run = match run_forward(&input.imu.epochs, input.fixes, init, &fcfg) {
        Ok(r) => r,
        Err(e) => return failed(input.case, format!("forward filter: {e}")),
    };
    let opts = MetricOptions {
        growth_step_s: 1.0,
        ..MetricOptions::default()
    };
    let forward_solution = from_nav_states(run.epochs.iter().map(|e| &e.nav));
    let forward = outage_errors(reference, &forward_solution, windows, &opts)
        .map_err(|e| format!("forward solution: {e}"));
    let smoothed = session.smooth.then(|| {
        let sm = smooth(&run, &init, &fcfg).map_err(|e| format!("smoother: {e}"))?;
        let sol = from_nav_states(sm.epochs.iter().map(|e| &e.nav));
        outage_errors(reference, &sol, windows, &opts)
            .map_err(|e| format!("smoothed solution: {e}"))
    });
    let budgets =
        keep_solution.then(|| outage_budgets(windows, reference, &run.epochs, &input.imu.epochs));
    CaseRun {
        case: input.case,
        forward,
        smoothed,
        gnss_accepted: run.gnss_accepted,
        gnss_rejected: run.gnss_rejected,
        forward_solution: keep_solution.then_some(forward_solution),
        budgets,
    }
}

/// The session (filter, aids, initialisation) of a simulated run.
pub(super) fn simulated_session(
    sc: &ExperimentScenario,
    noise: &NoiseStage,
    lever_arm_b_m: [f64; 3],
) -> Result<SessionConfig, ExperimentError> {
    let mut f = FilterConfig::new(filter_noise(sc, &noise.model)?, lever_arm_b_m);
    if sc.filter.nhc {
        f.nhc = Some(NhcConfig::default());
    }
    let mut s = SessionConfig::new(f);
    s.static_prime_s = 10.0;
    Ok(s)
}

/// Vehicle run `run` in every case. `detail` keeps the reference and solutions for the
/// figures (and smooths; other runs smooth only with `monte_carlo.smooth_all_runs`). Errors are stage failures (simulation, reading); a filter that diverges in
/// one case is recorded in that case, not raised.
pub fn vehicle_run(
    p: &Prepared,
    noise: Option<&NoiseStage>,
    thermal: Option<&ThermalStage>,
    run: usize,
    detail: bool,
) -> Result<VehicleRun, ExperimentError> {
    let sc = &p.scenario;
    let smooth_this = sc.filter.smooth && (detail || sc.monte_carlo.smooth_all_runs);
    let windows = p.windows();
    match (&p.recorded, p.source) {
        (None, VehicleSource::Simulated) => {
            let (Some(sensor), Some(spec), Some(traj), Some(noise)) =
                (&p.sensor, &sc.sensor, &sc.vehicle.trajectory, noise)
            else {
                return Err(sc.invalid("a simulated [vehicle] needs [sensor] and [noise]"));
            };
            let mut scen = sim_scenario(
                sc,
                sensor,
                spec.rate_hz,
                traj.clone(),
                run_seed(sc.seed, TAG_VEHICLE, run),
                ErrorTerms::All,
            );
            scen.temperature = sc.vehicle.temperature.clone();
            scen.gnss = sc.vehicle.gnss.clone();
            let sim = scen
                .run()
                .map_err(|e| ExperimentError::stage("vehicle", e))?;
            let Some(fixes) = &sim.gnss else {
                return Err(ExperimentError::stage("vehicle", "no GNSS fixes simulated"));
            };
            let mut session = simulated_session(sc, noise, sim.lever_arm_b_m)?;
            session.smooth = smooth_this;
            let results: Vec<CaseRun> = Case::processed(thermal.is_some())
                .par_iter()
                .map(|&case| {
                    let imu = match case_stream(&sim.imu, case, thermal) {
                        Ok(s) => s,
                        Err(e) => return CaseRun::failed(case, format!("compensation: {e}")),
                    };
                    let input = CaseInput {
                        case,
                        imu,
                        fixes,
                        session: session.clone(),
                        // Without a room calibration, (b) removes the static-start gyro bias.
                        prime: case == Case::RoomBias && thermal.is_none(),
                    };
                    run_case(input, sc, &windows, &sim.truth, detail)
                })
                .collect();
            let t = &sim.imu.temperature_c;
            Ok(VehicleRun {
                run,
                cases: results,
                temperature_c: t.first().zip(t.last()).map(|(a, b)| (*a, *b)),
                reference: detail.then(|| sim.truth.clone()),
                fixes: detail.then(|| fixes.clone()),
            })
        }
        (Some(rec), _) => {
            let mut session = rec.session.clone();
            if let Some(n) = noise {
                session.filter.imu = filter_noise(sc, &n.model)?;
            }
            if sc.filter.nhc {
                session.filter.nhc = Some(NhcConfig::default());
            }
            session.smooth = smooth_this;
            // Reference: case (b)'s smoothed solution with every fix.
            let reference = {
                let mut s = session.clone();
                s.outages.clear();
                let primed = prime_gyro_bias(&rec.imu, s.static_prime_s.max(1.0));
                let init = initialise(&rec.imu, &rec.fixes, &s, primed)
                    .map_err(|e| ExperimentError::stage("reference", e))?;
                let run = run_forward(&rec.imu.epochs, &rec.fixes, init, &s.filter)
                    .map_err(|e| ExperimentError::stage("reference", e))?;
                let sm = smooth(&run, &init, &s.filter)
                    .map_err(|e| ExperimentError::stage("reference", e))?;
                from_nav_states(sm.epochs.iter().map(|e| &e.nav))
            };
            let results: Vec<CaseRun> = Case::processed(thermal.is_some())
                .par_iter()
                .map(|&case| {
                    // With a thermal model (csv data with temperature): (b), (d) and (c)
                    // from its room calibration and thermal deltas; without: (b) removes
                    // the static-start gyro bias.
                    let stream = match (case, thermal, &rec.rates) {
                        (Case::Raw, _, _) | (_, None, _) => Ok(rec.imu.clone()),
                        (_, Some(t), Some(r)) => {
                            let temp = r.temperature_c.as_deref();
                            let ready = match (case, temp) {
                                (Case::Thermal, None) => Err("no temperature column".to_string()),
                                (Case::RoomBias, _) => check_bias_only(&t.model),
                                _ => Ok(()),
                            };
                            ready.and_then(|()| {
                                r.stream(case.label(), |k, w, f| {
                                    let t_c = temp.map_or(f64::NAN, |v| v[k]);
                                    compensate_case(case, &t.model, w, f, t_c)
                                        .map_err(|e| format!("sample {k}: {e}"))
                                })
                            })
                        }
                        (_, Some(_), None) => {
                            Err("a thermal model needs the rates log (csv vehicle data)".into())
                        }
                    };
                    let imu = match stream {
                        Ok(s) => s,
                        Err(e) => {
                            return CaseRun::failed(case, format!("compensation: {e}"));
                        }
                    };
                    let input = CaseInput {
                        case,
                        imu,
                        fixes: &rec.fixes,
                        session: session.clone(),
                        prime: case == Case::RoomBias && thermal.is_none(),
                    };
                    run_case(input, sc, &windows, &reference, detail)
                })
                .collect();
            let temperature_c = rec
                .rates
                .as_ref()
                .and_then(|r| r.temperature_c.as_ref())
                .and_then(|t| t.first().zip(t.last()).map(|(a, b)| (*a, *b)));
            Ok(VehicleRun {
                run,
                cases: results,
                temperature_c,
                reference: detail.then_some(reference),
                fixes: detail.then(|| rec.fixes.clone()),
            })
        }
        (None, _) => Err(sc.invalid("recorded vehicle data were not read")),
    }
}

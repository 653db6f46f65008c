//! The experiment's stages: [`prepare`] (checks and outage windows, fast), then
//! [`noise_stage`] → [`thermal_stage`] → [`vehicle_run`] (module docs of
//! [`super`]).
//!
//! Seeds: run k of a Monte Carlo draws its chamber log, vehicle IMU and GNSS from
//! `splitmix64(seed ⊕ tag ⊕ k)`; the static log of the noise stage is drawn once. The
//! sensor's *design* (deterministic thermal curves, misalignment …) is the same in every
//! stage and run; what changes is what a new power-up changes (turn-on biases) and noise.

use rayon::prelude::*;
use serde::Serialize;

use super::ExperimentError;
use super::budget::{OutageBudget, outage_budgets};
use super::scenario::{ExperimentScenario, VehicleSource};
use crate::allan::analysis::{AnalysisConfig, ChannelResult};
use crate::allan::fit::FitConfig;
use crate::allan::log_analysis::{
    ChannelSelection, LogAnalysisError, LogAnalysisOptions, NoiseMethod, analyse_log,
};
use crate::allan::noise_model::NoiseModel;
use crate::allan::taus::TauSpec;
use crate::calib::six_position::SixPositionOptions;
use crate::eval::metrics::{MetricOptions, OutageReport, outage_errors};
use crate::eval::reference::{from_nav_states, reference_from_fixes};
use crate::eval::select::{SelectOptions, SelectedOutage, resolve_outages};
use crate::io::nav::{GnssFixes, GnssReadOptions, NavSolution};
use crate::io::{ImuLog, Quantity};
use crate::nav::filter::aids::NhcConfig;
use crate::nav::filter::model::{FilterConfig, GaussMarkov, ImuNoise};
use crate::nav::filter::run::{InitialState, run_forward};
use crate::nav::filter::smoother::smooth;
use crate::nav::outage::{OutageSpec, OutageWindow};
use crate::nav::pipeline::{
    GnssOutsideImu, ImuStream, ImuStreamOptions, imu_from_kfgins, read_gnss_file, select_gnss,
};
use crate::nav::session::{SessionConfig, initialise, prime_gyro_bias};
use crate::sim::scenario::{ErrorTerms, ImuSpec, OutputSpec, Scenario, TrajectorySpec};
use crate::sim::sensor_config::SensorConfig;
use crate::sim::sensor_data::{OutputKind, SensorOutput};
use crate::thermal::soak::{SoakCalibration, SoakDrift, soak_calibration};
use crate::thermal::{FitOptions, model_file::ThermalModelFile};
use driftless_model::compensation::{CompensationModel, OutOfRange};
use driftless_model::units::DEG;

/// The ways the vehicle IMU data are processed, from least to most compensated.
///
/// (a)–(c) are the paper's three columns; (d) is the full room calibration without the
/// thermal model, between (b) and (c): (a) ⊂ (b) ⊂ (d) ⊂ (c) in what is corrected.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Case {
    /// (a) the IMU output as logged.
    Raw,
    /// (b) the biases removed at room temperature — no scale factor, no misalignment, no
    /// thermal model: ω = ω̃ − b_g(25 °C), f = f̃ − b_a(25 °C). The paper's column 2
    /// ("without scale factor and thermal compensation models"). On recorded data
    /// without a calibration, the gyro biases of the static start removed.
    RoomBias,
    /// (c) room bias, scale factor and misalignment plus the thermal model at the
    /// sensor's temperature reading (and the gyro g-sensitivity when the model has it).
    Thermal,
    /// (d) the full room calibration at 25 °C (bias, scale factor, misalignment), no
    /// thermal model — what a calibration without a chamber gives.
    RoomFull,
}

impl Case {
    /// The cases an experiment processes: (a) and (b); (c) and (d) when there is a
    /// thermal model (its room calibration gives (d)). In table order.
    pub fn processed(with_thermal_model: bool) -> Vec<Case> {
        let mut c = vec![Case::Raw, Case::RoomBias];
        if with_thermal_model {
            c.push(Case::Thermal);
            c.push(Case::RoomFull);
        }
        c
    }

    /// Short label for tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Case::Raw => "(a) raw",
            Case::RoomBias => "(b) room biases",
            Case::Thermal => "(c) room + thermal",
            Case::RoomFull => "(d) full room cal",
        }
    }

    /// Rank in what is corrected: (a) 0 < (b) 1 < (d) 2 < (c) 3. A case with a higher
    /// rank corrects everything a lower one does, and more.
    pub fn compensation_rank(self) -> u8 {
        match self {
            Case::Raw => 0,
            Case::RoomBias => 1,
            Case::RoomFull => 2,
            Case::Thermal => 3,
        }
    }
}

/// Progress callback: (stage, done, total).
pub type Progress<'a> = &'a (dyn Fn(&str, u64, u64) + Sync);

/// Recorded vehicle data, read in [`prepare`].
#[derive(Debug)]
pub struct RecordedVehicle {
    /// The IMU stream (vehicle frame).
    pub imu: ImuStream,
    /// The rates log with its temperature column (`csv` format only): cases b and c
    /// compensate it sample by sample.
    pub rates: Option<RatesWithTemperature>,
    /// GNSS fixes inside the IMU span.
    pub fixes: GnssFixes,
    /// Session settings (filter, aids, floors) of the data set.
    pub session: SessionConfig,
}

/// A rates log split into SI triads and the temperature reading (`csv` vehicle data).
#[derive(Clone, Debug)]
pub struct RatesWithTemperature {
    /// Where it came from.
    pub source: String,
    /// Time stamps, GPS s.
    pub time_s: Vec<f64>,
    /// Angular rate x, y, z, rad/s.
    pub gyro_rad_s: [Vec<f64>; 3],
    /// Specific force x, y, z, m/s².
    pub accel_m_s2: [Vec<f64>; 3],
    /// Sensor temperature, °C (`None` without a temperature column).
    pub temperature_c: Option<Vec<f64>>,
}

impl RatesWithTemperature {
    /// Splits a log: the first three angular-rate and specific-force channels in file
    /// order, and the temperature channel if there is one.
    pub fn from_log(log: &ImuLog) -> Result<RatesWithTemperature, String> {
        let Some(t) = &log.time_s else {
            return Err(format!("{}: no time column", log.source));
        };
        let pick = |q: Quantity, what: &str| -> Result<[Vec<f64>; 3], String> {
            let idx = log.indices_of(q);
            if idx.len() != 3 {
                return Err(format!(
                    "{}: {} {what} columns found, 3 needed (name the units in the header, e.g. \
                     gyro_x [rad/s], acc_x [m/s^2])",
                    log.source,
                    idx.len()
                ));
            }
            Ok([0, 1, 2].map(|k| log.channels[idx[k]].values.clone()))
        };
        let temperature_c = log
            .indices_of(Quantity::Temperature)
            .first()
            .map(|&i| log.channels[i].values.clone());
        Ok(RatesWithTemperature {
            source: log.source.clone(),
            time_s: t.clone(),
            gyro_rad_s: pick(Quantity::AngularRate, "angular-rate")?,
            accel_m_s2: pick(Quantity::SpecificForce, "specific-force")?,
            temperature_c,
        })
    }

    /// The stream after `f(sample index, ω, f) → (ω', f')`.
    fn stream(
        &self,
        label: &str,
        f: impl Fn(usize, [f64; 3], [f64; 3]) -> Result<([f64; 3], [f64; 3]), String>,
    ) -> Result<ImuStream, String> {
        let n = self.time_s.len();
        let mut g: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        let mut a: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        for k in 0..n {
            let w = [0, 1, 2].map(|j| self.gyro_rad_s[j][k]);
            let fb = [0, 1, 2].map(|j| self.accel_m_s2[j][k]);
            let (wc, fc) = f(k, w, fb)?;
            for j in 0..3 {
                g[j].push(wc[j]);
                a[j].push(fc[j]);
            }
        }
        crate::nav::pipeline::rates_to_stream(
            &format!("{} ({label})", self.source),
            None,
            &self.time_s,
            g.each_ref().map(Vec::as_slice),
            a.each_ref().map(Vec::as_slice),
            &ImuStreamOptions::default(),
        )
        .map_err(|e| e.to_string())
    }
}

/// The checked experiment, ready to run.
#[derive(Debug)]
pub struct Prepared {
    /// The scenario.
    pub scenario: ExperimentScenario,
    /// Where the vehicle data come from.
    pub source: VehicleSource,
    /// The simulated sensor (simulated stages).
    pub sensor: Option<SensorConfig>,
    /// The outage windows, with the dynamics each covers.
    pub outages: Vec<SelectedOutage>,
    /// Vehicle data span (reference), s.
    pub span_s: (f64, f64),
    /// Recorded vehicle data.
    pub recorded: Option<RecordedVehicle>,
}

impl Prepared {
    /// The outage windows.
    pub fn windows(&self) -> Vec<OutageWindow> {
        self.outages.iter().map(|o| o.window).collect()
    }
}

/// 64-bit mix (Steele et al., SplitMix64) for per-run seeds.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Seed of stage `tag` in Monte Carlo run `run`.
pub fn run_seed(seed: u64, tag: u64, run: usize) -> u64 {
    splitmix64(seed ^ tag.wrapping_mul(0x1000_0000_01B3) ^ (run as u64).wrapping_mul(0x9E37))
}

const TAG_NOISE: u64 = 1;
const TAG_CHAMBER: u64 = 2;
const TAG_VEHICLE: u64 = 3;

fn sim_scenario(
    sc: &ExperimentScenario,
    sensor: &SensorConfig,
    rate_hz: f64,
    trajectory: TrajectorySpec,
    seed: u64,
    errors: ErrorTerms,
) -> Scenario {
    Scenario {
        seed,
        start_time_s: 0.0,
        gps_week: None,
        imu: ImuSpec {
            rate_hz,
            preset: None,
            sensor: Some(sensor.clone()),
            noise_model: None,
            errors,
            output: OutputKind::Rates,
        },
        trajectory,
        temperature: None,
        gnss: None,
        output: OutputSpec::default(),
        base_dir: sc.base_dir.clone(),
        name: sc.name.clone(),
    }
}

/// Checks everything that can be checked cheaply and fixes the outage windows: on a
/// 1-Hz truth of a simulated run (no sensor simulated), or on the GNSS fixes of a
/// recorded one (read here, with the IMU file). An impossible outage request fails here,
/// before any long computation.
pub fn prepare(scenario: ExperimentScenario) -> Result<Prepared, ExperimentError> {
    scenario.check()?;
    let source = scenario.vehicle_source()?;
    let sensor = scenario.sensor_config()?;
    let spec = scenario.outage_spec()?;
    let opts = SelectOptions {
        min_gap_s: scenario.outages.min_gap_s,
        converge_s: scenario.outages.converge_s,
        ..SelectOptions::default()
    };
    let outage_err = |e: crate::eval::EvalError| scenario.invalid(format!("[outages] {e}"));
    // Outages start no earlier than `converge_s` after the filter can start.
    let opts_for = |r: &NavSolution| {
        let t0 = r.time_s.first().copied().unwrap_or(0.0);
        let moving = r
            .time_s
            .iter()
            .zip(&r.vel_ned_m_s)
            .find(|(_, v)| v[0].hypot(v[1]) >= 3.0)
            .map_or(t0, |(t, _)| *t);
        SelectOptions {
            converge_s: moving - t0 + scenario.outages.converge_s,
            ..opts
        }
    };
    match source {
        VehicleSource::Simulated => {
            let (Some(s), Some(traj)) = (&sensor, &scenario.vehicle.trajectory) else {
                return Err(scenario.invalid("a simulated [vehicle] needs [sensor]"));
            };
            let mut sim = sim_scenario(&scenario, s, 10.0, traj.clone(), 1, ErrorTerms::None);
            sim.output.truth_rate_hz = Some(1.0);
            let truth = sim
                .run()
                .map_err(|e| scenario.invalid(format!("[vehicle]: {e}")))?
                .truth;
            let span = span(&truth.time_s);
            let outages = resolve_outages(&spec, &truth, &opts_for(&truth)).map_err(outage_err)?;
            Ok(Prepared {
                scenario,
                source,
                sensor,
                outages,
                span_s: span,
                recorded: None,
            })
        }
        VehicleSource::NavConfig | VehicleSource::KfGins | VehicleSource::Csv => {
            let v = &scenario.vehicle;
            let stage = |e: &dyn std::fmt::Display| ExperimentError::stage("vehicle", e);
            let (imu, rates, fixes, session) = if let Some(p) = &v.nav_config {
                let loaded = crate::nav::config::NavConfig::load(Some(&scenario.resolve(p)), &[])
                    .map_err(|e| stage(&e))?;
                let inputs =
                    crate::nav::job::read_nav_inputs(&loaded, &crate::io::TextOptions::default())
                        .map_err(|e| stage(&e))?;
                let mut session = inputs.session_config;
                session.smooth = false;
                (inputs.imu, None, inputs.fixes, session)
            } else {
                let (Some(imu_rel), Some(gnss_rel)) = (&v.imu_file, &v.gnss_file) else {
                    return Err(scenario.invalid("recorded [vehicle] needs imu_file and gnss_file"));
                };
                let (imu_path, gnss_path) = (scenario.resolve(imu_rel), scenario.resolve(gnss_rel));
                let mut rates = None;
                let (imu, mut session) = if source == VehicleSource::Csv {
                    let opts = crate::io::TextOptions {
                        time_column: Some(crate::io::text::ColumnRef::Index(1)),
                        ..crate::io::TextOptions::default()
                    };
                    let log = crate::io::read_log_file(&imu_path, &opts).map_err(|e| stage(&e))?;
                    let r = RatesWithTemperature::from_log(&log).map_err(|e| stage(&e))?;
                    if scenario.chamber.is_some() && r.temperature_c.is_none() {
                        return Err(scenario.invalid(format!(
                            "[chamber] model given, but {} has no temperature column (a header \
                         field with unit [degC] or named temperature)",
                            imu_path.display()
                        )));
                    }
                    let imu = r
                        .stream("raw", |_, w, f| Ok((w, f)))
                        .map_err(|e| stage(&e))?;
                    rates = Some(r);
                    let noise = crate::nav::session::consumer_mems_noise();
                    (imu, SessionConfig::new(FilterConfig::new(noise, [0.0; 3])))
                } else {
                    let inc =
                        crate::io::nav::read_kfgins_imu_file(&imu_path).map_err(|e| stage(&e))?;
                    let imu = imu_from_kfgins(
                        &inc,
                        &imu_path.display().to_string(),
                        &ImuStreamOptions::default(),
                    )
                    .map_err(|e| stage(&e))?;
                    let noise = crate::nav::session::consumer_mems_noise();
                    (imu, SessionConfig::new(FilterConfig::new(noise, [0.0; 3])))
                };
                if let Some(l) = v.lever_arm_b_m {
                    session.filter.lever_arm_b_m = l;
                }
                session.smooth = false;
                let gnss = read_gnss_file(&gnss_path, &GnssReadOptions::default())
                    .map_err(|e| stage(&e))?;
                let fixes = select_gnss(&gnss, &imu, &OutageSpec::None, GnssOutsideImu::Drop)
                    .map_err(|e| stage(&e))?
                    .fixes;
                (imu, rates, fixes, session)
            };
            let reference = reference_from_fixes(&fixes).map_err(|e| stage(&e))?;
            let outages =
                resolve_outages(&spec, &reference, &opts_for(&reference)).map_err(outage_err)?;
            Ok(Prepared {
                span_s: span(&reference.time_s),
                scenario,
                source,
                sensor,
                outages,
                recorded: Some(RecordedVehicle {
                    imu,
                    rates,
                    fixes,
                    session,
                }),
            })
        }
    }
}

fn span(t: &[f64]) -> (f64, f64) {
    (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(0.0),
    )
}

/// Allan curves of the noise stage (for the report's figure).
#[derive(Clone, Debug)]
pub struct AllanCurves {
    /// OADEV per channel.
    pub results: Vec<ChannelResult>,
    /// Channel quantities.
    pub quantities: Vec<Quantity>,
    /// Channel SI units.
    pub units: Vec<String>,
}

/// Result of the noise stage.
#[derive(Clone, Debug)]
pub struct NoiseStage {
    /// The noise model (fitted or read).
    pub model: NoiseModel,
    /// The curves, when a log was analysed.
    pub curves: Option<AllanCurves>,
    /// Where it came from.
    pub source: String,
}

/// Analyses a static log: OADEV on 100 log-spaced τ, the noise terms fitted (Q, N, B, K,
/// R), 68.3 % intervals.
pub fn analyse_static_log(log: &ImuLog) -> Result<NoiseStage, ExperimentError> {
    let keep: Vec<usize> = (0..log.channels.len())
        .filter(|&i| {
            matches!(
                log.channels[i].quantity,
                Quantity::AngularRate | Quantity::SpecificForce
            )
        })
        .collect();
    let n_g = keep
        .iter()
        .filter(|&&i| log.channels[i].quantity == Quantity::AngularRate)
        .count();
    if n_g != 3 || keep.len() != 6 {
        return Err(ExperimentError::stage(
            "noise",
            format!(
                "{}: the static log needs three angular-rate and three specific-force \
                 channels in SI units; found {} and {}",
                log.source,
                n_g,
                keep.len() - n_g
            ),
        ));
    }
    let opts = LogAnalysisOptions {
        analysis: AnalysisConfig {
            taus: TauSpec::Log(100),
            ..AnalysisConfig::default()
        },
        // The IEEE 952 terms: the filter's bias states are their first-order stand-in,
        // and the simulated sensors of a study carry exactly these terms.
        method: Some(NoiseMethod::Allan(FitConfig::IEEE_952, None)),
        scale: None,
        remove_lines: false,
        resolution_from_data: false,
        channels: ChannelSelection::Inertial,
    };
    let analysis = analyse_log(log, &opts).map_err(|e| match e {
        LogAnalysisError::Curves { source, .. } => ExperimentError::stage("noise", source),
        other => ExperimentError::stage("noise", other),
    })?;
    let (results, quantities) = (analysis.results, analysis.quantities);
    let Some(model) = analysis.noise else {
        return Err(ExperimentError::stage("noise", "no noise model was fitted"));
    };
    Ok(NoiseStage {
        model,
        curves: Some(AllanCurves {
            units: quantities.iter().map(|q| q.si_unit().to_string()).collect(),
            results,
            quantities,
        }),
        source: log.source.clone(),
    })
}

/// The static log the noise stage simulates for `[noise] hours` (sensor `[sensor]` at
/// rest, level, at the chamber site; every error term; the noise seed of the scenario).
pub fn simulated_static_log(p: &Prepared) -> Result<ImuLog, ExperimentError> {
    let sc = &p.scenario;
    let (Some(sensor), Some(spec), Some(h)) = (
        &p.sensor,
        &sc.sensor,
        sc.noise.as_ref().and_then(|n| n.hours),
    ) else {
        return Err(sc.invalid("[noise] hours needs [sensor]"));
    };
    let traj = TrajectorySpec::Static {
        lat_deg: 51.08,
        lon_deg: -114.13,
        height_m: 1100.0,
        roll_deg: 0.0,
        pitch_deg: 0.0,
        yaw_deg: 0.0,
        duration_s: h * 3600.0,
    };
    let sim = sim_scenario(
        sc,
        sensor,
        spec.rate_hz,
        traj,
        run_seed(sc.seed, TAG_NOISE, 0),
        ErrorTerms::All,
    )
    .run()
    .map_err(|e| ExperimentError::stage("noise", e))?;
    Ok(sim.rates_log(&format!("simulated {h} h static log")))
}

/// The noise stage: simulate a static log of the sensor and analyse it, analyse a given
/// log, or read a saved model. `None` for a recorded scenario without `[noise]` (the
/// data set's own noise settings are used).
pub fn noise_stage(p: &Prepared) -> Result<Option<NoiseStage>, ExperimentError> {
    let sc = &p.scenario;
    let Some(n) = &sc.noise else {
        return Ok(None);
    };
    if n.hours.is_some() {
        let log = simulated_static_log(p)?;
        return analyse_static_log(&log).map(Some);
    }
    if let Some(f) = &n.file {
        let path = sc.resolve(f);
        let opts = crate::io::TextOptions {
            time_column: n
                .rate_hz
                .is_none()
                .then_some(crate::io::text::ColumnRef::Index(1)),
            rate_hz: n.rate_hz,
            ..crate::io::TextOptions::default()
        };
        let log = crate::io::read_log_file(&path, &opts)
            .map_err(|e| ExperimentError::stage("noise", e))?;
        return analyse_static_log(&log).map(Some);
    }
    if let Some(m) = &n.model {
        let path = sc.resolve(m);
        let model = NoiseModel::load(&path).map_err(|e| ExperimentError::stage("noise", e))?;
        return Ok(Some(NoiseStage {
            model,
            curves: None,
            source: path.display().to_string(),
        }));
    }
    Ok(None)
}

/// Result of the thermal stage.
#[derive(Clone, Debug)]
pub struct ThermalStage {
    /// Room calibration + thermal deltas.
    pub model: CompensationModel,
    /// The soak calibration (simulated chamber), for the figures.
    pub soak: Option<SoakCalibration>,
}

/// The chamber stage of Monte Carlo run `run`: simulate the chamber protocol with the
/// sensor and calibrate it by the soak method (GLS with the drift implied by the noise
/// model), or read a thermal model file. `None` without `[chamber]`.
pub fn thermal_stage(
    p: &Prepared,
    noise: Option<&NoiseStage>,
    run: usize,
) -> Result<Option<ThermalStage>, ExperimentError> {
    let sc = &p.scenario;
    let Some(c) = &sc.chamber else {
        return Ok(None);
    };
    let err = |e: &dyn std::fmt::Display| ExperimentError::stage("chamber", e);
    if let Some(m) = &c.model {
        let (_, model) = ThermalModelFile::load(sc.resolve(m)).map_err(|e| err(&e))?;
        return Ok(Some(ThermalStage { model, soak: None }));
    }
    let (Some(protocol), Some(sensor), Some(spec)) = (&c.protocol, &p.sensor, &sc.sensor) else {
        return Ok(None);
    };
    let mut protocol = protocol.clone();
    protocol.sample_rate_hz = spec.rate_hz;
    let sim = sim_scenario(
        sc,
        sensor,
        spec.rate_hz,
        TrajectorySpec::Chamber(protocol),
        run_seed(sc.seed, TAG_CHAMBER, run),
        ErrorTerms::All,
    )
    .run()
    .map_err(|e| err(&e))?;
    let Some(manifest) = &sim.manifest else {
        return Err(err(&"the chamber simulation gave no segment manifest"));
    };
    let drift = match noise {
        Some(n) => Some(SoakDrift::from_noise_model(&n.model).map_err(|e| err(&e))?),
        None => None,
    };
    let soak = soak_calibration(
        manifest,
        sim.imu.accel.each_ref().map(Vec::as_slice),
        sim.imu.gyro.each_ref().map(Vec::as_slice),
        1.0,
        &SixPositionOptions::from_manifest(manifest),
        &FitOptions {
            order: c.order,
            ..FitOptions::default()
        },
        drift.as_ref(),
    )
    .map_err(|e| err(&e))?;
    let model = soak
        // Model id < 2⁶³: the model file stores it as a (signed 64-bit) TOML integer.
        .compensation_model(run_seed(sc.seed, TAG_CHAMBER, run) >> 1, OutOfRange::Clamp)
        .map_err(|e| err(&e))?;
    Ok(Some(ThermalStage {
        model,
        soak: Some(soak),
    }))
}

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
    /// Error budget per outage (detailed run only; [`super::budget`]).
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
    pub fn smoothed_mean_end_m(&self) -> Option<f64> {
        self.smoothed.as_ref().and_then(mean_end)
    }
}

fn mean_end(r: &Result<OutageReport, String>) -> Option<f64> {
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
    pub fn without_solutions(&self) -> VehicleRun {
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
const MAX_BIAS_ONLY_MATRIX_DEPARTURE: f64 = 0.1;

/// Checks that case (b) (biases only) applies to data calibrated by `model`.
fn check_bias_only(model: &CompensationModel) -> Result<(), String> {
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
fn compensate_case(
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
fn case_stream(
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

struct CaseInput<'a> {
    case: Case,
    imu: ImuStream,
    fixes: &'a GnssFixes,
    session: SessionConfig,
    prime: bool,
}

fn run_case(
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
fn simulated_session(
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

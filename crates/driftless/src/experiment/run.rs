//! The experiment's stages: [`prepare`] (checks and outage windows, fast), then
//! [`noise_stage`] → [`thermal_stage`] → [`vehicle_run`] (module docs of
//! [`super`]).
//!
//! The stages after the noise stage are in `thermal` and `vehicle`; recorded input data in
//! `recorded`.
//!
//! Seeds: run k of a Monte Carlo draws its chamber log, vehicle IMU and GNSS from
//! `splitmix64(seed ⊕ tag ⊕ k)`; the static log of the noise stage is drawn once. The
//! sensor's *design* (deterministic thermal curves, misalignment …) is the same in every
//! stage and run; what changes is what a new power-up changes (turn-on biases) and noise.

use serde::Serialize;

use super::ExperimentError;
use super::scenario::{ExperimentScenario, VehicleSource};
use crate::allan::analysis::{AnalysisConfig, ChannelResult};
use crate::allan::fit::FitConfig;
use crate::allan::log_analysis::{
    ChannelSelection, LogAnalysisError, LogAnalysisOptions, NoiseMethod, analyse_log,
};
use crate::allan::noise_model::NoiseModel;
use crate::allan::taus::TauSpec;
use crate::eval::reference::reference_from_fixes;
use crate::eval::select::{SelectOptions, SelectedOutage, resolve_outages};
use crate::io::nav::{GnssReadOptions, NavSolution};
use crate::io::{ImuLog, Quantity};
use crate::nav::filter::model::FilterConfig;
use crate::nav::outage::{OutageSpec, OutageWindow};
use crate::nav::pipeline::{
    GnssOutsideImu, ImuStreamOptions, imu_from_kfgins, read_gnss_file, select_gnss,
};
use crate::nav::session::SessionConfig;
use crate::numeric::splitmix::splitmix64_mix;
use crate::sim::scenario::{ErrorTerms, ImuSpec, OutputSpec, Scenario, TrajectorySpec};
use crate::sim::sensor_config::SensorConfig;
use crate::sim::sensor_data::OutputKind;

mod recorded;
mod thermal;
mod vehicle;

pub use recorded::{RatesWithTemperature, RecordedVehicle};
pub use thermal::{ThermalStage, thermal_stage};
pub use vehicle::{CaseRun, VehicleRun, filter_noise, vehicle_run};

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
    pub(crate) fn processed(with_thermal_model: bool) -> Vec<Case> {
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

/// Seed of stage `tag` in Monte Carlo run `run`.
pub fn run_seed(seed: u64, tag: u64, run: usize) -> u64 {
    splitmix64_mix(seed ^ tag.wrapping_mul(0x1000_0000_01B3) ^ (run as u64).wrapping_mul(0x9E37))
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
pub(crate) fn analyse_static_log(log: &ImuLog) -> Result<NoiseStage, ExperimentError> {
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

//! A simulation scenario (`driftless simulate SCENARIO.toml`): trajectory, sensor errors,
//! temperature and GNSS in one TOML file, run reproducibly from a seed into a
//! [`Simulation`] — IMU samples, GNSS fixes, the truth and (for the chamber) the segment
//! manifest. Writing files is the caller's job (the CLI's `simulate`).
//!
//! ```toml
//! seed = 7
//! start_time_s = 356400.0   # GPS seconds of week of t = 0 (profile / static; optional)
//! gps_week = 2300           # optional
//!
//! [imu]
//! rate_hz = 200.0
//! preset = "adis16465-like" # adi-like | adis16465-like | consumer | tactical | ideal
//! # noise_model = "noise-model.toml"   # replaces the preset's noise terms
//! # errors = "all"          # all | noise | deterministic | none
//! # output = "increments"   # increments | rates
//! # [imu.sensor] …          # a complete sensor configuration instead of a preset
//!
//! [trajectory]
//! type = "recorded"         # recorded | profile | static | chamber
//! file = "wuhan_gnss.txt"   # KF-GINS GNSS text or RTKLIB .pos (by extension)
//!
//! [temperature]             # optional (default constant 25 °C); not with a chamber
//! kind = "warm_up"
//! t0_c = 20.0
//! t1_c = 45.0
//! tau_s = 900.0
//!
//! [gnss]                    # optional; not with a chamber
//! rate_hz = 1.0
//! sigma_ned_m = [0.02, 0.02, 0.02]
//! lever_arm_b_m = [0.0, 0.0, -1.0]
//! outages = "9x60s every 300s from 300s"   # fixes removed from the output
//! # correlated_sigma_ned_m = [0.2, 0.2, 0.1]  # Gauss–Markov error (antenna motion)
//! # correlated_tau_s = 3.0
//! # reported_sigma_ned_m = [0.01, 0.01, 0.02] # the receiver's formal σ in the files
//! # [[gnss.degraded_windows]]                 # e.g. RTK float, s from the first fix
//! # start_s = 60.0
//! # end_s = 80.0
//! # sigma_ned_m = [0.4, 0.4, 0.8]             # extra Gauss–Markov error
//! # tau_s = 20.0
//! # reported_sigma_ned_m = [0.15, 0.15, 0.3]
//! ```
//!
//! Trajectory kinds: `recorded` ([`super::recorded`]: `file`, optional
//! `position_cutoff_hz`, `roll = "zero" | "coordinated_turn"`), `profile`
//! ([`super::profile`]: `file`, or the profile's `[start]`/`[mounting]`/`[gait]`/
//! `[[segment]]` inline under `[trajectory]`), `static` (`lat_deg`, `lon_deg`, `height_m`, `roll_deg`,
//! `pitch_deg`, `yaw_deg`, `duration_s`) and `chamber` ([`super::chamber::ChamberConfig`]
//! keys; its sample rate is `imu.rate_hz`). Relative paths resolve against the
//! scenario file's folder. Unknown keys anywhere are errors naming the key.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::chamber::ChamberConfig;
use super::gnss::{GnssSimConfig, simulate_gnss};
use super::ideal_imu::{Trajectory, TrajectoryPoint};
use super::presets::Preset;
use super::recorded::{RecordedOptions, RecordedTrajectory, RollModel};
use super::sensor::SensorModel;
use super::sensor_config::SensorConfig;
use super::sensor_data::{IdealImu, OutputKind, SensorOutput};
use super::temperature::TemperatureProfile;
use crate::calib::protocol::ChamberManifest;
use crate::io::nav::{GnssFixes, GnssReadOptions, NavSolution};
use crate::nav::attitude::{Euler, Quat};
use crate::nav::mechanization::NavState;
use crate::nav::outage::{OutageSpec, TimeSpan};
use driftless_model::units::DEG;

/// Why a scenario could not be read or run.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The scenario file could not be read or parsed (message names the key / line).
    #[error("{path}: {message}")]
    File {
        /// Scenario file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A value that parses but cannot be simulated.
    #[error("{path}: {message}")]
    Invalid {
        /// Scenario file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A trajectory or GNSS setting refused by the simulator.
    #[error("{path}: {source}")]
    Sim {
        /// Scenario file.
        path: String,
        /// The simulator's error.
        source: super::noise::SimError,
    },
    /// A sensor or temperature setting refused by the sensor model.
    #[error("{path}: {source}")]
    Sensor {
        /// Scenario file.
        path: String,
        /// The sensor model's error.
        source: super::sensor_error::SensorSimError,
    },
}

/// Which error terms to simulate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorTerms {
    /// Every configured term.
    #[default]
    All,
    /// Only the stochastic terms (white, bias instability, random walks, quantization).
    Noise,
    /// Only the deterministic terms (biases, scale factors, misalignment, thermal).
    Deterministic,
    /// None: ideal output.
    None,
}

/// `[imu]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuSpec {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Preset name ([`Preset`]) or `ideal`.
    #[serde(default)]
    pub preset: Option<String>,
    /// A complete sensor configuration (instead of a preset).
    #[serde(default)]
    pub sensor: Option<SensorConfig>,
    /// Noise-model file whose fitted terms replace the noise terms.
    #[serde(default)]
    pub noise_model: Option<PathBuf>,
    /// Which error terms to simulate.
    #[serde(default)]
    pub errors: ErrorTerms,
    /// Increments (default) or rates.
    #[serde(default = "default_kind")]
    pub output: OutputKind,
}

fn default_kind() -> OutputKind {
    OutputKind::Increments
}

/// `[trajectory]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum TrajectorySpec {
    /// Positions recorded at ≥ 1 Hz, smoothed.
    Recorded {
        /// KF-GINS GNSS text or RTKLIB `.pos`.
        file: PathBuf,
        /// Position smoother half-gain frequency, Hz.
        #[serde(default)]
        position_cutoff_hz: Option<f64>,
        /// `zero` (default) or `coordinated_turn`.
        #[serde(default)]
        roll: Option<String>,
    },
    /// A land-vehicle motion profile, from a file or inline.
    Profile {
        /// Profile TOML file.
        #[serde(default)]
        file: Option<PathBuf>,
        /// Inline `[start]`.
        #[serde(default)]
        start: Option<toml::Value>,
        /// Inline `[mounting]`.
        #[serde(default)]
        mounting: Option<toml::Value>,
        /// Inline `[gait]` (a hand-held walk).
        #[serde(default)]
        gait: Option<toml::Value>,
        /// Inline `[[segment]]`s.
        #[serde(default)]
        segment: Option<Vec<toml::Value>>,
    },
    /// A static IMU.
    Static {
        /// Latitude, deg.
        lat_deg: f64,
        /// Longitude, deg.
        #[serde(default)]
        lon_deg: f64,
        /// Height, m.
        #[serde(default)]
        height_m: f64,
        /// Roll, deg.
        #[serde(default)]
        roll_deg: f64,
        /// Pitch, deg.
        #[serde(default)]
        pitch_deg: f64,
        /// Yaw, deg.
        #[serde(default)]
        yaw_deg: f64,
        /// Length, s.
        duration_s: f64,
    },
    /// The thermal-chamber protocol.
    Chamber(ChamberConfig),
}

/// `[gnss]`: [`GnssSimConfig`] without the times (they follow the trajectory), with
/// outages in the `--outages` grammar (relative to the first fix).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Fix rate, Hz.
    pub rate_hz: f64,
    /// White position σ north, east, down, m.
    pub sigma_ned_m: [f64; 3],
    /// Correlated position σ, m.
    #[serde(default)]
    pub correlated_sigma_ned_m: [f64; 3],
    /// Its correlation time, s.
    #[serde(default)]
    pub correlated_tau_s: Option<f64>,
    /// Velocity output σ, m/s.
    #[serde(default)]
    pub velocity_sigma_ned_m_s: Option<[f64; 3]>,
    /// Lever arm IMU → antenna, body FRD, m.
    #[serde(default)]
    pub lever_arm_b_m: [f64; 3],
    /// RTKLIB quality flag.
    #[serde(default)]
    pub quality: Option<u8>,
    /// σ written with the fixes (the receiver's formal σ), m; default the true total σ.
    #[serde(default)]
    pub reported_sigma_ned_m: Option<[f64; 3]>,
    /// Degraded (e.g. RTK float) windows, times relative to the first fix
    /// ([`super::gnss::DegradedWindow`]).
    #[serde(default)]
    pub degraded_windows: Vec<super::gnss::DegradedWindow>,
    /// Outage windows (fixes removed), `--outages` grammar.
    #[serde(default)]
    pub outages: Option<String>,
}

/// `[output]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Folder (relative to the working directory).
    #[serde(default = "default_dir")]
    pub dir: PathBuf,
    /// Truth (`truth.nav`) rate, Hz (default: the IMU rate for moving trajectories,
    /// 1 Hz for static and chamber ones).
    #[serde(default)]
    pub truth_rate_hz: Option<f64>,
}

fn default_dir() -> PathBuf {
    PathBuf::from("sim-out")
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            dir: default_dir(),
            truth_rate_hz: None,
        }
    }
}

/// A whole scenario file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Seed of every random draw.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// GPS seconds of week of t = 0 (profile and static trajectories).
    #[serde(default)]
    pub start_time_s: f64,
    /// GPS week of the output.
    #[serde(default)]
    pub gps_week: Option<u16>,
    /// The IMU.
    pub imu: ImuSpec,
    /// The motion.
    pub trajectory: TrajectorySpec,
    /// Sensor temperature (default constant 25 °C).
    #[serde(default)]
    pub temperature: Option<TemperatureProfile>,
    /// GNSS.
    #[serde(default)]
    pub gnss: Option<GnssSpec>,
    /// Output.
    #[serde(default)]
    pub output: OutputSpec,
    /// Folder relative paths resolve against (the scenario file's).
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// Name for messages.
    #[serde(skip)]
    pub name: String,
}

fn default_seed() -> u64 {
    1
}

/// The result of a scenario.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// IMU output (increments or rates), on output time.
    pub imu: SensorOutput,
    /// GNSS fixes, on output time.
    pub gnss: Option<GnssFixes>,
    /// Outage windows removed from `gnss`, output time, s.
    pub gnss_outages_s: Vec<(f64, f64)>,
    /// Truth at the truth rate, on output time.
    pub truth: NavSolution,
    /// Truth at the start of the first IMU interval (output time).
    pub initial: NavState,
    /// The resolved sensor configuration.
    pub sensor: SensorConfig,
    /// Chamber segments (chamber trajectories).
    pub manifest: Option<ChamberManifest>,
    /// The GNSS lever arm, body FRD, m.
    pub lever_arm_b_m: [f64; 3],
}

impl Scenario {
    /// Reads a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let text = crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|e| {
            ScenarioError::File {
                path: path.display().to_string(),
                message: e.to_string(),
            }
        })?;
        let mut s = Scenario::from_toml_str(&text, &path.display().to_string())?;
        s.base_dir = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Ok(s)
    }

    /// Parses scenario text; `name` is used in messages, relative paths resolve against
    /// the working directory.
    pub fn from_toml_str(text: &str, name: &str) -> Result<Scenario, ScenarioError> {
        let mut s: Scenario = toml::from_str(text).map_err(|e| ScenarioError::File {
            path: name.to_owned(),
            message: e.to_string(),
        })?;
        s.name = name.to_owned();
        s.base_dir = PathBuf::from(".");
        Ok(s)
    }

    fn invalid(&self, message: impl Into<String>) -> ScenarioError {
        ScenarioError::Invalid {
            path: self.name.clone(),
            message: message.into(),
        }
    }

    fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }

    /// The sensor configuration after preset, explicit config, noise model and
    /// `errors`.
    pub fn sensor_config(&self) -> Result<SensorConfig, ScenarioError> {
        let mut cfg = match (&self.imu.preset, &self.imu.sensor) {
            (Some(_), Some(_)) => {
                return Err(self.invalid("imu: give `preset` or `[imu.sensor]`, not both"));
            }
            (Some(p), None) if p == "ideal" => SensorConfig::default(),
            (Some(p), None) => p
                .parse::<Preset>()
                .map_err(|e| self.invalid(format!("imu.preset: {e}")))?
                .config(),
            (None, Some(c)) => c.clone(),
            (None, None) => {
                return Err(self.invalid(
                    "imu: give `preset` (adi-like, adis16465-like, consumer, tactical, ideal) \
                     or a `[imu.sensor]` table",
                ));
            }
        };
        if let Some(p) = &self.imu.noise_model {
            let path = self.resolve(p);
            let model = crate::allan::noise_model::NoiseModel::load(&path)
                .map_err(|e| self.invalid(format!("imu.noise_model {}: {e}", path.display())))?;
            cfg.apply_noise_model(&model)
                .map_err(|e| self.invalid(format!("imu.noise_model: {e}")))?;
        }
        Ok(match self.imu.errors {
            ErrorTerms::All => cfg,
            ErrorTerms::Noise => cfg.noise_only(),
            ErrorTerms::Deterministic => cfg.deterministic_only(),
            ErrorTerms::None => SensorConfig {
                valid_range_c: cfg.valid_range_c,
                t_ref_c: cfg.t_ref_c,
                ..SensorConfig::default()
            },
        })
    }

    /// Runs the scenario.
    pub fn run(&self) -> Result<Simulation, ScenarioError> {
        let rate = self.imu.rate_hz;
        if !(rate.is_finite() && rate > 0.0 && rate <= 100_000.0) {
            return Err(self.invalid(format!(
                "imu.rate_hz must be a positive number of Hz up to 100 kHz, got {rate}"
            )));
        }
        let dt = 1.0 / rate;
        let sensor = self.sensor_config()?;
        let model = SensorModel::new(sensor.clone()).map_err(|source| self.sensor_error(source))?;
        let Motion {
            traj,
            t0,
            t1,
            offset,
            manifest,
            temperature,
        } = self.motion(rate)?;
        if !offset.is_finite() {
            return Err(self.invalid("start_time_s must be finite"));
        }
        let n = ((t1 - t0) * rate + 1e-9).floor() as usize;
        if n < 2 {
            return Err(self.invalid(format!(
                "the trajectory lasts {} s: fewer than two IMU samples at {rate} Hz",
                t1 - t0
            )));
        }
        let first = match self.imu.output {
            OutputKind::Increments => t0 + dt,
            OutputKind::Rates => t0,
        };
        let n = match self.imu.output {
            OutputKind::Increments => n,
            OutputKind::Rates => n + 1,
        };
        let curve = temperature
            .curve()
            .map_err(|source| self.sensor_error(source))?;
        let ideal = match &self.trajectory {
            // A static IMU's ideal output is one constant: no per-sample evaluation.
            TrajectorySpec::Static { .. } => {
                let (w, f) = traj.point(t0).imu_rates();
                IdealImu::constant(self.imu.output, first, dt, n, w, f)
            }
            _ => IdealImu::from_trajectory(&*traj, self.imu.output, first, dt, n),
        };
        let mut imu = model
            .simulate(&ideal, &curve, self.seed)
            .map_err(|source| self.sensor_error(source))?;
        imu.first_time_s += offset;

        let (mut gnss, mut gnss_outages_s, mut lever) = (None, Vec::new(), [0.0; 3]);
        if let Some(g) = &self.gnss {
            let (fixes, outages_s) = self.gnss_fixes(g, &*traj, t0, t1, offset)?;
            (gnss, gnss_outages_s, lever) = (Some(fixes), outages_s, g.lever_arm_b_m);
        }

        // Truth.
        let moving = matches!(
            self.trajectory,
            TrajectorySpec::Recorded { .. } | TrajectorySpec::Profile { .. }
        );
        let truth_rate =
            self.output
                .truth_rate_hz
                .unwrap_or(if moving { rate } else { rate.min(1.0) });
        if !(truth_rate.is_finite() && truth_rate > 0.0) {
            return Err(self.invalid(format!(
                "output.truth_rate_hz must be > 0, got {truth_rate}"
            )));
        }
        let nt = ((t1 - t0) * truth_rate + 1e-9).floor() as usize + 1;
        let truth = truth_solution(&*traj, t0, 1.0 / truth_rate, nt, offset);
        let mut initial = traj.point(t0).nav_state(t0 + offset);
        initial.q_bn = initial.q_bn.normalized();
        Ok(Simulation {
            imu,
            gnss,
            gnss_outages_s,
            truth,
            initial,
            sensor,
            manifest,
            lever_arm_b_m: lever,
        })
    }

    fn sensor_error(&self, source: super::sensor_error::SensorSimError) -> ScenarioError {
        ScenarioError::Sensor {
            path: self.name.clone(),
            source,
        }
    }

    fn sim_error(&self, source: super::noise::SimError) -> ScenarioError {
        ScenarioError::Sim {
            path: self.name.clone(),
            source,
        }
    }

    /// The motion of the `[trajectory]` table at IMU rate `rate_hz`.
    fn motion(&self, rate_hz: f64) -> Result<Motion, ScenarioError> {
        let temperature = self
            .temperature
            .clone()
            .unwrap_or(TemperatureProfile::constant(25.0));
        let plain = |traj: Box<dyn Trajectory + Sync>, t0, t1, offset| Motion {
            traj,
            t0,
            t1,
            offset,
            manifest: None,
            temperature: temperature.clone(),
        };
        Ok(match &self.trajectory {
            TrajectorySpec::Recorded {
                file,
                position_cutoff_hz,
                roll,
            } => {
                let r = self.recorded_motion(file, *position_cutoff_hz, roll.as_deref())?;
                let (t0, t1) = (r.start_s(), r.end_s());
                plain(Box::new(r), t0, t1, 0.0)
            }
            TrajectorySpec::Profile {
                file,
                start,
                mounting,
                gait,
                segment,
            } => {
                let lv = self
                    .profile_motion(file, start, mounting, gait, segment)?
                    .build()
                    .map_err(|e| self.sim_error(e))?;
                let t1 = lv.duration_s();
                plain(Box::new(lv), 0.0, t1, self.start_time_s)
            }
            TrajectorySpec::Static {
                lat_deg,
                lon_deg,
                height_m,
                roll_deg,
                pitch_deg,
                yaw_deg,
                duration_s,
            } => {
                let vals = [
                    *lat_deg, *lon_deg, *height_m, *roll_deg, *pitch_deg, *yaw_deg,
                ];
                if vals.iter().any(|v| !v.is_finite()) || lat_deg.abs() > 90.0 {
                    return Err(self.invalid(
                        "trajectory (static): position and attitude must be finite, |lat_deg| ≤ 90",
                    ));
                }
                if !(duration_s.is_finite() && *duration_s > 0.0) {
                    return Err(self.invalid(format!(
                        "trajectory.duration_s must be > 0 s, got {duration_s}"
                    )));
                }
                let c_bn = Euler {
                    roll_rad: roll_deg * DEG,
                    pitch_rad: pitch_deg * DEG,
                    yaw_rad: yaw_deg * DEG,
                }
                .to_dcm();
                let p = TrajectoryPoint {
                    lat_rad: lat_deg * DEG,
                    lon_rad: lon_deg * DEG,
                    height_m: *height_m,
                    vel_ned_m_s: [0.0; 3],
                    acc_ned_m_s2: [0.0; 3],
                    c_bn,
                    omega_nb_b_rad_s: [0.0; 3],
                };
                plain(
                    Box::new(move |_t: f64| p),
                    0.0,
                    *duration_s,
                    self.start_time_s,
                )
            }
            TrajectorySpec::Chamber(c) => {
                if self.temperature.is_some() || self.gnss.is_some() {
                    return Err(self.invalid(
                        "a chamber trajectory brings its own temperature profile and has no \
                         GNSS: remove [temperature] and [gnss]",
                    ));
                }
                let mut c = c.clone();
                c.sample_rate_hz = rate_hz;
                let proto = c.build().map_err(|e| self.sensor_error(e))?;
                Motion {
                    t0: 0.0,
                    t1: proto.manifest.duration_s,
                    offset: self.start_time_s,
                    manifest: Some(proto.manifest.clone()),
                    temperature: proto.temperature.clone(),
                    traj: Box::new(proto.trajectory),
                }
            }
        })
    }

    /// A trajectory from a recorded GNSS track (`[trajectory] file = …`).
    fn recorded_motion(
        &self,
        file: &Path,
        position_cutoff_hz: Option<f64>,
        roll: Option<&str>,
    ) -> Result<RecordedTrajectory, ScenarioError> {
        let path = self.resolve(file);
        let fixes = crate::nav::pipeline::read_gnss_file(&path, &GnssReadOptions::default())
            .map_err(|e| self.invalid(format!("trajectory.file: {e}")))?;
        let mut opts = RecordedOptions::default();
        if let Some(f) = position_cutoff_hz {
            opts.position_cutoff_hz = f;
        }
        opts.roll = match roll {
            None | Some("zero") => RollModel::Zero,
            Some("coordinated_turn") => RollModel::CoordinatedTurn,
            Some(other) => {
                return Err(self.invalid(format!(
                    "trajectory.roll = {other:?}: expected \"zero\" or \"coordinated_turn\""
                )));
            }
        };
        RecordedTrajectory::from_fixes(&fixes, &opts).map_err(|e| self.sim_error(e))
    }

    /// A motion profile from its file or the inline `[trajectory]` tables.
    fn profile_motion(
        &self,
        file: &Option<PathBuf>,
        start: &Option<toml::Value>,
        mounting: &Option<toml::Value>,
        gait: &Option<toml::Value>,
        segment: &Option<Vec<toml::Value>>,
    ) -> Result<super::profile::MotionProfile, ScenarioError> {
        match (file, start) {
            (Some(f), None) => super::profile::MotionProfile::from_file(self.resolve(f))
                .map_err(|e| self.sim_error(e)),
            (None, Some(start)) => {
                let mut t = toml::Table::new();
                t.insert("start".into(), start.clone());
                if let Some(m) = mounting {
                    t.insert("mounting".into(), m.clone());
                }
                if let Some(g) = gait {
                    t.insert("gait".into(), g.clone());
                }
                t.insert(
                    "segment".into(),
                    toml::Value::Array(segment.clone().unwrap_or_default()),
                );
                let text =
                    toml::to_string(&t).map_err(|e| self.invalid(format!("trajectory: {e}")))?;
                super::profile::MotionProfile::from_toml_str(
                    &text,
                    &format!("{} [trajectory]", self.name),
                )
                .map_err(|e| self.sim_error(e))
            }
            _ => Err(self.invalid(
                "trajectory (profile): give `file` or an inline [trajectory.start] \
                 with [[trajectory.segment]]s, not both",
            )),
        }
    }

    /// The GNSS fixes of the `[gnss]` table along `traj` over \[t0, t1\], and the outage
    /// windows on output time (`offset` added).
    fn gnss_fixes(
        &self,
        g: &GnssSpec,
        traj: &(dyn Trajectory + Sync),
        t0: f64,
        t1: f64,
        offset: f64,
    ) -> Result<(GnssFixes, Vec<(f64, f64)>), ScenarioError> {
        let mut cfg = GnssSimConfig::new(g.rate_hz, t0, t1, 0.0);
        cfg.sigma_ned_m = g.sigma_ned_m;
        cfg.correlated_sigma_ned_m = g.correlated_sigma_ned_m;
        if let Some(tau) = g.correlated_tau_s {
            cfg.correlated_tau_s = tau;
        }
        cfg.velocity_sigma_ned_m_s = g.velocity_sigma_ned_m_s;
        cfg.lever_arm_b_m = g.lever_arm_b_m;
        if let Some(q) = g.quality {
            cfg.quality = q;
        }
        cfg.reported_sigma_ned_m = g.reported_sigma_ned_m;
        cfg.degraded_windows = g
            .degraded_windows
            .iter()
            .map(|w| super::gnss::DegradedWindow {
                start_s: w.start_s + t0,
                end_s: w.end_s + t0,
                ..w.clone()
            })
            .collect();
        cfg.time_offset_s = offset;
        cfg.gps_week = self.gps_week;
        // The first fix is at t0 (the start of the trajectory); 1 s margin at the end.
        cfg.end_s = (t1 - 1e-6).max(t0);
        let mut outages_s = Vec::new();
        if let Some(spec) = &g.outages {
            let spec: OutageSpec = spec
                .parse()
                .map_err(|e| self.invalid(format!("gnss.outages: {e}")))?;
            let windows = spec
                .resolve(TimeSpan {
                    start_s: t0,
                    end_s: cfg.end_s,
                })
                .map_err(|e| self.invalid(format!("gnss.outages: {e}")))?;
            cfg.outages_s = windows.iter().map(|w| (w.start_s, w.end_s)).collect();
            outages_s = cfg
                .outages_s
                .iter()
                .map(|&(a, b)| (a + offset, b + offset))
                .collect();
        }
        let fixes =
            simulate_gnss(traj, &cfg, self.seed ^ 0x9e37_79b9).map_err(|e| self.sim_error(e))?;
        Ok((fixes, outages_s))
    }
}

/// A scenario's motion: the trajectory on its own clock over \[`t0`, `t1`\] s, the offset
/// added to put it on output time, the chamber protocol's manifest when there is one, and
/// the temperature the sensor sees.
struct Motion {
    traj: Box<dyn Trajectory + Sync>,
    t0: f64,
    t1: f64,
    offset: f64,
    manifest: Option<ChamberManifest>,
    temperature: TemperatureProfile,
}

/// Truth samples t0 + k·dt (k < n) as a navigation solution on output time.
fn truth_solution<T: Trajectory + Sync + ?Sized>(
    traj: &T,
    t0: f64,
    dt: f64,
    n: usize,
    offset: f64,
) -> NavSolution {
    use rayon::prelude::*;
    let pts: Vec<TrajectoryPoint> = (0..n)
        .into_par_iter()
        .map(|k| traj.point(t0 + k as f64 * dt))
        .collect();
    let mut s = NavSolution::default();
    for (k, p) in pts.iter().enumerate() {
        let e = Euler::from_dcm(&p.c_bn);
        s.push_epoch(
            t0 + k as f64 * dt + offset,
            p.lat_rad,
            p.lon_rad,
            p.height_m,
            p.vel_ned_m_s,
            [e.roll_rad, e.pitch_rad, e.yaw_rad],
        );
    }
    s
}

impl Simulation {
    /// The IMU output as a log of rates (increments divided by Δt: interval averages)
    /// with the reported temperature, for CSV/DRIFTLOG output and `driftless nav
    /// --imu-format csv`.
    pub fn rates_log(&self, source: &str) -> crate::io::ImuLog {
        let mut out = self.imu.clone();
        if out.kind == OutputKind::Increments {
            let inv = 1.0 / out.dt_s;
            for v in out.gyro.iter_mut().chain(out.accel.iter_mut()) {
                v.iter_mut().for_each(|x| *x *= inv);
            }
            out.kind = OutputKind::Rates;
        }
        out.to_imu_log(source)
    }

    /// The IMU output as the navigation session's input
    /// ([`crate::nav::session::run_session`]): increments on output time in the IMU's
    /// own axes (with a profile `[mounting]`, the session needs that rotation too), GPS
    /// week from the GNSS output when there is one.
    pub fn imu_stream(&self, source: &str) -> crate::nav::pipeline::ImuStream {
        crate::nav::pipeline::ImuStream {
            source: source.to_owned(),
            gps_week: self.gnss.as_ref().and_then(|g| g.gps_week),
            nominal_dt_s: self.imu.dt_s,
            epochs: self.imu.to_increments(),
            gaps: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// The IMU output as KF-GINS increments.
    pub fn increments(&self) -> crate::io::nav::ImuIncrements {
        crate::nav::pipeline::increment_columns(&self.imu.to_increments())
    }
}

/// Attitude of a truth state as Euler angles (for configs), rad.
pub(crate) fn euler_of(q: &Quat) -> Euler {
    Euler::from_dcm(&q.to_dcm())
}

#[cfg(test)]
mod tests {
    use super::*;

    const PROFILE: &str = r#"
seed = 3
start_time_s = 100000.0
[imu]
rate_hz = 100.0
preset = "consumer"
[trajectory]
type = "profile"
[trajectory.start]
lat_deg = 30.5
lon_deg = 114.3
height_m = 20.0
heading_deg = 10.0
[[trajectory.segment]]
type = "stop"
duration_s = 5.0
[[trajectory.segment]]
type = "accelerate"
to_speed_m_s = 10.0
duration_s = 10.0
[[trajectory.segment]]
type = "turn"
angle_deg = 90.0
radius_m = 40.0
[gnss]
rate_hz = 1.0
sigma_ned_m = [0.02, 0.02, 0.04]
lever_arm_b_m = [0.5, 0.0, -1.0]
outages = "8+5"
"#;

    #[test]
    fn profile_scenario_runs_and_is_reproducible() {
        let s = Scenario::from_toml_str(PROFILE, "p.toml").unwrap();
        let a = s.run().unwrap();
        let b = s.run().unwrap();
        assert_eq!(a.imu, b.imu);
        assert_eq!(a.gnss, b.gnss);
        let dur = 15.0 + 40.0 * std::f64::consts::FRAC_PI_2 / 10.0;
        assert_eq!(a.imu.len(), (dur * 100.0 + 1e-9).floor() as usize);
        assert!((a.imu.time_s(0) - 100_000.01).abs() < 1e-9);
        let g = a.gnss.as_ref().unwrap();
        assert_eq!(g.time_s[0], 100_000.0);
        // Window (8, 13] s: the fix at 8 s stays, those after it up to 13 s are removed.
        assert!(g.time_s.iter().all(|&t| !(t > 100_008.0 && t <= 100_013.0)));
        assert!(g.time_s.contains(&100_008.0));
        assert_eq!(a.gnss_outages_s, vec![(100_008.0, 100_013.0)]);
        assert_eq!(
            a.truth.time_s.len(),
            (dur * 100.0 + 1e-9).floor() as usize + 1
        );
        assert_eq!(a.initial.time_s, 100_000.0);
        let stream = a.imu_stream("p.toml");
        assert_eq!(stream.len(), a.imu.len());
        assert_eq!(stream.nominal_dt_s, 0.01);
        assert!((stream.epochs[0].time_s - 100_000.01).abs() < 1e-9);
        let mut s2 = s.clone();
        s2.seed = 4;
        assert_ne!(s2.run().unwrap().imu, a.imu);
    }

    #[test]
    fn bad_scenarios_are_named() {
        let cases = [
            (
                PROFILE.replace("rate_hz = 100.0", "rate_hz = 100.0\nrate_khz = 1"),
                "rate_khz",
            ),
            (
                PROFILE.replace("\"consumer\"", "\"nasa-grade\""),
                "nasa-grade",
            ),
            (
                PROFILE.replace("to_speed_m_s = 10.0", "to_speed_m_s = -10.0"),
                "to_speed_m_s",
            ),
            (
                PROFILE.replace("radius_m = 40.0", "radius_m = 0.0"),
                "radius_m",
            ),
            (
                PROFILE.replace("type = \"profile\"", "type = \"orbit\""),
                "orbit",
            ),
            (
                PROFILE.replace("outages = \"8+5\"", "outages = \"20+500\""),
                "gnss.outages",
            ),
            (
                PROFILE.replace("rate_hz = 100.0", "rate_hz = \"100 Hz\""),
                "rate_hz",
            ),
        ];
        for (text, want) in cases {
            let e = Scenario::from_toml_str(&text, "p.toml")
                .and_then(|s| s.run())
                .unwrap_err()
                .to_string();
            assert!(e.contains(want) && e.contains("p.toml"), "{want}: {e}");
        }
        // A temperature outside the sensor model's valid range.
        let hot = PROFILE.replace(
            "[gnss]",
            "[temperature]\nkind = \"constant\"\nt_c = 150.0\n[gnss]",
        );
        let e = Scenario::from_toml_str(&hot, "p.toml")
            .unwrap()
            .run()
            .unwrap_err()
            .to_string();
        assert!(e.contains("150"), "{e}");
    }

    /// The chamber examples parse and build their protocol (the recommended one with its
    /// 22 steps, palindromic order and three position cycles).
    #[test]
    fn chamber_examples_build() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios");
        for (file, steps) in [
            ("chamber-adi.toml", 20),
            ("chamber-adi-recommended.toml", 22),
        ] {
            let text = std::fs::read_to_string(dir.join(file)).expect(file);
            let sc: Scenario = toml::from_str(&text).expect(file);
            let TrajectorySpec::Chamber(c) = &sc.trajectory else {
                panic!("{file}: not a chamber")
            };
            let p = c.build().expect(file);
            assert_eq!(p.manifest.steps().len(), steps, "{file}");
            if steps == 22 {
                assert_eq!(c.position_cycles, 3);
                assert_eq!(c.step_order, super::super::chamber::StepOrder::Palindromic);
                assert_eq!(c.visit_dwell_s(), 5.0);
            }
        }
    }

    #[test]
    fn static_scenario_with_ideal_sensor_is_exact() {
        let text = r#"
[imu]
rate_hz = 50.0
preset = "ideal"
output = "rates"
[trajectory]
type = "static"
lat_deg = 45.0
yaw_deg = 30.0
duration_s = 2.0
"#;
        let sim = Scenario::from_toml_str(text, "s.toml")
            .unwrap()
            .run()
            .unwrap();
        assert_eq!(sim.imu.len(), 101);
        let f = sim.imu.accel_at(50);
        let g = crate::nav::earth::gravity_ned(45f64.to_radians(), 0.0)[2];
        assert!((f[2] + g).abs() < 1e-12, "{f:?}");
        let w = sim.imu.gyro_at(0);
        let we = 7.292_115e-5;
        assert!((driftless_model::linalg::norm(w) - we).abs() < 1e-9);
    }
}

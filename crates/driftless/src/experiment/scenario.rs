//! The experiment scenario file (`driftless experiment SCENARIO.toml`) and its checks.
//!
//! ```toml
//! title = "adi-like: the paper's experiment on simulated data"
//! seed = 2005
//!
//! [sensor]                 # simulated stages: the one sensor of every stage
//! preset = "adi-like"      # or [sensor.config] (a full SensorConfig)
//! rate_hz = 100.0
//!
//! [noise]                  # Allan analysis → noise model (filter tuning)
//! hours = 2.0              # simulated static log; or file = "static.csv"; or model = "noise.toml"
//!
//! [chamber]                # chamber soak → thermal model (optional: absent = cases a, b)
//! [chamber.protocol]       # simulated (ChamberConfig keys); or model = "thermal.toml"
//! soak_s = 600.0
//!
//! [vehicle]                # simulated: trajectory, temperature, gnss tables
//! [vehicle.trajectory]     #   (the `driftless simulate` keys)
//! type = "profile"
//! …
//! # recorded: imu_file, gnss_file, format = "kf-gins" | "csv", lever_arm_b_m;
//! #   or nav_config = "nav.toml" (a `driftless nav` configuration: files, mounting, noise …)
//!
//! [outages]
//! spec = "auto:9x60"       # or "300+60,600+60" (s after the first reference epoch)
//!
//! [filter]
//! bias_tau_s = 3600.0
//!
//! [monte_carlo]
//! runs = 20
//! ```
//!
//! Relative paths resolve against the scenario file's folder. Unknown keys are errors
//! naming the key. [`ExperimentScenario::check`] finds every inconsistency that does not
//! need the data (missing files, conflicting rates, a stage given two ways, Monte Carlo on
//! recorded data) before anything is computed.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::ExperimentError;
use crate::nav::outage::OutageSpec;
use crate::sim::chamber::ChamberConfig;
use crate::sim::presets::Preset;
use crate::sim::scenario::{GnssSpec, TrajectorySpec};
use crate::sim::sensor_config::SensorConfig;
use crate::sim::temperature::TemperatureProfile;

/// The built-in scenario of `driftless demo` (magnitudes and sources in its comments).
pub const BUILTIN_ADI_LIKE: &str = include_str!("builtin_adi_like.toml");

/// A whole experiment file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentScenario {
    /// Title for the report.
    #[serde(default)]
    pub title: Option<String>,
    /// Seed of every random draw (run k of a Monte Carlo derives its seeds from it).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The simulated sensor (required by every simulated stage).
    #[serde(default)]
    pub sensor: Option<SensorSpec>,
    /// Noise analysis stage.
    #[serde(default)]
    pub noise: Option<NoiseSpec>,
    /// Chamber stage (absent: no thermal model, cases a and b only).
    #[serde(default)]
    pub chamber: Option<ChamberSpec>,
    /// The vehicle run.
    pub vehicle: VehicleSpec,
    /// GNSS outages.
    #[serde(default)]
    pub outages: OutageSettings,
    /// Navigation filter settings.
    #[serde(default)]
    pub filter: FilterSettings,
    /// Monte Carlo repetitions.
    #[serde(default)]
    pub monte_carlo: MonteCarloSettings,
    /// Folder relative paths resolve against.
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// Name for messages (the file path, or `built-in adi-like`).
    #[serde(skip)]
    pub name: String,
}

fn default_seed() -> u64 {
    1
}

/// `[sensor]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Sample rate of every simulated IMU log, Hz.
    pub rate_hz: f64,
    /// Preset name.
    #[serde(default)]
    pub preset: Option<String>,
    /// A complete sensor configuration instead of a preset.
    #[serde(default)]
    pub config: Option<SensorConfig>,
}

/// `[noise]`: exactly one of `hours`, `file`, `model`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Length of a simulated static log of `[sensor]`, h.
    #[serde(default)]
    pub hours: Option<f64>,
    /// A static log to analyse: DRIFTLOG, or delimited text with units in its header
    /// (`gyro_x [deg/s]`) and the time in its first column — or no time column and
    /// `rate_hz`.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// Sample rate of a `file` without a time column, Hz.
    #[serde(default)]
    pub rate_hz: Option<f64>,
    /// A saved noise model (`driftless allan --save-model`).
    #[serde(default)]
    pub model: Option<PathBuf>,
}

/// `[chamber]`: `protocol` (simulated) or `model` (a thermal model file).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamberSpec {
    /// Simulated chamber protocol of `[sensor]`.
    #[serde(default)]
    pub protocol: Option<ChamberConfig>,
    /// A thermal compensation model file (`driftless thermal soak --out`).
    #[serde(default)]
    pub model: Option<PathBuf>,
    /// Polynomial order of the fit (default 3, the paper's cubic).
    #[serde(default = "default_order")]
    pub order: usize,
}

fn default_order() -> usize {
    3
}

/// `[vehicle]`: simulated (`trajectory`, `gnss`, optional `temperature`) or recorded
/// (`imu_file`, `gnss_file`, `format`, or a navigation configuration `nav_config`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSpec {
    /// Simulated motion (`driftless simulate`'s `[trajectory]`).
    #[serde(default)]
    pub trajectory: Option<TrajectorySpec>,
    /// Sensor temperature during the run (default constant 25 °C).
    #[serde(default)]
    pub temperature: Option<TemperatureProfile>,
    /// Simulated GNSS (`driftless simulate`'s `[gnss]`, without outages).
    #[serde(default)]
    pub gnss: Option<GnssSpec>,
    /// Recorded IMU file.
    #[serde(default)]
    pub imu_file: Option<PathBuf>,
    /// Recorded GNSS file (RTKLIB `.pos` or KF-GINS text).
    #[serde(default)]
    pub gnss_file: Option<PathBuf>,
    /// Recorded data format: `kf-gins` (increments), or `csv` (delimited text of rates with
    /// a header naming units, the time in GPS seconds in the first column, and optionally a
    /// temperature column — the format `driftless simulate` writes — which allows case c
    /// with `[chamber] model`).
    #[serde(default)]
    pub format: Option<String>,
    /// A `driftless nav` configuration ([`crate::nav::config`]) naming the recorded files
    /// and everything about them (format, time offset, mounting, lever arm, noise, aids);
    /// replaces `imu_file`, `gnss_file`, `format` and `lever_arm_b_m`.
    #[serde(default)]
    pub nav_config: Option<PathBuf>,
    /// IMU → antenna lever arm, body FRD, m (recorded data; simulated data use the gnss one).
    #[serde(default)]
    pub lever_arm_b_m: Option<[f64; 3]>,
}

/// `[outages]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutageSettings {
    /// `auto:NxL`, explicit windows or a generator (`driftless nav --outages` grammar).
    #[serde(default = "default_outages")]
    pub spec: String,
    /// Least time between outages for `auto`, s (default max(2·L, 120 s)).
    #[serde(default)]
    pub min_gap_s: Option<f64>,
    /// Time after the filter can start (the first reference epoch moving at ≥ 3 m/s, the
    /// in-motion initialisation's threshold) kept free of outages, s.
    #[serde(default = "default_converge")]
    pub converge_s: f64,
}

fn default_outages() -> String {
    "auto:9x60".into()
}

fn default_converge() -> f64 {
    120.0
}

impl Default for OutageSettings {
    fn default() -> Self {
        OutageSettings {
            spec: default_outages(),
            min_gap_s: None,
            converge_s: default_converge(),
        }
    }
}

/// `[filter]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterSettings {
    /// Correlation time of the bias Gauss–Markov states, s.
    #[serde(default = "default_bias_tau")]
    pub bias_tau_s: f64,
    /// σ of the scale-factor Gauss–Markov states (fraction, 5e-3 = 0.5 %).
    #[serde(default = "default_scale_sigma")]
    pub scale_sigma: f64,
    /// Initial gyro-bias σ, deg/s (default: the noise model's bias σ).
    #[serde(default)]
    pub initial_gyro_bias_sigma_deg_s: Option<f64>,
    /// Initial accelerometer-bias σ, m/s² (default: the noise model's bias σ).
    #[serde(default)]
    pub initial_accel_bias_sigma_m_s2: Option<f64>,
    /// Non-holonomic constraint (the paper used none).
    #[serde(default)]
    pub nhc: bool,
    /// Run the RTS smoother too (the paper's reference processing).
    #[serde(default = "default_true")]
    pub smooth: bool,
}

fn default_bias_tau() -> f64 {
    3600.0
}
fn default_scale_sigma() -> f64 {
    5e-3
}
fn default_true() -> bool {
    true
}

impl Default for FilterSettings {
    fn default() -> Self {
        FilterSettings {
            bias_tau_s: default_bias_tau(),
            scale_sigma: default_scale_sigma(),
            initial_gyro_bias_sigma_deg_s: None,
            initial_accel_bias_sigma_m_s2: None,
            nhc: false,
            smooth: true,
        }
    }
}

/// `[monte_carlo]`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloSettings {
    /// Number of runs (new chamber, vehicle IMU and GNSS draws per run).
    #[serde(default = "default_runs")]
    pub runs: usize,
    /// Confidence level of the reported intervals.
    #[serde(default = "default_confidence")]
    pub confidence: f64,
    /// Smooth every run, not only run 0 (the smoother costs about twice the filter).
    #[serde(default)]
    pub smooth_all_runs: bool,
}

fn default_runs() -> usize {
    1
}
fn default_confidence() -> f64 {
    0.95
}

impl Default for MonteCarloSettings {
    fn default() -> Self {
        MonteCarloSettings {
            runs: default_runs(),
            confidence: default_confidence(),
            smooth_all_runs: false,
        }
    }
}

/// Where the vehicle data come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VehicleSource {
    /// Simulated from `[sensor]` and `[vehicle.trajectory]`.
    Simulated,
    /// A navigation configuration file (`[vehicle] nav_config`).
    NavConfig,
    /// KF-GINS increment text.
    KfGins,
    /// Delimited text of rates (and temperature), first column GPS time.
    Csv,
}

impl ExperimentScenario {
    /// Reads and checks a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<ExperimentScenario, ExperimentError> {
        let path = path.as_ref();
        let text = crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|e| {
            ExperimentError::Scenario {
                path: path.display().to_string(),
                message: format!("cannot read: {e}"),
            }
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        ExperimentScenario::from_toml_str(&text, &path.display().to_string(), base)
    }

    /// The built-in `adi-like` scenario of `driftless demo`.
    pub fn builtin_adi_like() -> Result<ExperimentScenario, ExperimentError> {
        ExperimentScenario::from_toml_str(BUILTIN_ADI_LIKE, "built-in adi-like", PathBuf::new())
    }

    /// Parses and checks scenario text; `base_dir` anchors relative paths.
    pub fn from_toml_str(
        text: &str,
        name: &str,
        base_dir: PathBuf,
    ) -> Result<ExperimentScenario, ExperimentError> {
        let mut s: ExperimentScenario =
            toml::from_str(text).map_err(|e| ExperimentError::Scenario {
                path: name.to_string(),
                message: e.to_string(),
            })?;
        s.base_dir = base_dir;
        s.name = name.to_string();
        s.check()?;
        Ok(s)
    }

    pub(crate) fn invalid(&self, message: impl Into<String>) -> ExperimentError {
        ExperimentError::Scenario {
            path: self.name.clone(),
            message: message.into(),
        }
    }

    /// A path of the scenario: `${DRIFTLESS_DATA}` replaced by that environment variable
    /// (default `../shared/data`, relative to the working directory — the repository root
    /// in the README's commands), then resolved against the scenario's folder.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        crate::io::resolve_data_path(p, &self.base_dir)
    }

    fn existing(&self, key: &str, p: &Path) -> Result<PathBuf, ExperimentError> {
        let r = self.resolve(p);
        if r.is_file() {
            Ok(r)
        } else {
            Err(self.invalid(format!("{key} = {:?}: no such file ({})", p, r.display())))
        }
    }

    /// The simulated sensor's configuration (`None` without `[sensor]`).
    pub fn sensor_config(&self) -> Result<Option<SensorConfig>, ExperimentError> {
        let Some(s) = &self.sensor else {
            return Ok(None);
        };
        match (&s.preset, &s.config) {
            (Some(p), None) => p
                .parse::<Preset>()
                .map(|p| Some(p.config()))
                .map_err(|e| self.invalid(format!("sensor.preset: {e}"))),
            (None, Some(c)) => Ok(Some(c.clone())),
            _ => {
                Err(self.invalid("[sensor]: give `preset` or a [sensor.config] table, one of them"))
            }
        }
    }

    /// Where the vehicle data come from.
    pub fn vehicle_source(&self) -> Result<VehicleSource, ExperimentError> {
        let v = &self.vehicle;
        let sim = v.trajectory.is_some() || v.gnss.is_some() || v.temperature.is_some();
        let rec = v.imu_file.is_some()
            || v.gnss_file.is_some()
            || v.format.is_some()
            || v.nav_config.is_some();
        match (sim, rec) {
            (true, true) => Err(self.invalid(
                "[vehicle]: give a simulated run (trajectory, gnss, temperature) or recorded \
                 files (imu_file, gnss_file, format), not both",
            )),
            (false, false) => Err(self.invalid(
                "[vehicle]: give a simulated run ([vehicle.trajectory] and [vehicle.gnss]) or \
                 recorded files (imu_file, gnss_file, format)",
            )),
            (true, false) => Ok(VehicleSource::Simulated),
            (false, true) if v.nav_config.is_some() => {
                if v.imu_file.is_some() || v.gnss_file.is_some() || v.format.is_some() || v.lever_arm_b_m.is_some() {
                    return Err(self.invalid(
                        "[vehicle]: nav_config names the files and their settings; drop imu_file, \
                         gnss_file, format and lever_arm_b_m (or drop nav_config)",
                    ));
                }
                Ok(VehicleSource::NavConfig)
            }
            (false, true) => match v.format.as_deref() {
                Some("drive_0708") => Err(self.invalid(
                    "vehicle.format = \"drive_0708\": the drive's settings are a navigation \
                     configuration now: nav_config = \"nav/drive0708.toml\" (from the examples folder)",
                )),
                Some("kf-gins") => Ok(VehicleSource::KfGins),
                Some("csv") => Ok(VehicleSource::Csv),
                Some(other) => Err(self.invalid(format!(
                    "vehicle.format = {other:?}: expected \"kf-gins\" or \"csv\", or give nav_config"
                ))),
                None => Err(self.invalid(
                    "vehicle.format is needed with recorded files: \"drive_0708\", \"kf-gins\" \
                     or \"csv\"",
                )),
            },
        }
    }

    /// Every check that needs no data (module docs). Called by the constructors.
    pub fn check(&self) -> Result<(), ExperimentError> {
        let sensor = self.sensor_config()?;
        if let Some(s) = &self.sensor
            && !(s.rate_hz.is_finite() && s.rate_hz > 0.0 && s.rate_hz <= 10_000.0)
        {
            return Err(self.invalid(format!(
                "sensor.rate_hz must be a positive number of Hz up to 10 kHz, got {}",
                s.rate_hz
            )));
        }
        let has_sensor = sensor.is_some();
        self.check_noise(has_sensor)?;
        self.check_chamber(has_sensor)?;
        let source = self.vehicle_source()?;
        self.check_vehicle(source, has_sensor)?;
        let spec: OutageSpec = self
            .outages
            .spec
            .parse()
            .map_err(|e| self.invalid(format!("outages.spec: {e}")))?;
        if matches!(spec, OutageSpec::None) {
            return Err(self.invalid(
                "outages.spec = \"none\": the experiment measures drift in GNSS outages; give \
                 e.g. \"auto:9x60\"",
            ));
        }
        let f = &self.filter;
        if !(f.bias_tau_s.is_finite() && f.bias_tau_s > 0.0) {
            return Err(self.invalid(format!("filter.bias_tau_s = {}: must be > 0", f.bias_tau_s)));
        }
        if !(f.scale_sigma.is_finite() && f.scale_sigma >= 0.0 && f.scale_sigma < 0.5) {
            return Err(self.invalid(format!(
                "filter.scale_sigma = {}: a fraction in [0, 0.5)",
                f.scale_sigma
            )));
        }
        for (k, v) in [
            (
                "initial_gyro_bias_sigma_deg_s",
                f.initial_gyro_bias_sigma_deg_s,
            ),
            (
                "initial_accel_bias_sigma_m_s2",
                f.initial_accel_bias_sigma_m_s2,
            ),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return Err(self.invalid(format!("filter.{k} = {v}: must be > 0")));
            }
        }
        let mc = &self.monte_carlo;
        if !(1..=10_000).contains(&mc.runs) {
            return Err(self.invalid(format!("monte_carlo.runs = {}: 1 to 10 000", mc.runs)));
        }
        if !(mc.confidence > 0.5 && mc.confidence < 1.0) {
            return Err(self.invalid(format!(
                "monte_carlo.confidence = {}: between 0.5 and 1",
                mc.confidence
            )));
        }
        if self.noise.is_none() && source == VehicleSource::Simulated {
            return Err(self.invalid(
                "[noise] is missing: the filter's noise model comes from the Allan analysis \
                 (give hours, file or model)",
            ));
        }
        Ok(())
    }

    /// Error unless the scenario has a `[sensor]` table, which `what` needs to be simulated.
    fn needs_sensor(&self, has_sensor: bool, what: &str) -> Result<(), ExperimentError> {
        if !has_sensor {
            Err(self.invalid(format!(
                "{what} is simulated, so the scenario needs a [sensor] table (preset and rate_hz)"
            )))
        } else {
            Ok(())
        }
    }

    /// The `[noise]` table: one source of the noise model, usable.
    fn check_noise(&self, has_sensor: bool) -> Result<(), ExperimentError> {
        if let Some(n) = &self.noise {
            let given = [n.hours.is_some(), n.file.is_some(), n.model.is_some()];
            if given.iter().filter(|g| **g).count() != 1 {
                return Err(self.invalid(
                    "[noise]: give exactly one of `hours` (simulated static log), `file` (a \
                     static log) or `model` (a saved noise model)",
                ));
            }
            if let Some(h) = n.hours {
                self.needs_sensor(has_sensor, "[noise]")?;
                if !(h.is_finite() && (0.05..=100.0).contains(&h)) {
                    return Err(self.invalid(format!(
                        "noise.hours = {h}: a static log of 0.05 to 100 h is needed"
                    )));
                }
            }
            if let Some(f) = &n.file {
                self.existing("noise.file", f)?;
            }
            if let Some(r) = n.rate_hz
                && (n.file.is_none() || !(r.is_finite() && r > 0.0))
            {
                return Err(self.invalid(format!(
                    "noise.rate_hz = {r}: a positive rate, only with noise.file (a log without \
                     a time column)"
                )));
            }
            if let Some(f) = &n.model {
                self.existing("noise.model", f)?;
            }
        }
        Ok(())
    }

    /// The `[chamber]` table: a simulated protocol at the sensor's rate or a thermal model,
    /// and a polynomial order of 1 to 5.
    fn check_chamber(&self, has_sensor: bool) -> Result<(), ExperimentError> {
        if let Some(c) = &self.chamber {
            match (&c.protocol, &c.model) {
                (Some(p), None) => {
                    self.needs_sensor(has_sensor, "[chamber]")?;
                    let rate = self.sensor.as_ref().map_or(0.0, |s| s.rate_hz);
                    if (p.sample_rate_hz - rate).abs() > 1e-9 * rate
                        && p.sample_rate_hz != ChamberConfig::default().sample_rate_hz
                    {
                        return Err(self.invalid(format!(
                            "inconsistent rates: [sensor] rate_hz = {rate} Hz but \
                             [chamber.protocol] sample_rate_hz = {} Hz (one sensor, one \
                             rate: drop the chamber's key or make them equal)",
                            p.sample_rate_hz
                        )));
                    }
                }
                (None, Some(m)) => {
                    self.existing("chamber.model", m)?;
                }
                _ => {
                    return Err(self.invalid(
                        "[chamber]: give a simulated [chamber.protocol] or `model` (a thermal \
                         model file), one of them",
                    ));
                }
            }
            if !(1..=5).contains(&c.order) {
                return Err(self.invalid(format!(
                    "chamber.order = {}: polynomial order 1 to 5",
                    c.order
                )));
            }
        }
        Ok(())
    }

    /// The `[vehicle]` table: a simulated run with GNSS at a rate not above the IMU's, or
    /// recorded files that exist (one run, and a chamber only where the data carry a
    /// temperature).
    fn check_vehicle(
        &self,
        source: VehicleSource,
        has_sensor: bool,
    ) -> Result<(), ExperimentError> {
        match source {
            VehicleSource::Simulated => {
                self.needs_sensor(has_sensor, "[vehicle]")?;
                if self.vehicle.trajectory.is_none() {
                    return Err(self.invalid("[vehicle.trajectory] is missing"));
                }
                if matches!(self.vehicle.trajectory, Some(TrajectorySpec::Chamber(_))) {
                    return Err(
                        self.invalid("vehicle.trajectory.type = \"chamber\" is not a vehicle run")
                    );
                }
                let Some(g) = &self.vehicle.gnss else {
                    return Err(self.invalid(
                        "[vehicle.gnss] is missing: the experiment needs GNSS to withhold",
                    ));
                };
                if g.outages.is_some() {
                    return Err(self.invalid(
                        "vehicle.gnss.outages: the experiment's outages go in [outages] spec \
                         (fixes are withheld from the filter, not removed from the data)",
                    ));
                }
                let rate = self.sensor.as_ref().map_or(0.0, |s| s.rate_hz);
                if !(g.rate_hz.is_finite() && g.rate_hz > 0.0) || g.rate_hz > rate {
                    return Err(self.invalid(format!(
                        "inconsistent rates: vehicle.gnss.rate_hz = {} Hz must be > 0 and not \
                         above the IMU's {rate} Hz",
                        g.rate_hz
                    )));
                }
            }
            VehicleSource::NavConfig | VehicleSource::KfGins | VehicleSource::Csv => {
                let v = &self.vehicle;
                if let Some(p) = &v.nav_config {
                    let path = self.existing("vehicle.nav_config", p)?;
                    crate::nav::config::NavConfig::load(Some(&path), &[])
                        .map_err(|e| self.invalid(format!("vehicle.nav_config: {e}")))?;
                } else {
                    let (Some(i), Some(g)) = (&v.imu_file, &v.gnss_file) else {
                        return Err(self.invalid("recorded [vehicle] needs imu_file and gnss_file"));
                    };
                    self.existing("vehicle.imu_file", i)?;
                    self.existing("vehicle.gnss_file", g)?;
                }
                if self.monte_carlo.runs > 1 {
                    return Err(self.invalid(format!(
                        "monte_carlo.runs = {}: a recorded run cannot be redrawn; Monte Carlo \
                         needs a simulated [vehicle]",
                        self.monte_carlo.runs
                    )));
                }
                match (&self.chamber, source) {
                    (Some(c), VehicleSource::Csv) if c.protocol.is_some() => {
                        return Err(self.invalid(
                            "[chamber.protocol] simulates a sensor, but the vehicle data are \
                             recorded: give chamber.model, the thermal model of this IMU \
                             (`driftless thermal soak --out`)",
                        ));
                    }
                    (Some(_), VehicleSource::NavConfig | VehicleSource::KfGins) => {
                        return Err(self.invalid(
                            "[chamber] with recorded vehicle data: a nav_config run and the kf-gins \
                             format carry no sensor temperature, so a thermal model cannot be \
                             applied (case c); drop [chamber], or give the IMU as format = \
                             \"csv\" with a temperature column",
                        ));
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }

    /// The outage specification (checked by [`ExperimentScenario::check`]).
    pub fn outage_spec(&self) -> Result<OutageSpec, ExperimentError> {
        self.outages
            .spec
            .parse()
            .map_err(|e| self.invalid(format!("outages.spec: {e}")))
    }
}

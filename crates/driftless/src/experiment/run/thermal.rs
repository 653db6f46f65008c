//! The thermal stage: the chamber protocol simulated and calibrated by the soak method,
//! or a thermal model read.

use crate::calib::six_position::SixPositionOptions;
use crate::experiment::ExperimentError;
use crate::sim::scenario::{ErrorTerms, TrajectorySpec};
use crate::thermal::soak::{SoakCalibration, SoakDrift, soak_calibration};
use crate::thermal::{FitOptions, model_file::ThermalModelFile};
use driftless_model::compensation::{CompensationModel, OutOfRange};

use super::{NoiseStage, Prepared, TAG_CHAMBER, run_seed, sim_scenario};

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

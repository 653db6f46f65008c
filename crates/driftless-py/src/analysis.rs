//! `driftless.analyse`: one channel's stability curve with confidence bounds
//! ([`driftless::allan::analysis::analyse`]) and, for a gyro or accelerometer channel, the
//! fitted noise model ([`NoiseModel::from_curves_with`]) — what `driftless allan` computes
//! for each column of a log.

use driftless::allan::analysis::{AnalysisConfig, ChannelResult, analyse};
use driftless::allan::checks::resolution_step;
use driftless::allan::fit::FitConfig;
use driftless::allan::noise_model::{ModelOptions, NoiseModel};
use driftless::allan::taus::TauSpec;
use driftless::allan::{AllanError, DataType, Estimator};
use driftless::prelude::Quantity;

/// What to compute, as given from Python.
pub struct Request {
    /// Channel name used in the result and the model.
    pub name: String,
    /// Estimator of the curve.
    pub estimator: Estimator,
    /// Tau grid (`octave`, `decade`, `all`, `log:N`, or a list of seconds).
    pub taus: TauSpec,
    /// Rates or their integral.
    pub data_type: DataType,
    /// Fixed noise exponent for the bounds, or None to identify it per tau.
    pub alpha: Option<i32>,
    /// Confidence level of the bounds and of the model's term intervals.
    pub confidence: f64,
    /// Fit a noise model of this quantity (None: no model).
    pub quantity: Option<Quantity>,
    /// Which noise terms the model may use.
    pub terms: FitConfig,
}

/// The curve and, when asked for, the model.
pub struct Outcome {
    /// The stability curve with bounds.
    pub curve: ChannelResult,
    /// The fitted noise model.
    pub model: Option<NoiseModel>,
}

/// Parse a quantity name as the noise-model file spells it.
pub fn quantity(name: &str) -> Result<Quantity, AllanError> {
    match name {
        "angular_rate" | "gyro" => Ok(Quantity::AngularRate),
        "specific_force" | "accel" => Ok(Quantity::SpecificForce),
        other => Err(AllanError::Invalid(format!(
            "unknown quantity {other:?}; expected \"angular_rate\" (gyro, rad/s) or \
             \"specific_force\" (accelerometer, m/s^2)"
        ))),
    }
}

/// Run the analysis (and the fit) on `values` sampled at `rate_hz`.
pub fn run(values: &[f64], rate_hz: f64, req: &Request) -> Result<Outcome, AllanError> {
    let tau0_s = crate::compat::sample_interval_s(rate_hz)?;
    let cfg = AnalysisConfig {
        estimator: req.estimator,
        taus: req.taus.clone(),
        data_type: req.data_type,
        alpha: req.alpha,
        confidence: req.confidence,
        fast: false,
    };
    let curve = analyse(&req.name, values, tau0_s, &cfg)?;
    let Some(q) = req.quantity else {
        return Ok(Outcome { curve, model: None });
    };
    // The model is fitted to an OADEV curve: the requested one, else OADEV on log:100.
    let oadev_curve;
    let fit_curve = if req.estimator == Estimator::Oadev {
        &curve
    } else {
        let fit_cfg = AnalysisConfig {
            estimator: Estimator::Oadev,
            taus: TauSpec::Log(100),
            ..cfg
        };
        oadev_curve = analyse(&req.name, values, tau0_s, &fit_cfg)?;
        &oadev_curve
    };
    let resolution = match req.data_type {
        DataType::Frequency => vec![resolution_step(values)],
        DataType::Phase => Vec::new(),
    };
    let opts = ModelOptions {
        resolution,
        ..ModelOptions::default()
    };
    let model = NoiseModel::from_curves_with(
        "<array>",
        std::slice::from_ref(fit_curve),
        &[q],
        &req.terms,
        req.confidence,
        &opts,
    )?;
    Ok(Outcome {
        curve,
        model: Some(model),
    })
}

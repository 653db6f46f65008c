//! Thermal models: a sensor parameter (bias, scale factor …) as a polynomial in
//! the temperature difference ΔT = T − T_ref, seed paper §3.3 eqs. 1–2
//! (cubics about t₀ = 25 °C fitted by least squares to soak-test results over −25…70 °C).
//!
//! * [`fit`](mod@fit): the polynomial fit (order 1–5, default 3) by Householder QR on a centred,
//!   scaled temperature, with coefficient covariance, residual RMS, χ²/dof, confidence
//!   band, leave-one-temperature-out cross-validation and AIC/BIC order advice. Its
//!   result carries a [`driftless_model::thermal::ThermalPoly`] for compensation.
//! * [`stats`]: Student-t and normal quantiles for the intervals.
//! * [`model_file`]: the thermal compensation model file (TOML).
//! * [`ramp`]: the ramp method — bias versus temperature from one warm-up or cool-down,
//!   binned medians (robust to quantised temperature and uneven heating), hysteresis.
//! * [`soak`]: the soak method — six-position + rate-table calibration at every set
//!   temperature of a chamber recording, then a weighted fit of each bias and scale series.
//! * [`check`]: checks of a log before a fit (temperature rise and resolution, heating-rate
//!   profile, motion, gaps) with a verdict per method.
//! * [`autopilot`]: export of a model's bias part to PX4 `TC_*` and ArduPilot `INS_TCAL*`
//!   parameter files, their import, and each autopilot's correction formula.
//!
//! Algorithms only: no file I/O here.

pub mod autopilot;
pub mod check;
pub mod fit;
pub mod job;
pub mod model_file;
pub mod ramp;
pub mod soak;
pub mod stats;

pub use fit::{
    BandPoint, CrossValidation, FitOptions, HeldOut, NoiseScale, OrderAdvice, OrderRow, ThermalFit,
    ThermalFitError, advise_order, cross_validate, fit, fit_correlated, held_out,
};

//! The crate's one error type: every stage's error, so a program using several stages
//! can return [`Result`] and use `?` throughout.
//!
//! Each variant wraps one stage's own error unchanged. `Display` is that error's
//! message and [`std::error::Error::source`] continues its chain (the I/O error under
//! a file read, the parse error under a configuration key), so
//! `anyhow`'s `{:#}` or a loop over `source()` prints every cause. Match on a variant
//! for the stage's detail (file, line, column, time span).

/// Any error of the library, by stage. Each variant boxes the stage's error (so a
/// `Result<T, Error>` stays two words wide); `From` takes the stage error unboxed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    // ---- data and files ----
    /// Arrays that do not make a valid log or set of fixes.
    #[error(transparent)]
    Data(Box<crate::data::DataError>),
    /// Reading an IMU log (file, line, column).
    #[error(transparent)]
    Log(Box<crate::io::LogError>),
    /// Writing an output file or claiming an output folder.
    #[error(transparent)]
    Output(Box<crate::io::output::OutputError>),
    /// A GNSS or IMU time base that does not fit the data.
    #[error(transparent)]
    TimeBase(Box<crate::io::nav::TimeBaseError>),
    /// A unit string that could not be parsed.
    #[error(transparent)]
    Unit(Box<crate::io::units::UnknownUnit>),
    /// A plot that could not be drawn or written.
    #[error(transparent)]
    Plot(Box<crate::report::plot::PlotError>),

    // ---- noise analysis ----
    /// An Allan-family analysis.
    #[error(transparent)]
    Allan(Box<crate::allan::AllanError>),
    /// A noise-model file or fit.
    #[error(transparent)]
    NoiseModel(Box<crate::allan::noise_model::NoiseModelError>),
    /// Combining replicate logs.
    #[error(transparent)]
    Replicate(Box<crate::allan::replicates::ReplicateError>),
    /// Exporting noise terms to another estimator's configuration.
    #[error(transparent)]
    Export(Box<crate::allan::export::ExportError>),

    // ---- calibration ----
    /// Six-position calibration.
    #[error(transparent)]
    SixPosition(Box<crate::calib::six_position::SixPositionError>),
    /// Multi-position calibration.
    #[error(transparent)]
    Calibration(Box<crate::calib::multi_position::CalibError>),
    /// A least-squares problem without a unique solution.
    #[error(transparent)]
    LeastSquares(Box<crate::calib::lsq::LsqError>),
    /// Finding the static positions of a calibration log.
    #[error(transparent)]
    Segment(Box<crate::calib::segment::SegmentError>),
    /// A calibration model file.
    #[error(transparent)]
    CalibrationFile(Box<crate::calib::model_file::ModelFileError>),

    // ---- thermal calibration ----
    /// A temperature polynomial fit.
    #[error(transparent)]
    ThermalFit(Box<crate::thermal::ThermalFitError>),
    /// A chamber soak session.
    #[error(transparent)]
    Soak(Box<crate::thermal::soak::SoakError>),
    /// A warm-up ramp.
    #[error(transparent)]
    Ramp(Box<crate::thermal::ramp::RampError>),
    /// A thermal model file.
    #[error(transparent)]
    ThermalModel(Box<crate::thermal::model_file::ThermalModelError>),
    /// An autopilot (PX4 / ArduPilot) thermal export.
    #[error(transparent)]
    Autopilot(Box<crate::thermal::autopilot::AutopilotError>),
    /// The real-time compensation kernel's configuration.
    #[error(transparent)]
    Compensation(Box<driftless_model::compensation::CompensationError>),
    /// A block of samples the compensation kernel could not take.
    #[error(transparent)]
    CompensationBlock(Box<driftless_model::compensation::BlockError>),
    /// A thermal polynomial the kernel cannot evaluate.
    #[error(transparent)]
    ThermalPoly(Box<driftless_model::thermal::ThermalPolyError>),

    // ---- navigation ----
    /// The GNSS/INS filter or smoother.
    #[error(transparent)]
    Nav(Box<crate::nav::filter::NavError>),
    /// Preparing IMU and GNSS data for the filter.
    #[error(transparent)]
    Pipeline(Box<crate::nav::pipeline::PipelineError>),
    /// Non-physical IMU samples.
    #[error(transparent)]
    ImuCheck(Box<crate::nav::imu_check::ImuCheckError>),
    /// A navigation configuration.
    #[error(transparent)]
    NavConfig(Box<crate::nav::config::ConfigError>),
    /// A navigation job (its input files).
    #[error(transparent)]
    NavJob(Box<crate::nav::job::NavJobError>),
    /// A KF-GINS job.
    #[error(transparent)]
    KfGinsJob(Box<crate::nav::kfgins_job::KfGinsJobError>),
    /// GNSS outage windows.
    #[error(transparent)]
    Outage(Box<crate::nav::outage::OutageError>),

    // ---- evaluation, experiments, simulation ----
    /// Evaluating a solution against a reference.
    #[error(transparent)]
    Eval(Box<crate::eval::EvalError>),
    /// An experiment (Monte Carlo outage study).
    #[error(transparent)]
    Experiment(Box<crate::experiment::ExperimentError>),
    /// A simulation scenario.
    #[error(transparent)]
    Scenario(Box<crate::sim::scenario::ScenarioError>),
    /// A sensor error model of the simulator.
    #[error(transparent)]
    SensorSim(Box<crate::sim::sensor_error::SensorSimError>),
    /// A noise process of the simulator.
    #[error(transparent)]
    Noise(Box<crate::sim::noise::SimError>),
}

macro_rules! from_stage_errors {
    ($($variant:ident => $ty:ty,)*) => {
        $(impl From<$ty> for Error {
            fn from(e: $ty) -> Error {
                Error::$variant(Box::new(e))
            }
        })*
    };
}

from_stage_errors! {
    Data => crate::data::DataError,
    Log => crate::io::LogError,
    Output => crate::io::output::OutputError,
    TimeBase => crate::io::nav::TimeBaseError,
    Unit => crate::io::units::UnknownUnit,
    Plot => crate::report::plot::PlotError,
    Allan => crate::allan::AllanError,
    NoiseModel => crate::allan::noise_model::NoiseModelError,
    Replicate => crate::allan::replicates::ReplicateError,
    Export => crate::allan::export::ExportError,
    SixPosition => crate::calib::six_position::SixPositionError,
    Calibration => crate::calib::multi_position::CalibError,
    LeastSquares => crate::calib::lsq::LsqError,
    Segment => crate::calib::segment::SegmentError,
    CalibrationFile => crate::calib::model_file::ModelFileError,
    ThermalFit => crate::thermal::ThermalFitError,
    Soak => crate::thermal::soak::SoakError,
    Ramp => crate::thermal::ramp::RampError,
    ThermalModel => crate::thermal::model_file::ThermalModelError,
    Autopilot => crate::thermal::autopilot::AutopilotError,
    Compensation => driftless_model::compensation::CompensationError,
    CompensationBlock => driftless_model::compensation::BlockError,
    ThermalPoly => driftless_model::thermal::ThermalPolyError,
    Nav => crate::nav::filter::NavError,
    Pipeline => crate::nav::pipeline::PipelineError,
    ImuCheck => crate::nav::imu_check::ImuCheckError,
    NavConfig => crate::nav::config::ConfigError,
    NavJob => crate::nav::job::NavJobError,
    KfGinsJob => crate::nav::kfgins_job::KfGinsJobError,
    Outage => crate::nav::outage::OutageError,
    Eval => crate::eval::EvalError,
    Experiment => crate::experiment::ExperimentError,
    Scenario => crate::sim::scenario::ScenarioError,
    SensorSim => crate::sim::sensor_error::SensorSimError,
    Noise => crate::sim::noise::SimError,
}

/// `Result` with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_error_keeps_its_message_and_its_source_chain() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "gone");
        let stage = crate::io::LogError::Io {
            path: "imu.csv".into(),
            error: io,
        };
        let msg = stage.to_string();
        let e: Error = stage.into();
        assert_eq!(e.to_string(), msg);
        let cause = std::error::Error::source(&e).map(|s| s.to_string());
        assert_eq!(cause.as_deref(), Some("gone"));
    }

    #[test]
    fn question_mark_converts_each_stage() {
        fn allan() -> Result<()> {
            let cfg = crate::allan::analysis::AnalysisConfig::default();
            crate::allan::analysis::analyse("x", &[1.0], 0.01, &cfg)?;
            Ok(())
        }
        assert!(matches!(allan(), Err(Error::Allan(_))));
    }
}

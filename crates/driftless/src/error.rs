//! The crate's one error type: every stage's error, so a program using several stages
//! can return [`Result`] and use `?` throughout.
//!
//! Each variant wraps one stage's own error unchanged. `Display` is that error's
//! message and [`std::error::Error::source`] continues its chain (the I/O error under
//! a file read, the parse error under a configuration key), so
//! `anyhow`'s `{:#}` or a loop over `source()` prints every cause. Match on a variant
//! for the stage's detail (file, line, column, time span).

macro_rules! stage_errors {
    ($($(#[$attr:meta])* $variant:ident => $ty:ty,)*) => {
        /// Any error of the library, by stage. Each variant boxes the stage's error (so a
        /// `Result<T, Error>` stays two words wide); `From` takes the stage error unboxed.
        #[derive(Debug, thiserror::Error)]
        #[non_exhaustive]
        pub enum Error {
            $($(#[$attr])* #[error(transparent)] $variant(Box<$ty>),)*
        }
        $(impl From<$ty> for Error {
            fn from(e: $ty) -> Error {
                Error::$variant(Box::new(e))
            }
        })*
    };
}

stage_errors! {
    // ---- data and files ----
    /// Arrays that do not make a valid log or set of fixes.
    Data => crate::data::DataError,
    /// Reading an IMU log (file, line, column).
    Log => crate::io::LogError,
    /// Writing an output file or claiming an output folder.
    Output => crate::io::output::OutputError,
    /// A GNSS or IMU time base that does not fit the data.
    TimeBase => crate::io::nav::TimeBaseError,
    /// A unit string that could not be parsed.
    Unit => crate::io::units::UnknownUnit,
    /// A plot that could not be drawn or written.
    Plot => crate::report::plot::PlotError,

    // ---- noise analysis ----
    /// An Allan-family analysis.
    Allan => crate::allan::AllanError,
    /// A noise-model file or fit.
    NoiseModel => crate::allan::noise_model::NoiseModelError,
    /// Combining replicate logs.
    Replicate => crate::allan::replicates::ReplicateError,
    /// Exporting noise terms to another estimator's configuration.
    Export => crate::allan::export::ExportError,

    // ---- calibration ----
    /// Six-position calibration.
    SixPosition => crate::calib::six_position::SixPositionError,
    /// Multi-position calibration.
    Calibration => crate::calib::multi_position::CalibError,
    /// A least-squares problem without a unique solution.
    LeastSquares => crate::calib::lsq::LsqError,
    /// Finding the static positions of a calibration log.
    Segment => crate::calib::segment::SegmentError,
    /// A calibration model file.
    CalibrationFile => crate::calib::model_file::ModelFileError,

    // ---- thermal calibration ----
    /// A temperature polynomial fit.
    ThermalFit => crate::thermal::ThermalFitError,
    /// A chamber soak session.
    Soak => crate::thermal::soak::SoakError,
    /// A warm-up ramp.
    Ramp => crate::thermal::ramp::RampError,
    /// A thermal model file.
    ThermalModel => crate::thermal::model_file::ThermalModelError,
    /// An autopilot (PX4 / ArduPilot) thermal export.
    Autopilot => crate::thermal::autopilot::AutopilotError,
    /// The real-time compensation kernel's configuration.
    Compensation => driftless_model::compensation::CompensationError,
    /// A block of samples the compensation kernel could not take.
    CompensationBlock => driftless_model::compensation::BlockError,
    /// A thermal polynomial the kernel cannot evaluate.
    ThermalPoly => driftless_model::thermal::ThermalPolyError,

    // ---- navigation ----
    /// The GNSS/INS filter or smoother.
    Nav => crate::nav::filter::NavError,
    /// Preparing IMU and GNSS data for the filter.
    Pipeline => crate::nav::pipeline::PipelineError,
    /// Non-physical IMU samples.
    ImuCheck => crate::nav::imu_check::ImuCheckError,
    /// A navigation configuration.
    NavConfig => crate::nav::config::ConfigError,
    /// A navigation job (its input files).
    NavJob => crate::nav::job::NavJobError,
    /// A KF-GINS job.
    KfGinsJob => crate::nav::kfgins_job::KfGinsJobError,
    /// GNSS outage windows.
    Outage => crate::nav::outage::OutageError,

    // ---- evaluation, experiments, simulation ----
    /// Evaluating a solution against a reference.
    Eval => crate::eval::EvalError,
    /// An experiment (Monte Carlo outage study).
    Experiment => crate::experiment::ExperimentError,
    /// A simulation scenario.
    Scenario => crate::sim::scenario::ScenarioError,
    /// A sensor error model of the simulator.
    SensorSim => crate::sim::sensor_error::SensorSimError,
    /// A noise process of the simulator.
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

//! IMU calibration: static-interval detection, six-position and rate-table
//! calibration (Titterton & Weston; IEEE Std 1293), multi-position calibration without
//! fixtures (Tedaldi, Pretto & Menegatti, ICRA 2014), with parameter uncertainties. The
//! estimated model is [`driftless_model::calib::TriadCalibration`]:
//! calibrated = M · (raw − b).
//!
//! * [`lsq`]: dense linear least squares and Levenberg–Marquardt with covariances.
//! * [`model_file`]: the calibration model file (TOML, with uncertainties).
//! * [`static_detect`]: static-interval detection by moving variance (Tedaldi et al. 2014).
//! * [`multi_position`]: multi-position accelerometer and gyro calibration without
//!   fixtures (Tedaldi et al. 2014).
//! * [`protocol`]: the protocol's axes and positions and its segment manifest (which time
//!   range holds which test at which set temperature).
//! * [`quality`]: χ²/dof, warnings and the plausibility verdict of a fit.
//! * [`segment`]: segmentation of a calibration log from its data (static positions,
//!   rotations, temperature plateaus) into a segment manifest.
//! * [`six_position`]: six-position accelerometer and rate-table gyro calibration with
//!   covariances (Titterton & Weston §8; IEEE Std 1293).

pub mod job;
pub mod lsq;
pub mod model_file;
pub mod multi_position;
pub mod protocol;
pub mod quality;
pub mod segment;
pub mod six_position;
pub mod static_detect;

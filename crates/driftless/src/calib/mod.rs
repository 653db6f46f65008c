//! IMU calibration (issue 5): static-interval detection, six-position and rate-table
//! calibration (Titterton & Weston; IEEE Std 1293), multi-position calibration without
//! fixtures (Tedaldi, Pretto & Menegatti, ICRA 2014), with parameter uncertainties. The
//! estimated model is [`driftless_model::calib::TriadCalibration`]:
//! calibrated = M · (raw − b).
//!
//! * [`lsq`]: dense linear least squares and Levenberg–Marquardt with covariances.
//! * [`model_file`]: the calibration model file (TOML, with uncertainties).

pub mod lsq;
pub mod model_file;

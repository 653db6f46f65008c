//! `driftless-model`: the IMU error model that runs on a device.
//!
//! `no_std`, allocation-free: unit constants, the small 3-vector/3×3 algebra and the
//! thermal polynomial ([`thermal::ThermalPoly`]) shared by the host library (simulation,
//! calibration) and firmware, and the triad calibration `M·(raw − b)`
//! ([`calib::TriadCalibration`]), and the real-time thermal compensation kernel
//! ([`compensation::CompensationModel`]).
#![no_std]
#![forbid(unsafe_code)]

pub mod calib;
pub mod compensation;
pub mod linalg;
pub mod thermal;
pub mod units;

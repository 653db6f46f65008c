//! `driftless-model`: the IMU error model that runs on a device.
//!
//! `no_std`, allocation-free: unit constants, the small 3-vector/3×3 algebra and the
//! thermal polynomial ([`thermal::ThermalPoly`]) shared by the host library (simulation,
//! calibration) and firmware; the compensation kernel (bias, scale factor, misalignment)
//! lands with the calibration and thermal issues.
#![no_std]
#![forbid(unsafe_code)]

pub mod linalg;
pub mod thermal;
pub mod units;

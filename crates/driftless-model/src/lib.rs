//! `driftless-model`: the IMU error model that runs on a device.
//!
//! `no_std`, allocation-free: unit constants and the small 3-vector/3×3 algebra shared by
//! the host library and firmware; the compensation kernel (bias, scale factor,
//! misalignment, thermal polynomials) lands with the calibration and thermal issues.
#![no_std]
#![forbid(unsafe_code)]

pub mod linalg;
pub mod units;

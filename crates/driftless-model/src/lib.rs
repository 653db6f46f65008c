//! `driftless-model`: the IMU error model that runs on a device.
//!
//! `no_std`, allocation-free. Issue 2 only needs the unit constants shared by the
//! host library and firmware; the compensation kernel (bias, scale factor,
//! misalignment, thermal polynomials) lands with the calibration and thermal issues.
#![no_std]
#![forbid(unsafe_code)]

pub mod units;

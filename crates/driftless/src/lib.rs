//! `driftless`: from raw MEMS IMU logs to a navigation error budget.
//!
//! Data flows one way: [`io`] readers → typed columnar logs ([`io::log`]) →
//! algorithms ([`allan`], …) → results → writers and [`report`]s.
//! Algorithms never parse files; readers never do math.
//!
//! Conventions: SI inside (s, m, rad, m/s, m/s², rad/s, °C). Display/file units
//! (deg/h, deg/√h, mg, g …) are converted at the edges only.
// One audited exception: the AVX2 dispatch of the Allan kernel (allan::estimators).
#![deny(unsafe_code)]

pub mod allan;
pub mod calib;
pub mod eval;
pub mod experiment;
pub mod io;
pub mod nav;
pub mod report;
pub mod sim;
pub mod thermal;

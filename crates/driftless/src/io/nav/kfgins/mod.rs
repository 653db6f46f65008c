//! KF-GINS text formats (i2Nav-WHU/KF-GINS, GPL-3.0). Formats learnt from its README
//! ("2.2 Data format"), `src/fileio/{fileloader.cc,imufileloader.h,gnssfileloader.h,
//! filesaver.cc}` and `src/kf_gins.cpp`; no code taken.
//!
//! **Input files.** One epoch per line; fields separated by any run of spaces, tabs or
//! commas (KF-GINS splits on `", \t"` and skips empty pieces). No header, no comments.
//! KF-GINS feeds every field to `strtod` without checks; here every field must be a finite
//! number, every row must have as many fields as the reference row (the first, unless it is
//! shorter than the rows after it; see `io::edge`), and time must strictly increase —
//! otherwise one [`LogError`] names the file, line and column. Blank lines are skipped
//! (KF-GINS stops reading at the first blank line). A truncated first or last record (fewer
//! fields than the reference row, or a cut field that is not a number: what a logger that
//! starts or stops mid-line leaves) is dropped and reported in the result's `notes`.
//!
//! * IMU (`imupath`): `time [GPS s of week], dθx, dθy, dθz [rad], dvx, dvy, dvz [m/s]`,
//!   increments over the interval ending at `time`, body frame forward-right-down. KF-GINS
//!   reads `imudatalen` ≥ 7 columns and uses the first 7 (an 8th is an odometer speed,
//!   m/s); extra columns are accepted and ignored here too.
//! * GNSS (`gnsspath`): 7 columns `time [s], lat [deg], lon [deg], h [m], σN, σE, σD [m]`,
//!   or 13 columns, which KF-GINS's loader reads as `time, lat, lon, h, vN, vE, vD [m/s],
//!   σN, σE, σD [m], σvN, σvE, σvD [m/s]` (it takes σ from columns 8–10 of a 13-column file;
//!   the velocity meaning of columns 5–7 and 11–13 follows its comment "13-column GNSS
//!   files contain GNSS velocity").
//!
//! **Output files** (written by `kf_gins.cpp` into `outputpath`): every value printed with
//! C's `"%-15.9lf "` (left-aligned, width 15, 9 decimals, one space after), lines ending
//! in `\n`:
//! * `KF_GINS_Navresult.nav`: `week, time [s], lat [deg], lon [deg], h [m], vN, vE, vD
//!   [m/s], roll, pitch, yaw [deg]` — KF-GINS always writes 0 as the week, and yaw in
//!   \[0°, 360°) ([`kfgins_heading_rad`]; the writers here write the yaw they are given).
//! * `KF_GINS_IMU_ERR.txt`: `time, gyro bias xyz [deg/h], accel bias xyz [mGal], gyro
//!   scale xyz [ppm], accel scale xyz [ppm]`.
//! * `KF_GINS_STD.txt`: `time, pos NED [m], vel NED [m/s], att [deg], gyro bias [deg/h],
//!   accel bias [mGal], gyro scale [ppm], accel scale [ppm]` (22 columns).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::types::{GnssFixes, ImuErrors, ImuIncrements, NavSolution, NavStd, common_len};
use super::{
    Field, as_utf8, check_time_order, parse_num, read_text_file, read_text_file_parallel,
    split_fields, split_fields_into,
};
use crate::io::edge::{
    Edge, REFERENCE_SAMPLE, cut_record, last_data_line, line_of_offset, note, reference_count,
};
use crate::io::output::AtomicFile;
use crate::io::{Location, LogError};

/// Field separators of KF-GINS's text loader.
const SEPS: &[u8] = b", \t\r";

/// Degrees per radian.
const R2D: f64 = 180.0 / std::f64::consts::PI;
/// 1 mGal = 1e-5 m/s².
const MGAL_PER_M_S2: f64 = 1e5;
/// 1 ppm = 1e-6.
const PPM: f64 = 1e6;

/// File names KF-GINS writes into `outputpath`.
pub(crate) const NAV_FILE: &str = "KF_GINS_Navresult.nav";
/// IMU-error file name.
pub(crate) const IMU_ERR_FILE: &str = "KF_GINS_IMU_ERR.txt";
/// State-std file name.
pub(crate) const STD_FILE: &str = "KF_GINS_STD.txt";

/// What a GNSS reader does with a standard deviation of zero.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum ZeroSigma {
    /// σ = 0 is an error naming the field (default): a zero σ makes a measurement
    /// infinitely trusted, which a Kalman filter cannot digest.
    #[default]
    Error,
    /// Replace σ below the floor (zero included) by the floor; negative σ is still an error.
    Floor {
        /// Floor for position σ, m (must be > 0).
        pos_m: f64,
        /// Floor for velocity σ, m/s (must be > 0).
        vel_m_s: f64,
    },
}

/// Options of the GNSS readers (KF-GINS and RTKLIB).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct GnssReadOptions {
    /// Handling of σ = 0.
    pub zero_sigma: ZeroSigma,
}

/// Applies the σ policy to one σ value.
pub(crate) fn check_sigma(
    v: f64,
    vel: bool,
    opts: &GnssReadOptions,
    at: Location,
    name: &str,
) -> Result<f64, LogError> {
    if v < 0.0 {
        return Err(LogError::InvalidValue {
            at,
            message: format!("negative standard deviation {v} in column {name}"),
        });
    }
    match opts.zero_sigma {
        ZeroSigma::Error if v == 0.0 => Err(LogError::InvalidValue {
            at,
            message: format!(
                "standard deviation 0 in column {name}: a zero σ would make the fix infinitely trusted; set a σ floor (ZeroSigma::Floor) to accept it"
            ),
        }),
        ZeroSigma::Error => Ok(v),
        ZeroSigma::Floor { pos_m, vel_m_s } => {
            let floor = if vel { vel_m_s } else { pos_m };
            if !(floor > 0.0 && floor.is_finite()) {
                return Err(LogError::InvalidOptions {
                    at: Location::input(&at.path),
                    message: format!("σ floor must be finite and > 0, got {floor}"),
                });
            }
            Ok(v.max(floor))
        }
    }
}

/// Checks latitude and longitude ranges (degrees) of one epoch.
pub(crate) fn check_lat_lon(
    lat_deg: f64,
    lon_deg: f64,
    path: &str,
    line: usize,
    lat_f: Field<'_>,
    lon_f: Field<'_>,
) -> Result<(), LogError> {
    if !(-90.0..=90.0).contains(&lat_deg) {
        return Err(LogError::InvalidValue {
            at: Location::field(path, line, lat_f.col),
            message: format!("latitude {lat_deg} deg outside [-90, 90]"),
        });
    }
    if !(-360.0..=360.0).contains(&lon_deg) {
        return Err(LogError::InvalidValue {
            at: Location::field(path, line, lon_f.col),
            message: format!("longitude {lon_deg} deg outside [-360, 360]"),
        });
    }
    Ok(())
}

mod line;
mod output;
mod read;
#[cfg(test)]
mod tests;
mod write;

pub use output::*;
pub use read::*;
pub use write::*;

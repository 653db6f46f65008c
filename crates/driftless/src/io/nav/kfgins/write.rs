//! Writers of KF-GINS's IMU and GNSS input files.

use super::line::*;
use super::*;

/// The error of a value that is not finite in row `row` (0-based), column `col` (0-based).
pub(super) fn non_finite(name: &str, v: f64, row: usize, col: usize) -> LogError {
    LogError::InvalidLog {
        at: Location::input(name),
        message: format!("non-finite value {v} in row {row}, column {}", col + 1),
    }
}

/// Writes `n` rows of values (`row(i)`) after checking that every value is finite;
/// `first_row` numbers the rows in error messages. The rows go through a [`LineBuf`]
/// kept per thread between calls (a fresh one per block of rows would be page-faulted and
/// zeroed by the kernel anew), handed to `w` in chunks of [`CHUNK`] bytes (a `BufWriter`
/// of at most that capacity passes them straight through). Does not flush.
pub(super) fn write_rows<const N: usize>(
    w: &mut impl Write,
    name: &str,
    n: usize,
    first_row: usize,
    row: impl Fn(usize) -> [f64; N],
) -> Result<(), LogError> {
    thread_local! {
        static SCRATCH: std::cell::Cell<Option<Box<LineBuf>>> = const { std::cell::Cell::new(None) };
    }
    let mut buf = SCRATCH.take().unwrap_or_else(|| Box::new(LineBuf::new()));
    buf.pos = 0;
    let mut r = Ok(());
    for i in 0..n {
        let vals = row(i);
        if let Err(k) = buf.line(&vals) {
            r = Err(non_finite(name, vals[k], first_row + i, k));
            break;
        }
        if buf.is_full() {
            r = buf.drain_to(w, name);
            if r.is_err() {
                break;
            }
        }
    }
    if r.is_ok() {
        r = buf.drain_to(w, name);
    }
    buf.pos = 0;
    SCRATCH.set(Some(buf));
    r
}

pub(super) fn io_error(name: &str, error: std::io::Error) -> LogError {
    LogError::Io {
        path: name.to_owned(),
        error,
    }
}

pub(super) fn lens_err(name: &str, message: String) -> LogError {
    LogError::InvalidLog {
        at: Location::input(name),
        message,
    }
}

/// Writes increments as a KF-GINS IMU input file: `time [s], dθ xyz [rad], dv xyz [m/s]`,
/// space separated, time to 1 µs and increments with 13 significant digits (the `.nav`
/// output format's 9 decimals would cut 1e-5 rad increments to 4 digits).
pub fn write_kfgins_imu(
    mut w: impl Write,
    name: &str,
    imu: &ImuIncrements,
) -> Result<(), LogError> {
    let n = common_len(&[
        ("time_s", imu.time_s.len()),
        ("dtheta_rad", imu.dtheta_rad.len()),
        ("dvel_m_s", imu.dvel_m_s.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    let io_err = |error| LogError::Io {
        path: name.to_owned(),
        error,
    };
    for i in 0..n {
        let (a, b) = (imu.dtheta_rad[i], imu.dvel_m_s[i]);
        let vals = [imu.time_s[i], a[0], a[1], a[2], b[0], b[1], b[2]];
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: format!("non-finite value {v} in row {i}"),
            });
        }
        writeln!(
            w,
            "{:.6} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}",
            vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6]
        )
        .map_err(io_err)?;
    }
    w.flush().map_err(io_err)
}

/// Writes fixes as a 7-column KF-GINS GNSS input file: `time [s], lat, lon [deg], h [m],
/// σN, σE, σD [m]`.
pub fn write_kfgins_gnss(mut w: impl Write, name: &str, g: &GnssFixes) -> Result<(), LogError> {
    let n = common_len(&[
        ("time_s", g.time_s.len()),
        ("lat_rad", g.lat_rad.len()),
        ("lon_rad", g.lon_rad.len()),
        ("height_m", g.height_m.len()),
        ("sigma_ned_m", g.sigma_ned_m.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    let io_err = |error| LogError::Io {
        path: name.to_owned(),
        error,
    };
    for i in 0..n {
        let s = g.sigma_ned_m[i];
        let vals = [
            g.time_s[i],
            g.lat_rad[i] * R2D,
            g.lon_rad[i] * R2D,
            g.height_m[i],
            s[0],
            s[1],
            s[2],
        ];
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(LogError::InvalidLog {
                at: Location::input(name),
                message: format!("non-finite value {v} in row {i}"),
            });
        }
        writeln!(
            w,
            "{:.6} {:.11} {:.11} {:.4} {:.4} {:.4} {:.4}",
            vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6]
        )
        .map_err(io_err)?;
    }
    w.flush().map_err(io_err)
}

#[cfg(test)]
mod input_writer_tests {
    use super::*;

    #[test]
    fn imu_and_gnss_writers_round_trip_through_the_readers() {
        let imu = ImuIncrements {
            time_s: vec![100.005, 100.010],
            dtheta_rad: vec![[1.234_567_890_123e-5, -2e-6, 3e-7], [4e-5, 5e-5, -6e-5]],
            dvel_m_s: vec![[0.049_031, 1e-4, -2e-4], [0.05, 0.0, 0.001]],
            notes: Vec::new(),
        };
        let mut buf = Vec::new();
        write_kfgins_imu(&mut buf, "imu.txt", &imu).unwrap();
        let back = read_kfgins_imu(&buf, "imu.txt").unwrap();
        for i in 0..2 {
            assert!((back.time_s[i] - imu.time_s[i]).abs() < 1e-9);
            for k in 0..3 {
                assert!(
                    (back.dtheta_rad[i][k] - imu.dtheta_rad[i][k]).abs()
                        <= 1e-12 * imu.dtheta_rad[i][k].abs()
                );
                assert!(
                    (back.dvel_m_s[i][k] - imu.dvel_m_s[i][k]).abs()
                        <= 1e-12 * imu.dvel_m_s[i][k].abs()
                );
            }
        }
        let g = GnssFixes {
            time_s: vec![101.0, 102.0],
            lat_rad: vec![0.5, 0.500_001],
            lon_rad: vec![2.0, 2.000_001],
            height_m: vec![20.0, 20.5],
            sigma_ned_m: vec![[0.02, 0.02, 0.04]; 2],
            quality: vec![0; 2],
            ..GnssFixes::default()
        };
        let mut buf = Vec::new();
        write_kfgins_gnss(&mut buf, "gnss.txt", &g).unwrap();
        let back = read_kfgins_gnss(&buf, "gnss.txt", &GnssReadOptions::default()).unwrap();
        for i in 0..2 {
            // 11 decimals of a degree ≈ 1 µm on the ground
            assert!((back.lat_rad[i] - g.lat_rad[i]).abs() < 1e-12);
            assert!((back.lon_rad[i] - g.lon_rad[i]).abs() < 1e-12);
            assert_eq!(back.sigma_ned_m[i], g.sigma_ned_m[i]);
        }
    }
}

//! Validated constructors of the in-memory types from plain arrays.

use super::imu::{Channel, ImuLog, Quantity};
use super::nav::{GnssFixes, quality};

/// Why arrays do not make a valid log or set of fixes. Every variant names the column
/// and the row.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DataError {
    /// Columns of different lengths.
    #[error("{what}: column {column} has {len} rows but time has {expected}")]
    Length {
        /// What was being built.
        what: &'static str,
        /// The column.
        column: &'static str,
        /// Its length.
        len: usize,
        /// The length of the time column.
        expected: usize,
    },
    /// Too few rows to be used.
    #[error("{what}: {len} row(s); at least {min} are needed")]
    TooShort {
        /// What was being built.
        what: &'static str,
        /// Rows given.
        len: usize,
        /// Rows needed.
        min: usize,
    },
    /// A value that is NaN or infinite.
    #[error("{what}: {column} at row {row} is {value}, not a finite number")]
    NonFinite {
        /// What was being built.
        what: &'static str,
        /// The column.
        column: &'static str,
        /// Row index (0-based).
        row: usize,
        /// The value.
        value: f64,
    },
    /// Time that does not increase.
    #[error(
        "{what}: time does not increase at row {row} ({prev} s then {time_s} s); sort the rows and drop duplicates"
    )]
    NotIncreasing {
        /// What was being built.
        what: &'static str,
        /// Row index (0-based) of the second stamp.
        row: usize,
        /// The stamp before it, s.
        prev: f64,
        /// The stamp, s.
        time_s: f64,
    },
    /// A value outside its physical range.
    #[error("{what}: {column} at row {row} is {value}: {reason}")]
    OutOfRange {
        /// What was being built.
        what: &'static str,
        /// The column.
        column: &'static str,
        /// Row index (0-based).
        row: usize,
        /// The value.
        value: f64,
        /// The allowed range.
        reason: &'static str,
    },
}

fn check_len(
    what: &'static str,
    column: &'static str,
    len: usize,
    n: usize,
) -> Result<(), DataError> {
    if len == n {
        Ok(())
    } else {
        Err(DataError::Length {
            what,
            column,
            len,
            expected: n,
        })
    }
}

fn check_finite<'a>(
    what: &'static str,
    column: &'static str,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), DataError> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((row, &value)) => Err(DataError::NonFinite {
            what,
            column,
            row,
            value,
        }),
        None => Ok(()),
    }
}

/// [`check_finite`] of rows of three, naming the row.
fn check_finite_rows(
    what: &'static str,
    column: &'static str,
    rows: &[[f64; 3]],
) -> Result<(), DataError> {
    match rows.iter().flatten().position(|v| !v.is_finite()) {
        Some(k) => Err(DataError::NonFinite {
            what,
            column,
            row: k / 3,
            value: rows[k / 3][k % 3],
        }),
        None => Ok(()),
    }
}

fn check_increasing(what: &'static str, time_s: &[f64]) -> Result<(), DataError> {
    check_finite(what, "time_s", time_s)?;
    match time_s.windows(2).position(|w| w[1] <= w[0]) {
        Some(k) => Err(DataError::NotIncreasing {
            what,
            row: k + 1,
            prev: time_s[k],
            time_s: time_s[k + 1],
        }),
        None => Ok(()),
    }
}

impl ImuLog {
    /// A log of rates from arrays: time stamps `time_s` (s, strictly increasing), gyro
    /// `gyro_rad_s` and specific force `accel_m_s2` (body x, y, z per row). Channels are
    /// named `gyro_x … acc_z`; τ0 is the median time-stamp interval.
    ///
    /// Errors ([`DataError`]): fewer than two rows, columns of different lengths, a value
    /// that is not finite, time that does not increase.
    pub fn from_rates(
        source: impl Into<String>,
        time_s: Vec<f64>,
        gyro_rad_s: &[[f64; 3]],
        accel_m_s2: &[[f64; 3]],
    ) -> Result<ImuLog, DataError> {
        const WHAT: &str = "IMU log";
        let n = time_s.len();
        if n < 2 {
            return Err(DataError::TooShort {
                what: WHAT,
                len: n,
                min: 2,
            });
        }
        check_len(WHAT, "gyro_rad_s", gyro_rad_s.len(), n)?;
        check_len(WHAT, "accel_m_s2", accel_m_s2.len(), n)?;
        check_increasing(WHAT, &time_s)?;
        check_finite_rows(WHAT, "gyro_rad_s", gyro_rad_s)?;
        check_finite_rows(WHAT, "accel_m_s2", accel_m_s2)?;
        let column = |name: &str, quantity: Quantity, rows: &[[f64; 3]], k: usize| Channel {
            name: name.to_owned(),
            quantity,
            source_unit: quantity.si_unit().to_owned(),
            values: rows.iter().map(|r| r[k]).collect(),
        };
        let channels = vec![
            column("gyro_x", Quantity::AngularRate, gyro_rad_s, 0),
            column("gyro_y", Quantity::AngularRate, gyro_rad_s, 1),
            column("gyro_z", Quantity::AngularRate, gyro_rad_s, 2),
            column("acc_x", Quantity::SpecificForce, accel_m_s2, 0),
            column("acc_y", Quantity::SpecificForce, accel_m_s2, 1),
            column("acc_z", Quantity::SpecificForce, accel_m_s2, 2),
        ];
        // τ0: the (upper) median time-stamp interval; n ≥ 2 rows give at least one.
        let mut intervals: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
        let tau0_s = crate::numeric::order::upper_median(&mut intervals).unwrap_or(f64::NAN);
        Ok(ImuLog::new(source, Some(time_s), tau0_s, channels))
    }

    /// Adds a temperature channel `temp` (°C, one value per row, finite).
    pub fn with_temperature_c(mut self, temp_c: Vec<f64>) -> Result<ImuLog, DataError> {
        const WHAT: &str = "IMU log";
        check_len(WHAT, "temp_c", temp_c.len(), self.len())?;
        check_finite(WHAT, "temp_c", &temp_c)?;
        self.channels.push(Channel {
            name: "temp".to_owned(),
            quantity: Quantity::Temperature,
            source_unit: Quantity::Temperature.si_unit().to_owned(),
            values: temp_c,
        });
        Ok(self)
    }
}

impl GnssFixes {
    /// Position fixes from arrays: GPS time `time_s` (s of week, strictly increasing),
    /// geodetic latitude and longitude (rad), ellipsoidal height (m) and the σ north,
    /// east, down of each fix (m, > 0). No quality flags, no velocity: add velocity with
    /// [`GnssFixes::with_velocity`].
    ///
    /// Errors ([`DataError`]): no rows, columns of different lengths, a value that is not
    /// finite, time that does not increase, a latitude outside ±π/2, a σ that is not > 0.
    pub fn new(
        time_s: Vec<f64>,
        lat_rad: Vec<f64>,
        lon_rad: Vec<f64>,
        height_m: Vec<f64>,
        sigma_ned_m: Vec<[f64; 3]>,
    ) -> Result<GnssFixes, DataError> {
        let fixes = GnssFixes {
            quality: vec![quality::UNSPECIFIED; time_s.len()],
            time_s,
            lat_rad,
            lon_rad,
            height_m,
            sigma_ned_m,
            ..GnssFixes::default()
        };
        fixes.validate()?;
        Ok(fixes)
    }

    /// Adds velocity north, east, down (m/s) and its σ (m/s, > 0) to every fix.
    pub fn with_velocity(
        mut self,
        vel_ned_m_s: Vec<[f64; 3]>,
        sigma_vel_ned_m_s: Vec<[f64; 3]>,
    ) -> Result<GnssFixes, DataError> {
        self.vel_ned_m_s = Some(vel_ned_m_s);
        self.sigma_vel_ned_m_s = Some(sigma_vel_ned_m_s);
        self.validate()?;
        Ok(self)
    }

    /// Checks what the filter relies on: equal column lengths, finite values, strictly
    /// increasing time, |latitude| ≤ π/2 and σ > 0. Readers produce fixes that pass;
    /// call it after building or editing the columns by hand.
    pub fn validate(&self) -> Result<(), DataError> {
        const WHAT: &str = "GNSS fixes";
        let n = self.time_s.len();
        if n == 0 {
            return Err(DataError::TooShort {
                what: WHAT,
                len: 0,
                min: 1,
            });
        }
        check_len(WHAT, "lat_rad", self.lat_rad.len(), n)?;
        check_len(WHAT, "lon_rad", self.lon_rad.len(), n)?;
        check_len(WHAT, "height_m", self.height_m.len(), n)?;
        check_len(WHAT, "sigma_ned_m", self.sigma_ned_m.len(), n)?;
        check_len(WHAT, "quality", self.quality.len(), n)?;
        if let Some(s) = &self.n_sats {
            check_len(WHAT, "n_sats", s.len(), n)?;
        }
        check_increasing(WHAT, &self.time_s)?;
        check_finite(WHAT, "lat_rad", &self.lat_rad)?;
        check_finite(WHAT, "lon_rad", &self.lon_rad)?;
        check_finite(WHAT, "height_m", &self.height_m)?;
        if let Some(row) = self
            .lat_rad
            .iter()
            .position(|l| l.abs() > std::f64::consts::FRAC_PI_2)
        {
            return Err(DataError::OutOfRange {
                what: WHAT,
                column: "lat_rad",
                row,
                value: self.lat_rad[row],
                reason: "latitude must lie within ±π/2 rad (give radians, not degrees)",
            });
        }
        let positive = |column: &'static str, rows: &[[f64; 3]]| {
            check_finite_rows(WHAT, column, rows)?;
            match rows.iter().flatten().position(|s| *s <= 0.0) {
                Some(k) => Err(DataError::OutOfRange {
                    what: WHAT,
                    column,
                    row: k / 3,
                    value: rows[k / 3][k % 3],
                    reason: "a σ must be > 0",
                }),
                None => Ok(()),
            }
        };
        positive("sigma_ned_m", &self.sigma_ned_m)?;
        match (&self.vel_ned_m_s, &self.sigma_vel_ned_m_s) {
            (Some(v), Some(s)) => {
                check_len(WHAT, "vel_ned_m_s", v.len(), n)?;
                check_len(WHAT, "sigma_vel_ned_m_s", s.len(), n)?;
                check_finite_rows(WHAT, "vel_ned_m_s", v)?;
                positive("sigma_vel_ned_m_s", s)?;
            }
            (None, None) => {}
            (Some(_), None) => check_len(WHAT, "sigma_vel_ned_m_s", 0, n)?,
            (None, Some(_)) => check_len(WHAT, "vel_ned_m_s", 0, n)?,
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_imu_log_from_arrays_is_checked_and_named() {
        let t = vec![0.0, 0.01, 0.02];
        let g = [[0.0, 0.0, 1e-3]; 3];
        let f = [[0.0, 0.0, -9.8]; 3];
        let log = ImuLog::from_rates("mem", t.clone(), &g, &f).unwrap();
        assert_eq!(log.len(), 3);
        assert!((log.tau0_s - 0.01).abs() < 1e-15);
        assert_eq!(
            log.triad_of(Quantity::SpecificForce).unwrap()[2],
            &[-9.8; 3]
        );
        let log = log.with_temperature_c(vec![20.0, 20.1, 20.2]).unwrap();
        assert_eq!(log.indices_of(Quantity::Temperature), vec![6]);

        let e = ImuLog::from_rates("mem", vec![0.0, 0.01, 0.01], &g, &f).unwrap_err();
        assert!(e.to_string().contains("row 2"), "{e}");
        let mut bad = g;
        bad[1][0] = f64::NAN;
        let e = ImuLog::from_rates("mem", t.clone(), &bad, &f).unwrap_err();
        assert!(matches!(e, DataError::NonFinite { row: 1, .. }), "{e}");
        let e = ImuLog::from_rates("mem", t, &g[..2], &f).unwrap_err();
        assert!(e.to_string().contains("gyro_rad_s has 2 rows"), "{e}");
    }

    #[test]
    fn gnss_fixes_from_arrays_are_checked() {
        let n = 3;
        let fixes = |lat: f64, sigma: f64| {
            GnssFixes::new(
                vec![1.0, 2.0, 3.0],
                vec![lat; n],
                vec![0.2; n],
                vec![10.0; n],
                vec![[sigma; 3]; n],
            )
        };
        let ok = fixes(0.5, 0.1).unwrap();
        assert_eq!(ok.quality, vec![quality::UNSPECIFIED; n]);
        let e = fixes(45.0, 0.1).unwrap_err();
        assert!(e.to_string().contains("not degrees"), "{e}");
        let e = fixes(0.5, 0.0).unwrap_err();
        assert!(
            matches!(
                e,
                DataError::OutOfRange {
                    column: "sigma_ned_m",
                    ..
                }
            ),
            "{e}"
        );
        let e = ok
            .clone()
            .with_velocity(vec![[0.0; 3]; 2], vec![[0.1; 3]; 2])
            .unwrap_err();
        assert!(e.to_string().contains("vel_ned_m_s has 2 rows"), "{e}");
        let v = ok.with_velocity(vec![[1.0, 0.0, 0.0]; n], vec![[0.05; 3]; n]);
        assert!(v.is_ok());
    }
}

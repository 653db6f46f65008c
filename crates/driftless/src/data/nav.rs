//! Typed, columnar in-memory navigation records. SI units throughout; every field name
//! carries its unit. Angles in radians; navigation frame north-east-down (NED); body frame
//! forward-right-down (the frames KF-GINS uses).

/// RTKLIB solution quality flags (`Q` column of a `.pos` file).
pub mod quality {
    /// No quality flag in the input (KF-GINS GNSS files carry none). RTKLIB itself uses 0
    /// for "no solution", which never appears as an epoch in a `.pos` file.
    pub const UNSPECIFIED: u8 = 0;
    /// Fixed integer-ambiguity RTK.
    pub const FIX: u8 = 1;
    /// Float RTK.
    pub const FLOAT: u8 = 2;
    /// SBAS-corrected.
    pub const SBAS: u8 = 3;
    /// Code-differential (DGPS/DGNSS).
    pub const DGPS: u8 = 4;
    /// Single point positioning.
    pub(crate) const SINGLE: u8 = 5;
    /// Precise point positioning.
    pub const PPP: u8 = 6;
}

/// IMU output as increments per epoch (the KF-GINS IMU format): the angle and velocity
/// increments accumulated over the interval that ends at `time_s[i]`, in the body frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuIncrements {
    /// End of each interval, s (KF-GINS: GPS seconds of week).
    pub time_s: Vec<f64>,
    /// Angle increments about body x, y, z, rad.
    pub dtheta_rad: Vec<[f64; 3]>,
    /// Velocity increments along body x, y, z, m/s.
    pub dvel_m_s: Vec<[f64; 3]>,
    /// What the reader dropped and why (a truncated first or last record), one message
    /// per item naming file and line. Empty when nothing was dropped.
    pub notes: Vec<String>,
}

impl ImuIncrements {
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    /// True when there are no epochs.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
}

/// GNSS position (and optionally velocity) fixes, one entry per epoch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GnssFixes {
    /// GPS week of `time_s`, when the input names it (RTKLIB `.pos`); `None` for inputs
    /// that carry seconds of week only (KF-GINS).
    pub gps_week: Option<u16>,
    /// GPS time, s: seconds of week `gps_week` (values pass 604 800 s when a file
    /// crosses into the next week, so the column stays increasing).
    pub time_s: Vec<f64>,
    /// Geodetic latitude (WGS-84 in both supported formats), rad.
    pub lat_rad: Vec<f64>,
    /// Geodetic longitude, rad.
    pub lon_rad: Vec<f64>,
    /// Ellipsoidal height, m.
    pub height_m: Vec<f64>,
    /// Position standard deviation north, east, down, m (always > 0 after reading; see
    /// [`crate::io::nav::ZeroSigma`]).
    pub sigma_ned_m: Vec<[f64; 3]>,
    /// Velocity north, east, down, m/s, when the input has velocity columns.
    pub vel_ned_m_s: Option<Vec<[f64; 3]>>,
    /// Velocity standard deviation north, east, down, m/s, with `vel_ned_m_s`.
    pub sigma_vel_ned_m_s: Option<Vec<[f64; 3]>>,
    /// RTKLIB quality flag per epoch (see [`quality`]): 1 fix, 2 float, 3 SBAS, 4 DGPS,
    /// 5 single, 6 PPP; [`quality::UNSPECIFIED`] when the input has none.
    pub quality: Vec<u8>,
    /// Number of satellites used, when the input has it.
    pub n_sats: Option<Vec<u8>>,
    /// What the reader dropped and why (a truncated first or last record), one message
    /// per item naming file and line. Empty when nothing was dropped.
    pub notes: Vec<String>,
}

impl GnssFixes {
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    /// True when there are no epochs.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
}

/// A navigation solution (output of a filter or smoother), one entry per epoch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NavSolution {
    /// GPS seconds of week, s.
    pub time_s: Vec<f64>,
    /// Geodetic latitude, rad.
    pub lat_rad: Vec<f64>,
    /// Geodetic longitude, rad.
    pub lon_rad: Vec<f64>,
    /// Ellipsoidal height, m.
    pub height_m: Vec<f64>,
    /// Velocity north, east, down, m/s.
    pub vel_ned_m_s: Vec<[f64; 3]>,
    /// Attitude of the body frame relative to NED as Euler angles roll, pitch, yaw
    /// (ZYX rotation order), rad.
    pub roll_pitch_yaw_rad: Vec<[f64; 3]>,
}

impl NavSolution {
    /// Append one epoch (every column grows by one).
    pub(crate) fn push_epoch(
        &mut self,
        time_s: f64,
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        vel_ned_m_s: [f64; 3],
        roll_pitch_yaw_rad: [f64; 3],
    ) {
        self.time_s.push(time_s);
        self.lat_rad.push(lat_rad);
        self.lon_rad.push(lon_rad);
        self.height_m.push(height_m);
        self.vel_ned_m_s.push(vel_ned_m_s);
        self.roll_pitch_yaw_rad.push(roll_pitch_yaw_rad);
    }
}

/// Estimated IMU errors per epoch (KF-GINS's `KF_GINS_IMU_ERR.txt` content), SI.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuErrors {
    /// GPS seconds of week, s.
    pub time_s: Vec<f64>,
    /// Gyroscope bias x, y, z, rad/s.
    pub gyro_bias_rad_s: Vec<[f64; 3]>,
    /// Accelerometer bias x, y, z, m/s².
    pub accel_bias_m_s2: Vec<[f64; 3]>,
    /// Gyroscope scale-factor error x, y, z, dimensionless (1e-6 = 1 ppm).
    pub gyro_scale: Vec<[f64; 3]>,
    /// Accelerometer scale-factor error x, y, z, dimensionless.
    pub accel_scale: Vec<[f64; 3]>,
}

/// Standard deviations of the 21 filter states per epoch (KF-GINS's `KF_GINS_STD.txt`
/// content), SI.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NavStd {
    /// GPS seconds of week, s.
    pub time_s: Vec<f64>,
    /// Position north, east, down, m.
    pub pos_ned_m: Vec<[f64; 3]>,
    /// Velocity north, east, down, m/s.
    pub vel_ned_m_s: Vec<[f64; 3]>,
    /// Attitude roll, pitch, yaw (KF-GINS: the φ-angle error components), rad.
    pub att_rad: Vec<[f64; 3]>,
    /// Gyroscope bias x, y, z, rad/s.
    pub gyro_bias_rad_s: Vec<[f64; 3]>,
    /// Accelerometer bias x, y, z, m/s².
    pub accel_bias_m_s2: Vec<[f64; 3]>,
    /// Gyroscope scale factor x, y, z, dimensionless.
    pub gyro_scale: Vec<[f64; 3]>,
    /// Accelerometer scale factor x, y, z, dimensionless.
    pub accel_scale: Vec<[f64; 3]>,
}

/// Checks that all column lengths equal the first; returns the common length or a message.
pub(crate) fn common_len(lens: &[(&str, usize)]) -> Result<usize, String> {
    let Some(&(first_name, n)) = lens.first() else {
        return Ok(0);
    };
    for &(name, len) in &lens[1..] {
        if len != n {
            return Err(format!(
                "column {name} has {len} entries but {first_name} has {n}"
            ));
        }
    }
    Ok(n)
}

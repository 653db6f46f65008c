//! Writers of KF-GINS's output files (navigation result, IMU errors, state σ).

use super::line::*;
use super::*;

/// Writes a navigation solution in KF-GINS's `.nav` format (11 columns, see the module
/// docs); `gps_week` goes into column 1 (KF-GINS itself always writes 0).
pub fn write_kfgins_nav(
    mut w: impl Write,
    name: &str,
    sol: &NavSolution,
    gps_week: u16,
) -> Result<(), LogError> {
    append_nav(&mut w, name, sol, gps_week, 0)?;
    w.flush().map_err(|e| io_error(name, e))
}

/// One row of KF-GINS's three output files in SI units (angles in rad, as the column
/// structs [`NavSolution`], [`ImuErrors`] and [`NavStd`] hold them); the writers convert to
/// the files' units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KfGinsRow {
    /// GPS seconds of week, s.
    pub time_s: f64,
    /// Geodetic latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// Velocity north, east, down, m/s.
    pub vel_ned_m_s: [f64; 3],
    /// Roll, pitch, yaw, rad (written as given; KF-GINS's yaw range is
    /// [`kfgins_heading_rad`]).
    pub roll_pitch_yaw_rad: [f64; 3],
    /// Gyroscope bias x, y, z, rad/s.
    pub gyro_bias_rad_s: [f64; 3],
    /// Accelerometer bias x, y, z, m/s².
    pub accel_bias_m_s2: [f64; 3],
    /// Gyroscope scale-factor error x, y, z (dimensionless).
    pub gyro_scale: [f64; 3],
    /// Accelerometer scale-factor error x, y, z (dimensionless).
    pub accel_scale: [f64; 3],
    /// σ of position north, east, down, m.
    pub std_pos_ned_m: [f64; 3],
    /// σ of velocity north, east, down, m/s.
    pub std_vel_ned_m_s: [f64; 3],
    /// σ of roll, pitch, yaw, rad.
    pub std_att_rad: [f64; 3],
    /// σ of the gyroscope bias, rad/s.
    pub std_gyro_bias_rad_s: [f64; 3],
    /// σ of the accelerometer bias, m/s².
    pub std_accel_bias_m_s2: [f64; 3],
    /// σ of the gyroscope scale-factor error.
    pub std_gyro_scale: [f64; 3],
    /// σ of the accelerometer scale-factor error.
    pub std_accel_scale: [f64; 3],
}

/// Gyroscope bias, rad/s → deg/h.
pub(super) fn deg_h(b: [f64; 3]) -> [f64; 3] {
    b.map(|x| x * R2D * 3600.0)
}

/// Values scaled by `k` (rad → deg, m/s² → mGal, 1 → ppm).
pub(super) fn times(a: [f64; 3], k: f64) -> [f64; 3] {
    a.map(|x| x * k)
}

impl KfGinsRow {
    /// The `.nav` line: week, time, lat, lon [deg], h, v NED, roll, pitch, yaw [deg].
    pub(super) fn nav_values(&self, gps_week: u16) -> [f64; 11] {
        let [vn, ve, vd] = self.vel_ned_m_s;
        let [r, p, y] = times(self.roll_pitch_yaw_rad, R2D);
        let h = self.height_m;
        let (lat, lon) = (self.lat_rad * R2D, self.lon_rad * R2D);
        [
            f64::from(gps_week),
            self.time_s,
            lat,
            lon,
            h,
            vn,
            ve,
            vd,
            r,
            p,
            y,
        ]
    }

    /// The IMU-error line: time, gyro bias [deg/h], accel bias [mGal], scales [ppm].
    pub(super) fn imu_err_values(&self) -> [f64; 13] {
        let mut v = [self.time_s; 13];
        v[1..4].copy_from_slice(&deg_h(self.gyro_bias_rad_s));
        v[4..7].copy_from_slice(&times(self.accel_bias_m_s2, MGAL_PER_M_S2));
        v[7..10].copy_from_slice(&times(self.gyro_scale, PPM));
        v[10..13].copy_from_slice(&times(self.accel_scale, PPM));
        v
    }

    /// The std line: time, pos NED [m], vel NED [m/s], att [deg], gyro bias [deg/h],
    /// accel bias [mGal], scales [ppm].
    pub(super) fn std_values(&self) -> [f64; 22] {
        let mut v = [self.time_s; 22];
        v[1..4].copy_from_slice(&self.std_pos_ned_m);
        v[4..7].copy_from_slice(&self.std_vel_ned_m_s);
        v[7..10].copy_from_slice(&times(self.std_att_rad, R2D));
        v[10..13].copy_from_slice(&deg_h(self.std_gyro_bias_rad_s));
        v[13..16].copy_from_slice(&times(self.std_accel_bias_m_s2, MGAL_PER_M_S2));
        v[16..19].copy_from_slice(&times(self.std_gyro_scale, PPM));
        v[19..22].copy_from_slice(&times(self.std_accel_scale, PPM));
        v
    }
}

pub(super) fn append_nav(
    w: &mut impl Write,
    name: &str,
    sol: &NavSolution,
    gps_week: u16,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = common_len(&[
        ("time_s", sol.time_s.len()),
        ("lat_rad", sol.lat_rad.len()),
        ("lon_rad", sol.lon_rad.len()),
        ("height_m", sol.height_m.len()),
        ("vel_ned_m_s", sol.vel_ned_m_s.len()),
        ("roll_pitch_yaw_rad", sol.roll_pitch_yaw_rad.len()),
    ])
    .map_err(|m| lens_err(name, m))?;
    write_rows(w, name, n, first_row, |i| {
        nav_row(sol, i).nav_values(gps_week)
    })?;
    Ok(n)
}

/// Row `i` of `sol` (the navigation columns; the others zero).
pub(super) fn nav_row(sol: &NavSolution, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: sol.time_s[i],
        lat_rad: sol.lat_rad[i],
        lon_rad: sol.lon_rad[i],
        height_m: sol.height_m[i],
        vel_ned_m_s: sol.vel_ned_m_s[i],
        roll_pitch_yaw_rad: sol.roll_pitch_yaw_rad[i],
        ..KfGinsRow::default()
    }
}

/// Row `i` of `e` (time and the IMU-error columns; the others zero).
pub(super) fn imu_err_row(e: &ImuErrors, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: e.time_s[i],
        gyro_bias_rad_s: e.gyro_bias_rad_s[i],
        accel_bias_m_s2: e.accel_bias_m_s2[i],
        gyro_scale: e.gyro_scale[i],
        accel_scale: e.accel_scale[i],
        ..KfGinsRow::default()
    }
}

/// Row `i` of `s` (time and the std columns; the others zero).
pub(super) fn std_row(s: &NavStd, i: usize) -> KfGinsRow {
    KfGinsRow {
        time_s: s.time_s[i],
        std_pos_ned_m: s.pos_ned_m[i],
        std_vel_ned_m_s: s.vel_ned_m_s[i],
        std_att_rad: s.att_rad[i],
        std_gyro_bias_rad_s: s.gyro_bias_rad_s[i],
        std_accel_bias_m_s2: s.accel_bias_m_s2[i],
        std_gyro_scale: s.gyro_scale[i],
        std_accel_scale: s.accel_scale[i],
        ..KfGinsRow::default()
    }
}

/// Writes estimated IMU errors in KF-GINS's `KF_GINS_IMU_ERR.txt` format (13 columns).
pub fn write_kfgins_imu_err(mut w: impl Write, name: &str, e: &ImuErrors) -> Result<(), LogError> {
    append_imu_err(&mut w, name, e, 0)?;
    w.flush().map_err(|err| io_error(name, err))
}

/// Rows in `e` (all columns the same length).
pub(super) fn imu_err_len(name: &str, e: &ImuErrors) -> Result<usize, LogError> {
    common_len(&[
        ("time_s", e.time_s.len()),
        ("gyro_bias_rad_s", e.gyro_bias_rad_s.len()),
        ("accel_bias_m_s2", e.accel_bias_m_s2.len()),
        ("gyro_scale", e.gyro_scale.len()),
        ("accel_scale", e.accel_scale.len()),
    ])
    .map_err(|m| lens_err(name, m))
}

pub(super) fn append_imu_err(
    w: &mut impl Write,
    name: &str,
    e: &ImuErrors,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = imu_err_len(name, e)?;
    write_rows(w, name, n, first_row, |i| {
        imu_err_row(e, i).imu_err_values()
    })?;
    Ok(n)
}

/// Writes state standard deviations in KF-GINS's `KF_GINS_STD.txt` format (22 columns).
pub fn write_kfgins_std(mut w: impl Write, name: &str, s: &NavStd) -> Result<(), LogError> {
    append_std(&mut w, name, s, 0)?;
    w.flush().map_err(|e| io_error(name, e))
}

/// Rows in `s` (all columns the same length).
pub(super) fn std_len(name: &str, s: &NavStd) -> Result<usize, LogError> {
    common_len(&[
        ("time_s", s.time_s.len()),
        ("pos_ned_m", s.pos_ned_m.len()),
        ("vel_ned_m_s", s.vel_ned_m_s.len()),
        ("att_rad", s.att_rad.len()),
        ("gyro_bias_rad_s", s.gyro_bias_rad_s.len()),
        ("accel_bias_m_s2", s.accel_bias_m_s2.len()),
        ("gyro_scale", s.gyro_scale.len()),
        ("accel_scale", s.accel_scale.len()),
    ])
    .map_err(|m| lens_err(name, m))
}

pub(super) fn append_std(
    w: &mut impl Write,
    name: &str,
    s: &NavStd,
    first_row: usize,
) -> Result<usize, LogError> {
    let n = std_len(name, s)?;
    write_rows(w, name, n, first_row, |i| std_row(s, i).std_values())?;
    Ok(n)
}

/// The three output paths in `dir`: `.nav`, IMU error, std.
pub(super) fn output_paths(dir: &Path) -> [PathBuf; 3] {
    [NAV_FILE, IMU_ERR_FILE, STD_FILE].map(|f| dir.join(f))
}

/// Suffix of the smoothed solution's files: `KF_GINS_Navresult_smoothed.nav`,
/// `KF_GINS_IMU_ERR_smoothed.txt`, `KF_GINS_STD_smoothed.txt` (same formats).
pub(crate) const SMOOTHED_SUFFIX: &str = "_smoothed";

/// KF-GINS's three output file names with `suffix` before the extension (`""`: KF-GINS's
/// own names).
pub(crate) fn output_file_names(suffix: &str) -> [String; 3] {
    [NAV_FILE, IMU_ERR_FILE, STD_FILE].map(|f| match f.rsplit_once('.') {
        Some((stem, ext)) => format!("{stem}{suffix}.{ext}"),
        None => format!("{f}{suffix}"),
    })
}

/// Heading in KF-GINS's range \[0, 2π): its Euler conversion (`Rotation::matrix2euler`)
/// adds 2π to a negative `atan2` yaw, so its `.nav` files give yaw in \[0°, 360°).
pub fn kfgins_heading_rad(yaw_rad: f64) -> f64 {
    if yaw_rad < 0.0 {
        yaw_rad + 2.0 * std::f64::consts::PI
    } else {
        yaw_rad
    }
}

/// Writes one output file atomically ([`AtomicFile`]) through a 64 KiB buffer:
/// [`write_rows`] hands it whole chunks, which a buffer smaller than them passes straight
/// to the file.
pub(super) fn write_output(
    p: &Path,
    body: impl FnOnce(std::io::BufWriter<&mut AtomicFile>, &str) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let name = p.display().to_string();
    let mut file = AtomicFile::create(p).map_err(|e| io_error(&name, e))?;
    body(std::io::BufWriter::with_capacity(1 << 16, &mut file), &name)?;
    file.commit().map_err(|e| io_error(&name, e))
}

/// Commits the three files of one run concurrently (each sync waits for its own data to
/// reach the disk).
pub(super) fn commit_outputs(files: [AtomicFile; 3], names: &[String; 3]) -> Result<(), LogError> {
    let [a, b, c] = files;
    let commit = |f: AtomicFile, name: &str| f.commit().map_err(|e| io_error(name, e));
    let ((ra, rb), rc) = rayon::join(
        || rayon::join(|| commit(a, &names[0]), || commit(b, &names[1])),
        || commit(c, &names[2]),
    );
    ra.and(rb).and(rc)
}

/// KF-GINS's three output files, written row by row or block by block — e.g. on one
/// thread while a filter on another produces the rows
/// ([`crate::nav::filter::run_forward_observed`]). Each file has its own line buffer,
/// written to the file in chunks of 512 KiB.
pub struct KfGinsOutputWriter {
    files: [AtomicFile; 3],
    bufs: [Box<LineBuf>; 3],
    paths: [PathBuf; 3],
    names: [String; 3],
    rows: usize,
    gps_week: u16,
}

impl KfGinsOutputWriter {
    /// Starts the three files in `dir` (KF-GINS's `outputpath`, which must exist, as in
    /// KF-GINS). They replace earlier files of those names only in
    /// [`KfGinsOutputWriter::finish`]; dropped before, the earlier files stay.
    pub fn create(dir: impl AsRef<Path>, gps_week: u16) -> Result<Self, LogError> {
        Self::create_with_suffix(dir, gps_week, "")
    }

    /// [`KfGinsOutputWriter::create`] with `suffix` before each file's extension
    /// ([`output_file_names`], e.g. [`SMOOTHED_SUFFIX`]).
    pub(crate) fn create_with_suffix(
        dir: impl AsRef<Path>,
        gps_week: u16,
        suffix: &str,
    ) -> Result<Self, LogError> {
        let paths = output_file_names(suffix).map(|f| dir.as_ref().join(f));
        // Each file is new (a temporary name beside the final one), so ext4's flush of a
        // file truncated to zero when its handle closes (`auto_da_alloc`) does not apply;
        // the data is synced once, all three files at once, in `finish`.
        let create = |p: &Path| {
            AtomicFile::create(p)
                .map(|f| f.durable(false))
                .map_err(|e| io_error(&p.display().to_string(), e))
        };
        Ok(KfGinsOutputWriter {
            files: [create(&paths[0])?, create(&paths[1])?, create(&paths[2])?],
            bufs: [(); 3].map(|()| Box::new(LineBuf::new())),
            names: [0, 1, 2].map(|k| paths[k].display().to_string()),
            paths,
            rows: 0,
            gps_week,
        })
    }

    /// Appends one row to each file. A value that is not finite is an error naming the
    /// file, row (0-based) and column.
    pub fn append_row(&mut self, row: &KfGinsRow) -> Result<(), LogError> {
        let [nav, err, std] = &mut self.bufs;
        let r = self.rows;
        let names = &self.names;
        let nav_v = row.nav_values(self.gps_week);
        nav.line(&nav_v)
            .map_err(|k| non_finite(&names[0], nav_v[k], r, k))?;
        let err_v = row.imu_err_values();
        err.line(&err_v)
            .map_err(|k| non_finite(&names[1], err_v[k], r, k))?;
        let std_v = row.std_values();
        std.line(&std_v)
            .map_err(|k| non_finite(&names[2], std_v[k], r, k))?;
        self.rows += 1;
        for k in 0..3 {
            if self.bufs[k].is_full() {
                self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
            }
        }
        Ok(())
    }

    /// Appends one block of rows (all three parts the same length).
    pub fn append(
        &mut self,
        sol: &NavSolution,
        imu_err: &ImuErrors,
        std: &NavStd,
    ) -> Result<(), LogError> {
        // Rows appended one by one come first.
        for k in 0..3 {
            self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
        }
        let [nav_f, err_f, std_f] = &mut self.files;
        let (names, rows) = (&self.names, self.rows);
        let n = append_nav(nav_f, &names[0], sol, self.gps_week, rows)?;
        let m = append_imu_err(err_f, &names[1], imu_err, rows)?;
        let k = append_std(std_f, &names[2], std, rows)?;
        if n != m || n != k {
            return Err(lens_err(
                &self.names[0],
                format!("blocks of {n} solution, {m} IMU-error and {k} std rows"),
            ));
        }
        self.rows += n;
        Ok(())
    }

    /// Writes the rest of the rows, puts the three files under their final names and
    /// returns the paths: `.nav`, IMU error, std.
    pub fn finish(mut self) -> Result<[PathBuf; 3], LogError> {
        for k in 0..3 {
            self.bufs[k].drain_to(&mut self.files[k], &self.names[k])?;
        }
        commit_outputs(self.files, &self.names)?;
        Ok(self.paths)
    }
}

/// Writes KF-GINS's three output files into `dir` (KF-GINS's `outputpath`, which must
/// exist, as in KF-GINS) and returns their paths: `.nav`, IMU error, std.
pub fn write_kfgins_outputs(
    dir: impl AsRef<Path>,
    sol: &NavSolution,
    imu_err: &ImuErrors,
    std: &NavStd,
    gps_week: u16,
) -> Result<[PathBuf; 3], LogError> {
    let paths = output_paths(dir.as_ref());
    // The three files are independent and formatting-bound: write them concurrently.
    let ((nav, err), std_res) = rayon::join(
        || {
            rayon::join(
                || write_output(&paths[0], |w, n| write_kfgins_nav(w, n, sol, gps_week)),
                || write_output(&paths[1], |w, n| write_kfgins_imu_err(w, n, imu_err)),
            )
        },
        || write_output(&paths[2], |w, n| write_kfgins_std(w, n, std)),
    );
    nav?;
    err?;
    std_res?;
    Ok(paths)
}

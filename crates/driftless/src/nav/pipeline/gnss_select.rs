//! GNSS fixes for a run: reading and the selection of fixes inside the IMU span.

use super::*;

/// Reads GNSS fixes, choosing the format by content: text whose first non-blank line
/// starts with `%` is an RTKLIB `.pos` solution, anything else a KF-GINS GNSS file. The
/// σ = 0 policy (`opts.zero_sigma`) is passed to the reader.
pub fn read_gnss_file(
    path: impl AsRef<Path>,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, PipelineError> {
    let path = path.as_ref();
    let bytes = crate::io::nav::read_text_file(path)?;
    read_gnss(&bytes, &path.display().to_string(), opts)
}

/// [`read_gnss_file`] from memory.
pub fn read_gnss(
    bytes: &[u8],
    name: &str,
    opts: &GnssReadOptions,
) -> Result<GnssFixes, PipelineError> {
    let first = bytes
        .split(|&b| b == b'\n')
        .map(|l| l.trim_ascii())
        .find(|l| !l.is_empty());
    Ok(match first {
        Some(l) if l.starts_with(b"%") => read_rtklib_pos(bytes, name, opts)?,
        _ => read_kfgins_gnss(bytes, name, opts)?,
    })
}

/// What to do with GNSS epochs before the first or after the last IMU epoch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GnssOutsideImu {
    /// Drop them and count them in [`GnssSelection`] (the caller logs the counts).
    #[default]
    Drop,
    /// Stop with [`PipelineError::GnssOutsideImu`] naming the first such epoch.
    Error,
}

/// GNSS epochs for the filter, with what was removed and why.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GnssSelection {
    /// Epochs to use (all columns subset consistently).
    pub fixes: GnssFixes,
    /// Outage windows applied (absolute GPS s, sorted).
    pub windows: Vec<OutageWindow>,
    /// Epochs dropped because they precede the first IMU epoch.
    pub dropped_before_imu: usize,
    /// Epochs dropped because they follow the last IMU epoch.
    pub dropped_after_imu: usize,
    /// Epochs withheld by the outage windows.
    pub masked: usize,
    /// Time span of the GNSS epochs inside the IMU span (before masking), the span the
    /// outage specification was resolved against.
    pub usable_span: Option<TimeSpan>,
}

/// The rows of `g` where `keep` is true (every column).
pub(crate) fn subset_fixes(g: &GnssFixes, keep: &[bool]) -> GnssFixes {
    fn pick<T: Copy>(v: &[T], keep: &[bool]) -> Vec<T> {
        v.iter()
            .zip(keep)
            .filter_map(|(x, &k)| k.then_some(*x))
            .collect()
    }
    GnssFixes {
        gps_week: g.gps_week,
        time_s: pick(&g.time_s, keep),
        lat_rad: pick(&g.lat_rad, keep),
        lon_rad: pick(&g.lon_rad, keep),
        height_m: pick(&g.height_m, keep),
        sigma_ned_m: pick(&g.sigma_ned_m, keep),
        vel_ned_m_s: g.vel_ned_m_s.as_deref().map(|v| pick(v, keep)),
        sigma_vel_ned_m_s: g.sigma_vel_ned_m_s.as_deref().map(|v| pick(v, keep)),
        quality: pick(&g.quality, keep),
        n_sats: g.n_sats.as_deref().map(|v| pick(v, keep)),
        notes: g.notes.clone(),
    }
}

/// The GNSS epochs a filter should use: those inside the IMU's time span (others dropped
/// and counted, or an error, per `outside`), minus those inside the outage windows.
///
/// The outage specification is resolved ([`super::super::outage::resolve`]) against the span of
/// the GNSS epochs that lie inside the IMU span, so "300 s after the first GNSS epoch"
/// counts from the first *usable* epoch. An epoch exactly at the first or last IMU time is
/// inside. GNSS time and IMU time must be on the same scale (GPS s of week).
pub fn select_gnss(
    gnss: &GnssFixes,
    imu: &ImuStream,
    outages: &OutageSpec,
    outside: GnssOutsideImu,
) -> Result<GnssSelection, PipelineError> {
    let Some(imu_span) = imu.time_span() else {
        return Err(PipelineError::TooFewEpochs {
            source_name: imu.source.clone(),
            count: 0,
        });
    };
    let mut keep = vec![true; gnss.len()];
    let (mut before, mut after) = (0, 0);
    for (i, &t) in gnss.time_s.iter().enumerate() {
        let is_before = t < imu_span.start_s;
        let is_after = t > imu_span.end_s;
        if is_before || is_after {
            if outside == GnssOutsideImu::Error {
                return Err(PipelineError::GnssOutsideImu {
                    index: i,
                    time_s: t,
                    imu_start_s: imu_span.start_s,
                    imu_end_s: imu_span.end_s,
                });
            }
            keep[i] = false;
            before += usize::from(is_before);
            after += usize::from(is_after);
        }
    }
    let inside: Vec<f64> = gnss
        .time_s
        .iter()
        .zip(&keep)
        .filter_map(|(&t, &k)| k.then_some(t))
        .collect();
    let Some(usable_span) = TimeSpan::of(&inside) else {
        return Err(PipelineError::NoGnssInImuSpan {
            imu_start_s: imu_span.start_s,
            imu_end_s: imu_span.end_s,
        });
    };
    let windows = match outages {
        OutageSpec::None => Vec::new(),
        spec => spec.resolve(usable_span)?,
    };
    let mut masked = 0;
    for (k, &t) in keep.iter_mut().zip(&gnss.time_s) {
        if *k && is_masked(&windows, t) {
            *k = false;
            masked += 1;
        }
    }
    Ok(GnssSelection {
        fixes: subset_fixes(gnss, &keep),
        windows,
        dropped_before_imu: before,
        dropped_after_imu: after,
        masked,
        usable_span: Some(usable_span),
    })
}

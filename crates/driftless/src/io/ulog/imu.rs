//! IMU logs from a parsed ULog: `sensor_gyro` and `sensor_accel` instances paired by
//! time.

use crate::io::autopilot::{
    AutopilotFormat, AutopilotImu, AutopilotImuLogs, Column, build_imu_log,
};
use crate::io::error::{Location, LogError};
use crate::io::log::Quantity;

use super::{FORMAT, Topic, parse_ulog};

/// One [`crate::io::ImuLog`] per IMU instance from `sensor_gyro` (x, y, z in rad/s,
/// `temperature` in °C) and `sensor_accel` (x, y, z in m/s², `temperature`).
///
/// **Alignment.** The two topics are separate uORB messages with their own time stamps
/// (tens of µs apart for one IMU chip). Gyro instance *k* is paired with accel instance *k*
/// (the same `multi_id`; a note is added when their `device_id`s differ) and each gyro row
/// takes the accel row **nearest in time** if it lies within half the larger of the two
/// median sample intervals; gyro rows without such a partner are dropped (counted in the
/// notes). Nearest-neighbour, not interpolation: no sample is invented, and the pairing
/// error (≤ half an interval) is irrelevant to bias-versus-temperature fits. The log's time
/// base is the gyro's `timestamp`. Channels: `gyro_x/y/z`, `acc_x/y/z`, `temperature`
/// (the gyro's), plus `acc_temperature` (quantity `Other`, unit degC) only when the accel
/// topic's temperature differs from the gyro's on some row. An instance with only one of
/// the two topics gives a log with that triad alone.
pub fn imu_logs_from_ulog(bytes: &[u8], source: &str) -> Result<AutopilotImuLogs, LogError> {
    let ulog = parse_ulog(bytes, source)?;
    let mut found: Vec<(String, usize)> = ulog
        .topics
        .iter()
        .map(|t| (format!("{}[{}]", t.name, t.multi_id), t.len()))
        .collect();
    found.sort();
    let mut notes = ulog.notes.clone();
    let mut ids: Vec<u8> = ulog
        .topics
        .iter()
        .filter(|t| (t.name == "sensor_gyro" || t.name == "sensor_accel") && !t.is_empty())
        .map(|t| t.multi_id)
        .collect();
    ids.sort_unstable();
    ids.dedup();
    if ids.is_empty() {
        return Err(LogError::Malformed {
            at: Location::input(source),
            format: FORMAT,
            message: format!(
                "no sensor_gyro or sensor_accel data (topics: {})",
                crate::io::autopilot::list_counts(&found)
            ),
        });
    }
    let mut imus = Vec::new();
    for id in ids {
        let gyro = ulog.topic("sensor_gyro", id).filter(|t| !t.is_empty());
        let accel = ulog.topic("sensor_accel", id).filter(|t| !t.is_empty());
        let log = instance_log(source, id, gyro, accel, &mut notes)?;
        imus.push(AutopilotImu { instance: id, log });
    }
    Ok(AutopilotImuLogs {
        format: AutopilotFormat::ULog,
        imus,
        truncated_at_byte: ulog.truncated_at_byte,
        found,
        notes,
    })
}

/// A sensor topic's columns: (time µs, byte offsets, x, y, z, temperature?).
pub(super) type Triad = (Vec<u64>, Vec<u64>, [Vec<f64>; 3], Option<Vec<f64>>);

pub(super) fn triad(source: &str, t: &Topic) -> Result<Triad, LogError> {
    let missing = |what: &str| LogError::AtByte {
        path: source.to_owned(),
        byte_offset: t.row_byte_offset(0).unwrap_or(0),
        format: FORMAT,
        message: format!(
            "topic {}[{}] has no {what} field (fields: {})",
            t.name,
            t.multi_id,
            t.field_names().collect::<Vec<_>>().join(", ")
        ),
    };
    let time = t
        .timestamps_us()
        .ok_or_else(|| missing("uint64_t timestamp"))?;
    let col = |n: &str| t.column(n).ok_or_else(|| missing(n));
    Ok((
        time,
        t.row_offsets.clone(),
        [col("x")?, col("y")?, col("z")?],
        t.column("temperature"),
    ))
}

pub(super) fn median_dt_us(t: &[u64]) -> u64 {
    let mut d: Vec<u64> = t.windows(2).map(|w| w[1].saturating_sub(w[0])).collect();
    d.sort_unstable();
    d.get(d.len() / 2).copied().unwrap_or(0)
}

pub(super) fn instance_log(
    source: &str,
    id: u8,
    gyro: Option<&Topic>,
    accel: Option<&Topic>,
    notes: &mut Vec<String>,
) -> Result<crate::io::ImuLog, LogError> {
    let temp_col = |values| Column {
        name: "temperature",
        quantity: Quantity::Temperature,
        source_unit: "degC",
        values,
    };
    let triad_cols =
        |names: [&'static str; 3], q: Quantity, unit: &'static str, v: [Vec<f64>; 3]| {
            let [x, y, z] = v;
            [x, y, z]
                .into_iter()
                .zip(names)
                .map(|(values, name)| Column {
                    name,
                    quantity: q,
                    source_unit: unit,
                    values,
                })
                .collect::<Vec<_>>()
        };
    const GYRO: [&str; 3] = ["gyro_x", "gyro_y", "gyro_z"];
    const ACC: [&str; 3] = ["acc_x", "acc_y", "acc_z"];
    match (gyro, accel) {
        (None, None) => Err(LogError::Malformed {
            at: Location::input(source),
            format: FORMAT,
            message: format!("IMU instance {id} has no data"),
        }),
        (Some(only), None) | (None, Some(only)) => {
            let is_gyro = gyro.is_some();
            notes.push(format!(
                "instance {id}: {} only (no {} topic)",
                only.name,
                if is_gyro {
                    "sensor_accel"
                } else {
                    "sensor_gyro"
                }
            ));
            let (time, offsets, xyz, temp) = triad(source, only)?;
            let mut cols = if is_gyro {
                triad_cols(GYRO, Quantity::AngularRate, "rad/s", xyz)
            } else {
                triad_cols(ACC, Quantity::SpecificForce, "m/s^2", xyz)
            };
            cols.extend(temp.map(temp_col));
            build_imu_log(source, FORMAT, &time, &offsets, cols)
        }
        (Some(g), Some(a)) => {
            let (gt, goff, gxyz, gtemp) = triad(source, g)?;
            let (at, _, axyz, atemp) = triad(source, a)?;
            if let (Some(gd), Some(ad)) = (g.column("device_id"), a.column("device_id"))
                && gd.first() != ad.first()
            {
                notes.push(format!(
                    "instance {id}: sensor_gyro device_id {:?} differs from sensor_accel's {:?}; paired by instance number",
                    gd.first(),
                    ad.first()
                ));
            }
            let tol = median_dt_us(&gt).max(median_dt_us(&at)) / 2;
            // Nearest accel row for each gyro row (both time series are walked once; a
            // non-monotonic series is caught by build_imu_log for the gyro, and only
            // worsens pairing for the accel).
            let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(gt.len());
            let mut j = 0usize;
            for (i, &t) in gt.iter().enumerate() {
                while j + 1 < at.len() && at[j + 1] <= t {
                    j += 1;
                }
                let best = [j, j + 1]
                    .into_iter()
                    .filter(|&k| k < at.len())
                    .min_by_key(|&k| at[k].abs_diff(t));
                if let Some(k) = best
                    && at[k].abs_diff(t) <= tol
                {
                    pairs.push((i, k));
                }
            }
            if pairs.len() < gt.len() {
                notes.push(format!(
                    "instance {id}: {} of {} gyro rows had no accel row within {tol} µs and were dropped",
                    gt.len() - pairs.len(),
                    gt.len()
                ));
            }
            let pick = |v: &[f64], gyro_side: bool| -> Vec<f64> {
                pairs
                    .iter()
                    .map(|&(i, k)| {
                        v.get(if gyro_side { i } else { k })
                            .copied()
                            .unwrap_or(f64::NAN)
                    })
                    .collect()
            };
            let time: Vec<u64> = pairs.iter().map(|&(i, _)| gt[i]).collect();
            let offsets: Vec<u64> = pairs
                .iter()
                .map(|&(i, _)| goff.get(i).copied().unwrap_or(0))
                .collect();
            let mut cols = triad_cols(
                GYRO,
                Quantity::AngularRate,
                "rad/s",
                gxyz.each_ref().map(|v| pick(v, true)),
            );
            cols.extend(triad_cols(
                ACC,
                Quantity::SpecificForce,
                "m/s^2",
                axyz.each_ref().map(|v| pick(v, false)),
            ));
            let gtemp = gtemp.map(|v| pick(&v, true));
            let atemp = atemp.map(|v| pick(&v, false));
            let temp_differs = matches!((&gtemp, &atemp), (Some(g), Some(a)) if g != a);
            match (gtemp, atemp) {
                (Some(g), Some(a)) => {
                    cols.push(temp_col(g));
                    if temp_differs {
                        cols.push(Column {
                            name: "acc_temperature",
                            quantity: Quantity::Other,
                            source_unit: "degC",
                            values: a,
                        });
                    }
                }
                (Some(t), None) | (None, Some(t)) => cols.push(temp_col(t)),
                (None, None) => {}
            }
            build_imu_log(source, FORMAT, &time, &offsets, cols)
        }
    }
}

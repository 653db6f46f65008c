//! The solution of a session as records for the writers.

use super::*;

/// The forward run as KF-GINS-style output records (navigation solution, IMU errors,
/// state standard deviations), one row per IMU epoch.
pub fn solution_records(
    run: &ForwardRun,
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    epoch_solution_records(&run.epochs)
}

/// [`solution_records`] of a block of epoch records (e.g. one handed out by
/// [`super::super::filter::run_forward_observed`]).
pub(crate) fn epoch_solution_records(
    epochs: &[super::super::filter::EpochRecord],
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    state_solution_records(epochs.iter().map(|e| (&e.nav, &e.sensors, &e.std)))
}

/// Output records of any sequence of states — navigation state, sensor-error estimates,
/// √diag(P) in the order of [`super::super::filter::state`] — e.g. forward records or smoothed
/// epochs ([`super::super::filter::SmoothedEpoch`]). Attitude as roll, pitch, yaw from
/// [`Euler::from_dcm`] (yaw in (−π, π]).
pub(crate) fn state_solution_records<'a>(
    states: impl IntoIterator<
        Item = (
            &'a NavState,
            &'a super::super::filter::SensorErrors,
            &'a [f64; super::super::filter::N_STATES],
        ),
    >,
) -> (
    crate::io::nav::NavSolution,
    crate::io::nav::ImuErrors,
    crate::io::nav::NavStd,
) {
    use super::super::filter::state::{ATT, BA, BG, POS, SA, SG, VEL};
    let mut sol = crate::io::nav::NavSolution::default();
    let mut err = crate::io::nav::ImuErrors::default();
    let mut std = crate::io::nav::NavStd::default();
    let tri = |s: &[f64], i: usize| [s[i], s[i + 1], s[i + 2]];
    for (n, sensors, sd) in states {
        let att = Euler::from_dcm(&n.q_bn.to_dcm());
        sol.push_epoch(
            n.time_s,
            n.lat_rad,
            n.lon_rad,
            n.height_m,
            n.vel_ned_m_s,
            [att.roll_rad, att.pitch_rad, att.yaw_rad],
        );
        err.time_s.push(n.time_s);
        err.gyro_bias_rad_s.push(sensors.gyro_bias_rad_s);
        err.accel_bias_m_s2.push(sensors.accel_bias_m_s2);
        err.gyro_scale.push(sensors.gyro_scale);
        err.accel_scale.push(sensors.accel_scale);
        std.time_s.push(n.time_s);
        std.pos_ned_m.push(tri(sd, POS));
        std.vel_ned_m_s.push(tri(sd, VEL));
        std.att_rad.push(tri(sd, ATT));
        std.gyro_bias_rad_s.push(tri(sd, BG));
        std.accel_bias_m_s2.push(tri(sd, BA));
        std.gyro_scale.push(tri(sd, SG));
        std.accel_scale.push(tri(sd, SA));
    }
    (sol, err, std)
}

//! [`NavConfig::validate`]: every value checked against its range, names and units.

use super::*;

impl NavConfig {
    /// Checks every value: ranges, names, units. The first problem, by key.
    pub fn validate(&self) -> Result<(), KeyError> {
        self.validate_imu()?;
        self.validate_gnss()?;
        self.noise_settings(None)?;
        self.validate_align()?;
        self.validate_aids()?;
        self.gate()?;
        self.validate_outages()
    }

    /// The `[imu]` values: reader format and tag, time offset and base, rate, mounting,
    /// gap policy and hard limits.
    fn validate_imu(&self) -> Result<(), KeyError> {
        let i = &self.imu;
        if !["auto", "kfgins", "tagged-csv", "csv"].contains(&i.format.as_str()) {
            return Err(key_err(
                "imu.format",
                format!(
                    "{:?} is not a format: auto, kfgins, tagged-csv or csv",
                    i.format
                ),
            ));
        }
        if i.tag.is_some() && !["auto", "tagged-csv"].contains(&i.format.as_str()) {
            return Err(key_err(
                "imu.tag",
                format!(
                    "a time-tag file goes with the tagged-CSV reader, but imu.format = {:?}: drop the tag or set format tagged-csv (or auto)",
                    i.format
                ),
            ));
        }
        if !i.time_offset_s.is_finite() || i.time_offset_s.abs() > 86_400.0 {
            return Err(key_err(
                "imu.time_offset_s",
                format!(
                    "{} s: give the offset in seconds, |offset| ≤ 1 day",
                    i.time_offset_s
                ),
            ));
        }
        let base = self.time_base().map_err(|e| key_err("imu.time_base", e))?;
        if base == crate::io::nav::TimeBase::GpsWeekAndSeconds && i.week_column.is_none() {
            return Err(key_err(
                "imu.time_base",
                "gps-week-sow needs the week column: set imu.week_column (--imu-week-column)",
            ));
        }
        if let Some(r) = i.rate_hz
            && !(r.is_finite() && r > 0.0 && r <= 100_000.0)
        {
            return Err(key_err(
                "imu.rate_hz",
                format!("{r} Hz: a rate is > 0 (or leave it out to take it from the time stamps)"),
            ));
        }
        for (k, v) in [
            ("imu.mounting_rpy_deg", i.mounting_rpy_deg),
            ("imu.misalignment_rpy_deg", i.misalignment_rpy_deg),
        ] {
            check_angles(k, v)?;
        }
        if !["error", "bridge"].contains(&i.gaps.as_str()) {
            return Err(key_err(
                "imu.gaps",
                format!("{:?}: error or bridge", i.gaps),
            ));
        }
        for (k, v, unit) in [
            ("imu.max_gyro_deg_s", i.max_gyro_deg_s, "deg/s"),
            ("imu.max_accel_g", i.max_accel_g, "g"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(key_err(k, format!("{v} {unit}: a limit is > 0")));
            }
        }
        Ok(())
    }

    /// The `[gnss]` values: lever arm, σ floors and multipliers, accepted qualities.
    fn validate_gnss(&self) -> Result<(), KeyError> {
        let g = &self.gnss;
        if !g
            .lever_arm_m
            .iter()
            .all(|v| v.is_finite() && v.abs() <= 100.0)
        {
            return Err(key_err(
                "gnss.lever_arm_m",
                format!(
                    "{:?} m: three lengths in metres, each within ±100 m",
                    g.lever_arm_m
                ),
            ));
        }
        if let FloorSetting::Metres(m) = g.sigma_floor_m {
            nonneg("gnss.sigma_floor_m", m, 1000.0, "m")?;
        }
        if let Some(v) = g.sigma_floor_vertical_m {
            nonneg("gnss.sigma_floor_vertical_m", v, 1000.0, "m")?;
        }
        for (name, k) in QUALITY_NAMES.iter().zip(g.sigma_scale.as_array()) {
            if !(k.is_finite() && k > 0.0 && k <= 1e6) {
                return Err(key_err(
                    "gnss.sigma_scale",
                    format!("{name} = {k}: a σ multiplier is > 0"),
                ));
            }
        }
        if g.accept.is_empty() {
            return Err(key_err(
                "gnss.accept",
                format!(
                    "no quality accepted: list some of {}",
                    QUALITY_NAMES.join(", ")
                ),
            ));
        }
        for q in &g.accept {
            if !QUALITY_NAMES.contains(&q.as_str()) {
                return Err(key_err(
                    "gnss.accept",
                    format!(
                        "{q:?} is not a solution quality: {}",
                        QUALITY_NAMES.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The `[align]` values: speed, static time, course σ, baseline, given attitude.
    fn validate_align(&self) -> Result<(), KeyError> {
        let a = &self.align;
        nonneg("align.min_speed_m_s", a.min_speed_m_s, 1000.0, "m/s")?;
        nonneg("align.static_s", a.static_s, 3600.0, "s")?;
        positive(
            "align.max_heading_sigma_deg",
            a.max_heading_sigma_deg,
            180.0,
            "deg",
        )?;
        positive("align.baseline_s", a.baseline_s, 600.0, "s")?;
        if let Some(y) = a.initial_yaw_deg {
            check_angles("align.initial_yaw_deg", [0.0, 0.0, y])?;
        }
        if let Some(att) = a.initial_attitude_deg {
            check_angles("align.initial_attitude_deg", att)?;
            if att[1].abs() > 90.0 {
                return Err(key_err(
                    "align.initial_attitude_deg",
                    format!("pitch {}°: within ±90°", att[1]),
                ));
            }
        }
        if a.initial_yaw_deg.is_some() && a.initial_attitude_deg.is_some() {
            return Err(key_err(
                "align.initial_yaw_deg",
                "give either initial_yaw_deg or initial_attitude_deg, not both",
            ));
        }
        Ok(())
    }

    /// The `[aids]` values: ZUPT, ZARU, standstill detection and NHC.
    fn validate_aids(&self) -> Result<(), KeyError> {
        let x = &self.aids;
        for (k, v, max, unit) in [
            ("aids.zupt_sigma_m_s", x.zupt_sigma_m_s, 10.0, "m/s"),
            ("aids.zaru_sigma_deg_s", x.zaru_sigma_deg_s, 100.0, "deg/s"),
            ("aids.standstill_window_s", x.standstill_window_s, 60.0, "s"),
            (
                "aids.standstill_accel_std_m_s2",
                x.standstill_accel_std_m_s2,
                100.0,
                "m/s²",
            ),
            (
                "aids.standstill_gyro_std_deg_s",
                x.standstill_gyro_std_deg_s,
                1000.0,
                "deg/s",
            ),
            ("aids.nhc_sigma_m_s", x.nhc_sigma_m_s, 100.0, "m/s"),
            (
                "aids.nhc_max_yaw_rate_deg_s",
                x.nhc_max_yaw_rate_deg_s,
                10_000.0,
                "deg/s",
            ),
        ] {
            positive(k, v, max, unit)?;
        }
        nonneg("aids.standstill_min_s", x.standstill_min_s, 3600.0, "s")?;
        nonneg(
            "aids.standstill_max_speed_m_s",
            x.standstill_max_speed_m_s,
            1000.0,
            "m/s",
        )?;
        nonneg("aids.nhc_min_speed_m_s", x.nhc_min_speed_m_s, 1000.0, "m/s")?;
        Ok(())
    }

    /// The `[outages]` values: the window specification and the convergence times.
    fn validate_outages(&self) -> Result<(), KeyError> {
        let o = &self.outages;
        o.spec
            .parse::<crate::nav::outage::OutageSpec>()
            .map_err(|e| key_err("outages.spec", e.to_string()))?;
        nonneg("outages.converge_s", o.converge_s, 1e7, "s")?;
        nonneg("outages.reconverge_s", o.reconverge_s, 1e7, "s")?;
        Ok(())
    }
}

pub(super) fn check_angles(key: &str, v: [f64; 3]) -> Result<(), KeyError> {
    if v.iter().all(|a| a.is_finite() && a.abs() <= 360.0) {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!(
                "{v:?}: angles in degrees, each within ±360° (were radians or another unit meant?)"
            ),
        ))
    }
}

pub(super) fn nonneg(key: &str, v: f64, max: f64, unit: &str) -> Result<(), KeyError> {
    if v.is_finite() && (0.0..=max).contains(&v) {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!("{v} {unit}: must be ≥ 0 and ≤ {max} {unit}"),
        ))
    }
}

pub(super) fn positive(key: &str, v: f64, max: f64, unit: &str) -> Result<(), KeyError> {
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(())
    } else {
        Err(key_err(
            key,
            format!("{v} {unit}: must be > 0 and ≤ {max} {unit}"),
        ))
    }
}

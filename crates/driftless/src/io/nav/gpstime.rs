//! GPS time (GPST) helpers: calendar date and time in the GPST scale ↔ (GPS week, seconds of
//! week). GPST has no leap seconds, so these conversions are plain calendar arithmetic
//! (proleptic Gregorian calendar); converting to or from UTC needs the leap-second count
//! and is deliberately not offered here.
//!
//! The GPS epoch (week 0, 0 s) is 1980-01-06 00:00:00 GPST. RTKLIB's `gtime_t` counts
//! GPST seconds from 1970-01-01 00:00:00 in the same calendar (no leap seconds), which
//! [`GpsTime::from_gtime`] converts.

/// Seconds in one GPS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;
/// Seconds in one day.
const SECONDS_PER_DAY: i64 = 86_400;
/// Days from 1970-01-01 to the GPS epoch 1980-01-06.
const GPS_EPOCH_DAYS_FROM_1970: i64 = 3_657;

/// A GPS time: week number and seconds into the week.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsTime {
    /// Full GPS week number (not modulo 1024).
    pub week: u16,
    /// Seconds of week, in [0, 604 800).
    pub sow_s: f64,
}

/// A calendar date and time of day (GPST scale).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calendar {
    /// Year, e.g. 2025.
    pub year: i32,
    /// Month 1–12.
    pub month: u32,
    /// Day of month 1–31.
    pub day: u32,
    /// Hour 0–23.
    pub hour: u32,
    /// Minute 0–59.
    pub minute: u32,
    /// Seconds, in [0, 60).
    pub second: f64,
}

/// Days since 1970-01-01 of a proleptic Gregorian date (era-based civil-day count).
fn days_from_civil(year: i32, month: u32, day: u32) -> i64 {
    let y = i64::from(year) - i64::from(month <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400; // [0, 399]
    let m = i64::from(month);
    let mp = (m + 9) % 12; // March = 0
    let doy = (153 * mp + 2) / 5 + i64::from(day) - 1; // [0, 365]
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy; // [0, 146096]
    era * 146_097 + doe - 719_468
}

/// Inverse of [`days_from_civil`].
fn civil_from_days(days: i64) -> (i32, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = (yoe + era * 400 + i64::from(month <= 2)) as i32;
    (year, month, day)
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        2 => 28,
        _ => 0,
    }
}

impl Calendar {
    /// True when every field is in range (month 1–12, a day that exists, hour < 24,
    /// minute < 60, 0 ≤ second < 60).
    pub fn is_valid(&self) -> bool {
        (1..=12).contains(&self.month)
            && self.day >= 1
            && self.day <= days_in_month(self.year, self.month)
            && self.hour < 24
            && self.minute < 60
            && self.second.is_finite()
            && (0.0..60.0).contains(&self.second)
    }
}

impl GpsTime {
    /// GPS time of a GPST calendar date and time; `None` when the calendar fields are out
    /// of range or the time is before the GPS epoch or after week 65 535.
    pub fn from_calendar(c: &Calendar) -> Option<GpsTime> {
        if !c.is_valid() {
            return None;
        }
        let days = days_from_civil(c.year, c.month, c.day) - GPS_EPOCH_DAYS_FROM_1970;
        if days < 0 {
            return None;
        }
        let week = days / 7;
        let week = u16::try_from(week).ok()?;
        let sow_s = ((days % 7) * SECONDS_PER_DAY) as f64
            + f64::from(c.hour * 3600 + c.minute * 60)
            + c.second;
        Some(GpsTime { week, sow_s })
    }

    /// The GPST calendar date and time of this GPS time (seconds of week may be outside
    /// [0, 604 800); they are carried into the date).
    pub fn to_calendar(&self) -> Calendar {
        let whole = self.sow_s.floor();
        let frac = self.sow_s - whole;
        let total = i64::from(self.week) * 7 * SECONDS_PER_DAY + whole as i64;
        let days = total.div_euclid(SECONDS_PER_DAY);
        let sod = total.rem_euclid(SECONDS_PER_DAY);
        let (year, month, day) = civil_from_days(days + GPS_EPOCH_DAYS_FROM_1970);
        Calendar {
            year,
            month,
            day,
            hour: (sod / 3600) as u32,
            minute: ((sod % 3600) / 60) as u32,
            second: (sod % 60) as f64 + frac,
        }
    }

    /// GPS time of an RTKLIB `gtime_t` (`time`: whole GPST seconds since 1970-01-01,
    /// `sec`: fraction); `None` before the GPS epoch or past week 65 535.
    pub fn from_gtime(time: i64, sec: f64) -> Option<GpsTime> {
        let since = time.checked_sub(GPS_EPOCH_DAYS_FROM_1970 * SECONDS_PER_DAY)?;
        if since < 0 || !sec.is_finite() {
            return None;
        }
        let week = u16::try_from(since / (7 * SECONDS_PER_DAY)).ok()?;
        let sow_s = (since % (7 * SECONDS_PER_DAY)) as f64 + sec;
        Some(GpsTime { week, sow_s })
    }

    /// Seconds from the start of week `week` (may exceed a week or be negative).
    pub fn seconds_since_week(&self, week: u16) -> f64 {
        (f64::from(self.week) - f64::from(week)) * SECONDS_PER_WEEK + self.sow_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cal(y: i32, mo: u32, d: u32, h: u32, mi: u32, s: f64) -> Calendar {
        Calendar {
            year: y,
            month: mo,
            day: d,
            hour: h,
            minute: mi,
            second: s,
        }
    }

    #[test]
    fn known_dates() {
        // GPS epoch.
        let t = GpsTime::from_calendar(&cal(1980, 1, 6, 0, 0, 0.0)).unwrap();
        assert_eq!((t.week, t.sow_s), (0, 0.0));
        // Start of the drive_0708 RTK solution (Python datetime gives week 2374, 243258 s).
        let t = GpsTime::from_calendar(&cal(2025, 7, 8, 19, 34, 18.0)).unwrap();
        assert_eq!(t.week, 2374);
        assert_eq!(t.sow_s, 243_258.0);
        // First week-number rollover (1999-08-22 = week 1024).
        let t = GpsTime::from_calendar(&cal(1999, 8, 22, 0, 0, 0.0)).unwrap();
        assert_eq!((t.week, t.sow_s), (1024, 0.0));
        // Second rollover (2019-04-07 = week 2048).
        let t = GpsTime::from_calendar(&cal(2019, 4, 7, 0, 0, 0.0)).unwrap();
        assert_eq!((t.week, t.sow_s), (2048, 0.0));
        // Leap day, Thursday 2024-02-29 23:59:59.5: week 2303, day 4.
        let t = GpsTime::from_calendar(&cal(2024, 2, 29, 23, 59, 59.5)).unwrap();
        assert_eq!(t.week, 2303);
        assert_eq!(t.sow_s, 4.0 * 86_400.0 + 86_399.5);
    }

    #[test]
    fn round_trip_and_rejects() {
        for &(w, s) in &[(0u16, 0.0), (2374, 243_258.25), (2047, 604_799.5), (1, 1.0)] {
            let c = GpsTime { week: w, sow_s: s }.to_calendar();
            let back = GpsTime::from_calendar(&c).unwrap();
            assert_eq!(back.week, w);
            assert!((back.sow_s - s).abs() < 1e-9, "{s} -> {c:?} -> {back:?}");
        }
        assert!(GpsTime::from_calendar(&cal(1980, 1, 5, 23, 59, 59.0)).is_none());
        assert!(GpsTime::from_calendar(&cal(2023, 2, 29, 0, 0, 0.0)).is_none());
        assert!(GpsTime::from_calendar(&cal(2025, 13, 1, 0, 0, 0.0)).is_none());
        assert!(GpsTime::from_calendar(&cal(2025, 1, 1, 24, 0, 0.0)).is_none());
        assert!(GpsTime::from_calendar(&cal(2025, 1, 1, 0, 0, 60.0)).is_none());
    }

    #[test]
    fn gtime() {
        // 1752003261 s after 1970-01-01 (GPST scale) is 2025-07-08 19:34:21.
        let t = GpsTime::from_gtime(1_752_003_261, 0.854).unwrap();
        assert_eq!(t.week, 2374);
        assert!((t.sow_s - 243_261.854).abs() < 1e-9);
        assert!(GpsTime::from_gtime(0, 0.0).is_none());
        assert_eq!(t.seconds_since_week(2373), 604_800.0 + t.sow_s);
    }
}

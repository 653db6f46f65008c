//! GPS time (GPST) helpers: calendar date and time in the GPST scale ↔ (GPS week, seconds of
//! week), and the time bases an IMU log's time column may use ([`TimeBase`]).
//!
//! GPST has no leap seconds, so GPST calendar conversions are plain calendar arithmetic
//! (proleptic Gregorian calendar). The GPS epoch (week 0, 0 s) is 1980-01-06 00:00:00 GPST.
//! RTKLIB's `gtime_t` counts GPST seconds from 1970-01-01 00:00:00 in the same calendar (no
//! leap seconds), which [`GpsTime::from_gtime`] converts.
//!
//! **UTC.** GPST = UTC + (GPS − UTC), where GPS − UTC is a whole number of leap seconds
//! that grows each time the IERS inserts one: [`gps_minus_utc_s`] looks it up in
//! `LEAP_SECONDS` (18 s since 2017-01-01). Unix time counts UTC days of 86 400 s, so
//! Unix seconds map to a UTC calendar date without leap seconds, and the table is indexed
//! by that date.

/// Seconds in one GPS week.
pub(crate) const SECONDS_PER_WEEK: f64 = 604_800.0;
/// Seconds in one day.
const SECONDS_PER_DAY: i64 = 86_400;
/// Days from 1970-01-01 to the GPS epoch 1980-01-06.
const GPS_EPOCH_DAYS_FROM_1970: i64 = 3_657;

/// Days from 1970-01-01 to the GPS epoch, as Unix seconds: 1980-01-06 00:00:00 is
/// 3 657 × 86 400 = 315 964 800 s after 1970-01-01 00:00:00 in either scale (GPS − UTC was 0).
pub(crate) const GPS_EPOCH_UNIX_S: f64 = 315_964_800.0;

/// GPS − UTC leap seconds: (first UTC day it applies, as (year, month, day); GPS − UTC, s).
///
/// Source: IERS Bulletin C (the TAI − UTC history, <https://hpiers.obspm.fr/eop-pc/>);
/// GPS − UTC = (TAI − UTC) − 19 s, since GPST was set to UTC at the GPS epoch when
/// TAI − UTC was 19 s. Each leap second was inserted at 23:59:60 UTC of the day before the
/// date given. No leap second has been inserted since 2017-01-01, and the IERS Bulletins C
/// published up to the end of 2025 announce none; a later announcement needs a new row here.
pub(crate) const LEAP_SECONDS: [((i32, u32, u32), i32); 18] = [
    ((1981, 7, 1), 1),
    ((1982, 7, 1), 2),
    ((1983, 7, 1), 3),
    ((1985, 7, 1), 4),
    ((1988, 1, 1), 5),
    ((1990, 1, 1), 6),
    ((1991, 1, 1), 7),
    ((1992, 7, 1), 8),
    ((1993, 7, 1), 9),
    ((1994, 7, 1), 10),
    ((1996, 1, 1), 11),
    ((1997, 7, 1), 12),
    ((1999, 1, 1), 13),
    ((2006, 1, 1), 14),
    ((2009, 1, 1), 15),
    ((2012, 7, 1), 16),
    ((2015, 7, 1), 17),
    ((2017, 1, 1), 18),
];

/// A time stamp that cannot be converted to GPS time.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TimeBaseError {
    /// Before 1980-01-06 00:00:00 (GPS week 0 starts there).
    #[error(
        "time {value_s} s ({base}) lies before the GPS epoch 1980-01-06 00:00:00; check the time base and the time unit"
    )]
    BeforeGpsEpoch {
        /// The time stamp, s, in `base`.
        value_s: f64,
        /// The time base's name.
        base: &'static str,
    },
    /// NaN or infinite.
    #[error("time {value_s} s ({base}) is not finite")]
    NonFinite {
        /// The value.
        value_s: f64,
        /// The time base's name.
        base: &'static str,
    },
    /// Past GPS week 65 535.
    #[error("time {value_s} s ({base}) lies past GPS week 65535")]
    PastLastWeek {
        /// The value.
        value_s: f64,
        /// The time base's name.
        base: &'static str,
    },
}

/// GPS − UTC, s, at the UTC instant `unix_utc_s` (Unix seconds: UTC days × 86 400 + seconds
/// of the UTC day), from `LEAP_SECONDS`; 0 before 1981-07-01. Errors before the GPS epoch.
///
/// A Unix time inside an inserted leap second (23:59:60, which Unix time cannot name) reads
/// as the following day's 00:00:00, i.e. with the new count.
pub fn gps_minus_utc_s(unix_utc_s: f64) -> Result<i32, TimeBaseError> {
    let base = TimeBase::UtcUnix.name();
    if !unix_utc_s.is_finite() {
        return Err(TimeBaseError::NonFinite {
            value_s: unix_utc_s,
            base,
        });
    }
    if unix_utc_s < GPS_EPOCH_UNIX_S {
        return Err(TimeBaseError::BeforeGpsEpoch {
            value_s: unix_utc_s,
            base,
        });
    }
    let day = (unix_utc_s / SECONDS_PER_DAY as f64).floor() as i64;
    Ok(LEAP_SECONDS
        .iter()
        .rev()
        .find(|((y, m, d), _)| day >= days_from_civil(*y, *m, *d))
        .map_or(0, |&(_, n)| n))
}

/// What an IMU log's time column counts. The navigation filter works in GPS seconds of week;
/// [`TimeBase::to_gps_week_seconds`] converts stamps of any base to GPS week + seconds of week.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeBase {
    /// GPS seconds of week (GPST, no leap seconds), the filter's own time (`gps-sow`).
    #[default]
    GpsSecondsOfWeek,
    /// GPS seconds of week in one column and the GPS week number in another
    /// (`gps-week-sow`); the text reader combines them (`TextOptions::week_column`).
    GpsWeekAndSeconds,
    /// Seconds since 1970-01-01 00:00:00 counted in the GPST scale, i.e. without leap
    /// seconds, as RTKLIB's `gtime_t` (`gpst-unix`): GPS s = t − 315 964 800.
    GpstUnix,
    /// Ordinary Unix time, UTC (`utc-unix`): GPS s = t − 315 964 800 + (GPS − UTC)(t),
    /// with the leap seconds of `LEAP_SECONDS`.
    UtcUnix,
}

/// A time-base name that is not one of the choices.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown time base {0:?}: expected gps-sow (GPS seconds of week), gps-week-sow (GPS week and seconds of week in two columns), gpst-unix (seconds since 1970 in the GPST scale) or utc-unix (Unix time, UTC)"
)]
pub struct ParseTimeBaseError(pub String);

impl std::str::FromStr for TimeBase {
    type Err = ParseTimeBaseError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "gps-sow" => Ok(TimeBase::GpsSecondsOfWeek),
            "gps-week-sow" => Ok(TimeBase::GpsWeekAndSeconds),
            "gpst-unix" => Ok(TimeBase::GpstUnix),
            "utc-unix" => Ok(TimeBase::UtcUnix),
            _ => Err(ParseTimeBaseError(s.to_owned())),
        }
    }
}

impl std::fmt::Display for TimeBase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl TimeBase {
    /// The name [`FromStr`](std::str::FromStr) accepts.
    pub fn name(self) -> &'static str {
        match self {
            TimeBase::GpsSecondsOfWeek => "gps-sow",
            TimeBase::GpsWeekAndSeconds => "gps-week-sow",
            TimeBase::GpstUnix => "gpst-unix",
            TimeBase::UtcUnix => "utc-unix",
        }
    }

    /// True for the bases whose stamps name the week themselves (the Unix ones).
    pub fn is_absolute(self) -> bool {
        matches!(self, TimeBase::GpstUnix | TimeBase::UtcUnix)
    }

    /// Seconds since the GPS epoch of a time stamp `t_s` in this base. For the week-based
    /// bases `week` is the week `t_s` counts from (`t_s` may pass 604 800 s or be the
    /// seconds of that week); without it they have no absolute time (`None`).
    pub(crate) fn gps_seconds(
        self,
        t_s: f64,
        week: Option<u16>,
    ) -> Result<Option<f64>, TimeBaseError> {
        let base = self.name();
        if !t_s.is_finite() {
            return Err(TimeBaseError::NonFinite { value_s: t_s, base });
        }
        let since_epoch = match self {
            TimeBase::GpsSecondsOfWeek | TimeBase::GpsWeekAndSeconds => {
                return Ok(week.map(|w| f64::from(w) * SECONDS_PER_WEEK + t_s));
            }
            TimeBase::GpstUnix => t_s - GPS_EPOCH_UNIX_S,
            TimeBase::UtcUnix => t_s - GPS_EPOCH_UNIX_S + f64::from(gps_minus_utc_s(t_s)?),
        };
        if since_epoch < 0.0 {
            return Err(TimeBaseError::BeforeGpsEpoch { value_s: t_s, base });
        }
        Ok(Some(since_epoch))
    }

    /// Converts time stamps of this base to GPS time: the GPS week of the first stamp and
    /// every stamp as seconds from the start of that week, so a log crossing a week
    /// boundary keeps increasing past 604 800 s (the convention of
    /// [`crate::io::nav::GnssFixes::time_s`]). The week-based bases pass the stamps through
    /// with `week` (the week they count from, when known); the Unix ones ignore `week`.
    ///
    /// Precision: a Unix stamp near 1.8 × 10⁹ s is held to ±2.4 × 10⁻⁷ s by f64; the
    /// result is exact given that value (the subtracted whole seconds are exact).
    pub fn to_gps_week_seconds(
        self,
        time_s: &[f64],
        week: Option<u16>,
    ) -> Result<(Option<u16>, Vec<f64>), TimeBaseError> {
        if !self.is_absolute() {
            return Ok((week, time_s.to_vec()));
        }
        let Some(&first) = time_s.first() else {
            return Ok((None, Vec::new()));
        };
        let first_gps = self.gps_seconds(first, None)?.unwrap_or(0.0);
        let leap0 = match self {
            TimeBase::UtcUnix => f64::from(gps_minus_utc_s(first)?),
            _ => 0.0,
        };
        let mut week0 = (first_gps / SECONDS_PER_WEEK).floor();
        // The rounded quotient may land on the next week by a hair: the first stamp's
        // seconds of week, computed exactly below, must be ≥ 0.
        if (first - (week0 * SECONDS_PER_WEEK + GPS_EPOCH_UNIX_S)) + leap0 < 0.0 {
            week0 -= 1.0;
        }
        let Ok(w) = u16::try_from(week0 as i64) else {
            return Err(TimeBaseError::PastLastWeek {
                value_s: first,
                base: self.name(),
            });
        };
        let start = week0 * SECONDS_PER_WEEK + GPS_EPOCH_UNIX_S;
        let mut out = Vec::with_capacity(time_s.len());
        for &t in time_s {
            // (t − epoch) − week start, grouped so the subtracted whole seconds stay exact.
            let leap = match self {
                TimeBase::UtcUnix => f64::from(gps_minus_utc_s(t)?),
                _ => {
                    if !t.is_finite() {
                        return Err(TimeBaseError::NonFinite {
                            value_s: t,
                            base: self.name(),
                        });
                    }
                    0.0
                }
            };
            out.push((t - start) + leap);
        }
        Ok((Some(w), out))
    }
}

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
    pub(crate) fn is_valid(&self) -> bool {
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
    pub(crate) fn from_calendar(c: &Calendar) -> Option<GpsTime> {
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
    pub(crate) fn seconds_since_week(&self, week: u16) -> f64 {
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
    fn time_base_names() {
        for b in [
            TimeBase::GpsSecondsOfWeek,
            TimeBase::GpsWeekAndSeconds,
            TimeBase::GpstUnix,
            TimeBase::UtcUnix,
        ] {
            assert_eq!(b.name().parse::<TimeBase>().unwrap(), b);
            assert_eq!(b.to_string(), b.name());
        }
        assert_eq!(" UTC-Unix ".parse::<TimeBase>(), Ok(TimeBase::UtcUnix));
        let e = "unix".parse::<TimeBase>().unwrap_err().to_string();
        for choice in [
            "gps-sow",
            "gps-week-sow",
            "gpst-unix",
            "utc-unix",
            "\"unix\"",
        ] {
            assert!(e.contains(choice), "{e}");
        }
    }

    #[test]
    fn leap_seconds_by_date() {
        let unix = |y, m, d, sod: i64| (days_from_civil(y, m, d) * 86_400 + sod) as f64;
        // 1970-01-01 + 3657 days is the GPS epoch.
        assert_eq!(unix(1980, 1, 6, 0), GPS_EPOCH_UNIX_S);
        assert_eq!(gps_minus_utc_s(GPS_EPOCH_UNIX_S), Ok(0));
        assert_eq!(gps_minus_utc_s(unix(1981, 6, 30, 86_399)), Ok(0));
        assert_eq!(gps_minus_utc_s(unix(1981, 7, 1, 0)), Ok(1));
        assert_eq!(gps_minus_utc_s(unix(2016, 12, 31, 86_399)), Ok(17));
        assert_eq!(gps_minus_utc_s(unix(2017, 1, 1, 0)), Ok(18));
        assert_eq!(gps_minus_utc_s(unix(2026, 1, 1, 0)), Ok(18));
        assert!(matches!(
            gps_minus_utc_s(GPS_EPOCH_UNIX_S - 0.5),
            Err(TimeBaseError::BeforeGpsEpoch { .. })
        ));
        assert!(gps_minus_utc_s(f64::NAN).is_err());
        // The table is sorted and grows by one second per row.
        for (k, w) in LEAP_SECONDS.windows(2).enumerate() {
            let (a, b) = (w[0].0, w[1].0);
            assert!(days_from_civil(a.0, a.1, a.2) < days_from_civil(b.0, b.1, b.2));
            assert_eq!(w[1].1, w[0].1 + 1, "row {k}");
        }
    }

    #[test]
    fn time_bases_closed_form() {
        // 2026-01-01T00:00:00 UTC: 56 years after 1970 with 14 leap days (1972…2024) is
        // 20 454 days, Unix 1 767 225 600 s. GPS days: 20 454 − 3 657 = 16 797 = 7 × 2 399 + 4,
        // so GPS week 2399, day 4 (Thursday); GPST = UTC + 18 s → SOW 4 × 86 400 + 18 = 345 618.
        let utc = 1_767_225_600.0;
        let (w, t) = TimeBase::UtcUnix
            .to_gps_week_seconds(&[utc, utc + 0.25], None)
            .unwrap();
        assert_eq!(w, Some(2399));
        assert_eq!(t, vec![345_618.0, 345_618.25]);
        // The same instant in GPST-scale Unix seconds is 18 s later on that count.
        let (w, t) = TimeBase::GpstUnix
            .to_gps_week_seconds(&[utc + 18.0], None)
            .unwrap();
        assert_eq!((w, t[0]), (Some(2399), 345_618.0));
        // And it is that calendar date in GPST.
        let c = GpsTime {
            week: 2399,
            sow_s: 345_618.0,
        }
        .to_calendar();
        assert_eq!(
            (c.year, c.month, c.day, c.hour, c.minute),
            (2026, 1, 1, 0, 0)
        );
        assert_eq!(c.second, 18.0);
        // Absolute GPS seconds round-trip.
        assert_eq!(
            TimeBase::UtcUnix.gps_seconds(utc, None).unwrap(),
            Some(2399.0 * SECONDS_PER_WEEK + 345_618.0)
        );
        // Week-based bases pass through with their week.
        assert_eq!(
            TimeBase::GpsWeekAndSeconds
                .to_gps_week_seconds(&[604_799.5, 604_800.5], Some(2399))
                .unwrap(),
            (Some(2399), vec![604_799.5, 604_800.5])
        );
        assert_eq!(
            TimeBase::GpsSecondsOfWeek
                .gps_seconds(10.0, Some(1))
                .unwrap(),
            Some(604_810.0)
        );
        assert_eq!(TimeBase::GpsSecondsOfWeek.gps_seconds(10.0, None), Ok(None));
    }

    #[test]
    fn unix_week_rollover_and_epoch() {
        // Saturday 2026-01-03 23:59:41 UTC = 23:59:59 GPST, the last second of GPS week
        // 2399: SOW 6 × 86 400 + 86 399 = 604 799; the next second starts week 2400.
        let sat = 1_767_225_600.0 + 2.0 * 86_400.0 + 86_399.0 - 18.0; // 23:59:41 UTC
        let (w, t) = TimeBase::UtcUnix
            .to_gps_week_seconds(&[sat, sat + 1.0, sat + 2.0], None)
            .unwrap();
        assert_eq!(w, Some(2399));
        // Seconds continue past the week's end instead of restarting at 0.
        assert_eq!(t, vec![604_799.0, 604_800.0, 604_801.0]);
        let e = TimeBase::GpstUnix
            .to_gps_week_seconds(&[100.0], None)
            .unwrap_err();
        assert!(e.to_string().contains("before the GPS epoch"), "{e}");
        assert!(
            TimeBase::UtcUnix
                .to_gps_week_seconds(&[f64::INFINITY], None)
                .is_err()
        );
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

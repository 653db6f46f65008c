//! Checks of a log *before* a thermal fit: can this recording give a thermal model, by
//! the ramp method ([`super::ramp`]), the soak method ([`super::soak`]), or neither — and
//! why. These are the failures autopilot users meet with their thermal calibrations:
//! temperature quantised to 1 °C, too little rise (ArduPilot's own calibration asks for
//! at least 10 °C), uneven heating, the board moved during a ramp, drop-outs.
//!
//! [`check_log`] measures, on one IMU instance ([`ImuLog`]):
//!
//! * **Temperature**: range and rise (the 0.5 % and 99.5 % quantiles, so a single spike
//!   does not count as rise), the resolution (LSB: median spacing of the distinct
//!   readings), and the number of 1 °C-wide levels holding at least
//!   [`CheckOptions::min_samples_per_level`] samples — the bins the ramp fit uses.
//! * **Heating-rate profile**: dT/dt by least squares over consecutive windows of
//!   `w = max(rate_window_s, 5·LSB/(rise/duration))` (at least five LSB of change per window,
//!   so a quantised reading still gives a slope); windows with |dT/dt| below
//!   [`CheckOptions::flat_c_per_min`] are flat, the others heating or cooling.
//!   **Unevenness** is the ratio of the 90th to the 10th percentile of the time spent per
//!   1 °C level, per direction (heating samples and cooling samples apart; each
//!   direction's first and last level, covered only in part, left out), the larger of
//!   the two: the weight a per-sample fit would give each degree. Runs of flat windows
//!   lasting [`CheckOptions::plateau_min_s`] are plateaus (the set temperatures of a
//!   soak).
//! * **Motion**: per window of [`CheckOptions::motion_window_s`], the mean gyro vector
//!   against the median of its neighbours (±30 windows), and the tilt of the mean
//!   specific force against the neighbours' median and against the whole log's median
//!   direction. A window is moving when |Δω| > [`CheckOptions::gyro_motion_rad_s`] or
//!   the tilt exceeds [`CheckOptions::tilt_motion_rad`] (neighbours) or twice that (whole
//!   log). Slow thermal drift changes neither over a minute; a handling or a new
//!   orientation does.
//! * **Gaps**: the reader's time gaps ([`ImuLog::gaps`]) and the temperature change
//!   across each.
//!
//! Verdict ([`ThermalCheck::fit_for_ramp`], [`ThermalCheck::fit_for_soak`]): each
//! [`Finding`] says how it affects each method ([`Impact`]); a method is fit when no
//! finding blocks it. A ramp needs a temperature rise of at least
//! [`CheckOptions::min_rise_c`], at least `order + 2` populated 1 °C levels, gyro or
//! accelerometer channels and a static sensor. A soak (judged from the log alone, without
//! its manifest) needs at least `order + 2` plateaus at least 2 °C apart spanning
//! `min_rise_c`, each with the six static orientations (every axis up and down) of the
//! six-position calibration. Coarse resolution, uneven heating and gaps are warnings:
//! the ramp's per-bin points already stop a slow stretch from outweighing a fast one and
//! the bin means recover sub-LSB values from dithered readings, but the user should know.
//!
//! Everything here is an observation of the data, with thresholds in [`CheckOptions`]
//! whose defaults hold for any platform (none is tuned to a dataset).

use serde::Serialize;

use crate::io::{ImuLog, Quantity};

mod excursion;
mod heating;
mod motion;
pub use excursion::*;
use heating::*;
use motion::*;

/// Thresholds of the checks (module docs). The defaults are platform-neutral.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckOptions {
    /// Smallest temperature rise (max − min) a model needs, °C (default 10, ArduPilot's
    /// requirement for its thermal calibration).
    pub min_rise_c: f64,
    /// A resolution at or above this is flagged as coarse, °C (default 0.5).
    pub coarse_lsb_c: f64,
    /// Polynomial order the model will have (default 3): a ramp needs `order + 2`
    /// populated levels, a soak `order + 2` plateaus.
    pub order: usize,
    /// Samples a 1 °C level needs to count (default 50, the ramp's default per bin).
    pub min_samples_per_level: usize,
    /// Shortest window of the heating-rate profile, s (default 60).
    pub rate_window_s: f64,
    /// |dT/dt| below this is flat, °C/min (default 0.05).
    pub flat_c_per_min: f64,
    /// Unevenness (p90/p10 of the time per 1 °C level, module docs) above this is
    /// flagged (default 5).
    pub uneven_ratio: f64,
    /// Shortest plateau, s (default 120).
    pub plateau_min_s: f64,
    /// Motion window, s (default 1).
    pub motion_window_s: f64,
    /// Gyro change against the neighbours that counts as motion, rad/s (default 0.02,
    /// 1.1 °/s — far above any thermal bias change within a minute).
    pub gyro_motion_rad_s: f64,
    /// Tilt against the neighbours that counts as motion, rad (default 0.035, 2°).
    pub tilt_motion_rad: f64,
    /// A ramp with more than this fraction of moving windows is refused (default 0.01).
    pub max_moving_fraction: f64,
    /// A gap across which the temperature moves more than this is flagged, °C
    /// (default 1, one bin).
    pub gap_temperature_c: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            min_rise_c: 10.0,
            coarse_lsb_c: 0.5,
            order: 3,
            min_samples_per_level: 50,
            rate_window_s: 60.0,
            flat_c_per_min: 0.05,
            uneven_ratio: 5.0,
            plateau_min_s: 120.0,
            motion_window_s: 1.0,
            gyro_motion_rad_s: 0.02,
            tilt_motion_rad: 0.035,
            max_moving_fraction: 0.01,
            gap_temperature_c: 1.0,
        }
    }
}

/// A time span of the log, s (the log's own time axis).
pub use crate::data::TimeSpan;

/// How a finding affects a method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Impact {
    /// Not relevant.
    None,
    /// The fit can be made, but its quality suffers.
    Warn,
    /// The method cannot give a model from this log.
    Block,
}

/// What a finding is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// No samples, or no time stamps.
    NoData,
    /// No temperature channel.
    NoTemperature,
    /// A NaN or infinite temperature.
    BadTemperature,
    /// No gyro or accelerometer channel.
    NoInertial,
    /// Temperature rise below [`CheckOptions::min_rise_c`].
    TooLittleRise,
    /// Resolution at or above [`CheckOptions::coarse_lsb_c`].
    CoarseResolution,
    /// Fewer than `order + 2` populated 1 °C levels.
    TooFewLevels,
    /// Heating rate uneven beyond [`CheckOptions::uneven_ratio`].
    UnevenHeating,
    /// The sensor moved.
    Motion,
    /// Time gaps.
    Gaps,
    /// Too few temperature plateaus for a soak.
    TooFewPlateaus,
    /// Plateaus without the six static orientations.
    MissingOrientations,
}

/// One observation and what it means for each method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// What.
    pub kind: FindingKind,
    /// Effect on the ramp method.
    pub ramp: Impact,
    /// Effect on the soak method.
    pub soak: Impact,
    /// Where in the log (first offending span), when it is local.
    pub span: Option<TimeSpan>,
    /// The observation with its numbers and what to change.
    pub message: String,
}

/// Temperature summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TemperatureSummary {
    /// 0.5 % quantile, °C.
    pub min_c: f64,
    /// 99.5 % quantile, °C.
    pub max_c: f64,
    /// First reading, °C.
    pub start_c: f64,
    /// Last reading, °C.
    pub end_c: f64,
    /// max_c − min_c, °C.
    pub rise_c: f64,
    /// Resolution (median spacing of distinct readings), °C; 0 with one distinct value.
    pub lsb_c: f64,
    /// Distinct readings.
    pub distinct_readings: usize,
    /// 1 °C levels (round(T)) with at least `min_samples_per_level` samples.
    pub populated_levels: usize,
}

/// A temperature plateau.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plateau {
    /// Where.
    pub span: TimeSpan,
    /// Mean temperature, °C.
    pub mean_c: f64,
    /// Static orientations seen (faces ±x, ±y, ±z of gravity), 0–6.
    pub orientations: usize,
}

/// Heating-rate profile.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeatingProfile {
    /// Window length used, s.
    pub window_s: f64,
    /// Windows.
    pub windows: usize,
    /// Fraction of windows heating / cooling / flat.
    pub heating_fraction: f64,
    /// Fraction cooling.
    pub cooling_fraction: f64,
    /// Fraction flat.
    pub flat_fraction: f64,
    /// 10th, 50th, 90th percentile of |dT/dt| over changing windows, °C/min (0 when none).
    pub rate_p10_c_per_min: f64,
    /// Median.
    pub rate_median_c_per_min: f64,
    /// 90th percentile.
    pub rate_p90_c_per_min: f64,
    /// Fastest window, °C/min (signed).
    pub rate_max_c_per_min: f64,
    /// p90/p10 of the time per 1 °C level, the larger of heating and cooling (module
    /// docs); 1 when no direction has three inner levels.
    pub unevenness: f64,
    /// 10th and 90th percentile of the time per 1 °C level in that direction, s.
    pub dwell_p10_p90_s: [f64; 2],
    /// Plateaus.
    pub plateaus: Vec<Plateau>,
}

/// Motion summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MotionSummary {
    /// Window length, s.
    pub window_s: f64,
    /// Windows.
    pub windows: usize,
    /// Fraction of moving windows.
    pub moving_fraction: f64,
    /// Largest gyro change against the neighbours, rad/s.
    pub max_gyro_change_rad_s: f64,
    /// Largest tilt against the whole log's median direction, rad.
    pub max_tilt_rad: f64,
    /// Moving spans (merged windows), at most the first 20.
    pub moving_spans: Vec<TimeSpan>,
}

/// Gap summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapSummary {
    /// Number of gaps.
    pub count: usize,
    /// Longest, s.
    pub longest_s: f64,
    /// Total, s.
    pub total_s: f64,
    /// Largest temperature change across a gap, °C.
    pub max_temperature_jump_c: f64,
}

/// The checks of one IMU instance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ThermalCheck {
    /// What was checked (file, instance).
    pub label: String,
    /// Samples.
    pub samples: usize,
    /// Time span, s.
    pub span: Option<TimeSpan>,
    /// Sample interval τ0, s.
    pub tau0_s: f64,
    /// Temperature (None without a usable temperature channel).
    pub temperature: Option<TemperatureSummary>,
    /// Heating-rate profile (None without temperature and time).
    pub heating: Option<HeatingProfile>,
    /// Motion (None without gyro and accelerometer triads).
    pub motion: Option<MotionSummary>,
    /// Gaps.
    pub gaps: GapSummary,
    /// Findings, in check order.
    pub findings: Vec<Finding>,
    /// No finding blocks the ramp method.
    pub fit_for_ramp: bool,
    /// No finding blocks the soak method.
    pub fit_for_soak: bool,
}

impl ThermalCheck {
    /// "ramp and soak", "ramp", "soak" or "neither".
    pub fn verdict(&self) -> &'static str {
        match (self.fit_for_ramp, self.fit_for_soak) {
            (true, true) => "ramp and soak",
            (true, false) => "ramp",
            (false, true) => "soak",
            (false, false) => "neither",
        }
    }

    /// The findings that block `ramp` (true) or soak (false), their messages joined.
    pub(crate) fn blocking(&self, ramp: bool) -> Vec<&Finding> {
        self.findings
            .iter()
            .filter(|f| (if ramp { f.ramp } else { f.soak }) == Impact::Block)
            .collect()
    }

    /// The first finding of `kind`.
    pub fn finding(&self, kind: FindingKind) -> Option<&Finding> {
        self.findings.iter().find(|f| f.kind == kind)
    }
}

/// Value at quantile `q` (0–1) of sorted `v` (nearest rank); 0 for empty.
fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

/// Median of `v` (mean of the middle two for even lengths; reorders it); 0 when empty.
fn median_of(v: &mut [f64]) -> f64 {
    crate::numeric::median(v).unwrap_or(0.0)
}

/// Least-squares slope of y on t over `range`, per second (0 with < 2 distinct times).
fn slope(t: &[f64], y: &[f64], range: std::ops::Range<usize>) -> f64 {
    let n = range.len() as f64;
    if range.len() < 2 {
        return 0.0;
    }
    let tm = t[range.clone()].iter().sum::<f64>() / n;
    let ym = y[range.clone()].iter().sum::<f64>() / n;
    let (mut sty, mut stt) = (0.0, 0.0);
    for i in range {
        sty += (t[i] - tm) * (y[i] - ym);
        stt += (t[i] - tm).powi(2);
    }
    if stt > 0.0 { sty / stt } else { 0.0 }
}

/// Consecutive index ranges of `t` each spanning about `w` seconds (the last may be
/// shorter; dropped when under half a window).
fn windows(t: &[f64], w: f64) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let mut j = i + 1;
        while j < t.len() && t[j] - t[i] < w {
            j += 1;
        }
        if t[j - 1] - t[i] >= 0.5 * w || out.is_empty() {
            out.push(i..j);
        } else if let Some(last) = out.last_mut() {
            last.end = j;
        }
        i = j;
    }
    out
}

fn span_of(t: &[f64], r: &std::ops::Range<usize>) -> TimeSpan {
    TimeSpan {
        start_s: t[r.start],
        end_s: t[r.end - 1],
    }
}

fn fmt_span(s: &TimeSpan) -> String {
    format!("{:.1}–{:.1} s", s.start_s, s.end_s)
}

/// Checks one IMU instance (module docs). `label` names it in the report and in the
/// messages (file and instance). Never fails: what cannot be measured is a finding.
pub fn check_log(log: &ImuLog, label: &str, opts: &CheckOptions) -> ThermalCheck {
    let n = log.len();
    let mut findings = Vec::new();
    let time = sample_times(log);
    let gaps = gap_summary(log, &time);
    let mut report = ThermalCheck {
        label: label.to_owned(),
        samples: n,
        span: (!time.is_empty()).then(|| span_of(&time, &(0..n))),
        tau0_s: log.tau0_s,
        temperature: None,
        heating: None,
        motion: None,
        gaps,
        findings: Vec::new(),
        fit_for_ramp: false,
        fit_for_soak: false,
    };
    if n < 2 || time.len() != n {
        findings.push(blocks_both(
            FindingKind::NoData,
            format!(
                "{label}: {n} sample(s){}: a thermal fit needs a time-stamped recording \
                 (give a time column or --rate)",
                if time.len() == n { "" } else { " without time" }
            ),
            None,
        ));
        return finish(report, findings);
    }
    let temp = log
        .channels
        .iter()
        .find(|c| c.quantity == Quantity::Temperature);
    let gyro = log.triad_of(Quantity::AngularRate);
    let accel = log.triad_of(Quantity::SpecificForce);
    if gyro.is_none() && accel.is_none() {
        findings.push(blocks_both(
            FindingKind::NoInertial,
            format!(
                "{label}: no three gyro or three accelerometer channels with units: nothing \
                 to calibrate (give units, e.g. --column gyro_x:deg/s)"
            ),
            None,
        ));
    }
    let Some(temp) = temp else {
        findings.push(blocks_both(
            FindingKind::NoTemperature,
            format!(
                "{label}: no temperature channel: a thermal model needs the sensor \
                 temperature of every sample (a column with unit degC, or --column N:degC)"
            ),
            None,
        ));
        report.motion = motion_summary(&time, gyro, accel, opts);
        return finish(report, findings);
    };
    let tc = &temp.values;
    if let Some(finding) = bad_temperature_finding(&time, tc, label) {
        findings.push(finding);
        return finish(report, findings);
    }
    let ts = temperature_summary(tc, opts);
    temperature_findings(&ts, label, opts, &mut findings);
    let flags = motion_flags(&time, gyro, accel, opts);
    let motion = flags.as_ref().map(|f| f.3.clone());
    let heating = heating_profile(&time, tc, &ts, accel, flags.as_ref(), opts);
    findings.extend(uneven_heating_finding(&heating, label, opts));
    if let Some(m) = &motion
        && m.moving_fraction > 0.0
    {
        findings.push(motion_finding(m, label, opts));
    }
    findings.extend(gap_finding(log, &report.gaps, label, opts));
    soak_findings(&heating, label, opts, &mut findings);
    report.temperature = Some(ts);
    report.heating = Some(heating);
    report.motion = motion;
    finish(report, findings)
}

/// A finding that blocks both the ramp and the soak fit.
fn blocks_both(kind: FindingKind, message: String, span: Option<TimeSpan>) -> Finding {
    Finding {
        kind,
        ramp: Impact::Block,
        soak: Impact::Block,
        span,
        message,
    }
}

/// Sample times of `log`: its time column when complete, else `i·tau0_s`; empty when
/// neither is known.
fn sample_times(log: &ImuLog) -> Vec<f64> {
    let n = log.len();
    match &log.time_s {
        Some(t) if t.len() == n => t.clone(),
        _ if log.tau0_s > 0.0 => (0..n).map(|i| i as f64 * log.tau0_s).collect(),
        _ => Vec::new(),
    }
}

/// The blocking finding for the first non-finite temperature reading, if any.
fn bad_temperature_finding(time: &[f64], tc: &[f64], label: &str) -> Option<Finding> {
    let i = tc.iter().position(|v| !v.is_finite())?;
    Some(blocks_both(
        FindingKind::BadTemperature,
        format!(
            "{label}: temperature of sample {i} (t = {:.3} s) is {}: remove or repair \
             that sample",
            time[i], tc[i]
        ),
        Some(TimeSpan {
            start_s: time[i],
            end_s: time[i],
        }),
    ))
}

/// Findings on the temperature readings alone: too little rise, coarse resolution and
/// too few populated one-degree levels, in that order.
fn temperature_findings(
    ts: &TemperatureSummary,
    label: &str,
    opts: &CheckOptions,
    findings: &mut Vec<Finding>,
) {
    if ts.rise_c < opts.min_rise_c {
        findings.push(blocks_both(
            FindingKind::TooLittleRise,
            format!(
                "{label}: temperature {:.2}–{:.2} °C, a rise of {:.2} °C; a thermal model \
                 needs at least {:.1} °C (cold-soak the board, then let it warm up, or use \
                 a chamber)",
                ts.min_c, ts.max_c, ts.rise_c, opts.min_rise_c
            ),
            None,
        ));
    }
    if ts.lsb_c >= opts.coarse_lsb_c {
        findings.push(Finding {
            kind: FindingKind::CoarseResolution,
            ramp: Impact::Warn,
            soak: Impact::Warn,
            span: None,
            message: format!(
                "{label}: temperature resolution {:.3} °C ({} distinct readings): the true \
                 temperature moves unseen within a step, so bins are one LSB wide at best; \
                 read the sensor's temperature register at full resolution if it has one",
                ts.lsb_c, ts.distinct_readings
            ),
        });
    }
    if ts.populated_levels < opts.order + 2 {
        findings.push(Finding {
            kind: FindingKind::TooFewLevels,
            ramp: Impact::Block,
            soak: Impact::None,
            span: None,
            message: format!(
                "{label}: {} one-degree level(s) with ≥ {} samples; an order-{} ramp fit \
                 needs at least {} (a wider temperature span, or more samples per degree)",
                ts.populated_levels,
                opts.min_samples_per_level,
                opts.order,
                opts.order + 2
            ),
        });
    }
}

/// The ramp warning when the dwell per degree varies by more than `opts.uneven_ratio`.
fn uneven_heating_finding(
    heating: &HeatingProfile,
    label: &str,
    opts: &CheckOptions,
) -> Option<Finding> {
    (heating.unevenness > opts.uneven_ratio).then(|| Finding {
        kind: FindingKind::UnevenHeating,
        ramp: Impact::Warn,
        soak: Impact::None,
        span: None,
        message: format!(
            "{label}: uneven heating: {:.0} to {:.0} s per degree (10th–90th percentile, \
             ratio {:.1} > {:.1}; |dT/dt| {:.3}–{:.3} °C/min over {:.0}-s windows); the ramp \
             fit takes one point per degree so slow stretches do not dominate, but the \
             sensor's thermal lag differs along the ramp — heat at a steady rate if you can",
            heating.dwell_p10_p90_s[0],
            heating.dwell_p10_p90_s[1],
            heating.unevenness,
            opts.uneven_ratio,
            heating.rate_p10_c_per_min,
            heating.rate_p90_c_per_min,
            heating.window_s
        ),
    })
}

/// The finding for a log that moved: a ramp warning when brief, a ramp block above
/// `opts.max_moving_fraction`.
fn motion_finding(m: &MotionSummary, label: &str, opts: &CheckOptions) -> Finding {
    let block = m.moving_fraction > opts.max_moving_fraction;
    Finding {
        kind: FindingKind::Motion,
        ramp: if block { Impact::Block } else { Impact::Warn },
        soak: Impact::None,
        span: m.moving_spans.first().copied(),
        message: format!(
            "{label}: the sensor moved in {:.2} % of {:.0}-s windows (gyro change up to \
             {:.3} rad/s, tilt up to {:.1}°), first at {}: a ramp needs the board \
             untouched in one orientation{}",
            100.0 * m.moving_fraction,
            m.window_s,
            m.max_gyro_change_rad_s,
            m.max_tilt_rad.to_degrees(),
            m.moving_spans.first().map_or("–".into(), fmt_span),
            if block {
                " — record the ramp again without moving it, or cut the log to a static part"
            } else {
                " (brief, tolerated)"
            }
        ),
    }
}

/// The warning on time gaps in the log, if it has any.
fn gap_finding(
    log: &ImuLog,
    gaps: &GapSummary,
    label: &str,
    opts: &CheckOptions,
) -> Option<Finding> {
    if gaps.count == 0 {
        return None;
    }
    let big = gaps.max_temperature_jump_c > opts.gap_temperature_c;
    let first = log.gaps.first().map(|g| TimeSpan {
        start_s: g.start_s,
        end_s: g.start_s + g.duration_s,
    });
    Some(Finding {
        kind: FindingKind::Gaps,
        ramp: Impact::Warn,
        soak: Impact::Warn,
        span: first,
        message: format!(
            "{label}: {} time gap(s), longest {:.3} s, {:.1} s in all (first at {}); \
             the temperature moves up to {:.2} °C across one{}",
            gaps.count,
            gaps.longest_s,
            gaps.total_s,
            first.as_ref().map_or("–".into(), fmt_span),
            gaps.max_temperature_jump_c,
            if big {
                ": temperature bins are missing there"
            } else {
                ""
            }
        ),
    })
}

fn finish(mut r: ThermalCheck, findings: Vec<Finding>) -> ThermalCheck {
    r.fit_for_ramp = findings.iter().all(|f| f.ramp != Impact::Block);
    r.fit_for_soak = findings.iter().all(|f| f.soak != Impact::Block);
    r.findings = findings;
    r
}

fn soak_findings(
    h: &HeatingProfile,
    label: &str,
    opts: &CheckOptions,
    findings: &mut Vec<Finding>,
) {
    // Distinct plateau levels (≥ 2 °C apart), keeping the best-covered plateau of each.
    let mut levels: Vec<&Plateau> = Vec::new();
    let mut sorted: Vec<&Plateau> = h.plateaus.iter().collect();
    sorted.sort_by(|a, b| a.mean_c.total_cmp(&b.mean_c));
    for p in sorted {
        match levels.last_mut() {
            Some(l) if (p.mean_c - l.mean_c).abs() < 2.0 => {
                if p.orientations > l.orientations {
                    *l = p;
                }
            }
            _ => levels.push(p),
        }
    }
    let need = opts.order + 2;
    let lo = levels.first().map_or(0.0, |p| p.mean_c);
    let hi = levels.last().map_or(0.0, |p| p.mean_c);
    if levels.len() < need || hi - lo < opts.min_rise_c {
        findings.push(Finding {
            kind: FindingKind::TooFewPlateaus,
            ramp: Impact::None,
            soak: Impact::Block,
            span: None,
            message: format!(
                "{label}: {} temperature plateau(s) (≥ {:.0} s with |dT/dt| < {} °C/min, ≥ 2 °C \
                 apart) spanning {:.1} °C; a soak needs at least {need} spanning {:.1} °C \
                 (hold each chamber set point until the sensor settles)",
                levels.len(),
                opts.plateau_min_s,
                opts.flat_c_per_min,
                hi - lo,
                opts.min_rise_c
            ),
        });
        return;
    }
    let short: Vec<&&Plateau> = levels.iter().filter(|p| p.orientations < 6).collect();
    if levels.len() - short.len() < need {
        let first = short.first().map(|p| p.span);
        findings.push(Finding {
            kind: FindingKind::MissingOrientations,
            ramp: Impact::None,
            soak: Impact::Block,
            span: first,
            message: format!(
                "{label}: {} of {} plateaus lack the six static orientations (each axis up \
                 and down) the six-position calibration needs (first at {}, {} seen)",
                short.len(),
                levels.len(),
                first.as_ref().map_or("–".into(), fmt_span),
                short.first().map_or(0, |p| p.orientations)
            ),
        });
    }
}

fn gap_summary(log: &ImuLog, time: &[f64]) -> GapSummary {
    let temp = log
        .channels
        .iter()
        .find(|c| c.quantity == Quantity::Temperature);
    let mut g = GapSummary {
        count: log.gaps.len(),
        longest_s: 0.0,
        total_s: 0.0,
        max_temperature_jump_c: 0.0,
    };
    for gap in &log.gaps {
        g.longest_s = g.longest_s.max(gap.duration_s);
        g.total_s += gap.duration_s;
        if let Some(t) = temp
            && gap.index > 0
            && gap.index < t.values.len()
            && gap.index <= time.len()
        {
            let d = (t.values[gap.index] - t.values[gap.index - 1]).abs();
            if d.is_finite() {
                g.max_temperature_jump_c = g.max_temperature_jump_c.max(d);
            }
        }
    }
    g
}

fn temperature_summary(tc: &[f64], opts: &CheckOptions) -> TemperatureSummary {
    let mut sorted = tc.to_vec();
    sorted.sort_by(f64::total_cmp);
    let (min_c, max_c) = (quantile(&sorted, 0.005), quantile(&sorted, 0.995));
    let mut distinct = sorted.clone();
    distinct.dedup();
    let mut diffs: Vec<f64> = distinct.windows(2).map(|w| w[1] - w[0]).collect();
    let lsb_c = median_of(&mut diffs);
    let mut levels = std::collections::BTreeMap::<i64, usize>::new();
    for &t in tc {
        *levels.entry(t.round() as i64).or_default() += 1;
    }
    TemperatureSummary {
        min_c,
        max_c,
        start_c: tc[0],
        end_c: tc[tc.len() - 1],
        rise_c: max_c - min_c,
        lsb_c,
        distinct_readings: distinct.len(),
        populated_levels: levels
            .values()
            .filter(|&&c| c >= opts.min_samples_per_level)
            .count(),
    }
}

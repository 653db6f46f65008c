//! Segmentation of a calibration log from its own data: static intervals with the body
//! axis that points up, rate-table rotations (axis, rate, sense, revolutions) and
//! temperature plateaus (temperature, settled or not, dwell), with findings (missing
//! positions, unsettled plateaus, ambiguous segments) named by their time span. A
//! [`Segmentation`] becomes the segment manifest of [`super::protocol`]
//! ([`Segmentation::manifest_of`]), so the six-position and soak calibrations
//! ([`crate::calib::six_position`], [`crate::thermal::soak`]) run on it unchanged.
//!
//! # Motion
//!
//! With var_w(x)(t) the sample variance of x over a centred window of `window_s`
//! seconds, the accelerometer and gyro variance magnitudes are
//!
//! ```text
//! ς_a(t) = ‖(var_w(a_x), var_w(a_y), var_w(a_z))‖,   ς_g(t) likewise for ω
//! ```
//!
//! (the detector of [`super::static_detect`], Tedaldi et al. 2014, applied to both
//! triads). A sample is *quiet* when ς_a < k·med(ς_a) and ς_g < k·med(ς_g), med the median
//! over the log: a chamber or turntable log is mostly static or turning at a constant
//! rate, and both leave only the sensor noise in the window. No initial rest period is
//! needed. A run of quiet samples is grown at each end while every sample of both triads
//! stays within 4σ of the run's mean (the centred window leaves out up to half a window
//! at each edge), and is then, by its mean rate ‖ω̄‖:
//!
//! * **static** when ‖ω̄‖ < `static_max_rate_deg_s` (a sensor bias, not motion). The axis
//!   up is the body axis j whose ±e_j is within `orientation_tolerance_deg` of the mean
//!   specific force f̄ (at rest f = +g along the upward vertical); a reading further off
//!   but within 2× the tolerance is *ambiguous*, beyond it the static is "other" (a tilted
//!   fixture, handling) and not a position. The default 15° leaves room for the raw
//!   accelerometer bias of an uncalibrated MEMS triad at a temperature extreme (≈ 0.9 m/s²
//!   across an axis, 5°, on `adi-like` at 65 °C);
//! * a **rotation** when ‖ω̄‖ ≥ `rotation_min_rate_deg_s`, about the body axis k of the
//!   largest |ω̄_k| (the other two components below 5 % of ‖ω̄‖, else ambiguous), sense
//!   sign(ω̄_k), revolutions |∫ω_k dt|/2π;
//! * ambiguous in between.
//!
//! The commanded table rate is not in the data: the gyro measures (1 + s)·ω + b. It is
//! `table_rate_deg_s` when given, else |ω̄_k| rounded to the nearest multiple of
//! `rate_round_deg_s` (a finding says so). A rotation whose measured rate differs from
//! the commanded one by more than `rate_tolerance` (relative) is ambiguous and not used.
//! A rotation is kept to whole revolutions of the commanded rate about its centre when it
//! is long enough, so the horizontal Earth rate averages out as the calibration assumes.
//!
//! # Soaks
//!
//! A static more than 3× the median length D of all static positions of the log is a
//! soak. When the next segment is a static position of ordinary length, the soak ends in
//! a position (the chamber protocol holds its first position, the home attitude, right
//! after the soak): its last D seconds are that position. Other soaks give no position.
//! A position "missed" at the end of a soak therefore cannot be told from the soak.
//!
//! # Temperature plateaus
//!
//! The temperature column is averaged to one value per second, smoothed by a centred
//! moving mean over `temperature_window_s`, and differentiated over the same window. The
//! temperature is *moving* where |dT/dt| > `moving_rate_c_per_min`; each moving run (gaps
//! shorter than `min_plateau_s` closed) starts a new plateau at the first second whose
//! temperature has left the level before the run by half of `settled_band_c` (the
//! smoothed rate flags a change up to a window early). A plateau thus runs from one
//! set-point change to the next and includes the settling after it. Its temperature is
//! the mean over its calibration segments (positions and rotations); it is *settled*
//! when the smoothed temperature over those segments spans at most `settled_band_c`.
//! A segment belongs to the plateau holding its mid-time. Without a temperature column
//! the whole log is one plateau at the temperature given by the caller.
//!
//! # Attitude and site
//!
//! The Earth-rate term of the gyro fit needs each position's heading, which the data
//! do not give: positions are taken in the attitude of the chamber protocol
//! ([`SignedAxis::c_bn_up`], a horizontal axis north), as with a manifest. Gravity and the
//! Earth rate come from the site the caller names ([`SiteConstants`]).

use driftless_model::linalg::{Vec3, norm};
use serde::Serialize;

use super::protocol::{
    BodyAxis, ChamberManifest, MANIFEST_VERSION, Segment, SegmentKind, SignedAxis,
};
use super::static_detect::{StaticDetectOptions, variance_profile};
use crate::nav::earth;

mod manifest;
mod plateau;
mod runs;
use plateau::*;
use runs::RunClassifier;

/// Settings of [`segment_log`] (module docs for each threshold).
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentOptions {
    /// Moving-variance window, s (default 1).
    pub window_s: f64,
    /// Quiet when both variance magnitudes are below this multiple of their log medians
    /// (default 4).
    pub quiet_multiple: f64,
    /// Shortest static interval kept, s (default 2).
    pub min_static_s: f64,
    /// Shortest rotation kept, s (default 2).
    pub min_rotation_s: f64,
    /// Removed from each end of a static interval, s (default 0.2: sensor filter delay).
    pub trim_s: f64,
    /// Largest mean rate of a static interval, deg/s (default 3).
    pub static_max_rate_deg_s: f64,
    /// Smallest mean rate of a rotation, deg/s (default 5).
    pub rotation_min_rate_deg_s: f64,
    /// Largest angle between the mean specific force and a body axis for a position, deg
    /// (default 15; below 30).
    pub orientation_tolerance_deg: f64,
    /// Commanded table rate |ω|, deg/s (default: inferred, module docs).
    pub table_rate_deg_s: Option<f64>,
    /// Rounding step of an inferred table rate, deg/s (default 5).
    pub rate_round_deg_s: f64,
    /// Largest relative difference between measured and commanded rate (default 0.03).
    pub rate_tolerance: f64,
    /// Temperature smoothing and differentiation window, s (default 30).
    pub temperature_window_s: f64,
    /// |dT/dt| above which the temperature is changing set point, °C/min (default 0.2).
    pub moving_rate_c_per_min: f64,
    /// Shortest plateau, s (default 60): shorter quiet spells between moving runs join
    /// the transition.
    pub min_plateau_s: f64,
    /// Largest span of the smoothed temperature over a plateau's calibration segments
    /// for it to be settled, °C (default 0.2).
    pub settled_band_c: f64,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions {
            window_s: 1.0,
            quiet_multiple: 4.0,
            min_static_s: 2.0,
            min_rotation_s: 2.0,
            trim_s: 0.2,
            static_max_rate_deg_s: 3.0,
            rotation_min_rate_deg_s: 5.0,
            orientation_tolerance_deg: 15.0,
            table_rate_deg_s: None,
            rate_round_deg_s: 5.0,
            rate_tolerance: 0.03,
            temperature_window_s: 30.0,
            moving_rate_c_per_min: 0.2,
            min_plateau_s: 60.0,
            settled_band_c: 0.2,
        }
    }
}

/// The samples `start..end` of a segment and their times in the log's time column, s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Span {
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// Time of the first sample, s.
    pub start_s: f64,
    /// Time of the last sample, s.
    pub end_s: f64,
}

impl Span {
    /// Samples.
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }

    /// "t0–t1 s".
    pub fn label(&self) -> String {
        format!("{:.2}–{:.2} s", self.start_s, self.end_s)
    }
}

/// What a static interval is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StaticRole {
    /// A static position with a body axis up.
    Position,
    /// A long static (soak); with `position_tail` its last dwell is a position.
    Soak,
    /// No body axis vertical, or ambiguous: not used.
    Other,
}

/// One static interval.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StaticSegment {
    /// Samples and times (trimmed).
    pub span: Span,
    /// The body axis up (None: no axis within the tolerance).
    pub up: Option<SignedAxis>,
    /// Angle between the mean specific force and the nearest body axis, deg.
    pub tilt_deg: f64,
    /// Mean specific force, m/s².
    pub mean_accel_m_s2: Vec3,
    /// Role.
    pub role: StaticRole,
    /// For a soak ending in a position: that position's samples (its last dwell).
    pub position_tail: Option<Span>,
    /// Index of the plateau of the interval (of its position tail for a soak).
    pub plateau: Option<usize>,
}

impl StaticSegment {
    /// The samples used as a static position, if any: the interval itself, or the tail
    /// of a soak.
    pub(crate) fn position_span(&self) -> Option<Span> {
        match self.role {
            StaticRole::Position => Some(self.span),
            StaticRole::Soak => self.position_tail,
            StaticRole::Other => None,
        }
    }
}

/// One rotation at constant rate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RotationSegment {
    /// Samples and times (whole revolutions of the commanded rate when long enough).
    pub span: Span,
    /// Rotation axis (body).
    pub axis: BodyAxis,
    /// The body axis up during the rotation (None: none vertical).
    pub up: Option<SignedAxis>,
    /// Mean measured rate about +axis, rad/s (signed).
    pub measured_rate_rad_s: f64,
    /// Commanded rate about +axis, rad/s (signed; None when not usable).
    pub commanded_rate_rad_s: Option<f64>,
    /// Revolutions over `span` from the measured rate.
    pub revolutions: f64,
    /// Whether it enters the calibration: commanded rate known and +axis up (the rate
    /// rows of the six-position fit assume the tested axis up).
    pub usable: bool,
    /// Index of the plateau.
    pub plateau: Option<usize>,
}

/// One temperature plateau: from one set-point change to the next.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TemperaturePlateau {
    /// Samples and times.
    pub span: Span,
    /// Temperature of the calibration: mean over its calibration segments (the mean of
    /// the plateau without any; the caller's value without a temperature column), °C.
    pub temperature_c: f64,
    /// Span of the smoothed temperature over its calibration segments, °C.
    pub spread_c: f64,
    /// Spread within `settled_band_c` (always true without a temperature column).
    pub settled: bool,
    /// Length, s.
    pub dwell_s: f64,
    /// Static positions per direction, in [`SignedAxis::POSITIONS`] order.
    pub positions: [usize; 6],
    /// Usable rotations about x, y, z with ω > 0 and ω < 0.
    pub rotations: [[usize; 2]; 3],
}

impl TemperaturePlateau {
    /// Every one of the six directions has a position.
    pub fn complete(&self) -> bool {
        self.positions.iter().all(|&n| n > 0)
    }

    /// Holds any static position.
    pub(crate) fn has_positions(&self) -> bool {
        self.positions.iter().any(|&n| n > 0)
    }
}

/// What a finding is about.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FindingKind {
    /// A plateau with positions lacks the position with `up` up.
    MissingPosition {
        /// The missing direction.
        up: SignedAxis,
        /// Plateau index.
        plateau: usize,
    },
    /// A plateau with positions lacks a usable rotation about `axis` with this sense.
    MissingRotation {
        /// Axis.
        axis: BodyAxis,
        /// ω > 0.
        positive: bool,
        /// Plateau index.
        plateau: usize,
    },
    /// The temperature was still changing over the plateau's calibration segments.
    UnsettledPlateau {
        /// Plateau index.
        plateau: usize,
        /// Span of the temperature, °C.
        spread_c: f64,
    },
    /// A segment that fits no class cleanly (not used).
    Ambiguous,
    /// The commanded table rate was inferred from the gyro.
    RateInferred {
        /// The rate assumed, deg/s.
        rate_deg_s: f64,
    },
}

/// One finding, with the time span it concerns and what to do.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// What.
    #[serde(flatten)]
    pub kind: FindingKind,
    /// Where, s (log time).
    pub start_s: f64,
    /// Where, s (log time).
    pub end_s: f64,
    /// The sentence to print.
    pub message: String,
}

/// The segmentation of a log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segmentation {
    /// Sample rate (from the median time step), Hz.
    pub sample_rate_hz: f64,
    /// Samples.
    pub n_samples: usize,
    /// Static intervals in time order.
    pub statics: Vec<StaticSegment>,
    /// Rotations in time order.
    pub rotations: Vec<RotationSegment>,
    /// Temperature plateaus in time order.
    pub plateaus: Vec<TemperaturePlateau>,
    /// Findings in time order.
    pub findings: Vec<Finding>,
}

/// The site of the recording: what a manifest states beside its segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SiteConstants {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// |f| in a static position, m/s² (default: WGS-84 normal gravity at the site).
    pub gravity_m_s2: Option<f64>,
}

/// Why a log could not be segmented, or a segmentation not used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SegmentError {
    /// A setting out of range.
    #[error("segmentation option {name} = {value}: {what}")]
    Option {
        /// Option name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What is allowed.
        what: &'static str,
    },
    /// Columns of different lengths, too few samples, bad time stamps.
    #[error("{0}")]
    BadInput(String),
    /// A NaN or infinity in a column.
    #[error("non-finite {column} at sample {sample} (t = {time_s} s): repair or remove that row")]
    NonFinite {
        /// Column name.
        column: String,
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time_s: f64,
    },
    /// Nothing static with a body axis up was found.
    #[error(
        "no static position with a body axis up over {start_s:.2}–{end_s:.2} s: the log has no \
         dwell of at least {min_static_s} s within {tolerance_deg}° of an axis (check the \
         units of the accelerometer columns, or pass a manifest)"
    )]
    NoPositions {
        /// Log start, s.
        start_s: f64,
        /// Log end, s.
        end_s: f64,
        /// `min_static_s`.
        min_static_s: f64,
        /// `orientation_tolerance_deg`.
        tolerance_deg: f64,
    },
    /// A plateau cannot be calibrated: the findings that say why.
    #[error("{0}")]
    Incomplete(String),
}

fn check_option(name: &'static str, value: f64, min: f64) -> Result<(), SegmentError> {
    if value.is_finite() && value > min {
        Ok(())
    } else {
        Err(SegmentError::Option {
            name,
            value,
            what: if min == 0.0 {
                "must be finite and > 0"
            } else {
                "must be finite and > 1"
            },
        })
    }
}

impl SegmentOptions {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), SegmentError> {
        for (name, v) in [
            ("window_s", self.window_s),
            ("min_static_s", self.min_static_s),
            ("min_rotation_s", self.min_rotation_s),
            ("static_max_rate_deg_s", self.static_max_rate_deg_s),
            ("orientation_tolerance_deg", self.orientation_tolerance_deg),
            ("rate_round_deg_s", self.rate_round_deg_s),
            ("rate_tolerance", self.rate_tolerance),
            ("temperature_window_s", self.temperature_window_s),
            ("moving_rate_c_per_min", self.moving_rate_c_per_min),
            ("min_plateau_s", self.min_plateau_s),
            ("settled_band_c", self.settled_band_c),
        ] {
            check_option(name, v, 0.0)?;
        }
        check_option("quiet_multiple", self.quiet_multiple, 1.0)?;
        if !(self.trim_s.is_finite() && self.trim_s >= 0.0) {
            return Err(SegmentError::Option {
                name: "trim_s",
                value: self.trim_s,
                what: "must be finite and ≥ 0",
            });
        }
        if !(self.rotation_min_rate_deg_s.is_finite()
            && self.rotation_min_rate_deg_s >= self.static_max_rate_deg_s)
        {
            return Err(SegmentError::Option {
                name: "rotation_min_rate_deg_s",
                value: self.rotation_min_rate_deg_s,
                what: "must be finite and ≥ static_max_rate_deg_s",
            });
        }
        if self.orientation_tolerance_deg >= 30.0 {
            return Err(SegmentError::Option {
                name: "orientation_tolerance_deg",
                value: self.orientation_tolerance_deg,
                what: "must be below 30°",
            });
        }
        if let Some(r) = self.table_rate_deg_s {
            check_option("table_rate_deg_s", r, 0.0)?;
        }
        Ok(())
    }
}

/// The log columns a segmentation reads (SI: m/s², rad/s, °C).
#[derive(Clone, Copy, Debug)]
pub struct SegmentInput<'a> {
    /// Time of each sample, s (increasing).
    pub time_s: &'a [f64],
    /// Specific force x, y, z, m/s².
    pub accel_m_s2: [&'a [f64]; 3],
    /// Angular rate x, y, z, rad/s.
    pub gyro_rad_s: [&'a [f64]; 3],
    /// Sensor temperature, °C (None: one plateau at `nominal_temperature_c`).
    pub temperature_c: Option<&'a [f64]>,
    /// Temperature of the single plateau of a log without a temperature column, °C.
    pub nominal_temperature_c: f64,
}

fn check_input(inp: &SegmentInput) -> Result<f64, SegmentError> {
    let n = inp.time_s.len();
    let cols: Vec<(String, &[f64])> = [("time".to_string(), inp.time_s)]
        .into_iter()
        .chain(
            ["x", "y", "z"]
                .iter()
                .zip(inp.accel_m_s2)
                .map(|(a, c)| (format!("accelerometer {a}"), c)),
        )
        .chain(
            ["x", "y", "z"]
                .iter()
                .zip(inp.gyro_rad_s)
                .map(|(a, c)| (format!("gyro {a}"), c)),
        )
        .chain(inp.temperature_c.map(|t| ("temperature".to_string(), t)))
        .collect();
    for (name, c) in &cols {
        if c.len() != n {
            return Err(SegmentError::BadInput(format!(
                "{name} column has {} samples, the time column {n}",
                c.len()
            )));
        }
        if let Some(k) = c.iter().position(|v| !v.is_finite()) {
            return Err(SegmentError::NonFinite {
                column: name.clone(),
                sample: k,
                time_s: inp.time_s.get(k).copied().unwrap_or(f64::NAN),
            });
        }
    }
    if !inp.nominal_temperature_c.is_finite() {
        return Err(SegmentError::BadInput(format!(
            "nominal temperature {} °C is not finite",
            inp.nominal_temperature_c
        )));
    }
    if let Some(k) = inp.time_s.windows(2).position(|w| w[1] <= w[0]) {
        return Err(SegmentError::BadInput(format!(
            "time stamps not increasing at sample {} (t = {} s after {} s): sort the log or \
             remove the repeated rows",
            k + 1,
            inp.time_s[k + 1],
            inp.time_s[k]
        )));
    }
    let dt = super::static_detect::median_dt(inp.time_s)
        .map_err(|e| SegmentError::BadInput(format!("time column: {e}")))?;
    Ok(1.0 / dt)
}

/// Upper median of `v`; 0 when empty.
fn median(mut v: Vec<f64>) -> f64 {
    crate::numeric::upper_median(&mut v).unwrap_or(0.0)
}

/// Prefix sums of the columns, for means over sample ranges.
struct Sums {
    s: Vec<[f64; 7]>,
}

impl Sums {
    fn new(a: [&[f64]; 3], g: [&[f64]; 3], t: Option<&[f64]>) -> Sums {
        let n = a[0].len();
        let mut s = vec![[0.0; 7]; n + 1];
        for k in 0..n {
            let row = [
                a[0][k],
                a[1][k],
                a[2][k],
                g[0][k],
                g[1][k],
                g[2][k],
                t.map_or(0.0, |t| t[k]),
            ];
            for j in 0..7 {
                s[k + 1][j] = s[k][j] + row[j];
            }
        }
        Sums { s }
    }

    fn mean(&self, lo: usize, hi: usize, j: usize) -> f64 {
        (self.s[hi][j] - self.s[lo][j]) / (hi - lo).max(1) as f64
    }

    fn accel(&self, lo: usize, hi: usize) -> Vec3 {
        std::array::from_fn(|j| self.mean(lo, hi, j))
    }

    fn gyro(&self, lo: usize, hi: usize) -> Vec3 {
        std::array::from_fn(|j| self.mean(lo, hi, 3 + j))
    }
}

/// Angle between `f` and the nearest signed body axis, deg, and that axis.
fn nearest_axis(f: Vec3) -> (SignedAxis, f64) {
    let j = (0..3)
        .max_by(|&a, &b| f[a].abs().total_cmp(&f[b].abs()))
        .unwrap_or(2);
    let n = norm(f);
    let cos = if n > 0.0 { f[j].abs() / n } else { 0.0 };
    (
        SignedAxis::new(BodyAxis::ALL[j], f[j] > 0.0),
        cos.clamp(-1.0, 1.0).acos().to_degrees(),
    )
}

/// Segment a log (module docs).
pub fn segment_log(
    inp: &SegmentInput,
    opts: &SegmentOptions,
) -> Result<Segmentation, SegmentError> {
    opts.validate()?;
    let fs = check_input(inp)?;
    let n = inp.time_s.len();
    let dt = 1.0 / fs;
    let need = ((opts.min_static_s.max(opts.window_s) * fs).ceil() as usize).max(3);
    if n < need {
        return Err(SegmentError::BadInput(format!(
            "{n} samples ({:.3} s) are too few to segment: need at least {need} ({} s)",
            n as f64 * dt,
            opts.min_static_s.max(opts.window_s)
        )));
    }
    let t = inp.time_s;
    let span = |a: usize, b: usize| Span {
        start: a,
        end: b,
        start_s: t[a],
        end_s: t[b - 1],
    };
    // Variance magnitudes of both triads.
    let vopts = StaticDetectOptions {
        window_s: opts.window_s,
        init_rest_s: opts.window_s,
        ..StaticDetectOptions::default()
    };
    let rows = |c: [&[f64]; 3]| -> Vec<Vec3> { (0..n).map(|k| c.map(|col| col[k])).collect() };
    let bad = |e: super::multi_position::CalibError| SegmentError::BadInput(e.to_string());
    let va = variance_profile(t, &rows(inp.accel_m_s2), &vopts).map_err(bad)?;
    let vg = variance_profile(t, &rows(inp.gyro_rad_s), &vopts).map_err(bad)?;
    // Noise-free data has zero variance at rest: absolute floors of 1e-8 (σ ≈ 1e-4 m/s²,
    // 1e-4 rad/s) keep the thresholds above rounding and above the horizontal Earth rate
    // seen turning on a table (variance ≈ (Ω cos L)²/2 ≈ 1e-9 rad²/s²), far below any
    // moving fixture.
    let th_a = (opts.quiet_multiple * median(va.sigma.clone())).max(1e-8);
    let th_g = (opts.quiet_multiple * median(vg.sigma.clone())).max(1e-8);
    let quiet: Vec<bool> = (0..n)
        .map(|k| va.sigma[k] < th_a && vg.sigma[k] < th_g)
        .collect();
    let sums = Sums::new(inp.accel_m_s2, inp.gyro_rad_s, inp.temperature_c);
    let mut runs = RunClassifier {
        inp,
        opts,
        fs,
        sums: &sums,
        min_static: ((opts.min_static_s * fs).round() as usize).max(2),
        min_rot: ((opts.min_rotation_s * fs).round() as usize).max(2),
        trim: (opts.trim_s * fs).round() as usize,
        tol: opts.orientation_tolerance_deg,
        findings: Vec::new(),
        statics: Vec::new(),
        rotations: Vec::new(),
        inferred_rates: Vec::new(),
    };
    let tol = runs.tol;
    let mut k0 = 0;
    while k0 < n {
        if !quiet[k0] {
            k0 += 1;
            continue;
        }
        let mut k1 = k0;
        while k1 < n && quiet[k1] {
            k1 += 1;
        }
        let (a, b) = (k0, k1);
        k0 = k1;
        if b - a < runs.min_static.min(runs.min_rot) {
            continue;
        }
        k0 = k0.max(runs.classify(a, b));
    }
    let RunClassifier {
        mut statics,
        rotations,
        findings,
        ..
    } = runs;
    if !statics.iter().any(|s| s.role == StaticRole::Position) {
        return Err(SegmentError::NoPositions {
            start_s: t[0],
            end_s: t[n - 1],
            min_static_s: opts.min_static_s,
            tolerance_deg: tol,
        });
    }
    mark_soaks(&mut statics, &rotations);
    let plateaus_spans = plateau_spans(inp, opts, fs);
    let mut seg = Segmentation {
        sample_rate_hz: fs,
        n_samples: n,
        statics,
        rotations,
        plateaus: Vec::new(),
        findings,
    };
    assign_plateaus(&mut seg, inp, &plateaus_spans, opts, &span, &sums);
    seg.findings.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
    Ok(seg)
}

/// The run `a..b` grown sample by sample at each end, by at most `max` samples, while
/// every channel of both triads stays within 4σ of the run's mean (σ the run's own
/// sample standard deviation, floored at 1e-6 m/s² and 1e-5 rad/s for noise-free data):
/// the centred variance window leaves out up to half a window at each edge, which a
/// rotation of a whole number of revolutions needs back.
fn extend_run(inp: &SegmentInput, a: usize, b: usize, max: usize) -> (usize, usize) {
    let n = inp.time_s.len();
    let cols: Vec<&[f64]> = inp
        .accel_m_s2
        .iter()
        .chain(&inp.gyro_rad_s)
        .copied()
        .collect();
    let stats: Vec<(f64, f64)> = cols
        .iter()
        .enumerate()
        .map(|(j, c)| {
            let x = &c[a..b];
            let m = x.iter().sum::<f64>() / x.len() as f64;
            let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len().max(2) - 1) as f64;
            (m, v.sqrt().max(if j < 3 { 1e-6 } else { 1e-5 }))
        })
        .collect();
    let fits = |k: usize| {
        cols.iter()
            .zip(&stats)
            .all(|(c, &(m, s))| (c[k] - m).abs() <= 4.0 * s)
    };
    let (mut lo, mut hi) = (a, b);
    while lo > 0 && a - lo < max && fits(lo - 1) {
        lo -= 1;
    }
    while hi < n && hi - b < max && fits(hi) {
        hi += 1;
    }
    (lo, hi)
}

/// Soaks (module docs): statics longer than 3× the median position length D; one
/// followed by a position of ordinary length ends in a position, its last D seconds.
fn mark_soaks(statics: &mut [StaticSegment], rotations: &[RotationSegment]) {
    let lens: Vec<f64> = statics
        .iter()
        .filter(|s| s.role == StaticRole::Position)
        .map(|s| s.span.len() as f64)
        .collect();
    if lens.len() < 3 {
        return;
    }
    let d = median(lens);
    let long = |s: &StaticSegment| s.span.len() as f64 > 3.0 * d;
    let flags: Vec<bool> = statics.iter().map(long).collect();
    for i in 0..statics.len() {
        if !(flags[i] && statics[i].role == StaticRole::Position) {
            continue;
        }
        let end = statics[i].span.end;
        // The next segment in time: a static or a rotation.
        let next_static = statics.get(i + 1).map(|s| s.span.start);
        let next_rot = rotations
            .iter()
            .map(|r| r.span.start)
            .filter(|&s| s >= end)
            .min();
        let next_is_position = match (next_static, next_rot) {
            (Some(s), Some(r)) if r < s => false,
            (Some(_), _) => statics[i + 1].role == StaticRole::Position && !flags[i + 1],
            _ => false,
        };
        let s = &mut statics[i];
        s.role = StaticRole::Soak;
        if next_is_position {
            let len = d.round() as usize;
            let sp = s.span;
            s.position_tail = Some(Span {
                start: sp.end - len,
                end: sp.end,
                start_s: sp.end_s - (sp.end_s - sp.start_s) * len as f64 / sp.len() as f64,
                end_s: sp.end_s,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Cols = (Vec<f64>, [Vec<f64>; 3], [Vec<f64>; 3]);

    /// A log of pieces (duration s, specific force, rate, motion): small uniform noise
    /// on every sample; in a motion piece every other sample is negated (large variance).
    fn synthetic(pieces: &[(f64, Vec3, Vec3, bool)], fs: f64) -> Cols {
        let (mut t, mut a, mut g): Cols = Default::default();
        let mut seed = 1u64;
        for &(dur, f, w, motion) in pieces {
            for i in 0..(dur * fs).round() as usize {
                t.push(t.len() as f64 / fs);
                let sign = if motion && i % 2 == 0 { -1.0 } else { 1.0 };
                for j in 0..3 {
                    let e = crate::numeric::splitmix64(&mut seed) as f64 / u64::MAX as f64 - 0.5;
                    a[j].push(sign * f[j] + 1e-3 * e);
                    g[j].push(sign * w[j] + 1e-4 * e);
                }
            }
        }
        (t, a, g)
    }

    fn site() -> SiteConstants {
        SiteConstants {
            latitude_deg: 45.0,
            longitude_deg: 0.0,
            height_m: 0.0,
            gravity_m_s2: None,
        }
    }

    #[test]
    fn classifies_statics_rotations_and_motion() {
        let g = 9.8;
        let r = 30f64.to_radians();
        let mv = ([3.0, -2.0, 1.0], [0.5, 0.2, 0.1], true);
        let tilt = 20f64.to_radians();
        let (t, a, gy) = synthetic(
            &[
                (20.0, [0.0, 0.0, -g], [0.0; 3], false),
                (3.0, mv.0, mv.1, mv.2),
                (10.0, [0.0, g, 0.0], [0.0; 3], false),
                (3.0, mv.0, mv.1, mv.2),
                (12.0, [g, 0.0, 0.0], [0.0; 3], false),
                (3.0, mv.0, mv.1, mv.2),
                // 30 deg/s about +x with +x up, 24 s: two revolutions.
                (24.0, [g, 0.0, 0.0], [r, 0.0, 0.0], false),
                (3.0, mv.0, mv.1, mv.2),
                // 20° off +y: ambiguous, not a position.
                (10.0, [0.0, g * tilt.cos(), g * tilt.sin()], [0.0; 3], false),
                (3.0, mv.0, mv.1, mv.2),
                // 4 deg/s: neither static nor a rotation.
                (10.0, [0.0, 0.0, -g], [0.0, 0.0, 4f64.to_radians()], false),
            ],
            50.0,
        );
        let inp = SegmentInput {
            time_s: &t,
            accel_m_s2: [&a[0], &a[1], &a[2]],
            gyro_rad_s: [&gy[0], &gy[1], &gy[2]],
            temperature_c: None,
            nominal_temperature_c: 25.0,
        };
        let s = segment_log(&inp, &SegmentOptions::default()).expect("segment");
        let ups: Vec<Option<SignedAxis>> = s.statics.iter().map(|x| x.up).collect();
        let (zd, yu, xu) = (
            SignedAxis::new(BodyAxis::Z, false),
            SignedAxis::new(BodyAxis::Y, true),
            SignedAxis::new(BodyAxis::X, true),
        );
        assert_eq!(
            ups,
            vec![Some(zd), Some(yu), Some(xu), None],
            "{:?}",
            s.statics
        );
        // Trimmed by 0.2 s at each end, within a window of the true edges.
        let first = s.statics[0].span;
        assert!(
            first.start_s <= 0.25 && (19.0..=19.8).contains(&first.end_s),
            "{first:?}"
        );
        assert_eq!(s.rotations.len(), 1);
        let rot = &s.rotations[0];
        assert_eq!(
            (rot.axis, rot.up, rot.usable),
            (BodyAxis::X, Some(xu), true)
        );
        assert_eq!(rot.commanded_rate_rad_s, Some(r));
        // Two revolutions less up to a window at the abrupt edges of this log.
        assert!(
            (1.9..=2.0 + 1e-9).contains(&rot.revolutions),
            "{}",
            rot.revolutions
        );
        assert_eq!(s.plateaus.len(), 1);
        assert_eq!(s.plateaus[0].positions, [1, 0, 1, 0, 1, 0]);
        assert_eq!(s.plateaus[0].rotations, [[1, 0], [0, 0], [0, 0]]);
        let missing: Vec<String> = s
            .findings
            .iter()
            .filter_map(|f| match f.kind {
                FindingKind::MissingPosition { up, .. } => Some(up.to_string()),
                _ => None,
            })
            .collect();
        assert_eq!(missing, vec!["+z", "-x", "-y"]);
        let ambiguous: Vec<&str> = s
            .findings
            .iter()
            .filter(|f| f.kind == FindingKind::Ambiguous)
            .map(|f| f.message.as_str())
            .collect();
        assert_eq!(ambiguous.len(), 2, "{ambiguous:?}");
        assert!(
            ambiguous[0].contains("20.0° from +y up"),
            "{}",
            ambiguous[0]
        );
        assert!(ambiguous[1].contains("4.00 deg/s"), "{}", ambiguous[1]);
        assert!(s.findings.iter().any(|f| matches!(
            f.kind,
            FindingKind::RateInferred { rate_deg_s } if rate_deg_s == 30.0
        )));
        let e = s
            .six_position_manifest(None, &site())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no static position with +z up") && e.contains("plateau 0"),
            "{e}"
        );
        // A stated table rate 3.5 % off the measured one: the rotation is not used.
        let s = segment_log(
            &inp,
            &SegmentOptions {
                table_rate_deg_s: Some(31.05),
                ..Default::default()
            },
        )
        .expect("segment");
        assert!(!s.rotations[0].usable);
        assert!(
            s.findings
                .iter()
                .any(|f| f.message.contains("differs from the table rate"))
        );
    }

    #[test]
    fn bad_input_names_the_sample() {
        let t: Vec<f64> = (0..500).map(|k| k as f64 * 0.01).collect();
        let z = vec![0.0; 500];
        let mut g = vec![-9.8; 500];
        g[123] = f64::NAN;
        let inp = SegmentInput {
            time_s: &t,
            accel_m_s2: [&z, &z, &g],
            gyro_rad_s: [&z, &z, &z],
            temperature_c: None,
            nominal_temperature_c: 25.0,
        };
        let e = segment_log(&inp, &SegmentOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("accelerometer z") && e.contains("sample 123") && e.contains("1.23 s"),
            "{e}"
        );
        let short = &z[..10];
        let inp = SegmentInput {
            accel_m_s2: [short, &z, &z],
            ..inp
        };
        let e = segment_log(&inp, &SegmentOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("accelerometer x column has 10 samples"), "{e}");
        let e = SegmentOptions {
            quiet_multiple: 0.5,
            ..Default::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("quiet_multiple = 0.5"), "{e}");
        // Tilted everywhere: no position, a clear error with the span.
        let x = vec![5.0; 500];
        let inp = SegmentInput {
            time_s: &t,
            accel_m_s2: [&x, &z, &x],
            gyro_rad_s: [&z, &z, &z],
            temperature_c: None,
            nominal_temperature_c: 25.0,
        };
        let e = segment_log(&inp, &SegmentOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no static position") && e.contains("0.00–4.99 s"),
            "{e}"
        );
    }
}

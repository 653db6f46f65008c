//! Validation of IMU *values* before navigation: non-physical samples, isolated outliers
//! and saturation, per channel, with their time and channel, and an optional repair of
//! isolated spikes. [`super::pipeline`] validates the time stamps and finiteness; this
//! module the magnitudes. Neither the readers nor the filter do this: a reader only
//! converts, the filter trusts its input.
//!
//! The checks run on the sensor's own axes: the rates ω = Δθ/Δt and f = Δv/Δt of each
//! epoch, rotated back by C_vbᵀ when the stream was built with a mounting rotation C_vb
//! ([`super::pipeline::Mounting`]), so a finding names the file's channel (`gyro_z`) and a
//! pinned axis stays pinned. One pass over the data per channel (plus a short robust
//! window at the rare candidates); for a 57-min, 100-Hz log it costs milliseconds.
//!
//! # Tests (per channel x, samples i = 0 … n−1)
//!
//! * **Non-physical**: |x_i| above the hard limit — by default 4000 °/s for a gyro
//!   ([`ImuCheckConfig::max_gyro_rad_s`]: twice the widest full-scale range of MEMS
//!   gyros, ±2000 °/s, e.g. TDK ICM-42688-P, Bosch BMI088, ST LSM6DSO data sheets) and
//!   400 g for an accelerometer ([`ImuCheckConfig::max_accel_m_s2`]: twice the ±200 g of
//!   high-g MEMS parts such as the ADXL375; navigation accelerometers stop at ±16…±32 g).
//!   No working sensor reports such a value: it is a transfer or conversion fault. A run
//!   of consecutive such samples is one finding.
//! * **Isolated outlier** (a Hampel identifier, Hampel 1974, JASA 69:383–393, on the
//!   spike residual instead of the raw value so that trends and steps do not count):
//!   r_i = x_i − ½(x_{i−1} + x_{i+1}). Sample i is an outlier when all of
//!   1. |r_i| ≥ |x_{i+1} − x_{i−1}| — the sample leaves *both* neighbours, which agree
//!      with each other (a step or a fast ramp, where the neighbours differ, never
//!      passes);
//!   2. |r_i| > the floor ([`ImuCheckConfig::outlier_min_gyro_rad_s`], 2 rad/s
//!      ≈ 115 °/s; [`ImuCheckConfig::outlier_min_accel_m_s2`], 3 g): a one-sample
//!      excursion no rigid-body motion of a car, a walker's hand or a multirotor makes
//!      at 50–1000 Hz (a 1440-°/s flip ramps over tens of milliseconds), and a smaller
//!      one matters little: it turns the attitude by at most r·Δt (1.1° at 100 Hz) and
//!      the velocity by 0.3 m/s, which the GNSS updates absorb. (The real car drive
//!      `drive_0708` has one-sample pitch-rate swings of 1.0–1.3 rad/s over bumps: a
//!      mechanical shock the sensor did see, below this floor);
//!   3. |r_i − med(r)| > k·σ̂ with σ̂ = 1.4826·MAD(r) over the window i ± h (the
//!      window's samples other than i − 1, i, i + 1, whose residuals the spike itself
//!      sets), k = [`ImuCheckConfig::outlier_threshold`] = 10 and h =
//!      [`ImuCheckConfig::outlier_half_window`] = 50 samples. 1.4826·MAD is the
//!      consistent σ estimate of Gaussian data (Rousseeuw & Croux 1993, JASA
//!      88:1273–1283); k = 10 rather than Hampel's usual 3 because vibration is
//!      heavy-tailed and a long log has 10⁶ samples: the floor and the window keep real
//!      vibration and impacts (which raise σ̂ around them) from counting.
//!
//!   Only samples whose neighbours are physical are tested.
//! * **Saturation**: a run of at least [`ImuCheckConfig::saturation_min_samples`] (3)
//!   consecutive samples pinned at the channel's largest or smallest value over the
//!   whole log (equal within 10⁻⁹ relative: the value a clipping converter repeats), when
//!   that value's magnitude is at least 100 °/s (gyro) or 1.5 g (accelerometer) — below
//!   the smallest full-scale ranges sold (±125 °/s, ±2 g), so a quantised static or
//!   slow signal repeating its largest code is not taken for a clipped one.
//!
//! # Policy
//!
//! [`check_imu`] only reports. [`refuse_non_physical`] turns the first non-physical
//! finding into an error naming time, channel and the repair option; the navigation job
//! ([`super::job`]) calls it unless spike repair is on, because one such sample rotates
//! the attitude by Δθ = ω·Δt (10⁴ rad for 10⁶ rad/s at 100 Hz) and turns the solution
//! into one no check afterwards can vouch for. [`repair_spikes`] replaces each
//! non-physical or outlier run of at most [`ImuCheckConfig::max_repair_samples`] (2)
//! samples by linear interpolation in time between its two neighbours (on that channel
//! only) and refuses longer runs and runs at either end of the log (nothing to
//! interpolate from). Outliers and saturation are warnings: a test on statistics can be
//! wrong about a real transient, and clipping bounds the error it causes; the GNSS
//! updates see the consequence.

use driftless_model::linalg::{Mat3, Vec3};

use super::pipeline::ImuStream;

/// One IMU channel, in the sensor's own axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ImuChannel {
    /// Angular rate about x.
    GyroX,
    /// Angular rate about y.
    GyroY,
    /// Angular rate about z.
    GyroZ,
    /// Specific force along x.
    AccelX,
    /// Specific force along y.
    AccelY,
    /// Specific force along z.
    AccelZ,
}

impl ImuChannel {
    /// Every channel: gyro x, y, z, then accelerometer x, y, z.
    pub const ALL: [ImuChannel; 6] = [
        ImuChannel::GyroX,
        ImuChannel::GyroY,
        ImuChannel::GyroZ,
        ImuChannel::AccelX,
        ImuChannel::AccelY,
        ImuChannel::AccelZ,
    ];

    /// `gyro_x` … `accel_z`.
    pub fn name(self) -> &'static str {
        match self {
            ImuChannel::GyroX => "gyro_x",
            ImuChannel::GyroY => "gyro_y",
            ImuChannel::GyroZ => "gyro_z",
            ImuChannel::AccelX => "accel_x",
            ImuChannel::AccelY => "accel_y",
            ImuChannel::AccelZ => "accel_z",
        }
    }

    /// True for the three gyro channels.
    pub(crate) fn is_gyro(self) -> bool {
        (self as usize) < 3
    }

    /// Axis 0, 1, 2 within its triad.
    pub fn axis(self) -> usize {
        self as usize % 3
    }

    /// A value of this channel in SI (rad/s or m/s²) for display: °/s or g.
    pub fn display(self, value_si: f64) -> String {
        if self.is_gyro() {
            format!("{:.6} deg/s", value_si.to_degrees())
        } else {
            format!(
                "{:.6} g",
                value_si / driftless_model::units::STANDARD_GRAVITY
            )
        }
    }
}

impl std::fmt::Display for ImuChannel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a finding is (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FindingKind {
    /// Above the hard physical limit.
    NonPhysical,
    /// An isolated one-sample outlier (Hampel test on the spike residual).
    Outlier,
    /// A run pinned at the channel's extreme value.
    Saturated,
}

impl FindingKind {
    /// `non_physical`, `outlier`, `saturated`.
    pub fn name(self) -> &'static str {
        match self {
            FindingKind::NonPhysical => "non_physical",
            FindingKind::Outlier => "outlier",
            FindingKind::Saturated => "saturated",
        }
    }
}

/// One finding: a sample or a run of samples of one channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuFinding {
    /// What it is.
    pub kind: FindingKind,
    /// Which channel.
    pub channel: ImuChannel,
    /// Index of the (first) epoch in the stream.
    pub index: usize,
    /// Its time, s (the stream's time).
    pub time_s: f64,
    /// Number of consecutive epochs (1 for an outlier).
    pub samples: usize,
    /// The (largest) value, SI (rad/s or m/s²); the pinned value of a saturated run.
    pub value_si: f64,
    /// What it was compared with: the limit (non-physical), the mean of the two
    /// neighbours (outlier), the median of the channel (saturated), SI.
    pub reference_si: f64,
    /// Replaced by interpolation ([`repair_spikes`]).
    pub repaired: bool,
}

impl ImuFinding {
    /// One line: kind, channel, time, value.
    pub fn describe(&self) -> String {
        let ch = self.channel;
        let run = if self.samples > 1 {
            format!(" ({} samples)", self.samples)
        } else {
            String::new()
        };
        let what = match self.kind {
            FindingKind::NonPhysical => format!(
                "non-physical value {} (limit {}){run}",
                ch.display(self.value_si),
                ch.display(self.reference_si)
            ),
            FindingKind::Outlier => format!(
                "isolated outlier {} (neighbours' mean {})",
                ch.display(self.value_si),
                ch.display(self.reference_si)
            ),
            FindingKind::Saturated => format!(
                "pinned at {} for {} samples (saturation; channel median {})",
                ch.display(self.value_si),
                self.samples,
                ch.display(self.reference_si)
            ),
        };
        let fix = if self.repaired {
            "; replaced by interpolation of its neighbours"
        } else {
            ""
        };
        format!(
            "IMU {ch} at t = {:.3} s (epoch {}): {what}{fix}",
            self.time_s, self.index
        )
    }
}

/// Thresholds of the checks (module docs for their sources).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuCheckConfig {
    /// Hard limit on |ω| per axis, rad/s. Default 4000 °/s.
    pub max_gyro_rad_s: f64,
    /// Hard limit on |f| per axis, m/s². Default 400 g.
    pub max_accel_m_s2: f64,
    /// Half-width h of the outlier test's window, samples. Default 50.
    pub outlier_half_window: usize,
    /// Threshold k of the outlier test, in robust σ (1.4826·MAD). Default 10.
    pub outlier_threshold: f64,
    /// Smallest gyro spike residual |r| tested, rad/s. Default 2 rad/s.
    pub outlier_min_gyro_rad_s: f64,
    /// Smallest accelerometer spike residual |r| tested, m/s². Default 3 g.
    pub outlier_min_accel_m_s2: f64,
    /// Shortest pinned run reported as saturation, samples. Default 3.
    pub saturation_min_samples: usize,
    /// Smallest |value| a gyro can saturate at, rad/s. Default 100 °/s.
    pub saturation_min_gyro_rad_s: f64,
    /// Smallest |value| an accelerometer can saturate at, m/s². Default 1.5 g.
    pub saturation_min_accel_m_s2: f64,
    /// Longest run [`repair_spikes`] interpolates over, samples. Default 2.
    pub max_repair_samples: usize,
}

impl Default for ImuCheckConfig {
    fn default() -> Self {
        use driftless_model::units::STANDARD_GRAVITY as G;
        ImuCheckConfig {
            max_gyro_rad_s: 4000f64.to_radians(),
            max_accel_m_s2: 400.0 * G,
            outlier_half_window: 50,
            outlier_threshold: 10.0,
            outlier_min_gyro_rad_s: 2.0,
            outlier_min_accel_m_s2: 3.0 * G,
            saturation_min_samples: 3,
            saturation_min_gyro_rad_s: 100f64.to_radians(),
            saturation_min_accel_m_s2: 1.5 * G,
            max_repair_samples: 2,
        }
    }
}

impl ImuCheckConfig {
    /// Checks every value (finite, positive; window ≥ 2 samples).
    pub fn validate(&self) -> Result<(), ImuCheckError> {
        let pos = [
            ("max_gyro_rad_s", self.max_gyro_rad_s),
            ("max_accel_m_s2", self.max_accel_m_s2),
            ("outlier_threshold", self.outlier_threshold),
            ("outlier_min_gyro_rad_s", self.outlier_min_gyro_rad_s),
            ("outlier_min_accel_m_s2", self.outlier_min_accel_m_s2),
            ("saturation_min_gyro_rad_s", self.saturation_min_gyro_rad_s),
            ("saturation_min_accel_m_s2", self.saturation_min_accel_m_s2),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(ImuCheckError::Config(format!(
                    "{name} = {v} must be finite and > 0"
                )));
            }
        }
        if self.outlier_half_window < 2 || self.saturation_min_samples < 2 {
            return Err(ImuCheckError::Config(format!(
                "outlier_half_window ({}) and saturation_min_samples ({}) must be ≥ 2",
                self.outlier_half_window, self.saturation_min_samples
            )));
        }
        Ok(())
    }

    fn limit(&self, ch: ImuChannel) -> f64 {
        if ch.is_gyro() {
            self.max_gyro_rad_s
        } else {
            self.max_accel_m_s2
        }
    }

    fn outlier_floor(&self, ch: ImuChannel) -> f64 {
        if ch.is_gyro() {
            self.outlier_min_gyro_rad_s
        } else {
            self.outlier_min_accel_m_s2
        }
    }

    fn saturation_floor(&self, ch: ImuChannel) -> f64 {
        if ch.is_gyro() {
            self.saturation_min_gyro_rad_s
        } else {
            self.saturation_min_accel_m_s2
        }
    }
}

/// What [`check_imu`] found, in time order (then channel order).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuCheckReport {
    /// Epochs checked.
    pub epochs: usize,
    /// The findings.
    pub findings: Vec<ImuFinding>,
}

impl ImuCheckReport {
    /// Number of findings of a kind.
    pub fn count(&self, kind: FindingKind) -> usize {
        self.findings.iter().filter(|f| f.kind == kind).count()
    }
    /// The findings of a kind.
    pub(crate) fn of_kind(&self, kind: FindingKind) -> impl Iterator<Item = &ImuFinding> {
        self.findings.iter().filter(move |f| f.kind == kind)
    }
    /// Findings replaced by [`repair_spikes`].
    pub fn repaired(&self) -> usize {
        self.findings.iter().filter(|f| f.repaired).count()
    }
    /// Non-physical findings not repaired: what [`refuse_non_physical`] refuses.
    pub(crate) fn unrepaired_non_physical(&self) -> impl Iterator<Item = &ImuFinding> {
        self.of_kind(FindingKind::NonPhysical)
            .filter(|f| !f.repaired)
    }
}

/// Errors of the IMU value checks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImuCheckError {
    /// A threshold out of range.
    #[error("IMU check: {0}")]
    Config(String),
    /// Non-physical values that navigation would integrate.
    #[error(
        "{source_name}: IMU {channel} at t = {time_s:.3} s (epoch {index}): non-physical value {value} \
         (limit {limit}){more}; navigation refuses to integrate it: pass --repair-spikes \
         (imu.repair_spikes = true) to replace isolated spikes by interpolation of their \
         neighbours, or raise the limit (--max-gyro-deg-s, --max-accel-g) if the sensor \
         really measures such values"
    )]
    NonPhysical {
        /// Source of the IMU data.
        source_name: String,
        /// Channel of the first such finding.
        channel: ImuChannel,
        /// Its epoch index.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// The value, display units.
        value: String,
        /// The limit, display units.
        limit: String,
        /// How many more findings, as text (empty when none).
        more: String,
    },
    /// A run that interpolation cannot bridge.
    #[error(
        "{source_name}: IMU {channel} at t = {time_s:.3} s (epoch {index}): {samples} consecutive \
         {kind} samples{why}: not an isolated spike, so it is not repaired by interpolation; \
         cut this stretch from the log"
    )]
    NotRepairable {
        /// Source of the IMU data.
        source_name: String,
        /// Channel.
        channel: ImuChannel,
        /// First epoch of the run.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Run length.
        samples: usize,
        /// `non-physical` or `outlier`.
        kind: &'static str,
        /// Why (too long, at an end of the log).
        why: String,
    },
}

/// The rate of channel `ch` at every epoch, sensor axes (module docs).
fn channel_rates(stream: &ImuStream, c_bv: Option<&Mat3>) -> [Vec<f64>; 6] {
    let n = stream.epochs.len();
    let mut out: [Vec<f64>; 6] = std::array::from_fn(|_| Vec::with_capacity(n));
    for e in &stream.epochs {
        let inv = 1.0 / e.dt_s;
        let w: Vec3 = e.dtheta_rad.map(|v| v * inv);
        let f: Vec3 = e.dvel_m_s.map(|v| v * inv);
        let (w, f) = match c_bv {
            Some(c) => (c.mul_vec(w), c.mul_vec(f)),
            None => (w, f),
        };
        for k in 0..3 {
            out[k].push(w[k]);
            out[3 + k].push(f[k]);
        }
    }
    out
}

/// Median of `v` (upper median for even lengths; reorders it); NaN when empty.
fn median(v: &mut [f64]) -> f64 {
    crate::numeric::upper_median(v).unwrap_or(f64::NAN)
}

/// Checks the values of `stream` (module docs). `c_vb` is the mounting rotation the
/// stream was built with (IMU axes → vehicle axes; `None` when the stream is in the IMU's
/// own axes), so the checks and the findings are on the sensor's channels.
pub fn check_imu(
    stream: &ImuStream,
    c_vb: Option<&Mat3>,
    cfg: &ImuCheckConfig,
) -> Result<ImuCheckReport, ImuCheckError> {
    cfg.validate()?;
    let c_bv = c_vb.map(Mat3::t);
    let rates = channel_rates(stream, c_bv.as_ref());
    let time = |i: usize| stream.epochs[i].time_s;
    let mut findings = Vec::new();
    let mut window = Vec::with_capacity(2 * cfg.outlier_half_window + 1);
    for ch in ImuChannel::ALL {
        let x = &rates[ch as usize];
        let n = x.len();
        let limit = cfg.limit(ch);
        let bad = |i: usize| x[i].abs() > limit;
        // Non-physical runs.
        let mut i = 0;
        while i < n {
            if !bad(i) {
                i += 1;
                continue;
            }
            let start = i;
            let mut worst = x[i];
            while i < n && bad(i) {
                if x[i].abs() > worst.abs() {
                    worst = x[i];
                }
                i += 1;
            }
            findings.push(ImuFinding {
                kind: FindingKind::NonPhysical,
                channel: ch,
                index: start,
                time_s: time(start),
                samples: i - start,
                value_si: worst,
                reference_si: limit.copysign(worst),
                repaired: false,
            });
        }
        // Isolated outliers: the spike residual r_i against its window.
        let resid = |i: usize| x[i] - 0.5 * (x[i - 1] + x[i + 1]);
        let floor = cfg.outlier_floor(ch);
        let h = cfg.outlier_half_window;
        for i in 1..n.saturating_sub(1) {
            let r = resid(i);
            if r.abs() <= floor || r.abs() < (x[i + 1] - x[i - 1]).abs() {
                continue;
            }
            if bad(i) || bad(i - 1) || bad(i + 1) {
                continue;
            }
            // Window i ± h of residuals, without i − 1, i, i + 1 and non-physical samples.
            window.clear();
            let lo = i.saturating_sub(h).max(1);
            let hi = (i + h).min(n - 2);
            for j in lo..=hi {
                if j + 1 >= i && j <= i + 1 {
                    continue;
                }
                if bad(j - 1) || bad(j) || bad(j + 1) {
                    continue;
                }
                window.push(resid(j));
            }
            if window.len() < 4 {
                continue;
            }
            let med = median(&mut window);
            for v in window.iter_mut() {
                *v = (*v - med).abs();
            }
            let sigma = 1.4826 * median(&mut window);
            if (r - med).abs() > cfg.outlier_threshold * sigma {
                findings.push(ImuFinding {
                    kind: FindingKind::Outlier,
                    channel: ch,
                    index: i,
                    time_s: time(i),
                    samples: 1,
                    value_si: x[i],
                    reference_si: 0.5 * (x[i - 1] + x[i + 1]),
                    repaired: false,
                });
            }
        }
        // Saturation: runs pinned at the channel's extreme values.
        let finite_max = x.iter().copied().filter(|v| v.abs() <= limit);
        let (lo_v, hi_v) = finite_max.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let sat_floor = cfg.saturation_floor(ch);
        let mut chan_median = None;
        for extreme in [hi_v, lo_v] {
            if !(extreme.is_finite() && extreme.abs() >= sat_floor) {
                continue;
            }
            let tol = 1e-9 * extreme.abs();
            let pinned = |i: usize| (x[i] - extreme).abs() <= tol;
            let mut i = 0;
            while i < n {
                if !pinned(i) {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < n && pinned(i) {
                    i += 1;
                }
                if i - start >= cfg.saturation_min_samples {
                    let med = *chan_median.get_or_insert_with(|| median(&mut x.clone()));
                    findings.push(ImuFinding {
                        kind: FindingKind::Saturated,
                        channel: ch,
                        index: start,
                        time_s: time(start),
                        samples: i - start,
                        value_si: extreme,
                        reference_si: med,
                        repaired: false,
                    });
                }
            }
            if hi_v == lo_v {
                break;
            }
        }
    }
    findings.sort_by_key(|f| (f.index, f.channel));
    Ok(ImuCheckReport {
        epochs: stream.epochs.len(),
        findings,
    })
}

/// The error [`refuse_non_physical`] returns for the first unrepaired non-physical finding
/// (`None` when there is none).
pub(crate) fn non_physical_error(
    report: &ImuCheckReport,
    source_name: &str,
) -> Option<ImuCheckError> {
    let mut it = report.unrepaired_non_physical();
    let first = it.next()?;
    let rest = it.count();
    let more = if rest > 0 {
        format!(" and {rest} more such run(s)")
    } else {
        String::new()
    };
    Some(ImuCheckError::NonPhysical {
        source_name: source_name.to_owned(),
        channel: first.channel,
        index: first.index,
        time_s: first.time_s,
        value: first.channel.display(first.value_si),
        limit: first.channel.display(first.reference_si.abs()),
        more,
    })
}

/// Err for the first non-physical finding not repaired (module docs, policy).
pub fn refuse_non_physical(
    report: &ImuCheckReport,
    source_name: &str,
) -> Result<(), ImuCheckError> {
    match non_physical_error(report, source_name) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Replaces every non-physical and outlier finding of at most
/// [`ImuCheckConfig::max_repair_samples`] samples, on its channel only, by linear
/// interpolation in time between the neighbouring samples: x_j = x_a + (x_b − x_a)·
/// (t_j − t_a)/(t_b − t_a), a and b the epochs before and after the run (sensor axes,
/// then rotated back by C_vb). Marks them [`ImuFinding::repaired`] and returns how many
/// were. A longer run, or one at the first or last epoch, is an error
/// ([`ImuCheckError::NotRepairable`]) when it is non-physical and is left alone (reported,
/// not repaired) when it is an outlier. `c_vb` as for [`check_imu`].
pub fn repair_spikes(
    stream: &mut ImuStream,
    c_vb: Option<&Mat3>,
    report: &mut ImuCheckReport,
    cfg: &ImuCheckConfig,
) -> Result<usize, ImuCheckError> {
    cfg.validate()?;
    let c_bv = c_vb.map(Mat3::t);
    let n = stream.epochs.len();
    let mut done = 0;
    for f in report.findings.iter_mut() {
        if f.kind == FindingKind::Saturated || f.repaired {
            continue;
        }
        let (a, b) = (f.index.checked_sub(1), f.index + f.samples);
        let ok = f.samples <= cfg.max_repair_samples && b < n;
        let Some(a) = a.filter(|_| ok) else {
            if f.kind == FindingKind::Outlier {
                continue;
            }
            let why = if f.samples > cfg.max_repair_samples {
                format!(" (more than {})", cfg.max_repair_samples)
            } else {
                " at an end of the log".to_string()
            };
            return Err(ImuCheckError::NotRepairable {
                source_name: stream.source.clone(),
                channel: f.channel,
                index: f.index,
                time_s: f.time_s,
                samples: f.samples,
                kind: "non-physical",
                why,
            });
        };
        let sensor = |e: &super::mechanization::ImuIncrement| -> (Vec3, Vec3) {
            let inv = 1.0 / e.dt_s;
            let w: Vec3 = e.dtheta_rad.map(|v| v * inv);
            let fb: Vec3 = e.dvel_m_s.map(|v| v * inv);
            match &c_bv {
                Some(c) => (c.mul_vec(w), c.mul_vec(fb)),
                None => (w, fb),
            }
        };
        let value = |e: &super::mechanization::ImuIncrement| {
            let (w, fb) = sensor(e);
            if f.channel.is_gyro() {
                w[f.channel.axis()]
            } else {
                fb[f.channel.axis()]
            }
        };
        let (ea, eb) = (stream.epochs[a], stream.epochs[b]);
        let (xa, xb) = (value(&ea), value(&eb));
        for j in f.index..b {
            let e = &mut stream.epochs[j];
            let x = xa + (xb - xa) * (e.time_s - ea.time_s) / (eb.time_s - ea.time_s);
            let (mut w, mut fb) = sensor(e);
            if f.channel.is_gyro() {
                w[f.channel.axis()] = x;
            } else {
                fb[f.channel.axis()] = x;
            }
            let (w, fb) = match c_vb {
                Some(c) => (c.mul_vec(w), c.mul_vec(fb)),
                None => (w, fb),
            };
            e.dtheta_rad = w.map(|v| v * e.dt_s);
            e.dvel_m_s = fb.map(|v| v * e.dt_s);
        }
        f.repaired = true;
        done += 1;
    }
    Ok(done)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::mechanization::ImuIncrement;

    /// A 100-Hz stream of rates `w(i)`, `f(i)` at t = i/100.
    fn stream(n: usize, w: impl Fn(usize) -> Vec3, f: impl Fn(usize) -> Vec3) -> ImuStream {
        let dt = 0.01;
        ImuStream {
            source: "test".into(),
            nominal_dt_s: dt,
            epochs: (0..n)
                .map(|i| ImuIncrement {
                    time_s: (i + 1) as f64 * dt,
                    dt_s: dt,
                    dtheta_rad: w(i).map(|v| v * dt),
                    dvel_m_s: f(i).map(|v| v * dt),
                })
                .collect(),
            ..ImuStream::default()
        }
    }

    /// Deterministic pseudo-noise in [−1, 1).
    fn noise(i: usize, k: usize) -> f64 {
        let mut s = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ ((k as u64 + 1) * 0xBF58_476D);
        s ^= s >> 31;
        s = s.wrapping_mul(0x94D0_49BB_1331_11EB);
        s ^= s >> 29;
        (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn quiet(n: usize) -> ImuStream {
        stream(
            n,
            |i| std::array::from_fn(|k| 0.01 * noise(i, k)),
            |i| std::array::from_fn(|k| [0.0, 0.0, -9.81][k] + 0.05 * noise(i, k + 3)),
        )
    }

    #[test]
    fn a_non_physical_gyro_sample_is_found_refused_and_repaired() {
        let mut s = quiet(500);
        let before = s.epochs[201];
        s.epochs[200].dtheta_rad[2] += 1e6 * 0.01;
        let cfg = ImuCheckConfig::default();
        let mut r = check_imu(&s, None, &cfg).unwrap();
        assert_eq!(r.count(FindingKind::NonPhysical), 1, "{r:?}");
        let f = r.findings[0];
        assert_eq!((f.channel, f.index, f.samples), (ImuChannel::GyroZ, 200, 1));
        assert!((f.time_s - 2.01).abs() < 1e-12);
        let e = refuse_non_physical(&r, "test").unwrap_err().to_string();
        assert!(e.contains("gyro_z") && e.contains("2.010 s") && e.contains("--repair-spikes"));
        assert_eq!(repair_spikes(&mut s, None, &mut r, &cfg).unwrap(), 1);
        assert!(refuse_non_physical(&r, "test").is_ok());
        let (a, b) = (s.epochs[199].dtheta_rad[2], s.epochs[201].dtheta_rad[2]);
        assert!((s.epochs[200].dtheta_rad[2] - 0.5 * (a + b)).abs() < 1e-15);
        assert_eq!(s.epochs[201], before);
        assert!(check_imu(&s, None, &cfg).unwrap().findings.is_empty());
    }

    #[test]
    fn mounting_is_undone_so_the_sensor_channel_is_named_and_repaired_alone() {
        let c_vb = Mat3([[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
        let mut s = quiet(300);
        for e in &mut s.epochs {
            e.dtheta_rad = c_vb.mul_vec(e.dtheta_rad);
            e.dvel_m_s = c_vb.mul_vec(e.dvel_m_s);
        }
        let sensor_before = c_vb.t().mul_vec(s.epochs[150].dvel_m_s);
        // +500 g on the sensor's y axis = the vehicle's z axis.
        s.epochs[150].dvel_m_s[2] += 500.0 * 9.80665 * 0.01;
        let cfg = ImuCheckConfig::default();
        let mut r = check_imu(&s, Some(&c_vb), &cfg).unwrap();
        assert_eq!(r.findings.len(), 1, "{r:?}");
        assert_eq!(r.findings[0].channel, ImuChannel::AccelY);
        repair_spikes(&mut s, Some(&c_vb), &mut r, &cfg).unwrap();
        let after = c_vb.t().mul_vec(s.epochs[150].dvel_m_s);
        assert!((after[0] - sensor_before[0]).abs() < 1e-12);
        assert!((after[2] - sensor_before[2]).abs() < 1e-12);
    }

    #[test]
    fn an_isolated_outlier_is_found_but_steps_and_ramps_are_not() {
        // A 20-rad/s yaw-rate step at 1 s and a 2000-°/s² ramp over 3–4 s: real motion.
        let w = |i: usize| -> Vec3 {
            let t = i as f64 * 0.01;
            let step = if t >= 1.0 { 20.0 } else { 0.0 };
            let ramp = 2000f64.to_radians() * (t - 3.0).clamp(0.0, 1.0);
            [
                0.01 * noise(i, 0),
                ramp + 0.01 * noise(i, 1),
                step + 0.01 * noise(i, 2),
            ]
        };
        let mut s = stream(600, w, |i| [0.05 * noise(i, 3), 0.0, -9.81]);
        let cfg = ImuCheckConfig::default();
        let clean = check_imu(&s, None, &cfg).unwrap();
        assert!(clean.findings.is_empty(), "{clean:?}");
        // A 3-rad/s one-sample glitch on gyro_x at 2 s.
        s.epochs[200].dtheta_rad[0] += 3.0 * 0.01;
        let r = check_imu(&s, None, &cfg).unwrap();
        assert_eq!(r.findings.len(), 1, "{r:?}");
        assert_eq!(
            (
                r.findings[0].kind,
                r.findings[0].channel,
                r.findings[0].index
            ),
            (FindingKind::Outlier, ImuChannel::GyroX, 200)
        );
        // Below the floor: not reported.
        s.epochs[200].dtheta_rad[0] -= 2.5 * 0.01;
        assert!(check_imu(&s, None, &cfg).unwrap().findings.is_empty());
    }

    #[test]
    fn a_pinned_run_is_saturation_and_a_quantised_static_signal_is_not() {
        let lsb = 0.001;
        // Quantised static signal: repeats its largest code many times.
        let q = |v: f64| (v / lsb).round() * lsb;
        let mut s = stream(
            1000,
            |i| std::array::from_fn(|k| q(0.002 * noise(i, k))),
            |i| std::array::from_fn(|k| q([0.0, 0.0, -9.81][k] + 0.02 * noise(i, k + 3))),
        );
        let cfg = ImuCheckConfig::default();
        assert!(check_imu(&s, None, &cfg).unwrap().findings.is_empty());
        // A swing on gyro_y clipped at 250 °/s for 5 samples.
        let clip = 250f64.to_radians();
        for (j, e) in s.epochs[400..420].iter_mut().enumerate() {
            let v = (8.0 * (j as f64 / 19.0 * std::f64::consts::PI).sin()).min(clip);
            e.dtheta_rad[1] = v * 0.01;
        }
        let r = check_imu(&s, None, &cfg).unwrap();
        let sat: Vec<_> = r.of_kind(FindingKind::Saturated).collect();
        assert_eq!(sat.len(), 1, "{r:?}");
        assert_eq!(sat[0].channel, ImuChannel::GyroY);
        assert!(sat[0].samples >= 3);
        assert!((sat[0].value_si - clip).abs() < 1e-12);
    }

    #[test]
    fn a_long_non_physical_run_is_not_repaired() {
        let mut s = quiet(200);
        for e in &mut s.epochs[100..104] {
            e.dtheta_rad[0] = 1e3 * e.dt_s;
        }
        let cfg = ImuCheckConfig::default();
        let mut r = check_imu(&s, None, &cfg).unwrap();
        assert_eq!(r.findings[0].samples, 4);
        let e = repair_spikes(&mut s, None, &mut r, &cfg).unwrap_err();
        assert!(
            matches!(e, ImuCheckError::NotRepairable { samples: 4, .. }),
            "{e}"
        );
    }
}

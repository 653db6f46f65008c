//! Typed, columnar in-memory IMU log.

use serde::{Deserialize, Serialize};

/// Physical quantity of a column after unit conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Angular rate, rad/s.
    AngularRate,
    /// Specific force, m/s².
    SpecificForce,
    /// Temperature, °C.
    Temperature,
    /// Anything else: stored as given (dimensionless / user unit).
    Other,
}

impl Quantity {
    /// SI unit label.
    pub fn si_unit(self) -> &'static str {
        match self {
            Quantity::AngularRate => "rad/s",
            Quantity::SpecificForce => "m/s^2",
            Quantity::Temperature => "degC",
            Quantity::Other => "",
        }
    }
}

/// One data column, converted to SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Column name (`gyro_x`, `acc_z`, `col3`, …).
    pub name: String,
    /// What the column measures.
    pub quantity: Quantity,
    /// The unit the file used (for display: `deg/s`, `mg`, `counts*0.001`).
    pub source_unit: String,
    /// Samples in SI units.
    pub values: Vec<f64>,
}

/// A gap in the time column: the interval between two consecutive rows exceeded the
/// gap threshold (`gap_factor × τ0`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeGap {
    /// Index of the first row after the gap (the gap lies between rows `index - 1` and `index`).
    pub index: usize,
    /// Time stamp of the row before the gap, s.
    pub start_s: f64,
    /// Length of the interval `t[index] - t[index - 1]`, s.
    pub duration_s: f64,
}

/// A columnar log: optional time stamps plus data channels of equal length.
///
/// Build one with [`ImuLog::new`] (or `ImuLog { .., ..Default::default() }`) so that
/// fields added later keep their neutral defaults.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuLog {
    /// Where it came from (file path or `simulated:…`).
    pub source: String,
    /// Time stamps, s, strictly increasing, if the file had a time column.
    pub time_s: Option<Vec<f64>>,
    /// Nominal sample interval τ0, s (from `--rate`, the time column, or the binary header).
    pub tau0_s: f64,
    /// Data channels, equal lengths.
    pub channels: Vec<Channel>,
    /// Contiguous row ranges to analyse independently. One full range `0..len` when the
    /// log has no gaps or gaps were bridged; several when a reader split at gaps
    /// ([`crate::io::GapPolicy::Split`]). Empty only for an empty log.
    pub segments: Vec<std::ops::Range<usize>>,
    /// Time gaps found by the reader (with `GapPolicy::Split` or `GapPolicy::Bridge`), in
    /// row order; callers should warn about them. Empty when there were none.
    pub gaps: Vec<TimeGap>,
    /// Week number of the first row when the time came as week + seconds of week
    /// ([`crate::io::TextOptions::week_column`]); `time_s` then counts seconds from the
    /// start of that week. `None` otherwise.
    pub week: Option<u16>,
    /// What the reader dropped and why (a truncated first or last record, see
    /// [`crate::io::TextOptions::drop_truncated_edges`]), one message per item, naming file
    /// and line, for the caller to show. Empty when nothing was dropped.
    pub notes: Vec<String>,
}

impl ImuLog {
    /// A log with one full-range segment and no gaps.
    pub fn new(
        source: impl Into<String>,
        time_s: Option<Vec<f64>>,
        tau0_s: f64,
        channels: Vec<Channel>,
    ) -> Self {
        let n = channels
            .first()
            .map(|c| c.values.len())
            .or_else(|| time_s.as_ref().map(Vec::len))
            .unwrap_or(0);
        ImuLog {
            source: source.into(),
            time_s,
            tau0_s,
            channels,
            segments: if n > 0 {
                std::iter::once(0..n).collect()
            } else {
                Vec::new()
            },
            gaps: Vec::new(),
            week: None,
            notes: Vec::new(),
        }
    }
    /// The channel with this name, if any.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }
    /// Indices of the channels of quantity `q`, in file order.
    pub fn indices_of(&self, q: Quantity) -> Vec<usize> {
        (0..self.channels.len())
            .filter(|&i| self.channels[i].quantity == q)
            .collect()
    }
    /// The samples of the channels of quantity `q` as a triad (x, y, z in file order),
    /// when there are exactly three.
    pub fn triad_of(&self, q: Quantity) -> Option<[&[f64]; 3]> {
        match self.indices_of(q).as_slice() {
            &[a, b, c] => Some([a, b, c].map(|i| self.channels[i].values.as_slice())),
            _ => None,
        }
    }
    /// Number of samples per channel.
    pub fn len(&self) -> usize {
        self.channels.first().map(|c| c.values.len()).unwrap_or(0)
    }
    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

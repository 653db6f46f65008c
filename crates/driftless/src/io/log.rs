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

/// A columnar log: optional time stamps plus data channels of equal length.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuLog {
    /// Where it came from (file path or `simulated:…`).
    pub source: String,
    /// Time stamps, s, strictly increasing, if the file had a time column.
    pub time_s: Option<Vec<f64>>,
    /// Nominal sample interval τ0, s (from `--rate`, the time column, or the binary header).
    pub tau0_s: f64,
    /// Data channels, equal lengths.
    pub channels: Vec<Channel>,
}

impl ImuLog {
    /// Number of samples per channel.
    pub fn len(&self) -> usize {
        self.channels.first().map(|c| c.values.len()).unwrap_or(0)
    }
    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

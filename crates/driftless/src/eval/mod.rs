//! Evaluation of navigation solutions against a reference trajectory: which dynamics a drive contains, where to put the GNSS outages, and the
//! errors a solution makes inside them.
//!
//! The intended flow of an outage experiment (the paper's Table 1):
//!
//! 1. Build the **reference** as a [`NavSolution`](crate::io::nav::NavSolution): a smoothed best estimate, a
//!    simulation's truth ([`reference::sample_trajectory`]) or RTK fixes
//!    ([`reference::reference_from_fixes`]).
//! 2. **Select** the outage windows once from the reference: automatically
//!    ([`select::select_outages`], N windows of L s covering the dynamics classes of
//!    [`dynamics`]) or from a user's `--outages` text ([`select::resolve_outages`], which
//!    also validates user windows). All checks run before any filtering, so a wrong
//!    scenario fails at once.
//! 3. Run any number of solutions (raw, calibrated, calibrated + thermal; forward and
//!    smoothed) with GNSS withheld in those windows, and **score** each against the same
//!    reference with [`metrics::outage_errors`].
//!
//! Conventions: SI inside (s, m, rad); results carry display units in their field names
//! (`end_horizontal_m`, `end_heading_deg`). Times are GPS seconds of week, the time
//! column of the trajectories. A window is the half-open interval (start, end]
//! of [`OutageWindow`]: the fix at the start is used, the one at the end is withheld.

pub mod accuracy;
pub mod dynamics;
pub mod metrics;
pub mod reference;
pub mod select;

pub use accuracy::horizontal_rms_m;
pub use dynamics::{ClassMix, Dynamics, DynamicsThresholds, classify};
pub use metrics::{MetricOptions, OutageErrors, OutageReport, outage_errors};
pub use select::{SelectOptions, SelectedOutage, check_outages, resolve_outages, select_outages};

use crate::nav::outage::{OutageError, OutageWindow};

/// Why an evaluation could not be done. Every variant names what to change.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A trajectory's columns are unusable.
    #[error("{which} trajectory: {reason}")]
    BadTrajectory {
        /// `"reference"` or `"solution"`.
        which: &'static str,
        /// What is wrong, naming the column and epoch.
        reason: String,
    },
    /// An option is out of its range.
    #[error("bad option {name} = {value}: {reason}")]
    BadOption {
        /// The option's field name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range.
        reason: &'static str,
    },
    /// No outages were asked for.
    #[error("asked for 0 outages: the count must be at least 1")]
    ZeroCount,
    /// The outage length is not a positive number of seconds.
    #[error("outage length {length_s} s must be a finite number > 0")]
    NonPositiveLength {
        /// The length given, s.
        length_s: f64,
    },
    /// One outage is longer than the whole reference.
    #[error("an outage of {length_s} s is longer than the reference data ({data_s} s)")]
    LongerThanData {
        /// Outage length, s.
        length_s: f64,
        /// Reference span, s.
        data_s: f64,
    },
    /// N outages with their re-convergence gaps do not fit in the usable reference.
    #[error(
        "{count} outages of {length_s} s with at least {gap_s} s between them need \
         {needed_s:.1} s, but the usable reference spans only {usable_s:.1} s \
         ([{usable_start_s:.1} s, {usable_end_s:.1} s]: {converge_s} s kept for filter \
         convergence at the start, {end_margin_s} s at the end); ask for fewer or shorter \
         outages or a smaller gap"
    )]
    NotEnoughData {
        /// Outages asked for.
        count: usize,
        /// Their length, s.
        length_s: f64,
        /// Minimum gap between consecutive outages, s.
        gap_s: f64,
        /// count·length + (count − 1)·gap, s.
        needed_s: f64,
        /// Usable span, s.
        usable_s: f64,
        /// Usable span start, GPS s.
        usable_start_s: f64,
        /// Usable span end, GPS s.
        usable_end_s: f64,
        /// Convergence margin at the start, s.
        converge_s: f64,
        /// Margin at the end, s.
        end_margin_s: f64,
    },
    /// Selection could not place every window (the reference has too many gaps).
    #[error(
        "could place only {placed} of {count} outages of {length_s} s: the reference has \
         gaps longer than {max_gap_s} s where the others would go"
    )]
    NoRoom {
        /// Windows placed.
        placed: usize,
        /// Windows asked for.
        count: usize,
        /// Their length, s.
        length_s: f64,
        /// Largest reference gap tolerated inside a window, s.
        max_gap_s: f64,
    },
    /// A given window has a non-positive or non-finite length.
    #[error("outage window {window} has no positive finite length")]
    EmptyWindow {
        /// The window.
        window: OutageWindow,
    },
    /// A given window is longer than the reference.
    #[error(
        "outage window {window} lasts {length_s} s, longer than the reference data ({data_s} s)"
    )]
    WindowLongerThanData {
        /// The window.
        window: OutageWindow,
        /// Its length, s.
        length_s: f64,
        /// Reference span, s.
        data_s: f64,
    },
    /// A given window is not inside the reference.
    #[error(
        "outage window {window} lies outside the reference data [{start_s} s, {end_s} s]: {reason}"
    )]
    OutsideData {
        /// The window.
        window: OutageWindow,
        /// Reference start, GPS s.
        start_s: f64,
        /// Reference end, GPS s.
        end_s: f64,
        /// Which end is outside.
        reason: &'static str,
    },
    /// Two given windows overlap.
    #[error("outage windows {first} and {second} overlap")]
    Overlap {
        /// The earlier window.
        first: OutageWindow,
        /// The later one.
        second: OutageWindow,
    },
    /// A window has no reference epochs, or a reference gap inside it.
    #[error("outage window {window}: {reason}")]
    ReferenceGap {
        /// The window.
        window: OutageWindow,
        /// The gap found.
        reason: String,
    },
    /// The solution has no epoch inside a window.
    #[error("outage window {window}: the solution has no epoch inside it")]
    NoSolutionInWindow {
        /// The window.
        window: OutageWindow,
    },
    /// The reference cannot be interpolated at a window's end epoch.
    #[error(
        "outage window {window}: no reference at the end-of-outage epoch {time_s} s (outside \
         the reference, or inside a reference gap longer than {max_gap_s} s)"
    )]
    NoReferenceAtEnd {
        /// The window.
        window: OutageWindow,
        /// The solution epoch, GPS s.
        time_s: f64,
        /// Largest gap interpolated across, s.
        max_gap_s: f64,
    },
    /// The `--outages` text could not be resolved.
    #[error(transparent)]
    Spec(#[from] OutageError),
}

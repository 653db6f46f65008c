//! Per-outage navigation errors against a reference trajectory, and their summary over
//! the outages (the paper's Table 1: position error after 60-s GNSS outages).
//!
//! # Errors of one epoch
//!
//! The reference is interpolated to the solution epoch ([`super::reference::interpolate`]).
//! Errors are **solution minus reference**:
//!
//! * **position**: both points go to ECEF on the WGS-84 ellipsoid
//!   ([`crate::nav::earth::llh_to_ecef`]), and the difference is resolved in the local NED
//!   frame of the reference point: δr^n = C_e^n(φ_ref, λ_ref)·(r^e_sol − r^e_ref) with
//!   C_e^n rows (−sinφ cosλ, −sinφ sinλ, cosφ), (−sinλ, cosλ, 0), (−cosφ cosλ, −cosφ sinλ,
//!   −sinφ) (Groves 2013, eq. 2.150). This is exact at any separation (the small-offset
//!   formula of [`crate::nav::earth::ned_offset_m`] differs from it by ≈ d²·tanφ/R, 0.3 m
//!   at 2 km and 51° latitude — the size of the paper's uncompensated errors).
//!   **Horizontal error** = √(δN² + δE²);
//! * **height error** = h_sol − h_ref (ellipsoidal heights; unlike δD it does not
//!   include the Earth's curvature drop d²/2R of a long horizontal error);
//! * **heading error** = wrap(ψ_sol − ψ_ref) into (−180°, 180°], where both yaws are
//!   known.
//!
//! # One outage (half-open window (a, b], as [`OutageWindow`])
//!
//! The solution epochs a < t ≤ b are dead reckoning (GNSS withheld; the fix at a is
//! the last one used). The **end-of-outage** errors are taken at the last of them,
//! t_end ≤ b (the first fix used again lies after b); the **maximum horizontal error**
//! is over all of them with a reference, the end included. The **error growth** series is
//! (t − a, horizontal error) every `growth_step_s` of the window plus the end epoch.
//!
//! # Summary
//!
//! Over the outages: mean, RMS and maximum of the end horizontal error, the maximum
//! horizontal error, |height error| and |heading error| (magnitudes: signed height and
//! heading errors of different outages would otherwise cancel in the mean).

use serde::{Deserialize, Serialize};

use super::EvalError;
use super::reference::{ReferencePoint, interpolate, validate, wrap_pi};
use crate::io::nav::NavSolution;
use crate::nav::earth::llh_to_ecef;
use crate::nav::outage::OutageWindow;
use driftless_model::linalg::Vec3;

/// Options of the scoring.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricOptions {
    /// Largest reference gap interpolated across, s (2).
    pub max_reference_gap_s: f64,
    /// Spacing of the error-growth series, s (1; 0 keeps every solution epoch).
    pub growth_step_s: f64,
}

impl Default for MetricOptions {
    fn default() -> Self {
        MetricOptions {
            max_reference_gap_s: 2.0,
            growth_step_s: 1.0,
        }
    }
}

/// Position error of one epoch, solution minus reference (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PositionError {
    /// North, east, down components in the reference's local frame, m.
    pub ned_m: Vec3,
    /// √(N² + E²), m.
    pub horizontal_m: f64,
    /// Ellipsoidal height difference, m.
    pub height_m: f64,
}

/// Position error of `solution` against `reference`, both (φ, λ, h) in rad, rad, m
/// (module docs).
pub fn position_error(reference: (f64, f64, f64), solution: (f64, f64, f64)) -> PositionError {
    let (lat, lon, h) = reference;
    let r = llh_to_ecef(lat, lon, h);
    let s = llh_to_ecef(solution.0, solution.1, solution.2);
    let d = [s[0] - r[0], s[1] - r[1], s[2] - r[2]];
    let (sp, cp) = lat.sin_cos();
    let (sl, cl) = lon.sin_cos();
    let n = -sp * cl * d[0] - sp * sl * d[1] + cp * d[2];
    let e = -sl * d[0] + cl * d[1];
    let dn = -cp * cl * d[0] - cp * sl * d[1] - sp * d[2];
    PositionError {
        ned_m: [n, e, dn],
        horizontal_m: n.hypot(e),
        height_m: solution.2 - h,
    }
}

/// Heading error ψ_sol − ψ_ref wrapped into (−π, π], rad.
pub fn heading_error_rad(solution_yaw_rad: f64, reference_yaw_rad: f64) -> f64 {
    wrap_pi(solution_yaw_rad - reference_yaw_rad)
}

/// One point of an error-growth curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GrowthPoint {
    /// Time since the outage start, s.
    pub since_start_s: f64,
    /// Horizontal error, m.
    pub horizontal_m: f64,
}

/// Errors of one outage (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutageErrors {
    /// The window, GPS s.
    pub window: OutageWindow,
    /// Epoch of the end-of-outage errors (the last solution epoch in the window), GPS s.
    pub end_time_s: f64,
    /// Horizontal error at `end_time_s`, m.
    pub end_horizontal_m: f64,
    /// North, east, down error at `end_time_s`, m.
    pub end_ned_m: Vec3,
    /// Height error (solution − reference) at `end_time_s`, m.
    pub end_height_m: f64,
    /// Heading error at `end_time_s` in (−180, 180], deg; `None` when either heading
    /// is unknown there.
    pub end_heading_deg: Option<f64>,
    /// Largest horizontal error inside the window, m.
    pub max_horizontal_m: f64,
    /// Epoch of that maximum, GPS s.
    pub max_time_s: f64,
    /// Solution epochs compared (with a reference) inside the window.
    pub epochs: usize,
    /// Horizontal error growth inside the window.
    pub growth: Vec<GrowthPoint>,
}

/// Mean, RMS and maximum of a set of values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Number of values.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// Root mean square.
    pub rms: f64,
    /// Largest value.
    pub max: f64,
}

impl Stat {
    /// Statistics of `values`; `None` when there are none.
    pub fn of(values: &[f64]) -> Option<Stat> {
        if values.is_empty() {
            return None;
        }
        let n = values.len() as f64;
        Some(Stat {
            count: values.len(),
            mean: values.iter().sum::<f64>() / n,
            rms: (values.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// Summary over the outages (module docs); `None` fields when there is nothing to
/// summarise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OutageSummary {
    /// Number of outages.
    pub outages: usize,
    /// End-of-outage horizontal error, m.
    pub end_horizontal_m: Option<Stat>,
    /// Maximum horizontal error inside each outage, m.
    pub max_horizontal_m: Option<Stat>,
    /// |End-of-outage height error|, m.
    pub end_height_abs_m: Option<Stat>,
    /// |End-of-outage heading error|, deg (outages with known headings only).
    pub end_heading_abs_deg: Option<Stat>,
}

impl OutageSummary {
    /// Summary of per-outage errors.
    pub fn of(outages: &[OutageErrors]) -> OutageSummary {
        let col = |f: &dyn Fn(&OutageErrors) -> Option<f64>| {
            Stat::of(&outages.iter().filter_map(f).collect::<Vec<_>>())
        };
        OutageSummary {
            outages: outages.len(),
            end_horizontal_m: col(&|o| Some(o.end_horizontal_m)),
            max_horizontal_m: col(&|o| Some(o.max_horizontal_m)),
            end_height_abs_m: col(&|o| Some(o.end_height_m.abs())),
            end_heading_abs_deg: col(&|o| o.end_heading_deg.map(f64::abs)),
        }
    }
}

/// Per-outage errors of one solution and their summary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutageReport {
    /// One entry per window, in the order given.
    pub outages: Vec<OutageErrors>,
    /// Over all of them.
    pub summary: OutageSummary,
}

fn check_metric_options(o: &MetricOptions) -> Result<(), EvalError> {
    if !(o.max_reference_gap_s.is_finite() && o.max_reference_gap_s > 0.0) {
        return Err(EvalError::BadOption {
            name: "max_reference_gap_s",
            value: o.max_reference_gap_s,
            reason: "must be a finite number > 0",
        });
    }
    if !(o.growth_step_s.is_finite() && o.growth_step_s >= 0.0) {
        return Err(EvalError::BadOption {
            name: "growth_step_s",
            value: o.growth_step_s,
            reason: "must be a finite number ≥ 0",
        });
    }
    Ok(())
}

fn epoch_error(
    p: &ReferencePoint,
    solution: &NavSolution,
    k: usize,
) -> (PositionError, Option<f64>) {
    let e = position_error(
        (p.lat_rad, p.lon_rad, p.height_m),
        (
            solution.lat_rad[k],
            solution.lon_rad[k],
            solution.height_m[k],
        ),
    );
    let ys = solution.roll_pitch_yaw_rad[k][2];
    let h = match (ys.is_finite(), p.yaw_rad) {
        (true, Some(yr)) => Some(heading_error_rad(ys, yr).to_degrees()),
        _ => None,
    };
    (e, h)
}

/// Errors of `solution` in each of `windows` against `reference` (module docs). Both
/// trajectories are validated first. Errors: no solution epoch in a window; no
/// reference at a window's end epoch.
pub fn outage_errors(
    reference: &NavSolution,
    solution: &NavSolution,
    windows: &[OutageWindow],
    opts: &MetricOptions,
) -> Result<OutageReport, EvalError> {
    validate(reference, "reference")?;
    validate(solution, "solution")?;
    check_metric_options(opts)?;
    let mut outages = Vec::with_capacity(windows.len());
    for &w in windows {
        let t = &solution.time_s;
        let i = t.partition_point(|&x| x <= w.start_s);
        let j = t.partition_point(|&x| x <= w.end_s);
        if i >= j {
            return Err(EvalError::NoSolutionInWindow { window: w });
        }
        let end = j - 1;
        let gap = opts.max_reference_gap_s;
        let Some(pe) = interpolate(reference, t[end], gap) else {
            return Err(EvalError::NoReferenceAtEnd {
                window: w,
                time_s: t[end],
                max_gap_s: gap,
            });
        };
        let (end_err, end_heading) = epoch_error(&pe, solution, end);
        let (mut max_h, mut max_t, mut count) = (f64::NEG_INFINITY, t[end], 0usize);
        let mut growth = Vec::new();
        let mut next_mark = 0.0;
        for (k, &tk) in t.iter().enumerate().take(end + 1).skip(i) {
            let Some(p) = interpolate(reference, tk, gap) else {
                continue;
            };
            let h = epoch_error(&p, solution, k).0.horizontal_m;
            count += 1;
            if h > max_h {
                max_h = h;
                max_t = tk;
            }
            let since = tk - w.start_s;
            if k == end || since >= next_mark - 1e-9 {
                growth.push(GrowthPoint {
                    since_start_s: since,
                    horizontal_m: h,
                });
                if opts.growth_step_s > 0.0 {
                    next_mark =
                        ((since / opts.growth_step_s + 1e-9).floor() + 1.0) * opts.growth_step_s;
                }
            }
        }
        outages.push(OutageErrors {
            window: w,
            end_time_s: t[end],
            end_horizontal_m: end_err.horizontal_m,
            end_ned_m: end_err.ned_m,
            end_height_m: end_err.height_m,
            end_heading_deg: end_heading,
            max_horizontal_m: max_h,
            max_time_s: max_t,
            epochs: count,
            growth,
        });
    }
    let summary = OutageSummary::of(&outages);
    Ok(OutageReport { outages, summary })
}

/// Horizontal error of every solution epoch against `reference` (`None` where the
/// reference cannot be interpolated), e.g. for a full-GNSS RMS.
pub fn horizontal_errors(
    reference: &NavSolution,
    solution: &NavSolution,
    max_reference_gap_s: f64,
) -> Result<Vec<Option<f64>>, EvalError> {
    validate(reference, "reference")?;
    validate(solution, "solution")?;
    check_metric_options(&MetricOptions {
        max_reference_gap_s,
        ..MetricOptions::default()
    })?;
    Ok((0..solution.time_s.len())
        .map(|k| {
            interpolate(reference, solution.time_s[k], max_reference_gap_s)
                .map(|p| epoch_error(&p, solution, k).0.horizontal_m)
        })
        .collect())
}

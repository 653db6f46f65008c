//! Land-vehicle motion profiles in TOML, built into an exact [`LandVehicle`]
//! trajectory (closed-form pieces, see [`super::ideal_imu::DriveSegment`]). A walk is a
//! profile at walking speeds (≈ 1–1.5 m/s, turns by radius down to a metre or two,
//! stops) with an optional `[gait]`: the hand-held carriage of the IMU
//! ([`super::ideal_imu::Gait`]: vertical bob and pitch sway once per step, roll sway once
//! per stride, all driven by the distance walked, so they stop when the walker stops).
//!
//! ```toml
//! [start]
//! lat_deg = 30.5
//! lon_deg = 114.3
//! height_m = 20.0
//! heading_deg = 45.0      # yaw of the vehicle, from north towards east
//! speed_m_s = 0.0         # optional, default 0
//!
//! [mounting]              # optional: IMU (body) axes relative to the vehicle's
//! roll_deg = 0.0          # forward-right-down axes, z-y-x Euler angles, x_v = C_vb x_b
//! pitch_deg = 0.0
//! yaw_deg = 0.0
//!
//! [gait]                  # optional: hand-held walk
//! step_length_m = 0.6     # > 0; step frequency = speed / step length
//! bob_amplitude_m = 0.02  # vertical, ≥ 0 (default 0)
//! pitch_sway_deg = 1.5    # ≥ 0, ≤ 30 (default 0)
//! roll_sway_deg = 2.0     # ≥ 0, ≤ 30 (default 0)
//!
//! [[segment]]
//! type = "stop"
//! duration_s = 5.0
//!
//! [[segment]]
//! type = "accelerate"     # also "brake" (to_speed_m_s defaults to 0)
//! to_speed_m_s = 15.0
//! duration_s = 10.0
//!
//! [[segment]]
//! type = "cruise"         # constant speed: duration_s or distance_m
//! distance_m = 200.0
//!
//! [[segment]]
//! type = "turn"           # angle_deg (positive right) with rate_deg_s (> 0) or radius_m
//! angle_deg = 90.0
//! radius_m = 50.0
//!
//! [[segment]]
//! type = "climb"          # height change at the current speed: duration_s or grade_pct
//! height_change_m = 10.0  # (mean grade, 100·|Δh|/horizontal distance)
//! grade_pct = 5.0
//! ```
//!
//! Units are part of every key name; unknown keys (a misspelt one, or a unit that is
//! not offered such as `speed_km_h`) and wrong types are refused by the parser, which
//! names them. Speeds are horizontal speeds. Motions a land vehicle cannot perform are
//! refused with the segment index (from 0, in file order) and key: negative or
//! non-finite values, non-positive durations, stopping while moving, accelerating to a
//! lower speed (or braking to a higher one), turning by radius (or climbing, or cruising
//! a distance) at zero speed, a zero radius. Durations derived from the other keys:
//! turn T = |angle|/rate or |angle|·R/V; cruise T = distance/V; climb
//! T = |Δh|/(V·grade/100).

use std::path::Path;

use serde::Deserialize;

use super::ideal_imu::{DriveSegment, Gait, LandVehicle};
use super::noise::SimError;
use crate::nav::attitude::Euler;
use driftless_model::units::DEG;

/// Start state of a profile (`[start]`).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartSpec {
    /// Geodetic latitude, deg (|φ| < 90).
    pub lat_deg: f64,
    /// Longitude, deg.
    pub lon_deg: f64,
    /// Ellipsoidal height, m.
    pub height_m: f64,
    /// Initial heading (vehicle yaw), deg from north towards east.
    pub heading_deg: f64,
    /// Initial horizontal speed, m/s (≥ 0; default 0).
    #[serde(default)]
    pub speed_m_s: f64,
}

/// IMU mounting (`[mounting]`): z-y-x Euler angles of the body axes relative to the
/// vehicle's forward-right-down axes (x_v = C_vb x_b).
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MountingSpec {
    /// Roll, deg.
    pub roll_deg: f64,
    /// Pitch, deg.
    pub pitch_deg: f64,
    /// Yaw, deg.
    pub yaw_deg: f64,
}

/// Hand-held carriage (`[gait]`, module documentation; [`Gait`] for the motion).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitSpec {
    /// Step length, m (> 0).
    pub step_length_m: f64,
    /// Vertical bob amplitude, m (≥ 0).
    #[serde(default)]
    pub bob_amplitude_m: f64,
    /// Pitch sway amplitude, deg (0 … 30).
    #[serde(default)]
    pub pitch_sway_deg: f64,
    /// Roll sway amplitude, deg (0 … 30).
    #[serde(default)]
    pub roll_sway_deg: f64,
}

/// One `[[segment]]` as written (module documentation for the keys).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SegmentSpec {
    /// Stand still (the speed must be 0).
    Stop {
        /// Duration, s.
        duration_s: f64,
    },
    /// Speed up to `to_speed_m_s` (above the current speed).
    Accelerate {
        /// Final speed, m/s.
        to_speed_m_s: f64,
        /// Duration, s.
        duration_s: f64,
    },
    /// Slow down to `to_speed_m_s` (below the current speed; default 0).
    Brake {
        /// Final speed, m/s.
        #[serde(default)]
        to_speed_m_s: f64,
        /// Duration, s.
        duration_s: f64,
    },
    /// Constant speed and heading, for a duration or a distance (exactly one).
    Cruise {
        /// Duration, s.
        duration_s: Option<f64>,
        /// Distance, m (needs a non-zero speed).
        distance_m: Option<f64>,
    },
    /// Level turn at the current speed through `angle_deg` (positive right), by yaw
    /// rate or by radius (exactly one).
    Turn {
        /// Heading change, deg.
        angle_deg: f64,
        /// Yaw-rate magnitude, deg/s (> 0).
        rate_deg_s: Option<f64>,
        /// Turn radius, m (> 0; needs a non-zero speed).
        radius_m: Option<f64>,
    },
    /// Straight climb (descent if negative) at the current speed, over a duration or at
    /// a mean grade (exactly one).
    Climb {
        /// Height change, m (non-zero).
        height_change_m: f64,
        /// Duration, s.
        duration_s: Option<f64>,
        /// Mean grade, percent (100·|Δh|/horizontal distance, > 0).
        grade_pct: Option<f64>,
    },
}

impl SegmentSpec {
    /// The `type` value of the segment.
    pub fn kind(&self) -> &'static str {
        match self {
            SegmentSpec::Stop { .. } => "stop",
            SegmentSpec::Accelerate { .. } => "accelerate",
            SegmentSpec::Brake { .. } => "brake",
            SegmentSpec::Cruise { .. } => "cruise",
            SegmentSpec::Turn { .. } => "turn",
            SegmentSpec::Climb { .. } => "climb",
        }
    }
}

/// The file layout; segments are deserialised one by one so that errors name their
/// index.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    start: StartSpec,
    #[serde(default)]
    mounting: MountingSpec,
    #[serde(default)]
    gait: Option<GaitSpec>,
    #[serde(default)]
    segment: Vec<toml::Value>,
}

/// A land-vehicle motion profile (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct MotionProfile {
    /// Start position, heading and speed.
    pub start: StartSpec,
    /// IMU mounting.
    pub mounting: MountingSpec,
    /// Hand-held carriage, if a walk.
    pub gait: Option<GaitSpec>,
    /// Segments in order.
    pub segments: Vec<SegmentSpec>,
}

fn motion(segment: Option<(usize, &'static str)>, key: &'static str, why: String) -> SimError {
    SimError::Motion { segment, key, why }
}

/// Where a motion error occurred: segment index and type, or `None` for the header.
type SegmentAt = Option<(usize, &'static str)>;

/// `v` when finite, else a motion error on `key`.
fn finite(at: SegmentAt, key: &'static str, v: f64) -> Result<f64, SimError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(motion(at, key, format!("{v} is not a finite number")))
    }
}

/// `v` when finite and > 0, else a motion error on `key`.
fn positive(at: SegmentAt, key: &'static str, v: f64) -> Result<f64, SimError> {
    if finite(at, key, v)? > 0.0 {
        Ok(v)
    } else {
        Err(motion(at, key, format!("{v} must be > 0")))
    }
}

/// `v` when a finite speed ≥ 0 m/s, else a motion error on `key`.
fn non_negative_speed(at: SegmentAt, key: &'static str, v: f64) -> Result<f64, SimError> {
    if finite(at, key, v)? >= 0.0 {
        Ok(v)
    } else {
        Err(motion(at, key, format!("negative speed {v} m/s")))
    }
}

/// The one of two alternative keys that is given: (key, value, whether it is `a`).
fn one_of(
    at: SegmentAt,
    a: (&'static str, Option<f64>),
    b: (&'static str, Option<f64>),
) -> Result<(&'static str, f64, bool), SimError> {
    match (a.1, b.1) {
        (Some(x), None) => Ok((a.0, x, true)),
        (None, Some(x)) => Ok((b.0, x, false)),
        _ => Err(motion(
            at,
            a.0,
            format!("give exactly one of {} and {}", a.0, b.0),
        )),
    }
}

/// The current speed `v` when moving, else an error that `what` needs motion.
fn need_speed(at: SegmentAt, v: f64, key: &'static str, what: &str) -> Result<f64, SimError> {
    if v > 0.0 {
        Ok(v)
    } else {
        Err(motion(
            at,
            key,
            format!("{what} at zero speed is impossible: accelerate first"),
        ))
    }
}

/// Checks one segment against the current speed `v`, converts it to a
/// [`DriveSegment`] and updates `v` to the speed at its end.
fn drive_segment(spec: &SegmentSpec, at: SegmentAt, v: &mut f64) -> Result<DriveSegment, SimError> {
    Ok(match *spec {
        SegmentSpec::Stop { duration_s } => {
            let duration_s = positive(at, "duration_s", duration_s)?;
            if *v != 0.0 {
                return Err(motion(
                    at,
                    "type",
                    format!("stop while moving at {v} m/s: brake to 0 first"),
                ));
            }
            DriveSegment::Stop { duration_s }
        }
        SegmentSpec::Accelerate {
            to_speed_m_s,
            duration_s,
        } => {
            let to = non_negative_speed(at, "to_speed_m_s", to_speed_m_s)?;
            let duration_s = positive(at, "duration_s", duration_s)?;
            if to <= *v {
                return Err(motion(
                    at,
                    "to_speed_m_s",
                    format!("{to} m/s is not above the current {v} m/s: use brake"),
                ));
            }
            *v = to;
            DriveSegment::Speed {
                to_m_s: to,
                duration_s,
            }
        }
        SegmentSpec::Brake {
            to_speed_m_s,
            duration_s,
        } => {
            let to = non_negative_speed(at, "to_speed_m_s", to_speed_m_s)?;
            let duration_s = positive(at, "duration_s", duration_s)?;
            if to >= *v {
                return Err(motion(
                    at,
                    "to_speed_m_s",
                    format!("{to} m/s is not below the current {v} m/s: use accelerate"),
                ));
            }
            *v = to;
            DriveSegment::Speed {
                to_m_s: to,
                duration_s,
            }
        }
        SegmentSpec::Cruise {
            duration_s,
            distance_m,
        } => {
            let (key, x, by_time) =
                one_of(at, ("duration_s", duration_s), ("distance_m", distance_m))?;
            let x = positive(at, key, x)?;
            let duration_s = if by_time {
                x
            } else {
                x / need_speed(at, *v, key, "cruise by distance")?
            };
            DriveSegment::Speed {
                to_m_s: *v,
                duration_s,
            }
        }
        SegmentSpec::Turn {
            angle_deg,
            rate_deg_s,
            radius_m,
        } => turn_segment(at, *v, angle_deg, rate_deg_s, radius_m)?,
        SegmentSpec::Climb {
            height_change_m,
            duration_s,
            grade_pct,
        } => climb_segment(at, *v, height_change_m, duration_s, grade_pct)?,
    })
}

/// A turn of `angle_deg` at a given rate, or on a given radius at speed `v`
/// (duration = |angle|·r / v).
fn turn_segment(
    at: SegmentAt,
    v: f64,
    angle_deg: f64,
    rate_deg_s: Option<f64>,
    radius_m: Option<f64>,
) -> Result<DriveSegment, SimError> {
    let angle = finite(at, "angle_deg", angle_deg)?;
    if angle == 0.0 {
        return Err(motion(at, "angle_deg", "0 is not a turn".into()));
    }
    let (key, x, by_rate) = one_of(at, ("rate_deg_s", rate_deg_s), ("radius_m", radius_m))?;
    let x = positive(at, key, x)?;
    let duration_s = if by_rate {
        angle.abs() / x
    } else {
        angle.abs() * DEG * x / need_speed(at, v, key, "turn by radius")?
    };
    Ok(DriveSegment::Turn {
        angle_rad: angle * DEG,
        duration_s,
    })
}

/// A height change over a given duration, or at a given grade at speed `v`
/// (duration = |Δh| / (v · grade/100)).
fn climb_segment(
    at: SegmentAt,
    v: f64,
    height_change_m: f64,
    duration_s: Option<f64>,
    grade_pct: Option<f64>,
) -> Result<DriveSegment, SimError> {
    let dh = finite(at, "height_change_m", height_change_m)?;
    if dh == 0.0 {
        return Err(motion(
            at,
            "height_change_m",
            "0 is not a climb: use cruise".into(),
        ));
    }
    let speed_now = need_speed(at, v, "type", "climb")?;
    let (key, x, by_time) = one_of(at, ("duration_s", duration_s), ("grade_pct", grade_pct))?;
    let x = positive(at, key, x)?;
    let duration_s = if by_time {
        x
    } else {
        dh.abs() / (speed_now * x / 100.0)
    };
    Ok(DriveSegment::Climb {
        height_change_m: dh,
        duration_s,
    })
}

impl MotionProfile {
    /// Parses TOML text; `name` is used in error messages. Checks syntax, keys and
    /// types only: [`MotionProfile::drive_segments`] checks the motion.
    pub fn from_toml_str(text: &str, name: &str) -> Result<MotionProfile, SimError> {
        let perr = |message: String| SimError::Profile {
            name: name.to_owned(),
            message,
        };
        let file: ProfileFile = toml::from_str(text).map_err(|e| perr(e.to_string()))?;
        let segments = file
            .segment
            .into_iter()
            .enumerate()
            .map(|(i, v)| {
                // Every key but `type` is a number: name a mistyped one (serde's message
                // through the tagged enum does not).
                if let Some(table) = v.as_table() {
                    for (key, val) in table {
                        let number = matches!(val, toml::Value::Float(_) | toml::Value::Integer(_));
                        if key != "type" && !number {
                            return Err(perr(format!(
                                "segment[{i}]: {key} must be a number in the unit its name gives, got {} {val}",
                                val.type_str()
                            )));
                        }
                    }
                }
                v.try_into::<SegmentSpec>()
                    .map_err(|e| perr(format!("segment[{i}]: {}", e.message())))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(MotionProfile {
            start: file.start,
            mounting: file.mounting,
            gait: file.gait,
            segments,
        })
    }

    /// Reads and parses a TOML file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<MotionProfile, SimError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text = crate::io::read_config_text(path, crate::io::MAX_CONFIG_BYTES).map_err(|e| {
            SimError::Profile {
                name: name.clone(),
                message: e.to_string(),
            }
        })?;
        MotionProfile::from_toml_str(&text, &name)
    }

    /// Checks the start, the mounting and every segment for possible motion, and
    /// converts the segments to [`DriveSegment`]s (SI units, durations derived).
    pub fn drive_segments(&self) -> Result<Vec<DriveSegment>, SimError> {
        let mut v = self.checked_start_speed()?;
        if self.segments.is_empty() {
            return Err(motion(
                None,
                "segment",
                "no segments: add at least one [[segment]]".into(),
            ));
        }
        let mut out = Vec::with_capacity(self.segments.len());
        for (i, spec) in self.segments.iter().enumerate() {
            let at = Some((i, spec.kind()));
            let seg = drive_segment(spec, at, &mut v)?;
            if !(seg.duration_s().is_finite() && seg.duration_s() > 0.0) {
                return Err(motion(
                    at,
                    "duration_s",
                    format!("derived duration {} s is not usable", seg.duration_s()),
                ));
            }
            out.push(seg);
        }
        Ok(out)
    }

    /// Checks the start, the mounting and the gait; returns the start speed (m/s).
    fn checked_start_speed(&self) -> Result<f64, SimError> {
        let s = &self.start;
        if finite(None, "start.lat_deg", s.lat_deg)?.abs() >= 90.0 {
            return Err(motion(
                None,
                "start.lat_deg",
                format!("{} outside (−90, 90)", s.lat_deg),
            ));
        }
        finite(None, "start.lon_deg", s.lon_deg)?;
        finite(None, "start.height_m", s.height_m)?;
        finite(None, "start.heading_deg", s.heading_deg)?;
        let v = non_negative_speed(None, "start.speed_m_s", s.speed_m_s)?;
        finite(None, "mounting.roll_deg", self.mounting.roll_deg)?;
        finite(None, "mounting.pitch_deg", self.mounting.pitch_deg)?;
        finite(None, "mounting.yaw_deg", self.mounting.yaw_deg)?;
        self.gait()?;
        Ok(v)
    }

    /// The checked `[gait]` in SI units (`None` without one): a positive step length,
    /// a bob amplitude ≥ 0 and sway amplitudes in [0, 30]°.
    pub fn gait(&self) -> Result<Option<Gait>, SimError> {
        let Some(g) = &self.gait else {
            return Ok(None);
        };
        if !(g.step_length_m.is_finite() && g.step_length_m > 0.0) {
            return Err(motion(
                None,
                "gait.step_length_m",
                format!("{} must be a positive number of metres", g.step_length_m),
            ));
        }
        if !(g.bob_amplitude_m.is_finite() && g.bob_amplitude_m >= 0.0) {
            return Err(motion(
                None,
                "gait.bob_amplitude_m",
                format!("{} must be finite and ≥ 0", g.bob_amplitude_m),
            ));
        }
        for (key, v) in [
            ("gait.pitch_sway_deg", g.pitch_sway_deg),
            ("gait.roll_sway_deg", g.roll_sway_deg),
        ] {
            if !(v.is_finite() && (0.0..=30.0).contains(&v)) {
                return Err(motion(
                    None,
                    key,
                    format!("{v} must be between 0 and 30 degrees"),
                ));
            }
        }
        Ok(Some(Gait {
            step_length_m: g.step_length_m,
            bob_amplitude_m: g.bob_amplitude_m,
            pitch_amplitude_rad: g.pitch_sway_deg * DEG,
            roll_amplitude_rad: g.roll_sway_deg * DEG,
        }))
    }

    /// The validated drive as an exact trajectory (t = 0 at the start of the first
    /// segment).
    pub fn build(&self) -> Result<LandVehicle, SimError> {
        let segs = self.drive_segments()?;
        let m = &self.mounting;
        let c_vb = Euler {
            roll_rad: m.roll_deg * DEG,
            pitch_rad: m.pitch_deg * DEG,
            yaw_rad: m.yaw_deg * DEG,
        }
        .to_dcm();
        let s = &self.start;
        Ok(LandVehicle::new(
            s.lat_deg * DEG,
            s.lon_deg * DEG,
            s.height_m,
            s.heading_deg * DEG,
            s.speed_m_s,
            c_vb,
            &segs,
        )
        .with_gait(self.gait()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::earth;
    use crate::nav::mechanization::mechanize;
    use crate::sim::ideal_imu::{Trajectory, ideal_increments};

    const GOOD: &str = r#"
[start]
lat_deg = 30.5
lon_deg = 114.3
height_m = 20.0
heading_deg = 45.0

[mounting]
roll_deg = 1.0
pitch_deg = -2.0
yaw_deg = 3.0

[[segment]]
type = "stop"
duration_s = 3

[[segment]]
type = "accelerate"
to_speed_m_s = 12.5
duration_s = 7.3

[[segment]]
type = "turn"
angle_deg = 75.0
radius_m = 40.0

[[segment]]
type = "cruise"
distance_m = 31.0

[[segment]]
type = "climb"
height_change_m = 6.0
grade_pct = 8.0

[[segment]]
type = "turn"
angle_deg = -30.0
rate_deg_s = 12.0

[[segment]]
type = "climb"
height_change_m = -4.0
duration_s = 9.1

[[segment]]
type = "brake"
duration_s = 6.7

[[segment]]
type = "stop"
duration_s = 2.0
"#;

    fn parse(text: &str) -> Result<MotionProfile, SimError> {
        MotionProfile::from_toml_str(text, "test.toml")
    }

    #[test]
    fn parses_and_derives_durations() {
        let p = parse(GOOD).unwrap();
        let segs = p.drive_segments().unwrap();
        assert_eq!(segs.len(), 9);
        // Turn by radius at 12.5 m/s: T = (75° in rad)·40/12.5.
        let t = segs[2].duration_s();
        assert!((t - 75.0 * DEG * 40.0 / 12.5).abs() < 1e-12, "{t}");
        assert!((segs[3].duration_s() - 31.0 / 12.5).abs() < 1e-12);
        // Climb 6 m at 8 % mean grade: 75 m horizontal.
        assert!((segs[4].duration_s() - 75.0 / 12.5).abs() < 1e-12);
        assert!((segs[5].duration_s() - 2.5).abs() < 1e-12);
        assert_eq!(
            segs[7],
            DriveSegment::Speed {
                to_m_s: 0.0,
                duration_s: 6.7
            }
        );
    }

    /// Largest horizontal, vertical (m) and attitude (rad) difference between a
    /// mechanization of the ideal increments at interval `dt` from the true start and the
    /// truth.
    fn mechanization_errors(traj: &LandVehicle, dt: f64) -> (f64, f64, f64) {
        let n = (traj.duration_s() / dt).ceil() as usize;
        let mut state = traj.point(0.0).nav_state(0.0);
        let mut incs = ideal_increments(traj, 0.0, dt, n + 1);
        let mut prev = incs.next().unwrap();
        let (mut horiz_max, mut vert_max, mut att_max) = (0.0f64, 0.0f64, 0.0f64);
        for (k, inc) in incs.enumerate() {
            state = mechanize(&state, &prev, &inc);
            prev = inc;
            let truth = traj.point((k + 1) as f64 * dt);
            let d = earth::ned_offset_m(
                (truth.lat_rad, truth.lon_rad, truth.height_m),
                (state.lat_rad, state.lon_rad, state.height_m),
            );
            horiz_max = horiz_max.max(d[0].hypot(d[1]));
            vert_max = vert_max.max(d[2].abs());
            let q = truth.nav_state(0.0).q_bn;
            let r = q.conj().mul(&state.q_bn).to_rotation_vector();
            att_max = att_max.max((r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt());
        }
        (horiz_max, vert_max, att_max)
    }

    /// The profile's drive is exact: a mechanization from the true start reproduces it
    /// to < 1 mm over its whole length (joins fall between IMU samples: the increments
    /// are integrated piecewise across them).
    #[test]
    fn profile_round_trips_through_mechanization() {
        let traj = parse(GOOD).unwrap().build().unwrap();
        let duration = traj.duration_s();
        let (horiz_max, vert_max, att_max) = mechanization_errors(&traj, 0.005);
        // It climbed, turned and stopped.
        let (a, b) = (traj.point(0.0), traj.point(duration));
        assert!((b.height_m - a.height_m - 2.0).abs() < 1e-9);
        assert!(b.vel_ned_m_s.iter().all(|v| v.abs() < 1e-12));
        // Mid-climb the vehicle pitches up by the flight-path angle (peak grade 16 %),
        // mid-descent down (the mounting adds −2° to the body pitch).
        let starts = traj.segment_starts_s();
        let mid = |i: usize| 0.5 * (starts[i] + starts[i + 1]);
        let up = Euler::from_dcm(&traj.point(mid(4)).c_bn).pitch_rad;
        let down = Euler::from_dcm(&traj.point(mid(6)).c_bn).pitch_rad;
        assert!(
            (up - (0.16f64.atan() - 2.0 * DEG)).abs() < 0.2 * DEG,
            "{up}"
        );
        assert!(down < -4.0 * DEG, "{down}");
        eprintln!(
            "profile {duration:.1} s: horizontal max {horiz_max:.3e} m, vertical max {vert_max:.3e} m, attitude max {att_max:.3e} rad"
        );
        assert!(
            horiz_max < 1e-3 && vert_max < 1e-3,
            "{horiz_max} {vert_max}"
        );
        assert!(att_max < 1e-8, "{att_max}");
    }

    const WALK: &str = r#"
[start]
lat_deg = 47.0
lon_deg = 8.0
height_m = 400.0
heading_deg = 0.0
[gait]
step_length_m = 0.6
bob_amplitude_m = 0.02
pitch_sway_deg = 1.5
roll_sway_deg = 2.0
[[segment]]
type = "stop"
duration_s = 2
[[segment]]
type = "accelerate"
to_speed_m_s = 1.2
duration_s = 1.5
[[segment]]
type = "turn"
angle_deg = 180.0
radius_m = 2.0
[[segment]]
type = "cruise"
distance_m = 5.0
[[segment]]
type = "turn"
angle_deg = -90.0
radius_m = 3.0
[[segment]]
type = "brake"
duration_s = 1.0
[[segment]]
type = "stop"
duration_s = 2
"#;

    /// A hand-held walk (2-m and 3-m turns at 1.2 m/s, 2 steps/s with a 2-cm bob and
    /// 1.5°/2° sway) is as exact as a drive, and the gait shows in the truth.
    #[test]
    fn walk_profile_round_trips_through_mechanization() {
        let p = parse(WALK).unwrap();
        let walk = p.build().unwrap();
        let (horiz_max, vert_max, att_max) = mechanization_errors(&walk, 0.005);
        let (h2, v2, a2) = mechanization_errors(&walk, 0.0025);
        eprintln!(
            "walk {:.1} s at 200 / 400 Hz: horizontal max {horiz_max:.3e} / {h2:.3e} m, vertical max {vert_max:.3e} / {v2:.3e} m, attitude max {att_max:.3e} / {a2:.3e} rad",
            walk.duration_s()
        );
        assert!(
            horiz_max < 1e-3 && vert_max < 1e-3,
            "{horiz_max} {vert_max}"
        );
        assert!(att_max < 1e-6 && a2 < att_max, "{att_max} {a2}");
        // Without the turns (whose yaw-rate steps under the sway meet the mechanization's
        // two-sample coning correction at the joins) the attitude error is the
        // mechanization's smooth-motion one: it falls by more than 3× at half the
        // interval — the truth is not what limits it.
        let mut straight = p.clone();
        straight.segments.retain(|s| s.kind() != "turn");
        let straight = straight.build().unwrap();
        let (_, _, s1) = mechanization_errors(&straight, 0.005);
        let (_, _, s2) = mechanization_errors(&straight, 0.0025);
        eprintln!("straight walk: attitude max {s1:.3e} / {s2:.3e} rad");
        assert!(s1 < 1e-7 && s2 < s1 / 3.0, "{s1} {s2}");
        // The same segments without the gait: level, and the bob is the difference.
        let mut flat = p.clone();
        flat.gait = None;
        let flat = flat.build().unwrap();
        let (mut bob, mut roll) = (0.0f64, 0.0f64);
        for i in 0..2000 {
            let t = i as f64 * 0.01;
            let (a, b) = (walk.point(t), flat.point(t));
            bob = bob.max((a.height_m - b.height_m).abs());
            roll = roll.max(Euler::from_dcm(&a.c_bn).roll_rad.abs());
            assert_eq!(Euler::from_dcm(&b.c_bn).roll_rad, 0.0);
        }
        assert!((bob - 0.02).abs() < 1e-4 && (roll - 2.0 * DEG).abs() < 1e-3 * DEG);
    }

    fn motion_err(text: &str) -> (Option<(usize, &'static str)>, &'static str, String) {
        match parse(text).and_then(|p| p.drive_segments()) {
            Err(SimError::Motion { segment, key, why }) => (segment, key, why),
            other => panic!("expected a motion error, got {other:?}"),
        }
    }

    fn parse_err(text: &str) -> String {
        match parse(text) {
            Err(e @ SimError::Profile { .. }) => e.to_string(),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    const START: &str = "[start]\nlat_deg = 30\nlon_deg = 114\nheight_m = 0\nheading_deg = 0\n";

    fn with(segments: &str) -> String {
        format!("{START}speed_m_s = 10.0\n{segments}")
    }

    #[test]
    fn impossible_motions_name_segment_and_key() {
        let (s, k, why) = motion_err(&with(
            "[[segment]]\ntype = \"brake\"\nto_speed_m_s = -1\nduration_s = 3\n",
        ));
        assert_eq!((s, k), (Some((0, "brake")), "to_speed_m_s"));
        assert!(why.contains("negative speed"), "{why}");

        let (s, k, _) = motion_err(&with(
            "[[segment]]\ntype = \"cruise\"\nduration_s = 1\n[[segment]]\ntype = \"turn\"\nangle_deg = 90\nradius_m = 0\n",
        ));
        assert_eq!((s, k), (Some((1, "turn")), "radius_m"));

        let zero = format!(
            "{START}[[segment]]\ntype = \"stop\"\nduration_s = 1\n[[segment]]\ntype = \"turn\"\nangle_deg = 90\nradius_m = 20\n"
        );
        let (s, k, why) = motion_err(&zero);
        assert_eq!((s, k), (Some((1, "turn")), "radius_m"));
        assert!(why.contains("zero speed"), "{why}");

        for dur in ["0", "-2", "nan", "inf"] {
            let (s, k, _) = motion_err(&with(&format!(
                "[[segment]]\ntype = \"accelerate\"\nto_speed_m_s = 20\nduration_s = {dur}\n"
            )));
            assert_eq!((s, k), (Some((0, "accelerate")), "duration_s"), "{dur}");
        }
        let (s, k, _) = motion_err(&with(
            "[[segment]]\ntype = \"turn\"\nangle_deg = nan\nrate_deg_s = 3\n",
        ));
        assert_eq!((s, k), (Some((0, "turn")), "angle_deg"));
        let (_, k, why) = motion_err(&with(
            "[[segment]]\ntype = \"turn\"\nangle_deg = 10\nrate_deg_s = 3\nradius_m = 5\n",
        ));
        assert_eq!(k, "rate_deg_s");
        assert!(why.contains("exactly one"), "{why}");
        let (s, k, _) = motion_err(&with("[[segment]]\ntype = \"stop\"\nduration_s = 3\n"));
        assert_eq!((s, k), (Some((0, "stop")), "type"));
        let (_, k, _) = motion_err(&with(
            "[[segment]]\ntype = \"accelerate\"\nto_speed_m_s = 5\nduration_s = 3\n",
        ));
        assert_eq!(k, "to_speed_m_s");
        let (s, k, _) = motion_err(&format!(
            "{START}[[segment]]\ntype = \"climb\"\nheight_change_m = 5\nduration_s = 3\n"
        ));
        assert_eq!((s, k), (Some((0, "climb")), "type"));
        let (s, k, _) = motion_err(&format!(
            "{START}speed_m_s = -3\n[[segment]]\ntype = \"stop\"\nduration_s = 1\n"
        ));
        assert_eq!((s, k), (None, "start.speed_m_s"));
        let (s, k, _) = motion_err(START);
        assert_eq!((s, k), (None, "segment"));
        for (gait, key) in [
            ("step_length_m = 0", "gait.step_length_m"),
            (
                "step_length_m = 0.6\nbob_amplitude_m = -0.01",
                "gait.bob_amplitude_m",
            ),
            (
                "step_length_m = 0.6\npitch_sway_deg = 45",
                "gait.pitch_sway_deg",
            ),
            (
                "step_length_m = 0.6\nroll_sway_deg = nan",
                "gait.roll_sway_deg",
            ),
        ] {
            let (s, k, _) = motion_err(&format!(
                "{START}[gait]\n{gait}\n[[segment]]\ntype = \"stop\"\nduration_s = 1\n"
            ));
            assert_eq!((s, k), (None, key), "{gait}");
        }
        // The message names everything.
        let e = parse(&with(
            "[[segment]]\ntype = \"turn\"\nangle_deg = 90\nradius_m = 0\n",
        ))
        .unwrap()
        .drive_segments()
        .unwrap_err()
        .to_string();
        assert!(e.contains("segment[0] (turn): radius_m"), "{e}");
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_refused() {
        let e = parse_err(&with(
            "[[segment]]\ntype = \"accelerate\"\nspeed_km_h = 50\nduration_s = 3\n",
        ));
        assert!(e.contains("segment[0]") && e.contains("speed_km_h"), "{e}");
        let e = parse_err(&with(
            "[[segment]]\ntype = \"cruise\"\nduration_s = \"10 s\"\n",
        ));
        assert!(
            e.contains("segment[0]: duration_s must be a number") && e.contains("string"),
            "{e}"
        );
        let e = parse_err(&with("[[segment]]\ntype = \"hover\"\nduration_s = 1\n"));
        assert!(e.contains("hover"), "{e}");
        let e = parse_err(&format!("{START}speed_km_h = 3\n"));
        assert!(e.contains("speed_km_h"), "{e}");
        let e = parse_err(&format!("{START}[mounting]\nroll_rad = 0.1\n"));
        assert!(e.contains("roll_rad"), "{e}");
        let e = parse_err(&format!(
            "{START}[gait]\nstep_length_m = 0.6\nbob_amplitude_cm = 2\n"
        ));
        assert!(e.contains("bob_amplitude_cm"), "{e}");
        let e = parse_err("[start]\nlat_deg = 30\n");
        assert!(e.contains("lon_deg"), "{e}");
        let e = parse_err(&format!("{START}[[segments]]\ntype = \"stop\"\n"));
        assert!(e.contains("segments"), "{e}");
    }
}

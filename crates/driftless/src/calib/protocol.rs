//! Segment manifest of a calibration protocol (the thermal-chamber protocol
//! [`crate::sim::chamber`] writes one; [`super::segment`] finds one in a log): which time
//! range holds which test (soak, a static position with a given axis up, a rate-table
//! rotation, a transition) at which set temperature, with the site constants a
//! calibration needs (exact local gravity, Earth rate). Serialises to TOML as a flat list
//! of `[[segment]]` tables (`kind = "soak" | "position" | "rate" | "move"`, plus `up` for
//! positions and `axis`, `rate_rad_s` for rates), with unknown or misplaced keys refused.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use driftless_model::linalg::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

/// A manifest could not be written or read as TOML.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("chamber manifest: {0}")]
pub struct ManifestError(pub String);

/// Manifest format version.
pub const MANIFEST_VERSION: u32 = 1;

/// A body axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BodyAxis {
    /// x (forward).
    X,
    /// y (right).
    Y,
    /// z (down).
    Z,
}

impl BodyAxis {
    /// All three, in order.
    pub const ALL: [BodyAxis; 3] = [BodyAxis::X, BodyAxis::Y, BodyAxis::Z];

    /// 0, 1, 2.
    pub fn index(self) -> usize {
        match self {
            BodyAxis::X => 0,
            BodyAxis::Y => 1,
            BodyAxis::Z => 2,
        }
    }

    /// Unit vector.
    pub fn unit(self) -> Vec3 {
        let mut v = [0.0; 3];
        v[self.index()] = 1.0;
        v
    }

    fn letter(self) -> char {
        ['x', 'y', 'z'][self.index()]
    }
}

/// A signed body axis, written `+x` … `-z`; in a position it is the axis pointing up.
/// Serialises as that string.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct SignedAxis {
    /// The axis.
    pub axis: BodyAxis,
    /// `true` for +axis.
    pub positive: bool,
}

impl SignedAxis {
    /// The six positions in protocol order: −z (home), +z, +x, −x, +y, −y.
    pub const POSITIONS: [SignedAxis; 6] = [
        SignedAxis::new(BodyAxis::Z, false),
        SignedAxis::new(BodyAxis::Z, true),
        SignedAxis::new(BodyAxis::X, true),
        SignedAxis::new(BodyAxis::X, false),
        SignedAxis::new(BodyAxis::Y, true),
        SignedAxis::new(BodyAxis::Y, false),
    ];

    /// `axis` with sign.
    pub const fn new(axis: BodyAxis, positive: bool) -> SignedAxis {
        SignedAxis { axis, positive }
    }

    /// ±1.
    pub fn sign(self) -> f64 {
        if self.positive { 1.0 } else { -1.0 }
    }

    /// C_bn of the position with this body axis pointing up (exact 0/±1 entries; the
    /// remaining axes are chosen right-handed with a horizontal one north):
    /// −z up is the level home attitude (C_bn = I).
    pub fn c_bn_up(self) -> Mat3 {
        use BodyAxis::*;
        Mat3(match (self.axis, self.positive) {
            (Z, false) => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            (Z, true) => [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
            (X, true) => [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
            (X, false) => [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
            (Y, true) => [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            (Y, false) => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
        })
    }
}

impl fmt::Display for SignedAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}",
            if self.positive { '+' } else { '-' },
            self.axis.letter()
        )
    }
}

impl From<SignedAxis> for String {
    fn from(s: SignedAxis) -> String {
        s.to_string()
    }
}

impl TryFrom<String> for SignedAxis {
    type Error = String;
    fn try_from(s: String) -> Result<SignedAxis, String> {
        s.parse()
    }
}

impl FromStr for SignedAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<SignedAxis, String> {
        let mut c = s.trim().chars();
        let (sign, letter) = (c.next(), c.next());
        if c.next().is_some() {
            return Err(format!("'{s}' is not a signed axis (+x … -z)"));
        }
        let positive = match sign {
            Some('+') => true,
            Some('-') => false,
            _ => return Err(format!("'{s}' is not a signed axis (+x … -z)")),
        };
        let axis = match letter {
            Some('x') => BodyAxis::X,
            Some('y') => BodyAxis::Y,
            Some('z') => BodyAxis::Z,
            _ => return Err(format!("'{s}' is not a signed axis (+x … -z)")),
        };
        Ok(SignedAxis { axis, positive })
    }
}

/// What happens during a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SegmentKind {
    /// Static at the home attitude while the temperature settles.
    Soak,
    /// Static with body axis `up` pointing up.
    Position {
        /// The axis pointing up.
        up: SignedAxis,
    },
    /// Constant rotation about body `axis` (which points up) at `rate_rad_s` (signed,
    /// right-handed about +axis), whole revolutions.
    Rate {
        /// Rotation axis.
        axis: BodyAxis,
        /// ω_nb about +axis, rad/s.
        rate_rad_s: f64,
    },
    /// A transition (rotation between positions, spin-up/down).
    Move,
}

/// One segment of the protocol.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSegment", into = "RawSegment")]
pub struct Segment {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// Chamber set temperature, °C.
    pub set_temperature_c: f64,
    /// What happens.
    pub kind: SegmentKind,
}

impl Segment {
    /// Length, s.
    pub fn duration_s(&self) -> f64 {
        self.end_s - self.start_s
    }

    /// Samples inside the segment: round(start·f_s) .. round(end·f_s) (increment i
    /// covers (iΔt, (i+1)Δt]; rate sample i is at iΔt).
    pub fn sample_range(&self, sample_rate_hz: f64) -> Range<usize> {
        let k = |t: f64| (t * sample_rate_hz).round().max(0.0) as usize;
        k(self.start_s)..k(self.end_s)
    }
}

/// Flat TOML form of a [`Segment`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSegment {
    kind: String,
    start_s: f64,
    end_s: f64,
    set_temperature_c: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    up: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axis: Option<BodyAxis>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rate_rad_s: Option<f64>,
}

impl From<Segment> for RawSegment {
    fn from(s: Segment) -> RawSegment {
        let (kind, up, axis, rate) = match s.kind {
            SegmentKind::Soak => ("soak", None, None, None),
            SegmentKind::Position { up } => ("position", Some(up.to_string()), None, None),
            SegmentKind::Rate { axis, rate_rad_s } => ("rate", None, Some(axis), Some(rate_rad_s)),
            SegmentKind::Move => ("move", None, None, None),
        };
        RawSegment {
            kind: kind.into(),
            start_s: s.start_s,
            end_s: s.end_s,
            set_temperature_c: s.set_temperature_c,
            up,
            axis,
            rate_rad_s: rate,
        }
    }
}

impl TryFrom<RawSegment> for Segment {
    type Error = String;
    fn try_from(r: RawSegment) -> Result<Segment, String> {
        let extra = |ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(format!(
                    "segment kind '{}' takes only start_s, end_s, set_temperature_c{}",
                    r.kind,
                    match r.kind.as_str() {
                        "position" => ", up",
                        "rate" => ", axis, rate_rad_s",
                        _ => "",
                    }
                ))
            }
        };
        let kind = match r.kind.as_str() {
            "soak" | "move" => {
                extra(r.up.is_none() && r.axis.is_none() && r.rate_rad_s.is_none())?;
                if r.kind == "soak" {
                    SegmentKind::Soak
                } else {
                    SegmentKind::Move
                }
            }
            "position" => {
                extra(r.axis.is_none() && r.rate_rad_s.is_none())?;
                let up =
                    r.up.as_deref()
                        .ok_or("a position segment needs `up` (+x … -z)")?
                        .parse()?;
                SegmentKind::Position { up }
            }
            "rate" => {
                extra(r.up.is_none())?;
                SegmentKind::Rate {
                    axis: r.axis.ok_or("a rate segment needs `axis`")?,
                    rate_rad_s: r.rate_rad_s.ok_or("a rate segment needs `rate_rad_s`")?,
                }
            }
            other => {
                return Err(format!(
                    "unknown segment kind '{other}' (soak, position, rate, move)"
                ));
            }
        };
        Ok(Segment {
            start_s: r.start_s,
            end_s: r.end_s,
            set_temperature_c: r.set_temperature_c,
            kind,
        })
    }
}

/// The segment list of a chamber run with the site constants a calibration needs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamberManifest {
    /// [`MANIFEST_VERSION`].
    pub format_version: u32,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Site latitude, deg.
    pub latitude_deg: f64,
    /// Site longitude, deg.
    pub longitude_deg: f64,
    /// Site ellipsoidal height, m.
    pub height_m: f64,
    /// Exact |f^b| in the static positions: WGS-84 normal gravity at the site, m/s².
    pub gravity_m_s2: f64,
    /// Earth rotation rate ω_ie, rad/s.
    pub earth_rate_rad_s: f64,
    /// Sensor thermal time constant τ used for the temperature profile, s.
    pub lag_tau_s: f64,
    /// Total duration, s.
    pub duration_s: f64,
    /// Segments in time order, covering [0, duration_s].
    #[serde(rename = "segment")]
    pub segments: Vec<Segment>,
}

impl ChamberManifest {
    /// TOML text.
    pub fn to_toml_string(&self) -> Result<String, ManifestError> {
        toml::to_string(self).map_err(|e| ManifestError(e.to_string()))
    }

    /// Parse TOML text.
    pub fn from_toml_str(s: &str) -> Result<ChamberManifest, ManifestError> {
        toml::from_str(s).map_err(|e| ManifestError(e.to_string()))
    }

    /// The distinct set temperatures in protocol order, °C.
    pub fn set_temperatures_c(&self) -> Vec<f64> {
        let mut v: Vec<f64> = Vec::new();
        for s in &self.segments {
            if v.last() != Some(&s.set_temperature_c) {
                v.push(s.set_temperature_c);
            }
        }
        v
    }

    /// The temperature steps in protocol order: maximal runs of consecutive segments at
    /// one set temperature, as (set temperature, range of segment indices). A set
    /// temperature visited twice (e.g. a reference temperature at the start and the end)
    /// gives two steps.
    pub fn steps(&self) -> Vec<(f64, Range<usize>)> {
        let mut v: Vec<(f64, Range<usize>)> = Vec::new();
        for (i, s) in self.segments.iter().enumerate() {
            match v.last_mut() {
                Some((t, r)) if *t == s.set_temperature_c && r.end == i => r.end = i + 1,
                _ => v.push((s.set_temperature_c, i..i + 1)),
            }
        }
        v
    }

    /// The manifest of step `segments` (a range from [`ChamberManifest::steps`]): the same
    /// site constants and time axis, only those segments.
    pub(crate) fn step_manifest(&self, segments: Range<usize>) -> ChamberManifest {
        ChamberManifest {
            format_version: self.format_version,
            sample_rate_hz: self.sample_rate_hz,
            latitude_deg: self.latitude_deg,
            longitude_deg: self.longitude_deg,
            height_m: self.height_m,
            gravity_m_s2: self.gravity_m_s2,
            earth_rate_rad_s: self.earth_rate_rad_s,
            lag_tau_s: self.lag_tau_s,
            duration_s: self.duration_s,
            segments: self.segments[segments].to_vec(),
        }
    }

    /// The (first) position segment with `up` at set temperature `set_c`.
    pub fn position(&self, set_c: f64, up: SignedAxis) -> Option<&Segment> {
        self.segments
            .iter()
            .find(|s| s.set_temperature_c == set_c && s.kind == SegmentKind::Position { up })
    }

    /// The (first) rate segment about `axis` with the sign of ω `positive` at `set_c`.
    pub fn rate(&self, set_c: f64, axis: BodyAxis, positive: bool) -> Option<&Segment> {
        self.segments.iter().find(|s| {
            s.set_temperature_c == set_c
                && matches!(s.kind, SegmentKind::Rate { axis: a, rate_rad_s }
                    if a == axis && (rate_rad_s > 0.0) == positive)
        })
    }
}

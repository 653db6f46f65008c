//! File units → SI. The only math a reader does: `si = (raw − offset) × scale`.
//!
//! Unit grammar (case-insensitive, spaces ignored):
//!
//! ```text
//! UNIT   := BASE | RAW
//! BASE   := rad/s | deg/s (dps, °/s) | rad/h | deg/h (°/h, deg/hr)
//!         | m/s^2 (m/s2, m/s/s, m/s²) | g | mg | ug (µg, μg)
//!         | degC (C, °C, celsius) | K | none (unitless, -, 1)
//! RAW    := counts [ ("-" | "+") OFFSET ] [ ("*" | "/") SCALE [ BASE ] ]
//!         | "(" counts ("-" | "+") OFFSET ")" ("*" | "/") SCALE [ BASE ]
//! ```
//!
//! `RAW` is read left to right as `(raw − OFFSET) × SCALE × BASE`: `counts-32768*0.00875deg/s`
//! and `(counts-32768)*0.00875 deg/s` both mean "subtract 32768 counts, then 0.00875 deg/s per
//! count"; `counts/6258 rad/s` means 6258 counts per rad/s. Without `BASE` the scale is in SI
//! units per count and the quantity is [`Quantity::Other`] (override it with [`Unit::counts`]).
//! `lsb` is accepted for `counts`.
//!
//! Time columns use [`TimeUnit`]: `s`, `ms`, `us` (µs), `ns`.

use std::fmt;
use std::str::FromStr;

use driftless_model::units as k;

use super::log::Quantity;

/// The unit strings accepted, for error messages.
pub(crate) const KNOWN_UNITS: &str = "rad/s, deg/s, rad/h, deg/h, m/s^2, g, mg, ug, degC, K, none, \
     counts[-OFFSET][*SCALE|/DIVISOR][UNIT] (e.g. counts-32768*0.00875deg/s)";

/// A column's file unit and its conversion to SI: `si = (raw − offset_raw) × scale_si`.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// The unit as written (for display and [`super::log::Channel::source_unit`]).
    pub label: String,
    /// What the converted column measures.
    pub quantity: Quantity,
    /// SI units per file unit (after the offset is removed).
    pub scale_si: f64,
    /// Offset subtracted from the raw value before scaling, in file units (raw counts,
    /// or 273.15 for kelvin).
    pub offset_raw: f64,
}

/// A unit string that could not be parsed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown unit {unit:?}; known units: {KNOWN_UNITS}")]
pub struct UnknownUnit {
    /// The text that was given.
    pub unit: String,
}

impl Unit {
    /// Unitless: values kept as they are, quantity [`Quantity::Other`].
    pub fn none() -> Self {
        Unit {
            label: "none".into(),
            quantity: Quantity::Other,
            scale_si: 1.0,
            offset_raw: 0.0,
        }
    }

    /// Raw counts with an explicit conversion: `si = (raw − offset_counts) × si_per_count`.
    pub fn counts(si_per_count: f64, offset_counts: f64, quantity: Quantity) -> Self {
        let mut label = String::from("counts");
        if offset_counts != 0.0 {
            label.push_str(&format!("{:+}", -offset_counts));
        }
        if si_per_count != 1.0 {
            label.push_str(&format!("*{si_per_count}"));
            if quantity != Quantity::Other {
                label.push_str(quantity.si_unit());
            }
        }
        Unit {
            label,
            quantity,
            scale_si: si_per_count,
            offset_raw: offset_counts,
        }
    }

    /// Parses a unit string (see the module docs for the grammar).
    pub fn parse(text: &str) -> Result<Self, UnknownUnit> {
        let err = || UnknownUnit {
            unit: text.to_owned(),
        };
        let compact: String = text
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect::<String>()
            .to_lowercase();
        if let Some((quantity, scale_si, offset_raw)) = base_unit(&compact) {
            return Ok(Unit {
                label: text.trim().to_owned(),
                quantity,
                scale_si,
                offset_raw,
            });
        }
        let raw = parse_raw(&compact).ok_or_else(err)?;
        if !(raw.scale_si.is_finite() && raw.scale_si != 0.0 && raw.offset_raw.is_finite()) {
            return Err(err());
        }
        Ok(Unit {
            label: text.trim().to_owned(),
            ..raw
        })
    }

    /// Converts one raw file value to SI.
    #[inline]
    pub(crate) fn to_si(&self, raw: f64) -> f64 {
        (raw - self.offset_raw) * self.scale_si
    }
}

impl Default for Unit {
    fn default() -> Self {
        Unit::none()
    }
}

impl FromStr for Unit {
    type Err = UnknownUnit;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Unit::parse(s)
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label)
    }
}

/// (quantity, SI per unit, offset) of a base unit, compact lower-case form.
fn base_unit(u: &str) -> Option<(Quantity, f64, f64)> {
    use Quantity::*;
    Some(match u {
        "rad/s" | "rps" | "rads^-1" | "rads-1" => (AngularRate, 1.0, 0.0),
        "deg/s" | "dps" | "°/s" => (AngularRate, k::DEG_PER_S, 0.0),
        "rad/h" | "rad/hr" => (AngularRate, 1.0 / k::HOUR_S, 0.0),
        "deg/h" | "deg/hr" | "°/h" | "dph" => (AngularRate, k::DEG_PER_H, 0.0),
        "m/s^2" | "m/s2" | "m/s/s" | "m/s²" | "ms^-2" | "ms-2" => (SpecificForce, 1.0, 0.0),
        "g" => (SpecificForce, k::STANDARD_GRAVITY, 0.0),
        "mg" => (SpecificForce, k::MILLI_G, 0.0),
        "ug" | "µg" | "μg" => (SpecificForce, k::MICRO_G, 0.0),
        "degc" | "c" | "°c" | "celsius" => (Temperature, 1.0, 0.0),
        "k" | "kelvin" => (Temperature, 1.0, k::KELVIN_OFFSET),
        "none" | "unitless" | "-" | "1" | "" => (Other, 1.0, 0.0),
        _ => return None,
    })
}

/// `counts[±OFFSET][*SCALE|/DIV][BASE]` or `(counts±OFFSET)*SCALE[BASE]`, compact lower case.
fn parse_raw(u: &str) -> Option<Unit> {
    let (rest, parenthesised) = match u.strip_prefix('(') {
        Some(r) => (r, true),
        None => (u, false),
    };
    let mut rest = rest
        .strip_prefix("counts")
        .or_else(|| rest.strip_prefix("count"))
        .or_else(|| rest.strip_prefix("lsb"))?;
    let mut offset_raw = 0.0;
    if let Some(sign) = rest.chars().next().filter(|c| *c == '-' || *c == '+') {
        let (num, used) = leading_number(&rest[1..])?;
        offset_raw = if sign == '-' { num } else { -num };
        rest = &rest[1 + used..];
    }
    if parenthesised {
        rest = rest.strip_prefix(')')?;
    }
    let mut scale_si = 1.0;
    let mut quantity = Quantity::Other;
    if let Some(op) = rest.chars().next().filter(|c| *c == '*' || *c == '/') {
        let (num, used) = leading_number(&rest[1..])?;
        scale_si = if op == '*' { num } else { 1.0 / num };
        rest = &rest[1 + used..];
        if !rest.is_empty() {
            let (q, s, off) = base_unit(rest)?;
            if off != 0.0 {
                return None; // "counts*0.1K" would mix two offsets: not supported
            }
            quantity = q;
            scale_si *= s;
            rest = "";
        }
    }
    if !rest.is_empty() {
        return None;
    }
    Some(Unit {
        label: String::new(),
        quantity,
        scale_si,
        offset_raw,
    })
}

/// The longest prefix of `s` that is a decimal number, and its byte length.
fn leading_number(s: &str) -> Option<(f64, usize)> {
    let b = s.as_bytes();
    let mut end = 0;
    let mut seen_digit = false;
    while end < b.len() {
        let c = b[end];
        let ok = c.is_ascii_digit()
            || c == b'.'
            || ((c == b'e') && seen_digit && end + 1 < b.len() && {
                let n = b[end + 1];
                n.is_ascii_digit() || n == b'-' || n == b'+'
            })
            || ((c == b'-' || c == b'+') && end > 0 && b[end - 1] == b'e');
        if !ok {
            break;
        }
        seen_digit |= c.is_ascii_digit();
        end += 1;
    }
    let v: f64 = s.get(..end)?.parse().ok()?;
    v.is_finite().then_some((v, end))
}

/// Unit of a time column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds.
    #[default]
    Seconds,
    /// Milliseconds.
    Milliseconds,
    /// Microseconds.
    Microseconds,
    /// Nanoseconds.
    Nanoseconds,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn to_s(self) -> f64 {
        match self {
            TimeUnit::Seconds => 1.0,
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Microseconds => 1e-6,
            TimeUnit::Nanoseconds => 1e-9,
        }
    }
    /// Short label (`s`, `ms`, `us`, `ns`).
    pub fn label(self) -> &'static str {
        match self {
            TimeUnit::Seconds => "s",
            TimeUnit::Milliseconds => "ms",
            TimeUnit::Microseconds => "us",
            TimeUnit::Nanoseconds => "ns",
        }
    }
}

impl FromStr for TimeUnit {
    type Err = UnknownUnit;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.trim().to_lowercase().as_str() {
            "s" | "sec" | "seconds" => TimeUnit::Seconds,
            "ms" | "msec" | "milliseconds" => TimeUnit::Milliseconds,
            "us" | "µs" | "μs" | "usec" | "microseconds" => TimeUnit::Microseconds,
            "ns" | "nsec" | "nanoseconds" => TimeUnit::Nanoseconds,
            _ => {
                return Err(UnknownUnit { unit: s.to_owned() });
            }
        })
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn base_units_convert_to_si() {
        let u = Unit::parse("deg/s").unwrap();
        assert_eq!(u.quantity, Quantity::AngularRate);
        assert!(close(u.to_si(180.0), std::f64::consts::PI));
        let u = Unit::parse("deg/h").unwrap();
        assert!(close(u.to_si(3600.0 * 180.0), std::f64::consts::PI));
        assert!(close(Unit::parse("rad/h").unwrap().to_si(3600.0), 1.0));
        let u = Unit::parse("mg").unwrap();
        assert_eq!(u.quantity, Quantity::SpecificForce);
        assert!(close(u.to_si(1000.0), 9.80665));
        assert!(close(Unit::parse("ug").unwrap().to_si(1e6), 9.80665));
        assert!(close(Unit::parse(" G ").unwrap().to_si(2.0), 2.0 * 9.80665));
        assert_eq!(Unit::parse("m/s2").unwrap().scale_si, 1.0);
        assert_eq!(
            Unit::parse("m/s^2").unwrap().quantity,
            Quantity::SpecificForce
        );
        let t = Unit::parse("degC").unwrap();
        assert_eq!(t.quantity, Quantity::Temperature);
        assert!(close(Unit::parse("K").unwrap().to_si(300.0), 26.85));
        assert_eq!(Unit::parse("none").unwrap().quantity, Quantity::Other);
    }

    #[test]
    fn raw_counts_with_offset_and_scale() {
        let u = Unit::parse("counts-32768*0.00875deg/s").unwrap();
        assert_eq!(u.quantity, Quantity::AngularRate);
        assert!(close(u.to_si(32768.0 + 1000.0), 8.75 * k::DEG));
        let v = Unit::parse("(counts - 32768) * 0.00875 deg/s").unwrap();
        assert!(close(v.to_si(33768.0), u.to_si(33768.0)));
        let g = Unit::parse("counts/6258 rad/s").unwrap();
        assert!(close(g.to_si(6258.0), 1.0));
        let p = Unit::parse("counts*1e-3").unwrap();
        assert_eq!(p.quantity, Quantity::Other);
        assert!(close(p.to_si(5.0), 5e-3));
        let plus = Unit::parse("counts+100").unwrap();
        assert!(close(plus.to_si(-100.0), -0.0 + 0.0) || plus.to_si(-100.0) == 0.0);
        let c = Unit::counts(0.001, 32768.0, Quantity::SpecificForce);
        assert!(close(c.to_si(33768.0), 1.0));
        assert_eq!(Unit::parse("counts").unwrap().to_si(7.0), 7.0);
    }

    #[test]
    fn unknown_units_are_rejected() {
        for bad in [
            "furlong",
            "deg",
            "counts*",
            "counts*0",
            "counts*abc",
            "counts/0",
            "counts-x",
            "(counts-1",
            "counts*2furlong",
            "counts*1e999",
        ] {
            assert!(Unit::parse(bad).is_err(), "{bad} should be rejected");
        }
        let e = Unit::parse("furlong").unwrap_err();
        assert!(e.to_string().contains("furlong"));
    }

    #[test]
    fn time_units() {
        assert_eq!("ms".parse::<TimeUnit>().unwrap().to_s(), 1e-3);
        assert_eq!("S".parse::<TimeUnit>().unwrap(), TimeUnit::Seconds);
        assert!("h".parse::<TimeUnit>().is_err());
    }
}

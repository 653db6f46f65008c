//! Noise and sensor-error values as data sheets and papers state them, converted to SI.
//!
//! A value is a number followed by a unit: `"3.8 mdeg/s/√Hz"`, `"0.5 deg/sqrt(h)"`,
//! `"70 ug/sqrt(Hz)"`, `"8 deg/h"`, `"5000 ppm"`. Spaces and case do not matter; `√x`,
//! `sqrt(x)`, `rt(x)` and `rtx` all mean the square root of x; `°` = `deg`, `dps` = `deg/s`,
//! `hr` = `h`, `µ`/`μ` = `u`. The unit must fit the quantity ([`Kind`]): a white-noise
//! density given as a bias is refused, not guessed.
//!
//! Conversions (Groves 2013 §4.4.3; IEEE Std 952-1997 Annex C): a rate-noise density of
//! 1 deg/s/√Hz is an angle random walk of 1 deg/√s = 60 deg/√h; 1 g/√Hz of accelerometer
//! noise is a velocity random walk of 9.806 65 m/s/√s; a rate random walk of 1 deg/h/√h is
//! 1/(3600·60) deg/s/√s; standard gravity converts g, mg, µg; 1 mGal = 1e-5 m/s².

use std::fmt;

use driftless_model::units::{DEG, STANDARD_GRAVITY};

/// What a value measures, in the SI unit it is converted to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Gyro white noise (angle random walk), rad/√s.
    AngleRandomWalk,
    /// Accelerometer white noise (velocity random walk), m/s/√s.
    VelocityRandomWalk,
    /// A gyro bias (σ or bias instability), rad/s.
    AngularRate,
    /// An accelerometer bias (σ or bias instability), m/s².
    SpecificForce,
    /// Gyro rate random walk (bias driving-noise density), rad/s/√s.
    RateRandomWalk,
    /// Accelerometer bias random walk (driving-noise density), m/s²/√s.
    AccelRandomWalk,
    /// A scale-factor error, dimensionless.
    Scale,
}

impl Kind {
    fn units(self) -> &'static [(&'static str, f64)] {
        const SQRT_H: f64 = 60.0;
        const H: f64 = 3600.0;
        const G: f64 = STANDARD_GRAVITY;
        match self {
            Kind::AngleRandomWalk => &[
                ("rad/sqrt(s)", 1.0),
                ("rad/s/sqrt(hz)", 1.0),
                ("deg/sqrt(s)", DEG),
                ("deg/s/sqrt(hz)", DEG),
                ("mdeg/s/sqrt(hz)", 1e-3 * DEG),
                ("deg/sqrt(h)", DEG / SQRT_H),
                ("deg/h/sqrt(hz)", DEG / H),
            ],
            Kind::VelocityRandomWalk => &[
                ("m/s/sqrt(s)", 1.0),
                ("m/s^2/sqrt(hz)", 1.0),
                ("m/s/sqrt(h)", 1.0 / SQRT_H),
                ("g/sqrt(hz)", G),
                ("mg/sqrt(hz)", 1e-3 * G),
                ("ug/sqrt(hz)", 1e-6 * G),
            ],
            Kind::AngularRate => &[
                ("rad/s", 1.0),
                ("deg/s", DEG),
                ("mdeg/s", 1e-3 * DEG),
                ("deg/h", DEG / H),
            ],
            Kind::SpecificForce => &[
                ("m/s^2", 1.0),
                ("g", G),
                ("mg", 1e-3 * G),
                ("ug", 1e-6 * G),
                ("mgal", 1e-5),
            ],
            Kind::RateRandomWalk => &[
                ("rad/s/sqrt(s)", 1.0),
                ("rad/s^2/sqrt(hz)", 1.0),
                ("deg/s/sqrt(s)", DEG),
                ("deg/s/sqrt(h)", DEG / SQRT_H),
                ("deg/h/sqrt(h)", DEG / (H * SQRT_H)),
                ("deg/h/sqrt(s)", DEG / H),
            ],
            Kind::AccelRandomWalk => &[
                ("m/s^2/sqrt(s)", 1.0),
                ("m/s^3/sqrt(hz)", 1.0),
                ("m/s/h/sqrt(h)", 1.0 / (H * SQRT_H)),
                ("mg/sqrt(s)", 1e-3 * G),
                ("ug/sqrt(s)", 1e-6 * G),
                ("ug/sqrt(h)", 1e-6 * G / SQRT_H),
            ],
            Kind::Scale => &[("ppm", 1e-6), ("%", 1e-2), ("", 1.0)],
        }
    }

    /// What the quantity is, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Kind::AngleRandomWalk => "a gyro white-noise density (angle random walk)",
            Kind::VelocityRandomWalk => {
                "an accelerometer white-noise density (velocity random walk)"
            }
            Kind::AngularRate => "an angular rate (gyro bias)",
            Kind::SpecificForce => "a specific force (accelerometer bias)",
            Kind::RateRandomWalk => "a gyro rate random walk",
            Kind::AccelRandomWalk => "an accelerometer bias random walk",
            Kind::Scale => "a scale-factor error",
        }
    }

    /// The accepted units, as written in messages.
    pub(crate) fn unit_list(self) -> String {
        self.units()
            .iter()
            .map(|(u, _)| if u.is_empty() { "(none)" } else { u })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A value that could not be read as the quantity asked for.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct QuantityError {
    /// The text given.
    pub text: String,
    /// What was expected.
    pub kind: Kind,
    /// Why it failed.
    pub reason: String,
}

impl fmt::Display for QuantityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:?} is not {}: {}; write a number and one of these units: {}",
            self.text,
            self.kind.describe(),
            self.reason,
            self.kind.unit_list()
        )
    }
}

/// Lower-case, no spaces, one spelling for every alias (module docs).
fn normalize(unit: &str) -> String {
    let mut s: String = unit
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_lowercase()
        .replace('°', "deg")
        .replace(['µ', 'μ'], "u")
        .replace('²', "^2")
        .replace('³', "^3");
    for (from, to) in [
        ("mdps", "mdeg/s"),
        ("dps", "deg/s"),
        ("degrees", "deg"),
        ("degree", "deg"),
        ("hour", "h"),
        ("hr", "h"),
        // Every spelling of a square root becomes `√`, then `√x` / `√(x)` → `sqrt(x)`.
        ("sqrt", "√"),
        ("rt", "√"),
        ("√(hz)", "√hz"),
        ("√(h)", "√h"),
        ("√(s)", "√s"),
        ("√hz", "sqrt(hz)"),
        ("√h", "sqrt(h)"),
        ("√s", "sqrt(s)"),
        ("m/s2", "m/s^2"),
    ] {
        s = s.replace(from, to);
    }
    s
}

/// Reads `text` as a value of `kind`, in SI units. Errors when the number is not finite or
/// negative, or the unit does not fit the quantity.
pub fn parse_quantity(text: &str, kind: Kind) -> Result<f64, QuantityError> {
    let err = |reason: String| QuantityError {
        text: text.to_owned(),
        kind,
        reason,
    };
    let t = text.trim();
    let split = t
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || c == '+'
                || c == '-'
                || ((c == 'e' || c == 'E')
                    && t[i + 1..]
                        .starts_with(|d: char| d.is_ascii_digit() || d == '-' || d == '+')))
        })
        .map_or(t.len(), |(i, _)| i);
    let (num, unit) = t.split_at(split);
    let value: f64 = num
        .parse()
        .map_err(|_| err(format!("{num:?} is not a number")))?;
    if !value.is_finite() || value < 0.0 {
        return Err(err("the value must be finite and ≥ 0".into()));
    }
    let u = normalize(unit);
    match kind.units().iter().find(|(name, _)| *name == u) {
        Some((_, factor)) => Ok(value * factor),
        None if u.is_empty() => Err(err("no unit given".into())),
        None => Err(err(format!("unit {:?} does not fit", unit.trim()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn data_sheet_spellings_convert() {
        // 3.8 mdps/√Hz = 3.8e-3 deg/s/√Hz = 3.8e-3·60 deg/√h = 0.228 deg/√h.
        let arw = parse_quantity("3.8 mdps/√Hz", Kind::AngleRandomWalk).unwrap();
        assert!(close(arw, 0.228 * DEG / 60.0));
        for s in [
            "0.228 deg/sqrt(h)",
            "0.228 °/√hr",
            "0.228deg/rt(h)",
            "0.228 deg/rthr",
        ] {
            assert!(
                close(parse_quantity(s, Kind::AngleRandomWalk).unwrap(), arw),
                "{s}"
            );
        }
        // 70 µg/√Hz = 70e-6·9.80665 m/s/√s.
        let vrw = parse_quantity("70 µg/√Hz", Kind::VelocityRandomWalk).unwrap();
        assert!(close(vrw, 70e-6 * STANDARD_GRAVITY));
        let vrw_h = parse_quantity("0.04118793 m/s/√h", Kind::VelocityRandomWalk).unwrap();
        assert!((vrw_h - vrw).abs() < 1e-8);
        assert!(close(
            parse_quantity("8 deg/h", Kind::AngularRate).unwrap(),
            8.0 * DEG / 3600.0
        ));
        assert!(close(
            parse_quantity("40 ug", Kind::SpecificForce).unwrap(),
            40e-6 * STANDARD_GRAVITY
        ));
        assert!(close(
            parse_quantity("40 deg/h/√h", Kind::RateRandomWalk).unwrap(),
            40.0 * DEG / (3600.0 * 60.0)
        ));
        assert!(close(
            parse_quantity("5000 ppm", Kind::Scale).unwrap(),
            5e-3
        ));
        assert!(close(parse_quantity("0.5 %", Kind::Scale).unwrap(), 5e-3));
        assert!(close(parse_quantity("0.005", Kind::Scale).unwrap(), 5e-3));
        assert!(close(
            parse_quantity("1e-3 rad/s", Kind::AngularRate).unwrap(),
            1e-3
        ));
    }

    #[test]
    fn wrong_units_and_values_are_refused_with_the_choices() {
        let e = parse_quantity("0.5 deg/h", Kind::AngleRandomWalk).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("does not fit") && m.contains("deg/sqrt(h)"),
            "{m}"
        );
        let e = parse_quantity("0.5", Kind::AngularRate).unwrap_err();
        assert!(e.to_string().contains("no unit"), "{e}");
        let e = parse_quantity("-1 deg/s", Kind::AngularRate).unwrap_err();
        assert!(e.to_string().contains("≥ 0"), "{e}");
        let e = parse_quantity("fast deg/s", Kind::AngularRate).unwrap_err();
        assert!(e.to_string().contains("not a number"), "{e}");
    }
}

//! Value parsers of numeric flags. A number out of range is a usage error (exit status 2)
//! that says what the flag needs — `invalid value '-100' for '--rate <HZ>': must be a
//! positive number, got -100` — and never clap's "unexpected argument '-1'": every flag
//! using one of these also sets `allow_hyphen_values`, so that `-100` or `-1e-4` reaches
//! the parser as the flag's value (a flag in its place, `--rate --json`, is then refused
//! as "expected a number").

use std::str::FromStr;

/// `s` as a finite number for which `ok` holds; else "must be {need}, got {s}".
fn number(s: &str, ok: impl Fn(f64) -> bool, need: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("expected a number, got {s:?}"))?;
    if !v.is_finite() {
        Err(format!("must be a finite number, got {s}"))
    } else if ok(v) {
        Ok(v)
    } else {
        Err(format!("must be {need}, got {s}"))
    }
}

/// A finite number > 0 (rates, durations, widths, gravity).
pub fn positive(s: &str) -> Result<f64, String> {
    number(s, |v| v > 0.0, "a positive number")
}

/// A finite number other than 0 (a scale factor may be negative).
pub fn finite_nonzero(s: &str) -> Result<f64, String> {
    number(s, |v| v != 0.0, "a finite number other than 0")
}

/// A probability strictly between 0 and 1 (confidence levels).
pub fn probability(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| v > 0.0 && v < 1.0,
        "a number between 0 and 1 (exclusive)",
    )
}

/// A finite number ≥ 0 (thresholds where 0 turns the check off).
pub fn non_negative(s: &str) -> Result<f64, String> {
    number(s, |v| v >= 0.0, "zero or a positive number")
}

/// A finite number > 1 (`--gap-factor`: an interval longer than this many nominal
/// sample intervals is a gap, so 1 or less would make every interval one).
pub fn above_one(s: &str) -> Result<f64, String> {
    number(s, |v| v > 1.0, "a number greater than 1")
}

/// A whole number ≥ 0 that fits `T` (indices, seeds, polynomial orders).
pub fn whole<T: FromStr>(s: &str) -> Result<T, String> {
    s.trim().parse().map_err(|_| {
        if s.trim().starts_with('-') {
            format!("must be zero or a positive whole number, got {s}")
        } else {
            format!("expected a whole number ≥ 0 within range, got {s:?}")
        }
    })
}

/// A whole number ≥ 1 (counts of runs).
pub fn count(s: &str) -> Result<usize, String> {
    match whole::<usize>(s) {
        Ok(0) => Err(format!("must be a positive whole number, got {s}")),
        Ok(n) => Ok(n),
        Err(_) if !s.trim().starts_with('-') => {
            Err(format!("expected a whole number ≥ 1, got {s:?}"))
        }
        Err(_) => Err(format!("must be a positive whole number, got {s}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_and_out_of_range_values_are_named() {
        assert_eq!(positive("100"), Ok(100.0));
        assert!(
            positive("-100")
                .unwrap_err()
                .contains("must be a positive number")
        );
        assert!(positive("0").is_err());
        assert!(positive("nan").unwrap_err().contains("finite"));
        assert!(positive("abc").unwrap_err().contains("expected a number"));
        assert_eq!(non_negative("0"), Ok(0.0));
        assert!(non_negative("-1").is_err());
        assert!(above_one("1").is_err());
        assert_eq!(above_one("1.5"), Ok(1.5));
        assert_eq!(whole::<u8>("3"), Ok(3));
        assert!(
            whole::<u8>("-3")
                .unwrap_err()
                .contains("must be zero or a positive")
        );
        assert!(whole::<u8>("300").is_err());
        assert_eq!(count("5"), Ok(5));
        assert!(count("0").unwrap_err().contains("positive whole number"));
        assert!(count("-2").unwrap_err().contains("positive whole number"));
    }
}

//! Decimal → f64 scanner for the text reader.
//!
//! Why hand-written instead of `fast-float2` or `lexical-core`: IMU logs are short decimal
//! numbers (≤ 19 significant digits, small exponents), for which Clinger's fast path is exact:
//! a mantissa `m ≤ 2^53` and a power of ten `10^e` with `|e| ≤ 22` are both exactly
//! representable in f64, so one IEEE multiplication or division yields the correctly rounded
//! result (W. D. Clinger, "How to read floating point numbers accurately", PLDI 1990).
//! Everything else (long mantissas such as `10000000.126856699585915`, large exponents,
//! `inf`/`nan` spellings) falls back to `str::parse::<f64>`, which is correctly rounded too.
//! This costs ~60 lines, no dependency and no compile time, and measured well above the
//! 400 MB/s target on the 2-core machine (see `benches/io_parse.rs`), so neither crate earns
//! its place here.

/// 10^0 … 10^22, all exact in f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses a whole field as a decimal number. `None` when the field is not a number.
/// May return a non-finite value (`inf`, `nan`, `1e999`): the caller rejects those.
#[inline]
pub(crate) fn parse_f64(s: &[u8]) -> Option<f64> {
    match parse_prefix(s) {
        Some((v, used)) if used == s.len() => Some(v),
        _ => slow(s),
    }
}

/// Fast path only: parses the longest decimal-number prefix of `s` when Clinger's exact fast
/// path applies, returning the value and the bytes used. `None` (caller falls back to
/// [`parse_f64`] on the delimited field) when there is no digit, the mantissa has more than
/// 19 digits or exceeds 2^53, or the decimal exponent is outside ±22.
#[inline(always)]
pub(crate) fn parse_prefix(s: &[u8]) -> Option<(f64, usize)> {
    let n = s.len();
    let mut i = 0;
    let neg = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut mant: u64 = 0;
    let int_start = i;
    while i < n {
        let d = s[i].wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        mant = mant.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    let mut digits = i - int_start;
    let mut exp: i64 = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        let frac_start = i;
        while let Some(eight) = eight_digits(s, i) {
            mant = mant.wrapping_mul(100_000_000).wrapping_add(eight);
            i += 8;
        }
        while i < n {
            let d = s[i].wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            mant = mant.wrapping_mul(10).wrapping_add(u64::from(d));
            i += 1;
        }
        let frac = i - frac_start;
        digits += frac;
        exp = -(frac as i64);
    }
    if digits == 0 || digits > 19 {
        return None;
    }
    if i < n && (s[i] | 0x20) == b'e' {
        i += 1;
        let eneg = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let start = i;
        let mut e: i64 = 0;
        while i < n {
            let d = s[i].wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            if e < 100_000 {
                e = e * 10 + i64::from(d);
            }
            i += 1;
        }
        if i == start {
            return None;
        }
        exp += if eneg { -e } else { e };
    }
    if mant > (1u64 << 53) || !(-22..=22).contains(&exp) {
        return None;
    }
    let m = mant as f64;
    let v = if exp < 0 {
        m / POW10[(-exp) as usize]
    } else {
        m * POW10[exp as usize]
    };
    Some((if neg { -v } else { v }, i))
}

/// The value of 8 ASCII digits at `s[i..i + 8]`, if they all are digits (SWAR: one load,
/// a validity test and three multiplications instead of eight dependent steps).
#[inline(always)]
fn eight_digits(s: &[u8], i: usize) -> Option<u64> {
    const LOW: u64 = 0x3030_3030_3030_3030;
    const HIGH: u64 = 0xF0F0_F0F0_F0F0_F0F0;
    let bytes: [u8; 8] = s.get(i..i.checked_add(8)?)?.try_into().ok()?;
    let v = u64::from_le_bytes(bytes);
    // every byte in 0x30..=0x39: high nibble 3, and adding 6 does not carry into it
    if (v & HIGH) != LOW || (v.wrapping_add(0x0606_0606_0606_0606) & HIGH) != LOW {
        return None;
    }
    let v = v - LOW;
    // pairs: byte k holds d_k; combine neighbours into 2-digit, then 4-digit, then 8-digit
    let v = (v * 10) + (v >> 8); // 16-bit lanes: 10*d0 + d1 in the low byte of each lane
    let v = ((v & 0x0000_00FF_0000_00FF).wrapping_mul(100 + (1_000_000 << 32))
        + ((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32)))
        >> 32;
    Some(v)
}

#[cold]
fn slow(s: &[u8]) -> Option<f64> {
    std::str::from_utf8(s).ok()?.parse::<f64>().ok()
}

#[cfg(test)]
mod tests {
    use super::parse_f64;

    #[test]
    fn agrees_with_std_on_many_spellings() {
        let cases = [
            "0",
            "-0",
            "+1",
            "1.",
            ".5",
            "-.5",
            "3.14159",
            "1e5",
            "1E-5",
            "2.5e+3",
            "9007199254740993",
            "123456789012345678901234",
            "10000000.126856699585915",
            "1e-300",
            "1e308",
            "4.9e-324",
            "0.000000000000000000001",
            "-7.25e-22",
            "123.456e22",
            "1.7976931348623157e308",
            "0.1",
            "0.2",
            "0.3",
            "261906",
            "-0.671",
            "3.3108000e+04",
        ];
        for c in cases {
            let want: f64 = c.parse().unwrap();
            let got = parse_f64(c.as_bytes()).unwrap();
            assert_eq!(got.to_bits(), want.to_bits(), "{c}");
        }
    }

    #[test]
    fn rejects_non_numbers() {
        for c in [
            "", "-", "+", ".", "e5", "1e", "1e+", "1.2.3", "abc", "1,5", "--1", "1 2", "0x10",
            "1_0",
        ] {
            assert!(parse_f64(c.as_bytes()).is_none(), "{c:?}");
        }
        assert!(parse_f64(b"nan").unwrap().is_nan());
        assert!(parse_f64(b"-inf").unwrap().is_infinite());
        assert!(parse_f64(b"1e999").unwrap().is_infinite());
    }

    #[test]
    fn random_decimals_round_trip_bit_exact() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if !v.is_finite() {
                continue;
            }
            for s in [
                format!("{v}"),
                format!("{v:e}"),
                format!("{:.6}", v / 1e300),
            ] {
                let want: f64 = s.parse().unwrap();
                assert_eq!(
                    parse_f64(s.as_bytes()).unwrap().to_bits(),
                    want.to_bits(),
                    "{s}"
                );
            }
            let short = format!("{:.5e}", (x % 2_000_000) as f64 * 1e-4 - 100.0);
            let want: f64 = short.parse().unwrap();
            assert_eq!(
                parse_f64(short.as_bytes()).unwrap().to_bits(),
                want.to_bits(),
                "{short}"
            );
        }
    }
}

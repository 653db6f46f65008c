//! One line of a KF-GINS file: each value in its `"%-15.9lf "` layout, lines
//! collected in a buffer written out in large chunks.

use super::*;

/// Appends one value in KF-GINS's `"%-15.9lf "` format ([`put_value`], else the standard
/// formatter) after bytes of garbage: every byte of the value must be written.
#[cfg(test)]
pub(super) fn push_value(line: &mut Vec<u8>, v: f64) {
    let len = line.len();
    line.resize(len + SLOW_MAX, 0xAA);
    let n = put_value(&mut line[len..], v).unwrap_or_else(|| put_slow(&mut line[len..], v));
    line.truncate(len + n);
}

/// Bytes [`put_value`] may touch.
pub(super) const VALUE_MAX: usize = 24;

/// Bytes the standard formatter may write for one finite value in `"%-15.9lf "`: f64::MAX
/// has 309 integer digits, then the point, 9 decimals, a sign and the trailing space.
pub(super) const SLOW_MAX: usize = 330;

/// Writes `v` in KF-GINS's `"%-15.9lf "` format (left-aligned, width 15, 9 decimals, one
/// space after) at the start of `out` (≥ [`VALUE_MAX`] bytes; the padding spaces are
/// written too) and returns the bytes written, or `None` when the fast path does not apply.
///
/// Fast path for |v| < 1e8: the integer part and 9 fractional digits by integer
/// arithmetic (the fraction v − trunc(v) is exact; its scaling by 1e9 errs by < 1e-6 of a
/// unit, so the rounding is the correctly rounded decimal except within 1e-6 of a tie,
/// where the standard formatter takes over), eight digits at a time in one register
/// ([`eight_digits`]) and stored with one 8-byte write. Output is identical to
/// `format!("{v:<15.9} ")`, several times faster — the writers emit ~33 M values per hour
/// of 200 Hz data.
#[inline(always)]
pub(super) fn put_value(out: &mut [u8], v: f64) -> Option<usize> {
    let a = v.abs();
    if a.is_nan() || a >= 1.0e8 {
        return None;
    }
    // Truncation by conversion (exact below 2^53), no libm call; through i64, which
    // converts to and from f64 in one instruction (u64 needs a branchy sequence).
    let int0 = a as i64;
    let f = (a - int0 as f64) * 1e9;
    let f_floor = f as i64;
    let rem = f - f_floor as f64;
    if (rem - 0.5).abs() <= 1e-6 {
        return None;
    }
    let mut int = int0 as u64;
    let mut frac = f_floor as u64 + u64::from(rem > 0.5);
    if frac >= 1_000_000_000 {
        frac -= 1_000_000_000;
        int += 1;
        if int >= 100_000_000 {
            return None;
        }
    }
    let out = &mut out[..VALUE_MAX];
    // The padding (at most 19 bytes are digits, sign and point; the rest spaces).
    out.fill(b' ');
    let mut n = usize::from(v.is_sign_negative());
    out[0] = if n == 1 { b'-' } else { b' ' };
    if int < 10 {
        // One digit (σ's, biases, angles below 10): no digit split needed.
        out[n] = b'0' + int as u8;
        n += 1;
    } else {
        // The digit values (not yet ASCII), most significant first: the leading zero
        // digits are the low-order zero bytes (int ≥ 10, so at most six of them). The
        // integer's digits are the last `int_digits` of its eight; the zero bytes
        // shifted in behind them are overwritten by the point and the fraction.
        let digits = eight_digit_values(int as u32);
        let lead = (digits.trailing_zeros() / 8) as usize;
        let int_ascii = (digits + ASCII_ZEROS) >> (8 * lead);
        out[n..n + 8].copy_from_slice(&int_ascii.to_le_bytes());
        n += 8 - lead;
    }
    out[n] = b'.';
    out[n + 1] = b'0' + (frac / 100_000_000) as u8;
    out[n + 2..n + 10].copy_from_slice(&eight_digits((frac % 100_000_000) as u32).to_le_bytes());
    n += 10;
    Some(n.max(15) + 1)
}

/// Writes finite `v` in `"%-15.9lf "` with the standard formatter at the start of `out`
/// (≥ [`SLOW_MAX`] bytes) and returns the bytes written: the values [`put_value`] leaves.
pub(super) fn put_slow(out: &mut [u8], v: f64) -> usize {
    let room = out.len();
    let mut rest = &mut out[..];
    // Cannot fail: `out` has room for any finite value (SLOW_MAX).
    let _ = write!(rest, "{v:<15.9} ");
    room - rest.len()
}

/// Eight ASCII `'0'` bytes.
pub(super) const ASCII_ZEROS: u64 = 0x3030_3030_3030_3030;

/// The eight decimal digits of `x` < 10⁸ (zero-padded) as ASCII bytes of a little-endian
/// u64, the most significant digit first ([`eight_digit_values`] plus `'0'`).
pub(super) fn eight_digits(x: u32) -> u64 {
    eight_digit_values(x) + ASCII_ZEROS
}

/// The eight decimal digits of `x` < 10⁸ (zero-padded) as byte values 0–9 of a
/// little-endian u64, the most significant digit first: x splits into two 4-digit halves
/// in 32-bit lanes, each into two 2-digit quarters in 16-bit lanes, each into two digits
/// in bytes, by multiply-shift division (x/100 = ⌊10486x / 2²⁰⌋ for x < 10⁴,
/// x/10 = ⌊103x / 2¹⁰⌋ for x < 100; no carry crosses a lane).
pub(super) fn eight_digit_values(x: u32) -> u64 {
    let hi = u64::from(x / 10_000);
    let lo = u64::from(x % 10_000);
    let v = hi | (lo << 32);
    let q = ((v * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let v = q | ((v - q * 100) << 16);
    let q = ((v * 103) >> 10) & 0x000F_000F_000F_000F;
    q | ((v - q * 10) << 8)
}

/// Bytes a [`LineBuf`] collects before it is written out: 512 KiB, so that the three
/// files' buffers stay in a core's L2 cache while the kernel copies them into the page
/// cache (with 4 MiB buffers that copy was 3–4× slower: 0.8–1.2 s of system time per
pub(super) const CHUNK: usize = 1 << 19;
/// Most values in one line of the output files (the std file's 22).
pub(super) const MAX_COLS: usize = 22;

/// Staging buffer of an output file: lines of `"%-15.9lf "` values are formatted into a
/// buffer whose length is set once ([`CHUNK`] plus room for one line of the longest
/// values), behind a cursor, so a row costs no resize, fill or capacity check; the filled
/// part is written out once past [`CHUNK`].
pub(super) struct LineBuf {
    pub(super) buf: Vec<u8>,
    pub(super) pos: usize,
}

impl LineBuf {
    pub(super) fn new() -> Self {
        LineBuf {
            buf: vec![b' '; CHUNK + MAX_COLS * SLOW_MAX + 1],
            pos: 0,
        }
    }

    /// Appends `vals` as one line; `Err(k)`, nothing appended, when `vals[k]` is the first
    /// value that is not finite.
    pub(super) fn line<const N: usize>(&mut self, vals: &[f64; N]) -> Result<(), usize> {
        const { assert!(N <= MAX_COLS) };
        if let Some(k) = vals.iter().position(|v| !v.is_finite()) {
            return Err(k);
        }
        let mut pos = self.pos;
        for &v in vals {
            let out = &mut self.buf[pos..];
            pos += match put_value(out, v) {
                Some(m) => m,
                None => put_slow(out, v),
            };
        }
        self.buf[pos] = b'\n';
        self.pos = pos + 1;
        Ok(())
    }

    pub(super) fn is_full(&self) -> bool {
        self.pos >= CHUNK
    }

    /// Writes the filled part to `w` and empties the buffer.
    pub(super) fn drain_to(&mut self, w: &mut impl Write, name: &str) -> Result<(), LogError> {
        let filled = &self.buf[..self.pos];
        self.pos = 0;
        w.write_all(filled).map_err(|error| io_error(name, error))
    }
}

#[cfg(test)]
mod push_value_tests {
    use super::push_value;

    #[test]
    fn matches_the_standard_formatter() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut checked = 0;
        for i in 0..1_000_000u64 {
            let r = next();
            let mag = 10f64.powi((r % 24) as i32 - 12);
            let v = match i % 5 {
                0 => (r >> 11) as f64 / (1u64 << 53) as f64 * mag,
                1 => -((r >> 11) as f64 / (1u64 << 53) as f64) * mag,
                2 => (r % 1_000_000_000) as f64 * 1e-9 + (r % 1000) as f64, // on the grid
                3 => 243_300.0 + (r >> 11) as f64 / (1u64 << 53) as f64 * 600.0,
                _ => f64::from_bits(r) % 5e9,
            };
            if !v.is_finite() {
                continue;
            }
            let mut fast = Vec::new();
            push_value(&mut fast, v);
            assert_eq!(fast, format!("{v:<15.9} ").as_bytes(), "value {v:e}");
            checked += 1;
        }
        for v in [
            0.0,
            -0.0,
            0.5e-9,
            1.5e-9,
            -2.5e-9,
            3_999_999_999.999_999_9,
            1e10,
            -1e12,
        ] {
            let mut fast = Vec::new();
            push_value(&mut fast, v);
            assert_eq!(fast, format!("{v:<15.9} ").as_bytes(), "value {v:e}");
        }
        assert!(checked > 900_000);
    }
}

//! Seedable pseudo-random numbers for the simulators (no external crate).
//!
//! * Generator: xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number
//!   generators", ACM TOMS 47(4), 2021), 256-bit state, period 2²⁵⁶ − 1.
//! * Seeding: the four state words are consecutive outputs of SplitMix64 (Steele, Lea &
//!   Flood, OOPSLA 2014) started from the user's `u64` seed, as the xoshiro authors
//!   recommend; an all-zero state is impossible that way.
//! * Independent streams (one per channel): [`Rng::stream`] mixes the stream index into
//!   the seed through SplitMix64 before seeding, so streams are statistically independent
//!   for practical purposes (overlap probability ≈ 2⁻¹⁹⁰ for 10¹⁰-sample streams).
//! * Standard normal: 256-layer ziggurat (Marsaglia & Tsang, J. Stat. Softw. 5(8), 2000)
//!   in the form of Doornik (2005, "An improved ziggurat method to generate normal random
//!   samples"): one 64-bit draw gives both the layer index (8 bits) and a 53-bit uniform,
//!   ~98.8 % of draws return after one multiply and one compare; the base layer's tail
//!   beyond r is sampled exactly by Marsaglia's (1964) exponential method.
//!
//! Everything is deterministic: the same seed gives the same sequence on every platform
//! (only IEEE-754 `f64` arithmetic and `exp`/`ln` in the rare slow path are involved).

use std::sync::OnceLock;

pub use crate::numeric::splitmix64;

/// xoshiro256++ generator with uniform and standard-normal variates.
#[derive(Clone, Debug)]
pub struct Rng {
    s: [u64; 4],
}

impl Rng {
    /// Seed from a `u64` through SplitMix64.
    pub fn seed_from_u64(seed: u64) -> Rng {
        let mut sm = seed;
        let s = [
            splitmix64(&mut sm),
            splitmix64(&mut sm),
            splitmix64(&mut sm),
            splitmix64(&mut sm),
        ];
        Rng { s }
    }

    /// Generator for sub-stream `stream` of `seed` (e.g. one per channel or per noise
    /// component). Different `(seed, stream)` pairs give unrelated sequences.
    pub fn stream(seed: u64, stream: u64) -> Rng {
        let mut sm = stream ^ 0x6A09_E667_F3BC_C909;
        let mixed = seed ^ splitmix64(&mut sm);
        Rng::seed_from_u64(mixed)
    }

    /// Next raw 64-bit output.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform on [0, 1) with 53 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform on the open interval (0, 1) (safe to take `ln`).
    #[inline]
    pub(crate) fn uniform_open(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform on [−1, 1).
    #[inline]
    pub(crate) fn uniform_pm1(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (2.0 / (1u64 << 53) as f64) - 1.0
    }

    /// Standard normal N(0, 1) variate (ziggurat).
    #[inline]
    pub fn normal(&mut self) -> f64 {
        let z = ziggurat();
        loop {
            let bits = self.next_u64();
            let i = (bits & 0xff) as usize;
            // 53-bit uniform on [−1, 1) from the upper bits (disjoint from the index bits).
            let u = (bits >> 11) as f64 * (2.0 / (1u64 << 53) as f64) - 1.0;
            if u.abs() < z.ratio[i] {
                return u * z.x[i];
            }
            if let Some(v) = self.normal_slow(z, i, u) {
                return v;
            }
        }
    }

    /// Fill `out` with independent N(0, sigma²) variates.
    pub fn fill_normal(&mut self, out: &mut [f64], sigma: f64) {
        for v in out.iter_mut() {
            *v = sigma * self.normal();
        }
    }

    #[cold]
    fn normal_slow(&mut self, z: &Ziggurat, i: usize, u: f64) -> Option<f64> {
        if i == 0 {
            // Tail beyond r: x = r + a with a ~ Exp(r) restricted by the Gaussian shape.
            loop {
                let a = -self.uniform_open().ln() / ZIG_R;
                let b = -self.uniform_open().ln();
                if 2.0 * b > a * a {
                    return Some(if u < 0.0 { -(ZIG_R + a) } else { ZIG_R + a });
                }
            }
        }
        // Wedge between layers i and i+1: accept under the density.
        let x = u * z.x[i];
        let f0 = (-0.5 * (z.x[i] * z.x[i] - x * x)).exp();
        let f1 = (-0.5 * (z.x[i + 1] * z.x[i + 1] - x * x)).exp();
        if f1 + self.uniform() * (f0 - f1) < 1.0 {
            Some(x)
        } else {
            None
        }
    }
}

/// Right edge of the base strip for 256 layers of exp(−x²/2).
const ZIG_R: f64 = 3.654_152_885_361_009;
/// Common area of every layer (including the base strip with its tail).
const ZIG_V: f64 = 0.004_928_673_233_992_336_5;

struct Ziggurat {
    /// Layer right edges, x[0] = V/f(r) (pseudo-width of the base strip), x[1] = r, …, x[256] = 0.
    x: [f64; 257],
    /// x[i+1]/x[i]: the fast-accept threshold of layer i.
    ratio: [f64; 256],
}

fn ziggurat() -> &'static Ziggurat {
    static TABLE: OnceLock<Ziggurat> = OnceLock::new();
    TABLE.get_or_init(|| {
        let f = |x: f64| (-0.5 * x * x).exp();
        let mut x = [0.0; 257];
        x[0] = ZIG_V / f(ZIG_R);
        x[1] = ZIG_R;
        for i in 1..256 {
            // Layer i has area V: x[i]·(f(x[i+1]) − f(x[i])) = V.
            let arg = ZIG_V / x[i] + f(x[i]);
            x[i + 1] = if arg >= 1.0 {
                0.0
            } else {
                (-2.0 * arg.ln()).sqrt()
            };
        }
        x[256] = 0.0;
        let mut ratio = [0.0; 256];
        for i in 0..256 {
            ratio[i] = x[i + 1] / x[i];
        }
        Ziggurat { x, ratio }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproducible_and_streams_differ() {
        let mut a = Rng::seed_from_u64(42);
        let mut b = Rng::seed_from_u64(42);
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
        let mut c = Rng::stream(42, 0);
        let mut d = Rng::stream(42, 1);
        let same = (0..64).filter(|_| c.next_u64() == d.next_u64()).count();
        assert_eq!(same, 0);
    }

    #[test]
    fn ziggurat_table_closes_at_zero() {
        let z = ziggurat();
        // The recursion must land (numerically) on the peak: the last computed edge is tiny.
        assert!(z.x[255] > 0.0 && z.x[255] < 0.3, "x[255] = {}", z.x[255]);
        for i in 0..256 {
            assert!(z.x[i + 1] < z.x[i]);
        }
    }

    #[test]
    fn uniform_moments() {
        let mut r = Rng::seed_from_u64(7);
        let n = 1_000_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            s1 += u;
            s2 += u * u;
        }
        let m = s1 / n as f64;
        let v = s2 / n as f64 - m * m;
        assert!((m - 0.5).abs() < 1.5e-3, "mean {m}");
        assert!((v - 1.0 / 12.0).abs() < 1e-3, "var {v}");
    }

    #[test]
    fn normal_moments_and_tails() {
        let mut r = Rng::seed_from_u64(12345);
        let n = 4_000_000usize;
        let (mut s1, mut s2, mut s3, mut s4) = (0.0, 0.0, 0.0, 0.0);
        let (mut over2, mut over3, mut over4) = (0usize, 0usize, 0usize);
        for _ in 0..n {
            let x = r.normal();
            let x2 = x * x;
            s1 += x;
            s2 += x2;
            s3 += x2 * x;
            s4 += x2 * x2;
            over2 += (x.abs() > 2.0) as usize;
            over3 += (x.abs() > 3.0) as usize;
            over4 += (x.abs() > 4.0) as usize;
        }
        let nf = n as f64;
        let (m, v, sk, ku) = (s1 / nf, s2 / nf, s3 / nf, s4 / nf);
        // Standard errors: mean 5e-4, var 7e-4, skew 1.2e-3, kurt 4.9e-3 → ~5σ bounds.
        assert!(m.abs() < 2.5e-3, "mean {m}");
        assert!((v - 1.0).abs() < 3.5e-3, "var {v}");
        assert!(sk.abs() < 6e-3, "third moment {sk}");
        assert!((ku - 3.0).abs() < 2.5e-2, "fourth moment {ku}");
        // Two-sided tail probabilities: 0.0455003, 0.0026998, 6.334e-5.
        let p2 = over2 as f64 / nf;
        let p3 = over3 as f64 / nf;
        let p4 = over4 as f64 / nf;
        assert!(
            (p2 - 0.045_500_3).abs() < 5.0 * (0.0455 / nf).sqrt(),
            "P(|x|>2) {p2}"
        );
        assert!(
            (p3 - 0.002_699_8).abs() < 5.0 * (0.0027 / nf).sqrt(),
            "P(|x|>3) {p3}"
        );
        assert!(
            (p4 - 6.334e-5).abs() < 5.0 * (6.334e-5 / nf).sqrt(),
            "P(|x|>4) {p4}"
        );
    }

    #[test]
    fn normal_histogram_matches_density() {
        // Chi-square goodness of fit on 40 bins over [−4, 4]: catches a wrong layer table.
        let mut r = Rng::seed_from_u64(99);
        let n = 2_000_000usize;
        let bins = 40usize;
        let mut h = vec![0usize; bins];
        for _ in 0..n {
            let x = r.normal();
            if x.abs() < 4.0 {
                h[((x + 4.0) / 8.0 * bins as f64) as usize] += 1;
            }
        }
        let phi = crate::numeric::normal_cdf;
        let mut chi2 = 0.0;
        for (k, &c) in h.iter().enumerate() {
            let a = -4.0 + 8.0 * k as f64 / bins as f64;
            let b = a + 8.0 / bins as f64;
            let e = n as f64 * (phi(b) - phi(a));
            chi2 += (c as f64 - e).powi(2) / e;
        }
        // 39 dof: 99.99 % quantile ≈ 80.
        assert!(chi2 < 80.0, "chi2 = {chi2}");
    }
}

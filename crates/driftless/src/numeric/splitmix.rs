//! SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
//! OOPSLA 2014): a Weyl sequence with increment γ = 0x9E37_79B9_7F4A_7C15 followed by the
//! variant-13 64-bit finaliser (Stafford's mix):
//!
//! ```text
//! s ← s + γ;  z = (s ⊕ s≫30)·0xBF58_476D_1CE4_E5B9;  z = (z ⊕ z≫27)·0x94D0_49BB_1331_11EB;  z ⊕ z≫31
//! ```
//!
//! Used to seed the xoshiro generators and to derive independent sub-seeds.

/// Weyl increment γ (2⁶⁴ / golden ratio, odd).
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64 step: advances `state` by γ and returns the mixed new state.
#[inline]
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(GAMMA);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The first SplitMix64 output from state `z` (a stateless 64-bit hash of `z`), i.e.
/// [`splitmix64`] on a copy of `z`.
#[inline]
pub fn splitmix64_mix(z: u64) -> u64 {
    let mut s = z;
    splitmix64(&mut s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_reference_sequence() {
        // First outputs from seed 0 of the reference implementation (Vigna's
        // splitmix64.c): 0xE220A8397B1DCDAF, 0x6E789E6AA1B965F4, 0x06C45D188009454F.
        let mut s = 0u64;
        assert_eq!(splitmix64(&mut s), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64(&mut s), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(splitmix64(&mut s), 0x06C4_5D18_8009_454F);
        assert_eq!(s, GAMMA.wrapping_mul(3));
        assert_eq!(splitmix64_mix(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64_mix(GAMMA), 0x6E78_9E6A_A1B9_65F4);
    }
}

//! Medians of samples. Ordering is `f64::total_cmp` (NaN sorts above +∞, −0 below +0),
//! so no input panics; selection is O(n) (`select_nth_unstable_by`) and reorders the
//! slice.

/// Upper median: the element of rank ⌊n/2⌋ (0-based) in sorted order, i.e. the middle
/// element for odd n and the upper of the two middle ones for even n; `None` when empty.
/// Always one of the samples (used for nominal intervals, where an average of two
/// intervals would be no interval at all).
pub fn upper_median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    Some(*v.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// Median: the middle element for odd n, the mean of the two middle elements for even n;
/// `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    let n = v.len();
    let upper = upper_median(v)?;
    if n % 2 == 1 {
        return Some(upper);
    }
    // After selection the lower middle element is the largest of v[..n/2].
    let lower = v[..n / 2].iter().copied().max_by(f64::total_cmp)?;
    Some(0.5 * (lower + upper))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_even_and_empty() {
        assert_eq!(median(&mut []), None);
        assert_eq!(upper_median(&mut []), None);
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(upper_median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(upper_median(&mut [4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median(&mut [5.0]), Some(5.0));
    }

    #[test]
    fn agrees_with_sorting() {
        // A fixed scrambled sequence with repeats, every length 1..60.
        let data: Vec<f64> = (0..60u64)
            .map(|k| ((k * 37 + 11) % 23) as f64 - 7.5)
            .collect();
        for n in 1..=data.len() {
            let mut sorted = data[..n].to_vec();
            sorted.sort_by(f64::total_cmp);
            let want = if n % 2 == 1 {
                sorted[n / 2]
            } else {
                0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
            };
            assert_eq!(median(&mut data[..n].to_vec()), Some(want), "n = {n}");
            assert_eq!(upper_median(&mut data[..n].to_vec()), Some(sorted[n / 2]));
        }
    }

    #[test]
    fn nan_does_not_panic() {
        assert_eq!(median(&mut [1.0, f64::NAN, 0.0]), Some(1.0));
    }
}

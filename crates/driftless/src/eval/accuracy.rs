//! One-number accuracy of a whole solution: the horizontal RMS error against a
//! reference over the epochs after a convergence time.

use super::EvalError;
use super::metrics::horizontal_errors;
use crate::io::nav::NavSolution;

/// Horizontal RMS error of `solution` against `reference`, m: √(Σ e_k² / n) over the
/// solution epochs at or after `from_s` where the reference can be interpolated (gaps
/// of at most `max_reference_gap_s`), with e_k the horizontal distance of
/// [`horizontal_errors`]. Returns the RMS and n.
///
/// Errors: the trajectories' own checks ([`horizontal_errors`]), and
/// [`EvalError::BadTrajectory`] when no solution epoch at or after `from_s` overlaps the
/// reference (an RMS of nothing is not 0).
pub fn horizontal_rms_m(
    reference: &NavSolution,
    solution: &NavSolution,
    from_s: f64,
    max_reference_gap_s: f64,
) -> Result<(f64, usize), EvalError> {
    let errs = horizontal_errors(reference, solution, max_reference_gap_s)?;
    let (sum2, n) = solution
        .time_s
        .iter()
        .zip(errs)
        .filter(|(t, _)| **t >= from_s)
        .filter_map(|(_, e)| e)
        .fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    if n == 0 {
        return Err(EvalError::BadTrajectory {
            which: "solution",
            reason: format!(
                "no epoch at or after t = {from_s} s overlaps the reference; start the \
                 score earlier or give a reference covering the solution"
            ),
        });
    }
    Ok(((sum2 / n as f64).sqrt(), n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(offset_north_m: f64, times: &[f64]) -> NavSolution {
        let mut s = NavSolution::default();
        let r = 6_378_137.0;
        for &t in times {
            s.push_epoch(t, 0.5 + offset_north_m / r, 0.1, 10.0, [0.0; 3], [0.0; 3]);
        }
        s
    }

    #[test]
    fn a_constant_offset_is_its_own_rms_and_early_epochs_are_left_out() {
        let times: Vec<f64> = (0..20).map(f64::from).collect();
        let reference = line(0.0, &times);
        let mut sol = line(2.0, &times);
        // A large error before the score starts must not count.
        sol.lat_rad[0] += 100.0 / 6_378_137.0;
        let (rms, n) = horizontal_rms_m(&reference, &sol, 1.0, 1.5).unwrap();
        assert_eq!(n, 19);
        assert!((rms - 2.0).abs() < 0.02, "{rms}");
        assert!(horizontal_rms_m(&reference, &sol, 100.0, 1.5).is_err());
    }
}

//! A σ floor for the GNSS fixes estimated from the data's own innovations.
//!
//! A receiver's formal σ (RTKLIB's sdn/sde/sdu, ~1 cm for a fixed RTK solution) describes
//! the antenna's phase centre under white-noise assumptions. What the filter needs is the
//! error of the fix against the point the IMU carries: antenna sway on a hand-held pole or
//! a person, multipath, body blockage and the IMU–GNSS time-tag error, which on a moving
//! consumer rig reach decimetres, correlated over seconds. Taken at 1 cm, every such fix
//! pins the filter, its state absorbs the motion and its covariance under-states the error
//! at the end of every outage. On a rigid antenna with a good receiver the formal σ is
//! close to right and any fixed floor costs accuracy. Neither number is platform-free, so
//! the default is to measure it.
//!
//! **Method** (covariance matching of the innovations, Mehra 1970, IEEE TAC 15:175–184;
//! for INS/GNSS Mohamed & Schwarz 1999, J. Geodesy 73:193–203): for a consistent filter
//! the one-step innovation ν = ẑ⁻ − z of a fix has E[ν νᵀ] = H P⁻ Hᵀ + R. A first forward
//! pass with the file's σ gives ν and H P⁻ Hᵀ at every accepted fix; per quality flag and
//! measurement kind the batch estimate
//!
//! > R̂_h = mean over fixes of ½(ν_N² + ν_E²) − ½(HPHᵀ_NN + HPHᵀ_EE),
//! > R̂_v = mean(ν_D²) − mean(HPHᵀ_DD)
//!
//! (horizontal axes pooled: antenna motion has no preferred horizontal direction) is
//! the measurement variance the innovations call for. The second, final pass uses
//! σ = max(σ_file·k, √R̂) (k the quality multiplier): a floor, so fixes whose file σ
//! already covers their spread keep it. On data whose σ is right R̂ ≈ σ², and the floor
//! changes nothing material.
//!
//! It is estimated once, from the first pass, and never fed back: an on-line version
//! (R from a running window of innovations) is unstable here — weaker fixes let the
//! state drift, the drift enters the innovations, and R grows without bound. In the first
//! pass the filter follows the fixes closely (their σ is the small formal one), so its
//! innovations measure the fixes' fix-to-fix scatter plus the one-step prediction error,
//! both of which the final pass must treat as measurement error to stay consistent.
//!
//! Fixes in the convergence periods (after the start, after outages and data gaps) and
//! rejected fixes do not count; a class with fewer than [`MIN_FIXES`] usable fixes keeps
//! the file's σ.

use super::filter::eskf::{UpdateKind, UpdateOutcome};
use super::filter::model::QualityScale;
use crate::io::nav::GnssFixes;

/// Fewest usable fixes for an estimate of one class.
pub const MIN_FIXES: usize = 20;

/// The floor estimated for one quality flag and measurement kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassFloor {
    /// RTKLIB quality flag ([`crate::io::nav::quality`]).
    pub quality: u8,
    /// [`UpdateKind::Position`] (floor in m) or [`UpdateKind::Velocity`] (m/s).
    pub kind: UpdateKind,
    /// Fixes the estimate used.
    pub fixes: usize,
    /// Horizontal floor √R̂_h (0 when the innovations call for no more than H P Hᵀ).
    pub horizontal: f64,
    /// Vertical floor √R̂_v.
    pub vertical: f64,
    /// Median file σ of the class after the quality multiplier (horizontal, vertical),
    /// for the report.
    pub file_sigma: (f64, f64),
}

/// The innovations of one class: ½(ν_N² + ν_E²), ν_D², and the matching H P⁻ Hᵀ terms.
#[derive(Clone, Debug, Default)]
struct ClassSamples {
    nu2_h: Vec<f64>,
    nu2_v: Vec<f64>,
    hph_h: Vec<f64>,
    hph_v: Vec<f64>,
}

/// Median of χ²₁ (for ν_D²/σ²); ½(ν_N² + ν_E²)/σ² is exponential with median ln 2.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// Squared innovations beyond this many robust σ count as this many σ (winsorised).
pub(crate) const CLIP_SIGMA: f64 = 10.0;

/// Batch covariance-matching floors (module docs) from a first pass's update outcomes.
/// `used(t)` is false for fixes inside a convergence period. Classes are listed by
/// kind, then quality flag.
pub fn estimate(
    outcomes: impl IntoIterator<Item = UpdateOutcome>,
    gnss: &GnssFixes,
    scale: &QualityScale,
    used: impl Fn(f64) -> bool,
) -> Vec<ClassFloor> {
    let mut classes: Vec<((UpdateKind, u8), ClassSamples)> = Vec::new();
    for o in outcomes {
        if !matches!(o.kind, UpdateKind::Position | UpdateKind::Velocity)
            || !o.accepted
            || !used(o.time_s)
        {
            continue;
        }
        let Some(i) = fix_index(&gnss.time_s, o.time_s) else {
            continue;
        };
        let key = (o.kind, gnss.quality[i]);
        let slot = match classes.iter().position(|(k, _)| *k == key) {
            Some(j) => &mut classes[j].1,
            None => {
                classes.push((key, ClassSamples::default()));
                &mut classes.last_mut().expect("just pushed").1
            }
        };
        let (v, hph) = (o.innovation, o.hph_diag);
        slot.nu2_h.push(0.5 * (v[0] * v[0] + v[1] * v[1]));
        slot.nu2_v.push(v[2] * v[2]);
        slot.hph_h.push(0.5 * (hph[0] + hph[1]));
        slot.hph_v.push(hph[2]);
    }
    classes.sort_by_key(|((kind, q), _)| (*kind != UpdateKind::Position, *q));
    classes
        .into_iter()
        .filter(|(_, s)| s.nu2_h.len() >= MIN_FIXES)
        .map(|((kind, q), s)| ClassFloor {
            quality: q,
            kind,
            fixes: s.nu2_h.len(),
            horizontal: excess_variance(&s.nu2_h, &s.hph_h, std::f64::consts::LN_2).sqrt(),
            vertical: excess_variance(&s.nu2_v, &s.hph_v, CHI2_1_MEDIAN).sqrt(),
            file_sigma: median_file_sigma(gnss, scale, kind, q),
        })
        .collect()
}

/// mean(ν²) − mean(H P Hᵀ), at least 0, with each ν² winsorised at [`CLIP_SIGMA`]² times
/// the robust variance median(ν²)/`median_ratio` (the median of ν²/σ² for Gaussian ν):
/// heavy tails count (they are what a consistent filter must cover), a handful of gross
/// values (a recovery from a fault) cannot set the floor of the whole run.
fn excess_variance(nu2: &[f64], hph: &[f64], median_ratio: f64) -> f64 {
    let n = nu2.len() as f64;
    let robust = median(nu2) / median_ratio;
    let cap = CLIP_SIGMA * CLIP_SIGMA * robust;
    let m_nu2 = nu2.iter().map(|&x| x.min(cap)).sum::<f64>() / n;
    let m_hph = hph.iter().sum::<f64>() / n;
    (m_nu2 - m_hph).max(0.0)
}

/// Median of a sample (upper median for even lengths; NaN when empty).
fn median(x: &[f64]) -> f64 {
    crate::numeric::upper_median(&mut x.to_vec()).unwrap_or(f64::NAN)
}

/// The fixes with each class's floor applied: σ = max(σ_file, floor / k) so that after
/// the filter's quality multiplier k the σ is max(k·σ_file, floor).
pub fn apply(gnss: &GnssFixes, floors: &[ClassFloor], scale: &QualityScale) -> GnssFixes {
    let mut g = gnss.clone();
    for f in floors {
        for i in 0..g.len() {
            if g.quality[i] != f.quality {
                continue;
            }
            let k = scale.factor(f.quality);
            let (h, v) = (f.horizontal / k, f.vertical / k);
            let s = match f.kind {
                UpdateKind::Position => &mut g.sigma_ned_m[i],
                _ => match g.sigma_vel_ned_m_s.as_mut() {
                    Some(sv) => &mut sv[i],
                    None => continue,
                },
            };
            *s = [s[0].max(h), s[1].max(h), s[2].max(v)];
        }
    }
    g
}

/// Index of the fix at time `t` (within 1 µs), if any.
fn fix_index(time_s: &[f64], t: f64) -> Option<usize> {
    let j = time_s.partition_point(|&x| x < t - 1e-6);
    (j < time_s.len() && (time_s[j] - t).abs() <= 1e-6).then_some(j)
}

/// Median σ (horizontal = larger of N/E, vertical) of one class after the quality
/// multiplier.
fn median_file_sigma(g: &GnssFixes, scale: &QualityScale, kind: UpdateKind, q: u8) -> (f64, f64) {
    let k = scale.factor(q);
    let src: &[[f64; 3]] = match kind {
        UpdateKind::Position => &g.sigma_ned_m,
        _ => g.sigma_vel_ned_m_s.as_deref().unwrap_or(&[]),
    };
    let mut h: Vec<f64> = Vec::new();
    let mut v: Vec<f64> = Vec::new();
    for (s, _) in src.iter().zip(&g.quality).filter(|(_, qq)| **qq == q) {
        h.push(s[0].max(s[1]) * k);
        v.push(s[2] * k);
    }
    if h.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    (median(&h), median(&v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::rng::Rng;

    /// Fixes 0..n at 1 Hz, quality `q` for all, file σ 1 cm / 2 cm.
    fn fixes(n: usize, q: u8) -> GnssFixes {
        GnssFixes {
            time_s: (0..n).map(|i| i as f64).collect(),
            lat_rad: vec![0.5; n],
            lon_rad: vec![1.0; n],
            height_m: vec![0.0; n],
            sigma_ned_m: vec![[0.01, 0.01, 0.02]; n],
            quality: vec![q; n],
            ..GnssFixes::default()
        }
    }

    /// Outcomes with Gaussian innovations of σ `s_h` (N, E) and `s_v` (D) and
    /// H P Hᵀ = `hph` on every axis.
    fn outcomes(n: usize, s_h: f64, s_v: f64, hph: f64, seed: u64) -> Vec<UpdateOutcome> {
        let mut rng = Rng::seed_from_u64(seed);
        (0..n)
            .map(|i| UpdateOutcome {
                kind: UpdateKind::Position,
                time_s: i as f64,
                innovation: [s_h * rng.normal(), s_h * rng.normal(), s_v * rng.normal()],
                nis: 0.0,
                accepted: true,
                r_scale: 1.0,
                hph_diag: [hph; 3],
            })
            .collect()
    }

    /// Closed form: with E[ν²] = HPHᵀ + R the estimate is √R, to the sampling error of
    /// 20 000 draws (σ of a variance estimate √(2/n) ≈ 1 %; the horizontal pools two axes).
    #[test]
    fn recovers_the_excess_variance() {
        let n = 20_000;
        let (s_h, s_v, hph) = (0.3f64, 0.2f64, 0.1f64 * 0.1);
        let f = estimate(
            outcomes(n, s_h, s_v, hph, 1),
            &fixes(n, 1),
            &QualityScale::default(),
            |_| true,
        );
        assert_eq!(f.len(), 1);
        let want_h = (s_h * s_h - hph).sqrt();
        let want_v = (s_v * s_v - hph).sqrt();
        assert!(
            (f[0].horizontal / want_h - 1.0).abs() < 0.02,
            "{f:?} vs {want_h}"
        );
        assert!(
            (f[0].vertical / want_v - 1.0).abs() < 0.03,
            "{f:?} vs {want_v}"
        );
        assert_eq!(f[0].fixes, n);
        assert_eq!(f[0].file_sigma, (0.01, 0.02));
        // Innovations fully explained by H P Hᵀ: no floor.
        let f = estimate(
            outcomes(n, 0.1, 0.1, 0.02, 2),
            &fixes(n, 1),
            &QualityScale::default(),
            |_| true,
        );
        assert_eq!((f[0].horizontal, f[0].vertical), (0.0, 0.0));
    }

    /// Rejected fixes, fixes in a convergence period and classes with too few fixes do
    /// not count; a handful of gross innovations is winsorised, not averaged in.
    #[test]
    fn exclusions_and_winsorising() {
        let n = 2_000;
        let mut o = outcomes(n, 0.2, 0.2, 0.0, 3);
        let clean = estimate(o.clone(), &fixes(n, 1), &QualityScale::default(), |_| true);
        // Five 1-km innovations: without the clip the floor would be ≈ 50 m.
        for k in 0..5 {
            o[100 * k].innovation = [1000.0, 1000.0, 1000.0];
        }
        let dirty = estimate(o.clone(), &fixes(n, 1), &QualityScale::default(), |_| true);
        assert!(
            dirty[0].horizontal < 1.2 * clean[0].horizontal,
            "{dirty:?} vs {clean:?}"
        );
        // Rejected and excluded ones are left out entirely.
        for k in 0..5 {
            o[100 * k].accepted = false;
        }
        let f = estimate(o.clone(), &fixes(n, 1), &QualityScale::default(), |_| true);
        assert_eq!(f[0].fixes, n - 5);
        let f = estimate(o.clone(), &fixes(n, 1), &QualityScale::default(), |t| {
            t >= 1000.0
        });
        assert_eq!(f[0].fixes, n - 1000);
        // Too few fixes of a class: no estimate for it.
        let f = estimate(
            o.into_iter().take(MIN_FIXES - 1),
            &fixes(n, 1),
            &QualityScale::default(),
            |_| true,
        );
        assert!(f.is_empty());
    }

    /// The floor is applied per class after the quality multiplier: σ·k ≥ floor, a larger
    /// file σ kept.
    #[test]
    fn applied_per_class_after_the_multiplier() {
        let mut g = fixes(4, 1);
        g.quality[3] = 2;
        g.sigma_ned_m[2] = [0.5, 0.5, 0.5];
        let scale = QualityScale::default();
        let floors = [
            ClassFloor {
                quality: 1,
                kind: UpdateKind::Position,
                fixes: 100,
                horizontal: 0.2,
                vertical: 0.3,
                file_sigma: (0.01, 0.02),
            },
            ClassFloor {
                quality: 2,
                kind: UpdateKind::Position,
                fixes: 100,
                horizontal: 0.6,
                vertical: 0.0,
                file_sigma: (0.03, 0.06),
            },
        ];
        let out = apply(&g, &floors, &scale);
        assert_eq!(out.sigma_ned_m[0], [0.2, 0.2, 0.3]);
        assert_eq!(out.sigma_ned_m[2], [0.5, 0.5, 0.5]);
        // Float: multiplier 3, so σ = 0.6 / 3 = 0.2 in the file's units.
        let k = scale.factor(2);
        assert!((out.sigma_ned_m[3][0] * k - 0.6).abs() < 1e-12);
        assert_eq!(out.sigma_ned_m[3][2], 0.02);
    }
}

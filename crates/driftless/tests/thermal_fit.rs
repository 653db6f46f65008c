//! Thermal polynomial fit: exactness, coverage, order advice,
//! bad input.

use driftless::sim::rng::Rng;
use driftless::thermal::{
    FitOptions, NoiseScale, ThermalFitError, advise_order, cross_validate, fit,
};

/// Soak temperatures of the seed paper (§3.3): −25 … 70 °C in 5 °C steps (20 points).
fn soak_temps() -> Vec<f64> {
    (0..20).map(|i| -25.0 + 5.0 * i as f64).collect()
}

fn poly(c: &[f64], t_ref: f64, t: f64) -> f64 {
    let dt = t - t_ref;
    c.iter().rev().fold(0.0, |acc, &v| acc * dt + v)
}

/// A realistic gyro-bias cubic (deg/s, deg/s/°C^k): ~0.1 °/s drift over the range.
const CUBIC: [f64; 4] = [0.1, 2.0e-3, -3.0e-5, 4.0e-7];
const QUINTIC: [f64; 6] = [0.01, 2.0e-4, -3.0e-6, 4.0e-8, -5.0e-10, 6.0e-12];

fn opts(order: usize) -> FitOptions {
    FitOptions {
        order,
        ..FitOptions::default()
    }
}

fn assert_exact(truth: &[f64], got: &[f64], tol: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for (k, (&c, &g)) in truth.iter().zip(got).enumerate() {
        let rel = ((g - c) / c).abs();
        worst = worst.max(rel);
        assert!(rel <= tol, "c{k}: got {g:e}, truth {c:e}, rel {rel:e}");
    }
    worst
}

#[test]
fn recovers_noise_free_cubic_exactly() {
    let t = soak_temps();
    let y: Vec<f64> = t.iter().map(|&t| poly(&CUBIC, 25.0, t)).collect();
    let f = fit(&t, &y, None, &FitOptions::default()).unwrap();
    let worst = assert_exact(&CUBIC, &f.coeffs, 1e-12);
    eprintln!("cubic: worst relative coefficient error {worst:.2e}");
    assert_eq!(f.order, 3);
    assert_eq!(f.range_c(), (-25.0, 70.0));
    assert_eq!(f.poly.coeffs()[..4], f.coeffs[..]);
    assert!(f.residual_rms < 1e-15);
    // The ThermalPoly and the scaled evaluation agree.
    for &tc in &t {
        assert!((f.poly.eval(tc) - f.eval(tc)).abs() < 1e-15);
    }
    // Weighted with arbitrary σ_i: still exact.
    let s: Vec<f64> = (0..t.len())
        .map(|i| 1e-3 * (1.0 + 0.1 * i as f64))
        .collect();
    let f = fit(&t, &y, Some(&s), &FitOptions::default()).unwrap();
    assert_exact(&CUBIC, &f.coeffs, 1e-12);
    assert!(f.chi2_per_dof.unwrap() < 1e-20);
}

#[test]
fn recovers_noise_free_quintic_exactly() {
    let t = soak_temps();
    let y: Vec<f64> = t.iter().map(|&t| poly(&QUINTIC, 25.0, t)).collect();
    let f = fit(&t, &y, None, &opts(5)).unwrap();
    let worst = assert_exact(&QUINTIC, &f.coeffs, 1e-12);
    eprintln!("quintic: worst relative coefficient error {worst:.2e}");
    // Another reference temperature: the binomial re-expansion is exact too.
    let o = FitOptions {
        order: 5,
        t_ref_c: 0.0,
        ..FitOptions::default()
    };
    let f0 = fit(&t, &y, None, &o).unwrap();
    for &tc in &[-25.0, 0.0, 25.0, 70.0] {
        let want = poly(&QUINTIC, 25.0, tc);
        assert!((f0.poly.eval(tc) - want).abs() <= 1e-13 * want.abs().max(1e-3));
    }
}

#[test]
fn unsorted_and_repeated_temperatures() {
    let t = soak_temps();
    let mut rng = Rng::seed_from_u64(7);
    let y: Vec<f64> = t
        .iter()
        .map(|&t| poly(&CUBIC, 25.0, t) + 0.003 * rng.normal())
        .collect();
    let sorted = fit(&t, &y, None, &FitOptions::default()).unwrap();
    // Reverse order: same fit.
    let tr: Vec<f64> = t.iter().rev().copied().collect();
    let yr: Vec<f64> = y.iter().rev().copied().collect();
    let rev = fit(&tr, &yr, None, &FitOptions::default()).unwrap();
    for k in 0..4 {
        assert!((rev.coeffs[k] - sorted.coeffs[k]).abs() <= 1e-12 * sorted.coeffs[k].abs());
    }
    // Four readings at each of four temperatures: a cubic is determined (16 points,
    // 4 distinct); a quartic is not.
    let tt: Vec<f64> = [-20.0, 0.0, 30.0, 60.0]
        .iter()
        .flat_map(|&t| [t; 4])
        .collect();
    let yy: Vec<f64> = tt.iter().map(|&t| poly(&CUBIC, 25.0, t)).collect();
    let f = fit(&tt, &yy, None, &FitOptions::default()).unwrap();
    assert_eq!((f.n_points, f.n_distinct, f.dof), (16, 4, 12));
    assert_exact(&CUBIC, &f.coeffs, 1e-11);
    assert_eq!(
        fit(&tt, &yy, None, &opts(4)),
        Err(ThermalFitError::TooFewTemperatures {
            distinct: 4,
            order: 4
        })
    );
}

/// Fraction of `hits` over `n`, asserted within 95 % ± 3 %.
fn check_coverage(what: &str, hits: usize, n: usize) -> f64 {
    let f = hits as f64 / n as f64;
    assert!((f - 0.95).abs() <= 0.03, "{what}: coverage {f:.3}");
    f
}

/// `inflate`: the default rule (covariance × χ²/dof when above 1); off, the σ are taken
/// as absolute (the pure known-σ case).
fn coverage_run(given_sigma: bool, inflate: bool) -> (Vec<f64>, f64, f64) {
    const SEEDS: u64 = 1000;
    const SIGMA: f64 = 0.003;
    let t = soak_temps();
    let s = vec![SIGMA; t.len()];
    let mut coef_hits = [0usize; 4];
    let mut band_hits = vec![0usize; t.len()];
    for seed in 0..SEEDS {
        let mut rng = Rng::stream(2024, seed);
        let y: Vec<f64> = t
            .iter()
            .map(|&t| poly(&CUBIC, 25.0, t) + SIGMA * rng.normal())
            .collect();
        let o = FitOptions {
            inflate_by_scatter: inflate,
            ..FitOptions::default()
        };
        let f = fit(&t, &y, given_sigma.then_some(&s[..]), &o).unwrap();
        let chi2_dof = f.chi2_per_dof.unwrap_or(0.0);
        let want = match (given_sigma, inflate && chi2_dof > 1.0) {
            (false, _) => NoiseScale::Estimated,
            (true, false) => NoiseScale::Given,
            (true, true) => NoiseScale::Inflated,
        };
        assert_eq!(f.noise_scale, want);
        if want == NoiseScale::Inflated {
            assert!((f.sigma_scale - chi2_dof.sqrt()).abs() < 1e-12);
        }
        for (k, hits) in coef_hits.iter_mut().enumerate() {
            let (lo, hi) = f.coeff_interval(k, 0.95).unwrap();
            *hits += usize::from(lo <= CUBIC[k] && CUBIC[k] <= hi);
        }
        for (i, &tc) in t.iter().enumerate() {
            let b = f.band(tc, 0.95).unwrap();
            let truth = poly(&CUBIC, 25.0, tc);
            band_hits[i] += usize::from(b.lo <= truth && truth <= b.hi);
        }
    }
    let n = SEEDS as usize;
    let frac = |h: usize| h as f64 / n as f64;
    let pure = !(given_sigma && inflate);
    let coef: Vec<f64> = coef_hits
        .iter()
        .enumerate()
        .map(|(k, &h)| {
            if pure {
                check_coverage(&format!("c{k}"), h, n)
            } else {
                frac(h)
            }
        })
        .collect();
    let band: Vec<f64> = band_hits
        .iter()
        .zip(&t)
        .map(|(&h, tc)| {
            if pure {
                check_coverage(&format!("band at {tc} °C"), h, n)
            } else {
                frac(h)
            }
        })
        .collect();
    let (bmin, bmax) = band
        .iter()
        .fold((1.0f64, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    eprintln!(
        "coverage (σ {}, inflation {inflate}): coefficients {coef:.3?}, band min {bmin:.3} max {bmax:.3}",
        if given_sigma { "given" } else { "estimated" }
    );
    (coef, bmin, bmax)
}

#[test]
fn coverage_with_given_sigma() {
    coverage_run(true, false);
}

#[test]
fn coverage_with_estimated_sigma() {
    coverage_run(false, true);
}

/// With correct σ the default rule inflates only the fits whose χ²/dof exceeds 1 (about
/// half): intervals get slightly conservative, never narrower than the known-σ ones.
#[test]
fn coverage_with_given_sigma_and_scatter_inflation() {
    let (coef, bmin, bmax) = coverage_run(true, true);
    for (k, c) in coef.iter().enumerate() {
        assert!((0.95..=0.99).contains(c), "c{k}: {c}");
    }
    assert!(bmin >= 0.95 && bmax <= 0.99, "band {bmin}–{bmax}");
}

/// σ_i stated 5× too small (the per-bin or per-step σ that ignore the drift between
/// points): taken as absolute, the 95 % band covers the truth far too rarely; with the
/// default scatter inflation it covers it as if σ had been estimated, and the fit reports
/// the ratio.
#[test]
fn understated_sigma_is_inflated_to_the_scatter() {
    const SEEDS: u64 = 400;
    const SIGMA: f64 = 0.003;
    let t = soak_temps();
    let stated = vec![SIGMA / 5.0; t.len()];
    let (mut hits_abs, mut hits_inf, mut n, mut ratio) = (0usize, 0usize, 0usize, 0.0);
    for seed in 0..SEEDS {
        let mut rng = Rng::stream(77, seed);
        let y: Vec<f64> = t
            .iter()
            .map(|&t| poly(&CUBIC, 25.0, t) + SIGMA * rng.normal())
            .collect();
        let abs = fit(
            &t,
            &y,
            Some(&stated),
            &FitOptions {
                inflate_by_scatter: false,
                ..FitOptions::default()
            },
        )
        .unwrap();
        let inf = fit(&t, &y, Some(&stated), &FitOptions::default()).unwrap();
        assert_eq!(inf.noise_scale, NoiseScale::Inflated);
        ratio += inf.scatter_ratio.unwrap();
        for &tc in &t {
            let truth = poly(&CUBIC, 25.0, tc);
            let a = abs.band(tc, 0.95).unwrap();
            let b = inf.band(tc, 0.95).unwrap();
            hits_abs += usize::from(a.lo <= truth && truth <= a.hi);
            hits_inf += usize::from(b.lo <= truth && truth <= b.hi);
            n += 1;
        }
    }
    let (ca, ci) = (hits_abs as f64 / n as f64, hits_inf as f64 / n as f64);
    let mean_ratio = ratio / SEEDS as f64;
    eprintln!(
        "σ stated 5× too small: band coverage {ca:.3} absolute, {ci:.3} inflated; mean ratio {mean_ratio:.2}"
    );
    assert!(ca < 0.5, "{ca}");
    assert!((ci - 0.95).abs() <= 0.03, "{ci}");
    assert!((mean_ratio - 5.0).abs() < 0.5, "{mean_ratio}");
}

/// Leave-one-temperature-out: held-out points fall in their 95 % prediction band at the
/// nominal rate — independent points with σ given or estimated, and points sharing a
/// drift (a random walk over the visiting order) whose full covariance is given, where
/// the correlation of the held-out point with the kept ones is part of the band.
#[test]
fn held_out_points_fall_in_their_prediction_band() {
    use driftless::thermal::held_out;
    const SEEDS: u64 = 300;
    const SIGMA: f64 = 0.003;
    let t = soak_temps();
    let n = t.len();
    // Random walk of step q per visit, visits in the order k·7 mod n.
    let q = 0.002;
    let order: Vec<usize> = (0..n).map(|k| (k * 7) % n).collect();
    let mut visit = vec![0usize; n];
    for (k, &i) in order.iter().enumerate() {
        visit[i] = k + 1;
    }
    let mut cov = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            cov[i * n + j] = q * q * visit[i].min(visit[j]) as f64;
        }
        cov[i * n + i] += SIGMA * SIGMA;
    }
    let s = vec![SIGMA; n];
    let (mut given, mut est, mut corr, mut corr_naive, mut total) = (0, 0, 0, 0, 0);
    for seed in 0..SEEDS {
        let mut rng = Rng::stream(99, seed);
        let white: Vec<f64> = t
            .iter()
            .map(|&tc| poly(&CUBIC, 25.0, tc) + SIGMA * rng.normal())
            .collect();
        let mut walk = vec![0.0; n];
        let mut w = 0.0;
        for &i in &order {
            w += q * rng.normal();
            walk[i] = w;
        }
        let drifted: Vec<f64> = white.iter().zip(&walk).map(|(a, b)| a + b).collect();
        let absolute = FitOptions {
            inflate_by_scatter: false,
            ..FitOptions::default()
        };
        let count = |h: &driftless::thermal::HeldOut| h.inside.iter().filter(|&&b| b).count();
        given += count(&held_out(&t, &white, Some(&s), None, &absolute, 0.95).unwrap());
        est += count(&held_out(&t, &white, None, None, &FitOptions::default(), 0.95).unwrap());
        corr += count(&held_out(&t, &drifted, None, Some(&cov), &absolute, 0.95).unwrap());
        // The same drifted points with their diagonal only: the drift is unmodelled.
        let diag: Vec<f64> = (0..n).map(|i| cov[i * n + i].sqrt()).collect();
        corr_naive += count(&held_out(&t, &drifted, Some(&diag), None, &absolute, 0.95).unwrap());
        total += n;
    }
    let f = |h: usize| h as f64 / total as f64;
    eprintln!(
        "held-out coverage: σ given {:.3}, estimated {:.3}, drift covariance {:.3}, drift as diagonal {:.3}",
        f(given),
        f(est),
        f(corr),
        f(corr_naive)
    );
    for (what, c) in [
        ("given", f(given)),
        ("estimated", f(est)),
        ("drift", f(corr)),
    ] {
        assert!((c - 0.95).abs() <= 0.02, "{what}: {c}");
    }
    let e = held_out(
        &t,
        &t,
        None,
        None,
        &FitOptions {
            order: 5,
            ..FitOptions::default()
        },
        1.5,
    );
    assert!(e.is_err());
}

#[test]
fn order_advice_picks_cubic() {
    const SEEDS: u64 = 500;
    let t = soak_temps();
    let mut picks = [0usize; 6];
    let mut picks_given = [0usize; 6];
    let mut picks_min_bic = [0usize; 6];
    let s = vec![0.003; t.len()];
    for seed in 0..SEEDS {
        let mut rng = Rng::stream(99, seed);
        let y: Vec<f64> = t
            .iter()
            .map(|&t| poly(&CUBIC, 25.0, t) + 0.003 * rng.normal())
            .collect();
        let adv = advise_order(&t, &y, None, 25.0).unwrap();
        assert_eq!(adv.rows.len(), 5);
        picks[adv.recommended] += 1;
        picks_min_bic[adv.min_bic] += 1;
        let adv = advise_order(&t, &y, Some(&s), 25.0).unwrap();
        picks_given[adv.recommended] += 1;
    }
    let frac = picks[3] as f64 / SEEDS as f64;
    let frac_given = picks_given[3] as f64 / SEEDS as f64;
    eprintln!(
        "order advice picks by order 0..5: σ estimated {picks:?} ({frac:.3} cubic), σ given {picks_given:?} ({frac_given:.3} cubic); plain min-BIC (σ estimated) {picks_min_bic:?}"
    );
    assert!(frac >= 0.85, "cubic chosen in only {frac}");
    assert!(frac_given >= 0.9, "cubic chosen in only {frac_given}");
}

#[test]
fn cross_validation_separates_orders() {
    let t = soak_temps();
    let mut rng = Rng::seed_from_u64(3);
    let y: Vec<f64> = t
        .iter()
        .map(|&t| poly(&CUBIC, 25.0, t) + 0.003 * rng.normal())
        .collect();
    let adv = advise_order(&t, &y, None, 25.0).unwrap();
    for r in &adv.rows {
        eprintln!(
            "p={} rms={:.2e} aic={:.1} aicc={:.1} bic={:.1} cv={:.2e}",
            r.order, r.residual_rms, r.aic, r.aicc, r.bic, r.cv_rms
        );
    }
    // Under-fitting shows in the CV error; at the right order CV ≈ noise level.
    assert!(adv.rows[0].cv_rms > 5.0 * adv.rows[2].cv_rms);
    assert!(adv.rows[2].cv_rms < 0.006);
    let cv = cross_validate(&t, &y, None, &FitOptions::default()).unwrap();
    assert_eq!(cv.residuals.len(), t.len());
    assert_eq!(cv.rms, adv.rows[2].cv_rms);
}

#[test]
fn bad_input_is_rejected() {
    let t = soak_temps();
    let y: Vec<f64> = t.iter().map(|&t| poly(&CUBIC, 25.0, t)).collect();
    let d = FitOptions::default();
    // Too few distinct temperatures for the order.
    assert_eq!(
        fit(&t[..3], &y[..3], None, &d),
        Err(ThermalFitError::TooFewTemperatures {
            distinct: 3,
            order: 3
        })
    );
    // Exactly order + 1 points: fine with σ given, no residual dof without.
    let s = vec![1e-3; t.len()];
    assert!(fit(&t[..4], &y[..4], Some(&s[..4]), &d).is_ok());
    assert_eq!(
        fit(&t[..4], &y[..4], None, &d),
        Err(ThermalFitError::NoResidualDof {
            points: 4,
            order: 3
        })
    );
    // NaN temperature / value.
    let mut tn = t.clone();
    tn[5] = f64::NAN;
    assert_eq!(
        fit(&tn, &y, None, &d),
        Err(ThermalFitError::NonFiniteTemperature(5))
    );
    let mut yn = y.clone();
    yn[2] = f64::INFINITY;
    assert_eq!(
        fit(&t, &yn, None, &d),
        Err(ThermalFitError::NonFiniteValue(2))
    );
    // Mismatched lengths.
    assert!(matches!(
        fit(&t, &y[..10], None, &d),
        Err(ThermalFitError::LengthMismatch { what: "values", .. })
    ));
    assert!(matches!(
        fit(&t, &y, Some(&s[..3]), &d),
        Err(ThermalFitError::LengthMismatch {
            what: "standard errors",
            ..
        })
    ));
    // σ ≤ 0 or NaN.
    let mut sb = s.clone();
    sb[4] = 0.0;
    assert_eq!(
        fit(&t, &y, Some(&sb), &d),
        Err(ThermalFitError::BadSigma(4))
    );
    sb[4] = -1.0;
    assert_eq!(
        fit(&t, &y, Some(&sb), &d),
        Err(ThermalFitError::BadSigma(4))
    );
    sb[4] = f64::NAN;
    assert_eq!(
        fit(&t, &y, Some(&sb), &d),
        Err(ThermalFitError::BadSigma(4))
    );
    // Order out of range; bad reference; bad level.
    assert_eq!(
        fit(&t, &y, None, &opts(0)),
        Err(ThermalFitError::BadOrder(0))
    );
    assert_eq!(
        fit(&t, &y, None, &opts(6)),
        Err(ThermalFitError::BadOrder(6))
    );
    let nr = FitOptions {
        t_ref_c: f64::NAN,
        ..d
    };
    assert_eq!(
        fit(&t, &y, None, &nr),
        Err(ThermalFitError::NonFiniteReference)
    );
    let f = fit(&t, &y, None, &d).unwrap();
    assert_eq!(f.band(0.0, 1.5), Err(ThermalFitError::BadLevel(1.5)));
    assert!(f.coeff_interval(4, 0.95).is_err());
    // Empty input; CV and advice need spare temperatures.
    assert!(fit(&[], &[], None, &d).is_err());
    assert!(cross_validate(&t[..4], &y[..4], Some(&s[..4]), &d).is_err());
    assert!(advise_order(&t[..2], &y[..2], None, 25.0).is_err());
    // Errors render.
    let msg = fit(&t[..3], &y[..3], None, &d).unwrap_err().to_string();
    assert!(msg.contains("3 distinct"), "{msg}");
}

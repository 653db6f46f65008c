//! Acceptance test: simulate 18-h 100-Hz gyro channels with known noise terms, analyse
//! them with overlapping ADEV on a ~100-point log grid, fit the IEEE 952 model with
//! Greenhall EDF weights, and check the recovered terms and their confidence intervals.
//!
//! Run in release (`cargo test --release`); the figures are printed with `--nocapture`.

use std::sync::OnceLock;

use driftless::allan::Estimator;
use driftless::allan::ci;
use driftless::allan::estimators::oadev;
use driftless::allan::fit::{FitConfig, NoiseFit, TermKind, fit_noise_with_edf, slope_readings};
use driftless::allan::phase::frequency_to_phase;
use driftless::allan::taus::{TauSpec, averaging_factors};
use driftless::sim::noise::{StaticNoiseConfig, generate};
use driftless_model::units::{DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H};
use rayon::prelude::*;

const FS: f64 = 100.0;
const HOURS_18: f64 = 18.0 * 3600.0;
const CONFIDENCE: f64 = 0.683;

/// Truth: N = 0.15 deg/√h, B = 3 deg/h, K = 12 deg/h/√h (a consumer-grade MEMS gyro).
/// White noise dominates below ~20 s, the flicker floor from ~20 s to ~250 s, rate
/// random walk above (to 16 200 s, the longest OADEV tau of an 18-h log).
fn truth() -> (f64, f64, f64) {
    (
        0.15 * DEG_PER_SQRT_H,
        3.0 * DEG_PER_H,
        12.0 * DEG_PER_H_PER_SQRT_H,
    )
}

fn sim_cfg(n: f64, b: f64, k: f64, duration: f64) -> StaticNoiseConfig {
    StaticNoiseConfig {
        sample_rate_hz: FS,
        duration_s: duration,
        white: n,
        bias_instability: b,
        rate_random_walk: k,
        turn_on_bias: 0.01,
        ..Default::default()
    }
}

fn fit_cfg(b: bool, k: bool) -> FitConfig {
    FitConfig {
        quantization: false,
        white: true,
        bias_instability: b,
        rate_random_walk: k,
        rate_ramp: false,
        gauss_markov: false,
    }
}

/// The analysis chain a user runs: phase → OADEV on `log:100` → EDF-weighted fit.
fn analyse(y: &[f64], cfg: &FitConfig) -> (NoiseFit, Vec<f64>, Vec<f64>) {
    let dt = 1.0 / FS;
    let x = frequency_to_phase(y, dt);
    let n_phase = x.len();
    let ms =
        averaging_factors(&TauSpec::Log(100), dt, n_phase, Estimator::Oadev).expect("tau grid");
    let pts = oadev(&x, dt, &ms);
    let tau: Vec<f64> = pts.iter().map(|p| p.tau).collect();
    let avar: Vec<f64> = pts.iter().map(|p| p.dev * p.dev).collect();
    let m: Vec<usize> = pts.iter().map(|p| p.m).collect();
    let fit = fit_noise_with_edf(
        &tau,
        &avar,
        |i, alpha| ci::edf(Estimator::Oadev, alpha, m[i], n_phase),
        cfg,
        CONFIDENCE,
    )
    .expect("fit");
    let adev = avar.iter().map(|v| v.sqrt()).collect();
    (fit, tau, adev)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn rel_err(fit: &NoiseFit, kind: TermKind, truth: f64) -> f64 {
    let v = fit.term(kind).map(|t| t.value).unwrap_or(0.0);
    (v / truth - 1.0).abs()
}

struct SeedResult {
    fit: NoiseFit,
    /// Same data, every linear term (Q, N, B, K, R) switched on.
    fit_all: NoiseFit,
    slope_n: Option<f64>,
    slope_b: Option<f64>,
    slope_k: Option<f64>,
}

/// The main Monte Carlo (N, B, K all present, all fitted), shared by two tests.
fn main_run() -> &'static Vec<SeedResult> {
    static RUN: OnceLock<Vec<SeedResult>> = OnceLock::new();
    RUN.get_or_init(|| {
        let (n, b, k) = truth();
        let t0 = std::time::Instant::now();
        let r: Vec<SeedResult> = (0..12u64)
            .into_par_iter()
            .map(|seed| {
                let y = generate(&sim_cfg(n, b, k, HOURS_18), 1000 + seed).expect("sim");
                let (fit, tau, adev) = analyse(&y, &fit_cfg(true, true));
                let (fit_all, _, _) = analyse(&y, &FitConfig::IEEE_952);
                let s = slope_readings(&tau, &adev);
                SeedResult {
                    fit,
                    fit_all,
                    slope_n: s.white,
                    slope_b: s.bias_instability,
                    slope_k: s.rate_random_walk,
                }
            })
            .collect();
        eprintln!(
            "main run: 12 seeds x 18 h in {:.1} s",
            t0.elapsed().as_secs_f64()
        );
        r
    })
}

#[test]
fn recovers_white_bias_instability_and_rate_random_walk() {
    let (n, b, k) = truth();
    let run = main_run();
    let en = median(
        run.iter()
            .map(|r| rel_err(&r.fit, TermKind::White, n))
            .collect(),
    );
    let eb = median(
        run.iter()
            .map(|r| rel_err(&r.fit, TermKind::BiasInstability, b))
            .collect(),
    );
    let ek = median(
        run.iter()
            .map(|r| rel_err(&r.fit, TermKind::RateRandomWalk, k))
            .collect(),
    );
    let rel = |v: Option<f64>, t: f64| v.map(|v| (v / t - 1.0).abs()).unwrap_or(1.0);
    let sn = median(run.iter().map(|r| rel(r.slope_n, n)).collect());
    let sb = median(run.iter().map(|r| rel(r.slope_b, b)).collect());
    let sk = median(run.iter().map(|r| rel(r.slope_k, k)).collect());
    eprintln!(
        "fit   median |rel err|: N {:.2} %  B {:.2} %  K {:.2} %",
        100.0 * en,
        100.0 * eb,
        100.0 * ek
    );
    eprintln!(
        "slope median |rel err|: N {:.2} %  B {:.2} %  K {:.2} %",
        100.0 * sn,
        100.0 * sb,
        100.0 * sk
    );
    let med =
        |kind: TermKind, t: f64| median(run.iter().map(|r| rel_err(&r.fit_all, kind, t)).collect());
    let (an, ab, ak) = (
        med(TermKind::White, n),
        med(TermKind::BiasInstability, b),
        med(TermKind::RateRandomWalk, k),
    );
    let q_found = run
        .iter()
        .filter(|r| r.fit_all.quantization.is_some())
        .count();
    let r_found = run.iter().filter(|r| r.fit_all.rate_ramp.is_some()).count();
    eprintln!(
        "all five terms fitted: N {:.2} %  B {:.2} %  K {:.2} %; Q fitted in {q_found}/12, R in {r_found}/12",
        100.0 * an,
        100.0 * ab,
        100.0 * ak
    );
    assert!(an < 0.02, "N median error (all terms) {an}");
    assert!(ab < 0.15, "B median error (all terms) {ab}");
    assert!(ak < 0.25, "K median error (all terms) {ak}");
    for r in run {
        assert!(r.fit.rms_log10_residual < 0.3, "{:?}", r.fit);
    }
    assert!(en < 0.02, "N median error {en}");
    assert!(eb < 0.15, "B median error {eb}");
    assert!(ek < 0.10, "K median error {ek}");
}

#[test]
fn confidence_intervals_cover_truth() {
    // Pool the 12 long seeds with 48 short (2 h) ones, where the long-tau points are
    // fewer and the intervals wider, to estimate the coverage of the 68.3 % intervals.
    let (n, b, k) = truth();
    let mut fits: Vec<NoiseFit> = main_run().iter().map(|r| r.fit.clone()).collect();
    let short: Vec<NoiseFit> = (0..48u64)
        .into_par_iter()
        .map(|seed| {
            let y = generate(&sim_cfg(n, b, k, 2.0 * 3600.0), 5000 + seed).expect("sim");
            analyse(&y, &fit_cfg(true, true)).0
        })
        .collect();
    fits.extend(short);
    let mut report = String::new();
    let mut total = (0usize, 0usize);
    for (kind, t) in [
        (TermKind::White, n),
        (TermKind::BiasInstability, b),
        (TermKind::RateRandomWalk, k),
    ] {
        let covered = fits
            .iter()
            .filter(|f| {
                f.term(kind).is_some_and(|x| x.covers(t))
                    || (f.term(kind).is_none()
                        && f.not_detected
                            .iter()
                            .any(|u| u.term == kind && u.upper >= t))
            })
            .count();
        report += &format!("{}: {}/{}  ", kind.name(), covered, fits.len());
        total.0 += covered;
        total.1 += fits.len();
        let frac = covered as f64 / fits.len() as f64;
        // Nominal 0.683; 60 trials → binomial sd ≈ 0.06. Accept 0.45 … 0.95 per term.
        assert!(
            frac > 0.45 && frac < 0.95,
            "{}: coverage {frac}",
            kind.name()
        );
    }
    let frac = total.0 as f64 / total.1 as f64;
    eprintln!("coverage of {CONFIDENCE} intervals: {report} pooled {frac:.3}");
    assert!(frac > 0.55 && frac < 0.85, "pooled coverage {frac}");
}

#[test]
fn white_and_rrw_only_with_bias_switched_off() {
    let (n, _, k) = truth();
    let fits: Vec<NoiseFit> = (0..10u64)
        .into_par_iter()
        .map(|seed| {
            let y = generate(&sim_cfg(n, 0.0, k, HOURS_18), 2000 + seed).expect("sim");
            analyse(&y, &fit_cfg(false, true)).0
        })
        .collect();
    let en = median(
        fits.iter()
            .map(|f| rel_err(f, TermKind::White, n))
            .collect(),
    );
    let ek = median(
        fits.iter()
            .map(|f| rel_err(f, TermKind::RateRandomWalk, k))
            .collect(),
    );
    eprintln!(
        "N+K data, B off: median |rel err| N {:.2} %  K {:.2} %",
        100.0 * en,
        100.0 * ek
    );
    assert!(en < 0.02, "N median error {en}");
    assert!(ek < 0.10, "K median error {ek}");
    for f in &fits {
        assert!(f.bias_instability.is_none());
    }
}

#[test]
fn absent_rate_random_walk_is_not_detected_or_tiny() {
    let (n, b, k_ref) = truth();
    let fits: Vec<NoiseFit> = (0..10u64)
        .into_par_iter()
        .map(|seed| {
            let y = generate(&sim_cfg(n, b, 0.0, HOURS_18), 3000 + seed).expect("sim");
            analyse(&y, &fit_cfg(true, true)).0
        })
        .collect();
    let en = median(
        fits.iter()
            .map(|f| rel_err(f, TermKind::White, n))
            .collect(),
    );
    let eb = median(
        fits.iter()
            .map(|f| rel_err(f, TermKind::BiasInstability, b))
            .collect(),
    );
    let mut n_not_detected = 0;
    let mut n_consistent_zero = 0;
    let mut k_max = 0.0f64;
    for f in &fits {
        match f.rate_random_walk {
            None => {
                n_not_detected += 1;
                assert!(
                    f.not_detected
                        .iter()
                        .any(|u| u.term == TermKind::RateRandomWalk),
                    "{f:?}"
                );
            }
            Some(t) => {
                eprintln!(
                    "  K without K: {:.2} [{:.2}, {:.2}] deg/h/sqrt(h)",
                    t.value / DEG_PER_H_PER_SQRT_H,
                    t.lo / DEG_PER_H_PER_SQRT_H,
                    t.hi / DEG_PER_H_PER_SQRT_H
                );
                k_max = k_max.max(t.value);
                // A fitted K must be small next to the K the main test recovers (its
                // contribution to the Allan variance ≤ 1/8 of K_ref's).
                assert!(
                    t.value < 0.35 * k_ref,
                    "K = {} deg/h/√h",
                    t.value / DEG_PER_H_PER_SQRT_H
                );
                if t.lo == 0.0 {
                    n_consistent_zero += 1;
                }
            }
        }
    }
    eprintln!(
        "N+B data, K on: N {:.2} %  B {:.2} %  K not detected in {n_not_detected}/10, interval reaching 0 in {n_consistent_zero} more, largest K {:.3} deg/h/sqrt(h)",
        100.0 * en,
        100.0 * eb,
        k_max / DEG_PER_H_PER_SQRT_H
    );
    assert!(en < 0.02, "N median error {en}");
    assert!(eb < 0.15, "B median error {eb}");
    assert!(
        n_not_detected + n_consistent_zero >= 5,
        "K reported significant in {} of 10 seeds without K",
        10 - n_not_detected - n_consistent_zero
    );
}

//! The Allan noise fit on the real ADIS16405 static runs, default options: the automatic
//! fit range leaves out the short τ the sensor's filtering colours, the model follows the
//! curve (χ²_red, and within ±10 % at every τ of the range, which ends where the curve
//! is known to 10 %), reads the white noise off the curve, keeps only physically possible
//! terms, and a model fitted on one run predicts the other run's curve over 0.2–30 s and
//! covers it with its intervals beyond.

use driftless::allan::analysis::{AnalysisConfig, ChannelResult, analyse};
use driftless::allan::checks::resolution_step;
use driftless::allan::fit::{CHI2_RED_WARN, FitConfig, NoiseFit, RangeSource, TermKind};
use driftless::allan::noise_model::{ModelOptions, NoiseModel};
use driftless::allan::taus::TauSpec;
use driftless::io::{ImuLog, Quantity, TextOptions, read_log_file};
use std::path::PathBuf;

fn data() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

fn read_run(run: u32) -> ImuLog {
    let path = data().join(format!(
        "static/adis16405_calgary/adis16405_run{run}.csv.gz"
    ));
    read_log_file(&path, &TextOptions::default()).expect("read run")
}

/// The gyro curves (OADEV, log:100 as `driftless allan` by default) and their model.
fn gyro_model(log: &ImuLog) -> (Vec<ChannelResult>, NoiseModel) {
    let cfg = AnalysisConfig {
        taus: TauSpec::Log(100),
        ..AnalysisConfig::default()
    };
    let gyros: Vec<_> = log
        .channels
        .iter()
        .filter(|c| c.quantity == Quantity::AngularRate)
        .collect();
    let curves: Vec<ChannelResult> = gyros
        .iter()
        .map(|c| analyse(&c.name, &c.values, log.tau0_s, &cfg).expect("oadev"))
        .collect();
    let opts = ModelOptions {
        resolution: gyros.iter().map(|c| resolution_step(&c.values)).collect(),
        ..ModelOptions::default()
    };
    let q = vec![Quantity::AngularRate; curves.len()];
    let model = NoiseModel::from_curves_with(
        &log.source,
        &curves,
        &q,
        &FitConfig::default(),
        0.683,
        &opts,
    )
    .expect("model");
    (curves, model)
}

/// σ(τ) of a curve at `t` by log-log interpolation.
fn dev_at(c: &ChannelResult, t: f64) -> f64 {
    let p = &c.points;
    let i = p.iter().position(|q| q.tau >= t).expect("tau inside");
    if i == 0 || (p[i].tau - t).abs() < 1e-12 {
        return p[i].dev;
    }
    let (a, b) = (&p[i - 1], &p[i]);
    let u = (t / a.tau).ln() / (b.tau / a.tau).ln();
    (a.dev.ln() + u * (b.dev / a.dev).ln()).exp()
}

fn worst_departure(fit: &NoiseFit, c: &ChannelResult, lo: f64, hi: f64) -> f64 {
    c.points
        .iter()
        .filter(|p| p.tau >= lo * (1.0 - 1e-9) && p.tau <= hi * (1.0 + 1e-9))
        .map(|p| (fit.model_avar(p.tau).sqrt() / p.dev - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
#[ignore = "needs shared data"]
fn adis16405_gyro_fit_over_the_automatic_range() {
    let runs = [read_run(2), read_run(3)];
    let fitted: Vec<_> = runs.iter().map(gyro_model).collect();
    for (run, (curves, model)) in [2, 3].iter().zip(&fitted) {
        for (c, ch) in curves.iter().zip(&model.channels) {
            let f = &ch.fit;
            let r = f.fit_range.expect("range reported");
            let n = f.white.expect("white noise").value;
            let read = dev_at(c, 1.0);
            let in_range = worst_departure(f, c, r.tau_min_s, r.tau_max_s);
            eprintln!(
                "run {run} {}: range {:.3}..{:.0} s ({:?}, {} short points out), chi2_red {:.3}, \
                 N/σ(1 s) − 1 = {:+.2} %, worst model/curve − 1 in range {:.1} %, \
                 GM {:?}, K {:?}, not detected {:?}, not identifiable {:?}",
                c.name,
                r.tau_min_s,
                r.tau_max_s,
                r.source,
                r.excluded_short,
                f.chi2_reduced,
                100.0 * (n / read - 1.0),
                100.0 * in_range,
                f.gauss_markov.map(|g| g.tau_c_s.value),
                f.rate_random_walk.map(|k| k.value),
                f.not_detected.iter().map(|u| u.term).collect::<Vec<_>>(),
                f.not_identifiable
                    .iter()
                    .map(|u| u.term)
                    .collect::<Vec<_>>(),
            );
            // The model follows the curve within ±10 % at every τ of the range.
            assert!(in_range <= 0.10, "{}: {in_range}", c.name);
            // The filtered short τ are found and left out.
            assert_eq!(r.source, RangeSource::Auto, "{}", c.name);
            assert!(r.tau_min_s > 0.01 && r.tau_min_s <= 0.5, "{r:?}");
            assert!(
                f.chi2_reduced <= CHI2_RED_WARN,
                "{}: {}",
                c.name,
                f.chi2_reduced
            );
            assert!(
                (n / read - 1.0).abs() <= 0.05,
                "{}: N {n} vs {read}",
                c.name
            );
            // K found, or reported as an upper bound.
            assert!(
                f.rate_random_walk.is_some_and(|k| k.lo > 0.0)
                    || f.not_detected
                        .iter()
                        .any(|u| u.term == TermKind::RateRandomWalk && u.upper > 0.0),
                "{}: {f:?}",
                c.name
            );
            // No term with an impossible correlation time: within 5 samples … T/10.
            let record = c.segment_phase_points[0] as f64 * c.tau0_s;
            if let Some(g) = f.gauss_markov {
                assert!(g.tau_c_s.value >= 5.0 * c.tau0_s && g.tau_c_s.value <= 0.1 * record);
            }
            if let Some(gm) = ch.discrete.bias_instability_gm {
                assert!(gm.tau_c_s <= record, "{}: {gm:?}", c.name);
            }
            // Every saved term is resolved from zero.
            for k in [
                TermKind::Quantization,
                TermKind::White,
                TermKind::BiasInstability,
                TermKind::RateRandomWalk,
                TermKind::RateRamp,
            ] {
                if let Some(t) = f.term(k) {
                    assert!(t.lo > 0.0, "{}: {k:?} {t:?}", c.name);
                }
            }
        }
    }
    // A model fitted on one run predicts the other run's curve over 0.2–30 s.
    let (mut band_covered, mut band_points) = (0usize, 0usize);
    for (a, b) in [(0usize, 1usize), (1, 0)] {
        let (_, model) = &fitted[a];
        let (curves, _) = &fitted[b];
        for (c, ch) in curves.iter().zip(&model.channels) {
            let worst = worst_departure(&ch.fit, c, 0.2, 30.0);
            eprintln!(
                "run {} model on run {} {}: worst departure over 0.2–30 s {:.1} %",
                a + 2,
                b + 2,
                c.name,
                100.0 * worst
            );
            assert!(worst <= 0.15, "{}: {worst}", c.name);
            // Beyond 30 s the runs differ; the model's stated intervals should cover the
            // other run's curve there (to the end of the curve, within the curve's own
            // interval).
            let long: Vec<_> = c
                .points
                .iter()
                .enumerate()
                .filter(|(_, p)| p.tau > 30.0)
                .collect();
            let covered = long
                .iter()
                .filter(|(i, p)| {
                    let (lo, hi) = ch.fit.model_avar_band(p.tau);
                    c.dev_hi[*i] >= lo.sqrt() && c.dev_lo[*i] <= hi.sqrt()
                })
                .count();
            eprintln!(
                "    and its intervals cover the other run's curve beyond 30 s at {covered}/{} points",
                long.len()
            );
            band_covered += covered;
            band_points += long.len();
        }
    }
    // In-sample figure (two runs): 197 of 216 points; one pair differs for real (run 2's
    // gyro x rises with a rate random walk, run 3's falls).
    let frac = band_covered as f64 / band_points as f64;
    eprintln!("intervals cover the other run beyond 30 s at {band_covered}/{band_points} points");
    assert!(frac >= 0.85, "{band_covered}/{band_points}");
}

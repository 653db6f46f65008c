//! Replicate logs of one sensor: simulated pairs of runs of one truth (the homogeneity
//! test's false-alarm rate, the joint model's white noise), pairs whose bias instability
//! differs by 2× (the test's power), and the two real ADIS16405 static runs.
//!
//! Run in release (`cargo test --release`); the figures are printed with `--nocapture`.

use std::path::PathBuf;

use driftless::allan::analysis::{AnalysisConfig, ChannelResult, analyse};
use driftless::allan::checks::resolution_step;
use driftless::allan::fit::{FitConfig, TermKind};
use driftless::allan::noise_model::{ModelOptions, NoiseModel};
use driftless::allan::replicates::{
    DEFAULT_LEVEL, ReplicateError, ReplicateOptions, ReplicateRun, Replicates, RunEstimate,
    compare_replicates,
};
use driftless::allan::taus::TauSpec;
use driftless::io::{ImuLog, Quantity, TextOptions, read_log_file};
use driftless::sim::noise::{StaticNoiseConfig, generate};
use driftless_model::units::{DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H};
use rayon::prelude::*;

const FS: f64 = 100.0;
const HOURS_2: f64 = 2.0 * 3600.0;
const SEEDS: u64 = 20;

/// Truth: N = 0.15 deg/√h, B = 3 deg/h, K = 12 deg/h/√h (a consumer-grade MEMS gyro).
fn sim(b_scale: f64, seed: u64) -> Vec<f64> {
    let cfg = StaticNoiseConfig {
        sample_rate_hz: FS,
        duration_s: HOURS_2,
        white: 0.15 * DEG_PER_SQRT_H,
        bias_instability: 3.0 * b_scale * DEG_PER_H,
        rate_random_walk: 12.0 * DEG_PER_H_PER_SQRT_H,
        turn_on_bias: 0.01,
        ..Default::default()
    };
    generate(&cfg, seed).expect("simulate")
}

/// What `driftless allan --terms q,n,b,k,r` does per run: OADEV on `log:100`, the IEEE
/// 952 terms the simulated sensor carries, the automatic fit range. (With the default
/// terms a Gauss-Markov term is sometimes kept on these 2-h runs of IEEE terms alone,
/// which is a question of term selection, not of the replicate statistics tested here.)
fn fit_run(name: &str, y: &[f64]) -> (Vec<ChannelResult>, NoiseModel) {
    let cfg = AnalysisConfig {
        taus: TauSpec::Log(100),
        ..AnalysisConfig::default()
    };
    let curves = vec![analyse("gyro_x", y, 1.0 / FS, &cfg).expect("oadev")];
    let model = NoiseModel::from_curves_with(
        name,
        &curves,
        &[Quantity::AngularRate],
        &FitConfig::IEEE_952,
        cfg.confidence,
        &ModelOptions::default(),
    )
    .expect("fit");
    (curves, model)
}

fn compare(
    a: &(Vec<ChannelResult>, NoiseModel),
    b: &(Vec<ChannelResult>, NoiseModel),
) -> Replicates {
    let runs = [
        ReplicateRun {
            source: "run_a",
            curves: &a.0,
            model: &a.1,
            resolution: &[],
        },
        ReplicateRun {
            source: "run_b",
            curves: &b.0,
            model: &b.1,
            resolution: &[],
        },
    ];
    let opts = ReplicateOptions {
        fit: FitConfig::IEEE_952,
        ..ReplicateOptions::default()
    };
    compare_replicates(&runs, &opts).expect("compare")
}

struct Outcome {
    /// Per term (N, B, K): Some(disagree) when tested.
    flags: [Option<bool>; 3],
    /// |N − truth| of run a, run b and the joint model.
    white_err: [f64; 3],
    /// Per term (N, B, K): the test's p-value when tested.
    p: [Option<f64>; 3],
}

const TESTED: [TermKind; 3] = [
    TermKind::White,
    TermKind::BiasInstability,
    TermKind::RateRandomWalk,
];

fn outcome(r: &Replicates) -> Outcome {
    let c = &r.channels[0];
    let flags = TESTED.map(|k| {
        c.terms
            .iter()
            .find(|t| t.term == k)
            .and_then(|t| t.consistent)
            .map(|ok| !ok)
    });
    let n_true = 0.15 * DEG_PER_SQRT_H;
    let white = c.terms.iter().find(|t| t.term == TermKind::White);
    let run_n = |i: usize| match white.map(|t| t.runs[i]) {
        Some(RunEstimate::Value(t)) => (t.value - n_true).abs(),
        _ => f64::INFINITY,
    };
    let joint = r.joint.channels[0]
        .fit
        .white
        .map_or(f64::INFINITY, |t| (t.value - n_true).abs());
    let p = TESTED.map(|k| {
        c.terms
            .iter()
            .find(|t| t.term == k)
            .and_then(|t| t.test)
            .map(|m| m.p_value)
    });
    Outcome {
        flags,
        p,
        white_err: [run_n(0), run_n(1), joint],
    }
}

fn rates(outs: &[Outcome]) -> [(usize, usize); 3] {
    let mut r = [(0, 0); 3];
    for o in outs {
        for (k, f) in o.flags.iter().enumerate() {
            if let Some(d) = f {
                r[k].1 += 1;
                if *d {
                    r[k].0 += 1;
                }
            }
        }
    }
    r
}

/// Replicates of one truth: the test rarely says the runs disagree (level 0.01), and the
/// joint model's N is closer to the truth than the worse of the two runs in most seeds.
/// Pairs whose B differs by 2×: the test flags B in most seeds.
#[test]
fn replicate_test_false_alarms_and_power() {
    let start = std::time::Instant::now();
    let same: Vec<Outcome> = (0..SEEDS)
        .into_par_iter()
        .map(|s| {
            let a = fit_run("a", &sim(1.0, 1000 + 2 * s));
            let b = fit_run("b", &sim(1.0, 1001 + 2 * s));
            outcome(&compare(&a, &b))
        })
        .collect();
    let differ: Vec<Outcome> = (0..SEEDS)
        .into_par_iter()
        .map(|s| {
            let a = fit_run("a", &sim(1.0, 5000 + 2 * s));
            let b = fit_run("b", &sim(2.0, 5001 + 2 * s));
            let r = compare(&a, &b);
            // Where the runs disagree the joint interval holds the pooled one.
            for t in &r.channels[0].terms {
                if let (Some(false), Some(p), Some(j)) = (t.consistent, t.pooled, t.joint) {
                    assert!(j.lo <= p.lo && j.hi >= p.hi, "{t:?}");
                    assert!(j.lo <= j.value && j.value <= j.hi, "{t:?}");
                }
            }
            assert!(
                r.warnings().len()
                    == r.channels[0]
                        .terms
                        .iter()
                        .filter(|t| t.consistent == Some(false))
                        .count()
            );
            outcome(&r)
        })
        .collect();
    let fa = rates(&same);
    let pw = rates(&differ);
    let joint_better = same
        .iter()
        .filter(|o| o.white_err[2] < o.white_err[0].max(o.white_err[1]))
        .count();
    for (k, term) in TESTED.iter().enumerate() {
        eprintln!(
            "{term:?}: false 'disagree' {}/{} pairs of one truth; flagged {}/{} pairs with B 2x apart",
            fa[k].0, fa[k].1, pw[k].0, pw[k].1
        );
    }
    for (k, term) in TESTED.iter().enumerate() {
        let mut p: Vec<f64> = same.iter().filter_map(|o| o.p[k]).collect();
        p.sort_by(f64::total_cmp);
        if !p.is_empty() {
            eprintln!(
                "{term:?}: p-values under one truth: min {:.3}, median {:.3} (uniform if the \
                 intervals are calibrated)",
                p[0],
                p[p.len() / 2]
            );
        }
    }
    eprintln!(
        "joint N closer to truth than the worse run: {joint_better}/{SEEDS}; {:.1} s",
        start.elapsed().as_secs_f64()
    );
    // N and B are resolved in (nearly) every 2-h run; K, above ~250 s, often is not
    // (an upper limit in one run leaves nothing to test).
    for (k, term) in TESTED.iter().enumerate() {
        if k < 2 {
            assert!(
                fa[k].1 >= SEEDS as usize * 3 / 4,
                "{term:?} tested in {} pairs",
                fa[k].1
            );
        }
        assert!(
            fa[k].0 * 20 <= 3 * fa[k].1,
            "{term:?}: {}/{}",
            fa[k].0,
            fa[k].1
        );
    }
    assert!(
        joint_better * 4 >= 3 * SEEDS as usize,
        "{joint_better}/{SEEDS}"
    );
    let (hit, tested) = pw[1];
    assert!(
        tested >= SEEDS as usize * 3 / 4,
        "B tested in {tested} pairs"
    );
    assert!(hit * 10 >= 7 * tested, "power {hit}/{tested}");
}

/// One run given twice: Q = 0, no between-run variance, the pooled value is the run's,
/// the joint curve is the run's curve with twice the EDF.
#[test]
fn identical_runs_agree_exactly() {
    let a = fit_run("a", &sim(1.0, 7));
    let r = compare(&a, &a);
    let c = &r.channels[0];
    assert!(!c.terms.is_empty());
    for t in &c.terms {
        if let (Some(m), RunEstimate::Value(v)) = (t.test, t.runs[0]) {
            assert!(m.q < 1e-20, "{t:?}");
            assert_eq!(m.tau2, 0.0);
            assert_eq!(t.consistent, Some(true));
            let p = t.pooled.expect("pooled");
            assert!((p.value / v.value - 1.0).abs() < 1e-12, "{t:?}");
            assert_eq!(t.spread.map(|s| s.relative), Some(0.0));
        }
    }
    let (j, one) = (&r.joint_curves[0], &a.0[0]);
    assert_eq!(j.points.len(), one.points.len());
    for (i, (p, q)) in j.points.iter().zip(&one.points).enumerate() {
        assert!((p.dev / q.dev - 1.0).abs() < 1e-12);
        assert!((j.edf[i] / one.edf[i] - 2.0).abs() < 1e-12);
    }
    assert!(r.warnings().is_empty());
    assert_eq!(c.worst_cross_check.map(|w| w < 0.2), Some(true));
}

/// Runs of different lengths: the joint grid is the shorter run's, the longer run is
/// read off its own grid by interpolation, and the joint σ lies between the runs'.
#[test]
fn runs_of_different_length_combine_on_the_shorter_grid() {
    let a = fit_run("a", &sim(1.0, 11));
    let y = sim(1.0, 12);
    let b = fit_run("b", &y[..y.len() * 2 / 3]);
    let r = compare(&a, &b);
    let j = &r.joint_curves[0];
    assert_eq!(
        j.points.last().map(|p| p.m),
        b.0[0].points.last().map(|p| p.m)
    );
    for (i, p) in j.points.iter().enumerate() {
        let q = &b.0[0].points[i];
        assert_eq!(p.m, q.m);
        let lo = q.dev.min(interp(&a.0[0], p.m));
        let hi = q.dev.max(interp(&a.0[0], p.m));
        assert!(
            p.dev >= lo * (1.0 - 1e-9) && p.dev <= hi * (1.0 + 1e-9),
            "m = {}",
            p.m
        );
    }
}

fn interp(c: &ChannelResult, m: usize) -> f64 {
    let i = c.points.iter().position(|p| p.m >= m).expect("inside");
    if c.points[i].m == m {
        return c.points[i].dev;
    }
    let (a, b) = (&c.points[i - 1], &c.points[i]);
    let u = (m as f64 / a.m as f64).ln() / (b.m as f64 / a.m as f64).ln();
    (a.dev.powi(2).ln() + u * (b.dev.powi(2).ln() - a.dev.powi(2).ln()))
        .exp()
        .sqrt()
}

/// Different rates or channels are refused, naming both runs.
#[test]
fn mismatched_runs_are_refused() {
    let a = fit_run("a", &sim(1.0, 21));
    let mut b = a.clone();
    for c in &mut b.0 {
        c.tau0_s *= 2.0;
    }
    let runs = |b: &(Vec<ChannelResult>, NoiseModel)| {
        let r = [
            ReplicateRun {
                source: "first.csv",
                curves: &a.0,
                model: &a.1,
                resolution: &[],
            },
            ReplicateRun {
                source: "second.csv",
                curves: &b.0,
                model: &b.1,
                resolution: &[],
            },
        ];
        compare_replicates(&r, &ReplicateOptions::default())
    };
    let e = runs(&b).expect_err("rates differ");
    let msg = e.to_string();
    assert!(matches!(e, ReplicateError::Mismatch { .. }), "{msg}");
    assert!(
        msg.contains("first.csv") && msg.contains("second.csv"),
        "{msg}"
    );
    assert!(msg.contains("sample rates differ"), "{msg}");
    let mut c = a.clone();
    c.0[0].name = "gyro_y".into();
    c.1.channels[0].name = "gyro_y".into();
    let msg = runs(&c).expect_err("channels differ").to_string();
    assert!(
        msg.contains("first.csv") && msg.contains("second.csv"),
        "{msg}"
    );
    assert!(msg.contains("gyro_x") && msg.contains("gyro_y"), "{msg}");
    let one = [ReplicateRun {
        source: "first.csv",
        curves: &a.0,
        model: &a.1,
        resolution: &[],
    }];
    assert!(matches!(
        compare_replicates(&one, &ReplicateOptions::default()),
        Err(ReplicateError::TooFewRuns(1))
    ));
}

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

/// The gyro curves and model of a real run, as `driftless allan` fits them.
fn gyro_run(log: &ImuLog) -> (Vec<ChannelResult>, NoiseModel, Vec<Option<f64>>) {
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
    let resolution: Vec<Option<f64>> = gyros.iter().map(|c| resolution_step(&c.values)).collect();
    let opts = ModelOptions {
        resolution: resolution.clone(),
        ..ModelOptions::default()
    };
    let q = vec![Quantity::AngularRate; curves.len()];
    let model = NoiseModel::from_curves_with(
        &log.source,
        &curves,
        &q,
        &FitConfig::default(),
        cfg.confidence,
        &opts,
    )
    .expect("model");
    (curves, model, resolution)
}

/// The two ADIS16405 static runs: both runs listed per gyro, the joint white noise within
/// 5 % of the runs' mean; verdicts and spreads printed.
#[test]
#[ignore = "needs shared data"]
fn adis16405_run2_run3_replicates() {
    let logs = [read_run(2), read_run(3)];
    let fitted: Vec<_> = logs.iter().map(gyro_run).collect();
    let runs: Vec<ReplicateRun<'_>> = logs
        .iter()
        .zip(&fitted)
        .map(|(l, (c, m, r))| ReplicateRun {
            source: &l.source,
            curves: c,
            model: m,
            resolution: r,
        })
        .collect();
    let rep = compare_replicates(
        &runs,
        &ReplicateOptions {
            level: DEFAULT_LEVEL,
            ..ReplicateOptions::default()
        },
    )
    .expect("compare");
    eprintln!("{}", rep.human_table());
    eprintln!("{}", rep.joint.human_table());
    for (_, m, _) in &fitted {
        eprintln!("{}", m.human_table());
    }
    assert_eq!(rep.channels.len(), 3);
    for c in &rep.channels {
        let w = c
            .terms
            .iter()
            .find(|t| t.term == TermKind::White)
            .expect("white noise compared");
        assert_eq!(w.runs.len(), 2);
        let vals: Vec<f64> = w
            .runs
            .iter()
            .map(|e| match e {
                RunEstimate::Value(t) => t.value,
                other => panic!("{}: white noise {other:?}", c.name),
            })
            .collect();
        let mean = 0.5 * (vals[0] + vals[1]);
        let joint = rep
            .joint
            .channel(&c.name)
            .and_then(|j| j.fit.white)
            .expect("joint white noise")
            .value;
        for t in &c.terms {
            eprintln!(
                "{} {:?}: {} spread {:.1} %",
                c.name,
                t.term,
                t.verdict,
                t.spread.map_or(f64::NAN, |s| 100.0 * s.relative)
            );
        }
        eprintln!(
            "{}: N runs {:.4} {:.4} joint {:.4} deg/√h ({:+.2} % of the mean); worst cross-run {:.1} %",
            c.name,
            vals[0] / DEG_PER_SQRT_H,
            vals[1] / DEG_PER_SQRT_H,
            joint / DEG_PER_SQRT_H,
            100.0 * (joint / mean - 1.0),
            100.0 * c.worst_cross_check.unwrap_or(f64::NAN)
        );
        assert!(
            (joint / mean - 1.0).abs() <= 0.05,
            "{}: {joint} vs {mean}",
            c.name
        );
    }
    for w in rep.warnings() {
        eprintln!("warning: {w}");
    }
}

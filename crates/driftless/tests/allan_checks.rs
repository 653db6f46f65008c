//! Whether a record suits a noise analysis: a simulated static log passes the
//! stationarity test, a simulated moving one (turns and vibration) fails it with a
//! warning; a long-τ term read beyond a tenth of the record, or dominating nowhere, warns.

use driftless::allan::checks::{record_length_warnings, stationarity, stationarity_warning};
use driftless::allan::fit::{NoiseFit, Term};
use driftless::sim::presets::Preset;
use driftless::sim::sensor::{IdealImu, OutputKind, SensorModel};
use driftless::sim::temperature::TemperatureProfile;

const DT: f64 = 0.01;

/// Gyro z of a consumer-grade sensor over `n` samples of the ideal rate `rate(t)`.
fn gyro_z(n: usize, rate: impl Fn(f64) -> f64 + Sync, seed: u64) -> Vec<f64> {
    let ideal = IdealImu::from_fn(OutputKind::Rates, 0.0, DT, n, |k| {
        let t = k as f64 * DT;
        ([0.0, 0.0, rate(t)], [0.0, 0.0, -9.80665])
    });
    let model = SensorModel::new(Preset::Consumer.config()).expect("model");
    let temp = TemperatureProfile::constant(25.0).curve().expect("curve");
    let out = model.simulate(&ideal, &temp, seed).expect("simulate");
    (0..out.len()).map(|k| out.gyro_at(k)[2]).collect()
}

#[test]
fn static_log_passes_moving_log_warns() {
    let n = 60_000; // 10 min at 100 Hz
    for seed in 1..=5 {
        let rest = gyro_z(n, |_| 0.0, seed);
        let s = stationarity(&rest, DT).expect("long enough");
        println!("static: {s:?}");
        assert!(s.is_static(), "{s:?}");
        assert!(stationarity_warning("gyro_z", &rest, DT).is_none());
    }
    // A vehicle: stops, then drives with turns (0.3 rad/s for 5 s every 30 s) and road
    // vibration (0.05 rad/s at 13 Hz) while moving.
    let drive = |t: f64| {
        let moving = (t % 120.0) > 20.0;
        if !moving {
            return 0.0;
        }
        let turn = if (t % 30.0) < 5.0 { 0.3 } else { 0.0 };
        turn + 0.05 * (2.0 * std::f64::consts::PI * 13.0 * t).sin()
    };
    let moving = gyro_z(n, drive, 9);
    let s = stationarity(&moving, DT).expect("long enough");
    println!("moving: {s:?}");
    assert!(!s.is_static(), "{s:?}");
    let w = stationarity_warning("gyro_z", &moving, DT).expect("warning");
    println!("{w}");
    assert!(w.contains("gyro_z") && w.contains("not static"), "{w}");
}

fn term(v: f64) -> Option<Term> {
    Some(Term {
        value: v,
        lo: 0.5 * v,
        hi: 2.0 * v,
    })
}

fn fit(white: f64, bias: f64, rrw: f64) -> NoiseFit {
    NoiseFit {
        quantization: None,
        white: term(white),
        bias_instability: term(bias),
        rate_random_walk: term(rrw),
        rate_ramp: None,
        gauss_markov: None,
        confidence: 0.683,
        rms_log10_residual: 0.0,
        not_detected: Vec::new(),
        chi2_reduced: 1.0,
        n_points: 20,
        fit_range: None,
        not_identifiable: Vec::new(),
    }
}

#[test]
fn long_tau_terms_need_a_long_record() {
    // N = 1e-3 u·√s and B = 1e-4 u: B (0.664·B² = 6.6e-9) overtakes N²/τ at τ ≈ 150 s.
    let f = fit(1e-3, 1e-4, 1e-7);
    let taus: Vec<f64> = (0..=40)
        .map(|i| 0.01 * 10f64.powf(i as f64 / 8.0))
        .collect();
    let taus: Vec<f64> = taus.into_iter().filter(|&t| t <= 1000.0).collect();
    // a 10 000 s record: B is read at ~150 s < T/10, fine; K dominates nowhere ≤ 1000 s
    let long = record_length_warnings("gyro_x", &f, &taus, 10_000.0);
    println!("{long:?}");
    assert_eq!(long.len(), 1, "{long:?}");
    assert!(long[0].contains("rate random walk"), "{long:?}");
    // a 1000 s record: B is read only beyond T/10 = 100 s
    let short = record_length_warnings("gyro_x", &f, &taus, 1000.0);
    println!("{short:?}");
    assert!(
        short
            .iter()
            .any(|w| w.contains("bias instability") && w.contains("only 1000 s")),
        "{short:?}"
    );
    // without K the long record gives no warning
    let f = fit(1e-3, 1e-4, 0.0);
    assert!(record_length_warnings("gyro_x", &f, &taus, 10_000.0).is_empty());
}

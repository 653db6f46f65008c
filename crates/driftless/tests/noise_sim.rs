//! Simulator speed, multi-channel generation, Gauss-Markov recovery and the noise-model
//! file written from a real fit. Run in release.

use std::time::Instant;

use driftless::allan::Estimator;
use driftless::allan::ci;
use driftless::allan::estimators::oadev;
use driftless::allan::fit::{FitConfig, NoiseFit, fit_noise_with_edf};
use driftless::allan::noise_model::{ChannelNoise, NoiseModel, Quantity};
use driftless::allan::phase::frequency_to_phase;
use driftless::allan::taus::{TauSpec, averaging_factors};
use driftless::sim::noise::{GaussMarkovConfig, StaticNoiseConfig, generate, generate_channels};
use driftless::sim::rng::Rng;
use driftless_model::units::{DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, MICRO_G};

fn gyro_18h() -> StaticNoiseConfig {
    StaticNoiseConfig {
        sample_rate_hz: 100.0,
        duration_s: 18.0 * 3600.0,
        quantization: 1e-6,
        white: 0.15 * DEG_PER_SQRT_H,
        bias_instability: 3.0 * DEG_PER_H,
        rate_random_walk: 12.0 * DEG_PER_H_PER_SQRT_H,
        rate_ramp: 1e-9,
        gauss_markov: Some(GaussMarkovConfig {
            sigma: 1.0 * DEG_PER_H,
            tau_c_s: 300.0,
        }),
        turn_on_bias: 0.02,
        ..Default::default()
    }
}

fn fit(y: &[f64], fs: f64, cfg: &FitConfig) -> NoiseFit {
    let dt = 1.0 / fs;
    let x = frequency_to_phase(y, dt);
    let n_phase = x.len();
    let ms = averaging_factors(&TauSpec::Log(100), dt, n_phase, Estimator::Oadev).unwrap();
    let pts = oadev(&x, dt, &ms);
    let tau: Vec<f64> = pts.iter().map(|p| p.tau).collect();
    let avar: Vec<f64> = pts.iter().map(|p| p.dev * p.dev).collect();
    fit_noise_with_edf(
        &tau,
        &avar,
        |i, a| ci::edf(Estimator::Oadev, a, pts[i].m, n_phase),
        cfg,
        0.683,
    )
    .unwrap()
}

#[test]
fn simulator_speed_18h_channel() {
    let cfg = gyro_18h();
    let _warm = generate(
        &StaticNoiseConfig {
            duration_s: 10.0,
            ..cfg.clone()
        },
        0,
    );
    let t = Instant::now();
    let y = generate(&cfg, 1).unwrap();
    let el = t.elapsed().as_secs_f64();
    assert_eq!(y.len(), 6_480_000);
    let n_flicker = cfg.flicker_components().len();
    eprintln!(
        "18 h @ 100 Hz, all terms ({n_flicker} flicker components): {:.3} s",
        el
    );
    // Generous bound (tests share 2 cores); typical is ~0.35 s.
    assert!(el < 2.0, "generation took {el} s");

    let mut r = Rng::seed_from_u64(3);
    let t = Instant::now();
    let mut s = 0.0;
    for _ in 0..20_000_000 {
        s += r.normal();
    }
    let el = t.elapsed().as_secs_f64();
    eprintln!(
        "20 M normals: {:.3} s ({:.2} ns each), mean {:.2e}",
        el,
        el / 2e-2,
        s / 2e7
    );
}

#[test]
fn six_axis_parallel_and_discrete_sigma() {
    let gyro = StaticNoiseConfig {
        sample_rate_hz: 200.0,
        duration_s: 600.0,
        white: 0.2 * DEG_PER_SQRT_H,
        ..Default::default()
    };
    let acc = StaticNoiseConfig {
        white: 60.0 * MICRO_G, // 60 µg/√Hz
        turn_on_bias: 9.80665,
        ..gyro.clone()
    };
    let cfgs = vec![
        gyro.clone(),
        gyro.clone(),
        gyro.clone(),
        acc.clone(),
        acc.clone(),
        acc,
    ];
    let t = Instant::now();
    let ch = generate_channels(&cfgs, 77).unwrap();
    eprintln!(
        "six-axis 10 min @ 200 Hz: {:.3} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(ch.len(), 6);
    // The sample std equals the discrete σ_d = N·√fs the noise model reports.
    for (c, cfg) in ch.iter().zip(&cfgs) {
        let n = c.len() as f64;
        let mean = c.iter().sum::<f64>() / n;
        let sd = (c.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let want = cfg.white * cfg.sample_rate_hz.sqrt();
        assert!((sd / want - 1.0).abs() < 0.01, "sd {sd} vs {want}");
        assert!((mean - cfg.turn_on_bias).abs() < 5.0 * want / n.sqrt());
    }
    assert_ne!(ch[0], ch[1]);
}

#[test]
fn gauss_markov_term_recovered() {
    // White + GM (σ = 20 deg/h, T = 100 s) over 6 h at 100 Hz.
    let (n, s, t) = (0.2 * DEG_PER_SQRT_H, 20.0 * DEG_PER_H, 100.0);
    let cfg = StaticNoiseConfig {
        sample_rate_hz: 100.0,
        duration_s: 6.0 * 3600.0,
        white: n,
        gauss_markov: Some(GaussMarkovConfig {
            sigma: s,
            tau_c_s: t,
        }),
        ..Default::default()
    };
    let fcfg = FitConfig {
        quantization: false,
        white: true,
        bias_instability: false,
        rate_random_walk: false,
        rate_ramp: false,
        gauss_markov: true,
    };
    let mut es = Vec::new();
    let mut et = Vec::new();
    for seed in 0..4 {
        let y = generate(&cfg, 40 + seed).unwrap();
        let f = fit(&y, 100.0, &fcfg);
        let gm = f.gauss_markov.expect("GM detected");
        eprintln!(
            "GM: sigma {:.2} [{:.2}, {:.2}] deg/h, T {:.1} [{:.1}, {:.1}] s",
            gm.sigma.value / DEG_PER_H,
            gm.sigma.lo / DEG_PER_H,
            gm.sigma.hi / DEG_PER_H,
            gm.tau_c_s.value,
            gm.tau_c_s.lo,
            gm.tau_c_s.hi
        );
        es.push((gm.sigma.value / s - 1.0).abs());
        et.push((gm.tau_c_s.value / t - 1.0).abs());
        assert!((f.white.unwrap().value / n - 1.0).abs() < 0.02);
    }
    es.sort_by(f64::total_cmp);
    et.sort_by(f64::total_cmp);
    assert!(es[2] < 0.15, "sigma errors {es:?}");
    assert!(et[2] < 0.30, "T errors {et:?}");
}

#[test]
fn noise_model_file_from_a_fit() {
    let cfg = StaticNoiseConfig {
        duration_s: 2.0 * 3600.0,
        ..gyro_18h()
    };
    let y = generate(&cfg, 5).unwrap();
    let f = fit(&y, 100.0, &FitConfig::default());
    let mut model = NoiseModel::new(Some("sim.csv".into()), 100.0, Some("oadev".into()));
    model.channels.push(ChannelNoise::new(
        "gyro_x",
        Quantity::AngularRate,
        f.clone(),
        100.0,
    ));
    let s = model.to_toml_string().unwrap();
    let back = NoiseModel::from_toml_str(&s).unwrap();
    let c = back.channel("gyro_x").unwrap();
    assert_eq!(c.fit, f);
    let n = f.white.unwrap().value;
    assert!((c.discrete.white_sigma.unwrap() - n * 10.0).abs() < 1e-15);
    let arw = c
        .display
        .iter()
        .find(|d| d.unit == "deg/sqrt(h)")
        .unwrap()
        .value;
    assert!((arw / 0.15 - 1.0).abs() < 0.05, "ARW {arw} deg/sqrt(h)");
}

#[test]
fn model_from_analysis_curves_and_human_table() {
    use driftless::allan::analysis::{AnalysisConfig, analyse};
    let gyro = StaticNoiseConfig {
        duration_s: 3.0 * 3600.0,
        ..gyro_18h()
    };
    let acc = StaticNoiseConfig {
        duration_s: 3.0 * 3600.0,
        white: 0.02 / 60.0,
        bias_instability: 20.0 * MICRO_G,
        rate_random_walk: 1e-5,
        gauss_markov: None,
        quantization: 0.0,
        rate_ramp: 0.0,
        turn_on_bias: 9.8,
        ..Default::default()
    };
    let data = generate_channels(&[gyro, acc], 11).unwrap();
    let cfg = AnalysisConfig {
        taus: TauSpec::Log(100),
        ..Default::default()
    };
    let curves = vec![
        analyse("gyro_z", &data[0], 0.01, &cfg).unwrap(),
        analyse("acc_z", &data[1], 0.01, &cfg).unwrap(),
    ];
    let fcfg = FitConfig {
        gauss_markov: false,
        ..FitConfig::default()
    };
    let q = [Quantity::AngularRate, Quantity::SpecificForce];
    let m = NoiseModel::from_curves("sim", &curves, &q, &fcfg, 0.683).unwrap();
    assert_eq!(m.channels.len(), 2);
    assert!((m.sample_rate_hz - 100.0).abs() < 1e-9);
    let n_acc = m.channel("acc_z").unwrap().fit.white.unwrap().value;
    assert!((n_acc / (0.02 / 60.0) - 1.0).abs() < 0.02, "VRW {n_acc}");
    assert!(m.fits().count() == 2);
    let table = m.human_table();
    eprintln!("{table}");
    assert!(table.contains("deg/sqrt(h)") && table.contains("m/s/sqrt(h)"));
    assert!(table.contains("discrete: white"));
    // Mismatched inputs are an error, not a panic.
    assert!(NoiseModel::from_curves("sim", &curves, &q[..1], &fcfg, 0.683).is_err());
    let back = NoiseModel::from_toml_str(&m.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, m);
}

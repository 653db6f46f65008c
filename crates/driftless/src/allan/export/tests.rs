use driftless_model::units::{DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, MICRO_G};

use super::kalibr::KalibrImu;
use super::*;
use crate::allan::fit::{
    FitRange, GaussMarkovTerm, NoiseFit, RangeSource, Term, TermKind, UpperLimit,
};
use crate::allan::noise_model::{ChannelNoise, NoiseModel};
use crate::io::nav::kfgins_config::KfGinsConfig;

fn term(v: f64) -> Option<Term> {
    Some(Term {
        value: v,
        lo: 0.8 * v,
        hi: 1.2 * v,
    })
}

/// White N, bias instability B and rate random walk K, fitted up to 10⁴ s (the floor at
/// √3·N/K lies inside, so the bias instability has its Gauss-Markov stand-in).
fn fit(n: f64, b: f64, k: f64) -> NoiseFit {
    NoiseFit {
        quantization: None,
        white: term(n),
        bias_instability: term(b),
        rate_random_walk: term(k),
        rate_ramp: None,
        gauss_markov: None,
        confidence: 0.683,
        rms_log10_residual: 0.01,
        not_detected: Vec::new(),
        chi2_reduced: 1.0,
        n_points: 80,
        fit_range: Some(FitRange {
            tau_min_s: 0.1,
            tau_max_s: 2e4,
            source: RangeSource::Full,
            excluded_short: 0,
            excluded_long: 0,
        }),
        not_identifiable: Vec::new(),
    }
}

/// Gyro N = 0.2, 0.25, 0.3 deg/√h (x, y, z), B = 3 deg/h, K = 0.5 deg/h/√h; accel
/// N = 0.02 m/s/√h (0.03 on z), B = 50 µg, K = 2e-5 m/s³/√Hz; 100 Hz.
fn model() -> NoiseModel {
    let mut m = NoiseModel::new(Some("bench.csv".into()), 100.0, Some("oadev".into()));
    for (axis, n) in [("x", 0.2), ("y", 0.25), ("z", 0.3)] {
        m.channels.push(ChannelNoise::new(
            &format!("gyro_{axis}"),
            Quantity::AngularRate,
            fit(
                n * DEG_PER_SQRT_H,
                3.0 * DEG_PER_H,
                0.5 * DEG_PER_H_PER_SQRT_H,
            ),
            100.0,
        ));
    }
    for (axis, n) in [("x", 0.02), ("y", 0.02), ("z", 0.03)] {
        m.channels.push(ChannelNoise::new(
            &format!("accel_{axis}"),
            Quantity::SpecificForce,
            fit(n / 60.0, 50.0 * MICRO_G, 2e-5),
            100.0,
        ));
    }
    m
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// `KEY: VALUE` / `KEY,VALUE` / QGC `1 1 KEY VALUE 9` value of `key` in an exported text.
fn value_of(text: &str, key: &str) -> f64 {
    for line in text.lines().filter(|l| !l.trim_start().starts_with('#')) {
        let line = line.split('#').next().unwrap_or("");
        let fields: Vec<&str> = line.split([':', ',', '\t']).map(str::trim).collect();
        if let Some(i) = fields.iter().position(|f| *f == key) {
            return fields[i + 1].parse().expect("a number");
        }
    }
    panic!("{key} not in\n{text}")
}

#[test]
fn yaml_floats_are_yaml_1_1_floats_and_exact() {
    for (v, s) in [
        (100.0, "1.0e+2"),
        (5.817764173314432e-5, "5.817764173314432e-5"),
        (1e-9, "1.0e-9"),
        (0.0, "0.0e+0"),
        (2.5, "2.5e+0"),
    ] {
        assert_eq!(yaml_float(v), s);
        assert_eq!(s.parse::<f64>().unwrap(), v);
    }
    // PyYAML's 1.1 float pattern: digits, a point, digits, a signed exponent.
    for v in [1.0, 3e-7, 123456.789, 4.040114009246133e-8] {
        let s = yaml_float(v);
        let (m, e) = s.split_once('e').unwrap();
        assert!(
            m.contains('.') && (e.starts_with('+') || e.starts_with('-')),
            "{s}"
        );
    }
}

#[test]
fn kalibr_export_reads_back_and_matches_hand_conversions() {
    let m = model();
    let imu = imu_noise(&m, &GivenValues::default());
    let text = export(ExportFormat::Kalibr, &imu, &ExportOptions::default()).unwrap();
    assert!(!text.contains("!!") && !text.contains('%'), "{text}");
    let k = KalibrImu::from_yaml_str(&text, "imu.yaml").unwrap();
    // Largest gyro N: 0.3 deg/√h = 0.3·(π/180)/60 rad/s/√Hz.
    assert!(rel(k.gyro_noise_density_rad_s_sqrt_hz, 8.726646259971648e-5) < 1e-12);
    // 0.2 deg/√h is 5.818e-5 rad/s/√Hz (hand value).
    assert!(rel(0.2 * DEG_PER_SQRT_H, 5.817764173314432e-5) < 1e-15);
    // K = 0.5 deg/h/√h = 0.5·(π/180)/216000 rad/s²/√Hz.
    assert!(rel(k.gyro_random_walk_rad_s2_sqrt_hz, 4.040114009246133e-8) < 1e-12);
    // Accel N = 0.03 m/s/√h = 5e-4 m/s²/√Hz; K as fitted.
    assert!(rel(k.accel_noise_density_m_s2_sqrt_hz, 5e-4) < 1e-12);
    assert!(rel(k.accel_random_walk_m_s3_sqrt_hz, 2e-5) < 1e-12);
    assert_eq!(k.update_rate_hz, 100.0);
    assert_eq!(k.rostopic.as_deref(), Some("/imu0"));
    // Exactly the model's values (1e-12 relative), channel by channel.
    let n = |name: &str| m.channel(name).unwrap().fit.white.unwrap().value;
    assert!(rel(k.gyro_noise_density_rad_s_sqrt_hz, n("gyro_z")) < 1e-12);
    assert!(rel(k.accel_noise_density_m_s2_sqrt_hz, n("accel_z")) < 1e-12);
    assert!(text.contains("gyro_z (largest of 3 axes)"), "{text}");
    assert!(!text.contains("CHECK:"), "{text}");

    // The OpenVINS chain file carries the same numbers in its imu0 block.
    let ov = export(ExportFormat::OpenVins, &imu, &ExportOptions::default()).unwrap();
    assert!(ov.starts_with("%YAML:1.0\n"), "{ov}");
    assert_eq!(KalibrImu::from_yaml_str(&ov, "chain.yaml").unwrap(), k);
}

#[test]
fn kalibr_reader_names_the_place_of_a_bad_value() {
    let text = "accelerometer_noise_density: 2.0e-3\naccelerometer_random_walk: -1\n\
                gyroscope_noise_density: 1.7e-4\ngyroscope_random_walk: 2.0e-5\nupdate_rate: 200\n";
    let e = KalibrImu::from_yaml_str(text, "imu.yaml").unwrap_err();
    let s = e.to_string();
    assert!(
        s.contains("imu.yaml:2:") && s.contains("accelerometer_random_walk"),
        "{s}"
    );
    let e = KalibrImu::from_yaml_str("update_rate: 200\n", "imu.yaml").unwrap_err();
    assert!(e.to_string().contains("accelerometer_noise_density"), "{e}");
}

#[test]
fn vins_values_are_per_sample_sigmas_at_the_imu_rate() {
    let imu = imu_noise(&model(), &GivenValues::default());
    let text = export(ExportFormat::Vins, &imu, &ExportOptions::default()).unwrap();
    // N·√100: 0.3 deg/√h → 8.7266e-4 rad/s; 0.03 m/s/√h → 5e-3 m/s².
    assert!(rel(value_of(&text, "gyr_n"), 8.726646259971648e-4) < 1e-12);
    assert!(rel(value_of(&text, "acc_n"), 5e-3) < 1e-12);
    assert!(rel(value_of(&text, "gyr_w"), 4.040114009246133e-7) < 1e-12);
    assert!(rel(value_of(&text, "acc_w"), 2e-4) < 1e-12);
}

#[test]
fn autopilot_params_use_the_filter_rate() {
    let imu = imu_noise(&model(), &GivenValues::default());
    let opts = ExportOptions::default();
    let px4 = export(ExportFormat::Px4, &imu, &opts).unwrap();
    // 100 Hz: density × 10.
    assert!(rel(value_of(&px4, "EKF2_GYR_NOISE"), 8.726646259971648e-4) < 1e-12);
    assert!(rel(value_of(&px4, "EKF2_ACC_NOISE"), 5e-3) < 1e-12);
    assert!(rel(value_of(&px4, "EKF2_GYR_B_NOISE"), 4.040114009246133e-7) < 1e-12);
    assert!(rel(value_of(&px4, "EKF2_ACC_B_NOISE"), 2e-4) < 1e-12);
    assert!(px4.contains("1\t1\tEKF2_GYR_NOISE\t"), "{px4}");
    // ArduPilot EKF3 at 1/0.012 s: density × √(250/3).
    let ap = export(ExportFormat::ArduPilot, &imu, &opts).unwrap();
    let r = (250.0f64 / 3.0).sqrt();
    assert!(rel(value_of(&ap, "EK3_GYRO_P_NSE"), 8.726646259971648e-5 * r) < 1e-12);
    assert!(rel(value_of(&ap, "EK3_ABIAS_P_NSE"), 2e-5 * r) < 1e-12);
    assert!(ap.lines().any(|l| l.starts_with("EK3_ACC_P_NSE,")), "{ap}");
}

#[test]
fn kfgins_block_is_read_by_our_kfgins_reader() {
    let m = model();
    let imu = imu_noise(&m, &GivenValues::default());
    let block = export(ExportFormat::KfGins, &imu, &ExportOptions::default()).unwrap();
    let base = "imupath: \"imu.txt\"\ngnsspath: \"gnss.txt\"\noutputpath: \"out\"\n\
                imudatalen: 7\nimudatarate: 100\nstarttime: 0\nendtime: -1\n\
                initpos: [30.0, 114.0, 20.0]\ninitvel: [0, 0, 0]\ninitatt: [0, 0, 0]\n\
                initgyrbias: [0, 0, 0]\ninitaccbias: [0, 0, 0]\ninitgyrscale: [0, 0, 0]\n\
                initaccscale: [0, 0, 0]\ninitposstd: [1, 1, 1]\ninitvelstd: [1, 1, 1]\n\
                initattstd: [1, 1, 1]\nantlever: [0, 0, 0]\n";
    let cfg = KfGinsConfig::from_yaml_str(&format!("{base}{block}"), "kf-gins.yaml").unwrap();
    let n = &cfg.imu_noise;
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        let g = &m.channel(&format!("gyro_{axis}")).unwrap();
        let a = &m.channel(&format!("accel_{axis}")).unwrap();
        assert!(rel(n.arw_rad_sqrt_s[i], g.fit.white.unwrap().value) < 1e-12);
        assert!(rel(n.vrw_m_s_sqrt_s[i], a.fit.white.unwrap().value) < 1e-12);
        let gs = g.discrete.bias_instability_gm.unwrap().sigma;
        let as_ = a.discrete.bias_instability_gm.unwrap().sigma;
        assert!(rel(n.gyro_bias_std_rad_s[i], gs) < 1e-12);
        assert!(rel(n.accel_bias_std_m_s2[i], as_) < 1e-12);
    }
    // Hand values: 0.2 deg/√h is written as 0.2; 0.02 m/s/√h as 0.02.
    assert!(rel(cfg.raw.imunoise.arw[0], 0.2) < 1e-12);
    assert!(rel(cfg.raw.imunoise.vrw[0], 0.02) < 1e-12);
    let shortest = m
        .channels
        .iter()
        .map(|c| c.discrete.bias_instability_gm.unwrap().tau_c_s)
        .fold(f64::INFINITY, f64::min);
    assert!(rel(n.corr_time_s, shortest) < 1e-12);
    assert_eq!(n.gyro_scale_std, [0.0; 3]);
    assert!(block.contains("CHECK: not measured"), "{block}");
}

#[test]
fn an_undetected_k_takes_the_larger_conservative_bound_and_is_flagged() {
    let mut m = model();
    for c in &mut m.channels {
        let k = c.fit.rate_random_walk.take().unwrap();
        c.fit.not_detected.push(UpperLimit {
            term: TermKind::RateRandomWalk,
            upper: k.value * 1e-3,
        });
    }
    let imu = imu_noise(&m, &GivenValues::default());
    let g = imu.gyro.random_walk_density.clone().unwrap();
    // Without K the floor runs on past the fitted range (to 2e4 s): the stand-in's Allan
    // peak (0.3811·σ_b² at τ = 1.8926·T_c) is put there, equal to the floor (2 ln2/π)·B².
    let ValueSource::BiasInstabilityRangeEnd { tau_c_s } = g.source else {
        panic!("{g:?}")
    };
    let (u_peak, peak) = gauss_markov_avar_peak();
    assert!((u_peak - 1.8926).abs() < 1e-3 && (peak - 0.3811).abs() < 1e-3);
    assert!(rel(tau_c_s, 2e4 / u_peak) < 1e-15);
    let sigma_b = (BIAS_AVAR_COEF / peak).sqrt() * 3.0 * DEG_PER_H;
    // σ_b·√(2/T_c) (the upper limit, 1e-3·K, is far smaller).
    assert!(rel(g.value, sigma_b * (2.0 / tau_c_s).sqrt()) < 1e-12);
    let text = export(ExportFormat::Kalibr, &imu, &ExportOptions::default()).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("gyroscope_random_walk"))
        .unwrap();
    assert!(line.contains("CHECK: K not detected"), "{line}");

    // With the floor inside the range the stand-in of the noise model is used.
    let inside = model();
    let a = axis_noise(&inside.channels[0], 100.0);
    assert!(matches!(
        a.random_walk_density.unwrap().source,
        ValueSource::Fitted
    ));
    let b = a.bias.unwrap();
    let gm = inside.channels[0].discrete.bias_instability_gm.unwrap();
    assert_eq!(
        (b.sigma, b.source),
        (
            gm.sigma,
            ValueSource::BiasInstability {
                tau_c_s: gm.tau_c_s
            }
        )
    );

    // A large upper limit wins over the stand-in.
    for c in &mut m.channels {
        c.fit.not_detected[0].upper = 1.0;
    }
    let imu = imu_noise(&m, &GivenValues::default());
    let g = imu.gyro.random_walk_density.unwrap();
    assert_eq!((g.value, g.source), (1.0, ValueSource::UpperLimit));
}

#[test]
fn a_missing_quantity_is_named_or_filled_by_given_values() {
    let mut m = model();
    m.channels.retain(|c| c.quantity == Quantity::AngularRate);
    let imu = imu_noise(&m, &GivenValues::default());
    for f in [
        ExportFormat::Kalibr,
        ExportFormat::OpenVins,
        ExportFormat::Vins,
        ExportFormat::KfGins,
    ] {
        let e = export(f, &imu, &ExportOptions::default()).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("accelerometer") && s.contains("--export-set"),
            "{s}"
        );
    }
    // The autopilots get what exists and a comment on what is not.
    let px4 = export(ExportFormat::Px4, &imu, &ExportOptions::default()).unwrap();
    assert!(px4.contains("\tEKF2_GYR_NOISE\t") && !px4.contains("\tEKF2_ACC_NOISE\t"));
    assert!(px4.contains("# EKF2_ACC_NOISE: not written"), "{px4}");

    let given: GivenValues = "accelerometer_noise_density=2e-3, accelerometer_random_walk=3e-3"
        .parse()
        .unwrap();
    let imu = imu_noise(&m, &given);
    let text = export(ExportFormat::Kalibr, &imu, &ExportOptions::default()).unwrap();
    let k = KalibrImu::from_yaml_str(&text, "imu.yaml").unwrap();
    assert_eq!(k.accel_noise_density_m_s2_sqrt_hz, 2e-3);
    assert_eq!(k.accel_random_walk_m_s3_sqrt_hz, 3e-3);
    assert!(text.contains("given by the user"), "{text}");

    for bad in [
        "accel=1",
        "gyroscope_random_walk=-1",
        "gyroscope_random_walk",
    ] {
        assert!(matches!(
            bad.parse::<GivenValues>(),
            Err(ExportError::BadValue { .. })
        ));
    }
    assert!("bogus".parse::<ExportFormat>().is_err());
    assert_eq!("PX4".parse::<ExportFormat>().unwrap(), ExportFormat::Px4);
}

#[test]
fn a_fitted_gauss_markov_term_is_the_kfgins_bias() {
    let mut m = model();
    for c in &mut m.channels {
        c.fit.gauss_markov = Some(GaussMarkovTerm {
            sigma: term(1e-4).unwrap(),
            tau_c_s: term(200.0).unwrap(),
        });
    }
    let imu = imu_noise(&m, &GivenValues::default());
    let block = export(ExportFormat::KfGins, &imu, &ExportOptions::default()).unwrap();
    // 1e-4 rad/s = 20.6265 deg/h; 1e-4 m/s² = 10 mGal; 200 s = 1/18 h.
    assert!(rel(value_of_list(&block, "gbstd")[0], 1e-4 / DEG_PER_H) < 1e-12);
    assert!(rel(value_of_list(&block, "abstd")[2], 10.0) < 1e-12);
    assert!(rel(value_of(&block, "corrtime"), 200.0 / 3600.0) < 1e-12);
}

fn value_of_list(text: &str, key: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key}:")))
        .unwrap();
    let inner = line.split('[').nth(1).unwrap().split(']').next().unwrap();
    inner
        .split(',')
        .map(|t| t.trim().parse().unwrap())
        .collect()
}

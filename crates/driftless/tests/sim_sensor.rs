//! Sensor-error model, temperature profiles, presets and the thermal-chamber protocol
//! (`sim::sensor`, `sim::temperature`, `sim::presets`, `sim::chamber`).
//!
//! Run in release; figures print with `--nocapture`. The 18-h speed figure is an ignored
//! test: `cargo test --release -p driftless --test sim_sensor -- --ignored --nocapture`.

use std::time::Instant;

use driftless::allan::Estimator;
use driftless::allan::ci;
use driftless::allan::estimators::oadev;
use driftless::allan::fit::{FitConfig, NoiseFit, Term, fit_noise_with_edf};
use driftless::allan::noise_model::{ChannelNoise, NoiseModel};
use driftless::allan::phase::frequency_to_phase;
use driftless::allan::taus::{TauSpec, averaging_factors};
use driftless::io::Quantity;
use driftless::nav::attitude::Euler;
use driftless::sim::chamber::{BodyAxis, ChamberConfig, SegmentKind, SignedAxis};
use driftless::sim::ideal_imu::{Stationary, Trajectory};
use driftless::sim::noise::GaussMarkovConfig;
use driftless::sim::presets::Preset;
use driftless::sim::sensor::{
    CHANNEL_NAMES, IdealImu, OutputKind, SensorConfig, SensorModel, SensorOutput,
};
use driftless::sim::sensor_error::SensorSimError;
use driftless::sim::temperature::{ChamberStep, TemperatureProfile};
use driftless_model::units::{DEG, DEG_PER_H};
use rayon::prelude::*;

const FS: f64 = 100.0;

/// Sum of one channel over a segment's samples, divided by its duration: the mean rate.
fn segment_mean(out: &SensorOutput, col: &[f64], seg: &driftless::sim::chamber::Segment) -> f64 {
    let r = seg.sample_range(FS);
    let n = r.len() as f64;
    let sum: f64 = col[r].iter().sum();
    match out.kind {
        OutputKind::Increments => sum / (n / FS),
        OutputKind::Rates => sum / n,
    }
}

/// Noise off, every deterministic term of the `adi-like` preset on (thermal bias and
/// scale-factor cubics, misalignment, g-sensitivity), increments through the full chamber
/// protocol at the paper's 20 set temperatures. At every set temperature the classic
/// estimates — accelerometer b = (f_up + f_down)/2 and 1 + s = (f_up − f_down)/(2g) from the
/// six positions with the exact local gravity g of the simulation (the manifest's normal
/// gravity, equal to |f^b| in a static position), gyro 1 + s = (ω̄(+ω) − ω̄(−ω))/(2ω) from
/// the rate table (Earth rate cancels in the difference, its horizontal part averages out
/// over whole revolutions) — must equal the configured polynomials to 1e-9 relative.
///
/// How the truth is taken: the soak lasts 40 sensor time constants (τ = 5 s, soak 200 s),
/// so the sensor temperature is within 5 °C·e^−40 ≈ 2e-17 °C of the set point — settled to
/// rounding — before the first position; the truth is therefore the polynomial at the set
/// temperature, and the test also checks the simulated sensor temperature in every
/// position and rate segment equals the set point to 1e-12 °C.
#[test]
fn chamber_protocol_recovers_thermal_polynomials_to_1e9() {
    let cfg = Preset::AdiLike.config().deterministic_only();
    let model = SensorModel::new(cfg).expect("model");
    let chamber = ChamberConfig {
        soak_s: 200.0,
        lag_tau_s: 5.0,
        position_dwell_s: 10.0,
        move_s: 4.0,
        rate_deg_s: 90.0,
        rate_revolutions: 1,
        spin_s: 2.0,
        sample_rate_hz: FS,
        ..Default::default()
    }
    .build()
    .expect("protocol");
    let m = &chamber.manifest;
    assert_eq!(m.set_temperatures_c().len(), 20);
    let t0 = Instant::now();
    let ideal = chamber.ideal(OutputKind::Increments);
    let t_ideal = t0.elapsed().as_secs_f64();
    let curve = chamber.temperature.curve().expect("temperature");
    let out = model.simulate(&ideal, &curve, 7).expect("simulate");
    let g = m.gravity_m_s2;
    // |f^b| of the trajectory in a static position is the manifest's gravity.
    let p = chamber.trajectory.point(
        m.position(-25.0, SignedAxis::POSITIONS[2])
            .map_or(0.0, |s| s.start_s + 1.0),
    );
    let f = p.imu_rates().1;
    assert!(((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() - g).abs() < 1e-14);

    let rel = |est: f64, truth: f64| (est - truth).abs() / truth.abs();
    let (mut worst_b, mut worst_sa, mut worst_sg) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_temp = 0.0f64;
    for set in m.set_temperatures_c() {
        for seg in m.segments.iter().filter(|s| {
            s.set_temperature_c == set && !matches!(s.kind, SegmentKind::Soak | SegmentKind::Move)
        }) {
            for &t in &out.temperature_c[seg.sample_range(FS)] {
                worst_temp = worst_temp.max((t - set).abs());
            }
        }
        for axis in BodyAxis::ALL {
            let k = axis.index();
            let up = m.position(set, SignedAxis::new(axis, true)).expect("up");
            let down = m.position(set, SignedAxis::new(axis, false)).expect("down");
            let f_up = segment_mean(&out, &out.accel[k], up);
            let f_down = segment_mean(&out, &out.accel[k], down);
            let b = 0.5 * (f_up + f_down);
            let s = (f_up - f_down) / (2.0 * g) - 1.0;
            let (bt, st) = (model.bias_at(3 + k, set), model.scale_factor_at(3 + k, set));
            worst_b = worst_b.max(rel(b, bt));
            worst_sa = worst_sa.max(rel(s, st));
            assert!(rel(b, bt) < 1e-9, "accel {k} bias at {set} °C: {b} vs {bt}");
            assert!(
                rel(s, st) < 1e-9,
                "accel {k} scale at {set} °C: {s} vs {st}"
            );

            let plus = m.rate(set, axis, true).expect("+w");
            let minus = m.rate(set, axis, false).expect("-w");
            let SegmentKind::Rate { rate_rad_s: w, .. } = plus.kind else {
                panic!("not a rate segment")
            };
            let wp = segment_mean(&out, &out.gyro[k], plus);
            let wm = segment_mean(&out, &out.gyro[k], minus);
            let sg = (wp - wm) / (2.0 * w) - 1.0;
            let sgt = model.scale_factor_at(k, set);
            worst_sg = worst_sg.max(rel(sg, sgt));
            assert!(
                rel(sg, sgt) < 1e-9,
                "gyro {k} scale at {set} °C: {sg} vs {sgt}"
            );
        }
    }
    eprintln!(
        "chamber: {} samples ({:.1} h), ideal increments {t_ideal:.2} s; max relative error: \
         accel bias {worst_b:.1e}, accel scale {worst_sa:.1e}, gyro scale {worst_sg:.1e}; \
         max |T - T_set| in test segments {worst_temp:.1e} °C",
        out.len(),
        m.duration_s / 3600.0
    );
    assert!(worst_temp < 1e-12);
}

/// The paper's analysis chain on one channel: phase → OADEV on log:100 → EDF-weighted fit
/// of N, B, K (as in tests/noise_recovery.rs).
fn fit_channel(y: &[f64]) -> NoiseFit {
    let dt = 1.0 / FS;
    let x = frequency_to_phase(y, dt);
    let n_phase = x.len();
    let ms = averaging_factors(&TauSpec::Log(100), dt, n_phase, Estimator::Oadev).expect("taus");
    let pts = oadev(&x, dt, &ms);
    let tau: Vec<f64> = pts.iter().map(|p| p.tau).collect();
    let avar: Vec<f64> = pts.iter().map(|p| p.dev * p.dev).collect();
    let m: Vec<usize> = pts.iter().map(|p| p.m).collect();
    let cfg = FitConfig {
        quantization: false,
        white: true,
        bias_instability: true,
        rate_random_walk: true,
        rate_ramp: false,
        gauss_markov: false,
    };
    fit_noise_with_edf(
        &tau,
        &avar,
        |i, alpha| ci::edf(Estimator::Oadev, alpha, m[i], n_phase),
        &cfg,
        0.683,
    )
    .expect("fit")
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

/// An 18-h, 100-Hz static six-axis log through the full sensor model (noise terms of the
/// `adis16465-like` preset only, thermal off, constant 25 °C, Earth rate and gravity in the
/// ideal input), analysed per channel: the fitted N, B, K recover the configured values
/// within the issue-2 tolerances (median |relative error| over the 12 channels of two
/// seeds: N 2 %, B 15 %, K 10 %).
#[test]
fn allan_analysis_recovers_noise_terms_of_the_sensor_model() {
    let cfg = Preset::Adis16465Like.config().noise_only();
    let model = SensorModel::new(cfg.clone()).expect("model");
    let site = Stationary {
        lat_rad: 51.08 * DEG,
        lon_rad: -114.13 * DEG,
        height_m: 1100.0,
        attitude: Euler {
            roll_rad: 0.0,
            pitch_rad: 0.0,
            yaw_rad: 30.0 * DEG,
        },
    };
    let (w, f) = site.point(0.0).imu_rates();
    let n = (18.0 * 3600.0 * FS) as usize;
    let input = IdealImu::constant(OutputKind::Rates, 0.0, 1.0 / FS, n, w, f);
    let temp = TemperatureProfile::constant(25.0)
        .curve()
        .expect("temperature");
    let truth = |a: usize| {
        if a < 3 {
            cfg.gyro.noise[a].clone()
        } else {
            cfg.accel.noise[a - 3].clone()
        }
    };
    let (mut en, mut eb, mut ek) = (Vec::new(), Vec::new(), Vec::new());
    let t0 = Instant::now();
    for seed in [11u64, 12] {
        let out = model.simulate(&input, &temp, seed).expect("simulate");
        let cols: Vec<&Vec<f64>> = out.gyro.iter().chain(out.accel.iter()).collect();
        let fits: Vec<NoiseFit> = cols.par_iter().map(|c| fit_channel(c)).collect();
        for (a, fit) in fits.iter().enumerate() {
            let t = truth(a);
            let v = |x: Option<Term>| x.map_or(0.0, |t| t.value);
            en.push((v(fit.white) / t.white - 1.0).abs());
            eb.push((v(fit.bias_instability) / t.bias_instability - 1.0).abs());
            ek.push((v(fit.rate_random_walk) / t.rate_random_walk - 1.0).abs());
        }
    }
    let (mn, mb, mk) = (median(en.clone()), median(eb.clone()), median(ek.clone()));
    eprintln!(
        "Allan recovery, 2 seeds x 6 channels x 18 h ({:.1} s): median |rel err| N {:.2} %, \
         B {:.2} %, K {:.2} % (max N {:.2} %, B {:.1} %, K {:.1} %)",
        t0.elapsed().as_secs_f64(),
        100.0 * mn,
        100.0 * mb,
        100.0 * mk,
        100.0 * en.iter().cloned().fold(0.0, f64::max),
        100.0 * eb.iter().cloned().fold(0.0, f64::max),
        100.0 * ek.iter().cloned().fold(0.0, f64::max),
    );
    assert!(mn < 0.02, "N median error {mn}");
    assert!(mb < 0.15, "B median error {mb}");
    assert!(mk < 0.10, "K median error {mk}");
}

/// Noise terms can come from a `driftless allan` noise-model file; a missing channel is
/// a clear error.
#[test]
fn noise_model_file_sets_the_six_axes() {
    let term = |v: f64| {
        Some(Term {
            value: v,
            lo: 0.9 * v,
            hi: 1.1 * v,
        })
    };
    let fit = |n: f64, b: f64| NoiseFit {
        quantization: None,
        white: term(n),
        bias_instability: term(b),
        rate_random_walk: None,
        rate_ramp: None,
        gauss_markov: None,
        confidence: 0.683,
        rms_log10_residual: 0.01,
        not_detected: Vec::new(),
        chi2_reduced: 1.0,
        n_points: 100,
        fit_range: None,
        not_identifiable: Vec::new(),
    };
    let mut model = NoiseModel::new(Some("test".into()), FS, Some("oadev".into()));
    for (a, name) in CHANNEL_NAMES.iter().enumerate() {
        let q = if a < 3 {
            Quantity::AngularRate
        } else {
            Quantity::SpecificForce
        };
        model.channels.push(ChannelNoise::new(
            name,
            q,
            fit(1e-4 * (a + 1) as f64, 1e-5),
            FS,
        ));
    }
    let text = model.to_toml_string().expect("toml");
    let back = NoiseModel::from_toml_str(&text).expect("parse");
    let mut cfg = SensorConfig::default();
    cfg.apply_noise_model(&back).expect("apply");
    assert_eq!(cfg.gyro.noise[1].white, 1e-4 * 2.0);
    assert_eq!(cfg.accel.noise[2].white, 1e-4 * 6.0);
    assert_eq!(cfg.accel.noise[0].bias_instability, 1e-5);
    assert_eq!(cfg.gyro.noise[0].rate_random_walk, 0.0);

    model.channels.retain(|c| c.name != "acc_y");
    let e = SensorConfig::default()
        .apply_noise_model(&model)
        .unwrap_err();
    assert!(
        matches!(&e, SensorSimError::MissingChannel { name, .. } if name == "acc_y"),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains("gyro_x, gyro_y, gyro_z, acc_x, acc_z"),
        "{e}"
    );
}

#[test]
fn bad_input_is_refused_with_clear_errors() {
    let input = IdealImu::constant(OutputKind::Rates, 0.0, 0.01, 1000, [0.0; 3], [0.0; 3]);
    let adi = SensorModel::new(Preset::AdiLike.config()).expect("model");

    // Temperature outside the thermal model's valid range (−25 … 70 °C): no extrapolation.
    let hot = TemperatureProfile::constant(75.0).curve().expect("curve");
    let e = adi.simulate(&input, &hot, 1).unwrap_err();
    assert!(
        matches!(e, SensorSimError::TemperatureOutOfRange { t_c, .. } if t_c == 75.0),
        "{e}"
    );
    let msg = e.to_string();
    assert!(msg.contains("75") && msg.contains("[-25, 70]"), "{msg}");
    // … also when only part of a profile leaves it: a warm-up that crosses 70 °C at
    // t = 600·ln 2 s.
    let warm = TemperatureProfile::WarmUp {
        t0_c: 20.0,
        t1_c: 120.0,
        tau_s: 600.0,
        start_s: 0.0,
    }
    .curve()
    .expect("curve");
    let long = IdealImu::constant(OutputKind::Rates, 0.0, 0.01, 60_000, [0.0; 3], [0.0; 3]);
    match adi.simulate(&long, &warm, 1) {
        Err(SensorSimError::TemperatureOutOfRange { t_c, t_s, .. }) => {
            assert!(t_c > 70.0 && t_c < 70.01, "{t_c}");
            assert!((t_s - 600.0 * 2f64.ln()).abs() < 0.02, "{t_s}");
        }
        other => panic!("expected out-of-range, got {other:?}"),
    }
    // A chamber run beyond the range.
    let e = ChamberConfig {
        temperatures_c: vec![60.0, 80.0],
        soak_s: 10.0,
        position_dwell_s: 1.0,
        move_s: 1.0,
        rate_deg_s: 360.0,
        spin_s: 1.0,
        rate_revolutions: 1,
        lag_tau_s: 1.0,
        ..Default::default()
    }
    .build()
    .and_then(|p| {
        let c = p.temperature.curve()?;
        adi.simulate(&p.ideal(OutputKind::Increments), &c, 1)
    })
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("outside the thermal model's valid range"),
        "{e}"
    );

    // Unknown preset.
    let e = "mpu6050".parse::<Preset>().unwrap_err().to_string();
    assert!(e.contains("unknown sensor preset 'mpu6050'"), "{e}");
    assert!(
        e.contains("adi-like, adis16465-like, consumer, tactical"),
        "{e}"
    );

    // Negative σ, NaN.
    let mut c = SensorConfig::default();
    c.accel.noise[1].bias_instability = -1e-5;
    let e = SensorModel::new(c).unwrap_err().to_string();
    assert!(
        e.contains("accel.noise[1].bias_instability = -0.00001"),
        "{e}"
    );
    let mut c = SensorConfig::default();
    c.gyro.turn_on_bias_sigma_rad_s[2] = -1.0;
    assert!(SensorModel::new(c).is_err());
    let mut c = SensorConfig::default();
    c.gyro.bias_poly_rad_s[0] = vec![0.0, f64::NAN];
    let e = SensorModel::new(c).unwrap_err().to_string();
    assert!(
        e.contains("gyro.bias_poly[0]") && e.contains("c1 is not finite"),
        "{e}"
    );
    let mut c = SensorConfig::default();
    c.gyro.noise[0].gauss_markov = Some(GaussMarkovConfig {
        sigma: f64::NAN,
        tau_c_s: 10.0,
    });
    assert!(SensorModel::new(c).is_err());
    let nan_in = IdealImu::constant(
        OutputKind::Rates,
        0.0,
        0.01,
        10,
        [f64::NAN, 0.0, 0.0],
        [0.0; 3],
    );
    let e = SensorModel::new(SensorConfig::default())
        .expect("model")
        .simulate(
            &nan_in,
            &TemperatureProfile::constant(20.0).curve().expect("c"),
            1,
        )
        .unwrap_err();
    assert!(e.to_string().contains("input.gyro[0] = NaN"), "{e}");

    // Lag τ ≤ 0.
    for tau in [0.0, -5.0] {
        let p = TemperatureProfile::Chamber {
            steps: vec![ChamberStep {
                set_c: 20.0,
                duration_s: 100.0,
            }],
            lag_tau_s: tau,
            initial_c: None,
            ramp_c_per_min: None,
        };
        let e = p.curve().unwrap_err().to_string();
        assert!(e.contains("lag_tau_s") && e.contains("> 0"), "{e}");
        let e = ChamberConfig {
            lag_tau_s: tau,
            ..Default::default()
        }
        .build()
        .unwrap_err()
        .to_string();
        assert!(e.contains("lag_tau_s"), "{e}");
    }

    // Non-increasing user series.
    let e = TemperatureProfile::Series {
        time_s: vec![0.0, 5.0, 4.0],
        t_c: vec![20.0, 21.0, 22.0],
    }
    .curve()
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("time_s[2] = 4") && e.contains("strictly increasing"),
        "{e}"
    );

    // Unknown TOML fields.
    assert!(toml::from_str::<SensorConfig>("[accel]\nbias_m_s2 = [0.1, 0.0, 0.0]\n").is_err());
    assert!(toml::from_str::<ChamberConfig>("soak_time_s = 10.0\n").is_err());
}

/// The same seed gives the same output; increments and rates agree for a static IMU.
#[test]
fn reproducible_and_rates_consistent_with_increments() {
    let model = SensorModel::new(Preset::Consumer.config().deterministic_only()).expect("model");
    let temp = TemperatureProfile::WarmUp {
        t0_c: 0.0,
        t1_c: 40.0,
        tau_s: 30.0,
        start_s: 0.0,
    }
    .curve()
    .expect("curve");
    let w = [1e-5, 2e-5, -3e-5];
    let f = [0.1, -0.2, -9.8];
    let n = 10_000;
    let rates = model
        .simulate(
            &IdealImu::constant(OutputKind::Rates, 0.005, 0.01, n, w, f),
            &temp,
            3,
        )
        .expect("rates");
    let inc = model
        .simulate(
            &IdealImu::constant(OutputKind::Increments, 0.01, 0.01, n, w, f),
            &temp,
            3,
        )
        .expect("increments");
    // Rates at the interval midpoints (same temperatures) times Δt = the increments.
    for k in [0, 17, n - 1] {
        for i in 0..3 {
            assert!((rates.gyro[i][k] * 0.01 - inc.gyro[i][k]).abs() < 1e-17);
            assert!((rates.accel[i][k] * 0.01 - inc.accel[i][k]).abs() < 1e-15);
        }
    }
    let full = SensorModel::new(Preset::Consumer.config()).expect("model");
    let a = full
        .simulate(
            &IdealImu::constant(OutputKind::Rates, 0.0, 0.01, n, w, f),
            &temp,
            5,
        )
        .expect("a");
    let b = full
        .simulate(
            &IdealImu::constant(OutputKind::Rates, 0.0, 0.01, n, w, f),
            &temp,
            5,
        )
        .expect("b");
    assert_eq!(a, b);
    let log = a.to_imu_log("simulated:consumer");
    assert_eq!(log.channels.len(), 7);
    assert_eq!(log.channel("temp").map(|c| c.values.len()), Some(n));
}

/// Speed: an 18-h, 100-Hz static six-axis log with every error term on (the `adi-like`
/// preset plus quantization noise, rate ramp and a Gauss-Markov term on every axis, a
/// warm-up temperature profile, temperature-sensor noise) — rates and increments.
#[test]
#[ignore = "timing figure; run with --ignored --nocapture"]
fn speed_18h_six_axis_all_terms() {
    let mut cfg = Preset::AdiLike.config();
    for nz in cfg.gyro.noise.iter_mut() {
        nz.quantization = 1e-6;
        nz.rate_ramp = 1e-9;
        nz.gauss_markov = Some(GaussMarkovConfig {
            sigma: 10.0 * DEG_PER_H,
            tau_c_s: 300.0,
        });
    }
    for nz in cfg.accel.noise.iter_mut() {
        nz.quantization = 1e-5;
        nz.rate_ramp = 1e-9;
        nz.gauss_markov = Some(GaussMarkovConfig {
            sigma: 1e-4,
            tau_c_s: 300.0,
        });
    }
    cfg.temperature_sensor.noise_sigma_c = 0.05;
    cfg.accel.increment_lsb_m_s = 1e-6;
    cfg.gyro.increment_lsb_rad = 1e-8;
    let model = SensorModel::new(cfg).expect("model");
    let temp = TemperatureProfile::WarmUp {
        t0_c: -20.0,
        t1_c: 60.0,
        tau_s: 1800.0,
        start_s: 0.0,
    }
    .curve()
    .expect("curve");
    let n = (18.0 * 3600.0 * FS) as usize;
    let (w, f) = ([7e-5, 0.0, -3e-5], [0.0, 0.0, -9.81]);
    for kind in [OutputKind::Rates, OutputKind::Increments] {
        let input = IdealImu::constant(kind, 0.01, 0.01, n, w, f);
        let t0 = Instant::now();
        let out = model.simulate(&input, &temp, 1).expect("simulate");
        let dt = t0.elapsed().as_secs_f64();
        eprintln!(
            "18 h x 100 Hz x 6 axes, all terms, {kind:?}: {dt:.2} s on {} threads ({} samples/axis)",
            rayon::current_num_threads(),
            out.len()
        );
    }
}

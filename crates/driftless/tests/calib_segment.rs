//! Segmentation from the data (`calib::segment`) against the simulator's manifest, on
//! simulated `adi-like` chamber and turntable recordings with every noise term, a 5-min
//! prefix before the protocol, dwells jittered ±30 % and (where said) one position
//! missed. Bar: every calibration parameter (six-position) or thermal coefficient (soak)
//! without the manifest within 1σ (the manifest run's σ) of the run with it, and the
//! missing position named with its time span.
//!
//! Figures print with `--nocapture`.

use driftless::calib::segment::{
    FindingKind, SegmentInput, SegmentOptions, Segmentation, SiteConstants, StaticRole, segment_log,
};
use driftless::calib::six_position::{SixPositionInput, SixPositionOptions, calibrate};
use driftless::sim::chamber::{
    BodyAxis, ChamberConfig, ChamberManifest, ChamberProtocol, SignedAxis, SkippedPosition,
};
use driftless::sim::presets::Preset;
use driftless::sim::sensor::{OutputKind, SensorModel, SensorOutput};
use driftless::thermal::FitOptions;
use driftless::thermal::soak::soak_calibration;

const PLUS_X: SignedAxis = SignedAxis::new(BodyAxis::X, true);

/// A short protocol with the session variants: 5-min prefix, ±30 % dwells, 10-s
/// positions, one revolution at ±90 °/s, sensor lag 20 s against a 200-s soak.
fn protocol(temperatures_c: Vec<f64>, skip: Option<f64>, seed: u64) -> ChamberProtocol {
    ChamberConfig {
        temperatures_c,
        soak_s: 200.0,
        lag_tau_s: 20.0,
        position_dwell_s: 10.0,
        move_s: 2.0,
        rate_deg_s: 90.0,
        rate_revolutions: 1,
        spin_s: 1.0,
        sample_rate_hz: 100.0,
        prefix_s: 300.0,
        dwell_jitter: 0.3,
        jitter_seed: seed,
        skip_positions: skip
            .map(|t| SkippedPosition {
                set_temperature_c: t,
                up: PLUS_X,
            })
            .into_iter()
            .collect(),
        ..ChamberConfig::default()
    }
    .build()
    .expect("protocol")
}

fn simulate(p: &ChamberProtocol, seed: u64) -> SensorOutput {
    let model = SensorModel::new(Preset::AdiLike.config()).expect("model");
    let curve = p.temperature.curve().expect("temperature");
    model
        .simulate(&p.ideal(OutputKind::Rates), &curve, seed)
        .expect("simulate")
}

fn site(m: &ChamberManifest) -> SiteConstants {
    SiteConstants {
        latitude_deg: m.latitude_deg,
        longitude_deg: m.longitude_deg,
        height_m: m.height_m,
        gravity_m_s2: None,
    }
}

fn segment(out: &SensorOutput) -> Segmentation {
    let time: Vec<f64> = (0..out.len()).map(|k| out.time_s(k)).collect();
    let inp = SegmentInput {
        time_s: &time,
        accel_m_s2: out.accel.each_ref().map(Vec::as_slice),
        gyro_rad_s: out.gyro.each_ref().map(Vec::as_slice),
        temperature_c: Some(&out.temperature_c),
        nominal_temperature_c: 25.0,
    };
    let t = std::time::Instant::now();
    let s = segment_log(&inp, &SegmentOptions::default()).expect("segment");
    eprintln!(
        "segmented {} samples in {:.3} s: {} statics, {} rotations, {} plateaus, {} findings",
        out.len(),
        t.elapsed().as_secs_f64(),
        s.statics.len(),
        s.rotations.len(),
        s.plateaus.len(),
        s.findings.len()
    );
    s
}

fn cols(out: &SensorOutput) -> ([&[f64]; 3], [&[f64]; 3]) {
    (
        out.accel.each_ref().map(Vec::as_slice),
        out.gyro.each_ref().map(Vec::as_slice),
    )
}

/// |Δ|/σ of the 24 parameters (M and b of both triads) and the largest.
fn six_position_z(p: &ChamberProtocol, out: &SensorOutput, seg: &Segmentation) -> f64 {
    let (accel, gyro) = cols(out);
    let m = &p.manifest;
    let opts = SixPositionOptions::from_manifest(m);
    let with = calibrate(
        &SixPositionInput::from_manifest_columns(m, accel, gyro, 1.0, 25.0).expect("input"),
        &opts,
    )
    .expect("calibrate");
    let (dm, _) = seg
        .six_position_manifest(None, &site(m))
        .expect("detected manifest");
    let set = dm.set_temperatures_c()[0];
    assert!((set - 25.0).abs() < 1e-3, "{set}");
    let dopts = SixPositionOptions::from_manifest(&dm);
    assert_eq!(dopts.estimate_g_sensitivity, opts.estimate_g_sensitivity);
    assert!((dopts.gravity_m_s2 - opts.gravity_m_s2).abs() < 1e-12);
    let without = calibrate(
        &SixPositionInput::from_manifest_columns(&dm, accel, gyro, 1.0, set).expect("input"),
        &dopts,
    )
    .expect("calibrate");
    let mut worst: f64 = 0.0;
    for (a, b) in [(&with.accel, &without.accel), (&with.gyro, &without.gyro)] {
        let (sb, sm) = (a.bias_sigma(), a.matrix_sigma());
        for i in 0..3 {
            worst = worst.max((a.calibration.bias[i] - b.calibration.bias[i]).abs() / sb[i]);
            for (j, s) in sm[i].iter().enumerate() {
                worst = worst
                    .max((a.calibration.matrix.0[i][j] - b.calibration.matrix.0[i][j]).abs() / s);
            }
        }
    }
    worst
}

#[test]
fn six_position_without_manifest_matches_the_manifest() {
    for seed in 1..=3 {
        let p = protocol(vec![25.0], None, seed);
        let out = simulate(&p, seed);
        let seg = segment(&out);
        // The prefix: one soak without a position (home), one tilted static ("other").
        assert!(seg.statics.iter().any(|s| s.role == StaticRole::Other));
        assert_eq!(seg.steps().len(), 1);
        assert!(seg.plateaus[seg.steps()[0]].complete());
        assert!(
            !seg.findings
                .iter()
                .any(|f| matches!(f.kind, FindingKind::MissingPosition { .. })),
            "{:?}",
            seg.findings
        );
        let z = six_position_z(&p, &out, &seg);
        eprintln!("seed {seed}: six-position, largest |Δ|/σ over 24 parameters {z:.3}");
        assert!(z <= 1.0, "seed {seed}: {z}");
    }
}

#[test]
fn six_position_missing_position_is_named() {
    let p = protocol(vec![25.0], Some(25.0), 4);
    let out = simulate(&p, 4);
    let seg = segment(&out);
    let f: Vec<_> = seg
        .findings
        .iter()
        .filter(|f| matches!(f.kind, FindingKind::MissingPosition { .. }))
        .collect();
    assert_eq!(f.len(), 1, "{:?}", seg.findings);
    assert!(matches!(f[0].kind, FindingKind::MissingPosition { up, .. } if up == PLUS_X));
    let e = seg
        .six_position_manifest(None, &site(&p.manifest))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no static position with +x up"), "{e}");
    // The plateau's span: the whole log (one temperature).
    assert!(e.contains("0.00–"), "{e}");
}

/// The manifest without the steps at `t_c` (their six-position fit cannot run).
fn without_step(m: &ChamberManifest, t_c: f64) -> ChamberManifest {
    let mut m = m.clone();
    m.segments.retain(|s| s.set_temperature_c != t_c);
    m
}

#[test]
fn soak_without_manifest_matches_the_manifest() {
    let temps = vec![-10.0, 5.0, 20.0, 35.0, 50.0, 65.0];
    let missing_at = 35.0;
    // Order 3, the order of the preset's polynomials: with a lower order the fit is
    // misspecified (residuals ≫ σ) and its coefficients hinge on the weights, not only
    // on the data the segmentation picks.
    let fit_opts = FitOptions {
        order: 3,
        t_ref_c: 25.0,
        ..FitOptions::default()
    };
    let mut worst_all: f64 = 0.0;
    for seed in 1..=2 {
        let p = protocol(temps.clone(), Some(missing_at), seed);
        let out = simulate(&p, seed);
        let seg = segment(&out);
        // Six steps found, each at its set temperature; the one missing +x is named.
        let steps = seg.steps();
        let found: Vec<f64> = steps
            .iter()
            .map(|&i| seg.plateaus[i].temperature_c)
            .collect();
        assert_eq!(found.len(), temps.len(), "{found:?}");
        for (a, b) in found.iter().zip(&temps) {
            assert!((a - b).abs() < 0.01, "{found:?}");
        }
        assert!(steps.iter().all(|&i| seg.plateaus[i].settled));
        let missing: Vec<_> = seg
            .findings
            .iter()
            .filter_map(|f| match f.kind {
                FindingKind::MissingPosition { up, plateau } => Some((up, plateau, f)),
                _ => None,
            })
            .collect();
        assert_eq!(missing.len(), 1, "{:?}", seg.findings);
        let (up, plateau, f) = missing[0];
        assert_eq!(up, PLUS_X);
        assert!((seg.plateaus[plateau].temperature_c - missing_at).abs() < 0.01);
        // Its time span covers the step of the manifest.
        let step = p
            .manifest
            .segments
            .iter()
            .filter(|s| s.set_temperature_c == missing_at)
            .fold((f64::INFINITY, 0.0f64), |(a, b), s| {
                (a.min(s.start_s), b.max(s.end_s))
            });
        assert!(
            f.start_s <= step.0 + 5.0 && f.end_s >= step.1 - 5.0,
            "{f:?} vs {step:?}"
        );
        assert!(f.message.contains("+x up"), "{}", f.message);
        // No other finding but the inferred table rate (the prefix's 35° tilt is "other").
        assert!(
            seg.findings.iter().all(|f| matches!(
                f.kind,
                FindingKind::MissingPosition { .. } | FindingKind::RateInferred { .. }
            )),
            "{:?}",
            seg.findings
        );
        let (accel, gyro) = cols(&out);
        let reference = without_step(&p.manifest, missing_at);
        let with = soak_calibration(
            &reference,
            accel,
            gyro,
            1.0,
            &SixPositionOptions::from_manifest(&reference),
            &fit_opts,
            None,
        )
        .expect("soak with manifest");
        let (dm, dropped) = seg.soak_manifest(&site(&p.manifest)).expect("manifest");
        assert_eq!(dropped.len(), 1);
        let without = soak_calibration(
            &dm,
            accel,
            gyro,
            1.0,
            &SixPositionOptions::from_manifest(&dm),
            &fit_opts,
            None,
        )
        .expect("soak without manifest");
        let mut worst: (f64, String) = (0.0, String::new());
        for a in &with.series {
            let b = without
                .get(a.triad, a.quantity, a.axis)
                .expect("same series");
            for (k, ((ca, cb), s)) in a
                .fit
                .coeffs
                .iter()
                .zip(&b.fit.coeffs)
                .zip(&a.fit.std_errors)
                .enumerate()
            {
                let z = (ca - cb).abs() / s;
                if z > worst.0 {
                    worst = (z, format!("{} {} {} c{k}", a.triad, a.quantity, a.axis));
                }
            }
        }
        eprintln!(
            "seed {seed}: soak, largest |Δ|/σ over {} coefficients {:.3} ({})",
            with.series.len() * 4,
            worst.0,
            worst.1
        );
        assert!(worst.0 <= 1.0, "seed {seed}: {} {}", worst.0, worst.1);
        worst_all = worst_all.max(worst.0);
    }
    eprintln!("soak: worst |Δ|/σ over seeds {worst_all:.3}");
}

//! The ramp method on a simulated static consumer-grade IMU (500 Hz) warming 20 → 60 °C
//! and cooling back, its temperature sensor quantised to 1 °C (the autopilots' pain), with
//! deterministic errors and white noise: the fitted bias change b(T) − b(25 °C) of each
//! gyro axis against the truth, the hysteresis (none simulated), and bad input.

use driftless::sim::presets::Preset;
use driftless::sim::sensor::{IdealImu, OutputKind, SensorModel};
use driftless::sim::temperature::TemperatureProfile;
use driftless::thermal::ramp::{RampError, RampOptions, ramp_calibration};

#[test]
fn warm_up_and_cool_down_with_one_degree_readings() {
    let mut cfg = Preset::Consumer.config();
    for n in cfg.gyro.noise.iter_mut().chain(cfg.accel.noise.iter_mut()) {
        n.bias_instability = 0.0;
        n.rate_random_walk = 0.0;
        n.gauss_markov = None;
    }
    cfg.temperature_sensor.lsb_c = 1.0;
    cfg.valid_range_c = [-40.0, 85.0];
    let model = SensorModel::new(cfg).expect("model");
    // 20 → 60 °C over 30 min, then back over 30 min, at an uneven rate. Sampled at
    // 500 Hz, as such sensors are read: the per-sample white noise (0.06 °/s, ~1 LSB of
    // the ±2000 °/s 16-bit output) dithers the quantisation, so bin means resolve
    // sub-LSB bias changes (at 20 Hz, 0.2 LSB of noise, they do not: errors of ~0.2 LSB).
    let profile = TemperatureProfile::Series {
        time_s: vec![0.0, 150.0, 600.0, 1800.0, 2000.0, 2500.0, 3600.0],
        t_c: vec![20.0, 30.0, 50.0, 60.0, 55.0, 35.0, 20.0],
    };
    let curve = profile.curve().expect("curve");
    let rate = 500.0;
    let n = (3600.0 * rate) as usize;
    let ideal = IdealImu::constant(
        OutputKind::Rates,
        0.0,
        1.0 / rate,
        n,
        [1e-5, 2e-5, -6e-5],
        [0.0, 0.0, -9.80],
    );
    let out = model.simulate(&ideal, &curve, 77).expect("simulate");
    let time: Vec<f64> = (0..n).map(|k| out.time_s(k)).collect();
    let chans: Vec<(&str, &[f64])> = vec![
        ("gyro_x", &out.gyro[0]),
        ("gyro_y", &out.gyro[1]),
        ("gyro_z", &out.gyro[2]),
    ];
    let r =
        ramp_calibration(&time, &out.temperature_c, &chans, &RampOptions::default()).expect("ramp");
    let heating = r.points.iter().filter(|p| p.heating).count();
    eprintln!(
        "{} bin points ({heating} heating, {} cooling); hysteresis RMS (rad/s) {:?}",
        r.points.len(),
        r.points.len() - heating,
        r.hysteresis
    );
    assert!(heating >= 30 && r.points.len() - heating >= 30);
    let grid: Vec<f64> = (20..=60).map(f64::from).collect();
    for (k, f) in r.fits.iter().enumerate() {
        let truth: Vec<f64> = grid
            .iter()
            .map(|&t| model.bias_at(k, t) - model.bias_at(k, 25.0))
            .collect();
        let fitted: Vec<f64> = grid.iter().map(|&t| f.eval(t) - f.eval(25.0)).collect();
        let swing = truth.iter().cloned().fold(f64::MIN, f64::max)
            - truth.iter().cloned().fold(f64::MAX, f64::min);
        let rms = (truth
            .iter()
            .zip(&fitted)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / grid.len() as f64)
            .sqrt();
        eprintln!(
            "gyro {}: thermal bias swing {swing:.3e} rad/s, fit error RMS {rms:.3e} ({:.2} %)",
            ["x", "y", "z"][k],
            100.0 * rms / swing
        );
        assert!(rms <= 0.02 * swing, "axis {k}: {rms} vs swing {swing}");
    }
    let h = r.hysteresis.as_ref().expect("both directions");
    for (k, v) in h.iter().enumerate() {
        let swing = (model.bias_at(k, 60.0) - model.bias_at(k, 20.0)).abs();
        assert!(
            *v <= 0.02 * swing,
            "axis {k}: hysteresis {v} with none simulated"
        );
    }
}

#[test]
fn ramp_bad_input() {
    let t: Vec<f64> = (0..1000).map(|i| i as f64).collect();
    let mut temp: Vec<f64> = (0..1000).map(|i| 20.0 + i as f64 * 0.01).collect();
    let y = vec![0.0; 1000];
    let ch: Vec<(&str, &[f64])> = vec![("gyro_x", &y)];
    // 10 °C of ramp at 100 samples per bin: 11 bins — enough for a cubic
    assert!(ramp_calibration(&t, &temp, &ch, &RampOptions::default()).is_ok());
    // only 3 bins of ≥ 50 samples
    let short: Vec<f64> = (0..1000).map(|i| 20.0 + i as f64 * 0.002).collect();
    assert!(matches!(
        ramp_calibration(&t, &short, &ch, &RampOptions::default()),
        Err(RampError::TooFewBins { .. })
    ));
    temp[500] = f64::NAN;
    let e = ramp_calibration(&t, &temp, &ch, &RampOptions::default()).unwrap_err();
    assert!(e.to_string().contains("sample 500") && e.to_string().contains("temperature"));
    assert!(matches!(
        ramp_calibration(&t[..10], &temp, &ch, &RampOptions::default()),
        Err(RampError::BadInput(_))
    ));
}

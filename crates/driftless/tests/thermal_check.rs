//! `thermal::check` on synthetic recordings of a static IMU warming up: a clean ramp is
//! fit for the ramp method and flagged for nothing; 1 °C quantisation, too little rise,
//! uneven heating, motion during the ramp and time gaps are each flagged, and only what
//! cannot give a model blocks. A simulated chamber soak with six positions per set
//! temperature is fit for the soak method and not for the ramp.

use driftless::io::{Channel, ImuLog, Quantity, TimeGap};
use driftless::sim::rng::Rng;
use driftless::thermal::check::{
    CheckOptions, FindingKind, Impact, ThermalCheck, check_log, out_of_range_spans,
};

const RATE_HZ: f64 = 50.0;

fn channel(name: &str, q: Quantity, values: Vec<f64>) -> Channel {
    Channel {
        name: name.into(),
        quantity: q,
        source_unit: q.si_unit().into(),
        values,
    }
}

/// A static IMU (z up) for `duration_s` at `RATE_HZ`, temperature `temp(t)` read with
/// resolution `lsb_c`, gyro bias drifting 2e-4 rad/s/°C, white noise, and `motion(t)`
/// (added rate rad/s about x, and tilt about x, rad).
fn log(
    duration_s: f64,
    temp: impl Fn(f64) -> f64,
    lsb_c: f64,
    motion: impl Fn(f64) -> (f64, f64),
    seed: u64,
) -> ImuLog {
    let n = (duration_s * RATE_HZ) as usize;
    let mut rng = Rng::seed_from_u64(seed);
    let time: Vec<f64> = (0..n).map(|k| k as f64 / RATE_HZ).collect();
    let mut ch: Vec<Vec<f64>> = (0..7).map(|_| Vec::with_capacity(n)).collect();
    for &t in &time {
        let tc = temp(t);
        let (w, tilt) = motion(t);
        let b = 2e-4 * (tc - 25.0);
        ch[0].push(0.01 + b + w + 1e-3 * rng.normal());
        ch[1].push(-0.005 + b + 1e-3 * rng.normal());
        ch[2].push(0.002 + 1e-3 * rng.normal());
        ch[3].push(0.05 + 0.02 * rng.normal());
        ch[4].push(9.80665 * tilt.sin() + 0.02 * rng.normal());
        ch[5].push(-9.80665 * tilt.cos() + 0.02 * rng.normal());
        let read = tc + 0.01 * rng.normal();
        ch[6].push(if lsb_c > 0.0 {
            (read / lsb_c).round() * lsb_c
        } else {
            read
        });
    }
    imu_log(time, ch)
}

/// A log of gyro x, y, z, accelerometer x, y, z and temperature columns (SI, °C).
fn imu_log(time: Vec<f64>, ch: Vec<Vec<f64>>) -> ImuLog {
    let names = [
        "gyro_x",
        "gyro_y",
        "gyro_z",
        "acc_x",
        "acc_y",
        "acc_z",
        "temperature",
    ];
    let channels = ch
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            let q = match i {
                0..=2 => Quantity::AngularRate,
                3..=5 => Quantity::SpecificForce,
                _ => Quantity::Temperature,
            };
            channel(names[i], q, v)
        })
        .collect();
    ImuLog::new("synthetic", Some(time), 1.0 / RATE_HZ, channels)
}

/// 20 → 50 °C linearly over 40 min.
fn linear(t: f64) -> f64 {
    20.0 + 30.0 * t / 2400.0
}

fn still(_: f64) -> (f64, f64) {
    (0.0, 0.0)
}

fn check(l: &ImuLog) -> ThermalCheck {
    let c = check_log(l, "synthetic", &CheckOptions::default());
    for f in &c.findings {
        eprintln!(
            "{:?} ramp {:?} soak {:?}: {}",
            f.kind, f.ramp, f.soak, f.message
        );
    }
    c
}

#[test]
fn clean_linear_ramp_is_fit_for_ramp_and_flags_nothing_else() {
    let c = check(&log(2400.0, linear, 0.01, still, 1));
    assert!(c.fit_for_ramp, "{:?}", c.findings);
    assert!(!c.fit_for_soak, "no plateaus, one orientation");
    assert_eq!(c.verdict(), "ramp");
    let t = c.temperature.as_ref().unwrap();
    assert!((t.rise_c - 30.0).abs() < 0.5, "rise {}", t.rise_c);
    assert!((t.lsb_c - 0.01).abs() < 1e-9, "lsb {}", t.lsb_c);
    let h = c.heating.as_ref().unwrap();
    assert!((h.rate_median_c_per_min - 0.75).abs() < 0.02, "{h:?}");
    assert!(h.unevenness < 1.5, "{}", h.unevenness);
    assert!(h.heating_fraction > 0.95);
    assert_eq!(c.motion.as_ref().unwrap().moving_fraction, 0.0);
    // Nothing but the soak's own needs is flagged.
    for f in &c.findings {
        assert_eq!(f.ramp, Impact::None, "{f:?}");
    }
}

#[test]
fn one_degree_quantisation_is_flagged_but_does_not_block() {
    let c = check(&log(2400.0, linear, 1.0, still, 2));
    let f = c.finding(FindingKind::CoarseResolution).expect("flagged");
    assert_eq!(f.ramp, Impact::Warn);
    assert!(f.message.contains("1.000 °C"), "{}", f.message);
    assert!((c.temperature.as_ref().unwrap().lsb_c - 1.0).abs() < 1e-12);
    // Quantisation alone is not mistaken for uneven heating (window ≥ 5 LSB of change).
    assert!(c.finding(FindingKind::UnevenHeating).is_none());
    assert!(c.fit_for_ramp);
}

#[test]
fn too_little_rise_blocks_both_methods() {
    let c = check(&log(2400.0, |t| 30.0 + 6.0 * t / 2400.0, 0.01, still, 3));
    let f = c.finding(FindingKind::TooLittleRise).expect("flagged");
    assert_eq!((f.ramp, f.soak), (Impact::Block, Impact::Block));
    assert!(f.message.contains("at least 10.0 °C"), "{}", f.message);
    assert_eq!(c.verdict(), "neither");
}

#[test]
fn uneven_heating_is_flagged() {
    // Fast to 40 °C in 5 min, then 10 °C over the next 35 min: rates differ ~ 20×.
    let uneven = |t: f64| {
        if t < 300.0 {
            20.0 + 20.0 * t / 300.0
        } else {
            40.0 + 10.0 * (t - 300.0) / 2100.0
        }
    };
    let c = check(&log(2400.0, uneven, 0.01, still, 4));
    let f = c.finding(FindingKind::UnevenHeating).expect("flagged");
    assert_eq!(f.ramp, Impact::Warn);
    assert!(c.heating.as_ref().unwrap().unevenness > 5.0);
    assert!(c.fit_for_ramp);
}

#[test]
fn motion_during_the_ramp_blocks_it_and_names_the_span() {
    // Picked up at 1200 s for 30 s: turned 40° about x and back, 0.5 rad/s.
    let handled = |t: f64| {
        if (1200.0..1230.0).contains(&t) {
            let tilt = 0.7 * ((t - 1200.0) / 30.0 * std::f64::consts::PI).sin();
            (
                0.5 * ((t - 1200.0) / 30.0 * 2.0 * std::f64::consts::PI).cos(),
                tilt,
            )
        } else {
            (0.0, 0.0)
        }
    };
    let c = check(&log(2400.0, linear, 0.01, handled, 5));
    let f = c.finding(FindingKind::Motion).expect("flagged");
    assert_eq!(f.ramp, Impact::Block);
    let span = f.span.expect("span");
    assert!(
        span.start_s >= 1198.0 && span.start_s <= 1202.0 && span.end_s <= 1232.0,
        "{span:?}"
    );
    assert!(f.message.contains("1200.0"), "{}", f.message);
    assert!(!c.fit_for_ramp);
    // A brief bump (one second) is tolerated with a warning.
    let bump = |t: f64| {
        if (600.0..601.0).contains(&t) {
            (0.3, 0.0)
        } else {
            (0.0, 0.0)
        }
    };
    let c = check(&log(2400.0, linear, 0.01, bump, 6));
    assert_eq!(
        c.finding(FindingKind::Motion).map(|f| f.ramp),
        Some(Impact::Warn)
    );
    assert!(c.fit_for_ramp);
}

#[test]
fn gaps_are_reported_with_the_temperature_jump() {
    let mut l = log(2400.0, linear, 0.01, still, 7);
    // Cut 120 s (1.5 °C) out of the middle.
    let (a, b) = ((1000.0 * RATE_HZ) as usize, (1120.0 * RATE_HZ) as usize);
    let time: Vec<f64> = l.time_s.take().unwrap();
    let keep = |v: &Vec<f64>| -> Vec<f64> { v[..a].iter().chain(&v[b..]).copied().collect() };
    for c in &mut l.channels {
        c.values = keep(&c.values);
    }
    l.time_s = Some(keep(&time));
    l.gaps = vec![TimeGap {
        index: a,
        start_s: time[a - 1],
        duration_s: time[b] - time[a - 1],
    }];
    let c = check(&l);
    let f = c.finding(FindingKind::Gaps).expect("flagged");
    assert_eq!(f.ramp, Impact::Warn);
    assert!(
        (c.gaps.max_temperature_jump_c - 1.5).abs() < 0.1,
        "{:?}",
        c.gaps
    );
    assert!(f.message.contains("bins are missing"), "{}", f.message);
}

#[test]
fn no_temperature_and_bad_temperature_are_clear() {
    let mut l = log(100.0, linear, 0.01, still, 8);
    l.channels[6].values[37] = f64::NAN;
    let c = check(&l);
    let f = c.finding(FindingKind::BadTemperature).expect("flagged");
    assert!(
        f.message.contains("sample 37") && f.message.contains("0.740 s"),
        "{}",
        f.message
    );
    assert_eq!(c.verdict(), "neither");
    l.channels.pop();
    let c = check(&l);
    assert!(c.finding(FindingKind::NoTemperature).is_some());
    assert_eq!(c.verdict(), "neither");
}

/// A soak-like recording: 6 plateaus 0…50 °C, each held 8 min, the board turned through
/// its six faces (60 s each) on every plateau; 4 min transitions.
#[test]
fn six_positions_on_plateaus_are_fit_for_soak_not_ramp() {
    let hold = 480.0;
    let trans = 240.0;
    let step = hold + trans;
    let temp = move |t: f64| {
        let i = (t / step).floor();
        let u = t - i * step;
        let base = 10.0 * i;
        if u < hold {
            base
        } else {
            base + 10.0 * (u - hold) / trans
        }
    };
    let n = (6.0 * step * RATE_HZ) as usize;
    let mut rng = Rng::seed_from_u64(9);
    let faces: [[f64; 3]; 6] = [
        [0.0, 0.0, -1.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let time: Vec<f64> = (0..n).map(|k| k as f64 / RATE_HZ).collect();
    let mut ch: Vec<Vec<f64>> = (0..7).map(|_| Vec::with_capacity(n)).collect();
    for &t in &time {
        let u = t - (t / step).floor() * step;
        let f = if u < hold {
            faces[((u / 60.0) as usize).min(5)]
        } else {
            faces[0]
        };
        for k in 0..3 {
            ch[k].push(1e-3 * rng.normal());
            ch[3 + k].push(9.80665 * f[k] + 0.02 * rng.normal());
        }
        ch[6].push(temp(t));
    }
    let l = imu_log(time, ch);
    let c = check(&l);
    let h = c.heating.as_ref().unwrap();
    assert_eq!(h.plateaus.len(), 6, "{:?}", h.plateaus);
    assert!(
        h.plateaus.iter().all(|p| p.orientations == 6),
        "{:?}",
        h.plateaus
    );
    assert!(c.fit_for_soak, "{:?}", c.findings);
    assert!(!c.fit_for_ramp, "turned between faces");
    assert_eq!(c.verdict(), "soak");
}

#[test]
fn out_of_range_spans_name_time_and_temperature() {
    let t: Vec<f64> = (0..10).map(|k| k as f64).collect();
    let temp = [
        20.0,
        24.0,
        26.0,
        27.0,
        25.0,
        30.0,
        31.0,
        30.0,
        f64::NAN,
        22.0,
    ];
    let e = out_of_range_spans(Some(&t), 1.0, &temp, [21.0, 29.0]);
    assert_eq!(e.len(), 2);
    assert_eq!(
        (e[0].span.start_s, e[0].span.end_s, e[0].samples),
        (0.0, 0.0, 1)
    );
    assert_eq!(
        (e[1].span.start_s, e[1].span.end_s, e[1].samples),
        (5.0, 8.0, 4)
    );
    assert_eq!((e[1].min_c, e[1].max_c), (30.0, 31.0));
    assert!(e[1].describe().contains("5.0–8.0 s"), "{}", e[1].describe());
    assert!(out_of_range_spans(None, 0.5, &[22.0, 23.0], [21.0, 29.0]).is_empty());
}

/// The product's simulator: a consumer IMU (every noise term) warming 20 → 60 °C and
/// cooling back at an uneven rate, its temperature read in 1 °C steps (the ramp of
/// `tests/thermal_ramp.rs`, at 50 Hz): coarse resolution and uneven heating are flagged
/// as warnings, the ramp stays possible (its binning handles both), and no motion is
/// seen on the static sensor whose bias drifts with temperature.
#[test]
fn simulated_quantised_uneven_ramp_is_flagged_and_fit() {
    use driftless::sim::presets::Preset;
    use driftless::sim::sensor::{IdealImu, OutputKind, SensorModel};
    use driftless::sim::temperature::TemperatureProfile;
    let mut cfg = Preset::Consumer.config();
    cfg.temperature_sensor.lsb_c = 1.0;
    cfg.valid_range_c = [-40.0, 85.0];
    let model = SensorModel::new(cfg).expect("model");
    let curve = TemperatureProfile::Series {
        time_s: vec![0.0, 150.0, 600.0, 1800.0, 2000.0, 2500.0, 3600.0],
        t_c: vec![20.0, 30.0, 50.0, 60.0, 55.0, 35.0, 20.0],
    }
    .curve()
    .expect("curve");
    let n = (3600.0 * RATE_HZ) as usize;
    let ideal = IdealImu::constant(
        OutputKind::Rates,
        0.0,
        1.0 / RATE_HZ,
        n,
        [1e-5, 2e-5, -6e-5],
        [0.0, 0.0, -9.80],
    );
    let out = model.simulate(&ideal, &curve, 77).expect("simulate");
    let time: Vec<f64> = (0..n).map(|k| out.time_s(k)).collect();
    let mut ch: Vec<Vec<f64>> = out.gyro.iter().chain(&out.accel).cloned().collect();
    ch.push(out.temperature_c.clone());
    let c = check(&imu_log(time, ch));
    assert!(c.finding(FindingKind::CoarseResolution).is_some());
    assert!(c.finding(FindingKind::UnevenHeating).is_some());
    assert!(c.finding(FindingKind::Motion).is_none());
    let h = c.heating.as_ref().unwrap();
    assert!(
        h.heating_fraction > 0.3 && h.cooling_fraction > 0.3,
        "{h:?}"
    );
    assert!(c.fit_for_ramp, "{:?}", c.findings);
}

//! The soak method on simulated `adi-like` chamber data (recovery of the truth):
//! −25…70 °C in 5 °C steps, soak, six positions and ±ω rate-table segments per step.
//! Bar: fitted bias and scale-factor curves within 2 % of each curve's swing (RMS over the
//! range) of the truth, and the truth inside the reported 95 % band at ≥ 90 % of the
//! temperatures.
//!
//! **The truth.** Scale factor: 1 + s(T). Bias: the bias at the start of the run plus b(T)
//! — the estimand of [`driftless::thermal::soak`]. "At the start" is the turn-on bias plus
//! the flicker in effect over the first step's static positions: the components of the
//! bias-instability process slower than a step are constant over the run, and no
//! measurement can tell them from the turn-on bias (σ ≈ 1.5·B here, 0.7 % of the
//! accelerometer-z bias swing). The rate random walk since power-on is *not* in the
//! truth: a protocol controls it by measuring early, so it counts as error. Every run
//! also prints the figures against turn-on + b(T) alone, which counts the flicker at the
//! start as error too.
//!
//! * `deterministic_and_white_noise`: the preset's deterministic errors, turn-on biases
//!   and white noise, temperatures ascending (worst 0.60 % of swing, gyro scale x; band
//!   coverage 92.1 %). The six-position fits estimate the gyro g-sensitivity G (the
//!   default of `SixPositionOptions::from_manifest` on six-position steps). Without it,
//!   the rate-table segments, all turned with +k up, carry b_i + g·G_ik into the bias
//!   fit, and the worst curve was gyro bias z at 1.37 % (coverage 93.3 %).
//! * `every_noise_term`: every noise term of the preset, on the recommended protocol
//!   (`RECOMMENDED`). The terms include bias instability B and rate random walk
//!   (K = 160 °/h/√h gyro, 1.3e-4 m/s²/√s accel: ≈ 2.0e-3 rad/s and 0.020 m/s² over
//!   the 6.4-h protocol, 5.6 % of the gyro-z and 4.9 % of the accelerometer-z bias
//!   swing). The protocol:
//!   - the 25 °C reference first, measured 10 s after power-on at ambient, so the rate
//!     random walk since turn-on stays out of every bias value;
//!   - the other temperatures interleaved (k·7 mod 20), so the drift is not a smooth
//!     function of temperature; ascending, the worst curve was 2.4–8.3 % over 8 seeds;
//!   - 25 °C again at the end;
//!   - the palindromic order (`StepOrder::Palindromic`): ± visits centred on one
//!     instant, so a linear drift cancels in the scale factors;
//!   - three position cycles per step (`ChamberConfig::position_cycles`): the flicker
//!     between adjacent ± visits, flat in averaging time, averages down as 1/√cycles;
//!   - the bias series fitted by generalised least squares with the drift covariance
//!     from the Allan terms (`SoakDrift`): without it the band coverage was 67.5 %.
//!
//!   Seeds 1–3 are asserted. Over seeds 1…48 (`measure_recommended_protocol`) the worst
//!   of the 12 curves is **0.65 / 1.02 / 1.63 %** of its swing (min / median / max; none
//!   above 2 %), coverage 95.0–100 %. Against turn-on + b(T) alone it is 0.77 / 1.36 /
//!   2.96 % and coverage 83.3–100 %: the rest is the flicker at the start (seed 12:
//!   accelerometer-z flicker of −6.2e-3 m/s² over the first step, 3.2·B).
//! * `every_noise_term_plain_protocol`: one palindrome per step, full first soak, no
//!   revisit. The band coverage and the thermal part of every bias curve,
//!   Δb(T) = b(T) − b(25 °C), are asserted; the curves themselves miss the bar on some
//!   seeds (table).
//!
//! Protocols measured by `measure_protocols` over seeds 1…12, G estimated (the
//! default). Worst of the 12 curves, RMS over −25…70 °C in % of its swing
//! (min / median / max):
//!
//! | protocol                                         | truth: start + b(T) | runs > 2 % | truth: turn-on + b(T) | coverage (start) |
//! |--------------------------------------------------|---------------------|-----------|-----------------------|------------------|
//! | sequential                                       | 1.33 / 1.97 / 3.24  | 6 / 12    | 1.33 / 2.02 / 4.10    | 93.8–100 %       |
//! | palindromic                                      | 1.18 / 1.71 / 3.04  | 3 / 12    | 1.23 / 1.64 / 4.44    | 92.5–100 %       |
//! | palindromic, 3 cycles                            | 1.03 / 1.59 / 2.70  | 2 / 12    | 1.03 / 1.63 / 4.21    | 91.3–100 %       |
//! | sequential + revisit, 10-s first soak, 3 cycles  | 0.76 / 1.09 / 1.59  | 0 / 12    | 0.84 / 1.43 / 2.34    | 96.3–100 %       |
//! | palindromic + revisit, 10-s first soak           | 0.77 / 1.26 / 2.48  | 1 / 12    | 0.92 / 1.57 / 2.48    | 95.8–100 %       |
//! | palindromic + revisit, 10-s first soak, 2 cycles | 0.69 / 1.12 / 1.62  | 0 / 12    | 0.90 / 1.31 / 2.22    | 94.2–100 %       |
//! | **recommended**: the same, 3 cycles              | 0.65 / 1.02 / 1.33  | 0 / 12    | 0.77 / 1.24 / 2.57    | 95.0–100 %       |
//!
//! Without the 10-s first soak, the 600-s soak of the first step lets the rate random
//! walk reach K·√600 s before the first positions (0.8 % of the accelerometer-z swing,
//! 1σ). The accelerometer scale factors (swing only 0.3 %) took the flicker between ±
//! visits; one palindrome per step left up to 2.48 %, three cycles leave ≤ 1.33 %. The
//! thermal part of every bias curve is ≤ 0.80 % in every row. An earlier measurement
//! (G left out, the same seeds) is in the history of this file: without G, gyro bias z
//! carries the rate rows' g·G (0.2 °/s/g on the sensing axis).

use driftless::calib::protocol::SegmentKind;
use driftless::calib::six_position::SixPositionOptions;
use driftless::sim::chamber::{ChamberConfig, StepOrder};
use driftless::sim::presets::Preset;
use driftless::sim::sensor::{OutputKind, SensorModel};
use driftless::thermal::FitOptions;
use driftless::thermal::soak::{SoakDrift, soak_calibration};

/// The chamber protocol of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Protocol {
    /// Temperatures ascending, sequential order; deterministic errors, turn-on biases and
    /// white noise only; `estimate_g` as for `EveryTerm`.
    WhiteNoiseAscending { estimate_g: bool },
    /// Every noise term; temperatures interleaved (k·7 mod 20), positions and rate
    /// segments in `order`; with `revisit`, an extra 25 °C step at the start and the end;
    /// `first_soak_s` the soak of the first step (None: as every step); `estimate_g`
    /// fits the gyro g-sensitivity in each six-position calibration (true: the default
    /// `SixPositionOptions::from_manifest` gives on this protocol).
    EveryTerm {
        order: StepOrder,
        revisit: bool,
        first_soak_s: Option<f64>,
        estimate_g: bool,
        cycles: u32,
    },
}

/// Figures of one run.
struct Run {
    /// Worst RMS error over the range / swing, over the 12 series (bias truth: turn-on +
    /// flicker at the start + b(T), module docs).
    worst: f64,
    /// The series with that error.
    worst_series: String,
    /// The same against turn-on + b(T) alone (flicker at the start counted as error).
    worst_at_turn_on: f64,
    /// Worst RMS error of the thermal part (value at 25 °C removed) / swing, bias series.
    worst_bias_shape: f64,
    /// Fraction of (series, temperature) with the truth inside the 95 % band.
    coverage: f64,
    /// The same against turn-on + b(T) alone.
    coverage_at_turn_on: f64,
    /// RMS static accelerometer error with the model / with the room calibration alone.
    compensated_fraction: f64,
}

impl Run {
    /// One line of the figures.
    fn summary(&self) -> String {
        format!(
            "worst curve {:.2} % ({}), against turn-on + b(T) {:.2} %; bias thermal part {:.2} %; coverage {:.1} % ({:.1} %)",
            100.0 * self.worst,
            self.worst_series,
            100.0 * self.worst_at_turn_on,
            100.0 * self.worst_bias_shape,
            100.0 * self.coverage,
            100.0 * self.coverage_at_turn_on
        )
    }
}

#[test]
fn deterministic_and_white_noise() {
    let r = run(2026, Protocol::WhiteNoiseAscending { estimate_g: true });
    assert!(r.worst <= 0.02, "worst {:.4}", r.worst);
    assert!(r.coverage >= 0.90, "band coverage {}", r.coverage);
    assert!(r.compensated_fraction <= 0.05, "{}", r.compensated_fraction);
}

/// The recommended protocol for a sensor with slow noise (module docs): the 25 °C
/// reference first, measured at once after power-on at ambient (10-s first soak), the
/// other temperatures interleaved, 25 °C again at the end, palindromic order, three
/// position cycles per step, gyro g-sensitivity estimated.
const RECOMMENDED: Protocol = Protocol::EveryTerm {
    order: StepOrder::Palindromic,
    revisit: true,
    first_soak_s: Some(10.0),
    estimate_g: true,
    cycles: 3,
};

/// The Recovery bar with every noise term on the recommended protocol.
#[test]
fn every_noise_term() {
    for seed in 1..=3 {
        let r = run(seed, RECOMMENDED);
        eprintln!("seed {seed}: {}", r.summary());
        assert!(r.worst <= 0.02, "seed {seed}: worst curve {}", r.worst);
        assert_band_and_bias_shape(seed, &r);
        // The static positions' error left by the model is the sensor's own drift
        // (≈ 0.015 m/s² RMS, 6 % of the room-calibration-only error); not asserted.
    }
}

/// The plain protocol (interleaved temperatures, full first soak, one palindrome per
/// step): the band still covers the truth and the thermal part of every bias curve is
/// within the bar; the curves themselves are not asserted (module docs table).
#[test]
fn every_noise_term_plain_protocol() {
    for seed in 1..=2 {
        let r = run(
            seed,
            Protocol::EveryTerm {
                order: StepOrder::Palindromic,
                revisit: false,
                first_soak_s: None,
                estimate_g: true,
                cycles: 1,
            },
        );
        assert_band_and_bias_shape(seed, &r);
    }
}

/// The truth inside the 95 % band at ≥ 90 % of (series, temperature), and the thermal
/// part of every bias curve within 2 % of its swing.
fn assert_band_and_bias_shape(seed: u64, r: &Run) {
    assert!(
        r.coverage >= 0.90,
        "seed {seed}: band coverage {}",
        r.coverage
    );
    assert!(
        r.worst_bias_shape <= 0.02,
        "seed {seed}: bias thermal part {}",
        r.worst_bias_shape
    );
}

/// Measurement (not a check; `--ignored --nocapture`, ≈ 5 min): worst curve and band
/// coverage over seeds 1 … 12 for the protocols of the module docs table.
#[test]
#[ignore = "measurement: 84 runs"]
fn measure_protocols() {
    let (s, p) = (StepOrder::Sequential, StepOrder::Palindromic);
    measure(
        &[
            (s, false, None, true, 1),
            (p, false, None, true, 1),
            (p, false, None, true, 3),
            (s, true, Some(10.0), true, 3),
            (p, true, Some(10.0), true, 1),
            (p, true, Some(10.0), true, 2),
            (p, true, Some(10.0), true, 3),
        ],
        1..=12,
    );
}

/// Measurement (not a check; `--ignored --nocapture`, ≈ 4 min): the recommended
/// protocol over seeds 1 … 48, and `deterministic_and_white_noise` without and with G.
#[test]
#[ignore = "measurement: 50 runs"]
fn measure_recommended_protocol() {
    for estimate_g in [false, true] {
        let r = run(2026, Protocol::WhiteNoiseAscending { estimate_g });
        eprintln!(
            "SUMMARY white noise ascending G={estimate_g}: worst {:.2} % ({}), coverage {:.1} %",
            100.0 * r.worst,
            r.worst_series,
            100.0 * r.coverage
        );
    }
    measure(
        &[(StepOrder::Palindromic, true, Some(10.0), true, 3)],
        1..=48,
    );
}

/// Every (order, revisit, first soak, estimate G, cycles) in `configs` over `seeds`:
/// prints one line per run and a summary per configuration (min / median / max of the
/// worst curve, against both truths, and the coverage range).
fn measure(
    configs: &[(StepOrder, bool, Option<f64>, bool, u32)],
    seeds: std::ops::RangeInclusive<u64>,
) {
    let pct = |v: &mut Vec<f64>| -> String {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = 0.5 * (v[(n - 1) / 2] + v[n / 2]);
        format!(
            "{:.2} / {:.2} / {:.2}",
            100.0 * v[0],
            100.0 * median,
            100.0 * v[n - 1]
        )
    };
    let mut table = Vec::new();
    for &(order, revisit, first_soak_s, estimate_g, cycles) in configs {
        let (mut worst, mut worst_on, mut cov, mut cov_on, mut shape) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut names = Vec::new();
        let mut over = 0;
        for seed in seeds.clone() {
            let r = run(
                seed,
                Protocol::EveryTerm {
                    order,
                    revisit,
                    first_soak_s,
                    estimate_g,
                    cycles,
                },
            );
            eprintln!(
                "MEASURE {order:?} revisit={revisit} first_soak={first_soak_s:?} G={estimate_g} cycles={cycles} seed {seed}: {}",
                r.summary()
            );
            over += usize::from(r.worst > 0.02);
            worst.push(r.worst);
            worst_on.push(r.worst_at_turn_on);
            cov.push(r.coverage);
            cov_on.push(r.coverage_at_turn_on);
            shape.push(r.worst_bias_shape);
            names.push(r.worst_series);
        }
        let n = worst.len();
        table.push(format!(
            "{order:?} revisit={revisit} first_soak={first_soak_s:?} G={estimate_g} cycles={cycles}, {n} seeds: worst curve {} % of swing ({over} above 2 %); against turn-on + b(T) {} %; bias thermal part {} %; coverage {} % (against turn-on + b(T) {} %); worst series {names:?}",
            pct(&mut worst),
            pct(&mut worst_on),
            pct(&mut shape),
            pct(&mut cov),
            pct(&mut cov_on),
        ));
    }
    for line in table {
        eprintln!("SUMMARY {line}");
    }
}

fn run(seed: u64, protocol: Protocol) -> Run {
    let t0 = std::time::Instant::now();
    let all_terms = matches!(protocol, Protocol::EveryTerm { .. });
    let (step_order, temperatures_c, first_soak_s, estimate_g, position_cycles) = match protocol {
        Protocol::WhiteNoiseAscending { estimate_g } => (
            StepOrder::Sequential,
            (0..20).map(|i| -25.0 + 5.0 * i as f64).collect(),
            None,
            estimate_g,
            1,
        ),
        Protocol::EveryTerm {
            order,
            revisit,
            first_soak_s,
            estimate_g,
            cycles,
        } => {
            let mut t: Vec<f64> = (0..20)
                .map(|i| -25.0 + 5.0 * ((i * 7) % 20) as f64)
                .collect();
            if revisit {
                t.insert(0, 25.0);
                t.push(25.0);
            }
            (order, t, first_soak_s, estimate_g, cycles)
        }
    };
    let proto = ChamberConfig {
        soak_s: 600.0,
        lag_tau_s: 60.0,
        position_dwell_s: 30.0,
        move_s: 5.0,
        rate_revolutions: 2,
        spin_s: 2.0,
        sample_rate_hz: 100.0,
        temperatures_c,
        step_order,
        first_soak_s,
        position_cycles,
        ..ChamberConfig::default()
    }
    .build()
    .expect("protocol");
    let mut cfg = Preset::AdiLike.config();
    if !all_terms {
        // deterministic errors, turn-on biases and white noise only (module docs)
        cfg = cfg.without_slow_noise();
    }
    let model = SensorModel::new(cfg.clone()).expect("model");
    let curve = proto.temperature.curve().expect("temperature");
    let out = model
        .simulate(&proto.ideal(OutputKind::Rates), &curve, seed)
        .expect("simulate");
    let sim_s = t0.elapsed().as_secs_f64();
    // The same run's slow noise alone: `slow` every stochastic term but white noise and
    // quantization (bias instability and rate random walk), `flicker` the bias
    // instability alone. Each term has its own random stream, so these are the
    // realisations inside the full run.
    let ideal = proto.ideal(OutputKind::Rates);
    let only = |keep_rrw: bool| {
        let mut c = cfg.noise_only();
        for n in c.gyro.noise.iter_mut().chain(c.accel.noise.iter_mut()) {
            n.white = 0.0;
            n.quantization = 0.0;
            if !keep_rrw {
                n.rate_random_walk = 0.0;
            }
        }
        SensorModel::new(c)
            .expect("model")
            .simulate(&ideal, &curve, seed)
            .expect("simulate")
    };
    let (slow, flicker) = if all_terms {
        (Some(only(true)), Some(only(false)))
    } else {
        (None, None)
    };
    // Mean of a noise realisation over the static positions of the segments `segs`.
    let fs = proto.manifest.sample_rate_hz;
    let mean_over = |o: &Option<driftless::sim::sensor::SensorOutput>,
                     channel: usize,
                     segs: &mut dyn Iterator<Item = &driftless::calib::protocol::Segment>|
     -> f64 {
        let Some(o) = o else { return 0.0 };
        let (mut s, mut n) = (0.0, 0usize);
        for seg in segs.filter(|g| matches!(g.kind, SegmentKind::Position { .. })) {
            for k in seg.sample_range(fs) {
                s += if channel < 3 {
                    o.gyro_at(k)[channel] - ideal.gyro.at(k)[channel]
                } else {
                    o.accel_at(k)[channel - 3] - ideal.accel.at(k)[channel - 3]
                };
                n += 1;
            }
        }
        s / n.max(1) as f64
    };
    // The slow noise in effect at each set temperature (its mean over the positions).
    let slow_mean = |channel: usize, t: f64| -> f64 {
        mean_over(
            &slow,
            channel,
            &mut proto
                .manifest
                .segments
                .iter()
                .filter(|g| g.set_temperature_c == t),
        )
    };
    // The flicker in effect over the first step's positions: the part of the bias at the
    // start of the run that no measurement can tell from the turn-on bias (module docs).
    let steps = proto.manifest.steps();
    let first = steps[0].1.clone();
    let flicker_start: [f64; 6] = std::array::from_fn(|ch| {
        mean_over(
            &flicker,
            ch,
            &mut proto.manifest.segments[first.clone()].iter(),
        )
    });
    let mut six = SixPositionOptions::from_manifest(&proto.manifest);
    // Six positions per step: the default estimates the gyro g-sensitivity.
    assert!(six.estimate_g_sensitivity, "from_manifest default");
    six.estimate_g_sensitivity = estimate_g;
    // The drift model from the preset's Allan terms (what `driftless allan` reports).
    let drift = SoakDrift::from(&cfg);
    let t1 = std::time::Instant::now();
    let soak = soak_calibration(
        &proto.manifest,
        out.accel.each_ref().map(Vec::as_slice),
        out.gyro.each_ref().map(Vec::as_slice),
        1.0,
        &six,
        &FitOptions::default(),
        all_terms.then_some(&drift),
    )
    .expect("soak calibration");
    let fit_s = t1.elapsed().as_secs_f64();
    // Truth per series (module docs): bias = turn-on + b(T), plus with `at_start` the
    // flicker in effect over the first step; scale A_kk = 1 + s(T) (zero-diagonal
    // misalignment).
    let truth = |triad: &str, quantity: &str, axis: usize, t: f64, at_start: bool| -> f64 {
        let a = if triad == "accel" { 3 + axis } else { axis };
        if quantity == "bias" {
            let on = if triad == "accel" {
                out.accel_turn_on_bias_m_s2[axis]
            } else {
                out.gyro_turn_on_bias_rad_s[axis]
            };
            let start = if at_start { flicker_start[a] } else { 0.0 };
            on + start + model.bias_at(a, t)
        } else {
            1.0 + model.scale_factor_at(a, t)
        }
    };
    let grid: Vec<f64> = (0..=95).map(|i| -25.0 + i as f64).collect();
    // The distinct set temperatures (a revisited one counts once).
    let mut temps = soak.temperatures_c.clone();
    temps.dedup();
    let mut r = Run {
        worst: 0.0,
        worst_series: String::new(),
        worst_at_turn_on: 0.0,
        worst_bias_shape: 0.0,
        coverage: 0.0,
        coverage_at_turn_on: 0.0,
        compensated_fraction: 0.0,
    };
    let (mut inside, mut inside_on, mut total) = (0usize, 0usize, 0usize);
    for s in &soak.series {
        let name = format!("{} {} {}", s.triad, s.quantity, ["x", "y", "z"][s.axis]);
        let ch = if s.triad == "accel" {
            3 + s.axis
        } else {
            s.axis
        };
        // RMS over the range / swing, and the same with the value at 25 °C removed.
        let rms_of = |at_start: bool| -> (f64, f64, f64) {
            let tr: Vec<f64> = grid
                .iter()
                .map(|&t| truth(s.triad, s.quantity, s.axis, t, at_start))
                .collect();
            let swing = tr.iter().cloned().fold(f64::MIN, f64::max)
                - tr.iter().cloned().fold(f64::MAX, f64::min);
            let i25 = grid.iter().position(|&t| t == 25.0).expect("25 °C");
            let off = s.fit.eval(25.0) - tr[i25];
            let (mut e2, mut shape2) = (0.0, 0.0);
            for (&t, y) in grid.iter().zip(&tr) {
                e2 += (s.fit.eval(t) - y).powi(2);
                shape2 += (s.fit.eval(t) - y - off).powi(2);
            }
            let n = grid.len() as f64;
            ((e2 / n).sqrt() / swing, (shape2 / n).sqrt() / swing, swing)
        };
        let (rel, shape, swing) = rms_of(true);
        let (rel_on, _, _) = rms_of(false);
        if s.quantity == "bias" {
            r.worst_bias_shape = r.worst_bias_shape.max(shape);
        }
        let (mut ins, mut ins_on, mut eff2) = (0, 0, 0.0);
        for &t in &temps {
            let b = s.fit.band(t, 0.95).expect("band");
            let y = truth(s.triad, s.quantity, s.axis, t, true);
            let y_on = truth(s.triad, s.quantity, s.axis, t, false);
            if s.quantity == "bias" {
                eff2 += (b.value - y_on - slow_mean(ch, t)).powi(2);
            }
            ins += usize::from(y >= b.lo && y <= b.hi);
            ins_on += usize::from(y_on >= b.lo && y_on <= b.hi);
        }
        eprintln!(
            "{name}: swing {swing:.4e}, RMS error {:.2} % of swing (thermal part {:.2} %; \
             against turn-on + b(T) alone {:.2} %; bias in effect at the set temperatures \
             {:.3e}), truth in band at {ins}/{} temperatures ({ins_on} against turn-on + b(T))",
            100.0 * rel,
            100.0 * shape,
            100.0 * rel_on,
            (eff2 / temps.len() as f64).sqrt(),
            temps.len()
        );
        if rel > r.worst {
            r.worst = rel;
            r.worst_series = name;
        }
        r.worst_at_turn_on = r.worst_at_turn_on.max(rel_on);
        inside += ins;
        inside_on += ins_on;
        total += temps.len();
    }
    r.coverage = inside as f64 / total as f64;
    r.coverage_at_turn_on = inside_on as f64 / total as f64;
    eprintln!(
        "soak: {} steps at {} temperatures, {} samples simulated in {sim_s:.2} s, calibrated + fitted in {fit_s:.3} s; worst RMS {:.2} % of swing ({:.2} % against turn-on + b(T)); truth inside the 95 % band at {:.1} % of (series, temperature) ({:.1} %)",
        soak.temperatures_c.len(),
        temps.len(),
        out.len(),
        100.0 * r.worst,
        100.0 * r.worst_at_turn_on,
        100.0 * r.coverage,
        100.0 * r.coverage_at_turn_on,
    );

    // The compensation model built from the soak, applied to every static position of
    // every temperature: the thermal error left, against the room calibration alone.
    let model = soak
        .compensation_model(7, driftless_model::compensation::OutOfRange::Clamp)
        .expect("model");
    let room = model.calibration().accel;
    let g = six.gravity_m_s2;
    let (mut e_comp, mut e_room, mut n) = (0.0, 0.0, 0usize);
    for &t in &temps {
        let input = driftless::calib::six_position::SixPositionInput::from_manifest_columns(
            &proto.manifest,
            out.accel.each_ref().map(Vec::as_slice),
            out.gyro.each_ref().map(Vec::as_slice),
            1.0,
            t,
        )
        .expect("positions");
        for p in &input.positions {
            let want = p.c_bn.t().mul_vec([0.0, 0.0, -g]);
            let (_, a) = model
                .compensate([0.0; 3], p.accel_raw, t)
                .expect("compensate");
            let r = room.apply(p.accel_raw);
            for k in 0..3 {
                e_comp += (a[k] - want[k]).powi(2);
                e_room += (r[k] - want[k]).powi(2);
                n += 1;
            }
        }
    }
    let (rc, rr) = ((e_comp / n as f64).sqrt(), (e_room / n as f64).sqrt());
    eprintln!(
        "compensation of the static positions over −25…70 °C: accelerometer error RMS {rc:.3e} m/s² with the thermal model vs {rr:.3e} with the room calibration alone ({:.1} %)",
        100.0 * rc / rr
    );

    // The model file round trip: the same compensation, bit for bit.
    use driftless::thermal::model_file::ThermalModelFile;
    let path = std::env::temp_dir().join(format!("driftless-thermal-{}.toml", std::process::id()));
    ThermalModelFile::from_model(&model, ["m/s^2", "rad/s"])
        .save(&path)
        .expect("save");
    let (_, back) = ThermalModelFile::load(&path).expect("load");
    for t in [-30.0, -25.0, 3.3, 25.0, 47.1, 70.0, 80.0] {
        let x = ([0.01, -0.02, 0.03], [0.5, -9.7, 0.2]);
        assert_eq!(
            back.compensate(x.0, x.1, t),
            model.compensate(x.0, x.1, t),
            "{t} °C"
        );
    }
    let text = std::fs::read_to_string(&path).expect("read");
    std::fs::write(&path, text.replace("\"clamp\"", "\"wrap\"")).expect("write");
    let e = ThermalModelFile::load(&path).unwrap_err().to_string();
    assert!(e.contains("out_of_range") && e.contains("wrap"), "{e}");
    let _ = std::fs::remove_file(&path);
    r.compensated_fraction = rc / rr;
    r
}

/// Bad input: a temperature step that lacks one of the six positions is refused naming
/// the temperature and the count of positions; fewer set temperatures than the order
/// needs are refused naming both.
#[test]
fn a_temperature_missing_a_position_is_refused() {
    let proto = ChamberConfig {
        temperatures_c: vec![0.0, 20.0, 40.0, 60.0, 10.0],
        soak_s: 60.0,
        lag_tau_s: 5.0,
        position_dwell_s: 5.0,
        move_s: 2.0,
        rate_revolutions: 1,
        spin_s: 1.0,
        sample_rate_hz: 50.0,
        ..ChamberConfig::default()
    }
    .build()
    .expect("protocol");
    let cfg = Preset::AdiLike.config().deterministic_only();
    let curve = proto.temperature.curve().expect("temperature");
    let out = SensorModel::new(cfg)
        .expect("model")
        .simulate(&proto.ideal(OutputKind::Rates), &curve, 1)
        .expect("simulate");
    let six = SixPositionOptions::from_manifest(&proto.manifest);
    let soak = |manifest: &driftless::calib::protocol::ChamberManifest, order: usize| {
        soak_calibration(
            manifest,
            out.accel.each_ref().map(Vec::as_slice),
            out.gyro.each_ref().map(Vec::as_slice),
            1.0,
            &six,
            &FitOptions {
                order,
                ..FitOptions::default()
            },
            None,
        )
    };
    // Unsorted set temperatures are fine (sorted internally).
    let ok = soak(&proto.manifest, 3).expect("complete protocol");
    assert_eq!(ok.temperatures_c, vec![0.0, 10.0, 20.0, 40.0, 60.0]);
    // Drop the last static position at 40 °C.
    let mut m = proto.manifest.clone();
    let i = m
        .segments
        .iter()
        .rposition(|g| {
            g.set_temperature_c == 40.0 && matches!(g.kind, SegmentKind::Position { .. })
        })
        .expect("a position at 40 °C");
    m.segments.remove(i);
    let e = soak(&m, 3).unwrap_err().to_string();
    assert!(
        e.contains("at 40 °C") && e.contains("5 static positions"),
        "{e}"
    );
    // Order 4 from 5 temperatures: refused (needs order + 2 for a residual).
    let e = soak(&proto.manifest, 4).unwrap_err().to_string();
    assert!(
        e.contains("5 set temperatures") && e.contains("order-4"),
        "{e}"
    );
}

/// Repeated visits: a set temperature visited in two steps gives two calibration points
/// (each step calibrated from its own segments), and the palindromic order (every
/// position and rate sign visited twice per step) gives, on noise-free data, the same
/// per-step estimates as the sequential order.
///
/// Gyro g-sensitivity (`adi-like`: 0.2 °/s/g on the sensing axis, 0.05 across): with
/// the default options (`from_manifest` estimates G on six-position steps) every step
/// recovers the zero-g bias b(T) and the preset's G; with G left out, the +k-up rate
/// segments carry b_i + g·G_ik into the bias fit and the worst gyro bias is off by
/// 4.7e-4 (sequential) / 9.8e-5 rad/s (palindromic; the share depends on the rows'
/// weights), checked > 1e-5 = 100 × the bias tolerance — the checks can fail.
#[test]
fn revisited_temperatures_and_palindromic_positions() {
    let build = |order: StepOrder| {
        ChamberConfig {
            temperatures_c: vec![0.0, 20.0, 40.0, 60.0, 10.0, 0.0],
            soak_s: 60.0,
            lag_tau_s: 5.0,
            position_dwell_s: 6.0,
            move_s: 2.0,
            rate_revolutions: 2,
            spin_s: 1.0,
            sample_rate_hz: 50.0,
            step_order: order,
            ..ChamberConfig::default()
        }
        .build()
        .expect("protocol")
    };
    let cfg = Preset::AdiLike.config().deterministic_only();
    let model = SensorModel::new(cfg).expect("model");
    let mut results = Vec::new();
    for order in [StepOrder::Sequential, StepOrder::Palindromic] {
        let proto = build(order);
        assert_eq!(proto.manifest.steps().len(), 6);
        let curve = proto.temperature.curve().expect("temperature");
        let out = model
            .simulate(&proto.ideal(OutputKind::Rates), &curve, 1)
            .expect("simulate");
        let mut six = SixPositionOptions::from_manifest(&proto.manifest);
        assert!(
            six.estimate_g_sensitivity,
            "G is identifiable: on by default"
        );
        let soak_with = |six: &SixPositionOptions| {
            soak_calibration(
                &proto.manifest,
                out.accel.each_ref().map(Vec::as_slice),
                out.gyro.each_ref().map(Vec::as_slice),
                1.0,
                six,
                &FitOptions {
                    order: 3,
                    ..FitOptions::default()
                },
                None,
            )
            .expect("soak calibration")
        };
        let soak = soak_with(&six);
        // G per step and its mean: the preset's (|G| ≈ 3.6e-4 rad/s per m/s²) to 1e-8,
        // i.e. 1e-7 rad/s at 1 g as the bias check; what is left is the sensor's lag
        // behind the set temperature after the 60-s soak (e^(−60/5) ≈ 6e-6 of a step).
        let g_true = model.config().gyro.g_sensitivity_rad_s_per_m_s2;
        assert_eq!(soak.gyro_g_sensitivity.len(), 6);
        let steps = soak
            .gyro_g_sensitivity
            .iter()
            .map(|g| g.expect("G estimated"));
        let mean = soak.gyro_g_sensitivity_mean().expect("G mean");
        let mut worst_g = 0.0f64;
        for g in steps.chain([mean]) {
            for (i, row) in g_true.iter().enumerate() {
                for (j, want) in row.iter().enumerate() {
                    let d = g.matrix_raw_per_m_s2.0[i][j] - want;
                    assert!(d.abs() < 1e-8, "{order:?} G_{i}{j}: {d}");
                    worst_g = worst_g.max(d.abs());
                }
            }
        }
        eprintln!("{order:?}: worst G error {worst_g:e} rad/s per m/s²");
        // Without G: the gyro biases are pulled off by the rate rows' g·G_ik.
        six.estimate_g_sensitivity = false;
        let off = soak_with(&six);
        assert!(off.gyro_g_sensitivity.iter().all(Option::is_none));
        assert!(off.gyro_g_sensitivity_mean().is_none());
        let worst_off = (0..6)
            .flat_map(|i| (0..3).map(move |k| (i, k)))
            .map(|(i, k)| {
                let t = off.temperatures_c[i];
                (off.estimates[i].1.calibration.bias[k] - model.bias_at(k, t)).abs()
            })
            .fold(0.0, f64::max);
        eprintln!("{order:?}: worst gyro bias error without G {worst_off:e} rad/s");
        assert!(worst_off > 1e-5, "{order:?}: {worst_off}");
        assert_eq!(soak.temperatures_c, vec![0.0, 0.0, 10.0, 20.0, 40.0, 60.0]);
        assert_eq!(soak.estimates.len(), 6);
        // Every step: the deterministic truth (bias, scale) at its set temperature.
        for (i, &t) in soak.temperatures_c.iter().enumerate() {
            let (acc, gyr) = &soak.estimates[i];
            for k in 0..3 {
                let ab = acc.calibration.bias[k] - model.bias_at(3 + k, t);
                let as_ = acc.forward_matrix.0[k][k] - 1.0 - model.scale_factor_at(3 + k, t);
                let gb = gyr.calibration.bias[k] - model.bias_at(k, t);
                let gs = gyr.forward_matrix.0[k][k] - 1.0 - model.scale_factor_at(k, t);
                assert!(ab.abs() < 1e-6, "{order:?} {t} °C accel bias {k}: {ab}");
                assert!(as_.abs() < 1e-6, "{order:?} {t} °C accel scale {k}: {as_}");
                assert!(gb.abs() < 1e-7, "{order:?} {t} °C gyro bias {k}: {gb}");
                assert!(gs.abs() < 1e-6, "{order:?} {t} °C gyro scale {k}: {gs}");
            }
        }
        results.push(soak);
    }
    for (a, b) in results[0].estimates.iter().zip(&results[1].estimates) {
        for k in 0..3 {
            assert!((a.0.calibration.bias[k] - b.0.calibration.bias[k]).abs() < 1e-6);
            assert!((a.1.calibration.bias[k] - b.1.calibration.bias[k]).abs() < 1e-7);
        }
    }
}

//! Thermal-compensation kernel throughput (`driftless_model::compensation`), one core.
//!
//! `cargo bench -p driftless --bench compensation [-- --samples N]`
//! Cubic bias and scale-factor deltas on all 12 channels, misaligned 3×3 matrices, a
//! warm-up ramp 25 → 45 °C over the block. The temperature is quantised to 0.01 °C (a
//! typical MEMS temperature-sensor resolution), so the block APIs see runs of equal
//! temperatures (~500 samples per run at 1 M samples); the "every sample distinct" rows
//! are the worst case (a fresh polynomial evaluation per sample). Best of 7; reports
//! six-axis samples per second, and the f32 − f64 difference.

use std::hint::black_box;
use std::time::Instant;

use driftless_model::calib::{ImuCalibration, TriadCalibration};
use driftless_model::compensation::{CompensationModel, Compensator, OutOfRange, TriadThermal};
use driftless_model::linalg::Mat3;
use driftless_model::thermal::ThermalPoly;

const REPS: usize = 7;

fn poly(c: [f64; 4]) -> ThermalPoly {
    ThermalPoly::new(25.0, &c, -40.0, 85.0).expect("valid polynomial")
}

fn triad(k: f64) -> TriadThermal {
    TriadThermal {
        bias_delta: [
            poly([0.0, 3e-4 * k, -2e-6, 1e-8]),
            poly([0.0, -2e-4 * k, 3e-6, -2e-8]),
            poly([0.0, 1e-4 * k, 1e-6, 4e-9]),
        ],
        scale_delta: [
            poly([0.0, 2e-5, -3e-7, 1e-9]),
            poly([0.0, -1e-5, 2e-7, -2e-9]),
            poly([0.0, 3e-5, 1e-7, 3e-9]),
        ],
    }
}

fn model() -> CompensationModel {
    let m = Mat3([
        [1.001, 2e-3, -1e-3],
        [-1.5e-3, 0.998, 3e-3],
        [0.5e-3, -2e-3, 1.002],
    ]);
    let cal = ImuCalibration {
        gyro: TriadCalibration {
            bias: [1e-3, -2e-3, 5e-4],
            matrix: m,
        },
        accel: TriadCalibration {
            bias: [0.05, -0.03, 0.02],
            matrix: m.t(),
        },
    };
    CompensationModel::new(
        0x5EED,
        cal,
        Some(triad(1.0)),
        Some(triad(10.0)),
        [-40.0, 85.0],
        OutOfRange::Clamp,
    )
    .expect("valid model")
}

fn best(mut f: impl FnMut() -> f64) -> f64 {
    (0..REPS).map(|_| f()).fold(f64::INFINITY, f64::min)
}

/// Best time of a per-sample loop: `setup` makes fresh per-repetition state (e.g. a
/// `Compensator` with an empty cache), `step(state, i)` compensates sample `i` and
/// returns its output, which is kept so that nothing is optimised away.
fn per_sample<S, O: Default + Clone>(
    n: usize,
    mut setup: impl FnMut() -> S,
    mut step: impl FnMut(&mut S, usize) -> O,
) -> f64 {
    let mut out = vec![O::default(); n];
    best(|| {
        let mut state = setup();
        let t0 = Instant::now();
        for (i, o) in out.iter_mut().enumerate() {
            *o = step(&mut state, i);
        }
        black_box(&out);
        t0.elapsed().as_secs_f64()
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args
        .iter()
        .position(|a| a == "--samples")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1_000_000);
    let m = model();
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut noise = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let gyro: Vec<[f64; 3]> = (0..n).map(|_| [noise(), noise(), noise()]).collect();
    let accel: Vec<[f64; 3]> = (0..n)
        .map(|_| [noise(), noise(), 9.80665 + noise()])
        .collect();
    let ramp = |i: usize| 25.0 + 20.0 * i as f64 / n as f64;
    let t_quant: Vec<f64> = (0..n).map(|i| (ramp(i) * 100.0).round() / 100.0).collect();
    let t_dist: Vec<f64> = (0..n).map(ramp).collect();
    let runs = 1 + t_quant.windows(2).filter(|w| w[0] != w[1]).count();
    let g32: Vec<[f32; 3]> = gyro.iter().map(|v| v.map(|c| c as f32)).collect();
    let a32: Vec<[f32; 3]> = accel.iter().map(|v| v.map(|c| c as f32)).collect();
    let tq32: Vec<f32> = t_quant.iter().map(|&t| t as f32).collect();
    let td32: Vec<f32> = t_dist.iter().map(|&t| t as f32).collect();
    println!(
        "{n} six-axis samples, 25 -> 45 °C ramp, {runs} distinct quantised temperatures, best of {REPS}"
    );
    let report = |name: &str, secs: f64| {
        println!(
            "{name:<44} {:>8.1} M samples/s  ({:.2} ns/sample)",
            n as f64 / secs / 1e6,
            secs * 1e9 / n as f64
        );
    };

    // Per-sample f64 (stateless).
    for (label, t) in [
        ("quantised T", &t_quant),
        ("every sample distinct", &t_dist),
    ] {
        let s = per_sample(
            n,
            || (),
            |_, i| {
                m.compensate(black_box(gyro[i]), black_box(accel[i]), t[i])
                    .expect("in range")
            },
        );
        report(&format!("f64 per-sample, {label}"), s);
    }
    // Streaming per-sample f64 (cached factors for the last temperature).
    for (label, t) in [
        ("quantised T", &t_quant),
        ("every sample distinct", &t_dist),
    ] {
        let s = per_sample(
            n,
            || Compensator::new(&m),
            |c, i| {
                c.compensate(black_box(gyro[i]), black_box(accel[i]), t[i])
                    .expect("in range")
            },
        );
        report(&format!("f64 streaming Compensator, {label}"), s);
    }
    // Block f64.
    for (label, t) in [
        ("quantised T", &t_quant),
        ("every sample distinct", &t_dist),
    ] {
        let mut bg = gyro.clone();
        let mut ba = accel.clone();
        let s = best(|| {
            bg.copy_from_slice(&gyro);
            ba.copy_from_slice(&accel);
            let t0 = Instant::now();
            m.compensate_block(&mut bg, &mut ba, t).expect("in range");
            black_box((&bg, &ba));
            t0.elapsed().as_secs_f64()
        });
        report(&format!("f64 block, {label}"), s);
    }
    // Per-sample f32 (stateless).
    for (label, t) in [("quantised T", &tq32), ("every sample distinct", &td32)] {
        let s = per_sample(
            n,
            || (),
            |_, i| {
                m.compensate_f32(black_box(g32[i]), black_box(a32[i]), t[i])
                    .expect("in range")
            },
        );
        report(&format!("f32 per-sample, {label}"), s);
    }
    // Streaming per-sample f32.
    for (label, t) in [("quantised T", &tq32), ("every sample distinct", &td32)] {
        let s = per_sample(
            n,
            || Compensator::new(&m),
            |c, i| {
                c.compensate_f32(black_box(g32[i]), black_box(a32[i]), t[i])
                    .expect("in range")
            },
        );
        report(&format!("f32 streaming Compensator, {label}"), s);
    }
    // Block f32.
    let mut bg32 = g32.clone();
    let mut ba32 = a32.clone();
    for (label, t) in [("quantised T", &tq32), ("every sample distinct", &td32)] {
        let s = best(|| {
            bg32.copy_from_slice(&g32);
            ba32.copy_from_slice(&a32);
            let t0 = Instant::now();
            m.compensate_block_f32(&mut bg32, &mut ba32, t)
                .expect("in range");
            black_box((&bg32, &ba32));
            t0.elapsed().as_secs_f64()
        });
        report(&format!("f32 block, {label}"), s);
    }

    // f32 accuracy against f64 on the same (f32) inputs and temperatures.
    bg32.copy_from_slice(&g32);
    ba32.copy_from_slice(&a32);
    m.compensate_block_f32(&mut bg32, &mut ba32, &tq32)?;
    let mut bg: Vec<[f64; 3]> = g32.iter().map(|v| v.map(f64::from)).collect();
    let mut ba: Vec<[f64; 3]> = a32.iter().map(|v| v.map(f64::from)).collect();
    let tq: Vec<f64> = tq32.iter().map(|&t| f64::from(t)).collect();
    m.compensate_block(&mut bg, &mut ba, &tq)?;
    let (mut max_g, mut max_a, mut max_rel) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..n {
        for k in 0..3 {
            let dg = (f64::from(bg32[i][k]) - bg[i][k]).abs();
            let da = (f64::from(ba32[i][k]) - ba[i][k]).abs();
            max_g = max_g.max(dg);
            max_a = max_a.max(da);
            let norm_a = ba[i].iter().map(|v| v * v).sum::<f64>().sqrt();
            max_rel = max_rel.max(da / norm_a);
        }
    }
    println!(
        "f32 - f64: max |Δgyro| {max_g:.2e} rad/s (|ω| ≤ 0.87), max |Δaccel| {max_a:.2e} m/s² \
         ({max_rel:.2e} of |f|)"
    );
    Ok(())
}

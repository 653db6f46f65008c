//! PX4 ULog and ArduPilot DataFlash reader throughput on the real logs in
//! `$DRIFTLESS_DATA/logs` (else `../shared/data/logs`): full parse and IMU extraction,
//! best of 20, from memory (file reading excluded).
//!
//! `cargo bench -p driftless --bench autopilot_parse`

use std::path::PathBuf;
use std::time::Instant;

use driftless::io::{imu_logs_from_dataflash, imu_logs_from_ulog, parse_dataflash, parse_ulog};

fn best_of<T>(n: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..n)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let dir = match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join("logs");
    let Ok(ulog) = std::fs::read(dir.join("px4_ulog/sample_log_small.ulg")) else {
        eprintln!("no shared data at {}; set DRIFTLESS_DATA", dir.display());
        return;
    };
    let Ok(df) = std::fs::read(dir.join("ardupilot_dataflash/backend_log_80k.bin")) else {
        eprintln!("no shared data at {}; set DRIFTLESS_DATA", dir.display());
        return;
    };
    let mb = |b: &[u8], s: f64| b.len() as f64 / 1e6 / s;
    let s = best_of(20, || parse_ulog(&ulog, "u").ok().map(|u| u.topics.len()));
    println!(
        "ULog parse        {:>8.0} MB/s ({:.2} ms for {} bytes)",
        mb(&ulog, s),
        s * 1e3,
        ulog.len()
    );
    let s = best_of(20, || {
        imu_logs_from_ulog(&ulog, "u").ok().map(|r| r.imus.len())
    });
    println!(
        "ULog → IMU logs   {:>8.0} MB/s ({:.2} ms)",
        mb(&ulog, s),
        s * 1e3
    );
    let s = best_of(20, || {
        parse_dataflash(&df, "d").ok().map(|d| d.skipped_bytes)
    });
    println!(
        "DataFlash parse   {:>8.0} MB/s ({:.3} ms for {} bytes)",
        mb(&df, s),
        s * 1e3,
        df.len()
    );
    let s = best_of(20, || {
        imu_logs_from_dataflash(&df, "d").ok().map(|r| r.imus.len())
    });
    println!(
        "DataFlash → IMU   {:>8.0} MB/s ({:.3} ms)",
        mb(&df, s),
        s * 1e3
    );
}

//! Text and binary reader throughput on an 18 h × 100 Hz × 7-column log (6.48 M rows).
//!
//! `cargo bench -p driftless --bench io_parse [-- text|binary|all] [--rows N]`
//! Writes `/tmp/driftless_bench_<rows>.csv` (~680 MB for the default size) and
//! `/tmp/driftless_bench_<rows>.dlog` once, then times the readers (best of 3).
//! For peak RSS run the bench binary under `/usr/bin/time -v` with `text` or `binary`.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use driftless::io::{ColumnRef, TextOptions, read_binary_file, read_text_file, write_binary_file};

fn generate(path: &PathBuf, rows: usize) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::with_capacity(1 << 22, std::fs::File::create(path)?);
    writeln!(w, "# synthetic static IMU log, 100 Hz")?;
    writeln!(
        w,
        "time [s],gyro_x [deg/s],gyro_y [deg/s],gyro_z [deg/s],acc_x [m/s^2],acc_y [m/s^2],acc_z [m/s^2]"
    )?;
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut noise = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for i in 0..rows {
        let t = i as f64 * 0.01;
        write!(w, "{t:.2}")?;
        for k in 0..3 {
            write!(w, ",{:.9e}", 0.01 * noise() + 1e-3 * k as f64)?;
        }
        for k in 0..3 {
            let g = if k == 2 { 9.80665 } else { 0.0 };
            write!(w, ",{:.9e}", g + 0.05 * noise())?;
        }
        writeln!(w)?;
    }
    w.flush()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let mode = args
        .iter()
        .find(|a| ["text", "binary", "all"].contains(&a.as_str()))
        .cloned()
        .unwrap_or_else(|| "all".into());
    let rows: usize = args
        .iter()
        .position(|a| a == "--rows")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(18 * 3600 * 100);
    let csv = PathBuf::from(format!("/tmp/driftless_bench_{rows}.csv"));
    let bin = csv.with_extension("dlog");
    if !csv.exists() {
        eprintln!("generating {} ({rows} rows)…", csv.display());
        generate(&csv, rows)?;
    }
    let size = std::fs::metadata(&csv)?.len() as f64;
    let opts = TextOptions::default().with_time(ColumnRef::Name("time".into()), None);
    let mem_mb = (rows * 7 * 8) as f64 / 1e6;
    println!(
        "rows {rows}, csv {:.0} MB, in-memory f64 {mem_mb:.0} MB, {} rayon threads",
        size / 1e6,
        rayon::current_num_threads()
    );
    let mut text_best = f64::INFINITY;
    if mode != "binary" || !bin.exists() {
        for _ in 0..if mode == "binary" { 1 } else { 3 } {
            let t0 = Instant::now();
            let log = read_text_file(&csv, &opts)?;
            let dt = t0.elapsed().as_secs_f64();
            assert_eq!(log.len(), rows);
            text_best = text_best.min(dt);
            if !bin.exists() {
                write_binary_file(&log, &bin)?;
            }
        }
        println!(
            "text:   {:.3} s  {:.0} MB/s of CSV",
            text_best,
            size / 1e6 / text_best
        );
    }
    if mode != "text" {
        let bsize = std::fs::metadata(&bin)?.len() as f64;
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let t0 = Instant::now();
            let log = read_binary_file(&bin)?;
            best = best.min(t0.elapsed().as_secs_f64());
            assert_eq!(log.len(), rows);
        }
        println!(
            "binary: {best:.3} s  {:.0} MB/s of file ({:.0} MB)",
            bsize / 1e6 / best,
            bsize / 1e6
        );
        if text_best.is_finite() {
            println!("binary read is {:.1}× faster than text", text_best / best);
        }
    }
    Ok(())
}

//! Spectral lines on the real ADIS16405 static runs: every accelerometer carries a line
//! near 0.5 Hz of about a milli-g; the gyros carry none (gyro z's 17–21 Hz hump is coloured
//! noise, not a line); notching the line out leaves no line.

use driftless::allan::lines::{LineConfig, detect_lines, remove_lines};
use driftless::io::{Quantity, TextOptions, read_log_file};
use std::path::PathBuf;

fn data() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

#[test]
#[ignore = "needs shared data"]
fn adis16405_accelerometer_line_found_gyros_clean() {
    let cfg = LineConfig::default();
    for run in ["adis16405_run2.csv.gz", "adis16405_run3.csv.gz"] {
        let path = data().join("static/adis16405_calgary").join(run);
        let log = read_log_file(&path, &TextOptions::default()).expect("read");
        for c in &log.channels {
            let lines = detect_lines(&c.values, log.tau0_s, &cfg);
            eprintln!("{run} {}: {lines:?}", c.name);
            match c.quantity {
                Quantity::SpecificForce => {
                    assert_eq!(lines.len(), 1, "{run} {}: {lines:?}", c.name);
                    let l = lines[0];
                    assert!(
                        (0.4..0.65).contains(&l.frequency_hz),
                        "{run} {}: {l:?}",
                        c.name
                    );
                    let mg = l.amplitude / 9.80665e-3;
                    assert!((0.3..1.5).contains(&mg), "{run} {}: {mg} mg", c.name);
                    let clean = remove_lines(&c.values, log.tau0_s, &lines);
                    assert!(detect_lines(&clean, log.tau0_s, &cfg).is_empty());
                }
                _ => assert!(lines.is_empty(), "{run} {}: {lines:?}", c.name),
            }
        }
    }
}

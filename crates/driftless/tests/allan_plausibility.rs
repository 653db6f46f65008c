//! Unit plausibility on the real ADIS16405 static runs: read as their header says, no
//! warning; with the gyro columns declared rad/s (they are deg/s) and the accelerometer
//! columns m/s² (they are g), each mislabel is named.

use driftless::allan::plausibility::{ChannelInput, unit_warnings};
use driftless::io::{ColumnRef, ImuLog, TextOptions, Unit, read_log_file};
use std::path::PathBuf;

fn data() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

fn warnings(log: &ImuLog) -> Vec<String> {
    let inputs: Vec<ChannelInput<'_>> = log
        .channels
        .iter()
        .map(|c| ChannelInput {
            name: &c.name,
            quantity: c.quantity,
            stated_unit: &c.source_unit,
            values: &c.values,
        })
        .collect();
    unit_warnings(&inputs, log.tau0_s)
}

#[test]
#[ignore = "needs shared data"]
fn adis16405_units_as_stated_pass_and_mislabels_are_named() {
    for run in ["adis16405_run2.csv.gz", "adis16405_run3.csv.gz"] {
        let path = data().join("static/adis16405_calgary").join(run);
        let log = read_log_file(&path, &TextOptions::default()).expect("read");
        assert_eq!(log.channels.len(), 6, "t [s] is the time, not a channel");
        assert!((log.tau0_s - 0.01).abs() < 1e-9);
        let w = warnings(&log);
        assert!(w.is_empty(), "{run}: {w:?}");
        let mut opts = TextOptions::default();
        for (name, unit) in [
            ("gyro_x", "rad/s"),
            ("gyro_y", "rad/s"),
            ("gyro_z", "rad/s"),
            ("accel_x", "m/s^2"),
            ("accel_y", "m/s^2"),
            ("accel_z", "m/s^2"),
        ] {
            opts = opts.with_column(
                ColumnRef::Name(name.into()),
                Some(Unit::parse(unit).expect("unit")),
            );
        }
        let log = read_log_file(&path, &opts).expect("read mislabelled");
        let w = warnings(&log);
        eprintln!("{run}: {w:#?}");
        for g in ["gyro_x", "gyro_y", "gyro_z"] {
            assert!(
                w.iter()
                    .any(|s| s.starts_with(&format!("{g}:")) && s.contains("deg/s read as rad/s")),
                "{run} {g}: {w:?}"
            );
        }
        assert!(
            w.iter()
                .any(|s| s.contains("accel_x, accel_y, accel_z") && s.contains("look like g")),
            "{run}: {w:?}"
        );
    }
}

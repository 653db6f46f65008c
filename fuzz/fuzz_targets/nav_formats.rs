//! Arbitrary bytes into the navigation and simulation readers: KF-GINS IMU and GNSS text,
//! RTKLIB `.pos`, KF-GINS YAML, scenario and calibration TOML (parsed, not run).
//! Invariants: no panic; errors name the input; parsed numbers are finite.
#![no_main]

use driftless::io::nav::{GnssReadOptions, KfGinsConfig, read_kfgins_gnss, read_kfgins_imu, read_rtklib_pos};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (sel, body) = match data.split_first() {
        Some((s, b)) => (*s, b),
        None => (0, data),
    };
    match sel % 6 {
        0 => match read_kfgins_imu(body, "fuzz") {
            Ok(imu) => {
                assert!(imu.time_s.iter().all(|t| t.is_finite()));
                assert!(imu.time_s.windows(2).all(|w| w[1] > w[0]));
            }
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        1 => match read_kfgins_gnss(body, "fuzz", &GnssReadOptions::default()) {
            Ok(g) => assert!(g.sigma_ned_m.iter().flatten().all(|s| *s > 0.0)),
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        2 => match read_rtklib_pos(body, "fuzz", &GnssReadOptions::default()) {
            Ok(g) => assert!(g.lat_rad.iter().all(|v| v.is_finite())),
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        3 => {
            if let Ok(text) = std::str::from_utf8(body) {
                if let Err(e) = KfGinsConfig::from_yaml_str(text, "fuzz") {
                    assert!(e.to_string().starts_with("fuzz"));
                }
            }
        }
        4 => {
            if let Ok(text) = std::str::from_utf8(body) {
                if let Err(e) = driftless::sim::scenario::Scenario::from_toml_str(text, "fuzz") {
                    assert!(e.to_string().starts_with("fuzz"));
                }
            }
        }
        _ => {
            if let Ok(text) = std::str::from_utf8(body) {
                if let Ok(f) = toml::from_str::<driftless::calib::model_file::CalibrationFile>(text) {
                    let _ = f.validate("fuzz");
                }
            }
        }
    }
});

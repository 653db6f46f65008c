//! `driftless allan LOG --export FORMAT=PATH,…` and `driftless allan --model M --export …`:
//! all six formats from one simulated 6-channel log, each read back or checked against the
//! saved model; the same files from the saved model; the refusals (no fit, an output over
//! an input, an unknown format, a missing accelerometer) with one error line and no panic.

mod common;

use common::{bin, error_of};
use driftless::allan::export::kalibr::KalibrImu;
use driftless::allan::export::{GivenValues, imu_noise};
use driftless::allan::noise_model::NoiseModel;
use driftless::io::nav::kfgins_config::KfGinsConfig;
use driftless::sim::noise::{StaticNoiseConfig, generate};
use driftless_model::units::{DEG, DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, MICRO_G};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn tmp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-export-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Gyro N = 0.15 deg/√h (2.0e-3 rad/s/√Hz… in deg/s columns), B = 3 deg/h, K = 12
/// deg/h/√h; accel N = 0.02 m/s/√h, B = 50 µg, K = 2e-4 m/s³/√Hz; 10 min at 100 Hz.
fn imu_csv(path: &Path, with_accel: bool) {
    let gyro = StaticNoiseConfig {
        sample_rate_hz: 100.0,
        duration_s: 600.0,
        white: 0.15 * DEG_PER_SQRT_H,
        bias_instability: 3.0 * DEG_PER_H,
        rate_random_walk: 12.0 * DEG_PER_H_PER_SQRT_H,
        ..Default::default()
    };
    let accel = StaticNoiseConfig {
        white: 0.02 / 60.0,
        bias_instability: 50.0 * MICRO_G,
        rate_random_walk: 2e-4,
        ..gyro.clone()
    };
    let n_ch = if with_accel { 6 } else { 3 };
    let ch: Vec<Vec<f64>> = (0..n_ch)
        .map(|k| generate(if k < 3 { &gyro } else { &accel }, 7 + k as u64).unwrap())
        .collect();
    let mut s = String::from("t [s],gyro_x [deg/s],gyro_y [deg/s],gyro_z [deg/s]");
    if with_accel {
        s.push_str(",accel_x [m/s^2],accel_y [m/s^2],accel_z [m/s^2]");
    }
    s.push('\n');
    for i in 0..ch[0].len() {
        let _ = write!(s, "{:.2}", i as f64 / 100.0);
        for (k, c) in ch.iter().enumerate() {
            let v = if k < 3 { c[i] / DEG } else { c[i] };
            let _ = write!(s, ",{v:.9e}");
        }
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

fn run_ok(args: &[&std::ffi::OsStr]) -> String {
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// The value of `key` in a `KEY,VALUE` or QGC tab-separated parameter file.
fn param(text: &str, key: &str) -> f64 {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .find_map(|l| {
            let f: Vec<&str> = l.split([',', '\t']).collect();
            let i = f.iter().position(|x| *x == key)?;
            f.get(i + 1)?.parse().ok()
        })
        .unwrap_or_else(|| panic!("{key} not in\n{text}"))
}

#[test]
fn all_six_formats_from_a_log_and_from_its_saved_model() {
    let dir = tmp_dir("six");
    let log = dir.join("imu.csv");
    imu_csv(&log, true);
    let model_path = dir.join("noise.toml");
    let f = |name: &str| dir.join(name);
    let spec = format!(
        "kalibr={},openvins={},vins={},kfgins={},px4={},ardupilot={}",
        f("imu.yaml").display(),
        f("chain.yaml").display(),
        f("vins.yaml").display(),
        f("kfgins.yaml").display(),
        f("ekf2.params").display(),
        f("ekf3.param").display()
    );
    let stdout = run_ok(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--save-model".as_ref(),
        model_path.as_os_str(),
        "--export".as_ref(),
        spec.as_ref(),
    ]);
    for name in ["kalibr", "openvins", "vins", "kfgins", "px4", "ardupilot"] {
        assert!(
            stdout.contains(&format!("{name} noise parameters written to")),
            "{stdout}"
        );
    }
    let model = NoiseModel::load(&model_path).unwrap();
    let imu = imu_noise(&model, &GivenValues::default());
    let gyro_n = imu.gyro.white_density.as_ref().unwrap().value;
    let gyro_k = imu.gyro.random_walk_density.as_ref().unwrap().value;
    let accel_n = imu.accel.white_density.as_ref().unwrap().value;
    let accel_k = imu.accel.random_walk_density.as_ref().unwrap().value;
    // The fit found the simulated white noise (largest of three axes: a little above).
    assert!(rel(gyro_n, 0.15 * DEG_PER_SQRT_H) < 0.15, "{gyro_n}");
    assert!(rel(accel_n, 0.02 / 60.0) < 0.15, "{accel_n}");

    // Kalibr and OpenVINS read back to the model's values.
    let k = KalibrImu::from_file(f("imu.yaml")).unwrap();
    assert!(rel(k.gyro_noise_density_rad_s_sqrt_hz, gyro_n) < 1e-12);
    assert!(rel(k.gyro_random_walk_rad_s2_sqrt_hz, gyro_k) < 1e-12);
    assert!(rel(k.accel_noise_density_m_s2_sqrt_hz, accel_n) < 1e-12);
    assert!(rel(k.accel_random_walk_m_s3_sqrt_hz, accel_k) < 1e-12);
    assert!(rel(k.update_rate_hz, 100.0) < 1e-12);
    assert_eq!(KalibrImu::from_file(f("chain.yaml")).unwrap(), k);

    // VINS: per-sample σ at 100 Hz.
    let vins = std::fs::read_to_string(f("vins.yaml")).unwrap();
    let vins_value = |key: &str| -> f64 {
        vins.lines()
            .find_map(|l| l.strip_prefix(&format!("{key}: ")))
            .and_then(|r| r.split_whitespace().next()?.parse().ok())
            .unwrap()
    };
    assert!(rel(vins_value("gyr_n"), gyro_n * 10.0) < 1e-12);
    assert!(rel(vins_value("acc_w"), accel_k * 10.0) < 1e-12);

    // KF-GINS: the block read by our KF-GINS reader.
    let block = std::fs::read_to_string(f("kfgins.yaml")).unwrap();
    let base = "imupath: imu.txt\ngnsspath: gnss.txt\noutputpath: out\nimudatalen: 7\n\
                imudatarate: 100\nstarttime: 0\nendtime: -1\ninitpos: [30, 114, 20]\n\
                initvel: [0, 0, 0]\ninitatt: [0, 0, 0]\ninitgyrbias: [0, 0, 0]\n\
                initaccbias: [0, 0, 0]\ninitgyrscale: [0, 0, 0]\ninitaccscale: [0, 0, 0]\n\
                initposstd: [1, 1, 1]\ninitvelstd: [1, 1, 1]\ninitattstd: [1, 1, 1]\n\
                antlever: [0, 0, 0]\n";
    let cfg = KfGinsConfig::from_yaml_str(&format!("{base}{block}"), "kf-gins.yaml").unwrap();
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        let g = model.channel(&format!("gyro_{axis}")).unwrap();
        let a = model.channel(&format!("accel_{axis}")).unwrap();
        assert!(rel(cfg.imu_noise.arw_rad_sqrt_s[i], g.fit.white.unwrap().value) < 1e-12);
        assert!(rel(cfg.imu_noise.vrw_m_s_sqrt_s[i], a.fit.white.unwrap().value) < 1e-12);
    }
    let tau = imu.gyro.bias.as_ref().unwrap().tau_c_s;
    let tau = tau.min(imu.accel.bias.as_ref().unwrap().tau_c_s);
    assert!(rel(cfg.imu_noise.corr_time_s, tau) < 1e-12);

    // PX4 at 100 Hz, ArduPilot EKF3 at 1/0.012 s.
    let px4 = std::fs::read_to_string(f("ekf2.params")).unwrap();
    assert!(rel(param(&px4, "EKF2_GYR_NOISE"), gyro_n * 10.0) < 1e-12);
    assert!(rel(param(&px4, "EKF2_ACC_B_NOISE"), accel_k * 10.0) < 1e-12);
    let ap = std::fs::read_to_string(f("ekf3.param")).unwrap();
    let r = (1.0f64 / 0.012).sqrt();
    assert!(rel(param(&ap, "EK3_ACC_P_NSE"), accel_n * r) < 1e-12);
    assert!(rel(param(&ap, "EK3_GBIAS_P_NSE"), gyro_k * r) < 1e-12);

    // The saved model exports the same files without a new analysis.
    let again = f("again.yaml");
    let spec = format!(
        "kalibr={},px4={}",
        again.display(),
        f("again.params").display()
    );
    run_ok(&[
        "allan".as_ref(),
        "--model".as_ref(),
        model_path.as_os_str(),
        "--export".as_ref(),
        spec.as_ref(),
    ]);
    assert_eq!(
        std::fs::read_to_string(&again).unwrap(),
        std::fs::read_to_string(f("imu.yaml")).unwrap()
    );
    assert_eq!(std::fs::read_to_string(f("again.params")).unwrap(), px4);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn exports_are_refused_with_a_reason() {
    let dir = tmp_dir("refused");
    let log = dir.join("gyro.csv");
    imu_csv(&log, false);
    let out = dir.join("imu.yaml");
    let kalibr = format!("kalibr={}", out.display());
    let e = error_of(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--no-fit".as_ref(),
        "--export".as_ref(),
        kalibr.as_ref(),
    ]);
    assert!(e.contains("--export needs the noise fit"), "{e}");
    let over = format!("kalibr={}", log.display());
    let e = error_of(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--export".as_ref(),
        over.as_ref(),
    ]);
    assert!(e.contains("gyro.csv"), "{e}");
    assert!(std::fs::read_to_string(&log).unwrap().starts_with("t [s]"));
    let e = error_of(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--export".as_ref(),
        "rtklib=x.yaml".as_ref(),
    ]);
    assert!(
        e.contains("kalibr, openvins, vins, kfgins, px4 or ardupilot"),
        "{e}"
    );
    // No accelerometer in the log: Kalibr needs one; nothing is written.
    let e = error_of(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--export".as_ref(),
        kalibr.as_ref(),
    ]);
    assert!(
        e.contains("accelerometer_noise_density") && e.contains("no specific-force"),
        "{e}"
    );
    assert!(!out.exists());
    // … unless its values are given.
    run_ok(&[
        "allan".as_ref(),
        log.as_os_str(),
        "--export".as_ref(),
        kalibr.as_ref(),
        "--export-set".as_ref(),
        "accelerometer_noise_density=2e-3,accelerometer_random_walk=3e-3".as_ref(),
    ]);
    let k = KalibrImu::from_file(&out).unwrap();
    assert_eq!(k.accel_random_walk_m_s3_sqrt_hz, 3e-3);
    // --model without --export.
    let e = error_of(&["allan".as_ref(), "--model".as_ref(), out.as_os_str()]);
    assert!(e.contains("needs --export"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

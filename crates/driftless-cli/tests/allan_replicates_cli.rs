//! `driftless allan RUN1 RUN2 …`: replicate logs of one sensor end to end — the JSON
//! document (joint result, `runs`, `replicates`), the saved joint model and overlay plot,
//! the errors for an unreadable file and for logs that are not replicates, and the two
//! real ADIS16405 static runs.

mod common;

use common::{bin, error_of};
use driftless::sim::noise::{StaticNoiseConfig, generate};
use driftless_model::units::{DEG, DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn tmp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-rep-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A simulated 3-gyro log (deg/s) of `minutes` at `rate_hz`.
fn gyro_csv(path: &Path, rate_hz: f64, minutes: f64, seed: u64) {
    let cfg = StaticNoiseConfig {
        sample_rate_hz: rate_hz,
        duration_s: minutes * 60.0,
        white: 0.15 * DEG_PER_SQRT_H,
        bias_instability: 3.0 * DEG_PER_H,
        rate_random_walk: 12.0 * DEG_PER_H_PER_SQRT_H,
        ..Default::default()
    };
    let ch: Vec<Vec<f64>> = (0..3)
        .map(|k| generate(&cfg, seed * 10 + k).unwrap())
        .collect();
    let mut s = String::from("t [s],gyro_x [deg/s],gyro_y [deg/s],gyro_z [deg/s]\n");
    for (i, ((x, y), z)) in ch[0].iter().zip(&ch[1]).zip(&ch[2]).enumerate() {
        let _ = writeln!(
            s,
            "{:.4},{:.7},{:.7},{:.7}",
            i as f64 / rate_hz,
            x / DEG,
            y / DEG,
            z / DEG
        );
    }
    std::fs::write(path, s).unwrap();
}

fn data_dir() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

fn json(args: &[&std::ffi::OsStr]) -> serde_json::Value {
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn two_runs_give_runs_replicates_and_a_joint_model() {
    let dir = tmp_dir("two");
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    gyro_csv(&a, 100.0, 20.0, 1);
    gyro_csv(&b, 100.0, 20.0, 2);
    let model = dir.join("joint.toml");
    let plot = dir.join("runs.svg");
    let doc = json(&[
        "allan".as_ref(),
        a.as_os_str(),
        b.as_os_str(),
        "--json".as_ref(),
        "--save-model".as_ref(),
        model.as_os_str(),
        "--plot".as_ref(),
        plot.as_os_str(),
    ]);
    // The single-run shape describes the joint result.
    let chans = doc["channels"].as_array().expect("channels");
    assert_eq!(chans.len(), 3);
    assert!(
        doc["noise"]["channels"][0]["fit"]["white"]["value"]
            .as_f64()
            .is_some()
    );
    let runs = doc["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[0]["file"].as_str(), a.to_str());
    assert_eq!(runs[1]["channels"].as_array().map(Vec::len), Some(3));
    let rep = &doc["replicates"];
    assert_eq!(rep["runs"].as_array().map(Vec::len), Some(2));
    for c in rep["channels"].as_array().expect("replicate channels") {
        let white = c["terms"]
            .as_array()
            .and_then(|t| t.iter().find(|t| t["term"] == "white"))
            .expect("white noise compared");
        assert_eq!(white["runs"].as_array().map(Vec::len), Some(2));
        assert!(white["verdict"].as_str().is_some());
        assert!(white["pooled"]["value"].as_f64().is_some(), "{white}");
    }
    // The saved model is the joint one.
    let saved = driftless::allan::noise_model::NoiseModel::load(&model).expect("joint model");
    assert!(
        saved
            .source_file
            .as_deref()
            .is_some_and(|s| s.starts_with("joint of"))
    );
    let svg = std::fs::read_to_string(&plot).expect("plot");
    assert!(svg.contains("joint model") && svg.contains("a.csv") && svg.contains("b.csv"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn one_unreadable_file_is_named() {
    let dir = tmp_dir("missing");
    let a = dir.join("a.csv");
    gyro_csv(&a, 100.0, 2.0, 3);
    let missing = dir.join("no_such_run.csv");
    let e = error_of(&["allan".as_ref(), a.as_os_str(), missing.as_os_str()]);
    assert!(e.contains("no_such_run.csv"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn logs_at_different_rates_are_refused_naming_both() {
    let dir = tmp_dir("rates");
    let (a, b) = (dir.join("fast_100hz.csv"), dir.join("slow_50hz.csv"));
    gyro_csv(&a, 100.0, 10.0, 4);
    gyro_csv(&b, 50.0, 20.0, 5);
    let e = error_of(&["allan".as_ref(), a.as_os_str(), b.as_os_str()]);
    assert!(
        e.contains("fast_100hz.csv") && e.contains("slow_50hz.csv"),
        "{e}"
    );
    assert!(e.contains("sample rates differ"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
#[ignore = "needs shared data"]
fn adis16405_run2_run3_through_the_cli() {
    let d = data_dir().join("static/adis16405_calgary");
    let (r2, r3) = (
        d.join("adis16405_run2.csv.gz"),
        d.join("adis16405_run3.csv.gz"),
    );
    // Mismatched logs: an ADIS run (3 gyros, 3 accelerometers) and a 3-gyro log.
    let dir = tmp_dir("adis");
    let sim = dir.join("three_gyros.csv");
    gyro_csv(&sim, 100.0, 10.0, 6);
    let e = error_of(&["allan".as_ref(), r2.as_os_str(), sim.as_os_str()]);
    assert!(
        e.contains("adis16405_run2.csv.gz") && e.contains("three_gyros.csv"),
        "{e}"
    );
    assert!(e.contains("accel_x"), "{e}");

    let start = std::time::Instant::now();
    let doc = json(&[
        "allan".as_ref(),
        r2.as_os_str(),
        r3.as_os_str(),
        "--json".as_ref(),
    ]);
    eprintln!(
        "allan on two ADIS runs: {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert_eq!(doc["runs"].as_array().map(Vec::len), Some(2));
    let rep = &doc["replicates"];
    for name in ["gyro_x", "gyro_y", "gyro_z"] {
        let c = rep["channels"]
            .as_array()
            .and_then(|cs| cs.iter().find(|c| c["name"] == name))
            .expect("gyro compared");
        for t in c["terms"].as_array().expect("terms") {
            eprintln!(
                "{name} {}: {} (spread {})",
                t["term"], t["verdict"], t["spread"]["relative"]
            );
        }
        let white = c["terms"]
            .as_array()
            .and_then(|t| t.iter().find(|t| t["term"] == "white"))
            .expect("white");
        let vals: Vec<f64> = white["runs"]
            .as_array()
            .expect("runs")
            .iter()
            .map(|r| r["value"]["value"].as_f64().expect("white detected"))
            .collect();
        assert_eq!(vals.len(), 2);
        let joint = doc["noise"]["channels"]
            .as_array()
            .and_then(|cs| cs.iter().find(|c| c["name"] == name))
            .and_then(|c| c["fit"]["white"]["value"].as_f64())
            .expect("joint white");
        let mean = 0.5 * (vals[0] + vals[1]);
        eprintln!(
            "{name}: N {:.4} / {:.4} deg/√h, joint {:.4} ({:+.2} % of the mean)",
            vals[0] / DEG_PER_SQRT_H,
            vals[1] / DEG_PER_SQRT_H,
            joint / DEG_PER_SQRT_H,
            100.0 * (joint / mean - 1.0)
        );
        assert!(
            (joint / mean - 1.0).abs() <= 0.05,
            "{name}: {joint} vs {mean}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

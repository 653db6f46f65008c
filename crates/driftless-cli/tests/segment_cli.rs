//! `calibrate six-position LOG` and `thermal soak LOG` without a manifest: a simulated
//! `adi-like` chamber run (every noise term) with a 5-min prefix, dwells jittered ±30 %
//! and +x missed at one temperature, its manifest left unused. The segmentation is
//! printed as a table and in `--json`, the missing position named with its time span, and
//! the soak coefficients agree with the manifest run; bad input is one clear error.

mod common;
use common::{bin, run_json, simulate};

fn chamber(keys: &str) -> String {
    format!(
        "seed = 3\n[imu]\nrate_hz = 50.0\npreset = \"adi-like\"\noutput = \"rates\"\n\
         [trajectory]\ntype = \"chamber\"\nsoak_s = 150.0\nlag_tau_s = 15.0\nmove_s = 2.0\n\
         spin_s = 1.0\nposition_dwell_s = 10.0\nrate_deg_s = 90.0\nrate_revolutions = 1\n\
         prefix_s = 300.0\ndwell_jitter = 0.3\njitter_seed = 2\n{keys}"
    )
}

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-seg-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn soak_without_manifest() {
    let dir = tmp("soak");
    let sim = simulate(
        &dir,
        "sim",
        &chamber(
            "temperatures_c = [-10.0, 5.0, 20.0, 35.0, 50.0, 65.0]\n\
             skip_positions = [{ set_temperature_c = 35.0, up = \"+x\" }]\n",
        ),
    );
    let site = ["--lat-deg", "51.08", "--height-m", "1100"];
    let v = run_json(
        bin()
            .args(["thermal", "soak", "--json", "--order", "3"])
            .args(site)
            .arg(sim.join("imu.csv")),
    );
    let seg = &v["segmentation"];
    let missing: Vec<&serde_json::Value> = seg["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["kind"] == "missing_position")
        .collect();
    assert_eq!(missing.len(), 1, "{}", seg["findings"]);
    assert_eq!(missing[0]["up"], "+x");
    let p = missing[0]["plateau"].as_u64().unwrap() as usize;
    let t = seg["plateaus"][p]["temperature_c"].as_f64().unwrap();
    assert!((t - 35.0).abs() < 0.01, "{t}");
    assert!(missing[0]["end_s"].as_f64().unwrap() > missing[0]["start_s"].as_f64().unwrap());
    // The step without +x is left out: five temperatures in the fit.
    let temps: Vec<f64> = v["temperatures_c"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(temps.len(), 5, "{temps:?}");
    // Against the manifest run without that step: every coefficient within 1σ.
    let text = std::fs::read_to_string(sim.join("manifest.toml")).unwrap();
    let mut m = driftless::calib::protocol::ChamberManifest::from_toml_str(&text).unwrap();
    m.segments.retain(|s| s.set_temperature_c != 35.0);
    std::fs::write(dir.join("reduced.toml"), m.to_toml_string().unwrap()).unwrap();
    let w = run_json(
        bin()
            .args(["thermal", "soak", "--json", "--order", "3", "--manifest"])
            .arg(dir.join("reduced.toml"))
            .arg(sim.join("imu.csv")),
    );
    assert!(w["segmentation"].is_null());
    let mut worst: f64 = 0.0;
    for (a, b) in w["series"]
        .as_array()
        .unwrap()
        .iter()
        .zip(v["series"].as_array().unwrap())
    {
        assert_eq!(
            (&a["triad"], &a["quantity"], &a["axis"]),
            (&b["triad"], &b["quantity"], &b["axis"])
        );
        for k in 0..4 {
            let (ca, cb) = (
                a["coefficients"][k].as_f64().unwrap(),
                b["coefficients"][k].as_f64().unwrap(),
            );
            let s = a["std_errors"][k].as_f64().unwrap();
            worst = worst.max((ca - cb).abs() / s);
        }
    }
    eprintln!("thermal soak CLI: largest |Δ|/σ {worst:.3}");
    assert!(worst <= 1.0, "{worst}");
    // Text mode: the table, the finding with its span, the step left out.
    let out = bin()
        .args(["thermal", "soak", "--order", "3"])
        .args(site)
        .arg(sim.join("imu.csv"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stdout.contains("segmentation of") && stdout.contains("settled"),
        "{stdout}"
    );
    assert!(
        stdout.contains("no static position with +x up") && stdout.contains(" s: plateau "),
        "{stdout}"
    );
    assert!(stderr.contains("plateau left out of the fit"), "{stderr}");
    // Without the site: one clear error naming the file and the options.
    let out = bin()
        .args(["thermal", "soak"])
        .arg(sim.join("imu.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("imu.csv") && e.contains("--lat-deg") && e.lines().count() == 1,
        "{e}"
    );
}

#[test]
fn six_position_without_manifest() {
    let dir = tmp("six");
    let sim = simulate(&dir, "sim", &chamber("temperatures_c = [25.0]\n"));
    let v = run_json(
        bin()
            .args(["calibrate", "six-position", "--json"])
            .args(["--lat-deg", "51.08", "--height-m", "1100"])
            .arg(sim.join("imu.csv")),
    );
    let seg = &v["segmentation"];
    assert_eq!(seg["plateaus"].as_array().unwrap().len(), 1);
    let pos: Vec<u64> = seg["plateaus"][0]["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert!(pos.iter().all(|&n| n == 1), "{pos:?}");
    assert!(
        seg["statics"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s["role"] == "other"),
        "the prefix's tilt"
    );
    let w = run_json(
        bin()
            .args(["calibrate", "six-position", "--json", "--manifest"])
            .arg(sim.join("manifest.toml"))
            .arg(sim.join("imu.csv")),
    );
    for triad in ["accel", "gyro"] {
        for i in 0..3 {
            let (a, b, s) = (
                w[triad]["bias"][i].as_f64().unwrap(),
                v[triad]["bias"][i].as_f64().unwrap(),
                w[triad]["bias_sigma"][i].as_f64().unwrap(),
            );
            assert!((a - b).abs() <= s, "{triad} bias {i}: {a} vs {b} ± {s}");
            for j in 0..3 {
                let (a, b, s) = (
                    w[triad]["matrix"][i][j].as_f64().unwrap(),
                    v[triad]["matrix"][i][j].as_f64().unwrap(),
                    w[triad]["matrix_sigma"][i][j].as_f64().unwrap(),
                );
                assert!((a - b).abs() <= s, "{triad} M[{i}][{j}]: {a} vs {b} ± {s}");
            }
        }
    }
    // Text mode prints the segment table before the calibration.
    let out = bin()
        .args(["calibrate", "six-position"])
        .args(["--lat-deg", "51.08", "--height-m", "1100"])
        .arg(sim.join("imu.csv"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("rotation") && stdout.contains("soak, position from"),
        "{stdout}"
    );
    // A NaN row: one error naming the file, the sample and its time.
    let text = std::fs::read_to_string(sim.join("imu.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let row = lines
        .iter()
        .position(|l| l.starts_with("100.000") || l.starts_with("100,"))
        .unwrap_or(5001);
    let mut cells: Vec<String> = lines[row].split(',').map(String::from).collect();
    cells[5] = "NaN".into();
    lines[row] = cells.join(",");
    std::fs::write(dir.join("bad.csv"), lines.join("\n") + "\n").unwrap();
    let out = bin()
        .args(["calibrate", "six-position"])
        .arg(dir.join("bad.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("bad.csv") && e.contains("sample") && e.lines().count() == 1,
        "{e}"
    );
}

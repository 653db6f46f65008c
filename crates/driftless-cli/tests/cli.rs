//! End-to-end tests of the `driftless` binary: the `allan --json` contract, bad input
//! (one clear error naming file, line and column; exit code ≠ 0; nothing on stdout), and
//! gap handling.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_driftless"))
}

fn data_dir() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

fn tmp_file(name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, contents).unwrap();
    p
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run driftless")
}

/// Runs and expects failure with exactly one error line naming `needle`s; stdout empty.
fn expect_error(args: &[&str], needles: &[&str]) -> String {
    let out = run(args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        !out.status.success(),
        "expected failure for {args:?}; stderr: {stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "partial output on stdout for {args:?}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "one error line expected: {stderr}");
    for n in needles {
        assert!(stderr.contains(n), "error should mention {n:?}: {stderr}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

fn csv_with_time(rows: &[&str]) -> String {
    let mut s = String::from("time,gyro_x,gyro_y\n");
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

/// A clean 3-column CSV with `n` rows at 100 Hz.
fn good_rows(n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let t = i as f64 * 0.01;
            format!(
                "{t:.2},{:.6},{:.6}",
                ((i * 7919) % 101) as f64 * 1e-3,
                ((i * 104_729) % 97) as f64 * 1e-3
            )
        })
        .collect()
}

#[test]
fn non_numeric_field_names_line_and_column() {
    let mut rows = good_rows(50);
    rows[9] = "0.09,0.001,abc".into();
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("nonnum.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    // header is line 1, row index 9 is line 11; "abc" starts at byte column 12
    expect_error(
        &["allan", &path, "--time-column", "time"],
        &[&format!("{path}:11:12"), "abc", "gyro_y"],
    );
}

#[test]
fn ragged_row() {
    let mut rows = good_rows(50);
    rows[4] = "0.04,0.001".into();
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("ragged.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &["allan", &path, "--time-column", "time"],
        &[&format!("{path}:6:")],
    );
}

#[test]
fn nan_and_inf_values() {
    for (name, bad) in [("nan.csv", "NaN"), ("inf.csv", "inf")] {
        let mut rows = good_rows(50);
        rows[20] = format!("0.20,{bad},0.001");
        let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
        let p = tmp_file(name, &csv_with_time(&refs));
        let path = p.display().to_string();
        expect_error(
            &["allan", &path, "--time-column", "time"],
            &[&format!("{path}:22:6")],
        );
    }
}

#[test]
fn non_monotonic_and_duplicated_timestamps() {
    let mut rows = good_rows(50);
    rows[30] = "0.25,0.001,0.002".into();
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("backwards.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &["allan", &path, "--time-column", "time"],
        &[&format!("{path}:32")],
    );

    let mut rows = good_rows(50);
    rows[30] = "0.29,0.001,0.002".into();
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("dup.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &["allan", &path, "--time-column", "time"],
        &[&format!("{path}:32")],
    );
}

#[test]
fn gaps_error_by_default_and_split_or_bridge_on_request() {
    // 400 rows, then a 1-s gap, then 400 rows
    let mut rows = good_rows(400);
    for i in 0..400 {
        let t = 5.0 + i as f64 * 0.01;
        rows.push(format!(
            "{t:.2},{:.6},{:.6}",
            ((i * 31) % 17) as f64 * 1e-3,
            ((i * 13) % 11) as f64 * 1e-3
        ));
    }
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("gap.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &["allan", &path, "--time-column", "time"],
        &[&format!("{path}:402")],
    );

    for policy in ["split", "bridge"] {
        let out = run(&[
            "allan",
            &path,
            "--time-column",
            "time",
            "--gaps",
            policy,
            "--taus",
            "0.01,0.1",
            "--no-fit",
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{policy}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let n0 = v["channels"][0]["n"][0].as_u64().unwrap();
        // split: no second difference straddles the gap → (400−2)+(400−2) terms at m=1
        // from two segments of 400 rates (401 phase points each); bridge: 800 rates → 799.
        let want = if policy == "split" {
            2 * (401 - 2)
        } else {
            801 - 2
        };
        assert_eq!(n0, want as u64, "{policy}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("gap"),
            "{policy} should warn about the gap: {stderr}"
        );
    }
}

#[test]
fn too_few_samples_for_a_tau() {
    let rows = good_rows(50);
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("short.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &[
            "allan",
            &path,
            "--time-column",
            "time",
            "--taus",
            "0.01,100",
        ],
        &[&path, "tau = 100", "needs at least"],
    );
}

#[test]
fn empty_file_and_header_only() {
    let p = tmp_file("empty.csv", "");
    let path = p.display().to_string();
    expect_error(&["allan", &path, "--rate", "100"], &[&path]);
    let p = tmp_file("comments.csv", "# only a comment\n\n");
    let path = p.display().to_string();
    expect_error(&["allan", &path, "--rate", "100"], &[&path]);
    let p = tmp_file("header.csv", "time,gyro_x\n");
    let path = p.display().to_string();
    expect_error(&["allan", &path, "--time-column", "time"], &[&path]);
}

#[test]
fn missing_file_and_bad_flags() {
    expect_error(
        &["allan", "/nonexistent/x.csv", "--rate", "1"],
        &["/nonexistent/x.csv"],
    );
    let rows = good_rows(50);
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("ok.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    expect_error(
        &["allan", &path, "--time-column", "time", "--taus", "log:x"],
        &["log:x"],
    );
    expect_error(
        &[
            "allan",
            &path,
            "--time-column",
            "time",
            "--estimator",
            "xdev",
        ],
        &["xdev"],
    );
    expect_error(
        &[
            "allan",
            &path,
            "--time-column",
            "time",
            "--column",
            "gyro_x:furlongs",
        ],
        &["furlongs"],
    );
    expect_error(&["allan", &path, "--time-column", "nope"], &["nope"]);
}

#[test]
fn units_are_converted_at_the_edge() {
    // the same data in deg/s and in rad/s must give the same deviations in rad/s
    let rows = good_rows(2000);
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let p = tmp_file("deg.csv", &csv_with_time(&refs));
    let path = p.display().to_string();
    let json = |unit: &str| -> serde_json::Value {
        let out = run(&[
            "allan",
            &path,
            "--time-column",
            "time",
            "--unit",
            unit,
            "--taus",
            "octave",
            "--no-fit",
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let deg = json("deg/s");
    let rad = json("rad/s");
    let d = deg["channels"][0]["dev"].as_array().unwrap();
    let r = rad["channels"][0]["dev"].as_array().unwrap();
    for (a, b) in d.iter().zip(r) {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        assert!((a / b - std::f64::consts::PI / 180.0).abs() < 1e-12);
    }
    assert_eq!(deg["channels"][0]["unit"], "rad/s");
}

fn stable32_rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|f| f.parse().unwrap()).collect())
        .collect()
}

/// The machine-readable contract, through the binary, on Stable32 reference data.
#[test]
#[ignore = "needs shared data"]
fn json_contract_matches_stable32() {
    let d = data_dir().join("allan");
    let cases: [(&str, &str, &[&str], &str, f64); 3] = [
        (
            "phasedat/PHASE.DAT",
            "phase",
            &[],
            "phasedat/phase_dat_oadev_octave.txt",
            1e-4,
        ),
        (
            "ocxo/ocxo_frequency.txt",
            "freq",
            &["--scale", "1e-7"],
            "ocxo/adev_octave.txt",
            2e-3,
        ),
        (
            "pink_frequency/pink_frequency.txt",
            "freq",
            &[],
            "pink_frequency/s32_oadev_octave.txt",
            1e-4,
        ),
    ];
    for (input, dtype, extra, result, tol) in cases {
        let est = if result.contains("_adev") || result.starts_with("ocxo/adev") {
            "adev"
        } else {
            "oadev"
        };
        let input = d.join(input).display().to_string();
        let mut args = vec![
            "allan",
            &input,
            "--data-type",
            dtype,
            "--rate",
            "1",
            "--taus",
            "octave",
            "--estimator",
            est,
            "--json",
        ];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let ch = &v["channels"][0];
        for key in [
            "name",
            "estimator",
            "tau",
            "m",
            "n",
            "dev",
            "dev_lo",
            "dev_hi",
            "alpha",
        ] {
            assert!(!ch[key].is_null(), "missing {key}");
        }
        assert!(v.get("noise").is_some());
        assert_eq!(ch["estimator"], est);
        let rows = stable32_rows(&d.join(result));
        let n = ch["n"].as_array().unwrap();
        let dev = ch["dev"].as_array().unwrap();
        assert_eq!(n.len(), rows.len(), "{result}: number of taus");
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(ch["m"][i].as_u64().unwrap() as f64, r[0]);
            assert_eq!(n[i].as_u64().unwrap() as f64, r[2], "{result} row {i}");
            let got = dev[i].as_f64().unwrap();
            assert!(
                (got - r[5]).abs() / r[5] < tol,
                "{result} row {i}: {got} vs {}",
                r[5]
            );
            let lo = ch["dev_lo"][i].as_f64().unwrap();
            let hi = ch["dev_hi"][i].as_f64().unwrap();
            assert!(lo < got && got < hi);
        }
    }
}

/// `allan` on a moving log (a simulated vehicle: stops, turns, vibration) warns on
/// stderr and in `--json` that the input is not static; a static one of the same noise
/// does not.
#[test]
fn allan_warns_when_the_input_is_not_static() {
    let noise = |i: usize| {
        // deterministic pseudo-random, uniform in ±0.01
        let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        ((z >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
    };
    let log = |moving: bool| {
        let mut s = String::from("time,gyro_z\n");
        for i in 0..60_000 {
            let t = i as f64 * 0.01;
            let mut w = noise(i);
            if moving && (t % 120.0) > 20.0 {
                w += if (t % 30.0) < 5.0 { 0.3 } else { 0.0 };
                w += 0.05 * (2.0 * std::f64::consts::PI * 13.0 * t).sin();
            }
            s.push_str(&format!("{t:.2},{w:.6}\n"));
        }
        s
    };
    for moving in [false, true] {
        let path = tmp_file(&format!("allan-moving-{moving}.csv"), &log(moving));
        let path = path.to_str().unwrap();
        let out = run(&["allan", path, "--time-column", "time", "--json"]);
        assert!(out.status.success());
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let warnings = v["warnings"].as_array().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let not_static = warnings.iter().any(|w| {
            w.as_str()
                .unwrap()
                .contains("gyro_z: the input is not static")
        });
        assert_eq!(not_static, moving, "{warnings:?}");
        assert_eq!(stderr.contains("not static"), moving, "{stderr}");
        if moving {
            assert!(stderr.contains(path), "{stderr}");
        }
    }
}

/// The real car drive (gyro z in deg/s): not static.
#[test]
#[ignore = "needs shared data"]
fn allan_warns_on_the_real_drive_log() {
    let p = data_dir().join("drive/drive_0708/imu_1934.csv");
    let p = p.to_str().unwrap();
    let out = run(&[
        "allan", p, "--rate", "100", "--column", "6", "--unit", "deg/s", "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    eprintln!("{}", v["warnings"]);
    assert!(
        v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("not static"))
    );
}

/// White noise through a 4-tap moving average (a sensor's anti-alias filter): the fit
/// leaves out the short τ it colours and says so; `--fit-range` sets the range by hand;
/// bad ranges are one error naming the flag.
#[test]
fn allan_fit_range_automatic_and_by_hand() {
    let white = |i: usize| {
        let mut z = (i as u64 + 17).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 29;
        ((z >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
    };
    let mut s = String::from("time,gyro_z\n");
    for i in 0..100_000 {
        let w = (0..4).map(|k| white(i + k)).sum::<f64>() / 4.0;
        s.push_str(&format!("{:.2},{w:.9}\n", i as f64 * 0.01));
    }
    let path = tmp_file("allan-filtered.csv", &s);
    let path = path.to_str().unwrap();
    let out = run(&["allan", path, "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let fit = &v["noise"]["channels"][0]["fit"];
    assert_eq!(fit["fit_range"]["source"], "auto", "{fit}");
    assert!(
        fit["fit_range"]["excluded_short"].as_u64().unwrap() >= 1,
        "{fit}"
    );
    assert!(fit["fit_range"]["tau_min_s"].as_f64().unwrap() > 0.01);
    assert!(fit["chi2_reduced"].as_f64().unwrap() <= 5.0, "{fit}");
    assert!(fit["chi2_verdict"].as_str().unwrap().len() > 4);
    assert!(v["channels"][0]["rate_acf1"][0].as_f64().unwrap() > 0.5);

    let text = run(&["allan", path]);
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(stdout.contains("fit range 0."), "{stdout}");
    assert!(stdout.contains("automatic:"), "{stdout}");
    assert!(stdout.contains("chi2_red"), "{stdout}");

    let out = run(&["allan", path, "--json", "--fit-range", "0.5:50"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &v["noise"]["channels"][0]["fit"]["fit_range"];
    assert_eq!(r["source"], "user");
    assert!(r["tau_min_s"].as_f64().unwrap() >= 0.5 && r["tau_max_s"].as_f64().unwrap() <= 50.0);

    for bad in ["5:1", "abc", "0.1", "-1:5"] {
        let flag = format!("--fit-range={bad}");
        expect_error(&["allan", path, &flag], &["--fit-range", "TMIN:TMAX"]);
    }
    expect_error(
        &["allan", path, "--fit-range", "1e6:2e6"],
        &["--fit-range", "no curve point inside"],
    );
    expect_error(
        &["allan", path, "--fit-range", "1:10", "--method", "gmwm"],
        &["--fit-range", "gmwm"],
    );
}

//! What a user sees on the terminal and reads back: binary or control bytes given as a text
//! log are one clean error line (never echoed raw), and `simulate`'s own `imu.csv` reads
//! in `allan` and `convert` as it is, with errors that name command-line flags.

mod common;
use common::bin;
use std::path::{Path, PathBuf};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-defects-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `driftless ARGS` expecting failure: exit 1, nothing on stdout, stderr printable
/// (no byte of the input, no control character but the line end) and short; returns it.
fn clean_error(args: &[&std::ffi::OsStr]) -> String {
    let o = bin().args(args).output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(1),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.stdout.is_empty(), "{args:?}: stdout {:?}", o.stdout);
    let err = String::from_utf8(o.stderr.clone())
        .unwrap_or_else(|_| panic!("{args:?}: stderr is not UTF-8: {:?}", o.stderr));
    assert!(
        !err.chars().any(|c| c.is_control() && c != '\n'),
        "{args:?}: control characters on the terminal: {err:?}"
    );
    assert!(err.len() < 1500, "{args:?}: {} bytes of error", err.len());
    err
}

#[test]
fn binary_and_control_bytes_given_as_text_are_one_clean_error() {
    let d = scratch("binary");
    // The start of an executable (NUL bytes), the same without its NULs, and a text log
    // with a terminal escape sequence in a value.
    let exe = std::fs::read(env!("CARGO_BIN_EXE_driftless")).unwrap();
    let head = &exe[..exe.len().min(4096)];
    let no_nul: Vec<u8> = head.iter().copied().filter(|&b| b != 0).collect();
    let cases: [(&str, Vec<u8>, &str); 3] = [
        ("prog.csv", head.to_vec(), "binary data"),
        ("prog-nonul.csv", no_nul, "binary data"),
        (
            "escape.csv",
            b"t,gx\n0,\x1b[2J\x1b[31mred\n0.01,1\n".to_vec(),
            "column 2",
        ),
    ];
    for (name, bytes, what) in cases {
        let input = d.join(name);
        std::fs::write(&input, bytes).unwrap();
        let out = d.join("out.csv");
        for args in [
            vec![
                "allan".as_ref(),
                input.as_os_str(),
                "--rate".as_ref(),
                "100".as_ref(),
            ],
            vec!["convert".as_ref(), input.as_os_str(), out.as_os_str()],
        ] {
            let err = clean_error(&args);
            assert!(
                err.contains(name) && err.contains(what),
                "{name}: {args:?}: {err}"
            );
            assert!(!out.exists(), "{name}: convert wrote an output");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Simulates a 20-s static log with every output family into `dir/sim`.
fn simulate_static(dir: &Path) -> PathBuf {
    let sc = dir.join("static.toml");
    std::fs::write(
        &sc,
        "seed = 2\n[imu]\nrate_hz = 100.0\npreset = \"consumer\"\n[trajectory]\n\
         type = \"static\"\nlat_deg = 30.0\nduration_s = 20.0\n",
    )
    .unwrap();
    let out = dir.join("sim");
    let o = bin()
        .args(["simulate", "--quiet", "--out"])
        .arg(&out)
        .arg(&sc)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

#[test]
fn simulated_imu_csv_reads_in_allan_and_convert_and_errors_name_flags() {
    let d = scratch("simcsv");
    let sim = simulate_static(&d);
    let csv = sim.join("imu.csv");
    // allan: time from the header, the six rate channels analysed.
    let o = bin().arg("allan").arg(&csv).arg("--json").output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "allan on simulate's imu.csv: {err}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let names: Vec<&str> = v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 6, "{names:?}");
    assert!(
        names.contains(&"gyro_x") && names.contains(&"acc_z"),
        "{names:?}"
    );
    assert!((v["channels"][0]["tau0"].as_f64().unwrap() - 0.01).abs() < 1e-12);
    // convert: to DRIFTLOG and back to CSV, which allan reads as the original.
    let dlog = d.join("imu.dlog");
    let back = d.join("back.csv");
    for (from, to) in [(&csv, &dlog), (&dlog, &back)] {
        let o = bin().arg("convert").arg(from).arg(to).output().unwrap();
        assert!(
            o.status.success(),
            "convert {} {}: {}",
            from.display(),
            to.display(),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let again = bin()
        .arg("allan")
        .arg(&back)
        .arg("--json")
        .output()
        .unwrap();
    assert!(again.status.success());
    let w: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    for (a, b) in v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .zip(w["channels"].as_array().unwrap())
    {
        assert_eq!(a["name"], b["name"]);
        assert_eq!(a["dev"], b["dev"], "{}: CSV → DRIFTLOG → CSV", a["name"]);
    }
    // Without a time column the error names the flags to give, not a configuration key.
    let no_time = d.join("no-time.csv");
    std::fs::write(&no_time, "gyro_x [rad/s]\n0.1\n0.2\n0.3\n").unwrap();
    for cmd in ["allan", "convert"] {
        let mut args = vec![cmd.as_ref(), no_time.as_os_str()];
        let out = d.join("x.csv");
        if cmd == "convert" {
            args.push(out.as_os_str());
        }
        let err = clean_error(&args);
        assert!(
            err.contains("--rate") && err.contains("--time-column"),
            "{cmd}: {err}"
        );
        assert!(!err.contains("rate_hz"), "{cmd}: names a TOML key: {err}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

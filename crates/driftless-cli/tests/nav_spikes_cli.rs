//! `driftless nav` on the simulated city drive (`examples/scenarios/city-drive.toml`, via
//! `driftless simulate`) with one 10⁶-rad/s gyro sample written into its KF-GINS IMU
//! file: refused by default (non-zero exit, naming time, channel and `--repair-spikes`),
//! navigated with `--repair-spikes` (the repair reported), and a clean run reports
//! nothing.

mod common;
use common::{bin, run_json};

/// GPS seconds of week of the scenario's start.
const T0: f64 = 356_400.0;

/// The simulated drive in `dir/sim`.
fn simulated(dir: &std::path::Path) -> std::path::PathBuf {
    let scenario = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/scenarios/city-drive.toml");
    let out = dir.join("sim");
    run_json(
        bin()
            .args(["simulate", "--json", "--force", "--out"])
            .arg(&out)
            .arg(&scenario),
    );
    out
}

/// `imu.txt` with `value` added to field `field` (1..=3: Δθ x, y, z) of the row whose time
/// is `time_s`, written to `out`.
fn with_spike(imu: &std::path::Path, out: &std::path::Path, time_s: f64, field: usize, add: f64) {
    let text = std::fs::read_to_string(imu).unwrap();
    let mut hit = false;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            let mut f: Vec<String> = l.split_whitespace().map(str::to_owned).collect();
            let t: f64 = f[0].parse().unwrap();
            if !hit && (t - time_s).abs() < 1e-6 {
                hit = true;
                let v: f64 = f[field].parse().unwrap();
                f[field] = format!("{:e}", v + add);
            }
            f.join(" ")
        })
        .collect();
    assert!(hit, "no row at {time_s}");
    std::fs::write(out, lines.join("\n") + "\n").unwrap();
}

fn nav(sim: &std::path::Path, imu: &std::path::Path) -> std::process::Command {
    let mut c = bin();
    c.arg("nav")
        .arg("--imu")
        .arg(imu)
        .arg("--gnss")
        .arg(sim.join("gnss.txt"))
        .args(["--lever-arm", "0.3,0,-1.2"]);
    c
}

#[test]
fn nav_refuses_a_non_physical_gyro_sample_and_repairs_it_when_asked() {
    let dir = std::env::temp_dir().join(format!("driftless-nav-spikes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let sim = simulated(&dir);

    // Clean: nothing found, no recovery.
    let clean = run_json(nav(&sim, &sim.join("imu.txt")).arg("--json"));
    assert_eq!(clean["imu_check"]["findings"].as_array().unwrap().len(), 0);
    assert_eq!(clean["gnss_recoveries"].as_array().unwrap().len(), 0);
    let clean_rms = clean["horizontal_rms_m"].as_f64().unwrap();

    // 10⁶ rad/s about z for one 10-ms sample: Δθ += 10⁴ rad.
    let t_spike = T0 + 100.01;
    let spiked = dir.join("imu-spike.txt");
    with_spike(&sim.join("imu.txt"), &spiked, t_spike, 3, 1e6 * 0.01);

    let out = nav(&sim, &spiked).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    eprintln!("{err}");
    assert!(
        !out.status.success(),
        "a non-physical sample must not exit 0"
    );
    assert!(out.stdout.is_empty(), "no result is printed");
    for needle in ["gyro_z", "356500.010 s", "non-physical", "--repair-spikes"] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }

    // With --repair-spikes: navigated, the repair reported, the result as clean.
    let out = nav(&sim, &spiked)
        .args(["--repair-spikes", "--json"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: IMU gyro_z at t = 356500.010 s")
            && err.contains("replaced by interpolation"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ic = &v["imu_check"];
    assert_eq!(ic["non_physical"], 1);
    assert_eq!(ic["repaired"], 1);
    let f = &ic["findings"][0];
    assert_eq!(f["channel"], "gyro_z");
    assert_eq!(f["kind"], "non_physical");
    assert!((f["time_s"].as_f64().unwrap() - t_spike).abs() < 1e-6);
    let rms = v["horizontal_rms_m"].as_f64().unwrap();
    eprintln!("one-step RMS: clean {clean_rms:.4} m, repaired spike {rms:.4} m");
    assert!(rms < 1.5 * clean_rms, "{rms} vs {clean_rms}");
    assert_eq!(v["gnss_recoveries"].as_array().unwrap().len(), 0);

    // Text output lists the findings' summary.
    let out = nav(&sim, &spiked).arg("--repair-spikes").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "IMU values: 1 non-physical, 0 isolated outliers, 0 saturated runs; 1 replaced"
        ),
        "{text}"
    );

    // A hard limit below the drive's yaw rate makes ordinary samples non-physical: the
    // limit is what decides, and the error names the flag that sets it.
    let out = nav(&sim, &sim.join("imu.txt"))
        .args(["--max-gyro-deg-s", "5"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("--max-gyro-deg-s"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

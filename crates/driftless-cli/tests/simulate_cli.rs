//! `driftless simulate`: the self-contained example scenario end to end — files written,
//! read back by `nav` in two formats — and scenario errors naming file and key.

use std::path::PathBuf;

mod common;
use common::{bin, run_json};

fn scenario(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/scenarios")
        .join(name)
}

#[test]
fn city_drive_scenario_writes_files_that_nav_reads() {
    let dir = std::env::temp_dir().join(format!("driftless-sim-{}", std::process::id()));
    let v = run_json(
        bin()
            .args(["simulate", "--json", "--out"])
            .arg(&dir)
            .arg(scenario("city-drive.toml")),
    );
    assert_eq!(v["seed"], 7);
    let n = v["imu_samples"].as_u64().unwrap();
    assert!(n > 20_000, "{n}");
    for f in [
        "imu.csv",
        "imu.txt",
        "truth.nav",
        "gnss.txt",
        "gnss.pos",
        "kf-gins.yaml",
        "sensor.toml",
    ] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    // Same seed, same bytes.
    let again = dir.join("again");
    run_json(
        bin()
            .args(["simulate", "--json", "--out"])
            .arg(&again)
            .arg(scenario("city-drive.toml")),
    );
    for f in ["imu.txt", "gnss.pos"] {
        assert_eq!(
            std::fs::read(dir.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f} differs between two runs with one seed"
        );
    }
    // The KF-GINS job runs unchanged.
    let k = run_json(
        bin()
            .current_dir(&dir)
            .args(["nav", "--kf-gins", "kf-gins.yaml", "--json"]),
    );
    // one row per IMU epoch after the initial state (the simulated starttime is before
    // the first sample, so every sample is written)
    assert_eq!(k["epochs"].as_u64().unwrap(), n);
    assert!(k["gnss_accepted"].as_u64().unwrap() > 100);
    // The rate CSV with the RTKLIB fixes (velocity included) through the generic path.
    let r = run_json(bin().current_dir(&dir).args([
        "nav",
        "--imu",
        "imu.csv",
        "--imu-format",
        "csv",
        "--gnss",
        "gnss.pos",
        "--lever-arm",
        "0.3,0,-1.2",
        "--json",
    ]));
    let rms = r["horizontal_rms_m"].as_f64().unwrap();
    eprintln!("simulated city drive through nav --imu-format csv: RMS {rms:.3} m");
    assert!(rms < 0.2, "one-step prediction RMS {rms} m");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_scenario_names_file_and_key() {
    let dir = std::env::temp_dir().join(format!("driftless-simbad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "[imu]\nrate_hz = 100.0\npreset = \"consumer\"\nspeed_km_h = 3\n[trajectory]\ntype = \"static\"\nlat_deg = 1.0\nduration_s = 10.0\n",
            "speed_km_h",
        ),
        (
            "[imu]\nrate_hz = 100.0\npreset = \"consumer\"\n[trajectory]\ntype = \"static\"\nlat_deg = 1.0\nduration_s = -10.0\n",
            "duration_s",
        ),
        (
            "[imu]\nrate_hz = 100.0\npreset = \"consumer\"\n[trajectory]\ntype = \"profile\"\n[trajectory.start]\nlat_deg = 1.0\nlon_deg = 1.0\nheight_m = 0.0\nheading_deg = 0.0\n[[trajectory.segment]]\ntype = \"turn\"\nangle_deg = 90.0\nradius_m = 0.0\n",
            "radius_m",
        ),
        (
            "[imu]\nrate_hz = 100.0\npreset = \"consumer\"\n[trajectory]\ntype = \"static\"\nlat_deg = 1.0\nduration_s = 10.0\n[temperature]\nkind = \"constant\"\nt_c = 120.0\n",
            "120",
        ),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let p = dir.join(format!("bad{i}.toml"));
        std::fs::write(&p, text).unwrap();
        let out = bin()
            .args(["simulate", "--out"])
            .arg(dir.join("out"))
            .arg(&p)
            .output()
            .unwrap();
        assert!(!out.status.success(), "case {i} should fail");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(want) && err.contains(&format!("bad{i}.toml")),
            "case {i}: {err}"
        );
        assert!(out.stdout.is_empty());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The simulated hand-held walk (`walk-yard.toml`: consumer IMU, 4-Hz RTK saying 1 cm
/// while the antenna sways by decimetres) through `nav` with nothing but its geometry:
/// the σ floor is estimated from the data, the default gate keeps the fixes, and the
/// outage ends are covered by the filter's own 3σ.
#[test]
fn hand_held_walk_runs_from_the_cli_with_only_its_geometry() {
    let dir = std::env::temp_dir().join(format!("driftless-walk-{}", std::process::id()));
    run_json(
        bin()
            .args(["simulate", "--json", "--out"])
            .arg(&dir)
            .arg(scenario("walk-yard.toml")),
    );
    let v = run_json(bin().current_dir(&dir).args([
        "nav",
        "--imu",
        "imu.csv",
        "--gnss",
        "gnss.pos",
        "--lever-arm",
        "0,0,-0.25",
        "--json",
    ]));
    let floors = v["gnss_sigma_floors"].as_array().unwrap();
    let fix = floors
        .iter()
        .find(|f| f["quality"] == "fix" && f["kind"] == "position")
        .expect("a floor for the fixed solutions");
    let h = fix["horizontal"].as_f64().unwrap();
    eprintln!("walk through the CLI: fix floor {h:.3} m, {v}");
    // The antenna sways by σ 0.2 m per horizontal axis against a 1-cm file σ.
    assert!((0.1..0.8).contains(&h), "estimated floor {h} m");
    let (acc, rej) = (
        v["gnss_accepted"].as_u64().unwrap() as f64,
        v["gnss_rejected"].as_u64().unwrap() as f64,
    );
    assert!(rej < 0.02 * (acc + rej), "{rej} of {} rejected", acc + rej);
    let rms = v["horizontal_rms_m"].as_f64().unwrap();
    assert!(rms < 0.5, "one-step prediction RMS {rms} m");
    // The statistical bars (outage ends inside 3σ over 20 seeds) are asserted by the
    // library's walk study (`tests/nav_walk.rs`).
    let _ = std::fs::remove_dir_all(&dir);
}

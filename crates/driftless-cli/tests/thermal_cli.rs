//! `driftless thermal soak` on a short simulated adi-like chamber run (deterministic
//! errors): 12 fitted series, the model file and the figure; too few temperatures for
//! the order is a clear error.

mod common;
use common::{bin, run_json};

#[test]
fn soak_on_a_simulated_chamber_run() {
    let dir = std::env::temp_dir().join(format!("driftless-thermal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = "seed = 9\n[imu]\nrate_hz = 50.0\npreset = \"adi-like\"\noutput = \"rates\"\n\
                    errors = \"deterministic\"\n[trajectory]\ntype = \"chamber\"\n\
                    temperatures_c = [-20.0, 0.0, 25.0, 45.0, 70.0]\nsoak_s = 60.0\n\
                    lag_tau_s = 5.0\nposition_dwell_s = 5.0\nmove_s = 2.0\nrate_revolutions = 1\n\
                    spin_s = 1.0\n";
    std::fs::write(dir.join("chamber.toml"), scenario).unwrap();
    run_json(
        bin()
            .args(["simulate", "--json", "--out"])
            .arg(dir.join("sim"))
            .arg(dir.join("chamber.toml")),
    );
    let v = run_json(
        bin()
            .args(["thermal", "soak", "--json", "--manifest"])
            .arg(dir.join("sim/manifest.toml"))
            .arg(dir.join("sim/imu.csv"))
            .arg("--out")
            .arg(dir.join("model.toml"))
            .arg("--plot")
            .arg(dir.join("thermal.svg")),
    );
    assert_eq!(v["series"].as_array().unwrap().len(), 12);
    assert_eq!(v["temperatures_c"].as_array().unwrap().len(), 5);
    let model = std::fs::read_to_string(dir.join("model.toml")).unwrap();
    assert!(model.contains("bias_delta") && model.contains("out_of_range = \"clamp\""));
    let svg = std::fs::read_to_string(dir.join("thermal.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("gyro bias"));
    // Deterministic errors: the gyro x bias slope is the preset's (the turn-on bias
    // shifts c0 only), up to the output quantization of each constant position reading
    // (≤ LSB/2 of the preset's 16-bit ±10 V card: measured 3e-5 relative).
    let s = v["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["triad"] == "gyro" && s["quantity"] == "bias" && s["axis"] == "x")
        .unwrap();
    let c1 = s["coefficients"][1].as_f64().unwrap();
    let cfg = driftless::sim::presets::Preset::AdiLike.config();
    let want = cfg.gyro.bias_poly_rad_s[0][1];
    assert!((c1 - want).abs() <= 1e-3 * want.abs(), "c1 {c1} vs {want}");
    // Order 4 from five temperatures leaves no degree of freedom: refused, named.
    let out = bin()
        .args(["thermal", "soak", "--order", "4", "--manifest"])
        .arg(dir.join("sim/manifest.toml"))
        .arg(dir.join("sim/imu.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("5 set temperatures") && err.contains("order-4"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

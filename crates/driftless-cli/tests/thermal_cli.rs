//! `driftless thermal soak` on a short simulated adi-like chamber run (deterministic
//! errors): 12 fitted series, the model file and the figure; too few temperatures for
//! the order is a clear error.

mod common;
use common::{bin, run_json, simulate};

/// A 50-Hz `adi-like` chamber scenario with deterministic errors and a 40τ soak (200 s,
/// τ = 5 s), `keys` adding the protocol's temperatures, dwell and order.
fn deterministic_chamber(keys: &str) -> String {
    format!(
        "seed = 9\n[imu]\nrate_hz = 50.0\npreset = \"adi-like\"\noutput = \"rates\"\n\
         errors = \"deterministic\"\n[trajectory]\ntype = \"chamber\"\nsoak_s = 200.0\n\
         lag_tau_s = 5.0\nmove_s = 2.0\nspin_s = 1.0\n{keys}"
    )
}

#[test]
fn soak_on_a_simulated_chamber_run() {
    let dir = std::env::temp_dir().join(format!("driftless-thermal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    simulate(
        &dir,
        "sim",
        &deterministic_chamber(
            "temperatures_c = [-20.0, 0.0, 25.0, 45.0, 70.0]\nposition_dwell_s = 5.0\n\
             rate_revolutions = 1\n",
        ),
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
    // Deterministic errors and a 40τ soak (the sensor settled to ~1e-16 °C): the gyro x
    // bias slope is the preset's to rounding (the turn-on bias shifts c0 only; with a
    // 12τ soak the unsettled lag left 3e-5).
    assert_gyro_x_bias_slope_is_the_presets(&v);
    let cfg = driftless::sim::presets::Preset::AdiLike.config();
    // The gyro g-sensitivity is estimated in every step by default (six positions per
    // step) and reported per step and as a mean: the preset's G.
    assert_eq!(v["gyro_g_sensitivity"].as_array().unwrap().len(), 5);
    let g_true = cfg.gyro.g_sensitivity_rad_s_per_m_s2;
    for i in 0..3 {
        for j in 0..3 {
            let g = v["gyro_g_sensitivity_mean"]["matrix"][i][j]
                .as_f64()
                .unwrap();
            assert!(
                (g - g_true[i][j]).abs() <= 1e-6 * g_true[0][0],
                "G_{i}{j} {g} vs {}",
                g_true[i][j]
            );
        }
    }
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

/// `driftless thermal soak` on a recording of the recommended protocol (25 °C first with
/// a 2-s soak and again last, palindromic order, two position cycles; deterministic
/// errors): the revisited temperature gives two points, every step calibrates from its
/// repeated positions, and the gyro x bias slope is the preset's.
#[test]
fn soak_on_the_recommended_protocol() {
    let dir = std::env::temp_dir().join(format!("driftless-thermal-rec-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    simulate(
        &dir,
        "sim",
        &deterministic_chamber(
            "temperatures_c = [25.0, -20.0, 45.0, 0.0, 70.0, 25.0]\nfirst_soak_s = 2.0\n\
             position_dwell_s = 8.0\nstep_order = \"palindromic\"\nposition_cycles = 2\n\
             rate_revolutions = 2\n",
        ),
    );
    let v = run_json(
        bin()
            .args(["thermal", "soak", "--json", "--manifest"])
            .arg(dir.join("sim/manifest.toml"))
            .arg(dir.join("sim/imu.csv")),
    );
    assert_eq!(v["series"].as_array().unwrap().len(), 12);
    let temps: Vec<f64> = v["temperatures_c"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    assert_eq!(temps, [-20.0, 0.0, 25.0, 25.0, 45.0, 70.0]);
    assert_gyro_x_bias_slope_is_the_presets(&v);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The fitted gyro x bias slope (c₁ of the soak JSON) equals the `adi-like` preset's to
/// 1e-9 relative (deterministic errors, settled soak).
fn assert_gyro_x_bias_slope_is_the_presets(v: &serde_json::Value) {
    let s = v["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["triad"] == "gyro" && s["quantity"] == "bias" && s["axis"] == "x")
        .unwrap();
    let c1 = s["coefficients"][1].as_f64().unwrap();
    let want = driftless::sim::presets::Preset::AdiLike
        .config()
        .gyro
        .bias_poly_rad_s[0][1];
    assert!((c1 - want).abs() <= 1e-9 * want.abs(), "c1 {c1} vs {want}");
}

/// `driftless compensate`: a model from a simulated chamber run applied to a static
/// warm-up log (25 → 45 °C) of the same simulated sensor (same seed, deterministic
/// errors); the compensated accelerometer reads −g on z; a second pass is refused; a
/// log without temperature is refused.
#[test]
fn compensate_a_warm_up_log() {
    let dir = std::env::temp_dir().join(format!("driftless-comp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let head = "seed = 5\n[imu]\nrate_hz = 50.0\npreset = \"adi-like\"\noutput = \"rates\"\n\
                errors = \"deterministic\"\n";
    simulate(
        &dir,
        "chamber",
        &format!(
            "{head}[trajectory]\ntype = \"chamber\"\n\
             temperatures_c = [15.0, 25.0, 35.0, 45.0, 55.0, 65.0]\nsoak_s = 60.0\n\
             lag_tau_s = 5.0\nposition_dwell_s = 5.0\nmove_s = 2.0\nrate_revolutions = 1\n\
             spin_s = 1.0\n"
        ),
    );
    simulate(
        &dir,
        "warm",
        &format!(
            "{head}[trajectory]\ntype = \"static\"\nlat_deg = 51.08\nlon_deg = -114.13\n\
             height_m = 1100.0\nduration_s = 1800.0\n[temperature]\nkind = \"warm_up\"\n\
             t0_c = 25.0\nt1_c = 45.0\ntau_s = 300.0\n"
        ),
    );
    run_json(
        bin()
            .args(["thermal", "soak", "--json", "--manifest"])
            .arg(dir.join("chamber/manifest.toml"))
            .arg(dir.join("chamber/imu.csv"))
            .arg("--out")
            .arg(dir.join("model.toml")),
    );
    let out = bin()
        .args(["compensate", "--model"])
        .arg(dir.join("model.toml"))
        .arg("--out")
        .arg(dir.join("comp.csv"))
        .arg(dir.join("warm/imu.csv"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // accel z column of the raw and compensated logs against −g (level, static)
    let g = driftless::calib::multi_position::gravity_at(51.08f64.to_radians(), 1100.0);
    let acc_z = |p: &std::path::Path| -> Vec<f64> {
        let text = std::fs::read_to_string(p).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let k = head.iter().position(|h| h.starts_with("acc_z")).unwrap();
        lines
            .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
            .collect()
    };
    let rms = |v: &[f64]| (v.iter().map(|a| (a + g).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
    let (raw, comp) = (
        rms(&acc_z(&dir.join("warm/imu.csv"))),
        rms(&acc_z(&dir.join("comp.csv"))),
    );
    eprintln!(
        "warm-up 25→45 °C: accel z error RMS raw {raw:.3e} m/s², compensated {comp:.3e} m/s²"
    );
    assert!(
        comp < 1e-3 && comp < 0.05 * raw,
        "raw {raw}, compensated {comp}"
    );
    // Twice: refused, naming the stamp.
    let again = bin()
        .args(["compensate", "--model"])
        .arg(dir.join("model.toml"))
        .arg("--out")
        .arg(dir.join("comp2.csv"))
        .arg(dir.join("comp.csv"))
        .output()
        .unwrap();
    assert!(!again.status.success());
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(
        err.contains("already compensated by driftless thermal model"),
        "{err}"
    );
    // No temperature column: refused.
    std::fs::write(
        dir.join("notemp.csv"),
        "time [s],gyro_x [rad/s],gyro_y [rad/s],gyro_z [rad/s],acc_x [m/s^2],acc_y [m/s^2],acc_z [m/s^2]\n\
         0,0,0,0,0,0,-9.8\n0.02,0,0,0,0,0,-9.8\n",
    )
    .unwrap();
    let nt = bin()
        .args(["compensate", "--model"])
        .arg(dir.join("model.toml"))
        .arg("--out")
        .arg(dir.join("x.csv"))
        .arg(dir.join("notemp.csv"))
        .output()
        .unwrap();
    assert!(!nt.status.success());
    let err = String::from_utf8_lossy(&nt.stderr);
    assert!(
        err.contains("no temperature column") && err.contains("notemp.csv"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `driftless thermal ramp` on a simulated static warm-up: one fit per channel, heating
/// bins only; the gyro x slope close to the preset's (white noise, 200 Hz).
#[test]
fn ramp_on_a_simulated_warm_up() {
    let dir = std::env::temp_dir().join(format!("driftless-ramp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    simulate(
        &dir,
        "sim",
        "seed = 3\n[imu]\nrate_hz = 200.0\npreset = \"consumer\"\noutput = \"rates\"\n\
         [trajectory]\ntype = \"static\"\nlat_deg = 45.0\nduration_s = 1200.0\n\
         [temperature]\nkind = \"warm_up\"\nt0_c = 20.0\nt1_c = 50.0\ntau_s = 300.0\n",
    );
    let v = run_json(
        bin()
            .args(["thermal", "ramp", "--json"])
            .arg(dir.join("sim/imu.csv"))
            .arg("--out")
            .arg(dir.join("ramp-model.toml")),
    );
    let fits = v["fits"].as_array().unwrap();
    assert_eq!(fits.len(), 6);
    assert!(v["bins_heating"].as_u64().unwrap() >= 25);
    assert_eq!(v["bins_cooling"], 0);
    // The fitted bias change from 25 to 45 °C against the preset's (gyro x: linear,
    // 0.005 °/s/°C). Plumbing check: the accuracy of the method is in
    // driftless/tests/thermal_ramp.rs; here every noise term of the consumer preset is
    // on, and its rate random walk alone moves the bias by ~6 % of this change over the
    // 20-min log.
    let c: Vec<f64> = (0..4)
        .map(|k| fits[0]["coefficients"][k].as_f64().unwrap())
        .collect();
    let fitted = c[1] * 20.0 + c[2] * 400.0 + c[3] * 8000.0;
    let poly = &driftless::sim::presets::Preset::Consumer
        .config()
        .gyro
        .bias_poly_rad_s[0];
    let want: f64 = poly
        .iter()
        .enumerate()
        .map(|(k, ck)| ck * 20f64.powi(k as i32))
        .sum::<f64>()
        - poly[0];
    eprintln!("ramp CLI: gyro x bias change 25→45 °C {fitted:.4e} rad/s (preset {want:.4e})");
    assert!(
        (fitted - want).abs() <= 0.2 * want.abs(),
        "{fitted} vs {want}"
    );
    // ramp → bias-only model → autopilot parameters, and `compensate` takes the model.
    let model = std::fs::read_to_string(dir.join("ramp-model.toml")).unwrap();
    assert!(model.contains("bias_delta") && model.contains("raw_unit = \"rad/s\""));
    let e = run_json(
        bin()
            .args(["thermal", "export", "--json", "--no-offsets"])
            .arg(dir.join("ramp-model.toml"))
            .arg("--px4")
            .arg(dir.join("tc.params"))
            .arg("--ardupilot")
            .arg(dir.join("tc.param")),
    );
    for f in e["files"].as_array().unwrap() {
        assert!(
            f["max_error_accel_f32_m_s2"].as_f64().unwrap() <= 1e-6,
            "{f}"
        );
        assert!(
            f["max_error_gyro_f32_rad_s"].as_f64().unwrap() <= 1e-6,
            "{f}"
        );
    }
    let px4 = std::fs::read_to_string(dir.join("tc.params")).unwrap();
    assert!(px4.contains("\tTC_G0_X1_0\t") && px4.contains("1\t1\tTC_A0_X0_0\t0\t9\n"));
    let out = bin()
        .args(["compensate", "--model"])
        .arg(dir.join("ramp-model.toml"))
        .arg("--out")
        .arg(dir.join("comp.csv"))
        .arg(dir.join("sim/imu.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // The model's range ends at the last bin centre (49 °C); the log goes on warming to
    // ~49.5 °C: those samples are named with their time span, not compensated silently.
    let range: Vec<f64> = toml::from_str::<toml::Value>(&model).unwrap()["range_c"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_float().unwrap())
        .collect();
    eprintln!("{err}");
    assert!(
        err.contains("outside the model's calibrated range")
            && err.contains(&format!("[{}, {}] °C", range[0], range[1]))
            && err.contains("hold")
            && err.contains("t = "),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `thermal check` on simulated static warm-ups (CSV): a 20 → 50 °C warm-up is fit for the
/// ramp method and flagged as uneven (exponential warm-up); a 25 → 31 °C one is fit for
/// neither, and `thermal ramp` refuses it naming the file, the rise and what to change.
#[test]
fn check_verdicts_and_ramp_refusal_on_simulated_warm_ups() {
    let dir = std::env::temp_dir().join(format!("driftless-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, t1) in [("wide", 50.0), ("narrow", 31.0)] {
        simulate(
            &dir,
            name,
            &format!(
                "seed = 4\n[imu]\nrate_hz = 50.0\npreset = \"consumer\"\noutput = \"rates\"\n\
                 [trajectory]\ntype = \"static\"\nlat_deg = 45.0\nduration_s = 1200.0\n\
                 [temperature]\nkind = \"warm_up\"\nt0_c = {t0}\nt1_c = {t1}\ntau_s = 300.0\n",
                t0 = if name == "wide" { 20.0 } else { 25.0 }
            ),
        );
    }
    let v = run_json(
        bin()
            .args(["thermal", "check", "--json"])
            .arg(dir.join("wide/imu.csv")),
    );
    let r = &v.as_array().unwrap()[0];
    assert_eq!(r["fit_for_ramp"], true, "{r}");
    assert_eq!(r["fit_for_soak"], false, "{r}");
    let kinds: Vec<&str> = r["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"uneven_heating"), "{kinds:?}");
    assert!(
        !kinds.contains(&"motion") && !kinds.contains(&"too_little_rise"),
        "{kinds:?}"
    );
    let rise = r["temperature"]["rise_c"].as_f64().unwrap();
    assert!((rise - 29.4).abs() < 0.6, "{rise}");
    let v = run_json(
        bin()
            .args(["thermal", "check", "--json"])
            .arg(dir.join("narrow/imu.csv")),
    );
    let r = &v.as_array().unwrap()[0];
    assert_eq!(
        (&r["fit_for_ramp"], &r["fit_for_soak"]),
        (&false.into(), &false.into())
    );
    // The table names the verdict and why.
    let out = bin()
        .args(["thermal", "check"])
        .arg(dir.join("narrow/imu.csv"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("fit for neither") && text.contains("[ramp refused, soak refused]"),
        "{text}"
    );
    let out = bin()
        .args(["thermal", "ramp"])
        .arg(dir.join("narrow/imu.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("narrow/imu.csv")
            && err.contains("needs at least 10.0 °C")
            && err.contains("--min-rise"),
        "{err}"
    );
    // Lowering the bar is the user's call: the same log then fits.
    let out = bin()
        .args(["thermal", "ramp", "--min-rise", "5", "--order", "2"])
        .arg(dir.join("narrow/imu.csv"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = bin()
        .args(["thermal", "check", "--min-rise", "nan"])
        .arg(dir.join("narrow/imu.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--min-rise"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `thermal check` on the real autopilot logs: pyulog's PX4 ULog (three IMU instances,
/// about 28–40 °C, each nearly constant over its 6 samples) and the truncated ArduPilot
/// DataFlash log (two instances, 10 samples): every instance fit for neither method,
/// for too little rise, with its own temperatures.
#[test]
#[ignore = "needs shared data"]
fn check_on_real_autopilot_logs() {
    let v = run_json(
        bin()
            .args(["thermal", "check", "--json"])
            .arg(data("logs/px4_ulog/sample_log_small.ulg")),
    );
    let r = v.as_array().unwrap();
    assert_eq!(r.len(), 3);
    let mut lows = Vec::new();
    for (i, x) in r.iter().enumerate() {
        assert!(
            x["label"]
                .as_str()
                .unwrap()
                .ends_with(&format!("instance {i}"))
        );
        assert_eq!(
            (&x["fit_for_ramp"], &x["fit_for_soak"]),
            (&false.into(), &false.into())
        );
        assert_eq!(x["findings"][0]["kind"], "too_little_rise", "{x}");
        assert!(x["temperature"]["rise_c"].as_f64().unwrap() < 0.5);
        lows.push(x["temperature"]["min_c"].as_f64().unwrap());
    }
    eprintln!("ULog instance temperatures (min): {lows:?}");
    assert!(
        (lows[0] - 40.03).abs() < 0.01 && (lows[1] - 28.25).abs() < 0.01,
        "{lows:?}"
    );
    let v = run_json(
        bin()
            .args(["thermal", "check", "--json"])
            .arg(data("logs/ardupilot_dataflash/backend_log_80k.bin")),
    );
    let r = v.as_array().unwrap();
    assert_eq!(r.len(), 2);
    for x in r {
        assert_eq!(x["samples"], 10);
        assert_eq!(
            (&x["fit_for_ramp"], &x["fit_for_soak"]),
            (&false.into(), &false.into())
        );
        assert_eq!(x["findings"][0]["kind"], "too_little_rise", "{x}");
    }
}

/// `driftless thermal export` on the worked example of docs/autopilot-thermal.md: both
/// files written and verified; refusals named (nothing to write, order 4, instance).
#[test]
fn export_autopilot_parameters() {
    let dir = std::env::temp_dir().join(format!("driftless-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = "format_version = 1\nmodel_id = 42\nt_ref_c = 25.0\nrange_c = [-10.0, 60.0]\n\
                 out_of_range = \"clamp\"\n[accel]\nraw_unit = \"m/s^2\"\nbias = [0.2, 0.0, 0.0]\n\
                 matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
                 bias_delta = [[0.0, 0.004, -2e-5, 1e-7], [0.0], [0.0]]\n\
                 scale_delta = [[0.0, 5e-5], [0.0], [0.0]]\n[gyro]\nraw_unit = \"rad/s\"\n\
                 bias = [0.002, 0.0, 0.0]\nmatrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
                 bias_delta = [[0.0, 3e-5, 4e-7], [0.0], [0.0]]\nscale_delta = [[0.0], [0.0], [0.0]]\n";
    std::fs::write(dir.join("m.toml"), model).unwrap();
    let v = run_json(
        bin()
            .args(["thermal", "export", "--json", "--instance", "1"])
            .arg(dir.join("m.toml"))
            .args(["--px4-accel-id", "1310988", "--px4"])
            .arg(dir.join("tc.params"))
            .arg("--ardupilot")
            .arg(dir.join("tc.param")),
    );
    let files = v["files"].as_array().unwrap();
    assert_eq!(files.len(), 2);
    for f in files {
        let (a, g) = (
            f["max_error_accel_f32_m_s2"].as_f64().unwrap(),
            f["max_error_gyro_f32_rad_s"].as_f64().unwrap(),
        );
        eprintln!(
            "export {}: accel {a:.2e} m/s², gyro {g:.2e} rad/s",
            f["autopilot"]
        );
        assert!(a <= 1e-7 && g <= 1e-8, "{f}");
    }
    assert!((v["dropped_scale_delta_max"]["accel"].as_f64().unwrap() - 1.75e-3).abs() < 1e-12);
    let px4 = std::fs::read_to_string(dir.join("tc.params")).unwrap();
    assert!(px4.contains("1\t1\tTC_A1_X1_0\t0.004\t9\n") && px4.contains("TC_A1_ID\t1310988\t6"));
    assert!(px4.contains("TC_A1_ID / TC_G1_ID = 0 match no sensor"));
    let ap = std::fs::read_to_string(dir.join("tc.param")).unwrap();
    assert!(ap.contains("INS_TCAL2_ACC1_X,3630\n") && ap.contains("INS_ACC2OFFS_X,0.2\n"));
    assert!(ap.contains("Scale-factor and misalignment terms have no place"));

    let fail = |args: &[&str], model: &std::path::Path| -> String {
        let out = bin()
            .args(["thermal", "export"])
            .arg(model)
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let m = dir.join("m.toml");
    let p = dir.join("x.params").display().to_string();
    assert!(fail(&[], &m).contains("nothing to write"));
    assert!(fail(&["--instance", "4", "--px4", &p], &m).contains("PX4 has instances 0..=3"));
    std::fs::write(
        dir.join("m4.toml"),
        model.replace("[0.0, 3e-5, 4e-7]", "[0.0, 3e-5, 4e-7, 0.0, 1e-11]"),
    )
    .unwrap();
    let err = fail(&["--px4", &p], &dir.join("m4.toml"));
    assert!(
        err.contains("order 4") && err.contains("refit with order 3"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Shared reference data: `$DRIFTLESS_DATA`, else `../shared/data` beside the project.
fn data(rel: &str) -> std::path::PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => std::path::PathBuf::from(p),
        None => std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join(rel)
}

/// `thermal ramp` on pyulog's real PX4 ULog (`logs/px4_ulog/sample_log_small.ulg`): the
/// log is recognised by its magic bytes, its three IMU instances are listed with their
/// temperatures, and — 6 samples at 1 Hz spanning 0.29 °C — the checks run first refuse
/// it, naming the rise and the levels missing, rather than fitting noise. `--instance 7`
/// names the instances that exist.
#[test]
#[ignore = "needs shared data"]
fn ramp_on_a_real_px4_ulog_fails_clearly_for_lack_of_temperature_span() {
    let log = data("logs/px4_ulog/sample_log_small.ulg");
    let out = bin()
        .args(["thermal", "ramp", "--instance", "2"])
        .arg(&log)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("PX4 ULog"), "{err}");
    assert!(err.contains("sensor_gyro[2] ×6"), "{err}");
    assert!(err.contains("instance 2: 6 samples"), "{err}");
    assert!(err.contains("temperature 29.43–29.72 °C  ← used"), "{err}");
    assert!(
        err.contains("the ramp method cannot give a model from this log"),
        "{err}"
    );
    assert!(
        err.contains("sample_log_small.ulg: temperature 29.43–29.72 °C, a rise of 0.29 °C; a thermal model needs at least 10.0 °C"),
        "{err}"
    );
    assert!(
        err.contains(
            "0 one-degree level(s) with ≥ 50 samples; an order-3 ramp fit needs at least 5"
        ),
        "{err}"
    );
    let out = bin()
        .args(["thermal", "ramp", "--instance", "7"])
        .arg(&log)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no IMU instance 7 (instances: 0, 1, 2)"),
        "{err}"
    );
}

/// `convert` of the truncated real DataFlash log to CSV: instance 1, 10 rows, the cut
/// reported on stderr.
#[test]
#[ignore = "needs shared data"]
fn convert_a_truncated_dataflash_log_to_csv() {
    let dir = std::env::temp_dir().join(format!("driftless-df-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("imu1.csv");
    let out = bin()
        .args(["convert", "--instance", "1"])
        .arg(data("logs/ardupilot_dataflash/backend_log_80k.bin"))
        .arg(&csv)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("stopped cleanly at the message cut off at byte 81918"),
        "{err}"
    );
    assert!(err.contains("7 channels × 10 samples"), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len(), 11);
    assert!(
        rows[0].starts_with("time [s],gyro_x [rad/s]"),
        "{}",
        rows[0]
    );
    assert!(rows[1].ends_with(",28.5"), "{}", rows[1]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A warm-up log whose samples are subnormal (near 1e-310) is fitted with uncertainties
/// in proportion to its values, never exactly zero from squares that underflow.
#[test]
fn ramp_on_subnormal_samples_keeps_its_uncertainties() {
    let dir = std::env::temp_dir().join(format!("driftless-rampsub-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    simulate(
        &dir,
        "sim",
        "seed = 3\n[imu]\nrate_hz = 100.0\npreset = \"consumer\"\noutput = \"rates\"\n\
         [trajectory]\ntype = \"static\"\nlat_deg = 45.0\nduration_s = 900.0\n\
         [temperature]\nkind = \"warm_up\"\nt0_c = 20.0\nt1_c = 50.0\ntau_s = 250.0\n",
    );
    let text = std::fs::read_to_string(dir.join("sim/imu.csv")).unwrap();
    let tiny: String = text
        .lines()
        .map(|l| {
            if !l.starts_with(|c: char| c.is_ascii_digit()) {
                return format!("{l}\n");
            }
            let f: Vec<String> = l
                .split(',')
                .enumerate()
                .map(|(k, v)| match k {
                    1..=6 => format!("{:e}", v.parse::<f64>().unwrap() * 1e-310),
                    _ => v.to_owned(),
                })
                .collect();
            f.join(",") + "\n"
        })
        .collect();
    std::fs::write(dir.join("tiny.csv"), tiny).unwrap();
    let v = run_json(
        bin()
            .args(["thermal", "ramp", "--json"])
            .arg(dir.join("tiny.csv")),
    );
    for f in v["fits"].as_array().unwrap() {
        let se: Vec<f64> = f["std_errors"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_f64().unwrap())
            .collect();
        assert!(se.iter().all(|&s| s > 0.0), "{}: {se:?}", f["channel"]);
        assert!(f["residual_rms"].as_f64().unwrap() > 0.0, "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

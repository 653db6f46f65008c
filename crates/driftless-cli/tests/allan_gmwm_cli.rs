//! `driftless allan --method gmwm`: the JSON carries the wavelet variance, the selected
//! model with its criterion and intervals; `--save-model` writes a noise-model file the
//! library reads back; the default method is still the Allan fit; a term the GMWM cannot
//! model is refused naming the flag.

use std::path::PathBuf;
use std::process::Command;

use driftless::allan::noise_model::NoiseModel;
use driftless::sim::noise::{GaussMarkovConfig, StaticNoiseConfig, generate};

fn tmp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-gmwm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// 2^16 samples at 100 Hz of white noise N = 1e-3 plus a Gauss–Markov σ = 1e-3, T = 10 s,
/// in a file of its own per test (`name`): tests run in parallel.
fn sim_log(name: &str) -> PathBuf {
    let cfg = StaticNoiseConfig {
        sample_rate_hz: 100.0,
        duration_s: 655.36,
        white: 1e-3,
        gauss_markov: Some(GaussMarkovConfig {
            sigma: 1e-3,
            tau_c_s: 10.0,
        }),
        ..StaticNoiseConfig::default()
    };
    let y = generate(&cfg, 42).unwrap();
    let mut s = String::from("time,value\n");
    for (i, v) in y.iter().enumerate() {
        s.push_str(&format!("{:.2},{v:.9e}\n", i as f64 * 0.01));
    }
    let p = tmp_dir().join(format!("white_gm_{name}.csv"));
    std::fs::write(&p, s).unwrap();
    p
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_driftless"))
        .args(args)
        .output()
        .expect("run driftless")
}

#[test]
fn gmwm_method_reports_the_selected_model_and_saves_it() {
    let log = sim_log("gmwm");
    let path = log.to_str().unwrap();
    let model_path = tmp_dir().join("gmwm_model.toml");
    let mp = model_path.to_str().unwrap();
    let out = run(&[
        "allan",
        path,
        "--time-column",
        "time",
        "--method",
        "gmwm",
        "--terms",
        "n,k,gm2",
        "--json",
        "--save-model",
        mp,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["noise"]["estimator"], "gmwm");
    let g = &doc["gmwm"][0];
    assert_eq!(g["fit"]["model"], "WN+GM", "{}", g["fit"]);
    let wic = g["fit"]["wic"].as_f64().unwrap();
    let j = g["fit"]["objective"].as_f64().unwrap();
    assert!(
        (wic - j - 2.0 * 3.0).abs() < 1e-9,
        "WIC = J + 2p with p = 3"
    );
    assert!(g["fit"]["criterion"].as_str().unwrap().contains("WIC"));
    // Candidates: {∅, N, K, N+K} × 0..=2 GM without the empty model.
    assert_eq!(g["fit"]["candidates"].as_array().unwrap().len(), 11);
    let wv = &g["wavelet_variance"];
    let n_scales = wv["tau_s"].as_array().unwrap().len();
    assert_eq!(n_scales, 15, "m = 1 … 2^14 for 65 536 samples");
    for k in ["wv", "wv_lo", "wv_hi", "edf"] {
        assert_eq!(wv[k].as_array().unwrap().len(), n_scales, "{k}");
    }
    // The saved file reads back; its IEEE 952 view carries the white noise and the GM.
    let model = NoiseModel::load(&model_path).unwrap();
    let c = &model.channels[0];
    let n = c.fit.white.unwrap();
    assert!((n.value / 1e-3 - 1.0).abs() < 0.02, "{n:?}");
    assert!(n.lo < n.value && n.value < n.hi);
    let gm = c.fit.gauss_markov.unwrap();
    assert!((3.0..30.0).contains(&gm.tau_c_s.value), "{gm:?}");
    assert_eq!(c.gmwm.as_ref().unwrap().model, "WN+GM");

    // Text output names the model and the criterion.
    let out = run(&[
        "allan",
        path,
        "--time-column",
        "time",
        "--method",
        "gmwm",
        "--terms",
        "n,gm1",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("GMWM model WN+GM") && text.contains("WIC"),
        "{text}"
    );
    assert!(text.contains("Haar wavelet variance"), "{text}");
}

#[test]
fn allan_stays_the_default_and_bad_gmwm_terms_are_refused() {
    let log = sim_log("default");
    let path = log.to_str().unwrap();
    let out = run(&["allan", path, "--time-column", "time", "--json"]);
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc.get("gmwm").is_none());
    assert_eq!(doc["noise"]["estimator"], "oadev");

    let out = run(&[
        "allan",
        path,
        "--time-column",
        "time",
        "--method",
        "gmwm",
        "--terms",
        "n,b",
    ]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--terms") && stderr.contains("bias instability"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
}

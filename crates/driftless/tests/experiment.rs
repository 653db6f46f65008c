//! The experiment end to end.
//!
//! * `builtin_monte_carlo_thermal_model_pays`: the built-in `adi-like` scenario (the demo)
//!   over 20 Monte Carlo runs — case (c) room bias, scale factor and thermal model has a
//!   lower mean 60-s outage error than case (b) room biases only and than (d) the full
//!   room calibration, and the 95 % bootstrap interval of the ratio (b)/(c) lies above 1.
//!   Measured (2 cores): ratio 2.33× (2.07–2.63×), (d)/(c) 2.17× (1.94–2.42×); mean of
//!   the per-run means (a) 584 m, (b) 446 m, (c) 191 m, (d) 415 m; no run fails. The
//!   paper: 8.4× (1254 m / 150 m) — the report explains the difference; the scenario was
//!   not tuned towards it. Every outage of run 0 has its error budget, and the reversals
//!   (a more compensated case ending worse) are listed with their causes;
//! * wrong scenarios fail in [`prepare`] (before the noise stage, i.e. before any long
//!   computation) with a message naming the problem;
//! * the real drive `drive_0708` (ignored without the shared data).

use driftless::experiment::monte_carlo::run_experiment;
use driftless::experiment::run::Case;
use driftless::experiment::scenario::BUILTIN_ADI_LIKE;
use driftless::experiment::table::{Column, table_rows};
use driftless::experiment::{ExperimentScenario, prepare};
use std::path::PathBuf;

fn builtin_with(edit: impl Fn(String) -> String) -> Result<ExperimentScenario, String> {
    ExperimentScenario::from_toml_str(
        &edit(BUILTIN_ADI_LIKE.to_string()),
        "edited",
        PathBuf::new(),
    )
    .map_err(|e| e.to_string())
}

fn prepare_err(edit: impl Fn(String) -> String) -> String {
    match builtin_with(edit) {
        Err(e) => e,
        Ok(sc) => match prepare(sc) {
            Err(e) => e.to_string(),
            Ok(p) => panic!("accepted: {} outages", p.outages.len()),
        },
    }
}

#[test]
fn builtin_monte_carlo_thermal_model_pays() {
    let sc = ExperimentScenario::builtin_adi_like().expect("scenario");
    assert_eq!(sc.monte_carlo.runs, 20);
    let p = prepare(sc).expect("prepare");
    assert_eq!(p.outages.len(), 9);
    let r = run_experiment(&p, None, &|_, _, _| {}).expect("experiment");
    assert_eq!(r.runs.len(), 20);
    let s = &r.summary;
    let spread = |c: Case| {
        let cs = s.cases.iter().find(|x| x.case == c).expect("case");
        assert_eq!(cs.failed_runs, 0, "{:?}: {:?}", c, cs.first_failure);
        cs.forward_mean_end_m.expect("spread")
    };
    let (a, b, c, d) = (
        spread(Case::Raw),
        spread(Case::RoomBias),
        spread(Case::Thermal),
        spread(Case::RoomFull),
    );
    eprintln!("(a) {a:?}\n(b) {b:?}\n(c) {c:?}\n(d) {d:?}");
    assert_eq!((b.n, c.n, d.n), (20, 20, 20));
    assert!(c.mean < b.mean, "(c) {} m vs (b) {} m", c.mean, b.mean);
    assert!(c.mean < d.mean, "(c) {} m vs (d) {} m", c.mean, d.mean);
    let qd = s.ratio_full_room_over_thermal.expect("ratio (d)/(c)");
    eprintln!("ratio (d)/(c) {qd:?}");
    assert!(qd.lo <= qd.ratio && qd.ratio <= qd.hi);
    // Reversal counts: every pair of the four cases, over 20 runs × 9 outages.
    assert_eq!(s.reversals.len(), 6);
    for rc in &s.reversals {
        eprintln!(
            "{:?} worse than {:?}: {} of {}",
            rc.case, rc.than, rc.worse, rc.compared
        );
        assert!(rc.case.compensation_rank() > rc.than.compensation_rank());
        assert_eq!(rc.compared, 180);
        assert!(rc.worse < rc.compared);
    }
    // Run 0's budgets: every case, every outage; the thermal model leaves less error than
    // no compensation in every outage, and the start and sensor parts account for the
    // free-inertial error (triangle inequality, with 1 % for the mechanization's
    // nonlinearity).
    let budget = |c: Case| {
        r.detailed
            .case(c)
            .and_then(|x| x.budgets.clone())
            .expect("budgets")
    };
    let (raw_b, th_b) = (budget(Case::Raw), budget(Case::Thermal));
    assert_eq!((raw_b.len(), th_b.len()), (9, 9));
    for (i, (x, y)) in raw_b.iter().zip(&th_b).enumerate() {
        let (x, y) = (x.as_ref().expect("raw"), y.as_ref().expect("thermal"));
        eprintln!(
            "outage #{}: left by the compensation alone: raw {:.0} m, (c) {:.0} m; (c) start \
             {:.1} m + sensor {:.1} m → free inertial {:.1} m",
            i + 1,
            x.compensation_m,
            y.compensation_m,
            y.start_state_m,
            y.sensor_error_m,
            y.free_inertial_m
        );
        assert!(y.compensation_m < x.compensation_m, "outage #{}", i + 1);
        for z in [x, y] {
            assert!(
                z.free_inertial_m <= 1.01 * (z.start_state_m + z.sensor_error_m),
                "outage #{}: {z:?}",
                i + 1
            );
        }
    }
    for v in driftless::experiment::budget::reversals(&r.detailed) {
        eprintln!("{}", v.describe());
        assert!(v.end_m > v.than_end_m);
        assert!(v.budgets.is_some());
    }
    // Run 0 is complete: nine rows + mean + RMS per table, every case smoothed.
    for col in Column::ALL {
        let (h, rows) = table_rows(&p, &r.detailed, col);
        assert_eq!(h.len(), 7);
        assert_eq!(rows.len(), 11);
        assert!(
            rows.iter()
                .all(|row| row.iter().all(|c| c != "failed" && c != "n/a"))
        );
    }
    // Smoothing bridges the outages: in-outage maxima far below the forward ones.
    for cr in &r.detailed.cases {
        let f = cr
            .forward
            .as_ref()
            .expect("forward")
            .summary
            .max_horizontal_m
            .expect("f");
        let sm = cr
            .smoothed
            .as_ref()
            .expect("smoothed")
            .as_ref()
            .expect("ok");
        let m = sm.summary.max_horizontal_m.expect("m");
        assert!(
            m.mean < 0.1 * f.mean,
            "{:?}: smoothed {} vs forward {}",
            cr.case,
            m.mean,
            f.mean
        );
    }
}

#[test]
fn an_outage_request_longer_than_the_drive_fails_in_prepare() {
    let e = prepare_err(|s| s.replace("spec = \"auto:9x60\"", "spec = \"auto:9x300\""));
    assert!(e.contains("[outages]"), "{e}");
    assert!(e.contains("need 7500.0 s") && e.contains("2015.0 s"), "{e}");
    let e = prepare_err(|s| s.replace("spec = \"auto:9x60\"", "spec = \"100+6000\""));
    assert!(e.contains("[outages]"), "{e}");
}

#[test]
fn inconsistent_rates_are_refused() {
    let e = prepare_err(|s| s.replace("soak_s = 600.0", "soak_s = 600.0\nsample_rate_hz = 200.0"));
    assert!(e.contains("inconsistent rates") && e.contains("200"), "{e}");
    let e = prepare_err(|s| s.replace("rate_hz = 1.0\n", "rate_hz = 400.0\n"));
    assert!(e.contains("inconsistent rates") && e.contains("400"), "{e}");
}

#[test]
fn missing_files_and_stage_conflicts_are_named() {
    let e = prepare_err(|s| s.replace("hours = 2.0", "model = \"no-such-noise.toml\""));
    assert!(
        e.contains("noise.model") && e.contains("no-such-noise.toml"),
        "{e}"
    );
    let e = prepare_err(|s| s.replace("hours = 2.0", "hours = 2.0\nmodel = \"x.toml\""));
    assert!(e.contains("exactly one"), "{e}");
    let e = prepare_err(|s| s.replace("[sensor]\n", "[sensor]\nfoo = 1\n"));
    assert!(e.contains("foo"), "{e}");
    let e = prepare_err(|s| s.replace("preset = \"adi-like\"", "preset = \"adi-lke\""));
    assert!(e.contains("adi-lke"), "{e}");
    let e = prepare_err(|s| s.replace("runs = 20", "runs = 0"));
    assert!(e.contains("monte_carlo.runs"), "{e}");
    let e = prepare_err(|s| s.replace("spec = \"auto:9x60\"", "spec = \"none\""));
    assert!(e.contains("outages.spec"), "{e}");
}

fn data() -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

/// The README's real-drive experiment (`examples/experiment-drive_0708.toml`).
/// Measured: 3 outages of 60 s (standstill, turn, acceleration); forward mean end error
/// (a) 3.80 m, (b) 3.90 m; smoothed in-outage maxima below 0.1 m against the smoothed
/// full-GNSS reference.
#[test]
#[ignore = "needs shared data"]
fn drive_0708_experiment() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiment-drive_0708.toml");
    let text = std::fs::read_to_string(&path).expect("example");
    let text = text.replace("${DRIFTLESS_DATA}", &data().to_string_lossy());
    let sc =
        ExperimentScenario::from_toml_str(&text, "drive_0708", path.parent().expect("dir").into())
            .expect("scenario");
    let p = prepare(sc).expect("prepare");
    assert_eq!(p.outages.len(), 3);
    let r = run_experiment(&p, None, &|_, _, _| {}).expect("run");
    assert_eq!(r.detailed.cases.len(), 2, "no thermal model: cases a and b");
    for cr in &r.detailed.cases {
        let f = cr.forward.as_ref().expect("forward");
        let m = f.summary.end_horizontal_m.expect("end").mean;
        eprintln!("{:?}: mean end {m:.2} m", cr.case);
        // A consumer IMU with NHC over 60 s: metres, not hundreds of metres.
        assert!(m > 0.2 && m < 15.0, "{:?}: {m}", cr.case);
    }
    assert!(r.summary.ratio_room_over_thermal.is_none());
}

#[path = "common/chromium.rs"]
mod chromium;

/// The experiment's own HTML report (2 runs of the built-in scenario: every figure type)
/// renders in headless Chromium: every image loads, the page is not blank.
#[test]
#[ignore = "needs chromium"]
fn experiment_report_renders_in_chromium() {
    let sc = ExperimentScenario::builtin_adi_like().expect("scenario");
    let p = prepare(sc).expect("prepare");
    let r = run_experiment(&p, Some(2), &|_, _, _| {}).expect("run");
    let figs = driftless::experiment::report::figures(&p, &r);
    let names: Vec<&str> = figs.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "trajectory",
            "outage-errors",
            "error-growth",
            "thermal",
            "allan",
            "monte-carlo"
        ]
    );
    let html = driftless::experiment::report::html_report(&p, &r, &figs).expect("html");
    let dir = chromium::TempDir::new("experiment-report").expect("tmp");
    let path = dir.0.join("report.html");
    driftless::report::html::write_html(&path, &html).expect("write");
    let (loaded, total) = chromium::image_check(&path).expect("chromium image check");
    assert_eq!((loaded, total), (figs.len(), figs.len()));
    let png = dir.0.join("report.png");
    let shot = chromium::screenshot(&path, &png, 1200, 6000).expect("screenshot");
    eprintln!("{shot:?}");
    assert_eq!((shot.width, shot.height), (1200, 6000));
    chromium::check_not_blank(&shot, 0.03).expect("screenshot content");
}

/// "Run the same study on your own IMU": the vehicle run as recorded files — a rates CSV
/// with a temperature column (as `driftless simulate` writes it) and KF-GINS GNSS text —
/// with the noise model and the thermal model as files from the built-in scenario's
/// stages. All four cases run from the files; the thermal model pays as in the
/// simulated experiment (same drive, seed of run 0).
/// Measured: mean end error (a) 634 m, (b) 349 m, (c) 142 m, (d) 364 m. Here the windows are
/// chosen on the GNSS fixes and the reference is the smoothed full-GNSS solution (what a
/// user without truth has), which moves each window by a few seconds.
#[test]
fn recorded_csv_with_temperature_runs_every_case() {
    use driftless::experiment::run::{noise_stage, thermal_stage};
    use driftless::thermal::model_file::ThermalModelFile;
    let dir = std::env::temp_dir().join(format!("driftless-exp-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let p = prepare(ExperimentScenario::builtin_adi_like().expect("builtin")).expect("prepare");
    let noise = noise_stage(&p).expect("noise").expect("some");
    let thermal = thermal_stage(&p, Some(&noise), 0)
        .expect("thermal")
        .expect("some");
    noise
        .model
        .save(&dir.join("noise.toml"))
        .expect("save noise");
    ThermalModelFile::from_model(&thermal.model, ["m/s^2", "rad/s"])
        .save(dir.join("thermal.toml"))
        .expect("save thermal");
    // The built-in vehicle run as a `driftless simulate` scenario (run 0's seed).
    let vehicle = &BUILTIN_ADI_LIKE[BUILTIN_ADI_LIKE.find("[vehicle.trajectory]").expect("v")
        ..BUILTIN_ADI_LIKE.find("[outages]").expect("o")];
    let sim_text = format!(
        "seed = {}\n[imu]\nrate_hz = 100.0\npreset = \"adi-like\"\noutput = \"rates\"\n{}",
        driftless::experiment::run::run_seed(2005, 3, 0),
        vehicle.replace("vehicle.", "")
    );
    let sim = driftless::sim::scenario::Scenario::from_toml_str(&sim_text, "vehicle")
        .expect("scenario")
        .run()
        .expect("simulate");
    driftless::io::write_csv_file(&sim.rates_log("vehicle"), dir.join("imu.csv")).expect("csv");
    let gnss = sim.gnss.as_ref().expect("gnss");
    let f = std::fs::File::create(dir.join("gnss.txt")).expect("gnss file");
    driftless::io::nav::write_kfgins_gnss(std::io::BufWriter::new(f), "gnss.txt", gnss)
        .expect("write gnss");
    let filter = &BUILTIN_ADI_LIKE[BUILTIN_ADI_LIKE.find("[filter]").expect("f")
        ..BUILTIN_ADI_LIKE.find("[monte_carlo]").expect("m")];
    let text = format!(
        "seed = 2005\n[noise]\nmodel = \"noise.toml\"\n[chamber]\nmodel = \"thermal.toml\"\n\
         [vehicle]\nformat = \"csv\"\nimu_file = \"imu.csv\"\ngnss_file = \"gnss.txt\"\n\
         lever_arm_b_m = [0.0, 0.0, -1.5]\n[outages]\nspec = \"auto:9x60\"\n{filter}"
    );
    let sc = ExperimentScenario::from_toml_str(&text, "csv", dir.clone()).expect("scenario");
    let pr = prepare(sc).expect("prepare");
    assert_eq!(pr.outages.len(), 9);
    let r = run_experiment(&pr, None, &|_, _, _| {}).expect("run");
    let means: Vec<f64> = r
        .detailed
        .cases
        .iter()
        .map(|c| {
            let m = c.forward_mean_end_m();
            assert!(m.is_some(), "{:?}: {:?}", c.case, c.forward.as_ref().err());
            m.unwrap_or(f64::NAN)
        })
        .collect();
    eprintln!("csv experiment: mean end errors {means:?}");
    assert_eq!(means.len(), 4);
    assert!(means[2] < means[1], "(c) {} vs (b) {}", means[2], means[1]);
    // Budgets against the smoothed reference for every outage.
    let b = r.detailed.cases[2].budgets.as_ref().expect("budgets");
    assert!(b.len() == 9 && b.iter().all(Option::is_some));
    let (t0, t1) = r
        .detailed
        .temperature_c
        .expect("temperature read from the CSV");
    assert!(t0 < 1.0 && t1 > 30.0, "{t0} → {t1} °C");
    // Without a temperature column, [chamber] is refused before any computation.
    let imu = std::fs::read_to_string(dir.join("imu.csv")).expect("read");
    let no_t: String = imu
        .lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(a, _)| a))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("imu.csv"), no_t).expect("write");
    let sc = ExperimentScenario::from_toml_str(&text, "csv", dir.clone()).expect("scenario");
    let e = prepare(sc).expect_err("no temperature").to_string();
    assert!(e.contains("no temperature column"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `[noise] file`: the static log as a CSV file gives the same noise model as the
/// simulated log in memory (the CSV round trip is exact: shortest round-trip decimals).
#[test]
fn noise_stage_from_a_static_log_file_matches_the_in_memory_log() {
    use driftless::experiment::run::{noise_stage, simulated_static_log};
    let dir = std::env::temp_dir().join(format!("driftless-exp-noise-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let text = BUILTIN_ADI_LIKE.replace("hours = 2.0", "hours = 0.5");
    let p = prepare(
        ExperimentScenario::from_toml_str(&text, "half-hour", PathBuf::new()).expect("scenario"),
    )
    .expect("prepare");
    let a = noise_stage(&p).expect("noise").expect("some");
    let log = simulated_static_log(&p).expect("log");
    driftless::io::write_csv_file(&log, dir.join("static.csv")).expect("csv");
    let text = text.replace("hours = 0.5", "file = \"static.csv\"");
    let p =
        prepare(ExperimentScenario::from_toml_str(&text, "file", dir.clone()).expect("scenario"))
            .expect("prepare");
    let b = noise_stage(&p).expect("noise from file").expect("some");
    assert_eq!(a.model.channels.len(), 6);
    assert_eq!(b.model.channels.len(), 6);
    for (x, y) in a.model.channels.iter().zip(&b.model.channels) {
        assert_eq!(x.quantity, y.quantity);
        let (fx, fy) = (&x.fit, &y.fit);
        for (tx, ty) in [
            (fx.white, fy.white),
            (fx.bias_instability, fy.bias_instability),
            (fx.rate_random_walk, fy.rate_random_walk),
        ] {
            match (tx, ty) {
                (Some(u), Some(v)) => {
                    assert!(
                        (u.value - v.value).abs() <= 1e-9 * u.value.abs(),
                        "{u:?} vs {v:?}"
                    )
                }
                (None, None) => {}
                other => panic!("{}: {other:?}", x.name),
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

//! Issue 7 acceptance: the experiment end to end.
//!
//! * `builtin_monte_carlo_thermal_model_pays`: the built-in `adi-like` scenario (the demo)
//!   over 20 Monte Carlo runs — case (c) room + thermal has a lower mean 60-s outage
//!   error than case (b) room calibration only, and the 95 % bootstrap interval of the
//!   ratio (b)/(c) lies above 1. Measured (2 cores): ratio 2.05× (1.84–2.33×); mean of
//!   the per-run means (a) 426 m, (b) 421 m, (c) 205 m; no run fails. The paper: 8.4× (1254 m / 150 m) — the
//!   report explains the difference; the scenario was not tuned towards it.
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
    let (b, c) = (spread(Case::Room), spread(Case::Thermal));
    eprintln!("(b) {b:?}\n(c) {c:?}");
    assert_eq!((b.n, c.n), (20, 20));
    assert!(c.mean < b.mean, "(c) {} m vs (b) {} m", c.mean, b.mean);
    let q = s.ratio_room_over_thermal.expect("ratio");
    eprintln!("ratio {q:?}");
    assert_eq!(q.runs, 20);
    assert!(
        q.lo > 1.0,
        "95 % interval of (b)/(c) {:.2}–{:.2}",
        q.lo,
        q.hi
    );
    assert!(q.lo <= q.ratio && q.ratio <= q.hi);
    // Run 0 is complete: nine rows + mean + RMS per table, every case smoothed.
    for col in Column::ALL {
        let (h, rows) = table_rows(&p, &r.detailed, col);
        assert_eq!(h.len(), 6);
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

//! `driftless experiment` / `driftless demo` end to end through the binary.

mod common;
use common::{bin, run_json};

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-exp-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn builtin() -> String {
    let out = bin().args(["demo", "--print-scenario"]).output().unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stdout).unwrap()
}

/// A wrong scenario stops before any computation, names the problem, exits with 1 and
/// leaves no output folder.
#[test]
fn wrong_scenarios_fail_fast_without_output() {
    let dir = tmp("wrong");
    let text = builtin();
    for (name, edit, expect) in [
        (
            "missing-file",
            text.replace("hours = 2.0", "file = \"static-log-not-here.csv\""),
            "noise.file = \"static-log-not-here.csv\": no such file",
        ),
        (
            "rates",
            text.replace("soak_s = 600.0", "soak_s = 600.0\nsample_rate_hz = 50.0"),
            "inconsistent rates",
        ),
        (
            "too-long",
            text.replace("spec = \"auto:9x60\"", "spec = \"auto:9x600\""),
            "need",
        ),
    ] {
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(&file, edit).unwrap();
        let out_dir = dir.join(format!("{name}-out"));
        let out = bin()
            .args(["experiment", "--out"])
            .arg(&out_dir)
            .arg(&file)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(expect), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name}: names the file: {err}"
        );
        assert!(!out_dir.exists(), "{name}: no partial output");
    }
}

/// The printed built-in scenario is a valid experiment file: one run writes Table 1 in
/// Markdown and CSV and the JSON document, whose numbers agree with the CSV.
#[test]
fn printed_builtin_scenario_runs_one_run() {
    let dir = tmp("one");
    let file = dir.join("adi.toml");
    std::fs::write(&file, builtin()).unwrap();
    let out_dir = dir.join("out");
    let v = run_json(
        bin()
            .args(["experiment", "--json", "--runs", "1", "--out"])
            .arg(&out_dir)
            .arg(&file),
    );
    assert_eq!(v["outages"].as_array().unwrap().len(), 9);
    let run0 = v["run0"].as_array().unwrap();
    assert_eq!(run0.len(), 4);
    let cases: Vec<&str> = run0.iter().map(|c| c["case"].as_str().unwrap()).collect();
    assert_eq!(cases, ["raw", "room_bias", "thermal", "room_full"]);
    // Every case of run 0 carries its per-outage budget; the reversals are listed.
    assert!(
        run0.iter()
            .all(|c| c["budgets"].as_array().unwrap().len() == 9)
    );
    assert!(v["run0_reversals"].is_array());
    assert_eq!(v["monte_carlo"]["reversals"].as_array().unwrap().len(), 6);
    let csv = std::fs::read_to_string(out_dir.join("table1.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 12, "{csv}");
    // Outage #1, case (c): the CSV cell matches the JSON value to its printed digits.
    let cell: f64 = lines[1].split(',').nth(5).unwrap().parse().unwrap();
    let json = run0[2]["forward"]["Ok"]["outages"][0]["end_horizontal_m"]
        .as_f64()
        .unwrap();
    assert!((cell - json).abs() <= 0.5 + 0.01 * json, "{cell} vs {json}");
    let md = std::fs::read_to_string(out_dir.join("table1.md")).unwrap();
    assert!(md.contains("| #9 |") && md.contains("8.4×"), "{md}");
    // Every Markdown table keeps its header's cell count: the `mean |·|` summary rows
    // escape their bars.
    let mut tables = 0;
    let mut header_cells = None;
    for line in md.lines() {
        if !line.starts_with('|') {
            header_cells = None;
            continue;
        }
        let n = markdown_cells(line);
        match header_cells {
            None => {
                header_cells = Some(n);
                tables += 1;
            }
            Some(h) => assert_eq!(n, h, "{line}"),
        }
    }
    assert!(tables >= 5, "{tables} tables in table1.md");
    assert!(md.contains("| mean \\|·\\| |"), "{md}");
    assert!(md.contains("## Where more compensation did worse"), "{md}");
}

/// Cells of a Markdown table row such as `| mean \|·\| | 1.5 |` (two): its bars not
/// escaped by a backslash, less one.
fn markdown_cells(line: &str) -> usize {
    line.trim().replace("\\|", "").matches('|').count() - 1
}

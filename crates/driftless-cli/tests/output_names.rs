//! Output names and numeric flags are checked before any work: a figure is SVG or PNG by
//! its name, a converted log `.dlog` or `.csv`/`.txt`, and a negative `--rate` reaches the
//! rate check instead of being taken for a flag.

mod common;
use common::bin;

fn scratch(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-names-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small rate log with a time column.
fn small_log(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("log.csv");
    let mut s = String::from("t,gx\n");
    for i in 0..200 {
        s.push_str(&format!(
            "{},{}\n",
            i as f64 * 0.01,
            ((i * 7919) % 13) as f64 * 1e-3
        ));
    }
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn a_figure_name_that_is_neither_svg_nor_png_is_refused_before_the_analysis() {
    let d = scratch("plot");
    let log = small_log(&d);
    for cmd in [
        vec!["allan".to_string(), log.display().to_string()],
        vec!["thermal".into(), "soak".into(), log.display().to_string()],
        vec![
            "calibrate".into(),
            "six-position".into(),
            log.display().to_string(),
        ],
        vec![
            "calibrate".into(),
            "multi-position".into(),
            log.display().to_string(),
            log.display().to_string(),
        ],
    ] {
        let out = bin()
            .args(&cmd)
            .arg("--plot")
            .arg(d.join("fig.jpg"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd:?}: {err}");
        assert!(
            err.contains("fig.jpg") && err.contains(".svg or .png"),
            "{cmd:?}: {err}"
        );
        assert!(!d.join("fig.jpg").exists());
    }
    // The same names in SVG are written.
    let out = bin()
        .arg("allan")
        .arg(&log)
        .arg("--plot")
        .arg(d.join("fig.SVG"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(d.join("fig.SVG")).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..40.min(svg.len())]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn convert_refuses_an_output_format_it_does_not_write() {
    let d = scratch("convert");
    let log = small_log(&d);
    let out = bin()
        .arg("convert")
        .arg(&log)
        .arg(d.join("out.xlsx"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("out.xlsx") && err.contains(".dlog") && err.contains("--to csv|dlog"),
        "{err}"
    );
    assert!(!d.join("out.xlsx").exists());
    for name in ["out.dlog", "out.csv"] {
        let out = bin()
            .arg("convert")
            .arg(&log)
            .arg(d.join(name))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_negative_rate_is_a_value_not_a_flag() {
    let d = scratch("rate");
    let p = d.join("norate.txt");
    std::fs::write(&p, "1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n").unwrap();
    let out = bin()
        .arg("allan")
        .arg(&p)
        .args(["--rate", "-100"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "a bad flag value is a usage error: {err}"
    );
    assert!(
        err.contains("'--rate <HZ>': must be a positive number, got -100"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

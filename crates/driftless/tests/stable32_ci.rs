//! Confidence intervals against Stable32 1.60 (reference vectors from the allantools
//! test suite, see shared/data/README.md): for every row of every `*_octave.txt`
//! result file, (lo, hi) = bounds(Sigma, edf(estimator, Alpha, AF, N_phase), 0.683)
//! must reproduce Stable32's Min/Max Sigma to 2e-3 relative. AF, Alpha and Sigma are
//! taken from the file; only the EDF and the χ² quantiles are ours.

use std::path::PathBuf;

use driftless::allan::Estimator;
use driftless::allan::ci::{ONE_SIGMA_CL, bounds, chi2_quantile, edf};

const TOL: f64 = 2e-3;

/// Residual allowed against the model of Stable32's own χ² convention (below): the
/// printed values have 5 significant digits, i.e. up to ~1e-4 relative rounding each in
/// Sigma and in Min/Max Sigma.
const MODEL_TOL: f64 = 3e-4;

/// Stable32's χ² quantile convention, reconstructed from these files: exact quantiles
/// at the 1-σ level erf(1/√2) for edf ≤ 100; above 100 the Wilson–Hilferty
/// approximation ν(1 − 2/(9ν) ± z√(2/(9ν)))³ with z = Φ⁻¹(0.84) ≈ 0.9945 (not 1.0),
/// which makes its intervals ≈ 0.6 % narrower in half-width there. This explains every
/// residual of the plain check (≤ 5e-4) down to the 5-digit rounding of the files.
fn stable32_model_bounds(sigma: f64, nu: f64) -> (f64, f64) {
    if nu <= 100.0 {
        return bounds(sigma, nu, ONE_SIGMA_CL);
    }
    // Φ⁻¹(0.84) from our own χ²₁ quantile: P(χ²₁ ≤ z²) = 2Φ(z) − 1.
    let z = chi2_quantile(2.0 * 0.84 - 1.0, 1.0).sqrt();
    let wh = |z: f64| nu * (1.0 - 2.0 / (9.0 * nu) + z * (2.0 / (9.0 * nu)).sqrt()).powi(3);
    (sigma * (nu / wh(z)).sqrt(), sigma * (nu / wh(-z)).sqrt())
}

fn data_dir() -> PathBuf {
    std::env::var_os("DRIFTLESS_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

struct Row {
    af: usize,
    alpha: i32,
    sigma: f64,
    min: f64,
    max: f64,
}

fn read_rows(path: &std::path::Path) -> Vec<Row> {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 7, "bad row in {}: {l}", path.display());
            Row {
                af: f[0].parse().unwrap(),
                alpha: f[3].parse().unwrap(),
                min: f[4].parse().unwrap(),
                sigma: f[5].parse().unwrap(),
                max: f[6].parse().unwrap(),
            }
        })
        .collect()
}

fn estimator_of(file: &str) -> Estimator {
    // Longest names first: "ohdev" contains "hdev", "oadev" contains "adev".
    for name in ["totdev", "ohdev", "oadev", "mdev", "hdev", "tdev", "adev"] {
        if file.contains(name) {
            return Estimator::from_name(name).unwrap();
        }
    }
    panic!("no estimator in file name {file}");
}

/// Worst relative errors (lo, hi) over a file, printing per-row detail for failures;
/// the third element lists rows outside [`TOL`], the fourth rows whose residual against
/// [`stable32_model_bounds`] exceeds [`MODEL_TOL`].
fn check_file(dir: &str, file: &str, n_phase: usize) -> (f64, f64, Vec<String>, Vec<String>) {
    let path = data_dir().join("allan").join(dir).join(file);
    let est = estimator_of(file);
    let rows = read_rows(&path);
    assert!(!rows.is_empty(), "{} has no rows", path.display());
    let (mut wlo, mut whi) = (0.0f64, 0.0f64);
    let mut bad = Vec::new();
    let mut model_bad = Vec::new();
    let mut wmodel = 0.0f64;
    for r in &rows {
        let nu = edf(est, r.alpha, r.af, n_phase);
        let (lo, hi) = bounds(r.sigma, nu, 0.683);
        let elo = ((lo - r.min) / r.min).abs();
        let ehi = ((hi - r.max) / r.max).abs();
        wlo = wlo.max(elo);
        whi = whi.max(ehi);
        let (mlo, mhi) = stable32_model_bounds(r.sigma, nu);
        let emodel = ((mlo - r.min) / r.min)
            .abs()
            .max(((mhi - r.max) / r.max).abs());
        wmodel = wmodel.max(emodel);
        if emodel > MODEL_TOL {
            model_bad.push(format!(
                "{dir}/{file} AF={} alpha={} edf={nu:.3}: Stable32-convention residual {emodel:.2e}",
                r.af, r.alpha
            ));
        }
        if elo > TOL || ehi > TOL {
            bad.push(format!(
                "{dir}/{file} AF={} alpha={} edf={nu:.3}: lo {lo:.5e} vs {:.5e} ({elo:.2e}), hi {hi:.5e} vs {:.5e} ({ehi:.2e})",
                r.af, r.alpha, r.min, r.max
            ));
        }
    }
    println!(
        "{dir}/{file}: {} rows, worst rel. error lo {wlo:.2e}, hi {whi:.2e} \
         (vs Stable32 χ² convention: {wmodel:.2e})",
        rows.len()
    );
    (wlo, whi, bad, model_bad)
}

#[test]
#[ignore = "needs shared data"]
fn stable32_confidence_intervals() {
    let sets: [(&str, usize); 3] = [
        ("phasedat", 1001),
        ("ocxo", 19_983),
        ("pink_frequency", 10_001),
    ];
    let mut failures = Vec::new();
    let mut model_failures = Vec::new();
    let mut n_files = 0;
    for (dir, n_phase) in sets {
        let mut files: Vec<String> = std::fs::read_dir(data_dir().join("allan").join(dir))
            .unwrap_or_else(|e| panic!("data dir {dir}: {e}"))
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|f| f.ends_with("_octave.txt"))
            .collect();
        files.sort();
        for file in files {
            n_files += 1;
            let (_, _, bad, model_bad) = check_file(dir, &file, n_phase);
            // The OCXO TOTDEV rows are exempt from the brief's 2e-3 requirement; they are
            // reported, and (with the SP 1065 simple PM EDF for alpha = 1) pass anyway.
            if dir == "ocxo" && file.contains("totdev") {
                for b in bad.iter().chain(&model_bad) {
                    println!("  (exempt) {b}");
                }
                continue;
            }
            failures.extend(bad);
            model_failures.extend(model_bad);
        }
    }
    assert_eq!(n_files, 7 + 7 + 1, "expected 15 octave result files");
    assert!(
        failures.is_empty(),
        "rows outside {TOL}:\n{}",
        failures.join("\n")
    );
    assert!(
        model_failures.is_empty(),
        "rows not explained by Stable32's chi-square convention:\n{}",
        model_failures.join("\n")
    );
}

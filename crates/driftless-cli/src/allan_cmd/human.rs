//! The `allan` tables: curves with intervals, the wavelet variance, the noise model.

use crate::output::{Table, sci};
use driftless::allan::gmwm;
use driftless::allan::log_analysis::LogAnalysis;
use driftless::io::ImuLog;
use std::path::Path;

pub(super) fn human_output(out: &LogAnalysis, log: &ImuLog, file: &Path) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} samples at {} Hz ({:.2} h), {} channel(s)\n\n",
        file.display(),
        log.len(),
        sci(1.0 / log.tau0_s),
        log.len() as f64 * log.tau0_s / 3600.0,
        out.results.len()
    ));
    for (r, unit) in out.results.iter().zip(&out.units) {
        s.push_str(&format!(
            "{} — {} [{}], {:.1} % confidence\n",
            r.name,
            r.estimator.name().to_uppercase(),
            if unit.is_empty() { "data units" } else { unit },
            100.0 * r.confidence
        ));
        let mut t = Table::new([
            "tau [s]", "m", "n", "alpha", "edf", "dev_lo", "dev", "dev_hi",
        ]);
        for (i, p) in r.points.iter().enumerate() {
            t.row(vec![
                sci(p.tau),
                p.m.to_string(),
                p.n.to_string(),
                r.alpha[i].to_string(),
                sci(r.edf[i]),
                sci(r.dev_lo[i]),
                sci(p.dev),
                sci(r.dev_hi[i]),
            ]);
        }
        s.push_str(&t.render());
        s.push('\n');
    }
    for g in &out.gmwm {
        let w = &g.wavelet_variance;
        s.push_str(&format!(
            "{} — Haar wavelet variance, {:.1} % confidence (eta3 EDF)\n",
            g.name,
            100.0 * w.confidence
        ));
        let mut t = Table::new(["tau [s]", "edf", "wv_lo", "wv", "wv_hi", "model"]);
        for j in 0..w.m.len() {
            t.row(vec![
                sci(w.tau_s[j]),
                sci(w.edf[j]),
                sci(w.wv_lo[j]),
                sci(w.wv[j]),
                sci(w.wv_hi[j]),
                sci(g.fit.model_wv(w.tau_s[j])),
            ]);
        }
        s.push_str(&t.render());
        s.push('\n');
    }
    if let Some(m) = &out.noise {
        if out.gmwm.is_empty() {
            s.push_str(&m.human_table());
        } else {
            s.push_str(&format!(
                "GMWM noise models (selection by {}):\n",
                gmwm::CRITERION
            ));
            s.push_str(&gmwm::human_table(m));
        }
    }
    s
}

//! The human-readable summary of a noise model.

use crate::allan::fit::{NoiseFit, RangeSource, TermKind, chi2_verdict};

use super::NoiseModel;
use super::display::{ALL_TERMS, display_units, fmt_num, si_term_units, term_label};
use super::selection::CURVE_PRECISION;

/// The fit range, χ²_red and its verdict, as printed under each channel.
pub fn fit_quality_lines(fit: &NoiseFit) -> String {
    let mut s = String::new();
    if let Some(r) = &fit.fit_range {
        let how = match r.source {
            RangeSource::Full => "the whole curve".to_string(),
            RangeSource::User => "set by --fit-range".to_string(),
            RangeSource::Auto => {
                let mut why = Vec::new();
                if r.excluded_short > 0 {
                    why.push(format!(
                        "{} short-tau point(s) left out, where the sensor's own filtering \
                         colours the noise and the model does not apply",
                        r.excluded_short
                    ));
                }
                if r.excluded_long > 0 {
                    why.push(format!(
                        "{} long-tau point(s) left out, known to worse than {:.0} % (too few \
                         averages to hold a model to)",
                        r.excluded_long,
                        100.0 * CURVE_PRECISION
                    ));
                }
                format!("automatic: {}", why.join("; "))
            }
        };
        s.push_str(&format!(
            "  fit range {} … {} s ({} points; {how})\n",
            fmt_num(r.tau_min_s),
            fmt_num(r.tau_max_s),
            fit.n_points
        ));
    }
    let (verdict, warn) = chi2_verdict(fit.chi2_reduced);
    s.push_str(&format!(
        "  chi2_red {} — {}{verdict}\n",
        fmt_num(fit.chi2_reduced),
        if warn { "WARNING: " } else { "" }
    ));
    s
}

impl NoiseModel {
    /// Human-readable summary: per channel the continuous terms in display units with
    /// their intervals, upper limits of undetected terms, and the per-sample discrete σ.
    pub fn human_table(&self) -> String {
        let mut s = String::new();
        let conf = self
            .channels
            .first()
            .map_or(0.0, |c| 100.0 * c.fit.confidence);
        s.push_str(&format!(
            "Noise terms (IEEE 952 fit, {conf:.1} % intervals). Continuous-time densities first; \
             'discrete' lines are per-sample values at {} Hz.\n",
            fmt_num(self.sample_rate_hz)
        ));
        for c in &self.channels {
            s.push_str(&format!(
                "\n{} [{}]\n",
                c.name,
                if c.unit.is_empty() {
                    "data units"
                } else {
                    &c.unit
                }
            ));
            s.push_str(&fit_quality_lines(&c.fit));
            s.push_str(&format!(
                "  {:<18} {:>11} {:>11} {:>11}  {}\n",
                "term", "value", "lo", "hi", "unit"
            ));
            let mut rows: Vec<(String, f64, f64, f64, String)> = Vec::new();
            let si_units = si_term_units(&c.unit);
            for k in ALL_TERMS {
                let label = term_label(k);
                if let Some(t) = c.fit.term(k) {
                    match display_units(c.quantity, k).first() {
                        Some(&(u, size)) => rows.push((
                            label.into(),
                            t.value / size,
                            t.lo / size,
                            t.hi / size,
                            u.into(),
                        )),
                        None => rows.push((label.into(), t.value, t.lo, t.hi, si_units(k))),
                    }
                }
                if k == TermKind::GaussMarkov
                    && let Some(g) = &c.fit.gauss_markov
                {
                    let t = g.tau_c_s;
                    rows.push(("GM corr. time".into(), t.value, t.lo, t.hi, "s".into()));
                }
            }
            for (label, v, lo, hi, u) in rows {
                s.push_str(&format!(
                    "  {:<18} {:>11} {:>11} {:>11}  {}\n",
                    label,
                    fmt_num(v),
                    fmt_num(lo),
                    fmt_num(hi),
                    u
                ));
            }
            for u in &c.fit.not_detected {
                let (val, unit) = match display_units(c.quantity, u.term).first() {
                    Some(&(name, size)) => (u.upper / size, name.to_string()),
                    None => (u.upper, si_units(u.term)),
                };
                s.push_str(&format!(
                    "  {:<18} not detected (< {} {})\n",
                    term_label(u.term),
                    fmt_num(val),
                    unit
                ));
            }
            for u in &c.fit.not_identifiable {
                s.push_str(&format!(
                    "  {:<18} not identifiable: {}\n",
                    term_label(u.term),
                    u.reason
                ));
            }
            let d = &c.discrete;
            let su = if c.unit.is_empty() {
                "u"
            } else {
                c.unit.as_str()
            };
            let mut parts = Vec::new();
            if let Some(v) = d.white_sigma {
                parts.push(format!("white σ_d = N·√fs = {} {su}", fmt_num(v)));
            }
            if let Some(v) = d.rate_random_walk_sigma {
                parts.push(format!("RRW step σ = K·√Δt = {} {su}", fmt_num(v)));
            }
            if let Some(g) = &d.bias_instability_gm {
                parts.push(format!(
                    "bias-instability GM σ_b = {} {su}, T_c = {} s (φ = {}, σ_w = {} {su})",
                    fmt_num(g.sigma),
                    fmt_num(g.tau_c_s),
                    fmt_num(g.phi),
                    fmt_num(g.sigma_w)
                ));
            }
            for p in parts {
                s.push_str(&format!("  discrete: {p}\n"));
            }
        }
        s
    }
}

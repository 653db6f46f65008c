//! The replicate report as text and the warnings for runs that disagree.

use super::{ReplicateChannel, Replicates, RunEstimate};
use crate::allan::fit::TermKind;
use crate::allan::noise_model::{display_units, fmt_num, si_term_units, term_label};

pub(super) fn fmt_p(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.3}")
    } else {
        format!("{p:.1e}")
    }
}

impl Replicates {
    /// One warning per term on which the runs disagree, with the runs' range.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in &self.channels {
            for t in &c.terms {
                if t.consistent == Some(false) {
                    let (unit, size) = unit_of(c, t.term);
                    let range = t.spread.map_or(String::new(), |s| {
                        format!(
                            ": {} … {} {unit} across the runs",
                            fmt_num(s.min / size),
                            fmt_num(s.max / size)
                        )
                    });
                    out.push(format!(
                        "{}: {}: {}{range}; the pooled and joint intervals include the \
                         between-run spread",
                        c.name,
                        term_label(t.term),
                        t.verdict
                    ));
                }
            }
        }
        out
    }

    /// Human-readable report: per channel a table of term, each run's value, pooled
    /// value [lo, hi], spread and verdict, then the cross-run check.
    pub fn human_table(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "Replicates: {} runs of one sensor. Test: Cochran's Q on ln(value), runs disagree \
             when p < {}; pooled: random-effects (DerSimonian–Laird) mean, {:.1} % interval.\n",
            self.runs.len(),
            self.level,
            100.0 * self.confidence
        ));
        for (i, r) in self.runs.iter().enumerate() {
            s.push_str(&format!("  run {}: {r}\n", i + 1));
        }
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
            let mut header = format!("  {:<18}", "term");
            for i in 0..self.runs.len() {
                header.push_str(&format!(" {:>11}", format!("run {}", i + 1)));
            }
            header.push_str(&format!(
                " {:>35} {:>8}  {:<14} {}\n",
                "pooled [lo, hi]", "spread", "unit", "test"
            ));
            s.push_str(&header);
            for t in &c.terms {
                let (unit, size) = unit_of(c, t.term);
                let mut row = format!("  {:<18}", term_label(t.term));
                for e in &t.runs {
                    let cell = match e {
                        RunEstimate::Value(v) => fmt_num(v.value / size),
                        RunEstimate::UpperLimit(u) => format!("< {}", fmt_num(u / size)),
                        RunEstimate::Absent => "-".into(),
                    };
                    row.push_str(&format!(" {cell:>11}"));
                }
                let pooled = t.pooled.map_or("-".to_string(), |p| {
                    format!(
                        "{} [{}, {}]",
                        fmt_num(p.value / size),
                        fmt_num(p.lo / size),
                        fmt_num(p.hi / size)
                    )
                });
                let spread = t.spread.map_or("-".to_string(), |sp| {
                    format!("{:.1} %", 100.0 * sp.relative)
                });
                row.push_str(&format!(
                    " {pooled:>35} {spread:>8}  {unit:<14} {}\n",
                    t.verdict
                ));
                s.push_str(&row);
            }
            if let Some(w) = c
                .cross_checks
                .iter()
                .max_by(|a, b| a.worst.total_cmp(&b.worst))
            {
                s.push_str(&format!(
                    "  cross-run check: worst |model/curve − 1| = {:.1} % (run {}'s model on \
                     run {}'s curve at τ = {} s; span {} … {} s, every pair of runs)\n",
                    100.0 * w.worst,
                    w.model_run + 1,
                    w.curve_run + 1,
                    fmt_num(w.at_tau_s),
                    fmt_num(w.tau_min_s),
                    fmt_num(w.tau_max_s)
                ));
            }
        }
        s
    }
}

/// First display unit of a term for the channel's quantity: (name, size in SI).
fn unit_of(c: &ReplicateChannel, kind: TermKind) -> (String, f64) {
    match display_units(c.quantity, kind).first() {
        Some(&(u, size)) => (u.to_string(), size),
        None => (si_term_units(&c.unit)(kind), 1.0),
    }
}

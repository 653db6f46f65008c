//! Human-readable tables, JSON documents, and checks of output names made before any
//! work is done.

/// A `--json` document as printed: pretty, with the keys of every object sorted (as
/// `serde_json`'s own maps keep them, so documents built from typed results and from
/// maps read alike).
pub fn json_text<T: serde::Serialize>(doc: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string_pretty(&serde_json::to_value(doc)?)?)
}

/// `--plot FILE` value parser: the name must end in `.svg` or `.png` (PNG only in a build
/// with the `png` feature), so a long analysis never ends in a refused or mislabelled file.
pub fn figure_path(s: &str) -> Result<std::path::PathBuf, String> {
    let p = std::path::PathBuf::from(s);
    driftless::report::plot::check_figure_path(&p).map_err(|e| e.to_string())?;
    Ok(p)
}

/// Format a number with 5 significant digits in scientific or plain notation.
pub fn sci(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.4e}")
    } else {
        let digits = if a == 0.0 {
            4
        } else {
            (4 - a.log10().floor() as i32).clamp(0, 8) as usize
        };
        format!("{v:.digits$}")
    }
}

/// A simple left/right aligned text table.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Table {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }

    pub fn render(&self) -> String {
        let ncol = self.header.len();
        let mut w = vec![0usize; ncol];
        for r in std::iter::once(&self.header).chain(self.rows.iter()) {
            for (i, c) in r.iter().enumerate().take(ncol) {
                w[i] = w[i].max(c.chars().count());
            }
        }
        let mut out = String::new();
        let line = |r: &Vec<String>, out: &mut String| {
            for (i, c) in r.iter().enumerate().take(ncol) {
                let pad = w[i] - c.chars().count();
                if i == 0 {
                    out.push_str(c);
                    out.push_str(&" ".repeat(pad));
                } else {
                    out.push_str("  ");
                    out.push_str(&" ".repeat(pad));
                    out.push_str(c);
                }
            }
            out.push('\n');
        };
        line(&self.header, &mut out);
        let total: usize = w.iter().sum::<usize>() + 2 * (ncol.saturating_sub(1));
        out.push_str(&"-".repeat(total));
        out.push('\n');
        for r in &self.rows {
            line(r, &mut out);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn sci_formats() {
        assert_eq!(sci(0.29223), "0.29223");
        assert_eq!(sci(1.5e-7), "1.5000e-7");
        assert_eq!(sci(123.456), "123.46");
    }
}

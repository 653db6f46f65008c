//! Figures shared by the commands.

use anyhow::{Context, Result};
use driftless::allan::fit::NoiseFit;
use driftless::allan::log_analysis::LogAnalysis;
use driftless::report::allan_plot;
use std::path::Path;

/// Write the Allan plot of `out` to `path` (SVG, or PNG by extension).
pub fn write_allan_plot(path: &Path, out: &LogAnalysis, title: &str) -> Result<()> {
    let fits: Vec<Option<&NoiseFit>> = match &out.noise {
        Some(m) => m.fits().map(Some).collect(),
        None => vec![None; out.results.len()],
    };
    allan_plot::write(
        path,
        title,
        &out.results,
        &out.quantities,
        &out.units,
        &fits,
    )
    .with_context(|| format!("writing plot {}", path.display()))
}

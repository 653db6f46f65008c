//! Reports and plots.
//!
//! [`plot`]: generic log-log, linear and bar figures (SVG, PNG with the `png` feature);
//! [`allan_plot`]: the Allan-deviation figure built from analysis results;
//! [`calib_plot`]: calibration residuals; [`thermal_plot`]: bias and scale factor versus
//! temperature with the fit and its band; [`experiment_plots`]: the outage experiment's
//! trajectory, per-outage error bars and error growth; [`html`]: one self-contained HTML
//! report file with the figures embedded.

pub mod plot;

pub use plot::{Figure, PlotError, render_png, render_png_bytes, render_svg};
pub mod allan_plot;
pub mod calib_plot;
pub mod experiment_plots;
pub mod html;
pub mod thermal_plot;

pub use html::{HtmlReport, write_html};

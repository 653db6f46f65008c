//! Reports and plots.
//!
//! [`plot`]: generic log-log figures (SVG, PNG with the `png` feature);
//! [`allan_plot`]: the Allan-deviation figure built from analysis results;
//! [`calib_plot`]: calibration residuals; [`thermal_plot`]: bias and scale factor versus
//! temperature with the fit and its band.

pub mod plot;

pub use plot::{Figure, PlotError, render_png, render_png_bytes, render_svg};
pub mod allan_plot;
pub mod calib_plot;
pub mod thermal_plot;

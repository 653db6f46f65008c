//! Report plots — log-log (Allan deviation) and linear or semi-log
//! (calibration residuals, bias vs temperature) — rendered to SVG, and to PNG
//! with the `png` feature.
//!
//! The input types ([`Figure`], [`Plot`] (alias [`LogLogPlot`]), [`Series`],
//! [`Line`], [`Bars`], [`Annotation`]) are plain data, independent of the Allan
//! types. A panel can also carry category x ticks ([`Plot::x_tick_labels`], e.g.
//! under grouped bars) and keep equal axes ([`Plot::equal_aspect`], for maps).
//! A figure is laid out once into a display list which both back-ends draw,
//! so the SVG and the PNG show the same picture.
//!
//! Each panel axis is [`AxisScale::Log`] (the default: decade ticks, labels
//! like `10⁻²`) or [`AxisScale::Linear`] (1-2-5 × 10ᵏ ticks, 2–8 labels with
//! one precision per axis: `-0.5`, `0`, `2.5`, or `1.05e-3` / `-1.0e6` for
//! tiny and huge values); see [`scale`].
//!
//! ```
//! use driftless::report::plot::{Figure, Line, LogLogPlot, Plot, Series, render_svg};
//! // Allan deviation: log-log.
//! let taus = vec![0.01, 0.1, 1.0, 10.0, 100.0];
//! let adev = vec![0.3, 0.1, 0.04, 0.035, 0.05];
//! let allan = LogLogPlot::new("Gyro", "τ (s)", "σ(τ) (deg/s)")
//!     .with_series(Series::new("X", taus.clone(), adev))
//!     .with_line(Line::power_law("white noise", 0.03, -0.5, 0.01, 100.0, 2)
//!         .dashed()
//!         .with_label("N = 0.03 deg/√s"));
//! // Bias vs temperature: linear axes, negative values, a fitted curve with
//! // a shaded confidence band.
//! let t = vec![-20.0, 0.0, 20.0, 40.0];
//! let fit: Vec<f64> = t.iter().map(|x| -0.5 + 0.02 * x).collect();
//! let thermal = Plot::linear("Bias vs T", "T (°C)", "bias (deg/s)")
//!     .with_series(
//!         Series::new("fit ± 2σ", t.clone(), fit.clone())
//!             .with_band(fit.iter().map(|y| y - 0.1).collect(),
//!                        fit.iter().map(|y| y + 0.1).collect()),
//!     )
//!     .with_series(Series::new("bias", t, vec![-0.9, -0.45, -0.12, 0.33]).connected(false));
//! let svg = render_svg(&Figure::grid(vec![allan, thermal], 2));
//! assert!(svg.starts_with("<svg"));
//! assert!(svg.contains(">-0.4<") && svg.contains(">0<")); // linear tick labels
//! ```
//!
//! Robustness: values that an axis cannot show (NaN and ±∞ everywhere; zero
//! and negatives on a log axis) are skipped and break connecting lines and
//! bands; empty series, a single point, constant data and ranges of hundreds
//! of decades all render. Nothing here panics on data.

mod error;
mod figure;
mod geom;
mod layout;
#[cfg(feature = "png")]
mod png;
pub mod scale;
mod scene;
mod svg;
mod text;

use std::path::Path;

pub use error::PlotError;
pub use figure::{
    Annotation, AxisScale, Bars, Color, Figure, LegendPosition, Line, LineStyle, LogLogPlot,
    MarkerShape, PALETTE, Plot, Series,
};
pub use svg::xml_escape;
pub use text::text_width;

/// Whether this build can write PNG (the `png` cargo feature).
pub(crate) const PNG_SUPPORTED: bool = cfg!(feature = "png");

/// Default PNG resolution: 2 device pixels per SVG px (crisp text on
/// high-DPI screens and in print).
pub(crate) const DEFAULT_PNG_SCALE: f64 = 2.0;

/// Writes the figure as PNG when `path` ends in `.png`, as SVG when it ends in `.svg`
/// (any case).
///
/// # Errors
/// [`PlotError::UnsupportedFormat`] for any other name (nothing is written: a `.jpg`
/// holding SVG text would be a wrong file), else as [`render_png`] / [`write_svg`].
pub fn write_figure(fig: &Figure, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let path = path.as_ref();
    if check_figure_path(path)? {
        render_png(fig, path)
    } else {
        write_svg(fig, path)
    }
}

/// Checks a figure's output name before any work is done: `Ok(true)` for `.png`,
/// `Ok(false)` for `.svg` (any case).
///
/// # Errors
/// [`PlotError::UnsupportedFormat`] for any other ending; [`PlotError::PngUnsupported`]
/// for `.png` in a build without the `png` feature.
pub fn check_figure_path(path: &Path) -> Result<bool, PlotError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext.eq_ignore_ascii_case("png") {
        if PNG_SUPPORTED {
            Ok(true)
        } else {
            Err(PlotError::PngUnsupported)
        }
    } else if ext.eq_ignore_ascii_case("svg") {
        Ok(false)
    } else {
        Err(PlotError::UnsupportedFormat {
            path: path.to_path_buf(),
        })
    }
}

/// Renders the figure as a self-contained SVG document (UTF-8, no XML
/// declaration, no ids, no external resources: it can be written to a `.svg`
/// file or inlined in HTML as is).
pub fn render_svg(fig: &Figure) -> String {
    svg::write_svg(&layout::layout(fig))
}

/// Renders the figure as PNG bytes, `scale` device pixels per SVG px
/// (non-positive or non-finite: 1).
///
/// # Errors
/// [`PlotError::PngUnsupported`] without the `png` feature;
/// [`PlotError::BadRasterSize`] if the raster would exceed 10⁸ pixels.
pub fn render_png_bytes(fig: &Figure, scale: f64) -> Result<Vec<u8>, PlotError> {
    #[cfg(feature = "png")]
    {
        png::render(&layout::layout(fig), scale)
    }
    #[cfg(not(feature = "png"))]
    {
        let _ = (fig, scale);
        Err(PlotError::PngUnsupported)
    }
}

/// Writes the figure as a PNG file at `DEFAULT_PNG_SCALE`.
///
/// # Errors
/// As [`render_png_bytes`], plus [`PlotError::Io`] if the file cannot be
/// written. Without the `png` feature nothing is written.
pub fn render_png(fig: &Figure, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let bytes = render_png_bytes(fig, DEFAULT_PNG_SCALE)?;
    let path = path.as_ref();
    crate::io::output::write(path, bytes).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes the figure as an SVG file.
///
/// # Errors
/// [`PlotError::Io`] if the file cannot be written.
pub fn write_svg(fig: &Figure, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let path = path.as_ref();
    crate::io::output::write(path, render_svg(fig)).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Test hook: the embedded font's advance of `c` in em (`None` without the
/// `png` feature or for a missing glyph), to check [`text_width`]'s table.
#[doc(hidden)]
pub fn embedded_font_advance_em(c: char) -> Option<f64> {
    #[cfg(feature = "png")]
    {
        png::font_advance_em(c)
    }
    #[cfg(not(feature = "png"))]
    {
        let _ = c;
        None
    }
}

//! Log-log plots (Allan-deviation style) rendered to SVG, and to PNG with the
//! `png` feature.
//!
//! The input types ([`Figure`], [`LogLogPlot`], [`Series`], [`Line`],
//! [`Annotation`]) are plain data, independent of the Allan types. A figure is
//! laid out once into a display list which both back-ends draw, so the SVG
//! and the PNG show the same picture.
//!
//! ```
//! use driftless::report::plot::{Figure, Line, LogLogPlot, Series, render_svg};
//! let taus = vec![0.01, 0.1, 1.0, 10.0, 100.0];
//! let adev = vec![0.3, 0.1, 0.04, 0.035, 0.05];
//! let plot = LogLogPlot::new("Gyro", "τ (s)", "σ(τ) (deg/s)")
//!     .with_series(Series::new("X", taus.clone(), adev))
//!     .with_line(Line::power_law("white noise", 0.03, -0.5, 0.01, 100.0, 2)
//!         .dashed()
//!         .with_label("N = 0.03 deg/√s"));
//! let svg = render_svg(&Figure::single(plot));
//! assert!(svg.starts_with("<svg"));
//! ```
//!
//! Robustness: values that a log axis cannot show (NaN, ±∞, zero, negative)
//! are skipped and break connecting lines; empty series, a single point and
//! ranges of hundreds of decades all render. Nothing here panics on data.

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
    Annotation, AxisScale, Color, DEFAULT_PANEL_SIZE, Figure, LegendPosition, Line, LineStyle,
    LogLogPlot, MARKER_CYCLE, MarkerShape, PALETTE, Plot, Series,
};
pub use svg::xml_escape;
pub use text::text_width;

/// Whether this build can write PNG (the `png` cargo feature).
pub const PNG_SUPPORTED: bool = cfg!(feature = "png");

/// Default PNG resolution: 2 device pixels per SVG px (crisp text on
/// high-DPI screens and in print).
pub const DEFAULT_PNG_SCALE: f64 = 2.0;

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

/// Writes the figure as a PNG file at [`DEFAULT_PNG_SCALE`].
///
/// # Errors
/// As [`render_png_bytes`], plus [`PlotError::Io`] if the file cannot be
/// written. Without the `png` feature nothing is written.
pub fn render_png(fig: &Figure, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let bytes = render_png_bytes(fig, DEFAULT_PNG_SCALE)?;
    let path = path.as_ref();
    std::fs::write(path, bytes).map_err(|source| PlotError::Io {
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
    std::fs::write(path, render_svg(fig)).map_err(|source| PlotError::Io {
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

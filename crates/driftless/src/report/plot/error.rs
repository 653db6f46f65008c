use std::path::PathBuf;

/// Errors of the plot renderers. SVG rendering is infallible.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// PNG output was requested from a build without the `png` feature.
    #[error(
        "PNG output is not available: build the `driftless` crate with the `png` feature (e.g. `cargo build --features driftless/png`), or use SVG output"
    )]
    PngUnsupported,
    /// The raster would exceed the pixel budget (or has a zero side).
    #[error(
        "figure of {width}×{height} px cannot be rasterised (limit {limit} px in total, both sides ≥ 1)"
    )]
    BadRasterSize { width: u64, height: u64, limit: u64 },
    /// The embedded font did not parse (a broken build, not bad input).
    #[error("the embedded font could not be loaded")]
    Font,
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Encode(String),
    /// The output name ends in neither `.svg` nor `.png`.
    #[error(
        "{}: a figure is written as SVG or PNG; end the file name in .svg or .png",
        path.display()
    )]
    UnsupportedFormat { path: PathBuf },
    #[error("cannot write {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

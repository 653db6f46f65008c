//! The calibration residual figure: per static interval (or position), the residual of
//! the calibrated accelerometer |a| − g, on linear axes — what `driftless calibrate
//! --plot` writes.

use super::plot::{AxisScale, Figure, MarkerShape, Plot, PlotError, Series, write_figure};

/// One panel per residual set: `(title, y label, values)`, plotted against the interval
/// number 1, 2, …; written as PNG or SVG by the extension of `path`.
pub fn write_residual_plot(
    path: impl AsRef<std::path::Path>,
    title: &str,
    panels: &[(&str, &str, Vec<f64>)],
) -> Result<(), PlotError> {
    let plots: Vec<Plot> = panels
        .iter()
        .map(|(t, y, v)| {
            let x: Vec<f64> = (1..=v.len()).map(|i| i as f64).collect();
            Plot::linear(*t, "static interval #", *y)
                .with_scales(AxisScale::Linear, AxisScale::Linear)
                .with_series(
                    Series::new("residual", x, v.clone())
                        .with_marker(MarkerShape::Circle)
                        .connected(false),
                )
        })
        .collect();
    let cols = plots.len().clamp(1, 2);
    let mut fig = Figure::grid(plots, cols);
    fig.title = Some(title.to_owned());
    write_figure(&fig, path)
}

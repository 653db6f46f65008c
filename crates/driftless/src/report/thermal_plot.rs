//! The thermal figure (the seed paper's Figs. 3–4): per quantity, each axis's values at
//! the soak temperatures with the fitted polynomial and its 95 % confidence band, on
//! linear axes.

use super::plot::{Figure, MarkerShape, PALETTE, Plot, PlotError, Series, write_figure};
use crate::thermal::soak::SoakCalibration;

/// Four panels (accelerometer bias, accelerometer scale, gyro bias, gyro scale); the
/// bias of a triad is shown in `units[triad]` after multiplying by `factor[triad]`.
pub fn thermal_figure(soak: &SoakCalibration, bias_units: [(&str, f64); 2]) -> Figure {
    let mut panels = Vec::new();
    for (ti, triad) in ["accel", "gyro"].iter().enumerate() {
        for quantity in ["bias", "scale"] {
            let (unit, factor) = if quantity == "bias" {
                bias_units[ti]
            } else {
                ("A_kk", 1.0)
            };
            let title = format!(
                "{} {}",
                if ti == 0 { "accelerometer" } else { "gyro" },
                quantity
            );
            let mut p = Plot::linear(title, "temperature (°C)", unit.to_string());
            for axis in 0..3 {
                let Some(s) = soak.get(triad, quantity, axis) else {
                    continue;
                };
                let color = PALETTE[axis % PALETTE.len()];
                let (lo_t, hi_t) = s.fit.range_c();
                let xs: Vec<f64> = (0..=100)
                    .map(|i| lo_t + (hi_t - lo_t) * i as f64 / 100.0)
                    .collect();
                let (mut y, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new());
                for &t in &xs {
                    match s.fit.band(t, 0.95) {
                        Ok(b) => {
                            y.push(b.value * factor);
                            lo.push(b.lo * factor);
                            hi.push(b.hi * factor);
                        }
                        Err(_) => {
                            y.push(f64::NAN);
                            lo.push(f64::NAN);
                            hi.push(f64::NAN);
                        }
                    }
                }
                let name = ["x", "y", "z"][axis];
                p = p
                    .with_series(
                        // One legend entry per axis (line and band); the points (the
                        // per-step estimates) stay out of the legend.
                        Series::new(name, xs, y)
                            .with_band(lo, hi)
                            .with_marker(MarkerShape::None)
                            .with_color(color),
                    )
                    .with_series(
                        Series::new(
                            "",
                            soak.temperatures_c.clone(),
                            s.values.iter().map(|v| v * factor).collect(),
                        )
                        .connected(false)
                        .with_marker(MarkerShape::Circle)
                        .with_color(color),
                    );
            }
            panels.push(p);
        }
    }
    Figure::grid(panels, 2)
}

/// [`thermal_figure`] written as PNG or SVG by the extension of `path`.
pub fn write_thermal_plot(
    path: impl AsRef<std::path::Path>,
    title: &str,
    soak: &SoakCalibration,
    bias_units: [(&str, f64); 2],
) -> Result<(), PlotError> {
    let mut fig = thermal_figure(soak, bias_units);
    fig.title = Some(title.to_owned());
    write_figure(&fig, path)
}

//! Renders an Allan-like six-axis example figure to the temp dir
//! (`driftless_plot_example.svg`, and `.png` with the `png` feature) so a
//! person can look at it; asserts only that rendering succeeds.

use driftless::report::plot::{
    Annotation, Color, Figure, Line, LineStyle, LogLogPlot, PALETTE, Series, render_png, render_svg,
};

/// σ(τ) = √(N²/τ + B² + K²τ/3) on log-spaced taus, with ~1σ CI bars.
fn channel(name: &str, n: f64, b: f64, k: f64, wobble: f64) -> Series {
    let taus: Vec<f64> = (0..32)
        .map(|i| 10f64.powf(-2.0 + 6.0 * f64::from(i) / 31.0))
        .collect();
    let t_total = 2.0e5;
    let mut y = Vec::new();
    let (mut lo, mut hi) = (Vec::new(), Vec::new());
    for (i, &t) in taus.iter().enumerate() {
        let s = (n * n / t + b * b + k * k * t / 3.0).sqrt();
        let s = s * (1.0 + wobble * (i as f64 * 1.7).sin() * (t / 1e4).sqrt().min(1.0));
        let rel = 1.0 / (2.0 * (t_total / t - 1.0)).max(1.0).sqrt();
        y.push(s);
        lo.push(s * (1.0 - rel).max(0.05));
        hi.push(s * (1.0 + rel));
    }
    Series::new(name, taus, y).with_ci(lo, hi)
}

fn panel(
    title: &str,
    unit: &str,
    n_unit: &str,
    k_unit: &str,
    p: [(f64, f64, f64); 3],
) -> LogLogPlot {
    let mut plot = LogLogPlot::new(
        title,
        "Averaging time τ (s)",
        format!("Allan deviation σ(τ) ({unit})"),
    );
    for (i, (axis, (n, b, k))) in ["X", "Y", "Z"].iter().zip(p).enumerate() {
        plot.series
            .push(channel(axis, n, b, k, 0.08 * (i as f64 + 1.0)).with_color(PALETTE[i]));
    }
    let (n, b, k) = p[0];
    let grey = Color::rgb(0x55, 0x55, 0x55);
    plot.lines.push(
        Line::power_law("", n, -0.5, 1e-3, 1e5, 2)
            .dashed()
            .with_color(grey)
            .with_label(format!("N = {n:.3} {n_unit}"))
            .with_label_at(0.05),
    );
    plot.lines.push(
        Line::power_law("", b, 0.0, 1e-3, 1e5, 2)
            .dashed()
            .with_color(grey)
            .with_label(format!("B = {:.3} {unit}", b / 0.664)),
    );
    plot.lines.push(
        Line::power_law("X asymptotes", k / 3f64.sqrt(), 0.5, 1e-3, 1e5, 2)
            .dashed()
            .with_color(grey)
            .with_label(format!("K = {k:.2e} {k_unit}"))
            .with_label_at(3e3),
    );
    let model: Vec<f64> = (0..60)
        .map(|i| 10f64.powf(-2.0 + 6.0 * f64::from(i) / 59.0))
        .collect();
    let ym = model
        .iter()
        .map(|t| (n * n / t + b * b + k * k * t / 3.0).sqrt())
        .collect();
    plot.lines.push(Line {
        name: "X fit".into(),
        x: model,
        y: ym,
        style: LineStyle::Solid,
        color: Some(Color::BLACK),
        width: Some(1.0),
        ..Default::default()
    });
    let tmin = (3.0f64).sqrt() * b / k; // rough minimum
    plot.annotations
        .push(Annotation::new("bias instability", tmin, b * 1.05));
    plot
}

pub fn example_figure() -> Figure {
    let gyro = panel(
        "Gyroscope",
        "deg/h",
        "deg/h/√Hz",
        "deg/h·√Hz",
        [(9.0, 2.1, 0.05), (11.0, 3.0, 0.08), (8.0, 1.6, 0.03)],
    );
    let accel = panel(
        "Accelerometer",
        "mg",
        "mg/√Hz",
        "mg·√Hz",
        [(0.06, 0.012, 3e-4), (0.07, 0.02, 5e-4), (0.09, 0.03, 2e-4)],
    );
    Figure::grid(vec![gyro, accel], 2)
        .with_title("IMU-42 static log — overlapping Allan deviation <2 h>")
}

#[test]
fn plot_example_renders() {
    let fig = example_figure();
    let dir = std::env::temp_dir();
    let svg = render_svg(&fig);
    std::fs::write(dir.join("driftless_plot_example.svg"), &svg).expect("write svg");
    let png = render_png(&fig, dir.join("driftless_plot_example.png"));
    assert_eq!(png.is_ok(), cfg!(feature = "png"), "{png:?}");
}

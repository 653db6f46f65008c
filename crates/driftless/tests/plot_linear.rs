//! Linear axes: tick maths, rendering with negative values and CI bands.

use driftless::report::plot::scale::{
    Tick, explicit_linear_range, linear_extent, linear_padded_range, linear_ticks,
};
use driftless::report::plot::{
    AxisScale, Figure, Line, LogLogPlot, MarkerShape, Plot, Series, render_png_bytes, render_svg,
};

fn labels(ticks: &[Tick]) -> Vec<&str> {
    ticks.iter().filter_map(|t| t.label.as_deref()).collect()
}

fn majors(ticks: &[Tick]) -> Vec<f64> {
    ticks.iter().filter(|t| t.major).map(|t| t.value).collect()
}

/// Major ticks are evenly spaced by a 1-2-5 step, inside the range, 2–8 of
/// them, and every major tick is labelled.
fn check_axis(ticks: &[Tick], lo: f64, hi: f64) {
    let m = majors(ticks);
    assert!((2..=8).contains(&m.len()), "{m:?}");
    let step = m[1] - m[0];
    let k = step.log10().floor();
    let mant = step / 10f64.powf(k);
    assert!(
        [1.0, 2.0, 5.0, 10.0]
            .iter()
            .any(|c| (mant - c).abs() < 1e-6),
        "step {step}"
    );
    for w in m.windows(2) {
        assert!(((w[1] - w[0]) - step).abs() <= 1e-9 * step);
    }
    let eps = 1e-9 * (hi - lo);
    for t in ticks {
        assert!(t.value >= lo - eps && t.value <= hi + eps, "{t:?}");
        assert_eq!(t.value, t.log, "linear ticks: axis coordinate = value");
        assert_eq!(t.major, t.label.is_some());
    }
}

#[test]
fn plot_linear_ticks_mixed_sign() {
    let t = linear_ticks(-3.2, 7.9, 400.0, 22.5);
    check_axis(&t, -3.2, 7.9);
    assert_eq!(labels(&t), ["-2", "0", "2", "4", "6"]);
    assert!(t.iter().any(|t| !t.major), "minor ticks when there is room");
    // Padded range: a 5 % margin, zero not forced in.
    let (lo, hi) = linear_padded_range(-3.2, 7.9);
    assert!((lo - (-3.2 - 0.555)).abs() < 1e-12 && (hi - (7.9 + 0.555)).abs() < 1e-12);
    let (lo, hi) = linear_padded_range(20.0, 21.0);
    assert!(lo > 19.0 && hi < 22.0);
    // Fewer labels on a short axis.
    let short = linear_ticks(-3.2, 7.9, 60.0, 22.5);
    assert!(majors(&short).len() <= 3, "{:?}", labels(&short));
}

#[test]
fn plot_linear_ticks_small_values() {
    let t = linear_ticks(0.001, 0.0012, 400.0, 22.5);
    check_axis(&t, 0.001, 0.0012);
    assert_eq!(
        labels(&t),
        ["1.00e-3", "1.05e-3", "1.10e-3", "1.15e-3", "1.20e-3"]
    );
    // Moderate decimals stay fixed-point with one precision per axis.
    let t = linear_ticks(19.95, 21.05, 400.0, 22.5);
    assert_eq!(labels(&t), ["20.0", "20.2", "20.4", "20.6", "20.8", "21.0"]);
    let t = linear_ticks(-1.1, 1.3, 400.0, 22.5);
    check_axis(&t, -1.1, 1.3);
    assert_eq!(labels(&t), ["-1.0", "-0.5", "0", "0.5", "1.0"]);
}

#[test]
fn plot_linear_ticks_degenerate_range() {
    // A single value is widened (±10 %), then ticked normally.
    let (lo, hi) = linear_padded_range(5.0, 5.0);
    assert!(lo < 5.0 && hi > 5.0 && hi - lo < 2.0, "{lo} {hi}");
    let t = linear_ticks(lo, hi, 400.0, 22.5);
    check_axis(&t, lo, hi);
    assert!(labels(&t).contains(&"5.0"), "{:?}", labels(&t));
    // All zeros.
    let (lo, hi) = linear_padded_range(0.0, 0.0);
    assert!(lo < 0.0 && hi > 0.0);
    assert!(labels(&linear_ticks(lo, hi, 400.0, 22.5)).contains(&"0"));
    // Empty / invalid ranges give no ticks, never a panic.
    assert!(linear_ticks(5.0, 5.0, 400.0, 22.5).is_empty());
    assert!(linear_ticks(f64::NAN, 1.0, 400.0, 22.5).is_empty());
    assert!(linear_ticks(2.0, 1.0, 400.0, 22.5).is_empty());
    assert!(linear_ticks(-f64::MAX, f64::MAX, 400.0, 22.5).is_empty());
    assert!(!linear_ticks(0.0, 1.0, f64::NAN, f64::NAN).is_empty());
    assert!(!linear_ticks(1e15, 1e15 + 1.0, 400.0, 22.5).is_empty());
    let (lo, hi) = linear_padded_range(f64::MAX, -f64::MAX);
    check_axis(&linear_ticks(lo, hi, 400.0, 22.5), lo, hi);
    assert_eq!(linear_extent([f64::NAN, f64::INFINITY]), None);
    assert_eq!(linear_extent([3.0, f64::NAN, -1.0]), Some((-1.0, 3.0)));
    assert_eq!(explicit_linear_range((2.0, -1.0)), Some((-1.0, 2.0)));
    assert_eq!(explicit_linear_range((1.0, 1.0)), None);
    assert_eq!(explicit_linear_range((f64::NAN, 1.0)), None);
}

#[test]
fn plot_linear_ticks_huge_values() {
    let t = linear_ticks(-1e6, 2e6, 400.0, 22.5);
    check_axis(&t, -1e6, 2e6);
    assert_eq!(
        labels(&t),
        ["-1.0e6", "-0.5e6", "0", "0.5e6", "1.0e6", "1.5e6", "2.0e6"]
    );
}

/// Bias vs temperature: negative values, a fitted curve, a confidence band
/// and residual error bars.
fn thermal() -> Plot {
    let t: Vec<f64> = (0..9).map(|i| -20.0 + 7.5 * f64::from(i)).collect();
    let fit = |x: f64| -0.8 + 0.02 * x + 4e-4 * x * x;
    let bias: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, &x)| fit(x) + if i % 2 == 0 { 0.05 } else { -0.04 })
        .collect();
    let curve_x: Vec<f64> = (0..=40).map(|i| -22.0 + 2.0 * f64::from(i)).collect();
    let curve_y: Vec<f64> = curve_x.iter().map(|&x| fit(x)).collect();
    let lo: Vec<f64> = curve_y.iter().map(|y| y - 0.12).collect();
    let hi: Vec<f64> = curve_y.iter().map(|y| y + 0.12).collect();
    Plot::linear("Gyro X bias vs temperature", "T (°C)", "bias (deg/s)")
        .with_series(
            Series::new("95 % band", curve_x.clone(), curve_y.clone())
                .with_band(lo, hi)
                .with_marker(MarkerShape::None)
                .connected(false),
        )
        .with_series(
            Series::new("bias", t, bias.clone())
                .with_ci(
                    bias.iter().map(|b| b - 0.03).collect(),
                    bias.iter().map(|b| b + 0.03).collect(),
                )
                .connected(false),
        )
        .with_line(Line::new("quadratic fit", curve_x, curve_y).with_label("b(T) = −0.8 + 0.02·T"))
}

#[test]
fn plot_linear_render_svg_and_png() {
    let fig = Figure::single(thermal());
    let svg = render_svg(&fig);
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
    // y spans about −1.0 … 1.8: fixed-point labels with one decimal, zero
    // plain; x (−22 … 58 °C) in steps of 20.
    for l in [
        ">-1.0<", ">-0.5<", ">0<", ">0.5<", ">1.5<", ">-20<", ">20<", ">60<",
    ] {
        assert!(svg.contains(l), "missing tick label {l}");
    }
    // No log-axis labels on a linear panel.
    assert!(!svg.contains("10⁻") && !svg.contains(">10⁰<"));
    // The confidence band is one translucent filled polygon.
    assert_eq!(
        svg.matches("stroke=\"none\" fill-opacity=\"0.18\"").count(),
        1
    );
    let png = render_png_bytes(&fig, 1.0);
    if cfg!(feature = "png") {
        let png = png.expect("png");
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    } else {
        assert!(png.is_err());
    }
}

#[test]
fn plot_linear_x_only_and_residuals() {
    // Residuals per static interval (index on a linear x, signed y) next to
    // a log-log panel in the same figure.
    let idx: Vec<f64> = (1..=12).map(f64::from).collect();
    let res: Vec<f64> = idx.iter().map(|i| (i * 1.7).sin() * 2e-3).collect();
    let residuals = Plot::linear("Residuals", "interval", "residual (g)")
        .with_series(Series::new("|a| − g", idx, res).connected(false));
    let semi = LogLogPlot::new("semi-log", "T (°C)", "σ")
        .linear_x()
        .with_series(Series::new(
            "s",
            vec![-10.0, 0.0, 25.0],
            vec![0.1, 0.3, 2.0],
        ));
    assert_eq!(semi.x_scale, AxisScale::Linear);
    assert_eq!(semi.y_scale, AxisScale::Log);
    let svg = render_svg(&Figure::grid(vec![residuals, semi], 2));
    assert!(
        svg.contains(">0<") && svg.contains("e-3<"),
        "sci labels for ±2e-3"
    );
    assert!(svg.contains(">-10<"), "negative x on the semi-log panel");
    assert!(svg.contains("10⁰"), "log y still in decades");
}

#[test]
fn plot_log_is_the_default_and_unchanged() {
    let p = LogLogPlot::new("a", "x", "y").with_series(Series::new(
        "s",
        vec![0.1, 1.0, 10.0],
        vec![3.0, 1.0, 0.5],
    ));
    assert_eq!((p.x_scale, p.y_scale), (AxisScale::Log, AxisScale::Log));
    let explicit = p.clone().with_scales(AxisScale::Log, AxisScale::Log);
    assert_eq!(
        render_svg(&Figure::single(p)),
        render_svg(&Figure::single(explicit))
    );
}

#[test]
fn plot_linear_bad_data_does_not_panic() {
    let nasty = vec![
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -f64::MAX,
        0.0,
        f64::MAX,
        1.0,
    ];
    let cases = vec![
        Plot::linear("empty", "x", "y"),
        Plot::linear("one", "x", "y").with_series(Series::new("p", vec![5.0], vec![5.0])),
        Plot::linear("zeros", "x", "y").with_series(Series::new(
            "p",
            vec![0.0, 0.0],
            vec![0.0, 0.0],
        )),
        Plot::linear("nasty", "x", "y").with_series(
            Series::new("p", nasty.clone(), nasty.iter().rev().copied().collect())
                .with_band(nasty.clone(), nasty.iter().map(|v| -v).collect()),
        ),
        Plot::linear("nasty ci", "x", "y").with_series(
            Series::new("p", vec![1.0, 2.0, 3.0, 4.0], vec![0.0, -1.0, 1.0, 2.0])
                .with_ci(nasty.clone(), nasty.clone()),
        ),
        Plot::linear("band off-screen", "x", "y")
            .with_y_range(-1.0, 1.0)
            .with_series(
                Series::new("p", vec![1.0, 2.0, 3.0], vec![0.0, 5.0, 0.0])
                    .with_band(vec![-1e300, 4.0, -0.5], vec![1e300, 6.0, 0.5]),
            ),
        Plot::linear("bad ranges", "x", "y")
            .with_x_range(f64::NAN, 1.0)
            .with_y_range(3.0, 3.0)
            .with_line(Line::new("l", vec![-1.0, 1.0], vec![-2.0, 2.0])),
    ];
    for p in cases {
        let fig = Figure::single(p);
        let svg = render_svg(&fig);
        assert!(svg.starts_with("<svg") && !svg.contains("NaN"), "{svg}");
        let _ = render_png_bytes(&fig, 0.5);
    }
}

#[test]
#[ignore = "writes /tmp/plot_linear.svg (and .png with the feature) for viewing"]
fn plot_dump_linear() {
    let idx: Vec<f64> = (1..=12).map(f64::from).collect();
    let res: Vec<f64> = idx.iter().map(|i| (i * 1.7).sin() * 2e-3).collect();
    let residuals = Plot::linear("Residuals", "interval", "residual (g)")
        .with_series(Series::new("|a| − g", idx, res).connected(false));
    let fig = Figure::grid(vec![thermal(), residuals], 2);
    std::fs::write("/tmp/plot_linear.svg", render_svg(&fig)).unwrap();
    if let Ok(png) = render_png_bytes(&fig, 1.0) {
        std::fs::write("/tmp/plot_linear.png", png).unwrap();
    }
}

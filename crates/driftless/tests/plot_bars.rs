//! Bars, category x ticks and equal-aspect panels of `report::plot`, measured in the
//! SVG (and, with the `png` feature, in the PNG pixels): bar heights proportional to the
//! value (linear) or to its decades above the axis bottom (log), a common baseline,
//! `n/a` at missing values, value labels, legend samples, and 1 m = 1 m on equal axes.

use driftless::report::plot::{
    AxisScale, Bars, Color, Figure, LegendPosition, Line, Plot, render_svg,
};

const BAR: Color = Color::rgb(0x20, 0x60, 0xe0);

#[path = "common/svg.rs"]
mod svg;
use svg::{rects, texts};

/// The plot frame of a single-panel figure.
fn frame(svg: &str) -> (f64, f64, f64, f64) {
    *svg::frames(svg).last().expect("frame")
}

fn linear_bars() -> Plot {
    Plot::linear("bars", "case", "error (m)")
        .with_x_range(0.5, 3.5)
        .with_y_range(0.0, 4.0)
        .with_bars(
            Bars::new("A", vec![1.0, 2.0, 3.0], vec![1.0, f64::NAN, 3.0])
                .with_width(0.5)
                .with_color(BAR)
                .with_missing_label("n/a")
                .with_value_labels(),
        )
}

#[test]
fn bars_linear_heights_baseline_and_missing_value() {
    let svg = render_svg(&Figure::single(linear_bars()));
    let (fx, fy, fw, fh) = frame(&svg);
    // Legend sample + 2 bars (the NaN has none).
    let r = rects(&svg, BAR);
    let bars: Vec<_> = r.iter().filter(|b| b.3 > 13.0).collect();
    assert_eq!(bars.len(), 2, "{r:?}");
    let (a, b) = (bars[0], bars[1]);
    // Baseline 0 is the frame bottom (y range starts at 0).
    for bar in [a, b] {
        assert!(
            (bar.1 + bar.3 - (fy + fh)).abs() < 0.02,
            "{bar:?} vs frame {fy}+{fh}"
        );
    }
    // Heights: 1/4 and 3/4 of the frame.
    assert!((a.3 - fh / 4.0).abs() < 0.02, "{} vs {}", a.3, fh / 4.0);
    assert!((b.3 - 3.0 * fh / 4.0).abs() < 0.02);
    // Width: 0.5 of the 3-unit x range; centred on x = 1 and 3.
    assert!((a.2 - fw / 6.0).abs() < 0.02);
    assert!((a.0 + a.2 / 2.0 - (fx + fw / 6.0)).abs() < 0.02);
    assert!((b.0 + b.2 / 2.0 - (fx + 5.0 * fw / 6.0)).abs() < 0.02);
    // "n/a" at the middle slot, just above the baseline; values above their bars.
    let t = texts(&svg);
    let na: Vec<_> = t.iter().filter(|t| t.0 == "n/a").collect();
    assert_eq!(na.len(), 1);
    assert!((na[0].1 - (fx + fw / 2.0)).abs() < 0.02);
    assert!(na[0].2 < fy + fh && na[0].2 > fy + fh - 10.0);
    let v3 = t.iter().find(|t| t.0 == "3").expect("value label 3");
    assert!(v3.2 < b.1 && v3.2 > b.1 - 8.0, "{v3:?} above {b:?}");
    assert!(t.iter().any(|t| t.0 == "1"));
    // Legend: a small filled sample of the bar colour.
    assert!(
        r.iter()
            .any(|s| (s.2 - 14.0).abs() < 0.01 && (s.3 - 12.0).abs() < 0.01)
    );
    assert!(t.iter().any(|t| t.0 == "A"));
}

#[test]
fn bars_negative_values_hang_from_zero() {
    let plot = Plot::linear("neg", "x", "y")
        .with_y_range(-2.0, 2.0)
        .with_bars(Bars::new("", vec![1.0, 2.0], vec![1.5, -1.0]).with_color(BAR));
    let svg = render_svg(&Figure::single(plot));
    let (_, fy, _, fh) = frame(&svg);
    let zero = fy + fh / 2.0;
    let r = rects(&svg, BAR);
    assert_eq!(r.len(), 2, "no legend entry for an unnamed series: {r:?}");
    assert!((r[0].1 + r[0].3 - zero).abs() < 0.02 && (r[0].3 - 0.375 * fh).abs() < 0.02);
    assert!((r[1].1 - zero).abs() < 0.02 && (r[1].3 - 0.25 * fh).abs() < 0.02);
    // Automatic width: 0.8 of the spacing.
    assert!((r[0].2 - r[1].2).abs() < 1e-9);
}

#[test]
fn bars_log_axis_rise_from_the_bottom_and_skip_unshowable_values() {
    let values = vec![0.1, 10.0, 1e4, 0.0, -1.0, f64::INFINITY, f64::NAN];
    let x: Vec<f64> = (1..=values.len()).map(|i| i as f64).collect();
    let plot = Plot::linear("log bars", "outage", "error (m)")
        .with_scales(AxisScale::Linear, AxisScale::Log)
        .with_bars(
            Bars::new("e", x, values)
                .with_color(BAR)
                .with_missing_label("n/a")
                .with_value_labels(),
        );
    let svg = render_svg(&Figure::single(plot));
    let (_, fy, _, fh) = frame(&svg);
    let bars: Vec<_> = rects(&svg, BAR)
        .into_iter()
        .filter(|r| r.3 > 12.5)
        .collect();
    assert_eq!(bars.len(), 3, "{bars:?}");
    for b in &bars {
        assert!(
            (b.1 + b.3 - (fy + fh)).abs() < 0.02,
            "bars start at the axis bottom"
        );
    }
    // Equal decades, equal heights: 0.1 → 10 is 2 decades, 10 → 10⁴ is 3.
    let (d1, d2) = (bars[1].3 - bars[0].3, bars[2].3 - bars[1].3);
    assert!((d2 / d1 - 1.5).abs() < 1e-3, "{d1} {d2}");
    // The smallest bar is a visible bar, not a sliver.
    assert!(bars[0].3 > 15.0, "{:?}", bars[0]);
    let t = texts(&svg);
    assert_eq!(t.iter().filter(|t| t.0 == "n/a").count(), 4);
    for v in ["0.1", "10", "10000"] {
        assert!(t.iter().any(|t| t.0 == v), "value label {v}");
    }
}

#[test]
fn category_ticks_replace_numbers_and_thin_when_crowded() {
    let plot = linear_bars().with_x_tick_labels(vec![
        (1.0, "#1".into()),
        (2.0, "#2".into()),
        (3.0, "#3".into()),
        (f64::NAN, "bad".into()),
    ]);
    let svg = render_svg(&Figure::single(plot));
    let (fx, fy, fw, fh) = frame(&svg);
    let t = texts(&svg);
    for (k, label) in ["#1", "#2", "#3"].iter().enumerate() {
        let at = t.iter().find(|t| t.0 == *label).expect("category label");
        let want = fx + fw * (2.0 * k as f64 + 1.0) / 6.0;
        assert!((at.1 - want).abs() < 0.02 && at.2 > fy + fh, "{at:?}");
    }
    assert!(!t.iter().any(|t| t.0 == "bad"));
    // No automatic x tick labels under the axis besides the categories.
    let under: Vec<_> = t
        .iter()
        .filter(|t| t.1 > fx && t.2 > fy + fh && t.2 < fy + fh + 25.0)
        .map(|t| t.0.as_str())
        .collect();
    assert_eq!(under, ["#1", "#2", "#3"]);

    // 60 long labels on 600 px cannot all be written: every n-th is.
    let many: Vec<(f64, String)> = (0..60).map(|i| (i as f64, format!("outage {i}"))).collect();
    let plot = Plot::linear("many", "x", "y")
        .with_bars(Bars::new(
            "",
            (0..60).map(f64::from).collect(),
            vec![1.0; 60],
        ))
        .with_x_tick_labels(many);
    let svg = render_svg(&Figure::single(plot));
    let shown: Vec<_> = texts(&svg)
        .into_iter()
        .filter(|t| t.0.starts_with("outage "))
        .collect();
    assert!(shown.len() >= 3 && shown.len() < 20, "{}", shown.len());
    for w in shown.windows(2) {
        assert!(w[1].1 - w[0].1 > 60.0, "labels collide: {w:?}");
    }
}

#[test]
fn equal_aspect_keeps_one_metre_equal_on_both_axes() {
    let red = Color::rgb(0xff, 0, 0);
    for (x1, y1) in [(1000.0, 500.0), (100.0, 800.0), (3.0, 3.0)] {
        let plot = Plot::linear("map", "east (m)", "north (m)")
            .with_equal_aspect()
            .with_line(Line::new("track", vec![0.0, x1], vec![0.0, y1]).with_color(red));
        let svg = render_svg(&Figure::single(plot).with_panel_size(700.0, 500.0));
        // The first red polyline is the track (the legend sample comes later).
        let pts = svg::polylines(&svg, red).swap_remove(0);
        let (dx, dy) = (pts[1].0 - pts[0].0, pts[0].1 - pts[1].1);
        let ratio = (dx / dy) / (x1 / y1);
        assert!((ratio - 1.0).abs() < 0.01, "({x1}, {y1}): px {dx} × {dy}");
        // The whole track stays visible.
        let (fx, fy, fw, fh) = frame(&svg);
        for p in &pts {
            assert!(p.0 >= fx && p.0 <= fx + fw && p.1 >= fy && p.1 <= fy + fh);
        }
    }
}

#[test]
fn bars_degenerate_inputs_do_not_panic() {
    let cases = vec![
        Plot::linear("empty", "x", "y").with_bars(Bars::default()),
        Plot::linear("all nan", "x", "y").with_bars(
            Bars::new("n", vec![1.0, 2.0], vec![f64::NAN, f64::NAN])
                .with_missing_label("n/a")
                .with_value_labels(),
        ),
        Plot::linear("mismatch", "x", "y")
            .with_bars(Bars::new("m", vec![1.0, 2.0, 3.0], vec![1.0]).with_width(f64::NAN)),
        Plot::linear("bad x", "x", "y").with_bars(Bars::new(
            "b",
            vec![f64::NAN, f64::INFINITY, 1.0],
            vec![1.0, 2.0, 3.0],
        )),
        Plot::new("log both", "x", "y").with_bars(
            Bars::new("l", vec![0.0, 1.0, 10.0], vec![1.0, 1e300, 1e-300])
                .with_width(0.5)
                .with_value_labels(),
        ),
        Plot::linear("huge", "x", "y").with_bars(
            Bars::new("h", vec![1.0, 2.0], vec![f64::MAX, -f64::MAX])
                .with_width(-1.0)
                .with_value_labels(),
        ),
        Plot::linear("equal nothing", "x", "y").with_equal_aspect(),
        Plot::linear("ticks only", "x", "y").with_x_tick_labels(vec![(1.0, String::new())]),
        Plot {
            legend: LegendPosition::Hidden,
            ..Plot::linear("tiny", "x", "y")
                .with_equal_aspect()
                .with_line(Line::new("", vec![0.0, 1e-300], vec![0.0, 1e300]))
        },
    ];
    for p in cases {
        let title = p.title.clone();
        let svg = render_svg(&Figure::single(p));
        assert!(
            svg.starts_with("<svg") && svg.ends_with("</svg>\n"),
            "{title}"
        );
        assert!(!svg.contains("NaN") && !svg.contains("inf"), "{title}");
    }
}

#[cfg(feature = "png")]
#[test]
fn bars_in_png_pixels() {
    use driftless::report::plot::render_png_bytes;
    const BAR2: Color = Color::rgb(0xe0, 0x60, 0x20);
    let plot = linear_bars().with_bars(
        Bars::new("B", vec![1.5, 2.5], vec![2.0, 2.0])
            .with_width(0.25)
            .with_color(BAR2),
    );
    let bytes = render_png_bytes(&Figure::single(plot), 1.0).expect("png");
    let img = tiny_skia::Pixmap::decode_png(&bytes).expect("decode");
    // Pixels whose nearest reference colour is the bar's (references: both bar colours,
    // white, black): edge pixels count when the bar covers about half of them or more,
    // so the count estimates the drawn area; text and grid are nearer black or white.
    let d = |p: &tiny_skia::PremultipliedColorU8, c: Color| {
        u32::from(p.red().abs_diff(c.r))
            + u32::from(p.green().abs_diff(c.g))
            + u32::from(p.blue().abs_diff(c.b))
    };
    let refs = [BAR, BAR2, Color::WHITE, Color::BLACK];
    let count = |c: Color| {
        img.pixels()
            .iter()
            .filter(|p| refs.iter().all(|r| *r == c || d(p, c) < d(p, *r)))
            .count() as f64
    };
    let svg = render_svg(&Figure::single(linear_bars()));
    let (_, _, fw, fh) = frame(&svg);
    // Series A: bars of 1 and 3 (of 4) units, 0.5 of 3 units wide, plus the 14 × 12
    // legend sample; series B: two bars of 2 units, 0.25 wide.
    let want_a = (fw / 6.0) * (fh / 4.0 + 3.0 * fh / 4.0) + 168.0;
    let want_b = 2.0 * (fw / 12.0) * (fh / 2.0) + 168.0;
    let (a, b) = (count(BAR), count(BAR2));
    eprintln!("bar pixels: {a} (expected {want_a:.0}), {b} (expected {want_b:.0})");
    assert!((a / want_a - 1.0).abs() < 0.03, "{a} vs {want_a}");
    assert!((b / want_b - 1.0).abs() < 0.03, "{b} vs {want_b}");
}

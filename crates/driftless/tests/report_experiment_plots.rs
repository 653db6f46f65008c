//! The experiment figures (`report::experiment_plots`), measured in their SVG: the
//! trajectory on equal axes with labelled outages and one legend entry per solution,
//! a drifting solution that cannot shrink the view, grouped bars with `n/a` for missing
//! values on a log axis, error-growth panels sharing their ranges, and consistent case
//! colours.

use driftless::report::experiment_plots::{
    FIGURE_WIDTH, case_color, error_growth_figure, error_growth_figure_scaled, fit_to_width,
    grouped_bars_figure, outage_bars_figure, trajectory_figure,
};
use driftless::report::plot::{AxisScale, Color, Figure, PALETTE, Plot, render_svg};

#[path = "common/svg.rs"]
mod svg;
use svg::{frames, polylines, rects, texts};

/// A circle of radius 500 m about (north 1000, east −2000), `[north, east]`, 1° steps.
fn circle() -> Vec<[f64; 2]> {
    (0..=360)
        .map(|d| {
            let a = f64::from(d).to_radians();
            [1000.0 + 500.0 * a.sin(), -2000.0 + 500.0 * a.cos()]
        })
        .collect()
}

fn extent(pts: &[(f64, f64)]) -> (f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in pts {
        x0 = x0.min(p.0);
        x1 = x1.max(p.0);
        y0 = y0.min(p.1);
        y1 = y1.max(p.1);
    }
    (x1 - x0, y1 - y0)
}

#[test]
fn trajectory_equal_axes_labels_legend_and_bounded_view() {
    let reference = circle();
    let tracks = vec![reference[10..40].to_vec(), reference[200..260].to_vec()];
    // (b) drifts 50 km away in its first outage; (c) stays close.
    let far: Vec<[f64; 2]> = (0..30)
        .map(|i| [tracks[0][i][0] + 50.0 * (i * i) as f64, tracks[0][i][1]])
        .collect();
    let solutions = vec![
        ("(b) room cal".to_owned(), vec![far, tracks[1].clone()]),
        (
            "(c) room + thermal".to_owned(),
            tracks
                .iter()
                .map(|t| t.iter().map(|p| [p[0] + 5.0, p[1] - 5.0]).collect())
                .collect(),
        ),
    ];
    let fig = trajectory_figure(&reference, &tracks, &solutions);
    assert!(fig.panel_width <= FIGURE_WIDTH);
    let svg = render_svg(&fig);
    let t = texts(&svg);
    let has = |s: &str| t.iter().filter(|x| x.0 == s).count();
    for s in [
        "east (m)",
        "north (m)",
        "#1",
        "#2",
        "reference",
        "GNSS outage (reference)",
    ] {
        assert_eq!(has(s), 1, "{s}");
    }
    // One legend entry per solution, however many outage tracks it has.
    assert_eq!(has("(b) room cal"), 1);
    assert_eq!(has("(c) room + thermal"), 1);

    // The reference circle is round on the page and fills most of the frame although
    // (b) left for 50 km.
    let frame = frames(&svg)[0];
    let ref_runs = polylines(&svg, Color::DARK_GREY);
    let circle_run = ref_runs
        .iter()
        .max_by_key(|r| r.len())
        .expect("reference line");
    let (w, h) = extent(circle_run);
    assert!(
        (w / h - 1.0).abs() < 0.01,
        "circle drawn {w:.1} × {h:.1} px"
    );
    assert!(
        h > 0.5 * frame.3.min(frame.2),
        "circle {h:.0} px in a {frame:?} frame"
    );
    // "#k" sits beside the open-circle marker at the start of outage k, which is on
    // the reference circle.
    let markers: Vec<(f64, f64)> = svg
        .lines()
        .filter(|l| l.starts_with("<circle") && l.contains("r=\"6\""))
        .map(|l| (svg::attr(l, "cx"), svg::attr(l, "cy")))
        .collect();
    assert_eq!(markers.len(), 2);
    let centre = |run: &[(f64, f64)]| {
        let n = run.len() as f64;
        (
            run.iter().map(|p| p.0).sum::<f64>() / n,
            run.iter().map(|p| p.1).sum::<f64>() / n,
        )
    };
    let (cx, cy) = centre(circle_run);
    for (k, m) in markers.iter().enumerate() {
        let r = (m.0 - cx).hypot(m.1 - cy);
        assert!(
            (r - h / 2.0).abs() < 2.0,
            "marker {k} off the circle: {r} vs {}",
            h / 2.0
        );
        let label = t
            .iter()
            .find(|x| x.0 == format!("#{}", k + 1))
            .expect("label");
        let d = (label.1 - m.0).hypot(label.2 - m.1);
        assert!(d < 45.0, "#{} is {d:.0} px from its outage start", k + 1);
    }
    // Outage 1 starts at 10° on the circle: right of and above the centre.
    assert!(markers[0].0 > cx && markers[0].1 < cy);
    // Solutions in their case colours: (b) is PALETTE[1] although (a) is absent.
    assert!(!polylines(&svg, PALETTE[1]).is_empty());
    assert!(!polylines(&svg, PALETTE[2]).is_empty());
    assert!(polylines(&svg, PALETTE[0]).is_empty());
    // (b)'s first track is clipped at the frame, not dropped.
    let b_runs = polylines(&svg, PALETTE[1]);
    for run in &b_runs {
        for p in run {
            assert!(p.1 >= frame.1 - 0.01 && p.1 <= frame.1 + frame.3 + 0.01);
        }
    }
}

#[test]
fn case_colours_follow_the_paper_tags() {
    assert_eq!(case_color("(a) raw", 5), PALETTE[0]);
    assert_eq!(case_color("(c) room + thermal", 0), PALETTE[2]);
    assert_eq!(case_color(" (b) x", 0), PALETTE[1]);
    assert_eq!(case_color("untagged", 3), PALETTE[3]);
    assert_eq!(case_color("(ab) not a tag", 1), PALETTE[1]);
}

#[test]
fn outage_bars_log_axis_with_missing_values() {
    let labels: Vec<String> = vec!["#1".into(), "#2".into(), "".into()];
    let cases = vec![
        ("(a) raw".to_owned(), vec![4200.0, f64::NAN, 9800.0]),
        ("(b) room cal".to_owned(), vec![95.0, 210.0, 88.0]),
        // One value short: outage 3 has no (c) value.
        ("(c) room + thermal".to_owned(), vec![0.1, 0.4]),
    ];
    let svg = render_svg(&outage_bars_figure(&labels, &cases, "max error (m)", true));
    let t = texts(&svg);
    assert_eq!(t.iter().filter(|x| x.0 == "n/a").count(), 2);
    for s in [
        "#1",
        "#2",
        "#3",
        "max error (m)",
        "GNSS outage",
        "(a) raw",
        "(c) room + thermal",
    ] {
        assert!(t.iter().any(|x| x.0 == s), "{s}");
    }
    let frame = frames(&svg)[0];
    let bottom = frame.1 + frame.3;
    let mut heights = Vec::new();
    for (c, n) in [(0, 2), (1, 3), (2, 2)] {
        let bars: Vec<_> = rects(&svg, PALETTE[c])
            .into_iter()
            .filter(|r| (r.1 + r.3 - bottom).abs() < 0.02)
            .collect();
        assert_eq!(bars.len(), n, "case {c}: {bars:?}");
        heights.push(bars);
    }
    // Log heights: 9800 vs 4200 and 210 vs 95 differ by their decades.
    let px_per_decade = (heights[0][1].3 - heights[0][0].3) / (9800f64 / 4200.0).log10();
    let d = heights[1][1].3 - heights[1][0].3;
    assert!((d / (210f64 / 95.0).log10() / px_per_decade - 1.0).abs() < 0.01);
    // The legend (top right) does not cover any bar.
    let legend = svg
        .lines()
        .find(|l| l.starts_with("<rect") && l.contains("fill-opacity=\"0.92\""))
        .map(|l| {
            (
                svg::attr(l, "x"),
                svg::attr(l, "y"),
                svg::attr(l, "width"),
                svg::attr(l, "height"),
            )
        })
        .expect("legend box");
    for b in heights.iter().flatten() {
        let overlap_x = b.0 < legend.0 + legend.2 && legend.0 < b.0 + b.2;
        let overlap_y = b.1 < legend.1 + legend.3 && legend.1 < b.1 + b.3;
        assert!(
            !(overlap_x && overlap_y),
            "legend {legend:?} covers bar {b:?}"
        );
    }

    // Linear axis: bars from zero, all finite values drawn, no data → still renders.
    let svg = render_svg(&outage_bars_figure(&labels, &cases, "m", false));
    assert_eq!(texts(&svg).iter().filter(|x| x.0 == "n/a").count(), 2);
    let svg = render_svg(&outage_bars_figure(&[], &[], "m", true));
    assert!(svg.ends_with("</svg>\n"));
}

#[test]
fn error_growth_panels_share_ranges_and_outage_colours() {
    let curve = |k: f64| -> Vec<(f64, f64)> {
        (0..=60)
            .map(|i| (f64::from(i), k * f64::from(i * i)))
            .collect()
    };
    let cases = vec![
        ("(a) raw".to_owned(), vec![curve(2.0), curve(3.0)]),
        ("(b) room cal".to_owned(), vec![curve(0.05), curve(0.02)]),
        (
            "(c) room + thermal".to_owned(),
            vec![curve(0.01), vec![(0.0, f64::NAN)]],
        ),
    ];
    for scale in [AxisScale::Linear, AxisScale::Log] {
        let fig = error_growth_figure_scaled(&cases, "horizontal error (m)", scale);
        assert_eq!(fig.panels.len(), 3);
        assert!(fig.panel_width * 3.0 <= FIGURE_WIDTH + 0.5);
        let first = (fig.panels[0].x_range, fig.panels[0].y_range);
        assert!(
            first
                .1
                .is_some_and(|(lo, hi)| hi >= 3.0 * 3600.0 && lo < 1.0)
        );
        for p in &fig.panels {
            assert_eq!((p.x_range, p.y_range), first, "{}", p.title);
            assert_eq!(p.y_scale, scale);
        }
        let svg = render_svg(&fig);
        // The same outage has the same colour in every panel: outage #1 is drawn in
        // all three (first line of each panel), so its colour has ≥ 3 data polylines.
        let c1 = fig.panels[0].lines[0].color.expect("colour");
        for p in &fig.panels {
            assert_eq!(p.lines[0].color, Some(c1));
            assert_eq!(p.lines[0].name, "#1");
        }
        assert!(polylines(&svg, c1).iter().filter(|r| r.len() > 10).count() >= 3);
        // Outage colours are not case colours.
        assert!(!PALETTE[..3].contains(&c1));
        for title in ["(a) raw", "(b) room cal", "(c) room + thermal"] {
            assert!(texts(&svg).iter().any(|t| t.0 == title));
        }
    }
    let lin = error_growth_figure(&cases, "m");
    assert_eq!(lin.panels[0].y_scale, AxisScale::Linear);
    // Empty input still renders.
    assert!(render_svg(&error_growth_figure(&[], "m")).ends_with("</svg>\n"));
}

#[test]
fn fit_to_width_shrinks_wide_grids_only() {
    let wide = Figure::grid(vec![Plot::default(), Plot::default()], 2);
    let f = fit_to_width(wide, 960.0);
    assert!((f.panel_width * 2.0 - 960.0).abs() < 1e-9);
    assert!((f.panel_height - 480.0 * 0.75).abs() < 1e-9);
    let narrow = Figure::single(Plot::default()).with_panel_size(500.0, 400.0);
    assert_eq!(fit_to_width(narrow.clone(), 960.0), narrow);
    // Never below a readable panel.
    let many = Figure::grid(vec![Plot::default(); 8], 0);
    let f = fit_to_width(many, 960.0);
    assert!(f.panel_width >= 300.0 && f.panel_height >= 230.0);
    assert_eq!(fit_to_width(narrow.clone(), f64::NAN), narrow);
}

/// No two outages of a panel look alike: nine outages (the demo's) in nine distinct
/// colours, and beyond the ten colours the same colour comes back dashed.
#[test]
fn outage_lines_are_distinct_within_a_panel() {
    let curve = |k: usize| -> Vec<(f64, f64)> {
        (0..=10)
            .map(|i| (f64::from(i), (k + 1) as f64 * f64::from(i)))
            .collect()
    };
    for n in [9usize, 14] {
        let cases = vec![("(a) raw".to_owned(), (0..n).map(curve).collect())];
        let fig = error_growth_figure(&cases, "m");
        let lines = &fig.panels[0].lines;
        assert_eq!(lines.len(), n);
        let looks: Vec<_> = lines.iter().map(|l| (l.color, l.style)).collect();
        for i in 0..n {
            for j in 0..i {
                assert_ne!(
                    looks[i],
                    looks[j],
                    "outages #{} and #{} alike",
                    j + 1,
                    i + 1
                );
            }
        }
        if n == 9 {
            let mut colours: Vec<_> = lines.iter().map(|l| l.color).collect();
            colours.dedup();
            colours.sort_by_key(|c| format!("{c:?}"));
            colours.dedup();
            assert_eq!(colours.len(), 9, "nine outages, nine colours");
        }
    }
}

/// Bars grouped by something other than outages carry their own title and axis label:
/// the Monte Carlo figure is not titled "Error per GNSS outage".
#[test]
fn grouped_bars_name_their_groups() {
    let cases = vec![("(a) raw".to_owned(), vec![3.0, 4.0, 5.0])];
    let runs: Vec<String> = ["1", "2", "3"].map(String::from).to_vec();
    let fig = grouped_bars_figure(
        "Mean end-of-outage error per Monte Carlo run",
        "Monte Carlo run",
        &runs,
        &cases,
        "m",
        true,
    );
    let svg = render_svg(&fig);
    let t = texts(&svg);
    assert!(
        t.iter()
            .any(|x| x.0 == "Mean end-of-outage error per Monte Carlo run")
    );
    assert!(t.iter().any(|x| x.0 == "Monte Carlo run"));
    assert!(!t.iter().any(|x| x.0.contains("GNSS outage")));
    let o = render_svg(&outage_bars_figure(&runs, &cases, "m", true));
    assert!(texts(&o).iter().any(|x| x.0 == "Error per GNSS outage"));
}

//! SVG output of `report::plot`: well-formedness, ticks, odd data, escaping.

use driftless::report::plot::scale::{decade_label, log_ticks, minor_label, superscript};
use driftless::report::plot::{
    Annotation, Figure, LegendPosition, Line, LogLogPlot, MarkerShape, PlotError, Series,
    render_png_bytes, render_svg, xml_escape,
};

/// A small XML well-formedness checker (enough for what we emit): balanced
/// and properly nested tags, quoted attributes without raw `<`/`&`, only the
/// five predefined entities or numeric references in text, one root element.
fn check_xml(doc: &str) -> Result<usize, String> {
    fn check_entities(s: &str) -> Result<(), String> {
        let mut rest = s;
        while let Some(i) = rest.find('&') {
            let tail = &rest[i + 1..];
            let end = tail.find(';').ok_or_else(|| format!("bare & in {s:?}"))?;
            let name = &tail[..end];
            let ok = matches!(name, "amp" | "lt" | "gt" | "quot" | "apos")
                || (name.starts_with('#') && name.len() > 1);
            if !ok {
                return Err(format!("bad entity &{name};"));
            }
            rest = &tail[end + 1..];
        }
        if s.chars()
            .any(|c| (c as u32) < 0x20 && !matches!(c, '\n' | '\r' | '\t'))
        {
            return Err("control character".into());
        }
        Ok(())
    }
    let mut stack: Vec<String> = Vec::new();
    let mut roots = 0;
    let mut elements = 0;
    let mut rest = doc;
    while let Some(lt) = rest.find('<') {
        let text = &rest[..lt];
        if stack.is_empty() && !text.trim().is_empty() {
            return Err(format!("text outside root: {text:?}"));
        }
        if text.contains('>') {
            return Err(format!("raw > in text {text:?}"));
        }
        check_entities(text)?;
        let after = &rest[lt + 1..];
        let gt = after.find('>').ok_or("unterminated tag")?;
        let tag = &after[..gt];
        rest = &after[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().ok_or("close without open")?;
            if open != name.trim() {
                return Err(format!("</{name}> closes <{open}>"));
            }
            continue;
        }
        let self_closing = tag.ends_with('/');
        let body = tag.trim_end_matches('/');
        let name: String = body.chars().take_while(|c| !c.is_whitespace()).collect();
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == ':')
        {
            return Err(format!("bad tag name in <{tag}>"));
        }
        // Attributes: name="value" pairs.
        let mut attrs = body[name.len()..].trim();
        let mut seen = Vec::new();
        while !attrs.is_empty() {
            let eq = attrs
                .find('=')
                .ok_or_else(|| format!("attribute without value in <{tag}>"))?;
            let an = attrs[..eq].trim();
            if an.is_empty() || seen.contains(&an) {
                return Err(format!("bad/duplicate attribute {an:?}"));
            }
            seen.push(an);
            let v = &attrs[eq + 1..];
            let q = v.chars().next().ok_or("missing value")?;
            if q != '"' && q != '\'' {
                return Err(format!("unquoted attribute in <{tag}>"));
            }
            let close = v[1..].find(q).ok_or("unterminated attribute")?;
            let val = &v[1..1 + close];
            if val.contains('<') {
                return Err("< in attribute".into());
            }
            check_entities(val)?;
            attrs = v[close + 2..].trim_start();
        }
        elements += 1;
        if stack.is_empty() {
            roots += 1;
        }
        if !self_closing {
            stack.push(name);
        }
    }
    if !rest.trim().is_empty() {
        return Err("trailing text".into());
    }
    if !stack.is_empty() {
        return Err(format!("unclosed {stack:?}"));
    }
    if roots != 1 {
        return Err(format!("{roots} root elements"));
    }
    Ok(elements)
}

fn assert_svg_ok(svg: &str) {
    if let Err(e) = check_xml(svg) {
        panic!("malformed SVG: {e}\n{svg}");
    }
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    for bad in ["NaN", "inf", "id=", "<image", "href", "<style"] {
        assert!(!svg.contains(bad), "SVG contains {bad:?}");
    }
}

/// All numbers in `points="…"` attributes.
fn polyline_coords(svg: &str) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for part in svg.split("<polyline points=\"").skip(1) {
        let pts = &part[..part.find('"').unwrap()];
        for p in pts.split(' ') {
            let (x, y) = p.split_once(',').unwrap();
            out.push((x.parse().unwrap(), y.parse().unwrap()));
        }
    }
    out
}

fn allan_like() -> LogLogPlot {
    let taus: Vec<f64> = (0..20)
        .map(|i| 10f64.powf(-2.0 + 0.3 * f64::from(i)))
        .collect();
    let y: Vec<f64> = taus
        .iter()
        .map(|t| (0.01 / t + 1e-4 + 1e-6 * t).sqrt())
        .collect();
    let lo = y.iter().map(|v| v * 0.9).collect();
    let hi = y.iter().map(|v| v * 1.1).collect();
    LogLogPlot::new("Gyro <x> & \"y\"", "τ (s)", "σ(τ) (rad/s)")
        .with_series(Series::new("X", taus.clone(), y).with_ci(lo, hi))
        .with_line(
            Line::power_law("white", 0.1, -0.5, 1e-4, 1e6, 2)
                .dashed()
                .with_label("N = 0.1 rad/√s"),
        )
        .with_line(
            Line::power_law("floor", 0.016, 0.0, 1e-4, 1e6, 2)
                .dashed()
                .with_label("B = 0.01"),
        )
        .with_annotation(Annotation::new("min", 100.0, 0.0175))
}

#[test]
fn plot_svg_is_well_formed() {
    let fig =
        Figure::grid(vec![allan_like(), allan_like(), allan_like()], 2).with_title("Six-axis");
    let svg = render_svg(&fig);
    assert_svg_ok(&svg);
    assert!(svg.contains("<title>Six-axis</title>"));
    assert!(svg.contains("width=\"1280\""), "two columns of 640 px");
    assert!(svg.contains("stroke-dasharray"), "dashed asymptotes");
    assert!(svg.contains(">N = 0.1 rad/√s</text>"), "line label drawn");
    assert!(svg.contains(">τ (s)</text>"), "axis title");
    assert!(svg.contains("rotate(-90"), "vertical y title");
    assert!(svg.contains(">10⁻²</text>"), "decade tick label");
}

#[test]
fn plot_ticks_at_decades() {
    let ticks = log_ticks(0.01f64.log10(), 1000f64.log10(), 600.0, 40.0);
    let majors: Vec<f64> = ticks.iter().filter(|t| t.major).map(|t| t.log).collect();
    assert_eq!(majors, vec![-2.0, -1.0, 0.0, 1.0, 2.0, 3.0]);
    let labels: Vec<&str> = ticks.iter().filter_map(|t| t.label.as_deref()).collect();
    assert_eq!(labels, vec!["10⁻²", "10⁻¹", "10⁰", "10¹", "10²", "10³"]);
    for t in &ticks {
        assert!((t.value.log10() - t.log).abs() < 1e-12);
    }
    // 100 px per decade: 8 minor ticks per full decade.
    assert_eq!(ticks.iter().filter(|t| !t.major).count(), 5 * 8);

    // Not aligned to decades: only interior decades, minors inside the range.
    let ticks = log_ticks(-1.5, 2.3, 400.0, 40.0);
    let majors: Vec<f64> = ticks.iter().filter(|t| t.major).map(|t| t.log).collect();
    assert_eq!(majors, vec![-1.0, 0.0, 1.0, 2.0]);
    assert!(ticks.iter().all(|t| t.log >= -1.5 && t.log <= 2.3));
}

#[test]
fn plot_ticks_short_and_huge_ranges() {
    // Less than one decade tick: minor ticks get labels.
    let ticks = log_ticks(0.2f64.log10(), 0.9f64.log10(), 400.0, 40.0);
    let labels: Vec<&str> = ticks.iter().filter_map(|t| t.label.as_deref()).collect();
    assert!(labels.len() >= 2, "{labels:?}");
    assert!(labels.contains(&"0.5"), "{labels:?}");

    // 600 decades on 500 px: labels thinned, bounded, no panic.
    let ticks = log_ticks(-300.0, 300.0, 500.0, 40.0);
    let n_labels = ticks.iter().filter(|t| t.label.is_some()).count();
    assert!((2..=13).contains(&n_labels), "{n_labels}");
    assert!(ticks.len() < 200);

    // Degenerate input.
    assert!(log_ticks(f64::NAN, 1.0, 100.0, 40.0).is_empty());
    assert!(log_ticks(2.0, 1.0, 100.0, 40.0).is_empty());
    assert!(!log_ticks(0.0, 1.0, f64::NAN, f64::NAN).is_empty());
}

#[test]
fn plot_tick_label_format() {
    assert_eq!(superscript(-12), "⁻¹²");
    assert_eq!(superscript(0), "⁰");
    assert_eq!(decade_label(3), "10³");
    assert_eq!(decade_label(i32::MIN), "10⁻²¹⁴⁷⁴⁸³⁶⁴⁸");
    assert_eq!(minor_label(2, -2), "0.02");
    assert_eq!(minor_label(5, 2), "500");
    assert_eq!(minor_label(3, -7), "3×10⁻⁷");
}

#[test]
fn plot_skips_nan_zero_negative() {
    let x = vec![
        0.1,
        f64::NAN,
        1.0,
        0.0,
        10.0,
        -5.0,
        100.0,
        f64::INFINITY,
        1000.0,
    ];
    let y = vec![1.0, 2.0, f64::NAN, 3.0, 0.5, 1.0, -1.0, 1.0, 0.3];
    let lo = vec![0.9, 1.0, 1.0, 1.0, -1.0, 1.0, 1.0, 1.0, f64::NAN];
    let hi = vec![1.1, 3.0, 1.0, 1.0, 0.6, 1.0, 1.0, 1.0, f64::INFINITY];
    let plot = LogLogPlot {
        legend: LegendPosition::Hidden,
        ..LogLogPlot::new("odd", "x", "y")
    }
    .with_series(
        Series::new("s", x, y)
            .with_ci(lo, hi)
            .with_marker(MarkerShape::Circle),
    )
    .with_line(
        Line::new(
            "l",
            vec![f64::NAN, 0.0, -1.0, 1.0],
            vec![1.0, 1.0, 1.0, f64::NAN],
        )
        .with_label("lbl"),
    )
    .with_annotation(Annotation::new("nan", f64::NAN, 1.0));
    let svg = render_svg(&Figure::single(plot));
    assert_svg_ok(&svg);
    // Valid points: (0.1, 1), (10, 0.5), (1000, 0.3).
    assert_eq!(svg.matches("<circle").count(), 3, "{svg}");
    // The connecting line breaks at every invalid point: no run of ≥ 2 valid
    // consecutive points exists, so no series polyline at all except error
    // bars / grid / ticks (all straight 2-point lines).
    for part in svg.split("<polyline points=\"").skip(1) {
        let pts = &part[..part.find('"').unwrap()];
        assert_eq!(pts.split(' ').count(), 2, "{pts}");
    }
}

#[test]
fn plot_degenerate_inputs_do_not_panic() {
    let cases = vec![
        Figure::default(),
        Figure::single(LogLogPlot::default()),
        Figure::single(LogLogPlot::new("", "", "").with_series(Series::new(
            "empty",
            vec![],
            vec![],
        ))),
        Figure::single(LogLogPlot::new("one", "x", "y").with_series(Series::new(
            "p",
            vec![3.0],
            vec![7.0],
        ))),
        Figure::single(LogLogPlot::new("mismatch", "x", "y").with_series(
            Series::new("p", vec![1.0, 2.0, 3.0], vec![1.0]).with_ci(vec![], vec![2.0; 9]),
        )),
        Figure::single(LogLogPlot::new("huge", "x", "y").with_series(Series::new(
            "p",
            vec![f64::MIN_POSITIVE, 1.0, f64::MAX],
            vec![5e-324, 1.0, f64::MAX],
        ))),
        Figure::single(
            LogLogPlot::new("all bad", "x", "y").with_series(Series::new(
                "p",
                vec![f64::NAN, -1.0, 0.0],
                vec![1.0, 1.0, 1.0],
            )),
        ),
        Figure::single(LogLogPlot {
            x_range: Some((10.0, 0.1)),
            y_range: Some((f64::NAN, 3.0)),
            ..allan_like()
        }),
        Figure {
            panel_width: f64::NAN,
            panel_height: -3.0,
            columns: 7,
            ..Figure::grid(vec![allan_like()], 3)
        },
        Figure::single(
            LogLogPlot::new("lines only", "x", "y")
                .with_line(Line::power_law("", 1.0, 0.5, 1.0, 1e3, 5)),
        ),
        Figure::single(
            LogLogPlot::new("bad power law", "x", "y").with_line(Line::power_law(
                "",
                1.0,
                0.5,
                -1.0,
                f64::NAN,
                5,
            )),
        ),
    ];
    for fig in &cases {
        let svg = render_svg(fig);
        assert_svg_ok(&svg);
        let _ = render_png_bytes(fig, 0.5);
    }
    // The huge-range case keeps every coordinate finite and small.
    for (x, y) in polyline_coords(&render_svg(&cases[5])) {
        assert!(x.abs() < 1e4 && y.abs() < 1e4);
    }
}

#[test]
fn plot_lines_are_clipped_to_the_plot_area() {
    let plot = LogLogPlot::new("clip", "x", "y")
        .with_series(Series::new("s", vec![1.0, 10.0], vec![1.0, 10.0]))
        .with_line(Line::power_law("wide", 1e-9, 3.0, 1e-12, 1e12, 50));
    let fig = Figure::single(plot);
    let svg = render_svg(&fig);
    assert_svg_ok(&svg);
    for (x, y) in polyline_coords(&svg) {
        assert!(
            (0.0..=640.0).contains(&x) && (0.0..=480.0).contains(&y),
            "({x}, {y})"
        );
    }
}

#[test]
fn plot_labels_are_escaped() {
    assert_eq!(xml_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    assert_eq!(xml_escape("x\u{1}y\nz"), "x\u{fffd}y z");
    let evil = "</text><script>alert(1)</script>&amp;\u{0}";
    let plot = LogLogPlot::new(evil, evil, evil)
        .with_series(Series::new(evil, vec![1.0, 2.0], vec![1.0, 2.0]))
        .with_line(Line::new(evil, vec![1.0, 2.0], vec![2.0, 1.0]).with_label(evil))
        .with_annotation(Annotation::new(evil, 1.5, 1.5));
    let svg = render_svg(&Figure::single(plot).with_title(evil));
    assert_svg_ok(&svg);
    assert!(!svg.contains("<script"));
    assert!(svg.contains("&lt;script&gt;"));
    assert!(svg.contains("&amp;amp;"));
}

#[test]
fn plot_legend_and_labels_do_not_overlap() {
    let svg = render_svg(&Figure::single(allan_like()));
    // Translucent boxes behind labels and the legend (fill-opacity < 1).
    let boxes: Vec<[f64; 4]> = svg
        .lines()
        .filter(|l| l.starts_with("<rect") && l.contains("fill-opacity"))
        .map(|l| {
            let attr = |name: &str| -> f64 {
                let s = &l[l.find(&format!(" {name}=\"")).unwrap() + name.len() + 3..];
                s[..s.find('"').unwrap()].parse().unwrap()
            };
            [attr("x"), attr("y"), attr("width"), attr("height")]
        })
        .collect();
    assert_eq!(boxes.len(), 4, "legend + 2 line labels + annotation");
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            let ox = (a[0] + a[2]).min(b[0] + b[2]) - a[0].max(b[0]);
            let oy = (a[1] + a[3]).min(b[1] + b[3]) - a[1].max(b[1]);
            assert!(ox <= 0.0 || oy <= 0.0, "{a:?} overlaps {b:?}");
        }
    }
}

#[cfg(not(feature = "png"))]
#[test]
fn plot_png_without_feature_is_an_error() {
    let path = std::env::temp_dir().join("driftless_plot_nofeature.png");
    let _ = std::fs::remove_file(&path);
    let err =
        driftless::report::plot::render_png(&Figure::single(allan_like()), &path).unwrap_err();
    assert!(matches!(err, PlotError::PngUnsupported));
    assert!(err.to_string().contains("`png` feature"));
    assert!(!path.exists());
}

#[test]
fn plot_png_error_is_typed() {
    let r = render_png_bytes(&Figure::single(allan_like()), 1.0);
    if cfg!(feature = "png") {
        assert!(r.is_ok());
    } else {
        assert!(matches!(r, Err(PlotError::PngUnsupported)));
    }
}

/// A figure name that is neither `.svg` nor `.png` is refused, naming the file, and
/// nothing is written (SVG text used to land in a `.jpg`); `.SVG` is SVG.
#[test]
fn write_figure_refuses_other_formats() {
    let dir = std::env::temp_dir().join(format!("driftless-plot-ext-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fig = Figure::single(allan_like());
    for name in ["x.jpg", "x.pdf", "x"] {
        let path = dir.join(name);
        let err = driftless::report::plot::write_figure(&fig, &path).unwrap_err();
        assert!(
            matches!(err, PlotError::UnsupportedFormat { .. }),
            "{name}: {err}"
        );
        assert!(err.to_string().contains(name), "{err}");
        assert!(!path.exists(), "{name} written");
    }
    let svg = dir.join("x.SVG");
    driftless::report::plot::write_figure(&fig, &svg).unwrap();
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
#[ignore = "writes /tmp/plot_allan_like.svg for viewing"]
fn plot_dump_allan_like() {
    std::fs::write(
        "/tmp/plot_allan_like.svg",
        render_svg(&Figure::single(allan_like())),
    )
    .unwrap();
}

#[test]
#[ignore = "writes /tmp/plot_edge_*.svg for viewing"]
fn plot_dump_edge_cases() {
    let one = LogLogPlot::new("single point", "x (s)", "y (m)").with_series(Series::new(
        "p",
        vec![3.0],
        vec![7.0],
    ));
    let huge = LogLogPlot::new("huge range", "x", "y").with_series(Series::new(
        "p",
        vec![1e-200, 1.0, 1e200],
        vec![1e-250, 1.0, 1e250],
    ));
    let fig = Figure::grid(vec![one, huge], 2);
    std::fs::write("/tmp/plot_edge.svg", render_svg(&fig)).unwrap();
}

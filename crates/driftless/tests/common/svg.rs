//! Reading back the SVG that `report::plot` writes (one element per line, plain
//! attributes), so tests can measure geometry: rects, texts, polylines and panel frames.
//! Included with `#[path]` by the plot tests.
#![allow(dead_code)] // each test file uses a different subset

use driftless::report::plot::Color;

/// Numeric attribute `name` of one element line.
pub fn attr(line: &str, name: &str) -> f64 {
    let key = format!(" {name}=\"");
    let i = line
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {line}"))
        + key.len();
    line[i..]
        .split('"')
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{name} not a number in {line}"))
}

/// `(x, y, w, h)` of every `<rect>` filled with `color`.
pub fn rects(svg: &str, color: Color) -> Vec<(f64, f64, f64, f64)> {
    let fill = format!("fill=\"{}\"", color.to_hex());
    svg.lines()
        .filter(|l| l.starts_with("<rect") && l.contains(&fill))
        .map(|l| {
            (
                attr(l, "x"),
                attr(l, "y"),
                attr(l, "width"),
                attr(l, "height"),
            )
        })
        .collect()
}

/// `(text, x, y)` of every `<text>`.
pub fn texts(svg: &str) -> Vec<(String, f64, f64)> {
    svg.lines()
        .filter(|l| l.starts_with("<text"))
        .map(|l| {
            let body = l
                .split_once('>')
                .map_or("", |(_, b)| b)
                .trim_end_matches("</text>");
            (body.to_owned(), attr(l, "x"), attr(l, "y"))
        })
        .collect()
}

/// Plot frames (unfilled stroked rects, one per panel), in drawing order.
pub fn frames(svg: &str) -> Vec<(f64, f64, f64, f64)> {
    svg.lines()
        .filter(|l| l.starts_with("<rect") && l.contains("fill=\"none\""))
        .map(|l| {
            (
                attr(l, "x"),
                attr(l, "y"),
                attr(l, "width"),
                attr(l, "height"),
            )
        })
        .collect()
}

/// Points of every `<polyline>` stroked with `color`.
pub fn polylines(svg: &str, color: Color) -> Vec<Vec<(f64, f64)>> {
    let stroke = format!("stroke=\"{}\"", color.to_hex());
    svg.lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&stroke))
        .map(polyline_points)
        .collect()
}

/// The points of one `<polyline>` element line.
pub fn polyline_points(line: &str) -> Vec<(f64, f64)> {
    line.split("points=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap_or("")
        .split(' ')
        .filter_map(|p| {
            let (a, b) = p.split_once(',')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .collect()
}

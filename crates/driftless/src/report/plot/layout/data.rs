//! The data of a panel: bars, bands, model lines, series with error bars and markers.

use crate::report::plot::figure::{
    AxisScale, Bars, Color, LineStyle, MARKER_CYCLE, MarkerShape, PALETTE, Plot, Series,
};
use crate::report::plot::geom::{Pt, Rect, clip_polygon, clip_polyline, clip_segment};
use crate::report::plot::scale::AxisMap;
use crate::report::plot::scene::{Anchor, Dash, Prim};
use crate::report::plot::text::{CAP_HEIGHT_EM, text_width};

use super::axes::{PanelGeom, bar_width};
use super::labels::Obstacles;
use super::legend::{LegendEntry, Sample};
use super::{BAND_OPACITY, BAR_TEXT_SIZE, MARKER_R, TEXT};

/// `v` to 3 significant digits without trailing zeros (`3.1`, `0.4`, `9800`;
/// scientific notation outside 10⁻³ … 10⁵).
pub(super) fn format_value(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".to_owned();
    }
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let d = (2 - a.log10().floor() as i32).clamp(0, 5) as usize;
    let mut s = format!("{v:.d$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    s
}

pub(super) fn dash_of(style: LineStyle) -> Dash {
    match style {
        LineStyle::Solid => Dash::Solid,
        LineStyle::Dashed => Dash::Pattern(7.0, 4.0),
        LineStyle::Dotted => Dash::Pattern(1.5, 3.0),
    }
}

/// The model / asymptote lines clipped to the plot area; returns each line's runs.
pub(super) fn draw_lines(
    plot: &Plot,
    g: &PanelGeom,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) -> Vec<Vec<Vec<Pt>>> {
    let mut line_runs = Vec::with_capacity(plot.lines.len());
    for line in &plot.lines {
        let pts: Vec<Option<Pt>> = line
            .x
            .iter()
            .zip(&line.y)
            .map(|(&x, &y)| g.map(x, y))
            .collect();
        let runs = clip_polyline(&pts, &g.area);
        let color = line.color.unwrap_or(Color::DARK_GREY);
        let width = line
            .width
            .filter(|w| w.is_finite() && *w > 0.0)
            .unwrap_or(1.5)
            .min(12.0);
        for r in &runs {
            items.push(Prim::Path {
                pts: r.clone(),
                color,
                width,
                dash: dash_of(line.style),
                opacity: 1.0,
            });
        }
        if line.style == LineStyle::Solid {
            obstacles.add_runs(&runs);
        } else {
            obstacles.add_guide_runs(&runs);
        }
        line_runs.push(runs);
    }
    line_runs
}

/// One series: band, connecting line, error bars and markers; returns its legend entry
/// when it is named.
pub(super) fn draw_series(
    plot: &Plot,
    si: usize,
    s: &Series,
    g: &PanelGeom,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) -> Option<LegendEntry> {
    let area = &g.area;
    let color = s.color.unwrap_or(PALETTE[si % PALETTE.len()]);
    let shape = s.marker.unwrap_or(MARKER_CYCLE[si % MARKER_CYCLE.len()]);
    let pts: Vec<Option<Pt>> = s.x.iter().zip(&s.y).map(|(&x, &y)| g.map(x, y)).collect();
    if s.band {
        push_band(s, &g.xm, &g.ym, area, color, items);
    }
    if s.connect {
        let runs = clip_polyline(&pts, area);
        for r in &runs {
            items.push(Prim::Path {
                pts: r.clone(),
                color,
                width: 1.2,
                dash: Dash::Solid,
                opacity: 0.7,
            });
        }
        obstacles.add_runs(&runs);
    }
    if !s.band && (s.y_lo.is_some() || s.y_hi.is_some()) {
        draw_error_bars(plot, s, &pts, color, g, obstacles, items);
    }
    if shape != MarkerShape::None {
        for p in pts.iter().flatten() {
            if area.inflate(0.5).contains(*p) {
                items.push(Prim::Marker {
                    at: *p,
                    shape,
                    r: MARKER_R,
                    color,
                    filled: true,
                });
                obstacles.points.push(*p);
            }
        }
    }
    (!s.name.trim().is_empty()).then(|| LegendEntry {
        label: s.name.trim().to_owned(),
        color,
        sample: Sample::Series {
            shape,
            connect: s.connect,
            band: s.band && s.y_lo.is_some() && s.y_hi.is_some(),
        },
    })
}

/// Vertical error bars from `y_lo` to `y_hi` at each shown point, capped where they end
/// inside the plot area (an infinite or, on a log axis, non-positive end runs off it).
pub(super) fn draw_error_bars(
    plot: &Plot,
    s: &Series,
    pts: &[Option<Pt>],
    color: Color,
    g: &PanelGeom,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) {
    let (area, ym) = (&g.area, &g.ym);
    for (i, p) in pts.iter().enumerate() {
        let Some(p) = *p else { continue };
        let log_y = plot.y_scale == AxisScale::Log;
        let end = |b: &Option<Vec<f64>>, beyond: f64| -> f64 {
            match b.as_ref().and_then(|v| v.get(i)).copied() {
                Some(v) if ym.accepts(v) => ym.px(v).unwrap_or(p.1),
                Some(v) if log_y && v <= 0.0 => beyond, // −∞ on a log axis
                Some(v) if v == f64::NEG_INFINITY => area.bottom() + 1.0,
                Some(v) if v == f64::INFINITY => area.y - 1.0,
                _ => p.1,
            }
        };
        let (y0, y1) = (
            end(&s.y_lo, area.bottom() + 1.0),
            end(&s.y_hi, area.y - 1.0),
        );
        if (y0 - y1).abs() < 0.5 {
            continue;
        }
        let Some((a, b)) = clip_segment((p.0, y0), (p.0, y1), area) else {
            continue;
        };
        items.push(Prim::Path {
            pts: vec![a, b],
            color,
            width: 1.1,
            dash: Dash::Solid,
            opacity: 1.0,
        });
        for (end_pt, orig) in [(a, y0), (b, y1)] {
            if (end_pt.1 - orig).abs() < 1e-6 {
                items.push(Prim::Path {
                    pts: vec![(p.0 - 3.0, end_pt.1), (p.0 + 3.0, end_pt.1)],
                    color,
                    width: 1.1,
                    dash: Dash::Solid,
                    opacity: 1.0,
                });
            }
        }
        obstacles.guides.push((a, b));
    }
}

/// The bars of `b` clipped to `area`, their value labels and missing-value
/// notes; every drawn box becomes an obstacle for the legend and labels.
pub(super) fn push_bars(
    b: &Bars,
    color: Color,
    xm: &AxisMap,
    ym: &AxisMap,
    area: &Rect,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) {
    let w = bar_width(b);
    let base = match ym.scale {
        AxisScale::Linear => ym
            .px(0.0)
            .map_or(area.bottom(), |p| p.clamp(area.y, area.bottom())),
        AxisScale::Log => area.bottom(),
    };
    let missing = b
        .missing_label
        .as_deref()
        .map(str::trim)
        .filter(|m| !m.is_empty());
    let cap = BAR_TEXT_SIZE * CAP_HEIGHT_EM;
    for (&x, &y) in b.x.iter().zip(&b.y) {
        let (Some(a), Some(c)) = (xm.px(x - w / 2.0), xm.px(x + w / 2.0)) else {
            continue;
        };
        let (x0, x1) = (a.min(c).max(area.x), a.max(c).min(area.right()));
        if x1 - x0 < 0.5 {
            continue;
        }
        let mid = 0.5 * (x0 + x1);
        let Some(py) = ym.px(y) else {
            if let Some(m) = missing {
                // Just above the baseline (below it for a baseline at the top).
                let at_y = if base - cap - 4.0 > area.y {
                    base - 4.0
                } else {
                    base + cap + 4.0
                };
                items.push(Prim::Text {
                    at: (mid, at_y),
                    text: m.to_owned(),
                    size: BAR_TEXT_SIZE,
                    color: TEXT,
                    anchor: Anchor::Middle,
                    vertical: false,
                    bold: false,
                });
                let tw = text_width(m, BAR_TEXT_SIZE);
                obstacles
                    .boxes
                    .push(Rect::new(mid - tw / 2.0, at_y - cap, tw, cap));
            }
            continue;
        };
        let py = py.clamp(area.y, area.bottom());
        let (y0, y1) = (py.min(base), py.max(base));
        if y1 - y0 > 0.0 {
            items.push(Prim::Rect {
                x: x0,
                y: y0,
                w: x1 - x0,
                h: y1 - y0,
                fill: Some((color, 1.0)),
                stroke: None,
            });
            obstacles.boxes.push(Rect::new(x0, y0, x1 - x0, y1 - y0));
        }
        if b.value_labels {
            let t = format_value(y);
            let tw = text_width(&t, BAR_TEXT_SIZE);
            if tw > (x1 - x0) * 1.4 + 2.0 {
                continue;
            }
            // Beyond the bar's end, or inside it (white) when that is off the area.
            let upward = py <= base;
            let outside = if upward { py - 3.0 } else { py + 3.0 + cap };
            let fits = if upward {
                outside - cap >= area.y
            } else {
                outside <= area.bottom()
            };
            let (at_y, fg) = if fits {
                (outside, TEXT)
            } else if upward {
                (py + 3.0 + cap, Color::WHITE)
            } else {
                (py - 3.0, Color::WHITE)
            };
            items.push(Prim::Text {
                at: (mid, at_y),
                text: t,
                size: BAR_TEXT_SIZE,
                color: fg,
                anchor: Anchor::Middle,
                vertical: false,
                bold: false,
            });
            obstacles
                .boxes
                .push(Rect::new(mid - tw / 2.0, at_y - cap, tw, cap));
        }
    }
}

/// The shaded CI band of a series: one polygon per run of consecutive points
/// whose x, `y_lo` and `y_hi` are all shown by the axes, clipped to `area`.
pub(super) fn push_band(
    s: &Series,
    xm: &AxisMap,
    ym: &AxisMap,
    area: &Rect,
    color: Color,
    items: &mut Vec<Prim>,
) {
    let (Some(lo), Some(hi)) = (&s.y_lo, &s.y_hi) else {
        return;
    };
    let mut runs: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new()];
    for ((&x, &l), &h) in s.x.iter().zip(lo).zip(hi) {
        // Far-off vertices are pulled in so the clip arithmetic stays finite.
        let (bx, by) = (
            area.x - 1e7..=area.right() + 1e7,
            area.y - 1e7..=area.bottom() + 1e7,
        );
        let cx = |v: f64| v.clamp(*bx.start(), *bx.end());
        let cy = |v: f64| v.clamp(*by.start(), *by.end());
        match (xm.px(x), ym.px(l), ym.px(h)) {
            (Some(px), Some(pl), Some(ph)) if !(px + pl + ph).is_nan() => {
                if let Some(r) = runs.last_mut() {
                    r.push((cx(px), cy(pl), cy(ph)));
                }
            }
            _ => runs.push(Vec::new()),
        }
    }
    for run in runs.iter().filter(|r| r.len() >= 2) {
        let poly: Vec<Pt> = run
            .iter()
            .map(|&(x, _, h)| (x, h))
            .chain(run.iter().rev().map(|&(x, l, _)| (x, l)))
            .collect();
        let poly = clip_polygon(&poly, area);
        if !poly.is_empty() {
            items.push(Prim::Polygon {
                pts: poly,
                color,
                opacity: BAND_OPACITY,
            });
        }
    }
}

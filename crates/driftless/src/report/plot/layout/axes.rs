//! A panel's geometry and axes: data ranges, margins, axis maps, ticks, grid, frame and
//! titles.

use crate::report::plot::figure::{AxisScale, Bars, Color, Plot};
use crate::report::plot::geom::{Pt, Rect};
use crate::report::plot::scale::{
    AxisMap, Tick, explicit_linear_range, explicit_range, linear_extent, linear_padded_range,
    linear_ticks, log_extent, log_ticks, padded_range,
};
use crate::report::plot::scene::{Anchor, Dash, Prim};
use crate::report::plot::text::{CAP_HEIGHT_EM, DESCENT_EM, text_width};

use super::{
    AXIS_TITLE_SIZE, FRAME, GRID_MAJOR, GRID_MINOR, LOG_BAR_FOOT, MAJOR_TICK, MINOR_TICK, TEXT,
    TICK_SIZE, TITLE_SIZE, fit_text, text,
};

/// Whether an axis of this scale can show `v`.
pub(super) fn valid(scale: AxisScale, v: f64) -> bool {
    match scale {
        AxisScale::Log => v.is_finite() && v > 0.0,
        AxisScale::Linear => v.is_finite(),
    }
}

/// Displayed ranges `(x, y)` of a panel, in axis coordinates (log10 units on
/// a log axis, data units on a linear one).
pub(super) fn panel_ranges(plot: &Plot) -> ((f64, f64), (f64, f64)) {
    let vx = |v| valid(plot.x_scale, v);
    let vy = |v| valid(plot.y_scale, v);
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for s in &plot.series {
        for (i, (&x, &y)) in s.x.iter().zip(&s.y).enumerate() {
            if vx(x) && vy(y) {
                xs.push(x);
                ys.push(y);
                for b in [&s.y_lo, &s.y_hi].into_iter().flatten() {
                    if let Some(&v) = b.get(i) {
                        ys.push(v);
                    }
                }
            }
        }
    }
    // Bars: the x extent of every slot (shown or not), the tops, and on a
    // linear y axis the baseline 0.
    let mut bar_min_log: Option<f64> = None;
    for b in &plot.bars {
        let w = bar_width(b);
        for (&x, &y) in b.x.iter().zip(&b.y) {
            if !vx(x) {
                continue;
            }
            xs.extend([x - w / 2.0, x + w / 2.0].into_iter().filter(|&e| vx(e)));
            if vy(y) {
                ys.push(y);
                if plot.y_scale == AxisScale::Log {
                    let l = y.log10();
                    bar_min_log = Some(bar_min_log.map_or(l, |m: f64| m.min(l)));
                }
            }
            if plot.y_scale == AxisScale::Linear {
                ys.push(0.0);
            }
        }
    }
    if xs.is_empty() {
        for l in &plot.lines {
            for (&x, &y) in l.x.iter().zip(&l.y) {
                if vx(x) && vy(y) {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
    }
    let fit = |scale: AxisScale, explicit: Option<(f64, f64)>, vals: Vec<f64>| match scale {
        AxisScale::Log => explicit
            .and_then(explicit_range)
            .or_else(|| log_extent(vals).map(|(a, b)| padded_range(a, b)))
            .unwrap_or((0.0, 1.0)),
        AxisScale::Linear => explicit
            .and_then(explicit_linear_range)
            .or_else(|| linear_extent(vals).map(|(a, b)| linear_padded_range(a, b)))
            .unwrap_or((0.0, 1.0)),
    };
    let xr = fit(plot.x_scale, plot.x_range, xs);
    let mut yr = fit(plot.y_scale, plot.y_range, ys);
    if let (Some(m), None) = (bar_min_log, plot.y_range) {
        yr.0 = yr.0.min(m - LOG_BAR_FOOT);
    }
    (xr, yr)
}

/// Width of each bar of `b` in x data units (see [`Bars::width`]).
pub(super) fn bar_width(b: &Bars) -> f64 {
    if b.width.is_finite() && b.width > 0.0 {
        return b.width;
    }
    let mut xs: Vec<f64> = b.x.iter().copied().filter(|x| x.is_finite()).collect();
    xs.sort_by(f64::total_cmp);
    let gap = xs
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if gap.is_finite() { 0.8 * gap } else { 0.8 }
}

/// Ranges `(x, y)` widened about their centres so that one data unit spans
/// as many pixels on both axes, for a plot area of `w` × `h` px.
pub(super) fn equalize(xr: (f64, f64), yr: (f64, f64), w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
    let (sx, sy) = ((xr.1 - xr.0) / w, (yr.1 - yr.0) / h);
    let s = sx.max(sy);
    if !(s.is_finite() && s > 0.0 && w > 0.0 && h > 0.0) {
        return (xr, yr);
    }
    let (cx, cy) = (0.5 * (xr.0 + xr.1), 0.5 * (yr.0 + yr.1));
    (
        (cx - s * w / 2.0, cx + s * w / 2.0),
        (cy - s * h / 2.0, cy + s * h / 2.0),
    )
}

/// Explicit x ticks (categories): labelled major ticks at the given positions,
/// every n-th label kept when neighbours would collide.
pub(super) fn category_ticks(ticks: &[(f64, String)], xm: &AxisMap) -> Vec<Tick> {
    let mut out: Vec<(f64, Tick)> = ticks
        .iter()
        .filter_map(|(v, label)| {
            let px = xm.px(*v)?;
            let log = match xm.scale {
                AxisScale::Log => v.log10(),
                AxisScale::Linear => *v,
            };
            let label = label.trim();
            Some((
                px,
                Tick {
                    value: *v,
                    log,
                    major: true,
                    label: (!label.is_empty()).then(|| label.to_owned()),
                },
            ))
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    let widest = out
        .iter()
        .filter_map(|(_, t)| t.label.as_deref())
        .map(|l| text_width(l, TICK_SIZE))
        .fold(0.0, f64::max);
    let spacing = out
        .windows(2)
        .map(|w| w[1].0 - w[0].0)
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let step = if spacing.is_finite() {
        ((widest + 8.0) / spacing).ceil().max(1.0) as usize
    } else {
        1
    };
    out.into_iter()
        .enumerate()
        .map(|(i, (_, mut t))| {
            if i % step != 0 {
                t.label = None;
            }
            t
        })
        .collect()
}

/// Ticks for an axis, with the label gap widened until labels fit.
pub(super) fn axis_ticks(
    scale: AxisScale,
    range: (f64, f64),
    len: f64,
    horizontal: bool,
) -> Vec<Tick> {
    let ticks_fn = match scale {
        AxisScale::Log => log_ticks,
        AxisScale::Linear => linear_ticks,
    };
    let min_gap = if horizontal { 40.0 } else { TICK_SIZE * 1.8 };
    let mut ticks = ticks_fn(range.0, range.1, len, min_gap);
    if horizontal {
        let widest = ticks
            .iter()
            .filter_map(|t| t.label.as_deref())
            .map(|l| text_width(l, TICK_SIZE))
            .fold(0.0, f64::max);
        if widest + 12.0 > min_gap {
            ticks = ticks_fn(range.0, range.1, len, widest + 12.0);
        }
    }
    ticks
}

/// Where a panel's plot area lies in its cell, how data map onto it, and its ticks.
pub(super) struct PanelGeom {
    pub(super) area: Rect,
    pub(super) left: f64,
    pub(super) right: f64,
    pub(super) top: f64,
    pub(super) bottom: f64,
    pub(super) plot_w: f64,
    pub(super) plot_h: f64,
    /// Baseline of the x tick labels below the plot area.
    pub(super) tick_label_base: f64,
    /// Baseline of the x axis title below the plot area.
    pub(super) x_title_base: f64,
    /// x of the (vertical) y axis title.
    pub(super) y_title_x: f64,
    pub(super) xm: AxisMap,
    pub(super) ym: AxisMap,
    pub(super) x_ticks: Vec<Tick>,
    pub(super) y_ticks: Vec<Tick>,
    /// The x axis holds categories (no vertical grid lines).
    pub(super) category_x: bool,
}

impl PanelGeom {
    /// Margins from the titles and tick labels (the y tick labels set the left margin,
    /// which sets the plot width), the data ranges (equalised for an equal aspect), the
    /// axis maps and ticks.
    pub(super) fn new(plot: &Plot, cell: Rect) -> Self {
        let title = plot.title.trim();
        let x_title = plot.x_label.trim();
        let y_title = plot.y_label.trim();

        // Vertical budget.
        let title_band = if title.is_empty() {
            0.0
        } else {
            TITLE_SIZE + 12.0
        };
        let top = cell.y + 14.0 + title_band;
        let tick_label_base = MAJOR_TICK + 4.0 + TICK_SIZE * CAP_HEIGHT_EM + 1.0;
        let x_title_base = tick_label_base + TICK_SIZE * DESCENT_EM + 8.0 + AXIS_TITLE_SIZE * 0.76;
        let bottom_margin = if x_title.is_empty() {
            tick_label_base + 10.0
        } else {
            x_title_base + AXIS_TITLE_SIZE * DESCENT_EM + 8.0
        };
        let bottom = (cell.bottom() - bottom_margin).max(top + 20.0);
        let plot_h = bottom - top;

        let (mut xr, mut yr) = panel_ranges(plot);
        let y_title_x = cell.x + 10.0 + AXIS_TITLE_SIZE * 0.78;
        // The y tick labels set the left margin, which sets the plot width.
        let y_side = |yr: (f64, f64)| {
            let ticks = axis_ticks(plot.y_scale, yr, plot_h, false);
            let ytick_w = ticks
                .iter()
                .filter_map(|t| t.label.as_deref())
                .map(|l| text_width(l, TICK_SIZE))
                .fold(0.0, f64::max);
            let left = if y_title.is_empty() {
                cell.x + 12.0 + ytick_w + MAJOR_TICK + 4.0
            } else {
                y_title_x + AXIS_TITLE_SIZE * DESCENT_EM + 8.0 + ytick_w + MAJOR_TICK + 4.0
            };
            (ticks, left)
        };
        let width_from = |left: f64| (cell.right() - 24.0).max(left + 20.0) - left;
        let (mut y_ticks, mut left) = y_side(yr);
        let linear = plot.x_scale == AxisScale::Linear && plot.y_scale == AxisScale::Linear;
        if plot.equal_aspect && linear {
            // Widening y can widen its labels and so narrow the plot: iterate
            // until the y range stops changing, then match x to the final width.
            let (xr0, yr0) = (xr, yr);
            for _ in 0..4 {
                let (_, ny) = equalize(xr0, yr0, width_from(left), plot_h);
                if ny == yr {
                    break;
                }
                yr = ny;
                (y_ticks, left) = y_side(yr);
            }
            let per_px = (yr.1 - yr.0) / plot_h;
            let cx = 0.5 * (xr0.0 + xr0.1);
            let half = 0.5 * per_px * width_from(left);
            if half.is_finite() && half > 0.0 {
                xr = (cx - half, cx + half);
            }
        }
        let right = (cell.right() - 24.0).max(left + 20.0);
        let plot_w = right - left;

        let area = Rect::new(left, top, plot_w, plot_h);
        let xm = AxisMap {
            scale: plot.x_scale,
            lo: xr.0,
            hi: xr.1,
            p0: left,
            p1: right,
        };
        let ym = AxisMap {
            scale: plot.y_scale,
            lo: yr.0,
            hi: yr.1,
            p0: bottom,
            p1: top,
        };
        let x_ticks = match &plot.x_tick_labels {
            Some(t) => category_ticks(t, &xm),
            None => axis_ticks(plot.x_scale, xr, plot_w, true),
        };
        PanelGeom {
            area,
            left,
            right,
            top,
            bottom,
            plot_w,
            plot_h,
            tick_label_base,
            x_title_base,
            y_title_x,
            xm,
            ym,
            x_ticks,
            y_ticks,
            category_x: plot.x_tick_labels.is_some(),
        }
    }

    /// A data point in pixels (`None` where an axis cannot show it).
    pub(super) fn map(&self, x: f64, y: f64) -> Option<Pt> {
        Some((self.xm.px(x)?, self.ym.px(y)?))
    }
}

/// Plot background and grid (minor first so major lines sit on top).
pub(super) fn draw_grid(g: &PanelGeom, items: &mut Vec<Prim>) {
    let (area, left, right, top, bottom) = (&g.area, g.left, g.right, g.top, g.bottom);
    items.push(Prim::Rect {
        x: area.x,
        y: area.y,
        w: area.w,
        h: area.h,
        fill: Some((Color::WHITE, 1.0)),
        stroke: None,
    });
    for major in [false, true] {
        let color = if major { GRID_MAJOR } else { GRID_MINOR };
        for t in g
            .x_ticks
            .iter()
            .filter(|t| t.major == major && !g.category_x)
        {
            let x = g.xm.px_log(t.log);
            if x >= left - 0.01 && x <= right + 0.01 {
                items.push(grid_line((x, top), (x, bottom), color));
            }
        }
        for t in g.y_ticks.iter().filter(|t| t.major == major) {
            let y = g.ym.px_log(t.log);
            if y >= top - 0.01 && y <= bottom + 0.01 {
                items.push(grid_line((left, y), (right, y), color));
            }
        }
    }
}

/// Frame, ticks and tick labels.
pub(super) fn draw_frame_and_ticks(g: &PanelGeom, items: &mut Vec<Prim>) {
    let (area, left, right, top, bottom) = (&g.area, g.left, g.right, g.top, g.bottom);
    items.push(Prim::Rect {
        x: area.x,
        y: area.y,
        w: area.w,
        h: area.h,
        fill: None,
        stroke: Some((FRAME, 1.0)),
    });
    for t in &g.x_ticks {
        let x = g.xm.px_log(t.log);
        if x < left - 0.01 || x > right + 0.01 {
            continue;
        }
        let len = if t.major { MAJOR_TICK } else { MINOR_TICK };
        items.push(tick_line((x, bottom), (x, bottom + len)));
        if let Some(l) = &t.label {
            items.push(text(
                (x, bottom + g.tick_label_base),
                l,
                TICK_SIZE,
                Anchor::Middle,
                false,
            ));
        }
    }
    for t in &g.y_ticks {
        let y = g.ym.px_log(t.log);
        if y < top - 0.01 || y > bottom + 0.01 {
            continue;
        }
        let len = if t.major { MAJOR_TICK } else { MINOR_TICK };
        items.push(tick_line((left - len, y), (left, y)));
        if let Some(l) = &t.label {
            let at = (left - MAJOR_TICK - 4.0, y + TICK_SIZE * CAP_HEIGHT_EM / 2.0);
            items.push(text(at, l, TICK_SIZE, Anchor::End, false));
        }
    }
}

/// The axis titles and the panel title.
pub(super) fn draw_titles(plot: &Plot, cell: Rect, g: &PanelGeom, items: &mut Vec<Prim>) {
    let title = plot.title.trim();
    let x_title = plot.x_label.trim();
    let y_title = plot.y_label.trim();
    let (left, top, bottom, plot_w, plot_h) = (g.left, g.top, g.bottom, g.plot_w, g.plot_h);
    if !x_title.is_empty() {
        let t = fit_text(x_title, AXIS_TITLE_SIZE, cell.w - 20.0);
        let at = (left + plot_w / 2.0, bottom + g.x_title_base);
        items.push(text(at, &t, AXIS_TITLE_SIZE, Anchor::Middle, false));
    }
    if !y_title.is_empty() {
        let t = fit_text(y_title, AXIS_TITLE_SIZE, plot_h + 20.0);
        items.push(Prim::Text {
            at: (g.y_title_x, top + plot_h / 2.0),
            text: t,
            size: AXIS_TITLE_SIZE,
            color: TEXT,
            anchor: Anchor::Middle,
            vertical: true,
            bold: false,
        });
    }
    if !title.is_empty() {
        let t = fit_text(title, TITLE_SIZE, cell.w - 20.0);
        let at = (
            left + plot_w / 2.0,
            cell.y + 12.0 + TITLE_SIZE * CAP_HEIGHT_EM + 2.0,
        );
        items.push(text(at, &t, TITLE_SIZE, Anchor::Middle, true));
    }
}

pub(super) fn grid_line(a: Pt, b: Pt, color: Color) -> Prim {
    Prim::Path {
        pts: vec![a, b],
        color,
        width: 0.8,
        dash: Dash::Solid,
        opacity: 1.0,
    }
}

pub(super) fn tick_line(a: Pt, b: Pt) -> Prim {
    Prim::Path {
        pts: vec![a, b],
        color: FRAME,
        width: 1.0,
        dash: Dash::Solid,
        opacity: 1.0,
    }
}

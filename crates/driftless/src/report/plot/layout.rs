//! Figure → [`Scene`]: margins, axes, ticks, data, legend and label placement.

use super::figure::{
    AxisScale, Bars, Color, DEFAULT_PANEL_SIZE, Figure, LegendPosition, LineStyle, MARKER_CYCLE,
    MarkerShape, PALETTE, Plot, Series,
};
use super::geom::{Pt, Rect, clip_polygon, clip_polyline, clip_segment, segment_hits_rect};
use super::scale::{
    AxisMap, Tick, explicit_linear_range, explicit_range, linear_extent, linear_padded_range,
    linear_ticks, log_extent, log_ticks, padded_range,
};
use super::scene::{Anchor, Dash, Prim, Scene};
use super::text::{CAP_HEIGHT_EM, DESCENT_EM, text_width};

const FIG_TITLE_SIZE: f64 = 17.0;
const TITLE_SIZE: f64 = 15.0;
const AXIS_TITLE_SIZE: f64 = 13.5;
const TICK_SIZE: f64 = 12.5;
const LEGEND_SIZE: f64 = 12.0;
const LABEL_SIZE: f64 = 12.0;
/// Bar value labels and "missing value" notes.
const BAR_TEXT_SIZE: f64 = 11.0;
/// How far below the smallest bar a log y axis starts (decades), so that the
/// smallest bar is still a visible bar and not a sliver.
const LOG_BAR_FOOT: f64 = 0.3;

const TEXT: Color = Color::rgb(0x1f, 0x1f, 0x1f);
const FRAME: Color = Color::rgb(0x40, 0x40, 0x40);
const GRID_MAJOR: Color = Color::rgb(0xcf, 0xcf, 0xcf);
const GRID_MINOR: Color = Color::rgb(0xeb, 0xeb, 0xeb);
const LEGEND_BORDER: Color = Color::rgb(0xb0, 0xb0, 0xb0);

const MAJOR_TICK: f64 = 5.0;
const MINOR_TICK: f64 = 3.0;
const MARKER_R: f64 = 3.6;
/// Fill opacity of a series' confidence band.
const BAND_OPACITY: f64 = 0.18;
/// Upper bound on obstacle primitives considered by label placement, so huge
/// series do not make layout quadratic.
const MAX_OBSTACLES: usize = 4000;

/// Lays out the whole figure.
pub(crate) fn layout(fig: &Figure) -> Scene {
    let pw = sane_size(fig.panel_width, DEFAULT_PANEL_SIZE.0);
    let ph = sane_size(fig.panel_height, DEFAULT_PANEL_SIZE.1);
    let n = fig.panels.len();
    let cols = match (n, fig.columns) {
        (0, _) => 1,
        (_, 0) => n,
        (_, c) => c.min(n),
    };
    let rows = if n == 0 { 1 } else { n.div_ceil(cols) };
    let title = fig
        .title
        .as_deref()
        .map(str::trim)
        .filter(|t| !t.is_empty());
    let title_h = if title.is_some() { 38.0 } else { 0.0 };
    let width = pw * cols as f64;
    let height = ph * rows as f64 + title_h;

    let mut items = vec![Prim::Rect {
        x: 0.0,
        y: 0.0,
        w: width,
        h: height,
        fill: Some((Color::WHITE, 1.0)),
        stroke: None,
    }];
    if let Some(t) = title {
        items.push(text(
            (width / 2.0, 12.0 + FIG_TITLE_SIZE * CAP_HEIGHT_EM + 2.0),
            &fit_text(t, FIG_TITLE_SIZE, width - 20.0),
            FIG_TITLE_SIZE,
            Anchor::Middle,
            true,
        ));
    }
    if n == 0 {
        items.push(text(
            (width / 2.0, height / 2.0),
            "(no data)",
            TICK_SIZE,
            Anchor::Middle,
            false,
        ));
    }
    for (i, plot) in fig.panels.iter().enumerate() {
        let (r, c) = (i / cols, i % cols);
        let cell = Rect::new(c as f64 * pw, title_h + r as f64 * ph, pw, ph);
        layout_panel(plot, cell, &mut items);
    }
    Scene {
        width,
        height,
        title: title.map(str::to_owned),
        items,
    }
}

fn sane_size(v: f64, default: f64) -> f64 {
    if v.is_finite() && v >= 160.0 {
        v.min(10_000.0)
    } else {
        default
    }
}

fn text(at: Pt, s: &str, size: f64, anchor: Anchor, bold: bool) -> Prim {
    Prim::Text {
        at,
        text: s.to_owned(),
        size,
        color: TEXT,
        anchor,
        vertical: false,
        bold,
    }
}

/// `s` shortened with an ellipsis to fit `max_w` px.
fn fit_text(s: &str, size: f64, max_w: f64) -> String {
    if text_width(s, size) <= max_w {
        return s.to_owned();
    }
    let mut out = String::new();
    let budget = max_w - text_width("…", size);
    for c in s.chars() {
        out.push(c);
        if text_width(&out, size) > budget {
            out.pop();
            break;
        }
    }
    out.push('…');
    out
}

/// Whether an axis of this scale can show `v`.
fn valid(scale: AxisScale, v: f64) -> bool {
    match scale {
        AxisScale::Log => v.is_finite() && v > 0.0,
        AxisScale::Linear => v.is_finite(),
    }
}

/// Displayed ranges `(x, y)` of a panel, in axis coordinates (log10 units on
/// a log axis, data units on a linear one).
fn panel_ranges(plot: &Plot) -> ((f64, f64), (f64, f64)) {
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
fn bar_width(b: &Bars) -> f64 {
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
fn equalize(xr: (f64, f64), yr: (f64, f64), w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
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
fn category_ticks(ticks: &[(f64, String)], xm: &AxisMap) -> Vec<Tick> {
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

/// `v` to 3 significant digits without trailing zeros (`3.1`, `0.4`, `9800`;
/// scientific notation outside 10⁻³ … 10⁵).
fn format_value(v: f64) -> String {
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

/// Things that labels and the legend should not cover.
#[derive(Default)]
struct Obstacles {
    /// The curves themselves (series' connecting lines, solid lines such as a fitted
    /// model): a label crosses one only where no place is free of them.
    segments: Vec<(Pt, Pt)>,
    /// Guides (dashed or dotted reference lines such as asymptotes, error bars): better
    /// not covered, but a label may cross one rather than a curve.
    guides: Vec<(Pt, Pt)>,
    points: Vec<Pt>,
    boxes: Vec<Rect>,
}

/// Clutter score of a label crossing a curve segment: more than a label pushed off its
/// line to stay inside the plot area (500), less than covering another label or the
/// legend ([`BOX_HIT`]); a marker costs 40, a guide 25.
const CURVE_HIT: f64 = 600.0;
/// Clutter score of covering another label, the legend or a bar.
const BOX_HIT: f64 = 10_000.0;

impl Obstacles {
    fn add_runs(&mut self, runs: &[Vec<Pt>]) {
        for r in runs {
            for w in r.windows(2) {
                self.segments.push((w[0], w[1]));
            }
        }
    }

    fn add_guide_runs(&mut self, runs: &[Vec<Pt>]) {
        for r in runs {
            for w in r.windows(2) {
                self.guides.push((w[0], w[1]));
            }
        }
    }

    /// Thins segments and points to at most [`MAX_OBSTACLES`] each.
    fn decimate(&mut self) {
        fn thin<T: Copy>(v: &mut Vec<T>) {
            if v.len() > MAX_OBSTACLES {
                let step = v.len().div_ceil(MAX_OBSTACLES);
                *v = v.iter().step_by(step).copied().collect();
            }
        }
        thin(&mut self.segments);
        thin(&mut self.guides);
        thin(&mut self.points);
    }

    /// Clutter score of a rectangle (0 = free): hard penalties for covering
    /// boxes, lines and markers, soft ones for crowding them.
    fn score(&self, r: &Rect) -> f64 {
        let mut s = 0.0;
        let near = r.inflate(8.0);
        for b in &self.boxes {
            let a = r.overlap_area(b);
            if a > 0.0 {
                s += BOX_HIT + a;
            }
        }
        for (segments, hit) in [(&self.segments, CURVE_HIT), (&self.guides, 25.0)] {
            for &(a, b) in segments {
                if segment_hits_rect(a, b, r) {
                    s += hit;
                } else if segment_hits_rect(a, b, &near) {
                    s += 3.0;
                }
            }
        }
        let grown = r.inflate(MARKER_R);
        for &p in &self.points {
            if grown.contains(p) {
                s += 40.0;
            } else if near.contains(p) {
                s += 6.0;
            }
        }
        s
    }
}

fn dash_of(style: LineStyle) -> Dash {
    match style {
        LineStyle::Solid => Dash::Solid,
        LineStyle::Dashed => Dash::Pattern(7.0, 4.0),
        LineStyle::Dotted => Dash::Pattern(1.5, 3.0),
    }
}

/// Ticks for an axis, with the label gap widened until labels fit.
fn axis_ticks(scale: AxisScale, range: (f64, f64), len: f64, horizontal: bool) -> Vec<Tick> {
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

fn layout_panel(plot: &Plot, cell: Rect, items: &mut Vec<Prim>) {
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
    let map = |x: f64, y: f64| -> Option<Pt> { Some((xm.px(x)?, ym.px(y)?)) };
    let category_x = plot.x_tick_labels.is_some();
    let x_ticks = match &plot.x_tick_labels {
        Some(t) => category_ticks(t, &xm),
        None => axis_ticks(plot.x_scale, xr, plot_w, true),
    };

    // Plot background and grid (minor first so major lines sit on top).
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
        for t in x_ticks.iter().filter(|t| t.major == major && !category_x) {
            let x = xm.px_log(t.log);
            if x >= left - 0.01 && x <= right + 0.01 {
                items.push(grid_line((x, top), (x, bottom), color));
            }
        }
        for t in y_ticks.iter().filter(|t| t.major == major) {
            let y = ym.px_log(t.log);
            if y >= top - 0.01 && y <= bottom + 0.01 {
                items.push(grid_line((left, y), (right, y), color));
            }
        }
    }

    let mut obstacles = Obstacles::default();
    let mut legend_entries = Vec::new();

    // Bars (under lines and series).
    for (bi, b) in plot.bars.iter().enumerate() {
        let color = b
            .color
            .unwrap_or(PALETTE[(plot.series.len() + bi) % PALETTE.len()]);
        push_bars(b, color, &xm, &ym, &area, &mut obstacles, items);
        if !b.name.trim().is_empty() {
            legend_entries.push(LegendEntry {
                label: b.name.trim().to_owned(),
                color,
                sample: Sample::Bar,
            });
        }
    }

    // Model / asymptote lines (under the data).
    let mut line_runs = Vec::with_capacity(plot.lines.len());
    for line in &plot.lines {
        let pts: Vec<Option<Pt>> = line
            .x
            .iter()
            .zip(&line.y)
            .map(|(&x, &y)| map(x, y))
            .collect();
        let runs = clip_polyline(&pts, &area);
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

    // Series: connecting lines, error bars, markers.
    for (si, s) in plot.series.iter().enumerate() {
        let color = s.color.unwrap_or(PALETTE[si % PALETTE.len()]);
        let shape = s.marker.unwrap_or(MARKER_CYCLE[si % MARKER_CYCLE.len()]);
        let pts: Vec<Option<Pt>> = s.x.iter().zip(&s.y).map(|(&x, &y)| map(x, y)).collect();
        if s.band {
            push_band(s, &xm, &ym, &area, color, items);
        }
        if s.connect {
            let runs = clip_polyline(&pts, &area);
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
                let Some((a, b)) = clip_segment((p.0, y0), (p.0, y1), &area) else {
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
        if !s.name.trim().is_empty() {
            legend_entries.push(LegendEntry {
                label: s.name.trim().to_owned(),
                color,
                sample: Sample::Series {
                    shape,
                    connect: s.connect,
                    band: s.band && s.y_lo.is_some() && s.y_hi.is_some(),
                },
            });
        }
    }
    for (line, runs) in plot.lines.iter().zip(&line_runs) {
        if !line.name.trim().is_empty() && !runs.is_empty() {
            legend_entries.push(LegendEntry {
                label: line.name.trim().to_owned(),
                color: line.color.unwrap_or(Color::DARK_GREY),
                sample: Sample::Line {
                    dash: dash_of(line.style),
                    width: line
                        .width
                        .filter(|w| w.is_finite() && *w > 0.0)
                        .unwrap_or(1.5)
                        .clamp(1.0, 6.0),
                },
            });
        }
    }

    // Annotations.
    for a in &plot.annotations {
        let Some(p) = map(a.x, a.y).filter(|p| area.contains(*p)) else {
            continue;
        };
        let color = a.color.unwrap_or(TEXT);
        if a.marker {
            items.push(Prim::Marker {
                at: p,
                shape: MarkerShape::Circle,
                r: 6.0,
                color,
                filled: false,
            });
        }
        let t = a.text.trim();
        if t.is_empty() {
            continue;
        }
        let t = fit_text(t, LABEL_SIZE, area.w - 8.0);
        let r = place_annotation_label(&t, p, &area, &obstacles);
        push_label(items, &r, &t, color);
        obstacles.boxes.push(r);
    }
    obstacles.decimate();

    // Legend, then line labels around it.
    if plot.legend != LegendPosition::Hidden && !legend_entries.is_empty() {
        let r = draw_legend(&legend_entries, plot.legend, &area, &obstacles, items);
        obstacles.boxes.push(r);
    }
    for (line, runs) in plot.lines.iter().zip(&line_runs) {
        let Some(label) = line
            .label
            .as_deref()
            .map(str::trim)
            .filter(|l| !l.is_empty())
        else {
            continue;
        };
        let label = fit_text(label, LABEL_SIZE, area.w - 8.0);
        let pref = line.label_x.and_then(|x| xm.px(x));
        if let Some(r) = place_label(&label, runs, &area, &obstacles, pref) {
            push_label(items, &r, &label, line.color.unwrap_or(Color::DARK_GREY));
            obstacles.boxes.push(r);
        }
    }

    // Frame, ticks, tick labels.
    items.push(Prim::Rect {
        x: area.x,
        y: area.y,
        w: area.w,
        h: area.h,
        fill: None,
        stroke: Some((FRAME, 1.0)),
    });
    for t in &x_ticks {
        let x = xm.px_log(t.log);
        if x < left - 0.01 || x > right + 0.01 {
            continue;
        }
        let len = if t.major { MAJOR_TICK } else { MINOR_TICK };
        items.push(tick_line((x, bottom), (x, bottom + len)));
        if let Some(l) = &t.label {
            items.push(text(
                (x, bottom + tick_label_base),
                l,
                TICK_SIZE,
                Anchor::Middle,
                false,
            ));
        }
    }
    for t in &y_ticks {
        let y = ym.px_log(t.log);
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

    // Titles.
    if !x_title.is_empty() {
        let t = fit_text(x_title, AXIS_TITLE_SIZE, cell.w - 20.0);
        let at = (left + plot_w / 2.0, bottom + x_title_base);
        items.push(text(at, &t, AXIS_TITLE_SIZE, Anchor::Middle, false));
    }
    if !y_title.is_empty() {
        let t = fit_text(y_title, AXIS_TITLE_SIZE, plot_h + 20.0);
        items.push(Prim::Text {
            at: (y_title_x, top + plot_h / 2.0),
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

/// The bars of `b` clipped to `area`, their value labels and missing-value
/// notes; every drawn box becomes an obstacle for the legend and labels.
fn push_bars(
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
fn push_band(
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

fn grid_line(a: Pt, b: Pt, color: Color) -> Prim {
    Prim::Path {
        pts: vec![a, b],
        color,
        width: 0.8,
        dash: Dash::Solid,
        opacity: 1.0,
    }
}

fn tick_line(a: Pt, b: Pt) -> Prim {
    Prim::Path {
        pts: vec![a, b],
        color: FRAME,
        width: 1.0,
        dash: Dash::Solid,
        opacity: 1.0,
    }
}

/// Moves `r` inside `area` (as far as it fits).
fn clamp_into(mut r: Rect, area: &Rect) -> Rect {
    r.x = r.x.min(area.right() - 2.0 - r.w).max(area.x + 2.0);
    r.y = r.y.min(area.bottom() - 2.0 - r.h).max(area.y + 2.0);
    r
}

/// A text label on a translucent white box `r` (3 px padding).
fn push_label(items: &mut Vec<Prim>, r: &Rect, label: &str, color: Color) {
    items.push(Prim::Rect {
        x: r.x,
        y: r.y,
        w: r.w,
        h: r.h,
        fill: Some((Color::WHITE, 0.85)),
        stroke: None,
    });
    items.push(Prim::Text {
        at: (r.x + 3.0, r.y + 3.0 + LABEL_SIZE * 0.78),
        text: label.to_owned(),
        size: LABEL_SIZE,
        color,
        anchor: Anchor::Start,
        vertical: false,
        bold: false,
    });
}

/// Best box for `label` beside the visible runs of its line: candidates every
/// 1/48 of the visible length on both sides, scored by clutter (other
/// labels, the legend, lines, markers) and distance from the preferred x
/// (or from the middle of the visible part).
/// Box of an annotation's text next to its point `p`: of the positions around the point
/// (above/below × right/left, then further out) the one that covers the least of the
/// data, lines, legends and labels already placed ([`Obstacles::score`]), inside the
/// plot area; ties go to the first (above right).
fn place_annotation_label(text: &str, p: Pt, area: &Rect, obstacles: &Obstacles) -> Rect {
    let (w, h) = (text_width(text, LABEL_SIZE) + 6.0, LABEL_SIZE + 6.0);
    let inner = area.inflate(-2.0);
    let mut best: Option<(f64, Rect)> = None;
    for gap in [7.0, 16.0, 28.0, 44.0] {
        for (sx, sy) in [(1.0, -1.0), (-1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let x = if sx > 0.0 { p.0 + gap } else { p.0 - gap - w };
            let y = if sy < 0.0 { p.1 - gap - h } else { p.1 + gap };
            let mut r = Rect::new(x, y, w, h);
            let mut score = 0.1 * gap;
            if !inner.contains_rect(&r) {
                r = clamp_into(r, area);
                score += 500.0;
            }
            score += obstacles.score(&r);
            if best.is_none_or(|(b, _)| score < b) {
                best = Some((score, r));
            }
        }
    }
    best.map_or_else(
        || clamp_into(Rect::new(p.0 + 7.0, p.1 - 7.0 - h, w, h), area),
        |b| b.1,
    )
}

fn place_label(
    label: &str,
    runs: &[Vec<Pt>],
    area: &Rect,
    obstacles: &Obstacles,
    preferred_x: Option<f64>,
) -> Option<Rect> {
    let w = text_width(label, LABEL_SIZE) + 6.0;
    let h = LABEL_SIZE + 6.0;
    let segs: Vec<(Pt, Pt, f64)> = runs
        .iter()
        .flat_map(|r| r.windows(2))
        .map(|s| (s[0], s[1], (s[1].0 - s[0].0).hypot(s[1].1 - s[0].1)))
        .filter(|s| s.2 > 1e-9)
        .collect();
    let total: f64 = segs.iter().map(|s| s.2).sum();
    if total.is_nan() || total <= 1.0 {
        return None;
    }
    const N: usize = 48;
    const GAPS: [f64; 3] = [3.0, 14.0, 28.0];
    let inner = area.inflate(-2.0);
    let mut best: Option<(f64, Rect)> = None;
    let mut seg_i = 0;
    let mut acc = 0.0;
    for i in 0..N {
        let s = (i as f64 + 0.5) / N as f64 * total;
        while seg_i + 1 < segs.len() && acc + segs[seg_i].2 < s {
            acc += segs[seg_i].2;
            seg_i += 1;
        }
        let (a, b, len) = segs[seg_i];
        let t = ((s - acc) / len).clamp(0.0, 1.0);
        let p = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        let (dx, dy) = ((b.0 - a.0) / len, (b.1 - a.1) / len);
        // Beside the line, or further out where a curve runs beside it.
        for (side, gap) in [-1.0, 1.0].into_iter().flat_map(|s| GAPS.map(|g| (s, g))) {
            let n = (-dy * side, dx * side);
            let ext = n.0.abs() * w / 2.0 + n.1.abs() * h / 2.0;
            let c = (p.0 + n.0 * (gap + ext), p.1 + n.1 * (gap + ext));
            let mut r = Rect::new(c.0 - w / 2.0, c.1 - h / 2.0, w, h);
            let mut score = gap - GAPS[0];
            if !inner.contains_rect(&r) {
                r = clamp_into(r, area);
                score += 500.0;
            }
            score += obstacles.score(&r);
            score += match preferred_x {
                // The preferred place yields to any data it would cover (a marker costs
                // 40, as much as moving 400 px).
                Some(px) => 0.1 * (c.0 - px).abs(),
                None => 0.1 * (s - total / 2.0).abs(),
            };
            if best.is_none_or(|(bs, _)| score < bs) {
                best = Some((score, r));
            }
        }
    }
    best.map(|(_, r)| r)
}

enum Sample {
    Series {
        shape: MarkerShape,
        connect: bool,
        band: bool,
    },
    Line {
        dash: Dash,
        width: f64,
    },
    Bar,
}

struct LegendEntry {
    label: String,
    color: Color,
    sample: Sample,
}

const LEGEND_ROW: f64 = 18.0;
const LEGEND_PAD: f64 = 8.0;
const LEGEND_SAMPLE: f64 = 26.0;

fn draw_legend(
    entries: &[LegendEntry],
    pos: LegendPosition,
    area: &Rect,
    obstacles: &Obstacles,
    items: &mut Vec<Prim>,
) -> Rect {
    let max_text = (area.w * 0.5).max(60.0);
    let labels: Vec<String> = entries
        .iter()
        .map(|e| fit_text(&e.label, LEGEND_SIZE, max_text))
        .collect();
    let text_w = labels
        .iter()
        .map(|l| text_width(l, LEGEND_SIZE))
        .fold(0.0, f64::max);
    let w = LEGEND_PAD * 2.0 + LEGEND_SAMPLE + 6.0 + text_w;
    let h = 8.0 + LEGEND_ROW * entries.len() as f64;
    let inset = 8.0;
    let (l, r) = (area.x + inset, area.right() - inset - w);
    let (t, b) = (area.y + inset, area.bottom() - inset - h);
    let corner = |p: LegendPosition| match p {
        LegendPosition::TopLeft => Rect::new(l, t, w, h),
        LegendPosition::BottomLeft => Rect::new(l, b, w, h),
        LegendPosition::BottomRight => Rect::new(r, b, w, h),
        _ => Rect::new(r, t, w, h),
    };
    let rect = if pos == LegendPosition::Auto {
        let order = [
            LegendPosition::TopRight,
            LegendPosition::BottomLeft,
            LegendPosition::TopLeft,
            LegendPosition::BottomRight,
        ];
        let mut best = (f64::INFINITY, corner(LegendPosition::TopRight));
        for p in order {
            let c = corner(p);
            let s = obstacles.score(&c);
            if s < best.0 {
                best = (s, c);
            }
        }
        best.1
    } else {
        corner(pos)
    };
    items.push(Prim::Rect {
        x: rect.x,
        y: rect.y,
        w: rect.w,
        h: rect.h,
        fill: Some((Color::WHITE, 0.92)),
        stroke: Some((LEGEND_BORDER, 0.8)),
    });
    for (i, (e, label)) in entries.iter().zip(&labels).enumerate() {
        let cy = rect.y + 4.0 + LEGEND_ROW * (i as f64 + 0.5);
        let x0 = rect.x + LEGEND_PAD;
        let mid = (x0 + LEGEND_SAMPLE / 2.0, cy);
        match e.sample {
            Sample::Series {
                shape,
                connect,
                band,
            } => {
                if band {
                    items.push(Prim::Rect {
                        x: x0,
                        y: cy - 5.0,
                        w: LEGEND_SAMPLE,
                        h: 10.0,
                        fill: Some((e.color, BAND_OPACITY)),
                        stroke: None,
                    });
                }
                if connect {
                    items.push(Prim::Path {
                        pts: vec![(x0, cy), (x0 + LEGEND_SAMPLE, cy)],
                        color: e.color,
                        width: 1.2,
                        dash: Dash::Solid,
                        opacity: 0.7,
                    });
                }
                if shape != MarkerShape::None {
                    items.push(Prim::Marker {
                        at: mid,
                        shape,
                        r: MARKER_R,
                        color: e.color,
                        filled: true,
                    });
                }
            }
            Sample::Line { dash, width } => items.push(Prim::Path {
                pts: vec![(x0, cy), (x0 + LEGEND_SAMPLE, cy)],
                color: e.color,
                width,
                dash,
                opacity: 1.0,
            }),
            Sample::Bar => items.push(Prim::Rect {
                x: x0 + LEGEND_SAMPLE / 2.0 - 7.0,
                y: cy - 6.0,
                w: 14.0,
                h: 12.0,
                fill: Some((e.color, 1.0)),
                stroke: None,
            }),
        }
        items.push(Prim::Text {
            at: (
                x0 + LEGEND_SAMPLE + 6.0,
                cy + LEGEND_SIZE * CAP_HEIGHT_EM / 2.0,
            ),
            text: label.clone(),
            size: LEGEND_SIZE,
            color: TEXT,
            anchor: Anchor::Start,
            vertical: false,
            bold: false,
        });
    }
    rect
}

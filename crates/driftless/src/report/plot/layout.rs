//! Figure → [`Scene`]: margins, axes, ticks, data, legend and label placement.
//!
//! The panel is drawn in layers: `axes` (geometry, ticks, grid, frame, titles), `data`
//! (bars, bands, lines, series), `labels` (annotations and line labels placed clear of
//! what is drawn) and `legend`.

use super::figure::{Color, DEFAULT_PANEL_SIZE, Figure, LegendPosition, PALETTE, Plot};
use super::geom::{Pt, Rect};
use super::scene::{Anchor, Prim, Scene};
use super::text::{CAP_HEIGHT_EM, text_width};

mod axes;
mod data;
mod labels;
mod legend;

use axes::{PanelGeom, draw_frame_and_ticks, draw_grid, draw_titles};
use data::{dash_of, draw_lines, draw_series, push_bars};
use labels::{Obstacles, draw_annotations, draw_line_labels};
use legend::{LegendEntry, Sample, draw_legend};

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

/// Lays out one panel in `cell`: geometry and ticks, grid, bars, lines, series,
/// annotations, legend and line labels, then frame, tick labels and titles.
fn layout_panel(plot: &Plot, cell: Rect, items: &mut Vec<Prim>) {
    let g = PanelGeom::new(plot, cell);
    draw_grid(&g, items);

    let mut obstacles = Obstacles::default();
    let mut legend_entries = Vec::new();

    // Bars (under lines and series).
    for (bi, b) in plot.bars.iter().enumerate() {
        let color = b
            .color
            .unwrap_or(PALETTE[(plot.series.len() + bi) % PALETTE.len()]);
        push_bars(b, color, &g.xm, &g.ym, &g.area, &mut obstacles, items);
        if !b.name.trim().is_empty() {
            legend_entries.push(LegendEntry {
                label: b.name.trim().to_owned(),
                color,
                sample: Sample::Bar,
            });
        }
    }

    // Model / asymptote lines (under the data).
    let line_runs = draw_lines(plot, &g, &mut obstacles, items);

    // Series: connecting lines, error bars, markers.
    for (si, s) in plot.series.iter().enumerate() {
        let entry = draw_series(plot, si, s, &g, &mut obstacles, items);
        legend_entries.extend(entry);
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

    draw_annotations(plot, &g, &mut obstacles, items);
    obstacles.decimate();

    // Legend, then line labels around it.
    if plot.legend != LegendPosition::Hidden && !legend_entries.is_empty() {
        let r = draw_legend(&legend_entries, plot.legend, &g.area, &obstacles, items);
        obstacles.boxes.push(r);
    }
    draw_line_labels(plot, &line_runs, &g, &mut obstacles, items);

    draw_frame_and_ticks(&g, items);
    draw_titles(plot, cell, &g, items);
}

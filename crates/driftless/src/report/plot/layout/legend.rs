//! The legend: entries with their samples, placed where they cover the least.

use crate::report::plot::figure::{Color, LegendPosition, MarkerShape};
use crate::report::plot::geom::Rect;
use crate::report::plot::scene::{Anchor, Dash, Prim};
use crate::report::plot::text::{CAP_HEIGHT_EM, text_width};

use super::labels::Obstacles;
use super::{BAND_OPACITY, LEGEND_BORDER, LEGEND_SIZE, MARKER_R, TEXT, fit_text};

pub(super) enum Sample {
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

pub(super) struct LegendEntry {
    pub(super) label: String,
    pub(super) color: Color,
    pub(super) sample: Sample,
}

pub(super) const LEGEND_ROW: f64 = 18.0;
pub(super) const LEGEND_PAD: f64 = 8.0;
pub(super) const LEGEND_SAMPLE: f64 = 26.0;

pub(super) fn draw_legend(
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

//! Placing text clear of the data: the obstacles already drawn, annotation and line
//! labels.

use crate::report::plot::figure::{Color, MarkerShape, Plot};
use crate::report::plot::geom::{Pt, Rect, segment_hits_rect};
use crate::report::plot::scene::{Anchor, Prim};
use crate::report::plot::text::text_width;

use super::axes::PanelGeom;
use super::{LABEL_SIZE, MARKER_R, MAX_OBSTACLES, TEXT, fit_text};

/// Things that labels and the legend should not cover.
#[derive(Default)]
pub(super) struct Obstacles {
    /// The curves themselves (series' connecting lines, solid lines such as a fitted
    /// model): a label crosses one only where no place is free of them.
    pub(super) segments: Vec<(Pt, Pt)>,
    /// Guides (dashed or dotted reference lines such as asymptotes, error bars): better
    /// not covered, but a label may cross one rather than a curve.
    pub(super) guides: Vec<(Pt, Pt)>,
    pub(super) points: Vec<Pt>,
    pub(super) boxes: Vec<Rect>,
}

/// Clutter score of a label crossing a curve segment: more than a label pushed off its
/// line to stay inside the plot area (500), less than covering another label or the
/// legend ([`BOX_HIT`]); a marker costs 40, a guide 25.
const CURVE_HIT: f64 = 600.0;
/// Clutter score of covering another label, the legend or a bar.
const BOX_HIT: f64 = 10_000.0;

impl Obstacles {
    pub(super) fn add_guide_runs(&mut self, runs: &[Vec<Pt>]) {
        for r in runs {
            for w in r.windows(2) {
                self.guides.push((w[0], w[1]));
            }
        }
    }

    pub(super) fn add_runs(&mut self, runs: &[Vec<Pt>]) {
        for r in runs {
            for w in r.windows(2) {
                self.segments.push((w[0], w[1]));
            }
        }
    }

    /// Thins segments and points to at most [`MAX_OBSTACLES`] each.
    pub(super) fn decimate(&mut self) {
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
    pub(super) fn score(&self, r: &Rect) -> f64 {
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

/// Annotations: a ring at the point and a label placed clear of the data.
pub(super) fn draw_annotations(
    plot: &Plot,
    g: &PanelGeom,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) {
    let area = &g.area;
    for a in &plot.annotations {
        let Some(p) = g.map(a.x, a.y).filter(|p| area.contains(*p)) else {
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
        let r = place_annotation_label(&t, p, area, obstacles);
        push_label(items, &r, &t, color);
        obstacles.boxes.push(r);
    }
}

/// The lines' labels, each placed along its line clear of the data and the legend.
pub(super) fn draw_line_labels(
    plot: &Plot,
    line_runs: &[Vec<Vec<Pt>>],
    g: &PanelGeom,
    obstacles: &mut Obstacles,
    items: &mut Vec<Prim>,
) {
    let area = &g.area;
    for (line, runs) in plot.lines.iter().zip(line_runs) {
        let Some(label) = line
            .label
            .as_deref()
            .map(str::trim)
            .filter(|l| !l.is_empty())
        else {
            continue;
        };
        let label = fit_text(label, LABEL_SIZE, area.w - 8.0);
        let pref = line.label_x.and_then(|x| g.xm.px(x));
        if let Some(r) = place_label(&label, runs, area, obstacles, pref) {
            push_label(items, &r, &label, line.color.unwrap_or(Color::DARK_GREY));
            obstacles.boxes.push(r);
        }
    }
}

/// Moves `r` inside `area` (as far as it fits).
pub(super) fn clamp_into(mut r: Rect, area: &Rect) -> Rect {
    r.x = r.x.min(area.right() - 2.0 - r.w).max(area.x + 2.0);
    r.y = r.y.min(area.bottom() - 2.0 - r.h).max(area.y + 2.0);
    r
}

/// A text label on a translucent white box `r` (3 px padding).
pub(super) fn push_label(items: &mut Vec<Prim>, r: &Rect, label: &str, color: Color) {
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

/// Box of an annotation's text next to its point `p`: of the positions around the point
/// (above/below × right/left, then further out) the one that covers the least of the
/// data, lines, legends and labels already placed ([`Obstacles::score`]), inside the
/// plot area; ties go to the first (above right).
pub(super) fn place_annotation_label(
    text: &str,
    p: Pt,
    area: &Rect,
    obstacles: &Obstacles,
) -> Rect {
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

/// Best box for `label` beside the visible runs of its line: candidates every
/// 1/48 of the visible length on both sides, scored by clutter (other
/// labels, the legend, lines, markers) and distance from the preferred x
/// (or from the middle of the visible part).
pub(super) fn place_label(
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

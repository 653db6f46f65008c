//! Pixel-space geometry: rectangles and line clipping.
//!
//! Lines are clipped geometrically instead of with an SVG `<clipPath>`: clip
//! paths need document-unique ids, which break when several figures are
//! inlined into one HTML page, and the PNG renderer gets the same geometry.

pub(crate) type Pt = (f64, f64);

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
}

impl Rect {
    pub fn new(x: f64, y: f64, w: f64, h: f64) -> Self {
        Rect { x, y, w, h }
    }
    pub fn right(&self) -> f64 {
        self.x + self.w
    }
    pub fn bottom(&self) -> f64 {
        self.y + self.h
    }
    pub fn contains(&self, p: Pt) -> bool {
        p.0 >= self.x && p.0 <= self.right() && p.1 >= self.y && p.1 <= self.bottom()
    }
    pub(crate) fn contains_rect(&self, r: &Rect) -> bool {
        r.x >= self.x && r.y >= self.y && r.right() <= self.right() && r.bottom() <= self.bottom()
    }
    pub fn inflate(&self, d: f64) -> Rect {
        Rect::new(self.x - d, self.y - d, self.w + 2.0 * d, self.h + 2.0 * d)
    }
    pub(crate) fn overlap_area(&self, o: &Rect) -> f64 {
        let w = self.right().min(o.right()) - self.x.max(o.x);
        let h = self.bottom().min(o.bottom()) - self.y.max(o.y);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }
}

/// Liang–Barsky: the part of segment `a`–`b` inside `r`, if any.
pub(crate) fn clip_segment(a: Pt, b: Pt, r: &Rect) -> Option<(Pt, Pt)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    let checks = [
        (-dx, a.0 - r.x),
        (dx, r.right() - a.0),
        (-dy, a.1 - r.y),
        (dy, r.bottom() - a.1),
    ];
    for (p, q) in checks {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    if !(t0.is_finite() && t1.is_finite()) {
        return None;
    }
    Some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Clips a polyline whose vertices may be missing (`None`: a value that
/// cannot be shown on a log axis, which breaks the line) to `r`, returning
/// the visible runs, each with at least two points.
pub(crate) fn clip_polyline(pts: &[Option<Pt>], r: &Rect) -> Vec<Vec<Pt>> {
    let mut runs: Vec<Vec<Pt>> = Vec::new();
    let mut cur: Vec<Pt> = Vec::new();
    let close = |cur: &mut Vec<Pt>, runs: &mut Vec<Vec<Pt>>| {
        if cur.len() >= 2 {
            runs.push(std::mem::take(cur));
        } else {
            cur.clear();
        }
    };
    for w in pts.windows(2) {
        match (w[0], w[1]) {
            (Some(a), Some(b)) => match clip_segment(a, b, r) {
                Some((p, q)) => {
                    let continues = cur
                        .last()
                        .is_some_and(|l| (l.0 - p.0).abs() < 1e-9 && (l.1 - p.1).abs() < 1e-9);
                    if !continues {
                        close(&mut cur, &mut runs);
                        cur.push(p);
                    }
                    cur.push(q);
                    if q != b {
                        // Left the rectangle.
                        close(&mut cur, &mut runs);
                    }
                }
                None => close(&mut cur, &mut runs),
            },
            _ => close(&mut cur, &mut runs),
        }
    }
    close(&mut cur, &mut runs);
    runs
}

/// Does segment `a`–`b` pass through `r`?
pub(crate) fn segment_hits_rect(a: Pt, b: Pt, r: &Rect) -> bool {
    clip_segment(a, b, r).is_some()
}

/// Sutherland–Hodgman clip of a closed polygon to `r` (empty if nothing of
/// it is inside). Vertices must be finite.
pub(crate) fn clip_polygon(pts: &[Pt], r: &Rect) -> Vec<Pt> {
    // Each edge: (is the point inside, intersection of a→b with the edge).
    fn clip_edge(poly: &[Pt], inside: impl Fn(Pt) -> bool, cut: impl Fn(Pt, Pt) -> Pt) -> Vec<Pt> {
        let mut out = Vec::with_capacity(poly.len() + 2);
        for (i, &b) in poly.iter().enumerate() {
            let a = poly[(i + poly.len() - 1) % poly.len()];
            match (inside(a), inside(b)) {
                (true, true) => out.push(b),
                (true, false) => out.push(cut(a, b)),
                (false, true) => {
                    out.push(cut(a, b));
                    out.push(b);
                }
                (false, false) => {}
            }
        }
        out
    }
    let at_x = |a: Pt, b: Pt, x: f64| {
        let t = if b.0 == a.0 {
            0.0
        } else {
            (x - a.0) / (b.0 - a.0)
        };
        (x, a.1 + t * (b.1 - a.1))
    };
    let at_y = |a: Pt, b: Pt, y: f64| {
        let t = if b.1 == a.1 {
            0.0
        } else {
            (y - a.1) / (b.1 - a.1)
        };
        (a.0 + t * (b.0 - a.0), y)
    };
    let (x0, x1, y0, y1) = (r.x, r.right(), r.y, r.bottom());
    let mut poly = pts.to_vec();
    if poly.len() < 3 {
        return Vec::new();
    }
    poly = clip_edge(&poly, |p| p.0 >= x0, |a, b| at_x(a, b, x0));
    if poly.is_empty() {
        return poly;
    }
    poly = clip_edge(&poly, |p| p.0 <= x1, |a, b| at_x(a, b, x1));
    if poly.is_empty() {
        return poly;
    }
    poly = clip_edge(&poly, |p| p.1 >= y0, |a, b| at_y(a, b, y0));
    if poly.is_empty() {
        return poly;
    }
    poly = clip_edge(&poly, |p| p.1 <= y1, |a, b| at_y(a, b, y1));
    if poly.len() < 3 { Vec::new() } else { poly }
}

//! A backend-neutral display list: the layout computes it once, the SVG
//! writer serialises it and the PNG renderer rasterises it, so both outputs
//! show exactly the same picture.

use super::figure::{Color, MarkerShape};
use super::geom::Pt;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Anchor {
    Start,
    Middle,
    End,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Dash {
    Solid,
    /// On / off lengths in px.
    Pattern(f64, f64),
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Prim {
    Rect {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
        /// Fill colour and opacity.
        fill: Option<(Color, f64)>,
        /// Stroke colour and width.
        stroke: Option<(Color, f64)>,
    },
    /// An open polyline.
    Path {
        pts: Vec<Pt>,
        color: Color,
        width: f64,
        dash: Dash,
        opacity: f64,
    },
    /// A closed, filled polygon without outline (confidence bands).
    Polygon {
        pts: Vec<Pt>,
        color: Color,
        opacity: f64,
    },
    Marker {
        at: Pt,
        shape: MarkerShape,
        /// Half-size in px.
        r: f64,
        color: Color,
        /// `false`: white inside, coloured outline.
        filled: bool,
    },
    /// Single-line text; `at` is the start / middle / end of the baseline.
    Text {
        at: Pt,
        text: String,
        size: f64,
        color: Color,
        anchor: Anchor,
        /// Rotated −90° about `at` (reads bottom-to-top).
        vertical: bool,
        bold: bool,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Scene {
    pub width: f64,
    pub height: f64,
    pub title: Option<String>,
    pub items: Vec<Prim>,
}

/// Vertices of a marker polygon centred at `c` with half-size `r`
/// (`None` for circles and for no marker).
pub(crate) fn marker_polygon(shape: MarkerShape, c: Pt, r: f64) -> Option<Vec<Pt>> {
    let (x, y) = c;
    match shape {
        MarkerShape::Square => {
            let s = r * 0.9;
            Some(vec![
                (x - s, y - s),
                (x + s, y - s),
                (x + s, y + s),
                (x - s, y + s),
            ])
        }
        MarkerShape::Triangle => {
            let s = r * 1.2;
            Some(vec![
                (x, y - s),
                (x + s * 0.866, y + s * 0.5),
                (x - s * 0.866, y + s * 0.5),
            ])
        }
        MarkerShape::Diamond => {
            let s = r * 1.25;
            Some(vec![
                (x, y - s),
                (x + s * 0.8, y),
                (x, y + s),
                (x - s * 0.8, y),
            ])
        }
        MarkerShape::Circle | MarkerShape::None => None,
    }
}

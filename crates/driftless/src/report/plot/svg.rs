//! Scene → self-contained SVG 1.1 (no external fonts, images, CSS or ids, so
//! it can be inlined into HTML any number of times).

use std::fmt::Write as _;

use super::figure::{Color, MarkerShape};
use super::geom::Pt;
use super::scene::{Anchor, Dash, Prim, Scene, marker_polygon};

const FONT_FAMILY: &str = "'DejaVu Sans', Verdana, 'Helvetica Neue', Arial, sans-serif";

/// Escapes text for XML content and attribute values. Characters that XML 1.0
/// forbids (most C0 controls, lone surrogates cannot occur in `str`, U+FFFE/F)
/// become U+FFFD.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            '\u{0}'..='\u{1f}' | '\u{fffe}' | '\u{ffff}' => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

/// Compact number: at most two decimals, no trailing zeros, never NaN/inf.
fn num(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_owned();
    }
    let mut s = format!("{:.2}", v);
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" { "0".to_owned() } else { s }
}

pub fn write_svg(scene: &Scene) -> String {
    let mut o = String::with_capacity(64 * scene.items.len() + 512);
    let (w, h) = (num(scene.width), num(scene.height));
    let _ = writeln!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\" font-family=\"{FONT_FAMILY}\" role=\"img\">"
    );
    if let Some(t) = &scene.title {
        let _ = writeln!(o, "<title>{}</title>", xml_escape(t));
    }
    for item in &scene.items {
        write_prim(&mut o, item);
    }
    o.push_str("</svg>\n");
    o
}

fn write_prim(o: &mut String, p: &Prim) {
    match p {
        Prim::Rect {
            x,
            y,
            w,
            h,
            fill,
            stroke,
        } => {
            let _ = write!(
                o,
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"",
                num(*x),
                num(*y),
                num(w.max(0.0)),
                num(h.max(0.0))
            );
            match fill {
                Some((c, a)) => {
                    let _ = write!(o, " fill=\"{}\"", c.to_hex());
                    if *a < 1.0 {
                        let _ = write!(o, " fill-opacity=\"{}\"", num(*a));
                    }
                }
                None => o.push_str(" fill=\"none\""),
            }
            if let Some((c, sw)) = stroke {
                let _ = write!(
                    o,
                    " stroke=\"{}\" stroke-width=\"{}\"",
                    c.to_hex(),
                    num(*sw)
                );
            }
            o.push_str("/>\n");
        }
        Prim::Path {
            pts,
            color,
            width,
            dash,
            opacity,
        } => {
            if pts.len() < 2 {
                return;
            }
            o.push_str("<polyline points=\"");
            write_points(o, pts);
            let _ = write!(
                o,
                "\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"",
                color.to_hex(),
                num(*width)
            );
            if let Dash::Pattern(on, off) = dash {
                let _ = write!(o, " stroke-dasharray=\"{} {}\"", num(*on), num(*off));
            }
            if *opacity < 1.0 {
                let _ = write!(o, " stroke-opacity=\"{}\"", num(*opacity));
            }
            o.push_str("/>\n");
        }
        Prim::Polygon {
            pts,
            color,
            opacity,
        } => {
            if pts.len() < 3 {
                return;
            }
            o.push_str("<polygon points=\"");
            write_points(o, pts);
            let _ = write!(o, "\" fill=\"{}\" stroke=\"none\"", color.to_hex());
            if *opacity < 1.0 {
                let _ = write!(o, " fill-opacity=\"{}\"", num(*opacity));
            }
            o.push_str("/>\n");
        }
        Prim::Marker {
            at,
            shape,
            r,
            color,
            filled,
        } => write_marker(o, *at, *shape, *r, *color, *filled),
        Prim::Text {
            at,
            text,
            size,
            color,
            anchor,
            vertical,
            bold,
        } => write_text(o, *at, text, *size, *color, *anchor, *vertical, *bold),
    }
}

/// Writes `x,y` pairs separated by spaces (a `points` attribute's value).
fn write_points(o: &mut String, pts: &[Pt]) {
    for (i, (x, y)) in pts.iter().enumerate() {
        if i > 0 {
            o.push(' ');
        }
        let _ = write!(o, "{},{}", num(*x), num(*y));
    }
}

/// A marker: a circle, or the shape's polygon; filled, or white with a coloured ring.
fn write_marker(o: &mut String, at: Pt, shape: MarkerShape, r: f64, color: Color, filled: bool) {
    let fill = if filled {
        color.to_hex()
    } else {
        "#ffffff".to_owned()
    };
    let paint = format!(
        " fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>\n",
        if filled { fill.as_str() } else { "none" },
        color.to_hex(),
        if filled { "0.8" } else { "1.4" }
    );
    match shape {
        MarkerShape::None => {}
        MarkerShape::Circle => {
            let _ = write!(
                o,
                "<circle cx=\"{}\" cy=\"{}\" r=\"{}\"{paint}",
                num(at.0),
                num(at.1),
                num(r)
            );
        }
        _ => {
            if let Some(poly) = marker_polygon(shape, at, r) {
                o.push_str("<polygon points=\"");
                write_points(o, &poly);
                let _ = write!(o, "\"{paint}");
            }
        }
    }
}

/// A text element with its anchor, weight and (for a y axis title) rotation.
#[allow(clippy::too_many_arguments)]
fn write_text(
    o: &mut String,
    at: Pt,
    text: &str,
    size: f64,
    color: Color,
    anchor: Anchor,
    vertical: bool,
    bold: bool,
) {
    let (x, y) = (num(at.0), num(at.1));
    let _ = write!(
        o,
        "<text x=\"{x}\" y=\"{y}\" font-size=\"{}\" fill=\"{}\"",
        num(size),
        color.to_hex()
    );
    match anchor {
        Anchor::Start => {}
        Anchor::Middle => o.push_str(" text-anchor=\"middle\""),
        Anchor::End => o.push_str(" text-anchor=\"end\""),
    }
    if bold {
        o.push_str(" font-weight=\"bold\"");
    }
    if vertical {
        let _ = write!(o, " transform=\"rotate(-90 {x} {y})\"");
    }
    let _ = writeln!(o, ">{}</text>", xml_escape(text));
}

//! Scene → PNG (feature `png`).
//!
//! Why this path: the figure is already a display list of lines, rectangles,
//! markers and text, so rasterising it directly is far leaner than parsing
//! our own SVG back with a full SVG renderer (`resvg` would pull in an XML
//! parser, a CSS/SVG attribute parser, a font database and a text shaper).
//! The whole feature is three crates plus the PNG encoder:
//!
//! * `tiny-skia` — anti-aliased paths, strokes and dashes, PNG encoding
//!   (its `png-format` feature: `png`, `flate2`/`miniz_oxide`, `crc32fast`);
//! * `ttf-parser` — glyph outlines and advances, no other dependencies;
//! * `dejavu` — DejaVu Sans as `&'static [u8]` (free licence), so text is
//!   legible on machines without any system fonts (CI, containers). Only the
//!   regular face is linked; bold is drawn by stroking the outline lightly.
//!
//! Glyph outlines are filled as vector paths, which handles rotation (the y
//! axis title) and any scale factor uniformly. There is no shaping or kerning:
//! plot labels are short Latin/Greek/symbol strings where that is invisible.

use std::collections::HashMap;

use tiny_skia::{
    FillRule, LineCap, LineJoin, Paint, Path, PathBuilder, Pixmap, Stroke, StrokeDash, Transform,
};
use ttf_parser::{Face, GlyphId, OutlineBuilder};

use super::PlotError;
use super::figure::{Color, MarkerShape};
use super::scene::{Anchor, Dash, Prim, Scene, marker_polygon};

/// At most this many pixels (≈ 400 MB of RGBA) in one raster.
pub(crate) const MAX_PIXELS: u64 = 100_000_000;

pub(crate) fn render(scene: &Scene, scale: f64) -> Result<Vec<u8>, PlotError> {
    let scale = if scale.is_finite() && scale > 0.0 {
        scale
    } else {
        1.0
    };
    let w = (scene.width * scale).round();
    let h = (scene.height * scale).round();
    let too_big = !(w >= 1.0 && h >= 1.0) || w * h > MAX_PIXELS as f64;
    let size_err = || PlotError::BadRasterSize {
        width: if w.is_finite() {
            w.max(0.0) as u64
        } else {
            u64::MAX
        },
        height: if h.is_finite() {
            h.max(0.0) as u64
        } else {
            u64::MAX
        },
        limit: MAX_PIXELS,
    };
    if too_big {
        return Err(size_err());
    }
    let mut pixmap = Pixmap::new(w as u32, h as u32).ok_or_else(size_err)?;
    pixmap.fill(tiny_skia::Color::WHITE);
    let face = Face::parse(dejavu::sans::regular(), 0).map_err(|_| PlotError::Font)?;
    let mut r = Raster {
        pixmap,
        base: Transform::from_scale(scale as f32, scale as f32),
        font: FontCache::new(face),
    };
    for item in &scene.items {
        r.draw(item);
    }
    r.pixmap
        .encode_png()
        .map_err(|e| PlotError::Encode(e.to_string()))
}

fn paint(c: Color, alpha: f64) -> Paint<'static> {
    let mut p = Paint::default();
    let a = (alpha.clamp(0.0, 1.0) * 255.0).round() as u8;
    p.set_color_rgba8(c.r, c.g, c.b, a);
    p.anti_alias = true;
    p
}

fn polyline(pts: &[(f64, f64)], close: bool) -> Option<Path> {
    let mut pb = PathBuilder::new();
    let (first, rest) = pts.split_first()?;
    pb.move_to(first.0 as f32, first.1 as f32);
    for p in rest {
        pb.line_to(p.0 as f32, p.1 as f32);
    }
    if close {
        pb.close();
    }
    pb.finish()
}

struct Raster<'a> {
    pixmap: Pixmap,
    base: Transform,
    font: FontCache<'a>,
}

impl Raster<'_> {
    fn stroke(&mut self, path: &Path, c: Color, alpha: f64, width: f64, dash: Dash) {
        let mut stroke = Stroke {
            width: width as f32,
            line_cap: LineCap::Butt,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        if let Dash::Pattern(on, off) = dash {
            stroke.dash = StrokeDash::new(vec![on as f32, off as f32], 0.0);
        }
        self.pixmap
            .stroke_path(path, &paint(c, alpha), &stroke, self.base, None);
    }

    fn fill(&mut self, path: &Path, c: Color, alpha: f64) {
        self.pixmap
            .fill_path(path, &paint(c, alpha), FillRule::Winding, self.base, None);
    }

    fn draw(&mut self, item: &Prim) {
        match item {
            Prim::Rect {
                x,
                y,
                w,
                h,
                fill,
                stroke,
            } => {
                let Some(rect) =
                    tiny_skia::Rect::from_xywh(*x as f32, *y as f32, *w as f32, *h as f32)
                else {
                    return;
                };
                let path = PathBuilder::from_rect(rect);
                if let Some((c, a)) = fill {
                    self.fill(&path, *c, *a);
                }
                if let Some((c, sw)) = stroke {
                    self.stroke(&path, *c, 1.0, *sw, Dash::Solid);
                }
            }
            Prim::Path {
                pts,
                color,
                width,
                dash,
                opacity,
            } => {
                if let Some(path) = polyline(pts, false) {
                    self.stroke(&path, *color, *opacity, *width, *dash);
                }
            }
            Prim::Polygon {
                pts,
                color,
                opacity,
            } => {
                if pts.len() >= 3
                    && let Some(path) = polyline(pts, true)
                {
                    self.fill(&path, *color, *opacity);
                }
            }
            Prim::Marker {
                at,
                shape,
                r,
                color,
                filled,
            } => {
                let path = match shape {
                    MarkerShape::None => None,
                    MarkerShape::Circle => {
                        PathBuilder::from_circle(at.0 as f32, at.1 as f32, *r as f32)
                    }
                    _ => marker_polygon(*shape, *at, *r).and_then(|p| polyline(&p, true)),
                };
                if let Some(path) = path {
                    if *filled {
                        self.fill(&path, *color, 1.0);
                        self.stroke(&path, *color, 1.0, 0.8, Dash::Solid);
                    } else {
                        self.stroke(&path, *color, 1.0, 1.4, Dash::Solid);
                    }
                }
            }
            Prim::Text {
                at,
                text,
                size,
                color,
                anchor,
                vertical,
                bold,
            } => {
                self.text(*at, text, *size, *color, *anchor, *vertical, *bold);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn text(
        &mut self,
        at: (f64, f64),
        text: &str,
        size: f64,
        color: Color,
        anchor: Anchor,
        vertical: bool,
        bold: bool,
    ) {
        let k = size / self.font.upem;
        let glyphs: Vec<(GlyphId, f64)> = text
            .chars()
            .filter(|c| !c.is_control())
            .map(|c| {
                let g = self.font.face.glyph_index(c).unwrap_or(GlyphId(0));
                let adv = self.font.face.glyph_hor_advance(g).map_or(0.0, f64::from) * k;
                (g, adv)
            })
            .collect();
        let total: f64 = glyphs.iter().map(|g| g.1).sum();
        let mut pen = match anchor {
            Anchor::Start => 0.0,
            Anchor::Middle => -total / 2.0,
            Anchor::End => -total,
        };
        let mut origin = self.base.pre_translate(at.0 as f32, at.1 as f32);
        if vertical {
            origin = origin.pre_rotate(-90.0);
        }
        let p = paint(color, 1.0);
        let bold_stroke = Stroke {
            width: (0.045 * self.font.upem) as f32,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        for (g, adv) in glyphs {
            if let Some(path) = self.font.outline(g) {
                let ts = origin
                    .pre_translate(pen as f32, 0.0)
                    .pre_scale(k as f32, -k as f32);
                self.pixmap.fill_path(path, &p, FillRule::Winding, ts, None);
                if bold {
                    self.pixmap.stroke_path(path, &p, &bold_stroke, ts, None);
                }
            }
            pen += adv;
        }
    }
}

/// Glyph outlines in font units (y up), parsed once per glyph.
struct FontCache<'a> {
    face: Face<'a>,
    upem: f64,
    outlines: HashMap<GlyphId, Option<Path>>,
}

impl<'a> FontCache<'a> {
    fn new(face: Face<'a>) -> Self {
        let upem = f64::from(face.units_per_em()).max(1.0);
        FontCache {
            face,
            upem,
            outlines: HashMap::new(),
        }
    }

    fn outline(&mut self, g: GlyphId) -> Option<&Path> {
        let face = &self.face;
        self.outlines
            .entry(g)
            .or_insert_with(|| {
                let mut b = GlyphPath(PathBuilder::new());
                face.outline_glyph(g, &mut b)?;
                b.0.finish()
            })
            .as_ref()
    }
}

struct GlyphPath(PathBuilder);

impl OutlineBuilder for GlyphPath {
    fn move_to(&mut self, x: f32, y: f32) {
        self.0.move_to(x, y);
    }
    fn line_to(&mut self, x: f32, y: f32) {
        self.0.line_to(x, y);
    }
    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        self.0.quad_to(x1, y1, x, y);
    }
    fn curve_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        self.0.cubic_to(x1, y1, x2, y2, x, y);
    }
    fn close(&mut self) {
        self.0.close();
    }
}

/// Horizontal advance of `c` in em according to the embedded font.
pub(crate) fn font_advance_em(c: char) -> Option<f64> {
    let face = Face::parse(dejavu::sans::regular(), 0).ok()?;
    let g = face.glyph_index(c)?;
    Some(f64::from(face.glyph_hor_advance(g)?) / f64::from(face.units_per_em()))
}

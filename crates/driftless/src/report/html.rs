//! One self-contained HTML report file: headings, paragraphs, tables, preformatted text
//! and figures embedded as base64 `data:` URIs — no external stylesheet, font, script or
//! image, so the file can be mailed, archived or attached to an issue and still shows
//! everything.
//!
//! ```
//! use driftless::report::html::HtmlReport;
//! use driftless::report::plot::{Figure, Plot, Series};
//! let mut r = HtmlReport::new("Outage study");
//! r.heading(2, "Errors").paragraph("Horizontal error <1 m & more.");
//! r.table("Per outage", &["outage".into(), "error (m)".into()], &[vec!["#1".into(), "3.2".into()]]);
//! let fig = Figure::single(Plot::linear("p", "x (s)", "y (m)")
//!     .with_series(Series::new("s", vec![0.0, 1.0], vec![1.0, 2.0])));
//! r.figure("A figure", &fig).expect("SVG embedding does not fail");
//! let html = r.render();
//! assert!(html.contains("&lt;1 m &amp; more") && html.contains("data:image/svg+xml;base64,"));
//! ```
//!
//! The page carries a few lines of inline script that, once the page has loaded, count
//! the images that decoded (`naturalWidth > 0`) and write `images loaded: K/N` into
//! `<p id="image-check">` (also as `data-loaded` / `data-total`), so a headless browser
//! test can tell whether every embedded figure renders.

use super::plot::{Figure, PlotError, render_png_bytes, render_svg};
use std::fmt::Write as _;
use std::path::Path;

/// Escapes text for HTML content and attribute values.
pub(crate) fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            // Controls other than tab / newline / CR are not allowed in HTML text.
            '\u{0}'..='\u{8}' | '\u{b}' | '\u{c}' | '\u{e}'..='\u{1f}' | '\u{7f}' => {
                out.push('\u{fffd}')
            }
            c => out.push(c),
        }
    }
    out
}

const BASE64_ALPHABET: &[u8; 64] =
    b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648 §4, with `=` padding), as `data:` URIs need.
pub(crate) fn base64_encode(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sextet = |i: u32| char::from(BASE64_ALPHABET[((n >> (18 - 6 * i)) & 63) as usize]);
        out.push(sextet(0));
        out.push(sextet(1));
        out.push(if chunk.len() > 1 { sextet(2) } else { '=' });
        out.push(if chunk.len() > 2 { sextet(3) } else { '=' });
    }
    out
}

/// Whether a table cell reads as a number (right-aligned): its first word parses as a
/// number after an optional `±`/`<`/`>`/`≈`, with `−` (U+2212) read as a minus sign.
fn is_numeric(cell: &str) -> bool {
    let word = cell.split_whitespace().next().unwrap_or("");
    let word = word.trim_start_matches(['±', '<', '>', '≈', '~', '+']);
    let word = word.trim_end_matches('%').replace('\u{2212}', "-");
    !word.is_empty() && word.parse::<f64>().is_ok()
}

/// Placeholder cells that do not decide whether a column is numeric.
fn is_blank(cell: &str) -> bool {
    matches!(cell.trim(), "" | "-" | "—" | "–" | "n/a" | "N/A")
}

/// A self-contained HTML report under construction (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct HtmlReport {
    title: String,
    body: String,
    figures: usize,
}

impl HtmlReport {
    /// An empty report; `title` is the page title and its top heading.
    pub fn new(title: impl Into<String>) -> Self {
        HtmlReport {
            title: title.into(),
            ..Default::default()
        }
    }

    /// Number of figures added so far (each is one `<img>`).
    pub fn figure_count(&self) -> usize {
        self.figures
    }

    /// A paragraph of plain text (escaped: markup in `text` is shown, not interpreted).
    pub fn paragraph(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<p>{}</p>", html_escape(text));
        self
    }

    /// A section heading; `level` is clamped to 2…6 (level 1 is the report title).
    pub fn heading(&mut self, level: u8, text: &str) -> &mut Self {
        let l = level.clamp(2, 6);
        let _ = writeln!(self.body, "<h{l}>{}</h{l}>", html_escape(text));
        self
    }

    /// A table with a caption and a header row. Columns whose cells all read as numbers
    /// (ignoring `n/a`, `—` and empty cells) are right-aligned with tabular figures;
    /// rows shorter than the header are padded with empty cells.
    pub fn table(&mut self, caption: &str, header: &[String], rows: &[Vec<String>]) -> &mut Self {
        let cols = rows.iter().map(Vec::len).fold(header.len(), usize::max);
        let numeric: Vec<bool> = (0..cols)
            .map(|c| {
                let cells = rows
                    .iter()
                    .filter_map(|r| r.get(c))
                    .filter(|v| !is_blank(v));
                let mut any = false;
                for v in cells {
                    if !is_numeric(v) {
                        return false;
                    }
                    any = true;
                }
                any
            })
            .collect();
        let class = |c: usize| if numeric[c] { " class=\"num\"" } else { "" };
        let b = &mut self.body;
        b.push_str("<div class=\"table-wrap\"><table>\n");
        if !caption.trim().is_empty() {
            let _ = writeln!(b, "<caption>{}</caption>", html_escape(caption));
        }
        if !header.is_empty() {
            b.push_str("<thead><tr>");
            for c in 0..cols {
                let h = header.get(c).map_or("", String::as_str);
                let _ = write!(b, "<th{}>{}</th>", class(c), html_escape(h));
            }
            b.push_str("</tr></thead>\n");
        }
        b.push_str("<tbody>\n");
        for row in rows {
            b.push_str("<tr>");
            for c in 0..cols {
                let v = row.get(c).map_or("", String::as_str);
                let _ = write!(b, "<td{}>{}</td>", class(c), html_escape(v));
            }
            b.push_str("</tr>\n");
        }
        b.push_str("</tbody></table></div>\n");
        self
    }

    /// Preformatted text (console output, configuration), escaped, in a scrolling box.
    pub fn preformatted(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<pre>{}</pre>", html_escape(text));
        self
    }

    /// Embeds `fig` as an SVG `data:` URI image with `caption` as its caption and alt
    /// text. The image keeps the figure's natural size and shrinks with the page.
    ///
    /// # Errors
    /// None at present (SVG rendering cannot fail); the `Result` matches
    /// [`figure_png`](Self::figure_png) so callers can switch between them.
    pub fn figure(&mut self, caption: &str, fig: &Figure) -> Result<(), PlotError> {
        let svg = render_svg(fig);
        let (w, h) = svg_size(&svg);
        self.push_image(caption, "image/svg+xml", svg.as_bytes(), w, h);
        Ok(())
    }

    /// Embeds `fig` as a PNG `data:` URI at `scale` device pixels per px (shown at the
    /// figure's natural size), for viewers that cannot display SVG.
    ///
    /// # Errors
    /// As [`render_png_bytes`]: [`PlotError::PngUnsupported`] without the `png` feature.
    pub fn figure_png(&mut self, caption: &str, fig: &Figure, scale: f64) -> Result<(), PlotError> {
        let png = render_png_bytes(fig, scale)?;
        let (w, h) = svg_size(&render_svg(fig));
        self.push_image(caption, "image/png", &png, w, h);
        Ok(())
    }

    fn push_image(&mut self, caption: &str, mime: &str, bytes: &[u8], w: String, h: String) {
        self.figures += 1;
        let cap = html_escape(caption);
        let size = if w.is_empty() || h.is_empty() {
            String::new()
        } else {
            format!(" width=\"{w}\" height=\"{h}\"")
        };
        let _ = writeln!(
            self.body,
            "<figure><img src=\"data:{mime};base64,{}\" alt=\"{cap}\"{size}>\
             <figcaption>Figure {}. {cap}</figcaption></figure>",
            base64_encode(bytes),
            self.figures
        );
    }

    /// The complete HTML document.
    pub fn render(&self) -> String {
        let title = html_escape(&self.title);
        let mut o = String::with_capacity(self.body.len() + STYLE.len() + SCRIPT.len() + 512);
        o.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        o.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        let _ = writeln!(o, "<title>{title}</title>");
        let _ = writeln!(o, "<style>{STYLE}</style>");
        o.push_str("</head>\n<body>\n<main>\n");
        let _ = writeln!(o, "<h1>{title}</h1>");
        o.push_str(&self.body);
        o.push_str(
            "<p id=\"image-check\" class=\"check\">image check: not run (needs JavaScript)</p>\n",
        );
        o.push_str("</main>\n");
        let _ = writeln!(o, "<script>{SCRIPT}</script>");
        o.push_str("</body>\n</html>\n");
        o
    }
}

/// `width` and `height` attributes of the root `<svg>` (empty strings if absent).
fn svg_size(svg: &str) -> (String, String) {
    let head = svg.split('>').next().unwrap_or("");
    let attr = |name: &str| {
        let key = format!(" {name}=\"");
        head.find(&key)
            .map(|i| &head[i + key.len()..])
            .and_then(|rest| rest.split('"').next())
            .filter(|v| v.parse::<f64>().is_ok())
            .unwrap_or("")
            .to_owned()
    };
    (attr("width"), attr("height"))
}

/// Writes the rendered report to `path`.
pub fn write_html(path: impl AsRef<Path>, report: &HtmlReport) -> std::io::Result<()> {
    crate::io::output::write(path, report.render())
}

const STYLE: &str = "
:root { color-scheme: light; }
body { margin: 0; background: #fff; color: #1f1f1f;
  font: 16px/1.5 'DejaVu Sans', Verdana, 'Helvetica Neue', Arial, sans-serif; }
main { max-width: 1000px; margin: 0 auto; padding: 1.5rem 1.25rem 3rem; }
h1 { font-size: 1.7rem; margin: 0 0 1rem; }
h2 { font-size: 1.35rem; margin: 2rem 0 0.6rem; border-bottom: 1px solid #ddd; padding-bottom: 0.2rem; }
h3, h4, h5, h6 { font-size: 1.1rem; margin: 1.4rem 0 0.5rem; }
p { margin: 0.6rem 0; }
.table-wrap { overflow-x: auto; margin: 1rem 0; }
table { border-collapse: collapse; font-size: 0.92rem; }
caption { caption-side: top; text-align: left; font-weight: bold; padding: 0 0 0.4rem; }
th, td { padding: 0.3rem 0.7rem; border-bottom: 1px solid #e2e2e2; text-align: left; vertical-align: top; }
thead th { border-bottom: 2px solid #999; background: #f6f6f6; }
tbody tr:nth-child(even) { background: #fafafa; }
.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
pre { background: #f6f6f6; border: 1px solid #e2e2e2; padding: 0.7rem; overflow-x: auto;
  font: 0.85rem/1.4 'DejaVu Sans Mono', Menlo, Consolas, monospace; }
figure { margin: 1.5rem 0; }
figure img { display: block; max-width: 100%; height: auto; margin: 0 auto; }
figcaption { font-size: 0.92rem; color: #444; margin-top: 0.4rem; text-align: center; }
.check { font-size: 0.8rem; color: #888; margin-top: 2rem; }
";

/// Counts decoded images after `load` (module docs); touches only `#image-check`.
const SCRIPT: &str = "
window.addEventListener('load', function () {
  var imgs = document.images, ok = 0;
  for (var i = 0; i < imgs.length; i++) {
    if (imgs[i].complete && imgs[i].naturalWidth > 0) { ok++; }
  }
  var p = document.getElementById('image-check');
  if (p) {
    p.textContent = 'images loaded: ' + ok + '/' + imgs.length;
    p.setAttribute('data-loaded', String(ok));
    p.setAttribute('data-total', String(imgs.length));
  }
});
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_rfc4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, enc) in cases {
            assert_eq!(base64_encode(plain.as_bytes()), enc, "{plain:?}");
        }
        // All 64 symbols, including '+' and '/'.
        assert_eq!(base64_encode(&[0xfb, 0xff, 0xbf]), "+/+/");
        assert_eq!(base64_encode(&[0, 0x10, 0x83]), "ABCD");
    }

    #[test]
    fn numeric_cells() {
        for yes in ["3.2", "-1e3", "−4.5", "12 %", "±0.3", "42 m", "1.5%", "NaN"] {
            assert!(is_numeric(yes), "{yes}");
        }
        for no in ["#1", "(a) raw", "", "m", "x1"] {
            assert!(!is_numeric(no), "{no}");
        }
    }

    #[test]
    fn svg_size_reads_root_attributes() {
        let (w, h) =
            svg_size("<svg xmlns=\"x\" width=\"960\" height=\"440.5\" viewBox=\"0 0 1 1\">");
        assert_eq!((w.as_str(), h.as_str()), ("960", "440.5"));
        assert_eq!(svg_size("<svg>"), (String::new(), String::new()));
    }
}

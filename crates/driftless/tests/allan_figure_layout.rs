//! The Allan figure's legend and term labels never cover the curves or each other: on
//! figures of simulated six-channel static logs with white noise, bias instability and
//! rate random walk (so each panel carries the N, B and K labels, the "minimum" note and a
//! legend), measured on the SVG itself:
//!
//! * no label box and no legend box crosses the deviation curve (its connecting line) or
//!   the fitted model line;
//! * no two boxes overlap, so the legend and the "minimum" note never hide a term's value;
//! * (`--ignored`, needs Chromium) every label's and legend entry's text, laid out by the
//!   browser with its own fonts, stays inside its box — so what the boxes keep clear, the
//!   text keeps clear.

use driftless::allan::analysis::{AnalysisConfig, analyse};
use driftless::allan::fit::{FitConfig, fit_noise_with_edf};
use driftless::allan::taus::TauSpec;
use driftless::io::log::Quantity;
use driftless::report::allan_plot;
use driftless::report::plot::{Color, PALETTE, render_svg};
use driftless::sim::noise::{StaticNoiseConfig, generate_channels};
use driftless_model::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MILLI_G};

#[path = "common/svg.rs"]
mod svg;

#[path = "common/chromium.rs"]
mod chromium;

/// `(x, y, w, h)` in SVG px.
type Rect = (f64, f64, f64, f64);

/// The Allan figure (SVG) of a simulated 2-h, 100-Hz static log of three gyros and three
/// accelerometers with N, B and K, seed `seed`.
fn allan_svg(seed: u64) -> String {
    let fs = 100.0;
    let gyro = StaticNoiseConfig {
        sample_rate_hz: fs,
        duration_s: 7200.0,
        white: 0.2 * DEG_PER_SQRT_H,
        bias_instability: 3.0 * DEG_PER_H,
        rate_random_walk: 6.0 * DEG_PER_H / 3600f64.sqrt(),
        ..Default::default()
    };
    let accel = StaticNoiseConfig {
        white: 0.03 * M_PER_S_PER_SQRT_H,
        bias_instability: 0.02 * MILLI_G,
        rate_random_walk: 2e-5,
        ..gyro.clone()
    };
    let cfgs = [
        gyro.clone(),
        gyro.clone(),
        gyro,
        accel.clone(),
        accel.clone(),
        accel,
    ];
    let data = generate_channels(&cfgs, seed).expect("simulated log");
    let names = [
        "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
    ];
    let cfg = AnalysisConfig {
        taus: TauSpec::Log(60),
        ..Default::default()
    };
    let results: Vec<_> = names
        .iter()
        .zip(&data)
        .map(|(name, y)| analyse(name, y, 1.0 / fs, &cfg).expect("analysis"))
        .collect();
    let fit_cfg = FitConfig {
        quantization: false,
        rate_ramp: false,
        gauss_markov: false,
        ..FitConfig::default()
    };
    let fits: Vec<_> = results
        .iter()
        .map(|r| {
            let tau: Vec<f64> = r.points.iter().map(|p| p.tau).collect();
            let avar: Vec<f64> = r.points.iter().map(|p| p.dev * p.dev).collect();
            fit_noise_with_edf(&tau, &avar, |i, a| r.edf_for_alpha(i, a), &fit_cfg, 0.683)
                .expect("noise fit")
        })
        .collect();
    let refs: Vec<_> = fits.iter().map(Some).collect();
    let quantities = [
        Quantity::AngularRate,
        Quantity::AngularRate,
        Quantity::AngularRate,
        Quantity::SpecificForce,
        Quantity::SpecificForce,
        Quantity::SpecificForce,
    ];
    render_svg(&allan_plot::figure(
        "Allan deviation",
        &results,
        &quantities,
        &[],
        &refs,
    ))
}

/// The boxes behind line labels and annotations (translucent white, no stroke) and the
/// legend boxes (translucent white with a border), each with the text drawn on it.
struct Boxes {
    labels: Vec<(Rect, String)>,
    legends: Vec<Rect>,
}

fn boxes(svg_text: &str) -> Boxes {
    let mut labels = Vec::new();
    let mut legends = Vec::new();
    let lines: Vec<&str> = svg_text.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        if !(l.starts_with("<rect") && l.contains("fill=\"#ffffff\" fill-opacity")) {
            continue;
        }
        let r = (
            svg::attr(l, "x"),
            svg::attr(l, "y"),
            svg::attr(l, "width"),
            svg::attr(l, "height"),
        );
        if l.contains("stroke=") {
            legends.push(r);
        } else {
            let text = lines
                .get(i + 1)
                .filter(|t| t.starts_with("<text"))
                .and_then(|t| t.split_once('>'))
                .map(|(_, b)| b.trim_end_matches("</text>").to_owned())
                .unwrap_or_default();
            labels.push((r, text));
        }
    }
    Boxes { labels, legends }
}

/// Does the segment a–b pass through the interior of `r` (shrunk by `inset` px)? Sampled
/// every 0.1 px along the segment.
fn crosses(a: (f64, f64), b: (f64, f64), r: Rect, inset: f64) -> bool {
    let (x0, y0, x1, y1) = (
        r.0 + inset,
        r.1 + inset,
        r.0 + r.2 - inset,
        r.1 + r.3 - inset,
    );
    let steps = ((b.0 - a.0).hypot(b.1 - a.1) / 0.1).ceil().max(1.0) as usize;
    (0..=steps).any(|k| {
        let t = k as f64 / steps as f64;
        let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        x > x0 && x < x1 && y > y0 && y < y1
    })
}

fn overlap(a: Rect, b: Rect) -> bool {
    let ox = (a.0 + a.2).min(b.0 + b.2) - a.0.max(b.0);
    let oy = (a.1 + a.3).min(b.1 + b.3) - a.1.max(b.1);
    ox > 0.0 && oy > 0.0
}

/// The curves a label must leave visible: each channel's connecting line (its palette
/// colour, width 1.2) and the fitted model (dark grey). A legend's own sample line lies
/// inside its legend box and is left out.
fn curves(svg_text: &str, legends: &[Rect]) -> Vec<Vec<(f64, f64)>> {
    let inside = |pts: &[(f64, f64)], r: Rect| {
        pts.iter()
            .all(|p| p.0 >= r.0 && p.0 <= r.0 + r.2 && p.1 >= r.1 && p.1 <= r.1 + r.3)
    };
    let mut keys: Vec<String> = PALETTE
        .iter()
        .map(|c| format!("stroke=\"{}\" stroke-width=\"1.2\"", c.to_hex()))
        .collect();
    keys.push(format!(
        "stroke=\"{}\"",
        Color::rgb(0x20, 0x20, 0x20).to_hex()
    ));
    let mut out = Vec::new();
    for l in svg_text.lines().filter(|l| l.starts_with("<polyline")) {
        if !keys.iter().any(|k| l.contains(k.as_str())) {
            continue;
        }
        let pts = svg::polyline_points(l);
        if pts.len() >= 2 && !legends.iter().any(|r| inside(&pts, *r)) {
            out.push(pts);
        }
    }
    out
}

/// Every seed's figure: boxes clear of the curves and of each other. Every panel has its
/// `N = …` label, and at least half a `K = …` one (where the fit resolves K).
#[test]
fn labels_and_legends_leave_curves_and_term_values_visible() {
    let mut bad = Vec::new();
    for seed in [3u64, 11, 29, 41, 57, 73, 89, 97] {
        let svg_text = allan_svg(seed);
        let b = boxes(&svg_text);
        assert_eq!(b.legends.len(), 6, "seed {seed}: one legend per panel");
        let count = |term: &str| b.labels.iter().filter(|(_, t)| t.starts_with(term)).count();
        let (n, k) = (count("N = "), count("K = "));
        assert_eq!(n, 6, "seed {seed}: N = … labels: {n} of 6");
        assert!(k >= 3, "seed {seed}: K = … labels: {k} of 6");
        let curves = curves(&svg_text, &b.legends);
        assert!(curves.len() >= 12, "seed {seed}: {} curves", curves.len());
        let all: Vec<(Rect, String)> = b
            .labels
            .iter()
            .cloned()
            .chain(b.legends.iter().map(|r| (*r, "legend".to_owned())))
            .collect();
        for (r, what) in &all {
            for c in &curves {
                if let Some(w) = c.windows(2).find(|w| crosses(w[0], w[1], *r, 0.5)) {
                    bad.push(format!(
                        "seed {seed}: {what:?} box {r:?} covers a curve at {:?}–{:?}",
                        w[0], w[1]
                    ));
                }
            }
        }
        for (i, (a, wa)) in all.iter().enumerate() {
            for (bx, wb) in &all[i + 1..] {
                if overlap(*a, *bx) {
                    bad.push(format!("seed {seed}: {wa:?} {a:?} overlaps {wb:?} {bx:?}"));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The checks themselves: a segment through a box is found, one beside it is not;
/// overlapping boxes are found.
#[test]
fn the_geometry_checks_find_what_they_look_for() {
    let r = (10.0, 10.0, 20.0, 10.0);
    assert!(crosses((0.0, 15.0), (40.0, 15.0), r, 0.5));
    assert!(crosses((12.0, 0.0), (25.0, 30.0), r, 0.5));
    assert!(!crosses((0.0, 5.0), (40.0, 5.0), r, 0.5));
    assert!(!crosses((0.0, 0.0), (9.0, 30.0), r, 0.5));
    assert!(overlap(r, (25.0, 15.0, 10.0, 10.0)));
    assert!(!overlap(r, (30.0, 10.0, 5.0, 5.0)));
}

/// In headless Chromium (its fonts, its text layout), the text of every label and legend
/// entry lies inside its box (0.5 px tolerance): the page's script measures each `<text>`
/// with `getBBox()` against the box drawn behind it and writes the verdict into the DOM.
#[test]
#[ignore = "needs chromium"]
fn label_texts_stay_inside_their_boxes_in_chromium() {
    let svg_text = allan_svg(3);
    let script = r#"
<script>
const out = [];
let n = 0;
const rects = Array.from(document.querySelectorAll('svg rect'))
  .filter(r => r.getAttribute('fill') === '#ffffff' && r.getAttribute('fill-opacity'));
const texts = Array.from(document.querySelectorAll('svg text'));
for (const r of rects) {
  const x = +r.getAttribute('x'), y = +r.getAttribute('y');
  const w = +r.getAttribute('width'), h = +r.getAttribute('height');
  const legend = r.hasAttribute('stroke');
  // A label's text follows its box; a legend's texts are those whose anchor is inside it.
  const mine = legend
    ? texts.filter(t => { const tx = +t.getAttribute('x'), ty = +t.getAttribute('y');
        return tx > x && tx < x + w && ty > y && ty < y + h; })
    : [r.nextElementSibling].filter(t => t && t.tagName === 'text');
  for (const t of mine) {
    n += 1;
    const b = t.getBBox();
    if (b.x < x - 0.5 || b.y < y - 0.5 || b.x + b.width > x + w + 0.5 || b.y + b.height > y + h + 0.5) {
      out.push(JSON.stringify(t.textContent) + ' [' + [b.x, b.y, b.width, b.height].map(v => v.toFixed(1)) +
               '] outside [' + [x, y, w, h].map(v => v.toFixed(1)) + ']');
    }
  }
}
const p = document.createElement('pre');
p.textContent = 'layout check: ' + n + ' texts; ' + (out.length ? 'FAIL ' + out.join(' | ') : 'OK') + ' :end';
document.body.appendChild(p);
</script>"#;
    let html = format!("<!DOCTYPE html><html><body>{svg_text}{script}</body></html>");
    let dir = chromium::TempDir::new("allan-layout").expect("tmp");
    let path = dir.0.join("allan.html");
    std::fs::write(&path, html).expect("write");
    let dom = chromium::dump_dom(&path).expect("chromium");
    let verdict = dom
        .split("<pre>layout check: ")
        .nth(1)
        .and_then(|s| s.split(" :end").next())
        .expect("the page's script ran");
    eprintln!("{verdict}");
    let n: usize = verdict
        .split(' ')
        .next()
        .and_then(|s| s.parse().ok())
        .expect("count");
    // 6 panels × (N, B, K, minimum) labels + the legend entries.
    assert!(n >= 6 * 4 + 6 * 3, "{n} texts measured");
    assert!(verdict.ends_with("OK"), "{verdict}");
}

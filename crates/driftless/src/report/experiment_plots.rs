//! The figures of the paper's experiment: the vehicle trajectory with its GNSS
//! outages and each solution's drift inside them (the seed paper's Fig. 2), the
//! per-outage errors of each processing case as grouped bars (its Table 1 as a chart),
//! and the error growth inside the outages, one panel per case.
//!
//! The figures are sized for a page about [`FIGURE_WIDTH`] px wide, so their text stays
//! legible when an HTML report shows them at that width; [`fit_to_width`] shrinks other
//! figures (the Allan and thermal figures) to the same width. A case keeps its colour
//! across the trajectory and bar figures even when one of them leaves a case out, as
//! long as its name starts with the paper's `(a)`, `(b)`, … tag ([`case_color`]).

use super::plot::{
    Annotation, AxisScale, Bars, Color, Figure, LegendPosition, Line, LineStyle, PALETTE, Plot,
};

/// Natural width (px) of the experiment figures.
pub const FIGURE_WIDTH: f64 = 960.0;

/// Smallest panel that stays readable after [`fit_to_width`] (px).
const MIN_PANEL: (f64, f64) = (300.0, 230.0);

/// Pale amber under the reference track inside each outage: a wide highlight that the
/// thin reference line and the coloured solutions stay visible on.
const OUTAGE_HIGHLIGHT: Color = Color::rgb(0xff, 0xd2, 0x6e);

/// Line colours of the outages `#1`, `#2`, … in the error-growth panels: none of them is
/// one of the first three case colours, so an outage is not mistaken for a case.
/// Outage line colours: black and Paul Tol's "muted" scheme (distinct for colour-blind
/// readers), ten in all; beyond ten the colours repeat with a dashed, then a dotted line
/// ([`outage_style`]), so no two outages of one panel look alike.
const OUTAGE_COLORS: [Color; 10] = [
    Color::rgb(0x00, 0x00, 0x00), // black
    Color::rgb(0xcc, 0x66, 0x77), // rose
    Color::rgb(0x33, 0x22, 0x88), // indigo
    Color::rgb(0xdd, 0xcc, 0x77), // sand
    Color::rgb(0x11, 0x77, 0x33), // green
    Color::rgb(0x88, 0xcc, 0xee), // cyan
    Color::rgb(0x88, 0x22, 0x55), // wine
    Color::rgb(0x44, 0xaa, 0x99), // teal
    Color::rgb(0x99, 0x99, 0x33), // olive
    Color::rgb(0xaa, 0x44, 0x99), // purple
];

/// Colour and dash of outage `k` (0-based): unique for the first 30 outages.
pub(crate) fn outage_style(k: usize) -> (Color, LineStyle) {
    const STYLES: [LineStyle; 3] = [LineStyle::Solid, LineStyle::Dashed, LineStyle::Dotted];
    (
        OUTAGE_COLORS[k % OUTAGE_COLORS.len()],
        STYLES[(k / OUTAGE_COLORS.len()) % STYLES.len()],
    )
}

/// Colour of a processing case in the trajectory and bar figures: a name starting with
/// the paper's tag `(a)`, `(b)`, … gets the tag's colour of [`PALETTE`] (so `(b) room
/// cal` has the same colour whether or not `(a) raw` is shown); any other name the
/// colour of its position `i`.
pub fn case_color(name: &str, i: usize) -> Color {
    let tag = name.trim_start().as_bytes();
    let idx = match tag {
        [b'(', c @ b'a'..=b'z', b')', ..] => usize::from(c - b'a'),
        _ => i,
    };
    PALETTE[idx % PALETTE.len()]
}

/// `fig` with its panels shrunk (aspect kept, not below 300 × 230 px) so the whole
/// figure is at most `max_width` px wide; figures already narrow enough are unchanged.
/// For figures built elsewhere (`allan_plot::figure`, `thermal_plot::thermal_figure`)
/// whose default panels make a grid too wide to read in a page.
pub fn fit_to_width(mut fig: Figure, max_width: f64) -> Figure {
    let cols = match (fig.panels.len(), fig.columns) {
        (0, _) => 1,
        (n, 0) => n,
        (n, c) => c.min(n),
    } as f64;
    let width = fig.panel_width * cols;
    if max_width.is_finite() && max_width > 0.0 && width > max_width {
        let k = (max_width / width).max(MIN_PANEL.0 / fig.panel_width);
        fig.panel_height = (fig.panel_height * k).max(MIN_PANEL.1);
        fig.panel_width *= k;
    }
    fig
}

/// `[north, east]` points as `(east, north)`, i.e. `(x, y)` (non-finite ones pass through;
/// the plot skips them).
fn en(points: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    points.iter().map(|p| (p[1], p[0])).unzip()
}

/// `(min, max)` of the finite values, `None` if there are none.
fn extent<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((a, b)) => Some((a.min(v), b.max(v))),
        })
}

fn union(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<(f64, f64)> {
    match (a, b) {
        (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
        (a, None) => a,
        (None, b) => b,
    }
}

/// The seed paper's Fig. 2: the north-east trajectory on equal axes (x east, y north,
/// metres). The full reference is a thin dark line; inside each GNSS outage its track is
/// highlighted and labelled `#1`, `#2`, … at the outage's start; each named solution
/// (e.g. `"(c) room + thermal"`) draws its track inside every outage (one `Vec` per
/// outage) in its own colour ([`case_color`]).
///
/// The view is fitted to the reference and the outage tracks and extended by at most
/// half their span on each side for the solutions: a solution that drifts kilometres
/// away runs off the frame (clipped) instead of shrinking the trajectory to a dot. Its
/// error is in [`outage_bars_figure`]. Non-finite points break a track.
pub fn trajectory_figure(
    reference_ne_m: &[[f64; 2]],
    outage_tracks_ne_m: &[Vec<[f64; 2]>],
    solutions: &[(String, Vec<Vec<[f64; 2]>>)],
) -> Figure {
    let mut plot = Plot::linear(
        "Trajectory and GNSS outages (north-east)",
        "east (m)",
        "north (m)",
    )
    .with_equal_aspect();
    plot.legend = LegendPosition::Auto;

    // Highlights first, so the reference line is drawn on top of them.
    for (k, track) in outage_tracks_ne_m.iter().enumerate() {
        let (x, y) = en(track);
        let name = if k == 0 {
            "GNSS outage (reference)"
        } else {
            ""
        };
        plot.lines.push(
            Line::new(name, x, y)
                .with_color(OUTAGE_HIGHLIGHT)
                .with_width(7.0),
        );
    }
    let (rx, ry) = en(reference_ne_m);
    plot.lines.push(
        Line::new("reference", rx, ry)
            .with_color(Color::DARK_GREY)
            .with_width(1.0),
    );
    for (i, (name, tracks)) in solutions.iter().enumerate() {
        let mut first = true;
        for track in tracks {
            let (x, y) = en(track);
            let label = if first && !x.is_empty() {
                first = false;
                name.as_str()
            } else {
                ""
            };
            plot.lines.push(
                Line::new(label, x, y)
                    .with_color(case_color(name, i))
                    .with_width(1.8),
            );
        }
    }
    for (k, track) in outage_tracks_ne_m.iter().enumerate() {
        if let Some(p) = track.iter().find(|p| p[0].is_finite() && p[1].is_finite()) {
            plot.annotations
                .push(Annotation::new(format!("#{}", k + 1), p[1], p[0]));
        }
    }

    // View: reference and outages, plus the solutions within half a span.
    let base_pts = reference_ne_m
        .iter()
        .chain(outage_tracks_ne_m.iter().flatten());
    let base_pts: Vec<[f64; 2]> = base_pts.copied().collect();
    let bx = extent(base_pts.iter().map(|p| &p[1]));
    let by = extent(base_pts.iter().map(|p| &p[0]));
    let sol_pts: Vec<[f64; 2]> = solutions
        .iter()
        .flat_map(|(_, t)| t.iter().flatten())
        .copied()
        .collect();
    let sx = extent(sol_pts.iter().map(|p| &p[1]));
    let sy = extent(sol_pts.iter().map(|p| &p[0]));
    let limit = |b: Option<(f64, f64)>, s: Option<(f64, f64)>| -> Option<(f64, f64)> {
        match (b, s) {
            (Some(b), Some(s)) => {
                let half = 0.5 * (b.1 - b.0).max(1.0);
                Some((s.0.max(b.0 - half).min(b.0), s.1.min(b.1 + half).max(b.1)))
            }
            (b, s) => union(b, s),
        }
    };
    let pad = |r: (f64, f64)| {
        let p = 0.04 * (r.1 - r.0).max(1.0);
        (r.0 - p, r.1 + p)
    };
    let (xr, yr) = (limit(bx, sx).map(pad), limit(by, sy).map(pad));
    plot.x_range = xr;
    plot.y_range = yr;

    // Panel height from the trajectory's shape, so equal axes leave little white space.
    let plot_w = FIGURE_WIDTH - 110.0;
    let height = match (xr, yr) {
        (Some(x), Some(y)) if x.1 > x.0 && y.1 > y.0 => {
            (plot_w * (y.1 - y.0) / (x.1 - x.0) + 110.0).clamp(420.0, 860.0)
        }
        _ => 560.0,
    };
    Figure::single(plot).with_panel_size(FIGURE_WIDTH, height)
}

/// Grouped bars, one group per outage (labelled by `outage_labels`, `#k` where a label
/// is missing) and one bar per case in its [`case_color`]: the seed paper's Table 1 as a
/// chart. `cases[c].1[k]` is case `c`'s value in outage `k`.
///
/// With `log_y` the bars rise from the bottom of a log axis, so values from 0.1 m to
/// 10 km compare on one chart. A value the axis cannot show (NaN, ±∞, or ≤ 0 with
/// `log_y`) — and a case with fewer values than there are outages — gets no bar but an
/// `n/a` note at its slot. Each bar is labelled with its value where it fits; the top
/// of the y range leaves room for the legend.
pub fn outage_bars_figure(
    outage_labels: &[String],
    cases: &[(String, Vec<f64>)],
    y_label: &str,
    log_y: bool,
) -> Figure {
    grouped_bars_figure(
        "Error per GNSS outage",
        "GNSS outage",
        outage_labels,
        cases,
        y_label,
        log_y,
    )
}

/// [`outage_bars_figure`] for any grouping (e.g. one group per Monte Carlo run), with
/// its own title and x-axis label; groups without a label are numbered `#k`.
pub fn grouped_bars_figure(
    title: &str,
    x_label: &str,
    outage_labels: &[String],
    cases: &[(String, Vec<f64>)],
    y_label: &str,
    log_y: bool,
) -> Figure {
    let groups = cases
        .iter()
        .map(|(_, v)| v.len())
        .fold(outage_labels.len(), usize::max);
    let nc = cases.len().max(1);
    let slot = 0.8 / nc as f64;
    let mut plot = Plot::linear(title, x_label, y_label);
    if log_y {
        plot.y_scale = AxisScale::Log;
    }
    plot.x_range = Some((0.5, groups as f64 + 0.5));
    plot.x_tick_labels = Some(
        (0..groups)
            .map(|k| {
                let label = outage_labels
                    .get(k)
                    .map(|l| l.trim())
                    .filter(|l| !l.is_empty())
                    .map_or_else(|| format!("#{}", k + 1), str::to_owned);
                ((k + 1) as f64, label)
            })
            .collect(),
    );
    let shown = |v: f64| v.is_finite() && (!log_y || v > 0.0);
    for (c, (name, values)) in cases.iter().enumerate() {
        let offset = (c as f64 - (nc as f64 - 1.0) / 2.0) * slot;
        let x: Vec<f64> = (0..groups).map(|k| (k + 1) as f64 + offset).collect();
        let y: Vec<f64> = (0..groups)
            .map(|k| values.get(k).copied().unwrap_or(f64::NAN))
            .collect();
        plot.bars.push(
            Bars::new(name.clone(), x, y)
                .with_width(slot * 0.9)
                .with_color(case_color(name, c))
                .with_missing_label("n/a")
                .with_value_labels(),
        );
    }

    // y range: the data, room for the value labels, and a band at the top as tall as
    // the legend so it does not cover the bars.
    let panel_h = 440.0;
    let plot_h = panel_h - 100.0;
    let legend_px = 8.0 + 18.0 * cases.len() as f64 + 16.0;
    let label_px = 18.0;
    let top_fraction = ((legend_px + label_px) / plot_h).min(0.6);
    let values = cases.iter().flat_map(|(_, v)| v.iter().copied());
    let data = extent(values.filter(|v| shown(*v)).collect::<Vec<_>>().iter());
    plot.y_range = data.map(|(lo, hi)| {
        if log_y {
            let lo_l = lo.log10() - 0.3;
            let hi_l = hi.log10();
            let span = (hi_l - lo_l).max(0.5);
            let top = lo_l + span / (1.0 - top_fraction);
            (10f64.powf(lo_l), 10f64.powf(top))
        } else {
            let lo = lo.min(0.0);
            let hi = hi.max(0.0);
            let span = if hi > lo { hi - lo } else { 1.0 };
            (lo, lo + span / (1.0 - top_fraction))
        }
    });
    Figure::single(plot).with_panel_size(FIGURE_WIDTH, panel_h)
}

/// One case's error curves, one per outage: `(seconds since the outage began, error)`.
pub(crate) type GrowthCurves = Vec<Vec<(f64, f64)>>;

/// Error growth inside the outages on a linear y axis: see
/// [`error_growth_figure_scaled`].
pub fn error_growth_figure(cases: &[(String, GrowthCurves)], y_label: &str) -> Figure {
    error_growth_figure_scaled(cases, y_label, AxisScale::Linear)
}

/// Error growth inside each outage: one panel per case (titled with its name), one line
/// per outage (`#1`, `#2`, …, the same colour in every panel) of `(seconds since the
/// outage began, error)`. All panels share their x and y ranges, so the cases compare
/// by eye. `y_scale` [`AxisScale::Log`] shows small and large errors together (values
/// ≤ 0 are then not drawn).
pub fn error_growth_figure_scaled(
    cases: &[(String, GrowthCurves)],
    y_label: &str,
    y_scale: AxisScale,
) -> Figure {
    let log = y_scale == AxisScale::Log;
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for (_, outages) in cases {
        for &(t, e) in outages.iter().flatten() {
            if t.is_finite() && e.is_finite() && (!log || e > 0.0) {
                xs.push(t);
                ys.push(e);
            }
        }
    }
    let x_range = extent(&xs).map(|(a, b)| {
        let a = a.min(0.0);
        if b > a { (a, b) } else { (a, a + 1.0) }
    });
    let y_range = extent(&ys).map(|(a, b)| {
        if log {
            (a / 1.5, if b > a { b * 1.5 } else { a * 10.0 })
        } else {
            let lo = a.min(0.0);
            let span = if b > lo { b - lo } else { 1.0 };
            (lo, lo + span * 1.05)
        }
    });
    let panels: Vec<Plot> = cases
        .iter()
        .map(|(name, outages)| {
            let mut p = Plot::linear(name.clone(), "time since outage start (s)", y_label);
            p.y_scale = y_scale;
            p.x_range = x_range;
            p.y_range = y_range;
            for (k, track) in outages.iter().enumerate() {
                let (x, y): (Vec<f64>, Vec<f64>) = track.iter().copied().unzip();
                let (color, style) = outage_style(k);
                p.lines.push(
                    Line::new(format!("#{}", k + 1), x, y)
                        .with_color(color)
                        .with_style(style)
                        .with_width(1.6),
                );
            }
            p
        })
        .collect();
    let (cols, w, h) = match panels.len() {
        0 | 1 => (1, FIGURE_WIDTH, 420.0),
        2 => (2, FIGURE_WIDTH / 2.0, 380.0),
        4 => (2, FIGURE_WIDTH / 2.0, 340.0),
        _ => (3, FIGURE_WIDTH / 3.0, 340.0),
    };
    Figure::grid(panels, cols)
        .with_title("Error growth inside the GNSS outages")
        .with_panel_size(w, h)
}

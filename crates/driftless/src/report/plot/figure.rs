//! Plain input data for plots: what to draw, not how.
//!
//! These types deliberately know nothing about Allan deviations or IMUs; the
//! caller converts its results (taus, deviations, confidence intervals, fitted
//! noise terms) into [`Series`] and [`Line`]s. All fields are public and every
//! type has a [`Default`], so both struct literals and the small builder
//! methods work.

/// An sRGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Color {
    pub r: u8,
    pub g: u8,
    pub b: u8,
}

impl Color {
    pub const BLACK: Color = Color::rgb(0, 0, 0);
    pub const WHITE: Color = Color::rgb(255, 255, 255);
    /// Dark grey used for text and model lines by default.
    pub const DARK_GREY: Color = Color::rgb(0x33, 0x33, 0x33);
    /// Mid grey.
    pub const GREY: Color = Color::rgb(0x77, 0x77, 0x77);

    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Color { r, g, b }
    }

    /// Parses `#rrggbb` or `rrggbb` (case-insensitive). `None` on anything else.
    pub fn from_hex(s: &str) -> Option<Self> {
        let h = s.strip_prefix('#').unwrap_or(s);
        if h.len() != 6 || !h.is_ascii() {
            return None;
        }
        let p = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).ok();
        Some(Color::rgb(p(0)?, p(2)?, p(4)?))
    }

    /// `#rrggbb`, lower-case.
    pub fn to_hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.r, self.g, self.b)
    }
}

/// The default series colours (Okabe–Ito, colour-blind safe; yellow omitted
/// because it is unreadable on white). Series without an explicit colour
/// cycle through this list in order.
pub const PALETTE: [Color; 7] = [
    Color::rgb(0x00, 0x72, 0xb2), // blue
    Color::rgb(0xd5, 0x5e, 0x00), // vermillion
    Color::rgb(0x00, 0x9e, 0x73), // bluish green
    Color::rgb(0xcc, 0x79, 0xa7), // reddish purple
    Color::rgb(0xe6, 0x9f, 0x00), // orange
    Color::rgb(0x56, 0xb4, 0xe9), // sky blue
    Color::rgb(0x00, 0x00, 0x00), // black
];

/// Marker drawn at each data point of a [`Series`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum MarkerShape {
    #[default]
    Circle,
    Square,
    Triangle,
    Diamond,
    /// No marker (the series is then usually drawn with `connect = true`).
    None,
}

/// Default marker shapes, cycled like [`PALETTE`] so that series stay
/// distinguishable in grey-scale print.
pub(crate) const MARKER_CYCLE: [MarkerShape; 4] = [
    MarkerShape::Circle,
    MarkerShape::Square,
    MarkerShape::Triangle,
    MarkerShape::Diamond,
];

/// Stroke pattern of a [`Line`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LineStyle {
    #[default]
    Solid,
    Dashed,
    Dotted,
}

/// Measured points: markers, an optional thin connecting line and optional
/// confidence-interval error bars (`y_lo[i] ..= y_hi[i]` at `x[i]`).
///
/// Points that an axis cannot show are skipped (not finite, or not positive
/// on a log axis); if the vectors differ in length the extra elements are
/// ignored. On a linear y axis the CI bounds may be negative.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend entry; an empty name keeps the series out of the legend.
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    /// Lower CI bound per point (error bar bottom).
    pub y_lo: Option<Vec<f64>>,
    /// Upper CI bound per point (error bar top).
    pub y_hi: Option<Vec<f64>>,
    /// `None`: next colour of [`PALETTE`].
    pub color: Option<Color>,
    /// `None`: next shape of `MARKER_CYCLE`.
    pub marker: Option<MarkerShape>,
    /// Join consecutive valid points with a thin line.
    pub connect: bool,
    /// Draw the CI (`y_lo`, `y_hi`) as a translucent shaded band between
    /// consecutive valid points instead of error bars (e.g. the confidence
    /// band of a fitted curve).
    pub band: bool,
}

impl Series {
    /// Markers joined by a thin line, no error bars, automatic colour.
    pub fn new(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            name: name.into(),
            x,
            y,
            connect: true,
            ..Default::default()
        }
    }

    /// Adds confidence-interval error bars.
    pub fn with_ci(mut self, y_lo: Vec<f64>, y_hi: Vec<f64>) -> Self {
        self.y_lo = Some(y_lo);
        self.y_hi = Some(y_hi);
        self
    }

    /// Adds a confidence band: like [`with_ci`](Self::with_ci), drawn as a
    /// shaded area rather than error bars.
    pub fn with_band(mut self, y_lo: Vec<f64>, y_hi: Vec<f64>) -> Self {
        self.band = true;
        self.with_ci(y_lo, y_hi)
    }

    pub fn with_color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }

    pub fn with_marker(mut self, marker: MarkerShape) -> Self {
        self.marker = Some(marker);
        self
    }

    pub fn connected(mut self, connect: bool) -> Self {
        self.connect = connect;
        self
    }
}

/// A curve: a fitted model, or a per-term asymptote, optionally with a text
/// label (e.g. `"N = 0.152 deg/√h"`) that the layout places next to the
/// visible part of the line, away from other labels, the legend and the data.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Line {
    /// Legend entry; an empty name keeps the line out of the legend.
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: LineStyle,
    /// `None`: dark grey.
    pub color: Option<Color>,
    /// Stroke width in px; `None`: 1.5.
    pub width: Option<f64>,
    /// Text drawn next to the line.
    pub label: Option<String>,
    /// Preferred x (data units) for the label, e.g. where the asymptote
    /// dominates. `None`: anywhere reasonable, middle preferred.
    pub label_x: Option<f64>,
}

impl Line {
    pub fn new(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Line {
            name: name.into(),
            x,
            y,
            ..Default::default()
        }
    }

    /// The power law `y = coeff · x^exponent`, sampled at `n` log-spaced
    /// points on `[x_min, x_max]` (asymptotes: −½ white noise, 0 flicker,
    /// +½ random walk …). Invalid ranges give an empty (invisible) line.
    pub fn power_law(
        name: impl Into<String>,
        coeff: f64,
        exponent: f64,
        x_min: f64,
        x_max: f64,
        n: usize,
    ) -> Self {
        let mut line = Line::new(name, Vec::new(), Vec::new());
        let ok = x_min.is_finite() && x_max.is_finite() && x_min > 0.0 && x_max > x_min;
        if ok && n > 0 {
            let n = n.max(2);
            let (a, b) = (x_min.log10(), x_max.log10());
            for i in 0..n {
                let x = 10f64.powf(a + (b - a) * i as f64 / (n - 1) as f64);
                line.x.push(x);
                line.y.push(coeff * x.powf(exponent));
            }
        }
        line
    }

    pub fn dashed(mut self) -> Self {
        self.style = LineStyle::Dashed;
        self
    }

    pub(crate) fn with_style(mut self, style: LineStyle) -> Self {
        self.style = style;
        self
    }

    pub fn with_color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }

    pub fn with_width(mut self, width: f64) -> Self {
        self.width = Some(width);
        self
    }

    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Preferred x position (data units) of the label.
    pub fn with_label_at(mut self, x: f64) -> Self {
        self.label_x = Some(x);
        self
    }
}

/// Free text at a data point, optionally with a small open-circle marker
/// (e.g. "bias instability" at the minimum of the curve).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Annotation {
    pub text: String,
    pub x: f64,
    pub y: f64,
    pub marker: bool,
    /// `None`: dark grey.
    pub color: Option<Color>,
}

impl Annotation {
    pub fn new(text: impl Into<String>, x: f64, y: f64) -> Self {
        Annotation {
            text: text.into(),
            x,
            y,
            marker: true,
            color: None,
        }
    }
}

/// Vertical bars (a bar chart, or one case of a grouped bar chart): bar `i`
/// is centred on `x[i]` and reaches from the baseline to `y[i]`.
///
/// The baseline is 0 on a linear y axis and the bottom of the axis on a log
/// y axis (log bars have no natural zero). Values the y axis cannot show
/// (NaN and ±∞; zero and negatives on a log axis) get no bar; with
/// [`missing_label`](Self::missing_label) that text is written at the foot
/// of the empty slot instead, so a missing value is not mistaken for a small
/// one. Bars use the next colour of [`PALETTE`] after the panel's series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Bars {
    /// Legend entry; an empty name keeps the bars out of the legend.
    pub name: String,
    /// Bar centres (data units).
    pub x: Vec<f64>,
    /// Bar tops (data units).
    pub y: Vec<f64>,
    /// Bar width in x data units; non-finite or non-positive: 0.8 × the
    /// smallest spacing of `x` (0.8 for a single bar).
    pub width: f64,
    /// `None`: next colour of [`PALETTE`].
    pub color: Option<Color>,
    /// Text at the foot of a bar whose value cannot be shown (e.g. `"n/a"`).
    pub missing_label: Option<String>,
    /// Print each bar's value (3 significant digits) above it, where it fits.
    pub value_labels: bool,
}

impl Bars {
    /// Bars with automatic width and colour, no value labels.
    pub fn new(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Bars {
            name: name.into(),
            x,
            y,
            ..Default::default()
        }
    }

    /// Bar width in x data units.
    pub fn with_width(mut self, width: f64) -> Self {
        self.width = width;
        self
    }

    pub fn with_color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }

    /// Text shown where a value cannot be drawn.
    pub fn with_missing_label(mut self, label: impl Into<String>) -> Self {
        self.missing_label = Some(label.into());
        self
    }

    /// Prints the values above the bars.
    pub fn with_value_labels(mut self) -> Self {
        self.value_labels = true;
        self
    }
}

/// Where a panel's legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LegendPosition {
    /// The inside corner that hides the least data.
    #[default]
    Auto,
    TopLeft,
    TopRight,
    BottomLeft,
    BottomRight,
    Hidden,
}

/// How an axis maps data onto the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum AxisScale {
    /// Log₁₀ axis with decade ticks; only finite positive values are shown.
    #[default]
    Log,
    /// Linear axis with 1-2-5 × 10ᵏ ticks; any finite value is shown
    /// (negatives and zero included).
    Linear,
}

/// The historical name of [`Plot`] (log-log is still the default).
pub type LogLogPlot = Plot;

/// One panel: log-log by default (Allan deviation), either axis can be
/// switched to linear with [`Plot::linear_x`] / [`Plot::linear_y`] or
/// created linear-linear with [`Plot::linear`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plot {
    pub title: String,
    /// Axis title including the unit, e.g. `"τ (s)"`.
    pub x_label: String,
    /// Axis title including the unit, e.g. `"σ(τ) (deg/h)"`.
    pub y_label: String,
    pub series: Vec<Series>,
    pub lines: Vec<Line>,
    pub annotations: Vec<Annotation>,
    /// Bar groups, drawn above the grid and below lines and series.
    pub bars: Vec<Bars>,
    /// Fixed x range (data units). `None`: fitted to the series (and, if
    /// there are no series, the lines), with a small margin.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range (data units), as `x_range`.
    pub y_range: Option<(f64, f64)>,
    pub legend: LegendPosition,
    /// Scale of the x axis (default [`AxisScale::Log`]).
    pub x_scale: AxisScale,
    /// Scale of the y axis (default [`AxisScale::Log`]).
    pub y_scale: AxisScale,
    /// Explicit x ticks `(position in data units, label)` replacing the
    /// automatic ones, e.g. the categories of a bar chart. They get tick
    /// marks and labels but no vertical grid lines; labels that would collide
    /// are thinned to every n-th.
    pub x_tick_labels: Option<Vec<(f64, String)>>,
    /// One data unit is as long in x as in y (maps, trajectories): the
    /// shorter range is widened about its centre. Only when both axes are
    /// linear; ignored otherwise.
    pub equal_aspect: bool,
}

impl Plot {
    /// A log-log panel.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Plot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Default::default()
        }
    }

    /// A panel with both axes linear (e.g. bias vs temperature).
    pub fn linear(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Plot::new(title, x_label, y_label).linear_x().linear_y()
    }

    /// Makes the x axis linear.
    pub fn linear_x(mut self) -> Self {
        self.x_scale = AxisScale::Linear;
        self
    }

    /// Makes the y axis linear.
    pub fn linear_y(mut self) -> Self {
        self.y_scale = AxisScale::Linear;
        self
    }

    /// Sets both axis scales.
    pub fn with_scales(mut self, x: AxisScale, y: AxisScale) -> Self {
        self.x_scale = x;
        self.y_scale = y;
        self
    }

    /// Fixes the x range (data units).
    pub fn with_x_range(mut self, min: f64, max: f64) -> Self {
        self.x_range = Some((min, max));
        self
    }

    /// Fixes the y range (data units).
    pub fn with_y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }

    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    pub fn with_line(mut self, line: Line) -> Self {
        self.lines.push(line);
        self
    }

    pub fn with_annotation(mut self, annotation: Annotation) -> Self {
        self.annotations.push(annotation);
        self
    }

    pub fn with_bars(mut self, bars: Bars) -> Self {
        self.bars.push(bars);
        self
    }

    /// Replaces the automatic x ticks by labelled positions (categories).
    pub fn with_x_tick_labels(mut self, ticks: Vec<(f64, String)>) -> Self {
        self.x_tick_labels = Some(ticks);
        self
    }

    /// Keeps one data unit equally long on both (linear) axes.
    pub fn with_equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }
}

/// Default size of one panel in px (CSS px in SVG; PNG multiplies by its
/// scale factor).
pub(crate) const DEFAULT_PANEL_SIZE: (f64, f64) = (640.0, 480.0);

/// One or more panels on a grid, with an optional overall title.
///
/// A six-axis IMU report is typically `Figure::grid(vec![gyro, accel], 2)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    pub title: Option<String>,
    pub panels: Vec<Plot>,
    /// Panels per row; `0` means all in one row.
    pub columns: usize,
    /// Size of each panel cell in px.
    pub panel_width: f64,
    pub panel_height: f64,
}

impl Default for Figure {
    fn default() -> Self {
        Figure {
            title: None,
            panels: Vec::new(),
            columns: 0,
            panel_width: DEFAULT_PANEL_SIZE.0,
            panel_height: DEFAULT_PANEL_SIZE.1,
        }
    }
}

impl Figure {
    pub fn single(plot: Plot) -> Self {
        Figure {
            panels: vec![plot],
            ..Default::default()
        }
    }

    /// Panels laid out row-major, `columns` per row (`0`: one row).
    pub fn grid(panels: Vec<Plot>, columns: usize) -> Self {
        Figure {
            panels,
            columns,
            ..Default::default()
        }
    }

    pub fn with_title(mut self, title: impl Into<String>) -> Self {
        self.title = Some(title.into());
        self
    }

    pub fn with_panel_size(mut self, width: f64, height: f64) -> Self {
        self.panel_width = width;
        self.panel_height = height;
        self
    }
}

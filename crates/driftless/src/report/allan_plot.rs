//! The Allan-deviation figure: one log-log panel per channel with the deviation and its
//! confidence bars, the fitted noise model, and each fitted term's asymptote labelled
//! with its value (IEEE Std 952-1997 Annex C slopes: Q −1, N −½, B 0, K +½, R +1).

use super::plot::{Annotation, Color, Figure, Line, LogLogPlot, PALETTE, PlotError, Series};
use crate::allan::analysis::ChannelResult;
use crate::allan::fit::{NoiseFit, gauss_markov_avar};
use crate::io::log::Quantity;
use driftless_model::units::{DEG, DEG_PER_H, MILLI_G};
use std::path::Path;

/// Display unit of a deviation axis: (factor SI→display, label).
fn axis_unit(q: Quantity, fallback: &str) -> (f64, String) {
    match q {
        Quantity::AngularRate => (1.0 / DEG_PER_H, "deg/h".into()),
        Quantity::SpecificForce => (1.0 / MILLI_G, "mg".into()),
        _ => (
            1.0,
            if fallback.is_empty() {
                "data units".into()
            } else {
                fallback.into()
            },
        ),
    }
}

/// Term labels in the units engineers quote (continuous-time densities).
fn term_label(term: char, q: Quantity, v: f64) -> String {
    let s = |x: f64| format_sig(x);
    match (q, term) {
        (Quantity::AngularRate, 'Q') => format!("Q = {} µrad", s(v * 1e6)),
        (Quantity::AngularRate, 'N') => format!("N = {} deg/√h", s(v / DEG * 60.0)),
        (Quantity::AngularRate, 'B') => format!("B = {} deg/h", s(v / DEG_PER_H)),
        (Quantity::AngularRate, 'K') => format!("K = {} deg/h/√h", s(v / DEG * 3600.0 * 60.0)),
        (Quantity::AngularRate, 'R') => format!("R = {} deg/h²", s(v / DEG * 3600.0 * 3600.0)),
        (Quantity::SpecificForce, 'Q') => format!("Q = {} mm/s", s(v * 1e3)),
        (Quantity::SpecificForce, 'N') => format!("N = {} m/s/√h", s(v * 60.0)),
        (Quantity::SpecificForce, 'B') => format!("B = {} µg", s(v / MILLI_G * 1e3)),
        (Quantity::SpecificForce, 'K') => format!("K = {} m/s²/√s", s(v)),
        (Quantity::SpecificForce, 'R') => format!("R = {} m/s³", s(v)),
        (_, t) => format!("{t} = {}", s(v)),
    }
}

fn format_sig(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() {
        format!("{x}")
    } else if !(1e-3..1e4).contains(&a) {
        format!("{x:.2e}")
    } else {
        let d = (2 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.d$}")
    }
}

/// Build the figure. `fits[i]` (if any) belongs to `results[i]`.
pub fn figure(
    title: &str,
    results: &[ChannelResult],
    quantities: &[Quantity],
    units: &[String],
    fits: &[Option<&NoiseFit>],
) -> Figure {
    let mut panels = Vec::with_capacity(results.len());
    for (i, r) in results.iter().enumerate() {
        let q = quantities.get(i).copied().unwrap_or(Quantity::Other);
        let (k, unit) = axis_unit(q, units.get(i).map(String::as_str).unwrap_or(""));
        let color: Color = PALETTE[i % PALETTE.len()];
        let tau: Vec<f64> = r.points.iter().map(|p| p.tau).collect();
        let dev: Vec<f64> = r.points.iter().map(|p| p.dev * k).collect();
        let lo: Vec<f64> = r.dev_lo.iter().map(|v| v * k).collect();
        let hi: Vec<f64> = r.dev_hi.iter().map(|v| v * k).collect();
        // y range: the data with its bars, extended down to the flicker floor 0.664·B,
        // which lies below the curve's minimum (white noise and rate random walk still add
        // there) and would otherwise be clipped away.
        let y_range = y_range(&dev, &lo, &hi, fits.get(i).copied().flatten(), k);
        let mut plot = LogLogPlot::new(
            format!("{} — {}", r.name, r.estimator.name().to_uppercase()),
            "averaging time τ (s)",
            format!("σ(τ) ({unit})"),
        )
        .with_series(
            Series::new(
                format!("{} ({:.1} % CI)", r.name, 100.0 * r.confidence),
                tau.clone(),
                dev.clone(),
            )
            .with_ci(lo, hi)
            .with_color(color),
        );
        if let Some(Some(f)) = fits.get(i) {
            plot = with_model(plot, f, q, k, &tau, &dev);
        }
        plot.y_range = y_range;
        panels.push(plot);
    }
    let cols = match panels.len() {
        0..=1 => 1,
        2 | 4 => 2,
        _ => 3,
    };
    Figure::grid(panels, cols).with_title(title)
}

/// y range of a panel: the data with its bars, extended down to the flicker floor 0.664·B,
/// which lies below the curve's minimum (white noise and rate random walk still add
/// there) and would otherwise be clipped away. `k` converts to the display unit.
fn y_range(
    dev: &[f64],
    lo: &[f64],
    hi: &[f64],
    fit: Option<&NoiseFit>,
    k: f64,
) -> Option<(f64, f64)> {
    let pos = |v: &f64| v.is_finite() && *v > 0.0;
    let data_min = dev
        .iter()
        .chain(lo)
        .copied()
        .filter(pos)
        .fold(f64::INFINITY, f64::min);
    let data_max = dev
        .iter()
        .chain(hi)
        .copied()
        .filter(pos)
        .fold(0.0, f64::max);
    let floor = fit
        .and_then(|f| f.bias_instability)
        .filter(|t| t.lo > 0.0)
        .map(|t| (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt() * t.value * k);
    (data_min.is_finite() && data_max > 0.0).then(|| {
        let bottom = floor.filter(pos).map_or(data_min, |f| f.min(data_min));
        (bottom / 1.3, data_max * 1.3)
    })
}

/// The fitted model on a panel: the model curve, the asymptote of each term whose interval
/// excludes zero (the others are listed in the noise table with their intervals), the
/// Gauss-Markov term, and the curve's minimum marked.
fn with_model(
    mut plot: LogLogPlot,
    f: &NoiseFit,
    q: Quantity,
    k: f64,
    tau: &[f64],
    dev: &[f64],
) -> LogLogPlot {
    let (tmin, tmax) = (
        tau.first().copied().unwrap_or(1.0),
        tau.last().copied().unwrap_or(10.0),
    );
    let model = Line::new(
        "fitted model",
        tau.to_vec(),
        tau.iter().map(|&t| f.model_avar(t).sqrt() * k).collect(),
    )
    .with_color(Color::rgb(0x20, 0x20, 0x20));
    plot = plot.with_line(model);
    let grey = Color::rgb(0x70, 0x70, 0x70);
    // Draw only terms whose interval excludes zero; the others are listed in the
    // noise table with their intervals.
    let significant = |t: &crate::allan::fit::Term| t.lo > 0.0;
    let mut asym = |name: &str, term: char, v: f64, coeff: f64, exp: f64, at: f64| {
        let l = Line::power_law(name, coeff * k, exp, tmin, tmax, 32)
            .dashed()
            .with_color(grey)
            .with_label(term_label(term, q, v))
            .with_label_at(at);
        plot.lines.push(l);
    };
    let geo = |a: f64, b: f64| (a * b).sqrt();
    if let Some(t) = f.quantization.filter(significant) {
        asym(
            "Q asymptote",
            'Q',
            t.value,
            3f64.sqrt() * t.value,
            -1.0,
            tmin * 2.0,
        );
    }
    if let Some(t) = f.white.filter(significant) {
        asym(
            "N asymptote",
            'N',
            t.value,
            t.value,
            -0.5,
            geo(tmin, geo(tmin, tmax)),
        );
    }
    if let Some(t) = f.bias_instability.filter(significant) {
        let c = (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt();
        asym(
            "B asymptote",
            'B',
            t.value,
            c * t.value,
            0.0,
            geo(tmin, tmax),
        );
    }
    if let Some(t) = f.rate_random_walk.filter(significant) {
        asym(
            "K asymptote",
            'K',
            t.value,
            t.value / 3f64.sqrt(),
            0.5,
            geo(geo(tmin, tmax), tmax),
        );
    }
    if let Some(t) = f.rate_ramp.filter(significant) {
        asym(
            "R asymptote",
            'R',
            t.value,
            t.value / 2f64.sqrt(),
            1.0,
            tmax / 2.0,
        );
    }
    if let Some(gm) = f.gauss_markov.filter(|g| significant(&g.sigma)) {
        let (s, tc) = (gm.sigma.value, gm.tau_c_s.value);
        let y: Vec<f64> = tau
            .iter()
            .map(|&t| gauss_markov_avar(s, tc, t).sqrt() * k)
            .collect();
        plot.lines.push(
            Line::new("Gauss-Markov term", tau.to_vec(), y)
                .dashed()
                .with_color(grey)
                .with_label(format!(
                    "GM σ = {}, T = {} s",
                    format_sig(s * k),
                    format_sig(tc)
                )),
        );
    }
    // Mark the curve's minimum (where bias instability is read classically).
    if let Some((j, _)) = dev
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite() && **v > 0.0)
        .min_by(|a, b| a.1.total_cmp(b.1))
    {
        plot = plot.with_annotation(Annotation::new("minimum", tau[j], dev[j]));
    }
    plot
}

/// Write the figure to `path`: `.png` → PNG (needs the `png` feature), anything else SVG.
pub fn write(
    path: &Path,
    title: &str,
    results: &[ChannelResult],
    quantities: &[Quantity],
    units: &[String],
    fits: &[Option<&NoiseFit>],
) -> Result<(), PlotError> {
    super::plot::write_figure(&figure(title, results, quantities, units, fits), path)
}

/// One run of a replicate figure: its name (shown in the legend) and its curves.
pub struct RunCurves<'a> {
    /// Legend name of the run (its file name).
    pub name: &'a str,
    /// The run's curves (channels matched by name).
    pub results: &'a [ChannelResult],
}

/// Replicate runs of one sensor overlaid: one log-log panel per channel (the first run's
/// channels, matched by name) with every run's deviation and confidence bars, and the
/// joint model `joint[i]` (fitted to the combined curves, see
/// [`crate::allan::replicates`]) over the τ span of the runs.
pub fn replicates_figure(
    title: &str,
    runs: &[RunCurves<'_>],
    quantities: &[Quantity],
    units: &[String],
    joint: &[Option<&NoiseFit>],
) -> Figure {
    let Some(first) = runs.first() else {
        return Figure::grid(Vec::new(), 1).with_title(title);
    };
    let mut panels = Vec::with_capacity(first.results.len());
    for (i, r0) in first.results.iter().enumerate() {
        let q = quantities.get(i).copied().unwrap_or(Quantity::Other);
        let (k, unit) = axis_unit(q, units.get(i).map(String::as_str).unwrap_or(""));
        let mut plot = LogLogPlot::new(
            format!(
                "{} — {}, {} runs",
                r0.name,
                r0.estimator.name().to_uppercase(),
                runs.len()
            ),
            "averaging time τ (s)",
            format!("σ(τ) ({unit})"),
        );
        let (mut tmin, mut tmax) = (f64::INFINITY, 0.0f64);
        let (mut ymin, mut ymax) = (f64::INFINITY, 0.0f64);
        for (j, run) in runs.iter().enumerate() {
            let Some(r) = run.results.iter().find(|c| c.name == r0.name) else {
                continue;
            };
            let tau: Vec<f64> = r.points.iter().map(|p| p.tau).collect();
            let dev: Vec<f64> = r.points.iter().map(|p| p.dev * k).collect();
            let lo: Vec<f64> = r.dev_lo.iter().map(|v| v * k).collect();
            let hi: Vec<f64> = r.dev_hi.iter().map(|v| v * k).collect();
            for v in dev.iter().chain(&lo).chain(&hi) {
                if v.is_finite() && *v > 0.0 {
                    ymin = ymin.min(*v);
                    ymax = ymax.max(*v);
                }
            }
            tmin = tmin.min(tau.first().copied().unwrap_or(tmin));
            tmax = tmax.max(tau.last().copied().unwrap_or(tmax));
            plot = plot.with_series(
                Series::new(
                    format!("{} ({:.1} % CI)", run.name, 100.0 * r.confidence),
                    tau,
                    dev,
                )
                .with_ci(lo, hi)
                .with_color(PALETTE[j % PALETTE.len()]),
            );
        }
        if let Some(Some(f)) = joint.get(i)
            && tmax > tmin
        {
            let n = 64;
            let tau: Vec<f64> = (0..=n)
                .map(|s| tmin * (tmax / tmin).powf(s as f64 / n as f64))
                .collect();
            let y: Vec<f64> = tau.iter().map(|&t| f.model_avar(t).sqrt() * k).collect();
            plot = plot.with_line(
                Line::new("joint model", tau, y).with_color(Color::rgb(0x20, 0x20, 0x20)),
            );
        }
        if ymin.is_finite() && ymax > 0.0 {
            plot.y_range = Some((ymin / 1.3, ymax * 1.3));
        }
        panels.push(plot);
    }
    let cols = match panels.len() {
        0..=1 => 1,
        2 | 4 => 2,
        _ => 3,
    };
    Figure::grid(panels, cols).with_title(title)
}

/// Write [`replicates_figure`] to `path` (`.png` → PNG with the `png` feature, else SVG).
pub fn write_replicates(
    path: &Path,
    title: &str,
    runs: &[RunCurves<'_>],
    quantities: &[Quantity],
    units: &[String],
    joint: &[Option<&NoiseFit>],
) -> Result<(), PlotError> {
    super::plot::write_figure(
        &replicates_figure(title, runs, quantities, units, joint),
        path,
    )
}

//! Choosing what the model is fitted to: the τ range (given, or past the short τ the
//! sensor's filtering colours, up to where the curve is known well enough) and the terms
//! the data support.

use crate::allan::AllanError;
use crate::allan::analysis::ChannelResult;
use crate::allan::fit::{
    CHI2_RED_GOOD, FitConfig, FitRangeSpec, NoiseFit, NotIdentifiable, RangeSource, Term, TermKind,
    UpperLimit,
};

use super::display::fmt_num;

/// Relative half-width of the 68.3 % interval of σ̂(τ) up to which the automatic fit
/// range reaches: a model can be held to ±10 % of the curve only where the curve itself
/// is known to 10 %.
pub(crate) const CURVE_PRECISION: f64 = 0.10;
/// Confidence level of the curve interval [`CURVE_PRECISION`] applies to (one σ).
pub(crate) const CURVE_PRECISION_CONFIDENCE: f64 = 0.683;

/// Fewest curve points the automatic range keeps, whatever their precision.
pub(crate) const AUTO_RANGE_MIN_POINTS: usize = 12;

/// End (exclusive) of the automatic fit range: before the first point whose 68.3 %
/// interval reaches beyond ±`precision` of σ̂, with the EDF ν of the long-τ noise types
/// (flicker and random-walk FM, the smaller of the two, so that the end does not depend
/// on a noise identification that is itself uncertain at long τ). σ̂² is ≈ σ²·χ²_ν/ν, so
/// the interval's wider, upper side is σ̂·√(ν/χ²_ν(0.1587)) (NIST SP 1065 §5.3); it stays
/// within +10 % for ν ≳ 68 — a few tens of independent averages. Beyond it the points
/// scatter by more than the tolerance a model is held to, and on real sensors the
/// longest τ carry slow effects (temperature, run-to-run changes of the bias) that no
/// stationary term describes; they stay on the curve, with their intervals, but do not
/// shape the model. At least `AUTO_RANGE_MIN_POINTS`
/// points are kept.
pub fn auto_fit_end(c: &ChannelResult, precision: f64) -> usize {
    let n = c.points.len();
    // The lower χ² point of the two-sided interval (Wilson–Hilferty: a few 0.1 % at the
    // ν of a few tens this decides at).
    let z_lo = crate::allan::fit::normal_quantile(0.5 * (1.0 - CURVE_PRECISION_CONFIDENCE));
    let end = (0..n)
        .position(|i| {
            let nu = c.edf_for_alpha(i, -1).min(c.edf_for_alpha(i, -2));
            !(nu.is_finite()
                && nu > 0.0
                && (nu / crate::allan::checks::chi2_quantile(nu, z_lo)).sqrt() <= 1.0 + precision)
        })
        .unwrap_or(n);
    end.max(AUTO_RANGE_MIN_POINTS).min(n)
}

/// Quantization above this multiple of Δτ0/√12 is not taken as quantization.
pub(crate) const QUANTIZATION_RESOLUTION_FACTOR: f64 = 3.0;

/// The curve points inside a user range, [i0, i1).
pub(super) fn user_indices(
    c: &ChannelResult,
    r: FitRangeSpec,
) -> Result<(usize, usize), AllanError> {
    let n = c.points.len();
    let tol = 1e-9;
    let lo = r.tau_min_s.map_or(0.0, |t| t * (1.0 - tol));
    let hi = r.tau_max_s.map_or(f64::INFINITY, |t| t * (1.0 + tol));
    let i0 = c.points.iter().position(|p| p.tau >= lo).unwrap_or(n);
    let i1 = c
        .points
        .iter()
        .rposition(|p| p.tau <= hi)
        .map_or(0, |i| i + 1);
    if i1 <= i0 {
        return Err(AllanError::Invalid(format!(
            "channel '{}': no curve point inside the fit range (the curve spans {} … {} s)",
            c.name,
            fmt_num(c.points.first().map_or(0.0, |p| p.tau)),
            fmt_num(c.points.last().map_or(0.0, |p| p.tau))
        )));
    }
    Ok((i0, i1))
}

/// Widens the interval of the white-noise term — the term the start of the range
/// decides — by the bias the sensor's filtering may leave at the start. That leftover
/// decays as 1/τ (a low-pass of time constant T_f changes σ²(τ) of white noise by
/// ≈ −3N²T_f/τ²; a decimation filter's is of the same form), so the bias of the fitted
/// θ = N² from a start τ_s is b(τ_s) ∝ 1/τ_s, and the fit from the next start r·τ_s
/// (`later`, r = `ratio` > 1) differs from the one from τ_s (`at_start`, same terms) by
/// Δ = θ_later − θ_start = −b(τ_s)·(1 − 1/r); hence b(τ_s) = −Δ·r/(r − 1) (Richardson's
/// extrapolation). The bias is systematic and its sign known, so the interval is
/// extended on that side by |b| (added to the statistical half-width, not in
/// quadrature); the value itself is left as fitted.
pub fn widen_for_the_start(fit: &mut NoiseFit, at_start: &NoiseFit, later: &NoiseFit, ratio: f64) {
    let (Some(t), Some(s0), Some(l)) = (fit.white.as_mut(), at_start.white, later.white) else {
        return;
    };
    if !(ratio.is_finite() && ratio > 1.0) {
        return;
    }
    let theta = t.value * t.value;
    let (lo, hi) = (t.lo * t.lo, t.hi * t.hi);
    // The truth lies on the side the later start moves towards.
    let shift = (l.value * l.value - s0.value * s0.value) * ratio / (ratio - 1.0);
    if !(shift.is_finite() && lo.is_finite() && hi.is_finite() && lo <= theta && theta <= hi) {
        return;
    }
    if shift > 0.0 {
        t.hi = (hi + shift).sqrt();
    } else {
        t.lo = (lo + shift).max(0.0).sqrt();
    }
}

/// The automatic fit range: the fit from each candidate first point (shortest first)
/// to the curve's end; the first whose χ²_red is at most [`CHI2_RED_GOOD`] over the whole
/// range *and* over its first half decade (`head(i0, fit)`: where a filter's leftover
/// shows, and where the whole-range χ²_red would dilute it) — the widest range over which
/// the model follows the curve within its uncertainty — or, if none is, the candidate
/// with the smallest χ²_red.
pub(super) fn auto_range<F, H>(
    candidates: &[usize],
    n: usize,
    fit_over: &F,
    head: &H,
) -> Result<(usize, usize, RangeSource, NoiseFit), AllanError>
where
    F: Fn(usize, usize) -> Result<NoiseFit, AllanError>,
    H: Fn(usize, &NoiseFit) -> f64,
{
    let mut best: Option<(usize, NoiseFit)> = None;
    let mut first_err = None;
    for &i0 in candidates {
        match fit_over(i0, n) {
            Ok(f) => {
                let good = f.chi2_reduced <= CHI2_RED_GOOD && head(i0, &f) <= CHI2_RED_GOOD;
                if best
                    .as_ref()
                    .is_none_or(|(_, b)| f.chi2_reduced < b.chi2_reduced)
                {
                    best = Some((i0, f));
                }
                if good {
                    break;
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    match (best, first_err) {
        (Some((i0, f)), _) => {
            let source = if i0 == 0 {
                RangeSource::Full
            } else {
                RangeSource::Auto
            };
            Ok((i0, n, source, f))
        }
        (None, Some(e)) => Err(e),
        (None, None) => Err(AllanError::Invalid("no curve point to fit".into())),
    }
}

/// What a term the data do not support is reported as instead of a value.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Unsupported {
    /// Its interval reaches zero: the upper end of the interval is the upper limit.
    UpperLimit(UpperLimit),
    /// Its value cannot be what the term describes (see [`least_supported_term`]).
    NotIdentifiable(NotIdentifiable),
}

/// The term of `fit` the data support least, if any does not stand:
/// * a quantization above `QUANTIZATION_RESOLUTION_FACTOR`·Δτ0/√12 — what angle
///   increments quantized at the rate resolution step Δ = `step` would give (IEEE Std
///   952-1997 C.1) — is not quantization (filtering, a spectral hump): not identifiable;
/// * otherwise, of the terms whose interval reaches zero, the one with the smallest
///   significance θ/(z·s_θ) (θ the squared coefficient, z·s_θ its interval half-width,
///   so θ/(z·s_θ) = v²/(hi² − v²)): an upper limit at its interval's upper end.
pub(crate) fn least_supported_term(
    fit: &NoiseFit,
    step: Option<f64>,
    tau0_s: f64,
) -> Option<(TermKind, Unsupported)> {
    if let (Some(q), Some(step)) = (fit.quantization, step) {
        let implied = step * tau0_s / 12f64.sqrt();
        if q.value > QUANTIZATION_RESOLUTION_FACTOR * implied {
            return Some((
                TermKind::Quantization,
                Unsupported::NotIdentifiable(NotIdentifiable {
                    term: TermKind::Quantization,
                    reason: format!(
                        "{:.1}x what the resolution step {} implies ({} (u)·s): the short-τ \
                         rise is not quantization (filtering, a spectral hump)",
                        q.value / implied,
                        fmt_num(step),
                        fmt_num(implied)
                    ),
                }),
            ));
        }
    }
    let significance = |t: &Term| {
        let half = t.hi * t.hi - t.value * t.value;
        if half > 0.0 {
            t.value * t.value / half
        } else {
            f64::INFINITY
        }
    };
    let mut candidates: Vec<(TermKind, Term)> = TermKind::LINEAR
        .into_iter()
        .filter_map(|k| fit.term(k).map(|t| (k, t)))
        .collect();
    if let Some(g) = fit.gauss_markov {
        candidates.push((TermKind::GaussMarkov, g.sigma));
    }
    candidates
        .into_iter()
        .filter(|(_, t)| t.lo <= 0.0)
        .min_by(|a, b| significance(&a.1).total_cmp(&significance(&b.1)))
        .map(|(kind, t)| {
            (
                kind,
                Unsupported::UpperLimit(UpperLimit {
                    term: kind,
                    upper: t.hi,
                }),
            )
        })
}

/// The fit with physically possible, resolved terms only, by backward elimination: fit
/// with `cfg`, drop the `least_supported_term`, refit without it and repeat until every
/// remaining term stands. Each dropped term is reported (upper limit or not
/// identifiable) from the fit that still had it; the returned fit's values, χ²_red and
/// model curve are those of the terms that stand, so the saved model is the model
/// that was fitted. `fit_with(cfg)` fits the curve with the terms `cfg` switches on.
pub fn fit_supported_terms<F>(
    cfg: &FitConfig,
    step: Option<f64>,
    tau0_s: f64,
    fit_with: F,
) -> Result<NoiseFit, AllanError>
where
    F: Fn(&FitConfig) -> Result<NoiseFit, AllanError>,
{
    let mut cfg = *cfg;
    let mut dropped: Vec<Unsupported> = Vec::new();
    let mut fit = fit_with(&cfg)?;
    while let Some((kind, why)) = least_supported_term(&fit, step, tau0_s) {
        dropped.push(why);
        let next = cfg.without(kind);
        let refit = if next.linear_terms().is_empty() && !next.gauss_markov {
            None
        } else {
            fit_with(&next).ok()
        };
        match refit {
            Some(f) => {
                fit = f;
                cfg = next;
            }
            None => {
                // Nothing left to refit with: report the term and leave it out.
                fit.clear_term(kind);
                break;
            }
        }
    }
    for d in dropped {
        match d {
            Unsupported::UpperLimit(u) => {
                fit.not_detected.retain(|x| x.term != u.term);
                fit.not_detected.push(u);
            }
            Unsupported::NotIdentifiable(n) => fit.not_identifiable.push(n),
        }
    }
    Ok(fit)
}

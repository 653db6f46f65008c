//! The runs' Allan curves of one channel combined per τ (EDF-weighted σ², EDFs summed;
//! why in the parent module doc).

use crate::allan::analysis::ChannelResult;
use crate::allan::{DevPoint, ci};

/// A curve's (σ², EDF, lag-1 ACF, n) at averaging factor `m`: its own point when it has
/// one, else interpolated log-log (ACF: linearly in ln m) between the neighbouring
/// points. None outside the curve.
fn sample_at(c: &ChannelResult, m: usize) -> Option<(f64, f64, f64, usize)> {
    let i = c.points.iter().position(|p| p.m >= m)?;
    let at = |j: usize| {
        let p: &DevPoint = &c.points[j];
        (
            p.dev * p.dev,
            c.edf.get(j).copied().unwrap_or(0.0),
            c.rate_acf1.get(j).copied().unwrap_or(f64::NAN),
            p.n,
        )
    };
    if c.points[i].m == m {
        return Some(at(i));
    }
    if i == 0 {
        return None;
    }
    let (a, b) = (at(i - 1), at(i));
    let (ma, mb) = (c.points[i - 1].m as f64, c.points[i].m as f64);
    let u = (m as f64 / ma).ln() / (mb / ma).ln();
    let logi = |x: f64, y: f64| {
        if x > 0.0 && y > 0.0 {
            (x.ln() + u * (y.ln() - x.ln())).exp()
        } else {
            x + u * (y - x)
        }
    };
    Some((logi(a.0, b.0), logi(a.1, b.1), a.2 + u * (b.2 - a.2), a.3))
}

/// The runs' curves of one channel combined per τ: EDF-weighted mean of σ², EDFs summed
/// (module doc). The grid is the shortest run's (its longest τ lies inside every run);
/// the other runs are read at its factors, interpolated where their grid differs. The
/// segments of all runs are kept so that [`ChannelResult::edf_for_alpha`] sums their
/// EDFs.
pub fn combine_curves(curves: &[&ChannelResult]) -> Option<ChannelResult> {
    let reference = curves
        .iter()
        .min_by(|a, b| {
            let end = |c: &ChannelResult| c.points.last().map_or(0, |p| p.m);
            end(a).cmp(&end(b))
        })
        .copied()?;
    let mut points = Vec::with_capacity(reference.points.len());
    let (mut lo, mut hi, mut alpha, mut edf, mut acf) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    'points: for (i, p) in reference.points.iter().enumerate() {
        let (mut sw, mut swv, mut sv, mut n) = (0.0, 0.0, 0.0, 0usize);
        let (mut acf_sum, mut acf_n) = (0.0, 0usize);
        for c in curves {
            let Some((v, nu, r, ni)) = sample_at(c, p.m) else {
                continue 'points;
            };
            if nu.is_finite() && nu > 0.0 {
                sw += nu;
                swv += nu * v;
            }
            sv += v;
            n += ni;
            if r.is_finite() {
                acf_sum += r;
                acf_n += 1;
            }
        }
        let avar = if sw > 0.0 {
            swv / sw
        } else {
            sv / curves.len() as f64
        };
        let dev = avar.sqrt();
        let (l, h) = if sw > 0.0 {
            ci::bounds(dev, sw, reference.confidence)
        } else {
            (0.0, f64::INFINITY)
        };
        points.push(DevPoint {
            m: p.m,
            tau: p.tau,
            n,
            dev,
        });
        lo.push(l);
        hi.push(h);
        alpha.push(reference.alpha.get(i).copied().unwrap_or(0));
        edf.push(sw);
        acf.push(if acf_n > 0 {
            acf_sum / acf_n as f64
        } else {
            f64::NAN
        });
    }
    Some(ChannelResult {
        name: reference.name.clone(),
        estimator: reference.estimator,
        tau0_s: reference.tau0_s,
        points,
        dev_lo: lo,
        dev_hi: hi,
        alpha,
        edf,
        confidence: reference.confidence,
        segment_phase_points: curves
            .iter()
            .flat_map(|c| c.segment_phase_points.iter().copied())
            .collect(),
        fast: reference.fast,
        rate_acf1: acf,
    })
}

//! Temperature plateaus: the spans where the temperature holds still, and the assignment
//! of static positions and rotations to them with the findings about each plateau.

use super::*;

/// Sample ranges of the temperature plateaus (module docs).
pub(super) fn plateau_spans(
    inp: &SegmentInput,
    opts: &SegmentOptions,
    fs: f64,
) -> Vec<(usize, usize)> {
    let n = inp.time_s.len();
    let Some(temp) = inp.temperature_c else {
        return vec![(0, n)];
    };
    // One value per second.
    let block = (fs.round() as usize).max(1);
    let nb = n.div_ceil(block);
    let tb: Vec<f64> = (0..nb)
        .map(|i| {
            let (lo, hi) = (i * block, ((i + 1) * block).min(n));
            temp[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect();
    let bs = block as f64 / fs;
    let h = ((0.5 * opts.temperature_window_s / bs).round() as usize).max(1);
    let mut pre = vec![0.0; nb + 1];
    for i in 0..nb {
        pre[i + 1] = pre[i] + tb[i];
    }
    let smooth: Vec<f64> = (0..nb)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h + 1).min(nb));
            (pre[hi] - pre[lo]) / (hi - lo) as f64
        })
        .collect();
    let limit = opts.moving_rate_c_per_min / 60.0;
    let moving: Vec<bool> = (0..nb)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h).min(nb - 1));
            hi > lo && ((smooth[hi] - smooth[lo]) / ((hi - lo) as f64 * bs)).abs() > limit
        })
        .collect();
    // Starts of moving runs, gaps shorter than min_plateau_s closed.
    let gap = ((opts.min_plateau_s / bs).round() as usize).max(1);
    let mut starts = Vec::new();
    let mut last_moving: Option<usize> = None;
    for (i, &m) in moving.iter().enumerate() {
        if m {
            if last_moving.is_none_or(|l| i - l > gap) {
                starts.push(i);
            }
            last_moving = Some(i);
        }
    }
    // The smoothed rate flags a change up to a window early: the cut is the first
    // second whose temperature has left the level before the flag by half the settled
    // band.
    let mut cuts: Vec<usize> = Vec::with_capacity(starts.len());
    for (r, &i0) in starts.iter().enumerate() {
        let lo = i0.saturating_sub(2 * h);
        let level = tb[lo..=i0].iter().sum::<f64>() / (i0 - lo + 1) as f64;
        let stop = starts.get(r + 1).copied().unwrap_or(nb);
        let i = (i0..stop)
            .find(|&i| (tb[i] - level).abs() > 0.5 * opts.settled_band_c)
            .unwrap_or(i0);
        let k = (i * block).min(n);
        if k > 0 {
            cuts.push(k);
        }
    }
    cuts.dedup();
    let mut out = Vec::new();
    let mut a = 0;
    for c in cuts {
        if c > a {
            out.push((a, c));
            a = c;
        }
    }
    out.push((a, n));
    out
}

pub(super) fn assign_plateaus(
    seg: &mut Segmentation,
    inp: &SegmentInput,
    spans: &[(usize, usize)],
    opts: &SegmentOptions,
    span: &dyn Fn(usize, usize) -> Span,
    sums: &Sums,
) {
    let which = |sp: Span| -> Option<usize> {
        let mid = (sp.start + sp.end) / 2;
        spans.iter().position(|&(a, b)| a <= mid && mid < b)
    };
    for s in &mut seg.statics {
        s.plateau = s.position_span().or(Some(s.span)).and_then(which);
    }
    for r in &mut seg.rotations {
        r.plateau = which(r.span);
    }
    for (p, &(a, b)) in spans.iter().enumerate() {
        let mut positions = [0usize; 6];
        let mut rot = [[0usize; 2]; 3];
        // Calibration segments of the plateau: (start, end) samples.
        let mut cal: Vec<(usize, usize)> = Vec::new();
        for s in seg.statics.iter().filter(|s| s.plateau == Some(p)) {
            if let (Some(sp), Some(up)) = (s.position_span(), s.up) {
                if let Some(i) = SignedAxis::POSITIONS.iter().position(|&q| q == up) {
                    positions[i] += 1;
                }
                cal.push((sp.start, sp.end));
            }
        }
        for r in seg
            .rotations
            .iter()
            .filter(|r| r.plateau == Some(p) && r.usable)
        {
            let pos = r.commanded_rate_rad_s.is_some_and(|w| w > 0.0);
            rot[r.axis.index()][usize::from(!pos)] += 1;
            cal.push((r.span.start, r.span.end));
        }
        let (temperature_c, spread_c) = match inp.temperature_c {
            None => (inp.nominal_temperature_c, 0.0),
            Some(temp) => {
                let ranges: Vec<(usize, usize)> = if cal.is_empty() {
                    vec![(a, b)]
                } else {
                    cal.clone()
                };
                let (mut sw, mut swt) = (0.0, 0.0);
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for &(x, y) in &ranges {
                    let m = (y - x) as f64;
                    sw += m;
                    swt += m * sums.mean(x, y, 6);
                    // Spread of the segment means over 1-s pieces (smoothed).
                    let piece = (seg.sample_rate_hz.round() as usize).max(1);
                    let mut k = x;
                    while k < y {
                        let e = (k + piece).min(y);
                        let v = temp[k..e].iter().sum::<f64>() / (e - k) as f64;
                        lo = lo.min(v);
                        hi = hi.max(v);
                        k = e;
                    }
                }
                (swt / sw, (hi - lo).max(0.0))
            }
        };
        let settled = spread_c <= opts.settled_band_c;
        let sp = span(a, b);
        let plateau = TemperaturePlateau {
            span: sp,
            temperature_c,
            spread_c,
            settled,
            dwell_s: sp.end_s - sp.start_s,
            positions,
            rotations: rot,
        };
        if plateau.has_positions() {
            let label = format!("plateau {p} ({:.2} °C, {})", temperature_c, sp.label());
            for (i, &c) in positions.iter().enumerate() {
                if c == 0 {
                    let up = SignedAxis::POSITIONS[i];
                    seg.findings.push(Finding {
                        kind: FindingKind::MissingPosition { up, plateau: p },
                        start_s: sp.start_s,
                        end_s: sp.end_s,
                        message: format!(
                            "{label}: no static position with {up} up; this plateau cannot be \
                             calibrated (repeat the position, or leave the plateau out)"
                        ),
                    });
                }
            }
            for axis in BodyAxis::ALL {
                for (s, positive) in [(0, true), (1, false)] {
                    if rot[axis.index()][s] == 0 {
                        seg.findings.push(Finding {
                            kind: FindingKind::MissingRotation {
                                axis,
                                positive,
                                plateau: p,
                            },
                            start_s: sp.start_s,
                            end_s: sp.end_s,
                            message: format!(
                                "{label}: no usable rotation about {}{} (ω {} 0 with +{} up); \
                                 the gyro scale of that axis is not observable here",
                                if positive { '+' } else { '-' },
                                ['x', 'y', 'z'][axis.index()],
                                if positive { '>' } else { '<' },
                                ['x', 'y', 'z'][axis.index()]
                            ),
                        });
                    }
                }
            }
            if !settled {
                seg.findings.push(Finding {
                    kind: FindingKind::UnsettledPlateau {
                        plateau: p,
                        spread_c,
                    },
                    start_s: sp.start_s,
                    end_s: sp.end_s,
                    message: format!(
                        "{label}: the temperature spans {spread_c:.3} °C over its positions and \
                         rotations (> {} °C): not settled (soak longer, or raise the settled band)",
                        opts.settled_band_c
                    ),
                });
            }
        }
        seg.plateaus.push(plateau);
    }
}

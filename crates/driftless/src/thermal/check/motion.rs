//! Motion of the IMU during a thermal log: window means of both triads, changes of
//! orientation and the flags a chamber run should not raise.

use super::*;

/// Per-window mean of a triad.
pub(super) fn window_means(tri: [&[f64]; 3], wins: &[std::ops::Range<usize>]) -> Vec<[f64; 3]> {
    wins.iter()
        .map(|r| {
            let k = r.len().max(1) as f64;
            std::array::from_fn(|a| tri[a][r.clone()].iter().sum::<f64>() / k)
        })
        .collect()
}

pub(super) fn angle(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let dot: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    let na = a.iter().map(|v| v * v).sum::<f64>().sqrt();
    let nb = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if na == 0.0 || nb == 0.0 {
        return 0.0;
    }
    (dot / (na * nb)).clamp(-1.0, 1.0).acos()
}

/// Component-wise median of `v[range]`.
pub(super) fn vec_median(v: &[[f64; 3]], range: std::ops::Range<usize>) -> [f64; 3] {
    std::array::from_fn(|k| {
        let mut c: Vec<f64> = v[range.clone()].iter().map(|x| x[k]).collect();
        median_of(&mut c)
    })
}

/// Motion windows, their moving flags, their local-motion flags (against the
/// neighbours only: a turn, not a new orientation) and the summary.
pub(super) type MotionFlags = (
    Vec<std::ops::Range<usize>>,
    Vec<bool>,
    Vec<bool>,
    MotionSummary,
);

/// Moving flags per motion window, with the summary.
pub(super) fn motion_flags(
    time: &[f64],
    gyro: Option<[&[f64]; 3]>,
    accel: Option<[&[f64]; 3]>,
    opts: &CheckOptions,
) -> Option<MotionFlags> {
    if gyro.is_none() && accel.is_none() {
        return None;
    }
    let wins = windows(time, opts.motion_window_s);
    let nw = wins.len();
    let mut moving = vec![false; nw];
    let mut local_motion = vec![false; nw];
    let (mut max_dw, mut max_tilt) = (0.0f64, 0.0f64);
    const HALF: usize = 30;
    let hood = |i: usize| i.saturating_sub(HALF)..(i + HALF + 1).min(nw);
    if let Some(g) = gyro {
        let m = window_means(g, &wins);
        for i in 0..nw {
            let med = vec_median(&m, hood(i));
            let d = (0..3)
                .map(|k| (m[i][k] - med[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            max_dw = max_dw.max(d);
            moving[i] |= d > opts.gyro_motion_rad_s;
            local_motion[i] |= d > opts.gyro_motion_rad_s;
        }
    }
    if let Some(a) = accel {
        let m = window_means(a, &wins);
        let global = vec_median(&m, 0..nw);
        for i in 0..nw {
            let local = vec_median(&m, hood(i));
            let tl = angle(&m[i], &local);
            let tg = angle(&m[i], &global);
            max_tilt = max_tilt.max(tg);
            moving[i] |= tl > opts.tilt_motion_rad || tg > 2.0 * opts.tilt_motion_rad;
            local_motion[i] |= tl > opts.tilt_motion_rad;
        }
    }
    let mut spans: Vec<TimeSpan> = Vec::new();
    let mut prev = false;
    for (i, r) in wins.iter().enumerate() {
        if moving[i] {
            let s = span_of(time, r);
            match spans.last_mut() {
                Some(last) if prev => last.end_s = s.end_s,
                _ => spans.push(s),
            }
        }
        prev = moving[i];
    }
    spans.truncate(20);
    let summary = MotionSummary {
        window_s: opts.motion_window_s,
        windows: nw,
        moving_fraction: moving.iter().filter(|&&m| m).count() as f64 / nw.max(1) as f64,
        max_gyro_change_rad_s: max_dw,
        max_tilt_rad: max_tilt,
        moving_spans: spans,
    };
    Some((wins, moving, local_motion, summary))
}

pub(super) fn motion_summary(
    time: &[f64],
    gyro: Option<[&[f64]; 3]>,
    accel: Option<[&[f64]; 3]>,
    opts: &CheckOptions,
) -> Option<MotionSummary> {
    motion_flags(time, gyro, accel, opts).map(|x| x.3)
}

/// Gravity face (0..6: +x, −x, +y, −y, +z, −z) of a mean specific force, when one axis
/// carries more than 80 % of it.
pub(super) fn face(a: &[f64; 3]) -> Option<usize> {
    let norm = a.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm == 0.0 {
        return None;
    }
    (0..3).find_map(|k| {
        let c = a[k] / norm;
        (c.abs() > 0.8).then_some(2 * k + usize::from(c < 0.0))
    })
}

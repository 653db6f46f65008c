//! The heating profile of a thermal log: ramps, plateaus and their rates.

use super::*;

pub(super) fn heating_profile(
    time: &[f64],
    tc: &[f64],
    ts: &TemperatureSummary,
    accel: Option<[&[f64]; 3]>,
    flags: Option<&MotionFlags>,
    opts: &CheckOptions,
) -> HeatingProfile {
    let duration = time[time.len() - 1] - time[0];
    let mean_rate = ts.rise_c / duration.max(f64::MIN_POSITIVE);
    let mut w = opts.rate_window_s;
    if ts.lsb_c > 0.0 && mean_rate > 0.0 {
        w = w.max(5.0 * ts.lsb_c / mean_rate);
    }
    let w = w.min(duration.max(opts.rate_window_s));
    let wins = windows(time, w);
    let rates: Vec<f64> = wins
        .iter()
        .map(|r| 60.0 * slope(time, tc, r.clone()))
        .collect();
    let flat_lim = opts.flat_c_per_min;
    let nw = rates.len().max(1) as f64;
    let heating = rates.iter().filter(|&&r| r >= flat_lim).count() as f64 / nw;
    let cooling = rates.iter().filter(|&&r| r <= -flat_lim).count() as f64 / nw;
    let mut changing: Vec<f64> = rates
        .iter()
        .map(|r| r.abs())
        .filter(|&r| r >= flat_lim)
        .collect();
    changing.sort_by(f64::total_cmp);
    let (p10, p50, p90) = (
        quantile(&changing, 0.1),
        quantile(&changing, 0.5),
        quantile(&changing, 0.9),
    );
    // Time per 1 °C level, per direction (module docs).
    let mut dwell = [
        std::collections::BTreeMap::<i64, usize>::new(),
        std::collections::BTreeMap::<i64, usize>::new(),
    ];
    for (win, r) in wins.iter().zip(&rates) {
        if r.abs() < flat_lim {
            continue;
        }
        let d = &mut dwell[usize::from(*r < 0.0)];
        for i in win.clone() {
            *d.entry(tc[i].round() as i64).or_default() += 1;
        }
    }
    let dt = duration / (time.len() - 1).max(1) as f64;
    let (mut unevenness, mut dwell_p10_p90_s) = (1.0, [0.0, 0.0]);
    for d in &dwell {
        if d.len() < 5 {
            continue;
        }
        let mut v: Vec<f64> = d.values().map(|&c| c as f64 * dt).collect();
        v.remove(v.len() - 1);
        v.remove(0);
        v.sort_by(f64::total_cmp);
        let (a, b) = (quantile(&v, 0.1), quantile(&v, 0.9));
        if a > 0.0 && b / a > unevenness {
            unevenness = b / a;
            dwell_p10_p90_s = [a, b];
        }
    }
    let rate_max = rates
        .iter()
        .copied()
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(0.0);
    // Plateaus: runs of flat windows (rate from the shorter plateau windows).
    let pw = windows(time, opts.rate_window_s);
    let flat: Vec<bool> = pw
        .iter()
        .map(|r| (60.0 * slope(time, tc, r.clone())).abs() < flat_lim)
        .collect();
    let mut plateaus = Vec::new();
    let mut i = 0;
    while i < pw.len() {
        if !flat[i] {
            i += 1;
            continue;
        }
        let mut j = i;
        while j + 1 < pw.len() && flat[j + 1] {
            j += 1;
        }
        let r = pw[i].start..pw[j].end;
        let span = span_of(time, &r);
        if span.end_s - span.start_s >= opts.plateau_min_s {
            let mean_c = tc[r.clone()].iter().sum::<f64>() / r.len() as f64;
            let mut faces = [false; 6];
            if let (Some(a), Some((mw, _, turning, _))) = (accel, flags) {
                for (k, win) in mw.iter().enumerate() {
                    if turning[k] || win.start < r.start || win.end > r.end {
                        continue;
                    }
                    let m = window_means(a, std::slice::from_ref(win));
                    if let Some(f) = face(&m[0]) {
                        faces[f] = true;
                    }
                }
            }
            plateaus.push(Plateau {
                span,
                mean_c,
                orientations: faces.iter().filter(|&&f| f).count(),
            });
        }
        i = j + 1;
    }
    HeatingProfile {
        window_s: w,
        windows: rates.len(),
        heating_fraction: heating,
        cooling_fraction: cooling,
        flat_fraction: 1.0 - heating - cooling,
        rate_p10_c_per_min: p10,
        rate_median_c_per_min: p50,
        rate_p90_c_per_min: p90,
        rate_max_c_per_min: rate_max,
        unevenness,
        dwell_p10_p90_s,
        plateaus,
    }
}

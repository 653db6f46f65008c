//! Deterministic spectral lines in a static log — vibration, pumps, fans, mains harmonics
//! — which no IEEE noise term models: found, measured, and removed before the noise fit.
//!
//! **Spectrum.** Welch's averaged periodogram (Welch 1967, IEEE Trans. Audio
//! Electroacoust. 15(2)): segments of L = 2^m samples, Hann window w, one-sided
//! PSD S_k = 2·|Σ wₙ yₙ e^{−2πikn/L}|² / (f_s·Σ wₙ²) (u²/Hz, bins f_k = k·f_s/L), averaged
//! over at most [`LineConfig::max_segments`] segments spread evenly over the record (a
//! line is a stationary feature; a few dozen averages resolve it, and the cost stays far
//! below the Allan computation's).
//!
//! **Detection.** A line is a run of bins standing above the noise floor on *both* sides:
//! the floor left and right of bin k is the median of S over the `floor_bins` bins on that
//! side (skipping `guard_bins` next to k; fewer, but at least 6, near DC — bins 0 and 1 are
//! never used — and near Nyquist); bin k is a peak when S_k exceeds
//! `threshold` × each side's floor (a monotone slope — a 1/f rise, a filter roll-off —
//! exceeds at most one side, and a broad hump is its own floor). With K averages the PSD
//! estimate scatters by about 1/√K about its mean, so a threshold of 10 is far beyond
//! chance for any K ≥ 8. A line spans the contiguous bins above 2 × the floor around the
//! peak, at most `max_width_bins` wide (wider is coloured noise, not a line).
//!
//! **Size.** Power P = Σ (S_k − floor)·Δf over the line's bins (Hann's energy spread
//! across bins is in the sum); a sinusoid of amplitude A has power A²/2, so
//! A = √(2P). Frequency: the power-weighted mean of its bins.
//!
//! **Removal.** A zero-phase notch: the second-order IIR notch of the RBJ audio-EQ
//! cookbook (b = [1, −2cos ω₀, 1], a = [1 + α, −2cos ω₀, 1 − α], α = sin ω₀ / (2Q),
//! ω₀ = 2πf₀/f_s, Q = f₀ / bandwidth, bandwidth the line's width plus one bin on each
//! side), run forward then backward (Gustafsson 1996, IEEE TSP 44(4): forward–backward
//! filtering), each pass started in the steady state of the first sample. It removes the
//! line whatever its phase and a slow wander of its frequency within the band, and only
//! the noise inside that band (a fraction bandwidth/(f_s/2) of white power).

use serde::Serialize;

/// Fewest bins a side's floor median may use (near DC or Nyquist the side is shorter).
const MIN_FLOOR_BINS: usize = 6;

/// Detection settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineConfig {
    /// Segment length L (a power of two; shorter records use the largest power of two
    /// that gives 8 segments).
    pub segment_len: usize,
    /// Most segments averaged.
    pub max_segments: usize,
    /// Peak / floor ratio (each side) that makes a line.
    pub threshold: f64,
    /// Bins each side for the floor's median.
    pub floor_bins: usize,
    /// Bins next to the candidate left out of the floor.
    pub guard_bins: usize,
    /// Widest line, bins.
    pub max_width_bins: usize,
}

impl Default for LineConfig {
    fn default() -> Self {
        LineConfig {
            segment_len: 4096,
            max_segments: 64,
            threshold: 10.0,
            floor_bins: 24,
            guard_bins: 3,
            max_width_bins: 12,
        }
    }
}

/// One line found.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpectralLine {
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Sinusoid amplitude (peak), in the channel's unit.
    pub amplitude: f64,
    /// Peak PSD over the floor.
    pub peak_to_floor: f64,
    /// Width of the bins above twice the floor, Hz.
    pub width_hz: f64,
    /// Frequency resolution Δf of the spectrum, Hz.
    pub resolution_hz: f64,
}

/// In-place iterative radix-2 FFT (Cooley–Tukey, decimation in time) of `re` + i·`im`,
/// length a power of two.
fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    debug_assert!(n.is_power_of_two() && im.len() == n);
    let mut j = 0usize;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = -2.0 * std::f64::consts::PI / len as f64;
        let (ws, wc) = ang.sin_cos();
        for start in (0..n).step_by(len) {
            let (mut cr, mut ci) = (1.0, 0.0);
            for k in 0..len / 2 {
                let (a, b) = (start + k, start + k + len / 2);
                let tr = re[b] * cr - im[b] * ci;
                let ti = re[b] * ci + im[b] * cr;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
                let nc = cr * wc - ci * ws;
                ci = cr * ws + ci * wc;
                cr = nc;
            }
        }
        len <<= 1;
    }
}

/// Welch one-sided PSD of `y` sampled every `tau0_s` (module docs): (Δf, S_k for
/// k = 0 … L/2). `None` for fewer than 8·64 samples.
pub(crate) fn welch_psd(y: &[f64], tau0_s: f64, cfg: &LineConfig) -> Option<(f64, Vec<f64>)> {
    let n = y.len();
    let mut l = cfg.segment_len.next_power_of_two().max(64);
    while l > 64 && n < 8 * l {
        l /= 2;
    }
    if n < 8 * l || !(tau0_s > 0.0 && tau0_s.is_finite()) {
        return None;
    }
    let fs = 1.0 / tau0_s;
    let w: Vec<f64> = (0..l)
        .map(|k| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / l as f64).cos())
        .collect();
    let u: f64 = w.iter().map(|v| v * v).sum();
    let available = n / l;
    let segs = available.min(cfg.max_segments.max(1));
    let mut psd = vec![0.0; l / 2 + 1];
    let (mut re, mut im) = (vec![0.0; l], vec![0.0; l]);
    for s in 0..segs {
        // Evenly spread over the record.
        let start = if segs == 1 {
            0
        } else {
            s * (n - l) / (segs - 1)
        };
        let seg = &y[start..start + l];
        let mean = seg.iter().sum::<f64>() / l as f64;
        for k in 0..l {
            re[k] = (seg[k] - mean) * w[k];
            im[k] = 0.0;
        }
        fft(&mut re, &mut im);
        for (k, p) in psd.iter_mut().enumerate() {
            let scale = if k == 0 || k == l / 2 { 1.0 } else { 2.0 };
            *p += scale * (re[k] * re[k] + im[k] * im[k]) / (fs * u);
        }
    }
    for p in &mut psd {
        *p /= segs as f64;
    }
    Some((fs / l as f64, psd))
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// The lines of `y` (rate data sampled every `tau0_s`), strongest first.
pub fn detect_lines(y: &[f64], tau0_s: f64, cfg: &LineConfig) -> Vec<SpectralLine> {
    let Some((df, s)) = welch_psd(y, tau0_s, cfg) else {
        return Vec::new();
    };
    let nb = s.len();
    let (fb, gb) = (cfg.floor_bins.max(4), cfg.guard_bins);
    let side_floor = |k: usize, left: bool| -> Option<f64> {
        let v: Vec<f64> = if left {
            // Down to bin 2 at most: DC and bin 1 hold the record's mean and slowest drift.
            let hi = k.checked_sub(gb + 1)?;
            let lo = (hi + 1).saturating_sub(fb).max(2);
            if hi < lo + MIN_FLOOR_BINS - 1 {
                return None;
            }
            s[lo..=hi].to_vec()
        } else {
            let lo = k + gb + 1;
            let hi = (lo + fb - 1).min(nb - 1);
            if hi < lo + MIN_FLOOR_BINS - 1 {
                return None;
            }
            s[lo..=hi].to_vec()
        };
        Some(median(v))
    };
    let floor =
        |k: usize| -> Option<(f64, f64)> { Some((side_floor(k, true)?, side_floor(k, false)?)) };
    let mut lines = Vec::new();
    let mut k = 0;
    while k < nb {
        let Some((fl, fr)) = floor(k) else {
            k += 1;
            continue;
        };
        let is_peak = s[k] > cfg.threshold * fl
            && s[k] > cfg.threshold * fr
            && (k == 0 || s[k] >= s[k - 1])
            && (k + 1 >= nb || s[k] >= s[k + 1]);
        if !is_peak {
            k += 1;
            continue;
        }
        let base = fl.max(fr);
        let (mut lo, mut hi) = (k, k);
        while lo > 1 && s[lo - 1] > 2.0 * base {
            lo -= 1;
        }
        while hi + 1 < nb && s[hi + 1] > 2.0 * base {
            hi += 1;
        }
        let width = hi - lo + 1;
        if width <= cfg.max_width_bins {
            let (mut p, mut pf) = (0.0, 0.0);
            for (j, &v) in s.iter().enumerate().take(hi + 1).skip(lo) {
                let e = (v - base).max(0.0) * df;
                p += e;
                pf += e * j as f64 * df;
            }
            if p > 0.0 {
                lines.push(SpectralLine {
                    frequency_hz: pf / p,
                    amplitude: (2.0 * p).sqrt(),
                    peak_to_floor: s[k] / base,
                    width_hz: width as f64 * df,
                    resolution_hz: df,
                });
            }
        }
        k = hi + 1;
    }
    lines.sort_by(|a, b| b.amplitude.total_cmp(&a.amplitude));
    lines
}

/// One forward pass of the RBJ notch (module docs) in transposed direct form II,
/// started in the steady state of the first sample.
fn notch_pass(y: &mut [f64], b: [f64; 3], a: [f64; 2]) {
    let Some(&x0) = y.first() else {
        return;
    };
    let mut z2 = (b[2] - a[1]) * x0;
    let mut z1 = (b[1] - a[0]) * x0 + z2;
    for v in y.iter_mut() {
        let x = *v;
        let out = b[0] * x + z1;
        z1 = b[1] * x - a[0] * out + z2;
        z2 = b[2] * x - a[1] * out;
        *v = out;
    }
}

/// `y` with each line removed by a zero-phase notch (module docs).
pub fn remove_lines(y: &[f64], tau0_s: f64, lines: &[SpectralLine]) -> Vec<f64> {
    let mut out = y.to_vec();
    let fs = 1.0 / tau0_s;
    for l in lines {
        let f0 = l.frequency_hz;
        if !(f0 > 0.0 && f0 < fs / 2.0) {
            continue;
        }
        let bw = l.width_hz + 2.0 * l.resolution_hz;
        let w0 = 2.0 * std::f64::consts::PI * f0 / fs;
        let q = (f0 / bw).max(0.5);
        let alpha = w0.sin() / (2.0 * q);
        let a0 = 1.0 + alpha;
        let b = [1.0 / a0, -2.0 * w0.cos() / a0, 1.0 / a0];
        let a = [-2.0 * w0.cos() / a0, (1.0 - alpha) / a0];
        notch_pass(&mut out, b, a);
        out.reverse();
        notch_pass(&mut out, b, a);
        out.reverse();
    }
    out
}

/// The lines of one channel and what removing them did to its Allan deviation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChannelLines {
    /// Channel name.
    pub channel: String,
    /// Lines found, strongest first.
    pub lines: Vec<SpectralLine>,
    /// Largest σ_with(τ)/σ_without(τ) − 1 over the analysed τ (how much the lines raised
    /// the Allan deviation).
    pub max_sigma_increase: f64,
    /// τ of that maximum, s.
    pub at_tau_s: f64,
}

impl ChannelLines {
    /// One line of text for warnings.
    pub fn describe(&self, unit: &str) -> String {
        let list: Vec<String> = self
            .lines
            .iter()
            .map(|l| {
                format!(
                    "{:.3} Hz, amplitude {:.3e} {unit} ({:.0}× the floor)",
                    l.frequency_hz, l.amplitude, l.peak_to_floor
                )
            })
            .collect();
        format!(
            "{}: spectral line(s) no noise term models — {}; removed (zero-phase notch) before \
             the noise fit: they raised σ(τ) by up to {:.0} % (at τ = {:.3} s)",
            self.channel,
            list.join("; "),
            100.0 * self.max_sigma_increase,
            self.at_tau_s
        )
    }
}

/// The largest relative increase of `with` over `without` (paired deviations at the same
/// τ) and its τ: (max σ_with/σ_without − 1, τ).
pub(crate) fn sigma_increase(tau: &[f64], with: &[f64], without: &[f64]) -> (f64, f64) {
    tau.iter()
        .zip(with.iter().zip(without))
        .filter(|(_, (a, b))| a.is_finite() && b.is_finite() && **b > 0.0)
        .map(|(t, (a, b))| (a / b - 1.0, *t))
        .fold((0.0, f64::NAN), |acc, x| if x.0 > acc.0 { x } else { acc })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gauss(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut u = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let (a, b) = (u().max(1e-300), u());
                (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect()
    }

    #[test]
    fn fft_matches_the_direct_dft() {
        let x = gauss(64, 3);
        let (mut re, mut im) = (x.clone(), vec![0.0; 64]);
        fft(&mut re, &mut im);
        for k in [0, 1, 5, 31, 32, 63] {
            let (mut r, mut i) = (0.0, 0.0);
            for (n, v) in x.iter().enumerate() {
                let a = -2.0 * std::f64::consts::PI * (k * n) as f64 / 64.0;
                r += v * a.cos();
                i += v * a.sin();
            }
            assert!(
                (re[k] - r).abs() < 1e-9 && (im[k] - i).abs() < 1e-9,
                "bin {k}"
            );
        }
    }

    #[test]
    fn white_noise_psd_is_its_variance_over_nyquist() {
        // White σ² = 1 at f_s = 100 Hz: one-sided PSD 2σ²/f_s = 0.02 u²/Hz.
        let y = gauss(1 << 18, 7);
        let (_, s) = welch_psd(&y, 0.01, &LineConfig::default()).expect("psd");
        let mid = median(s[10..s.len() - 10].to_vec());
        assert!((mid / 0.02 - 1.0).abs() < 0.05, "{mid}");
    }

    #[test]
    fn a_line_is_found_measured_and_removed() {
        let (n, tau0) = (1usize << 19, 0.01);
        let (f0, amp) = (0.512, 0.3);
        for seed in 1..=4 {
            let noise = gauss(n, seed);
            let y: Vec<f64> = (0..n)
                .map(|k| {
                    noise[k] + amp * (2.0 * std::f64::consts::PI * f0 * k as f64 * tau0 + 0.7).sin()
                })
                .collect();
            let lines = detect_lines(&y, tau0, &LineConfig::default());
            assert_eq!(lines.len(), 1, "seed {seed}: {lines:?}");
            let l = lines[0];
            assert!((l.frequency_hz - f0).abs() < l.resolution_hz, "{l:?}");
            assert!((l.amplitude / amp - 1.0).abs() < 0.1, "{l:?}");
            let clean = remove_lines(&y, tau0, &lines);
            assert!(detect_lines(&clean, tau0, &LineConfig::default()).is_empty());
            // What is removed is the sinusoid plus the noise inside the notch band: white
            // PSD 2σ²/f_s = 0.02 over bandwidth (width + 2Δf), with a factor 2 for the
            // band edges' partial attenuation and the estimate's scatter.
            let removed: f64 = (0..n)
                .map(|k| {
                    let line =
                        amp * (2.0 * std::f64::consts::PI * f0 * k as f64 * tau0 + 0.7).sin();
                    (y[k] - clean[k] - line).powi(2)
                })
                .sum::<f64>()
                / n as f64;
            let band_hz = l.width_hz + 2.0 * l.resolution_hz;
            let bound = 2.0 * (0.02 * band_hz).sqrt();
            assert!(
                removed.sqrt() < bound,
                "seed {seed}: rms {} vs {bound}",
                removed.sqrt()
            );
            // The notch band is narrow: under 0.5 % of the 50-Hz band's white power.
            assert!(band_hz < 0.25, "band {band_hz} Hz");
        }
    }

    #[test]
    fn noise_slopes_and_broad_humps_are_not_lines() {
        let (n, tau0) = (1usize << 18, 0.01);
        for seed in 1..=6 {
            let w = gauss(n, 100 + seed);
            // White + random walk (a 1/f² rise at low frequency).
            let mut rw = 0.0;
            let a: Vec<f64> = w
                .iter()
                .zip(gauss(n, 200 + seed))
                .map(|(x, z)| {
                    rw += 0.02 * z;
                    x + rw
                })
                .collect();
            assert!(
                detect_lines(&a, tau0, &LineConfig::default()).is_empty(),
                "rw {seed}"
            );
            // A resonant AR(2) hump at 19 Hz with a few-Hz bandwidth (a sensor's filter).
            let (r, th) = (0.85, 2.0 * std::f64::consts::PI * 19.0 * tau0);
            let (mut y1, mut y2) = (0.0, 0.0);
            let h: Vec<f64> = w
                .iter()
                .map(|x| {
                    let v = x + 2.0 * r * th.cos() * y1 - r * r * y2;
                    y2 = y1;
                    y1 = v;
                    v
                })
                .collect();
            assert!(
                detect_lines(&h, tau0, &LineConfig::default()).is_empty(),
                "hump {seed}"
            );
        }
    }
}

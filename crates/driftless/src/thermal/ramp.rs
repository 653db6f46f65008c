//! The ramp method: bias versus temperature from one continuous
//! warm-up or cool-down of a static sensor — what the autopilots' thermal calibrations
//! do (PX4 `TC_*`, ArduPilot `INS_TCAL*`), with their known pains addressed:
//!
//! * **Quantised temperature** (1 °C sensors give stepped fits): samples are binned by
//!   temperature (default 1 °C wide, centred on whole degrees, so a 1 °C-quantised
//!   reading falls in the middle of its bin) and each bin contributes **one point**: the
//!   mean of each channel after rejecting spikes beyond 6 robust σ of the median (a
//!   median or trimmed mean would stick to the LSB grid of a quantised output), with its
//!   standard error.
//! * **Uneven heating rate**: one point per bin whatever the time spent in it, so a slow
//!   stretch does not outweigh a fast one.
//! * **Heating vs cooling**: samples are split by the sign of dT/dt (over
//!   `slope_window_s`); when both directions cover common bins the RMS difference of
//!   their bin medians there is reported as the hysteresis, per channel.
//!
//! The points of both directions are then fitted per channel by [`super::fit`](mod@super::fit). The
//! fitted "bias" of a static sensor includes the constant part of what it senses (Earth
//! rate, gravity along the axis) and, on an axis that senses gravity, the thermal scale
//! factor times g — as in the autopilots' ramp calibrations; [`ThermalFit`] values are
//! therefore used relative to T_ref (the Δb of the compensation model).

use super::fit::{FitOptions, ThermalFit, ThermalFitError, fit};

/// Ramp settings.
#[derive(Clone, Debug, PartialEq)]
pub struct RampOptions {
    /// Bin width, °C (> 0); bins are centred on multiples of it.
    pub bin_c: f64,
    /// Fewest samples a bin needs to give a point.
    pub min_samples_per_bin: usize,
    /// Window over which dT/dt's sign is taken, s.
    pub slope_window_s: f64,
    /// The polynomial fit.
    pub fit: FitOptions,
}

impl Default for RampOptions {
    fn default() -> Self {
        RampOptions {
            bin_c: 1.0,
            min_samples_per_bin: 50,
            slope_window_s: 60.0,
            fit: FitOptions::default(),
        }
    }
}

/// Why a ramp calibration failed.
#[derive(Debug, thiserror::Error)]
pub enum RampError {
    /// Columns of different lengths, or none.
    #[error("{0}")]
    BadInput(String),
    /// A temperature or sample that is NaN or infinite.
    #[error("sample {index}: non-finite {what}")]
    NonFinite {
        /// Sample index.
        index: usize,
        /// `temperature` or the channel's name.
        what: String,
    },
    /// Too few bins with enough samples for the fit.
    #[error("{bins} temperature bins with ≥ {min} samples; an order-{order} fit needs at least {}: widen the temperature span or lower the bin width", order + 2)]
    TooFewBins {
        /// Bins with enough samples.
        bins: usize,
        /// Samples a bin needs.
        min: usize,
        /// Order asked for.
        order: usize,
    },
    /// A fit failed.
    #[error("{channel}: {source}")]
    Fit {
        /// Channel name.
        channel: String,
        /// Cause.
        source: ThermalFitError,
    },
}

/// One bin of one direction.
#[derive(Clone, Debug, PartialEq)]
pub struct RampPoint {
    /// Bin centre, °C.
    pub t_c: f64,
    /// Samples in it.
    pub n: usize,
    /// Heating (true) or cooling.
    pub heating: bool,
    /// Spike-rejected mean per channel.
    pub value: Vec<f64>,
    /// Its standard error.
    pub sigma: Vec<f64>,
}

/// Result of [`ramp_calibration`].
#[derive(Clone, Debug)]
pub struct RampCalibration {
    /// Channel names, as given.
    pub names: Vec<String>,
    /// Bin points of both directions, by temperature.
    pub points: Vec<RampPoint>,
    /// RMS difference heating − cooling of the bin values over common bins per channel (None when only one
    /// direction covers ≥ 2 common bins).
    pub hysteresis: Option<Vec<f64>>,
    /// One fit per channel over all points.
    pub fits: Vec<ThermalFit>,
}

/// Mean after rejecting spikes beyond 6 robust standard deviations of the median
/// (1.4826·MAD; no rejection when the MAD is 0, e.g. a quantised output sitting on two
/// levels), and its standard error s/√n. A plain median or trimmed mean would be biased
/// on quantised outputs: their samples take a few LSB levels whose proportions carry the
/// sub-LSB value, which only the mean recovers.
fn robust_mean_and_se(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let mid = |w: &[f64]| {
        let k = w.len();
        if k % 2 == 1 {
            w[k / 2]
        } else {
            0.5 * (w[k / 2 - 1] + w[k / 2])
        }
    };
    let med = mid(v);
    let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    dev.sort_by(f64::total_cmp);
    let limit = 6.0 * 1.4826 * mid(&dev);
    let kept: Vec<f64> = v
        .iter()
        .copied()
        .filter(|x| limit <= 0.0 || (x - med).abs() <= limit)
        .collect();
    let k = kept.len().max(1) as f64;
    let m = kept.iter().sum::<f64>() / k;
    // The deviations scaled by a power of two near the largest (exact), so that their
    // squares neither underflow (data near 1e-310 would get σ = 0) nor overflow.
    let spread = kept.iter().fold(0.0f64, |a, x| a.max((x - m).abs()));
    let unit = if spread > 0.0 && spread.is_finite() {
        2f64.powi(spread.log2().floor() as i32)
    } else {
        1.0
    };
    let var = kept.iter().map(|x| ((x - m) / unit).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
    (m, (var / k).sqrt() * unit)
}

/// Bias versus temperature from a ramp (module docs). `channels` are (name, samples),
/// all of the length of `time_s` and `temperature_c`.
pub fn ramp_calibration(
    time_s: &[f64],
    temperature_c: &[f64],
    channels: &[(&str, &[f64])],
    opts: &RampOptions,
) -> Result<RampCalibration, RampError> {
    let n = time_s.len();
    if n == 0 || temperature_c.len() != n || channels.iter().any(|(_, c)| c.len() != n) {
        return Err(RampError::BadInput(format!(
            "{n} times, {} temperatures and channels of lengths {:?}: all must be equal and non-zero",
            temperature_c.len(),
            channels.iter().map(|(_, c)| c.len()).collect::<Vec<_>>()
        )));
    }
    if !(opts.bin_c.is_finite() && opts.bin_c > 0.0) {
        return Err(RampError::BadInput(format!("bin width {} °C", opts.bin_c)));
    }
    if let Some(i) = temperature_c.iter().position(|t| !t.is_finite()) {
        return Err(RampError::NonFinite {
            index: i,
            what: "temperature".into(),
        });
    }
    for (name, c) in channels {
        if let Some(i) = c.iter().position(|v| !v.is_finite()) {
            return Err(RampError::NonFinite {
                index: i,
                what: (*name).to_string(),
            });
        }
    }
    // Direction per sample: sign of T(t + w/2) − T(t − w/2).
    let half = 0.5 * opts.slope_window_s;
    let (mut lo, mut hi) = (0usize, 0usize);
    let mut heating = vec![true; n];
    for i in 0..n {
        while lo < i && time_s[lo] < time_s[i] - half {
            lo += 1;
        }
        while hi + 1 < n && time_s[hi + 1] <= time_s[i] + half {
            hi += 1;
        }
        heating[i] = temperature_c[hi.max(i)] >= temperature_c[lo];
    }
    // Bins per direction.
    use std::collections::BTreeMap;
    let mut bins: BTreeMap<(i64, bool), Vec<usize>> = BTreeMap::new();
    for i in 0..n {
        let b = (temperature_c[i] / opts.bin_c).round() as i64;
        bins.entry((b, heating[i])).or_default().push(i);
    }
    let mut points = Vec::new();
    for ((b, heat), idx) in &bins {
        if idx.len() < opts.min_samples_per_bin {
            continue;
        }
        let mut median = Vec::with_capacity(channels.len());
        let mut sigma = Vec::with_capacity(channels.len());
        for (_, c) in channels {
            let mut v: Vec<f64> = idx.iter().map(|&i| c[i]).collect();
            let (m, s) = robust_mean_and_se(&mut v);
            median.push(m);
            sigma.push(s);
        }
        points.push(RampPoint {
            t_c: *b as f64 * opts.bin_c,
            n: idx.len(),
            heating: *heat,
            value: median,
            sigma,
        });
    }
    points.sort_by(|a, b| a.t_c.total_cmp(&b.t_c));
    let mut distinct: Vec<f64> = points.iter().map(|p| p.t_c).collect();
    distinct.dedup();
    if distinct.len() < opts.fit.order + 2 {
        return Err(RampError::TooFewBins {
            bins: distinct.len(),
            min: opts.min_samples_per_bin,
            order: opts.fit.order,
        });
    }
    // Hysteresis over bins both directions cover.
    let common: Vec<(&RampPoint, &RampPoint)> = points
        .iter()
        .filter(|p| p.heating)
        .filter_map(|h| {
            points
                .iter()
                .find(|c| !c.heating && c.t_c == h.t_c)
                .map(|c| (h, c))
        })
        .collect();
    let hysteresis = (common.len() >= 2).then(|| {
        (0..channels.len())
            .map(|k| {
                let s: f64 = common
                    .iter()
                    .map(|(h, c)| (h.value[k] - c.value[k]).powi(2))
                    .sum();
                (s / common.len() as f64).sqrt()
            })
            .collect()
    });
    let t: Vec<f64> = points.iter().map(|p| p.t_c).collect();
    let mut fits = Vec::with_capacity(channels.len());
    for (k, (name, _)) in channels.iter().enumerate() {
        let y: Vec<f64> = points.iter().map(|p| p.value[k]).collect();
        let s: Vec<f64> = points.iter().map(|p| p.sigma[k]).collect();
        let weights = s.iter().all(|v| *v > 0.0).then_some(s.as_slice());
        let f = fit(&t, &y, weights, &opts.fit).map_err(|source| RampError::Fit {
            channel: (*name).to_string(),
            source,
        })?;
        fits.push(f);
    }
    Ok(RampCalibration {
        names: channels.iter().map(|(n, _)| (*n).to_string()).collect(),
        points,
        hysteresis,
        fits,
    })
}

impl RampCalibration {
    /// A bias-only compensation model file from the fits (for `driftless compensate` and
    /// the autopilot export, [`super::autopilot`]). `accel` / `gyro` give the channel
    /// indices of the x, y, z axes (SI samples: m/s², rad/s); a triad not given gets no
    /// thermal terms.
    ///
    /// * matrix = I, scale_delta = 0: a ramp sees no scale factor;
    /// * bias_delta = the fit minus its constant (Δb(T) = ŷ(T) − ŷ(T_ref));
    /// * gyro bias = the fitted value at T_ref (it includes the Earth-rate projection,
    ///   ≤ 7.3e-5 rad/s, as the autopilots' own gyro calibrations do);
    /// * accelerometer bias = 0: a static ramp cannot separate the bias from gravity (the
    ///   fitted value at T_ref is mostly g along the axis), so the room offset must come
    ///   from a regular accelerometer calibration — PX4's and ArduPilot's ramp
    ///   calibrations likewise keep the accelerometer relative.
    ///
    /// Range: the temperatures of the bins; T_ref: the fits'; out of range: clamp.
    pub(crate) fn bias_model_file(
        &self,
        accel: Option<[usize; 3]>,
        gyro: Option<[usize; 3]>,
        model_id: u64,
    ) -> Result<super::model_file::ThermalModelFile, RampError> {
        use super::model_file::{FORMAT_VERSION, ThermalModelFile, TriadSection};
        let first = self
            .fits
            .first()
            .ok_or_else(|| RampError::BadInput("no channel was fitted".into()))?;
        let t_ref_c = first.poly.t_ref_c();
        let lo = self
            .points
            .iter()
            .map(|p| p.t_c)
            .fold(f64::INFINITY, f64::min);
        let hi = self
            .points
            .iter()
            .map(|p| p.t_c)
            .fold(f64::NEG_INFINITY, f64::max);
        let section = |idx: Option<[usize; 3]>,
                       unit: &str,
                       absolute: bool|
         -> Result<TriadSection, RampError> {
            let mut s = TriadSection {
                raw_unit: unit.into(),
                bias: [0.0; 3],
                matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                bias_delta: [vec![0.0], vec![0.0], vec![0.0]],
                scale_delta: [vec![0.0], vec![0.0], vec![0.0]],
            };
            if let Some(idx) = idx {
                for (k, &i) in idx.iter().enumerate() {
                    let f = self.fits.get(i).ok_or_else(|| {
                        RampError::BadInput(format!(
                            "channel index {i} out of range ({} channels)",
                            self.fits.len()
                        ))
                    })?;
                    let mut c = f.coeffs.clone();
                    if absolute {
                        s.bias[k] = c[0];
                    }
                    c[0] = 0.0;
                    s.bias_delta[k] = c;
                }
            }
            Ok(s)
        };
        Ok(ThermalModelFile {
            format_version: FORMAT_VERSION,
            model_id,
            t_ref_c,
            range_c: [lo, hi],
            out_of_range: "clamp".into(),
            gyro_g_sensitivity: None,
            accel: section(accel, "m/s^2", false)?,
            gyro: section(gyro, "rad/s", true)?,
        })
    }
}

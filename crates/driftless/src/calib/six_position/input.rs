//! Position and rate means from sample columns of a segment manifest.

use super::*;

/// Mean, sample standard deviation and peak |x| of a segment of one channel, in rate
/// units (increments are divided by Δt).
pub(super) fn channel_stats(col: &[f64], scale: f64) -> (f64, f64, f64) {
    let n = col.len() as f64;
    let mean = col.iter().sum::<f64>() / n;
    let var = if col.len() > 1 {
        col.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    let peak = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (mean * scale, var.sqrt() * scale.abs(), peak * scale.abs())
}

pub(super) type Stats3 = (Vec3, Vec3, Vec3);

pub(super) fn triad_stats(cols: &[&[f64]; 3], range: std::ops::Range<usize>, scale: f64) -> Stats3 {
    let s: [(f64, f64, f64); 3] =
        std::array::from_fn(|k| channel_stats(&cols[k][range.clone()], scale));
    (s.map(|v| v.0), s.map(|v| v.1), s.map(|v| v.2))
}

impl SixPositionInput {
    /// The positions and rate segments of `manifest` at `set_temperature_c` from raw
    /// sample columns (x, y, z) indexed as the manifest's samples (sample k at
    /// k/`sample_rate_hz` from the protocol start), each multiplied by `scale` (1 for
    /// rates; 1/Δt for increments).
    pub fn from_manifest_columns(
        manifest: &ChamberManifest,
        accel: [&[f64]; 3],
        gyro: [&[f64]; 3],
        scale: f64,
        set_temperature_c: f64,
    ) -> Result<SixPositionInput, SixPositionError> {
        let fs = manifest.sample_rate_hz;
        let len = accel[0].len();
        if accel.iter().chain(&gyro).any(|c| c.len() != len) {
            return Err(SixPositionError::Invalid(
                "accelerometer and gyro columns differ in length".into(),
            ));
        }
        let mut input = SixPositionInput::default();
        for seg in manifest
            .segments
            .iter()
            .filter(|s| s.set_temperature_c == set_temperature_c)
        {
            let range = seg.sample_range(fs);
            if range.is_empty() || range.end > len {
                if matches!(
                    seg.kind,
                    SegmentKind::Position { .. } | SegmentKind::Rate { .. }
                ) {
                    return Err(SixPositionError::Invalid(format!(
                        "segment {:.3}–{:.3} s: samples {range:?} not inside the {len} recorded",
                        seg.start_s, seg.end_s,
                    )));
                }
                continue;
            }
            let n = range.len();
            match seg.kind {
                SegmentKind::Position { up } => {
                    let (am, asd, apk) = triad_stats(&accel, range.clone(), scale);
                    let (gm, gsd, gpk) = triad_stats(&gyro, range, scale);
                    input.positions.push(PositionMean {
                        up,
                        c_bn: up.c_bn_up(),
                        accel_raw: am,
                        accel_std_raw: asd,
                        accel_peak_abs_raw: apk,
                        gyro_raw: gm,
                        gyro_std_raw: gsd,
                        gyro_peak_abs_raw: gpk,
                        n,
                    });
                }
                SegmentKind::Rate { axis, rate_rad_s } => {
                    let (gm, gsd, gpk) = triad_stats(&gyro, range, scale);
                    input.rates.push(RateMean {
                        axis,
                        rate_rad_s,
                        up: SignedAxis::new(axis, true),
                        gyro_raw: gm,
                        gyro_std_raw: gsd,
                        gyro_peak_abs_raw: gpk,
                        n,
                    });
                }
                SegmentKind::Soak | SegmentKind::Move => {}
            }
        }
        Ok(input)
    }
}

//! Whether a static log's values are plausible for the units its channels claim — the
//! check that catches a mislabelled column (deg/s read as rad/s, g read as m/s²) before
//! its noise terms go into a filter 57 or 9.8 times off.
//!
//! All on rate (frequency) data of a sensor at rest, in SI after the reader's conversion:
//!
//! * gyro: |mean| ≤ `MAX_GYRO_BIAS_RAD_S` (any MEMS turn-on bias is far below 1 rad/s;
//!   the Earth turns at 7.3·10⁻⁵ rad/s); white noise read from the sample spread,
//!   N ≈ s·√τ₀ (the white term dominates the sample variance at the sampling interval for
//!   a MEMS gyro; an upper bound otherwise), between `MIN_ARW_DEG_RT_H` (a navigation-grade
//!   gyro) and `MAX_ARW_DEG_RT_H` (the noisiest consumer parts are near 10 °/√h);
//! * accelerometer: with three accelerometer channels, the magnitude of the mean specific
//!   force at rest is g ≈ 9.81 m/s² (9.78–9.83 on the Earth's surface); outside
//!   `ACCEL_AT_REST_M_S2` the unit or the static assumption is wrong, and the ratio to g
//!   says which unit it looks like; per channel, white noise as for the gyro against
//!   `MAX_VRW_M_S_RT_H`.
//!
//! Each finding is one warning naming the channel, the figure, and what to check.

use crate::io::Quantity;

/// Largest plausible |mean| of a gyro at rest, rad/s (≈ 57 °/s).
pub(crate) const MAX_GYRO_BIAS_RAD_S: f64 = 1.0;
/// Largest plausible angle random walk, °/√h.
pub(crate) const MAX_ARW_DEG_RT_H: f64 = 30.0;
/// Smallest plausible angle random walk for a MEMS-class log, °/√h (a navigation-grade
/// ring-laser gyro is near 0.001 °/√h).
pub(crate) const MIN_ARW_DEG_RT_H: f64 = 5e-4;
/// Largest plausible velocity random walk, m/s/√h.
pub(crate) const MAX_VRW_M_S_RT_H: f64 = 3.0;
/// Range of |mean specific force| that is a sensor at rest on the Earth, m/s².
pub(crate) const ACCEL_AT_REST_M_S2: (f64, f64) = (9.0, 10.6);

/// One channel to check: name, quantity, the unit the file gave, the SI values.
#[derive(Clone, Copy, Debug)]
pub struct ChannelInput<'a> {
    /// Channel name (for the warning).
    pub name: &'a str,
    /// What the channel measures.
    pub quantity: Quantity,
    /// The unit as the file or the user stated it.
    pub stated_unit: &'a str,
    /// Values, SI (rad/s, m/s²).
    pub values: &'a [f64],
}

/// Mean and sample standard deviation of the finite values (two passes, no copy).
fn mean_sd(v: &[f64]) -> Option<(f64, f64)> {
    let finite = || v.iter().copied().filter(|x| x.is_finite());
    let (n, sum) = finite().fold((0usize, 0.0), |(n, s), x| (n + 1, s + x));
    if n < 2 {
        return None;
    }
    let m = sum / n as f64;
    let var = finite().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
    Some((m, var.sqrt()))
}

/// The unit warnings of a static log sampled every `tau0_s` (module docs).
pub fn unit_warnings(channels: &[ChannelInput<'_>], tau0_s: f64) -> Vec<String> {
    let mut out = Vec::new();
    if !(tau0_s > 0.0 && tau0_s.is_finite()) {
        return out;
    }
    let sqrt_h = 60.0; // √(3600 s)
    let mut accel_means = Vec::new();
    for c in channels {
        let Some((mean, sd)) = mean_sd(c.values) else {
            continue;
        };
        let white = sd * tau0_s.sqrt(); // u·√s
        match c.quantity {
            Quantity::AngularRate => {
                if mean.abs() > MAX_GYRO_BIAS_RAD_S {
                    out.push(format!(
                        "{}: mean {:.3} rad/s ({:.1} deg/s) at rest is implausible for a gyro \
                         (turn-on biases are far below 1 rad/s): check the unit (the file says \
                         {}) and that the log is static",
                        c.name,
                        mean,
                        mean.to_degrees(),
                        c.stated_unit
                    ));
                }
                let arw = white.to_degrees() * sqrt_h;
                if arw > MAX_ARW_DEG_RT_H {
                    out.push(format!(
                        "{}: white noise ≈ {arw:.0} deg/sqrt(h) from the sample spread is \
                         implausible for a gyro (MEMS parts: 0.1–10 deg/sqrt(h)): check the \
                         unit (the file says {}; deg/s read as rad/s gives 57× too much) and \
                         the sample rate",
                        c.name, c.stated_unit
                    ));
                } else if arw > 0.0 && arw < MIN_ARW_DEG_RT_H {
                    out.push(format!(
                        "{}: white noise ≈ {arw:.2e} deg/sqrt(h) from the sample spread is below \
                         a navigation-grade gyro's: check the unit (the file says {}; rad/s read \
                         as deg/s gives 57× too little) and the sample rate",
                        c.name, c.stated_unit
                    ));
                }
            }
            Quantity::SpecificForce => {
                accel_means.push((c.name, mean, c.stated_unit));
                let vrw = white * sqrt_h;
                if vrw > MAX_VRW_M_S_RT_H {
                    out.push(format!(
                        "{}: white noise ≈ {vrw:.1} m/s/sqrt(h) from the sample spread is \
                         implausible for an accelerometer (MEMS parts: 0.02–0.5 m/s/sqrt(h)): \
                         check the unit (the file says {}; m/s² read as g gives 9.8× too much) \
                         and the sample rate",
                        c.name, c.stated_unit
                    ));
                }
            }
            _ => {}
        }
    }
    if accel_means.len() == 3 {
        let g = accel_means.iter().map(|a| a.1 * a.1).sum::<f64>().sqrt();
        let (lo, hi) = ACCEL_AT_REST_M_S2;
        if !(lo..=hi).contains(&g) {
            let names: Vec<&str> = accel_means.iter().map(|a| a.0).collect();
            let looks = if (lo / 9.80665..=hi / 9.80665).contains(&g) {
                " — it is ≈ 1: the values look like g"
            } else if (lo * 1000.0 / 9.80665..=hi * 1000.0 / 9.80665).contains(&g) {
                " — it is ≈ 1000: the values look like mg"
            } else if (lo * 9.80665..=hi * 9.80665).contains(&g) {
                " — it is ≈ 96: the values look like m/s² read as g"
            } else {
                ""
            };
            out.push(format!(
                "{}: the mean specific force at rest is {g:.4} m/s², not g ≈ 9.81 m/s²{looks}: \
                 check the unit (the file says {}) and that the log is static",
                names.join(", "),
                accel_means[0].2
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, sd: f64, mean: f64, seed: u64) -> Vec<f64> {
        // Sum of 12 uniforms − 6: unit variance.
        let mut s = seed;
        (0..n)
            .map(|_| {
                let mut acc = 0.0;
                for _ in 0..12 {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    acc += (s >> 11) as f64 / (1u64 << 53) as f64;
                }
                mean + sd * (acc - 6.0)
            })
            .collect()
    }

    fn check(gyro_scale: f64, accel_scale: f64) -> Vec<String> {
        // ADIS16405-like at 100 Hz: gyro σ 0.0072 rad/s (N ≈ 2.5 deg/√h), accel σ 0.04 m/s²
        // (VRW ≈ 0.24 m/s/√h), at rest level: f = (0, 0, −g).
        let tau0 = 0.01;
        let g: Vec<Vec<f64>> = (0..3)
            .map(|k| noise(20_000, 0.0072 * gyro_scale, 0.002 * gyro_scale, k))
            .collect();
        let a: Vec<Vec<f64>> = (0..3)
            .map(|k| {
                let m = if k == 2 { -9.80665 } else { 0.05 };
                noise(20_000, 0.04 * accel_scale, m * accel_scale, 10 + k)
            })
            .collect();
        let names = ["gx", "gy", "gz", "ax", "ay", "az"];
        let chans: Vec<ChannelInput<'_>> = (0..6)
            .map(|i| ChannelInput {
                name: names[i],
                quantity: if i < 3 {
                    Quantity::AngularRate
                } else {
                    Quantity::SpecificForce
                },
                stated_unit: if i < 3 { "rad/s" } else { "m/s^2" },
                values: if i < 3 { &g[i] } else { &a[i - 3] },
            })
            .collect();
        unit_warnings(&chans, tau0)
    }

    #[test]
    fn correct_units_pass_and_each_mislabel_is_named() {
        assert!(check(1.0, 1.0).is_empty(), "{:?}", check(1.0, 1.0));
        // deg/s values read as rad/s: every gyro's noise is 57× too high.
        let w = check(57.29578, 1.0);
        assert_eq!(w.len(), 3, "{w:?}");
        assert!(w.iter().all(|s| s.contains("deg/s read as rad/s")), "{w:?}");
        // Values in g read as m/s²: one warning naming the three channels and "g".
        let w = check(1.0, 1.0 / 9.80665);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("ax, ay, az") && w[0].contains("look like g"),
            "{w:?}"
        );
        // Values in mg read as m/s²: the magnitude and the noise both flag it.
        let w = check(1.0, 1000.0 / 9.80665);
        assert!(w.iter().any(|s| s.contains("look like mg")), "{w:?}");
        // A gyro biased by 20 rad/s.
        let mut g = noise(1000, 0.007, 20.0, 3);
        g[0] = f64::NAN; // non-finite values are skipped, not propagated
        let w = unit_warnings(
            &[ChannelInput {
                name: "gz",
                quantity: Quantity::AngularRate,
                stated_unit: "rad/s",
                values: &g,
            }],
            0.01,
        );
        assert!(w.len() == 1 && w[0].contains("gz: mean 20.0"), "{w:?}");
    }
}

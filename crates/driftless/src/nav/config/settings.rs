//! The settings a navigation job needs, resolved from a checked configuration: time base,
//! IMU stream and check options, GNSS quality handling, the gate and the noise model.

use super::*;

impl NavConfig {
    /// The IMU time base.
    pub fn time_base(&self) -> Result<crate::io::nav::TimeBase, String> {
        self.imu
            .time_base
            .parse()
            .map_err(|e: crate::io::nav::ParseTimeBaseError| e.to_string())
    }

    /// The IMU stream options: time offset, time base, mounting, gap policy, nominal
    /// interval.
    pub fn stream_options(&self) -> ImuStreamOptions {
        let i = &self.imu;
        ImuStreamOptions {
            time_base: self.time_base().unwrap_or_default(),
            time_shift_s: i.time_offset_s,
            mounting: Mounting {
                rpy_deg: i.mounting_rpy_deg,
                misalignment_rpy_deg: i.misalignment_rpy_deg,
            },
            gap_policy: if i.gaps == "bridge" {
                ImuGapPolicy::Bridge
            } else {
                ImuGapPolicy::Error
            },
            nominal_dt_s: i.rate_hz.map(|r| 1.0 / r),
            ..ImuStreamOptions::default()
        }
    }

    /// The IMU value checks ([`crate::nav::imu_check`]) with the configured hard limits.
    pub(crate) fn imu_check_config(&self) -> crate::nav::imu_check::ImuCheckConfig {
        crate::nav::imu_check::ImuCheckConfig {
            max_gyro_rad_s: self.imu.max_gyro_deg_s.to_radians(),
            max_accel_m_s2: self.imu.max_accel_g * driftless_model::units::STANDARD_GRAVITY,
            ..Default::default()
        }
    }

    /// The quality flags accepted (index = RTKLIB flag).
    pub(crate) fn accepted_qualities(&self) -> [bool; 7] {
        let mut ok = [false; 7];
        for (k, name) in QUALITY_NAMES.iter().enumerate() {
            ok[k] = self.gnss.accept.iter().any(|a| a == name);
        }
        ok
    }

    /// σ multipliers per quality flag.
    pub(crate) fn quality_scale(&self) -> QualityScale {
        QualityScale(self.gnss.sigma_scale.as_array())
    }

    /// (horizontal, vertical) fixed σ floor, m; `None` when both are zero. With `auto`
    /// the horizontal part is 0 and the vertical one is `sigma_floor_vertical_m` if given.
    pub fn sigma_floor_m(&self) -> Option<(f64, f64)> {
        let (h, v) = match self.gnss.sigma_floor_m {
            FloorSetting::Auto => (0.0, self.gnss.sigma_floor_vertical_m.unwrap_or(0.0)),
            FloorSetting::Metres(h) => (h, self.gnss.sigma_floor_vertical_m.unwrap_or(2.0 * h)),
        };
        (h > 0.0 || v > 0.0).then_some((h, v))
    }

    /// True when the σ floor is estimated from the data (`gnss.sigma_floor_m = "auto"`).
    pub fn auto_sigma_floor(&self) -> bool {
        self.gnss.sigma_floor_m == FloorSetting::Auto
    }

    /// The innovation gate ([`Gate`]: `off`, `chi2:P`, `robust` or
    /// `robust:P_INFLATE:P_REJECT:MAX_SIGMA_SCALE`).
    pub fn gate(&self) -> Result<Gate, KeyError> {
        self.filter.gate.trim().parse::<Gate>().map_err(|_| {
            key_err(
                "filter.gate",
                format!(
                    "{:?} is not a gate: expected one of {}",
                    self.filter.gate,
                    crate::nav::filter::model::GATE_CHOICES
                ),
            )
        })
    }

    /// The filter's noise model and the initial σ of its 12 sensor states, from the
    /// `[noise]` values over `model` (the noise-model file, when given) over the built-in
    /// consumer-MEMS values ([`NoiseSection`]).
    ///
    /// In-run bias: a Gauss–Markov σ when given; else σ² = B² + K²T/2 from the bias
    /// instability B and random walk K (as [`ImuNoise::from_noise_model`]); else the
    /// model's; else the built-in. Multipliers scale the white densities, the in-run bias
    /// σ and the scale-factor σ.
    pub fn noise_settings(
        &self,
        model: Option<&crate::allan::noise_model::NoiseModel>,
    ) -> Result<(ImuNoise, [f64; 12]), KeyError> {
        let n = &self.noise;
        check_noise_ranges(n)?;
        let base = match model {
            Some(m) => {
                let dummy = GaussMarkov {
                    sigma: 1.0,
                    tau_s: n.scale_tau_s,
                };
                ImuNoise::from_noise_model(m, n.bias_tau_s, dummy, dummy)
                    .map_err(|e| key_err("noise.model", e.to_string()))?
            }
            None => crate::nav::session::consumer_mems_noise(),
        };
        let mut out = base;
        if let Some(v) = quantity("noise.gyro_white", &n.gyro_white, Kind::AngleRandomWalk)? {
            out.gyro_arw_rad_sqrt_s = v;
        }
        if let Some(v) = quantity(
            "noise.accel_white",
            &n.accel_white,
            Kind::VelocityRandomWalk,
        )? {
            out.accel_vrw_m_s_sqrt_s = v;
        }
        let from_model = model.is_some();
        out.gyro_bias = in_run_bias(
            [
                ("noise.gyro_bias_sigma", &n.gyro_bias_sigma),
                ("noise.gyro_bias_instability", &n.gyro_bias_instability),
                ("noise.gyro_bias_random_walk", &n.gyro_bias_random_walk),
            ],
            (Kind::AngularRate, Kind::RateRandomWalk),
            base.gyro_bias,
            n.bias_tau_s,
            from_model,
        )?;
        out.accel_bias = in_run_bias(
            [
                ("noise.accel_bias_sigma", &n.accel_bias_sigma),
                ("noise.accel_bias_instability", &n.accel_bias_instability),
                ("noise.accel_bias_random_walk", &n.accel_bias_random_walk),
            ],
            (Kind::SpecificForce, Kind::AccelRandomWalk),
            base.accel_bias,
            n.bias_tau_s,
            from_model,
        )?;
        let sg = required_quantity("noise.gyro_scale_sigma", &n.gyro_scale_sigma, Kind::Scale)?;
        let sa = required_quantity("noise.accel_scale_sigma", &n.accel_scale_sigma, Kind::Scale)?;
        apply_multipliers(&mut out, n, sg, sa);
        check_noise_nonzero(&out)?;
        let bg0 = required_quantity(
            "noise.gyro_bias_initial",
            &n.gyro_bias_initial,
            Kind::AngularRate,
        )?;
        let ba0 = required_quantity(
            "noise.accel_bias_initial",
            &n.accel_bias_initial,
            Kind::SpecificForce,
        )?;
        check_noise_plausible(&out, bg0, ba0)?;
        let s0 = initial_sensor_sigma(&out, bg0, ba0)?;
        Ok((out, s0))
    }
}

/// An optional `[noise]` quantity parsed to the SI unit of `kind` (an error by `key`).
fn quantity(key: &str, v: &Option<String>, kind: Kind) -> Result<Option<f64>, KeyError> {
    v.as_deref()
        .map(|s| parse_quantity(s, kind).map_err(|e| key_err(key, e.to_string())))
        .transpose()
}

/// A required `[noise]` quantity parsed to the SI unit of `kind` (an error by `key`).
fn required_quantity(key: &str, v: &str, kind: Kind) -> Result<f64, KeyError> {
    parse_quantity(v, kind).map_err(|e| key_err(key, e.to_string()))
}

/// The correlation times (> 0, ≤ 10⁹ s) and the multipliers (> 0, ≤ 10⁴) of `[noise]`.
fn check_noise_ranges(n: &NoiseSection) -> Result<(), KeyError> {
    positive("noise.bias_tau_s", n.bias_tau_s, 1e9, "s")?;
    positive("noise.scale_tau_s", n.scale_tau_s, 1e9, "s")?;
    for (k, v) in [
        ("white", n.multiplier.white),
        ("bias", n.multiplier.bias),
        ("scale", n.multiplier.scale),
    ] {
        if !(v.is_finite() && v > 0.0 && v <= 1e4) {
            return Err(key_err(
                "noise.multiplier",
                format!("{k} = {v}: a multiplier is > 0 (1 = as given)"),
            ));
        }
    }
    Ok(())
}

/// In-run bias of one sensor as a Gauss–Markov process with correlation time `tau_s`:
/// the given σ (`keys[0]`); else σ² = B² + K²T/2 from the bias instability B (`keys[1]`)
/// and random walk K (`keys[2]`); else `base` (its own time when `from_model`).
fn in_run_bias(
    keys: [(&str, &Option<String>); 3],
    kinds: (Kind, Kind),
    base: GaussMarkov,
    tau_s: f64,
    from_model: bool,
) -> Result<GaussMarkov, KeyError> {
    let t = tau_s;
    let [(sigma_key, sigma), (b_key, b), (k_key, k)] = keys;
    if let Some(s) = quantity(sigma_key, sigma, kinds.0)? {
        return Ok(GaussMarkov { sigma: s, tau_s: t });
    }
    let bi = quantity(b_key, b, kinds.0)?;
    let rw = quantity(k_key, k, kinds.1)?;
    if bi.is_none() && rw.is_none() {
        return Ok(GaussMarkov {
            sigma: base.sigma,
            tau_s: if from_model { base.tau_s } else { t },
        });
    }
    let (b, k) = (bi.unwrap_or(0.0), rw.unwrap_or(0.0));
    Ok(GaussMarkov {
        sigma: (b * b + k * k * t / 2.0).sqrt(),
        tau_s: t,
    })
}

/// Scales the white densities, in-run bias σ and scale-factor σ (`sg`, `sa`) by the
/// `[noise]` multipliers and sets the scale-factor processes (time `scale_tau_s`).
fn apply_multipliers(out: &mut ImuNoise, n: &NoiseSection, sg: f64, sa: f64) {
    let m = n.multiplier;
    out.gyro_arw_rad_sqrt_s *= m.white;
    out.accel_vrw_m_s_sqrt_s *= m.white;
    out.gyro_bias.sigma *= m.bias;
    out.accel_bias.sigma *= m.bias;
    out.gyro_scale = GaussMarkov {
        sigma: sg * m.scale,
        tau_s: n.scale_tau_s,
    };
    out.accel_scale = GaussMarkov {
        sigma: sa * m.scale,
        tau_s: n.scale_tau_s,
    };
}

/// Every scale-factor σ, in-run bias σ and white density of `out` > 0 (the filter needs
/// some uncertainty).
fn check_noise_nonzero(out: &ImuNoise) -> Result<(), KeyError> {
    for (key, v, kind) in [
        ("noise.gyro_scale_sigma", out.gyro_scale.sigma, "scale"),
        ("noise.accel_scale_sigma", out.accel_scale.sigma, "scale"),
        ("noise.gyro_bias_sigma", out.gyro_bias.sigma, "bias"),
        ("noise.accel_bias_sigma", out.accel_bias.sigma, "bias"),
    ] {
        if v <= 0.0 {
            return Err(key_err(
                key,
                format!(
                    "the {kind} σ is zero: give a value > 0 (the filter needs some uncertainty)"
                ),
            ));
        }
    }
    if out.gyro_arw_rad_sqrt_s <= 0.0 || out.accel_vrw_m_s_sqrt_s <= 0.0 {
        return Err(key_err("noise.gyro_white", "white noise must be > 0"));
    }
    Ok(())
}

/// Plausible magnitudes (the usual unit mix-ups show as absurd ones): gyro white noise
/// ≤ 0.01 rad/√s, gyro bias σ ≤ 0.2 rad/s, accelerometer bias σ ≤ 20 m/s²; `bg0`, `ba0`:
/// the turn-on bias σ.
fn check_noise_plausible(out: &ImuNoise, bg0: f64, ba0: f64) -> Result<(), KeyError> {
    let deg_s = |v: f64| v.to_degrees();
    if out.gyro_arw_rad_sqrt_s > 0.01 {
        return Err(key_err(
            "noise.gyro_white",
            format!(
                "{:.0} deg/sqrt(h) is implausible for a gyro: check the unit (deg/sqrt(h) vs deg/s/sqrt(Hz))",
                deg_s(out.gyro_arw_rad_sqrt_s) * 60.0
            ),
        ));
    }
    if bg0 > 0.2 || out.gyro_bias.sigma > 0.2 {
        return Err(key_err(
            "noise.gyro_bias_initial",
            format!(
                "gyro bias σ {:.1} deg/s is implausible: check the unit (deg/h vs deg/s)",
                deg_s(bg0.max(out.gyro_bias.sigma))
            ),
        ));
    }
    if ba0 > 20.0 || out.accel_bias.sigma > 20.0 {
        return Err(key_err(
            "noise.accel_bias_initial",
            "accelerometer bias σ above 2 g is implausible: check the unit (mg vs m/s^2)",
        ));
    }
    Ok(())
}

/// Initial σ of the 12 sensor states (gyro bias, accelerometer bias, gyro scale,
/// accelerometer scale, three axes each): the larger of turn-on and in-run bias σ, the
/// scale-factor σ; an error when one is not > 0.
fn initial_sensor_sigma(out: &ImuNoise, bg0: f64, ba0: f64) -> Result<[f64; 12], KeyError> {
    let mut s0 = [0.0; 12];
    for k in 0..3 {
        s0[k] = bg0.max(out.gyro_bias.sigma);
        s0[3 + k] = ba0.max(out.accel_bias.sigma);
        s0[6 + k] = out.gyro_scale.sigma;
        s0[9 + k] = out.accel_scale.sigma;
    }
    if s0.iter().any(|v| *v <= 0.0) {
        return Err(key_err(
            "noise.gyro_bias_initial",
            "initial bias σ must be > 0",
        ));
    }
    Ok(s0)
}

//! `driftless thermal soak LOG [--manifest M]`: the soak method —
//! six-position + rate-table calibration at every set temperature of a chamber
//! recording (the temperature steps from the manifest, or without one from the log's own
//! segmentation), polynomial fits of each bias and scale series, the real-time compensation
//! model file (`--out`) and the bias/scale-versus-temperature figure (`--plot`).
//! `driftless thermal ramp LOG [--out MODEL.toml]`: the ramp method, optionally as a
//! bias-only model file. `driftless thermal export MODEL.toml --px4 F.params
//! --ardupilot F.param`: the model's bias part as autopilot parameters
//! (`docs/autopilot-thermal.md`), re-read and checked against the model.

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use driftless::calib::protocol::ChamberManifest;
use driftless::io::ImuLog;
use driftless::thermal::FitOptions;
use driftless::thermal::check::{CheckOptions, Impact, ThermalCheck, check_log};
use driftless::thermal::job::{RampInput, ramp_precheck, run_ramp, run_soak, soak_precheck};
use driftless::thermal::model_file::ThermalModelFile;
use driftless::thermal::ramp::RampOptions;
use driftless_model::compensation::OutOfRange;
use std::path::PathBuf;

use crate::input::InputArgs;

#[derive(Args, Debug)]
pub struct ThermalArgs {
    #[command(subcommand)]
    pub method: ThermalMethod,
}

#[derive(Subcommand, Debug)]
pub enum ThermalMethod {
    /// Chamber (soak) recording + segment manifest → thermal model.
    Soak(SoakArgs),
    /// Bias versus temperature from one warm-up or cool-down of a static sensor.
    Ramp(RampArgs),
    /// A model's bias part as PX4 TC_* and/or ArduPilot INS_TCAL* parameter files.
    Export(ExportArgs),
    /// Can this log give a thermal model? Temperature range, rise and resolution,
    /// heating-rate profile, motion and gaps, with a verdict per IMU instance.
    Check(CheckArgs),
}

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Log: CSV/text or DRIFTLOG (one IMU), PX4 ULog or ArduPilot DataFlash (every IMU
    /// instance is checked).
    pub log: PathBuf,
    /// Polynomial order the model will have (sets how many levels/plateaus are needed).
    #[arg(long, default_value_t = 3, value_parser = crate::numbers::whole::<usize>, allow_hyphen_values = true)]
    pub order: usize,
    /// Smallest temperature rise a model needs, °C.
    #[arg(long, default_value_t = 10.0, value_parser = crate::numbers::non_negative, allow_hyphen_values = true)]
    pub min_rise: f64,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub input: InputArgs,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// Thermal compensation model file (TOML), from `thermal soak|ramp --out`.
    pub model: PathBuf,
    /// Write PX4 parameters here (QGroundControl .params).
    #[arg(long, value_name = "FILE.params")]
    pub px4: Option<PathBuf>,
    /// Write ArduPilot parameters here (Mission Planner .param).
    #[arg(long, value_name = "FILE.param")]
    pub ardupilot: Option<PathBuf>,
    /// Sensor instance: PX4 TC_A<N>/TC_G<N> (0-3), ArduPilot INS_TCAL<N+1> (0-2).
    #[arg(long, default_value_t = 0, value_parser = crate::numbers::whole::<usize>, allow_hyphen_values = true)]
    pub instance: usize,
    /// Only the temperature dependence: no room offsets (PX4 X0 = 0 and no CAL_*OFF;
    /// ArduPilot no INS_*OFFS / CALTEMP), the vehicle's own calibration stays.
    #[arg(long)]
    pub no_offsets: bool,
    /// PX4 TC_A<N>_ID: the accelerometer's device id (CAL_ACC<N>_ID).
    #[arg(long, default_value_t = 0)]
    pub px4_accel_id: i32,
    /// PX4 TC_G<N>_ID: the gyro's device id (CAL_GYRO<N>_ID).
    #[arg(long, default_value_t = 0)]
    pub px4_gyro_id: i32,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct RampArgs {
    /// Static log: time, gyro and/or accelerometer columns with units, one temperature
    /// column (°C); or a PX4 ULog (`sensor_gyro`/`sensor_accel`) or ArduPilot DataFlash
    /// (`IMU`) log, recognised by its magic bytes (pick the IMU with `--instance N`).
    pub log: PathBuf,
    /// Polynomial order, 1–5.
    #[arg(long, default_value_t = 3, value_parser = crate::numbers::whole::<usize>, allow_hyphen_values = true)]
    pub order: usize,
    /// Reference temperature, °C.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub t_ref: f64,
    /// Temperature bin width, °C.
    #[arg(long, default_value_t = 1.0, value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub bin: f64,
    /// Smallest temperature rise the log must show, °C (the checks of `thermal check`
    /// run first and refuse a log that cannot give a model).
    #[arg(long, default_value_t = 10.0, value_parser = crate::numbers::non_negative, allow_hyphen_values = true)]
    pub min_rise: f64,
    /// Write a bias-only compensation model file here (TOML): matrix I, no scale terms,
    /// gyro bias = fit at T_ref, accelerometer bias 0 (not separable from gravity).
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub input: InputArgs,
}

#[derive(Args, Debug)]
pub struct SoakArgs {
    /// IMU log: time + gyro x, y, z + accel x, y, z (+ temperature), sample k at k/rate
    /// from the protocol start (the `imu.csv` of a `driftless simulate` chamber run).
    pub log: PathBuf,
    /// Segment manifest (TOML): positions and rate segments per set temperature
    /// (default: segment the log from its data — static positions, rotations and
    /// temperature plateaus — and print the segmentation; needs --lat-deg, --height-m).
    #[arg(long)]
    pub manifest: Option<PathBuf>,
    /// Without a manifest: site latitude, deg (normal gravity and the Earth rate).
    #[arg(long, allow_hyphen_values = true)]
    pub lat_deg: Option<f64>,
    /// Without a manifest: site ellipsoidal height, m.
    #[arg(long, allow_hyphen_values = true)]
    pub height_m: Option<f64>,
    /// Without a manifest: gravity magnitude, m/s² (default: normal gravity at the site).
    #[arg(long, value_name = "M_S2", value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub gravity: Option<f64>,
    #[command(flatten)]
    pub segment: crate::segment_view::SegmentArgs,
    /// Polynomial order, 1–5.
    #[arg(long, default_value_t = 3, value_parser = crate::numbers::whole::<usize>, allow_hyphen_values = true)]
    pub order: usize,
    /// Reference temperature, °C.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub t_ref: f64,
    /// Allan noise model of the sensor (`driftless allan --save-model`): its bias
    /// instability and rate random walk make the bias fits generalised least squares
    /// with the drift between temperature steps in the covariance, so the bands include
    /// it (without it they describe only the scatter within each step).
    #[arg(long, value_name = "FILE.toml")]
    pub noise_model: Option<PathBuf>,
    /// Smallest span of the set temperatures, °C.
    #[arg(long, default_value_t = 10.0, value_parser = crate::numbers::non_negative, allow_hyphen_values = true)]
    pub min_rise: f64,
    /// Outside the soaked range: clamp, extrapolate or error.
    #[arg(long, default_value = "clamp")]
    pub out_of_range: String,
    /// Write the compensation model file here (TOML).
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Plot bias and scale factor versus temperature with the fits (SVG, or PNG).
    #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = crate::output::figure_path)]
    pub plot: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub input: InputArgs,
}

pub fn run(a: ThermalArgs) -> Result<()> {
    match a.method {
        ThermalMethod::Soak(s) => soak(s),
        ThermalMethod::Ramp(r) => ramp(r),
        ThermalMethod::Export(e) => export(e),
        ThermalMethod::Check(c) => check(c),
    }
}

/// What the "scatter/σ" column means.
const SCATTER_NOTE: &str = "scatter/σ: √(χ²/dof) of the points against their own σ; where \
     above 1 the σ and bands are scaled by it (×), so they match the scatter seen";

/// "1.23 ×" when the σ were scaled by the scatter, "0.87" when not, "–" without σ.
fn scatter_cell(f: &driftless::thermal::ThermalFit) -> String {
    match f.scatter_ratio {
        Some(r) if f.noise_scale == driftless::thermal::NoiseScale::Inflated => {
            format!("{r:.2} ×")
        }
        Some(r) => format!("{r:.2}"),
        None => "–".into(),
    }
}

/// Every IMU instance of `path` with its label: all instances of an autopilot log, or
/// the one log of a text / DRIFTLOG file. Gaps are bridged (and reported by the check)
/// unless `--gaps` asks otherwise.
fn read_instances(path: &std::path::Path, input: &InputArgs) -> Result<Vec<(String, ImuLog)>> {
    let opened = driftless::io::LogInput::open(path)?;
    #[cfg(feature = "autopilot-logs")]
    if opened.is_autopilot() {
        {
            let all = opened.read_autopilot()?;
            if all.imus.is_empty() {
                anyhow::bail!(
                    "{}: {} log without IMU data (found: {}); nothing to check",
                    path.display(),
                    all.format.name(),
                    all.found
                        .iter()
                        .map(|(n, c)| format!("{n} ×{c}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            if let Some(at) = all.truncated_at_byte {
                eprintln!(
                    "{}: truncated; read up to the message cut off at byte {at}",
                    path.display()
                );
            }
            return Ok(all
                .imus
                .into_iter()
                .map(|i| (format!("{} instance {}", path.display(), i.instance), i.log))
                .collect());
        }
    }
    read_one(opened, input)
}

/// The one log of a text / DRIFTLOG input, gaps bridged unless `--gaps` asks otherwise.
fn read_one(opened: driftless::io::LogInput, input: &InputArgs) -> Result<Vec<(String, ImuLog)>> {
    let mut input = input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    if input.gaps == "error" {
        input.gaps = "bridge".into();
    }
    let name = opened.name().to_owned();
    let log = input.read_input(opened)?;
    Ok(vec![(name, log)])
}

/// Check options for a fit of `order`.
fn check_options(order: usize, min_rise_c: f64) -> Result<CheckOptions> {
    if !(min_rise_c.is_finite() && min_rise_c >= 0.0) {
        anyhow::bail!("--min-rise {min_rise_c}: give a temperature rise in °C, ≥ 0");
    }
    Ok(CheckOptions {
        order,
        min_rise_c,
        ..CheckOptions::default()
    })
}

fn check(c: CheckArgs) -> Result<()> {
    let opts = check_options(c.order, c.min_rise)?;
    let reports: Vec<ThermalCheck> = read_instances(&c.log, &c.input)?
        .iter()
        .map(|(label, log)| check_log(log, label, &opts))
        .collect();
    if c.json {
        outln!("{}", serde_json::to_string_pretty(&reports)?);
        return Ok(());
    }
    let mut tab = crate::output::Table::new(
        [
            "instance",
            "samples",
            "span (s)",
            "T (°C)",
            "rise (°C)",
            "LSB (°C)",
            "dT/dt p10/50/90 (°C/min)",
            "moving",
            "gaps",
            "verdict",
        ]
        .map(String::from)
        .to_vec(),
    );
    for r in &reports {
        let t = r.temperature.as_ref();
        let h = r.heating.as_ref();
        tab.row(vec![
            r.label.clone(),
            r.samples.to_string(),
            r.span
                .map_or("–".into(), |s| format!("{:.1}", s.end_s - s.start_s)),
            t.map_or("–".into(), |t| format!("{:.2}–{:.2}", t.min_c, t.max_c)),
            t.map_or("–".into(), |t| format!("{:.2}", t.rise_c)),
            t.map_or("–".into(), |t| format!("{:.3}", t.lsb_c)),
            h.map_or("–".into(), |h| {
                format!(
                    "{:.2}/{:.2}/{:.2}",
                    h.rate_p10_c_per_min, h.rate_median_c_per_min, h.rate_p90_c_per_min
                )
            }),
            r.motion.as_ref().map_or("–".into(), |m| {
                format!("{:.1} %", 100.0 * m.moving_fraction)
            }),
            format!("{} ({:.1} s)", r.gaps.count, r.gaps.total_s),
            r.verdict().to_string(),
        ]);
    }
    out!("{}", tab.render());
    for r in &reports {
        outln!("{}: fit for {}", r.label, r.verdict());
        for f in &r.findings {
            let tag = |i: Impact| match i {
                Impact::Block => "refused",
                Impact::Warn => "warning",
                Impact::None => "–",
            };
            outln!(
                "  [ramp {}, soak {}] {}",
                tag(f.ramp),
                tag(f.soak),
                f.message
            );
        }
    }
    Ok(())
}

/// Prints the warnings of a check on stderr.
fn warn_all(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

fn soak(s: SoakArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(
        &[s.out.as_deref(), s.plot.as_deref()],
        &[
            Some(&s.log),
            s.manifest.as_deref(),
            s.noise_model.as_deref(),
        ],
    )?;
    let policy = match s.out_of_range.as_str() {
        "clamp" => OutOfRange::Clamp,
        "extrapolate" => OutOfRange::Extrapolate,
        "error" => OutOfRange::Error,
        other => anyhow::bail!("--out-of-range {other:?}: expected clamp, extrapolate or error"),
    };
    let mut input = s.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let log = input.read(&s.log)?;
    let (manifest, segmentation) = soak_manifest(&s, &log)?;
    let manifest_source = match &s.manifest {
        Some(p) => p.display().to_string(),
        None => format!("{} (plateaus found in the log)", s.log.display()),
    };
    let log_name = s.log.display().to_string();
    let check = check_options(s.order, s.min_rise)?;
    warn_all(&soak_precheck(
        &log,
        &log_name,
        &manifest,
        &manifest_source,
        &check,
    )?);
    let fit_opts = FitOptions {
        order: s.order,
        t_ref_c: s.t_ref,
        ..FitOptions::default()
    };
    let drift = match &s.noise_model {
        Some(p) => {
            let m = driftless::allan::noise_model::NoiseModel::load(p)?;
            Some(
                driftless::thermal::soak::SoakDrift::from_noise_model(&m)
                    .with_context(|| format!("{}", p.display()))?,
            )
        }
        None => None,
    };
    let run = run_soak(
        &log,
        &log_name,
        &manifest,
        &fit_opts,
        drift.as_ref(),
        policy,
    )?;
    let (soak, model, id, secs) = (&run.soak, &run.model, run.model_id, run.seconds);
    if let Some(p) = &s.out {
        ThermalModelFile::from_model(model, ["m/s^2", "rad/s"]).save(p)?;
    }
    if let Some(p) = &s.plot {
        driftless::report::thermal_plot::write_thermal_plot(
            p,
            &format!("soak calibration of {}", s.log.display()),
            soak,
            [
                ("bias (mg)", 1e3 / 9.80665),
                ("bias (deg/s)", 180.0 / std::f64::consts::PI),
            ],
        )
        .with_context(|| format!("writing {}", p.display()))?;
    }
    if s.json {
        return print_soak_json(&s, soak, id, segmentation, secs);
    }
    print_soak_human(&s, soak, secs);
    Ok(())
}

/// The `--json` document of a soak calibration.
fn print_soak_json(
    s: &SoakArgs,
    soak: &driftless::thermal::soak::SoakCalibration,
    id: u64,
    segmentation: Option<serde_json::Value>,
    secs: f64,
) -> Result<()> {
    let g_json = |g: &driftless::calib::six_position::GSensitivityEstimate| {
        serde_json::json!({
            "matrix": g.matrix_raw_per_m_s2.0,
            "sigma": g.sigma_raw_per_m_s2,
        })
    };
    let g_mean = soak.gyro_g_sensitivity_mean();
    let g_steps: Vec<Option<serde_json::Value>> = soak
        .gyro_g_sensitivity
        .iter()
        .map(|g| g.as_ref().map(g_json))
        .collect();
    let g_mean = g_mean.as_ref().map(g_json);
    let series: Vec<serde_json::Value> = soak
        .series
        .iter()
        .map(|x| {
            serde_json::json!({
                "triad": x.triad, "quantity": x.quantity, "axis": (["x", "y", "z"][x.axis]),
                "coefficients": x.fit.coeffs, "std_errors": x.fit.std_errors,
                "residual_rms": x.fit.residual_rms, "chi2_per_dof": x.fit.chi2_per_dof,
                // √(χ²/dof) of the points against their σ, and the factor applied
                // to the σ (≥ 1: the bands follow the scatter seen)
                "scatter_ratio": x.fit.scatter_ratio, "sigma_scale": x.fit.sigma_scale,
            })
        })
        .collect();
    outln!(
        "{}",
        serde_json::to_string_pretty(&serde_json::json!({
            "temperatures_c": soak.temperatures_c,
            "t_ref_c": s.t_ref,
            "order": s.order,
            "model_id": id,
            "series": series,
            // per step (order of temperatures_c), raw gyro units per m/s²; null when
            // not estimated
            "gyro_g_sensitivity": g_steps,
            "gyro_g_sensitivity_mean": g_mean,
            // the log's own segmentation when there was no manifest
            "segmentation": segmentation,
            "seconds": secs,
        }))?
    );
    Ok(())
}

/// The tables of a soak calibration.
fn print_soak_human(s: &SoakArgs, soak: &driftless::thermal::soak::SoakCalibration, secs: f64) {
    let g_mean = soak.gyro_g_sensitivity_mean();
    outln!(
        "{} set temperatures {:?} °C; order {} about {} °C; {:.3} s",
        soak.temperatures_c.len(),
        soak.temperatures_c,
        s.order,
        s.t_ref,
        secs
    );
    let mut head = vec!["series".to_string()];
    head.extend((0..=s.order).map(|k| format!("c{k} ± σ")));
    head.push("resid. RMS".into());
    head.push("scatter/σ".into());
    let mut tab = crate::output::Table::new(head);
    for x in &soak.series {
        let mut row = vec![format!(
            "{} {} {}",
            x.triad,
            x.quantity,
            ["x", "y", "z"][x.axis]
        )];
        for (c, e) in x.fit.coeffs.iter().zip(&x.fit.std_errors) {
            row.push(format!(
                "{} ± {}",
                crate::output::sci(*c),
                crate::output::sci(*e)
            ));
        }
        row.push(crate::output::sci(x.fit.residual_rms));
        row.push(scatter_cell(&x.fit));
        tab.row(row);
    }
    out!("{}", tab.render());
    outln!("{SCATTER_NOTE}");
    if let Some(g) = &g_mean {
        // Estimated per step (rate segments all +k up); the model file carries the mean.
        let d = |i: usize| {
            format!(
                "{} ± {}",
                crate::output::sci(g.matrix_raw_per_m_s2.0[i][i]),
                crate::output::sci(g.sigma_raw_per_m_s2[i][i])
            )
        };
        outln!(
            "gyro g-sensitivity (mean over {} steps, per m/s^2): G_xx {}, G_yy {}, G_zz {}",
            soak.gyro_g_sensitivity.len(),
            d(0),
            d(1),
            d(2)
        );
    }
    for p in [&s.out, &s.plot].into_iter().flatten() {
        outln!("wrote {}", p.display());
    }
}

/// The manifest of `--manifest`, or without one the log's own segmentation (printed
/// unless `--json`) with its JSON.
fn soak_manifest(
    s: &SoakArgs,
    log: &driftless::io::ImuLog,
) -> Result<(ChamberManifest, Option<serde_json::Value>)> {
    if let Some(path) = &s.manifest {
        let text = driftless::io::read_config_text(path, driftless::io::MAX_CONFIG_BYTES)
            .with_context(|| format!("reading {}", path.display()))?;
        let manifest =
            ChamberManifest::from_toml_str(&text).with_context(|| format!("{}", path.display()))?;
        return Ok((manifest, None));
    }
    let site = crate::segment_view::site(s.lat_deg, s.height_m, s.gravity, &s.log)?;
    let d = crate::segment_view::soak_from_log(log, &s.log, &s.segment, &site, s.json)?;
    Ok((d.manifest, Some(d.json)))
}

fn ramp(r: RampArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(&[r.out.as_deref()], &[Some(&r.log)])?;
    let mut input = r.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let log = input.read(&r.log)?;
    let log_name = r.log.display().to_string();
    warn_all(&ramp_precheck(
        &log,
        &log_name,
        &check_options(r.order, r.min_rise)?,
    )?);
    let input = RampInput::from_log(&log, &log_name)?;
    let (t_lo, t_hi) = input.temperature_range_c();
    note!(
        "{}: {} samples over {:.1} s, temperature {t_lo:.2}–{t_hi:.2} °C (span {:.2} °C)",
        r.log.display(),
        log.len(),
        input.span_s(),
        t_hi - t_lo
    );
    let opts = RampOptions {
        bin_c: r.bin,
        fit: FitOptions {
            order: r.order,
            t_ref_c: r.t_ref,
            ..FitOptions::default()
        },
        ..RampOptions::default()
    };
    let run = run_ramp(&input, &opts, r.out.is_some())?;
    let (res, heating) = (&run.result, run.heating_bins);
    if let (Some(p), Some(file)) = (&r.out, &run.model_file) {
        // Refuse to write what `compensate` and `export` would not read.
        file.model(&p.display().to_string())?;
        file.save(p)?;
    }
    if r.json {
        let fits: Vec<serde_json::Value> = res
            .names
            .iter()
            .zip(&res.fits)
            .enumerate()
            .map(|(k, (n, f))| {
                serde_json::json!({
                    "channel": n, "coefficients": f.coeffs, "std_errors": f.std_errors,
                    "residual_rms": f.residual_rms,
                    "scatter_ratio": f.scatter_ratio, "sigma_scale": f.sigma_scale,
                    "hysteresis_rms": res.hysteresis.as_ref().map(|h| h[k]),
                })
            })
            .collect();
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "bins_heating": heating,
                "bins_cooling": res.points.len() - heating,
                "t_ref_c": r.t_ref,
                "order": r.order,
                "fits": fits,
                "model_file": r.out.as_ref().map(|p| p.display().to_string()),
            }))?
        );
        return Ok(());
    }
    outln!(
        "{} temperature bins ({heating} heating, {} cooling); order {} about {} °C",
        res.points.len(),
        res.points.len() - heating,
        r.order,
        r.t_ref
    );
    let mut head = vec!["channel".to_string()];
    head.extend((0..=r.order).map(|k| format!("c{k} ± σ")));
    head.push("hysteresis RMS".into());
    head.push("scatter/σ".into());
    let mut tab = crate::output::Table::new(head);
    for (k, (n, f)) in res.names.iter().zip(&res.fits).enumerate() {
        let mut row = vec![n.clone()];
        for (c, e) in f.coeffs.iter().zip(&f.std_errors) {
            row.push(format!(
                "{} ± {}",
                crate::output::sci(*c),
                crate::output::sci(*e)
            ));
        }
        row.push(
            res.hysteresis
                .as_ref()
                .map_or("–".into(), |h| crate::output::sci(h[k])),
        );
        row.push(scatter_cell(f));
        tab.row(row);
    }
    out!("{}", tab.render());
    outln!("{SCATTER_NOTE}");
    if let Some(p) = &r.out {
        outln!("wrote {} (bias-only model)", p.display());
    }
    Ok(())
}

fn export(e: ExportArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(
        &[e.px4.as_deref(), e.ardupilot.as_deref()],
        &[Some(&e.model)],
    )?;
    use driftless::thermal::autopilot::{
        BiasModel, ExportOptions, check_temperatures, compare_ardupilot, compare_px4,
        export_ardupilot, export_px4, parse_ardupilot, parse_px4,
    };
    if e.px4.is_none() && e.ardupilot.is_none() {
        anyhow::bail!("nothing to write: give --px4 FILE.params and/or --ardupilot FILE.param");
    }
    let (file, model) = ThermalModelFile::load(&e.model)?;
    let name = e.model.display().to_string();
    let bm = BiasModel::from_model_file(&file, &name)?;
    let opts = ExportOptions {
        instance: e.instance,
        include_offsets: !e.no_offsets,
        px4_accel_id: e.px4_accel_id,
        px4_gyro_id: e.px4_gyro_id,
    };
    // Every written file is read back and its autopilot's formula compared with the model
    // at 10 temperatures over the range.
    let temps = check_temperatures(file.range_c, 10);
    let mut checks = Vec::new();
    if let Some(p) = &e.px4 {
        let text = export_px4(&bm, &opts)?;
        driftless::io::output::write(p, &text)
            .with_context(|| format!("writing {}", p.display()))?;
        let back = std::fs::read_to_string(p)?;
        let parsed = parse_px4(&back, &p.display().to_string(), e.instance)?;
        let err = compare_px4(&file, &model, &parsed, &temps, e.no_offsets)?;
        checks.push(("px4", p, err));
    }
    if let Some(p) = &e.ardupilot {
        let text = export_ardupilot(&bm, &opts)?;
        driftless::io::output::write(p, &text)
            .with_context(|| format!("writing {}", p.display()))?;
        let back = std::fs::read_to_string(p)?;
        let mut parsed = parse_ardupilot(&back, &p.display().to_string(), e.instance)?;
        if e.no_offsets {
            // No CALTEMP in the file: check relative to T_ref.
            parsed.acc_caltemp = file.t_ref_c as f32;
            parsed.gyr_caltemp = file.t_ref_c as f32;
        }
        let err = compare_ardupilot(&file, &model, &parsed, &temps, e.no_offsets)?;
        checks.push(("ardupilot", p, err));
    }
    let worst = checks
        .iter()
        .map(|(_, _, c)| c.accel_f32.max(c.gyro_f32))
        .fold(0.0f64, f64::max);
    let ds = |t: &driftless::thermal::autopilot::TriadBias| {
        t.scale_delta_max.iter().fold(0.0f64, |a, b| a.max(*b))
    };
    if e.json {
        let files: Vec<serde_json::Value> = checks
            .iter()
            .map(|(ap, p, c)| {
                serde_json::json!({
                    "autopilot": ap, "file": p.display().to_string(),
                    "max_error_accel_m_s2": c.accel, "max_error_gyro_rad_s": c.gyro,
                    "max_error_accel_f32_m_s2": c.accel_f32, "max_error_gyro_f32_rad_s": c.gyro_f32,
                })
            })
            .collect();
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "model_id": file.model_id,
                "instance": e.instance,
                "offsets": !e.no_offsets,
                "check_temperatures_c": temps,
                "files": files,
                "dropped_scale_delta_max": {"accel": ds(&bm.accel), "gyro": ds(&bm.gyro)},
                // PX4 and ArduPilot have no gyro g-sensitivity parameter
                "dropped_gyro_g_sensitivity": file.gyro_g_sensitivity.is_some(),
            }))?
        );
    } else {
        for (ap, p, c) in &checks {
            outln!(
                "wrote {} ({ap}); read back, max |model − {ap}| over 10 temperatures in \
                 [{}, {}] °C: accel {} m/s², gyro {} rad/s (float32 arithmetic)",
                p.display(),
                file.range_c[0],
                file.range_c[1],
                crate::output::sci(c.accel_f32),
                crate::output::sci(c.gyro_f32)
            );
        }
        outln!(
            "bias only: thermal scale-factor change dropped (max |Δs| accel {}, gyro {}); \
             misalignment and room scale left to the autopilot's own calibration",
            crate::output::sci(ds(&bm.accel)),
            crate::output::sci(ds(&bm.gyro))
        );
        if file.gyro_g_sensitivity.is_some() {
            outln!(
                "the model's gyro g-sensitivity is not exported: neither autopilot has a \
                 parameter for it"
            );
        }
    }
    if worst > 1e-6 {
        anyhow::bail!(
            "the written parameters differ from the model by {worst:.3e} (> 1e-6) after \
             float32 rounding: the model's values are too large for float32 parameters"
        );
    }
    Ok(())
}

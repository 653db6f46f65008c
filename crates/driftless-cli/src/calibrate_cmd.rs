//! `driftless calibrate six-position|multi-position`: room-temperature calibration
//! calibrated = M·(raw − b) of both triads, with σ, written as a calibration model file
//! (`--out`), printed as tables or as `--json`:
//! `{"accel":{"bias":[3],"matrix":[[3],[3],[3]],…},"gyro":{…},"static_intervals":[[t0,t1],…],
//! "quality":{"accel":{"chi2_per_dof","dof","warnings":[…],"implausible":[…]},"gyro":{…}}}`
//! (SI: m/s², rad/s; raw in the input's units). Multi-position adds
//! `"gyro_scale_estimate"` (null when `--gyro-scale-guess` was given) and
//! `"accepted_poor_fit"`; an implausible result fails unless `--accept-poor-fit`.

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use driftless::calib::job::{MultiPositionLogs, run_multi_position, run_six_position};
use driftless::calib::model_file::{CalibrationFile, TriadEntry};
use driftless::calib::multi_position::MultiPositionOptions;
use driftless::calib::protocol::ChamberManifest;
use driftless::calib::quality::FitQuality;
use driftless::io::ImuLog;
use std::path::{Path, PathBuf};

use crate::input::InputArgs;

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    #[command(subcommand)]
    pub method: Method,
}

#[derive(Subcommand, Debug)]
pub enum Method {
    /// Fixture-free calibration from hand-placed static poses (Tedaldi et al. 2014): the
    /// log starts at rest, then many static orientations with rotations in between.
    MultiPosition(MultiArgs),
    /// Six-position + rate-table calibration from a log and its segment manifest (the
    /// `manifest.toml` of a chamber protocol: positions and ±ω segments), or without a
    /// manifest from the positions and rotations found in the log itself.
    SixPosition(SixArgs),
}

#[derive(Args, Debug)]
pub struct Common {
    /// Gravity magnitude, m/s² (default: normal gravity at --lat-deg / --height-m).
    #[arg(long, value_name = "M_S2", value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub gravity: Option<f64>,
    /// Site latitude for normal gravity, deg.
    #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
    pub lat_deg: f64,
    /// Site height for normal gravity, m.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub height_m: f64,
    /// Write the calibration model file here (TOML).
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Plot the accelerometer residuals per static interval (SVG, or PNG by extension).
    #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = crate::output::figure_path)]
    pub plot: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub input: InputArgs,
}

#[derive(Args, Debug)]
pub struct MultiArgs {
    /// Accelerometer log (time + x, y, z), or one log with both triads (then give no
    /// GYRO: channels by quantity, or the first three = accel, next three = gyro).
    pub accel: PathBuf,
    /// Gyro log (time + x, y, z), sampled with the accelerometer.
    pub gyro: Option<PathBuf>,
    /// Gyro raw scale guess, rad/s per raw unit, within ±20 % (e.g. 1.6e-4 for 16-bit
    /// counts at ±300 deg/s; 1 for a log in rad/s). Default: found from the data (the
    /// tilts between poses against the integrated raw gyro).
    #[arg(long, value_name = "RAD_S_PER_RAW", value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub gyro_scale_guess: Option<f64>,
    /// Keep a result whose own quality figures are implausible (gravity direction after
    /// integrating the gyro beyond 3° RMS, or |a| − g far above its noise) instead of
    /// failing.
    #[arg(long)]
    pub accept_poor_fit: bool,
    /// Accelerometer zero offset, raw units (e.g. 32768 for offset-binary counts; the
    /// starting bias and the origin for classifying poses). Default: per axis, the
    /// middle of the 1st and 99th percentiles of the log.
    #[arg(long, value_name = "RAW", allow_hyphen_values = true)]
    pub accel_offset: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

#[derive(Args, Debug)]
pub struct SixArgs {
    /// IMU log: time + gyro x, y, z + accel x, y, z (the `imu.csv` of `driftless
    /// simulate`; channels by quantity or name), sample k at k/rate from the protocol
    /// start.
    pub log: PathBuf,
    /// Segment manifest (TOML) naming each static position and rate-table segment
    /// (default: segment the log from its data and print the segmentation).
    #[arg(long)]
    pub manifest: Option<PathBuf>,
    /// Set temperature to use when the manifest (or the log's temperature plateaus) has
    /// several, °C.
    #[arg(long, allow_hyphen_values = true)]
    pub temperature_c: Option<f64>,
    #[command(flatten)]
    pub segment: crate::segment_view::SegmentArgs,
    /// Also estimate the gyro g-sensitivity (3 × 3, raw per m/s²) from the positions.
    #[arg(long)]
    pub g_sensitivity: bool,
    #[command(flatten)]
    pub common: Common,
}

pub fn run(a: CalibrateArgs) -> Result<()> {
    match a.method {
        Method::MultiPosition(m) => multi(m),
        Method::SixPosition(s) => six(s),
    }
}

fn gravity(c: &Common) -> Result<f64> {
    let g = match c.gravity {
        Some(g) => g,
        None => driftless::calib::multi_position::gravity_at(c.lat_deg.to_radians(), c.height_m),
    };
    if !(g.is_finite() && (9.7..=9.9).contains(&g)) {
        bail!("--gravity {g} m/s² is not an Earth gravity (9.7–9.9)");
    }
    Ok(g)
}

/// Reads a log with the time in column 1 unless told otherwise.
fn read(input: &InputArgs, path: &Path) -> Result<ImuLog> {
    let mut input = input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    input.read(path)
}

fn multi(m: MultiArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(
        &[m.common.out.as_deref(), m.common.plot.as_deref()],
        &[Some(&m.accel), m.gyro.as_deref()],
    )?;
    let g = gravity(&m.common)?;
    let acc_log = read(&m.common.input, &m.accel)?;
    let gyro_log = match &m.gyro {
        Some(p) => Some((p.display().to_string(), read(&m.common.input, p)?)),
        None => None,
    };
    let acc_name = m.accel.display().to_string();
    let logs = MultiPositionLogs {
        accel: (&acc_name, &acc_log),
        gyro: gyro_log.as_ref().map(|(n, l)| (n.as_str(), l)),
    };
    let opts = MultiPositionOptions {
        gravity_m_s2: g,
        gyro_scale_guess_rad_s_per_raw: m.gyro_scale_guess,
        ..MultiPositionOptions::default()
    };
    let run = run_multi_position(logs, m.accel_offset, &opts)?;
    let (res, file, secs) = (&run.result, &run.file, run.seconds);
    let implausible = run.implausible();
    if !implausible.is_empty() && !m.accept_poor_fit {
        let list: Vec<String> = implausible.iter().map(|r| format!("  - {r}")).collect();
        bail!(
            "{} ({}): the multi-position calibration is implausible, so it was not written:\n{}\n(pass --accept-poor-fit to keep it anyway)",
            run.sources,
            run.span,
            list.join("\n")
        );
    }
    let quality = [
        ("accelerometer", &res.accel_quality),
        ("gyro", &res.gyro_quality),
    ];
    let resid = &run.residuals_m_s2;
    let residuals: Vec<Vec<String>> = res
        .intervals
        .iter()
        .zip(resid)
        .enumerate()
        .map(|(i, (iv, r))| {
            vec![
                format!("{}", i + 1),
                format!("{:.2}–{:.2}", iv.start_time_s, iv.end_time_s),
                format!("{:?}", iv.orientation),
                format!("{r:+.5}"),
            ]
        })
        .collect();
    if let Some(p) = &m.common.plot {
        driftless::report::calib_plot::write_residual_plot(
            p,
            &format!("multi-position calibration of {}", m.accel.display()),
            &[(
                "accelerometer after calibration",
                "|a| − g (m/s²)",
                resid.clone(),
            )],
        )
        .with_context(|| format!("writing {}", p.display()))?;
    }
    let before = run.before_rms_m_s2;
    let summary = [
        ("static intervals", format!("{}", res.intervals.len())),
        (
            "RMS |a| − g before (nominal offset, best single scale)",
            format!("{before:.5} m/s²"),
        ),
        ("threshold multiple", format!("{}", res.threshold_multiple)),
        (
            "RMS |a| − g after",
            format!("{:.5} m/s²", res.accel_norm_rms_m_s2),
        ),
        (
            "gravity direction after integrating the gyro, RMS",
            format!("{:.3}°", res.gravity_angle_rms_rad.to_degrees()),
        ),
        (
            "gyro scale",
            match &res.gyro_scale {
                Some(e) => format!(
                    "{} rad/s per raw unit, found from the data (RMS gravity angle {:.2}° at M = s·I)",
                    crate::output::sci(e.scale_rad_s_per_raw),
                    e.gravity_angle_rms_rad.to_degrees()
                ),
                None => format!(
                    "{} rad/s per raw unit, given (--gyro-scale-guess)",
                    crate::output::sci(m.gyro_scale_guess.unwrap_or(f64::NAN))
                ),
            },
        ),
        (
            "χ²/dof accel, gyro",
            format!(
                "{:.2}, {:.2}",
                res.accel_quality.chi2_per_dof, res.gyro_quality.chi2_per_dof
            ),
        ),
        ("time", format!("{:.3} s", secs)),
    ];
    let scale_json = res.gyro_scale.as_ref().map(|e| {
        serde_json::json!({
            "scale_rad_s_per_raw": e.scale_rad_s_per_raw,
            "gravity_angle_rms_rad": e.gravity_angle_rms_rad,
            "tilting_moves": e.tilting_moves,
            "runner_up": e.runner_up.map(|(s, a)| serde_json::json!({"scale_rad_s_per_raw": s, "gravity_angle_rms_rad": a})),
        })
    });
    output(
        &m.common,
        file,
        &summary,
        secs,
        (["#", "interval [s]", "pose", "|a| − g [m/s²]"], residuals),
        &quality,
        serde_json::json!({ "gyro_scale_estimate": scale_json, "accepted_poor_fit": !implausible.is_empty() }),
    )
}

fn six(s: SixArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(
        &[s.common.out.as_deref(), s.common.plot.as_deref()],
        &[Some(&s.log), s.manifest.as_deref()],
    )?;
    let log = read(&s.common.input, &s.log)?;
    let (manifest, temp, source, segmentation) = match &s.manifest {
        Some(path) => {
            let (m, t) = six_manifest(&s, path)?;
            (
                m,
                t,
                format!("{} + {}", s.log.display(), path.display()),
                None,
            )
        }
        None => six_segmented(&s, &log)?,
    };
    six_calibrate(&s, &log, &manifest, temp, source, segmentation)
}

/// Without `--manifest`: the log's own segmentation (printed unless `--json`).
fn six_segmented(
    s: &SixArgs,
    log: &ImuLog,
) -> Result<(ChamberManifest, f64, String, Option<serde_json::Value>)> {
    let site = driftless::calib::segment::SiteConstants {
        latitude_deg: s.common.lat_deg,
        longitude_deg: 0.0,
        height_m: s.common.height_m,
        gravity_m_s2: s.common.gravity,
    };
    let (d, temp) = crate::segment_view::six_position_from_log(
        log,
        &s.log,
        &s.segment,
        s.temperature_c,
        &site,
        s.common.json,
    )?;
    Ok((
        d.manifest,
        temp,
        format!("{} (segmented from the data)", s.log.display()),
        Some(d.json),
    ))
}

/// The manifest of `--manifest` and the set temperature to calibrate.
fn six_manifest(s: &SixArgs, path: &Path) -> Result<(ChamberManifest, f64)> {
    let text = driftless::io::read_config_text(path, driftless::io::MAX_CONFIG_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let manifest =
        ChamberManifest::from_toml_str(&text).with_context(|| format!("{}", path.display()))?;
    let mut temps: Vec<f64> = manifest
        .segments
        .iter()
        .map(|x| x.set_temperature_c)
        .collect();
    temps.sort_by(f64::total_cmp);
    temps.dedup();
    let temp = match (s.temperature_c, temps.as_slice()) {
        (Some(t), _) if temps.contains(&t) => t,
        (Some(t), _) => bail!("--temperature-c {t}: the manifest's set temperatures are {temps:?}"),
        (None, [t]) => *t,
        (None, _) => bail!(
            "{}: {} set temperatures ({temps:?}); choose one with --temperature-c",
            path.display(),
            temps.len()
        ),
    };
    Ok((manifest, temp))
}

fn six_calibrate(
    s: &SixArgs,
    log: &ImuLog,
    manifest: &ChamberManifest,
    temp: f64,
    source: String,
    segmentation: Option<serde_json::Value>,
) -> Result<()> {
    let gravity = match s.common.gravity {
        Some(_) => Some(gravity(&s.common)?),
        None => None,
    };
    let run = run_six_position(
        log,
        &s.log.display().to_string(),
        manifest,
        temp,
        gravity,
        s.g_sensitivity,
        source,
    )?;
    let (input, res, file, secs) = (&run.input, &run.result, &run.file, run.seconds);
    let (accel_quality, gyro_quality) =
        res.quality(driftless::calib::quality::DEFAULT_WARN_CHI2_PER_DOF);
    if let Some(p) = &s.common.plot {
        let comp = |k: usize| run.residuals.iter().map(|r| r.a_minus_g_m_s2[k]).collect();
        driftless::report::calib_plot::write_residual_plot(
            p,
            &format!("six-position calibration of {}", s.log.display()),
            &[
                (
                    "|a| − g",
                    "m/s²",
                    run.residuals.iter().map(|r| r.norm_m_s2).collect(),
                ),
                ("a − g·up, x", "m/s²", comp(0)),
                ("a − g·up, y", "m/s²", comp(1)),
                ("a − g·up, z", "m/s²", comp(2)),
            ],
        )
        .with_context(|| format!("writing {}", p.display()))?;
    }
    let residuals: Vec<Vec<String>> = input
        .positions
        .iter()
        .zip(&run.residuals)
        .map(|(p, r)| {
            let d = r.a_minus_g_m_s2;
            vec![
                format!("{}", p.up),
                format!("{}", p.n),
                format!("{:+.2e} {:+.2e} {:+.2e}", d[0], d[1], d[2]),
                format!("{:+.2e}", r.norm_m_s2),
            ]
        })
        .collect();
    let summary = [
        ("positions", format!("{}", input.positions.len())),
        ("rate segments", format!("{}", input.rates.len())),
        ("set temperature", format!("{temp} °C")),
        (
            "χ²/dof accel, gyro",
            format!(
                "{:.2}, {:.2}",
                res.accel.chi2_per_dof(),
                res.gyro.chi2_per_dof()
            ),
        ),
        ("time", format!("{:.4} s", secs)),
    ];
    output(
        &s.common,
        file,
        &summary,
        secs,
        (
            ["up", "samples", "a − g·up (x y z) [m/s²]", "|a| − g [m/s²]"],
            residuals,
        ),
        &[("accelerometer", &accel_quality), ("gyro", &gyro_quality)],
        // the log's own segmentation when there was no manifest
        serde_json::json!({ "segmentation": segmentation }),
    )
}

fn triad_json(t: &TriadEntry) -> serde_json::Value {
    serde_json::json!({
        "bias": t.bias,
        "bias_sigma": t.bias_sigma,
        "matrix": t.matrix,
        "matrix_sigma": t.matrix_sigma,
        "raw_unit": t.raw_unit,
        "residual_rms": t.residual_rms,
    })
}

/// Prints the fit-quality warnings (to stderr, so that `--json` stays one document).
fn warn_quality(quality: &[(&str, &FitQuality)]) {
    for (name, q) in quality {
        for w in q.warnings.iter().chain(&q.implausible) {
            eprintln!("warning: {name} fit: {w}");
        }
    }
}

fn output(
    c: &Common,
    file: &CalibrationFile,
    summary: &[(&str, String)],
    secs: f64,
    residuals: ([&str; 4], Vec<Vec<String>>),
    quality: &[(&str, &FitQuality)],
    extra: serde_json::Value,
) -> Result<()> {
    if let Some(p) = &c.out {
        file.save(p)?;
    }
    warn_quality(quality);
    if c.json {
        let mut v = serde_json::json!({
            "quality": {
                "accel": serde_json::to_value(quality[0].1)?,
                "gyro": serde_json::to_value(quality[1].1)?,
            },
            "method": file.method,
            "gravity_m_s2": file.gravity_m_s2,
            "accel": triad_json(&file.accel),
            "gyro": triad_json(&file.gyro),
            "static_intervals": file.static_intervals,
            "gyro_g_sensitivity": file.gyro_g_sensitivity,
            "summary": summary.iter().map(|(k, v)| (k.to_string(), v.clone())).collect::<std::collections::BTreeMap<_, _>>(),
            "seconds": secs,
        });
        if let (Some(obj), serde_json::Value::Object(more)) = (v.as_object_mut(), extra) {
            obj.extend(more);
        }
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    let mut tab = crate::output::Table::new(residuals.0);
    for row in residuals.1 {
        tab.row(row);
    }
    outln!("residuals of the calibrated accelerometer per static interval:");
    out!("{}", tab.render());
    outln!();
    for (k, v) in summary {
        outln!("{k}: {v}");
    }
    for (name, t, unit) in [
        ("accelerometer", &file.accel, "m/s²"),
        ("gyro", &file.gyro, "rad/s"),
    ] {
        outln!(
            "\n{name}: calibrated [{unit}] = M · (raw − b); raw unit: {}",
            t.raw_unit
        );
        let mut tab = crate::output::Table::new(["", "b", "σ(b)", "M · x", "M · y", "M · z"]);
        for (i, ax) in ["x", "y", "z"].iter().enumerate() {
            tab.row(vec![
                ax.to_string(),
                crate::output::sci(t.bias[i]),
                crate::output::sci(t.bias_sigma[i]),
                format!(
                    "{} ± {}",
                    crate::output::sci(t.matrix[i][0]),
                    crate::output::sci(t.matrix_sigma[i][0])
                ),
                format!(
                    "{} ± {}",
                    crate::output::sci(t.matrix[i][1]),
                    crate::output::sci(t.matrix_sigma[i][1])
                ),
                format!(
                    "{} ± {}",
                    crate::output::sci(t.matrix[i][2]),
                    crate::output::sci(t.matrix_sigma[i][2])
                ),
            ]);
        }
        out!("{}", tab.render());
    }
    for p in [&c.out, &c.plot].into_iter().flatten() {
        outln!("\nwrote {}", p.display());
    }
    Ok(())
}

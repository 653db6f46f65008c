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
use driftless::calib::model_file::{CalibrationFile, FORMAT_VERSION, TriadEntry};
use driftless::calib::multi_position::{MultiPositionOptions, calibrate_multi_position};
use driftless::calib::protocol::ChamberManifest;
use driftless::calib::quality::FitQuality;
use driftless::calib::six_position::{SixPositionInput, SixPositionOptions, calibrate};
use driftless::io::{ImuLog, Quantity};
use driftless_model::calib::TriadCalibration;
use driftless_model::linalg::Vec3;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

/// Three columns of `log`: by quantity when it has exactly three of it (units given),
/// else the channels at `first..first + 3` (raw counts).
fn triad_columns<'a>(
    log: &'a ImuLog,
    q: Quantity,
    first: usize,
    what: &str,
) -> Result<[&'a [f64]; 3]> {
    if let Some(t) = log.triad_of(q) {
        return Ok(t);
    }
    if first + 3 > log.channels.len() {
        bail!(
            "{}: needs three {what} columns, found {} data columns",
            log.source,
            log.channels.len()
        );
    }
    Ok(std::array::from_fn(|k| {
        log.channels[first + k].values.as_slice()
    }))
}

/// [`triad_columns`] as one vector per sample.
fn triad(log: &ImuLog, q: Quantity, first: usize, what: &str) -> Result<Vec<Vec3>> {
    let c = triad_columns(log, q, first, what)?;
    Ok((0..log.len()).map(|i| c.map(|col| col[i])).collect())
}

fn entry(
    cal: &TriadCalibration,
    bias_sigma: Vec3,
    matrix_sigma: [[f64; 3]; 3],
    unit: &str,
    rms: Option<f64>,
) -> TriadEntry {
    TriadEntry {
        raw_unit: unit.into(),
        bias: cal.bias,
        bias_sigma,
        matrix: cal.matrix.0,
        matrix_sigma,
        residual_rms: rms,
    }
}

fn raw_unit(log: &ImuLog, q: Quantity) -> String {
    match log.channels.iter().find(|c| c.quantity == q) {
        Some(_) => q.si_unit().to_string(),
        None => "raw".into(),
    }
}

fn multi(m: MultiArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(
        &[m.common.out.as_deref(), m.common.plot.as_deref()],
        &[Some(&m.accel), m.gyro.as_deref()],
    )?;
    let g = gravity(&m.common)?;
    let acc_log = read(&m.common.input, &m.accel)?;
    let (accel, gyro, gyro_log) = match &m.gyro {
        Some(p) => {
            let gl = read(&m.common.input, p)?;
            if gl.len() != acc_log.len() {
                bail!(
                    "{} has {} samples, {} has {}: the two files must be sampled together",
                    m.accel.display(),
                    acc_log.len(),
                    p.display(),
                    gl.len()
                );
            }
            // Sampled together means at the same instants: a file's own time stamps are
            // not set aside for its row order.
            if let (Some(ta), Some(tg)) = (&acc_log.time_s, &gl.time_s) {
                let tol = 0.5 * acc_log.tau0_s.min(gl.tau0_s);
                if let Some(i) = ta
                    .iter()
                    .zip(tg)
                    .position(|(a, b)| (a - b).abs().is_nan() || (a - b).abs() > tol)
                {
                    bail!(
                        "{} and {} are not sampled together: sample {} is at t = {} s in the \
                         first and t = {} s in the second (more than half a sample interval \
                         apart); give files recorded at the same instants, or one file with \
                         both triads",
                        m.accel.display(),
                        p.display(),
                        i + 1,
                        ta[i],
                        tg[i]
                    );
                }
            }
            (
                triad(&acc_log, Quantity::SpecificForce, 0, "accelerometer")?,
                triad(&gl, Quantity::AngularRate, 0, "gyro")?,
                gl,
            )
        }
        None => (
            triad(&acc_log, Quantity::SpecificForce, 0, "accelerometer")?,
            triad(&acc_log, Quantity::AngularRate, 3, "gyro")?,
            acc_log.clone(),
        ),
    };
    let Some(time) = acc_log.time_s.clone() else {
        bail!("{}: no time column", m.accel.display());
    };
    let offset: Vec3 = match m.accel_offset {
        Some(o) => [o; 3],
        None => std::array::from_fn(|k| {
            let mut v: Vec<f64> = accel.iter().map(|a| a[k]).collect();
            v.sort_by(f64::total_cmp);
            let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
            0.5 * (at(0.01) + at(0.99))
        }),
    };
    let mut opts = MultiPositionOptions {
        gravity_m_s2: g,
        gyro_scale_guess_rad_s_per_raw: m.gyro_scale_guess,
        ..MultiPositionOptions::default()
    };
    opts.detect.accel_offset_raw = offset;
    let sources = match &m.gyro {
        Some(p) => format!("{} + {}", m.accel.display(), p.display()),
        None => m.accel.display().to_string(),
    };
    let span = match (time.first(), time.last()) {
        (Some(a), Some(b)) => format!("{a:.2}–{b:.2} s"),
        _ => "empty".into(),
    };
    let t = Instant::now();
    let res = calibrate_multi_position(&time, &accel, &gyro, &opts)
        .with_context(|| format!("calibrating {sources} ({span})"))?;
    let secs = t.elapsed().as_secs_f64();
    let implausible: Vec<&String> = res
        .accel_quality
        .implausible
        .iter()
        .chain(&res.gyro_quality.implausible)
        .collect();
    if !implausible.is_empty() && !m.accept_poor_fit {
        let list: Vec<String> = implausible.iter().map(|r| format!("  - {r}")).collect();
        bail!(
            "{sources} ({span}): the multi-position calibration is implausible, so it was not written:\n{}\n(pass --accept-poor-fit to keep it anyway)",
            list.join("\n")
        );
    }
    let quality = [
        ("accelerometer", &res.accel_quality),
        ("gyro", &res.gyro_quality),
    ];
    let intervals: Vec<[f64; 2]> = res
        .intervals
        .iter()
        .map(|iv| [iv.start_time_s, iv.end_time_s])
        .collect();
    let file = CalibrationFile {
        format_version: FORMAT_VERSION,
        method: "multi-position".into(),
        source: sources.clone(),
        gravity_m_s2: g,
        accel: entry(
            &res.accel.calibration,
            res.accel.bias_sigma(),
            res.accel.matrix_sigma().0,
            &raw_unit(&acc_log, Quantity::SpecificForce),
            Some(res.accel_norm_rms_m_s2),
        ),
        gyro: entry(
            &res.gyro.calibration,
            res.gyro.bias_sigma(),
            res.gyro.matrix_sigma().0,
            &raw_unit(&gyro_log, Quantity::AngularRate),
            Some(res.gravity_angle_rms_rad),
        ),
        static_intervals: intervals,
        gyro_g_sensitivity: None,
    };
    let resid: Vec<f64> = res
        .intervals
        .iter()
        .map(|iv| driftless_model::linalg::norm(res.accel.calibration.apply(iv.mean_accel_raw)) - g)
        .collect();
    let residuals: Vec<Vec<String>> = res
        .intervals
        .iter()
        .zip(&resid)
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
    // Before: the nominal zero offset and the best single scale s (least squares of
    // s·|ā − o| = g over the intervals: s = g·Σ|r| / Σ|r|²).
    let r: Vec<f64> = res
        .intervals
        .iter()
        .map(|iv| {
            driftless_model::linalg::norm(driftless_model::linalg::sub(iv.mean_accel_raw, offset))
        })
        .collect();
    let single = g * r.iter().sum::<f64>() / r.iter().map(|v| v * v).sum::<f64>().max(1e-300);
    let before = driftless::calib::multi_position::accel_norm_rms(
        &res.intervals,
        &TriadCalibration {
            bias: offset,
            matrix: driftless_model::linalg::Mat3::diag([single; 3]),
        },
        g,
    );
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
        &file,
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
    let rate = 1.0 / log.tau0_s;
    if (rate - manifest.sample_rate_hz).abs() > 1e-6 * rate {
        bail!(
            "{} is sampled at {rate} Hz, the manifest at {} Hz",
            s.log.display(),
            manifest.sample_rate_hz
        );
    }
    let gyro = triad_columns(log, Quantity::AngularRate, 0, "gyro")?;
    let accel = triad_columns(log, Quantity::SpecificForce, 3, "accelerometer")?;
    let input = SixPositionInput::from_manifest_columns(manifest, accel, gyro, 1.0, temp)?;
    let mut opts = SixPositionOptions::from_manifest(manifest);
    opts.estimate_g_sensitivity = s.g_sensitivity;
    if s.common.gravity.is_some() {
        opts.gravity_m_s2 = gravity(&s.common)?;
    }
    let t = Instant::now();
    let res = calibrate(&input, &opts)?;
    let secs = t.elapsed().as_secs_f64();
    let (accel_quality, gyro_quality) =
        res.quality(driftless::calib::quality::DEFAULT_WARN_CHI2_PER_DOF);
    let file = CalibrationFile {
        format_version: FORMAT_VERSION,
        method: "six-position".into(),
        source,
        gravity_m_s2: opts.gravity_m_s2,
        accel: entry(
            &res.accel.calibration,
            res.accel.bias_sigma(),
            res.accel.matrix_sigma(),
            &raw_unit(log, Quantity::SpecificForce),
            None,
        ),
        gyro: entry(
            &res.gyro.calibration,
            res.gyro.bias_sigma(),
            res.gyro.matrix_sigma(),
            &raw_unit(log, Quantity::AngularRate),
            None,
        ),
        static_intervals: Vec::new(),
        gyro_g_sensitivity: res
            .gyro_g_sensitivity
            .as_ref()
            .map(|g| g.matrix_raw_per_m_s2.0),
    };
    let g = opts.gravity_m_s2;
    if let Some(p) = &s.common.plot {
        let (mut norm_r, mut comp) = (Vec::new(), [Vec::new(), Vec::new(), Vec::new()]);
        for pos in &input.positions {
            let a = res.accel.calibration.apply(pos.accel_raw);
            let d = driftless_model::linalg::sub(a, pos.c_bn.t().mul_vec([0.0, 0.0, -g]));
            norm_r.push(driftless_model::linalg::norm(a) - g);
            for k in 0..3 {
                comp[k].push(d[k]);
            }
        }
        let [cx, cy, cz] = comp;
        driftless::report::calib_plot::write_residual_plot(
            p,
            &format!("six-position calibration of {}", s.log.display()),
            &[
                ("|a| − g", "m/s²", norm_r),
                ("a − g·up, x", "m/s²", cx),
                ("a − g·up, y", "m/s²", cy),
                ("a − g·up, z", "m/s²", cz),
            ],
        )
        .with_context(|| format!("writing {}", p.display()))?;
    }
    let residuals: Vec<Vec<String>> = input
        .positions
        .iter()
        .map(|p| {
            let a = res.accel.calibration.apply(p.accel_raw);
            let want = p.c_bn.t().mul_vec([0.0, 0.0, -g]);
            let d = driftless_model::linalg::sub(a, want);
            vec![
                format!("{}", p.up),
                format!("{}", p.n),
                format!("{:+.2e} {:+.2e} {:+.2e}", d[0], d[1], d[2]),
                format!("{:+.2e}", driftless_model::linalg::norm(a) - g),
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
        &file,
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

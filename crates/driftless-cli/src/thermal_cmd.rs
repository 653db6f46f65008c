//! `driftless thermal soak LOG --manifest M`: the soak method (issue 6, in progress) —
//! six-position + rate-table calibration at every set temperature of a chamber
//! recording, polynomial fits of each bias and scale series, the real-time compensation
//! model file (`--out`) and the bias/scale-versus-temperature figure (`--plot`).

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use driftless::calib::six_position::SixPositionOptions;
use driftless::io::Quantity;
use driftless::sim::chamber_manifest::ChamberManifest;
use driftless::thermal::FitOptions;
use driftless::thermal::model_file::ThermalModelFile;
use driftless::thermal::soak::soak_calibration;
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
}

#[derive(Args, Debug)]
pub struct RampArgs {
    /// Static log: time, gyro and/or accelerometer columns with units, one temperature
    /// column (°C); or a PX4 ULog (`sensor_gyro`/`sensor_accel`) or ArduPilot DataFlash
    /// (`IMU`) log, recognised by its magic bytes (pick the IMU with `--instance N`).
    pub log: PathBuf,
    /// Polynomial order, 1–5.
    #[arg(long, default_value_t = 3)]
    pub order: usize,
    /// Reference temperature, °C.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub t_ref: f64,
    /// Temperature bin width, °C.
    #[arg(long, default_value_t = 1.0)]
    pub bin: f64,
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
    /// Segment manifest (TOML): positions and rate segments per set temperature.
    #[arg(long)]
    pub manifest: PathBuf,
    /// Polynomial order, 1–5.
    #[arg(long, default_value_t = 3)]
    pub order: usize,
    /// Reference temperature, °C.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub t_ref: f64,
    /// Outside the soaked range: clamp, extrapolate or error.
    #[arg(long, default_value = "clamp")]
    pub out_of_range: String,
    /// Write the compensation model file here (TOML).
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Plot bias and scale factor versus temperature with the fits (SVG, or PNG).
    #[arg(long, value_name = "FILE.svg")]
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
    }
}

fn soak(s: SoakArgs) -> Result<()> {
    let policy = match s.out_of_range.as_str() {
        "clamp" => OutOfRange::Clamp,
        "extrapolate" => OutOfRange::Extrapolate,
        "error" => OutOfRange::Error,
        other => anyhow::bail!("--out-of-range {other:?}: expected clamp, extrapolate or error"),
    };
    let text = std::fs::read_to_string(&s.manifest)
        .with_context(|| format!("reading {}", s.manifest.display()))?;
    let manifest = ChamberManifest::from_toml_str(&text)
        .with_context(|| format!("{}", s.manifest.display()))?;
    let mut input = s.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let log = input.read(&s.log)?;
    let pick = |q: Quantity, what: &str| -> Result<[&[f64]; 3]> {
        log.triad_of(q).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: needs three {what} columns with units (found {})",
                s.log.display(),
                log.indices_of(q).len()
            )
        })
    };
    let gyro = pick(Quantity::AngularRate, "angular-rate")?;
    let accel = pick(Quantity::SpecificForce, "specific-force")?;
    let fit_opts = FitOptions {
        order: s.order,
        t_ref_c: s.t_ref,
        ..FitOptions::default()
    };
    let six = SixPositionOptions::from_manifest(&manifest);
    let t = std::time::Instant::now();
    let soak = soak_calibration(&manifest, accel, gyro, 1.0, &six, &fit_opts)?;
    // A model id from the coefficients (stable for the same fit; < 2⁶³: TOML integers
    // are signed 64-bit).
    let id = soak
        .series
        .iter()
        .flat_map(|x| x.fit.coeffs.iter())
        .fold(0xcbf2_9ce4_8422_2325u64, |h, c| {
            (h ^ c.to_bits()).wrapping_mul(0x0100_0000_01b3)
        })
        >> 1;
    let model = soak.compensation_model(id, policy)?;
    let secs = t.elapsed().as_secs_f64();
    if let Some(p) = &s.out {
        ThermalModelFile::from_model(&model, ["m/s^2", "rad/s"]).save(p)?;
    }
    if let Some(p) = &s.plot {
        driftless::report::thermal_plot::write_thermal_plot(
            p,
            &format!("soak calibration of {}", s.log.display()),
            &soak,
            [
                ("bias (mg)", 1e3 / 9.80665),
                ("bias (deg/s)", 180.0 / std::f64::consts::PI),
            ],
        )
        .with_context(|| format!("writing {}", p.display()))?;
    }
    if s.json {
        let series: Vec<serde_json::Value> = soak
            .series
            .iter()
            .map(|x| {
                serde_json::json!({
                    "triad": x.triad, "quantity": x.quantity, "axis": (["x", "y", "z"][x.axis]),
                    "coefficients": x.fit.coeffs, "std_errors": x.fit.std_errors,
                    "residual_rms": x.fit.residual_rms, "chi2_per_dof": x.fit.chi2_per_dof,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "temperatures_c": soak.temperatures_c,
                "t_ref_c": s.t_ref,
                "order": s.order,
                "model_id": id,
                "series": series,
                "seconds": secs,
            }))?
        );
        return Ok(());
    }
    println!(
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
        tab.row(row);
    }
    print!("{}", tab.render());
    for p in [&s.out, &s.plot].into_iter().flatten() {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn ramp(r: RampArgs) -> Result<()> {
    use driftless::thermal::ramp::{RampOptions, ramp_calibration};
    let mut input = r.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let log = input.read(&r.log)?;
    let Some(time) = log.time_s.as_deref() else {
        anyhow::bail!("{}: no time column", r.log.display());
    };
    let Some(temp) = log
        .channels
        .iter()
        .find(|c| c.quantity == Quantity::Temperature)
    else {
        anyhow::bail!(
            "{}: no temperature column (a column with unit degC, or `--column N:degC`)",
            r.log.display()
        );
    };
    let (t_lo, t_hi) = temp
        .values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    eprintln!(
        "{}: {} samples over {:.1} s, temperature {t_lo:.2}–{t_hi:.2} °C (span {:.2} °C)",
        r.log.display(),
        log.len(),
        time.last().copied().unwrap_or(0.0) - time.first().copied().unwrap_or(0.0),
        t_hi - t_lo
    );
    let chans: Vec<(&str, &[f64])> = log
        .channels
        .iter()
        .filter(|c| matches!(c.quantity, Quantity::AngularRate | Quantity::SpecificForce))
        .map(|c| (c.name.as_str(), c.values.as_slice()))
        .collect();
    if chans.is_empty() {
        anyhow::bail!(
            "{}: no angular-rate or specific-force column with a unit",
            r.log.display()
        );
    }
    let opts = RampOptions {
        bin_c: r.bin,
        fit: FitOptions {
            order: r.order,
            t_ref_c: r.t_ref,
            ..FitOptions::default()
        },
        ..RampOptions::default()
    };
    let res = ramp_calibration(time, &temp.values, &chans, &opts)
        .with_context(|| format!("{}", r.log.display()))?;
    let heating = res.points.iter().filter(|p| p.heating).count();
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
                    "hysteresis_rms": res.hysteresis.as_ref().map(|h| h[k]),
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "bins_heating": heating,
                "bins_cooling": res.points.len() - heating,
                "t_ref_c": r.t_ref,
                "order": r.order,
                "fits": fits,
            }))?
        );
        return Ok(());
    }
    println!(
        "{} temperature bins ({heating} heating, {} cooling); order {} about {} °C",
        res.points.len(),
        res.points.len() - heating,
        r.order,
        r.t_ref
    );
    let mut head = vec!["channel".to_string()];
    head.extend((0..=r.order).map(|k| format!("c{k} ± σ")));
    head.push("hysteresis RMS".into());
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
        tab.row(row);
    }
    print!("{}", tab.render());
    Ok(())
}

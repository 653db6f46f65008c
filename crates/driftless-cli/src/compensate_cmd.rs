//! `driftless compensate LOG --model MODEL.toml --out OUT`: streams a log through the
//! `no_std` real-time compensation (room calibration + thermal polynomials, applied per
//! sample at the log's own temperature reading) and writes the compensated log (CSV, or
//! DRIFTLOG for `.dlog`). The output names the model in its source line
//! (`compensated by driftless thermal model 0x…`); an input that already carries such a
//! stamp is refused, so a model is never applied twice. Samples whose temperature lies
//! outside the model's calibrated range are reported on stderr with their time spans.

use anyhow::{Result, bail};
use clap::Args;
use driftless::io::{ImuLog, Quantity};
use driftless::thermal::model_file::ThermalModelFile;
use std::path::{Path, PathBuf};

use crate::input::InputArgs;

/// The stamp written into (and looked for in) a log's source line.
pub const STAMP: &str = "compensated by driftless thermal model";

#[derive(Args, Debug)]
pub struct CompensateArgs {
    /// Input log: time, three angular-rate and three specific-force columns with units,
    /// and one temperature column (°C).
    pub log: PathBuf,
    /// Thermal compensation model (`driftless thermal soak --out`).
    #[arg(long)]
    pub model: PathBuf,
    /// Output log (`.dlog` → DRIFTLOG, otherwise CSV).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub input: InputArgs,
}

/// The stamp an input carries, from its source line (text: the first line, read from
/// the first 4 KiB only, of a regular file — a pipe or FIFO, already read, cannot be opened
/// again; DRIFTLOG: the header's source).
fn existing_stamp(path: &Path, log: &ImuLog) -> Option<String> {
    use std::io::Read as _;
    let mut head = Vec::with_capacity(4096);
    let first = std::fs::metadata(path)
        .ok()
        .filter(std::fs::Metadata::is_file)
        .and_then(|_| std::fs::File::open(path).ok())
        .ok_or_else(|| std::io::Error::other("not a regular file"))
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .ok()
        .map(|_| {
            let end = head.iter().position(|&c| c == b'\n').unwrap_or(head.len());
            String::from_utf8_lossy(&head[..end]).into_owned()
        });
    [first.unwrap_or_default(), log.source.clone()]
        .into_iter()
        .find_map(|s| s.find(STAMP).map(|i| s[i..].trim().to_string()))
}

/// Warns on stderr, with the time spans, where the log's temperature leaves the model's
/// calibrated range (the model then clamps, extrapolates or refuses, per `policy`):
/// compensation outside the range is never silent.
pub fn warn_out_of_range(
    path: &Path,
    log: &ImuLog,
    temperature_c: &[f64],
    range_c: &[f64; 2],
    policy: &str,
) -> usize {
    let spans = driftless::thermal::check::out_of_range_spans(
        log.time_s.as_deref(),
        log.tau0_s,
        temperature_c,
        *range_c,
    );
    if spans.is_empty() {
        return 0;
    }
    let samples: usize = spans.iter().map(|e| e.samples).sum();
    let what = match policy {
        "clamp" => "the model holds its end values there (clamp)",
        "extrapolate" => "the model extrapolates its polynomials there",
        _ => "the model refuses such samples",
    };
    eprintln!(
        "warning: {}: {samples} of {} samples in {} span(s) lie outside the model's \
         calibrated range [{}, {}] °C; {what} — calibrate over a wider range for this use:",
        path.display(),
        temperature_c.len(),
        spans.len(),
        range_c[0],
        range_c[1]
    );
    for e in spans.iter().take(10) {
        eprintln!("  {}", e.describe());
    }
    if spans.len() > 10 {
        eprintln!("  … and {} more span(s)", spans.len() - 10);
    }
    samples
}

pub fn run(a: CompensateArgs) -> Result<()> {
    crate::paths::refuse_outputs_over_inputs(&[Some(&a.out)], &[Some(&a.log), Some(&a.model)])?;
    let (file, model) = ThermalModelFile::load(&a.model)?;
    for (t, si) in [
        (&file.accel, ["m/s^2", "m/s²"]),
        (&file.gyro, ["rad/s", "rad/s"]),
    ] {
        if !si.contains(&t.raw_unit.as_str()) {
            bail!(
                "{}: raw unit {:?}: the log reader delivers SI samples, so only a model of SI \
                 samples ({} / rad/s) can be applied",
                a.model.display(),
                t.raw_unit,
                si[0]
            );
        }
    }
    let mut input = a.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let log = input.read(&a.log)?;
    if let Some(stamp) = existing_stamp(&a.log, &log) {
        bail!(
            "{}: already {stamp}; refusing to compensate twice (this model is {:#x})",
            a.log.display(),
            model.id()
        );
    }
    let (gi, ai, ti) = (
        log.indices_of(Quantity::AngularRate),
        log.indices_of(Quantity::SpecificForce),
        log.indices_of(Quantity::Temperature),
    );
    if gi.len() != 3 || ai.len() != 3 {
        bail!(
            "{}: needs three angular-rate and three specific-force columns with units (found {} and {})",
            a.log.display(),
            gi.len(),
            ai.len()
        );
    }
    let Some(&ti) = ti.first() else {
        bail!(
            "{}: no temperature column (a column with unit degC, or `--column N:degC`); \
             thermal compensation needs the sensor temperature of every sample",
            a.log.display()
        );
    };
    let n = log.len();
    let mut gyro: Vec<[f64; 3]> = (0..n)
        .map(|i| std::array::from_fn(|k| log.channels[gi[k]].values[i]))
        .collect();
    let mut accel: Vec<[f64; 3]> = (0..n)
        .map(|i| std::array::from_fn(|k| log.channels[ai[k]].values[i]))
        .collect();
    let temp = &log.channels[ti].values;
    warn_out_of_range(&a.log, &log, temp, &file.range_c, &file.out_of_range);
    let t0 = std::time::Instant::now();
    model
        .compensate_block(&mut gyro, &mut accel, temp)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.log.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    let mut out = log.clone();
    for k in 0..3 {
        out.channels[gi[k]].values = gyro.iter().map(|v| v[k]).collect();
        out.channels[ai[k]].values = accel.iter().map(|v| v[k]).collect();
    }
    out.source = format!(
        "{} | {STAMP} {:#x} ({})",
        log.source,
        model.id(),
        a.model.display()
    );
    let is_dlog = a
        .out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("dlog"));
    if is_dlog {
        driftless::io::write_binary_file(&out, &a.out)?;
    } else {
        driftless::io::write_csv_file(&out, &a.out)?;
    }
    let (lo, hi) = temp
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
            (a.min(t), b.max(t))
        });
    outln!(
        "{}: {n} samples at {lo:.2}–{hi:.2} °C compensated with model {:#x} (valid {:?} °C, {}{}) in {:.3} s → {}",
        a.log.display(),
        model.id(),
        file.range_c,
        file.out_of_range,
        if model.gyro_g_sensitivity().is_some() {
            ", gyro g-sensitivity"
        } else {
            ""
        },
        secs,
        a.out.display()
    );
    Ok(())
}

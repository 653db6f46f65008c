//! `driftless nav`: loosely coupled GNSS/INS on recorded data, with simulated outages.
//!
//! Inputs today: KF-GINS increment files or an RTKLIB-tagged IMU CSV (the `drive-0708`
//! preset sets its units, time shift, mounting and lever arm), and GNSS as RTKLIB `.pos`
//! or a KF-GINS GNSS file. Output: a summary (full-GNSS accuracy against the fixes,
//! per-outage errors) and KF-GINS's three output files in `--out`.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use driftless::eval::SelectedOutage;
use driftless::io::nav::GnssFixes;
use driftless::io::nav::kfgins::GnssReadOptions;
use driftless::io::nav::read_kfgins_imu_file;
use driftless::nav::filter::model::{FilterConfig, GaussMarkov, ImuNoise};
use driftless::nav::outage::OutageSpec;
use driftless::nav::pipeline::{
    GnssOutsideImu, ImuStreamOptions, RateChannels, TaggedCsvOptions, imu_from_kfgins,
    imu_from_rates_log, imu_from_tagged_csv_files, read_gnss_file, select_gnss,
};
use driftless::nav::session::{SessionConfig, consumer_mems_noise, run_session, solution_records};
use std::path::PathBuf;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum ImuFormat {
    /// KF-GINS increments: time, dθ xyz [rad], dv xyz [m/s].
    Kfgins,
    /// RTKLIB-tagged CSV (acc [g], gyro [deg/s], tick [ms]) with a `.tag` file.
    TaggedCsv,
    /// Generic delimited text (or DRIFTLOG) of rates: a time column (the first unless
    /// `--time-column`) in GPS seconds and
    /// three angular-rate and three specific-force columns, units from the header
    /// (`gyro_x [deg/s]`) or the input options below; Δθ = ω·Δt, Δv = f·Δt.
    Csv,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Preset {
    /// `shared/data/drive/drive_0708`: tagged CSV, −0.125 s, mounting (180, 0, 180)° plus
    /// (0, −6.79, 5.35)°, antenna (0, −0.05, 0) m from the IMU, consumer MEMS noise.
    Drive0708,
}

#[derive(Args, Debug)]
pub struct NavArgs {
    /// Run a KF-GINS configuration unchanged: its IMU and GNSS files, initial state, noise,
    /// lever arm and time span; KF-GINS's three output files go to its `outputpath`
    /// (relative paths resolve against the working directory, as in KF-GINS).
    #[arg(long, value_name = "CONFIG.yaml", conflicts_with_all = ["imu", "gnss", "preset"])]
    pub kf_gins: Option<PathBuf>,
    /// IMU file.
    #[arg(long, required_unless_present = "kf_gins")]
    pub imu: Option<PathBuf>,
    /// IMU file format (set by --preset).
    #[arg(long, value_enum)]
    pub imu_format: Option<ImuFormat>,
    /// RTKLIB time-tag file for a tagged CSV (default: IMU path + `.tag`).
    #[arg(long)]
    pub tag: Option<PathBuf>,
    /// GNSS file: RTKLIB `.pos` or KF-GINS GNSS text.
    #[arg(long, required_unless_present = "kf_gins")]
    pub gnss: Option<PathBuf>,
    /// Settings for a known dataset.
    #[arg(long, value_enum)]
    pub preset: Option<Preset>,
    /// Antenna lever arm from the IMU in the body frame, forward,right,down [m].
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub lever_arm: Option<String>,
    /// Apply a calibration model file (`driftless calibrate --out`) to the IMU before
    /// navigation; its raw units must be SI (rad/s, m/s²), as the IMU readers deliver.
    #[arg(long, value_name = "FILE.toml")]
    pub calibration: Option<PathBuf>,
    /// IMU noise from an Allan noise-model file (`driftless allan --save-model`); default
    /// consumer-MEMS values.
    #[arg(long)]
    pub noise_model: Option<PathBuf>,
    /// GNSS outages: `none`, `300+60,600+60` (s after the first fix), `@243600+60`
    /// (absolute), `6x60s every 85s from 50s`, or `auto:9x60` (nine 60-s windows chosen
    /// on the GNSS track to cover straight runs, turns, accelerations, braking and stops,
    /// at least max(2·60, 120) s apart, 60 s after the first fix and 30 s before the last).
    #[arg(long, default_value = "none")]
    pub outages: String,
    /// Folder for KF-GINS-format output files.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write the solution as CSV (time, lat/lon in deg, height, NED velocity, roll/pitch/yaw in deg).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Also write the track as GeoJSON (one point per 0.1 s).
    #[arg(long, value_name = "FILE")]
    pub geojson: Option<PathBuf>,
    /// Also run the RTS smoother and report its in-outage errors (on by default with
    /// `--preset drive0708`); with `--kf-gins`, also write its solution as
    /// `KF_GINS_Navresult_smoothed.nav`, `KF_GINS_IMU_ERR_smoothed.txt`, `KF_GINS_STD_smoothed.txt`.
    #[arg(long)]
    pub smooth: bool,
    /// Machine-readable summary.
    #[arg(long)]
    pub json: bool,
    /// How to read a generic CSV IMU file (`--imu-format csv`).
    #[command(
        flatten,
        next_help_heading = "Generic CSV IMU input (--imu-format csv)"
    )]
    pub input: crate::input::InputArgs,
}

fn parse_vec3(s: &str, what: &str) -> Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{what} {s:?}: expected three comma-separated numbers"))?;
    match v.as_slice() {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        _ => bail!("{what} {s:?}: expected three finite comma-separated numbers"),
    }
}

pub fn run(a: NavArgs) -> Result<()> {
    if let Some(cfg_path) = &a.kf_gins {
        return run_kf_gins(cfg_path, &a);
    }
    let (Some(imu_path), Some(gnss_path)) = (a.imu.clone(), a.gnss.clone()) else {
        bail!("--imu and --gnss are required without --kf-gins");
    };
    let imu_file = imu_path;
    let gnss_file = gnss_path;
    let format = match (a.imu_format, a.preset) {
        (Some(f), _) => f,
        (None, Some(Preset::Drive0708)) => ImuFormat::TaggedCsv,
        (None, None) => ImuFormat::Kfgins,
    };
    let imu = match format {
        ImuFormat::Kfgins => {
            let inc = read_kfgins_imu_file(&imu_file)?;
            imu_from_kfgins(
                &inc,
                &imu_file.display().to_string(),
                &ImuStreamOptions::default(),
            )?
        }
        ImuFormat::TaggedCsv => {
            let tag = a.tag.clone().unwrap_or_else(|| {
                let mut p = imu_file.clone().into_os_string();
                p.push(".tag");
                PathBuf::from(p)
            });
            let opts = match a.preset {
                Some(Preset::Drive0708) => TaggedCsvOptions::drive_0708(),
                None => TaggedCsvOptions::default(),
            };
            imu_from_tagged_csv_files(&imu_file, &tag, &opts)?
        }
        ImuFormat::Csv => {
            // Navigation needs time stamps: the first column unless told otherwise.
            let mut input = a.input.clone();
            input.time_column.get_or_insert_with(|| "1".into());
            let log = input.read(&imu_file)?;
            imu_from_rates_log(
                &log,
                &RateChannels::ByQuantity,
                &ImuStreamOptions::default(),
            )?
        }
    };
    let mut imu = imu;
    if let Some(p) = &a.calibration {
        let f = driftless::calib::model_file::CalibrationFile::load(p)?;
        for (t, si) in [(&f.accel, ["m/s^2", "m/s²"]), (&f.gyro, ["rad/s", "rad/s"])] {
            if !si.contains(&t.raw_unit.as_str()) {
                bail!(
                    "{}: raw unit {:?}: nav reads SI samples, so it can apply only a \
                     calibration of SI samples ({} / rad/s)",
                    p.display(),
                    t.raw_unit,
                    si[0]
                );
            }
        }
        imu.apply_calibration(&f.calibration());
    }
    let gnss = read_gnss_file(&gnss_file, &GnssReadOptions::default())?;
    let lever = match (&a.lever_arm, a.preset) {
        (Some(s), _) => parse_vec3(s, "--lever-arm")?,
        (None, Some(Preset::Drive0708)) => [0.0, -0.05, 0.0],
        (None, None) => [0.0, 0.0, 0.0],
    };
    let noise = match &a.noise_model {
        Some(p) => {
            let m = driftless::allan::noise_model::NoiseModel::load(p)?;
            let scale = GaussMarkov {
                sigma: 5e-3,
                tau_s: 3600.0,
            };
            ImuNoise::from_noise_model(&m, 3600.0, scale, scale)?
        }
        None => consumer_mems_noise(),
    };
    let spec: OutageSpec = a.outages.parse().context("--outages")?;
    let all = select_gnss(&gnss, &imu, &OutageSpec::None, GnssOutsideImu::Drop)?;
    let (spec, selection) = choose_outages(spec, &all.fixes)?;
    let windows = select_gnss(&gnss, &imu, &spec, GnssOutsideImu::Drop)?.windows;
    let mut cfg = match a.preset {
        Some(Preset::Drive0708) => SessionConfig::drive_0708(),
        None => SessionConfig::new(FilterConfig::new(noise, lever)),
    };
    if a.preset.is_some() {
        if a.noise_model.is_some() {
            cfg.filter.imu = noise;
        }
        cfg.filter.lever_arm_b_m = lever;
    }
    cfg.smooth |= a.smooth;
    cfg.outages = windows;
    let res = run_session(&imu, &all.fixes, &cfg)?;

    log_rejections(&res.run, 20);
    let (sol, err, std) = solution_records(&res.run);
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        driftless::io::nav::write_kfgins_outputs(dir, &sol, &err, &std, imu.gps_week.unwrap_or(0))?;
    }
    write_extra_outputs(&a, &sol, imu.nominal_dt_s)?;
    let ends: Vec<f64> = res
        .outages
        .iter()
        .filter_map(|o| o.end_horizontal_m)
        .collect();
    let mean_end = (!ends.is_empty()).then(|| ends.iter().sum::<f64>() / ends.len() as f64);
    if a.json {
        let v = serde_json::json!({
            "imu_epochs": imu.len(),
            "gnss_fixes": all.fixes.time_s.len(),
            "start_time_s": res.init.nav.time_s,
            "gnss_accepted": res.run.gnss_accepted,
            "gnss_rejected": res.run.gnss_rejected,
            "gnss_withheld": res.run.gnss_withheld,
            "horizontal_rms_m": res.horizontal_rms_m.map(|r| r.0),
            "outages": res.outages.iter().map(|o| serde_json::json!({
                "start_s": o.window.start_s, "end_s": o.window.end_s,
                "end_horizontal_m": o.end_horizontal_m, "max_horizontal_m": o.max_horizontal_m,
                "end_vertical_m": o.end_vertical_m,
            })).collect::<Vec<_>>(),
            "mean_end_horizontal_m": mean_end,
            "outage_selection": selection,
            "smoothed_outages": res.smoothed_outages.as_ref().map(|v| v.iter().map(|o| serde_json::json!({
                "start_s": o.window.start_s, "end_s": o.window.end_s,
                "end_horizontal_m": o.end_horizontal_m, "max_horizontal_m": o.max_horizontal_m,
            })).collect::<Vec<_>>()),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "{} IMU epochs, {} GNSS fixes in the IMU span; filter started at {:.2} s (first fix above {} m/s)",
        imu.len(),
        all.fixes.time_s.len(),
        res.init.nav.time_s,
        cfg.min_speed_m_s
    );
    println!(
        "GNSS: {} accepted, {} rejected by the χ² gate, {} withheld by outages",
        res.run.gnss_accepted, res.run.gnss_rejected, res.run.gnss_withheld
    );
    if let Some((rms, n)) = res.horizontal_rms_m {
        println!("full-GNSS horizontal one-step prediction error: RMS {rms:.3} m over {n} fixes");
    }
    if let Some(sel) = &selection {
        print!("{}", selection_table(sel));
    }
    if !res.outages.is_empty() {
        let mut t = crate::output::Table::new([
            "outage",
            "start [s]",
            "end [s]",
            "end error [m]",
            "max inside [m]",
            "smoothed max [m]",
        ]);
        for (i, o) in res.outages.iter().enumerate() {
            let sm = res
                .smoothed_outages
                .as_ref()
                .and_then(|v| v.get(i))
                .map_or("–".into(), |s| format!("{:.2}", s.max_horizontal_m));
            t.row(vec![
                format!("#{}", i + 1),
                format!("{:.1}", o.window.start_s),
                format!("{:.1}", o.window.end_s),
                o.end_horizontal_m.map_or("–".into(), |v| format!("{v:.2}")),
                format!("{:.2}", o.max_horizontal_m),
                sm,
            ]);
        }
        print!("{}", t.render());
        if let Some(m) = mean_end {
            println!(
                "mean end-of-outage horizontal error {m:.2} m over {} outages",
                ends.len()
            );
        }
    }
    if let Some(dir) = &a.out {
        println!("KF-GINS-format outputs written to {}", dir.display());
    }
    Ok(())
}

/// `auto:NxL` outages: chosen on the GNSS fixes inside the IMU span (the drive's only
/// reference) before any filtering, so an impossible request fails at once; returned as
/// absolute windows. Other specifications pass through unchanged.
fn choose_outages(
    spec: OutageSpec,
    fixes: &GnssFixes,
) -> Result<(OutageSpec, Option<Vec<SelectedOutage>>)> {
    driftless::nav::kfgins_job::resolve_auto_outages(spec, fixes).context("--outages")
}

/// The automatically chosen windows and the dynamics inside them.
fn selection_table(sel: &[SelectedOutage]) -> String {
    let mut t = crate::output::Table::new([
        "outage",
        "start [s]",
        "end [s]",
        "chosen for",
        "dynamics inside",
    ]);
    for (i, s) in sel.iter().enumerate() {
        t.row(vec![
            format!("#{}", i + 1),
            format!("{:.1}", s.window.start_s),
            format!("{:.1}", s.window.end_s),
            s.chosen_for.map_or("–".into(), |d| d.to_string()),
            s.mix.to_string(),
        ]);
    }
    format!("automatic outages:\n{}", t.render())
}

/// `--kf-gins CONFIG`: the KF-GINS job of the library
/// ([`driftless::nav::kfgins_job::run_kf_gins_job`]: KF-GINS's semantics and files; with
/// `--smooth` also the smoothed solution's three files).
fn run_kf_gins(path: &std::path::Path, a: &NavArgs) -> Result<()> {
    use driftless::nav::kfgins_job::{KfGinsJobOptions, run_kf_gins_job};
    let opts = KfGinsJobOptions {
        outages: a.outages.parse().context("--outages")?,
        gate: None,
        smooth: a.smooth,
        keep_records: a.csv.is_some() || a.geojson.is_some(),
    };
    let job = run_kf_gins_job(path, &opts)?;
    for n in &job.notes {
        eprintln!("note: {n}");
    }
    if let Some(sel) = &job.outage_selection {
        eprint!("{}", selection_table(sel));
    }
    log_rejections(&job.run, 20);
    if let Some((sol, _, _)) = (a.csv.is_some() || a.geojson.is_some())
        .then(|| job.solution())
        .flatten()
    {
        write_extra_outputs(a, &sol, job.dt_s)?;
    }
    let run = &job.run;
    let files: Vec<&PathBuf> = job
        .files
        .iter()
        .chain(job.smoothed_files.iter().flatten())
        .collect();
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "epochs": job.rows,
                "start_time_s": job.start_time_s,
                "gnss_accepted": run.gnss_accepted,
                "gnss_rejected": run.gnss_rejected,
                "gnss_withheld": run.gnss_withheld,
                "gnss_skipped": run.gnss_skipped,
                "outputs": files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            }))?
        );
    } else {
        println!(
            "{}: {} epochs written from {:.3} s, GNSS {} accepted, {} rejected, {} withheld, {} skipped",
            path.display(),
            job.rows,
            job.start_time_s,
            run.gnss_accepted,
            run.gnss_rejected,
            run.gnss_withheld,
            run.gnss_skipped
        );
        for f in files {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}

/// `--csv` and `--geojson`.
fn write_extra_outputs(
    a: &NavArgs,
    sol: &driftless::io::nav::NavSolution,
    dt_s: f64,
) -> Result<()> {
    use driftless::io::nav::track::{write_solution_csv, write_track_geojson};
    if let Some(p) = &a.csv {
        write_solution_csv(p, sol)?;
    }
    if let Some(p) = &a.geojson {
        let stride = if dt_s > 0.0 {
            (0.1 / dt_s).round() as usize
        } else {
            1
        };
        write_track_geojson(p, sol, stride)?;
    }
    Ok(())
}

/// Log the measurements the χ² gate rejected (stderr; at most `max` lines).
fn log_rejections(run: &driftless::nav::filter::run::ForwardRun, max: usize) {
    let mut n = 0usize;
    for o in run.rejections() {
        if n < max {
            eprintln!(
                "rejected {:?} at {:.3} s: NIS {:.1}, innovation N/E/D {:.3} {:.3} {:.3}",
                o.kind, o.time_s, o.nis, o.innovation[0], o.innovation[1], o.innovation[2]
            );
        }
        n += 1;
    }
    if n > max {
        eprintln!("… {} more rejections", n - max);
    }
}

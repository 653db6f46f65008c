//! `driftless nav`: loosely coupled GNSS/INS on recorded data, with simulated outages.
//!
//! A navigation configuration (`--config nav.toml`, `--print-config` for the commented
//! default, every key also a flag) says what the data are and how to treat them; the
//! library runs the job ([`driftless::nav::job::run_nav_job`]); this module prints the
//! summary and writes the outputs. `--kf-gins CONFIG.yaml` runs a KF-GINS job instead.

use anyhow::{Context, Result, bail};
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use driftless::eval::SelectedOutage;
use driftless::nav::config::{KEYS, NavConfig, Override, ValueKind};
use driftless::nav::job::{NavJobResult, run_nav_job};
use driftless::nav::session::solution_records;
use std::path::PathBuf;

/// Configurations shipped with driftless (`--preset NAME`), from `examples/nav/`.
const PRESETS: &[(&str, &str)] = &[
    (
        "drive0708",
        include_str!("../../../examples/nav/drive0708.toml"),
    ),
    (
        "drive_0708",
        include_str!("../../../examples/nav/drive_0708.toml"),
    ),
    (
        "hand-held",
        include_str!("../../../examples/nav/hand-held.toml"),
    ),
];

/// Every configuration key as a flag ([`KEYS`]); given flags override the file.
#[derive(Clone, Debug, Default)]
pub struct ConfigFlags {
    /// The flags given, in table order.
    pub overrides: Vec<Override>,
}

impl ConfigFlags {
    /// The text of the flag for `path`, when given.
    pub fn get(&self, path: &str) -> Option<&str> {
        self.overrides
            .iter()
            .find(|o| o.key.path == path)
            .map(|o| o.value.as_str())
    }
}

impl FromArgMatches for ConfigFlags {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let overrides = KEYS
            .iter()
            .filter_map(|k| {
                m.get_one::<String>(k.flag).map(|v| Override {
                    key: k,
                    value: v.clone(),
                })
            })
            .collect();
        Ok(ConfigFlags { overrides })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl Args for ConfigFlags {
    fn augment_args(mut cmd: Command) -> Command {
        for k in KEYS {
            let section = k.path.split_once('.').map_or("", |(s, _)| s);
            let heading: &'static str = match section {
                "imu" => "Configuration [imu]",
                "gnss" => "Configuration [gnss]",
                "noise" => "Configuration [noise]",
                "align" => "Configuration [align]",
                "aids" => "Configuration [aids]",
                "filter" => "Configuration [filter]",
                _ => "Configuration [outages]",
            };
            let mut a = Arg::new(k.flag)
                .long(k.flag)
                .value_name(k.value_name)
                .help(k.help)
                .help_heading(heading)
                .action(ArgAction::Set);
            a = if k.kind == ValueKind::Bool {
                a.num_args(0..=1)
                    .require_equals(true)
                    .default_missing_value("true")
            } else {
                a.allow_hyphen_values(true)
            };
            cmd = cmd.arg(a);
        }
        cmd
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

#[derive(Args, Debug)]
pub struct NavArgs {
    /// Run a KF-GINS configuration unchanged: its IMU and GNSS files, initial state, noise,
    /// lever arm and time span; KF-GINS's three output files go to its `outputpath`
    /// (relative paths resolve against the working directory, as in KF-GINS).
    #[arg(long, value_name = "CONFIG.yaml", conflicts_with_all = ["imu", "gnss", "preset", "config"])]
    pub kf_gins: Option<PathBuf>,
    /// Navigation configuration (TOML; `--print-config` writes the commented default).
    #[arg(long, value_name = "NAV.toml")]
    pub config: Option<PathBuf>,
    /// A configuration shipped with driftless: `drive_0708` (the shared drive, published
    /// values only) or `drive0708` (the same with settings tuned on that drive).
    #[arg(long, value_name = "NAME", conflicts_with = "config")]
    pub preset: Option<String>,
    /// Print the commented default configuration (or, with --config/--preset and flags,
    /// the configuration in effect) and exit.
    #[arg(long)]
    pub print_config: bool,
    /// Folder for KF-GINS-format output files (refused when it already holds files,
    /// unless --force).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write --out into a folder that already holds files (this run's three files replace
    /// theirs).
    #[arg(long)]
    pub force: bool,
    /// Also write the solution as CSV (time, lat/lon in deg, height, NED velocity, roll/pitch/yaw in deg).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Also write the track as GeoJSON (one point per 0.1 s).
    #[arg(long, value_name = "FILE")]
    pub geojson: Option<PathBuf>,
    /// Machine-readable summary.
    #[arg(long)]
    pub json: bool,
    /// The configuration keys as flags.
    #[command(flatten)]
    pub settings: ConfigFlags,
    /// How to read a generic CSV IMU file (`--imu-format csv`).
    #[command(
        flatten,
        next_help_heading = "Generic CSV IMU input (--imu-format csv)"
    )]
    pub input: crate::input::InputArgs,
}

impl NavArgs {
    /// The outage specification given as a flag (`--outages`), default `none`.
    pub fn outages_spec(&self) -> &str {
        self.settings.get("outages.spec").unwrap_or("none")
    }
    /// `--smooth` given (and not `--smooth=false`).
    pub fn smooth_flag(&self) -> bool {
        self.settings
            .get("filter.smooth")
            .is_some_and(|v| matches!(v, "true" | "yes" | "on" | "1"))
    }
}

fn load_config(a: &NavArgs) -> Result<driftless::nav::config::LoadedConfig> {
    let overrides = &a.settings.overrides;
    if let Some(name) = &a.preset {
        let Some((_, text)) = PRESETS.iter().find(|(n, _)| n == name) else {
            bail!(
                "--preset {name:?}: no such preset; shipped: {}",
                PRESETS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        };
        return Ok(NavConfig::load_text(
            Some((
                (*text).to_owned(),
                PathBuf::from(format!("preset {name}")),
                PathBuf::new(),
            )),
            overrides,
        )?);
    }
    Ok(NavConfig::load(a.config.as_deref(), overrides)?)
}

pub fn run(a: NavArgs) -> Result<()> {
    if let Some(cfg_path) = &a.kf_gins {
        return run_kf_gins(cfg_path, &a);
    }
    if a.print_config {
        if a.config.is_none() && a.preset.is_none() && a.settings.overrides.is_empty() {
            out!("{}", NavConfig::default_toml());
        } else {
            let c = load_config(&a)?;
            out!("{}", toml::to_string_pretty(&c.config)?);
        }
        return Ok(());
    }
    let cfg = load_config(&a)?;
    // Held until the last file is written.
    let _lock = (a.out.as_ref())
        .map(|dir| driftless::io::output::claim_folder(dir, a.force))
        .transpose()?;
    let imu_file = (cfg.config.imu.file.as_deref()).map(|p| cfg.path("imu.file", p));
    let gnss_file = (cfg.config.gnss.file.as_deref()).map(|p| cfg.path("gnss.file", p));
    crate::paths::refuse_outputs_over_inputs(
        &[a.csv.as_deref(), a.geojson.as_deref()],
        &[
            a.config.as_deref(),
            imu_file.as_deref(),
            gnss_file.as_deref(),
        ],
    )?;
    // Navigation needs time stamps: the first column unless told otherwise.
    let mut input = a.input.clone();
    input.time_column.get_or_insert_with(|| "1".into());
    let csv = input.text_options()?;
    let job = match run_nav_job(&cfg, &csv) {
        Ok(job) => job,
        Err(driftless::nav::job::NavJobError::ImuValues { error, report }) => {
            warn_imu_findings(&report, usize::MAX);
            return Err(anyhow::Error::new(*error)).context("checking the IMU values");
        }
        Err(e) => return Err(e.into()),
    };
    let note = |m: &str| note!("note: {m}");
    for n in &job.notes {
        note(n);
    }
    // Bad IMU values are warnings even with --quiet: the result depends on them.
    warn_imu_findings(
        &job.imu_check,
        if crate::verbosity::verbose() {
            usize::MAX
        } else {
            20
        },
    );
    let res = &job.session;
    let run = &res.run;
    if crate::verbosity::verbose() {
        log_rejections(run, usize::MAX);
    } else if !crate::verbosity::quiet() && run.gnss_rejected > 0 {
        let worst = run.rejections().map(|o| o.nis).fold(0.0f64, f64::max);
        let first = run.rejections().next().map_or(f64::NAN, |o| o.time_s);
        note(&format!(
            "{} GNSS measurements rejected by the gate (first at {first:.3} s, largest NIS {worst:.1}); --verbose lists them",
            run.gnss_rejected
        ));
    }
    let (sol, err, std) = solution_records(run);
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        driftless::io::nav::write_kfgins_outputs(
            dir,
            &sol,
            &err,
            &std,
            job.imu.gps_week.unwrap_or(0),
        )?;
    }
    write_extra_outputs(&a, &sol, job.imu.nominal_dt_s)?;
    let ends: Vec<f64> = res
        .outages
        .iter()
        .filter_map(|o| o.end_horizontal_m)
        .collect();
    let mean_end = (!ends.is_empty()).then(|| ends.iter().sum::<f64>() / ends.len() as f64);
    if a.json {
        return print_json(&job, mean_end);
    }
    print_human(&a, &job, mean_end, ends.len());
    Ok(())
}

/// The `--json` document of a run.
fn print_json(job: &NavJobResult, mean_end: Option<f64>) -> Result<()> {
    let res = &job.session;
    let run = &res.run;
    let sc = &job.session_config;
    let v = serde_json::json!({
        "imu_epochs": job.imu.len(),
        "imu_format": format!("{:?}", job.imu_format),
        "imu_rate_hz": 1.0 / job.imu.nominal_dt_s,
        "gnss_fixes": job.fixes.time_s.len(),
        "gnss_dropped_by_quality": job.dropped_by_quality,
        "start_time_s": res.init.nav.time_s,
        "gnss_accepted": run.gnss_accepted,
        "gnss_rejected": run.gnss_rejected,
        "gnss_withheld": run.gnss_withheld,
        "gnss_forced": run.gnss_forced,
        "gnss_sigma_floor": if sc.auto_sigma_floor { "auto" } else { "fixed" },
        "gnss_sigma_floors": res.sigma_floors.iter().map(|f| serde_json::json!({
            "quality": quality_name(f.quality), "kind": format!("{:?}", f.kind).to_lowercase(),
            "fixes": f.fixes, "horizontal": f.horizontal, "vertical": f.vertical,
            "file_sigma_horizontal": f.file_sigma.0, "file_sigma_vertical": f.file_sigma.1,
        })).collect::<Vec<_>>(),
        "horizontal_rms_m": res.horizontal_rms_m.map(|r| r.0),
        "horizontal_rms_fixes": res.horizontal_rms_m.map(|r| r.1),
        "outages": res.outages.iter().map(|o| serde_json::json!({
            "start_s": o.window.start_s, "end_s": o.window.end_s,
            "end_horizontal_m": o.end_horizontal_m, "max_horizontal_m": o.max_horizontal_m,
            "end_vertical_m": o.end_vertical_m,
        })).collect::<Vec<_>>(),
        "mean_end_horizontal_m": mean_end,
        "gnss_resets": run.gnss_resets,
        "gnss_recoveries": run.recoveries.iter().map(|e| serde_json::json!({
            "time_s": e.time_s,
            "trigger": match e.trigger {
                driftless::nav::filter::RecoveryTrigger::Rejections => "rejections",
                driftless::nav::filter::RecoveryTrigger::Time => "time",
            },
            "rejected_fixes": e.rejected_fixes, "starved_s": e.starved_s,
            "horizontal_innovation_m": e.horizontal_innovation_m,
            "reset": e.reset, "yaw_from_course": e.yaw_from_course,
        })).collect::<Vec<_>>(),
        "imu_check": imu_check_json(&job.imu_check),
        "outage_selection": job.selection,
        "smoothed_outages": res.smoothed_outages.as_ref().map(|v| v.iter().map(|o| serde_json::json!({
            "start_s": o.window.start_s, "end_s": o.window.end_s,
            "end_horizontal_m": o.end_horizontal_m, "max_horizontal_m": o.max_horizontal_m,
        })).collect::<Vec<_>>()),
        "notes": job.notes,
    });
    outln!("{}", serde_json::to_string_pretty(&v)?);
    Ok(())
}

/// The tables of a run.
fn print_human(a: &NavArgs, job: &NavJobResult, mean_end: Option<f64>, n_ends: usize) {
    let res = &job.session;
    let run = &res.run;
    let sc = &job.session_config;
    outln!(
        "{} IMU epochs at {:.1} Hz ({:?}), {} GNSS fixes in the IMU span; filter started at {:.2} s",
        job.imu.len(),
        1.0 / job.imu.nominal_dt_s,
        job.imu_format,
        job.fixes.time_s.len(),
        res.init.nav.time_s,
    );
    outln!(
        "GNSS: {} accepted, {} rejected by the gate, {} withheld by outages, {} dropped by the quality filter",
        run.gnss_accepted,
        run.gnss_rejected,
        run.gnss_withheld,
        job.dropped_by_quality
    );
    if sc.auto_sigma_floor {
        outln!("{}", floor_summary(&res.sigma_floors));
    }
    let ic = &job.imu_check;
    if !ic.findings.is_empty() {
        use driftless::nav::imu_check::FindingKind;
        outln!(
            "IMU values: {} non-physical, {} isolated outliers, {} saturated runs; {} replaced by interpolation{}",
            ic.count(FindingKind::NonPhysical),
            ic.count(FindingKind::Outlier),
            ic.count(FindingKind::Saturated),
            ic.repaired(),
            if ic.repaired() > 0 {
                " (--repair-spikes)"
            } else {
                ""
            }
        );
    }
    for e in &run.recoveries {
        outln!("{}", e.describe());
    }
    if let Some((rms, n)) = res.horizontal_rms_m {
        outln!(
            "full-GNSS horizontal one-step prediction error: RMS {rms:.3} m over {n} fixes \
             (not counting {:.0} s after the start and {:.0} s after each outage)",
            sc.converge_s,
            sc.reconverge_s
        );
    }
    if let Some(sel) = &job.selection {
        out!("{}", selection_table(sel));
    }
    if !res.outages.is_empty() {
        let mut t = crate::output::Table::new([
            "outage",
            "start s [s]",
            "end e [s]",
            "end error¹ [m]",
            "max inside² [m]",
            "smoothed max² [m]",
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
        out!("{}", t.render());
        outln!(
            "fixes withheld in (s, e]. ¹ horizontal error of the forward filter at the first fix after e \
             (its prediction against that fix); ² largest horizontal error at the IMU epochs in (s, e] \
             against the fixes interpolated linearly"
        );
        if let Some(m) = mean_end {
            outln!(
                "mean end-of-outage horizontal error {m:.2} m over {} outages",
                n_ends
            );
        }
    }
    if let Some(dir) = &a.out {
        outln!("KF-GINS-format outputs written to {}", dir.display());
    }
}

/// The IMU value findings on stderr as warnings (at most `max` lines).
fn warn_imu_findings(report: &driftless::nav::imu_check::ImuCheckReport, max: usize) {
    for f in report.findings.iter().take(max) {
        eprintln!("warning: {}", f.describe());
    }
    if report.findings.len() > max {
        eprintln!(
            "warning: … {} more IMU findings (--verbose or --json lists them)",
            report.findings.len() - max
        );
    }
}

/// The IMU value checks as JSON.
fn imu_check_json(report: &driftless::nav::imu_check::ImuCheckReport) -> serde_json::Value {
    use driftless::nav::imu_check::FindingKind;
    serde_json::json!({
        "epochs": report.epochs,
        "non_physical": report.count(FindingKind::NonPhysical),
        "outliers": report.count(FindingKind::Outlier),
        "saturated": report.count(FindingKind::Saturated),
        "repaired": report.repaired(),
        "findings": report.findings.iter().map(|f| serde_json::json!({
            "kind": f.kind.name(), "channel": f.channel.name(), "index": f.index,
            "time_s": f.time_s, "samples": f.samples, "value_si": f.value_si,
            "reference_si": f.reference_si, "repaired": f.repaired,
        })).collect::<Vec<_>>(),
    })
}

/// RTKLIB quality name of a flag.
fn quality_name(q: u8) -> &'static str {
    driftless::nav::config::QUALITY_NAMES
        .get(q as usize)
        .copied()
        .unwrap_or("unknown")
}

/// One line per class of the estimated GNSS σ floor (`--gnss-sigma-floor auto`).
fn floor_summary(floors: &[driftless::nav::gnss_floor::ClassFloor]) -> String {
    use driftless::nav::filter::UpdateKind;
    if floors.is_empty() {
        return format!(
            "GNSS σ floor: not estimated (fewer than {} usable fixes per solution quality after              the convergence period): the file's σ is used; give --gnss-sigma-floor M if the              antenna moves",
            driftless::nav::gnss_floor::MIN_FIXES
        );
    }
    let mut out = String::from(
        "GNSS σ floor estimated from the innovations of a first pass (--gnss-sigma-floor auto):",
    );
    for f in floors {
        let unit = if f.kind == UpdateKind::Position {
            "m"
        } else {
            "m/s"
        };
        out.push_str(&format!(
            "\n  {} {}: {:.3} {unit} horizontal, {:.3} {unit} vertical from {} fixes (file σ {:.3} / {:.3} {unit})",
            quality_name(f.quality),
            if f.kind == UpdateKind::Position { "position" } else { "velocity" },
            f.horizontal,
            f.vertical,
            f.fixes,
            f.file_sigma.0,
            f.file_sigma.1,
        ));
    }
    out
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
    // No gate unless asked, as in KF-GINS.
    let gate = match a.settings.get("filter.gate") {
        None | Some("off") => None,
        Some(g) => Some(
            g.parse::<driftless::nav::filter::model::Gate>()
                .with_context(|| format!("--gate {g}"))?,
        ),
    };
    let opts = KfGinsJobOptions {
        outages: a.outages_spec().parse().context("--outages")?,
        gate,
        smooth: a.smooth_flag(),
        keep_records: a.csv.is_some() || a.geojson.is_some(),
    };
    let job = run_kf_gins_job(path, &opts)?;
    if !crate::verbosity::quiet() {
        for n in &job.notes {
            eprintln!("note: {n}");
        }
        if let Some(sel) = &job.outage_selection {
            eprint!("{}", selection_table(sel));
        }
    }
    if !crate::verbosity::quiet() {
        log_rejections(
            &job.run,
            if crate::verbosity::verbose() {
                usize::MAX
            } else {
                20
            },
        );
    }
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
        outln!(
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
        outln!(
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
            outln!("wrote {}", f.display());
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

/// Log the measurements the gate rejected (stderr; at most `max` lines).
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

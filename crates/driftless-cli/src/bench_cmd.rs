//! `driftless bench`: the speed figures of BENCHMARKS.md, measured on this machine.
//!
//! Generates an 18-h, 100 Hz, 7-column log (time + 6 axes; 6.48 M rows) in a temporary
//! folder, then times, best and median of `--runs`:
//! * text parse of the CSV (MB/s), binary DRIFTLOG read (MB/s);
//! * exact overlapping ADEV of the six channels on `log:100` taus, with and without CIs;
//! * the opt-in fast (reduced-overlap) OADEV.
//!
//! `--only nav`: the strapdown mechanization, the IMU value checks, the forward filter
//! and the RTS smoother over 1 h at 200 Hz, and `driftless nav --kf-gins` on that hour written as KF-GINS
//! text, in process and as a whole process (this executable spawned, its three files
//! written into `--dir`).

use anyhow::{Context, Result};
use clap::Args;
use driftless::allan::analysis::{AnalysisConfig, FAST_OVERLAP, analyse_channels};
use driftless::allan::phase::frequency_to_phase;
use driftless::allan::taus::{TauSpec, averaging_factors};
use driftless::allan::{DataType, Estimator, estimators};
use driftless::io::{Channel, ImuLog, Quantity, TextOptions};
use driftless::sim::noise::{StaticNoiseConfig, generate_channels};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Hours of 100 Hz data per channel.
    #[arg(long, default_value_t = 18.0, value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub hours: f64,
    /// Repetitions per measurement.
    #[arg(long, default_value_t = 5, value_parser = crate::numbers::count, allow_hyphen_values = true)]
    pub runs: usize,
    /// Where to write the generated logs (deleted afterwards unless --keep).
    #[arg(long, default_value = "/tmp/driftless-bench")]
    pub dir: PathBuf,
    /// Keep the generated CSV and binary logs (for the allantools comparison).
    #[arg(long)]
    pub keep: bool,
    /// Skip the text/binary parse benchmarks.
    #[arg(long)]
    pub no_io: bool,
    /// Print results as JSON.
    #[arg(long)]
    pub json: bool,
    /// Run one group only: allan (parsing and Allan deviation), nav, sim.
    #[arg(long, value_parser = ["allan", "nav", "sim"])]
    pub only: Option<String>,
}

fn time_runs<T>(runs: usize, mut f: impl FnMut() -> Result<T>) -> Result<(f64, f64)> {
    let mut v = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let r = f()?;
        v.push(t.elapsed().as_secs_f64());
        drop(r);
    }
    v.sort_by(f64::total_cmp);
    Ok((v[0], v[v.len() / 2]))
}

pub fn run(a: BenchArgs) -> Result<()> {
    let want = |g: &str| a.only.as_deref().is_none_or(|o| o == g);
    let mut results: Vec<(String, f64, f64, String)> = Vec::new();
    if want("allan") {
        allan_benches(&a, &mut results)?;
    }
    if want("nav") {
        nav_benches(&a, &mut results)?;
    }
    if want("sim") {
        sim_benches(&a, &mut results)?;
    }
    print_results(&a, &results)
}

type Results = Vec<(String, f64, f64, String)>;

fn allan_benches(a: &BenchArgs, results: &mut Results) -> Result<()> {
    let rate = 100.0;
    let n = (a.hours * 3600.0 * rate).round() as usize;
    let cfg = StaticNoiseConfig {
        sample_rate_hz: rate,
        duration_s: n as f64 / rate,
        white: 1e-3,
        rate_random_walk: 1e-6,
        ..StaticNoiseConfig::default()
    };
    note!("generating 6 × {n} samples …");
    let data = generate_channels(&vec![cfg; 6], 7)?;
    let names = ["gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"];
    let channels: Vec<Channel> = names
        .iter()
        .zip(data)
        .map(|(nm, values)| Channel {
            name: nm.to_string(),
            quantity: if nm.starts_with("gyro") {
                Quantity::AngularRate
            } else {
                Quantity::SpecificForce
            },
            source_unit: if nm.starts_with("gyro") {
                "rad/s"
            } else {
                "m/s^2"
            }
            .into(),
            values,
        })
        .collect();
    let time: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
    let log = ImuLog::new("bench", Some(time), 1.0 / rate, channels);

    // Held while the benchmark writes and reads its files: a second run would race them.
    let _lock = driftless::io::output::lock_folder(&a.dir)?;
    if !a.no_io {
        let csv = a.dir.join("static_18h.csv");
        let csv_full = a.dir.join("static_18h_full.csv");
        let bin = a.dir.join("static_18h.dlog");
        note!(
            "writing {}, {} and {} …",
            csv.display(),
            csv_full.display(),
            bin.display()
        );
        write_logger_csv(&log, &csv)?;
        driftless::io::write_csv_file(&log, &csv_full)?;
        driftless::io::write_binary_file(&log, &bin)?;
        let bin_mb = std::fs::metadata(&bin)?.len() as f64 / 1e6;
        let opts = TextOptions {
            time_column: Some(driftless::io::ColumnRef::Index(1)),
            ..TextOptions::default()
        };
        let mut best_text = f64::INFINITY;
        for (path, what) in [
            (&csv, "logger precision: t to 0.01 s, 7 significant digits"),
            (&csv_full, "full f64 precision, 17 digits"),
        ] {
            let mb = std::fs::metadata(path)?.len() as f64 / 1e6;
            let (best, med) =
                time_runs(a.runs, || Ok(driftless::io::read_text_file(path, &opts)?))?;
            best_text = best_text.min(best);
            results.push((
                format!("text parse, {mb:.0} MB CSV, 7 columns ({what})"),
                best,
                med,
                format!("{:.0} MB/s", mb / best),
            ));
        }
        let best = best_text;
        let (bbest, bmed) = time_runs(a.runs, || Ok(driftless::io::read_binary_file(&bin)?))?;
        results.push((
            format!("binary DRIFTLOG read, {bin_mb:.0} MB"),
            bbest,
            bmed,
            format!(
                "{:.0} MB/s, {:.1}x faster than text",
                bin_mb / bbest,
                best / bbest
            ),
        ));
        if !a.keep {
            let _ = std::fs::remove_file(&csv);
            let _ = std::fs::remove_file(&csv_full);
            let _ = std::fs::remove_file(&bin);
        }
    }

    let ms = averaging_factors(&TauSpec::Log(100), 1.0 / rate, n + 1, Estimator::Oadev)?;
    let phases: Vec<Vec<f64>> = log
        .channels
        .iter()
        .map(|c| frequency_to_phase(&c.values, 1.0 / rate))
        .collect();
    let (best, med) = time_runs(a.runs, || {
        use rayon::prelude::*;
        Ok(phases
            .par_iter()
            .map(|x| estimators::sums(Estimator::Oadev, x, &ms))
            .collect::<Vec<_>>())
    })?;
    results.push((
        format!("exact OADEV, 6 ch × {n}, {} taus (sums only)", ms.len()),
        best,
        med,
        String::new(),
    ));
    let (best, med) = time_runs(a.runs, || {
        use rayon::prelude::*;
        Ok(phases
            .par_iter()
            .map(|x| estimators::oadev_strided_sums(x, &ms, FAST_OVERLAP))
            .collect::<Vec<_>>())
    })?;
    results.push((
        format!(
            "fast OADEV (stride m/{FAST_OVERLAP}), 6 ch, {} taus (sums only)",
            ms.len()
        ),
        best,
        med,
        String::new(),
    ));
    let inputs: Vec<(&str, Vec<&[f64]>)> = log
        .channels
        .iter()
        .map(|c| (c.name.as_str(), vec![c.values.as_slice()]))
        .collect();
    for (fast, label) in [(false, "exact"), (true, "fast")] {
        let cfg = AnalysisConfig {
            estimator: Estimator::Oadev,
            taus: TauSpec::Log(100),
            data_type: DataType::Frequency,
            alpha: None,
            confidence: 0.683,
            fast,
        };
        let (best, med) = time_runs(a.runs, || Ok(analyse_channels(&inputs, 1.0 / rate, &cfg)?))?;
        results.push((
            format!("{label} OADEV + noise ID + EDF/CI, 6 ch, log:100, from rates"),
            best,
            med,
            String::new(),
        ));
    }

    Ok(())
}

fn nav_benches(a: &BenchArgs, results: &mut Results) -> Result<()> {
    // Strapdown mechanization: 1 h at 200 Hz of a constant-rate turn (ideal increments
    // generated first, outside the timing).
    {
        use driftless::nav::mechanization::mechanize;
        use driftless::sim::ideal_imu::{ConstantTurn, Trajectory, ideal_increments};
        let turn = ConstantTurn {
            lat_rad: 30f64.to_radians(),
            lon_rad: 114f64.to_radians(),
            height_m: 20.0,
            speed_m_s: 15.0,
            yaw0_rad: 0.0,
            yaw_rate_rad_s: 3f64.to_radians(),
            roll_rad: 0.0,
            pitch_rad: 0.0,
        };
        let dt = 0.005;
        let n_epochs = 720_000usize;
        let incs: Vec<_> = ideal_increments(&turn, dt, dt, n_epochs).collect();
        let start = turn.point(0.0).nav_state(0.0);
        let (best, med) = time_runs(a.runs, || {
            let mut st = start;
            let mut prev = incs[0];
            for inc in &incs {
                st = mechanize(&st, &prev, inc);
                prev = *inc;
            }
            Ok(st)
        })?;
        results.push((
            format!("strapdown mechanization, {n_epochs} epochs (1 h at 200 Hz)"),
            best,
            med,
            format!("{:.0} ns/epoch", best / n_epochs as f64 * 1e9),
        ));

        // The IMU value checks of `driftless nav` (non-physical, outliers, saturation)
        // on the same hour, as one stream.
        {
            use driftless::nav::imu_check::{ImuCheckConfig, check_imu};
            use driftless::nav::pipeline::ImuStream;
            let stream = ImuStream {
                source: "bench".into(),
                nominal_dt_s: dt,
                epochs: incs.clone(),
                ..ImuStream::default()
            };
            let cfg = ImuCheckConfig::default();
            let (best, med) = time_runs(a.runs, || Ok(check_imu(&stream, None, &cfg)?))?;
            results.push((
                format!("IMU value check (spikes, saturation), {n_epochs} epochs"),
                best,
                med,
                format!("{:.0} ns/epoch", best / n_epochs as f64 * 1e9),
            ));
        }

        // 21-state forward filter with 1 Hz position fixes (truth, 2 cm σ), then the RTS
        // smoother, on the same hour.
        use driftless::io::nav::GnssFixes;
        use driftless::nav::filter::run::{InitialState, run_forward};
        use driftless::nav::filter::smoother::smooth;
        use driftless::nav::filter::state::SensorErrors;
        let mut g = GnssFixes::default();
        for s in 1..3600 {
            let p = turn.point(s as f64);
            g.time_s.push(s as f64);
            g.lat_rad.push(p.lat_rad);
            g.lon_rad.push(p.lon_rad);
            g.height_m.push(p.height_m);
            g.sigma_ned_m.push([0.02, 0.02, 0.04]);
            g.quality.push(1);
        }
        let cfg = driftless::nav::filter::model::FilterConfig::new(
            driftless::nav::session::consumer_mems_noise(),
            [0.0; 3],
        );
        let init = InitialState {
            nav: start,
            sensors: SensorErrors::default(),
            sigma_pos_ned_m: [0.05; 3],
            sigma_vel_ned_m_s: [0.05; 3],
            sigma_att_rad: [0.01; 3],
            sigma_sensors: None,
        };
        let mut last_run = None;
        let (best, med) = time_runs(a.runs, || {
            let r = run_forward(&incs, &g, init, &cfg)?;
            last_run = Some(r);
            Ok(())
        })?;
        results.push((
            format!("GNSS/INS forward filter, {n_epochs} epochs + 3599 fixes"),
            best,
            med,
            format!("{:.2} µs/epoch", best / n_epochs as f64 * 1e6),
        ));
        kfgins_benches(a, results, &incs, &g, &start)?;
        if let Some(run) = &last_run {
            let (sbest, smed) = time_runs(a.runs.min(3), || Ok(smooth(run, &init, &cfg)?))?;
            results.push((
                "RTS smoother over that hour".to_string(),
                sbest,
                smed,
                format!("forward + smoother {:.2} s", best + sbest),
            ));
        }
    }

    Ok(())
}

/// End to end as KF-GINS is used: its text IMU and GNSS files and YAML in, its three
/// output files out (`driftless nav --kf-gins`), in-process and as a whole process.
fn kfgins_benches(
    a: &BenchArgs,
    results: &mut Results,
    incs: &[driftless::nav::mechanization::ImuIncrement],
    g: &driftless::io::nav::GnssFixes,
    start: &driftless::nav::mechanization::NavState,
) -> Result<()> {
    let n_epochs = incs.len();
    use driftless::io::nav::{write_kfgins_gnss, write_kfgins_imu};
    let dir = a.dir.join("kfgins");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let cols = driftless::nav::pipeline::increment_columns(incs);
    let imu_file = dir.join("imu.txt");
    bench_input(&imu_file, |w| Ok(write_kfgins_imu(w, "imu.txt", &cols)?))?;
    let imu_mb = std::fs::metadata(&imu_file)?.len() as f64 / 1e6;
    bench_input(&dir.join("gnss.txt"), |w| {
        Ok(write_kfgins_gnss(w, "gnss.txt", g)?)
    })?;
    let e0 = driftless::nav::attitude::Euler::from_dcm(&start.q_bn.to_dcm());
    let yaml = format!(
        "imupath: \"{}\"\ngnsspath: \"{}\"\noutputpath: \"{}\"\nimudatalen: 7\n\
         imudatarate: 200\nstarttime: 0\nendtime: -1\ninitpos: [{}, {}, {}]\n\
         initvel: [{}, {}, {}]\ninitatt: [{}, {}, {}]\ninitgyrbias: [0, 0, 0]\n\
         initaccbias: [0, 0, 0]\ninitgyrscale: [0, 0, 0]\ninitaccscale: [0, 0, 0]\n\
         initposstd: [0.05, 0.05, 0.05]\ninitvelstd: [0.05, 0.05, 0.05]\n\
         initattstd: [0.5, 0.5, 0.5]\nimunoise:\n  arw: [0.5, 0.5, 0.5]\n\
         \x20 vrw: [0.1, 0.1, 0.1]\n  gbstd: [100, 100, 100]\n  abstd: [5000, 5000, 5000]\n\
         \x20 gsstd: [5000, 5000, 5000]\n  asstd: [5000, 5000, 5000]\n  corrtime: 1.0\n\
         antlever: [0, 0, 0]\n",
        dir.join("imu.txt").display(),
        dir.join("gnss.txt").display(),
        dir.join("out").display(),
        start.lat_rad.to_degrees(),
        start.lon_rad.to_degrees(),
        start.height_m,
        start.vel_ned_m_s[0],
        start.vel_ned_m_s[1],
        start.vel_ned_m_s[2],
        e0.roll_rad.to_degrees(),
        e0.pitch_rad.to_degrees(),
        e0.yaw_rad.to_degrees()
    );
    let cfg_path = dir.join("kf-gins.yaml");
    driftless::io::output::write(&cfg_path, yaml)?;
    let (kbest, kmed) = time_runs(a.runs.min(3), || {
        driftless::nav::kfgins_job::run_kf_gins_job(&cfg_path, &Default::default())
            .map(|_| ())
            .map_err(Into::into)
    })?;
    results.push((
        format!(
            "driftless nav --kf-gins end to end: {imu_mb:.0} MB IMU text + GNSS + YAML in, 3 KF-GINS files out"
        ),
        kbest,
        kmed,
        format!("{:.2} µs/epoch", kbest / n_epochs as f64 * 1e6),
    ));
    // The same job as a whole process (start-up, reading, filtering, writing and
    // exit), the files in `--dir`, as `/usr/bin/time driftless nav --kf-gins`.
    let whole = whole_process_runs(a.runs, &cfg_path)?;
    results.push((
        format!(
            "driftless nav --kf-gins as a whole process (spawned), files to {}",
            dir.join("out").display()
        ),
        whole.best_s,
        whole.median_s,
        whole.note(n_epochs),
    ));
    if !a.keep {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(())
}

/// Wall times of `driftless nav --kf-gins` run as child processes of this executable.
struct WholeProcess {
    best_s: f64,
    median_s: f64,
    /// User + system CPU seconds of the best run (Linux), when readable.
    best_cpu_s: Option<(f64, f64)>,
    /// Load average (1 min) before the first run (Linux), when readable.
    load_1min: Option<f64>,
}

impl WholeProcess {
    fn note(&self, n_epochs: usize) -> String {
        let mut note = format!("{:.2} µs/epoch", self.best_s / n_epochs as f64 * 1e6);
        if let Some((user, sys)) = self.best_cpu_s {
            note.push_str(&format!(", {user:.2} s user + {sys:.2} s sys"));
        }
        if let Some(l) = self.load_1min {
            note.push_str(&format!(", load average {l:.1}"));
        }
        note
    }
}

/// CPU seconds (user, system) of the waited-for children of this process, from
/// `/proc/self/stat` (fields 16 and 17, `cutime` and `cstime`, in clock ticks of
/// 1/100 s, `proc(5)`). `None` where that file is not available.
fn children_cpu_s() -> Option<(f64, f64)> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name, which is in parentheses and may contain spaces.
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // `rest` starts at field 3 (state), so field n is f[n - 3].
    let tick = |n: usize| f.get(n - 3)?.parse::<f64>().ok().map(|t| t / 100.0);
    Some((tick(16)?, tick(17)?))
}

/// Runs `driftless nav --kf-gins CONFIG` `runs` times as a child process and times each
/// from spawn to exit.
fn whole_process_runs(runs: usize, config: &std::path::Path) -> Result<WholeProcess> {
    let exe = std::env::current_exe().context("locating the driftless executable")?;
    let load_1min = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next()?.parse().ok());
    let mut times = Vec::with_capacity(runs.max(1));
    let mut best: Option<(f64, Option<(f64, f64)>)> = None;
    for _ in 0..runs.max(1) {
        let cpu0 = children_cpu_s();
        let t = Instant::now();
        let status = std::process::Command::new(&exe)
            .arg("nav")
            .arg("--kf-gins")
            .arg(config)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .with_context(|| format!("running {} nav --kf-gins", exe.display()))?;
        let wall = t.elapsed().as_secs_f64();
        if !status.success() {
            anyhow::bail!(
                "{} nav --kf-gins {} failed ({status}); run it by hand to see the error",
                exe.display(),
                config.display()
            );
        }
        let cpu = match (cpu0, children_cpu_s()) {
            (Some(a), Some(b)) => Some((b.0 - a.0, b.1 - a.1)),
            _ => None,
        };
        if best.is_none_or(|(b, _)| wall < b) {
            best = Some((wall, cpu));
        }
        times.push(wall);
    }
    times.sort_by(f64::total_cmp);
    Ok(WholeProcess {
        best_s: times[0],
        median_s: times[times.len() / 2],
        best_cpu_s: best.and_then(|b| b.1),
        load_1min,
    })
}

/// Simulation speed: an 18-h, 100 Hz six-axis static log through the full
/// sensor model with every error term (ADIS16465-like preset), and a 1-h, 200 Hz land
/// drive (TOML profile) with ideal increments, sensor errors and 1 Hz GNSS.
fn sim_benches(a: &BenchArgs, results: &mut Results) -> Result<()> {
    use driftless::sim::scenario::Scenario;
    let static_18h = format!(
        "seed = 5\n[imu]\nrate_hz = 100.0\npreset = \"adis16465-like\"\noutput = \"rates\"\n\
         [trajectory]\ntype = \"static\"\nlat_deg = 30.5\nduration_s = {}\n",
        a.hours * 3600.0
    );
    let sc = Scenario::from_toml_str(&static_18h, "bench static")?;
    let (best, med) = time_runs(a.runs.min(3), || Ok(sc.run()?))?;
    results.push((
        format!(
            "simulate {} h × 100 Hz static six-axis log, all error terms (adis16465-like)",
            a.hours
        ),
        best,
        med,
        String::new(),
    ));
    // A 1-h drive: 14 laps of stop, accelerate, cruise, four right turns, brake.
    let mut drive = String::from(
        "seed = 3\n[imu]\nrate_hz = 200.0\npreset = \"adis16465-like\"\n[trajectory]\n\
         type = \"profile\"\n[trajectory.start]\nlat_deg = 30.5\nlon_deg = 114.3\n\
         height_m = 20.0\nheading_deg = 0.0\n",
    );
    for _ in 0..14 {
        drive.push_str(
            "[[trajectory.segment]]\ntype = \"stop\"\nduration_s = 20.0\n\
             [[trajectory.segment]]\ntype = \"accelerate\"\nto_speed_m_s = 15.0\nduration_s = 10.0\n",
        );
        for _ in 0..4 {
            drive.push_str(
                "[[trajectory.segment]]\ntype = \"cruise\"\nduration_s = 50.0\n\
                 [[trajectory.segment]]\ntype = \"turn\"\nangle_deg = 90.0\nradius_m = 40.0\n",
            );
        }
        drive.push_str("[[trajectory.segment]]\ntype = \"brake\"\nduration_s = 8.0\n");
    }
    drive.push_str("[gnss]\nrate_hz = 1.0\nsigma_ned_m = [0.02, 0.02, 0.02]\n");
    let sc = Scenario::from_toml_str(&drive, "bench drive")?;
    let probe = sc.run()?;
    let n = probe.imu.len();
    let (best, med) = time_runs(a.runs.min(3), || Ok(sc.run()?))?;
    results.push((
        format!(
            "simulate a {:.0}-min land drive at 200 Hz ({n} increments) with sensor errors and 1 Hz GNSS",
            n as f64 * probe.imu.dt_s / 60.0
        ),
        best,
        med,
        format!("{:.2} s per hour", best * 3600.0 / (n as f64 * probe.imu.dt_s)),
    ));
    Ok(())
}

fn print_results(a: &BenchArgs, results: &Results) -> Result<()> {
    if a.json {
        let v: Vec<serde_json::Value> = results
            .iter()
            .map(|(w, b, m, note)| serde_json::json!({"what": w, "best_s": b, "median_s": m, "note": note}))
            .collect();
        outln!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let mut t = crate::output::Table::new(["benchmark", "best [s]", "median [s]", "note"]);
        for (w, b, m, note) in results {
            t.row(vec![
                w.clone(),
                format!("{b:.3}"),
                format!("{m:.3}"),
                note.clone(),
            ]);
        }
        out!("{}", t.render());
        outln!(
            "machine: {} cores (rayon threads: {})",
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            rayon::current_num_threads()
        );
    }
    Ok(())
}

/// Writes one generated input file through a buffer (not synced: it is read back at once).
fn bench_input(
    path: &std::path::Path,
    body: impl FnOnce(std::io::BufWriter<&mut driftless::io::output::AtomicFile>) -> Result<()>,
) -> Result<()> {
    let mut f = driftless::io::output::AtomicFile::create(path)
        .with_context(|| format!("creating {}", path.display()))?
        .durable(false);
    body(std::io::BufWriter::new(&mut f))?;
    f.commit()
        .with_context(|| format!("writing {}", path.display()))
}

/// The CSV a data logger writes: time to 0.01 s, samples with 7 significant digits
/// (a 16-bit MEMS output carries about 5), as in a user's ~650 MB 18-h log.
fn write_logger_csv(log: &ImuLog, path: &std::path::Path) -> Result<()> {
    use std::io::Write;
    let mut f = driftless::io::output::AtomicFile::create(path)
        .with_context(|| format!("creating {}", path.display()))?
        .durable(false);
    let mut w = std::io::BufWriter::with_capacity(1 << 20, &mut f);
    let names: Vec<&str> = log.channels.iter().map(|c| c.name.as_str()).collect();
    writeln!(w, "time,{}", names.join(","))?;
    let t = log.time_s.as_deref().unwrap_or(&[]);
    for i in 0..log.len() {
        write!(
            w,
            "{:.2}",
            t.get(i).copied().unwrap_or(i as f64 * log.tau0_s)
        )?;
        for c in &log.channels {
            write!(w, ",{:.6e}", c.values[i])?;
        }
        w.write_all(b"\n")?;
    }
    w.flush()?;
    drop(w);
    f.commit()
        .with_context(|| format!("writing {}", path.display()))
}

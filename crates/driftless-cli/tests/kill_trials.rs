//! `kill -9` at random instants of every command that writes files, and two runs into one
//! folder at once. After a kill every output is the earlier file (or absent when there was
//! none), or the complete new one — byte for byte the output of a completed run — never a
//! partial file under a final name; the temporary files a kill leaves are cleared by the
//! next run. The instants are spread over the whole run time of the command, measured on
//! this machine; a meaningful share of the kills must land before the run ends.
//! (Unix: the kills are signals.)
#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::bin;

/// Kill trials per command.
const TRIALS: usize = 50;

fn scratch(tag: &str) -> PathBuf {
    common::scratch(&format!("kill-{tag}"))
}

fn city_drive() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/city-drive.toml")
}

fn stderr_of(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `cmd` to its end, which must be a success; returns how long it took.
fn run_ok(cmd: &mut Command) -> Duration {
    let t = Instant::now();
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{cmd:?}: {}", stderr_of(&o));
    t.elapsed()
}

/// `simulate --force --seed SEED --out OUT` of the city drive.
fn simulate(out: &Path, seed: u64) -> Command {
    let mut c = bin();
    c.args(["simulate", "--json", "--force", "--seed", &seed.to_string()])
        .arg("--out")
        .arg(out)
        .arg(city_drive());
    c
}

/// Regular files under `dir` (recursively), relative to it, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, dir, &mut v);
    v.sort();
    v
}

/// Every file under `dir` with its bytes.
fn contents(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    files_under(dir)
        .into_iter()
        .map(|n| {
            let b = std::fs::read(dir.join(&n)).unwrap();
            (n, b)
        })
        .collect()
}

/// Runs `earlier` and then `new`, which both write the folder `out`: the outputs (every
/// file of the folder, the same after both runs) and how long `new` took.
fn folder_outputs(out: &Path, earlier: &mut Command, new: &mut Command) -> (Vec<Output>, Duration) {
    run_ok(earlier);
    let old = contents(out);
    let whole = run_ok(new);
    assert_eq!(
        files_under(out),
        old.iter().map(|o| o.0.clone()).collect::<Vec<_>>()
    );
    let outputs = old
        .into_iter()
        .map(|(n, b)| Output::new(out.join(n), Some(b)))
        .collect();
    (outputs, whole)
}

fn is_partial(p: &Path) -> bool {
    p.file_name()
        .is_some_and(|n| driftless::io::output::partial_owner(&n.to_string_lossy()).is_some())
}

/// A small linear congruential generator: the trial instants, seeded from the clock.
struct Rng(u64);

impl Rng {
    fn new() -> Self {
        let t = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap();
        Rng(t.subsec_nanos() as u64 | 1)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % n.max(1)
    }
}

/// One output of a command: its path, the earlier file (`None`: none), and the bytes a
/// completed run writes.
struct Output {
    path: PathBuf,
    old: Option<Vec<u8>>,
    new: Vec<u8>,
}

impl Output {
    /// Reads the complete new file now, with `old` from before the run.
    fn new(path: PathBuf, old: Option<Vec<u8>>) -> Self {
        let new = std::fs::read(&path).unwrap();
        Output { path, old, new }
    }
}

/// What the trials of one command found.
struct Tally {
    /// Kills that landed before the run ended.
    mid_run: usize,
    /// Of those, runs that had replaced some of their outputs but not all.
    between_files: usize,
    /// Temporary files left by the kills, before the next run cleared them.
    temporaries: usize,
}

/// `TRIALS` times: puts the earlier files in place, starts `cmd`, kills it (`SIGKILL`) at a
/// random instant within `whole` (one run's time on this machine) and checks every
/// output. `may_vanish`: the writer removes an earlier file just before renaming the new
/// one over its name (KF-GINS's files), so an absent file is also whole. Ends with one
/// completed run, after which no temporary file may remain.
fn kill_trials(
    label: &str,
    outputs: &[Output],
    may_vanish: bool,
    whole: Duration,
    cmd: &dyn Fn() -> Command,
) -> Tally {
    // (A file may be the same in both runs, such as a configuration that does not depend
    // on the seed; most must differ.)
    let differ = outputs.iter().filter(|o| o.old.as_ref() != Some(&o.new));
    assert!(
        differ.count() * 2 > outputs.len(),
        "{label}: the earlier and the new run write the same files: no test"
    );
    let folders: Vec<&Path> = {
        let mut f: Vec<&Path> = outputs.iter().filter_map(|o| o.path.parent()).collect();
        f.sort();
        f.dedup();
        f
    };
    let temporaries = |folders: &[&Path]| -> usize {
        folders
            .iter()
            .flat_map(|d| std::fs::read_dir(d).unwrap())
            .filter(|e| is_partial(&e.as_ref().unwrap().path()))
            .count()
    };
    let mut rng = Rng::new();
    let whole_us = whole.as_micros() as u64;
    let mut tally = Tally {
        mid_run: 0,
        between_files: 0,
        temporaries: 0,
    };
    for trial in 0..TRIALS {
        for o in outputs {
            match &o.old {
                Some(b) => std::fs::write(&o.path, b).unwrap(),
                None => {
                    let _ = std::fs::remove_file(&o.path);
                }
            }
        }
        let delay = Duration::from_micros(rng.below(whole_us));
        let mut child = cmd()
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(delay);
        let _ = child.kill();
        let status = child.wait().unwrap();
        let killed = status.signal() == Some(9);
        assert!(
            killed || status.success(),
            "{label} trial {trial}: {status}"
        );
        let (mut replaced, mut changing) = (0, 0);
        for o in outputs {
            let got = std::fs::read(&o.path).ok();
            let whole_file =
                got.as_ref() == Some(&o.new) || got == o.old || (got.is_none() && may_vanish);
            assert!(
                whole_file,
                "{label} trial {trial} (killed after {delay:?} of {whole:?}, {status}): {} is \
                 neither the earlier file nor the complete new one ({:?} bytes)",
                o.path.display(),
                got.map(|g| g.len())
            );
            if o.old.as_ref() != Some(&o.new) {
                changing += 1;
                replaced += usize::from(got.as_ref() == Some(&o.new));
            }
        }
        if killed {
            tally.mid_run += 1;
            tally.between_files += usize::from(replaced > 0 && replaced < changing);
        }
        tally.temporaries += temporaries(&folders);
    }
    // A completed run: the complete files, and nothing the kills left.
    run_ok(&mut cmd());
    for o in outputs {
        assert!(
            std::fs::read(&o.path).unwrap() == o.new,
            "{label}: {}",
            o.path.display()
        );
    }
    assert_eq!(temporaries(&folders), 0, "{label}: temporary files remain");
    eprintln!(
        "{label}: {TRIALS} kills within {whole:?}: {} before the end ({} between files), \
         {} temporary files left and cleared",
        tally.mid_run, tally.between_files, tally.temporaries
    );
    assert!(
        tally.mid_run * 5 >= TRIALS,
        "{label}: only {} of {TRIALS} kills landed before the run ended",
        tally.mid_run
    );
    tally
}

/// `simulate --force` over an earlier simulation (another seed).
#[test]
#[ignore = "kill trials (minutes)"]
fn simulate_killed_at_random_instants() {
    let d = scratch("simulate");
    let out = d.join("sim");
    let (outputs, whole) = folder_outputs(&out, &mut simulate(&out, 1), &mut simulate(&out, 2));
    kill_trials("simulate", &outputs, false, whole, &|| simulate(&out, 2));
    let _ = std::fs::remove_dir_all(&d);
}

/// A thermal model for `compensate` (SI units, valid over the city drive's temperatures).
fn thermal_model(bias_x_m_s2: f64) -> String {
    format!(
        "format_version = 1\nmodel_id = 42\nt_ref_c = 25.0\nrange_c = [-10.0, 60.0]\n\
         out_of_range = \"clamp\"\n[accel]\nraw_unit = \"m/s^2\"\nbias = [{bias_x_m_s2:?}, 0.0, 0.0]\n\
         matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
         bias_delta = [[0.0, 0.004, -2e-5, 1e-7], [0.0], [0.0]]\n\
         scale_delta = [[0.0, 5e-5], [0.0], [0.0]]\n[gyro]\nraw_unit = \"rad/s\"\n\
         bias = [0.002, 0.0, 0.0]\nmatrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
         bias_delta = [[0.0, 3e-5, 4e-7], [0.0], [0.0]]\nscale_delta = [[0.0], [0.0], [0.0]]\n"
    )
}

/// `compensate` of the city drive's IMU log over an earlier compensated log (another
/// model).
#[test]
#[ignore = "kill trials (minutes)"]
fn compensate_killed_at_random_instants() {
    let d = scratch("compensate");
    run_ok(&mut simulate(&d.join("sim"), 1));
    std::fs::write(d.join("earlier.toml"), thermal_model(0.3)).unwrap();
    std::fs::write(d.join("model.toml"), thermal_model(0.2)).unwrap();
    let out = d.join("comp.csv");
    let cmd = |model: &str| {
        let mut c = bin();
        c.arg("compensate")
            .arg(d.join("sim/imu.csv"))
            .arg("--model")
            .arg(d.join(model))
            .arg("--out")
            .arg(&out);
        c
    };
    run_ok(&mut cmd("earlier.toml"));
    let old = std::fs::read(&out).unwrap();
    let whole = run_ok(&mut cmd("model.toml"));
    let outputs = [Output::new(out.clone(), Some(old))];
    kill_trials("compensate", &outputs, false, whole, &|| cmd("model.toml"));
    let _ = std::fs::remove_dir_all(&d);
}

/// `convert` of a DRIFTLOG to CSV over an earlier CSV (another simulation's log).
#[test]
#[ignore = "kill trials (minutes)"]
fn convert_killed_at_random_instants() {
    let d = scratch("convert");
    run_ok(&mut simulate(&d.join("sim"), 1));
    run_ok(
        bin()
            .arg("convert")
            .arg(d.join("sim/imu.csv"))
            .arg(d.join("imu.dlog")),
    );
    let out = d.join("out.csv");
    std::fs::copy(d.join("sim/imu.csv"), &out).unwrap();
    let old = std::fs::read(&out).unwrap();
    let cmd = || {
        let mut c = bin();
        c.arg("convert").arg(d.join("imu.dlog")).arg(&out);
        c
    };
    let whole = run_ok(&mut cmd());
    let outputs = [Output::new(out.clone(), Some(old))];
    kill_trials("convert", &outputs, false, whole, &cmd);
    let _ = std::fs::remove_dir_all(&d);
}

/// `nav --kf-gins` of the simulated drive over an earlier run's files (the first 60 s).
#[test]
#[ignore = "kill trials (minutes)"]
fn kf_gins_killed_at_random_instants() {
    let d = scratch("kf-gins");
    let sim = d.join("sim");
    run_ok(&mut simulate(&sim, 1));
    let cfg = std::fs::read_to_string(sim.join("kf-gins.yaml")).unwrap();
    std::fs::write(
        sim.join("earlier.yaml"),
        common::kf_gins_first_seconds(&cfg, 60.0),
    )
    .unwrap();
    let cmd = |yaml: &str| {
        let mut c = bin();
        c.current_dir(&sim)
            .args(["nav", "--kf-gins", yaml, "--json"]);
        c
    };
    let out = sim.join("kf-gins-out");
    let (outputs, whole) = folder_outputs(&out, &mut cmd("earlier.yaml"), &mut cmd("kf-gins.yaml"));
    assert_eq!(outputs.len(), 3);
    kill_trials("nav --kf-gins", &outputs, true, whole, &|| {
        cmd("kf-gins.yaml")
    });
    let _ = std::fs::remove_dir_all(&d);
}

/// The built-in experiment scenario cut down to run in about a second: a shorter static
/// log, six chamber temperatures with short soaks, the first nine segments of the drive
/// with two 30-s outages.
fn small_experiment(seed: u64) -> String {
    let out = bin().args(["demo", "--print-scenario"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = Vec::new();
    let mut segments = 0;
    let mut in_dropped_segment = false;
    for line in text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        if line.trim() == "[[vehicle.trajectory.segment]]" {
            segments += 1;
            in_dropped_segment = segments > 9;
        } else if line.starts_with('[') {
            in_dropped_segment = false;
        }
        if in_dropped_segment {
            continue;
        }
        lines.push(match key {
            "seed" => format!("seed = {seed}"),
            "hours" => "hours = 0.3".into(),
            "temperatures_c" => "temperatures_c = [25.0, -5.0, 10.0, 40.0, 55.0, 25.0]".into(),
            "soak_s" => "soak_s = 120.0".into(),
            "position_cycles" => "position_cycles = 1".into(),
            "spec" => "spec = \"auto:2x30\"".into(),
            _ => line.to_string(),
        });
    }
    assert!(segments > 9, "{text}");
    lines.join("\n") + "\n"
}

/// `experiment --force` (one Monte Carlo run) over an earlier experiment (another seed).
#[test]
#[ignore = "kill trials (minutes)"]
fn experiment_killed_at_random_instants() {
    let d = scratch("experiment");
    std::fs::write(d.join("earlier.toml"), small_experiment(2006)).unwrap();
    std::fs::write(d.join("small.toml"), small_experiment(2005)).unwrap();
    let out = d.join("exp");
    let cmd = |scenario: &str| {
        let mut c = bin();
        c.args(["experiment", "--json", "--force", "--runs", "1", "--out"])
            .arg(&out)
            .arg(d.join(scenario));
        c
    };
    let (outputs, whole) = folder_outputs(&out, &mut cmd("earlier.toml"), &mut cmd("small.toml"));
    kill_trials("experiment", &outputs, false, whole, &|| cmd("small.toml"));
    let _ = std::fs::remove_dir_all(&d);
}

/// Two `simulate` runs started together into one new folder: exactly one succeeds; the
/// other fails at once on the folder's lock, naming the folder; the folder holds the
/// winner's complete files and nothing else.
#[test]
#[ignore = "kill trials (minutes)"]
fn two_runs_into_one_folder() {
    let d = scratch("concurrent");
    let reference: Vec<Vec<(PathBuf, Vec<u8>)>> = [1, 2]
        .iter()
        .map(|&seed| {
            let out = d.join(format!("ref{seed}"));
            run_ok(&mut simulate(&out, seed));
            contents(&out)
        })
        .collect();
    for round in 0..5 {
        let out = d.join(format!("both{round}"));
        let start = |seed: u64| {
            bin()
                .args(["simulate", "--json", "--seed", &seed.to_string(), "--out"])
                .arg(&out)
                .arg(city_drive())
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (start(1), start(2));
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let ok: Vec<usize> = [&a, &b]
            .iter()
            .enumerate()
            .filter(|(_, o)| o.status.success())
            .map(|(k, _)| k)
            .collect();
        assert_eq!(
            ok.len(),
            1,
            "round {round}: {} | {}",
            stderr_of(&a),
            stderr_of(&b)
        );
        let winner = ok[0];
        let loser = if winner == 0 { &b } else { &a };
        assert_eq!(loser.status.code(), Some(1));
        let e = stderr_of(loser);
        assert!(
            e.contains(&out.display().to_string())
                && e.contains("another driftless run is writing it"),
            "round {round}: {e}"
        );
        let got = contents(&out);
        assert!(
            got == reference[winner],
            "round {round}: the folder is not run {winner}'s files: {:?}",
            got.iter().map(|g| &g.0).collect::<Vec<_>>()
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

//! What happens around a run when things go wrong: outputs that are inputs, writes that
//! fail half-way, a closed or full standard output, a process killed mid-write. Every
//! earlier file must survive, and nothing partial may sit under a final name.
//! (Unix: the tests use `sh`, `ulimit`, `/dev/full` and symbolic links.)
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

mod common;
use common::bin;

fn scratch(tag: &str) -> PathBuf {
    common::scratch(&format!("faults-{tag}"))
}

fn scenario() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/city-drive.toml")
}

/// Simulates the city drive with `seed` into `out` (which may hold an earlier run).
fn simulate(out: &Path, seed: u64) {
    let o = bin()
        .args([
            "simulate",
            "--json",
            "--force",
            "--seed",
            &seed.to_string(),
            "--out",
        ])
        .arg(out)
        .arg(scenario())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Names in `dir` that are not `keep`: temporary files left behind, for instance.
fn others(dir: &Path, keep: &[&str]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect()
}

fn stderr_of(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn an_output_that_is_an_input_is_refused() {
    let d = scratch("same");
    let log = d.join("log.csv");
    let text = "time,gx\n0,1\n0.01,2\n0.02,3\n0.03,4\n";
    std::fs::write(&log, text).unwrap();
    std::fs::create_dir_all(d.join("sub")).unwrap();
    let link = d.join("link.csv");
    std::os::unix::fs::symlink(&log, &link).unwrap();
    for out in [log.clone(), d.join("sub/../././log.csv"), link] {
        let o = bin().arg("convert").arg(&log).arg(&out).output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", out.display());
        assert!(stderr_of(&o).contains("is the input"), "{}", stderr_of(&o));
        assert_eq!(std::fs::read_to_string(&log).unwrap(), text);
    }
    let o = bin()
        .arg("compensate")
        .arg(&log)
        .args(["--model", "model.toml", "--out"])
        .arg(&log)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr_of(&o).contains("is the input"), "{}", stderr_of(&o));
    assert_eq!(std::fs::read_to_string(&log).unwrap(), text);
    let _ = std::fs::remove_dir_all(&d);
}

/// A write that fails half-way (the file-size limit standing in for a full disk) leaves
/// the earlier file as it was and no temporary file.
#[test]
fn a_failed_write_keeps_the_earlier_file() {
    let d = scratch("efbig");
    simulate(&d.join("sim"), 1);
    let input = d.join("sim/imu.csv");
    let out = d.join("out.csv");
    std::fs::write(&out, "the earlier, good file\n").unwrap();
    // SIGXFSZ ignored: a write past the limit fails with EFBIG, as on a full disk.
    let o = Command::new("sh")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 64; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_driftless"))
        .arg("convert")
        .arg(&input)
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr_of(&o));
    assert!(stderr_of(&o).contains("out.csv"), "{}", stderr_of(&o));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        "the earlier, good file\n"
    );
    assert!(
        others(&d, &["sim", "out.csv"]).is_empty(),
        "{:?}",
        others(&d, &["sim", "out.csv"])
    );
    // A device that is full: a clear error, exit 1.
    let o = bin()
        .arg("convert")
        .args(["--to", "csv"])
        .arg(&input)
        .arg("/dev/full")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr_of(&o).contains("/dev/full"), "{}", stderr_of(&o));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_closed_standard_output_ends_quietly() {
    // The reader end is closed long before the command starts writing.
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("sleep 0.3; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_driftless"))
        .args(["nav", "--print-config"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    assert!(o.stderr.is_empty(), "{}", stderr_of(&o));
}

#[test]
fn a_full_standard_output_is_an_error() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = bin()
        .args(["nav", "--print-config"])
        .stdout(full)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr_of(&o));
    let e = stderr_of(&o);
    assert!(
        e.contains("standard output") && !e.contains("panicked"),
        "{e}"
    );
}

#[test]
fn a_folder_with_another_run_needs_force() {
    let d = scratch("folder");
    let out = d.join("sim");
    simulate(&out, 1);
    let before = std::fs::read(out.join("imu.txt")).unwrap();
    let o = bin()
        .args(["simulate", "--seed", "2", "--out"])
        .arg(&out)
        .arg(scenario())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr_of(&o).contains("--force"), "{}", stderr_of(&o));
    assert_eq!(std::fs::read(out.join("imu.txt")).unwrap(), before);
    // `nav --out` the same.
    let o = bin()
        .args(["nav", "--preset", "drive_0708", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr_of(&o).contains("already holds files"),
        "{}",
        stderr_of(&o)
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `kill -9` at random instants of `simulate --force` over an earlier run: every file is
/// the earlier run's or the complete new one, never a partial one.
#[test]
fn a_kill_mid_write_leaves_old_or_complete_files() {
    let d = scratch("kill");
    let (old, new) = (d.join("old"), d.join("new"));
    simulate(&old, 1);
    simulate(&new, 2);
    let names = [
        "imu.csv",
        "imu.txt",
        "truth.nav",
        "gnss.txt",
        "gnss.pos",
        "kf-gins.yaml",
        "sensor.toml",
    ];
    let read = |dir: &Path| names.map(|n| std::fs::read(dir.join(n)).unwrap());
    let (old_bytes, new_bytes) = (read(&old), read(&new));
    let mut state = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos() as u64
        | 1;
    let mut saw_partial_run = false;
    for trial in 0..12 {
        let run = d.join(format!("run{trial}"));
        // The kill falls inside the run: a random instant within the time this machine
        // takes for one whole run (measured on the run that lays the old files).
        let clock = std::time::Instant::now();
        simulate(&run, 1);
        let whole_ms = (clock.elapsed().as_millis() as u64).max(10);
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let delay_ms = whole_ms / 20 + (state >> 33) % (whole_ms * 9 / 10);
        let mut child = bin()
            .args(["simulate", "--json", "--force", "--seed", "2", "--out"])
            .arg(&run)
            .arg(scenario())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let status = child.wait().unwrap();
        for (k, n) in names.iter().enumerate() {
            let got = std::fs::read(run.join(n)).unwrap();
            assert!(
                got == old_bytes[k] || got == new_bytes[k],
                "trial {trial} ({delay_ms} ms, {status}): {n} is neither the old nor the new file ({} bytes)",
                got.len()
            );
        }
        let done: Vec<bool> = (0..names.len())
            .map(|k| std::fs::read(run.join(names[k])).unwrap() == new_bytes[k])
            .collect();
        saw_partial_run |= done.iter().any(|&x| x) && !done.iter().all(|&x| x) || !status.success();
    }
    assert!(saw_partial_run, "no kill landed before the run ended");
    let _ = std::fs::remove_dir_all(&d);
}

/// A CSV written by driftless and cut at a line end (an interrupted `simulate` or
/// `convert`) is an error naming the file and the rows expected and found, not a shorter
/// log.
#[test]
fn a_cut_driftless_csv_is_an_error() {
    let d = scratch("cut");
    simulate(&d.join("sim"), 1);
    let text = std::fs::read_to_string(d.join("sim/imu.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let rows = lines.iter().filter(|l| !l.starts_with('#')).count() - 1;
    let cut = d.join("cut.csv");
    let keep = lines.len() * 4 / 5;
    std::fs::write(&cut, lines[..keep].join("\n") + "\n").unwrap();
    let o = bin().arg("allan").arg(&cut).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = stderr_of(&o);
    assert!(
        e.contains("cut.csv")
            && e.contains(&format!("says {rows} rows, {} found", keep - 3))
            && !e.contains("panicked"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Finite values so large that the Allan sums would overflow are refused with the reason,
/// not reported as `inf` (text) or `null` (JSON) with exit 0.
#[test]
fn values_that_would_overflow_the_sums_are_refused() {
    let d = scratch("huge");
    let log = d.join("huge.csv");
    let rows: String = (0..2000)
        .map(|i| format!("{},{:e}\n", i as f64 * 0.01, (1.0 + (i % 7) as f64) * 1e154))
        .collect();
    std::fs::write(&log, format!("time,gx\n{rows}")).unwrap();
    for extra in [&[][..], &["--no-fit"], &["--no-fit", "--json"]] {
        let mut cmd = bin();
        cmd.arg("allan").arg(&log).args(extra);
        let o = cmd.output().unwrap();
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(1), "{out}");
        assert!(!out.contains("inf") && !out.contains("null"), "{out}");
        assert!(stderr_of(&o).contains("rescale"), "{}", stderr_of(&o));
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `kill -9` at random instants of `nav --kf-gins` over an earlier run's files: each of
/// KF-GINS's three files is the earlier one, the complete new one, or absent (the moment
/// between removing the old file and renaming the new one) — never partial.
#[test]
fn a_kill_mid_kf_gins_run_leaves_old_complete_or_no_files() {
    let d = scratch("killnav");
    let sim = d.join("sim");
    simulate(&sim, 1);
    let cfg = std::fs::read_to_string(sim.join("kf-gins.yaml")).unwrap();
    let out = sim.join("kf-gins-out");
    let names = [
        "KF_GINS_Navresult.nav",
        "KF_GINS_IMU_ERR.txt",
        "KF_GINS_STD.txt",
    ];
    let run = |yaml: &str| {
        std::fs::write(sim.join("run.yaml"), yaml).unwrap();
        let o = bin()
            .current_dir(&sim)
            .args(["nav", "--kf-gins", "run.yaml", "--json"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr_of(&o));
        names.map(|n| std::fs::read(out.join(n)).unwrap())
    };
    // The earlier run: the first 60 s only.
    let short = common::kf_gins_first_seconds(&cfg, 60.0);
    let old = run(&short);
    let new = run(&cfg);
    assert!(old[0] != new[0]);
    let mut state = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos() as u64
        | 1;
    for trial in 0..12 {
        for (n, bytes) in names.iter().zip(&old) {
            std::fs::write(out.join(n), bytes).unwrap();
        }
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let delay_ms = 5 + (state >> 33) % 90;
        let mut child = bin()
            .current_dir(&sim)
            .args(["nav", "--kf-gins", "kf-gins.yaml", "--json"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let status = child.wait().unwrap();
        for (k, n) in names.iter().enumerate() {
            if let Ok(got) = std::fs::read(out.join(n)) {
                assert!(
                    got == old[k] || got == new[k],
                    "trial {trial} ({delay_ms} ms, {status}): {n} is neither the old nor the new file ({} bytes)",
                    got.len()
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Every command that writes a folder fails at once, exit 1, on a folder another run is
/// writing (here the test holds the folder's lock), naming the folder; the folder is left
/// as it was.
#[test]
fn a_folder_another_run_writes_is_refused_at_once() {
    let d = scratch("locked");
    let sim = d.join("sim");
    simulate(&sim, 1);
    let busy = d.join("busy");
    std::fs::create_dir_all(&busy).unwrap();
    std::fs::write(busy.join("kept.txt"), "another run's file").unwrap();
    let lock = driftless::io::output::lock_folder(&busy).unwrap();
    let yaml = std::fs::read_to_string(sim.join("kf-gins.yaml"))
        .unwrap()
        .replace(
            "outputpath: \"kf-gins-out\"",
            &format!("outputpath: \"{}\"", busy.display()),
        );
    assert!(yaml.contains(&busy.display().to_string()), "{yaml}");
    std::fs::write(sim.join("busy.yaml"), yaml).unwrap();
    let experiment = d.join("adi.toml");
    let o = bin().args(["demo", "--print-scenario"]).output().unwrap();
    std::fs::write(&experiment, &o.stdout).unwrap();
    let commands: [&[&str]; 5] = [
        &["simulate", "--force", "--out", "BUSY", "SCENARIO"],
        &["nav", "--preset", "drive_0708", "--force", "--out", "BUSY"],
        &["experiment", "--force", "--out", "BUSY", "EXPERIMENT"],
        &["demo", "--force", "--out", "BUSY"],
        &["nav", "--kf-gins", "busy.yaml"],
    ];
    for args in commands {
        let clock = std::time::Instant::now();
        let o = bin()
            .current_dir(&sim)
            .args(args.iter().map(|a| match *a {
                "BUSY" => busy.clone().into_os_string(),
                "SCENARIO" => scenario().into_os_string(),
                "EXPERIMENT" => experiment.clone().into_os_string(),
                a => a.into(),
            }))
            .output()
            .unwrap();
        let e = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains(&busy.display().to_string())
                && e.contains("another driftless run is writing it"),
            "{args:?}: {e}"
        );
        assert!(clock.elapsed() < Duration::from_secs(5), "{args:?}");
        assert_eq!(others(&busy, &[]), ["kept.txt"], "{args:?}");
    }
    drop(lock);
    let _ = std::fs::remove_dir_all(&d);
}

/// `experiment --out` and `demo --out` refuse a folder that holds files unless `--force`,
/// before any work; a killed run's temporary files alone do not count.
#[test]
fn experiment_and_demo_folders_with_files_need_force() {
    let d = scratch("expfolder");
    let out = d.join("exp");
    std::fs::create_dir_all(&out).unwrap();
    // A temporary file of a process that has ended: not another run's file.
    let mut ended = Command::new("true").spawn().unwrap();
    let pid = ended.id();
    ended.wait().unwrap();
    let stale = format!(".table1.csv.partial-{pid}-0");
    std::fs::write(out.join(&stale), "half").unwrap();
    std::fs::write(out.join("table1.csv"), "an earlier run\n").unwrap();
    let scenario_file = d.join("adi.toml");
    let o = bin().args(["demo", "--print-scenario"]).output().unwrap();
    std::fs::write(&scenario_file, &o.stdout).unwrap();
    for args in [
        vec![
            "experiment".into(),
            "--out".into(),
            out.clone().into_os_string(),
            scenario_file.clone().into_os_string(),
        ],
        vec!["demo".into(), "--out".into(), out.clone().into_os_string()],
        vec![
            "demo".into(),
            "--noise".into(),
            "--out".into(),
            out.clone().into_os_string(),
        ],
    ] {
        let clock = std::time::Instant::now();
        let o = bin().args(&args).output().unwrap();
        let e = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains("already holds files (table1.csv)") && e.contains("--force"),
            "{args:?}: {e}"
        );
        assert!(clock.elapsed() < Duration::from_secs(5), "{args:?}");
        assert_eq!(
            std::fs::read_to_string(out.join("table1.csv")).unwrap(),
            "an earlier run\n"
        );
        // The lock taken before the refusal cleared the ended run's temporary file
        // (where process ids can be checked).
        #[cfg(target_os = "linux")]
        assert!(!out.join(&stale).exists(), "{args:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
